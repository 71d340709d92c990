"""Stable-Baselines3 models (PPO, A2C, DQN with a discrete action space) as neurosym agents.

A model's ``.zip`` is read without running anything in it. ``BaseAlgorithm.load`` unpickles
(cloudpickle) the spaces, schedules and policy class stored in the file, which runs whatever
the file says; neurosym reads instead:

* ``data``, the JSON of the model's attributes (at most :data:`DATA_BYTES`): the policy class
  and ``policy_kwargs`` are the only pickled entries used, and they are read by an unpickler
  that only looks names up in :data:`ALLOWED` and refuses every opcode that would call
  anything (so no object is ever constructed from the file); the spaces are the env's own,
  checked against the shapes the file records;
* ``policy.pth``, the weights, with ``torch.load(weights_only=True)``; every size in
  ``policy_kwargs`` must fit them before the policy is built.

A model whose policy_kwargs name a class of the user's (a custom features extractor) cannot
be read so: the user loads it in their own Python file (``PPO.load``, their own code) and
passes it to :func:`sb3_agent`, named on the command line as ``FILE.py:FUNCTION``.
"""

from __future__ import annotations

import base64
import binascii
import io
import json
import pickle
import pickletools
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import torch

from neurosym.errors import CheckpointError, ConfigError
from neurosym.outside.agent import OutsideAgent, TorchAgent, observation_shape

DATA_BYTES = 16 * 1024 * 1024
"""the largest ``data`` entry read (a model's is a few KB)"""
WEIGHTS_BYTES = 4 * 1024**3
"""the largest ``policy.pth`` read"""

ALLOWED: dict[str, frozenset[str]] = {
    "stable_baselines3.common.policies": frozenset(
        {"ActorCriticPolicy", "ActorCriticCnnPolicy", "MultiInputActorCriticPolicy"}
    ),
    "stable_baselines3.dqn.policies": frozenset({"DQNPolicy", "CnnPolicy", "MultiInputPolicy"}),
    "stable_baselines3.common.torch_layers": frozenset(
        {"FlattenExtractor", "NatureCNN", "CombinedExtractor"}
    ),
    "torch.nn.modules.activation": frozenset(
        {"ReLU", "Tanh", "ELU", "LeakyReLU", "GELU", "SiLU", "Sigmoid", "Mish"}
    ),
    "torch.optim.adam": frozenset({"Adam"}),
    "torch.optim.adamw": frozenset({"AdamW"}),
    "torch.optim.rmsprop": frozenset({"RMSprop"}),
    "torch.optim.sgd": frozenset({"SGD"}),
}
"""(module, name) a model file may name in its policy class and policy_kwargs"""

_CALLS = frozenset({"REDUCE", "NEWOBJ", "NEWOBJ_EX", "BUILD", "INST", "OBJ", "EXT1", "EXT2",
                    "EXT4", "PERSID", "BINPERSID"})  # fmt: skip
"""pickle opcodes that call or build objects: none may occur in an entry neurosym reads"""


def is_sb3_zip(path: Path) -> bool:
    """Whether ``path`` is a zip file holding an SB3 model's ``data`` and ``policy.pth``."""
    try:
        with zipfile.ZipFile(path) as z:
            names = set(z.namelist())
    except (OSError, zipfile.BadZipFile):
        return False
    return {"data", "policy.pth"} <= names


class _NamesOnly(pickle.Unpickler):
    """Looks up only the names of :data:`ALLOWED` (nothing else is ever imported)."""

    def __init__(self, data: bytes, where: str) -> None:
        super().__init__(io.BytesIO(data))
        self.where = where

    def find_class(self, module: str, name: str) -> Any:
        if name not in ALLOWED.get(module, ()):
            raise CheckpointError(
                f"{self.where} names {module}.{name}, which neurosym does not load from a file "
                "(only SB3's own policies and feature extractors, torch activations and "
                "optimisers); load the model in your own Python file and name it with "
                "--checkpoint FILE.py:FUNCTION (neurosym.outside.sb3_agent)"
            )
        import importlib

        return getattr(importlib.import_module(module), name)


