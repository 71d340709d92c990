"""Model and training settings, with the thesis's Table 4 as defaults per env family.

Three kinds of settings, each a frozen dataclass whose fields carry a one-line
docstring (the ``neurosym train`` help is generated from them,
:mod:`neurosym.agent.run.cli_train`):

* :class:`ModelConfig`: the network's sizes and switches.
* :class:`TrainConfig`: what every learner shares (optimiser, discount, rollout
  length, seed, ...) and, in ``learner``, the chosen learner's own settings:
  :class:`A3CConfig`, :class:`PPOConfig` or :class:`ImitationConfig`.

Table 4 (thesis section 5.1) fixes one set of sizes for both relational modules;
where it differs between Box-World (BW) and Relational-Grid-World (RGW) the
family decides: query/key size 64 BW / 32 RGW, learning rate 2e-4 BW / 2e-3 RGW,
entropy 0.01 BW / 0.02 RGW. PrediNet relations: the table says 8 and the text
of 5.1 says 4; we follow the table. The discount gamma is not in the thesis;
we use 0.99.

Presets. ``preset="thesis"`` is Table 4 exactly: RMSprop (lr as above, epsilon
0.1, decay 0.99), gradient clip 400, classic A3C (one env per worker), the
network as first built (no entity normalisation), raw rewards, unnormalised
advantages, n-step returns, and the RGB Box-World observation.
``preset="default"`` is what learns best here; each departure from Table 4
says why at its field (docs/results.md has the figures).

Checkpoints store the configs as plain flat dicts (``to_dict``/``from_dict``;
the training settings are the common ones and the learner's side by side). A
key missing from a stored config predates that setting: ``from_dict`` fills it
with the value the code had before the setting existed (``_LEGACY``), so older
checkpoints load and replay as they were made. Older checkpoints store every
learner's fields; ``from_dict`` keeps those of the run's learner. Settings that were
retired (``RETIRED``) load when they hold their neutral value; a checkpoint
that used one is refused in one line naming it.
"""

from __future__ import annotations

import ast
import inspect
import textwrap
from dataclasses import MISSING, asdict, dataclass, field, fields
from functools import cache
from typing import Any

from neurosym.errors import ConfigError

MODULES = ("predinet", "mhdpa")
FAMILIES = ("rgw", "boxworld")
PRESETS = ("default", "thesis")
ALGOS = ("a3c", "ppo", "imitate")
OPTIMIZERS = ("adam", "rmsprop")
PPO_ADVANTAGES = ("minibatch", "running")
INITS = ("orthogonal", "torch")
QUERIES = ("scene", "learned")
KEYS = ("entities", "cells")

FLAG = {"flag": True}
"""field metadata: the setting is a ``neurosym train`` flag of its own (others: ``--set``)"""


def flag(**cli: Any) -> dict[str, Any]:
    """Field metadata for a setting with a flag: ``choices``, ``metavar``, ``parse`` ("channels")."""
    return {"flag": True, **cli}


