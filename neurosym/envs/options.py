"""The options an environment takes, typed from its class's signature.

An option's type comes from the annotation of the env class's ``__init__``
parameter (or its default when it has none); options an env gathers in
``**kwargs`` (rgw-random's level parameters) are the fields of the dataclass
its registration names. So a new option is typed by declaring it, and two
things follow from one table: :func:`parse_value` turns command-line text
(``--env-option classic=false``) into the option's type, and :func:`check_value`
refuses a value of the wrong type given to ``make`` (``classic="false"`` would
otherwise be truthy).
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import math
import os
import types
import typing
from dataclasses import dataclass
from typing import Any

_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")
_EXPECTED = {
    "bool": "true or false",
    "int": "an integer",
    "float": "a number",
    "str": "a string",
    "path": "a file or map name",
    "any": "a value",
}


@dataclass(frozen=True)
class OptionType:
    """What values one option takes."""

    kind: str
    """"bool", "int", "float", "str", "path" (a str or os.PathLike) or "any" (unchecked)"""
    optional: bool = False
    """None is a value too (written ``none`` on the command line)"""
    choices: tuple[Any, ...] = ()
    """the only values allowed, when the annotation is a Literal"""

    def expected(self) -> str:
        """What a right value looks like, for error messages: ``an integer or none``."""
        text = (
            "one of " + ", ".join(str(c) for c in self.choices)
            if self.choices
            else _EXPECTED[self.kind]
        )
        return f"{text} or none" if self.optional else text


def load(path: str) -> Any:
    """The object named by ``"module:attribute"``."""
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)


def option_types(entry_point: str, extra: str = "") -> dict[str, OptionType]:
    """name -> OptionType of every option of the env class at ``entry_point``.

    ``extra``: ``"module:Dataclass"`` whose fields the class takes through ``**kwargs``.
    """
    cls = load(entry_point)
    params = inspect.signature(cls.__init__).parameters
    hints = _hints(cls.__init__)
    out = {
        name: _option_type(hints.get(name), p.default)
        for name, p in params.items()
        if name != "self" and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    }
    if extra:
        config = load(extra)
        hints = _hints(config)
        for f in dataclasses.fields(config):
            out.setdefault(f.name, _option_type(hints.get(f.name), f.default))
    return out


def _hints(obj: Any) -> dict[str, Any]:
    try:
        return typing.get_type_hints(obj)
    except Exception:  # an annotation that does not evaluate: fall back to the defaults
        return {}


def _option_type(annotation: Any, default: Any) -> OptionType:
    """The OptionType of an annotation (or, without one, of the default's type)."""
    if annotation is None:
        if default is inspect.Parameter.empty or default is None:
            return OptionType("any")
        annotation = type(default)
    origin = typing.get_origin(annotation)
    args = (
        typing.get_args(annotation) if origin in (typing.Union, types.UnionType) else (annotation,)
    )
    optional = type(None) in args
    rest = [a for a in args if a is not type(None)]
    literals = [a for a in rest if typing.get_origin(a) is typing.Literal]
    if literals:
        choices = tuple(c for lit in literals for c in typing.get_args(lit))
        kinds = {type(c) for c in choices}
        kind = {bool: "bool", int: "int", float: "float"}.get(next(iter(kinds)), "str")
        return OptionType(kind if len(kinds) == 1 else "any", optional, choices)
    if any(a is os.PathLike or typing.get_origin(a) is os.PathLike for a in rest):
        return OptionType("path", optional)
    for cls, kind in ((bool, "bool"), (float, "float"), (int, "int"), (str, "str")):
        if cls in rest:
            return OptionType(kind, optional)
    return OptionType("any", optional)


def parse_value(option: OptionType, text: str) -> Any:
    """Command-line text as a value of the option's type; ValueError saying what is expected."""
    if option.optional and text.strip().lower() in ("none", "null"):
        return None
    value: Any = text
    if option.kind == "bool":
        word = text.strip().lower()
        if word not in _TRUE + _FALSE:
            raise ValueError(option.expected())
        value = word in _TRUE
    elif option.kind == "int":
        try:
            value = int(text.strip(), 10)
        except ValueError:
            raise ValueError(option.expected()) from None
    elif option.kind == "float":
        try:
            value = float(text.strip())
        except ValueError:
            raise ValueError(option.expected()) from None
        if not math.isfinite(value):
            raise ValueError(f"a finite number{' or none' if option.optional else ''}")
    elif option.kind == "any":
        value = _literal(text)
    if option.choices and value not in option.choices:
        raise ValueError(option.expected())
    return value


def _literal(text: str) -> Any:
    """A Python literal when ``text`` is one, else the text (options of no declared type)."""
    import ast

    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError, MemoryError, RecursionError):
        return text


def check_value(option: OptionType, value: Any) -> bool:
    """Whether ``value`` (given to ``make``) has the option's type."""
    import numpy as np

    if value is None:
        return option.optional
    if option.choices:
        return value in option.choices
    is_bool = isinstance(value, bool | np.bool_)
    if option.kind == "bool":
        return is_bool
    if option.kind == "int":
        return isinstance(value, int | np.integer) and not is_bool
    if option.kind == "float":
        return isinstance(value, int | float | np.integer | np.floating) and not is_bool
    if option.kind == "str":
        return isinstance(value, str)
    if option.kind == "path":
        return isinstance(value, str | os.PathLike)
    return True
