"""The elastic half-space under axisymmetric pressures: a uniform disk and a Hertz (elliptic) distribution.

The surface deflection W(r) = integral t/(t + r) K(m) p(t) dt of eq. (4), in closed
form for two pressures: the checks of the influence matrix (eq. 12) to near round-off.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ellipe, ellipk

from .rigid import _out

__all__ = ["disk_deflection", "hertz_deflection"]


def disk_deflection(r: ArrayLike, a: float) -> float | np.ndarray:
    """W(r) for unit pressure on t <= a (Johnson, Contact Mechanics 1985, sec. 3.4).

    Inside, W = a E(r^2/a^2); outside, W = r [E(a^2/r^2) - (1 - a^2/r^2) K(a^2/r^2)],
    with scipy's parameter convention m = k^2. Johnson's u_z is (4/(pi E)) W.

    Parameters
    ----------
    r : array_like
        Radii >= 0.
    a : float
        Disk radius > 0.

    Returns
    -------
    float or ndarray
        W(r).

    Examples
    --------
    >>> disk_deflection(0.0, 2.0) == np.pi    # int_0^a K(0) dt
    True
    >>> disk_deflection(2.0, 2.0)             # both forms give a at the edge
    2.0
    """
    r = np.asarray(r, dtype=float)
    inside = r <= a
    # Each branch sees only arguments in [0, 1]; np.where evaluates both.
    m_in = np.where(inside, (r / a) ** 2, 0.0)
    m_out = np.where(inside, 0.0, (a / np.where(inside, a, r)) ** 2)
    w_out = r * (ellipe(m_out) - (1.0 - m_out) * ellipk(m_out))
    return _out(np.where(inside, a * ellipe(m_in), w_out))


def hertz_deflection(r: ArrayLike, a: float) -> float | np.ndarray:
    """W(r) for p = sqrt(1 - t^2/a^2) on t <= a (Johnson, Contact Mechanics 1985, sec. 3.4).

    Inside, W = pi^2/(16 a) (2 a^2 - r^2); outside,
    W = pi/(8 a) [(2 a^2 - r^2) arcsin(a/r) + a sqrt(r^2 - a^2)].

    Parameters
    ----------
    r : array_like
        Radii >= 0.
    a : float
        Contact radius > 0.

    Returns
    -------
    float or ndarray
        W(r).

    Examples
    --------
    >>> hertz_deflection(1.0, 1.0) == np.pi**2 / 16
    True
    """
    r = np.asarray(r, dtype=float)
    inside = r <= a
    ro = np.where(inside, a, r)
    w_out = np.pi / (8 * a) * ((2 * a**2 - ro**2) * np.arcsin(a / ro) + a * np.sqrt(ro**2 - a**2))
    return _out(np.where(inside, np.pi**2 / (16 * a) * (2 * a**2 - r**2), w_out))
