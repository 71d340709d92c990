"""``neurosym probe``: which predicates each head's relations encode, and how selectively.

    neurosym probe --checkpoint ckpt.pt [--env rgw2] [--env-option K=V] [--episodes 200] [--seed 0]
        [--sample|--greedy] --out DIR [--json] [--no-untrained]

Records the episodes (sampled by default: greedy episodes of a fixed map are
all the same one), fits the probes of :mod:`neurosym.meaning.probe` and writes
into ``--out``:

* ``kb.pl`` -- ``probe(Head, J, Predicate, Accuracy, Control)``,
  ``probe_untrained/5``, ``probe_skipped(Predicate, Reason)``, ``kb_meta/2``;
* ``probes.parquet`` -- the table (head, relation, predicate, accuracy, control,
  selectivity, the untrained network's three, positive_rate, states);
* ``probes_skipped.parquet`` -- predicates that could not be probed, with why.

``--json`` prints one JSON object per probe instead of the summary.
``neurosym plot probes --probes DIR --out probes.png`` draws the table.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from neurosym.cli import add_env_option, play_env
from neurosym.errors import ConfigError


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the probe options."""
    parser.add_argument("--checkpoint", required=True, metavar="FILE", help="trained agent (.pt)")
    parser.add_argument(
        "--env",
        metavar="NAME",
        help="environment, e.g. rgw2: any of the checkpoint's family with its observation "
        "shape (default: the checkpoint's own)",
    )
    add_env_option(parser)
    parser.add_argument(
        "--episodes", type=int, default=200, metavar="N", help="episodes to record (default: 200)"
    )
    parser.add_argument(
        "--seed", type=int, default=0, metavar="S", help="episode k uses seed S + k (default: 0)"
    )
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument(
        "--sample",
        dest="greedy",
        action="store_false",
        default=False,
        help="sample actions from the policy (default: varied episodes)",
    )
    mode.add_argument("--greedy", dest="greedy", action="store_true", help="most likely action")
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder")
    parser.add_argument("--json", action="store_true", help="print one JSON object per probe")
    parser.add_argument(
        "--no-untrained",
        dest="untrained",
        action="store_false",
        help="skip the untrained network's probes",
    )
    parser.add_argument(
        "--solver",
        choices=("batched", "sklearn"),
        default="batched",
        help="batched Newton fits (default) or one scikit-learn fit per probe (slow)",
    )


def run(args: argparse.Namespace) -> int:
    """Validate, record, probe, write, print."""
    from neurosym.meaning.output import check_out, publish

    if args.episodes < 2:
        raise ConfigError(
            f"--episodes must be at least 2 (probes hold episodes out), got {args.episodes}"
        )
    from neurosym.seeds import check_seed

    check_seed(args.seed, args.episodes)
    out = check_out(Path(args.out))

    from neurosym.agent.checkpoint import load_agent
    from neurosym.envs import canonical_name
    from neurosym.meaning.probe import probe

    env = canonical_name(args.env) if args.env else None
    agent = load_agent(args.checkpoint, env=env)
    env, env_kwargs = play_env(agent, env, args.env_option)
    report = probe(
        agent,
        env,
        env_kwargs=env_kwargs,
        episodes=args.episodes,
        seed=args.seed,
        greedy=args.greedy,
        progress=sys.stderr.isatty(),
        untrained=args.untrained,
        solver=args.solver,
    )
    written = publish(
        out,
        {
            "kb.pl": report.to_prolog,
            "probes.parquet": lambda p: report.table.to_parquet(p, index=False),
            "probes_skipped.parquet": lambda p: report.skipped.to_parquet(p, index=False),
        },
    )
    if args.json:
        for row in report.table.to_dict(orient="records"):
            print(json.dumps({k: _plain(v) for k, v in row.items()}))
        return 0
    print_summary(report, written)
    return 0


def _plain(value: object) -> object:
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, float) and value != value:
        return None
    return value


def print_summary(report, written: dict[str, Path]) -> None:  # noqa: ANN001 (a ProbeReport)
    """Per head: the most selective predicates of the whole vector and of single relations."""
    from neurosym.display import plain

    m = report.meta
    mode = "greedy" if m.get("greedy") else "sampled"
    print(
        f"{plain(m['env'])} {plain(m['module'])}: {m['episodes']} episodes ({mode}, seed {m['seed']}), "
        f"{m['states']} states; {m['probed']} of {m['predicates']} predicates probed "
        f"({len(report.skipped)} skipped, see probe_skipped/2)"
    )
    t = report.table
    if t.empty:
        print("no predicate varied on these states: nothing to probe", file=sys.stderr)
    for h in sorted(t["head"].unique()):
        rows = t[t["head"] == h].sort_values(["selectivity", "accuracy"], ascending=False)
        best = rows.head(3)
        parts = [
            f"{plain(r.predicate)} r({plain(r.relation)}) acc {r.accuracy:.2f} ctl {r.control:.2f} "
            f"sel {r.selectivity:+.2f}"
            + ("" if r.untrained_selectivity != r.untrained_selectivity
               else f" (untrained sel {r.untrained_selectivity:+.2f})")
            for r in best.itertuples()
        ]  # fmt: skip
        print(f"head {h}: " + "; ".join(parts))
    for name, path in sorted(written.items(), key=lambda item: item[0] != "kb.pl"):
        print(f"wrote {plain(path)}" if name == "kb.pl" else f"      {plain(path)}")
