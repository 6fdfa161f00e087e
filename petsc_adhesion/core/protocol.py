"""What the continuation core asks of a problem, and the point of a curve it gives back.

The core traces G(x, p) = 0 in one parameter p and knows nothing of adhesion.
It sees a problem only through :class:`ContinuationProblem` (in the manner of
pacopy's ``f``, ``df_dlmbda``, ``jacobian_solver``, ``inner``): the Newton
solver, the bordered arclength system, the continuation and the event finder
call nothing else.  Code that follows a curve over several discretizations
(the tracer, the error bars, the results, the checkpoint) needs a little more
of each discretization, :class:`TracedProblem`; the fold system
(:mod:`~petsc_adhesion.core.fold`) continues a turning point in a second
parameter through :class:`FoldBase`.  The adhesion problems evaluate a pressure
law of the model, :class:`PressureLaw`, which the discretization and the tracing
read too.  ``residual``, ``dG_dp`` and
``linearize`` get x as a PETSc Vec; the other members deal in the rank's local
parts (numpy arrays); parameters are floats.

The problems of this package: the adhesion problem in the physical frame
(:class:`~petsc_adhesion.discretization.problem.Problem`), in the frame of the
contact edge (:class:`~petsc_adhesion.discretization.edge_frame.EdgeFrameProblem`),
and the fold system built on the first
(:class:`~petsc_adhesion.core.fold.FoldSystem`); the tests add a scalar fold,
Bratu and a cusp.  Each is checked against finite differences of its residual
(tests/test_protocol.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:       # for the annotations only: importing petsc4py here would initialise it
    from petsc4py import PETSc

__all__ = ["Point", "ContinuationProblem", "TracedProblem", "FoldBase", "PressureLaw", "POINT_FIELDS", "check_point"]


@runtime_checkable
class ContinuationProblem(Protocol):
    """What the corrector, the tangents, the step control and the events need of a problem.

    The bordered matrix of the arclength corrector is [[G_x, G_p], [w xdot^T, pdot]]
    (eq. 25); a problem with unknowns of its own beyond x's nodal part (the frame
    of the edge, the fold system) borders G_x itself, and ``create_pmat`` /
    ``fill_pmat`` then put their own borders first.
    """

    #: the PETSc communicator of every object of the problem
    comm: PETSc.Comm
    #: the name of p, for monitors ("lambda")
    parameter: str
    #: G_x at the point of :meth:`linearize` (a PETSc Mat, often a shell)
    jacobian: PETSc.Mat
    #: local weights w of the inner product <u, v> = sum w u v of the continuation's norm
    weights: np.ndarray

    def create_vec(self):
        """A Vec in the layout of x and of G."""

    def residual(self, x, p: float, G) -> None:
        """G(x, p) into the Vec G, at the p passed in (nothing is stored on the problem)."""

    def dG_dp(self, x, p: float, out: np.ndarray) -> np.ndarray:
        """dG/dp on the local rows into ``out``; returns ``out``."""

    def linearize(self, x, p: float) -> None:
        """Set the point of :attr:`jacobian`."""

    def create_pmat(self, borders: int):
        """The Mat the preconditioner is built from for G_x with ``borders`` extra rows and columns
        (0: Newton at fixed p; 1: the bordered matrix); None: the operator itself."""

    def fill_pmat(self, P, borders=()) -> None:
        """Assemble P at the linearization point, with the :class:`~petsc_adhesion.core.bordered.Border`
        objects ``borders`` appended in order."""

    def setup_pc(self, pc, bordered: bool = False) -> None:
        """The default preconditioner for the square or the bordered matrix."""

    def inside(self, x: np.ndarray) -> bool:
        """Domain guard: whether the local part x is admissible (collective, the same on every rank)."""

    def step_fraction(self, x: np.ndarray, y: np.ndarray) -> float:
        """Domain guard: the largest fraction of the Newton step x -> x - y allowed (the same on every rank);
        a query, which changes nothing."""

    def record_guard(self) -> None:
        """Count one Newton step the guard shortened (Newton calls it when :meth:`step_fraction` is below 1)."""

    def observe(self, x: np.ndarray, p: float, xdot: np.ndarray, pdot: float) -> tuple[dict, dict]:
        """Named observables at (x, p) and their rates d/ds along the tangent (xdot, pdot)."""


@runtime_checkable
class TracedProblem(ContinuationProblem, Protocol):
    """What the tracer, the error bars, the results and the checkpoint need beside the protocol.

    A state x may hold unknowns beside the nodal separation (the contact radius in
    the frame of the edge); these members give its physical meaning, and
    :meth:`carry` puts a point of another problem's curve into this one's unknowns,
    so that code following a curve over grids asks no problem for its class.
    """

    #: the model (mu, sigma, roughness, r_m) the problem discretizes: a Model of model/parameters.py,
    #: which the core does not import (Any: object would refuse every use of it, and a problem's own type)
    model: Any

    @property
    def law(self) -> PressureLaw:
        """Its pressure law (:func:`~petsc_adhesion.model.pressure.pressure_law`), at the parameters of now."""

    #: the nodal rows [lo, hi) this rank owns
    lo: int
    hi: int
    #: rows of the nodal part on this rank, of all ranks, and whether this is the last rank (a Layout of
    #: discretization/preconditioning.py, which the core does not import)
    layout: Any
    #: Newton steps the domain guard shortened so far
    guarded: int

    def separation(self, x: np.ndarray) -> np.ndarray:
        """The local nodal separation H of a state x (collective)."""

    def nodes(self, x: np.ndarray) -> np.ndarray:
        """All physical nodes r of a state x, r_m the last (collective)."""

    def gather(self, local: np.ndarray) -> np.ndarray:
        """A whole nodal vector from its local parts, on every rank."""

    def radius(self, x: np.ndarray) -> float:
        """The contact radius of a state x (collective)."""

    def radius_rate(self, point: Point, a: float) -> float:
        """d(contact radius)/ds along the tangent of ``point``, whose contact radius is a (collective)."""

    def carry(self, source: TracedProblem, point: Point, scale: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The state x and tangent xdot of ``point`` of ``source``'s curve, on this problem's local unknowns
        (collective): how a curve goes on from one grid to another.  ``scale``: the contact radius to take
        in a frame that scales with it (default: ``source.radius`` at the point)."""

    def stable(self, point: Point) -> bool:
        """Stable under displacement control at a point of the curve."""

    def restore_counters(self, guarded: int) -> None:
        """Take up the count of guarded Newton steps (:attr:`guarded`) a checkpoint saved."""

    def destroy(self) -> None:
        """Free the PETSc objects of the problem."""


