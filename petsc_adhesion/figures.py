"""The figures and tables of docs/: each made by one function here, from real runs.

    ./run figures                  # all of them, into docs/figures/
    ./run figures convergence      # one

Every figure NAME.png comes with NAME.md, the table of the numbers behind it, which
docs/results.md includes by reference; rerun after any change to the solver.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .reference import rigid_load
from .plot import load_approach, profiles, read

__all__ = ["FIGURES", "run", "runs"]

OUT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "docs", "figures")
TMP = tempfile.mkdtemp(prefix="petsc-adhesion-figures-")


def run(*args) -> tuple[dict, str]:
    """One petsc-adhesion run: its JSON summary and the path of its HDF5 file."""
    tag = "_".join(str(a).lstrip("-") for a in args).replace("/", "")
    h5, js = f"{TMP}/{tag}.h5", f"{TMP}/{tag}.json"
    cmd = [sys.executable, "-m", "petsc_adhesion", *map(str, args), "-out", h5, "-summary", js]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode:
        raise RuntimeError(f"{' '.join(cmd)}: {proc.stderr.strip()}")
    with open(js) as f:
        return json.load(f), h5


def runs(cases, workers: int = 2):
    """Run cases (argument tuples), two at a time by default: the machines we target have 2 cores."""
    with ThreadPoolExecutor(workers) as pool:
        return list(pool.map(lambda a: run(*a), cases))


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, name: str, table: str, command: str) -> None:
    fig.tight_layout()
    fig.savefig(f"{OUT}/{name}.png", dpi=110)
    with open(f"{OUT}/{name}.md", "w") as f:
        f.write(f"<!-- made by: {command} -->\n{table}\n")


def _table(head, rows) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def _f(x, fmt=".5f"):
    return "-" if x is None else format(x, fmt)


def spacing_for(mu: float) -> int:
    """Uniform N on [0, 10] that resolves the cohesive zone: h <= 0.75 mu^-1.5 / 5."""
    return max(531, int(np.ceil(10 / (0.15 * mu ** -1.5))) + 1)


def smooth():
    """Load-approach curves of smooth spheres (paper Figs. 4, 5, 8) and the rigid limit."""
    plt = _plt()
    mus = (0.01, 0.5, 1.0, 2.0, 3.0)
    res = runs([("-adh_mu", m) for m in mus])
    fig, ax = plt.subplots(figsize=(7, 5))
    lam = np.linspace(-4, 0.6, 300)
    ax.plot(lam, rigid_load(lam), "k:", label="mu = 0, eq. (28)")
    rows = []
    for m, (s, h5) in zip(mus, res):
        load_approach(ax, read(h5), label=f"mu = {m:g}")
        fo = {f["kind"]: f["lambda"] for f in s["folds"]}
        rows.append([f"{m:g}", _f(s["pull_off"]["F"]), _f(s["pull_off"]["lambda"]), _f(fo.get("snap_on")),
                     _f(fo.get("snap_off")), _f(s["equilibria"][-1]["lambda"]), str(s["steps"]),
                     f"{s['wall_time_s']:.2f}"])
    ax.set_xlim(-6, 7)
    ax.set_ylim(-1.1, 1.0)
    ax.legend(fontsize=8)
    _save(fig, "smooth", _table(["mu", "pull-off F", "lambda_p", "snap-on lambda", "snap-off lambda",
                                 "equilibrium lambda", "steps", "time (s)"], rows),
          "./run figures smooth")


def rough():
    """Roughness at mu = 0.01 and mu = 2 (paper Figs. 13, 14)."""
    plt = _plt()
    sig = (0.0, 0.2, 0.4, 1.0)
    cases = [(m, s) for m in (0.01, 2.0) for s in sig]
    res = runs([("-adh_mu", m, "-adh_sigma", s) for m, s in cases])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    rows = []
    for (m, s), (summ, h5) in zip(cases, res):
        ax = axes[0 if m < 1 else 1]
        load_approach(ax, read(h5), label=f"sigma = {s:g}")
        ax.set_title(f"mu = {m:g}")
        fo = {f["kind"]: f["lambda"] for f in summ["folds"]}
        rows.append([f"{m:g}", f"{s:g}", _f(summ["pull_off"]["F"]), _f(summ["pull_off"]["lambda"]),
                     _f(fo.get("snap_on")), _f(fo.get("snap_off")), _f(summ["equilibria"][-1]["lambda"])])
    for ax in axes:
        ax.set_ylim(-1.1, 0.6)
        ax.set_xlim(-9, 6)
        ax.legend(fontsize=8)
    _save(fig, "rough", _table(["mu", "sigma", "pull-off F", "lambda_p", "snap-on", "snap-off", "equilibrium"],
                               rows), "./run figures rough")


def snaps():
    """States just before and after snap-on and snap-off at mu = 1 (paper Figs. 6, 7)."""
    plt = _plt()
    (summ, h5), = runs([("-adh_mu", 1, "-profiles")])
    res = read(h5)
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    rows = []
    for col, kind in enumerate(("snap_on", "snap_off")):
        ev = next(e for e in res["events"] if e["kind"] == kind)
        profiles(axes[0, col], axes[1, col], res["r"], ev["H"], ev["P"], f"at the fold, F = {ev['F']:.4f}")
        land = ev["landing"]
        profiles(axes[0, col], axes[1, col], res["r"], land["H"], land["P"], f"after the jump, F = {land['F']:.4f}")
        axes[0, col].set_title(f"{kind.replace('_', '-')} at lambda = {ev['lambda']:.5f}")
        axes[0, col].legend(fontsize=8)
        rows.append([kind, _f(ev["lambda"], ".8f"), _f(ev["F"]), _f(land["F"]), _f(ev["H0"]), _f(land["H0"])])
    _save(fig, "snaps", _table(["fold", "lambda", "F before", "F after", "H(0) before", "H(0) after"], rows),
          "./run figures snaps")


def convergence():
    """Error of the mu = 1 events against grid size and run time (uniform grids)."""
    plt = _plt()
    ns = (101, 201, 401, 801, 1601)
    # one at a time: the run times are part of the figure
    res = [s for s, _ in runs([("-adh_mu", 1, "-grid_type", "uniform", "-grid_n", n, "-cont_F_max", 0.2)
                               for n in ns], workers=1)]
    quantities = {
        "snap-on lambda": lambda s: next(f["lambda"] for f in s["folds"] if f["kind"] == "snap_on"),
        "snap-off lambda": lambda s: next(f["lambda"] for f in s["folds"] if f["kind"] == "snap_off"),
        "pull-off F": lambda s: s["pull_off"]["F"],
        "pull-off lambda": lambda s: s["pull_off"]["lambda"],
        "equilibrium lambda": lambda s: s["equilibria"][-1]["lambda"],
    }
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5))
    rows = []
    times = np.array([s["wall_time_s"] for s in res])
    for name, get in quantities.items():
        x = np.array([get(s) for s in res])
        ref = x[-1] + (x[-1] - x[-2]) / 3            # Richardson from the two finest
        err = np.abs(x[:-1] - ref)
        a1.loglog(ns[:-1], err, "o-", label=name)
        a2.loglog(times[:-1], err, "o-", label=name)
        orders = np.log2(np.abs(np.diff(x[:-1])[:-1] / np.diff(x[:-1])[1:]))
        rows.append([name, _f(ref, ".8f")] + [_f(e, ".1e") for e in err] + [" ".join(f"{o:.2f}" for o in orders)])
    a1.loglog(ns[:-1], 2e-3 * (np.array(ns[:-1]) / 100.0) ** -2, "k:", label="N^-2")
    a1.set_xlabel("nodes N (uniform on [0, 10])")
    a2.set_xlabel("continuation time (s), one rank")
    for a in (a1, a2):
        a.set_ylabel("|error| vs extrapolated")
        a.legend(fontsize=7)
    head = ["quantity", "extrapolated"] + [f"err N={n}" for n in ns[:-1]] + ["observed orders"]
    table = _table(head, rows) + "\n\n" + _table(["N"] + [str(n) for n in ns],
                                                 [["time (s)"] + [f"{t:.2f}" for t in times]])
    _save(fig, "convergence", table, "./run figures convergence")


def hermite():
    """Dependence of the pull-off on the Gauss-Hermite rule (the regularization of eq. 14)."""
    plt = _plt()
    points = (8, 12, 16, 24, 32, 48, 64)
    cases = [(m, s, n) for m in (0.01, 2.0) for s in (0.2, 0.4, 1.0) for n in points]
    res = runs([("-adh_mu", m, "-adh_sigma", s, "-adh_hermite_points", n, "-cont_F_max", 0.2)
                for m, s, n in cases])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    rows = {}
    for (m, s, n), (summ, _) in zip(cases, res):
        rows.setdefault((m, s), []).append(summ["pull_off"]["F"])
    warned = {c for c, (summ, _) in zip(cases, res) if summ["warnings"]}
    for (m, s), F in rows.items():
        ok = [(n, x) for n, x in zip(points, F) if (m, s, n) not in warned]
        ax.plot(*zip(*ok), "o-", label=f"mu = {m:g}, sigma = {s:g}")
    ax.axvline(16, color="0.6", lw=0.8)
    ax.set_xlabel("points of the Gauss-Hermite rule (runs that sit at the wall left out)")
    ax.set_ylabel("pull-off F")
    ax.legend(fontsize=8)
    table = _table(["mu", "sigma"] + [f"n={n}" for n in points],
                   [[f"{m:g}", f"{s:g}"] + [_f(x) + (" (w)" if (m, s, n) in warned else "")
                                            for n, x in zip(points, F)] for (m, s), F in rows.items()])
    table += ("\n\n(w): the run warned that the curve sits at the wall of the rule (gap < 1e-3), where "
              "the load is set by weights near 1e-40 and is ill-conditioned.")
    _save(fig, "hermite", table, "./run figures hermite")


def coarse():
    """A grid that does not resolve the contact edge: mu = 3, h = 0.08 against h = 0.025."""
    plt = _plt()
    res = runs([("-adh_mu", 3, "-grid_type", "uniform", "-grid_n", n) for n in (126, 401)])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    rows = []
    for n, (s, h5) in zip((126, 401), res):
        load_approach(ax, read(h5), label=f"h = {10 / (n - 1):.3g}", events=False)
        rows.append([str(n), f"{10 / (n - 1):.3g}", str(len(s["folds"])), s["stop_reason"], s["grid_warning"] or "-"])
    ax.set_xlim(-6, -1)
    ax.set_ylim(-0.9, 0.0)
    ax.legend(fontsize=8)
    _save(fig, "coarse", _table(["N", "h", "folds", "stopped", "grid_warning"], rows), "./run figures coarse")


def reduction():
    """Reduction of the pull-off by roughness, phi_r = 1 - F_p / F_p0 (eq. 29, paper Fig. 17)."""
    plt = _plt()
    sig = (0.0, 0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0, 1.2)
    mus = (0.01, 1.0, 2.0)
    res = runs([("-adh_mu", m, "-adh_sigma", s, "-cont_F_max", 0.2) for m in mus for s in sig])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    rows = []
    for i, m in enumerate(mus):
        F = np.array([res[i * len(sig) + j][0]["pull_off"]["F"] for j in range(len(sig))])
        phi = 1 - F / F[0]
        ax.plot(sig, phi, "o-", label=f"mu = {m:g}")
        rows.append([f"{m:g}"] + [f"{p:.3f}" for p in phi])
    ax.set_xlabel("sigma")
    ax.set_ylabel("reduction rate phi_r")
    ax.legend()
    _save(fig, "reduction", _table(["mu"] + [f"sigma={s:g}" for s in sig], rows), "./run figures reduction")


def tabor():
    """Pull-off against the Tabor parameter, smooth and rough (paper Fig. 18), on resolving grids."""
    plt = _plt()
    mus = (0.01, 0.1, 0.3, 0.5, 1.0, 2.0, 3.0, 4.0)
    sig = (0.0, 0.2, 1.0)
    cases = [(m, s) for s in sig for m in mus]
    res = runs([("-adh_mu", m, "-adh_sigma", s, "-grid_type", "uniform", "-grid_n", spacing_for(m),
                 "-cont_F_max", 0.2) for m, s in cases])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    rows = {}
    for (m, s), (summ, _) in zip(cases, res):
        rows.setdefault(s, []).append(summ["pull_off"]["F"])
    for s, F in rows.items():
        ax.semilogx(mus, -np.array(F), "o-", label=f"sigma = {s:g}")
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.axhline(0.75, color="0.6", lw=0.8)
    ax.set_xlabel("Tabor parameter mu")
    ax.set_ylabel("pull-off |F| / (2 pi R gamma)")
    ax.legend()
    _save(fig, "tabor", _table(["sigma"] + [f"mu={m:g}" for m in mus],
                               [[f"{s:g}"] + [_f(x, ".4f") for x in F] for s, F in rows.items()]),
          "./run figures tabor")


#: The roughness models compared: label -> options (docs/model.md, "Roughness models").
MODELS = {"Hermite, 16 points (paper)": (),
          "truncated Gaussian, K = 3": ("-adh_roughness", "truncated_gaussian"),
          "truncated Gaussian, K = 4": ("-adh_roughness", "truncated_gaussian", "-adh_roughness_cutoff", 4),
          "truncated Gaussian, K = 5": ("-adh_roughness", "truncated_gaussian", "-adh_roughness_cutoff", 5),
          "Weibull, skewness -1": ("-adh_roughness", "weibull", "-adh_roughness_skewness", -1),
          "Weibull, skewness 0": ("-adh_roughness", "weibull")}


def quadrature():
    """The pull-off as each roughness model's quadrature is refined (mu = 1): converging, unlike Hermite's."""
    plt = _plt()
    points = (3, 6, 12, 24, 48)
    hermite = (8, 16, 32, 64)
    rules = [label for label in MODELS if "Hermite" not in label]
    cases = [(s, label, n) for s in (0.2, 1.0) for label in rules for n in points]
    cases += [(s, "Hermite", n) for s in (0.2, 1.0) for n in hermite]
    res = runs([("-adh_mu", 1, "-adh_sigma", s, "-cont_F_max", 0.2, "-cont_error_estimate", "false",
                 *(MODELS[label] + ("-adh_quadrature_points", n) if label != "Hermite" else
                   ("-adh_hermite_points", n))) for s, label, n in cases])
    F = {c: summ["pull_off"]["F"] for c, (summ, _) in zip(cases, res)}
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    rows = []
    for ax, s in zip(axes, (0.2, 1.0)):
        for label in rules:
            best = F[(s, label, points[-1])]
            change = [abs(F[(s, label, n)] - best) for n in points[:-1]]
            ax.semilogy(points[:-1], np.maximum(change, 1e-17), "o-", label=label)
            rows.append([f"{s:g}", label] + [f"{F[(s, label, n)]:.10f}" for n in points])
        hb = F[(s, "Hermite", hermite[-1])]
        ax.semilogy(hermite[:-1], [abs(F[(s, "Hermite", n)] - hb) for n in hermite[:-1]], "ks--",
                    label="Hermite (against 64 points)")
        rows.append([f"{s:g}", "Hermite, points " + ", ".join(map(str, hermite))]
                    + [f"{F[(s, 'Hermite', n)]:.10f}" for n in hermite] + [""])
        ax.set_title(f"mu = 1, sigma = {s:g}")
        ax.set_xlabel("quadrature points (moving part at the wall)")
        ax.set_ylabel("|F_p - F_p(48 points)|")
    axes[0].legend(fontsize=7)
    table = _table(["sigma", "model"] + [f"n={n}" for n in points], rows)
    table += "\n\nPull-off F at mu = 1 against the points of each model's quadrature (error bars off)."
    _save(fig, "quadrature", table, "./run figures quadrature")


def models():
    """The pull-off against sigma for the paper's rule and the well-posed models, at mu = 0.01, 1 and 5."""
    plt = _plt()
    sig = (0.0, 0.05, 0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0)
    mus = (0.01, 1.0, 5.0)
    cases = [(m, label, s) for m in mus for label in MODELS for s in sig]
    res = runs([("-adh_mu", m, "-adh_sigma", s, "-cont_F_max", 0.2, *(MODELS[label] if s else ()))
                for m, label, s in cases])
    out = {c: summ for c, (summ, _) in zip(cases, res)}
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), sharey=True)
    rows = []
    for ax, m in zip(axes, mus):
        for label in MODELS:
            po = [out[(m, label, s)]["pull_off"] for s in sig]
            ax.errorbar(sig, [-p["F"] for p in po], yerr=[p.get("F_err", 0) for p in po], fmt="o-", ms=3,
                        label=label)
            rows.append([f"{m:g}", label] + [f"{p['F']:.5f} +- {p.get('F_err', float('nan')):.0e}" for p in po])
        ax.set_title(f"mu = {m:g}")
        ax.set_xlabel("sigma")
    axes[0].set_ylabel("pull-off |F| / (2 pi R gamma)")
    axes[0].legend(fontsize=7)
    _save(fig, "models", _table(["mu", "model"] + [f"sigma={s:g}" for s in sig], rows), "./run figures models")


FIGURES = {f.__name__: f for f in (smooth, rough, snaps, convergence, hermite, coarse, reduction, tabor,
                                   quadrature, models)}

if __name__ == "__main__":
    names = sys.argv[1:] or list(FIGURES)
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        sys.exit(f"unknown figure {unknown[0]}; one of: {', '.join(FIGURES)}")
    os.makedirs(OUT, exist_ok=True)
    for name in names:
        print(f"figure {name} ...", flush=True)
        FIGURES[name]()
