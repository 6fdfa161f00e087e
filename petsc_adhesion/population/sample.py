"""The particles of a population: their radii (a lognormal law or a list) and the sites they land on, drawn
from the seed by each particle's index.

Particle i draws from its own stream, ``numpy.random.default_rng([seed, i])``: its radius
and its site are the same whatever the number of particles drawn before it, the ranks
the population is spread over, or the order they run in.  A lognormal radius is
R = median * spread^z with z a standard normal deviate (``spread`` the geometric
standard deviation: 1 gives one radius); a list gives particle i the i-th radius.  The
site is uniform over the sites whose footprint lies inside the scan: each coordinate
uniform in [m, L - m], m the footprint's radius, L the scan's length along that axis.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["RadiusLaw", "Draw", "draw"]


@dataclass(frozen=True)
class RadiusLaw:
    """The particles' radii (m): lognormal by ``median`` and ``spread`` (the geometric standard deviation,
    >= 1), or the ``radii`` of a list, particle i the i-th."""

    median: float | None = None
    spread: float = 1.0
    radii: tuple = ()

    def __post_init__(self):
        if self.radii:
            if self.median is not None:
                raise ValueError("a radius law is a list of radii or a lognormal median, not both")
            if not all(math.isfinite(r) and r > 0 for r in self.radii):
                raise ValueError("radii: expected finite positive radii (m)")
        elif self.median is None or not (math.isfinite(self.median) and self.median > 0):
            raise ValueError(f"median: expected a finite positive radius (m), got {self.median!r}")
        if not (math.isfinite(self.spread) and self.spread >= 1):
            raise ValueError(f"spread: expected a geometric standard deviation >= 1, got {self.spread!r}")

    @property
    def listed(self) -> bool:
        """Whether the radii come from a list."""
        return bool(self.radii)

    def describe(self) -> str:
        """The law in words."""
        if self.radii:
            return f"a list of {len(self.radii)} radii ({min(self.radii):.4g} to {max(self.radii):.4g} m)"
        if self.spread == 1:
            return f"one radius, {self.median:.4g} m"
        return f"lognormal, median {self.median:.4g} m, geometric standard deviation {self.spread:.4g}"


@dataclass(frozen=True)
class Draw:
    """What particle ``index`` drew: its ``radius`` (m) and the uniform deviates ``u`` that place its site."""

    index: int
    radius: float
    u: tuple

    def site(self, margin: float, size: tuple, pixel: tuple) -> tuple | None:
        """The site (m from the first pixel's centre, each axis) of a footprint of radius ``margin`` (m) on a
        scan of ``size`` (m) and ``pixel`` (m), which covers half a pixel either side of the pixels' centres:
        uniform over the sites whose footprint lies inside; None where none does."""
        if any(2 * margin > L for L in size):
            return None
        return tuple(margin - p / 2 + u * (L - 2 * margin) for u, L, p in zip(self.u, size, pixel))


def draw(index: int, seed: int, law: RadiusLaw) -> Draw:
    """Particle ``index``'s radius and site deviates, from its own stream of ``seed`` (module docstring)."""
    rng = np.random.default_rng([int(seed), int(index)])
    z = float(rng.standard_normal())
    u = tuple(float(x) for x in rng.random(2))
    radius = law.radii[index] if law.radii else law.median * law.spread ** z
    return Draw(index, float(radius), u)