@runtime_checkable
class FoldBase(ContinuationProblem, Protocol):
    """What the fold system needs of a problem G(u, p; s) = 0 whose turning points in p it continues in s.

    Besides the protocol (for u at fixed p): the transpose of G_u, the second
    derivatives of G along the null vectors, and the second parameter s, set
    through the problem (never by writing its fields).
    """

    def set_parameter(self, name: str, value: float) -> bool:
        """Make the problem that of the second parameter ``name`` at ``value``; False (the problem
        unchanged) where ``value`` is outside the parameter's range."""

    def jacobian_transpose(self, u, y) -> None:
        """y = G_u^T u at the point of :meth:`linearize` (Vecs)."""

    def second_derivatives(self, u: np.ndarray, p: float, v: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, float]:
        """(w^T (dG_u/du)[v] on the local rows, w^T (dG_u/dp) v) at (u, p): the gradient of the fold's
        test function, negated (collective)."""

    def parameter_derivatives(self, name: str, u: np.ndarray, p: float, v: np.ndarray, w: np.ndarray,
                              gap: float) -> tuple[np.ndarray, float]:
        """(dG/ds on the local rows, w^T (dG_u/ds) v) for the second parameter s = ``name`` at (u, p)
        (collective); ``gap``: how far the state lies from the edge of its domain, which bounds a
        difference step."""

    def domain_gap(self, u: np.ndarray) -> float:
        """How far the local part u lies inside the domain at the current parameters (collective)."""

    def destroy(self) -> None:
        """Free the PETSc objects of the problem (the fold system owns its base problem)."""


