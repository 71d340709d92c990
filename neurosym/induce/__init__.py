"""Rules learned back from knowledge bases (``neurosym induce``).

* :func:`induce_world` (:mod:`neurosym.induce.world`): ``predicts(E, T, Event)``
  clauses per event of the env's vocabulary, as :class:`WorldRules`
  (``.scores``, ``.clauses``, ``.write(path)``).
* :func:`induce_strategy` (:mod:`neurosym.induce.strategy`): ``goal(E, T, Object)``
  clauses, the object the agent goes for next, as a :class:`Strategy`
  (``.fidelity``, ``.predict(trace)``, ``.write(path)``); :func:`load_trace`
  reads a KB's tables for it.

Names are imported on first use, so ``neurosym induce`` imports neither
torch nor the envs.
"""

from __future__ import annotations

from neurosym.lazy import lazy_attributes

_LAZY = {
    "induce_world": "neurosym.induce.world",
    "WorldRules": "neurosym.induce.world",
    "EventScore": "neurosym.induce.world",
    "Bias": "neurosym.induce.foil",
    "induce_strategy": "neurosym.induce.strategy",
    "Strategy": "neurosym.induce.strategy",
    "load_trace": "neurosym.induce.strategy_data",
}

__all__ = sorted(_LAZY)


__getattr__ = lazy_attributes(__name__, _LAZY)
