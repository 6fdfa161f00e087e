"""The error of each event: the same event located on nested refinement levels of its own grid.

An event was located on the grid of one segment of the curve (refinement level
0).  The same grid design at level k has 2^k times the nodes, nested: every
other node of level k + 1 is a node of level k.  The event is located again at
other levels by carrying the point before it to that level's grid and tracing
a few steps through it (:func:`relocate`), never by tracing the whole curve
again and never across grids of different centres.  The collocation of
eq. (11)-(12) is second order, but with the log-singular kernel on graded
grids its error has an h^2 log h term too: X_k = X + h_k^2 (A + B log h_k) +
...; three levels determine X, A and B, and the distance of that value from
Richardson's (which has no B) is its error bar's scale (:func:`extrapolate`,
calibrated by the coverage study of docs/coverage.md).

"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..core.events import EventFinder, ParameterValue
from ..discretization.preconditioning import memory_available, memory_needed
from ..discretization.resolution import NODES_PER_ZONE, cohesive_zone
from . import energy
from .measured import Measured
from .tracer import carry, contact_radius

__all__ = ["Estimate", "LandingEstimate", "relocate", "extrapolate", "event_errors", "coarse_levels", "LOCAL_STEPS", "BAR_FACTOR", "FLOOR", "COARSE", "MAX_LEVEL", "too_large",
           "energy_levels", "energy_bar_of",
           "ENERGY_BAR_FACTOR"]

#: Steps a local trace may take to pass the event on another level.
LOCAL_STEPS = 40
#: The bar is this times the distance of the three-level value from Richardson's (docs/coverage.md:
#: 234 of 235 quantities covered, median bar about 3 times the true error).
BAR_FACTOR = 2.5
#: ... and at least this times the last refinement's change: the two values can agree by accident
#: (mu = 1, snap-on landing: 3e-9 apart, 2.4e-8 from the truth, after a change of 1e-4).  On the
#: coverage data, 2e-4 starts to miss (4 of 235) and 3e-3 made the snap-on lambda's bars 25 times its
#: error; 6e-4 covers as 3e-3 did with those bars 5 times the error.
FLOOR = 6e-4


@dataclass(frozen=True)
class LandingEstimate:
    """The best values and bars of a fold's landing: its load (with the value on the fold's grid), its
    contact radius and, behind a spring (where the landing moves in lambda), its lambda (else None)."""

    F: Measured
    contact_radius: Measured
    lam: Measured | None = None


@dataclass(frozen=True)
class Estimate:
    """The best values and bars of an event's lambda, F and contact radius from its levels (no grid values:
    the event's own point holds them); behind a spring Z (else None); the ``levels`` used; whether
    -target_error was met; why refinement stopped short (``refinement``, or None); the landing's; and the
    event located on each other level (``located``: (level, point, its landing's point or None), the
    corners of the cycle's loops on that level, :func:`energy_levels`)."""

    lam: Measured
    F: Measured
    contact_radius: Measured
    levels: tuple[int, ...]
    target_met: bool
    Z: Measured | None = None
    refinement: str | None = None
    landing: LandingEstimate | None = None
    located: tuple = ()


def relocate(tracer, seg, found, level: int, target=None):
    """The event ``found`` of segment ``seg`` located on ``seg``'s grid at refinement ``level``.

    Starts from the point before the step that found it (an extremum of F, flat
    about itself, may move on another level by more than a step's part: mu = 3,
    sigma = 0.2, the pull-off moved back past the step's first point), carried
    to that level, and traces with steps no longer than the step that found the
    event until the event's test function changes sign; of several such events,
    the one nearest in lambda.  ``target``: for a landing, the control to find
    (the fold's own at that level: its lambda, or its base position Z behind a
    spring), from the step's first point.  Returns the located point with its
    contact radius on that level's grid among its values (``contact_radius``),
    or None.
    """
    j = found.segment if target is None else found.landing_step
    owner = seg if target is None else next(s for s in tracer.segments if s.finder is found.landing_by)
    a, b = owner.cont.points[j], owner.cont.points[j + 1]
    back = owner.cont.points[j - 1] if target is None and j > 0 else a
    fold = found.event
    event = fold if target is None else ParameterValue(target, "landing", fold.weight, fold.name)
    length = max(b.ds, 1e-3) if b.ds else 0.05
    settings = replace(tracer.set, ds=length / 2, ds_max=length, max_steps=LOCAL_STEPS, max_folds=10**6,
                       monitor=False)
    at = owner.grid.edge if owner.grid is not None else None
    new = tracer.segment(owner.kind, at, level=level, settings=settings,
                         band=owner.grid.band if owner.kind == "scaled" else None, zone=owner.zone)
    try:
        start = _carry_start(owner, new, back)
        if start is None:
            return None
        finder = EventFinder(new.cont, [event], tracer.tol or 1e-10)
        if target is not None and (fold.value(a) - target) * (fold.value(b) - target) > 0 and \
                abs(fold.value(a) - target) > 2 * length:
            return None
        behind = a.ds if back is not a and a.ds else 0.0        # an event found there may be another

        def far(u, v):
            # an event of another label on the way (a jump-off before the jump-in sought) is not the one
            travelled[0] += v.ds
            hit = any(f.label == found.label for f in finder.found) if target is None else bool(finder.found)
            return hit and travelled[0] > behind or travelled[0] > 4 * length + behind

        travelled = [0.0]

        new.cont.run(start, on_step=finder, until=far)
        hits = [f for f in finder.found if f.label == found.label] if target is None else finder.found
        if not hits:
            return None
        pt = min(hits, key=lambda f: abs(f.point.p - found.point.p)).point
        return replace(pt, values={**pt.values, "contact_radius": contact_radius(new.problem, pt.x)})
    finally:
        new.destroy()


def _carry_start(old, new, pt):
    return carry(old, new, pt)


def extrapolate(values: dict) -> tuple[float, float]:
    """(best value, error bar) from values at refinement levels {level: X}, the finest three used.

    With h = 2^-level, X + h^2 (A + B log h) through the three values is the
    best value; the bar is BAR_FACTOR times its distance from Richardson's
    R = X_2 + (X_2 - X_1) / 3 of the finest two, and at least FLOOR |X_2 - X_1|.
    Two levels only: R with the bar |X_2 - X_1|.

    >>> value, bar = extrapolate({k: 1.0 + 4.0**-k for k in (-2, -1, 0)})   # pure h^2: exact, the floor's bar
    >>> round(value, 12), round(bar, 12)
    (1.0, 0.0018)
    """
    ks = sorted(values)[-3:]
    X = [values[k] for k in ks]
    if len(X) == 1:
        return X[0], float("inf")
    R = X[-1] + (X[-1] - X[-2]) / 3
    if len(X) == 2:
        return R, abs(X[1] - X[0])
    h = 2.0 ** -np.array(ks, dtype=float)
    best = np.linalg.solve(np.column_stack([np.ones(3), h**2, h**2 * np.log(h)]), np.array(X))[0]
    return float(best), max(BAR_FACTOR * abs(best - R), FLOOR * abs(X[2] - X[1]))


#: The levels tried first, cheapest first, as far as they resolve the contact edge (:func:`coarse_levels`);
#: refined ones when a coarse level fails or does not resolve, and for -target_error.
COARSE = (-1, -2)
#: The finest level -target_error may reach.
MAX_LEVEL = 4


def coarse_levels(segments) -> tuple:
    """The levels of COARSE whose grids still resolve the cohesive zone in each of ``segments``.

    A grid that follows the edge has its finest spacing h there; level -k has
    2^k h, which must stay below zone / NODES_PER_ZONE, or the coarse levels
    trap the edge and their values are no guide to the error (mu = 7: the best
    value from levels -2, -1, 0 was 60 times further from the truth than the
    grid's own).  Fixed grids are the user's choice: all of COARSE.
    """
    keep = len(COARSE)
    for seg in segments:
        if seg.grid is not None:
            zone = cohesive_zone(seg.problem.model, seg.problem.law) if seg.zone is None else seg.zone
            spare = zone / NODES_PER_ZONE / seg.grid.fine
            if np.isfinite(spare):                  # mu = 0: no edge to resolve
                keep = min(keep, max(0, int(np.floor(np.log2(spare) + 1e-9))))
    return COARSE[:keep]


def too_large(tracer, seg, level: int) -> str | None:
    """Why the grid of ``seg`` at refinement ``level`` cannot be held in memory, or None when it can.

    Its grid has (N - 1) 2^level + 1 nodes for the N of level 0 (nested levels), and
    :func:`~petsc_adhesion.discretization.preconditioning.memory_needed` of them must fit in what the
    machine has left (:func:`~petsc_adhesion.discretization.preconditioning.memory_available`).
    """
    n = (seg.problem.layout.N - 1) * 2 ** (level - tracer.level) + 1
    need = memory_needed(n, getattr(tracer.pmat, "kind", "dense"), True, seg.problem.comm.getSize())
    have = memory_available()
    if need <= have:
        return None
    return f"refinement stopped before level {level}: its {n} nodes need {need / 2**30:.1f} GiB a rank, " \
           f"this machine has {have / 2**30:.1f} GiB available"


def event_errors(tracer, seg, found, target_error: float | None = None) -> Estimate | None:
    """Best values and error bars of one event's lambda, F and contact radius (and its landing's) from its
    levels.

    Levels 0, -1, -2 by default, as far as they resolve the edge (:func:`coarse_levels`), then finer ones;
    where a coarse level does not yield the event, 0,
    1, 2; with ``target_error``, finer levels up to MAX_LEVEL until every bar of lambda and F is
    below it (``target_met`` says whether it was).  Returns the :class:`Estimate`, for a turning point of a
    spring's control with Z, and for a fold with a landing the landing's (behind a spring, whose landing
    moves in lambda, with its lambda); None when no other level yields the event.
    """
    fold = found.event
    spring = bool(getattr(fold, "weight", 0.0))
    points = {0: replace(found.point, values={**found.point.values,
                                              "contact_radius": contact_radius(seg.problem, found.point.x)})}
    landing = {}
    if found.landing is not None:
        land = found.landing
        landing[0] = replace(land, values={**land.values,
                                           "contact_radius": contact_radius(found.landing_by.cont.pb, land.x)})

    def add(level: int) -> bool:
        pt = relocate(tracer, seg, found, level)
        if pt is None:
            return False
        points[level] = pt
        if found.landing is not None:
            landing[level] = relocate(tracer, seg, found, level, target=fold.value(pt))
        return True

    owners = [seg] + [s for s in tracer.segments if found.landing is not None and s.finder is found.landing_by]
    for level in coarse_levels(owners):
        if not add(level):
            break
    while len(points) < 3:
        if not add(max(points) + 1):
            return None

    def series(pts, key):
        return {k: (p.p if key == "lambda" else fold.value(p) if key == "Z" else p.values[key])
                for k, p in pts.items() if p is not None}

    def bars() -> dict[str, Any]:
        out: dict[str, Any] = {key: extrapolate(series(points, key)) for key in ("lambda", "F", "contact_radius")}
        if spring:
            out["Z"] = extrapolate(series(points, "Z"))
        land = {key: series(landing, key) for key in ("lambda", "F", "contact_radius")}
        if found.landing is not None and len(land["F"]) >= 2:
            out["landing"] = {key: extrapolate(v) for key, v in land.items()}
        return out

    def largest(est) -> float:
        """The bar -target_error watches: lambda and F, of the event and its landing."""
        return max([est[k][1] for k in ("lambda", "F")] +
                   ([est["landing"][k][1] for k in ("F", *(("lambda",) if spring else ()))] if "landing" in est else []))

    est, stop = bars(), None
    while target_error and largest(est) > target_error and max(points) < MAX_LEVEL:
        stop = too_large(tracer, seg, max(points) + 1)
        if stop or not add(max(points) + 1):
            break
        est = bars()
    met = not target_error or largest(est) <= target_error
    # the landing's estimate (its points, ``landing`` above, are done with)
    landed = None
    if "landing" in est:
        bar: dict[str, tuple[float, float]] = est["landing"]
        point = found.landing
        assert point is not None, "a landing's bars are of a located landing"
        landed = LandingEstimate(F=Measured(*bar["F"], grid=point.values["F"]),
                                 contact_radius=Measured(*bar["contact_radius"]),
                                 lam=Measured(*bar["lambda"], grid=point.p) if spring else None)
    return Estimate(lam=Measured(*est["lambda"]), F=Measured(*est["F"]), contact_radius=Measured(*est["contact_radius"]),
                    levels=tuple(sorted(points)), target_met=met, Z=Measured(*est["Z"]) if "Z" in est else None,
                    refinement=stop if stop and not met else None, landing=landed,
                    located=tuple((k, points[k], landing.get(k)) for k in sorted(points) if k))


#: The energy's bar is this times the level-0 value's distance from Richardson's value of levels 0 and k
#: (:func:`energy_bar_of`): about 3 times the level-0 error, as the events' grid values' is |X_0 - X_-1| / 3
#: (docs/coverage.md).  Chosen on the first 14 cases with hysteresis at mu <= 2 of docs/coverage.md's energy
#: study, against whole curves traced on levels 0, 1, 2: the three-level extrapolation of levels -2, -1, 0
#: (or -1, 0, 1) put point by point missed 2 (bar / error 0.42, 0.51), this bar none (median 3); the whole
#: study, and where it loses (two levels that agree by accident; the finer level at mu = 3), is there.
ENERGY_BAR_FACTOR = 3.0


def energy_bar_of(levels: dict[int, float]) -> float:
    """The bar of the level-0 energy from {0: E_0, k: E_k} (:func:`energy_levels`): ENERGY_BAR_FACTOR times
    |E_0 - R|, R Richardson's value of the two (an h^2 error: R = (h_k^2 E_0 - h_0^2 E_k) / (h_k^2 - h_0^2),
    h = 2^-level); with k = -1 it is |E_0 - E_-1|, with k = 1 it is 4 |E_1 - E_0|.

    >>> round(energy_bar_of({0: 1.0 + 1e-4, -1: 1.0 + 4e-4}), 12)     # the level-0 error 1e-4: bar 3e-4
    0.0003
    """
    (k, other), = ((k, v) for k, v in levels.items() if k != 0)
    h0, hk = 1.0, 2.0 ** -k
    richardson = (hk**2 * levels[0] - h0**2 * other) / (hk**2 - h0**2)
    return ENERGY_BAR_FACTOR * abs(levels[0] - richardson)


def energy_levels(tracer, loop, fold, estimate_of) -> dict[int, float] | str:
    """The energy of ``loop`` (:func:`~.energy.cycle` under ``fold``'s control) on one other level of its
    grids, as {0: the loop's own, k: its energy on level k}; or why not (collective).

    On level k the loops' borders are the same points put on that level's curve: every computed point and
    every point the quadrature halved at carried to the level's grid of its segment (:func:`~.tracer.carry`,
    a zero-length arclength correction normal to the curve), and the corners (each fold jumped at and its
    landing) located there by the events' error bars (``estimate_of(found)``: the event's :class:`Estimate`,
    its ``located`` points), since a corner carried would slide along its branch off the jump.  The level's
    energy is the loop's plus the change of :func:`~.energy.border_integral` from level 0 to k: the same
    pieces, the same quadrature, so the quadrature's error cancels and the grid's remains.  The level: the
    nearest coarser one on which every jump and landing was located (the events' levels resolve the edge
    there), else the nearest finer one.
    """
    jumps = {id(f): f for f in loop.jumps}
    located = {}
    for f in jumps.values():
        est = estimate_of(f)
        if not isinstance(est, Estimate):
            return f"the {f.label} at lambda = {f.point.p:.6g} has no error estimate"
        located[id(f)] = {k: (pt, land) for k, pt, land in est.located if pt is not None and land is not None}
    shared = sorted(set.intersection(*(set(v) for v in located.values()))) if located else []
    coarser, finer = [k for k in shared if k < 0], [k for k in shared if k > 0]
    if not shared:
        return "the jumps were not located on a common level"
    levels = [coarser[-1] if coarser else finer[0]]
    nodes, inner = loop.nodes, dict(loop.inner)
    on = energy.border(loop)
    own = {(n, m): nodes[n].point if m < 0 else inner[n][m] for n, m in on}
    base = energy.border_integral(loop, own, fold.weight)
    out = {0: float(loop.energy)}
    for level in levels:
        pts: dict[tuple[int, int], Any] = {}
        made: dict[int, Any] = {}

        def on_level(k: int):
            """Segment k's grid on this level (made once)."""
            if k not in made:
                owner = tracer.segments[k]
                made[k] = tracer.segment(
                    owner.kind, owner.grid.edge if owner.grid is not None else None, level=level,
                    settings=replace(tracer.set, monitor=False),
                    band=owner.grid.band if owner.kind == "scaled" else None, zone=owner.zone)
            return made[k]

        try:
            for n, m in on:
                node = nodes[n]
                if m < 0 and node.found is not None and id(node.found) in jumps:
                    pt, land = located[id(node.found)][level]
                    pts[n, m] = land if node.landing else pt
                    continue
                if m < 0 and _handover(nodes, n) and (n - 1, -1) in pts:
                    # the first point of a segment is the previous segment's last carried to its grid, and
                    # that carry slides along the curve by the level's own interpolation error (the step
                    # between grids does no work in the quadrature, energy.py): carried on this level as
                    # the trace did, so that the slide's omitted work is this level's (mu = 5, sigma = 0:
                    # 7.3e-5 on level 0, 1.9e-5 on level 1), not level 0's carried along
                    pt = carry(on_level(nodes[n - 1].seg), on_level(node.seg), pts[n - 1, -1])
                else:
                    pt = carry(tracer.segments[node.seg], on_level(node.seg), own[n, m])
                if pt is None:
                    return f"a point of the loop at lambda = {own[n, m].p:.6g} was not carried to level {level}"
                pts[n, m] = pt
        finally:
            for seg in made.values():
                seg.destroy()
        out[level] = out[0] + energy.border_integral(loop, pts, fold.weight) - base
    return out


def _handover(nodes, n: int) -> bool:
    """Whether node ``n`` is a segment's first computed point after the previous segment's last: the point
    the trace carried from one grid to the next (:class:`~.tracer.Tracer`)."""
    return n > 0 and nodes[n].found is None and nodes[n].seg != nodes[n - 1].seg and nodes[n].key[1:] == (0, 0.0) \
        and nodes[n - 1].found is None
