"""What a KB load cannot go below: SWI-Prolog's own reading and adding of N facts, timed alone.

``KnowledgeBase(path)`` reads a KB as data: every term with ``read_term/3``,
checked, then added with ``assertz/1`` (neurosym/prolog/fact_reader.py). This
script times the parts of that work in a plain ``swipl`` process, with none of
neurosym's checks, on the relation/7 file of ``bench/kb.py`` (same generator,
same writer), so a load figure can be read against what the engine itself
costs:

* ``lines_cpu_s``: reading the file line by line (``read_line_to_string/2``),
  the least any text reader in Prolog does;
* ``read_term_cpu_s``: ``read_term/3`` of every term, nothing kept;
* ``read_assert_cpu_s``: ``read_term/3`` and ``assertz/1`` of every term;
* ``fast_read_assert_cpu_s``: the same terms from SWI-Prolog's binary
  ``fast_write/2`` format, read with ``fast_read/2`` and added (no parsing);
* ``qlf_load_s``: loading the file compiled to ``.qlf`` (clauses in bulk).

CPU seconds of one thread, the steadier figure on a shared machine; the
safe load spreads its work over the cores (up to 4), so its wall time is at
best the read-and-assert CPU time divided by the cores::

    python experiments/kb_read_floor.py                 # 1,000,000 facts
    python experiments/kb_read_floor.py --facts 100000

Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(
    0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bench")
)

from kb import relation_table  # noqa: E402

from neurosym.facts.prolog_writer import write_prolog  # noqa: E402
from neurosym.prolog.locate import find_swipl  # noqa: E402
from neurosym.prolog.qlf import qcompile  # noqa: E402
from neurosym.terms import atom_text  # noqa: E402

# Each timed goal reads stream S to its end; T0/T1 bracket it in CPU seconds.
_PROGRAM = r"""
:- use_module(library(readutil)).
:- dynamic relation/7.
lines(S) :- read_line_to_string(S, L), ( L == end_of_file -> true ; lines(S) ).
terms(S) :- read_term(S, T, []), ( T == end_of_file -> true ; terms(S) ).
adds(S) :- read_term(S, T, []), ( T == end_of_file -> true ; assertz(T), adds(S) ).
fast_adds(S) :- fast_read(S, T), ( T == end_of_file -> true ; assertz(T), fast_adds(S) ).
to_fast(In, Out) :-
    setup_call_cleanup(open(In, read, S), setup_call_cleanup(open(Out, write, O, [type(binary)]),
        copy_fast(S, O), close(O)), close(S)).
copy_fast(S, O) :- read_term(S, T, []), ( T == end_of_file -> true ; fast_write(O, T), copy_fast(S, O) ).
cpu(Goal, File, Type, Secs) :-
    retractall(relation(_, _, _, _, _, _, _)),
    setup_call_cleanup(open(File, read, S, [type(Type)]),
        ( statistics(cputime, T0), call(Goal, S), statistics(cputime, T1) ), close(S)),
    Secs is T1 - T0.
qlf(File, Secs) :-
    statistics(cputime, T0),
    setup_call_cleanup(open(File, read, S, [type(binary)]),
        load_files(neurosym_qlf:kb, [stream(S), format(qlf), silent(true)]), close(S)),
    statistics(cputime, T1), Secs is T1 - T0.
"""


def measure(pl: Path, qlf_path: Path, fast: Path) -> dict[str, float]:
    """CPU seconds of each part, timed in one fresh swipl."""
    text, q, f = atom_text(str(pl)), atom_text(str(qlf_path)), atom_text(str(fast))
    goal = (
        f"to_fast({text}, {f}),"
        f" cpu(lines, {text}, text, A), cpu(terms, {text}, text, B), cpu(adds, {text}, text, C),"
        f" cpu(fast_adds, {f}, binary, D), qlf({q}, E),"
        " format('~6f ~6f ~6f ~6f ~6f~n', [A, B, C, D, E])"
    )
    with tempfile.NamedTemporaryFile("w", suffix=".pl", delete=False) as prog:
        prog.write(_PROGRAM)
    try:
        out = subprocess.run(
            [str(find_swipl().executable), "-f", "none", "-q", "-g", goal, "-t", "halt", prog.name],
            capture_output=True, text=True, check=True,
        ).stdout  # fmt: skip
    finally:
        os.unlink(prog.name)
    names = (
        "lines_cpu_s",
        "read_term_cpu_s",
        "read_assert_cpu_s",
        "fast_read_assert_cpu_s",
        "qlf_load_s",
    )
    return {name: round(float(v), 3) for name, v in zip(names, out.split(), strict=True)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--facts", type=int, default=1_000_000, help="relation/7 facts in the file")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        pl = Path(tmp) / "relation.pl"
        write_prolog(pl, {"relation": relation_table(args.facts)})
        qlf_path = Path(qcompile(pl))
        out = {"facts": args.facts, "load_average": round(os.getloadavg()[0], 2)}
        out.update(measure(pl, qlf_path, Path(tmp) / "relation.fast"))
    print(json.dumps(out))


if __name__ == "__main__":
    main()
