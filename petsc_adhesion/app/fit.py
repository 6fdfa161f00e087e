"""A run that fits a measurement: ``-fit_pull_off P`` (the work of adhesion of a pull-off force) or
``-fit_curve FILE`` (the work of adhesion and the modulus of a force-distance curve).

    petsc-adhesion -fit_pull_off 12.5e-9 -phys_radius 20e-9 -phys_young1 150e9 -phys_poisson1 0.27 \\
        -phys_epsilon 0.3e-9 -summary fit.json
    petsc-adhesion -fit_curve curve.ibw -phys_radius 20e-9 -phys_epsilon 0.3e-9 -plot fit.png

As a curve's run: the options are read into typed objects and checked before any
work (one line naming the option for what is wrong or missing, exit status 2,
nothing written), the library fits (:mod:`petsc_adhesion.fitting`), and rank 0
writes the files all together and the report.  A fit runs on one rank.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, replace

from petsc4py import PETSc

from ..errors import InputError, collective, printable, say
from ..fitting.curve_fit import CurveFitError, FitProgress, OutsideDomain, fit_curve, predict_curve
from ..fitting.table_search import TABLE_CAP
from ..fitting.data import CurveFileError, MeasuredCurve, NeedsInstrument, read_curve
from ..fitting.forward import open_table
from ..fitting.pull_off import PullOffCurveError, PullOffFitError, fit_pull_off
from ..fitting.results import FitChoice, Spring
from ..io.fit import fit_summary, fit_tree, report_fit
from ..io.inputs import check_input
from ..io.resultset import PLOT_FORMATS, check_targets, written
from ..io.summary import model_record, program_record
from ..io.write import write_fit
from ..model.parameters import Model
from ..model.physical import Bodies
from ..tracing.curve import Program
from ..tracing.trace import GridChoice
from .options.checks import check_misspelled, check_petsc_values
from .options.reading import AppOptions, read_grid, read_model_spread, read_solver
from .options.plausible import PLAUSIBLE, implausible
from .options.table import ROUGHNESS_OPTIONS, TABLE
from .optionsfile import options_files
from .progress import Progress
from .run import is_fit, refuse_fit_options      # here for the fit's callers; in run.py, which every run loads

__all__ = ["FitRequest", "is_fit", "refuse_fit_options", "read", "execute", "main", "FIT_OPTIONS"]

#: The application options a fit honours besides its own (-fit_*): the bodies, the roughness average, the
#: domain, the grid and the preconditioner of the curves it traces, its outputs.
FIT_OPTIONS = {"phys_radius", "phys_radius2", "phys_young1", "phys_poisson1", "phys_young2", "phys_poisson2",
               "phys_epsilon", "phys_rms", "phys_spring", "adh_roughness", "adh_rmax", "adh_farfield", "adh_pmat",
               "adh_pmat_band", "adh_pc_reuse_its", "grid_type", "grid_n", "grid_paper_uniform", "grid_paper_extra",
               "grid_paper_split", "grid_paper_refine_from", "out", "summary", "plot", "csv",
               "adh_model_spread", "adh_model_spread_rules", "progress", "progress_interval", *ROUGHNESS_OPTIONS}
#: The options of -fit_curve alone: what is fitted and how.
CURVE_ONLY = ("fit_curve_index", "fit_modulus", "fit_roughness", "fit_invols", "fit_invols_scale",
              "fit_calibrate_invols", "fit_spring_err", "fit_virtual_deflection", "fit_drag", "fit_segment",
              "fit_z_range", "fit_max_evals", "fit_outside_domain", "fit_table")
_OUTPUTS = ("out", "summary", "plot", "csv")
#: Points per leg of the fitted model's curve in the files.
MODEL_POINTS = 400


@dataclass
class FitRequest:
    """A fit's inputs, read and checked."""

    kind: str                   # "pull_off" | "curve"
    model: Model                # the roughness average and the domain (mu and bodies are the fit's)
    grid: GridChoice
    solver: object
    bodies: Bodies              # radii, moduli (a curve's: where given), epsilon, rms
    P: float | None             # pull_off: the measured pull-off (N) and its bar
    P_err: float
    data: MeasuredCurve | None  # curve: the MeasuredCurve
    spring: Spring | None       # curve: the cantilever
    choice: FitChoice | None    # curve: what is fitted
    targets: dict
    spread_rules: tuple | None = None   # the laws of gamma's (a curve's: w's and E*'s) model spread (None: none)
    warnings: tuple = ()                # inputs outside what the field measures, one line each (plausible.py)
    table: str = "none"                 # curve: the table its search runs on (-fit_table, checked), or none


