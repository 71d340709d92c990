"""PrologAgent: a strategy's ``goal/3`` and route.pl's ``route/4`` playing a batched env.

Each step, for every sub-env whose episode is running, the live state's facts
(:mod:`neurosym.play.live`) go into SWI-Prolog as data (asserted, never
consulted), the strategy's first answer of ``goal(E, T, Object)`` names the
object to go for and ``route(E, T, Object, Action)`` (rules/route.pl, loaded
as code beside the strategy) the action. The Prolog side is
:mod:`neurosym.play.prolog`: one call per sub-env and step.

On Minigrid and BabyAI the state also has ``facing/3`` and ``door_state/4``
(:func:`neurosym.play.live.minigrid_rows`, as the recorder writes them), route/4
answers Minigrid's actions (left, right, forward, pickup, toggle: the env's
``action_names``), and a state is its positions, held items, direction and doors.

The strategy leaves a state undecided when goal/3 has no answer
(``no_goal``), when route/4 finds no path to its object (``no_route``: the
route planner refuses it), or when the episode has been in this very state
before (``loop``: the same positions and held items; a strategy that reads the
state alone would choose as it did then and go round the same loop for good).
What happens then is the agent's ``fallback``:

* ``default`` (the default): route.pl's ``default_goal/3`` (a hand-written
  strategy: RGW the sword, then enemies, then the terminal; Box-World the
  held key's lock, else a loose key; Minigrid the key of a locked door, the
  door, the goal) decides, else ``safe_step/3`` (the first move into a free
  cell; Minigrid: forward into a free cell, else left), else ``up``;
* ``none``: nothing decides for the strategy, and the episode ends there as
  a failure. The env is stepped once more (a batched env steps every
  sub-env), but nothing of that step counts: its reward is 0, it has no
  events, and the episode's outcome is the cause (``no_goal``, ``no_route``
  or ``loop``); the step counts in the episode's length.

:attr:`PrologAgent.deciders` counts the steps by what decided them
(``strategy``: goal/3 and route/4; ``default_goal``, ``safe_step``, ``up``:
the fallback; ``none``: an episode ended by ``fallback="none"``), and
:attr:`PrologAgent.fallbacks` the undecided ones by cause. One janus call
decides the running episodes of a step (``decide_all/5``).

Episode E of the facts is the episode's number (its reset seed minus the
first seed), T its state; an episode's facts are retracted when it ends.
"""

from __future__ import annotations

import os
import time
import warnings
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from neurosym.envs.actions import ACTION_NAMES
from neurosym.errors import ConfigError, PrologError
from neurosym.facts.schema import TRACE, group
from neurosym.play import live
from neurosym.play import prolog as play_prolog
from neurosym.play.policy import Policy, read_policy
from neurosym.prolog.interrupt import interruptible
from neurosym.terms import Term

INFERENCE_LIMIT = 10_000_000
"""inferences a strategy may take to choose one object (then the run stops with one line)"""

SCHEMA = tuple(group(TRACE))
"""every predicate of the KB schema (:mod:`neurosym.facts.schema`), declared dynamic in the agent's module"""

FALLBACKS = ("default", "none")
"""what decides a state the strategy leaves undecided: route.pl's default_goal/3, safe_step/3
and up (default), or nothing: the episode ends as a failure (none)"""

DECIDERS = ("strategy", "default_goal", "safe_step", "up", "none")
"""what can decide a step: the strategy (goal/3 and route/4), a part of the fallback, or
nothing (fallback none: the episode ends)"""

_C_STACK_BASE = 16 << 20
_C_STACK_PER_LEVEL = 768
"""C stack of the thread that reads a strategy file: as neurosym.prolog.knowledge_base sizes it"""


def _janus() -> Any:
    """janus with neurosym_play consulted (once per process)."""
    from neurosym.prolog.locate import janus_with

    return janus_with(play_prolog)


