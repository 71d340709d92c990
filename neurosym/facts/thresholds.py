"""Thresholds that turn recorded relation values into ``holds/5`` facts.

A threshold is chosen per relation j from the recorded values of D_j (all heads
together: W_S is shared, so relation j means the same thing in every head). Three
kinds, written as a spec string on the command line:

* ``abs:X``       -- the same X >= 0 for every relation;
* ``quantile:Q``  -- the Q-quantile (0 <= Q <= 1) of |D_j|: ``quantile:0.9`` keeps
  about the strongest tenth of each relation's values;
* ``z:K``         -- mean(|D_j|) + K * std(|D_j|): a z-score of the magnitude.

A value is kept when ``|value| > threshold_j`` (strictly, so that a zero value,
which has no orientation, is never kept). D is antisymmetric, so the kept fact is
oriented by the sign of the value (see :mod:`neurosym.facts.tables`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError

Kind = Literal["abs", "quantile", "z"]

_HELP = "expected abs:X (X >= 0), quantile:Q (0 <= Q <= 1) or z:K, e.g. quantile:0.9"


@dataclass(frozen=True, slots=True)
class Threshold:
    """A threshold rule: its kind and its parameter (see the module docstring)."""

    kind: Kind
    param: float

    def __post_init__(self) -> None:
        if self.kind not in ("abs", "quantile", "z"):
            raise ConfigError(f"unknown threshold kind {self.kind!r}; {_HELP}")
        if not math.isfinite(self.param):
            raise ConfigError(f"threshold {self.kind}:{self.param} is not a finite number; {_HELP}")
        if self.kind == "abs" and self.param < 0:
            raise ConfigError(f"threshold abs:{self.param} is negative; {_HELP}")
        if self.kind == "quantile" and not 0.0 <= self.param <= 1.0:
            raise ConfigError(f"threshold quantile:{self.param} is outside [0, 1]; {_HELP}")

    def __str__(self) -> str:
        return f"{self.kind}:{self.param:g}"

    def per_relation(self, relations: pd.DataFrame) -> pd.Series:
        """Threshold per relation j (index j, sorted) from a table with columns j and value.

        Relations with no recorded value get no threshold (they cannot hold).
        """
        if relations.empty:
            return pd.Series(
                [], index=pd.Index([], dtype="int64", name="j"), dtype="float64", name="threshold"
            )
        mag = relations["value"].abs().groupby(relations["j"], sort=True)
        if self.kind == "abs":
            out = pd.Series(self.param, index=mag.size().index, dtype="float64")
        elif self.kind == "quantile":
            out = mag.quantile(self.param)
        else:
            # ddof=0: the population std of what was recorded, defined for one value too.
            out = mag.mean() + self.param * mag.std(ddof=0)
        out = out.astype("float64")
        out.index = out.index.astype("int64")
        out.index.name = "j"
        out.name = "threshold"
        return out

    def keep(self, relations: pd.DataFrame, per_j: pd.Series | None = None) -> np.ndarray:
        """Boolean mask of the rows of ``relations`` whose |value| exceeds their relation's threshold."""
        if per_j is None:
            per_j = self.per_relation(relations)
        if relations.empty:
            return np.zeros(0, dtype=bool)
        thr = per_j.reindex(relations["j"].to_numpy()).to_numpy()
        return np.abs(relations["value"].to_numpy()) > thr


def parse_threshold(spec: str | float | int | Threshold) -> Threshold:
    """Parse ``abs:X``, ``quantile:Q`` or ``z:K``; a bare number means ``abs``.

    Raises ConfigError with one line naming the bad spec and the accepted forms.
    """
    if isinstance(spec, Threshold):
        return spec
    if isinstance(spec, bool):
        raise ConfigError(f"bad threshold {spec!r}; {_HELP}")
    if isinstance(spec, int | float):
        return Threshold("abs", float(spec))
    if not isinstance(spec, str):
        raise ConfigError(f"bad threshold {spec!r}; {_HELP}")
    text = spec.strip()
    kind, sep, value = text.partition(":")
    kind = kind.strip().lower()
    if not sep or kind not in ("abs", "quantile", "z"):
        raise ConfigError(f"bad threshold {spec!r}; {_HELP}")
    try:
        param = float(value)
    except ValueError:
        raise ConfigError(
            f"bad threshold {spec!r}: {value.strip()!r} is not a number; {_HELP}"
        ) from None
    return Threshold(kind, param)  # type: ignore[arg-type]
