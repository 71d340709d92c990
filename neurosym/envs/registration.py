"""Environment names: short names, gymnasium ids, registration and the two factories.

Every environment is registered with gymnasium under a versioned id with a
string entry point, so nothing is imported until an environment is made (a
missing Box-World module only fails when a Box-World env is made). Each id
also carries a ``vector_entry_point``: the batched class that
:func:`make_batched` (and ``gymnasium.make_vec``) builds.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any

from neurosym.envs.options import OptionType, check_value, load
from neurosym.envs.options import option_types as option_types_of
from neurosym.errors import ConfigError


@dataclass(frozen=True)
class EnvEntry:
    """One registered environment."""

    short: str
    id: str
    family: str
    entry_point: str
    vector_entry_point: str
    description: str
    kwargs: dict[str, Any] = field(default_factory=dict)
    level_options: str = ""
    """``"module:Dataclass"`` whose fields the class takes through ``**kwargs`` (typed options)"""


_RGW = "neurosym.envs.rgw:RGWEnv"
_RGW_VEC = "neurosym.envs.rgw_vector:RGWVectorEnv"
_BW = "neurosym.envs.boxworld:BoxWorldEnv"
_BW_VEC = "neurosym.envs.boxworld:BoxWorldVectorEnv"
_MG = "neurosym.envs.minigrid_env:MinigridEnv"
_MG_VEC = "neurosym.envs.minigrid_env:MinigridVectorEnv"
MINIGRID_PREFIXES = ("MiniGrid-", "BabyAI-")
"""the ids of Farama's Minigrid package: every one is a neurosym env of family ``minigrid``"""

ENTRIES: tuple[EnvEntry, ...] = (
    EnvEntry(
        "rgw1",
        "neurosym/RGW1-v0",
        "rgw",
        _RGW,
        _RGW_VEC,
        "RGW Configuration-1: sword, enemy, teleport, terminal (optimal return 11)",
        {"map": "rgw1"},
    ),
    EnvEntry(
        "rgw2",
        "neurosym/RGW2-v0",
        "rgw",
        _RGW,
        _RGW_VEC,
        "RGW Configuration-2, the original map: adds mountains and pits (optimal 10.7)",
        {"map": "rgw2"},
    ),
    EnvEntry(
        "rgw-random",
        "neurosym/RGWRandom-v0",
        "rgw",
        "neurosym.envs.rgw_random:RGWRandomEnv",
        "neurosym.envs.rgw_vector:RGWRandomVectorEnv",
        "RGW on procedural levels, a new one every episode: blocking enemy; guarded, decoy, "
        "teleport-only and hazard levels, each with its optimal return",
        level_options="neurosym.envs.rgw_random:RandomLevelConfig",
    ),
    EnvEntry(
        "bw1",
        "neurosym/BW1-v0",
        "boxworld",
        _BW,
        _BW_VEC,
        "Box-World Configuration-1: solution length 1, no distractor",
        {"solution_length": 1, "num_distractors": 0, "distractor_length": 1},
    ),
    EnvEntry(
        "bw2",
        "neurosym/BW2-v0",
        "boxworld",
        _BW,
        _BW_VEC,
        "Box-World Configuration-2: solution length 1, one distractor of length 1",
        {"solution_length": 1, "num_distractors": 1, "distractor_length": 1},
    ),
    EnvEntry(
        "bw3",
        "neurosym/BW3-v0",
        "boxworld",
        _BW,
        _BW_VEC,
        "Box-World Configuration-3: solution length 2, no distractor",
        {"solution_length": 2, "num_distractors": 0, "distractor_length": 1},
    ),
    EnvEntry(
        "boxworld",
        "neurosym/BoxWorld-v0",
        "boxworld",
        _BW,
        _BW_VEC,
        "Box-World, free parameters: solution_length, num_distractors, distractor_length",
    ),
)

ENVS: dict[str, str] = {e.short: e.id for e in ENTRIES}
"""short name -> registered gymnasium id"""

_BY_NAME: dict[str, EnvEntry] = {**{e.short: e for e in ENTRIES}, **{e.id: e for e in ENTRIES}}


def register_envs() -> None:
    """Register every neurosym id with gymnasium (idempotent; done on import of neurosym.envs).

    The Minigrid family's ids (``neurosym/MiniGrid-DoorKey-5x5-v0``) are registered
    when one is first named, so that importing neurosym does not import Minigrid.
    """
    for e in ENTRIES:
        _register(e)


