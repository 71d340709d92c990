"""The training run: start the learner processes, watch them, evaluate, checkpoint, stop.

The learners are the A3C workers (:func:`neurosym.agent.learners.a3c.worker`, W of
them) or one PPO learner (:func:`neurosym.agent.learners.ppo.ppo_learner`); both write
into one shared model and report through one queue, so everything below is
the same for both.

:func:`train` is the plain function behind ``neurosym train``. The parent
process owns everything the user sees: the progress bar, ``metrics.csv``,
``checkpoint.pt`` in the output directory, and the periodic greedy evaluation
that decides when a target return is reached. It evaluates a snapshot of the
shared weights, and when that snapshot reaches the target it is exactly what
the final checkpoint holds (the workers keep changing the shared weights).

Stops on: a frame budget (total frames, counting those before a resume), a
time budget (this session), the greedy return reaching ``target_return``, the
success rate over the last ``window`` training episodes reaching
``target_success``, or Ctrl-C (the workers ignore SIGINT; the parent stops them and checkpoints).

Under torchrun (PPO only) every rank runs this function; rank 0 alone
evaluates and writes, the others only run their learner and stop when it
does (:mod:`neurosym.agent.learners.distributed` says how the ranks agree).
"""

from __future__ import annotations

import collections
import csv
import io
import math
import multiprocessing as _mp
import os
import queue as _queue
import signal
import sys
import time
from collections.abc import Callable
from dataclasses import astuple, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.multiprocessing as mp

from neurosym.agent.checkpoint import build_model, read_checkpoint, save_checkpoint
from neurosym.agent.config import ModelConfig, TrainConfig, preset_env_kwargs
from neurosym.agent.evaluation import play_episodes
from neurosym.agent.learners import distributed
from neurosym.agent.learners.a3c import worker
from neurosym.agent.learners.imitation import imitation_learner
from neurosym.agent.learners.messages import Failed, LossStats, Stopped, Update
from neurosym.agent.learners.optimizers import set_optimizer_hyperparameters, shared_optimizer
from neurosym.agent.learners.ppo import ppo_learner
from neurosym.agent.learners.process import Learner, LearnerContext
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import SUCCESS_OUTCOMES, Finished, select_actions
from neurosym.atomic import write_bytes_atomic
from neurosym.errors import CheckpointError, ConfigError

CHECKPOINT_NAME = "checkpoint.pt"
METRICS_NAME = "metrics.csv"
SNAPSHOTS_DIR = "snapshots"
METRIC_COLUMNS = (
    "wall_s",
    "frames",
    "episodes",
    "fps",
    "mean_return",
    "success_rate",
    "mean_length",
    "greedy_return",
    "greedy_success",
    "policy_loss",
    "value_loss",
    "entropy",
    "grad_norm",
    "approx_kl",
    "clip_fraction",
    "explained_variance",
)
LOSS_FORMATS = {
    "policy_loss": ".5g",
    "value_loss": ".5g",
    "entropy": ".5g",
    "grad_norm": ".5g",
    "approx_kl": ".3g",
    "clip_fraction": ".3g",
    "explained_variance": ".3g",
}
"""metrics.csv's loss columns (:class:`LossStats` fields) and their number formats"""
INIT_KEYS = ("init_from", "init_env", "init_frames", "init_wall_s")
"""What a run started with --init-from records of its source, in its metrics (kept on resume)."""
LEARNERS: dict[str, Learner] = {"a3c": worker, "ppo": ppo_learner, "imitate": imitation_learner}
"""Each ``--algo``'s learner process (:mod:`neurosym.agent.learners`)."""
TARGET_TOLERANCE = 1e-6
"""A greedy mean return within this of the target counts as reaching it (10.7 is not exact in binary)."""


