"""The grids that follow the contact edge: their design in the physical frame and in the frame of the edge.

Fine (the cohesive zone over NODES_PER_ZONE, at most CONTACT_SPACING) within BAND of
the edge, graded beyond, geometric out to RMAX, where the attraction left out carries
|F| < 1e-8; in the frame of the edge the same, in units of the contact radius a, fine
enough while a grows by GROW^2 (:mod:`~petsc_adhesion.tracing.tracer` changes grids).
"""
from __future__ import annotations

import math

from ..discretization.grid import EdgeGrid
from ..discretization.resolution import NODES_PER_ZONE, cohesive_zone
from ..discretization.problem import MU_SOFT
from ..model.pressure import pressure_law

__all__ = ["BAND", "BAND_ZONES", "CONTACT_SPACING", "REACH", "RMAX", "A_SWITCH", "A_SWITCH_ZONES", "GROW", "band",
           "a_switch", "grid_for", "scaled_grid_for", "scaled_band", "sharp",
           "frame_of_edge", "MU_TRUNCATED", "soft", "margined", "EDGE_SHARE", "PEAK_ATTRACTION", "domain_load"]


#: Half-width of the fine band about the edge in the physical frame ...
BAND = 0.25
#: ... and at most this many cohesive zones (mu > 20: the zone narrows as mu^-1.5, and a band of fixed
#: width would take mu^1.5 nodes; the frame of the edge takes over within it, A_SWITCH_ZONES).
BAND_ZONES = 10


#: Largest spacing within reach of the surface forces (the paper grid's is 0.02).
CONTACT_SPACING = 0.025


#: How far beyond the edge the forces reach (rigid gap 4 epsilon at the equilibrium approach).
REACH = 3.0


#: End of the domain: the rigid sphere's attraction beyond it carries |F| < 1e-8.
RMAX = 150.0


#: Contact radius at which a sharp edge is pinned and the frame of the edge takes over ...
A_SWITCH = 0.3
#: ... or this many cohesive zones when fewer (mu > 6.5): in the physical frame the edge moves a
#: fraction of the zone a step, so the steps there grow like the travel over the zone; six zones is
#: wide enough for the frame's pin (mu = 20 to 100: the same events as at A_SWITCH, in a third of the steps).
A_SWITCH_ZONES = 6


#: Factor by which the contact radius may change on one grid of the frame of the edge.
GROW = 1.5
#: In the frame of the edge the spacing inside the contact may reach this share of the contact radius
#: (the interior varies on the scale of a, the edge's cohesive zone on its own, graded between them) ...
CORE_SHARE = 0.02
#: How much finer than NODES_PER_ZONE the grids of a sharp edge are: their levels -1 and -2 resolve it too.
COARSE_MARGIN = 4


def _zone(model, given: float | None = None) -> float:
    """The cohesive zone of the model, roughness included (:func:`~petsc_adhesion.discretization.resolution.cohesive_zone`),
    or the one ``given`` (a rough soft sphere's, measured on its state)."""
    return cohesive_zone(model, pressure_law(model)) if given is None else given


def _fine(model, zone: float | None = None) -> float:
    """The spacing about the edge: the zone (default the model's, :func:`_zone`) over NODES_PER_ZONE,
    COARSE_MARGIN times finer where :func:`margined` (so that its two coarser levels still resolve the zone
    and give the error bars), at most CONTACT_SPACING."""
    zone = _zone(model, zone)
    return min(zone / NODES_PER_ZONE / (COARSE_MARGIN if margined(model) else 1), CONTACT_SPACING)


def margined(model) -> bool:
    """Whether the grids about the edge are COARSE_MARGIN times finer than NODES_PER_ZONE asks: a soft
    sphere's, and the truncated model's sharp edge (:func:`frame_of_edge` False), which crosses the nodes of
    the physical frame all along its curve.  There, at NODES_PER_ZONE a zone, the edge's lattice trapping is
    small but shows wherever dlambda/da vanishes: at mu = 10 nine spurious fold pairs within 3e-3 in lambda of
    the contact's snap-off (-16.199), the curve stopped by -cont_max_folds; COARSE_MARGIN times finer, none
    (and its levels -1 and -2 still resolve the zone: the error bars come from coarser grids)."""
    return soft(model) or (not model.farfield and sharp(model))


def soft(model) -> bool:
    """A soft sphere (mu from MU_SOFT on): its grids are sized by the cohesive zone and the contact radius,
    its curve measured in units of mu; below MU_SOFT the grids are as they were, node for node (their
    bars, from finer levels, are tighter: on a soft grid mu = 16's zero-load contact radius has a bar of
    2.0e-4, a quarter of its 7.6e-3 distance from JKR)."""
    return model.mu >= MU_SOFT


def band(model) -> float:
    """The half-width of the fine band about the edge in the physical frame: BAND, or for a soft sphere
    BAND_ZONES zones where fewer."""
    return min(BAND, BAND_ZONES * _zone(model)) if soft(model) else BAND


def a_switch(model) -> float:
    """The contact radius at which the frame of the edge takes over: A_SWITCH, or for a soft sphere
    A_SWITCH_ZONES zones where fewer."""
    return min(A_SWITCH, A_SWITCH_ZONES * _zone(model)) if soft(model) else A_SWITCH


