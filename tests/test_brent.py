"""petsc_adhesion.brent takes scipy's steps: the same root and the same minimum to the last bit, on functions
of every shape the package meets (polynomials, exponentials, kinks, flat minima, roots at an end), and the
same refusals."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from petsc_adhesion import brent


def _functions():
    rng = np.random.default_rng(2026)
    out = []
    for _ in range(300):
        c = rng.normal(size=4)
        out.append(lambda x, c=c: c[0] + c[1] * x + c[2] * x * x + c[3] * x ** 3)
    for _ in range(100):
        a, b = rng.uniform(0.1, 5.0, 2)
        out.append(lambda x, a=a, b=b: math.exp(a * x) - b)
    for _ in range(100):
        a = rng.uniform(-1.0, 1.0)
        out.append(lambda x, a=a: abs(x - a) - 0.1 + 1e-3 * x)           # kinks
    for _ in range(100):
        a, k = rng.uniform(-1.0, 1.0), rng.integers(2, 8)
        out.append(lambda x, a=a, k=k: (x - a) ** (2 * k) * (1 + x * x) - 1e-3)   # flat
    return out


FUNCTIONS = _functions()


def test_the_roots_are_scipys():
    compared = 0
    for f in FUNCTIONS:
        for a, b, xtol in ((-2.0, 2.0, 2e-12), (-1.0, 3.0, 1e-10), (0.0, 1.0, 1e-14), (-3.0, 0.5, 1e-6)):
            try:
                want = brentq(f, a, b, xtol=xtol, rtol=brent.RTOL, maxiter=100)
            except ValueError:
                with pytest.raises(ValueError):
                    brent.root(f, a, b, xtol=xtol)
                continue
            assert brent.root(f, a, b, xtol=xtol) == want
            compared += 1
    assert compared > 500


def test_the_minima_are_scipys():
    for f in FUNCTIONS:
        for a, b, xatol in ((-2.0, 2.0, 1e-5), (-1.0, 3.0, 1e-10), (0.0, 1.0, 1e-3)):
            want = minimize_scalar(f, bounds=(a, b), method="bounded", options={"xatol": xatol}).x
            assert brent.minimum(f, a, b, xatol=xatol) == want


def test_ends_and_refusals_are_scipys():
    assert brent.root(lambda x: x, 0.0, 1.0) == brentq(lambda x: x, 0.0, 1.0) == 0.0
    assert brent.root(lambda x: x - 1.0, 0.0, 1.0) == 1.0
    with pytest.raises(ValueError, match="different signs"):
        brent.root(lambda x: x * x + 1, -1.0, 1.0)
    with pytest.raises(ValueError, match="xtol"):
        brent.root(lambda x: x, -1.0, 1.0, xtol=0.0)
    f = lambda x: math.exp(5 * x) - 2.0                   # noqa: E731
    for err in (RuntimeError,):
        with pytest.raises(err, match="converge"):
            brentq(f, -1.0, 1.0, xtol=1e-15, maxiter=2)
        with pytest.raises(err, match="converge"):
            brent.root(f, -1.0, 1.0, xtol=1e-15, maxiter=2)
