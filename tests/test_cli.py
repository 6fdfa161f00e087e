"""The command line: bad input, options files, -help, the output files, parallel runs, monitors.

Every test runs ``python -m petsc_adhesion`` in a subprocess (conftest.run_cli).
Runs that several tests look at are made once per module, two at a time on
the two cores, so the file stays well under a minute.
"""
import json
import math
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import petsc4py
import pytest
from petsc4py import PETSc

import petsc_adhesion
from petsc_adhesion.model.reference.rigid import load_beyond
import conftest
from conftest import run_cli
from petsc_adhesion.app.options.table import TABLE

h5py = pytest.importorskip("h5py")

#: a grid on which a fixed-lambda solve takes a few milliseconds
FAST = ("-grid_type", "uniform", "-grid_n", "101")
#: mu = 1, lambda = -2 converges from the default (rigid) guess
SOLVE = ("-adh_mu", "1", "-adh_lambda", "-2", *FAST)
PREFIX = "petsc-adhesion: error:"


def run_all(jobs: dict, workers: int = 2) -> dict:
    """{key: (args, kwargs)} -> {key: CompletedProcess}, ``workers`` at a time."""
    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {k: pool.submit(run_cli, *args, **kw) for k, (args, kw) in jobs.items()}
        return {k: f.result() for k, f in futures.items()}


def merge(base, extra):
    """``base`` options (name, value pairs) not given in ``extra``, then ``extra``."""
    given = {a for a in extra if a.startswith("-") and not _number(a)}
    out = []
    for name, value in zip(base[::2], base[1::2]):
        if name not in given:
            out += [name, value]
    return [*out, *extra]


def _number(s: str) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False


def files(folder) -> set:
    """Every entry of ``folder``, hidden ones (temporaries) included."""
    return set(os.listdir(folder))


def text(v) -> str:
    return v.decode() if isinstance(v, bytes) else str(v)


def read_h5(path) -> dict:
    with h5py.File(path, "r") as f:
        return {"attrs": dict(f.attrs), "options": {k: text(v) for k, v in f["options"].attrs.items()},
                "model": dict(f["model"].attrs), "r": f["grid/r"][()],
                "H": f["solution/H"][()], "P": f["solution/P"][()], "solution": dict(f["solution"].attrs)}


def plain_error(proc) -> str:
    """The one stderr line of a failed run, checked for the common contract."""
    assert proc.returncode != 0, proc.stdout + proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(PREFIX), proc.stderr
    return lines[0]


# ---------------------------------------------------------------------------
# 1. bad input: one line naming the option and what it accepts, no file left
# ---------------------------------------------------------------------------

