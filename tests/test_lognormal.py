"""Lognormal heights (roughness.Lognormal): the depth below the highest asperity lognormal, the tail in the valleys.

Every reference here is computed apart from the class: moments and averages by quad on
scipy.stats' lognormal (its own parametrisation, shape s and scale e^m), the average at
the wall and the rigid sphere's load there in closed form (E[W^-k] = e^(-k m + k^2 s^2 / 2)).
"""
import json
import math

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad
from scipy.optimize import minimize_scalar
from scipy.stats import lognorm

from petsc_adhesion.model.pressure import WallLaw, lennard_jones
from petsc_adhesion.model.reference.rigid import rigid_load
from petsc_adhesion.model.roughness import DISTRIBUTIONS, Lognormal, WallQuadrature

pytestmark = pytest.mark.filterwarnings("ignore", category=IntegrationWarning)

SKEWNESS = [-4.0, -1.0, -0.25]


def depth_law(dist: Lognormal):
    """scipy's lognormal of the depth W = S_max - S, from the rms and skewness by scipy's own moments."""
    # s from the skewness by scipy's stats (not the class's formula): bisection on lognorm(s).stats('s')
    lo, hi = 1e-4, 3.0
    for _ in range(200):
        mid = (lo + hi) / 2
        if float(lognorm(mid).stats(moments="s")) < -dist.skewness:
            lo = mid
        else:
            hi = mid
    s = (lo + hi) / 2
    scale = dist.rms / float(lognorm(s).std())
    return lognorm(s, scale=scale)


def expect(law, f, center: float) -> float:
    """E[f(W)] by quad in t = log W over +-40 s about the median, with break points at ``center``."""
    s, m = law.kwds["s"] if "s" in law.kwds else law.args[0], math.log(law.kwds["scale"])
    pts = sorted({m, center})
    edges = [m - 40 * s, *[p for p in pts if m - 40 * s < p < m + 40 * s], m + 40 * s]
    return sum(quad(lambda t: f(math.exp(t)) * law.pdf(math.exp(t)) * math.exp(t), a, b, epsabs=0, epsrel=1e-13,
                    limit=400)[0] for a, b in zip(edges[:-1], edges[1:]))


@pytest.mark.parametrize("skewness", SKEWNESS)
def test_moments_and_the_top(skewness):
    """The stated rms and skewness, zero mean, nothing above the highest asperity; the top is E[W]."""
    dist = Lognormal(0.3, skewness)
    law = depth_law(dist)
    assert dist.top == pytest.approx(float(law.mean()), rel=1e-8)
    assert dist.shape == pytest.approx(law.args[0] if law.args else law.kwds["s"], rel=1e-8)
    mean = dist.top - float(law.mean())
    assert abs(mean) < 1e-8 * dist.rms
    assert dist.pdf(dist.top) == 0 and dist.pdf(dist.top + 1e-9) == 0 and dist.bottom == -math.inf
    # the density the class integrates is scipy's, at a few depths
    u = np.array([0.1, 1.0, 3.0]) * dist.rms
    assert np.allclose(dist.depth_pdf(u), law.pdf(u), rtol=1e-7, atol=0)
    assert "lognormal" in DISTRIBUTIONS
    for bad in (0.0, -0.2, -4.5):
        with pytest.raises(ValueError, match="skewness"):
            Lognormal(1.0, bad)


@pytest.mark.parametrize("skewness", SKEWNESS)
@pytest.mark.parametrize("dr", [0.0, 1e-5, 1e-2, 0.3, 30.0])
def test_quadrature_against_quad(skewness, dr):
    """E[(d + W)^-k], k = 3, 4, 9, 10, to 1e-12 relative for every d >= 0, the wall (d = 0) included."""
    dist = Lognormal(0.3, skewness)
    law = depth_law(dist)
    rule = WallQuadrature(dist)
    assert rule.near_points == 0          # fixed panels only: the density vanishes faster than any power at the top
    d = dr * dist.rms
    for k in (3, 4, 9, 10):
        ref = expect(law, lambda w: (d + w) ** -k, math.log(d) if d > 0 else -math.inf)
        mine = float(rule.weights @ (d + rule.depths) ** -k)
        assert mine == pytest.approx(ref, rel=1e-12), (k, mine / ref - 1)


@pytest.mark.parametrize("skewness", SKEWNESS)
def test_repulsion_at_the_wall_is_finite_in_closed_form(skewness):
    """P(wall) = E[W^-9] - E[W^-3], E[W^-k] = e^(-k m + k^2 s^2 / 2): the law tends to it, and refuses the wall."""
    dist = Lognormal(0.2, skewness)
    law = depth_law(dist)
    s, m = dist.shape, math.log(law.kwds["scale"])
    def inverse(k):
        return math.exp(-k * m + k * k * s * s / 2)

    closed = inverse(9) - inverse(3)
    p = WallLaw(dist)
    H = p.wall + np.array([1e-9, 1e-7]) * dist.rms
    P, dP = p(H)
    d = H + 1 - dist.top          # the gap left, to first order: dP/dd = -9 E[W^-10] + 3 E[W^-4]
    assert P == pytest.approx(closed + d * (3 * inverse(4) - 9 * inverse(10)), rel=1e-6)
    assert dist.wall_pressure == pytest.approx(closed, rel=1e-12)
    with pytest.raises(FloatingPointError):
        p(np.array([p.wall]))


