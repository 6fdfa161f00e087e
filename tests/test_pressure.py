"""The Lennard-Jones law and its Gauss-Hermite roughness average (eq. 5, 10, 14)."""
import math

import numpy as np
import pytest

from petsc_adhesion.pressure import PressureLaw


def test_smooth_law_is_lennard_jones():
    law = PressureLaw(0.0)
    H = np.linspace(-0.5, 5, 101)
    p, _ = law(H)
    assert np.allclose(p, (H + 1) ** -9 - (H + 1) ** -3, rtol=1e-14, atol=0)
    # zero stress at the equilibrium spacing, h = epsilon
    assert law(np.array([0.0]))[0][0] == 0.0
    # peak attraction 16 gamma / (9 sqrt 3 epsilon) at h = 3^(1/6) epsilon (paper, below eq. 5),
    # in units of 8 gamma / (3 epsilon): 2 / (3 sqrt 3)
    p, dp = law(np.array([3 ** (1 / 6) - 1]))
    assert p[0] == pytest.approx(-2 / (3 * math.sqrt(3)), rel=1e-14)
    assert abs(dp[0]) < 1e-14


@pytest.mark.parametrize("sigma", [0.0, 0.2, 1.0])
def test_derivative_is_exact(sigma):
    law = PressureLaw(sigma)
    H = np.linspace(law.wall + 0.3, law.wall + 6, 57)
    _, dp = law(H)
    eps = 1e-6
    fd = (law(H + eps)[0] - law(H - eps)[0]) / (2 * eps)
    assert np.allclose(dp, fd, rtol=1e-7, atol=1e-12)


def test_small_roughness_is_second_order_correction():
    """E[P(H - S)] = P(H) + sigma^2/2 P''(H) + O(sigma^4) for Gaussian S: the rule is exact on it."""
    H = np.array([0.1, 0.5, 1.0, 2.0])
    smooth = PressureLaw(0.0)
    g = H + 1
    d2p = 90 * g ** -11 - 12 * g ** -5
    d4p = 11880 * g ** -13 - 360 * g ** -7
    for sigma in (2e-3, 1e-3):
        rough = PressureLaw(sigma)
        corr = rough(H)[0] - smooth(H)[0]
        # the next term, sigma^4/8 d4P/dH4, bounds the mismatch
        assert np.allclose(corr, 0.5 * sigma**2 * d2p, rtol=0, atol=sigma**4 * np.abs(d4p).max() / 4)


def test_rule_and_its_wall():
    """The outermost node is a hard wall: 6.63 sigma for 16 points, 14.9 for 64 (NOTES)."""
    law = PressureLaw(1.0, "hermite", 16)
    assert law.weights.sum() == pytest.approx(1.0, rel=1e-14)
    assert law.wall + 1 == pytest.approx(6.63, abs=0.005)
    assert PressureLaw(1.0, "hermite", 64).wall + 1 == pytest.approx(14.9, abs=0.05)
    # the outermost node's normalized weight (NOTES: 1.5e-10)
    assert law.weights.max() > 0.2 and law.weights.min() == pytest.approx(1.5e-10, rel=0.1)


def test_smooth_path_takes_no_quadrature():
    law = PressureLaw(0.0, "hermite", 16)
    assert law.smooth and law.shifts.size == 1 and law.n == 1
    assert PressureLaw(0.3).shifts.size == 16


@pytest.mark.parametrize("sigma", [0.0, 0.5])
def test_closed_gap_is_refused_not_nan(sigma):
    law = PressureLaw(sigma)
    with pytest.raises(FloatingPointError):
        law(np.array([1.0, law.wall]))
    p, dp = law(np.array([law.wall + 1e-3]))
    assert np.isfinite(p).all() and np.isfinite(dp).all()
