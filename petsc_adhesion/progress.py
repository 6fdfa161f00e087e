"""Progress lines of a long run: what it has done, the time elapsed and an estimate of the time left.

    petsc-adhesion: lambda 1.27 of about 4.6, 85 steps, 3 events, 12 s elapsed, about 31 s left

Rank 0 prints them on stderr, at most one every ``interval`` seconds
(:meth:`Progress.update`), or at once (:meth:`Progress.line`).  The caller
says how far along it is as a fraction ``done`` of the whole; the time left is
the elapsed time scaled by what remains, ``elapsed (1 - done) / done``, so it
is as good as that fraction is proportional to the work.

Along a curve (:func:`curve_status`) the fraction is lambda's progress from the
start towards where the curve is expected to stop (:func:`curve_end`): rough,
since the steps crowd where the contact forms and about the turning points
(where lambda turns back and the fraction stands still), and JKR's stop misses
a rough surface's; the estimate of the time left is a guide to its order of
magnitude, too low on the approach and steadier past the snap-on.
"""
from __future__ import annotations

import math
import sys
import time

from scipy.optimize import brentq

from .errors import say
from .reference import jkr_approach, jkr_load

__all__ = ["Progress", "clock", "curve_end", "curve_status", "INTERVAL"]

#: Least seconds between two progress lines by default.
INTERVAL = 5.0


def clock(seconds: float) -> str:
    """A duration for a progress line: ``0.4 s``, ``12 s``, ``2.5 min``, ``1.3 h``.

    >>> clock(0.43), clock(12.4), clock(150.0), clock(4680.0)
    ('0.4 s', '12 s', '2.5 min', '1.3 h')
    """
    if not math.isfinite(seconds):
        return "?"
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 100:
        return f"{seconds:.0f} s"
    if seconds < 3600:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def _rank(comm) -> int:
    """The rank in ``comm``: a PETSc or an mpi4py communicator."""
    return comm.getRank() if hasattr(comm, "getRank") else comm.Get_rank()


class Progress:
    """One-line progress reports on rank 0 of ``comm`` (PETSc or mpi4py), when ``enabled``.

    Not collective: each rank decides alone, and only rank 0 prints.  The clock
    starts at construction.
    """

    def __init__(self, comm, enabled: bool, interval: float = INTERVAL, stream=sys.stderr):
        self.enabled = bool(enabled) and _rank(comm) == 0
        self.interval, self.stream = interval, stream
        self.t0 = self.last = time.perf_counter()

    def reset(self) -> None:
        """Start the clock again: a new stage of the work, whose fraction done starts from 0."""
        self.t0 = time.perf_counter()

    def due(self) -> bool:
        """Whether :meth:`update` would print now (so that the caller need not say what it has done else)."""
        return self.enabled and time.perf_counter() - self.last >= self.interval

    def update(self, done: float, text: str) -> None:
        """Print ``text`` with the times if ``interval`` seconds have passed since the last line (or the start).

        ``done``: the fraction of the work done, in [0, 1]; no estimate of the time left while it is 0.
        """
        if self.due():
            self.line(text, done)

    def line(self, text: str, done: float = 0.0) -> None:
        """Print ``text`` with the times now, whatever the interval."""
        if not self.enabled:
            return
        now = time.perf_counter()
        self.last = now
        elapsed = now - self.t0
        done = min(max(done, 0.0), 1.0)
        left = f", about {clock(elapsed * (1.0 - done) / done)} left" if done > 0 else ""
        say(f"{text}, {clock(elapsed)} elapsed{left}", self.stream)


def curve_end(model, settings) -> float:
    """Where a curve is expected to stop in lambda: ``settings.p_max`` (-cont_lambda_max), or sooner
    where JKR's load (Johnson, Kendall & Roberts 1971) on its stable branch reaches the stop load
    ``settings.observable_max`` (-cont_F_max; at JKR's pull-off when that is below it); 0 for a rigid
    sphere (mu = 0), whose load rises steeply at contact."""
    end = 0.0
    if model.mu > 0 and math.isfinite(settings.observable_max):
        pull = (9.0 * math.pi / 8.0) ** (1.0 / 3.0) * math.sqrt(model.mu)     # JKR's least load
        hi = 2.0 * pull
        while jkr_load(hi, model.mu) < settings.observable_max:
            hi *= 2.0
        A = pull if settings.observable_max <= jkr_load(pull, model.mu) else \
            brentq(lambda a: jkr_load(a, model.mu) - settings.observable_max, pull, hi)
        end = float(jkr_approach(A, model.mu))
    return min(end, settings.p_max)


def curve_status(tracer, lam0: float, end: float) -> tuple[float, str]:
    """(fraction done, text) of a curve being traced from ``lam0`` towards ``end`` (:func:`curve_end`):
    the furthest lambda reached, the steps and the events so far."""
    segments = tracer.segments
    reached = max(p.p for seg in segments for p in seg.cont.points)
    steps = sum(len(seg.cont.points) - 1 for seg in segments)
    events = sum(len(seg.finder.found) for seg in segments)
    done = (reached - lam0) / (end - lam0) if end > lam0 else 0.0
    return min(max(done, 0.0), 0.99), (f"lambda {reached:.4g} (the curve should stop near {end:.3g}), "
                                       f"{steps} steps, {events} event{'s' * (events != 1)}")
