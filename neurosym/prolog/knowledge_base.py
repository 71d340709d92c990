"""KnowledgeBase: fact files and rule files queried from Python through janus-swi.

Fact files are data, rule files are code (docs/design.md, "Prolog"). A KB is
something people pass around, so a fact file is never consulted: it is read
term by term (:mod:`neurosym.prolog.fact_reader`) and only ground facts
with plain predicate names and the writer's ``:- encoding``/``:- dynamic``
headers are admitted; anything else (directives, rules of any kind, hooks,
built-in or rule-defined predicates, terms nested deeper than
:data:`~neurosym.terms.MAX_DEPTH`, text that is not UTF-8) is refused with one
line naming file and line, and nothing of the file has run or stays loaded.
Every file is read once, into a private copy, and checked, loaded and
compiled from that copy only (:mod:`neurosym.prolog.snapshot`). Rule files (``rules=``) are consulted as code, before the
facts, so facts for a predicate the rules define are refused. ``trusted=``
(True, or the fact files to trust) consults fact files as code. A ``.qlf``
is compiled code and loads only when neurosym signed it on this account
(:mod:`neurosym.prolog.signature`) or when trusted. Queries take
``timeout=``, ``inferences=`` and ``stack_limit=``: a goal that goes past
one stops with a one-line :class:`~neurosym.errors.PrologError`. Ctrl-C
stops a running goal with :class:`KeyboardInterrupt` (Prolog checks for it
every 100,000 inferences; the KB stays usable).

Each KnowledgeBase lives in a Prolog module of its own, so several coexist in
one process even when they load the same rule file. A rule file that is a
module (the shipped ones: ``rules/rgw.pl`` is module ``rgw``) is loaded for
each KB as a module of its own (``rgw@<KB module>``) whose default import
module is the KB's, so its goals for facts are plain calls to that KB's facts
(``rules/lib/kb_common.pl``), and the KB imports its exports. Any other file
is plain Prolog, loaded into the KB's module. Either is loaded under a
per-module source id, because SWI-Prolog will not load one file into two
modules.

Values cross the boundary as data, never as goal text:

* inputs (``kb.query("object(Id, T)", Id="agent")``): ``str`` -> atom,
  ``int``/``float`` -> number, ``bool`` -> ``true``/``false``,
  :class:`~neurosym.terms.Term` -> compound, list/tuple -> list;
* outputs: atoms and strings -> ``str``, numbers -> ``int``/``float``,
  lists -> ``tuple`` (at the top of an answer as inside a Term, which must
  stay hashable, and as :func:`~neurosym.terms.parse_term` reads them),
  compound terms -> :class:`~neurosym.terms.Term` (whose ``str()`` is the
  canonical text that recordings store, e.g. ``picked(sword)``), an unbound
  output variable -> None, an unbound variable inside a value ->
  :class:`~neurosym.terms.Var` (``_G1``, shared within one answer).

Values are at most :data:`~neurosym.terms.MAX_DEPTH` levels deep each way,
integers in answers at most 4,300 digits (Python's limit for writing one);
a deeper or larger value is refused with one line.

Output variables are the goal's named variables that are not inputs; names
starting with ``_`` are left out. Any Prolog error (syntax, unknown
procedure, type) raises :class:`~neurosym.errors.PrologError` with Prolog's
message on one line; load errors name the file and line, load warnings
become :class:`PrologWarning`.

Several fact files add up: facts are added with ``assertz``, so a second
``relation/7`` file extends the first (trusted files consulted as code get
their loaded predicates declared multifile first, to the same end). Large
fact files load from ``.qlf`` with ``qlf=True`` (compiled by
:func:`neurosym.prolog.qlf.qcompile`, after the source has been checked as
data, on first use and again when the source changed, the signature does
not check, or the ``.qlf`` cannot be read); the
``dynamic``/``discontiguous``/``multifile`` directives in such files apply to
the KB's module, other directives run in module ``neurosym_qlf``.
"""

from __future__ import annotations

