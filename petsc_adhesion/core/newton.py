"""Newton-Krylov (SNES + GMRES) for G(x; p) = 0 at a fixed parameter p, for any problem of the protocol.

The problem (see :mod:`petsc_adhesion.core.continuation` for the protocol) supplies
the residual, its linearization as an operator (often a shell), the matrix the
preconditioner is built from, and the domain guard.  Each SNES gets its own
options prefix and its defaults before ``setFromOptions()``, so every default
can be overridden at run time, solver by solver, and nothing is written into
the options database.

    petsc-adhesion -adh_lambda -2 -snes_monitor -ksp_monitor   # the fixed-approach solve
    petsc-adhesion -nat_snes_monitor -arc_ksp_converged_reason  # the continuation's correctors
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from ..core import capi
from .capi import python_errors

__all__ = ["Tolerances", "create_snes", "PCReuse", "fresh_retry", "krylov_retry", "guard", "Newton", "PC_REUSE_ITS", "TRUE_RESIDUAL"]

#: Keep a preconditioner while GMRES needs at most this many iterations with it.
PC_REUSE_ITS = 10


@dataclass(frozen=True)
class Tolerances:
    """Newton-Krylov defaults, tight enough for events located to 1e-8 in the parameter."""

    snes_rtol: float = 1e-10
    snes_atol: float = 1e-10
    snes_stol: float = 1e-14
    snes_max_it: int = 50
    ksp_rtol: float = 1e-10
    ksp_atol: float = 1e-13
    ksp_max_it: int = 400


def create_snes(comm: PETSc.Comm, prefix: str, function, residual: PETSc.Vec, jacobian,
                J: PETSc.Mat, P: PETSc.Mat, setup_pc, precheck, full_steps: bool = False,
                bordered: bool = False, tol: Tolerances = Tolerances()) -> PETSc.SNES:
    """A Newton-Krylov SNES with prefix ``prefix``, configured, then ``setFromOptions()``.

    Parameters
    ----------
    function, jacobian
        SNES callbacks ``(snes, x, f)`` and ``(snes, x, J, P)``.
    J, P
        The linearization (operator) and the matrix the preconditioner is built from.
    setup_pc
        ``setup_pc(pc, bordered)`` sets the default preconditioner for the kind of P.
    precheck
        Line-search pre-check ``(x, y, ...) -> bool`` that shortens the step y (domain guard).
    full_steps
        Newton starts from a continuation predictor, close to the solution, where full
        steps (still shortened by the guard) need no backtracking: the ``basic`` line
        search, which halves the residual evaluations of the default ``bt``.
    bordered
        Whether J is the bordered matrix of the arclength corrector (for ``setup_pc``).
    """
    snes = PETSc.SNES().create(comm)
    try:            # an option refused (a type name PETSc does not know): the SNES would outlive the call
        snes.setOptionsPrefix(prefix)
        snes.setFunction(function, residual)
        snes.setJacobian(jacobian, J, P)
        snes.setType("newtonls")
        if full_steps:
            capi.set_linesearch_type(snes, "basic")
        snes.setTolerances(rtol=tol.snes_rtol, atol=tol.snes_atol, stol=tol.snes_stol, max_it=tol.snes_max_it)
        ksp = snes.getKSP()
        ksp.setType("gmres")
        ksp.setTolerances(rtol=tol.ksp_rtol, atol=tol.ksp_atol, max_it=tol.ksp_max_it)
        setup_pc(ksp.getPC(), bordered)
        snes.setLineSearchPreCheck(precheck)
        snes.setFromOptions()
    except BaseException:
        snes.destroy()
        raise
    return snes


class PCReuse:
    """When to refill a preconditioning matrix: only when its factorization got stale.

    PETSc's PCSetUp refactors only a matrix whose state changed, so a matrix
    left alone keeps its factorization across Newton iterations and
    continuation steps.  Refill when the last Krylov solve of ``ksp`` failed or
    took more than ``its`` iterations, or after :meth:`expire`.

    ``at`` is the point the matrix was last filled at, as its owner recorded it
    (:meth:`filled`): a checkpoint saves it, so that a restarted run fills the
    same matrix and continues with the same preconditioner.
    """

    def __init__(self, its: int = PC_REUSE_ITS):
        self.its, self.stale, self.at = its, True, None

    def expire(self) -> None:
        """Refill at the next linearization."""
        self.stale = True

    def pending(self, ksp: PETSc.KSP) -> bool:
        """Whether the next linearization will refill (asking nothing)."""
        return self.stale or ksp.getConvergedReason() < 0 or ksp.getIterationNumber() > self.its

    def __call__(self, ksp: PETSc.KSP) -> bool:
        """Whether to refill now (and, by asking, the matrix counts as fresh)."""
        refill = self.pending(ksp)
        self.stale = False
        return refill

    def restore(self, pending: bool) -> None:
        """Take up :meth:`state`'s ``pending``: whether the next linearization refills."""
        self.stale = pending

    def filled(self, *at) -> None:
        """Record the point the matrix was just filled at (arrays copied)."""
        self.at = tuple(np.array(v) if isinstance(v, np.ndarray) else v for v in at)

    def state(self, ksp: PETSc.KSP) -> dict:
        """Where the matrix was last filled and whether the next linearization refills it."""
        return {"pending": bool(self.pending(ksp)), "at": None if self.at is None else list(self.at)}


