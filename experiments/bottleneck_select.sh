#!/bin/sh
# Validation figures for choosing between RGW fact-bottleneck checkpoints, on levels that the
# held-out figures (bottleneck_measure.sh, seed 3e9) never use: sampled success on 300
# levels of seed 4e9; next-object fidelity of a strategy learned from the relation facts of
# 200 greedy episodes (seed 2e9) and scored on 100 greedy episodes of seed 4e9; rgw2's
# greedy return. Choose on these, then measure the chosen one once with bottleneck_measure.sh.
#   sh experiments/bottleneck_select.sh CHECKPOINT OUTDIR
set -eu
CK=$1
OUT=$2
PY=${PY:-python}
mkdir -p "$OUT"
run() { nice -n 10 $PY -m neurosym "$@"; }
run eval --checkpoint "$CK" --episodes 300 --seed 4000000000 --sample --json > "$OUT/eval-sampled.json"
run eval --checkpoint "$CK" --env rgw2 --episodes 1 --json > "$OUT/rgw2.json"
run extract --checkpoint "$CK" --episodes 200 --seed 2000000000 --out "$OUT/train" --quiet
run extract --checkpoint "$CK" --episodes 100 --seed 4000000000 --out "$OUT/valid" --quiet
run induce strategy --kb "$OUT/train/kb.pl" --holdout "$OUT/valid/kb.pl" \
    --features relations --out "$OUT/relations.pl" > "$OUT/induce.txt"
grep -o '"success_rate": [0-9.]*' "$OUT/eval-sampled.json" || true
grep -o '"mean_return": [0-9.-]*' "$OUT/rgw2.json" || true
grep fidelity "$OUT/induce.txt" || true
