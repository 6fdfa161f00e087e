"""A population's results as values: each particle, the lognormal fit of the pull-off forces with its
bootstrap bars, their median and spread against the radius, the model spread on a subsample.

The statistics are of the pull-off force's magnitude |F| 2 pi R w (N): the radii differ,
so the forces, not the dimensionless loads, are what a resuspension model takes.  So
too the energy of a cycle, in J (units 2 pi R w epsilon times its value): its lognormal
is of the positive energies only, a particle without hysteresis dissipating a true 0
(counted, not fitted: a lognormal has no mass at 0).  The
lognormal fit is the maximum-likelihood one, median exp(mean ln|F|) and geometric
standard deviation exp(std ln|F|) (n - 1 in the variance), with bars from
:data:`BOOTSTRAP` resamples of the particles (drawn from the population's seed).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..tracing.measured import Measured, Missing

__all__ = ["Particle", "LognormalFit", "RadiusBins", "SpreadSample", "PopulationResult", "lognormal_fit",
           "energy_fit", "radius_bins", "BOOTSTRAP", "MIN_FIT"]

#: Bootstrap resamples of the lognormal fit's bars.
BOOTSTRAP = 200
#: The fewest pull-offs a lognormal is fitted to.
MIN_FIT = 3


@dataclass(frozen=True)
class Particle:
    """One particle: ``index``, ``radius`` (m), ``site`` (m from the first pixel; None: no footprint fits the
    scan), ``mu`` (eq. 9 at its radius), its footprint's ``footprint_radius`` (m), ``pixels`` and
    ``independent`` samples, the local ``rms`` (m) and ``skewness`` of its heights from their mean plane
    (None where there are none, or flat), ``sigma`` = rms / epsilon, ``pull_off`` in units 2 pi R w
    (Measured, or Missing with its reason), ``force_unit`` = 2 pi R w (N), the ``energy`` of a cycle under a
    rigid machine in units 2 pi R w epsilon (Measured: 0 without hysteresis; or Missing with its reason),
    ``energy_unit`` = 2 pi R w epsilon (J), the footprint iteration's ``passes``, and ``note``: a flag ('' none:
    a footprint of few independent samples, an unsettled iteration)."""

    index: int
    radius: float
    site: tuple | None
    mu: float
    footprint_radius: float | None
    pixels: int
    independent: float
    rms: float | None
    skewness: float | None
    sigma: float | None
    pull_off: Measured | Missing
    force_unit: float
    energy: Measured | Missing
    energy_unit: float
    passes: int = 0
    note: str = ""

    @property
    def force(self) -> Measured | Missing:
        """The pull-off force's magnitude (N) with its bar."""
        if not isinstance(self.pull_off, Measured):
            return self.pull_off
        err = None if self.pull_off.err is None else self.pull_off.err * self.force_unit
        return Measured(-self.pull_off.value * self.force_unit, err)

    @property
    def work(self) -> Measured | Missing:
        """The energy of a cycle (J) with its bar: what the cycle dissipates."""
        if not isinstance(self.energy, Measured):
            return self.energy
        err = None if self.energy.err is None else self.energy.err * self.energy_unit
        return Measured(self.energy.value * self.energy_unit, err)


@dataclass(frozen=True)
class LognormalFit:
    """|F| ~ lognormal: ``median`` (N) and ``gsd`` (the geometric standard deviation) with bootstrap bars, of
    ``count`` pull-offs, ``resamples`` bootstrap resamples."""

    median: Measured
    gsd: Measured
    count: int
    resamples: int


@dataclass(frozen=True)
class RadiusBins:
    """The pull-off force against the radius: ``edges`` (m, log-spaced), each bin's ``count``, ``median``,
    ``p16`` and ``p84`` of |F| (N; NaN in a bin of no particle, its count 0 saying why)."""

    edges: np.ndarray = field(repr=False)
    count: np.ndarray = field(repr=False)
    median: np.ndarray = field(repr=False)
    p16: np.ndarray = field(repr=False)
    p84: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class SpreadSample:
    """The model spread: particles (``indices``) evaluated on the same footprints under their measured law
    (``measured``, the solver) and the Gaussian rule at their rms (``rule``, from ``rule_source``), units
    2 pi R w.  ``relative`` (rule - measured) / |measured| of each pair both computed; ``median``, ``p16``,
    ``p84`` of it; ``numerical``: the median of the pairs' combined relative bars; ``decides``: whether the
    model, not the numerics, makes the difference (|median| above twice ``numerical``)."""

    indices: tuple
    measured: tuple
    rule: tuple
    rule_source: str
    relative: np.ndarray = field(repr=False)
    median: float | None
    p16: float | None
    p84: float | None
    numerical: float | None
    decides: bool | None


