"""Figures of a study (:mod:`petsc_adhesion.app.study`): its curves, profiles and maps.

    petsc-adhesion -options_file options/fig18.opts          # -plot docs/figures/fig18.png
    python -m petsc_adhesion.io.plot.study STUDY.h5 OUT.png [KIND]

The kinds are those of ``-study_plot``: ``curves`` (paper Figs. 4, 5, 8, 13, 14),
``folds`` (one panel per case about its turning points, Fig. 9), ``profiles``
(Figs. 6, 7, 10-12, 15, 16), ``pull_off`` (against mu, Fig. 18) and
``reduction`` (1 - F_p(sigma) / F_p(0) against sigma, Fig. 17).  The maps read
the study's event table; every pull-off is drawn with its error bar.  A critical
study (``-study_compute critical``) draws the boundary of hysteresis in (mu, sigma)
(:func:`critical_figure`).
"""
from __future__ import annotations

import sys
from collections import defaultdict

import numpy as np

from .curve import load_approach, profiles
from .read import figure, from_tree, legend, read_group

__all__ = ["read_study", "study_figure", "pull_offs", "read_critical", "critical_figure", "KINDS"]

_NAMES = {"adh_mu": "mu", "adh_sigma": "sigma"}


def read_study(path: str) -> dict:
    """A study file as the tree :func:`~petsc_adhesion.io.write.write_study` wrote (what the figures use)."""
    import h5py

    with h5py.File(path, "r") as f:
        if f.attrs.get("kind") != "study":
            raise ValueError(f"'{path}' is not a study result (its kind is '{f.attrs.get('kind', '')}')")
        study = dict(f["study"].attrs)
        study["axes"] = [a.decode() if isinstance(a, bytes) else str(a) for a in study["axes"]]
        cases = []
        for name in sorted(f["cases"]) if "cases" in f else []:
            g = f["cases"][name]
            values = {k: v for k, v in g["values"].attrs.items() if k not in ("units", "description")}
            cases.append({"case": int(g.attrs["case"]), "values": values, **read_group(g)})
        table = {k: v[()] for k, v in f["table"].items()}
    return {"study": study, "cases": cases, "table": table}


def _cases(tree: dict) -> list[dict]:
    return [c if "mu" in c else {"case": c["case"], "values": c["values"], **from_tree(c)} for c in tree["cases"]]


def _label(values: dict, skip=()) -> str:
    return ", ".join(f"{_NAMES.get(k, k)} = {v:g}" for k, v in values.items() if k not in skip)


def _kind(e: dict) -> str:
    k = e["kind"]
    return k.decode() if isinstance(k, bytes) else str(k)


def pull_offs(table: dict) -> dict:
    """Each case's pull-off from the event table: case -> (F, F_err, lambda, lambda_err); the most
    tensile load minimum (NaN bars where a case has none)."""
    out: dict[int, tuple[float, float, float, float]] = {}
    for i, kind, F, Fe, lam, le in zip(table["case"], table["kind"], table["F"], table["F_err"], table["lambda"],
                                       table["lambda_err"]):
        kind = kind.decode() if isinstance(kind, bytes) else str(kind)
        if kind == "F_min" and (int(i) not in out or F < out[int(i)][0]):
            out[int(i)] = (float(F), float(Fe), float(lam), float(le))
    return out


def _by_case(table: dict, axes: list[str]) -> dict:
    """case -> its values of the swept options, from the table."""
    return {int(i): {a: float(table[a][k]) for a in axes} for k, i in enumerate(table["case"])}


def _curves(fig, tree):
    ax = fig.add_subplot(111)
    for c in _cases(tree):
        load_approach(ax, c, label=_label(c["values"]))
    legend(ax, fontsize=7)


