"""The agent network: shapes, batch size 1, introspection, PrediNet antisymmetry, MHDPA attention."""

from __future__ import annotations

import pytest
import torch

from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.networks.encoder import Encoder, coordinates
from neurosym.agent.networks.introspection import MHDPAIntrospection, PrediNetIntrospection
from neurosym.agent.networks.model import ActorCritic
from neurosym.errors import ConfigError

RGW = ((9, 10, 10), "rgw", 1.0)
BW = ((3, 14, 14), "boxworld", 1 / 255)


def make(
    module: str, shape=RGW[0], family: str = "rgw", scale: float = 1.0, seed: int = 0, **kw
) -> ActorCritic:
    torch.manual_seed(seed)
    return ActorCritic(ModelConfig.for_family(family, module, shape, scale, **kw))


def obs_batch(batch: int, shape, seed: int = 1) -> torch.Tensor:
    g = torch.Generator().manual_seed(seed)
    high = 2 if shape[0] > 3 else 256
    return torch.randint(0, high, (batch, *shape), generator=g, dtype=torch.uint8)


@pytest.mark.parametrize("module", ["predinet", "mhdpa"])
@pytest.mark.parametrize("env", [RGW, BW], ids=["rgw", "boxworld"])
@pytest.mark.parametrize("batch", [1, 3])
def test_forward_shapes(module: str, env, batch: int) -> None:
    shape, family, scale = env
    net = make(module, shape, family, scale)
    N = shape[1] * shape[2]
    logits, value = net(obs_batch(batch, shape))
    assert logits.shape == (batch, 4) and value.shape == (batch,)
    logits, value, intro = net(obs_batch(batch, shape), introspect=True)
    H = net.config.heads
    if module == "predinet":
        J = net.config.relations
        assert isinstance(intro, PrediNetIntrospection)
        assert intro.attention1.shape == intro.attention2.shape == (batch, H, N)
        assert intro.relations.shape == (batch, H, J)
        assert intro.positions1.shape == intro.positions2.shape == (batch, H, 2)
        assert intro.r_vectors().shape == (batch, H, J + 4)
        assert intro.numpy().r_vectors().shape == (batch, H, J + 4)
    else:
        assert isinstance(intro, MHDPAIntrospection)
        assert intro.attention.shape == (batch, H, N, N)


def test_table4_defaults_per_family() -> None:
    rgw = ModelConfig.for_family("rgw", "predinet", (9, 10, 10))
    bw = ModelConfig.for_family("boxworld", "mhdpa", (3, 14, 14), 1 / 255, preset="thesis")
    assert (rgw.heads, rgw.key_size, rgw.relations, rgw.output_size) == (4, 32, 8, 26)
    assert (bw.key_size, bw.value_size, bw.conv_channels, bw.hidden_sizes) == (
        64,
        64,
        (12, 24),
        (256, 128, 64),
    )
    assert rgw.entity_size == 26
    assert (TrainConfig.for_family("rgw").lr, TrainConfig.for_family("rgw").entropy) == (2e-3, 0.02)
    thesis = TrainConfig.for_family("boxworld", preset="thesis")
    assert (thesis.lr, thesis.entropy) == (2e-4, 0.01)
    assert ModelConfig.for_family("boxworld", "mhdpa", (26, 14, 14)).key_size == 32  # default
    assert ModelConfig.for_family("rgw", "predinet", (9, 10, 10), relations=4).relations == 4


def test_config_round_trip_and_errors() -> None:
    cfg = ModelConfig.for_family("boxworld", "mhdpa", (3, 14, 14), 1 / 255, heads=2)
    data = cfg.to_dict()
    assert all(not isinstance(v, tuple) for v in data.values())
    assert ModelConfig.from_dict(data) == cfg
    with pytest.raises(ConfigError, match="unknown module 'lstm'"):
        ModelConfig(module="lstm", obs_shape=(1, 2, 2))
    with pytest.raises(ConfigError, match="unknown ModelConfig keys: colour"):
        ModelConfig.from_dict({**data, "colour": 1})
    with pytest.raises(ConfigError, match=r"^heads must be an integer in \[1, 64\], got 0$"):
        ModelConfig(module="predinet", obs_shape=(1, 4, 4), heads=0)
    with pytest.raises(ConfigError, match="unknown env family"):
        TrainConfig.for_family("atari")


