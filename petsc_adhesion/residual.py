"""Residual G(H, lambda) of eq. (12), its Jacobian, and the load of eq. (26).

One :class:`Problem` holds the discretization (grid, influence matrix, pressure
law) and the linearization point; the fixed-lambda solve and the continuation
both call it, so nothing is copied between them.

    G_i = H_i + lambda - r_i^2/2 - c sum_j A_ij P(H_j)          (eq. 12)
    G_H v = v - c A (P'(H) v),  G_lambda = 1                    (eq. 23)
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .grid import l2_weights, load_weights
from .options import TABLE
from .pressure import PressureLaw

__all__ = ["Problem", "PCReuse", "preallocation", "shorten_to_wall", "TO_WALL"]

#: Newton may cover at most this fraction of the way to the wall in one step.
TO_WALL = 0.9


class Problem:
    """The discrete problem on the rows this rank owns.

    Parameters
    ----------
    model : Model
    r : ndarray
        All grid nodes (every rank holds them: N numbers).
    A : PETSc.Mat
        Influence matrix (eq. 4, 12), dense, distributed by rows.
    pmat : {"dense", "band", "shell"}
        What the preconditioner is built from: the assembled Jacobian, its
        near-field band as AIJ, or nothing (the shell itself).
    band : int
        Half bandwidth of ``pmat="band"``.
    reuse_its : int
        Keep the preconditioner while the last Krylov solve took at most this
        many iterations (0: rebuild at every Newton iteration).
    """

    def __init__(self, model, r: np.ndarray, A: PETSc.Mat, pmat: str = TABLE["adh_pmat"].default,
                 band: int = TABLE["adh_pmat_band"].default, reuse_its: int = TABLE["adh_pc_reuse_its"].default):
        self.model, self.r, self.A = model, r, A
        self.comm = A.getComm()
        self.law = PressureLaw(model.sigma, model.roughness, model.hermite_points)
        self.c = model.coupling
        self.lo, self.hi = A.getOwnershipRange()
        rl = r[self.lo:self.hi]
        self.shape = 0.5 * rl * rl
        self.q = (8.0 / 3.0) * load_weights(r)[self.lo:self.hi]
        self.w = l2_weights(r)[self.lo:self.hi]
        self.lam = 0.0
        self.p, self.Ap = A.createVecs()
        self.dp = np.zeros(self.hi - self.lo)
        self.J = PETSc.Mat().createPython(A.getSizes(), _Jacobian(self), comm=self.comm)
        self.J.setUp()
        self.pmat_kind = pmat
        self.P = {"dense": self._dense_pmat, "band": lambda: self._band_pmat(band),
                  "shell": lambda: self.J}[pmat]()
        self._gather = None
        self.reuse = PCReuse(reuse_its)

    # -- vectors ---------------------------------------------------------
    def create_vec(self) -> PETSc.Vec:
        return self.A.createVecLeft()

    def rigid(self, lam: float, H: PETSc.Vec) -> PETSc.Vec:
        """H = -lambda + r^2/2 (eq. 27), lifted where it would reach the wall.

        The lift keeps every gap at least 1 (zero smooth pressure), so the guess
        is inside the domain for any lambda.
        """
        H.setArray(np.maximum(self.shape - lam, self.law.wall + 1.0))
        return H

    # -- eq. 12 and 26 ---------------------------------------------------
    def pressure(self, H: PETSc.Vec):
        """Nodal P and dP/dH (eq. 14) of the local part of H."""
        return self.law(H.getArray(readonly=True))

    def residual(self, H: PETSc.Vec, lam: float, G: PETSc.Vec) -> None:
        """G(H, lambda) of eq. (12)."""
        p, _ = self.pressure(H)
        self.p.setArray(p)
        self.A.mult(self.p, self.Ap)
        G.setArray(H.getArray(readonly=True) + (lam - self.shape) - self.c * self.Ap.getArray(readonly=True))

    def load(self, H: PETSc.Vec) -> float:
        """F = (8/3) integral_0^{r_m} P r dr (eq. 26), exact for piecewise-linear P."""
        p, _ = self.pressure(H)
        return self.comm.tompi4py().allreduce(float(self.q @ p))

    def load_rate(self, h: np.ndarray, th: np.ndarray) -> tuple[float, float]:
        """F (eq. 26) of the local H values h, and its rate dF/ds = (8/3) q . (P'(H) th)."""
        p, dp = self.law(h)
        F, dF = self.comm.tompi4py().allreduce(np.array([self.q @ p, self.q @ (dp * th)]))
        return float(F), float(dF)

    def inner(self, u: np.ndarray, v: np.ndarray) -> float:
        """(1/r_m) integral u v dr on local parts, summed over ranks."""
        return self.comm.tompi4py().allreduce(float(np.dot(self.w * u, v)))

    # -- Jacobian --------------------------------------------------------
    def inside(self, h: np.ndarray) -> bool:
        """True when every gap of the local H values h is open, on all ranks."""
        return self.comm.tompi4py().allreduce(bool(np.all(h > self.law.wall)), op=MPI.LAND)

    def linearize(self, H: PETSc.Vec, assemble: bool = True) -> None:
        """Set the point of G_H (the shell) and, with ``assemble``, refill the PC matrix."""
        _, self.dp = self.pressure(H)
        if assemble and self.pmat_kind == "dense":
            self.jacobian_rows(self.P.getDenseArray())
            self.P.assemble()
        elif assemble and self.pmat_kind == "band":
            self.P.setValuesCSR(*self.band_values())
            self.P.assemble()

    def dp_all(self) -> np.ndarray:
        """P'(H) on all nodes, on every rank."""
        if self._gather is None:
            self._dpv = self.create_vec()
            self._gather, self._dpall = PETSc.Scatter.toAll(self._dpv)
        self._dpv.setArray(self.dp)
        self._gather.scatter(self._dpv, self._dpall, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return self._dpall.getArray(readonly=True)

    def jacobian_rows(self, out: np.ndarray) -> np.ndarray:
        """Local rows of G_H = I - c A diag(P'), dense, into ``out``."""
        np.multiply(self.A.getDenseArray(), -self.c * self.dp_all(), out=out)
        out[np.arange(self.hi - self.lo), np.arange(self.lo, self.hi)] += 1.0
        return out

    def _dense_pmat(self) -> PETSc.Mat:
        P = PETSc.Mat().createDense(self.A.getSizes(), comm=self.comm)
        P.setUp()
        return P

    def band_pattern(self):
        """Local CSR pattern (row pointers, global columns) of |i - j| <= band."""
        return self._band_ai, self._band_aj

    def band_values(self):
        """Near field of G_H in CSR: the entries within the band, exact; the far field dropped."""
        j = self._band_aj
        v = -self.c * self.A.getDenseArray()[self._band_rows, j] * self.dp_all()[j]
        v[self._band_rows + self.lo == j] += 1.0
        return self._band_ai, j, v

    def _band_pmat(self, band: int) -> PETSc.Mat:
        N = self.r.size
        rows = np.arange(self.lo, self.hi)
        first = np.maximum(rows - band, 0)
        last = np.minimum(rows + band, N - 1)
        counts = (last - first + 1).astype(PETSc.IntType)
        self._band_ai = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
        self._band_aj = (first.repeat(counts) + np.arange(counts.sum())
                         - np.repeat(self._band_ai[:-1], counts)).astype(PETSc.IntType)
        self._band_rows = np.repeat(np.arange(self.hi - self.lo), counts)
        P = PETSc.Mat().createAIJ(self.A.getSizes(), nnz=preallocation(self._band_ai, self._band_aj,
                                                                     self.lo, self.hi), comm=self.comm)
        P.setUp()
        return P

    # -- SNES callbacks ----------------------------------------------------
    def form_function(self, snes, H, G):
        self.residual(H, self.lam, G)

    def form_jacobian(self, snes, H, J, P):
        self.linearize(H, assemble=self.reuse(snes.getKSP()))

    def precheck(self, H: PETSc.Vec, Y: PETSc.Vec, *args) -> bool:
        """Shorten the Newton step H - Y so that no gap closes (domain guard).

        Allowed: at most TO_WALL of the distance to the wall of the roughness
        rule, node by node; all ranks scale by the same factor.
        """
        return shorten_to_wall(self, H.getArray(readonly=True), Y)


def preallocation(ai: np.ndarray, aj: np.ndarray, lo: int, hi: int):
    """(diagonal, off-diagonal) block counts per local CSR row, columns [lo, hi) owned here."""
    rows = np.repeat(np.arange(ai.size - 1), np.diff(ai))
    d = np.bincount(rows, weights=(aj >= lo) & (aj < hi), minlength=ai.size - 1).astype(PETSc.IntType)
    return d, (np.diff(ai) - d).astype(PETSc.IntType)


class PCReuse:
    """When to refill a preconditioning matrix: only when its factorization got stale.

    PETSc's PCSetUp refactors only a matrix whose state changed, so a matrix
    left alone keeps its factorization across Newton iterations and
    continuation steps.  Refill when the last Krylov solve of ``ksp`` failed or
    took more than ``its`` iterations, or after :meth:`expire`.
    """

    def __init__(self, its: int):
        self.its, self.stale = its, True

    def expire(self) -> None:
        self.stale = True

    def __call__(self, ksp: PETSc.KSP) -> bool:
        refill = self.stale or ksp.getConvergedReason() < 0 or ksp.getIterationNumber() > self.its
        self.stale = False
        return refill


def shorten_to_wall(problem: Problem, h: np.ndarray, Y: PETSc.Vec, y: np.ndarray | None = None) -> bool:
    """Scale the step Y (new H = h - y) so that H stays TO_WALL short of the wall.

    ``y`` is the part of Y acting on H when Y also holds other unknowns.
    """
    y = Y.getArray(readonly=True) if y is None else y
    room = h - problem.law.wall
    toward = y > 0
    alpha = float(np.min(TO_WALL * room[toward] / y[toward], initial=1.0))
    alpha = problem.comm.tompi4py().allreduce(alpha, op=MPI.MIN)
    if alpha < 1.0:
        Y.scale(alpha)
        return True
    return False


class _Jacobian:
    """MatPython context of G_H: y = x - c A (P'(H) x)."""

    def __init__(self, problem: Problem):
        self.pb = problem

    def mult(self, mat, x, y):
        pb = self.pb
        pb.p.setArray(pb.dp * x.getArray(readonly=True))
        pb.A.mult(pb.p, y)
        y.aypx(-pb.c, x)

