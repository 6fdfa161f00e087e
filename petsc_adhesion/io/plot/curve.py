"""Figures from result files (matplotlib, imported only when something is drawn).

    petsc-adhesion -adh_mu 1 -out mu1.h5 -plot mu1.png
    petsc-adhesion plot mu1.h5 [-o mu1.pdf]

``petsc-adhesion plot`` draws any result file: a curve (its load-approach curve,
events marked, unstable branches dashed, and the profiles at the events when the
file holds them), a fixed-approach solve (H and P), a study (its own kind of
figure) or a critical study (the boundary of hysteresis); with physical inputs,
a curve gets axes in nm and nN beside the dimensionless ones.  A curve traced behind
a spring (``-afm_spring``, ``-phys_spring``: the file has the group ``instrument``) is led
by the force curve as the instrument records it (:func:`instrument_panel`: force in nN
against piezo displacement in nm with physical inputs, approach and retract in two
colours, the jumps at constant Z, the jump-in, pull-off and jump-off labelled with their
bars, the energy of the cycle shaded and stated, after the fit's figure,
:mod:`~petsc_adhesion.io.plot.fit`), with the rigid machine's load-approach curve and the
contact radius against the load beside it.  It reads HDF5 only: neither MPI nor PETSc is
started.
"""
from __future__ import annotations

import h5py
import numpy as np

from .read import figure, from_tree, legend, read

__all__ = ["load_approach", "profiles", "force_distance", "contact_load", "curve_figure", "solve_figure", "MARK",
           "stiffness", "instrument_panel", "LEG_COLOURS"]


MARK = {"snap_on": ("v", "snap-on"), "snap_off": ("^", "snap-off"), "F_min": ("o", "load extremum"),
        "equilibrium": ("s", "equilibrium"), "lambda": ("x", "at lambda"), "jump_in": ("<", "jump-in"),
        "jump_off": (">", "jump-off")}
#: The turning points of a spring's base Z.
JUMPS = ("jump_in", "jump_off")


def _kind(ev: dict) -> str:
    return ev["kind"].decode() if isinstance(ev["kind"], bytes) else str(ev["kind"])


def _solid_dashed(ax, x, y, stable, label=None, joints=(), **style):
    """y(x), solid where ``stable``, dashed elsewhere in the same colour, the two joined; the solid line.

    ``joints``: (x, y) of the located turning points (where the stability changes between two computed
    points): each is put between the two points it lies between, on both lines; where none does, the
    dashed line runs on to the stable point next to it.
    """
    x, y, stable = np.asarray(x, float), np.asarray(y, float), np.asarray(stable, bool)
    span = np.array([np.ptp(x[np.isfinite(x)]) if np.isfinite(x).any() else 1.0,
                     np.ptp(y[np.isfinite(y)]) if np.isfinite(y).any() else 1.0])
    span[~(span > 0)] = 1.0
    joints = [np.array(j, float) / span for j in joints]
    xs, ys, solid, dashed = [], [], [], []
    for i in range(x.size):
        xs.append(x[i])
        ys.append(y[i])
        solid.append(stable[i])
        dashed.append(not stable[i])
        if i + 1 < x.size and stable[i] != stable[i + 1]:
            a, b = np.array([x[i], y[i]]) / span, np.array([x[i + 1], y[i + 1]]) / span
            near = [j for j in joints if np.linalg.norm(j - (a + b) / 2) <= max(np.linalg.norm(b - a), 1e-12)]
            if near:
                j = min(near, key=lambda j: np.linalg.norm(j - (a + b) / 2)) * span
                xs.append(j[0])
                ys.append(j[1])
                solid.append(True)
                dashed.append(True)
            else:
                dashed[-1] = True          # the dashed line runs on to this stable point
                if not stable[i]:
                    xs.append(x[i + 1])
                    ys.append(y[i + 1])
                    solid.append(False)
                    dashed.append(True)
    X, Y, on, off = np.array(xs), np.array(ys), np.array(solid), np.array(dashed)
    line, = ax.plot(np.where(on, X, np.nan), np.where(on, Y, np.nan), label=label, **style)
    if off.any():
        ax.plot(np.where(off, X, np.nan), np.where(off, Y, np.nan), "--", color=line.get_color(),
                lw=line.get_linewidth())
    return line