# Table 4 values that differ by env family.
_MODEL_FAMILY: dict[str, dict[str, Any]] = {
    "rgw": {"key_size": 32},
    "boxworld": {"key_size": 64},
}
# Table 4 exactly (preset "thesis"): classic A3C, RMSprop with epsilon 0.1.
_THESIS_TRAIN: dict[str, dict[str, Any]] = {
    "rgw": {"lr": 2e-3, "entropy": 0.02},
    "boxworld": {"lr": 2e-4, "entropy": 0.01},
}
_THESIS_COMMON: dict[str, Any] = {
    "optimizer": "rmsprop",
    "rms_eps": 0.1,
    "grad_clip": 400.0,
    "envs": 1,
    "gamma": 0.99,
    "reward_scale": 1.0,
    "normalize_advantages": False,
    "gae_lambda": 1.0,
}
# What learns best here (preset "default"), flat: each learner takes its own fields.
_DEFAULT_TRAIN: dict[str, dict[str, Any]] = {
    # RGW keeps the learner its shipped agents were trained with: RMSprop with epsilon 1e-5
    # (Table 4's 0.1 stalls), n-step returns, and two exploration aids, since the +10
    # terminal sits behind a teleport reached across a mountain.
    "rgw": {
        "optimizer": "rmsprop",
        "lr": 2e-3,
        "rms_eps": 1e-5,
        "grad_clip": 400.0,
        "entropy": 0.02,
        "gamma": 0.95,
        "explore": 0.2,
        "sil": 1.0,
        "normalize_advantages": False,
        "gae_lambda": 1.0,
    },
    # Adam, GAE, running-RMS advantages, rewards x 0.1: the +11 gem otherwise makes the
    # critic's loss (and its pull on the shared layers) far larger than the actor's;
    # self-imitation, without which A3C on bw1 stays far from solving it.
    "boxworld": {"lr": 5e-4, "entropy": 0.01, "reward_scale": 0.1, "sil": 1.0},
}
# PPO: no exploration aids, the plain comparison point.
_PPO_TRAIN: dict[str, Any] = {
    "envs": 64,
    "n_steps": 128,
    "lr": 5e-4,
    "optimizer": "adam",
    "grad_clip": 0.5,
    "normalize_advantages": True,
    "gae_lambda": 0.95,
    "explore": 0.0,
}
# DAgger from the RGW planner: one process, 64 envs x 32 steps of labelled states.
_IMITATE_TRAIN: dict[str, Any] = {
    "envs": 64,
    "n_steps": 32,
    "lr": 5e-4,
    "optimizer": "adam",
    "grad_clip": 0.5,
    "reward_scale": 0.1,
    "explore": 0.0,
}
_SEEING_MODEL: dict[str, Any] = {"entity_norm": True, "attention_gain": 8.0, "init": "orthogonal"}
_THESIS_MODEL: dict[str, Any] = {"entity_norm": False, "attention_gain": 1.0, "init": "torch"}
_DEFAULT_MODEL: dict[str, dict[str, Any]] = {
    # RGW: the network the shipped agents were trained with (see _DEFAULT_TRAIN)
    "rgw": _THESIS_MODEL,
    # Box-World: sizes of Table 4 but key size 32 (as RGW): queries come from the flattened
    # entities, so key size 64 makes that one layer nearly all of the weights and most of
    # a forward-backward; 32 halves both
    "boxworld": {**_SEEING_MODEL, "key_size": 32},
}
_LEGACY: dict[str, dict[str, Any]] = {
    # what the code did before each setting existed (checkpoints without the key)
    "ModelConfig": {"entity_norm": False, "attention_gain": 1.0, "init": "torch"},
    "TrainConfig": {
        "algo": "a3c",
        "optimizer": "rmsprop",
        "reward_scale": 1.0,
        "normalize_advantages": False,
        "gae_lambda": 1.0,
        "preset": "legacy",
    },
}
RETIRED: dict[str, dict[str, tuple[str, Any]]] = {
    # setting -> (its flag, its neutral value): old checkpoints record them; none used them
    "ModelConfig": {"local_view": ("--local-view", 0), "agent_plane": ("--local-view", -1)},
    "TrainConfig": {
        "critic_warmup": ("--critic-warmup", 0),
        "planner_coef": ("--planner-coef", 0.0),
    },
}


def _check_family(family: str) -> None:
    if family not in FAMILIES:
        raise ConfigError(f"unknown env family {family!r}; expected one of {', '.join(FAMILIES)}")


def _check_preset(preset: str) -> None:
    if preset not in PRESETS:
        raise ConfigError(f"unknown preset {preset!r}; expected one of {', '.join(PRESETS)}")


def _check_choice(config: Any, name: str, allowed: tuple[str, ...]) -> None:
    value = getattr(config, name)
    if value not in allowed:
        raise ConfigError(f"unknown {name} {value!r}; expected one of {', '.join(allowed)}")


def _check_positive(config: Any, *names: str, integer: bool = False) -> None:
    for name in names:
        value = getattr(config, name)
        if not (int(value) >= 1 if integer else float(value) > 0):
            kind = "a positive integer" if integer else "positive"
            raise ConfigError(f"{name} must be {kind}, got {value}")


def preset_env_kwargs(family: str, preset: str = "default") -> dict[str, Any]:
    """Env options a preset trains with: Box-World's one-hot observation by default, RGB for the thesis."""
    _check_family(family)
    _check_preset(preset)
    if family == "boxworld":
        return {"obs_mode": "rgb" if preset == "thesis" else "onehot"}
    return {}


