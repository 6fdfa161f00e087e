"""The critical roughness and Tabor parameter (petsc_adhesion.tracing.critical, -study_compute critical).

The cusp is checked against what it claims: ordinary load-approach curves (the
command line's own tracing, independent of the fold continuation) have the fold
pair just below sigma_c and none just above it, and none just below mu_c(0) but
the pair just above it; the cusp found by continuing the fold in sigma at mu = 2
is found again by continuing it in mu at that sigma; the grid values converge
and the bar covers the step to the extrapolated value.
"""
import json
import os

import h5py
import numpy as np
import pytest

import petsc_adhesion as pa
from conftest import run_cli

#: sigma_c(2) to 7 digits (docs/figures/critical_roughness.json: 0.32712259 +- 3e-8); mu_c there must be 2.
SIGMA_AT_2 = 0.3271226
#: |d mu_c / d sigma| near (2, 0.327) is about 14 (sigma_c(2.5) - sigma_c(2) = 0.036): a generous bound.
SLOPE = 20.0


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """sigma_c at mu = 0.5 (below the onset of hysteresis: a failed case) and 2; mu_c at sigma = 0 and at
    SIGMA_AT_2."""
    tmp = tmp_path_factory.mktemp("critical")
    files = {k: tmp / f"c.{k}" for k in ("h5", "json", "png")}
    proc = run_cli("-study_compute", "critical", "-study_mu", "0.5,2", "-study_sigma", f"0,{SIGMA_AT_2}",
                   "-out", files["h5"], "-summary", files["json"], "-plot", files["png"], timeout=600)
    return proc, json.loads(files["json"].read_text()), files


def test_failed_case_is_one_line_and_the_rest_stands(study):
    proc, s, files = study
    assert proc.returncode == 3, proc.stderr
    bad = [ln for ln in proc.stderr.splitlines() if "failed" in ln]
    assert len(bad) == 1 and "case 1 (mu = 0.5)" in bad[0] and "no hysteresis" in bad[0], proc.stderr
    assert [f["case"] for f in s["failed"]] == [0]
    assert [c["mu"] for c in s["critical_roughness"]] == [2.0]
    assert [c["sigma"] for c in s["critical_mu"]] == [0.0, SIGMA_AT_2]
    with h5py.File(files["h5"], "r") as f:
        assert f.attrs["kind"] == "critical"
        assert np.allclose(f["critical_roughness/sigma_c"][()], [s["critical_roughness"][0]["sigma_c"]], rtol=0,
                           atol=0)
        assert f["critical_mu/mu_c_grid"].shape == (2, 3)
    assert files["png"].stat().st_size > 10_000


def test_sigma_c_grid_converged(study):
    """The values on the nested levels converge at second order, and one level finer (levels 1-3
    instead of 0-2) moves the best values by less than their bars."""
    from petsc_adhesion.tracing import critical
    from petsc_adhesion.model.parameters import Model

    c = study[1]["critical_roughness"][0]
    g = np.array(c["sigma_c_grid"])
    d = np.abs(np.diff(g))
    assert c["n_nodes"][1] > 1.9 * c["n_nodes"][0] and c["n_nodes"][2] > 1.9 * c["n_nodes"][1]
    assert d[1] < d[0] / 2.5, g                       # second order: differences shrink about 4x
    assert c["sigma_c_err"] < 1e-6 and c["sigma_c_domain"] < c["sigma_c_err"]
    assert abs(c["sigma_c"] - SIGMA_AT_2) < 1e-7       # the value the figure reports
    finer = critical.sigma_c(Model(rmax=c["rmax"]), 2.0, grid_refinements=(1, 2, 3))
    assert finer.kind == "sigma_c" and finer.fixed == 2.0 and finer.levels == (1, 2, 3)
    assert finer.n_nodes[-1] > 3.8 * c["n_nodes"][-2]
    for k, m in (("sigma_c", finer.value), ("lambda_c", finer.lam), ("F_c", finer.F)):
        assert abs(m.value - c[k]) <= c[k + "_err"], (k, m.value, c[k], c[k + "_err"])


def test_fold_continued_in_mu_meets_fold_continued_in_sigma(study):
    """The cusp at (mu, sigma) = (2, sigma_c(2)) found again from the mu side: two different extended
    systems (G_sigma vs G_mu) whose zero is the same point."""
    s = study[1]
    c = s["critical_roughness"][0]
    m = s["critical_mu"][1]
    tol = SLOPE * (abs(SIGMA_AT_2 - c["sigma_c"]) + c["sigma_c_err"]) + m["mu_c_err"]
    assert abs(m["mu_c"] - 2.0) <= tol < 2e-6, (m["mu_c"], tol)
    assert abs(m["lambda_c"] - c["lambda_c"]) < 1e-5 and abs(m["F_c"] - c["F_c"]) < 1e-5


def test_two_ranks_per_case_equal_serial(study, tmp_path):
    """The fold system on two ranks (its collective borders and bordered solves) finds the serial cusp."""
    summ = tmp_path / "c.json"
    proc = run_cli("-study_compute", "critical", "-study_mu", "2", "-study_ranks", "2", "-summary", summ, np=2,
                   timeout=300)
    assert proc.returncode == 0, proc.stderr
    two, one = json.loads(summ.read_text())["critical_roughness"][0], study[1]["critical_roughness"][0]
    for k in ("sigma_c", "lambda_c", "F_c", "sigma_c_err"):
        assert abs(two[k] - one[k]) < 1e-10, (k, two[k], one[k])


