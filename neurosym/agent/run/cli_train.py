"""``neurosym train``: train a PrediNet or MHDPA agent with A3C (or PPO).

A thin wrapper over :func:`neurosym.agent.run.trainer.train`. Unset options take
the preset's defaults for the env family (``neurosym.agent.config``;
``--preset thesis`` is Table 4 exactly); with ``--resume`` they take the
checkpoint's settings. The command line is stored in the checkpoint.
Under ``torchrun`` (``--algo ppo``) every rank runs this command and rank 0
writes (:mod:`neurosym.agent.learners.distributed`).
"""

from __future__ import annotations

import argparse
import os
import shlex
from typing import Any

from neurosym.cli import parse_env_options

# (flag, dest, kind) for the settings passed through as overrides; kind: train | model
_OVERRIDES = (
    ("--workers", "workers", "train"),
    ("--envs", "envs", "train"),
    ("--seed", "seed", "train"),
    ("--lr", "lr", "train"),
    ("--entropy", "entropy", "train"),
    ("--gamma", "gamma", "train"),
    ("--n-steps", "n_steps", "train"),
    ("--grad-clip", "grad_clip", "train"),
    ("--value-coef", "value_coef", "train"),
    ("--rms-eps", "rms_eps", "train"),
    ("--explore", "explore", "train"),
    ("--sil", "sil", "train"),
    ("--sil-episodes", "sil_episodes", "train"),
    ("--optimizer", "optimizer", "train"),
    ("--adam-eps", "adam_eps", "train"),
    ("--reward-scale", "reward_scale", "train"),
    ("--gae-lambda", "gae_lambda", "train"),
    ("--normalize-advantages", "normalize_advantages", "train"),
    ("--ppo-epochs", "ppo_epochs", "train"),
    ("--ppo-minibatches", "ppo_minibatches", "train"),
    ("--clip-range", "clip_range", "train"),
    ("--ppo-advantages", "ppo_advantages", "train"),
    ("--critic-warmup", "critic_warmup", "train"),
    ("--planner-coef", "planner_coef", "train"),
    ("--dagger-beta-frames", "dagger_beta_frames", "train"),
    ("--dagger-steps", "dagger_steps", "train"),
    ("--augment", "augment", "train"),
    ("--safe-coef", "safe_coef", "train"),
    ("--attention-gain", "attention_gain", "model"),
    ("--entity-norm", "entity_norm", "model"),
    ("--init", "init", "model"),
    ("--query", "query", "model"),
    ("--keys", "keys", "model"),
    ("--heads", "heads", "model"),
    ("--key-size", "key_size", "model"),
    ("--relations", "relations", "model"),
    ("--value-size", "value_size", "model"),
    ("--conv-channels", "conv_channels", "model"),
    ("--kernel-size", "kernel_size", "model"),
    ("--local-view", "local_view", "model"),
)


