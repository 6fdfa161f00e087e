"""Newton-Krylov (SNES + GMRES) for G(x; p) = 0 at a fixed parameter p, for any problem of the protocol.

The problem (see :mod:`petsc_adhesion.core.continuation` for the protocol) supplies
the residual, its linearization as an operator (often a shell), the matrix the
preconditioner is built from, and the domain guard.  Each solver gets its
defaults, then the user's :class:`PetscSettings` for its role (natural or
arclength corrector, fixed-approach solve, fold system), then
``setFromOptions()``: the values given are honoured exactly, the others keep the
defaults.  The settings reach PETSc under an options prefix of the solver's own
(:class:`SolverOptions`), so two solvers, of one curve or of two, never read
each other's, nor what a caller left in the options database.

    Newton(problem, settings=PetscSettings(ksp_type="bcgs", snes_monitor=True))
    petsc-adhesion -adh_lambda -2 -snes_monitor -ksp_monitor   # the command line reads them into these
"""
from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np
from petsc4py import PETSc

from ..core import capi
from .capi import python_errors

__all__ = ["Tolerances", "PetscSettings", "SolverOptions", "role_of", "is_solvers_own", "create_snes", "PCReuse", "solved", "fresh_retry", "krylov_retry", "guard", "Newton", "PC_REUSE_ITS", "TRUE_RESIDUAL"]

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


_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
#: PetscSettings' typed fields and the PETSc options they are (without prefix).
_OPTION_OF = {"snes_rtol": "snes_rtol", "snes_atol": "snes_atol", "snes_stol": "snes_stol",
              "snes_max_it": "snes_max_it", "linesearch": "snes_linesearch_type", "ksp_type": "ksp_type",
              "ksp_rtol": "ksp_rtol", "ksp_atol": "ksp_atol", "ksp_max_it": "ksp_max_it", "pc_type": "pc_type",
              "snes_monitor": "snes_monitor", "ksp_monitor": "ksp_monitor"}
#: (lowest, highest, highest open) of the numbers: PETSc takes some out of range without a word.
_RANGES = {"snes_rtol": (0.0, 1.0, True), "snes_atol": (0.0, math.inf, False), "snes_stol": (0.0, 1.0, True),
           "snes_max_it": (1, 10**9, False), "ksp_rtol": (0.0, 1.0, True), "ksp_atol": (0.0, math.inf, False),
           "ksp_max_it": (1, 10**9, False)}


class _Options(Mapping):
    """PetscSettings' further options: a mapping that cannot change (a value, hashed and pickled as one)."""

    def __init__(self, items: Mapping):
        self._items = dict(items)

    def __getitem__(self, key):
        return self._items[key]

    def __iter__(self):
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._items.items(), key=lambda kv: kv[0])))

    def __repr__(self) -> str:
        return repr(self._items)


