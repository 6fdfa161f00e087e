"""Radial collocation grids on [0, r_m] (paper, section "Discretization").

The unknown separation H is piecewise linear on the nodes (eq. 11), so a grid
is nothing but its sorted node array; this module builds the node sets and the
exact integration weights that the piecewise-linear interpolant implies.
"""
from __future__ import annotations

import numpy as np

__all__ = ["uniform", "paper", "load_weights", "l2_weights", "PAPER_UNIFORM", "PAPER_EXTRA", "PAPER_SPLIT"]

#: The paper's grid: 501 uniform nodes plus about 30 (N = 531): 30 elements halved.
PAPER_UNIFORM, PAPER_EXTRA, PAPER_SPLIT = 501, 30, 2


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


def load_weights(r: np.ndarray) -> np.ndarray:
    """Weights q with  integral_0^{r_m} P(r) r dr = q . P  for piecewise-linear P.

    Exact for the interpolant of eq. (11); the load of eq. (26) is
    F = (8/3) q . P.

    >>> r = uniform(3, 2.0)                 # nodes 0, 1, 2
    >>> load_weights(r)                     # P = 1 gives integral_0^2 r dr = 2
    array([0.16666667, 1.        , 0.83333333])
    >>> abs(load_weights(r) @ r - 8 / 3) < 1e-15   # P = r: integral_0^2 r^2 dr = 8/3, exact
    True
    """
    a, b = r[:-1], r[1:]
    h = b - a
    q = np.zeros_like(r)
    # integral over [a, b] of phi_left * t dt and phi_right * t dt
    q[:-1] += h * (2 * a + b) / 6
    q[1:] += h * (a + 2 * b) / 6
    return q


def l2_weights(r: np.ndarray) -> np.ndarray:
    """Trapezoidal weights of (1/r_m) integral_0^{r_m} u v dr.

    The continuation measures the unknown H in this grid-independent norm: with
    the Euclidean norm of the paper, |lambdadot| would be about N^-1/2 on the
    whole curve and the paper's switch at |lambdadot| = 0.5 would never act.

    >>> l2_weights(uniform(5, 1.0))         # trapezoid rule, weights summing to 1
    array([0.125, 0.25 , 0.25 , 0.25 , 0.125])
    """
    h = np.diff(r)
    w = np.zeros_like(r)
    w[:-1] += h / 2
    w[1:] += h / 2
    return w / (r[-1] - r[0])