class PrologAgent:
    """Plays with a strategy file's ``goal/3`` and route.pl; ``act(obs, venv)`` as evaluation wants.

    ``policy``: the strategy file (or a :class:`Policy`). ``network``: the
    loaded checkpoint (:class:`~neurosym.agent.agent.Agent`) whose
    relation facts a strategy with ``features: relations`` or ``both`` reads
    (:mod:`neurosym.play.relations`), with ``thresholds`` (relation j ->
    threshold of holds/5) when the strategy file has no threshold/2. Play
    the envs :meth:`make_venv` makes, so that the agent sees their infos;
    close it (or use ``with``) when done.

        >>> with PrologAgent("neurosym/play/strategies/rgw_handwritten.pl") as agent:
        ...     venv = agent.make_venv("rgw2", 1, seed=0)
        ...     obs, _ = venv.reset(seed=[0])
        ...     agent.act(obs, venv)
        array([1])
    """

    def __init__(
        self,
        policy: str | os.PathLike[str] | Policy,
        network: Any = None,
        *,
        thresholds: dict[int, float] | None = None,
        inference_limit: int = INFERENCE_LIMIT,
        fallback: str = "default",
    ) -> None:
        from neurosym.prolog.knowledge_base import KnowledgeBase
        from neurosym.shipped import rule_file

        if fallback not in FALLBACKS:
            raise ConfigError(f"fallback must be one of {', '.join(FALLBACKS)}, got {fallback!r}")
        self.fallback = fallback
        self.policy = policy if isinstance(policy, Policy) else read_policy(policy)
        if self.policy.needs_network and network is None:
            raise ConfigError(
                f"{self.policy.path} reads the network's relation facts "
                f"(features: {self.policy.features}); give the agent they came from "
                "(--checkpoint)"
            )
        self.inference_limit = int(inference_limit)
        self.kb = KnowledgeBase(None)
        try:
            with interruptible():
                self.kb.query(
                    "forall(member(PI, Ps), dynamic(PI))",
                    Ps=[Term("/", (p.name, p.arity)) for p in SCHEMA],
                )
                self.kb.load_rules(rule_file("route"))
                _load_policy(self.kb, self.policy.path)
                if not self.kb.query("current_predicate(goal/3)"):
                    raise ConfigError(
                        f"{self.policy.path} defines no goal/3; a strategy file defines "
                        "goal(E, T, Object), the object to go for next in state T of episode E"
                    )
                self.relations = None
                if self.policy.needs_network:
                    from neurosym.play.relations import RelationFacts

                    self.relations = RelationFacts(network, self.kb, self.policy, thresholds)
                _janus().query_once(f"{play_prolog.MODULE}:guard(M)", {"M": self.kb.module})
        except BaseException:
            self.kb.close()
            raise
        self.module = self.kb.module
        self.fallbacks: Counter[str] = Counter()
        """undecided steps by cause: no_goal, no_route, loop"""
        self.deciders: Counter[str] = Counter()
        """steps by what decided them: strategy, default_goal, safe_step, up, none"""
        self.decisions = 0
        self.chosen = 0
        """decisions whose object the strategy chose (decider strategy)"""
        self.decide_seconds = 0.0
        self.goals: Counter[str] = Counter()
        self.last: tuple[str, str, str] | None = None
        """(decider, goal, action) of the latest decision"""

    # -- envs -------------------------------------------------------------

    def make_venv(self, env: str, n: int, seed: int, **env_kwargs: Any) -> _Watched:
        """A batched env of ``n`` whose resets and steps this agent follows (episode = seed - ``seed``)."""
        from neurosym.envs import make_batched

        return _Watched(make_batched(env, n, seed=seed, **env_kwargs), self, seed)

    # -- acting -----------------------------------------------------------

    def act(self, obs: np.ndarray, venv: _Watched) -> np.ndarray:
        """Actions (n,) for the batch: Prolog's choice for every running episode, 0 for idle ones
        (and for an episode that ``fallback="none"`` ends in this step)."""
        actions = np.zeros(len(obs), dtype=np.int64)
        live = [i for i in range(len(obs)) if venv.running[i]]
        if not live:
            return actions
        extra: dict[int, list[Any]] = {}
        if self.relations is not None:
            extra = self.relations.facts(obs, venv, live)
        items = [self._item(venv, i, extra.get(i, [])) for i in live]
        start = time.perf_counter()
        outs = self._query(
            f"{play_prolog.MODULE}:decide_all(M, Items, L, F, Outs)",
            {"M": self.module, "Items": items, "L": self.inference_limit, "F": self.fallback},
        )["Outs"]
        self.decide_seconds += time.perf_counter() - start
        for i, item, out in zip(live, items, outs, strict=True):
            actions[i] = self._taken(venv, i, item[0], item[1], out)
        return actions

    def _item(self, venv: _Watched, i: int, extra: list[Any]) -> list[Any]:
        """decide_all/5's item for sub-env i: [E, T, State, Prev, Extra, Seen]."""
        ats, held, minigrid = venv.state[i]
        key = (tuple(ats), tuple(held), minigrid and (minigrid[0], tuple(minigrid[1])))
        seen = key in venv.visited[i]
        venv.visited[i].add(key)
        prev, venv.prev[i] = venv.prev[i], []
        state = [[list(a) for a in ats], [live.encode(h) for h in held]]
        if minigrid is not None:
            state += [minigrid[0], [list(d) for d in minigrid[1]]]
        return [
            int(venv.episode[i]), int(venv.t[i]), state, prev, extra, "true" if seen else "false",
        ]  # fmt: skip

    def _taken(self, venv: _Watched, i: int, e: int, t: int, out: Any) -> int:
        """The action index of one decision ([Decider, Why, Goal, Action]), counted."""
        if out[0] == "error":
            raise PrologError(f"{self.policy.path}: {' '.join(str(out[1]).split())}")
        decider, why, goal, action = out
        self.decisions += 1
        self.deciders[decider] += 1
        if why != "none":
            self.fallbacks[why] += 1
        if decider == "none":
            venv.ended[i] = str(why)
            self.last = (decider, str(goal), "none")
            return 0
        if action not in venv.action_index:
            raise PrologError(
                f"{self.policy.path}: route/4 answered {_shown(action)} for {_shown(goal)} in "
                f"state {t} of episode {e}; an action is one of {', '.join(venv.action_names)} "
                "(a strategy may not redefine route.pl's predicates)"
            )
        self.last = (decider, str(goal), action)
        if decider == "strategy":
            self.chosen += 1
        self.goals[str(goal)] += 1
        return venv.action_index[action]

    def _query(self, goal: str, inputs: dict[str, Any]) -> Any:
        """One janus call of the agent's Prolog side; Ctrl-C stops it, a Prolog error is one line."""
        janus = _janus()
        try:
            with interruptible():
                return janus.query_once(goal, inputs)
        except janus.PrologError as exc:  # decide/9 catches the strategy's errors: this is abort/0
            raise PrologError(f"{self.policy.path}: {' '.join(str(exc).split())}") from None

    def state_facts(self, episode: int, t: int) -> dict[str, list[tuple[Any, ...]]]:
        """The facts of state (episode, t) now in the agent's KB, per schema predicate of one
        state (at/5, holding/3, step/4, event/3, and the network's when asserted), as text rows
        of their arguments after E and T."""
        out: dict[str, list[tuple[Any, ...]]] = {}
        for p in SCHEMA:
            if not p.per_state:
                continue
            cols = [f"V{i}" for i in range(p.arity - 2)]
            goal = p.goal(**dict(zip(p.columns, ["E", "T", *cols], strict=True)))
            rows = self.kb.query(goal, E=episode, T=t)
            out[p.name] = sorted(tuple(_text(r[c]) for c in cols) for r in rows)
        return out

    def close(self) -> None:
        """Unload the strategy and its facts."""
        with interruptible():
            self.kb.close()

    def __enter__(self) -> PrologAgent:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- episodes (called by _Watched) -------------------------------------

    def begin(self, episode: int, facts: live.EpisodeFacts) -> None:
        self._query(
            f"{play_prolog.MODULE}:begin_episode(M, E, O, X, G)",
            {
                "M": self.module, "E": episode,
                "O": [[i, live.encode(t)] for i, t in facts.objects],
                "X": [list(row) for row in facts.terrain],
                "G": [facts.rows, facts.cols],
            },
        )  # fmt: skip

    def end(self, episode: int) -> None:
        self._query(f"{play_prolog.MODULE}:end_episode(M, E)", {"M": self.module, "E": episode})