def _register(e: EnvEntry) -> None:
    import gymnasium

    if e.id not in gymnasium.registry:
        gymnasium.register(
            id=e.id,
            entry_point=e.entry_point,
            vector_entry_point=e.vector_entry_point,
            kwargs=dict(e.kwargs),
            nondeterministic=False,
        )


MINIGRID_UNSUPPORTED: dict[str, str] = {
    "minigrid.envs:DynamicObstaclesEnv": "its env takes 3 actions (left, right, forward), "
    "not Minigrid's 7",
    "minigrid.envs.wfc": "its env needs Minigrid's wfc extra (imageio, networkx), which neurosym "
    "does not install",
}
"""Minigrid env classes (``module:Class``) or modules left out of the family, and why"""


def _minigrid_class(spec: Any) -> str:
    return str(spec.entry_point).rpartition(":")[2] if isinstance(spec.entry_point, str) else ""


def _unsupported(spec: Any) -> str | None:
    """Why neurosym does not play the env of a Minigrid spec, or None when it does."""
    point = str(spec.entry_point) if isinstance(spec.entry_point, str) else ""
    return MINIGRID_UNSUPPORTED.get(point) or MINIGRID_UNSUPPORTED.get(point.partition(":")[0])


@functools.cache
def minigrid_entries() -> tuple[EnvEntry, ...]:
    """One EnvEntry per id Farama's Minigrid registers (``MiniGrid-*``, ``BabyAI-*``).

    The short name is Minigrid's own id (``--env MiniGrid-DoorKey-5x5-v0``); the
    gymnasium id neurosym registers for it is ``neurosym/`` + that id, whose
    env is :class:`~neurosym.envs.minigrid_env.MinigridEnv` over Minigrid's.
    """
    import gymnasium
    import minigrid  # noqa: F401  (registers its ids with gymnasium)

    out = []
    for name, spec in gymnasium.registry.items():
        if not name.startswith(MINIGRID_PREFIXES):
            continue
        if _unsupported(spec) is not None:
            continue
        cls = _minigrid_class(spec)
        options = ", ".join(f"{k}={v!r}" for k, v in sorted(spec.kwargs.items()))
        package = "BabyAI" if name.startswith("BabyAI-") else "Minigrid"
        description = f"{package} {cls}{f' ({options})' if options else ''}"
        out.append(EnvEntry(name, f"neurosym/{name}", "minigrid", _MG, _MG_VEC, description,
                            {"env_id": name}))  # fmt: skip
    return tuple(out)


def all_entries() -> tuple[EnvEntry, ...]:
    """Every environment: neurosym's own (:data:`ENTRIES`), then the Minigrid family's."""
    return ENTRIES + minigrid_entries()


def entry(name_or_id: str) -> EnvEntry:
    """The EnvEntry of a short name or id, or ConfigError listing the known names."""
    found = _BY_NAME.get(name_or_id)
    if found is not None:
        return found
    name = str(name_or_id).removeprefix("neurosym/")
    if name.startswith(MINIGRID_PREFIXES):
        return _minigrid_entry(name)
    raise ConfigError(
        f"unknown environment {name_or_id!r}; expected one of {', '.join(ENVS)}, "
        f"an id such as {ENVS['rgw2']}, or a Minigrid id such as MiniGrid-DoorKey-5x5-v0"
    )


def _minigrid_entry(name: str) -> EnvEntry:
    """The Minigrid family's entry of an id, or one line naming the nearest ids."""
    import difflib

    import gymnasium

    entries = {e.short: e for e in minigrid_entries()}
    found = entries.get(name)
    if found is not None:
        _register(found)
        return found
    spec = gymnasium.registry.get(name)
    why = _unsupported(spec) if spec is not None else None
    if why is not None:
        raise ConfigError(f"Minigrid environment {name!r} is not one neurosym plays: {why}")
    near = difflib.get_close_matches(name, list(entries), n=3, cutoff=0.75)
    hint = f"did you mean {', '.join(near[:-1]) + ' or ' if near[1:] else ''}{near[-1]}? " if near else ""
    raise ConfigError(
        f"unknown Minigrid environment {name!r}; {hint}`neurosym envs` lists the "
        f"{len(entries)} Minigrid and BabyAI ids"
    )


