"""Command-line flags generated from dataclasses: each command's options are one dataclass.

Every field of an options class gets the flag ``--its-name`` (underscores as dashes) whose
help is the field's docstring (the string literal after it in the class body) followed by
its default. The field's type says how the value is read:

* ``bool``: a switch, ``--x`` when off by default, ``--x/--no-x`` when on by default or
  ``bool | None`` (None: neither given);
* ``int``, ``float``, ``str`` (optionally ``| None``): one value of that type;
* ``Literal["a", "b"]``: one of those words;
* ``list[str]``: repeatable, each value appended.

A field without a default is required. :func:`option` says what a type cannot: the metavar,
a pair of switches for one boolean (``--greedy``/``--sample``), flags that exclude each
other, a positional argument, a parser for the value, the default as the help shows it.

The option groups every command shares (:class:`EnvChoice`, :class:`Episodes`, :class:`Seed`,
:class:`ActionMode`, :class:`Out`, :class:`Quiet`, :class:`Json`) are mixins: a command's
options class inherits the ones it takes, so each flag is written once and means one thing
in every command; a command redeclares a field to give it its own default or docstring
(the flag's metavar and the rest stay the group's). The mixins' fields are listed after the
command's own, under the group's title. A class that inherits a field from two bases with
different defaults redeclares it: a dataclass takes the default of the base it processes last.

``RENAMED`` (a class variable: old flag -> what to write now) refuses a flag that was renamed
or removed with one line naming the new spelling and exit status 2, as argparse refuses a
flag it does not know (:class:`Parser`).
"""

from __future__ import annotations

import argparse
import ast
import inspect
import sys
import textwrap
import types
from collections.abc import Callable, Sequence
from dataclasses import MISSING, Field, dataclass, field, fields, is_dataclass
from functools import cache
from typing import Any, ClassVar, Literal, Union, get_args, get_origin, get_type_hints


def option_name(name: str) -> str:
    """The flag of a field (``ppo_epochs`` -> ``--ppo-epochs``)."""
    return "--" + name.replace("_", "-")


@cache
def field_docs(cls: type) -> dict[str, str]:
    """Each field's docstring (the string literal after it in the class body), whitespace joined."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    body = tree.body[0].body  # type: ignore[attr-defined]
    docs: dict[str, str] = {}
    for node, after in zip(body, body[1:], strict=False):
        if (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and isinstance(after, ast.Expr)
            and isinstance(after.value, ast.Constant)
            and isinstance(after.value.value, str)
        ):
            docs[node.target.id] = " ".join(after.value.value.split())
    return docs


def option(
    default: Any = MISSING,
    *,
    factory: Callable[[], Any] | Any = MISSING,
    metavar: str | None = None,
    flag: str | None = None,
    switches: tuple[str, str] | None = None,
    off_help: str | None = None,
    positional: bool = False,
    exclusive: str | None = None,
    required_one: bool = False,
    parse: Callable[[str], Any] | None = None,
    shown: str | None = None,
    hidden: bool = False,
    group: str | None = None,
    fill: Callable[[], dict[str, str]] | None = None,
) -> Any:
    """A dataclass field with what its flag needs beyond its type and docstring.

    ``flag``: the flag's spelling when not ``--its-name``; ``switches``: (on, off) flags of
    one boolean, ``off_help`` the off one's help; ``exclusive``: the name of a set of flags
    that exclude each other, ``required_one`` when one of them must be given; ``parse``:
    reads the value (raising argparse.ArgumentTypeError); ``shown``: the default as the help
    says it ("": none said); ``hidden``: left out of the help; ``fill``: the values of the ``{name}``
    fields in the docstring, computed when the parser is built; ``group``: the shared
    group's title to list a command's own flag under.
    """
    meta = {
        "metavar": metavar, "flag": flag, "switches": switches, "off_help": off_help,
        "positional": positional, "exclusive": exclusive, "required_one": required_one,
        "parse": parse, "shown": shown, "hidden": hidden, "fill": fill,
        "group": group,
    }  # fmt: skip
    return field(
        default=default,
        default_factory=factory,
        metadata={k: v for k, v in meta.items() if v not in (None, False)},
    )


# -- the groups every command shares ------------------------------------------------------


@dataclass(kw_only=True)
class EnvName:
    """The env a command plays."""

    GROUP: ClassVar[str] = "environment"
    env: str | None = option(None, metavar="NAME", shown="the checkpoint's own")
    """environment, e.g. rgw2: any of the checkpoint's family with its observation shape"""


