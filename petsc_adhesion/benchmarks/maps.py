"""The speed of a force map's fit (docs/maps.md): a synthetic map made by the solver with noise, fitted over
the ranks it runs on.

    python -m petsc_adhesion.benchmarks.maps 4                     # a 4x4 map on one rank
    mpiexec -n 2 python -m petsc_adhesion.benchmarks.maps 4        # on two
    mpiexec -n 2 python -m petsc_adhesion.benchmarks.maps 64       # a 64x64 map (4,096 curves)

The map: a 20 nm tip on four materials in quadrants (w 0.04 and 0.06 J/m^2, mu 0.1 and 0.15 by eq. 9: where
one fit is fastest), 1% noise of 2 pi R w, 100 points a leg, each pixel's noise its own; every curve fitted
from one start (E* 30 GPa) as ``-fit_map`` fits it.  Printed and written to docs/data/maps_N.json (with the
ranks): the wall time, the CPU time of each rank, pixels per second, the time a pixel, and how many pixels'
95% intervals of w and E* cover their truth; a map of up to 16 x 16 is drawn into docs/figures/map_NxN.png.
"""
from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np

__all__ = ["run", "main", "R", "EPS", "MATERIALS"]

R, EPS, K_SPRING = 20e-9, 0.3e-9, 1.0
#: (w J/m^2, mu) of the map's four quadrants.
MATERIALS = ((0.04, 0.1), (0.06, 0.1), (0.04, 0.15), (0.06, 0.15))


def _bodies(w: float, mu: float):
    from petsc_adhesion.model.physical import Bodies

    return Bodies(radius=R, young1=w * math.sqrt(R / (mu**3 * EPS**3)), poisson1=0.0, epsilon=EPS, gamma=w)


def run(n: int) -> dict:
    """Make and fit the n x n map on the ranks of COMM_WORLD; its figures (on every rank)."""
    from petsc4py import PETSc

    from petsc_adhesion.fitting.results import Spring
    from petsc_adhesion.fitting.synthetic import Sampling
    from petsc_adhesion.maps.fit import fit_map
    from petsc_adhesion.maps.synthetic import synthetic_map
    from petsc_adhesion.model.physical import Bodies

    def truth(ix: int, iy: int):
        return _bodies(*MATERIALS[(2 * iy >= n) * 2 + (2 * ix >= n)])

    spring = Spring(K_SPRING)
    t0, c0 = time.perf_counter(), time.process_time()
    m = synthetic_map((n, n), truth, spring, Sampling(noise=0.01 * 2 * math.pi * R * 0.05, points=100, z0=5e-9))
    made = time.perf_counter() - t0
    t1, c1 = time.perf_counter(), time.process_time()
    shown = [0]

    def say(pr) -> None:            # rank 0's line every 256 pixels: a map stopped part way still measured
        if pr.done // 256 > shown[0] or pr.done == pr.total:
            shown[0] = pr.done // 256
            print(f"{pr.done} of {pr.total} pixels, {pr.elapsed:.0f} s wall, rank 0 CPU "
                  f"{time.process_time() - c1:.1f} s, load {os.getloadavg()[0]:.1f}", flush=True)

    # each fit's CPU, timed from outside the library (the map's own fit_curve wrapped for this run alone)
    from petsc_adhesion.maps import fit as map_fit

    own = map_fit.fit_curve
    fits: list = []

    def timed(*args, **kwargs):
        c = time.process_time()
        f = own(*args, **kwargs)
        fits.append((time.process_time() - c, f.traces))
        return f

    map_fit.fit_curve = timed
    try:
        r = fit_map(m, Bodies(radius=R, young1=30e9, poisson1=0.0, epsilon=EPS), spring, progress=say)
    finally:
        map_fit.fit_curve = own
    wall, cpu = time.perf_counter() - t1, time.process_time() - c1
    comm = PETSc.COMM_WORLD.tompi4py()
    cpus = comm.gather(cpu, root=0)
    every = comm.allgather(fits)
    each = np.array([c for part in every for c, _ in part])
    traced = np.array([t > 0 for part in every for _, t in part])
    covered = {"gamma": 0, "E_star": 0}
    for p in r.pixels:
        t = truth(p.entry.ix, p.entry.iy)
        covered["gamma"] += bool(p.fitted and p.gamma and p.gamma.covers(t.gamma, 1.96))
        covered["E_star"] += bool(p.fitted and p.E_star and p.E_star.covers(t.E, 1.96))
    if PETSc.COMM_WORLD.getRank() == 0 and n <= 16:         # the docs' figure of the map (docs/maps.md)
        from petsc_adhesion.io.map import map_tree
        from petsc_adhesion.io.plot.map import map_figure

        from . import paths

        os.makedirs(paths.FIGURES, exist_ok=True)
        map_figure(map_tree(r, {"benchmark": f"maps {n}"}, {}), os.path.join(paths.FIGURES, f"map_{n}x{n}.png"))
    return {"n": n, "pixels": n * n, "ranks": r.ranks, "make_s": made, "wall_s": wall, "cpu_s_by_rank": cpus,
            "pixels_per_s": n * n / wall, "cpu_s_per_pixel": None if cpus is None else sum(cpus) / (n * n),
            "ok": r.count("ok"), "flagged": n * n - r.count("ok"), "covered_95": covered,
            # each pixel not ok with why: its place, its status and its reasons (a map's flag is its own account)
            "flagged_pixels": [{"ix": p.entry.ix, "iy": p.entry.iy, "status": p.status, "reasons": list(p.reasons)}
                               for p in r.pixels if p.status != "ok"],
            "solver_curves_traced": sum(p.traces for p in r.pixels),
            "fit_cpu_s_median": float(np.median(each)) if each.size else None,
            "fit_cpu_s_median_found": float(np.median(each[~traced])) if (~traced).any() else None,
            "fits_that_traced": int(traced.sum()), "their_cpu_s": float(each[traced].sum()),
            "fits_cpu_s": float(each.sum()),
            "load_average": os.getloadavg()[0], "setup_cpu_s": c1 - c0}


def main(argv=None) -> int:
    from petsc4py import PETSc

    argv = sys.argv[1:] if argv is None else argv
    n = int(argv[0]) if argv else 4
    out = run(n)
    if PETSc.COMM_WORLD.getRank() == 0:
        from . import paths

        print(f"map {n}x{n} on {out['ranks']} rank(s): {out['wall_s']:.1f} s wall, "
              f"{out['pixels_per_s']:.3g} pixels/s, {out['cpu_s_per_pixel']:.2f} CPU s a pixel; "
              f"{out['ok']} ok, {out['flagged']} flagged; 95% intervals cover w in {out['covered_95']['gamma']}, "
              f"E* in {out['covered_95']['E_star']} of {n * n}; {out['solver_curves_traced']} solver curves traced "
              f"by {out['fits_that_traced']} fits ({out['their_cpu_s']:.1f} CPU s of the fits' "
              f"{out['fits_cpu_s']:.1f}); a fit's median {out['fit_cpu_s_median'] or math.nan:.3f} CPU s, "
              f"{out['fit_cpu_s_median_found'] or math.nan:.3f} where it found its branch; "
              f"load average {out['load_average']:.1f}")
        os.makedirs(paths.DATA, exist_ok=True)
        with open(os.path.join(paths.DATA, f"maps_{n}_np{out['ranks']}.json"), "w") as f:
            json.dump({**out, "source": paths.source()}, f, indent=1)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
