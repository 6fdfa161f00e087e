"""petsc_adhesion.model.reference against independent truth.

Every check goes another way than the module: adaptive quadrature of the
integral the closed form evaluates, a numerical extremum or root of a curve,
the published formula in physical units, or numbers from another package.
"""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad
from scipy.optimize import brentq, minimize_scalar
from scipy.special import ellipkm1

from petsc_adhesion.model.parameters import tabor
from petsc_adhesion.model.reference.rigid import DMT_PULL_OFF, RIGID_EQUILIBRIUM, load_beyond, rigid_load
from petsc_adhesion.model.reference.jkr import JKR_PULL_OFF, jkr_approach, jkr_fixed_grip_pull_off, jkr_load, jkr_zero_load
from petsc_adhesion.model.reference.elastic import disk_deflection, hertz_deflection
from petsc_adhesion.model.reference.maugis_dugdale import maugis_dugdale_curve, maugis_dugdale_pull_off, maugis_parameter


# --- rigid sphere, eqs. (26)-(28) --------------------------------------------

def lj(g):
    """Eq. (14) with sigma = 0 at gap g = H + 1: P > 0 is repulsion."""
    return g ** -9 - g ** -3


def eq26_rigid(lam, lo=0.0):
    """(8/3) int_lo^inf P(H) r dr with the rigid gap H = -lambda + r^2/2 of eq. (27)."""
    with warnings.catch_warnings():
        # near zero load the two terms cancel and quad cannot reach epsrel; abs tolerance then
        warnings.simplefilter("ignore", IntegrationWarning)
        val, err = quad(lambda r: lj(1.0 - lam + 0.5 * r * r) * r, lo, np.inf, epsabs=1e-15, epsrel=1e-12,
                        limit=200)
    return 8.0 / 3.0 * val


@pytest.mark.parametrize("lam", [-3.0, -0.5, 0.0, 0.1, RIGID_EQUILIBRIUM, 0.4])
def test_rigid_load_is_eq26_of_rigid_gap(lam):
    assert rigid_load(lam) == pytest.approx(eq26_rigid(lam), rel=1e-10, abs=1e-13)


def test_rigid_load_known_values():
    assert rigid_load(0.0) == pytest.approx(-1.0, abs=1e-15)
    assert rigid_load(0.0) == DMT_PULL_OFF
    assert brentq(rigid_load, 0.1, 0.3, xtol=1e-15) == pytest.approx(RIGID_EQUILIBRIUM, abs=1e-14)
    assert RIGID_EQUILIBRIUM == pytest.approx(0.20630, abs=5e-6)
    res = minimize_scalar(rigid_load, bounds=(-1.0, 0.2), method="bounded", options={"xatol": 1e-10})
    assert res.x == pytest.approx(0.0, abs=1e-7)
    assert res.fun == pytest.approx(-1.0, abs=1e-12)


def test_rigid_load_is_vectorised():
    lam = np.array([[-1.0, 0.0], [0.1, 0.2]])
    F = rigid_load(lam)
    assert F.shape == lam.shape
    assert F[0, 1] == -1.0
    assert isinstance(rigid_load(0.0), float)


@pytest.mark.parametrize("rmax", [2.0, 5.0, 10.0, 20.0])
def test_load_beyond_matches_quadrature(rmax):
    lam = np.array([-2.0, 0.0, 0.15, RIGID_EQUILIBRIUM])
    got = load_beyond(rmax, lam)
    assert got.shape == lam.shape
    want = [eq26_rigid(x, lo=rmax) for x in lam]
    np.testing.assert_allclose(got, want, rtol=1e-10)
    assert np.all(got < 0)


def test_load_beyond_size_at_paper_domain():
    # the figure docs/model.md quotes for r_m = 10: about 5.13e-4 of attraction
    assert load_beyond(10.0, 0.0) == pytest.approx(-5.13e-4, abs=5e-7)


# --- influence operator closed forms ------------------------------------------

