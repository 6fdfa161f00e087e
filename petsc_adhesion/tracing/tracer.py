"""The load-approach curve on grids that follow the contact edge (the default grid).

At large mu the cohesive zone at the contact edge is about 0.75 mu^-1.5 wide
and needs several nodes across it, but only where the edge is, and the edge
travels from r = 0 outward along the curve (to about 2.4 mu^0.5 at zero
load, further under compression).  The curve is traced in segments, each on
one grid, of two kinds:

* ``edge``: the physical frame, an :class:`~petsc_adhesion.discretization.grid.EdgeGrid`
  centred on the edge (fine, zone / NODES_PER_ZONE and at most
  CONTACT_SPACING, within a band of it (BAND, or BAND_ZONES zones); graded beyond; geometric out to RMAX,
  where the attraction left out carries |F| < 1e-8).  A new segment when the
  edge has travelled more than ``travel`` from the grid's centre.
* ``scaled``: once a sharp edge (zone / NODES_PER_ZONE < CONTACT_SPACING)
  has formed a contact of radius A_SWITCH (or A_SWITCH_ZONES zones when fewer),
  the frame of the edge (:mod:`petsc_adhesion.discretization.edge_frame`): the grid in rho = r/a
  follows the contact radius a by itself, and a new segment is needed only
  when a has changed by the factor GROW.

A point is carried to the next segment's grid by interpolating its
deformation H - r^2/2 and a zero-length arclength correction there (regular
at folds).  Events are located within a segment, on one discrete problem,
never across a change of grid: a change waits while any event's test
function has a different sign on the two grids at the carried point (it is
close to an event), unless the old grid no longer resolves the edge.
"""
from __future__ import annotations

import math
from typing import Any
from dataclasses import dataclass, replace

import numpy as np
from mpi4py import MPI

from ..core.continuation import Continuation, Settings
from ..core.newton import PetscSettings
from ..core.events import EVENT_TOL, EventFinder
from ..core.protocol import Point, TracedProblem
from ..discretization import grid
from ..discretization.contact import contact_radius, crossing
from ..discretization.edge_frame import EdgeFrameProblem
from ..discretization.influence import create_influence
from ..discretization.problem import Problem
from ..discretization.resolution import zone_of
from .edge_grids import (
    EDGE_SHARE,
    PEAK_ATTRACTION,
    a_switch,
    band,
    GROW,
    REACH,
    RMAX,
    _zone,
    grid_for,
    scaled_band,
    scaled_grid_for,
    frame_of_edge,
)

__all__ = ["edge_of", "state_zone", "contact_radius", "crossing", "Segment", "Tracer", "carry", "FAR_STEPS"]


def edge_of(problem, x: np.ndarray) -> float:
    """The contact edge of a state: the radius of peak attraction (most negative P); collective."""
    pressure, _ = problem.law(problem.separation(x))
    k = int(np.argmin(pressure))
    best = (float(pressure[k]), float(problem.nodes(x)[problem.lo + k]))
    return problem.comm.tompi4py().allreduce(best, op=MPI.MIN)[1]


def state_zone(problem, x: np.ndarray) -> float:
    """The cohesive zone the grid for the state x must resolve
    (:func:`~petsc_adhesion.discretization.resolution.zone_of`); collective."""
    pressure, _ = problem.law(problem.separation(x))
    return zone_of(problem.model, problem.law, problem.nodes(x), problem.gather(pressure))


@dataclass(frozen=True)
class Segment:
    """A stretch of the curve on one grid: its problem, continuation and events."""

    kind: str             # "fixed", "edge" or "scaled"
    grid: grid.EdgeGrid | None  # the EdgeGrid (None for a fixed grid)
    problem: TracedProblem
    cont: Continuation
    finder: EventFinder
    far: bool = False     # the far branch traced back from the start (Tracer.extend_back)
    zone: float | None = None   # the cohesive zone its grid resolves (None: the model's, _zone)

    def destroy(self) -> None:
        """Free the segment's PETSc objects."""
        self.cont.destroy()
        self.problem.destroy()


def carry(old: Segment, new: Segment, pt, scale: float | None = None):
    """The point ``pt`` of ``old``'s curve put on ``new``'s: interpolated, then a zero-length arclength
    correction there (regular at folds), its tangent oriented like pt's; None when that fails.

    ``scale``: the contact radius to start from in the frame of the edge (default: pt's own,
    or where its H rises through the edge level).
    """
    dst = new.problem
    shaped, slope = dst.carry(old.problem, pt, scale)      # each problem knows its own unknowns
    x = dst.create_vec()
    x.setArray(shaped)
    out = new.cont.project(x, pt.p, slope, pt.pdot)
    x.destroy()
    return out