def stiffness(curve: dict) -> float | None:
    """The stiffness K of the spring a curve was traced behind, from its points (Z = lambda + F / K); None
    without a spring."""
    if "Z" not in curve:
        return None
    F, d = np.asarray(curve["F"], float), np.asarray(curve["Z"], float) - np.asarray(curve["lambda"], float)
    i = int(np.argmax(np.abs(F)))
    return float(F[i] / d[i]) if d[i] != 0 else None


def force_distance(ax, res: dict, label: str | None = None, scale: tuple = (1.0, 1.0), **style) -> None:
    """Behind a spring: F against its base Z = lambda + F / K, stable parts (dZ/ds > 0) solid and unstable
    dashed, each jump-in and jump-off marked and drawn as an arrow at constant Z to its landing.
    ``scale``: the factors of Z and F (1, 1: the model's units; the physical ones for nm and nN)."""
    c = res["curve"]
    sz, sf = scale
    K = stiffness(c)
    joints = [(sz * float(e["Z"]), sf * float(e["F"])) for e in res["events"] if _kind(e) in JUMPS]
    line = _solid_dashed(ax, sz * np.asarray(c["Z"]), sf * np.asarray(c["F"]), np.asarray(c["stable_spring"], bool),
                         label=label or (f"mu = {res['mu']:g}, K = {K:.4g}" if K else None), joints=joints, **style)
    for ev in res["events"]:
        kind = _kind(ev)
        if kind not in JUMPS:
            continue
        Z, F = sz * float(ev["Z"]), sf * float(ev["F"])
        ax.plot(Z, F, MARK[kind][0], color=line.get_color(), ms=6)
        land = ev.get("landing")
        if land:
            ax.annotate("", xy=(Z, sf * float(land["F"])), xytext=(Z, F),
                        arrowprops={"arrowstyle": "->", "color": line.get_color(), "lw": 1.0})
            ax.plot(Z, sf * float(land["F"]), "o", mfc="none", color=line.get_color(), ms=4)
    ax.axhline(0.0, color="0.7", lw=0.5)


#: The legs' colours (as the fit's figure, io/plot/fit.py).
LEG_COLOURS = {"approach": "tab:blue", "retract": "tab:red"}


def _pm(value: float, err, scale: float, unit: str) -> str:
    """``value +- bar unit`` in units of ``scale`` (no bar: the value alone)."""
    text = f"{value * scale:.4g}"
    if err is not None and not isinstance(err, (str, bytes)) and np.isfinite(err):
        text += f" +- {abs(err * scale):.2g}"
    return f"{text} {unit}".rstrip()


def _primary(res: dict, kind: str) -> dict | None:
    """The primary jump of ``kind``: the jump-in reached first on approach (largest Z), the jump-off reached
    last on retraction (smallest Z)."""
    evs = [e for e in res["events"] if _kind(e) == kind and "Z" in e]
    if not evs:
        return None
    return (max if kind == "jump_in" else min)(evs, key=lambda e: float(e["Z"]))


