"""The instrument's legs behind a spring (tracing/legs.py): approach and retract, the trigger, the files, the figure.

Judged against constructions of their own: Z = lambda + F / K on the traced branch and each traced point
of a leg a point of the branch stable behind the spring, Z monotone along a leg, each jump at constant Z
from the solver's turning point to the solver's landing; the polygon the two legs enclose against the
cycle's energy (integrated by tracing/energy.py on its own interpolant); the trigger against the
approach's last force within one step of the load; the rigid sphere's pull-off against DMT's closed form
and against the Gauss-Hermite average of eq. (28) computed here; the CSV against the HDF5 file bit for bit.
"""
import csv
import json
import os
import warnings

import matplotlib
import numpy as np
import pytest

from conftest import drawn_figure, run_cli

h5py = pytest.importorskip("h5py")
matplotlib.use("Agg")

K = 0.5
TRIGGER = 0.7
#: a 20 nm tip on glass behind a 1 N/m cantilever (docs/afm.md), no error bars: about a second
TIP = ("-phys_radius", "20e-9", "-phys_young1", "150e9", "-phys_poisson1", "0.27", "-phys_young2", "70e9",
       "-phys_poisson2", "0.17", "-phys_gamma", "0.05", "-phys_epsilon", "0.3e-9", "-phys_spring", "1")
PREFIX = "petsc-adhesion: error: "


@pytest.fixture(scope="module")
def traced():
    import petsc_adhesion as pa

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return pa.curve(mu=1.0, afm_spring=K, afm_trigger=TRIGGER)


def _grid(m) -> float:
    return float(m.grid if m.grid is not None else m.value)


def test_legs_are_the_stable_branch_behind_the_spring(traced):
    """Every point of a leg has Z = lambda + F / K; every point but the landings is a traced point stable
    behind the spring or a turning point; Z grows along the approach and falls along the retract; every
    stable traced point is on a leg (one hysteresis loop: no piece left unvisited)."""
    legs, b = traced.instrument, traced.branch
    assert legs.K == K and legs.approach.name == "approach" and legs.retract.name == "retract"
    stable = {(float(l), float(f)) for l, f, s in zip(b.lam, b.F, b.stable_spring) if s}
    folds = {(_grid(e.lam), _grid(e.F)) for e in traced.spring.jumps}
    seen = set()
    for leg, sign in ((legs.approach, 1), (legs.retract, -1)):
        np.testing.assert_allclose(leg.Z, leg.lam + leg.F / K, rtol=0, atol=1e-12 * np.abs(leg.Z).max())
        np.testing.assert_array_equal(leg.separation, -leg.lam)
        np.testing.assert_array_equal(leg.deflection, leg.F / K)
        assert np.all(sign * np.diff(leg.Z) >= -1e-12), leg.name
        landings = {i + 1 for i in leg.jumps}
        for i, (lam, F) in enumerate(zip(leg.lam, leg.F)):
            if i not in landings:
                assert (lam, F) in stable or (lam, F) in folds, (leg.name, i, lam, F)
                seen.add((lam, F))
    assert stable <= seen
    # the legs start and end together: the curve's first point and its last (the trigger)
    assert legs.approach.Z[0] == legs.retract.Z[-1] == b.Z[0] and legs.approach.Z[-1] == legs.retract.Z[0] == b.Z[-1]


def test_each_jump_lands_where_the_solver_found_its_landing(traced):
    """One jump a leg at mu = 1, K = 0.5: the approach's at the jump_in, the retract's at the jump_off, each from
    the turning point (its grid values) straight down or up at its Z to the solver's landing."""
    legs = traced.instrument
    for leg, kind in ((legs.approach, "jump_in"), (legs.retract, "jump_off")):
        assert len(leg.jumps) == 1
        i = leg.jumps[0]
        (e,) = traced.events_of(kind)
        assert leg.lam[i] == _grid(e.lam) and leg.F[i] == _grid(e.F)
        assert leg.Z[i + 1] == leg.Z[i]                                     # vertical
        assert leg.lam[i + 1] == _grid(e.landing.lam) and leg.F[i + 1] == _grid(e.landing.F)
        # the landing holds the jump's Z: lambda moved by the spring's extension
        assert abs(_grid(e.landing.lam) + _grid(e.landing.F) / K - leg.Z[i]) < 1e-6
    # jump-in: the tip is pulled onto the flat (F falls); jump-off: it lets go (F rises toward 0)
    a, r = legs.approach, legs.retract
    assert a.F[a.jumps[0] + 1] < a.F[a.jumps[0]] and r.F[r.jumps[0] + 1] > r.F[r.jumps[0]]


