"""The training run: start the learner processes, watch them, evaluate, checkpoint, stop.

:func:`train` is the plain function behind ``neurosym train``, in four steps:
resolve the run (:func:`neurosym.agent.run.plan.resolve_run`: new, resumed or
from another checkpoint's weights), start the learners (A3C's W workers, or
one PPO or DAgger learner, :mod:`neurosym.agent.learners`; all write into one
shared model and report through one queue), supervise them, finish.

The parent process owns everything the user sees: the progress bar,
``metrics.csv``, ``checkpoint.pt`` in the output directory, and the periodic
greedy evaluation that decides when a target return is reached. It evaluates
a snapshot of the shared weights, and when that snapshot reaches the target
it is exactly what the final checkpoint holds (the learners keep changing the
shared weights).

Stops on: a frame budget (total frames, counting those before a resume), a
time budget (this session), the greedy return reaching ``target_return``, the
success rate over the last ``window`` training episodes reaching
``target_success``, or Ctrl-C (the learners ignore SIGINT; the parent stops
them and checkpoints).

Under torchrun (PPO only) every rank runs this function; rank 0 alone
evaluates and writes, the others only run their learner and stop when it
does (:mod:`neurosym.agent.learners.distributed` says how the ranks agree).
"""

from __future__ import annotations

import contextlib
import multiprocessing as _mp
import os
import queue as _queue
import shutil
import signal
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.multiprocessing as mp

from neurosym.agent.checkpoint import build_model, save_checkpoint
from neurosym.agent.evaluation import play_episodes
from neurosym.agent.learners.a3c import worker
from neurosym.agent.learners.imitation import imitation_learner
from neurosym.agent.learners.messages import Diverged, Failed, Stopped, Update
from neurosym.agent.learners.optimizers import (
    SharedOptimizer,
    set_optimizer_hyperparameters,
    shared_optimizer,
)
from neurosym.agent.learners.ppo import ppo_learner
from neurosym.agent.learners.process import Learner, LearnerContext
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import SUCCESS_OUTCOMES, Finished, select_actions
from neurosym.agent.run.metrics import (
    FrameRate,
    RunningStats,
    TensorBoard,
    fmt,
    read_rows,
    row_frames,
    write_rows,
)
from neurosym.agent.run.options import RunOptions
from neurosym.agent.run.plan import (
    CHECKPOINT_NAME,
    METRICS_NAME,
    SNAPSHOTS_DIR,
    RunPlan,
    probe_env,
    resolve_run,
)
from neurosym.atomic import write_bytes_atomic
from neurosym.errors import CheckpointError, ConfigError, NeurosymError, OutputError

__all__ = [
    "LEARNERS",
    "RunOptions",
    "TrainResult",
    "TrainingDiverged",
    "probe_env",
    "snapshot_path",
    "train",
]

LEARNERS: dict[str, Learner] = {"a3c": worker, "ppo": ppo_learner, "imitate": imitation_learner}
"""Each ``--algo``'s learner process (:mod:`neurosym.agent.learners`)."""
TARGET_TOLERANCE = 1e-6
"""A greedy mean return within this of the target counts as reaching it (10.7 is not exact in binary)."""


class TrainingDiverged(NeurosymError):
    """A run whose loss, gradient or weights became inf or NaN: it stopped without writing
    them; the checkpoint keeps the last finite weights it had written (if any)."""


def non_finite(state: dict[str, torch.Tensor]) -> str | None:
    """The first tensor of a model's ``state`` holding inf or NaN, in words (None: all finite)."""
    for name, tensor in state.items():
        if tensor.is_floating_point() and not bool(torch.isfinite(tensor).all()):
            return f"its weights {name} are not finite"
    return None


@dataclass
class TrainResult:
    """What a run did; also printed by the CLI."""

    checkpoint: Path
    frames: int
    episodes: int
    wall_s: float
    stop_reason: str
    """frames, time, target, interrupted, peer (another rank stopped the run); a run that
    diverged raises :class:`TrainingDiverged` instead"""
    greedy_return: float | None
    solved_frames: int | None = None
    solved_wall_s: float | None = None
    metrics: dict[str, Any] = field(default_factory=dict)


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


