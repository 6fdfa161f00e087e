"""The force a cantilever measures against its base position: the traced curve behind a spring, read as an
approach and a retract.

Behind a spring of stiffness K the base sits at Z = lambda + F / K (units of
epsilon; F in 2 pi R gamma).  Where dZ/ds > 0 along the traced curve the state is
stable behind the spring (``stable_spring``); each run of such points is a
*piece* on which F is a function of Z.  A piece ends at a turning point of Z: a
jump_in where Z is largest (the approach leaves the piece there), a jump_off
where it is smallest (the retract leaves it there); the jump is vertical in F at
constant Z and lands on the piece the library found its landing on.  So:

- the approach follows the first piece (the far branch, continued beyond the
  curve's start by the rigid sphere's load, eq. 28, matched to the curve there)
  up to its jump_in, jumps to the piece it lands on, follows that up to its own
  jump_in, and so on to the last piece (the contact, continued linearly past
  the curve's end);
- the retract follows the last piece down to its jump_off, jumps to the piece it
  lands on, and so on back to the far branch.

On each piece, Z(lambda) and F(lambda) are cubic splines through the traced
points in lambda (which grows on a piece), with the turning point's own values
at a folded end and its slopes there, dZ/dlambda = 0 and dF/dlambda = -K; F(Z)
is read off a table of 8 evaluations between two traced points.

The pieces, the pieces their jumps land on and the chains of pieces each leg
follows are the instrument's legs' own (:mod:`petsc_adhesion.tracing.legs`: one
implementation); this module adds F(Z) between the traced points and beyond the
curve's ends, for a fit's residuals at the measured Z.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.reference.rigid import rigid_load
from ..tracing.legs import APPROACH, RETRACT, chain, event_value, landing_piece, stable_pieces

__all__ = ["Piece", "ForwardCurve", "APPROACH", "RETRACT", "curve_stop_reason", "curve_jumps",
           "event_value",
           "pull_off_values"]

#: Table entries per interval between two traced points.
_SUBDIVIDE = 8


@dataclass
class Piece:
    """One stable piece: a table of lambda, Z (non-decreasing) and F; ``start_to``/``end_to``: the index of the
    piece the jump from its start (a jump_off) or end (a jump_in) lands on, None where the piece does not end
    in a turning point (the curve's start or end)."""

    lam: np.ndarray
    Z: np.ndarray
    F: np.ndarray
    start_to: int | None = None
    end_to: int | None = None
    start_fold: bool = False
    end_fold: bool = False

    @property
    def Z_lo(self) -> float:
        return float(self.Z[0])

    @property
    def Z_hi(self) -> float:
        return float(self.Z[-1])


def _spline(x: np.ndarray, y: np.ndarray, left: float | None, right: float | None):
    """A cubic spline through (x, y) with the slopes ``left``/``right`` at the ends where given."""
    from scipy.interpolate import CubicSpline

    if x.size < 3:
        return lambda t: np.interp(t, x, y)
    bc: tuple = ((1, left) if left is not None else "not-a-knot", (1, right) if right is not None else "not-a-knot")
    if x.size == 3 and "not-a-knot" in bc:
        bc = tuple((2, 0.0) if b == "not-a-knot" else b for b in bc)
    return CubicSpline(x, y, bc_type=bc)


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


def _value(e, key: str, K: float | None = None) -> float:
    """An event's value on its grid (its best value when it has none): lam, F, or Z = lam + F / K."""
    return event_value(e, key, K)


class ForwardCurve:
    """F(Z) on the approach and the retract of a traced :class:`~petsc_adhesion.tracing.curve.Curve` behind a
    spring (see the module); everything in the model's units.

    ``predict(Z, leg)`` the force on the approach or the retract; ``assign(Z, leg)`` the piece each Z is on
    there, and ``evaluate(Z, pieces)`` the force on given pieces (clamped at a turning point, continued past
    the curve's ends): a prediction whose jumps stay where they were, for derivatives.
    """

    def __init__(self, curve, K: float):
        self.K = float(K)
        shared, notes = stable_pieces(curve.branch, curve_jumps(curve, "jump_in") + curve_jumps(curve, "jump_off"),
                                      self.K)
        self.notes: list[str] = list(notes)
        self.pieces = [self._piece(p.lam, p.Z, p.F, p.start, p.end) for p in shared]
        for i, p in enumerate(shared):
            if p.start is not None:
                self.pieces[i].start_to = self._landing(p.start, i, -1)
            if p.end is not None:
                self.pieces[i].end_to = self._landing(p.end, i, +1)
        first = self.pieces[0]
        self._lam0, self._F0 = float(first.lam[0]), float(first.F[0])
        rigid0 = float(rigid_load(self._lam0))
        self._far_factor = self._F0 / rigid0 if rigid0 < 0 and self._F0 < 0 else 1.0
        self.chains = {APPROACH: chain(self.pieces, [p.end_to for p in self.pieces], 0, +1),
                       RETRACT: chain(self.pieces, [p.start_to for p in self.pieces], len(self.pieces) - 1, -1)}

    # -- construction ---------------------------------------------------------------
    def _piece(self, lam, Z, F, start, end) -> Piece:
        order = np.argsort(lam, kind="stable")
        lam, Z, F = lam[order], Z[order], F[order]
        # points of two grids at one state (a regrid) and the like: keep lambda strictly increasing, and a
        # turning point rather than a point next to it
        gaps = np.diff(lam)
        least = max(1e-3 * float(np.median(gaps)) if gaps.size else 0.0, 1e-12)
        kept = [0]
        for i in range(1, lam.size):
            if lam[i] - lam[kept[-1]] > least:
                kept.append(i)
            elif end is not None and i == lam.size - 1 and len(kept) > 1:
                kept[-1] = i
        lam, Z, F = lam[kept], Z[kept], F[kept]
        if lam.size == 1:
            return Piece(lam, Z, F, start_fold=start is not None, end_fold=end is not None)
        zs = _spline(lam, Z, 0.0 if start is not None else None, 0.0 if end is not None else None)
        fs = _spline(lam, F, -self.K if start is not None else None, -self.K if end is not None else None)
        t = np.linspace(0.0, 1.0, _SUBDIVIDE + 1)[:-1]
        dense = np.r_[(lam[:-1, None] + np.diff(lam)[:, None] * t[None, :]).ravel(), lam[-1]]
        Zd, Fd = np.asarray(zs(dense), dtype=float), np.asarray(fs(dense), dtype=float)
        if start is not None:
            Zd[0] = Z[0]
        Zd = np.maximum.accumulate(Zd)                 # no overshoot of the spline about a turning point
        return Piece(dense, Zd, Fd, start_fold=start is not None, end_fold=end is not None)

    def _landing(self, event, i: int, step: int) -> int | None:
        """The piece the jump of ``event`` at an end of piece ``i`` lands on (:func:`landing_piece`), None with
        a note where none holds it (the piece before it is then continued)."""
        j = landing_piece(self.pieces, i, event, step, self.K)
        if j is None:
            self.notes.append(f"the jump at Z = {_value(event, 'Z', self.K):.6g} lands on no traced piece; the "
                              f"piece before it is continued")
        return j

    # -- predictions ----------------------------------------------------------------
    @property
    def jumps(self) -> dict:
        """The turning points the legs jump at: {approach: [Z, ...], retract: [Z, ...]}."""
        return {leg: list(cuts) for leg, (chain, cuts) in self.chains.items()}

    def steep(self, leg: str) -> float:
        """The width in Z, next to the first turning point of ``leg``, of the part of the branch before it that
        is steeper than the spring (|dF/dZ| > K, where dF/dlambda < -K/2): there the force goes as the square
        root of the distance to the turning point (0 when the leg has no jump)."""
        chain, cuts = self.chains[leg]
        if not cuts.size:
            return 0.0
        p = self.pieces[chain[0]]
        if p.lam.size < 3:
            return 0.0
        slope = np.gradient(p.F, p.lam)
        gentle = np.flatnonzero(slope >= -0.5 * self.K)
        if leg == APPROACH:
            return float(p.Z_hi - p.Z[gentle[-1]]) if gentle.size else float(p.Z_hi - p.Z_lo)
        return float(p.Z[gentle[0]] - p.Z_lo) if gentle.size else float(p.Z_hi - p.Z_lo)

    def assign(self, Z: np.ndarray, leg: str) -> np.ndarray:
        """The index of the piece each base position ``Z`` is on along ``leg`` (approach or retract)."""
        chain, cuts = self.chains[leg]
        Z = np.asarray(Z, dtype=float)
        k = np.searchsorted(cuts, Z, side="left") if leg == APPROACH else \
            np.searchsorted(-cuts, -Z, side="right")
        return np.asarray(chain)[k]

    def predict(self, Z: np.ndarray, leg: str) -> np.ndarray:
        """The force along ``leg`` at the base positions ``Z``."""
        return self.evaluate(Z, self.assign(Z, leg))

    def evaluate(self, Z: np.ndarray, pieces: np.ndarray) -> np.ndarray:
        """The force at ``Z`` on the given ``pieces`` (indices): clamped at a turning point, the far branch
        continued below the curve's start, the last piece continued linearly past the curve's end."""
        Z = np.asarray(Z, dtype=float)
        out = np.empty_like(Z)
        last = len(self.pieces) - 1
        for j in np.unique(pieces):
            sel = pieces == j
            p, z = self.pieces[j], Z[sel]
            f = np.interp(z, p.Z, p.F)
            if j == 0:
                below = z < p.Z_lo
                if below.any():
                    f[below] = self._far(z[below])
            if j == last and not p.end_fold and p.Z.size > 1:
                above = z > p.Z_hi
                if above.any():
                    i = max(p.Z.size - 1 - _SUBDIVIDE, 0)
                    slope = (p.F[-1] - p.F[i]) / max(p.Z[-1] - p.Z[i], 1e-300)
                    f[above] = p.F[-1] + slope * (z[above] - p.Z_hi)
            out[sel] = f
        return out

    def _far(self, Z: np.ndarray) -> np.ndarray:
        """The far branch below the curve's start: the rigid sphere's load (eq. 28) times its ratio to the
        curve's at the start, at the lambda of Z = lambda + F / K (bisection: Z <= lambda <= lambda_0)."""
        lo, hi = np.minimum(Z, self._lam0 - 1e-12), np.full_like(Z, self._lam0)

        def load(lam):
            return self._far_factor * rigid_load(lam)

        for _ in range(60):
            mid = 0.5 * (lo + hi)
            above = mid + load(mid) / self.K > Z
            hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
        return load(0.5 * (lo + hi))