def _channels(text: str) -> tuple[int, ...]:
    """'16,16,24' -> (16, 16, 24): the encoder's conv layers, one positive width each."""
    try:
        widths = tuple(int(part) for part in text.split(","))
    except ValueError:
        widths = ()
    if not widths or min(widths) < 1:
        raise argparse.ArgumentTypeError(
            f"want comma-separated positive channel counts such as 12,24, got {text!r}"
        )
    return widths


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--env", help="environment short name or id, e.g. rgw2 (required unless --resume)"
    )
    parser.add_argument(
        "--module",
        choices=("predinet", "mhdpa"),
        help="relational module (required unless --resume or --init-from)",
    )
    parser.add_argument(
        "--out", required=True, help="run directory: checkpoint.pt and metrics.csv go here"
    )
    parser.add_argument(
        "--resume", action="store_true", help="continue the run in --out from its checkpoint"
    )
    parser.add_argument(
        "--init-from",
        metavar="CHECKPOINT",
        help="start a new run from this checkpoint's weights and model (a curriculum: e.g. a bw1 "
        "agent on bw2); any env of its family with its observation shape; frames count afresh",
    )
    parser.add_argument(
        "--algo",
        choices=("a3c", "ppo", "imitate"),
        help="learner: a3c (asynchronous workers, default), ppo (one synchronous learner) or "
        "imitate (DAgger from the env's optimal planner; RGW only)",
    )
    parser.add_argument(
        "--preset",
        choices=("default", "thesis"),
        default="default",
        help="settings to start from: default (what learns best here) or thesis (Table 4 exactly)",
    )
    parser.add_argument(
        "--tensorboard",
        action="store_true",
        help="also write TensorBoard event files to OUT/tensorboard",
    )
    parser.add_argument(
        "--device",
        choices=("cpu", "cuda", "auto"),
        default="cpu",
        help="where the PPO learner acts and learns: cpu (default), cuda (falls back to the CPU "
        "with a warning when no GPU is visible) or auto (cuda when one is visible); A3C is CPU-only",
    )
    stop = parser.add_argument_group("stopping (any that is reached; none: run until Ctrl-C)")
    stop.add_argument(
        "--frames", type=int, help="total training frames (env steps), counting resumed ones"
    )
    stop.add_argument("--minutes", type=float, help="wall-clock minutes for this session")
    stop.add_argument(
        "--target-return", type=float, help="stop when the greedy policy's mean return reaches this"
    )
    stop.add_argument(
        "--target-success",
        type=float,
        help="stop when the success rate over the last --window training episodes reaches this (0-1)",
    )
    a3c = parser.add_argument_group(
        "learner (defaults: the preset's for the env family, see neurosym/agent/config.py)"
    )
    a3c.add_argument("--workers", type=int, help="worker processes W (default: CPU cores)")
    a3c.add_argument("--envs", type=int, help="environments per worker K (1 = classic A3C)")
    a3c.add_argument("--seed", type=int, help="base seed (default 0)")
    a3c.add_argument("--lr", type=float, help="learning rate")
    a3c.add_argument("--optimizer", choices=("adam", "rmsprop"), help="shared optimiser")
    a3c.add_argument("--adam-eps", type=float, help="Adam epsilon")
    a3c.add_argument("--reward-scale", type=float, help="factor on rewards in the training signal")
    a3c.add_argument("--gae-lambda", type=float, help="GAE lambda (1: n-step returns)")
    a3c.add_argument(
        "--normalize-advantages",
        action=argparse.BooleanOptionalAction,
        help="normalise each update's advantages",
    )
    a3c.add_argument("--ppo-epochs", type=int, help="PPO passes over each rollout")
    a3c.add_argument("--ppo-minibatches", type=int, help="PPO minibatches per pass")
    a3c.add_argument("--clip-range", type=float, help="PPO probability-ratio clip")
    a3c.add_argument(
        "--ppo-advantages",
        choices=("minibatch", "running"),
        help="PPO's advantage normalisation: per minibatch, or a running RMS over rollouts",
    )
    a3c.add_argument(
        "--dagger-beta-frames",
        type=int,
        help="imitate: frames over which following the planner falls from always to never",
    )
    a3c.add_argument("--dagger-steps", type=int, help="imitate: gradient steps per rollout")
    a3c.add_argument(
        "--augment",
        action=argparse.BooleanOptionalAction,
        help="imitate: fit each minibatch turned or mirrored at random (RGW's symmetries)",
    )
    a3c.add_argument(
        "--safe-coef",
        type=float,
        metavar="C",
        help="imitate: weight of the loss on actions that give return up (the planner's "
        "regret > 0) beside the fastest actions' loss (0: none)",
    )
    a3c.add_argument(
        "--critic-warmup",
        type=int,
        metavar="FRAMES",
        help="A3C: first frames of the run in which only the value head learns (0: none)",
    )
    a3c.add_argument(
        "--planner-coef",
        type=float,
        metavar="C",
        help="A3C on RGW: weight of the planner's imitation loss beside A3C's (0: none)",
    )
    a3c.add_argument("--entropy", type=float, help="entropy bonus weight")
    a3c.add_argument("--gamma", type=float, help="discount")
    a3c.add_argument("--n-steps", type=int, help="rollout length per update (Table 4: 40)")
    a3c.add_argument("--grad-clip", type=float, help="gradient norm clip")
    a3c.add_argument("--value-coef", type=float, help="value loss weight")
    a3c.add_argument("--rms-eps", type=float, help="RMSprop epsilon")
    a3c.add_argument("--explore", type=float, help="count-based exploration bonus beta (0: none)")
    a3c.add_argument("--sil", type=float, help="self-imitation loss weight (0: none)")
    a3c.add_argument(
        "--sil-episodes", type=int, help="best episodes each worker keeps for self-imitation"
    )
    model = parser.add_argument_group("model (defaults: Table 4)")
    model.add_argument("--heads", type=int, help="attention heads (4)")
    model.add_argument("--key-size", type=int, help="query/key size (32 RGW, 64 Box-World)")
    model.add_argument("--relations", type=int, help="PrediNet relations per head (8)")
    model.add_argument("--value-size", type=int, help="MHDPA value size (64)")
    model.add_argument(
        "--conv-channels",
        type=_channels,
        metavar="C1,C2,...",
        help="encoder conv layers' output channels (Table 4: 12,24)",
    )
    model.add_argument(
        "--kernel-size", type=int, help="encoder conv kernel, stride 1, grid shape kept (2)"
    )
    model.add_argument(
        "--local-view",
        type=int,
        metavar="K",
        help="the MLP also sees the K x K cells around the agent, K odd (0: off, Table 4)",
    )
    model.add_argument(
        "--attention-gain", type=float, help="factor on the attention logits (default 8; thesis 1)"
    )
    model.add_argument(
        "--entity-norm",
        action=argparse.BooleanOptionalAction,
        help="LayerNorm on the entities (default on; thesis off)",
    )
    model.add_argument(
        "--query",
        choices=("scene", "learned"),
        help="PrediNet's queries: from the whole scene (scene, DESIGN and the thesis; default) "
        "or learned vectors, the same for every scene (learned)",
    )
    model.add_argument(
        "--keys",
        choices=("entities", "cells"),
        help="what PrediNet's attention compares its queries with: the encoder's entities "
        "(default, DESIGN and the thesis) or each cell's own observation (cells: a head "
        "addresses cells by what they hold); --init-from may switch to cells",
    )
    model.add_argument(
        "--init",
        choices=("orthogonal", "torch"),
        help="weight init of the MLP and heads (default orthogonal; thesis torch)",
    )
    watch = parser.add_argument_group("watching")
    watch.add_argument(
        "--env-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="keyword argument for the env, e.g. obs_mode=grey (repeatable)",
    )
    watch.add_argument(
        "--eval-interval", type=float, default=2.0, help="seconds between greedy evaluations (2)"
    )
    watch.add_argument(
        "--eval-episodes", type=int, default=8, help="episodes per greedy evaluation (8)"
    )
    watch.add_argument(
        "--checkpoint-interval", type=float, default=60.0, help="seconds between checkpoints (60)"
    )
    watch.add_argument(
        "--snapshot-every",
        type=float,
        metavar="MINUTES",
        help="also keep a copy of the checkpoint every MINUTES in OUT/snapshots/frames-N.pt "
        "(for curves on held-out levels: bench/curve.py)",
    )
    watch.add_argument(
        "--window",
        type=int,
        default=100,
        help="recent episodes behind mean return and success (100)",
    )
    watch.add_argument(
        "--slim",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="leave the optimizer state out of checkpoints (with --resume: as the run was)",
    )
    watch.add_argument("--quiet", action="store_true", help="no progress bar")


