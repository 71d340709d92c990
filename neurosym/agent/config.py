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
import math
import numbers
from dataclasses import MISSING, asdict, dataclass, field, fields
from functools import cache
from typing import Any

from neurosym.errors import ConfigError
from neurosym.flags import field_docs, option_name  # noqa: F401 (the train command's too)

MODULES = ("predinet", "mhdpa")
FAMILIES = ("rgw", "boxworld", "minigrid")
PRESETS = ("default", "thesis")
ALGOS = ("a3c", "ppo", "imitate")
IMITATE_FAMILIES = ("rgw", "minigrid")
"""families with a planner for ``--algo imitate`` (Minigrid's: DoorKey levels); any family
imitates a trained agent (``--set teacher=CHECKPOINT``)"""
OPTIMIZERS = ("adam", "rmsprop")
PPO_ADVANTAGES = ("minibatch", "running")
INITS = ("orthogonal", "torch")
QUERIES = ("scene", "learned", "scene_mlp")
KEYS = ("entities", "cells", "cells_xy")


@dataclass(frozen=True)
class Range:
    """The values a numeric setting may take: finite, from ``low`` to ``high``, each end
    open or closed; for a tuple setting (widths), each entry, and at most ``length`` of them.

    Declared with the setting (``field(metadata=bounded("(0, 1]"))``): the config
    classes check their values against it (:func:`check_ranges`), and ``neurosym
    train --set`` reads it. Sizes are bounded too, since they size allocations.
    """

    low: float
    high: float
    low_open: bool = False
    high_open: bool = False
    length: int | None = None

    @classmethod
    def parse(cls, text: str, length: int | None = None) -> Range:
        """'(0, 1]' -> Range(0, 1, low_open=True); ends are Python numbers."""
        low, high = (ast.literal_eval(part.strip()) for part in text[1:-1].split(","))
        return cls(low, high, text[0] == "(", text[-1] == ")", length)

    def holds(self, value: Any) -> bool:
        """Whether one number is finite and inside the range."""
        if isinstance(value, bool) or not isinstance(value, numbers.Real):  # numpy's too
            return False
        if not math.isfinite(value):
            return False
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def __str__(self) -> str:
        low, high = _number(self.low), _number(self.high)
        return f"{'(' if self.low_open else '['}{low}, {high}{')' if self.high_open else ']'}"


def _number(value: float) -> str:
    """A range's end as people write it: 4096, 0.5, 1e-05, 1e12."""
    if abs(value) < 10**7 and float(value).is_integer():
        return str(int(value))
    return f"{value:g}".replace("e+", "e")


def bounded(interval: str, *, length: int | None = None, **meta: Any) -> dict[str, Any]:
    """Field metadata: the setting's :class:`Range` (``interval`` such as "(0, 1]") and ``meta``."""
    return {**meta, "range": Range.parse(interval, length)}


def flag(interval: str | None = None, **cli: Any) -> dict[str, Any]:
    """Field metadata for a setting with a flag: its range (``interval``, as :func:`bounded`),
    ``choices``, ``metavar``, ``parse`` ("channels"), ``length`` (for a tuple)."""
    meta = {"flag": True, **cli}
    if interval is not None:
        meta = bounded(interval, **meta)
    return meta


FLAG = flag()
"""field metadata: the setting is a ``neurosym train`` flag of its own (others: ``--set``)"""


def range_error(name: str, value: Any, kind: type, bounds: Range) -> str | None:
    """Why ``value`` does not fit the setting ``name``, in one line (None when it fits)."""
    what = "an integer" if kind is int else "a finite number"
    if bounds.length is not None:  # widths: 1 to length entries, each in range
        entries = value if isinstance(value, tuple | list) else (value,)
        if 1 <= len(entries) <= bounds.length and all(_fits(v, kind, bounds) for v in entries):
            return None
        shown = ",".join(map(str, entries))
        return f"{name} must be 1 to {bounds.length} entries, each {what} in {bounds}, got {shown}"
    if _fits(value, kind, bounds):
        return None
    return f"{name} must be {what} in {bounds}, got {value}"


def _fits(value: Any, kind: type, bounds: Range) -> bool:
    if kind is int and not isinstance(value, numbers.Integral):
        return False
    return bounds.holds(value)