def _folds(fig, tree):
    cs = _cases(tree)
    cols = min(3, len(cs))
    rows = -(-len(cs) // cols)
    fig.set_size_inches(4.0 * cols, 3.2 * rows)
    for k, c in enumerate(cs):
        ax = fig.add_subplot(rows, cols, k + 1)
        folds = [e["lambda"] for e in c["events"] if _kind(e) in ("snap_on", "snap_off")]
        load_approach(ax, c, label=_label(c["values"]))
        if folds:
            lo, hi = min(folds), max(folds)
            pad = max(0.15 * (hi - lo), 0.02)
            lam, F = c["curve"]["lambda"], c["curve"]["F"]
            near = (lam > lo - pad) & (lam < hi + pad)
            ax.set_xlim(lo - pad, hi + pad)
            if near.any():
                f0, f1 = F[near].min(), F[near].max()
                ax.set_ylim(f0 - 0.1 * (f1 - f0 + 1e-3), f1 + 0.1 * (f1 - f0 + 1e-3))
        ax.set_title(_label(c["values"]) + f": {len(folds)} turning points", fontsize=8)


def _profiles(fig, tree):
    ax_h, ax_p = fig.add_subplot(211), fig.add_subplot(212, sharex=None)
    fig.set_size_inches(6.4, 7.2)
    for c in _cases(tree):
        minima = [e for e in c["events"] if _kind(e) == "F_min"]
        for e in c["events"]:
            if "H" not in e or (minima and _kind(e) == "F_min" and e is not min(minima, key=lambda m: m["F"])):
                continue                                  # of the load minima, the pull-off
            name = f"{_label(c['values'])}: {'pull-off' if _kind(e) == 'F_min' else _kind(e)}"
            if "H" in e.get("landing", {}):
                name += " (before the jump)"
            reach = max(4.0, 1.5 * float(e["r"][np.argmin(e["P"])]))
            profiles(ax_h, ax_p, e["r"], e["H"], e["P"], name, rmax=reach)
            land = e.get("landing", {})
            if "H" in land:
                profiles(ax_h, ax_p, land["r"], land["H"], land["P"], name.replace("before", "after"), rmax=reach)
    legend(ax_h, fontsize=6)


def _series(tree: dict, x: str):
    """(series label, [(x, F_p, F_err, case)]) grouped by the swept options other than ``x``."""
    table, axes = tree["table"], tree["study"]["axes"]
    values, po = _by_case(table, axes), pull_offs(table)
    groups = defaultdict(list)
    for case, (F, Fe, _, _) in po.items():
        v = values[case]
        groups[_label(v, skip=(x,))].append((v[x], F, 0.0 if Fe != Fe else Fe, case))
    return {k: sorted(g) for k, g in groups.items()}


def _pull_off(fig, tree):
    from ...model.reference.maugis_dugdale import maugis_dugdale_pull_off

    ax = fig.add_subplot(111)
    lo, hi = np.inf, 0.0
    for label, pts in _series(tree, "adh_mu").items():
        x, F, e, _ = map(np.array, zip(*pts))
        ax.errorbar(x, F, yerr=e, marker="o", ms=3, capsize=2, label=label or "ours")
        lo, hi = min(lo, x[x > 0].min(initial=np.inf)), max(hi, x.max())
    mus = np.geomspace(lo, hi, 60) if lo < hi else np.array([])
    ax.plot(mus, maugis_dugdale_pull_off(mus), "k:", lw=1, label="Maugis-Dugdale (smooth)")
    ax.axhline(-1.0, color="0.5", lw=0.7, ls="--", label="DMT, -1")
    ax.axhline(-0.75, color="0.5", lw=0.7, ls="-.", label="JKR, -0.75")
    ax.set_xscale("log")
    ax.set_xlabel("Tabor parameter mu")
    ax.set_ylabel("pull-off F_p / (2 pi R gamma)")
    legend(ax, fontsize=7)


def _reduction(fig, tree):
    ax = fig.add_subplot(111)
    for label, pts in _series(tree, "adh_sigma").items():
        smooth = [p for p in pts if p[0] == 0.0]
        if not smooth:
            continue
        F0, e0 = smooth[0][1], smooth[0][2]
        x = np.array([p[0] for p in pts])
        F, e = np.array([p[1] for p in pts]), np.array([p[2] for p in pts])
        phi = 1.0 - F / F0
        bar = (e + np.abs(F / F0) * e0) / abs(F0)
        ax.errorbar(x, 100 * phi, yerr=100 * bar, marker="o", ms=3, capsize=2, label=label)
    ax.set_xlabel("roughness sigma")
    ax.set_ylabel("reduction of the pull-off, 1 - F_p / F_p(0)  (%)")
    legend(ax, fontsize=7)


KINDS = {"curves": _curves, "folds": _folds, "profiles": _profiles, "pull_off": _pull_off,
         "reduction": _reduction}


def read_critical(path: str) -> dict:
    """A critical study's file (``-study_compute critical``): its two tables, as columns."""
    import h5py

    with h5py.File(path, "r") as f:
        if f.attrs.get("kind") != "critical":
            raise ValueError(f"'{path}' is not a critical study (its kind is '{f.attrs.get('kind', '')}')")
        return {name: {k: v[()] for k, v in f[name].items()} for name in ("critical_roughness", "critical_mu")
                if name in f}


def critical_figure(source, out: str, fmt: str = "png") -> None:
    """The boundary of hysteresis in (mu, sigma): sigma_c(mu) and mu_c(sigma) with their error bars,
    from a critical study's tree or file."""
    tree = read_critical(source) if isinstance(source, str) else source
    fig = figure(figsize=(6.4, 4.8))
    ax = fig.subplots()
    rough, crit = tree.get("critical_roughness"), tree.get("critical_mu")
    if rough is not None and rough["mu"].size:
        ax.errorbar(rough["mu"], rough["sigma_c"], yerr=rough["sigma_c_err"], marker="o", ms=4, capsize=2,
                    label="sigma_c(mu): fold continued in sigma")
    if crit is not None and crit["sigma"].size:
        ax.errorbar(crit["mu_c"], crit["sigma"], xerr=crit["mu_c_err"], marker="s", ms=4, mfc="none", ls="none",
                    capsize=2, label="mu_c(sigma): fold continued in mu")
    ax.set_xscale("log")
    ax.set_xlabel("Tabor parameter mu")
    ax.set_ylabel("roughness sigma / epsilon")
    ax.text(0.97, 0.05, "snap-on and snap-off\n(hysteresis)", transform=ax.transAxes, ha="right", fontsize=8)
    ax.text(0.03, 0.93, "no turning points", transform=ax.transAxes, va="top", fontsize=8)
    legend(ax, fontsize=7, loc="upper center")
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)


def study_figure(source, out: str, kind: str, fmt: str = "png") -> None:
    """Draw ``kind`` (one of KINDS) from a study tree or file into ``out``."""
    tree = read_study(source) if isinstance(source, str) else source
    fig = figure(figsize=(6.4, 4.8))
    KINDS[kind](fig, tree)
    fig.tight_layout()
    fig.savefig(out, dpi=120, format=fmt)


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        sys.exit("usage: python -m petsc_adhesion.io.plot.study STUDY.h5 OUT.png [KIND]")
    if (sys.argv[3:] or [""])[0] == "critical":
        critical_figure(sys.argv[1], sys.argv[2])
    else:
        src = read_study(sys.argv[1])
        study_figure(src, sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else src["study"]["plot"])
