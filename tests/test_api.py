"""The Python API (petsc_adhesion.curve, .solve): the command line's results and errors, repeatable in one
process without leaking PETSc objects, the limits mu -> 0, every rank's result, and docs/python.md run.

The command line runs in subprocesses (conftest.run_cli), two at a time; the API in this process,
where conftest has initialised PETSc, as a notebook would have.
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from contextlib import redirect_stdout
from io import StringIO

import numpy as np
import pytest

import conftest
import petsc_adhesion as pa
from conftest import ROOT, run_cli
from petsc_adhesion.io.summary import solve_summary, summary_of
from petsc_adhesion.model.reference.rigid import DMT_PULL_OFF, rigid_load

h5py = pytest.importorskip("h5py")

#: a curve of about a second, and a solve of milliseconds (keywords for the API)
CURVE = {"mu": 1.0, "grid_type": "uniform", "grid_n": 101, "cont_F_max": 0}
SOLVE = {"lam": -2.0, "mu": 1.0, "grid_type": "uniform", "grid_n": 101}
PREFIX = "petsc-adhesion: error: "


def args(options: dict) -> list[str]:
    """The command line of API keywords (independent of the API's own translation)."""
    names = {"mu": "adh_mu", "sigma": "adh_sigma", "lam": "adh_lambda"}
    out = []
    for k, v in options.items():
        out += [f"-{names.get(k, k)}"] + ([] if v is True else [str(v)])
    return out


def same(a, b, where="summary"):
    """``a`` and ``b`` equal, numbers to 1e-12 (relative above 1); wall times (``*_s``) left out."""
    if isinstance(a, dict):
        assert set(a) == set(b), (where, set(a) ^ set(b))
        for k in a:
            if not k.endswith("_s"):
                same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{where}/{i}")
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        assert abs(a - b) <= 1e-12 * max(1.0, abs(a)), (where, a, b)
    else:
        assert a == b, (where, a, b)


# -- import ----------------------------------------------------------------------------------------
def test_import_starts_no_petsc_nor_mpi():
    code = ("import sys, petsc_adhesion as pa; "
            "print(sorted(m for m in ('petsc4py.PETSc', 'mpi4py.MPI') if m in sys.modules), callable(pa.curve))")
    proc = subprocess.run([sys.executable, "-c", code], env=conftest._env(), cwd=ROOT, capture_output=True,
                          text=True, timeout=60)
    assert proc.stdout.split() == ["[]", "True"], proc.stderr


# -- the same as the command line ------------------------------------------------------------------
@pytest.fixture(scope="module")
def cli_runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    jobs = {"curve": [*args(CURVE), "-out", d / "c.h5", "-summary", d / "c.json"],
            "solve": [*args(SOLVE), "-out", d / "s.h5", "-summary", d / "s.json"]}
    with ThreadPoolExecutor(max_workers=2) as pool:
        procs = dict(zip(jobs, pool.map(lambda a: run_cli(*a), jobs.values())))
    for proc in procs.values():
        assert proc.returncode == 0, proc.stderr
    return d


def test_curve_is_the_command_lines(cli_runs):
    c = pa.curve(**CURVE)
    files = json.loads((cli_runs / "c.json").read_text())
    same(files, summary_of(c))
    with h5py.File(cli_runs / "c.h5") as f:
        for name, ours in (("lambda", c.lam), ("F", c.F), ("H0", c.H0)):
            np.testing.assert_allclose(ours, f[f"curve/{name}"][()], rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(c.stable, f["curve/stable"][()])
    po = files["pull_off"]
    assert (c.pull_off.kind, c.pull_off.lam.value, c.pull_off.F.value, c.pull_off.F.err) == \
        ("F_min", po["lambda"], po["F"], po["F_err"])
    assert [e.kind for e in c.events] == ["snap_on", "snap_off", "F_min", "equilibrium"]
    assert c.complete and c.warnings == []


def test_solve_is_the_command_lines(cli_runs):
    s = pa.solve(**SOLVE)
    files = json.loads((cli_runs / "s.json").read_text())
    same(files, solve_summary(s))
    with h5py.File(cli_runs / "s.h5") as f:
        for name, ours in (("r", s.r), ("H", s.H), ("P", s.P)):
            np.testing.assert_allclose(ours, f["grid/r" if name == "r" else f"solution/{name}"][()], rtol=1e-12,
                                       atol=1e-12)
    assert (s.lam, s.F) == (SOLVE["lam"], files["F"])


# each: API keywords, and where the command line's message must start
BAD = {
    "range": ({**CURVE, "grid_n": 2}, "-grid_n"),
    "unknown": ({**CURVE, "grid_nodes": 5}, "-grid_nodes"),
    "unknown solver option": ({**CURVE, "arc_snes_rtoll": 1e-8}, "-arc_snes_rtoll"),
    "petsc range": ({**SOLVE, "snes_rtol": 2}, "-snes_rtol"),
    "petsc type": ({**CURVE, "nat_pc_type": "nonesuch"}, "-nat_pc_type"),
    "contradiction": ({**CURVE, "adh_roughness": "none", "sigma": 0.5}, "-adh_sigma"),
    "ignored": ({**SOLVE, "cont_ds": 0.1}, "-cont_ds"),
    "flag": ({**CURVE, "profiles": "maybe"}, "-profiles"),
}


@pytest.fixture(scope="module")
def cli_errors(tmp_path_factory):
    d = tmp_path_factory.mktemp("bad")
    with ThreadPoolExecutor(max_workers=2) as pool:
        procs = dict(zip(BAD, pool.map(lambda kw: run_cli(*args(kw[0]), "-summary", d / "x.json"), BAD.values())))
    lines = {}
    for key, proc in procs.items():
        assert proc.returncode == 2 and proc.stderr.startswith(PREFIX) and proc.stderr.count("\n") == 1, proc.stderr
        lines[key] = proc.stderr.strip()[len(PREFIX):]
    assert os.listdir(d) == []
    return lines


@pytest.mark.parametrize("key", BAD)
def test_bad_option_is_the_command_lines_line(cli_errors, tmp_path, key):
    options, option = BAD[key]
    call = pa.solve if "lam" in options else pa.curve
    with pytest.raises(pa.InputError) as e:
        call(**options, summary=str(tmp_path / "x.json"))
    assert str(e.value) == cli_errors[key] and str(e.value).startswith(option)
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("call, line", [
    (lambda: pa.curve(mu=1, adh_mu=2), "-adh_mu: given twice, as mu and as adh_mu"),
    (lambda: pa.curve(adh_lambda=-1), "-adh_lambda: curve() traces"),
    (lambda: pa.curve(grid_n={"n": 5}), "-grid_n: cannot give a dict"),
    (lambda: pa.curve(**{"-grid_n": 5}), "'-grid_n': not an option name"),
    (lambda: pa.curve(help=True), "-help: not in the Python API"),
    (lambda: pa.curve(study_mu="1,2"), "-study_mu, -study_sigma, -study_option: a study of many cases"),
])
def test_what_only_the_api_refuses(call, line):
    with pytest.raises(pa.InputError, match=re.escape(line)):
        call()


def test_petsc_options_reach_the_solver_and_stay_in_their_run():
    with pytest.raises(RuntimeError, match="Newton did not converge"):
        pa.solve(**SOLVE, snes_max_it=1)
    loose, tight = pa.solve(**SOLVE, snes_rtol=1e-2), pa.solve(**SOLVE, snes_rtol=1e-12)
    assert loose.snes_iterations < tight.snes_iterations
    assert pa.solve(**SOLVE).snes_iterations > loose.snes_iterations


def test_files_are_the_summary(tmp_path):
    s = pa.solve(**SOLVE, summary=str(tmp_path / "s.json"), out=str(tmp_path / "s.h5"))
    assert json.loads((tmp_path / "s.json").read_text()) == solve_summary(s)
    with h5py.File(tmp_path / "s.h5") as f:
        np.testing.assert_array_equal(f["solution/H"][()], s.H)
    assert sorted(os.listdir(tmp_path)) == ["s.h5", "s.json"]


# -- repeatable, no PETSc object left -------------------------------------------------------------
_REPEAT = r'''
import ctypes, gc, json, sys
import petsc4py
petsc4py.init([sys.argv[0], "-objects_dump"])     # PETSc keeps a list of its live objects
from petsc4py import PETSc
import petsc_adhesion as pa

lib = ctypes.CDLL(PETSc.__file__)
lib.PetscObjectsView.argtypes = [ctypes.c_void_p]


def live():
    """PETSc's objects alive now (PetscObjectsView), but the viewer that lists them."""
    gc.collect()
    PETSc.garbage_cleanup()
    v = PETSc.Viewer().createASCII(sys.argv[1], comm=PETSc.COMM_SELF)
    lib.PetscObjectsView(ctypes.c_void_p(v.handle))
    v.destroy()
    return [ln for ln in open(sys.argv[1]).read().splitlines()[2:] if "PetscViewer" not in ln]


out = {"before": live(), "curves": [], "solves": [], "after": []}
for i in range(2):
    c = pa.curve(mu=1.0, grid_type="uniform", grid_n=101, cont_F_max=0, profiles=True)
    on = c.events_of("snap_on")[0]
    out["curves"].append([c.lam.tolist(), c.F.tolist(), c.H0.tolist(), on.profile.H.tolist(), c.pull_off.F.value])
    s = pa.solve(-2.0, mu=1.0, grid_type="uniform", grid_n=101)
    out["solves"].append([s.H.tolist(), s.P.tolist(), s.F])
    out["after"].append(live())
for call, bad in ((pa.curve, {"arc_snes_rtoll": 1}), (pa.curve, {"cont_ds_min": 2}),
                  (pa.curve, {"nat_pc_type": "nonesuch"}), (pa.curve, {"arc_ksp_type": "nonesuch"}),
                  (pa.solve, {"snes_max_it": 1}), (pa.solve, {"snes_rtoll": 1}), (pa.solve, {"pc_type": "nonesuch"})):
    try:
        call(*([-2.0] if call is pa.solve else []), mu=1.0, grid_type="uniform", grid_n=101,
             **({} if call is pa.solve else {"cont_F_max": 0}), **bad)
    except (RuntimeError, pa.InputError):
        pass
    out["after"].append(live())                  # once the exception, and what its frames held, is gone
print(json.dumps(out))
'''


def test_repeated_calls_are_identical_and_free_their_objects(tmp_path):
    script = tmp_path / "repeat.py"
    script.write_text(_REPEAT)
    proc = subprocess.run([sys.executable, str(script), str(tmp_path / "objects.txt")], env=conftest._env(),
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.splitlines()[-1])
    assert out["before"] == [] and out["after"] == [[]] * 9, out["after"]
    for first, second in (out["curves"], out["solves"]):
        for a, b in zip(first, second):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


# -- limits ----------------------------------------------------------------------------------------
def test_solve_rigid_limit():
    """mu = 0: H = -lambda + r^2/2 (eq. 27) exactly; F tends to eq. (28) at second order in the spacing."""
    errors = []
    for n in (101, 201, 401):
        s = pa.solve(0.5, mu=0, grid_type="uniform", grid_n=n)
        np.testing.assert_allclose(s.H, s.r ** 2 / 2 - 0.5, rtol=0, atol=1e-12)
        errors.append(abs(s.F - rigid_load(0.5)))
    rates = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert all(1.9 < p < 2.1 for p in rates), (errors, rates)


def test_curve_tends_to_the_rigid_one():
    """As mu -> 0 the curve approaches eq. (28): its distance falls faster than mu (like mu^1.5, elastic)."""
    dist = {}
    for mu in (0.01, 0.001):
        c = pa.curve(mu=mu, cont_F_max=0, cont_error_estimate=False)
        dist[mu] = np.abs(c.F - rigid_load(c.lam)).max()
    assert dist[0.001] < dist[0.01] / 10 and dist[0.001] < 5e-3, dist


# -- under mpiexec ---------------------------------------------------------------------------------
def test_every_rank_gets_the_result(tmp_path):
    code = ("import json, petsc_adhesion as pa; from mpi4py import MPI; "
            "c = pa.curve(mu=1.0, grid_type='uniform', grid_n=101, cont_F_max=0, profiles=True); "
            "e = c.events_of('snap_on')[0]; "
            "open(f'rank{MPI.COMM_WORLD.rank}.json', 'w').write(json.dumps([MPI.COMM_WORLD.rank, "
            "c.program.mpi_ranks, c.pull_off.F.value, c.H0.tolist(), e.profile.H.tolist()]))")
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        pytest.skip("mpiexec not found")
    run = subprocess.run([*conftest.mpiexec(2), sys.executable, "-c", code], env=conftest._env(), cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    # a file a rank: mpiexec interleaves the ranks' stdout in 2048-byte pieces
    rows = sorted(json.loads((tmp_path / f"rank{k}.json").read_text()) for k in (0, 1))
    assert [r[:2] for r in rows] == [[0, 2], [1, 2]]
    assert rows[0][2:] == rows[1][2:]
    serial = pa.curve(mu=1.0, grid_type="uniform", grid_n=101, cont_F_max=0, profiles=True)
    assert abs(rows[0][2] - serial.pull_off.F.value) < 1e-10
    np.testing.assert_allclose(rows[0][3], serial.H0, atol=1e-10)
    np.testing.assert_allclose(rows[0][4], serial.events_of("snap_on")[0].profile.H, atol=1e-10)


# -- docs/python.md --------------------------------------------------------------------------------
def test_python_md_runs_and_prints_what_it_shows(tmp_path, monkeypatch):
    """Its code blocks, run in order, print the numbers of its output blocks; its limits hold."""
    import matplotlib
    matplotlib.use("Agg")
    text = open(os.path.join(ROOT, "docs", "python.md")).read()
    code = re.findall(r"```python\n(.*?)```", text, re.S)
    shown = "".join(re.findall(r"```text\n(.*?)```", text, re.S))
    monkeypatch.chdir(tmp_path)
    printed, ns = StringIO(), {}
    with redirect_stdout(printed):
        for block in code:
            exec(compile(block, "docs/python.md", "exec"), ns)
    number = r"-?\d+\.\d{6,}"
    assert re.findall(number, printed.getvalue()) == re.findall(number, shown) != []
    assert abs(ns["d"].pull_off.F.value - DMT_PULL_OFF) < 2e-3                    # mu = 0.01: DMT
    np.testing.assert_allclose(ns["s"].H, ns["s"].r ** 2 / 2 - 0.5, atol=1e-12)   # mu = 0: rigid, eq. (27)
    assert json.loads((tmp_path / "mu2.json").read_text()) == summary_of(ns["f"])
    assert {"mu1.png", "mu2.png", "mu2.json"} <= set(os.listdir(tmp_path))


def test_a_program_given_with_python_c_starts_petsc_without_its_name_as_an_option(tmp_path):
    """``python -c`` gives sys.argv[0] = '-c': the library's start took it for the program's name, and PETSc
    then held '-c' as an option of the run, which the API refused ('-c: unknown option'); now it starts under
    its own name and the curve is the command line's (its pull-off to round-off)."""
    import conftest

    code = ("import json, petsc_adhesion as p\nfrom petsc_adhesion.core.start import start_petsc\nstart_petsc()\n"
            "c = p.curve(adh_mu=0.5, grid_type='uniform', grid_n=41, cont_F_max=0)\n"
            "print(json.dumps(c.pull_off.F.value))")
    run = subprocess.run([sys.executable, "-c", code], env=conftest._env(), cwd=tmp_path, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-800:]
    cli = conftest.run_cli("-adh_mu", "0.5", "-grid_type", "uniform", "-grid_n", "41", "-cont_F_max", "0",
                           "-summary", tmp_path / "s.json", cwd=tmp_path)
    assert cli.returncode == 0, cli.stderr
    assert json.loads(run.stdout.strip().splitlines()[-1]) == json.loads((tmp_path / "s.json").read_text())["pull_off"]["F"]
