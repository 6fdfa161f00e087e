"""The continuation core (continuation.py, events.py, solver.py) on toy problems with known answers.

No adhesion model: the problems of tests/toy_problems.py, a few unknowns each,
every trace a few milliseconds to a tenth of a second.  The numbers are
checked against closed forms (the scalar fold, the cusp), against the
continuum Bratu problem through the measured order of convergence and
Richardson extrapolation, and against the discrete Bratu fold computed
independently (numpy Newton on the extended system).  Each tolerance says
what was measured (PETSc 3.18, OpenBLAS, one rank) and why it holds.

Traces read by several tests are made once per module (fixtures); each
fixture destroys its Continuation and its problem before the tests run.
"""
from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import pytest
from petsc4py import PETSc

from petsc_adhesion.core.continuation import Continuation, Settings
from petsc_adhesion.core.events import EventFinder, Extremum, Fold, ParameterValue, Zero
from petsc_adhesion.core.newton import Newton, guard
from toy_problems import (BRATU_LAMBDA_STAR, BRATU_MID_STAR, Barrier, Bratu, Cusp, Outside, ScalarFold,
                          bratu_discrete_fold, bratu_mid, bratu_theta)

#: Event location tolerance in the parameter (EventFinder's default, passed explicitly).
TOL = 1e-10


# -- running a trace -------------------------------------------------------------------
@dataclass
class Trace:
    """What a finished trace leaves: its points, located events, stop, step statistics, the problem's counts."""

    points: list
    found: list
    stop: tuple
    rejected: int
    folds: int
    counts: dict = field(default_factory=dict)
    lowest: float = math.inf
    sign: int = 1               # the scalar fold's orientation, for the fixture of its four cases

    def events(self, label: str) -> list:
        """The located events named ``label``, in the order met."""
        return [f for f in self.found if f.label == label]

    def labels(self) -> list:
        """The labels of the located events, in the order met."""
        return [f.label for f in self.found]


def trace(pb, x0, p0: float, settings: Settings | None = None, events=(), reverse: bool = False,
          stable=None) -> Trace:
    """Trace pb from the solution near x0 at p0 with ``events``; then destroy the solvers and pb.

    ``reverse``: follow the curve toward smaller p (Continuation.start, direction -1).
    ``stable``: a stability predicate for EventFinder.jumps.
    """
    cont = Continuation(pb, settings or Settings())
    finder = EventFinder(cont, events, tol=TOL)
    guess = pb.vec(x0)
    try:
        start = cont.start(guess, p0, direction=-1 if reverse else 1)
        cont.run(start, on_step=finder)
        if stable is not None:
            finder.jumps(stable)
        return Trace(cont.points, finder.found, cont.stop, cont.rejected, cont.folds, Counter(pb.counts), pb.lowest)
    finally:
        guess.destroy()
        cont.destroy()
        pb.destroy()


# -- 1. the scalar fold x^2 + sign p = 0 ---------------------------------------------------
#: (sign, x0): sign +1 folds where p is largest, -1 where smallest (traced toward smaller p);
#: x0 = -1 starts on the lower branch, +1 on the upper one.
SCALAR_CASES = {"max-lower": (1, -1.0), "max-upper": (1, 1.0), "min-lower": (-1, -1.0), "min-upper": (-1, 1.0)}


@pytest.fixture(scope="module", params=list(SCALAR_CASES))
def scalar(request):
    sign, x0 = SCALAR_CASES[request.param]
    pb = ScalarFold(sign)
    stable = pb.stable
    # f = x + p = x - sign x^2 on the curve: extremum at x = sign/2, p = -sign/4
    events = [Fold(), Extremum("f"), Zero("x", level=sign / 2), ParameterValue(-sign / 2)]
    tr = trace(pb, x0, -sign * x0 * x0, Settings(max_steps=30), events, reverse=sign < 0, stable=stable)
    tr.sign = sign
    return tr


