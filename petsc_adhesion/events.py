"""Events along a curve, located on the discrete problem (in the manner of BifurcationKit's events).

An event is a zero of a test function between two accepted points a, b of a
:class:`~petsc_adhesion.continuation.Continuation`.  It is located by Brent's
method on the pseudo-arclength distance s from a (each evaluation one
corrector solve, eq. 24-25), never taken as the nearest computed point.

=====================  =======================  ==========================================
event                  test function            labels (by the sign before the zero)
=====================  =======================  ==========================================
:class:`Fold`          pdot                     + to -: p is largest; - to +: smallest
:class:`Extremum`      d(observable)/ds         - to +: minimum; + to -: maximum
:class:`Zero`          observable - level       one label
:class:`ParameterValue` p - target              one label
=====================  =======================  ==========================================

Where the control is the parameter p, the solution jumps at a fold to
another stable branch at the same p: forward along the curve from a fold
where p is largest, backward from one where it is smallest
(:meth:`EventFinder.jumps`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

__all__ = ["Fold", "Extremum", "Zero", "ParameterValue", "Found", "EventFinder", "jumps", "EVENT_TOL"]

#: Default location tolerance in the parameter.
EVENT_TOL = 1e-10


@dataclass(frozen=True)
class Fold:
    """Turning point in p: pdot changes sign. ``labels``: (p largest, p smallest)."""

    labels: tuple = ("fold_max", "fold_min")
    needs_tangent = True

    def test(self, pt) -> float:
        """The test function at a point: pdot."""
        return pt.pdot

    def label(self, before: float) -> str:
        """The name of the fold, by the sign of pdot before it."""
        return self.labels[0] if before > 0 else self.labels[1]


@dataclass(frozen=True)
class Extremum:
    """Extremum of the observable ``name`` along the curve: its rate d/ds changes sign.

    ``labels``: (minimum, maximum).
    """

    name: str
    labels: tuple = ("min", "max")
    needs_tangent = True

    def test(self, pt) -> float:
        """The test function at a point: the observable's rate d/ds."""
        return pt.rates[self.name]

    def label(self, before: float) -> str:
        """The name of the extremum, by the sign of the rate before it."""
        return self.labels[0] if before < 0 else self.labels[1]


@dataclass(frozen=True)
class Zero:
    """The observable ``name`` crosses ``level``."""

    name: str
    tag: str = "zero"
    level: float = 0.0
    needs_tangent = False

    def test(self, pt) -> float:
        """The test function at a point: observable - level."""
        return pt.values[self.name] - self.level

    def label(self, before: float) -> str:
        """The event's one name."""
        return self.tag


@dataclass(frozen=True)
class ParameterValue:
    """The parameter crosses ``target``."""

    target: float
    tag: str = "p"
    needs_tangent = False

    def test(self, pt) -> float:
        """The test function at a point: p - target."""
        return pt.p - self.target

    def label(self, before: float) -> str:
        """The event's one name."""
        return self.tag


@dataclass
class Found:
    """A located event: its point, its label, and the curve segment [points[segment], points[segment + 1]]."""

    event: object
    label: str
    point: object
    segment: int
    before: float                 # the test function's value at the segment's start
    landing: object = None        # for a fold: the point it jumps to (see jumps)
    landing_by: object = None     # the EventFinder (segment) that located it
    landing_step: int = -1        # and the step of that segment it lies on
    estimate: dict | None = None  # best values and error bars, when asked for (error_estimate.event_errors)


class EventFinder:
    """Watch accepted steps for sign changes of the events' test functions; locate them.

    Parameters
    ----------
    cont : Continuation
    events : sequence
        Event objects, tested in this order at every step.
    tol : float
        Tolerance in the parameter of the located events.
    """

    def __init__(self, cont, events, tol: float = EVENT_TOL):
        self.cont, self.events, self.tol = cont, list(events), tol
        self.found: list[Found] = []

    def __call__(self, a, b) -> None:
        """The ``on_step`` callback of the continuation."""
        for ev in self.events:
            fa, fb = ev.test(a), ev.test(b)
            if fa == 0.0 or fa * fb > 0:
                continue
            pt = self.locate(a, b, ev.test, tangent=ev.needs_tangent)
            self.found.append(Found(ev, ev.label(fa), pt, len(self.cont.points) - 2, fa))

    def locate(self, a, b, f, level: float = 0.0, tangent: bool = True):
        """The point between a and b where f = level, to ``tol`` in the parameter.

        Without ``tangent`` the evaluations skip the tangent solve (f must not
        need it); the located point gets its own tangent at the end.
        """
        cont = self.cont
        # b's distance from a: along a's tangent for the arclength corrector, in p for the natural
        sb = b.ds if b.ds and b.corrector == ("natural" if cont.natural_ok(a) else "arclength") else \
            cont.inner(a.xdot, b.x - a.x) + a.pdot * (b.p - a.p)
        cache = {}

        def g(s, tangent=tangent):
            if s not in cache:
                sol = cont.correct(a, s, tangent) if s else (a.x, a.p, (a.xdot, a.pdot, 0), 0, 0, "")
                if sol is None:                       # a factorization kept from afar: once more, fresh
                    cont.newton.reuse.expire()
                    cont.bordered.reuse.expire()
                    sol = cont.correct(a, s, tangent)
                if sol is None:
                    raise RuntimeError(f"event location failed near {cont.pb.parameter} = {a.p:.6g}")
                x, p, (xdot, pdot, _), *_ = sol
                cache[s] = cont.make_point(x, p, xdot, pdot, corrector="event")
            return f(cache[s]) - level

        # p moves by at most |s| along a unit tangent, so xtol in s bounds the error in p
        s = brentq(g, 0.0, sb, xtol=self.tol, rtol=4 * np.finfo(float).eps, maxiter=100) \
            if g(0.0) * g(sb) < 0 else (0.0 if g(0.0) == 0 else sb)
        if not tangent and s:
            del cache[s]
        g(s, True)
        return cache[s]

    def jumps(self, stable) -> None:
        """For each fold, the state it jumps to (``Found.landing``): :func:`jumps` on this one curve."""
        jumps([self], stable)


def jumps(finders, stable) -> None:
    """For each fold found by ``finders`` (the segments of one curve, in order), the state on another
    stable branch at the same p (``Found.landing``).

    Under control of p the state jumps forward along the curve from a fold
    where p is largest, backward from one where it is smallest: the first
    crossing of the fold's p on a step whose ends are ``stable(point)`` in that
    direction is where it lands, located on that step's own segment.  Steps
    between segments (a change of discretization) are not crossings.
    """
    steps = [(f, j) for f in finders for j in range(len(f.cont.points) - 1)]
    for k, finder in enumerate(finders):
        for ev in finder.found:
            if not isinstance(ev.event, Fold):
                continue
            at = steps.index((finder, ev.segment))
            pf = ev.point.p
            order = steps[at + 1:] if ev.before > 0 else steps[at - 1::-1] if at else []
            for owner, j in order:
                a, b = owner.cont.points[j], owner.cont.points[j + 1]
                if stable(a) and stable(b) and (a.p - pf) * (b.p - pf) <= 0:
                    ev.landing = owner.locate(a, b, lambda pt: pt.p, level=pf, tangent=False)
                    ev.landing_by, ev.landing_step = owner, j
                    break
