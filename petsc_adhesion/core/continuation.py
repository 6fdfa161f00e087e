"""Predictor-corrector continuation of G(x, p) = 0 in one parameter p (paper, "Numerical Procedure").

The core knows nothing of the problem beyond its protocol
(:class:`~petsc_adhesion.core.protocol.ContinuationProblem`, in the manner of
pacopy's ``f``, ``df_dlmbda``, ``jacobian_solver``, ``inner``).

The curve is followed in X = (x, p) with the inner product <x, y> + p q.

* Natural corrector (eq. 20-22): Newton on G(x; p) = 0 at the predicted p;
  tangent from G_x phi_0 = -G_p with the normalisation and sign rule of
  eq. (16)-(19).  Fails at a turning point, where G_x is singular.
* Pseudo-arclength corrector (eq. 24-25): Newton on [G; Q] = 0, whose Jacobian
  is the bordered matrix [[G_x, G_p], [xdot^T W, pdot]], a MatNest holding
  the problem's operator; regular at a fold.  Its tangent solves the same
  bordered matrix with right-hand side (0, 1), which also keeps eq. (19).
* ``auto`` (the paper's switch) takes the natural step while |pdot| >= 0.5.

Step control (:class:`Settings`): halve on a failed corrector, a predictor
outside the domain, a turn of the tangent, a corrector far from its predictor
(curvature), or a large change of the watched observable; grow on fast Newton
and a nearly straight curve.

Solvers and their roles' options prefixes: the natural corrector ``nat_`` (also the
first point), the arclength corrector ``arc_`` (also every tangent along it); each
takes its :class:`~petsc_adhesion.core.newton.PetscSettings` under a prefix of its own
before the role's (:class:`~petsc_adhesion.core.newton.SolverOptions`).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np
from petsc4py import PETSc

from ..errors import tell
from .bordered import Bordered
from .newton import Tolerances, PC_REUSE_ITS, Newton, PetscSettings, krylov_retry
from .protocol import POINT_FIELDS, Point, check_point

__all__ = ["Settings", "Continuation", "Correction", "NATURAL_PREFIX", "CORRECTORS"]

#: Options prefix of the natural corrector (and the first point).
NATURAL_PREFIX = "nat_"
#: What -cont_type accepts: the paper's switch, or one corrector throughout.
CORRECTORS = ("auto", "natural", "arclength")
#: Newton's first iterate: the tangent's (eq. 20, 23), or with the curvature of the step before added.
PREDICTORS = ("linear", "quadratic")


@dataclass
class Settings:
    """Step control and stop criteria; the one place of their defaults.

    Step lengths are measured in the inner product of X = (x, p).
    """

    corrector: str = "auto"         # one of CORRECTORS
    ds: float = 0.05                # first step
    ds_min: float = 1e-7            # give up below
    ds_max: float = 0.5
    newton_target: int = 5          # corrector iterations aimed at
    max_deviation: float = 0.2      # largest corrector distance from the predictor per unit step
    min_turn_cosine: float = 0.8    # smallest cosine between successive tangents (37 degrees)
    grow: float = 1.5               # step factor after an easy step
    shrink: float = 0.7             # after a slow one (more than newton_target iterations)
    cut: float = 0.5                # after a rejected one
    grow_margin: float = 0.5        # easy: deviation and observable change below this share of their bounds
    switch: float = 0.5             # auto: natural corrector while |pdot| >= switch (the paper's)
    natural_fallback: float = 0.1   # natural corrector as fallback only while |pdot| >= this
    observable: str | None = None   # the observable bounded per step and stopped on
    observable_step: float = 0.2    # its largest change in one step, relative above magnitude 1
    observable_bend: float = math.inf  # its largest distance in one step from its tangent's line (absolute)
    observable_max: float = math.inf  # stop when the observable reaches this
    observable_max_label: str = ""  # what set that stop, as the stop's message names it ("": the caller's default)
    p_max: float = math.inf         # stop when the parameter reaches this
    p_min: float = -math.inf        # or falls to this
    max_steps: int = 5000           # the truncated model at mu = 10 takes about 3950 (edge_grids.MU_TRUNCATED)
    max_folds: int = 12             # stop after more than this many turning points
    pc_reuse_its: int = PC_REUSE_ITS
    monitor: bool = False           # one line a step
    predictor: str = "linear"       # one of PREDICTORS
    unit: float = 1.0               # the size of x and p: SNES's absolute tolerance is Tolerances' times its square

    @classmethod
    def from_state(cls, d: dict) -> Settings:
        """The settings of ``asdict(settings)`` as a checkpoint kept them; ValueError for what are not settings."""
        if isinstance(d, dict) and "observable_bend" not in d:
            d = {**d, "observable_bend": math.inf}     # a checkpoint kept before the bound was: none
        if not isinstance(d, dict) or set(d) != {f.name for f in fields(cls)}:
            raise ValueError("settings that are not the continuation's")
        for f in fields(cls):
            v, default = d[f.name], f.default
            if isinstance(default, bool):
                ok = isinstance(v, bool)
            elif isinstance(default, int):
                ok = isinstance(v, int) and not isinstance(v, bool) and v >= 0
            elif isinstance(default, float):
                ok = isinstance(v, (int, float)) and not isinstance(v, bool) and not math.isnan(v) and \
                    (math.isfinite(v) or math.isinf(default) or f.name in ("observable_max", "p_max", "p_min"))
            else:
                ok = v is None or isinstance(v, str)
            if not ok:
                raise ValueError(f"the setting {f.name} = {v!r}")
        if not 0 < d["ds_min"] <= d["ds"] <= d["ds_max"] or d["corrector"] not in CORRECTORS or \
                d["predictor"] not in PREDICTORS:
            raise ValueError("step lengths or a corrector the continuation cannot take")
        return cls(**d)


@dataclass(frozen=True, eq=False)
class Correction:
    """What a corrector gives back: the corrected point (x, p) with its tangent (xdot, pdot), the work it
    took, and whether it converged and, if not, why.

    ``reason``: "converged"; "outside" (the natural predictor left the domain); "diverged" (Newton did not
    converge, or the arclength predictor left the domain); "tangent" (the tangent's solve failed).
    A failed correction holds no point.
    """

    corrector: str                      # "natural" | "arclength" ("" for a step's own start)
    converged: bool
    reason: str = "converged"
    x: np.ndarray | None = None         # local part
    p: float = math.nan
    xdot: np.ndarray | None = None
    pdot: float = math.nan
    newton_its: int = 0
    ksp_its: int = 0                    # Newton's Krylov iterations
    tangent_its: int = 0                # the tangent solve's

    @classmethod
    def failed(cls, corrector: str, reason: str) -> Correction:
        """A correction that did not converge, for ``reason``."""
        return cls(corrector, False, reason)


class Continuation:
    """Trace a curve of G(x, p) = 0 from a start point; collect the points and step statistics.

    ``stop`` after :meth:`run`: (reason, value) with reason one of
    "observable_max", "p_max", "p_min", "max_steps", "max_folds", "ds_min",
    or "until" (the caller's criterion).  ``ds`` is the step it would take next.
    ``index0`` numbers the monitor's lines after those of earlier segments.
    """

    def __init__(self, problem, settings: Settings | None = None, index0: int = 0,
                 natural: PetscSettings = PetscSettings(), arclength: PetscSettings = PetscSettings()):
        """``natural``, ``arclength``: the user's PETSc settings of the two correctors' solvers."""
        self.pb, self.set, self.index0 = problem, settings or Settings(), index0
        # the residual's rounding floor grows faster than the size of x and p (a soft sphere's deformation
        # and approach grow like mu, the coupling c like mu^1.5): measured 1e-5 to 6e-5 at mu = 1000 in the
        # frame of the edge (-nat_snes_monitor), where an absolute tolerance of 1e-10 is out of reach from a
        # first iterate already near the curve and Newton stalls for its 50 iterations: unit^2 times it
        tol = Tolerances(snes_atol=Tolerances.snes_atol * self.set.unit**2)
        self.newton = Newton(problem, NATURAL_PREFIX, full_steps=True, pc_reuse_its=self.set.pc_reuse_its, tol=tol,
                             settings=natural)
        try:
            self.bordered = Bordered(problem, self.set.pc_reuse_its, tol, arclength)
        except BaseException:           # a solver option refused: free the Newton solver made
            self.newton.destroy()
            raise
        self._x, self._xt, self._rhs, self._phi, self._r = (problem.create_vec() for _ in range(5))
        self._gp = np.zeros(self._x.getLocalSize())
        self.points: list[Point] = []
        self.rejected = 0
        self.folds = 0
        self.stop: tuple[str, float] | None = None
        self.ds = self.set.ds

    @property
    def size(self) -> int:
        """The number of x's unknowns on this rank."""
        return self._x.getLocalSize()

    def inner(self, u: np.ndarray, v: np.ndarray) -> float:
        """<u, v> of local parts, summed over ranks."""
        return self.bordered.inner(u, v)

    # -- tangents -----------------------------------------------------------
    def natural_tangent(self, x: np.ndarray, p: float, prev: Point):
        """Tangent of eq. (16)-(19): G_x phi_0 = -G_p, a = +-1/sqrt(1 + |phi_0|^2)."""
        pb, newton = self.pb, self.newton
        self._xt.setArray(x)
        self._rhs.setArray(-pb.dG_dp(self._xt, p, self._gp))
        ksp = newton.snes.getKSP()
        if not krylov_retry(ksp, pb.jacobian, newton.pmat or pb.jacobian, self._rhs, self._phi, newton.reuse,
                            lambda refill: newton.linearize(self._xt, refill), self._r):
            return None
        phi = self._phi.getArray(readonly=True).copy()
        a = 1.0 / math.sqrt(1.0 + self.inner(phi, phi))
        if a * (self.inner(prev.xdot, phi) + prev.pdot) < 0:      # eq. (19)
            a = -a
        return a * phi, a, ksp.getIterationNumber()

    def make_point(self, x, p, xdot, pdot, **kw) -> Point:
        """A Point with the problem's observables at (x, p) along (xdot, pdot)."""
        values, rates = self.pb.observe(x, p, xdot, pdot)
        return Point(x=x, p=p, xdot=xdot, pdot=pdot, values=values, rates=rates, **kw)

    def start(self, guess: PETSc.Vec, p0: float, direction: int = 1) -> Point:
        """Solve at p0 from ``guess`` (natural corrector's SNES); tangent towards larger p (``direction`` 1)
        or smaller (-1).

        RuntimeError when Newton or the tangent fails there.
        """
        x = guess.copy()
        if not self.newton.solve(p0, x):
            x.destroy()
            raise RuntimeError(f"no solution at the start {self.pb.parameter} = {p0:g}")
        a = x.getArray(readonly=True).copy()
        x.destroy()
        tan = self.bordered.tangent(a, p0, np.zeros_like(a), float(direction))
        if tan is None:
            raise RuntimeError(f"no tangent at the start {self.pb.parameter} = {p0:g}")
        xdot, pdot, kits = tan
        its, lits = self.newton.iterations
        return self.make_point(a, p0, xdot, pdot, newton_its=its, ksp_its=lits + kits)

    def project(self, x: PETSc.Vec, p: float, xdot: np.ndarray, pdot: float) -> Point | None:
        """The point of the curve nearest (x, p) along (xdot, pdot), with its tangent oriented alike.

        A zero-length arclength correction (eq. 24-25, regular at folds): how a
        point carried over from another discretization is put back on this one's
        curve.  None when it fails.
        """
        guess = Point(x=x.getArray(readonly=True).copy(), p=p, xdot=xdot, pdot=pdot)
        c = self.arclength(guess, 0.0)
        if not c.converged:
            return None
        return self.make_point(c.x, c.p, c.xdot, c.pdot, newton_its=c.newton_its, ksp_its=c.ksp_its + c.tangent_its,
                               corrector="regrid")

    # -- one step -------------------------------------------------------------
    def natural_ok(self, a: Point) -> bool:
        """Whether the step from a takes the natural corrector first."""
        s = self.set
        return s.corrector == "natural" or (s.corrector == "auto" and abs(a.pdot) >= s.switch)

    def natural(self, a: Point, ds: float, tangent: bool = True, guess=None) -> Correction:
        """Natural corrector (eq. 20-22) at p = a.p + ds a.pdot; tangent of eq. (16)-(19).  ``guess``: a
        first iterate (x, p) other than the predictor, moved along a's tangent to that p."""
        p = a.p + ds * a.pdot
        x = a.x + ds * a.xdot if guess is None else guess[0] + (p - guess[1]) / a.pdot * a.xdot  # eq. (20)
        if not self.pb.inside(x):
            return Correction.failed("natural", "outside")
        self._x.setArray(x)
        if not self.newton.solve(p, self._x, retry=True):   # eq. (21)-(22)
            return Correction.failed("natural", "diverged")
        x = self._x.getArray(readonly=True).copy()
        its, kits = self.newton.iterations
        tan = self.natural_tangent(x, p, a) if tangent else (a.xdot, a.pdot, 0)
        if tan is None:
            return Correction.failed("natural", "tangent")
        return Correction("natural", True, x=x, p=p, xdot=tan[0], pdot=tan[1], newton_its=its, ksp_its=kits,
                          tangent_its=tan[2])

    def arclength(self, a: Point, ds: float, tangent: bool = True, guess=None) -> Correction:
        """Pseudo-arclength corrector (eq. 24-25) at distance ds (from ``guess`` (x, p) if given, else the
        predictor); tangent of the bordered system."""
        sol = self.bordered.correct(a, ds, guess)
        if sol is None:
            return Correction.failed("arclength", "diverged")
        x, p, its, kits = sol
        tan = self.bordered.tangent(x, p, a.xdot, a.pdot) if tangent else (a.xdot, a.pdot, 0)
        if tan is None:
            return Correction.failed("arclength", "tangent")
        return Correction("arclength", True, x=x, p=p, xdot=tan[0], pdot=tan[1], newton_its=its, ksp_its=kits,
                          tangent_its=tan[2])

    def correct(self, a: Point, ds: float, tangent: bool = True, guess=None) -> Correction:
        """The point at step ds from a: the corrector the mode asks for, the other as fallback.

        The natural one serves only away from folds (|pdot| >= ``natural_fallback``),
        where p is a good parameter; near the wall of a fine roughness rule it is
        the more robust of the two.  Without ``tangent`` the point gets a's.
        A failed :class:`Correction` is the last corrector's tried.
        """
        s = self.set
        first, second = (self.natural, self.arclength) if self.natural_ok(a) else (self.arclength, self.natural)
        sol = first(a, ds, tangent, guess)
        if not sol.converged and (second is self.arclength or abs(a.pdot) >= s.natural_fallback) \
                and s.corrector != "natural":
            sol = second(a, ds, tangent, guess)
        return sol

    def extrapolate(self, a: Point, ds: float):
        """Newton's first iterate for the step ds from the last point ``a`` with the quadratic predictor:
        (x, p) + ds (xdot, pdot) + ds^2 / 2 kappa, the curvature kappa the change of the tangent over the
        step that reached a.  None for the linear predictor, or with no such step on this grid.

        Why: in the frame of a soft sphere's edge the curve is nearly straight, yet the linear predictor
        misses the contact radius by several cohesive zones (mu = 300: 5e-4 in a, the zone 1.4e-4),
        and Newton needs 5 to 6 iterations from the predictor, which holds the step to 1/40 of mu.
        """
        pts = self.points
        if self.set.predictor != "quadratic" or len(pts) < 2 or pts[-1] is not a or not a.ds > 0 \
                or a.corrector not in ("natural", "arclength"):
            return None
        b = pts[-2]
        h = 0.5 * ds * ds / a.ds
        return a.x + ds * a.xdot + h * (a.xdot - b.xdot), a.p + ds * a.pdot + h * (a.pdot - b.pdot)

    def between(self, a: Point, b: Point, sb: float, s: float, natural: bool):
        """Newton's first iterate at step s from a on the step a -> b of length sb (measured as the corrector
        measures it: in p / a.pdot for the natural one, along a's tangent for the arclength one): the cubic
        Hermite interpolant of the two points and their tangents.  None with the linear predictor, or
        where b's tangent turns too far from a's for the measure to follow it."""
        if self.set.predictor != "quadratic" or not sb:
            return None
        rate = b.pdot / a.pdot if natural else self.inner(a.xdot, b.xdot) + a.pdot * b.pdot   # d sigma / ds at b
        if not rate > 0.5:
            return None
        t = s / sb
        h00, h10, h01, h11 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2
        x = h00 * a.x + h10 * sb * a.xdot + h01 * b.x + h11 * sb / rate * b.xdot
        return x, h00 * a.p + h10 * sb * a.pdot + h01 * b.p + h11 * sb / rate * b.pdot

    def _observable_bound(self, a: Point) -> float:
        return self.set.observable_step * max(1.0, abs(a.values[self.set.observable]))

    def step(self, a: Point, ds: float) -> Point | None:
        """One predictor-corrector step of length ds from a, or None (retry smaller)."""
        s = self.set
        sol = self.correct(a, ds, guess=self.extrapolate(a, ds))
        if not sol.converged:
            return None
        x, p, xdot, pdot = sol.x, sol.p, sol.xdot, sol.pdot
        assert x is not None and xdot is not None, "a converged correction holds its point and tangent"
        # the corrector's distance from the predictor grows as ds^2 times the curvature;
        # a step that had to travel far may have cut across a fold pair unseen
        dx = x - (a.x + ds * a.xdot)
        deviation = math.sqrt(self.inner(dx, dx) + (p - a.p - ds * a.pdot) ** 2) / ds
        if deviation > s.max_deviation or self.inner(a.xdot, xdot) + a.pdot * pdot < s.min_turn_cosine:
            return None
        b = self.make_point(x, p, xdot, pdot, ds=ds, newton_its=sol.newton_its, ksp_its=sol.ksp_its + sol.tangent_its,
                            corrector=sol.corrector, deviation=deviation)
        # the observable is what users read: resolve the curve in it too
        if s.observable is not None and abs(b.values[s.observable] - a.values[s.observable]) > self._observable_bound(a):
            return None
        # and its bends: a kink in the load (a rough sphere stopped by the roughness rule's outermost wall turns
        # dF/dlambda from 0 to 50 within 0.02 epsilon) is small in the state's norm but rounded off by a spline
        # through points farther apart; the distance from the tangent's line grows as ds^2 times the bend
        if s.observable is not None and self._bend(a, b, ds) > s.observable_bend:
            return None
        return b

    def _bend(self, a: Point, b: Point, ds: float) -> float:
        """The observable at b less its value on a's tangent line at the step ds."""
        o = self.set.observable
        return abs(b.values[o] - a.values[o] - ds * a.rates.get(o, 0.0)) if o in a.rates else 0.0

    def done(self, b: Point) -> tuple[str, float] | None:
        """The stop criterion b meets, as (reason, value), or None."""
        s = self.set
        if s.observable is not None and b.values[s.observable] >= s.observable_max:
            return "observable_max", b.values[s.observable]
        if b.p >= s.p_max:
            return "p_max", b.p
        if b.p <= s.p_min:
            return "p_min", b.p
        if len(self.points) > s.max_steps:
            return "max_steps", s.max_steps
        if self.folds > s.max_folds:
            return "max_folds", s.max_folds
        return None

    def run(self, start: Point, on_step=None, until=None, pause=None) -> list[Point]:
        """Trace from ``start`` until a stop criterion; ``on_step(a, b)`` sees every accepted step,
        and ``until(a, b)`` True ends the run there (after on_step).

        ``pause()`` is called before every step attempt, where the state is whole: the
        points, ``ds``, the counters and what the solvers keep (the points their
        preconditioners were built at, :class:`~petsc_adhesion.core.newton.PCReuse`).  A
        checkpoint saves it there, and :meth:`resume` goes on from it alike.
        """
        self.points.append(start)
        self.ds = self.set.ds
        self.monitor(start)
        return self.resume(on_step, until, pause)

    def name_stop(self, reason: str, value: float) -> None:
        """Name the stop an ``until`` of the caller ended the run with (its own reason and value: the end of a
        model's domain, say), for the stop's message and the files."""
        self.stop = (reason, value)

    def resume(self, on_step=None, until=None, pause=None) -> list[Point]:
        """Go on from the last point with the step ``ds``: after :meth:`run`'s start, or from a state
        restored as :meth:`run`'s ``pause`` saw it."""
        s = self.set
        a, ds = self.points[-1], self.ds
        while True:
            if pause:
                pause()
            b = self.step(a, ds)
            if b is None:
                self.newton.reuse.expire()
                self.bordered.reuse.expire()
                self.rejected += 1
                ds *= s.cut
                self.ds = ds
                if ds < s.ds_min:
                    self.stop = ("ds_min", a.p)
                    break
                continue
            self.points.append(b)
            self.folds += a.pdot * b.pdot < 0
            self.monitor(b)
            if on_step:
                on_step(a, b)
            self.stop = self.done(b)
            if self.stop:
                break
            self.ds = self._next_step(a, b, ds)
            if until and until(a, b):
                self.stop = ("until", b.p)
            if self.stop:
                break
            ds = self.ds
            a = b
        return self.points

    def _next_step(self, a: Point, b: Point, ds: float) -> float:
        """The step after an accepted one of length ds: grow on fast Newton and a nearly straight
        curve, shrink on slow Newton."""
        s = self.set
        easy = b.deviation < s.grow_margin * s.max_deviation and (
            s.observable is None or abs(b.values[s.observable] - a.values[s.observable])
            < s.grow_margin * self._observable_bound(a) and self._bend(a, b, ds) < s.grow_margin * s.observable_bend)
        if b.newton_its < s.newton_target and easy:
            return min(s.grow * ds, s.ds_max)
        if b.newton_its > s.newton_target:
            return max(s.shrink * ds, s.ds_min)
        return ds

    def monitor(self, pt: Point) -> None:
        """One line a point with -cont_monitor (rank 0)."""
        if self.set.monitor:
            obs = "".join(f" {k} {v: .10e}" for k, v in pt.values.items())
            if self.pb.comm.getRank() == 0:
                tell(f"{self.index0 + len(self.points) - 1:4d} CONT {self.pb.parameter} {pt.p: .10e}{obs} ds {pt.ds:.3e} "
                            f"{pt.corrector[:3]} Newton {pt.newton_its} KSP {pt.ksp_its}")

    def state(self, solvers: bool = True) -> dict:
        """Everything the run depends on, as plain data (a checkpoint saves it): the settings, the points
        (local parts), the next step, the counters and, with ``solvers``, what each solver keeps of its
        preconditioner.  :meth:`restore` on a continuation made with these settings goes on exactly
        as this one would (the continuation is deterministic)."""
        pts = self.points
        out = {"settings": asdict(self.set), "index0": self.index0, "ds": self.ds, "rejected": self.rejected,
               "folds": self.folds, "stop": self.stop,
               "points": {"x": np.array([p.x for p in pts]), "xdot": np.array([p.xdot for p in pts]),
                          **{k: [getattr(p, k) for p in pts] for k in POINT_FIELDS}}}
        if solvers:
            out |= {"newton": self.newton.state(), "bordered": self.bordered.state()}
        return out

    def restore(self, state: dict) -> None:
        """Take up :meth:`state` (its settings are this continuation's own, given at its making).  ValueError for
        a state this continuation could not go on from (a crafted or damaged one): its checks run first."""
        size = self._x.getLocalSize()
        counts = [state[k] for k in ("index0", "rejected", "folds")]
        if not all(isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in counts):
            raise ValueError("counters that are not counts")
        if not (isinstance(state["ds"], (int, float)) and math.isfinite(state["ds"]) and state["ds"] > 0):
            raise ValueError(f"a next step {state['ds']!r} that is not a finite positive real")
        stop = state["stop"]
        if stop is not None and not (isinstance(stop, (list, tuple)) and len(stop) == 2 and isinstance(stop[0], str)):
            raise ValueError("a stop that is not (reason, value)")
        pts = state["points"]
        x, xdot = np.asarray(pts["x"], dtype=float), np.asarray(pts["xdot"], dtype=float)
        n = len(pts["p"])
        if n < 1 or x.shape != (n, size) or xdot.shape != (n, size) or any(len(pts[k]) != n for k in POINT_FIELDS):
            raise ValueError(f"points of {x.shape} unknowns where ({n}, {size}) are expected")
        points = []
        for i in range(n):
            fields = {k: pts[k][i] for k in POINT_FIELDS}
            check_point(x[i], xdot[i], fields, size)
            points.append(Point(x=x[i].copy(), xdot=xdot[i].copy(), **fields))
        self.index0, self.ds, self.rejected, self.folds = state["index0"], float(state["ds"]), state["rejected"], \
            state["folds"]
        self.stop = tuple(stop) if stop is not None else None
        self.points = points
        if "newton" in state:
            self.newton.restore(state["newton"])
            self.bordered.restore(state["bordered"])

    def turn_around(self, label: str) -> None:
        """Put the points of a run traced backward in the curve's order, tangents and rates reversed.

        The first becomes the start (no step); every other one's step is the one from the point before it,
        its length that point's distance along its own tangent, <xdot_a, x_b - x_a> + pdot_a (p_b - p_a)
        (the backward run's corrector measured it from the other end), and its corrector is ``label``.
        """
        pts = [p.reversed() for p in reversed(self.points)]
        self.points = [replace(pts[0], ds=0.0, corrector="start")] + [
            replace(b, ds=self.inner(a.xdot, b.x - a.x) + a.pdot * (b.p - a.p), corrector=label)
            for a, b in zip(pts, pts[1:])]

    def destroy(self) -> None:
        """Free the PETSc objects made here."""
        self.newton.destroy()
        self.bordered.destroy()
        for v in (self._x, self._xt, self._rhs, self._phi, self._r):
            v.destroy()