def test_scalar_fold_located_with_its_label(scalar):
    """One fold, at (0, 0), labelled by the orientation: fold_max for x^2 + p, fold_min for x^2 - p."""
    label = "fold_max" if scalar.sign > 0 else "fold_min"
    folds = [f for f in scalar.found if isinstance(f.event, Fold)]
    assert [f.label for f in folds] == [label] and scalar.folds == 1
    pt = folds[0].point
    # p is quadratic in the distance from the fold: measured |p| <= 1.2e-18 (the promise is TOL)
    assert abs(pt.p) <= TOL
    # x is linear in it: measured |x| <= 2e-11 (Brent's xtol in s is TOL; the SNES atol is 1e-10)
    assert abs(pt.x[0]) <= 1e-9
    assert abs(pt.pdot) <= 1e-9 and abs(abs(pt.xdot[0]) - 1) <= 1e-12


def test_scalar_fold_has_no_landing(scalar):
    """The fold ends the branch in p: there is no other state at p = 0 to jump to."""
    folds = [f for f in scalar.found if isinstance(f.event, Fold)]
    assert folds and all(f.landing is None for f in folds)


def test_scalar_curve_and_tangents(scalar):
    """Every accepted point is on x^2 + sign p = 0 (SNES atol 1e-10) with its unit tangent."""
    s = scalar.sign
    for pt in scalar.points:
        x = pt.x[0]
        assert abs(x * x + s * pt.p) <= 1e-10                      # measured 5.8e-11
        assert abs(pt.xdot[0] ** 2 + pt.pdot ** 2 - 1) <= 1e-12
        assert abs(2 * x * pt.xdot[0] + s * pt.pdot) <= 1e-10     # G_x xdot + G_p pdot = 0; measured 2e-16
    # the trace runs away from the start's p and comes back through the fold
    assert scalar.stop == ("max_steps", 30) and scalar.rejected <= 3


def test_scalar_extremum_zero_and_parameter_events(scalar):
    """Extremum of f = x + p, f crossing, p crossing: against the closed forms."""
    s = scalar.sign
    ext = [f for f in scalar.found if isinstance(f.event, Extremum)]
    assert [f.label for f in ext] == ["max" if s > 0 else "min"]
    pt = ext[0].point
    # measured |p - p_exact| <= 7.4e-12, |x - x_exact| <= 7.4e-12, |f - f_exact| <= 1.7e-13, |df/ds| <= 1e-11
    assert abs(pt.p + s / 4) <= TOL
    assert abs(pt.x[0] - s / 2) <= 1e-9
    assert abs(pt.values["f"] - s / 4) <= 1e-9
    assert abs(pt.rates["f"]) <= 1e-9

    zero = scalar.events("zero")
    assert len(zero) == 1
    # the observable x crosses sign/2 where p = -1/4 sign: measured |x - level| <= 1e-15, |p + s/4| <= 2e-13
    assert abs(zero[0].point.x[0] - s / 2) <= 1e-10 and abs(zero[0].point.p + s / 4) <= 1e-10

    hits = scalar.events("p")
    assert len(hits) == 2
    assert all(abs(h.point.p + s / 2) <= TOL for h in hits)
    # x = -+sqrt(1/2), in the order the trace meets them (the start's branch first); measured 5.6e-11
    # (p is the located quantity, x follows through the SNES tolerance)
    x0 = -1.0 if scalar.points[0].x[0] < 0 else 1.0
    assert [h.point.x[0] for h in hits] == pytest.approx([x0 * math.sqrt(0.5), -x0 * math.sqrt(0.5)], abs=1e-9)


@pytest.mark.parametrize("jacobian, pmat, comm", [
    ("python", "dense", "self"), ("dense", "dense", "self"), ("python", "own", "self"),
    ("python", "band", "self"), ("python", "none", "self"), ("dense", "none", "self"),
    ("python", "dense", "world")])
def test_scalar_fold_for_every_operator_and_pc_matrix(jacobian, pmat, comm):
    """MatPython or dense operator; the core's Dense or Band strategy, a matrix made here, or none;
    COMM_SELF or COMM_WORLD (one rank): the same fold."""
    pb = ScalarFold(comm=PETSc.COMM_WORLD if comm == "world" else None, jacobian=jacobian, pmat=pmat)
    tr = trace(pb, -1.0, -1.0, Settings(max_steps=15), [Fold()])
    assert tr.labels() == ["fold_max"]
    pt = tr.found[0].point
    assert abs(pt.p) <= TOL and abs(pt.x[0]) <= 1e-9


