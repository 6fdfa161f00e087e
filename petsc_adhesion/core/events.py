"""Events along a curve, located on the discrete problem (in the manner of BifurcationKit's events).

An event is a zero of a test function between two accepted points a, b of a
:class:`~petsc_adhesion.core.continuation.Continuation`.  It is located by Brent's
method on the pseudo-arclength distance s from a (each evaluation one
corrector solve, eq. 24-25), never taken as the nearest computed point.

=====================  =======================  ==========================================
event                  test function            labels (by the sign before the zero)
=====================  =======================  ==========================================
:class:`Fold`          cdot = pdot + w v'       + to -: c is largest; - to +: smallest
:class:`Extremum`      d(observable)/ds         - to +: minimum; + to -: maximum
:class:`Zero`          observable - level       one label
:class:`ParameterValue` c - target              one label
=====================  =======================  ==========================================

The control c = p + w v is what the experimenter sets: the parameter p itself
(w = 0), or p behind a spring, c = p + v / K with v the load the spring
carries and K its stiffness (an AFM cantilever's base position).  Where c is
the control, the solution jumps at a turning point of c to another stable
branch at the same c: forward along the curve from a fold where c is
largest, backward from one where it is smallest (:meth:`EventFinder.jumps`);
a point is stable where cdot > 0 (the curve starts on a stable branch with c
growing; stability changes only at turning points of c).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import brent
from .continuation import Correction
from .protocol import Point

__all__ = ["Fold", "Extremum", "Zero", "ParameterValue", "Found", "EventFinder", "jumps", "EVENT_TOL", "SUBSTEPS", "DIP_XTOL"]

#: Default location tolerance in the parameter.
EVENT_TOL = 1e-10
#: Where the sampled pdot dips toward zero without changing sign, the two steps about the dip are
#: walked again in SUBSTEPS sub-steps each, and a dip of the walk's pdot is searched for its
#: minimum to DIP_XTOL of its sub-steps: a fold pair inside one step (near a cusp the pair is
#: narrower than any step) is found when its depth exceeds pdot's change over that distance.
SUBSTEPS, DIP_XTOL = 8, 1e-3


class _Below(Exception):
    """The dip search met the other sign at distance ``s``: a fold pair lies on the step."""

    def __init__(self, s: float):
        super().__init__(s)
        self.s = s


@dataclass(frozen=True)
class Fold:
    """Turning point of the control c = p + ``weight`` v (v the observable ``name``): cdot changes sign.
    ``labels``: (c largest, c smallest).  The default weight 0 is a turning point in p.

    Two folds inside one step leave cdot with one sign at both ends; the
    :class:`EventFinder` looks for them where the sampled cdot dips toward zero.
    """

    labels: tuple = ("fold_max", "fold_min")
    weight: float = 0.0
    name: str = "F"
    needs_tangent = True

    def value(self, pt) -> float:
        """The control at a point: c = p + weight v (needs no tangent)."""
        return pt.p + self.weight * pt.values[self.name] if self.weight else pt.p

    def test(self, pt) -> float:
        """The test function at a point: cdot = pdot + weight dv/ds."""
        return pt.pdot + self.weight * pt.rates[self.name] if self.weight else pt.pdot

    def stable(self, pt) -> bool:
        """Stable under control of c: cdot > 0."""
        return self.test(pt) > 0

    def label(self, before: float) -> str:
        """The name of the fold, by the sign of cdot before it."""
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
    """The control c = p + ``weight`` v (v the observable ``name``; the parameter p itself by default)
    crosses ``target``."""

    target: float
    tag: str = "p"
    weight: float = 0.0
    name: str = "F"
    needs_tangent = False

    def test(self, pt) -> float:
        """The test function at a point: c - target."""
        return (pt.p + self.weight * pt.values[self.name] if self.weight else pt.p) - self.target

    def label(self, before: float) -> str:
        """The event's one name."""
        return self.tag


