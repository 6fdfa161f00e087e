"""The force a cantilever measures against its base position: a branch F(lambda) behind a spring, read as an
approach and a retract, F(Z) predicted between its points (for fitting/forward.py's traced curves and the
family table's interpolated ones; one code for both).

The stable pieces of the branch, the turning points at their ends (a jump_in where
Z = lambda + F / K is largest, a jump_off where it is smallest), the piece each
jump lands on and the chain of pieces each leg follows are
:mod:`petsc_adhesion.tracing.legs`'s (the instrument's legs are made by the same
code).  What this module adds is the prediction:

- on each piece, Z(lambda) and F(lambda) are cubic splines through the branch's
  points in lambda (which grows on a piece), with the turning point's own values
  at a folded end and its slopes there, dZ/dlambda = 0 and dF/dlambda = -K; F(Z)
  is read off a table of 8 evaluations between two points;
- the far branch is continued beyond the branch's start by the rigid sphere's
  load (eq. 28) matched to the branch there, the contact linearly past its end.
"""
from __future__ import annotations

import numpy as np

from ..model.reference.rigid import rigid_load
from ..tracing.legs import APPROACH, RETRACT, Piece, Turn, chain, landing_piece, stable_pieces

__all__ = ["Piece", "Turn", "Legs", "APPROACH", "RETRACT", "spring_legs"]

#: Table entries per interval between two points of the branch.
_SUBDIVIDE = 8


def _spline(x: np.ndarray, y: np.ndarray, left: float | None, right: float | None):
    """A cubic spline through (x, y) with the slopes ``left``/``right`` at the ends where given."""
    if x.size < 3:
        return lambda t: np.interp(t, x, y)
    if x.size == 3 and (left is None or right is None):
        from scipy.interpolate import CubicSpline

        bc: tuple = ((1, left) if left is not None else (2, 0.0), (1, right) if right is not None else (2, 0.0))
        return CubicSpline(x, y, bc_type=bc)
    return cubic_spline(x, y, left, right)


def cubic_spline(x: np.ndarray, y: np.ndarray, left=None, right=None):
    """scipy's ``CubicSpline(x, y, bc_type)`` through at least 4 points (x increasing), the slope given at an end
    (``left``, ``right``; one a column of ``y`` of shape (n, k)) or not-a-knot there, as the same PPoly to the
    bit: the same tridiagonal system for the slopes at the points, solved by the same LAPACK routine (gtsv, all
    the columns at once: each as alone), and the same Hermite coefficients, without the checks and copies that
    made up most of its cost on the few hundred points of a branch (a fit builds some twenty curves behind a
    spring, each 3 to 8 splines; tests/test_family.py compares them with scipy's).  Fewer points: scipy's own."""
    from scipy.interpolate import CubicSpline, PPoly
    from scipy.linalg.lapack import dgtsv

    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    n = x.size
    if n < 4:
        return CubicSpline(x, y, bc_type=((1, left) if left is not None else "not-a-knot",
                                          (1, right) if right is not None else "not-a-knot"))
    dx = np.diff(x)
    dxr = dx.reshape((n - 1,) + (1,) * (y.ndim - 1))
    slope = np.diff(y, axis=0) / dxr
    # the system's three diagonals and its right side, as CubicSpline fills its banded matrix
    dl, d, du, b = np.empty(n - 1), np.empty(n), np.empty(n - 1), np.empty(y.shape, order="F")
    d[1:-1] = 2 * (dx[:-1] + dx[1:])
    du[1:] = dx[:-1]
    dl[:-1] = dx[1:]
    b[1:-1] = 3 * (dxr[1:] * slope[:-1] + dxr[:-1] * slope[1:])
    if left is None:
        d[0], du[0] = dx[1], x[2] - x[0]
        w = x[2] - x[0]
        b[0] = ((dxr[0] + 2 * w) * dxr[1] * slope[0] + dxr[0] ** 2 * slope[1]) / w
    else:
        d[0], du[0], b[0] = 1.0, 0.0, left
    if right is None:
        d[-1], dl[-1] = dx[-2], x[-1] - x[-3]
        w = x[-1] - x[-3]
        b[-1] = (dxr[-1] ** 2 * slope[-2] + (2 * w + dxr[-1]) * dxr[-2] * slope[-1]) / w
    else:
        d[-1], dl[-1], b[-1] = 1.0, 0.0, right
    *_, s, info = dgtsv(dl, d, du, b, 1, 1, 1, 1)
    if info != 0:
        raise np.linalg.LinAlgError(f"the spline's system is singular (gtsv info {info})")
    t = (s[:-1] + s[1:] - 2 * slope) / dxr
    c = np.empty((4, n - 1) + y.shape[1:])
    c[0] = t / dxr
    c[1] = (slope - s[:-1]) / dxr - t
    c[2] = s[:-1]
    c[3] = y[:-1]
    return PPoly.construct_fast(c, x)


