#!/usr/bin/env bash
# One run, same machine: the whole default `fogsim train` pipeline (width, degree and
# size selection by grouped CV + final fit) timed with /usr/bin/time -v (wall, CPU,
# peak RSS), then scikit-learn's OMP with 35 atoms on the same points and candidates.
# Needs: pip install scikit-learn numpy; a release build of fogsim.
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-$(mktemp -d)}"
fogsim="${FOGSIM:-${CARGO_TARGET_DIR:-target}/release/fogsim}"
"$fogsim" campaign --out "$work/campaign" > /dev/null
mkdir -p "$work/train"
cp "$work"/campaign/*run[123].csv "$work/train/"
/usr/bin/time -v "$fogsim" train "$work/train" --out "$work/model.bin" \
    --export-design "$work/design.json" 2> "$work/time.txt" | tail -3
grep -E "Elapsed|User time|Maximum resident" "$work/time.txt"
python3 bench/sklearn_omp.py "$work/design.json"
