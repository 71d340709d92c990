"""The element-wise mean of several checkpoints' weights (one run's snapshots), as one checkpoint.

    python experiments/average_weights.py OUT.pt A.pt B.pt [C.pt ...]

Averaging the weights along one run's trajectory (Izmailov et al. 2018, SWA) often lands
nearer the middle of the region the run wanders in than any one snapshot. The checkpoints
must share their model config and weight names (snapshots of one run, or a run and its
continuation); OUT keeps the last one's metadata, no optimizer state, and its command
chain with this script's command added.
"""

from __future__ import annotations

import shlex
import sys

import torch

from neurosym.agent.checkpoint import chain_command, write_payload


def average_checkpoints(out: str, paths: list[str]) -> None:
    """Write the mean of ``paths``' state dicts to ``out``, with the last one's metadata."""
    cks = [torch.load(p, map_location="cpu", weights_only=False) for p in paths]
    last = cks[-1]
    for path, ck in zip(paths, cks, strict=True):
        if ck["model_config"] != last["model_config"]:
            sys.exit(f"{path}: its model config differs from {paths[-1]}'s; average one run's snapshots")
        if ck["state_dict"].keys() != last["state_dict"].keys():
            sys.exit(f"{path}: its weight names differ from {paths[-1]}'s")
    state = {}
    for name, value in last["state_dict"].items():
        if value.is_floating_point():
            mean = torch.stack([ck["state_dict"][name].float() for ck in cks]).mean(0)
            state[name] = mean.to(value.dtype)
        else:
            state[name] = value
    this = shlex.join(["python", "experiments/average_weights.py", out, *paths])
    last["command"] = chain_command(last.get("command"), this)
    last["state_dict"] = state
    last.pop("optimizer", None)
    write_payload(out, last)


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    average_checkpoints(sys.argv[1], sys.argv[2:])
