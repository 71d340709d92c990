"""``neurosym train``: train a PrediNet or MHDPA agent with A3C, PPO or DAgger.

A thin wrapper over :func:`neurosym.agent.run.trainer.train`. The settings'
flags are generated from the config dataclasses (:mod:`neurosym.agent.config`,
:class:`~neurosym.agent.run.options.RunOptions`): a field whose metadata says
``flag`` gets ``--its-name`` with its docstring as help; every other field is
set with ``--set NAME=VALUE``. Unset options take the preset's defaults for
the env family (``--preset thesis`` is Table 4 exactly); with ``--resume``
they take the checkpoint's settings. The command line, rebuilt from what was
given, is stored in the checkpoint. Under ``torchrun`` (``--algo ppo``) every
rank runs this command and rank 0 writes
(:mod:`neurosym.agent.learners.distributed`).
"""

from __future__ import annotations

import argparse
import ast
import functools
import os
import shlex
from dataclasses import Field, dataclass, fields
from typing import Any, Literal

from neurosym.agent.config import (
    A3CConfig,
    ImitationConfig,
    ModelConfig,
    PPOConfig,
    TrainConfig,
    field_docs,
    option_name,
    range_error,
)
from neurosym.agent.run.options import RunOptions
from neurosym.cli import parse_env_options
from neurosym.errors import ConfigError
from neurosym.flags import EnvOptions, Out, Quiet, add_flags, option

SETTINGS: tuple[tuple[str, type, str], ...] = (
    (
        "settings every learner shares (default: the preset's for the env family)",
        TrainConfig,
        "train",
    ),
    ("--algo a3c", A3CConfig, "train"),
    ("--algo ppo", PPOConfig, "train"),
    ("--algo imitate (DAgger from a planner or a teacher)", ImitationConfig, "train"),
    ("model (default: Table 4 and the preset's switches)", ModelConfig, "model"),
)
"""(argument group title, config class, train | model) of the settings' flags, in help order"""
FIXED = {"algo", "preset", "learner", "module", "obs_shape", "obs_scale", "n_actions"}
"""config fields that are not settings of a run (own flags, derived, or nested)"""
FROM_ENV = {"obs_shape": "observation shape", "obs_scale": "observation scale",
            "n_actions": "number of actions"}  # fmt: skip
"""fixed fields the env decides (a ``--set`` of one says so)"""
GROUPS = {
    "stop": "stopping (any that is reached; none: run until Ctrl-C)",
    "watch": "watching",
}


def _help(cls: type, f: Field[Any]) -> str:
    """The field's docstring up to its first top-level '. ', '; ' or ': ', plus its default
    (a setting's: the default preset's for each env family and learner, :mod:`.defaults`)."""
    text, depth = field_docs(cls).get(f.name, ""), 0
    for i, char in enumerate(text):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0 and char in ".;:" and text[i + 1 : i + 2] in (" ", ""):
            text = text[:i]
            break
    text = text.replace("``", "")
    bounds = f.metadata.get("range")
    within = (
        f"; each in {bounds}" if bounds and bounds.length else f"; range {bounds}" if bounds else ""
    )
    text += f" (default {default_text(cls, f)}{within})"
    return text.replace("%", "%%")


def default_text(cls: type, f: Field[Any]) -> str:
    """A flag's default as its help shows it: a setting's is the default preset's, per env
    family ("rgw", "bw") and learner where they differ; a field may say it in words
    (metadata ``shown``)."""
    if "shown" in f.metadata:
        return str(f.metadata["shown"])
    if cls is RunOptions:
        return "none" if f.default is None else _shown(f.default)
    if f.name == "workers":
        return "one per CPU core it may use"
    per_algo: dict[str, dict[str, Any]] = {}
    for (family, algo), values in _preset_values().items():
        if f.name in values and (cls is not ModelConfig or algo == "a3c"):  # the model's: any
            per_algo.setdefault(algo, {})[family] = values[f.name]
    texts = {algo: _per_family(values) for algo, values in per_algo.items()}
    first = next(iter(texts))
    others = [f"--algo {algo} {text}" for algo, text in texts.items() if text != texts[first]]
    return "; ".join([texts[first], *others])


@functools.cache
def _preset_values() -> dict[tuple[str, str], dict[str, Any]]:
    """(family label, algo) -> the default preset's flat settings and PrediNet model switches."""
    table: dict[tuple[str, str], dict[str, Any]] = {}
    for family, label in (("rgw", "rgw"), ("boxworld", "bw")):
        model = ModelConfig.for_family(family, "predinet", (1, 1, 1))
        model_values = {f.name: getattr(model, f.name) for f in fields(ModelConfig)}
        for algo in ("a3c", "ppo", "imitate"):
            if algo == "imitate" and family != "rgw":
                continue
            train = TrainConfig.for_family(family, algo=algo).flat()
            table[(label, algo)] = {**model_values, **train}
    return table


def _per_family(values: dict[str, Any]) -> str:
    """'0.002' when every family has it, else 'rgw 0.002, bw 0.0005'."""
    shown = {family: _shown(v) for family, v in values.items()}
    if len(set(shown.values())) == 1:
        return next(iter(shown.values()))
    return ", ".join(f"{family} {text}" for family, text in shown.items())


