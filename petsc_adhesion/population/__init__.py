"""A particle population on a measured topography: radii and sites drawn from a seed, each particle's
footprint and its local heights, its pull-off by the solver (the measured law) or a table (the Gaussian
rule), the distribution's lognormal fit (docs/population.md).

``petsc_adhesion.particle_population(...)`` is :func:`~petsc_adhesion.population.compute.population`
(a name of its own: the package keeps ``petsc_adhesion.population``).
"""
from __future__ import annotations

from .compute import population

__all__ = ["population"]