import itertools
import os
import re
import stat
import warnings
import weakref
from collections.abc import Iterable, Sequence
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from neurosym.errors import ConfigError, NeurosymError, OutputError, PrologError
from neurosym.prolog import bridge, fact_reader, signature
from neurosym.prolog.locate import janus_with
from neurosym.prolog.qlf import is_fresh, qcompile, qlf_path
from neurosym.prolog.snapshot import Snapshot, nesting_bound, nesting_of, snapshot
from neurosym.terms import MAX_DEPTH, Term, Var

if TYPE_CHECKING:
    import pandas as pd

PathArg = str | PathLike[str]
_VARIABLE = re.compile(r"[A-Z_][A-Za-z0-9_]*")
_SCALARS = frozenset({str, int, float, type(None)})
_INT64_MAX = (1 << 63) - 1
# How deeply a goal's text can nest (snapshot.nesting_of); the C stack
# SWI-Prolog parses it on holds far more than this many levels.
_GOAL_NESTING = 5_000
# The C stack of the threads that read a file: parsing took up to 566 bytes
# of it per level of nesting (SWI-Prolog 9.2, x86-64), and no term nests
# deeper than the file's nesting_bound. Address space is reserved, not memory:
# pages are taken only as a parse goes deep.
_C_STACK_BASE = 16 << 20
_C_STACK_PER_LEVEL = 768
_ids = itertools.count(1)


MAX_TIMEOUT = 1e9
"""The longest ``timeout`` a query takes, in seconds (about 32 years)."""


class Answers(NamedTuple):
    """The answers of a goal: output variable names, and one row of values per answer."""

    variables: list[str]
    rows: list[list[Any]]


class PrologWarning(UserWarning):
    """A warning SWI-Prolog printed while loading a file (singleton variables, discontiguous clauses).

    Its location is the user's file and line (not neurosym's source), and it
    is shown as one line, ``rules.pl:3: warning: Singleton variables: [X]``.
    """


_LOCATED = re.compile(r"(?P<file>.+?):(?P<line>\d+):(?:\d+:)? (?P<text>.*)")
_python_formatwarning = warnings.formatwarning


def _formatwarning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    line: str | None = None,
) -> str:
    """One plain line for a :class:`PrologWarning`; Python's format for every other warning."""
    if issubclass(category, PrologWarning):
        where = f"{filename}:{lineno}: " if lineno else ""
        return f"{where}warning: {message}\n"
    return _python_formatwarning(message, category, filename, lineno, line)


warnings.formatwarning = _formatwarning


def _warn(note: str) -> None:
    """Issue a Prolog load warning located at the file and line it names."""
    located = _LOCATED.fullmatch(note)
    if located:
        filename, lineno, text = located["file"], int(located["line"]), located["text"]
    else:
        filename, lineno, text = "prolog", 0, note
    warnings.warn_explicit(text, PrologWarning, filename, lineno, module="neurosym.prolog")


class KnowledgeBaseFileNotFoundError(NeurosymError, FileNotFoundError):
    """A fact or rule file that does not exist."""


