"""``neurosym plot``: attention maps, R-vector heat maps, relation histograms, episode films.

Every subcommand draws from one of two sources:

* ``--checkpoint FILE [--env NAME] [--seed S]`` plays one greedy
  episode from ``reset(seed=S)`` with the model's introspection on (full maps);
* ``--recording DIR [--episode E]`` reads a recording saved by
  ``neurosym extract`` / ``Recording.save`` (attention keeps only the strongest cells).

and writes ``--out FILE`` (.png or .svg; ``episode`` also .gif). Identical
inputs give identical bytes. The subcommands are thin wrappers over the
functions in :mod:`neurosym.viz`.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Any, ClassVar

from neurosym.flags import EnvName, Episodes, Out, Seed, add_options, option

MIN_DPI, MAX_DPI = 1, 1200
"""--dpi range: a 4-head figure at 1200 dpi is about 12,700 pixels wide (matplotlib's limit: 65,536)"""


def _cell(text: str) -> tuple[int, int]:
    try:
        row, col = (int(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected ROW,COL such as 3,9, got {text!r}") from None
    return row, col


@dataclass(kw_only=True)
class PlotOptions(Out):
    """What every plot takes: the image to write."""

    out: str = option(metavar="FILE")
    """image to write (.png or .svg)"""
    dpi: float = option(100.0, group="output")
    """resolution of PNG output"""


@dataclass(kw_only=True)
class SourceOptions(EnvName, Seed, PlotOptions):
    """A plot of an episode: played from a checkpoint, or read from a recording."""

    RENAMED: ClassVar[dict[str, str]] = {"--episode-seed": "--episode-seed is now --seed"}
    checkpoint: str | None = option(None, metavar="FILE", exclusive="source", required_one=True)
    """play this checkpoint (greedy)"""
    recording: str | None = option(None, metavar="DIR", exclusive="source")
    """read this saved recording"""
    episode: int | None = option(None, metavar="E", shown="the first")
    """with --recording: episode number"""
    env: str | None = option(None, shown="the checkpoint's")
    """with --checkpoint: environment"""
    seed: int | None = option(None, shown="0")
    """with --checkpoint: reset seed of the episode"""


@dataclass(kw_only=True)
class Head:
    """The plots of one head or all."""

    head: int | None = option(None, shown="all")
    """draw one head"""


@dataclass(kw_only=True)
class MaxSteps:
    """The plots of a whole played episode."""

    max_steps: int | None = option(None, metavar="N", shown="the env's limit")
    """with --checkpoint: stop the episode after this many steps"""


@dataclass(kw_only=True)
class MhdpaOptions(Head, SourceOptions):
    plot: ClassVar[str] = "mhdpa"
    step: int = 0
    """state to show"""
    object: str | None = option(None, exclusive="object", shown="agent")
    """entity or object id whose attention to draw: agent, enemy, key(red), lock_red_2"""
    cell: tuple[int, int] | None = option(None, metavar="ROW,COL", exclusive="object", parse=_cell)
    """pick the object by its cell instead (for walls, pits, ...)"""


@dataclass(kw_only=True)
class PredinetOptions(Head, SourceOptions):
    plot: ClassVar[str] = "predinet"
    step: int = 0
    """state to show"""


@dataclass(kw_only=True)
class RvectorsOptions(MaxSteps, Head, SourceOptions):
    plot: ClassVar[str] = "rvectors"


@dataclass(kw_only=True)
class RelationsOptions(Episodes, SourceOptions):
    plot: ClassVar[str] = "relations"
    threshold: str = option("quantile:0.9", metavar="SPEC")
    """abs:X, quantile:Q or z:K, as for extract"""
    episodes: int | None = option(None, shown="1")
    """with --checkpoint: episodes to play, seeds S, S+1, ..."""
    seed: int | None = option(None, shown="0")
    """with --checkpoint: reset seed of the first episode"""


@dataclass(kw_only=True)
class EpisodeOptions(MaxSteps, Head, SourceOptions):
    plot: ClassVar[str] = "episode"
    RENAMED: ClassVar[dict[str, str]] = {
        **SourceOptions.RENAMED,
        "--frames": "--frames is now --panels (the states the strip shows; --frames is "
        "train's frame budget)",
    }
    steps: str | None = option(None, metavar="START:STOP", shown="all")
    """states to draw, inclusive, e.g. 0:20"""
    panels: int = option(12, metavar="N")
    """PNG/SVG strip: states shown, evenly spaced"""
    every: int = 1
    """GIF: draw every k-th state"""
    fps: float = 4.0
    """GIF: frames per second"""
    out: str = option(metavar="FILE")
    """image to write (.png, .svg or .gif)"""


@dataclass(kw_only=True)
class ProbesOptions(PlotOptions):
    plot: ClassVar[str] = "probes"
    RENAMED: ClassVar[dict[str, str]] = {
        "--probes": "--probes is now --probe (as in neurosym report)"
    }
    probe: str = option(metavar="DIR")
    """a `neurosym probe` output folder"""
    relation: str = "all"
    """relation to show: all (the whole vector), 0, 1, ... or best"""
    top: int = 25
    """predicates shown at most"""


_SUBCOMMANDS: dict[str, tuple[type, str]] = {
    "mhdpa": (MhdpaOptions, "MHDPA: per head, the attention of one object on every cell and of every cell on it."),
    "predinet": (PredinetOptions, "PrediNet: per head, the attention maps a1 and a2 over the grid at one step."),
    "rvectors": (RvectorsOptions, "PrediNet: the R vector of every head at every step of an episode, as a heat map."),
    "relations": (RelationsOptions, "PrediNet: each relation's distribution of values, its threshold marked."),
    "episode": (EpisodeOptions, "An episode as a strip of states (PNG/SVG) or an animated GIF, with route and head arrows."),
    "probes": (ProbesOptions, "Probe selectivity (accuracy - control), heads x predicates, from `neurosym probe`."),
}  # fmt: skip


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the plot subcommands, each with its own options."""
    sub = parser.add_subparsers(dest="plot", metavar="PLOT", required=True)
    for name, (cls, help_text) in _SUBCOMMANDS.items():
        add_options(sub.add_parser(name, help=help_text, description=help_text), cls)


def run(args: Any) -> int:
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
        fig = probes_figure(load_probe_table(args.probe), args.relation, args.top)
        path = save_figure(fig, args.out, dpi=args.dpi)
        print(f"wrote {plain(args.out)} ({_pixels(path) if fmt == 'png' else 'svg'})")
        return 0
    source = _load_source(args)
    written = _draw(args, source, fmt)
    print(f"wrote {plain(args.out)} ({written})")
    return 0


def _load_source(args: Any) -> Any:
    from neurosym.errors import ConfigError

    if args.recording is not None:
        played = (
            ("--env", args.env),
            ("--seed", args.seed),
            ("--max-steps", getattr(args, "max_steps", None)),
            ("--episodes", getattr(args, "episodes", None)),
        )
        for flag, value in played:
            if value is not None:
                raise ConfigError(f"{flag} goes with --checkpoint; a recording already fixes it")
        from neurosym.record.recording import Recording

        return Recording.load(args.recording)
    if args.episode is not None:
        raise ConfigError(
            "--episode goes with --recording; with --checkpoint pick the episode by --seed"
        )
    from neurosym.agent.agent import load_agent

    return load_agent(args.checkpoint)


def _draw(args: Any, source: Any, fmt: str) -> str:
    """Draw and write; returns a short description of what was written."""
    from neurosym.viz import attention, episode, predinet, relations
    from neurosym.viz.output import save_figure

    where = {"episode": args.episode, "seed": args.seed or 0}
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
            frames=args.panels,
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