# -- 2. Bratu ------------------------------------------------------------------------
#: Interior nodes: odd, so that x = 1/2 is a node (h = 1/100, 1/200).
BRATU_N = (99, 199)


def bratu_trace(n, corrector="auto", **kw):
    settings = Settings(corrector=corrector, observable="mid", **{"observable_max": 4.5, **kw})
    return trace(Bratu(n), 0.0, 0.1, settings, [Fold(), ParameterValue(1.0)])


@pytest.fixture(scope="module")
def bratu():
    """{n: (trace, (lambda_h, u_h) of the extended system)}, up to u(1/2) = 4.5 (past lambda = 1 on the upper branch)."""
    return {n: (bratu_trace(n), bratu_discrete_fold(n)) for n in BRATU_N}


def bratu_fold(tr):
    folds = tr.events("fold_max")
    assert len(folds) == 1 and len(tr.events("fold_min")) == 0
    return folds[0].point


def test_bratu_fold_is_the_discrete_fold(bratu):
    """The located fold is the fold of the discrete problem (independent extended-system Newton)."""
    for n, (tr, (lam_h, u_h)) in bratu.items():
        pt = bratu_fold(tr)
        # measured |lambda - lambda_h| = 2.6e-13 (n = 99), 1.4e-13 (n = 199)
        assert abs(pt.p - lam_h) <= TOL
        # the state moves linearly with the location error in s (<= TOL, |udot| < 10): measured 5.4e-14
        assert np.abs(pt.x - u_h).max() <= 1e-9
        assert tr.stop[0] == "observable_max"


def test_bratu_fold_converges_to_lambda_star_at_second_order(bratu):
    """lambda_h = lambda* + C h^2 + O(h^4): error ratio 4 between h = 1/100 and 1/200; Richardson."""
    (l1, h1), (l2, h2) = [(bratu_fold(bratu[n][0]).p, 1.0 / (n + 1)) for n in BRATU_N]
    e1, e2 = l1 - BRATU_LAMBDA_STAR, l2 - BRATU_LAMBDA_STAR
    # measured e1 = -1.8282e-4, e2 = -4.5703e-5: C = -1.828, ratio 4.00009 (order 2.00003)
    assert e1 < e2 < 0
    assert abs(e2) <= 5e-5
    assert math.log2(e1 / e2) == pytest.approx(2.0, abs=1e-3)
    # Richardson extrapolation removes the h^2 term: measured |lambda_R - lambda*| = 1.4e-9 (the h^4 term)
    rich = (h1 ** 2 * l2 - h2 ** 2 * l1) / (h1 ** 2 - h2 ** 2)
    assert abs(rich - BRATU_LAMBDA_STAR) <= 5e-9


def test_bratu_observable_at_the_fold(bratu):
    """u(1/2) at the fold -> 2 ln cosh(theta*/4) = 1.18684216863...; its rate along the tangent."""
    mids = []
    for n in BRATU_N:
        pt = bratu_fold(bratu[n][0])
        assert pt.values["max"] == pt.values["mid"]       # the solution is symmetric about x = 1/2
        assert pt.rates["mid"] > 0                        # u(1/2) grows along the whole curve
        mids.append(pt.values["mid"])
    e1, e2 = mids[0] - BRATU_MID_STAR, mids[1] - BRATU_MID_STAR
    # measured e1 = -3.34e-5, e2 = -8.33e-6: second order as well, ratio 4.00
    assert e1 < e2 < 0 and abs(e2) <= 1e-5
    assert math.log2(e1 / e2) == pytest.approx(2.0, abs=2e-3)
    rich = (4 * mids[1] - mids[0]) / 3
    assert abs(rich - BRATU_MID_STAR) <= 5e-9          # measured 5.4e-10 (the h^4 term)