class Legs:
    """F(Z) on the approach and the retract of a branch behind a spring (see the module); everything in the
    model's units.

    ``lam``, ``F``: the branch's points in its order; ``stable``: dZ/ds > 0 at each; ``K``: the spring;
    ``jump_in``, ``jump_off``: its turning points (:class:`~petsc_adhesion.tracing.legs.Turn`).
    ``pieces``: each stable piece as a table of the splines (its ``contact_radius`` NaN: not interpolated);
    ``predict(Z, leg)`` the force on the approach or the retract; ``assign(Z, leg)`` the piece each Z is on
    there, and ``evaluate(Z, pieces)`` the force on given pieces (clamped at a turning point, continued past
    the branch's ends): a prediction whose jumps stay where they were, for derivatives.
    """

    def __init__(self, lam, F, stable, K: float, jump_in: list[Turn], jump_off: list[Turn]):
        self.K = float(K)
        shared, notes = stable_pieces(lam, F, stable, self.K, jump_in, jump_off)
        self.notes: list[str] = list(notes)
        self.pieces = [self._piece(p) for p in shared]
        # the piece the jump from each piece's end (a jump_in) and start (a jump_off) lands on, None: none
        self.start_to: list[int | None] = [None] * len(shared)
        self.end_to: list[int | None] = [None] * len(shared)
        for i, p in enumerate(shared):
            if p.start is not None:
                self.start_to[i] = self._landing(p.start, i, -1)
            if p.end is not None:
                self.end_to[i] = self._landing(p.end, i, +1)
        first = self.pieces[0]
        self._lam0, self._F0 = float(first.lam[0]), float(first.F[0])
        rigid0 = float(rigid_load(self._lam0))
        self._far_factor = self._F0 / rigid0 if rigid0 < 0 and self._F0 < 0 else 1.0
        self.chains = {APPROACH: chain(self.pieces, self.end_to, 0, +1),
                       RETRACT: chain(self.pieces, self.start_to, len(self.pieces) - 1, -1)}

    # -- construction ---------------------------------------------------------------
    def _piece(self, piece: Piece) -> Piece:
        """The table of a stable piece's splines, its turning points kept."""
        start, end = piece.start, piece.end
        order = np.argsort(piece.lam, kind="stable")
        lam, Z, F = piece.lam[order], piece.Z[order], piece.F[order]
        # points of two grids at one state (a regrid) and the like: keep lambda strictly increasing, and a
        # turning point rather than a point next to it
        gaps = np.diff(lam)
        least = max(1e-3 * float(np.median(gaps)) if gaps.size else 0.0, 1e-12)
        if not np.all(gaps > least):              # (where every gap is wider, every point is kept)
            kept = [0]
            for i in range(1, lam.size):
                if lam[i] - lam[kept[-1]] > least:
                    kept.append(i)
                elif end is not None and i == lam.size - 1 and len(kept) > 1:
                    kept[-1] = i
            lam, Z, F = lam[kept], Z[kept], F[kept]
        if lam.size == 1:
            return Piece(lam, Z, F, np.full_like(lam, np.nan), start, end)
        t = np.linspace(0.0, 1.0, _SUBDIVIDE + 1)[:-1]
        dense = np.concatenate(((lam[:-1, None] + np.diff(lam)[:, None] * t[None, :]).ravel(), lam[-1:]))
        if lam.size >= 4:                       # Z and F in one spline of two columns (each as alone)
            both = cubic_spline(lam, np.column_stack((Z, F)), None if start is None else np.array([0.0, -self.K]),
                                None if end is None else np.array([0.0, -self.K]))(dense)
            Zd, Fd = both[:, 0].copy(), both[:, 1].copy()
        else:
            zs = _spline(lam, Z, 0.0 if start is not None else None, 0.0 if end is not None else None)
            fs = _spline(lam, F, -self.K if start is not None else None, -self.K if end is not None else None)
            Zd, Fd = np.asarray(zs(dense), dtype=float), np.asarray(fs(dense), dtype=float)
        if start is not None:
            Zd[0] = Z[0]
        Zd = np.maximum.accumulate(Zd)                 # no overshoot of the spline about a turning point
        return Piece(dense, Zd, Fd, np.full_like(dense, np.nan), start, end)

    def _landing(self, turn: Turn, i: int, step: int) -> int | None:
        """The piece the jump of ``turn`` at an end of piece ``i`` lands on
        (:func:`~petsc_adhesion.tracing.legs.landing_piece`), None with a note where none holds it (the piece
        before it is then continued)."""
        j = landing_piece(self.pieces, i, turn, step, self.K)
        if j is None:
            self.notes.append(f"the jump at Z = {turn.Z(self.K):.6g} lands on no traced piece; the piece before "
                              f"it is continued")
        return j

    # -- predictions ----------------------------------------------------------------
    @property
    def jumps(self) -> dict:
        """The turning points the legs jump at: {approach: [Z, ...], retract: [Z, ...]}."""
        return {leg: list(cuts) for leg, (chain, cuts) in self.chains.items()}

    def jump_forces(self, leg: str) -> list[tuple[float, float]]:
        """(F before, F after) of each jump of ``leg``, in its order: the force at the turning point and on
        the piece it lands on, at the same Z."""
        chain, cuts = self.chains[leg]
        out = []
        for k, z in enumerate(cuts):
            before = self.evaluate(np.array([z]), np.array([chain[k]]))[0]
            after = self.evaluate(np.array([z]), np.array([chain[k + 1]]))[0]
            out.append((float(before), float(after)))
        return out

    def least_force(self, leg: str) -> tuple[float, float]:
        """(Z, F) of the most tensile of the points on the pieces ``leg`` follows (its pull-off on the
        retract)."""
        piece = min((self.pieces[i] for i in self.chains[leg][0]), key=lambda p: float(p.F.min()))
        k = int(np.argmin(piece.F))
        return float(piece.Z[k]), float(piece.F[k])

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
        continued below the branch's start, the last piece continued linearly past the branch's end."""
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
            if j == last and p.end is None and p.Z.size > 1:
                above = z > p.Z_hi
                if above.any():
                    i = max(p.Z.size - 1 - _SUBDIVIDE, 0)
                    slope = (p.F[-1] - p.F[i]) / max(p.Z[-1] - p.Z[i], 1e-300)
                    f[above] = p.F[-1] + slope * (z[above] - p.Z_hi)
            out[sel] = f
        return out

    def _far(self, Z: np.ndarray) -> np.ndarray:
        """The far branch below the branch's start: the rigid sphere's load (eq. 28) times its ratio to the
        branch's at the start, at the lambda of Z = lambda + F / K.  That lambda lies in [Z, lambda_0], where
        Z(lambda) rises (the far branch is stable behind the spring below the branch's start): Newton's method on
        h(lambda) = lambda + F(lambda) / K - Z, with dF/dlambda = (8/3) c ((1 - lambda)^-9 - (1 - lambda)^-3)
        from eq. 28, each step kept inside the bracket where h changes sign (halved where it would leave it), to
        a few units in the last place: the root the bisection this replaced found (to 1e-15 of F), in 3 to 6 steps
        instead of its 60."""
        Z = np.asarray(Z, dtype=float)
        lo, hi = np.minimum(Z, self._lam0 - 1e-12), np.full_like(Z, self._lam0)
        c = self._far_factor / self.K
        x = lo.copy()
        for _ in range(60):
            g = 1.0 - x
            h = x + c * (1.0 - 4.0 * g**6) / (3.0 * g**8) - Z
            above = h > 0
            hi, lo = np.where(above, x, hi), np.where(above, lo, x)
            new = x - h / (1.0 + c * (8.0 / 3.0) * (g**-9 - g**-3))
            new = np.where((new >= lo) & (new <= hi), new, 0.5 * (lo + hi))
            done = np.all(np.abs(new - x) <= 4e-16 * np.maximum(np.abs(x), 1.0))
            x = new
            if done:
                break
        return np.asarray(self._far_factor * rigid_load(x), dtype=float)


def spring_legs(t: np.ndarray, lam: np.ndarray, F: np.ndarray, K: float) -> Legs:
    """The legs behind a spring of stiffness ``K`` of a branch given at the increasing coordinate ``t`` (any
    parameter monotone along it) by ``lam`` and ``F``: Z = lambda + F / K and its rate in t from cubic splines
    in t, the turning points of Z where that rate changes sign (the roots of the spline's derivative), their
    jumps landing on the next piece that holds their Z."""
    from scipy.interpolate import PPoly

    t, lam, F = (np.asarray(a, dtype=float) for a in (t, lam, F))
    if t.size < 4:
        return _spring_legs_few(t, lam, F, K)
    # Z, lambda and F in one spline of three columns (each as alone), Z's own for its derivatives
    splines = cubic_spline(t, np.column_stack((lam + F / K, lam, F)))
    Z = PPoly.construct_fast(np.ascontiguousarray(splines.c[:, :, 0]), splines.x)
    dZ = Z.derivative()
    rate = dZ(t)
    roots = np.asarray(dZ.roots(extrapolate=False), dtype=float)
    # a root where the rate changes sign is a turning point: a maximum of Z (jump_in) or a minimum (jump_off)
    curv = Z.derivative(2)(roots)
    roots, curv = roots[curv != 0], curv[curv != 0]
    at = splines(roots)
    jump_in = [Turn(float(v[1]), float(v[2])) for v in at[curv < 0]]
    jump_off = [Turn(float(v[1]), float(v[2])) for v in at[curv > 0]]
    return Legs(lam, F, rate > 0, K, jump_in, jump_off)


def _spring_legs_few(t: np.ndarray, lam: np.ndarray, F: np.ndarray, K: float) -> Legs:
    """spring_legs of a branch of fewer than 4 points: scipy's splines."""
    from scipy.interpolate import CubicSpline

    Z = CubicSpline(t, lam + F / K)
    dZ = Z.derivative()
    roots = np.asarray(dZ.roots(extrapolate=False), dtype=float)
    curv = Z.derivative(2)(roots)
    roots, curv = roots[curv != 0], curv[curv != 0]
    ls, fs = CubicSpline(t, lam), CubicSpline(t, F)
    return Legs(lam, F, dZ(t) > 0, K, [Turn(float(ls(r)), float(fs(r))) for r in roots[curv < 0]],
                [Turn(float(ls(r)), float(fs(r))) for r in roots[curv > 0]])
