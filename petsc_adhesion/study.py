"""The study driver: options -> model -> grid -> problem -> solve or continuation -> events
-> error estimates -> output.

A study is either one solve at a fixed approach (``-adh_lambda``) or the whole
load-approach curve by continuation (the default).  This module only reads
the options into objects and calls the modules named for each step, in that
order.
"""
from __future__ import annotations

import sys
import time

import petsc4py
from petsc4py import PETSc

from . import __version__, error_estimate, preconditioning, resolution, results
from .continuation import Continuation
from .events import EventFinder
from .influence import create_influence
from .model import scales
from .options import (TABLE, AppOptions, InputError, check_memory, check_unused, print_help, read_guess,
                      read_grid, read_model, read_physical, read_settings)
from .output import check_writable, write_curve, write_solve
from .problem import Problem
from .solver import Newton

__all__ = ["discretize", "trace", "fixed_solve", "main"]

_APP = ("adh_", "grid_", "cont_")


def _is_app(name: str) -> bool:
    return name.startswith(_APP) or name in TABLE


def discretize(model, r, pmat=None) -> Problem:
    """The problem on grid r: influence matrix (eq. 4, 12), pressure law, preconditioning matrix kind."""
    return Problem(model, r, create_influence(r, PETSc.COMM_WORLD), pmat)


def trace(problem: Problem, settings, lam0: float, at_lambda=(), tol: float | None = None,
          profiles: bool = False) -> dict:
    """The load-approach curve from lam0 with its events, landings, pull-off, resolution check and warnings."""
    t0 = time.perf_counter()
    cont = Continuation(problem, settings)
    finder = EventFinder(cont, results.curve_events(at_lambda), *([tol] if tol else []))
    guess = problem.rigid(lam0, problem.create_vec())
    try:
        start = cont.start(guess, lam0)
    except RuntimeError as e:
        raise RuntimeError(f"{e}; give -cont_lambda_start further apart") from None
    finally:
        guess.destroy()
    cont.run(start, on_step=finder)
    finder.jumps(problem.stable)
    wall = time.perf_counter() - t0
    res = results.curve(problem, cont, finder, profiles)
    edges = resolution.contact_edges(problem.r, res.pop("pressures"))
    res["grid_warning"] = resolution.check(problem.model, problem.r, edges, cont.folds)
    res["warnings"] = results.curve_warnings(problem, cont.points,
                                             None if res["grid_warning"] else res["pull_off"])
    res |= {"wall_time_s": wall, "lambda_start": lam0}
    cont.destroy()
    return res


def fixed_solve(problem: Problem, newton: Newton, lam: float, H: PETSc.Vec) -> dict:
    """One solve at approach ``lam`` from the guess in H: the state, its load and the solver's effort."""
    t0 = time.perf_counter()
    ok = newton.solve(lam, H)
    wall = time.perf_counter() - t0
    if not ok:
        raise RuntimeError(f"Newton did not converge at lambda = {lam:g} "
                           f"(reason {newton.snes.getConvergedReason()}); try -adh_guess or -snes_monitor")
    pressure, _ = problem.pressure(H)
    Hall = problem.gather(H.getArray(readonly=True))
    its, kits = newton.iterations
    return {"lambda": lam, "F": problem.load(H), "H0": float(Hall[0]), "H": Hall,
            "P": problem.gather(pressure), "snes_iterations": its, "ksp_iterations": kits, "wall_time_s": wall}


def _head(comm, opts: AppOptions, model, r) -> dict:
    """What every result file says about its run: versions, options, model, grid, SI scales."""
    phys = read_physical(opts)
    return {"program": "petsc-adhesion", "version": __version__,
            "petsc_version": "%d.%d.%d" % PETSc.Sys.getVersion(),
            "petsc4py_version": petsc4py.__version__, "mpi_ranks": comm.getSize(),
            "options": opts.db.getAll(),
            "model": {"mu": model.mu, "sigma": model.sigma, "rmax": model.rmax,
                      "roughness": model.roughness, "hermite_points": model.hermite_points},
            "grid": {"r": r}, **({"scales": scales(*phys)} if phys else {})}


def main() -> int:
    """The program: one study from the options database; 0 on success (errors raise)."""
    comm = PETSc.COMM_WORLD
    opts = AppOptions()
    helping = opts.db.hasName("help")
    if helping and comm.getRank() == 0:
        print_help(sys.stdout)
    model = read_model(opts)
    r = read_grid(opts, model)
    lam = opts.real("adh_lambda")
    out, summary, plot = opts.string("out"), opts.string("summary"), opts.string("plot")
    check_memory(r.size, opts.choice("adh_pmat"), lam is None, comm.getSize())
    if opts.string("adh_guess") is not None and lam is None:
        raise InputError("-adh_guess: only with -adh_lambda (the curve starts from the rigid state)")
    opts.read_all()
    check_unused(_is_app)
    for name, path in (("out", out), ("summary", summary), ("plot", plot)):
        check_writable(name, path)
    if plot and lam is not None:
        raise InputError("-plot: draws a curve; not with -adh_lambda")

    pmat = preconditioning.create(opts.choice("adh_pmat"), opts.int("adh_pmat_band"))
    problem = discretize(model, r, pmat)
    if lam is None:
        settings = read_settings(opts)
        lam0 = opts.real("cont_lambda_start")
        lam0 = problem.far_approach() if lam0 is None else lam0
        if helping:
            Continuation(problem, settings).destroy()       # its solvers print their options
            return 0
        at, tol, profiles = opts.reals("cont_at_lambda"), opts.real("cont_event_tol"), opts.flag("profiles")
        res = trace(problem, settings, lam0, at, tol, profiles)
        if opts.flag("cont_error_estimate"):
            coarse = discretize(model, error_estimate.coarsen(r), pmat)
            error_estimate.attach(res, trace(coarse, settings, lam0, at, tol), model.rmax)
            coarse.destroy()
    else:
        newton = Newton(problem, "", pc_reuse_its=opts.int("adh_pc_reuse_its"))
        if helping:
            return 0
        res = fixed_solve(problem, newton, lam, read_guess(problem, lam, opts.string("adh_guess")))
        newton.destroy()
    check_unused()                          # PETSc has read all of its options by now
    if comm.getRank() == 0:
        head = _head(comm, opts, model, r)
        if lam is None:
            results.report_curve(write_curve(res, head, out, summary, plot))
        else:
            write_solve(res, head, out, summary)
            results.report_solve(res)
    problem.destroy()
    PETSc.garbage_cleanup()
    return 0
