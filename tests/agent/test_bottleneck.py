"""The fact bottleneck (ModelConfig.relation_bits): the policy reads only what holds/5 says.

A tiny PrediNet on rgw2 with relation_bits=tau: its read-out sees, per head, the bits
[D_j > tau], [D_j < -tau] and the observations of the two attended cells, nothing else; its
checkpoint records tau; and ``neurosym extract`` writes, with threshold(J, tau), holds/5 facts
that are exactly those bits.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import save_checkpoint
from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.hooks import hooked
from neurosym.agent.networks.model import ActorCritic
from neurosym.envs import make
from neurosym.errors import ConfigError

TAU = 0.03  # not a float32: the forward and extract must round it alike


def tiny_config(tau: float | None = TAU, keys: str = "entities") -> ModelConfig:
    """rgw2's observation, a 2-head PrediNet of 3 relations, small layers."""
    env = make("rgw2")
    shape = tuple(env.observation_space.shape)
    env.close()
    return ModelConfig.for_family(
        "rgw", "predinet", shape, heads=2, key_size=4, relations=3, conv_channels=(4, 8),
        hidden_sizes=(16,), relation_bits=tau, keys=keys, entity_norm=True, attention_gain=8.0,
    )  # fmt: skip


def rgw2_states(n: int = 6) -> torch.Tensor:
    """n observations of an rgw2 episode under fixed random actions."""
    env = make("rgw2")
    obs, _ = env.reset(seed=0)
    states = [obs]
    rng = np.random.default_rng(0)
    while len(states) < n:
        obs, _, term, trunc, _ = env.step(int(rng.integers(4)))
        states.append(obs)
        if term or trunc:
            obs, _ = env.reset()
    env.close()
    return torch.as_tensor(np.stack(states))


def keep_sides(d: torch.Tensor, tau: float, gen: torch.Generator) -> torch.Tensor:
    """Other relation values on the same side of every threshold: above tau, in [-tau, tau],
    below -tau each stay where they were."""
    u = torch.rand(d.shape, generator=gen) * 2.0 + 0.05  # (0.05, 2.05)
    t = torch.tensor(tau, dtype=d.dtype)
    above = t + (d - t).abs() * u + 1e-3
    inside = torch.rand(d.shape, generator=gen) * 1.8 * t - 0.9 * t
    return torch.where(d > t, above, torch.where(d < -t, -above, inside))


def test_relation_bits_round_trip_through_a_checkpoint_and_old_ones_read_as_off(
    tmp_path: Path,
) -> None:
    config = tiny_config()
    torch.manual_seed(0)
    model = ActorCritic(config)
    path = tmp_path / "bits.pt"
    save_checkpoint(path, model=model, config=config, env_name="rgw2")
    agent = load_agent(path)
    assert agent.config.relation_bits == TAU
    assert agent.model.relational.relation_bits == float(np.float32(TAU)) != TAU
    obs = rgw2_states()
    with torch.no_grad():
        assert torch.equal(agent.model(obs)[0], model(obs)[0])
    stored = config.to_dict()
    del stored["relation_bits"]  # a checkpoint from before the setting
    assert ModelConfig.from_dict(stored).relation_bits is None
    with pytest.raises(ConfigError, match="relation_bits is PrediNet's"):
        ModelConfig.for_family("rgw", "mhdpa", config.obs_shape, relation_bits=0.5)


@pytest.mark.parametrize("keys", ["entities", "cells"])
def test_logits_and_value_depend_only_on_which_side_of_the_threshold(keys: str) -> None:
    torch.manual_seed(1)
    model = ActorCritic(tiny_config(keys=keys)).eval()
    obs = rgw2_states()
    gen = torch.Generator().manual_seed(2)

    def run(replace):
        with torch.no_grad(), hooked(model.relational, [("relations", replace)]):
            return model(obs)

    logits, value = run(lambda d: None)
    with torch.no_grad():
        d = model(obs, introspect=True)[2].relations
    moved = keep_sides(d, TAU, gen)
    assert not torch.allclose(moved, d)
    same_logits, same_value = run(lambda _: moved)
    assert torch.equal(same_logits, logits) and torch.equal(same_value, value)
    # positions are not read either: the attended cells' coordinates moved, nothing changes
    with torch.no_grad(), hooked(model.relational, [("positions1", lambda p: p.flip(-1) * 0.3)]):
        assert torch.equal(model(obs)[0], logits)
    flipped = d.clone()
    flipped[:, 0, 0] = torch.where(d[:, 0, 0] > TAU, -1.0, 1.0)  # relation 0 of head 0 crosses
    other_logits, _ = run(lambda _: flipped)
    assert not torch.equal(other_logits, logits)


