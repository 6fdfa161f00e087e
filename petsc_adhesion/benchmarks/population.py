"""A particle population's speed by each evaluator, and how much its pull-offs depend on the footprint's size
(docs/population.md).

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.population speed [--solver 20] [--table 10000]
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.population zone [--count 10]

On the repository's AFM image (tests/data/wsxm-afm-topography.top) with silica on a rigid
flat (E 70 GPa, nu 0.17, w 0.05 J/m^2, epsilon 0.4 nm), radii lognormal about 10 um
(geometric standard deviation 1.3).

``speed``: particles per CPU second (``time.process_time``, this process; under
``mpiexec`` each rank's summed) through the solver (the measured law, the footprint
iterated, error bars on), with each particle's energy of a cycle and without it
(``--flat``: soft particles, E 7 GPa, mu about 2, on a flat of the image's pixels, where
every cycle has hysteresis and its folds are located on nested grids for the energy's
bar; on the image the footprints' tall features hold the particles off and no cycle
has any), and through the table (the Gaussian rule at the footprint's
rms).  The table is the family's ``PullOffTable`` where it is installed; where it is not,
a PullOffModel made here for the timing alone: the solver's Gaussian rule at nodes of
(ln mu, sigma) over the particles' range, interpolated bilinearly (its nodes' cost
reported apart, not in the particles').  A table's lookup is a vectorized interpolation
either way, so the particles' time is the population's own work: draws, footprints,
their planes and moments, the statistics.

``zone``: for ``--count`` particles at their sites and the contact radius of their
solve, the pull-off with the footprint holding 95 % of the rigid sphere's attraction
(the default) against 99 %: the relative change says how much the heights beyond the
zone move the answer.

A benchmark is a measurement, not a test: the machine's load is printed with it.
"""
from __future__ import annotations

import argparse
import os
import time
from collections import Counter

import numpy as np

from ..model.physical import Bodies
from ..model.topography import read_topography
from ..population.compute import population
from ..population.evaluate import GaussianRule, SolverEvaluator, TableMissing, Trace, load_table
from ..population.footprint import footprint, footprint_radius
from ..population.sample import RadiusLaw
from .paths import ROOT

AFM = os.path.join("tests", "data", "wsxm-afm-topography.top")
BODIES = Bodies(radius=10e-6, young1=7e10, poisson1=0.17, gamma=0.05, epsilon=4e-10)
LAW = RadiusLaw(median=10e-6, spread=1.3)
#: Soft particles on a flat: mu about 2 at 10 um, where a smooth sphere's cycle under a
#: rigid machine has hysteresis.
SOFT = Bodies(radius=10e-6, young1=7e9, poisson1=0.0, gamma=0.05, epsilon=4e-10)


def flat_like(topo):
    """A flat of ``topo``'s pixels and size (its heights 0; moments of a flat: none)."""
    from ..model.topography import Moment, Statistics, Topography

    z = np.zeros_like(topo.heights)
    stats = Statistics(Moment(0.0, 0.0), Moment(float("nan"), None), Moment(float("nan"), None),
                       (float("nan"), float("nan")), (float(z.size),) * 3, 0.0, 0.0, "flat")
    return Topography(z, topo.pixel_size, "flat", "m", "option", "none", stats)


class NodeTable:
    """The solver's Gaussian rule at nodes of (ln mu, sigma), interpolated bilinearly: a PullOffModel for the
    timing where the family's table is not installed (its bar: the nodes' largest solver bar)."""

    def __init__(self, mu_range, sigma_range, n_mu=3, n_sigma=6):
        self.mu = np.geomspace(*mu_range, n_mu)
        self.sigma = np.linspace(*sigma_range, n_sigma)
        M, S = np.meshgrid(self.mu, self.sigma, indexing="ij")
        F, err = GaussianRule().pull_off(M.ravel(), S.ravel())
        self.F, self.err = F.reshape(M.shape), float(np.nanmax(err))

    def covers(self, mu, sigma):
        mu, sigma = np.asarray(mu), np.asarray(sigma)
        return (mu >= self.mu[0]) & (mu <= self.mu[-1]) & (sigma >= self.sigma[0]) & (sigma <= self.sigma[-1])

    def pull_off(self, mu, sigma):
        x = np.interp(np.log(mu), np.log(self.mu), np.arange(self.mu.size))
        y = np.interp(sigma, self.sigma, np.arange(self.sigma.size))
        i = np.clip(x.astype(int), 0, self.mu.size - 2)
        j = np.clip(y.astype(int), 0, self.sigma.size - 2)
        tx, ty = x - i, y - j
        F = ((1 - tx) * (1 - ty) * self.F[i, j] + tx * (1 - ty) * self.F[i + 1, j] + (1 - tx) * ty * self.F[i, j + 1]
             + tx * ty * self.F[i + 1, j + 1])
        return F, np.full(np.shape(F), self.err)


