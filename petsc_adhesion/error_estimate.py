"""The error of each event: discretization (Richardson from a second trace) and domain truncation.

Discretization: the same curve traced on every other node; for a
second-order method the error of the fine value is about |X_h - X_2h| / 3
(Richardson).  Domain truncation of F: the attraction of the rigid sphere
beyond r_m (:func:`petsc_adhesion.reference.load_beyond`).
"""
from __future__ import annotations

import numpy as np

from .reference import load_beyond

__all__ = ["coarsen", "attach"]


def coarsen(r: np.ndarray) -> np.ndarray:
    """Every other node of r, keeping both ends."""
    return r[::2] if r.size % 2 else np.append(r[::2], r[-1])


def _by_kind(events) -> dict:
    out = {}
    for e in events:
        out.setdefault(e["kind"], []).append(e)
    return out


def attach(fine: dict, coarse: dict, rmax: float) -> None:
    """Give the events of ``fine`` their error estimates from ``coarse`` (in place).

    Events are matched by kind and order; a kind whose count differs between
    the two traces gets no discretization estimate.  Each event gets
    ``F_truncation``, the magnitude of the load carried beyond r_m.
    """
    cs = _by_kind(coarse["events"])
    for kind, evs in _by_kind(fine["events"]).items():
        matched = len(cs.get(kind, [])) == len(evs)
        for i, e in enumerate(evs):
            e["F_truncation"] = float(abs(load_beyond(rmax, e["lambda"])))
            if matched:
                c = cs[kind][i]
                e["lambda_err"] = abs(e["lambda"] - c["lambda"]) / 3
                e["F_err"] = abs(e["F"] - c["F"]) / 3
    fine["error_estimate"] = {"coarse_wall_time_s": coarse["wall_time_s"],
                              "coarse_events_matched": all(len(cs.get(k, [])) == len(v)
                                                           for k, v in _by_kind(fine["events"]).items())}
