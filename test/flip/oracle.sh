#!/usr/bin/env bash
# Remakes test/flip/oracle.tsv from the reference implementations (NVIDIA's
# flip-evaluator and scikit-image, installed by pip into a virtual environment under
# out/), then runs test/flip, which fails where lancer's FLIP or SSIM differs from them by
# more than 0.001. Needs the network the first time (pip), and python3 with venv.
# `git diff test/flip/oracle.tsv` afterwards shows whether the references moved.
#
#   bash test/flip/oracle.sh        (or make flip-oracle)
#   PYTHON=/path/to/python bash test/flip/oracle.sh   a Python that has the packages
set -euo pipefail
top=$(cd "$(dirname "$0")/../.." && pwd)
cd "$top"
venv=out/flip-oracle
python=${PYTHON:-$venv/bin/python}
if [ ! -x "$python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet flip-evaluator==1.7 scikit-image==0.26.0
fi
"$python" test/flip/oracle.py test/flip/pairs > out/oracle.tsv
mv out/oracle.tsv test/flip/oracle.tsv
echo "test/flip/oracle.tsv remade:"
grep -v '^#' test/flip/oracle.tsv
bash .ci/toolchain run dune test -j 2 --force test/flip
