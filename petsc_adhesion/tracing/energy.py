"""The energy dissipated in one quasi-static approach-retract cycle: the area of the hysteresis loops.

Under control of c (the approach lambda with a rigid machine; the base
position Z = lambda + F / K behind a spring of stiffness K) the state follows
a stable branch until a turning point of c, where it jumps at constant c to
the landing on another stable branch (:func:`~petsc_adhesion.core.events.jumps`).
The approach walks the traced curve forward from its start, jumping forward
at the folds where c is largest; the retraction walks it backward from its
end, jumping backward at the folds where c is smallest.  The work the machine
does on the sphere over the cycle,

    W = closed integral of F dc = sum over the approach of F dc - sum over the retraction of F dc,

is what the cycle dissipates (the elastic energy and the spring's return to
their starting values; the jumps, at constant c, do no work).  It is positive,
in units of 2 pi R gamma epsilon, and zero when the curve has no turning point
of c (both walks then cover the same stretch, which cancels exactly).

Each stretch between two computed or located points of one grid is integrated
(halved at points solved for on the curve until the integral settles,
:class:`_Pieces`) along the planar cubic Hermite interpolant of the curve (lambda, F) through
its ends, with the tangents' directions there (lambdadot : dF/ds) and
magnitudes the chord's (the curve parametrised by its chord length, which is
smooth through the folds, where lambdadot = 0), by 3-point Gauss-Legendre,
exact for that interpolant; behind a spring, F dZ = F dlambda + d(F^2) / (2K)
exactly.  The
step between two grids (a point carried to the next segment's grid) adds
nothing: its two ends are one state on two discretizations, up to the carry's
slide along the curve (the tangential part of the interpolation's error, which
falls like h^2: at mu = 5, sigma = 0 the work it leaves out is 7.3e-5 on the
default grids, 1.9e-5 on grids twice as fine), part of the grid's error that the
levels of the bar measure, each level carrying its own handovers.

The error bar comes from the loops on the nested levels of the events' error
bars (:func:`~petsc_adhesion.tracing.error_bars.energy_levels`): the borders'
points (:func:`border`) put on each level's curve and integrated there by
the same quadrature on the same partition (:func:`border_integral`), so that
the errors of the jumps and of the borders, which largely cancel in the
area, cancel in each level's area too; the results (``tracing/results.py``)
extrapolate them.  Where the levels cannot be had, :func:`energy_bar` bounds
the grid's effect on the area from the events' errors: each jump moved in c
by its fold's error (times the jump's height in F), and each stretch of a
loop's border moved in F by the larger error of F at its two ends (times its
width in c); an event's grid error is its distance from its best value plus
its bar (sums of absolute values, which do not credit that cancellation).  Both are
measured against finer grids in docs/coverage.md.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..core.events import Fold, Found
from ..core.protocol import Point

__all__ = ["Node", "Loop", "cycle", "energy_bar", "hermite_integral", "border", "border_integral"]

#: 3-point Gauss-Legendre on [0, 1]: exact for the product of a cubic and a quadratic.
_GL_T = 0.5 + 0.5 * np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
_GL_W = np.array([5.0, 8.0, 5.0]) / 18.0


def hermite_integral(L: float, p0: float, p1: float, pd0: float, pd1: float,
                     F0: float, F1: float, Fd0: float, Fd1: float) -> float:
    """The integral of F dp over [0, L] for the cubic Hermite interpolants of p(s) and F(s) with the given
    end values and end rates (exact: the integrand F p' is a quintic).

    >>> round(hermite_integral(2.0, 0.0, 2.0, 1.0, 1.0, 0.0, 4.0, 0.0, 4.0), 12)   # F = p^2: 8/3
    2.666666666667
    """
    t = _GL_T
    h00, h10, h01, h11 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2
    d00, d10, d01, d11 = 6 * t**2 - 6 * t, 3 * t**2 - 4 * t + 1, -6 * t**2 + 6 * t, 3 * t**2 - 2 * t
    F = h00 * F0 + h10 * L * Fd0 + h01 * F1 + h11 * L * Fd1
    dp = (d00 * p0 + d10 * L * pd0 + d01 * p1 + d11 * L * pd1) / L        # dp/ds
    return float(L * np.dot(_GL_W, F * dp))


@dataclass
class Node:
    """A point of the traced curve in its order: a computed point, a located fold of the control or a landing.

    ``key``: (segment, step, distance along the step's start tangent); ``found``: the fold (for a fold or
    its landing), else None; ``landing``: whether it is the fold's landing."""

    key: tuple
    seg: int
    point: Point
    found: Found | None = None
    landing: bool = False


def _nodes(segments, fold: Fold) -> list[Node]:
    """Every computed point, every located turning point of ``fold``'s control and every landing of one, in
    the order of the curve (collective: the distances along a step are inner products)."""
    index = {id(seg.finder): k for k, seg in enumerate(segments)}
    nodes = [Node((k, j, 0.0), k, p) for k, seg in enumerate(segments) for j, p in enumerate(seg.cont.points)]

    def along(k: int, j: int, pt) -> float:
        cont = segments[k].cont
        a = cont.points[j]
        return cont.inner(a.xdot, pt.x - a.x) + a.pdot * (pt.p - a.p)

    for k, seg in enumerate(segments):
        for f in seg.finder.found:
            if f.event is not fold:
                continue
            nodes.append(Node((k, f.segment, along(k, f.segment, f.point)), k, f.point, f))
            if f.landing is not None:
                kl = index[id(f.landing_by)]
                nodes.append(Node((kl, f.landing_step, along(kl, f.landing_step, f.landing)), kl, f.landing, f, True))
    nodes.sort(key=lambda n: n.key)
    return nodes


def _integral(a, b, weight: float) -> float:
    """The integral of F dc from the point a to the point b along the planar Hermite interpolant."""
    Fa, Fb = a.values["F"], b.values["F"]
    d = math.hypot(b.p - a.p, Fb - Fa)
    if d == 0.0:
        return 0.0
    na, nb = math.hypot(a.pdot, a.rates["F"]), math.hypot(b.pdot, b.rates["F"])
    return hermite_integral(d, a.p, b.p, a.pdot / na, b.pdot / nb, Fa, Fb, a.rates["F"] / na, b.rates["F"] / nb) \
        + weight * (Fb * Fb - Fa * Fa) / 2


class _Pieces:
    """The integrals of F dc over the pieces between consecutive nodes, refined where the interpolant is
    not yet accurate (collective: a refinement solves for points on the curve)."""

    def __init__(self, segments, nodes: list[Node], weight: float, tol: float):
        self.segments, self.nodes, self.weight, self.tol = segments, nodes, weight, tol
        self.arcs: dict[tuple[int, int], Callable[..., Point]] = {}     # (segment, step) -> its arc
        self.solves = 0

    def _arc(self, k: int, j: int):
        if (k, j) not in self.arcs:
            seg = self.segments[k]
            a, b = seg.cont.points[j], seg.cont.points[j + 1]
            self.arcs[k, j] = seg.finder.arc(a, b, True, arclength=True)[0]
        return self.arcs[k, j]

    def _along(self, k: int, j: int, pt) -> float:
        cont = self.segments[k].cont
        a = cont.points[j]
        return cont.inner(a.xdot, pt.x - a.x) + a.pdot * (pt.p - a.p)

    def integral(self, i: int) -> tuple[float, float, list]:
        """(integral, error estimate, the points it was halved at, in order) from node i to node i + 1;
        (0, 0, []) between two grids.

        The piece is halved at the curve's point halfway along the step (the arclength corrector on the
        hyperplane there) until the two halves' sum changes by less than the piece's share of ``tol``
        (at most MAX_HALVINGS times); the last change is the estimate."""
        u, v = self.nodes[i], self.nodes[i + 1]
        if u.seg != v.seg:
            return 0.0, 0.0, []
        k, j = u.seg, u.key[1]
        s0 = u.key[2]
        s1 = v.key[2] if v.key[1] == j else self._along(k, j, v.point)
        width = abs(v.point.p - u.point.p) + abs(v.point.values["F"] - u.point.values["F"])
        return self._refine(k, j, u.point, v.point, s0, s1, _integral(u.point, v.point, self.weight), 0, width)

    def _refine(self, k, j, a, b, s0, s1, whole, depth, width):
        if depth >= MAX_HALVINGS or j >= len(self.segments[k].cont.points) - 1:
            return whole, (abs(whole) if depth == 0 else 0.0), []
        try:
            m = self._arc(k, j)(0.5 * (s0 + s1), True)
        except RuntimeError:                   # the corrector did not reach: the piece as it is, its whole value its bar
            return whole, abs(whole), []
        self.solves += 1
        left, right = _integral(a, m, self.weight), _integral(m, b, self.weight)
        change = abs(left + right - whole)
        if change <= self.tol * max(width, 1e-300):
            return left + right, change, [m]
        half = 0.5 * width
        il, el, pl = self._refine(k, j, a, m, s0, 0.5 * (s0 + s1), left, depth + 1, half)
        ir, er, pr = self._refine(k, j, m, b, 0.5 * (s0 + s1), s1, right, depth + 1, half)
        return il + ir, el + er, pl + [m] + pr


#: Halvings of a piece at most (the interpolant's error falls by about 16 with each).
MAX_HALVINGS = 6
#: The quadrature's tolerance: the change of a piece's integral on halving, per unit of its extent
#: |d lambda| + |dF| (2 pi R gamma epsilon per epsilon).
QUADRATURE_TOL = 1e-5


def _walk(nodes: list[Node], forward: bool) -> tuple[list[int], list] | str:
    """(the pieces, by the index of their first node, the quasi-static walk covers, the folds it jumps at):
    the approach (``forward``) from the first node, the retraction from the last; or why there is none."""
    where = {(id(n.found), n.landing): i for i, n in enumerate(nodes) if n.found is not None}
    step = 1 if forward else -1
    i, end, pieces, jumped = (0, len(nodes) - 1, [], []) if forward else (len(nodes) - 1, 0, [], [])
    while i != end:
        n = nodes[i]
        if n.found is not None and not n.landing and (n.found.before > 0) == forward:
            if n.found.landing is None:
                return f"the jump at {n.found.label} lands beyond the traced curve"
            j = where[(id(n.found), True)]
            if (j - i) * step <= 0:
                return f"the jump at {n.found.label} lands {'behind' if forward else 'ahead of'} itself"
            jumped.append(n.found)
            i = j
            continue
        pieces.append(i if forward else i - 1)
        i += step
    return pieces, jumped


@dataclass(frozen=True)
class Loop:
    """The cycle walked under control of a fold's c (:func:`cycle`): the ``energy`` it dissipates (None when
    it cannot be walked, ``note`` saying why), the sum of the last changes of the pieces' integrals on
    halving (``quadrature_err``), the points solved for on the way (``solves``), the hysteresis ``loops``,
    the folds the approach and then the retraction jump at (``jumps``), the ``pieces`` of the loops'
    borders as (first node, last node, multiplicity), the ``nodes`` walked and the points each piece of
    the borders was halved at (``inner``: (first node, its points in order))."""

    energy: float | None
    note: str | None = None
    quadrature_err: float = 0.0
    solves: int = 0
    loops: int = 0
    jumps: tuple = ()
    pieces: tuple = ()
    nodes: tuple = ()
    inner: tuple = ()


def cycle(segments, fold: Fold) -> Loop:
    """The energy one approach-retract cycle dissipates under control of ``fold``'s c (collective).

    Returns the :class:`Loop`, its energy None with a note when the cycle cannot be walked (a jump lands
    beyond the traced curve; the curve ends on an unstable branch).  ``quadrature_err``: the error of the
    pieces' integrals (:class:`_Pieces`; the error of the halved value is smaller by about 16 where the
    interpolant resolves the border).
    """
    nodes = _nodes(segments, fold)
    if not fold.stable(nodes[-1].point) or not fold.stable(nodes[0].point):
        return Loop(None, "the curve does not end on a stable branch: no cycle to close")
    approach, retract = _walk(nodes, True), _walk(nodes, False)
    if isinstance(approach, str):
        return Loop(None, approach)
    if isinstance(retract, str):
        return Loop(None, retract)
    m = np.zeros(len(nodes) - 1, dtype=int)
    np.add.at(m, approach[0], 1)
    np.add.at(m, retract[0], -1)
    runs, i = [], 0
    while i < len(m):
        if m[i] == 0:
            i += 1
            continue
        j = i
        while j + 1 < len(m) and m[j + 1] == m[i]:
            j += 1
        runs.append((i, j + 1, int(m[i])))
        i = j + 1
    pieces = _Pieces(segments, nodes, fold.weight, QUADRATURE_TOL)
    energy = quadrature = 0.0
    inner = []
    for i, j, k in runs:
        for n in range(i, j):
            value, err, halved = pieces.integral(n)
            energy += k * value
            quadrature += abs(k) * err
            inner.append((n, tuple(halved)))
    jumped = approach[1] + retract[1]
    return Loop(energy, None, quadrature, pieces.solves, len(approach[1]) if runs else 0,
                tuple(jumped) if runs else (), tuple(runs), tuple(nodes), tuple(inner))


def energy_bar(result: Loop, fold: Fold, event_of) -> float | None:
    """The error bar of ``result``'s energy (:func:`cycle`) under control of ``fold``'s c; ``event_of(found)``:
    the :class:`~.curve.Event` of a located fold, with its best values, bars and grid values (no bar, no grid
    value without an error estimate: then no bar here, None).  0 without hysteresis; None without an
    energy.

    Each jump: |F(fold) - F(landing)| times the error of the fold's c; each stretch of a loop's border:
    |c(end) - c(start)| times the larger error of F at its two ends (an end that is no event: the largest
    error of F of the loop's events).  An error: |grid value - best value| + bar.  Plus the quadrature's
    estimate (:func:`cycle`).
    """
    if result.energy is None or not result.pieces:
        return None if result.energy is None else 0.0
    key = "Z" if fold.weight else "lam"
    evs = {id(n.found): event_of(n.found) for n in result.nodes if n.found is not None}
    if any(getattr(evs[id(f)], key) is None or getattr(evs[id(f)], key).err is None or evs[id(f)].F.err is None
           for f in result.jumps):
        return None

    def err(m) -> float:
        """The grid value's distance from the best value, plus the bar."""
        return abs((m.value if m.grid is None else m.grid) - m.value) + m.err

    def F_error(node) -> float | None:
        if node.found is None:
            return None
        ev = evs[id(node.found)]
        if node.landing:
            return None if ev.landing is None or ev.landing.F.err is None else err(ev.landing.F)
        return err(ev.F)

    bar = result.quadrature_err
    for f in result.jumps:
        ev = evs[id(f)]
        if ev.landing is not None:
            bar += abs(ev.landing.F.value - ev.F.value) * err(getattr(ev, key))
    nodes = result.nodes
    jumped = {id(f) for f in result.jumps}
    ends = [e for n in nodes if n.found is not None and id(n.found) in jumped and (e := F_error(n)) is not None]
    worst = max(ends, default=0.0)
    for i, j, _ in result.pieces:
        u, v = nodes[i], nodes[j]
        eu, ev = F_error(u), F_error(v)
        e = max(worst if eu is None else eu, worst if ev is None else ev)
        bar += abs(fold.value(v.point) - fold.value(u.point)) * e
    return bar


def border(result: Loop) -> list[tuple[int, int]]:
    """The points of ``result``'s loops' borders (:func:`cycle`) as (node index, -1) for a node of
    ``result.nodes`` and (node index, m) for the m-th point its piece was halved at, each once."""
    out = {(n, -1) for i, j, _ in result.pieces for n in range(i, j + 1)}
    out |= {(n, m) for n, pts in result.inner for m in range(len(pts))}
    return sorted(out)


def border_integral(result: Loop, points: dict, weight: float) -> float:
    """The closed integral of F dc along the loops' borders through ``points`` (one for every key of
    :func:`border`), each piece by the planar Hermite interpolants between the points it was halved at.

    With the curve's own points it is the energy of :func:`cycle` (the same sums); with the same points
    put on another level's curve (the corners, a fold and its landing, located there) it is that level's
    energy by the same quadrature on the same partition, so that the difference of the two holds the
    grid's change and not the quadrature's error.
    """
    nodes, inner = result.nodes, dict(result.inner)
    total = 0.0
    for i, j, k in result.pieces:
        for n in range(i, j):
            if nodes[n].seg != nodes[n + 1].seg:            # between two grids: one state, no work (but its slide)
                continue
            chain = [points[n, -1]] + [points[n, m] for m in range(len(inner.get(n, ())))] + [points[n + 1, -1]]
            total += k * sum(_integral(a, b, weight) for a, b in zip(chain, chain[1:]))
    return total
