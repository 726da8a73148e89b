#!/usr/bin/perl
# An independent PNG decoder for the tests (Perl's own zlib binding): checks the
# signature and every chunk's CRC, inflates the image data, undoes the filters of a
# non-interlaced image and prints "WIDTH HEIGHT CHANNELS DEPTH\n" and the raw samples.
use strict;
use warnings;
use Compress::Zlib;

my $file = shift or die "usage: png_check.pl FILE.png\n";
open my $fh, '<:raw', $file or die "$file: $!\n";
my $s = do { local $/; <$fh> };
substr($s, 0, 8) eq "\x89PNG\r\n\x1a\n" or die "$file: not a PNG signature\n";
my ($p, $w, $h, $d, $ct, $il, $idat, $ended) = (8, 0, 0, 0, 0, 0, '', 0);
while ($p + 12 <= length $s) {
  my ($len, $type) = unpack('Na4', substr($s, $p, 8));
  my $data = substr($s, $p + 8, $len);
  my $crc = unpack('N', substr($s, $p + 8 + $len, 4));
  crc32($type . $data) == $crc or die "$file: bad CRC in chunk $type\n";
  if ($type eq 'IHDR') { ($w, $h, $d, $ct, undef, undef, $il) = unpack('NNCCCCC', $data) }
  elsif ($type eq 'IDAT') { $idat .= $data }
  elsif ($type eq 'IEND') { $ended = 1; last }
  $p += 12 + $len;
}
$ended or die "$file: no IEND chunk\n";
$p + 12 == length $s or die "$file: bytes after IEND\n";
$il == 0 or die "$file: interlaced\n";
my $ch = {0 => 1, 2 => 3, 4 => 2, 6 => 4}->{$ct} or die "$file: colour type $ct\n";
my $bpp = $ch * $d / 8;
my $stride = $w * $bpp;
my $raw = uncompress($idat);
defined $raw or die "$file: the image data does not inflate\n";
length($raw) == $h * ($stride + 1) or die "$file: wrong amount of image data\n";
my @prev = (0) x $stride;
my $out = '';
for my $y (0 .. $h - 1) {
  my @r = unpack('C*', substr($raw, $y * ($stride + 1), $stride + 1));
  my $ft = shift @r;
  for my $k (0 .. $stride - 1) {
    my $a = $k >= $bpp ? $r[$k - $bpp] : 0;
    my $b = $prev[$k];
    my $c = $k >= $bpp ? $prev[$k - $bpp] : 0;
    my $x = $r[$k];
    if ($ft == 1) { $x += $a }
    elsif ($ft == 2) { $x += $b }
    elsif ($ft == 3) { $x += int(($a + $b) / 2) }
    elsif ($ft == 4) {
      my $q = $a + $b - $c;
      my ($pa, $pb, $pc) = (abs($q - $a), abs($q - $b), abs($q - $c));
      $x += ($pa <= $pb && $pa <= $pc) ? $a : ($pb <= $pc ? $b : $c);
    }
    elsif ($ft != 0) { die "$file: filter type $ft\n" }
    $r[$k] = $x & 255;
  }
  $out .= pack('C*', @r);
  @prev = @r;
}
binmode STDOUT;
print "$w $h $ch $d\n", $out;