R = re.escape
# id: (arguments, the option named, regexes of what the message must also say)
BAD = {
    "mu_negative": (["-adh_mu", "-1"], "-adh_mu", [R("[0, 1000]")]),
    "mu_nan": (["-adh_mu", "nan"], "-adh_mu", [R("[0, 1000]"), "finite"]),
    "mu_inf": (["-adh_mu", "inf"], "-adh_mu", [R("[0, 1000]"), "finite"]),
    "mu_not_a_number": (["-adh_mu", "abc"], "-adh_mu", [R("[0, 1000]"), "abc"]),
    "sigma_negative": (["-adh_sigma", "-0.1"], "-adh_sigma", [R("[0, 5]")]),
    "rmax_zero": (["-adh_rmax", "0"], "-adh_rmax", [R("(0, 1000]")]),
    "rmax_negative": (["-adh_rmax", "-3"], "-adh_rmax", [R("(0, 1000]")]),
    "grid_n_2": (["-grid_type", "uniform", "-grid_n", "2"], "-grid_n", [R("[3, 200000]")]),
    "roughness_unknown": (["-adh_roughness", "gauss"], "-adh_roughness", ["none", "hermite", "gauss"]),
    "grid_type_unknown": (["-grid_type", "foo"], "-grid_type", ["paper", "uniform", "foo"]),
    "hermite_points_1": (["-adh_hermite_points", "1"], "-adh_hermite_points", [R("[2, 200]")]),
    "lambda_nan": (["-adh_lambda", "nan"], "-adh_lambda", [R("[-1000, 1000]")]),
    # the allowed value here is sigma = 0 (a bare 0, not the 0 of 0.2)
    "sigma_without_roughness": (["-adh_sigma", "0.2", "-adh_roughness", "none"], "-adh_sigma",
                                ["-adh_roughness none", r"(?<![\d.])0(?![\d.])"]),
    "options_file_missing": (["-options_file", "/nonexistent.opts"], "-options_file", [R("/nonexistent.opts")]),
    "app_option_misspelled": (["-adh_muu", "1"], "-adh_muu", ["unknown option", r"-adh_mu(?!u)"]),
    "petsc_option_misspelled": (["-snes_monitr"], "-snes_monitr", ["unknown option"]),
    "guess_missing": (["-adh_guess", "/nonexistent.h5"], "-adh_guess", [R("/nonexistent.h5")]),
    "cutoff_with_hermite": (["-adh_sigma", "0.2", "-adh_roughness_cutoff", "4"], "-adh_roughness_cutoff",
                            ["truncated_gaussian"]),
    "cutoff_zero": (["-adh_sigma", "0.2", "-adh_roughness", "truncated_gaussian", "-adh_roughness_cutoff", "0"],
                    "-adh_roughness_cutoff", [R("[1e-06, 10]")]),
    "skewness_range": (["-adh_sigma", "0.2", "-adh_roughness", "weibull", "-adh_roughness_skewness", "1"],
                       "-adh_roughness_skewness", [R("[-2, 0.5]")]),
    "quadrature_smooth": (["-adh_roughness", "weibull", "-adh_quadrature_points", "12"], "-adh_quadrature_points",
                          ["-adh_sigma 0"]),
    "measured_no_file": (["-adh_roughness", "measured"], "-adh_roughness_file", ["required"]),
    "measured_missing_file": (["-adh_roughness", "measured", "-adh_roughness_file", "/nonexistent.txt"],
                              "-adh_roughness_file", [R("nonexistent.txt"), "no file"]),
    "measured_with_sigma": (["-adh_roughness", "measured", "-adh_roughness_file", "/nonexistent.txt",
                             "-adh_sigma", "0.2"], "-adh_sigma", ["heights set it"]),
    "file_without_measured": (["-adh_sigma", "0.2", "-adh_roughness_file", "/nonexistent.txt"],
                              "-adh_roughness_file", ["measured"]),
}


@pytest.fixture(scope="module")
def bad_runs(tmp_path_factory):
    jobs, dirs = {}, {}
    for key, (args, _, _) in BAD.items():
        d = dirs[key] = tmp_path_factory.mktemp(key)
        jobs[key] = (merge([*SOLVE, "-out", str(d / "x.h5"), "-summary", str(d / "x.json")], args), {})
    procs = run_all(jobs)
    return {k: (procs[k], dirs[k]) for k in BAD}


@pytest.mark.parametrize("key", list(BAD))
def test_bad_input(bad_runs, key):
    proc, folder = bad_runs[key]
    _, option, says = BAD[key]
    line = plain_error(proc)
    msg = line[len(PREFIX):]
    assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w])", msg), line
    for pattern in says:
        assert re.search(pattern, msg), f"{pattern!r} not in {line!r}"
    assert "Traceback" not in proc.stdout + proc.stderr
    assert files(folder) == set(), "a failed run left files"


def test_bad_input_status_is_2(bad_runs):
    """cli.py: bad input ends with exit status 2 (1 is for a failed solve)."""
    assert {k: p.returncode for k, (p, _) in bad_runs.items()} == {k: 2 for k in BAD}


def test_bad_input_parallel_one_line(tmp_path):
    """On 2 ranks the program's error is still said once (mpiexec adds its own banner)."""
    proc = run_cli(*SOLVE, "-adh_mu", "-1", "-out", tmp_path / "x.h5", "-summary", tmp_path / "x.json", np=2)
    assert proc.returncode != 0
    ours = [ln for ln in proc.stderr.splitlines() if "petsc-adhesion" in ln]
    assert len(ours) == 1 and ours[0].startswith(PREFIX) and "-adh_mu" in ours[0], proc.stderr
    assert "Traceback" not in proc.stderr and "PETSC ERROR" not in proc.stderr
    assert files(tmp_path) == set()


def test_newton_failure_one_line_no_files(tmp_path):
    """A solve that does not converge: status 1, one line, and no result file."""
    proc = run_cli(*SOLVE, "-snes_max_it", "1", "-out", tmp_path / "x.h5", "-summary", tmp_path / "x.json")
    line = plain_error(proc)
    assert proc.returncode == 1
    assert "converge" in line and "lambda = -2" in line
    assert files(tmp_path) == set()


@pytest.mark.parametrize("args", [("-pc_type", "foo"), ("-snes_rtol", "abc"), ("-ksp_type", "baz")],
                         ids=["pc_type", "snes_rtol", "ksp_type"])
