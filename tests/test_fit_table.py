"""Curve fits through the curve family table (docs/fitting.md, "The search on the table"): the search on the
package's table, then the solver's curve at its optimum and one Gauss-Newton step; checked on curves the solver
made (not the table), against the solver's own fit, at a node of the table, and the refusals of -fit_table."""
import json
import math
import os

import numpy as np
import pytest

from conftest import ROOT, run_cli
from test_hostile import listing, one_line

from petsc_adhesion.family.table import shipped, shipped_path
from petsc_adhesion.fitting import table_search
from petsc_adhesion.fitting.curve_fit import CurveFitError, TableStep, fit_curve
from petsc_adhesion.fitting.forward import table_covers
from petsc_adhesion.fitting.results import FitChoice, Spring
from petsc_adhesion.fitting.synthetic import Sampling, synthetic_curve
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.model.physical import Bodies

R, EPS, W = 20e-9, 0.3e-9, 0.05
TIP = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS)
TIP_ARGS = ("-phys_radius", "20e-9", "-phys_epsilon", "0.3e-9")
GOLDEN_CURVE = os.path.join(ROOT, "tests", "data", "golden", "curve.csv")


def _curve(mu: float, noise_share: float = 0.01, seed: int = 1, k: float = 1.0, R_tip: float = R):
    """A curve made by the solver at mu (w = 0.05 J/m^2, E* by eq. 9), noise a share of 2 pi R w; its E*."""
    E = W * math.sqrt(R_tip / (mu**3 * EPS**3))
    truth = Bodies(radius=R_tip, young1=E, poisson1=0.0, epsilon=EPS, gamma=W)
    data = synthetic_curve(truth, Spring(k), Sampling(noise=noise_share * 2 * math.pi * R_tip * W, points=300,
                                                       z0=3e-9, F0=1e-10, seed=seed))
    return data, E


@pytest.mark.parametrize("mu", [0.003, 0.4, 25.0])
def test_a_fit_through_the_table_recovers_w_and_E(mu):
    """Three mu across the range, each between the table's nodes: w and E* within their 95% intervals, one to
    three solver curves after the search.  At mu = 0.003, the DMT end, the curve hardly depends on E* (a rigid
    sphere's): the fit says E* is undetermined instead of a number.  At mu = 25, the JKR side, the solver's
    branches are traced in units of mu (mu >= 20, fitting/branches.py), as at any larger mu: the tip is 0.5 um
    (the indentation at the top load, about 5 mu epsilon, within R/4, the model's domain) and the lever 25 N/m
    (K = 0.048, as 1 N/m on 20 nm).  (The case was mu = 60, 65 CPU s where 25 takes 49, measured in one
    process: w -0.52 and E* -1.30 bars off there, -1.31 and -1.33 at 25, two curves after the search at
    both.)"""
    scale = max(1.0, mu)
    data, E = _curve(mu, R_tip=R * scale, k=scale)
    fit = fit_curve(data, Bodies(radius=R * scale, young1=None, poisson1=None, epsilon=EPS), Spring(scale))
    assert isinstance(fit.path, TableStep) and fit.traces <= fit.path.curves + fit.path.differenced, fit.path
    assert fit.path.curves <= 3, fit.path
    assert abs(fit.gamma.value - W) <= 1.96 * fit.gamma.err
    if mu < 0.01:
        assert not fit.E_star and "interval" in fit.E_star.reason
        assert fit.warnings == (f"E_star undetermined: {fit.E_star.reason}",)
        return
    assert fit.trustworthy, fit.warnings
    assert abs(fit.E_star.value - E) <= 1.96 * fit.E_star.err
    assert fit.mu == pytest.approx(mu, rel=0.2)
    assert any(n.startswith("the search ran on the table default") for n in fit.notes), fit.notes


