"""Benchmarks on one rank: the influence matrix, one Newton solve, the mu = 1 curve.

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks [-bench_repeats K] \\
        [-bench_only influence|solve|curve|stiff|fit|leaveout|workprecision] [-bench_json bench.json] [-bench_profile] [-log_view]

Each quantity is the median wall time of repeated runs (7, 3 at N = 4000 and 5
for the curve, or K each), shown with its min, max and number of repeats,
against its target where it has one.  The cores may be shared with other work:
the load average before the runs is printed with the table, and a benchmark is
a measurement, not a test.

* influence: ``create_influence(r)`` on the paper grid (N = 531) and on a
  uniform grid of N = 4000.
* solve: Newton at mu = 1, lambda = -2 on the paper grid, from the rigid guess
  (eq. 27), a fresh guess each repeat; the influence matrix and the SNES are
  built once, untimed.  The SNES keeps its preconditioner between solves by
  design (:class:`~petsc_adhesion.core.newton.PCReuse`); each repeat expires it,
  so every repeat assembles and factors it again.
* curve: :func:`~petsc_adhesion.app.run.trace` with the program's defaults
  (mu = 1, grids that follow the contact edge, error bars): the time of the
  call (its solvers made inside, as in the program), its steps, and a check
  that it found both turning points, the pull-off and the equilibrium; and the
  same curve on the paper grid (N = 531, r_m = 10), the grid it must not be slower than.
* stiff: the default curves at mu = 7 (target 10 s) and mu = 20 (target 60 s),
  error bars included, checked for their fold pairs, pull-off and equilibrium
  and for no warning (3 repeats each).
* fit: one fit of a force curve (:func:`~petsc_adhesion.fitting.curve_fit.fit_curve`, target 60 s)
  made by the forward solver at mu = 1 with 1% noise (300 points a leg, its
  making untimed), checked for w and E* inside their 95% intervals (3 repeats).

``-bench_profile`` profiles one more curve (cProfile, which slows the Python
side) and prints the ten functions of largest own time; ``-log_view`` gives PETSc's account of all runs.
The model and grids are fixed; other options reach the fixed-approach solve (``-snes_*``,
``-ksp_*``, read into its settings) and the continuation (``-cont_*``).
"""
from __future__ import annotations

import cProfile
import os
import pstats
import statistics
import sys
import time

import petsc4py

petsc4py.init(sys.argv)
from petsc4py import PETSc

from ..app.options.checks import check_unused
from ..app.options.reading import AppOptions, read_petsc, read_settings
from ..core.newton import Newton, PetscSettings
from ..discretization import grid
from ..discretization.influence import create_influence
from ..discretization.problem import Problem
from ..errors import InputError
from ..io.resultset import ResultSet, check_targets
from ..io.write import write_json
from ..model.parameters import Model
from ..tracing.edge_grids import RMAX
from ..tracing.trace import discretize
from ..version import __version__
from ._library import traced

__all__ = ["bench_influence", "bench_solve", "bench_curve", "profile_curve", "main", "PARTS", "STIFF", "row", "mu1_problem", "check_curve", "bench_stiff", "bench_fit", "report"]

#: -bench_only choices, in the order they run; the last two only when asked for: "leaveout" (about
#: 15 minutes, writes docs/figures/leaveout.md: petsc_adhesion/benchmarks/leaveout.py) with -bench_only leaveout,
#: "workprecision" (about 20 minutes, writes docs/performance.md: petsc_adhesion/benchmarks/workprecision)
#: with -bench_only workprecision or -bench_workprecision
PARTS = ("influence", "solve", "curve", "stiff", "fit", "leaveout", "workprecision")
#: Stiff curves: mu -> (target in s, turning points of the resolved curve; docs/stability.md).
STIFF = {7.0: (10.0, 4), 20.0: (60.0, 6)}


def row(quantity: str, times: list[float], target: float | None = None, **extra) -> dict:
    """Median, min and max of ``times`` (s) and whether the median meets ``target``."""
    med = statistics.median(times)
    return {"quantity": quantity, "median_s": med, "min_s": min(times), "max_s": max(times),
            "repeats": len(times), "target_s": target, "met": None if target is None else med <= target,
            **extra}


