"""`--algo imitate --set teacher=CHECKPOINT`: DAgger from a trained agent -- labels, loss,
refusals, an update that fits the teacher, and a Box-World run through the CLI."""

from __future__ import annotations

import functools
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import read_checkpoint
from neurosym.agent.config import TrainConfig
from neurosym.agent.learners.imitation import LabelBuffer, distill_loss, imitation_update
from neurosym.agent.learners.teacher import load_teacher
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import select_actions
from neurosym.envs import make_batched
from neurosym.errors import ConfigError

TEACHER = "bw1-predinet"  # a shipped name: found from any working directory


def test_distill_loss_is_the_kl_from_the_teachers_probabilities() -> None:
    logits = torch.tensor([[2.0, 0.0, -1.0, 0.5], [0.0, 0.0, 0.0, 0.0]])
    probs = torch.tensor([[0.7, 0.1, 0.1, 0.1], [0.0, 0.0, 1.0, 0.0]])
    p = torch.softmax(logits, -1)
    kl = [sum(q * np.log(q / pp) for q, pp in zip(qs, ps, strict=True) if q > 0)
          for qs, ps in zip(probs.tolist(), p.tolist(), strict=True)]  # fmt: skip
    assert distill_loss(logits, probs).item() == pytest.approx(float(np.mean(kl)), rel=1e-5)
    assert distill_loss(torch.log(probs[:1]), probs[:1]).item() == pytest.approx(0.0, abs=1e-6)


def test_a_checkpoints_labels_are_its_policy_and_its_value_in_returns() -> None:
    agent = load_agent(TEACHER)
    teacher = load_teacher(TEACHER, "bw1", agent.config.obs_shape, agent.config.n_actions)
    venv = make_batched("bw1", 4, seed=2, **agent.env_kwargs)
    obs, _ = venv.reset(seed=2)
    probs, values = teacher.labels(obs)
    with torch.no_grad():
        logits, value = agent.model(torch.from_numpy(obs))
    scale = agent.meta["train_config"]["reward_scale"]
    assert probs.dtype == np.float32 and probs.shape == (4, agent.config.n_actions)
    assert probs == pytest.approx(torch.softmax(logits, -1).numpy(), abs=1e-6)
    assert values == pytest.approx((value / scale).numpy(), rel=1e-5)


def test_a_teacher_of_other_observations_is_refused_in_one_line() -> None:
    with pytest.raises(ConfigError, match=r"^--set teacher=rgw1-predinet: .*rgw"):
        load_teacher("rgw1-predinet", "bw1", (22, 14, 14), 4)
    with pytest.raises(ConfigError, match=r"^--set teacher=nothing.pt: "):
        load_teacher("nothing.pt", "bw1", (22, 14, 14), 4)
    agent = load_agent(TEACHER)
    shape = agent.config.obs_shape
    with pytest.raises(
        ConfigError,
        match=rf"^--set teacher={TEACHER}: it sees observations .* and has 4 actions; this "
        r"run's bw1 has .* and 5: pick a teacher trained on the same observations$",
    ):
        load_teacher(TEACHER, "bw1", shape, 5)


@pytest.mark.expensive
def test_updates_fit_the_teachers_probabilities() -> None:
    """The teacher's network with a fresh policy layer, on a fixed buffer of its labels: the KL
    falls well below its start."""
    agent = load_agent(TEACHER)
    teacher = load_teacher(TEACHER, "bw1", agent.config.obs_shape, agent.config.n_actions)
    venv = make_batched("bw1", 16, seed=4, **agent.env_kwargs)
    obs, _ = venv.reset(seed=4)
    buf = LabelBuffer(256, obs.shape[1:], obs.dtype, agent.config.n_actions)
    rng = np.random.default_rng(0)
    for _ in range(16):
        probs, values = teacher.labels(obs)
        buf.add(obs, probs, values)
        obs, *_ = venv.step(select_actions(torch.from_numpy(probs).log(), False).numpy())
    torch.manual_seed(0)
    model = ActorCritic(agent.config)
    model.load_state_dict(agent.model.state_dict())
    torch.nn.init.normal_(model.policy.weight, std=0.5)
    train = TrainConfig.for_family("boxworld", algo="imitate", teacher=TEACHER,
                                   dagger_batch=128, dagger_steps=10)  # fmt: skip
    opt = torch.optim.Adam(model.parameters(), lr=3e-3)
    first = imitation_update(model, opt, buf, train, rng, torch.device("cpu")).policy_loss
    for _ in range(5):
        last = imitation_update(model, opt, buf, train, rng, torch.device("cpu")).policy_loss
    assert last < 0.5 * first, (first, last)


