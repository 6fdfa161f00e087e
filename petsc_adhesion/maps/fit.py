"""A force map fitted: every curve fitted as ``-fit_curve`` fits one, the curves dealt to MPI ranks, the
pixels gathered on rank 0 (docs/maps.md).

The per-curve fit is one call of :func:`~petsc_adhesion.fitting.curve_fit.fit_curve` with the map's options
(whatever it does, a map does: a faster fit makes a faster map).  Each rank fits its curves alone, on
``PETSc.COMM_SELF``, so that a pixel's fit is the same whichever rank fits it and however many there are:
the map of one rank and of N is the same (tests/test_map.py).  The curves still to fit are dealt round by
round, the i-th of a round to rank i mod N (rounds of 1, 2, 4, ... up to ROUND curves a rank); after each round
the ranks' pixels are gathered to rank 0, which hands them to ``record`` (the journal a killed map resumes from)
and ``progress``.  A curve that cannot be fitted
is a flagged pixel (:mod:`~petsc_adhesion.maps.result`), and the map goes on.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..fitting.curve_fit import CurveFitError, OutsideDomain, fit_curve
from ..fitting.data import CurveFileError, MeasuredCurve
from ..fitting.results import FitChoice, Spring
from ..model.parameters import Model
from ..model.physical import Bodies
from .result import MapResult, Pixel, fitted_pixel, flagged_pixel
from .source import MapEntry, MapSource, curves_map

__all__ = ["MapProgress", "fit_map", "fit_pixel", "SOLVER_ERRORS", "ROUND"]

#: The curves a rank fits in a round, at most: rounds of 1, 2, 4, ... up to ROUND a rank.  A round ends with
#: every rank waiting for the slowest (Open MPI's gather polls: the wait costs CPU too), and a curve whose fit
#: traces a new branch costs 10 to 50 times one that finds it; over ROUND curves a rank's traces are spread
#: among the others' fits.  The first rounds are short so that a map journals its first pixels soon.
ROUND = 16


@dataclass(frozen=True)
class MapProgress:
    """How far a map has gone: ``done`` pixels of ``total`` (``resumed`` of them from a journal), the seconds
    ``elapsed`` in this run; the rate and the time left from the pixels this run fitted."""

    done: int
    total: int
    resumed: int
    elapsed: float

    @property
    def rate(self) -> float:
        """Pixels per second fitted in this run (0 before the first)."""
        fitted = self.done - self.resumed
        return fitted / self.elapsed if fitted > 0 and self.elapsed > 0 else 0.0

    @property
    def left_s(self) -> float:
        """Seconds left at the rate so far (inf before the first pixel)."""
        return (self.total - self.done) / self.rate if self.rate > 0 else float("inf")


def _solver_errors() -> tuple:
    from petsc4py import PETSc

    return (ArithmeticError, np.linalg.LinAlgError, RuntimeError, PETSc.Error)


#: What a solver failing on one curve raises (the pixel is flagged ``failed``); anything else is a defect and
#: stops the map.
SOLVER_ERRORS = ("ArithmeticError", "LinAlgError", "RuntimeError", "PETSc.Error")


def fit_pixel(source: MapSource, entry: MapEntry, bodies: Bodies, spring: Spring | None,
              choice: FitChoice, model: Model | None = None, grid=None, solver=None, invols: float | None = None,
              spread_rules: tuple | None = None) -> Pixel:
    """The pixel of one curve of ``source``: read (``invols``: the sensitivity, m/V, of a deflection in
    volts), its force made that of ``spring`` (None: the file's spring constant), fitted on this rank alone."""
    from petsc4py import PETSc

    rough = choice.roughness
    try:
        data = source.curve(entry, spring.k if spring is not None else None, invols)
    except CurveFileError as e:
        return flagged_pixel(entry, "unreadable", str(e), rms_fitted=rough)
    if spring is None:
        if data.spring is None:
            return flagged_pixel(entry, "refused", "the curve states no spring constant (N/m): give -phys_spring",
                                 data, rough)
        spring = Spring(data.spring, "the file")
    elif data.spring is not None and data.spring != spring.k:
        data = data.rescaled(spring.k)          # the file's force is its spring constant times the deflection
    try:
        fit = fit_curve(data, bodies, spring, choice, model=model, grid=grid, solver=solver, comm=PETSc.COMM_SELF,
                        spread_rules=spread_rules)
    except OutsideDomain as e:
        return flagged_pixel(entry, "outside", f"outside the model's domain: {e}", data, rough)
    except CurveFitError as e:
        return flagged_pixel(entry, "refused", str(e), data, rough)
    except _solver_errors() as e:
        why = str(e).strip().splitlines()[0][:160] if str(e).strip() else ""
        return flagged_pixel(entry, "failed", f"the solver failed: {type(e).__name__}: {why}", data, rough)
    return fitted_pixel(entry, fit)


def fit_map(source: MapSource | Sequence[MeasuredCurve], bodies: Bodies, spring: Spring | None = None,
            choice: FitChoice | None = None, model: Model | None = None, grid=None, solver=None, comm=None,
            invols: float | None = None, spread_rules: tuple | None = None, done: Mapping[int, Pixel] | None = None,
            record: Callable[[list], None] | None = None,
            progress: Callable[[MapProgress], None] | None = None) -> MapResult:
    """Fit every curve of a force map (see the module).

    Parameters
    ----------
    source : MapSource or a sequence of MeasuredCurve
        The map (:func:`~petsc_adhesion.maps.source.open_map`), or curves given as values (a row of pixels).
    bodies, choice, model, grid, solver, spread_rules
        As :func:`~petsc_adhesion.fitting.curve_fit.fit_curve`'s, the same for every curve.
    spring : Spring
        The cantilever (a curve's force rescaled to it where its file states another); None: each curve's
        file's spring constant (a curve without one is flagged).
    comm : PETSc communicator
        The ranks the curves are dealt to (default COMM_WORLD).
    invols : float
        The sensitivity (m/V) of curves whose deflection is in volts.
    done : mapping of the curve's index to its Pixel
        Pixels fitted by an earlier run of the same map (its journal): not fitted again.
    record, progress : callables, called on rank 0
        ``record(pixels)`` with each round's new pixels (the journal), ``progress(MapProgress)`` after it.

    Returns the :class:`~petsc_adhesion.maps.result.MapResult`, the same on every rank.
    """
    from petsc4py import PETSc

    t0 = time.perf_counter()
    comm = comm or PETSc.COMM_WORLD
    mpi = comm.tompi4py()
    rank, size = mpi.Get_rank(), mpi.Get_size()
    if not isinstance(source, MapSource):
        source = curves_map(source)
    choice = choice or FitChoice()
    known = dict(done or {})
    pending = [e for e in source.entries if e.index not in known]
    total, resumed = len(source.entries), len(source.entries) - len(pending)
    pixels: dict[int, Pixel] = {i: p for i, p in known.items()}
    start, width = 0, 1
    while start < len(pending):
        block = pending[start:start + width * size]         # this round's curves, the i-th to rank i mod size
        mine = [fit_pixel(source, e, bodies, spring, choice, model, grid, solver, invols, spread_rules)
                for e in block[rank::size]]
        got = mpi.gather(mine, root=0)
        start, width = start + len(block), min(2 * width, ROUND)
        if rank == 0:
            new = [got[i % size][i // size] for i in range(len(block))]      # in the curves' order
            pixels.update((p.entry.index, p) for p in new)
            if record is not None:
                record(new)
            if progress is not None:
                progress(MapProgress(len(pixels), total, resumed, time.perf_counter() - t0))
    ordered = tuple(pixels[e.index] for e in source.entries) if rank == 0 else None
    ordered = mpi.bcast(ordered, root=0)
    return MapResult(source.path, source.kind, source.grid, ordered, choice, bodies, spring, resumed, size,
                     time.perf_counter() - t0)
