"""A particle population on a measured topography: radii and sites drawn from a seed, each particle's
footprint and its local heights, its pull-off by the solver (the measured law) or a table (the Gaussian
rule), the distribution's lognormal fit (docs/population.md).

``petsc_adhesion.population(...)`` calls :func:`~petsc_adhesion.population.compute.population`: the
package is callable, so that the Python API's name and the package's are one (its modules,
``petsc_adhesion.population.sample`` and the rest, stay importable under it).
"""
from __future__ import annotations

import sys
import types

from .compute import population

__all__ = ["population"]


class _Callable(types.ModuleType):
    """This package, callable as :func:`population`."""

    def __call__(self, *args, **kwargs):
        return population(*args, **kwargs)


sys.modules[__name__].__class__ = _Callable
