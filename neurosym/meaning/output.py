"""The meaning commands' products into their output folder (``neurosym probe``, ``intervene``).

A thin adapter over :mod:`neurosym.publish`, which ``neurosym extract`` uses
too: products are written in a staging folder, then each moved in by one
rename; anything else in the folder is left alone.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path

from neurosym.publish import check_out
from neurosym.publish import publish as publish_staged

__all__ = ["check_out", "publish"]


def publish(out: Path, products: Mapping[str, Callable[[Path], object]]) -> dict[str, Path]:
    """Call ``write(stage / name)`` for every product, then rename each into ``out``."""

    def write(stage: Path) -> None:
        for name, write_one in products.items():
            write_one(stage / name)

    folders = [name for name in products if "." not in name]
    return publish_staged(out, write, folders=folders, prefix=".meaning-")