def test_the_table_and_the_solver_agree_within_their_bars(monkeypatch):
    """One curve fitted through the table and by the solver alone (-fit_table none): w and E* within the smaller
    of the two bars of each other; the solver alone traced many curves, the table's path one: its first step,
    from the table's optimum, is 0.036 bars (the table's error alone: its first curve at the table's optimum
    itself, no lattice), within STEP_BARS.  On the table's earlier nodes, whose splines overshot the pull-off by
    up to 1.7e-2 about mu = 0.05 (docs/family.md), that step was 3 bars and a second curve was traced."""
    monkeypatch.setattr(table_search, "on_lattice", lambda x, names, sd, lo, hi: (x, None))
    data, _ = _curve(0.05, seed=2)
    t = fit_curve(data, TIP, Spring(1.0))
    s = fit_curve(data, TIP, Spring(1.0), table="none")
    assert isinstance(t.path, TableStep) and s.path == "the solver's curves throughout: -fit_table none"
    for a, b in ((t.gamma, s.gamma), (t.E_star, s.E_star)):
        assert abs(a.value - b.value) <= min(a.err, b.err), (a, b)
    assert t.path.curves == 1 and t.traces == 1 + t.path.differenced and s.traces > 5
    assert t.path.first < table_search.STEP_BARS
    # the last step is a share of the bar, not the whole of it
    assert np.all(t.path.bars[:2] < 0.5), t.path.bars


def test_the_step_vanishes_at_a_node(monkeypatch):
    """At mu = 1, a node of the table (there the table is the solver's curve sampled), the first step from the
    table's optimum is a small share of the bar (0.10 measured, in F0); half a cell away (mu = 10^0.125, a
    cell's centre) it is more than a bar (1.3: another curve is traced).  The first curve at the table's optimum
    itself (no lattice: the step is the table's error alone)."""
    monkeypatch.setattr(table_search, "on_lattice", lambda x, names, sd, lo, hi: (x, None))
    assert np.any(np.isclose(shipped().mu, 1.0, rtol=1e-12))
    at = fit_curve(_curve(1.0, noise_share=0.003)[0], TIP, Spring(1.0)).path
    mid = fit_curve(_curve(10**0.125, noise_share=0.003)[0], TIP, Spring(1.0)).path
    assert isinstance(at, TableStep) and isinstance(mid, TableStep)
    assert at.curves == 1 and at.first < 0.2 and np.max(at.bars[:2]) < 0.1, at
    assert mid.curves == 2 and mid.first > 5 * at.first, mid


def test_what_the_table_does_not_hold_goes_through_the_solver():
    """The package's table holds the smooth sphere of the default model: a fitted or a held roughness, another
    law, another domain, no far field are the solver's, each said; the default model is the table's."""
    table = shipped()
    assert table.sigma.tolist() == [0.0] and table.mu[0] == pytest.approx(1e-3) and table.mu[-1] == pytest.approx(1e3)
    assert table_covers(table, Model(), 150.0, False, 0.0) is None
    assert table_covers(table, Model(roughness="none"), 150.0, False, 0.0) is None
    assert table_covers(table, Model(), 150.0, True, 0.3) == "the roughness is fitted and the table holds sigma = 0 alone"
    assert table_covers(table, Model(sigma=0.5), 150.0, False, 0.5) == "sigma = 0.5 is outside the table's [0, 0]"
    assert table_covers(table, Model(), 10.0, False, 0.0) == "the domain ends at r_m = 10; the table's at 150"
    assert "far field" in table_covers(table, Model(farfield=False), 150.0, False, 0.0)
    assert table_covers(table, Model(roughness="weibull"), 150.0, False, 0.0).startswith("the roughness law is weibull")