@dataclass
class RunOptions:
    """How long to train and how to watch it (everything but the model and A3C settings)."""

    frames: int | None = None
    """stop once this many frames (env steps, all workers, counting earlier sessions) are done"""
    minutes: float | None = None
    """stop after this many minutes of this session"""
    target_return: float | None = None
    """stop when the greedy policy's mean return reaches this"""
    target_success: float | None = None
    """stop when the success rate over the last ``window`` training episodes (a full window)
    reaches this: the stop a learning-speed comparison wants (bench/peers.py)"""
    eval_interval: float = 2.0
    """seconds between greedy evaluations (more when one takes over 5 % of that)"""
    device: str = "cpu"
    """the PPO learner's device: cpu, cuda or auto (cuda when one is visible)"""
    eval_episodes: int = 8
    """episodes per greedy evaluation (played side by side)"""
    checkpoint_interval: float = 60.0
    """seconds between periodic checkpoints"""
    snapshot_every: float | None = None
    """minutes between copies of the checkpoint kept in ``out/snapshots/frames-N.pt``: the
    checkpoint.pt of a run holds only its last weights, a curve on held-out levels needs
    the earlier ones (bench/curve.py); None keeps none"""
    log_interval: float = 2.0
    """seconds between metrics rows"""
    window: int = 100
    """recent episodes behind mean_return and success_rate"""
    slim: bool | None = None
    """leave the optimizer state out of checkpoints; None: as the checkpoint a resumed run
    continues (slim when it holds no optimizer state), else keep it"""
    progress: bool = True
    """show a rich progress bar on stderr"""
    tensorboard: bool = False
    """also write the metrics as TensorBoard event files under ``out/tensorboard``"""

    def __post_init__(self) -> None:
        if self.frames is not None and self.frames < 1:
            raise ConfigError(f"--frames must be a positive integer, got {self.frames}")
        if self.minutes is not None and not self.minutes > 0:
            raise ConfigError(f"--minutes must be positive, got {self.minutes}")
        if self.target_success is not None and not 0 < self.target_success <= 1:
            raise ConfigError(
                f"--target-success must be a rate in (0, 1], such as 0.9; got {self.target_success}"
            )
        if self.snapshot_every is not None and not self.snapshot_every > 0:
            raise ConfigError(
                f"--snapshot-every must be positive minutes, got {self.snapshot_every}"
            )
        for name in ("eval_interval", "checkpoint_interval", "log_interval"):
            if not getattr(self, name) > 0:
                raise ConfigError(f"{name} must be positive, got {getattr(self, name)}")
        if self.eval_episodes < 1 or self.window < 1:
            raise ConfigError("eval_episodes and window must be positive integers")


@dataclass
class TrainResult:
    """What a run did; also printed by the CLI."""

    checkpoint: Path
    frames: int
    episodes: int
    wall_s: float
    stop_reason: str
    """frames, time, target, interrupted, peer (another rank stopped the run)"""
    greedy_return: float | None
    solved_frames: int | None = None
    solved_wall_s: float | None = None
    metrics: dict[str, Any] = field(default_factory=dict)


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


def greedy_evaluator(
    model: ActorCritic, env: str, env_kwargs: dict[str, Any], episodes: int, seed: int
) -> Callable[[], Finished]:
    """A function playing ``episodes`` greedy episodes with ``model`` (reused env)."""
    from neurosym.envs import make_batched

    def act(obs: np.ndarray) -> np.ndarray:
        with torch.inference_mode():
            logits, _ = model(torch.from_numpy(obs))
            return select_actions(logits, greedy=True).numpy()

    venv = make_batched(env, episodes, seed=seed, **env_kwargs)
    return lambda: play_episodes(act, lambda n: venv, episodes, seed, batch=episodes)


def _read_rows(path: Path) -> list[dict[str, str]]:
    if not path.exists():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def _frames(row: dict[str, Any]) -> int:
    try:
        return int(row.get("frames") or 0)
    except ValueError:
        return 0


def _remove_stale_temporaries(out: Path) -> None:
    """Temporary files a killed run left behind (``.checkpoint.pt.*.tmp``); the real files are whole."""
    for name in (CHECKPOINT_NAME, METRICS_NAME):
        for tmp in out.glob(f".{name}.*.tmp"):
            tmp.unlink(missing_ok=True)
    for tmp in (out / SNAPSHOTS_DIR).glob(".frames-*.pt.*.tmp"):
        tmp.unlink(missing_ok=True)


