"""Small problems with known answers for the continuation core (no adhesion model).

Each class implements the problem protocol of :mod:`petsc_adhesion.core.continuation`
with petsc4py on one rank (PETSc.COMM_SELF by default, or COMM_WORLD of size 1):

===================  ===========================================  =====================================
class                G(x, p)                                      known answer
===================  ===========================================  =====================================
:class:`ScalarFold`  x^2 + p   (``sign=-1``: x^2 - p)              fold at (0, 0): p largest (smallest)
:class:`Cusp`        x^3 - a x + p                                folds at x = +-sqrt(a/3),
                                                                  p = +-2 (a/3)^(3/2); none for a < 0
:class:`Barrier`     p + x + 1/x on x > 0                         fold at (1, -2); Newton overshoots
                                                                  the wall x = 0 from x < 1
:class:`Bratu`       u'' + p e^u, u(0) = u(1) = 0, n points       fold -> lambda* = 3.5138307191...
===================  ===========================================  =====================================

The operator ``jacobian`` is a MatPython (``jacobian="python"``, the default)
or an assembled dense Mat (``"dense"``).  The preconditioning matrix is the
core's :class:`~petsc_adhesion.discretization.preconditioning.Dense` strategy (``pmat="dense"``,
through ``jacobian_rows``), this module's own :class:`OwnDense` (created and
filled here, border included), :class:`~petsc_adhesion.discretization.preconditioning.Band`
(``"band"``, half bandwidth 1: exact for all of them, through ``band_values``) or none
(``"none"``: GMRES on the operator, enough for one or two unknowns).

The domain guard: ``xmin`` (None: no guard) makes every component keep
x > xmin; ``inside`` refuses predictors beyond it, ``step_fraction`` lets a
Newton step cover at most ``to_wall`` of the way to it, and ``residual``
raises :class:`Outside` (after counting it in ``counts["outside"]``) if
evaluated beyond it.  ``counts`` also records residual evaluations,
linearizations, refused predictors and shortened Newton steps.
"""
from __future__ import annotations

import math
from collections import Counter

import numpy as np
from petsc4py import PETSc
from scipy.optimize import brentq

from petsc_adhesion.discretization.preconditioning import Band, Dense, Layout, Shell

__all__ = ["Outside", "OwnDense", "Toy", "ScalarFold", "Cusp", "Barrier", "Bratu", "BRATU_THETA_STAR",
           "BRATU_LAMBDA_STAR", "BRATU_MID_STAR", "bratu_theta", "bratu_mid", "bratu_discrete_fold"]


class Outside(ValueError):
    """The residual was asked for outside the problem's domain."""


class OwnDense:
    """A preconditioning matrix made and filled here (not by the core's strategies): dense, LU."""

    kind = "own"

    def create(self, layout: Layout, comm, extra: int = 0) -> PETSc.Mat:
        m = layout.N + extra
        P = PETSc.Mat().createDense(((m, m), (m, m)), comm=comm)
        P.setUp()
        return P

    def fill(self, P: PETSc.Mat, problem, layout: Layout, borders=()) -> None:
        N = layout.N
        a = np.zeros(P.getSize())
        problem.jacobian_rows(a[:N, :N])
        for border in borders:
            a[:N, N] = border.column
            a[N, :N] = border.row
            a[N, N] = border.corner
        P.getDenseArray()[:] = a
        P.assemble()

    @staticmethod
    def setup_pc(pc: PETSc.PC, bordered: bool = False) -> None:
        pc.setType("lu")


class _Operator:
    """MatPython context: y = G_x v at the linearization point."""

    def __init__(self, pb: "Toy"):
        self.pb = pb

    def mult(self, mat, x, y):
        y.setArray(self.pb.jac_mult(x.getArray(readonly=True)))


