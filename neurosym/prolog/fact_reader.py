"""Reading a fact file as data: the Prolog module ``pl/fact_reader.pl``, loaded once per process beside the bridge.

A knowledge base is something people pass around, so loading one must not
run it. Consulting a file runs its directives (``:- shell(...)``) and lets
it define ``term_expansion/2`` and other hooks; this reader never consults.
It reads the file term by term with ``read_term/3`` and admits only what has
the shape of a fact, rather than refusing a list of known bad forms:

* facts: a ground atom or compound whose name is a plain predicate name
  (a lowercase letter, then letters, digits, underscores: never an operator
  such as ``:-``, ``=>``, ``-->`` or ``:``, never a quoted name), nested at
  most :data:`~neurosym.terms.MAX_DEPTH` levels, and whose predicate is not
  built in, not a hook (``term_expansion``, ``goal_expansion``,
  ``portray``, ``message_hook``, ...), not autoloadable from the library,
  and not defined by the KB's rule files (static) or imported into its
  module;
* the headers neurosym's writer emits: ``:- encoding(Enc).`` (applied to the
  stream) and ``:- dynamic Name/Arity, ...`` (the same checks on each
  predicate).

Anything else, and text SWI-Prolog warns about while reading it, stops the
load with ``error-Text``, one line naming file, line and what was found, and
leaves the KB as it was. Files are read in threads whose C stack holds the
file's nesting (embedded in Python, SWI-Prolog has no guard against C-stack
overflow), files of 8 MB and more in parallel chunks with the result of a
front-to-back read. The module comment of ``pl/fact_reader.pl`` says how and
why in full; ``pl/fact_reader.plt`` beside it tests the rule in Prolog.
"""

from __future__ import annotations

from pathlib import Path

from neurosym.terms import MAX_DEPTH

MODULE = "neurosym_facts"

FILE = Path(__file__).resolve().with_name("pl") / "fact_reader.pl"
"""the Prolog module, shipped in the package"""

SETUP = (f"{MODULE}:set_max_depth(D)", {"D": MAX_DEPTH})
"""run once after loading it: terms deeper than :data:`~neurosym.terms.MAX_DEPTH` are refused"""
