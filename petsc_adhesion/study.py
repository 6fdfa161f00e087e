"""The study driver: options -> model -> grid -> problem -> solve or continuation -> events
-> error estimates -> output.

A study is either one solve at a fixed approach (``-adh_lambda``) or the whole
load-approach curve by continuation (the default).  This module only reads
the options into objects, checks them (on every rank, agreed before any
work), and calls the modules named for each step, in that order.
"""
from __future__ import annotations

import sys
import time
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np
import petsc4py
from petsc4py import PETSc

from . import __version__, error_estimate, preconditioning, resolution, results
from .adaptive import Tracer, grid_for
from .checkpoint import open_checkpoint
from .continuation import Continuation, Settings
from .events import jumps
from .errors import Interrupted
from .files import PLOT_FORMATS, check_targets, mark_done, printable, written
from .influence import create_influence
from .model import Model
from .optionsfile import options_files
from .options import (TABLE, AppOptions, InputError, check_consistency, check_memory, check_petsc_values,
                      check_unused, collective, print_help, read_grid, read_guess, read_model, read_physical,
                      read_settings)
from .output import write_curve, write_solve
from .pressure import pressure_law
from .problem import Problem, far_approach
from .progress import Progress, curve_end, curve_status
from .solver import Newton

__all__ = ["Plan", "plan", "discretize", "trace", "curve", "fixed_solve", "program", "head", "main"]

_APP = ("adh_", "grid_", "cont_")
_OUTPUTS = ("out", "summary", "plot")


def _is_sweep(opts: AppOptions) -> bool:
    """Whether the options describe a study of many cases (:mod:`petsc_adhesion.sweep`)."""
    return any(opts.db.hasName(n) for n in ("study_mu", "study_sigma", "study_option")) or \
        opts.choice("study_compute") == "critical"


def _is_app(name: str) -> bool:
    return name.startswith(_APP) or name in TABLE


@dataclass
class Plan:
    """Everything a run needs from its options, checked."""

    model: Model
    r: object
    lam: float | None                 # fixed approach, or None for a curve
    settings: Settings
    targets: dict                     # option -> output path
    inputs: dict                      # option -> paths read


def plan(opts: AppOptions, comm, argv: list[str]) -> Plan:
    """Read and check every option before any work (PETSc's solver options too, as far as
    they can be judged before the solvers exist)."""
    model = read_model(opts)
    r = read_grid(opts, model)
    lam = opts.real("adh_lambda")
    if r is not None:
        check_memory(r.size, opts.choice("adh_pmat"), lam is None, comm.getSize())
    if opts.string("adh_guess") is not None and lam is None:
        raise InputError("-adh_guess: only with -adh_lambda (the curve starts from the rigid state)")
    opts.read_all()
    check_unused(_is_app)
    check_consistency(opts, model)
    check_petsc_values(opts.db)
    targets = {k: opts.string(k) for k in _OUTPUTS if opts.string(k)}
    if "plot" in targets and not targets["plot"].lower().endswith(tuple(PLOT_FORMATS)):
        raise InputError(f"-plot: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{targets['plot']}'")
    inputs = {"options_file": options_files(argv), "adh_guess": [opts.string("adh_guess") or ""],
              "adh_roughness_file": [opts.string("adh_roughness_file") or ""]}
    if comm.getRank() == 0:                  # only rank 0 writes
        check_targets(targets, inputs)
    return Plan(model, r, lam, read_settings(opts), targets, inputs)


def rigid_edge(lam: float) -> float:
    """The contact edge of the rigid sphere at approach lam: the peak attraction, gap 3^(1/6) epsilon."""
    return float(np.sqrt(2.0 * max(0.0, lam + 3.0 ** (1.0 / 6.0) - 1.0)))


def discretize(model, r, pmat=None) -> Problem:
    """The problem on grid r: influence matrix (eq. 4, 12), pressure law, preconditioning matrix kind."""
    return Problem(model, r, create_influence(r, PETSc.COMM_WORLD), pmat)