def _keep_snapshot(checkpoint: Path, snapshot: Path) -> None:
    snapshot.parent.mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(snapshot, checkpoint.read_bytes())


def snapshot_path(out: Path, frames: int) -> Path:
    """Where ``--snapshot-every`` keeps the checkpoint at ``frames`` (names sort by frames)."""
    return out / SNAPSHOTS_DIR / f"frames-{frames:012d}.pt"


def _write_rows(path: Path, rows: list[dict[str, Any]]) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(
        buf, fieldnames=METRIC_COLUMNS, extrasaction="ignore", lineterminator="\n"
    )
    writer.writeheader()
    writer.writerows(rows)
    write_bytes_atomic(path, buf.getvalue().encode())


class _TensorBoard:
    """The metrics rows as TensorBoard scalars against frames, namespaced as SB3/CleanRL do.

    torch's own ``SummaryWriter`` (the ``tensorboard`` package writes the files).
    Tags: ``charts/*`` for returns, success and speed, ``losses/*`` for the
    learner's loss parts.
    """

    TAGS = {
        "mean_return": "charts/episodic_return",
        "success_rate": "charts/success_rate",
        "mean_length": "charts/episodic_length",
        "greedy_return": "charts/greedy_return",
        "greedy_success": "charts/greedy_success",
        "fps": "charts/fps",
        "episodes": "charts/episodes",
        "policy_loss": "losses/policy_loss",
        "value_loss": "losses/value_loss",
        "entropy": "losses/entropy",
        "grad_norm": "losses/grad_norm",
        "approx_kl": "losses/approx_kl",
        "clip_fraction": "losses/clipfrac",
        "explained_variance": "losses/explained_variance",
    }

    def __init__(self, directory: Path) -> None:
        from torch.utils.tensorboard import SummaryWriter

        self.writer = SummaryWriter(log_dir=str(directory))

    def add(self, row: dict[str, Any]) -> None:
        step = int(row["frames"])
        for column, tag in self.TAGS.items():
            text = str(row.get(column, ""))
            if text:
                self.writer.add_scalar(tag, float(text), step)
        self.writer.flush()

    def close(self) -> None:
        self.writer.close()


def _fmt(value: float | None, spec: str = ".3f") -> str:
    return (
        ""
        if value is None or (isinstance(value, float) and math.isnan(value))
        else format(value, spec)
    )


class _Stats:
    """Running figures in the parent, fed by the workers' messages."""

    def __init__(self, frames: int, episodes: int, window: int) -> None:
        self.frames, self.episodes = frames, episodes
        self.returns: collections.deque[float] = collections.deque(maxlen=window)
        self.success: collections.deque[bool] = collections.deque(maxlen=window)
        self.lengths: collections.deque[int] = collections.deque(maxlen=window)
        self.losses: list[LossStats] = []

    def add(self, update: Update) -> None:
        done = update.finished
        self.frames += update.frames
        self.episodes += len(done.returns)
        self.returns.extend(done.returns)
        self.lengths.extend(done.lengths)
        self.success.extend(o in SUCCESS_OUTCOMES for o in done.outcomes)
        self.losses.append(update.stats)

    def mean_return(self) -> float | None:
        return float(np.mean(self.returns)) if self.returns else None

    def success_rate(self) -> float | None:
        return float(np.mean(self.success)) if self.success else None

    def window_full(self) -> bool:
        return len(self.success) == self.success.maxlen

    def row(
        self, wall: float, fps: float, greedy: float | None, greedy_success: float | None
    ) -> dict[str, Any]:
        """One metrics.csv row (strings, blank where unknown); takes the losses since the last row."""
        losses = self.take_losses()
        return {
            "wall_s": _fmt(wall, ".2f"),
            "frames": self.frames,
            "episodes": self.episodes,
            "fps": _fmt(fps, ".1f"),
            "mean_return": _fmt(self.mean_return(), ".4f"),
            "success_rate": _fmt(self.success_rate(), ".4f"),
            "mean_length": _fmt(float(np.mean(self.lengths)) if self.lengths else None, ".2f"),
            "greedy_return": _fmt(greedy, ".4f"),
            "greedy_success": _fmt(greedy_success, ".4f"),
            **{
                name: _fmt(None if losses is None else getattr(losses, name), spec)
                for name, spec in LOSS_FORMATS.items()
            },
        }

    def take_losses(self) -> LossStats | None:
        """The mean of each loss part over the updates since the last call (None: no update)."""
        if not self.losses:
            return None
        losses = np.asarray([astuple(s) for s in self.losses], dtype=np.float64)  # (updates, parts)
        # a part an update could not measure (NaN: a learner without it, or returns that did
        # not vary for explained_variance) is left out of the mean, not allowed to blank it
        counts = (~np.isnan(losses)).sum(axis=0)
        sums = np.nansum(losses, axis=0)
        self.losses = []
        return LossStats(
            *(float(s / c) if c else math.nan for s, c in zip(sums, counts, strict=True))
        )


