"""Reliability: refusals before any work, files that cannot be misused, all-or-nothing result sets,
collective checks under MPI, signals, exit status 3, files that describe themselves.

Each case is a real command line (subprocess); the file-system cases build
their special files in a temporary folder.
"""
import json
import os
import signal
import stat
import subprocess
import sys
import time

import numpy as np
import pytest

import conftest
from conftest import ROOT, run_cli

h5py = pytest.importorskip("h5py")

FAST = ("-grid_type", "uniform", "-grid_n", "101")
SOLVE = ("-adh_mu", "1", "-adh_lambda", "-2", *FAST)
CURVE = ("-adh_mu", "1", *FAST)
PREFIX = "petsc-adhesion: error: "


def one_line(proc, status=2) -> str:
    assert proc.returncode == status, (proc.returncode, proc.stdout[-500:], proc.stderr)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith(PREFIX), proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr and "PETSC ERROR" not in proc.stderr
    assert all(c.isprintable() for c in lines[0]), repr(lines[0])
    return lines[0][len(PREFIX):]


# -- 1. refused before any work: one line naming the option, exit 2, nothing written ------------------
REFUSED = {
    # (arguments, the option named first, a phrase of the message)
    "lambda_start_past_max": (("-cont_lambda_start", "0", "-cont_lambda_max", "-1"), "-cont_lambda_start", "not below"),
    "ds_min_above_max": (("-cont_ds_min", "1", "-cont_ds_max", "0.1"), "-cont_ds_min", "above"),
    "ds_outside": (("-cont_ds", "2"), "-cont_ds", "outside"),
    "grid_n_with_paper": (("-grid_type", "paper", "-grid_n", "101"), "-grid_n", "uniform"),
    "paper_option_with_uniform": (("-grid_paper_extra", "40"), "-grid_paper_extra", "paper"),
    "hermite_points_smooth": (("-adh_hermite_points", "32"), "-adh_hermite_points", "sigma 0"),
    "band_without_band": (("-adh_pmat_band", "8"), "-adh_pmat_band", "band"),
    "curve_option_with_solve": (("-adh_lambda", "-2", "-cont_ds", "0.1"), "-cont_ds", "-adh_lambda"),
    "domain_smaller_than_contact": (("-adh_rmax", "0.5"), "-adh_rmax", "at least"),
    "at_lambda_outside": (("-cont_lambda_max", "1", "-cont_at_lambda", "5"), "-cont_at_lambda", "outside"),
    "snes_max_it_negative": (("-nat_snes_max_it", "-5"), "-nat_snes_max_it", "integer"),
    "ksp_rtol_above_one": (("-arc_ksp_rtol", "2"), "-arc_ksp_rtol", "[0, 1)"),
    "gmres_restart_zero": (("-arc_ksp_gmres_restart", "0"), "-arc_ksp_gmres_restart", "[1,"),
    "typo_petsc_prefixed": (("-arc_snes_linesearch_typ", "basic"), "-arc_snes_linesearch_typ",
                            "did you mean -arc_snes_linesearch_type"),
    "typo_ksp": (("-nat_ksp_monitr",), "-nat_ksp_monitr", "did you mean -nat_ksp_monitor"),
    "solver_option_of_other_run": (("-snes_monitor",), "-snes_monitor", "-nat_snes_monitor"),
    "plot_format": (("-plot", "o.jpg"), "-plot", ".png"),
}


@pytest.mark.parametrize("key", list(REFUSED))
def test_refused_before_any_work(tmp_path, key):
    args, option, phrase = REFUSED[key]
    proc = run_cli(*CURVE, *args, "-out", tmp_path / "x.h5", "-summary", tmp_path / "x.json", cwd=tmp_path)
    line = one_line(proc)
    assert line.startswith(option), line
    assert phrase in line, line
    assert sorted(os.listdir(tmp_path)) == [], "a refused run wrote something"


def test_typo_is_refused_before_the_work(tmp_path):
    """A misspelt solver option ends a run that would take minutes (N = 4001) within seconds."""
    t0 = time.perf_counter()
    proc = run_cli("-adh_mu", "1", "-grid_type", "uniform", "-grid_n", "4001", "-arc_snes_linesearch_typ", "basic",
                   "-out", tmp_path / "x.h5", timeout=120)
    one_line(proc)
    assert time.perf_counter() - t0 < 60          # measured 6 s: the influence matrix and the first point


