#!/bin/sh
# Every command that `lancer --help` lists has an installed man page and completion
# entry (a command added without them fails here). usage: check.sh LANCER_EXE
set -eu
exe=$1
cmds=$("$exe" --help=plain | awk '/^COMMANDS/ {on=1; next} /^[A-Z]/ {on=0} on && /^       [a-z]/ {print $1}')
[ -n "$cmds" ] || { echo "no commands found in lancer --help=plain"; exit 1; }
status=0
for c in $cmds; do
  [ -s "lancer-$c.1" ] || { echo "lancer $c has no man page (add it to bin/share/dune)"; status=1; }
  grep -q "^    $c) opts=\"--" lancer.bash || { echo "lancer $c has no completion entry"; status=1; }
done
grep -q '^\.TH "LANCER-RENDER" 1' lancer-render.1 || { echo "lancer-render.1 is not a man page"; status=1; }
exit $status
