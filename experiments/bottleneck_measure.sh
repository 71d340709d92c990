#!/bin/sh
# Held-out figures of a checkpoint (the fact-bottleneck agent) beside its untrained control:
#   sampled success on 300 unseen rgw-random levels (seed 3e9); next-object fidelity of a
#   strategy learned from the relation facts alone (holds/5, attends/8), trained on a KB of
#   200 greedy episodes (seed 2e9) and scored on 100 held-out ones (seed 3e9), as
#   docs/results.md "Strategies learned back" does, for the agent and for the same
#   architecture untrained (experiments/bottleneck_init.py --fresh); rgw2 zero-shot (greedy,
#   one episode: the fixed map) and, on that episode's KB, the relations between the enemy
#   and the agent that carries the sword (armed_enemy_link/1 of rules/rgw.pl; its untrained
#   control: experiments/link_control.py).
#   sh experiments/bottleneck_measure.sh CHECKPOINT OUTDIR
# To choose between checkpoints, measure them on levels the held-out figures never use
# (SEED=4000000000: sampled success and the strategy's held-out episodes come from that
# seed), then measure the chosen one once with the default.
set -eu
CK=$1
OUT=$2
PY=${PY:-python}
SEED=${SEED:-3000000000}
mkdir -p "$OUT"
run() { nice -n 10 $PY -m neurosym "$@"; }
run eval --checkpoint "$CK" --episodes 300 --seed "$SEED" --sample --json > "$OUT/eval-sampled.json"
run eval --checkpoint "$CK" --episodes 300 --seed "$SEED" --json > "$OUT/eval-greedy.json"
$PY experiments/bottleneck_init.py "$CK" "$OUT/untrained.pt" --fresh
for who in agent untrained; do
    ck=$CK
    [ "$who" = untrained ] && ck="$OUT/untrained.pt"
    run extract --checkpoint "$ck" --episodes 200 --seed 2000000000 --out "$OUT/$who-train" --quiet
    run extract --checkpoint "$ck" --episodes 100 --seed "$SEED" --out "$OUT/$who-test" --quiet
    run induce strategy --kb "$OUT/$who-train/kb.pl" --holdout "$OUT/$who-test/kb.pl" \
        --features relations --out "$OUT/$who-relations.pl" > "$OUT/$who-induce.txt"
done
run eval --checkpoint "$CK" --env rgw2 --episodes 1 --json > "$OUT/rgw2.json"
run extract --checkpoint "$CK" --env rgw2 --episodes 1 --out "$OUT/rgw2-kb" --quiet
run query --kb "$OUT/rgw2-kb/kb.pl" --rules rgw \
    'armed_enemy_link(A), sword_enemy_link(L)' > "$OUT/rgw2-links.txt"
grep -o '"success_rate": [0-9.]*' "$OUT/eval-sampled.json" "$OUT/eval-greedy.json" || true
grep -o '"mean_return": [0-9.-]*' "$OUT/rgw2.json" || true
grep -H fidelity "$OUT/agent-induce.txt" "$OUT/untrained-induce.txt" || true
cat "$OUT/rgw2-links.txt"
