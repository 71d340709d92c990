"""Controlled experiments: play the unchanged level and changed ones with the same seeds.

An experiment changes one thing and says which (``experiment(X, Kind,
Detail)``):

=============================  =================================================
``baseline``                   the unchanged level
``remove(sword)``              the sword's cell emptied
``remove(enemy)``              the enemy's cell emptied
``move(enemy, R, C)``          the enemy off the route: the free cell nearest to
                               it that no baseline episode stood on
``move(sword, R, C)``          the sword behind the enemy: the free cell off the
                               routes nearest to the enemy and farther from the
                               start (Detail says ``near`` when none is farther)
``swap(sword, enemy)``         the two cells exchanged
``ablate(head(H))``            head H's R vector (MHDPA: its output) replaced by
                               its mean over the baseline episodes' states
``ablate(heads)``              every head at once: what the policy does with no
                               state-dependent relational input
=============================  =================================================

Level changes are made to a fixed RGW map (rgw1, rgw2, a map given as an
env option) or, on rgw-random, to every episode's own level (env option
``edit``: ``remove(sword)``, ``remove(enemy)``, ``swap(sword, enemy)``, with
Detail ``every_level(Edit)``; the moves need one map's routes and are
skipped); on Box-World only the ablations run (what is skipped is listed as
``experiment_skipped(Kind, Reason)``). Every experiment
plays the same episodes: episode k from ``reset(seed=seed + k)`` and, when
sampling, the same torch generator seed, so the baseline and a change differ
only by the change.

Measures (``measure(X, M, V)``, absolute, per experiment): ``return``,
``success``, ``steps``; RGW also ``sword_picked``, ``enemy_met``,
``enemy_unarmed`` (met without the sword), ``enemy_defeated`` and
``sword_before_enemy`` (shares of episodes). ``effect(X, M, V)`` is measure
minus the baseline's, plus, at the baseline's own states (the same agent cell
and holding, the changed cells redrawn as the changed level shows them; for
ablations the same observations): ``kl`` (mean KL(baseline || experiment) of
the action distributions), ``relation_shift(H, J)`` (PrediNet: mean |change|
of D^h_j) or ``head_shift(H)`` (MHDPA: mean L2 change of the head's pooled
output). ``relates(H, A, B, Share)``: in the baseline, the share of states at
which head H relates A and B (PrediNet: attends the pair; MHDPA: one's
strongest key is the other), which rules/causal.pl uses to tell whether an
ablated head related sword and enemy.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import functools
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from neurosym.agent.networks.adapters import adapter_class
from neurosym.errors import ConfigError
from neurosym.facts.schema import TRACE, group
from neurosym.terms import Term

DEFAULT_EPISODES = 100
"""episodes per experiment by default (sampled actions, seeds S..S+99)"""

TRACE_TABLES = ("episodes", "grids", "terrain", "optimal", "steps", "positions", "holding", "events")

NETWORK_FACTS = tuple(p.name for p in group(TRACE) if "intervene" not in p.writers)
"""the trace predicates an experiment KB leaves out (:mod:`neurosym.facts.schema`: those intervene does
not write): what the network computed, per state"""


@dataclass(frozen=True)
class Experiment:
    """One experiment: its id, what it changes, and how."""

    id: str
    """atom naming it in the facts: baseline, remove_sword, ablate_head_2, ..."""
    kind: Any
    """Term (or the atom ``baseline``) for experiment/3's Kind"""
    detail: Any
    """Term or atom for experiment/3's Detail"""
    map_text: str | None = None
    """the changed map (None: the baseline's level)"""
    ablate: tuple[int, ...] = ()
    """heads replaced by their baseline mean"""
    edit: str | None = None
    """procedural levels: the change made to every level (RandomLevelConfig.edit)"""


