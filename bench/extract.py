"""Recording, fact extraction and KB queries at scale; prints JSON lines.

Lines, in order:

* ``machine``: cores, load average, torch threads (figures are wall times on a
  machine that may be shared: compare with the load average);
* ``record``: steps per second recorded with introspection by
  :func:`neurosym.record` (batched env + model + table building), best and
  median of ``--repeat`` runs, beside the model's own forward rate with
  introspection at the same batch size (``agent.act`` alone), which bounds it;
* ``extract``: ``extract_facts`` time and the facts per second written by
  ``FactSet.to_prolog``;
* ``kb`` (one line per KB): a KB of N episodes made by replicating the recorded
  episodes with new episode numbers (the facts are real, the episodes repeat),
  written, loaded (consult through janus up to ``--consult-max`` episodes, and
  from .qlf), then ``sword_before_enemy(E)`` asked for all answers: ``first_ms``
  is the first call (SWI-Prolog builds its just-in-time indexes then), ``ms`` the
  median of later calls, counted in Prolog (``count``) and returned to Python
  (``query``). ``facts`` says which predicates the KB holds: ``trace``
  (episode/4, step/4, event/3, holding/3: what the behavioural rules read) or
  ``all`` (every schema predicate, also at/5 and the network facts, up to
  ``--full-max`` episodes).

The checkpoint defaults to the shipped ``checkpoints/rgw2-predinet.pt``; without
it an untrained default-size PrediNet introspects while the actions follow the
optimal route of Configuration-2 (``"policy": "route"``), so that the KBs hold
the events the rules ask about (sword, teleport, enemy, terminal).

    python bench/extract.py                       # 1k, 10k, 100k episodes
    python bench/extract.py --sizes 1000 --episodes 64     # quick
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from neurosym.facts.tables import PREDICATES, FactSet, extract_facts  # noqa: E402
from neurosym.record.recorder import record  # noqa: E402

TRACE = ("kb_meta", "object", "episode", "step", "event", "holding", "threshold")


def emit(**fields: Any) -> None:
    print(json.dumps(fields), flush=True)


def load_or_build_agent(path: Path, env: str) -> tuple[Any, str]:
    from neurosym.agent.agent import Agent, load_agent

    if path.is_file():
        return load_agent(path, env=env), str(
            path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
        )
    import torch

    from neurosym.agent.config import ModelConfig
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.envs import env_family, make

    probe = make(env)
    torch.manual_seed(0)
    cfg = ModelConfig.for_family(
        env_family(env), "predinet", probe.observation_space.shape, probe.unwrapped.obs_scale
    )
    return Agent(
        model=ActorCritic(cfg).eval(), config=cfg, env_name=env, env_kwargs={}, path=None
    ), "untrained"


# The optimal route of Configuration-2 (thesis figure 9): sword, teleport, enemy, terminal.
RGW2_ROUTE = [1] * 6 + [2] * 3 + [1] * 3 + [2] + [3] * 8


class RouteAgent:
    """Plays RGW2_ROUTE in every episode while the wrapped agent's model introspects.

    For KBs whose episodes hold the events the rules ask about when no trained
    checkpoint is at hand. Every episode of a wave ends at the same step, so
    the batch never shrinks and step k of the wave is step k of every episode.
    """

    def __init__(self, inner: Any) -> None:
        self.inner, self.step = inner, 0
        self.config, self.env_name, self.env_kwargs = inner.config, inner.env_name, inner.env_kwargs
        self.path = "optimal route"

    def act(
        self, obs: Any, greedy: bool = True, introspect: bool = False, generator: Any = None
    ) -> Any:
        _, intro = self.inner.act(obs, introspect=introspect)
        k = self.step % len(RGW2_ROUTE)
        self.step += 1
        return np.full(len(obs), RGW2_ROUTE[k], dtype=np.int64), intro


def model_rate(agent: Any, env: str, batch: int, repeats: int) -> tuple[float, float]:
    """Best and median steps per second of agent.act(introspect=True) alone on real observations,
    with the torch threads the recorder uses (one)."""
    import torch

    from neurosym.envs import make_batched

    venv = make_batched(env, batch, seed=0, **agent.env_kwargs)
    obs, _ = venv.reset(seed=0)
    saved = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        agent.act(obs, introspect=True)
        times = [timed(lambda: agent.act(obs, introspect=True))[1] for _ in range(10 * repeats)]
    finally:
        torch.set_num_threads(saved)
    return batch / min(times), batch / statistics.median(times)


def replicate(facts: FactSet, episodes: int, names: tuple[str, ...]) -> FactSet:
    """A FactSet of ``episodes`` episodes: the recorded ones repeated with new numbers."""
    base = facts["episode"]["episode"].to_numpy()
    reps = -(-episodes // len(base))
    renumber = {int(e): i for i, e in enumerate(base)}
    tables: dict[str, pd.DataFrame] = {}
    for name in names:
        df = facts[name]
        if "episode" in df.columns:
            idx = df["episode"].map(renumber).to_numpy()
            offsets = np.repeat(np.arange(reps) * len(base), len(df))
            big = pd.concat([df] * reps, ignore_index=True)
            big["episode"] = np.tile(idx, reps) + offsets
            df = big[big["episode"] < episodes].reset_index(drop=True)
        tables[name] = df
    return FactSet(tables=tables, threshold=facts.threshold, meta=facts.meta)


def timed(fn: Any) -> tuple[Any, float]:
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def bench_kb(facts: FactSet, episodes: int, kind: str, consult_max: int, workdir: Path) -> None:
    from neurosym.prolog.knowledge_base import KnowledgeBase
    from neurosym.prolog.qlf import qcompile

    names = TRACE if kind == "trace" else tuple(PREDICATES)
    big = replicate(facts, episodes, names)
    n_facts = big.n_facts
    path = workdir / f"kb_{kind}_{episodes}.pl"
    _, write_s = timed(lambda: big.to_prolog(path))
    line: dict[str, Any] = {
        "bench": "kb",
        "facts": kind,
        "episodes": episodes,
        "n_facts": n_facts,
        "write_s": round(write_s, 3),
        "write_facts_per_s": round(n_facts / write_s),
        "file_mb": round(path.stat().st_size / 2**20, 1),
    }
    rules = [ROOT / "rules" / "rgw.pl"]
    if episodes <= consult_max:
        kb, consult_s = timed(lambda: KnowledgeBase(path, rules=rules))
        kb.close()
        line["consult_s"] = round(consult_s, 3)
    _, qcompile_s = timed(lambda: qcompile(path))
    line["qcompile_s"] = round(qcompile_s, 3)
    kb, qlf_s = timed(lambda: KnowledgeBase(path, rules=rules, qlf=True))
    line["qlf_load_s"] = round(qlf_s, 3)
    try:
        goal = "sword_before_enemy(E)"
        answers, first = timed(lambda: kb.count(goal))
        counts = [timed(lambda: kb.count(goal))[1] for _ in range(5)]
        queries = [timed(lambda: kb.query(goal))[1] for _ in range(3)]
        line.update(
            query=goal,
            answers=answers,
            first_ms=round(first * 1e3, 2),
            count_ms=round(statistics.median(counts) * 1e3, 2),
            query_ms=round(statistics.median(queries) * 1e3, 2),
        )
    finally:
        kb.close()
    emit(**line)
    path.unlink(missing_ok=True)
    path.with_suffix(".qlf").unlink(missing_ok=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--checkpoint", type=Path, default=ROOT / "checkpoints" / "rgw2-predinet.pt")
    ap.add_argument("--env", default="rgw2")
    ap.add_argument("--episodes", type=int, default=256, help="episodes recorded (default 256)")
    ap.add_argument(
        "--batch", type=int, default=None, help="recorder batch (default: the recorder's)"
    )
    ap.add_argument("--sizes", default="1000,10000,100000", help="KB sizes in episodes")
    ap.add_argument(
        "--repeat",
        type=int,
        default=3,
        help="timed recordings; best and median reported (default 3)",
    )
    ap.add_argument("--threads", type=int, default=None, help="torch threads (default: torch's)")
    ap.add_argument(
        "--policy",
        choices=["checkpoint", "route"],
        default=None,
        help="actions from the checkpoint, or rgw2's optimal route with the model introspecting "
        "(default: checkpoint when there is one, else route)",
    )
    ap.add_argument(
        "--full-max", type=int, default=1000, help="largest KB with every predicate (default 1000)"
    )
    ap.add_argument(
        "--consult-max", type=int, default=10000, help="largest KB also consulted from source"
    )
    args = ap.parse_args()

    import torch

    from neurosym.record.recorder import DEFAULT_BATCH

    if args.threads:
        torch.set_num_threads(args.threads)

    emit(
        bench="machine",
        cpus=os.cpu_count(),
        load_avg=[round(x, 2) for x in os.getloadavg()],
        torch_threads=torch.get_num_threads(),
        python=platform.python_version(),
        torch=torch.__version__,
    )
    agent, source = load_or_build_agent(args.checkpoint, args.env)
    policy = args.policy or ("checkpoint" if source != "untrained" else "route")
    if policy == "route":
        if args.env != "rgw2":
            raise SystemExit("--policy route plays Configuration-2's optimal route: use --env rgw2")
        agent = RouteAgent(agent)
    batch = args.batch or DEFAULT_BATCH
    record(agent, args.env, episodes=min(8, args.episodes), seed=0, batch=batch)  # warm-up
    runs = []
    for _ in range(args.repeat):
        rec, seconds = timed(
            lambda: record(agent, args.env, episodes=args.episodes, seed=0, batch=batch)
        )
        runs.append(seconds)
    steps = rec.n_steps
    model = getattr(agent, "inner", agent)  # the model alone, not the route counter
    model_best, model_median = model_rate(model, args.env, min(batch, args.episodes), args.repeat)
    emit(
        bench="record",
        checkpoint=source,
        policy=policy,
        env=args.env,
        module=agent.config.module,
        heads=agent.config.heads,
        relations=agent.config.relations,
        episodes=args.episodes,
        batch=batch,
        steps=steps,
        seconds=[round(x, 3) for x in runs],
        steps_per_s=round(steps / min(runs)),
        steps_per_s_median=round(steps / statistics.median(runs)),
        model_steps_per_s=round(model_best),
        model_steps_per_s_median=round(model_median),
        returns_mean=round(float(rec.episodes["return"].mean()), 3),
    )
    facts, extract_s = timed(lambda: extract_facts(rec, threshold="quantile:0.9"))
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        _, write_s = timed(lambda: facts.to_prolog(work / "kb.pl"))
        emit(
            bench="extract",
            episodes=args.episodes,
            n_facts=facts.n_facts,
            extract_s=round(extract_s, 3),
            write_s=round(write_s, 3),
            facts_per_s=round(facts.n_facts / write_s),
            counts=facts.counts(),
        )
        for size in (int(s) for s in args.sizes.split(",") if s.strip()):
            bench_kb(facts, size, "trace", args.consult_max, work)
            if size <= args.full_max:
                bench_kb(facts, size, "all", args.consult_max, work)


if __name__ == "__main__":
    main()
