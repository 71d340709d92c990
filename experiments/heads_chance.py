"""Chance level of the heads tables: two uniformly random cells per state instead of a head's.

``neurosym extract`` reports per PrediNet head how often its two arguments are
two different objects (``two_objects``, the argmax cells themselves) and how
often they are on or beside two (``beside_objects``, terrain read as the
object on the 8 cells around it). The second reading is lenient on a
small map crowded with objects, so a figure needs its chance level: the same
two numbers when each state's two arguments are drawn uniformly from the grid
(an object's cell names that object, any other cell is terrain), over the same
states and object positions as a recording::

    neurosym extract --checkpoint checkpoints/rgw-random-predinet-cellkeys.pt --env rgw2 --episodes 20 --seed 0 --sample --out kb_out/rgw2-general
    python experiments/heads_chance.py kb_out/rgw2-general/recording

Prints one JSON line per recording: the mean over ``--draws`` random heads.
"""

from __future__ import annotations

import argparse
import json
from types import SimpleNamespace

import numpy as np
import pandas as pd

from neurosym.envs import make
from neurosym.record.heads import head_summary
from neurosym.record.recording import Recording


def random_attends(rec: Recording, draws: int, seed: int) -> pd.DataFrame:
    """An ``attends`` table with ``draws`` heads whose arguments are uniformly random cells."""
    env = make(rec.meta["env"], **rec.meta.get("env_kwargs", {}))
    _, height, width = env.observation_space.shape
    env.close()
    states = rec.attends[["episode", "t"]].drop_duplicates().reset_index(drop=True)
    rng = np.random.default_rng(seed)
    n = len(states) * draws
    table = pd.DataFrame(
        {
            "episode": np.tile(states["episode"].to_numpy(), draws * 2),
            "t": np.tile(states["t"].to_numpy(), draws * 2),
            "head": np.tile(np.repeat(np.arange(draws), len(states)), 2),
            "arg": np.repeat([1, 2], n),
            "row": rng.integers(0, height, 2 * n),
            "col": rng.integers(0, width, 2 * n),
            "weight": 1.0,
        }
    )
    named = rec.positions.sort_values("type", kind="stable").drop_duplicates(
        ["episode", "t", "row", "col"]
    )[["episode", "t", "row", "col", "type"]]
    table = table.merge(named, on=["episode", "t", "row", "col"], how="left")
    table["entity"] = table["type"].fillna("empty")
    return table.drop(columns="type")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "recordings",
        nargs="+",
        help="recording folders (neurosym extract --out DIR: DIR/recording)",
    )
    parser.add_argument("--draws", type=int, default=20, help="random heads per recording")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    for path in args.recordings:
        rec = Recording.load(path)
        fake = SimpleNamespace(
            attends=random_attends(rec, args.draws, args.seed), positions=rec.positions
        )
        heads = head_summary(fake)
        print(
            json.dumps(
                {
                    "recording": path,
                    "states": int(heads["states"].iloc[0]),
                    "two_objects": round(float(heads["two_objects"].mean()), 4),
                    "beside_objects": round(float(heads["beside_objects"].astype(float).mean()), 4),
                }
            )
        )


if __name__ == "__main__":
    main()
