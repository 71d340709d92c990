"""experiments/query_mlp.py: a checkpoint given MLP queries plays as its source until trained."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import torch

from neurosym.agent.agent import load_agent

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("query_mlp", ROOT / "experiments" / "query_mlp.py")
query_mlp = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(query_mlp)

SOURCE = ROOT / "checkpoints" / "rgw-random-predinet-cellkeys.pt"  # cell keys, scene queries


def test_the_added_mlp_acts_as_its_source_until_trained(tmp_path: Path) -> None:
    out = tmp_path / "mlp.pt"
    query_mlp.with_mlp_queries(str(SOURCE), str(out))
    source, mlp = load_agent(SOURCE), load_agent(out)
    assert mlp.config.query == "scene_mlp" and source.config.query == "scene"
    assert not mlp.model.relational.query_mlp[2].weight.any()  # its output layer is zero
    obs = np.random.default_rng(0).integers(0, 2, (16, *source.config.obs_shape), dtype=np.uint8)
    with torch.no_grad():
        torch.testing.assert_close(mlp.model(torch.from_numpy(obs))[0], source.model(torch.from_numpy(obs))[0])
    # a file that holds the MLP's weights keeps them
    trained = torch.load(out, weights_only=False)
    trained["state_dict"]["relational.query_mlp.2.weight"].fill_(0.5)
    trained["model_config"]["query"] = "scene"  # as the study's first run recorded it
    torch.save(trained, tmp_path / "trained.pt")
    query_mlp.with_mlp_queries(str(tmp_path / "trained.pt"), str(tmp_path / "again.pt"))
    again = load_agent(tmp_path / "again.pt")
    assert again.config.query == "scene_mlp"
    assert (again.model.relational.query_mlp[2].weight == 0.5).all()


def test_entity_keys_are_refused(tmp_path: Path) -> None:
    with pytest.raises(SystemExit, match="need cell keys"):
        query_mlp.with_mlp_queries(str(ROOT / "checkpoints" / "rgw2-predinet.pt"), str(tmp_path / "x.pt"))
    assert not (tmp_path / "x.pt").exists()
