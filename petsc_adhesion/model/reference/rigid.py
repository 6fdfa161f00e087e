"""The rigid sphere (mu = 0): its load-approach curve (eq. 28), the DMT pull-off, and the attraction beyond r_m.

A rigid sphere keeps the gap H = -lambda + r^2/2 (eq. 27); its load is the Lennard-Jones
law integrated in closed form.  The part of that load beyond a radius r_m is the
attraction the half-infinite model adds to a domain [0, r_m], and the deflection it
causes inside is what the error bars allow for (:func:`far_deflection`).
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["RIGID_EQUILIBRIUM", "DMT_PULL_OFF", "rigid_load", "load_beyond", "load_beyond_rates", "far_deflection"]


#: Approach of zero load of the rigid sphere, 1 - 2^(-1/3) = 0.20630 (root of eq. 28).
RIGID_EQUILIBRIUM = 1.0 - 2.0 ** (-1.0 / 3.0)


#: Pull-off of the rigid sphere (Derjaguin-Muller-Toporov; eq. 28 at lambda = 0).
DMT_PULL_OFF = -1.0


def _out(x: np.ndarray) -> float | np.ndarray:
    """A Python float for scalar input, the array otherwise."""
    return float(x) if np.ndim(x) == 0 else x


def rigid_load(lam: ArrayLike) -> float | np.ndarray:
    """Load on the rigid sphere (mu = 0) over the half-infinite domain, eq. (28).

    F = [1 - 4 (1 - lambda)^6] / [3 (1 - lambda)^8], from eqs. (26), (27) with
    H = -lambda + r^2/2 (Feng's result quoted by the paper). Minimum -1 at
    lambda = 0, zero at ``RIGID_EQUILIBRIUM``.

    Parameters
    ----------
    lam : array_like
        Approach lambda < 1.

    Returns
    -------
    float or ndarray
        F in units of 2 pi R gamma.

    Examples
    --------
    >>> rigid_load(0.0)
    -1.0
    >>> abs(rigid_load(RIGID_EQUILIBRIUM)) < 1e-14
    True
    """
    g = 1.0 - np.asarray(lam, dtype=float)
    return _out((1.0 - 4.0 * g**6) / (3.0 * g**8))


def load_beyond(rmax: float, lam: ArrayLike) -> float | np.ndarray:
    """Load of the rigid sphere carried beyond r = rmax: the truncation error of eq. (26).

    With g = 1 - lambda + r^2/2 (so r dr = dg),
    (8/3) int_{rmax}^inf P r dr = (8/3) (g_m^-8 / 8 - g_m^-2 / 2), g_m = g(rmax).
    At small mu the gap beyond rmax is nearly rigid and this is the leading
    error of a load computed on [0, rmax].

    Parameters
    ----------
    rmax : float
        Outer radius r_m of the domain.
    lam : array_like
        Approach.

    Returns
    -------
    float or ndarray
        Load in units of 2 pi R gamma; negative (attraction).

    Examples
    --------
    >>> round(load_beyond(10.0, 0.0), 9)   # about -(4/3) / (r_m^2/2 + 1)^2
    -0.000512623
    >>> load_beyond(0.0, 0.0)  # the whole of eq. (28)
    -1.0
    """
    g = 1.0 - np.asarray(lam, dtype=float) + 0.5 * rmax**2
    return _out((8.0 / 3.0) * (g**-8 / 8.0 - g**-2 / 2.0))


def load_beyond_rates(rmax: float, lam: float) -> tuple[float, float]:
    """The derivatives of :func:`load_beyond` with respect to lambda and to rmax.

    d/dlambda = (8/3) P(g_m) with P(g) = g^-9 - g^-3, and d/drmax = -(8/3) P(g_m) rmax.

    >>> dlam, dr = load_beyond_rates(0.0, 0.0)          # P(1) = 0: eq. (28) is flat at lambda = 0
    >>> abs(dlam) < 1e-15
    True
    """
    g = 1.0 - lam + 0.5 * rmax**2
    P = (8.0 / 3.0) * (g**-9 - g**-3)
    return float(P), float(-P * rmax)


def far_deflection(rmax: float, coupling: float) -> float:
    """A bound on the deflection the attraction beyond rmax causes inside it (the far field's remainder).

    c integral_{rmax}^inf t/(t + r) K P dt <= c (pi/2) integral_{rmax}^inf |P| dt with the
    rigid gap t^2/2, where |P| <= 8 / t^6: c (pi/2) 8 / (5 rmax^5).

    >>> f"{far_deflection(10.0, 3.3953):.1e}"
    '8.5e-05'
    """
    return coupling * (math.pi / 2) * 8.0 / (5.0 * rmax**5)
