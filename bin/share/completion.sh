#!/bin/sh
# Writes a bash completion script for lancer on stdout, read from the commands' own
# --help=plain (so it always lists the commands and options the binary has).
# cmdliner 1.3, the version Debian 13 packages, has no completion generator of its own.
# usage: completion.sh LANCER_EXE
set -eu
exe=$1
cmds=$("$exe" --help=plain | awk '/^COMMANDS/ {on=1; next} /^[A-Z]/ {on=0} on && /^       [a-z]/ {print $1}' | tr '\n' ' ')
opts_of() {
  "$exe" "$@" --help=plain 2>/dev/null | grep -oE '(^|[ ,])--?[A-Za-z][A-Za-z0-9-]*' |
    sed 's/^[ ,]*//' | sort -u | tr '\n' ' '
}
echo "# bash completion for lancer (generated from lancer --help=plain)"
echo "_lancer() {"
echo '  local cur=${COMP_WORDS[COMP_CWORD]} cmd=${COMP_WORDS[1]:-} opts'
echo '  if [ "$COMP_CWORD" = 1 ]; then'
echo "    COMPREPLY=(\$(compgen -W \"$cmds --help --version\" -- \"\$cur\")); return"
echo '  fi'
echo '  case "$cmd" in'
for c in $cmds; do
  echo "    $c) opts=\"$(opts_of "$c")\" ;;"
done
echo '    *) opts="" ;;'
echo '  esac'
echo '  case "$cur" in'
echo '    -*) COMPREPLY=($(compgen -W "$opts" -- "$cur")) ;;'
echo '    *) COMPREPLY=($(compgen -f -- "$cur")) ;;'
echo '  esac'
echo "}"
echo "complete -o filenames -F _lancer lancer"
