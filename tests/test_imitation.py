"""`--algo imitate`: DAgger from the RGW planner -- labels, loss, buffer, an update that learns, the CLI."""

from __future__ import annotations

import functools
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import torch

from neurosym.agent.checkpoint import load_agent, read_checkpoint
from neurosym.agent.cli_eval import score
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.imitation import (
    LabelBuffer,
    expert_share,
    imitation_loss,
    imitation_update,
)
from neurosym.agent.model import ActorCritic
from neurosym.envs import make_batched
from neurosym.envs.rgw_solver import Planner
from neurosym.errors import ConfigError


class SetSampler:
    """A policy that draws uniformly among the planner's optimal actions."""

    def __init__(self, seed: int) -> None:
        self.planner = Planner()
        self.rng = np.random.default_rng(seed)

    def __call__(self, obs: np.ndarray, venv: object) -> np.ndarray:
        sets, _ = self.planner.action_sets(venv)
        return (self.rng.random(sets.shape) * sets).argmax(axis=1)


def test_any_action_of_the_optimal_sets_earns_the_optimal_return() -> None:
    report = score(SetSampler(0), "rgw-random", 48, seed=2000)
    assert report["optimal_rate"] == 1.0 and report["success_rate"] == 1.0


def test_the_sets_hold_the_planners_action_and_often_more_than_one() -> None:
    venv = make_batched("rgw-random", 32, seed=3)
    venv.reset(seed=3)
    planner = Planner()
    sizes = []
    for _ in range(10):
        chosen = planner(None, venv)
        sets, values = planner.action_sets(venv)
        assert sets[np.arange(32), chosen].all()
        assert values.shape == (32,) and np.isfinite(values).all()
        sizes += sets.sum(1).tolist()
        venv.step(chosen)
    assert min(sizes) >= 1 and max(sizes) >= 2  # ties exist: one label would be arbitrary


def test_imitation_loss_is_cross_entropy_of_the_set() -> None:
    logits = torch.tensor([[2.0, 0.0, -1.0, 0.5], [0.0, 0.0, 0.0, 0.0]])
    one = torch.tensor([[True, False, False, False], [False, False, True, False]])
    expected = torch.nn.functional.cross_entropy(logits, torch.tensor([0, 2]))
    assert imitation_loss(logits, one).item() == pytest.approx(expected.item())
    both = torch.tensor([[True, True, False, False]] * 2)
    p = torch.softmax(logits, -1)
    assert imitation_loss(logits, both).item() == pytest.approx(
        -torch.log(p[:, 0] + p[:, 1]).mean().item()
    )
    assert imitation_loss(logits, torch.ones(2, 4, dtype=torch.bool)).item() == pytest.approx(0.0)


def test_expert_share_falls_linearly_to_zero() -> None:
    assert [expert_share(f, 100) for f in (0, 50, 100, 500)] == [1.0, 0.5, 0.0, 0.0]
    assert expert_share(0, 0) == 0.0


def test_label_buffer_keeps_the_latest_states() -> None:
    buf = LabelBuffer(5, (1,), np.uint8)
    for start in (0, 3):
        obs = np.arange(start, start + 3, dtype=np.uint8)[:, None]
        buf.add(obs, np.ones((3, 4), bool), obs[:, 0].astype(np.float32))
    assert buf.size == 5 and sorted(buf.obs[:, 0].tolist()) == [1, 2, 3, 4, 5]
    buf.add(np.arange(10, 17, dtype=np.uint8)[:, None], np.ones((7, 4), bool), np.zeros(7, "f4"))
    assert sorted(buf.obs[:, 0].tolist()) == [12, 13, 14, 15, 16]


def labelled_buffer() -> tuple[LabelBuffer, np.random.Generator]:
    """256 labelled states of rgw-random (8 random steps of 32 levels), and the rng that drew them."""
    venv = make_batched("rgw-random", 32, seed=11)
    obs, _ = venv.reset(seed=11)
    planner = Planner()
    buf = LabelBuffer(256, obs.shape[1:], obs.dtype)
    rng = np.random.default_rng(0)
    for _ in range(8):
        sets, values = planner.action_sets(venv)
        buf.add(obs, sets, values)
        obs, *_ = venv.step(rng.integers(0, 4, 32))
    return buf, rng


def seeing_predinet(obs_shape: tuple[int, ...]) -> ActorCritic:
    """The PrediNet that DAgger trains (LayerNorm on entities, attention gain 8, orthogonal init)."""
    cfg = ModelConfig.for_family("rgw", "predinet", tuple(obs_shape),
                                 entity_norm=True, attention_gain=8.0, init="orthogonal")  # fmt: skip
    return ActorCritic(cfg)


def test_updates_fit_the_planners_labels() -> None:
    """On a fixed buffer of rgw-random states the imitation loss falls well below its start."""
    torch.manual_seed(0)
    buf, rng = labelled_buffer()
    model = seeing_predinet(buf.obs.shape[1:])
    train = TrainConfig.for_family("rgw", algo="imitate", dagger_batch=256, dagger_steps=10)
    opt = torch.optim.Adam(model.parameters(), lr=2e-3)
    first = imitation_update(model, opt, buf, train, rng, torch.device("cpu")).policy_loss
    for _ in range(7):
        last = imitation_update(model, opt, buf, train, rng, torch.device("cpu")).policy_loss
    assert last < 0.5 * first, (first, last)