class FrameRate:
    """Frames per second between the learners' reports of the last ``window`` seconds.

    A row's own 2-second interval is the wrong span for a synchronous learner:
    PPO reports its 8,192 frames once every several seconds, so per-row rates
    alternated between bursts (4 k/s) and zeros while the run made 1.1 k/s.
    Measured from the first to the last report in the window, a steady
    learner's rate is the same on every row; once no report has come for a
    whole window the rate runs to now and falls towards 0.
    """

    def __init__(self, now: float, frames: int, window: float = 30.0) -> None:
        self.window = window
        self.points: collections.deque[tuple[float, int]] = collections.deque([(now, frames)])

    def update(self, now: float, frames: int) -> float:
        """Record the frame count at ``now``; the current rate."""
        if frames != self.points[-1][1]:
            self.points.append((now, frames))
        while len(self.points) > 2 and now - self.points[1][0] >= self.window:
            self.points.popleft()
        (t0, f0), (t1, f1) = self.points[0], self.points[-1]
        if len(self.points) > 1 and now - t1 < self.window:
            return (f1 - f0) / max(t1 - t0, 1e-9)
        return (frames - f0) / max(now - t0, 1e-9)


class _StopSignal:
    """Ctrl-C and SIGTERM as a flag the watch loop polls, not an exception.

    A KeyboardInterrupt raised in the middle of reading a worker's message
    from the queue leaves the rest of that message in the pipe; the next read
    then takes its bytes for a length header and can wait forever (the likely
    cause of a Ctrl-C that once never stopped a run under heavy load). A
    handler that only sets a flag lets every read finish.
    """

    def __init__(self) -> None:
        self.received = False
        self._previous: dict[int, Any] = {}

    def _handle(self, signum: int, frame: object) -> None:
        self.received = True

    def install(self) -> None:
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._previous[sig] = signal.signal(sig, self._handle)

    def restore(self) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)