def test_a_table_that_is_none_is_refused(tmp_path):
    """-fit_table: a file that is no table, in one line naming the option, exit 2, nothing written; in the
    library a CurveFitError; and -fit_table with a pull-off is refused as every option of -fit_curve."""
    bad, half = tmp_path / "bad.npz", tmp_path / "half.npz"
    bad.write_bytes(b"not a table")
    raw = open(shipped_path("smooth"), "rb").read()
    half.write_bytes(raw[:len(raw) // 2])           # a table cut short (a copy interrupted)
    out = tmp_path / "out"
    out.mkdir()
    for given, why in ((bad, "(not an .npz archive)"), (half, "(a truncated or corrupted .npz archive: ")):
        p = run_cli("-fit_curve", GOLDEN_CURVE, *TIP_ARGS, "-phys_spring", "1", "-fit_table", given,
                    "-summary", out / "f.json")
        msg = one_line(p)
        assert msg.startswith(f"-fit_table: {given}: not a curve family table {why}") and \
            msg.endswith("expected a table file, default or none"), msg
        assert listing(out) == []
    p = run_cli("-fit_pull_off", "12e-9", *TIP_ARGS, "-phys_young1", "150e9", "-phys_poisson1", "0.27",
                "-fit_table", "none", "-summary", out / "f.json")
    assert one_line(p) == "-fit_table: only with -fit_curve"
    assert listing(out) == []
    with pytest.raises(CurveFitError, match="^the table: "):
        fit_curve(_curve(0.01)[0], TIP, Spring(1.0), table=str(bad))


def test_the_command_line_says_its_path(tmp_path):
    """The golden curve on the command line: through the table by default (its note in the summary and the
    report), the solver alone with -fit_table none; w's interval covers the truth either way."""
    notes = {}
    for how in ("default", "none"):
        out = tmp_path / f"{how}.json"
        p = run_cli("-fit_curve", GOLDEN_CURVE, *TIP_ARGS, "-phys_spring", "1", "-fit_table", how, "-summary", out)
        assert p.returncode == 0, p.stderr
        fit = json.load(open(out))["fit"]
        notes[how] = fit["notes"]
        assert abs(fit["gamma"] - 0.05) <= 1.96 * fit["gamma_err"]
        assert any(n.startswith("the search ran on the table" if how == "default" else
                                "the solver's curves throughout") for n in fit["notes"]), fit["notes"]
        assert (how == "default") == ("the search ran on the table default" in p.stdout)


def test_the_error_is_measured_on_the_piece_each_point_is_on():
    """At a node (mu = 2, where the curve folds: its far piece and contact overlap in lambda between the jumps)
    the table is the solver's curve sampled: behind K = 0.5 its force at the solver's own points is the
    solver's to the sampling's error.  Read on whichever piece's lambda range holds a point, as the error
    measurement once did, contact points were compared with the far branch: an 'error' of 0.68."""
    from petsc_adhesion.benchmarks.family import _spring
    from petsc_adhesion.family.build import TableGrid, build

    table = build(TableGrid(mu=(2.0,), sigma=(0.0,), n_tau=150))
    eF, eZ, eJ = _spring(table, 2.0, 0.0, 0.5)
    assert eF < 1e-3 and eZ < 1e-3 and eJ < 1e-3, (eF, eZ, eJ)


def _rough_curve(mu: float, sigma: float, k: float = 1.0, noise_share: float = 0.01, seed: int = 3):
    """A curve the solver made at (mu, sigma) behind k N/m (w = 0.05 J/m^2, E* by eq. 9), noise a share of
    2 pi R w; its E*."""
    E = W * math.sqrt(R / (mu**3 * EPS**3))
    truth = Bodies(radius=R, young1=E, poisson1=0.0, epsilon=EPS, gamma=W, rms=sigma * EPS)
    return synthetic_curve(truth, Spring(k), Sampling(noise=noise_share * 2 * math.pi * R * W, points=300,
                                                      z0=3e-9, F0=1e-10, seed=seed)), E


@pytest.mark.parametrize("mu, sigma", [(0.2, 0.12), (0.2, 0.25)])
def test_a_rough_curve_fitted_through_the_rough_table_recovers_w_and_E(mu, sigma):
    """A curve the solver made on a rough surface (mu = 0.2 between the rough table's nodes; sigma = 0.12 between
    them, and 0.25, above the earlier table's 0.2), its roughness held at the truth, searched on the shipped rough
    table: w and E* within their 95% intervals, the path the table's and one to three solver curves after it.  (A
    fitted roughness is refused by a table that does not hold sigma from 0 to 3, the search's range: it would
    leave the table mid-fit.)"""
    data, E = _rough_curve(mu, sigma)
    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS, rms=sigma * EPS)
    fit = fit_curve(data, tip, Spring(1.0), table="rough")
    assert isinstance(fit.path, TableStep) and fit.path.table == "rough" and 1 <= fit.path.curves <= 3, fit.path
    assert fit.sigma == pytest.approx(sigma)
    for got, want in ((fit.gamma, W), (fit.E_star, E)):
        assert abs(got.value - want) <= 1.96 * got.err, (got, want)


@pytest.fixture(scope="module")
def default_rough_fit():
    """-fit_table default with the roughness fitted (mu = 0.0055, sigma = 1, behind 4 N/m, K = 0.19; 0.3% noise,
    seed 1): the fit, and the truth (w, E*, rms)."""
    mu, sigma = 0.0055, 1.0
    data, E = _rough_curve(mu, sigma, k=4.0, noise_share=0.003, seed=1)
    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS)
    return fit_curve(data, tip, Spring(4.0), FitChoice(roughness=True)), (W, E, sigma * EPS)


