"""A third relational module is one file plus its registration.

The module below (self-attention over the cells with torch's nn.MultiheadAttention)
declares its hook points and registers an adapter; nothing else in the package
changes, and an untrained agent with it goes through extract (KB written), a rule
query through KnowledgeBase, head ablation and the report page.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import torch
import torch.nn.functional as F_
from torch import nn

from neurosym.agent.config import ModelConfig
from neurosym.agent.networks import adapters
from neurosym.agent.networks.hooks import HookPoint, introspected
from neurosym.agent.networks.introspection import MHDPAIntrospection
from neurosym.errors import ConfigError


class TorchAttention(nn.Module):
    """(B, N, F) entities -> (B, output_size): one nn.MultiheadAttention block, max-pooled."""

    def __init__(self, entity_size: int, heads: int, output_size: int) -> None:
        super().__init__()
        self.heads = heads
        self.attn = nn.MultiheadAttention(entity_size, heads, batch_first=True)
        self.out = nn.Linear(entity_size, output_size)
        self.hook_attention = HookPoint()  # (B, H, N, N) query x key
        self.hook_head_out = HookPoint()  # (B, H, N, F / H) each head's attended values

    def forward(self, x: torch.Tensor, introspect: bool = False):
        if not introspect:
            return self._forward(x), None
        return introspected(self, MHDPAIntrospection, lambda: self._forward(x))

    def _forward(self, x: torch.Tensor) -> torch.Tensor:
        B, N, F = x.shape
        H = self.heads
        _, att = self.attn(x, x, x, need_weights=True, average_attn_weights=False)
        att = self.hook_attention(att)
        w_v, b_v = self.attn.in_proj_weight[2 * F :], self.attn.in_proj_bias[2 * F :]
        v = F_.linear(x, w_v, b_v).view(B, N, H, F // H).transpose(1, 2)  # (B, H, N, F / H)
        heads = self.hook_head_out(att @ v)
        y = self.attn.out_proj(heads.transpose(1, 2).reshape(B, N, F))
        return self.out((x + y).amax(dim=1))


class TorchAttentionAdapter(adapters.AttentionAdapter):
    name = "torch_attention"
    label = "torch attention"
    article = "a torch attention"
    head_point = "head_out"

    @classmethod
    def build(cls, config: ModelConfig) -> nn.Module:
        return TorchAttention(config.entity_size, config.heads, config.output_size)

    def head_vector(self, value: torch.Tensor) -> torch.Tensor:
        return value.detach().amax(dim=2)


@pytest.fixture
def registered() -> Iterator[None]:
    adapters.register(TorchAttentionAdapter)
    try:
        yield
    finally:
        adapters.unregister(TorchAttentionAdapter.name)


def _checkpoint(path: Path) -> Path:
    from neurosym.agent.checkpoint import save_checkpoint
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.envs import make

    probe = make("rgw2")
    torch.manual_seed(0)
    config = ModelConfig.for_family(
        "rgw", "torch_attention", probe.observation_space.shape, probe.unwrapped.obs_scale,
        heads=2, key_size=8, conv_channels=(4, 8), hidden_sizes=(16,),
    )  # fmt: skip
    model = ActorCritic(config).eval()
    return save_checkpoint(path, model=model, config=config, env_name="rgw2",
                           env_kwargs={"max_steps": 12})  # fmt: skip


def test_a_registered_module_goes_through_extract_query_ablation_and_report(
    registered: None, tmp_path: Path
) -> None:
    from neurosym.agent.agent import load_agent
    from neurosym.cli import main
    from neurosym.envs import make
    from neurosym.meaning.features import ablate_heads, head_vectors
    from neurosym.prolog.knowledge_base import KnowledgeBase
    from neurosym.record.recording import Recording

    path = _checkpoint(tmp_path / "attention.pt")
    out = tmp_path / "extract"
    code = main(["extract", "--checkpoint", str(path), "--episodes", "2", "--format",
                 "pl,parquet", "--out", str(out), "--quiet"])  # fmt: skip
    assert code == 0
    rec = Recording.load(out / "recording")
    assert rec.meta["module"] == "torch_attention" and rec.meta["relations"] == 0
    assert len(rec.attention) > 0 and rec.attends.empty
    assert set(rec.attention["head"]) == {0, 1}
    with KnowledgeBase(out / "kb.pl", rules=["relations"]) as kb:
        assert [row["H"] for row in kb.query("head(H)")] == [0, 1]
        assert kb.query("kb_meta(module, M)")[0]["M"] == "torch_attention"

    agent = load_agent(path)
    env = make("rgw2")
    obs = np.stack([env.reset(seed=s)[0] for s in range(3)])
    plain, _ = head_vectors(agent.model, obs)  # (S, H, F / H)
    assert plain.shape == (3, 2, agent.config.entity_size // 2)
    with ablate_heads(agent.model, {1: torch.zeros(agent.config.n_entities, agent.config.entity_size // 2)}):
        ablated, _ = head_vectors(agent.model, obs)
    np.testing.assert_array_equal(ablated[:, 0], plain[:, 0])
    np.testing.assert_array_equal(ablated[:, 1], 0.0)

    assert main(["report", "--recording", str(out), "--quiet"]) == 0
    page = (out / "index.html").read_text()
    assert "torch_attention, 2 heads" in page
    assert "torch attention computes no relation values" in page


def test_an_unregistered_module_is_refused_by_name() -> None:
    with pytest.raises(ConfigError, match="unknown module 'torch_attention'; expected one of"):
        adapters.adapter_class("torch_attention")
