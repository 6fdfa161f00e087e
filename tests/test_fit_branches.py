"""The solver's curves of a fit as branches of (mu, sigma) (petsc_adhesion/fitting/branches.py, docs/fitting.md
"The solver's curves"): a branch traced without a spring and read behind one jumps where the curve traced with
the spring in the system jumps, to that curve's own error; a later fit reads the branch an earlier one traced
and gives the same numbers; the lattice the first curve is traced on stays within half a bar of the optimum."""
import math

import numpy as np
import pytest

from petsc_adhesion.fitting import table_search
from petsc_adhesion.fitting.branches import BRANCHES, BranchCache
from petsc_adhesion.fitting.curve_fit import TableStep, fit_curve
from petsc_adhesion.fitting.forward import APPROACH, RETRACT, ForwardCurve
from petsc_adhesion.fitting.results import Spring
from petsc_adhesion.fitting.synthetic import Sampling, synthetic_curve
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.model.physical import Bodies
from petsc_adhesion.tracing.trace import CurveRequest, GridChoice, SolverChoice, curve_settings, trace_curve

R, EPS, W = 20e-9, 0.3e-9, 0.05


@pytest.mark.parametrize("mu, K", [(1.0, 0.048), (0.01, 0.005)])
def test_a_branch_behind_a_spring_jumps_where_the_spring_traced_curve_does(mu, K):
    """mu = 1 behind K = 0.048 (1 N/m on a 20 nm tip), and mu = 0.01 behind a soft K = 0.005, whose jump-in lies
    before the branch's start (the far branch continued by eq. 28): each jump's base position Z and its force
    before and after agree with the curve traced with the spring in the system (error bars on) within that
    curve's own error: twice the distance of its grid value from its extrapolated one, or 3 bars, whichever is
    larger (the branch's jumps agree with the grid values to 1e-5: both are values on the fit's grid);
    the force between the jumps within 5e-4 of 2 pi R w (1.8e-4 measured at mu = 1; 1% noise is 1e-2)."""
    cache = BranchCache()
    grid, solver = GridChoice(), SolverChoice()
    legs, traced = cache.legs(Model(mu=mu), 2.5, K, -300.0, grid, solver, None)
    assert traced == 1 and cache.traced == 1
    again, traced = cache.legs(Model(mu=mu), 2.5, K, -300.0, grid, solver, None)
    assert traced == 0 and cache.traced == 1           # read, not traced again
    c = trace_curve(Model(mu=mu), grid, solver, curve_settings(observable_max=4.0, observable_step=0.1, ds_max=0.2),
                    CurveRequest(error_bars=True, kinds=("jump_in", "jump_off"), spring=K))
    spring = ForwardCurve(c, K)
    for leg, kind in ((APPROACH, "jump_in"), (RETRACT, "jump_off")):
        (e,) = [e for e in c.events if e.kind == kind]
        best = e.lam.value + e.F.value / K
        grid_Z = e.lam.grid + e.F.grid / K
        allowed = max(2 * abs(grid_Z - best), 3 * (e.lam.err + e.F.err / K))
        assert len(legs.jumps[leg]) == 1
        assert abs(legs.jumps[leg][0] - best) <= allowed, (leg, legs.jumps[leg], best, allowed)
        (before, after), = legs.jump_forces(leg)
        (b_s, a_s), = spring.jump_forces(leg)
        assert abs(before - e.F.value) <= max(2 * abs(e.F.grid - e.F.value), 3 * e.F.err) + 5e-4
        assert abs(after - a_s) <= 5e-4
        # up to the branch's end (a load of the ladder past the 2.5 asked for; beyond it the contact is continued
        # linearly, as past any traced curve's end, while the spring's curve runs on to 4)
        (branch,) = cache.kept.values()
        end = float(branch.curve.lam[-1] + branch.curve.F[-1] / K)
        assert branch.curve.F[-1] >= 2.5
        Z = np.linspace(legs.jumps[RETRACT][0] - 20.0, min(spring.pieces[-1].Z_hi, end), 1500)
        near = np.zeros(Z.size, bool)
        for z in legs.jumps[leg] + spring.jumps[leg]:
            near |= np.abs(Z - z) < max(allowed, 0.02)
        d = legs.predict(Z, leg) - spring.predict(Z, leg)
        assert np.max(np.abs(d[~near])) < 5e-4, (leg, np.max(np.abs(d[~near])))