def test_bad_petsc_option_value_is_named(tmp_path, args):
    proc = run_cli(*SOLVE, *args, "-out", tmp_path / "x.h5", "-summary", tmp_path / "x.json")
    assert files(tmp_path) == set()
    line = plain_error(proc)
    assert proc.returncode == 2
    assert line[len(PREFIX):].strip().startswith(args[0]) and args[1] in line, line


# ---------------------------------------------------------------------------
# 2. options files
# ---------------------------------------------------------------------------

def test_options_file_with_comments(tmp_path):
    opts = tmp_path / "study.opts"
    opts.write_text("# a study\n"
                    "-adh_mu 0.5   # Tabor\n"
                    "-adh_lambda -2\n"
                    "\n"
                    "   # indented comment\n"
                    "-grid_type uniform\n"
                    "-grid_n 101\n")
    summary = tmp_path / "S.json"
    proc = run_cli("-options_file", opts, "-summary", summary)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    s = json.loads(summary.read_text())
    assert s["mu"] == 0.5
    assert s["lambda"] == -2.0
    assert s["n_nodes"] == 101
    assert files(tmp_path) == {"study.opts", "S.json"}


def test_options_file_error_inside(tmp_path):
    """A bad value read from a file is reported like one on the command line."""
    opts = tmp_path / "bad.opts"
    opts.write_text("-adh_mu -1  # oops\n-adh_lambda -2\n-grid_type uniform\n-grid_n 101\n")
    proc = run_cli("-options_file", opts, "-summary", tmp_path / "S.json")
    line = plain_error(proc)
    assert "-adh_mu" in line and "[0, 1000]" in line
    assert files(tmp_path) == {"bad.opts"}


# ---------------------------------------------------------------------------
# 3. -help
# ---------------------------------------------------------------------------

def test_help_lists_every_option(tmp_path):
    proc = run_cli("-help", "-out", tmp_path / "x.h5", "-summary", tmp_path / "x.json")
    assert proc.returncode == 0, proc.stderr
    missing = [name for name in TABLE
               if not re.search(rf"^\s*-{re.escape(name)}(?![\w])", proc.stdout, re.M)]
    assert missing == [], f"-help does not list {missing}"
    for name, o in TABLE.items():
        line = re.search(rf"^\s*-{re.escape(name)}(?![\w]).*$", proc.stdout, re.M).group(0)
        assert o.allowed() in line, line
    assert files(tmp_path) == set(), "-help wrote output files"


# ---------------------------------------------------------------------------
# 4-6. the files of a fixed-lambda solve
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def solve201(tmp_path_factory):
    d = tmp_path_factory.mktemp("solve201")
    args = ["-adh_mu", "1", "-adh_lambda", "-2", "-grid_type", "uniform", "-grid_n", "201"]
    proc = run_cli(*args, "-out", d / "x.h5", "-summary", d / "x.json")
    assert proc.returncode == 0, proc.stderr
    return {"proc": proc, "dir": d, "h5": read_h5(d / "x.h5"),
            "json": json.loads((d / "x.json").read_text())}


def test_solve_only_named_files(solve201):
    """Atomic writes leave nothing but the two named files (no temporaries)."""
    assert solve201["proc"].stderr == ""
    assert files(solve201["dir"]) == {"x.h5", "x.json"}


def test_h5_provenance(solve201):
    a = solve201["h5"]["attrs"]
    assert text(a["program"]) == "petsc-adhesion"
    assert text(a["version"]) == petsc_adhesion.__version__
    assert text(a["petsc_version"]) == "%d.%d.%d" % PETSc.Sys.getVersion()
    assert text(a["petsc4py_version"]) == petsc4py.__version__
    assert int(a["mpi_ranks"]) == 1


def test_h5_options_and_model(solve201):
    h = solve201["h5"]
    o = h["options"]
    assert float(o["adh_mu"]) == 1.0
    assert float(o["adh_lambda"]) == -2.0
    assert o["grid_type"] == "uniform"
    assert int(o["grid_n"]) == 201
    assert h["model"]["mu"] == 1.0
    assert h["model"]["sigma"] == 0.0


