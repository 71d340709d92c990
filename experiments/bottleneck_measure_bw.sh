#!/bin/sh
# Held-out figures of a Box-World fact-bottleneck checkpoint beside its controls: sampled and
#   greedy success on 300 unseen levels (seed 3e9); the heads table and extract's faithfulness
#   (relation facts / world facts / an untrained network's relation facts on the same states /
#   chance) on 100 greedy held-out episodes; key_lock_link/2 (rules/boxworld.pl) over that KB
#   beside the untrained network's facts on the same states (experiments/link_control.py); and
#   of the states holding a key (Holding), those at which some head (A) or head 0 (Head0)
#   attends the lock it opens, head 0 attends the held key and that lock (Pair), and a relation
#   fact holds between them (Related).
#   sh experiments/bottleneck_measure_bw.sh CHECKPOINT ENV OUTDIR
set -eu
CK=$1
ENV=$2
OUT=$3
PY=${PY:-python}
mkdir -p "$OUT"
run() { nice -n 10 $PY -m neurosym "$@"; }
run eval --checkpoint "$CK" --env "$ENV" --episodes 300 --seed 3000000000 --sample --json \
    > "$OUT/eval-sampled.json"
run eval --checkpoint "$CK" --env "$ENV" --episodes 300 --seed 3000000000 --json \
    > "$OUT/eval-greedy.json"
run extract --checkpoint "$CK" --env "$ENV" --episodes 100 --seed 3000000000 --greedy \
    --out "$OUT/kb" > "$OUT/extract.txt"
run query --kb "$OUT/kb/kb.pl" --rules boxworld \
    'matching_lock_rate(A, Holding), aggregate_all(count, attends_matching_lock(_, _, 0), Head0),
     aggregate_all(count, (holding(_E, _T, key(_C)), attends(_E, _T, 0, 1, held(_C), _, _, _),
                           attends(_E, _T, 0, 2, lock(_C), _, _, _)), Pair),
     aggregate_all(count, (holding(_E2, _T2, key(_C2)),
                           once((holds(_E2, _T2, _, held(_C2), lock(_C2))
                               ; holds(_E2, _T2, _, lock(_C2), held(_C2))))), Related)' \
    > "$OUT/matching-lock.txt"
$PY experiments/link_control.py "$CK" --env "$ENV" --rules boxworld --goal 'key_lock_link(C, A)' \
    --episodes 100 --seed 3000000000 --greedy > "$OUT/links.txt"
grep -o '"success_rate": [0-9.]*' "$OUT/eval-sampled.json" "$OUT/eval-greedy.json" || true
cat "$OUT/extract.txt" "$OUT/matching-lock.txt"
