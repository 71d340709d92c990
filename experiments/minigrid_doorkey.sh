#!/usr/bin/env bash
# A PrediNet agent on Minigrid's DoorKey with neurosym's own trainer: DAgger from the exact
# DoorKey planner (neurosym/envs/minigrid_solver.py), then held-out evaluation and a KB.
#
#   bash experiments/minigrid_doorkey.sh RUNS_DIR [MINUTES]
#
# Stages (each resumable by hand with `neurosym train --resume --out DIR`):
#   1. DoorKey-5x5, the fast check: does the network copy the planner at all.
#   2. DoorKey-8x8 (a fresh network: --init-from needs the same observation shape), many
#      small gradient steps per labelled frame: on a shared CPU the gradient steps, not the
#      env frames, are what is scarce.
#   3. 300 unseen levels (seed 3e9) greedy, then `neurosym extract` on 100 levels (seed 2e9)
#      and rules/minigrid.pl's key_door_link/2 over the KB.
#
# The learner takes one torch thread per core it may use (os.sched_getaffinity); on a machine
# whose cores other jobs share, those threads wait on each other: an update took 6x longer
# with 2 threads than with 1 here. PIN (default `taskset -c 0`) gives the run one core, so one
# thread; PIN= leaves it unpinned.
set -euo pipefail
runs=${1:?usage: $0 RUNS_DIR [MINUTES]}
minutes=${2:-40}
py=${PYTHON:-python}
pin=${PIN-taskset -c 0}
dagger=(--algo imitate --envs 16 --n-steps 16 --dagger-steps 16 --set dagger_batch=64
        --set reward_scale=1 --lr 1e-3 --eval-interval 300 --eval-episodes 8
        --checkpoint-interval 120 --snapshot-every 6 --quiet)

nice $pin "$py" -m neurosym train --env MiniGrid-DoorKey-5x5-v0 --module predinet \
    --out "$runs/dk5" --minutes "$((minutes / 4))" --set dagger_beta_frames=10000 "${dagger[@]}"
nice $pin "$py" -m neurosym train --env MiniGrid-DoorKey-8x8-v0 --module predinet \
    --out "$runs/dk8" --minutes "$minutes" --set dagger_beta_frames=20000 "${dagger[@]}"

for run in dk5 dk8; do
    nice $pin "$py" -m neurosym eval --checkpoint "$runs/$run/checkpoint.pt" --episodes 300 \
        --seed 3000000000 --json
done
nice $pin "$py" -m neurosym extract --checkpoint "$runs/dk8/checkpoint.pt" --episodes 100 \
    --seed 2000000000 --out "$runs/dk8-kb"
"$py" -m neurosym query --kb "$runs/dk8-kb/kb.pl" --rules minigrid 'key_door_link(C, L)'
