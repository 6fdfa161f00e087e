"""The force a cantilever measures against its base position: the traced curve behind a spring, read as an
approach and a retract.

The construction (stable pieces between the turning points of Z = lambda + F / K,
jumps vertical in F at constant Z, the far branch continued by the rigid sphere's
load, eq. 28) is :class:`~petsc_adhesion.family.legs.Legs`, shared with the family
table's interpolated curves; here a traced
:class:`~petsc_adhesion.tracing.curve.Curve` is read into it: its branch's points,
its stability behind the spring, and its jump_in and jump_off events (their values
on their grid, and where the library found each jump lands).
"""
from __future__ import annotations

import numpy as np

from ..family.legs import APPROACH, RETRACT, Legs, Piece, Turn

__all__ = ["Piece", "ForwardCurve", "APPROACH", "RETRACT", "curve_branch", "curve_stop_reason", "curve_jumps",
           "event_landing", "event_value", "pull_off_values"]


# -- what fitting/ reads of a traced Curve: these functions alone ---------------------------------------------
def curve_branch(curve) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(lambda, Z, F, stable behind the spring) at every computed point of a curve traced behind a spring."""
    b = curve.branch
    lam, Z, F = (np.asarray(a, dtype=float) for a in (b.lam, b.Z, b.F))
    return lam, Z, F, np.asarray(b.stable_spring, dtype=bool)


def curve_stop_reason(curve) -> str:
    """Why the traced curve ended."""
    return str(curve.diagnostics.stop_reason)


def curve_jumps(curve, kind: str) -> list:
    """The events of ``kind`` (jump_in or jump_off) of a curve traced behind a spring."""
    return [e for e in curve.events if e.kind == kind]


def event_landing(e):
    """The state a jump lands on (an event), None where the library found none."""
    return getattr(e, "landing", None)


def event_value(e, key: str) -> float:
    """An event's ``key`` (lam or F) on its grid (its best value when it has none)."""
    m = getattr(e, key)                 # a Measured
    return float(m.grid if m.grid is not None else m.value)


def pull_off_values(e) -> tuple[float, float | None, float]:
    """A pull-off event's (best F, its bar or None, F on its grid)."""
    F = e.F                             # a Measured
    return float(F.value), (None if F.err is None else float(F.err)), \
        float(F.grid if F.grid is not None else F.value)


def _turn(e) -> Turn:
    """A jump_in or jump_off event as the turning point the legs read: its lambda and F on its grid, and the
    lambda of its landing where the library found one."""
    land = event_landing(e)
    return Turn(event_value(e, "lam"), event_value(e, "F"), None if land is None else event_value(land, "lam"))


class ForwardCurve(Legs):
    """F(Z) on the approach and the retract of a traced :class:`~petsc_adhesion.tracing.curve.Curve` behind a
    spring of stiffness ``K`` (:class:`~petsc_adhesion.family.legs.Legs`); everything in the model's units."""

    def __init__(self, curve, K: float):
        lam, _, F, stable = curve_branch(curve)
        super().__init__(lam, F, stable, K, [_turn(e) for e in curve_jumps(curve, "jump_in")],
                         [_turn(e) for e in curve_jumps(curve, "jump_off")])
