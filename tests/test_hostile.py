"""Hostile input, by class: each guarantee of the command line (and of the Python API) tested over every
member of its class of hostile input, not one example each.

1. File options are judged by what the file is before it is opened: every file option the program reads
   (-options_file, one nested in an options file, one named in PETSC_OPTIONS, a .petscrc in the working
   directory, -adh_roughness_file, -adh_guess, -cont_restart, -fit_curve, ``plot FILE``) given every special kind (a
   FIFO, /dev/zero, /dev/null, a directory, a symbolic link that loops, one to nothing, a missing file):
   exit 2, one line naming the option, the file and what it is, promptly (a FIFO never blocks), nothing
   written; on two ranks too for the files read after MPI starts.
2. Output files are never touched unless asked for and earlier results are never damaged: a file that is no
   checkpoint given as -cont_checkpoint; an earlier result set after later runs that fail in every way
   (bad option, refused study, study whose every case fails, failed curve, an input named as an output);
   the all-or-nothing commit with a rename refused (in-process, os.rename monkeypatched).
3. Resources are checked before anything is allocated: grids, sweep ranges, listed values, study sizes.
4. Numbers that under- or overflow, height files and crafted checkpoints are refused in one line, never an
   internal error.
5. Environment oddities: PETSC_OPTIONS, a removed working directory, MPLBACKEND, TMPDIR, PETSC_DIR.
6. Broken pipes, full devices and SIGHUP.
7. Options that would be silently ignored are refused.
8. The Python API: concurrent calls from threads, and solve() without an approach.

Subprocesses run two at a time (module fixtures with a pool of two), curves are cheap (N = 101), so the file
takes under a minute on two cores (about 45 s measured).  Every case was first seen to fail on the
code before the fixes it checks (the defects its first version marked).
"""
from __future__ import annotations

import copy
import errno
import functools
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import conftest
from conftest import run_cli

h5py = pytest.importorskip("h5py")

PREFIX = "petsc-adhesion: error: "
FAST = ("-grid_type", "uniform", "-grid_n", "101")
#: a curve of well under a second, a solve of milliseconds, a study of two such curves
CURVE = ("-adh_mu", "1", *FAST, "-cont_F_max", "0", "-cont_error_estimate", "false")
SOLVE = ("-adh_mu", "1", "-adh_lambda", "-2", *FAST)
STUDY_BASE = (*FAST, "-cont_F_max", "0", "-cont_error_estimate", "false")
STUDY = ("-study_mu", "0.5,1", *STUDY_BASE)
#: seconds: a refusal takes about half a second; anything near this is a hang
HANG = 60
#: what must never reach the user on a refusal or a failure
NEVER = ("Traceback", "PETSC ERROR", "internal error", "MPI_ABORT", "Open MPI")
MPIEXEC = shutil.which("mpiexec") is not None
needs_mpiexec = pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found")