def test_a_fitted_roughness_by_default_is_searched_on_the_rough_table_where_it_holds_mu(default_rough_fit):
    """The rough table holds sigma over the whole search but mu only to 1, so the fit searches it first and keeps
    it, mu's 95% interval ending inside the table: the path the rough table's, at most 6 curves traced (on the
    solver's curves throughout such a fit took 74 traces), no warning, and each of w, E* and sigma with a bar
    within 3 standard deviations of the truth (see the next test for the 95% intervals)."""
    fit, truth = default_rough_fit
    assert isinstance(fit.path, TableStep) and fit.path.table == "rough", fit.path
    assert fit.traces <= 6 and not fit.warnings, (fit.traces, fit.warnings)
    for got, want in zip((fit.gamma, fit.E_star, fit.rms), truth):
        assert abs(got.value - want) <= 3.0 * got.err, (got, want)


def test_the_default_rough_fit_holds_the_truth_in_its_95_percent_intervals(default_rough_fit):
    """w, E* and sigma each within 1.96 of its bars of the truth.  Held as a strict xfail until the search's start
    was mended: behind this lever (K = 0.19, stiffer than the rough curve's well: no jump-off) every start put its
    contact point at the far end of the model's curve, 25 epsilon off, and the search that began from the smooth
    start alone stopped on the valley's side, w 2.1 and sigma 2.8 bars from the truth, its chi^2 782 above the
    777.8 that sigma held at the truth reaches (the bars were not short: the optimum was not found).  Now
    chi^2 776: w 1.5, sigma 1.3, E* 0.2 bars off."""
    fit, truth = default_rough_fit
    for got, want in zip((fit.gamma, fit.E_star, fit.rms), truth):
        assert abs(got.value - want) <= 1.96 * got.err, (got, want)


def test_a_rough_curve_whose_lever_is_stiffer_than_its_well_is_aligned_on_its_least_force():
    """Behind K = 0.19 the rough curve of mu = 0.0055, sigma = 1 has no jump-off (the lever is stiffer than its
    well, 0.03 of 2 pi R w deep): the start's contact point is then put where the model's least force meets the
    measured pull-off.  It was put at the curve's far end, 25 epsilon off, where the model is flat over the data:
    with sigma held at the truth the search went to w's bound 1e-6 J/m^2, reduced chi^2 1.9e5.  Now w within its
    95% interval (0.0492 +- 0.0011 against 0.05), chi^2 of the noise's order."""
    data, _ = _rough_curve(0.0055, 1.0, k=4.0, noise_share=0.003, seed=1)
    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS, rms=1.0 * EPS)
    fit = fit_curve(data, tip, Spring(4.0), table="rough")
    assert not fit.warnings, fit.warnings
    assert fit.chi2 / fit.dof < 1.5, fit.chi2 / fit.dof
    assert abs(fit.gamma.value - W) <= 1.96 * fit.gamma.err, fit.gamma


