"""What the relational modules show when asked (``forward(obs, introspect=True)``).

Named fields instead of positions, so the recorder and the plots read
``intro.attention1`` rather than ``intro[0]``. Fields are torch tensors when
they come from the model and numpy arrays after :meth:`numpy` (what
``Agent.act`` returns). Entity ``k`` is grid cell ``k`` in row-major order.
"""

from __future__ import annotations

from typing import Any, NamedTuple


def _to_numpy(value: Any) -> Any:
    return value.detach().cpu().numpy() if hasattr(value, "detach") else value


class PrediNetIntrospection(NamedTuple):
    """Per-head PrediNet internals; B batch, H heads, N entities, J relations."""

    attention1: Any
    """(B, H, N) softmax weights a1 of the first attended entity (rows sum to 1)"""
    attention2: Any
    """(B, H, N) softmax weights a2 of the second attended entity"""
    relations: Any
    """(B, H, J) D^h = E1 W_S - E2 W_S, antisymmetric in the two entities"""
    positions1: Any
    """(B, H, 2) attention-weighted (row, col) in [0, 1] of E1"""
    positions2: Any
    """(B, H, 2) attention-weighted (row, col) in [0, 1] of E2"""

    def r_vectors(self) -> Any:
        """(B, H, J + 4) R^h = [D^h, pos(E1), pos(E2)] (torch or numpy, like the fields)."""
        parts = (self.relations, self.positions1, self.positions2)
        if hasattr(self.relations, "detach"):
            import torch

            return torch.cat(parts, dim=-1)
        import numpy as np

        return np.concatenate(parts, axis=-1)

    def numpy(self) -> PrediNetIntrospection:
        """The same record with numpy arrays."""
        return PrediNetIntrospection(*(_to_numpy(v) for v in self))


class MHDPAIntrospection(NamedTuple):
    """MHDPA self-attention weights; B batch, H heads, N entities."""

    attention: Any
    """(B, H, N, N) query x key softmax weights, each row sums to 1"""

    def numpy(self) -> MHDPAIntrospection:
        """The same record with numpy arrays."""
        return MHDPAIntrospection(*(_to_numpy(v) for v in self))


Introspection = PrediNetIntrospection | MHDPAIntrospection