class _StopSignal:
    """Ctrl-C and SIGTERM as a flag the watch loop polls, not an exception.

    A KeyboardInterrupt raised in the middle of reading a worker's message
    from the queue leaves the rest of that message in the pipe; the next read
    then takes its bytes for a length header and can wait forever. A handler
    that only sets a flag lets every read finish.
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
    """Train an agent with A3C, PPO or DAgger into ``out`` (``checkpoint.pt``, ``metrics.csv``).

    ``train_overrides`` / ``model_overrides``: TrainConfig / ModelConfig fields
    to change from the preset's family defaults (None values are ignored);
    ``env_kwargs`` are added to the preset's env options (Box-World: one-hot
    observation by default). ``algo``: "a3c" (default), "ppo" or "imitate".
    With ``resume`` the run continues ``out/checkpoint.pt``: its model and
    settings, unless overridden (a model override that differs is an error),
    its frame and episode counts, its metrics rows. ``init_from``: a new run
    that starts from that checkpoint's weights and model config (a curriculum
    step; the settings are the preset's for ``env``, frames count from 0, and
    the checkpoint records the source's command before this one and its
    frames as ``init_frames``).
    """
    say = print_fn or (lambda text: print(text, file=sys.stderr))
    torch.set_num_threads(1)
    plan = resolve_run(
        env, module, out, train_overrides=train_overrides, model_overrides=model_overrides,
        env_kwargs=env_kwargs, options=options, resume=resume, command=command, preset=preset,
        algo=algo, init_from=init_from, say=say,
    )  # fmt: skip
    created = not plan.out.exists()
    make_run_directory(plan.out)
    shared, optimizer = build_learning_state(plan)
    run = _Supervisor(plan, shared, optimizer)
    try:
        learners = start_learners(plan, shared, optimizer)
        run.supervise(learners)
        return run.finish(say)
    except OutputError:  # a full disk: leave no new run that looks resumable but is not
        if not plan.resume and not run.wrote_checkpoint:
            _remove_unfinished_run(plan.out, created)
        raise


def _remove_unfinished_run(out: Path, created: bool) -> None:
    """What a new run wrote before its first checkpoint (and ``out`` itself, if it made it)."""
    (out / METRICS_NAME).unlink(missing_ok=True)
    shutil.rmtree(out / "tensorboard", ignore_errors=True)
    _remove_stale_temporaries(out)
    if created:
        with contextlib.suppress(OSError):  # only if nothing else is in it
            out.rmdir()


def make_run_directory(out: Path) -> None:
    """Create ``out`` (and its parents), or say in one line why it cannot be."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create the run directory {out}: {exc.strerror or exc}") from None
    if not os.access(out, os.W_OK):
        raise ConfigError(f"cannot write to the run directory {out}: permission denied")


def build_learning_state(plan: RunPlan) -> tuple[ActorCritic, SharedOptimizer]:
    """The shared model (fresh, resumed or --init-from) and its optimiser, in shared memory."""
    torch.manual_seed(plan.train_config.seed)
    if plan.source is not None:
        shared = build_model(plan.source, plan.source_path, keys=plan.model_config.keys)
    else:
        shared = ActorCritic(plan.model_config)
    shared.share_memory()
    optimizer = shared_optimizer(shared.parameters(), plan.train_config)
    if plan.optimizer_state:
        try:
            optimizer.load_state_dict(plan.optimizer_state)
        except (ValueError, KeyError, RuntimeError) as exc:
            raise CheckpointError(
                f"{plan.checkpoint}: its optimizer state does not fit the model ({exc})"
            ) from None
        optimizer._init_state()
        set_optimizer_hyperparameters(optimizer, plan.train_config)
    optimizer.share_memory()
    return shared, optimizer


@dataclass
class Learners:
    """The learner processes of a run, the event that stops them and the queue they report to."""

    procs: list[Any]
    stop: Any
    messages: Any

    def any_alive(self) -> bool:
        return any(p.is_alive() for p in self.procs)


