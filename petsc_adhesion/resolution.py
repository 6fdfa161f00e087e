"""Does the grid resolve the contact edge?  The check of a traced curve, and the grid it would need.

At large mu the cohesive zone at the contact edge narrows, about 0.75 mu^-1.5
in r.  A grid that does not resolve it where the edge travels traps the edge
between nodes (lattice trapping), and the S-curve turns into a staircase of
spurious turning points.
"""
from __future__ import annotations

import numpy as np

from .grid import PAPER_UNIFORM

__all__ = ["contact_edges", "check", "NODES_PER_ZONE", "MAX_TRUE_FOLDS"]

#: Nodes needed across the cohesive zone: measured at mu = 3 and 5, where uniform
#: grids with h > zone/5 showed staircases of spurious folds and h <= zone/5 did not.
NODES_PER_ZONE = 5
#: The resolved model shows at most two fold pairs (paper, Fig. 9, up to mu = 7).
MAX_TRUE_FOLDS = 4


def contact_edges(r: np.ndarray, pressures) -> np.ndarray:
    """Radii of peak attraction (P most negative), the contact edge, of each pressure profile that attracts."""
    return np.array([r[np.argmin(P)] for P in pressures if P.min() < 0])


def check(model, r: np.ndarray, edges: np.ndarray, folds: int) -> str:
    """One line when the grid cannot resolve the cohesive zone where the contact edge travels, else "".

    ``edges`` are the radii of the contact edge along the curve
    (:func:`contact_edges`); ``folds`` the turning points the curve showed, the
    other symptom (more than :data:`MAX_TRUE_FOLDS`).  The line names the
    spacing the case needs there and a paper grid that has it.
    """
    zone = model.cohesive_zone
    if edges.size == 0 or not np.isfinite(zone):
        return ""
    lo, hi = edges.min(), edges.max()
    h = np.diff(r)
    mid = 0.5 * (r[:-1] + r[1:])
    sel = (mid >= lo - h) & (mid <= hi + h)
    hmax = float(h[sel].max()) if sel.any() else float(h.max())
    need = zone / NODES_PER_ZONE
    if hmax <= need and folds <= MAX_TRUE_FOLDS:
        return ""
    # a paper grid that refines [0, r_edge + 2] enough (the edge may travel further than seen)
    h0 = model.rmax / (PAPER_UNIFORM - 1)
    extra = min(int(np.ceil(min(hi + 2.0, model.rmax) / h0)), PAPER_UNIFORM - 1)
    split = max(2, int(np.ceil(h0 / need)))
    return (f"{folds} turning points; grid spacing {hmax:.3g} where the contact edge travels "
            f"(r in [{lo:.3g}, {hi:.3g}]) does not resolve the cohesive zone {zone:.3g} at mu = {model.mu:g}: "
            f"this case needs spacing <= {need:.3g} there, e.g. -grid_type paper "
            f"-grid_paper_extra {extra} -grid_paper_split {split} ({PAPER_UNIFORM + extra * (split - 1)} nodes)")