def test_wrong_observation_shape_is_one_clear_error() -> None:
    net = make("predinet")
    with pytest.raises(ConfigError, match=r"shape \(B, 9, 10, 10\), got \(2, 3, 14, 14\)"):
        net(obs_batch(2, (3, 14, 14)))


@pytest.mark.parametrize("module", ["predinet", "mhdpa"])
def test_introspection_does_not_change_logits(module: str) -> None:
    net = make(module)
    obs = obs_batch(4, RGW[0])
    logits, value = net(obs)
    logits_i, value_i, _ = net(obs, introspect=True)
    assert torch.equal(logits, logits_i) and torch.equal(value, value_i)
    # batch size 1 gives the same numbers as the same row inside a batch
    one, _ = net(obs[2:3])
    torch.testing.assert_close(one, logits[2:3], rtol=1e-5, atol=1e-6)


def test_predinet_relations_antisymmetric_when_attentions_swap() -> None:
    net = make("predinet")
    obs = obs_batch(3, RGW[0])
    _, _, a = net(obs, introspect=True)
    rel = net.relational
    with torch.no_grad():
        w1, w2 = rel.query1.weight.clone(), rel.query2.weight.clone()
        rel.query1.weight.copy_(w2)
        rel.query2.weight.copy_(w1)
    _, _, b = net(obs, introspect=True)
    assert torch.equal(b.attention1, a.attention2) and torch.equal(b.attention2, a.attention1)
    assert torch.equal(b.relations, -a.relations)
    assert torch.equal(b.positions1, a.positions2) and torch.equal(b.positions2, a.positions1)
    assert a.relations.abs().max() > 0


def test_predinet_attention_and_positions() -> None:
    net = make("predinet")
    _, _, intro = net(obs_batch(2, RGW[0]), introspect=True)
    for att in (intro.attention1, intro.attention2):
        torch.testing.assert_close(att.sum(-1), torch.ones(2, 4))
    # positions are the attention-weighted cell coordinates
    coords = coordinates(10, 10)
    torch.testing.assert_close(intro.positions1, intro.attention1 @ coords)
    assert (
        float(intro.positions2.min().detach()) >= 0 and float(intro.positions2.max().detach()) <= 1
    )


def test_mhdpa_attention_rows_sum_to_one_and_fold_is_exact() -> None:
    net = make("mhdpa")
    obs = obs_batch(2, RGW[0])
    logits, _, intro = net(obs, introspect=True)
    torch.testing.assert_close(intro.attention.sum(-1), torch.ones(2, 4, 100))
    # the folded weights compute the textbook multi-head attention of the same parameters
    m = net.relational
    x = net.encoder(obs.float())
    B, N, F = x.shape
    H, D, V = m.heads, m.key_size, m.value_size
    q = m.query(x).view(B, N, H, D).transpose(1, 2)
    k = m.key(x).view(B, N, H, D).transpose(1, 2)
    v = m.value(x).view(B, N, H, V).transpose(1, 2)
    att = torch.softmax(q @ k.transpose(-1, -2) / D**0.5, dim=-1)
    torch.testing.assert_close(att, intro.attention, rtol=1e-4, atol=1e-6)
    y = m.norm1(x + m.proj((att @ v).transpose(1, 2).reshape(B, N, H * V)))
    y = m.norm2(y + m.mlp(y)).amax(dim=1)
    ref = net.policy(net.body(y))
    torch.testing.assert_close(ref, logits, rtol=1e-4, atol=1e-6)


