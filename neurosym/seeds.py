"""The range of ``--seed``: episode k of a run plays seed S + k, and every one must fit in 63 bits.

Seeds are stored with the episodes they played (a recording's ``seed``
column, Parquet and Prolog integers are signed 64-bit), and the envs seed
numpy and torch generators that take at most 64 bits; a larger seed wrapped
round to a negative number in a recording or crashed with an OverflowError.
"""

from __future__ import annotations

from neurosym.errors import ConfigError

MAX_SEED = 2**63 - 1
"""the largest seed an episode may play"""


def check_seed(seed: object, episodes: int = 1, name: str = "--seed") -> int:
    """``seed`` when it and the seeds of the episodes after it (``seed + episodes - 1``) are in range.

    Otherwise a one-line ConfigError stating the valid range for this many episodes.
    """
    last = MAX_SEED - max(int(episodes), 1) + 1
    if last < 0:
        raise ConfigError(
            f"--episodes must be at most 2**63 (one seed each, at most 2**63 - 1), got {episodes}"
        )
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= last:
        many = f" with {episodes} episodes" if episodes > 1 else ""
        raise ConfigError(
            f"{name} must be an integer from 0 to {last}{many} (episode k plays seed "
            f"{name.lstrip('-').upper()} + k, at most 2**63 - 1), got {seed!r}"
        )
    return seed
