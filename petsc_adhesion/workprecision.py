"""Work-precision: the error of each result against the wall time it took, per method (issue 9, items 5-8).

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.bench -bench_only workprecision
    ./run bench -bench_workprecision          # after the default parts

writes docs/performance.md, and docs/figures/wp_<case>.png with wp_<case>.md (the
table behind each figure), in the manner of DiffEqDevTools' work-precision sets:
log10 error against log10 median wall time, one marked line per method.

* Cases (:data:`CASES`): mu = 1 smooth, mu = 2 with sigma = 0.2, mu = 5 smooth.
* Quantities (:data:`QUANTITIES`): the pull-off F and lambda (most tensile load),
  the primary turning points' lambda (snap-on: the fold of largest lambda, snap-off:
  of smallest), the equilibrium lambda (F = 0).
* Truth: the default grid (edge grid, r_m = 150, far field added) refined by
  ``-target_error`` :data:`TRUTH_TOL`, extrapolated; its own bars are reported.
* Methods: the paper grid (N = 531, r_m = 10, far-field load added; grid value and
  extrapolated), uniform grids on [0, 10] (N = 101 .. 4001, grid values), the
  default edge grid (grid value and extrapolated), ``-target_error`` 1e-3 .. 1e-8,
  the preconditioning choices on the edge grid (dense LU, band AIJ + LU, block
  Jacobi with 4 LU blocks through the solvers' option prefixes, none), a plain
  numpy/scipy implementation (:func:`numpy_curve`, mu = 1, paper grid) and the
  stored ContactMechanics + Adhesion runs (mu = 1, docs/data/peer_contactmechanics.json).
* Speed (item 7): the mu = 1 default curve with and without bars, the whole process,
  the pull-off to 1e-6 and 1e-8, against the issue's targets; where the curve's time
  goes (:func:`profile`: cProfile's own time of every function, summed by where it runs).
* Scaling (item 8): a fixed-approach solve and continuation steps on uniform grids
  N = 100 .. 8000, 1 and 2 ranks, dense and band, each in its own process
  (``python -m petsc_adhesion.workprecision scale N PMAT STEPS``), with its peak
  resident memory (getrusage ru_maxrss).

Times are medians of repeats (:data:`REPEATS`, one run where a single run exceeds
:data:`SLOW` seconds), each a fresh call of :func:`petsc_adhesion.study.trace`
(influence matrices and solvers made inside, as the program makes them).
"""
from __future__ import annotations

import compileall
import json
import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace

import numpy as np
import petsc4py

petsc4py.init(sys.argv)
from petsc4py import PETSc

from . import grid
from .adaptive import RMAX
from .influence import create_influence
from .model import Model
from .options import AppOptions, read_settings
from .preconditioning import REDUNDANT_MAX, create as create_pmat
from .problem import far_approach
from .singleton import OPENMPI_SINGLETON

__all__ = ["CASES", "QUANTITIES", "quantities", "numpy_curve", "contactmechanics_points", "observed_orders",
           "measure", "speed", "scaling", "write_docs", "run"]

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURES = os.path.join(ROOT, "docs", "figures")
PERFORMANCE = os.path.join(ROOT, "docs", "performance.md")
PEER = os.path.join(ROOT, "docs", "data", "peer_contactmechanics.json")
COMMAND = "OPENBLAS_NUM_THREADS=1 ./run bench -bench_only workprecision"

#: name -> (mu, sigma)
CASES = {"mu1": (1.0, 0.0), "mu2_rough": (2.0, 0.2), "mu5": (5.0, 0.0)}
#: the quantities of each diagram, in panel order
QUANTITIES = ("pull-off F", "pull-off lambda", "snap-on lambda", "snap-off lambda", "equilibrium lambda")
#: -target_error of the truth (bars about 3e-9 reached; levels stop at 4, 16 times the nodes)
TRUTH_TOL = 1e-9
TARGETS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
#: uniform grids on [0, 10]: elements 100 * 2^k, nested, so h halves exactly
UNIFORM = (101, 201, 401, 801, 1601)
#: the largest uniform grid per case: a curve costs about N^3 (a dense factorization every few steps), 2.3 s at
#: N = 801, mu = 1, so N = 4001 (about 5 minutes) only at mu = 1; mu = 2 rough and mu = 5 take 3 and 8 times longer
UNIFORM_TOP = {"mu1": 4001, "mu2_rough": 1601, "mu5": 801}
REPEATS = 3
#: a run longer than this (s) is not repeated
SLOW = 8.0
#: preconditioning choices: label -> (pmat kind, PETSc options on both correctors' prefixes)
PMATS = {"dense LU": ("dense", {}), "band AIJ + LU": ("band", {}),
         "block Jacobi (4 LU blocks)": ("band", {"pc_type": "bjacobi", "pc_bjacobi_blocks": "4",
                                                  "sub_pc_type": "lu"}),
         "none (GMRES on the operator)": ("shell", {})}
PREFIXES = ("nat_", "arc_")
#: scaling grids and steps
SCALE_N = (100, 200, 500, 1000, 2000, 4000, 8000)
SCALE_STEPS = 8
ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
       "OMPI_MCA_btl_vader_single_copy_mechanism": "none", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


# -- what a run found -----------------------------------------------------------------------------------
def quantities(res: dict, grid_values: bool = False) -> dict:
    """The quantities of a traced curve (:func:`petsc_adhesion.study.trace`): name -> (value, error bar or None).

    The snap-on is the fold of largest lambda, the snap-off the fold of smallest lambda (the
    primary pair; mu = 5 has a narrow secondary pair between them).  ``grid_values``: the
    finest single grid's values (``lambda_grid``, ``F_grid``) instead of the best ones.
    """
    def pick(e, key):
        g = e.get(f"{key}_grid") if grid_values else None
        return (e[key] if g is None else g), (None if grid_values else e.get(f"{key}_err"))

    out = {}
    po = res.get("pull_off")
    if po:
        out["pull-off F"], out["pull-off lambda"] = pick(po, "F"), pick(po, "lambda")
    ons = [e for e in res["events"] if e["kind"] == "snap_on"]
    offs = [e for e in res["events"] if e["kind"] == "snap_off"]
    eqs = [e for e in res["events"] if e["kind"] == "equilibrium"]
    if ons:
        out["snap-on lambda"] = pick(max(ons, key=lambda e: e["lambda"]), "lambda")
    if offs:
        out["snap-off lambda"] = pick(min(offs, key=lambda e: e["lambda"]), "lambda")
    if eqs:
        out["equilibrium lambda"] = pick(eqs[0], "lambda")
    out["folds"] = (len(ons) + len(offs), None)
    return out


