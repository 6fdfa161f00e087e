"""Radial collocation grids on [0, r_m] (paper, section "Discretization").

The unknown separation H is piecewise linear on the nodes (eq. 11), so a grid
is nothing but its sorted node array; this module builds the node sets and the
exact integration weights that the piecewise-linear interpolant implies.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["uniform", "paper", "nested", "load_weights", "l2_weights", "EdgeGrid", "PAPER_UNIFORM",
           "PAPER_EXTRA", "PAPER_SPLIT"]

#: The paper's grid: 501 uniform nodes plus about 30 (N = 531): 30 elements halved.
PAPER_UNIFORM, PAPER_EXTRA, PAPER_SPLIT = 501, 30, 2
#: The end of the paper's domain, r_m = 10.
PAPER_RMAX = 10.0


def uniform(n: int, rmax: float) -> np.ndarray:
    """``n`` equally spaced nodes on [0, rmax]."""
    return np.linspace(0.0, rmax, n)


def paper(rmax: float, n_uniform: int = PAPER_UNIFORM, extra: int = PAPER_EXTRA,
          refine_from: float = 0.0, split: int = PAPER_SPLIT) -> np.ndarray:
    """The paper's node set: ``n_uniform`` uniform nodes plus refined elements.

    The paper adds about 30 nodes "where H and P change fastest" to 501
    uniform ones (N = 531) without saying where.  Our rule: the ``extra``
    uniform elements that start at or after ``refine_from`` are split into
    ``split`` equal parts (by default their midpoints: 30 nodes).  The default,
    ``refine_from = 0``, halves the spacing on [0, 30 h] where the pressure
    peaks for small mu and at the centre of the contact.  For large mu, refine
    the whole range the contact edge travels (see resolution.check).
    """
    r = uniform(n_uniform, rmax)
    first = int(np.searchsorted(r, refine_from - 1e-12 * rmax))
    first = min(first, n_uniform - 1 - extra)
    a, h = r[first:first + extra], r[1] - r[0]
    inner = (a[:, None] + h * np.arange(1, split)[None, :] / split).ravel()
    return np.sort(np.concatenate([r, inner]))


def nested(r: np.ndarray, level: int) -> np.ndarray:
    """The grid ``level`` times refined (element midpoints added) or, for level < 0, coarsened
    (every other node, both ends kept: the last element may merge two).

    >>> nested(uniform(5, 1.0), -1)
    array([0. , 0.5, 1. ])
    >>> nested(uniform(3, 1.0), 1)
    array([0.  , 0.25, 0.5 , 0.75, 1.  ])
    """
    for _ in range(max(0, -level)):
        r = r[::2] if r.size % 2 else np.append(r[:-1:2], r[-1])
    for _ in range(max(0, level)):
        r = np.sort(np.concatenate([r, 0.5 * (r[1:] + r[:-1])]))
    return r


def load_weights(r: np.ndarray) -> np.ndarray:
    """Weights q with  integral_0^{r_m} P(r) r dr = q . P  for piecewise-linear P.

    Exact for the interpolant of eq. (11); the load of eq. (26) is
    F = (8/3) q . P.

    >>> r = uniform(3, 2.0)                 # nodes 0, 1, 2
    >>> load_weights(r)                     # P = 1 gives integral_0^2 r dr = 2
    array([0.16666667, 1.        , 0.83333333])
    >>> bool(abs(load_weights(r) @ r - 8 / 3) < 1e-15)  # P = r: integral_0^2 r^2 dr = 8/3, exact
    True
    """
    a, b = r[:-1], r[1:]
    h = b - a
    q = np.zeros_like(r)
    # integral over [a, b] of phi_left * t dt and phi_right * t dt
    q[:-1] += h * (2 * a + b) / 6
    q[1:] += h * (a + 2 * b) / 6
    return q


def l2_weights(r: np.ndarray, upto: float | None = None) -> np.ndarray:
    """Trapezoidal weights of (1/R) integral_0^R u v dr, R = min(upto, r_m).

    The continuation measures the unknown H in this grid-independent norm: with
    the Euclidean norm of the paper, |lambdadot| would be about N^-1/2 on the
    whole curve and the paper's switch at |lambdadot| = 0.5 would never act.
    Beyond the reach of the contact H only shifts with lambda: ``upto`` keeps a
    large domain's far field from drowning the contact region in the norm
    (the elements cut by R count in part).

    >>> l2_weights(uniform(5, 1.0))         # trapezoid rule, weights summing to 1
    array([0.125, 0.25 , 0.25 , 0.25 , 0.125])
    >>> l2_weights(uniform(5, 1.0), 0.5)    # [0, 0.5] only
    array([0.25, 0.5 , 0.25, 0.  , 0.  ])
    """
    R = r[-1] if upto is None else min(upto, r[-1])
    h = np.clip(np.minimum(r[1:], R) - r[:-1], 0.0, None)
    w = np.zeros_like(r)
    w[:-1] += h / 2
    w[1:] += h / 2
    return w / R


#: The most samples of an EdgeGrid's mapping over the reach of the forces (:meth:`EdgeGrid._mapping`).
UNIFORM_SAMPLES = 1_000_000


@dataclass(frozen=True)
class EdgeGrid:
    """Nodes graded around the contact edge ``edge``, fine enough for the cohesive zone there.

    The spacing h(r) is ``fine`` within ``band`` of the edge, grows by ``grading``
    times the distance beyond, and is capped by ``contact`` within ``reach`` of
    the forces (by ``interior`` times r, or ``core`` where that is larger, inside the
    contact), growing by ``far`` times the distance beyond that, out to ``rmax``.  The nodes are the mapping
    xi = integral_0^r dr / h at equal steps of xi, so refinement levels are nested:
    every other node of ``level`` + 1 is a node of ``level`` (spacing / 2^level).
    """

    edge: float
    fine: float
    rmax: float
    band: float = 0.0
    grading: float = 0.1
    contact: float = 0.025
    interior: float = 0.01
    reach: float = 3.0
    far: float = 0.1
    core: float = 0.0
    level: int = 0

    def spacing(self, r: np.ndarray) -> np.ndarray:
        """h(r) at level 0."""
        d = np.abs(r - self.edge)
        cap = np.where(r < self.edge, np.maximum(np.maximum(self.contact, self.interior * r), self.core),
                       self.contact + self.far * np.maximum(0.0, r - self.edge - self.reach))
        return np.minimum(np.maximum(self.fine, self.grading * (d - self.band)), np.maximum(cap, self.fine))

    def _mapping(self) -> tuple[np.ndarray, np.ndarray]:
        """(r, xi(r)), xi = integral dr / h by the trapezoid rule on samples at most h/8 apart.

        Samples: geometric about the edge (ratio 1 + grading/8), uniform over the band
        and over the reach of the forces (at most UNIFORM_SAMPLES there: beyond the band
        the spacing is at least ``contact`` or grows from ``fine`` geometrically, which
        the samples about the edge follow; a soft sphere's fine / 2 over a contact of
        radius 100 took 4e8 samples and 14 GB at mu = 1000).
        """
        q = 1.0 + self.grading / 8
        steps = (self.fine / 8) * (q ** np.arange(int(np.log(8 * self.rmax / self.fine) / np.log(q)) + 2) - 1) / (q - 1)
        near = min(self.rmax, self.edge + self.reach + 1.0)
        r = np.concatenate([self.edge - self.band - steps, self.edge + self.band + steps,
                            np.arange(max(0.0, self.edge - self.band), min(self.rmax, self.edge + self.band),
                                      self.fine / 8),
                            np.arange(0.0, near, max(min(self.contact, self.fine * 4) / 8, near / UNIFORM_SAMPLES)),
                            [0.0, self.rmax]])
        r = np.unique(r[(r >= 0.0) & (r <= self.rmax)])
        inv = 1.0 / self.spacing(r)
        return r, np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(r))])

    def nodes(self) -> np.ndarray:
        """The nodes of this level: 4 k elements at level 0 (so two coarser levels nest), times 2^level."""
        r, xi = self._mapping()
        elements = 4 * int(np.ceil(xi[-1] / 4)) * 2 ** self.level if self.level >= 0 else \
            4 * int(np.ceil(xi[-1] / 4)) // 2 ** -self.level
        out = np.interp(np.linspace(0.0, xi[-1], elements + 1), xi, r)
        out[0], out[-1] = 0.0, self.rmax
        return out
