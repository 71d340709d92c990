"""``neurosym probe``: which predicates each head's relations encode, and how selectively.

    neurosym probe --checkpoint ckpt.pt [--env rgw2] [--map FILE] [--env-option K=V]
        [--episodes 200] [--seed 0] [--sample|--greedy] --out DIR [--json] [--no-untrained]

Records the episodes (sampled by default: greedy episodes of a fixed map are
all the same one), fits the probes of :mod:`neurosym.meaning.probe` and writes
into ``--out``:

* ``kb.pl`` -- ``probe(Head, J, Predicate, Accuracy, Control)``,
  ``probe_untrained/5``, ``probe_skipped(Predicate, Reason)``, ``kb_meta/2``;
* ``probes.parquet`` -- the table (head, relation, predicate, accuracy, control,
  selectivity, the untrained network's three, positive_rate, states);
* ``probes_skipped.parquet`` -- predicates that could not be probed, with why.

``--json`` prints one JSON object per probe instead of the summary.
``neurosym plot probes --probe DIR --out probes.png`` draws the table.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from neurosym.cli import agent_env
from neurosym.errors import ConfigError
from neurosym.flags import ActionMode, EnvChoice, Episodes, Json, Out, add_options, option


@dataclass(kw_only=True)
class ProbeOptions(EnvChoice, Episodes, ActionMode, Out, Json):
    """``neurosym probe``'s options."""

    checkpoint: str = option(metavar="FILE")
    """trained agent: a checkpoint (.pt) or a shipped agent's name, FILE.py:FUNCTION (your PyTorch module) or a Stable-Baselines3 .zip"""
    untrained: bool = True
    """also probe the untrained network (the baseline of each probe)"""
    solver: Literal["batched", "sklearn"] = "batched"
    """batched Newton fits, or one scikit-learn fit per probe (slow)"""
    episodes: int = 200
    """episodes to record"""
    greedy: bool = False
    """take the most likely action (greedy episodes of a fixed map are all the same one)"""
    out: str = option(metavar="DIR")
    """output folder"""
    json: bool = False
    """print one JSON object per probe"""


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the probe options."""
    add_options(parser, ProbeOptions)


def run(args: ProbeOptions) -> int:
    """Validate, record, probe, write, print."""
    from neurosym.meaning.output import check_out, publish

    if args.episodes < 2:
        raise ConfigError(
            f"--episodes must be at least 2 (probes hold episodes out), got {args.episodes}"
        )
    from neurosym.seeds import check_seed

    check_seed(args.seed, args.episodes)
    out = check_out(Path(args.out))

    from neurosym.agent.agent import load_agent
    from neurosym.envs import canonical_name
    from neurosym.meaning.probe import probe

    env = canonical_name(args.env) if args.env else None
    agent = load_agent(args.checkpoint, env=env)
    env, env_kwargs = agent_env(agent, env, args.env_option, args.map)
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