@dataclass(kw_only=True)
class EnvOptions(EnvName):
    """The env and options of its own."""

    GROUP: ClassVar[str] = "environment"
    env_option: list[str] = option(factory=list, metavar="KEY=VALUE")
    """an option of the env on top of the checkpoint's, e.g. num_mountains=12 on rgw-random
    (repeatable)"""


@dataclass(kw_only=True)
class EnvChoice(EnvOptions):
    """The env, its options, and a map of one's own."""

    GROUP: ClassVar[str] = "environment"
    map: str | None = option(None, metavar="FILE")
    """RGW: play this map file on a fixed-map env (--env rgw1 or rgw2, default rgw2)"""


@dataclass(kw_only=True)
class Seed:
    """The seed the episodes are played from."""

    GROUP: ClassVar[str] = "episodes"
    seed: int = option(0, metavar="S")
    """episode k is played from reset(seed=S + k)"""


@dataclass(kw_only=True)
class Episodes(Seed):
    """How many episodes, from which seed."""

    GROUP: ClassVar[str] = "episodes"
    episodes: int = option(100, metavar="N")
    """episodes to play"""


@dataclass(kw_only=True)
class ActionMode:
    """Greedy or sampled actions."""

    GROUP: ClassVar[str] = "episodes"
    greedy: bool = option(
        True, switches=("--greedy", "--sample"), off_help="sample actions from the policy"
    )
    """take the most likely action"""


@dataclass(kw_only=True)
class Out:
    """Where the command writes."""

    GROUP: ClassVar[str] = "output"
    out: str = option(metavar="PATH")
    """where to write"""


@dataclass(kw_only=True)
class Quiet:
    GROUP: ClassVar[str] = "output"
    quiet: bool = False
    """print nothing but errors"""


@dataclass(kw_only=True)
class Json:
    GROUP: ClassVar[str] = "output"
    json: bool = False
    """print JSON instead of text"""


# -- the generator ---------------------------------------------------------------------------


class Parser(argparse.ArgumentParser):
    """An argparse parser that refuses a renamed or removed flag in one line naming the new
    spelling (exit 2): its ``renamed`` table, old flag -> message, set by :func:`add_options`."""

    renamed: dict[str, str]

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        argv = list(sys.argv[1:] if args is None else args)
        table = getattr(self, "renamed", {})
        for token in argv:
            if token == "--":
                break
            message = table.get(token.split("=", 1)[0])
            if message is not None:
                self.exit(2, f"{self.prog}: error: {message}\n")
        return super().parse_known_args(argv, namespace)


def refuse(parser: argparse.ArgumentParser, renamed: dict[str, str]) -> None:
    """Refuse these old flags in ``parser`` (a :class:`Parser`; others ignore the table)."""
    parser.renamed = {**getattr(parser, "renamed", {}), **renamed}  # type: ignore[attr-defined]


def add_options(parser: argparse.ArgumentParser, cls: type) -> None:
    """Add the flags of the options class ``cls``; the parsed namespace becomes a ``cls``
    (:func:`options_of`)."""
    add_flags(parser, cls)
    parser.set_defaults(_options=cls)
    refuse(parser, dict(getattr(cls, "RENAMED", {})))


def add_flags(parser: argparse.ArgumentParser, cls: type) -> None:
    """Add a flag per field of ``cls``: its own fields first, then each shared group's."""
    hints = get_type_hints(cls)
    containers: dict[str | None, Any] = {None: parser}
    exclusive: dict[str, Any] = {}
    for f in _ordered(cls):
        title = group_of(cls, f.name)
        if title not in containers:
            containers[title] = parser.add_argument_group(title)
        container = containers[title]
        meta = metadata(cls, f.name)
        if "exclusive" in meta:
            key = meta["exclusive"]
            if key not in exclusive:
                exclusive[key] = container.add_mutually_exclusive_group(
                    required=bool(meta.get("required_one"))
                )
            container = exclusive[key]
        _add(container, cls, f, hints[f.name], meta)


def options_of(args: argparse.Namespace) -> Any:
    """The options object of parsed arguments: their options class filled in, or the
    namespace itself for a command that reads it as such (``train``)."""
    cls = getattr(args, "_options", None)
    if cls is None:
        return args
    return cls(**{f.name: getattr(args, f.name) for f in fields(cls) if f.init})


def group_of(cls: type, name: str) -> str | None:
    """The title of the shared group that first declares field ``name`` (None: the command's)."""
    if "group" in metadata(cls, name):
        return metadata(cls, name)["group"]
    for klass in reversed(cls.__mro__):
        if name in klass.__dict__.get("__annotations__", {}):
            return klass.__dict__.get("GROUP")
    return None