def test_petsc_error_named(tmp_path):
    """MUMPS cannot factor the dense matrix: PETSc's error says which option."""
    proc = run_cli(*SOLVE, "-pc_factor_mat_solver_type", "mumps", "-out", tmp_path / "x.h5")
    line = one_line(proc)
    assert line.startswith("-pc_factor_mat_solver_type mumps:") and "seqdense" in line


@pytest.mark.parametrize("option", ["-options_left", "-options_view", "-get_total_flops", "-log_view",
                                    "-malloc_dump", "-memory_view"])
def test_standard_petsc_options_work(tmp_path, option):
    proc = run_cli(*SOLVE, option, "-summary", tmp_path / "x.json")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "x.json").exists()


def test_version():
    from petsc4py import PETSc
    import petsc_adhesion
    proc = run_cli("-version")
    assert proc.returncode == 0
    assert f"petsc-adhesion {petsc_adhesion.__version__} (PETSc {'%d.%d.%d' % PETSc.Sys.getVersion()})" in proc.stdout


# -- 2. options files and PETSc's start-up options --------------------------------------------------
def test_options_file_including_itself(tmp_path):
    f = tmp_path / "self.opts"
    f.write_text(f"-options_file {f}\n")
    line = one_line(run_cli(*SOLVE, "-options_file", f))
    assert "includes itself" in line


def test_options_file_bytes_are_escaped(tmp_path):
    f = tmp_path / "bin.opts"
    f.write_bytes(b"-adh_mu \x1b[31m\xff\xfe 1 2\n")
    line = one_line(run_cli(*SOLVE, "-options_file", f))
    assert "\\x1b" in line and "\\xff" in line


def test_petsc_options_variable_without_dash(tmp_path):
    env = dict(conftest._env(), PETSC_OPTIONS="adh_mu 2")
    proc = subprocess.run([sys.executable, "-m", "petsc_adhesion", *SOLVE], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert "PETSC_OPTIONS" in one_line(proc)


def test_bad_petscrc(tmp_path):
    (tmp_path / ".petscrc").write_text("adh_mu 2 3\n")
    line = one_line(run_cli(*SOLVE, cwd=tmp_path))
    assert ".petscrc" in line and "line 1" in line


# -- 3. files that must never be written ------------------------------------------------------------
def test_special_files_refused(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    link = tmp_path / "link.json"
    link.symlink_to(tmp_path / "elsewhere.json")
    opts = tmp_path / "s.opts"
    opts.write_text("-adh_mu 1\n")
    for args, option, phrase in [(("-summary", "/dev/null"), "-summary", "character device"),
                                 (("-out", fifo), "-out", "FIFO"),
                                 (("-summary", link), "-summary", "symbolic link"),
                                 (("-out", tmp_path / "x", "-summary", tmp_path / "x"), "-summary", "also the file"),
                                 (("-options_file", opts, "-summary", opts), "-summary", "input of this run")]:
        line = one_line(run_cli(*SOLVE, *args))
        assert line.startswith(option) and phrase in line, line
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and os.path.islink(link)
    assert opts.read_text() == "-adh_mu 1\n"
    assert sorted(os.listdir(tmp_path)) == ["fifo", "link.json", "s.opts"]


def test_non_utf8_file_name(tmp_path):
    name = os.fsencode(tmp_path) + b"/r\xff.json"
    cmd = [sys.executable.encode(), b"-m", b"petsc_adhesion", *(a.encode() for a in SOLVE), b"-summary", name]
    proc = subprocess.run(cmd, env=conftest._env(), cwd=ROOT, capture_output=True, timeout=120)
    proc.stderr, proc.stdout = proc.stderr.decode(), proc.stdout.decode()
    line = one_line(proc)
    assert line.startswith("-summary") and "UTF-8" in line and "\\xff" in line


@pytest.mark.parametrize("umask", [0o022, 0o077])
def test_files_get_the_umask_mode(tmp_path, umask):
    code = (f"import os, sys; os.umask({umask}); from petsc_adhesion.app.cli import main; "
            f"sys.exit(main(['petsc-adhesion', *{list(SOLVE)!r}, '-out', '{tmp_path}/r.h5', "
            f"'-summary', '{tmp_path}/r.json']))")
    proc = subprocess.run([sys.executable, "-c", code], env=conftest._env(), cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    for name in ("r.h5", "r.json"):
        assert stat.S_IMODE(os.stat(tmp_path / name).st_mode) == 0o666 & ~umask


@pytest.mark.parametrize("ext, magic", [(".pdf", b"%PDF"), (".svg", b"<?xml"), (".png", b"\x89PNG")])
def test_plot_format_follows_the_name(tmp_path, ext, magic):
    proc = run_cli(*CURVE, "-cont_F_max", "0", "-plot", tmp_path / f"c{ext}")
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / f"c{ext}").read_bytes().startswith(magic)


# -- 4. all or nothing ------------------------------------------------------------------------------
def _set(folder):
    return {n: (folder / n).read_bytes() for n in ("r.h5", "r.json")}


def test_failed_run_leaves_the_earlier_set(tmp_path):
    out = ("-out", tmp_path / "r.h5", "-summary", tmp_path / "r.json")
    assert run_cli(*SOLVE, *out).returncode == 0
    before = _set(tmp_path)
    proc = run_cli(*SOLVE, "-snes_max_it", "1", *out)                # fails after the work
    assert one_line(proc, status=1).startswith("Newton did not converge")
    assert _set(tmp_path) == before
    assert sorted(os.listdir(tmp_path)) == ["r.h5", "r.json"]


def _signal_run(tmp_path, signum):
    out = ("-out", tmp_path / "r.h5", "-summary", tmp_path / "r.json")
    assert run_cli(*SOLVE, *out).returncode == 0
    before = _set(tmp_path)
    proc = subprocess.Popen([sys.executable, "-m", "petsc_adhesion", "-adh_mu", "1", "-grid_type", "uniform",
                             "-grid_n", "1501", *map(str, out)], env=conftest._env(), cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(4)                                                     # inside the continuation
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=60)
    return proc, stdout, stderr, before


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["TERM", "INT"])
def test_signal_ends_cleanly(tmp_path, signum):
    proc, stdout, stderr, before = _signal_run(tmp_path, signum)
    assert proc.returncode == 128 + signum
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0] == f"{PREFIX}interrupted by {signal.Signals(signum).name}; nothing written"
    assert _set(tmp_path) == before
    assert sorted(os.listdir(tmp_path)) == ["r.h5", "r.json"]


