"""``neurosym play`` speed: env steps per second through janus, and where the time goes; JSON lines.

Lines, in order:

* ``machine``: cores, load average (figures are wall times on a machine that
  may be shared: compare with the load average);
* ``play`` (one line per strategy file and env): episodes played by
  :func:`neurosym.play.score_strategy` (batched env, live facts asserted through
  janus, goal/3 and route/4 in SWI-Prolog, scoring as ``neurosym eval``),
  best and median of ``--repeat`` runs of ``steps_per_s`` (env steps per
  second of the whole loop), ``decide_ms`` (mean Prolog time of one decision:
  the step's one janus call, decide_all/5, that asserts each running
  episode's state and asks goal/3 and route/4, divided by its decisions), and
  the strategy's ``success_rate``, ``fallback_steps`` and ``deciders`` (steps
  by what decided them) under ``--fallback``;
* ``route`` : route/4 alone on a live rgw-random state, mean ms per call over
  ``--calls`` calls with route.pl's memory of routes cleared before each,
  and the same remembered (the cost a strategy pays when it asks again);
  ``moves_fresh_ms`` and ``moves_remembered_ms`` the same for
  route_moves/4 (the route length of a learned strategy's features).

    python bench/play.py                                    # the shipped examples
    python bench/play.py --policy strategy.pl --env rgw-random --episodes 300
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from neurosym.agent.evaluation import play_scored  # noqa: E402
from neurosym.cli import parse_env_options  # noqa: E402
from neurosym.play import PrologAgent  # noqa: E402

EXAMPLES = [
    (ROOT / "neurosym" / "play" / "strategies" / "rgw_handwritten.pl", "rgw-random"),
    (ROOT / "neurosym" / "play" / "strategies" / "boxworld_handwritten.pl", "bw2"),
]


def emit(**fields: Any) -> None:
    print(json.dumps(fields), flush=True)


def play_once(
    policy: Path, env: str, episodes: int, seed: int, kwargs: dict, fallback: str
) -> dict[str, Any]:
    with PrologAgent(policy, fallback=fallback) as agent:
        start = time.perf_counter()
        done = play_scored(
            agent.act,
            lambda n: agent.make_venv(env, n, seed, **kwargs),
            episodes,
            seed,
            levels=False,
        )
        seconds = time.perf_counter() - start
        steps = int(sum(done.lengths))
        return {
            "steps": steps,
            "steps_per_s": steps / seconds,
            "decide_ms": 1000 * agent.decide_seconds / max(agent.decisions, 1),
            "success_rate": sum(o in ("terminal", "gem") for o in done.outcomes) / episodes,
            "fallback_steps": int(sum(agent.fallbacks.values())),
            "deciders": dict(agent.deciders),
        }


def bench_route(calls: int) -> None:
    policy = ROOT / "neurosym" / "play" / "strategies" / "rgw_handwritten.pl"
    with PrologAgent(policy) as agent:
        venv = agent.make_venv("rgw-random", 1, 7)
        obs, _ = venv.reset(seed=[7])
        agent.act(obs, venv)
        fresh = []
        for _ in range(calls):
            agent.kb.query("route_forget(0)")
            start = time.perf_counter()
            agent.kb.query("route(0, 0, terminal, A)")
            fresh.append(time.perf_counter() - start)
        start = time.perf_counter()
        for _ in range(calls):
            agent.kb.query("route(0, 0, terminal, A)")
        remembered = (time.perf_counter() - start) / calls
        moves = _timed(agent.kb, "route_moves(0, 0, terminal, D)", calls)
        venv.close()
    emit(
        what="route",
        fresh_ms=round(1000 * statistics.mean(fresh), 3),
        remembered_ms=round(1000 * remembered, 3),
        **moves,
        calls=calls,
    )


def _timed(kb: Any, goal: str, calls: int) -> dict[str, float]:
    """Mean ms of ``goal`` with route.pl's memory of episode 0 cleared before each call, and
    remembered (``{}`` where route.pl has no such predicate: an older checkout)."""
    if not kb.query("current_predicate(route_moves/4)"):
        return {}
    fresh = []
    for _ in range(calls):
        kb.query("route_forget(0)")
        start = time.perf_counter()
        kb.query(goal)
        fresh.append(time.perf_counter() - start)
    start = time.perf_counter()
    for _ in range(calls):
        kb.query(goal)
    remembered = (time.perf_counter() - start) / calls
    return {
        "moves_fresh_ms": round(1000 * statistics.mean(fresh), 3),
        "moves_remembered_ms": round(1000 * remembered, 3),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", type=Path, help="strategy file (default: the shipped examples)")
    parser.add_argument("--env", help="env of --policy")
    parser.add_argument("--env-option", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--episodes", type=int, default=64)
    parser.add_argument("--seed", type=int, default=3_000_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--calls", type=int, default=200)
    parser.add_argument("--fallback", choices=("default", "none"), default="default")
    args = parser.parse_args()
    emit(
        what="machine",
        cpus=os.cpu_count(),
        load_avg=[round(x, 2) for x in os.getloadavg()],
        python=platform.python_version(),
    )
    runs = [(args.policy, args.env)] if args.policy else EXAMPLES
    kwargs = parse_env_options(args.env_option, args.env)
    for policy, env in runs:
        results = [
            play_once(policy, env, args.episodes, args.seed, kwargs, args.fallback)
            for _ in range(args.repeat)
        ]
        rates = [r["steps_per_s"] for r in results]
        emit(
            what="play",
            policy=str(policy.relative_to(ROOT) if policy.is_relative_to(ROOT) else policy),
            env=env,
            env_options=kwargs,
            episodes=args.episodes,
            steps=results[0]["steps"],
            steps_per_s_best=round(max(rates), 1),
            steps_per_s_median=round(statistics.median(rates), 1),
            decide_ms=round(min(r["decide_ms"] for r in results), 3),
            success_rate=results[0]["success_rate"],
            fallback_steps=results[0]["fallback_steps"],
            fallback=args.fallback,
            deciders=results[0]["deciders"],
        )
    bench_route(args.calls)


if __name__ == "__main__":
    main()