# -- helpers ---------------------------------------------------------------------------------------------
def cli(*args, np=1, cwd, env=None, timeout=HANG) -> subprocess.CompletedProcess:
    """conftest.run_cli, or the same command with the environment changed (name -> value, None: unset).

    A run that does not end within ``timeout`` is killed and comes back with returncode None and a stderr
    that says so: a hang fails the test like any other wrong answer (and never blocks the pool)."""
    try:
        if env is None:
            return run_cli(*args, np=np, cwd=cwd, timeout=timeout)
        full = conftest._env()
        for k, v in env.items():
            if v is None:
                full.pop(k, None)
            else:
                full[k] = v
        cmd = [sys.executable, "-m", "petsc_adhesion", *map(str, args)]
        if np > 1:                                  # the environment given to every rank
            cmd = [*conftest.mpiexec(np), *cmd]
        return subprocess.run(cmd, cwd=cwd, env=full, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return subprocess.CompletedProcess(args, None, "", f"HANG: no answer within {timeout} s")


def timed(fn) -> tuple:
    t0 = time.perf_counter()
    proc = fn()
    return proc, time.perf_counter() - t0


def pool(jobs: dict) -> dict:
    """{key: zero-argument callable} -> {key: its result}, two at a time (two cores)."""
    with ThreadPoolExecutor(max_workers=2) as ex:
        futures = {k: ex.submit(fn) for k, fn in jobs.items()}
        return {k: f.result() for k, f in futures.items()}


def one_line(proc, status=2) -> str:
    """The message of a run's only line on stderr, after checking the contract: exit ``status``, exactly one
    line, ours, printable, and no traceback, PETSc or Open MPI text, nor internal error anywhere."""
    both = proc.stdout + proc.stderr
    assert proc.returncode == status, (proc.returncode, proc.stderr[-1500:])
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(PREFIX), proc.stderr[-1500:]
    assert all(c.isprintable() for c in lines[0]), repr(lines[0])
    assert not [w for w in NEVER if w in both], proc.stderr[-1500:]
    return lines[0][len(PREFIX):]


def ours_of_two_ranks(proc, status=2) -> str:
    """As :func:`one_line` on two ranks: mpiexec adds its own banner, but the program says one line, from
    rank 0, with no traceback, PETSc error or internal error."""
    assert proc.returncode == status, (proc.returncode, proc.stderr[-1500:])
    ours = [ln for ln in proc.stderr.splitlines() if "petsc-adhesion" in ln]
    assert len(ours) == 1 and ours[0].startswith(PREFIX), proc.stderr[-1500:]
    assert not [w for w in ("Traceback", "PETSC ERROR", "internal error") if w in proc.stdout + proc.stderr], \
        proc.stderr[-1500:]
    return ours[0][len(PREFIX):]


def listing(folder) -> list:
    """Every entry of ``folder``, hidden ones (temporaries, journals, checkpoints) included."""
    return sorted(os.listdir(folder))


def snapshot(folder) -> dict:
    """name -> bytes of every regular file in ``folder`` (hidden ones included), or its kind."""
    out = {}
    for name in listing(folder):
        path = os.path.join(folder, name)
        if os.path.islink(path):
            out[name] = ("link", os.readlink(path))
        elif os.path.isfile(path):
            with open(path, "rb") as f:
                out[name] = f.read()
        else:
            out[name] = ("special", os.lstat(path).st_mode)
    return out


# =========================================================================================================
# 1. file options judged by what the file is, before it is opened
# =========================================================================================================
KINDS = ("fifo", "dev_zero", "dev_null", "directory", "link_loop", "link_dangling", "missing")
#: what the line says each kind is
SAYS = {"fifo": r"is a FIFO", "dev_zero": r"is a character device", "dev_null": r"is a character device",
        "directory": r"is a directory", "link_loop": r"is a symbolic link that loops",
        "link_dangling": r"is a symbolic link to nothing", "missing": r"does not exist|no file"}
#: each file option -> how its line starts
FILE_OPTIONS = {"options_file": "-options_file: ", "nested_options_file": "-options_file: ",
                "PETSC_OPTIONS": "PETSC_OPTIONS: -options_file: ",
                "petscrc": ".petscrc (read by PETSc at start-up): ",
                "adh_roughness_file": "-adh_roughness_file: ", "adh_guess": "-adh_guess: ",
                "cont_restart": "-cont_restart: ", "fit_curve": "-fit_curve: ", "plot": "plot: "}
#: on two ranks: the files read once MPI runs (a check on rank 0 must end every rank)
TWO_RANKS = [("adh_roughness_file", "fifo"), ("adh_guess", "fifo"), ("cont_restart", "fifo"),
             ("cont_restart", "dev_zero")]
FILE_CASES = [(o, k, 1) for o in FILE_OPTIONS for k in KINDS if not (o == "petscrc" and k == "missing")] + \
    [(o, k, 2) for o, k in TWO_RANKS]


def _special(kind: str, path: str) -> str:
    """Make a file of ``kind`` at ``path`` (the devices: a link to them when ``path`` is .petscrc); the name
    to give the program."""
    if kind.startswith("dev_"):
        device = "/dev/" + kind[4:]
        if os.path.basename(path) != ".petscrc":
            return device
        os.symlink(device, path)
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "directory":
        os.mkdir(path)
    elif kind == "link_loop":
        os.symlink(os.path.basename(path), path)           # a link to itself
    elif kind == "link_dangling":
        os.symlink(path + ".gone", path)
    return path


def _file_case(option: str, kind: str, work: str, out: str) -> tuple:
    """(arguments, environment, the name shown in the line) of a run given ``kind`` for ``option``."""
    outputs = ("-out", os.path.join(out, "r.h5"), "-summary", os.path.join(out, "r.json"))
    if option == "petscrc":
        return (*CURVE, *outputs), None, _special(kind, os.path.join(work, ".petscrc")).replace(work + "/", "")
    path = _special(kind, os.path.join(work, "input"))
    if option == "options_file":
        return (*CURVE, "-options_file", path, *outputs), None, path
    if option == "nested_options_file":
        outer = os.path.join(work, "outer.opts")
        with open(outer, "w") as f:
            f.write(f"-adh_mu 1\n-options_file {path}\n")
        return (*CURVE, "-options_file", outer, *outputs), None, path
    if option == "PETSC_OPTIONS":
        return (*CURVE, *outputs), {"PETSC_OPTIONS": f"-options_file {path}"}, path
    if option == "adh_roughness_file":
        return (*CURVE, "-adh_roughness", "measured", "-adh_roughness_file", path, *outputs), None, path
    if option == "adh_guess":
        return (*SOLVE, "-adh_guess", path, *outputs), None, path
    if option == "cont_restart":
        return (*CURVE, "-cont_restart", path, *outputs), None, path
    if option == "fit_curve":
        return ("-fit_curve", path, "-phys_radius", "20e-9", "-phys_epsilon", "3e-10", "-phys_spring", "1",
                *outputs), None, path
    assert option == "plot"
    return ("plot", path, "-o", os.path.join(out, "r.png")), None, path


@pytest.fixture(scope="module")
def file_runs(tmp_path_factory):
    cases, jobs = {}, {}
    for option, kind, np_ in FILE_CASES:
        if np_ > 1 and not MPIEXEC:
            continue
        root = tmp_path_factory.mktemp(f"{option}-{kind}-np{np_}")
        work, out = str(root / "work"), str(root / "out")
        os.makedirs(work)
        os.makedirs(out)
        args, env, shown = _file_case(option, kind, work, out)
        cases[option, kind, np_] = {"work": work, "out": out, "shown": shown, "before": snapshot(work)}
        jobs[option, kind, np_] = functools.partial(timed, functools.partial(cli, *args, np=np_, cwd=work, env=env))
    for key, (proc, elapsed) in pool(jobs).items():
        cases[key].update(proc=proc, elapsed=elapsed)
    return cases


@pytest.mark.parametrize("option, kind, np_", [pytest.param(o, k, n, id=f"{o}-{k}-np{n}",
                                                            marks=[needs_mpiexec] if n > 1 else [])
                                               for o, k, n in FILE_CASES])
def test_file_option_judged_before_it_is_opened(file_runs, option, kind, np_):
    """Guarantee 1: a special or missing file given to any file option is refused before it is opened:
    exit 2, one line naming the option, the file and what it is, within seconds (a FIFO never blocks), and
    nothing written (the output folder empty, the working folder as it was)."""
    case = file_runs[option, kind, np_]
    proc = case["proc"]
    assert proc.returncode is not None, f"{option} given {kind}: {proc.stderr}"
    msg = one_line(proc) if np_ == 1 else ours_of_two_ranks(proc)
    assert msg.startswith(FILE_OPTIONS[option]), msg
    assert f"'{case['shown']}'" in msg and re.search(SAYS[kind], msg), msg
    assert case["elapsed"] < 30, f"{case['elapsed']:.1f} s for a refusal"
    assert listing(case["out"]) == [], "a refused run wrote something"
    assert snapshot(case["work"]) == case["before"], "a refused run changed its working folder"


# =========================================================================================================
# 2. output files never touched unless asked for; earlier results never damaged
# =========================================================================================================
SET = ("c.h5", "c.json", "c.png")


def _set_args(folder) -> tuple:
    return ("-out", os.path.join(folder, SET[0]), "-summary", os.path.join(folder, SET[1]),
            "-plot", os.path.join(folder, SET[2]))


#: later runs over an earlier result set that fail: (arguments given the folder, exit status, how the line
#: starts (a regular expression))
LATER = {
    "bad_option": (lambda f: (*CURVE, "-cont_ds", "2", *_set_args(f)), 2, r"-cont_ds\b"),
    "study_refused_at_validation": (lambda f: (*STUDY, "-adh_roughness", "none", "-adh_sigma", "0.2",
                                               *_set_args(f)), 2, r"-adh_sigma\b"),
    "study_every_case_fails": (lambda f: (*STUDY, "-nat_snes_max_it", "1", *_set_args(f)), 1,
                               r"none of the 2 cases ran \(each is said above\); nothing written$"),
    "curve_fails": (lambda f: (*CURVE, "-nat_snes_max_it", "1", *_set_args(f)), 1, r"no solution at the start"),
    "earlier_result_as_checkpoint": (lambda f: (*CURVE, "-out", os.path.join(f, "c.h5"), "-summary",
                                                os.path.join(f, "c.json"), "-cont_checkpoint",
                                                os.path.join(f, "c.png")), 2, r"-cont_checkpoint\b"),
    "earlier_result_as_restart": (lambda f: (*CURVE, "-cont_restart", os.path.join(f, "c.json"), "-cont_checkpoint",
                                             "none", *_set_args(f)), 2, r"-cont_restart\b"),
    "guess_is_an_output": (lambda f: (*SOLVE, "-adh_guess", os.path.join(f, "c.h5"), *_set_args(f)[:4]), 2,
                           r"-out\b.*input of this run"),
    "plot_of_a_summary": (lambda f: ("plot", os.path.join(f, "c.json"), "-o", os.path.join(f, "c.png")), 2,
                          r"plot: .*not an HDF5 file"),
}


@pytest.fixture(scope="module")
def later_runs(tmp_path_factory):
    first = tmp_path_factory.mktemp("earlier")
    proc = cli(*CURVE, *_set_args(first), cwd=first)
    assert proc.returncode == 0, proc.stderr
    earlier = snapshot(first)
    assert sorted(earlier) == sorted(SET)
    folders, jobs = {}, {}
    for key, (args, _, _) in LATER.items():
        folder = folders[key] = tmp_path_factory.mktemp(key)
        for name, data in earlier.items():
            (folder / name).write_bytes(data)
        jobs[key] = functools.partial(cli, *args(str(folder)), cwd=folder)
    return earlier, folders, pool(jobs)


@pytest.mark.parametrize("key", list(LATER))
def test_failed_later_run_leaves_the_earlier_set(later_runs, key):
    """Guarantee 2: a later run over the names of an earlier result set (-out, -summary, -plot of a good
    run) that fails, however it fails, leaves those files byte-identical and no temporary, journal or
    moved-aside file (.partial-, .commit, .previous-) in the folder."""
    earlier, folders, procs = later_runs
    proc, (_, status, says) = procs[key], LATER[key]
    if key == "study_every_case_fails":       # each case's failure is said first, then the one error line
        assert proc.returncode == 1, proc.stderr
        lines = proc.stderr.splitlines()
        errors = [ln for ln in lines if ln.startswith(PREFIX)]
        assert errors == [lines[-1]] and re.search(says, lines[-1]), proc.stderr
        assert all(re.match(r"petsc-adhesion: case \d+ \(mu = [\d.]+\) failed: ", ln) for ln in lines[:-1]), \
            proc.stderr
        assert not [w for w in NEVER if w in proc.stderr], proc.stderr
    else:
        assert re.match(says, one_line(proc, status)), proc.stderr
    assert snapshot(folders[key]) == earlier, "the earlier result set was changed"


@pytest.mark.parametrize("kind", ["curve", "study"])
def test_a_file_that_is_no_checkpoint_is_never_a_checkpoint(tmp_path, kind):
    """Guarantee 2: an existing file that is not a checkpoint (notes.txt) named by -cont_checkpoint is
    refused before any work (exit 2, one line naming -cont_checkpoint) and left byte-identical."""
    notes = tmp_path / "notes.txt"
    notes.write_bytes(b"my notes\n\x00\xff binary too\n")
    base = CURVE if kind == "curve" else STUDY
    proc = cli(*base, "-cont_checkpoint", "notes.txt", "-cont_checkpoint_interval", "0", "-summary", "s.json",
               cwd=tmp_path)
    msg = one_line(proc)
    assert msg.startswith("-cont_checkpoint: 'notes.txt'") and "not a petsc-adhesion checkpoint" in msg, msg
    assert listing(tmp_path) == ["notes.txt"]
    assert notes.read_bytes() == b"my notes\n\x00\xff binary too\n"


@pytest.mark.parametrize("refused", ["moving_aside", "placing"])
@pytest.mark.parametrize("layout", ["one_folder", "two_folders"])
def test_commit_refused_half_way_restores_the_earlier_set(tmp_path, monkeypatch, refused, layout):
    """Guarantee 2, in-process: the all-or-nothing commit of three outputs whose second target's rename is
    refused (EPERM, as for an immutable file), while moving the earlier file aside or while putting the new
    one in place: OSError naming that target, every earlier file byte-identical, no journal, no moved-aside
    file, and once the set is discarded (as the program's ``written`` does) no temporary either."""
    from petsc_adhesion.io import resultset
    from petsc_adhesion.io.resultset import ResultSet, written

    other = tmp_path / "other" if layout == "two_folders" else tmp_path
    other.mkdir(exist_ok=True)
    targets = {"out": str(tmp_path / "r.h5"), "summary": str(other / "r.json"), "plot": str(tmp_path / "r.png")}
    for option, path in targets.items():
        with open(path, "wb") as f:
            f.write(f"earlier {option}\n".encode())
    earlier = {folder: snapshot(folder) for folder in {tmp_path, other}}
    second = os.path.abspath(targets["summary"])
    real_rename, attempts = os.rename, []

    def rename(src, dst, *a, **kw):
        src, dst = os.fspath(src), os.fspath(dst)
        if (refused == "moving_aside" and src == second) or \
                (refused == "placing" and dst == second and ".partial-" in src):
            attempts.append((src, dst))
            raise OSError(errno.EPERM, "Operation not permitted", dst)
        return real_rename(src, dst, *a, **kw)

    # the ResultSet by itself: commit raises, the earlier set is back at once
    rs = ResultSet(targets)
    for option in targets:
        with open(rs.temp(option), "w") as f:
            f.write(f"new {option}\n")
    monkeypatch.setattr(resultset.os, "rename", rename)
    try:
        with pytest.raises(OSError) as info:
            rs.commit()
    finally:
        monkeypatch.undo()
    assert attempts, "the refused rename was never tried"
    assert info.value.errno == errno.EPERM and info.value.filename == second, info.value
    assert not rs.committed
    for folder, files in earlier.items():
        now = snapshot(folder)
        assert {n: now[n] for n in files} == files, "an earlier file was changed"
        assert not [n for n in now if n.endswith(".commit") or ".previous-" in n], listing(folder)
    rs.discard()
    for folder, files in earlier.items():
        assert snapshot(folder) == files, "a temporary was left"

    # as the program commits: through written(), which discards what a failed commit leaves
    attempts.clear()
    monkeypatch.setattr(resultset.os, "rename", rename)
    try:
        with pytest.raises(OSError):
            with written(targets) as files:
                for option in targets:
                    with open(files.temp(option), "w") as f:
                        f.write(f"new {option}\n")
                files.commit()
    finally:
        monkeypatch.undo()
    assert attempts
    for folder, files in earlier.items():
        assert snapshot(folder) == files


# =========================================================================================================
# 3. resources checked before anything is allocated
# =========================================================================================================
def _million(folder) -> tuple:
    """A million listed values: too long for one argument (128 KiB), so in an options file."""
    path = os.path.join(folder, "million.opts")
    with open(path, "w") as f:
        f.write("-study_mu " + ",".join(f"{0.5 + 1e-6 * i:.6f}" for i in range(1_000_000)) + "\n")
    return (*STUDY_BASE, "-options_file", path)


RESOURCES = {
    # (arguments given the folder, the options the line may name first)
    "uniform_grid_200000": (lambda f: ("-adh_mu", "1", "-grid_type", "uniform", "-grid_n", "200000"), ("-grid_n",)),
    "uniform_grid_200000_solve": (lambda f: ("-adh_mu", "1", "-adh_lambda", "-2", "-grid_type", "uniform",
                                             "-grid_n", "200000", "-adh_pmat", "shell"), ("-grid_n",)),
    "paper_grid_500001": (lambda f: ("-adh_mu", "1", "-grid_type", "paper", "-grid_paper_extra", "500",
                                     "-grid_paper_split", "1000"), ("-grid_paper_extra", "-grid_paper_split")),
    "study_range_1e9": (lambda f: (*STUDY_BASE, "-study_mu", "0:1:1000000000"), ("-study_mu",)),
    "study_log_range_1e9": (lambda f: (*STUDY_BASE, "-study_mu", "0.001:1:1000000000:log"), ("-study_mu",)),
    "study_values_range_1e9": (lambda f: (*STUDY_BASE, "-adh_mu", "1", "-study_option", "cont_ds_max",
                                          "-study_values", "0.01:0.5:1000000000"), ("-study_values",)),
    "study_million_listed": (_million, ("-study_mu",)),
    "study_20000_listed": (lambda f: (*STUDY_BASE, "-study_mu", ",".join(["0.5"] * 20000)), ("-study_mu",)),
    "study_1e10_cases": (lambda f: (*STUDY_BASE, "-study_mu", "0.001:1:10000", "-study_sigma", "0:1:10000",
                                    "-study_option", "cont_ds_max", "-study_values", "0.01:0.5:100"),
                         ("-study_mu",)),
}
#: on two ranks: the grid too large for a rank
RESOURCES_TWO_RANKS = ("uniform_grid_200000",)
RESOURCE_CASES = [(k, 1) for k in RESOURCES] + [(k, 2) for k in RESOURCES_TWO_RANKS]


@pytest.fixture(scope="module")
def resource_runs(tmp_path_factory):
    folders, jobs = {}, {}
    for key, np_ in RESOURCE_CASES:
        if np_ > 1 and not MPIEXEC:
            continue
        folder = folders[key, np_] = tmp_path_factory.mktemp(f"{key}-np{np_}")
        args = RESOURCES[key][0](str(folder))
        jobs[key, np_] = functools.partial(timed, functools.partial(
            cli, *args, "-out", folder / "x.h5", "-summary", folder / "x.json", np=np_, cwd=folder))
    return {k: (*v, folders[k]) for k, v in pool(jobs).items()}


@pytest.mark.parametrize("key, np_", [
    pytest.param(k, n, id=f"{k}-np{n}", marks=[needs_mpiexec] if n > 1 else [])
    for k, n in RESOURCE_CASES])
def test_resources_checked_before_allocating(resource_runs, key, np_):
    """Guarantee 3: a grid, a sweep or a study too large to run is refused from its size alone, before
    anything is made of it: exit 2, one line naming the option, in seconds, nothing written."""
    proc, elapsed, folder = resource_runs[key, np_]
    msg = one_line(proc) if np_ == 1 else ours_of_two_ranks(proc)
    assert msg.startswith(tuple(o + ":" for o in RESOURCES[key][1])), msg
    assert elapsed < 20, f"{elapsed:.1f} s: the size was not checked first"
    assert [n for n in listing(folder) if n != "million.opts"] == []


def test_a_long_file_name_is_taken_whole_or_refused(tmp_path):
    """Guarantee 2: an output name longer than PETSc's string buffer is written under that name or refused
    (exit 2 naming the option); never cut short into the name of another file."""
    name = "./" * 507 + "result.json"                         # its first 1023 characters: './' * 507 + 'result.js'
    assert len(name) == 1025
    proc = cli(*SOLVE, "-summary", name, cwd=tmp_path)
    assert proc.returncode in (0, 2), proc.stderr
    if proc.returncode == 0:
        assert listing(tmp_path) == ["result.json"], listing(tmp_path)
    else:
        assert one_line(proc).startswith("-summary") and listing(tmp_path) == []


# =========================================================================================================
# 4. one-line refusals of numbers that under- or overflow, of height files and of crafted checkpoints
# =========================================================================================================
PHYS = ("-phys_radius", "1e-6", "-phys_poisson1", "0.3")
NUMBERS = {
    # (arguments, the options the line may name)
    "young_underflows": ((*PHYS, "-phys_young1", "1e-300", "-phys_gamma", "0.05", "-phys_epsilon", "4e-10"),
                         "-phys_"),
    "epsilon_tiny": ((*PHYS, "-phys_young1", "1e11", "-phys_gamma", "0.05", "-phys_epsilon", "1e-300"), "-phys_"),
    "hamaker_cutoff_tiny": ((*PHYS, "-phys_young1", "1e11", "-phys_hamaker", "1e-20", "-phys_hamaker_cutoff",
                             "1e-300", "-phys_epsilon", "4e-10"), "-phys_"),
    "radius_huge_young_tiny": (("-phys_radius", "1", "-phys_poisson1", "0.3", "-phys_young1", "1e-300",
                                "-phys_gamma", "1e3", "-phys_epsilon", "1e-300"), "-phys_"),
    "mu_subnormal": (("-adh_mu", "1e-310"), "-adh_mu"),
    "mu_smallest_subnormal": (("-adh_mu", "5e-324"), "-adh_mu"),
    "roughness_cutoff_tiny": (("-adh_mu", "1", "-adh_roughness", "truncated_gaussian", "-adh_sigma", "0.2",
                               "-adh_roughness_cutoff", "1e-300"), "-adh_roughness_cutoff"),
}


def _write(path, fill) -> None:
    with open(path, "wb") as f:
        fill(f)


#: height files (-adh_roughness measured -adh_roughness_file F): name -> writer
HEIGHTS = {
    "values_1e308.txt": lambda p: np.savetxt(p, 1e308 * np.random.default_rng(1).uniform(0.5, 1, 100)),
    "values_pm_1e308.npy": lambda p: np.save(p, 1.7e308 * np.random.default_rng(2).uniform(-1, 1, 100)),
    "npz_as.npy": lambda p: _write(p, lambda f: np.savez(f, h=np.random.default_rng(3).normal(size=100) * 0.1)),
    "subnormal.txt": lambda p: np.savetxt(p, 1e-320 * np.random.default_rng(4).integers(-5, 6, 100)),
    "subnormal.npy": lambda p: np.save(p, np.array([5e-324, 1e-320, -1e-320, 0.0] * 25)),
    "all_equal.txt": lambda p: np.savetxt(p, np.full(100, 0.3)),
    "all_equal_2d.npy": lambda p: np.save(p, np.full((10, 10), 0.1)),
    "one_value.npy": lambda p: np.save(p, np.array([0.1])),
    "empty.txt": lambda p: _write(p, lambda f: None),
    "not_finite.txt": lambda p: np.savetxt(p, np.r_[np.inf, np.random.default_rng(5).normal(size=99)]),
    "complex.npy": lambda p: np.save(p, np.arange(100) * 1j),
    "pickled_objects.npy": lambda p: np.save(p, np.array([1, "a"], dtype=object), allow_pickle=True),
    "huge_npy_header.npy": lambda p: _write(p, lambda f: f.write(b"\x93NUMPY\x01\x00\xff\xff" + b" " * 65535)),
}


@pytest.fixture(scope="module")
def checkpoint_file(tmp_path_factory):
    """A real checkpoint of the cheap curve, saved at every pause (-cont_checkpoint_interval 0) and kept
    (the run's removal of it, once its results are in place, patched out): its bytes."""
    folder = tmp_path_factory.mktemp("checkpoint")
    code = ("import sys\n"
            "from petsc_adhesion.io import resultset\n"
            "init = resultset.ResultSet.__init__\n"
            "resultset.ResultSet.__init__ = lambda self, targets, drop=(): init(self, targets, ())\n"
            "from petsc_adhesion.app.cli import main\n"
            "sys.exit(main(['petsc-adhesion', *sys.argv[1:]]))\n")
    proc = subprocess.run([sys.executable, "-c", code, *CURVE, "-cont_checkpoint", "ck", "-cont_checkpoint_interval",
                           "0", "-summary", "s.json"], cwd=folder, env=conftest._env(), capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return (folder / "ck").read_bytes()


def _points(tree):
    return tree["tracer"]["segments"][0]["continuation"]["points"]


def _study_fingerprint(header, tree):
    del header["fingerprint"]["mpi_ranks"]                 # a study's fingerprint has no ranks
    return {"phase": "study", "cases": []}


#: crafted checkpoints: name -> change of (header, tree) (returning a new tree, or None to keep it), rewritten
#: with a valid header (format, length and SHA-256 of the new payload)
CRAFTED = {
    "no_segments": lambda h, t: t["tracer"].__setitem__("segments", []),
    "unknown_phase": lambda h, t: t.__setitem__("phase", "bogus"),
    "a_studys": _study_fingerprint,
    "study_state_curve_fingerprint": lambda h, t: {"phase": "study", "cases": []},
    "wall_not_a_dict": lambda h, t: t.__setitem__("wall", 5),
    "tracer_a_list": lambda h, t: t.__setitem__("tracer", [1]),
    "segment_empty": lambda h, t: t["tracer"].__setitem__("segments", [{}]),
    "segment_a_string": lambda h, t: t["tracer"].__setitem__("segments", ["x"]),
    "nodes_changed": lambda h, t: t["tracer"]["segments"][0].__setitem__("N", 50),
    "event_incomplete": lambda h, t: t["tracer"]["segments"][0].__setitem__("events", [{"label": 3}]),
    "points_empty": lambda h, t: t["tracer"]["segments"][0]["continuation"].__setitem__("points", {}),
    # the ones the program does not refuse
    "tree_a_list": lambda h, t: [1, 2],
    "state_rows_too_short": lambda h, t: _points(t)["x"].__setitem__("__local__", np.zeros((52, 50))),
    "state_of_strings": lambda h, t: _points(t)["x"].__setitem__("__local__", np.full((52, 101), "a")),
    "fewer_loads_than_states": lambda h, t: _points(t).__setitem__("p", [1.0]),
    "loads_of_strings": lambda h, t: _points(t).__setitem__("p", ["a"] * 52),
    "guarded_a_string": lambda h, t: t["tracer"]["segments"][0].__setitem__("guarded", "x"),
    "state_nan": lambda h, t: _points(t)["x"]["__local__"].__setitem__(Ellipsis, np.nan),
    "step_nan": lambda h, t: t["tracer"]["segments"][0]["continuation"].__setitem__("ds", float("nan")),
    "step_negative": lambda h, t: t["tracer"]["segments"][0]["continuation"].__setitem__("ds", -1.0),
}
REFUSALS = {**{k: (NUMBERS[k][0], NUMBERS[k][1]) for k in NUMBERS},
            **{f"heights_{k}": (None, "-adh_roughness_file") for k in HEIGHTS},
            **{f"checkpoint_{k}": (None, "-cont_restart") for k in CRAFTED}}


def _params():
    out = []
    for key in REFUSALS:
        out.append(pytest.param(key, id=key))
    return out


@pytest.fixture(scope="module")
def refusal_runs(tmp_path_factory, checkpoint_file):
    from petsc_adhesion.app.checkpoint import read_file, write_file

    inputs = tmp_path_factory.mktemp("inputs")
    (inputs / "ck").write_bytes(checkpoint_file)
    header, tree, _ = read_file(str(inputs / "ck"))
    header = {k: v for k, v in header.items() if k not in ("format", "bytes", "sha256")}
    cases, jobs = {}, {}
    for key, (args, _) in REFUSALS.items():
        out = tmp_path_factory.mktemp(key)
        given = None
        if key.startswith("heights_"):
            given = str(inputs / key[len("heights_"):])
            HEIGHTS[key[len("heights_"):]](given)
            args = (*SOLVE, "-adh_roughness", "measured", "-adh_roughness_file", given)
        elif key.startswith("checkpoint_"):
            h, t = copy.deepcopy(header), copy.deepcopy(tree)
            new = CRAFTED[key[len("checkpoint_"):]](h, t)
            given = str(inputs / key)
            write_file(given, h, t if new is None else new)
            args = (*CURVE, "-cont_restart", given)
        else:
            args = (*args, *FAST) if "-adh_lambda" in args else (*args, "-adh_lambda", "-2", *FAST)
        cases[key] = {"out": out, "given": given,
                      "before": open(given, "rb").read() if given and os.path.isfile(given) else None}
        jobs[key] = functools.partial(cli, *args, "-out", out / "x.h5", "-summary", out / "x.json", cwd=out,
                                      timeout=10 if key.startswith("checkpoint_") else HANG)
    for key, proc in pool(jobs).items():
        cases[key]["proc"] = proc
    return cases


@pytest.mark.parametrize("key", _params())
def test_refused_in_one_line_never_an_internal_error(refusal_runs, key):
    """Guarantee 4: physical inputs that under- or overflow double precision, a subnormal Tabor parameter, a
    vanishing roughness cutoff, height files of extreme, subnormal, equal, foreign or malformed values, and
    checkpoints crafted with a valid header around a state that is not one (restarted with the same
    options): exit 2, one line naming the option, never 'internal error', nothing written, the input file
    left as it was."""
    case = refusal_runs[key]
    proc = case["proc"]
    assert proc.returncode is not None, proc.stderr
    assert "internal error" not in proc.stderr, proc.stderr
    msg = one_line(proc)
    assert msg.startswith(REFUSALS[key][1]), msg
    assert listing(case["out"]) == [], "a refused run wrote something"
    if case["before"] is not None:
        assert open(case["given"], "rb").read() == case["before"], "the input file was changed"


@pytest.mark.parametrize("rms", [1e-10, 1e-6, 1e-3])
def test_nearly_smooth_measured_heights_are_solved_or_refused(tmp_path, rms):
    """Guarantee 4: heights of an rms too small for the histogram's average (its rounding grows as 1 / rms:
    below 1e-4 epsilon it exceeds what the roughness changes) are refused in one line naming the file
    option; above that floor the solve converges to a load within rms^2 of the smooth one."""
    heights = np.random.default_rng(1).normal(size=100)
    np.savetxt(tmp_path / "h.txt", (heights - heights.mean()) / heights.std() * rms)
    proc = cli(*SOLVE, "-adh_roughness", "measured", "-adh_roughness_file", "h.txt", "-summary", "s.json",
               cwd=tmp_path)
    if rms < 1e-4:
        assert one_line(proc).startswith("-adh_roughness_file: heights: rms"), proc.stderr
        return
    smooth = cli(*SOLVE, "-summary", "smooth.json", cwd=tmp_path)
    assert smooth.returncode == 0 and proc.returncode == 0, proc.stderr
    F = json.loads((tmp_path / "s.json").read_text())["F"]
    assert abs(F - json.loads((tmp_path / "smooth.json").read_text())["F"]) < 10 * rms ** 2


# =========================================================================================================
# 5. environment oddities
# =========================================================================================================
def _removed_cwd(*args, root):
    """The program started in a working directory removed just before (by the shell that starts it)."""
    gone = os.path.join(root, "gone")
    os.mkdir(gone)
    cmd = ["sh", "-c", 'cd "$1" && rmdir "$1" && shift && exec "$@"', "sh", gone, sys.executable, "-m",
           "petsc_adhesion", *map(str, args)]
    return subprocess.run(cmd, env=conftest._env(), capture_output=True, text=True, timeout=HANG)


def test_petsc_options_naming_a_missing_file(tmp_path):
    """Guarantee 5: PETSC_OPTIONS naming an options file in a folder that does not exist: exit 2, one line
    naming PETSC_OPTIONS and the file, nothing written."""
    proc = cli(*CURVE, "-summary", "s.json", cwd=tmp_path,
               env={"PETSC_OPTIONS": "-adh_sigma 0 -options_file /nonexistent/folder/x.opts"})
    msg = one_line(proc)
    assert msg.startswith("PETSC_OPTIONS: -options_file: '/nonexistent/folder/x.opts'"), msg
    assert listing(tmp_path) == []


@pytest.mark.parametrize("what", ["curve", "plot_relative"])
def test_removed_working_directory(tmp_path, what):
    """Guarantee 5: started in a working directory that was removed: a run says so in one line (exit 2,
    PETSc would read .petscrc there); the plot command of a relative name says there is no such file;
    nothing written."""
    out = tmp_path / "out"
    out.mkdir()
    if what == "curve":
        msg = one_line(_removed_cwd(*CURVE, "-summary", out / "s.json", root=str(tmp_path)))
        assert "working directory no longer exists" in msg, msg
    else:
        msg = one_line(_removed_cwd("plot", "c.h5", "-o", out / "c.png", root=str(tmp_path)))
        assert msg.startswith("plot: no file 'c.h5'"), msg
    assert listing(out) == []


@pytest.mark.parametrize("what", ["run_plot", "plot_command"])
def test_invalid_mplbackend_still_draws(tmp_path, what):
    """Guarantee 5: MPLBACKEND naming no backend (matplotlib refuses to import then): the figure is still
    drawn into its file (exit 0, a PNG), no traceback."""
    env = {"MPLBACKEND": "no_such_backend"}
    if what == "run_plot":
        proc = cli(*CURVE, "-plot", "c.png", cwd=tmp_path, env=env)
    else:
        assert cli(*CURVE, "-out", "c.h5", cwd=tmp_path).returncode == 0
        proc = cli("plot", "c.h5", "-o", "c.png", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    assert not [w for w in NEVER if w in proc.stderr], proc.stderr
    assert (tmp_path / "c.png").read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize("tmpdir", ["missing", "a_file", "read_only"])
def test_unusable_tmpdir(tmp_path, tmpdir):
    """Guarantee 5: TMPDIR that is no writable directory (Open MPI keeps its session files there and would
    abort with a page): exit 2, one line naming TMPDIR, nothing written."""
    path = tmp_path / "tmp"
    if tmpdir == "a_file":
        path.write_text("x")
    elif tmpdir == "read_only":
        path.mkdir(mode=0o500)
        if os.access(path, os.W_OK):
            pytest.skip("a read-only folder is writable here (root)")
    out = tmp_path / "out"
    out.mkdir()
    msg = one_line(cli(*CURVE, "-summary", out / "s.json", cwd=out, env={"TMPDIR": str(path)}))
    assert msg.startswith(f"TMPDIR: '{path}'"), msg
    assert listing(out) == []


@pytest.mark.parametrize("petsc_dir", ["/nonexistent/petsc", "/tmp"])
def test_nonsense_petsc_dir(tmp_path, petsc_dir):
    """Guarantee 5: PETSC_DIR naming no PETSc: whatever the program can do, it says it in one line, without a
    traceback, and writes nothing."""
    proc = cli(*SOLVE, "-summary", "s.json", cwd=tmp_path, env={"PETSC_DIR": petsc_dir, "PETSC_ARCH": "nonsense"})
    assert proc.returncode in (0, 1, 2), proc.stderr
    if proc.returncode:
        one_line(proc, proc.returncode)
        assert listing(tmp_path) == []
    else:
        assert not [w for w in NEVER if w in proc.stderr], proc.stderr


# =========================================================================================================
# 6. broken pipes, full devices, SIGHUP
# =========================================================================================================
def test_reader_that_goes_away(tmp_path):
    """Guarantee 6: ``petsc-adhesion CURVE -cont_monitor | head -1``: the reader goes after one line; the run
    ends with its own status (0) and says nothing of it: no traceback, no PETSc or Open MPI text."""
    cmd = " ".join([sys.executable, "-m", "petsc_adhesion", *CURVE, "-cont_monitor"])
    proc = subprocess.run(["bash", "-c", f"set -o pipefail; {cmd} | head -1; echo status=${{PIPESTATUS[0]}}"],
                          cwd=tmp_path, env=conftest._env(), capture_output=True, text=True, timeout=HANG)
    assert proc.stdout.splitlines()[0].lstrip().startswith("0 CONT lambda"), proc.stdout
    assert not [w for w in NEVER if w in proc.stderr], proc.stderr[-1500:]
    assert proc.stderr == "", proc.stderr[-1500:]
    assert proc.stdout.splitlines()[-1] == "status=0", proc.stdout


@pytest.mark.parametrize("what", [
    "solve", "version", "plot_usage", "study", "bad_input"])
def test_stdout_whose_reader_is_gone(tmp_path, what):
    """Guarantee 6: standard output a pipe nobody reads any more (its read end closed before the start):
    the run ends with its own status, saying nothing of it (no traceback, PETSc or Open MPI text)."""
    args, status = {"solve": (SOLVE, 0), "version": (("-version",), 0), "plot_usage": (("plot", "-h"), 0),
                    "study": (STUDY, 0), "bad_input": ((*SOLVE, "-adh_mu", "-1"), 2)}[what]
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        proc = subprocess.run([sys.executable, "-m", "petsc_adhesion", *args], stdout=write_end,
                              stderr=subprocess.PIPE, cwd=tmp_path, env=conftest._env(), text=True, timeout=HANG)
    finally:
        os.close(write_end)
    assert proc.returncode == status, (proc.returncode, proc.stderr[-1500:])
    assert not [w for w in NEVER if w in proc.stderr], proc.stderr[-1500:]
    assert not [ln for ln in proc.stderr.splitlines() if ln.startswith(PREFIX) and status == 0], proc.stderr


@pytest.mark.parametrize("what", [
    "solve", "curve", "version", "help", "plot_usage"])
def test_stdout_on_a_full_device(tmp_path, what):
    """Guarantee 6: standard output on /dev/full, no files asked: the report cannot be written, so the run
    fails, exit 1, in one line naming standard output."""
    args = {"solve": SOLVE, "curve": CURVE, "version": ("-version",), "help": (*SOLVE, "-help"),
            "plot_usage": ("plot", "-h")}[what]
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "petsc_adhesion", *args], stdout=full, stderr=subprocess.PIPE,
                              cwd=tmp_path, env=conftest._env(), text=True, timeout=HANG)
    proc.stdout = ""
    msg = one_line(proc, 1)
    assert msg == "cannot write 'standard output': No space left on device", msg
    assert listing(tmp_path) == []


def test_full_stdout_and_files_agree(tmp_path):
    """Guarantees 2 and 6: the report on a full device while files are asked: the exit status and the folder
    agree: 1 and nothing written, or the run's own status and its files."""
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "petsc_adhesion", *CURVE, "-summary", "s.json"], stdout=full,
                              stderr=subprocess.PIPE, cwd=tmp_path, env=conftest._env(), text=True, timeout=HANG)
    assert "Traceback" not in proc.stderr
    assert (proc.returncode == 1 and listing(tmp_path) == []) or \
        (proc.returncode == 0 and listing(tmp_path) == ["s.json"]), (proc.returncode, listing(tmp_path))


