"""What a traced load-approach curve means for adhesion: its events by name, the pull-off, warnings, the report.

The continuation core finds folds, extrema and zeros; here they get their
physical names:

=============  ======================  =============================================
kind           core event              meaning
=============  ======================  =============================================
snap_on        fold, lambda largest    jump-in on approach (displacement control)
snap_off       fold, lambda smallest   jump-out on retraction
jump_in        fold of Z, Z largest    behind a spring of stiffness K, Z = lambda + F / K: jump-in
jump_off       fold of Z, Z smallest   ... and jump-off (K -> 0: the pull-off; K -> inf: snap_on, snap_off)
F_min, F_max   extremum of F           the most tensile F_min is the load-controlled pull-off
equilibrium    F = 0                   zero load
lambda         lambda = target         state asked for by -cont_at_lambda
=============  ======================  =============================================

Under displacement control a point is stable when lambdadot > 0; a fold's
landing is the state on the other stable branch at the same lambda after the
jump (Figs. 6, 7).  Behind a spring (an AFM cantilever, its base at Z) a point
is stable when dZ/ds > 0, and a jump lands at the same Z.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from mpi4py import MPI

from ..core.events import Extremum, Fold, ParameterValue, Zero
from ..discretization import grid
from ..model.reference.rigid import far_deflection, load_beyond
from . import energy, error_bars
from .curve import Assessment, Branch, Cycle, Event, Landing, Profile
from .measured import Measured, Missing
from .edge_grids import EDGE_SHARE, PEAK_ATTRACTION
from .tracer import contact_radius

__all__ = ["curve_events", "spring_fold", "curve", "Traced", "stop_reason", "assess", "WALL_GAP", "event_of",
           "NO_BAR", "unclosed", "QUADRATURE_MARGIN", "quadrature_error", "EDGE_SHARE", "PEAK_ATTRACTION"]

#: Closer than this to the wall of the roughness rule, a state is set by its smallest weights.
WALL_GAP = 1e-3


def curve_events(at_lambda=(), spring: float | None = None) -> list:
    """The events of a load-approach curve, in the order they are tested at every step; with a ``spring``
    of stiffness K (units 2 pi R gamma / epsilon), the turning points of its base Z = lambda + F / K too."""
    return [Fold(("snap_on", "snap_off")), Extremum("F", ("F_min", "F_max")), Zero("F", "equilibrium"),
            *(ParameterValue(t, "lambda") for t in at_lambda),
            *([Fold(("jump_in", "jump_off"), 1.0 / spring, "F")] if spring else [])]


def spring_fold(events) -> Fold | None:
    """The turning points of a spring's base among ``events`` (None without a spring)."""
    return next((e for e in events if isinstance(e, Fold) and e.weight), None)


def _H0(problem, pt) -> float:
    """H at r = 0, on every rank (collective)."""
    return problem.comm.tompi4py().bcast(float(pt.x[0]) if problem.lo == 0 else None, root=0)


def _whole(problem, local: np.ndarray):
    """The whole nodal vector on rank 0 (None elsewhere); collective."""
    parts = problem.comm.tompi4py().gather(local, root=0)
    return np.concatenate(parts) if parts is not None else None


@dataclass(frozen=True)
class _State:
    lam: float
    F: float
    H0: float
    contact_radius: float
    Z: float | None
    profile: Profile | None


def _measured(value: float | None) -> Measured | None:
    """A state's Z as an event holds it: None where the state has none (no spring)."""
    return None if value is None else Measured(value)


def _state(problem, pt, profiles: bool, spring=None) -> _State:
    """The state of a point on the grid it was located on (collective: H0 and the profiles gather)."""
    profile = None
    if profiles:
        r = problem.nodes(pt.x)
        H = _whole(problem, problem.separation(pt.x))
        if H is not None:
            profile = Profile(r, H, problem.law(H)[0])
    return _State(pt.p, pt.values["F"], _H0(problem, pt), contact_radius(problem, pt.x),
                  None if spring is None else spring.value(pt), profile)


