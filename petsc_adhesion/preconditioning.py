"""The matrix handed to the preconditioner: G_x assembled dense, its near field as AIJ, or none.

One strategy serves both systems the solvers see: G_x alone (Newton at a
fixed parameter, the natural corrector) and the bordered matrix of the
arclength corrector (eq. 25),

    [[G_x,        dG/dp ],
     [w xdot^T,   pdot  ]],

whose extra column and row (the row on the last rank) are appended here, in
one place.  The problem supplies its Jacobian's local rows, dense
(``jacobian_rows``) or within a band (``band_values``).

==========  ======================================  ====================================
kind        matrix                                  default PC (1 rank / more)
==========  ======================================  ====================================
dense       G_x assembled, dense                    LU / block Jacobi, dense LU blocks
band        |i - j| <= band of G_x, AIJ             LU / block Jacobi + ILU; any PC
shell       none: the operator itself               none
==========  ======================================  ====================================

On a dense block PETSc's default sub-preconditioner of block Jacobi, ILU(0),
has the full pattern and is the LU factorization itself.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

__all__ = ["Border", "Layout", "Dense", "Band", "Shell", "KINDS", "BAND", "create"]

#: Half bandwidth of the near field kept by ``band``.
BAND = 64


@dataclass
class Border:
    """The extra column, row and corner of the bordered matrix."""

    column: np.ndarray          # local rows of dG/dp
    row: np.ndarray | None      # the whole weighted tangent w xdot, on the last rank only
    corner: float               # pdot


@dataclass(frozen=True)
class Layout:
    """Row layout of G_x on this rank: rows [lo, hi) of N; the border row lives on the last rank."""

    lo: int
    hi: int
    N: int
    last: bool

    @property
    def nloc(self) -> int:
        """Rows of G_x on this rank."""
        return self.hi - self.lo

    def sizes(self, bordered: bool):
        """PETSc (local, global) sizes of the square or bordered matrix."""
        if not bordered:
            return ((self.nloc, self.N), (self.nloc, self.N))
        n1 = int(self.last)
        return ((self.nloc + n1, self.N + 1), (self.nloc + n1, self.N + 1))


def _preallocation(ai: np.ndarray, aj: np.ndarray, lo: int, hi: int):
    """(diagonal, off-diagonal) block counts per local CSR row, columns [lo, hi) owned here."""
    rows = np.repeat(np.arange(ai.size - 1), np.diff(ai))
    d = np.bincount(rows, weights=(aj >= lo) & (aj < hi), minlength=ai.size - 1).astype(PETSc.IntType)
    return d, (np.diff(ai) - d).astype(PETSc.IntType)


def _lu_or_block_jacobi(pc: PETSc.PC, bordered: bool = False) -> None:
    pc.setType("lu" if pc.getComm().getSize() == 1 else "bjacobi")


class Dense:
    """G_x assembled dense: exact, O(N^2) memory, LU in O(N^3)."""

    kind = "dense"

    def create(self, layout: Layout, comm: PETSc.Comm, bordered: bool) -> PETSc.Mat:
        """A dense Mat of the square or bordered size."""
        P = PETSc.Mat().createDense(layout.sizes(bordered), comm=comm)
        P.setUp()
        return P

    def fill(self, P: PETSc.Mat, problem, layout: Layout, border: Border | None = None) -> None:
        """P = G_x (``problem.jacobian_rows``), with the border appended when given."""
        a = P.getDenseArray()
        problem.jacobian_rows(a[:layout.nloc, :layout.N])
        if border is not None:
            a[:layout.nloc, -1] = border.column
            if layout.last:
                a[-1, :-1] = border.row
                a[-1, -1] = border.corner
        P.assemble()

    setup_pc = staticmethod(_lu_or_block_jacobi)


class Band:
    """The near field |i - j| <= ``band`` of G_x as AIJ (the far field dropped): any PETSc PC."""

    kind = "band"

    def __init__(self, band: int = BAND):
        self.band = band
        self._patterns = {}

    def pattern(self, layout: Layout):
        """Local CSR row pointers and global columns of the band of G_x (made once per layout)."""
        if layout not in self._patterns:
            self._patterns[layout] = self._pattern(layout)
        return self._patterns[layout]

    def _pattern(self, layout: Layout):
        rows = np.arange(layout.lo, layout.hi)
        first = np.maximum(rows - self.band, 0)
        last = np.minimum(rows + self.band, layout.N - 1)
        counts = (last - first + 1).astype(PETSc.IntType)
        ai = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
        aj = (first.repeat(counts) + np.arange(counts.sum()) - np.repeat(ai[:-1], counts)).astype(PETSc.IntType)
        return ai, aj

    def _csr(self, layout: Layout, ai, aj, v, border: Border | None):
        """The band's CSR with, when bordered, the dG/dp column and (last rank) the border row."""
        if border is None and v is not None:
            return ai, aj, v
        j = np.insert(aj, ai[1:], layout.N)
        vals = None if v is None else np.insert(v, ai[1:], border.column)
        ai2 = ai + np.arange(ai.size)
        if layout.last:
            j = np.concatenate([j, np.arange(layout.N + 1)])
            if v is not None:
                vals = np.concatenate([vals, border.row, [border.corner]])
            ai2 = np.append(ai2, ai2[-1] + layout.N + 1)
        return ai2.astype(PETSc.IntType), j.astype(PETSc.IntType), vals

    def create(self, layout: Layout, comm: PETSc.Comm, bordered: bool) -> PETSc.Mat:
        """An AIJ Mat preallocated for the band (and the border)."""
        ai, aj = self.pattern(layout)
        if bordered:
            ai, aj, _ = self._csr(layout, ai, aj, None, Border(np.zeros(0), None, 0.0))
        lo = layout.lo
        hi = layout.hi + int(bordered and layout.last)
        P = PETSc.Mat().createAIJ(layout.sizes(bordered), nnz=_preallocation(ai, aj, lo, hi), comm=comm)
        P.setUp()
        return P

    def fill(self, P: PETSc.Mat, problem, layout: Layout, border: Border | None = None) -> None:
        """P = the band of G_x (``problem.band_values``), with the border appended when given."""
        ai, aj = self.pattern(layout)
        v = problem.band_values(ai, aj)
        P.setValuesCSR(*self._csr(layout, ai, aj, v, border))
        P.assemble()

    setup_pc = staticmethod(_lu_or_block_jacobi)


class Shell:
    """No matrix: GMRES on the operator itself, unpreconditioned unless the user says otherwise."""

    kind = "shell"

    def create(self, layout: Layout, comm: PETSc.Comm, bordered: bool) -> None:
        """None: the solvers hand the operator itself to the PC."""
        return None

    def fill(self, P, problem, layout: Layout, border: Border | None = None) -> None:
        """Nothing to fill."""

    @staticmethod
    def setup_pc(pc: PETSc.PC, bordered: bool = False) -> None:
        """No preconditioner (-pc_type jacobi reads the shell's diagonal)."""
        pc.setType("none")


KINDS = ("dense", "band", "shell")


def create(kind: str, band: int = BAND):
    """The strategy named ``kind`` (one of :data:`KINDS`)."""
    return {"dense": Dense, "band": lambda: Band(band), "shell": Shell}[kind]()