def test_a_signal_python_wraps_ends_the_run_as_the_signal(tmp_path, monkeypatch):
    """A signal that comes while a class is made (an import: matplotlib's, for the figure, in the writing) is
    raised by Python 3.11 as RuntimeError("Error calling __set_name__ ...") from the signal's exception: the
    run still ends as interrupted (status 128 + 15, its one line), and the earlier set stays whole.  The
    signal is raised where its handler would raise it, inside a class's __set_name__."""
    from petsc_adhesion.errors import Interrupted
    from petsc_adhesion.io.plot import curve as plot_curve

    out = ("-out", "r.h5", "-summary", "r.json")
    assert conftest.in_process(*CURVE, *out, cwd=tmp_path).returncode == 0
    before = _set(tmp_path)

    class SignalHere:
        def __set_name__(self, owner, name):
            raise Interrupted(signal.SIGTERM)

    def drawn_while_imported(*args):
        type("Figure", (), {"patch": SignalHere()})

    monkeypatch.setattr(plot_curve, "curve_figure", drawn_while_imported)
    proc = conftest.in_process(*CURVE, *out, "-plot", "r.png", cwd=tmp_path)
    assert (proc.returncode, proc.stderr.strip()) == (128 + signal.SIGTERM,
                                                      f"{PREFIX}interrupted by SIGTERM; nothing written")
    assert _set(tmp_path) == before
    assert sorted(os.listdir(tmp_path)) == ["r.h5", "r.json"]


def test_journal_of_a_killed_commit_is_finished_by_the_next_run(tmp_path):
    """A run killed between the journal and its renames: the next run writing those names completes
    the set it was committing (roll forward) and removes dead runs' temporaries."""
    from petsc_adhesion.io.resultset import JOURNAL, ResultSet
    old = {"out": tmp_path / "r.h5", "summary": tmp_path / "r.json"}
    for p in old.values():
        p.write_text("old")
    new = {k: tmp_path / f".{p.name}.partial-{os.uname().nodename}-999999999" for k, p in old.items()}
    for p in new.values():
        p.write_text("new")
    (tmp_path / ".r.h5.commit").write_text(json.dumps({"program": JOURNAL,
                                                       "renames": [[str(new[k]), str(old[k])] for k in old]}))
    stray = tmp_path / f".r.json.partial-{os.uname().nodename}-999999998"
    stray.write_text("dead")
    ResultSet({k: str(v) for k, v in old.items()})
    assert {p.read_text() for p in old.values()} == {"new"}
    assert sorted(os.listdir(tmp_path)) == ["r.h5", "r.json"]


