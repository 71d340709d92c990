"""A Prolog agent that plays: a strategy's goal/3 and rules/route.pl's route/4 choose the actions.

* :mod:`~neurosym.play.agent` -- :class:`PrologAgent`, live facts in, actions out
* :mod:`~neurosym.play.evaluate` -- :func:`score_strategy`: the figures of ``neurosym eval``
* :mod:`~neurosym.play.live` -- the live state's facts under the KB schema
* :mod:`~neurosym.play.policy` -- :func:`read_policy`: a strategy file and its features line
* :mod:`~neurosym.play.relations` -- the network's relation facts of live states
* :mod:`~neurosym.play.cli_play` -- the ``neurosym play`` command

Names are imported on first use, so ``import neurosym.play`` loads neither
torch nor janus.
"""

from __future__ import annotations

from neurosym.lazy import lazy_attributes

_API = {
    "PrologAgent": "neurosym.play.agent",
    "score_strategy": "neurosym.play.evaluate",
    "StrategyPlay": "neurosym.play.evaluate",
    "read_policy": "neurosym.play.policy",
    "Policy": "neurosym.play.policy",
    "episode_facts": "neurosym.play.live",
    "state_rows": "neurosym.play.live",
}

__all__ = sorted(_API)


__getattr__ = lazy_attributes(__name__, _API)