def test_sighup_during_a_curve(tmp_path):
    """Guarantee 6: SIGHUP (the terminal closed) while a curve is traced (mu = 5 on the default grid, a few
    seconds; sent once the first step is monitored): exit 129, the one line 'interrupted by SIGHUP; nothing
    written', and nothing written but the checkpoint that line names."""
    proc = subprocess.Popen([sys.executable, "-m", "petsc_adhesion", "-adh_mu", "5", "-cont_monitor", "-out", "c.h5",
                             "-summary", "c.json"], cwd=tmp_path, env=conftest._env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        first = proc.stdout.readline()                      # PETSc runs, the curve is being traced
        assert "CONT" in first, first
        time.sleep(0.3)
        proc.send_signal(signal.SIGHUP)
        _, stderr = proc.communicate(timeout=HANG)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 128 + signal.SIGHUP, (proc.returncode, stderr[-1500:])
    lines = stderr.splitlines()
    assert len(lines) == 1, stderr[-1500:]
    m = re.fullmatch(re.escape(PREFIX + "interrupted by SIGHUP; nothing written")
                     + r"(; go on with -cont_restart (.+))?", lines[0])
    assert m, lines[0]
    named = [os.path.basename(m.group(2))] if m.group(2) else []
    assert listing(tmp_path) == named


# =========================================================================================================
# 7. options honoured or refused, never silently ignored
# =========================================================================================================
IGNORED = {
    # (arguments, the option named)
    "grid_n_with_edge_grid": (("-adh_mu", "1", "-grid_n", "101"), "-grid_n"),
    "reuse_without_matrix": ((*CURVE, "-adh_pmat", "shell", "-adh_pc_reuse_its", "3"), "-adh_pc_reuse_its"),
    "interval_without_checkpoint": ((*CURVE, "-cont_checkpoint", "none", "-cont_checkpoint_interval", "5"),
                                    "-cont_checkpoint_interval"),
    "interval_without_progress": ((*CURVE, "-progress", "false", "-progress_interval", "2"), "-progress_interval"),
    "band_without_band": ((*CURVE, "-adh_pmat", "dense", "-adh_pmat_band", "5"), "-adh_pmat_band"),
    "cutoff_without_truncation": ((*CURVE, "-adh_roughness_cutoff", "2"), "-adh_roughness_cutoff"),
    "progress_of_a_solve": ((*SOLVE, "-progress", "true"), "-progress"),
    "restart_of_a_solve": ((*SOLVE, "-cont_restart", "ck"), "-cont_restart"),
    "study_option_in_one_run": ((*CURVE, "-study_ranks", "1"), "-study_ranks"),
    "target_without_error_bars": ((*CURVE, "-target_error", "1e-3"), "-target_error"),
    "interval_with_nothing_saved": ((*CURVE, "-cont_checkpoint_interval", "0"), "-cont_checkpoint_interval"),
}


@pytest.fixture(scope="module")
def ignored_runs(tmp_path_factory):
    folders = {k: tmp_path_factory.mktemp(k) for k in IGNORED}
    return {k: (proc, folders[k]) for k, proc in
            pool({k: functools.partial(cli, *args, cwd=folders[k]) for k, (args, _) in IGNORED.items()}).items()}


@pytest.mark.parametrize("key", [
    k for k in IGNORED])
def test_option_without_effect_is_refused(ignored_runs, key):
    """Guarantee 7: an option that the rest of the command line makes meaningless (another grid's, a
    preconditioner's reuse without a matrix, the interval of saves or progress lines that are off, a
    curve's option in a solve, a study's in one run) is refused: exit 2, one line naming it, nothing
    written."""
    proc, folder = ignored_runs[key]
    msg = one_line(proc)
    assert msg.startswith(IGNORED[key][1] + ":"), msg
    assert listing(folder) == []


# =========================================================================================================
# 8. the Python API
# =========================================================================================================
_THREADS = r'''
import json, sys, threading
import petsc_adhesion as pa

KW = dict(grid_type="uniform", grid_n=101, cont_F_max=0, cont_error_estimate=False)
MUS = (0.5, 0.3)
serial = {mu: pa.curve(mu=mu, **KW).pull_off.F.value for mu in MUS}
trials = []
for _ in range(6):
    got, errors = {}, []

    def run(mu, bad=None):
        try:
            if bad:
                pa.curve(mu=mu, **KW, **bad)
                errors.append(f"mu = {mu}: {bad} was not refused")
            else:
                got[str(mu)] = pa.curve(mu=mu, **KW).pull_off.F.value
        except pa.InputError as e:
            if not bad:
                errors.append(f"mu = {mu}: InputError {e}")
            elif not str(e).startswith("-cont_ds_min"):
                errors.append(f"mu = {mu}: {bad} refused as {e}")
        except BaseException as e:
            errors.append(f"mu = {mu}: {type(e).__name__}: {e}")

    threads = [threading.Thread(target=run, args=(mu,)) for mu in MUS] + \
        [threading.Thread(target=run, args=(1.0, {"cont_ds_min": 2}))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    trials.append({"got": got, "errors": errors})
print(json.dumps({"serial": {str(k): v for k, v in serial.items()}, "trials": trials}))
'''


def test_concurrent_curves_from_threads(tmp_path):
    """Guarantee 8: curve(mu=0.5) and curve(mu=0.3) called at once from two threads (and a third call with a
    bad option beside them), six times: each call gets its own pull-off, equal to the same call made alone
    to 1e-12, no exception but the bad call's own InputError."""
    script = tmp_path / "threads.py"
    script.write_text(_THREADS)
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=conftest._env(), capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-1500:]
    out = json.loads(proc.stdout.splitlines()[-1])
    serial = out["serial"]
    assert abs(serial["0.5"] - serial["0.3"]) > 1e-3          # the two calls are told apart
    for i, trial in enumerate(out["trials"]):
        assert trial["errors"] == [], (i, trial["errors"])
        assert set(trial["got"]) == set(serial), (i, trial)
        for mu, F in trial["got"].items():
            assert abs(F - serial[mu]) <= 1e-12 * max(1.0, abs(F)), (i, mu, F, serial[mu])


