"""The library's two calls: the load-approach curve of a model, and the state at one fixed approach.

    from petsc_adhesion import Model, GridChoice, trace_curve, solve_at
    c = trace_curve(Model(mu=1.0))                          # grids that follow the contact edge, error bars
    print(c.pull_off.F.value, "+-", c.pull_off.F.err)
    s = solve_at(-2.0, Model(mu=1.0), GridChoice("uniform", n=201))

Each takes plain typed objects: the :class:`~petsc_adhesion.model.parameters.Model`
(mu, sigma, roughness, r_m, the far field, the physical inputs), a
:class:`GridChoice`, a :class:`SolverChoice` (the matrix handed to the
preconditioner, and each solver's PETSc settings, a
:class:`~petsc_adhesion.core.newton.PetscSettings` by role), the continuation's
:class:`~petsc_adhesion.core.continuation.Settings` (step control and stops;
:func:`curve_settings` gives a curve's) and a :class:`CurveRequest` (what the
curve reports).  They read nothing from PETSc's options database: each solver
takes its settings under a prefix of its own
(:class:`~petsc_adhesion.core.newton.SolverOptions`).  The command line and the
Python API (:mod:`petsc_adhesion.app`) are thin layers that read their options
into these objects and call these two functions.

    fast = SolverChoice(arclength=PetscSettings(ksp_type="bcgs", ksp_rtol=1e-11))
    c = trace_curve(Model(mu=1.0), solver=fast)

Collective: under MPI every rank calls them with the same arguments and gets
the same result.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from .. import brent
from ..core.continuation import Continuation, Settings
from ..core.start import start_petsc
from ..core.events import EVENT_TOL, Found, jumps
from ..core.newton import PC_REUSE_ITS, Newton, PetscSettings
from ..discretization import grid, preconditioning, resolution
from ..discretization.influence import create_influence
from ..discretization.problem import Problem, far_approach, step_scale
from ..model.reference.jkr import jkr_approach, jkr_load
from . import error_bars, results
from .legs import instrument_curve
from .curve import Curve, Diagnostics, ErrorEstimate, GridRecord, Program, Solution, SpringResult
from .measured import Missing
from .edge_grids import MU_TRUNCATED, RMAX, domain_load, grid_for
from .tracer import Segment, Tracer

__all__ = ["GridChoice", "SolverChoice", "PetscSettings", "check_inputs", "CurveRequest", "curve_settings", "trace_curve", "solve_at", "rigid_edge",
           "discretize", "configure_solvers", "expected_end", "F_MAX", "GRID_KINDS", "spring_start",
           "step_scale", "WALL_BEND_F", "wall_bend"]

#: The load at which a curve stops by default: past equilibrium, into compression.
F_MAX = 2.0
#: The node sets of :class:`GridChoice`.
GRID_KINDS = ("edge", "paper", "uniform", "given")


@dataclass(frozen=True)
class GridChoice:
    """The collocation grid: ``edge`` (graded about the contact edge and following it along the curve, out to
    r_m = 150 by default), ``paper`` (the paper's N = 531 on r_m = 10: uniform nodes with refined elements,
    :func:`~petsc_adhesion.discretization.grid.paper`), ``uniform`` (``n`` nodes) or ``given`` (the nodes ``r``,
    r_m their last)."""

    kind: str = "edge"
    n: int = grid.PAPER_UNIFORM + grid.PAPER_EXTRA
    paper_uniform: int = grid.PAPER_UNIFORM
    paper_extra: int = grid.PAPER_EXTRA
    paper_split: int = grid.PAPER_SPLIT
    paper_refine_from: float = 0.0
    r: np.ndarray | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        if self.kind not in GRID_KINDS:
            raise ValueError(f"grid kind '{self.kind}': expected one of {', '.join(GRID_KINDS)}")
        if (self.kind == "given") != (self.r is not None):
            raise ValueError("grid kind 'given' takes its nodes r, and only it")

    @property
    def default_rmax(self) -> float:
        """r_m when the model leaves it to the grid: 150 for grids that follow the edge, 10 (the paper's) else."""
        if self.kind == "given":
            assert self.r is not None, "a given grid holds its nodes (__post_init__)"
            return float(self.r[-1])
        return RMAX if self.kind == "edge" else grid.PAPER_RMAX

    @property
    def size(self) -> int | None:
        """The number of nodes, known before any is made; None for grids that follow the edge (made along the
        curve, each a few hundred to a few thousand nodes)."""
        return {"uniform": self.n, "paper": self.paper_uniform + self.paper_extra * (self.paper_split - 1),
                "given": None if self.r is None else len(self.r)}.get(self.kind)

    def nodes(self, rmax: float) -> np.ndarray | None:
        """The nodes on [0, rmax]; None for grids that follow the contact edge (made along the curve)."""
        if self.kind == "edge":
            return None
        if self.kind == "uniform":
            return grid.uniform(self.n, rmax)
        if self.kind == "given":
            return np.asarray(self.r, dtype=float)
        return grid.paper(rmax, self.paper_uniform, self.paper_extra, self.paper_refine_from, self.paper_split)


@dataclass(frozen=True)
class SolverChoice:
    """What the preconditioner of every solver is built from (``pmat``: dense, band or shell,
    :mod:`~petsc_adhesion.discretization.preconditioning`; ``band``: the half bandwidth of band), how long a
    preconditioner is kept (``pc_reuse_its``: while Krylov needs at most that many iterations), and the PETSc
    settings of each solver by its role (:class:`~petsc_adhesion.core.newton.PetscSettings`): ``natural``
    (the natural corrector and the first point, the command line's ``-nat_``), ``arclength`` (the arclength
    corrector and its tangents, ``-arc_``), ``fixed`` (the solve at one approach, no prefix), ``fold`` (the
    fold system's bordered solves, ``-fold_``; :class:`~petsc_adhesion.core.fold.FoldSystem` takes them from
    the critical-roughness calls, :func:`~petsc_adhesion.tracing.critical.sigma_c` and ``mu_c``).  Settings not given keep each solver's defaults; settings of a
    solver the call does not make are refused (ValueError)."""

    pmat: str = "dense"
    band: int = preconditioning.BAND
    pc_reuse_its: int = PC_REUSE_ITS
    natural: PetscSettings = PetscSettings()
    arclength: PetscSettings = PetscSettings()
    fixed: PetscSettings = PetscSettings()
    fold: PetscSettings = PetscSettings()

    def __post_init__(self):
        if self.pmat not in preconditioning.KINDS:
            raise ValueError(f"pmat '{self.pmat}': expected one of {', '.join(preconditioning.KINDS)}")
        for name in ("band", "pc_reuse_its"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
                raise ValueError(f"{name}: expected an integer >= 0, got {v!r}")
        for role in ("natural", "arclength", "fixed", "fold"):
            if not isinstance(getattr(self, role), PetscSettings):
                raise ValueError(f"{role}: expected a PetscSettings, got {getattr(self, role)!r}")

    def strategy(self):
        """A fresh preconditioning strategy of this kind."""
        return preconditioning.create(self.pmat, self.band)


@dataclass(frozen=True)
class CurveRequest:
    """What a curve reports.

    ``lambda_start``: the first approach (None: out of reach of the forces,
    :func:`~petsc_adhesion.discretization.problem.far_approach`); ``at_lambda``: approaches at which to
    record the state; ``event_tol``: the location tolerance of events in lambda; ``error_bars``: every event
    located again on nested levels of its grid for its best value and bar, refined to ``target_error`` when
    given; ``profiles``: H(r) and P(r) at every event; ``kinds``: the event kinds reported (None: all; the
    others are left out, unestimated); ``spring``: the stiffness K of a spring the approach is driven
    through (an AFM cantilever, units 2 pi R gamma / epsilon; None: a rigid machine), whose base
    Z = lambda + F / K jumps at its turning points (events jump_in, jump_off); ``cycles``: the energy each cycle
    dissipates (False: Missing, said so, and the events ``kinds`` leaves out not made into values: a fit's
    branch, :mod:`~petsc_adhesion.fitting.branches`, reads neither).
    """

    lambda_start: float | None = None
    at_lambda: tuple = ()
    event_tol: float = EVENT_TOL
    error_bars: bool = True
    target_error: float | None = None
    profiles: bool = False
    kinds: tuple | None = None
    spring: float | None = None
    cycles: bool = True

    def __post_init__(self):
        if self.spring is not None and not (self.spring > 0 and math.isfinite(self.spring)):
            raise ValueError(f"spring stiffness {self.spring!r}: expected a finite K > 0")


#: The largest distance of a rough sphere's load from its tangent's line in one step (units 2 pi R w; the
#: continuation's observable_bend) of the curves made to be read at fixed Z (a fit's branches, the family
#: table's nodes): where the roughness rule's outermost wall stops the sphere, dF/dlambda turns from 0 to 50
#: within 0.02 epsilon, a kink that steps bounded in F and in the state's norm alone pass over, the spline
#: through their points rounding it by 0.044 (mu = 0.0055, sigma = 1, behind K = 0.19: 15 times the noise of
#: 0.3%); with this bound 2.1e-4, in the same CPU.
WALL_BEND_F = 1e-3


def wall_bend(model) -> float:
    """The bound on the load's bend in a step for a curve of ``model`` read at fixed Z: WALL_BEND_F on a rough
    sphere (a rule with an outermost wall), none (inf) on a smooth one."""
    return WALL_BEND_F if model.sigma > 0 and model.roughness != "none" else math.inf


def curve_settings(scale: float = 1.0, **changes) -> Settings:
    """The continuation settings of a load-approach curve: the load F watched, stopping at F_MAX; the
    first and the largest step (ds, ds_max) in units of ``scale`` (:func:`step_scale`), and SNES's absolute
    tolerance and the events' location (``unit``).  The smallest
    (ds_min) stays absolute: where the contact forms at large mu the curve turns on the scale of the
    cohesive zone, not of mu (mu = 1000: steps of 2e-4 there)."""
    s = Settings(**{"observable": "F", "observable_max": F_MAX, **changes})
    return replace(s, ds=s.ds * scale, ds_max=s.ds_max * scale, unit=scale)


def rigid_edge(lam: float) -> float:
    """The contact edge of the rigid sphere at approach lam: the peak attraction, gap 3^(1/6) epsilon."""
    return float(np.sqrt(2.0 * max(0.0, lam + 3.0 ** (1.0 / 6.0) - 1.0)))


def discretize(model, r: np.ndarray, pmat=None, comm=None) -> Problem:
    """The problem on grid r: influence matrix (eq. 4, 12), pressure law, preconditioning strategy."""
    from petsc4py import PETSc

    return Problem(model, r, create_influence(r, comm or PETSc.COMM_WORLD), pmat)


def _init() -> None:
    """PETSc, on a library call from a process that has not started it (the options of the caller's argv
    are not read: a program reading them calls petsc4py.init itself first)."""
    start_petsc()


#: The physical inputs that must be finite and positive, and what each is.
_POSITIVE = (("radius", "the sphere's radius (m)"), ("young1", "Young's modulus (Pa)"),
             ("epsilon", "the equilibrium spacing epsilon (m)"))


def check_inputs(model, grid_choice: GridChoice = GridChoice(), solver: SolverChoice = SolverChoice(),
                 lam: float | None = None) -> None:
    """ValueError, one line naming the parameter and what it accepts, for arguments the library cannot
    compute with: mu or sigma not finite or negative, physical inputs that are not finite and positive, an
    approach that is not a finite real, objects of another type; before any work (the command line refuses
    the same in its options)."""
    from ..model.parameters import Model

    if not isinstance(model, Model):
        raise ValueError(f"model: expected a Model, got {type(model).__name__}")
    if not isinstance(grid_choice, GridChoice):
        raise ValueError(f"grid_choice: expected a GridChoice, got {type(grid_choice).__name__}")
    if not isinstance(solver, SolverChoice):
        raise ValueError(f"solver: expected a SolverChoice, got {type(solver).__name__}")
    for name in ("mu", "sigma"):
        v = getattr(model, name)
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v) \
                or v < 0:
            raise ValueError(f"{name}: expected a finite real >= 0, got {v!r}")
    if model.rmax is not None and not (math.isfinite(model.rmax) and model.rmax > 0):
        raise ValueError(f"rmax: expected a finite real > 0 (the end of the domain), got {model.rmax!r}")
    bodies = model.bodies
    if bodies is not None:
        given = [(f, what) for f, what in _POSITIVE] + \
            [(f, what) for f, what in (("gamma", "the work of adhesion (J/m^2)"), ("hamaker", "the Hamaker constant (J)"),
                                      ("radius2", "the second radius (m)"), ("young2", "the second modulus (Pa)"),
                                      ("rms", "the rms roughness (m)")) if getattr(bodies, f) is not None]
        for f, what in given:
            v = getattr(bodies, f)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or \
                    not math.isfinite(v) or v < 0 or (v == 0 and f != "rms"):
                raise ValueError(f"{f}: expected {what}, a finite real {'>= 0' if f == 'rms' else '> 0'}, got {v!r}")
    if lam is not None and (isinstance(lam, bool) or not isinstance(lam, (int, float, np.integer, np.floating))
                            or not math.isfinite(lam)):
        raise ValueError(f"lam: expected the approach, a finite real, got {lam!r}")
    # settings of a solver the call does not make: refused, as the command line refuses its options
    used = ("fixed",) if lam is not None else ("natural", "arclength")
    for role in ("natural", "arclength", "fixed", "fold"):
        if role not in used and getattr(solver, role) != PetscSettings():
            call = "solve_at" if lam is not None else "trace_curve"
            raise ValueError(f"solver.{role}: settings of a solver {call} does not make (it makes "
                             f"{' and '.join(used)}); leave them out")


def _domain(model, grid_choice: GridChoice):
    """``model`` with its r_m: its own, or the grid's default."""
    return model if model.rmax is not None else replace(model, rmax=grid_choice.default_rmax)


def configure_solvers(model, grid_choice: GridChoice = GridChoice(), solver: SolverChoice = SolverChoice(),
                      settings: Settings | None = None, lam: float | None = None, comm=None) -> None:
    """Make the solvers of a curve (or, at a fixed approach ``lam``, of the solve) and free them again: each
    reads its options, and with -help prints those it reads."""
    check_inputs(model, grid_choice, solver, lam)
    _init()
    from petsc4py import PETSc

    model = _domain(model, grid_choice)
    r = grid_choice.nodes(model.rmax)
    if r is None:
        r = grid_for(model, 0.0 if lam is None else rigid_edge(lam), rmax=model.rmax).nodes()
    problem = discretize(model, r, solver.strategy(), comm or PETSc.COMM_WORLD)
    try:
        if lam is None:
            Continuation(problem, settings or curve_settings(step_scale(model)), natural=solver.natural,
                         arclength=solver.arclength).destroy()
        else:
            Newton(problem, "", pc_reuse_its=solver.pc_reuse_its, settings=solver.fixed).destroy()
    finally:
        problem.destroy()


def trace_curve(model, grid_choice: GridChoice = GridChoice(), solver: SolverChoice = SolverChoice(),
                settings: Settings | None = None, request: CurveRequest = CurveRequest(), comm=None,
                checkpoint=None, progress=None, started=None) -> Curve:
    """The load-approach curve of ``model``: every event with its best value, error bar and landing, the
    pull-off, the resolution check and the warnings (collective).

    Parameters
    ----------
    model : Model
        Its ``rmax`` is the end of the domain (:attr:`GridChoice.default_rmax` when the caller takes the grid's).
    grid_choice, solver, request
        The grid, the preconditioning, what the curve reports.
    settings : Settings
        Step control and stops (default :func:`curve_settings`).
    comm : petsc4py.PETSc.Comm
        The communicator of every object (PETSc.COMM_WORLD by default): a study runs cases on parts of it.
    checkpoint
        Saves the run as it goes and restores the state it holds first: ``restore(tracer)`` returns
        (phase, seconds spent by phase, the error bars' estimates already made) or None,
        ``pause(tracer, phase, seconds, estimates)`` is called where the state is whole, with the
        estimates made so far in the order of the events (:class:`~petsc_adhesion.app.checkpoint.Checkpoint`):
        a restart does not locate again an event already estimated.
    progress
        Says how far the run is: ``due()``, ``update(fraction, text)``, ``line(text)``, ``reset()``
        (:class:`~petsc_adhesion.app.progress.Progress`).
    started
        Called once the first point and its tangent are computed (the solvers have then read their options).

    Raises RuntimeError when the curve cannot start; a curve that ends early is returned with its warnings
    (``complete`` False).
    """
    check_inputs(model, grid_choice, solver)
    if not isinstance(request, CurveRequest):
        raise ValueError(f"request: expected a CurveRequest, got {type(request).__name__}")
    _init()
    from petsc4py import PETSc

    comm = comm or PETSc.COMM_WORLD
    model = _domain(model, grid_choice)
    if grid_choice.kind == "edge" and not model.farfield and model.mu > MU_TRUNCATED:
        raise ValueError(f"farfield False (the model truncated at r_m) is traced in the physical frame, up to "
                         f"mu = {MU_TRUNCATED:g}: got mu = {model.mu:g}")
    settings = settings or curve_settings(step_scale(model))
    if not model.farfield and settings.observable == "F" and settings.observable_max > domain_load(model.mu, model.rmax):
        raise ValueError(f"settings.observable_max: {settings.observable_max:g} lies beyond the truncated model's "
                         f"domain at mu = {model.mu:g}: Hertz's contact reaches r_m = {model.rmax:g} at F = "
                         f"{domain_load(model.mu, model.rmax):.4g}; give at most that, a larger rmax, or farfield True")
    lam0 = far_approach(model) if request.lambda_start is None else request.lambda_start
    if request.spring and request.lambda_start is None:
        lam0 = min(lam0, spring_start(request.spring))
    nodes = grid_choice.nodes(model.rmax)
    t0 = t1 = time.perf_counter()
    tracer = Tracer(model, settings, results.curve_events(request.at_lambda, request.spring), request.event_tol, nodes=nodes,
                    pmat=solver.strategy(), rmax=model.rmax, comm=comm, natural=solver.natural,
                    arclength=solver.arclength)
    kinds = request.kinds
    kept = (lambda label: True) if kinds is None else (lambda label: label in kinds or label == "lambda")
    try:
        restored = checkpoint.restore(tracer) if checkpoint is not None else None
        phase, spent, made = restored or ("trace", {"trace": 0.0, "errors": 0.0}, ())
        bars: list[tuple[Segment, Found]] = []
        estimates: dict[int, error_bars.Estimate | Missing] = {}   # id of a located Found -> its Estimate, or Missing
        if restored and progress is not None:
            progress.line(f"going on from the checkpoint {checkpoint.name} at lambda "
                          f"{tracer.segments[-1].cont.points[-1].p:.6g}"
                          + (", to its error bars" if phase == "errors" else ""))
        end = expected_end(model, settings)

        def pause(tr, stage: str = "trace") -> None:
            """Where the state is whole: a checkpoint may be saved, progress said."""
            walls = {**spent, stage: spent[stage] + time.perf_counter() - (t0 if stage == "trace" else t1)}
            if checkpoint is not None:
                checkpoint.pause(tr, stage, walls, tuple(estimates[id(f)] for _, f in bars if id(f) in estimates))
            if progress is not None and progress.due():
                done = sum(id(f) in estimates for _, f in bars)
                progress.update(*(_status(tr, lam0, end) if stage == "trace" else
                                  (done / len(bars), f"error bars: {done} of {len(bars)} events done")))

        if phase == "trace":
            segments = tracer.run(lam0, started, pause)
            if request.spring:
                _reach_landings(tracer, results.spring_fold(tracer.events))
            jumps([seg.finder for seg in segments])
            spent["trace"] += time.perf_counter() - t0
        else:
            segments = tracer.segments
            if started:
                started()
        wall = spent["trace"]
        if request.error_bars:
            t1 = time.perf_counter()
            bars = [(seg, f) for seg in segments for f in seg.finder.found if kept(f.label)]
            if progress is not None:
                progress.reset()
            if len(made) > len(bars):
                raise ValueError(f"{len(made)} error-bar estimates for the {len(bars)} events of the curve restored")
            # the estimates of the checkpoint first, in the events' order (the restored finders' order)
            estimates |= {id(f): e for (_, f), e in zip(bars, made)}
            for seg, found in bars[len(made):]:
                pause(tracer, "errors")
                est = error_bars.event_errors(tracer, seg, found, request.target_error)
                estimates[id(found)] = Missing(results.NO_BAR) if est is None else est
            errors_wall = spent["errors"] + time.perf_counter() - t1
        traced = results.curve(segments, estimates, request.profiles, tracer, request.cycles, kept)
        mpi = comm.tompi4py()
        law = tracer.segments[0].problem.law
        grid_warning = mpi.bcast(resolution.check(model, law, traced.states, traced.folds)
                                 if mpi.Get_rank() == 0 else None)
        assessment = results.assess(segments, traced, grid_warning, request.at_lambda)
    finally:
        tracer.destroy()
    events = tuple(e for e in traced.events if kept(e.kind))
    estimate = ErrorEstimate(errors_wall, request.target_error, tuple(sorted({k for e in events for k in e.levels}))) \
        if request.error_bars else None
    diagnostics = Diagnostics(
        steps=traced.steps, rejected_steps=traced.rejected_steps, regrids=traced.regrids, folds=traced.folds,
        guard_activations=traced.guard_activations, smallest_step=traced.smallest_step,
        most_newton_its=traced.most_newton_its, most_ksp_its=traced.most_ksp_its, stop_reason=traced.stop_reason,
        wall_time_s=wall, lambda_start=lam0, wall_gap=traced.wall_gap, error_estimate=estimate)
    spring = None
    if traced.spring is not None:
        assert traced.spring.K is not None, "the cycle behind a spring holds its K"
        jumps_ = tuple(e for e in events if e.kind in ("jump_in", "jump_off"))
        spring = SpringResult(traced.spring.K, jumps_, traced.spring,
                              _instrument(traced.branch, jumps_, traced.spring.K, settings.observable_max))
    curve = Curve(model=model, program=Program.of(comm),
                  grid=GridRecord(traced.r, traced.starts, traced.n_nodes, traced.edges), branch=traced.branch,
                  events=events, pull_off=traced.pull_off if kept("F_min") else None, rigid=traced.rigid,
                  spring=spring, diagnostics=diagnostics, assessment=assessment)
    return mpi.bcast(curve if mpi.Get_rank() == 0 else None, root=0)


def solve_at(lam: float, model, grid_choice: GridChoice = GridChoice(), solver: SolverChoice = SolverChoice(),
             guess: tuple | None = None, comm=None, started=None) -> Solution:
    """The state at the one approach ``lam`` (eq. 12 by Newton, its PETSc settings ``solver.fixed``; collective).

    The grid that follows the contact edge is centred on the rigid sphere's edge at ``lam``.  ``guess``:
    (r, H) of an earlier state, interpolated as the initial guess (its deformation H - r^2/2 linearly); the
    rigid state of eq. (27) by default.  ``started``: called once the solver has read its options.
    RuntimeError when Newton does not converge.
    """
    check_inputs(model, grid_choice, solver, lam)
    _init()
    from petsc4py import PETSc

    comm = comm or PETSc.COMM_WORLD
    model = _domain(model, grid_choice)
    r = grid_choice.nodes(model.rmax)
    r = grid_for(model, rigid_edge(lam), rmax=model.rmax).nodes() if r is None else r
    problem, newton, H = discretize(model, r, solver.strategy(), comm), None, None
    try:                    # on failure too: the shell's context holds a cycle that gc cannot free
        newton = Newton(problem, "", pc_reuse_its=solver.pc_reuse_its, settings=solver.fixed)
        H = problem.rigid(lam, problem.create_vec())
        if guess is not None:
            r0, h0 = guess
            H.setArray(np.interp(r[problem.lo:problem.hi], r0, h0))
        t0 = time.perf_counter()
        ok = newton.solve(lam, H)
        wall = time.perf_counter() - t0
        if started:
            started()
        if not ok:
            raise RuntimeError(f"Newton did not converge at lambda = {lam:g} "
                               f"(reason {newton.snes.getConvergedReason()}); try -adh_guess or -snes_monitor")
        pressure, _ = problem.pressure(H)
        Hall = problem.gather(H.getArray(readonly=True))
        its, kits = newton.iterations
        solution = Solution(lam=lam, F=problem.load(H, lam), F_beyond=problem.far_load(lam), H0=float(Hall[0]),
                            r=np.asarray(r), H=Hall, P=problem.gather(pressure), snes_iterations=its,
                            ksp_iterations=kits, wall_time_s=wall, model=model, program=Program.of(comm),
                            grid=GridRecord(np.asarray(r)))
    finally:
        for obj in (H, newton, problem):
            if obj is not None:
                obj.destroy()
    return solution


def _instrument(branch, jumps, K: float, trigger: float):
    """The approach and retract a cantilever follows (:func:`~.legs.instrument_curve`), or Missing with the
    reason where the curve has none."""
    try:
        return instrument_curve(branch, jumps, K, trigger if math.isfinite(trigger) else None)
    except ValueError as e:
        return Missing(str(e))


def spring_start(K: float) -> float:
    """An approach where a spring of stiffness K still holds the sphere well (the default start of a
    curve behind it): the rigid sphere's load falls like -4 / (3 (1 - lambda)^2) far out (eq. 28), its
    slope |dF/dlambda| = 8 / (3 (1 - lambda)^3) is K / 2 here, and the jump-in (K + dF/dlambda = 0) lies
    ahead."""
    return 1.0 - (16.0 / (3.0 * K)) ** (1.0 / 3.0)


def _reach_landings(tracer, fold) -> None:
    """Trace the curve back from its start (:meth:`~.tracer.Tracer.extend_back`) far enough for the jumps
    off the contact to land: where the base Z of the spring ``fold`` falls below the smallest Z of its
    jump-offs (Z < lambda there, the load being tensile)."""
    offs = [fold.value(f.point) for seg in tracer.segments for f in seg.finder.found
            if f.event is fold and f.before < 0]
    first = tracer.segments[0].cont.points[0]
    if offs and min(offs) <= fold.value(first):
        tracer.extend_back(min(offs) - 1.0 - 1e-3 * abs(min(offs)))


def expected_end(model, settings) -> float:
    """Where a curve is expected to stop in lambda, for its progress lines: ``settings.p_max`` (-cont_lambda_max), or sooner
    where JKR's load (Johnson, Kendall & Roberts 1971) on its stable branch reaches the stop load
    ``settings.observable_max`` (-cont_F_max; at JKR's pull-off when that is below it); 0 for a rigid
    sphere (mu = 0), whose load rises steeply at contact.

    The fraction of a curve done is lambda's progress from the start towards this: rough,
    since the steps crowd where the contact forms and about the turning points (where
    lambda turns back and the fraction stands still), and JKR's stop misses a rough
    surface's; the time left it gives is a guide to its order of magnitude, too low on the
    approach and steadier past the snap-on.
    """
    end = 0.0
    if model.mu > 0 and math.isfinite(settings.observable_max):
        pull = (9.0 * math.pi / 8.0) ** (1.0 / 3.0) * math.sqrt(model.mu)     # JKR's least load
        hi = 2.0 * pull
        while jkr_load(hi, model.mu) < settings.observable_max:
            hi *= 2.0
        A = pull if settings.observable_max <= jkr_load(pull, model.mu) else \
            brent.root(lambda a: jkr_load(a, model.mu) - settings.observable_max, pull, hi)
        end = float(jkr_approach(A, model.mu))
    return min(end, settings.p_max)


def _status(tracer, lam0: float, end: float) -> tuple[float, str]:
    """(fraction done, text) of a curve being traced from ``lam0`` towards ``end``: the furthest lambda
    reached, the steps and the events so far."""
    segments = tracer.segments
    reached = max(p.p for seg in segments for p in seg.cont.points)
    steps = sum(len(seg.cont.points) - 1 for seg in segments)
    events = sum(len(seg.finder.found) for seg in segments)
    done = (reached - lam0) / (end - lam0) if end > lam0 else 0.0
    return min(max(done, 0.0), 0.99), (f"lambda {reached:.4g} (the curve should stop near {end:.3g}), "
                                       f"{steps} steps, {events} event{'s' * (events != 1)}")