def _shown(value: Any) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, tuple):
        return ",".join(map(str, value))
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _channels(text: str) -> tuple[int, ...]:
    """'16,16,24' -> (16, 16, 24): the encoder's conv layers, one positive width each."""
    try:
        widths = tuple(int(part) for part in text.split(","))
    except ValueError:
        widths = ()
    if not widths or min(widths) < 1:
        raise argparse.ArgumentTypeError(
            f"want comma-separated positive channel counts such as 12,24, got {text!r}"
        )
    return widths


def _kind(f: Field[Any]) -> str:
    """bool, channels, int, float or str: how a field's value is read from text."""
    declared = str(f.type)
    for kind in ("bool", "tuple", "int", "float"):
        if kind in declared:
            return "channels" if kind == "tuple" else kind
    return "str"


def _add_flag(group: Any, cls: type, f: Field[Any]) -> None:
    meta, kind = f.metadata, _kind(f)
    extra: dict[str, Any] = {}
    if kind == "bool":
        extra["action"] = argparse.BooleanOptionalAction
    else:
        extra["type"] = {"channels": _channels, "int": int, "float": float, "str": str}[kind]
    for key in ("choices", "metavar"):
        if key in meta:
            extra[key] = meta[key]
    group.add_argument(option_name(f.name), dest=f.name, default=None, help=_help(cls, f), **extra)


def flag_fields() -> list[tuple[type, Field[Any]]]:
    """Every config field with a flag of its own."""
    classes = [cls for _, cls, _ in SETTINGS] + [RunOptions]
    return [(cls, f) for cls in classes for f in fields(cls) if f.metadata.get("flag")]


def settable() -> dict[str, tuple[type, Field[Any]]]:
    """Every setting ``--set`` takes: name -> (its config class, its field)."""
    out: dict[str, tuple[type, Field[Any]]] = {}
    for _, cls, _ in SETTINGS:
        for f in fields(cls):
            if f.name not in FIXED:
                out[f.name] = (cls, f)
    return out


def set_names_help() -> str:
    """The settings ``--set NAME=VALUE`` takes, a line each with what it does (the help's epilog)."""
    lines = ["settings without a flag of their own (--set NAME=VALUE):"]
    for name, (cls, f) in sorted(settable().items()):
        if not f.metadata.get("flag"):
            lines.append(f"  {name:<22} {_help(cls, f).replace('%%', '%')}")
    return "\n".join(lines)


@dataclass(kw_only=True)
class TrainCommand(EnvOptions, Out, Quiet):
    """``neurosym train``'s own flags (the settings' come from the config classes)."""

    module: Literal["predinet", "mhdpa"] | None = None
    """relational module (required unless --resume or --init-from)"""
    resume: bool = False
    """continue the run in --out from its checkpoint"""
    init_from: str | None = option(None, metavar="CHECKPOINT")
    """start a new run from this checkpoint's weights and model (a curriculum: e.g. a bw1 agent
    on bw2); any env of its family with its observation shape; frames count afresh"""
    algo: Literal["a3c", "ppo", "imitate"] | None = None
    """learner: a3c (asynchronous workers, default), ppo (one synchronous learner) or imitate
    (DAgger from the env's optimal planner, RGW and Minigrid's DoorKey levels, or from a trained
    agent: --set teacher=CHECKPOINT)"""
    preset: Literal["default", "thesis"] = option("default", shown="")
    """settings to start from: default (what learns best here) or thesis (Table 4 exactly)"""
    settings: list[str] = option(factory=list, flag="--set", metavar="NAME=VALUE")
    """any other setting of neurosym/agent/config.py, e.g. --set attention_gain=32 (repeatable)"""
    env: str | None = option(None, metavar="NAME", shown="")
    """environment short name or id, e.g. rgw2 (required unless --resume)"""
    env_option: list[str] = option(factory=list)
    """keyword argument for the env, e.g. obs_mode=grey (repeatable)"""
    out: str = option(metavar="DIR")
    """run directory: checkpoint.pt and metrics.csv go here"""
    quiet: bool = False
    """no progress bar"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_flags(parser, TrainCommand)
    parser.epilog = set_names_help()
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    groups = {key: parser.add_argument_group(title) for key, title in GROUPS.items()}
    for f in fields(RunOptions):
        if f.metadata.get("flag"):
            _add_flag(groups[f.metadata["group"]], RunOptions, f)
    for title, cls, _ in SETTINGS:
        group = parser.add_argument_group(title)
        for f in fields(cls):
            if f.metadata.get("flag"):
                _add_flag(group, cls, f)


def _parse_value(name: str, f: Field[Any], text: str) -> Any:
    """``--set NAME=TEXT``'s value, read as the field's type and checked against its range."""
    value = _read_value(name, f, text)
    bounds = f.metadata.get("range")
    if bounds is not None:
        kind = float if _kind(f) == "float" else int
        problem = range_error(name, value, kind, bounds)
        if problem:
            raise ConfigError(f"--set {name}={text}: {problem}")
    return value


def _read_value(name: str, f: Field[Any], text: str) -> Any:
    kind = _kind(f)
    if kind == "channels":
        try:
            return _channels(text)
        except argparse.ArgumentTypeError as exc:
            raise ConfigError(f"--set {name}: {exc}") from None
    if kind == "bool":
        lowered = text.lower()
        if lowered not in ("true", "false", "1", "0", "yes", "no"):
            raise ConfigError(f"--set {name} wants true or false, got {text!r}")
        return lowered in ("true", "1", "yes")
    if kind == "str":
        return text
    try:
        value = ast.literal_eval(text)
    except (ValueError, SyntaxError):
        value = None
    if kind == "float" and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if type(value).__name__ != kind:
        raise ConfigError(f"--set {name} wants a number ({kind}), got {text!r}")
    return value


def parse_settings(items: list[str]) -> dict[str, Any]:
    """``--set`` items -> {name: value}, each read as its field's type."""
    known = settable()
    out: dict[str, Any] = {}
    for item in items:
        name, sep, text = item.partition("=")
        if name in FROM_ENV:
            raise ConfigError(f"--set {name}: not a setting; the env's {FROM_ENV[name]} decides it")
        if not sep or name not in known:
            raise ConfigError(
                f"--set wants NAME=VALUE with NAME a setting ({', '.join(sorted(known))}), "
                f"got {item!r}"
            )
        out[name] = _parse_value(name, known[name][1], text)
    return out


