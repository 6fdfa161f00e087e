"""The PETSc plumbing both frames of the adhesion problem share.

The problem in the physical frame (:class:`~petsc_adhesion.discretization.problem.Problem`)
and in the frame of the contact edge
(:class:`~petsc_adhesion.discretization.edge_frame.EdgeFrameProblem`) differ in
their unknowns and equations, not in how they talk to PETSc: both hold an
influence matrix A distributed by rows (eq. 4, 12), multiply nodal vectors by
it and by its transpose, gather nodal vectors to every rank, scatter P'(H) to
all nodes for the dense rows of the preconditioner, and expose G_x as a shell
Mat.  :class:`Plumbing` is that part, held by each problem (composition, in the
manner of ContactMechanics' ``SystemBase`` holding the substrate it is built
on): made once, destroyed once, its objects owned by it alone.
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from .preconditioning import Layout

__all__ = ["Plumbing", "local_diagonal"]


class Plumbing:
    """A's layout and work vectors, the gathers, and the shell Mat of a problem's Jacobian.

    Parameters
    ----------
    A : petsc4py.PETSc.Mat
        The influence matrix, dense, distributed by rows; the plumbing owns it from here on.
    borders : int
        Unknowns beyond the nodal ones, on the last rank (0: the physical frame; 1: the frame of the
        edge, its contact radius).
    owner
        The problem whose ``jacobian_mult(x, y)`` (y = G_x x) and ``jacobian_diagonal(d)`` (d = diag G_x)
        the shell Mat calls.
    """

    def __init__(self, A: PETSc.Mat, borders: int, owner):
        self.A = A
        self.comm = A.getComm()
        self.mpi = self.comm.tompi4py()
        lo, hi = A.getOwnershipRange()
        self.layout = Layout(lo, hi, A.getSize()[0], self.comm.getRank() == self.comm.getSize() - 1)
        self._in, self._out = A.createVecs()         # what A multiplies, and its product
        # made at the first call of everywhere()
        self._scatter: PETSc.Scatter = None
        self._local: PETSc.Vec = None
        self._all: PETSc.Vec = None
        self._diagonal: np.ndarray | None = None
        self.jacobian = PETSc.Mat().createPython(self.layout.sizes(borders), _Shell(owner), comm=self.comm)
        self.jacobian.setUp()

    def nodal_vec(self) -> PETSc.Vec:
        """A new Vec of nodal values in A's row layout."""
        return self.A.createVecLeft()

    def multiply(self, u: np.ndarray) -> np.ndarray:
        """A u on the local rows, for the local part u of a nodal vector (a view, valid until the next call)."""
        self._in.setArray(u)
        self.A.mult(self._in, self._out)
        return self._out.getArray(readonly=True)

    def multiply_into(self, u: np.ndarray, y: PETSc.Vec) -> None:
        """y = A u, for the local part u of a nodal vector."""
        self._in.setArray(u)
        self.A.mult(self._in, y)

    def multiply_transpose(self, x) -> np.ndarray:
        """A^T x on the local rows, x a nodal Vec or its local part (a view, valid until the next call)."""
        if not isinstance(x, PETSc.Vec):
            self._in.setArray(x)
            x = self._in
        self.A.multTranspose(x, self._out)
        return self._out.getArray(readonly=True)

    def gather(self, local: np.ndarray) -> np.ndarray:
        """The whole nodal vector of its local parts, on every rank."""
        return np.concatenate(self.mpi.allgather(np.asarray(local)))

    def everywhere(self, local: np.ndarray) -> np.ndarray:
        """The whole nodal vector of its local parts on every rank by a PETSc scatter (made at the first call):
        the dense rows of G_x need P'(H) on all nodes at every linearization."""
        if self._scatter is None:
            self._local = self._in.duplicate()
            self._scatter, self._all = PETSc.Scatter.toAll(self._local)
        self._local.setArray(local)
        self._scatter.scatter(self._local, self._all, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
        return self._all.getArray(readonly=True)

    def diagonal(self) -> np.ndarray:
        """The local part of A's diagonal (A does not change: taken once)."""
        if self._diagonal is None:
            self._diagonal = local_diagonal(self.A)
        return self._diagonal

    def destroy(self) -> None:
        """Free every PETSc object held here, the influence matrix included."""
        for obj in (self.jacobian, self._in, self._out, self.A):
            obj.destroy()
        if self._scatter is not None:
            for obj in (self._scatter, self._local, self._all):
                obj.destroy()


class _Shell:
    """MatPython context of a problem's G_x: y = G_x x and its diagonal (for -pc_type jacobi), both the
    problem's own; the shell keeps no state."""

    def __init__(self, owner):
        self.owner = owner

    def mult(self, mat, x, y):
        """y = G_x x."""
        self.owner.jacobian_mult(x, y)

    def getDiagonal(self, mat, d):
        """d = diag G_x."""
        self.owner.jacobian_diagonal(d)


def local_diagonal(A: PETSc.Mat) -> np.ndarray:
    """The local part of A's diagonal (the Vec PETSc makes for it freed at once)."""
    d = A.getDiagonal()
    try:
        return d.getArray(readonly=True).copy()
    finally:
        d.destroy()
