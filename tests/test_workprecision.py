"""The work-precision benchmark (petsc_adhesion/benchmarks/workprecision) measures what it says.

Numbers against independent truth, never timings (the cores are shared):

* the plain numpy/scipy implementation and ours, two independent codes for the same
  discrete problem (mu = 1, paper grid), agree on every event to the solvers' tolerances;
* the errors of uniform grids shrink at the collocation's order 2 at small N;
* the stored ContactMechanics runs (an independent code, a 2-D FFT half-space) agree with
  our half-infinite model to their own resolution;
* the scaling worker runs in its own process and reports its memory.
"""
import json
import subprocess
import sys

import pytest

from conftest import ROOT, _env

from petsc_adhesion.discretization import grid
from petsc_adhesion.benchmarks.workprecision import accuracy as wp
from petsc_adhesion.benchmarks.workprecision.render import table_case
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.discretization.problem import far_approach

#: the half-infinite model at mu = 1, default run (README; error bars about 1e-6 and below)
PULL_OFF_F, SNAP_ON, SNAP_OFF = -0.8353323, -1.6292167, -1.7434298


@pytest.fixture(scope="module")
def paper_mu1():
    model = Model(mu=1.0, rmax=10.0)
    return model, wp._trace(model, grid.paper(10.0))


def test_numpy_reference_reproduces_ours(paper_mu1):
    model, ours = paper_mu1
    mine = wp.quantities(ours, grid_values=True)
    ref = wp._numpy_values(wp.numpy_curve(1.0, grid.paper(10.0), far_approach(model), F_max=0.2))
    assert ref["folds"][0] == mine["folds"][0] == 2
    for q in ("snap-on lambda", "snap-off lambda", "pull-off F", "equilibrium lambda"):
        assert abs(ref[q][0] - mine[q][0]) < 1e-6, (q, ref[q][0], mine[q][0])
    # the pull-off lambda is ill-conditioned (F is flat there: an error e in F moves it by sqrt(e))
    assert abs(ref["pull-off lambda"][0] - mine["pull-off lambda"][0]) < 1e-4
    # and both are the paper's problem: close to the half-infinite model, within the r_m = 10 truncation
    assert abs(mine["snap-on lambda"][0] - SNAP_ON) < 3e-4 and abs(mine["pull-off F"][0] - PULL_OFF_F) < 3e-5


def test_uniform_grids_converge_at_order_two():
    model = Model(mu=1.0, rmax=10.0)
    recs = [wp._record("uniform grid, r_m = 10", [1.0], wp.quantities(wp._trace(model, grid.uniform(n, 10.0)), True),
                       n, n) for n in (101, 201, 401)]
    orders = wp.observed_orders(recs)
    for q in ("pull-off F", "snap-on lambda", "snap-off lambda"):
        (n, p), = orders[q]
        assert n == 401 and 1.7 < p < 2.3, (q, p)
    # the changes shrink with N
    for q in ("pull-off F", "snap-on lambda", "snap-off lambda", "equilibrium lambda"):
        x = [r["values"][q][0] for r in recs]
        assert abs(x[2] - x[1]) < abs(x[1] - x[0]) / 2.5, q


def test_contactmechanics_points_agree_to_their_resolution():
    pts = wp.contactmechanics_points()
    assert [p["n"] for p in pts] == [64, 128, 256] and all(p["wall_time_s"] > 0 for p in pts)
    finest = pts[-1]["values"]
    assert abs(finest["pull-off F"][0] - PULL_OFF_F) < 3e-4
    for q, truth in (("snap-on lambda", SNAP_ON), ("snap-off lambda", SNAP_OFF)):
        value, half_bracket = finest[q]
        assert abs(value - truth) < half_bracket + 1e-3, q
    assert "equilibrium lambda" not in finest          # its curves stop at lambda = 0.5


def test_quantities_pick_the_primary_folds():
    ev = [{"kind": "snap_on", "lambda": -4.26, "F": -0.08}, {"kind": "snap_off", "lambda": -4.52, "F": -0.09},
          {"kind": "snap_on", "lambda": -4.50, "F": -0.09}, {"kind": "snap_off", "lambda": -8.19, "F": -0.43},
          {"kind": "equilibrium", "lambda": 9.82, "F": 0.0, "lambda_err": 1e-6, "lambda_grid": 9.8}]
    res = {"events": ev, "pull_off": {"lambda": -3.96, "F": -0.76, "F_err": 2e-7, "lambda_err": 3e-7}}
    q = wp.quantities(res)
    assert q["snap-on lambda"][0] == -4.26 and q["snap-off lambda"][0] == -8.19 and q["folds"][0] == 4
    assert q["pull-off F"] == (-0.76, 2e-7) and q["equilibrium lambda"] == (9.82, 1e-6)
    assert wp.quantities(res, grid_values=True)["equilibrium lambda"] == (9.8, None)


def test_table_and_errors(paper_mu1):
    _, ours = paper_mu1
    truth = {"tol": 1e-5, "wall_time_s": 1.0, "n_nodes": 297, "warnings": [],
             "values": {"pull-off F": (PULL_OFF_F, 1e-7), "pull-off lambda": (-0.87338, 3e-7),
                        "snap-on lambda": (SNAP_ON, 2e-7), "snap-off lambda": (SNAP_OFF, 2e-6),
                        "equilibrium lambda": (2.0750694, 2e-7), "folds": (2, None)}}
    rec = wp._record("paper grid, extrapolated", [1.0, 2.0, 3.0], wp.quantities(ours, True), None, 531)
    err = wp.errors(rec, truth)
    assert rec["median_s"] == 2.0 and all(e is not None and e < 2e-4 for e in err.values())
    text = table_case({"case": "mu1", "mu": 1.0, "sigma": 0.0, "truth": truth, "records": [rec]})
    assert "| paper grid, extrapolated |" in text and "Domain truncation" in text


def test_scale_worker_runs_in_its_own_process():
    cmd = [sys.executable, "-m", "petsc_adhesion.benchmarks.workprecision", "scale", "100", "band", "2"]
    run = subprocess.run(cmd, cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["n"] == 100 and out["pmat"] == "band" and out["ranks"] == 1 and out["solve_ok"]
    assert out["steps"] == 2 and 10 < out["rss_max_mib"] < 2000
