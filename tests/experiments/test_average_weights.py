"""experiments/average_weights.py: the element-wise mean of one run's checkpoints."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
import torch

from neurosym.agent.agent import load_agent

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("average_weights", ROOT / "experiments" / "average_weights.py")
average_weights = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(average_weights)

SOURCE = ROOT / "checkpoints" / "rgw2-predinet.pt"


def test_the_mean_of_two_checkpoints(tmp_path: Path) -> None:
    ck = torch.load(SOURCE, weights_only=False)
    other = {k: (v + 1 if v.is_floating_point() else v) for k, v in ck["state_dict"].items()}
    torch.save({**ck, "state_dict": other, "command": "second"}, tmp_path / "b.pt")
    out = tmp_path / "mean.pt"
    average_weights.average_checkpoints(str(out), [str(SOURCE), str(tmp_path / "b.pt")])
    mean = torch.load(out, weights_only=False)
    for name, value in ck["state_dict"].items():
        if value.is_floating_point():
            torch.testing.assert_close(mean["state_dict"][name], (value.float() + 0.5).to(value.dtype))
            assert mean["state_dict"][name].dtype == value.dtype
        else:
            assert torch.equal(mean["state_dict"][name], value)
    assert mean["command"].startswith("second && python experiments/average_weights.py")
    assert "optimizer" not in mean
    load_agent(out)  # loads and builds as any checkpoint


def test_different_models_are_refused(tmp_path: Path) -> None:
    with pytest.raises(SystemExit, match="model config differs"):
        average_weights.average_checkpoints(
            str(tmp_path / "x.pt"), [str(SOURCE), str(ROOT / "checkpoints" / "rgw-random-predinet-cellkeys.pt")]
        )
    assert not (tmp_path / "x.pt").exists()
