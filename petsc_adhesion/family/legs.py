"""The force a cantilever measures against its base position: a branch F(lambda) behind a spring, read as an
approach and a retract (the construction fitting/forward.py applies to a traced curve, and the family table
to an interpolated one; one code for both).

Behind a spring of stiffness K the base sits at Z = lambda + F / K (units of
epsilon; F in 2 pi R gamma).  Where dZ/ds > 0 along the branch the state is
stable behind the spring; each run of such points is a *piece* on which F is a
function of Z.  A piece ends at a turning point of Z (a :class:`Turn`): a
jump_in where Z is largest (the approach leaves the piece there), a jump_off
where it is smallest (the retract leaves it there); the jump is vertical in F at
constant Z and lands on the piece holding the state it lands on (given), else on
the next piece in its direction that holds its Z.  So:

- the approach follows the first piece (the far branch, continued beyond the
  branch's start by the rigid sphere's load, eq. 28, matched to the branch there)
  up to its jump_in, jumps to the piece it lands on, follows that up to its own
  jump_in, and so on to the last piece (the contact, continued linearly past
  the branch's end);
- the retract follows the last piece down to its jump_off, jumps to the piece it
  lands on, and so on back to the far branch.

On each piece, Z(lambda) and F(lambda) are cubic splines through the branch's
points in lambda (which grows on a piece), with the turning point's own values
at a folded end and its slopes there, dZ/dlambda = 0 and dF/dlambda = -K; F(Z)
is read off a table of 8 evaluations between two points.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.reference.rigid import rigid_load

__all__ = ["Piece", "Turn", "Legs", "APPROACH", "RETRACT", "spring_legs"]

APPROACH, RETRACT = "approach", "retract"
#: Table entries per interval between two points of the branch.
_SUBDIVIDE = 8


@dataclass(frozen=True)
class Turn:
    """A turning point of Z = lambda + F / K: its ``lam`` and ``F``, and ``landing_lam``, the lambda of the state
    its jump lands on (None: not known; the next piece holding its Z is taken)."""

    lam: float
    F: float
    landing_lam: float | None = None

    def Z(self, K: float) -> float:
        return self.lam + self.F / K


@dataclass
class Piece:
    """One stable piece: a table of lambda, Z (non-decreasing) and F; ``start_to``/``end_to``: the index of the
    piece the jump from its start (a jump_off) or end (a jump_in) lands on, None where the piece does not end
    in a turning point (the branch's start or end)."""

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


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The maximal runs [i0, i1] of True in ``mask``."""
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1).tolist(), (np.flatnonzero(edges == -1) - 1).tolist()))


class Legs:
    """F(Z) on the approach and the retract of a branch behind a spring (see the module); everything in the
    model's units.

    ``lam``, ``F``: the branch's points in its order; ``stable``: dZ/ds > 0 at each; ``K``: the spring;
    ``jump_in``, ``jump_off``: its turning points (:class:`Turn`).  ``predict(Z, leg)`` the force on the
    approach or the retract; ``assign(Z, leg)`` the piece each Z is on there, and ``evaluate(Z, pieces)`` the
    force on given pieces (clamped at a turning point, continued past the branch's ends): a prediction whose
    jumps stay where they were, for derivatives.
    """

    def __init__(self, lam, F, stable, K: float, jump_in: list[Turn], jump_off: list[Turn]):
        lam, F = np.asarray(lam, dtype=float), np.asarray(F, dtype=float)
        stable = np.asarray(stable, dtype=bool)
        self.K = float(K)
        Z = lam + F / self.K
        self.notes: list[str] = []
        turns = {"jump_in": list(jump_in), "jump_off": list(jump_off)}
        used: dict[str, set[int]] = {"jump_in": set(), "jump_off": set()}
        raw = []
        for i0, i1 in _runs(stable):
            pl, pz, pf = lam[i0:i1 + 1], Z[i0:i1 + 1], F[i0:i1 + 1]
            start = self._match(turns["jump_off"], used["jump_off"], pl[0], pz[0]) if i0 > 0 else None
            end = self._match(turns["jump_in"], used["jump_in"], pl[-1], pz[-1]) if i1 < lam.size - 1 else None
            if start is not None:
                pl, pz, pf = np.r_[start.lam, pl], np.r_[start.Z(self.K), pz], np.r_[start.F, pf]
            if end is not None:
                pl, pz, pf = np.r_[pl, end.lam], np.r_[pz, end.Z(self.K)], np.r_[pf, end.F]
            raw.append((pl, pz, pf, start, end))
        if not raw:
            raise ValueError("the branch has no state stable behind the spring")
        self.pieces = [self._piece(*r) for r in raw]
        for kind, ts in turns.items():
            left = len(ts) - len(used[kind])
            if left:
                self.notes.append(f"{left} {kind} inside one step of the curve left out (a hysteresis loop "
                                  f"narrower than a step)")
        for i, (_, _, _, start, end) in enumerate(raw):
            p = self.pieces[i]
            if start is not None:
                p.start_to = self._landing(start, i, -1)
            if end is not None:
                p.end_to = self._landing(end, i, +1)
        first = self.pieces[0]
        self._lam0, self._F0 = float(first.lam[0]), float(first.F[0])
        rigid0 = float(rigid_load(self._lam0))
        self._far_factor = self._F0 / rigid0 if rigid0 < 0 and self._F0 < 0 else 1.0
        self.chains = {APPROACH: self._chain(0, "end_to", +1), RETRACT: self._chain(len(self.pieces) - 1, "start_to", -1)}

    # -- construction ---------------------------------------------------------------
    def _match(self, turns: list[Turn], used: set, lam: float, Z: float) -> Turn | None:
        """The turning point (of ``turns``, not yet used) nearest to the end (lam, Z) of a run."""
        free = [i for i in range(len(turns)) if i not in used]
        if not free:
            return None
        best = min(free, key=lambda i: abs(turns[i].lam - lam) + abs(turns[i].Z(self.K) - Z))
        used.add(best)
        return turns[best]

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

    def _landing(self, turn: Turn, i: int, step: int) -> int | None:
        """The piece the jump of ``turn`` at an end of piece ``i`` lands on: the one holding its landing, else
        the next piece in the jump's direction that holds its Z."""
        Zf = turn.Z(self.K)
        others = range(i + step, len(self.pieces) if step > 0 else -1, step)
        if turn.landing_lam is not None:
            for j in others:
                p = self.pieces[j]
                span = max(p.lam[-1] - p.lam[0], 1.0)
                if p.lam[0] - 1e-6 * span <= turn.landing_lam <= p.lam[-1] + 1e-6 * span:
                    return j
        for j in others:
            p = self.pieces[j]
            if p.Z_lo <= Zf <= p.Z_hi or (step > 0 and j == len(self.pieces) - 1 and Zf >= p.Z_lo) or \
                    (step < 0 and j == 0 and Zf <= p.Z_hi):
                return j
        self.notes.append(f"the jump at Z = {Zf:.6g} lands on no traced piece; the piece before it is continued")
        return None

    def _chain(self, first: int, link: str, step: int) -> tuple[list[int], np.ndarray]:
        """The pieces a leg follows and the Z at which it leaves each (increasing on the approach, decreasing on
        the retract)."""
        chain, p = [first], first
        cuts: list[float] = []
        while getattr(self.pieces[p], link) is not None and len(chain) <= len(self.pieces):
            nxt = getattr(self.pieces[p], link)
            cut = self.pieces[p].Z_hi if step > 0 else self.pieces[p].Z_lo
            if nxt in chain or (cuts and (cut - cuts[-1]) * step <= 0):
                break
            chain.append(nxt)
            cuts.append(cut)
            p = nxt
        return chain, np.array(cuts, dtype=float)

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
            if j == last and not p.end_fold and p.Z.size > 1:
                above = z > p.Z_hi
                if above.any():
                    i = max(p.Z.size - 1 - _SUBDIVIDE, 0)
                    slope = (p.F[-1] - p.F[i]) / max(p.Z[-1] - p.Z[i], 1e-300)
                    f[above] = p.F[-1] + slope * (z[above] - p.Z_hi)
            out[sel] = f
        return out

    def _far(self, Z: np.ndarray) -> np.ndarray:
        """The far branch below the branch's start: the rigid sphere's load (eq. 28) times its ratio to the
        branch's at the start, at the lambda of Z = lambda + F / K (bisection: Z <= lambda <= lambda_0)."""
        lo, hi = np.minimum(Z, self._lam0 - 1e-12), np.full_like(Z, self._lam0)

        def load(lam):
            return self._far_factor * rigid_load(lam)

        for _ in range(60):
            mid = 0.5 * (lo + hi)
            above = mid + load(mid) / self.K > Z
            hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
        return load(0.5 * (lo + hi))


def spring_legs(t: np.ndarray, lam: np.ndarray, F: np.ndarray, K: float) -> Legs:
    """The legs behind a spring of stiffness ``K`` of a branch given at the increasing coordinate ``t`` (any
    parameter monotone along it) by ``lam`` and ``F``: Z = lambda + F / K and its rate in t from cubic splines
    in t, the turning points of Z where that rate changes sign (the roots of the spline's derivative), their
    jumps landing on the next piece that holds their Z."""
    from scipy.interpolate import CubicSpline

    t, lam, F = (np.asarray(a, dtype=float) for a in (t, lam, F))
    Z = CubicSpline(t, lam + F / K)
    dZ = Z.derivative()
    rate = dZ(t)
    roots = np.asarray(dZ.roots(extrapolate=False), dtype=float)
    # a root where the rate changes sign is a turning point: a maximum of Z (jump_in) or a minimum (jump_off)
    curv = Z.derivative(2)(roots)
    roots, curv = roots[curv != 0], curv[curv != 0]
    ls, fs = CubicSpline(t, lam), CubicSpline(t, F)
    jump_in = [Turn(float(ls(r)), float(fs(r))) for r in roots[curv < 0]]
    jump_off = [Turn(float(ls(r)), float(fs(r))) for r in roots[curv > 0]]
    return Legs(lam, F, rate > 0, K, jump_in, jump_off)
