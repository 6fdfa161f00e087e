"""The force a cantilever measures against its base position: the traced curve behind a spring, read as an
approach and a retract.

The construction (stable pieces between the turning points of Z = lambda + F / K,
jumps vertical in F at constant Z: :mod:`petsc_adhesion.tracing.legs`, the
instrument's legs' own; F(Z) between the points by splines, the far branch
continued by the rigid sphere's load, eq. 28: :class:`~petsc_adhesion.family.legs.Legs`,
shared with the family table's interpolated curves) is not repeated here; a traced
:class:`~petsc_adhesion.tracing.curve.Curve` is read into it: its branch's points,
its stability behind the spring, and its jump_in and jump_off events (their values
on their grid, and the state the library found each jump lands on).
"""
from __future__ import annotations

from ..family.legs import APPROACH, RETRACT, Legs, Piece
from ..tracing.legs import turn_of

__all__ = ["Piece", "ForwardCurve", "APPROACH", "RETRACT", "curve_stop_reason", "curve_jumps", "pull_off_values"]


# -- what fitting/ reads of a traced Curve: these functions alone ---------------------------------------------
def curve_stop_reason(curve) -> str:
    """Why the traced curve ended."""
    return str(curve.diagnostics.stop_reason)


def curve_jumps(curve, kind: str) -> list:
    """The events of ``kind`` (jump_in or jump_off) of a curve traced behind a spring."""
    return [e for e in curve.events if e.kind == kind]


def pull_off_values(e) -> tuple[float, float | None, float]:
    """A pull-off event's (best F, its bar or None, F on its grid)."""
    F = e.F                             # a Measured
    return float(F.value), (None if F.err is None else float(F.err)), \
        float(F.grid if F.grid is not None else F.value)


class ForwardCurve(Legs):
    """F(Z) on the approach and the retract of a traced :class:`~petsc_adhesion.tracing.curve.Curve` behind a
    spring of stiffness ``K`` (:class:`~petsc_adhesion.family.legs.Legs`); everything in the model's units."""

    def __init__(self, curve, K: float):
        b = curve.branch
        super().__init__(b.lam, b.F, b.stable_spring, K, [turn_of(e) for e in curve_jumps(curve, "jump_in")],
                         [turn_of(e) for e in curve_jumps(curve, "jump_off")])