def test_encoder_entity_k_is_cell_k() -> None:
    enc = Encoder(1, 5, 7, (12, 24), 2)
    torch.nn.init.constant_(enc.convs[0].bias, 0.0)
    torch.nn.init.constant_(enc.convs[1].bias, 0.0)
    for conv in enc.convs:
        torch.nn.init.constant_(conv.weight, 1.0)
    x = torch.zeros(1, 1, 5, 7)
    x[0, 0, 2, 3] = 1.0
    out = enc(x)
    assert out.shape == (1, 35, 26)
    lit = (out[0, :, :24].abs().sum(-1) > 0).view(5, 7).nonzero().tolist()
    # one lit cell reaches exactly its 3 x 3 neighbourhood, centred on itself
    assert lit == [[r, c] for r in (1, 2, 3) for c in (2, 3, 4)]
    # coordinate channels: entity k = (k // W, k % W), scaled to [0, 1]
    torch.testing.assert_close(out[0, 17, 24:], torch.tensor([2 / 4, 3 / 6]))


def test_gradients_reach_every_parameter() -> None:
    for module in ("predinet", "mhdpa"):
        net = make(module)
        logits, value = net(obs_batch(2, RGW[0]))
        (logits.logsumexp(-1).sum() + value.sum()).backward()
        missing = [
            n for n, p in net.named_parameters() if p.grad is None or not p.grad.abs().sum() > 0
        ]
        assert missing == [], module


def _reference_attention(L, w_q, w_k, scale):
    """PrediNet's attention as plain autograd computes it (the hand-written backward's oracle):
    a, e and the scores."""
    B, N, F = L.shape
    q = (L.reshape(B, N * F) @ w_q.t()).view(B, -1, w_k.shape[0])
    scores = ((q @ w_k) * scale) @ L.transpose(1, 2)
    a = torch.softmax(scores, dim=-1)
    return a, a @ L, scores


def test_predinet_attention_backward_matches_autograd() -> None:
    from neurosym.agent.networks.predinet import PrediNetAttention

    g = torch.Generator().manual_seed(0)
    B, N, F, H, D = 3, 7, 5, 2, 4
    L = torch.randn(B, N, F, dtype=torch.float64, generator=g, requires_grad=True)
    w_q = torch.randn(2 * H * D, N * F, dtype=torch.float64, generator=g, requires_grad=True)
    w_k = torch.randn(D, F, dtype=torch.float64, generator=g, requires_grad=True)
    mine = lambda *x: PrediNetAttention.apply(*x, 0.7)  # noqa: E731
    assert torch.autograd.gradcheck(lambda *x: mine(*x)[:2], (L, w_q, w_k))
    assert torch.autograd.gradcheck(lambda *x: (mine(*x)[1], mine(*x)[3]), (L, w_q, w_k))
    # and equal to autograd's own gradients, for a loss on e alone, on a and e, on the scores
    for use in ("e", "a", "scores"):
        grads = []
        for fn in (mine, _reference_attention):
            a, e, *rest = fn(L, w_q, w_k, 0.7) if fn is _reference_attention else fn(L, w_q, w_k)
            loss = (e * torch.linspace(-1, 1, e.numel(), dtype=e.dtype).view_as(e)).sum()
            if use == "a":
                loss = loss + (a[:, :, 0] ** 2).sum()
            if use == "scores":
                loss = loss - torch.log_softmax(rest[-1], -1)[:, :, 1].sum()
            grads.append(torch.autograd.grad(loss, (L, w_q, w_k)))
        for got, ref in zip(*grads, strict=True):
            torch.testing.assert_close(got, ref)


