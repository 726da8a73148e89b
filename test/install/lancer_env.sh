#!/usr/bin/env bash
# lancer-env from a project outside the tree, as make install leaves it: .ci/install-env
# installs the libraries dune built (its install tree) and lancer-env into a prefix in a
# temporary directory, outside this workspace; beside it, the project of
# doc/howto/golden-tests.md (the files of its blocks marked route=golden) is written, and
# its commands run there in a clean environment: the golden is written and the test
# passes; it passes against the example project's golden of the same scene too, and
# fails once the ball changes colour. Without lancer-env, dune there must
# not find lancer-alcotest (or the check would prove nothing).
# Usage (dune runs it from _build/default/test/install): lancer_env.sh
set -euo pipefail
build=$(cd ../.. && pwd)          # _build/default: the copies of .ci/ and doc/
tmp=$(mktemp -d "${TMPDIR:-/tmp}/lancer-env-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix project=$tmp/my-scenes
libdir=$build/../install/default/lib
if [ ! -d "$libdir/lancer" ]; then
  # dune build -p lancer-alcotest, against a lancer installed elsewhere: make install
  # installs both from one build, which this cannot play.
  echo "lancer-env: not checked: lancer is not built in this workspace"
  exit 0
fi
mode=$(bash "$build/.ci/install-env" "$libdir" "$prefix" "$prefix")
fail() { echo "lancer-env: $*" >&2; exit 1; }

# The blocks of the guide marked route=golden: files into the project, sh lines to run.
mkdir -p "$project"
awk -v dir="$project" '
  /^```/ && !inside { inside = 1; take = 0; file = ""
    for (i = 2; i <= split($0, w, " "); i++) { if (w[i] == "route=golden") take = 1; if (w[i] ~ /^file=/) file = substr(w[i], 6) }
    if (take && file != "") out = dir "/" file; else if (take && $0 ~ /^```sh /) out = dir "/route.sh"; else take = 0
    next }
  /^```/ { inside = 0; if (take) close(out); next }
  inside && take { print >> out }' "$build/doc/howto/golden-tests.md"
for f in dune-project dune test_scenes.ml ball.rts route.sh; do
  [ -s "$project/$f" ] || fail "doc/howto/golden-tests.md has no route=golden block for $f"
done

# A user's shell: no variable of dune's or of this build, lancer's prefix on PATH.
clean() {
  (cd "$project" && env -i PATH="$prefix/bin:$PATH" HOME="$tmp" TMPDIR="$tmp" \
    ${LANCER_IN_TOOLCHAIN:+LANCER_IN_TOOLCHAIN=1} DUNE_CACHE=disabled "$@")
}
if clean dune build >"$tmp/without.log" 2>&1; then fail "dune found lancer-alcotest without lancer-env"; fi
grep -q 'lancer-alcotest' "$tmp/without.log" || { cat "$tmp/without.log"; fail "dune failed otherwise than on lancer-alcotest"; }

clean bash -e route.sh >"$tmp/route.log" 2>&1 || { cat "$tmp/route.log"; fail "the guide's commands failed"; }
# The same scene against the example project's committed golden: rendered, not copied.
cp "$build/test/example-user/golden/ball.png" "$project/golden/ball.png"
clean lancer-env dune test >"$tmp/example.log" 2>&1 ||
  { cat "$tmp/example.log"; fail "ball.rts does not match test/example-user/golden/ball.png"; }

sed -i 's/0.15, 0.35, 0.9/0.2, 0.8, 0.2/' "$project/ball.rts"
if clean lancer-env dune test >"$tmp/changed.log" 2>&1; then fail "the test passed with the ball's colour changed"; fi
grep -q 'differs from its golden' "$tmp/changed.log" || { cat "$tmp/changed.log"; fail "the changed ball failed otherwise"; }
echo "lancer-env ($mode): the guide's project outside the tree wrote its golden, passed, and failed on a change"
