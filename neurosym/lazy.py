"""Package attributes imported on first use (PEP 562), so that importing a package stays cheap.

``import neurosym`` and the commands that need no network (``neurosym query``,
``neurosym induce``) never pay for importing torch: a package lists its public
names with the module each lives in and hands :func:`lazy_attributes`'s
function to Python as its module ``__getattr__``.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any


def lazy_attributes(package: str, names: Mapping[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package``: ``names[name]`` is imported when ``name`` is first
    asked for, and the value kept in the package so that later lookups do not come back here."""

    def __getattr__(name: str) -> Any:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    return __getattr__