def _given(opts: AppOptions, name: str) -> bool:
    return opts.db.hasName(name)


def _refuse_others(opts: AppOptions, what: str) -> None:
    for name in TABLE:
        if _given(opts, name) and not name.startswith("fit_") and name not in FIT_OPTIONS:
            why = "the work of adhesion is what the fit finds" if name in ("phys_gamma", "phys_hamaker",
                                                                          "phys_hamaker_cutoff") else \
                "mu is what the fit finds (eq. 9)" if name == "adh_mu" else \
                "sigma is -phys_rms / -phys_epsilon" if name == "adh_sigma" else "a fit traces its own curves"
            raise InputError(f"-{name}: not with {what}: {why}; remove it")


def instrument_error(e: NeedsInstrument, run: str) -> InputError:
    """The refusal of a file's missing calibration, naming its option (-fit_invols, -phys_spring): required with
    ``run`` (-fit_curve, -fit_map) where not given, or to be removed where given and the file cannot take it."""
    if e.given:
        return InputError(f"-{e.option}: {printable(str(e))}; remove it")
    return InputError(f"-{e.option}: required with {run}: {printable(str(e))}")


def _moduli(opts: AppOptions, need: bool, what: str) -> float | None:
    """E* of eq. (2) from -phys_young1, -phys_poisson1 (and -phys_young2, -phys_poisson2), or None: checked
    here, given to the fit in the Bodies."""
    have = {n: opts.real(n) for n in ("phys_young1", "phys_poisson1", "phys_young2", "phys_poisson2") if _given(opts, n)}
    for a, b in (("phys_young1", "phys_poisson1"), ("phys_young2", "phys_poisson2")):
        if (a in have) != (b in have):
            missing = b if a in have else a
            raise InputError(f"-{missing}: needed with -{a if a in have else b} (eq. 2)")
    if "phys_young2" in have and "phys_young1" not in have:
        raise InputError("-phys_young1: needed with -phys_young2 (the sphere's modulus, eq. 2)")
    if "phys_young1" not in have:
        if need:
            raise InputError(f"-phys_young1: required with {what}, with -phys_poisson1 (the sphere's modulus; the "
                             f"flat's -phys_young2, -phys_poisson2, or a rigid flat)")
        return None
    bodies = Bodies(radius=1.0, young1=have["phys_young1"], poisson1=have["phys_poisson1"], epsilon=1.0,
                    young2=have.get("phys_young2"), poisson2=have.get("phys_poisson2"))
    E = bodies.E
    if not (math.isfinite(E) and E > 0):
        raise InputError("-phys_young1: with the other moduli gives no finite positive E* (eq. 2)")
    return E


def _template(opts: AppOptions, rms: float | None, eps: float) -> Model:
    rough = opts.choice("adh_roughness")
    if rough == "measured":
        raise InputError("-adh_roughness: measured is not fitted (its heights set sigma); give -phys_rms with "
                         "hermite, truncated_gaussian, weibull or lognormal")
    sigma = 0.0 if rms is None else rms / eps
    if rough == "none" and sigma > 0:
        raise InputError("-phys_rms: not with -adh_roughness none (a smooth surface)")
    if sigma > TABLE["adh_sigma"].hi:
        raise InputError(f"-phys_rms: gives sigma = rms / epsilon = {sigma:.3g}, above {TABLE['adh_sigma'].hi:g}")
    rmax = opts.real("adh_rmax")
    if rmax is None:
        rmax = GridChoice(opts.choice("grid_type")).default_rmax
    return Model(mu=1.0, sigma=sigma, rmax=rmax, roughness=rough, hermite_points=opts.int("adh_hermite_points"),
                 roughness_cutoff=opts.real("adh_roughness_cutoff"),
                 roughness_skewness=opts.real("adh_roughness_skewness"),
                 lognormal_skewness=opts.real("adh_lognormal_skewness"),
                 quadrature_points=opts.int("adh_quadrature_points"), farfield=opts.flag("adh_farfield"))


