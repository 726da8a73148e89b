#!/bin/sh
# check_example.sh PAGE.mld PROGRAM.ml: the page's {[ … ]} block must be the program from
# its `open Lancer` line on, so that the example the API documentation shows is one the
# tests compile and run.
set -eu
sed -n '/^{\[$/,/^\]}$/p' "$1" | sed '1d;$d' >page-example.ml
sed -n '/^open Lancer$/,$p' "$2" >program-example.ml
if ! diff program-example.ml page-example.ml >&2; then
  echo "$1: its example differs from $2 (from 'open Lancer' on)" >&2
  exit 1
fi
