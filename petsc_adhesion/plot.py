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

import sys

import h5py
import numpy as np

__all__ = ["read", "read_group", "from_tree", "load_approach", "profiles", "curve_figure", "solve_figure", "command",
           "USAGE"]

USAGE = "usage: petsc-adhesion plot RESULT.h5 [-o OUT.png|OUT.pdf|OUT.svg]   (default OUT: RESULT.png)"

MARK = {"snap_on": ("v", "snap-on"), "snap_off": ("^", "snap-off"), "F_min": ("o", "load extremum"),
        "equilibrium": ("s", "equilibrium"), "lambda": ("x", "at lambda")}


def from_tree(tree: dict) -> dict:
    """The layout of :func:`read` from a result tree of :mod:`petsc_adhesion.output` (before it is a file)."""
    return {"mu": tree["model"]["mu"], "sigma": tree["model"]["sigma"], "r": tree["grid"]["r"],
            "curve": tree["curve"], "events": tree["events"], "physical": tree.get("physical")}


def read(path: str) -> dict:
    """A curve result file as plain arrays and event dicts."""
    with h5py.File(path, "r") as f:
        return read_group(f)


def read_group(f) -> dict:
    """A curve's layout from an HDF5 group (a curve file's root, or a study's case)."""
    out = {"mu": f["model"].attrs["mu"], "sigma": f["model"].attrs["sigma"], "r": f["grid/r"][()],
           "curve": {k: v[()] for k, v in f["curve"].items()}, "events": [],
           "physical": dict(f["physical"].attrs) if "physical" in f else None}
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
    if res.get("physical"):
        _physical_axes(ax, res["physical"], ax_p if with_profiles else None)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)
    plt.close(fig)


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
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with h5py.File(path, "r") as f:
        r, sol = f["grid/r"][()], f["solution"]
        H, P, lam, F = sol["H"][()], sol["P"][()], sol.attrs["lambda"], sol.attrs["F"]
        mu = f["model"].attrs["mu"]
    fig, (ax_h, ax_p) = plt.subplots(2, 1, figsize=(6.4, 6.4), sharex=True)
    # out to where the stress has died away (the domain reaches r = 150)
    live = r[np.abs(P) > 1e-3 * np.abs(P).max()] if np.any(P) else r[:1]
    profiles(ax_h, ax_p, r, H, P, f"mu = {mu:g}, lambda = {lam:g}: F = {F:.6g}",
             rmax=min(float(r[-1]), max(4.0, 1.5 * float(live.max()))))
    ax_h.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)
    plt.close(fig)


def _kind(path: str) -> str:
    """The ``kind`` of a result file; InputError for what is not one."""
    import os

    from .errors import InputError

    if not os.path.isfile(path):
        raise InputError(f"plot: no file '{path}'")
    try:
        with h5py.File(path, "r") as f:
            kind = f.attrs.get("kind")
    except OSError:
        raise InputError(f"plot: '{path}' is not an HDF5 file") from None
    kind = kind.decode() if isinstance(kind, bytes) else kind
    if kind not in ("curve", "solve", "study", "critical"):
        raise InputError(f"plot: '{path}' is not a petsc-adhesion result (no curve, solve, study or critical kind)")
    return kind


def _draw(kind: str, path: str, out: str, fmt: str) -> None:
    from . import studyplot

    if kind == "curve":
        curve_figure(path, out, fmt)
    elif kind == "solve":
        solve_figure(path, out, fmt)
    elif kind == "critical":
        studyplot.critical_figure(path, out, fmt)
    else:
        with h5py.File(path, "r") as f:
            drawn = f["study"].attrs.get("plot", "curves")
        studyplot.study_figure(path, out, drawn.decode() if isinstance(drawn, bytes) else drawn, fmt)


def command(args: list[str]) -> int:
    """``petsc-adhesion plot RESULT.h5 [-o OUT]``: the figure of a result file, written whole or not at all.

    Returns 0, or 2 after one line on stderr (a missing or foreign file, a bad argument, an output
    that cannot be written or would overwrite the input).
    """
    import os

    from .errors import InputError, say
    from .files import PLOT_FORMATS, check_targets, written

    if args in (["-h"], ["-help"], ["--help"]):
        print(USAGE)
        return 0
    try:
        if len(args) not in (1, 3) or (len(args) == 3 and args[1] != "-o") or args[0].startswith("-"):
            raise InputError(f"plot: expected RESULT.h5 [-o OUT], got '{' '.join(args)}' ({USAGE})")
        src = args[0]
        out = args[2] if len(args) == 3 else os.path.splitext(src)[0] + ".png"
        ext = os.path.splitext(out)[1].lower()
        if ext not in PLOT_FORMATS:
            raise InputError(f"-o: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{out}'")
        kind = _kind(src)
        check_targets({"o": out}, {"plot": [src]})
        with written({"o": out}) as files:
            _draw(kind, src, files.temp("o"), PLOT_FORMATS[ext])
            files.commit()
    except InputError as e:
        say(f"error: {e}")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(command(sys.argv[1:]))