def bench_influence(repeats: int | None = None) -> dict:
    """Build time of the influence matrix of eq. (12) at N = 531 (target 0.3 s) and 4000."""
    out = {}
    for key, r, default, target in (("influence_531", grid.paper(10.0), 7, 0.3),
                                    ("influence_4000", grid.uniform(4000, 10.0), 3, None)):
        times = []
        for _ in range(repeats or default):
            t0 = time.perf_counter()
            A = create_influence(r)
            times.append(time.perf_counter() - t0)
            A.destroy()
        out[key] = row(f"influence build, N = {r.size}", times, target, n_nodes=r.size)
    return out


def mu1_problem() -> Problem:
    """The default study's Problem (mu = 1, paper grid, dense PC), as the program makes it."""
    return discretize(Model(mu=1.0), grid.paper(10.0))


def bench_solve(problem: Problem, repeats: int | None = None, lam: float = -2.0,
                settings: PetscSettings = PetscSettings()) -> dict:
    """One fixed-lambda Newton solve from the rigid guess (target 20 ms), refactoring each repeat; ``settings``:
    its PETSc settings."""
    newton = Newton(problem, settings=settings)
    H = problem.create_vec()
    times = []
    for _ in range(repeats or 7):
        problem.rigid(lam, H)
        newton.reuse.expire()
        t0 = time.perf_counter()
        ok = newton.solve(lam, H)
        times.append(time.perf_counter() - t0)
        if not ok:
            raise RuntimeError(f"Newton did not converge at lambda = {lam:g} "
                               f"(reason {newton.snes.getConvergedReason()})")
    its, kits = newton.iterations
    newton.destroy()
    H.destroy()
    return {"solve": row(f"solve, mu = {problem.model.mu:g}, lambda = {lam:g}, N = {problem.r.size}", times, 0.020,
                         snes_iterations=its, ksp_iterations=kits)}


def check_curve(res: dict) -> dict:
    """The curve's landmarks; RuntimeError unless both folds, the pull-off and F = 0 are found."""
    first = {}
    for e in res["events"]:
        first.setdefault(e["kind"], e)
    missing = [k for k in ("snap_on", "snap_off", "equilibrium") if k not in first]
    if missing or res["pull_off"] is None:
        raise RuntimeError(f"mu = 1 curve without {', '.join(missing) or 'pull-off'} "
                           f"({res['steps']} steps; stopped: {res['stop_reason']})")
    return {"steps": res["steps"], "rejected_steps": res["rejected_steps"],
            "pull_off_lambda": res["pull_off"]["lambda"], "pull_off_F": res["pull_off"]["F"],
            "snap_on_lambda": first["snap_on"]["lambda"], "snap_off_lambda": first["snap_off"]["lambda"],
            "equilibrium_lambda": first["equilibrium"]["lambda"]}


def _trace(mu: float = 1.0, nodes=None) -> dict:
    """The program's default curve at ``mu``: on grids that follow the contact edge (or on ``nodes``,
    r_m = 10), step control from the options (-cont_*), error bars."""
    model = Model(mu=mu, rmax=RMAX if nodes is None else 10.0)
    return traced(model, nodes, "dense", read_settings(AppOptions()))


def bench_curve(repeats: int | None = None) -> dict:
    """The whole default curve (target 1 s), each repeat with fresh grids and solvers (as the program makes them)."""
    times = []
    for _ in range(repeats or 5):
        t0 = time.perf_counter()
        res = _trace()
        times.append(time.perf_counter() - t0)
        marks = check_curve(res)
    paper = []
    for _ in range(repeats or 5):
        t0 = time.perf_counter()
        res = _trace(1.0, grid.paper(10.0))
        paper.append(time.perf_counter() - t0)
        check_curve(res)
    return {"curve": row("curve, mu = 1, edge grid", times, 1.0, **marks),
            "curve_paper": row("curve, mu = 1, paper grid", paper, None, steps=res["steps"])}


