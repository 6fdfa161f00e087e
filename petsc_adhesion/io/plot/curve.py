"""Figures from result files (matplotlib, imported only when something is drawn).

    petsc-adhesion -adh_mu 1 -out mu1.h5 -plot mu1.png
    petsc-adhesion plot mu1.h5 [-o mu1.pdf]

``petsc-adhesion plot`` draws any result file: a curve (its load-approach curve,
events marked, unstable branches dashed, and the profiles at the events when the
file holds them), a fixed-approach solve (H and P), a study (its own kind of
figure) or a critical study (the boundary of hysteresis); with physical inputs,
a curve gets axes in nm and nN beside the dimensionless ones.  It reads HDF5
only: neither MPI nor PETSc is started.
"""
from __future__ import annotations

import h5py
import numpy as np

from .read import figure, from_tree, legend, read

__all__ = ["load_approach", "profiles", "curve_figure", "solve_figure", "MARK"]


MARK = {"snap_on": ("v", "snap-on"), "snap_off": ("^", "snap-off"), "F_min": ("o", "load extremum"),
        "equilibrium": ("s", "equilibrium"), "lambda": ("x", "at lambda")}


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
    res = read(source) if isinstance(source, str) else from_tree(source)
    with_profiles = [e for e in res["events"] if "H" in e]
    if with_profiles:
        fig = figure(figsize=(6.4, 9.6))
        ax, ax_h, ax_p = fig.subplots(3, 1)
        for ev in with_profiles:
            kind = ev["kind"].decode() if isinstance(ev["kind"], bytes) else ev["kind"]
            profiles(ax_h, ax_p, ev.get("r", res["r"]), ev["H"], ev["P"], f"{kind} lambda = {ev['lambda']:.4f}")
        legend(ax_h, fontsize=7)
    else:
        fig = figure(figsize=(6.4, 4.8))
        ax = fig.subplots()
    load_approach(ax, res)
    legend(ax, fontsize=8)
    if res.get("physical"):
        _physical_axes(ax, res["physical"], ax_p if with_profiles else None)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)


def _physical_axes(ax, phys: dict, ax_p=None) -> None:
    """Secondary axes for a curve with physical inputs: approach in nm (top) and load in nN (right); on
    the pressure profiles ``ax_p``, r in nm (top) and P in MPa (right)."""
    def twin(axis, where, scale, label):
        side = axis.secondary_xaxis if where == "top" else axis.secondary_yaxis
        sec = side(where, functions=(lambda v: v * scale, lambda v: v / scale))
        (sec.set_xlabel if where == "top" else sec.set_ylabel)(label)

    twin(ax, "top", float(phys["approach_nm"]), "approach (nm)")
    twin(ax, "right", float(phys["force_nN"]), "load (nN)")
    if ax_p is not None:
        twin(ax_p, "top", float(phys["radius_nm"]), "r (nm)")
        twin(ax_p, "right", float(phys["pressure_MPa"]), "pressure (MPa)")


def solve_figure(path: str, out: str, fmt: str = "png") -> None:
    """H(r) and P(r) of a fixed-approach solve's file."""
    with h5py.File(path, "r") as f:
        r, sol = f["grid/r"][()], f["solution"]
        H, P, lam, F = sol["H"][()], sol["P"][()], sol.attrs["lambda"], sol.attrs["F"]
        mu = f["model"].attrs["mu"]
    fig = figure(figsize=(6.4, 6.4))
    ax_h, ax_p = fig.subplots(2, 1, sharex=True)
    # out to where the stress has died away (the domain reaches r = 150)
    live = r[np.abs(P) > 1e-3 * np.abs(P).max()] if np.any(P) else r[:1]
    profiles(ax_h, ax_p, r, H, P, f"mu = {mu:g}, lambda = {lam:g}: F = {F:.6g}",
             rmax=min(float(r[-1]), max(4.0, 1.5 * float(live.max()))))
    legend(ax_h, fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)