def read(opts: AppOptions, comm, argv: list[str]) -> FitRequest:
    """Read and check a fit's options before any work (see the module)."""
    check_misspelled(opts)          # before the options required together: a misspelling named as such
    check_petsc_values(opts.db)
    pull, path = opts.real("fit_pull_off"), opts.string("fit_curve")
    if pull is not None and path is not None:
        raise InputError("-fit_pull_off: not with -fit_curve; a run fits one measurement")
    kind = "pull_off" if pull is not None else "curve"
    what = "-fit_pull_off" if pull is not None else "-fit_curve"
    for name, needs in (("fit_pull_off_err", "pull_off"), *((n, "curve") for n in CURVE_ONLY)):
        if _given(opts, name) and kind != needs:
            raise InputError(f"-{name}: only with -fit_{needs}")
    if _given(opts, "fit_map_shape"):
        raise InputError("-fit_map_shape: only with -fit_map")
    if comm.getSize() > 1:
        raise InputError(f"{what}: a fit runs on one rank (its curves are small); run it without mpiexec")
    _refuse_others(opts, what)
    for name in ("phys_radius", "phys_epsilon"):
        if not _given(opts, name):
            need = "the tip's radius R" if name == "phys_radius" else "the Lennard-Jones law's epsilon"
            raise InputError(f"-{name}: required with {what} ({need}, m)")
    eps = opts.real("phys_epsilon")
    rms = opts.real("phys_rms")
    if opts.choice("adh_roughness") == "none" and rms:
        raise InputError("-phys_rms: not with -adh_roughness none (a smooth surface)")
    model = _template(opts, rms, eps)
    for name, kinds in ROUGHNESS_OPTIONS.items():
        if _given(opts, name) and (model.roughness not in kinds or (model.sigma == 0 and not
                                                                    opts.flag("fit_roughness"))):
            raise InputError(f"-{name}: applies to -adh_roughness {' or '.join(kinds)} with a roughness "
                             f"(-phys_rms or -fit_roughness); remove it")
    grid, solver = read_grid(opts, model), read_solver(opts)
    targets = {k: opts.string(k) for k in _OUTPUTS if opts.string(k)}
    if kind == "pull_off":
        for name in ("plot", "csv", "phys_spring"):
            if name in targets or _given(opts, name):
                raise InputError(f"-{name}: applies to -fit_curve (a pull-off has no curve); remove it")
        for name in ("progress", "progress_interval"):
            if _given(opts, name):
                raise InputError(f"-{name}: applies to -fit_curve (a pull-off's fit is a few curves, without "
                                 f"progress lines); remove it")
    if "plot" in targets and not targets["plot"].lower().endswith(tuple(PLOT_FORMATS)):
        raise InputError(f"-plot: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{targets['plot']}'")
    inputs = {"options_file": options_files(argv), "fit_curve": [path or ""]}
    fit_modulus, fit_rough = opts.flag("fit_modulus"), opts.flag("fit_roughness")
    _moduli(opts, kind == "pull_off" or not fit_modulus, what if kind == "pull_off" else "-fit_modulus false")
    bodies = Bodies(radius=opts.real("phys_radius"), young1=opts.real("phys_young1"),
                    poisson1=opts.real("phys_poisson1"), epsilon=eps, radius2=opts.real("phys_radius2"),
                    young2=opts.real("phys_young2"), poisson2=opts.real("phys_poisson2"), rms=rms)
    if kind == "pull_off":
        req = FitRequest("pull_off", model, grid, solver, bodies, pull, opts.real("fit_pull_off_err"), None, None,
                         None, targets, read_model_spread(opts, model))
    else:
        if fit_rough and model.roughness == "none":
            raise InputError("-fit_roughness: not with -adh_roughness none (a smooth surface)")
        choice = _curve_choice(opts, fit_modulus, fit_rough)
        table = opts.string("fit_table")
        try:
            open_table(table)           # checked before any work; the fit opens it again (the package's: once)
        except ValueError as e:
            raise InputError(f"-fit_table: {printable(str(e))}; expected a table file, default or none") from None
        rough = model.roughness != "none" and (model.sigma > 0 or fit_rough)
        spread = read_model_spread(opts, replace(model, sigma=model.sigma or (0.3 if rough else 0.0)))
        check_input("fit_curve", path)
        try:
            data = read_curve(path, opts.int("fit_curve_index"), spring=opts.real("phys_spring"),
                              invols=opts.real("fit_invols"))
        except NeedsInstrument as e:
            raise instrument_error(e, "-fit_curve") from None
        except CurveFileError as e:
            raise InputError(f"-fit_curve: {printable(str(e))}") from None
        invols = opts.real("fit_invols")
        if invols is not None and data.sensitivity != invols:
            raise InputError(f"-fit_invols: '{printable(path)}' gives a force, not a deflection in volts: no "
                             f"sensitivity to apply; remove it")
        held = int(data.metadata.get("curves_in_file", 1))
        if held > 1 and not _given(opts, "fit_curve_index"):
            raise InputError(f"-fit_curve_index: required with -fit_curve: '{printable(path)}' holds {held} curves "
                             f"(a force map); name the one to fit, 0 to {held - 1}")
        k = opts.real("phys_spring")
        source = "-phys_spring"
        if k is None:
            if data.spring is None:
                raise InputError(f"-phys_spring: required with -fit_curve: the file '{printable(path)}' states no "
                                 f"spring constant (N/m)")
            k, source = data.spring, "the file"
        elif data.spring is not None and k != data.spring:
            data = data.rescaled(k)       # the file's force is its spring constant times the measured deflection
            source = f"-phys_spring (the file's force rescaled from its {data.metadata.get('spring constant')} N/m)"
        req = FitRequest("curve", model, grid, solver, bodies, None, 0.0, data, Spring(k, source), choice, targets,
                         spread, table=table)
    if comm.getRank() == 0:
        check_targets(targets, inputs)
    # last: a fit refused says its one line, not warnings beside it
    return replace(req, warnings=tuple(implausible({n: opts.real(n) for n in PLAUSIBLE if n in TABLE})))