class Toy:
    """Base of the toy problems: the protocol from a few numpy methods of the subclass.

    A subclass provides ``G(x, p)``, ``Gx(x, p)`` (dense, n x n), ``Gp(x, p)`` and
    ``observables(x, p, xdot, pdot)``, all on numpy arrays.
    """

    parameter = "p"

    def __init__(self, n: int, comm=None, jacobian: str = "python", pmat: str = "dense",
                 xmin: float | None = None, to_wall: float = 0.9):
        self.comm = PETSc.COMM_SELF if comm is None else comm
        if self.comm.getSize() != 1:
            raise ValueError("the toy problems are serial")
        self.n = n
        self.layout = Layout(0, n, n, True)
        self.weights = np.ones(n)
        self.xmin, self.to_wall = xmin, to_wall
        self.guard_on = True                # False: step_fraction lets every Newton step through
        self.counts = Counter()
        self.lowest = math.inf              # smallest component at which the residual was evaluated
        self.x_lin, self.p_lin = np.zeros(n), 0.0
        sizes = ((n, n), (n, n))
        if jacobian == "python":
            self.jacobian = PETSc.Mat().createPython(sizes, _Operator(self), comm=self.comm)
        elif jacobian == "dense":
            self.jacobian = PETSc.Mat().createDense(sizes, comm=self.comm)
        else:
            raise ValueError(jacobian)
        self.jacobian.setUp()
        self.jacobian_kind = jacobian
        self.pc = {"dense": Dense, "own": OwnDense, "none": Shell, "band": lambda: Band(1)}[pmat]()

    # -- the model (subclasses) -------------------------------------------------
    def G(self, x: np.ndarray, p: float) -> np.ndarray:
        raise NotImplementedError

    def Gx(self, x: np.ndarray, p: float) -> np.ndarray:
        raise NotImplementedError

    def Gp(self, x: np.ndarray, p: float) -> np.ndarray:
        raise NotImplementedError

    def observables(self, x, p, xdot, pdot):
        return {}, {}

    def jac_mult(self, v: np.ndarray) -> np.ndarray:
        """G_x v at the linearization point (dense by default)."""
        return self.Gx(self.x_lin, self.p_lin) @ v

    # -- the protocol ---------------------------------------------------------
    def create_vec(self) -> PETSc.Vec:
        v = PETSc.Vec().create(comm=self.comm)
        v.setSizes((self.n, self.n))
        v.setType(PETSc.Vec.Type.STANDARD)
        v.setUp()
        return v

    def residual(self, x: PETSc.Vec, p: float, G: PETSc.Vec) -> None:
        a = x.getArray(readonly=True)
        self.counts["residual"] += 1
        self.lowest = min(self.lowest, float(a.min()))
        if self.xmin is not None and not np.all(a > self.xmin):
            self.counts["outside"] += 1
            raise Outside(f"residual at x = {a.min():g} <= xmin = {self.xmin:g}")
        G.setArray(self.G(a, p))

    def dG_dp(self, x: PETSc.Vec, p: float, out: np.ndarray) -> np.ndarray:
        out[:] = self.Gp(x.getArray(readonly=True), p)
        return out

    def linearize(self, x: PETSc.Vec, p: float) -> None:
        self.counts["linearize"] += 1
        self.x_lin, self.p_lin = x.getArray(readonly=True).copy(), p
        if self.jacobian_kind == "dense":
            self.jacobian.getDenseArray()[:] = self.Gx(self.x_lin, p)
            self.jacobian.assemble()

    def jacobian_rows(self, out: np.ndarray) -> np.ndarray:
        out[:] = self.Gx(self.x_lin, self.p_lin)
        return out

    def band_values(self, ai: np.ndarray, aj: np.ndarray) -> np.ndarray:
        """G_x on the CSR pattern (ai, aj) of the Band strategy."""
        rows = np.repeat(np.arange(self.n), np.diff(ai))
        return self.Gx(self.x_lin, self.p_lin)[rows, aj]

    def create_pmat(self, borders: int):
        return self.pc.create(self.layout, self.comm, borders)

    def fill_pmat(self, P, borders=()) -> None:
        self.pc.fill(P, self, self.layout, list(borders))

    def setup_pc(self, pc: PETSc.PC, bordered: bool = False) -> None:
        self.pc.setup_pc(pc, bordered)

    def inside(self, x: np.ndarray) -> bool:
        ok = self.xmin is None or bool(np.all(x > self.xmin))
        if not ok:
            self.counts["refused"] += 1
        return ok

    def step_fraction(self, x: np.ndarray, y: np.ndarray) -> float:
        """Largest fraction of x -> x - y covering at most ``to_wall`` of the way to xmin."""
        if self.xmin is None or not self.guard_on:
            return 1.0
        toward = y > 0
        return float(np.min(self.to_wall * (x[toward] - self.xmin) / y[toward], initial=1.0))

    def record_guard(self) -> None:
        self.counts["shortened"] += 1

    def observe(self, x, p, xdot, pdot):
        return self.observables(np.asarray(x), p, np.asarray(xdot), pdot)

    # -- helpers for the tests -------------------------------------------------
    def vec(self, values) -> PETSc.Vec:
        """A new Vec holding ``values``."""
        v = self.create_vec()
        v.setArray(np.broadcast_to(np.asarray(values, dtype=float), (self.n,)))
        return v

    def destroy(self) -> None:
        self.jacobian.destroy()


