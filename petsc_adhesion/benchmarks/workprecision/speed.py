"""Speed, start-up, where the time goes, and scaling with the grid and the ranks: the work-precision benchmark's timings."""
from __future__ import annotations

import compileall
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time
from dataclasses import replace

from petsc4py import PETSc

from ...app.options.reading import AppOptions, read_settings
from ...discretization import grid
from ...discretization.preconditioning import create as create_pmat
from ...model.parameters import Model
from ...singleton import OPENMPI_SINGLETON, SESSION_VARIABLE
from ...tracing.edge_grids import RMAX
from .accuracy import ENV, REPEATS, SCALE_N, SCALE_STEPS, SLOW, _trace

__all__ = ["speed", "PROFILE_STAGES", "profile", "STARTUP", "startup", "peak_rss_kib", "scale_worker", "scaling"]


# -- speed -------------------------------------------------------------------------------------------------
def _user_env(singleton: bool = True) -> dict:
    """The environment of a timed process: a user's Python, which keeps its bytecode cache (a sandbox's
    PYTHONDONTWRITEBYTECODE would have every run compile petsc-adhesion's modules again, 40-60 ms here),
    with petsc-adhesion's Open MPI singleton defaults unless ``singleton`` is False.  The cache is written
    first, as by a user's first run."""
    compileall.compile_dir(os.path.dirname(os.path.dirname(__file__)), quiet=1)
    # the session folder this process's own import chose is its own: a timed process chooses its own
    env = {k: v for k, v in os.environ.items()
           if k not in OPENMPI_SINGLETON and k not in (SESSION_VARIABLE, "PYTHONDONTWRITEBYTECODE")}
    return env | ENV | (OPENMPI_SINGLETON if singleton else {})


def _process(args: list[str], repeats: int = REPEATS, timeout: float = 600.0):
    """Median wall time of the whole program ``python -m petsc_adhesion ARGS`` (start-up included)."""
    times, out = [], ""
    env = _user_env()
    for k in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "petsc_adhesion", *args], capture_output=True, text=True,
                           env=env, timeout=timeout)
        times.append(time.perf_counter() - t0)
        if p.returncode not in (0, 3):
            raise RuntimeError(f"petsc_adhesion {' '.join(args)}: {p.stderr.strip()}")
        out = p.stdout
        if times[0] > SLOW * 2:
            break
    return times, out


def _row(quantity, times, target=None, **extra) -> dict:
    med = statistics.median(times)
    return {"quantity": quantity, "median_s": med, "min_s": min(times), "max_s": max(times), "repeats": len(times),
            "target_s": target, "met": None if target is None else med <= target, **extra}


def speed(quick: bool = False, log=print) -> dict:
    """The mu = 1 curve's continuation without and with bars, the whole process, the
    pull-off to 1e-6 and 1e-8 (whole process), each against its target."""
    reps = 1 if quick else 5
    model = Model(mu=1.0, rmax=RMAX)
    out = {}
    t_no, res = [], None
    for _ in range(reps):
        res = _trace(model, None)
        t_no.append(res["wall_time_s"])
    out["speed_curve"] = _row("mu = 1 curve, continuation, no bars", t_no, 0.3, steps=res["steps"])
    t_with, t_bars = [], []
    for _ in range(reps):
        t0 = time.perf_counter()
        res = _trace(model, None, errors=True)
        t_with.append(time.perf_counter() - t0)
        t_bars.append(res["error_estimate"]["wall_time_s"])
    out["speed_curve_bars"] = _row("mu = 1 curve with error bars", t_with, 0.5, bars_median_s=statistics.median(t_bars))
    times, _ = _process(["-adh_mu", "1"], reps)
    out["speed_process"] = _row("mu = 1, whole process", times, 1.0)
    for tol, target in ((1e-6, 2.0), (1e-8, 15.0)):
        times, text = _process(["-adh_mu", "1", "-target_error", f"{tol:g}"], 1 if quick or tol < 1e-7 else reps)
        line = next((ln.strip() for ln in text.splitlines() if ln.strip().startswith("pull-off")), "")
        out[f"speed_target_{tol:g}"] = _row(f"mu = 1, -target_error {tol:g}, whole process", times, target,
                                            pull_off_line=line)
    for v in out.values():
        log(f"[speed] {v['quantity']}: {v['median_s']:.3g} s (target {v['target_s']} s)")
    return out