def _curve_choice(opts: AppOptions, fit_modulus: bool, fit_rough: bool) -> FitChoice:
    """What -fit_curve fits, from its options (checked: one line naming the option)."""
    z_range = opts.reals("fit_z_range")
    if _given(opts, "fit_z_range") and (len(z_range) != 2 or z_range[0] >= z_range[1]):
        raise InputError(f"-fit_z_range: expected two piezo positions lo,hi (m) with lo < hi, got "
                         f"'{opts.string('fit_z_range')}'")
    segment = opts.choice("fit_segment")
    if opts.flag("fit_drag") and segment == "approach":
        raise InputError("-fit_drag: the retract's offset needs the retract; -fit_segment approach fits none")
    return FitChoice(modulus=fit_modulus, roughness=fit_rough, max_evaluations=opts.int("fit_max_evals"),
                     invols_fitted=bool(opts.flag("fit_invols_scale")),
                     calibrate_invols=bool(opts.flag("fit_calibrate_invols")), spring_err=opts.real("fit_spring_err"),
                     virtual_deflection=bool(opts.flag("fit_virtual_deflection")), drag=bool(opts.flag("fit_drag")),
                     segment=segment, z_range=tuple(z_range) if z_range else None,
                     outside_domain=opts.choice("fit_outside_domain"))


def _progress(opts: AppOptions, comm, cap: int):
    """The progress line of a curve fit (-progress, -progress_interval): evaluations, curves traced, the best
    reduced chi^2; None where it is not shown."""
    shown = opts.flag("progress")
    bar = Progress(comm, sys.stderr.isatty() if shown is None else shown, opts.real("progress_interval"))
    if not bar.enabled:
        return None

    def update(p: FitProgress) -> None:
        at_most = p.cap or cap         # the search's own: TABLE_EVALS times -fit_max_evals on a rough table
        bar.update(min(1.0, p.evaluations / at_most),
                   f"fit: {p.evaluations} evaluations of at most {at_most} (-fit_max_evals"
                   f"{'' if at_most == cap else TABLE_CAP}), {p.traces} curve{'' if p.traces == 1 else 's'} traced, "
                   f"best reduced chi^2 {p.best_reduced_chi2:.4g}")
    return update