def test_bratu_parameter_value_on_both_branches(bratu):
    """lambda = 1 is crossed twice; u(1/2) there against the continuum's two solutions (Richardson)."""
    exact = [bratu_mid(bratu_theta(1.0)), bratu_mid(bratu_theta(1.0, upper=True))]   # 0.1405392, 4.0914672
    per_n = []
    for n in BRATU_N:
        hits = bratu[n][0].events("p")
        assert len(hits) == 2 and all(abs(h.point.p - 1.0) <= TOL for h in hits)
        assert hits[0].segment < bratu[n][0].events("fold_max")[0].segment < hits[1].segment
        per_n.append([h.point.values["mid"] for h in hits])
    for branch in (0, 1):
        coarse, fine = per_n[0][branch], per_n[1][branch]
        # measured errors (n = 199): 3.6e-7 lower, -8.7e-6 upper; Richardson -1.1e-11 and -2.8e-8
        assert abs(fine - exact[branch]) <= 1e-5
        assert abs((4 * fine - coarse) / 3 - exact[branch]) <= 1e-7


@pytest.mark.parametrize("jacobian, pmat", [("python", "dense"), ("dense", "dense"), ("python", "band"),
                                            ("python", "own")])
def test_bratu_fold_for_every_operator_and_pc_matrix(jacobian, pmat):
    """The fold of a small Bratu (n = 31) does not depend on how G_x and the PC matrix are given."""
    lam_h, _ = bratu_discrete_fold(31)
    tr = trace(Bratu(31, jacobian=jacobian, pmat=pmat), 0.0, 0.1,
               Settings(observable="mid", observable_max=1.5), [Fold()])
    assert abs(bratu_fold(tr).p - lam_h) <= TOL


# -- 3. the cusp x^3 - a x + p = 0 ----------------------------------------------------------
#: a > 0: two folds of width 2 sqrt(a/3) in x, 4 (a/3)^(3/2) in p; a < 0: none.
CUSP_A = (1.0, 0.1, 0.01, 1e-4)


def cusp_trace(a: float, **kw) -> Trace:
    """From x0 = 3 X to p = -p(x0), X = sqrt(|a|/3), with steps of at most X/2.

    The steps scale with the fold pair, so that both folds show as sign changes of
    pdot; :func:`test_fold_pair_inside_one_step` takes the default steps instead.
    """
    X = math.sqrt(abs(a) / 3)
    pb = Cusp(a)
    x0 = 3 * X
    settings = Settings(ds=X / 2, ds_max=X / 2, p_max=-pb.on_curve(x0), **kw)
    return trace(pb, x0, pb.on_curve(x0), settings, [Fold()], stable=pb.stable)


@pytest.fixture(scope="module")
def cusp():
    return {a: cusp_trace(a) for a in CUSP_A + (-1.0, -1e-4)}


def test_cusp_two_folds_with_labels_values_and_landings(cusp):
    """For a > 0: fold_max at (sqrt(a/3), 2 (a/3)^(3/2)), then fold_min at the mirror point;
    each lands at the third root -+2 sqrt(a/3) on the other stable branch."""
    for a in CUSP_A:
        tr = cusp[a]
        assert tr.labels() == ["fold_max", "fold_min"] and tr.folds == 2 and tr.stop[0] == "p_max"
        X, P = math.sqrt(a / 3), 2 * (a / 3) ** 1.5
        for f, (xe, pe) in zip(tr.found, [(X, P), (-X, -P)]):
            # p: measured <= 2e-11 (a = 1) and <= 3e-12 below (the promise is TOL)
            assert abs(f.point.p - pe) <= TOL
            # x: measured <= 1.3e-11 for a >= 0.01, but 1.2e-8 at a = 1e-4: a tangent is accepted
            # with a true residual up to 1e3 KSP rtol (solver.krylov_retry), and x at the fold moves
            # by delta(pdot) / (6 X), X = 0.006 there
            assert abs(f.point.x[0] - xe) <= (1e-9 if a >= 0.01 else 1e-7)
            land = f.landing
            assert land is not None and land.p == pytest.approx(f.point.p, abs=TOL)
            # landing located in p to TOL; |dp/dx| = 3a there; measured <= 9.3e-12
            assert abs(land.x[0] + 2 * xe) <= 1e-9
            assert 3 * land.x[0] ** 2 - a > 0          # on a stable branch