def fresh_retry(snes: PETSc.SNES, X: PETSc.Vec, reuse: PCReuse, work: PETSc.Vec) -> bool:
    """Solve from X in place; after a failure, once more from X with a fresh preconditioner.

    A factorization kept from a distant point of the curve can make the first
    linear solve fail where Newton itself is fine.  ``work`` keeps the start.
    """
    X.copy(work)
    for _ in range(2):
        with python_errors():
            snes.solve(None, X)
        if snes.getConvergedReason() > 0:
            return True
        reuse.expire()
        work.copy(X)
    return False


#: A Krylov solution is accepted when its true residual is below this many times KSP's rtol.
TRUE_RESIDUAL = 1e3
#: ... and, with a preconditioner filled afresh, below this share of the right-hand side (a tangent to 1e-6
#: serves the predictor and the border: the corrector converges from it all the same).
FRESH_RESIDUAL = 1e-6


def krylov_retry(ksp: PETSc.KSP, A: PETSc.Mat, P: PETSc.Mat, b: PETSc.Vec, x: PETSc.Vec,
                 reuse: PCReuse, linearize, work: PETSc.Vec) -> bool:
    """Solve A x = b at the point set by ``linearize(refill)``; retry once with a fresh PC.

    GMRES with a left preconditioner stops on the preconditioned residual; with
    a preconditioner kept from a distant point that can pass while A x = b is
    far from solved (the first iterate is then the old tangent).  So the true
    residual (in ``work``) must be below TRUE_RESIDUAL times KSP's rtol, too.
    With the preconditioner filled afresh at this point (the retry) that guard
    has nothing left to catch, and the true residual may sit at the rounding
    floor of an ill-conditioned matrix (a soft sphere's frame of the edge at
    mu = 1000, a = 32: 1.8e-7 after GMRES converged): FRESH_RESIDUAL then.
    """
    for attempt in range(2):
        linearize(reuse(ksp))
        ksp.setOperators(A, P)
        with python_errors():
            ksp.solve(b, x)
        if ksp.getConvergedReason() > 0:
            with python_errors():
                A.mult(x, work)
            work.aypx(-1.0, b)
            bound = TRUE_RESIDUAL * ksp.getTolerances()[0] if attempt == 0 else FRESH_RESIDUAL
            if work.norm() <= bound * b.norm():
                return True
        reuse.expire()
    return False


def guard(problem, x: np.ndarray, Y: PETSc.Vec, y: np.ndarray | None = None) -> bool:
    """Shorten the Newton step Y (new x = x - y) by the problem's domain guard; True if shortened.

    ``y`` is the part of Y acting on x when Y also holds other unknowns.
    The problem returns the same fraction on all ranks; a shortened step is recorded with it.
    """
    alpha = problem.step_fraction(x, Y.getArray(readonly=True) if y is None else y)
    if alpha < 1.0:
        problem.record_guard()
        Y.scale(alpha)
        return True
    return False