# -- the plain numpy/scipy implementation ---------------------------------------------------------------
def numpy_curve(mu: float, r: np.ndarray, lam0: float, F_max: float = 2.0, ds_max: float = 0.1,
                tol: float = 1e-10) -> dict:
    """The mu, sigma = 0 load-approach curve on nodes ``r`` as a scientist would write it in numpy/scipy.

    The same discrete problem as ours (eq. 12, collocation with the package's influence matrix A,
    r_m = r[-1], the rigid sphere's attraction beyond r_m added to F) but none of our solver code:

        G(H, lambda) = H + lambda - r^2/2 - c A sigma_LJ(H + 1),   c = 32 mu^1.5 / (3 pi)   (eq. 12)
        F = (8/3) q . sigma_LJ(H + 1) + (8/3)(g_m^-8/8 - g_m^-2/2),  g_m = r_m^2/2 + 1 - lambda  (eq. 26)

    Pseudo-arclength continuation in (H, lambda) with the inner product <u, v> = mean(u v):
    tangent predictor, full Newton on the bordered system [[G_H, 1], [t_H^T / N, t_lambda]] with
    ``scipy.linalg.lu_factor`` every iteration; the step grows by 1.3 after an easy step (<= 3
    iterations) and halves after a failed one.  Folds are sign changes of lambdadot, the pull-off a
    sign change of dF/ds from - to +, the equilibrium a sign change of F; each is located by the
    secant method on the step length from the point before it.  Returns the events found and the
    wall time (the influence matrix included).
    """
    from scipy.linalg import lu_factor, lu_solve

    t0 = time.perf_counter()
    M = create_influence(r, PETSc.COMM_SELF)
    A = M.getDenseArray().copy()
    M.destroy()
    N, c, shape = r.size, 32.0 * mu**1.5 / (3.0 * math.pi), 0.5 * r * r
    q = np.zeros(N)                                   # q . P = integral P r dr for piecewise-linear P
    a, b = r[:-1], r[1:]
    np.add.at(q, np.arange(N - 1), (b - a) * (2 * a + b) / 6)
    np.add.at(q, np.arange(1, N), (b - a) * (a + 2 * b) / 6)
    q *= 8.0 / 3.0

    def lj(H):
        g = H + 1.0
        return g**-9 - g**-3, 3 * g**-4 - 9 * g**-10

    def far(lam):                                     # the load beyond r_m and its d/dlambda
        g = 0.5 * r[-1]**2 + 1.0 - lam
        return (8 / 3) * (g**-8 / 8 - g**-2 / 2), (8 / 3) * (g**-9 - g**-3)

    def bordered(H, lam, t):
        _, dP = lj(H)
        K = np.empty((N + 1, N + 1))
        np.multiply(A, -c * dP, out=K[:N, :N])
        K[np.arange(N), np.arange(N)] += 1.0
        K[:N, N], K[N, :N], K[N, N] = 1.0, t[:N] / N, t[N]
        return K

    def tangent(H, lam, t):                           # [[G_H, 1], [t^T]] z = e_N, normalised
        z = np.linalg.solve(bordered(H, lam, t), np.r_[np.zeros(N), 1.0])
        return z / math.sqrt(z[:N] @ z[:N] / N + z[N]**2)

    def correct(X, t, ds):                            # Newton on G = 0, <X - X0, t> = ds
        Y = X + ds * t
        for its in range(1, 9):
            if np.any(Y[:N] <= -0.95) or not np.all(np.isfinite(Y)):
                return None
            P, _ = lj(Y[:N])
            R = np.r_[Y[:N] + Y[N] - shape - c * A @ P, (Y - X)[:N] @ t[:N] / N + (Y - X)[N] * t[N] - ds]
            dY = lu_solve(lu_factor(bordered(Y[:N], Y[N], t)), R)
            Y = Y - dY
            if np.max(np.abs(dY)) < tol:
                T = tangent(Y[:N], Y[N], t)
                return Y, T, its
        return None

    def observe(Y, T):                                # lambdadot, F, dF/ds
        P, dP = lj(Y[:N])
        Fb, dFb = far(Y[N])
        return {"fold": T[N], "F": q @ P + Fb, "dF": q @ (dP * T[:N]) + dFb * T[N]}

    def locate(X, t, ds, key):                        # secant on the step length: observe(...)[key] = 0
        s0, f0, s1 = 0.0, observe(X, t)[key], ds
        for _ in range(30):
            Y, T, _ = correct(X, t, s1)
            f1 = observe(Y, T)[key]
            if abs(s1 - s0) < 1e-13 * max(1.0, abs(s1)) or f1 == f0:
                break
            s0, f0, s1 = s1, f1, s1 - f1 * (s1 - s0) / (f1 - f0)
        return Y, T

    # the start: Newton at fixed lambda0 from the rigid gap, then the tangent towards larger lambda
    H = np.maximum(shape - lam0, 0.0)
    for _ in range(50):
        P, dP = lj(H)
        J = np.eye(N) - c * A * dP
        dH = np.linalg.solve(J, H + lam0 - shape - c * A @ P)
        H = H - dH
        if np.max(np.abs(dH)) < tol:
            break
    X = np.r_[H, lam0]
    t = tangent(H, lam0, np.r_[np.zeros(N), 1.0])
    ds, events, steps = 0.05, [], 0
    while steps < 5000:
        got = correct(X, t, ds)
        if got is None:
            ds *= 0.5
            if ds < 1e-8:
                raise RuntimeError(f"numpy reference: step too small at lambda = {X[N]:g}")
            continue
        Y, T, its = got
        steps += 1
        a_obs, b_obs = observe(X, t), observe(Y, T)
        for key, kind in (("fold", "fold"), ("dF", "F_min"), ("F", "equilibrium")):
            if a_obs[key] * b_obs[key] < 0 and (key != "dF" or a_obs[key] < 0):
                Z, TZ = locate(X, t, ds, key)
                if key == "fold":
                    kind = "snap_on" if a_obs["fold"] > 0 else "snap_off"
                events.append({"kind": kind, "lambda": float(Z[N]), "F": float(observe(Z, TZ)["F"])})
        X, t = Y, T
        if b_obs["F"] >= F_max:
            break
        ds = min(ds * 1.3, ds_max) if its <= 3 else ds
    mins = [e for e in events if e["kind"] == "F_min"]
    return {"events": events, "steps": steps, "wall_time_s": time.perf_counter() - t0,
            "pull_off": min(mins, key=lambda e: e["F"]) if mins else None}


# -- ContactMechanics' stored runs --------------------------------------------------------------------
def contactmechanics_points(path: str = PEER, mu: float = 1.0) -> list[dict]:
    """The stored ContactMechanics + Adhesion runs ("main" tag) at ``mu``: n, wall time and the
    quantities it yields (pull-off by parabolic refinement; the jumps as the midpoints of their
    lambda brackets, half their width as the location error; no equilibrium: its curves stop at
    lambda = 0.5)."""
    with open(path) as f:
        runs = json.load(f)["runs"]
    out = []
    for r in runs:
        if r["tag"] != "main" or r["mu"] != mu:
            continue
        q = {"pull-off F": (r["pulloff"]["F"], None), "pull-off lambda": (r["pulloff"]["lam"], None)}
        for key, name in (("jump_in", "snap-on lambda"), ("jump_out", "snap-off lambda")):
            if r.get(key):
                j = r[key]
                q[name] = (0.5 * (j["lam_lo"] + j["lam_hi"]), 0.5 * j["width"])
        out.append({"n": r["n"], "L": r["L"], "wall_time_s": r["wall_time_s"], "cpu_time_s": r["cpu_time_s"],
                    "values": q, "date": r["date"], "command": r["command"]})
    return sorted(out, key=lambda p: p["n"])


# -- measuring ------------------------------------------------------------------------------------------
def _set_options(opts: dict) -> None:
    db = PETSc.Options()
    for prefix in PREFIXES:
        for k, v in opts.items():
            db.setValue(f"{prefix}{k}", v)


def _clear_options(opts: dict) -> None:
    db = PETSc.Options()
    for prefix in PREFIXES:
        for k in opts:
            db.delValue(f"{prefix}{k}")


def timed(fn, repeats: int = REPEATS):
    """(times, last result) of calling ``fn`` ``repeats`` times; once when the first call exceeds SLOW s."""
    times, res = [], None
    for k in range(repeats):
        t0 = time.perf_counter()
        res = fn()
        times.append(time.perf_counter() - t0)
        if times[0] > SLOW:
            break
    return times, res


def _trace(model, r, kind="dense", errors=False, target_error=None, options=None):
    from .study import trace
    opts = options or {}
    _set_options(opts)
    try:
        return trace(model, r, create_pmat(kind), read_settings(AppOptions()), far_approach(model),
                     errors=errors, target_error=target_error)
    finally:
        _clear_options(opts)