@dataclass(frozen=True)
class PopulationResult:
    """A population: its ``particles`` (in index order), the ``evaluator`` that made their pull-offs
    ('solver': the measured law; 'table': the Gaussian rule), its ``seed``, radius ``law``
    (:class:`~petsc_adhesion.population.sample.RadiusLaw`), the ``topography``
    (:class:`~petsc_adhesion.model.topography.Topography`), the ``bodies``
    (:class:`~petsc_adhesion.model.physical.Bodies`, their radius each particle's), the footprint's
    ``zone_share``, the lognormal ``fit`` (or Missing), the ``bins`` against radius, the model ``spread``
    (or Missing), the ``ranks`` it ran on, its ``wall_time`` and ``cpu_time`` (s, over all ranks), and the
    lognormal ``energy_fit`` of the positive energies of a cycle (J; or Missing with why)."""

    particles: tuple
    evaluator: str
    seed: int
    law: object
    topography: object = field(repr=False)
    bodies: object
    zone_share: float
    fit: LognormalFit | Missing
    bins: RadiusBins | Missing
    spread: SpreadSample | Missing
    ranks: int
    wall_time: float
    cpu_time: float
    energy_fit: LognormalFit | Missing

    @property
    def forces(self) -> np.ndarray:
        """The pull-off forces' magnitudes (N) of the particles that have one, in index order."""
        return np.array([p.force.value for p in self.particles if isinstance(p.pull_off, Measured)])

    @property
    def works(self) -> np.ndarray:
        """The energies of a cycle (J) of the particles that have one (0: no hysteresis), in index order."""
        return np.array([p.work.value for p in self.particles if isinstance(p.energy, Measured)])

    @property
    def energy_missing(self) -> list:
        """The particles without an energy of a cycle."""
        return [p for p in self.particles if not isinstance(p.energy, Measured)]

    @property
    def missing(self) -> list:
        """The particles without a pull-off."""
        return [p for p in self.particles if not isinstance(p.pull_off, Measured)]

    @property
    def flagged(self) -> list:
        """The particles with a pull-off and a note."""
        return [p for p in self.particles if isinstance(p.pull_off, Measured) and p.note]

    @property
    def complete(self) -> bool:
        """Whether the distribution was fitted (at least MIN_FIT pull-offs)."""
        return isinstance(self.fit, LognormalFit)


def lognormal_fit(forces: np.ndarray, seed: int, resamples: int = BOOTSTRAP,
                  stream: int = 2**31 - 1) -> LognormalFit | Missing:
    """The lognormal of the magnitudes ``forces`` (module docstring), bars by ``resamples`` bootstrap
    resamples from ``seed`` (and ``stream``, its own); Missing for fewer than :data:`MIN_FIT` or a non-positive
    force."""
    x = np.asarray(forces, dtype=float)
    if x.size < MIN_FIT:
        return Missing(f"{x.size} pull-offs: a lognormal needs at least {MIN_FIT}")
    if not np.all(x > 0):
        return Missing(f"{int(np.sum(x <= 0))} pull-offs not tensile: no lognormal of their magnitudes")
    ln = np.log(x)
    rng = np.random.default_rng([int(seed), int(stream)])     # a stream of its own, not any particle's
    pick = rng.integers(0, x.size, size=(resamples, x.size))
    means, sds = ln[pick].mean(axis=1), ln[pick].std(axis=1, ddof=1)
    median = Measured(math.exp(ln.mean()), float(np.std(np.exp(means), ddof=1)))
    gsd = Measured(math.exp(ln.std(ddof=1)), float(np.std(np.exp(sds), ddof=1)))
    return LognormalFit(median, gsd, int(x.size), int(resamples))


def energy_fit(works: np.ndarray, missing: int, seed: int, resamples: int = BOOTSTRAP) -> LognormalFit | Missing:
    """The lognormal of the positive energies of a cycle among ``works`` (J; a 0 is a particle without
    hysteresis, not fitted), bars by bootstrap from ``seed`` (a stream of their own); Missing, saying how many
    were 0 and how many ``missing``, for fewer than :data:`MIN_FIT` positive ones."""
    x = np.asarray(works, dtype=float)
    positive = x[x > 0]
    if positive.size < MIN_FIT:
        return Missing(f"{positive.size} positive energies of a cycle ({int(np.sum(x == 0))} particles without "
                       f"hysteresis, a computed 0; {missing} without an energy): a lognormal needs at least "
                       f"{MIN_FIT}")
    return lognormal_fit(positive, seed, resamples, stream=2**31 - 2)


def radius_bins(radii: np.ndarray, forces: np.ndarray, bins: int) -> RadiusBins | Missing:
    """|F| (N) against the radius (m) in ``bins`` log-spaced bins over the radii (one bin for one radius)."""
    r, f = np.asarray(radii, dtype=float), np.asarray(forces, dtype=float)
    if r.size == 0:
        return Missing("no pull-off to bin")
    lo, hi = float(r.min()), float(r.max())
    n = 1 if hi <= lo * (1 + 1e-12) else int(bins)
    edges = np.array([lo, hi]) if n == 1 else np.geomspace(lo, hi, n + 1)
    which = np.clip(np.searchsorted(edges, r, side="right") - 1, 0, n - 1)
    count = np.bincount(which, minlength=n)
    stat = np.full((3, n), np.nan)
    for k in range(n):
        if count[k]:
            stat[:, k] = np.percentile(f[which == k], [50, 16, 84])
    return RadiusBins(edges, count, stat[0], stat[1], stat[2])