def start_learners(plan: RunPlan, shared: ActorCritic, optimizer: SharedOptimizer) -> Learners:
    """Start the run's learner processes, each with its own env seed."""
    # CUDA cannot be used in a forked child once the parent touched it: spawn for GPUs
    fork = "fork" in _mp.get_all_start_methods() and plan.device != "cuda"
    ctx = mp.get_context("fork" if fork else "spawn")
    learners = Learners([], ctx.Event(), ctx.Queue())
    learner = LEARNERS[plan.train_config.algo]
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # children start with Ctrl-C ignored
    try:
        for rank in range(plan.learners):
            # under torchrun each rank's learner has its own seeds
            seed = _env_seed(plan.train_config.seed, rank + plan.world.rank, plan.frames0)
            context = LearnerContext(
                rank=rank,
                shared=shared,
                optimizer=optimizer,
                model_config=plan.model_config,
                train_config=plan.train_config,
                env_name=plan.env_name,
                env_kwargs=plan.env_kwargs,
                env_seed=seed,
                stop=learners.stop,
                queue=learners.messages,
                device=plan.device,
                frames0=plan.frames0,
            )
            proc = ctx.Process(
                target=learner,
                args=(context,),
                daemon=True,
                name=f"neurosym-{plan.train_config.algo}-{rank}",
            )
            proc.start()
            learners.procs.append(proc)
    finally:
        signal.signal(signal.SIGINT, previous)
    return learners


