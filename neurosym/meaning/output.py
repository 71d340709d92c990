"""Writing a command's products into its output folder: staged, then each moved in by one rename.

Only the products' own names are replaced in the folder; anything else there
is left alone, and a failed run leaves nothing half-written (a folder the run
created is removed again).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path

from neurosym.errors import ConfigError


def check_out(out: Path) -> Path:
    """Refuse an --out that exists and is not a folder."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} exists and is not a folder")
    return out


def publish(out: Path, products: Mapping[str, Callable[[Path], object]]) -> dict[str, Path]:
    """Call ``write(stage / name)`` for every product, then rename each into ``out``."""
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".meaning-", dir=out))
    ok = False
    try:
        for name, write in products.items():
            write(stage / name)
        written: dict[str, Path] = {}
        for name in products:
            src, dst = stage / name, out / name
            if src.is_dir():
                old = None
                if dst.exists():
                    old = dst.with_name(f".{dst.name}.old-{os.getpid()}")
                    shutil.rmtree(old, ignore_errors=True)
                    os.replace(dst, old)
                os.replace(src, dst)
                if old is not None:
                    shutil.rmtree(old, ignore_errors=True)
            else:
                os.replace(src, dst)
            written[name] = dst
        ok = True
        return written
    finally:
        shutil.rmtree(stage, ignore_errors=True)
        if created and not ok:
            shutil.rmtree(out, ignore_errors=True)