def trace(model, r, pmat, settings, lam0: float, at_lambda=(), tol: float | None = None,
          profiles: bool = False, started=None, errors: bool = True, target_error: float | None = None,
          kinds=None, comm=None, checkpoint=None, progress=None) -> dict:
    """The load-approach curve from lam0 on grid ``r`` (None: grids following the contact edge), with
    its events, landings, pull-off, error bars (``errors``: down to ``target_error`` when given),
    resolution check and warnings.

    ``started()`` is called once the first point and its tangent are computed (the
    solvers then have read all their options).  ``kinds``: the event kinds to report
    (None: all); the others are left out of the result, unestimated (their levels' traces saved).
    ``comm``: the communicator of the run (PETSc.COMM_WORLD by default).  ``checkpoint``: a
    :class:`~petsc_adhesion.checkpoint.Checkpoint` that saves the run as it goes, and restores
    the state it holds first; ``progress``: a :class:`~petsc_adhesion.progress.Progress` for its lines.
    """
    t0 = t1 = time.perf_counter()
    comm = comm or PETSc.COMM_WORLD
    tracer = Tracer(model, settings, results.curve_events(at_lambda), tol, nodes=r, pmat=pmat, rmax=model.rmax,
                    comm=comm)
    kept = (lambda label: True) if kinds is None else (lambda label: label in kinds or label == "lambda")
    restored = checkpoint.restore(tracer) if checkpoint is not None else None
    phase, spent = restored or ("trace", {"trace": 0.0, "errors": 0.0})
    end, bars = curve_end(model, settings), []
    if restored and progress is not None:
        progress.line(f"going on from the checkpoint {printable(checkpoint.restart)} at lambda "
                      f"{tracer.segments[-1].cont.points[-1].p:.6g}"
                      + (", to its error bars" if phase == "errors" else ""))

    def pause(tr, stage: str = "trace") -> None:
        """Where the state is whole: a checkpoint may be saved, progress said."""
        walls = {**spent, stage: spent[stage] + time.perf_counter() - (t0 if stage == "trace" else t1)}
        if checkpoint is not None:
            checkpoint.pause(tr, stage, walls)
        if progress is not None and progress.due():
            done = sum(f.estimate is not None for _, f in bars)
            progress.update(*(curve_status(tr, lam0, end) if stage == "trace" else
                              (done / len(bars), f"error bars: {done} of {len(bars)} events done")))

    if phase == "trace":
        try:                    # a solver option refused at the start: the run in one process may go on
            segments = tracer.run(lam0, started, pause)
        except BaseException:
            tracer.destroy()
            raise
        jumps([seg.finder for seg in segments], Problem.stable)
        spent["trace"] += time.perf_counter() - t0
    else:
        segments = tracer.segments
        if started:
            started()
    wall = spent["trace"]
    if errors:
        t1 = time.perf_counter()
        bars = [(seg, f) for seg in segments for f in seg.finder.found if kept(f.label)]
        if progress is not None:
            progress.reset()
        for seg, found in bars:
            pause(tracer, "errors")
            if found.estimate is None:
                found.estimate = error_estimate.event_errors(tracer, seg, found, target_error)
        errors_wall = spent["errors"] + time.perf_counter() - t1
    res = results.curve(segments, profiles)
    mpi = comm.tompi4py()
    states = res.pop("states")
    law = tracer.segments[0].problem.law
    res["grid_warning"] = mpi.bcast(resolution.check(model, law, states, res["folds"])
                                    if mpi.Get_rank() == 0 else None)
    res["warnings"], res["incomplete"] = results.assess(segments, res, at_lambda)
    res["events"] = [e for e in res["events"] if kept(e["kind"])]
    if not kept("F_min"):
        res["pull_off"] = None
    res |= {"wall_time_s": wall, "lambda_start": lam0}
    if errors:
        res["error_estimate"] = {"wall_time_s": errors_wall, "target_error": target_error,
                                 "levels": sorted({k for e in res["events"] for k in e.get("levels", ())})}
    tracer.destroy()
    return res


def curve(opts: AppOptions, p: Plan, pmat, lam0: float, comm=None, kinds=None, profiles: bool = False,
          checkpoint=None, progress=None) -> tuple:
    """The curve of plan ``p`` from lam0 as its options ask (:func:`trace`); ``kinds`` and ``profiles``
    as a study's case asks; ``checkpoint`` and ``progress`` as :func:`trace` takes them.  Returns the
    result and its grids."""
    res = trace(p.model, p.r, pmat, p.settings, lam0, opts.reals("cont_at_lambda"), opts.real("cont_event_tol"),
                profiles or opts.flag("profiles"), started=check_unused, errors=opts.flag("cont_error_estimate"),
                target_error=opts.real("target_error"), kinds=kinds, comm=comm, checkpoint=checkpoint,
                progress=progress)
    return res, {"r": res["grid"], **res["grids"]}


def fixed_solve(problem: Problem, newton: Newton, lam: float, H: PETSc.Vec) -> dict:
    """One solve at approach ``lam`` from the guess in H: the state, its load and the solver's effort."""
    t0 = time.perf_counter()
    ok = newton.solve(lam, H)
    wall = time.perf_counter() - t0
    check_unused()                          # the solver has read all of its options
    if not ok:
        raise RuntimeError(f"Newton did not converge at lambda = {lam:g} "
                           f"(reason {newton.snes.getConvergedReason()}); try -adh_guess or -snes_monitor")
    pressure, _ = problem.pressure(H)
    Hall = problem.gather(H.getArray(readonly=True))
    its, kits = newton.iterations
    return {"lambda": lam, "F": problem.load(H, lam), "F_beyond": problem.far_load(lam), "H0": float(Hall[0]), "H": Hall,
            "P": problem.gather(pressure), "snes_iterations": its, "ksp_iterations": kits, "wall_time_s": wall}


