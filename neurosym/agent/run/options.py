"""How long a run trains and how it is watched: everything but the model and learner settings."""

from __future__ import annotations

from dataclasses import dataclass, field

from neurosym.errors import ConfigError

STOP = {"flag": True, "group": "stop"}
WATCH = {"flag": True, "group": "watch"}


@dataclass
class RunOptions:
    """How long to train and how to watch it (everything but the model and learner settings)."""

    frames: int | None = field(default=None, metadata=STOP)
    """stop at this many training frames (env steps of all learners, counting resumed ones)"""
    minutes: float | None = field(default=None, metadata=STOP)
    """stop after this many minutes of this session"""
    target_return: float | None = field(default=None, metadata=STOP)
    """stop when the greedy policy's mean return reaches this"""
    target_success: float | None = field(default=None, metadata=STOP)
    """stop when the success rate over the last ``window`` training episodes (a full window)
    reaches this: the stop a learning-speed comparison wants"""
    eval_interval: float = field(default=2.0, metadata=WATCH)
    """seconds between greedy evaluations (more when one takes over 5 % of that)"""
    device: str = field(default="cpu", metadata={**WATCH, "choices": ("cpu", "cuda", "auto")})
    """where the PPO and DAgger learners act and learn: cpu, cuda (the CPU, with a warning, when
    no GPU is visible) or auto (cuda when one is visible); A3C is CPU-only"""
    eval_episodes: int = field(default=8, metadata=WATCH)
    """episodes per greedy evaluation (played side by side)"""
    checkpoint_interval: float = field(default=60.0, metadata=WATCH)
    """seconds between periodic checkpoints"""
    snapshot_every: float | None = field(default=None, metadata={**WATCH, "metavar": "MINUTES"})
    """minutes between copies of the checkpoint kept in OUT/snapshots/frames-N.pt (for curves
    on held-out levels: checkpoint.pt holds only the last weights); None keeps none"""
    log_interval: float = 2.0
    """seconds between metrics rows"""
    window: int = field(default=100, metadata=WATCH)
    """recent episodes behind mean_return and success_rate"""
    slim: bool | None = field(
        default=None,
        metadata={**WATCH, "shown": "as the checkpoint a resumed run continues, else off"},
    )
    """leave the optimizer state out of checkpoints; None: as the checkpoint a resumed run
    continues, else keep it"""
    progress: bool = True
    """show a rich progress bar on stderr"""
    tensorboard: bool = field(default=False, metadata=WATCH)
    """also write the metrics as TensorBoard event files to OUT/tensorboard"""

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