@pytest.mark.parametrize("a", [0.01, 1e-4, 1e-6])
def test_fold_pair_inside_one_step(a):
    """With the default steps (up to 0.5) from x = 2 the whole pair lies inside one step: pdot is
    positive at every computed point.  The dip of pdot toward zero is walked again and both folds
    and their landings are located as precisely as with steps that resolve them (pair width
    4 (a/3)^(3/2) in p: 7.7e-10 at a = 1e-6)."""
    pb = Cusp(a)
    tr = trace(pb, 2.0, pb.on_curve(2.0), Settings(p_max=8.0), [Fold()], stable=pb.stable)
    assert all(pt.pdot > 0 for pt in tr.points) and tr.folds == 0
    assert tr.labels() == ["fold_max", "fold_min"]
    X, P = math.sqrt(a / 3), 2 * (a / 3) ** 1.5
    for f, (xe, pe) in zip(tr.found, [(X, P), (-X, -P)]):
        # measured: p within 8e-15, x within 1.2e-11, landings within 1e-10 (a = 0.01 .. 1e-6)
        assert abs(f.point.p - pe) <= TOL and abs(f.point.x[0] - xe) <= 1e-9
        assert f.landing is not None and f.landing.p == pytest.approx(pe, abs=TOL)
        assert abs(f.landing.x[0] + 2 * xe) <= 1e-9 and pb.stable(f.landing)


def test_no_pair_where_pdot_only_dips():
    """a < 0: pdot dips toward zero at x = 0 (to |a|) but keeps its sign: the walk finds no fold."""
    pb = Cusp(-1e-4)
    tr = trace(pb, 2.0, pb.on_curve(2.0), Settings(p_max=8.0), [Fold()], stable=pb.stable)
    assert min(pt.pdot for pt in tr.points) < 0.1 and tr.found == [] and tr.stop[0] == "p_max"


def test_cusp_folds_merge_as_a_goes_to_zero(cusp):
    """The pair shrinks like sqrt(a) in x and a^(3/2) in p, to the cusp point (0, 0)."""
    widths = []
    for a in CUSP_A:
        fmax, fmin = (f.point for f in cusp[a].found)
        widths.append((fmax.x[0] - fmin.x[0], fmax.p - fmin.p))
        # measured rel. 1e-11 (a >= 0.01), 1.7e-6 at a = 1e-4 (the x error above); p: <= 2.2e-10
        assert widths[-1][0] == pytest.approx(2 * math.sqrt(a / 3), rel=1e-5)
        assert widths[-1][1] == pytest.approx(4 * (a / 3) ** 1.5, rel=1e-9)
    assert all(w1[0] > w2[0] > 0 and w1[1] > w2[1] > 0 for w1, w2 in zip(widths, widths[1:]))


def test_cusp_no_fold_for_negative_a(cusp):
    """For a < 0, p = a x - x^3 is monotone: no fold, pdot > 0 throughout, the trace ends at p_max."""
    for a in (-1.0, -1e-4):
        tr = cusp[a]
        assert tr.found == [] and tr.folds == 0 and tr.stop[0] == "p_max"
        assert all(pt.pdot > 0 for pt in tr.points)


def test_cusp_tangent_is_updated_with_a_kept_preconditioner():
    """At a = 1e-6 (|G_x| <= 8e-6) a preconditioner kept from the start makes GMRES's preconditioned
    residual pass after one iteration on the start's tangent; before the true-residual check of
    solver.krylov_retry every point kept pdot = 8e-6 and both folds were missed."""
    tr = cusp_trace(1e-6)
    assert tr.labels() == ["fold_max", "fold_min"]


def test_cusp_with_a_fresh_preconditioner_is_exact():
    """The same a = 1e-4 trace, refilling the PC matrix every linearization: x of the folds to 1e-15."""
    tr = cusp_trace(1e-4, pc_reuse_its=0)
    X = math.sqrt(1e-4 / 3)
    assert tr.labels() == ["fold_max", "fold_min"]
    assert [f.point.x[0] for f in tr.found] == pytest.approx([X, -X], abs=1e-15)   # measured 2e-17