def bench_stiff(repeats: int | None = None) -> dict:
    """The default curves at mu = 7 and 20 (:data:`STIFF`), each repeat with fresh grids and solvers."""
    out = {}
    for mu, (target, folds) in STIFF.items():
        times = []
        for _ in range(repeats or 3):
            t0 = time.perf_counter()
            res = _trace(mu)
            times.append(time.perf_counter() - t0)
            got = sum(e["kind"] in ("snap_on", "snap_off") for e in res["events"])
            if got != folds or res["pull_off"] is None or res["warnings"] or \
                    not any(e["kind"] == "equilibrium" for e in res["events"]):
                raise RuntimeError(f"mu = {mu:g} curve with {got} turning points (expected {folds}), "
                                   f"warnings: {'; '.join(res['warnings']) or 'none'}")
        out[f"curve_mu{mu:g}"] = row(f"curve, mu = {mu:g}, edge grid", times, target, steps=res["steps"],
                                     n_nodes=int(max(res["grids"]["n_nodes"])), turning_points=got,
                                     pull_off_F=res["pull_off"]["F"], pull_off_F_err=res["pull_off"].get("F_err"))
    return out


def bench_fit(repeats: int | None = None) -> dict:
    """One fit of a synthetic force curve at mu = 1 (target 60 s on one core; docs/fitting.md)."""
    import math

    from ..fitting.curve_fit import fit_curve
    from ..fitting.results import Spring
    from ..fitting.synthetic import Sampling, synthetic_curve
    from ..model.physical import Bodies

    R, eps, k, w, mu = 20e-9, 0.3e-9, 1.0, 0.05, 1.0
    E = w * math.sqrt(R / (mu**3 * eps**3))
    data = synthetic_curve(Bodies(radius=R, young1=E, poisson1=0.0, epsilon=eps, gamma=w), Spring(k),
                           Sampling(noise=0.01 * 2 * math.pi * R * w, points=300, z0=5e-9, seed=1))
    times = []
    for _ in range(repeats or 3):
        t0 = time.perf_counter()
        f = fit_curve(data, Bodies(radius=R, young1=None, poisson1=None, epsilon=eps), Spring(k))
        times.append(time.perf_counter() - t0)
        if not (f.trustworthy and f.gamma.covers(w, 1.96) and f.E_star.covers(E, 1.96)):
            raise RuntimeError(f"fit of the mu = 1 curve: w = {f.gamma} (true {w:g}), E* = {f.E_star} (true "
                               f"{E:.5g}); {'; '.join(f.warnings)}")
    return {"fit": row("fit of a force curve, mu = 1", times, 60.0, traces=f.traces, evaluations=f.iterations,
                       gamma=f.gamma.value, gamma_err=f.gamma.err, E_star=f.E_star.value, E_star_err=f.E_star.err)}


def _where(key: tuple) -> str:
    path, line, name = key
    if path == "~":
        return name
    return f"{os.path.join(*path.split(os.sep)[-2:])}:{line}({name})"


def profile_curve(top: int = 10) -> dict:
    """Profiled time of one traced curve and its ``top`` functions by own time (cProfile's tottime)."""
    prof = cProfile.Profile()
    check_curve(prof.runcall(_trace))
    st = pstats.Stats(prof)
    best = sorted(st.stats.items(), key=lambda kv: kv[1][2], reverse=True)[:top]
    return {"total_s": st.total_tt,
            "top": [{"function": _where(k), "calls": nc, "tottime_s": tt, "cumtime_s": ct, "share": tt / st.total_tt}
                    for k, (_, nc, tt, ct, _) in best]}


def _t(s: float | None) -> str:
    if s is None:
        return "-"
    return f"{s * 1e3:.3g} ms" if s < 1 else f"{s:.3g} s"


