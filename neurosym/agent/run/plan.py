"""What a run will do, decided before any process starts: a new run, a resumed one, or a
new run from another checkpoint's weights (``--init-from``).

:func:`resolve_run` reads and checks everything (the env, the checkpoint, the
configs, the output directory) and returns a :class:`RunPlan`. It starts no
process and writes nothing, so every mistake is reported before a run
directory exists, and tests can resolve runs without training them.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from neurosym.agent.checkpoint import chain_command, read_checkpoint
from neurosym.agent.config import ModelConfig, TrainConfig, preset_env_kwargs
from neurosym.agent.learners import distributed
from neurosym.agent.networks.adapters import module_has
from neurosym.agent.run.options import RunOptions
from neurosym.errors import CheckpointError, ConfigError

CHECKPOINT_NAME = "checkpoint.pt"
METRICS_NAME = "metrics.csv"
SNAPSHOTS_DIR = "snapshots"
WEIGHT_LIMIT = 50_000_000
"""The most weights a new run's model may have (about 200 MB a copy)."""
INIT_KEYS = ("init_from", "init_env", "init_frames", "init_wall_s")
"""What a run started with --init-from records of its source, in its metrics (kept on resume)."""


@dataclass
class RunPlan:
    """A resolved run: where it writes, what it trains, and what it starts from."""

    out: Path
    env_name: str
    env_kwargs: dict[str, Any]
    family: str
    model_config: ModelConfig
    train_config: TrainConfig
    options: RunOptions
    command: str
    """every command that made the checkpoint, `` && ``-joined, this one last"""
    device: str = "cpu"
    """where a synchronous learner runs (resolved: cpu or cuda)"""
    world: distributed.World = field(default_factory=distributed.World)
    resume: bool = False
    frames0: int = 0
    """frames, episodes and wall seconds trained before this session (a resumed run)"""
    episodes0: int = 0
    wall0: float = 0.0
    source: dict[str, Any] | None = None
    """the checkpoint payload whose weights the run starts from (resumed or --init-from)"""
    source_path: Path | None = None
    init_meta: dict[str, Any] = field(default_factory=dict)
    """the --init-from source's record (:data:`INIT_KEYS`)"""

    @property
    def checkpoint(self) -> Path:
        return self.out / CHECKPOINT_NAME

    @property
    def learners(self) -> int:
        """Learner processes: A3C's W workers, or one synchronous learner."""
        return self.train_config.a3c.workers if self.train_config.algo == "a3c" else 1

    @property
    def optimizer_state(self) -> dict[str, Any] | None:
        """The optimiser statistics a resumed run continues (None: fresh ones)."""
        return self.source.get("optimizer") if self.resume and self.source else None


def probe_env(env: str, env_kwargs: dict[str, Any]) -> tuple[str, str, tuple[int, int, int], float]:
    """(short name, family, obs shape, obs scale) of an environment, checking the name and kwargs."""
    from neurosym.envs import canonical_name, env_family, make

    name = canonical_name(env)
    probe = make(name, **env_kwargs)
    try:
        shape = tuple(int(v) for v in probe.observation_space.shape)
        scale = float(getattr(probe.unwrapped, "obs_scale", 1.0))
    finally:
        probe.close()
    if len(shape) != 3:
        raise ConfigError(
            f"env {name} has observations of shape {shape}; the agent needs (C, H, W)"
        )
    return name, env_family(name), shape, scale  # type: ignore[return-value]


def resolve_run(
    env: str | None,
    module: str | None,
    out: str | os.PathLike[str],
    *,
    train_overrides: dict[str, Any] | None = None,
    model_overrides: dict[str, Any] | None = None,
    env_kwargs: dict[str, Any] | None = None,
    options: RunOptions | None = None,
    resume: bool = False,
    command: str = "",
    preset: str = "default",
    algo: str | None = None,
    init_from: str | os.PathLike[str] | None = None,
    world: distributed.World | None = None,
    say: Callable[[str], None] | None = None,
) -> RunPlan:
    """The run :func:`neurosym.agent.run.trainer.train` would make of these arguments (its docstring)."""
    options = options or RunOptions()
    world = world or distributed.world_from_env()
    if not world.leader:  # rank 0 alone shows progress and writes
        options = replace(options, progress=False, tensorboard=False)
    out = Path(out)
    given_train = {k: v for k, v in (train_overrides or {}).items() if v is not None}
    given_model = {k: v for k, v in (model_overrides or {}).items() if v is not None}
    if resume and init_from is not None:
        raise ConfigError(
            "--init-from starts a new run and --resume continues one: pass one of them"
        )
    check_out(out, resume, world)
    if resume:
        plan = _resumed(out, env, module, given_train, given_model, env_kwargs, options, algo)
    else:
        plan = _new(env, module, out, given_train, given_model, env_kwargs, options, preset, algo,
                    init_from)  # fmt: skip
    if plan.source is not None and command:
        command = chain_command(plan.source.get("command"), command)
    plan.command, plan.world = command, world
    _check_learner(plan)
    plan.device = distributed.resolve_device(
        options.device, plan.train_config.algo, say if world.leader else None
    )
    if options.frames is not None and options.frames <= plan.frames0:
        raise ConfigError(
            f"--frames {options.frames} is not above the {plan.frames0} frames already trained"
        )
    return plan


