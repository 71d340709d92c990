"""`neurosym compact`: half-precision weights, the same agent, one line for bad input."""

from __future__ import annotations

import functools
import os
import stat
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import compact_checkpoint, save_checkpoint
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.networks.model import ActorCritic
from neurosym.errors import CheckpointError, ConfigError

CONFIG = ModelConfig.for_family("rgw", "predinet", (9, 10, 10))


@pytest.fixture
def neurosym(
    run_neurosym: Callable[..., subprocess.CompletedProcess[str]],
) -> Callable[..., subprocess.CompletedProcess[str]]:
    return functools.partial(run_neurosym, timeout=120)


@pytest.fixture
def original(tmp_path: Path) -> Path:
    path = tmp_path / "a.pt"
    torch.manual_seed(0)
    model = ActorCritic(CONFIG)
    optimizer = torch.optim.Adam(model.parameters())
    model(torch.rand(2, *CONFIG.obs_shape))[1].sum().backward()
    optimizer.step()
    save_checkpoint(
        path,
        model=model,
        config=CONFIG,
        env_name="rgw2",
        env_kwargs={"max_steps": 100},
        train_config=TrainConfig.for_family("rgw"),
        optimizer_state=optimizer.state_dict(),
        frames=1234,
        episodes=12,
        metrics={"wall_s": 1.5, "stop_reason": "target"},
        command="neurosym train --env rgw2 --module predinet --out runs/x",
    )
    return path


def test_half_precision_copy_keeps_the_agent(original: Path, tmp_path: Path) -> None:
    small = tmp_path / "small.pt"
    report = compact_checkpoint(original, small)
    raw = torch.load(small, weights_only=True)
    floats = [v for v in raw["state_dict"].values() if v.is_floating_point()]
    assert floats and all(v.dtype == torch.float16 for v in floats)
    assert raw["weights_dtype"] == "float16" and raw["optimizer"] is None
    assert report["bytes_after"] < 0.6 * report["bytes_before"]
    assert report["bytes_after"] == small.stat().st_size
    assert 0 < report["max_change"] < 1e-2
    # everything but the weights is kept, and the command records the step
    old, new = load_agent(original), load_agent(small)
    assert new.config == old.config and new.env_name == "rgw2" and new.env_kwargs == old.env_kwargs
    assert new.meta["frames"] == 1234 and new.meta["metrics"] == old.meta["metrics"]
    assert new.meta["command"] == (
        f"neurosym train --env rgw2 --module predinet --out runs/x && "
        f"neurosym compact {original} --out {small} --dtype float16"
    )
    # the model computes in float32 with weights within half-precision rounding of the old ones
    new_state = new.model.state_dict()
    for name, a in old.model.state_dict().items():
        assert new_state[name].dtype == a.dtype, name
        torch.testing.assert_close(new_state[name], a, rtol=1e-3, atol=1e-4)
    obs = np.random.default_rng(0).random((16, *CONFIG.obs_shape), dtype=np.float32)
    with torch.inference_mode():
        logits_old = old.model(torch.as_tensor(obs))[0]
        logits_new = new.model(torch.as_tensor(obs))[0]
    torch.testing.assert_close(logits_new, logits_old, rtol=1e-2, atol=1e-2)


def test_in_place_and_bfloat16(original: Path) -> None:
    compact_checkpoint(original, original, "bfloat16")
    raw = torch.load(original, weights_only=True)
    assert raw["weights_dtype"] == "bfloat16"
    assert [p.name for p in original.parent.iterdir()] == ["a.pt"]  # no temp file left
    assert load_agent(original).meta["command"].endswith("--dtype bfloat16")


def test_bad_input_is_one_line(original: Path, tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="--dtype 'int8' is not one of float16, bfloat16"):
        compact_checkpoint(original, tmp_path / "b.pt", "int8")
    with pytest.raises(CheckpointError, match="checkpoint not found"):
        compact_checkpoint(tmp_path / "missing.pt", tmp_path / "b.pt")
    assert not (tmp_path / "b.pt").exists()


def test_overflowing_weight_is_refused(tmp_path: Path) -> None:
    model = ActorCritic(CONFIG)
    with torch.no_grad():
        next(model.parameters()).view(-1)[0] = 1e6
    path = tmp_path / "big.pt"
    save_checkpoint(path, model=model, config=CONFIG, env_name="rgw2")
    with pytest.raises(CheckpointError, match="overflows float16.*bfloat16"):
        compact_checkpoint(path, tmp_path / "b.pt")
    compact_checkpoint(path, tmp_path / "b.pt", "bfloat16")  # bfloat16 has float32's range


def test_cli(neurosym, neurosym_main, original: Path, tmp_path: Path) -> None:
    small = tmp_path / "small.pt"
    proc = neurosym("compact", original, "--out", small)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(f"wrote {small}: ") and "float16" in proc.stdout
    proc = neurosym_main("eval", "--checkpoint", small, "--episodes", "2", "--json")
    assert proc.returncode == 0, proc.stderr
    bad = neurosym_main("compact", tmp_path / "none.pt", "--out", small)
    assert bad.returncode == 1 and bad.stderr.count("\n") == 1 and "not found" in bad.stderr


def test_cli_refuses_a_target_that_is_not_a_regular_file(
    neurosym, original: Path, tmp_path: Path
) -> None:
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    device = tmp_path / "null"
    device.symlink_to("/dev/null")  # a rename would replace the link, never /dev/null itself
    for target, kind in ((fifo, "a FIFO"), (device, "a character device"), (tmp_path, "a folder")):
        proc = neurosym("compact", original, "--out", target)
        assert proc.returncode == 1, proc.stderr
        assert proc.stderr == (
            f"neurosym compact: error: cannot write {target}: it exists and is {kind}, "
            "not a regular file; nothing was written\n"
        )
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
    assert device.is_symlink() and stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.pt", "fifo", "null"]
