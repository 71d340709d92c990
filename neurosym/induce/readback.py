"""A learned file is written only when it reads back as exactly the clauses learned.

The writers of learned files (:mod:`neurosym.induce.world`,
:mod:`neurosym.induce.strategy_writer`) spell every value through
:mod:`neurosym.terms`, keep data out of anything but one-line ``%`` comments,
and then hand the text to :func:`check_reads_back` with what it must hold:
the fixed code (directives, background predicates: text of this package,
no data) and each learned clause as a :class:`~neurosym.terms.Term`
structure. SWI-Prolog reads the text with ``read_term/3`` (nothing is run:
no directive, no term expansion, quasi-quotations refused) and compares it,
term by term, with what the parts say; a file that holds one term more or
less, or any term that differs (an atom read as a variable, a quote that
closes early), is refused with one line and not written.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from neurosym.display import plain
from neurosym.errors import OutputError
from neurosym.terms import Term

MODULE = "neurosym_readback"

SOURCE = r"""
:- module(neurosym_readback, [readback/4]).

%   readback(+Text, +Kinds, +Texts, -Result): read Text term by term and compare it with
%   the terms of the parts (Kinds: code, every term of the text; term: exactly one term).
%   Result: "" when they are the same, else a string saying where they differ.
readback(Text, Kinds, Texts, Result) :-
    catch(readback_(Text, Kinds, Texts, Result), E, error_text_(E, Result)).

readback_(Text, Kinds, Texts, Result) :-
    terms_of_(Text, Got),
    parts_(Kinds, Texts, Wants),
    append(Wants, Want),
    compare_(Got, Want, 1, Result).

error_text_(error(format(F, A), _), Result) :- !,
    format(string(Result), F, A).
error_text_(error(syntax_error(What), stream(_, Line, _, _)), Result) :- !,
    format(string(Result), 'syntax error: ~w on line ~d', [What, Line]).
error_text_(E, Result) :-
    format(string(Result), '~q', [E]).

parts_([], [], []).
parts_([K|Ks], [T|Ts], [Terms|Rest]) :-
    atom_string(Kind, K),
    part_(Kind, T, Terms),
    parts_(Ks, Ts, Rest).

part_(code, Text, Terms) :- terms_of_(Text, Terms).
part_(term, Text, [Term]) :-
    (   terms_of_(Text, [Term0]) -> Term = Term0 ; throw(error(format('not one term: ~s', [Text]), _)) ).

terms_of_(Text, Terms) :-
    setup_call_cleanup(open_string(Text, S), read_all_(S, Terms), close(S)).

read_all_(S, Terms) :-
    read_term(S, T, [ variable_names(Vs), quasi_quotations(QQ), syntax_errors(error),
                      module(neurosym_readback) ]),
    (   QQ \== []
    ->  throw(error(format('a quasi-quotation', []), _))
    ;   T == end_of_file
    ->  Terms = []
    ;   name_vars_(Vs),
        Terms = [T|Rest],
        read_all_(S, Rest)
    ).

name_vars_([]).
name_vars_([Name=Var|Vs]) :- Var = '$VAR'(Name), name_vars_(Vs).

compare_([], [], _, "") :- !.
compare_([G|_], [], I, Result) :- !,
    text_(G, GT), format(string(Result), 'term ~d, ~s, is not one of them', [I, GT]).
compare_([], [W|_], I, Result) :- !,
    text_(W, WT), format(string(Result), 'term ~d, ~s, is missing', [I, WT]).
compare_([G|Gs], [W|Ws], I, Result) :-
    (   G =@= W
    ->  I1 is I + 1, compare_(Gs, Ws, I1, Result)
    ;   text_(G, GT), text_(W, WT),
        format(string(Result), 'term ~d reads as ~s, not ~s', [I, GT, WT])
    ).

text_(T, Text) :-
    format(string(Text), '~W', [T, [quoted(true), numbervars(true), ignore_ops(true)]]).
"""


def comment(text: str) -> str:
    """``text`` as one ``%`` comment line: control characters and newlines shown as escapes,
    so no data can end the comment and become code."""
    return "% " + plain(text) if text else "%"


@dataclass(frozen=True)
class Code:
    """Fixed Prolog text of this package (directives, background predicates): no data in it."""

    text: str


Part = Code | Term
"""What a learned file holds, in order: fixed code, or one learned clause or directive as a term."""


def check_reads_back(text: str, parts: list[Part], path: str | os.PathLike[str]) -> None:
    """Refuse (:class:`OutputError`, one line) a text that does not read back as ``parts``.

    Each :class:`Code` part stands for every term of its text; each
    :class:`Term` part for exactly that term (its :class:`~neurosym.terms.Var`
    arguments are the clause's variables, by name).
    """
    from neurosym.prolog.locate import janus_with

    janus = janus_with(_module())
    kinds = ["code" if isinstance(p, Code) else "term" for p in parts]
    texts = [p.text if isinstance(p, Code) else f"{p} ." for p in parts]
    answer = janus.query_once(
        f"{MODULE}:readback(Text, Kinds, Texts, Result)", {"Text": text, "Kinds": kinds, "Texts": texts}
    )
    difference = str(answer["Result"])
    if difference:
        raise OutputError(
            f"refusing to write {plain(os.fspath(path))}: the learned file would not read back as "
            f"the clauses learned ({plain(difference)}); nothing was written"
        )


def _module():  # type: ignore[no-untyped-def]
    """This module as janus_with's embedded Prolog module (its MODULE and SOURCE)."""
    import sys

    return sys.modules[__name__]