def _unpickle_entry(entry: dict[str, Any], where: str) -> Any:
    """The value of a pickled ``data`` entry, read by :class:`_NamesOnly` with no calls."""
    try:
        raw = base64.b64decode(str(entry[":serialized:"]).encode(), validate=True)
        ops = {op.name for op, _arg, _pos in pickletools.genops(raw)}
    except (binascii.Error, ValueError) as exc:
        raise CheckpointError(f"{where} is damaged: {exc}") from None
    calls = sorted(ops & _CALLS)
    if calls:
        raise CheckpointError(
            f"{where} builds objects when unpickled ({', '.join(calls)}); neurosym reads only "
            "names, numbers, strings, lists and dicts from a model file"
        )
    try:
        return _NamesOnly(raw, where).load()
    except (pickle.UnpicklingError, EOFError, ValueError, TypeError) as exc:
        raise CheckpointError(f"{where} is damaged: {exc}") from None


def read_model_zip(path: Path) -> tuple[dict[str, Any], dict[str, torch.Tensor]]:
    """The ``data`` JSON and the policy's weights of an SB3 model file (nothing in it run)."""
    try:
        with zipfile.ZipFile(path) as z:
            infos = {i.filename: i for i in z.infolist()}
            for name, limit in (("data", DATA_BYTES), ("policy.pth", WEIGHTS_BYTES)):
                if name not in infos:
                    raise CheckpointError(
                        f"{path} is not a Stable-Baselines3 model: it has no {name!r}"
                    )
                if infos[name].file_size > limit:
                    raise CheckpointError(
                        f"{path}: its {name!r} is {infos[name].file_size:,} bytes, more than {limit:,}"
                    )
            text = z.read("data")
            weights = z.read("policy.pth")
    except (OSError, zipfile.BadZipFile) as exc:
        raise CheckpointError(f"cannot read {path}: {exc}") from None
    try:
        data = json.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CheckpointError(f"{path}: its 'data' is not JSON ({exc})") from None
    try:
        state = torch.load(io.BytesIO(weights), map_location="cpu", weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, ValueError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CheckpointError(
            f"{path}: its policy.pth is not a plain state dict ({first})"
        ) from None
    if (
        not isinstance(data, dict)
        or not isinstance(state, dict)
        or not all(isinstance(v, torch.Tensor) for v in state.values())
    ):
        raise CheckpointError(
            f"{path} is not a Stable-Baselines3 model (unexpected 'data' or weights)"
        )
    return data, state


def _policy_parts(
    path: Path, data: dict[str, Any], state: dict[str, torch.Tensor]
) -> tuple[type, dict]:
    """(policy class, policy kwargs) of a model file, checked against its weights."""
    entry = data.get("policy_class")
    if not isinstance(entry, dict) or ":serialized:" not in entry:
        raise CheckpointError(f"{path} is not a Stable-Baselines3 model: no policy_class")
    policy_class = _unpickle_entry(entry, f"{path}'s policy_class")
    if not isinstance(policy_class, type):
        raise CheckpointError(f"{path}'s policy_class is not a class")
    kwargs = data.get("policy_kwargs") or {}
    if isinstance(kwargs, dict) and ":serialized:" in kwargs:
        kwargs = _unpickle_entry(kwargs, f"{path}'s policy_kwargs")
    if not isinstance(kwargs, dict) or not all(isinstance(k, str) for k in kwargs):
        raise CheckpointError(f"{path}'s policy_kwargs is not a dict of named options")
    largest = max((max(t.shape, default=1) for t in state.values()), default=0)
    for value in _ints(kwargs):
        if value > largest or value < 0:
            raise CheckpointError(
                f"{path}'s policy_kwargs hold the size {value}, larger than any dimension of its "
                f"weights ({largest})"
            )
    return policy_class, kwargs


def _ints(value: Any, depth: int = 0) -> list[int]:
    """Every int in nested lists, tuples and dicts (sizes), at most 20 levels deep."""
    if depth > 20:
        raise CheckpointError("policy_kwargs nest more than 20 levels")
    if isinstance(value, bool):
        return []
    if isinstance(value, int):
        return [value]
    if isinstance(value, dict):
        value = list(value.values())
    if isinstance(value, list | tuple):
        return [i for v in value for i in _ints(v, depth + 1)]
    return []


def _spaces(
    path: Path, data: dict[str, Any], env: str, env_kwargs: dict[str, Any]
) -> tuple[Any, Any, bool]:
    """(observation space, action space, transpose) for the policy, from the env's own spaces.

    ``transpose``: the model was trained on channel-first images of the env's channel-last
    observations (SB3's VecTransposeImage), so observations are transposed before it sees them.
    """
    from gymnasium import spaces

    from neurosym.envs import make

    probe = make(env, **env_kwargs)
    try:
        obs_space, act_space = probe.observation_space, probe.action_space
    finally:
        probe.close()
    saved = data.get("observation_space") if isinstance(data.get("observation_space"), dict) else {}
    shape = tuple(saved.get("_shape") or ())
    mine = tuple(int(v) for v in obs_space.shape)
    transpose = False
    if len(mine) == 3 and shape == (mine[2], mine[0], mine[1]) and shape != mine:
        transpose = True
        obs_space = spaces.Box(
            np.transpose(obs_space.low, (2, 0, 1)), np.transpose(obs_space.high, (2, 0, 1)),
            dtype=obs_space.dtype,
        )  # fmt: skip
    elif shape != mine:
        raise ConfigError(
            f"{path} was trained on observations {shape or 'of unknown shape'}; {env} gives {mine}: "
            "name the env it was trained on with --env"
        )
    saved_dtype = str(saved.get("dtype", obs_space.dtype))
    if saved_dtype != str(obs_space.dtype):
        raise ConfigError(
            f"{path} was trained on {saved_dtype} observations; {env} gives {obs_space.dtype}"
        )
    saved_n = (
        (data.get("action_space") or {}).get("n")
        if isinstance(data.get("action_space"), dict)
        else None
    )
    if not isinstance(act_space, spaces.Discrete) or str(saved_n) != str(int(act_space.n)):
        raise ConfigError(
            f"{path} was trained with {saved_n or 'non-discrete'} actions; {env} has {act_space}"
        )
    return obs_space, act_space, transpose


def load_sb3_zip(
    path: str | Path, env: str | None = None, env_kwargs: dict[str, Any] | None = None
) -> OutsideAgent:
    """The SB3 model file at ``path`` as an agent on ``env`` (default: the first neurosym env
    whose observations have the model's shape). Nothing in the file is run."""
    _require_sb3()
    path = Path(path)
    data, state = read_model_zip(path)
    policy_class, kwargs = _policy_parts(path, data, state)
    env = env or _env_of_shape(path, data)
    obs_space, act_space, transpose = _spaces(path, data, env, dict(env_kwargs or {}))
    try:
        policy = policy_class(obs_space, act_space, lambda _progress: 0.0, **kwargs)
    except (TypeError, ValueError, AssertionError) as exc:
        raise CheckpointError(f"{path}: its policy cannot be built here ({exc})") from None
    try:
        policy.load_state_dict(state, strict=True)
    except RuntimeError as exc:
        line = " ".join(str(exc).splitlines()[1:2]) or str(exc).splitlines()[0]
        raise CheckpointError(
            f"{path}: the weights do not fit its policy ({line.strip()})"
        ) from None
    algo = _algorithm(data)
    meta = {
        "frames": _count(data.get("num_timesteps")),
        "episodes": 0,
        "command": f"stable-baselines3 {algo} ({policy_class.__name__})",
        "metrics": {},
        "train_config": {"algo": f"stable-baselines3 {algo}"},
    }
    return sb3_agent(policy, env, env_kwargs=env_kwargs, meta=meta, transpose=transpose)


def _algorithm(data: dict[str, Any]) -> str:
    """PPO, A2C or DQN, from the attributes only that algorithm saves."""
    if "exploration_rate" in data:
        return "DQN"
    return "PPO" if "clip_range" in data else "A2C"


def _count(value: Any) -> int:
    return value if isinstance(value, int) and not isinstance(value, bool) and value >= 0 else 0


def _env_of_shape(path: Path, data: dict[str, Any]) -> str:
    """The first neurosym env whose observations have the model's shape (either channel order)."""
    from neurosym.envs import ENVS

    saved = data.get("observation_space") if isinstance(data.get("observation_space"), dict) else {}
    shape = tuple(saved.get("_shape") or ())
    for name in ENVS:
        try:
            mine, _ = observation_shape(name)
        except Exception:  # noqa: BLE001 (an env that cannot be made here is no candidate)
            continue
        if shape == mine or (len(mine) == 3 and shape == (mine[2], mine[0], mine[1])):
            return name
    raise ConfigError(
        f"{path} was trained on observations {shape}; no neurosym env gives that shape: name "
        "the env with --env"
    )


def _require_sb3() -> None:
    try:
        import stable_baselines3  # noqa: F401
    except ImportError:
        raise ConfigError(
            "reading a Stable-Baselines3 model needs stable-baselines3: pip install 'neurosym[sb3]'"
        ) from None


def sb3_agent(
    model: Any,
    env: str,
    *,
    attention: str | None = None,
    env_kwargs: dict[str, Any] | None = None,
    meta: dict[str, Any] | None = None,
    transpose: bool | None = None,
) -> OutsideAgent:
    """An SB3 algorithm (``PPO.load(...)``) or its policy as a neurosym agent on ``env``.

    ``attention``: the dotted name, inside the policy, of an attention layer over the grid's
    cells (``"features_extractor.attn"``), for attention/6 facts and head ablation.
    ``transpose``: feed channel-last observations channel-first (default: when the policy's
    observation shape is the env's transposed, as SB3's VecTransposeImage makes it).
    """
    _require_sb3()
    from stable_baselines3.common.policies import ActorCriticPolicy
    from stable_baselines3.dqn.policies import DQNPolicy

    policy = getattr(model, "policy", model)
    if not isinstance(policy, ActorCriticPolicy | DQNPolicy):
        raise ConfigError(
            f"sb3_agent takes a PPO, A2C or DQN model or its policy, got {type(policy).__name__}"
        )
    policy = policy.to("cpu").eval()
    if transpose is None:
        mine, _ = observation_shape(env, env_kwargs)
        theirs = tuple(policy.observation_space.shape)
        transpose = len(mine) == 3 and theirs == (mine[2], mine[0], mine[1]) and theirs != mine
    act = _dqn_act if isinstance(policy, DQNPolicy) else _actor_critic_act
    if transpose:
        inner = act

        def act(net: Any, obs: torch.Tensor) -> Any:
            return inner(net, obs.permute(0, 3, 1, 2))

    return TorchAgent(policy, env, act=act, attention=attention, env_kwargs=env_kwargs,
                      meta=meta or {"train_config": {"algo": "stable-baselines3"}})  # fmt: skip


def _actor_critic_act(policy: Any, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """PPO/A2C: the policy's action logits and value (its own forward, without sampling)."""
    features = policy.extract_features(obs)
    if policy.share_features_extractor:
        latent_pi, latent_vf = policy.mlp_extractor(features)
    else:
        pi_features, vf_features = features
        latent_pi = policy.mlp_extractor.forward_actor(pi_features)
        latent_vf = policy.mlp_extractor.forward_critic(vf_features)
    return policy.action_net(latent_pi), policy.value_net(latent_vf)


def _dqn_act(policy: Any, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """DQN: the Q-values as logits (greedy play takes the best), their maximum as the value."""
    q = policy.q_net(obs)
    return q, q.max(dim=-1).values