def _curve(mu: float, seed: int):
    E = W * math.sqrt(R / (mu**3 * EPS**3))
    truth = Bodies(radius=R, young1=E, poisson1=0.0, epsilon=EPS, gamma=W)
    return synthetic_curve(truth, Spring(1.0), Sampling(noise=0.01 * 2 * math.pi * R * W, points=300, z0=3e-9,
                                                         F0=1e-10, seed=seed)), E


def test_a_later_fit_reads_the_branch_and_gives_the_same_numbers():
    """A fit traces its solver curve at a lattice point; the same fit again in the process traces nothing (its
    curve found: ``shared``) and gives the same numbers bit for bit, as a fit after the process forgot every
    branch does: a fit's result never depends on the fits before it."""
    data, E = _curve(0.3, 4)
    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS)
    BRANCHES.clear()
    first = fit_curve(data, tip, Spring(1.0))
    again = fit_curve(data, tip, Spring(1.0))
    BRANCHES.clear()
    fresh = fit_curve(data, tip, Spring(1.0))
    assert isinstance(first.path, TableStep) and first.path.curves >= 1 and first.path.shared == 0
    assert first.traces == first.path.curves + first.path.differenced
    assert again.traces == 0 and again.path.shared == again.path.curves == first.path.curves
    assert math.isfinite(first.path.lattice_mu)
    for f in (again, fresh):
        assert (f.gamma.value, f.gamma.err, f.E_star.value, f.E_star.err, f.chi2) == \
            (first.gamma.value, first.gamma.err, first.E_star.value, first.E_star.err, first.chi2)
    assert abs(first.gamma.value - W) <= 1.96 * first.gamma.err and abs(first.E_star.value - E) <= 1.96 * first.E_star.err
    assert any("the first at the lattice point" in n for n in first.notes) and \
        any("read from a branch traced before" in n for n in again.notes)


def test_the_lattice_point_is_within_half_a_bar_and_the_levels_nest():
    """on_lattice moves ln mu by at most LATTICE_BARS of its bar, to a point of the coarsest level that allows it;
    each level's points are points of every finer level (fits of nearby bars share curves); a bar finer
    than the finest level leaves x where it is."""
    rng = np.random.default_rng(5)
    names = ("ln_mu", "ln_gamma", "z0", "F0")
    lo, hi = np.array([math.log(1e-3), -10, -50, -50]), np.array([math.log(1e3), 0, 50, 50])
    for _ in range(200):
        x = np.array([rng.uniform(lo[0], hi[0]), -3.0, 0.0, 0.0])
        sd = np.array([10 ** rng.uniform(-4.0, 1.0), 0.01, 0.1, 0.1])
        y, level = table_search.on_lattice(x, names, sd, lo, hi)
        assert level is not None and abs(y[0] - x[0]) <= table_search.LATTICE_BARS * sd[0] * (1 + 1e-9)
        assert np.array_equal(y[1:], x[1:])
        h = math.log(10.0) / (table_search.LATTICE * 2**level)
        assert abs(y[0] / h - round(y[0] / h)) < 1e-6 and abs(2 * y[0] / h - round(2 * y[0] / h)) < 1e-6
        assert level == -table_search.COARSER or 0.5 * 2 * h > table_search.LATTICE_BARS * sd[0]   # the coarsest
    y, level = table_search.on_lattice(x, names, np.array([1e-7, 1, 1, 1]), lo, hi)
    assert level is None and np.array_equal(y, x)
    y, level = table_search.on_lattice(x, names[1:] + ("ln_k",), sd, lo, hi)
    assert level is None and y is x


def test_the_step_from_the_lattice_point_matches_the_fit_at_the_optimum(monkeypatch):
    """At mu = 1 the first curve half a bar of ln mu away from the table's optimum (the lattice's largest offset)
    and one step: w and E* within 0.1 of their bars of the fit whose curve is traced at the optimum itself
    (0.006 and 0.014 measured, docs/fitting.md), the bars at most 1.2 times as wide (the step added to them: 1.16 measured for E*)
    and at least 0.98 times: each is its own curve's Jacobian's, the solver's at that curve (w's 0.3% narrower
    half a bar of ln mu away, measured)."""
    data, _ = _curve(1.0, 1)
    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS)

    def offset(k):
        def move(x, names, sd, lo, hi):
            y = x.copy()
            y[0] += k * sd[0]
            return y, 0
        return move

    fits = []
    for k in (0.0, 0.5):
        monkeypatch.setattr(table_search, "on_lattice", offset(k))
        monkeypatch.setattr(table_search, "STEP_BARS", 1e9)
        fits.append(fit_curve(data, tip, Spring(1.0)))
    at, off = fits
    assert off.path.curves == 1 and 0.4 < off.path.first < 0.8, off.path
    for a, b in ((at.gamma, off.gamma), (at.E_star, off.E_star)):
        assert abs(a.value - b.value) <= 0.1 * a.err and 0.98 * a.err <= b.err <= 1.2 * a.err, (a, b)


