"""``neurosym plot`` end to end: real checkpoints (random weights) and a real recording.

Each subcommand runs once as ``python -m neurosym`` in a subprocess and once
in-process; the two files must be byte-identical and of the documented size.
"""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import torch
from PIL import Image

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import save_checkpoint
from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.model import ActorCritic
from neurosym.cli import main
from neurosym.envs import env_family, make
from neurosym.record.recorder import record

ROOT = Path(__file__).resolve().parents[2]
DPI = "40"
MAX_STEPS = 30


def _checkpoint(path: Path, module: str, env: str = "rgw2") -> Path:
    """Random weights; episodes capped at 30 steps (env option stored in the checkpoint)."""
    torch.manual_seed(0)
    obs, _ = make(env).reset(seed=0)
    config = ModelConfig.for_family(env_family(env), module, tuple(obs.shape))
    model = ActorCritic(config)
    return save_checkpoint(
        path, model=model, config=config, env_name=env, env_kwargs={"max_steps": MAX_STEPS}
    )


@pytest.fixture(autouse=True)
def one_torch_thread() -> Iterator[None]:
    """Batch-1 acting on a shared 2-core machine is many times faster on one thread."""
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    tmp = tmp_path_factory.mktemp("plot")
    out = {m: _checkpoint(tmp / f"rgw2-{m}.pt", m) for m in ("predinet", "mhdpa")}
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        rec = record(load_agent(out["predinet"]), "rgw2", episodes=2, seed=3)
    finally:
        torch.set_num_threads(before)
    out["recording"] = rec.save(tmp / "rec")
    out["tmp"] = tmp
    return out


def _subprocess(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONHASHSEED": "0", "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "neurosym", "plot", *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
    )


def _size(data: bytes) -> tuple[int, int, int]:
    with Image.open(io.BytesIO(data)) as im:
        return im.width, im.height, getattr(im, "n_frames", 1)


CASES = [
    # (name, source, args, expected (width, height, frames) at 40 dpi)
    ("mhdpa.png", "mhdpa", ["mhdpa", "--step", "2", "--object", "agent"], (424, 232, 1)),
    ("predinet.png", "recording", ["predinet", "--episode", "1", "--step", "3"], (424, 232, 1)),
    ("rvectors.png", "predinet", ["rvectors", "--max-steps", "6"], (320, 296, 1)),
    ("relations.png", "recording", ["relations", "--threshold", "z:1"], (432, 216, 1)),
    ("episode.png", "recording", ["episode", "--panels", "4", "--head", "1"], (332, 132, 1)),
    ("episode.gif", "mhdpa", ["episode", "--max-steps", "5", "--fps", "8"], (320, 368, 6)),
]


@pytest.mark.parametrize(("name", "source", "args", "size"), CASES, ids=[c[0] for c in CASES])
def test_each_plot_is_reproducible_and_of_the_documented_size(
    files: dict[str, Path],
    name: str,
    source: str,
    args: list[str],
    size: tuple[int, int, int],
    capsys,
) -> None:
    flag = (
        ["--recording", str(files["recording"])]
        if source == "recording"
        else ["--checkpoint", str(files[source])]
    )
    first, second = files["tmp"] / f"a-{name}", files["tmp"] / f"b-{name}"
    done = _subprocess(*args, *flag, "--dpi", DPI, "--out", str(first))
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"wrote {first} (")
    assert main(["plot", *args, *flag, "--dpi", DPI, "--out", str(second)]) == 0
    data = first.read_bytes()
    assert data == second.read_bytes()
    assert _size(data) == size


def test_svg_is_reproducible_with_the_figure_size_in_points(files: dict[str, Path]) -> None:
    outs = [files["tmp"] / f"{k}.svg" for k in "ab"]
    for out in outs:
        assert (
            main(
                [
                    "plot",
                    "predinet",
                    "--checkpoint",
                    str(files["predinet"]),
                    "--head",
                    "0",
                    "--out",
                    str(out),
                ]
            )
            == 0
        )
    text = outs[0].read_text()
    assert outs[0].read_bytes() == outs[1].read_bytes()
    # (2.4 + 1.0) x (2 * 2.4 + 1.0) inches, or wider for the title and the D line of one head
    size = re.search(r'<svg [^>]*width="([0-9.]+)pt" height="([0-9.]+)pt"', text)
    assert size is not None and float(size[1]) >= 244.8 and size[2] == "417.6"


