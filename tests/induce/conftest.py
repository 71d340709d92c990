"""Fixtures of the induce tests: small real KBs, and a hostile copy of one."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def write_world_kb() -> Callable[[Path, str, int], Path]:
    """``write_world_kb(path, env, seed)``: a KB of random-action episodes (builders.WORLD_CASES)."""
    from builders import write_world_kb

    return write_world_kb


@pytest.fixture(scope="module")
def world_kb(small_agent, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small real Relational-Grid-World KB of random-action episodes."""
    from neurosym.facts.tables import extract_facts
    from neurosym.record.recorder import record

    rec = record(
        small_agent("rgw-random"), "rgw-random", 8, seed=0, actions="random",
        env_kwargs={"max_steps": 60, "enemy": "pass"},
    )  # fmt: skip
    return extract_facts(rec).to_prolog(tmp_path_factory.mktemp("world") / "kb.pl")


def _hostile_world_kb(source: Path, path: Path, meta: str = "", wall: str = "") -> Path:
    """A copy of ``source`` with kb_meta(env, _) replaced by ``meta`` and the wall terrain renamed."""
    text = source.read_text()
    if meta:
        text = text.replace("kb_meta(env,'rgw-random').", meta)
    if wall:
        text = re.sub(r"^terrain\((\d+),wall,", lambda m: f"terrain({m[1]},{wall},", text, flags=re.M)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


@pytest.fixture(scope="session")
def hostile_world_kb() -> Callable[..., Path]:
    """``hostile_world_kb(source, path, meta="", wall="")``: a world KB edited by a hostile hand."""
    return _hostile_world_kb