@pytest.mark.parametrize("lam", [None, float("nan"), float("inf"), True, "-2", [-2.0]],
                         ids=["None", "nan", "inf", "True", "str", "list"])
def test_solve_without_an_approach_is_refused_at_once(lam):
    """Guarantee 8: solve() given no finite real approach raises InputError naming -adh_lambda at once (in
    under a second), before any work."""
    import petsc_adhesion as pa

    t0 = time.perf_counter()
    with pytest.raises(pa.InputError) as info:
        pa.solve(lam)
    assert time.perf_counter() - t0 < 1.0
    assert str(info.value).startswith("-adh_lambda"), info.value


# =========================================================================================================
# 9. the newer probe's classes: true refusals, damaged files, the process's limits, MPI's surroundings,
#    environment text, measured curves, every file the program writes drawn, ./run's variables
# =========================================================================================================
def _sizes(msg: str) -> tuple:
    """The two sizes of a 'has X, more than the Y read whole' line, in bytes."""
    units = {"bytes": 1, "KiB": 1 << 10, "MiB": 1 << 20, "GiB": 1 << 30, "TiB": 1 << 40}
    m = re.search(r"has ([\d.]+) (\w+), more than the ([\d.]+) (\w+)", msg)
    assert m, msg
    return float(m.group(1)) * units[m.group(2)], float(m.group(3)) * units[m.group(4)]


