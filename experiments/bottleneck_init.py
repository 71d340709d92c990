"""Start a fact-bottleneck PrediNet (ModelConfig.relation_bits) from a trained PrediNet's weights.

    python experiments/bottleneck_init.py checkpoints/rgw-random-predinet-cellkeys.pt \
        runs/bn-init.pt --tau 0.25 [--fresh]

Writes a checkpoint whose model is the source's with ``relation_bits=tau``: the encoder,
attention, W_S and the actor-critic MLP are the source's, PrediNet's read-out (``out``, whose
input is now the bits and the attended cells) starts afresh; ``--fresh`` starts every weight
afresh instead (the untrained control of the same shape). Train it with
``neurosym train --init-from OUT --algo imitate ...`` (experiments/bottleneck_train.sh).
"""

from __future__ import annotations

import argparse
import shlex
import sys
from dataclasses import replace

import torch

from neurosym.agent.checkpoint import chain_command, read_checkpoint, save_checkpoint
from neurosym.agent.networks.model import ActorCritic


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source")
    parser.add_argument("out")
    parser.add_argument(
        "--tau",
        type=float,
        default=None,
        help="threshold (default: the source's relation_bits, else 0.25)",
    )
    parser.add_argument("--fresh", action="store_true", help="every weight afresh (control)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--env-option", action="append", default=[], metavar="KEY=INT")
    args = parser.parse_args()
    source = read_checkpoint(args.source)
    if args.tau is None:
        args.tau = getattr(source["model_config"], "relation_bits", None) or 0.25
    config = replace(source["model_config"], relation_bits=args.tau)
    torch.manual_seed(args.seed)
    model = ActorCritic(config)
    state = model.state_dict()
    if not args.fresh:
        kept = {
            k: v for k, v in source["state_dict"].items() if not k.startswith("relational.out.")
        }
        state.update({k: v.float() for k, v in kept.items()})
        model.load_state_dict(state, strict=True)
    env_kwargs = dict(source["env_kwargs"])
    for item in args.env_option:
        key, value = item.split("=", 1)
        env_kwargs[key] = int(value)
    how = "fresh weights" if args.fresh else f"weights of {args.source} but relational.out"
    save_checkpoint(
        args.out,
        model=model,
        config=config,
        env_name=source["env"],
        env_kwargs=env_kwargs,
        train_config=None,
        command=chain_command(
            None if args.fresh else source.get("command"),
            shlex.join(["python", "experiments/bottleneck_init.py", *sys.argv[1:]]),
        ),
    )
    print(f"wrote {args.out}: relation_bits={config.relation_bits}, {how}")


if __name__ == "__main__":
    main()
