"""Checkpoints: save atomically, read safely, build the model they hold.

The trained agent made from one is :class:`neurosym.agent.agent.Agent`.

A checkpoint is a dict of tensors and plain values (docs/design.md "Checkpoints"):

=================== ==========================================================
``format``          ``"neurosym-checkpoint"``
``format_version``  1
``model_config``    ``ModelConfig.to_dict()``
``train_config``    ``TrainConfig.to_dict()``
``env``             short env name (``rgw2``), ``env_kwargs`` its keyword args
``state_dict``      the model's tensors
``optimizer``       RMSprop state (``None`` in slim checkpoints)
``frames``          training frames (env steps) so far; ``episodes`` likewise
``metrics``         plain summary values (last metrics row, stop reason, ...)
``version``         neurosym version; ``torch_version``; ``created`` (ISO time)
``command``         the command line that made it (`` && ``-joined: every command
                    that made it, in order, for a curriculum or a compacted file)
``weights_dtype``   ``"float16"`` / ``"bfloat16"`` in a compacted checkpoint
                    (:func:`compact_checkpoint`); absent: float32
=================== ==========================================================

Weights of any floating dtype load into the float32 model (``load_state_dict``
copies with a cast), so a compacted checkpoint plays, extracts, resumes and
seeds a curriculum like any other, and older neurosym versions read it too.

It is always read with ``torch.load(weights_only=True)``, so a pickled object
(a malicious ``__reduce__``) is refused without running it. Every way a file
can be wrong (missing, truncated, foreign, for another env family or
observation shape, another model config) is one line of
:class:`~neurosym.errors.CheckpointError`.

A checkpoint runs on any environment of its family whose observations have
its shape (docs/design.md): an agent trained on rgw-random plays rgw1, rgw2 or a
user's map, and the other way round (:func:`neurosym.agent.agent.env_for`).
"""

from __future__ import annotations

import datetime as _dt
import io
import os
import pickle
import shlex
from dataclasses import replace
from pathlib import Path
from typing import Any

import torch

from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.networks.model import ActorCritic
from neurosym.atomic import make_folder, write_bytes_atomic
from neurosym.errors import CheckpointError, ConfigError
from neurosym.shipped import checkpoint_file

CARRIED_OPTIONS = ("obs_mode",)
"""env options a checkpoint brings to another env of its family: they decide the observation"""

FORMAT = "neurosym-checkpoint"
FORMAT_VERSION = 1

COMPACT_DTYPES = {"float16": torch.float16, "bfloat16": torch.bfloat16}
"""storage dtypes :func:`compact_checkpoint` offers (float16 keeps 3 more mantissa bits)"""

_PLAIN = (str, int, float, bool, type(None))


def _one_line(text: object) -> str:
    lines = [ln.strip() for ln in str(text).strip().splitlines() if ln.strip()]
    return lines[0] if lines else type(text).__name__


def _check_plain(value: Any, where: str) -> None:
    """Refuse anything but tensors, plain scalars, lists and str-keyed dicts (saving side)."""
    if isinstance(value, (torch.Tensor, *_PLAIN)):
        return
    if isinstance(value, list | tuple):
        for i, v in enumerate(value):
            _check_plain(v, f"{where}[{i}]")
        return
    if isinstance(value, dict):
        for k, v in value.items():
            if not isinstance(k, str | int):
                raise ConfigError(f"checkpoint key {where}.{k!r} is not a str or int")
            _check_plain(v, f"{where}.{k}")
        return
    raise ConfigError(
        f"checkpoint value {where} is a {type(value).__name__}; only tensors and plain values"
    )


def save_checkpoint(
    path: str | os.PathLike[str],
    *,
    model: torch.nn.Module,
    config: ModelConfig,
    env_name: str,
    env_kwargs: dict[str, Any] | None = None,
    train_config: TrainConfig | None = None,
    optimizer_state: dict[str, Any] | None = None,
    frames: int = 0,
    episodes: int = 0,
    metrics: dict[str, Any] | None = None,
    command: str = "",
    state_dict: dict[str, torch.Tensor] | None = None,
) -> Path:
    """Write a checkpoint atomically (temp file in the same directory, then os.replace).

    ``state_dict`` overrides ``model.state_dict()`` (the trainer passes the
    snapshot that was evaluated).
    """
    from neurosym import __version__

    path = Path(path)
    weights = state_dict if state_dict is not None else model.state_dict()
    payload: dict[str, Any] = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "model_config": config.to_dict(),
        "train_config": train_config.to_dict() if train_config is not None else None,
        "env": env_name,
        "env_kwargs": dict(env_kwargs or {}),
        "state_dict": {k: v.detach().clone().cpu() for k, v in weights.items()},
        "optimizer": optimizer_state,
        "frames": int(frames),
        "episodes": int(episodes),
        "metrics": dict(metrics or {}),
        "version": __version__,
        "torch_version": torch.__version__.split("+")[0],
        "created": _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
        "command": command,
    }
    return write_payload(path, payload)