def test_without_the_bottleneck_the_same_perturbation_changes_the_logits() -> None:
    torch.manual_seed(1)
    model = ActorCritic(tiny_config(tau=None)).eval()
    obs = rgw2_states()
    with torch.no_grad():
        logits, _, intro = model(obs, introspect=True)
        moved = keep_sides(intro.relations, TAU, torch.Generator().manual_seed(2))
        with hooked(model.relational, [("relations", lambda _: moved)]):
            assert not torch.equal(model(obs)[0], logits)


def test_gradients_reach_the_predinet_and_the_encoder_through_the_bits() -> None:
    torch.manual_seed(3)
    model = ActorCritic(tiny_config())
    logits, value = model(rgw2_states())
    (torch.log_softmax(logits, -1)[:, 1].sum() + value.sum()).backward()
    for name in (
        "relational.embed.weight",  # W_S: only through the bits' surrogate
        "relational.key.weight",  # W_K: through the soft attention
        "relational.query1.weight",
        "relational.query2.weight",
        "encoder.convs.0.weight",
        "relational.out.weight",
    ):
        grad = dict(model.named_parameters())[name].grad
        assert grad is not None and grad.abs().sum() > 0, name


def read_out_inputs(model: ActorCritic, obs: torch.Tensor) -> torch.Tensor:
    """What PrediNet's read-out layer was given on ``obs``: (B, H, 2 J + 2 C)."""
    seen: list[torch.Tensor] = []
    handle = model.relational.out.register_forward_hook(lambda _m, args, _o: seen.append(args[0]))
    try:
        with torch.no_grad():
            logits = model(obs)[0]
    finally:
        handle.remove()
    return seen[0].view(obs.shape[0], model.config.heads, -1), logits


@pytest.mark.expensive
def test_extract_writes_holds_facts_that_are_the_bits_the_policy_read(
    tmp_path: Path, neurosym_main
) -> None:
    config = tiny_config()
    torch.manual_seed(4)
    model = ActorCritic(config).eval()
    path = tmp_path / "bits.pt"
    save_checkpoint(path, model=model, config=config, env_name="rgw2")
    out = tmp_path / "kb"
    done = neurosym_main(
        "extract", "--checkpoint", path, "--episodes", 2, "--seed", 5, "--greedy",
        "--format", "pl,parquet", "--out", out, "--quiet",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    facts = out / "facts"
    tau = float(np.float32(TAU))
    thresholds = pd.read_parquet(facts / "threshold.parquet")
    assert thresholds["value"].tolist() == [tau] * 3
    assert f"threshold(0,{tau!r})." in (out / "kb.pl").read_text().replace(" ", "")
    attends = pd.read_parquet(facts / "attends.parquet").set_index(["episode", "t", "head", "arg"])
    kb = {tuple(r) for r in pd.read_parquet(facts / "holds.parquet")[
        ["episode", "t", "j", "a", "b"]].itertuples(index=False)}  # fmt: skip

    # replay the greedy episodes and read the bits where the policy reads them
    J, C, H = config.relations, config.obs_shape[0], config.heads
    read: set[tuple] = set()
    cells_checked = 0
    env = make("rgw2")
    for episode in range(2):
        obs, _ = env.reset(seed=5 + episode)
        for t in range(200):
            x = torch.as_tensor(obs)[None]
            seen, logits = read_out_inputs(model, x)
            for h in range(H):
                args = [attends.loc[(episode, t, h, arg)] for arg in (1, 2)]
                for arg, row in zip((1, 2), args, strict=True):  # the cell read is the one named
                    cell = seen[0, h, 2 * J + (arg - 1) * C : 2 * J + arg * C]
                    assert torch.equal(cell, x[0, :, int(row["row"]), int(row["col"])].float())
                    cells_checked += 1
                a, b = (str(row["entity"]) for row in args)
                for j in range(J):
                    if seen[0, h, j] == 1:
                        read.add((episode, t, j, a, b))
                    if seen[0, h, J + j] == 1:
                        read.add((episode, t, j, b, a))
                assert set(seen[0, h, : 2 * J].tolist()) <= {0.0, 1.0}
            obs, _, term, trunc, _ = env.step(int(logits.argmax()))
            if term or trunc:
                break
    env.close()
    assert cells_checked == int(attends.shape[0])
    assert len(kb) > 20 and read == kb
