"""A fold pair inside one step: its landings located from a point of the pair's arc, not from the step's start.

mu = 2.171925997, sigma = 0.33 (the default rule and grid): the curve turns twice within one arclength
step near lambda = -2.756 (snap-on at -2.75434, snap-off at -2.75785, a wiggle 3.5e-3 wide), so the pair is
found by a walk of sub-steps, and a landing is sought on the piece from the walk's last point to the step's
end.  That piece's length was taken as the whole step's (b.ds, 0.125, measured from the step's start), the
corrector was asked for a point beyond the step's end, failed, and the curve ended in "event location failed
near lambda = -2.75761": the first curve of `-fit_pull_off`'s secant at mu = 5, sigma = 0.33 (the benchmark
`python -m petsc_adhesion.benchmarks.pull_off fit`, P = 1.36996e-9 N by the table of that day), a
RuntimeError out of the fit.  The truth here is independent of the walk: the same curve traced with steps
fifty times shorter (ds_max 0.01), where each fold has its own step and each landing a step of its own
(measured: the folds and landings of both agree to 1e-9 in lambda and F).
"""
from dataclasses import replace

import pytest

from petsc_adhesion import Model
from petsc_adhesion.discretization.problem import step_scale
from petsc_adhesion.family.pull_off import F_STOP
from petsc_adhesion.tracing.trace import CurveRequest, GridChoice, SolverChoice, curve_settings, trace_curve

MU, SIGMA = 2.171925997, 0.33


def _curve(ds_max=None):
    model = Model(mu=MU, sigma=SIGMA)
    settings = curve_settings(step_scale(model), observable_max=F_STOP)
    if ds_max is not None:
        settings = replace(settings, ds_max=ds_max)
    return trace_curve(model, GridChoice(), SolverChoice(), settings, CurveRequest(error_bars=False))


def test_a_fold_pair_inside_a_step_gets_its_landings():
    """The curve traced whole (before: RuntimeError), its two folds and their landings where short steps put
    them (1e-7 in lambda and F; measured 1e-9), each landing on the other side of the wiggle: the snap-on lands
    more tensile than its fold, the snap-off less."""
    c, short = _curve(), _curve(0.01)
    assert c.complete and not c.warnings, c.warnings
    for kind in ("snap_on", "snap_off"):
        (e,), (t,) = c.events_of(kind), short.events_of(kind)
        assert e.landing is not None and t.landing is not None, kind
        for got, truth in ((e.lam, t.lam), (e.F, t.F), (e.landing.lam, t.landing.lam), (e.landing.F, t.landing.F)):
            assert got.value == pytest.approx(truth.value, abs=1e-7), kind
    (on,), (off,) = c.events_of("snap_on"), c.events_of("snap_off")
    assert on.landing.F.value < on.F.value and off.landing.F.value > off.F.value
    assert off.lam.value < on.lam.value
