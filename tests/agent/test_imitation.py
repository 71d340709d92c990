"""`--algo imitate`: DAgger from the RGW planner -- labels, loss, buffer, an update that learns, the CLI."""

from __future__ import annotations

import functools
import json
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import read_checkpoint
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.evaluation import score
from neurosym.agent.learners.imitation import (
    LabelBuffer,
    expert_share,
    imitation_loss,
    imitation_update,
)
from neurosym.agent.networks.model import ActorCritic
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
    report = score(SetSampler(0), "rgw-random", 48, seed=2000).as_dict()
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


def labelled_buffer(targets: bool = False) -> tuple[LabelBuffer, np.random.Generator]:
    """256 labelled states of rgw-random (8 random steps of 32 levels), and the rng that drew them;
    with ``targets``, each state's next contact on the planner's route too."""
    venv = make_batched("rgw-random", 32, seed=11)
    obs, _ = venv.reset(seed=11)
    planner = Planner()
    buf = LabelBuffer(256, obs.shape[1:], obs.dtype)
    rng = np.random.default_rng(0)
    for _ in range(8):
        sets, values = planner.action_sets(venv)
        buf.add(obs, sets, values, targets=planner.attention_targets(venv) if targets else None)
        obs, *_ = venv.step(rng.integers(0, 4, 32))
    return buf, rng


def seeing_predinet(obs_shape: tuple[int, ...]) -> ActorCritic:
    """The PrediNet that DAgger trains (LayerNorm on entities, attention gain 8, orthogonal init)."""
    cfg = ModelConfig.for_family("rgw", "predinet", tuple(obs_shape),
                                 entity_norm=True, attention_gain=8.0, init="orthogonal")  # fmt: skip
    return ActorCritic(cfg)


@pytest.mark.expensive
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


@pytest.mark.expensive
def test_augmented_updates_fit_the_turned_levels_too() -> None:
    """--augment: fitted on random turns and mirrors, the network also knows the levels turned;
    fitted on the levels as they come, it knows them less well."""
    from neurosym.agent.learners.augment import action_permutation, transform_grid

    buf, _ = labelled_buffer()
    turned_obs = transform_grid(torch.from_numpy(buf.obs), 1, False).contiguous()
    turned_sets = torch.empty(buf.policy.shape, dtype=torch.bool)
    turned_sets[:, list(action_permutation(1, False, 10, 10))] = torch.from_numpy(buf.policy > 0)
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
    with pytest.raises(ConfigError, match="--augment is a setting of --algo imitate; this run.s"):
        TrainConfig.for_family("rgw", augment=True)


def test_imitate_needs_a_planner() -> None:
    with pytest.raises(
        ConfigError,
        match=r"^--algo imitate learns from an env's planner \(RGW's, Minigrid DoorKey's\); "
        r"boxworld has none \(use a3c or ppo, or a trained agent: --set teacher=CHECKPOINT\)$",
    ):
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
    neurosym: Callable[..., subprocess.CompletedProcess[str]],
    neurosym_main: Callable[..., subprocess.CompletedProcess[str]],
    tmp_path: Path,
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
    ev = neurosym_main("eval", "--checkpoint", out / "checkpoint.pt", "--episodes", "4", "--json")
    assert ev.returncode == 0, ev.stderr[-2000:]
    assert json.loads(ev.stdout)["episodes"] == 4