def canonical_name(name_or_id: str) -> str:
    """The short name (``rgw2``) of a short name or registered id (``neurosym/RGW2-v0``)."""
    return entry(name_or_id).short


def env_family(name_or_id: str) -> str:
    """``"rgw"``, ``"boxworld"`` or ``"minigrid"``."""
    return entry(name_or_id).family


def family_members(family: str) -> str:
    """The envs of a family as error messages name them: ``rgw1, rgw2, rgw-random``, or for
    Minigrid's 166 ids a pointer to ``neurosym envs``."""
    if family == "minigrid":
        return "the MiniGrid-* and BabyAI-* ids (`neurosym envs` lists them)"
    return ", ".join(e.short for e in ENTRIES if e.family == family)


RENDER_ONLY_OPTIONS = ("render_mode", "tile_size")
"""options that change only what ``env.render()`` draws: no command shows it"""


def option_types(name_or_id: str) -> dict[str, OptionType]:
    """name -> :class:`~neurosym.envs.options.OptionType` of every option the env takes."""
    e = entry(name_or_id)
    return dict(_option_types(e.entry_point, e.level_options))


@functools.cache
def _option_types(entry_point: str, level_options: str) -> dict[str, OptionType]:
    return option_types_of(entry_point, level_options)


def _batched_only(e: Any) -> list[str]:
    """Options of the batched class that the single env does not take (such as ``copy``)."""
    import inspect

    params = inspect.signature(load(e.vector_entry_point).__init__).parameters
    apart = ("self", "num_envs", "seed")  # make_batched's own arguments
    single = option_types(e.short)
    return [
        n
        for n, p in params.items()
        if n not in apart and n not in single and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]


def check_options(name_or_id: str, kwargs: dict[str, Any], batched: bool = False) -> None:
    """Refuse, in one line, an option the env's class does not take or a value of the wrong type.

    gymnasium would raise a TypeError deep in its factory instead (or, for a
    render mode the env lacks, warn first); options the class gathers in
    ``**kwargs`` it checks itself (rgw-random names its level parameters). Values
    are checked against the option's annotation: ``classic="false"`` is refused,
    not played as a true value. ``batched``: the batched class's own options
    (such as ``copy``, which :func:`make_batched` passes on) are accepted too.
    """
    import inspect

    e = entry(name_or_id)
    cls = load(e.entry_point)
    params = inspect.signature(cls.__init__).parameters
    types = option_types(name_or_id)
    extra = _batched_only(e) if batched else []
    if not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
        unknown = sorted(set(kwargs) - set(types) - set(extra))
        if unknown:
            raise ConfigError(
                f"unknown option {unknown[0]!r} for {e.short}; "
                f"expected one of {', '.join([*types, *extra])}"
            )
    for key, value in kwargs.items():
        option = types.get(key)
        if option is not None and not check_value(option, value):
            raise ConfigError(
                f"option {key}={value!r} for {e.short}: {key} takes {option.expected()}"
            )
    modes = (getattr(cls, "metadata", None) or {}).get("render_modes")
    mode = kwargs.get("render_mode")
    if mode is not None and modes is not None and mode not in modes:
        raise ConfigError(
            f"render_mode {mode!r} is not one of {e.short}'s: {', '.join(map(str, modes))} or None"
        )


def make(name: str, **kwargs: Any) -> Any:
    """A gymnasium env by short name or id; kwargs override the registered ones."""
    import gymnasium

    e = entry(name)
    check_options(name, kwargs)
    register_envs()
    _register(e)
    return gymnasium.make(e.id, **kwargs)


def make_batched(name: str, n: int, seed: int | None = None, **kwargs: Any) -> Any:
    """A batched env of n copies (gymnasium VectorEnv, next-step autoreset).

    ``seed`` seeds the first ``reset()`` that gets none (sub-env i: seed + i).
    """
    import gymnasium

    e = entry(name)
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ConfigError(f"number of environments must be a positive integer, got {n!r}")
    check_options(name, kwargs, batched=True)
    register_envs()
    _register(e)
    return gymnasium.make_vec(
        e.id, num_envs=n, vectorization_mode="vector_entry_point", seed=seed, **kwargs
    )
