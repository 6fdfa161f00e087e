"""Studies (petsc_adhesion.app.study): cases from options, spread over ranks, written as one file.

A case must be exactly the single curve its options describe: compared with the
single run itself (to round-off), serial against ``mpiexec -n 2`` (one and two
ranks per case), and the DMT limit as an independent number.
"""
import json
import os

import h5py
import numpy as np
import pytest

from conftest import run_cli

TINY = ("-grid_type", "uniform", "-grid_n", "101")
#: The model spread of the rough cases under one law (the default four are the golden study's,
#: tests/test_golden.py): a quarter of their cost
ONE_LAW = ("-adh_model_spread_rules", "weibull:0")


def study(tmp_path, *args, np_=1, name="s"):
    out, summ = tmp_path / f"{name}.h5", tmp_path / f"{name}.json"
    proc = run_cli(*TINY, *args, "-out", out, "-summary", summ, np=np_, timeout=900)
    s = json.loads(summ.read_text()) if summ.exists() else None
    return proc, s, out


def events(case: dict, grid: bool = False) -> dict:
    """kind (numbered when repeated) -> (lambda, F, lambda_err, F_err) of a case's or a curve's summary;
    ``grid``: (lambda_grid, F_grid) instead."""
    out, seen = {}, {}
    for e in case["folds"] + case["load_extrema"] + case["equilibria"] + case["at_lambda"]:
        k = e["kind"]
        seen[k] = seen.get(k, 0) + 1
        out[f"{k}{seen[k]}"] = (e["lambda_grid"], e.get("F_grid", 0.0)) if grid else \
            (e["lambda"], e.get("F", 0.0), e.get("lambda_err", 0.0), e.get("F_err", 0.0))
    return out


def spread_values(case: dict) -> dict:
    """quantity name -> (its value under each law, None where a law has it not; the spread) of a case's or a
    curve's model spread."""
    return {q["name"]: (q["values"], q.get("spread")) for q in case["model_spread"]["quantities"]}


def close_spread(a: dict, b: dict, tol: float) -> None:
    a, b = spread_values(a), spread_values(b)
    assert a.keys() == b.keys() and a
    for k in a:
        (va, sa), (vb, sb) = a[k], b[k]
        assert [v is None for v in va] == [v is None for v in vb], k
        assert np.allclose([v for v in va if v is not None], [v for v in vb if v is not None], rtol=0, atol=tol), k
        assert (sa is None) == (sb is None) and (sa is None or abs(sa - sb) <= tol), (k, sa, sb)


def close(a: dict, b: dict, tol: float) -> None:
    assert a.keys() == b.keys()
    for k in a:
        assert np.allclose(a[k], b[k], rtol=0, atol=tol), (k, a[k], b[k])


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("serial")
    proc, s, out = study(tmp, "-study_mu", "0.001,1", "-study_sigma", "0,0.3", "-study_compute", "events", *ONE_LAW)
    assert proc.returncode == 0, proc.stderr
    return proc, s, out


def test_cases_are_the_single_curves(serial, tmp_path):
    proc, s, out = serial
    assert [(c["mu"], c["sigma"]) for c in s["cases"]] == [(0.001, 0.0), (0.001, 0.3), (1.0, 0.0), (1.0, 0.3)]
    for mu, sigma in ((1.0, 0.3), (0.001, 0.0)):
        single = tmp_path / f"{mu}_{sigma}.json"
        # a rough case carries its model spread, as a single rough run does by default: the same laws' curves
        p = run_cli(*TINY, "-adh_mu", mu, "-adh_sigma", sigma, "-cont_F_max", 0, *(ONE_LAW if sigma else ()),
                    "-summary", single)
        assert p.returncode == 0, p.stderr
        one = json.loads(single.read_text())
        case = next(c for c in s["cases"] if (c["mu"], c["sigma"]) == (mu, sigma))
        assert set(one) <= set(case) and set(case) - set(one) == {"case", "values"}
        close(events(case), events(one), 1e-12)
        assert ("model_spread" in case) == (sigma > 0)
        if sigma > 0:
            close_spread(case, one, 1e-12)
            assert case["model_spread"]["rules"] == ["weibull:0"]
    # one line for the study's spreads, not one a case, counting the rough cases whose spread warns (the
    # rough case at mu = 1 does: the law moves its pull-off by far more than 10 %, docs/model.md)
    warned = [c["case"] + 1 for c in s["cases"] if c.get("model_spread", {}).get("warnings")]
    assert 4 in warned
    spread_lines = [ln for ln in proc.stderr.splitlines() if "model spread" in ln]
    assert spread_lines == [f"petsc-adhesion: model spread: {len(warned)} of the 2 rough cases warn (case"
                            f"{'s' * (len(warned) > 1)} {', '.join(map(str, warned))}): the roughness law moves an "
                            "event beyond ten error bars or 10% of its value; each case's model_spread in the files "
                            "says which and by how much"], proc.stderr
    # an independent number: at mu = 0.001 the pull-off is DMT's, F = -1 at lambda = 0, up to O(mu)
    po = s["cases"][0]["pull_off"]
    assert abs(po["F"] + 1) < 2e-3 and abs(po["lambda"]) < 2e-2
    # one progress line a case, rank 0, numbered to the end
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("petsc-adhesion: case")]
    assert len(lines) == 4 and lines[-1].split("; ")[1].startswith("4/4 done")