def test_a_branch_traced_without_its_cycles_holds_the_same_points_and_says_the_energy_is_missing():
    """CurveRequest(cycles=False), as a fit's branch is traced: the same points bit for bit as the curve traced
    with its cycles (the energy is computed after the trace, from its points), the rigid cycle's energy Missing
    with its reason instead of a number, the events kinds=() leaves out not made (mu = 1: a hysteresis loop, whose
    energy the curve with its cycles gives, positive)."""
    from petsc_adhesion.fitting.branches import branch_settings
    from petsc_adhesion.tracing.measured import Missing
    from petsc_adhesion.tracing.results import NO_CYCLE

    m = Model(mu=1.0)
    s = branch_settings(m, 2.0)
    full = trace_curve(m, GridChoice(), SolverChoice(), s, CurveRequest(error_bars=False, kinds=()))
    bare = trace_curve(m, GridChoice(), SolverChoice(), s, CurveRequest(error_bars=False, kinds=(), cycles=False))
    for key in ("lam", "F", "H0", "contact_radius"):
        assert np.array_equal(np.asarray(getattr(full.branch, key)), np.asarray(getattr(bare.branch, key))), key
    assert full.rigid.energy.value > 0 and full.rigid.loops >= 1
    assert isinstance(bare.rigid.energy, Missing) and bare.rigid.energy.reason == NO_CYCLE and bare.rigid.loops is None
    assert bare.events == () and bare.pull_off is None


def test_a_rough_branch_keeps_the_kink_where_the_rules_wall_stops_the_sphere():
    """mu = 0.0055, sigma = 1 behind K = 0.19: the roughness rule's outermost wall stops the sphere at lambda of about
    -5.7, dF/dlambda turning from 0 to 50 within 0.02 epsilon.  The fit's branch (its steps' bend bounded, WALL_BEND_F)
    reads within 1e-3 of 2 pi R w of a curve traced with steps of 0.01 in F and in the state (the refinement's
    truth: 2.1e-4 measured, against 0.044 with the steps bounded in F alone, 15 times the noise of 0.3%), and a
    synthetic curve's truth within 5e-4 (3.1e-4 measured, a tenth of that noise), with finer steps (as the
    coverage study makes them) within 5e-5 (1.1e-5)."""
    from dataclasses import replace

    from petsc_adhesion.fitting.branches import branch_settings
    from petsc_adhesion.fitting.synthetic import forward_curve, truth_settings

    model, K = Model(mu=0.0055, sigma=1.0), 0.19
    dense = forward_curve(model, K, 2.0, settings=curve_settings(observable_max=2.0, ds_max=0.01, observable_step=0.01))
    fit = forward_curve(model, K, 2.0, settings=branch_settings(model, 2.0))
    truth = forward_curve(model, K, 2.0, settings=truth_settings(model, 2.0))
    finer = forward_curve(model, K, 2.0, settings=truth_settings(model, 2.0, finer=2.0))
    loose = forward_curve(model, K, 2.0, settings=replace(branch_settings(model, 2.0), observable_bend=math.inf))
    Z = np.linspace(-40.0, dense.pieces[-1].Z_hi, 3000)
    for leg in (APPROACH, RETRACT):
        assert dense.jumps[leg] == fit.jumps[leg] == []
        assert np.max(np.abs(fit.predict(Z, leg) - dense.predict(Z, leg))) <= 1e-3
        assert np.max(np.abs(truth.predict(Z, leg) - dense.predict(Z, leg))) <= 5e-4
        assert np.max(np.abs(finer.predict(Z, leg) - dense.predict(Z, leg))) <= 5e-5
        assert np.max(np.abs(loose.predict(Z, leg) - dense.predict(Z, leg))) >= 1e-2