def test_the_legs_enclose_the_energy_of_the_cycle(traced):
    """The closed integral of F dZ round the legs' polygon (trapezoids on the solver's points) against the
    cycle's energy of tracing/energy.py (its own interpolant): within 1 %."""
    W = traced.spring.cycle.energy.value
    assert W > 0.1
    assert traced.instrument.area == pytest.approx(W, rel=1e-2)


def test_the_approach_ends_at_the_trigger(traced):
    """-afm_trigger 0.7: the curve stops at the first point past it, within one step of the load, which the
    trigger bounds to 1/50 of the range from the rigid pull-off (-1) to it."""
    from petsc_adhesion.tracing.legs import figure_step

    legs = traced.instrument
    step = figure_step(TRIGGER, -1.0)
    assert step == pytest.approx(1.7 / 50)
    assert legs.trigger == TRIGGER and legs.reached
    assert TRIGGER <= legs.approach.F[-1] <= TRIGGER + step
    assert np.all(np.abs(np.diff(traced.branch.F)) <= step * np.maximum(1.0, np.abs(traced.branch.F[:-1])) + 1e-12)


def test_the_rigid_pull_off_is_dmt_smooth_and_the_hermite_average_rough():
    """Smooth: DMT's -1 (eq. 28 at lambda = 0).  Gaussian roughness by the Gauss-Hermite rule: the least of
    the rule's average of eq. (28) over the shifted heights, found here by a fine scan and Brent."""
    from scipy.optimize import minimize_scalar

    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.model.reference.rigid import rigid_load
    from petsc_adhesion.tracing.legs import rigid_pull_off

    assert rigid_pull_off(Model(mu=1.0)) == pytest.approx(-1.0, abs=1e-4)
    sigma = 0.5
    x, w = np.polynomial.hermite_e.hermegauss(Model.hermite_points)
    w = w / w.sum()

    def load(H0):           # gap g = H0 + 1 - s, i.e. rigid_load at lambda = s - H0
        return float(np.sum(w * rigid_load(sigma * x - H0)))

    lo = sigma * x.max() - 1.0 + 1e-3
    H = np.linspace(lo, lo + 10.0, 20001)
    i = int(np.argmin([load(h) for h in H]))
    best = minimize_scalar(load, bracket=(H[i - 1], H[i], H[i + 1]))
    assert rigid_pull_off(Model(mu=1.0, sigma=sigma)) == pytest.approx(best.fun, rel=1e-3)
    assert -1.0 < best.fun < -0.1


@pytest.fixture(scope="module")
def tip(tmp_path_factory):
    d = tmp_path_factory.mktemp("tip")
    proc = run_cli(*TIP, "-cont_error_estimate", "false", "-out", d / "t.h5", "-csv", d / "t.csv",
                   "-summary", d / "t.json", "-plot", d / "t.png")
    assert proc.returncode == 0, proc.stderr
    return d


def _csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], {h.split(" [")[0]: [r[i] for r in rows[1:]] for i, h in enumerate(rows[0])}


def test_the_default_trigger_is_three_rigid_pull_offs(tip):
    """With a spring and physical inputs and no -cont_F_max: 3 times the rigid sphere's pull-off (-1, smooth);
    the approach got there."""
    with h5py.File(tip / "t.h5", "r") as f:
        g = f["instrument"]
        assert g.attrs["trigger"] == pytest.approx(3.0, abs=1e-3) and bool(g.attrs["reached"])
        assert g.attrs["units"].startswith("K: ") and "approach" in g and "retract" in g
        assert g["approach/F"].attrs["units"] == "2 pi R gamma" and g["retract/Z"].attrs["units"] == "epsilon"
        assert g["approach/F"][-1] >= g.attrs["trigger"]