def _load_policy(kb: Any, path: Path) -> None:
    """Load a strategy file into ``kb`` as code, once :func:`check_policy` found nothing it may not hold.

    The file is read once, into a private copy, which is checked and loaded:
    what is checked is what runs. Messages name the file, not the copy.
    """
    from neurosym.prolog.snapshot import snapshot

    with snapshot(path) as copy:
        check_policy(kb.module, copy.path, path, copy.nesting)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                kb.load_rules(copy.path)
            except PrologError as exc:
                raise PrologError(str(exc).replace(str(copy.path), str(path))) from None
    for w in caught:
        warnings.warn_explicit(
            str(w.message).replace(str(copy.path), str(path)), w.category, str(path), 0
        )


def check_policy(module: str, file: Path, shown: Path, nesting: int) -> None:
    """ConfigError (one line, naming ``shown`` and the line) for the first term of a strategy
    file it may not hold: a directive that would run, a clause for another module, an
    expansion hook, a built-in or route.pl's predicates, a process-level predicate
    (:mod:`neurosym.play.prolog`, ``check_policy/4``)."""
    problem = _janus().query_once(
        f"{play_prolog.MODULE}:check_policy(M, F, C, P)",
        {"M": module, "F": str(file), "C": _C_STACK_BASE + _C_STACK_PER_LEVEL * nesting},
    )["P"]
    if problem != "none":
        line, text = problem
        where = f"{shown}:{line}" if line else str(shown)
        text = " ".join(str(text).replace(str(file), str(shown)).split())
        raise ConfigError(f"{where}: {text}")