@dataclass
class InterventionReport:
    """What the experiments did: the experiments, their measures and effects, their episodes."""

    experiments: list[Experiment]
    measures: pd.DataFrame
    """``experiment, measure, value`` (measure as Prolog text)"""
    effects: pd.DataFrame
    """``experiment, measure, value``: change against the baseline"""
    relates: pd.DataFrame
    """``head, a, b, share``"""
    recordings: dict[str, Any]
    """experiment id -> its Recording (episode ids already offset)"""
    skipped: list[tuple[str, str]] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)

    def episode_offset(self, experiment: str) -> int:
        return int(self.meta["episode_stride"]) * [e.id for e in self.experiments].index(experiment)

    def facts(self) -> dict[str, pd.DataFrame]:
        """Tables for the Prolog writer (see :meth:`to_prolog`)."""
        from neurosym.facts.tables import extract_facts
        from neurosym.record.recording import Recording

        merged = Recording(
            **{
                name: pd.concat(
                    [getattr(r, name) for r in self.recordings.values()], ignore_index=True
                )
                for name in TRACE_TABLES
            },
            meta=self.recordings["baseline"].meta,
        )
        trace = extract_facts(merged).prolog_tables()
        for name in NETWORK_FACTS:
            trace.pop(name, None)
        meta = trace.pop("kb_meta")
        meta = meta[meta["key"] != "threshold"]
        extra = pd.DataFrame(
            {
                "key": list(self.meta),
                "value": pd.Series([self.meta[k] for k in self.meta], dtype=object),
            }
        )
        meta = pd.concat([meta[~meta["key"].isin(extra["key"])], extra], ignore_index=True)
        ep_rows = [
            (e.id, int(ep))
            for e in self.experiments
            for ep in self.recordings[e.id].episodes["episode"].tolist()
        ]
        return {
            "kb_meta": meta,
            **trace,
            "experiment": pd.DataFrame(
                {
                    "x": [e.id for e in self.experiments],
                    "kind": pd.Series([e.kind for e in self.experiments], dtype=object),
                    "detail": pd.Series([e.detail for e in self.experiments], dtype=object),
                }
            ),
            "experiment_episode": pd.DataFrame(ep_rows, columns=["x", "episode"]),
            "experiment_skipped": pd.DataFrame(
                {
                    "kind": pd.Series([_term_of(k) for k, _ in self.skipped], dtype=object),
                    "reason": [r for _, r in self.skipped],
                }
            ),
            "measure": self.measures.assign(
                measure=pd.Series([_term_of(m) for m in self.measures["measure"]], dtype=object)
            ),
            "effect": self.effects.assign(
                measure=pd.Series([_term_of(m) for m in self.effects["measure"]], dtype=object)
            ),
            "relates": self.relates.loc[:, ["head", "a", "b", "share"]],
        }

    def to_prolog(self, path: str | os.PathLike[str]) -> Path:
        """Write the KB: trace facts of every experiment's episodes plus the experiment facts."""
        from neurosym.facts.prolog_writer import write_prolog
        from neurosym.facts.schema import indicators, term_columns, written_by

        tables = self.facts()
        header = (
            "neurosym experiments: the unchanged level and changed ones, same seeds"
            " (neurosym intervene).\n"
            + ", ".join(f"{k}={v}" for k, v in self.meta.items())
            + "\nexperiment(X, Kind, Detail), experiment_episode(X, E), experiment_skipped(Kind,"
            " Reason),\nmeasure(X, Measure, Value), effect(X, Measure, Change), relates(Head, A,"
            " B, Share),\nand the trace facts (episode/4, grid/3, terrain/4, step/4, at/5,"
            " holding/3, event/3) of every experiment."
        )
        # the network's facts: none here, rules may ask for them
        names = [p.name for p in written_by("intervene")] + list(NETWORK_FACTS)
        return write_prolog(
            Path(path), tables, header=header, dynamic=indicators(names),
            term_columns=term_columns(tables),
        )


def _term_of(text: Any) -> Any:
    """Measure/kind text -> Term (atoms stay str)."""
    from neurosym.terms import parse_term

    return parse_term(text) if isinstance(text, str) else text


