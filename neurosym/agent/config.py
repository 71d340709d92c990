"""Model and training settings, with the thesis's Table 4 as defaults per env family.

Table 4 (thesis section 5.1) fixes one set of sizes for both relational modules;
where it differs between Box-World (BW) and Relational-Grid-World (RGW) the
family decides: query/key size 64 BW / 32 RGW, learning rate 2e-4 BW / 2e-3 RGW,
entropy 0.01 BW / 0.02 RGW. Two notes on the table:

* PrediNet relations: the table says 8, the text of 5.1 says 4 was chosen;
  we follow the table (``relations=8``), ``--relations 4`` gives the text's value.
* The discount gamma is not in the thesis; we use 0.99.

Presets. ``preset="thesis"`` (``neurosym train --preset thesis``) is Table 4
exactly: RMSprop (lr as above, epsilon 0.1, decay 0.99), gradient clip 400,
classic A3C (one env per worker), the network as first built (no entity
normalisation), raw rewards, unnormalised advantages, n-step returns, and the
RGB Box-World observation. ``preset="default"`` is what learns best here,
measured with ``bench/diagnose.py`` (the fresh network's input signal and
gradient split) and ``bench/train.py``; each departure from Table 4 says why
at its field. In short: the thesis network is blind at initialisation (policy
logits varied by 6e-9 across bw1 observations, PrediNet attention exactly
uniform), its per-weight gradients (1e-8 to 4e-7) sit far below RMSprop's
epsilon, and the critic's gradient on the shared layers was 100-200x the
actor's; the default preset fixes each of these.

Both configs are plain frozen dataclasses that round-trip through
``to_dict``/``from_dict`` (plain ints, floats, strings and lists only), which is
how checkpoints store them. A key missing from a stored config predates that
setting: ``from_dict`` fills it with the value the code had before the setting
existed (``_LEGACY``), so older checkpoints load and replay as they were made.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
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
# What learns best here (preset "default"); each value's reason is at its field.
_DEFAULT_TRAIN: dict[str, dict[str, Any]] = {
    # RGW keeps the learner its shipped agents were measured with (rgw2 solved in 54-245 s):
    # RMSprop with epsilon 1e-5 (Table 4's 0.1 stalls), n-step returns, and two exploration
    # aids, since the +10 terminal sits behind a teleport reached across a mountain (random
    # actions reach it in ~0.2 %). The Box-World learner below is not yet measured on RGW.
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
    # critic's loss (and its pull on the shared layers) a hundred times the actor's.
    # Self-imitation 1.0: without it A3C on bw1 stayed at 17-29 % success after 1.8 M
    # frames; with it 75 % at 1.4 M and 93-100 % at 2.3-2.5 M (PrediNet, 2 workers)
    "boxworld": {"lr": 5e-4, "entropy": 0.01, "reward_scale": 0.1, "sil": 1.0},
}
_PPO_TRAIN: dict[str, Any] = {
    "envs": 64,
    "n_steps": 128,
    "workers": 1,
    "lr": 5e-4,
    "optimizer": "adam",
    "grad_clip": 0.5,
    "normalize_advantages": True,
    "gae_lambda": 0.95,
}
# DAgger from the RGW planner (neurosym/agent/imitation.py): one process, 64 envs x 32 steps
# of labelled states, 8 Adam steps of 512 from the latest 204,800 (measured on rgw-random,
# PrediNet: 4 steps of single-action labels reached 58 % action agreement and 4 % greedy
# success on unseen levels in 8 min; 8 steps on the optimal-action sets 73 % and 21 % in 6).
_IMITATE_TRAIN: dict[str, Any] = {
    "envs": 64,
    "n_steps": 32,
    "workers": 1,
    "lr": 5e-4,
    "optimizer": "adam",
    "grad_clip": 0.5,
    "reward_scale": 0.1,
    "explore": 0.0,
    "sil": 0.0,
}
_SEEING_MODEL: dict[str, Any] = {"entity_norm": True, "attention_gain": 8.0, "init": "orthogonal"}
_THESIS_MODEL: dict[str, Any] = {"entity_norm": False, "attention_gain": 1.0, "init": "torch"}
_DEFAULT_MODEL: dict[str, dict[str, Any]] = {
    # RGW: the network the shipped agents were measured with (see _DEFAULT_TRAIN)
    "rgw": _THESIS_MODEL,
    # Box-World: sizes of Table 4 but key size 32 (as RGW): queries come from the flattened
    # entities (196 x 26 inputs), so key size 64 makes that one layer 2.6 M of the 2.7 M
    # weights and about 60 % of a forward-backward; 32 halves both
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


def _agent_plane(family: str) -> int:
    """The one-hot plane that marks the agent, as the family's env lays out its observation."""
    if family == "rgw":
        from neurosym.envs.rgw_rules import AGENT  # plane e holds entity e

        return AGENT
    from neurosym.envs.boxworld_entities import TYPE_PLANES

    return TYPE_PLANES.index("agent")


