"""The results of the library as values: a load-approach curve, its events, its cycles, a fixed-approach solution.

:func:`~petsc_adhesion.tracing.trace.trace_curve` returns a :class:`Curve`,
:func:`~petsc_adhesion.tracing.trace.solve_at` a :class:`Solution`: plain frozen
objects, the same on every rank, holding what was computed.  Learnt from
BifurcationKit's ``ContResult`` (a branch and its special points) and
``SpecialPoint`` (a value with its precision and status): every quantity with an
error bar is a :class:`~.measured.Measured`, what a run did not compute a
:class:`~.measured.Missing` (or None where it does not exist, e.g. Z without a
spring); no dict.  The result files are made from these objects by
:mod:`petsc_adhesion.io` alone (one serializer per format), which also names
their keys.  A new quantity of an event is one field here and, where it is not
read generically, one line in a serializer (docs/architecture.md).

Units (docs/model.md): lambda and H in epsilon, F in 2 pi R gamma (eq. 26,
negative when tensile), r and contact radii in sqrt(epsilon R), P in
8 gamma / (3 epsilon), energies in 2 pi R gamma epsilon.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..version import __version__
from .measured import Measured, Missing

if TYPE_CHECKING:
    from ..model.parameters import Model

__all__ = ["Profile", "Landing", "Event", "Branch", "Cycle", "SpringResult", "ErrorEstimate", "Diagnostics",
           "Assessment", "Program", "GridRecord", "Curve", "Solution", "EVENT_KINDS"]

#: The kinds of events of a curve (:mod:`~petsc_adhesion.tracing.results` names them).
EVENT_KINDS = ("snap_on", "snap_off", "F_min", "F_max", "equilibrium", "lambda", "jump_in", "jump_off")


@dataclass(frozen=True)
class Profile:
    """The state at an event on the nodes ``r``: the separation ``H`` (eq. 12) and the pressure ``P`` (eq. 14)."""

    r: np.ndarray = field(repr=False)
    H: np.ndarray = field(repr=False)
    P: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class Landing:
    """Where the jump from a fold lands: the other stable branch at the fold's lambda (behind a spring, at its
    Z, ``lam`` then moved by the spring's extension).  ``lam`` is the fold's best lambda (with a rigid
    machine) or its own best value and bar (behind a spring); ``F`` its best load, bar and grid value."""

    lam: Measured
    F: Measured
    H0: float
    Z: Measured | None = None
    contact_radius: Measured | None = None
    profile: Profile | None = None


@dataclass(frozen=True)
class Event:
    """One event of a curve: its best values and bars.

    ``kind``: snap_on, snap_off (the turning points in lambda), F_min, F_max (the
    extrema of the load; the most tensile F_min is the pull-off under load control),
    equilibrium (F = 0), lambda (a state asked for), or behind a spring jump_in and
    jump_off (the turning points of its base Z = lambda + F / K; ``stable`` is then
    None, the state marginal under the spring).  ``lam``, ``F``, ``Z`` and
    ``contact_radius`` are :class:`~.measured.Measured`: the best value
    (Richardson-extrapolated over nested grids), its bar and the value on the grid
    the event was located on (no bar and no grid value without an error estimate:
    ``note`` says why when one was tried).  ``Z`` is None without a spring.
    ``stable`` is None at a fold (marginal).  ``F_beyond``: the part of F from the
    rigid sphere's attraction beyond r_m (half-infinite model; None without an
    error estimate).  ``levels``: the refinement levels it was located on;
    ``target_met``: whether -target_error was reached (None without one tried);
    ``refinement_note``: why refinement stopped short.  ``landing``: where the
    jump from a fold lands.  ``profile``: H and P at the event when asked for.
    """

    kind: str
    lam: Measured
    F: Measured
    H0: float
    Z: Measured | None = None
    contact_radius: Measured | None = None
    stable: bool | None = None
    F_beyond: float | None = None
    levels: tuple[int, ...] = ()
    target_met: bool | None = None
    note: str | None = None
    refinement_note: str | None = None
    landing: Landing | None = None
    profile: Profile | None = None


@dataclass(frozen=True)
class Branch:
    """The computed points of a curve, one entry each in the order traced: lambda = alpha / epsilon, F (eq.
    26), H0 = H(0), stability under displacement control (lambdadot > 0), the contact radius (on the grid of
    the point), the step that reached it (0 at the start), Newton and Krylov iterations, d lambda / ds and
    the corrector; behind a spring its base Z = lambda + F / K and the stability under it (dZ/ds > 0),
    None without one."""

    lam: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    H0: np.ndarray = field(repr=False)
    stable: np.ndarray = field(repr=False)
    contact_radius: np.ndarray = field(repr=False)
    ds: np.ndarray = field(repr=False)
    newton_its: np.ndarray = field(repr=False)
    ksp_its: np.ndarray = field(repr=False)
    lambdadot: np.ndarray = field(repr=False)
    corrector: np.ndarray = field(repr=False)
    Z: np.ndarray | None = field(default=None, repr=False)
    stable_spring: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def from_points(cls, points, radii, K: float | None = None) -> Branch:
        """The branch of the core's points (:class:`~petsc_adhesion.core.protocol.Point`) and their contact
        radii; ``K``: the stiffness of the spring the approach is driven through (None: a rigid machine)."""
        lam = np.array([p.p for p in points])
        F = np.array([p.values["F"] for p in points])
        spring = {} if K is None else {             # its base Z = lambda + F / K, stable where dZ/ds > 0
            "Z": lam + F / K, "stable_spring": np.array([p.pdot + p.rates["F"] / K > 0 for p in points])}
        return cls(lam=lam, F=F, H0=np.array([p.x[0] for p in points]),
                   stable=np.array([p.pdot > 0 for p in points]),
                   contact_radius=np.array(radii, dtype=float), ds=np.array([p.ds for p in points]),
                   newton_its=np.array([p.newton_its for p in points]),
                   ksp_its=np.array([p.ksp_its for p in points]),
                   lambdadot=np.array([p.pdot for p in points]),
                   corrector=np.array([p.corrector for p in points], dtype="S9"), **spring)


@dataclass(frozen=True)
class Cycle:
    """One quasi-static approach-retract cycle (:mod:`~petsc_adhesion.tracing.energy`): the energy it
    dissipates (units 2 pi R gamma epsilon; a true 0 without hysteresis on a curve traced through; Missing
    with its reason when the cycle was not closed), the number of its hysteresis ``loops`` (None where the
    energy is missing) and the stiffness ``K`` of the machine's spring (None: the rigid machine)."""

    energy: Measured | Missing
    loops: int | None
    K: float | None = None