# ------------------------------------------------------------------ experiments


def _cells_term(changes: tuple[Any, ...]) -> Term:
    return Term("cells", (tuple(Term("cell", (c.row, c.col, c.before, c.after)) for c in changes),))


def level_experiments(grid_map: Any, route: np.ndarray) -> tuple[list[Experiment], list]:
    """The level changes for a fixed map (module docstring); (experiments, skipped)."""
    from neurosym.meaning import levels

    out: list[Experiment] = []
    skipped: list[tuple[str, str]] = []

    def add(ident: str, kind: Any, level: Any, how: str | None = None) -> None:
        detail = _cells_term(level.changes)
        if how is not None:
            detail = Term(how, (detail,))
        out.append(Experiment(ident, kind, detail, level.text))

    has = {o: _count(grid_map, o) == 1 for o in ("sword", "enemy")}
    for obj in ("sword", "enemy"):
        if has[obj]:
            add(f"remove_{obj}", Term("remove", (obj,)), levels.remove(grid_map, obj))
        else:
            skipped.append((f"remove({obj})", f"the map has {_count(grid_map, obj)} {obj} cells"))
    if has["enemy"]:
        cell = off_route_enemy = levels.off_route_cell(
            grid_map, levels.cell_of(grid_map, "enemy"), route
        )
        if cell is not None:
            add(
                "move_enemy",
                Term("move", ("enemy", *off_route_enemy)),
                levels.move(grid_map, "enemy", *cell),
                "off_route",
            )
        else:
            skipped.append(("move(enemy)", "every free cell is on a baseline route"))
    if has["sword"] and has["enemy"]:
        found = levels.behind_cell(grid_map, "enemy", route)
        if found is not None:
            (r, c), how = found
            add(
                "move_sword",
                Term("move", ("sword", r, c)),
                levels.move(grid_map, "sword", r, c),
                f"{how}_enemy",
            )
        else:
            skipped.append(("move(sword)", "no free cell off the baseline routes"))
        add(
            "swap_sword_enemy",
            Term("swap", ("sword", "enemy")),
            levels.swap(grid_map, "sword", "enemy"),
        )
    else:
        skipped.append(("swap(sword,enemy)", "the map lacks a single sword and enemy"))
    return out, skipped


def procedural_experiments(env_kwargs: dict[str, Any]) -> tuple[list[Experiment], list]:
    """The level changes for rgw-random: each made to every episode's own level; (experiments, skipped).

    Episode k plays level (seed + k, 0) with the one change, so it differs
    from the baseline's episode k only by it. Moving an object needs routes
    on one map, so the moves are skipped.
    """
    from neurosym.envs.rgw_random import RandomLevelConfig, config_from_kwargs

    level_keys = {f.name for f in dataclasses.fields(RandomLevelConfig)}
    cfg = config_from_kwargs({k: v for k, v in env_kwargs.items() if k in level_keys})
    out: list[Experiment] = []
    for edit, kind in (
        ("remove_sword", Term("remove", ("sword",))),
        ("remove_enemy", Term("remove", ("enemy",))),
        ("swap_sword_enemy", Term("swap", ("sword", "enemy"))),
    ):
        if edit == "swap_sword_enemy" and cfg.num_enemies != 1:
            continue
        out.append(Experiment(edit, kind, Term("every_level", (edit,)), edit=edit))
    skipped = [
        (kind, "moving an object needs the baseline's routes on one fixed map")
        for kind in ("move(enemy)", "move(sword)")
    ]
    if cfg.num_enemies != 1:
        skipped.append(("swap(sword,enemy)", f"the levels have {cfg.num_enemies} enemies"))
    return out, skipped


def _count(grid_map: Any, obj: str) -> int:
    from neurosym.meaning.levels import SYMBOL_OF

    return int(("".join(grid_map.text().splitlines())).count(SYMBOL_OF[obj]))


