"""Johnson, Kendall and Roberts (1971): the soft-sphere limit, mu -> infinity.

The load and approach against the contact radius, the zero-load state and the
fixed-grip pull-off, in the model's units (contact radii in sqrt(epsilon R), loads in
2 pi R gamma, approaches in epsilon): the limits the curves approach as mu grows.
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .rigid import _out

__all__ = ["JKR_PULL_OFF", "jkr_load", "jkr_approach", "jkr_zero_load", "jkr_fixed_grip_pull_off"]


#: Load-controlled pull-off of Johnson-Kendall-Roberts 1971, -(3/2) pi R gamma.
JKR_PULL_OFF = -0.75


def jkr_load(A: ArrayLike, mu: float) -> float | np.ndarray:
    """JKR load at contact radius A (Johnson, Kendall & Roberts 1971).

    P = 4 E a^3/(3R) - sqrt(8 pi gamma E a^3) becomes
    F = (2/(3 pi)) A^3 mu^(-3/2) - sqrt(2 A^3 / (pi mu^(3/2))): the load F (units
    2 pi R gamma) at contact radius A (units sqrt(epsilon R)), Tabor parameter mu > 0.

    >>> round(jkr_load((9 * np.pi / 8) ** (1 / 3), 1.0), 12)  # at the pull-off radius
    -0.75
    """
    A = np.asarray(A, dtype=float)
    s = mu**1.5
    return _out(2.0 / (3.0 * math.pi) * A**3 / s - np.sqrt(2.0 * A**3 / (math.pi * s)))


def jkr_approach(A: ArrayLike, mu: float) -> float | np.ndarray:
    """JKR approach at contact radius A (Johnson, Kendall & Roberts 1971).

    delta = a^2/R - sqrt(2 pi gamma a / E) becomes lambda = A^2 - sqrt(2 pi mu^(3/2) A),
    A and mu as in :func:`jkr_load`.  JKR's delta is measured from first touch;
    lambda = delta/epsilon holds to leading order at large mu (lambda ~ mu), an
    O(1) shift being beyond the model.
    """
    A = np.asarray(A, dtype=float)
    return _out(A**2 - np.sqrt(2.0 * math.pi * mu**1.5 * A))


def jkr_zero_load(mu: float) -> tuple[float, float]:
    """JKR contact radius and approach at zero load (Johnson, Kendall & Roberts 1971).

    Returns (A0, lambda0): A0 = (9 pi/2)^(1/3) mu^(1/2) and
    lambda0 = [(9 pi/2)^(2/3) - (2 pi (9 pi/2)^(1/3))^(1/2)] mu, for mu > 0.

    Examples
    --------
    >>> [round(x, 4) for x in jkr_zero_load(1.0)]
    [2.418, 1.9489]
    """
    A0 = (4.5 * math.pi) ** (1.0 / 3.0) * math.sqrt(mu)
    return A0, float(jkr_approach(A0, mu))


def jkr_fixed_grip_pull_off(mu: float) -> tuple[float, float]:
    """JKR pull-off under displacement control, d lambda / dA = 0 (Johnson, Kendall & Roberts 1971).

    Returns (lambda, F) at A = (pi/8)^(1/3) mu^(1/2): lambda = -3 (pi/8)^(2/3) mu and
    F = -5/12 for every mu > 0.

    >>> lam, F = jkr_fixed_grip_pull_off(2.0)
    >>> round(F * 12, 12), round(lam / 2.0, 4)
    (-5.0, -1.6088)
    """
    A = (math.pi / 8.0) ** (1.0 / 3.0) * math.sqrt(mu)
    return float(jkr_approach(A, mu)), float(jkr_load(A, mu))
