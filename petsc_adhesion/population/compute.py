"""The pull-offs of a particle population on a measured topography, spread over MPI ranks.

    import petsc_adhesion as pa
    from petsc_adhesion.model.topography import read_topography
    from petsc_adhesion.population.sample import RadiusLaw
    topo = read_topography("tests/data/wsxm-afm-topography.top")
    bodies = pa.Bodies(radius=10e-6, young1=7e10, poisson1=0.17, gamma=0.05, epsilon=4e-10)
    result = pa.particle_population(topo, bodies, RadiusLaw(median=10e-6, spread=1.3), count=200, seed=1)
    print(result.fit.median.value, "+-", result.fit.median.err, "N")

Particle i (its radius and site drawn from the seed by its index, sample.py) is
evaluated on rank i mod (ranks): the same particles and the same values whatever the
rank count; the results are gathered to every rank.  Each particle's Tabor parameter
is that of the ``bodies`` at its radius (eq. 9), its roughness its footprint's heights
(footprint.py), its pull-off by the evaluator asked for (evaluate.py), and with the
solver the energy its cycle dissipates under a rigid machine (the curve traced just past
the pull-off closes that cycle); the lognormal of the positive energies beside the
pull-off forces'.  The model
spread: the first ``spread_count`` particles with a footprint evaluated under both the
measured law (the solver) and the Gaussian rule at their rms (the table where it is
given, else the solver's rule), on the same footprints.
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..tracing.measured import Measured, Missing
from .evaluate import EVALUATORS, Evaluator, GaussianRule, PullOffModel, SolverEvaluator, TableEvaluator, Trace
from .footprint import MIN_PIXELS, ZONE_SHARE
from .results import BOOTSTRAP, Particle, PopulationResult, SpreadSample, energy_fit, lognormal_fit, radius_bins
from .sample import RadiusLaw, draw

__all__ = ["population", "MAX_COUNT", "SPREAD_COUNT"]

#: The most particles of one population.
MAX_COUNT = 10**6
#: Particles of the model spread's subsample, by default.
SPREAD_COUNT = 50


def _check(topography, bodies, law, count: int, evaluator: str) -> None:
    if evaluator not in EVALUATORS:
        raise ValueError(f"evaluator: one of {', '.join(EVALUATORS)}, got {evaluator!r}")
    if not isinstance(law, RadiusLaw):
        raise ValueError(f"law: expected a RadiusLaw, got {type(law).__name__}")
    if law.listed and count != len(law.radii):
        raise ValueError(f"count: {count}, but the list gives {len(law.radii)} radii")
    if not 1 <= count <= MAX_COUNT:
        raise ValueError(f"count: expected 1 to {MAX_COUNT} particles, got {count}")
    if topography.kind != "map" or topography.pixel_size is None:
        raise ValueError(f"{topography.path}: a population lands on a map with its lateral size; this is "
                         f"{'a profile' if topography.kind != 'map' else 'a map of no stated size'}")
    if bodies.young1 is None:
        raise ValueError("bodies: the moduli are needed for mu (eq. 9)")


def _particle(d, mu: float, unit: float, ev, epsilon: float) -> Particle:
    """The particle of draw ``d`` from its evaluation ``ev``; ``unit`` 2 pi R w (N), its energy's unit that
    times ``epsilon`` (J)."""
    fp, F, passes, note = ev.footprint, ev.pull_off, ev.passes, ev.note
    if fp is None:
        return Particle(d.index, d.radius, None, mu, None, 0, 0.0, None, None, None, F, unit, ev.energy,
                        unit * epsilon, passes, note)
    rms = fp.rms if fp.pixels else None
    note = note or (fp.note if isinstance(F, Measured) else "")
    return Particle(d.index, d.radius, fp.center, mu, fp.radius, fp.pixels, fp.independent, rms, fp.skewness,
                    None if rms is None else rms / epsilon, F, unit, ev.energy, unit * epsilon, passes, note)


def _mine(count: int, rank: int, size: int) -> range:
    return range(rank, count, size)


def population(topography, bodies, law: RadiusLaw, count: int | None = None, seed: int = 0,
               evaluator: str = "solver", table: PullOffModel | None = None, comm=None,
               spread_count: int = SPREAD_COUNT, bins: int = 8, resamples: int = BOOTSTRAP,
               trace: Trace = Trace()) -> PopulationResult:
    """The pull-off distribution of ``count`` particles (collective over ``comm``, PETSc.COMM_WORLD by default).

    Parameters
    ----------
    topography : Topography
        The surface the particles land on (model/topography.py: a map with its pixel size).
    bodies : Bodies
        The particles' and the flat's moduli, the work of adhesion, epsilon; each particle's radius replaces
        ``bodies.radius`` (and ``bodies.rms`` is not used: the footprint's heights are the roughness).
    law : RadiusLaw
        The radii; ``count`` None takes a list's length.
    seed
        The draws of every particle (sample.py) and of the bootstrap.
    evaluator
        'solver' (the measured law) or 'table' (the Gaussian rule from ``table``, a :class:`PullOffModel`).
    spread_count
        Particles through both the measured law and the rule (0: no model spread).
    bins, resamples
        Bins of the pull-off against radius; bootstrap resamples of the lognormal's bars.
    trace
        The solver's grid and settings (evaluate.Trace), and whether each particle's energy of a cycle is
        given (``trace.energy``; the solver only: the table evaluator's particles have none, with the reason).

    Raises ValueError for inputs it cannot take (one line).
    """
    from ..core.start import start_petsc

    start_petsc()                      # a library call from a process that has not started PETSc
    from petsc4py import PETSc

    count = len(law.radii) if count is None and law.listed else count
    if count is None:
        raise ValueError("count: needed with a lognormal radius law")
    _check(topography, bodies, law, count, evaluator)
    if evaluator == "table" and table is None:
        raise ValueError("table: the table evaluator needs a PullOffModel (evaluate.load_table())")
    if not 0 <= spread_count:
        raise ValueError(f"spread_count: expected 0 or more, got {spread_count}")
    comm = comm or PETSc.COMM_WORLD
    mpi = comm.tompi4py()
    rank, size = mpi.Get_rank(), mpi.Get_size()
    t0, c0 = time.perf_counter(), time.process_time()
    eps, w = bodies.epsilon, bodies.work_of_adhesion
    solver = SolverEvaluator(trace, PETSc.COMM_SELF)
    tab = TableEvaluator(table) if table is not None else None
    draws = [draw(i, seed, law) for i in _mine(count, rank, size)]
    mus = [replace(bodies, radius=d.radius, rms=None).mu for d in draws]
    chosen: Evaluator = solver
    if evaluator == "table":
        assert tab is not None, "a table evaluator without its table: refused above"
        chosen = tab
    mine = [_particle(d, mu, 2 * np.pi * d.radius * w, ev, eps)
            for d, mu, ev in zip(draws, mus, chosen.evaluate_all(topography, draws, mus, eps))]
    particles = tuple(sorted((p for part in mpi.allgather(mine) for p in part), key=lambda p: p.index))
    spread = _spread(particles, topography, eps, spread_count, evaluator, solver, tab, trace, mpi)
    forces = np.array([p.force.value for p in particles if isinstance(p.pull_off, Measured)])
    radii = np.array([p.radius for p in particles if isinstance(p.pull_off, Measured)])
    fit = lognormal_fit(forces, seed, resamples)
    works = np.array([p.work.value for p in particles if isinstance(p.energy, Measured)])
    energies = energy_fit(works, sum(not isinstance(p.energy, Measured) for p in particles), seed, resamples)
    cpu = mpi.allreduce(time.process_time() - c0)
    return PopulationResult(particles, evaluator, int(seed), law, topography, bodies, ZONE_SHARE, fit,
                            radius_bins(radii, forces, bins), spread, size, time.perf_counter() - t0, cpu, energies)


def _spread(particles, topography, eps, spread_count, evaluator, solver, tab, trace, mpi) -> SpreadSample | Missing:
    """The first ``spread_count`` particles with a footprint under both laws, on the same footprints."""
    from .footprint import footprint

    if spread_count == 0:
        return Missing("no model spread asked for (spread_count 0)")
    chosen = [p for p in particles if p.footprint_radius is not None and p.pixels >= MIN_PIXELS][:spread_count]
    if not chosen:
        return Missing("no particle with a footprint")
    rank, size = mpi.Get_rank(), mpi.Get_size()
    rule = tab
    source = "table" if rule is not None else "the solver's Gaussian rule (16-point Hermite)"
    exact = GaussianRule(trace, solver.comm)
    mine = []
    for k in range(rank, len(chosen), size):
        p = chosen[k]
        fp = footprint(topography, p.site, p.footprint_radius, eps, clip=True)
        # the spread compares pull-offs: its solves leave the energy out
        measured = p.pull_off if evaluator == "solver" else solver.measured(p.mu, fp.heights, energy=False).F
        if evaluator == "table":
            ruled = p.pull_off
        elif rule is not None:
            ruled = rule.evaluate_many(np.array([p.mu]), np.array([fp.rms / eps]))[0]
        else:
            ruled = exact.one(p.mu, fp.rms / eps)
        mine.append((k, measured, ruled))
    pairs = sorted((t for part in mpi.allgather(mine) for t in part), key=lambda t: t[0])
    measured = tuple(t[1] for t in pairs)
    ruled = tuple(t[2] for t in pairs)
    both = [(m, r) for m, r in zip(measured, ruled) if isinstance(m, Measured) and isinstance(r, Measured)]
    rel = np.array([(r.value - m.value) / abs(m.value) for m, r in both])
    bars = np.array([((m.err or 0.0) + (r.err or 0.0)) / abs(m.value) for m, r in both])
    if rel.size == 0:
        return SpreadSample(tuple(p.index for p in chosen), measured, ruled, source, rel, None, None, None, None, None)
    med = float(np.median(rel))
    num = float(np.median(bars))
    return SpreadSample(tuple(p.index for p in chosen), measured, ruled, source, rel, med,
                        float(np.percentile(rel, 16)), float(np.percentile(rel, 84)), num, abs(med) > 2 * num)