def ablation_experiments(heads: int, module: str) -> list[Experiment]:
    """Each head ablated in turn, then all of them; none for a network without heads (an
    outside agent whose attention nobody named)."""
    if heads < 1:
        return []
    what = adapter_class(module).head_term
    detail = Term("replaced", (what, Term("mean_over", ("baseline",))))
    out = [
        Experiment(f"ablate_head_{h}", Term("ablate", (Term("head", (h,)),)), detail, ablate=(h,))
        for h in range(heads)
    ]
    out.append(
        Experiment("ablate_heads", Term("ablate", ("heads",)), detail, ablate=tuple(range(heads)))
    )
    return out


# ------------------------------------------------------------------ measures


def behaviour(recording: Any, family: str) -> dict[str, float]:
    """Absolute measures of one experiment's episodes (module docstring)."""
    from neurosym.agent.rollout import SUCCESS_OUTCOMES

    eps = recording.episodes
    n = max(len(eps), 1)
    out = {
        "return": float(eps["return"].mean()),
        "success": float(eps["outcome"].isin(SUCCESS_OUTCOMES).sum() / n),
        "steps": float(eps["steps"].mean()),
    }
    if family != "rgw":
        return out
    ev = recording.events
    first = ev.groupby(["episode", "event"])["t"].min().unstack()  # (episodes, events)
    first = first.reindex(eps["episode"])

    def col(name: str) -> np.ndarray:
        if name in first:
            return first[name].to_numpy(dtype=np.float64)
        return np.full(len(first), np.nan)

    picked = col("picked(sword)")
    met = np.fmin(col("defeated(enemy)"), col("hurt_by(enemy)"))
    out.update(
        sword_picked=float(np.isfinite(picked).sum() / n),
        enemy_met=float(np.isfinite(met).sum() / n),
        enemy_unarmed=float(np.isfinite(col("hurt_by(enemy)")).sum() / n),
        enemy_defeated=float(np.isfinite(col("defeated(enemy)")).sum() / n),
        sword_before_enemy=float(
            (np.isfinite(picked) & np.isfinite(met) & (picked < met)).sum() / n
        ),
    )
    return out


def relates_table(recording: Any, module: str) -> pd.DataFrame:
    """``head, a, b, share``: share of the baseline's states at which head H relates A and B.

    Unordered pairs of different entities, a before b alphabetically, shares > 0.
    """
    states = max(int(recording.episodes["steps"].sum()), 1)
    if adapter_class(module).has("attends"):
        att = recording.attends
        wide = att.pivot_table(
            index=["episode", "t", "head"], columns="arg", values="entity", aggfunc="first"
        ).reset_index()
        if wide.empty:
            return pd.DataFrame(columns=["head", "a", "b", "share"])
        a = wide[1].astype(str).to_numpy()
        b = wide[2].astype(str).to_numpy()
        pairs = pd.DataFrame(
            {"head": wide["head"].to_numpy(), "a": np.minimum(a, b), "b": np.maximum(a, b)}
        )
        pairs["episode"], pairs["t"] = wide["episode"].to_numpy(), wide["t"].to_numpy()
    else:
        att = recording.attention
        q = att["query"].astype(str).to_numpy()
        k = att["key"].astype(str).to_numpy()
        pairs = pd.DataFrame({"head": att["head"].to_numpy(), "a": np.minimum(q, k), "b": np.maximum(q, k),
                              "episode": att["episode"].to_numpy(), "t": att["t"].to_numpy()})  # fmt: skip
    pairs = pairs[pairs["a"] != pairs["b"]].drop_duplicates(["episode", "t", "head", "a", "b"])
    table = pairs.groupby(["head", "a", "b"]).size().rename("count").reset_index()
    table["share"] = table["count"] / states
    return (
        table.loc[:, ["head", "a", "b", "share"]]
        .sort_values(["head", "a", "b"])
        .reset_index(drop=True)
    )