@pytest.mark.expensive
def test_attend_coef_teaches_head_0_the_key_and_the_lock_it_opens() -> None:
    """Box-World's route targets on the teacher's own network: after a few updates head 0's
    second argument is on the route's next object and, where that is a lock, its first on the
    held key; before, the network (whose attention is near one-hot elsewhere) looked there on
    few states."""
    from neurosym.envs.boxworld_solver import RouteTargets

    agent = load_agent(TEACHER)
    teacher = load_teacher(TEACHER, "bw1", agent.config.obs_shape, agent.config.n_actions)
    venv = make_batched("bw1", 32, seed=6, **agent.env_kwargs)
    obs, _ = venv.reset(seed=6)
    route = RouteTargets()
    buf = LabelBuffer(512, obs.shape[1:], obs.dtype, agent.config.n_actions)
    for _ in range(16):
        probs, values = teacher.labels(obs)
        buf.add(obs, probs, values, targets=route.attention_targets(venv))
        obs, *_ = venv.step(select_actions(torch.from_numpy(probs).log(), False).numpy())
    model = ActorCritic(agent.config)
    model.load_state_dict(agent.model.state_dict())
    targets = buf.targets.astype(np.int64)
    first, second = targets[:, 0] >= 0, targets[:, 1] >= 0
    assert first.sum() > 30 and second.mean() > 0.9

    def hits() -> tuple[float, float]:
        with torch.no_grad():
            _, _, intro = model(torch.from_numpy(buf.obs), introspect=True)
        a1 = intro.attention1[:, 0].argmax(-1).numpy()
        a2 = intro.attention2[:, 0].argmax(-1).numpy()
        return (float((a1 == targets[:, 0])[first].mean()),
                float((a2 == targets[:, 1])[second].mean()))  # fmt: skip

    before = hits()
    train = TrainConfig.for_family("boxworld", algo="imitate", teacher=TEACHER, attend_coef=1.0,
                                   dagger_batch=256, dagger_steps=10)  # fmt: skip
    opt = torch.optim.Adam(model.parameters(), lr=2e-3)
    rng = np.random.default_rng(0)
    torch.manual_seed(0)
    for _ in range(8):
        imitation_update(model, opt, buf, train, rng, torch.device("cpu"))
    after = hits()
    assert after[0] > 0.9 and after[1] > 0.8 and max(before) < 0.5, (before, after)


def test_a_teacher_gives_no_safe_set(
    train_refused: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    proc = train_refused("train", "--env", "rgw-random", "--module", "predinet", "--algo",
                         "imitate", "--set", "teacher=checkpoints/rgw-random-mhdpa.pt",
                         "--safe-coef", "2", "--frames", "10", "--out", tmp_path / "x")  # fmt: skip
    assert proc.returncode != 0
    assert proc.stderr.strip().splitlines() == [
        "neurosym train: error: safe_coef reads the planner's regrets, which a teacher does not "
        "give (leave --safe-coef at 0 with --set teacher=...)"
    ], proc.stderr


@pytest.mark.expensive
def test_train_imitates_a_teacher_on_box_world_and_resumes(
    run_neurosym: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    neurosym = functools.partial(run_neurosym, timeout=180)
    out = tmp_path / "run"
    first = neurosym("train", "--env", "bw1", "--module", "predinet", "--algo", "imitate",
                     "--set", f"teacher={TEACHER}", "--set", "attend_coef=1",
                     "--envs", "4", "--n-steps", "8",
                     "--dagger-steps", "2", "--frames", "100", "--quiet",
                     "--eval-episodes", "2", "--out", out)  # fmt: skip
    assert first.returncode == 0, first.stderr[-2000:]
    payload = read_checkpoint(out / "checkpoint.pt")
    assert payload["train_config"]["teacher"] == TEACHER
    assert payload["train_config"]["attend_coef"] == 1.0  # Box-World's route targets
    assert f"--set teacher={TEACHER}" in payload["command"]
    metrics = (out / "metrics.csv").read_text().splitlines()
    assert len(metrics) >= 2 and float(metrics[-1].split(",")[9]) > 0  # the KL, logged
    frames = int(payload["frames"])
    again = neurosym("train", "--out", out, "--resume", "--frames", frames + 64, "--quiet")
    assert again.returncode == 0, again.stderr[-2000:]
    assert int(read_checkpoint(out / "checkpoint.pt")["frames"]) >= frames + 64
