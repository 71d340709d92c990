"""`neurosym play` end to end: --json with eval's names, the lines for people, one-line errors."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RGW = "neurosym/play/strategies/rgw_handwritten.pl"


@pytest.fixture(autouse=True)
def _from_the_repository(monkeypatch: pytest.MonkeyPatch) -> None:
    """Relative paths (RGW, the error messages that name them) as from the repository root."""
    monkeypatch.chdir(ROOT)


def test_json(neurosym_main) -> None:
    proc = neurosym_main("play", "--policy", RGW, "--env", "rgw2", "--episodes", "2", "--json")
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    assert report["mean_return"] == pytest.approx(10.7)
    assert report["success_rate"] == 1.0 and report["optimal_rate"] == 1.0
    assert report["sword_first_guarded"] == 1.0 and report["no_detour_decoy"] is None
    assert report["outcomes"] == {"terminal": 2} and report["fallback_steps"] == 0
    assert report["steps_per_s"] > 0 and report["features"] == "world"


def test_text_and_env_option(neurosym_main) -> None:
    proc = neurosym_main(
        "play", "--policy", RGW, "--env", "rgw-random", "--episodes", "3", "--seed", "1000",
        "--env-option", "enemy=end",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert [line.split()[0] for line in lines[:5]] == [
        "policy", "episodes", "mean", "success", "optimal",
    ]  # fmt: skip
    assert [line.split()[0] for line in lines[-5:]] == [
        "mean", "outcomes", "fallbacks", "decided", "speed",
    ]  # fmt: skip
    assert lines[3] == "success      100.0 %"
    assert lines[-3] == "fallbacks    0 of " + lines[-3].split()[3] + " steps (0.0 %)"
    assert lines[-2] == "decided by   strategy 100.0 %"


def test_compare_prints_one_table_of_the_same_levels(neurosym_main, tmp_path: Path) -> None:
    """--compare trivial,handwritten under --fallback none: the shipped strategies play the
    same levels; the strategy under test answers in state 0 only, so both its episodes end
    there (no_goal); the trivial one goes straight for the terminal (rgw2's enemy blocks the
    way: no route)."""
    policy = tmp_path / "once.pl"
    policy.write_text("goal(_, 0, sword).\n")
    args = ["play", "--policy", policy, "--env", "rgw2", "--episodes", "2", "--fallback", "none"]
    proc = neurosym_main(*args, "--compare", "trivial,handwritten")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert "ended        2 of 4 steps (50.0 %): no_goal 2" in lines
    assert "decided by   strategy 50.0 %, none 50.0 %" in lines
    table = lines[lines.index("") + 1 :]
    assert [re.sub(r" +\d+$", "", line) for line in table] == [
        "strategy      success  optimal  return by goal/3 fallback   ended  steps/s",
        "once.pl         0.0 %    0.0 %    0.00    50.0 %    0.0 %  50.0 %",
        "trivial         0.0 %    0.0 %    0.00     0.0 %    0.0 % 100.0 %",
        "handwritten   100.0 %  100.0 %   10.70   100.0 %    0.0 %   0.0 %",
        "(same 2 levels from seed 0, fallback none; by goal/3, fallback, ended: shares of steps)",
    ]
    proc = neurosym_main(*args, "--compare", "trivial", "--json")
    report = json.loads(proc.stdout)
    trivial = report["compare"]["trivial"]
    assert trivial["policy"].endswith("neurosym/play/strategies/rgw_trivial.pl")
    assert trivial["outcomes"] == {"no_route": 2} and trivial["fallback"] == "none"
    assert report["outcomes"] == {"no_goal": 2}


def test_compare_names_a_shipped_strategy_or_a_file(neurosym_main) -> None:
    proc = neurosym_main("play", "--policy", RGW, "--env", "rgw2", "--compare", "trivial,,x")
    assert proc.returncode == 1
    assert proc.stderr == (
        "neurosym play: error: --compare 'trivial,,x': give strategies separated by commas, "
        "e.g. trivial,handwritten\n"
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--policy", "no/such.pl", "--env", "rgw2"], "no such policy file: no/such.pl"),
        (["--policy", "{nogoal}", "--env", "rgw2"], "defines no goal/3"),
        (
            ["--policy", "{relations}", "--env", "rgw2"],
            "give the agent they came from (--checkpoint)",
        ),
        (["--policy", RGW], "give the env to play (--env NAME"),
        (["--policy", RGW, "--env", "rgw2", "--episodes", "0"], "--episodes must be a positive"),
        (
            ["--policy", RGW, "--env", "rgw2", "--env-option", "colour=red"],
            "unknown option 'colour'",
        ),
    ],
)
def test_errors(neurosym_main, tmp_path: Path, args: list[str], message: str) -> None:
    (tmp_path / "nogoal.pl").write_text("foo(1).\n")
    (tmp_path / "relations.pl").write_text("%! features: relations\ngoal(_, _, terminal).\n")
    args = [
        a.format(nogoal=tmp_path / "nogoal.pl", relations=tmp_path / "relations.pl") for a in args
    ]
    proc = neurosym_main("play", *args)
    assert proc.returncode == 1, proc.stdout
    assert proc.stderr.startswith("neurosym play: error: ") and message in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_a_strategy_over_the_networks_relations(neurosym_main, tmp_path: Path) -> None:
    """features: both: holds/5 computed live from the checkpoint, thresholds from --kb."""
    policy = tmp_path / "both.pl"
    policy.write_text(
        "%! features: both\n"
        "goal(E, T, sword) :- holds(E, T, r(_), agent, sword), at(E, T, sword, _, _).\n"
        "goal(E, T, O) :- holds(E, T, r(_), _, _), default_goal(E, T, O).\n"
    )
    kb = tmp_path / "kb.pl"
    kb.write_text("".join(f"threshold({j}, 0.5).\n" for j in range(8)))
    args = ["play", "--policy", policy, "--checkpoint", "rgw-random-predinet-cellkeys"]
    proc = neurosym_main(*args, "--kb", kb, "--episodes", "2", "--seed", "3000000000", "--json")
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    assert report["env"] == "rgw-random" and report["env_kwargs"] == {"num_mountains": 12}
    assert report["features"] == "both" and report["success_rate"] == 1.0
    assert report["fallback_steps"] < report["steps"]  # holds/5 facts were there to read
    proc = neurosym_main(*args, "--episodes", "1")
    assert proc.returncode == 1
    assert "has no threshold/2 for holds/5: give the KB it was learned from (--kb)" in proc.stderr


@pytest.mark.subprocess
def test_ctrl_c_stops_a_strategy_blocked_in_a_foreign_call(tmp_path: Path) -> None:
    """A goal/3 asleep in sleep/1 (no inferences, no heartbeat), catching what stops its first
    sleep: SIGINT ends the run within seconds with the CLI's one line and status 130."""
    import os
    import signal
    import subprocess
    import sys
    import time

    policy = tmp_path / "asleep.pl"
    policy.write_text(
        "goal(_, _, terminal) :- format(user_error, 'asleep~n', []), flush_output(user_error), "
        "catch(sleep(1000), _, true), sleep(1000).\n"
    )
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)
    proc = subprocess.Popen(
        [sys.executable, "-m", "neurosym", "play", "--policy", str(policy), "--env", "rgw2",
         "--episodes", "1"],
        cwd=ROOT, env={**os.environ, "PYTHONPATH": path}, text=True,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        assert proc.stderr is not None
        assert proc.stderr.readline() == "asleep\n"  # goal/3 has begun its sleep
        time.sleep(2)
        proc.send_signal(signal.SIGINT)
        start = time.monotonic()
        stdout, stderr = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert time.monotonic() - start < 10
    assert (proc.returncode, stdout, stderr) == (130, "", "neurosym play: interrupted\n")
