"""Progress lines of a long run: what it has done, the time elapsed and an estimate of the time left.

    petsc-adhesion: lambda 1.27 of about 4.6, 85 steps, 3 events, 12 s elapsed, about 31 s left

Rank 0 prints them on stderr, at most one every ``interval`` seconds
(:meth:`Progress.update`), or at once (:meth:`Progress.line`).  The caller
says how far along it is as a fraction ``done`` of the whole; the time left is
the elapsed time scaled by what remains, ``elapsed (1 - done) / done``, so it
is as good as that fraction is proportional to the work.

Along a curve the fraction is the library's
(:func:`~petsc_adhesion.tracing.trace.expected_end`).
"""
from __future__ import annotations

import math
import sys
import time

from ..errors import say

__all__ = ["Progress", "clock", "INTERVAL"]

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