def operator_quad(p, r, a):
    """W(r) = int_0^a t/(t + r) K(m) p(t) dt by adaptive quadrature.

    K(m) through ellipkm1(1 - m), 1 - m = ((t - r)/(t + r))^2, which keeps its
    digits near t = r; the log singularity there is put at an interval end.
    """
    def f(t):
        return t / (t + r) * ellipkm1(((t - r) / (t + r)) ** 2) * p(t)

    cuts = [0.0, r, a] if 0.0 < r < a else [0.0, a]
    total = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            val, err = quad(f, lo, hi, epsabs=0, epsrel=1e-13, limit=400)
            total += val
    return total


RADII = [0.0, 0.3, 0.77, 0.999, 1.0, 1.001, 1.4, 3.0, 25.0]


@pytest.mark.parametrize("a", [0.4, 1.0, 6.5])
def test_disk_deflection_matches_quadrature(a):
    r = np.array(RADII) * a
    want = [operator_quad(lambda t: 1.0, x, a) for x in r]
    np.testing.assert_allclose(disk_deflection(r, a), want, rtol=1e-12)   # measured 7e-14


@pytest.mark.parametrize("a", [0.4, 1.0, 6.5])
def test_hertz_deflection_matches_quadrature(a):
    r = np.array(RADII) * a
    want = [operator_quad(lambda t: math.sqrt(max(1.0 - (t / a) ** 2, 0.0)), x, a) for x in r]
    np.testing.assert_allclose(hertz_deflection(r, a), want, rtol=1e-12)  # measured 4e-14


def test_deflections_far_field_is_point_load():
    # far away any load acts as a point force: W -> K(0) (int p t dt) / r, K(0) = pi/2
    a, r = 1.0, 1e4
    assert disk_deflection(r, a) == pytest.approx(math.pi / 2 * (a * a / 2) / r, rel=1e-7)
    assert hertz_deflection(r, a) == pytest.approx(math.pi / 2 * (a * a / 3) / r, rel=1e-7)


# --- JKR ----------------------------------------------------------------------

MUS = [0.3, 1.0, 5.0, 50.0]