def test_h5_solution(solve201):
    h = solve201["h5"]
    r, H, P = h["r"], h["H"], h["P"]
    assert r.shape == H.shape == P.shape == (201,)
    assert r[0] == 0.0 and r[-1] == pytest.approx(10.0) and np.all(np.diff(r) > 0)
    assert np.all(np.isfinite(H)) and np.all(np.isfinite(P))
    assert h["solution"]["lambda"] == -2.0
    assert math.isfinite(h["solution"]["F"])
    # far from the contact the surfaces are apart: the gap follows the rigid shape (eq. 27) to O(1/r)
    assert np.all(H > 0)
    assert H[-1] == pytest.approx(0.5 * r[-1] ** 2 + 2.0, rel=1e-2)


def test_json_summary(solve201):
    s, h = solve201["json"], solve201["h5"]
    for key in ("mu", "sigma", "n_nodes", "lambda", "F", "H0", "snes_iterations", "ksp_iterations",
                "wall_time_s"):
        assert key in s, key
    assert s["mu"] == 1.0 and s["sigma"] == 0.0 and s["n_nodes"] == 201 and s["lambda"] == -2.0
    assert s["F"] == h["solution"]["F"]
    assert s["H0"] == h["H"][0]
    assert s["mpi_ranks"] == 1
    assert isinstance(s["snes_iterations"], int) and s["snes_iterations"] >= 1
    assert isinstance(s["ksp_iterations"], int) and s["ksp_iterations"] >= s["snes_iterations"]
    assert s["snes_iterations"] == h["solution"]["snes_iterations"]
    assert 0 < s["wall_time_s"] < 60


def test_stdout_line(solve201):
    m = re.search(r"lambda = (\S+)\s+F = (\S+)\s+H0 = (\S+)", solve201["proc"].stdout)
    assert m, solve201["proc"].stdout
    s = solve201["json"]
    assert float(m.group(1)) == -2.0
    assert float(m.group(2)) == pytest.approx(s["F"], rel=1e-9)
    assert float(m.group(3)) == pytest.approx(s["H0"], rel=1e-9)


def test_F_against_trapz(solve201):
    """F = (8/3) int P r dr + F_beyond: trapz on the stored (r, P) agrees to O(h^2)."""
    h = solve201["h5"]
    r, P, F = h["r"], h["P"], h["solution"]["F"] - h["solution"]["F_beyond"]
    trapz = getattr(np, "trapezoid", None) or np.trapz
    assert (8.0 / 3.0) * trapz(P * r, r) == pytest.approx(F, rel=1e-3)


def test_F_is_exact_for_linear_P(solve201):
    """The program integrates the piecewise-linear P times r exactly (eq. 26); the far field is
    the rigid sphere's attraction beyond r_m (eq. 28's integrand, reference.load_beyond)."""
    h = solve201["h5"]
    r, P, F = h["r"], h["P"], h["solution"]["F"]
    assert h["solution"]["F_beyond"] == pytest.approx(load_beyond(10.0, -2.0), rel=1e-14)
    F -= h["solution"]["F_beyond"]
    dr = np.diff(r)
    exact = np.sum(dr / 6.0 * (P[:-1] * (2 * r[:-1] + r[1:]) + P[1:] * (r[:-1] + 2 * r[1:])))
    assert (8.0 / 3.0) * exact == pytest.approx(F, rel=1e-12, abs=1e-15)


# ---------------------------------------------------------------------------
# 7-8. preconditioners and ranks give the same solution
# ---------------------------------------------------------------------------

PCS = {
    "default": (),
    "band": ("-adh_pmat", "band"),
    "band_ilu": ("-adh_pmat", "band", "-pc_type", "ilu"),
    "shell": ("-adh_pmat", "shell"),
    "dense_bjacobi": ("-adh_pmat", "dense", "-pc_type", "bjacobi"),
    "shell_jacobi": ("-adh_pmat", "shell", "-pc_type", "jacobi"),
    "lag2": ("-snes_lag_preconditioner", "2"),
}


@pytest.fixture(scope="module")
def pc_runs(tmp_path_factory):
    dirs = {k: tmp_path_factory.mktemp(f"pc_{k}") for k in PCS}
    procs = run_all({k: ((*SOLVE, *a, "-out", dirs[k] / "x.h5"), {}) for k, a in PCS.items()})
    out = {}
    for k, p in procs.items():
        assert p.returncode == 0, f"{k}: {p.stderr}"
        out[k] = read_h5(dirs[k] / "x.h5")
    return out


@pytest.mark.parametrize("key", [k for k in PCS if k != "default"])
def test_preconditioners_same_solution(pc_runs, key):
    ref, got = pc_runs["default"], pc_runs[key]
    assert np.max(np.abs(got["H"] - ref["H"])) < 1e-9
    assert got["solution"]["F"] == pytest.approx(ref["solution"]["F"], rel=1e-9)