# -- 4. step control and stops ---------------------------------------------------------------
def test_rejected_steps_still_give_the_right_curve():
    """A long first step with a tight curvature bound: steps are refused and halved; the curve and fold stay right."""
    settings = Settings(ds=0.5, ds_max=0.5, max_deviation=0.02, max_steps=60)
    tr = trace(ScalarFold(), -1.0, -1.0, settings, [Fold()])
    default = trace(ScalarFold(), -1.0, -1.0, Settings(max_steps=60), [Fold()])
    assert tr.rejected >= 5 > default.rejected                 # measured 7 against 2
    assert max(pt.deviation for pt in tr.points) <= 0.02
    assert all(abs(pt.x[0] ** 2 + pt.p) <= 1e-10 for pt in tr.points)
    assert tr.labels() == ["fold_max"] and abs(tr.found[0].point.x[0]) <= 1e-9


@pytest.mark.parametrize("bend", [1e-3, 1e-4])
def test_a_bound_on_the_observables_bend_bounds_its_chords(bend):
    """x^2 + p = 0 traced through its fold with f = x + p watched: with ``observable_bend`` the chord of f between
    accepted points stays within twice the bound of the exact curve at the chord's middle x (f = x - x^2 there:
    the chord's error is (delta x)^2 / 4), and the bound is what sets it (measured 1.3e-3 and 1.2e-4; without
    the bound 0.011); the fold is found alike."""
    def chord_error(tr):
        pts = tr.points
        return max(abs((a.values["f"] + b.values["f"]) / 2 - (0.5 * (a.x[0] + b.x[0]) - (0.5 * (a.x[0] + b.x[0])) ** 2))
                   for a, b in zip(pts, pts[1:]))

    def run(**kw):
        return trace(ScalarFold(), -3.0, -9.0, Settings(observable="f", p_min=-9.0, max_steps=5000, **kw), [Fold()])

    bound, free = run(observable_bend=bend), run()
    assert chord_error(bound) <= 2 * bend
    assert chord_error(free) >= 10 * 1e-3
    assert bound.labels() == free.labels() == ["fold_max"] and abs(bound.found[0].point.x[0]) <= 1e-9


def test_rejected_steps_bratu():
    """The same on Bratu (n = 31): more rejections, every step within the bound, the same discrete fold."""
    lam_h, _ = bratu_discrete_fold(31)
    tr = trace(Bratu(31), 0.0, 0.1, Settings(ds=0.5, ds_max=0.5, max_deviation=0.02, observable="mid",
                                             observable_max=1.5), [Fold()])
    default = trace(Bratu(31), 0.0, 0.1, Settings(observable="mid", observable_max=1.5), [Fold()])
    assert tr.rejected > default.rejected                       # measured 9 against 6 (97 points against 23)
    assert max(pt.deviation for pt in tr.points) <= 0.02 < max(pt.deviation for pt in default.points)
    assert abs(bratu_fold(tr).p - lam_h) <= TOL                 # measured 2.9e-12


def test_predictor_outside_the_domain_is_refused():
    """x^2 + p = 0 on x > -0.6: predictors beyond the wall are refused and the step halved until ds_min."""
    pb = ScalarFold(xmin=-0.6)
    tr = trace(pb, 1.0, -1.0, Settings(ds_min=1e-6), [Fold()])
    assert tr.counts["refused"] > 0 and tr.rejected > 0         # measured 46 refused, 25 rejected
    assert tr.counts["outside"] == 0 and tr.lowest > -0.6
    assert tr.labels() == ["fold_max"]
    assert tr.stop[0] == "ds_min" and tr.stop[1] == pytest.approx(-0.36, abs=1e-5)   # measured -0.3599992
    assert all(pt.x[0] > -0.6 for pt in tr.points)


STOPS = {
    # reason: (problem, start x, start p, settings)
    "observable_max": (lambda: ScalarFold(), -1.0, -1.0, Settings(observable="x", observable_max=0.5)),
    "p_max": (lambda: Cusp(1.0), 2.0, -6.0, Settings(p_max=1.0)),
    "max_steps": (lambda: ScalarFold(), -1.0, -1.0, Settings(max_steps=5)),
    "max_folds": (lambda: Cusp(1.0), 2.0, -6.0, Settings(max_folds=0)),
    "ds_min": (lambda: ScalarFold(), -1.0, -1.0, Settings(corrector="natural")),
}


