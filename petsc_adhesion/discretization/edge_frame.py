"""The problem in the frame of the contact edge: r = a rho, the edge pinned at rho = 1.

At large mu the separation has a sharp feature at the contact edge, about
0.75 mu^-1.5 wide, that travels along the curve.  In the physical frame a
tangent predictor moves it only linearly, so every step must stay within a
fraction of its width.  In the frame r = a rho, with the contact radius a an
unknown and the edge pinned at rho = 1, the profile changes smoothly and the
steps can be long.  The kernel t/(t + r) K(k) depends on t/r alone, so the
influence matrix on the nodes a rho is a times that on rho.  The unknown is
the deformation D = H - a^2 rho^2 / 2 (H itself would change by r^2/a per
unit change of a far out, and make the curve look long), and eq. (12) reads

    G_i = D_i + lambda - c a sum_j Ahat_ij P(D_j + a^2 rho_j^2 / 2)            (eq. 12)
    G_a = D(1) + a^2 / 2 - level                                               (the pin)

with D(1) interpolated between its two nodes: the edge is where H reaches
:func:`edge_level`.  The unknowns are x = (D_0 .. D_{N-1}, a), a the last
entry (on the last rank); it implements the continuation's protocol.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..core.bordered import Border
from ..core.protocol import PressureLaw
from ..model.pressure import pressure_law
from ..model.reference.rigid import load_beyond, load_beyond_rates
from .contact import SMOOTH_LEVEL, SMOOTH_PEAK, deformation_at, edge_level, peak_attraction, rate_at
from .grid import l2_weights, load_weights
from .plumbing import Plumbing
from .problem import TO_WALL, norm_radius, step_scale

__all__ = ["EdgeFrameProblem", "edge_level", "SMOOTH_LEVEL", "SMOOTH_PEAK", "peak_attraction"]


class EdgeFrameProblem:
    """Eq. (12) on the nodes a rho with the contact edge pinned at rho = 1.

    Parameters
    ----------
    model : Model
    rho : numpy.ndarray
        The nodes in units of the contact radius, from 0 past 1.
    A : petsc4py.PETSc.Mat
        The influence matrix on ``rho`` (eq. 4, 12), dense, distributed by rows.
    scale : float
        The contact radius the grid was made for: it sets the norm's reach and
        the weight of a in it.
    pmat
        A strategy of :mod:`petsc_adhesion.discretization.preconditioning`.
    """

    parameter = "lambda"

    def __init__(self, model, rho: np.ndarray, A: PETSc.Mat, scale: float, pmat):
        self.model, self.rho, self.A, self.scale, self.pc = model, rho, A, scale, pmat
        self.plumbing = Plumbing(A, 1, self)     # owns A from here on
        self.comm, self._mpi, self.layout, self.jacobian = \
            self.plumbing.comm, self.plumbing.mpi, self.plumbing.layout, self.plumbing.jacobian
        self._serial = self._mpi.Get_size() == 1
        self.law = pressure_law(model)
        self.level = edge_level(self.law)
        self.c = model.coupling
        self.lo, self.hi, self.last = self.layout.lo, self.layout.hi, self.layout.last
        self.nloc, N = self.hi - self.lo, rho.size
        local = rho[self.lo:self.hi]
        self.half_rho2 = 0.5 * local * local
        self.q = (8.0 / 3.0) * load_weights(rho)[self.lo:self.hi]
        # the pin: H(1) = (1 - t) H_k + t H_{k+1}
        k = int(np.searchsorted(rho, 1.0)) - 1
        t = (1.0 - rho[k]) / (rho[k + 1] - rho[k])
        self.pin = np.zeros(N)
        self.pin[k], self.pin[k + 1] = 1.0 - t, t
        self._pin_local = self.pin[self.lo:self.hi]
        w = l2_weights(scale * rho, norm_radius(model))[self.lo:self.hi]
        # a relative change of the contact radius weighs like a change of H by the step unit (max(1, mu):
        # H and lambda grow like mu towards the JKR end, the relative changes of a stay of order one)
        self.weights = np.append(w, (step_scale(model) / scale) ** 2) if self.last else w
        self.dp, self.column, self.a = np.zeros(self.nloc), np.zeros(self.nloc), scale
        self.guarded = 0                  # Newton steps the domain guard shortened

    # -- x = (H, a) --------------------------------------------------------------------
    def create_vec(self) -> PETSc.Vec:
        """A vector (H, a), a on the last rank."""
        n1 = int(self.last)
        return PETSc.Vec().createMPI((self.nloc + n1, self.rho.size + 1), comm=self.comm)

    def _reduce(self, value, op=None):
        """``value`` reduced over the ranks by ``op`` (MPI.SUM by default); on one rank the value itself, as the
        reduction returns it: mpi4py's pickling reduction cost 70 us a call, 2 of a branch's 11 s of CPU at
        mu = 10 (about 27,000 calls; docs/fitting.md, "The speed of a curve fit")."""
        if self._serial:
            return value
        return self._mpi.allreduce(value, op=MPI.SUM if op is None else op)

    def _split(self, x: np.ndarray, pinned: bool = False):
        """(local H, a, and with ``pinned`` H(1)): one reduction."""
        h = x[:self.nloc]
        parts = np.array([x[self.nloc] if self.last else 0.0, self._pin_local @ h if pinned else 0.0])
        a, h1 = self._reduce(parts)
        return h, a, h1

    def separation(self, x: np.ndarray) -> np.ndarray:
        """The local H = D + a^2 rho^2 / 2 of a state x (collective)."""
        d, a, _ = self._split(x)
        return d + a * a * self.half_rho2

    def nodes(self, x: np.ndarray) -> np.ndarray:
        """The physical nodes a rho of a state x, all of them (collective)."""
        return self._split(x)[1] * self.rho

    def radius(self, x: np.ndarray) -> float:
        """The contact radius a of a state x (collective)."""
        return self._split(x)[1]

    def gather(self, local: np.ndarray) -> np.ndarray:
        """The whole nodal vector of local parts of H, on every rank."""
        return self.plumbing.gather(local)

    def radius_rate(self, point, a: float) -> float:
        """d(contact radius)/ds along a point's tangent: the rate of the unknown a (collective)."""
        return self.radius(point.xdot)

    def carry(self, source, point, scale: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The state and tangent of ``point`` of ``source``'s curve on this problem's local unknowns (collective).

        The nodes are taken at contact radius ``scale`` (default ``source``'s radius at the point):
        the deformation D and the tangent's nodal part interpolated at scale rho
        (:func:`~petsc_adhesion.discretization.contact.deformation_at`), then a and its rate
        (``source.radius_rate``: with adot left 0 this frame, which weighs a's relative change by
        (mu / a)^2, could orient its tangent against the curve's).
        """
        if scale is None:
            scale = source.radius(point.x)
        r = (scale * self.rho)[self.lo:self.hi]
        x, xdot = deformation_at(source, point.x, r), rate_at(source, point.x, point.xdot, r)
        adot = source.radius_rate(point, scale)
        if self.last:
            x, xdot = np.append(x, scale), np.append(xdot, adot)
        return x, xdot

    # -- eq. 12, 14, 26 in the frame of the edge ------------------------------------------
    def residual(self, X: PETSc.Vec, lam: float, G: PETSc.Vec) -> None:
        """G(D, a, lambda): eq. (12) on the nodes a rho, and the pin."""
        d, a, d1 = self._split(X.getArray(readonly=True), pinned=True)
        pressure, _ = self.law(d + a * a * self.half_rho2)
        g = d + lam - self.c * a * self.plumbing.multiply(pressure)
        G.setArray(np.append(g, d1 + 0.5 * a * a - self.level) if self.last else g)

    def dG_dp(self, X: PETSc.Vec, lam: float, out: np.ndarray) -> np.ndarray:
        """G_lambda: ones on the rows of eq. (12), zero on the pin."""
        out[:self.nloc] = 1.0
        out[self.nloc:] = 0.0
        return out

    def observe(self, x: np.ndarray, lam: float, xdot: np.ndarray, pdot: float):
        """The load F = (8/3) a^2 integral P rho drho (eq. 26) and its rate d/ds along the tangent."""
        d, a, _ = self._split(x)
        ddot, adot, _ = self._split(xdot)
        pressure, dpressure = self.law(d + a * a * self.half_rho2)
        hdot = ddot + 2 * a * adot * self.half_rho2
        S, dS = self._reduce(np.array([self.q @ pressure, self.q @ (dpressure * hdot)]))
        F, dF = a * a * S, 2 * a * adot * S + a * a * dS
        if self.model.farfield:                 # beyond r_m = a rho_m (problem.Problem.observe)
            rm = a * self.rho[-1]
            dlam, drm = load_beyond_rates(rm, lam)
            F, dF = F + load_beyond(rm, lam), dF + dlam * pdot + drm * self.rho[-1] * adot
        return {"F": float(F)}, {"F": float(dF)}

    @staticmethod
    def stable(point) -> bool:
        """Stable under displacement control: lambdadot > 0."""
        return point.pdot > 0

    # -- domain guard ----------------------------------------------------------------------
    def inside(self, x: np.ndarray) -> bool:
        """Every gap open and the contact radius positive, on all ranks."""
        d, a, _ = self._split(x)
        return self._reduce(bool(np.all(d + a * a * self.half_rho2 > self.law.wall)), MPI.LAND) and a > 0

    def step_fraction(self, x: np.ndarray, y: np.ndarray) -> float:
        """Largest fraction of x -> x - y that covers at most TO_WALL of the way to the wall,
        and at most halves the contact radius."""
        d, a, _ = self._split(x)
        yd, ya, _ = self._split(y)
        # H falls by yd + a ya rho^2 to first order in the step
        room, yh = d + a * a * self.half_rho2 - self.law.wall, yd + 2 * a * ya * self.half_rho2
        toward = yh > 0
        alpha = float(np.min(TO_WALL * room[toward] / yh[toward], initial=1.0))
        if ya > 0:
            alpha = min(alpha, 0.5 * a / ya)
        return self._reduce(alpha, MPI.MIN)

    def record_guard(self) -> None:
        """Count a Newton step the domain guard shortened (:meth:`step_fraction` below 1)."""
        self.guarded += 1

    def restore_counters(self, guarded: int) -> None:
        """Take up the count of guarded steps a checkpoint saved."""
        self.guarded = guarded

    # -- linearization -----------------------------------------------------------------------
    def linearize(self, X: PETSc.Vec, lam: float) -> None:
        """Set the point of the shell Jacobian: P'(H), a and the column dG/da = -c Ahat (P + a^2 rho^2 P')."""
        d, self.a, _ = self._split(X.getArray(readonly=True))
        pressure, self.dp = self.law(d + self.a * self.a * self.half_rho2)
        # dG/da = -c Ahat (P + a^2 rho^2 P')
        self.column = -self.c * self.plumbing.multiply(pressure + 2 * self.a * self.a * self.half_rho2 * self.dp)

    def jacobian_mult(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = J x, J = [[I - c a Ahat diag(P'), dG/da], [pin, a]] at the linearization point (the shell's)."""
        vh, va, v1 = self._split(x.getArray(readonly=True), pinned=True)
        yh = vh - self.c * self.a * self.plumbing.multiply(self.dp * vh) + va * self.column
        y.setArray(np.append(yh, v1 + self.a * va) if self.last else yh)

    def jacobian_diagonal(self, d: PETSc.Vec) -> None:
        """d = diag J (for -pc_type jacobi on the shell)."""
        dh = 1.0 - self.c * self.a * self.plumbing.diagonal() * self.dp
        d.setArray(np.append(dh, self.a) if self.last else dh)

    def _dp_all(self) -> np.ndarray:
        return self.plumbing.everywhere(self.dp)

    def jacobian_rows(self, out: np.ndarray) -> np.ndarray:
        """Local rows of dG/dD = I - c a Ahat diag(P'), dense, into ``out``."""
        np.multiply(self.A.getDenseArray(), -self.c * self.a * self._dp_all(), out=out)
        out[np.arange(self.nloc), np.arange(self.lo, self.hi)] += 1.0
        return out

    def band_values(self, ai: np.ndarray, aj: np.ndarray) -> np.ndarray:
        """Entries of dG/dD on the local CSR pattern (ai, aj)."""
        rows = np.repeat(np.arange(self.nloc), np.diff(ai))
        v = -self.c * self.a * self.A.getDenseArray()[rows, aj] * self._dp_all()[aj]
        v[rows + self.lo == aj] += 1.0
        return v

    def _own_border(self) -> Border:
        return Border(self.column, self.pin if self.last else None, self.a)

    def create_pmat(self, borders: int) -> PETSc.Mat | None:
        """The PC matrix of [[dG/dD, dG/da], [pin, a]] with ``borders`` more (1: the arclength corrector's)."""
        return self.pc.create(self.layout, self.comm, 1 + borders)

    def fill_pmat(self, P: PETSc.Mat, borders=()) -> None:
        """Assemble P at the linearization point, its own border first."""
        self.pc.fill(P, self, self.layout, [self._own_border(), *borders])

    def setup_pc(self, pc: PETSc.PC, bordered: bool = False) -> None:
        """Default preconditioner for the kind of P."""
        self.pc.setup_pc(pc, bordered, self.layout.N)

    def destroy(self) -> None:
        """Free the PETSc objects held here, the influence matrix included."""
        self.plumbing.destroy()