class _Regrid:
    """The ``until`` criterion of a segment: the edge has travelled; the next segment, ready."""

    def __init__(self, tracer, seg: Segment):
        self.tracer, self.seg = tracer, seg
        self.next: tuple[Segment, Point] | None = None
        zone = _zone(seg.problem.model)
        half = band(seg.problem.model)
        self.travel = min(half / 2 + zone, REACH / 3)
        self.forced = min(half + 2 * zone, 2 * REACH / 3)

    def target(self, b) -> tuple | None:
        """(kind, where, forced) of the next segment, or None to stay."""
        seg, tr = self.seg, self.tracer
        assert seg.grid is not None, "a segment that regrids follows the edge on an EdgeGrid"
        edge = edge_of(seg.problem, b.x)
        if seg.kind == "scaled":
            a = seg.problem.radius(b.x)
            ratio = a / seg.grid.edge
            return None if 1 / GROW <= ratio <= GROW else ("scaled", a, not 1 / GROW**2 <= ratio <= GROW**2, edge)
        # a contact, and the peak attraction off the centre (a rough centre may still attract most); the
        # contact radius only where the scaled frame can take over (it is a cubic root search at every step)
        if tr.sharp:
            a = contact_radius(seg.problem, b.x)
            if min(edge, a) >= a_switch(seg.problem.model):
                return "scaled", a, False, edge
        moved = abs(edge - seg.grid.edge)
        return None if moved <= self.travel else ("edge", edge, moved > self.forced, edge)

    def __call__(self, a, b) -> bool:
        where = self.target(b)
        if where is None:
            return False
        kind, at, forced, peak = where
        band = zone = None
        if kind == "scaled":
            zone = state_zone(self.seg.problem, b.x)
            band = scaled_band(self.seg.problem.model, at, peak, zone)
        new = self.tracer.segment(kind, at, self.seg, band=band, zone=zone)
        try:
            pt = carry(self.seg, new, b, at if kind == "scaled" else None)
        except BaseException:           # a failed carry: the new segment is no one's
            new.destroy()
            raise
        same = pt is not None and all(np.sign(ev.test(b)) == np.sign(ev.test(pt)) != 0
                                      for ev in self.tracer.events)
        if same or (pt is not None and forced):
            self.next = (new, pt)
            return True
        new.destroy()
        if forced:
            raise RuntimeError(f"cannot carry the curve to a new grid at lambda = {b.p:.6g}")
        return False


def at_domain_end(problem, x: np.ndarray) -> bool:
    """Whether the contact of a physical-frame state x reaches the end of its domain r_m: |P(r_m)| above
    EDGE_SHARE of the peak attraction (collective: the last node lies on the last rank)."""
    local = 0.0
    if problem.hi == problem.layout.N:
        local = abs(float(problem.law(problem.separation(x)[-1:])[0][0]))
    return problem.comm.tompi4py().allreduce(local, op=MPI.MAX) > EDGE_SHARE * PEAK_ATTRACTION


#: Steps at most of the far branch traced back from the start (:meth:`Tracer.extend_back`); its steps grow
#: by the continuation's factor 1.5 a step, so 200 reach lambda = -1e15 from a step of 0.05.
FAR_STEPS = 200