def _record(method: str, times: list, values: dict, param=None, n=None, **extra) -> dict:
    return {"method": method, "param": param, "n_nodes": n, "times": times, "median_s": statistics.median(times),
            "values": {k: v for k, v in values.items()}, **extra}


def _nodes(res: dict) -> int:
    return int(max(res["grids"]["n_nodes"]))


def measure(case: str, quick: bool = False, log=print) -> dict:
    """Every method of one case: its records (times and values) and the truth."""
    mu, sigma = CASES[case]
    edge_model = Model(mu=mu, sigma=sigma, rmax=RMAX)
    box = Model(mu=mu, sigma=sigma, rmax=10.0)
    reps = 1 if quick else REPEATS
    recs = []

    t0 = time.perf_counter()
    truth_res = _trace(edge_model, None, errors=True, target_error=1e-5 if quick else TRUTH_TOL)
    truth = {"tol": 1e-5 if quick else TRUTH_TOL, "wall_time_s": time.perf_counter() - t0,
             "values": quantities(truth_res), "n_nodes": _nodes(truth_res), "warnings": truth_res["warnings"]}
    log(f"[{case}] truth {truth['wall_time_s']:.1f} s")

    def add(method, fn, grid_values, param=None, **extra):
        times, res = timed(fn, reps)
        recs.append(_record(method, times, quantities(res, grid_values), param, _nodes(res),
                            warned=bool(res["warnings"] or res.get("grid_warning")), **extra))
        log(f"[{case}] {method} {param if param is not None else ''}: {statistics.median(times):.3g} s")
        return res

    paper = grid.paper(10.0)
    add("paper grid", lambda: _trace(box, paper), True)
    add("paper grid, extrapolated", lambda: _trace(box, paper, errors=True), False)
    top = 801 if quick else UNIFORM_TOP[case]
    for n in [n for n in UNIFORM if n <= top] + ([top] if top not in UNIFORM else []):
        add("uniform grid, r_m = 10", lambda n=n: _trace(box, grid.uniform(n, 10.0)), True, n)
    add("edge grid (default), grid value", lambda: _trace(edge_model, None), True)
    add("edge grid (default), extrapolated", lambda: _trace(edge_model, None, errors=True), False)
    for tol in (TARGETS[:3] if quick else TARGETS):
        add("-target_error", lambda tol=tol: _trace(edge_model, None, errors=True, target_error=tol), False, tol)
    for label, (kind, opts) in PMATS.items():
        if quick and kind == "shell":
            continue
        add(f"pmat: {label}", lambda kind=kind, opts=opts: _trace(edge_model, None, kind, options=opts), True)
    if mu == 1.0 and sigma == 0.0:
        times, res = timed(lambda: numpy_curve(mu, paper, far_approach(box)), reps)
        recs.append(_record("numpy/scipy reference, paper grid", times, _numpy_values(res), None, paper.size,
                            steps=res["steps"]))
        log(f"[{case}] numpy reference: {statistics.median(times):.3g} s, {res['steps']} steps")
        for p in contactmechanics_points():
            recs.append(_record("ContactMechanics + Adhesion (stored)", [p["wall_time_s"]], p["values"], p["n"],
                                p["n"] ** 2, stored=True))
    return {"case": case, "mu": mu, "sigma": sigma, "truth": truth, "records": recs}


def _numpy_values(res: dict) -> dict:
    ev = res["events"]
    ons = [e for e in ev if e["kind"] == "snap_on"]
    offs = [e for e in ev if e["kind"] == "snap_off"]
    eqs = [e for e in ev if e["kind"] == "equilibrium"]
    out = {}
    if res["pull_off"]:
        out["pull-off F"], out["pull-off lambda"] = (res["pull_off"]["F"], None), (res["pull_off"]["lambda"], None)
    if ons:
        out["snap-on lambda"] = (max(e["lambda"] for e in ons), None)
    if offs:
        out["snap-off lambda"] = (min(e["lambda"] for e in offs), None)
    if eqs:
        out["equilibrium lambda"] = (eqs[0]["lambda"], None)
    out["folds"] = (len(ons) + len(offs), None)
    return out


def errors(record: dict, truth: dict) -> dict:
    """|value - truth| per quantity (None where the method did not find it or found another event structure)."""
    out = {}
    for q in QUANTITIES:
        v, t = record["values"].get(q), truth["values"].get(q)
        out[q] = None if v is None or t is None else abs(v[0] - t[0])
    return out


def observed_orders(recs: list[dict]) -> dict:
    """Observed orders of the uniform grids from successive doublings, log2 |X_h - X_h/2| / |X_h/2 - X_h/4|
    (independent of the truth and of the domain truncation): quantity -> [(N, p)]."""
    uni = sorted((r for r in recs if r["method"].startswith("uniform") and r["n_nodes"] in UNIFORM
                  and not r.get("warned")),           # a grid that does not resolve the case has no order
                 key=lambda r: r["n_nodes"])
    out = {}
    for q in QUANTITIES:
        xs = [(r["n_nodes"], r["values"].get(q, (None,))[0]) for r in uni]
        ps = []
        for (n0, a), (_, b), (n2, c) in zip(xs, xs[1:], xs[2:]):
            if None not in (a, b, c) and b != c and a != b:
                ps.append((n2, math.log2(abs(a - b) / abs(b - c))))
        out[q] = ps
    return out


def domain_part(recs: list[dict], truth: dict) -> dict:
    """The domain truncation of r_m = 10: the paper grid's extrapolated value minus the truth (the far
    field's load is added on r_m = 10; the deflection it causes inside r_m is not)."""
    rec = next(r for r in recs if r["method"] == "paper grid, extrapolated")
    if rec.get("warned"):
        return {}
    return {q: (rec["values"][q][0] - truth["values"][q][0]) if q in rec["values"] and q in truth["values"] else None
            for q in QUANTITIES}


