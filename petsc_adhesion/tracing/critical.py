"""The fold curve and its cusp: the critical roughness sigma_c(mu) and Tabor parameter mu_c(sigma).

Above a Tabor parameter mu_c(0) the load-approach curve F(lambda) has a pair of
turning points in lambda: snap-on at the larger lambda, snap-off at the smaller
(Figs. 5-9).  Roughness shrinks the pair; at the critical roughness sigma_c(mu)
the two folds merge at a cusp, and above it the curve is monotone in lambda: no
hysteresis.  Read the other way, mu_c(sigma) is the smallest mu with hysteresis
at roughness sigma, mu_c(0) the onset for a smooth sphere.

A fold, continued in a second parameter s (sigma or mu), traces a curve in
(s, lambda): the fold system of :mod:`~petsc_adhesion.core.fold` on the
adhesion problem (:func:`fold_system`), which gives it its second derivatives
(:meth:`~petsc_adhesion.discretization.problem.Problem.second_derivatives`,
:meth:`~petsc_adhesion.discretization.problem.Problem.parameter_derivatives`):
with G_H = I - c A diag(P'(H)) (eq. 23),

    g_H = c (A^T w) P''(H) v   (elementwise),   g_lambda = 0,
    G_sigma = -c A dP/dsigma,                  g_sigma = c w^T A (dP'/dsigma v),
    G_mu = -c' A P,                            g_mu = c' w^T A (P' v),   c' = dc/dmu = 3 c / (2 mu),

P'' and the sigma derivatives central differences of the laws' exact P and P'
(:func:`~petsc_adhesion.model.pressure.curvature`,
:func:`~petsc_adhesion.model.pressure.sigma_rates`): every law serves, and these
derivatives enter only the Jacobian and the tangent, never the residual whose
zero is the fold.  The core traces the fold curve as it traces a load-approach
curve, and its fold event, the turning point of the fold curve in s, is the cusp.

:func:`sigma_c` and :func:`mu_c` find the cusp in three stages:

1. a bracket from ordinary load-approach curves (:class:`~petsc_adhesion.tracing.tracer.Tracer`,
   grids that follow the contact edge, traced to equilibrium): the parameter
   is bisected geometrically until the values with and without folds are
   within the ratio BRACKET;
2. from every snap-on fold at the end with folds, carried to a fixed grid
   graded about its contact edge (:func:`~petsc_adhesion.tracing.edge_grids.grid_for`),
   the fold curve is traced toward the other end until it turns: the cusp on
   that grid, the most extreme one when there are several pairs;
3. the cusp is located again, each level from the one before, on the nested levels of
   a grid centred on the cusp's own contact edge, and Richardson's
   extrapolation of those values (:func:`~petsc_adhesion.tracing.error_bars.extrapolate`)
   gives the best value and its bar; the finest level once more on a domain
   twice as long adds the truncation's share to the bar.

Every solver takes the PETSc settings of its role from one
:class:`~petsc_adhesion.tracing.trace.SolverChoice`, as a curve's do: ``natural``
and ``arclength`` the correctors of the ordinary curves and of the fold curve
(the command line's ``-nat_``, ``-arc_``), ``fold`` the fold system's bordered
solves of g (``-fold_``).  The preconditioners are dense (the fold system's is
the base problem's, bordered), and there is no solve at a fixed approach: a
choice of another preconditioner, or settings of the fixed role, are refused.

Stage 1 relies on the fold pair being seen on an ordinary curve however narrow
it is: :class:`~petsc_adhesion.core.events.EventFinder` walks again the steps where
lambdadot dips toward zero (near the cusp the pair is far narrower than a step).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from petsc4py import PETSc

from ..core.continuation import Continuation, Point, Settings
from ..core.events import EventFinder, Fold, Found
from ..core.fold import FoldSystem
from ..core.newton import PC_REUSE_ITS, PetscSettings
from ..discretization.influence import create_influence
from ..discretization.preconditioning import Dense
from ..discretization.problem import Problem, far_approach
from ..discretization.resolution import cohesive_zone
from ..model.parameters import Model
from ..model.pressure import pressure_law
from ..tracing import results
from .edge_grids import BAND, RMAX, grid_for
from .error_bars import extrapolate
from .measured import Measured
from .trace import SolverChoice
from .tracer import Tracer, contact_radius, edge_of

__all__ = ["Critical", "fold_system", "at_parameter", "ordinary_folds", "bracket", "trace_cusp", "sigma_c", "mu_c", "Cusp", "BRACKET",
           "LEVELS", "SIGMA_START", "SIGMA_RANGE", "MU_START", "MU_RANGE", "FOLD_SETTINGS", "check_solver", "configure_solvers"]

#: The bracket of stage 1 ends when its two values are within this ratio: the fold curve then travels
#: a short way to the cusp, its contact edge within the fine band of the grid it started on.
BRACKET = 1.1
#: Default refinement levels of the grid at the cusp (nested: spacing / 2^level).
LEVELS = (0, 1, 2)
#: Where stage 1 starts, and the ranges it may search: hysteresis below sigma_c, above mu_c.
SIGMA_START, SIGMA_RANGE = 0.25, (1e-3, 8.0)
MU_START, MU_RANGE = 1.0, (0.05, 100.0)
#: Step control of the fold curve (lengths in the norm of (H, lambda, s), see FoldSystem.weights).
FOLD_SETTINGS = Settings(ds=0.01, ds_max=0.1, max_steps=400, max_folds=1)


def at_parameter(model, name: str, value: float):
    """``model`` with its parameter ``name`` (sigma or mu) set to ``value`` (:meth:`~petsc_adhesion.model.parameters.Model.with_parameter`)."""
    return model.with_parameter(name, value)


def check_solver(solver: SolverChoice, call: str = "sigma_c") -> None:
    """ValueError, one line, for a :class:`~petsc_adhesion.tracing.trace.SolverChoice` the critical calls
    cannot honour: another type, a preconditioner other than dense, a kept preconditioner's limit other than
    the default, settings of the fixed-approach solve (a solver they do not make)."""
    if not isinstance(solver, SolverChoice):
        raise ValueError(f"solver: expected a SolverChoice, got {type(solver).__name__}")
    if solver.pmat != "dense" or solver.band != SolverChoice().band:
        raise ValueError(f"solver.pmat: {call} builds dense preconditioners (the fold system borders the base "
                         f"problem's); leave pmat and band out")
    if solver.pc_reuse_its != PC_REUSE_ITS:
        raise ValueError(f"solver.pc_reuse_its: {call} keeps its preconditioners by the continuation's "
                         f"Settings.pc_reuse_its; leave it out")
    if solver.fixed != PetscSettings():
        raise ValueError(f"solver.fixed: settings of a solver {call} does not make (it makes natural, arclength "
                         f"and fold); leave them out")


def fold_system(model, r: np.ndarray, name: str, s0: float, comm=None,
                settings: PetscSettings = PetscSettings()) -> FoldSystem[Problem]:
    """The fold system of ``model`` at ``name`` = ``s0`` on the nodes r, continued in ``name``: the adhesion
    problem (:class:`~petsc_adhesion.discretization.problem.Problem`, dense PC) under
    :class:`~petsc_adhesion.core.fold.FoldSystem`, with x = (H, lambda); ``settings``: the PETSc settings
    of its bordered solves of g (the role ``fold``)."""
    comm = comm or PETSc.COMM_WORLD
    base = Problem(at_parameter(model, name, s0), r, create_influence(r, comm), Dense())
    try:
        return FoldSystem(base, name, settings)
    except BaseException:
        base.destroy()
        raise


def _state(fs: FoldSystem[Problem], r: np.ndarray, H: np.ndarray, lam: float) -> np.ndarray:
    """The local part of (H, lambda) for a state H on nodes r: its deformation H - r^2/2 interpolated."""
    base = fs.base
    mine = base.r[base.lo:base.lo + fs.nloc]
    return fs.join(np.interp(mine, r, H - 0.5 * r * r) + 0.5 * mine * mine, lam)


def _whole(fs: FoldSystem[Problem], x: np.ndarray) -> tuple[np.ndarray, float]:
    """(all of H, lambda) of a local part x, on every rank."""
    h, lam = fs.split(x)
    return fs.base.gather(h), lam


def _edge(fs: FoldSystem[Problem], x: np.ndarray, s: float) -> tuple[float, float]:
    """(radius of peak attraction, contact radius) of a state at s (:mod:`~petsc_adhesion.tracing.tracer`)."""
    fs.base.set_parameter(fs.parameter, s)
    fs.forget()
    h, _ = fs.split(x)
    return edge_of(fs.base, h), contact_radius(fs.base, h)


# -- stage 1: the bracket from ordinary curves ---------------------------------------------


def ordinary_folds(model, comm=None, solver: SolverChoice = SolverChoice()) -> list[dict]:
    """The turning points of the ordinary load-approach curve of ``model``, in the order of the curve.

    Traced as the program traces a curve (:class:`~petsc_adhesion.tracing.tracer.Tracer`, grids that
    follow the contact edge, from far apart) to equilibrium, without error bars.  Each fold is
    {kind (snap_on or snap_off), lambda, F, r, H} with the nodes and H of the grid it was located
    on (whole, on every rank); its correctors with the ``natural`` and ``arclength`` settings of
    ``solver``.  RuntimeError when the curve ends before equilibrium.
    """
    settings = Settings(observable="F", observable_max=0.0)
    tracer = Tracer(model, settings, results.curve_events(), pmat=Dense(), rmax=model.rmax, comm=comm,
                    natural=solver.natural, arclength=solver.arclength)
    try:
        segments = tracer.run(far_approach(model))
        last = segments[-1].cont
        assert last.stop is not None, "a run ends with its reason"
        if last.stop[0] != "observable_max":
            raise RuntimeError(f"the curve at mu = {model.mu:g}, sigma = {model.sigma:g} ended before equilibrium: "
                               f"{results.stop_reason(last.stop, settings)}")
        out = []
        for seg in segments:
            pb = seg.problem
            for f in seg.finder.found:
                if isinstance(f.event, Fold):
                    x = f.point.x
                    out.append({"kind": f.label, "lambda": f.point.p, "F": f.point.values["F"],
                                "r": pb.nodes(x), "H": pb.gather(pb.separation(x))})
        return out
    finally:
        tracer.destroy()


def bracket(model, name: str, comm=None, ratio: float = BRACKET,
            solver: SolverChoice = SolverChoice()) -> tuple[float, float, list]:
    """Values (a, b) of the parameter ``name`` with folds at a and none at b, b/a or a/b within ``ratio``,
    and the folds at a (:func:`ordinary_folds`).

    Hysteresis lies below sigma_c and above mu_c.  From SIGMA_START (MU_START) the value is
    halved or doubled until the answer changes, then bisected geometrically.  ValueError when
    the range (SIGMA_RANGE, MU_RANGE) holds no change.
    """
    below = name == "sigma"
    start, (low, high) = (SIGMA_START, SIGMA_RANGE) if below else (MU_START, MU_RANGE)
    found = {}

    def probe(s: float) -> bool:
        found[s] = ordinary_folds(at_parameter(model, name, s), comm, solver)
        return bool(found[s])

    yes = no = None
    s = start
    while yes is None or no is None:
        if not low <= s <= high:
            other = f"mu = {model.mu:g}" if below else f"sigma = {model.sigma:g}"
            raise ValueError(f"{'no hysteresis' if yes is None else 'hysteresis'} at {other} for {name} from "
                             f"{start:g} to {s / 2 if s > start else s * 2:g}")
        if probe(s):
            yes = s
            s = s * 2 if below else s / 2
        else:
            no = s
            s = s / 2 if below else s * 2
    while max(yes, no) / min(yes, no) > ratio:
        s = math.sqrt(yes * no)
        if probe(s):
            yes = s
        else:
            no = s
    return yes, no, found[yes]


# -- stage 2: the fold curve to its cusp ---------------------------------------------------------


@dataclass
class Cusp:
    """A cusp located on one grid: the fold problem, its continuation and the located event."""

    problem: FoldSystem[Problem]
    cont: Continuation
    found: Found

    @property
    def point(self) -> Point:
        """The located cusp."""
        return self.found.point

    def values(self) -> tuple[float, float, float]:
        """(s, lambda, F) at the cusp."""
        pt = self.found.point
        return pt.p, pt.values["lambda"], pt.values["F"]

    def destroy(self) -> None:
        """Free the PETSc objects."""
        self.cont.destroy()
        self.problem.destroy()


def _to_cusp(fp: FoldSystem[Problem], cont: Continuation, start: Point):
    """Run ``cont`` from ``start`` until the fold curve turns in s: the located event, or RuntimeError.

    After every step the borders of g become the null vectors there (:meth:`~petsc_adhesion.core.fold.FoldSystem.adapt`);
    the preconditioners, built with the old ones, are rebuilt.
    """
    finder = EventFinder(cont, [Fold(("cusp", "cusp"))])

    def on_step(a, b):
        finder(a, b)
        fp.adapt(b.x, b.p)
        cont.newton.reuse.expire()
        cont.bordered.reuse.expire()

    cont.run(start, on_step=on_step, until=lambda a, b: bool(finder.found))
    if not finder.found:
        assert cont.stop is not None, "a run ends with its reason"
        raise RuntimeError(f"the fold curve did not turn in {fp.parameter} from {start.p:.6g}: "
                           f"stopped ({cont.stop[0]}) at {fp.parameter} = {cont.points[-1].p:.6g}")
    return finder.found[0]


def trace_cusp(model, name: str, fold: dict, s0: float, direction: int, comm=None,
               settings: Settings = FOLD_SETTINGS, solver: SolverChoice = SolverChoice()) -> Cusp:
    """The cusp reached by continuing the ordinary fold ``fold`` (of :func:`ordinary_folds` at ``name`` =
    ``s0``) in ``name`` toward ``direction`` (+1: increasing), on the grid it was located on; the fold
    system's solves with the ``fold`` settings of ``solver``, its correctors with ``natural`` and
    ``arclength``."""
    fp = fold_system(model, fold["r"], name, s0, comm, solver.fold)
    cont = guess = None
    try:
        x = _state(fp, fold["r"], fold["H"], fold["lambda"])
        fp.adapt(x, s0, sweeps=2)
        guess = fp.create_vec()
        guess.setArray(x)
        cont = Continuation(fp, settings, natural=solver.natural, arclength=solver.arclength)
        start = cont.start(guess, s0, direction)
        return Cusp(fp, cont, _to_cusp(fp, cont, start))
    except BaseException:
        if cont is not None:
            cont.destroy()
        fp.destroy()
        raise
    finally:
        if guess is not None:
            guess.destroy()


# -- stage 3: refinement at the cusp ---------------------------------------------------------------


def _design(model, name: str, cusp: Cusp):
    """The grid about the cusp's contact edge: :func:`~petsc_adhesion.tracing.tracer.grid_for` at the radius
    of peak attraction, its fine band widened to reach the contact radius by a cohesive zone."""
    s = cusp.point.p
    at = at_parameter(model, name, s)
    peak, a = _edge(cusp.problem, cusp.point.x, s)
    band = max(BAND, abs(a - peak) + cohesive_zone(at, pressure_law(at)))
    return replace(grid_for(at, peak, 0, model.rmax), band=band)


def _relocate(cusp: Cusp, model, name: str, nodes: np.ndarray, direction: int, comm,
              solver: SolverChoice = SolverChoice()) -> Cusp | None:
    """The cusp of ``cusp`` located again on ``nodes``: from the start of the step that passed it (or an
    earlier point, if that fails), carried there and put on the new fold curve by a zero-length
    arclength correction, traced toward the cusp with steps no longer than that step.  Where the new
    grid's cusp lies behind that point in s, the correction lands on the fold curve's other branch,
    beyond the cusp, with s moving away from it: the curve is then followed backwards."""
    src, pts, j = cusp.problem, cusp.cont.points, cusp.found.segment
    length = max(pts[j + 1].ds, 1e-3)
    settings = replace(FOLD_SETTINGS, ds=length / 2, ds_max=length, max_steps=40)
    for a in reversed(pts[max(0, j - 3):j + 1]):
        fp, cont, guess, kept = fold_system(model, nodes, name, a.p, comm, solver.fold), None, None, False
        try:
            cont = Continuation(fp, settings, natural=solver.natural, arclength=solver.arclength)
            H, lam = _whole(src, a.x)
            Hdot, lamdot = _whole(src, a.xdot)
            x = _state(fp, src.base.r, H, lam)
            fp.adapt(x, a.p, sweeps=2)
            guess = fp.create_vec()
            guess.setArray(x)
            mine = fp.base.r[fp.base.lo:fp.base.lo + fp.nloc]
            start = cont.project(guess, a.p, fp.join(np.interp(mine, src.base.r, Hdot), lamdot), a.pdot)
            if start is not None:
                found = _to_cusp(fp, cont, start if start.pdot * direction > 0 else start.reversed())
                kept = True
                return Cusp(fp, cont, found)
        except (RuntimeError, FloatingPointError):
            pass
        finally:                    # on every path that does not hand them to the Cusp
            if guess is not None:
                guess.destroy()
            if not kept:
                if cont is not None:
                    cont.destroy()
                fp.destroy()
    return None


@dataclass(frozen=True)
class Critical:
    """The cusp of the fold curve: the critical value of ``name`` (sigma: sigma_c at the fixed mu; mu: mu_c
    at the fixed sigma) and the lambda and F there, each a :class:`~.measured.Measured` (its best value
    from the levels, its bar with the domain's share); ``domain``: the change of the critical value on the
    finest level from r_m to 2 r_m; per level (``levels``, ``n_nodes``) the values on it (``value_grid``,
    ``lam_grid``, ``F_grid``); the ``bracket`` of ordinary curves (with folds, without); the cusp's radius
    of peak attraction ``edge`` and ``contact_radius``; the ``model`` at the cusp (its roughness law, its
    r_m); the wall time; ``warning`` when the cusp lies outside the bracket (else None)."""

    name: str
    fixed: float
    value: Measured
    lam: Measured
    F: Measured
    domain: float
    levels: tuple
    n_nodes: tuple
    value_grid: tuple
    lam_grid: tuple
    F_grid: tuple
    bracket: tuple
    edge: float
    contact_radius: float
    model: Model = field(repr=False)
    wall_time_s: float = 0.0
    warning: str | None = None

    @property
    def kind(self) -> str:
        """sigma_c or mu_c."""
        return f"{self.name}_c"

    @property
    def fixed_name(self) -> str:
        """The parameter held: mu for sigma_c, sigma for mu_c."""
        return "mu" if self.name == "sigma" else "sigma"


def _critical(model, name: str, levels, comm, solver: SolverChoice) -> Critical:
    """The cusp in ``name`` (sigma: hysteresis below it; mu: above it) of ``model``: stages 1-3, every
    solver with its role's settings in ``solver``."""
    t0 = time.perf_counter()
    direction = 1 if name == "sigma" else -1
    yes, no, folds = bracket(model, name, comm, solver=solver)
    cusps = []
    try:
        for fold in folds:
            if fold["kind"] == "snap_on":
                cusps.append(trace_cusp(model, name, fold, yes, direction, comm, solver=solver))
        first = max(cusps, key=lambda c: direction * c.point.p)
        design = _design(model, name, first)
        at, src = {}, first
        # the refinement levels, each from the one before (nested nodes: a close start at large mu,
        # where the cohesive zone is a few nodes of the coarser grid), then the finest on a domain
        # twice as long: the truncation's share
        for level, grid in [(k, replace(design, level=k)) for k in sorted(levels)] + \
                [("domain", replace(design, level=max(levels), rmax=2 * design.rmax))]:
            nodes = grid.nodes()
            found = _relocate(src, model, name, nodes, direction, comm, solver)
            if found is None:
                raise RuntimeError(f"the cusp at {name} = {first.point.p:.6g} was not found again on "
                                   f"{'refinement level ' + str(level) if level != 'domain' else 'the longer domain'}"
                                   f" ({nodes.size} nodes)")
            at[level] = found.values() + (nodes.size,)
            cusps.append(found)
            src = found
        peak, contact = _edge(first.problem, first.point.x, first.point.p)
    finally:
        for c in cusps:
            c.destroy()
    longer = at.pop("domain")
    domain = [abs(longer[i] - at[max(levels)][i]) for i in range(3)]
    best = {k: extrapolate({level: v[i] for level, v in at.items()}) for i, k in enumerate(("s", "lambda", "F"))}
    s, s_err = best["s"]
    fixed = model.mu if name == "sigma" else \
        (pressure_law(model).sigma if model.roughness == "measured" else model.sigma)
    lo, hi = sorted((yes, no))
    keys = sorted(at)
    return Critical(name=name, fixed=fixed, value=Measured(s, s_err + domain[0]),
                    lam=Measured(best["lambda"][0], best["lambda"][1] + domain[1]),
                    F=Measured(best["F"][0], best["F"][1] + domain[2]), domain=domain[0], levels=tuple(keys),
                    n_nodes=tuple(at[k][3] for k in keys), value_grid=tuple(at[k][0] for k in keys),
                    lam_grid=tuple(at[k][1] for k in keys), F_grid=tuple(at[k][2] for k in keys),
                    bracket=(yes, no), edge=peak, contact_radius=contact, model=at_parameter(model, name, s),
                    wall_time_s=time.perf_counter() - t0,
                    warning=None if lo <= s <= hi else (f"the cusp at {name} = {s:.6g} lies outside the bracket "
                                                        f"[{lo:.6g}, {hi:.6g}] of the traced curves"))


def sigma_c(model, mu: float, grid_refinements=LEVELS, comm=None, solver: SolverChoice = SolverChoice()) -> Critical:
    """The critical roughness at Tabor parameter ``mu``: the largest sigma with hysteresis, the cusp of the
    fold curve in (sigma, lambda), with its error bar.

    Parameters
    ----------
    model : Model
        The roughness law and its parameters (its mu and sigma are replaced), r_m and the far field.
    mu : float
        Tabor parameter (eq. 9).
    grid_refinements : sequence of int
        Refinement levels of the grid at the cusp (nested, spacing / 2^level); three for the bar.
    comm : petsc4py.PETSc.Comm
        Communicator of every object (PETSc.COMM_WORLD by default): a study may run cases on
        subcommunicators.
    solver : SolverChoice
        The PETSc settings of the solvers by role: ``natural`` and ``arclength`` (the correctors of the
        ordinary curves and of the fold curve), ``fold`` (the fold system's bordered solves).  Settings
        of the ``fixed`` role, or a preconditioner other than dense, are refused (ValueError,
        :func:`check_solver`).

    Returns
    -------
    Critical
        sigma_c, lambda_c and F_c at the cusp (best values and bars from the levels), the values on
        each level, the levels and their nodes, the change on the finest level from r_m to 2 r_m
        (``domain``, part of the bars), the ``bracket`` of ordinary curves (with folds, without), the
        cusp's radius of peak attraction ``edge`` and ``contact_radius``, the model at the cusp,
        ``wall_time_s``; ``warning`` when the cusp lies outside the bracket.  ValueError when there is
        no hysteresis even at sigma = SIGMA_RANGE[0].
    """
    check_solver(solver, "sigma_c")
    return _critical(replace(model, mu=mu), "sigma", grid_refinements, comm or PETSc.COMM_WORLD, solver)


def mu_c(model, sigma: float, grid_refinements=LEVELS, comm=None, solver: SolverChoice = SolverChoice()) -> Critical:
    """The critical Tabor parameter at roughness ``sigma``: the smallest mu with hysteresis, the cusp of the
    fold curve in (mu, lambda), with its error bar; at sigma = 0 the onset of hysteresis of a smooth
    sphere.

    Parameters and result as :func:`sigma_c`, with mu and sigma exchanged.
    ValueError when there is no hysteresis up to mu = MU_RANGE[1].
    """
    check_solver(solver, "mu_c")
    return _critical(at_parameter(model, "sigma", sigma), "mu", grid_refinements, comm or PETSc.COMM_WORLD,
                     solver)


def configure_solvers(model, solver: SolverChoice = SolverChoice(), comm=None, made=None) -> None:
    """Make the solvers of a critical study once, solve with each once and free them again, before any
    work: each reads its options under its own prefix (:class:`~petsc_adhesion.core.newton.SolverOptions`),
    some of them only at its first solve, and ``made()`` (if given) is called while they live, so that an
    option no solver reads can be named; with -help each prints those it reads.  They are those of
    :func:`sigma_c` and :func:`mu_c`, on a small uniform grid at mu = MU_START and the far approach (what a solver reads does
    not depend on the size or the state): a curve's natural corrector (its first point) and arclength
    corrector (a zero-length correction there), and the fold system's bordered solves (its borders made
    the null vectors there); the fold curve's correctors are of the same two roles."""
    check_solver(solver, "-study_compute critical")
    comm = comm or PETSc.COMM_WORLD
    model = at_parameter(model, "mu", MU_START)   # a fold system continued in mu: any sigma, 0 too
    r = np.linspace(0.0, model.rmax or RMAX, 33)
    lam = far_approach(model)
    problem = Problem(model, r, create_influence(r, comm), Dense())
    cont = guess = fp = None
    try:
        cont = Continuation(problem, Settings(), natural=solver.natural, arclength=solver.arclength)
        guess = problem.rigid(lam, problem.create_vec())
        a = cont.start(guess, lam, 1)
        if not cont.arclength(a, 0.0).converged:
            raise RuntimeError(f"the arclength corrector did not converge at the far approach lambda = {lam:g}")
        fp = fold_system(model, r, "mu", MU_START, comm, solver.fold)
        fp.adapt(_state(fp, r, problem.gather(problem.separation(a.x)), lam), MU_START)
        if made is not None:
            made()
    finally:
        for obj in (fp, cont, guess):
            if obj is not None:
                obj.destroy()
        problem.destroy()