@pytest.mark.parametrize("reason", list(STOPS))
def test_stop_reason(reason):
    make, x0, p0, settings = STOPS[reason]
    tr = trace(make(), x0, p0, settings, [Fold()])
    last = tr.points[-1]
    assert tr.stop[0] == reason
    if reason == "observable_max":
        assert tr.stop[1] == last.values["x"] >= 0.5 > tr.points[-2].values["x"]
        assert tr.labels() == ["fold_max"]                  # x = 0.5 lies past the fold
    elif reason == "p_max":
        assert tr.stop[1] == last.p >= 1.0 and all(pt.p < 1.0 for pt in tr.points[:-1])
        assert tr.labels() == ["fold_max", "fold_min"]
    elif reason == "max_steps":
        assert tr.stop[1] == 5 and len(tr.points) == 6       # the start and 5 accepted steps
    elif reason == "max_folds":
        # "more than max_folds turning points": max_folds = 0 stops right after the first one
        assert tr.stop[1] == 0 and tr.folds == 1 and tr.labels() == ["fold_max"]
        assert last.pdot < 0 < tr.points[-2].pdot
    else:
        # the natural corrector cannot pass the fold (G_x singular): it creeps up to it and gives up
        assert tr.stop[1] == last.p and -1e-8 < last.p < 0     # measured p = -2.1e-12
        assert tr.found == [] and tr.folds == 0 and tr.rejected > 0


def test_max_folds_counts_more_than():
    """max_folds = 1: the trace passes two folds before it stops (the check is folds > max_folds)."""
    tr = trace(Cusp(1.0), 2.0, -6.0, Settings(max_folds=1), [Fold()])
    assert tr.stop == ("max_folds", 1) and tr.folds == 2 and tr.labels() == ["fold_max", "fold_min"]


# -- 5. correctors ---------------------------------------------------------------------------
SCALAR_EVENTS = (Fold(), Extremum("f"), Zero("x", level=0.5), ParameterValue(-0.5))


@pytest.fixture(scope="module")
def correctors():
    """The x^2 + p trace from the lower branch with each corrector, through x = 1."""
    out = {}
    for kind in ("natural", "arclength", "auto"):
        settings = Settings(corrector=kind, observable="x", observable_max=1.0)
        out[kind] = trace(ScalarFold(), -1.0, -1.0, settings, SCALAR_EVENTS)
    return out


def test_natural_corrector_stops_at_the_fold(correctors):
    tr = correctors["natural"]
    assert tr.stop[0] == "ds_min" and -1e-8 < tr.stop[1] < 0       # measured -1.4e-9
    assert {pt.corrector for pt in tr.points[1:]} == {"natural"}
    assert tr.labels() == ["p"] and tr.folds == 0                 # only p = -0.5 lies before the fold


def test_arclength_and_auto_pass_the_fold_and_agree(correctors):
    arc, auto = correctors["arclength"], correctors["auto"]
    assert {pt.corrector for pt in arc.points[1:]} == {"arclength"}
    assert {pt.corrector for pt in auto.points[1:]} == {"natural", "arclength"}
    for tr in (arc, auto):
        assert tr.stop[0] == "observable_max"
        assert tr.labels() == ["p", "fold_max", "max", "zero", "p"]
    # measured: fold x 2e-11 apart, the other events <= 2e-13 in p and x
    for ea, eb in zip(arc.found, auto.found):
        assert abs(ea.point.p - eb.point.p) <= 1e-8 and abs(ea.point.x[0] - eb.point.x[0]) <= 1e-8
    # and both are right
    assert abs(auto.events("fold_max")[0].point.p) <= TOL and abs(arc.events("max")[0].point.p + 0.25) <= TOL


@pytest.fixture(scope="module")
def bratu_correctors():
    return {kind: bratu_trace(99, kind, observable_max=2.0) for kind in ("natural", "arclength")}