def chain_command(history: str | None, step: str) -> str:
    """A checkpoint's ``command``: every command that made it, in order, ``step`` the last."""
    return f"{history} && {step}" if history else step


def write_payload(path: str | os.PathLike[str], payload: dict[str, Any]) -> Path:
    """Check that ``payload`` (a checkpoint's entries) holds only tensors and plain values,
    then write it atomically."""
    path = Path(path)
    _check_plain(payload, "checkpoint")
    make_folder(path.parent)
    # Serialised in memory first: torch reports a failed file write as a
    # RuntimeError, a plain write reports it as the OSError it is.
    buf = io.BytesIO()
    torch.save(payload, buf)
    return write_bytes_atomic(path, buf.getvalue())


def _load_raw(path: Path) -> Any:
    if not path.exists():
        raise CheckpointError(f"checkpoint not found: {path}")
    if not path.is_file():
        raise CheckpointError(f"checkpoint {path} is not a file")
    try:
        with path.open("rb") as fh:
            head = fh.read(4)
    except OSError as exc:
        raise CheckpointError(f"cannot read {path}: {exc.strerror or exc}") from None
    if not head:
        raise CheckpointError(f"cannot read {path}: the file is empty")
    if not (
        head.startswith(b"PK\x03\x04") or head.startswith(b"\x80")
    ):  # torch zip, or a bare pickle
        raise CheckpointError(
            f"cannot read {path}: not a torch checkpoint (neither a torch zip file nor a pickle)"
        )
    try:
        return torch.load(path, map_location="cpu", weights_only=True)
    except pickle.UnpicklingError as exc:
        if "weights only" in str(exc).lower() or "weights_only" in str(exc).lower():
            raise CheckpointError(
                f"refused {path}: it holds pickled Python objects, not only tensors and plain values "
                "(a foreign or unsafe file; nothing in it was run)"
            ) from None
        raise CheckpointError(
            f"cannot read {path}: not a torch checkpoint ({_one_line(exc)})"
        ) from None
    except (
        RuntimeError,
        EOFError,
        OSError,
        ValueError,
        AttributeError,
        ImportError,
        IndexError,
        KeyError,
    ) as exc:
        raise CheckpointError(
            f"cannot read {path}: truncated, corrupt or not a torch checkpoint ({_one_line(exc)})"
        ) from None


def _require(payload: dict[str, Any], path: Path, key: str, kind: type | tuple[type, ...]) -> Any:
    value = payload.get(key)
    if not isinstance(value, kind) or isinstance(value, bool) and kind is int:
        raise CheckpointError(
            f"checkpoint {path} is damaged: {key!r} is missing or has the wrong type"
        )
    return value


def _require_count(payload: dict[str, Any], path: Path, key: str) -> int:
    """A count (``frames``, ``episodes``): an int, not negative."""
    value = _require(payload, path, key, int)
    if value < 0:
        raise CheckpointError(
            f"checkpoint {path} is damaged: {key!r} is {value}; it counts, so it is 0 or more"
        )
    return value


METADATA_NODES = 10_000
"""values (counted at every place they occur) a checkpoint's metadata or a recording's meta
may hold: the shipped agents' hold about 200"""
METADATA_DEPTH = 20
"""lists and dicts in lists and dicts, at most"""
METADATA_CHARS = 1_000_000
"""characters of all its strings and keys together (a curriculum's command is about 1,000)"""

_LEAVES = (str, int, float, bool, type(None))