def test_a_rough_fit_whose_mu_reaches_the_rough_tables_end_goes_to_the_solver():
    """The rough table's fit kept or not by where mu's 95% interval ends (ln mu = (2/3)(ln w - ln E*) + const, eq.
    9): a fit at half the table's last mu whose interval in ln mu is +-0.2 ends at 0.61 of it, inside the table:
    kept; at +-0.9 at 1.23 of it: the fit is made again on the solver's curves, its path saying so; so too where
    the table's fit is a misfit (p below MISFIT_P).  Where the table's profile of mu ran (mu hardly determined),
    its end decides, not the linear interval: +-0.9 with the profile ending at 0.8 of the table's last mu is
    kept, and with the profile at the table's end it is not; nor is a mu at the table's end whose profile ran
    inwards alone (ending a hair inside: case 83 of the coverage study was kept so)."""
    from dataclasses import dataclass, replace

    from petsc_adhesion.fitting.forward import rough_first

    @dataclass(frozen=True)
    class Fit:                          # what rough_first reads of a CurveFit
        mu: float
        parameters: tuple
        covariance: np.ndarray
        path: object
        p_value: float
        reduced_chi2: float = 1.0

    @dataclass(frozen=True)
    class OnTable:
        table: str = "rough"
        mu_span: tuple | None = None

    rough = shipped("rough")
    if rough.mu[-1] >= 1e3:
        pytest.skip("the rough table holds all of mu: the default takes it itself")
    made = []

    def fit(table, half, p=0.5, span=None):
        made.append(table)
        # var ln mu = (4/9)(var ln w + var ln E*) with no covariance: half = 1.96 sqrt(var)
        v = (half / 1.96) ** 2 * 9.0 / 8.0
        path = OnTable(mu_span=span) if table == "rough" else "the solver's curves throughout"
        return Fit(0.5 * float(rough.mu[-1]), ("ln_E_star", "ln_gamma", "sigma"), np.diag([v, v, 0.01]), path, p)

    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS)
    kept = rough_first(lambda t: fit(t, 0.2), FitChoice(roughness=True), None, tip, (1e-3, 1e3))
    assert made == ["rough"] and kept.path.table == "rough"
    made.clear()
    again = rough_first(lambda t: fit(t, 0.9), FitChoice(roughness=True), None, tip, (1e-3, 1e3))
    assert made == ["rough", "none"] and f"95% interval up to {1.23 * float(rough.mu[-1]):.3g}" in again.path, again.path
    made.clear()                         # inside the table, but a misfit (another valley than the data's)
    again = rough_first(lambda t: fit(t, 0.2, p=1e-9), FitChoice(roughness=True), None, tip, (1e-3, 1e3))
    assert made == ["rough", "none"] and "misfit the data" in again.path, again.path
    edge = float(rough.mu[-1])
    made.clear()
    kept = rough_first(lambda t: fit(t, 0.9, span=(1e-3, 0.8 * edge)), FitChoice(roughness=True), None, tip,
                       (1e-3, 1e3))
    assert made == ["rough"] and kept.path.table == "rough"
    made.clear()
    again = rough_first(lambda t: fit(t, 0.9, span=(1e-3, edge)), FitChoice(roughness=True), None, tip, (1e-3, 1e3))
    assert made == ["rough", "none"] and f"95% interval up to {edge:.3g}" in again.path, again.path
    made.clear()                         # at the table's end, its profile running inwards alone
    again = rough_first(lambda t: replace(fit(t, 0.9, span=(0.5 * edge, edge * (1 - 1e-8))), mu=edge),
                        FitChoice(roughness=True), None, tip, (1e-3, 1e3))
    assert made == ["rough", "none"] and f"stopped at mu = {edge:.3g}, the table's end" in again.path, again.path


def test_the_default_takes_the_rough_table_where_its_range_holds_the_fit():
    """-fit_table default: the smooth table without roughness; the rough one where the fit has a roughness
    held > 0 and the rough table's range holds the fit's, its sigma and all the mu the fit may reach (the
    model's, [1e-3, 1e3]); else the smooth one, whose refusal of a roughness sends the fit to the solver with
    its reason.  The rough table holds a held roughness of the default model inside its range, and refuses a
    fitted one unless it holds sigma 0 to 3."""
    from petsc_adhesion.family.build import select
    from petsc_adhesion.family.table import default_table
    from petsc_adhesion.fitting.domain import MU_BOUNDS

    rough = shipped("rough")
    inside = (float(rough.mu[0]), float(rough.mu[-1]))
    top = float(rough.sigma[-1])
    assert default_table(0.0, False, inside) == "smooth"
    assert default_table(0.1, False, inside) == "rough"
    assert default_table(top + 0.1, False, inside) == "smooth"
    assert default_table(0.1, False, MU_BOUNDS) == ("rough" if rough.mu[-1] >= MU_BOUNDS[1] else "smooth")
    assert table_covers(rough, Model(sigma=0.1), 150.0, False, 0.1) is None
    # a fitted roughness needs the search's whole sigma range, [0, 3]
    assert table_covers(rough, Model(), 150.0, True, 0.1) == (None if top >= 3 else
                                                              f"the roughness is fitted over [0, 3] and the table holds sigma in [0, {top:g}]")
    assert table_covers(select(rough, sigma=range(rough.sigma.size - 1)), Model(), 150.0, True, 0.1) == \
        f"the roughness is fitted over [0, 3] and the table holds sigma in [0, {rough.sigma[-2]:g}]"
    assert table_covers(rough, Model(roughness="weibull"), 150.0, False, 0.1).startswith("the roughness law is")


