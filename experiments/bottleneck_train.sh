#!/bin/sh
# The fact-bottleneck PrediNet (ModelConfig.relation_bits) on rgw-random by DAgger from the
# env's planner, starting from the cell-keyed agent's encoder, attention and MLP
# (experiments/bottleneck_init.py); niced, snapshots every 8 minutes for the learning curve.
#   sh experiments/bottleneck_train.sh RUN MINUTES            # a new run in runs/RUN
#   sh experiments/bottleneck_train.sh RUN MINUTES --resume   # continue it (LR=1e-4: its lr)
# Then, per snapshot: neurosym eval --checkpoint FILE --episodes 300 --seed 3000000000 --sample
set -eu
RUN=${1:-bn1}
MINUTES=${2:-55}
PY=${PY:-python}
if [ "${3:-}" = "--resume" ]; then
    exec nice -n 10 $PY -m neurosym train --out "runs/$RUN" --resume --minutes "$MINUTES" \
        --snapshot-every 4 --quiet ${LR:+--lr $LR}
fi
$PY experiments/bottleneck_init.py checkpoints/rgw-random-predinet-cellkeys.pt \
    "runs/$RUN-init.pt" --tau 0.25 --env-option num_mountains=6
exec nice -n 10 $PY -m neurosym train --env rgw-random --env-option num_mountains=6 \
    --out "runs/$RUN" --init-from "runs/$RUN-init.pt" --algo imitate --minutes "$MINUTES" \
    --seed 0 --augment --safe-coef 4 --snapshot-every 8 --slim --quiet