# -- speed (item 7) -------------------------------------------------------------------------------------
def _user_env(singleton: bool = True) -> dict:
    """The environment of a timed process: a user's Python, which keeps its bytecode cache (a sandbox's
    PYTHONDONTWRITEBYTECODE would have every run compile petsc-adhesion's modules again, 40-60 ms here),
    with petsc-adhesion's Open MPI singleton defaults unless ``singleton`` is False.  The cache is written
    first, as by a user's first run."""
    compileall.compile_dir(os.path.dirname(__file__), quiet=1)
    env = {k: v for k, v in os.environ.items() if k not in OPENMPI_SINGLETON and k != "PYTHONDONTWRITEBYTECODE"}
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
    """Issue 9, item 7: the mu = 1 curve's continuation without and with bars, the whole process, the
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
    """Where the mu = 1 curve with bars spends its time (issue 9, item 7): one run under cProfile after a
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
           ("petsc_adhesion.options (every module a curve needs, PETSc initialised)",
            "import petsc_adhesion, petsc4py; petsc4py.init(); import petsc_adhesion.options, petsc_adhesion.study",
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


# -- scaling (item 8) ------------------------------------------------------------------------------------
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
    from .continuation import Continuation
    from .solver import Newton
    from .study import discretize

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
    """Issue 9, item 8: :func:`scale_worker` for each N, pmat and rank count, each in its own process.
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
                cmd = [sys.executable, "-m", "petsc_adhesion.workprecision", "scale", str(n), kind,
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


# -- the documents -------------------------------------------------------------------------------------
#: marker and line style per method (DiffEqDevTools: one marked line per method)
STYLE = {"paper grid": ("^", "C0"), "paper grid, extrapolated": ("v", "C0"), "uniform grid, r_m = 10": ("o", "C1"),
         "edge grid (default), grid value": ("D", "C2"), "edge grid (default), extrapolated": ("*", "C2"),
         "-target_error": ("s", "C3"), "pmat: dense LU": ("x", "C4"), "pmat: band AIJ + LU": ("+", "C4"),
         "pmat: block Jacobi (4 LU blocks)": ("1", "C4"), "pmat: none (GMRES on the operator)": ("2", "C4"),
         "numpy/scipy reference, paper grid": ("P", "C5"), "ContactMechanics + Adhesion (stored)": ("h", "C6")}
FLOOR = 1e-12


def _methods(recs):
    seen = []
    for r in recs:
        if r["method"] not in seen:
            seen.append(r["method"])
    return seen


def plot_case(data: dict, path: str) -> None:
    """The work-precision diagram of one case: one panel per quantity, log10 error against log10 median time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 9))
    truth, recs = data["truth"], data["records"]
    nf = truth["values"]["folds"][0]
    for ax, q in zip(axes.flat, QUANTITIES):
        for m in _methods(recs):
            rs = [r for r in recs if r["method"] == m]
            pts = [(r["median_s"], errors(r, truth)[q], r["values"].get("folds", (nf,))[0] not in (nf, None))
                   for r in rs]
            pts = [(t, max(e, FLOOR), wrong) for t, e, wrong in pts if e is not None]
            if not pts:
                continue
            marker, color = STYLE.get(m, ("o", "k"))
            x, y = np.log10([p[0] for p in pts]), np.log10([p[1] for p in pts])
            ax.plot(x, y, marker=marker, color=color, ls="-" if len(pts) > 1 else "none", ms=8, label=m)
            bad = [k for k, p in enumerate(pts) if p[2]]      # another event structure than the truth's: hollow
            if bad:
                ax.plot(x[bad], y[bad], marker=marker, ls="none", ms=8, mfc="white", mec=color)
        bar = truth["values"].get(q, (None, None))[1]
        if bar:
            ax.axhline(math.log10(bar), color="k", ls=":", lw=1, label="truth's own bar")
        ax.set_title(f"{q}" + (f" (truth {truth['values'][q][0]:.9f})" if q in truth["values"] else ""), fontsize=10)
        ax.set_xlabel("log10 median wall time (s)")
        ax.set_ylabel("log10 |error|")
        ax.grid(alpha=0.3)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    for ax in axes.flat[1:5]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    axes.flat[5].axis("off")
    axes.flat[5].legend(handles, labels, loc="center", fontsize=9)
    fig.suptitle(f"work-precision, mu = {data['mu']:g}, sigma = {data['sigma']:g} "
                 f"(truth: edge grid, -target_error {truth['tol']:g}, extrapolated)\n"
                 f"hollow: another number of turning points than the truth's; errors below 1e-12 drawn at 1e-12")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _e(x) -> str:
    return "-" if x is None else ("< 1e-12" if x < FLOOR else f"{x:.1e}")


def _t(s: float) -> str:
    return f"{s * 1e3:.0f} ms" if s < 1 else f"{s:.2f} s" if s < 100 else f"{s:.0f} s"


def table_case(data: dict) -> str:
    """The numbers behind one diagram: the truth, every method's errors and times, observed orders, domain part."""
    truth, recs = data["truth"], data["records"]
    lines = [f"Truth: edge grid (r_m = 150, far field added), `-target_error {truth['tol']:g}`, extrapolated; "
             f"up to {truth['n_nodes']} nodes; {_t(truth['wall_time_s'])} (one run)."
             + (f" It says: {'; '.join(truth['warnings'])}." if truth["warnings"] else ""), "",
             "| quantity | truth | its bar |", "|---|---|---|"]
    for q in QUANTITIES:
        if q in truth["values"]:
            v, b = truth["values"][q]
            lines.append(f"| {q} | {v:.10f} | {_e(b)} |")
    lines += ["", "| method | N or tol | nodes | median time | repeats | " + " | ".join(QUANTITIES) + " | folds |",
              "|---|---|---|---|---|" + "---|" * len(QUANTITIES) + "---|"]
    nfolds = truth["values"]["folds"][0]
    for r in recs:
        err = errors(r, truth)
        folds = r["values"].get("folds", (None,))[0]
        p = r["param"]
        p = "" if p is None else (f"{p:g}" if isinstance(p, float) else str(p))
        flag = ("" if folds in (None, nfolds) else " (truth: %d)" % nfolds) + (" warned" if r.get("warned") else "")
        lines.append(f"| {r['method']} | {p} | {r['n_nodes'] or ''} | {_t(r['median_s'])}"
                     f"{' (stored)' if r.get('stored') else ''} | {len(r['times'])} | "
                     + " | ".join(_e(err[q]) for q in QUANTITIES) + f" | {'-' if folds is None else folds}{flag} |")
    lines += ["", "Errors are |value - truth| (\"< 1e-12\": the same value as the truth's, where the method ran the "
              "same levels); `folds`: turning points found (the truth's number where it differs); `warned`: the run "
              "printed a warning (a grid that does not resolve the contact edge, or a target not reached).  Stored "
              "times are those of the peer's own runs."]
    orders = observed_orders(recs)
    lines += ["", "Observed orders of the uniform grids, log2 |X_h - X_h/2| / |X_h/2 - X_h/4| (independent of the truth):",
              "", "| N (finest of three) | " + " | ".join(QUANTITIES) + " |", "|---|" + "---|" * len(QUANTITIES)]
    ns = sorted({n for ps in orders.values() for n, _ in ps})
    for n in ns:
        cells = []
        for q in QUANTITIES:
            p = dict(orders[q]).get(n)
            cells.append("-" if p is None else f"{p:.2f}")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    dom = domain_part(recs, truth)
    if dom:
        lines += ["", "Domain truncation of r_m = 10 (far-field load added; the deflection it causes inside r_m is "
                  "not): paper grid extrapolated minus truth: "
                  + ", ".join(f"{q} {dom[q]:+.1e}" for q in QUANTITIES if dom[q] is not None)
                  + ".  This is the floor of the uniform and paper grids' lines."]
    else:
        lines += ["", "Domain truncation of r_m = 10: not measured here, the paper grid does not resolve this case "
                  "(it warns); uniform grids below N = 801 do not either, and give no orders."]
    return "\n".join(lines)


def _speed_table(rows: dict) -> str:
    lines = ["| quantity | median | min | max | repeats | target | met |", "|---|---|---|---|---|---|---|"]
    for r in rows.values():
        met = "-" if r["met"] is None else "yes" if r["met"] else "**no**"
        lines.append(f"| {r['quantity']} | {_t(r['median_s'])} | {_t(r['min_s'])} | {_t(r['max_s'])} | {r['repeats']} | "
                     f"{'-' if r['target_s'] is None else _t(r['target_s'])} | {met} |")
    return "\n".join(lines)


def _profile_lines(pr: dict, bars: dict) -> list[str]:
    """Where the curve's time goes, from :func:`profile`, against the curve-with-bars row ``bars``."""
    total = pr["total_s"]
    rows = [(k, v) for k, v in pr["own"].items() if v >= 0.01 * total]
    rest = total - sum(v for _, v in rows)
    table = "| where | own time | share |\n|---|---|---|\n" + "\n".join(
        f"| {k} | {_t(v)} | {100 * v / total:.0f}% |" for k, v in rows) + \
        f"\n| everything else (each below 1%) | {_t(rest)} | {100 * rest / total:.0f}% |"
    top, share = rows[0][0], rows[0][1] / total
    stages = "; ".join(f"{k} {_t(v)} ({100 * v / total:.0f}%)" for k, v in pr["stages"].items())
    return ["Where the curve's time goes: the mu = 1 curve with error bars once under cProfile "
            f"(`petsc_adhesion.workprecision.profile`, after a warm run; the profiler slows the Python side, so "
            f"the shares are the measurement): {_t(total)} in all, {pr['snes_solves']} SNES solves.  Own time of "
            f"every function, summed by where it runs:", "", table, "",
            f"Stages (cumulative, they nest): {stages}.  The largest single place is {top} with "
            f"{100 * share:.0f}% (under the profiler, which inflates the Python places); the curve with bars "
            f"({_t(bars['median_s'])}) is {100 * (bars['median_s'] / bars['target_s'] - 1):+.0f}% from its target "
            f"({_t(bars['target_s'])}).", ""]


