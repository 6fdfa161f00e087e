"""The fold system: a turning point of G(u, p; s) = 0 in p, continued in a second parameter s.

A fold of the curve G(u, p) = 0 (a turning point in p, where G_u is singular)
traces a curve in (s, p) as a second parameter s changes.  It solves the
minimally augmented system (Govaerts, Numerical Methods for Bifurcations of
Dynamical Equilibria, SIAM 2000, sec. 4.2; BifurcationKit's codim-2 fold
continuation)

    G(u, p; s) = 0,
    g(u, p; s) = 0,   [[G_u, psi], [phi^T, 0]] [v; g] = [0; 1],

g vanishing exactly where G_u is singular, v then its null vector; phi and
psi, approximate right and left null vectors, are renewed after every step
(:meth:`FoldSystem.adapt`; the zero set of g does not depend on them).
:class:`FoldSystem` implements the problem protocol
(:class:`~petsc_adhesion.core.protocol.ContinuationProblem`) with x = (u, p)
and the continuation parameter s, so the core traces the fold curve as it
traces any curve, and its own fold event, the turning point of the fold curve
in s, is a cusp.  With w from the transposed solve
[[G_u^T, phi], [psi^T, 0]] [w; h] = [0; 1] the derivatives of g are

    g_u = -w^T (dG_u/du)[v],   g_p = -w^T (dG_u/dp) v,   g_s = -w^T (dG_u/ds) v,

which the base problem gives through its second-derivative hooks
(:class:`~petsc_adhesion.core.protocol.FoldBase`); they enter only the
Jacobian and the tangent, never the residual whose zero is the fold.  The
second parameter is set through the base problem (``set_parameter``), never by
writing its fields.

Unknowns are laid out as u's, then p as the last entry on the last rank.  The
bordered solves of g have their own KSP, role ``fold_``, with the
:class:`~petsc_adhesion.core.newton.PetscSettings` the fold system is given.
"""
from __future__ import annotations

import math
from contextlib import contextmanager
from typing import Generic, TypeVar

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .bordered import Border
from .capi import python_errors
from .newton import TRUE_RESIDUAL, PCReuse, PetscSettings, SolverOptions, Tolerances
from .protocol import FoldBase

__all__ = ["FoldSystem", "FOLD_PREFIX"]

#: Options prefix of the bordered solves of g (-fold_ksp_type, ...).
FOLD_PREFIX = "fold_"

#: The type of the base problem, so that its owner may use the members it has beyond the protocol
Base = TypeVar("Base", bound=FoldBase)


