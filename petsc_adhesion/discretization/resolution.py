"""Does the grid resolve the contact edge?  The check of a traced curve, and the grid it would need.

At large mu the cohesive zone at the contact edge narrows, about 0.75 mu^-1.5
in r.  A grid that does not resolve it where the edge travels traps the edge
between nodes (lattice trapping), and the S-curve turns into a staircase of
spurious turning points.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..core.protocol import PressureLaw
from .grid import PAPER_UNIFORM
from .problem import MU_SOFT

__all__ = ["check", "cohesive_zone", "zone_of", "measured_zone", "INNER_SHARE", "attraction_range", "NODES_PER_ZONE", "MAX_TRUE_FOLDS", "UNRESOLVED_SHARE", "RANGE_SHARE"]

#: Nodes needed across the cohesive zone: measured at mu = 3 and 5, where uniform
#: grids with h > zone/5 showed staircases of spurious folds and h <= zone/5 did not.
NODES_PER_ZONE = 5
#: Share of a curve's states that may sit on a coarser spacing: a trapped edge makes its staircase over
#: a run of states, while a grid that follows the edge may lag it at one (mu = 20, sigma = 1: 1 of 364
#: states, at the switch to the frame of the edge, 1.3 times the spacing, no spurious fold).
UNRESOLVED_SHARE = 0.02
#: The resolved model shows two fold pairs up to mu = 7 (paper, Fig. 9), three at mu = 20 (ours,
#: the same on grids with 5, 10 and 20 nodes across the zone), four at mu = 100 (the same on grids
#: twice as fine) and five at mu = 1000, where the contact forms; a staircase shows dozens.
MAX_TRUE_FOLDS = 12


def attraction_range(law: PressureLaw) -> float:
    """The width in H of the law's attraction: from its zero (P = 0, the start of the attraction)
    out to where it has fallen to RANGE_SHARE of its peak.  Sampled on a geometric scale
    from the wall (3000 points, relative accuracy ~1e-3, ample for a grid spacing)."""
    H = law.wall + np.geomspace(1e-4, 2.0 * (law.wall + 1.0) + 40.0, 3000)
    P = law(H)[0]
    k = int(np.argmin(P))
    repulsive = np.nonzero(P[:k] > 0)[0]
    start = H[repulsive[-1]] if repulsive.size else H[0]
    return float(H[k:][P[k:] > RANGE_SHARE * P[k]][0] - start)


#: Where the attraction counts as ended, as a share of its peak (attraction_range).
RANGE_SHARE = 0.1


def cohesive_zone(model, law: PressureLaw) -> float:
    """The cohesive zone at the contact edge: 0.75 mu^-1.5 for a smooth surface, wider with roughness.

    The roughness average spreads the attraction over a wider range of the mean gap
    (:func:`attraction_range`); at the edge of a JKR-like contact the gap opens as the
    distance^(3/2), so the zone widens as the 2/3 power of that range against the
    smooth law's.  (Taking instead the reach of the lowest heights, the rule's wall,
    overstated the widening: with the 16-point Hermite rule at sigma = 0.2 it gave 1.76
    where the attraction's range gives 1.01, and grids designed with it trapped the edge
    at mu = 4 to 4.5, sigma = 0.2: 6 to 13 spurious turning points in the Fig. 18 study.)
    """
    if law.smooth:
        return model.cohesive_zone
    return model.cohesive_zone * (attraction_range(law) / _smooth_range()) ** (2.0 / 3.0)


#: A smooth surface's inner half-width (from the peak attraction inward to where it has halved) is about
#: this many cohesive zones (mu = 20: 0.0096 to 0.0100 against 0.0084, along the whole curve).
INNER_SHARE = 1.15


def measured_zone(r: np.ndarray, P: np.ndarray) -> float:
    """The cohesive zone a state shows: its inner half-width over INNER_SHARE; nan without attraction.

    On a rough soft sphere the roughness keeps the surfaces at its wall across the contact and
    the edge is Hertz-like, its attraction spread over the gap's slow opening: at mu = 20 the
    inner half-width is 0.055 at sigma = 0.4 and 0.09 at sigma = 1 and 2, where
    :func:`cohesive_zone` (a JKR edge's, widened by the law's range) says 0.012, 0.021, 0.032,
    and grids sized by it took 2000 to 3700 nodes at mu = 100, sigma = 1 (and would take 10^5 at
    mu = 1000).  The half-width holds the sharpest feature, the rise from repulsion to the peak
    attraction (0.09 to 0.2 at mu = 20, sigma = 2, against an inner half-width of 0.09 to 0.2).
    """
    k = int(np.argmin(P))
    if not P[k] < 0:
        return float("nan")
    weaker = np.nonzero(P[:k] > 0.5 * P[k])[0]
    if not weaker.size:                     # the attraction reaches the centre
        return float(r[k]) / INNER_SHARE
    j = int(weaker[-1])
    half = r[j] + (0.5 * P[k] - P[j]) / (P[j + 1] - P[j]) * (r[j + 1] - r[j])
    return float(r[k] - half) / INNER_SHARE


def zone_of(model, law: PressureLaw, r: np.ndarray | None = None, P: np.ndarray | None = None,
            formula: float | None = None) -> float:
    """The cohesive zone to resolve: :func:`cohesive_zone` (``formula`` when the caller has it), or for a
    rough soft sphere (mu from MU_SOFT) the wider :func:`measured_zone` of the state (r, P) where it is
    given and wider."""
    zone = cohesive_zone(model, law) if formula is None else formula
    if r is None or law.smooth or model.mu < MU_SOFT:
        return zone
    seen = measured_zone(np.asarray(r), np.asarray(P))
    return max(zone, seen) if np.isfinite(seen) else zone


def check(model, law: PressureLaw, states, folds: int) -> str:
    """One line when a grid did not resolve the cohesive zone where the contact edge was, else "".

    ``states``: (nodes, H, P) of each point of the curve; the contact edge of a
    point is its radius of peak attraction (P most negative), which lies inside the
    cohesive zone whether or not there is a contact (and is what the grids follow,
    :func:`~petsc_adhesion.tracing.tracer.edge_of`); the spacing there must be at most
    zone / NODES_PER_ZONE.
    ``folds``: the turning points the curve showed, the other symptom (more than
    :data:`MAX_TRUE_FOLDS`).  The line names the spacing the case needs there.
    """
    zone = cohesive_zone(model, law)
    spacing, where, needs = [], [], []
    for r, _, P in states:
        k = int(np.argmin(P))
        if P[k] < 0 and np.isfinite(zone):
            h = np.diff(r)
            spacing.append(h[max(0, k - 1):k + 1].max())
            where.append(r[k])
            needs.append(zone_of(model, law, r, P, zone) / NODES_PER_ZONE)
    if not spacing:
        return ""
    hmax, lo, hi = max(spacing), min(where), max(where)
    coarse = sum(h > n * (1 + 1e-9) for h, n in zip(spacing, needs))
    need = min(needs)
    zone = need * NODES_PER_ZONE
    if coarse <= UNRESOLVED_SHARE * len(spacing) and folds <= MAX_TRUE_FOLDS:
        return ""
    # a paper grid that refines [0, r_edge + 2] enough (the edge may travel further than seen)
    h0 = model.rmax / (PAPER_UNIFORM - 1)
    extra = min(int(np.ceil(min(hi + 2.0, model.rmax) / h0)), PAPER_UNIFORM - 1)
    split = max(2, int(np.ceil(h0 / need)))
    return (f"{folds} turning points; grid spacing {hmax:.3g} where the contact edge travels "
            f"(r in [{lo:.3g}, {hi:.3g}]) does not resolve the cohesive zone {zone:.3g} at mu = {model.mu:g}: "
            f"this case needs spacing <= {need:.3g} there, e.g. -grid_type paper "
            f"-grid_paper_extra {extra} -grid_paper_split {split} ({PAPER_UNIFORM + extra * (split - 1)} nodes)")


@lru_cache(maxsize=1)
def _smooth_range() -> float:
    from ..model.parameters import Model
    from ..model.pressure import pressure_law

    return attraction_range(pressure_law(Model(sigma=0.0)))
