"""The `neurosym` command: train | eval | compact | extract | probe | intervene | query | plot | envs.

Each subcommand lives beside the code it drives (``neurosym/<package>/cli_*.py``)
as a module with two functions:

* ``configure(parser: argparse.ArgumentParser) -> None`` adds its arguments;
* ``run(args: argparse.Namespace) -> int`` does the work and returns the exit code.

Only the module of the command being run is imported, so ``neurosym query``
never pays for importing torch. A :class:`~neurosym.errors.NeurosymError`
(bad input) is printed as one line and exits with status 1; argparse usage
errors exit with status 2.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import sys
from collections.abc import Sequence
from typing import Any

from neurosym import __version__
from neurosym.errors import ConfigError, NeurosymError


def add_action_mode(parser: argparse.ArgumentParser) -> None:
    """``--greedy`` (default) | ``--sample``, stored as ``args.greedy``; eval and extract share it."""
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument(
        "--greedy",
        dest="greedy",
        action="store_true",
        default=True,
        help="most likely action (default)",
    )
    mode.add_argument(
        "--sample", dest="greedy", action="store_false", help="sample actions from the policy"
    )


def add_env_options(parser: argparse.ArgumentParser) -> None:
    """``--env NAME`` and ``--map FILE``: where eval and extract play the checkpoint."""
    parser.add_argument(
        "--env",
        metavar="NAME",
        help="environment, e.g. rgw2: any of the checkpoint's family with its observation "
        "shape (default: the checkpoint's own)",
    )
    parser.add_argument(
        "--map",
        metavar="FILE",
        help="RGW: play this map file on a fixed-map env (--env rgw1 or rgw2, default rgw2)",
    )
    add_env_option(parser)


def add_env_option(parser: argparse.ArgumentParser) -> None:
    """``--env-option KEY=VALUE`` (repeatable): eval, extract, intervene and probe share it."""
    parser.add_argument(
        "--env-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an option of the env on top of the checkpoint's, e.g. num_mountains=12 on "
        "rgw-random (repeatable)",
    )


def parse_env_options(items: list[str]) -> dict[str, Any]:
    """KEY=VALUE strings -> kwargs; values are Python literals when they parse as one, else strings."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.isidentifier():
            raise ConfigError(f"--env-option wants KEY=VALUE with KEY a name, got {item!r}")
        try:
            out[key] = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            out[key] = text
    return out


def with_env_options(agent: Any, items: list[str]) -> Any:
    """The agent with ``--env-option`` items on top of its env options (checked by making the env).

    For the commands that play an agent on its own env only (intervene, probe).
    """
    import dataclasses

    extra = parse_env_options(items)
    if not extra:
        return agent
    from neurosym.agent.checkpoint import env_for

    _, kwargs = env_for(agent, None, extra)
    return dataclasses.replace(agent, env_kwargs=kwargs)


def play_options(
    args: argparse.Namespace, trained: str
) -> tuple[str | None, dict[str, Any] | None]:
    """(env name or None, the user's env options or None) from ``--env``, ``--map``, ``--env-option``."""
    env, overrides = map_option(args.env, args.map, trained)
    extra = parse_env_options(args.env_option)
    if not extra:
        return env, overrides
    if "map" in extra and overrides:
        raise ConfigError("give the map once: --map FILE or --env-option map=FILE, not both")
    return env, {**(overrides or {}), **extra}


def map_option(
    env: str | None, map_file: str | None, trained: str
) -> tuple[str | None, dict[str, Any] | None]:
    """(env name or None, env options or None) for ``--env`` and ``--map``.

    ``--map FILE`` plays a user's map on a fixed-map RGW env: ``--env`` rgw1 or
    rgw2, or none (then rgw2's: a checkpoint of rgw-random plays it too).
    """
    from neurosym.envs import canonical_name, env_family

    if map_file is None:
        return env, None
    name = canonical_name(env) if env else None
    if env_family(name or trained) != "rgw" or name not in (None, "rgw1", "rgw2"):
        raise ConfigError(
            f"--map goes with a fixed-map RGW env (--env rgw1 or rgw2, or none), not {name or trained}"
        )
    from neurosym.envs.rgw_maps import load_map

    load_map(map_file)  # a bad map is refused here, naming its row and column
    return name or "rgw2", {"map": map_file}


# name -> (module, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "train": (
        "neurosym.agent.run.cli_train",
        "Train a PrediNet or MHDPA agent with A3C or PPO (PPO also under torchrun).",
    ),
    "eval": (
        "neurosym.agent.cli_eval",
        "Evaluate a checkpoint: mean return, success rate, outcomes.",
    ),
    "compact": (
        "neurosym.agent.cli_compact",
        "Store a checkpoint's weights in half precision: a smaller file to ship.",
    ),
    "extract": (
        "neurosym.export.cli_extract",
        "Record episodes and write the R-vector facts as a Prolog KB.",
    ),
    "probe": (
        "neurosym.meaning.cli_probe",
        "Fit linear probes: which predicates each head's relations encode.",
    ),
    "intervene": (
        "neurosym.meaning.cli_intervene",
        "Controlled experiments: change the level or ablate heads, measure the effects.",
    ),
    "query": (
        "neurosym.prolog.cli_query",
        "Run a Prolog goal against a knowledge base and print the answers.",
    ),
    "plot": (
        "neurosym.viz.cli_plot",
        "Draw attention maps, R-vector heat maps and episode renderings.",
    ),
    "envs": ("neurosym.envs.cli_envs", "List the environments with one line each."),
}


def _selected_command(argv: Sequence[str]) -> str | None:
    for token in argv:
        if token.startswith("-"):
            continue
        return token if token in COMMANDS else None
    return None


def build_parser(argv: Sequence[str]) -> argparse.ArgumentParser:
    """Build the parser; only the selected subcommand's module is imported."""
    parser = argparse.ArgumentParser(
        prog="neurosym",
        description="Make a reinforcement-learning agent's relational reasoning explicit.",
    )
    parser.add_argument("--version", action="version", version=f"neurosym {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    selected = _selected_command(argv)
    for name, (module_name, help_text) in COMMANDS.items():
        cmd = sub.add_parser(name, help=help_text, description=help_text)
        if name == selected:
            module = importlib.import_module(module_name)
            module.configure(cmd)
            cmd.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or 0)
    except NeurosymError as exc:
        print(f"neurosym {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"neurosym {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
