"""The grids that follow the contact edge: their design in the physical frame and in the frame of the edge.

Fine (the cohesive zone over NODES_PER_ZONE, at most CONTACT_SPACING) within BAND of
the edge, graded beyond, geometric out to RMAX, where the attraction left out carries
|F| < 1e-8; in the frame of the edge the same, in units of the contact radius a, fine
enough while a grows by GROW^2 (:mod:`~petsc_adhesion.tracing.tracer` changes grids).
"""
from __future__ import annotations

from ..discretization.grid import EdgeGrid
from ..discretization.resolution import NODES_PER_ZONE, cohesive_zone
from ..model.pressure import pressure_law

__all__ = ["BAND", "CONTACT_SPACING", "REACH", "RMAX", "A_SWITCH", "GROW", "grid_for", "scaled_grid_for", "scaled_band", "sharp"]


#: Half-width of the fine band about the edge in the physical frame.
BAND = 0.25


#: Largest spacing within reach of the surface forces (the paper grid's is 0.02).
CONTACT_SPACING = 0.025


#: How far beyond the edge the forces reach (rigid gap 4 epsilon at the equilibrium approach).
REACH = 3.0


#: End of the domain: the rigid sphere's attraction beyond it carries |F| < 1e-8.
RMAX = 150.0


#: Contact radius at which a sharp edge is pinned and the frame of the edge takes over.
A_SWITCH = 0.3


#: Factor by which the contact radius may change on one grid of the frame of the edge.
GROW = 1.5


def _zone(model) -> float:
    """The cohesive zone of the model, roughness included (:func:`~petsc_adhesion.discretization.resolution.cohesive_zone`)."""
    return cohesive_zone(model, pressure_law(model))


def _fine(model) -> float:
    return min(_zone(model) / NODES_PER_ZONE, CONTACT_SPACING)


def grid_for(model, edge: float, level: int = 0, rmax: float = RMAX) -> EdgeGrid:
    """The physical-frame grid centred on the contact edge ``edge`` for ``model`` at refinement ``level``."""
    return EdgeGrid(edge=edge, fine=_fine(model), rmax=rmax, band=BAND, contact=CONTACT_SPACING, reach=REACH,
                    level=level)


def scaled_grid_for(model, a: float, level: int = 0, rmax: float = RMAX, band: float | None = None) -> EdgeGrid:
    """The grid of the frame of the edge, in physical units for contact radius ``a`` (divide by a for rho).

    Fine enough for the zone while a grows by GROW^2 (a change waits at most that
    long), over ``band`` about the pinned edge (default two zones: a smooth surface's
    peak attraction lies within one; :func:`scaled_band`), out to rmax GROW^2 at a, so
    past rmax at a / GROW^2.
    """
    return EdgeGrid(edge=a, fine=_fine(model) / GROW**2, rmax=rmax * GROW**2,
                    band=2 * _zone(model) if band is None else band, contact=CONTACT_SPACING, reach=REACH,
                    level=level)


def scaled_band(model, a: float, peak: float) -> float:
    """The fine band of the frame of the edge at contact radius ``a`` with the peak attraction at ``peak``.

    Two zones, or wider so that it holds the peak attraction with a zone to spare: on a
    rough surface the gap rises slowly at the edge, and the pinned level can lie far
    from the peak in r (0.34 at mu = 20, sigma = 1).
    """
    return max(2 * _zone(model), abs(a - peak) + _zone(model))


def sharp(model) -> bool:
    """Whether the contact edge is sharp enough to be traced in its own frame."""
    return _zone(model) / NODES_PER_ZONE < CONTACT_SPACING