_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def _existing(path: PathArg) -> Path:
    """``path`` resolved, when it is a regular file whose name SWI-Prolog can take; else one line."""
    path = Path(path)
    shown = _shown(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise KnowledgeBaseFileNotFoundError(f"no such Prolog file: {shown}") from None
    except OSError as exc:
        raise PrologError(f"cannot read {shown}: {exc.strerror or type(exc).__name__}") from None
    if not stat.S_ISREG(mode):
        kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
        raise ConfigError(
            f"cannot load {shown}: it is {kind}; a Prolog file (.pl or .qlf) is a regular file"
        )
    return _utf8_path(path.resolve())


def _shown(path: Path) -> str:
    """``path`` as text, bytes that are not UTF-8 written as ``\\xNN``."""
    return os.fsencode(path).decode("utf-8", "backslashreplace")


def _utf8_path(path: Path) -> Path:
    """``path``, when its name is valid UTF-8 (janus cannot pass any other name to Prolog)."""
    try:
        str(path).encode("utf-8")
    except UnicodeEncodeError:
        raise ConfigError(
            f"cannot load {_shown(path)}: its name is not valid UTF-8, and SWI-Prolog opens files "
            "by UTF-8 names; rename it (or copy it to a UTF-8 name)"
        ) from None
    return path


def _trust(trusted: bool | PathArg | Sequence[PathArg]) -> Any:
    """``trusted`` (True, False, or the files to trust) -> path -> bool."""
    if isinstance(trusted, bool):
        return lambda path: trusted
    chosen = {Path(p).resolve() for p in _as_paths(trusted)}
    return lambda path: Path(path).resolve() in chosen


def _sha256(path: Path) -> str:
    """The SHA-256 of ``path``'s bytes; a file that cannot be read is one line."""
    try:
        return signature.sha256(path)
    except OSError as exc:
        raise PrologError(f"cannot read {path}: {exc.strerror or type(exc).__name__}") from None


def _janus() -> Any:
    """janus with the bridge module and the fact reader loaded (once per process)."""
    return janus_with(bridge, fact_reader)


def _call_once(goal: str, inputs: dict[str, Any]) -> dict[str, Any]:
    janus = _janus()
    try:
        return janus.query_once(goal, inputs)
    except janus.PrologError as exc:  # the bridge catches user errors; this is a bug or a crash
        if str(exc).startswith("Python 'KeyboardInterrupt'"):  # Ctrl-C, seen at a heartbeat
            raise KeyboardInterrupt from None
        raise PrologError(_one_line(str(exc))) from exc


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _to_prolog(value: Any, name: str, depth: int = 0) -> Any:
    """Python input value -> what janus turns into the intended Prolog term."""
    if depth > MAX_DEPTH:
        raise ConfigError(f"input {name} is nested more than {MAX_DEPTH} levels deep")
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return value
    if isinstance(value, Term):
        if not value.args:
            return value.functor
        args = [_to_prolog(a, name, depth + 1) for a in value.args]
        return ("$neurosym_term", value.functor, args)
    if isinstance(value, list | tuple):
        return [_to_prolog(v, name, depth + 1) for v in value]
    kind = getattr(getattr(value, "dtype", None), "kind", None)
    if kind in ("b", "i", "u", "f", "U"):  # numpy scalars
        return _to_prolog(value.item(), name, depth)
    if value is None:
        raise ConfigError(f"input {name} is None; leave it out to keep {name} a free variable")
    raise ConfigError(f"input {name}: cannot pass a {type(value).__name__} to Prolog")


def _from_prolog(value: Any) -> Any:
    """What the bridge encoded -> Python value (see the module docstring)."""
    if type(value) in _SCALARS:
        return value
    if isinstance(value, tuple):
        functor, args = value
        for i, arg in enumerate(args):  # a loop, not a generator: one Python frame per level
            if type(arg) not in _SCALARS:
                args[i] = _from_prolog(arg)
        return Term(functor, tuple(args))
    if isinstance(value, list):  # a tuple, as inside a Term (which must stay hashable)
        for i, item in enumerate(value):
            if type(item) not in _SCALARS:
                value[i] = _from_prolog(item)
        return tuple(value)
    if isinstance(value, dict):  # the bridge's var:N
        return Var(f"_G{value['var']}")
    return value


def _bounds(
    timeout: float | None, inferences: int | None, stack_limit: int | None
) -> list[tuple[str, float | int]]:
    """The query's bounds as ``Name-Value`` pairs for the bridge, checked."""
    out: list[tuple[str, float | int]] = []
    if timeout is not None:
        if (
            isinstance(timeout, bool)
            or not isinstance(timeout, int | float)
            or not 0 < timeout <= MAX_TIMEOUT
        ):
            raise ConfigError(
                f"timeout must be a positive number of seconds up to {MAX_TIMEOUT:.0e} "
                f"(a year is 3e7), not {timeout!r}"
            )
        out.append(("timeout", float(timeout)))
    for name, value, floor in (
        ("inferences", inferences, 1),
        ("stack_limit", stack_limit, 1 << 20),
    ):
        if value is None:
            continue
        if (
            isinstance(value, bool)
            or not isinstance(value, int)
            or not floor <= value <= _INT64_MAX
        ):
            raise ConfigError(
                f"{name} must be an integer of at least {floor} and at most 2**63-1, not {value!r}"
            )
        out.append(("inferences" if name == "inferences" else "stack", value))
    return out


def _as_paths(paths: PathArg | Iterable[PathArg] | None) -> list[Path]:
    if paths is None:
        return []
    if isinstance(paths, str | PathLike):
        return [Path(paths)]
    return [Path(p) for p in paths]


class KnowledgeBase:
    """Facts and rules in a Prolog module of their own; query them with Python values.

    >>> with KnowledgeBase("kb/rgw2.pl", rules=["rules/rgw.pl"]) as kb:
    ...     kb.query("event(E, T, picked(Item))", E=0)
    [{'T': 4, 'Item': 'sword'}]
    """

    def __init__(
        self,
        facts: PathArg | Sequence[PathArg] | None,
        rules: PathArg | Sequence[PathArg] = (),
        *,
        qlf: bool = False,
        trusted: bool | PathArg | Sequence[PathArg] = False,
    ) -> None:
        self.module = f"neurosym_kb_{next(_ids)}"
        self.files: list[Path] = []
        self._closed = False
        _call_once(f"{bridge.MODULE}:new_kb(M)", {"M": self.module})
        self._source_ids: list[str] = []  # what to unload on close
        self._rule_ids: list[str] = []  # the source ids of the rule files
        self._finalizer = weakref.finalize(self, _close_module, self.module, self._source_ids)
        self._finalizer.atexit = False
        trust = _trust(trusted)
        try:
            # Rules first: a fact file may then be checked against what they define.
            for path in _as_paths(rules):
                self.load_rules(path)
            for path in _as_paths(facts):
                self.load(path, qlf=qlf, trusted=trust(path))
        except BaseException:
            self.close()
            raise

    # -- loading -----------------------------------------------------------

    def load(self, path: PathArg, *, qlf: bool = False, trusted: bool = False) -> None:
        """Load one more fact file into this KB, as data.

        The file is read term by term and only facts (and the ``:- encoding``
        and ``:- dynamic`` headers neurosym writes) are accepted; a directive,
        a rule, a hook or built-in predicate, or a predicate the rules define
        raises :class:`PrologError` naming file and line, and nothing of the
        file is loaded or run. ``trusted=True`` consults the file as code
        instead (directives run). A ``.qlf`` is compiled code: it is loaded
        only when neurosym compiled it on this account (its signature checks,
        :mod:`neurosym.prolog.signature`) or when trusted. With ``qlf=True`` a
        ``.pl`` source loads through its ``.qlf``, compiled (after the source
        has been checked as data) when missing, stale, unsigned, or written by
        another SWI-Prolog version.
        """
        self._check_open()
        path = _existing(path)
        if path.suffix == ".qlf":
            if trusted:
                self._finish(path, *self._load_file(path, "qlf"))
            else:
                self._load_signed_qlf(path)
        elif qlf:
            self._load_through_qlf(path, trusted)
        elif trusted:
            self._finish(path, *self._load_file(path, "source"))
        else:
            self._read_facts(path, "assert")
            self.files.append(path)

    def _load_signed_qlf(self, path: Path) -> None:
        """Load a ``.qlf`` from a private copy of the very bytes whose signature was checked."""
        with snapshot(path) as copy:
            reason = signature.check_digests(path, copy.sha256)
            if reason is not None:
                raise PrologError(
                    f"cannot load {path}: a .qlf is compiled code and this one was not "
                    f"compiled by neurosym on this account ({reason}); load its .pl source "
                    f"instead, or trust the file (--trust {path.name} / trusted=True)"
                )
            self._finish(path, *self._load_file(path, "qlf", data=copy.path, nesting=copy.nesting))

    def load_rules(self, path: PathArg) -> None:
        """Load one rule file into this KB, as code (its directives run; a ``.qlf`` loads as is).

        A bare name (``"rgw"``) is a shipped rule file (:func:`neurosym.shipped.rule_file`).
        A module file gets a copy of its module per KB, whose goals for facts
        resolve to this KB's facts, and the KB imports its exports. Syntax and
        other load errors raise
        :class:`PrologError` naming the file and line, and the file's clauses
        are unloaded again; warnings become :class:`PrologWarning`.
        """
        from neurosym.shipped import rule_file

        self._check_open()
        path = _existing(rule_file(path))
        fmt = "qlf" if path.suffix == ".qlf" else "rules"
        before = len(self._source_ids)
        self._finish(path, *self._load_file(path, fmt))
        self._rule_ids.extend([*self._source_ids[before:], str(path)])

    def _load_through_qlf(self, path: Path, trusted: bool) -> None:
        """Load ``path`` through its ``.qlf``, compiled first when that one will not do.

        The source is hashed to find a ``.qlf`` signed for those bytes, which
        is loaded from a private copy of the bytes whose signature was
        checked. Otherwise the source is read into a private copy that is
        hashed, checked as data and compiled, so the ``.qlf`` comes from the
        very bytes that were checked.
        """
        target = qlf_path(path)
        if trusted and is_fresh(path):
            errors, notes = self._load_file(path, "qlf")
            if not errors:
                self._finish(path, errors, notes)
                return
        if not trusted and self._load_qlf_if_signed(path, target, _sha256(path)):
            return
        with snapshot(path) as source:
            if not trusted:
                self._read_facts(path, "check", source)  # nothing of an unchecked source is compiled
            try:
                qcompile(source.path, target=target)
            except OutputError as exc:
                raise OutputError(f"{exc}; load {path.name} without --qlf (qlf=False)") from None
            built = qlf_path(source.path)  # the private .qlf just copied to target
            self._finish(path, *self._load_file(path, "qlf", data=built))

    def _load_qlf_if_signed(self, path: Path, target: Path, source_sha: str) -> bool:
        """Load ``target`` when its signature vouches for it and ``source_sha``; False otherwise."""
        if not target.is_file():
            return False
        with snapshot(target) as copy:
            if signature.check_digests(target, copy.sha256, source_sha, path.name) is not None:
                return False
            errors, notes = self._load_file(path, "qlf", data=copy.path, nesting=copy.nesting)
        if errors:  # e.g. a .qlf of another SWI-Prolog version: compiled again
            return False
        self._finish(path, errors, notes)
        return True

    def _read_facts(self, path: Path, mode: str, copy: Snapshot | None = None) -> int:
        """Read ``path`` as data (mode 'assert') or only check it ('check'); the number of terms.

        The file is read from a private copy (``copy``, or one made here), so
        that what is checked is what is loaded.
        """
        if copy is None:
            with snapshot(path, digest=False) as copy:
                return self._read_facts(path, mode, copy)
        answer = _call_once(
            f"{fact_reader.MODULE}:load_facts(M, File, Mode, Rules, CStack, Count, Status)",
            {
                "M": self.module,
                "File": str(copy.path),
                "Mode": mode,
                "Rules": self._rule_ids,
                "CStack": _C_STACK_BASE + _C_STACK_PER_LEVEL * copy.nesting,
            },
        )
        status = answer["Status"]
        if status != "ok":
            _, text = status
            raise PrologError(f"cannot load {self._clean(text.replace(str(copy.path), str(path)))}")
        return int(answer["Count"])

    def _finish(self, path: Path, errors: list[str], notes: list[str]) -> None:
        if errors:
            more = f" (and {len(errors) - 1} more errors)" if len(errors) > 1 else ""
            first = errors[0] if str(path) in errors[0] else f"{path}: {errors[0]}"
            raise PrologError(f"cannot load {first}{more}")
        for note in notes:
            _warn(note)
        self.files.append(path)

    def _load_file(
        self, path: Path, fmt: str, data: Path | None = None, nesting: int | None = None
    ) -> tuple[list[str], list[str]]:
        """Load ``path`` (its .qlf when fmt is 'qlf'); return (errors, warnings), unloading on error.

        ``data``: the file to read the bytes from (a private copy), when not
        ``path`` itself. ``nesting``: the nesting bound that sizes the loading
        thread's C stack, when known: a signed ``.qlf`` is sized by the
        brackets counted as it was copied (its terms come from a source
        checked as data, at most MAX_DEPTH deep, or from trusted code), other
        files by :func:`~neurosym.prolog.snapshot.nesting_bound`.
        """
        if fmt == "qlf":
            load_file = data or qlf_path(path)
            # A per-module directory: SWI-Prolog relocates the .qlf's recorded
            # source path into it, so each KB owns its own copy of the clauses.
            source_id = f"{path.parent}/.{self.module}/{load_file.name}"
            clause_source = f"{path.parent}/.{self.module}/{path.stem}.pl"
            aliases = {clause_source: str(path.with_suffix(".pl")), source_id: str(path)}
        else:
            load_file = data or path
            source_id = f"{path}#{self.module}"  # same directory: relative includes still resolve
            aliases = {source_id: str(path)}
        if nesting is None:
            nesting = nesting_bound(load_file)
        c_stack = _C_STACK_BASE + _C_STACK_PER_LEVEL * nesting
        answer = _call_once(
            f"{bridge.MODULE}:load(M, Id, File, Format, CStack, Messages)",
            {
                "M": self.module,
                "Id": source_id,
                "File": str(load_file),
                "Format": fmt,
                "CStack": c_stack,
            },
        )
        errors, notes = [], []
        for kind, text in answer["Messages"]:
            for alias, real in aliases.items():
                text = text.replace(alias, real)
            text = self._clean(text)
            (errors if kind == "error" else notes).append(text)
        if errors:
            _call_once(
                "forall(member(_Id, Ids), catch(unload_file(_Id), _, true))", {"Ids": list(aliases)}
            )
        else:
            self._source_ids.extend(aliases)
        return errors, notes

    # -- querying ----------------------------------------------------------

    def solve(
        self,
        goal: str,
        /,
        *,
        limit: int | None = None,
        timeout: float | None = None,
        inferences: int | None = None,
        stack_limit: int | None = None,
        **inputs: Any,
    ) -> Answers:
        """Every answer as rows of values, with the output variable names (the cheapest form).

        ``timeout`` (seconds), ``inferences`` (a count) and ``stack_limit``
        (bytes of Prolog stack, default SWI-Prolog's 1 GB) bound the goal: going
        past one stops it with a one-line :class:`PrologError` whose ``term`` is
        ``"timeout"``, ``"inferences"`` or ``"stack"``; the KB stays usable.
        """
        self._check_open()
        answer = _call_once(
            f"{bridge.MODULE}:solve(M, Goal, Inputs, Limit, Bounds, Names, Rows, Status)",
            {
                "M": self.module,
                "Goal": self._goal(goal),
                "Inputs": self._inputs(inputs),
                "Limit": self._limit(limit),
                "Bounds": _bounds(timeout, inferences, stack_limit),
            },
        )
        self._check_status(answer["Status"], goal)
        rows = answer["Rows"]
        for row in rows:
            for i, value in enumerate(row):
                if type(value) not in _SCALARS:
                    row[i] = _from_prolog(value)
        return Answers(answer["Names"], rows)

    def query(
        self, goal: str, /, *, limit: int | None = None, **options: Any
    ) -> list[dict[str, Any]]:
        """Every answer of ``goal`` (at most ``limit``) as a dict: output variable -> value.

        Keyword arguments named like the goal's variables bind them:
        ``kb.query("holds(E, T, R, A, B)", A="agent")``; ``timeout``,
        ``inferences`` and ``stack_limit`` bound the goal (see :meth:`solve`).
        """
        names, rows = self.solve(goal, limit=limit, **options)
        return [dict(zip(names, row, strict=True)) for row in rows]

    def query_df(self, goal: str, /, *, limit: int | None = None, **options: Any) -> pd.DataFrame:
        """Like :meth:`query`, as a DataFrame with one column per output variable (even when empty)."""
        import pandas as pd

        names, rows = self.solve(goal, limit=limit, **options)
        return pd.DataFrame(rows, columns=names)

    def once(self, goal: str, /, **options: Any) -> dict[str, Any] | None:
        """The first answer of ``goal``, or None when it has none."""
        answers = self.query(goal, limit=1, **options)
        return answers[0] if answers else None

    def count(
        self,
        goal: str,
        /,
        *,
        timeout: float | None = None,
        inferences: int | None = None,
        stack_limit: int | None = None,
        **inputs: Any,
    ) -> int:
        """How many answers ``goal`` has (counted in Prolog; nothing is converted)."""
        self._check_open()
        answer = _call_once(
            f"{bridge.MODULE}:count(M, Goal, Inputs, all, Bounds, N, Status)",
            {
                "M": self.module,
                "Goal": self._goal(goal),
                "Inputs": self._inputs(inputs),
                "Bounds": _bounds(timeout, inferences, stack_limit),
            },
        )
        self._check_status(answer["Status"], goal)
        return int(answer["N"])

    # -- lifetime ----------------------------------------------------------

    def close(self) -> None:
        """Unload the files and drop the module; the KB cannot be queried afterwards."""
        if not self._closed:
            self._closed = True
            self._finalizer.detach()
            _close_module(self.module, self._source_ids)

    def __enter__(self) -> KnowledgeBase:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else ", ".join(str(p) for p in self.files)
        return f"KnowledgeBase({self.module}: {state})"

    # -- helpers -----------------------------------------------------------

    def _check_open(self) -> None:
        if self._closed:
            raise NeurosymError(f"knowledge base {self.module} is closed")

    def _clean(self, text: str) -> str:
        """Prolog's text without this KB's module names (``neurosym_kb_3:``, ``'rgw@neurosym_kb_3'``)."""
        text = re.sub(rf"'([a-z]\w*)@{self.module}'", r"\1", text)
        return _one_line(text.replace(f"{self.module}:", ""))

    def _check_status(self, status: Any, goal: str) -> None:
        if status == "ok":
            return
        kind, detail = status
        if kind == "missing":
            raise ConfigError(f"input {', '.join(detail)} is not a variable of the goal {goal!r}")
        if kind == "limit":
            which = {"time": "timeout", "inference": "inferences"}.get(detail.split(" ", 1)[0])
            raise PrologError(self._clean(detail), term=which or "stack")
        raise PrologError(self._clean(detail))

    @staticmethod
    def _goal(goal: str) -> str:
        if not isinstance(goal, str) or not goal.strip():
            raise ConfigError(
                f"the goal must be Prolog text such as 'object(Id, Type)', not {goal!r}"
            )
        if nesting_of(goal) > _GOAL_NESTING:
            raise ConfigError(
                f"the goal could nest more than {_GOAL_NESTING:,} levels deep (opening brackets "
                "and prefix operators); pass large values as inputs (keyword arguments), not as goal text"
            )
        return goal

    @staticmethod
    def _inputs(inputs: dict[str, Any]) -> list[tuple[str, Any]]:
        out = []
        for name, value in inputs.items():
            if not _VARIABLE.fullmatch(name):
                raise ConfigError(
                    f"input {name!r} is not a Prolog variable name (start it with a capital)"
                )
            out.append((name, _to_prolog(value, name)))
        return out

    @staticmethod
    def _limit(limit: int | None) -> int | str:
        if limit is None:
            return "all"
        if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
            raise ConfigError(f"limit must be a positive integer, not {limit!r}")
        return limit


def _close_module(module: str, source_ids: list[str]) -> None:
    try:
        _call_once(f"{bridge.MODULE}:close_kb(M, Files)", {"M": module, "Files": source_ids})
    except Exception:  # noqa: BLE001 - closing must never mask the real error
        pass