class ScalarFold(Toy):
    """G(x, p) = x^2 + sign p: the curve p = -sign x^2, fold at (0, 0).

    ``sign=+1``: the fold is where p is largest (branch p <= 0); ``sign=-1``: smallest.
    Observables: ``x`` and ``f = x + p`` (on the curve f = x - sign x^2: an extremum
    at x = sign/2, f = sign/4, p = -sign/4; a maximum for sign = +1, a minimum for -1).
    Stable (for dx/dt = -G) where G_x = 2x > 0.
    """

    def __init__(self, sign: int = 1, **kw):
        self.sign = float(sign)
        super().__init__(1, **kw)

    def G(self, x, p):
        return x * x + self.sign * p

    def Gx(self, x, p):
        return np.diag(2.0 * x)

    def Gp(self, x, p):
        return np.full_like(x, self.sign)

    def observables(self, x, p, xdot, pdot):
        return {"x": float(x[0]), "f": float(x[0] + p)}, {"x": float(xdot[0]), "f": float(xdot[0] + pdot)}

    def on_curve(self, x: float) -> float:
        """p of the curve at x."""
        return -self.sign * x * x

    @staticmethod
    def stable(pt) -> bool:
        return pt.x[0] > 0


class Cusp(Toy):
    """G(x, p) = x^3 - a x + p: an S-curve p = a x - x^3 for a > 0, monotone for a < 0.

    For a > 0: a fold where p is largest at x = sqrt(a/3), p = 2 (a/3)^(3/2), one
    where it is smallest at the mirror point; at p = +-2 (a/3)^(3/2) the third root
    (the jump's landing) is x = -+2 sqrt(a/3).  Stable where G_x = 3x^2 - a > 0.
    """

    def __init__(self, a: float, **kw):
        self.a = float(a)
        super().__init__(1, **kw)

    def G(self, x, p):
        return x ** 3 - self.a * x + p

    def Gx(self, x, p):
        return np.diag(3.0 * x * x - self.a)

    def Gp(self, x, p):
        return np.ones_like(x)

    def observables(self, x, p, xdot, pdot):
        return {"x": float(x[0])}, {"x": float(xdot[0])}

    def on_curve(self, x: float) -> float:
        return self.a * x - x ** 3

    def folds(self):
        """((x, p) where p is largest, (x, p) where it is smallest), or None for a <= 0."""
        if self.a <= 0:
            return None
        xf, pf = math.sqrt(self.a / 3), 2 * (self.a / 3) ** 1.5
        return (xf, pf), (-xf, -pf)

    def stable(self, pt) -> bool:
        return 3 * pt.x[0] ** 2 - self.a > 0


class Barrier(Toy):
    """G(x, p) = p + x + 1/x on x > 0 (the wall x = 0 is part of the problem, as in adhesion).

    The curve p = -(x + 1/x) has its fold at x = 1, p = -2 (p largest).  From a
    guess in (1/2, 1) at p = -5/2 the full Newton step lands at x < 0: only the
    guard keeps Newton in the domain.  Observable ``inv`` = 1/x.
    """

    def __init__(self, **kw):
        kw.setdefault("xmin", 0.0)
        super().__init__(1, **kw)

    def G(self, x, p):
        return p + x + 1.0 / x

    def Gx(self, x, p):
        return np.diag(1.0 - 1.0 / (x * x))

    def Gp(self, x, p):
        return np.ones_like(x)

    def observables(self, x, p, xdot, pdot):
        return {"x": float(x[0]), "inv": float(1 / x[0])}, {"x": float(xdot[0]), "inv": float(-xdot[0] / x[0] ** 2)}

    def on_curve(self, x: float) -> float:
        return -(x + 1 / x)