def overrides_of(args: argparse.Namespace) -> dict[str, dict[str, Any]]:
    """The settings given on the command line, by config: {"train": {...}, "model": {...}}."""
    given = {f.name: getattr(args, f.name) for cls, f in flag_fields() if cls is not RunOptions}
    given.update(parse_settings(args.settings))
    model_names = {f.name for f in fields(ModelConfig)}
    out: dict[str, dict[str, Any]] = {"train": {}, "model": {}}
    for name, value in given.items():
        if value is not None:
            out["model" if name in model_names else "train"][name] = value
    return out


def _as_text(value: Any) -> str:
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def _run_options(args: argparse.Namespace, group: str) -> list[str]:
    """The given RunOptions flags of one group that differ from their defaults."""
    parts: list[str] = []
    for f in fields(RunOptions):
        value = getattr(args, f.name, None)
        if f.metadata.get("group") == group and value is not None and value != f.default:
            if isinstance(value, bool):
                parts.append(option_name(f.name) if value else "--no-" + option_name(f.name)[2:])
            else:
                parts += [option_name(f.name), str(value)]
    return parts


def command_line(args: argparse.Namespace) -> str:
    """The command as a user would type it, rebuilt from what was given."""
    parts = ["neurosym", "train"]
    for flag in ("env", "module", "out"):
        if getattr(args, flag) is not None:
            parts += [f"--{flag}", str(getattr(args, flag))]
    if args.resume:
        parts.append("--resume")
    for name in ("init_from", "algo"):
        if getattr(args, name) is not None:
            parts += [option_name(name), str(getattr(args, name))]
    if args.preset != "default":
        parts += ["--preset", args.preset]
    parts += _run_options(args, "stop")
    flagged = {f.name for _, f in flag_fields()}
    for settings in overrides_of(args).values():
        for name, value in settings.items():
            if name not in flagged:
                parts += ["--set", f"{name}={_as_text(value)}"]
            elif isinstance(value, bool):
                parts.append(option_name(name) if value else "--no-" + option_name(name)[2:])
            else:
                parts += [option_name(name), _as_text(value)]
    for item in args.env_option:
        parts += ["--env-option", item]
    parts += _run_options(args, "watch")
    command = shlex.join(parts)
    world = os.environ.get("WORLD_SIZE")
    if world and world != "1":  # the checkpoint says the run was distributed
        command = f"torchrun (WORLD_SIZE={world}) -m {command}"
    return command


def usable_cores() -> int:
    """The cores this process may run on (taskset, a container's CPU set), else all of them:
    A3C's default worker count."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # no affinity on this platform
        return os.cpu_count() or 1


def run(args: argparse.Namespace) -> int:
    from neurosym.agent.run.trainer import train

    overrides = overrides_of(args)
    if "workers" not in overrides["train"] and not args.resume and args.algo in (None, "a3c"):
        overrides["train"]["workers"] = usable_cores()
    given = {
        f.name: getattr(args, f.name)
        for f in fields(RunOptions)
        if f.metadata.get("flag") and getattr(args, f.name) is not None
    }
    options = RunOptions(**given, progress=not args.quiet)
    result = train(
        args.env,
        args.module,
        args.out,
        train_overrides=overrides["train"],
        model_overrides=overrides["model"],
        env_kwargs=parse_env_options(args.env_option) if args.env_option else None,
        options=options,
        resume=args.resume,
        init_from=args.init_from,
        command=command_line(args),
        print_fn=print,
        preset=args.preset,
        algo=args.algo,
    )
    return 130 if result.stop_reason == "interrupted" else 0