def _shown(value: Any) -> str:
    text = str(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _text(value: Any) -> Any:
    return value if isinstance(value, int | float) else str(value)


class _Watched:
    """A batched env that tells its PrologAgent about every reset and step.

    Per sub-env it keeps the episode number, the state index t, whether the
    episode is still running, the state's at/holding rows and the previous
    transition (action, reward, events) not yet asserted. Everything else is
    the wrapped env's.
    """

    def __init__(self, venv: Any, agent: PrologAgent, first_seed: int) -> None:
        self.venv, self.agent, self.first_seed = venv, agent, first_seed
        n = venv.num_envs
        self.num_envs = n
        self.names = tuple(venv.entity_names)
        self.action_names: tuple[str, ...] = tuple(getattr(venv, "action_names", ACTION_NAMES))
        self.action_index = {name: i for i, name in enumerate(self.action_names)}
        self.episode = np.zeros(n, dtype=np.int64)
        self.t = np.zeros(n, dtype=np.int64)
        self.running = np.zeros(n, dtype=bool)
        self.state: list[Any] = [None] * n
        self.prev: list[list[Any]] = [[] for _ in range(n)]
        self.visited: list[set[Any]] = [set() for _ in range(n)]
        self.ended: dict[int, str] = {}
        """sub-env -> cause, for episodes the agent ends in the coming step (fallback none)"""
        self.outcomes: dict[int, str] = {}
        """sub-env -> cause, for the episodes the latest step ended that way"""
        self.info: Any = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self.venv, name)

    def reset(self, seed: list[int]) -> tuple[np.ndarray, Any]:
        for i in np.flatnonzero(self.running):  # an earlier wave cut short
            self.agent.end(int(self.episode[i]))
        obs, info = self.venv.reset(seed=seed)
        grids = self.venv.entity_grid()
        self.info = info
        for i in range(self.num_envs):
            d = self.venv.decode_info(info, i)
            e = int(seed[i]) - self.first_seed
            self.episode[i], self.t[i], self.running[i] = e, 0, True
            self.state[i] = (*live.state_rows(d), live.minigrid_rows(d))
            self.prev[i] = []
            self.visited[i] = set()
            self.agent.begin(e, live.episode_facts(d, np.asarray(grids[i]), self.names))
        self.ended, self.outcomes = {}, {}
        return obs, info

    def step(self, actions: np.ndarray) -> tuple[Any, ...]:
        obs, reward, terminated, truncated, info = self.venv.step(actions)
        self.outcomes = {}
        if self.ended:
            reward, terminated, truncated, info = self._end(reward, terminated, truncated, info)
        self.info = info
        for i in np.flatnonzero(self.running):
            d = self.venv.decode_info(info, i)
            if terminated[i] or truncated[i]:
                self.running[i] = False
                self.agent.end(int(self.episode[i]))
                continue
            self.t[i] += 1
            self.state[i] = (*live.state_rows(d), live.minigrid_rows(d))
            self.prev[i] = [
                self.action_names[int(actions[i])],
                float(reward[i]),
                [live.encode(ev) for ev in d["events"]],
            ]
        return obs, reward, terminated, truncated, info

    def _end(self, reward: Any, terminated: Any, truncated: Any, info: Any) -> tuple[Any, ...]:
        """The step's results with the episodes in :attr:`ended` ended: terminated, reward 0,
        no events (the action was not the strategy's); their outcome is the cause
        (:meth:`episode_outcome`)."""
        rows = list(self.ended)
        reward, terminated, truncated = (
            np.array(x, copy=True) for x in (reward, terminated, truncated)
        )
        reward[rows], terminated[rows], truncated[rows] = 0.0, True, False
        if isinstance(info, dict) and "events" in info:
            info = {**info, "events": np.array(info["events"], copy=True)}
            info["events"][rows] = 0
        self.outcomes = dict(self.ended)
        self.ended = {}
        return reward, terminated, truncated, info

    def episode_outcome(self, info: Any, i: int) -> str | None:
        """The outcome of sub-env i's episode that ended in the latest step: the cause, for one
        the agent ended (fallback none), else the env's."""
        if i in self.outcomes:
            return self.outcomes[i]
        quick = getattr(self.venv, "episode_outcome", None)
        if quick is not None:
            return quick(info, i)
        return self.venv.decode_info(info, i).get("outcome")

    def close(self) -> None:
        for i in np.flatnonzero(self.running):
            self.agent.end(int(self.episode[i]))
        self.running[:] = False
        self.venv.close()