@pytest.mark.parametrize("size, limit", [(1500, 1000), (1001, 1000), (5 << 20, 1 << 20), ((1 << 20) + 3, 1 << 20),
                                         (3 << 30, 2 << 30)])
def test_a_size_refusal_says_true_sizes(tmp_path, size, limit):
    """Guarantee 9: a file over the size read whole is said with its size and the limit each in a unit that
    shows them (never '0.0 GiB' against '0 GiB'): the size said is over the limit said, both within 0.5% of
    the truth.  (A sparse file: no disk is used.)"""
    from petsc_adhesion.io.inputs import file_problem

    path = tmp_path / "big"
    with open(path, "wb") as f:
        f.truncate(size)
    said_size, said_limit = _sizes(file_problem(str(path), limit))
    assert said_size > said_limit > 0
    assert abs(said_size - size) <= 0.005 * size and abs(said_limit - limit) <= 0.005 * limit


def test_an_options_file_of_one_long_comment(tmp_path):
    """Guarantee 9 on the command line: an options file of one comment line just over the 16 MiB read whole
    (the probe's case: it was said as 'has 0.0 GiB, more than the 0 GiB'): exit 2, one line with its true size
    against the true limit, nothing written."""
    from petsc_adhesion.app.optionsfile import MAX_OPTIONS_BYTES

    (tmp_path / "long.opts").write_text("#" + "x" * MAX_OPTIONS_BYTES + "\n")
    out = tmp_path / "out"
    out.mkdir()
    msg = one_line(cli(*SOLVE, "-options_file", "long.opts", "-summary", out / "s.json", cwd=tmp_path))
    assert msg.startswith("-options_file: 'long.opts' has "), msg
    said_size, said_limit = _sizes(msg)
    assert said_size == MAX_OPTIONS_BYTES + 2 and said_limit == MAX_OPTIONS_BYTES, msg
    assert listing(out) == []


#: 64 bytes overwritten at this many evenly spread places of a result file, one place a file
DAMAGE_PLACES = 40


def _damaged_copies(src, folder, places=DAMAGE_PLACES) -> list:
    data = open(src, "rb").read()
    out = []
    for k in range(places):
        at = int(len(data) * (k + 0.5) / places)
        bad = bytearray(data)
        bad[at:at + 64] = bytes([0xA5]) * min(64, len(data) - at)
        path = os.path.join(folder, f"bad{k:02d}.h5")
        with open(path, "wb") as f:
            f.write(bad)
        out.append(path)
    return out


@pytest.fixture(scope="module")
def result_files(tmp_path_factory):
    """A curve's and a solve's -out files (cheap: N = 101)."""
    folder = tmp_path_factory.mktemp("results")
    runs = pool({"curve": functools.partial(cli, *CURVE, "-out", "c.h5", cwd=folder),
                 "solve": functools.partial(cli, *SOLVE, "-out", "s.h5", cwd=folder)})
    assert all(p.returncode == 0 for p in runs.values()), {k: p.stderr for k, p in runs.items()}
    return {"curve": str(folder / "c.h5"), "solve": str(folder / "s.h5")}


