"""The discrete adhesion problem: residual of eq. (12), its Jacobian, the load of eq. (26).

:class:`Problem` holds the discretization (grid, influence matrix, pressure
law) on the rows this rank owns and implements the problem protocol of the
continuation core (:mod:`petsc_adhesion.core.continuation`): the unknown x is the
nodal separation H, the parameter p the approach lambda, and the observable
along the curve is the load F.

    G_i = H_i + lambda - r_i^2/2 - c sum_j A_ij P(H_j)          (eq. 12)
    G_H v = v - c A (P'(H) v),  G_lambda = 1                    (eq. 23)
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..model.pressure import curvature, pressure_law, sigma_rates
from ..model.reference.jkr import jkr_zero_load
from ..model.reference.rigid import load_beyond, load_beyond_rates
from .contact import contact_radius, deformation_at, rate_at
from .grid import l2_weights, load_weights
from .plumbing import Plumbing
from .preconditioning import Dense

if TYPE_CHECKING:
    from ..core.protocol import PressureLaw

__all__ = ["Problem", "far_approach", "step_scale", "MU_SOFT", "norm_radius", "TO_WALL"]

#: Newton may cover at most this fraction of the way to the wall in one step.
TO_WALL = 0.9


def norm_radius(model) -> float:
    """Where the continuation's norm of H ends: the paper's domain, or three JKR contact radii at zero
    load when larger (mu > 1.9), beyond which H only shifts with lambda."""
    return max(10.0, 3.0 * jkr_zero_load(model.mu)[0]) if model.mu > 0 else 10.0


#: From this Tabor parameter on a sphere is soft: its curve is measured in units of mu (:func:`step_scale`).
MU_SOFT = 20.0


def step_scale(model) -> float:
    """The length unit of a soft sphere's curve: mu from MU_SOFT on, else 1.

    Towards the JKR end the curve is self-similar in lambda / mu and F (the
    deformation grows like mu, the contact radius like mu^(1/2), the load stays of
    order one): measured in units of mu its steps take the same number at any mu
    (the frame of the edge weighs the contact radius's relative change alike,
    :class:`~petsc_adhesion.discretization.edge_frame.EdgeFrameProblem`).  Below
    MU_SOFT curves are traced as they were, step for step.
    """
    return float(model.mu) if model.mu >= MU_SOFT else 1.0


def far_approach(model) -> float:
    """An approach with the sphere well out of reach of the surface forces: the default start.

    The rigid gap at r = 0 is then 3 + 2 mu above the wall of the roughness rule.
    """
    wall = pressure_law(model).wall
    return -(wall + 1.0) - 3.0 - 2.0 * model.mu


class Problem:
    """The adhesion problem on grid ``r`` with influence matrix ``A``.

    Parameters
    ----------
    model : Model
        mu, sigma and the roughness rule.
    r : numpy.ndarray
        All grid nodes (every rank holds them: N numbers).
    A : petsc4py.PETSc.Mat
        Influence matrix (eq. 4, 12), dense, distributed by rows.
    pmat
        What the preconditioner is built from: a strategy of
        :mod:`petsc_adhesion.discretization.preconditioning` (``Dense()`` by default).
    """

    #: Name of the continuation parameter, for monitors.
    parameter = "lambda"

    def __init__(self, model, r: np.ndarray, A: PETSc.Mat, pmat=None):
        self.model, self.r, self.A = model, r, A
        self.plumbing = Plumbing(A, 0, self)     # owns A from here on
        self.comm, self._mpi, self.layout, self.jacobian = \
            self.plumbing.comm, self.plumbing.mpi, self.plumbing.layout, self.plumbing.jacobian
        self.law = pressure_law(model)
        self.c = model.coupling
        self.lo, self.hi = self.layout.lo, self.layout.hi
        local = r[self.lo:self.hi]
        self.shape = 0.5 * local * local
        self.q = (8.0 / 3.0) * load_weights(r)[self.lo:self.hi]
        self.weights = l2_weights(r, norm_radius(model))[self.lo:self.hi]
        self.dp = np.zeros(self.hi - self.lo)
        self.pc = pmat if pmat is not None else Dense()
        self.guarded = 0                  # Newton steps the domain guard shortened
        self._own_law = self.law
        self._laws: dict[float, PressureLaw] = {}
        self._second: tuple[str, float] | None = None     # the parameter set_parameter set, and its value

    # -- state ------------------------------------------------------------------
    def create_vec(self) -> PETSc.Vec:
        """A vector of nodal values in the layout of G."""
        return self.plumbing.nodal_vec()

    def rigid(self, lam: float, H: PETSc.Vec) -> PETSc.Vec:
        """H = -lambda + r^2/2 (eq. 27), lifted where it would reach the wall.

        The lift keeps every gap at least 1 (zero smooth pressure), so the guess
        is inside the domain for any lambda.
        """
        H.setArray(np.maximum(self.shape - lam, self.law.wall + 1.0))
        return H

    # -- eq. 12, 14, 26 ---------------------------------------------------------
    def pressure(self, H: PETSc.Vec):
        """Nodal P and dP/dH (eq. 14) of the local part of H."""
        return self.law(H.getArray(readonly=True))

    def residual(self, H: PETSc.Vec, lam: float, G: PETSc.Vec) -> None:
        """G(H, lambda) of eq. (12) into G."""
        pressure, _ = self.pressure(H)
        G.setArray(H.getArray(readonly=True) + (lam - self.shape) - self.c * self.plumbing.multiply(pressure))

    def dG_dp(self, H: PETSc.Vec, lam: float, out: np.ndarray) -> np.ndarray:
        """G_lambda of eq. (23): ones, on the local rows."""
        out[:] = 1.0
        return out

    def load(self, H: PETSc.Vec, lam: float) -> float:
        """F = (8/3) integral_0^{r_m} P r dr (eq. 26), exact for piecewise-linear P, plus the far field
        beyond r_m when the model has it."""
        pressure, _ = self.pressure(H)
        return self._mpi.allreduce(float(self.q @ pressure)) + self.far_load(lam)

    def far_load(self, lam: float) -> float:
        """The rigid sphere's attraction beyond r_m (:func:`~petsc_adhesion.model.reference.load_beyond`) when the
        model is the half-infinite one, else 0."""
        return float(load_beyond(self.r[-1], lam)) if self.model.farfield else 0.0

    def observe(self, h: np.ndarray, lam: float, hdot: np.ndarray, lamdot: float):
        """The observable of the curve: the load F (eq. 26) and its rate dF/ds = (8/3) q . (P'(H) hdot).

        ``h`` and ``hdot`` are local parts of H and of the tangent's H part.  With
        the model's far field, the rigid sphere's attraction beyond r_m is added
        (the half-infinite domain; :func:`~petsc_adhesion.model.reference.load_beyond`).
        """
        pressure, dpressure = self.law(h)
        F, dF = self._mpi.allreduce(np.array([self.q @ pressure, self.q @ (dpressure * hdot)]))
        if self.model.farfield:
            F += load_beyond(self.r[-1], lam)
            dF += load_beyond_rates(self.r[-1], lam)[0] * lamdot
        return {"F": float(F)}, {"F": float(dF)}

    @staticmethod
    def stable(point) -> bool:
        """Stable under displacement control: lambdadot > 0.

        Along the curve det G_H has the sign of lambdadot, and the far branch is stable.
        """
        return point.pdot > 0

    # -- domain guard -------------------------------------------------------------
    def separation(self, x: np.ndarray) -> np.ndarray:
        """The local H of a state x (here x itself)."""
        return x

    def nodes(self, x: np.ndarray) -> np.ndarray:
        """The physical nodes of a state x, all of them (here the fixed grid)."""
        return self.r

    def gather(self, local: np.ndarray) -> np.ndarray:
        """The whole nodal vector of local parts, on every rank."""
        return self.plumbing.gather(local)

    # -- the contact edge, and a point carried onto this grid ---------------------------------
    def radius(self, h: np.ndarray) -> float:
        """The contact radius of a state: where H first rises through the edge level
        (:func:`~petsc_adhesion.discretization.contact.contact_radius`); collective."""
        return contact_radius(self, h)

    def radius_rate(self, point, a: float) -> float:
        """d(contact radius)/ds along the tangent of a point whose contact radius is a (collective): a central
        difference over a step that moves H by about 1e-6 of the contact radius."""
        xdot = point.xdot
        size = self._mpi.allreduce(float(np.max(np.abs(xdot), initial=0.0)), op=MPI.MAX)
        if size == 0.0:
            return 0.0
        h = 1e-6 * max(a, 1e-3) / size
        return (self.radius(point.x + h * xdot) - self.radius(point.x - h * xdot)) / (2 * h)

    def carry(self, source, point, scale: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The state and tangent of ``point`` of ``source``'s curve on this grid's local nodes (collective):
        the deformation H - r^2/2 interpolated, r^2/2 added back
        (:func:`~petsc_adhesion.discretization.contact.deformation_at`), and the tangent's nodal part;
        ``scale`` (a contact radius for the frame of the edge) is not needed here."""
        r = self.r[self.lo:self.hi]
        return deformation_at(source, point.x, r) + 0.5 * r * r, rate_at(source, point.x, point.xdot, r)

    def inside(self, h: np.ndarray) -> bool:
        """True when every gap of the local H values h is open, on all ranks."""
        return self._mpi.allreduce(bool(np.all(h > self.law.wall)), op=MPI.LAND)

    def step_fraction(self, h: np.ndarray, y: np.ndarray) -> float:
        """Largest fraction of the Newton step h -> h - y that covers at most TO_WALL of the way to the wall.

        Node by node; the same fraction on all ranks.
        """
        room = h - self.law.wall
        toward = y > 0
        return self._mpi.allreduce(float(np.min(TO_WALL * room[toward] / y[toward], initial=1.0)), op=MPI.MIN)

    def record_guard(self) -> None:
        """Count a Newton step the domain guard shortened (:meth:`step_fraction` below 1)."""
        self.guarded += 1

    def restore_counters(self, guarded: int) -> None:
        """Take up the count of guarded steps a checkpoint saved."""
        self.guarded = guarded

    # -- linearization --------------------------------------------------------------
    def linearize(self, H: PETSc.Vec, lam: float) -> None:
        """Set the point of the operator G_H (the shell :attr:`jacobian`)."""
        _, self.dp = self.pressure(H)

    def dp_all(self) -> np.ndarray:
        """P'(H) at the linearization point on all nodes, on every rank."""
        return self.plumbing.everywhere(self.dp)

    def jacobian_mult(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = G_H x = x - c A (P'(H) x) at the linearization point (eq. 23; the shell's)."""
        self.plumbing.multiply_into(self.dp * x.getArray(readonly=True), y)
        y.aypx(-self.c, x)

    def jacobian_diagonal(self, d: PETSc.Vec) -> None:
        """d = diag G_H = 1 - c A_ii P'_i, for -pc_type jacobi on the shell."""
        d.setArray(1.0 - self.c * self.plumbing.diagonal() * self.dp)

    def jacobian_rows(self, out: np.ndarray) -> np.ndarray:
        """Local rows of G_H = I - c A diag(P'), dense, into ``out``."""
        np.multiply(self.A.getDenseArray(), -self.c * self.dp_all(), out=out)
        out[np.arange(self.hi - self.lo), np.arange(self.lo, self.hi)] += 1.0
        return out

    def band_values(self, ai: np.ndarray, aj: np.ndarray) -> np.ndarray:
        """Entries of G_H on the local CSR pattern (ai, aj): exact there, the rest dropped."""
        rows = np.repeat(np.arange(self.hi - self.lo), np.diff(ai))
        v = -self.c * self.A.getDenseArray()[rows, aj] * self.dp_all()[aj]
        v[rows + self.lo == aj] += 1.0
        return v

    def create_pmat(self, borders: int) -> PETSc.Mat | None:
        """The preconditioning matrix of G_H with ``borders`` extra rows and columns; None: the operator itself."""
        return self.pc.create(self.layout, self.comm, borders)

    def fill_pmat(self, P: PETSc.Mat, borders=()) -> None:
        """Assemble P at the linearization point, with ``borders`` appended."""
        self.pc.fill(P, self, self.layout, list(borders))

    def setup_pc(self, pc: PETSc.PC, bordered: bool = False) -> None:
        """Default preconditioner for the kind of P."""
        self.pc.setup_pc(pc, bordered, self.layout.N)

    # -- a second parameter, for the fold system (core.fold) -------------------------------------
    def set_parameter(self, name: str, value: float) -> bool:
        """The problem at roughness sigma = ``value`` (its law's heights scaled) or Tabor parameter mu =
        ``value`` (the coupling c of eq. 12); False for a value that is not positive."""
        if not value > 0:
            return False
        if name == "sigma":
            self.law = self._law_at(value)
        elif name == "mu":
            self.law, self.c = self._own_law, self.model.with_parameter("mu", value).coupling
        else:
            raise ValueError(f"no parameter '{name}': sigma or mu")
        self._second = (name, value)
        return True

    def _law_at(self, sigma: float):
        """The pressure law at roughness sigma (a few kept: the difference quotients revisit them)."""
        if sigma not in self._laws:
            if len(self._laws) > 32:
                self._laws.clear()
            self._laws[sigma] = pressure_law(self.model.with_parameter("sigma", sigma))
        return self._laws[sigma]

    def domain_gap(self, h: np.ndarray) -> float:
        """The smallest H - wall over all nodes of the local H values h (collective)."""
        return self._mpi.allreduce(float(np.min(h - self.law.wall, initial=np.inf)), op=MPI.MIN)

    def _apply(self, u: np.ndarray) -> np.ndarray:
        """A u on the local rows."""
        return self.plumbing.multiply(u).copy()

    def _dot(self, u: np.ndarray, v: np.ndarray) -> float:
        return self._mpi.allreduce(float(np.dot(u, v)))

    def jacobian_transpose(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = G_H^T x = x - c diag(P') A^T x at the linearization point."""
        y.setArray(x.getArray(readonly=True) - self.c * self.dp * self.plumbing.multiply_transpose(x))

    def second_derivatives(self, h: np.ndarray, lam: float, v: np.ndarray, w: np.ndarray):
        """(w^T (dG_H/dH)[v], w^T (dG_H/dlambda) v) at the linearization point: G_H = I - c A diag(P'(H))
        (eq. 23) gives -c (A^T w) P''(H) v elementwise, and G_H does not depend on lambda.  P'' by
        :func:`~petsc_adhesion.model.pressure.curvature`."""
        return -(self.c * self.plumbing.multiply_transpose(w) * curvature(self.law, h) * v), 0.0

    def parameter_derivatives(self, name: str, h: np.ndarray, lam: float, v: np.ndarray, w: np.ndarray,
                              gap: float):
        """(dG/ds on the local rows, w^T (dG_H/ds) v) at the parameter set (:meth:`set_parameter`):

            G_sigma = -c A dP/dsigma,   w^T (dG_H/dsigma) v = -c w^T A (dP'/dsigma v),
            G_mu = -c' A P,             w^T (dG_H/dmu) v = -c' w^T A (P' v),   c' = dc/dmu = 3 c / (2 mu),

        the sigma derivatives by :func:`~petsc_adhesion.model.pressure.sigma_rates` (``gap``: the smallest
        H - wall, which bounds its step)."""
        assert self._second is not None, "set_parameter() before parameter_derivatives()"
        _, s = self._second
        if name == "sigma":
            c = self.c
            rate, slope = sigma_rates(self._law_at, s, h, gap)
        else:
            c = 1.5 * self.c / s
            rate, slope = self.law(h)
        return -c * self._apply(rate), -(c * self._dot(w, self._apply(slope * v)))

    def destroy(self) -> None:
        """Free the PETSc objects held here, the influence matrix included."""
        self.plumbing.destroy()
