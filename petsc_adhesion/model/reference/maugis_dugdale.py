"""Maugis (1992): the Dugdale cohesive zone between the DMT and JKR limits.

The Dugdale stress taken as the Lennard-Jones law's peak traction with its work of
adhesion gives Maugis' parameter lambda_MD = 1.157 mu.  Its load-approach curve in
parametric form and its load-controlled pull-off: the transition the Lennard-Jones
model shows, to a few per cent (a check of trends, not of digits).
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ... import brent
from .rigid import DMT_PULL_OFF, _out

__all__ = ["maugis_parameter", "maugis_dugdale_curve", "maugis_dugdale_pull_off"]


# Dugdale stress = peak Lennard-Jones traction 16 gamma / (9 sqrt(3) epsilon) in
# Maugis' lambda = 2 sigma_0 (R / (pi w K^2))^(1/3), K = 4E/3: lambda_MD = this * mu.
_MAUGIS_PER_TABOR = 32.0 / (9.0 * math.sqrt(3.0)) * (9.0 / (16.0 * math.pi)) ** (1.0 / 3.0)


# Maugis' Abar, Pbar, Deltabar into A / sqrt(mu), F, lambda / mu.
_MD_RADIUS = (3.0 * math.pi / 4.0) ** (1.0 / 3.0)


_MD_APPROACH = (9.0 * math.pi**2 / 16.0) ** (1.0 / 3.0)


def maugis_parameter(mu: ArrayLike) -> float | np.ndarray:
    """Maugis' lambda_MD for the Lennard-Jones law of eq. (5) (Maugis, J. Colloid Interface Sci. 150, 1992).

    lambda_MD = 2 sigma_0 (R / (pi w K^2))^(1/3), K = 4E/3, w = gamma, with the
    Dugdale stress sigma_0 = 16 gamma / (9 sqrt(3) epsilon) the Lennard-Jones peak,
    is lambda_MD = (32 / (9 sqrt 3)) (9 / (16 pi))^(1/3) mu.

    Parameters
    ----------
    mu : array_like
        Tabor parameter.

    Returns
    -------
    float or ndarray
        lambda_MD.

    Examples
    --------
    >>> round(maugis_parameter(1.0), 4)
    1.157
    """
    return _out(_MAUGIS_PER_TABOR * np.asarray(mu, dtype=float))


def _md_curve(lmd: float, m_minus_1: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maugis' (Abar, Pbar, Deltabar) at m = c/a, taking m - 1 to keep digits near m = 1."""
    q = np.asarray(m_minus_1, dtype=float)
    m2 = (1.0 + q) ** 2
    s = np.sqrt(q * (q + 2.0))          # sqrt(m^2 - 1)
    t = np.arctan(s)
    # s - arctan s loses all digits as s -> 0, where large lambda_MD puts the pull-off
    small = s < 0.02
    ss = np.where(small, s, 0.0)
    s_minus_t = np.where(small, ss**3 * (1 / 3 - ss**2 / 5 + ss**4 / 7 - ss**6 / 9), s - t)
    f1 = s_minus_t + s**2 * t           # sqrt(m^2-1) + (m^2 - 2) arctan sqrt(m^2-1)
    f2 = s * t - q                      # sqrt(m^2-1) arctan sqrt(m^2-1) - m + 1
    # cohesive-zone condition, (lmd/2) f1 Abar^2 + (4 lmd^2/3) f2 Abar - 1 = 0:
    # both coefficients are positive, so the positive root is unique
    a2, a1 = 0.5 * lmd * f1, 4.0 / 3.0 * lmd**2 * f2
    A = 2.0 / (a1 + np.sqrt(a1**2 + 4.0 * a2))
    P = A**3 - lmd * A**2 * (s + m2 * t)
    D = A**2 - 4.0 / 3.0 * lmd * A * s
    return A, P, D