class Bratu(Toy):
    """1-D Bratu u'' + p e^u = 0 on (0, 1), u(0) = u(1) = 0: second differences on n interior nodes.

    Weights h (the trapezoid rule; the boundary values are zero).  Observables:
    ``mid`` = u(1/2) (n odd: a node) and ``max`` = max u, with their rates.
    """

    def __init__(self, n: int, **kw):
        super().__init__(n, **kw)
        self.h = 1.0 / (n + 1)
        self.weights = np.full(n, self.h)
        self.nodes = self.h * np.arange(1, n + 1)
        self.mid = n // 2
        self._lap = (np.diag(np.full(n, -2.0)) + np.diag(np.ones(n - 1), 1) + np.diag(np.ones(n - 1), -1)) \
            / self.h ** 2

    def lap(self, u):
        v = -2.0 * u
        v[1:] += u[:-1]
        v[:-1] += u[1:]
        return v / self.h ** 2

    def G(self, u, p):
        return self.lap(u) + p * np.exp(u)

    def Gx(self, u, p):
        return self._lap + np.diag(p * np.exp(u))

    def Gp(self, u, p):
        return np.exp(u)

    def jac_mult(self, v):
        return self.lap(v) + self.p_lin * np.exp(self.x_lin) * v

    def observables(self, u, p, udot, pdot):
        k = int(np.argmax(u))
        return ({"mid": float(u[self.mid]), "max": float(u[k])},
                {"mid": float(udot[self.mid]), "max": float(udot[k])})


# -- closed forms of Bratu's continuum problem ----------------------------------------
def bratu_lambda(theta: float) -> float:
    """lambda of the solution u = -2 ln[cosh((x - 1/2) theta/2) / cosh(theta/4)]: theta^2 / (2 cosh^2(theta/4))."""
    return theta * theta / (2 * math.cosh(theta / 4) ** 2)


def bratu_mid(theta: float) -> float:
    """u(1/2) = 2 ln cosh(theta/4)."""
    return 2 * math.log(math.cosh(theta / 4))


def bratu_theta(lam: float, upper: bool = False) -> float:
    """theta of the lower (upper) continuum solution at lambda < lambda*."""
    f = lambda t: bratu_lambda(t) - lam
    return brentq(f, BRATU_THETA_STAR, 50.0, xtol=1e-15) if upper else brentq(f, 0.0, BRATU_THETA_STAR, xtol=1e-15)


#: The fold: d lambda / d theta = 0 <=> theta tanh(theta/4) = 4.
BRATU_THETA_STAR = brentq(lambda t: t * math.tanh(t / 4) - 4, 1.0, 10.0, xtol=1e-15)
BRATU_LAMBDA_STAR = bratu_lambda(BRATU_THETA_STAR)      # 3.513830719125161
BRATU_MID_STAR = bratu_mid(BRATU_THETA_STAR)            # 1.186842168634389


def bratu_discrete_fold(n: int):
    """The fold of the n-point discretization by Newton on the extended system
    G(u, l) = 0, G_u v = 0, sum(v) = n (numpy only, independent of the core).

    Returns (lambda_h, u).
    """
    h = 1.0 / (n + 1)
    nodes = h * np.arange(1, n + 1)
    lap = (np.diag(np.full(n, -2.0)) + np.diag(np.ones(n - 1), 1) + np.diag(np.ones(n - 1), -1)) / h ** 2
    t = BRATU_THETA_STAR
    u = -2 * np.log(np.cosh((nodes - 0.5) * t / 2) / math.cosh(t / 4))
    v = np.sin(np.pi * nodes)
    v *= n / v.sum()
    lam = BRATU_LAMBDA_STAR
    for _ in range(50):
        e = np.exp(u)
        Gu = lap + np.diag(lam * e)
        F = np.concatenate([lap @ u + lam * e, Gu @ v, [v.sum() - n]])
        J = np.zeros((2 * n + 1, 2 * n + 1))
        J[:n, :n], J[:n, 2 * n] = Gu, e
        J[n:2 * n, :n], J[n:2 * n, n:2 * n], J[n:2 * n, 2 * n] = np.diag(lam * e * v), Gu, e * v
        J[2 * n, n:2 * n] = 1.0
        d = np.linalg.solve(J, -F)
        u, v, lam = u + d[:n], v + d[n:2 * n], lam + d[2 * n]
        if np.abs(d).max() < 1e-9:         # quadratic convergence: the step after is at round-off
            return lam, u
    raise RuntimeError("the extended system did not converge")