def test_train_imitate_on_box_world_is_one_line(
    train_refused: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    proc = train_refused("train", "--env", "bw1", "--module", "predinet", "--algo", "imitate",
                         "--frames", "10", "--out", tmp_path / "x")  # fmt: skip
    assert proc.returncode != 0
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert lines == [
        "neurosym train: error: --algo imitate learns from an env's planner (RGW's, Minigrid "
        "DoorKey's); boxworld has none (use a3c or ppo, or a trained agent: --set "
        "teacher=CHECKPOINT)"
    ], proc.stderr


def test_regret_names_the_return_each_action_gives_up() -> None:
    """A mountain the free route avoids costs 0.1, a pit the whole terminal, a dawdle nothing."""
    from neurosym.envs.rgw_maps import parse_map
    from neurosym.envs.rgw_solver import Plan, Rules

    level = parse_map("W.W\nMA.\nWP.\nW.T\n")
    plan = Plan(level.cells, np.array([level.start]), level.height, level.width, Rules())
    regret = plan.regret(0, level.start, 0, 100)
    assert regret.dtype == np.float32
    # up: a free cell, back later at no cost; right: the route; down: the pit; left: the mountain
    assert regret.tolist() == pytest.approx([0.0, 0.0, 11.0, 0.1])
    assert plan.action_set(0, level.start, 0, 100).tolist() == [False, True, False, False]
    # three steps left: only the route (right, down, down) still ends on the terminal
    assert plan.regret(0, level.start, 0, 3).tolist() == pytest.approx([10.0, 0.0, 11.0, 10.1])
    # two: no route does; what is left to lose is the pit's -1 and the mountain's -0.1
    assert plan.regret(0, level.start, 0, 2).tolist() == pytest.approx([0.0, 0.0, 1.0, 0.1])


def test_regret_lets_the_agent_walk_to_the_farthest_cell_when_time_is_left() -> None:
    """A corridor: the far end needs every layer of the search, yet with 100 steps left a step
    onto it gives nothing up (V_99 there is the settled value, not the layer before the last)."""
    from neurosym.envs.rgw_maps import parse_map
    from neurosym.envs.rgw_solver import Plan, Rules

    level = parse_map("TA.......\n")
    plan = Plan(level.cells, np.array([level.start]), level.height, level.width, Rules())
    far = level.width - 1
    assert plan.regret(0, far - 1, 0, 100).tolist() == [0.0] * 4
    assert plan.value(0, far, 0, 99) == pytest.approx(10.0)
    # with just the steps to the terminal left, any move but the one toward it costs it
    assert plan.regret(0, far - 1, 0, far - 1).tolist() == pytest.approx([10.0, 10.0, 10.0, 0.0])


def test_labels_add_regrets_that_vanish_on_the_optimal_sets() -> None:
    venv = make_batched("rgw-random", 32, seed=5)
    venv.reset(seed=5)
    planner = Planner()
    critical = 0
    for _ in range(12):
        sets, values, regret = planner.labels(venv)
        same_sets, same_values = planner.action_sets(venv)
        assert (sets == same_sets).all() and (values == same_values).all()
        assert planner.labels(venv, regret=False)[2] is None
        assert regret.shape == (32, 4) and (regret >= 0).all() and (regret[sets] == 0).all()
        critical += int((regret.max(1) > 0).sum())
        venv.step(sets.argmax(1))
    assert critical > 0  # some states let an action give return up


def test_safe_coef_adds_the_loss_of_the_set_that_gives_nothing_up() -> None:
    """With safe_coef C the policy loss is the fastest set's plus C times the safe set's."""
    buf = LabelBuffer(4, (9, 10, 10), np.uint8)
    optimal = np.array([[True, False, False, False]] * 4)
    safe = np.array([[True, True, False, False]] * 4)
    buf.add(np.zeros((4, 9, 10, 10), np.uint8), optimal, np.zeros(4, "f4"), safe)
    assert (buf.safe[:4] == safe).all()
    model = seeing_predinet((9, 10, 10))
    with torch.no_grad():
        logits = model(torch.zeros(1, 9, 10, 10))[0]
    fast = imitation_loss(logits, torch.from_numpy(optimal[:1])).item()
    kept = imitation_loss(logits, torch.from_numpy(safe[:1])).item()
    losses = {}
    for coef in (0.0, 3.0):
        train = TrainConfig.for_family(
            "rgw", algo="imitate", dagger_batch=4, dagger_steps=1, safe_coef=coef, lr=1e-12
        )
        opt = torch.optim.Adam(model.parameters(), lr=1e-12)
        rng = np.random.default_rng(0)
        stats = imitation_update(model, opt, buf, train, rng, torch.device("cpu"))
        losses[coef] = stats.policy_loss
    assert losses[0.0] == pytest.approx(fast, rel=1e-4)
    assert losses[3.0] == pytest.approx(fast + 3.0 * kept, rel=1e-4)
    with pytest.raises(ConfigError, match="--safe-coef is a setting of --algo imitate; this run's learner is a3c"):
        TrainConfig.for_family("rgw", safe_coef=1.0)
    with pytest.raises(ConfigError, match=r"^safe_coef must be a finite number in \[0, 100\], got -1.0$"):
        TrainConfig.for_family("rgw", algo="imitate", safe_coef=-1.0)


def test_augmented_safe_sets_turn_with_the_optimal_sets() -> None:
    """Stacked (B, 4, 2) sets move as one: each column pair stays with its action."""
    from neurosym.agent.learners.augment import augment_batch

    optimal = torch.tensor([[True, False, False, False], [False, False, True, False]])
    safe = torch.tensor([[True, True, False, False], [False, True, True, True]])
    for seed in range(8):
        obs = torch.zeros(2, 9, 10, 10)
        gen = torch.Generator().manual_seed(seed)
        _, moved = augment_batch(obs, torch.stack((optimal, safe), -1), gen)
        o, s = moved.unbind(-1)
        assert (o.sum(1) == 1).all() and (s.sum(1) == safe.sum(1)).all()
        assert (s | ~o).all()  # the fastest action stays inside the safe set


def test_next_contact_walks_the_route_object_by_object() -> None:
    """Sword, enemy, the teleport end entered (not the one landed on), then the terminal."""
    from neurosym.envs.rgw_maps import parse_map
    from neurosym.envs.rgw_solver import Plan, Rules

    level = parse_map("A.S.\nWWW.\nO..E\nWWWW\nT..O\n")
    plan = Plan(level.cells, np.array([level.start]), level.height, level.width, Rules())
    assert plan.next_contact(0, level.start, 0, 100) == 2  # the sword
    assert plan.next_contact(0, 2, 0b01, 98) == 11  # holding it: the enemy
    assert plan.next_contact(0, 11, 0b11, 94) == 8  # then the teleport end it walks into
    assert plan.next_contact(0, 19, 0b11, 91) == 16  # landed on the other end: the terminal
    assert plan.next_contact(0, 19, 0b11, 2) == -1  # too few steps left to reach anything


def test_next_contacts_name_the_cell_of_every_contact_the_planner_makes() -> None:
    from neurosym.envs import rgw_rules as rules

    contact = (
        rules.EV_TELEPORTED | rules.EV_PICKED | rules.EV_DEFEATED | rules.EV_HURT
        | rules.EV_PIT | rules.EV_TERMINAL
    )  # fmt: skip
    venv = make_batched("rgw-random", 16, seed=8)
    venv.reset(seed=8)
    planner = Planner()
    env = venv.unwrapped
    entered, _ = rules.cell_geometry(env.height, env.width)
    checked = 0
    for _ in range(60):
        targets = planner.next_contacts(venv)
        assert targets.dtype == np.int16 and targets.shape == (16,)
        pos = env.agent_states()[0].copy()
        actions = planner(None, venv)
        _, _, _, _, info = venv.step(actions)
        for i in np.flatnonzero(info["events"] & contact):
            assert targets[i] == entered[actions[i], pos[i]]
            checked += 1
    assert checked > 40


def test_the_attention_target_moves_with_the_augmented_level() -> None:
    from neurosym.agent.learners.imitation import augment_with_targets

    obs = torch.zeros(64, 3, 5, 5, dtype=torch.uint8)
    targets = torch.randint(-1, 25, (64, 2))  # head 0's two arguments
    has = targets >= 0
    for k in range(2):  # mark each column's cells on a plane of its own
        obs[:, 1 + k].view(64, -1)[has[:, k].nonzero()[:, 0], targets[has[:, k], k]] = 1
    assert int(obs.sum()) == int(has.sum())
    sets = torch.zeros(64, 4, 2, dtype=torch.bool)
    seen = set()
    for seed in range(12):
        g = torch.Generator().manual_seed(seed)
        turned, _, moved = augment_with_targets(obs, sets, targets, g)
        assert turned.shape == obs.shape and moved.shape == (64, 2)
        assert ((moved >= 0) == has).all()
        for k in range(2):
            flat = turned[:, 1 + k].reshape(64, -1)
            rows = has[:, k]
            assert (flat[rows, moved[rows, k]] == 1).all()  # the mark went where the target went
        seen.add(tuple(moved.flatten().tolist()))
    assert len(seen) > 2  # the levels were turned


def test_attention_target_loss_is_the_mean_nll_of_the_rows_with_a_target() -> None:
    from neurosym.agent.learners.imitation import attention_target_nll

    a = torch.tensor([[0.5, 0.25, 0.25], [0.1, 0.1, 0.8], [1 / 3, 1 / 3, 1 / 3]])
    got = attention_target_nll(a.log() + 7.0, torch.tensor([0, -1, 2]))  # scores: any offset
    assert got.item() == pytest.approx((np.log(2) + np.log(3)) / 2, rel=1e-5)
    assert attention_target_nll(a.log(), torch.tensor([-1, -1, -1])).item() == 0.0


def test_attention_target_loss_moves_a_saturated_head() -> None:
    """A head whose softmax puts ~0 on the target (far below float32's smallest normal) still
    gets a gradient towards it: the loss reads the scores, not the probabilities."""
    from neurosym.agent.learners.imitation import attention_target_nll

    scores = torch.tensor([[200.0, 0.0, 0.0]], requires_grad=True)
    assert torch.softmax(scores, -1)[0, 1].item() == 0.0
    attention_target_nll(scores, torch.tensor([1])).backward()
    assert scores.grad[0, 1].item() == pytest.approx(-1.0)
    assert scores.grad[0, 0].item() == pytest.approx(1.0)


@pytest.mark.expensive
def test_attend_coef_teaches_head_0_to_attend_the_next_object() -> None:
    """With the attention target, head 0's second argument moves onto the planner's next
    object (cell keys with coordinates tell two teleport ends apart); without it, it does not."""
    buf, _ = labelled_buffer(targets=True)
    assert (buf.targets[:, 1] >= 0).mean() > 0.9 and (buf.targets[:, 0] == -1).all()
    hits = {}
    for coef in (0.0, 1.0):
        torch.manual_seed(0)
        cfg = ModelConfig.for_family("rgw", "predinet", tuple(buf.obs.shape[1:]), keys="cells_xy",
                                     entity_norm=True, attention_gain=8.0)  # fmt: skip
        model = ActorCritic(cfg)
        train = TrainConfig.for_family("rgw", algo="imitate", dagger_batch=256, dagger_steps=10,
                                       attend_coef=coef)  # fmt: skip
        opt = torch.optim.Adam(model.parameters(), lr=2e-3)
        step_rng = np.random.default_rng(0)
        for _ in range(8):
            imitation_update(model, opt, buf, train, step_rng, torch.device("cpu"))
        with torch.no_grad():
            _, _, intro = model(torch.from_numpy(buf.obs), introspect=True)
        picked = intro.attention2[:, 0].argmax(-1).numpy()
        second = buf.targets[:, 1]
        has = second >= 0
        hits[coef] = float((picked[has] == second[has]).mean())
    assert hits[1.0] > 0.8 and hits[0.0] < 0.5, hits


def test_attend_coef_needs_a_predinet_on_a_routed_env(
    train_refused: Callable[..., subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    for env, module in (("rgw-random", "mhdpa"), ("MiniGrid-DoorKey-5x5-v0", "predinet")):
        proc = train_refused("train", "--env", env, "--module", module, "--algo", "imitate",
                             "--set", "attend_coef=1", "--out", tmp_path / env)  # fmt: skip
        family = "rgw" if env == "rgw-random" else "minigrid"
        assert proc.returncode != 0
        lines = [line for line in proc.stderr.splitlines() if line.strip()]
        assert lines == [
            f"neurosym train: error: attend_coef teaches PrediNet head 0 the next object on an "
            f"RGW or Box-World route; this run is {module} on {family} (leave it at 0)"
        ]