def program(comm, opts: AppOptions) -> dict:
    """What every result file says about the program that wrote it: versions, ranks, options."""
    return {"program": "petsc-adhesion", "version": __version__,
            "petsc_version": "%d.%d.%d" % PETSc.Sys.getVersion(),
            "petsc4py_version": petsc4py.__version__, "mpi_ranks": comm.getSize(), "options": opts.given()}


def head(comm, opts: AppOptions, model, grid: dict) -> dict:
    """What every result file says about its run: the program, model, grid, the physical inputs."""
    phys = read_physical(opts)
    rough = pressure_law(model).describe()
    return {**program(comm, opts),
            "model": {"mu": model.mu, "sigma": model.sigma, "rmax": model.rmax, **rough,
                      "domain": "half-infinite (the rigid sphere's attraction beyond r_m added)" if model.farfield
                      else "truncated at r_m (the paper's model)"},
            "grid": grid, **({"physical": phys.describe()} if phys else {})}


def main(argv: list[str] | None = None, keep: dict | None = None) -> int:
    """The program: one study from the options database (initialised from ``argv``); its exit status.

    Errors raise (:mod:`petsc_adhesion.cli` turns them into one line).  ``keep`` (the Python API,
    :mod:`petsc_adhesion.api`): a dict that receives, on rank 0, the run's ``result``, ``head`` and
    ``summary`` instead of the console report; studies of many cases are the command line's.
    """
    comm = PETSc.COMM_WORLD
    opts = AppOptions()
    helping = opts.db.hasName("help")
    if helping and comm.getRank() == 0:
        print_help(sys.stdout)
    argv = sys.argv if argv is None else argv
    if collective(comm, _is_sweep, opts):
        from . import sweep                      # a sweep runs cases of this module's kind

        if keep is not None:
            raise InputError("-study_mu, -study_sigma, -study_option: a study of many cases runs from the "
                             "command line (petsc-adhesion -options_file FILE); the Python API traces one curve")
        return sweep.main(opts, argv, helping)
    stray = [n for n in TABLE if n.startswith("study_") and opts.db.hasName(n)]
    if stray and not helping:
        raise InputError(f"-{stray[0]}: applies to a study of many cases (-study_mu, -study_sigma or "
                         f"-study_option); remove it")
    p = collective(comm, plan, opts, comm, argv)
    pmat = preconditioning.create(opts.choice("adh_pmat"), opts.int("adh_pmat_band"))
    ck = None
    if p.lam is None:
        lam0 = opts.real("cont_lambda_start")
        lam0 = far_approach(p.model) if lam0 is None else lam0
        ck = open_checkpoint(opts, p.targets, p.inputs, comm)
        if helping:                                  # the solvers print their options
            problem = discretize(p.model, p.r if p.r is not None else grid_for(p.model, 0.0).nodes(), pmat)
            Continuation(problem, p.settings).destroy()
            problem.destroy()
            return 0
        shown = opts.flag("progress")
        progress = Progress(comm, sys.stderr.isatty() if shown is None else shown, opts.real("progress_interval"))
        with ck.on_interrupt():
            res, grid = curve(opts, p, pmat, lam0, checkpoint=ck, progress=progress)
    else:
        r = p.r if p.r is not None else grid_for(p.model, rigid_edge(p.lam)).nodes()
        problem, newton = discretize(p.model, r, pmat), None
        try:                    # on failure too: the shell's context holds a cycle that gc cannot free
            newton = Newton(problem, "", pc_reuse_its=opts.int("adh_pc_reuse_its"))
            if helping:
                return 0
            H = collective(comm, read_guess, problem, p.lam, opts.string("adh_guess"))
            res = fixed_solve(problem, newton, p.lam, H)
        finally:
            if newton is not None:
                newton.destroy()
            problem.destroy()
        grid = {"r": r}
    check_unused()
    status = 3 if p.lam is None and res["incomplete"] else 0
    files = None
    try:
        if comm.getRank() == 0:
            about = head(comm, opts, p.model, grid)
            with ck.on_interrupt() if ck else nullcontext(), written(p.targets, ck.paths() if ck else ()) as files:
                if p.lam is None:
                    summary = write_curve(res, about, files)
                    if keep is None:
                        results.report_curve(summary)
                else:
                    summary = write_solve(res, about, files)
                    if keep is None:
                        results.report_solve(res, summary.get("physical"))
            if keep is not None:
                keep |= {"result": res, "head": about, "summary": summary}
        PETSc.garbage_cleanup()
    except Interrupted as e:
        mark_done(e, files, status)
        raise
    return status