#: stages of a curve with bars, each the cumulative time of one function (file, name); they nest
PROFILE_STAGES = (("influence matrices (17 grids and their nested levels)", "influence.py", "create_influence"),
                  ("event location (roots along the arcs)", "events.py", "_root"),
                  ("error bars (events located again on the nested levels)", "error_estimate.py", "event_errors"))


def _where(path: str, name: str) -> str:
    """Where a profiled function runs: PETSc's or numpy's or scipy's compiled code, a module of ours, or
    other Python."""
    if path == "~":                                   # compiled: said by its name
        for lib, label in (("petsc4py", "PETSc, compiled (LU, triangular solves, GMRES, vector operations)"),
                           ("numpy", "numpy, compiled (the dense products of the operator, array arithmetic)"),
                           ("scipy", "scipy, compiled (Brent's method, elliptic integrals)")):
            if lib in name:
                return label
        return "Python's built-ins"
    if "/petsc_adhesion/" in path:
        return f"petsc_adhesion.{os.path.basename(path)[:-3]} (Python)"
    for lib in ("numpy", "scipy", "petsc4py"):
        if f"/{lib}/" in path:
            return f"{lib} (its Python)"
    return "other Python"


def profile(log=print) -> dict:
    """Where the mu = 1 curve with bars spends its time: one run under cProfile after a
    warm one, the own time of every function summed by :func:`_where`, and the cumulative time of
    :data:`PROFILE_STAGES`.  cProfile slows the Python side, so shares, not times, are the measurement."""
    import cProfile
    import pstats

    model = Model(mu=1.0, rmax=RMAX)
    _trace(model, None, errors=True)
    prof = cProfile.Profile()
    prof.enable()
    _trace(model, None, errors=True)
    prof.disable()
    stats = pstats.Stats(prof).stats                  # (file, line, name) -> (cc, nc, own, cumulative, callers)
    own = {}
    for (path, _, name), (_, _, tt, _, _) in stats.items():
        where = _where(path, name)
        own[where] = own.get(where, 0.0) + tt
    total = sum(own.values())
    stages = {label: sum(ct for (path, _, name), (_, _, _, ct, _) in stats.items()
                         if path.endswith("/" + file) and name == fn) for label, file, fn in PROFILE_STAGES}
    solves = sum(v[1] for (path, _, name), v in stats.items() if path == "~" and "PETSc.SNES" in name
                 and "solve" in name)
    log(f"[profile] {total:.3g} s under cProfile, {solves} SNES solves")
    return {"total_s": total, "snes_solves": solves, "stages": stages,
            "own": dict(sorted(own.items(), key=lambda kv: -kv[1]))}


#: What a start-up costs, stage by stage: each a fresh interpreter running only that code, with
#: petsc-adhesion's Open MPI singleton defaults (:mod:`petsc_adhesion.singleton`) unless the third item is False.
STARTUP = (("Python interpreter", "pass", True), ("numpy", "import numpy", True),
           ("scipy.optimize", "import scipy.optimize", True), ("h5py (a run that writes files)", "import h5py", True),
           ("mpi4py (MPI_Init), Open MPI's own singleton start-up", "import mpi4py.MPI", False),
           ("mpi4py (MPI_Init), petsc-adhesion's singleton defaults", "import mpi4py.MPI", True),
           ("petsc4py (MPI_Init, PetscInitialize)", "import petsc4py; petsc4py.init(); from petsc4py import PETSc",
            True),
           ("petsc_adhesion.app.options (every module a curve needs, PETSc initialised)",
            "import petsc_adhesion, petsc4py; petsc4py.init(); import petsc_adhesion.app.options, petsc_adhesion.app.run",
            True))


def startup(reps: int = REPEATS) -> list[dict]:
    """The fastest of ``reps`` fresh interpreters for each stage of :data:`STARTUP`: the fixed cost of any
    run before its work (the fastest, as this is a floor, not a typical time)."""
    rows = []
    for what, code, defaults in STARTUP:
        env = _user_env(defaults)
        times = []
        for _ in range(reps):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], check=True, env=env, capture_output=True)
            times.append(time.perf_counter() - t0)
        rows.append({"stage": what, "min_s": min(times), "median_s": statistics.median(times), "repeats": reps})
    return rows


