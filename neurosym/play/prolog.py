"""The Prolog half of ``neurosym play``: live-state facts asserted as data, one decision per call.

The Prolog is neurosym/play/pl/neurosym_play.pl, consulted once per process
as module ``neurosym_play``. Its predicates work on a KB module M made
by :class:`~neurosym.prolog.knowledge_base.KnowledgeBase` (which holds the
rule files, module route (rules/route.pl, its copy for M reading M's facts)
and the strategy, as code):

* ``begin_episode(M, E, Objects, Terrain, Grid)`` asserts ``object/2`` (once
  per id), ``terrain/4`` and ``grid/3`` of episode E;
* ``decide(M, E, T, State, Prev, Extra, Limit, Seen, Fallback, Out)`` asserts
  state T's ``at/5`` and ``holding/3`` (State ``[Ats, Held]``; on Minigrid
  ``[Ats, Held, Dir, Doors]`` adds ``facing/3`` and ``door_state/4``), the previous transition's ``step/4``
  and ``event/3``, and Extra (the network's ``holds/5``, ``attends/8`` or
  ``attention/6`` facts of state T), then asks ``goal(E, T, G)`` (first
  answer) and ``route(E, T, G, A)``. Out is ``[Decider, Why, Goal, Action]``:
  ``[strategy, none, G, A]`` when both answer; else Why is ``no_goal``,
  ``no_route`` or ``loop`` (Seen ``true``: the episode was in this very state
  before) and Fallback ``default`` falls back to ``default_goal/3``, then
  ``safe_step/3``, then ``up`` (Decider the one that answered), ``none`` to
  nothing (Decider and Action ``none``: the episode fails). Out is
  ``error-Text`` when the strategy raised or ran past Limit inferences;
* ``decide_all(M, Items, Limit, Fallback, Outs)``: decide/10 for each item
  ``[E, T, State, Prev, Extra, Seen]`` (the running episodes of one step: one
  janus call per step);
* ``end_episode(M, E)`` retracts every fact of episode E (not object/2,
  which, as in a KB, lists the ids of every episode) and the routes
  module route remembered for it (``route_forget/1``);
* ``check_policy(M, File, CStack, Problem)`` reads a strategy file term by
  term, running nothing (in a thread whose C stack is CStack bytes), and
  gives ``none`` or ``Line-Text`` for the first term a strategy may not hold:
  a directive other than ``dynamic``, ``discontiguous`` and
  ``use_module(library(Name))`` (directives run when a file loads), a
  clause for another module, for an expansion hook, for a built-in or for a
  predicate module route exports (imported into M), a clause that names a
  process-level predicate (:data:`FORBIDDEN`: halt, abort, shell, ...), or
  one that calls into module route qualified (``route:G``: its helpers are
  its own; a strategy calls the exports, such as ``route_moves/4``, as they
  are);
* ``guard(M)`` defines those process-level predicates in M as ones that
  raise a permission error, so a strategy that builds such a call at run
  time gets an error, not a process that ends; a ``halt/0,1`` that still
  reaches SWI-Prolog while a strategy chooses is cancelled (``at_halt/1``)
  and reported as an error.

Values arrive from janus as atoms, numbers and lists; a compound term arrives
as the tuple ``('$t', Functor, Args)`` and is rebuilt with
``compound_name_arguments/3``: nothing passed in is ever called, and Extra
may only hold the three network predicates.
"""

from __future__ import annotations

from pathlib import Path

MODULE = "neurosym_play"

FILE = Path(__file__).with_name("pl") / "neurosym_play.pl"
"""The module's source, shipped as package data."""