def matched_observations(
    obs: np.ndarray, base_text: str, changed_text: str, env: str, env_kwargs: dict[str, Any]
) -> np.ndarray:
    """The baseline's states as the changed level shows them: the same agent cell and holding.

    A cell the level change touched is redrawn as the changed level's first
    observation shows it, where the state still shows it as the baseline's
    first observation did (the agent is not on it and the baseline episode has
    not taken its object yet); every other cell is kept.
    """
    first_base = _first_observation(env, {**env_kwargs, "map": base_text}, 0)
    first_changed = _first_observation(env, {**env_kwargs, "map": changed_text}, 0)
    out = obs.copy()
    _redraw(out, np.arange(len(obs)), first_base, first_changed)
    return out


def matched_procedural_observations(
    obs: np.ndarray, recording: Any, edit: str, env: str, env_kwargs: dict[str, Any]
) -> np.ndarray:
    """As :func:`matched_observations`, episode by episode: each baseline state gets its own
    level's change (the level of the episode's seed, with and without ``edit``)."""
    from neurosym.meaning.predicates import acted_states

    eps = recording.episodes
    of_state = acted_states(eps)["episode"].to_numpy()
    out = obs.copy()
    for episode, seed in zip(eps["episode"].tolist(), eps["seed"].tolist(), strict=True):
        first_base = _first_observation(env, env_kwargs, int(seed))
        first_changed = _first_observation(env, {**env_kwargs, "edit": edit}, int(seed))
        _redraw(out, np.flatnonzero(of_state == episode), first_base, first_changed)
    return out


def _first_observation(env: str, env_kwargs: dict[str, Any], seed: int) -> np.ndarray:
    from neurosym.envs import make

    env_ = make(env, **env_kwargs)
    try:
        return env_.reset(seed=seed)[0]
    finally:
        env_.close()


def _redraw(
    out: np.ndarray, states: np.ndarray, first_base: np.ndarray, first_changed: np.ndarray
) -> None:
    """Cells that differ between the two first observations, redrawn at ``states`` that still show
    them as the baseline's first observation did (the agent not on them, the object not taken)."""
    differs = (first_base != first_changed).any(axis=0)  # (H, W) the changed cells
    rows, cols = np.nonzero(differs)
    for r, c in zip(rows.tolist(), cols.tolist(), strict=True):  # a handful of cells
        as_before = (out[states, :, r, c] == first_base[:, r, c]).all(axis=1)  # (s,)
        out[states[as_before], :, r, c] = first_changed[:, r, c]


def _kl(p: np.ndarray, q: np.ndarray) -> float:
    eps = 1e-12
    return float(np.mean(np.sum(p * (np.log(p + eps) - np.log(q + eps)), axis=1)))


# ------------------------------------------------------------------ running