# -- 5. collective checks under MPI -------------------------------------------------------------------
def test_check_failing_on_one_rank_ends_on_all(tmp_path):
    """An -adh_guess whose bad values lie in rank 1's half only: one line from rank 0, no hang."""
    r = np.linspace(0, 10, 101)
    H = 0.5 * r * r + 2.0
    H[r > 6] = -5.0                                                   # below the wall: rank 1's rows
    with h5py.File(tmp_path / "g.h5", "w") as f:
        f["grid/r"], f["solution/H"] = r, H
    proc = run_cli(*SOLVE, "-adh_guess", tmp_path / "g.h5", "-out", tmp_path / "x.h5", np=2, timeout=120)
    assert proc.returncode != 0
    ours = [ln for ln in proc.stderr.splitlines() if "petsc-adhesion" in ln]
    assert len(ours) == 1 and ours[0].startswith(PREFIX + "-adh_guess"), proc.stderr
    assert not (tmp_path / "x.h5").exists()


# -- 6. never exit 0 on a result that is not what was asked ------------------------------------------
@pytest.mark.parametrize("args, phrase", [
    (("-cont_at_lambda", "500"), "-cont_at_lambda 500 not reached"),
    (("-cont_lambda_start", "5"), "starts in contact"),
    (("-cont_max_steps", "5"), "ended early"),
], ids=["at_lambda_not_reached", "start_in_contact", "max_steps"])
def test_incomplete_result_exits_3(tmp_path, args, phrase):
    proc = run_cli(*CURVE, *args, "-summary", tmp_path / "s.json")
    assert proc.returncode == 3, proc.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    assert not s["complete"] and any(phrase in w for w in s["warnings"]), s["warnings"]
    assert phrase in proc.stdout


# -- 7. files that describe themselves ----------------------------------------------------------------
def test_every_group_and_dataset_has_units_and_a_description(tmp_path):
    proc = run_cli(*CURVE, "-adh_sigma", "0.1", "-profiles", "-cont_error_estimate", "-cont_at_lambda", "0",
                   "-out", tmp_path / "c.h5", "-summary", tmp_path / "c.json")
    assert proc.returncode == 0, proc.stderr
    s = json.loads((tmp_path / "c.json").read_text())
    with h5py.File(tmp_path / "c.h5") as f:
        seen = []
        f.visititems(lambda name, obj: seen.append((name, obj)))
        for name, obj in [("/", f)] + seen:
            assert "units" in obj.attrs and obj.attrs["description"], name
        # the JSON's warnings, pull-off and error estimates are in the file too
        assert list(f["summary"].attrs["warnings"]) == s["warnings"]
        po = f["summary/pull_off"].attrs
        assert po["F"] == s["pull_off"]["F"] and po["F_err"] == s["pull_off"]["F_err"]
        assert list(f["summary/error_estimate"].attrs["levels"]) == s["error_estimate"]["levels"]
        assert list(f["summary/pull_off"].attrs["levels"]) == s["pull_off"]["levels"] and 0 in s["pull_off"]["levels"]
        assert f["summary"].attrs["lambda_start"] == s["lambda_start"] == f["curve/lambda"][0]
        assert f["model"].attrs["roughness"] == "hermite" and f["model"].attrs["hermite_points"] == 16
    proc = run_cli(*SOLVE, "-out", tmp_path / "s.h5")
    with h5py.File(tmp_path / "s.h5") as f:
        assert "roughness" not in f["model"].attrs                    # no roughness average at sigma = 0
        assert f["solution/H"].attrs["units"] == "epsilon"


