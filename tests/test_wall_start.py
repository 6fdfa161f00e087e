"""A curve of the truncated Gaussian law traced past the approach where a predictor falls by its wall.

mu = 0.731, sigma = 0.20537, K = 3.6876 on 201 uniform nodes: the natural predictor from lambda = -1.357
(ds = 0.5) put the gap within a few hundredths of the law's wall (H = K sigma - 1), where P grows like the
gap's -8th power; Newton started at a residual of 2.0e11, the domain guard shortened each of its steps, the
residual fell by a steady 0.39 an iteration, and after 25 of them SNES's relative test (rtol 1e-10) took a
residual of 13.3 as converged, a point at lambda = -1.099 with F = -0.394 off the curve (F = -0.600 there),
from which no step could go on: the curve stopped with "step below -cont_ds_min".  A relative decrease counts
now only where the residual left is small against the unknowns or the last iteration shrank it at least
tenfold, Newton's quadratic phase (core/newton.py ``solved``).  The truths:
the same curve on 401 nodes (the refinement: the events' extrapolated values agree within their bars) and
the neighbouring cut-offs K = 3.6 and 3.8 (the pull-off moves monotonically with the highest asperity).
"""
import numpy as np
import pytest

from petsc_adhesion import Model
from petsc_adhesion.tracing.trace import GridChoice, trace_curve

MU, SIGMA, K = 0.731, 0.20537, 3.6876


def _curve(k: float, n: int):
    model = Model(mu=MU, sigma=SIGMA, roughness="truncated_gaussian", roughness_cutoff=k, rmax=10.0)
    return trace_curve(model, GridChoice(kind="uniform", n=n))


@pytest.fixture(scope="module")
def curves():
    return {(k, n): _curve(k, n) for k, n in ((K, 201), (K, 401), (3.6, 201), (3.8, 201))}


def test_the_curve_passes_the_wall_and_agrees_with_its_refinement(curves):
    """The whole curve to F = 2 (it stopped at lambda = -1.099 before), every point a solution (F at the
    stall's approach on the curve, not the stuck point's -0.394), and its pull-off and equilibrium within their
    bars of the 401-node curve's (measured: 1.8e-6 in F and 2.5e-4 in lambda against bars 5.6e-5, 6.6e-4)."""
    c, fine = curves[K, 201], curves[K, 401]
    assert c.complete and not c.warnings, c.warnings
    assert c.branch.F[-1] >= 2
    # no fold at this mu: lambda rises along the whole branch, which passes lambda = -1.099 near F = -0.600
    assert np.all(np.diff(c.branch.lam) > 0)
    assert float(np.interp(-1.099, c.branch.lam, c.branch.F)) == pytest.approx(-0.600, abs=0.01)
    for a, b in ((c.pull_off.lam, fine.pull_off.lam), (c.pull_off.F, fine.pull_off.F)):
        assert abs(a.value - b.value) <= a.err + b.err
    (eq,), (eq_fine,) = c.events_of("equilibrium"), fine.events_of("equilibrium")
    assert abs(eq.lam.value - eq_fine.lam.value) <= eq.lam.err + eq_fine.lam.err


def test_the_pull_off_lies_between_the_neighbouring_cut_offs(curves):
    """A higher asperity (larger K) stands further off and weakens the attraction: the pull-off at K = 3.6876
    between those at K = 3.6 (-0.6392 measured) and K = 3.8 (-0.6352), in order, each traced whole."""
    lo, mid, hi = (curves[k, 201] for k in (3.6, K, 3.8))
    assert lo.complete and hi.complete
    assert lo.pull_off.F.value < mid.pull_off.F.value < hi.pull_off.F.value
    assert lo.pull_off.lam.value > mid.pull_off.lam.value > hi.pull_off.lam.value