def check_out(out: Path, resume: bool, world: distributed.World) -> None:
    """Refuse an --out that is not a run directory, or that does not fit --resume."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is not a directory; the run directory goes there")
    ckpt = out / CHECKPOINT_NAME
    if resume and not ckpt.exists():
        if world.distributed:
            raise CheckpointError(
                f"rank {world.rank}: {ckpt} is not there; --resume under torchrun needs the "
                "run directory on every node (a shared file system)"
            )
        if not out.exists():
            raise CheckpointError(
                f"cannot resume: {out} does not exist (start the run without --resume)"
            )
        held = sorted(p.name for p in out.iterdir())
        raise CheckpointError(
            f"cannot resume: {out} has no {CHECKPOINT_NAME} (it holds "
            f"{', '.join(held) if held else 'nothing'}); the run never wrote one: start it again "
            "without --resume"
        )
    if not resume and ckpt.exists() and world.leader:
        raise ConfigError(
            f"{ckpt} already exists; pass --resume to continue it or choose another --out"
        )


def check_model_fits(
    path: str | os.PathLike[str],
    model_config: ModelConfig,
    module: str | None,
    model_overrides: dict[str, Any],
    shape: tuple[int, int, int],
    env_label: str,
) -> None:
    """Refuse a checkpoint's model that differs from what was asked for or from the env's shape."""
    wanted = {"module": module, **model_overrides} if module else dict(model_overrides)
    diffs = [
        f"{k} {getattr(model_config, k)!r} (asked for {v!r})"
        for k, v in wanted.items()
        if getattr(model_config, k) != v
    ]
    if diffs:
        raise CheckpointError(f"{path} has a different model config: {'; '.join(diffs)}")
    if model_config.obs_shape != shape:
        raise CheckpointError(
            f"{path} expects observations {model_config.obs_shape}, {env_label} gives {shape}"
        )


def check_model_size(config: ModelConfig) -> None:
    """Refuse a model with more than :data:`WEIGHT_LIMIT` weights before any is allocated
    (the sizes are each in range, but their product may not fit in memory)."""
    import torch

    from neurosym.agent.networks.model import ActorCritic

    with torch.device("meta"):  # shapes only, no memory
        weights = sum(p.numel() for p in ActorCritic(config).parameters())
    if weights > WEIGHT_LIMIT:
        raise ConfigError(
            f"the model would have {weights:,} weights, more than the {WEIGHT_LIMIT:,} a run "
            "may train (each learner holds copies): lower hidden_sizes, heads, key_size, "
            "relations, value_size or conv_channels"
        )


def _resumed(
    out: Path,
    env: str | None,
    module: str | None,
    train_overrides: dict[str, Any],
    model_overrides: dict[str, Any],
    env_kwargs: dict[str, Any] | None,
    options: RunOptions,
    algo: str | None,
) -> RunPlan:
    """The run in ``out`` continued: its model and settings unless overridden, its counts."""
    ckpt = out / CHECKPOINT_NAME
    payload = read_checkpoint(ckpt, env=env)
    kwargs = dict(payload["env_kwargs"]) if env_kwargs is None else dict(env_kwargs)
    name, family, shape, _ = probe_env(payload["env"], kwargs)
    model_config: ModelConfig = payload["model_config"]
    check_model_fits(ckpt, model_config, module, model_overrides, shape, "env")
    base = payload.get("train_config") or TrainConfig.for_family(family).to_dict()
    try:
        recorded = TrainConfig.from_dict(base)
    except ConfigError as exc:
        raise CheckpointError(f"{ckpt}: {exc}") from None
    train_config = recorded.replace(**train_overrides)
    if algo is not None and algo != train_config.algo:
        raise CheckpointError(
            f"{ckpt} was trained with --algo {train_config.algo}; resume it with that"
        )
    if options.slim is None:  # a slim run stays slim unless told --no-slim
        options = replace(options, slim=payload.get("optimizer") is None)
    metrics = payload["metrics"]
    return RunPlan(
        out, name, kwargs, family, model_config, train_config, options, command="",
        resume=True, frames0=int(payload["frames"]), episodes0=int(payload["episodes"]),
        wall0=float(metrics.get("wall_s", 0.0)), source=payload, source_path=ckpt,
        init_meta={k: metrics[k] for k in INIT_KEYS if k in metrics},
    )  # fmt: skip


def _new(
    env: str | None,
    module: str | None,
    out: Path,
    train_overrides: dict[str, Any],
    model_overrides: dict[str, Any],
    env_kwargs: dict[str, Any] | None,
    options: RunOptions,
    preset: str,
    algo: str | None,
    init_from: str | os.PathLike[str] | None,
) -> RunPlan:
    """A new run: the preset's settings for ``env``, a fresh model or ``init_from``'s."""
    if env is None:
        raise ConfigError("--env is needed unless --resume continues a run (e.g. --env rgw2)")
    if module is None and init_from is None:
        raise ConfigError(
            "--module (predinet or mhdpa) is needed unless --resume continues a run "
            "or --init-from supplies the model"
        )
    from neurosym.envs import env_family

    kwargs = {**preset_env_kwargs(env_family(env), preset), **(env_kwargs or {})}
    name, family, shape, scale = probe_env(env, kwargs)
    source = None
    init_meta: dict[str, Any] = {}
    if init_from is None:
        model_config = ModelConfig.for_family(
            family, module, shape, scale, preset=preset, **model_overrides
        )
        check_model_size(model_config)
    else:
        source = read_checkpoint(init_from, env=name)
        model_config = source["model_config"]
        keys = model_overrides.get("keys")  # the one model switch a new run may make
        others = {k: v for k, v in model_overrides.items() if k != "keys"}
        check_model_fits(
            init_from, model_config, module, others, shape, f"{name} with these options"
        )
        if keys is not None:
            model_config = replace(model_config, keys=keys)  # validated there
        init_meta = {
            "init_from": str(init_from),
            "init_env": source["env"],
            "init_frames": int(source["frames"]),
            "init_wall_s": float(source["metrics"].get("wall_s", 0.0)),
        }
    train_config = TrainConfig.for_family(
        family, preset=preset, algo=algo or "a3c", **train_overrides
    )
    return RunPlan(
        out, name, kwargs, family, model_config, train_config, options, command="",
        source=source, source_path=None if init_from is None else Path(init_from),
        init_meta=init_meta,
    )  # fmt: skip


def _check_learner(plan: RunPlan) -> None:
    """Refuse a learner that cannot run distributed under torchrun, and an attention target
    without the PrediNet and the route (RGW's planner, Box-World's search) it needs."""
    if plan.world.distributed and plan.train_config.algo != "ppo":
        raise ConfigError(
            "torchrun trains the synchronous learner: pass --algo ppo "
            "(A3C's workers share one machine's memory)"
        )
    if plan.train_config.algo == "imitate" and plan.train_config.imitate.teacher:
        _check_teacher(plan)
    attend = plan.train_config.algo == "imitate" and plan.train_config.imitate.attend_coef > 0
    # a module whose recordings have attends/8 has the two attended arguments the loss teaches
    routed = plan.family in ("rgw", "boxworld")
    if attend and (not routed or not module_has(plan.model_config.module, "attends")):
        raise ConfigError(
            f"attend_coef teaches PrediNet head 0 the next object on an RGW or Box-World route; "
            f"this run is {plan.model_config.module} on {plan.family} (leave it at 0)"
        )


def _check_teacher(plan: RunPlan) -> None:
    """Refuse a teacher that cannot label this run's states, and the safe set it has none of."""
    from neurosym.agent.learners.teacher import load_teacher

    imitate = plan.train_config.imitate
    if imitate.safe_coef > 0:
        raise ConfigError(
            "safe_coef reads the planner's regrets, which a teacher does not give "
            "(leave --safe-coef at 0 with --set teacher=...)"
        )
    config = plan.model_config
    load_teacher(imitate.teacher, plan.env_name, config.obs_shape, config.n_actions)
