"""Predictor-corrector continuation of G(H, lambda) = 0 (paper, "Numerical Procedure").

The curve is followed in the unknowns X = (H, lambda), measured in the
grid-independent inner product <u, v> = (1/r_m) integral u v dr for H.

* Natural corrector (eq. 20-22): Newton on G(H; lambda) = 0 at the predicted
  lambda, with the fixed-lambda SNES; tangent from G_H phi_0 = -G_lambda with
  the normalisation and sign rule of eq. (16)-(19).  Fails at a turning point,
  where G_H is singular.
* Pseudo-arclength corrector (eq. 24-25): Newton on [G; Q] = 0, whose Jacobian
  is the bordered matrix [[G_H, G_lambda], [Hdot^T, lambdadot]], a MatNest
  holding the shell G_H; regular at a fold.  Its tangent solves the same
  bordered matrix with right-hand side (0, 1), which also keeps eq. (19).
* ``auto`` (the paper's switch) takes the natural step while |lambdadot| >= 0.5.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from .options import TABLE
from .residual import PCReuse, preallocation, shorten_to_wall
from .solver import configure

__all__ = ["Point", "Bordered", "Continuation"]

#: The paper's switch to pseudo-arclength below this |lambdadot|.
SWITCH = 0.5


@dataclass
class Point:
    """A computed point of the curve, with its unit tangent (local parts of H)."""

    h: np.ndarray
    lam: float
    F: float
    th: np.ndarray
    tl: float
    dF: float                 # dF/ds along the tangent
    ds: float = 0.0           # the step that reached it
    dev: float = 0.0          # |corrector - predictor| / ds: the curvature the step met
    its: int = 0              # Newton iterations of the corrector
    ksp_its: int = 0
    kind: str = "start"       # "natural" | "arclength" | "start" | "event"


class Bordered:
    """The pseudo-arclength system [G(H, lambda); Q] = 0 and its SNES (eq. 24-25).

    X = (H, lambda) is one PETSc Vec, lambda its last entry (on the last rank),
    so the MatNest's blocks line up with X without index sets.
    """

    def __init__(self, problem):
        pb = self.pb = problem
        comm = self.comm = pb.comm
        N = pb.r.size
        self.nloc = pb.hi - pb.lo
        self.last = comm.getRank() == comm.getSize() - 1
        n1 = 1 if self.last else 0
        self.X = PETSc.Vec().createMPI((self.nloc + n1, N + 1), comm=comm)
        self.H, self.G = pb.create_vec(), pb.create_vec()

        def dense(rows, cols):
            M = PETSc.Mat().createDense((rows, cols), comm=comm)
            M.setUp()
            return M

        self.col = dense((self.nloc, N), (n1, 1))          # G_lambda = 1
        self.col.getDenseArray()[:] = 1.0
        self.col.assemble()
        self.row = dense((n1, 1), (self.nloc, N))          # weighted Hdot^T
        self.corner = dense((n1, 1), (n1, 1))              # lambdadot
        self.K = PETSc.Mat().createNest([[pb.J, self.col], [self.row, self.corner]], comm=comm)
        ext = (self.nloc + n1, N + 1)
        if pb.pmat_kind == "dense":
            self.P = dense(ext, ext)
        elif pb.pmat_kind == "band":
            self.P = self._band_bordered(ext)
        else:
            self.P = self.K
        self.snes = PETSc.SNES().create(comm)
        self.snes.setFunction(self.form_function, self.X.duplicate())
        self.snes.setJacobian(self.form_jacobian, self.K, self.P)
        configure(self.snes, pb.pmat_kind, self.precheck, full_steps=True)
        self.reuse = PCReuse(pb.reuse.its)
        # the hyperplane Q of eq. (24): through (h0, lam0), normal (th, tl), at distance ds
        self.h0, self.lam0, self.th, self.tl, self.ds = None, 0.0, None, 1.0, 0.0

    # -- X = (H, lambda) ---------------------------------------------------------
    def split(self, X: PETSc.Vec):
        """Local H part of X and lambda (broadcast from the last rank)."""
        x = X.getArray(readonly=True)
        lam = float(x[self.nloc]) if self.last else None
        return x[:self.nloc], self.comm.tompi4py().bcast(lam, root=self.comm.getSize() - 1)

    def join(self, h: np.ndarray, lam: float, X: PETSc.Vec | None = None) -> PETSc.Vec:
        X = X or self.X
        X.setArray(np.append(h, lam) if self.last else h)
        return X

    def set_border(self, th: np.ndarray, tl: float) -> None:
        """Bottom row (w * Hdot)^T, lambdadot of the bordered matrix."""
        full = self.comm.tompi4py().allgather(self.pb.w * th)
        if self.last:
            self.row.getDenseArray()[:] = np.concatenate(full)
            self.corner.getDenseArray()[:] = tl
        self.row.assemble()
        self.corner.assemble()
        self.K.assemble()

    # -- SNES callbacks ----------------------------------------------------------
    def form_function(self, snes, X, R):
        """[G(H, lambda); Q(H, lambda)] with Q of eq. (24)."""
        h, lam = self.split(X)
        self.H.setArray(h)
        self.pb.residual(self.H, lam, self.G)
        q = self.pb.inner(self.th, h - self.h0) + self.tl * (lam - self.lam0) - self.ds
        self.join(self.G.getArray(readonly=True), q, R)

    def form_jacobian(self, snes, X, K, P):
        h, _ = self.split(X)
        self.H.setArray(h)
        self.linearize(self.reuse(snes.getKSP()))

    def linearize(self, assemble: bool) -> None:
        """G_H at self.H (shell) and, with ``assemble``, the bordered matrix for the PC."""
        pb = self.pb
        pb.linearize(self.H, assemble=False)
        if assemble and pb.pmat_kind == "dense":
            a = self.P.getDenseArray()
            pb.jacobian_rows(a[:self.nloc, :-1])
            a[:self.nloc, -1] = 1.0
            if self.last:
                a[-1, :-1] = self.row.getDenseArray()[0]
                a[-1, -1] = self.corner.getDenseArray()[0, 0]
            self.P.assemble()
        elif assemble and pb.pmat_kind == "band":
            self._fill_band()
        self.K.assemble()

    def precheck(self, X, Y, *args) -> bool:
        h, _ = self.split(X)
        return shorten_to_wall(self.pb, h, Y, Y.getArray(readonly=True)[:self.nloc])

    # -- near-field bordered preconditioning matrix ------------------------------
    def _band_bordered(self, ext) -> PETSc.Mat:
        ai, aj = self._band_csr(*self.pb.band_pattern(), np.zeros(0), np.zeros(0))[:2]
        lo, hi = self.X.getOwnershipRange()
        P = PETSc.Mat().createAIJ((ext, ext), nnz=preallocation(ai, aj, lo, hi), comm=self.comm)
        P.setUp()
        return P

    def _band_csr(self, ai, aj, v, border):
        """The near-field CSR of G_H with the G_lambda column and, on the last rank, the border row."""
        N = self.pb.r.size
        j = np.insert(aj, ai[1:], N)
        vals = np.insert(v, ai[1:], 1.0) if v.size else v
        ai2 = ai + np.arange(ai.size)
        if self.last:
            j = np.concatenate([j, np.arange(N + 1)])
            vals = np.concatenate([vals, border]) if v.size else vals
            ai2 = np.append(ai2, ai2[-1] + N + 1)
        return ai2.astype(PETSc.IntType), j.astype(PETSc.IntType), vals

    def _fill_band(self) -> None:
        ai, aj, v = self.pb.band_values()
        border = np.append(self.row.getDenseArray()[0], self.corner.getDenseArray()[0, 0]) if self.last else None
        self.P.setValuesCSR(*self._band_csr(ai, aj, v, border))
        self.P.assemble()

    # -- use ---------------------------------------------------------------------
    def correct(self, a: Point, ds: float) -> tuple[np.ndarray, float, int, int] | None:
        """Solve for the point at distance ds from ``a`` along its tangent (eq. 24-25).

        Returns (h, lambda, Newton its, KSP its), or None when Newton fails or
        the predictor leaves the domain.
        """
        th, tl = a.th, a.tl
        h = a.h + ds * th
        if not self.pb.inside(h):
            return None
        self.h0, self.lam0, self.th, self.tl, self.ds = a.h, a.lam, th, tl, ds
        self.set_border(th, tl)
        if not fresh_retry(self.snes, self.join(h, a.lam + ds * tl), self.reuse):
            return None
        h, lam = self.split(self.X)
        return h.copy(), lam, self.snes.getIterationNumber(), self.snes.getLinearSolveIterations()

    def tangent(self, h: np.ndarray, lam: float, th: np.ndarray, tl: float):
        """Unit tangent at (h, lam) oriented along (th, tl): solve [[G_H, 1], [w th, tl]] z = (0, 1)."""
        self.H.setArray(h)
        self.set_border(th, tl)
        rhs = self.X.duplicate()
        rhs.set(0.0)
        if self.last:
            rhs.setValue(rhs.getSize() - 1, 1.0)
        rhs.assemble()
        z = self.X.duplicate()
        ksp = self.snes.getKSP()
        if not krylov_retry(ksp, self.K, self.P, rhs, z, self.reuse, self.linearize):
            return None
        zh, zl = self.split(z)
        norm = math.sqrt(self.pb.inner(zh, zh) + zl * zl)
        return zh / norm, zl / norm, ksp.getIterationNumber()


def fresh_retry(snes: PETSc.SNES, X: PETSc.Vec, reuse: PCReuse) -> bool:
    """Solve from X in place; after a failure, once more with a fresh preconditioner.

    A factorization kept from a distant point of the curve can make the first
    linear solve fail where Newton itself is fine.
    """
    x0 = X.copy()
    for _ in range(2):
        snes.solve(None, X)
        if snes.getConvergedReason() > 0:
            return True
        reuse.expire()
        x0.copy(X)
    return False


def krylov_retry(ksp: PETSc.KSP, A, P, b: PETSc.Vec, x: PETSc.Vec, reuse: PCReuse, linearize) -> bool:
    """Solve A x = b at the point set by ``linearize(assemble)``; retry once with a fresh PC."""
    for _ in range(2):
        linearize(reuse(ksp))
        ksp.setOperators(A, P)
        ksp.solve(b, x)
        if ksp.getConvergedReason() > 0:
            return True
        reuse.expire()
    return False


def _default(name: str):
    return TABLE[name].default


@dataclass
class Settings:
    """Step control and stop criteria; the defaults are the options' (options.TABLE)."""

    kind: str = _default("cont_type")
    ds: float = _default("cont_ds")
    ds_min: float = _default("cont_ds_min")
    ds_max: float = _default("cont_ds_max")
    newton_target: int = _default("cont_newton_target")
    max_deviation: float = _default("cont_max_deviation")
    dF_max: float = _default("cont_dF_max")
    lambda_max: float = math.inf
    F_max: float = _default("cont_F_max")
    max_steps: int = _default("cont_max_steps")
    max_folds: int = _default("cont_max_folds")
    monitor: bool = _default("cont_monitor")