#: Why an event has no bar when its error estimate was tried and failed.
NO_BAR = "no error bar: the event was not found again on the coarser and finer levels"


def event_of(problem, found, estimate, profiles: bool) -> Event:
    """One event as a value (collective: H0 and profiles gather).

    ``estimate``: its :class:`~.error_bars.Estimate`, a :class:`~.measured.Missing` when one was tried and
    failed, or None when none was asked for.  With an estimate, lambda and F are the best values with their
    bars and the values on the grid it was located on.  A lambda asked for is exact, so is F = 0 at an
    equilibrium.  The half-infinite model adds the rigid sphere's attraction beyond r_m to F
    (``F_beyond``); its remainder, the deflection that attraction causes inside, enters both bars
    (:func:`~petsc_adhesion.model.reference.far_deflection`).
    """
    spring = found.event if isinstance(found.event, Fold) and found.event.weight else None
    at = _state(problem, found.point, profiles, spring)
    stable = None if isinstance(found.event, Fold) else bool(problem.stable(found.point))
    landing = None                               # at a fold of its control the state is marginal: None
    if found.landing is not None:
        ld = _state(found.landing_by.cont.pb, found.landing, profiles, spring)
        landing = Landing(lam=Measured(ld.lam), F=Measured(ld.F), H0=ld.H0,
                          Z=_measured(ld.Z),
                          contact_radius=Measured(ld.contact_radius), profile=ld.profile)
    ev = Event(kind=found.label, lam=Measured(at.lam), F=Measured(at.F), H0=at.H0,
               Z=_measured(at.Z), contact_radius=Measured(at.contact_radius),
               stable=stable, landing=landing, profile=at.profile)
    if estimate is None:
        return ev
    if isinstance(estimate, Missing):
        return replace(ev, note=estimate.reason)
    est, model = estimate, problem.model
    rm = float(problem.nodes(found.point.x)[-1])
    far = far_deflection(rm, model.coupling) if model.farfield else 0.0
    beyond = far + quadrature_error(problem, found.point)
    if found.label == "lambda":
        lam, F = Measured(at.lam, 0.0, at.lam), Measured(est.F.value, est.F.err + beyond, at.F)
    elif found.label == "equilibrium":
        lam, F = Measured(est.lam.value, est.lam.err + beyond, at.lam), Measured(0.0, 0.0, at.F)
    else:
        lam, F = Measured(est.lam.value, est.lam.err + beyond, at.lam), Measured(est.F.value, est.F.err + beyond, at.F)
    Z: Measured | None = None
    if spring is not None:
        assert est.Z is not None, "an estimate behind a spring holds Z's"
        Z = Measured(est.Z.value, est.Z.err + beyond * (1 + spring.weight), at.Z)
    if landing is not None and est.landing is not None:
        land = est.landing
        landing = replace(landing, lam=Measured(lam.value), F=Measured(land.F.value, land.F.err + beyond, land.F.grid),
                          contact_radius=Measured(land.contact_radius.value, land.contact_radius.err))
        if Z is not None:                   # the same Z; lambda moves by the spring's extension (behind a spring)
            landing = replace(landing, lam=Measured(land.lam.value, land.lam.err + beyond, land.lam.grid),
                              Z=Measured(Z.value, Z.err))
    return replace(ev, lam=lam, F=F, Z=Z, landing=landing, levels=tuple(est.levels), target_met=est.target_met,
                   F_beyond=float(load_beyond(rm, at.lam)) if model.farfield else 0.0,
                   contact_radius=Measured(est.contact_radius.value, est.contact_radius.err, at.contact_radius),
                   refinement_note=est.refinement)


#: The load of the quadrature error, times this, bounds its effect on results (tests/test_roughness_models.py).
QUADRATURE_MARGIN = 3.0


