"""experiments/optimal_gap.py: each short episode goes in the class that says what it lost."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

from neurosym.agent.evaluation import ScoredEpisodes

_spec = importlib.util.spec_from_file_location(
    "optimal_gap", Path(__file__).resolve().parents[2] / "experiments" / "optimal_gap.py"
)
optimal_gap = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(optimal_gap)


def test_classes() -> None:
    done = ScoredEpisodes(
        returns=[11.0, 10.7 - 1e-9, 9.0, 10.0, 10.8, 10.0, 10.0],
        lengths=[20] * 7,
        outcomes=["terminal", "terminal", "timeout", "terminal", "terminal", "terminal", "pit"],
        optimal_return=[11.0, 10.7, 11.0, 11.0, 11.0, 11.0, 11.0],
        guarded=[True, False, True, False, True, True, False],
        sword_first=[True] * 7,
        took_sword=[True] * 7,
        no_sword_best=[math.nan, 10.0, math.nan, 10.0, math.nan, math.nan, 10.0],
    )
    assert optimal_gap.classify(done) == {
        "guarded:optimal": 1,
        "decoy:optimal": 1,  # within float tolerance of -0.1 sums
        "guarded:unfinished": 1,
        "decoy:decoy_enemy_left": 1,
        "guarded:small_detour": 1,
        "guarded:other": 1,  # a guarded level finished a whole point short
        "decoy:unfinished": 1,
    }
