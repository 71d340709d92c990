"""``neurosym intervene``: controlled experiments on the level and on the heads.

    neurosym intervene --checkpoint ckpt.pt [--env rgw2] [--map FILE] [--env-option K=V]
        [--episodes 100] [--seed 0]
        [--sample|--greedy] --out DIR [--no-levels] [--no-ablations] [--json]

Plays the unchanged level and every experiment of
:mod:`neurosym.meaning.intervene` with the same seeds (sampled actions by
default, so rates mean something; greedy episodes of a fixed map are all one
episode) and writes into ``--out``:

* ``kb.pl`` -- ``experiment/3``, ``experiment_episode/2``, ``measure/3``,
  ``effect/3``, ``relates/4``, ``experiment_skipped/2`` and the trace facts of
  every experiment's episodes (ids offset per experiment, never colliding);
* ``effects.parquet``, ``measures.parquet`` -- the same numbers as tables.

It prints the measures per experiment and the answer of
``sword_enemy_cause/1`` (rules/causal.pl) over the written KB.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path

from neurosym.cli import agent_env
from neurosym.errors import ConfigError
from neurosym.flags import ActionMode, EnvChoice, Episodes, Json, Out, add_options, option


@dataclass(kw_only=True)
class InterveneOptions(EnvChoice, Episodes, ActionMode, Out, Json):
    """``neurosym intervene``'s options."""

    checkpoint: str = option(metavar="FILE")
    """trained agent: a checkpoint (.pt) or a shipped agent's name, FILE.py:FUNCTION (your PyTorch module) or a Stable-Baselines3 .zip"""
    levels: bool = True
    """run the level changes (remove the sword, the enemy; swap them)"""
    ablations: bool = True
    """run the head ablations"""
    episodes: int = 100
    """episodes per experiment"""
    greedy: bool = False
    """take the most likely action"""
    out: str = option(metavar="DIR")
    """output folder"""
    json: bool = False
    """print one JSON object per measure and effect"""


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the intervene options."""
    add_options(parser, InterveneOptions)


def run(args: InterveneOptions) -> int:
    """Validate, run the experiments, write, print."""
    from neurosym.meaning.output import check_out, publish

    if args.episodes < 1:
        raise ConfigError(f"--episodes must be at least 1, got {args.episodes}")
    from neurosym.seeds import check_seed

    check_seed(args.seed, args.episodes)
    out = check_out(Path(args.out))

    from neurosym.agent.agent import load_agent
    from neurosym.envs import canonical_name
    from neurosym.meaning.intervene import intervene

    env = canonical_name(args.env) if args.env else None
    agent = load_agent(args.checkpoint, env=env)
    env, env_kwargs = agent_env(agent, env, args.env_option, args.map)
    if env_kwargs.get("edit") is not None:
        raise ConfigError(
            f"--env-option edit={env_kwargs['edit']}: intervene makes the level edits itself "
            "(remove(sword), remove(enemy), swap(sword, enemy)); play an edited level with eval"
        )
    report = intervene(
        agent,
        env,
        env_kwargs=env_kwargs,
        episodes=args.episodes,
        seed=args.seed,
        greedy=args.greedy,
        progress=sys.stderr.isatty(),
        levels=args.levels,
        ablations=args.ablations,
    )
    written = publish(
        out,
        {
            "kb.pl": report.to_prolog,
            "measures.parquet": lambda p: report.measures.to_parquet(p, index=False),
            "effects.parquet": lambda p: report.effects.to_parquet(p, index=False),
        },
    )
    if args.json:
        for kind, df in (("measure", report.measures), ("effect", report.effects)):
            for row in df.itertuples(index=False):
                print(json.dumps({"kind": kind, "experiment": row.experiment,
                                  "measure": row.measure, "value": float(row.value)}))  # fmt: skip
        return 0
    print_summary(report, written)
    return 0


def _causal_rules() -> Path | None:
    from neurosym.reports.terminal import rules_dir

    folder = rules_dir()
    return folder / "causal.pl" if folder and (folder / "causal.pl").is_file() else None


def cause_answer(kb_path: Path) -> str | None:
    """``sword_enemy_cause/1``'s answer over the written KB, as Prolog text (None without rules)."""
    from neurosym.prolog.knowledge_base import KnowledgeBase

    rules = _causal_rules()
    if rules is None:
        return None
    with KnowledgeBase(kb_path, rules=[rules]) as kb:
        rows = kb.query("sword_enemy_cause(A), format(atom(T), '~q', [A])")
    return str(rows[0]["T"]) if rows else None


def print_summary(report, written: dict[str, Path]) -> None:  # noqa: ANN001 (an InterventionReport)
    """The measures per experiment, the skipped ones, and the causal answer (RGW)."""
    from neurosym.display import plain

    m = report.meta
    mode = "greedy" if m["greedy"] else "sampled"
    print(
        f"{plain(m['env'])} {plain(m['module'])}: {len(report.experiments)} experiments x {m['episodes']} "
        f"episodes ({mode}, seed {m['seed']})"
    )
    table = report.measures.pivot(index="experiment", columns="measure", values="value")
    order = [e.id for e in report.experiments]
    table = table.reindex(order)
    cols = [c for c in ("return", "success", "sword_before_enemy", "enemy_met", "enemy_unarmed")
            if c in table]  # fmt: skip
    kl = report.effects[report.effects["measure"] == "kl"].set_index("experiment")["value"]
    print(f"{'experiment':<18} {'kind':<24} " + " ".join(f"{c:>18}" for c in cols) + f" {'kl':>9}")
    for exp in report.experiments:
        row = table.loc[exp.id]
        kl_text = f"{kl[exp.id]:9.4f}" if exp.id in kl.index else " " * 9
        print(
            f"{plain(exp.id):<18} {plain(exp.kind):<24} "
            + " ".join(f"{row[c]:18.3f}" for c in cols)
            + f" {kl_text}"
        )
    for kind, reason in report.skipped:
        print(f"skipped {plain(kind)}: {plain(reason)}")
    if "kb.pl" in written and m["env"].startswith("rgw"):
        answer = cause_answer(written["kb.pl"])
        if answer is not None:
            print(f"sword_enemy_cause: {plain(answer)}")
        elif _causal_rules() is None:
            print("sword_enemy_cause: not asked (the shipped rule file causal.pl is missing)")
    for name, path in sorted(written.items(), key=lambda item: item[0] != "kb.pl"):
        print(f"wrote {plain(path)}" if name == "kb.pl" else f"      {plain(path)}")