def test_augmented_updates_fit_the_turned_levels_too() -> None:
    """--augment: fitted on random turns and mirrors, the network also knows the levels turned;
    fitted on the levels as they come, it knows them less well."""
    from neurosym.agent.augment import action_permutation, transform_grid

    buf, _ = labelled_buffer()
    turned_obs = transform_grid(torch.from_numpy(buf.obs), 1, False).contiguous()
    turned_sets = torch.empty(buf.optimal.shape, dtype=torch.bool)
    turned_sets[:, list(action_permutation(1, False, 10, 10))] = torch.from_numpy(buf.optimal)
    losses = {}
    for augment in (False, True):
        torch.manual_seed(0)
        model = seeing_predinet(buf.obs.shape[1:])
        train = TrainConfig.for_family(
            "rgw", algo="imitate", dagger_batch=256, dagger_steps=10, augment=augment
        )
        opt = torch.optim.Adam(model.parameters(), lr=2e-3)
        gen, step_rng = torch.Generator().manual_seed(0), np.random.default_rng(0)
        for _ in range(8):
            imitation_update(model, opt, buf, train, step_rng, torch.device("cpu"), gen)
        with torch.no_grad():
            losses[augment] = imitation_loss(model(turned_obs)[0], turned_sets).item()
    assert losses[True] < 0.8 * losses[False], losses
    with pytest.raises(ConfigError, match="--augment .* needs --algo imitate, not a3c"):
        TrainConfig.for_family("rgw", augment=True)


def test_imitate_needs_the_rgw_planner() -> None:
    with pytest.raises(ConfigError, match="imitate learns from the RGW planner; boxworld"):
        TrainConfig.for_family("boxworld", algo="imitate")
    with pytest.raises(ConfigError, match="thesis is A3C"):
        TrainConfig.for_family("rgw", preset="thesis", algo="imitate")


@pytest.fixture
def neurosym(
    run_neurosym: Callable[..., subprocess.CompletedProcess[str]],
) -> Callable[..., subprocess.CompletedProcess[str]]:
    return functools.partial(run_neurosym, timeout=180)


@pytest.mark.expensive
def test_train_imitate_writes_a_checkpoint_that_resumes_and_evaluates(
    neurosym: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    out = tmp_path / "run"
    first = neurosym("train", "--env", "rgw-random", "--module", "predinet", "--algo", "imitate",
                     "--envs", "8", "--n-steps", "8", "--dagger-steps", "2", "--frames", "300",
                     "--quiet", "--eval-episodes", "2", "--out", out)  # fmt: skip
    assert first.returncode == 0, first.stderr[-2000:]
    payload = read_checkpoint(out / "checkpoint.pt")
    assert payload["train_config"]["algo"] == "imitate"
    assert payload["train_config"]["dagger_steps"] == 2
    frames = int(payload["frames"])
    assert frames >= 300
    again = neurosym("train", "--out", out, "--resume", "--frames", frames + 200, "--quiet")
    assert again.returncode == 0, again.stderr[-2000:]
    resumed = read_checkpoint(out / "checkpoint.pt")
    assert int(resumed["frames"]) >= frames + 200
    assert "--algo imitate" in resumed["command"] and " && " in resumed["command"]
    load_agent(out / "checkpoint.pt")
    ev = neurosym("eval", "--checkpoint", out / "checkpoint.pt", "--episodes", "4", "--json")
    assert ev.returncode == 0, ev.stderr[-2000:]


def test_train_with_a_local_view_records_it_and_resumes_with_it(
    neurosym: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    """--local-view is a model switch: in the checkpoint's config and command, kept on --resume."""
    out = tmp_path / "run"
    first = neurosym("train", "--env", "rgw-random", "--module", "predinet", "--algo", "imitate",
                     "--envs", "4", "--n-steps", "8", "--dagger-steps", "1", "--frames", "64",
                     "--kernel-size", "1", "--local-view", "3", "--quiet", "--eval-episodes", "1",
                     "--out", out)  # fmt: skip
    assert first.returncode == 0, first.stderr[-2000:]
    frames = int(read_checkpoint(out / "checkpoint.pt")["frames"])  # whole updates: past 64
    again = neurosym("train", "--out", out, "--resume", "--frames", frames + 64, "--quiet",
                     "--eval-episodes", "1")  # fmt: skip
    assert again.returncode == 0, again.stderr[-2000:]
    agent = load_agent(out / "checkpoint.pt")
    config = agent.config
    assert (config.local_view, config.agent_plane, config.kernel_size) == (3, 0, 1)
    assert "--kernel-size 1 --local-view 3" in agent.meta["command"]
    assert agent.model.body[0].in_features == agent.config.output_size + 9 * 9
    more = int(agent.meta["frames"]) + 64
    other = neurosym("train", "--out", out, "--resume", "--frames", more, "--local-view", "5")
    assert other.returncode != 0
    assert "local_view 3 (asked for 5)" in other.stderr, other.stderr[-2000:]


def test_train_imitate_on_box_world_is_one_line(
    neurosym: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    proc = neurosym("train", "--env", "bw1", "--module", "predinet", "--algo", "imitate",
                    "--frames", "10", "--out", tmp_path / "x")  # fmt: skip
    assert proc.returncode != 0
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "imitate learns from the RGW planner" in lines[0], proc.stderr