@dataclass(frozen=True)
class SpringResult:
    """Behind a spring of stiffness ``K`` (units 2 pi R gamma / epsilon): its jumps (jump_in, jump_off, in the
    order found), its cycle and the ``legs`` the instrument records (an
    :class:`~.legs.InstrumentCurve`: approach and retract; Missing with its reason where the curve has no
    state stable behind the spring; None where not made)."""

    K: float
    jumps: tuple[Event, ...]
    cycle: Cycle
    # an InstrumentCurve | Missing | None, typed object: legs.py builds on this module, not the reverse
    legs: object = field(default=None, repr=False)


@dataclass(frozen=True)
class ErrorEstimate:
    """What the error bars cost and reached: their wall time, the -target_error asked for (None: none) and
    the refinement levels the events were located on."""

    wall_time_s: float
    target_error: float | None
    levels: tuple[int, ...]


@dataclass(frozen=True)
class Diagnostics:
    """How the curve was traced: steps taken and rejected, regrids, turning points passed, the domain guard's
    activations, the smallest step, the most iterations of a corrector, why it stopped, the wall time, the
    start, the least gap to the wall of the roughness rule, and the error bars' cost (None: none made)."""

    steps: int
    rejected_steps: int
    regrids: int
    folds: int
    guard_activations: int
    smallest_step: float
    most_newton_its: int
    most_ksp_its: int
    stop_reason: str
    wall_time_s: float
    lambda_start: float
    wall_gap: float
    error_estimate: ErrorEstimate | None = None


@dataclass(frozen=True)
class Assessment:
    """What makes a curve untrustworthy, one line each (``warnings``), the subset that makes it not what was
    asked for (``incomplete``: the command line's exit status 3), among them the resolution check's
    ``grid_warning`` (None: the grids resolve the cohesive zone)."""

    warnings: tuple[str, ...]
    incomplete: tuple[str, ...]
    grid_warning: str | None = None

    @property
    def complete(self) -> bool:
        return not self.incomplete


@dataclass(frozen=True)
class Program:
    """What every result says about the program that made it: versions and ranks."""

    program: str
    version: str
    petsc_version: str
    petsc4py_version: str
    mpi_ranks: int

    @classmethod
    def of(cls, comm) -> Program:
        """This program on ``comm`` (PETSc's)."""
        import petsc4py
        from petsc4py import PETSc

        return cls("petsc-adhesion", __version__, "%d.%d.%d" % PETSc.Sys.getVersion(), petsc4py.__version__,
                   comm.getSize())


@dataclass(frozen=True)
class GridRecord:
    """The collocation grid: the nodes ``r`` (of the last segment when the grid followed the contact edge)
    and, for a curve, where each segment starts in lambda, its nodes and the edge its grid is centred on
    (None on a fixed grid)."""

    r: np.ndarray = field(repr=False)
    lam: np.ndarray | None = field(default=None, repr=False)
    n_nodes: np.ndarray | None = field(default=None, repr=False)
    edge: np.ndarray | None = field(default=None, repr=False)

    @property
    def largest(self) -> int:
        """The nodes of the largest grid."""
        return int(self.r.size if self.n_nodes is None else max(self.n_nodes))


