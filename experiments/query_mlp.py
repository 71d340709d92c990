"""A PrediNet checkpoint with MLP queries (``query="scene_mlp"``) that plays as its source.

    python experiments/query_mlp.py SOURCE.pt OUT.pt
    neurosym train --init-from OUT.pt --algo imitate ...    # then train on

PrediNet's scene queries are a linear read-out of the flattened entities (W_Q flat(L)). The
RGW fact bottleneck's head 0 misses the next object mostly where the route goes through a
teleport (it names the object past it), a choice between two route lengths that is not
linear in the scene. ``scene_mlp`` adds a one-layer MLP of flat(L) to the queries; this
script writes SOURCE's checkpoint with that query, the MLP's output layer zero (so the
network starts exactly where SOURCE was) and no optimizer state. A source that already holds
the MLP's weights (``relational.query_mlp.*``: a run of this study made before the option
was the library's, which recorded query "scene") keeps them.
"""

from __future__ import annotations

import shlex
import sys

import torch

from neurosym.agent.networks.predinet import PrediNet

PREFIX = "relational.query_mlp."


def with_mlp_queries(source: str, out: str) -> None:
    """Write ``source`` with query "scene_mlp" (its MLP's weights added when it has none)."""
    ck = torch.load(source, map_location="cpu", weights_only=False)
    config, state = ck["model_config"], ck["state_dict"]
    if config.get("keys", "entities") == "entities":
        sys.exit(f"{source}: MLP queries need cell keys (keys cells or cells_xy); it has entity keys")
    if config.get("query", "scene") not in ("scene", "scene_mlp"):
        sys.exit(f"{source}: its query is {config['query']!r}; MLP queries add to scene queries")
    if not any(name.startswith(PREFIX) for name in state):
        w_q = state["relational.query1.weight"]  # (H D, N F)
        n_entities = config["obs_shape"][1] * config["obs_shape"][2]
        fresh = PrediNet(
            n_entities, w_q.shape[1] // n_entities, config["heads"], config["key_size"],
            config["relations"], config["output_size"], query="scene_mlp", keys=config["keys"],
            cell_size=config["obs_shape"][0],
        )  # fmt: skip
        for name, value in fresh.query_mlp.state_dict().items():
            state[PREFIX + name] = value.to(w_q.dtype)
        this = " ".join(shlex.quote(a) for a in ["python", "experiments/query_mlp.py", source, out])
        ck["command"] = " && ".join(filter(None, [ck.get("command"), this]))  # history, then this
    config["query"] = "scene_mlp"
    ck.pop("optimizer", None)
    torch.save(ck, out)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with_mlp_queries(sys.argv[1], sys.argv[2])
