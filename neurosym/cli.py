"""The `neurosym` command: train | eval | compact | extract | probe | intervene | query | induce | play | plot | report | envs | agents | setup-prolog.

Each subcommand lives beside the code it drives (``neurosym/<package>/cli_*.py``)
as a module with two functions:

* ``configure(parser: argparse.ArgumentParser) -> None`` adds its arguments, generated
  from its options dataclass by :func:`neurosym.flags.add_options` (the flags every
  command shares, ``--env``, ``--seed``, ``--json``, ..., are written once there);
* ``run(options) -> int`` does the work with the filled-in options and returns the exit
  code (``train``, whose settings' flags come from its config classes, gets the namespace).

Only the module of the command being run is imported, so ``neurosym query``
never pays for importing torch. A :class:`~neurosym.errors.NeurosymError`
(bad input) is printed as one line and exits with status 1; argparse usage
errors exit with status 2, and so does a renamed flag (one line naming the new
spelling); Ctrl-C exits with 130; a closed stdout (the reader
of a pipe gone, ``neurosym envs | head -1``) ends the command quietly with 141.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import os
import sys
from collections.abc import Sequence
from typing import Any

from neurosym import __version__
from neurosym.display import plain
from neurosym.errors import ConfigError, NeurosymError
from neurosym.flags import Parser, options_of


def parse_env_options(items: list[str], env: str | None = None) -> dict[str, Any]:
    """KEY=VALUE strings -> env kwargs, each value typed by its option; ConfigError (one line) else.

    The types are the env class's (:func:`neurosym.envs.registration.option_types`):
    ``classic=false`` is False, ``max_steps=50`` 50, ``max_steps=none`` None.
    ``env``: the env they are for (an unknown option is refused here, naming
    the env's); None: typed by name over every env (the env refuses unknowns).
    Options that only change what ``env.render()`` draws are refused: no command shows it.
    """
    from neurosym.envs.options import parse_value
    from neurosym.envs.registration import ENTRIES, RENDER_ONLY_OPTIONS, entry, option_types

    if env is not None:
        types = option_types(env)
    else:
        types = {}
        for e in ENTRIES:
            for key, option in option_types(e.short).items():
                seen = types.get(key)
                if seen is not None and seen.kind != option.kind:
                    option = dataclasses.replace(option, kind="any")  # typed again by the env
                if seen is not None and seen.optional:
                    option = dataclasses.replace(option, optional=True)
                types[key] = option
    out: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.isidentifier():
            raise ConfigError(f"--env-option wants KEY=VALUE with KEY a name, got {item!r}")
        if key in out:
            raise ConfigError(f"--env-option {key} is given twice: give each option once")
        if key in RENDER_ONLY_OPTIONS:
            raise ConfigError(
                f"--env-option {key}: not an option here (it only changes what the env draws "
                "for env.render(), which no command shows)"
            )
        option = types.get(key)
        if option is None:
            if env is None:  # the env refuses it, naming its own options
                out[key] = text
                continue
            known = ", ".join(k for k in types if k not in RENDER_ONLY_OPTIONS)
            raise ConfigError(
                f"--env-option: unknown option {key!r} for {entry(env).short}; "
                f"expected one of {known}"
            )
        try:
            out[key] = parse_value(option, text)
        except ValueError as exc:
            raise ConfigError(f"--env-option {key}={text!r}: {key} takes {exc}") from None
    return out


def agent_env(
    agent: Any, env: str | None, items: list[str], map_file: str | None = None
) -> tuple[str, dict[str, Any]]:
    """(env name, options) for intervene and probe: ``--env`` (default: the agent's own)
    with the ``--env-option`` items and ``--map`` on top, typed and checked (family,
    observation shape).
    """
    from neurosym.agent.agent import env_for
    from neurosym.envs import canonical_name

    if map_file is not None:
        env, overrides = map_option(env, map_file, agent.env_name)
        extra = parse_env_options(items, env)
        if "map" in extra:
            raise ConfigError("give the map once: --map FILE or --env-option map=FILE, not both")
        return env_for(agent, env, {**(overrides or {}), **extra})
    name = canonical_name(env if env is not None else agent.env_name)
    return env_for(agent, name, parse_env_options(items, name))


def env_choice(args: Any, trained: str) -> tuple[str | None, dict[str, Any] | None]:
    """(env name or None, the user's env options or None) from ``--env``, ``--map``, ``--env-option``."""
    env, overrides = map_option(args.env, args.map, trained)
    extra = parse_env_options(args.env_option, env or trained)
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
        "neurosym.record.cli_extract",
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
    "induce": (
        "neurosym.induce.cli_induce",
        "Learn rules back from a knowledge base: the world's rules (predicts/3), "
        "the agent's strategy (goal/3).",
    ),
    "play": (
        "neurosym.play.cli_play",
        "Play with a strategy file: goal/3 picks the object, route.pl the action; eval's figures.",
    ),
    "report": ("neurosym.reports.web.cli_report", "One HTML page per agent: card, player, tables."),
    "envs": ("neurosym.envs.cli_envs", "List the environments with one line each."),
    "agents": (
        "neurosym.cli_agents",
        "List the shipped agents: env, module, learner, held-out success, what each is for.",
    ),
    "setup-prolog": (
        "neurosym.setup_prolog",
        "Find or build SWI-Prolog >= 9.1.12, link it into the venv, build janus-swi against it.",
    ),
}


def _selected_command(argv: Sequence[str]) -> str | None:
    for token in argv:
        if token.startswith("-"):
            continue
        return token if token in COMMANDS else None
    return None


def build_parser(argv: Sequence[str]) -> argparse.ArgumentParser:
    """Build the parser; only the selected subcommand's module is imported."""
    parser = Parser(
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


BROKEN_PIPE_EXIT = 141
"""exit status when the reader of stdout goes away (``neurosym ... | head``): 128 + SIGPIPE,
what a shell reports for a command that a closed pipe ends"""


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    try:
        code = int(args._run(options_of(args)) or 0)
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return code
    except BrokenPipeError:
        return _reader_gone()
    except SystemExit as exc:
        if isinstance(exc.__context__, BrokenPipeError):  # a rich console's own way out
            return _reader_gone()
        raise
    except NeurosymError as exc:  # one line, control characters shown (a path may hold any)
        print(f"neurosym {args.command}: error: {plain(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"neurosym {args.command}: interrupted", file=sys.stderr)
        return 130


def _reader_gone() -> int:
    """Stop quietly: point stdout at devnull so that Python's flush at exit finds no pipe
    to complain about (the recipe of the ``signal`` module's documentation)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # stdout without a file descriptor (tests)
        pass
    return BROKEN_PIPE_EXIT


if __name__ == "__main__":
    sys.exit(main())