def quadrature_error(problem, pt) -> float:
    """The part of an event's error bars due to the roughness quadrature (collective).

    The load of the pressure's quadrature error e(r) = |P - P_ref| at the event's
    state, (8/3) integral e r dr (eq. 26), is the first-order change of F at fixed
    H; the elastic response and, at a fold, the conversion into lambda change it
    by a factor of order one, which QUADRATURE_MARGIN covers (measured: bars 1.2 to
    20 times the error at 3 and 6 points, up to 1000 at 12, where both are tiny).
    Zero for the smooth law, the Hermite rule (which is the model) and a histogram
    (exact but for rounding).
    """
    H = _whole(problem, problem.separation(pt.x))
    r = problem.nodes(pt.x)
    load = 0.0 if H is None else 8.0 / 3.0 * float(grid.load_weights(r) @ problem.law.error(H))
    return QUADRATURE_MARGIN * problem.comm.tompi4py().bcast(load)


def stop_reason(stop, settings) -> str:
    """Why the continuation stopped, in the options' words."""
    reason, value = stop
    if reason == "ds_min":
        where = "a turning point (natural continuation cannot pass it)" \
            if settings.corrector == "natural" else "a point it cannot pass"
        return f"step below -cont_ds_min at lambda = {value:.6g}: {where}"
    # the load that stopped the curve named as the user gave it: -cont_F_max, or an instrument's trigger
    label = settings.observable_max_label
    at = f"{label} (F = {settings.observable_max:.4g})" if label else f"-cont_F_max {settings.observable_max:g}"
    return {"observable_max": f"load F = {value:.4g} >= {at}",
            "p_max": f"approach lambda = {value:.4g} >= -cont_lambda_max {settings.p_max:g}",
            "p_min": f"approach lambda = {value:.4g} <= {settings.p_min:g}",
            "max_steps": f"-cont_max_steps {value} reached",
            "max_folds": f"more than -cont_max_folds {value} turning points",
            "domain_end": f"the contact reaches the end of the truncated model's domain r_m at lambda = "
                          f"{value:.6g}"}[reason]


def _current(segments, seg) -> list:
    """``seg``'s points but, when another segment follows, its last: that is the next one's first,
    solved again on the grid the curve moved to, and the two differ by the grids' errors."""
    return seg.cont.points if seg is segments[-1] else seg.cont.points[:-1]


@dataclass(frozen=True)
class Traced:
    """What the traced segments hold, as values: the branch, the events (each with the core's ``Found`` it
    was made from, in the order found), the pull-off, the cycles of a rigid machine and (None without one)
    of a spring, the statistics of the steps, why it stopped, the least gap to the wall of the roughness
    rule, the profiles of every point (rank 0, for the resolution check) and the grids of the segments."""

    branch: Branch
    found: tuple
    events: tuple[Event, ...]
    pull_off: Event | None
    rigid: Cycle
    spring: Cycle | None
    wall_gap: float
    steps: int
    rejected_steps: int
    folds: int
    regrids: int
    guard_activations: int
    smallest_step: float
    most_newton_its: int
    most_ksp_its: int
    stop: tuple
    stop_reason: str
    states: tuple
    r: np.ndarray
    starts: np.ndarray
    n_nodes: np.ndarray
    edges: np.ndarray | None


def unclosed(segments, reason: str) -> str | None:
    """Why the cycle of a traced curve was not closed, or None when it was.

    A cycle is closed when the curve was traced through: from the far branch (not starting in contact) to
    the compressive branch (F >= 0 at its end) that lies past every turning point (adhesion pulls: the
    jumps and the pull-off lie at tensile loads), and not cut short (-cont_max_steps, a step too small,
    too many turning points).  Else its energy would be that of part of the curve (-cont_F_max below the
    pull-off: 0 from the far branch alone).
    """
    first, last = segments[0].cont.points[0], segments[-1].cont.points[-1]
    stop = segments[-1].cont.stop
    if stop[0] in ("ds_min", "max_steps", "max_folds"):
        return f"the cycle was not closed: the curve ended early ({reason})"
    if first.values["F"] > 0:
        return f"the cycle was not closed: the curve starts in contact (F = {first.values['F']:.4g} > 0)"
    if last.values["F"] < 0:
        return (f"the cycle was not closed: the curve stopped in tension (F = {last.values['F']:.4g} at lambda = "
                f"{last.p:.6g}; {reason}) before it was traced through its turning points to compression")
    return None