def command_line(args: argparse.Namespace) -> str:
    """The command as a user would type it, from the parsed options that were given."""
    parts = ["neurosym", "train"]
    for flag, dest in (("--env", "env"), ("--module", "module"), ("--out", "out")):
        if getattr(args, dest) is not None:
            parts += [flag, str(getattr(args, dest))]
    if args.resume:
        parts.append("--resume")
    if args.init_from is not None:
        parts += ["--init-from", args.init_from]
    if args.algo is not None:
        parts += ["--algo", args.algo]
    if args.preset != "default":
        parts += ["--preset", args.preset]
    for flag, dest in (
        ("--frames", "frames"),
        ("--minutes", "minutes"),
        ("--target-return", "target_return"),
        ("--target-success", "target_success"),
    ):
        if getattr(args, dest) is not None:
            parts += [flag, str(getattr(args, dest))]
    for flag, dest, _ in _OVERRIDES:
        value = getattr(args, dest)
        if isinstance(value, bool):
            parts.append(flag if value else "--no-" + flag[2:])
        elif isinstance(value, tuple):
            parts += [flag, ",".join(map(str, value))]
        elif value is not None:
            parts += [flag, str(value)]
    for item in args.env_option:
        parts += ["--env-option", item]
    for flag, dest, default in (
        ("--eval-interval", "eval_interval", 2.0),
        ("--eval-episodes", "eval_episodes", 8),
        ("--checkpoint-interval", "checkpoint_interval", 60.0),
        ("--snapshot-every", "snapshot_every", None),
        ("--window", "window", 100),
    ):
        if getattr(args, dest) != default:
            parts += [flag, str(getattr(args, dest))]
    if args.slim is not None:
        parts.append("--slim" if args.slim else "--no-slim")
    if args.tensorboard:
        parts.append("--tensorboard")
    if args.device != "cpu":
        parts += ["--device", args.device]
    command = shlex.join(parts)
    world = os.environ.get("WORLD_SIZE")
    if world and world != "1":  # the checkpoint says the run was distributed
        command = f"torchrun (WORLD_SIZE={world}) -m {command}"
    return command


def run(args: argparse.Namespace) -> int:
    from neurosym.agent.run.trainer import RunOptions, train

    overrides: dict[str, dict[str, Any]] = {"train": {}, "model": {}}
    for _, dest, kind in _OVERRIDES:
        overrides[kind][dest] = getattr(args, dest)
    if overrides["train"]["workers"] is None and not args.resume and args.algo in (None, "a3c"):
        overrides["train"]["workers"] = os.cpu_count() or 1
    options = RunOptions(
        frames=args.frames,
        minutes=args.minutes,
        target_return=args.target_return,
        target_success=args.target_success,
        eval_interval=args.eval_interval,
        eval_episodes=args.eval_episodes,
        checkpoint_interval=args.checkpoint_interval,
        snapshot_every=args.snapshot_every,
        window=args.window,
        slim=args.slim,
        progress=not args.quiet,
        tensorboard=args.tensorboard,
        device=args.device,
    )
    result = train(
        args.env,
        args.module,
        args.out,
        train_overrides=overrides["train"],
        model_overrides=overrides["model"],
        env_kwargs=parse_env_options(args.env_option) if args.env_option else None,
        options=options,
        resume=args.resume,
        init_from=args.init_from,
        command=command_line(args),
        print_fn=print,
        preset=args.preset,
        algo=args.algo,
    )
    return 130 if result.stop_reason == "interrupted" else 0