def report(info: dict, results: dict, profile: dict | None) -> None:
    """The benchmark table on stdout."""
    print(f"petsc-adhesion {info['version']} bench: PETSc {info['petsc_version']}, 1 rank, "
          f"OPENBLAS_NUM_THREADS={info['openblas_num_threads']}, "
          f"load average {info['load_average']:.2f} on {info['cpu_count']} cores before the runs")
    print(f"{'quantity':<38}{'median':>10}{'min':>10}{'max':>10}{'repeats':>9}{'target':>10}  met")
    for q in results.values():
        met = "-" if q["met"] is None else "yes" if q["met"] else "NO"
        print(f"{q['quantity']:<38}{_t(q['median_s']):>10}{_t(q['min_s']):>10}{_t(q['max_s']):>10}"
              f"{q['repeats']:>9}{_t(q['target_s']):>10}  {met}")
    if "solve" in results:
        s = results["solve"]
        print(f"solve: Newton {s['snes_iterations']}, KSP {s['ksp_iterations']}; "
              "preconditioner expired before each repeat (assembled and factored every time)")
    if "curve" in results:
        c = results["curve"]
        print(f"curve: {c['steps']} steps ({c['rejected_steps']} rejected); "
              f"snap-on lambda = {c['snap_on_lambda']:.6f}, snap-off lambda = {c['snap_off_lambda']:.6f}, "
              f"pull-off F = {c['pull_off_F']:.6f} at lambda = {c['pull_off_lambda']:.6f}, "
              f"equilibrium lambda = {c['equilibrium_lambda']:.6f}")
        p = results["curve_paper"]
        print(f"curve: the edge grid takes {c['median_s'] / p['median_s']:.2f} times the paper grid's time "
              f"(medians of this run; {p['steps']} steps on the paper grid)")
    if "fit" in results:
        q = results["fit"]
        print(f"fit: {q['traces']} curves traced, {q['evaluations']} evaluations; w = {q['gamma']:.6g} +- "
              f"{q['gamma_err']:.2g} J/m^2 (true 0.05), E* = {q['E_star']:.6g} +- {q['E_star_err']:.2g} Pa")
    for key, q in results.items():
        if key.startswith("curve_mu"):
            print(f"{q['quantity']}: {q['steps']} steps, {q['turning_points']} turning points, up to "
                  f"{q['n_nodes']} nodes, pull-off F = {q['pull_off_F']:.6f} +- {q['pull_off_F_err']:.1e}")
    if profile:
        print(f"curve profile (cProfile, one run, {_t(profile['total_s'])} in all; "
              f"top {len(profile['top'])} by own time):")
        print(f"{'own':>10}{'share':>7}{'cumul.':>10}{'calls':>8}  function")
        for p in profile["top"]:
            print(f"{_t(p['tottime_s']):>10}{p['share']:>7.1%}{_t(p['cumtime_s']):>10}{p['calls']:>8}  {p['function']}")


def main() -> int:
    """The benchmark program (options -bench_*); 0 on success."""
    opts = PETSc.Options("bench_")
    repeats = opts.getInt("repeats", 0)         # 0: each quantity's own number
    only = opts.getString("only", "")
    path = opts.getString("json", "")
    profile = opts.getBool("profile", False)
    workprecision = opts.getBool("workprecision", False)
    check_unused(lambda name: name.startswith("bench_"))
    if opts.hasName("repeats") and repeats < 1:
        raise InputError(f"-bench_repeats: expected an integer >= 1, got {repeats}")
    if only and only not in PARTS:
        raise InputError(f"-bench_only: expected one of {', '.join(PARTS)}, got '{only}'")
    if PETSc.COMM_WORLD.getSize() > 1:
        raise InputError("the benchmark runs on one rank")
    if path:
        check_targets({"bench_json": path})
    load = os.getloadavg()[0]

    parts = (only,) if only else PARTS[:-2] + (PARTS[-1:] if workprecision else ())
    results = bench_influence(repeats) if "influence" in parts else {}
    if "solve" in parts:
        results |= bench_solve(mu1_problem(), repeats, settings=read_petsc(AppOptions(), ""))
    if "curve" in parts:
        results |= bench_curve(repeats)
    if "stiff" in parts:
        results |= bench_stiff(repeats)
    if "fit" in parts:
        results |= bench_fit(repeats)
    if "leaveout" in parts:
        from ..benchmarks import leaveout
        leaveout.run()                       # its table is docs/figures/leaveout.md
    if "workprecision" in parts:
        from ..benchmarks import workprecision
        results |= workprecision.run()
    top = profile_curve() if profile else None
    info = {"program": "petsc-adhesion bench", "version": __version__,
            "petsc_version": "%d.%d.%d" % PETSc.Sys.getVersion(), "mpi_ranks": 1,
            "openblas_num_threads": os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
            "load_average": load, "cpu_count": os.cpu_count()}
    report(info, results, top)
    if path:
        files = ResultSet({"bench_json": path})
        write_json(files.temp("bench_json"), {**info, "results": results, **({"curve_profile": top} if top else {})})
        files.commit()
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except InputError as e:
        print(f"petsc-adhesion bench: error: {e}", file=sys.stderr)
        sys.exit(2)
    except RuntimeError as e:
        print(f"petsc-adhesion bench: FAILED: {e}", file=sys.stderr)
        sys.exit(1)