@dataclass(frozen=True)
class ModelConfig:
    """Sizes of the agent network (encoder -> PrediNet | MHDPA -> actor-critic MLP)."""

    module: str
    """relational module: "predinet" or "mhdpa" """
    obs_shape: tuple[int, int, int]
    """observation shape (C, H, W); the model has H * W entities"""
    obs_scale: float = 1.0
    """factor turning raw observation values into [0, 1] (1 for onehot, 1/255 for grey/RGB)"""
    conv_channels: tuple[int, ...] = field(
        default=(12, 24), metadata=flag(parse="channels", metavar="C1,C2,...")
    )
    """output channels of the encoder's conv layers (Table 4: 12,24)"""
    kernel_size: int = field(default=2, metadata=FLAG)
    """encoder conv kernel, stride 1, padded so the feature map keeps the grid shape (Table 4: 2)"""
    heads: int = field(default=4, metadata=FLAG)
    """attention heads (Table 4: 4)"""
    key_size: int = 32
    """query and key size per head (Table 4: 32 RGW, 64 BW)"""
    relations: int = 8
    """PrediNet relations J per head (Table 4: 8; the thesis text says 4)"""
    value_size: int = 64
    """MHDPA value size per head (Table 4: 64)"""
    output_size: int = 26
    """width of the vector the relational module hands the actor-critic (Table 4: 26)"""
    hidden_sizes: tuple[int, ...] = (256, 128, 64)
    """actor-critic MLP widths (Table 4: 256, 128, 64)"""
    n_actions: int = 4
    """policy outputs (up, right, down, left)"""
    entity_norm: bool = True
    """LayerNorm over each entity's conv features before the relational module (thesis: off).
    Without it the fresh network's entities are small and alike: PrediNet's attention is
    uniform and the logits barely vary across observations."""
    attention_gain: float = 8.0
    """factor on the attention logits, softmax(gain * Q K^T / sqrt(d)) (thesis: 1). At 1 the
    fresh attention is close to uniform, so every head attends to the mean entity; at 8 the
    heads start out looking at something."""
    query: str = "scene"
    """PrediNet's queries: "scene" (Q = flat(L) W_Q, docs/design.md and the thesis) or "learned" (a
    learned Q1, Q2 per head, the same for every scene: attention by what and where an entity
    is, not by the rest of the scene). "learned" also drops the query projection, most of a
    Box-World forward's arithmetic."""
    keys: str = field(default="entities", metadata=flag(choices=KEYS))
    """what PrediNet's attention compares its queries with: the encoder's entities (docs/design.md,
    the thesis) or each cell's own observation (cells). With cell keys a head singles out a cell
    by what it holds, so its two arguments are what it chose to compare, even when the
    encoder's view is wider than the map. The entity it reads still sees the encoder's window.
    Cells that hold the same thing get the same weight (a head on several cells of a kind
    reads their mean; the recorded argument is the first in row-major order).
    ``--init-from`` may switch an agent to cells: W_K starts afresh, every other weight is
    copied."""
    init: str = "orthogonal"
    """weight initialisation of the MLP, the value head and PrediNet's read-out: "orthogonal"
    (gain sqrt 2 before ReLUs, 1 for the value and read-out, as in SB3 and CleanRL) or "torch"
    (PyTorch's default, Table 4's network), which shrinks a signal's spread layer by layer
    until the fresh value barely varies across observations. The policy head starts at gain
    0.01 either way (a near uniform first policy)."""

    def __post_init__(self) -> None:
        if self.module not in MODULES:
            raise ConfigError(
                f"unknown module {self.module!r}; expected one of {', '.join(MODULES)}"
            )
        object.__setattr__(self, "obs_shape", tuple(int(v) for v in self.obs_shape))
        object.__setattr__(self, "conv_channels", tuple(int(v) for v in self.conv_channels))
        object.__setattr__(self, "hidden_sizes", tuple(int(v) for v in self.hidden_sizes))
        if len(self.obs_shape) != 3 or min(self.obs_shape) < 1:
            raise ConfigError(
                f"obs_shape must be (C, H, W) with positive sizes, got {self.obs_shape}"
            )
        if not self.conv_channels or not self.hidden_sizes:
            raise ConfigError("conv_channels and hidden_sizes need at least one entry each")
        for name in (
            "kernel_size",
            "heads",
            "key_size",
            "relations",
            "value_size",
            "output_size",
            "n_actions",
        ):
            if int(getattr(self, name)) < 1:
                raise ConfigError(f"{name} must be a positive integer, got {getattr(self, name)}")
        if min(self.conv_channels) < 1 or min(self.hidden_sizes) < 1:
            raise ConfigError("conv_channels and hidden_sizes must be positive")
        if not self.obs_scale > 0:
            raise ConfigError(f"obs_scale must be positive, got {self.obs_scale}")
        # PrediNet's switches: the first choice is DESIGN's, the only one MHDPA has
        for name, allowed, plural in (("query", QUERIES, "queries"), ("keys", KEYS, "keys")):
            value, default = getattr(self, name), allowed[0]
            if value not in allowed:
                raise ConfigError(f"unknown {name} {value!r}; expected one of {', '.join(allowed)}")
            if value != default and self.module != "predinet":
                raise ConfigError(
                    f"{name} {value!r} is PrediNet's; {self.module}'s {plural} come from each "
                    f"entity (use {name} {default!r})"
                )
        if self.init not in INITS:
            raise ConfigError(f"unknown init {self.init!r}; expected one of {', '.join(INITS)}")
        if not self.attention_gain > 0:
            raise ConfigError(f"attention_gain must be positive, got {self.attention_gain}")

    @property
    def n_entities(self) -> int:
        """Entities the relational module sees: one per grid cell."""
        return self.obs_shape[1] * self.obs_shape[2]

    @property
    def entity_size(self) -> int:
        """Features per entity: last conv layer's channels plus (row, col)."""
        return self.conv_channels[-1] + 2

    @classmethod
    def for_family(
        cls,
        family: str,
        module: str,
        obs_shape: tuple[int, int, int],
        obs_scale: float = 1.0,
        preset: str = "default",
        **overrides: Any,
    ) -> ModelConfig:
        """Table 4 sizes for an env family ("rgw" or "boxworld"), the preset's switches, then ``overrides``."""
        _check_family(family)
        _check_preset(preset)
        switches = _THESIS_MODEL if preset == "thesis" else _DEFAULT_MODEL[family]
        values = {
            **_MODEL_FAMILY[family],
            **switches,
            **{k: v for k, v in overrides.items() if v is not None},
        }
        return cls(module=module, obs_shape=obs_shape, obs_scale=obs_scale, **values)

    def to_dict(self) -> dict[str, Any]:
        """Plain values only (lists for tuples), as stored in checkpoints."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ModelConfig:
        """Inverse of :meth:`to_dict`; unknown or missing keys are a ConfigError."""
        return _from_dict(cls, data)


@dataclass(frozen=True)
class A3CConfig:
    """A3C's own settings (``--algo a3c``): asynchronous workers, self-imitation."""

    workers: int = field(default=2, metadata=FLAG)
    """worker processes W (neurosym train's default: one per CPU core)"""
    sil: float = field(default=0.0, metadata=FLAG)
    """weight of the self-imitation loss on the best episodes so far (0: none)"""
    sil_episodes: int = 32
    """best episodes each worker keeps for self-imitation"""

    def __post_init__(self) -> None:
        _check_positive(self, "workers", "sil_episodes", integer=True)
        if self.sil < 0:
            raise ConfigError(f"sil must be >= 0, got {self.sil}")


