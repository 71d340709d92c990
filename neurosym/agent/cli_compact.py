"""``neurosym compact``: a smaller copy of a checkpoint for shipping (half-precision weights).

The weights are stored as float16 (or bfloat16) and the optimizer state is
left out; the model still computes in float32 once loaded. The command
prints the sizes and the largest change of a weight; playing both files with
``neurosym eval`` on the same seeds tells whether the agent's behaviour moved.
"""

from __future__ import annotations

import argparse

from neurosym.agent.checkpoint import COMPACT_DTYPES


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("checkpoint", help="checkpoint file (.pt) to compact")
    parser.add_argument(
        "--out",
        required=True,
        help="file to write (may be the checkpoint itself: replaced atomically)",
    )
    parser.add_argument(
        "--dtype",
        choices=sorted(COMPACT_DTYPES),
        default="float16",
        help="storage dtype of the weights (default float16)",
    )


def run(args: argparse.Namespace) -> int:
    from neurosym.agent.checkpoint import compact_checkpoint

    report = compact_checkpoint(args.checkpoint, args.out, args.dtype)
    before, after = report["bytes_before"], report["bytes_after"]
    print(
        f"wrote {args.out}: {before / 1e6:.2f} MB -> {after / 1e6:.2f} MB "
        f"(weights as {args.dtype}, no optimizer state; largest weight change "
        f"{report['max_change']:.2g})"
    )
    return 0
