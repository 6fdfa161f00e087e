"""The dimensionless model of Cheng, Dunn and Brach (2002): its parameters, groups and units.

Lengths normal to the surface are in units of the equilibrium spacing epsilon
(H = h/epsilon - 1, lambda = alpha/epsilon, sigma = sigma_s/epsilon), radii in
sqrt(epsilon R), pressures in 8 gamma / (3 epsilon) and loads in 2 pi R gamma.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from .roughness import NEAR_POINTS, Measured

__all__ = ["Model", "tabor", "scales"]


def tabor(R: float, gamma: float, E: float, epsilon: float) -> float:
    """Tabor parameter mu = (R gamma^2 / (E^2 epsilon^3))^(1/3), eq. (9).

    R radius (m), gamma work of adhesion (J/m^2), E combined modulus of eq. (2)
    (Pa), epsilon equilibrium spacing (m).  A 1 um particle, gamma = 0.05 J/m^2,
    E = 1 GPa, epsilon = 0.4 nm:

    >>> round(tabor(1e-6, 0.05, 1e9, 4e-10), 4)
    3.393
    >>> round(tabor(1e-6, 0.05, 1e12, 4e-10), 5)   # 1000 times stiffer: mu / 1000^(2/3)
    0.03393
    """
    return (R * gamma**2 / (E**2 * epsilon**3)) ** (1.0 / 3.0)


def scales(R: float, gamma: float, E: float, epsilon: float) -> dict:
    """The units of the dimensionless results, in SI (section "The Mathematical Theory").

    R radius (m), gamma work of adhesion (J/m^2), E combined modulus of eq. (2)
    (Pa), epsilon equilibrium spacing (m).
    """
    return {"force_N": 2 * math.pi * R * gamma, "approach_m": epsilon, "radius_m": math.sqrt(epsilon * R),
            "pressure_Pa": 8 * gamma / (3 * epsilon)}


class PhysicalBodies(Protocol):
    """What a :class:`Model` made from physical inputs is asked of them: a
    :class:`~petsc_adhesion.model.physical.Bodies`, named by its members here because that module imports
    this one."""

    def spring_stiffness(self, k: float) -> float:
        """The dimensionless stiffness of a spring of k N/m."""

    def scales(self) -> dict:
        """The SI values of the model's units."""

    def describe(self) -> dict:
        """The inputs as given and what they make, in SI."""


@dataclass(frozen=True)
class Model:
    """The model of one curve: the Tabor parameter, the roughness and its average, the domain.

    ``mu`` (eq. 9) and ``sigma`` (the standard deviation of the heights in units
    of epsilon); ``roughness`` the height distribution and its average
    (:func:`~petsc_adhesion.model.pressure.pressure_law`) with its shape
    parameters; ``rmax`` the end r_m of the computational domain (None: the grid's
    default, :attr:`~petsc_adhesion.tracing.trace.GridChoice.default_rmax`) and ``farfield``
    whether the rigid sphere's attraction beyond it is added (the half-infinite
    model) or left out (the paper's truncated model); ``bodies`` the physical
    inputs (:class:`~petsc_adhesion.model.physical.Bodies`) when mu came from them.
    """

    mu: float = 1.0
    sigma: float = 0.0
    rmax: float | None = None  # None: the grid's own (150 on grids that follow the edge, the paper's 10 else)
    roughness: str = "hermite"   # the height distribution and its average (pressure.pressure_law)
    hermite_points: int = 16
    roughness_cutoff: float = 3.0     # truncated_gaussian: highest asperity at K sigma
    roughness_skewness: float = 0.0   # weibull: third standardised moment of the heights
    lognormal_skewness: float = -1.0  # lognormal: third standardised moment of the heights (< 0: bounded above)
    quadrature_points: int = NEAR_POINTS  # truncated_gaussian, weibull: points of the moving part at the wall
    heights: np.ndarray | None = field(default=None, repr=False, compare=False)  # measured, units of epsilon
    #: measured: the probability of each height (the gap of two surfaces, their convolution); None: equal
    height_weights: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: the measured topographies (model.topography.Topography) the heights came from: one surface or two
    topography: tuple = field(default=(), repr=False, compare=False)
    farfield: bool = True      # add the rigid sphere's attraction beyond r_m (the half-infinite model)
    #: the physical inputs that made mu (and sigma): results are reported in SI too (None: dimensionless only)
    bodies: PhysicalBodies | None = field(default=None, repr=False, compare=False)

    def with_parameter(self, name: str, value: float) -> Model:
        """This model with ``name`` (mu or sigma) set to ``value`` (and no physical inputs, which made the old
        one).  A measured roughness has its sigma from its heights: they are scaled to the rms ``value``."""
        if name == "mu":
            return replace(self, mu=value, bodies=None)
        if name != "sigma":
            raise ValueError(f"no parameter '{name}': mu or sigma")
        if self.roughness == "measured":
            assert self.heights is not None, "a measured roughness without its heights"
            rms = Measured(self.heights, weights=self.height_weights).rms
            return replace(self, heights=self.heights * (value / rms), bodies=None)
        return replace(self, sigma=value, bodies=None)

    @property
    def coupling(self) -> float:
        """c = 32 mu^(3/2) / (3 pi), the elastic coupling of eq. (12).

        >>> round(Model(mu=1.0).coupling, 6)
        3.395305
        """
        return 32.0 * self.mu**1.5 / (3.0 * math.pi)

    @property
    def cohesive_zone(self) -> float:
        """Width in r of the cohesive zone at the contact edge, about 0.75 mu^-1.5.

        A grid must resolve it; coarser grids trap the edge between nodes and
        show spurious turning points.
        """
        scale = self.mu**1.5
        return 0.75 / scale if scale > 0 else math.inf
