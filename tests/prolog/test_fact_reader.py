"""The fact reader's parallel chunks give exactly what reading front to back gives.

Large fact files are cut at line starts and read by helper threads; these
tests lower the size at which that happens so that small files with traps
(cuts inside quoted atoms and comments, a payload in a late chunk,
``end_of_file`` in the middle) go through the chunked path.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from neurosym.errors import PrologError
from neurosym.prolog.knowledge_base import KnowledgeBase, _janus


@pytest.fixture(params=["chunked", "sequential"])
def chunk_bytes(request: pytest.FixtureRequest):
    size = 64 if request.param == "chunked" else 1 << 40
    janus = _janus()
    janus.query_once("neurosym_facts:set_chunk_bytes(B)", {"B": size})
    janus.query_once("neurosym_facts:set_reader_threads(T)", {"T": 3})  # on any machine
    yield request.param
    janus.query_once("neurosym_facts:set_chunk_bytes(8388608)")
    janus.query_once("neurosym_facts:set_reader_threads(auto)")


def _tricky(n: int) -> tuple[str, list[tuple[int, str]]]:
    """Facts with line breaks in quoted atoms and comments that look like facts."""
    lines, expected = [":- encoding(utf8).", ":- dynamic later/1."], []
    for i in range(n):
        if i % 7 == 0:
            text = f"line {i}.\nfake({i})."  # a cut here lands inside the atom
            lines.append(f"p({i}, '{text}').")
            expected.append((i, text))
        elif i % 11 == 0:
            lines.append(f"/* a comment\nfake({i}).\n*/ p({i}, c).")
            expected.append((i, "c"))
        else:
            lines.append(f"p({i}, 'ключ {i}').")
            expected.append((i, f"ключ {i}"))
        if i % 5 == 0:
            lines.append(f"q({i}).")
    return "\n".join(lines) + "\n", expected


def test_chunks_read_what_a_front_to_back_read_reads(tmp_path: Path, chunk_bytes: str) -> None:
    text, expected = _tricky(3000)
    path = tmp_path / "kb.pl"
    path.write_text(text)
    with KnowledgeBase(path) as kb:
        assert [(a["I"], a["X"]) for a in kb.query("p(I, X)")] == expected
        assert [a["I"] for a in kb.query("q(I)")] == list(range(0, 3000, 5))
        with pytest.raises(PrologError, match="Unknown procedure: fake/1"):
            kb.query("fake(X)")
        assert kb.query("later(X)") == []


def test_helpers_add_the_chunks_they_read(tmp_path: Path, chunk_bytes: str) -> None:
    path = tmp_path / "kb.pl"
    path.write_text(
        ":- encoding(utf8).\n" + "".join(f"p({i}, f(x, [{i}]))." + "\n" for i in range(3000))
    )
    with KnowledgeBase(path) as kb:
        assert kb.count("p(_, _)") == 3000
        assert [a["I"] for a in kb.query("p(I, _)")] == list(range(3000))
    taken = _janus().query_once("neurosym_facts:chunks_taken(N)")["N"]
    assert taken == (2 if chunk_bytes == "chunked" else 0)


def test_a_header_in_a_late_chunk_is_read_in_order(tmp_path: Path, chunk_bytes: str) -> None:
    lines = [f"p({i})." for i in range(3000)]
    lines[2500] = ":- dynamic q/1."
    path = tmp_path / "kb.pl"
    path.write_text("\n".join(lines) + "\n")
    with KnowledgeBase(path) as kb:
        assert [a["I"] for a in kb.query("p(I)")] == [i for i in range(3000) if i != 2500]
        assert kb.query("q(X)") == []
    taken = _janus().query_once("neurosym_facts:chunks_taken(N)")["N"]
    assert taken == (1 if chunk_bytes == "chunked" else 0)


def test_a_payload_in_a_late_chunk_is_found_at_its_line(tmp_path: Path, chunk_bytes: str) -> None:
    text, _ = _tricky(3000)
    marker = tmp_path / "RAN"
    before, after = text[:-200], text[-200:]
    cut = after.index("\np(") + 1  # the start of a fact near the end
    before, after = before + after[:cut], after[cut:]
    line = before.count("\n") + 1
    path = tmp_path / "kb.pl"
    path.write_text(f"{before}:- open('{marker}', write, S), close(S).\n{after}")
    good = tmp_path / "good.pl"
    good.write_text("p(-1, first).\n")
    with KnowledgeBase(good) as kb:
        with pytest.raises(PrologError, match=rf"^cannot load {path}:{line}: found a directive"):
            kb.load(path)
        assert kb.query("p(I, X)") == [{"I": -1, "X": "first"}]  # every chunk taken out again
        with pytest.raises(PrologError, match="Unknown procedure: q/1"):
            kb.query("q(X)")
    assert not marker.exists()


def test_a_syntax_error_in_a_late_chunk_names_its_line(tmp_path: Path, chunk_bytes: str) -> None:
    lines = [f"p({i})." for i in range(2000)]
    lines[1500] = "p(1500."
    path = tmp_path / "kb.pl"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(PrologError, match=rf"^cannot load {path}:1501:\d+: Syntax error"):
        KnowledgeBase(path)


def test_end_of_file_in_the_middle_ends_the_facts(tmp_path: Path, chunk_bytes: str) -> None:
    lines = [f"p({i})." for i in range(2000)]
    lines[1200] = "end_of_file."
    path = tmp_path / "kb.pl"
    path.write_text("\n".join(lines) + "\n")
    with KnowledgeBase(path) as kb:
        assert kb.count("p(_)") == 1200