class Continuation:
    """Trace the curve from a start point; collect the points and step statistics."""

    def __init__(self, problem, snes: PETSc.SNES, settings: Settings):
        self.pb, self.snes, self.set = problem, snes, settings
        self.bordered = Bordered(problem)
        self.points: list[Point] = []
        self.rejected = 0
        self.folds = 0
        self.stop_reason = ""

    # -- tangents -----------------------------------------------------------
    def natural_tangent(self, h: np.ndarray, lam: float, prev: Point):
        """Tangent of eq. (16)-(19): G_H phi_0 = -G_lambda, a = +-1/sqrt(1 + |phi_0|^2)."""
        pb = self.pb
        H = pb.create_vec()
        H.setArray(h)
        rhs, phi = pb.create_vec(), pb.create_vec()
        rhs.set(-1.0)
        ksp = self.snes.getKSP()
        if not krylov_retry(ksp, pb.J, pb.P, rhs, phi, pb.reuse,
                            lambda assemble: pb.linearize(H, assemble)):
            return None
        p = phi.getArray(readonly=True).copy()
        a = 1.0 / math.sqrt(1.0 + pb.inner(p, p))
        if a * (pb.inner(prev.th, p) + prev.tl) < 0:      # eq. (19)
            a = -a
        return a * p, a, ksp.getIterationNumber()

    def make_point(self, h, lam, th, tl, **kw) -> Point:
        F, dF = self.pb.load_rate(h, th)
        return Point(h=h, lam=lam, F=F, th=th, tl=tl, dF=dF, **kw)

    def start(self, lam0: float) -> Point:
        """Solve at lam0 from the rigid guess; tangent pointing to larger lambda."""
        pb = self.pb
        H = pb.rigid(lam0, pb.create_vec())
        pb.lam = lam0
        self.snes.solve(None, H)
        if self.snes.getConvergedReason() <= 0:
            raise RuntimeError(f"no solution at the start lambda = {lam0:g}; give -cont_lambda_start further apart")
        h = H.getArray(readonly=True).copy()
        guess = Point(h=h, lam=lam0, F=0.0, th=np.zeros_like(h), tl=1.0, dF=0.0)
        th, tl, kits = self.bordered.tangent(h, lam0, guess.th, 1.0)
        return self.make_point(h, lam0, th, tl, its=self.snes.getIterationNumber(),
                               ksp_its=self.snes.getLinearSolveIterations() + kits)

    # -- one step -------------------------------------------------------------
    def natural_ok(self, a: Point) -> bool:
        return self.set.kind == "natural" or (self.set.kind == "auto" and abs(a.tl) >= SWITCH)

    def natural(self, a: Point, ds: float, tangent: bool = True):
        """Natural corrector (eq. 20-22) at lambda = a.lam + ds a.tl; tangent of eq. (16)-(19)."""
        pb = self.pb
        lam = a.lam + ds * a.tl
        h = a.h + ds * a.th                               # eq. (20)
        if not pb.inside(h):
            return None
        H = pb.create_vec()
        H.setArray(h)
        pb.lam = lam
        if not fresh_retry(self.snes, H, pb.reuse):       # eq. (21)-(22)
            return None
        h = H.getArray(readonly=True).copy()
        its, kits = self.snes.getIterationNumber(), self.snes.getLinearSolveIterations()
        tan = self.natural_tangent(h, lam, a) if tangent else (a.th, a.tl, 0)
        return None if tan is None else (h, lam, tan, its, kits, "natural")

    def arclength(self, a: Point, ds: float, tangent: bool = True):
        """Pseudo-arclength corrector (eq. 24-25) at distance ds; tangent of the bordered system."""
        sol = self.bordered.correct(a, ds)
        if sol is None:
            return None
        h, lam, its, kits = sol
        tan = self.bordered.tangent(h, lam, a.th, a.tl) if tangent else (a.th, a.tl, 0)
        return None if tan is None else (h, lam, tan, its, kits, "arclength")

    def correct(self, a: Point, ds: float, tangent: bool = True):
        """The point at step ds from a: the corrector the mode asks for, the other as fallback.

        The natural one serves only away from folds (|lambdadot| >= 0.1), where
        lambda is a good parameter; near the wall of a fine roughness rule it is
        the more robust of the two.  Without ``tangent`` the point gets a's.
        """
        first, second = (self.natural, self.arclength) if self.natural_ok(a) else (self.arclength, self.natural)
        sol = first(a, ds, tangent)
        if sol is None and (second is self.arclength or abs(a.tl) >= 0.1) and self.set.kind != "natural":
            sol = second(a, ds, tangent)
        return sol

    def step(self, a: Point, ds: float) -> Point | None:
        """One predictor-corrector step of length ds from a, or None (retry smaller)."""
        pb = self.pb
        sol = self.correct(a, ds)
        if sol is None:
            return None
        h, lam, (th, tl, tk), its, kits, kind = sol
        # the corrector's distance from the predictor grows as ds^2 times the curvature;
        # a step that had to travel far may have cut across a fold pair unseen
        dh = h - (a.h + ds * a.th)
        dev = math.sqrt(pb.inner(dh, dh) + (lam - a.lam - ds * a.tl) ** 2) / ds
        if dev > self.set.max_deviation or pb.inner(a.th, th) + a.tl * tl < 0.8:
            return None
        b = self.make_point(h, lam, th, tl, ds=ds, its=its, ksp_its=kits + tk, kind=kind, dev=dev)
        # the curve F(lambda) is what users read: resolve it in F too
        return b if abs(b.F - a.F) <= self.set.dF_max * max(1.0, abs(a.F)) else None

    def done(self, b: Point) -> str:
        s = self.set
        if b.F >= s.F_max:
            return f"load F = {b.F:.4g} >= -cont_F_max {s.F_max:g}"
        if b.lam >= s.lambda_max:
            return f"approach lambda = {b.lam:.4g} >= -cont_lambda_max {s.lambda_max:g}"
        if len(self.points) > s.max_steps:
            return f"-cont_max_steps {s.max_steps} reached"
        if self.folds > s.max_folds:
            return f"more than -cont_max_folds {s.max_folds} turning points"
        return ""

    def run(self, lam0: float, on_step=None):
        """Trace from lam0 until a stop criterion; ``on_step(a, b)`` sees every accepted step."""
        s = self.set
        a = self.start(lam0)
        self.points.append(a)
        ds = s.ds
        self.monitor(a)
        while True:
            b = self.step(a, ds)
            if b is None:
                self.pb.reuse.expire()
                self.bordered.reuse.expire()
                self.rejected += 1
                ds *= 0.5
                if ds < s.ds_min:
                    where = "a turning point (natural continuation cannot pass it)" \
                        if s.kind == "natural" else "a point it cannot pass"
                    self.stop_reason = f"step below -cont_ds_min at lambda = {a.lam:.6g}: {where}"
                    break
                continue
            self.points.append(b)
            self.folds += a.tl * b.tl < 0
            self.monitor(b)
            if on_step:
                on_step(a, b)
            self.stop_reason = self.done(b)
            if self.stop_reason:
                break
            # grow on fast Newton and a nearly straight curve, shrink on slow Newton
            if b.its < s.newton_target and b.dev < 0.5 * s.max_deviation and abs(b.F - a.F) < 0.5 * s.dF_max * max(1.0, abs(a.F)):
                ds = min(1.5 * ds, s.ds_max)
            elif b.its > s.newton_target:
                ds = max(0.7 * ds, s.ds_min)
            a = b
        return self.points

    def monitor(self, p: Point) -> None:
        if self.set.monitor and self.pb.comm.getRank() == 0:
            print(f"{len(self.points) - 1:4d} CONT lambda {p.lam: .10e} F {p.F: .10e} ds {p.ds:.3e} "
                  f"{p.kind[:3]} Newton {p.its} KSP {p.ksp_its}", flush=True)
