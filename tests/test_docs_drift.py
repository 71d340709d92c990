"""Docs that cannot drift: every `neurosym ...` command in README.md and docs/*.md parses with
the real parser (the cheap ones also run), and every relative link and image in README.md and
docs/*.md points at a file that exists."""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
COMMAND_DOCS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
LINK_DOCS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
FENCE = re.compile(r"^\s*(```|~~~)")
SPAN = re.compile(r"(?<!`)`(neurosym [^`]+)`(?!`)")
STOP = {"|", "||", "&&", ";", ">", ">>", "2>", "&", "<"}
"""shell tokens after which a command line is something else's (a pipe, a redirection)"""
CHEAP = {"envs", "agents"}
"""commands that run in a moment: their documented lines are run, not only parsed"""


def commands(path: Path) -> list[tuple[int, str, bool]]:
    """(line number, command text, whether in a code block) of every `neurosym ...` in code
    blocks and inline code."""
    out: list[tuple[int, str, bool]] = []
    in_code, pending, start = False, "", 0
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if FENCE.match(line):
            in_code, pending = not in_code, ""
            continue
        if in_code:
            text = pending + line.strip()
            if not pending:
                text = re.sub(r"^(\$|>>>|%)\s+", "", text)
                start = number
            if text.endswith("\\"):
                pending = text[:-1] + " "
                continue
            pending = ""
            if text.startswith("neurosym "):
                out.append((start, text, True))
        else:
            out += [(number, m.group(1), False) for m in SPAN.finditer(line)]
    return out


def argv_of(text: str) -> list[str]:
    """The arguments of a documented command line: shell comments, pipes and redirections cut
    off, optional parts written ``[--flag VALUE]`` left out (the line parses without them)."""
    lexer = shlex.shlex(text, posix=True, punctuation_chars="|&;<>")
    lexer.whitespace_split = True
    lexer.commenters = "#"
    words: list[str] = []
    optional = False
    for word in lexer:
        if word in STOP:
            break
        if optional or (word.startswith("[-") and not word.startswith("[--]")):
            optional = not word.endswith("]")
            continue
        words.append(word)
    return words[1:]  # without "neurosym"


def documented() -> list[tuple[str, int, str, bool]]:
    return [(p.name, *c) for p in COMMAND_DOCS if p.is_file() for c in commands(p)]


def test_the_docs_show_commands() -> None:
    assert len([d for d in documented() if d[3]]) >= 5, documented()


def _parser(argv: list[str]):  # noqa: ANN202 (an argparse parser)
    """The parser of the command (and plot's subcommand) that ``argv`` names, or None."""
    import argparse

    from neurosym.cli import COMMANDS, build_parser

    if not argv or argv[0] not in COMMANDS:
        return None
    parser = build_parser(argv)
    for depth in range(2):
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs or depth >= len(argv) or argv[depth] not in subs[0].choices:
            break
        parser = subs[0].choices[argv[depth]]
    return parser


@pytest.mark.parametrize(("doc", "line", "text", "block"), documented())
def test_a_documented_command_parses(doc: str, line: int, text: str, block: bool) -> None:
    """A command line in a code block parses whole; an inline mention (`neurosym probe`,
    `neurosym extract --top-keys N`) names a real command and real flags of it."""
    from neurosym.cli import build_parser

    argv = argv_of(text)
    where = f"{doc}:{line}: `{text}`"
    if argv and (argv[0].endswith(":") or argv[0].isupper() or argv[0] == "..."):
        return  # output the docs quote (`neurosym eval: error: ...`) or a placeholder (COMMAND)
    parser = _parser(argv)
    assert parser is not None, f"{where}: no such command"
    if block and "..." not in argv:
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            try:
                build_parser(argv).parse_args(argv)
            except SystemExit as exc:
                if exc.code not in (0, None):  # --help and --version exit 0
                    pytest.fail(f"{where} does not parse: {err.getvalue().strip()}")
        return
    for word in argv:
        if word.startswith("-") and not re.match(r"^-[0-9.]", word):
            flag = word.split("=", 1)[0]
            assert flag in parser._option_string_actions, f"{where}: no flag {flag}"


