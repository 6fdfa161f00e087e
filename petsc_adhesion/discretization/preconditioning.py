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
dense       G_x assembled, dense                    LU / LU on each rank, block Jacobi
band        |i - j| <= band of G_x, AIJ             LU / LU on each rank, block Jacobi; any PC
shell       none: the operator itself               none
==========  ======================================  ====================================

On several ranks the whole matrix is factored on every rank (PCREDUNDANT) up to
REDUNDANT_MAX unknowns, block Jacobi beyond.  On a dense block PETSc's default
sub-preconditioner of block Jacobi, ILU(0), has the full pattern and is the LU
factorization itself.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

__all__ = ["Layout", "Dense", "Band", "Shell", "KINDS", "BAND", "REDUNDANT_MAX", "create", "MATRICES", "BASE_BYTES", "memory_needed", "memory_available"]

#: Half bandwidth of the near field kept by ``band``.
BAND = 64
#: Up to this many unknowns a preconditioner on several ranks is the LU of the whole matrix on every rank
#: (PCREDUNDANT): exact as on one rank, so regular at the folds, where block Jacobi's blocks of a singular G_x
#: are not (mu = 5, and mu = 10 with sigma = 0.2, stopped at their snap-off on two ranks: GMRES could not
#: pass it).  A dense LU of 2000 takes about 0.2 s; beyond that block Jacobi's cheaper blocks win.
REDUNDANT_MAX = 2000


@dataclass(frozen=True)
class Layout:
    """Row layout of G_x on this rank: rows [lo, hi) of N; border rows live on the last rank."""

    lo: int
    hi: int
    N: int
    last: bool

    @property
    def nloc(self) -> int:
        """Rows of G_x on this rank."""
        return self.hi - self.lo

    def sizes(self, extra: int = 0):
        """PETSc (local, global) sizes of G_x with ``extra`` borders."""
        n = self.nloc + extra * int(self.last)
        return ((n, self.N + extra), (n, self.N + extra))


def _preallocation(ai: np.ndarray, aj: np.ndarray, lo: int, hi: int):
    """(diagonal, off-diagonal) block counts per local CSR row, columns [lo, hi) owned here."""
    rows = np.repeat(np.arange(ai.size - 1), np.diff(ai))
    d = np.bincount(rows, weights=(aj >= lo) & (aj < hi), minlength=ai.size - 1).astype(PETSc.IntType)
    return d, (np.diff(ai) - d).astype(PETSc.IntType)


def _lu_or_block_jacobi(pc: PETSc.PC, bordered: bool = False, n: int = 0) -> None:
    """LU on one rank; on several, LU of the whole matrix of ``n`` unknowns on each rank (PCREDUNDANT) up to
    REDUNDANT_MAX, block Jacobi beyond."""
    pc.setType("lu" if pc.getComm().getSize() == 1 else "redundant" if n <= REDUNDANT_MAX else "bjacobi")


class Dense:
    """G_x assembled dense: exact, O(N^2) memory, LU in O(N^3)."""

    kind = "dense"

    def create(self, layout: Layout, comm: PETSc.Comm, extra: int = 0) -> PETSc.Mat:
        """A dense Mat of G_x's size with ``extra`` borders."""
        P = PETSc.Mat().createDense(layout.sizes(extra), comm=comm)
        P.setUp()
        return P

    def fill(self, P: PETSc.Mat, problem, layout: Layout, borders=()) -> None:
        """P = G_x (``problem.jacobian_rows``), with the borders appended in order."""
        a = P.getDenseArray()
        problem.jacobian_rows(a[:layout.nloc, :layout.N])
        for j, b in enumerate(borders):
            n = layout.N + j
            a[:layout.nloc + j * layout.last, n] = b.column
            if layout.last:
                a[layout.nloc + j, :n] = b.row
                a[layout.nloc + j, n] = b.corner
        P.assemble()
        if P.getComm().getSize() > 1:
            # block Jacobi factors the diagonal block, a Mat of its own over P's memory whose state a fill
            # leaves alone: without this it would keep the factorization of the first fill for ever
            P.getDiagonalBlock().stateIncrease()

    setup_pc = staticmethod(_lu_or_block_jacobi)


