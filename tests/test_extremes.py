"""Stiff and extreme cases: tiny and huge mu, large roughness, strong compression."""
import json

import numpy as np
import pytest

from petsc_adhesion.model.reference.rigid import RIGID_EQUILIBRIUM
from conftest import run_cli


def trace(tmp_path, *args, status=0):
    js, h5 = tmp_path / "s.json", tmp_path / "c.h5"
    proc = run_cli(*args, "-summary", js, "-out", h5)
    assert proc.returncode == status, proc.stderr
    return json.loads(js.read_text()), h5


def test_tiny_mu_is_the_rigid_limit(tmp_path):
    """mu = 1e-3: c = 3.4e-4, the elastic shift of the equilibrium scales with c ~ mu^1.5
    (measured 0.0056 at mu = 0.01, so ~1.8e-4 here) and the pull-off is -1 up to the
    truncation 5e-4 and the shift."""
    s, _ = trace(tmp_path, "-adh_mu", 0.001)
    assert abs(s["pull_off"]["F"] + 1) < 1e-3 and abs(s["pull_off"]["lambda"]) < 1e-3
    assert 0 < s["equilibria"][-1]["lambda"] - RIGID_EQUILIBRIUM < 5e-4
    assert s["folds"] == [] and s["warnings"] == [] and s["grid_warning"] == ""


@pytest.mark.parametrize("mu", [0.01, 1.0])
def test_large_roughness(tmp_path, mu):
    """sigma = 2: the wall of the 16-point rule is at H = 12.26; the attraction is weak and
    spread out, the reduction of the pull-off above 99% and nearly independent of mu."""
    s, h5 = trace(tmp_path, "-adh_mu", mu, "-adh_sigma", 2, "-adh_model_spread", "false")
    import h5py
    with h5py.File(h5) as f:
        H0 = f["curve/H0"][()]
    assert np.all(H0 > 2 * 6.6256 - 1)                      # never at or past the wall
    assert -0.01 < s["pull_off"]["F"] < -0.005
    assert s["folds"] == [] and s["warnings"] == []


def test_strong_compression(tmp_path):
    """mu = 1 up to F = 50, where (H + 1)^-9 dominates: the curve goes on monotonically,
    every state stays inside the domain, steps grow with the load (relative resolution)."""
    s, h5 = trace(tmp_path, "-adh_mu", 1, "-cont_F_max", 50)
    import h5py
    with h5py.File(h5) as f:
        # a new grid's first point repeats the last state of the grid before (F differs by ~1e-5)
        kept = f["curve/corrector"][()] != b"regrid"
        lam, F, H0 = (f["curve"][k][()][kept] for k in ("lambda", "F", "H0"))
    assert F[-1] >= 50 and np.all(np.isfinite(F))
    after = lam > s["equilibria"][-1]["lambda"]
    assert np.all(np.diff(F[after]) > 0)
    assert H0.min() > -1                                     # gap H + 1 > 0
    assert s["steps"] < 200


def test_huge_mu_on_coarse_grid_is_caught(tmp_path):
    """mu = 20 on the paper grid (h = 0.02): the cohesive zone 0.0084 is far below the
    spacing; the run stops early on the staircase and names the spacing it needs.  Without error bars: what
    is checked is the trace's stop and the grid's warning, the same with them (measured: 233 steps, 13 turning
    points, the same warnings), and their nested levels took 45% of its time (58 s of 131 by the run's own report)."""
    s, _ = trace(tmp_path, "-adh_mu", 20, "-grid_type", "paper", "-cont_error_estimate", "false",
                 status=3)                                                   # written, but not a curve: exit 3
    assert not s["complete"] and s["grid_warning"] in s["warnings"]
    assert "turning points" in s["stop_reason"]
    assert "needs spacing <= 0.00168" in s["grid_warning"]


def test_secondary_turning_points_at_mu5(tmp_path):
    """mu = 5 (paper Fig. 9: secondary turning points from mu = 5 on), on a grid that resolves
    the 0.067-wide cohesive zone (h = 0.01 on [0, 6]: 801 nodes).  Two fold pairs, snap-on and
    snap-off alternating along the curve, the secondary pair inside the primary hysteresis.
    The same four folds came out of a uniform 1001-node grid: -4.262812, -4.520195, -4.504167,
    -8.189277 (to 3e-7, the difference of the two grids).  What is checked is the grid's own values: the
    run computes no error bars (their nested levels took 18% of its time: 25 s of 142 by the run's own report)."""
    s, _ = trace(tmp_path, "-adh_mu", 5, "-grid_type", "paper", "-grid_paper_extra", 300, "-cont_lambda_max", -3,
                 "-cont_error_estimate", "false")
    assert s["grid_warning"] == ""
    kinds = [f["kind"] for f in s["folds"]]
    assert kinds == ["snap_on", "snap_off", "snap_on", "snap_off"]
    assert not any("lambda_grid" in f for f in s["folds"])        # no bars: lambda is the grid's value
    lam = [f["lambda"] for f in s["folds"]]
    assert np.allclose(lam, [-4.262812, -4.520195, -4.504167, -8.189277], atol=2e-6)
    on, off = lam[0], lam[3]
    assert off < lam[1] < lam[2] < on                        # secondary pair inside the primary
    assert all("landing" in f for f in s["folds"])
    # the JKR-like limit: pull-off near -0.75 (the paper's Fig. 8: near JKR for mu >= 5)
    assert -0.80 < s["pull_off"]["F"] < -0.75