def intervene(
    agent: Any,
    env: str | None = None,
    episodes: int = DEFAULT_EPISODES,
    seed: int = 0,
    greedy: bool = False,
    *,
    levels: bool = True,
    ablations: bool = True,
    batch: int | None = None,
    progress: bool = False,
    env_kwargs: dict[str, Any] | None = None,
) -> InterventionReport:
    """Play the baseline and every experiment on the batched env; measure what changed.

    ``env``: any env of the agent's family with its observation shape (default:
    its own); ``env_kwargs``: options on top of the agent's (every experiment
    plays them, with its own change on top). ``progress``: bars on stderr.
    """
    from neurosym.envs import env_family
    from neurosym.meaning.features import head_means, head_vectors, replay_observations
    from neurosym.progress import Stages
    from neurosym.record.recorder import _resolve_env

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"episodes must be a positive integer, got {episodes!r}")
    name, env_kwargs = _resolve_env(agent, env, env_kwargs)
    run = _Run(agent, name, dict(env_kwargs), env_family(name), episodes, seed, greedy,
               # one wave per experiment where it fits: waves of the recorder's default 64
               # leave the model running on small batches (the cost is the forward pass)
               batch or min(episodes, 256))  # fmt: skip
    with Stages(progress) as stages:
        baseline = Experiment("baseline", "baseline", "unchanged")
        stages.stage("experiment baseline", 1)
        recs = {"baseline": run.play(baseline, 0, None)}
        with _one_thread():
            base_obs = replay_observations(_shifted(recs["baseline"], 0), name, run.env_kwargs)
            base = _Base(recs["baseline"], base_obs, *head_vectors(agent.model, base_obs),
                         head_means(agent.model, base_obs), None)  # fmt: skip
        found, skipped, base.text = _plan_experiments(run, recs["baseline"], levels)
        experiments = [baseline, *found]
        if ablations:
            experiments += ablation_experiments(int(agent.config.heads), agent.config.module)
        advance = stages.stage("experiments", len(experiments))
        advance(1)  # the baseline
        for index, exp in enumerate(experiments[1:], start=1):
            stages.describe(f"experiment {exp.id}")
            recs[exp.id] = run.play(exp, index, base.means)
            advance(1)
        advance = stages.stage("effects at the baseline's states", len(experiments) - 1)
        m_rows, e_rows = _measures(run, experiments, recs, base, advance)
    return InterventionReport(
        experiments=experiments,
        measures=pd.DataFrame(m_rows, columns=["experiment", "measure", "value"]),
        effects=pd.DataFrame(e_rows, columns=["experiment", "measure", "value"]),
        relates=relates_table(recs["baseline"], agent.config.module),
        recordings=recs,
        skipped=skipped,
        meta=run.meta(),
    )


@contextlib.contextmanager
def _one_thread() -> Any:
    """torch on one thread for the head-vector passes (batches of states, many small ops)."""
    import torch

    saved = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(saved)


@dataclasses.dataclass
class _Base:
    """The baseline's recording, its observations replayed, head vectors, policy and means."""

    rec: Any
    obs: Any
    vec: np.ndarray
    p: Any
    means: dict
    text: str | None  # the fixed map's text (level changes on fixed maps), else None


@dataclasses.dataclass
class _Run:
    """What every experiment of one call plays: the agent, env, episodes and seeds."""

    agent: Any
    name: str
    env_kwargs: dict[str, Any]
    family: str
    episodes: int
    seed: int
    greedy: bool
    batch: int

    @property
    def stride(self) -> int:
        """Episode ids of experiment i start at i * stride (ids stay apart in one KB)."""
        return 10 ** len(str(self.episodes - 1))

    def play(self, exp: Experiment, index: int, base_means: dict | None) -> Any:
        """Record ``exp``: its level change goes in as an option of the env played (not as the
        agent's own options, which another env than the agent's would not carry over)."""
        from neurosym.meaning.features import ablate_heads
        from neurosym.record.recorder import record

        kwargs = self.env_kwargs
        if exp.map_text is not None:
            kwargs = {**kwargs, "map": exp.map_text}
        elif exp.edit is not None:
            kwargs = {**kwargs, "edit": exp.edit}
        play_one = functools.partial(
            record, self.agent, self.name, self.episodes, self.seed, self.greedy, self.batch,
            env_kwargs=kwargs,
        )  # fmt: skip
        if exp.ablate:
            with ablate_heads(self.agent.model, {h: base_means[h] for h in exp.ablate}):
                rec = play_one()
        else:
            rec = play_one()
        for table in TRACE_TABLES:
            df = getattr(rec, table)
            df["episode"] = df["episode"] + index * self.stride
        return rec

    def meta(self) -> dict[str, Any]:
        from neurosym import __version__
        from neurosym.envs import canonical_name

        module = self.agent.config.module
        return {
            "checkpoint": str(getattr(self.agent, "path", "") or ""),
            "env": canonical_name(self.name),
            "module": module,
            "heads": int(self.agent.config.heads),
            "relations": adapter_class(module).relation_count(self.agent.config),
            "episodes": int(self.episodes),
            "seed": int(self.seed),
            "greedy": bool(self.greedy),
            "episode_stride": int(self.stride),
            "created": _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
            "version": __version__,
        }