@pytest.mark.parametrize("kind", ["curve", "solve"])
def test_plot_of_a_file_damaged_anywhere(result_files, tmp_path, capfd, kind):
    """Guarantee 9: ``plot`` of a result file with 64 bytes overwritten at each of 40 places (its header, its
    trees, its data): exit 2 and one line naming the file (the probe's case ended in h5py's 27-line traceback,
    a RuntimeError of an attribute message), or the figure when the damage fell where plot does not read; never
    an exception, never a partial figure."""
    from petsc_adhesion.io.plot.command import command

    refused = 0
    for path in _damaged_copies(result_files[kind], str(tmp_path)):
        png = path[:-3] + ".png"
        status = command([path, "-o", png])
        err = capfd.readouterr().err
        assert status in (0, 2), (path, status, err)
        if status == 2:
            refused += 1
            lines = err.splitlines()
            assert len(lines) == 1 and lines[0].startswith(f"{PREFIX}plot: '{path}' "), err
            assert re.search(r"is not an HDF5 file|damaged or incomplete|is not a petsc-adhesion result|"
                             r"not a whole", lines[0]), lines[0]
            assert not os.path.exists(png)
        else:
            assert err == "" and open(png, "rb").read(4) == b"\x89PNG"
    assert refused >= 5, f"only {refused} of {DAMAGE_PLACES} damaged files refused"


def test_plot_of_a_damaged_file_on_the_command_line(result_files, tmp_path):
    """Guarantee 9, the probe's case on the command line: each damaged copy plot refuses is one line, exit 2,
    nothing written (the first three such copies are run as the user runs them)."""
    from petsc_adhesion.io.plot.command import command

    bad = []
    for path in _damaged_copies(result_files["curve"], str(tmp_path)):
        if command([path, "-o", path[:-3] + ".png"]) == 2:
            bad.append(path)
    out = tmp_path / "out"
    out.mkdir()
    for path in bad[:3]:
        msg = one_line(cli("plot", path, "-o", out / "x.png", cwd=tmp_path))
        assert msg.startswith(f"plot: '{path}' "), msg
    assert listing(out) == []


def test_plot_of_a_file_the_machine_cannot_read(result_files, tmp_path, monkeypatch, capsys):
    """Guarantee 9: an I/O error of the device while the file is read (EIO) is the machine's failure, not bad
    input: exit 1, one line saying it cannot be read."""
    from petsc_adhesion.io.plot import command as cmd

    def eio(*a, **kw):
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(cmd.h5py, "File", eio)
    assert cmd.command([result_files["curve"], "-o", str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err == [f"{PREFIX}cannot read '{result_files['curve']}': Input/output error"], err
    assert listing(tmp_path) == []


def test_guess_damaged_anywhere(result_files, tmp_path):
    """Guarantee 9: -adh_guess given a solve's file damaged at each of 40 places: read (when the damage fell
    outside r and H) or InputError naming -adh_guess, never another exception."""
    from petsc_adhesion.errors import InputError
    from petsc_adhesion.io.guess import read_guess

    refused = 0
    for path in _damaged_copies(result_files["solve"], str(tmp_path)):
        try:
            read_guess(path, 0.0)
        except InputError as e:
            refused += 1
            assert str(e).startswith("-adh_guess: ") and "\n" not in str(e), e
    assert refused >= 5, refused


def _limited_run(args, cwd, address_space):
    """The command line under an address-space limit (as ``ulimit -v`` sets it)."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    return subprocess.run([sys.executable, "-m", "petsc_adhesion", *map(str, args)], cwd=cwd, env=conftest._env(),
                          capture_output=True, text=True, timeout=HANG, preexec_fn=limit)


@pytest.mark.parametrize("what", ["curve", "solve", "spring", "soft"])
def test_a_grid_over_the_address_space_limit(tmp_path, what):
    """Guarantee 9: a grid whose matrices fit the machine but not the process's address-space limit (3 GiB:
    N = 20000 needs 15 GiB for a curve, N = 8000 4.8 GiB for a solve; a spring's curve and a soft sphere's
    (mu = 300) likewise) is refused before anything is made: exit 2, one line naming the grid option and the
    limit (it ended in 'internal error: MemoryError' or a PETSc error), nothing written."""
    args = {"curve": ("-adh_mu", "1", "-grid_type", "uniform", "-grid_n", "20000"),
            "solve": ("-adh_mu", "1", "-adh_lambda", "-2", "-grid_type", "uniform", "-grid_n", "12000"),
            "spring": ("-adh_mu", "2", "-afm_spring", "0.5", "-grid_type", "uniform", "-grid_n", "20000"),
            "soft": ("-adh_mu", "300", "-grid_type", "uniform", "-grid_n", "20000")}[what]
    proc = _limited_run((*args, "-summary", "s.json", "-out", "s.h5"), tmp_path, 3 << 30)
    msg = one_line(proc)
    assert msg.startswith("-grid_n: N = "), msg
    assert "the address-space limit (ulimit -v, RLIMIT_AS) of 3 GiB leaves " in msg, msg
    assert listing(tmp_path) == []


def test_memory_limits_name_the_one_that_binds(tmp_path):
    """Guarantee 9, in-process: the control group's limit (v2's memory.max less memory.current) is read from its
    files, 'max' is no limit, and the refusal names the smallest of the limits given, with what it leaves."""
    from petsc_adhesion.app.options.checks import check_memory, memory_limits
    from petsc_adhesion.errors import InputError
    from petsc_adhesion.tracing.trace import GridChoice

    limit, used = tmp_path / "memory.max", tmp_path / "memory.current"
    limit.write_text(f"{4 << 30}\n")
    used.write_text(f"{1 << 30}\n")
    found = [x for x in memory_limits(((str(limit), str(used)),)) if "control group" in x[2]]
    assert found == [(float(3 << 30), float(4 << 30), f"the control group's memory limit ({limit})", False)]
    limit.write_text("max\n")
    assert not [x for x in memory_limits(((str(limit), str(used)),)) if "control group" in x[2]]

    grid = GridChoice(kind="uniform", n=20000)
    limits = [(64e9, None, "this machine has", False), (2.0 * (1 << 30), float(4 << 30), "the control group's "
              "memory limit (/sys/fs/cgroup/memory.max)", False)]
    with pytest.raises(InputError) as info:
        check_memory(grid, "dense", True, 1, limits)
    assert str(info.value).startswith("-grid_n: N = 20000 nodes need 15.2 GiB a rank") and \
        "the control group's memory limit (/sys/fs/cgroup/memory.max) of 4 GiB leaves 2 GiB" in str(info.value)
    check_memory(GridChoice(kind="uniform", n=101), "dense", True, 1, limits)      # fits: no refusal


@pytest.mark.parametrize("np_", [pytest.param(1), pytest.param(2, marks=needs_mpiexec)])
def test_shared_memory_folder_unusable(tmp_path, np_):
    """Guarantee 9: on two ranks, a shared-memory folder the ranks cannot make their segments in (Open MPI's
    backing directory a file, as an unwritable /dev/shm is) is refused before MPI starts: exit 2, one line
    naming it with the remedy (it was Open MPI's page of warnings); one process makes no segment and runs."""
    (tmp_path / "shm").write_text("a file, not a folder")
    out = tmp_path / "out"
    out.mkdir()
    proc = cli(*SOLVE, "-summary", out / "s.json", np=np_, cwd=tmp_path,
               env={"OMPI_MCA_btl_vader_backing_directory": str(tmp_path / "shm")})
    if np_ == 1:
        assert proc.returncode == 0 and listing(out) == ["s.json"], proc.stderr
        return
    msg = ours_of_two_ranks(proc)
    assert msg.startswith(f"OMPI_MCA_btl_vader_backing_directory: '{tmp_path / 'shm'}' is not a writable "
                          f"directory"), msg
    assert listing(out) == []


def test_library_start_refuses_unusable_tmpdir(tmp_path):
    """Guarantee 9, the library's start: a first call (petsc_adhesion.curve) in a process whose TMPDIR is a
    file raises RuntimeError, one line naming TMPDIR and the remedy, before MPI_Init (it was Open MPI's page
    from orte_init and MPI_Init's abort, exit 1, the caller's process gone); the caller goes on."""
    (tmp_path / "afile").write_text("x")
    code = ("import petsc_adhesion\n"
            "try:\n    petsc_adhesion.curve(1.0, cont_F_max=0)\n"
            "except RuntimeError as e:\n    print('said:', e)\n"
            "print('the caller goes on')\n")
    env = dict(conftest._env(), TMPDIR=str(tmp_path / "afile"))
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=HANG)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr[-1500:]
    assert proc.stdout.splitlines() == [f"said: TMPDIR: '{tmp_path / 'afile'}' is not a writable directory (MPI keeps "
                                        f"its session files there): set it to one that is, or unset it",
                                        "the caller goes on"], proc.stdout


@needs_mpiexec
def test_tmpdir_under_a_bare_mpiexec(tmp_path):
    """Guarantee 9 under `mpiexec -n 2` (not ./run): Open MPI's launcher makes its session folder in TMPDIR
    before any rank runs, so a TMPDIR it cannot use is its own text and no code of ours runs (documented:
    docs/guarantees.md, docs/install.md): nothing written, no line of ours.  A TMPDIR the ranks alone are
    given (mpiexec -x, env) is not read by their MPI_Init: the run is not refused for it, and completes."""
    (tmp_path / "afile").write_text("x")
    out = tmp_path / "out"
    out.mkdir()
    base = [shutil.which("mpiexec"), "-n", "2"]
    run = [sys.executable, "-m", "petsc_adhesion", *SOLVE, "-summary", str(out / "s.json")]
    env = conftest._env()
    proc = subprocess.run(base + run, cwd=out, env=dict(env, TMPDIR=str(tmp_path / "afile")), capture_output=True,
                          text=True, timeout=HANG)
    assert proc.returncode not in (0, None) and "petsc-adhesion" not in proc.stderr + proc.stdout, proc.stderr
    assert listing(out) == []
    proc = subprocess.run(base + ["env", f"TMPDIR={tmp_path / 'afile'}"] + run, cwd=out, env=env,
                          capture_output=True, text=True, timeout=HANG)
    assert proc.returncode == 0 and listing(out) == ["s.json"], proc.stderr[-1500:]


def test_dev_shm_unusable_in_process(tmp_path, monkeypatch):
    """Guarantee 9, in-process: /dev/shm itself not a writable folder, on a rank of two: the line names it and
    says how to mend it; on one rank nothing is said."""
    from petsc_adhesion import singleton
    from petsc_adhesion.app import cli as app_cli

    monkeypatch.setattr(singleton, "SHARED_MEMORY_DEFAULT", str(tmp_path / "missing-shm"))
    for v in singleton.SHARED_MEMORY_VARIABLES:
        monkeypatch.delenv(v, raising=False)
    monkeypatch.delenv("TMPDIR", raising=False)
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "2")
    msg = app_cli.environment()
    assert msg == (f"'{tmp_path / 'missing-shm'}' is not a writable directory (the ranks share memory through "
                   f"files there): mount it writable (a tmpfs), or set OMPI_MCA_btl_vader_backing_directory to a "
                   f"writable folder such as /tmp"), msg
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "1")
    assert app_cli.environment() is None


