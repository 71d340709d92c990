"""Run every plunit test file under rules/ and neurosym/ through pytest, one swipl call per file.

The package's own Prolog modules (``neurosym/**/pl/<name>.pl``: the fact
reader, the janus bridge, Ctrl-C, the text induce copies into learned files,
the Prolog agent of ``neurosym play``) have their ``<name>.plt`` beside them,
loading ``<name>.pl`` relative to their own directory like the rule files';
their small hand-written fact files live in a ``tests/`` folder beside them
(``neurosym/**/pl/tests/*.pl``), which is neither a module nor shipped.

The convention for ``rules/<name>.plt``:

* it sits beside ``rules/<name>.pl`` and loads what it tests itself, relative
  to its own directory, so it runs from anywhere::

      :- prolog_load_context(directory, Dir),
         atom_concat(Dir, '/<name>.pl', Rules),
         atom_concat(Dir, '/tests/<name>_facts.pl', Facts),
         consult(Facts), consult(Rules).

* small hand-written fact files for it live in ``rules/tests/``;
* tests sit between ``:- begin_tests(Unit).`` and ``:- end_tests(Unit).``;
* it passes when ``swipl --on-error=status -g run_tests -t halt rules/<name>.plt``
  exits 0. ``--on-error=status`` makes a load error (a syntax error in the
  rules or the tests) fail the run instead of leaving fewer tests to run, and a
  file that defines no tests at all fails too.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
RULES = REPO / "rules"
PLT_FILES = sorted(RULES.glob("*.plt"))
PACKAGE_PLT_FILES = sorted((REPO / "neurosym").rglob("*.plt"))


def run_plunit(swipl: Path, plt: Path, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    """Run one .plt file's tests in a fresh swipl; its output is in stdout + stderr."""
    return subprocess.run(
        [str(swipl), "--on-error=status", "-g", "run_tests", "-t", "halt", str(plt)],
        capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL,
    )  # fmt: skip


def assert_plunit_passes(swipl: Path, plt: Path) -> None:
    proc = run_plunit(swipl, plt)
    output = proc.stdout + proc.stderr
    assert proc.returncode == 0, f"plunit failed for {plt} (exit {proc.returncode}):\n{output}"
    assert "No tests to run" not in output, f"{plt} defines no tests:\n{output}"


@pytest.mark.parametrize("plt", PLT_FILES, ids=[p.name for p in PLT_FILES])
def test_rule_files(swipl: Path, plt: Path) -> None:
    assert_plunit_passes(swipl, plt)


@pytest.mark.parametrize(
    "plt", PACKAGE_PLT_FILES, ids=[str(p.relative_to(REPO / "neurosym")) for p in PACKAGE_PLT_FILES]
)
def test_package_prolog_modules(swipl: Path, plt: Path) -> None:
    assert_plunit_passes(swipl, plt)


def package_prolog_modules() -> list[Path]:
    """The package's Prolog modules: every ``neurosym/**/*.pl`` but the test fixtures in ``tests/`` folders."""
    return sorted(
        p for p in (REPO / "neurosym").rglob("*.pl") if "tests" not in p.relative_to(REPO).parts
    )


def test_every_package_prolog_module_has_its_plunit_file() -> None:
    modules = package_prolog_modules()
    assert modules, "no Prolog module found under neurosym/"
    assert [p.with_suffix(".plt") for p in modules] == PACKAGE_PLT_FILES


def _pair(tmp_path: Path, test_body: str) -> Path:
    (tmp_path / "tests").mkdir(exist_ok=True)
    (tmp_path / "tests" / "demo_facts.pl").write_text("event(0, 3, picked(sword)).\n")
    (tmp_path / "demo.pl").write_text("picked(E, I) :- event(E, _, picked(I)).\n")
    plt = tmp_path / "demo.plt"
    plt.write_text(
        ":- prolog_load_context(directory, Dir),\n"
        "   atom_concat(Dir, '/demo.pl', Rules),\n"
        "   atom_concat(Dir, '/tests/demo_facts.pl', Facts),\n"
        "   consult(Facts), consult(Rules).\n"
        ":- begin_tests(demo).\n"
        f"{test_body}\n"
        ":- end_tests(demo).\n"
    )
    return plt


def test_runner_passes_a_passing_file(swipl: Path, tmp_path: Path) -> None:
    plt = _pair(tmp_path, "test(item, I == sword) :- picked(0, I).")
    assert_plunit_passes(swipl, plt)


@pytest.mark.parametrize(
    ("body", "shown"),
    [
        ("test(item, I == shield) :- picked(0, I).", "Expected: shield"),
        ("test(item) :- picked(0, .", "Syntax error"),
        ("", "defines no tests"),
    ],
    ids=["wrong-answer", "syntax-error", "no-tests"],
)
def test_runner_fails_and_shows_the_output(
    swipl: Path, tmp_path: Path, body: str, shown: str
) -> None:
    plt = _pair(tmp_path, body)
    with pytest.raises(AssertionError) as info:
        assert_plunit_passes(swipl, plt)
    assert shown in str(info.value)