@dataclass(frozen=True)
class Curve:
    """A load-approach curve: its branch of computed points, its events, its pull-off, its cycles, how it was
    traced and what is wrong with it.

    ``model``: the :class:`~petsc_adhesion.model.parameters.Model` it was computed for; ``program`` and
    ``grid`` records; ``branch``: the points (:class:`Branch`); ``events`` in the order found; ``pull_off``
    the most tensile load minimum (load control; None without one); ``rigid``: the cycle of a rigid machine;
    ``spring``: behind a spring, its jumps and cycle (else None); ``diagnostics``; ``assessment``;
    ``spread``: the events under other roughness laws (:class:`~.model_spread.ModelSpread`), set by the
    caller that computed it (``dataclasses.replace``; the command line does for every rough run), Missing
    where it could not be, None where none was asked for (a smooth model, ``-adh_model_spread false``,
    the library's :func:`~.trace.trace_curve` alone).  It is no part of the assessment: a law that moves an
    event warns (:attr:`ModelSpread.warnings`) but leaves the curve complete.
    """

    model: Model = field(repr=False)
    program: Program = field(repr=False)
    grid: GridRecord = field(repr=False)
    branch: Branch = field(repr=False)
    events: tuple[Event, ...]
    pull_off: Event | None
    rigid: Cycle
    spring: SpringResult | None
    diagnostics: Diagnostics = field(repr=False)
    assessment: Assessment = field(repr=False)
    # a ModelSpread | Missing | None, typed object: model_spread traces curves and imports this module, not
    # the reverse (no import cycle, not even for the checker)
    spread: object = field(default=None, repr=False)

    @property
    def complete(self) -> bool:
        """Whether the curve is what was asked for (the command line's exit status 0, not 3)."""
        return self.assessment.complete

    @property
    def warnings(self) -> list:
        """What makes the curve untrustworthy, one line each (the command line's WARNING lines)."""
        return list(self.assessment.warnings)

    def events_of(self, kind: str) -> tuple:
        """The events of one kind: snap_on, snap_off, F_min, F_max, equilibrium, lambda, jump_in or jump_off."""
        return tuple(e for e in self.events if e.kind == kind)

    @property
    def lam(self) -> np.ndarray:
        """lambda at every computed point."""
        return self.branch.lam

    @property
    def F(self) -> np.ndarray:
        """F at every computed point."""
        return self.branch.F

    @property
    def H0(self) -> np.ndarray:
        """H(0) at every computed point."""
        return self.branch.H0

    @property
    def stable(self) -> np.ndarray:
        """Stability under displacement control at every computed point."""
        return self.branch.stable

    @property
    def contact_radius(self) -> np.ndarray:
        """The contact radius of every computed point (docs/numerics.md; units sqrt(epsilon R))."""
        return self.branch.contact_radius

    @property
    def Z(self) -> np.ndarray | None:
        """Behind a spring, its base position Z = lambda + F / K at every computed point (else None)."""
        return self.branch.Z

    @property
    def instrument(self):
        """Behind a spring, the approach and the retract its cantilever follows
        (:class:`~.legs.InstrumentCurve`, or Missing with the reason); None without a spring."""
        return None if self.spring is None else self.spring.legs

    def keeping_profiles(self, kinds: tuple | None) -> Curve:
        """This curve with the profiles (H and P at an event and at its landing) of the events of ``kinds``
        alone (None: all it has), as a study keeps a case (-study_profiles): the others' arrays are no part
        of its files, nor of its checkpoint."""
        if kinds is None:
            return self

        def kept(e: Event) -> Event:
            if e.kind in kinds:
                return e
            landing = None if e.landing is None else replace(e.landing, profile=None)
            return replace(e, profile=None, landing=landing)

        spring = None if self.spring is None else replace(self.spring, jumps=tuple(map(kept, self.spring.jumps)))
        return replace(self, events=tuple(map(kept, self.events)),
                       pull_off=None if self.pull_off is None else kept(self.pull_off), spring=spring)


@dataclass(frozen=True)
class Solution:
    """The state at one fixed approach ``lam``: H(r) (eq. 12) and P(r) (eq. 14) on the nodes r, the load F
    (eq. 26; ``F_beyond`` of it from beyond r_m), H0 = H(0), the solver's iterations and wall time, and the
    model, program and grid it was computed with."""

    lam: float
    F: float
    H0: float
    F_beyond: float
    r: np.ndarray = field(repr=False)
    H: np.ndarray = field(repr=False)
    P: np.ndarray = field(repr=False)
    snes_iterations: int
    ksp_iterations: int
    wall_time_s: float
    model: Model = field(repr=False)
    program: Program = field(repr=False)
    grid: GridRecord = field(repr=False)