@pytest.mark.parametrize("name, np_", [("PETSC_OPTIONS", 1), ("PETSC_OPTIONS_YAML", 1),
                                       pytest.param("PETSC_OPTIONS", 2, marks=needs_mpiexec)])
def test_environment_that_is_not_utf8(tmp_path, name, np_):
    """Guarantee 9: PETSC_OPTIONS (or PETSC_OPTIONS_YAML) holding a byte that is not UTF-8 (0xff): exit 2, one
    line naming the variable (it was 'internal error: UnicodeDecodeError', exit 1), nothing written; on two
    ranks too."""
    out = tmp_path / "out"
    out.mkdir()
    proc = cli(*SOLVE, "-summary", out / "s.json", np=np_, cwd=tmp_path, env={name: "-adh_sigma \udcff"})
    msg = one_line(proc) if np_ == 1 else ours_of_two_ranks(proc)
    assert msg == f"{name}: '-adh_sigma \\xff' is not valid UTF-8: write it in UTF-8, or unset it", msg
    assert listing(out) == []


LOOPED = {"adh_guess": lambda p: (*SOLVE, "-adh_guess", p), "fit_curve": lambda p: (
    "-fit_curve", p, "-phys_radius", "20e-9", "-phys_epsilon", "3e-10", "-phys_spring", "1"),
    "options_file": lambda p: (*CURVE, "-options_file", p), "plot": lambda p: ("plot", p, "-o", "x.png"),
    "cont_restart": lambda p: (*CURVE, "-cont_restart", p),
    "adh_roughness_file": lambda p: (*CURVE, "-adh_roughness", "measured", "-adh_roughness_file", p)}


@pytest.mark.parametrize("option", list(LOOPED))
@pytest.mark.parametrize("where", ["two_links", "in_the_folder"])
def test_input_through_a_symbolic_link_loop(tmp_path, option, where):
    """Guarantee 9: an input behind a loop of two links (a -> b -> a), or in a folder that is a link to itself
    (loop/x): exit 2 (the probe saw 1), one line naming the option and the loop, nothing written."""
    os.symlink("b", tmp_path / "a")
    os.symlink("a", tmp_path / "b")
    os.symlink("loop", tmp_path / "loop")
    path = "a" if where == "two_links" else "loop/x"
    before = listing(tmp_path)
    msg = one_line(cli(*LOOPED[option](path), cwd=tmp_path))
    assert msg.startswith(f"{'plot' if option == 'plot' else '-' + option}: '{path}' is a symbolic link that loops"), \
        msg
    assert listing(tmp_path) == before


def _curve_rows(header=True):
    """A measured-like curve in nm and nN: a baseline, a linear contact, a pull-off of 4 nN."""
    rng = np.random.default_rng(0)
    z = np.linspace(0, 100, 200)
    Fa = np.where(z > 80, (z - 80) * 0.5, 0.0)
    Fr = np.maximum(np.where(z > 70, (z - 80) * 0.5, 0.0), -4.0 * (z > 70))
    return np.r_[z, z[::-1]], np.r_[Fa, Fr[::-1]] + 0.01 * rng.standard_normal(400)


def _write_curve(path, header, fmt, z, F):
    with open(path, "w") as f:
        f.write((header + "\n" if header else "") + "\n".join(fmt(a, b) for a, b in zip(z, F)) + "\n")
    return str(path)


FIT_TIP = ("-phys_radius", "20e-9", "-phys_epsilon", "3e-10", "-phys_spring", "1")
#: text curves whose numbers no AFM measures in the units stated: (header, scale of z, of F, the line's start)
IMPLAUSIBLE = {
    "nm_under_metres": ("z (m), F (nN)", 1, 1, r"column 1 'z \(m\)': the piezo travels 100 m, .*likely in nm"),
    "nN_under_newtons": ("z (nm), F (N)", 1, 1, r"column 2 'F \(N\)': the largest force is [\d.]+ N, .*likely in nN"),
    "no_header_nm": ("", 1, 1e-9, r"column 1 \(no header: in m\): the piezo travels 100 m, .*give a header"),
    "kilometres": ("z (km?), F (nN)", 1, 1, r"column 1 'z \(km\?\)': 'km\?' is no length unit"),
    "near_1e300": ("z (nm), F (nN)", 1e298, 1e298, r"column 1 'z \(nm\)': the piezo travels 1e\+291 m"),
    "beyond_floats_sum": ("", 1e306, 1e-9, r"column 1 \(no header: in m\): the piezo travels (1e\+308|more than)"),
}


@pytest.mark.parametrize("key", list(IMPLAUSIBLE))
def test_a_curve_whose_units_lie(tmp_path, key):
    """Guarantee 9: a -fit_curve text file whose numbers no AFM measures in the units its header states (nm
    under a metres header ran past two minutes; values near 1e300 ended in 'internal error: OverflowError'):
    exit 2 within seconds, one line naming the column and the likely unit, nothing written."""
    header, sz, sF, says = IMPLAUSIBLE[key]
    z, F = _curve_rows()
    _write_curve(tmp_path / "c.csv", header, lambda a, b: f"{a * sz:.6g}, {b * sF:.6g}", z, F)
    out = tmp_path / "out"
    out.mkdir()
    proc, elapsed = timed(lambda: cli("-fit_curve", "c.csv", *FIT_TIP, "-summary", out / "f.json", cwd=tmp_path))
    msg = one_line(proc)
    assert re.match(r"-fit_curve: 'c\.csv': " + says, msg), msg
    assert elapsed < 30 and listing(out) == []


@pytest.mark.parametrize("form", ["semicolons", "blanks", "tabs", "semicolons_no_header", "first_row_whole"])
def test_a_decimal_comma_curve_is_read_as_such(tmp_path, form):
    """Guarantee 9: a curve written with decimal commas ('1,5;2,3', '1,5 2,3', tabs; its first row whole
    numbers) reads as the same curve written with points, to the digits written (it was split at the commas
    into wrong columns and ended in numpy's warnings)."""
    from petsc_adhesion.fitting.data import read_curve

    z, F = _curve_rows()
    if form == "first_row_whole":
        z[0], F[0] = 0.0, 0.0
    points = read_curve(_write_curve(tmp_path / "p.csv", "z (nm), F (nN)", lambda a, b: f"{a:.6g}, {b:.6g}", z, F))
    sep = {"semicolons": ";", "blanks": " ", "tabs": "\t", "semicolons_no_header": ";", "first_row_whole": ";"}[form]
    header = "" if form == "semicolons_no_header" else f"z (nm){sep}F (nN)".replace(" (", "(") if sep != ";" else \
        "z (nm);F (nN)"
    scale = 1e-9 if form == "semicolons_no_header" else 1.0
    comma = read_curve(_write_curve(tmp_path / "c.csv", header, lambda a, b: f"{a * scale:.6g}{sep}{b * scale:.6g}"
                                    .replace(".", ","), z, F))
    assert comma.turn == points.turn
    np.testing.assert_allclose(comma.z, points.z, rtol=1e-5, atol=1e-15)
    np.testing.assert_allclose(comma.F, points.F, rtol=1e-5, atol=1e-20)


def test_a_decimal_comma_curve_that_changes_its_mind(tmp_path):
    """Guarantee 9: a file whose rows start with decimal commas and then use points is refused in one line
    naming the first row that is not numbers as the first were; on the command line too."""
    z, F = _curve_rows()
    rows = [f"{a:.6g};{b:.6g}".replace(".", ",") for a, b in zip(z, F)]
    rows[50] = "12.5;1.5"
    (tmp_path / "c.csv").write_text("z (nm);F (nN)\n" + "\n".join(rows) + "\n")
    msg = one_line(cli("-fit_curve", "c.csv", *FIT_TIP, cwd=tmp_path))
    assert msg.startswith("-fit_curve: 'c.csv': line 52 is not numbers with decimal commas, as the first row: "
                          "'12.5;1.5'"), msg


def test_a_truncated_afm_file_is_one_line(tmp_path):
    """Guarantee 9: the Asylum .ibw of tests/data cut at half and at 300 bytes: one line each, with no raw bytes
    before it (igor2 logged the bytes it could not shape), exit 2."""
    pytest.importorskip("afmformats")
    data = open(os.path.join(conftest.ROOT, "tests", "data", "fmt-igor-fd_SiN_FD_plot.ibw"), "rb").read()
    for n in (len(data) // 2, 300):
        (tmp_path / "t.ibw").write_bytes(data[:n])
        msg = one_line(cli("-fit_curve", "t.ibw", *FIT_TIP, cwd=tmp_path))
        assert msg.startswith("-fit_curve: 't.ibw': not a force-distance curve afmformats reads"), msg


@pytest.fixture(scope="module")
def fit_file(tmp_path_factory):
    """The -out file of a fit of the golden synthetic curve (tests/golden.py's fit case)."""
    folder = tmp_path_factory.mktemp("fit")
    proc = cli("-fit_curve", os.path.join(conftest.ROOT, "tests", "data", "golden", "curve.csv"),
               "-phys_radius", "20e-9", "-phys_epsilon", "0.3e-9", "-phys_spring", "1", "-out", "f.h5",
               cwd=folder, timeout=900)
    assert proc.returncode in (0, 3), proc.stderr[-1500:]
    return str(folder / "f.h5")


def test_plot_draws_a_fit_file(fit_file, tmp_path):
    """Guarantee 9: ``plot`` draws every file the program writes: a fit's -out file is drawn (it was refused
    as 'not a petsc-adhesion result'), exit 0, a PNG of the measured points and the fitted model."""
    proc = cli("plot", fit_file, "-o", tmp_path / "f.png", cwd=tmp_path)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert (tmp_path / "f.png").read_bytes().startswith(b"\x89PNG") and (tmp_path / "f.png").stat().st_size > 10_000


def test_plot_of_a_pull_off_fit_says_there_is_no_curve(tmp_path):
    """Guarantee 9: a pull-off fit's file has no curve to draw: exit 2, one line saying so, nothing written."""
    assert cli("-fit_pull_off", "12.46e-9", "-phys_radius", "20e-9", "-phys_young1", "150e9", "-phys_poisson1",
               "0.27", "-phys_epsilon", "0.3e-9", "-out", "p.h5", cwd=tmp_path).returncode == 0
    msg = one_line(cli("plot", "p.h5", "-o", "p.png", cwd=tmp_path))
    assert msg == "plot: a fit of a pull-off force has no curve to draw", msg
    assert listing(tmp_path) == ["p.h5"]


# -- ./run's variables, in a copy of the script with a fake install: nothing is installed ------------------
def _run_script(tmp_path, *args, env=None, installed=False):
    """bash run ARGS in a copy of ./run beside pyproject.toml; ``installed``: a fake .venv whose stamp is
    current (its python a script that succeeds), so that setup finds the install in place."""
    for name in ("run", "pyproject.toml"):
        shutil.copy(os.path.join(conftest.ROOT, name), tmp_path / name)
    if installed:
        import hashlib

        venv = tmp_path / ".venv"
        (venv / "bin").mkdir(parents=True, exist_ok=True)
        (venv / "bin" / "python").write_text("#!/bin/sh\nexit 0\n")
        (venv / "bin" / "python").chmod(0o755)
        (venv / ".mpi").write_text("system Debian's Open MPI (mpiexec)\n")
        stamp = hashlib.sha1((tmp_path / "pyproject.toml").read_bytes() + (tmp_path / "run").read_bytes())
        (venv / ".installed").write_text(stamp.hexdigest() + "\n")
    full = {k: v for k, v in os.environ.items() if not k.startswith("RUN_") and k not in ("NP",)}
    full.update(HOME=str(tmp_path), **(env or {}))
    return subprocess.run(["bash", str(tmp_path / "run"), *args], cwd=tmp_path, env=full, capture_output=True,
                          text=True, timeout=60)


RUN_BAD = {"RUN_NO_APT": ["yes", "0", "true"], "RUN_MPI": ["openmpi", "System"], "RUN_BLAS": ["mkl"],
           "NP": ["0", "two", "-1", "1.5"], "RUN_PYTHON": ["/nonexistent/python3"], "RUN_CHECK_USER": ["Root User"]}
RUN_GOOD = {"RUN_NO_APT": ["1", ""], "RUN_MPI": ["system", "wheel", ""], "RUN_BLAS": ["system", "wheel"],
            "NP": ["1", "2"], "RUN_PYTHON": [sys.executable], "RUN_CHECK_USER": ["runcheck"]}


@pytest.mark.parametrize("name, value", [(n, v) for n, vs in RUN_BAD.items() for v in vs])
def test_run_refuses_a_variable_out_of_its_values(tmp_path, name, value):
    """Guarantee 9: a ./run variable given a value it does not document (RUN_NO_APT=yes was ignored): exit 2,
    one line naming it and what it takes, before anything is done (no .venv made)."""
    proc = _run_script(tmp_path, "check-variables", env={name: value})
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"run: {name}='{value}' "), proc.stderr
    assert not (tmp_path / ".venv").exists()


