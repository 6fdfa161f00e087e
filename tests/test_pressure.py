"""The Lennard-Jones law and its roughness averages (eq. 5, 7, 10, 14): Gauss-Hermite, and heights bounded above."""
import math

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad

from petsc_adhesion.model.pressure import HistogramLaw, PressureLaw, WallLaw, law_for
from petsc_adhesion.model.roughness import Measured, TruncatedGaussian, Weibull


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
    """The outermost node is a hard wall: 6.63 sigma for 16 points, 14.9 for 64 (docs/model.md)."""
    law = PressureLaw(1.0, "hermite", 16)
    assert law.weights.sum() == pytest.approx(1.0, rel=1e-14)
    assert law.wall + 1 == pytest.approx(6.63, abs=0.005)
    assert PressureLaw(1.0, "hermite", 64).wall + 1 == pytest.approx(14.9, abs=0.05)
    # the outermost node's normalized weight (docs/model.md: 1.5e-10)
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


def test_closed_gap_is_refused_exactly_at_the_wall():
    """At H = wall the gap H + 1 - sqrt(2) sigma x_n rounds to 1e-17 for (0.3, 2 points): refused all the same."""
    law = PressureLaw(0.3, "hermite", 2)
    assert float(law.gaps(np.array([law.wall])).min()) > 0
    with pytest.raises(FloatingPointError):
        law(np.array([law.wall]))


# -- averages over heights bounded above (roughness.py) ----------------------------

def rough_laws(sigma=0.2):
    """One law per family: truncated Gaussian, skewed Weibull, measured histogram."""
    z = np.random.default_rng(7).standard_normal(20000)
    return {"truncated_gaussian": WallLaw(TruncatedGaussian(sigma, 3.0)),
            "weibull": WallLaw(Weibull(sigma, -1.0)),
            "measured": HistogramLaw(Measured(sigma * z[np.abs(z) <= 3]))}


def lj_derivatives(x):
    """sigma_LJ(x) and its first four derivatives (eq. 5)."""
    return (x ** -9 - x ** -3, -9 * x ** -10 + 3 * x ** -4, 90 * x ** -11 - 12 * x ** -5,
            -990 * x ** -12 + 60 * x ** -6, 11880 * x ** -13 - 360 * x ** -7)


def moments(law, m=4):
    """E[S^j], j = 1..m, of the law's height density, by quad on its pdf."""
    dist = law.dist
    lo = dist.bottom if math.isfinite(dist.bottom) else dist.top - 60 * dist.rms
    edges = getattr(dist, "edges", np.linspace(lo, dist.top, 41))
    return [sum(quad(lambda S: S ** j * float(dist.pdf(S)), a, b, epsabs=1e-300, epsrel=1e-13)[0]
                for a, b in zip(edges[:-1], edges[1:])) for j in range(1, m + 1)]


@pytest.mark.parametrize("name", ["truncated_gaussian", "weibull", "measured"])
def test_rough_law_derivative_matches_differences(name):
    """dP/dH against central differences of P, from 1e-4 rms above the wall to far away."""
    law = rough_laws()[name]
    d = law.sigma * np.geomspace(1e-4, 300, 40)
    H = law.wall + d
    p, dp = law(H)
    # fourth order with h = d/1000: truncation ~ 1e-9, and the rounding of the gap H + 1 - S_max
    # (eps |H| absolute) stays ~ 1e-9 of dP however close to the wall
    h = 1e-3 * d
    fd = (8 * (law(H + h)[0] - law(H - h)[0]) - (law(H + 2 * h)[0] - law(H - 2 * h)[0])) / (12 * h)
    assert np.all(np.abs(fd - dp) <= 1e-8 * (np.abs(dp) + 10 * np.abs(p) / d)), np.max(np.abs(fd / dp - 1))


@pytest.mark.parametrize("name", ["truncated_gaussian", "weibull", "measured"])
def test_rough_law_wall_is_the_highest_asperity(name):
    """wall = S_max - 1; at or below it the law refuses, just above it the repulsion diverges as stated.

    Near the top the density is q(u) ~ q0 u^beta, so P ~ q0 B(beta + 1, 8 - beta) d^(beta - 8)
    (beta = 0: q0 / (8 d^8)), d = H + 1 - S_max.
    """
    law = rough_laws()[name]
    assert law.wall == law.dist.top - 1.0 and not law.smooth
    with pytest.raises(FloatingPointError):
        law(np.array([law.wall + 1.0, law.wall]))
    with pytest.raises(FloatingPointError):
        law(np.array([law.wall - 0.5]))
    dist = law.dist
    if name == "weibull":
        k, lam = dist.shape, dist.scale
        q0, beta = k / lam ** k, k - 1
    else:
        q0, beta = float(dist.pdf(dist.top)), 0.0
    d = 1e-4 * law.sigma
    p, dp = law(np.array([law.wall + d]))
    asymptote = q0 * math.gamma(beta + 1) * math.gamma(8 - beta) / math.gamma(9) * d ** (beta - 8)
    assert p[0] == pytest.approx(asymptote, rel=1e-3) and dp[0] < 0