# The hardest cells of docs/stability.md on the default grid, with reduced settings (no error bars,
# stopped past equilibrium): clean curves, the true number of turning points, no warning.  The counts
# are those of resolved grids: three fold pairs at mu = 20 (5, 10 and 20 nodes across the zone, and
# -grid_type paper with h = zone/5 give the same), two at mu = 7, 10 (paper Fig. 9), one at mu = 7,
# sigma = 0.4 and none at sigma = 1, where the rough edge is smooth.
HARDEST = {(20, 0.0): 6, (20, 0.4): 4, (10, 0.2): 4, (7, 0.4): 2, (10, 1.0): 0, (20, 1.0): 0}


@pytest.fixture(scope="module")
def hardest(tmp_path_factory):
    from test_cli import run_all
    d = tmp_path_factory.mktemp("hardest")
    procs = run_all({c: (("-adh_mu", c[0], "-adh_sigma", c[1], "-cont_F_max", 0.2, "-cont_error_estimate", "false",
                          "-adh_model_spread", "false", "-summary", d / f"{c[0]}_{c[1]}.json"), {}) for c in HARDEST})
    return {c: (p, d / f"{c[0]}_{c[1]}.json") for c, p in procs.items()}


@pytest.mark.parametrize("case", list(HARDEST), ids=[f"mu{m:g}-sigma{s:g}" for m, s in HARDEST])
def test_hardest_cells_trace_cleanly(hardest, case):
    proc, js = hardest[case]
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    assert s["complete"] and s["warnings"] == [] and s["grid_warning"] == ""
    assert len(s["folds"]) == HARDEST[case]
    kinds = [f["kind"] for f in s["folds"]]
    assert kinds == ["snap_on", "snap_off"] * (len(kinds) // 2)
    assert s["equilibria"] and s["wall_gap"] > 0.05


def test_stiff_end_bars_cover_a_refined_reference(tmp_path):
    """mu = 5 on the default grid: every fold's best value within its bar of the values located on the
    same grid designs refined 16 times (levels up to 4, extrapolated; bars below 3e-8):

        python -m petsc_adhesion -adh_mu 5 -target_error 1e-8     (140 s of error bars)

    The grid's own values are 2e-5 to 6e-4 off; the best ones 1e-8 to 5e-8 (measured), because the
    estimate uses only levels that resolve the contact edge (error_estimate.coarse_levels)."""
    reference = {"snap_on": [(-4.26358241, -0.08355878), (-4.50476259, -0.09323905)],
                 "snap_off": [(-4.52082488, -0.09654624), (-8.18976766, -0.42588509)]}
    s, _ = trace(tmp_path, "-adh_mu", 5, "-cont_lambda_max", -3)
    assert s["complete"] and s["warnings"] == []
    for kind, refs in reference.items():
        folds = [f for f in s["folds"] if f["kind"] == kind]
        assert len(folds) == len(refs)
        for f, (lam, F) in zip(folds, refs):
            assert abs(f["lambda"] - lam) <= f["lambda_err"] + 3e-8 and f["lambda_err"] < 1e-5
            assert abs(f["F"] - F) <= f["F_err"] + 3e-9 and f["F_err"] < 1e-6
            assert abs(f["lambda_grid"] - lam) > 100 * abs(f["lambda"] - lam)


@pytest.mark.parametrize("case", [(10.0, 0.2)], ids=["mu10-sigma0.2"])
def test_two_ranks_pass_the_stiff_folds_as_one_does(tmp_path, hardest, case):
    """Two ranks trace one rank's curve through every fold.  With block Jacobi on two ranks (the default
    before), GMRES could not converge beside the primary snap-off, where G_H is singular: mu = 5, sigma = 0
    and mu = 10, sigma = 0.2 both stopped there ("step below -cont_ds_min" at lambda = -8.19 and -12.58) with
    one fold pair found.  The suite keeps the stiffer of the two (the same defect, the same primary snap-off;
    mu = 5's two-rank run cost about 45 s more).  The one rank's run of a case of HARDEST (the same options)
    is the hardest fixture's."""
    args = ("-adh_mu", case[0], "-adh_sigma", case[1], "-cont_F_max", 0.2, "-cont_error_estimate", "false",
            "-adh_model_spread", "false")
    runs = []
    for np_ in (1, 2):
        js = tmp_path / f"np{np_}.json"
        if np_ == 1 and case in HARDEST:
            proc, js = hardest[case]
        else:
            proc = run_cli(*args, "-summary", js, np=np_)
        assert proc.returncode == 0, (np_, proc.stderr)
        runs.append(json.loads(js.read_text()))
    one, two = runs
    assert two["complete"] and two["steps"] == one["steps"]
    assert [f["kind"] for f in two["folds"]] == [f["kind"] for f in one["folds"]] and len(one["folds"]) == 4
    for a, b in zip(one["folds"] + [one["pull_off"]] + one["equilibria"], two["folds"] + [two["pull_off"]]
                    + two["equilibria"]):
        assert all(abs(a[q] - b[q]) <= 1e-8 for q in ("lambda", "F") if q in a), (a, b)
