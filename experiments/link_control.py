"""A rule's answer over an agent's KB beside its answer over an untrained network's facts on the same states.

    python experiments/link_control.py checkpoints/rgw-random-predinet-bottleneck.pt \
        --env rgw2 --rules rgw --goal 'armed_enemy_link(A)' [--episodes 20] [--seed 0] [--greedy]
    python experiments/link_control.py runs/bw2-bottleneck.pt --env bw2 --rules boxworld \
        --goal 'key_lock_link(C, A)' --episodes 100 --seed 3000000000

Records the agent's episodes (sampled unless ``--greedy``) and writes their KB, and a second
KB of the same states whose network facts are those of a freshly initialised network of the
same ModelConfig (neurosym.record.faithfulness.ControlledAgent: the trained network acts, the
untrained one is introspected; each at the agent's own threshold spec). Prints every answer
of ``--goal`` over both, each variable's value as Prolog writes it.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from neurosym.agent.agent import load_agent
from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.record.extraction import extract
from neurosym.record.faithfulness import ControlledAgent, untrained_agent
from neurosym.shipped import rule_file


def answers(agent: object, args: argparse.Namespace, where: Path) -> list[str]:
    """``--goal``'s answers over ``agent``'s KB of ``args``' episodes, one line each."""
    got = extract(agent, args.env, episodes=args.episodes, seed=args.seed,
                  greedy=args.greedy, faithfulness=False)  # fmt: skip
    got.facts.to_prolog(where)
    with KnowledgeBase(where, rules=[rule_file(args.rules)]) as kb:
        rows = kb.query(args.goal)
    return [", ".join(f"{k} = {v}" for k, v in row.items()) for row in rows]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint")
    parser.add_argument("--env")
    parser.add_argument("--rules", required=True, help="a shipped rule file's name or a path")
    parser.add_argument("--goal", required=True)
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--greedy", action="store_true")
    args = parser.parse_args()
    agent = load_agent(args.checkpoint)
    with tempfile.TemporaryDirectory() as tmp:
        trained = answers(agent, args, Path(tmp) / "agent.pl")
        control = ControlledAgent(agent, untrained_agent(agent))
        untrained = answers(control, args, Path(tmp) / "untrained.pl")
    mode = "greedy" if args.greedy else "sampled"
    env = args.env or agent.env_name
    print(f"{args.checkpoint} on {env}, {args.episodes} {mode} episodes from seed {args.seed}: {args.goal}")
    for who, rows in (("agent", trained), ("untrained network, same states", untrained)):
        print(f"{who}:")
        for row in rows or ["(no answer)"]:
            print(f"  {row}")


if __name__ == "__main__":
    main()
