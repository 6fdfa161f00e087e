"""Result files read back for their figures (a curve's layout from an HDF5 file or group, or from a tree), and the
figure they are drawn on."""
from __future__ import annotations

import os
import sys

import h5py

__all__ = ["from_tree", "read", "read_group", "figure", "legend"]


def figure(**kw):
    """A matplotlib Figure drawn by Agg into files, whatever the session's backend and MPLBACKEND say.

    No pyplot: the figure belongs to no window and switches no backend of a notebook's; and an
    MPLBACKEND that names no backend (matplotlib refuses to import then) is set aside while matplotlib
    is first imported, since nothing here shows a window.
    """
    saved = None if "matplotlib" in sys.modules else os.environ.pop("MPLBACKEND", None)
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    finally:
        if saved is not None:
            os.environ["MPLBACKEND"] = saved
    fig = Figure(**kw)
    FigureCanvasAgg(fig)
    return fig


def legend(ax, **kw) -> None:
    """The legend of ``ax`` when something on it has a label (matplotlib warns on an empty one)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(**kw)


def from_tree(tree: dict) -> dict:
    """The layout of :func:`read` from a result tree of :mod:`petsc_adhesion.io.write` (before it is a file)."""
    return {"mu": tree["model"]["mu"], "sigma": tree["model"]["sigma"], "r": tree["grid"]["r"],
            "curve": tree["curve"], "events": tree["events"], "physical": tree.get("physical"),
            "instrument": tree.get("instrument"), "spring": tree.get("summary", {}).get("spring")}


def read(path: str) -> dict:
    """A curve result file as plain arrays and event dicts."""
    with h5py.File(path, "r") as f:
        return read_group(f)


def _legs(g) -> dict:
    """The group ``instrument`` (the legs behind a spring): its attributes and a dict of arrays per leg."""
    return dict(g.attrs) | {name: {k: v[()] for k, v in g[name].items()} for name in g}


def read_group(f) -> dict:
    """A curve's layout from an HDF5 group (a curve file's root, or a study's case)."""
    out = {"mu": f["model"].attrs["mu"], "sigma": f["model"].attrs["sigma"], "r": f["grid/r"][()],
           "curve": {k: v[()] for k, v in f["curve"].items()}, "events": [],
           "physical": dict(f["physical"].attrs) if "physical" in f else None,
           "instrument": _legs(f["instrument"]) if "instrument" in f else None,
           "spring": dict(f["summary/spring"].attrs) if "summary/spring" in f else None}
    for name in sorted(f["events"]) if "events" in f else []:
        g = f["events"][name]
        ev = dict(g.attrs)
        ev.update({k: g[k][()] for k in ("r", "H", "P") if k in g})
        if "landing" in g:
            ev["landing"] = dict(g["landing"].attrs) | {k: g["landing"][k][()] for k in ("r", "H", "P")
                                                        if k in g["landing"]}
        out["events"].append(ev)
    return out
