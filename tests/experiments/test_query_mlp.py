"""experiments/query_mlp.py: the MLP added to the queries starts where its source was.

Run in subprocesses: the script changes PrediNet for the whole process it runs in.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
import torch

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "checkpoints" / "rgw-random-predinet-bottleneck.pt"


@pytest.mark.subprocess
def test_the_added_mlp_plays_as_its_source_until_trained(tmp_path: Path) -> None:
    init = tmp_path / "init.pt"
    script = str(ROOT / "experiments" / "query_mlp.py")
    subprocess.run([sys.executable, script, "init", str(SOURCE), str(init)], check=True, cwd=ROOT)
    state = torch.load(init, map_location="cpu", weights_only=False)["state_dict"]
    assert not state["relational.query_mlp.2.weight"].any()  # the last layer is zero
    assert state["relational.query_mlp.0.weight"].shape == (256, 2600)

    def returns(*command: str, checkpoint: Path) -> list[float]:
        out = subprocess.run(
            [sys.executable, *command, "eval", "--checkpoint", str(checkpoint), "--episodes", "3",
             "--seed", "5", "--json"],
            capture_output=True, text=True, cwd=ROOT, check=True,
        )  # fmt: skip
        return json.loads(out.stdout)["mean_return"]

    assert returns(script, checkpoint=init) == returns("-m", "neurosym", checkpoint=SOURCE)
    # the library alone refuses the file (its weights do not fit a PrediNet)
    plain = subprocess.run(
        [sys.executable, "-m", "neurosym", "eval", "--checkpoint", str(init), "--episodes", "1"],
        capture_output=True, text=True, cwd=ROOT, check=False,
    )  # fmt: skip
    assert plain.returncode != 0 and "query_mlp" in plain.stderr
