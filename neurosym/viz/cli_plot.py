"""``neurosym plot``: attention maps, R-vector heat maps, relation histograms, episode films.

Every subcommand draws from one of two sources:

* ``--checkpoint FILE [--env NAME] [--episode-seed S]`` plays one greedy
  episode from ``reset(seed=S)`` with the model's introspection on (full maps);
* ``--recording DIR [--episode E]`` reads a recording saved by
  ``neurosym extract`` / ``Recording.save`` (attention keeps only the strongest cells).

and writes ``--out FILE`` (.png or .svg; ``episode`` also .gif). Identical
inputs give identical bytes. The subcommands are thin wrappers over the
functions in :mod:`neurosym.viz`.
"""

from __future__ import annotations

import argparse
from typing import Any

_SUBCOMMANDS = {
    "mhdpa": "MHDPA: per head, the attention of one object on every cell and of every cell on it.",
    "predinet": "PrediNet: per head, the attention maps a1 and a2 over the grid at one step.",
    "rvectors": "PrediNet: the R vector of every head at every step of an episode, as a heat map.",
    "relations": "PrediNet: each relation's distribution of values, its threshold marked.",
    "episode": "An episode as a strip of states (PNG/SVG) or an animated GIF, with route and head arrows.",
    "probes": "Probe selectivity (accuracy - control), heads x predicates, from `neurosym probe`.",
}


_STEP_PLOTS = ("mhdpa", "predinet")
"""plots of one state (--step)"""
_OBJECT_PLOTS = ("mhdpa",)
"""plots of one object's attention (--object, --cell)"""

