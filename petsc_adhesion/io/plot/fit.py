"""The figure of a fitted force curve: the measured points and the fitted model over them, and the residuals
(``-fit_curve`` with ``-plot``, or ``petsc-adhesion plot FIT.h5``)."""
from __future__ import annotations

import h5py
import numpy as np

from .read import figure, legend

__all__ = ["fit_figure", "read_fit"]


def read_fit(source) -> dict:
    """The ``fit`` group of a result file, or of a tree, as plain arrays and values."""
    if not isinstance(source, str):
        return source["fit"]
    with h5py.File(source, "r") as f:
        g = f["fit"]
        out = {k: v for k, v in g.attrs.items()}
        for name in ("data", "model"):
            if name in g:
                out[name] = {k: v[()] for k, v in g[name].items()}
        if "instrument" in g:
            out["instrument"] = dict(g["instrument"].attrs)
        return out


def _pm(fit: dict, key: str, scale: float) -> str:
    """``value +- bar`` of ``key`` in units of ``scale``: "undetermined" where the fit has no value (null in
    JSON, an empty string in HDF5), the value alone where it has no bar (held)."""
    def number(k):
        v = fit.get(k)
        return None if v is None or isinstance(v, (str, bytes)) else float(v)

    v, e = number(key), number(f"{key}_err")
    if v is None:
        return "undetermined"
    return f"{v / scale:.4g}" + (f" +- {e / scale:.2g}" if e is not None else " (held)")


def fit_figure(source, out: str, fmt: str = "png") -> None:
    """Force (nN) against the piezo displacement (nm) of a fitted curve: approach and retract measured, the
    fitted model as lines, the points left out of the fit hollow; below, the residuals in units of the
    noise."""
    fit = read_fit(source)
    if "data" not in fit:
        from ...errors import InputError

        raise InputError("plot: a fit of a pull-off force has no curve to draw")
    d, m = fit["data"], fit.get("model")
    fig = figure(figsize=(7.5, 6.5))
    ax, rx = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    z, F, leg, used = d["z"] * 1e9, d["F"] * 1e9, np.asarray(d["leg"]), np.asarray(d["used"], bool)
    noise = float(fit["noise_N"]) * 1e9
    for k, (name, colour) in enumerate((("approach", "tab:blue"), ("retract", "tab:red"))):
        sel = leg == k
        ax.plot(z[sel & used], F[sel & used], ".", ms=3, color=colour, alpha=0.5, label=f"{name}, measured")
        if np.any(sel & ~used):
            ax.plot(z[sel & ~used], F[sel & ~used], "o", ms=4, mfc="none", color=colour, alpha=0.6,
                    label=f"{name}, left out (at a jump, or outside the segment or range fitted)")
        if m is not None:
            ax.plot(m["z"] * 1e9, m[f"F_{name}"] * 1e9, "-", lw=1.5, color="k" if k else "0.4",
                    label=f"{name}, fitted model")
        rx.plot(z[sel & used], (d["F_fit"][sel & used] * 1e9 - F[sel & used]) / noise, ".", ms=2, color=colour)
    ins = fit.get("instrument")
    scale = f"\nthe sensitivity times {_pm(ins, 'invols_scale', 1.0)}" if isinstance(ins, dict) else ""
    ax.set_title(f"gamma = {_pm(fit, 'gamma', 1.0)} J/m^2, E* = {_pm(fit, 'E_star', 1e9)} GPa, "
                 f"mu = {float(fit['mu']):.3g}{scale}", fontsize=10)
    ax.set_ylabel("force (nN)")
    rx.axhline(0.0, color="0.5", lw=0.8)
    rx.set_ylabel("(fit - data) / noise")
    rx.set_xlabel("piezo displacement z (nm)")
    legend(ax, fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)
