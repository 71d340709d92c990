"""Head ablation from outside the model: hooks change only the ablated head's part.

Also: the per-head vectors come back exactly by replaying a recording.
"""

from __future__ import annotations

import numpy as np
import pytest
import torch

from neurosym.agent.networks.hooks import cache
from neurosym.errors import ConfigError
from neurosym.meaning.features import (
    ablate_heads,
    capture_heads,
    head_means,
    head_vectors,
    replay_observations,
)


@pytest.fixture(scope="session")
def agent(small_agent):  # noqa: ANN201
    """``agent(...)``, built from the shared builders."""
    def agent(module: str):  # noqa: ANN201

        return small_agent("rgw2", module)
    return agent


def observations(n: int = 6) -> np.ndarray:
    from neurosym.envs import make_batched

    venv = make_batched("rgw2", n, seed=0)
    obs, _ = venv.reset(seed=0)
    for a in (1, 1, 2):
        obs, *_ = venv.step(np.full(n, a))
    return np.concatenate([obs, venv.reset(seed=0)[0]])


def test_predinet_ablation_replaces_only_that_heads_slice(agent) -> None:
    model = agent("predinet").model
    obs = torch.from_numpy(observations())
    with torch.inference_mode(), capture_heads(model) as got:
        logits = model(obs)[0]
    plain = got[0]  # (B, H, J + 4)
    value = torch.arange(plain.shape[-1], dtype=torch.float32)
    with torch.inference_mode(), ablate_heads(model, {1: value}), capture_heads(model) as got:
        ablated_logits = model(obs)[0]
    ablated = got[0]
    assert torch.equal(ablated[:, 0], plain[:, 0])
    assert torch.equal(ablated[:, 1], value.expand_as(plain[:, 1]))
    assert not torch.equal(logits, ablated_logits)
    with torch.inference_mode():  # hooks are gone afterwards
        assert torch.equal(model(obs)[0], logits)


def _mhdpa_values(model, obs: torch.Tensor) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    """The MHDPA's input x and its head_out and resid_mid hook values on ``obs``."""
    rel = model.relational
    seen = {}
    handle = rel.register_forward_pre_hook(lambda m, a: seen.__setitem__("x", a[0]))
    try:
        with torch.inference_mode(), cache(rel, ["head_out", "resid_mid"]) as values:
            model(obs)
    finally:
        handle.remove()
    return seen["x"], values


def test_mhdpa_head_outputs_are_what_enters_norm1(agent) -> None:
    model = agent("mhdpa").model
    x, values = _mhdpa_values(model, torch.from_numpy(observations()))
    heads = values["head_out"]  # (B, H, N, F)
    assert heads.shape[:2] == (x.shape[0], model.relational.heads)
    torch.testing.assert_close(
        x + heads.sum(1) + model.relational.proj.bias, values["resid_mid"], atol=1e-5, rtol=1e-5
    )


def test_mhdpa_ablation_swaps_only_that_heads_output(agent) -> None:
    model = agent("mhdpa").model
    rel = model.relational
    obs = torch.from_numpy(observations())
    N, F = obs.shape[-2] * obs.shape[-1], rel.query.in_features
    value = torch.full((N, F), 0.25)
    _, plain_values = _mhdpa_values(model, obs)
    with ablate_heads(model, {0: value}):
        _, ablated_values = _mhdpa_values(model, obs)
    head0 = plain_values["head_out"][:, 0]
    torch.testing.assert_close(
        ablated_values["resid_mid"] - plain_values["resid_mid"], value - head0,
        atol=1e-5, rtol=1e-5,
    )  # fmt: skip
    with ablate_heads(model, {0: value}), torch.inference_mode(), capture_heads(model) as got:
        model(obs)
    with torch.inference_mode(), capture_heads(model) as plain:
        model(obs)
    assert torch.equal(got[0][:, 1], plain[0][:, 1])  # the other head is untouched
    torch.testing.assert_close(got[0][:, 0], value.amax(0).expand_as(got[0][:, 0]))
    with torch.inference_mode():  # the hooks are gone afterwards: the plain forward again
        assert torch.equal(model(obs)[0], model(obs)[0])
        assert not rel.hook_head_out.active


def test_ablation_with_the_heads_own_output_changes_nothing(agent) -> None:
    model = agent("predinet").model
    obs = observations(1)[:1]  # one state: its R vectors are their own mean
    means = head_means(model, obs)
    _, p = head_vectors(model, obs)
    with ablate_heads(model, means):
        _, q = head_vectors(model, obs)
    np.testing.assert_allclose(p, q, atol=1e-6)


def test_unknown_head_is_refused(agent) -> None:
    model = agent("predinet").model
    with pytest.raises(ConfigError, match="head 7 does not exist"):
        with ablate_heads(model, {7: torch.zeros(7)}):
            pass


def test_replay_gives_back_the_recorded_r_vectors(agent, scripted_recording) -> None:

    rec = scripted_recording("predinet")
    a = agent("predinet")
    obs = replay_observations(rec, "rgw2", rec.meta["env_kwargs"])
    vecs, _ = head_vectors(a.model, obs)
    recorded = rec.r_vectors.sort_values(["episode", "t", "head", "j"])["value"].to_numpy()
    np.testing.assert_allclose(vecs.reshape(-1), recorded, atol=1e-6)


def test_replay_with_another_time_limit_or_map_is_refused(scripted_recording) -> None:

    rec = scripted_recording("predinet")
    from neurosym.envs.rgw_maps import load_map

    walled = load_map("rgw2").text().replace("A....", "AW...", 1)  # a wall right of the start
    with pytest.raises(ConfigError, match="episode 0 does not replay on rgw2 at step 1"):
        replay_observations(rec, "rgw2", {**rec.meta["env_kwargs"], "map": walled})
    with pytest.raises(ConfigError, match="episode 3 does not replay on rgw2 at step 26"):
        replay_observations(rec, "rgw2", {"max_steps": 25})
