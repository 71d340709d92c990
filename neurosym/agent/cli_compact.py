"""``neurosym compact``: a smaller copy of a checkpoint for shipping (half-precision weights).

The weights are stored as float16 (or bfloat16) and the optimizer state is
left out; the model still computes in float32 once loaded. The command
prints the sizes and the largest change of a weight; playing both files with
``neurosym eval`` on the same seeds tells whether the agent's behaviour moved.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Literal

from neurosym.flags import Out, add_options, option


@dataclass(kw_only=True)
class CompactOptions(Out):
    """``neurosym compact``'s options."""

    checkpoint: str = option(metavar="CHECKPOINT", positional=True)
    """checkpoint file (.pt) to compact"""
    dtype: Literal["bfloat16", "float16"] = "float16"
    """storage dtype of the weights"""
    out: str = option(metavar="FILE")
    """file to write (may be the checkpoint itself: replaced atomically)"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, CompactOptions)


def run(args: CompactOptions) -> int:
    from neurosym.agent.checkpoint import compact_checkpoint

    report = compact_checkpoint(args.checkpoint, args.out, args.dtype)
    before, after = report["bytes_before"], report["bytes_after"]
    print(
        f"wrote {args.out}: {before / 1e6:.2f} MB -> {after / 1e6:.2f} MB "
        f"(weights as {args.dtype}, no optimizer state; largest weight change "
        f"{report['max_change']:.2g})"
    )
    return 0