def _startup_lines(data: dict) -> list[str]:
    """Where the whole-process second goes: the start-up floor, stage by stage, against the target."""
    st, sp = {r["stage"]: r for r in data["startup"]}, data["speed"]
    rows = data["startup"]
    head = f"| a fresh interpreter doing only this | fastest of {rows[0]['repeats']} | median |\n|---|---|---|\n"
    table = head + "\n".join(f"| {r['stage']} | {_t(r['min_s'])} | {_t(r['median_s'])} |" for r in rows)
    floor = rows[-1]["min_s"]
    numpy = st["numpy"]["min_s"]
    mpi_own = st["mpi4py (MPI_Init), Open MPI's own singleton start-up"]["min_s"]
    mpi_ours = st["mpi4py (MPI_Init), petsc-adhesion's singleton defaults"]["min_s"]
    petsc = st["petsc4py (MPI_Init, PetscInitialize)"]["min_s"]
    bars = sp["speed_curve_bars"]["median_s"]
    least = floor + bars
    verdict = (f"within the 1 s whole-process target by {_t(1.0 - least)} at best" if least <= 1.0 else
               f"the 1 s whole-process target is out of reach on this stack without cutting the curve itself "
               f"below {_t(max(1.0 - floor, 0.0))}")
    return ["Start-up, stage by stage (`python -c CODE`, `petsc_adhesion.workprecision.STARTUP`).  Every process "
            "here runs as a user's Python does, with its bytecode cache written: one that may not write it "
            "(`PYTHONDONTWRITEBYTECODE`, set in this machine's sandbox) compiles petsc-adhesion's 31 modules at "
            "every start (40-60 ms here).", "", table, "",
            f"Before any work a run pays {_t(floor)} to have its modules loaded and PETSc and MPI initialised (its "
            f"floor: the fastest runs; MPI_Init and PetscInitialize alone {_t(petsc - numpy)}); a run that writes "
            f"files adds h5py's import.  Open MPI's own singleton start-up (a runtime daemon forked, the UCX "
            f"network layer probed) would add {_t(mpi_own - mpi_ours)} to every run that is not launched by mpiexec: "
            f"petsc-adhesion asks such a process for the shared-memory layer and no daemon "
            f"(`petsc_adhesion/singleton.py`; a variable the user set wins).  With the curve and its bars "
            f"({_t(bars)}) that is {_t(least)} at the least: {verdict}.", ""]