@pytest.mark.parametrize("mu, sigma, pair", [
    (2.0, SIGMA_AT_2 - 3e-3, True), (2.0, SIGMA_AT_2 + 3e-3, False),
    (0.6972 + 5e-3, 0.0, True), (0.6972 - 5e-3, 0.0, False)])
def test_ordinary_curves_either_side_of_the_cusp(study, mu, sigma, pair):
    """Just inside the hysteresis region the traced curve has snap-on and snap-off near the cusp's
    lambda; just outside it has neither.  The grid's own curve is what says it (its events' bars and the
    roughness laws' spread add nothing to the count, and move lambda by ~1e-4 of the 0.05 asked): without
    them, 0.9 CPU s in place of 11.1 at mu = 2 (measured)."""
    s = study[1]
    cusp = s["critical_roughness"][0] if sigma else s["critical_mu"][0]
    if not sigma:
        assert abs(cusp["mu_c"] - 0.6972) < 1e-4
    c = pa.curve(mu=mu, sigma=sigma, cont_F_max=0.0, cont_error_estimate=False, adh_model_spread=False)
    on, off = c.events_of("snap_on"), c.events_of("snap_off")
    assert (len(on), len(off)) == ((1, 1) if pair else (0, 0)), c.events
    if pair:
        assert off[0].lam.value < on[0].lam.value
        assert abs(on[0].lam.value - cusp["lambda_c"]) < 0.05 and abs(off[0].lam.value - cusp["lambda_c"]) < 0.05


def test_solver_settings_reach_their_solvers_and_keep_the_cusp(study, tmp_path):
    """-fold_ksp_rtol, -arc_ksp_type (not the defaults: 1e-12 and gmres) honoured: PETSc's own view of every
    fold-system KSP and every arclength KSP shows them, and sigma_c stays within the default run's bar."""
    summ, fold_view, arc_view = tmp_path / "c.json", tmp_path / "fold.txt", tmp_path / "arc.txt"
    proc = run_cli("-study_compute", "critical", "-study_mu", "2", "-summary", summ, "-fold_ksp_rtol", "1e-13",
                   "-arc_ksp_type", "bcgs", "-fold_ksp_view", f"ascii:{fold_view}", "-arc_ksp_view",
                   f"ascii:{arc_view}", timeout=300)
    assert proc.returncode == 0, proc.stderr
    for view, prefix, line in ((fold_view, "_fold_)", "relative=1e-13,"), (arc_view, "_arc_)", "type: bcgs")):
        blocks = view.read_text().split("KSP Object: (")[1:]
        assert len(blocks) > 10, (view, len(blocks))
        for b in blocks:
            head = b.split("\n", 1)[0]
            assert prefix in head and line in b.split("PC Object")[0], b[:400]
    mine, default = json.loads(summ.read_text())["critical_roughness"][0], study[1]["critical_roughness"][0]
    assert abs(mine["sigma_c"] - default["sigma_c"]) <= default["sigma_c_err"], (mine["sigma_c"], default)


def test_library_refuses_settings_it_cannot_honour():
    """sigma_c and mu_c make no fixed-approach solve and build dense preconditioners: the rest is refused
    before any work."""
    from petsc_adhesion.tracing import critical
    from petsc_adhesion.tracing.trace import PetscSettings, SolverChoice
    from petsc_adhesion.model.parameters import Model

    for solver, what in ((SolverChoice(fixed=PetscSettings(ksp_rtol=1e-3)), "solver.fixed"),
                         (SolverChoice(pmat="band"), "solver.pmat"), ("dense", "solver: expected a SolverChoice")):
        for call in (critical.sigma_c, critical.mu_c):
            with pytest.raises(ValueError, match=f"^{what}"):
                call(Model(rmax=10.0), 2.0, solver=solver)


@pytest.mark.parametrize("args, line", [
    (("-study_compute", "critical", "-study_mu", "2", "-ksp_type", "gmres"),
     "-ksp_type: -study_compute critical makes no fixed-approach solve; use -nat_ksp_type"),
    (("-study_compute", "critical", "-study_mu", "2", "-fold_ksp_foo", "3"), "-fold_ksp_foo: unknown option"),
    (("-study_compute", "critical", "-study_mu", "2", "-arc_ksp_typ", "gmres"),
     "-arc_ksp_typ: unknown option (did you mean -arc_ksp_type?)"),
    (("-study_compute", "critical", "-study_mu", "2", "-fold_snes_rtol", "1e-3"),
     "-fold_snes_rtol: the fold system's bordered solves have a KSP, no SNES"),
    (("-study_compute", "critical", "-study_mu", "2", "-fold_ksp_rtol", "2"), "-fold_ksp_rtol: expected a real"),
    (("-study_compute", "critical", "-study_mu", "2", "-adh_pmat", "band"), "-adh_pmat: not with -study_compute critical"),
    (("-study_compute", "critical", "-study_mu", "2", "-study_option", "adh_hermite_points", "-study_values", "8,16"),
     "-study_option: not with -study_compute critical"),
    (("-study_compute", "critical", "-study_mu", "2", "-study_plot", "curves"), "-study_plot: curves draws curves"),
    (("-study_mu", "2", "-study_plot", "critical"), "-study_plot: critical draws the cusps")])
def test_bad_critical_input(tmp_path, args, line):
    proc = run_cli(*args, "-out", tmp_path / "c.h5", "-summary", tmp_path / "c.json", "-plot", tmp_path / "c.png")
    assert proc.returncode == 2 and proc.stderr.startswith(f"petsc-adhesion: error: {line}"), proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and os.listdir(tmp_path) == []