def test_F_trapz_error_shrinks_as_h2(pc_runs, solve201):
    """The trapz-vs-exact gap is O(h^2): about 4 times smaller from 101 to 201 nodes."""
    trapz = getattr(np, "trapezoid", None) or np.trapz

    def gap(h):
        return abs((8.0 / 3.0) * trapz(h["P"] * h["r"], h["r"]) - h["solution"]["F"] + h["solution"]["F_beyond"])

    g101, g201 = gap(pc_runs["default"]), gap(solve201["h5"])
    assert 3.0 < g101 / g201 < 5.0


def test_guess_from_file(pc_runs, solve201, tmp_path):
    """-adh_guess: a 201-node result, interpolated, starts the 101-node solve."""
    s = tmp_path / "g.json"
    proc = run_cli(*SOLVE, "-adh_guess", solve201["dir"] / "x.h5", "-out", tmp_path / "g.h5", "-summary", s)
    assert proc.returncode == 0, proc.stderr
    got = read_h5(tmp_path / "g.h5")
    assert np.max(np.abs(got["H"] - pc_runs["default"]["H"])) < 1e-9
    assert json.loads(s.read_text())["snes_iterations"] < 4


@pytest.fixture(scope="module")
def parallel_runs(tmp_path_factory):
    out = {}
    for k, a in {"default": (), "band": ("-adh_pmat", "band"), "shell": ("-adh_pmat", "shell")}.items():
        d = tmp_path_factory.mktemp(f"np2_{k}")
        proc = run_cli(*SOLVE, *a, "-out", d / "x.h5", "-summary", d / "x.json", np=2)
        assert proc.returncode == 0, f"{k}: {proc.stderr}"
        out[k] = {"proc": proc, "dir": d, "h5": read_h5(d / "x.h5"), "json": json.loads((d / "x.json").read_text())}
    return out


def test_parallel_same_as_serial(parallel_runs, pc_runs):
    ref, got = pc_runs["default"], parallel_runs["default"]["h5"]
    assert np.max(np.abs(got["H"] - ref["H"])) < 1e-10
    assert got["solution"]["F"] == pytest.approx(ref["solution"]["F"], rel=1e-12)
    assert int(got["attrs"]["mpi_ranks"]) == 2
    assert parallel_runs["default"]["json"]["mpi_ranks"] == 2


@pytest.mark.parametrize("key", ["band", "shell"])
def test_parallel_pmats(parallel_runs, pc_runs, key):
    ref = pc_runs["default"]
    assert np.max(np.abs(parallel_runs[key]["h5"]["H"] - ref["H"])) < 1e-9
    assert np.max(np.abs(parallel_runs[key]["h5"]["H"] - parallel_runs["default"]["h5"]["H"])) < 1e-9


@pytest.mark.parametrize("key", ["default", "band", "shell"])
def test_parallel_writes_once(parallel_runs, key):
    """Rank 0 alone writes: the two named files, no temporaries, one result line."""
    run = parallel_runs[key]
    assert files(run["dir"]) == {"x.h5", "x.json"}
    assert len(re.findall(r"^lambda = ", run["proc"].stdout, re.M)) == 1, run["proc"].stdout


# ---------------------------------------------------------------------------
# 9. monitors of a curve run
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def curve(tmp_path_factory):
    d = tmp_path_factory.mktemp("curve")
    proc = run_cli("-adh_mu", "0.5", *FAST, "-cont_monitor", "-nat_snes_monitor", "-arc_snes_monitor",
                   "-out", d / "c.h5", "-summary", d / "c.json")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(d / "c.h5", "r") as f:
        lam = f["curve/lambda"][()]
    return {"proc": proc, "dir": d, "json": json.loads((d / "c.json").read_text()), "lambda": lam}


def test_cont_monitor_one_line_per_step(curve):
    cont = [ln for ln in curve["proc"].stdout.splitlines() if "CONT" in ln]
    steps = curve["json"]["steps"]
    assert steps > 5
    assert len(cont) == steps + 1                     # the start point, then one line per accepted step
    assert [int(ln.split()[0]) for ln in cont] == list(range(steps + 1))
    shown = np.array([float(re.search(r"lambda\s+(\S+)", ln).group(1)) for ln in cont])
    np.testing.assert_allclose(shown, curve["lambda"], rtol=1e-9, atol=1e-12)


