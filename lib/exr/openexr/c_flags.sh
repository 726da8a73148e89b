#!/bin/sh
# The C flags of OpenEXR's headers as a dune list, from pkg-config (OpenEXR 3.2's
# headers include Imath's, in a directory of their own); Debian's directories where
# pkg-config does not know OpenEXR.
flags=$(pkg-config --cflags OpenEXR 2>/dev/null) ||
  flags="-I/usr/include/OpenEXR -I/usr/include/Imath"
printf '(%s)\n' "$flags"
