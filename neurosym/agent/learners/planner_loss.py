"""The loss of a policy against a planner's set of optimal actions.

Why a set: equally short routes are all optimal, and a planner's tie-break
between them is arbitrary; ``-log sum_{a optimal} p(a)`` asks the policy to put
its probability on the set and leaves the split inside it free. Used by DAgger
(:mod:`neurosym.agent.learners.imitation`) and by A3C's ``planner_coef`` term
(:func:`neurosym.agent.learners.a3c.a3c_loss`).
"""

from __future__ import annotations

import torch


def optimal_set_nll(logits: torch.Tensor, optimal: torch.Tensor) -> torch.Tensor:
    """``-log sum_{a in optimal} softmax(logits)_a`` per row: (..., A) logits, (..., A) bool -> (...).

    A row whose set is empty (a state with no action left to choose: an
    autoreset step) gets 0, not infinity; callers mask those rows anyway.
    """
    some = optimal.any(-1, keepdim=True)
    chosen = optimal | ~some  # an empty set counts as every action: -log 1 = 0
    picked = torch.logsumexp(logits.masked_fill(~chosen, float("-inf")), dim=-1)
    return torch.logsumexp(logits, dim=-1) - picked
