"""The bordered system of the pseudo-arclength corrector (eq. 24-25) and its SNES, role ``arc_``.

Newton on [G(x, p); Q] = 0, Q the hyperplane through the last point normal to its
tangent, has the Jacobian [[G_x, G_p], [w xdot^T, pdot]]: a PETSc MatNest holding the
problem's own operator, regular at a fold, where G_x is singular.  Its tangent solves
the same matrix with right-hand side (0, 1).  :class:`Border` is one extra column,
row and corner around a matrix, as the preconditioning matrices get them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from .newton import PC_REUSE_ITS, PCReuse, PetscSettings, Tolerances, create_snes, fresh_retry, guard, krylov_retry

__all__ = ["ARCLENGTH_PREFIX", "Bordered", "Border"]

#: Options prefix of the arclength corrector's role (its own prefix comes before it: SolverOptions).
ARCLENGTH_PREFIX = "arc_"


class Bordered:
    """The pseudo-arclength system [G(x, p); Q] = 0 and its SNES (eq. 24-25), role ``arc_``, with the user's
    PETSc ``settings`` (:class:`~petsc_adhesion.core.newton.PetscSettings`).

    X = (x, p) is one PETSc Vec, p its last entry (on the last rank), so the
    MatNest's blocks line up with X without index sets.
    """

    def __init__(self, problem, pc_reuse_its: int = PC_REUSE_ITS, tol: Tolerances = Tolerances(),
                 settings: PetscSettings = PetscSettings()):
        pb = self.pb = problem
        comm = self.comm = pb.comm
        self._mpi = comm.tompi4py()
        self.x, self.G = pb.create_vec(), pb.create_vec()
        self.nloc, N = self.x.getLocalSize(), self.x.getSize()
        self.last = comm.getRank() == comm.getSize() - 1
        n1 = 1 if self.last else 0
        self.X = PETSc.Vec().createMPI((self.nloc + n1, N + 1), comm=comm)
        self.rhs, self.z, self.start, self.R, self.r = (self.X.duplicate() for _ in range(5))

        def dense(rows, cols):
            M = PETSc.Mat().createDense((rows, cols), comm=comm)
            M.setUp()
            return M

        self.column = dense((self.nloc, N), (n1, 1))        # G_p
        self.row = dense((n1, 1), (self.nloc, N))           # weighted xdot^T
        self.corner = dense((n1, 1), (n1, 1))               # pdot
        self.gp = np.zeros(self.nloc)
        self.K = PETSc.Mat().createNest([[pb.jacobian, self.column], [self.row, self.corner]], comm=comm)
        self.pmat = pb.create_pmat(1)
        self.reuse = PCReuse(pc_reuse_its)
        self.snes: PETSc.SNES = None      # made below; None only until then (destroy() skips it)
        self.options = None
        try:
            self.snes, self.options = create_snes(comm, ARCLENGTH_PREFIX, self.form_function, self.R,
                                                  self.form_jacobian, self.K, self.pmat or self.K, pb.setup_pc,
                                                  self.precheck, full_steps=True, bordered=True, tol=tol,
                                                  settings=settings)
        except BaseException:           # a solver option refused: free what is made
            self.destroy()
            raise
        # the hyperplane Q of eq. (24): through (x0, p0), normal (xdot, pdot), at distance ds
        self.x0: np.ndarray | None = None
        self.xdot: np.ndarray | None = None
        self.p0, self.pdot, self.ds = 0.0, 1.0, 0.0
        self.p = 0.0
        # the (xdot, pdot) of the bottom row, as last set
        self.border: tuple[np.ndarray | None, float] = (None, 1.0)

    # -- X = (x, p) --------------------------------------------------------------
    def split(self, X: PETSc.Vec):
        """Local x part of X and p (broadcast from the last rank)."""
        a = X.getArray(readonly=True)
        p = float(a[self.nloc]) if self.last else None
        return a[:self.nloc], self._mpi.bcast(p, root=self.comm.getSize() - 1)

    def join(self, x: np.ndarray, p: float, X: PETSc.Vec | None = None) -> PETSc.Vec:
        """X (default: the solution Vec) set to (x, p)."""
        X = X or self.X
        X.setArray(np.append(x, p) if self.last else x)
        return X

    def inner(self, u: np.ndarray, v: np.ndarray) -> float:
        """<u, v> of local parts, summed over ranks."""
        return self._mpi.allreduce(float(np.dot(self.pb.weights * u, v)))

    def set_border(self, xdot: np.ndarray, pdot: float) -> None:
        """Bottom row (W xdot)^T, pdot of the bordered matrix."""
        self.border = (xdot, pdot)
        full = self._mpi.allgather(self.pb.weights * xdot)
        if self.last:
            self.row.getDenseArray()[:] = np.concatenate(full)
            self.corner.getDenseArray()[:] = pdot
        self.row.assemble()
        self.corner.assemble()
        self.K.assemble()

    # -- SNES callbacks ----------------------------------------------------------
    def form_function(self, snes, X, R):
        """[G(x, p); Q(x, p)] with Q of eq. (24)."""
        x, p = self.split(X)
        assert self.xdot is not None and self.x0 is not None, "solve() sets the hyperplane before SNES calls back"
        self.x.setArray(x)
        self.pb.residual(self.x, p, self.G)
        q = self.inner(self.xdot, x - self.x0) + self.pdot * (p - self.p0) - self.ds
        self.join(self.G.getArray(readonly=True), q, R)

    def form_jacobian(self, snes, X, K, P):
        """SNES Jacobian callback: the bordered operator at X, its PC matrix when stale."""
        x, self.p = self.split(X)
        self.x.setArray(x)
        self.linearize(self.reuse(snes.getKSP()))

    def linearize(self, refill: bool) -> None:
        """G_x and G_p at (self.x, self.p) and, with ``refill``, the bordered matrix for the PC."""
        pb = self.pb
        pb.linearize(self.x, self.p)
        pb.dG_dp(self.x, self.p, self.gp)
        self.column.getDenseArray()[:, 0] = self.gp
        self.column.assemble()
        if refill and self.pmat is not None:
            row = self.row.getDenseArray()[0] if self.last else None
            corner = float(self.corner.getDenseArray()[0, 0]) if self.last else 0.0
            pb.fill_pmat(self.pmat, [Border(self.gp, row, corner)])
            self.reuse.filled(self.x.getArray(readonly=True), self.p, *self.border)
        self.K.assemble()

    def precheck(self, X, Y, *args) -> bool:
        """Line-search pre-check: the domain guard on the x part of the step."""
        x, _ = self.split(X)
        return guard(self.pb, x, Y, Y.getArray(readonly=True)[:self.nloc])

    # -- use ---------------------------------------------------------------------
    def correct(self, a, ds: float, guess=None):
        """Solve for the point at distance ds from ``a`` along its tangent (eq. 24-25), from ``guess``
        (x, p) when given, else from the predictor.

        Returns (x, p, Newton its, KSP its), or None when Newton fails or
        the predictor leaves the domain.
        """
        x, p = (a.x + ds * a.xdot, a.p + ds * a.pdot) if guess is None else guess
        if not self.pb.inside(x):
            return None
        self.x0, self.p0, self.xdot, self.pdot, self.ds = a.x, a.p, a.xdot, a.pdot, ds
        self.set_border(a.xdot, a.pdot)
        if not fresh_retry(self.snes, self.join(x, p), self.reuse, self.start):
            return None
        x, p = self.split(self.X)
        return x.copy(), p, self.snes.getIterationNumber(), self.snes.getLinearSolveIterations()

    def tangent(self, x: np.ndarray, p: float, xdot: np.ndarray, pdot: float):
        """Unit tangent at (x, p) oriented along (xdot, pdot): solve [[G_x, G_p], [W xdot, pdot]] z = (0, 1).

        Returns (xdot, pdot, KSP its) or None when GMRES fails.
        """
        self.x.setArray(x)
        self.p = p
        self.set_border(xdot, pdot)
        self.rhs.set(0.0)
        if self.last:
            self.rhs.setValue(self.rhs.getSize() - 1, 1.0)
        self.rhs.assemble()
        ksp = self.snes.getKSP()
        if not krylov_retry(ksp, self.K, self.pmat or self.K, self.rhs, self.z, self.reuse, self.linearize,
                            self.r):
            return None
        zx, zp = self.split(self.z)
        norm = math.sqrt(self.inner(zx, zx) + zp * zp)
        return zx / norm, zp / norm, ksp.getIterationNumber()

    def state(self) -> dict:
        """What the solver keeps between solves: its preconditioner's fill point and border (:class:`PCReuse`)."""
        return self.reuse.state(self.snes.getKSP())

    def restore(self, state: dict) -> None:
        """Fill the preconditioning matrix where :meth:`state`'s solver last filled it (as
        :meth:`~petsc_adhesion.core.newton.Newton.restore`); ValueError for a state that is not one."""
        if not isinstance(state["pending"], bool):
            raise ValueError("a preconditioner's state that is not one")
        if state["at"] is not None:
            x, p, xdot, pdot = state["at"]
            x, xdot = np.asarray(x, dtype=float), np.asarray(xdot, dtype=float)
            if x.shape != (self.nloc,) or xdot.shape != x.shape or not (np.isfinite(x).all() and np.isfinite(xdot).all()
                                                                        and np.isfinite([float(p), float(pdot)]).all()):
                raise ValueError("a preconditioner filled at a point that is not one")
            self.x.setArray(x)
            self.p = float(p)
            self.set_border(xdot, float(pdot))
            self.linearize(True)
        self.reuse.restore(state["pending"])

    def destroy(self) -> None:
        """Free the PETSc objects made here."""
        for obj in (self.snes, self.K, self.pmat, self.column, self.row, self.corner,
                    self.X, self.rhs, self.z, self.start, self.R, self.r, self.x, self.G, self.options):
            if obj is not None:
                obj.destroy()


@dataclass
class Border:
    """One extra column, row and corner around a matrix (the last rank holds the row).

    ``column``: its local rows of everything before it (G_x's rows, then the rows
    of earlier borders on the last rank); ``row``: the whole row over everything
    before it (on the last rank only; None elsewhere); ``corner``: the diagonal entry.
    """

    column: np.ndarray
    row: np.ndarray | None
    corner: float