def test_study_file(serial):
    _, s, out = serial
    with h5py.File(out, "r") as f:
        assert f.attrs["kind"] == "study" and len(f["cases"]) == 4
        assert "units" in f["table/F"].attrs and "description" in f["cases/0002/curve/F"].attrs
        t = {k: f["table"][k][()] for k in f["table"]}
        # the table holds each case's events with their bars, as the summaries do
        po = s["cases"][2]["pull_off"]
        row = (t["case"] == 2) & (t["kind"] == b"F_min") & (t["F"] == po["F"])
        assert row.sum() == 1 and t["F_err"][row][0] == po["F_err"] and t["adh_mu"][row][0] == 1.0
        assert (f["cases/0003/values"].attrs["adh_sigma"], f["cases/0003/model"].attrs["sigma"]) == (0.3, 0.3)
        # a rough case's model spread: a group, as a single run's file has it, and two columns of the table
        # (NaN for the smooth cases' rows and for an event kind the spread does not compare)
        assert "model_spread" in f["cases/0003"] and "model_spread" not in f["cases/0002"]
        q = s["cases"][3]["model_spread"]["quantities"]
        assert f["cases/0003/model_spread/quantities/0001/values"].attrs["weibull:0"] == q[1]["values"][0]
        pull = s["cases"][3]["pull_off"]
        row = (t["case"] == 3) & (t["kind"] == b"F_min") & (t["F"] == pull["F"])
        assert q[1]["name"] == "pull-off F" and t["F_spread"][row][0] == q[1]["spread"]
        assert q[0]["name"] == "pull-off lambda" and t["lambda_spread"][row][0] == q[0]["spread"]
        assert np.isnan(t["F_spread"][t["adh_sigma"] == 0]).all() and "units" in f["table/F_spread"].attrs
        # no roughness quadrature at sigma = 0: the smooth law, and no rule recorded
        assert "roughness" not in f["cases/0000/model"].attrs and f["cases/0001/model"].attrs["roughness"] == "hermite"


@pytest.mark.parametrize("ranks", [1, 2])
def test_two_ranks_equal_serial(serial, tmp_path, ranks):
    _, s, _ = serial
    proc, p, out = study(tmp_path, "-study_mu", "0.001,1", "-study_sigma", "0,0.3", "-study_compute", "events",
                         *ONE_LAW, "-study_ranks", ranks, np_=2)
    assert proc.returncode == 0, proc.stderr
    assert [c["mpi_ranks"] for c in p["cases"]] == [ranks] * 4 and p["mpi_ranks"] == 2
    for a, b in zip(s["cases"], p["cases"]):
        if "model_spread" in a:     # the spread's laws' curves (their events on their own grid) as the serial's
            close_spread(a, b, 1e-10 if ranks == 1 else 1e-9)
        assert ("model_spread" in a) == ("model_spread" in b) == (a["sigma"] > 0)
        if ranks == 1:          # the cases spread over two groups: each exactly as the serial study's
            close(events(a), events(b), 1e-10)
        else:
            # a case on two ranks: its grid's events as on one (the located values; the path of steps
            # and so the coarse levels' luck at 26 nodes may differ, and with them the best values)
            close(events(a, grid=True), events(b, grid=True), 1e-9)
    assert sum(ln.startswith("petsc-adhesion: case") for ln in proc.stderr.splitlines()) == 4


