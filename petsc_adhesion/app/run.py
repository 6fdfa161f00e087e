"""One run of the program: its options into the library's objects, one library call, the result files.

    petsc-adhesion -adh_mu 2 -out mu2.h5 -summary mu2.json     # the load-approach curve
    petsc-adhesion -adh_mu 2 -adh_lambda -3                    # the state at one approach

A run is either the whole load-approach curve
(:func:`~petsc_adhesion.tracing.trace.trace_curve`, the default) or one solve at
a fixed approach (``-adh_lambda``, :func:`~petsc_adhesion.tracing.trace.solve_at`).
Data flow one way: the options are read into typed objects and checked
(:func:`read`, on every rank, agreed before any work), the library computes,
and rank 0 writes the files all together or none
(:mod:`petsc_adhesion.io.write`) and the console report.  A study of many cases
is :mod:`petsc_adhesion.app.study`'s.
"""
from __future__ import annotations

import sys
import warnings
from contextlib import nullcontext
from dataclasses import dataclass, replace

from petsc4py import PETSc

from ..core.continuation import Settings
from ..errors import InputError, Interrupted, collective, say
from ..io.guess import read_guess
from ..io.report import report_curve, report_solve
from ..io.resultset import PLOT_FORMATS, check_targets, mark_done, written
from ..io.write import write_curve, write_solve
from ..model.parameters import Model
from ..model.pressure import pressure_law
from ..tracing.curve import Curve, Solution
from ..tracing.trace import (
    CurveRequest,
    GridChoice,
    SolverChoice,
    configure_solvers,
    solve_at,
    trace_curve,
)
from .checkpoint import open_checkpoint
from .options.checks import (
    check_consistency,
    check_misspelled,
    check_memory,
    check_petsc_values,
    check_unused,
)
from .options.reading import (
    AppOptions,
    read_grid,
    read_model,
    read_model_spread,
    read_request,
    read_settings,
    read_solver,
)
from .options.plausible import PLAUSIBLE, implausible
from .options.table import TABLE
from .optionsfile import options_files
from .progress import Progress

__all__ = ["Request", "read", "execute", "main", "is_study", "is_fit", "refuse_study_options", "refuse_fit_options"]

_OUTPUTS = ("out", "summary", "plot", "csv", "csv_events")


def is_study(opts: AppOptions) -> bool:
    """Whether the options describe a study of many cases (:mod:`petsc_adhesion.app.study`)."""
    return any(opts.db.hasName(n) for n in ("study_mu", "study_sigma", "study_option")) or \
        opts.choice("study_compute") == "critical"


def is_fit(opts: AppOptions) -> bool:
    """Whether the options ask for a fit of a measurement (:mod:`petsc_adhesion.app.fit`, loaded only then:
    a curve's run need not import the fitting code)."""
    return opts.db.hasName("fit_pull_off") or opts.db.hasName("fit_curve")


def refuse_fit_options(opts: AppOptions) -> None:
    """An InputError for a -fit_ option given without -fit_pull_off or -fit_curve."""
    stray = [n for n in TABLE if n.startswith("fit_") and opts.db.hasName(n)]
    if stray:
        needs = "-fit_pull_off" if stray[0] == "fit_pull_off_err" else \
            "-fit_map" if stray[0].startswith("fit_map") else "-fit_curve"
        raise InputError(f"-{stray[0]}: only with {needs}; remove it")


@dataclass
class Request:
    """Everything a run needs from its options, read into the library's objects and checked."""

    model: Model
    grid: GridChoice
    solver: SolverChoice
    settings: Settings
    curve: CurveRequest
    lam: float | None                 # a fixed approach, or None for the curve
    guess: str | None                 # -adh_guess
    targets: dict                     # option -> output path
    inputs: dict                      # option -> paths read
    spread_rules: tuple | None = None  # the laws of the model spread (-adh_model_spread), None: none
    warnings: tuple = ()              # inputs outside what the field measures, one line each (plausible.py)


def read(opts: AppOptions, comm, argv: list[str], kinds: tuple | None = None, profiles: bool = False,
         case: bool = False) -> Request:
    """Read and check every option before any work (PETSc's solver options too, as far as they can be judged
    before the solvers exist); ``kinds`` and ``profiles``: what a study's ``case`` reports (its model spread
    that of a rough case; a smooth case of a study has none, whatever -adh_model_spread says)."""
    check_misspelled(opts)          # before the options required together: a misspelling named as such
    model = read_model(opts)
    grid_choice = read_grid(opts, model)
    lam = opts.real("adh_lambda")
    check_memory(grid_choice, opts.choice("adh_pmat"), lam is None, comm.getSize())
    if opts.string("adh_guess") is not None and lam is None:
        raise InputError("-adh_guess: only with -adh_lambda (the curve starts from the rigid state)")
    check_consistency(opts, model)
    check_petsc_values(opts.db)
    targets = {k: opts.string(k) for k in _OUTPUTS if opts.string(k)}
    if "plot" in targets and not targets["plot"].lower().endswith(tuple(PLOT_FORMATS)):
        raise InputError(f"-plot: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{targets['plot']}'")
    inputs = {"options_file": options_files(argv), "adh_guess": [opts.string("adh_guess") or ""],
              "adh_roughness_file": [opts.string("adh_roughness_file") or ""],
              "adh_topography": [opts.string(n) or "" for n in ("adh_topography", "adh_topography2")]}
    if comm.getRank() == 0:                  # only rank 0 writes
        check_targets(targets, inputs)
    if lam is not None:    # no spread of one solve: asking is refused
        for name in ("adh_model_spread", "adh_model_spread_rules"):
            if opts.db.hasName(name):
                raise InputError(f"-{name}: applies to a curve (one run's, a study's cases) or -fit_pull_off, not "
                                 f"-adh_lambda (one solve); remove it")
        spread_rules = None
    elif case and not (model.roughness != "none" and model.sigma > 0):
        spread_rules = None        # a study's smooth case: no law to vary (the study refuses a spread no case has)
    else:
        spread_rules = read_model_spread(opts, model)
    req = Request(model, grid_choice, read_solver(opts), read_settings(opts, model),
                  read_request(opts, kinds, profiles, model.bodies), lam, opts.string("adh_guess"), targets, inputs,
                  spread_rules)
    # last: a run refused says its one line, not warnings beside it
    return replace(req, warnings=tuple(implausible({n: opts.real(n) for n in PLAUSIBLE if n in TABLE})))