def _check_model_fits(
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


def _env_seed(seed: int, rank: int, frames_before: int) -> int:
    """A distinct env/sampling seed per (run seed, worker, session start)."""
    return int((seed * 1_000_003 + rank * 7_919 + frames_before) % (2**31 - 1))


def train(
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
    print_fn: Callable[[str], None] | None = None,
    preset: str = "default",
    algo: str | None = None,
    init_from: str | os.PathLike[str] | None = None,
) -> TrainResult:
    """Train an agent with A3C or PPO into ``out`` (``checkpoint.pt``, ``metrics.csv``).

    ``train_overrides`` / ``model_overrides``: TrainConfig / ModelConfig fields
    to change from the preset's family defaults (None values are ignored);
    ``env_kwargs`` are added to the preset's env options (Box-World: one-hot
    observation by default). ``algo``: "a3c" (default) or "ppo". With
    ``resume`` the run continues ``out/checkpoint.pt``: its model and settings,
    unless overridden (a model override that differs is an error), its frame
    and episode counts, its metrics rows. ``init_from``: a new run that starts
    from that checkpoint's weights and model config (a curriculum step; the
    settings are the preset's for ``env``, frames count from 0, and the
    checkpoint records the source's command before this one and its frames as
    ``init_frames``).
    """
    options = options or RunOptions()
    world = distributed.world_from_env()
    if not world.leader:  # rank 0 alone shows progress and writes
        options = RunOptions(**{**options.__dict__, "progress": False, "tensorboard": False})
    out = Path(out)
    ckpt_path = out / CHECKPOINT_NAME
    train_overrides = {k: v for k, v in (train_overrides or {}).items() if v is not None}
    model_overrides = {k: v for k, v in (model_overrides or {}).items() if v is not None}
    torch.set_num_threads(1)

    payload: dict[str, Any] | None = None
    init_payload: dict[str, Any] | None = None
    init_meta: dict[str, Any] = {}
    if resume and init_from is not None:
        raise ConfigError(
            "--init-from starts a new run and --resume continues one: pass one of them"
        )
    if resume:
        if world.distributed and not ckpt_path.exists():
            raise CheckpointError(
                f"rank {world.rank}: {ckpt_path} is not there; --resume under torchrun needs the "
                "run directory on every node (a shared file system)"
            )
        payload = read_checkpoint(ckpt_path, env=env)
        env_name = payload["env"]
        kwargs = dict(payload["env_kwargs"]) if env_kwargs is None else dict(env_kwargs)
        name, family, shape, scale = probe_env(env_name, kwargs)
        model_config: ModelConfig = payload["model_config"]
        _check_model_fits(ckpt_path, model_config, module, model_overrides, shape, "env")
        base = payload.get("train_config") or TrainConfig.for_family(family).to_dict()
        train_config = TrainConfig.from_dict(base).replace(**train_overrides)
        if algo is not None and algo != train_config.algo:
            raise CheckpointError(
                f"{ckpt_path} was trained with --algo {train_config.algo}; resume it with that"
            )
        frames0, episodes0 = int(payload["frames"]), int(payload["episodes"])
        # the checkpoint records every command that made it, in order
        if payload.get("command") and command:
            command = f"{payload['command']} && {command}"
        wall0 = float(payload["metrics"].get("wall_s", 0.0))
        if options.slim is None:  # a slim run stays slim unless told --no-slim
            options = replace(options, slim=payload.get("optimizer") is None)
        init_meta = {k: payload["metrics"][k] for k in INIT_KEYS if k in payload["metrics"]}
    else:
        if env is None:
            raise ConfigError("--env is needed unless --resume continues a run (e.g. --env rgw2)")
        if module is None and init_from is None:
            raise ConfigError(
                "--module (predinet or mhdpa) is needed unless --resume continues a run "
                "or --init-from supplies the model"
            )
        if ckpt_path.exists() and world.leader:
            raise ConfigError(
                f"{ckpt_path} already exists; pass --resume to continue it or choose another --out"
            )
        from neurosym.envs import env_family

        kwargs = {**preset_env_kwargs(env_family(env), preset), **(env_kwargs or {})}
        name, family, shape, scale = probe_env(env, kwargs)
        if init_from is None:
            model_config = ModelConfig.for_family(
                family, module, shape, scale, preset=preset, **model_overrides
            )
        else:
            init_payload = read_checkpoint(init_from, env=name)
            model_config = init_payload["model_config"]
            init_keys = model_overrides.get("keys")  # the one model switch a new run may make
            _check_model_fits(
                init_from, model_config, module,
                {k: v for k, v in model_overrides.items() if k != "keys"}, shape,
                f"{name} with these options",
            )  # fmt: skip
            if init_keys is not None:
                model_config = replace(model_config, keys=init_keys)  # validated there
            if init_payload.get("command") and command:
                command = f"{init_payload['command']} && {command}"
            init_meta = {
                "init_from": str(init_from),
                "init_env": init_payload["env"],
                "init_frames": int(init_payload["frames"]),
                "init_wall_s": float(init_payload["metrics"].get("wall_s", 0.0)),
            }
        train_config = TrainConfig.for_family(
            family, preset=preset, algo=algo or "a3c", **train_overrides
        )
        frames0 = episodes0 = 0
        wall0 = 0.0
    if train_config.algo != "a3c" and train_config.sil > 0:  # a new run's or a resume's --sil
        raise ConfigError(
            f"--sil is A3C's self-imitation; {train_config.algo} has none (use --sil 0)"
        )
    if train_config.planner_coef and family != "rgw":
        raise ConfigError(
            f"--planner-coef learns from the RGW planner; {family} has none (use --planner-coef 0)"
        )
    if world.distributed and train_config.algo != "ppo":
        raise ConfigError(
            "torchrun trains the synchronous learner: pass --algo ppo "
            "(A3C's workers share one machine's memory)"
        )
    say = print_fn or (lambda text: print(text, file=sys.stderr))
    device = distributed.resolve_device(
        options.device, train_config.algo, say if world.leader else None
    )
    if options.frames is not None and options.frames <= frames0:
        raise ConfigError(
            f"--frames {options.frames} is not above the {frames0} frames already trained"
        )

    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(train_config.seed)
    if payload is not None:
        shared = build_model(payload, ckpt_path)
    elif init_payload is not None:
        shared = build_model(init_payload, Path(init_from), keys=model_config.keys)  # type: ignore[arg-type]
    else:
        shared = ActorCritic(model_config)
    shared.share_memory()
    optimizer = shared_optimizer(shared.parameters(), train_config)
    learners = 1 if train_config.algo in ("ppo", "imitate") else train_config.workers
    if payload is not None and payload.get("optimizer"):
        try:
            optimizer.load_state_dict(payload["optimizer"])
        except (ValueError, KeyError, RuntimeError) as exc:
            raise CheckpointError(
                f"{ckpt_path}: its optimizer state does not fit the model ({exc})"
            ) from None
        optimizer._init_state()
        set_optimizer_hyperparameters(optimizer, train_config)
    optimizer.share_memory()

    if world.leader:
        _remove_stale_temporaries(out)
    rows: list[dict[str, Any]] = []
    if resume:  # rows written after the checkpoint describe training that a kill lost
        rows = [r for r in _read_rows(out / METRICS_NAME) if _frames(r) <= frames0]
    board = _TensorBoard(out / "tensorboard") if options.tensorboard else None

    def log_row(row: dict[str, Any]) -> None:
        if not world.leader:
            return
        rows.append(row)
        _write_rows(out / METRICS_NAME, rows)
        if board is not None:
            board.add(row)

    stats = _Stats(frames0, episodes0, options.window)
    eval_model = ActorCritic(model_config)
    eval_model.eval()
    evaluate = greedy_evaluator(
        eval_model, name, kwargs, options.eval_episodes, seed=10_000 + train_config.seed
    )

    def checkpoint(state_dict: dict[str, torch.Tensor] | None, extra: dict[str, Any]) -> None:
        metrics = {**(rows[-1] if rows else {}), **init_meta, **extra}
        metrics = {
            k: (float(v) if isinstance(v, np.floating) else v)
            for k, v in metrics.items()
            if v is not None
        }
        save_checkpoint(
            ckpt_path,
            model=shared,
            config=model_config,
            env_name=name,
            env_kwargs=kwargs,
            train_config=train_config,
            optimizer_state=None if options.slim else optimizer.state_dict(),
            frames=stats.frames,
            episodes=stats.episodes,
            metrics=metrics,
            command=command,
            state_dict=state_dict,
        )

    # CUDA cannot be used in a forked child once the parent touched it: spawn for GPUs
    fork = "fork" in _mp.get_all_start_methods() and device != "cuda"
    ctx = mp.get_context("fork" if fork else "spawn")
    stop = ctx.Event()
    messages = ctx.Queue()
    procs = []
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # children start with Ctrl-C ignored
    learner = LEARNERS[train_config.algo]
    try:
        for rank in range(learners):
            # under torchrun each rank's learner has its own seeds
            seed = _env_seed(train_config.seed, rank + world.rank, frames0)
            args = LearnerContext(
                rank=rank,
                shared=shared,
                optimizer=optimizer,
                model_config=model_config,
                train_config=train_config,
                env_name=name,
                env_kwargs=kwargs,
                env_seed=seed,
                stop=stop,
                queue=messages,
                device=device,
                frames0=frames0,
            )
            proc = ctx.Process(
                target=learner,
                args=(args,),
                daemon=True,
                name=f"neurosym-{train_config.algo}-{rank}",
            )
            proc.start()
            procs.append(proc)
    finally:
        signal.signal(signal.SIGINT, previous)

    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    total = (
        options.frames - frames0
        if options.frames
        else (options.minutes * 60 if options.minutes else None)
    )
    progress = Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.fields[stats]}"),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        disable=not options.progress,
    )
    task = progress.add_task(f"{name} {model_config.module}", total=total, stats="starting workers")

    start = time.monotonic()
    last_log = last_eval = last_ckpt = last_snapshot = start

    def snapshot_due(now: float) -> bool:
        every = options.snapshot_every
        return every is not None and now - last_snapshot >= every * 60

    eval_cost = 0.0
    rate = FrameRate(start, stats.frames)
    greedy: float | None = None
    greedy_success: float | None = None
    best_state: dict[str, torch.Tensor] | None = None
    solved_frames = solved_wall = None
    stop_reason = ""
    failure: str | None = None
    learner_stopped = False
    digests: list[str] = []

    def drain(block_s: float) -> None:
        nonlocal failure, learner_stopped, digests
        deadline = time.monotonic() + block_s
        while True:
            timeout = max(0.0, deadline - time.monotonic())
            try:
                msg = messages.get(timeout=timeout) if timeout > 0 else messages.get_nowait()
            except _queue.Empty:
                return
            if isinstance(msg, Update):
                stats.add(msg)
            elif isinstance(msg, Stopped):
                learner_stopped, digests = True, list(msg.digests)
            elif isinstance(msg, Failed) and failure is None:
                where = f"rank {world.rank} " if world.distributed else ""
                failure = f"{where}worker {msg.rank} failed:\n{msg.traceback}"

    # Ctrl-C and SIGTERM (kill, a batch scheduler) stop the run: workers stopped, checkpoint written
    stop_signal = _StopSignal()
    stop_signal.install()
    try:
        with progress:
            while True:
                drain(0.1)
                now = time.monotonic()
                if stop_signal.received:
                    stop_reason = "interrupted"
                    break
                if failure:
                    stop_reason = "error"
                    break
                if learner_stopped:  # a stop on another rank reached this one's learner
                    stop_reason = "peer"
                    break
                if not any(p.is_alive() for p in procs):
                    failure = "all workers exited unexpectedly"
                    stop_reason = "error"
                    break
                # evaluations take at most ~5 % of the parent's time (they share the cores)
                if world.leader and now - last_eval >= max(options.eval_interval, 20 * eval_cost):
                    snapshot = {k: v.detach().clone() for k, v in shared.state_dict().items()}
                    eval_model.load_state_dict(snapshot)
                    done = evaluate()
                    greedy = float(np.mean(done.returns))
                    greedy_success = float(np.mean([o in SUCCESS_OUTCOMES for o in done.outcomes]))
                    last_eval = time.monotonic()
                    eval_cost = last_eval - now
                    if (
                        options.target_return is not None
                        and greedy >= options.target_return - TARGET_TOLERANCE
                    ):
                        best_state, stop_reason = snapshot, "target"
                        solved_frames, solved_wall = stats.frames, wall0 + (last_eval - start)
                now = time.monotonic()
                if now - last_log >= options.log_interval or stop_reason:
                    fps = rate.update(now, stats.frames)
                    log_row(stats.row(wall0 + now - start, fps, greedy, greedy_success))
                    last_log = now
                    progress.update(
                        task,
                        completed=min(
                            stats.frames - frames0 if options.frames else now - start, total or 0
                        )
                        if total
                        else None,
                        stats=(
                            f"{stats.frames:,} frames  {fps:,.0f}/s  {stats.episodes:,} ep  "
                            f"return {_fmt(stats.mean_return(), '.2f') or '-'}  "
                            f"success {_fmt(stats.success_rate(), '.0%') or '-'}  greedy {_fmt(greedy, '.2f') or '-'}"
                        ),
                    )
                if stop_reason:
                    break
                if not world.leader:  # rank 0 decides (its counts are every rank's)
                    continue
                if (
                    options.target_success is not None
                    and stats.window_full()
                    and (stats.success_rate() or 0.0) >= options.target_success
                ):
                    stop_reason = "target"
                    solved_frames, solved_wall = stats.frames, wall0 + now - start
                elif options.frames is not None and stats.frames >= options.frames:
                    stop_reason = "frames"
                elif options.minutes is not None and now - start >= options.minutes * 60:
                    stop_reason = "time"
                elif now - last_ckpt >= options.checkpoint_interval or snapshot_due(now):
                    checkpoint(None, {"wall_s": wall0 + now - start, "stop_reason": "running"})
                    last_ckpt = now
                    if snapshot_due(now):
                        _keep_snapshot(ckpt_path, snapshot_path(out, stats.frames))
                        last_snapshot = now
    except KeyboardInterrupt:  # a Ctrl-C that came before the handler was in place
        stop_reason = "interrupted"
    finally:
        if world.distributed and world.leader and stop_reason in ("interrupted", "error"):
            # torchrun may kill this rank within seconds of its SIGTERM (a peer died): keep the
            # last whole update now; the learners copy into the shared model only between updates
            checkpoint(None, {"wall_s": round(wall0 + time.monotonic() - start, 2),
                              "stop_reason": stop_reason})  # fmt: skip
        stop.set()
        # a learner blocked in a collective whose peer died never ends by itself, and torchrun
        # kills the survivors 30 s after its SIGTERM: leave time to write the checkpoint
        grace = 5 if world.distributed and stop_reason in ("interrupted", "error") else 30
        deadline = time.monotonic() + grace
        while any(p.is_alive() for p in procs) and time.monotonic() < deadline:
            drain(0.05)
            if learner_stopped:  # its last word is here: leaving the group may take no longer
                deadline = min(deadline, time.monotonic() + 5)
            for p in procs:
                p.join(timeout=0.01)
        cut = False
        for p in procs:
            if p.is_alive():
                p.terminate()
                p.join(timeout=5)
                cut = True
        if not cut:  # a terminated worker may have left half a message in the pipe
            drain(0.0)
        stop_signal.restore()
    wall = wall0 + time.monotonic() - start
    if (
        failure
        and world.distributed
        and world.leader
        and stop_reason not in ("interrupted", "error")
    ):
        # a learner that failed after another stop: keep the last whole update, then report
        # (an interrupted or failed run wrote it already, before stopping its learner)
        checkpoint(None, {"wall_s": round(wall, 2), "stop_reason": "error"})
    if failure:
        raise RuntimeError(failure)
    if (
        not rows or int(rows[-1]["frames"]) != stats.frames
    ):  # what arrived while the workers stopped
        fps = rate.update(time.monotonic(), stats.frames)
        log_row(stats.row(wall, fps, greedy, greedy_success))
    if board is not None:
        board.close()
    summary = {
        "wall_s": round(wall, 2),
        "stop_reason": stop_reason,
        "greedy_return": greedy,
        "greedy_success": greedy_success,
        "mean_return": stats.mean_return(),
        "success_rate": stats.success_rate(),
        "solved_frames": solved_frames,
        "solved_wall_s": None if solved_wall is None else round(solved_wall, 2),
        "device": device,
        "ranks": world.size,
    }
    if world.distributed and digests:
        summary["ranks_identical"] = len(set(digests)) == 1
    if solved_frames is None and payload is not None:
        prior = payload["metrics"]
        summary["solved_frames"], summary["solved_wall_s"] = (
            prior.get("solved_frames"),
            prior.get("solved_wall_s"),
        )
    if world.leader:
        checkpoint(best_state, summary)
    result = TrainResult(
        checkpoint=ckpt_path,
        frames=stats.frames,
        episodes=stats.episodes,
        wall_s=wall,
        stop_reason=stop_reason,
        greedy_return=greedy,
        solved_frames=summary["solved_frames"],
        solved_wall_s=summary["solved_wall_s"],
        metrics=summary,
    )
    if not world.leader:
        return result
    say(
        f"stopped ({stop_reason}) after {stats.frames:,} frames, {stats.episodes:,} episodes, {wall:.1f} s; "
        f"greedy return {_fmt(greedy, '.2f') or '-'}; checkpoint {ckpt_path}"
    )
    return result