class Tracer:
    """Trace a curve in segments: on a fixed grid (one segment), or on grids that follow the edge."""

    def __init__(self, model, settings: Settings, events, tol=None, nodes=None, pmat=None, level: int = 0,
                 rmax: float = RMAX, comm=None, natural: PetscSettings = PetscSettings(),
                 arclength: PetscSettings = PetscSettings()):
        """``nodes``: a fixed grid, or None for grids following the edge at refinement ``level`` out to
        ``rmax``; ``pmat``: the preconditioning strategy of every segment's problem; ``comm``: the
        communicator of every segment (PETSc.COMM_WORLD by default); ``natural``, ``arclength``: the
        PETSc settings of every segment's correctors."""
        self.model, self.set, self.events, self.tol, self.comm = model, settings, list(events), tol, comm
        self.natural, self.arclength = natural, arclength
        self.nodes, self.pmat, self.level, self.rmax = nodes, pmat, level, rmax
        self.segments: list[Segment] = []
        self.sharp: bool | None = None

    def segment(self, kind: str, at: float | None = None, before: Segment | None = None,
                level: int | None = None, settings: Settings | None = None, band: float | None = None,
                zone: float | None = None, far: bool = False) -> Segment:
        """A segment of ``kind`` (fixed, edge, scaled) centred on ``at`` at refinement ``level`` (default:
        the tracer's), continuing ``before``'s budget, or with ``settings`` of its own; ``band``: the
        fine band of a scaled segment (:func:`scaled_band`), ``zone`` the cohesive zone its grid resolves
        (:func:`state_zone`; None: the model's); ``far``: the far branch (:meth:`extend_back`)."""
        level = self.level if level is None else level
        if kind == "fixed":
            nodes = grid.nested(self.nodes, level - self.level)
            problem: TracedProblem = Problem(self.model, nodes, create_influence(nodes, self.comm), self.pmat)
            design = None
        elif kind == "edge":
            assert at is not None, "an edge segment is centred on a given edge"
            design = grid_for(self.model, at, level, self.rmax)
            r = design.nodes()
            problem = Problem(self.model, r, create_influence(r, self.comm), self.pmat)
        else:
            assert at is not None, "a scaled segment is centred on a given contact radius"
            design = scaled_grid_for(self.model, at, level, self.rmax, band, zone)
            rho = design.nodes() / at
            problem = EdgeFrameProblem(self.model, rho, create_influence(rho, self.comm), at, self.pmat)
        s = settings or self.set
        if kind == "scaled" and s.unit > 1:
            # a soft sphere's curve in the frame of its edge is smooth on the scale of mu, its Newton
            # iterations set by the cohesive zone's: the quadratic predictor takes steps 2-3x as long
            s = replace(s, predictor="quadratic")
        if before is not None:
            steps = sum(len(g.cont.points) - 1 for g in self.segments)
            folds = sum(g.cont.folds for g in self.segments)
            s = replace(s, ds=before.cont.ds, max_steps=max(1, s.max_steps - steps),
                        max_folds=s.max_folds - folds)
        try:                    # a solver option refused: the problem's shell holds a cycle that gc cannot free
            cont = Continuation(problem, s, index0=sum(len(g.cont.points) for g in self.segments) if before else 0,
                                natural=self.natural, arclength=self.arclength)
        except BaseException:
            problem.destroy()
            raise
        # events located to tol in units of the curve's size (lambda grows like mu towards the JKR end)
        tol = (self.tol or EVENT_TOL) * s.unit
        return Segment(kind, design, problem, cont, EventFinder(cont, self.events, tol), far=far,
                       zone=zone if kind == "scaled" else None)

    def run(self, lam0: float, started=None, pause=None) -> list[Segment]:
        """The curve from lam0, starting from the rigid state (eq. 27); ``started()`` after the first point.

        A tracer whose segments were restored from a checkpoint (:mod:`petsc_adhesion.app.checkpoint`)
        goes on from its last segment's state instead.  ``pause(tracer)``: before every step
        attempt (:meth:`~petsc_adhesion.core.continuation.Continuation.run`).
        """
        self.sharp = self.nodes is None and frame_of_edge(self.model)
        start = None
        if not self.segments:
            seg = self.segment("fixed" if self.nodes is not None else "edge", 0.0)
            self.segments.append(seg)
            # the first segment is on a fixed or an edge grid, a physical-frame problem with the rigid state
            # (eq. 27); the tracer asks it by that method, not by its class
            first: Any = seg.problem
            x = first.rigid(lam0, first.create_vec())
            try:
                start = seg.cont.start(x, lam0)
            except RuntimeError as e:
                raise RuntimeError(f"{e}; give -cont_lambda_start further apart") from None
            finally:
                x.destroy()
        seg = self.segments[-1]
        if started:
            started()
        hook = (lambda: pause(self)) if pause else None
        # the truncated model (no far field) ends at r_m: where its contact gets there the model no longer
        # holds, and its curve stops (the half-infinite model goes on: beyond r_m the far field is added)
        truncated = not self.model.farfield
        while True:
            regrid = _Regrid(self, seg) if seg.kind != "fixed" else None
            ended = [False]

            def until(a, b, seg=seg, regrid=regrid, ended=ended) -> bool:
                if truncated and at_domain_end(seg.problem, b.x):
                    ended[0] = True
                    return True
                return regrid is not None and regrid(a, b)

            if start is None:
                seg.cont.resume(on_step=seg.finder, until=until, pause=hook)
            else:
                seg.cont.run(start, on_step=seg.finder, until=until, pause=hook)
            if ended[0]:
                seg.cont.name_stop("domain_end", seg.cont.points[-1].p)
                return self.segments
            if regrid is None or regrid.next is None:
                return self.segments
            seg, start = regrid.next
            self.segments.append(seg)

    def extend_back(self, p_min: float) -> Segment | None:
        """The curve before its start, down to the approach ``p_min``, as a new first segment (collective).

        Behind a soft spring the jump off the contact lands far out, where the sphere
        is nearly rigid and the load falls like lambda^-2: the far branch is traced
        backward from the first point on the first segment's grid, with steps that
        grow without bound (:data:`FAR_STEPS` at most), and put in front of the curve in
        its order (tangents reversed).  None when the first point is already there.
        """
        first = self.segments[0]
        a = first.cont.points[0]
        if a.p <= p_min:
            return None
        settings = replace(self.set, ds=self.set.ds, ds_max=1e15, p_min=p_min, p_max=math.inf,
                           observable_max=math.inf, max_steps=FAR_STEPS, max_folds=0, monitor=False)
        seg = self.segment(first.kind, first.grid.edge if first.grid is not None else None, settings=settings,
                           far=True)
        try:
            x = seg.problem.create_vec()
            x.setArray(a.x)
            try:
                start = seg.cont.start(x, a.p, direction=-1)
            finally:
                x.destroy()
            seg.cont.run(start)
        except BaseException:
            seg.destroy()
            raise
        stop = seg.cont.stop
        assert stop is not None, "a run ends with its reason"
        if stop[0] != "p_min":
            seg.destroy()
            raise RuntimeError(f"the far branch could not be traced back to lambda = {p_min:.6g} "
                               f"({stop[0]} at lambda = {seg.cont.points[-1].p:.6g})")
        # in the curve's order; "far" marks its steps so that an event search on one takes its distance
        # along the tangent of the point before it (Continuation.turn_around)
        seg.cont.turn_around("far")
        self.segments.insert(0, seg)
        return seg

    def state(self, solvers: bool = True) -> dict:
        """The curve traced so far as plain data, local parts of its vectors included (a checkpoint saves it):
        every segment's kind, the grid it was made for, its continuation (with ``solvers``: what its
        solvers keep of their preconditioners) and the events found on it (their error bars once
        computed).  :meth:`restore` on a tracer made alike goes on as this one would."""
        index = {id(seg.finder): k for k, seg in enumerate(self.segments)}
        return {"segments": [{"kind": seg.kind, "at": seg.grid.edge if seg.grid is not None else None,
                              "band": seg.grid.band if seg.kind == "scaled" and seg.grid is not None else None,
                              "zone": seg.zone,
                              "N": seg.problem.layout.N,
                              "guarded": seg.problem.guarded, "far": seg.far,
                              "continuation": seg.cont.state(solvers),
                              "events": seg.finder.state(lambda f: index[id(f)])} for seg in self.segments]}

    def restore(self, state: dict) -> None:
        """Rebuild the segments of :meth:`state` (collective).  ValueError when a segment's grid has not the
        number of nodes it had (another version of the grids), or for a state that is not a curve's."""
        for k, st in enumerate(state["segments"]):
            cont = st["continuation"]
            settings = Settings.from_state({**cont["settings"], "monitor": self.set.monitor})
            if st["kind"] != ("fixed" if self.nodes is not None else st["kind"]) or \
                    st["kind"] not in ("fixed", "edge", "scaled") or k == 0 and st["kind"] == "scaled":
                raise ValueError(f"segment {k + 1} of a kind this run does not make ({st['kind']!r})")
            where = [st["at"]] + ([st["band"]] if st["kind"] == "scaled" else [])
            if st["kind"] != "fixed" and not all(isinstance(v, (int, float)) and math.isfinite(v) and v >= 0
                                                 for v in where) or st["kind"] == "scaled" and not where[0] > 0:
                raise ValueError(f"segment {k + 1} on a grid centred nowhere ({st['at']!r})")
            if not (isinstance(st["guarded"], int) and st["guarded"] >= 0 and isinstance(st["N"], int)):
                raise ValueError(f"segment {k + 1}'s counters are not counts")
            zone = st.get("zone")
            if zone is not None and not (isinstance(zone, float) and math.isfinite(zone) and zone > 0):
                raise ValueError(f"segment {k + 1} resolves a cohesive zone of {zone!r}")
            seg = self.segment(st["kind"], st["at"], settings=settings, band=st["band"], zone=zone,
                               far=st.get("far", False) is True)
            self.segments.append(seg)
            if seg.problem.layout.N != st["N"]:
                raise ValueError(f"a segment {k + 1} of {st['N']} nodes, where this version makes {seg.problem.layout.N}")
            seg.problem.restore_counters(st["guarded"])
            if not isinstance(st.get("far", False), bool) or st.get("far") and (k > 0 or st["kind"] == "scaled"):
                raise ValueError(f"segment {k + 1} marked as the far branch where none can be")
            seg.cont.restore(cont)
        for seg, st in zip(self.segments, state["segments"]):
            seg.finder.restore(st["events"], lambda k: self.segments[k].finder)

    def destroy(self) -> None:
        """Free every segment's PETSc objects."""
        for seg in self.segments:
            seg.destroy()
        self.segments = []
