"""The Prolog half of the janus bridge: the Prolog module ``pl/bridge.pl``, loaded once per process.

The file ships as package data (``pl/bridge.plt`` beside it tests it in
Prolog). What it does, and why in Prolog:

* ``new_kb/1`` makes a temporary module whose default is ``system`` (not
  ``user``), so a KB sees library predicates but nothing someone else put in
  ``user``; ``close_kb/2`` unloads its files and destroys the module.
* ``load/6`` loads one file into a KB module under a per-module source id,
  because SWI-Prolog refuses (or silently reconsults) one non-module file in
  two modules. Predicates already loaded are declared multifile first, so
  several fact files add up instead of replacing each other. Errors and
  warnings printed during the load are captured with ``message_hook/3`` and
  returned instead of being printed. The ``dynamic``, ``discontiguous`` and
  ``multifile`` directives a ``.qlf`` replays land in the KB's module.
* ``solve/8`` parses the goal text in the KB module, binds the inputs by
  variable name (values never pass through goal text), runs it under
  ``limit/2`` and returns every answer in one call, each value encoded so
  janus converts it unambiguously: atoms and strings -> str, numbers, lists
  -> list, compounds -> ``Functor-Args`` (a Python tuple), an unbound output
  -> None, a variable inside a value -> the dict ``var:N``. Values nested
  deeper than :data:`~neurosym.terms.MAX_DEPTH` (or cyclic) and integers of more than 4,300
  digits are refused with one line: Python could not take them.
* the goal text must be one goal: a variable, a number or text after its
  full stop is refused with one line.
"""

from __future__ import annotations

from pathlib import Path

from neurosym.terms import MAX_DEPTH

MODULE = "neurosym_bridge"

FILE = Path(__file__).resolve().with_name("pl") / "bridge.pl"
"""the Prolog module, shipped in the package"""

SETUP = (f"{MODULE}:set_max_depth(D)", {"D": MAX_DEPTH})
"""run once after loading it: answers deeper than :data:`~neurosym.terms.MAX_DEPTH` are refused"""