@pytest.mark.parametrize("name", ["truncated_gaussian", "weibull", "measured"])
def test_small_roughness_is_the_moment_expansion(name):
    """E[P(H - S)] = P - m1 P' + m2/2 P'' - m3/6 P''' + O(sigma^4), m_j the moments of the density.

    Zero mean and variance sigma^2 (up to truncation and binning) give P + sigma^2/2 P''
    for symmetric heights; the skewed Weibull adds - gamma sigma^3/6 P'''.
    """
    H = np.array([0.1, 0.5, 1.0, 2.0])
    residual = []
    for sigma in (2e-3, 1e-3):
        law = rough_laws(sigma)[name]
        m1, m2, m3, m4 = moments(law)
        P, d1, d2, d3, d4 = lj_derivatives(H + 1)
        residual.append(law(H)[0] - P - (-m1 * d1 + m2 / 2 * d2 - m3 / 6 * d3))
        # bounded by the next term, m4/24 times the fourth derivative
        assert np.all(np.abs(residual[-1]) <= m4 / 24 * np.abs(d4).max() * 2)
        if name == "weibull":
            assert m2 == pytest.approx(sigma ** 2, rel=1e-10) and m3 == pytest.approx(-sigma ** 3, rel=1e-9)
    # fourth order: halving sigma divides the remainder by 16 (where it is well above rounding)
    assert np.abs(residual[0]).max() / np.abs(residual[1]).max() == pytest.approx(16, rel=0.02)


def test_truncated_gaussian_approaches_hermite_where_that_rule_is_accurate():
    """For H + 1 >= 12 sigma the 16-point rule agrees with 32 points and, as K grows, with the truncated law.

    Measured differences to 16 points at 12-50 sigma: K = 3 1e-3..6e-5, K = 5 1e-6..4e-8,
    K = 8 below 1e-13 (tail weight 1e-15).  Near the rule's wall (6.63 sigma) it is
    not an average of anything: at 7 sigma it is off by 100 %.
    """
    for sigma in (0.2, 1.0):
        H = np.array([12.0, 15.0, 20.0, 30.0, 50.0]) * sigma - 1
        h16 = PressureLaw(sigma, "hermite", 16)(H)[0]
        assert np.allclose(PressureLaw(sigma, "hermite", 32)(H)[0], h16, rtol=1e-13, atol=0)
        diffs = [np.abs(WallLaw(TruncatedGaussian(sigma, K))(H)[0] / h16 - 1) for K in (3, 4, 5, 6, 7, 8)]
        assert all(np.all(a > b) for a, b in zip(diffs[:-2], diffs[1:-1]))
        assert diffs[0].max() < 2e-3 and diffs[2].max() < 2e-6 and diffs[-1].max() < 1e-12
    H = np.array([7 * 0.2 - 1])
    assert abs(PressureLaw(0.2, "hermite", 16)(H)[0][0] / WallLaw(TruncatedGaussian(0.2, 6.0))(H)[0][0] - 1) > 0.5


def test_measured_heights_approach_the_truncated_gaussian():
    """1e5 Gaussian heights cut at 3 sigma (seed fixed): the histogram law is the truncated one within sampling error.

    Standard error of the mean of sigma_LJ(x - S) over N independent heights, with the
    shift to their own mean: (sd[sigma_LJ] + |E sigma_LJ'| rms) / sqrt(N); binning adds
    w^2/24 |E sigma_LJ''|.  Measured: within 0.6 standard errors from 0.5 sigma above the
    wall on.
    """
    sigma = 0.2
    z = np.random.default_rng(2002).standard_normal(200000)
    measured = HistogramLaw(Measured(sigma * z[np.abs(z) <= 3][:100000]))
    tg = TruncatedGaussian(sigma, 3.0)
    exact = WallLaw(tg)
    w = np.diff(measured.edges)[0]
    for x in 3 * sigma + sigma * np.array([0.5, 1.0, 2.0, 4.5, 12.0]):
        def E(f):
            return quad(lambda S: f(x - S) * float(tg.pdf(S)), -tg.top, tg.top, epsabs=0, epsrel=1e-12, limit=200)[0]
        sd = math.sqrt(E(lambda g: (g ** -9 - g ** -3) ** 2) - E(lambda g: g ** -9 - g ** -3) ** 2)
        se = (sd + abs(E(lambda g: -9 * g ** -10 + 3 * g ** -4)) * tg.rms) / math.sqrt(100000)
        bias = w ** 2 / 24 * abs(E(lambda g: 90 * g ** -11 - 12 * g ** -5))
        H = np.array([x - 1])
        assert abs(measured(H)[0][0] - exact(H)[0][0]) <= 3 * se + bias