@pytest.mark.parametrize("name, value", [(n, v) for n, vs in RUN_GOOD.items() for v in vs])
def test_run_takes_a_documented_value(tmp_path, name, value):
    """Guarantee 9: each documented value of each variable is taken (./run check-variables: exit 0, silent)."""
    proc = _run_script(tmp_path, "check-variables", env={name: value})
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr


@pytest.mark.parametrize("given", [{"RUN_NO_APT": "1"}, {"RUN_BLAS": "system"},
                                   {"RUN_BLAS": "wheel", "RUN_NO_APT": "1"}])
def test_run_says_an_install_variable_waits_for_the_next_install(tmp_path, given):
    """Guarantee 9: a variable that chooses how to install, given where the install exists (it was ignored
    without a word): ./run setup says in one line that it applies to the next install and how to make one now,
    and leaves the install as it was (exit 0)."""
    proc = _run_script(tmp_path, "setup", env=given, installed=True)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    shown = ", ".join(f"{k}={given[k]}" for k in ("RUN_BLAS", "RUN_NO_APT") if k in given)
    assert lines[0].startswith(f"run: {shown}: appl") and "to the next install" in lines[0] and \
        f"rm {tmp_path}/.venv/.installed, then ./run setup" in lines[0], lines[0]
    assert _run_script(tmp_path, "setup", installed=True).stderr == ""        # nothing given: nothing said


@pytest.mark.parametrize("what", ["TMPDIR", "shm"])
def test_run_checks_mpis_surroundings_before_mpiexec(tmp_path, what):
    """Guarantee 9: NP=2 ./run study with a TMPDIR or a shared-memory folder that is no writable folder: one
    line naming it with the remedy before mpiexec starts (Open MPI's own page otherwise), exit 2."""
    (tmp_path / "afile").write_text("x")
    env = {"NP": "2", "TMPDIR" if what == "TMPDIR" else "OMPI_MCA_btl_vader_backing_directory": str(tmp_path / "afile")}
    proc = _run_script(tmp_path, "study", "x.opts", env=env, installed=True)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "is not a writable directory" in lines[0], proc.stderr
    assert lines[0].startswith("run: TMPDIR=" if what == "TMPDIR" else f"run: '{tmp_path / 'afile'}'"), lines[0]


#: numbers that under- or overflow in the cantilever's, the fit's and the soft sphere's options (the newer
#: probe: -afm_spring 1e-300 traced to lambda = -1.7e100, -phys_spring 1e-300 ended in numpy's overflow
#: warnings): (arguments, the option named)
NEW_NUMBERS = {
    "spring_underflows": ((*CURVE, "-afm_spring", "1e-300"), "-afm_spring"),
    "spring_of_a_soft_sphere_underflows": (("-adh_mu", "300", "-afm_spring", "1e-300"), "-afm_spring"),
    "lever_underflows": (("-fit_curve", "c.csv", *FIT_TIP[:4], "-phys_spring", "1e-300"), "-phys_spring"),
    "lever_overflows": (("-fit_curve", "c.csv", *FIT_TIP[:4], "-phys_spring", "1e300"), "-phys_spring"),
    "pull_off_subnormal": (("-fit_pull_off", "5e-324", "-phys_radius", "20e-9", "-phys_young1", "150e9",
                            "-phys_poisson1", "0.27", "-phys_epsilon", "0.3e-9"), "-fit_pull_off"),
    "soft_sphere_sigma_huge": (("-adh_mu", "300", "-adh_sigma", "1e300"), "-adh_sigma"),
}


@pytest.mark.parametrize("key", list(NEW_NUMBERS))
def test_new_options_numbers_that_under_or_overflow(tmp_path, key):
    """Guarantee 4 for the cantilever, the fit and the soft sphere: exit 2, one line naming the option and
    the range it takes (a subnormal pull-off: the mu it would need), nothing written."""
    args, option = NEW_NUMBERS[key]
    z, F = _curve_rows()
    _write_curve(tmp_path / "c.csv", "z (nm), F (nN)", lambda a, b: f"{a:.6g}, {b:.6g}", z, F)
    out = tmp_path / "out"
    out.mkdir()
    msg = one_line(cli(*args, "-summary", out / "s.json", cwd=tmp_path))
    assert msg.startswith(f"{option}: expected a finite real in " if key != "pull_off_subnormal" else
                          f"{option}: P = 4.941e-324 N needs mu below 1e-12"), msg
    assert listing(out) == []


PULL_OFF_FIT = ("-fit_pull_off", "1e-8", "-phys_radius", "20e-9", "-phys_young1", "150e9", "-phys_poisson1", "0.27",
                "-phys_epsilon", "0.3e-9")
#: the older classes (outputs judged before any work, options without effect, resources) for the cantilever,
#: CSV, energy, fit and soft-sphere options: (arguments given the folder, how the line starts)
NEW_OPTIONS = {
    "csv_a_fifo": (lambda f: (*CURVE, "-afm_spring", "0.5", "-csv", _special("fifo", f"{f}/ff")), "-csv: "),
    "csv_events_a_directory": (lambda f: (*CURVE, "-afm_spring", "0.5", "-csv_events", _special("directory", f"{f}/d")),
                               "-csv_events: "),
    "csv_a_device": (lambda f: (*CURVE, "-csv", "/dev/null"), "-csv: '/dev/null' is a character device"),
    "csv_events_a_dangling_link": (lambda f: (*CURVE, "-csv_events", _special("link_dangling", f"{f}/l")),
                                   "-csv_events: "),
    "csv_and_events_one_file": (lambda f: (*CURVE, "-csv", "c.csv", "-csv_events", "c.csv"),
                                "-csv_events: 'c.csv' is also the file of -csv"),
    "spring_in_a_solve": (lambda f: (*SOLVE, "-afm_spring", "0.5"), "-afm_spring: applies to a curve"),
    "csv_in_a_solve": (lambda f: (*SOLVE, "-csv", "x.csv"), "-csv: applies to a curve"),
    "csv_events_in_a_fit": (lambda f: (*PULL_OFF_FIT, "-csv_events", "e.csv"), "-csv_events: not with -fit_pull_off"),
    "spring_in_a_fit": (lambda f: (*PULL_OFF_FIT, "-afm_spring", "1"), "-afm_spring: not with -fit_pull_off"),
    "soft_sphere_grid_too_large": (lambda f: ("-adh_mu", "300", "-grid_type", "uniform", "-grid_n", "200000"),
                                   "-grid_n: N = 200000 nodes need 1.46 TiB"),
    "spring_grid_too_large": (lambda f: ("-adh_mu", "1", "-afm_spring", "0.5", "-grid_type", "uniform", "-grid_n",
                                         "200000"), "-grid_n: N = 200000 nodes need 1.46 TiB"),
}


@pytest.mark.parametrize("key", list(NEW_OPTIONS))
def test_the_older_classes_for_the_newer_options(tmp_path, key):
    """Guarantees 1, 3 and 7 for the cantilever, CSV, energy (a spring run's), fit and soft-sphere options: an
    output that is no regular file, two outputs on one file, an option the run would ignore, a grid too large:
    exit 2, one line naming the option, nothing written (the folder as it was)."""
    args = NEW_OPTIONS[key][0](str(tmp_path))
    before = snapshot(tmp_path)
    msg = one_line(cli(*args, cwd=tmp_path))
    assert msg.startswith(NEW_OPTIONS[key][1]), msg
    assert snapshot(tmp_path) == before


def test_a_failed_spring_run_leaves_the_earlier_csv_files(tmp_path):
    """Guarantee 2 for -csv and -csv_events (a spring run's points and events, its jumps and energy): a later
    run over the same names that fails (no solution at the start) leaves them byte for byte."""
    names = ("-out", "c.h5", "-csv", "c.csv", "-csv_events", "e.csv", "-summary", "c.json")
    first = cli(*CURVE, "-afm_spring", "0.5", *names, cwd=tmp_path)
    assert first.returncode in (0, 3), first.stderr
    earlier = snapshot(tmp_path)
    assert sorted(earlier) == ["c.csv", "c.h5", "c.json", "e.csv"]
    msg = one_line(cli(*CURVE, "-afm_spring", "0.5", "-nat_snes_max_it", "1", *names, cwd=tmp_path), 1)
    assert msg.startswith("no solution at the start"), msg
    assert snapshot(tmp_path) == earlier