def _fit(req: FitRequest, comm, progress=None):
    """The library's fit of ``req``; InputError (one line naming the option) for what it cannot fit."""
    try:
        if req.kind == "pull_off":
            assert req.P is not None, "a pull-off fit's request holds the measured pull-off"
            return fit_pull_off(req.P, req.bodies, req.P_err, model=req.model, grid=req.grid, solver=req.solver,
                                comm=comm, spread_rules=req.spread_rules)
        assert req.data is not None and req.spring is not None, "a curve fit's request holds the curve and spring"
        return fit_curve(req.data, req.bodies, req.spring, req.choice, model=req.model, grid=req.grid,
                         solver=req.solver, comm=comm, progress=progress, spread_rules=req.spread_rules,
                         table=req.table)
    except PullOffFitError as e:
        raise InputError(f"-fit_pull_off: {printable(str(e))}") from None
    except CurveFitError as e:
        raise InputError(f"-fit_curve: {printable(str(e))}") from None


def _model_curve(fit) -> dict:
    """The fitted model's force on an even grid of MODEL_POINTS piezo positions over the data, each leg."""
    import numpy as np

    z = np.linspace(float(fit.data.z.min()), float(fit.data.z.max()), MODEL_POINTS)
    return {"z": z, "F_approach": predict_curve(fit, z, "approach"), "F_retract": predict_curve(fit, z, "retract")}


def _implausible_result(fit) -> tuple:
    """The warning line for a fitted work of adhesion outside what the field measures (plausible.py's range of
    -phys_gamma): the model may reach it (mu up to 1000), yet a value of 1e4 J/m^2 says the input's units slipped."""
    g = getattr(fit.gamma, "value", None)
    p = PLAUSIBLE["phys_gamma"]
    if g is None or p.lo <= g <= p.hi:
        return ()
    where = p.low if g < p.lo else p.high
    return (f"the fitted work of adhesion {g:.4g} J/m^2 is {where}: check the measurement's units (N, m)",)


def execute(opts: AppOptions, argv: list[str], report: bool = True):
    """The fit of the options database: (exit status, the library's fit).  The status is 3 where the fit does
    not hold (its warnings: a parameter at a bound or undetermined, a misfit; docs/fitting.md), its files
    written all the same; else 0."""
    comm = PETSc.COMM_WORLD
    from .run import warn

    req = collective(comm, read, opts, comm, argv)
    try:
        fit = _fit(req, comm, _progress(opts, comm, req.choice.max_evaluations) if req.kind == "curve" else None)
    except OutsideDomain as e:          # refused before any work: nothing written, an earlier result intact
        say(f"-fit_curve: outside the model's domain: {printable(str(e))}; -fit_outside_domain warn fits it all "
            f"the same")
        return 3, None
    except PullOffCurveError as e:     # a curve the fit needed failed: what was not computed, nothing written
        say(f"-fit_pull_off: no work of adhesion: {printable(str(e))}")
        return 3, None
    warn(req.warnings + _implausible_result(fit), report)   # with the result: a refused fit stays one line
    head = program_record(Program.of(comm))
    head["model"] = model_record(replace(req.model, mu=fit.mu, sigma=fit.sigma))   # the model fitted
    given = opts.given()
    model = _model_curve(fit) if req.kind == "curve" else None
    with written(req.targets) as files:
        write_fit(fit_tree(head, given, fit, model), fit_summary(head, given, fit), files)
        if report:
            report_fit(fit)
        files.commit()
    PETSc.garbage_cleanup()
    return (0 if fit.trustworthy else 3), fit


def main(opts: AppOptions, argv: list[str], helping: bool = False) -> int:
    """A fit of the options database; its exit status (``helping``: checked only)."""
    from .run import command_main

    return command_main(opts, argv, helping, read, execute)