@dataclass(frozen=True)
class PPOConfig:
    """PPO's own settings (``--algo ppo``): clipped-surrogate epochs over each rollout."""

    ppo_epochs: int = field(default=4, metadata=FLAG)
    """passes over each rollout"""
    ppo_minibatches: int = field(default=4, metadata=FLAG)
    """minibatches per pass"""
    clip_range: float = 0.2
    """probability-ratio clip"""
    ppo_advantages: str = "minibatch"
    """with normalize_advantages: "minibatch" centres and scales each minibatch's advantages
    (SB3, CleanRL); "running" divides each rollout's by a running RMS of the advantages seen so
    far (A3C's), so that a rollout without reward keeps its small advantages small"""

    def __post_init__(self) -> None:
        _check_positive(self, "ppo_epochs", "ppo_minibatches", integer=True)
        _check_positive(self, "clip_range")
        _check_choice(self, "ppo_advantages", PPO_ADVANTAGES)


@dataclass(frozen=True)
class ImitationConfig:
    """DAgger's own settings (``--algo imitate``): imitation of the RGW planner."""

    dagger_beta_frames: int = 200_000
    """frames over which the chance of following the planner falls from 1 to 0"""
    dagger_buffer: int = 204_800
    """labelled states kept (the latest)"""
    dagger_batch: int = 512
    """states per gradient step"""
    dagger_steps: int = field(default=8, metadata=FLAG)
    """gradient steps per rollout of envs x n_steps labelled states"""
    safe_coef: float = field(default=0.0, metadata=flag(metavar="C"))
    """weight of a second set loss on every action that gives no return up (the planner's
    regret 0) beside the fastest actions' loss (0: none). It weighs only the states where an
    episode can miss its optimum, which the fastest-route loss weighs like any other."""
    augment: bool = field(default=False, metadata=FLAG)
    """fit each minibatch turned by a random quarter turn or mirrored (RGW's rules and its
    planner are symmetric), so that the network does not memorise its labelled states"""

    def __post_init__(self) -> None:
        _check_positive(self, "dagger_buffer", "dagger_batch", "dagger_steps", integer=True)
        for name in ("dagger_beta_frames", "safe_coef"):
            if getattr(self, name) < 0:
                raise ConfigError(f"{name} must be >= 0, got {getattr(self, name)}")