def test_the_csv_holds_both_legs_as_the_h5_file(tip):
    """-csv behind a spring: the approach's rows then the retract's, each column the HDF5 leg's doubles, jump
    1 where the HDF5 jumps say, the physical twins the scale times the column."""
    header, cols = _csv(tip / "t.csv")
    assert header[:8] == ["leg", "Z [epsilon]", "separation [epsilon]", "deflection [epsilon]",
                          "F [2 pi R gamma]", "lambda [epsilon]", "contact_radius [sqrt(epsilon R)]", "jump"]
    assert {"Z_nm", "separation_nm", "deflection_nm", "F_nN", "contact_radius_nm"} <= set(cols)
    with h5py.File(tip / "t.h5", "r") as f:
        phys = dict(f["physical"].attrs)
        legs = {name: {k: f["instrument"][name][k][()] for k in f["instrument"][name]}
                for name in ("approach", "retract")}
    n = len(legs["approach"]["Z"])
    assert cols["leg"] == ["approach"] * n + ["retract"] * len(legs["retract"]["Z"])
    for k in ("Z", "separation", "deflection", "F", "lambda", "contact_radius"):
        got = np.array([float(c) for c in cols[k]])
        want = np.r_[legs["approach"][k], legs["retract"][k]]
        assert np.array_equal(got.view(np.uint64), want.view(np.uint64)), k
    jumps = [i for i, c in enumerate(cols["jump"]) if c == "1"]
    assert jumps == [int(i) for i in legs["approach"]["jumps"]] + [n + int(i) for i in legs["retract"]["jumps"]]
    F = np.array([float(c) for c in cols["F"]])
    assert np.array_equal(np.array([float(c) for c in cols["F_nN"]]), F * phys["force_nN"])
    Z, d = (np.array([float(c) for c in cols[k]]) for k in ("Z_nm", "deflection_nm"))
    np.testing.assert_allclose(Z - d, -np.array([float(c) for c in cols["separation_nm"]]), atol=1e-9)


def test_the_figure_is_force_in_nn_against_piezo_in_nm(tip):
    """The figure drawn from the file: its main panel force (nN) against piezo displacement (nm), approach and
    retract in two colours, the jumps, the pull-off and the energy labelled; the rigid machine's and the contact
    radius's panels beside it."""
    axes = drawn_figure(tip / "t.h5").axes
    main = next(ax for ax in axes if ax.get_xlabel() == "piezo displacement Z (nm)")
    assert main.get_ylabel() == "force (nN)"
    labels = main.get_legend_handles_labels()[1]
    for word in ("approach", "retract", "jump-in: Z = ", "pull-off: F = ", "jump-off: Z = ", "energy of a cycle",
                 "aJ", "trigger"):
        assert any(word in lab for lab in labels), (word, labels)
    colours = {ln.get_label(): ln.get_color() for ln in main.get_lines() if ln.get_label() in ("approach", "retract")}
    assert colours["approach"] != colours["retract"]
    assert any(ax.get_xlabel() == "approach lambda" for ax in axes)
    assert any("contact radius" in ax.get_ylabel() for ax in axes)
    img = matplotlib.image.imread(tip / "t.png")
    assert img.shape[1] > 1500 and img.std() > 0.01


NO_SPRING = TIP[:-2]


@pytest.mark.parametrize("args, line", [
    ((*TIP, "-afm_trigger", "1", "-phys_trigger", "1e-8"), "-phys_trigger: not with -afm_trigger"),
    ((*TIP, "-phys_trigger", "1e-8", "-cont_F_max", "1"), "-cont_F_max: not with -phys_trigger"),
    (("-adh_mu", "1", "-afm_spring", "0.5", "-phys_trigger", "1e-8"), "-phys_trigger: needs the bodies"),
    ((*NO_SPRING, "-afm_trigger", "1"), "-afm_trigger: needs a spring"),
    ((*TIP, "-afm_trigger", "0"), "-afm_trigger"),
])
def test_contradictions_are_one_line(tmp_path, args, line):
    """One line naming the option, exit 2, nothing written."""
    proc = run_cli(*args, "-out", tmp_path / "x.h5", cwd=tmp_path)
    lines = proc.stderr.splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and lines[0].startswith(PREFIX + line), proc.stderr
    assert os.listdir(tmp_path) == []


