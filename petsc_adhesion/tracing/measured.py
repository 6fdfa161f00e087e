"""A quantity with its error bar, and a quantity a run did not compute: the two values every result is made of.

Learnt from BifurcationKit's ``SpecialPoint`` (a value with its precision and
status): a number with a bar travels as one :class:`Measured`, never as the
keys ``x``, ``x_err`` and ``x_grid`` of a dict; what a run did not compute is a
:class:`Missing` with its reason, never 0 (docs/guarantees.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Measured", "Missing", "value_of"]


@dataclass(frozen=True)
class Measured:
    """``value``: the best estimate (extrapolated over nested grids where a bar was made); ``err``: its error
    bar, None when it has none (``note`` says why); ``grid``: the value on the grid it was located on (None
    where it is not another value, e.g. without an error estimate); ``note``: why there is no bar, or what
    limits it."""

    value: float
    err: float | None = None
    grid: float | None = None
    note: str | None = None

    def __post_init__(self):
        if self.err is not None and not (self.err >= 0 or math.isnan(self.err)):
            raise ValueError(f"an error bar is not negative: got {self.err!r}")

    def __float__(self) -> float:
        return float(self.value)

    @property
    def relative(self) -> float | None:
        """The bar over the value's magnitude (None without a bar, inf at a value of 0 with a bar)."""
        if self.err is None:
            return None
        return self.err / abs(self.value) if self.value else math.inf

    def covers(self, truth: float, times: float = 1.0) -> bool:
        """Whether ``truth`` lies within ``times`` bars of the value (False without a bar)."""
        return self.err is not None and abs(self.value - truth) <= times * self.err


@dataclass(frozen=True)
class Missing:
    """A quantity the run did not compute, and why (e.g. the energy of a cycle that was never closed)."""

    reason: str

    def __bool__(self) -> bool:
        return False


def value_of(q: Measured | Missing | None) -> float | None:
    """The value of a quantity, None where it is missing."""
    return q.value if isinstance(q, Measured) else None