def _cycle(segments, fold, event_of_found, open_reason: str | None, levels=None) -> Cycle:
    """The cycle under ``fold``'s control: its energy and bar, or Missing with why (collective).

    ``levels(loop)``: the loop's energy on the nested levels ({level: energy}, :func:`~.error_bars.energy_levels`)
    or why not; None when the error bars were not asked for."""
    K = 1.0 / fold.weight if fold.weight else None
    if open_reason is not None:
        return Cycle(Missing(open_reason), None, K)
    loop = energy.cycle(segments, fold)
    if loop.energy is None:
        assert loop.note is not None, "a cycle not walked says why"
        return Cycle(Missing(loop.note), None, K)
    return Cycle(_energy(loop, fold, event_of_found, levels), loop.loops, K)


def _energy(loop, fold, event_of_found, levels) -> Measured:
    """The energy of a walked cycle with its bar (collective).

    The value is the curve's own (level 0: the integral of the branch the files hold).  Its bar: the loop
    computed whole on one other level of its grids (:func:`~.error_bars.energy_levels`), three times the
    level-0 value's distance from Richardson's value of the two (:func:`~.error_bars.energy_bar_of`), plus
    the quadrature's estimate; the errors of the jumps and of the borders cancel within each level's loop,
    which this credits (docs/coverage.md).  Where the level cannot be had (a jump not located on it, a point
    not carried), the bound of :func:`~.energy.energy_bar` (sums of the events' errors), with a note saying
    so.  0 without hysteresis: both walks cover the same stretch, a computed 0."""
    if not loop.pieces:
        return Measured(loop.energy, 0.0)
    got = levels(loop) if levels is not None else None
    if isinstance(got, dict):
        return Measured(loop.energy, error_bars.energy_bar_of(got) + loop.quadrature_err)
    bound = energy.energy_bar(loop, fold, event_of_found)
    note = None if got is None or bound is None else f"bar bounded by the events' errors ({got})"
    return Measured(loop.energy, bound, note=note)


#: The energy of a cycle not asked for (:class:`~.trace.CurveRequest` ``cycles`` False).
NO_CYCLE = "not computed: the curve was traced without its cycles' energies (CurveRequest cycles False)"


