"""The fold curve and its cusp: the critical roughness sigma_c(mu) and Tabor parameter mu_c(sigma).

Above a Tabor parameter mu_c(0) the load-approach curve F(lambda) has a pair of
turning points in lambda: snap-on at the larger lambda, snap-off at the smaller
(Figs. 5-9).  Roughness shrinks the pair; at the critical roughness sigma_c(mu)
the two folds merge at a cusp, and above it the curve is monotone in lambda: no
hysteresis.  Read the other way, mu_c(sigma) is the smallest mu with hysteresis
at roughness sigma, mu_c(0) the onset for a smooth sphere.

A fold, continued in a second parameter s (sigma or mu), traces a curve in
(s, lambda).  It solves the minimally augmented system (Govaerts, Numerical
Methods for Bifurcations of Dynamical Equilibria, SIAM 2000, sec. 4.2;
BifurcationKit's codim-2 fold continuation)

    G(H, lambda; s) = 0                                   (eq. 12)
    g(H, lambda; s) = 0,   [[G_H, psi], [phi^T, 0]] [v; g] = [0; 1],

g vanishing exactly where G_H (eq. 23) is singular, v then its null vector;
phi and psi, approximate right and left null vectors, are renewed after every
step (the zero set of g does not depend on them).  :class:`FoldProblem`
implements the problem protocol of :mod:`~petsc_adhesion.continuation` with
x = (H, lambda) and p = s, so the core traces the fold curve as it traces a
load-approach curve, and its fold event, the turning point of the fold curve
in s, is the cusp.  With w from the transposed solve
[[G_H^T, phi], [psi^T, 0]] [w; h] = [0; 1] the derivatives of g are
-w^T (dG_H/dz) v, and with G_H = I - c A diag(P'(H)) (eq. 23):

    g_H = c (A^T w) P''(H) v   (elementwise),   g_lambda = 0,
    G_sigma = -c A dP/dsigma,                  g_sigma = c w^T A (dP'/dsigma v),
    G_mu = -c' A P,                            g_mu = c' w^T A (P' v),   c' = dc/dmu = 3 c / (2 mu).

P'' and the sigma derivatives are central differences of the laws' exact P
and P' (:func:`curvature`, :func:`sigma_rates`): every law of
:mod:`~petsc_adhesion.pressure` serves, and these derivatives enter only the
Jacobian and the tangent, never the residual whose zero is the fold.

:func:`sigma_c` and :func:`mu_c` find the cusp in three stages:

1. a bracket from ordinary load-approach curves (:class:`~petsc_adhesion.adaptive.Tracer`,
   grids that follow the contact edge, traced to equilibrium): the parameter
   is bisected geometrically until the values with and without folds are
   within the ratio BRACKET;
2. from every snap-on fold at the end with folds, carried to a fixed grid
   graded about its contact edge (:func:`~petsc_adhesion.adaptive.grid_for`),
   the fold curve is traced toward the other end until it turns: the cusp on
   that grid, the most extreme one when there are several pairs;
3. the cusp is located again, each level from the one before, on the nested levels of
   a grid centred on the cusp's own contact edge, and Richardson's
   extrapolation of those values (:func:`~petsc_adhesion.error_estimate.extrapolate`)
   gives the best value and its bar; the finest level once more on a domain
   twice as long adds the truncation's share to the bar.

Stage 1 relies on the fold pair being seen on an ordinary curve however narrow
it is: :class:`~petsc_adhesion.events.EventFinder` walks again the steps where
lambdadot dips toward zero (near the cusp the pair is far narrower than a step).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from . import results
from .adaptive import BAND, Tracer, contact_radius, edge_of, grid_for
from .continuation import Continuation, Point, Settings
from .error_estimate import extrapolate
from .events import EventFinder, Fold
from .influence import create_influence
from .preconditioning import Border, Dense
from .pressure import pressure_law
from .problem import TO_WALL, Problem, far_approach
from .resolution import cohesive_zone
from .solver import TRUE_RESIDUAL, PCReuse, Tolerances

__all__ = ["FoldProblem", "curvature", "sigma_rates", "at_parameter", "ordinary_folds", "bracket", "trace_cusp",
           "sigma_c", "mu_c", "STEP", "BRACKET", "LEVELS", "FOLD_PREFIX"]

#: Relative step of the central differences: P'' with h = STEP (H - wall) at each node, d/dsigma with
#: STEP sigma min(1, gap / S_max).  The five-point rule's truncation, about 800 STEP^4 relative for the
#: g^-10 of P', and the laws' own error over the step (1e-11 / STEP for the wall quadratures, 1e-16 /
#: STEP for the Hermite rule) are both near 1e-9 at 1e-3.
STEP = 1e-3
#: The bracket of stage 1 ends when its two values are within this ratio: the fold curve then travels
#: a short way to the cusp, its contact edge within the fine band of the grid it started on.
BRACKET = 1.1
#: Default refinement levels of the grid at the cusp (nested: spacing / 2^level).
LEVELS = (0, 1, 2)
#: Options prefix of the bordered solves of g (-fold_ksp_type, ...).
FOLD_PREFIX = "fold_"
#: Where stage 1 starts, and the ranges it may search: hysteresis below sigma_c, above mu_c.
SIGMA_START, SIGMA_RANGE = 0.25, (1e-3, 8.0)
MU_START, MU_RANGE = 1.0, (0.05, 100.0)
#: Step control of the fold curve (lengths in the norm of (H, lambda, s), see FoldProblem.weights).
FOLD_SETTINGS = Settings(ds=0.01, ds_max=0.1, max_steps=400, max_folds=1)


def at_parameter(model, name: str, value: float):
    """``model`` with its parameter ``name`` (sigma or mu) set to ``value``.

    A measured roughness has its sigma from its heights: they are scaled to the rms ``value``.
    """
    if name == "mu":
        return replace(model, mu=value)
    if model.roughness == "measured":
        return replace(model, heights=model.heights * (value / pressure_law(model).sigma))
    return replace(model, sigma=value)


def curvature(law, H: np.ndarray) -> np.ndarray:
    """P''(H) by the five-point central difference of the law's exact P' (eq. 14's derivative).

    The step h = STEP (H - wall) at each node keeps H - 2h above the wall and scales
    with the distance to it, which sets how fast the law varies (see STEP).
    """
    h = STEP * (H - law.wall)
    k = np.array([1.0, -1.0, 2.0, -2.0])[:, None]
    d = law((H + k * h).ravel())[1].reshape(4, -1)
    return (8.0 * (d[0] - d[1]) - (d[2] - d[3])) / (12.0 * h)


def sigma_rates(law_at, sigma: float, H: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """dP/dsigma and dP'/dsigma at H by the five-point central difference in sigma.

    ``law_at(s)``: the law at roughness s; ``gap``: the smallest H - wall over all
    nodes (all ranks).  The heights scale with sigma, so a change ds moves the highest
    asperity S_max by ds S_max / sigma: the step STEP sigma min(1, gap / S_max)
    moves it by at most STEP times the gap, which keeps sigma + 2 ds off the wall.
    """
    top = law_at(sigma).wall + 1.0
    ds = STEP * sigma * min(1.0, gap / top)
    P = [law_at(sigma + k * ds)(H) for k in (1.0, -1.0, 2.0, -2.0)]
    return tuple((8.0 * (P[0][i] - P[1][i]) - (P[2][i] - P[3][i])) / (12.0 * ds) for i in (0, 1))


class _Laws:
    """The pressure law and the coupling c (eq. 12) of the model at parameter value s, cached."""

    def __init__(self, model, name: str):
        self.model, self.name, self._laws = model, name, {}

    def __call__(self, s: float):
        """The law at s (for mu: the model's own)."""
        key = s if self.name == "sigma" else None
        if key not in self._laws:
            if len(self._laws) > 32:
                self._laws.clear()
            self._laws[key] = pressure_law(at_parameter(self.model, "sigma", s) if key is not None else self.model)
        return self._laws[key]

    def coupling(self, s: float) -> float:
        """c at s."""
        return (at_parameter(self.model, "mu", s) if self.name == "mu" else self.model).coupling


class FoldProblem:
    """The fold system [G; g] = 0 in x = (H, lambda), parameter s = sigma or mu: the problem protocol.

    Parameters
    ----------
    model : Model
        The roughness law and the parameter that is not continued.
    r : numpy.ndarray
        The grid nodes.
    name : str
        The continuation parameter: "sigma" or "mu".
    comm : petsc4py.PETSc.Comm
        Communicator of every object made here (PETSc.COMM_WORLD by default).

    The adhesion :class:`~petsc_adhesion.problem.Problem` underneath (``base``) gets
    the law and coupling of each parameter value before it is used.  Unknowns are
    laid out as in :class:`~petsc_adhesion.scaled.ScaledProblem`: H, then lambda as
    the last entry on the last rank.
    """

    def __init__(self, model, r: np.ndarray, name: str, comm=None):
        comm = comm or PETSc.COMM_WORLD
        self.model, self.r, self.parameter = model, r, name
        self.laws = _Laws(model, name)
        self.base = base = Problem(model, r, create_influence(r, comm), Dense())
        self.comm, self._mpi, self.layout = base.comm, base.comm.tompi4py(), base.layout
        self.nloc, self.last, self.lo = base.hi - base.lo, base.layout.last, base.lo
        N, n1 = r.size, int(self.last)
        # lambda weighs like a uniform change of H in the continuation's norm
        self.weights = np.append(base.weights, 1.0) if self.last else base.weights
        self._h, self._G, self._u, self._y = (base.create_vec() for _ in range(4))
        sizes = ((self.nloc + n1, N + 1), (self.nloc + n1, N + 1))
        self.jacobian = PETSc.Mat().createPython(sizes, _FoldJacobian(self), comm=comm)
        self.jacobian.setUp()
        # the bordered matrix of g, its PC matrix and solver
        self.bordered = PETSc.Mat().createPython(sizes, _BorderedG(self), comm=comm)
        self.bordered.setUp()
        self.pmat = base.create_pmat(bordered=True)
        self.rhs, self.z, self.work = (self.create_vec() for _ in range(3))
        if self.last:
            self.rhs.setValue(N, 1.0)
        self.rhs.assemble()
        self.ksp = _bordered_ksp(comm, self.bordered, self.pmat or self.bordered, base)
        self.reuse = PCReuse()
        self.phi = self.psi = np.full(self.nloc, 1.0 / math.sqrt(N))
        self._key = None            # (x, s) of the state below
        self.s, self.v, self.w, self.g, self.row, self.row_all = None, None, None, 0.0, None, None
        self.gap = math.inf
        self.guard = None           # the parameter of the domain guard: set by adapt

    # -- x = (H, lambda) ------------------------------------------------------------
    def create_vec(self) -> PETSc.Vec:
        """A vector (H, lambda), lambda on the last rank."""
        n1 = int(self.last)
        return PETSc.Vec().createMPI((self.nloc + n1, self.r.size + 1), comm=self.comm)

    def split(self, x: np.ndarray) -> tuple[np.ndarray, float]:
        """Local H and lambda (broadcast from the last rank) of a local part x (collective)."""
        lam = float(x[self.nloc]) if self.last else None
        return x[:self.nloc], self._mpi.bcast(lam, root=self.comm.getSize() - 1)

    def join(self, h: np.ndarray, lam: float) -> np.ndarray:
        """The local part of (H, lambda)."""
        return np.append(h, lam) if self.last else np.asarray(h, dtype=float)

    def _dot(self, u: np.ndarray, v: np.ndarray) -> float:
        return self._mpi.allreduce(float(np.dot(u, v)))

    # -- the state at (x, s): law, G_H, v, g, w -------------------------------------
    def _at(self, x: np.ndarray, s: float, left: bool) -> bool:
        """Set the base problem, v and g (with ``left`` also w) at (x, s); False outside the domain.

        Kept while (x, s) does not change, agreed on all ranks.
        """
        key = self._key
        same = key is not None and key[1] == s and np.array_equal(key[0], x) and (self.w is not None or not left)
        if self._mpi.allreduce(same, op=MPI.LAND):
            return True
        if not s > 0:                  # mu (the coupling ~ mu^1.5) and sigma are positive; a corrector may overshoot
            return False
        h, lam = self.split(x)
        law, base = self.laws(s), self.base
        self.gap = self._mpi.allreduce(float(np.min(h - law.wall, initial=math.inf)), op=MPI.MIN)
        if not self.gap > 0:
            return False
        self.s = s
        base.law, base.c = law, self.laws.coupling(s)
        self._h.setArray(h)
        base.linearize(self._h, lam)
        z = self._solve(False)
        self.v, self.g = z[:self.nloc].copy(), self._mpi.bcast(float(z[self.nloc]) if self.last else None,
                                                            root=self.comm.getSize() - 1)
        self.w = self._solve(True)[:self.nloc].copy() if left else None
        self._key = (x.copy(), s)
        return True

    def _solve(self, transpose: bool) -> np.ndarray:
        """[v; g] (or, transposed, [w; h]) from the bordered matrix of g; retried once with a fresh PC."""
        ksp, M = self.ksp, self.bordered
        for _ in range(2):
            if self.reuse(ksp) and self.pmat is not None:
                row = np.concatenate(self._mpi.allgather(self.phi))     # collective: every rank gathers
                self.base.fill_pmat(self.pmat, Border(self.psi, row if self.last else None, 0.0))
            ksp.setOperators(M, self.pmat or M)
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
            self.phi = self.v / math.sqrt(self._dot(self.v, self.v))
            self.psi = self.w / math.sqrt(self._dot(self.w, self.w))
            self.reuse.expire()
        self._key = None

    # -- the protocol -------------------------------------------------------------------
    def residual(self, X: PETSc.Vec, s: float, R: PETSc.Vec) -> None:
        """[G(H, lambda; s); g(H, lambda; s)]; NaN outside the domain (the corrector then fails)."""
        x = X.getArray(readonly=True)
        if not self._at(x, s, False):
            R.set(np.nan)
            return
        h, lam = self.split(x)
        self._h.setArray(h)
        self.base.residual(self._h, lam, self._G)
        R.setArray(self.join(self._G.getArray(readonly=True), self.g))

    def dG_dp(self, X: PETSc.Vec, s: float, out: np.ndarray) -> np.ndarray:
        """[G_s; g_s] on the local rows (module docstring)."""
        x = X.getArray(readonly=True)
        self._at(x, s, True)
        h, _ = self.split(x)
        law = self.laws(s)
        if self.parameter == "sigma":
            c = self.base.c
            rate, slope = sigma_rates(self.laws, s, h, self.gap)
        else:
            c = 1.5 * self.base.c / s
            rate, slope = law(h)
        out[:self.nloc] = -c * self._apply(rate)
        gs = c * self._dot(self.w, self._apply(slope * self.v))
        out[self.nloc:] = gs
        return out

    def _apply(self, u: np.ndarray) -> np.ndarray:
        """A u on the local rows."""
        self._u.setArray(u)
        self.base.A.mult(self._u, self._y)
        return self._y.getArray(readonly=True).copy()

    def linearize(self, X: PETSc.Vec, s: float) -> None:
        """The point of :attr:`jacobian`: G_H, and the row g_H = c (A^T w) P'' v."""
        x = X.getArray(readonly=True)
        self._at(x, s, True)
        h, _ = self.split(x)
        self._u.setArray(self.w)
        self.base.A.multTranspose(self._u, self._y)
        self.row = self.base.c * self._y.getArray(readonly=True) * curvature(self.laws(s), h) * self.v
        full = self._mpi.allgather(self.row)
        self.row_all = np.concatenate(full) if self.last else None

    def create_pmat(self, bordered: bool):
        """The PC matrix of [[G_H, 1], [g_H, 0]], bordered once more for the arclength corrector."""
        return self.base.pc.create(self.layout, self.comm, 1 + int(bordered))

    def fill_pmat(self, P: PETSc.Mat, border: Border | None = None) -> None:
        """Assemble P at the linearization point."""
        own = Border(np.ones(self.nloc), self.row_all if self.last else None, 0.0)
        self.base.pc.fill(P, self.base, self.layout, [own] + ([border] if border is not None else []))

    def setup_pc(self, pc: PETSc.PC, bordered: bool = False) -> None:
        """Default preconditioner for the kind of P."""
        self.base.setup_pc(pc, bordered)

    def inside(self, x: np.ndarray) -> bool:
        """Every gap open at the parameter of the last point the borders were adapted at (the protocol
        gives no parameter here; a corrector that moves s past the wall gets a NaN residual)."""
        wall = self.laws(self.guard).wall
        return self._mpi.allreduce(bool(np.all(x[:self.nloc] > wall)), op=MPI.LAND)

    def step_fraction(self, x: np.ndarray, y: np.ndarray) -> float:
        """Largest fraction of the step x -> x - y whose H part covers at most TO_WALL of the way to the
        wall at that parameter, node by node (as the base problem's guard); the same on all ranks."""
        room, yh = x[:self.nloc] - self.laws(self.guard).wall, y[:self.nloc]
        toward = yh > 0
        return self._mpi.allreduce(float(np.min(TO_WALL * room[toward] / yh[toward], initial=1.0)), op=MPI.MIN)

    def observe(self, x: np.ndarray, s: float, xdot: np.ndarray, sdot: float):
        """lambda and the load F (eq. 26) at the fold; the rate of lambda along the fold curve."""
        h, lam = self.split(x)
        _, lamdot = self.split(xdot)
        F = self._dot(self.base.q, self.laws(s)(h)[0]) + self.base.far_load(lam)
        return {"lambda": lam, "F": F}, {"lambda": lamdot}

    def state(self, r: np.ndarray, H: np.ndarray, lam: float) -> np.ndarray:
        """The local part of (H, lambda) for a state H on nodes r: its deformation H - r^2/2 interpolated."""
        mine = self.r[self.lo:self.lo + self.nloc]
        return self.join(np.interp(mine, r, H - 0.5 * r * r) + 0.5 * mine * mine, lam)

    def whole(self, x: np.ndarray) -> tuple[np.ndarray, float]:
        """(all of H, lambda) of a local part x, on every rank."""
        h, lam = self.split(x)
        return self.base.gather(h), lam

    def edge(self, x: np.ndarray, s: float) -> tuple[float, float]:
        """(radius of peak attraction, contact radius) of a state at s (:mod:`~petsc_adhesion.adaptive`)."""
        self.base.law = self.laws(s)
        self._key = None
        h, _ = self.split(x)
        return edge_of(self.base, h), contact_radius(self.base, h)

    def destroy(self) -> None:
        """Free the PETSc objects made here, the base problem's too."""
        for obj in (self.ksp, self.bordered, self.pmat, self.jacobian, self.rhs, self.z, self.work,
                    self._h, self._G, self._u, self._y):
            if obj is not None:
                obj.destroy()
        self.base.destroy()


def _bordered_ksp(comm, M: PETSc.Mat, P: PETSc.Mat, base: Problem) -> PETSc.KSP:
    """GMRES on the bordered matrix of g with the base problem's PC, prefix FOLD_PREFIX, tight: g is
    the residual's last entry, so its error is the fold's."""
    tol = Tolerances()
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(FOLD_PREFIX)
    ksp.setType("gmres")
    ksp.setTolerances(rtol=1e-2 * tol.ksp_rtol, atol=1e-2 * tol.ksp_atol, max_it=tol.ksp_max_it)
    ksp.setOperators(M, P)
    base.setup_pc(ksp.getPC(), True)
    ksp.setFromOptions()
    return ksp


class _BorderedG:
    """MatPython context of [[G_H, psi], [phi^T, 0]] and its transpose."""

    def __init__(self, fp: FoldProblem):
        self.fp = fp

    def _parts(self, x):
        fp = self.fp
        a = x.getArray(readonly=True)
        last = float(a[fp.nloc]) if fp.last else None
        return a[:fp.nloc], fp._mpi.bcast(last, root=fp.comm.getSize() - 1)

    def mult(self, mat, x, y):
        """y = [G_H xh + psi xg; phi . xh]."""
        fp = self.fp
        xh, xg = self._parts(x)
        fp._u.setArray(xh)
        fp.base.jacobian.mult(fp._u, fp._y)
        y.setArray(fp.join(fp._y.getArray(readonly=True) + xg * fp.psi, fp._dot(fp.phi, xh)))

    def multTranspose(self, mat, x, y):
        """y = [G_H^T xh + phi xg; psi . xh], G_H^T = I - c diag(P') A^T."""
        fp = self.fp
        xh, xg = self._parts(x)
        fp._u.setArray(xh)
        fp.base.A.multTranspose(fp._u, fp._y)
        yh = xh - fp.base.c * fp.base.dp * fp._y.getArray(readonly=True) + xg * fp.phi
        y.setArray(fp.join(yh, fp._dot(fp.psi, xh)))


class _FoldJacobian:
    """MatPython context of the fold system's Jacobian [[G_H, 1], [g_H, 0]]."""

    def __init__(self, fp: FoldProblem):
        self.fp = fp

    def mult(self, mat, x, y):
        """y = [G_H xh + xlambda; g_H . xh]."""
        fp = self.fp
        xh, xl = fp.split(x.getArray(readonly=True))
        fp._u.setArray(xh)
        fp.base.jacobian.mult(fp._u, fp._y)
        y.setArray(fp.join(fp._y.getArray(readonly=True) + xl, fp._dot(fp.row, xh)))


# -- stage 1: the bracket from ordinary curves ---------------------------------------------


def ordinary_folds(model, comm=None) -> list[dict]:
    """The turning points of the ordinary load-approach curve of ``model``, in the order of the curve.

    Traced as the program traces a curve (:class:`~petsc_adhesion.adaptive.Tracer`, grids that
    follow the contact edge, from far apart) to equilibrium, without error bars.  Each fold is
    {kind (snap_on or snap_off), lambda, F, r, H} with the nodes and H of the grid it was located
    on (whole, on every rank).  RuntimeError when the curve ends before equilibrium.
    """
    settings = Settings(observable="F", observable_max=0.0)
    tracer = Tracer(model, settings, results.curve_events(), pmat=Dense(), rmax=model.rmax, comm=comm)
    try:
        segments = tracer.run(far_approach(model))
        last = segments[-1].cont
        if last.stop[0] != "observable_max":
            raise RuntimeError(f"the curve at mu = {model.mu:g}, sigma = {model.sigma:g} ended before equilibrium: "
                               f"{results.stop_reason(last.stop, settings)}")
        out = []
        for seg in segments:
            pb = seg.problem
            for f in seg.finder.found:
                if isinstance(f.event, Fold):
                    x = f.point.x
                    out.append({"kind": f.label, "lambda": f.point.p, "F": f.point.values["F"],
                                "r": pb.nodes(x), "H": pb.gather(pb.separation(x))})
        return out
    finally:
        tracer.destroy()


def bracket(model, name: str, comm=None, ratio: float = BRACKET) -> tuple[float, float, list]:
    """Values (a, b) of the parameter ``name`` with folds at a and none at b, b/a or a/b within ``ratio``,
    and the folds at a (:func:`ordinary_folds`).

    Hysteresis lies below sigma_c and above mu_c.  From SIGMA_START (MU_START) the value is
    halved or doubled until the answer changes, then bisected geometrically.  ValueError when
    the range (SIGMA_RANGE, MU_RANGE) holds no change.
    """
    below = name == "sigma"
    start, (low, high) = (SIGMA_START, SIGMA_RANGE) if below else (MU_START, MU_RANGE)
    found = {}

    def probe(s: float) -> bool:
        found[s] = ordinary_folds(at_parameter(model, name, s), comm)
        return bool(found[s])

    yes = no = None
    s = start
    while yes is None or no is None:
        if not low <= s <= high:
            other = f"mu = {model.mu:g}" if below else f"sigma = {model.sigma:g}"
            raise ValueError(f"{'no hysteresis' if yes is None else 'hysteresis'} at {other} for {name} from "
                             f"{start:g} to {s / 2 if s > start else s * 2:g}")
        if probe(s):
            yes = s
            s = s * 2 if below else s / 2
        else:
            no = s
            s = s / 2 if below else s * 2
    while max(yes, no) / min(yes, no) > ratio:
        s = math.sqrt(yes * no)
        if probe(s):
            yes = s
        else:
            no = s
    return yes, no, found[yes]


# -- stage 2: the fold curve to its cusp ---------------------------------------------------------


@dataclass
class Cusp:
    """A cusp located on one grid: the fold problem, its continuation and the located event."""

    problem: FoldProblem
    cont: Continuation
    found: object

    @property
    def point(self) -> Point:
        """The located cusp."""
        return self.found.point

    def values(self) -> tuple[float, float, float]:
        """(s, lambda, F) at the cusp."""
        pt = self.found.point
        return pt.p, pt.values["lambda"], pt.values["F"]

    def destroy(self) -> None:
        """Free the PETSc objects."""
        self.cont.destroy()
        self.problem.destroy()


def _to_cusp(fp: FoldProblem, cont: Continuation, start: Point):
    """Run ``cont`` from ``start`` until the fold curve turns in s: the located event, or RuntimeError.

    After every step the borders of g become the null vectors there (:meth:`FoldProblem.adapt`);
    the preconditioners, built with the old ones, are rebuilt.
    """
    finder = EventFinder(cont, [Fold(("cusp", "cusp"))])

    def on_step(a, b):
        finder(a, b)
        fp.adapt(b.x, b.p)
        cont.newton.reuse.expire()
        cont.bordered.reuse.expire()

    cont.run(start, on_step=on_step, until=lambda a, b: bool(finder.found))
    if not finder.found:
        raise RuntimeError(f"the fold curve did not turn in {fp.parameter} from {start.p:.6g}: "
                           f"stopped ({cont.stop[0]}) at {fp.parameter} = {cont.points[-1].p:.6g}")
    return finder.found[0]


def trace_cusp(model, name: str, fold: dict, s0: float, direction: int, comm=None,
               settings: Settings = FOLD_SETTINGS) -> Cusp:
    """The cusp reached by continuing the ordinary fold ``fold`` (of :func:`ordinary_folds` at ``name`` =
    ``s0``) in ``name`` toward ``direction`` (+1: increasing), on the grid it was located on."""
    fp = FoldProblem(at_parameter(model, name, s0), fold["r"], name, comm)
    cont = None
    try:
        x = fp.state(fold["r"], fold["H"], fold["lambda"])
        fp.adapt(x, s0, sweeps=2)
        guess = fp.create_vec()
        guess.setArray(x)
        cont = Continuation(fp, settings)
        try:
            start = cont.start(guess, s0, direction)
        finally:
            guess.destroy()
        return Cusp(fp, cont, _to_cusp(fp, cont, start))
    except Exception:
        if cont is not None:
            cont.destroy()
        fp.destroy()
        raise


# -- stage 3: refinement at the cusp ---------------------------------------------------------------


def _design(model, name: str, cusp: Cusp):
    """The grid about the cusp's contact edge: :func:`~petsc_adhesion.adaptive.grid_for` at the radius
    of peak attraction, its fine band widened to reach the contact radius by a cohesive zone."""
    s = cusp.point.p
    at = at_parameter(model, name, s)
    peak, a = cusp.problem.edge(cusp.point.x, s)
    band = max(BAND, abs(a - peak) + cohesive_zone(at, pressure_law(at)))
    return replace(grid_for(at, peak, 0, model.rmax), band=band)


def _relocate(cusp: Cusp, model, name: str, nodes: np.ndarray, direction: int, comm) -> Cusp | None:
    """The cusp of ``cusp`` located again on ``nodes``: from the start of the step that passed it (or an
    earlier point, if that fails), carried there and put on the new fold curve by a zero-length
    arclength correction, traced toward the cusp with steps no longer than that step.  Where the new
    grid's cusp lies behind that point in s, the correction lands on the fold curve's other branch,
    beyond the cusp, with s moving away from it: the curve is then followed backwards."""
    src, pts, j = cusp.problem, cusp.cont.points, cusp.found.segment
    length = max(pts[j + 1].ds, 1e-3)
    settings = replace(FOLD_SETTINGS, ds=length / 2, ds_max=length, max_steps=40)
    for a in reversed(pts[max(0, j - 3):j + 1]):
        fp = FoldProblem(at_parameter(model, name, a.p), nodes, name, comm)
        cont = Continuation(fp, settings)
        try:
            H, lam = src.whole(a.x)
            Hdot, lamdot = src.whole(a.xdot)
            x = fp.state(src.r, H, lam)
            fp.adapt(x, a.p, sweeps=2)
            guess = fp.create_vec()
            guess.setArray(x)
            mine = fp.r[fp.lo:fp.lo + fp.nloc]
            start = cont.project(guess, a.p, fp.join(np.interp(mine, src.r, Hdot), lamdot), a.pdot)
            guess.destroy()
            if start is not None:
                return Cusp(fp, cont, _to_cusp(fp, cont, start if start.pdot * direction > 0 else start.reversed()))
        except (RuntimeError, FloatingPointError):
            pass
        cont.destroy()
        fp.destroy()
    return None


def _critical(model, name: str, levels, comm) -> dict:
    """The cusp in ``name`` (sigma: hysteresis below it; mu: above it) of ``model``: stages 1-3."""
    t0 = time.perf_counter()
    direction = 1 if name == "sigma" else -1
    yes, no, folds = bracket(model, name, comm)
    cusps = []
    try:
        for fold in folds:
            if fold["kind"] == "snap_on":
                cusps.append(trace_cusp(model, name, fold, yes, direction, comm))
        first = max(cusps, key=lambda c: direction * c.point.p)
        design = _design(model, name, first)
        at, src = {}, first
        # the refinement levels, each from the one before (nested nodes: a close start at large mu,
        # where the cohesive zone is a few nodes of the coarser grid), then the finest on a domain
        # twice as long: the truncation's share
        for level, grid in [(k, replace(design, level=k)) for k in sorted(levels)] + \
                [("domain", replace(design, level=max(levels), rmax=2 * design.rmax))]:
            nodes = grid.nodes()
            found = _relocate(src, model, name, nodes, direction, comm)
            if found is None:
                raise RuntimeError(f"the cusp at {name} = {first.point.p:.6g} was not found again on "
                                   f"{'refinement level ' + str(level) if level != 'domain' else 'the longer domain'}"
                                   f" ({nodes.size} nodes)")
            at[level] = found.values() + (nodes.size,)
            cusps.append(found)
            src = found
        peak, contact = first.problem.edge(first.point.x, first.point.p)
    finally:
        for c in cusps:
            c.destroy()
    longer = at.pop("domain")
    domain = [abs(longer[i] - at[max(levels)][i]) for i in range(3)]
    best = {k: extrapolate({level: v[i] for level, v in at.items()}) for i, k in enumerate(("s", "lambda", "F"))}
    s, s_err = best["s"]
    fixed = ("mu", model.mu) if name == "sigma" else \
        ("sigma", pressure_law(model).sigma if model.roughness == "measured" else model.sigma)
    out = {fixed[0]: fixed[1], f"{name}_c": s, f"{name}_c_err": s_err + domain[0],
           "lambda_c": best["lambda"][0], "lambda_c_err": best["lambda"][1] + domain[1],
           "F_c": best["F"][0], "F_c_err": best["F"][1] + domain[2], f"{name}_c_domain": domain[0],
           "levels": sorted(at), "n_nodes": [at[k][3] for k in sorted(at)],
           f"{name}_c_grid": [at[k][0] for k in sorted(at)], "lambda_c_grid": [at[k][1] for k in sorted(at)],
           "F_c_grid": [at[k][2] for k in sorted(at)], "bracket": [yes, no], "edge": peak, "contact_radius": contact,
           "roughness": pressure_law(at_parameter(model, name, s)).describe(), "rmax": model.rmax,
           "wall_time_s": time.perf_counter() - t0}
    lo, hi = sorted((yes, no))
    if not lo <= s <= hi:
        out["warning"] = (f"the cusp at {name} = {s:.6g} lies outside the bracket [{lo:.6g}, {hi:.6g}] of the "
                          f"traced curves")
    return out


def sigma_c(model, mu: float, grid_refinements=LEVELS, comm=None) -> dict:
    """The critical roughness at Tabor parameter ``mu``: the largest sigma with hysteresis, the cusp of the
    fold curve in (sigma, lambda), with its error bar.

    Parameters
    ----------
    model : Model
        The roughness law and its parameters (its mu and sigma are replaced), r_m and the far field.
    mu : float
        Tabor parameter (eq. 9).
    grid_refinements : sequence of int
        Refinement levels of the grid at the cusp (nested, spacing / 2^level); three for the bar.
    comm : petsc4py.PETSc.Comm
        Communicator of every object (PETSc.COMM_WORLD by default): a study may run cases on
        subcommunicators.

    Returns
    -------
    dict
        mu, sigma_c, sigma_c_err, lambda_c(_err), F_c(_err) at the cusp (best values and bars from
        the levels), the values on each level (``*_grid``), ``levels``, ``n_nodes``, the change on
        the finest level from r_m to 2 r_m (``sigma_c_domain``, part of the bars), the ``bracket``
        of ordinary curves (with folds, without), the cusp's radius of peak attraction ``edge`` and
        ``contact_radius``, the roughness law, ``wall_time_s``; ``warning`` when the cusp lies outside
        the bracket.  ValueError when there is no hysteresis even at sigma = SIGMA_RANGE[0].
    """
    return _critical(replace(model, mu=mu), "sigma", grid_refinements, comm or PETSc.COMM_WORLD)


def mu_c(model, sigma: float, grid_refinements=LEVELS, comm=None) -> dict:
    """The critical Tabor parameter at roughness ``sigma``: the smallest mu with hysteresis, the cusp of the
    fold curve in (mu, lambda), with its error bar; at sigma = 0 the onset of hysteresis of a smooth
    sphere.

    Parameters and result as :func:`sigma_c`, with mu and sigma exchanged (``mu_c``, ``mu_c_err``, ...).
    ValueError when there is no hysteresis up to mu = MU_RANGE[1].
    """
    return _critical(at_parameter(model, "sigma", sigma), "mu", grid_refinements, comm or PETSc.COMM_WORLD)