class FoldSystem(Generic[Base]):
    """The fold system [G; g] = 0 in x = (u, p), continuation parameter s = ``name``: the problem protocol.

    Parameters
    ----------
    base : FoldBase
        The problem G(u, p; s) (:class:`~petsc_adhesion.core.protocol.FoldBase`); the fold system owns it
        from here on (:meth:`destroy` frees it).
    name : str
        The second parameter s, as the base problem knows it ("sigma", "mu").
    """

    def __init__(self, base, name: str, settings: PetscSettings = PetscSettings()):
        if settings.snes_given:
            raise ValueError(f"{settings.snes_given[0]}: the fold system's bordered solves have a KSP, no SNES")
        self.base, self.parameter = base, name
        self.options = None
        self.comm = base.comm
        self._mpi = self.comm.tompi4py()
        self._h, self._G, self._u, self._y = (base.create_vec() for _ in range(4))
        self.nloc, N = self._h.getLocalSize(), self._h.getSize()
        self.last = self.comm.getRank() == self.comm.getSize() - 1
        n1 = int(self.last)
        self.sizes = (self.nloc + n1, N + 1)
        # p weighs like a uniform change of u in the continuation's norm
        self.weights = np.append(base.weights, 1.0) if self.last else base.weights
        # None until made below: destroy() frees those made before a refused option
        self.jacobian: PETSc.Mat = None
        self.bordered: PETSc.Mat = None
        self.pmat: PETSc.Mat | None = None
        self.ksp: PETSc.KSP = None
        self.rhs: PETSc.Vec = None
        self.z: PETSc.Vec = None
        self.work: PETSc.Vec = None
        try:
            self.jacobian = PETSc.Mat().createPython((self.sizes, self.sizes), _Shell(self.jacobian_mult),
                                                     comm=self.comm)
            self.jacobian.setUp()
            # the bordered matrix of g, its PC matrix and solver
            self.bordered = PETSc.Mat().createPython(
                (self.sizes, self.sizes), _Shell(self.bordered_mult, self.bordered_mult_transpose), comm=self.comm)
            self.bordered.setUp()
            self.pmat = base.create_pmat(1)
            self.rhs, self.z, self.work = (self.create_vec() for _ in range(3))
            if self.last:
                self.rhs.setValue(N, 1.0)
            self.rhs.assemble()
            self.options = SolverOptions(FOLD_PREFIX, settings)
            self.ksp = _bordered_ksp(self.comm, self.bordered, self.pmat or self.bordered, base, self.options.prefix)
        except BaseException:               # a solver option refused: free what is made
            self.destroy()
            raise
        self.reuse = PCReuse()
        self.phi = self.psi = np.full(self.nloc, 1.0 / math.sqrt(N))
        self._key: tuple[np.ndarray, float] | None = None     # (x, s) of the state below
        # the state below (s, v, g, w), set by _at; w only when asked for
        self.s: float | None = None
        self.v: np.ndarray | None = None
        self.w: np.ndarray | None = None
        self.g, self.gap = 0.0, math.inf
        # the row [g_u, g_p] and the column G_p at the point of linearize
        self.row: np.ndarray | None = None
        self.row_all: np.ndarray | None = None
        self.gp: np.ndarray | None = None
        self.g_p = 0.0
        self.guard: float | None = None           # the parameter of the domain guard: set by adapt

    # -- x = (u, p) ------------------------------------------------------------------
    def create_vec(self) -> PETSc.Vec:
        """A vector (u, p), p on the last rank."""
        return PETSc.Vec().createMPI(self.sizes, comm=self.comm)

    def split(self, x: np.ndarray) -> tuple[np.ndarray, float]:
        """Local u and p (broadcast from the last rank) of a local part x (collective)."""
        p = float(x[self.nloc]) if self.last else None
        return x[:self.nloc], self._mpi.bcast(p, root=self.comm.getSize() - 1)

    def join(self, u: np.ndarray, p: float) -> np.ndarray:
        """The local part of (u, p)."""
        return np.append(u, p) if self.last else np.asarray(u, dtype=float)

    def _dot(self, u: np.ndarray, v: np.ndarray) -> float:
        return self._mpi.allreduce(float(np.dot(u, v)))

    # -- the state at (x, s): G_u, v, g, w -----------------------------------------
    def _at(self, x: np.ndarray, s: float, left: bool) -> bool:
        """Set the base problem at s, and v and g (with ``left`` also w) at (x, s); False outside the domain.

        Kept while (x, s) does not change, agreed on all ranks.
        """
        key = self._key
        same = key is not None and key[1] == s and np.array_equal(key[0], x) and (self.w is not None or not left)
        if self._mpi.allreduce(same, op=MPI.LAND):
            self.base.set_parameter(self.parameter, s)
            return True
        if not self.base.set_parameter(self.parameter, s):     # a corrector may overshoot the parameter's range
            return False
        u, p = self.split(x)
        self.gap = self.base.domain_gap(u)
        if not self.gap > 0:
            return False
        self.s = s
        self._h.setArray(u)
        self.base.linearize(self._h, p)
        z = self._solve(False)
        self.v, self.g = z[:self.nloc].copy(), self._mpi.bcast(float(z[self.nloc]) if self.last else None,
                                                            root=self.comm.getSize() - 1)
        self.w = self._solve(True)[:self.nloc].copy() if left else None
        self._key = (x.copy(), s)
        return True

    @contextmanager
    def _at_parameter(self, s: float):
        """The base problem at the parameter s for the block, at the state's after it."""
        self.base.set_parameter(self.parameter, s)
        try:
            yield
        finally:
            if self.s is not None:
                self.base.set_parameter(self.parameter, self.s)

    def forget(self) -> None:
        """Compute the state below afresh at the next call (after the base problem was used elsewhere)."""
        self._key = None

    def _solve(self, transpose: bool) -> np.ndarray:
        """[v; g] (or, transposed, [w; h]) from the bordered matrix of g; retried once with a fresh PC."""
        ksp, M = self.ksp, self.bordered
        for _ in range(2):
            if self.reuse(ksp) and self.pmat is not None:
                row = np.concatenate(self._mpi.allgather(self.phi))     # collective: every rank gathers
                self.base.fill_pmat(self.pmat, [Border(self.psi, row if self.last else None, 0.0)])
            ksp.setOperators(M, self.pmat or M)
            with python_errors():
                (ksp.solveTranspose if transpose else ksp.solve)(self.rhs, self.z)
            if ksp.getConvergedReason() > 0:
                (M.multTranspose if transpose else M.mult)(self.z, self.work)
                self.work.aypx(-1.0, self.rhs)
                if self.work.norm() <= TRUE_RESIDUAL * ksp.getTolerances()[0]:
                    return self.z.getArray(readonly=True)
            self.reuse.expire()
        raise RuntimeError(f"the bordered solve of the fold system failed at {self.parameter} = {self.s:.6g}")

    def adapt(self, x: np.ndarray, s: float, sweeps: int = 1) -> None:
        """Borders phi, psi := the null vectors v, w at (x, s), normalised: inverse iteration from the
        current ones (``sweeps`` times); keeps the bordered matrix far from singular along the curve."""
        self.guard = s
        for _ in range(sweeps):
            self._key = None
            if not self._at(x, s, True):
                raise FloatingPointError(f"a state below the wall at {self.parameter} = {s:.6g}")
            v, w = self._nulls()
            self.phi = v / math.sqrt(self._dot(v, v))
            self.psi = w / math.sqrt(self._dot(w, w))
            self.reuse.expire()
        self._key = None

    def _nulls(self) -> tuple[np.ndarray, np.ndarray]:
        """v and w of the state below: :meth:`_at` with ``left`` has set them."""
        assert self.v is not None and self.w is not None, "the null vectors before the state is computed"
        return self.v, self.w

    def _linearized(self) -> tuple[np.ndarray, np.ndarray]:
        """The row g_u and the column G_p at the point of :meth:`linearize`, which has set them."""
        assert self.row is not None and self.gp is not None, "the Jacobian's border before linearize"
        return self.row, self.gp

    def _guard(self) -> float:
        """The parameter of the domain guard, which :meth:`adapt` has set."""
        assert self.guard is not None, "the domain guard before adapt"
        return self.guard

    # -- the protocol -------------------------------------------------------------------
    def residual(self, X: PETSc.Vec, s: float, R: PETSc.Vec) -> None:
        """[G(u, p; s); g(u, p; s)]; NaN outside the domain (the corrector then fails)."""
        x = X.getArray(readonly=True)
        if not self._at(x, s, False):
            R.set(np.nan)
            return
        u, p = self.split(x)
        self._h.setArray(u)
        self.base.residual(self._h, p, self._G)
        R.setArray(self.join(self._G.getArray(readonly=True), self.g))

    def dG_dp(self, X: PETSc.Vec, s: float, out: np.ndarray) -> np.ndarray:
        """[G_s; g_s] on the local rows (the module's docstring)."""
        x = X.getArray(readonly=True)
        self._at(x, s, True)
        u, p = self.split(x)
        column, derivative = self.base.parameter_derivatives(self.parameter, u, p, *self._nulls(), self.gap)
        out[:self.nloc] = column
        out[self.nloc:] = -derivative
        return out

    def linearize(self, X: PETSc.Vec, s: float) -> None:
        """The point of :attr:`jacobian`: G_u, its column G_p, and the row [g_u, g_p]."""
        x = X.getArray(readonly=True)
        self._at(x, s, True)
        u, p = self.split(x)
        row, along_p = self.base.second_derivatives(u, p, *self._nulls())
        self.row, self.g_p = -row, (-along_p if along_p else 0.0)
        self.gp = self.base.dG_dp(self._h, p, np.zeros(self.nloc))
        full = self._mpi.allgather(self.row)
        self.row_all = np.concatenate(full) if self.last else None

    def create_pmat(self, borders: int):
        """The PC matrix of [[G_u, G_p], [g_u, g_p]] with ``borders`` more."""
        return self.base.create_pmat(1 + borders)

    def fill_pmat(self, P: PETSc.Mat, borders=()) -> None:
        """Assemble P at the linearization point."""
        own = Border(self._linearized()[1], self.row_all if self.last else None, self.g_p)
        self.base.fill_pmat(P, [own, *borders])

    def setup_pc(self, pc: PETSc.PC, bordered: bool = False) -> None:
        """Default preconditioner for the kind of P."""
        self.base.setup_pc(pc, bordered)

    def inside(self, x: np.ndarray) -> bool:
        """The base problem's guard on u at the parameter of the last point the borders were adapted at (the
        protocol gives no parameter here; a corrector that moves s out of the domain gets a NaN residual)."""
        with self._at_parameter(self._guard()):
            return self.base.inside(x[:self.nloc])

    def step_fraction(self, x: np.ndarray, y: np.ndarray) -> float:
        """The base problem's guard on the u part of the step x -> x - y, at the parameter of :meth:`inside`."""
        with self._at_parameter(self._guard()):
            return self.base.step_fraction(x[:self.nloc], y[:self.nloc])

    def record_guard(self) -> None:
        """The base problem counts the steps its guard shortened."""
        self.base.record_guard()

    def observe(self, x: np.ndarray, s: float, xdot: np.ndarray, sdot: float):
        """p and the base problem's observables at the fold; the rate of p along the fold curve."""
        u, p = self.split(x)
        _, pdot = self.split(xdot)
        with self._at_parameter(s):
            values, _ = self.base.observe(u, p, np.zeros_like(u), 0.0)
        name = self.base.parameter
        return {name: p, **values}, {name: pdot}

    def bordered_mult(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = [[G_u, psi], [phi^T, 0]] x = [G_u xu + psi xg; phi . xu] (the bordered matrix of g)."""
        xu, xg = self.split(x.getArray(readonly=True))
        self._u.setArray(xu)
        with python_errors():
            self.base.jacobian.mult(self._u, self._y)
        y.setArray(self.join(self._y.getArray(readonly=True) + xg * self.psi, self._dot(self.phi, xu)))

    def bordered_mult_transpose(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = [G_u^T xu + phi xg; psi . xu]: the transpose of :meth:`bordered_mult`."""
        xu, xg = self.split(x.getArray(readonly=True))
        self._u.setArray(xu)
        self.base.jacobian_transpose(self._u, self._y)
        y.setArray(self.join(self._y.getArray(readonly=True) + xg * self.phi, self._dot(self.psi, xu)))

    def jacobian_mult(self, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """y = [[G_u, G_p], [g_u, g_p]] x = [G_u xu + G_p xp; g_u . xu + g_p xp] (the fold system's Jacobian)."""
        xu, xp = self.split(x.getArray(readonly=True))
        self._u.setArray(xu)
        with python_errors():
            self.base.jacobian.mult(self._u, self._y)
        row, gp = self._linearized()
        g = self._dot(row, xu)
        if self.g_p:
            g += self.g_p * xp
        y.setArray(self.join(self._y.getArray(readonly=True) + xp * gp, g))

    def destroy(self) -> None:
        """Free the PETSc objects made here, the base problem's too."""
        for obj in (self.ksp, self.bordered, self.pmat, self.jacobian, self.rhs, self.z, self.work,
                    self._h, self._G, self._u, self._y, self.options):
            if obj is not None:
                obj.destroy()
        self.base.destroy()


def _bordered_ksp(comm, M: PETSc.Mat, P: PETSc.Mat, base, prefix: str) -> PETSc.KSP:
    """GMRES on the bordered matrix of g with the base problem's PC, tight (g is the residual's last entry, so
    its error is the fold's), with ``prefix``, its own of the role FOLD_PREFIX (:class:`SolverOptions`)."""
    tol = Tolerances()
    ksp = PETSc.KSP().create(comm)
    try:
        ksp.setOptionsPrefix(prefix)
        ksp.setType("gmres")
        ksp.setTolerances(rtol=1e-2 * tol.ksp_rtol, atol=1e-2 * tol.ksp_atol, max_it=tol.ksp_max_it)
        ksp.setOperators(M, P)
        base.setup_pc(ksp.getPC(), True)
        ksp.setFromOptions()
    except BaseException:
        ksp.destroy()
        raise
    return ksp


class _Shell:
    """MatPython context that hands y = M x (and y = M^T x) to its owner's ``mult`` (``mult_transpose``):
    the shell holds no state of its own."""

    def __init__(self, mult, mult_transpose=None):
        self._mult, self._mult_transpose = mult, mult_transpose

    def mult(self, mat, x, y):
        """y = M x."""
        self._mult(x, y)

    def multTranspose(self, mat, x, y):
        """y = M^T x."""
        self._mult_transpose(x, y)