def instrument_panel(ax, res: dict) -> None:
    """The force curve as the instrument records it (the file's ``instrument`` group): force against the
    base (piezo) position, the approach and the retract in two colours with their jumps at constant Z, the
    energy of the cycle shaded between them and stated, the primary jump-in, the pull-off (the force the
    retract leaves the contact at) and the jump-off marked and labelled with their best values and bars; in nN
    and nm with physical inputs, else in the model's units."""
    legs, phys, spring = res["instrument"], res.get("physical"), res.get("spring") or {}
    sz, sf = (float(phys["approach_nm"]), float(phys["force_nN"])) if phys else (1.0, 1.0)
    uz, uf = ("nm", "nN") if phys else ("", "")
    Zs, Fs = [], []
    for name in ("approach", "retract"):
        leg = legs[name]
        Z, F = sz * np.asarray(leg["Z"], float), sf * np.asarray(leg["F"], float)
        Zs.append(Z)
        Fs.append(F)
        ax.plot(Z, F, "-", lw=1.4, color=LEG_COLOURS[name], label=name, marker=".", ms=2.5)
        for i in np.asarray(leg["jumps"], int):
            ax.annotate("", xy=(Z[i + 1], F[i + 1]), xytext=(Z[i], F[i]),
                        arrowprops={"arrowstyle": "->", "color": LEG_COLOURS[name], "lw": 1.2})
    energy = spring.get("energy")
    if energy is not None and not isinstance(energy, (str, bytes)):
        scale, unit = (float(phys["work_aJ"]), "aJ") if phys else (1.0, "x 2 pi R gamma epsilon")
        ax.fill(np.r_[Zs[0], Zs[1]], np.r_[Fs[0], Fs[1]], color="0.6", alpha=0.3, lw=0,
                label=f"energy of a cycle {_pm(float(energy), spring.get('energy_err'), scale, unit)}")
    if "trigger" in legs:
        ax.axhline(sf * float(legs["trigger"]), color="0.5", lw=0.8, ls=":",
                   label=f"trigger {_pm(float(legs['trigger']), None, sf, uf)}")
    ax.axhline(0.0, color="0.7", lw=0.5)
    jin, joff = _primary(res, "jump_in"), _primary(res, "jump_off")
    marks = []
    if jin is not None:
        marks.append((jin, float(jin["F"]), "<", "jump-in", f"jump-in: Z = {_pm(float(jin['Z']), jin.get('Z_err'), sz, uz)}, "
                      f"F = {_pm(float(jin['F']), jin.get('F_err'), sf, uf)}"))
    if joff is not None:
        marks.append((joff, float(joff["F"]), "v", "pull-off",
                      f"pull-off: F = {_pm(float(joff['F']), joff.get('F_err'), sf, uf)}"))
        land = joff.get("landing")
        if land:
            marks.append((joff, float(land["F"]), ">", "jump-off",
                          f"jump-off: Z = {_pm(float(joff['Z']), joff.get('Z_err'), sz, uz)}"))
    for ev, at, marker, _, text in marks:
        bar_F = sf * float(ev.get("F_err", 0.0) or 0.0) if at == float(ev["F"]) else None   # a landing: no F bar
        ax.errorbar(sz * float(ev["Z"]), sf * at, xerr=sz * float(ev.get("Z_err", 0.0) or 0.0), yerr=bar_F,
                    fmt=marker, color="k", ms=7, mfc="none", capsize=3, label=text)
    ax.set_xlabel("piezo displacement Z (nm)" if phys else "base of the spring Z / epsilon")
    ax.set_ylabel("force (nN)" if phys else "force F / (2 pi R gamma)")
    K = float(legs["K"])
    lever = f"k = {K * sf / sz:.3g} N/m" if phys else f"K = {K:.4g}"
    ax.set_title(f"approach and retract behind the cantilever ({lever}): jumps at constant Z", fontsize=10)


def contact_load(ax, res: dict, label: str | None = None, **style) -> None:
    """The contact radius against the load along the curve: solid where stable (behind a spring, under it),
    the jumps of a spring (or the snaps of a rigid machine) drawn as arrows to their landings."""
    c = res["curve"]
    stable = np.asarray(c["stable_spring"] if "stable_spring" in c else c["stable"], bool)
    jumps = JUMPS if "Z" in c else ("snap_on", "snap_off")
    joints = [(float(e["F"]), float(e["contact_radius"])) for e in res["events"]
              if _kind(e) in jumps and "contact_radius" in e]
    line = _solid_dashed(ax, np.asarray(c["F"]), np.asarray(c["contact_radius"]), stable, label=label, joints=joints,
                         **style)
    for ev in res["events"]:
        kind, land = _kind(ev), ev.get("landing")
        if kind not in jumps or not land or "contact_radius" not in ev or "contact_radius" not in land:
            continue
        ax.plot(ev["F"], ev["contact_radius"], MARK[kind][0], color=line.get_color(), ms=6)
        ax.annotate("", xy=(land["F"], land["contact_radius"]), xytext=(ev["F"], ev["contact_radius"]),
                    arrowprops={"arrowstyle": "->", "color": line.get_color(), "lw": 1.0})
    ax.set_xlabel("load F / (2 pi R gamma)")
    ax.set_ylabel("contact radius a / sqrt(epsilon R)")


