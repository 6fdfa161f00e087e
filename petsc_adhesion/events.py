"""Events on a load-approach curve, located on the discrete problem.

An event is a zero of a test function between two accepted points a, b.  It is
located by Brent's method on the pseudo-arclength distance s from a (each
evaluation is one arclength corrector solve, eq. 24-25), never taken as the
nearest computed point:

=============  ====================  =============================================
kind           test function         meaning
=============  ====================  =============================================
snap_on        lambdadot (+ to -)    turning point in lambda: jump-in on approach
snap_off       lambdadot (- to +)    turning point in lambda: jump-out on retraction
F_min, F_max   dF/ds                 load extremum; the most tensile F_min is the
                                     load-controlled pull-off
equilibrium    F                     zero load
lambda         lambda - target       state asked for by -cont_at_lambda
=============  ====================  =============================================

Under displacement control a point is stable when lambdadot > 0: det G_H has
the sign of lambdadot along the curve, and the far branch is stable.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .grid import PAPER_UNIFORM

__all__ = ["EventFinder", "grid_warning"]


def _tests(targets):
    """name -> (test function, whether it needs the tangent at each evaluation)."""
    tests = {"fold": (lambda p: p.tl, True), "load_extremum": (lambda p: p.dF, True),
             "equilibrium": (lambda p: p.F, False)}
    for t in targets:
        tests[f"lambda={t!r}"] = (lambda p, t=t: p.lam - t, False)
    return tests


class EventFinder:
    """Watch accepted steps for sign changes of the test functions; locate them.

    Parameters
    ----------
    cont : Continuation
    targets : sequence of float
        Approaches at which to record the state.
    tol : float
        Tolerance in lambda of the located events.
    profiles : bool
        Keep H(r) and P(r) (local parts) of each event.
    """

    def __init__(self, cont, targets=(), tol=1e-10, profiles=False):
        self.cont, self.tol, self.profiles = cont, tol, profiles
        self.tests = _tests(targets)
        self.events: list[dict] = []

    def __call__(self, a, b) -> None:
        for name, (f, tangent) in self.tests.items():
            fa, fb = f(a), f(b)
            if fa == 0.0 or fa * fb > 0:
                continue
            p = self.locate(a, b, f, tangent=tangent)
            kind = {"fold": "snap_on" if fa > 0 else "snap_off",
                    "load_extremum": "F_min" if fa < 0 else "F_max",
                    "equilibrium": "equilibrium"}.get(name, "lambda")
            self.events.append(self.record(kind, p, segment=len(self.cont.points) - 2))

    def locate(self, a, b, f, level: float = 0.0, tangent: bool = True):
        """The point between a and b where f = level, to self.tol in lambda.

        Without ``tangent`` the evaluations skip the tangent solve (f must not
        need it); the located point gets its own tangent at the end.
        """
        cont = self.cont
        # b's distance from a: along a's tangent for the arclength corrector, in lambda for the natural
        sb = b.ds if b.ds and b.kind == ("natural" if cont.natural_ok(a) else "arclength") else \
            cont.pb.inner(a.th, b.h - a.h) + a.tl * (b.lam - a.lam)
        cache = {}

        def g(s, tangent=tangent):
            if s not in cache:
                sol = cont.correct(a, s, tangent) if s else (a.h, a.lam, (a.th, a.tl, 0), 0, 0, "")
                if sol is None:
                    raise RuntimeError(f"event location failed near lambda = {a.lam:.6g}")
                h, lam, (th, tl, _), *_ = sol
                cache[s] = cont.make_point(h, lam, th, tl, kind="event")
            return f(cache[s]) - level

        # lambda moves by at most |s| along a unit tangent, so xtol in s bounds the error in lambda
        s = brentq(g, 0.0, sb, xtol=self.tol, rtol=4 * np.finfo(float).eps, maxiter=100) \
            if g(0.0) * g(sb) < 0 else (0.0 if g(0.0) == 0 else sb)
        if not tangent and s:
            del cache[s]
        g(s, True)
        return cache[s]

    def record(self, kind: str, p, segment: int) -> dict:
        ev = {"kind": kind, "lambda": p.lam, "F": p.F, "segment": segment,
              "H0": self.cont.pb.comm.tompi4py().bcast(float(p.h[0]) if self.cont.pb.lo == 0 else None, root=0)}
        if kind not in ("snap_on", "snap_off"):           # at a fold lambdadot = 0: marginal
            ev["stable"] = bool(p.tl > 0)
        if self.profiles:
            ev["h"] = p.h
        return ev

    def landings(self) -> None:
        """For each fold, the state on the other stable branch at the same lambda (Figs. 6, 7).

        On approach the contact jumps forward along the curve from a snap-on; on
        retraction backward from a snap-off: the first crossing of the fold's
        lambda on a stable segment in that direction is where it lands.
        """
        pts = self.cont.points
        for ev in self.events:
            if ev["kind"] not in ("snap_on", "snap_off"):
                continue
            k, lf = ev["segment"], ev["lambda"]
            order = range(k + 1, len(pts) - 1) if ev["kind"] == "snap_on" else range(k - 1, -1, -1)
            for j in order:
                a, b = pts[j], pts[j + 1]
                if a.tl > 0 and b.tl > 0 and (a.lam - lf) * (b.lam - lf) <= 0:
                    p = self.locate(a, b, lambda p: p.lam, level=lf, tangent=False)
                    ev["landing"] = {"lambda": p.lam, "F": p.F, "H0": self.record("x", p, j)["H0"]}
                    if self.profiles:
                        ev["landing"]["h"] = p.h
                    break

    def pull_off(self) -> dict | None:
        """The load-controlled pull-off: the most tensile load extremum."""
        mins = [e for e in self.events if e["kind"] == "F_min"]
        return min(mins, key=lambda e: e["F"]) if mins else None


#: Nodes needed across the cohesive zone: measured at mu = 3 and 5, where uniform
#: grids with h > zone/5 showed staircases of spurious folds and h <= zone/5 did not.
NODES_PER_ZONE = 5
#: The resolved model shows at most two fold pairs (paper, Fig. 9, up to mu = 7).
MAX_TRUE_FOLDS = 4


def grid_warning(model, r: np.ndarray, edges: np.ndarray, folds: int) -> str:
    """One line when the grid cannot resolve the cohesive zone at the contact edge.

    ``edges`` are the radii of peak attraction (the contact edge) along the
    curve.  The zone is about 0.75 mu^-1.5 wide; a grid coarser than
    zone/NODES_PER_ZONE where the edge travels traps the edge between nodes
    (lattice trapping) and turns the S-curve into a staircase of spurious
    turning points, which is the other symptom checked (``folds``).
    """
    zone = model.cohesive_zone
    if edges.size == 0 or not np.isfinite(zone):
        return ""
    lo, hi = edges.min(), edges.max()
    h = np.diff(r)
    mid = 0.5 * (r[:-1] + r[1:])
    sel = (mid >= lo - h) & (mid <= hi + h)
    hmax = float(h[sel].max()) if sel.any() else float(h.max())
    need = zone / NODES_PER_ZONE
    if hmax <= need and folds <= MAX_TRUE_FOLDS:
        return ""
    # a paper grid that refines [0, r_edge + 2] enough (the edge may travel further than seen)
    h0 = model.rmax / (PAPER_UNIFORM - 1)
    extra = min(int(np.ceil(min(hi + 2.0, model.rmax) / h0)), PAPER_UNIFORM - 1)
    split = max(2, int(np.ceil(h0 / need)))
    return (f"{folds} turning points; grid spacing {hmax:.3g} where the contact edge travels "
            f"(r in [{lo:.3g}, {hi:.3g}]) does not resolve the cohesive zone {zone:.3g} at mu = {model.mu:g}: "
            f"this case needs spacing <= {need:.3g} there, e.g. -grid_type paper "
            f"-grid_paper_extra {extra} -grid_paper_split {split} ({PAPER_UNIFORM + extra * (split - 1)} nodes)")
