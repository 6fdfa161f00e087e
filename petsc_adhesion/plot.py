"""Figures from result files (matplotlib, imported only when something is drawn).

    petsc-adhesion -adh_mu 1 -out mu1.h5 -plot mu1.png
    python -m petsc_adhesion.plot mu1.h5 mu1.png
"""
from __future__ import annotations

import sys

import h5py
import numpy as np

__all__ = ["read", "read_group", "from_tree", "load_approach", "profiles", "curve_figure"]

MARK = {"snap_on": ("v", "snap-on"), "snap_off": ("^", "snap-off"), "F_min": ("o", "load extremum"),
        "equilibrium": ("s", "equilibrium"), "lambda": ("x", "at lambda")}


def from_tree(tree: dict) -> dict:
    """The layout of :func:`read` from a result tree of :mod:`petsc_adhesion.output` (before it is a file)."""
    return {"mu": tree["model"]["mu"], "sigma": tree["model"]["sigma"], "r": tree["grid"]["r"],
            "curve": tree["curve"], "events": tree["events"]}


def read(path: str) -> dict:
    """A curve result file as plain arrays and event dicts."""
    with h5py.File(path, "r") as f:
        return read_group(f)


def read_group(f) -> dict:
    """A curve's layout from an HDF5 group (a curve file's root, or a study's case)."""
    out = {"mu": f["model"].attrs["mu"], "sigma": f["model"].attrs["sigma"], "r": f["grid/r"][()],
           "curve": {k: v[()] for k, v in f["curve"].items()}, "events": []}
    for name in sorted(f["events"]) if "events" in f else []:
        g = f["events"][name]
        ev = dict(g.attrs)
        ev.update({k: g[k][()] for k in ("r", "H", "P") if k in g})
        if "landing" in g:
            ev["landing"] = dict(g["landing"].attrs) | {k: g["landing"][k][()] for k in ("r", "H", "P")
                                                        if k in g["landing"]}
        out["events"].append(ev)
    return out


def load_approach(ax, res: dict, label: str | None = None, events: bool = True, **style) -> None:
    """F(lambda), stable parts solid and unstable parts dashed, events marked (Figs. 4, 5, 13, 14)."""
    lam, F, stable = res["curve"]["lambda"], res["curve"]["F"], res["curve"]["stable"].astype(bool)
    line, = ax.plot(np.where(stable, lam, np.nan), np.where(stable, F, np.nan),
                    label=label or f"mu = {res['mu']:g}, sigma = {res['sigma']:g}", **style)
    if not stable.all():
        ax.plot(np.where(~stable, lam, np.nan), np.where(~stable, F, np.nan), "--", color=line.get_color())
    if events:
        for ev in res["events"]:
            kind = ev["kind"].decode() if isinstance(ev["kind"], bytes) else ev["kind"]
            if kind == "F_max" or kind not in MARK:
                continue
            ax.plot(ev["lambda"], ev["F"], MARK[kind][0], color=line.get_color(), ms=5)
    ax.set_xlabel("approach lambda")
    ax.set_ylabel("load F / (2 pi R gamma)")
    ax.axhline(0.0, color="0.7", lw=0.5)


def profiles(ax_h, ax_p, r: np.ndarray, H: np.ndarray, P: np.ndarray, label: str, rmax: float = 4.0) -> None:
    """Separation H(r) and pressure P(r) (Figs. 6, 7, 10-12, 15, 16)."""
    sel = r <= rmax
    ax_h.plot(r[sel], H[sel], label=label)
    ax_p.plot(r[sel], P[sel], label=label)
    ax_h.set_ylabel("separation H")
    ax_p.set_ylabel("pressure P")
    ax_p.set_xlabel("r")


def curve_figure(source, out: str, fmt: str = "png") -> None:
    """The load-approach curve of a result file or tree, with its event profiles when stored."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    res = read(source) if isinstance(source, str) else from_tree(source)
    with_profiles = [e for e in res["events"] if "H" in e]
    if with_profiles:
        fig, (ax, ax_h, ax_p) = plt.subplots(3, 1, figsize=(6.4, 9.6))
        for ev in with_profiles:
            kind = ev["kind"].decode() if isinstance(ev["kind"], bytes) else ev["kind"]
            profiles(ax_h, ax_p, ev.get("r", res["r"]), ev["H"], ev["P"], f"{kind} lambda = {ev['lambda']:.4f}")
        ax_h.legend(fontsize=7)
    else:
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
    load_approach(ax, res)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)
    plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python -m petsc_adhesion.plot RESULT.h5 FIGURE.png")
    curve_figure(sys.argv[1], sys.argv[2])
