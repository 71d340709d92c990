"""armed_enemy_link/1 (rules/rgw.pl) of an RGW agent beside its untrained control on the same states.

    python experiments/armed_control.py checkpoints/rgw-random-predinet-bottleneck.pt \
        [--env rgw2] [--episodes 20] [--seed 0] [--greedy]

Records the agent's episodes (sampled unless ``--greedy``), writes their KB, and writes a
second KB of the same states whose relation facts are those of a freshly initialised network
of the same ModelConfig (neurosym.record.faithfulness.ControlledAgent: the trained network
acts, the untrained one is introspected; each at the agent's own threshold spec). Prints
both answers: the share of the states between taking the sword and meeting the enemy on
which the network relates the agent that carries it and the enemy.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from neurosym.agent.agent import load_agent
from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.record.extraction import extract
from neurosym.record.faithfulness import ControlledAgent, untrained_agent

RULES = Path(__file__).resolve().parents[1] / "rules" / "rgw.pl"
QUERY = "armed_enemy_link(S), format(atom(A), '~q', [S])"


def answer(agent: object, args: argparse.Namespace, where: Path) -> str:
    got = extract(agent, args.env, episodes=args.episodes, seed=args.seed,
                  greedy=args.greedy, faithfulness=False)  # fmt: skip
    got.facts.to_prolog(where)
    with KnowledgeBase(where, rules=[RULES]) as kb:
        return str(kb.query(QUERY)[0]["A"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint")
    parser.add_argument("--env", default="rgw2")
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--greedy", action="store_true")
    args = parser.parse_args()
    agent = load_agent(args.checkpoint)
    with tempfile.TemporaryDirectory() as tmp:
        trained = answer(agent, args, Path(tmp) / "agent.pl")
        control = ControlledAgent(agent, untrained_agent(agent))
        untrained = answer(control, args, Path(tmp) / "untrained.pl")
    mode = "greedy" if args.greedy else "sampled"
    print(f"{args.checkpoint} on {args.env}, {args.episodes} {mode} episodes from seed {args.seed}")
    print(f"armed_enemy_link: agent {trained}, untrained network on the same states {untrained}")


if __name__ == "__main__":
    main()
