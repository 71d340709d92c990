"""Writing figures and animations to files, atomically and byte-for-byte reproducibly.

Pictures end up in READMEs and papers and get diffed in git, so identical inputs
must give identical bytes: PNGs carry no timestamp or software tag, SVGs get a
fixed hash salt for their element ids and no date, GIFs are encoded by Pillow
from one palette shared by all frames. Every file is written to a temporary name beside
the target and moved into place, so a crash never leaves half an image.
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Sequence
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from neurosym import atomic
from neurosym.errors import ConfigError

IMAGE_FORMATS = ("png", "svg")
"""formats a still figure can be written in"""

ANIMATION_FORMATS = ("gif",)
"""formats an episode animation can be written in"""

GIF_COLOURS = 64
"""palette size of animations"""

_SVG_SALT = "neurosym"


def image_format(path: str | os.PathLike[str], allowed: Sequence[str]) -> str:
    """The format named by the file's extension, or a one-line error naming the allowed ones."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in allowed:
        names = [f".{a}" for a in allowed]
        wanted = names[0] if len(names) == 1 else ", ".join(names[:-1]) + f" or {names[-1]}"
        raise ConfigError(f"cannot write {os.fspath(path)!r}: the file name must end in {wanted}")
    return suffix


def figure_bytes(fig: Figure, fmt: str, dpi: float) -> bytes:
    """Render ``fig`` as PNG or SVG bytes without timestamps, software tags or random ids."""
    buf = io.BytesIO()
    if fmt == "png":
        fig.savefig(buf, format="png", dpi=dpi, metadata={"Software": None})
    elif fmt == "svg":
        with matplotlib.rc_context({"svg.hashsalt": _SVG_SALT, "svg.fonttype": "path"}):
            fig.savefig(buf, format="svg", dpi=dpi, metadata={"Date": None, "Creator": None})
    else:
        raise ConfigError(
            f"cannot render a figure as {fmt!r}: use one of {', '.join(IMAGE_FORMATS)}"
        )
    return buf.getvalue()


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder and ``os.replace``."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise ConfigError(
            f"cannot write {os.fspath(path)!r}: folder {os.fspath(folder)!r} does not exist"
        )
    return atomic.write_bytes_atomic(target, data)


def save_figure(fig: Figure, path: str | os.PathLike[str], dpi: float = 100) -> Path:
    """Write ``fig`` as PNG or SVG (chosen by the extension) atomically and reproducibly."""
    fmt = image_format(path, IMAGE_FORMATS)
    return write_bytes_atomic(path, figure_bytes(fig, fmt, dpi))


def gif_bytes(frames: Sequence[np.ndarray], fps: float) -> bytes:
    """Encode RGB frames as a looping GIF; one shared palette keeps the colours steady.

    64 colours from a median cut over all frames keep entity and head colours
    recognisable; Pillow's optimiser (deterministic) halves the file.
    """
    from PIL import Image

    if not frames:
        raise ConfigError("an animation needs at least one frame")
    if not math.isfinite(fps) or fps <= 0:
        raise ConfigError(f"--fps must be a positive number, got {fps}")
    # One adaptive palette for the whole film, from all frames side by side.
    sheet = Image.fromarray(np.concatenate(list(frames), axis=1))
    palette = sheet.quantize(
        colors=GIF_COLOURS, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE
    )
    images = [
        Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames
    ]
    buf = io.BytesIO()
    images[0].save(
        buf,
        format="GIF",
        save_all=True,
        append_images=images[1:],
        duration=max(1, round(1000 / fps)),
        loop=0,
        optimize=True,
        disposal=1,
    )
    return buf.getvalue()


def save_gif(frames: Sequence[np.ndarray], path: str | os.PathLike[str], fps: float = 4.0) -> Path:
    """Write RGB frames as an animated GIF, atomically."""
    image_format(path, ANIMATION_FORMATS)
    return write_bytes_atomic(path, gif_bytes(frames, fps))