def test_bratu_correctors(bratu, bratu_correctors):
    """Bratu n = 99: natural stops just below the fold; arclength and auto locate the same fold."""
    lam_h = bratu[99][1][0]
    nat = bratu_correctors["natural"]
    assert nat.stop[0] == "ds_min" and -1e-8 < nat.stop[1] - lam_h < 0    # measured -8e-12
    assert nat.events("fold_max") == []
    p_arc, p_auto = bratu_fold(bratu_correctors["arclength"]).p, bratu_fold(bratu[99][0]).p
    assert abs(p_arc - p_auto) <= 1e-8                                      # measured 2.7e-13


# -- 6. the domain guard -----------------------------------------------------------------------
@pytest.mark.parametrize("full_steps", [False, True], ids=["bt", "basic"])
def test_newton_guard_keeps_newton_inside(full_steps):
    """p + x + 1/x = 0 at p = -5/2 from x = 0.9: the full Newton step lands at x = -1.18 < 0;
    the guard shortens it and Newton converges to the root 1/2 without a residual outside."""
    pb = Barrier()
    newton = Newton(pb, "toy_", full_steps=full_steps)
    x = pb.vec(0.9)
    try:
        assert newton.solve(-2.5, x)
        assert x.getArray()[0] == pytest.approx(0.5, abs=1e-12)
        assert pb.counts["shortened"] >= 1 and pb.counts["outside"] == 0 and pb.lowest > 0
        # without the guard the first step leaves the domain and the residual is asked there
        pb.guard_on = False
        x.set(0.9)
        with pytest.raises(Outside):
            newton.solve(-2.5, x)
        assert pb.counts["outside"] == 1
    finally:
        x.destroy()
        newton.destroy()
        pb.destroy()


def test_guard_scales_the_step():
    """solver.guard: a step toward the wall covers at most 0.9 of the way; one away is left alone."""
    pb = Barrier()
    Y = pb.vec(2.0)
    try:
        assert guard(pb, np.array([0.5]), Y)
        assert Y.getArray()[0] == pytest.approx(0.45)               # x - y = 0.05: 0.9 of the way to 0
        Y.set(-3.0)
        assert not guard(pb, np.array([0.5]), Y) and Y.getArray()[0] == -3.0
    finally:
        Y.destroy()
        pb.destroy()


def test_trace_near_the_wall():
    """The curve p = -(x + 1/x) down to x = 0.01: fold at (1, -2), no residual ever at x <= 0."""
    pb = Barrier()
    tr = trace(pb, 4.0, pb.on_curve(4.0), Settings(observable="inv", observable_max=100.0), [Fold()])
    assert tr.stop[0] == "observable_max" and tr.points[-1].x[0] <= 0.01
    assert tr.labels() == ["fold_max"]
    pt = tr.found[0].point
    assert abs(pt.p + 2) <= TOL and abs(pt.x[0] - 1) <= 1e-9             # measured 0 and 1e-11
    assert tr.counts["outside"] == 0 and tr.lowest > 0
    assert tr.counts["shortened"] >= 1                                   # measured 2 (arclength corrector)


def test_python_errors_gives_the_callbacks_own_exception():
    """capi.python_errors: petsc4py 3.22 and later raise PETSc.Error 101 *from* a callback's exception
    (as measured with 3.26); inside python_errors the caller gets the callback's exception itself, a
    PETSc error of PETSc's own stays one, and 3.18's plain re-raise passes through."""
    from petsc4py import PETSc
    from petsc_adhesion.core.capi import python_errors

    def wrapped(exc):
        try:
            raise exc
        except BaseException as e:
            raise PETSc.Error(101) from e

    with pytest.raises(Outside, match="inside"):
        with python_errors():
            wrapped(Outside("inside"))
    with pytest.raises(Outside, match="nested"):          # wrapped at each level of callbacks
        with python_errors():
            try:
                wrapped(Outside("nested"))
            except PETSc.Error as inner:
                raise PETSc.Error(101) from inner
    with pytest.raises(PETSc.Error) as own:
        with python_errors():
            raise PETSc.Error(73)
    assert own.value.ierr == 73
    with pytest.raises(PETSc.Error) as chained:
        with python_errors():
            wrapped(PETSc.Error(56))
    assert chained.value.ierr == 101
    with pytest.raises(KeyError):
        with python_errors():
            raise KeyError("3.18 re-raises the callback's exception as it is")