@dataclass
class Found:
    """A located event: its point, its label, and the curve segment [points[segment], points[segment + 1]]."""

    event: object
    label: str
    point: Point
    segment: int
    before: float                 # the test function's value at the segment's start
    landing: Point | None = None  # for a fold: the point it jumps to (see jumps)
    landing_by: EventFinder | None = None  # the EventFinder (segment) that located it
    landing_step: int = -1        # and the step of that segment it lies on
    estimate: dict | None = None  # best values and error bars, when asked for (error_estimate.event_errors)
    arc: tuple | None = None      # a fold: (point(s), s0, s, s1), the arc it was located on, s its place

    def land(self, point, by, step: int) -> None:
        """Record where a fold's jump lands: ``point``, located by the EventFinder ``by`` on its step ``step``."""
        self.landing, self.landing_by, self.landing_step = point, by, step


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
        pts = self.cont.points
        before = pts[-3] if len(pts) > 2 else None
        for ev in self.events:
            fa, fb = ev.test(a), ev.test(b)
            if fa == 0.0 or fa * fb > 0:
                if isinstance(ev, Fold) and before is not None and ev.test(before) * fa > 0 \
                        and abs(fa) < min(abs(ev.test(before)), abs(fb)):
                    self._pairs(ev, ((before, a, len(pts) - 3), (a, b, len(pts) - 2)))
                continue
            point, sb = self.arc(a, b, ev.needs_tangent)
            at = self._root(point, 0.0, sb, ev.test, 0.0)
            self.found.append(Found(ev, ev.label(fa), point(at, True), len(pts) - 2, fa,
                                    arc=(point, 0.0, at, sb) if isinstance(ev, Fold) else None))

    def arc(self, a, b, tangent: bool, arclength: bool = False):
        """(point(s, tangent), sb): the corrected point at distance s from a on the step a -> b
        (cached; RuntimeError when the corrector fails), and b's distance.  With ``arclength`` the
        pseudo-arclength corrector throughout, which follows the curve through folds where the
        natural one (at fixed p) may have stepped over them."""
        cont = self.cont
        # b's distance from a: along a's tangent for the arclength corrector, in p for the natural.  b's own
        # step is that distance only where a is the point b was stepped from: a landing's piece may start at
        # a point of a fold's arc inside the step (b.ds, the whole step's, then overshoots b)
        sb = b.ds if b.ds and b.corrector == ("natural" if cont.natural_ok(a) and not arclength else "arclength") \
            and self._stepped(a, b) else cont.inner(a.xdot, b.x - a.x) + a.pdot * (b.p - a.p)
        correct = cont.arclength if arclength else cont.correct
        natural = cont.natural_ok(a) and not arclength
        cache: dict[float, Point] = {}

        def point(s, tangent=tangent):
            if s not in cache or (tangent and cache[s].corrector != "event"):
                guess = cont.between(a, b, sb, s, natural) if s else None
                sol = correct(a, s, tangent, guess) if s else Correction("", True, x=a.x, p=a.p, xdot=a.xdot,
                                                                            pdot=a.pdot)
                if not sol.converged:                 # a factorization kept from afar: once more, fresh
                    cont.newton.reuse.expire()
                    cont.bordered.reuse.expire()
                    sol = correct(a, s, tangent, guess)
                if not sol.converged:
                    raise RuntimeError(f"event location failed near {cont.pb.parameter} = {a.p:.6g}")
                cache[s] = cont.make_point(sol.x, sol.p, sol.xdot, sol.pdot,
                                           corrector="event" if tangent else "untangented")
            return cache[s]

        return point, sb

    def _stepped(self, a, b) -> bool:
        """Whether b is the continuation's point after a (so b.ds is b's distance from a)."""
        pts = self.cont.points
        return any(pts[k + 1] is b and pts[k] is a for k in range(len(pts) - 2, -1, -1))

    def locate(self, a, b, f, level: float = 0.0, tangent: bool = True):
        """The point between a and b where f = level, to ``tol`` in the parameter.

        Without ``tangent`` the evaluations skip the tangent solve (f must not
        need it); the located point gets its own tangent at the end.
        """
        point, sb = self.arc(a, b, tangent)
        return point(self._root(point, 0.0, sb, f, level), True)

    def _root(self, point, s0: float, s1: float, f, level: float) -> float:
        """The s in [s0, s1] where f(point(s)) = level, point(s) from :meth:`_arc` (an end when f - level
        does not change sign)."""
        def g(s):
            return f(point(s)) - level

        # p moves by at most |s| along a unit tangent, so xtol in s bounds the error in p
        return brent.root(g, s0, s1, xtol=self.tol, rtol=float(4 * np.finfo(float).eps), maxiter=100) \
            if g(s0) * g(s1) < 0 else (s0 if g(s0) == 0 else s1)

    def _pairs(self, ev, steps) -> None:
        """Fold pairs inside a step, where pdot has one sign at both ends (near a cusp the pair is
        narrower than any step, and the natural corrector steps over it).

        Called where the sampled pdot dips toward zero: each of the two ``steps`` (a, b, segment)
        about the dip is walked again in SUBSTEPS arclength sub-steps; the sign changes found are
        located, and where the walk's own pdot still dips inside, its minimum is sought
        (to DIP_XTOL of the sub-step) and the two folds about it located when it has the other sign.
        """
        for a, b, segment in steps:
            if any(f.segment == segment and isinstance(f.event, Fold) for f in self.found):
                continue
            _, sb = self.arc(a, b, False, arclength=True)
            walk = self._walk(a, sb / SUBSTEPS)
            t = [ev.test(c) for c in walk]
            arcs = [(self.arc(walk[k], walk[k + 1], True, arclength=True), 0.0) for k in range(len(t) - 1)
                    if t[k] * t[k + 1] <= 0 and t[k] != 0]
            k = int(np.argmin(np.abs(t)))
            if not arcs and 0 < k < len(t) - 1:
                arcs = self._dip(ev, walk[k - 1], walk[k + 1])
            for (point, end), start in arcs:
                before = ev.test(point(start))
                at = self._root(point, start, end, ev.test, 0.0)
                self.found.append(Found(ev, ev.label(before), point(at, True), segment, before,
                                        arc=(point, start, at, end)))
            if arcs:
                self.found.sort(key=lambda f: (f.segment, self._along(f)))

    def _walk(self, a, h: float) -> list:
        """a and the points after it by up to SUBSTEPS arclength steps of length h, each from the last
        with its own tangent; ends early where the corrector fails."""
        walk = [a]
        for _ in range(SUBSTEPS):
            sol = self.cont.arclength(walk[-1], h, True)
            if not sol.converged:
                break
            walk.append(self.cont.make_point(sol.x, sol.p, sol.xdot, sol.pdot, corrector="event"))
        return walk

    def _dip(self, ev, a, b) -> list:
        """The minimum of |pdot| on the arc a -> b: when pdot has the other sign there, the two pieces
        of the arc about it, each ((point(s), end), start) bracketing a fold, else []."""
        sign = np.sign(ev.test(a))
        point, sb = self.arc(a, b, True, arclength=True)

        def depth(s):
            d = sign * ev.test(point(s))
            if d < 0:
                raise _Below(s)
            return d

        try:
            lo, hi = sorted((0.0, sb))
            brent.minimum(depth, lo, hi, xatol=DIP_XTOL * abs(sb))
            return []
        except _Below as below:
            return [((point, below.s), 0.0), ((point, sb), below.s)]
        except RuntimeError:                # the corrector did not reach: no pair seen
            return []

    def _along(self, f: Found) -> float:
        """Distance of a located event from the start of its step, along the start's tangent."""
        a = self.cont.points[f.segment]
        return self.cont.inner(a.xdot, f.point.x - a.x) + a.pdot * (f.point.p - a.p)

    def land_near(self, ev: Found, stable) -> bool:
        """The landing of the fold ``ev`` on the step of the next fold of its control (forward jump) or of the
        one before (backward), whose other end is unstable: on the arc that fold was located on, beyond it
        (before it), then, for a pair inside one step, from that arc's end to the step's end (from the step's
        start to the arc's start).  Found or not."""
        fold = ev.event
        assert isinstance(fold, Fold), "a landing is a fold's (jumps() calls this for folds alone)"
        folds = [f for f in self.found if f.event is fold]
        k = next(i for i, f in enumerate(folds) if f is ev) + (1 if ev.before > 0 else -1)
        other = folds[k] if 0 <= k < len(folds) else None
        if other is None or other.arc is None:
            return False
        pts, cf = self.cont.points, fold.value(ev.point)
        point, s0, at, s1 = other.arc
        landing = ev.landing         # a landing located before stands; the finder it names is set anew
        pieces: list[tuple] = [(point, at, s1)] if ev.before > 0 else [(point, s0, at)]
        if other.segment == ev.segment:
            pieces.append((point(s1), pts[ev.segment + 1]) if ev.before > 0 else (pts[ev.segment], point(s0)))
        for piece in pieces:
            if len(piece) == 3:
                arc, lo, hi = piece
                if (fold.value(arc(lo)) - cf) * (fold.value(arc(hi)) - cf) <= 0 and \
                        stable(arc(hi if ev.before > 0 else lo)):
                    landing = arc(self._root(arc, lo, hi, fold.value, cf), True)
            elif stable(piece[0]) and stable(piece[1]) and \
                    (fold.value(piece[0]) - cf) * (fold.value(piece[1]) - cf) <= 0:
                landing = self.locate(piece[0], piece[1], fold.value, level=cf, tangent=False)
            if landing is not None:
                ev.land(landing, self, other.segment)
                return True
        return False

    def jumps(self, stable=None) -> None:
        """For each fold, the state it jumps to (``Found.landing``): :func:`jumps` on this one curve."""
        jumps([self], stable)

    def state(self, index_of) -> list[dict]:
        """The events found, as plain data (a checkpoint saves them); ``index_of(finder)``: the number of the
        finder (of the curve's segments) a landing was located by."""
        return [{"event": self.events.index(f.event), "label": f.label, "segment": f.segment, "before": f.before,
                 "point": f.point.state(), "landing": None if f.landing is None else f.landing.state(),
                 "landing_by": None if f.landing_by is None else index_of(f.landing_by),
                 "landing_step": f.landing_step, "estimate": f.estimate} for f in self.found]

    def restore(self, state: list[dict], finder_at) -> None:
        """Take up :meth:`state`; ``finder_at(number)``: the finder of that number (IndexError for none).
        ValueError for events that are not this finder's."""
        found, size, steps = [], self.cont.size, len(self.cont.points) - 1
        for d in state:
            ints = (d["event"], d["segment"], d["landing_step"])
            if not all(isinstance(i, int) and not isinstance(i, bool) for i in ints) or \
                    not 0 <= d["event"] < len(self.events) or not 0 <= d["segment"] < max(steps, 1) or \
                    not isinstance(d["label"], str) or not isinstance(d["before"], (int, float)) or \
                    not np.isfinite(d["before"]) or not (d["estimate"] is None or isinstance(d["estimate"], dict)):
                raise ValueError("an event that is not one of this curve's")
            by = None
            if d["landing_by"] is not None:
                if not isinstance(d["landing_by"], int) or d["landing_by"] < 0:
                    raise ValueError("a landing on no segment")
                by = finder_at(d["landing_by"])
            landing = Point.from_state(d["landing"], by.cont.size) if by is not None else None
            found.append(Found(self.events[d["event"]], d["label"], Point.from_state(d["point"], size), d["segment"],
                               float(d["before"]), landing=landing, landing_by=by, landing_step=d["landing_step"],
                               estimate=d["estimate"]))
        self.found = found


