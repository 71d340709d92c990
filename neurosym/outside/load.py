"""How a command line names an agent trained outside neurosym (``--checkpoint SPEC``).

* ``FILE.py:FUNCTION`` -- the user's Python file, imported, and ``FUNCTION()`` called: it
  returns an agent (:func:`neurosym.outside.TorchAgent` or :func:`neurosym.outside.sb3_agent`).
  This runs the user's own code, which they named on their own command line. A name read from
  a data file must never come here: the one such caller, the report page's card (a recording's
  ``checkpoint``), loads only names that are existing files, and an existing file is never
  read as ``FILE.py:FUNCTION`` (a bare ``FILE.py`` is refused, asking for the function).
* ``MODEL.zip`` (or ``sb3:MODEL.zip``) -- a Stable-Baselines3 model, read without running
  anything in it (:mod:`neurosym.outside.sb3`); its env is ``--env`` or the first neurosym env
  with its observation shape.

Anything else is a neurosym checkpoint. A bad form is one line saying what would be right.
"""

from __future__ import annotations

import hashlib
import importlib.util
import re
import sys
import traceback
from pathlib import Path
from typing import Any

from neurosym.errors import CheckpointError, ConfigError

_PY = re.compile(r"^(?P<file>.+\.py)(?::(?P<fn>.*))?$", re.DOTALL)
SB3_PREFIX = "sb3:"


def outside_spec(spec: Any) -> tuple[str, str, str] | None:
    """("python", file, function) or ("sb3", file, "") for an outside agent's name; None for
    anything else (a neurosym checkpoint, a shipped agent's name)."""
    text = str(spec)
    if text.startswith(SB3_PREFIX):
        return "sb3", text[len(SB3_PREFIX) :], ""
    path = Path(text)
    if text.lower().endswith(".zip"):
        from neurosym.outside.sb3 import is_sb3_zip

        # a zip that is no SB3 model is read as a checkpoint (torch's files are zips too)
        return ("sb3", text, "") if not path.is_file() or is_sb3_zip(path) else None
    if path.is_file() and not text.endswith(".py"):
        return None
    match = _PY.match(text)
    if match is None:
        return None
    fn = match["fn"]
    if fn is None:
        raise ConfigError(
            f"{text} is Python code: name the function in it that returns the agent, "
            f"--checkpoint {text}:make_agent"
        )
    if not fn.isidentifier():
        raise ConfigError(
            f"--checkpoint {text}: {fn!r} is not a function name; expected FILE.py:FUNCTION "
            "(make_agent, say)"
        )
    return "python", match["file"], fn


def load_outside(spec: str, env: str | None = None) -> Any:
    """The agent an outside spec names (:func:`outside_spec`), its ``path`` the spec itself."""
    kind, file, fn = outside_spec(spec) or ("", "", "")
    if kind == "sb3":
        from neurosym.outside.sb3 import is_sb3_zip, load_sb3_zip

        path = Path(file)
        if not path.is_file():
            raise CheckpointError(f"Stable-Baselines3 model not found: {file}")
        if not is_sb3_zip(path):
            raise CheckpointError(
                f"{file} is not a Stable-Baselines3 model (a zip with 'data' and 'policy.pth'); "
                "a neurosym checkpoint is a .pt file"
            )
        agent = load_sb3_zip(path, env)
    elif kind == "python":
        agent = _call_user_function(Path(file), fn)
    else:
        raise ConfigError(f"{spec} names no outside agent (FILE.py:FUNCTION or MODEL.zip)")
    return agent.with_path(str(spec))


def _call_user_function(file: Path, fn: str) -> Any:
    """Import the user's file and call ``fn()``; its errors are one line naming file and line."""
    from neurosym.outside.agent import OutsideAgent

    if not file.is_file():
        raise ConfigError(f"--checkpoint {file}:{fn}: no such file {file}")
    resolved = file.resolve()
    name = "neurosym_user_" + hashlib.sha256(str(resolved).encode()).hexdigest()[:12]
    module = sys.modules.get(name)
    if module is None:
        loader = importlib.util.spec_from_file_location(name, resolved)
        if loader is None or loader.loader is None:
            raise ConfigError(f"cannot import {file} as Python")
        module = importlib.util.module_from_spec(loader)
        sys.modules[name] = module
        folder = str(resolved.parent)
        sys.path.insert(0, folder)
        try:
            _user_call(resolved, f"importing {file}", lambda: loader.loader.exec_module(module))
        except BaseException:
            sys.modules.pop(name, None)
            raise
        finally:
            sys.path.remove(folder)
    make = getattr(module, fn, None)
    if not callable(make):
        found = [n for n, v in vars(module).items() if callable(v) and not n.startswith("_")
                 and getattr(v, "__module__", None) == name]  # fmt: skip
        raise ConfigError(
            f"{file} has no function {fn!r}; its functions: {', '.join(found) or 'none'}"
        )
    agent = _user_call(resolved, f"{file}:{fn}()", make)
    if not isinstance(agent, OutsideAgent):
        raise ConfigError(
            f"{file}:{fn}() returned a {type(agent).__name__}; it must return "
            "neurosym.outside.TorchAgent(...) or neurosym.outside.sb3_agent(...)"
        )
    return agent


def _user_call(file: Path, what: str, call: Any) -> Any:
    """``call()``, an error of the user's code becoming one line with its place in ``file``."""
    from neurosym.errors import NeurosymError

    try:
        return call()
    except NeurosymError:
        raise
    except Exception as exc:  # the user's code: any error, told in one line
        frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename) == file]
        where = f" ({file.name} line {frames[-1].lineno})" if frames else ""
        text = str(exc).strip().splitlines()
        raise ConfigError(
            f"{what} raised {type(exc).__name__}{': ' + text[0] if text else ''}{where}"
        ) from None