class Band:
    """The near field |i - j| <= ``band`` of G_x as AIJ (the far field dropped), with its borders
    in full: any PETSc PC."""

    kind = "band"

    def __init__(self, band: int = BAND):
        self.band = band
        self._patterns: dict[Layout, tuple[np.ndarray, np.ndarray]] = {}

    def pattern(self, layout: Layout):
        """Local CSR row pointers and global columns of the band of G_x (made once per layout)."""
        if layout not in self._patterns:
            rows = np.arange(layout.lo, layout.hi)
            first = np.maximum(rows - self.band, 0)
            last = np.minimum(rows + self.band, layout.N - 1)
            counts = (last - first + 1).astype(PETSc.IntType)
            ai = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
            aj = (first.repeat(counts) + np.arange(counts.sum()) - np.repeat(ai[:-1], counts)).astype(PETSc.IntType)
            self._patterns[layout] = ai, aj
        return self._patterns[layout]

    def _csr(self, layout: Layout, extra: int, v, borders):
        """CSR of the band with ``extra`` border columns on G_x's rows and, on the last rank, the border
        rows in full (row k: everything before it, its corner, then later borders' columns).
        Values only when ``v``, the band's own, is given."""
        ai, aj = self.pattern(layout)
        at = np.repeat(ai[1:], extra)                       # each row's end, once per border column
        tail = layout.N + np.arange(extra)
        cols = [np.insert(aj, at, np.tile(tail, layout.nloc))]
        # values only with v (vals stays empty without)
        vals: list[np.ndarray] = [np.insert(v, at, np.stack([b.column[:layout.nloc] for b in borders], axis=1).ravel()
                                            if extra else [])] if v is not None else []
        counts: list = [np.diff(ai) + extra]
        for k in range(extra if layout.last else 0):
            cols.append(np.concatenate([np.arange(layout.N + k + 1), tail[k + 1:]]))
            counts.append([cols[-1].size])
            if v is not None:
                b = borders[k]
                vals.append(np.concatenate([b.row, [b.corner], [c.column[layout.nloc + k] for c in borders[k + 1:]]]))
        ai2 = np.concatenate([[0], np.cumsum(np.concatenate(counts))]).astype(PETSc.IntType)
        return ai2, np.concatenate(cols).astype(PETSc.IntType), None if v is None else np.concatenate(vals)

    def create(self, layout: Layout, comm: PETSc.Comm, extra: int = 0) -> PETSc.Mat:
        """An AIJ Mat preallocated for the band and the borders."""
        ai, aj, _ = self._csr(layout, extra, None, ())
        lo, hi = layout.lo, layout.hi + extra * int(layout.last)
        P = PETSc.Mat().createAIJ(layout.sizes(extra), nnz=_preallocation(ai, aj, lo, hi), comm=comm)
        P.setUp()
        return P

    def fill(self, P: PETSc.Mat, problem, layout: Layout, borders=()) -> None:
        """P = the band of G_x (``problem.band_values``), with the borders appended in order."""
        ai, aj = self.pattern(layout)
        P.setValuesCSR(*self._csr(layout, len(borders), problem.band_values(ai, aj), borders))
        P.assemble()

    setup_pc = staticmethod(_lu_or_block_jacobi)


class Shell:
    """No matrix: GMRES on the operator itself, unpreconditioned unless the user says otherwise."""

    kind = "shell"

    def create(self, layout: Layout, comm: PETSc.Comm, extra: int = 0) -> None:
        """None: the solvers hand the operator itself to the PC."""
        return None

    def fill(self, P, problem, layout: Layout, borders=()) -> None:
        """Nothing to fill."""

    @staticmethod
    def setup_pc(pc: PETSc.PC, bordered: bool = False, n: int = 0) -> None:
        """No preconditioner (-pc_type jacobi reads the shell's diagonal)."""
        pc.setType("none")


KINDS = ("dense", "band", "shell")

#: N x N doubles a rank holds at once, by preconditioning kind, for a curve and for a fixed-approach solve:
#: the influence matrix, and with dense the assembled G_x, the bordered matrix and their LU factors (measured:
#: 2564 MiB at N = 8000 on one rank with dense, 1323 MiB with band; docs/performance.md, scaling).
MATRICES = {("dense", True): 5.0, ("dense", False): 3.0, ("band", True): 2.0, ("band", False): 2.0,
            ("shell", True): 1.5, ("shell", False): 1.5}
#: What a run holds besides them (the interpreter, numpy, PETSc, MPI, h5py, the curve's points): about 350 MiB.
BASE_BYTES = 350 << 20


def memory_needed(n: int, kind: str, curve: bool = True, ranks: int = 1) -> float:
    """Bytes a rank needs for a problem of n nodes with the preconditioning ``kind``.

    >>> round(memory_needed(8000, "dense") / 2**20)     # measured 2564 MiB
    2791
    """
    return BASE_BYTES + MATRICES[(kind, curve)] * 8.0 * n * n / ranks


def memory_available() -> float:
    """Bytes this process may still use: the kernel's MemAvailable, within the control group's limit."""
    have = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    try:
        with open("/proc/meminfo") as f:
            info = {ln.split(":")[0]: ln.split()[1] for ln in f}
        have = float(info["MemAvailable"]) * 1024
    except (OSError, KeyError, ValueError, IndexError):
        pass
    for limit, used in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                        ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            with open(limit) as f, open(used) as g:
                have = min(have, float(f.read().strip()) - float(g.read().strip()))
        except (OSError, ValueError):
            continue
    return have


def create(kind: str, band: int = BAND):
    """The strategy named ``kind`` (one of :data:`KINDS`)."""
    return {"dense": Dense, "band": lambda: Band(band), "shell": Shell}[kind]()