def curve(segments, estimates: dict, profiles: bool = False, tracer=None, cycles: bool = True,
          kept=None) -> Traced:
    """The traced curve (its segments, in order) as values: its branch, its events with their bars
    (``estimates``: the :class:`~.error_bars.Estimate` of each located event by ``id`` of its ``Found``,
    Missing where it failed; none asked for: absent), the pull-off, its cycles (``tracer``: the one that
    traced the segments, for the energy's levels; None, or no estimates: the energy's bar from the events').

    Collective.  ``profiles`` (rank 0, else empty): the nodes and the pressure of
    every point, for the resolution check.  Without ``cycles`` each cycle's energy is Missing (NO_CYCLE), and
    the events whose kind ``kept(kind)`` refuses are not made into values (the cycles' bars were all that
    read them): a fit's branch, read behind springs, needs neither (at mu = 10 the cycle's energy alone took
    a tenth of the branch's CPU).
    """
    found = [(seg, f) for seg in segments for f in seg.finder.found]
    if not cycles and kept is not None:
        found = [(seg, f) for seg, f in found if kept(f.label)]
    events = [event_of(seg.problem, f, estimates.get(id(f)), profiles) for seg, f in found]
    pts = [p for seg in segments for p in seg.cont.points]
    radii = [contact_radius(seg.problem, p.x) for seg in segments for p in seg.cont.points]
    by_found = {id(f): e for (_, f), e in zip(found, events)}
    last = segments[-1].cont
    why = unclosed(segments, stop_reason(last.stop, last.set))
    cycles_ = {}
    for fold in (e for e in segments[0].finder.events if isinstance(e, Fold)):
        levels = None if tracer is None or not estimates else \
            (lambda loop, fold=fold: error_bars.energy_levels(tracer, loop, fold, lambda f: estimates.get(id(f))))
        cycle = _cycle(segments, fold, lambda f: by_found[id(f)], why, levels) if cycles else \
            Cycle(Missing(NO_CYCLE), None, 1.0 / fold.weight if fold.weight else None)
        cycles_["spring" if fold.weight else "rigid"] = cycle
    states = []
    for seg in segments:
        pb = seg.problem
        for p in _current(segments, seg):
            r, H = pb.nodes(p.x), _whole(pb, pb.separation(p.x))
            if H is not None:
                states.append((r, H, pb.law(H)[0]))
    mins = [e for e in events if e.kind == "F_min"]
    lowest = min(float(seg.problem.separation(p.x).min()) for seg in segments for p in seg.cont.points)
    spring = cycles_.get("spring")
    return Traced(
        branch=Branch.from_points(pts, radii, None if spring is None else spring.K),
        found=tuple(f for _, f in found), events=tuple(events),
        pull_off=min(mins, key=lambda e: e.F.value) if mins else None, rigid=cycles_["rigid"], spring=spring,
        wall_gap=segments[-1].problem.comm.tompi4py().allreduce(lowest, op=MPI.MIN) - segments[-1].problem.law.wall,
        steps=sum(len(seg.cont.points) - 1 for seg in segments),
        rejected_steps=sum(seg.cont.rejected for seg in segments),
        folds=sum(seg.cont.folds for seg in segments),
        regrids=len(segments) - 1 - sum(seg.far for seg in segments),
        guard_activations=sum(seg.problem.guarded for seg in segments),
        smallest_step=min((p.ds for p in pts if p.ds > 0), default=0.0),
        most_newton_its=max(p.newton_its for p in pts), most_ksp_its=max(p.ksp_its for p in pts),
        stop=last.stop, stop_reason=stop_reason(last.stop, last.set), states=tuple(states),
        r=segments[-1].problem.nodes(segments[-1].cont.points[-1].x),
        starts=np.array([seg.cont.points[0].p for seg in segments]),
        n_nodes=np.array([seg.problem.layout.N for seg in segments]),
        edges=np.array([seg.grid.edge for seg in segments]) if all(seg.grid is not None for seg in segments)
        else None)




def _missed_minimum(segments) -> str:
    """Why the located pull-off may not be the most tensile load of the curve, or "".

    A discrete minimum F[k-1] > F[k] < F[k+1] of a grid segment, more tensile than
    every located minimum, must lie next to a located minimum (on step k-1 or k)
    no higher than itself; a step that passes a shallow minimum and maximum of
    the load elsewhere (a wiggle of the unstable branch) does not matter here.
    Within one grid: the grids of two segments differ by their discretization errors.
    """
    found = [(seg, f) for seg in segments for f in seg.finder.found if f.label == "F_min"]
    pull_off = min((f.point.values["F"] for _, f in found), default=math.inf)
    for seg in segments:
        F = [p.values["F"] for p in _current(segments, seg)]
        located = {f.segment: f.point.values["F"] for s, f in found if s is seg}
        for k in range(1, len(F) - 1):
            if not F[k - 1] > F[k] < F[k + 1] or F[k] >= pull_off:
                continue
            near = [located[j] for j in (k - 1, k) if j in located]
            if not near:
                return f"a computed point (F = {F[k]:.6g}) is a load minimum more tensile than the located " \
                       f"pull-off ({pull_off:.6g})"
            if min(near) > F[k] + 1e-9:
                return f"a computed point (F = {F[k]:.6g}) is more tensile than the load minimum located " \
                       f"next to it ({min(near):.6g})"
    return ""


