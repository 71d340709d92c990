"""`neurosym setup-prolog`'s choices without a build: which SWI-Prolog it takes (an old one on
PATH is passed over for a build) and the venv's `swipl` link (one rename, never over a program).
tests/test_wheel.py runs the command in a fresh venv."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import pytest

from neurosym import setup_prolog
from neurosym.errors import NeurosymError


@pytest.fixture
def bare_prefix(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """sys.prefix of an empty venv, NEUROSYM_SWIPL unset, locate's cache cleared around the test."""
    prefix = tmp_path / "venv"
    (prefix / "bin").mkdir(parents=True)
    monkeypatch.setattr(sys, "prefix", str(prefix))
    monkeypatch.delenv("NEUROSYM_SWIPL", raising=False)
    setup_prolog.find_swipl.cache_clear()
    yield prefix
    monkeypatch.undo()
    setup_prolog.find_swipl.cache_clear()


def test_an_old_swipl_on_path_is_passed_over_for_a_build(
    bare_prefix: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys, fake_swipl
) -> None:
    old = fake_swipl(tmp_path / "usr" / "bin", 90004)
    monkeypatch.setenv("PATH", str(old.parent))
    new = bare_prefix / "swipl" / "bin" / "swipl"
    built: list[Path] = []

    def build(prefix: Path) -> Path:  # what setup_swipl.sh leaves, without the 70 s
        built.append(prefix)
        return fake_swipl(new.parent, 90209)

    monkeypatch.setattr(setup_prolog, "build_swipl", build)
    swipl, how = setup_prolog.choose_swipl(None, bare_prefix)
    assert (built, swipl.executable, swipl.version_text, how) == (
        [bare_prefix],
        new,
        "9.2.9",
        "built",
    )
    assert capsys.readouterr().out == (
        f"swipl on PATH ({old}) is version 9.0.4; neurosym needs SWI-Prolog >= 9.1.12: "
        f"building SWI-Prolog into {bare_prefix / 'swipl'}\n"
    )
    with pytest.raises(
        NeurosymError, match=r"^--swipl .*/usr/bin/swipl is SWI-Prolog 9\.0\.4; janus"
    ):
        setup_prolog.choose_swipl(str(old), bare_prefix)


def test_the_venv_link_points_at_the_prolog_and_is_replaced_whole(
    bare_prefix: Path, tmp_path: Path, fake_swipl
) -> None:
    built = fake_swipl(bare_prefix / "swipl" / "bin", 90209)
    link = setup_prolog.link_swipl(bare_prefix, built)
    assert (link, os.readlink(link)) == (bare_prefix / "bin" / "swipl", "../swipl/bin/swipl")
    assert setup_prolog.find_swipl().executable == link  # neurosym finds the venv's own first
    other = fake_swipl(tmp_path / "opt" / "bin", 90300)
    assert os.readlink(setup_prolog.link_swipl(bare_prefix, other)) == str(other)
    assert sorted(p.name for p in (bare_prefix / "bin").iterdir()) == ["swipl"]  # no temporary left
    link.unlink()
    link.write_text("#!/bin/sh\n")
    with pytest.raises(
        NeurosymError, match=r"^.*/bin/swipl is another program, not a link; remove"
    ):
        setup_prolog.link_swipl(bare_prefix, other)


def test_it_writes_into_a_virtual_environment_only(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "base_prefix", sys.prefix)  # the system's Python, as pip --user has
    monkeypatch.delenv("CONDA_PREFIX", raising=False)
    with pytest.raises(
        NeurosymError, match=r"is not a virtual environment's Python that may write"
    ):
        setup_prolog.run(argparse.Namespace(swipl=None))