def maugis_dugdale_curve(mu: float, m: ArrayLike) -> tuple[float | np.ndarray, float | np.ndarray, float | np.ndarray]:
    """Maugis-Dugdale load curve parametrised by m = c/a (Maugis, J. Colloid Interface Sci. 150, 1992).

    Maugis' equations in his variables, with lambda_MD = ``maugis_parameter(mu)``
    and s = sqrt(m^2 - 1):

    - cohesive zone: (lambda_MD Abar^2/2) [s + (m^2 - 2) arctan s]
      + (4 lambda_MD^2 Abar/3) [s arctan s - m + 1] = 1, solved for Abar;
    - Pbar = Abar^3 - lambda_MD Abar^2 [s + m^2 arctan s];
    - Deltabar = Abar^2 - (4/3) Abar lambda_MD s.

    Converted with Abar = a (K / (pi w R^2))^(1/3), Pbar = P / (pi w R),
    Deltabar = delta (K^2 / (pi^2 w^2 R))^(1/3), K = 4E/3:
    A = (3 pi/4)^(1/3) mu^(1/2) Abar, F = Pbar/2, lambda = (9 pi^2/16)^(1/3) mu Deltabar.
    As for JKR, delta/epsilon is lambda to leading order only.
    m runs from 1 (large contact) to infinity (vanishing contact).

    Parameters
    ----------
    mu : float
        Tabor parameter > 0.
    m : array_like
        Ratio of the cohesive-zone radius to the contact radius, > 1.

    Returns
    -------
    (A, F, lambda) : tuple of float or ndarray
        Contact radius in sqrt(epsilon R), load in 2 pi R gamma, approach.

    Examples
    --------
    >>> A, F, lam = maugis_dugdale_curve(1e-6, 1e9)  # contact vanishing at small mu: DMT
    >>> round(F, 6)
    -1.0
    """
    A, P, D = _md_curve(float(maugis_parameter(mu)), np.asarray(m, dtype=float) - 1.0)
    return _out(_MD_RADIUS * math.sqrt(mu) * A), _out(P / 2.0), _out(_MD_APPROACH * mu * D)


#: The grid in x = log(m - 1) that brackets the pull-off's minimum, and m - 1 on it (the same every time).
_PULL_OFF_GRID = (np.linspace(math.log(1e-14), math.log(1e14), 561),
                  np.exp(np.linspace(math.log(1e-14), math.log(1e14), 561)))
for _a in _PULL_OFF_GRID:
    _a.flags.writeable = False


def _md_pull_off(mu: float) -> float:
    if mu == 0.0:
        return DMT_PULL_OFF
    lmd = float(maugis_parameter(mu))
    # x = log(m - 1): the minimum moves from m - 1 ~ lmd^-3/2 (DMT) to ~ lmd^-2
    # (JKR), decades apart; a grid over x brackets it before Brent refines it
    x, q = _PULL_OFF_GRID
    P = _md_curve(lmd, q)[1]
    i = int(np.argmin(P))
    lo, hi = x[max(i - 1, 0)], x[min(i + 1, x.size - 1)]
    def load(y):
        return _md_load(lmd, math.exp(y))

    return 0.5 * min(load(brent.minimum(load, lo, hi, xatol=1e-10)), float(P[i]))


def _md_load(lmd: float, q: float) -> float:
    """Pbar of :func:`_md_curve` at one m - 1 = ``q``, in Python floats (the same operations in the same
    order: to the bit where numpy's arctan and powers are the C library's, within 1e-13 of Pbar's terms where
    numpy has its own AVX-512 kernels, tests/test_reference.py; a tenth of the cost of numpy's scalars in a
    minimization)."""
    m2 = (1.0 + q) ** 2
    s = math.sqrt(q * (q + 2.0))
    t = math.atan(s)
    s_minus_t = s**3 * (1 / 3 - s**2 / 5 + s**4 / 7 - s**6 / 9) if s < 0.02 else s - t
    f1 = s_minus_t + s**2 * t
    f2 = s * t - q
    a2, a1 = 0.5 * lmd * f1, 4.0 / 3.0 * lmd**2 * f2
    A = 2.0 / (a1 + math.sqrt(a1**2 + 4.0 * a2))
    return A**3 - lmd * A**2 * (s + m2 * t)


def maugis_dugdale_pull_off(mu: ArrayLike) -> float | np.ndarray:
    """Load-controlled Maugis-Dugdale pull-off: the most tensile F on the curve (Maugis 1992).

    The minimum of Pbar over m > 1 of ``maugis_dugdale_curve``, in 2 pi R gamma.
    It runs from the DMT -1 (mu -> 0) to the JKR -0.75 (mu -> infinity); with the
    Lennard-Jones peak stress it lies 1.5 to 6% below the Lennard-Jones pull-off
    in magnitude for mu in 0.1 to 3, so it checks trends, not digits.

    Parameters
    ----------
    mu : array_like
        Tabor parameter >= 0 (0 gives the DMT value).

    Returns
    -------
    float or ndarray
        F at pull-off.

    Examples
    --------
    >>> round(maugis_dugdale_pull_off(1.0), 4)
    -0.7911
    """
    mu_arr = np.asarray(mu, dtype=float)
    return _out(np.vectorize(_md_pull_off, otypes=[float])(mu_arr))
