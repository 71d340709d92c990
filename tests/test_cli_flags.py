"""The commands' flags, generated from their options dataclasses (neurosym/flags.py): one
spelling and one meaning per flag in every command, renamed flags refused in one line."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from neurosym.cli import COMMANDS, build_parser, main
from neurosym.flags import SHARED, option_name, options_of

REPO = Path(__file__).resolve().parents[1]


def parsers() -> dict[str, argparse.ArgumentParser]:
    """Every command's parser and every subcommand's ('plot episode', 'induce world', ...)."""
    out: dict[str, argparse.ArgumentParser] = {}

    def visit(name: str, parser: argparse.ArgumentParser) -> None:
        out[name] = parser
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub, child in action.choices.items():
                    visit(f"{name} {sub}", child)

    for command in COMMANDS:
        top = build_parser([command])
        visit(command, next(a for a in top._actions if isinstance(a, argparse._SubParsersAction))
              .choices[command])  # fmt: skip
    return out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["query", "--kb", "kb.pl", "--format", "json", "true"],
         "neurosym query: error: --format is now --json or --csv (the table is the default)"),
        (["query", "--kb", "kb.pl", "--format=csv", "true"],
         "neurosym query: error: --format is now --json or --csv (the table is the default)"),
        (["plot", "predinet", "--checkpoint", "c.pt", "--episode-seed", "3", "--out", "x.png"],
         "neurosym plot predinet: error: --episode-seed is now --seed"),
        (["plot", "episode", "--recording", "r", "--frames", "6", "--out", "x.png"],
         "neurosym plot episode: error: --frames is now --panels (the states the strip shows; "
         "--frames is train's frame budget)"),
        (["plot", "probes", "--probes", "p", "--out", "x.png"],
         "neurosym plot probes: error: --probes is now --probe (as in neurosym report)"),
        (["induce", "--kb", "kb.pl", "--what", "world", "--out", "w.pl"],
         "neurosym induce: error: --what is now a subcommand: neurosym induce world ... or "
         "neurosym induce strategy ..."),
    ],
)  # fmt: skip
def test_a_renamed_flag_is_one_line_naming_the_new_spelling(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    with pytest.raises(SystemExit) as exited:
        main(argv)
    assert exited.value.code == 2  # as argparse refuses a flag it does not know
    assert capsys.readouterr() == ("", message + "\n")


def test_a_shared_flag_is_spelled_and_read_alike_in_every_command() -> None:
    """--env, --seed, --json, ...: the same type, metavar and action wherever a command has it."""
    seen: dict[str, dict[tuple, list[str]]] = {}
    for name, parser in parsers().items():
        for action in parser._actions:
            for flag in action.option_strings:
                if (name, flag) == ("train", "--seed"):
                    continue  # a setting of the run (neurosym/agent/config.py): its seed
                if flag in {option_name(f) for f in SHARED} | {"--sample"}:
                    metavar = None if flag == "--out" else action.metavar  # FILE or DIR
                    kind = (type(action).__name__, action.type, metavar, action.nargs)
                    seen.setdefault(flag, {}).setdefault(kind, []).append(name)
    assert {flag: len(kinds) for flag, kinds in seen.items()} == dict.fromkeys(seen, 1), seen
    assert "play" in seen["--map"][next(iter(seen["--map"]))]
    assert "query" in seen["--json"][next(iter(seen["--json"]))]
    every = {flag for p in parsers().values() for a in p._actions for flag in a.option_strings}
    assert not every & {"--episode-seed", "--what", "--probes"}
    having = {f: [n for n, p in parsers().items() if f in p._option_string_actions]
              for f in ("--format", "--frames")}  # fmt: skip
    assert having == {"--format": ["extract"], "--frames": ["train"]}  # one meaning each


def test_the_options_are_the_commands_dataclass_with_its_defaults() -> None:
    from neurosym.agent.cli_eval import EvalOptions
    from neurosym.meaning.cli_probe import ProbeOptions

    def parsed(argv: list[str]):  # noqa: ANN202 (the command's options object)
        return options_of(build_parser(argv).parse_args(argv))

    got = parsed(["eval", "--checkpoint", "c.pt", "--env-option", "a=1", "--env-option", "b=2"])
    assert got == EvalOptions(checkpoint="c.pt", env_option=["a=1", "b=2"])
    assert (got.episodes, got.seed, got.greedy, got.json) == (100, 0, True, False)
    probe = parsed(["probe", "--checkpoint", "c.pt", "--out", "o", "--no-untrained"])
    assert isinstance(probe, ProbeOptions)
    assert (probe.episodes, probe.greedy, probe.untrained) == (200, False, False)
    assert parsed(["probe", "--checkpoint", "c", "--out", "o", "--greedy"]).greedy is True
    world = parsed(["induce", "world", "--kb", "k.pl", "--out", "w.pl"])
    assert (type(world).__name__, world.what, world.holdout) == ("WorldOptions", "world", None)
    assert not hasattr(world, "features")  # a strategy flag is no field of world's options
    strategy = parsed(["induce", "strategy", "--kb", "k.pl", "--out", "s.pl", "--learner", "tree"])
    assert (strategy.what, strategy.learner, strategy.features) == ("strategy", "tree", None)
    episode = parsed(["plot", "episode", "--recording", "r", "--panels", "6", "--out", "x.png"])
    assert (episode.plot, episode.panels) == ("episode", 6)
    for plot in ("mhdpa", "predinet", "rvectors", "relations", "episode"):
        # what a recording fixes is unset unless given (plot refuses it with --recording)
        got = parsed(["plot", plot, "--recording", "r", "--out", "x.png"])
        assert (got.env, got.seed, getattr(got, "episodes", None)) == (None, None, None), plot


def test_query_json_and_csv_exclude_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        main(["query", "--kb", "kb.pl", "--json", "--csv", "true"])
    assert exited.value.code == 2
    assert "argument --csv: not allowed with argument --json" in capsys.readouterr().err


def test_play_plays_a_map_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """--map, as eval, extract and report take it: rgw2 (by default) on the user's map."""
    layout = tmp_path / "map.txt"
    layout.write_text((REPO / "neurosym" / "envs" / "maps" / "rgw1.txt").read_text())
    policy = str(REPO / "neurosym" / "play" / "strategies" / "rgw_handwritten.pl")
    code = main(["play", "--policy", policy, "--map", str(layout), "--episodes", "1", "--json"])
    report = json.loads(capsys.readouterr().out)
    assert code == 0 and (report["env"], report["env_kwargs"]) == ("rgw2", {"map": str(layout)})
    assert report["success_rate"] == 1.0
    code = main(["play", "--policy", policy, "--map", str(layout),
                 "--env-option", f"map={layout}", "--episodes", "1"])  # fmt: skip
    assert code == 1 and capsys.readouterr().err == (
        "neurosym play: error: give the map once: --map FILE or --env-option map=FILE, not both\n"
    )
    assert main(["play", "--policy", policy, "--env", "bw1", "--map", str(layout)]) == 1
    assert "--map goes with a fixed-map RGW env" in capsys.readouterr().err


def test_probe_and_intervene_take_a_map_file(tmp_path: Path) -> None:
    """agent_env, their env: --map puts the user's map on rgw2 under the agent's options."""
    from neurosym.agent.agent import load_agent
    from neurosym.cli import agent_env
    from neurosym.errors import ConfigError

    layout = tmp_path / "map.txt"
    layout.write_text((REPO / "neurosym" / "envs" / "maps" / "rgw1.txt").read_text())
    agent = load_agent(REPO / "checkpoints" / "rgw-random-predinet-cellkeys.pt")
    name, options = agent_env(agent, None, ["max_steps=7"], str(layout))
    assert name == "rgw2" and options["map"] == str(layout) and options["max_steps"] == 7
    with pytest.raises(ConfigError, match="give the map once"):
        agent_env(agent, "rgw1", [f"map={layout}"], str(layout))