def _load() -> str:
    try:
        return f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores"
    except OSError:
        return "load unknown"


def speed(n_solver: int, n_table: int, seed: int = 1, flat: bool = False) -> None:
    topo = read_topography(os.path.join(ROOT, AFM))
    bodies = BODIES
    if flat:
        topo, bodies = flat_like(topo), SOFT
        print(f"soft particles (E 7 GPa) on a flat of {topo.heights.shape[0]} x {topo.heights.shape[1]} pixels")
    for energy in (True, False):
        t = time.process_time()
        r = population(topo, bodies, LAW, n_solver, seed, "solver", spread_count=0, trace=Trace(energy=energy))
        cpu = time.process_time() - t
        passes = [p.passes for p in r.particles]
        works = r.works
        what = (f"{works.size} energies of a cycle, {int(np.sum(works == 0))} of them 0" if energy else
                "without the energy of a cycle")
        print(f"solver ({what}): {n_solver} particles in {cpu:.1f} s CPU ({r.cpu_time:.1f} s over {r.ranks} "
              f"rank(s)): {n_solver / r.cpu_time:.3g} particles per CPU second; solves per particle "
              f"{np.mean(passes):.2f} (median pull-off {np.median(r.forces) * 1e9:.4g} nN); {_load()}")
    try:
        table, what, nodes = load_table(), "the family's PullOffTable", 0.0
    except TableMissing:
        mus = [p.mu for p in r.particles]
        sig = [p.sigma for p in r.particles if p.sigma is not None]
        t = time.process_time()
        table = NodeTable((min(mus) * 0.7, max(mus) * 1.4), (0.5 * min(sig), 1.5 * max(sig)))
        what, nodes = "nodes of the solver's rule (no PullOffTable installed)", time.process_time() - t
    t = time.process_time()
    r = population(topo, bodies, LAW, n_table, seed, "table", table, spread_count=0)
    cpu = time.process_time() - t
    print(f"table ({what}{f', its nodes {nodes:.1f} s CPU apart' if nodes else ''}): {n_table} particles in "
          f"{cpu:.1f} s CPU ({r.cpu_time:.1f} s over {r.ranks} rank(s)): {n_table / r.cpu_time:.4g} particles per "
          f"CPU second; {len(r.missing)} missing; {_load()}")
    for reason, n in Counter(p.pull_off.reason for p in r.missing).most_common(3):
        print(f"  missing ({n}): {reason}")
    sig = np.array([p.sigma for p in r.particles if p.sigma is not None])
    if sig.size:
        q = np.percentile(sig, [0, 16, 50, 84, 100])
        print(f"  local sigma {q[0]:.3g} to {q[4]:.3g} (median {q[2]:.3g}, 16-84 %: {q[1]:.3g} to {q[3]:.3g})")
    if hasattr(r.fit, "median"):
        print(f"  lognormal of |F|: median {r.fit.median.value * 1e9:.4g} +- {r.fit.median.err * 1e9:.2g} nN, gsd "
              f"{r.fit.gsd.value:.4g} +- {r.fit.gsd.err:.2g} ({r.fit.count} pull-offs)")


def zone(count: int, seed: int = 1) -> None:
    topo = read_topography(os.path.join(ROOT, AFM))
    r = population(topo, BODIES, LAW, count, seed, "solver", spread_count=0)
    ev = SolverEvaluator()
    eps = BODIES.epsilon
    for p in r.particles:
        if p.footprint_radius is None or not p.pull_off:
            continue
        a = np.sqrt(max(p.footprint_radius ** 2 / (p.radius * eps) - footprint_radius(0.0, 1.0, 1.0) ** 2, 0.0))
        wide = footprint(topo, p.site, footprint_radius(a, p.radius, eps, share=0.99), eps, clip=True)
        F99 = ev.measured(p.mu, wide.heights, energy=False).F
        print(f"particle {p.index}: R {p.radius * 1e6:.3g} um, footprint 95 % {p.footprint_radius * 1e9:.0f} nm "
              f"({p.pixels} pixels) F {p.pull_off.value:.6g}; 99 % {wide.radius * 1e9:.0f} nm ({wide.pixels} "
              f"pixels) F {F99.value:.6g}: relative change {(F99.value - p.pull_off.value) / abs(p.pull_off.value):+.3g}")
    print(_load())


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(prog="python -m petsc_adhesion.benchmarks.population", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    s = sub.add_parser("speed")
    s.add_argument("--solver", type=int, default=20)
    s.add_argument("--table", type=int, default=10000)
    s.add_argument("--flat", action="store_true")
    z = sub.add_parser("zone")
    z.add_argument("--count", type=int, default=10)
    args = ap.parse_args(argv)
    if args.what == "speed":
        speed(args.solver, args.table, flat=args.flat)
    else:
        zone(args.count)


if __name__ == "__main__":
    main()
