"""How long a run trains and how it is watched: everything but the model and learner settings."""

from __future__ import annotations

from dataclasses import dataclass

from neurosym.errors import ConfigError


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
    reaches this: the stop a learning-speed comparison wants"""
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
    the earlier ones; None keeps none"""
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
