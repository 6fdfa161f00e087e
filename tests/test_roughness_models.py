"""Roughness models through the program: -adh_roughness truncated_gaussian, weibull, measured.

The pull-off of each converges as its quadrature is refined, unlike the
Gauss-Hermite rule; at small sigma every model approaches the smooth one as
sigma^2; measured Gaussian heights approach the truncated Gaussian; the result
files say which model they hold.  One grid for all runs (uniform, 201 nodes on
[0, 10]), so that differences are the roughness model's alone.
"""
import json

import h5py
import numpy as np
import pytest

from conftest import in_process
from test_cli import plain_error

GRID = ("-adh_mu", "1", "-grid_type", "uniform", "-grid_n", "201", "-adh_rmax", "10", "-cont_F_max", "0.2",
        "-cont_error_estimate", "false", "-adh_model_spread", "false")
TG = ("-adh_roughness", "truncated_gaussian")
WB = ("-adh_roughness", "weibull", "-adh_roughness_skewness", "-1")
POINTS = (3, 6, 12, 24, 48)


def gaussian_heights(path, sigma, n=100000, seed=2002):
    """n Gaussian heights of standard deviation sigma, cut at 3 sigma, one a line."""
    z = np.random.default_rng(seed).standard_normal(2 * n)
    np.savetxt(path, sigma * z[np.abs(z) <= 3][:n])
    return path


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("rough")
    heights = gaussian_heights(d / "h.txt", 0.2)
    jobs = {"smooth": [], "hermite16": ["-adh_sigma", "0.2"],
            "hermite32": ["-adh_sigma", "0.2", "-adh_hermite_points", "32"],
            "measured": ["-adh_roughness", "measured", "-adh_roughness_file", str(heights)],
            "tg_default": ["-adh_sigma", "0.2", *TG]}
    for n in POINTS:
        jobs[f"tg{n}"] = ["-adh_sigma", "0.2", *TG, "-adh_quadrature_points", str(n)]
        jobs[f"wb{n}"] = ["-adh_sigma", "0.2", *WB, "-adh_quadrature_points", str(n)]
    jobs["tg6_bars"] = ["-adh_sigma", "0.2", *TG, "-adh_quadrature_points", "6", "-cont_error_estimate", "true"]
    for s in ("0.01", "0.02"):
        jobs[f"tg_{s}"] = ["-adh_sigma", s, *TG]
        jobs[f"wb_{s}"] = ["-adh_sigma", s, "-adh_roughness", "weibull"]
    # the program's main() in this process, one run after the other: a run is 0.5 to 1 CPU s, and a process of
    # its own would add about 1 s more to start Python and PETSc, 22 times (the command line's process itself is
    # the business of tests/test_cli.py and test_hostile.py; main() given its own options each run is what
    # tests/test_fuzz.py's worker does a hundred times)
    out = {}
    for k, a in jobs.items():
        p = in_process(*GRID, *a, "-summary", d / f"{k}.json", "-out", d / f"{k}.h5")
        assert p.returncode == 0, (k, p.stderr)
        out[k] = {"summary": json.load(open(d / f"{k}.json")), "h5": str(d / f"{k}.h5")}
    return out


def pull_off(run) -> float:
    return run["summary"]["pull_off"]["F"]


@pytest.mark.parametrize("family", ["tg", "wb"])
def test_pull_off_converges_with_the_quadrature(runs, family):
    """Doubling the points shrinks the change of the pull-off until rounding; 24 (the default) and 48 agree.

    Measured (tg): 3 -> 6 changes it by 6e-2, 12 -> 24 by 1.2e-6, 24 -> 48 by 2e-16.
    """
    F = [pull_off(runs[f"{family}{n}"]) for n in POINTS]
    changes = np.abs(np.diff(F))
    assert changes[-1] < 1e-9, changes
    assert changes[0] > 100 * changes[-1], changes
    assert F[3] == pull_off(runs["tg_default"]) or family == "wb"


def events(summary) -> dict:
    return {**{f["kind"]: f for f in summary["folds"]}, "F_min": summary["pull_off"],
            "equilibrium": summary["equilibria"][0]}


