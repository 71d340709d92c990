"""A user's own PyTorch agent, taken through neurosym with no neurosym code changed.

    neurosym extract --checkpoint examples/own_agent/my_agent.py:make_agent --episodes 20

The network plays MiniGrid-DoorKey-5x5-v0 (neurosym's fully observed observation: 31 one-hot
planes of the 5 x 5 grid). It reads each grid cell as a token, lets the cells attend to each other with an
nn.MultiheadAttention, and pools them into action logits and a value. make_agent() is all
neurosym needs: the network, the env it plays and the name of its attention layer.
"""

import os

import torch
from torch import nn

from neurosym.outside import TorchAgent


class CellAttentionNet(nn.Module):
    def __init__(self, channels: int = 31, width: int = 32, heads: int = 2, actions: int = 7):
        super().__init__()
        self.embed = nn.Conv2d(channels, width, kernel_size=3, padding=1)  # one token per cell
        self.attn = nn.MultiheadAttention(width, heads, batch_first=True)
        self.pi, self.v = nn.Linear(width, actions), nn.Linear(width, 1)

    def forward(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        x = torch.relu(self.embed(obs)).flatten(2).transpose(1, 2)  # (B, cells, width)
        y, _ = self.attn(x, x, x)
        h = (x + y).amax(dim=1)
        return self.pi(h), self.v(h).squeeze(-1)


def make_agent() -> TorchAgent:
    net = CellAttentionNet()
    weights = os.environ.get("MY_AGENT_WEIGHTS")  # a state dict saved by your own training
    if weights:
        net.load_state_dict(torch.load(weights, weights_only=True))
    return TorchAgent(net, env="MiniGrid-DoorKey-5x5-v0", attention="attn")


def make_rgw2_agent() -> TorchAgent:
    """The same network on rgw2 (9 planes, 4 actions), where `neurosym intervene` also runs."""
    return TorchAgent(CellAttentionNet(channels=9, actions=4), env="rgw2", attention="attn")