def test_recorded_queries_give_the_same_update_and_go_stale_with_the_weights() -> None:
    """A3C's update takes back the queries acting computed; same logits and gradients, and a
    record made with other weights is ignored."""
    net = make("predinet")
    obs = obs_batch(12, RGW[0])
    with torch.no_grad(), net.recording() as record:
        for part in obs.split(4):
            net(part)
    assert record is not None and len(record.parts) == 3

    def update(queries):
        net.zero_grad()
        logits, value = net(torch.cat([obs, obs_batch(2, RGW[0], seed=5)]), queries=queries)
        (logits.logsumexp(-1).sum() + value.sum()).backward()
        return logits.detach(), [p.grad.clone() for p in net.parameters()]

    fresh, reused = update(None), update(record)
    torch.testing.assert_close(reused[0], fresh[0])
    for a, b in zip(reused[1], fresh[1], strict=True):
        torch.testing.assert_close(a, b, rtol=1e-4, atol=1e-6)
    with torch.no_grad():
        net.relational.query1.weight.mul_(2.0)  # the record is now stale
    stale = update(record)
    changed = update(None)
    torch.testing.assert_close(stale[0], changed[0])
    assert not torch.allclose(stale[0], fresh[0])
    assert make("mhdpa").recording().__enter__() is None  # nothing to record


def test_learned_queries_are_one_vector_for_every_scene() -> None:
    """ModelConfig.query "learned": no query projection, the same Q for every scene, the same
    gradients as plain autograd, and heads that still attend by what is in each scene."""
    from neurosym.agent.networks.predinet import PrediNetAttention

    net = make("predinet", query="learned")
    rel = net.relational
    names = {n for n, _ in rel.named_parameters()}
    assert "queries" in names and not any(n.startswith("query1") for n in names)
    assert rel.queries.shape == (2 * 4 * 32,)
    obs = obs_batch(3, RGW[0])
    _, _, intro = net(obs, introspect=True)
    # same queries, different scenes: different attentions (keys read each entity)
    assert not torch.allclose(intro.attention1[0], intro.attention1[1])
    g = torch.Generator().manual_seed(0)
    L = torch.randn(3, 7, 5, dtype=torch.float64, generator=g, requires_grad=True)
    q = torch.randn(2 * 2 * 4, dtype=torch.float64, generator=g, requires_grad=True)
    w_k = torch.randn(4, 5, dtype=torch.float64, generator=g, requires_grad=True)
    mine = lambda L, q, w_k: PrediNetAttention.apply(L, None, w_k, 0.7, None, q)[:2]  # noqa: E731
    assert torch.autograd.gradcheck(mine, (L, q, w_k))
    scores = lambda L, q, w_k: PrediNetAttention.apply(L, None, w_k, 0.7, None, q)[3]  # noqa: E731
    assert torch.autograd.gradcheck(scores, (L, q, w_k))
    a, e = mine(L, q, w_k)
    ref = torch.softmax(((q.view(1, -1, 4) @ w_k) * 0.7) @ L.transpose(1, 2), dim=-1)
    torch.testing.assert_close(a, ref)
    torch.testing.assert_close(e, ref @ L)
    # A3C's query record has nothing to keep and the update's forward is unchanged
    with torch.no_grad(), net.recording() as record:
        net(obs)
    assert record is not None and record.parts == []
    torch.testing.assert_close(net(obs, queries=record)[0], net(obs)[0])


@pytest.mark.parametrize(
    ("name", "unknown", "expected", "switch", "refusal", "default"),
    [
        ("query", "flat", "scene, learned", "learned", "mhdpa's queries", "scene"),
        ("keys", "pixels", "entities, cells", "cells", "mhdpa's keys come from", "entities"),
    ],
)
def test_predinet_switches_are_predinet_only_and_old_configs_read_as_the_default(
    name: str, unknown: str, expected: str, switch: str, refusal: str, default: str
) -> None:
    with pytest.raises(
        ConfigError, match=f"unknown {name} '{unknown}'; expected one of {expected}"
    ):
        ModelConfig(module="predinet", obs_shape=(3, 4, 4), **{name: unknown})
    with pytest.raises(ConfigError, match=f"{name} '{switch}' is PrediNet's; {refusal}"):
        ModelConfig(module="mhdpa", obs_shape=(3, 4, 4), **{name: switch})
    data = ModelConfig.for_family("rgw", "predinet", RGW[0]).to_dict()
    del data[name]  # a checkpoint from before the switch
    assert getattr(ModelConfig.from_dict(data), name) == default


