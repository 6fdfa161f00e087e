"""The coordinate along a load-approach curve in which the family is tabulated, and a traced curve sampled on it.

F is no function of lambda (a curve folds: one pair of turning points at mu ~ 1,
many narrow pairs at mu ~ 1000), so each curve is parametrized by a coordinate
that grows along the whole branch, in which lambda and F are smooth functions of
(coordinate, ln mu, sigma).  Greenwood (1997) followed the Lennard-Jones sphere by
its central gap H(0) for this reason; in contact H(0) barely moves, and the
contact radius a does.  The blend

    s = a^2 / 2 - H(0)

(units epsilon) grows with both: out of contact (a = 0) it is -H(0); for a rigid
sphere in contact (H = H(0) + r^2 / 2, a^2 / 2 = level - H(0)) it is level - 2 H(0);
in deep contact it grows as a^2 / 2, like the approach (Hertz: lambda ~ a^2).
Measured on the solver's curves (docs/family.md): along every curve traced it only
falls between two points of one state on two grids (a regrid), by at most 2e-2 at
mu = 1000 (3e-6 of the curve's range of s); the sampling leaves those points out (their corrector is
`regrid`), and along the curves checked no fall is left (docs/family.md).

The curves' ranges of s differ by orders of magnitude (mu = 1000 starts at s = -2005
and ends at s ~ 4800, with its neck forming within 0.005 of s = 0), so the table's
coordinate stretches s about the place the contact forms, s0 = 1/2 - level (0 on a
smooth surface, where level = 1/2 is the contact edge's gap), on a logarithmic scale,

    T(s) = asinh((s - s0) / delta(mu)),    tau = T(s) / |T(s_lo)| below s0,  T(s) / T(s_hi) above,

so every curve spans tau in [-1, 1] from its start s_lo (the library's start,
far out of reach of the forces) to its end s_hi, where F reaches the table's
F_max, with s0 at tau = 0.  Both ends are smooth in (mu, sigma), so at fixed tau
lambda and F are too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..brent import root

__all__ = ["width", "NotMonotone", "Sampled", "EventPoint", "coordinate", "rising", "sample", "stretch", "unstretch",
           "shape_preserving", "overshoot", "PULL_OFF_TOL", "OVERSHOOT_TOL", "EVENT_KINDS"]

#: How far (relative) the cubic spline's most tensile load may lie from the solver's located pull-off before a
#: node is sampled shape-preserving instead (:func:`sample`).  Measured on the default curves at mu = 10^(k/4),
#: 1e-3 to 1: from mu = 0.178 up (39 to 79 points a curve) the spline is within 6e-6 to 4.5e-4 of it at sigma 0
#: to 0.2; below (29 to 40 points) it misses by 1e-3 to 1.7e-2 smooth, up to 0.47 at sigma 0.2 and 26 times the
#: pull-off at sigma 3 (docs/family.md).
PULL_OFF_TOL = 1e-3
#: The events of a curve a shape-preserving sampling takes as points of it: where lambda (snap-on, -off) or F
#: (F_min, F_max) turns, its rate along the curve is 0, which the interpolant's zero slope at a discrete extremum
#: then states exactly; F = 0 (equilibrium) is one more point located on the curve.
EVENT_KINDS = ("snap_on", "snap_off", "F_min", "F_max", "equilibrium")



def width(mu: float) -> float:
    """delta: the width in s about s0 inside which tau is nearly linear in s, 1 / (2 (1 + mu)): the scale on
    which the contact forms, ~0.3 at mu = 1 (no traced point within 0.1 of s0 there) and 5e-4 at mu = 1000
    (its neck forms within 5e-3 of s0); smooth in mu, so tau is."""
    return 0.5 / (1.0 + mu)


def coordinate(H0: np.ndarray, a: np.ndarray) -> np.ndarray:
    """s = a^2 / 2 - H(0) at each point (module docstring)."""
    return 0.5 * np.asarray(a, dtype=float) ** 2 - np.asarray(H0, dtype=float)



def rising(s: np.ndarray) -> tuple[np.ndarray, float]:
    """(the indices of the points of ``s`` that rise along the curve, the largest fall of a point left out, as a
    share of s's range).  A point of another grid at the state just before (a regrid), a hair before or behind
    the last kept one, is left out; a fall larger than a hair says the coordinate is not monotone there."""
    span = float(s.max() - s.min()) if s.size else 0.0
    gaps = np.diff(s)
    least = 1e-3 * float(np.median(gaps[gaps > 0])) if (gaps > 0).any() else 0.0
    kept, fall = [0], 0.0
    for i in range(1, s.size):
        if s[i] > s[kept[-1]] + least:
            kept.append(i)
        else:
            fall = max(fall, float(s[kept[-1]] - s[i]))
    return np.asarray(kept, dtype=int), (fall / span if span > 0 else 0.0)

def stretch(s, s0: float, s_lo: float, s_hi: float, delta: float):
    """tau of s (module docstring): -1 at s_lo, 0 at s0, 1 at s_hi."""
    T = np.arcsinh((np.asarray(s, dtype=float) - s0) / delta)
    return np.where(T < 0, T / abs(math.asinh((s_lo - s0) / delta)), T / math.asinh((s_hi - s0) / delta))


def unstretch(tau, s0: float, s_lo: float, s_hi: float, delta: float):
    """s of tau: the inverse of :func:`stretch`."""
    tau = np.asarray(tau, dtype=float)
    T = np.where(tau < 0, tau * abs(math.asinh((s_lo - s0) / delta)), tau * math.asinh((s_hi - s0) / delta))
    return s0 + delta * np.sinh(T)


def shape_preserving(t: np.ndarray, y: np.ndarray):
    """A C1 piecewise cubic through (t, y) that keeps the data's shape: the not-a-knot cubic spline's slopes,
    each limited where the data are monotone on both sides of a point to [0, 3 min(|m_left|, |m_right|)] times
    their sign (Hyman's filter, 1983: with both ends of an interval so limited, its cubic is monotone, by Fritsch
    and Carlson's condition), 0 at a discrete extremum (where the rate turns: with the located turning points
    among the points, exactly), and at an end within [0, 3 |m|] of its interval's secant.  Where the spline's
    slopes already satisfy the bounds (dense, smooth data) they are kept, and with them the spline's fourth
    order; where they do not (sparse points about a sharp bend), the interpolant stays within each interval's
    ends instead of swinging past them."""
    from scipy.interpolate import CubicHermiteSpline, CubicSpline

    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    d = np.asarray(CubicSpline(t, y)(t, 1), dtype=float)
    m = np.diff(y) / np.diff(t)
    left, right = m[:-1], m[1:]
    same = left * right > 0
    bound = 3.0 * np.minimum(np.abs(left), np.abs(right))
    sign = np.sign(left)
    d[1:-1] = np.where(same, sign * np.minimum(np.maximum(sign * d[1:-1], 0.0), bound), 0.0)
    for k, mk in ((0, m[0]), (-1, m[-1])):
        d[k] = np.sign(mk) * min(max(np.sign(mk) * d[k], 0.0), 3.0 * abs(mk)) if mk != 0 else 0.0
    return CubicHermiteSpline(t, y, d)


def overshoot(t: np.ndarray, y: np.ndarray, curve) -> float:
    """The largest distance ``curve`` (an interpolant of (t, y)) goes beyond the ends of an interval on which the
    data do not turn (neither end a discrete extremum), as a share of y's range: an interpolant's own swing."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    m = np.diff(y)
    turns = np.r_[False, m[:-1] * m[1:] <= 0, False]
    worst = 0.0
    for r in np.asarray(curve.derivative().roots(extrapolate=False), dtype=float):
        i = min(int(np.searchsorted(t, r, side="right")) - 1, t.size - 2)
        if i < 0 or turns[i] or turns[i + 1] or not t[i] < r < t[i + 1]:
            continue
        v = float(curve(r))
        worst = max(worst, min(y[i], y[i + 1]) - v, v - max(y[i], y[i + 1]))
    span = float(np.ptp(y))
    return worst / span if span > 0 else 0.0


class EventPoint(NamedTuple):
    """A point the solver located on a traced curve (an event: its ``kind``, ``lam``, ``F``, the central gap
    ``H0`` and the contact radius ``a``, on the grid it was located on)."""

    kind: str
    lam: float
    F: float
    H0: float
    a: float


@dataclass(frozen=True)
class Sampled:
    """A traced curve on the table's nodes ``tau``: ``lam`` and ``F`` there, the ends ``s_lo``, ``s_hi`` and the
    centre ``s0`` of its coordinate, and ``fall``, the largest fall of s between successive points left out
    (a regrid's two grids at one state); ``shape``: why it was sampled shape-preserving (None: by the cubic
    splines)."""

    lam: np.ndarray
    F: np.ndarray
    s_lo: float
    s_hi: float
    s0: float
    fall: float
    shape: str | None = None


class NotMonotone(ValueError):
    """A curve along which s falls by more than a regrid's difference: it cannot be tabulated in s."""


#: The swing of a spline past an interval's ends, as a share of the quantity's range, that calls for the
#: shape-preserving sampling: on the smooth curves none to mu = 5.6 and 3.3e-6 of F's range at mu = 10 (1e-5 in F
#: on a curve of 383 points, below any error the table states); on rough ones at sigma >= 0.2 1e-3 to 0.09, where
#: smaller ones came with a missed pull-off (docs/family.md).
OVERSHOOT_TOL = 1e-4


def _spline_fails(t, lam, F, L, G, events) -> str | None:
    """Why the cubic splines ``L``, ``G`` through the points (t, lam, F) do not describe the curve (None: they
    do): one swings past the ends of an interval on which its data do not turn, or the most tensile load along
    it misses the located pull-off (the least F_min of ``events``) by more than PULL_OFF_TOL."""
    for name, y, c in (("F", F, G), ("lambda", lam, L)):
        o = overshoot(t, y, c)
        if o > OVERSHOOT_TOL:
            return f"the spline of {name} swings past its points by {o:.2g} of its range"
    located = [e.F for e in events if e.kind == "F_min"]
    if located:
        inside = t <= 1.0
        roots = np.asarray(G.derivative().roots(extrapolate=False), dtype=float)
        cand = np.r_[t[inside], roots[roots <= 1.0], 1.0]
        least, po = float(np.min(G(cand))), min(located)
        if abs(least - po) > PULL_OFF_TOL * abs(po):
            return f"the spline's pull-off {least:.6g} misses the located {po:.6g}"
    return None


def _with_events(t, lam, F, events, stretched):
    """The points (t, lam, F) with the events among them in the order of their coordinate (``stretched``: tau
    of s); an event within a hair of a point, or outside the points' span, is left out."""
    if not events:
        return t, lam, F
    te = np.asarray([float(stretched(0.5 * e.a ** 2 - e.H0)) for e in events])
    hair = 1e-9 * float(t[-1] - t[0])
    ok = np.isfinite(te) & (te > t[0] + hair) & (te < t[-1] - hair)
    ok &= np.array([np.min(np.abs(t - x)) > hair for x in te])
    if not ok.any():
        return t, lam, F
    ev = [e for e, k in zip(events, ok) if k]
    T = np.r_[t, te[ok]]
    order = np.argsort(T, kind="stable")
    return (T[order], np.r_[lam, [e.lam for e in ev]][order], np.r_[F, [e.F for e in ev]][order])


def sample(lam, F, H0, a, level: float, F_max: float, tau: np.ndarray, mu: float, regrid=None,
           events=()) -> Sampled:
    """A traced curve (its points' ``lam``, ``F``, ``H0`` and contact radius ``a``; ``level``, the gap of the
    contact edge, :func:`~petsc_adhesion.discretization.contact.edge_level`) of Tabor parameter ``mu`` on the
    nodes ``tau`` (``regrid``: the points that repeat the state before them on a new grid, left out: the two
    grids' values differ by their discretization errors, a step a spline through both would ring on), from its
    start to where F first reaches ``F_max`` (past its last turning point): cubic splines of lambda and F in tau
    through its points where they describe the curve, else (a spline swings past its points, or misses the
    located pull-off: sparse points about a sharp bend) the shape-preserving piecewise cubic
    (:func:`shape_preserving`) through the points and ``events`` (:class:`EventPoint`: the solver's located
    turning points, where the rate is 0).  NotMonotone where s falls by more than 1e-4 of its range between
    two points; ValueError where the curve does not reach F_max."""
    from scipy.interpolate import CubicSpline

    lam, F, H0, a = (np.asarray(x, dtype=float) for x in (lam, F, H0, a))
    if regrid is not None:
        own = ~np.asarray(regrid, dtype=bool)
        lam, F, H0, a = lam[own], F[own], H0[own], a[own]
    s = coordinate(H0, a)
    kept, fall = rising(s)
    if fall > 1e-4:
        span = float(s.max() - s.min())
        raise NotMonotone(f"s = a^2/2 - H(0) falls by {fall * span:.3g} along the curve ({fall:.2g} of its range)")
    s, lam, F = s[kept], lam[kept], F[kept]
    over = np.flatnonzero(F >= F_max)
    if not over.size or over[0] == 0:
        raise ValueError(f"the curve does not reach F = {F_max:g} from below (its largest F {F.max():.4g})")
    k = int(over[0])
    s0 = 0.5 - level
    fs = CubicSpline(s[max(k - 3, 0):k + 2], F[max(k - 3, 0):k + 2]) if k + 1 < s.size and k >= 2 else None
    # the end: F = F_max between the two points about it, on the spline through its neighbours (linear at an end)
    frac = (F_max - F[k - 1]) / (F[k] - F[k - 1])
    s_hi = float(s[k - 1] + frac * (s[k] - s[k - 1]))
    if fs is not None:
        s_hi = float(root(lambda x: float(fs(x)) - F_max, float(s[k - 1]), float(s[k])))
    s_lo = float(s[0])
    if not s_lo < s0 < s_hi:
        raise ValueError(f"the curve's s spans [{s_lo:.4g}, {s_hi:.4g}], not its centre s0 = {s0:.4g}: it does "
                         f"not form a contact before F = {F_max:g}")
    t = stretch(s, s0, s_lo, s_hi, width(mu))
    keep = t <= 1.0 + 1e-12
    keep[k] = True                                    # one point past the end, for the spline's last interval
    t, lam_k, F_k = t[keep], lam[keep], F[keep]
    L, G = CubicSpline(t, lam_k), CubicSpline(t, F_k)
    events = tuple(e for e in events if e.kind in EVENT_KINDS)
    why = _spline_fails(t, lam_k, F_k, L, G, events)
    if why is not None:
        t, lam_k, F_k = _with_events(t, lam_k, F_k, events, lambda x: stretch(x, s0, s_lo, s_hi, width(mu)))
        L, G = shape_preserving(t, lam_k), shape_preserving(t, F_k)
    return Sampled(np.asarray(L(tau), dtype=float), np.asarray(G(tau), dtype=float), s_lo, s_hi, s0, fall, why)