def test_snes_monitor_in_curve_run(curve):
    out = curve["proc"].stdout
    norms = re.findall(r"^\s*\d+ SNES Function norm", out, re.M)
    starts = re.findall(r"^\s*0 SNES Function norm", out, re.M)
    assert len(starts) >= curve["json"]["steps"] + 1     # at least one Newton solve a point
    assert len(norms) > len(starts)


def test_curve_only_named_files(curve):
    assert files(curve["dir"]) == {"c.h5", "c.json"}


@pytest.mark.parametrize("pc", [("-pc_type", "lu", "-pc_factor_mat_solver_type", "mumps"),
                                ("-pc_type", "hypre")], ids=["mumps", "hypre"])
def test_parallel_band_with_external_solvers(tmp_path, pc):
    """The near-field AIJ matrix takes any PETSc PC in parallel: MUMPS LU, hypre BoomerAMG."""
    package = pc[-1]
    if not PETSc.Sys.hasExternalPackage(package):
        pytest.skip(f"this PETSc has no {package} (Debian's has both)")
    ref, par = tmp_path / "ref.h5", tmp_path / "par.h5"
    args = ("-adh_mu", 1, "-adh_lambda", -2, "-grid_type", "uniform", "-grid_n", 101)
    assert run_cli(*args, "-out", ref).returncode == 0
    proc = run_cli(*args, "-adh_pmat", "band", *pc, "-out", par, np=2)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(ref) as a, h5py.File(par) as b:
        assert np.max(np.abs(a["solution/H"][()] - b["solution/H"][()])) < 1e-9


def test_scene_leaves_out_what_it_does_not_need(tmp_path):
    """No plotting import when nothing is drawn, no profiles not asked for."""
    h5 = tmp_path / "c.h5"
    code = ("import sys; from petsc_adhesion.app.cli import main; "
            f"rc = main(['x', '-adh_mu', '0.5', '-grid_type', 'uniform', '-grid_n', '101', '-out', '{h5}']); "
            "assert rc == 0; print('matplotlib' in sys.modules)")
    env = conftest._env()
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=conftest.ROOT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "False"
    with h5py.File(h5, "r") as f:
        assert len(f["events"]) >= 2
        assert all("H" not in g and "P" not in g for g in f["events"].values())


@pytest.mark.parametrize("text, line", [("adh_mu 1\n", 1), ("# ok\n-adh_mu\n-adh_lambda -2 extra\n", 3),
                                        ("-options_file /nonexistent.opts\n", None)],
                         ids=["no-dash", "extra-token", "nested-unreadable"])
def test_malformed_options_file_is_one_line(tmp_path, text, line):
    """PETSc would abort with a page of text and a traceback: the program says it in one line."""
    opts = tmp_path / "bad.opts"
    opts.write_text(text)
    proc = run_cli("-options_file", opts, "-adh_lambda", -2, "-out", tmp_path / "x.h5")
    assert proc.returncode == 2
    err = proc.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("petsc-adhesion: error: -options_file"), proc.stderr
    if line:
        assert f"line {line}:" in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.opts"]


@pytest.mark.parametrize("option", ["-out", "-summary", "-plot"])
def test_unwritable_output_is_one_line(tmp_path, option):
    """A directory in place of a file, or a place no file can be created: refused before any work."""
    (tmp_path / "d").mkdir()
    for target in (tmp_path / "d", "/proc/petsc-adhesion.out"):
        proc = run_cli(option, target, "-grid_type", "uniform", "-grid_n", 51)
        err = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(err) == 1 and err[0].startswith(f"petsc-adhesion: error: {option}:")
    assert [p.name for p in tmp_path.iterdir()] == ["d"] and not any((tmp_path / "d").iterdir())


def test_the_installed_command_names_a_main_that_exists():
    """pyproject.toml's petsc-adhesion command (what ./run demo and ./run study start) names a module and a
    function that exist: it named petsc_adhesion.cli after the subpackages had moved it to app/cli.py, and
    every ./run demo failed with ModuleNotFoundError while the suite, which starts python -m petsc_adhesion,
    passed."""
    import importlib
    import tomllib

    with open(os.path.join(os.path.dirname(petsc_adhesion.__file__), os.pardir, "pyproject.toml"), "rb") as f:
        target = tomllib.load(f)["project"]["scripts"]["petsc-adhesion"]
    module, _, name = target.partition(":")
    assert callable(getattr(importlib.import_module(module), name))
    assert importlib.import_module(module) is importlib.import_module("petsc_adhesion.app.cli")