MIN_DPI, MAX_DPI = 1, 1200
"""--dpi range: a 4-head figure at 1200 dpi is about 12,700 pixels wide (matplotlib's limit: 65,536)"""


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the plot subcommands and their options."""
    sub = parser.add_subparsers(dest="plot", metavar="PLOT", required=True)
    for name, help_text in _SUBCOMMANDS.items():
        cmd = sub.add_parser(name, help=help_text, description=help_text)
        if name == "probes":
            _probes_options(cmd)
            continue
        _source_options(cmd, gif=name == "episode")
        if name in _STEP_PLOTS:
            cmd.add_argument("--step", type=int, default=0, help="state to show (default: 0)")
        if name in _OBJECT_PLOTS:
            which = cmd.add_mutually_exclusive_group()
            which.add_argument(
                "--object",
                default=None,
                help="entity or object id whose attention to draw: agent, enemy, key(red), lock_red_2 (default: agent)",
            )
            which.add_argument(
                "--cell",
                type=_cell,
                default=None,
                metavar="ROW,COL",
                help="pick the object by its cell instead (for walls, pits, ...)",
            )
        if name != "relations":
            cmd.add_argument("--head", type=int, default=None, help="draw one head (default: all)")
        if name in ("rvectors", "episode"):
            cmd.add_argument(
                "--max-steps",
                type=int,
                default=None,
                metavar="N",
                help="with --checkpoint: stop the episode after this many steps (default: the env's limit)",
            )
        if name == "relations":
            cmd.add_argument(
                "--threshold",
                default="quantile:0.9",
                help="abs:X, quantile:Q or z:K, as for extract (default: quantile:0.9)",
            )
            cmd.add_argument(
                "--episodes",
                type=int,
                default=None,
                help="with --checkpoint: episodes to play, seeds S, S+1, ... (default: 1)",
            )
        if name == "episode":
            cmd.add_argument(
                "--steps",
                default=None,
                metavar="START:STOP",
                help="states to draw, inclusive, e.g. 0:20 (default: all)",
            )
            cmd.add_argument(
                "--frames",
                type=int,
                default=12,
                help="PNG/SVG strip: states shown, evenly spaced (default: 12)",
            )
            cmd.add_argument(
                "--every", type=int, default=1, help="GIF: draw every k-th state (default: 1)"
            )
            cmd.add_argument(
                "--fps", type=float, default=4.0, help="GIF: frames per second (default: 4)"
            )


def _probes_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument(
        "--probes", required=True, metavar="DIR", help="a `neurosym probe` output folder"
    )
    cmd.add_argument(
        "--relation",
        default="all",
        help="relation to show: all (the whole vector), 0, 1, ... or best (default: all)",
    )
    cmd.add_argument("--top", type=int, default=25, help="predicates shown at most (default: 25)")
    cmd.add_argument("--out", required=True, metavar="FILE", help="image to write (.png or .svg)")
    cmd.add_argument(
        "--dpi", type=float, default=100.0, help="resolution of PNG output (default: 100)"
    )


def _source_options(cmd: argparse.ArgumentParser, *, gif: bool) -> None:
    source = cmd.add_mutually_exclusive_group(required=True)
    source.add_argument("--checkpoint", metavar="FILE", help="play this checkpoint (greedy)")
    source.add_argument("--recording", metavar="DIR", help="read this saved recording")
    cmd.add_argument(
        "--env", default=None, help="with --checkpoint: environment (default: the checkpoint's)"
    )
    cmd.add_argument(
        "--episode-seed",
        type=int,
        default=None,
        metavar="S",
        help="with --checkpoint: reset seed of the episode (default: 0)",
    )
    cmd.add_argument(
        "--episode",
        type=int,
        default=None,
        metavar="E",
        help="with --recording: episode number (default: the first)",
    )
    kinds = ".png, .svg or .gif" if gif else ".png or .svg"
    cmd.add_argument("--out", required=True, metavar="FILE", help=f"image to write ({kinds})")
    cmd.add_argument(
        "--dpi", type=float, default=100.0, help="resolution of PNG output (default: 100)"
    )


def _cell(text: str) -> tuple[int, int]:
    try:
        row, col = (int(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected ROW,COL such as 3,9, got {text!r}") from None
    return row, col


def run(args: argparse.Namespace) -> int:
    """Load the source, draw the requested picture and write it."""
    from neurosym.display import plain
    from neurosym.errors import ConfigError
    from neurosym.viz.output import ANIMATION_FORMATS, IMAGE_FORMATS, image_format

    allowed = IMAGE_FORMATS + (ANIMATION_FORMATS if args.plot == "episode" else ())
    fmt = image_format(args.out, allowed)
    if not MIN_DPI <= args.dpi <= MAX_DPI:  # NaN fails too
        raise ConfigError(f"--dpi must be a number from {MIN_DPI} to {MAX_DPI}, got {args.dpi:g}")
    if getattr(args, "step", 0) < 0:
        raise ConfigError(f"--step must be 0 or more, got {args.step}")
    if args.plot == "probes":
        from neurosym.viz.output import save_figure
        from neurosym.viz.probes import load_probe_table, probes_figure

        if args.top < 1:
            raise ConfigError(f"--top must be at least 1, got {args.top}")
        fig = probes_figure(load_probe_table(args.probes), args.relation, args.top)
        path = save_figure(fig, args.out, dpi=args.dpi)
        print(f"wrote {plain(args.out)} ({_pixels(path) if fmt == 'png' else 'svg'})")
        return 0
    source = _load_source(args)
    written = _draw(args, source, fmt)
    print(f"wrote {plain(args.out)} ({written})")
    return 0


def _load_source(args: argparse.Namespace) -> Any:
    from neurosym.errors import ConfigError

    if args.recording is not None:
        played = (
            ("--env", args.env),
            ("--episode-seed", args.episode_seed),
            ("--max-steps", getattr(args, "max_steps", None)),
            ("--episodes", getattr(args, "episodes", None)),
        )
        for flag, value in played:
            if value is not None:
                raise ConfigError(f"{flag} goes with --checkpoint; a recording already fixes it")
        from neurosym.export.recording import Recording

        return Recording.load(args.recording)
    if args.episode is not None:
        raise ConfigError(
            "--episode goes with --recording; with --checkpoint pick the episode by --episode-seed"
        )
    from neurosym.agent.checkpoint import load_agent

    return load_agent(args.checkpoint)


def _draw(args: argparse.Namespace, source: Any, fmt: str) -> str:
    """Draw and write; returns a short description of what was written."""
    from neurosym.viz import attention, episode, predinet, relations
    from neurosym.viz.output import save_figure

    where = {"episode": args.episode, "seed": args.episode_seed or 0}
    figures = {
        "mhdpa": lambda: attention.mhdpa_figure(
            source, args.env, step=args.step, object=args.object, cell=args.cell,
            head=args.head, **where,
        ),
        "predinet": lambda: predinet.predinet_figure(
            source, args.env, step=args.step, head=args.head, **where
        ),
        "rvectors": lambda: predinet.r_vectors_figure(
            source, args.env, head=args.head, max_steps=_positive(args.max_steps), **where
        ),
    }  # fmt: skip
    if args.plot in figures:
        fig = figures[args.plot]()
    elif args.plot == "relations":
        fig = relations.relations_figure(
            source,
            args.env,
            threshold=args.threshold,
            episodes=1 if args.episodes is None else args.episodes,
            seed=where["seed"],
        )
    elif fmt == "gif":
        path = episode.save_episode_gif(
            source,
            args.out,
            args.env,
            head=args.head,
            steps=episode.parse_steps(args.steps),
            every=args.every,
            fps=args.fps,
            max_steps=_positive(args.max_steps),
            **where,
        )
        return _pixels(path)
    else:
        fig = episode.episode_figure(
            source,
            args.env,
            head=args.head,
            steps=episode.parse_steps(args.steps),
            frames=args.frames,
            max_steps=_positive(args.max_steps),
            **where,
        )
    path = save_figure(fig, args.out, dpi=args.dpi)
    return _pixels(path) if fmt == "png" else "svg"


def _positive(value: int | None) -> int | None:
    from neurosym.errors import ConfigError

    if value is not None and value < 1:
        raise ConfigError(f"--max-steps must be at least 1, got {value}")
    return value


def _pixels(path: Any) -> str:
    from PIL import Image

    with Image.open(path) as im:
        frames = getattr(im, "n_frames", 1)
        size = f"{im.width} x {im.height} pixels"
        return f"{size}, {frames} frames" if frames > 1 else size