def _scaling_table(rows: list) -> str:
    lines = ["| N | pmat | ranks | influence build | solve (fresh factorization) | Newton / KSP its | "
             "time per continuation step | peak RSS per rank (max / sum) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("skipped") or r.get("failed"):
            why = "skipped (predicted over the time budget)" if r.get("skipped") else f"failed: {r['failed'][-120:]}"
            lines.append(f"| {r['n']} | {r['pmat']} | {r['ranks']} | {why} | | | | |")
            continue
        lines.append(f"| {r['n']}{' (run separately)' if r.get('separate') else ''} | {r['pmat']} | {r['ranks']} | "
                     f"{_t(r['build_s'])} | {_t(r['solve_s'])} | "
                     f"{r['newton_its']} / {r['ksp_its']} | {_t(r['step_s'])} ({r['steps']} steps) | "
                     f"{r['rss_max_mib']:.0f} / {r['rss_sum_mib']:.0f} MiB |")
    return "\n".join(lines)


def _one_and_two(rows: list, kind: str, most: float = math.inf):
    """(N, one rank's row, two ranks' row) at the largest N up to ``most`` measured on both, or None."""
    got = {(r["n"], r["ranks"]): r for r in rows if r.get("pmat") == kind and "step_s" in r}
    both = [n for n, k in got if k == 1 and (n, 2) in got and n <= most]
    return (max(both), got[(max(both), 1)], got[(max(both), 2)]) if both else None


def _rank_statement(rows: list) -> str:
    """Two ranks against one at the largest N measured on both, per pmat, and where the whole LU is factored."""
    out = []
    for kind in ("dense", "band"):
        if pair := _one_and_two(rows, kind):
            n, a, b = pair
            out.append(f"{kind} at N = {n}: a step takes {_t(b['step_s'])} on two ranks against {_t(a['step_s'])} on "
                       f"one (speed-up {a['step_s'] / b['step_s']:.2f}), the influence matrix "
                       f"{_t(b['build_s'])} against {_t(a['build_s'])}, peak memory per rank "
                       f"{b['rss_max_mib']:.0f} MiB against {a['rss_max_mib']:.0f} MiB")
    if pair := _one_and_two(rows, "dense", REDUNDANT_MAX):
        n, a, b = pair
        out.append(f"up to N = {REDUNDANT_MAX}, where each rank factors the whole matrix, two ranks are no faster "
                   f"for one curve (dense at N = {n}: {_t(b['step_s'])} a step against {_t(a['step_s'])} on one "
                   f"rank): the price of a preconditioner that stays exact at the folds; a study spreads its "
                   f"cases over the ranks instead")
    return ("Two ranks (one a core): " + "; ".join(out) + ".") if out else ""


def crossover(rows: list) -> int | None:
    """The smallest N from which on band's solve and step (1 rank) are faster than dense's at every measured N,
    both measured (one run each: a few milliseconds' luck at N = 100 is no crossover)."""
    one = {(r["n"], r["pmat"]): r for r in rows if r.get("ranks") == 1 and "step_s" in r}
    both = sorted(n for n, k in one if k == "dense" and (n, "band") in one)
    cost = {n: {k: one[(n, k)]["step_s"] + one[(n, k)]["solve_s"] for k in ("dense", "band")} for n in both}
    wins = [cost[n]["band"] < cost[n]["dense"] for n in both]
    return next((n for i, n in enumerate(both) if all(wins[i:])), None)


def machine() -> dict:
    """What the numbers were measured on."""
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    mem = next((int(ln.split()[1]) // 1024 for ln in open("/proc/meminfo") if ln.startswith("MemTotal")), 0)
    import scipy
    return {"cpu": cpu, "cores": os.cpu_count(), "memory_mib": mem, "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__, "petsc": "%d.%d.%d" % PETSc.Sys.getVersion(),
            "petsc4py": petsc4py.__version__, "platform": platform.platform(),
            "openblas_num_threads": os.environ.get("OPENBLAS_NUM_THREADS", "unset")}


#: what a user of ours would run for a given accuracy (a coarse uniform grid can be right by luck)
USER_METHODS = ("edge grid (default), grid value", "edge grid (default), extrapolated", "-target_error")


def _best_within(recs, truth, q, err, exclude=()):
    """Our fastest default-grid record (:data:`USER_METHODS`) whose error in ``q`` is at most ``err``:
    (record, its error) or None."""
    ok = [(r, errors(r, truth)[q]) for r in recs if r["method"] in USER_METHODS]
    ok = [(r, e) for r, e in ok if e is not None and e <= err]
    return min(ok, key=lambda re: re[0]["median_s"]) if ok else None


def compare_peers(data: dict) -> str:
    """Text and table: the numpy reference and ContactMechanics against ours at mu = 1."""
    truth, recs = data["truth"], data["records"]
    npy = next(r for r in recs if r["method"].startswith("numpy"))
    ours = next(r for r in recs if r["method"] == "paper grid")
    lines = ["| quantity | numpy/scipy, paper grid | ours, paper grid | difference |", "|---|---|---|---|"]
    for q in QUANTITIES:
        a, b = npy["values"].get(q, (None,))[0], ours["values"].get(q, (None,))[0]
        if a is not None and b is not None:
            lines.append(f"| {q} | {a:.12f} | {b:.12f} | {abs(a - b):.1e} |")
    lines += ["", f"Time on the paper grid (N = 531, the same discrete problem, influence matrix included): numpy/scipy "
              f"{_t(npy['median_s'])} ({npy.get('steps')} steps), ours {_t(ours['median_s'])}: ratio "
              f"{npy['median_s'] / ours['median_s']:.1f} (medians of this run).  At equal accuracy (our fastest "
              f"method whose error is at most the numpy code's, against the truth):", "",
              "| quantity | numpy/scipy error | ours at that accuracy | our time | time ratio |", "|---|---|---|---|---|"]
    enp = errors(npy, truth)
    for q in QUANTITIES:
        best = _best_within(recs, truth, q, enp[q], exclude=("ContactMechanics", "numpy")) if enp[q] is not None else None
        if best:
            r, e = best
            p = "" if r["param"] is None else f" {r['param']:g}" if isinstance(r["param"], float) else f" {r['param']}"
            lines.append(f"| {q} | {_e(enp[q])} | {r['method']}{p} ({_e(e)}) | {_t(r['median_s'])} | "
                         f"{npy['median_s'] / r['median_s']:.1f} |")
    lines += [""]
    cm = [r for r in recs if r.get("stored")]
    lines += ["ContactMechanics + Adhesion (stored runs; FFT half-space on [-7.5, 7.5]^2, L-BFGS-B in displacement "
              "control, wall time as stored) against the truth, and our fastest run on the default grid (grid value, "
              "extrapolated, or -target_error) at least as accurate:", "",
              "| n (pixels per side) | stored wall time | quantity | its error | ours at that accuracy | our time | time ratio |",
              "|---|---|---|---|---|---|---|"]
    for r in cm:
        err = errors(r, truth)
        for q in QUANTITIES:
            if err[q] is None:
                continue
            best = _best_within(recs, truth, q, err[q])
            who = "-" if best is None else f"{best[0]['method']}{'' if best[0]['param'] is None else ' ' + format(best[0]['param'], 'g') if isinstance(best[0]['param'], float) else ' ' + str(best[0]['param'])} ({_e(best[1])})"
            lines.append(f"| {r['param']} | {_t(r['median_s'])} | {q} | {_e(err[q])} | {who} | "
                         f"{'-' if best is None else _t(best[0]['median_s'])} | "
                         f"{'-' if best is None else format(r['median_s'] / best[0]['median_s'], '.0f')} |")
    return "\n".join(lines)


CASE_TITLES = {"mu1": "mu = 1, smooth", "mu2_rough": "mu = 2, sigma = 0.2 (Gauss-Hermite roughness)",
               "mu5": "mu = 5, smooth (stiff: a secondary fold pair)"}


def _losses(data: dict) -> list[str]:
    """Statements where a method of ours is slower or less accurate than another, from the numbers."""
    out = []
    for case in data["cases"]:
        truth, recs = case["truth"], case["records"]
        t = CASE_TITLES[case["case"]]
        edge = next(r for r in recs if r["method"] == "edge grid (default), grid value")
        for r in recs:
            if r["method"].startswith("pmat:") and r["method"] != "pmat: dense LU":
                d = next(x for x in recs if x["method"] == "pmat: dense LU")
                if r["median_s"] > 1.1 * d["median_s"]:
                    out.append(f"{t}: {r['method'][6:]} takes {r['median_s'] / d['median_s']:.1f} times the time of "
                               f"dense LU on the edge grid ({_t(r['median_s'])} against {_t(d['median_s'])}).")
        paper = next(r for r in recs if r["method"] == "paper grid")
        if paper["median_s"] < edge["median_s"]:
            out.append(f"{t}: the paper grid is faster than the default edge grid ({_t(paper['median_s'])} against "
                       f"{_t(edge['median_s'])}), but its errors are those of r_m = 10 (table).")
        nf = truth["values"]["folds"][0]
        wrong = {}                            # a wrong event structure: message -> the runs that have it
        for r in recs:
            if r.get("stored"):
                continue
            got = r["values"].get("folds", (nf,))[0]
            missing = [q for q in QUANTITIES if q in truth["values"] and q not in r["values"]]
            parts = ([f"{got} turning points where the truth has {nf}"] if got not in (nf, None) else []) + \
                ([f"no {', '.join(missing)}"] if missing else [])
            if parts:
                msg = " and ".join(parts) + (" (each run printed a warning)" if r.get("warned") else " without a warning")
                wrong.setdefault(msg, []).append(r["method"] + ("" if r["param"] is None else f" {r['param']:g}"
                                                                if isinstance(r["param"], float) else f" {r['param']}"))
        for msg, who in wrong.items():
            out.append(f"{t}: {'; '.join(who)}: {msg}.")
        grid_v = next(r for r in recs if r["method"] == "edge grid (default), grid value")
        extra = next(r for r in recs if r["method"] == "edge grid (default), extrapolated")
        eg, ex = errors(grid_v, truth), errors(extra, truth)
        worse = [f"{q} ({ex[q]:.1e} against {eg[q]:.1e})" for q in QUANTITIES
                 if ex[q] is not None and eg[q] is not None and ex[q] > 1.5 * eg[q]]
        if worse:
            out.append(f"{t}: the default extrapolated value is further from the truth than the grid value it "
                       f"corrects for {', '.join(worse)}: the coarse levels -2 and -1 are not yet in the asymptotic "
                       f"range.")
        for r in recs:                        # bars that did not cover their error against the truth
            if r.get("stored"):
                continue
            err = errors(r, truth)
            for q in QUANTITIES:
                bar = r["values"].get(q, (None, None))[1]
                if bar is not None and err[q] is not None and err[q] > bar:
                    tb = truth["values"][q][1] or 0.0
                    out.append(f"{t}: the bar of {q} from {r['method']}"
                               f"{'' if r['param'] is None else ' ' + format(r['param'], 'g')} ({bar:.1e}) is below "
                               f"its error against the truth ({err[q]:.1e}; the truth's own bar {tb:.1e}).")
        for r in (r for r in recs if r["method"] == "-target_error"):
            err = errors(r, truth)
            over = [f"{q} {e:.1e}" for q, e in err.items() if e is not None and e > r["param"]]
            if over:
                out.append(f"{t}: -target_error {r['param']:g} was not delivered: {', '.join(over)} against the "
                           f"truth (whose own bars are a few 1e-9).")
    npy = [r for c in data["cases"] for r in c["records"] if r["method"].startswith("numpy")]
    ours = [r for c in data["cases"] for r in c["records"] if r["method"] == "paper grid" and c["case"] == "mu1"]
    if npy and ours and npy[0]["median_s"] < ours[0]["median_s"]:
        out.append(f"mu = 1: the plain numpy/scipy code is faster than ours on the paper grid "
                   f"({_t(npy[0]['median_s'])} against {_t(ours[0]['median_s'])}).")
    for r in data["speed"].values():
        if r["met"] is False:
            out.append(f"Speed: {r['quantity']} took {_t(r['median_s'])}, the target is {_t(r['target_s'])}.")
    return out


def _summary(data: dict) -> list[str]:
    """Items 5 to 8 of issue 9 in one bullet each, from the numbers."""
    sp = data["speed"]
    mu1 = next(c for c in data["cases"] if c["case"] == "mu1")
    npy = next(r for r in mu1["records"] if r["method"].startswith("numpy"))
    paper = next(r for r in mu1["records"] if r["method"] == "paper grid")
    sc = data["scaling"]
    done8000 = [f"{r['pmat']} on {r['ranks']} rank(s)" for r in sc if r["n"] == 8000 and "step_s" in r]
    n_cross = crossover(sc)
    cm_t, cm_e, ours_t, ratios = [], [], [], []
    for r in (r for r in mu1["records"] if r.get("stored")):
        cm_t.append(r["median_s"])
        for q, e in errors(r, mu1["truth"]).items():
            best = _best_within(mu1["records"], mu1["truth"], q, e) if e is not None else None
            if e is not None:
                cm_e.append(e)
            if best:
                ours_t.append(best[0]["median_s"])
                ratios.append(r["median_s"] / best[0]["median_s"])
    met = [f"{r['quantity']} {_t(r['median_s'])} (target {_t(r['target_s'])}: {'met' if r['met'] else 'missed'})"
           for r in sp.values()]
    return ["- Item 5, work-precision diagrams: mu = 1, mu = 2 with sigma = 0.2 and mu = 5, every method asked for; "
            "uniform grids reach N = 4001 at mu = 1 only (1601 and 801 in the other cases, for the time budget).",
            f"- Item 6, against what users would use instead: the numpy/scipy code agrees with ours on the paper grid "
            f"to 1e-10 and takes {npy['median_s'] / paper['median_s']:.1f} times our time there; ContactMechanics + "
            f"Adhesion (stored) takes {_t(min(cm_t))} to {_t(max(cm_t))} per curve for errors of {min(cm_e):.0e} to "
            f"{max(cm_e):.0e}, which our default grid matches in {_t(min(ours_t))} to {_t(max(ours_t))} (time ratios "
            f"{min(ratios):.0f} to {max(ratios):.0f} at equal accuracy), and it cannot locate the folds or follow "
            f"the unstable branch.",
            "- Item 7, speed: " + "; ".join(met) + ".",
            "- Item 8, scaling: N = 100 to 4000 on 1 and 2 ranks, dense and band"
            + (f"; N = 8000 measured for {', '.join(done8000)}" if done8000 else "; N = 8000 predicted over the time budget, not run")
            + (f"; the band preconditioner is faster from N = {n_cross} on one rank." if n_cross else ".")]


def render(data: dict) -> str:
    """docs/performance.md."""
    m = data["machine"]
    L = [f"<!-- made by: {COMMAND} (petsc_adhesion/workprecision.py); do not edit by hand -->",
         "# Performance: error against run time", "",
         "Issue 9, items 5 to 8: work-precision diagrams, the comparison with what users would use instead, "
         "speed and scaling.  Everything on this page (tables, figures, the statements with numbers) is written "
         "by one command,", "", "```sh", COMMAND, "```", "",
         f"(the opt-in part of `./run bench`; `./run bench -bench_workprecision` runs it after the default parts).  "
         f"This run: {data['date']}, {data['total_s'] / 60:.1f} minutes"
         + (", **quick mode** (fewer sizes and repeats)" if data.get("quick") else "") + ".", "",
         "## Summary against issue 9", "", *_summary(data), "",
         "## The machine", "",
         f"{m['cpu']}, {m['cores']} cores, {m['memory_mib'] / 1024:.0f} GiB; {m['platform']}; Python {m['python']}, "
         f"numpy {m['numpy']}, scipy {m['scipy']}, PETSc {m['petsc']} and petsc4py {m['petsc4py']} (Debian), "
         f"OPENBLAS_NUM_THREADS={m['openblas_num_threads']}.  Load average {data['load_before'][0]:.2f} before the "
         f"run and {data['load_after'][0]:.2f} after it (its last part runs two ranks on the two cores).  On this "
         "shared machine single timings vary by up to 40%, so every time is the median of repeated runs "
         f"({REPEATS}, one run where a single run took more than {SLOW:g} s), and comparisons are ratios of medians "
         "measured in the same run.", "",
         "## Work-precision diagrams", "",
         "In the manner of DiffEqDevTools' work-precision sets: log10 |error| against log10 median wall time, one "
         "marked line per method, one panel per quantity: the pull-off F and lambda (the most tensile load), the "
         "primary turning points' lambda (snap-on: the fold of largest lambda; snap-off: of smallest) and the "
         "equilibrium lambda (F = 0).  Each time is that of one call of `study.trace` (influence matrices, "
         "solvers, continuation and, where used, error bars; not the process start-up).", "",
         "- **Truth**: the default grid refined by `-target_error 1e-9`, extrapolated (levels up to 4, 16 times the "
         "nodes; 1e-9 itself is not reached, the bars it reaches are in each table, about 2e-9 to 7e-9, so errors "
         "below about 1e-8 are not resolved by this truth).  `-target_error 1e-8` reaches the same finest level as the "
         "truth for most events, so its errors against it are zero or nearly: they say only that both agree.  The model is the half-infinite one.",
         "- **paper grid**: N = 531 on r_m = 10 (`-grid_type paper -adh_rmax 10`, far-field load added, the "
         "default), its grid value and its extrapolated value with bars (`paper grid, extrapolated`).",
         "- **uniform grid, r_m = 10**: N = 101, 201, 401, 801, 1601 and 4001 at mu = 1; up to 1601 at mu = 2 "
         "rough and 801 at mu = 5 (a curve costs about N^2.7 here: 125 s at N = 4001, mu = 1; the other cases "
         "take 3 to 10 times longer at equal N, so larger grids there would exceed the benchmark's time budget), "
         "grid values; its error has two parts, "
         "discretization (order ~2, observed orders below) and the domain truncation of r_m = 10 (the far-field load "
         "is added, the deflection it causes inside r_m is not), stated under each table and the floor of the line.",
         "- **edge grid (default)**: grids following the contact edge, r_m = 150, its grid value (no bars) and the "
         "default extrapolated value with bars.",
         "- **-target_error**: 1e-3 to 1e-8 on the edge grid, extrapolated.",
         "- **pmat**: the preconditioning choices on the edge grid (no bars): `-adh_pmat dense` (LU, the default), "
         "`band` (AIJ of |i - j| <= 64, LU), block Jacobi with 4 LU blocks on the band matrix (through the solvers' "
         "prefixes: `-nat_pc_type bjacobi -nat_pc_bjacobi_blocks 4 -nat_sub_pc_type lu` and the same for `arc_`) and "
         "`shell` (no preconditioner: GMRES on the operator).  They solve the same discrete problem: their errors "
         "coincide, their times differ.",
         "- mu = 1 only: the **numpy/scipy reference** (`workprecision.numpy_curve`, below) on the paper grid, and "
         "the stored **ContactMechanics + Adhesion** runs (n = 64, 128, 256 pixels per side).", ""]
    for case in data["cases"]:
        name = f"wp_{case['case']}"
        L += [f"### {CASE_TITLES[case['case']]}", "", f"![work-precision {case['case']}](figures/{name}.png)", "",
              f"Table: [figures/{name}.md](figures/{name}.md), the same numbers:", "", table_case(case), ""]
    mu1 = next(c for c in data["cases"] if c["case"] == "mu1")
    L += ["## Against what users would use instead", "",
          "### (a) A plain numpy/scipy implementation", "",
          "`workprecision.numpy_curve` is what a scientist would write in a few dozen lines: the package's influence "
          "matrix as a dense numpy array, the Lennard-Jones law, Newton with `scipy.linalg.lu_factor` of the "
          "bordered Jacobian at every iteration, pseudo-arclength continuation with a tangent predictor and simple "
          "step control (grow by 1.3 after an easy step, halve after a failure), folds by a sign change of "
          "lambdadot, the pull-off by one of dF/ds, the equilibrium by one of F, each located by the secant method "
          "on the step length.  It is an independent implementation of the same discrete problem (mu = 1, paper "
          "grid), so the event values must agree to the solvers' tolerances, and they do "
          "(`tests/test_workprecision.py` checks it):", "", compare_peers(mu1), "",
          "What it cannot do that ours does: error bars and extrapolation, grids that follow the contact edge "
          "(on a uniform or paper grid its cost grows as N^3 per factorization, and at mu = 5 a uniform grid fine "
          "enough for the cohesive zone is in the thousands of nodes), roughness, more than one rank, a domain guard "
          "(it rejects a step that closes a gap instead of shortening it).", "",
          "### (b) ContactMechanics + Adhesion", "",
          "Not installed nor run here: its results are stored in `docs/data/peer_contactmechanics.json` with the "
          "commands that regenerate them (`petsc_adhesion/peer_contactmechanics.py`, own virtual environment, about "
          "45 minutes).  Its points are on the mu = 1 diagram with their stored wall times (same machine type, "
          "measured on another day under a similar load).  Its jumps are brackets of the displacement steps: the "
          "error of a fold's lambda is at least half the bracket, 7.8e-4 here.", "",
          "What it cannot do: follow the unstable branch (energy minimisation in displacement control jumps at the "
          "folds), so the turning points are known only to a bracket of the load step and the snap-on and snap-off "
          "loads are those of the last stable state before the jump; no equilibrium (its curves stop at lambda = "
          "0.5); no error estimate; its finite square [-7.5, 7.5]^2 leaves a deflection of about 2e-4 at the centre "
          "uncorrected (see the script's docstring).  What it does that we do not: full 2-D contact of arbitrary "
          "topographies.", "",
          "## Speed (issue 9, item 7)", "",
          "The mu = 1 curve on the default grid, one rank: continuation without and with error bars (in-process, "
          "time of `study.trace`; no bars: `wall_time_s`, its continuation alone), the whole process "
          "`python -m petsc_adhesion -adh_mu 1` (start-up, imports and output included), and the pull-off to 1e-6 "
          "and 1e-8 of the half-infinite model (`-target_error`, whole process).", "", _speed_table(data["speed"]), "",
          f"The whole process minus the in-process curve with bars (medians): "
          f"{_t(data['speed']['speed_process']['median_s'] - data['speed']['speed_curve_bars']['median_s'])} of "
          f"start-up (Python, numpy, petsc4py and MPI initialisation, imports, option checks) and output files.", ""]
    if "profile" in data:
        L += _profile_lines(data["profile"], data["speed"]["speed_curve_bars"])
    if "startup" in data:
        L += _startup_lines(data)
    sc = data["scaling"]
    n_cross = crossover(sc)
    L += ["## Scaling (issue 9, item 8)", "",
          f"Uniform grids on [0, 10] at mu = 1, each in its own process "
          f"(`python -m petsc_adhesion.workprecision scale N PMAT STEPS`, under `mpiexec -n 2` for two ranks): the "
          f"influence matrix, one Newton solve at lambda = -2 from the rigid guess (fresh factorization), then "
          f"{SCALE_STEPS} continuation steps from there towards the snap-on (the time per step includes rejected "
          f"steps and refactorizations), and the peak resident memory of each rank (VmHWM of /proc/self/status; "
          f"getrusage's ru_maxrss is carried across exec by Linux and reported the benchmark process's own peak).  One "
          f"run each.  On two ranks the preconditioner is the LU of the whole matrix on each rank (PCREDUNDANT) up to "
          f"N = {REDUNDANT_MAX}, and block Jacobi with one LU block per rank beyond (PETSc's dense LU is "
          f"sequential), which does more GMRES iterations than one rank's LU.  A size whose predicted time exceeds "
          f"100 s for its (ranks, pmat) is skipped by the command; rows marked \"run separately\" were measured "
          f"after the command by the same worker, `python -m petsc_adhesion.workprecision scale N PMAT "
          f"{SCALE_STEPS}`, and merged (`python -m petsc_adhesion.workprecision docs DUMP` re-renders this page "
          f"from a run's measurements).", "", _scaling_table(sc), "",
          ("The dense operator stops being the right choice for the preconditioner at about N = "
           f"{n_cross}: from there the band matrix's solve and step (1 rank) are faster." if n_cross else
           "In the measured range the band preconditioner never beat the dense one on one rank.")
          + "  That is mu = 1 on uniform grids; on the default edge grids (300 to 500 nodes) dense LU is the "
          "faster choice in every case of the diagrams, and at mu = 5 the band preconditioner's run stops without "
          "the equilibrium (tables above)."
          + "  The operator itself (the influence matrix, O(N^2) memory and work per product) stays dense in "
          "every variant; at N = 8000 it alone is 0.5 GiB per copy.  " + _rank_statement(sc), "",
          "## Where we lose", "",
          "Every case where one of our methods was slower than another, less accurate than it claimed, or found a "
          "different curve, as measured in this run:", ""]
    L += [f"- {s}" for s in _losses(data)] or ["- nowhere in this run."]
    L += [""]
    return "\n".join(L) + "\n"


def write_docs(data: dict) -> None:
    """docs/performance.md and docs/figures/wp_<case>.{png,md} from the measured ``data``."""
    os.makedirs(FIGURES, exist_ok=True)
    for case in data["cases"]:
        name = f"wp_{case['case']}"
        plot_case(case, os.path.join(FIGURES, f"{name}.png"))
        with open(os.path.join(FIGURES, f"{name}.md"), "w") as f:
            f.write(f"<!-- made by: {COMMAND} -->\n{table_case(case)}\n")
    with open(PERFORMANCE, "w") as f:
        f.write(render(data))


#: where :func:`run` keeps its measurements (``python -m petsc_adhesion.workprecision docs PATH`` re-renders)
DUMP = os.path.join(tempfile.gettempdir(), "petsc-adhesion-workprecision.json")


def run(quick: bool = False, write: bool = True, log=print, dump: str | None = DUMP) -> dict:
    """The whole work-precision benchmark; writes the documents (``write``) and returns the speed rows
    in the format of :func:`petsc_adhesion.bench.row`."""
    t0 = time.perf_counter()
    load0 = os.getloadavg()
    cases = [measure(c, quick, log) for c in CASES]
    rows = speed(quick, log)
    prof = profile(log)
    start = startup(1 if quick else REPEATS)
    scale = scaling((100, 200, 500) if quick else SCALE_N, quick, log)
    data = {"machine": machine(), "load_before": load0, "load_after": os.getloadavg(),
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "total_s": time.perf_counter() - t0,
            "quick": quick, "cases": cases, "speed": rows, "profile": prof, "startup": start, "scaling": scale}
    if dump:
        with open(dump, "w") as f:
            json.dump(data, f)
        log(f"[workprecision] measurements kept in {dump}")
    if write:
        write_docs(data)
    return rows


if __name__ == "__main__":
    if len(sys.argv) >= 5 and sys.argv[1] == "scale":
        res = scale_worker(int(sys.argv[2]), sys.argv[3], int(sys.argv[4]))
        if PETSc.COMM_WORLD.getRank() == 0:
            print(json.dumps(res), flush=True)
    elif len(sys.argv) >= 3 and sys.argv[1] == "docs":      # re-render the documents from a dump of run()
        with open(sys.argv[2]) as f:
            write_docs(json.load(f))
    elif len(sys.argv) >= 3 and sys.argv[1] == "profile":   # profile() measured again into a dump, re-rendered
        with open(sys.argv[2]) as f:
            kept = json.load(f)
        kept["profile"] = profile()
        with open(sys.argv[2], "w") as f:
            json.dump(kept, f)
        write_docs(kept)
    else:
        print(__doc__)
