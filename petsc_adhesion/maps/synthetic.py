"""Synthetic force maps made by the forward solver with noise: the truth a map's fit is checked and timed on.

Pixel (ix, iy) of a grid of ``shape`` is the curve :func:`~petsc_adhesion.fitting.synthetic.synthetic_curve`
makes for the bodies ``truth(ix, iy)`` behind ``spring``, sampled as ``sampling`` says, with the noise's
stream seeded by the pixel (``sampling.seed`` + its number): each pixel's noise its own, the map the same
each time.  The noiseless curve of each distinct truth is traced once and each pixel's noise added to it,
as ``synthetic_curve`` adds it (the same numbers): a map of a few materials over many pixels costs a few
traces.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..fitting.results import Spring
from ..fitting.synthetic import Sampling, synthetic_curve
from ..model.physical import Bodies
from .source import MapSource, curves_map

__all__ = ["synthetic_map"]


def synthetic_map(shape: tuple, truth: Callable[[int, int], Bodies], spring: Spring,
                  sampling: Sampling = Sampling(), settings=None) -> MapSource:
    """A map of ``shape`` (nx, ny) whose pixel (ix, iy) is a curve of the bodies ``truth(ix, iy)`` (see the
    module), filled row by row (x fastest)."""
    nx, ny = shape
    clean: dict = {}
    curves = []
    for i in range(nx * ny):
        bodies = truth(i % nx, i // nx)
        if bodies not in clean:
            clean[bodies] = synthetic_curve(bodies, spring, replace(sampling, noise=0.0), settings=settings)
        c = clean[bodies]
        seed = sampling.seed + i
        F = c.F + sampling.noise * np.random.default_rng(seed).standard_normal(c.F.size)
        curves.append(replace(c, F=F, metadata={**c.metadata, "noise_N": sampling.noise, "seed": seed}))
    return curves_map(curves, (nx, ny), "synthetic")