def _check_family(family: str) -> None:
    if family not in FAMILIES:
        raise ConfigError(f"unknown env family {family!r}; expected one of {', '.join(FAMILIES)}")


def _check_preset(preset: str) -> None:
    if preset not in PRESETS:
        raise ConfigError(f"unknown preset {preset!r}; expected one of {', '.join(PRESETS)}")


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
    conv_channels: tuple[int, ...] = (12, 24)
    """output channels of the conv layers (Table 4: 12 and 24)"""
    kernel_size: int = 2
    """conv kernel size, stride 1, padded so the feature map keeps the grid shape"""
    heads: int = 4
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
    """LayerNorm over each entity's conv features (not its coordinates) before the relational
    module. Without it (Table 4's network) the entities are small and alike at initialisation:
    PrediNet's attention is exactly uniform and the logits barely vary across observations
    (bench/diagnose.py)."""
    attention_gain: float = 8.0
    """factor on the attention logits (softmax(gain * Q K^T / sqrt(d))). At 1 (Table 4's network)
    the fresh attention is uniform to within 1.3x on bw1 (max weight 0.0063 against 1/196), so
    every head attends to the mean entity and PrediNet's D is 0; at 8 the largest weight is
    5x uniform (entropy 96 % of uniform's), so heads start out looking at something"""
    query: str = "scene"
    """PrediNet's queries: "scene" (Q = flat(L) W_Q, DESIGN.md and the thesis) or "learned" (a
    learned Q1, Q2 per head, the same for every scene: attention by what and where an entity
    is, not by the rest of the scene; see neurosym/agent/predinet.py for the measurements).
    "learned" also drops the query projection, two thirds of a bw1 forward's arithmetic (PPO
    64 x 2 on bw1: 2.3-3.2 k frames/s against 1.5-2.0 k). Measured on bw1 (PPO 64 steps x 2
    passes, frames to 90 % training success, seeds 0/1/2): scene 657 k / none / none in 8
    minutes; learned none (seed 0 collapsed to 0.2 % success) / 1,216 k / 461 k; learned with
    ppo_advantages "running" 652 k / 787 k / 542 k (seed 3: 624 k). A3C (the defaults): scene
    1,167 k / none / none in 10 minutes, learned 531 k / 837 k / 705 k (135-205 s). Not yet
    measured on bw2/bw3, whose chains may need a query that depends on the held key, so
    "scene" stays the default."""
    keys: str = "entities"
    """what PrediNet's attention compares its queries with: "entities" (K = L W_K, DESIGN.md and
    the thesis) or "cells" (K = c W_K, c a cell's own observation vector, e.g. RGW's one-hot
    planes, without coordinates): a head addresses cells by what they hold and reads the
    encoder's entity there (E = a L, as before). Why it exists: with an encoder whose view is
    wider than the map (the deep rgw-random PrediNet, six 3x3 layers) every entity carries the
    whole route, and the heads attended background cells (no head on two different objects on
    more than 7 % of states); with cell keys a head can only single out a cell by its content,
    so its two arguments are what it chose to compare. The entity it reads still sees the
    encoder's window, so a relation names which cells were compared, not that nothing else
    entered D. Cells that hold the same thing get the same weight: a head on a kind with several
    cells (rgw's two teleport ends, walls) reads their mean, and the recorded argument (the
    attention's argmax) is the first of them in row-major order. ``--init-from`` may switch an
    agent to "cells": W_K starts afresh, every other weight is copied."""
    init: str = "orthogonal"
    """weight initialisation of the MLP, the value head and PrediNet's read-out: "orthogonal"
    (gain sqrt 2 before ReLUs, 1 for the value and read-out, as in SB3 and CleanRL) or "torch"
    (PyTorch's default, Table 4's network). torch's default shrinks a signal's spread by about
    0.4 per layer, so after the five layers behind the relational module the value varied by
    2.5e-7 across bw1 observations; orthogonal init with the entity norm and attention gain
    gives 3.7e-3 (bench/diagnose.py). The policy head starts at gain 0.01 either way (a near
    uniform first policy)."""

    local_view: int = 0
    """0 (Table 4's network, the default): the actor-critic MLP sees only the relational
    module's output. K (odd): it also sees the one-hot K x K window of cells centred on the
    agent (zeros off the grid), flattened. With single-cell entities (kernel_size 1) a head
    must attend a cell to know what is on it, and the cells agent of issue 11 fell into a pit
    in 37 % of unseen levels (`neurosym eval --checkpoint
    checkpoints/rgw-random-predinet-cells.pt --episodes 100 --seed 3000000000 --sample`): a
    3 x 3 window shows what one step can reach, so the heads are left with what lies beyond.
    Measured (README "Measured", 2026-11-27): with it pits all but vanish and the cells agent
    learns 2-3x faster per frame, its heads still on objects, but it flattens near 70 %
    sampled success on timeouts (routes around walls beyond the window); 5 x 5 alike"""
    agent_plane: int = -1
    """the observation plane marking the agent, which ``local_view`` centres on (RGW 0,
    Box-World's one-hot 1; -1 when local_view is 0)"""

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
        if self.local_view < 0 or (self.local_view and self.local_view % 2 == 0):
            raise ConfigError(
                f"local_view must be 0 (off) or an odd window size such as 3, got {self.local_view}"
            )
        if self.local_view and not 0 <= self.agent_plane < self.obs_shape[0]:
            raise ConfigError(
                f"local_view needs the agent's plane, one of 0..{self.obs_shape[0] - 1}, "
                f"got {self.agent_plane}"
            )

    @property
    def n_entities(self) -> int:
        """Entities the relational module sees: one per grid cell."""
        return self.obs_shape[1] * self.obs_shape[2]

    @property
    def local_size(self) -> int:
        """Features of the window around the agent the MLP sees besides the relations (0: none)."""
        return self.obs_shape[0] * self.local_view**2

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
        if values.get("local_view"):
            if obs_scale != 1.0:
                raise ConfigError(
                    "--local-view reads the agent's plane of a one-hot observation; this env's "
                    "observation is grey or RGB (use obs_mode=onehot)"
                )
            values["agent_plane"] = _agent_plane(family)
        return cls(module=module, obs_shape=obs_shape, obs_scale=obs_scale, **values)

    def to_dict(self) -> dict[str, Any]:
        """Plain values only (lists for tuples), as stored in checkpoints."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ModelConfig:
        """Inverse of :meth:`to_dict`; unknown or missing keys are a ConfigError."""
        return _from_dict(cls, data)


@dataclass(frozen=True)
class TrainConfig:
    """Learner settings (A3C or PPO). ``for_family`` gives a preset's values per env family."""

    algo: str = "a3c"
    """learner: "a3c" (asynchronous workers, the mission's algorithm), "ppo" (synchronous) or
    "imitate" (DAgger from the RGW planner, neurosym/agent/imitation.py)"""
    preset: str = "default"
    """the preset these settings started from ("default", "thesis"), recorded for the reader"""
    optimizer: str = "adam"
    """"adam" (shared statistics) or "rmsprop" (Table 4). Adam's per-weight step is about lr
    whatever the gradient's size; RMSprop with Table 4's epsilon 0.1 divided gradients of
    1e-8..4e-7 (encoder, queries, keys at initialisation) by ~0.3 and left those layers still"""
    lr: float = 1e-3
    """learning rate (Table 4, RMSprop: 2e-3 RGW, 2e-4 BW)"""
    entropy: float = 0.02
    """entropy bonus weight (Table 4: 0.02 RGW, 0.01 BW)"""
    gamma: float = 0.99
    """discount (not in the thesis)"""
    n_steps: int = 40
    """rollout length per update (Table 4 "buffer": 40)"""
    value_coef: float = 0.5
    """weight of the value loss"""
    explore: float = 0.0
    """count-based exploration bonus beta (intrinsic reward beta / sqrt(visits)); 0 = none"""
    explore_half_life: float = 2000.0
    """half-life of the visit counts, in worker steps (K frames each)"""
    sil: float = 0.0
    """weight of the self-imitation loss on the best episodes so far; 0 = none"""
    sil_episodes: int = 32
    """best episodes each worker keeps for self-imitation"""
    rms_eps: float = 1e-5
    """RMSprop epsilon (Table 4: 0.1, which stalls learning here; see the module docstring)"""
    adam_eps: float = 1e-5
    """Adam epsilon"""
    reward_scale: float = 1.0
    """factor on the env's rewards in the training signal (reported returns stay the env's)"""
    normalize_advantages: bool = True
    """scale each update's advantages to zero mean and unit variance: the actor's gradient then
    no longer grows with the rewards' size, and the critic stops drowning it on the shared
    layers (measured 100-200x on a bw1 rollout with one +11 gem)"""
    gae_lambda: float = 0.95
    """GAE lambda for the advantages (1.0 = the n-step returns of Table 4's A3C)"""
    ppo_epochs: int = 4
    """PPO: passes over each rollout"""
    ppo_minibatches: int = 4
    """PPO: minibatches per pass"""
    clip_range: float = 0.2
    """PPO: probability-ratio clip"""
    ppo_advantages: str = "minibatch"
    """PPO, with ``normalize_advantages``: "minibatch" centres and scales each minibatch's
    advantages (SB3, CleanRL); "running" divides each rollout's by a running RMS of the
    advantages seen so far (A3C's :class:`~neurosym.agent.learners.a3c.AdvantageScale`), so that a
    rollout without reward keeps its small advantages small instead of scaled to unit size.
    Measured on bw1 (PrediNet, 64 steps x 2 passes, README "Measured"): per minibatch with
    ``--attention-gain 32`` the policy collapsed below random (0.4 % success); "running" did not
    collapse, but took off later on seed 0 (75 % after 897 k frames against 90 % at 657 k) and
    not at all on seed 1, so the default stays "minibatch". With learned PrediNet queries
    (ModelConfig.query) it is what kept seed 0 from the same collapse (0.2 % after 1.29 M
    frames per minibatch; 90 % at 652 k with "running"), and that pair is the fastest PPO on
    bw1 measured here (README "Measured"; not the default, since bw2/bw3 are unmeasured)
    """
    rms_alpha: float = 0.99
    """RMSprop decay (Table 4: 0.99), no momentum"""
    grad_clip: float = 0.5
    """global gradient-norm clip (Table 4: 400, which never bites; 0.5 as in common A2C/PPO code
    keeps one rollout with a rare large reward from throwing the shared weights far)"""
    workers: int = 2
    """worker processes W"""
    envs: int = 8
    """environments per worker K (1 = classic A3C with one env)"""
    seed: int = 0
    """base seed; worker w uses seed + 1000 * w"""
    critic_warmup: int = 0
    """A3C: frames (all workers) at the start of a run in which only the value head learns (its
    loss alone; every other weight and the policy stay as they are). For fine-tuning a policy
    whose critic never learned (``--init-from`` an imitation agent: the deep rgw-random DAgger
    agent's values explain 1-4 % of its returns' variance, bench/critic_fit.py), whose first
    advantages are noise"""
    planner_coef: float = 0.0
    """A3C on RGW: weight of the planner's imitation loss (``-log`` of the probability the policy
    gives the env planner's optimal actions, on every state the rollout visits) beside the
    actor-critic loss; 0 = none. Kickstarting (Schmitt et al. 2018) with the exact planner as
    teacher: A3C fine-tuning of a DAgger agent finished more levels but lost the undiscounted
    optimum (decoy enemy's +1 left, shortcuts), which the planner's labels keep asking for"""
    dagger_beta_frames: int = 200_000
    """imitate: frames over which the chance of following the planner falls from 1 to 0"""
    dagger_buffer: int = 204_800
    """imitate: labelled states kept (the latest)"""
    dagger_batch: int = 512
    """imitate: states per gradient step"""
    dagger_steps: int = 8
    """imitate: gradient steps per rollout of envs x n_steps states"""
    safe_coef: float = 0.0
    """imitate: weight of a second set loss beside the planner's fastest actions, whose set is
    every action that gives no return up (:meth:`rgw_solver.Plan.regret` 0); 0 = none. It is 0
    wherever no action loses return, so its weight falls only on the states where an episode
    can miss its optimum (a mountain a free route avoids, the enemy met unarmed). On the
    shipped MHDPA's sampled play a quarter of the states are such states, and its set loss
    there (0.21) was twice the rest's (0.11): ``bench/regret_profile.py``"""
    augment: bool = False
    """imitate: fit each minibatch turned by a random quarter turn or mirrored
    (neurosym/agent/augment.py; RGW's rules and its planner are symmetric). Without it the
    Table 4 PrediNet memorised its labelled states (95 % optimal on them after 15 k
    minibatches) and stayed at 83 % on levels it never saw"""

    def __post_init__(self) -> None:
        if self.augment and self.algo != "imitate":
            raise ConfigError(
                f"--augment turns the planner's labelled states; it needs --algo imitate, "
                f"not {self.algo}"
            )
        for name, allowed in (
            ("algo", ALGOS),
            ("optimizer", OPTIMIZERS),
            ("ppo_advantages", PPO_ADVANTAGES),
        ):
            if getattr(self, name) not in allowed:
                raise ConfigError(
                    f"unknown {name} {getattr(self, name)!r}; expected one of {', '.join(allowed)}"
                )
        for name in (
            "lr",
            "gamma",
            "rms_eps",
            "adam_eps",
            "rms_alpha",
            "grad_clip",
            "explore_half_life",
            "reward_scale",
            "clip_range",
        ):
            if not float(getattr(self, name)) > 0:
                raise ConfigError(f"{name} must be positive, got {getattr(self, name)}")
        if not 0 < self.gamma <= 1 or not 0 < self.rms_alpha < 1:
            raise ConfigError("gamma must be in (0, 1] and rms_alpha in (0, 1)")
        if not 0 <= self.gae_lambda <= 1:
            raise ConfigError(f"gae_lambda must be in [0, 1], got {self.gae_lambda}")
        if self.critic_warmup < 0:
            raise ConfigError(f"critic_warmup must be >= 0 frames, got {self.critic_warmup}")
        if self.critic_warmup and self.algo != "a3c":
            raise ConfigError(
                f"--critic-warmup is an A3C setting; --algo {self.algo} does not use it"
            )
        if self.planner_coef < 0:
            raise ConfigError(f"planner_coef must be >= 0, got {self.planner_coef}")
        if self.planner_coef and self.algo != "a3c":
            raise ConfigError(
                f"--planner-coef is an A3C setting; --algo {self.algo} does not use it"
                + (" (DAgger learns from the planner alone)" if self.algo == "imitate" else "")
            )
        if self.safe_coef < 0:
            raise ConfigError(f"safe_coef must be >= 0, got {self.safe_coef}")
        if self.safe_coef and self.algo != "imitate":
            raise ConfigError(
                f"--safe-coef weighs DAgger's labels; it needs --algo imitate, not {self.algo}"
            )
        if self.entropy < 0 or self.value_coef < 0 or self.explore < 0 or self.sil < 0:
            raise ConfigError("entropy, value_coef, explore and sil must be >= 0")
        if self.dagger_beta_frames < 0:
            raise ConfigError(f"dagger_beta_frames must be >= 0, got {self.dagger_beta_frames}")
        for name in ("n_steps", "workers", "envs", "sil_episodes", "ppo_epochs", "ppo_minibatches",
                     "dagger_buffer", "dagger_batch", "dagger_steps"):  # fmt: skip
            if int(getattr(self, name)) < 1:
                raise ConfigError(f"{name} must be a positive integer, got {getattr(self, name)}")

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
            if algo == "ppo":  # no exploration aids: PPO is the plain comparison point
                base = {**base, "explore": 0.0, "sil": 0.0, **_PPO_TRAIN}
            elif algo == "imitate":
                base = {**base, **_IMITATE_TRAIN}
        values = {
            **base,
            "preset": preset,
            "algo": algo,
            **{k: v for k, v in overrides.items() if v is not None},
        }
        return cls(**values)

    def replace(self, **changes: Any) -> TrainConfig:
        """A copy with the changes that are not None."""
        return replace(self, **{k: v for k, v in changes.items() if v is not None})

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrainConfig:
        return _from_dict(cls, data)


def _from_dict(cls: Any, data: dict[str, Any]) -> Any:
    if not isinstance(data, dict):
        raise ConfigError(f"{cls.__name__} must be a dict, got {type(data).__name__}")
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ConfigError(f"unknown {cls.__name__} keys: {', '.join(unknown)}")
    legacy = {k: v for k, v in _LEGACY.get(cls.__name__, {}).items() if k not in data}
    try:
        return cls(**legacy, **data)
    except TypeError as exc:
        raise ConfigError(f"bad {cls.__name__}: {exc}") from None