class Newton:
    """SNES on G(x; p) = 0 at a parameter p given to :meth:`solve`.

    Parameters
    ----------
    problem
        Implements the protocol of :mod:`petsc_adhesion.core.continuation`.
    prefix
        Options prefix of the SNES ("" for the fixed-approach solve, "nat_" for
        the natural corrector of the continuation).
    full_steps
        See :func:`create_snes`.
    pc_reuse_its
        See :class:`PCReuse`.
    """

    def __init__(self, problem, prefix: str = "", full_steps: bool = False, pc_reuse_its: int = PC_REUSE_ITS,
                 tol: Tolerances = Tolerances()):
        self.pb, self.p, self.snes = problem, 0.0, None
        self.pmat = problem.create_pmat(0)
        self.reuse = PCReuse(pc_reuse_its)
        self.work, residual = problem.create_vec(), problem.create_vec()
        try:
            self.snes = create_snes(problem.comm, prefix, self._function, residual, self._jacobian,
                                    problem.jacobian, self.pmat or problem.jacobian, problem.setup_pc,
                                    self._precheck, full_steps, tol=tol)
        except BaseException:           # a solver option refused: free what is made
            self.destroy()
            raise
        finally:
            residual.destroy()          # the SNES holds its own reference

    def _function(self, snes, x, G):
        self.pb.residual(x, self.p, G)

    def _jacobian(self, snes, x, J, P):
        self.linearize(x, self.reuse(snes.getKSP()))

    def linearize(self, x: PETSc.Vec, refill: bool) -> None:
        """The operator at (x, p) and, with ``refill``, its preconditioning matrix."""
        self.pb.linearize(x, self.p)
        if refill and self.pmat is not None:
            self.pb.fill_pmat(self.pmat)
            self.reuse.filled(x.getArray(readonly=True), self.p)

    def _precheck(self, x, y, *args) -> bool:
        return guard(self.pb, x.getArray(readonly=True), y)

    def state(self) -> dict:
        """What the solver keeps between solves: its preconditioner's fill point (:class:`PCReuse`)."""
        return self.reuse.state(self.snes.getKSP())

    def restore(self, state: dict) -> None:
        """Fill the preconditioning matrix where :meth:`state`'s solver last filled it: the same
        preconditioner gives the same Newton and Krylov iterates (a fresh one would change them by the
        solver tolerances, and a continuation's step control with them).  ValueError for a state that is not
        one."""
        if not isinstance(state["pending"], bool):
            raise ValueError("a preconditioner's state that is not one")
        if state["at"] is not None:
            x, p = state["at"]
            v = self.pb.create_vec()
            try:
                x = np.asarray(x, dtype=float)
                if x.shape != (v.getLocalSize(),) or not np.isfinite(x).all() or not np.isfinite(float(p)):
                    raise ValueError("a preconditioner filled at a point that is not one")
                self.p = float(p)
                v.setArray(x)
                self.linearize(v, True)
            finally:
                v.destroy()
        self.reuse.restore(state["pending"])

    def solve(self, p: float, x: PETSc.Vec, retry: bool = False) -> bool:
        """Solve G(x; p) = 0 in place from the guess in x; True when converged.

        ``retry``: after a failure, once more with a fresh preconditioner.
        """
        self.p = p
        if retry:
            return fresh_retry(self.snes, x, self.reuse, self.work)
        with python_errors():
            self.snes.solve(None, x)
        return self.snes.getConvergedReason() > 0

    @property
    def iterations(self) -> tuple[int, int]:
        """Newton and Krylov iterations of the last solve."""
        return self.snes.getIterationNumber(), self.snes.getLinearSolveIterations()

    def destroy(self) -> None:
        """Free the PETSc objects made here."""
        for obj in (self.snes, self.pmat, self.work):
            if obj is not None:
                obj.destroy()
