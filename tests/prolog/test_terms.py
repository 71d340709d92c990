"""Canonical Prolog text of Python values (neurosym.terms) and reading it back."""

from __future__ import annotations

import math
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from neurosym.errors import FactError
from neurosym.terms import Term, atom_text, float_text, format_value, parse_term


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("sword", "sword"),
        ("key_2", "key_2"),
        ("Sword", "'Sword'"),
        ("_x", "'_x'"),
        ("2nd", "'2nd'"),
        ("", "''"),
        ("a b", "'a b'"),
        ("it's", "'it\\'s'"),
        ("back\\slash", "'back\\\\slash'"),
        ("épée", "'épée'"),
        ("-", "'-'"),
        ("[]", "'[]'"),
        ("{}", "'{}'"),
        ("a\n", "'a\\n'"),
        ("tab\there", "'tab\\there'"),
        ("\x00\x7f\x85", "'\\x0\\\\x7f\\\\x85\\'"),
    ],
)
def test_atom_text_quotes_exactly_when_needed(name: str, text: str) -> None:
    assert atom_text(name) == text


def test_atom_with_lone_surrogate_is_refused() -> None:
    with pytest.raises(FactError, match="surrogate"):
        atom_text("a\ud800")


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (0.5, "0.5"),
        (-0.0, "-0.0"),
        (100.0, "100.0"),
        (1e16, "1.0e16"),
        (1.5e-7, "1.5e-7"),
        (1e-05, "1.0e-5"),
        (5e-324, "5.0e-324"),
        (1.7976931348623157e308, "1.7976931348623157e308"),
    ],
)
def test_float_text_is_prolog_syntax(value: float, text: str) -> None:
    assert float_text(value) == text


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_nan_and_infinity_are_refused(value: float) -> None:
    with pytest.raises(FactError, match="NaN/inf"):
        float_text(value)


def test_term_text() -> None:
    assert str(Term("picked", ("sword",))) == "picked(sword)"
    assert str(Term("opened", (Term("lock", ("red",)),))) == "opened(lock(red))"
    assert str(Term("teleported")) == "teleported"
    assert str(Term("-", (1,))) == "'-'(1)"
    assert str(Term("f", ("A", -3, 0.25, True, ("a", ())))) == "f('A',-3,0.25,true,[a,[]])"
    assert format_value(2**70) == "1180591620717411303424"


def test_term_lists_become_tuples_so_terms_stay_hashable() -> None:
    term = Term("path", [["a", "b"], 1])  # type: ignore[arg-type]
    assert term.args == (("a", "b"), 1)
    assert hash(term) == hash(Term("path", (("a", "b"), 1)))


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("sword", "sword"),
        ("'Sword'", "Sword"),
        ("'it''s'", "it's"),
        ("'\\x41\\\\101\\'", "AA"),
        ("-12", -12),
        ("1.0e16", 1e16),
        ("1e3", 1000.0),
        ("f( a , [ ] )", Term("f", ("a", ()))),
        ("[a,[1,2]]", ("a", (1, 2))),
        ("-(1)", Term("-", (1,))),
        ("key(red)", Term("key", ("red",))),
    ],
)
def test_parse_term(text: str, value: object) -> None:
    assert parse_term(text) == value


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("f(X)", "variable X"),
        ("a-b", "trailing text at character 1"),
        ("f(a", "unexpected end"),
        ("'open", "unexpected"),
        ("f(a) g", "trailing text"),
        ("", "unexpected end"),
    ],
)
def test_parse_term_errors_name_the_position(text: str, message: str) -> None:
    with pytest.raises(FactError, match=message):
        parse_term(text)


atoms = st.text(max_size=12) | st.sampled_from(
    ["", "[]", "{}", "-", ";", "!", "a b", "It's", "\\", "é", "is"]
)
numbers = st.integers(min_value=-(2**100), max_value=2**100) | st.floats(
    allow_nan=False, allow_infinity=False
)
terms = st.recursive(
    atoms | numbers,
    lambda children: (
        st.builds(
            Term,
            atoms.filter(lambda a: a not in ("[|]", ".")),  # refused as '/2 (see below)
            st.lists(children, min_size=1, max_size=3).map(tuple),
        )
        | st.lists(children, max_size=3).map(tuple)
    ),
    max_leaves=12,
)


def _key(value: object) -> object:
    """Equality that tells -0.0 from 0.0 and 1 from 1.0."""
    if isinstance(value, float):
        return ("float", math.copysign(1.0, value), value)
    if isinstance(value, Term):
        return ("term", value.functor, tuple(_key(a) for a in value.args))
    if isinstance(value, tuple):
        return ("list", tuple(_key(a) for a in value))
    return (type(value).__name__, value)


@settings(max_examples=300, deadline=None)
@given(terms)
def test_parse_term_reads_back_what_format_value_writes(value: object) -> None:
    assert _key(parse_term(format_value(value))) == _key(value)


@pytest.mark.parametrize("functor", [".", "[|]"])
def test_pairs_that_prolog_reads_as_something_else_are_refused(functor: str) -> None:
    with pytest.raises(FactError, match=f"'{re.escape(functor)}'/2 compound cannot be written"):
        str(Term(functor, ("a", "b")))
    assert str(Term(functor, ("a",))) == f"'{functor}'(a)"  # other arities are plain compounds