LearnerConfig = A3CConfig | PPOConfig | ImitationConfig
LEARNER_CONFIGS: dict[str, type] = {"a3c": A3CConfig, "ppo": PPOConfig, "imitate": ImitationConfig}
"""each ``--algo``'s own settings"""
SEED_LIMIT = 2**64
"""seeds are integers in [0, 2**64): what torch and numpy accept"""


@dataclass(frozen=True)
class TrainConfig:
    """What every learner shares, and the chosen learner's own settings in ``learner``.

    ``for_family`` gives a preset's values per env family; ``build`` and
    ``replace`` take flat settings (common and the learner's side by side).
    """

    algo: str = "a3c"
    """learner: "a3c" (asynchronous workers, the mission's algorithm), "ppo" (synchronous) or
    "imitate" (DAgger from the RGW planner)"""
    preset: str = "default"
    """the preset these settings started from ("default", "thesis"), recorded for the reader"""
    optimizer: str = "adam"
    """"adam" (its per-weight step is about lr whatever the gradient's size) or "rmsprop"
    (Table 4; with its epsilon 0.1 the tiny gradients of a fresh encoder barely move it)"""
    lr: float = field(default=1e-3, metadata=FLAG)
    """learning rate (Table 4, RMSprop: 2e-3 RGW, 2e-4 BW)"""
    entropy: float = field(default=0.02, metadata=FLAG)
    """entropy bonus weight (Table 4: 0.02 RGW, 0.01 BW)"""
    gamma: float = field(default=0.99, metadata=FLAG)
    """discount (not in the thesis)"""
    n_steps: int = field(default=40, metadata=FLAG)
    """rollout length per update (Table 4 "buffer": 40)"""
    value_coef: float = 0.5
    """weight of the value loss"""
    explore: float = 0.0
    """count-based exploration bonus beta (intrinsic reward beta / sqrt(visits)); 0: none"""
    explore_half_life: float = 2000.0
    """half-life of the visit counts, in learner steps (K frames each)"""
    rms_eps: float = 1e-5
    """RMSprop epsilon (Table 4: 0.1, which stalls learning here)"""
    adam_eps: float = 1e-5
    """Adam epsilon"""
    reward_scale: float = 1.0
    """factor on the env's rewards in the training signal (reported returns stay the env's)"""
    normalize_advantages: bool = True
    """scale each update's advantages, so that the actor's gradient does not grow with the
    rewards' size and the critic does not drown it on the shared layers"""
    gae_lambda: float = 0.95
    """GAE lambda for the advantages (1: the n-step returns of Table 4's A3C)"""
    rms_alpha: float = 0.99
    """RMSprop decay (Table 4: 0.99), no momentum"""
    grad_clip: float = 0.5
    """global gradient-norm clip (Table 4: 400, which never bites; 0.5, as common A2C/PPO code
    has it, keeps one rollout with a rare large reward from throwing the weights far)"""
    envs: int = field(default=8, metadata=FLAG)
    """environments per learner K (1: classic A3C with one env per worker)"""
    seed: int = field(default=0, metadata=FLAG)
    """base seed of the run's envs, sampling and initial weights"""
    learner: LearnerConfig | None = None
    """the settings of ``algo``'s learner (None: its defaults)"""

    def __post_init__(self) -> None:
        for name, allowed in (("algo", ALGOS), ("optimizer", OPTIMIZERS)):
            _check_choice(self, name, allowed)
        own = LEARNER_CONFIGS[self.algo]
        if self.learner is None:
            object.__setattr__(self, "learner", own())
        elif not isinstance(self.learner, own):
            raise ConfigError(f"--algo {self.algo} needs {own.__name__}, got {self.learner!r}")
        _check_positive(self, "lr", "gamma", "rms_eps", "adam_eps", "rms_alpha", "grad_clip",
                        "explore_half_life", "reward_scale")  # fmt: skip
        _check_positive(self, "n_steps", "envs", integer=True)
        if not 0 < self.gamma <= 1 or not 0 < self.rms_alpha < 1:
            raise ConfigError("gamma must be in (0, 1] and rms_alpha in (0, 1)")
        if not 0 <= self.gae_lambda <= 1:
            raise ConfigError(f"gae_lambda must be in [0, 1], got {self.gae_lambda}")
        if self.entropy < 0 or self.value_coef < 0 or self.explore < 0:
            raise ConfigError("entropy, value_coef and explore must be >= 0")
        if not isinstance(self.seed, int) or not 0 <= self.seed < SEED_LIMIT:
            raise ConfigError(f"--seed must be an integer from 0 to 2**64 - 1, got {self.seed}")

    @property
    def a3c(self) -> A3CConfig:
        """A3C's settings (an error in another learner's run)."""
        return self._learner(A3CConfig)

    @property
    def ppo(self) -> PPOConfig:
        """PPO's settings (an error in another learner's run)."""
        return self._learner(PPOConfig)

    @property
    def imitate(self) -> ImitationConfig:
        """DAgger's settings (an error in another learner's run)."""
        return self._learner(ImitationConfig)

    def _learner(self, kind: type) -> Any:
        if not isinstance(self.learner, kind):
            raise ConfigError(f"this run's learner is {self.algo}, which has no {kind.__name__}")
        return self.learner

    @classmethod
    def build(cls, strict: bool = True, **flat: Any) -> TrainConfig:
        """A config from flat settings: the common fields, then ``algo``'s learner's.

        A setting of another learner is dropped; when ``strict`` (a user's flag)
        one that differs from its default is a ConfigError.
        """
        algo = flat.get("algo", "a3c")
        if algo not in LEARNER_CONFIGS:
            raise ConfigError(f"unknown algo {algo!r}; expected one of {', '.join(ALGOS)}")
        common, own = {}, {}
        mine = field_names(LEARNER_CONFIGS[algo])
        for name, value in flat.items():
            if name in mine:
                own[name] = value
            elif name in field_names(cls) and name != "learner":
                common[name] = value
            elif name in learner_setting_owner():
                owner = learner_setting_owner()[name]
                if strict and value != field_default(LEARNER_CONFIGS[owner], name):
                    raise ConfigError(
                        f"{option_name(name)} is a setting of --algo {owner}; this run's "
                        f"learner is {algo}"
                    )
            else:
                raise ConfigError(f"unknown TrainConfig keys: {name}")
        return cls(**common, learner=LEARNER_CONFIGS[algo](**own))

    def flat(self) -> dict[str, Any]:
        """The common settings and the learner's, side by side."""
        common = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "learner"}
        return {**common, **asdict(self.learner)}  # type: ignore[call-overload]

    @classmethod
    def for_family(
        cls, family: str, preset: str = "default", algo: str = "a3c", **overrides: Any
    ) -> TrainConfig:
        """A preset's settings for an env family and learner, then the overrides that are not None."""
        _check_family(family)
        _check_preset(preset)
        if algo == "imitate" and family != "rgw":
            raise ConfigError(
                f"--algo imitate learns from the RGW planner; {family} has none (use a3c or ppo)"
            )
        if preset == "thesis":
            if algo != "a3c":
                raise ConfigError(
                    f"--preset thesis is A3C (Table 4); it has no --algo {algo} settings"
                )
            base = {**_THESIS_COMMON, **_THESIS_TRAIN[family]}
        else:
            base = dict(_DEFAULT_TRAIN[family])
            if algo == "ppo":
                base = {**base, **_PPO_TRAIN}
            elif algo == "imitate":
                base = {**base, **_IMITATE_TRAIN}
        return cls.build(strict=False, **base, preset=preset, algo=algo).replace(**overrides)

    def replace(self, **changes: Any) -> TrainConfig:
        """A copy with the changes that are not None (flat names, as :meth:`build`)."""
        given = {k: v for k, v in changes.items() if v is not None}
        return TrainConfig.build(**{**self.flat(), **given}) if given else self

    def to_dict(self) -> dict[str, Any]:
        """Plain values, flat: the common settings and the learner's side by side (what a
        checkpoint stores; older neurosym versions read it too)."""
        return self.flat()

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        """Inverse of :meth:`to_dict`; also reads older checkpoints' records, which hold every
        learner's fields (only ``algo``'s are kept) and retired settings (see ``RETIRED``)."""
        if not isinstance(data, dict):
            raise ConfigError(f"TrainConfig must be a dict, got {type(data).__name__}")
        data = _without_retired(cls, data)
        legacy = {k: v for k, v in _LEGACY["TrainConfig"].items() if k not in data}
        try:
            return cls.build(strict=False, **legacy, **data)
        except TypeError as exc:
            raise ConfigError(f"bad TrainConfig: {exc}") from None