def rigid(law: WallLaw, lam: float) -> float:
    """The rigid sphere's load (eq. 26 with H = -lambda + r^2/2, r dr = dH) from the law: (8/3) int P dH."""
    lo = -lam
    edges = [lo, lo + 0.01, lo + 0.1, lo + 1, lo + 10, lo + 100, math.inf]
    return 8 / 3 * sum(quad(lambda H: float(law(np.array([H]))[0][0]), a, b, epsabs=1e-14, epsrel=1e-12,
                            limit=200)[0] for a, b in zip(edges[:-1], edges[1:]))


@pytest.mark.parametrize("skewness", [-1.0, -0.25])
def test_rigid_limit(skewness):
    """mu = 0: the load of the law equals eq. (28) averaged over the heights, E[F_rigid(lambda + S)], by quad on
    scipy's lognormal; at the wall (the highest asperity touching) in closed form; and the pull-off alike."""
    sigma = 0.2
    dist = Lognormal(sigma, skewness)
    law, p = depth_law(dist), WallLaw(dist)
    top = dist.top

    def averaged(lam):       # S = top - W: the gap 1 - lambda - S = (1 - lambda - top) + W
        return expect(law, lambda w: rigid_load(lam + top - w), math.log(max(1 - lam - top, 1e-300)))

    for lam in (1 - top - g for g in (2.0, 1.3, 1.0, 0.5)):       # g: the gap at the highest asperity
        assert rigid(p, lam) == pytest.approx(averaged(lam), rel=1e-9, abs=1e-12), lam
    # at the wall, lambda = 1 - top: (1/3) E[W^-8] - (4/3) E[W^-2], in closed form
    s, m = dist.shape, math.log(law.kwds["scale"])
    at_wall = math.exp(-8 * m + 32 * s * s) / 3 - 4 * math.exp(-2 * m + 2 * s * s) / 3
    assert rigid(p, 1 - top - 1e-10) == pytest.approx(at_wall, rel=1e-6)
    # the pull-off of the rigid rough sphere: the most tensile load, by quad on both sides
    ours = minimize_scalar(lambda lam: rigid(p, lam), bounds=(-1.5 - top, 1 - top - 1e-6), method="bounded",
                           options={"xatol": 1e-9})
    ref = minimize_scalar(averaged, bounds=(-1.5 - top, 1 - top - 1e-6), method="bounded", options={"xatol": 1e-9})
    assert ours.fun == pytest.approx(ref.fun, rel=1e-9) and ours.x == pytest.approx(ref.x, abs=1e-6)
    assert -1 < ref.fun < 0     # weaker than the smooth sphere's -1 (eq. 28): the asperities hold it off


def test_through_the_program(cli, tmp_path):
    """-adh_roughness lognormal: its rms is sigma, the files name its skewness and highest asperity; the option
    refused out of its range and under another law."""
    args = ("-adh_mu", "1", "-grid_type", "uniform", "-grid_n", "101", "-adh_rmax", "10", "-adh_sigma", "0.2",
            "-adh_roughness", "lognormal", "-adh_lognormal_skewness", "-2")
    p = cli(*args, "-cont_F_max", "0.2", "-cont_error_estimate", "false", "-adh_model_spread", "false",
            "-summary", tmp_path / "s.json")
    assert p.returncode == 0, p.stderr
    s = json.load(open(tmp_path / "s.json"))
    assert s["roughness"] == "lognormal" and s["lognormal_skewness"] == -2 and s["rms"] == 0.2
    assert s["highest_asperity"] == pytest.approx(Lognormal(0.2, -2).top, rel=1e-14)
    assert s["complete"] and -1 < s["pull_off"]["F"] < 0
    bad = cli(*args[:-2], "-adh_lognormal_skewness", "0.1", "-adh_lambda", "-1")
    assert bad.returncode == 2 and "-adh_lognormal_skewness" in bad.stderr and "[-4, -0.25]" in bad.stderr
    # at sigma 0.2 a skewness of -0.5 puts the top 1.2 epsilon up: P(wall) < 0, refused
    assert Lognormal(0.2, -0.5).wall_pressure < 0 < Lognormal(0.2, -1).wall_pressure
    bad = cli(*args[:-2], "-adh_lognormal_skewness", "-0.5", "-adh_lambda", "-1")
    assert bad.returncode == 2 and "-adh_lognormal_skewness" in bad.stderr and "repel nowhere" in bad.stderr
    bad = cli(*args[:-3], "weibull", "-adh_lognormal_skewness", "-1", "-adh_lambda", "-1")
    assert bad.returncode == 2 and "-adh_lognormal_skewness" in bad.stderr and "lognormal" in bad.stderr


def test_a_model_spread_rule():
    """lognormal:skewness among the model spread's laws: the model it makes, its range refused."""
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.model_spread import Rule, parse_rules
    (rule,) = parse_rules("lognormal:-2")
    m = rule.model(Model(mu=1.0, sigma=0.3))
    assert (m.roughness, m.lognormal_skewness, m.sigma, rule.label) == ("lognormal", -2.0, 0.3, "lognormal:-2")
    assert Rule.of(m) == rule
    with pytest.raises(ValueError, match=r"\[-4, -0.25\]"):
        parse_rules("lognormal:0")
