#!/usr/bin/env bash
# One run, same machine: the whole default `fogsim train` pipeline (width, degree and
# size selection by grouped CV + final fit) timed with /usr/bin/time -v (wall, CPU,
# peak RSS), then scikit-learn's OMP with 35 atoms on the same points and candidates,
# and the ratio of the two. FOG_TRAIN_PROFILE=1 also prints where training spends its
# time (per width: candidates, Gram accumulation, selection paths and held-out scores).
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
grep -E "^profile" "$work/time.txt" || true
grep -E "Elapsed|User time|System time|Maximum resident" "$work/time.txt"
wall=$(awk -F': ' '/Elapsed/ {n = split($2, t, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + t[i]; print s}' "$work/time.txt")
cpu=$(awk -F': ' '/User time|System time/ {s += $2} END {print s}' "$work/time.txt")
python3 bench/sklearn_omp.py "$work/design.json" "$wall" "$cpu"