def _progress_bar(options: RunOptions, description: str, total: float | None) -> tuple[Any, Any]:
    """The rich progress bar on stderr and its task."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Column

    from neurosym.progress import FieldsColumn

    progress = Progress(
        TextColumn("[bold]{task.description}", table_column=Column(no_wrap=True)),
        BarColumn(),
        FieldsColumn("stats"),  # whole figures only, those that fit
        TimeElapsedColumn(),
        console=Console(stderr=True),
        disable=not options.progress,
    )
    task = progress.add_task(description, total=total, stats="starting workers")
    return progress, task


@dataclass
class _Clock:
    """When the supervisor last did each periodic thing (monotonic seconds)."""

    start: float
    log: float = 0.0
    eval: float = 0.0
    ckpt: float = 0.0
    snapshot: float = 0.0
    eval_cost: float = 0.0

    def __post_init__(self) -> None:
        self.log = self.eval = self.ckpt = self.snapshot = self.start


@dataclass
class _Outcome:
    """What the watch loop found out."""

    stop_reason: str = ""
    failure: str | None = None
    greedy: float | None = None
    greedy_success: float | None = None
    best_state: dict[str, torch.Tensor] | None = None
    solved_frames: int | None = None
    solved_wall: float | None = None
    learner_stopped: bool = False
    digests: list[str] = field(default_factory=list)
    diverged: str | None = None
    """what went inf or NaN (the run stops without writing it)"""


class _Supervisor:
    """The parent's side of a run: reads the learners' messages, evaluates, logs, checkpoints."""

    def __init__(self, plan: RunPlan, shared: ActorCritic, optimizer: SharedOptimizer) -> None:
        self.plan, self.shared, self.optimizer = plan, shared, optimizer
        self.options, self.world = plan.options, plan.world
        if self.world.leader:
            _remove_stale_temporaries(plan.out)
        self.rows: list[dict[str, Any]] = []
        if plan.resume:  # rows written after the checkpoint describe training that a kill lost
            self.rows = [
                r for r in read_rows(plan.out / METRICS_NAME) if row_frames(r) <= plan.frames0
            ]
        self.board = TensorBoard(plan.out / "tensorboard") if self.options.tensorboard else None
        self.stats = RunningStats(plan.frames0, plan.episodes0, self.options.window)
        self.eval_model = ActorCritic(plan.model_config)
        self.eval_model.eval()
        self.evaluate = greedy_evaluator(
            self.eval_model, plan.env_name, plan.env_kwargs, self.options.eval_episodes,
            seed=10_000 + plan.train_config.seed,
        )  # fmt: skip
        self.outcome = _Outcome()
        self.clock = _Clock(time.monotonic())
        self.rate = FrameRate(self.clock.start, self.stats.frames)
        self.wrote_checkpoint = False
        self.checkpoint_frames = plan.frames0

    def log_row(self, row: dict[str, Any]) -> None:
        if not self.world.leader:
            return
        self.rows.append(row)
        write_rows(self.plan.out / METRICS_NAME, self.rows)
        if self.board is not None:
            self.board.add(row)

    def checkpoint(self, state_dict: dict[str, torch.Tensor] | None, extra: dict[str, Any]) -> None:
        """Write ``checkpoint.pt``: the shared model (or ``state_dict``) and the run's record;
        weights that are not finite are never written (the run stops as diverged)."""
        plan = self.plan
        if state_dict is None:  # a copy: the learners go on changing the shared weights
            state_dict = {k: v.detach().clone() for k, v in self.shared.state_dict().items()}
        if self.weights_diverged(state_dict):
            return
        self.checkpoint_frames = self.stats.frames
        metrics = {**(self.rows[-1] if self.rows else {}), **plan.init_meta, **extra}
        metrics = {
            k: (float(v) if isinstance(v, np.floating) else v)
            for k, v in metrics.items()
            if v is not None
        }
        save_checkpoint(
            plan.checkpoint,
            model=self.shared,
            config=plan.model_config,
            env_name=plan.env_name,
            env_kwargs=plan.env_kwargs,
            train_config=plan.train_config,
            optimizer_state=None if self.options.slim else self.optimizer.state_dict(),
            frames=self.stats.frames,
            episodes=self.stats.episodes,
            metrics=metrics,
            command=plan.command,
            state_dict=state_dict,
        )
        self.wrote_checkpoint = True

    def weights_diverged(self, state: dict[str, torch.Tensor] | None = None) -> bool:
        """Whether ``state`` (by default the shared weights) holds inf or NaN; the outcome
        then says so."""
        problem = non_finite(self.shared.state_dict() if state is None else state)
        if problem is not None and self.outcome.diverged is None:
            self.outcome.diverged = problem
        return problem is not None

    def drain(self, messages: Any, block_s: float) -> None:
        """Read the learners' messages for up to ``block_s`` seconds."""
        outcome = self.outcome
        deadline = time.monotonic() + block_s
        while True:
            timeout = max(0.0, deadline - time.monotonic())
            try:
                msg = messages.get(timeout=timeout) if timeout > 0 else messages.get_nowait()
            except _queue.Empty:
                return
            if isinstance(msg, Update):
                self.stats.add(msg)
            elif isinstance(msg, Stopped):
                outcome.learner_stopped, outcome.digests = True, list(msg.digests)
            elif isinstance(msg, Diverged) and outcome.diverged is None:
                outcome.diverged = f"{self._learner_name(msg.rank)}: {msg.what}"
            elif isinstance(msg, Failed) and outcome.failure is None:
                outcome.failure = f"{self._learner_name(msg.rank)} failed:\n{msg.traceback}"

    def _learner_name(self, rank: int) -> str:
        where = f"rank {self.world.rank} " if self.world.distributed else ""
        return f"{where}worker {rank}"

    def evaluate_if_due(self, now: float) -> None:
        """A greedy evaluation of a snapshot of the shared weights, at most ~5 % of the time."""
        clock, outcome = self.clock, self.outcome
        if not self.world.leader or now - clock.eval < max(
            self.options.eval_interval, 20 * clock.eval_cost
        ):
            return
        snapshot = {k: v.detach().clone() for k, v in self.shared.state_dict().items()}
        if self.weights_diverged(snapshot):  # the watch loop stops the run
            return
        self.eval_model.load_state_dict(snapshot)
        done = self.evaluate()
        outcome.greedy = float(np.mean(done.returns))
        outcome.greedy_success = float(np.mean([o in SUCCESS_OUTCOMES for o in done.outcomes]))
        clock.eval = time.monotonic()
        clock.eval_cost = clock.eval - now
        target = self.options.target_return
        if target is not None and outcome.greedy >= target - TARGET_TOLERANCE:
            outcome.best_state, outcome.stop_reason = snapshot, "target"
            outcome.solved_frames = self.stats.frames
            outcome.solved_wall = self.plan.wall0 + (clock.eval - clock.start)

    def log_if_due(self, now: float, progress: Any, task: Any, total: float | None) -> None:
        """A metrics row and a progress update every log interval (and on a stop)."""
        clock, stats, outcome = self.clock, self.stats, self.outcome
        if now - clock.log < self.options.log_interval and not outcome.stop_reason:
            return
        fps = self.rate.update(now, stats.frames)
        self.log_row(stats.row(self.plan.wall0 + now - clock.start, fps, outcome.greedy,
                               outcome.greedy_success))  # fmt: skip
        clock.log = now
        done = stats.frames - self.plan.frames0 if self.options.frames else now - clock.start
        progress.update(
            task,
            completed=min(done, total or 0) if total else None,
            stats=(
                f"{stats.frames:,} frames  {fps:,.0f}/s  {stats.episodes:,} ep  "
                f"return {fmt(stats.mean_return(), '.2f') or '-'}  "
                f"success {fmt(stats.success_rate(), '.0%') or '-'}  "
                f"greedy {fmt(outcome.greedy, '.2f') or '-'}"
            ),
        )

    def stop_reason_now(self, now: float) -> str:
        """Rank 0's decision to stop ("" to go on); a periodic checkpoint when it is due."""
        options, stats, clock, outcome = self.options, self.stats, self.clock, self.outcome
        if (
            options.target_success is not None
            and stats.window_full()
            and (stats.success_rate() or 0.0) >= options.target_success
        ):
            outcome.solved_frames = stats.frames
            outcome.solved_wall = self.plan.wall0 + now - clock.start
            return "target"
        if options.frames is not None and stats.frames >= options.frames:
            return "frames"
        if options.minutes is not None and now - clock.start >= options.minutes * 60:
            return "time"
        every = options.snapshot_every
        snapshot_due = every is not None and now - clock.snapshot >= every * 60
        if now - clock.ckpt >= options.checkpoint_interval or snapshot_due:
            self.checkpoint(None, {"wall_s": self.plan.wall0 + now - clock.start,
                                   "stop_reason": "running"})  # fmt: skip
            clock.ckpt = now
            if snapshot_due:
                _keep_snapshot(self.plan.checkpoint, snapshot_path(self.plan.out, stats.frames))
                clock.snapshot = now
        return ""

    def supervise(self, learners: Learners) -> None:
        """Watch the learners until a stop, then stop them (Ctrl-C and SIGTERM stop the run too)."""
        plan, outcome = self.plan, self.outcome
        options = self.options
        if options.frames:
            total: float | None = options.frames - plan.frames0
        else:
            total = options.minutes * 60 if options.minutes else None
        progress, task = _progress_bar(
            options, f"{plan.env_name} {plan.model_config.module}", total
        )
        stop_signal = _StopSignal()
        stop_signal.install()
        try:
            with progress:
                while not self._watch_once(learners, progress, task, total, stop_signal):
                    pass
        except KeyboardInterrupt:  # a Ctrl-C that came before the handler was in place
            outcome.stop_reason = "interrupted"
        finally:
            self._stop_learners(learners)
            stop_signal.restore()

    def _watch_once(
        self, learners: Learners, progress: Any, task: Any, total: float | None, stop_signal: Any
    ) -> bool:
        """One turn of the watch loop; True when the run stops."""
        outcome = self.outcome
        self.drain(learners.messages, 0.1)
        if outcome.diverged:
            outcome.stop_reason = "diverged"
        elif stop_signal.received:
            outcome.stop_reason = "interrupted"
        elif outcome.failure:
            outcome.stop_reason = "error"
        elif outcome.learner_stopped:  # a stop on another rank reached this one's learner
            outcome.stop_reason = "peer"
        elif not learners.any_alive():
            outcome.failure, outcome.stop_reason = "all workers exited unexpectedly", "error"
        if outcome.stop_reason in ("interrupted", "error", "peer", "diverged"):
            return True
        # a stop decided in the last turn (frames, minutes, success) still gets its last
        # evaluation chance and the final metrics row and progress figures
        self.evaluate_if_due(time.monotonic())
        self.log_if_due(time.monotonic(), progress, task, total)
        if outcome.stop_reason:
            return True
        if self.world.leader:  # rank 0 decides (its counts are every rank's)
            outcome.stop_reason = self.stop_reason_now(time.monotonic())
        return False

    def _stop_learners(self, learners: Learners) -> None:
        """Set the stop event, wait for the learners' last words, end any that hang."""
        world, outcome, clock = self.world, self.outcome, self.clock
        failed = outcome.stop_reason in ("interrupted", "error")
        if world.distributed and world.leader and failed:
            # torchrun may kill this rank within seconds of its SIGTERM (a peer died): keep the
            # last whole update now; the learners copy into the shared model only between updates
            self.checkpoint(None, {"wall_s": round(self.plan.wall0 + time.monotonic() - clock.start, 2),
                                   "stop_reason": outcome.stop_reason})  # fmt: skip
        learners.stop.set()
        # a learner blocked in a collective whose peer died never ends by itself, and torchrun
        # kills the survivors 30 s after its SIGTERM: leave time to write the checkpoint
        grace = 5 if world.distributed and failed else 30
        deadline = time.monotonic() + grace
        while learners.any_alive() and time.monotonic() < deadline:
            self.drain(learners.messages, 0.05)
            if (
                outcome.learner_stopped
            ):  # its last word is here: leaving the group may take no longer
                deadline = min(deadline, time.monotonic() + 5)
            for p in learners.procs:
                p.join(timeout=0.01)
        cut = False
        for p in learners.procs:
            if p.is_alive():
                p.terminate()
                p.join(timeout=5)
                cut = True
        if not cut:  # a terminated learner may have left half a message in the pipe
            self.drain(learners.messages, 0.0)

    def finish(self, say: Callable[[str], None]) -> TrainResult:
        """The last metrics row and the final checkpoint; what the run did."""
        plan, outcome, stats, world = self.plan, self.outcome, self.stats, self.world
        wall = plan.wall0 + time.monotonic() - self.clock.start
        if outcome.failure or (world.leader and outcome.best_state is None):
            self.weights_diverged()  # NaN weights, found before the last checkpoint takes them
        if outcome.diverged is not None:
            self._raise_diverged()
        if outcome.failure:
            if (
                world.distributed
                and world.leader
                and outcome.stop_reason not in ("interrupted", "error")
            ):
                # a learner that failed after another stop: keep the last whole update, then report
                # (an interrupted or failed run wrote it already, before stopping its learner)
                self.checkpoint(None, {"wall_s": round(wall, 2), "stop_reason": "error"})
            raise RuntimeError(outcome.failure)
        if not self.rows or int(self.rows[-1]["frames"]) != stats.frames:
            # what arrived while the learners stopped
            fps = self.rate.update(time.monotonic(), stats.frames)
            self.log_row(stats.row(wall, fps, outcome.greedy, outcome.greedy_success))
        if self.board is not None:
            self.board.close()
        summary = self._summary(wall)
        if world.leader:
            self.checkpoint(outcome.best_state, summary)
        result = TrainResult(
            checkpoint=plan.checkpoint,
            frames=stats.frames,
            episodes=stats.episodes,
            wall_s=wall,
            stop_reason=outcome.stop_reason,
            greedy_return=outcome.greedy,
            solved_frames=summary["solved_frames"],
            solved_wall_s=summary["solved_wall_s"],
            metrics=summary,
        )
        if world.leader:
            say(
                f"stopped ({outcome.stop_reason}) after {stats.frames:,} frames, "
                f"{stats.episodes:,} episodes, {wall:.1f} s; greedy return "
                f"{fmt(outcome.greedy, '.2f') or '-'}; checkpoint {plan.checkpoint}"
            )
        return result

    def _raise_diverged(self) -> None:
        """Stop as diverged, in one line: what went inf or NaN, what the checkpoint still holds."""
        frames, what = self.stats.frames, self.outcome.diverged
        if self.board is not None:
            self.board.close()
        if self.wrote_checkpoint:
            kept = (
                f"{self.plan.checkpoint} keeps the last finite weights "
                f"({self.checkpoint_frames:,} frames)"
            )
        elif self.plan.resume:
            kept = f"{self.plan.checkpoint} is as it was ({self.plan.frames0:,} frames)"
        else:
            kept = "no checkpoint was written"
        raise TrainingDiverged(
            f"training diverged at {frames:,} frames ({what}); {kept}: lower --lr or the "
            "settings that scale the loss (reward_scale, value_coef, attention_gain)"
        )

    def _summary(self, wall: float) -> dict[str, Any]:
        """The final checkpoint's record of the run."""
        plan, outcome, stats = self.plan, self.outcome, self.stats
        summary = {
            "wall_s": round(wall, 2),
            "stop_reason": outcome.stop_reason,
            "greedy_return": outcome.greedy,
            "greedy_success": outcome.greedy_success,
            "mean_return": stats.mean_return(),
            "success_rate": stats.success_rate(),
            "solved_frames": outcome.solved_frames,
            "solved_wall_s": None if outcome.solved_wall is None else round(outcome.solved_wall, 2),
            "device": plan.device,
            "ranks": self.world.size,
        }
        if self.world.distributed and outcome.digests:
            summary["ranks_identical"] = len(set(outcome.digests)) == 1
        if outcome.solved_frames is None and plan.resume and plan.source is not None:
            prior = plan.source["metrics"]
            summary["solved_frames"] = prior.get("solved_frames")
            summary["solved_wall_s"] = prior.get("solved_wall_s")
        return summary