def warn(lines, report: bool) -> None:
    """Rank 0 says each warning of the inputs: a line on stderr (``report``, the command line's), else a
    Python RuntimeWarning (the API's, as its curve's warnings)."""
    if PETSc.COMM_WORLD.getRank() != 0:
        return
    for line in lines:
        if report:
            say(f"warning: {line}")
        else:
            warnings.warn(f"petsc-adhesion: {line}", RuntimeWarning, stacklevel=5)   # the caller of curve()


def execute(opts: AppOptions, argv: list[str], report: bool = True):
    """The run of the options database: (exit status, the library's result: a
    :class:`~petsc_adhesion.tracing.curve.Curve` or :class:`~petsc_adhesion.tracing.curve.Solution`).

    Rank 0 writes the files asked for and, with ``report``, the console lines.  Errors raise
    (:mod:`petsc_adhesion.app.cli` turns them into one line).
    """
    comm = PETSc.COMM_WORLD
    req = collective(comm, read, opts, comm, argv)
    ck = None
    result: Curve | Solution
    if req.lam is None:
        ck = open_checkpoint(opts, req.targets, req.inputs, comm)
        shown = opts.flag("progress")
        progress = Progress(comm, sys.stderr.isatty() if shown is None else shown, opts.real("progress_interval"))
        with ck.on_interrupt():
            result = trace_curve(req.model, req.grid, req.solver, req.settings, req.curve, checkpoint=ck,
                                 progress=progress, started=lambda: check_unused(db=opts.db))
            if req.spread_rules is not None:   # the same curve under the other laws, events only
                from ..tracing.model_spread import model_spread   # only then: a smooth run need not load it
                result = replace(result, spread=model_spread(result, req.model, req.grid, req.solver, req.settings,
                                                             req.curve, req.spread_rules, comm=comm))
    else:
        guess = None if req.guess is None else \
            collective(comm, read_guess, req.guess, pressure_law(req.model).wall)
        result = solve_at(req.lam, req.model, req.grid, req.solver, guess=guess,
                          started=lambda: check_unused(db=opts.db))
    check_unused(db=opts.db)
    # with the result: a refusal found on the way (a solver's option nobody read) stays its one line
    warn(req.warnings, report)
    status = 3 if isinstance(result, Curve) and not result.complete else 0     # a curve's (req.lam None)
    files = None
    try:
        if comm.getRank() == 0:
            given = opts.given()
            with ck.on_interrupt() if ck else nullcontext(), written(req.targets, ck.paths() if ck else ()) as files:
                (write_curve if req.lam is None else write_solve)(result, given, files, commit=False)
                if report:       # before the files go in place: a report that cannot be written fails the run
                    report_curve(result) if isinstance(result, Curve) else report_solve(result)
                files.commit()
        PETSc.garbage_cleanup()
    except Interrupted as e:
        mark_done(e, files, status)
        raise
    return status, result


def refuse_study_options(opts: AppOptions) -> None:
    """An InputError for an option of a study of many cases given to one run."""
    stray = [n for n in TABLE if n.startswith("study_") and opts.db.hasName(n)]
    if stray:
        raise InputError(f"-{stray[0]}: applies to a study of many cases (-study_mu, -study_sigma or "
                         f"-study_option); remove it")


def command_main(opts: AppOptions, argv: list[str], helping: bool, read, execute) -> int:
    """The exit status of a command of one request (a fit, a map, a population): a study's options refused;
    ``helping`` (-help): ``read`` alone, on every rank, so that its refusals come first; else ``execute``'s status."""
    refuse_study_options(opts)
    if helping:
        collective(PETSc.COMM_WORLD, read, opts, PETSc.COMM_WORLD, argv)
        return 0
    return execute(opts, argv)[0]


def main(opts: AppOptions, argv: list[str], helping: bool = False) -> int:
    """One run of the options database (initialised from ``argv``); its exit status.

    ``helping`` (-help): the options are checked and the solvers made, so that they print their own
    options, and nothing is computed.
    """
    comm = PETSc.COMM_WORLD
    if not helping:
        refuse_study_options(opts)
    if helping:
        req = collective(comm, read, opts, comm, argv)
        if req.lam is None:
            open_checkpoint(opts, req.targets, req.inputs, comm)
        configure_solvers(req.model, req.grid, req.solver, req.settings, req.lam)
        return 0
    return execute(opts, argv)[0]