def check_plain_data(value: Any, where: str, error: type[Exception] = CheckpointError) -> None:
    """Refuse, in one line naming ``where``, anything but plain data of bounded size.

    Plain data: str, int, float, bool, None, lists (tuples) and dicts with str
    keys. Bounded: at most :data:`METADATA_NODES` values, :data:`METADATA_DEPTH`
    levels and :data:`METADATA_CHARS` characters, a value met twice (a pickle
    may share one list everywhere: 40 levels of ``[l, l]`` is 2**40 leaves,
    printed) counting twice. Why: cards, env options and metrics are printed,
    compared and embedded in pages; a few MB that expand to terabytes when
    walked must be refused before anything walks them.
    """
    stack: list[tuple[Any, int]] = [(value, 0)]
    seen = 1  # values visited or waiting on the stack
    chars = 0
    while stack:
        item, depth = stack.pop()
        if depth > METADATA_DEPTH:
            raise error(
                f"{where} is nested more than {METADATA_DEPTH} levels deep (plain metadata)"
            )
        if isinstance(item, str):
            chars += len(item)
        elif isinstance(item, int) and not isinstance(item, bool) and abs(item) >= 1 << 64:
            raise error(f"{where} holds an integer of {item.bit_length()} bits (at most 64)")
        elif isinstance(item, list | tuple | dict):
            seen += len(item)
            if seen > METADATA_NODES:
                raise error(
                    f"{where} is too large: more than {METADATA_NODES:,} values (counting "
                    "every place a shared one occurs; plain metadata holds far fewer)"
                )
            if isinstance(item, dict):
                for k in item:
                    if not isinstance(k, str):
                        raise error(
                            f"{where} has a key of type {type(k).__name__} (plain metadata: str)"
                        )
                    chars += len(k)
            stack.extend(
                (v, depth + 1) for v in (item.values() if isinstance(item, dict) else item)
            )
        elif not isinstance(item, _LEAVES):
            raise error(
                f"{where} holds a value of type {type(item).__name__}; plain metadata holds only str, "
                "int, float, bool, None, lists and dicts"
            )
        if chars > METADATA_CHARS:
            raise error(f"{where} is too large: more than {METADATA_CHARS:,} characters of text")


WEIGHT_KEYS = ("state_dict", "optimizer")
"""checkpoint entries of tensors; every other entry is plain metadata (:func:`check_plain_data`)"""


def _check_metadata(payload: dict[str, Any], path: Path) -> None:
    """Every entry but the weights is plain data of bounded size (one line naming the entry)."""
    for key, value in payload.items():
        if not isinstance(key, str):
            raise CheckpointError(
                f"checkpoint {path} is damaged: it has a key of type "
                f"{type(key).__name__}; a checkpoint's keys are str"
            )
        if key not in WEIGHT_KEYS:
            check_plain_data(value, f"checkpoint {path}: its {key!r}")