def jumps(finders, stable=None) -> None:
    """For each fold found by ``finders`` (the segments of one curve, in order), the state on another
    stable branch at the same control c (``Found.landing``).

    Under control of c the state jumps forward along the curve from a fold
    where c is largest, backward from one where it is smallest: the first
    crossing of the fold's c on a step whose ends are stable under c in that
    direction is where it lands, located on that step's own segment.  Steps
    between segments (a change of discretization) are not crossings.
    ``stable(point)``: stability under control of c (default :meth:`Fold.stable`,
    cdot > 0: for a curve that starts stable with c growing).
    """
    steps = [(f, j) for f in finders for j in range(len(f.cont.points) - 1)]
    for finder in finders:
        for ev in finder.found:
            if not isinstance(ev.event, Fold):
                continue
            fold = ev.event
            ok = stable or fold.stable
            at = steps.index((finder, ev.segment))
            cf = fold.value(ev.point)
            order = steps[at + 1:] if ev.before > 0 else steps[at - 1::-1] if at else []
            if finder.land_near(ev, ok):
                continue
            for owner, j in order:
                a, b = owner.cont.points[j], owner.cont.points[j + 1]
                if ok(a) and ok(b) and (fold.value(a) - cf) * (fold.value(b) - cf) <= 0:
                    ev.land(owner.locate(a, b, fold.value, level=cf, tangent=False), owner, j)
                    break