def field_names(cls: type) -> frozenset[str]:
    return frozenset(f.name for f in fields(cls))


@cache
def learner_setting_owner() -> dict[str, str]:
    """Every learner setting's name -> the ``--algo`` it belongs to."""
    return {name: algo for algo, kind in LEARNER_CONFIGS.items() for name in field_names(kind)}


def option_name(name: str) -> str:
    """The flag of a setting (``ppo_epochs`` -> ``--ppo-epochs``)."""
    return "--" + name.replace("_", "-")


@cache
def field_docs(cls: type) -> dict[str, str]:
    """Each field's docstring (the string literal after it in the class body), whitespace joined."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    body = tree.body[0].body  # type: ignore[attr-defined]
    docs: dict[str, str] = {}
    for node, after in zip(body, body[1:], strict=False):
        if (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and isinstance(after, ast.Expr)
            and isinstance(after.value, ast.Constant)
            and isinstance(after.value.value, str)
        ):
            docs[node.target.id] = " ".join(after.value.value.split())
    return docs


def field_default(cls: type, name: str) -> Any:
    """The default of one of ``cls``'s fields (MISSING when it has none)."""
    for f in fields(cls):
        if f.name == name:
            if f.default_factory is not MISSING:  # type: ignore[misc]
                return f.default_factory()  # type: ignore[misc]
            return f.default
    raise KeyError(name)


def _without_retired(cls: type, data: dict[str, Any]) -> dict[str, Any]:
    """``data`` without the retired settings it records at their neutral value; one it used
    is refused (the model or learner it describes no longer exists)."""
    retired = RETIRED.get(cls.__name__, {})
    for name, (option, neutral) in retired.items():
        if name in data and data[name] != neutral:
            raise ConfigError(
                f"it was trained with {option} {data[name]}, an option this version no longer "
                "has (neurosym before its removal plays it)"
            )
    return {k: v for k, v in data.items() if k not in retired}


def _from_dict(cls: Any, data: dict[str, Any]) -> Any:
    if not isinstance(data, dict):
        raise ConfigError(f"{cls.__name__} must be a dict, got {type(data).__name__}")
    data = _without_retired(cls, data)
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ConfigError(f"unknown {cls.__name__} keys: {', '.join(unknown)}")
    legacy = {k: v for k, v in _LEGACY.get(cls.__name__, {}).items() if k not in data}
    try:
        return cls(**legacy, **data)
    except TypeError as exc:
        raise ConfigError(f"bad {cls.__name__}: {exc}") from None