def metadata(cls: type, name: str) -> dict[str, Any]:
    """A field's metadata over its declarations, the most derived class's winning."""
    out: dict[str, Any] = {}
    for klass in reversed(cls.__mro__):
        if name in klass.__dict__.get("__annotations__", {}):  # declared there, not inherited
            out.update(klass.__dict__["__dataclass_fields__"][name].metadata)
    return out


def doc_of(cls: type, name: str) -> str:
    """A field's docstring: the most derived class's that documents it."""
    for klass in cls.__mro__:
        if is_dataclass(klass) and name in klass.__dict__.get("__annotations__", {}):
            text = field_docs(klass).get(name)
            if text:
                return text
    return ""


SHARED = ("env", "map", "env_option", "episodes", "seed", "greedy", "out", "quiet", "json")
"""the shared groups' fields in the order every command lists them"""


def _ordered(cls: type) -> list[Field[Any]]:
    """The fields, the command's own first (as declared), then the shared groups' (SHARED)."""
    every = [f for f in fields(cls) if f.init]
    own = [f for f in every if group_of(cls, f.name) is None]
    shared = [f for f in every if group_of(cls, f.name) is not None]
    rank = {name: i for i, name in enumerate(SHARED)}
    return own + sorted(shared, key=lambda f: rank.get(f.name, len(SHARED)))


def _default(f: Field[Any]) -> Any:
    if f.default_factory is not MISSING:
        return f.default_factory()
    return None if f.default is MISSING else f.default


def _help(cls: type, f: Field[Any], meta: dict[str, Any], text: str | None = None) -> str:
    """The field's docstring (or ``text``) with its default, ``%`` escaped for argparse."""
    if meta.get("hidden"):
        return argparse.SUPPRESS
    text = doc_of(cls, f.name) if text is None else text
    if meta.get("fill"):
        text = text.format(**meta["fill"]())
    default = _default(f)
    shown = meta.get("shown")
    if shown is None and default is not None and default is not False and default != []:
        shown = (
            "on" if default is True
            else ",".join(map(str, default)) if isinstance(default, tuple)
            else f"{default:g}" if isinstance(default, float)
            else str(default)
        )  # fmt: skip
    if shown and not meta.get("switches"):
        text += f" (default: {shown})"
    return text.replace("%", "%%")


def _base(hint: Any) -> tuple[Any, bool]:
    """(the type without None, whether None is allowed)."""
    if get_origin(hint) in (Union, types.UnionType):
        rest = [a for a in get_args(hint) if a is not type(None)]
        return (rest[0] if len(rest) == 1 else hint), len(rest) < len(get_args(hint))
    return hint, False


def _add(container: Any, cls: type, f: Field[Any], hint: Any, meta: dict[str, Any]) -> None:
    """One field's flag (or positional argument, or pair of switches)."""
    kind, optional = _base(hint)
    help_text = _help(cls, f, meta)
    if meta.get("switches"):
        _add_switches(container, cls, f, meta)
        return
    extra: dict[str, Any] = {"help": help_text}
    if meta.get("metavar"):
        extra["metavar"] = meta["metavar"]
    if kind is bool:
        on = f.default is True or optional
        extra["action"] = argparse.BooleanOptionalAction if on else "store_true"
    elif get_origin(kind) is list:
        extra.update(action="append", type=meta.get("parse") or get_args(kind)[0])
    elif get_origin(kind) is Literal:
        extra["choices"] = get_args(kind)
    else:
        extra["type"] = meta.get("parse") or (kind if kind in (int, float, str) else str)
    if meta.get("positional"):
        container.add_argument(f.name, **extra)
        return
    required = f.default is MISSING and f.default_factory is MISSING
    if required:
        extra["required"] = True
    else:
        extra["default"] = _default(f)
    container.add_argument(meta.get("flag") or option_name(f.name), dest=f.name, **extra)


def _add_switches(container: Any, cls: type, f: Field[Any], meta: dict[str, Any]) -> None:
    """``--on | --off`` for one boolean, the default one marked so in its help."""
    on, off = meta["switches"]
    pair = container.add_mutually_exclusive_group()
    on_help = doc_of(cls, f.name) + (" (default)" if f.default else "")
    off_help = meta.get("off_help", "") + ("" if f.default else " (default)")
    pair.add_argument(on, dest=f.name, action="store_true", default=f.default, help=on_help)
    pair.add_argument(off, dest=f.name, action="store_false", default=f.default, help=off_help)
