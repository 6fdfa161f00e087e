"""Work-precision: the error of each result against the wall time it took, per method.

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks -bench_only workprecision
    ./run bench -bench_workprecision          # after the default parts

writes docs/performance.md, and docs/figures/wp_<case>.png with wp_<case>.md (the
table behind each figure), in the manner of DiffEqDevTools' work-precision sets:
log10 error against log10 median wall time, one marked line per method.

* Cases (:data:`CASES`): mu = 1 smooth, mu = 2 with sigma = 0.2, mu = 5 smooth.
* Quantities (:data:`QUANTITIES`): the pull-off F and lambda (most tensile load),
  the primary turning points' lambda (snap-on: the fold of largest lambda, snap-off:
  of smallest), the equilibrium lambda (F = 0).
* Truth: the default grid (edge grid, r_m = 150, far field added) refined by
  ``-target_error`` :data:`TRUTH_TOL`, extrapolated; its own bars are reported.
* Methods: the paper grid (N = 531, r_m = 10, far-field load added; grid value and
  extrapolated), uniform grids on [0, 10] (N = 101 .. 4001, grid values), the
  default edge grid (grid value and extrapolated), ``-target_error`` 1e-3 .. 1e-8,
  the preconditioning choices on the edge grid (dense LU, band AIJ + LU, block
  Jacobi with 4 LU blocks through the solvers' option prefixes, none), a plain
  numpy/scipy implementation (:func:`numpy_curve`, mu = 1, paper grid) and the
  stored ContactMechanics + Adhesion runs (mu = 1, docs/data/peer_contactmechanics.json).
* Speed: the mu = 1 default curve with and without bars, the whole process,
  the pull-off to 1e-6 and 1e-8, against the issue's targets; where the curve's time
  goes (:func:`profile`: cProfile's own time of every function, summed by where it runs).
* Scaling: a fixed-approach solve and continuation steps on uniform grids
  N = 100 .. 8000, 1 and 2 ranks, dense and band, each in its own process
  (``python -m petsc_adhesion.benchmarks.workprecision scale N PMAT STEPS``), with its peak
  resident memory (getrusage ru_maxrss).

Times are medians of repeats (:data:`REPEATS`, one run where a single run exceeds
:data:`SLOW` seconds), each a fresh call of :func:`petsc_adhesion.app.run.trace`
(influence matrices and solvers made inside, as the program makes them).
"""
from __future__ import annotations

import json
import os
import tempfile
import time

from .accuracy import CASES, REPEATS, SCALE_N, measure
from .render import machine, write_docs
from .speed import profile, scaling, speed, startup

__all__ = ["run", "DUMP"]


#: where :func:`run` keeps its measurements (``python -m petsc_adhesion.benchmarks.workprecision docs PATH`` re-renders)
DUMP = os.path.join(tempfile.gettempdir(), "petsc-adhesion-workprecision.json")


def run(quick: bool = False, write: bool = True, log=print, dump: str | None = DUMP) -> dict:
    """The whole work-precision benchmark; writes the documents (``write``) and returns the speed rows
    in the format of :func:`petsc_adhesion.benchmarks.row`."""
    t0 = time.perf_counter()
    load0 = os.getloadavg()
    cases = [measure(c, quick, log) for c in CASES]
    rows = speed(quick, log)
    prof = profile(log)
    start = startup(1 if quick else REPEATS)
    scale = scaling((100, 200, 500) if quick else SCALE_N, quick, log)
    data = {"machine": machine(), "load_before": load0, "load_after": os.getloadavg(),
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "total_s": time.perf_counter() - t0,
            "quick": quick, "cases": cases, "speed": rows, "profile": prof, "startup": start, "scaling": scale}
    if dump:
        with open(dump, "w") as f:
            json.dump(data, f)
        log(f"[workprecision] measurements kept in {dump}")
    if write:
        write_docs(data)
    return rows
