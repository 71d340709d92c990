"""``neurosym induce`` on bad input: one line before any work, nothing lost, data shown as text."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
from strategy_kbs import nearest_key_kb

from neurosym.atomic import refuse_overwrite
from neurosym.cli import main
from neurosym.errors import ConfigError, OutputError
from neurosym.induce.strategy import induce_strategy
from neurosym.induce.strategy_data import load_trace
from neurosym.induce.world import induce_world
from neurosym.prolog.knowledge_base import KnowledgeBase


def induce(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    """Run ``neurosym induce ARGS`` in this process: (exit status, stdout, stderr)."""
    code = main(["induce", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def bw_kb(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return nearest_key_kb(tmp_path_factory.mktemp("bw") / "kb.pl", 12, seed=3)


def test_an_atom_is_written_as_an_atom_and_escapes_are_shown(
    hostile_world_kb,
    world_kb: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """'Wall' stays an atom (as a variable it predicted every state); ESC never reaches the terminal."""
    kb = hostile_world_kb(world_kb, tmp_path / "wall.pl", wall="'Wall'")
    out = tmp_path / "world.pl"
    code, stdout, _ = induce(capsys, "world", "--kb", kb, "--out", out)
    assert code == 0
    assert "  predicts(E, T, bumped(wall)) :- ahead(E, T, 'Wall')." in stdout.splitlines()
    assert states(kb, out) == states(kb) != set()
    osc = "'\\e]8;;http://x\\e\\\\wall\\e]8;;\\e\\\\'"  # a hyperlink: OSC 8 ... ST
    kb = hostile_world_kb(world_kb, tmp_path / "osc.pl", wall=osc)
    code, stdout, _ = induce(capsys, "world", "--kb", kb, "--out", out)
    assert code == 0 and "\x1b" not in stdout
    assert r"  predicts(E, T, bumped(wall)) :- ahead(E, T, '\x1b\]8;;http://x\x1b\\\wall\x1b\]8;;\x1b\\\')." in stdout.splitlines()
    assert states(kb, out) == states(kb) != set()  # world.pl loads, and means what it says


def states(kb: Path, rules: Path | None = None) -> set[tuple[int, int]]:
    """The states with a bumped(wall) event (or, with ``rules``, those its clauses predict it at)."""
    goal = "predicts(E, T, bumped(wall))" if rules else "event(E, T, bumped(wall))"
    with KnowledgeBase(kb, rules=[rules] if rules else []) as prolog:
        return {(r["E"], r["T"]) for r in prolog.query(goal)}


def test_values_read_from_the_kb_are_bounded_before_the_work(bw_kb: Path, tmp_path: Path) -> None:
    text = bw_kb.read_text()
    grid = tmp_path / "grid.pl"
    grid.write_text(text.replace("grid(0,7,7).", "grid(0,3000,3000)."))
    with pytest.raises(ConfigError, match=re.escape(
        f"grid(0, 3000, 3000) in {grid}: its at/5 and terrain/4 facts reach 7 rows and 7 columns, "
        "so a grid may have at most 16 rows and 16 columns (twice what the facts reach, plus 2)"
    )):  # fmt: skip
        induce_strategy(grid)
    heads = tmp_path / "heads.pl"
    heads.write_text(text.replace("kb_meta(heads,1).", "kb_meta(heads,20000000)."))
    with pytest.raises(ConfigError, match=re.escape(
        f"kb_meta(heads, 20000000) in {heads}: heads must be a whole number from 0 to 1 (the heads "
        "its attends/8, attention/6 and relation/7 facts name)"
    )):  # fmt: skip
        load_trace(heads)
    relations = tmp_path / "relations.pl"
    relations.write_text(text.replace("kb_meta(relations,1).", "kb_meta(relations,many)."))
    with pytest.raises(ConfigError, match=r"kb_meta\(relations, many\) .*: relations must be a whole number from 0 to 1"):
        load_trace(relations)
    untyped = tmp_path / "untyped.pl"
    untyped.write_text(text.replace("object(key_red,key(red)).\n", ""))
    with pytest.raises(ConfigError, match=re.escape(
        f"{untyped}: object key_red has at/5 facts but no object/2 fact naming its type; a KB "
        "written by neurosym extract has one per object"
    )):  # fmt: skip
        load_trace(untyped)


def test_a_held_out_kb_of_another_family_is_refused(
    bw_kb: Path, world_kb: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "s.pl"
    for what in ("strategy", "world"):
        code, _, err = induce(capsys, what, "--kb", bw_kb, "--holdout", world_kb, "--out", out)
        assert code == 1 and err == (
            f"neurosym induce: error: held-out KB {world_kb} is a rgw KB; the rules learned from "
            f"{bw_kb} are boxworld rules: give a held-out KB of the same env family\n"
        )
    assert not out.exists()


def test_an_output_that_is_an_input_is_refused(
    bw_kb: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    kb = tmp_path / "kb.pl"
    kb.write_bytes(bw_kb.read_bytes())
    before = kb.read_bytes()
    (tmp_path / "link.pl").symlink_to(kb)
    os.link(kb, tmp_path / "hard.pl")
    # an extract folder: out/kb.pl -> .neurosym/current/kb.pl -> run-1/kb.pl (neurosym.publish)
    run = tmp_path / "ext" / ".neurosym" / "run-1"
    run.mkdir(parents=True)
    (run / "kb.pl").write_bytes(before)
    (run.parent / "current").symlink_to("run-1")
    (tmp_path / "ext" / "kb.pl").symlink_to(".neurosym/current/kb.pl")
    cases = [
        (kb, kb, "is the input"),
        (kb, tmp_path / "link.pl", "is the input"),
        (tmp_path / "link.pl", tmp_path / "hard.pl", "is the input"),
        (tmp_path / "ext" / "kb.pl", tmp_path / "ext" / "kb.pl", "is the input"),
        (run / "kb.pl", tmp_path / "ext" / "kb.pl", "is the input"),
        (kb, tmp_path / "ext" / "kb.pl", "is a product of a published folder"),
        (kb, run / "world.pl", "lies inside a published folder's store"),
    ]
    for source, out, why in cases:
        for flags in (["--kb", source], ["--kb", bw_kb, "--holdout", source]):
            code, _, err = induce(capsys, "world", *flags, "--out", out)
            assert code == 1 and len(err.splitlines()) == 1, err
            assert err.startswith(f"neurosym induce: error: --out {out} {why}"), err
    assert kb.read_bytes() == before and (run / "kb.pl").read_bytes() == before
    assert os.readlink(tmp_path / "ext" / "kb.pl") == ".neurosym/current/kb.pl"
    assert not (run / "world.pl").exists()
    assert refuse_overwrite(tmp_path / "new.pl", [kb, None, tmp_path / "missing.pl"]) == tmp_path / "new.pl"
    with pytest.raises(OutputError, match="is the input"):
        refuse_overwrite(tmp_path / "hard.pl", [tmp_path / "link.pl"], flag="--to")


def test_a_file_name_that_is_not_utf8_is_one_line(
    bw_kb: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    name = os.fsdecode(bytes(tmp_path) + b"/kb\xff.pl")
    Path(name).write_bytes(bw_kb.read_bytes())
    for flags in (["--kb", name], ["--kb", bw_kb, "--holdout", name]):
        code, _, err = induce(capsys, "strategy", *flags, "--out", tmp_path / "s.pl")
        assert code == 1
        assert err == (
            f"neurosym induce: error: {flags[-2]} {tmp_path}/kb\\udcff.pl: the file name is not valid "
            "UTF-8, which SWI-Prolog cannot open; rename the file (or link it under a UTF-8 name)\n"
        )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["strategy", "--out", ""],
         "--out is empty: give the file to write the learned rules to (a .pl)"),
        (["world", "--out", ""],
         "--out is empty: give the file to write the learned rules to (a .pl)"),
        (["strategy", "--out", "{file}/x.pl"],
         "--out {file}/x.pl: {file} is not a folder, so the rules cannot be written there"),
    ],
)  # fmt: skip
def test_flags_are_used_or_refused_before_the_learning(
    bw_kb: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    file = tmp_path / "file"
    file.write_text("")
    args = [a.format(file=file) for a in args]
    if "--out" not in args:
        args += ["--out", str(tmp_path / "x.pl")]
    code, out, err = induce(capsys, args[0], "--kb", bw_kb, *args[1:])
    assert (code, out) == (1, "")  # nothing learned
    assert err == f"neurosym induce: error: {message.format(file=file)}\n"


@pytest.mark.parametrize("flag", ["--features=world", "--learner=tree", "--holdout-share=0.3"])
def test_a_strategy_flag_is_refused_by_induce_world(
    bw_kb: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], flag: str
) -> None:
    """Each subcommand has only its own flags: a strategy one given to world is one line, exit 2."""
    with pytest.raises(SystemExit) as exited:
        induce(capsys, "world", "--kb", bw_kb, flag, "--out", tmp_path / "x.pl")
    name = flag.split("=")[0]
    assert exited.value.code == 2 and capsys.readouterr().err == (
        f"neurosym induce world: error: {name} belongs to neurosym induce strategy; "
        "neurosym induce world does not read it\n"
    )
    assert not (tmp_path / "x.pl").exists()


def test_both_kinds_make_the_folders_of_out(
    bw_kb: Path, world_kb: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for what, kb in (("strategy", bw_kb), ("world", world_kb)):
        out = tmp_path / what / "missing" / "dir" / "x.pl"
        code, stdout, err = induce(capsys, what, "--kb", kb, "--out", out)
        assert code == 0, err
        assert stdout.splitlines()[-1] == f"wrote {out}" and out.is_file()
    rules = induce_world(world_kb)
    assert rules.write(tmp_path / "w" / "again.pl").is_file()
