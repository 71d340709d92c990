#!/bin/sh
# Held-out figures of a checkpoint (the fact-bottleneck agent or a control):
#   sampled success on 300 unseen rgw-random levels (seed 3e9), and next-object fidelity of a
#   strategy learned from its relation facts alone (holds/5, attends/8), trained on a KB of
#   200 greedy episodes (seed 2e9) and scored on 100 held-out ones (seed 3e9), as
#   docs/results.md "Strategies learned back" does.
#   sh experiments/bottleneck_measure.sh CHECKPOINT OUTDIR
set -eu
CK=$1
OUT=$2
PY=${PY:-python}
mkdir -p "$OUT"
nice -n 10 $PY -m neurosym eval --checkpoint "$CK" --episodes 300 --seed 3000000000 --sample \
    --json > "$OUT/eval-sampled.json"
nice -n 10 $PY -m neurosym extract --checkpoint "$CK" --episodes 200 --seed 2000000000 \
    --out "$OUT/kb-train" --quiet
nice -n 10 $PY -m neurosym extract --checkpoint "$CK" --episodes 100 --seed 3000000000 \
    --out "$OUT/kb-test" --quiet
nice -n 10 $PY -m neurosym induce strategy --kb "$OUT/kb-train/kb.pl" \
    --holdout "$OUT/kb-test/kb.pl" --features relations --out "$OUT/relations.pl" \
    > "$OUT/induce-relations.txt"
grep -o '"success_rate": [0-9.]*' "$OUT/eval-sampled.json" || true
grep fidelity "$OUT/induce-relations.txt" || true