def test_jkr_against_physical_units():
    # JKR 1971 in SI, scaled by hand; mu from the project's own tabor()
    R, gamma, E, eps = 2e-6, 0.08, 3e9, 3.5e-10
    mu = tabor(R, gamma, E, eps)
    a = np.linspace(0.01, 3.0, 25) * math.sqrt(eps * R) * math.sqrt(mu)
    P = 4 * E * a ** 3 / (3 * R) - np.sqrt(8 * math.pi * gamma * E * a ** 3)
    delta = a ** 2 / R - np.sqrt(2 * math.pi * gamma * a / E)
    A = a / math.sqrt(eps * R)
    np.testing.assert_allclose(jkr_load(A, mu), P / (2 * math.pi * R * gamma), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(jkr_approach(A, mu), delta / eps, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("mu", MUS)
def test_jkr_load_controlled_pull_off(mu):
    res = minimize_scalar(lambda A: jkr_load(A, mu), bounds=(1e-6, 10 * math.sqrt(mu)), method="bounded",
                          options={"xatol": 1e-12})
    assert res.fun == pytest.approx(JKR_PULL_OFF, abs=1e-12)
    assert JKR_PULL_OFF == -0.75


@pytest.mark.parametrize("mu", MUS)
def test_jkr_zero_load(mu):
    A0, lam0 = jkr_zero_load(mu)
    root = brentq(lambda A: jkr_load(A, mu), 0.5 * math.sqrt(mu), 10 * math.sqrt(mu), xtol=1e-14)
    assert A0 == pytest.approx(root, rel=1e-12)
    assert A0 / math.sqrt(mu) == pytest.approx(2.418, abs=5e-4)
    c = (4.5 * math.pi) ** (2 / 3) - math.sqrt(2 * math.pi * (4.5 * math.pi) ** (1 / 3))
    assert c == pytest.approx(1.949, abs=5e-4)
    assert lam0 == pytest.approx(c * mu, rel=1e-12)


@pytest.mark.parametrize("mu", MUS)
def test_jkr_fixed_grip_pull_off(mu):
    res = minimize_scalar(lambda A: jkr_approach(A, mu), bounds=(1e-8, 5 * math.sqrt(mu)), method="bounded",
                          options={"xatol": 1e-12})
    lam, F = jkr_fixed_grip_pull_off(mu)
    assert lam == pytest.approx(res.fun, rel=1e-12)
    assert jkr_load(res.x, mu) == pytest.approx(-5 / 12, abs=1e-6)   # A is found to sqrt(eps) only
    assert F == pytest.approx(-5 / 12, abs=1e-14)


# --- Maugis-Dugdale -------------------------------------------------------------

# From Adhesion 0.93 (PyPI `adhesion`, Adhesion.ReferenceSolutions.MaugisDugdale),
# installed in a throw-away venv: lambda_MD = maugis_parameter(radius=1,
# elastic_modulus=mu**-1.5, work_of_adhesion=1, cohesive_stress=16/(9*sqrt(3)))
# and the pull-off = min over Abar of _load(Abar, lambda_MD) / 2 (their route:
# brentq for m at given Abar, then bounded Brent over Abar, xatol 1e-12).
ADHESION_MAUGIS_PARAMETER = {0.1: 0.11570116348507999, 1.0: 1.1570116348507995, 2.0: 2.314023269701599}
ADHESION_PULL_OFF = {
    0.01: -0.998935351471, 0.1: -0.969929683508, 0.3: -0.894360651014, 0.5: -0.845240501891,
    1.0: -0.791135641415, 2.0: -0.763417335822, 3.0: -0.756384396288, 5.0: -0.752390104037,
    10.0: -0.750608117002,
}
# The Lennard-Jones pull-off of this model as the ContactMechanics + Adhesion packages compute it (a
# Lennard-Jones law on an FFT half-space; benchmarks/peers.py runs them, docs/performance.md shows their
# accuracy): a band for the Maugis-Dugdale comparison below only, not a reference value
LJ_PULL_OFF = {0.1: -0.9845, 0.5: -0.8937, 1.0: -0.8352, 2.0: -0.7917}


def test_maugis_parameter_from_peak_stress():
    # Maugis' definition in SI, with sigma_0 the peak of eq. (5) found numerically
    R, gamma, E, eps = 2e-6, 0.08, 3e9, 3.5e-10
    # eq. (5) is tensile for h > epsilon; x = h / epsilon
    res = minimize_scalar(lambda x: -8 * gamma / (3 * eps) * (x ** -3 - x ** -9),
                          bounds=(1.0, 3.0), method="bounded", options={"xatol": 1e-10})
    sigma0 = -res.fun
    assert res.x == pytest.approx(3 ** (1 / 6), abs=1e-8)
    K = 4 * E / 3
    lam_md = 2 * sigma0 * (R / (math.pi * gamma * K ** 2)) ** (1 / 3)
    assert maugis_parameter(tabor(R, gamma, E, eps)) == pytest.approx(lam_md, rel=1e-10)
    for mu, val in ADHESION_MAUGIS_PARAMETER.items():
        assert maugis_parameter(mu) == pytest.approx(val, rel=1e-14)


def test_maugis_dugdale_matches_adhesion_package():
    mu = np.array(list(ADHESION_PULL_OFF))
    np.testing.assert_allclose(maugis_dugdale_pull_off(mu), list(ADHESION_PULL_OFF.values()), rtol=0, atol=2e-11)


def test_maugis_dugdale_scalar_load_is_the_curves():
    # the pull-off's minimization reads the load one m at a time, now in Python floats: numpy's curve at that
    # one m (what it read before) is the reference, on both sides of the series for small sqrt(m^2 - 1) and
    # over the whole range of m.  The same operations in the same order, but not to the bit on every machine:
    # where numpy has AVX-512 kernels its arctan and powers differ from the C library's in the last bits
    # (measured: 27% of arctan's values on [0.01, 100]), and f2 = s arctan s - q cancels them up, to 3.5e-14 of
    # the larger of Pbar's two terms A^3 and lambda A^2 (s + m^2 t) on this grid; on machines without such
    # kernels the two were equal to the bit.  1e-13 of that scale is some 450 ulp: a wrong term or order is
    # off by far more
    from petsc_adhesion.model.reference.maugis_dugdale import _md_curve, _md_load

    rng = np.random.default_rng(7)
    q = np.r_[np.exp(rng.uniform(math.log(1e-14), math.log(1e14), 400)), 0.0199**2 / 2, 0.0201**2 / 2]
    for lmd in 10 ** rng.uniform(-4, 4, 40):
        for x in q:
            A, P, _ = (float(v) for v in _md_curve(float(lmd), float(x)))
            scale = max(A**3, A**3 - P)           # the two terms of Pbar = A^3 - lmd A^2 (s + m^2 t)
            assert abs(_md_load(float(lmd), float(x)) - P) <= 1e-13 * scale, (lmd, x)


def test_maugis_dugdale_limits():
    # measured: 1 + F = 3.4e-5 at mu = 1e-3 (goes as mu^1.5),
    #           F + 0.75 = -2.4e-5 at mu = 50 (goes as mu^-2)
    assert maugis_dugdale_pull_off(1e-3) == pytest.approx(DMT_PULL_OFF, abs=1e-4)
    assert maugis_dugdale_pull_off(50.0) == pytest.approx(JKR_PULL_OFF, abs=1e-4)
    assert maugis_dugdale_pull_off(0.0) == DMT_PULL_OFF
    assert maugis_dugdale_pull_off(1e-3) < maugis_dugdale_pull_off(50.0)


def test_maugis_dugdale_monotone_and_smooth():
    mu = np.logspace(-3, math.log10(50.0), 80)
    F = maugis_dugdale_pull_off(mu)
    d1, d2 = np.diff(F), np.diff(F, 2)
    assert np.all(d1 > 0)
    assert np.all(F > -1.0) and np.all(F < -0.75)
    # a mis-bracketed minimum would show as a kink; measured ratio 0.084
    assert np.max(np.abs(d2)) < 0.15 * np.max(np.abs(d1))


def test_maugis_dugdale_below_lennard_jones():
    # Maugis-Dugdale's step law pulls off at 1.5 to 6% less than the Lennard-Jones law for mu in 0.1 to 3
    # (LJ_PULL_OFF against maugis_dugdale_pull_off: 1.5% at mu = 0.1, 5.4% at mu = 0.5, 3.6% at mu = 2)
    for mu, F_lj in LJ_PULL_OFF.items():
        shortfall = 1.0 - maugis_dugdale_pull_off(mu) / F_lj
        assert 0.01 < shortfall < 0.07, (mu, shortfall)


def _curve_sample(mu):
    A, F, lam = maugis_dugdale_curve(mu, 1.0 + np.logspace(-12, 12, 2001))
    keep = (A > 0.8 * math.sqrt(mu)) & (A < 3.0 * math.sqrt(mu))
    assert keep.sum() > 20
    return A[keep], F[keep], lam[keep]


def test_maugis_dugdale_curve_tends_to_jkr():
    # checks the conversion of Abar, Pbar, Deltabar against JKR in our units
    errors = []
    for mu in (500.0, 5000.0):
        A, F, lam = _curve_sample(mu)
        errors.append((np.max(np.abs(F - jkr_load(A, mu))), np.max(np.abs(lam - jkr_approach(A, mu))) / mu))
    (eF1, eL1), (eF2, eL2) = errors
    assert eF1 < 2e-5 and eL1 < 3e-5          # measured 6.8e-6 and 1.0e-5
    assert eF1 / eF2 > 50 and eL1 / eL2 > 50  # mu^-2: 101 and 101


def test_maugis_dugdale_curve_tends_to_dmt():
    # DMT: Hertz, F = (2/(3 pi)) A^3 mu^-3/2 and lambda = A^2, shifted by the pull-off -1
    errors = []
    for mu in (1e-4, 1e-5):
        A, F, lam = _curve_sample(mu)
        errors.append((np.max(np.abs(F - (2 / (3 * math.pi) * A ** 3 * mu ** -1.5 - 1.0))),
                       np.max(np.abs(lam - A ** 2)) / mu))
    (eF1, eL1), (eF2, eL2) = errors
    assert eF1 < 2e-3 and eL1 < 5e-2          # measured 9.0e-4 and 2.9e-2
    assert eF1 / eF2 > 7 and eL1 / eL2 > 2.5  # mu^1 and mu^(1/2): 9.8 and 3.2