def test_pull_off_only_leaves_out_the_rest(serial, tmp_path):
    code = ("import sys; from petsc_adhesion.app.cli import main; "
            f"rc = main(['x', *{list(TINY)!r}, '-study_mu', '0.001,1', '-study_sigma', '0,0.3', "
            f"'-study_compute', 'pull_off', '-study_profiles', 'equilibrium', '-adh_model_spread', 'false', "
            f"'-out', '{tmp_path}/p.h5', "
            f"'-summary', '{tmp_path}/p.json']); print(rc, 'matplotlib' in sys.modules)")
    import subprocess
    import sys
    from conftest import ROOT, _env
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=_env(), capture_output=True, text=True)
    assert proc.stdout.split() == ["0", "False"], proc.stderr
    p = json.loads((tmp_path / "p.json").read_text())
    _, s, full = serial
    for a, b in zip(s["cases"], p["cases"]):
        assert not b["folds"] and b["pull_off"] == a["pull_off"] and b["equilibria"] == a["equilibria"]
    with h5py.File(tmp_path / "p.h5", "r") as f:
        for name, case in f["cases"].items():
            kinds = {g.attrs["kind"]: "H" in g for g in case["events"].values()}
            assert set(kinds) == {"F_min", "equilibrium"} and kinds["equilibrium"] and not kinds["F_min"]
            assert (case["curve/F"][:-1] < 0).all()        # stopped at the first step past equilibrium


def test_bad_case_does_not_spoil_the_study(tmp_path):
    (tmp_path / "s.json").write_text("earlier")
    proc, s, out = study(tmp_path, "-adh_roughness", "none", "-study_mu", "0.5", "-study_sigma", "0,0.2")
    assert proc.returncode == 3
    bad = [ln for ln in proc.stderr.splitlines() if "left out" in ln]
    assert bad == ["petsc-adhesion: case 2 (mu = 0.5, sigma = 0.2) left out: -adh_sigma: must be 0 with "
                   "-adh_roughness none, got 0.2"]
    assert [c["sigma"] for c in s["cases"]] == [0.0] and s["failed"][0]["case"] == 1
    with h5py.File(out, "r") as f:
        assert len(f["cases"]) == 1 and "-adh_sigma" in f["failed/0000"].attrs["error"]


@pytest.mark.parametrize("args, line", [
    (("-study_mu", "1:0:3"), "-study_mu: expected comma-separated reals or ranges lo:hi:n[:log] in [0, 1000], got '1:0:3'"),
    (("-study_mu", "0:1:3:log"), "-study_mu: expected comma-separated reals or ranges"),
    (("-study_mu", "1,1001"), "-study_mu: expected comma-separated reals or ranges"),
    (("-adh_mu", "1", "-study_mu", "1,2"), "-adh_mu: not with -study_mu, which sets it for each case"),
    (("-study_option", "adh_mu", "-study_values", "1"), "-study_option: 'adh_mu': use -study_mu or -study_sigma"),
    (("-study_option", "adh_rmax"), "-study_values: required with -study_option"),
    (("-study_mu", "1", "-study_values", "1"), "-study_values: only with -study_option"),
    (("-study_mu", "1", "-study_ranks", "2"), "-study_ranks: 2 does not divide the 1 ranks of the run"),
    (("-adh_mu", "1", "-study_plot", "pull_off"), "-study_plot: applies to a study of many cases"),
    (("-study_mu", "1", "-adh_lambda", "0"), "-adh_lambda: a study traces curves; remove it"),
    (("-study_sigma", "0.2,0.4", "-adh_roughness", "none"), "-adh_sigma: must be 0 with -adh_roughness none"),
])
def test_bad_study_input(tmp_path, args, line):
    proc, s, out = study(tmp_path, *args)
    assert proc.returncode == 2 and proc.stderr.startswith(f"petsc-adhesion: error: {line}"), proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and os.listdir(tmp_path) == []


def test_ranges():
    from petsc_adhesion.app.options.reading import AppOptions
    assert AppOptions._range("0.01:20:16:log")[-1] == 20.0
    assert np.allclose(np.diff(np.log(AppOptions._range("0.01:20:16:log"))), np.log(2000) / 15)
    assert AppOptions._range("0:1.2:13")[3] == 0.3


@pytest.mark.parametrize("kind", ["curves", "folds", "profiles", "pull_off", "reduction"])
def test_figures_from_the_file(serial, tmp_path, kind):
    from petsc_adhesion.io.plot.study import pull_offs, read_study, study_figure
    _, s, out = serial
    tree = read_study(str(out))
    assert {c: v[0] for c, v in pull_offs(tree["table"]).items()} == {c["case"]: c["pull_off"]["F"] for c in s["cases"]}
    study_figure(tree, str(tmp_path / "f.png"), kind)
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"


def test_more_ranks_than_cases(tmp_path):
    """A group without a case must not wait for the others' collective calls (options files are read
    once, not per case)."""
    opts = tmp_path / "one.opts"
    opts.write_text("-study_mu 0.5\n-cont_F_max 0\n")
    proc, s, _ = study(tmp_path, "-options_file", opts, np_=2)
    assert proc.returncode == 0 and len(s["cases"]) == 1, proc.stderr
