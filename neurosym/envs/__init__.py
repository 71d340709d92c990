"""Relational-Grid-World, Box-World and (wrapped) Minigrid/BabyAI as gymnasium environments,
single and batched.

    >>> from neurosym.envs import make, make_batched
    >>> env = make("rgw2")                       # or make("neurosym/RGW2-v0", classic=True)
    >>> obs, info = env.reset(seed=0)            # obs (9, 10, 10) uint8, info: symbolic state
    >>> envs = make_batched("rgw2", 1024, seed=0)
    >>> obs, info = envs.reset()                 # obs (1024, 9, 10, 10)

Importing this package registers the gymnasium ids (``neurosym/RGW2-v0``, ...);
the environment modules themselves are imported only when an env is made. A
Minigrid or BabyAI id (``MiniGrid-DoorKey-8x8-v0``) is registered as
``neurosym/<id>`` when it is first named, so importing neurosym does not import
Minigrid.
"""

from neurosym.envs.actions import ACTION_NAMES, Action
from neurosym.envs.registration import (
    ENVS,
    canonical_name,
    check_options,
    env_family,
    make,
    make_batched,
    register_envs,
)

register_envs()

__all__ = [
    "ACTION_NAMES",
    "ENVS",
    "Action",
    "canonical_name",
    "check_options",
    "env_family",
    "make",
    "make_batched",
    "register_envs",
]