def test_quadrature_error_is_in_the_bars(runs):
    """With 6 points every event's bar covers its distance to the converged quadrature (48 points).

    Measured: bars 1.2 to 20 times that distance (the snap lambdas are the tight ones);
    at the default 24 points the quadrature's part of a bar is below 1e-10.
    """
    coarse, fine = events(runs["tg6_bars"]["summary"]), events(runs["tg48"]["summary"])
    for kind, ev in coarse.items():
        for q in ("lambda", "F"):
            if ev.get(f"{q}_err", 0) > 0:
                err = abs(ev.get(f"{q}_grid", ev[q]) - fine[kind][q])
                assert err > 1e-4 and ev[f"{q}_err"] >= err, (kind, q, ev[f"{q}_err"], err)


def test_hermite_rule_sets_the_answer(runs):
    """The paper's rule, by contrast, does not converge: 16 and 32 points differ by far more than any bar."""
    assert abs(pull_off(runs["hermite16"]) - pull_off(runs["hermite32"])) > 0.05


@pytest.mark.parametrize("family", ["tg", "wb"])
def test_small_roughness_approaches_smooth_as_sigma_squared(runs, family):
    """F_p(sigma) - F_p(0) = O(sigma^2) (the moment expansion of the averaged law): halving sigma quarters it."""
    F0 = pull_off(runs["smooth"])
    d1, d2 = (pull_off(runs[f"{family}_{s}"]) - F0 for s in ("0.02", "0.01"))
    assert abs(d2) < 1e-3
    assert d1 / d2 == pytest.approx(4.0, rel=0.1)


def test_measured_gaussian_heights_approach_the_truncated_gaussian(runs):
    """1e5 Gaussian heights cut at 3 sigma against the truncated Gaussian (K = 3): sampling error only.

    The rms of the sample is its sigma; the pull-off differs by the sample's own rms
    and highest height (measured 3.7e-4 apart), far less than from the Hermite rule (0.09).
    """
    meas = runs["measured"]["summary"]
    assert meas["sigma"] == meas["rms"] == pytest.approx(0.2 * 0.9866, rel=0.01)
    assert abs(pull_off(runs["measured"]) - pull_off(runs["tg_default"])) < 2e-3
    assert abs(pull_off(runs["hermite16"]) - pull_off(runs["tg_default"])) > 20 * abs(
        pull_off(runs["measured"]) - pull_off(runs["tg_default"]))


def test_files_say_which_model(runs):
    """The model group records the distribution, its shape parameter and its wall; not the Hermite points."""
    with h5py.File(runs["tg_default"]["h5"], "r") as f:
        m = dict(f["model"].attrs)
    assert m["roughness"] == "truncated_gaussian" and m["roughness_cutoff"] == 3.0
    assert m["highest_asperity"] == pytest.approx(0.6, rel=1e-14) and "hermite_points" not in m
    meas = runs["measured"]["summary"]
    assert meas["roughness"] == "measured" and meas["samples"] == 100000 and meas["bins"] >= 32
    assert "roughness" not in runs["smooth"]["summary"]


def test_height_map_in_metres(tmp_path, cli):
    """A Gwyddion ASCII map in metres with -phys_epsilon: sigma is the levelled map's rms / epsilon."""
    rng = np.random.default_rng(5)
    i, j = np.indices((40, 50))
    Z = 0.08e-9 * rng.standard_normal((40, 50)) + 1e-11 * i - 2e-11 * j + 3e-9   # a tilt and an offset
    path = tmp_path / "map.txt"
    np.savetxt(path, Z, header="Channel: Height\nValue units: m")
    phys = ("-phys_radius", 1e-6, "-phys_gamma", 0.05, "-phys_young1", 1e10, "-phys_poisson1", 0, "-phys_epsilon",
            4e-10)
    p = cli(*GRID[2:8], *phys, "-adh_roughness", "measured", "-adh_roughness_file", path,
            "-adh_lambda", "-1", "-summary", tmp_path / "s.json")
    assert p.returncode == 0, p.stderr
    A = np.column_stack([np.ones(Z.size), i.ravel(), j.ravel()])
    level = Z.ravel() - A @ np.linalg.lstsq(A, Z.ravel(), rcond=None)[0]
    sigma = json.load(open(tmp_path / "s.json"))["sigma"]
    assert sigma == pytest.approx(np.sqrt(np.mean(level ** 2)) / 4e-10, rel=1e-12)
    bad = cli(*GRID[2:8], "-adh_roughness", "measured", "-adh_roughness_file", path, "-adh_lambda", "-1")
    assert "-adh_roughness_file" in plain_error(bad) and "-phys_epsilon" in plain_error(bad)
