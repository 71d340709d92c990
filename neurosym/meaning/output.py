"""The meaning commands' products into their output folder (``neurosym probe``, ``intervene``).

A thin adapter over :mod:`neurosym.publish`, which ``neurosym extract`` uses
too: products are written in a new run folder, then published together by
one rename; anything else in the folder is left alone.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path

from neurosym.publish import check_out
from neurosym.publish import publish as publish_staged

__all__ = ["check_out", "publish"]


def publish(out: Path, products: Mapping[str, Callable[[Path], object]]) -> dict[str, Path]:
    """Call ``write(run / name)`` for every product, then publish them together in ``out``."""

    def write(stage: Path) -> None:
        for name, write_one in products.items():
            write_one(stage / name)

    return publish_staged(out, write, owned=products)