def reference(dist, H: float) -> float:
    """E[sigma_LJ(H + 1 - S)] by quad on the density, in v = log(1 + (S_max - S)/d) (an exact substitution).

    Panels of 1 in v (the wall on the scale d), of rms/2 in S, and the bins of a histogram.
    """
    d = H + 1 - dist.top
    lo = dist.bottom if math.isfinite(dist.bottom) else dist.top - 60 * dist.rms
    U = dist.top - lo
    V = math.log1p(U / d)
    breaks = {0.0, V} | set(np.arange(1.0, V, 1.0))
    breaks |= {math.log1p(u / d) for u in np.arange(dist.rms / 2, U, dist.rms / 2)}
    breaks |= {math.log1p((dist.top - e) / d) for e in getattr(dist, "edges", [])[:-1]}
    edges = sorted(breaks)

    def f(v):
        g = d * math.exp(v)
        return float(dist.pdf(dist.top - d * math.expm1(v))) * (g ** -9 - g ** -3) * g

    return sum(quad(f, a, b, epsabs=0, epsrel=1e-13, limit=200)[0] for a, b in zip(edges[:-1], edges[1:]))


@pytest.mark.filterwarnings("ignore", category=IntegrationWarning)
@pytest.mark.parametrize("name", ["truncated_gaussian", "weibull", "measured"])
def test_error_estimate(name):
    """error(H) <= 1e-10 |P|, and |P - quad| <= error(H) + the accuracy of quad, d from 1e-4 rms on."""
    law = rough_laws()[name]
    H = law.wall + law.sigma * np.array([1e-4, 1e-2, 0.3, 3.0, 30.0])
    p = law(H)[0]
    err = law.error(H)
    assert np.all(err <= 1e-10 * np.abs(p))
    for h, pk, ek in zip(H, p, err):
        ref = reference(law.dist, h)
        assert abs(pk - ref) <= ek + 1e-12 * abs(ref), (h, pk / ref - 1, ek / abs(ref))


@pytest.mark.filterwarnings("ignore", category=IntegrationWarning)
def test_error_estimate_tracks_the_error_below_the_designed_range():
    """Below d = 1e-5 rms the rule loses digits, and error(H) says how many.

    Truncated Gaussian against quad: measured 1.2e-7, 6.5e-9, 1.3e-10 at d = 1e-8, 1e-7,
    1e-6 rms, estimated the same to 1 %.  Weibull (skewness -1) against mpmath, whose
    density at depth u is written here afresh: 4.5e-9 at d = 1e-9 rms, estimated alike.
    """
    law = rough_laws()["truncated_gaussian"]
    for dr in (1e-8, 1e-7, 1e-6):
        H = law.wall + law.sigma * dr
        true = abs(law(np.array([H]))[0][0] - reference(law.dist, H))
        assert law.error(np.array([H]))[0] == pytest.approx(true, rel=0.05)
    mp = pytest.importorskip("mpmath")
    law = rough_laws()["weibull"]
    H = law.wall + law.sigma * 1e-9
    with mp.workdps(20):
        k, lam = mp.mpf(law.dist.shape), mp.mpf(law.dist.scale)
        d = mp.mpf(H) + 1 - mp.mpf(law.dist.top)

        def f(v):
            u, g = d * mp.expm1(v), d * mp.exp(v)
            return k / lam * (u / lam) ** (k - 1) * mp.exp(-(u / lam) ** k) * (g ** -9 - g ** -3) * g

        ref = float(mp.quad(f, [0, 0.5, 1, 2, 4, 8, 12, 16, mp.log1p(60 * law.sigma / d)]))
    true = abs(law(np.array([H]))[0][0] - ref)
    assert true > 1e-9 * ref and law.error(np.array([H]))[0] == pytest.approx(true, rel=0.05)


def test_rough_laws_share_the_protocol():
    """What the solver uses: law(H) -> (P, dP/dH), wall, smooth, n, rule, sigma, error(H); zero rms is smooth."""
    H = np.linspace(0.5, 3.0, 7)
    for law in [PressureLaw(0.0), PressureLaw(0.2), *rough_laws().values()]:
        p, dp = law(H)
        assert p.shape == dp.shape == H.shape and law.error(H).shape == H.shape
        assert isinstance(law.wall, float) and law.n >= 1 and law.rule and law.sigma >= 0
    for dist in (TruncatedGaussian(0.0), Weibull(0.0, 0.3)):
        law = law_for(dist)
        assert law.smooth and law.n == 1 and law.wall == -1.0
        assert np.array_equal(law(H)[0], PressureLaw(0.0)(H)[0]) and not law.error(H).any()
    assert isinstance(law_for(Measured([0.0, 1.0])), HistogramLaw)