@pytest.mark.parametrize(
    ("doc", "line", "text", "block"),
    [d for d in documented() if d[3] and argv_of(d[2])[:1] and argv_of(d[2])[0] in CHEAP]
    + [d for d in documented() if d[3] and {"--help", "-h", "--version"} & set(argv_of(d[2]))],
)
def test_a_cheap_documented_command_runs(
    run_neurosym, doc: str, line: int, text: str, block: bool
) -> None:
    proc = run_neurosym(*argv_of(text), timeout=120)
    assert proc.returncode == 0, f"{doc}:{line}: `{text}` failed: {proc.stderr.strip()}"


LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
IMG = re.compile(r"<img\s[^>]*src=\"([^\"]+)\"")


def links(path: Path) -> list[tuple[int, str]]:
    """(line number, target) of every relative link and image outside code blocks."""
    out: list[tuple[int, str]] = []
    in_code = False
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if FENCE.match(line):
            in_code = not in_code
            continue
        if in_code:
            continue
        line = re.sub(r"`[^`]*`", "", line)  # code spans are not links
        for target in LINK.findall(line) + IMG.findall(line):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I) or target.startswith("#"):
                continue  # a URL or an anchor on the same page
            out.append((number, target))
    return out


def test_every_relative_link_and_image_exists() -> None:
    missing = []
    for doc in LINK_DOCS:
        for number, target in links(doc):
            path = target.split("#", 1)[0].split("?", 1)[0]
            if not (doc.parent / path).exists():
                missing.append(f"{doc.relative_to(REPO)}:{number}: {target}")
    assert not missing, "links to files that are not there:\n" + "\n".join(missing)


def test_the_link_check_finds_what_it_must(tmp_path: Path) -> None:
    """The parsers above on a page of their own: commands in blocks and spans, links, images."""
    page = tmp_path / "drift.md"
    text = (
        "Run `neurosym envs` or `neurosym eval --checkpoint x.pt [--sample]`.\n"
        "```\n$ neurosym extract --checkpoint a.pt \\\n    --episodes 3  # three\n"
        "neurosym query --kb kb.pl 'x(A)' | head\npython -m other\n```\n"
        "![a picture](docs/images/episode.png) [gone](docs/nowhere.md) [top](#top) "
        "[site](https://example.org) `[not](a-link.md)`\n"
    )
    page.write_text(text)
    found = commands(page)
    assert found == [
        (1, "neurosym envs", False),
        (1, "neurosym eval --checkpoint x.pt [--sample]", False),
        (3, "neurosym extract --checkpoint a.pt  --episodes 3  # three", True),
        (5, "neurosym query --kb kb.pl 'x(A)' | head", True),
    ]
    assert [argv_of(c) for _, c, _ in found] == [
        ["envs"],
        ["eval", "--checkpoint", "x.pt"],
        ["extract", "--checkpoint", "a.pt", "--episodes", "3"],
        ["query", "--kb", "kb.pl", "x(A)"],
    ]
    assert links(page) == [(8, "docs/images/episode.png"), (8, "docs/nowhere.md")]


def test_design_md_shows_every_package() -> None:
    """design.md's layout names every package of neurosym/ (a folder with __init__.py)."""
    text = (REPO / "docs" / "design.md").read_text()
    layout = text[text.index("## Layout") :]
    layout = layout[: layout.index("\n## ", 1)]
    packages = sorted(
        p.parent.relative_to(REPO / "neurosym").as_posix()
        for p in (REPO / "neurosym").glob("*/__init__.py")
    )
    missing = [name for name in packages if f"  {name}/" not in layout]
    assert packages and not missing, f"docs/design.md's layout lacks {missing}"
