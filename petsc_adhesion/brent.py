"""Brent's root finder and Brent's bounded minimizer, as scipy.optimize's ``brentq`` and
``minimize_scalar(method="bounded")`` compute them (scipy 1.10), step for step.

Importing scipy.optimize costs a run about 130 ms of its start-up (it loads
scipy.sparse, scipy.linalg and the rest of the optimizers); the package needs
only these two, on scalars.  Each takes the same steps as scipy's (Brent,
Algorithms for Minimization without Derivatives, 1973, ch. 3-5), so that the
events, the peak attraction and the reference solutions are the same numbers
to the last bit (tests/test_brent.py compares them on many functions).  A leaf
module: it imports nothing of the package.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["root", "minimum", "RTOL"]

#: The smallest relative tolerance of :func:`root`, scipy's: 4 machine epsilons.
RTOL = 4 * 2.220446049250313e-16


def root(f, a: float, b: float, xtol: float = 2e-12, rtol: float = RTOL, maxiter: int = 100) -> float:
    """The zero of f in [a, b] by Brent's method (inverse quadratic interpolation, secant, bisection).

    f(a) and f(b) must have opposite signs (ValueError otherwise); the result lies within
    xtol + rtol |x| of a zero.  RuntimeError when maxiter iterations do not reach it.

    >>> round(root(lambda x: x * x - 2.0, 0.0, 2.0), 12)
    1.414213562373
    """
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {RTOL:g})")
    xpre, xcur = float(a), float(b)
    xblk = fblk = spre = scur = 0.0
    fpre, fcur = float(f(xpre)), float(f(xcur))
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise ValueError("f(a) and f(b) must have different signs")
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:                                    # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:                                               # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry                         # a good short step
            else:
                spre = scur = sbis                              # bisect
        else:
            spre = scur = sbis                                  # bisect
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(f(xcur))
    raise RuntimeError(f"Failed to converge after {maxiter} iterations, value is {xcur}")


def minimum(f, a: float, b: float, xatol: float = 1e-5, maxiter: int = 500) -> float:
    """The x in [a, b] where f is least, by Brent's bounded method (golden sections and parabolas), to about
    xatol; the last point reached after maxiter evaluations.  f gets numpy floats, as from scipy.

    >>> round(float(minimum(lambda x: (x - 0.3) ** 2, 0.0, 1.0, xatol=1e-10)), 8)
    0.3
    """
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ValueError("Optimization bounds must be finite scalars.")
    if a > b:
        raise ValueError("The lower bound exceeds the upper bound.")
    # Python floats inside (IEEE doubles: numpy's arithmetic to the bit, without its scalars' overhead, which
    # was most of a Maugis-Dugdale pull-off's cost); f gets numpy floats, as scipy gives them
    a, b = float(a), float(b)
    f64 = np.float64
    sqrt_eps = math.sqrt(2.2e-16)
    golden_mean = 0.5 * (3.0 - math.sqrt(5.0))
    fulc = a + golden_mean * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    fx = float(f(f64(xf)))
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = True
        if abs(e) > tol1:                                      # a parabolic fit
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r, e = e, rat
            if abs(p) < abs(0.5 * q * r) and p > q * (a - xf) and p < q * (b - xf):
                rat = (p + 0.0) / q
                x = xf + rat
                if (x - a) < tol2 or (b - x) < tol2:
                    rat = tol1 * _sign1(xm - xf)
            else:
                golden = True
        if golden:                                             # a golden-section step
            e = (a - xf) if xf >= xm else (b - xf)
            rat = golden_mean * e
        x = xf + _sign1(rat) * _larger(abs(rat), tol1)
        fu = float(f(f64(x)))
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxiter:
            break
    return f64(xf)  # type: ignore[return-value]


def _sign1(x: float) -> float:
    """numpy's sign(x) + (x == 0), scipy's: 1 at and above 0, -1 below, NaN for NaN."""
    return x if x != x else (1.0 if x >= 0.0 else -1.0)


def _larger(x: float, y: float) -> float:
    """numpy's maximum(x, y): NaN where either is."""
    return x if x != x else y if y != y else (x if x >= y else y)