def load_approach(ax, res: dict, label: str | None = None, events: bool = True, **style) -> None:
    """F(lambda), stable parts solid and unstable parts dashed, events marked (Figs. 4, 5, 13, 14)."""
    lam, F, stable = res["curve"]["lambda"], res["curve"]["F"], res["curve"]["stable"].astype(bool)
    joints = [(float(e["lambda"]), float(e["F"])) for e in res["events"] if _kind(e) in ("snap_on", "snap_off")]
    line = _solid_dashed(ax, lam, F, stable, label=label or f"mu = {res['mu']:g}, sigma = {res['sigma']:g}",
                         joints=joints, **style)
    if events:
        for ev in res["events"]:
            kind = _kind(ev)
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
    """The load-approach curve of a result file or tree, with its event profiles when stored; behind a
    spring, the force curve as the instrument records it first and largest (:func:`instrument_panel`), beside
    it the rigid machine's load-approach curve and the contact radius against the load."""
    res = read(source) if isinstance(source, str) else from_tree(source)
    with_profiles = [e for e in res["events"] if "H" in e]
    spring = "Z" in res["curve"] and "stable_spring" in res["curve"]
    legs = res.get("instrument")
    legs = legs if legs and "approach" in legs else None
    ax_z = ax_a = ax_p = ax_i = None
    if spring:
        rows = 3 if with_profiles else 2
        fig = figure(figsize=(14.0, 10.5) if with_profiles else (14.0, 7.0))
        grid = fig.add_gridspec(rows, 3)
        if legs is not None:
            ax_i = fig.add_subplot(grid[:2, :2])
            ax = fig.add_subplot(grid[0, 2])
            ax_a = fig.add_subplot(grid[1, 2])
        else:                            # no legs (no state stable behind the spring): the traced curve
            ax_z = fig.add_subplot(grid[:2, :2])
            ax = fig.add_subplot(grid[0, 2])
            ax_a = fig.add_subplot(grid[1, 2])
        if with_profiles:
            ax_h, ax_p = fig.add_subplot(grid[2, 0]), fig.add_subplot(grid[2, 1])
    elif with_profiles:
        fig = figure(figsize=(6.4, 9.6))
        ax, ax_h, ax_p = fig.subplots(3, 1)
    else:
        fig = figure(figsize=(6.4, 4.8))
        ax = fig.subplots()
    for ev in with_profiles:
        profiles(ax_h, ax_p, ev.get("r", res["r"]), ev["H"], ev["P"], f"{_kind(ev)} lambda = {ev['lambda']:.4f}")
    if with_profiles:
        legend(ax_h, fontsize=7)
    load_approach(ax, res)
    legend(ax, fontsize=8)
    if spring:
        assert ax_a is not None, "the spring's axes are made above"
        ax.set_title("the rigid machine (load against approach)", fontsize=9)
        if ax_i is not None:
            instrument_panel(ax_i, res)
            legend(ax_i, fontsize=8, loc="best")
        else:
            assert ax_z is not None, "the traced curve's axes without legs"
            force_distance(ax_z, res)
            ax_z.set_xlabel("base of the spring Z = lambda + F / K")
            ax_z.set_ylabel("load F / (2 pi R gamma)")
            ax_z.set_title("behind the spring: jumps at constant Z (arrows)", fontsize=9)
            legend(ax_z, fontsize=8)
        if "contact_radius" in res["curve"]:
            contact_load(ax_a, res)
        else:
            ax_a.remove()
            ax_a = None
    if res.get("physical"):
        _physical_axes(ax, res["physical"], ax_p, ax_z, ax_a)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)


def _twin(axis, where: str, scale: float, label: str) -> None:
    side = axis.secondary_xaxis if where == "top" else axis.secondary_yaxis
    sec = side(where, functions=(lambda v: v * scale, lambda v: v / scale))
    (sec.set_xlabel if where == "top" else sec.set_ylabel)(label)


def _physical_axes(ax, phys: dict, ax_p=None, ax_z=None, ax_a=None) -> None:
    """Secondary axes for a curve with physical inputs: approach in nm (top) and load in nN (right); on
    the pressure profiles ``ax_p``, r in nm (top) and P in MPa (right); behind a spring, Z in nm and the
    load in nN on ``ax_z``, the load in nN and the contact radius in nm on ``ax_a``."""
    _twin(ax, "top", float(phys["approach_nm"]), "approach (nm)")
    _twin(ax, "right", float(phys["force_nN"]), "load (nN)")
    if ax_p is not None:
        _twin(ax_p, "top", float(phys["radius_nm"]), "r (nm)")
        _twin(ax_p, "right", float(phys["pressure_MPa"]), "pressure (MPa)")
    if ax_z is not None:
        _twin(ax_z, "top", float(phys["approach_nm"]), "Z (nm)")
        _twin(ax_z, "right", float(phys["force_nN"]), "load (nN)")
    if ax_a is not None:
        _twin(ax_a, "top", float(phys["force_nN"]), "load (nN)")
        _twin(ax_a, "right", float(phys["radius_nm"]), "contact radius (nm)")


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

