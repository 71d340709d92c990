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

from neurosym.agent.checkpoint import chain_command, write_payload
from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.model import ActorCritic

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
        fresh = ActorCritic(ModelConfig.from_dict({**config, "query": "scene_mlp"})).state_dict()
        dtype = state["relational.query1.weight"].dtype
        state.update({k: v.to(dtype) for k, v in fresh.items() if k.startswith(PREFIX)})
        this = shlex.join(["python", "experiments/query_mlp.py", source, out])
        ck["command"] = chain_command(ck.get("command"), this)
    config["query"] = "scene_mlp"
    ck.pop("optimizer", None)
    write_payload(out, ck)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with_mlp_queries(sys.argv[1], sys.argv[2])