# -- scaling ------------------------------------------------------------------------------------------------
def peak_rss_kib() -> int:
    """This process's peak resident memory in KiB: VmHWM of /proc/self/status, the high-water mark of
    its own address space.  getrusage's ru_maxrss is not used: Linux carries it across exec, so a
    worker started by a large benchmark process would report the benchmark's peak."""
    try:
        with open("/proc/self/status") as f:
            return next(int(ln.split()[1]) for ln in f if ln.startswith("VmHWM:"))
    except (OSError, StopIteration):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def scale_worker(n: int, kind: str, steps: int) -> dict:
    """One process of the scaling study: on a uniform grid of ``n`` nodes on [0, 10] at mu = 1, the
    influence matrix, one fixed-approach Newton solve at lambda = -2 from the rigid guess (a fresh
    factorization) and ``steps`` continuation steps from there; this rank's peak memory."""
    from ...core.continuation import Continuation
    from ...core.newton import Newton
    from ...tracing.trace import discretize

    comm = PETSc.COMM_WORLD
    model = Model(mu=1.0, rmax=10.0)
    settings = replace(read_settings(AppOptions()), max_steps=steps, observable_max=math.inf)
    comm.barrier()
    t0 = time.perf_counter()
    problem = discretize(model, grid.uniform(n, 10.0), create_pmat(kind))
    comm.barrier()
    t_build = time.perf_counter() - t0
    newton = Newton(problem)
    H = problem.rigid(-2.0, problem.create_vec())
    comm.barrier()
    t0 = time.perf_counter()
    ok = newton.solve(-2.0, H)
    comm.barrier()
    t_solve = time.perf_counter() - t0
    its = newton.iterations
    newton.destroy()
    cont = Continuation(problem, settings)
    start = cont.start(H, -2.0)
    comm.barrier()
    t0 = time.perf_counter()
    pts = cont.run(start)
    comm.barrier()
    t_steps = time.perf_counter() - t0
    mpi = comm.tompi4py()
    rss = mpi.gather(peak_rss_kib(), root=0)
    out = {"n": n, "pmat": kind, "ranks": comm.getSize(), "build_s": t_build, "solve_s": t_solve, "solve_ok": bool(ok),
           "newton_its": its[0], "ksp_its": its[1], "steps": len(pts) - 1,
           "step_s": t_steps / max(1, len(pts) - 1), "lambda_end": pts[-1].p,
           "rss_max_mib": None if rss is None else max(rss) / 1024, "rss_sum_mib": None if rss is None else sum(rss) / 1024}
    cont.destroy()
    H.destroy()
    problem.destroy()
    return out


def scaling(sizes=SCALE_N, quick: bool = False, log=print, budget_s: float = 450.0, ranks_list=(1, 2)) -> list[dict]:
    """:func:`scale_worker` for each N, pmat and rank count, each in its own process.
    A size whose predicted time (the last one's scaled by N^3 for dense, N^2 for band) exceeds what is
    left of ``budget_s`` for its (ranks, pmat) is skipped, and said so."""
    rows = []
    env = {**os.environ, **ENV}
    for ranks in ranks_list:
        for kind in ("dense", "band"):
            last, prev, left, power = None, None, budget_s, 3 if kind == "dense" else 2
            for n in sizes:
                if last is not None and last * (n / prev) ** power > left:
                    rows.append({"n": n, "pmat": kind, "ranks": ranks, "skipped": True})
                    log(f"[scaling] N = {n} {kind} {ranks} rank(s): skipped (predicted {last * (n / prev) ** power:.0f} s)")
                    continue
                cmd = [sys.executable, "-m", "petsc_adhesion.benchmarks.workprecision", "scale", str(n), kind,
                       str(2 if quick else SCALE_STEPS)]
                if ranks > 1:
                    cmd = ["mpiexec", "-n", str(ranks), *cmd]
                t0 = time.perf_counter()
                p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=1200)
                wall = time.perf_counter() - t0
                left -= wall
                if p.returncode:
                    rows.append({"n": n, "pmat": kind, "ranks": ranks, "failed": p.stderr.strip()[-300:]})
                    log(f"[scaling] N = {n} {kind} {ranks} rank(s): FAILED {p.stderr.strip()[-200:]}")
                    continue
                row = json.loads(p.stdout.strip().splitlines()[-1]) | {"process_s": wall}
                rows.append(row)
                last, prev = wall, n
                log(f"[scaling] N = {n} {kind} {ranks} rank(s): build {row['build_s']:.3g} s, solve {row['solve_s']:.3g} s,"
                    f" step {row['step_s']:.3g} s, {row['rss_max_mib']:.0f} MiB")
    return rows