def test_a_trigger_in_newtons(tmp_path):
    """-phys_trigger 5 nN on the 20 nm tip: 5e-9 / (2 pi R gamma) = 5e-9 / 6.2832e-9 N by hand; the approach
    ends there, within one step of the load (1/50 of the range from the rigid pull-off, -1, to it)."""
    proc = run_cli(*TIP, "-phys_trigger", "5e-9", "-cont_error_estimate", "false", "-out", tmp_path / "n.h5")
    assert proc.returncode == 0, proc.stderr
    unit = 2 * np.pi * 20e-9 * 0.05
    with h5py.File(tmp_path / "n.h5", "r") as f:
        trigger, last = f["instrument"].attrs["trigger"], f["instrument/approach/F"][-1]
        force_nN = f["physical"].attrs["force_nN"]
    assert trigger == pytest.approx(5e-9 / unit, rel=1e-12)
    assert force_nN == pytest.approx(unit / 1e-9, rel=1e-12)
    step = (trigger + 1.0) / 50
    assert trigger <= last <= trigger + step
    # the stop is named as the user gave it, not as -cont_F_max (which was not given)
    proc = run_cli(*TIP, "-phys_trigger", "5e-9", "-cont_error_estimate", "false", "-summary", tmp_path / "n.json")
    assert proc.returncode == 0, proc.stderr
    stopped = json.loads((tmp_path / "n.json").read_text())
    assert "-phys_trigger 5e-9" in stopped["stop_reason"] and "-cont_F_max" not in stopped["stop_reason"], stopped
    assert stopped["physical"]["spring"]["trigger_nN"] == pytest.approx(5.0, rel=1e-12)    # as given, in nN


def test_a_piece_between_two_turning_points_has_them_at_its_ends_from_arrays_or_a_branch():
    """Three stable runs on a made-up branch (lambda = 0..11, F = 0, K = 1): the middle piece starts at its
    jump_off and ends at its jump_in, lambda growing along it (the turning points are where its run is left);
    the same pieces whether made from the arrays and Turns or from a traced-branch-like object and its events."""
    from types import SimpleNamespace as NS

    from petsc_adhesion.tracing.legs import Turn, branch_pieces, stable_pieces

    lam, F = np.arange(12.0), np.zeros(12)
    stable = np.array([1, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1, 1], dtype=bool)
    turns = {"jump_in": [Turn(2.5, 0.0), Turn(7.5, 0.0)], "jump_off": [Turn(3.5, 0.0), Turn(8.5, 0.0)]}
    pieces, notes = stable_pieces(lam, F, stable, 1.0, turns["jump_in"], turns["jump_off"])
    assert notes == []
    assert [p.lam.tolist() for p in pieces] == [[0, 1, 2, 2.5], [3.5, 4, 5, 6, 7, 7.5], [8.5, 9, 10, 11]]
    assert [(p.start is not None, p.end is not None) for p in pieces] == [(False, True), (True, True), (True, False)]

    def event(kind, t):
        value = (lambda v: NS(value=v, grid=v, err=None))
        return NS(kind=kind, lam=value(t.lam), F=value(t.F), contact_radius=None, landing=None)

    branch = NS(lam=lam, F=F, contact_radius=np.full(12, np.nan), stable_spring=stable)
    again, _ = branch_pieces(branch, [event(k, t) for k, ts in turns.items() for t in ts], 1.0)
    assert [p.lam.tolist() for p in again] == [p.lam.tolist() for p in pieces]
    assert all(np.array_equal(a.Z, p.Z) for a, p in zip(again, pieces))
