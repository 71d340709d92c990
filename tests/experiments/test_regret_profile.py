"""experiments/regret_profile.py: the shipped MHDPA's mass on return-losing actions, on a few levels."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "regret_profile", ROOT / "experiments" / "regret_profile.py"
)
regret_profile = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(regret_profile)


def test_profile_splits_states_by_what_an_action_can_lose() -> None:
    out = regret_profile.profile(str(ROOT / "checkpoints" / "rgw-random-mhdpa.pt"),
                                 "rgw-random", 12, 2_000_000_000)  # fmt: skip
    assert out["states"] > 12 * 5  # every level takes more than five steps
    assert 0 < out["critical_share"] < 1  # some states can lose return, most cannot
    # a trained agent: little mass on losing actions, and argmax rarely one of them
    assert out["lost_mass_critical"] < 0.2 and out["argmax_loses_critical"] < 0.2
    assert 0 <= out["expected_loss_per_episode"] < 1
    assert out["nll_critical"] >= 0 and out["nll_other"] >= 0
