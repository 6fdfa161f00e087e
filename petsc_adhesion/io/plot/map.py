"""The figure of a force map: each quantity on the sample in physical units with its colour bar, its
histogram beneath (``-fit_map`` with ``-plot``, or ``petsc-adhesion plot MAP.h5``)."""
from __future__ import annotations

import h5py
import numpy as np

from .read import figure

__all__ = ["map_figure", "read_map", "PANELS"]

#: The panels: the image's name, its label and the unit it is drawn in (its scale from SI).
PANELS = (("gamma", "work of adhesion w", "mJ/m$^2$", 1e-3), ("E_star", "reduced modulus E*", "MPa", 1e6),
          ("pull_off", "pull-off", "nN", 1e-9), ("energy", "energy of a cycle", "aJ", 1e-18))


def read_map(source) -> dict:
    """A map file's (or tree's) images, grid and counts as plain values."""
    if not isinstance(source, str):
        return {"images": source["images"], "attrs": source["attrs"]}
    with h5py.File(source, "r") as f:
        return {"images": {k: v[()] for k, v in f["images"].items()}, "attrs": dict(f.attrs)}


def _extent(attrs: dict, shape: tuple):
    """The image's extent in um where the grid's size and origin are known, else in pixels."""
    size, origin = attrs.get("grid_size_m"), attrs.get("grid_origin_m")
    ny, nx = shape
    if isinstance(size, (np.ndarray, list)) and isinstance(origin, (np.ndarray, list)):
        dx, dy = size[0] / nx, size[1] / ny
        x0, y0 = origin[0] - dx / 2, origin[1] - dy / 2
        return [x0 * 1e6, (x0 + size[0]) * 1e6, y0 * 1e6, (y0 + size[1]) * 1e6], "x [um]", "y [um]"
    return [-0.5, nx - 0.5, -0.5, ny - 0.5], "pixel x", "pixel y"


def map_figure(source, out: str, fmt: str = "png") -> None:
    """Draw the map of ``source`` (a file or a tree of :func:`~petsc_adhesion.io.map.map_tree`) into ``out``."""
    m = read_map(source)
    attrs = m["attrs"]
    fig = figure(figsize=(4.2 * len(PANELS), 7.2))
    for j, (name, label, unit, scale) in enumerate(PANELS):
        img = np.asarray(m["images"][name], dtype=float) / scale
        ax, hx = fig.add_subplot(2, len(PANELS), j + 1), fig.add_subplot(2, len(PANELS), len(PANELS) + j + 1)
        extent, xl, yl = _extent(attrs, img.shape)
        ok = np.isfinite(img)
        shown = np.ma.masked_invalid(img)
        im = ax.imshow(shown, origin="lower", extent=extent, cmap="viridis", interpolation="nearest")
        im.cmap.set_bad("0.85")
        fig.colorbar(im, ax=ax, label=f"{label} [{unit}]", shrink=0.85)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_title(f"{label}: {int(ok.sum())} pixels", fontsize=10)
        if ok.any():
            hx.hist(img[ok], bins=max(5, min(40, int(ok.sum()) // 2)), color="C0")
        else:
            hx.text(0.5, 0.5, "no pixel whose fit holds", ha="center", va="center", transform=hx.transAxes)
        hx.set_xlabel(f"{label} [{unit}]")
        hx.set_ylabel("pixels")
    counts = ", ".join(f"{int(attrs[f'n_{s}'])} {s}" for s in ("ok", "warned", "refused", "outside", "unreadable",
                                                               "failed") if int(attrs.get(f"n_{s}", 0)))
    fig.suptitle(f"{attrs.get('source', '')}: {counts} (grey: no curve, or its fit does not hold)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, format=fmt, dpi=110)
