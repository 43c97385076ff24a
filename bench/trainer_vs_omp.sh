#!/usr/bin/env bash
# One run, same machine: the whole default `fogsim train` pipeline (width, degree and
# size selection by grouped CV + final fit) timed with /usr/bin/time -v (median wall,
# CPU, peak RSS of 5 processes), then scikit-learn's OMP with 35 atoms on the same
# points (our grid candidates, and every training point), and the ratios.
# FOG_TRAIN_PROFILE=1 also prints where training spends its time (per width:
# candidates, Gram accumulation, selection paths and held-out scores).
# Needs: pip install scikit-learn numpy; a release build of fogsim.
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-$(mktemp -d)}"
fogsim="${FOGSIM:-${CARGO_TARGET_DIR:-target}/release/fogsim}"
"$fogsim" campaign --out "$work/campaign" > /dev/null
mkdir -p "$work/train"
cp "$work"/campaign/*run[123].csv "$work/train/"
# Five whole processes; the medians of wall, CPU (user + sys) and peak RSS are compared.
for i in 1 2 3 4 5; do
    t0=$EPOCHREALTIME
    /usr/bin/time -v "$fogsim" train "$work/train" --out "$work/model.bin" \
        --export-design "$work/design.json" 2> "$work/time$i.txt" > "$work/train$i.txt"
    t1=$EPOCHREALTIME
    echo "$t0 $t1" | awk '{printf "%.4f\n", $2 - $1}' > "$work/wall$i.txt"
done
tail -3 "$work/train1.txt"
grep -E "^profile" "$work/time1.txt" || true
median() { sort -g | sed -n 3p; }
wall=$(cat "$work"/wall[1-5].txt | median)
cpu=$(for i in 1 2 3 4 5; do awk -F': ' '/User time|System time/ {s += $2} END {print s}' "$work/time$i.txt"; done | median)
rss=$(for i in 1 2 3 4 5; do awk -F': ' '/Maximum resident/ {print $2}' "$work/time$i.txt"; done | median)
echo "fogsim train, median of 5 processes: ${wall} s wall, ${cpu} s CPU, peak RSS ${rss} kB"
python3 bench/sklearn_omp.py "$work/design.json" "$wall" "$cpu"