def grid_for(model, edge: float, level: int = 0, rmax: float = RMAX) -> EdgeGrid:
    """The physical-frame grid centred on the contact edge ``edge`` for ``model`` at refinement ``level``."""
    return EdgeGrid(edge=edge, fine=_fine(model), rmax=rmax, band=band(model), contact=CONTACT_SPACING,
                    reach=REACH, level=level)


def scaled_grid_for(model, a: float, level: int = 0, rmax: float = RMAX, band: float | None = None,
                    zone: float | None = None) -> EdgeGrid:
    """The grid of the frame of the edge, in physical units for contact radius ``a`` (divide by a for rho).

    Fine enough for the zone while a grows by GROW^2 (a change waits at most that
    long), over ``band`` about the pinned edge (default two zones: a smooth surface's
    peak attraction lies within one; :func:`scaled_band`), out to rmax GROW^2 at a, so
    past rmax at a / GROW^2, or to GROW a where that is further (a small r_m must not
    put the end of a grid in rho = r / a before the edge pinned at rho = 1; the far
    field beyond keeps the model the half-infinite one, and
    :func:`~petsc_adhesion.tracing.results.assess` says when the contact nears the end).  For a soft
    sphere (:func:`soft`) inside the contact the spacing may grow to CORE_SHARE a;
    outside, it is capped by CONTACT_SPACING as far as the forces reach: where the rigid
    sphere's gap has opened by REACH^2 / 2 beyond the edge's, sqrt(a^2 + REACH^2) - a
    (REACH at a = 0, 3 / (2 a) for a large contact; the elastic opening only shortens it).
    ``zone``: the cohesive zone to resolve (default the model's; a rough soft sphere's is measured on
    its state, :func:`~petsc_adhesion.discretization.resolution.zone_of`).
    """
    big = soft(model)
    zone = _zone(model, zone)
    return EdgeGrid(edge=a, fine=_fine(model, zone) / GROW**2, rmax=max(rmax * GROW**2, GROW * a),
                    band=2 * zone if band is None else band, contact=CONTACT_SPACING,
                    reach=math.sqrt(a * a + REACH**2) - a if big else REACH, core=CORE_SHARE * a if big else 0.0,
                    level=level)


def scaled_band(model, a: float, peak: float, zone: float | None = None) -> float:
    """The fine band of the frame of the edge at contact radius ``a`` with the peak attraction at ``peak``.

    Two zones, or wider so that it holds the peak attraction with a zone to spare: on a
    rough surface the gap rises slowly at the edge, and the pinned level can lie far
    from the peak in r (0.34 at mu = 20, sigma = 1).  ``zone``: as in :func:`scaled_grid_for`.
    """
    zone = _zone(model, zone)
    return max(2 * zone, abs(a - peak) + zone)


def sharp(model) -> bool:
    """Whether the contact edge is sharp enough to be traced in its own frame."""
    return _zone(model) / NODES_PER_ZONE < CONTACT_SPACING


#: The truncated model (-adh_farfield false) on grids that follow the edge, traced in the physical frame
#: throughout (:func:`frame_of_edge`, on :func:`margined` grids), up to this mu: there every step moves the
#: edge by about a tenth of its zone, so the steps grow like the edge's travel over the zone, about mu^2
#: (mu = 5: 755, mu = 7: 1704 to F = 2, mu = 10: 3977 to F = 2 when it was traced on past r_m, within
#: -cont_max_steps' default; it now stops where its contact reaches r_m, before F = 2).
MU_TRUNCATED = 10.0


#: The contact reaches the end of the domain when |P(r_m)| exceeds this share of the peak attraction: there the
#: truncated model (nothing beyond r_m) ends, and its curve stops (:class:`~petsc_adhesion.tracing.tracer.Tracer`).
EDGE_SHARE = 1e-3
#: The peak of the Lennard-Jones attraction, |P| at H + 1 = 3^(1/6) (units 8 gamma / (3 epsilon)).
PEAK_ATTRACTION = 2.0 / (3.0 * 3.0 ** 0.5)


def domain_load(mu: float, rmax: float) -> float:
    """The load at which Hertz's contact radius reaches r_m: F_H = (2 / (3 pi)) r_m^3 mu^(-3/2).

    Hertz (1882), a^3 = 3 P R / (4 E*), in the model's units (contact radii in sqrt(epsilon R), loads in
    2 pi R gamma; the first term of :func:`~petsc_adhesion.model.reference.jkr.jkr_load`).  At a given load
    adhesion only widens the contact (the Maugis-Dugdale family runs from Hertz's and DMT's radius to JKR's,
    the widest), and roughness spreads the pressure further out, so the truncated model's contact has reached
    r_m by F_H at the latest: a curve asked to go past it would leave the model's domain (infinite for a
    rigid sphere, mu = 0, which does not deform)."""
    return math.inf if mu <= 0 else 2.0 / (3.0 * math.pi) * rmax**3 / mu**1.5


def frame_of_edge(model) -> bool:
    """Whether the frame of the edge may take over a sharp edge: for the half-infinite model only.

    Its grid is in rho = r / a and reaches r = a rho_m, at least r_m and up to
    GROW^4 r_m as a changes: beyond r_m the rigid sphere's attraction is added
    (-adh_farfield), so where the grid ends is a numerical choice whose error is in
    the bar.  The truncated model (no far field) ends at r_m itself, which a grid in
    rho cannot keep: it is traced in the physical frame throughout.
    """
    return sharp(model) and model.farfield