@pytest.mark.parametrize("query", ["scene", "learned"])
def test_cell_keys_address_cells_by_what_they_hold(query: str) -> None:
    """ModelConfig.keys "cells": K = c W_K from each cell's observation, no coordinates, so two
    cells holding the same thing get the same attention weight in every head, while the
    attended vectors are the encoder's entities; plain autograd reaches W_K."""
    net = make("predinet", keys="cells", query=query, conv_channels=(8, 8, 8), kernel_size=3)
    rel = net.relational
    assert rel.key.weight.shape == (32, RGW[0][0])  # W_K reads a cell's 9 planes
    obs = torch.zeros((2, *RGW[0]), dtype=torch.uint8)
    obs[:, 1] = 1  # every cell empty (plane 1) ...
    obs[:, 1, 2, 3] = obs[:, 1, 7, 7] = obs[:, 1, 5, 1] = 0
    obs[:, 0, 2, 3] = 1  # ... but the agent's
    obs[:, 4, 7, 7] = obs[:, 4, 5, 1] = 1  # and two cells of one kind
    logits, _, intro = net(obs, introspect=True)
    for att in (intro.attention1[0], intro.attention2[0]):  # (H, N)
        a = att.reshape(-1, 10, 10)
        torch.testing.assert_close(a[:, 7, 7], a[:, 5, 1])  # same content, same weight
        torch.testing.assert_close(a[:, 0, 0], a[:, 9, 9])  # two empty cells
        assert not torch.allclose(a[:, 2, 3], a[:, 0, 0])  # the agent is told apart
    # the same with entity keys: the encoder's view (and the coordinates) tell the cells apart
    plain = make("predinet", query=query, conv_channels=(8, 8, 8), kernel_size=3)
    a = plain(obs, introspect=True)[2].attention1[0].reshape(-1, 10, 10)
    assert not torch.allclose(a[:, 0, 0], a[:, 9, 9])
    logits.sum().backward()
    assert rel.key.weight.grad is not None and rel.key.weight.grad.abs().sum() > 0
    # nothing to record for A3C: the queries are recomputed in the update's forward
    assert net.recording().__enter__() is None


def test_switching_keys_keeps_every_weight_but_w_k() -> None:
    """checkpoint.build_model(..., keys="cells") (what --init-from --keys cells builds): W_K
    starts afresh with the cells' width, every other weight is the source's."""
    from neurosym.agent.checkpoint import build_model

    source = make("predinet", conv_channels=(8, 8, 8), kernel_size=3)
    payload = {"model_config": source.config, "state_dict": source.state_dict()}
    torch.manual_seed(5)
    switched = build_model(payload, "source.pt", keys="cells")
    assert switched.config.keys == "cells" and source.config.keys == "entities"
    new = switched.state_dict()
    assert set(new) == set(payload["state_dict"])
    for name, weight in payload["state_dict"].items():
        if name == "relational.key.weight":
            assert weight.shape == (32, 10) and new[name].shape == (32, 9)  # 8 + 2 coords
        else:
            torch.testing.assert_close(new[name], weight, rtol=0, atol=0)
    same = build_model(payload, "source.pt", keys="entities")  # no switch: a plain load
    torch.testing.assert_close(same.relational.key.weight, source.relational.key.weight)