def _plan_experiments(
    run: _Run, base_rec: Any, levels: bool
) -> tuple[list[Experiment], list[tuple[str, str]], str | None]:
    """(level experiments, those skipped with why, the fixed map's text or None)."""
    from neurosym.envs.rgw_maps import load_map

    if not levels:
        return [], [], None
    if run.family == "rgw" and run.name != "rgw-random":
        grid_map = load_map(run.env_kwargs.get("map", run.name))
        route = np.zeros(grid_map.height * grid_map.width, dtype=bool)
        agent_pos = base_rec.positions[base_rec.positions["object"] == "agent"]
        route[agent_pos["row"].to_numpy() * grid_map.width + agent_pos["col"].to_numpy()] = True
        found, skipped = level_experiments(grid_map, route)
        return found, skipped, grid_map.text()
    if run.family == "rgw":  # rgw-random: each episode's own level, changed
        found, skipped = procedural_experiments(run.env_kwargs)
        return found, skipped, None
    reason = "level changes are RGW-only; Box-World levels are generated"
    return [], [("level_changes", reason)], None


def _measures(
    run: _Run, experiments: list[Experiment], recs: dict[str, Any], base: _Base, advance: Any
) -> tuple[list[tuple], list[tuple]]:
    """(measure rows, effect rows): behaviour of every experiment, and at the baseline's
    states the change of the policy (kl) and of each head's vectors."""
    m_rows, e_rows = [], []
    base_m = behaviour(base.rec, run.family)
    for exp in experiments:
        m = behaviour(recs[exp.id], run.family)
        for key, value in m.items():
            m_rows.append((exp.id, key, value))
            if exp.id != "baseline":
                e_rows.append((exp.id, key, value - base_m[key]))
        if exp.id == "baseline":
            continue
        with _one_thread():
            vec, p = _vectors_at_base_states(run, exp, base)
        advance(1)
        e_rows.append((exp.id, "kl", _kl(base.p, p)))
        e_rows += _shift_rows(run.agent, exp.id, vec, base.vec)
    return m_rows, e_rows


def _vectors_at_base_states(run: _Run, exp: Experiment, base: _Base) -> tuple[np.ndarray, Any]:
    """The heads' vectors and the policy under ``exp`` at the baseline's states."""
    from neurosym.meaning.features import ablate_heads, head_vectors

    model = run.agent.model
    if exp.ablate:
        with ablate_heads(model, {h: base.means[h] for h in exp.ablate}):
            return head_vectors(model, base.obs)
    if exp.edit is not None:
        obs = matched_procedural_observations(
            base.obs, _shifted(base.rec, 0), exp.edit, run.name, run.env_kwargs
        )
    else:
        obs = matched_observations(base.obs, base.text, exp.map_text, run.name, run.env_kwargs)
    return head_vectors(model, obs)


def _shift_rows(agent: Any, exp_id: str, vec: np.ndarray, base_vec: np.ndarray) -> list[tuple]:
    """How far each head's relations (PrediNet) or vector (MHDPA) moved, on average."""
    diff = vec.astype(np.float64) - base_vec.astype(np.float64)  # (S, H, D)
    J = adapter_class(agent.config.module).relation_count(agent.config)
    if J:
        shift = np.abs(diff[:, :, :J]).mean(axis=0)  # (H, J)
        return [
            (exp_id, f"relation_shift({h},{j})", float(shift[h, j]))
            for h in range(shift.shape[0])
            for j in range(J)
        ]
    norms = np.linalg.norm(diff, axis=2).mean(axis=0)  # (H,)
    return [(exp_id, f"head_shift({h})", float(norms[h])) for h in range(len(norms))]


def _shifted(rec: Any, offset: int) -> Any:
    """The recording with its episode ids moved back by ``offset`` (for replay)."""
    if offset == 0:
        return rec
    out = dataclasses.replace(rec)
    for table in TRACE_TABLES:
        df = getattr(rec, table).copy()
        df["episode"] -= offset
        setattr(out, table, df)
    return out
