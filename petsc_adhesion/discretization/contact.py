"""Where the contact edge is, and how a state is carried from one grid to another.

The edge of a contact is where the separation H rises through a level inside
the cohesive zone (:func:`edge_level`); the contact radius of a state is the
first node-interpolated crossing of that level from the centre
(:func:`crossing`, :func:`contact_radius`).  Both frames of the problem
(:mod:`~petsc_adhesion.discretization.problem`,
:mod:`~petsc_adhesion.discretization.edge_frame`) measure their contact radius
and carry a state onto their own grid with these (their ``radius``,
``radius_rate`` and ``carry``): H grows like r^2/2 (eq. 27), so the deformation
D = H - r^2/2 is what is interpolated (:func:`deformation_at`), and a
tangent's nodal part carries over linearly (:func:`rate_at`).
"""
from __future__ import annotations

import numpy as np

from .. import brent

__all__ = ["edge_level", "peak_attraction", "SMOOTH_LEVEL", "SMOOTH_PEAK", "crossing", "contact_radius",
           "deformation_at", "rate_at"]


#: H at the pinned contact edge of a smooth surface: a gap of 1.5 epsilon, inside the cohesive zone.
SMOOTH_LEVEL = 0.5
#: H of the smooth law's peak attraction: a gap of 3^(1/6) epsilon (eq. 5).
SMOOTH_PEAK = 3.0 ** (1.0 / 6.0) - 1.0


def peak_attraction(law) -> float:
    """The H at which the law attracts most (P most negative), above its wall.

    A rough average spreads the attraction over the heights, and the peak can lie
    far from the wall + 1.5 of a smooth surface: with the 16-point Hermite rule at
    sigma = 1 it is 0.24 above the wall.  Sampled on a geometric scale from the
    wall, then refined by Brent's method between the neighbours of the best sample.
    """
    if law.smooth:
        return SMOOTH_PEAK
    reach = 2.0 * (law.wall + 1.0) + 3.0          # past the lowest heights' reach, for any law here
    H = law.wall + np.geomspace(1e-4, reach, 2000)
    k = int(np.argmin(law(H)[0]))
    lo, hi = H[max(k - 1, 0)], H[min(k + 1, H.size - 1)]
    return float(brent.minimum(lambda h: float(law(np.array([h]))[0][0]), lo, hi, xatol=1e-10))


def edge_level(law) -> float:
    """H at the pinned contact edge: as far beyond the law's peak attraction as a smooth surface's
    SMOOTH_LEVEL is beyond its own, so inside the cohesive zone whatever the roughness."""
    return SMOOTH_LEVEL if law.smooth else peak_attraction(law) + (SMOOTH_LEVEL - SMOOTH_PEAK)


def contact_radius(problem, x: np.ndarray) -> float:
    """Where H first rises through the edge level from the centre (0 when H(0) is above it); collective.

    :func:`crossing` of the nodal H, as docs/numerics.md defines it."""
    return crossing(problem.nodes(x), problem.gather(problem.separation(x)), edge_level(problem.law))


def crossing(r: np.ndarray, H: np.ndarray, level: float) -> float:
    """The first r where H rises through ``level`` (0 when H(0) is above it), on the cubic through the four
    nodes about the crossing (three where the grid has no fourth).

    Linear interpolation would err by h^2 t (1 - t) H'' / 2 with t the crossing's place in its element:
    a term that jumps as refinement moves the nodes past the crossing and spoils the extrapolation of
    the error bars; the cubic's error is O(h^4) and smooth enough.

    >>> r = np.linspace(0.0, 2.0, 9)
    >>> round(crossing(r, -1.0 + r**2 / 2, 0.0), 12)        # exact for a parabola: sqrt(2)
    1.414213562373
    """
    if H[0] >= level:
        return 0.0
    k = int(np.argmax(H >= level))
    if not H[k] >= level:                       # never rises through it on this grid
        return float(r[-1])
    lo = min(max(k - 2, 0), max(len(r) - 4, 0))
    idx = np.arange(lo, min(lo + 4, len(r)))
    rr, hh = r[idx], H[idx] - level

    def g(t: float) -> float:
        """The Lagrange polynomial through (rr, hh) at t."""
        total = 0.0
        for i in range(len(rr)):
            w = np.prod([(t - rr[j]) / (rr[i] - rr[j]) for j in range(len(rr)) if j != i])
            total += hh[i] * w
        return total

    a, b = float(r[k - 1]), float(r[k])
    if g(a) * g(b) > 0:                         # cannot happen but for round-off at a node
        return a if abs(H[k - 1] - level) < abs(H[k] - level) else b
    return brent.root(g, a, b, xtol=1e-15 * max(1.0, b), rtol=float(4 * np.finfo(float).eps), maxiter=100)


def deformation_at(source, x: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The deformation D = H - r^2/2 of ``source``'s state x, linearly interpolated at the physical radii r
    (collective).

    H grows like r^2/2 (eq. 27): its deformation is interpolated instead, since the far
    grid's spacing h would cost the quadratic h^2/8, and is what the frame of the edge
    takes as its unknown.
    """
    r_old = source.nodes(x)
    field = source.gather(source.separation(x) - 0.5 * r_old[source.lo:source.hi] ** 2)
    return np.interp(r, r_old, field)


def rate_at(source, x: np.ndarray, xdot: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The nodal part of ``source``'s tangent xdot at its state x (dH/ds, or dD/ds in the frame of the edge),
    linearly interpolated at the physical radii r (collective)."""
    return np.interp(r, source.nodes(x), source.gather(xdot[:source.hi - source.lo]))