def test_a_rough_search_on_the_table_keeps_the_least_of_its_best_starts():
    """table_search.searched runs the least squares from the start given and, for a rough search, from the next
    SEARCH_STARTS - 1 of the tries by their chi^2 (each moved just inside the bounds), and keeps the result of
    least cost: a run whose cost is its start's distance from 2 keeps the try nearest 2 among the best three
    by chi^2, never a worse-ranked try nor, for a search that is not rough, any but the start given."""
    from types import SimpleNamespace

    ran = []

    def run(x):
        ran.append(float(x[0]))
        return SimpleNamespace(x=x, cost=abs(float(x[0]) - 2.0))

    tries = [(np.array([v]), chi2) for v, chi2 in ((0.0, 5.0), (1.9, 3.0), (5.0, 1.0), (2.0, 9.0), (3.0, 2.0))]
    lo, hi = np.array([0.0]), np.array([10.0])
    best = table_search.searched(run, np.array([5.0]), tries, lo, hi, True)
    assert ran == pytest.approx([5.0, 3.0, 1.9]) and float(best.x[0]) == pytest.approx(1.9), ran
    ran.clear()
    assert float(table_search.searched(run, np.array([0.0]), tries, lo, hi, False).x[0]) == pytest.approx(0.0, abs=1e-8)
    assert len(ran) == 1 and ran[0] > 0.0, ran          # moved just inside its bound


def test_case_134_of_the_coverage_study_is_fitted_on_the_rough_table():
    """The coverage study's case 134 (mu = 0.0038, sigma = 0.43, K = 0.24, 0.3% noise): its search on the rough
    table had ended in the corner w = 1e-6 J/m^2, sigma = 3 (reduced chi^2 2.6e4) from the best start, and the
    fit went on to the solver's curves throughout (51 CPU s); the several starts found the valley, and since the
    starts' contact points are aligned on the least force where a curve has no jump-off, the best start alone
    does.  No misfit, w, E* and sigma with bars, within three of them of the truth (measured 0.2, 1.1 and 0.1
    standard deviations)."""
    from petsc_adhesion.benchmarks.fitting import _synthetic

    data, truth, bodies, spring = _synthetic(0.0038021286586764195, 0.24453432085978596, 0.003, 234, None, True,
                                             sigma=0.434572)
    fit = fit_curve(data, bodies, spring, FitChoice(roughness=True), table="rough")
    assert fit.p_value > 1e-6 and not fit.warnings, fit.warnings
    for got, want in ((fit.gamma, truth["gamma"]), (fit.E_star, truth["E_star"]), (fit.rms, truth["rms"])):
        assert abs(got.value - want) <= 3.0 * got.err, (got, want)


def test_a_mu_at_the_rough_tables_end_is_said_at_the_tables_bound():
    """A curve of mu = 3 (sigma 0.3 held) searched on the rough table's nodes up to mu = 1 alone: its mu stops at
    the table's end, and the warning names the table's range, not the model's (it said "mu = 1 is at the bound
    1000 of the model's range": the table is gone once the solver's curves take over, and the range was read
    from it)."""
    from petsc_adhesion.family.build import select

    rough = shipped("rough")
    to_1 = select(rough, mu=np.flatnonzero(rough.mu <= 1.0 + 1e-9))
    mu, sigma = 3.0, 0.3
    data, E = _rough_curve(mu, sigma)
    tip = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS, rms=sigma * EPS)
    fit = fit_curve(data, tip, Spring(1.0), table=to_1)
    said = [w for w in fit.warnings if "is at the bound" in w]
    assert fit.mu == pytest.approx(1.0, rel=0.02) and said, (fit.mu, fit.warnings)
    assert all("of the table's range [0.001, 1]" in w for w in said), said
