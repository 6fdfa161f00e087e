"""Closed-form reference solutions, in the project's dimensionless units.

One home for every formula that tests and code compare against, so none is
copied. Units (Cheng, Dunn & Brach 2002): approach lambda = alpha/epsilon,
radii r and contact radii A in sqrt(epsilon R), pressures in 8 gamma/(3 epsilon)
(P > 0 repulsion), loads F in 2 pi R gamma (F < 0 attraction), Tabor parameter
mu = (R gamma^2 / (E^2 epsilon^3))^(1/3) with E the combined modulus of eq. (2).
The influence operator is W(r) = int t/(t + r) K(m) p(t) dt, m = 4 t r/(t + r)^2,
so that the deflection in eq. (12) is c W, c = 32 mu^(3/2)/(3 pi).

Pure numpy/scipy: no PETSc here.
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize_scalar
from scipy.special import ellipe, ellipk

__all__ = [
    "RIGID_EQUILIBRIUM",
    "DMT_PULL_OFF",
    "JKR_PULL_OFF",
    "rigid_load",
    "load_beyond",
    "load_beyond_rates",
    "far_deflection",
    "disk_deflection",
    "hertz_deflection",
    "jkr_load",
    "jkr_approach",
    "jkr_zero_load",
    "jkr_fixed_grip_pull_off",
    "maugis_parameter",
    "maugis_dugdale_curve",
    "maugis_dugdale_pull_off",
]

#: Approach of zero load of the rigid sphere, 1 - 2^(-1/3) = 0.20630 (root of eq. 28).
RIGID_EQUILIBRIUM = 1.0 - 2.0 ** (-1.0 / 3.0)
#: Pull-off of the rigid sphere (Derjaguin-Muller-Toporov; eq. 28 at lambda = 0).
DMT_PULL_OFF = -1.0
#: Load-controlled pull-off of Johnson-Kendall-Roberts 1971, -(3/2) pi R gamma.
JKR_PULL_OFF = -0.75

# Dugdale stress = peak Lennard-Jones traction 16 gamma / (9 sqrt(3) epsilon) in
# Maugis' lambda = 2 sigma_0 (R / (pi w K^2))^(1/3), K = 4E/3: lambda_MD = this * mu.
_MAUGIS_PER_TABOR = 32.0 / (9.0 * math.sqrt(3.0)) * (9.0 / (16.0 * math.pi)) ** (1.0 / 3.0)
# Maugis' Abar, Pbar, Deltabar into A / sqrt(mu), F, lambda / mu.
_MD_RADIUS = (3.0 * math.pi / 4.0) ** (1.0 / 3.0)
_MD_APPROACH = (9.0 * math.pi**2 / 16.0) ** (1.0 / 3.0)


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


def _md_curve(lmd: float, m_minus_1: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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


def _md_pull_off(mu: float) -> float:
    if mu == 0.0:
        return DMT_PULL_OFF
    lmd = float(maugis_parameter(mu))
    # x = log(m - 1): the minimum moves from m - 1 ~ lmd^-3/2 (DMT) to ~ lmd^-2
    # (JKR), decades apart; a grid over x brackets it before Brent refines it
    x = np.linspace(math.log(1e-14), math.log(1e14), 561)
    P = _md_curve(lmd, np.exp(x))[1]
    i = int(np.argmin(P))
    lo, hi = x[max(i - 1, 0)], x[min(i + 1, x.size - 1)]
    res = minimize_scalar(lambda y: float(_md_curve(lmd, math.exp(y))[1]), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-10})
    return 0.5 * min(float(res.fun), float(P[i]))


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