def field_kind(cls: type, name: str) -> type:
    """int or float: how a numeric field's values are read (a tuple's entries are ints)."""
    declared = str(next(f.type for f in fields(cls) if f.name == name))
    return float if "float" in declared else int


def check_ranges(config: Any) -> None:
    """Refuse, in one line, a field value outside the range declared with it (:class:`Range`)."""
    for f in fields(config):
        bounds = f.metadata.get("range")
        if bounds is None:
            continue
        value = getattr(config, f.name)
        if value is None:  # an optional setting left unset
            continue
        problem = range_error(f.name, value, field_kind(type(config), f.name), bounds)
        if problem:
            raise ConfigError(problem)


# Table 4 values that differ by env family.
_MODEL_FAMILY: dict[str, dict[str, Any]] = {
    "rgw": {"key_size": 32},
    "boxworld": {"key_size": 64},
    # Minigrid: not in the thesis; RGW's key size, and Minigrid's seven actions
    "minigrid": {"key_size": 32, "n_actions": 7},
}
# Table 4 exactly (preset "thesis"): classic A3C, RMSprop with epsilon 0.1.
_THESIS_TRAIN: dict[str, dict[str, Any]] = {
    "rgw": {"lr": 2e-3, "entropy": 0.02},
    "boxworld": {"lr": 2e-4, "entropy": 0.01},
    "minigrid": {"lr": 2e-4, "entropy": 0.01},
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
    # Minigrid: Box-World's learner without the reward scale (Minigrid pays at most 1)
    "minigrid": {"lr": 5e-4, "entropy": 0.01, "sil": 1.0},
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
    "minigrid": {**_SEEING_MODEL, "key_size": 32},
}
_DEFAULT_PREDINET: dict[str, dict[str, Any]] = {
    # Box-World: learned queries. Scene queries (Q = flat(L) W_Q) let one update fix every
    # head's attention on a few cells of the first levels it saw (the largest weight goes from
    # 0.03 to 0.78 in two PPO updates), and A3C on bw1 then misses 90 % training success on 2 of
    # 3 seeds in 10 minutes; learned queries reach it on all 3, 2-3x sooner, and skip the
    # query projection, most of a forward's arithmetic (docs/results.md, "Against
    # Stable-Baselines3 on bw1"; bench/train_default.py). Checkpoints record their query.
    "boxworld": {"query": "learned"},
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
    obs_scale: float = field(default=1.0, metadata=bounded("(0, 1]"))
    """factor turning raw observation values into [0, 1] (1 for onehot, 1/255 for grey/RGB)"""
    conv_channels: tuple[int, ...] = field(
        default=(12, 24),
        metadata=flag("[1, 1024]", length=16, parse="channels", metavar="C1,C2,..."),
    )
    """output channels of the encoder's conv layers (Table 4: 12,24)"""
    kernel_size: int = field(default=2, metadata=flag("[1, 15]"))
    """encoder conv kernel, stride 1, padded so the feature map keeps the grid shape (Table 4: 2)"""
    heads: int = field(default=4, metadata=flag("[1, 64]"))
    """attention heads (Table 4: 4)"""
    key_size: int = field(default=32, metadata=bounded("[1, 1024]"))
    """query and key size per head (Table 4: 32 RGW, 64 BW)"""
    relations: int = field(default=8, metadata=bounded("[1, 256]"))
    """PrediNet relations J per head (Table 4: 8; the thesis text says 4)"""
    value_size: int = field(default=64, metadata=bounded("[1, 1024]"))
    """MHDPA value size per head (Table 4: 64)"""
    output_size: int = field(default=26, metadata=bounded("[1, 1024]"))
    """width of the vector the relational module hands the actor-critic (Table 4: 26)"""
    hidden_sizes: tuple[int, ...] = field(
        default=(256, 128, 64), metadata=bounded("[1, 8192]", length=8)
    )
    """actor-critic MLP widths (Table 4: 256, 128, 64)"""
    n_actions: int = field(default=4, metadata=bounded("[1, 64]"))
    """policy outputs (up, right, down, left): the env's actions"""
    entity_norm: bool = True
    """LayerNorm over each entity's conv features before the relational module (thesis: off).
    Without it the fresh network's entities are small and alike: PrediNet's attention is
    uniform and the logits barely vary across observations."""
    attention_gain: float = field(default=8.0, metadata=bounded("(0, 1000]"))
    """factor on the attention logits, softmax(gain * Q K^T / sqrt(d)) (thesis: 1). At 1 the
    fresh attention is close to uniform, so every head attends to the mean entity; at 8 the
    heads start out looking at something."""
    query: str = "scene"
    """PrediNet's queries: "scene" (Q = flat(L) W_Q, docs/design.md and the thesis) or "learned" (a
    learned Q1, Q2 per head, the same for every scene: attention by what and where an entity
    is, not by the rest of the scene). "learned" also drops the query projection, most of a
    Box-World forward's arithmetic. "scene_mlp" (cell keys only) adds a one-layer MLP of the
    scene to the scene queries, zero at the start (the RGW fact bottleneck's)."""
    keys: str = field(default="entities", metadata=flag(choices=KEYS))
    """what PrediNet's attention compares its queries with: the encoder's entities (docs/design.md,
    the thesis) or each cell's own observation (cells). With cell keys a head singles out a cell
    by what it holds, so its two arguments are what it chose to compare, even when the
    encoder's view is wider than the map. The entity it reads still sees the encoder's window.
    Cells that hold the same thing get the same weight (a head on several cells of a kind
    reads their mean; the recorded argument is the first in row-major order) unless the keys
    also read each cell's two coordinates (cells_xy: a head can then tell one teleport end
    from the other).
    ``--init-from`` may switch an agent's keys: W_K starts afresh (from cells to cells_xy it
    keeps the cells' columns and the coordinates' start at zero: the same attention), every
    other weight is copied."""
    relation_bits: float | None = field(default=None, metadata=bounded("[0, 1000]"))
    """PrediNet's fact bottleneck: None (off) or the threshold tau of every relation. On, the
    policy and value read only which relations hold between which attended cells, exactly as
    holds/5 writes them with threshold(J, tau): per head, D_j > tau and D_j < -tau as 0/1 and
    the observation of each argument's argmax cell (the thing attends/8 names; on RGW also
    the held-sword plane), no positions and no relation values. Straight-through gradients
    (sigmoid(D_j -+ tau) for the bits, the soft attention for the cells). tau is rounded to
    float32, as the forward compares it; extract writes abs:tau for such an agent."""
    init: str = "orthogonal"
    """weight initialisation of the MLP, the value head and PrediNet's read-out: "orthogonal"
    (gain sqrt 2 before ReLUs, 1 for the value and read-out, as in SB3 and CleanRL) or "torch"
    (PyTorch's default, Table 4's network), which shrinks a signal's spread layer by layer
    until the fresh value barely varies across observations. The policy head starts at gain
    0.01 either way (a near uniform first policy)."""

    def __post_init__(self) -> None:
        from neurosym.agent.networks.adapters import module_names  # the registry: torch

        if self.module not in module_names():
            raise ConfigError(
                f"unknown module {self.module!r}; expected one of {', '.join(module_names())}"
            )
        object.__setattr__(self, "obs_shape", tuple(int(v) for v in self.obs_shape))
        object.__setattr__(self, "conv_channels", tuple(int(v) for v in self.conv_channels))
        object.__setattr__(self, "hidden_sizes", tuple(int(v) for v in self.hidden_sizes))
        if len(self.obs_shape) != 3 or min(self.obs_shape) < 1:
            raise ConfigError(
                f"obs_shape must be (C, H, W) with positive sizes, got {self.obs_shape}"
            )
        check_ranges(self)
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
        if self.query == "scene_mlp" and self.keys == "entities":
            raise ConfigError(
                "query 'scene_mlp' needs cell keys (keys cells or cells_xy): the entity keys' "
                "attention is computed for linear queries (use query 'scene')"
            )
        if self.relation_bits is not None and self.module != "predinet":
            raise ConfigError(
                f"relation_bits is PrediNet's (the policy reads its thresholded relations); "
                f"{self.module} has no relations (leave relation_bits unset)"
            )
        if self.init not in INITS:
            raise ConfigError(f"unknown init {self.init!r}; expected one of {', '.join(INITS)}")

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
        if preset == "default" and module == "predinet":
            switches = {**switches, **_DEFAULT_PREDINET.get(family, {})}
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

    workers: int = field(default=2, metadata=flag("[1, 256]"))
    """worker processes W (2 when built in Python)"""
    sil: float = field(default=0.0, metadata=flag("[0, 100]"))
    """weight of the self-imitation loss on the best episodes so far (0: none)"""
    sil_episodes: int = field(default=32, metadata=bounded("[1, 100000]"))
    """best episodes each worker keeps for self-imitation"""

    def __post_init__(self) -> None:
        check_ranges(self)


@dataclass(frozen=True)
class PPOConfig:
    """PPO's own settings (``--algo ppo``): clipped-surrogate epochs over each rollout."""

    ppo_epochs: int = field(default=4, metadata=flag("[1, 1000]"))
    """passes over each rollout"""
    ppo_minibatches: int = field(default=4, metadata=flag("[1, 65536]"))
    """minibatches per pass"""
    clip_range: float = field(default=0.2, metadata=bounded("(0, 1000]"))
    """probability-ratio clip"""
    ppo_advantages: str = "minibatch"
    """with normalize_advantages: "minibatch" centres and scales each minibatch's advantages
    (SB3, CleanRL); "running" divides each rollout's by a running RMS of the advantages seen so
    far (A3C's), so that a rollout without reward keeps its small advantages small"""

    def __post_init__(self) -> None:
        check_ranges(self)
        _check_choice(self, "ppo_advantages", PPO_ADVANTAGES)


@dataclass(frozen=True)
class ImitationConfig:
    """DAgger's own settings (``--algo imitate``): imitation of the env's planner, or of a
    trained agent (``teacher``)."""

    dagger_beta_frames: int = field(default=200_000, metadata=bounded("[0, 1e12]"))
    """frames over which the chance of following the planner falls from 1 to 0"""
    dagger_buffer: int = field(default=204_800, metadata=bounded("[1, 1_048_576]"))
    """labelled states kept (the latest)"""
    dagger_batch: int = field(default=512, metadata=bounded("[1, 65536]"))
    """states per gradient step"""
    dagger_steps: int = field(default=8, metadata=flag("[1, 10000]"))
    """gradient steps per rollout of envs x n_steps labelled states"""
    safe_coef: float = field(default=0.0, metadata=flag("[0, 100]", metavar="C"))
    """weight of a second set loss on every action that gives no return up (the planner's
    regret 0) beside the fastest actions' loss (0: none). It weighs only the states where an
    episode can miss its optimum, which the fastest-route loss weighs like any other."""
    augment: bool = field(default=False, metadata=FLAG)
    """fit each minibatch turned by a random quarter turn or mirrored (RGW's rules and its
    planner are symmetric), so that the network does not memorise its labelled states"""
    attend_coef: float = field(default=0.0, metadata=bounded("[0, 100]"))
    """weight of a loss that PrediNet head 0's second argument attends the next key object on
    the route (RGW's planner; Box-World's fewest-boxes route, where the first argument is also
    taught the held key when that object is the lock it opens; 0: none; ``--set
    attend_coef=C``): with the fact bottleneck its KB then names the goal its policy steers by
    (attends/8)"""
    teacher: str = field(default="", metadata={"shown": "none: the planner"})
    """a trained agent whose policy labels the states instead of the planner (a checkpoint,
    a shipped agent's name or an SB3 .zip; ``--set teacher=CHECKPOINT``): the loss is the KL
    from its action probabilities and the critic fits its value (0 for an agent without one).
    Any family, Box-World too; e.g. a fact-bottleneck PrediNet taught a shipped agent's policy"""

    def __post_init__(self) -> None:
        check_ranges(self)


LearnerConfig = A3CConfig | PPOConfig | ImitationConfig
LEARNER_CONFIGS: dict[str, type] = {"a3c": A3CConfig, "ppo": PPOConfig, "imitate": ImitationConfig}
"""each ``--algo``'s own settings"""
SEED_LIMIT = 2**64
ROLLOUT_LIMIT = 2**20
"""states one rollout may hold (envs x n_steps): the buffers are allocated for them"""
"""seeds are integers in [0, 2**64): what torch and numpy accept"""


@dataclass(frozen=True)
class TrainConfig:
    """What every learner shares, and the chosen learner's own settings in ``learner``.

    ``for_family`` gives a preset's values per env family; ``build`` and
    ``replace`` take flat settings (common and the learner's side by side).
    """

    algo: str = "a3c"
    """learner: "a3c" (asynchronous workers, the mission's algorithm), "ppo" (synchronous) or
    "imitate" (DAgger from the env's planner or a trained agent)"""
    preset: str = "default"
    """the preset these settings started from ("default", "thesis"), recorded for the reader"""
    optimizer: str = "adam"
    """"adam" (its per-weight step is about lr whatever the gradient's size) or "rmsprop"
    (Table 4; with its epsilon 0.1 the tiny gradients of a fresh encoder barely move it)"""
    lr: float = field(default=1e-3, metadata=flag("(0, 1]"))
    """learning rate (Table 4, RMSprop: 2e-3 RGW, 2e-4 BW)"""
    entropy: float = field(default=0.02, metadata=flag("[0, 100]"))
    """entropy bonus weight (Table 4: 0.02 RGW, 0.01 BW)"""
    gamma: float = field(default=0.99, metadata=flag("(0, 1]"))
    """discount (not in the thesis)"""
    n_steps: int = field(default=40, metadata=flag("[1, 10000]"))
    """rollout length per update (Table 4 "buffer": 40)"""
    value_coef: float = field(default=0.5, metadata=bounded("[0, 1000]"))
    """weight of the value loss"""
    explore: float = field(default=0.0, metadata=bounded("[0, 1000]"))
    """count-based exploration bonus beta (intrinsic reward beta / sqrt(visits)); 0: none"""
    explore_half_life: float = field(default=2000.0, metadata=bounded("(0, 1e12]"))
    """half-life of the visit counts, in learner steps (K frames each)"""
    rms_eps: float = field(default=1e-5, metadata=bounded("(0, 1]"))
    """RMSprop epsilon (Table 4: 0.1, which stalls learning here)"""
    adam_eps: float = field(default=1e-5, metadata=bounded("(0, 1]"))
    """Adam epsilon"""
    reward_scale: float = field(default=1.0, metadata=bounded("(0, 1000]"))
    """factor on the env's rewards in the training signal (reported returns stay the env's)"""
    normalize_advantages: bool = True
    """scale each update's advantages, so that the actor's gradient does not grow with the
    rewards' size and the critic does not drown it on the shared layers"""
    gae_lambda: float = field(default=0.95, metadata=bounded("[0, 1]"))
    """GAE lambda for the advantages (1: the n-step returns of Table 4's A3C)"""
    rms_alpha: float = field(default=0.99, metadata=bounded("(0, 1)"))
    """RMSprop decay (Table 4: 0.99), no momentum"""
    grad_clip: float = field(default=0.5, metadata=bounded("(0, 1e6]"))
    """global gradient-norm clip (Table 4: 400, which never bites; 0.5, as common A2C/PPO code
    has it, keeps one rollout with a rare large reward from throwing the weights far)"""
    envs: int = field(default=8, metadata=flag("[1, 4096]"))
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
        check_ranges(self)
        if self.envs * self.n_steps > ROLLOUT_LIMIT:
            raise ConfigError(
                f"envs x n_steps must be at most {ROLLOUT_LIMIT:,} states per rollout, got "
                f"{self.envs} x {self.n_steps} = {self.envs * self.n_steps:,}"
            )
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
        if algo == "imitate" and family not in IMITATE_FAMILIES and not overrides.get("teacher"):
            raise ConfigError(
                f"--algo imitate learns from an env's planner (RGW's, Minigrid DoorKey's); "
                f"{family} has none (use a3c or ppo, or a trained agent: --set teacher=CHECKPOINT)"
            )
        if algo == "imitate" and family == "minigrid" and overrides.get("augment"):
            raise ConfigError(
                "--augment turns RGW levels; Minigrid's actions turn the agent (leave it off)"
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
