"""CNN encoder: observation grid -> one entity vector per grid cell.

Two conv layers (Table 4: 12 and 24 channels, kernel 2, stride 1, ReLU). A
kernel of 2 cannot be padded symmetrically, so the first layer pads right and
bottom and the second pads left and top: the map keeps the grid's shape and
entity k (cell k, row-major) sees the 3 x 3 neighbourhood centred on its own
cell (for kernel 2). Two coordinate channels (row, col scaled to [0, 1]) are
appended last, so an entity has ``channels[-1] + 2`` features (26 by default).

``norm=True`` (ModelConfig.entity_norm) puts a LayerNorm over each entity's
conv features (not its coordinates). Table 4's network has none, and on
Box-World's RGB input its entities start small and alike, so that the
relational module's attention starts uniform and the policy blind
(experiments/diagnose.py measures both).
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn


def _pads(kernel: int, layer: int) -> tuple[int, int, int, int]:
    """F.pad widths (left, right, top, bottom): alternate which side gets the extra cell."""
    extra = kernel - 1
    low, high = extra // 2, extra - extra // 2
    if layer % 2 == 1:
        low, high = high, low
    return (low, high, low, high)


def coordinates(height: int, width: int) -> torch.Tensor:
    """(H * W, 2) row and column of every cell, row-major, scaled to [0, 1]."""
    rows = torch.arange(height, dtype=torch.float32) / max(height - 1, 1)
    cols = torch.arange(width, dtype=torch.float32) / max(width - 1, 1)
    grid = torch.stack(torch.meshgrid(rows, cols, indexing="ij"), dim=-1)  # (H, W, 2)
    return grid.reshape(height * width, 2)


class Encoder(nn.Module):
    """(B, C, H, W) float -> (B, H * W, channels[-1] + 2) entities."""

    def __init__(
        self,
        in_channels: int,
        height: int,
        width: int,
        channels: tuple[int, ...],
        kernel: int,
        norm: bool = False,
    ) -> None:
        super().__init__()
        sizes = (in_channels, *channels)
        self.convs = nn.ModuleList(
            nn.Conv2d(a, b, kernel) for a, b in zip(sizes[:-1], sizes[1:], strict=True)
        )
        self.pads = [_pads(kernel, i) for i in range(len(channels))]
        self.register_buffer("coords", coordinates(height, width), persistent=False)
        self.norm = nn.LayerNorm(channels[-1]) if norm else None

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        # channels-last: oneDNN's convolutions run a third faster forward and
        # backward on these small maps, and the entities below are then a view
        x = x.contiguous(memory_format=torch.channels_last)
        for conv, pad in zip(self.convs, self.pads, strict=True):
            x = F.relu(conv(F.pad(x, pad)))  # (B, c, H, W)
        B, C, H, W = x.shape
        entities = x.permute(0, 2, 3, 1).reshape(B, H * W, C)  # (B, N, C), cell k row-major
        if self.norm is not None:
            entities = self.norm(entities)  # (B, N, C) zero mean, unit variance per entity
        coords = self.coords.expand(B, H * W, 2)  # (B, N, 2)
        return torch.cat([entities, coords], dim=-1)  # (B, N, C + 2)