def test_cells_xy_keys_tell_two_cells_of_one_kind_apart_and_start_as_cell_keys() -> None:
    """ModelConfig.keys "cells_xy": W_K reads each cell's planes and its two coordinates, so a
    head can weigh two teleport ends differently; switched from cell keys (build_model), the
    coordinates' columns start at zero: the same attention and the same outputs."""
    from neurosym.agent.checkpoint import build_model

    torch.manual_seed(2)
    source = make("predinet", keys="cells", conv_channels=(8, 8, 8), kernel_size=3)
    payload = {"model_config": source.config, "state_dict": source.state_dict()}
    switched = build_model(payload, "source.pt", keys="cells_xy")
    assert switched.relational.key.weight.shape == (32, RGW[0][0] + 2)
    obs = torch.zeros((2, *RGW[0]), dtype=torch.uint8)
    obs[:, 1] = 1
    obs[:, 1, 7, 7] = obs[:, 1, 5, 1] = obs[:, 1, 2, 3] = 0
    obs[:, 0, 2, 3] = 1
    obs[:, 4, 7, 7] = obs[:, 4, 5, 1] = 1  # two teleport ends
    with torch.no_grad():
        before, after = source(obs, introspect=True), switched(obs, introspect=True)
        torch.testing.assert_close(after[0], before[0])
        torch.testing.assert_close(after[2].attention2, before[2].attention2)
        switched.relational.key.weight[:, -2:].normal_()  # now the coordinates count
        a = switched(obs, introspect=True)[2].attention2[0].reshape(-1, 10, 10)
    assert not torch.allclose(a[:, 7, 7], a[:, 5, 1])


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"keys": "cells"},
        {"keys": "cells_xy"},
        {"query": "learned"},
        {"relation_bits": 0.25},
        {"keys": "cells_xy", "query": "scene_mlp"},
    ],
)
def test_scores_are_those_of_the_attention_the_heads_use(kw) -> None:
    """The hook point ``scores`` (what the attention target's loss reads) has the recorded
    attentions as its softmax and equals PrediNet.attention_logits, for every query and key
    mode (the hand-written attention's and autograd's)."""
    from neurosym.agent.networks.hooks import cache

    model = make("predinet", **kw)
    obs = torch.randint(0, 2, (3, *RGW[0]), dtype=torch.uint8)
    seen = []
    hook = model.relational.register_forward_pre_hook(lambda m, args: seen.append(args))
    with torch.no_grad(), cache(model.relational, ["scores"]) as values:
        _, _, intro = model(obs, introspect=True)
        args = seen[-1]
        logits = model.relational.attention_logits(args[0], args[3] if len(args) > 3 else None)
    hook.remove()
    H = model.relational.heads
    scores = values["scores"]
    assert scores.shape == (3, 2 * H, RGW[0][1] * RGW[0][2])
    a = torch.softmax(scores, dim=-1)
    torch.testing.assert_close(a[:, :H], intro.attention1)
    torch.testing.assert_close(a[:, H:], intro.attention2)
    torch.testing.assert_close(logits, scores)


def test_mlp_queries_start_as_the_scene_queries_and_need_cell_keys() -> None:
    """query "scene_mlp": flat(L) W_Q plus an MLP whose output layer starts at zero, so a fresh
    network with the same other weights attends as the scene queries do; trained, it moves the
    attention. Entity keys are refused in one line."""
    from neurosym.errors import ConfigError

    torch.manual_seed(0)
    linear = make("predinet", keys="cells_xy")
    mlp = make("predinet", keys="cells_xy", query="scene_mlp")
    missing = mlp.load_state_dict(linear.state_dict(), strict=False).missing_keys
    assert sorted(missing) == [f"relational.query_mlp.{n}" for n in ("0.bias", "0.weight", "2.bias", "2.weight")]
    obs = torch.randint(0, 2, (4, *RGW[0]), dtype=torch.uint8)
    with torch.no_grad():
        a, b = linear(obs, introspect=True)[2], mlp(obs, introspect=True)[2]
        torch.testing.assert_close(b.attention2, a.attention2)
        mlp.relational.query_mlp[2].weight.normal_()
        c = mlp(obs, introspect=True)[2]
    assert not torch.allclose(c.attention2, a.attention2)
    with pytest.raises(ConfigError, match="query 'scene_mlp' needs cell keys"):
        make("predinet", query="scene_mlp")