def read_checkpoint(
    path: str | os.PathLike[str],
    env: str | None = None,
    config: ModelConfig | dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Read and validate a checkpoint; the payload dict with ``model_config`` as a ModelConfig.

    ``env``: refuse a checkpoint that cannot run there (another family or
    observation shape, see :func:`env_for`). ``config``: refuse one whose
    model config differs (named field by field). A shipped agent's bare name
    (``rgw2-predinet``) reads the shipped file (:func:`neurosym.shipped.checkpoint_file`).
    """
    path = checkpoint_file(path)
    payload = _load_raw(path)
    if not isinstance(payload, dict):
        raise CheckpointError(
            f"{path} is not a neurosym checkpoint (it holds a {type(payload).__name__})"
        )
    if "format" not in payload:
        if payload and all(isinstance(v, torch.Tensor) for v in payload.values()):
            raise CheckpointError(
                f"{path} is a plain torch state dict, not a neurosym checkpoint (make one with `neurosym train`)"
            )
        raise CheckpointError(f"{path} is not a neurosym checkpoint (no 'format' entry)")
    if payload["format"] != FORMAT:
        named = payload["format"]
        named = repr(named) if isinstance(named, str) and len(named) <= 80 else "unknown"
        raise CheckpointError(f"{path} is not a neurosym checkpoint (format {named})")
    _check_metadata(payload, path)
    version = payload.get("format_version")
    if not isinstance(version, int) or version > FORMAT_VERSION or version < 1:
        raise CheckpointError(
            f"{path} has checkpoint format version {version!r}; this neurosym reads version {FORMAT_VERSION}"
        )
    raw_config = _require(payload, path, "model_config", dict)
    env_name = _require(payload, path, "env", str)
    _require(payload, path, "env_kwargs", dict)
    state = _require(payload, path, "state_dict", dict)
    _require_count(payload, path, "frames")
    _require_count(payload, path, "episodes")
    if not all(isinstance(v, torch.Tensor) for v in state.values()):
        raise CheckpointError(
            f"checkpoint {path} is damaged: its state_dict holds values other than tensors"
        )
    try:
        model_config = ModelConfig.from_dict(raw_config)
    except ConfigError as exc:
        raise CheckpointError(f"checkpoint {path} has a bad model config: {exc}") from None
    _check_sizes(path, model_config, state)
    if env is not None:
        check_env_fits(str(path), env_name, model_config.obs_shape, env, env_options(payload, env))
    else:
        _check_own_env(path, env_name, payload["env_kwargs"], model_config.obs_shape)
    if config is not None:
        expected = config if isinstance(config, ModelConfig) else ModelConfig.from_dict(config)
        mine, theirs = model_config.to_dict(), expected.to_dict()
        diffs = [f"{k} {mine[k]!r} (asked for {theirs[k]!r})" for k in mine if mine[k] != theirs[k]]
        if diffs:
            raise CheckpointError(f"{path} has a different model config: {'; '.join(diffs)}")
    payload = dict(payload)
    payload["model_config"] = model_config
    return payload


SIZE_FIELDS = ("conv_channels", "hidden_sizes", "kernel_size", "heads", "key_size",
               "output_size", "n_actions")  # fmt: skip
"""ModelConfig fields that size a layer: none can exceed every dimension of the weights"""

MODULE_SIZE_FIELDS = {"predinet": ("relations",), "mhdpa": ("value_size",)}
"""the same, for the fields only one relational module uses"""


def _check_sizes(path: Path, config: ModelConfig, state: dict[str, torch.Tensor]) -> None:
    """Refuse a model config (an edited file) that would build a network far larger than its weights.

    Every layer size of a config that fits its weights is at most the largest
    dimension of one of them; a larger one would allocate its layers (hundreds
    of GB for a hidden size in the millions) before the weights were found not
    to fit.
    """
    largest = max((max(t.shape, default=1) for t in state.values()), default=0)
    for name in (*SIZE_FIELDS, *MODULE_SIZE_FIELDS.get(config.module, ())):
        value = getattr(config, name)
        for v in value if isinstance(value, tuple) else (value,):
            if int(v) > largest:
                raise CheckpointError(
                    f"checkpoint {path} is damaged: its model config has {name} {value!r}, "
                    f"larger than any dimension of its weights ({largest})"
                )


def _check_own_env(
    path: Path, env: str, env_kwargs: dict[str, Any], shape: tuple[int, ...]
) -> None:
    """Refuse a checkpoint whose env is unknown or gives observations its model cannot take.

    Its options are the ones it was trained with; where they no longer make an
    env (a user's map moved), the check is left to whoever plays it, with the
    user's own options.
    """
    from neurosym.envs import canonical_name, make
    from neurosym.errors import NeurosymError

    try:
        name = canonical_name(env)
    except NeurosymError as exc:
        raise CheckpointError(
            f"checkpoint {path} names an env this neurosym lacks: {exc}"
        ) from None
    try:
        probe = make(name, **env_kwargs)
    except (NeurosymError, TypeError, ValueError):
        return
    try:
        got = tuple(int(v) for v in probe.observation_space.shape)
    finally:
        probe.close()
    if got != tuple(shape):
        raise CheckpointError(
            f"checkpoint {path} is damaged: its env {name} {_options_text(env_kwargs)}gives "
            f"observations {got}, its model takes {tuple(shape)}"
        )


RESTARTED_BY_KEYS = ("relational.key.weight",)
"""Weights a switch of ModelConfig.keys replaces (W_K reads cells instead of entities)."""


def build_model(
    payload: dict[str, Any], path: str | os.PathLike[str], keys: str | None = None
) -> ActorCritic:
    """The model of a validated payload with its weights loaded (strict).

    ``keys``: build it with that ModelConfig.keys instead (``--init-from`` switching an agent's
    attention keys): W_K starts afresh, every other weight is the payload's; from cells to
    cells_xy W_K keeps the cells' columns and the coordinates' start at zero (the same
    attention)."""
    config = payload["model_config"]
    state = payload["state_dict"]
    if keys is not None and keys != config.keys:
        old = config.keys
        config = replace(config, keys=keys)
        fresh = ActorCritic(config).state_dict()
        state = {**state, **{k: fresh[k] for k in RESTARTED_BY_KEYS}}
        if (old, keys) == ("cells", "cells_xy"):
            w = payload["state_dict"]["relational.key.weight"]
            state["relational.key.weight"] = torch.cat([w, torch.zeros(len(w), 2, dtype=w.dtype)], 1)
    try:
        model = ActorCritic(config)
    except (RuntimeError, MemoryError) as exc:  # a config that passed _check_sizes, yet too large
        raise CheckpointError(
            f"{path}: its model config does not fit in memory ({_one_line(exc)})"
        ) from None
    try:
        model.load_state_dict(state, strict=True)
    except RuntimeError as exc:
        msg = " ".join(_one_line(line) for line in str(exc).splitlines()[1:3]) or _one_line(exc)
        raise CheckpointError(f"{path}: the weights do not fit its model config ({msg})") from None
    return model


def compact_checkpoint(
    src: str | os.PathLike[str],
    dst: str | os.PathLike[str],
    dtype: str = "float16",
) -> dict[str, Any]:
    """Write ``src`` to ``dst`` with its floating weights stored in ``dtype`` and no optimizer state.

    Why: a shipped agent is read, never trained on with its old optimizer
    moments, and half precision halves its size (the Box-World PrediNet's
    1.36 M parameters take 5.4 MB in float32). The model still computes in
    float32: the weights are cast back when loaded. Everything else (config,
    env, frames, metrics) is kept but the agent card (its figures are the old weights'); the
    command gets `` && neurosym compact ...``.
    ``dst`` may be ``src``: the file is replaced atomically. Returns the sizes
    in bytes and the largest absolute change of a weight.
    """
    if dtype not in COMPACT_DTYPES:
        raise ConfigError(f"--dtype {dtype!r} is not one of {', '.join(COMPACT_DTYPES)}")
    src, dst = checkpoint_file(src), Path(dst)
    payload = read_checkpoint(src)
    target = COMPACT_DTYPES[dtype]
    state: dict[str, torch.Tensor] = {}
    largest = 0.0
    for key, tensor in payload["state_dict"].items():
        if not tensor.is_floating_point():
            state[key] = tensor
            continue
        stored = tensor.to(target)
        if not bool(torch.isfinite(stored).all()) and bool(torch.isfinite(tensor).all()):
            raise CheckpointError(
                f"{src}: weight {key} overflows {dtype} (largest |w| "
                f"{float(tensor.abs().max()):.3g}); keep float32 or try --dtype bfloat16"
            )
        if tensor.numel():
            largest = max(largest, float((stored.float() - tensor.float()).abs().max()))
        state[key] = stored
    before = src.stat().st_size
    out = dict(payload)
    out["model_config"] = payload["model_config"].to_dict()
    out["state_dict"] = state
    out["optimizer"] = None
    out["weights_dtype"] = dtype
    out.pop("card", None)  # its figures were measured on the weights before
    step = shlex.join(["neurosym", "compact", str(src), "--out", str(dst), "--dtype", dtype])
    out["command"] = chain_command(payload.get("command"), step)
    write_payload(dst, out)
    return {"bytes_before": before, "bytes_after": dst.stat().st_size, "max_change": largest}


def env_options(
    payload: dict[str, Any] | Any, env: str, overrides: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The options to make ``env`` with for this checkpoint (a payload dict or an Agent).

    Its own env: the options it was trained with; another env: only
    CARRIED_OPTIONS of them. ``overrides`` (the user's, e.g. ``map``) win.
    """
    from neurosym.envs import canonical_name

    if isinstance(payload, dict):
        trained, kwargs = payload["env"], payload["env_kwargs"]
    else:  # an Agent, or anything shaped like one
        trained, kwargs = payload.env_name, getattr(payload, "env_kwargs", None)
    kwargs = dict(kwargs or {})
    if canonical_name(env) != canonical_name(trained):
        kwargs = {k: v for k, v in kwargs.items() if k in CARRIED_OPTIONS}
    return {**kwargs, **dict(overrides or {})}


def check_env_fits(
    label: str,
    trained: str,
    obs_shape: tuple[int, ...] | list[int],
    env: str,
    env_kwargs: dict[str, Any],
) -> None:
    """Refuse, in one line naming both, an env of another family or observation shape."""
    from neurosym.envs import canonical_name, env_family, make
    from neurosym.envs.registration import family_members

    name, trained = canonical_name(env), canonical_name(trained)
    family, theirs = env_family(trained), env_family(name)
    shape = tuple(int(v) for v in obs_shape)
    if family != theirs:
        same = family_members(family)
        raise CheckpointError(
            f"{label} was trained on {trained} ({family} family, observations {shape}); "
            f"{name} is a {theirs} environment: pick one of {same}"
        )
    probe = make(name, **env_kwargs)
    try:
        got = tuple(int(v) for v in probe.observation_space.shape)
    finally:
        probe.close()
    if got != shape:
        raise CheckpointError(
            f"{label} was trained on {trained} with observations {shape}; {name} "
            f"{_options_text(env_kwargs)}gives {got}: pick an environment of the same shape"
        )


def _options_text(kwargs: dict[str, Any]) -> str:
    return f"({', '.join(f'{k}={v!r}' for k, v in kwargs.items())}) " if kwargs else ""