def test_a_bad_request_is_one_line_and_exit_status_1(files: dict[str, Path], neurosym_main) -> None:
    done = neurosym_main(
        "plot",
        "mhdpa",
        "--checkpoint",
        str(files["predinet"]),
        "--out",
        str(files["tmp"] / "x.png"),
    )
    assert done.returncode == 1
    assert done.stderr == (
        "neurosym plot: error: an MHDPA attention plot needs an MHDPA agent, "
        "but rgw2-predinet.pt is a PrediNet agent\n"
    )
    assert not (files["tmp"] / "x.png").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["predinet", "--checkpoint", "{mhdpa}"],
            "a PrediNet attention plot needs a PrediNet agent, but rgw2-mhdpa.pt",
        ),
        (
            ["predinet", "--checkpoint", "{predinet}", "--head", "4"],
            "--head 4 is out of range: this agent has heads 0..3",
        ),
        (
            ["mhdpa", "--checkpoint", "{mhdpa}", "--step", "500"],
            r"--step 500 is out of range: episode 0 has steps 0\.\.\d+$",
        ),
        (
            ["predinet", "--recording", "{recording}", "--episode", "5"],
            "--episode 5 is not in the recording: it has episodes 0, 1",
        ),
        (
            ["predinet", "--recording", "{recording}", "--seed", "2"],
            "--seed goes with --checkpoint",
        ),
        (
            ["rvectors", "--recording", "{recording}", "--max-steps", "3"],
            "--max-steps goes with --checkpoint",
        ),
        (
            ["relations", "--recording", "{recording}", "--episodes", "5"],
            "--episodes goes with --checkpoint",
        ),
        (
            ["predinet", "--checkpoint", "{predinet}", "--episode", "1"],
            "--episode goes with --recording",
        ),
        (
            ["rvectors", "--checkpoint", "{predinet}", "--env", "bw1"],
            "bw1 is a boxworld environment: pick one of rgw1, rgw2, rgw-random",
        ),
        (
            ["relations", "--recording", "{recording}", "--threshold", "quantile:2"],
            "threshold quantile:2.0 is outside [0, 1]",
        ),
        (
            ["episode", "--recording", "{recording}", "--steps", "7:3"],
            "--steps '7:3': expected 0 <= START <= STOP",
        ),
        (
            ["predinet", "--checkpoint", "{predinet}", "--dpi", "nan"],
            "--dpi must be a number from 1 to 1200, got nan",
        ),
        (
            ["predinet", "--checkpoint", "{predinet}", "--dpi", "1e6"],
            "--dpi must be a number from 1 to 1200",
        ),
        (
            ["predinet", "--checkpoint", "{predinet}", "--step", "-1"],
            "--step must be 0 or more, got -1",
        ),
        (["mhdpa", "--checkpoint", "{nowhere}"], "checkpoint not found"),
        (["predinet", "--recording", "{tmp}"], "is not a neurosym recording"),
        (["predinet", "--checkpoint", "{predinet}", "--out-as", "gif"], None),
    ],
)
def test_bad_requests_name_what_was_wrong(
    files: dict[str, Path], args: list[str], message: str | None, capsys
) -> None:
    paths = {k: str(v) for k, v in files.items()} | {"nowhere": str(files["tmp"] / "none.pt")}
    argv = ["plot", *(a.format(**paths) for a in args), "--out", str(files["tmp"] / "bad.png")]
    if message is None:  # argparse's own usage error
        with pytest.raises(SystemExit) as info:
            main(argv)
        assert info.value.code == 2
        return
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith("neurosym plot: error: ") and err.count("\n") == 1
    assert re.search(message if message.endswith("$") else re.escape(message), err.strip())


def test_gif_only_for_episodes(files: dict[str, Path], capsys) -> None:
    assert (
        main(
            [
                "plot",
                "predinet",
                "--checkpoint",
                str(files["predinet"]),
                "--out",
                str(files["tmp"] / "p.gif"),
            ]
        )
        == 1
    )
    assert "the file name must end in .png or .svg" in capsys.readouterr().err


@pytest.mark.parametrize("module", ["predinet", "mhdpa"])
def test_a_recording_and_a_live_run_of_the_same_seed_draw_the_same_episode(
    files: dict[str, Path], module: str
) -> None:
    """The grid rebuilt from the recording's positions equals the env's own entity grid, state by state."""
    import numpy as np

    from neurosym.viz.live import trace_from_agent
    from neurosym.viz.recorded import trace_from_recording

    agent = load_agent(files[module])
    recorded = trace_from_recording(record(agent, "rgw2", episodes=2, seed=4), 1)
    live = trace_from_agent(agent, seed=5)
    assert (recorded.grids == live.grids).all()
    assert recorded.actions == live.actions and recorded.outcome == live.outcome
    if module == "predinet":
        assert (np.nanargmax(recorded.attention1, axis=2) == live.attention1.argmax(axis=2)).all()
        assert (np.nanargmax(recorded.attention2, axis=2) == live.attention2.argmax(axis=2)).all()
        np.testing.assert_allclose(recorded.r_vectors, live.r_vectors, atol=1e-6)
    else:
        assert (recorded.mhdpa_focus == live.mhdpa_focus).all()


def test_the_default_threshold_is_extracts() -> None:
    import argparse

    from neurosym.facts.tables import DEFAULT_THRESHOLD
    from neurosym.viz.cli_plot import configure

    parser = argparse.ArgumentParser()
    configure(parser)
    args = parser.parse_args(["relations", "--recording", "r", "--out", "x.png"])
    assert args.threshold == DEFAULT_THRESHOLD


@pytest.mark.parametrize("fps", [float("nan"), float("inf"), 0.0])
def test_a_gif_needs_a_finite_positive_frame_rate(fps: float) -> None:
    import numpy as np

    from neurosym.errors import ConfigError
    from neurosym.viz.output import gif_bytes

    with pytest.raises(ConfigError, match="--fps must be a positive number"):
        gif_bytes([np.zeros((4, 4, 3), dtype=np.uint8)], fps)