# -- 8. what PETSc or Python would take silently ------------------------------------------------------
@pytest.mark.parametrize("args, phrase", [
    (("adh_mu", "2"), "'adh_mu' is neither an option"),
    (("-adh_mu", "1", "2"), "'2' is neither an option"),
    (("-adh_mu", "1_0"), "-adh_mu: expected a finite real"),
    (("-adh_mu", "0x1"), "-adh_mu: expected a finite real"),
], ids=["no_dash", "stray_value", "underscore", "hex"])
def test_words_python_or_petsc_would_take(tmp_path, args, phrase):
    proc = run_cli("-adh_lambda", "-2", "-grid_type", "uniform", *args, "-out", tmp_path / "x.h5")
    assert phrase in one_line(proc)
    assert not os.listdir(tmp_path)


def _guess(path, r, H):
    with h5py.File(path, "w") as f:
        f["grid/r"], f["solution/H"] = r, H


@pytest.mark.parametrize("kind, phrase", [
    ("two_columns", "two real vectors"), ("strings", "two real vectors"), ("lengths", "two real vectors"),
    ("decreasing", "increasing"), ("nan", "not finite"), ("curve_file", "cannot read"), ("text", "cannot read"),
])
def test_bad_guess_files(tmp_path, kind, phrase):
    path, r = tmp_path / "g.h5", np.linspace(0, 10, 21)
    if kind == "two_columns":
        _guess(path, r, np.ones((21, 2)))
    elif kind == "strings":
        _guess(path, r, np.array([b"a"] * 21))
    elif kind == "lengths":
        _guess(path, r[:5], np.ones(7))
    elif kind == "decreasing":
        _guess(path, r[::-1], 3 + r)
    elif kind == "nan":
        _guess(path, r, np.where(r > 5, np.nan, 3 + r))
    elif kind == "curve_file":
        assert run_cli(*CURVE, "-cont_F_max", "0", "-out", path).returncode == 0
    else:
        path.write_text("not HDF5\n")
    line = one_line(run_cli(*SOLVE, "-adh_guess", path, "-out", tmp_path / "x.h5"))
    assert line.startswith("-adh_guess") and phrase in line, line
    assert sorted(os.listdir(tmp_path)) == ["g.h5"]


def test_missed_load_minimum_is_judged_per_grid():
    """A discrete load minimum of a segment with no located minimum next to it, or one located above
    it, is reported; a lower point on another grid (a regrid's re-solved state) and a lower point on
    another part of the curve are not (results._missed_minimum)."""
    from types import SimpleNamespace as NS

    from petsc_adhesion.tracing.results import _missed_minimum

    def seg(Fs, located=()):
        """points with loads Fs; located: (step, F) of each F_min found on step [step, step + 1]."""
        pts = [NS(values={"F": F}) for F in Fs]
        found = [NS(label="F_min", segment=j, point=NS(values={"F": F})) for j, F in located]
        return NS(cont=NS(points=pts), finder=NS(found=found))

    # the minimum straddles a regrid: the old grid's last point is lower but is re-solved on the new one
    a, b = seg([-0.1, -0.5, -0.6000054]), seg([-0.6, -0.59, -0.5], located=[(0, -0.6000001)])
    assert _missed_minimum([a, b]) == ""
    # a shallow wiggle passed in one step, less tensile than the pull-off: no matter
    assert _missed_minimum([seg([-0.1, -0.3, -0.29, -0.31, -0.2]), b]) == ""
    assert "more tensile than the located pull-off" in _missed_minimum([seg([-0.1, -0.7, -0.2, -0.1]), b])
    assert "more tensile than the load minimum" in _missed_minimum([seg([-0.1, -0.7, -0.2, -0.1],
                                                                        located=[(1, -0.6)]), b])
    assert _missed_minimum([seg([-0.1, -0.2, -0.3])]) == ""     # monotone: the minimum lies beyond the curve


def test_next_run_removes_a_journal_killed_while_being_written(tmp_path):
    """A SIGKILL while the commit journal itself is written leaves '..NAME.commit.partial-HOST-PID'
    (found by tests/test_kill.py); the next run over the same names removes it, as it does the outputs'
    temporaries, and leaves a live process's alone."""
    import socket
    import subprocess
    import sys

    from petsc_adhesion.io.resultset import ResultSet

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    host = socket.gethostname()
    stale = tmp_path / f"..k.h5.commit.partial-{host}-{dead}"
    live = tmp_path / f"..k.h5.commit.partial-{host}-{os.getpid()}"
    stale.write_text("{")
    live.write_text("{")
    ResultSet({"out": str(tmp_path / "k.h5"), "summary": str(tmp_path / "k.json")})
    assert not stale.exists() and live.exists()
