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

import numpy as np

from ..brent import root

__all__ = ["width", "NotMonotone", "Sampled", "coordinate", "rising", "sample", "stretch", "unstretch"]



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


@dataclass(frozen=True)
class Sampled:
    """A traced curve on the table's nodes ``tau``: ``lam`` and ``F`` there, the ends ``s_lo``, ``s_hi`` and the
    centre ``s0`` of its coordinate, and ``fall``, the largest fall of s between successive points left out
    (a regrid's two grids at one state)."""

    lam: np.ndarray
    F: np.ndarray
    s_lo: float
    s_hi: float
    s0: float
    fall: float


class NotMonotone(ValueError):
    """A curve along which s falls by more than a regrid's difference: it cannot be tabulated in s."""


def sample(lam, F, H0, a, level: float, F_max: float, tau: np.ndarray, mu: float, regrid=None) -> Sampled:
    """A traced curve (its points' ``lam``, ``F``, ``H0`` and contact radius ``a``; ``level``, the gap of the
    contact edge, :func:`~petsc_adhesion.discretization.contact.edge_level`) of Tabor parameter ``mu`` on the
    nodes ``tau`` (``regrid``: the points that repeat the state before them on a new grid, left out: the two
    grids' values differ by their discretization errors, a step a spline through both would ring on): cubic
    splines of lambda and F in tau through its points, from its start to where F first reaches ``F_max``
    (past its last turning point).  NotMonotone where s falls by more than 1e-4 of its range between two
    points; ValueError where the curve does not reach F_max."""
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
    return Sampled(np.asarray(L(tau), dtype=float), np.asarray(G(tau), dtype=float), s_lo, s_hi, s0, fall)