@dataclass(frozen=True)
class PetscSettings:
    """What a user sets of one solver's PETSc objects; None (False for the monitors): the solver's default.

    ``snes_rtol``, ``snes_atol``, ``snes_stol``, ``snes_max_it``: SNES's tolerances; ``linesearch``: its line
    search type (``bt``, ``basic``, ...); ``ksp_type``, ``ksp_rtol``, ``ksp_atol``, ``ksp_max_it``: the
    Krylov solver; ``pc_type``: the preconditioner; ``snes_monitor``, ``ksp_monitor``: PETSc's monitors;
    ``options``: further PETSc options of this solver, by name without dash and prefix
    (``{"ksp_gmres_restart": "60", "ksp_converged_reason": None}``, None a bare flag).  ValueError
    for a value out of its range, one line naming it.

    >>> PetscSettings(ksp_type="bcgs", ksp_rtol=1e-12).entries()
    {'ksp_type': 'bcgs', 'ksp_rtol': '1e-12'}
    """

    snes_rtol: float | None = None
    snes_atol: float | None = None
    snes_stol: float | None = None
    snes_max_it: int | None = None
    linesearch: str | None = None
    ksp_type: str | None = None
    ksp_rtol: float | None = None
    ksp_atol: float | None = None
    ksp_max_it: int | None = None
    pc_type: str | None = None
    snes_monitor: bool = False
    ksp_monitor: bool = False
    options: Mapping[str, str | None] = field(default_factory=dict)

    def __post_init__(self):
        for name, (lo, hi, hi_open) in _RANGES.items():
            v = getattr(self, name)
            if v is None:
                continue
            integer = name.endswith("max_it")
            kinds = (int, np.integer) if integer else (int, float, np.integer, np.floating)
            if isinstance(v, bool) or not isinstance(v, kinds) or not (lo <= v < hi if hi_open else lo <= v <= hi) \
                    or not math.isfinite(v):
                what = f"an integer in [{lo}, {hi:g}]" if integer else \
                    f"a real in [{lo:g}, {hi:g}{')' if hi_open else ']'}"
                raise ValueError(f"{name}: expected {what}, got {v!r}")
            object.__setattr__(self, name, int(v) if integer else float(v))
        for name in ("linesearch", "ksp_type", "pc_type"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, str) and _NAME.fullmatch(v)):
                raise ValueError(f"{name}: expected the name of a PETSc type, got {v!r}")
        for name in ("snes_monitor", "ksp_monitor"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name}: expected True or False, got {getattr(self, name)!r}")
        if not isinstance(self.options, Mapping):
            raise ValueError(f"options: expected a mapping of PETSc option names to strings, got {self.options!r}")
        for k, v in self.options.items():
            if not (isinstance(k, str) and _NAME.fullmatch(k)):
                raise ValueError(f"options: {k!r} is not a PETSc option name (give it without dash or prefix)")
            field_name = next((f for f, o in _OPTION_OF.items() if o == k), None)
            if field_name is not None and getattr(self, field_name) not in (None, False):
                raise ValueError(f"options: {k} is given as the field {field_name} too; give it once")
            if v is not None and not isinstance(v, str):
                raise ValueError(f"options: {k} = {v!r}; expected a string, or None for a bare flag")
        object.__setattr__(self, "options", _Options(self.options))

    def entries(self) -> dict:
        """The PETSc options these settings give (name without dash and prefix -> value, None a bare flag)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "options" or v is None or v is False:
                continue
            out[_OPTION_OF[f.name]] = None if v is True else (v if isinstance(v, str) else repr(v))
        return out | dict(self.options)

    @property
    def snes_given(self) -> list[str]:
        """The options given that only a SNES reads."""
        return [k for k in self.entries() if k.startswith("snes_")]


#: The solvers made in this process, for their prefixes (:class:`SolverOptions`).
_SOLVERS_MADE = itertools.count(1)


class SolverOptions:
    """One solver's settings in PETSc's options database under a prefix of its own, for the solver's lifetime.

    ``prefix``: the role's (``nat_``, ``arc_``, ``fold_``, none) after ``pa<n>_``, n counting the solvers made
    in the process: two solvers never read each other's options, nor the role's own options a caller may have
    left in the database (the command line reads those into :class:`PetscSettings`).  The values stay in
    the database while the solver lives and go in :meth:`destroy`: PETSc reads some of them only at the
    first solve (``ksp_converged_reason``, ``snes_view``, a block preconditioner's ``sub_`` options, a
    factorization's), after ``setFromOptions()``.
    """

    def __init__(self, role: str, settings: PetscSettings):
        self.prefix = f"pa{next(_SOLVERS_MADE)}_{role}"
        self.names: list[str] = []
        db = PETSc.Options()
        for name, value in settings.entries().items():
            db.setValue(self.prefix + name, value)
            self.names.append(self.prefix + name)

    def destroy(self) -> None:
        """Take the values out of the options database again."""
        db = PETSc.Options()
        for name in self.names:
            db.delValue(name)
        self.names = []


def is_solvers_own(name: str) -> bool:
    """Whether an option of the database is one a solver put there under its own prefix (:class:`SolverOptions`)."""
    return re.fullmatch(r"pa\d+_.*", name) is not None


def role_of(name: str) -> str:
    """An option name as the user gave it: without the solver's own ``pa<n>_`` (see :class:`SolverOptions`).

    >>> role_of("pa12_arc_ksp_type"), role_of("pa3_snes_rtol"), role_of("nat_snes_rtol")
    ('arc_ksp_type', 'snes_rtol', 'nat_snes_rtol')
    """
    m = re.fullmatch(r"pa\d+_(.*)", name)
    return m.group(1) if m else name


def create_snes(comm: PETSc.Comm, prefix: str, function, residual: PETSc.Vec, jacobian,
                J: PETSc.Mat, P: PETSc.Mat, setup_pc, precheck, full_steps: bool = False,
                bordered: bool = False, tol: Tolerances = Tolerances(),
                settings: PetscSettings = PetscSettings()) -> tuple[PETSc.SNES, SolverOptions]:
    """A Newton-Krylov SNES for the role ``prefix``, configured with its defaults, then ``settings``
    (:class:`SolverOptions`), then ``setFromOptions()``; the SNES and its options (freed after it).

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
    snes, options = PETSc.SNES().create(comm), None
    try:            # an option refused (a type name PETSc does not know): the SNES would outlive the call
        options = SolverOptions(prefix, settings)
        snes.setOptionsPrefix(options.prefix)
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
        # every iterate's residual norm, for solved(): the whole of each solve (max_it as the options left it)
        snes.setConvergenceHistory(length=snes.getTolerances()[3] + 1, reset=True)
    except BaseException:
        snes.destroy()
        if options is not None:
            options.destroy()
        raise
    return snes, options


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
        self.its, self.stale = its, True
        self.at: tuple | None = None

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


#: A relative stop counts where SNES's last iteration shrank the residual at least this many times
#: (Newton's quadratic phase: 3.21e-2, 1.81e-3, 6.36e-6 at mu = 3), not where it still shrank it by a
#: constant factor (0.39 an iteration, a guarded descent from a predictor by a wall).
QUADRATIC = 10.0


def solved(snes: PETSc.SNES, X: PETSc.Vec) -> bool:
    """Whether the last solve of ``snes`` left X a solution (collective): PETSc's reason is convergence, and
    where the reason is rtol's relative decrease, either the residual left is at most rtol times the size of
    X (at least 1) or the last Newton iteration shrank the residual at least QUADRATIC times.

    Why: rtol measures the decrease from the first iterate, and from a first iterate far off the curve that
    decrease proves nothing.  A predictor by the wall of a truncated height distribution (where P grows
    like the gap's -8th power) started a solve at a residual of 2.0e11; the domain guard shortened every
    Newton step, the residual fell by a steady factor 0.39 an iteration, and after 25 of them rtol's 1e-10
    "converged" it at 13.3, a point off the curve that no later step could leave (mu = 0.731, sigma =
    0.20537, K = 3.6876, 201 uniform nodes: stuck at lambda = -1.099).  A solve that has reached the curve
    ends in Newton's quadratic phase, each iteration squaring the residual's smallness (at mu = 3 a first
    residual of 1.3e5 ends 3.2e-2, 1.8e-3, 6.4e-6, accepted as before); one still in a steady descent is
    not there yet, and its step is retried shorter.
    """
    reason = snes.getConvergedReason()
    if reason <= 0:
        return False
    if reason != PETSc.SNES.ConvergedReason.CONVERGED_FNORM_RELATIVE:
        return True
    left = snes.getFunctionNorm()
    if left <= snes.getTolerances()[0] * max(1.0, X.norm()):
        return True
    history, its = snes.getConvergenceHistory()[0], snes.getIterationNumber()
    return 1 <= its < len(history) and QUADRATIC * left <= history[its - 1]


def fresh_retry(snes: PETSc.SNES, X: PETSc.Vec, reuse: PCReuse, work: PETSc.Vec) -> bool:
    """Solve from X in place; after a failure, once more from X with a fresh preconditioner.

    A factorization kept from a distant point of the curve can make the first
    linear solve fail where Newton itself is fine.  ``work`` keeps the start.
    """
    X.copy(work)
    for _ in range(2):
        with python_errors():
            snes.solve(None, X)
        if solved(snes, X):
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
        The role's options prefix ("" for the fixed-approach solve, "nat_" for the natural
        corrector of the continuation); the SNES's own comes before it (:class:`SolverOptions`).
    full_steps
        See :func:`create_snes`.
    pc_reuse_its
        See :class:`PCReuse`.
    settings
        The user's PETSc settings of this solver (:class:`PetscSettings`).
    """

    def __init__(self, problem, prefix: str = "", full_steps: bool = False, pc_reuse_its: int = PC_REUSE_ITS,
                 tol: Tolerances = Tolerances(), settings: PetscSettings = PetscSettings()):
        self.pb, self.p, self.options = problem, 0.0, None
        self.snes: PETSc.SNES = None      # made below; None only until then (destroy() skips it)
        self.pmat = problem.create_pmat(0)
        self.reuse = PCReuse(pc_reuse_its)
        self.work, residual = problem.create_vec(), problem.create_vec()
        try:
            self.snes, self.options = create_snes(problem.comm, prefix, self._function, residual, self._jacobian,
                                                  problem.jacobian, self.pmat or problem.jacobian, problem.setup_pc,
                                                  self._precheck, full_steps, tol=tol, settings=settings)
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
        return solved(self.snes, x)

    @property
    def iterations(self) -> tuple[int, int]:
        """Newton and Krylov iterations of the last solve."""
        return self.snes.getIterationNumber(), self.snes.getLinearSolveIterations()

    def destroy(self) -> None:
        """Free the PETSc objects made here."""
        for obj in (self.snes, self.pmat, self.work, self.options):
            if obj is not None:
                obj.destroy()