def assess(segments, res: Traced, grid_warning: str | None, at_lambda=()) -> Assessment:
    """What makes a traced curve untrustworthy, one line each: its warnings, the subset that makes it
    not what was asked for (exit status 3), and ``grid_warning`` (the resolution check's).  Collective."""
    warn, short = [], []
    problem = segments[-1].problem
    pts = [p for seg in segments for p in seg.cont.points]
    law, gap, mpi = problem.law, res.wall_gap, problem.comm.tompi4py()
    if law.rule == "hermite" and gap < WALL_GAP:
        warn.append(f"the curve comes within {gap:.1e} of the wall H = {law.wall:.6g} of the {law.n}-point "
                    f"Hermite rule, where node weights down to {law.weights.min():.1e} set the repulsion: "
                    f"the loads there are properties of the rule and ill-conditioned; use fewer points")
    if res.stop[0] in ("ds_min", "max_steps", "max_folds"):
        short.append(f"the curve ended early: {res.stop_reason}")
    if grid_warning:
        short.append(grid_warning)
    missed_min = "" if grid_warning else _missed_minimum(segments)
    if missed_min:
        short.append(f"{missed_min}: the load varies faster than the steps resolve; lower -cont_dF_max or -cont_ds_max")
    if pts[0].values["F"] > 0:
        short.append(f"the curve starts in contact (F = {pts[0].values['F']:.3g} > 0 at lambda = {pts[0].p:g}): "
                     f"the approach and its events lie before it; give -cont_lambda_start further apart")
    missed = [e for e in res.events if e.target_met is False]
    if missed:
        e = max(missed, key=lambda e: max(e.lam.err or 0, e.F.err or 0))
        note = next((f"; {m.refinement_note}" for m in missed if m.refinement_note), "")
        short.append(f"-target_error not reached for {len(missed)} event(s): {e.kind} at lambda = {e.lam.value:.6g} "
                     f"has lambda +- {e.lam.err or 0:.1e}, F +- {e.F.err or 0:.1e} on levels up to "
                     f"{max(e.levels)}, the finest tried{note}")
    spring = spring_fold(segments[0].finder.events)
    start = next(seg for seg in segments if not seg.far).cont.points[0]
    if spring is not None and not spring.stable(start):
        short.append(f"the curve starts where the spring (K = {1 / spring.weight:.4g}) cannot hold the sphere "
                     f"(dZ/ds < 0 at lambda = {start.p:.6g}): its jump-in lies before the start; give "
                     f"-cont_lambda_start further apart, or leave it to the default")
    found = [e.lam.value for e in res.events if e.kind == "lambda"]
    for t in at_lambda:
        if not any(abs(x - t) <= 1e-9 * max(1.0, abs(t)) for x in found):
            short.append(f"-cont_at_lambda {t:g} not reached: the curve spans lambda in "
                         f"[{min(p.p for p in pts):.4g}, {max(p.p for p in pts):.4g}]")
    rm = float(problem.nodes(pts[-1].x)[-1])         # in the frame of the edge r_m moves with the contact radius
    if res.stop[0] == "domain_end":
        # the truncated model ends at r_m: its curve stopped there, every event before it whole; the load
        # asked for lies beyond the model's domain, not the grid's
        end = pts[-1]
        short.append(f"the curve ends at F = {end.values['F']:.4g} (lambda = {end.p:.6g}), short of -cont_F_max "
                     f"{segments[-1].cont.set.observable_max:g}: there the contact reaches the end of the truncated "
                     f"model's domain r_m = {rm:g}, beyond which it does not hold (its events before it are whole): "
                     f"give a larger -adh_rmax, or -cont_F_max up to {end.values['F']:.3g}")
        return Assessment(tuple(warn + short), tuple(short), grid_warning or None)
    edge = 0.0
    for seg in segments:
        last = seg.problem.hi == seg.problem.layout.N
        for p in seg.cont.points:
            H = seg.problem.separation(p.x)           # collective in the frame of the edge: on every rank
            if last:
                edge = max(edge, abs(float(law(H[-1:])[0][0])))
    edge = mpi.allreduce(edge, op=MPI.MAX)
    if edge > EDGE_SHARE * PEAK_ATTRACTION:
        short.append(f"the contact reaches the end of the domain r_m = {rm:g} (|P(r_m)| up to "
                     f"{edge:.2g}): give a larger -adh_rmax")
    return Assessment(tuple(warn + short), tuple(short), grid_warning or None)


