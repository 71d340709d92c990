#!/usr/bin/env bash
# Both outside agents of this folder through neurosym, end to end (a minute of CPU time):
# a user's own PyTorch module (my_agent.py) and a Stable-Baselines3 PPO model (sb3_agent.py),
# each recorded, written as a KB, queried, intervened on and shown on a report page.
set -euo pipefail
cd "$(dirname "$0")/../.."
ENV=MiniGrid-DoorKey-5x5-v0
OUT=${OUT:-kb_out/own_agent}

# 1. A user's PyTorch module: FILE.py:FUNCTION returns the agent; its nn.MultiheadAttention's
#    weights become attention/6 facts and its heads can be ablated.
neurosym extract --checkpoint examples/own_agent/my_agent.py:make_agent --episodes 10 --out "$OUT/torch"
neurosym query --kb "$OUT/torch/kb.pl" --rules relations --limit 5 'attention(0, 0, Head, agent, Key, W)'
# (intervene plays RGW and Box-World: the same network on rgw2, heads ablated one by one)
neurosym intervene --checkpoint examples/own_agent/my_agent.py:make_rgw2_agent --no-levels --episodes 10 --out "$OUT/torch-ablate"
neurosym query --kb "$OUT/torch-ablate/kb.pl" 'effect(X, kl, KL)'
neurosym report --recording "$OUT/torch" --quiet

# 2. A Stable-Baselines3 model: the saved .zip, read without unpickling anything in it.
#    (STEPS=20000 shows the mechanics; train_doorkey_sb3.py trains one that solves DoorKey.)
python examples/own_agent/sb3_agent.py --steps "${STEPS:-20000}" --out "$OUT/ppo_doorkey.zip"
neurosym extract --checkpoint "$OUT/ppo_doorkey.zip" --env "$ENV" --episodes 10 --out "$OUT/sb3"
neurosym query --kb "$OUT/sb3/kb.pl" --rules minigrid 'episode(E, Steps, Return, Outcome)'
neurosym report --recording "$OUT/sb3" --quiet
echo "pages: $OUT/torch/index.html $OUT/sb3/index.html"