@runtime_checkable
class PressureLaw(Protocol):
    """What the problems, the grids, the resolution check and the results ask of a pressure law.

    The surface stress P(H) at mean separation H in units of 8 gamma / (3 epsilon), P > 0
    repulsion: the Lennard-Jones law sigma_LJ(g) = g^-9 - g^-3 of a gap g = H + 1 (eq. 5)
    when smooth, else its average over the roughness heights S, E[sigma_LJ(H + 1 - S)]
    (eq. 7, 10) by a quadrature (eq. 14 for Gaussian heights).  The laws of
    :mod:`~petsc_adhesion.model.pressure` (which the core does not import) are the
    implementations: the paper's Gauss-Hermite rule (the class that module names
    ``PressureLaw``: one implementation of this protocol, not the protocol), the wall quadrature of heights
    bounded above (``WallLaw``) and the exact average over a measured histogram
    (``HistogramLaw``).  Read-only members: a law is not changed once made (a problem
    at another roughness takes another law).
    """

    @property
    def wall(self) -> float:
        """The H at or below which some gap H + 1 - S closes: the highest asperity's, S_max - 1."""

    @property
    def smooth(self) -> bool:
        """No roughness (sigma = 0): eq. (5) itself, no quadrature."""

    @property
    def rule(self) -> str:
        """The name of the height distribution and its average ("none", "hermite", "truncated_gaussian", ...)."""

    @property
    def n(self) -> int:
        """Points per node of the average (1 when smooth)."""

    @property
    def sigma(self) -> float:
        """The rms of the heights (units of epsilon)."""

    def __call__(self, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(P(H), dP/dH) at the nodal separations H, the derivative exact for the quadrature;
        FloatingPointError when some H is at or below :attr:`wall`."""

    def error(self, H: np.ndarray) -> np.ndarray:
        """An estimate of |P - the average P stands for| at H (zero where the rule is the model)."""

    def describe(self) -> dict:
        """The roughness model as result files record it ({} when smooth)."""



#: The fields of a :class:`Point` beside its vectors x and xdot.
POINT_FIELDS = ("p", "pdot", "values", "rates", "ds", "deviation", "newton_its", "ksp_its", "corrector")


@dataclass
class Point:
    """A computed point of the curve with its unit tangent (local parts of x)."""

    x: np.ndarray
    p: float
    xdot: np.ndarray
    pdot: float
    values: dict = field(default_factory=dict)   # observables
    rates: dict = field(default_factory=dict)    # their d/ds along the tangent
    ds: float = 0.0             # the step that reached it
    deviation: float = 0.0      # |corrector - predictor| / ds: the curvature the step met
    newton_its: int = 0         # Newton iterations of the corrector
    ksp_its: int = 0
    corrector: str = "start"    # "natural" | "arclength" | "start" | "event"

    def reversed(self) -> Point:
        """The same point with the curve's orientation reversed (tangent and rates negated)."""
        return replace(self, xdot=-self.xdot, pdot=-self.pdot, rates={k: -v for k, v in self.rates.items()})

    def state(self) -> dict:
        """The point as plain data: its local vectors and its fields (a checkpoint saves it)."""
        return {"x": self.x, "xdot": self.xdot, **{k: getattr(self, k) for k in POINT_FIELDS}}

    @classmethod
    def from_state(cls, d: dict, size: int | None = None) -> Point:
        """The point of :meth:`state`; ValueError for one that is not a point's (of ``size`` local unknowns)."""
        x, xdot = np.asarray(d["x"], dtype=float), np.asarray(d["xdot"], dtype=float)
        check_point(x, xdot, {k: d[k] for k in POINT_FIELDS}, size)
        return cls(x=x.copy(), xdot=xdot.copy(), **{k: d[k] for k in POINT_FIELDS})


def _real(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def check_point(x: np.ndarray, xdot: np.ndarray, fields: dict, size: int | None = None) -> None:
    """ValueError unless (x, xdot, fields) make a point of ``size`` local unknowns: finite vectors of that
    length, finite p, pdot, ds and deviation, counts that are counts, observables and rates of finite reals."""
    if x.ndim != 1 or xdot.shape != x.shape or (size is not None and x.size != size):
        raise ValueError(f"a point of {x.shape} unknowns where {size} are expected")
    if not (np.isfinite(x).all() and np.isfinite(xdot).all()):
        raise ValueError("a point whose state is not finite")
    if not all(_real(fields[k]) for k in ("p", "pdot", "ds", "deviation")) or fields["ds"] < 0:
        raise ValueError("a point whose parameter, tangent or step is not a finite real")
    if not all(isinstance(fields[k], int) and fields[k] >= 0 for k in ("newton_its", "ksp_its")):
        raise ValueError("a point whose iteration counts are not counts")
    if not all(isinstance(fields[k], dict) and all(isinstance(n, str) and _real(v) for n, v in fields[k].items())
               for k in ("values", "rates")) or not isinstance(fields["corrector"], str):
        raise ValueError("a point whose observables are not finite reals")


assert set(POINT_FIELDS) | {"x", "xdot"} == {f.name for f in fields(Point)}
