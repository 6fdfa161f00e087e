"""The figures and tables of docs/, from real runs.

    ./run figures                  # all of them, into docs/figures/
    ./run figures fig18            # one paper figure: the study options/fig18.opts
    ./run figures convergence      # one of our own studies
    ./run figures afm_example      # one of docs/afm.md's (petsc_adhesion.benchmarks.afm)

The paper's figures are the studies ``options/figNN.opts`` (:mod:`petsc_adhesion.app.study`),
run here one after another as ``./run study`` runs them (``NP=2`` spreads each over two
ranks); each writes its PNG and JSON summary into docs/figures/, and this module adds
the table of its events, figNN.md.  Our own studies (refinement, quadrature, models)
are the functions below.

Every figure NAME.png comes with NAME.md, the table of the numbers behind it, which
docs/results.md includes by reference; rerun after any change to the solver.
"""
from __future__ import annotations

import glob
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..io.plot.curve import load_approach
from ..io.plot.read import read
from . import paths

__all__ = ["FIGURES", "STUDIES", "study", "run", "runs", "OUT", "TMP", "convergence", "hermite", "coarse", "MODELS", "quadrature", "models", "critical_models", "ROOT", "validation", "OWN"]

OUT = paths.FIGURES
TMP = tempfile.mkdtemp(prefix="petsc-adhesion-figures-")


def run(*args, partial: bool = False) -> tuple[dict, str]:
    """One petsc-adhesion run: its JSON summary and the path of its HDF5 file; ``partial``: a curve that
    ends early (exit status 3, its result written) is what the figure shows."""
    tag = "_".join(str(a).lstrip("-") for a in args).replace("/", "")
    h5, js = f"{TMP}/{tag}.h5", f"{TMP}/{tag}.json"
    cmd = [sys.executable, "-m", "petsc_adhesion", *map(str, args), "-out", h5, "-summary", js]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode and not (partial and proc.returncode == 3):
        raise RuntimeError(f"{' '.join(cmd)}: {proc.stderr.strip()}")
    with open(js) as f:
        return json.load(f), h5


def runs(cases, workers: int = 2, partial: bool = False):
    """Run cases (argument tuples), two at a time by default: the machines we target have 2 cores."""
    with ThreadPoolExecutor(workers) as pool:
        return list(pool.map(lambda a: run(*a, partial=partial), cases))


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






def convergence():
    """Error of the mu = 1 events against grid size and run time (uniform grids)."""
    plt = _plt()
    ns = (101, 201, 401, 801, 1601)
    # one at a time: the run times are part of the figure; each grid's own values, not its
    # extrapolation from a second trace, are what converges here
    res = [s for s, _ in runs([("-adh_mu", 1, "-grid_type", "uniform", "-grid_n", n, "-cont_F_max", 0.2,
                                "-cont_error_estimate", "false")
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
    res = runs([("-adh_mu", 3, "-grid_type", "uniform", "-grid_n", n) for n in (126, 401)], partial=True)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    rows = []
    for n, (s, h5) in zip((126, 401), res):
        load_approach(ax, read(h5), label=f"h = {10 / (n - 1):.3g}", events=False)
        rows.append([str(n), f"{10 / (n - 1):.3g}", str(len(s["folds"])), s["stop_reason"], s["grid_warning"] or "-"])
    ax.set_xlim(-6, -1)
    ax.set_ylim(-0.9, 0.0)
    ax.legend(fontsize=8)
    _save(fig, "coarse", _table(["N", "h", "folds", "stopped", "grid_warning"], rows), "./run figures coarse")




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


def critical_models():
    """The critical roughness sigma_c(mu) of each roughness model (``-study_compute critical``), where it
    exists below sigma = 8."""
    plt = _plt()
    mus = (0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0, 20.0)
    rows, fig = [], plt.figure(figsize=(6.4, 4.8))
    ax = fig.gca()
    with tempfile.TemporaryDirectory() as tmp:
        for i, (label, args) in enumerate(MODELS.items()):
            path = os.path.join(tmp, f"{i}.json")
            cmd = [sys.executable, "-m", "petsc_adhesion", "-study_compute", "critical", "-study_mu",
                   ",".join(f"{m:g}" for m in mus), *map(str, args), "-summary", path]
            np_ = os.environ.get("NP")
            proc = subprocess.run((["mpiexec", "-n", np_] if np_ else []) + cmd, cwd=ROOT, capture_output=True,
                                  text=True)
            if proc.returncode not in (0, 3):
                raise RuntimeError(f"{' '.join(cmd)}: {proc.stderr.strip().splitlines()[-1]}")
            with open(path) as f:
                s = json.load(f)
            got = {c["mu"]: c for c in s["critical_roughness"]}
            why = {f["values"]["adh_mu"]: f["error"] for f in s["failed"]}
            xs = sorted(got)
            ax.errorbar(xs, [got[m]["sigma_c"] for m in xs], yerr=[got[m]["sigma_c_err"] for m in xs],
                        fmt="o-", ms=3, label=label)
            rows.append([label] + [f"{got[m]['sigma_c']:.6f} +- {got[m]['sigma_c_err']:.0e}" if m in got else
                                   ("none below 8" if why.get(m, "").startswith("hysteresis at") else
                                    "below 0.001" if why.get(m, "").startswith("no hysteresis") else "failed")
                                   for m in mus])
    ax.set_xscale("log")
    ax.set_xlabel("Tabor parameter mu")
    ax.set_ylabel("critical roughness sigma_c / epsilon")
    ax.legend(fontsize=7)
    _save(fig, "critical_models", _table(["model"] + [f"mu={m:g}" for m in mus], rows),
          "./run figures critical_models")


ROOT = paths.ROOT
#: The studies of the paper's figures, by name: figNN -> its options file.
STUDIES = {os.path.basename(f)[:-5]: f for f in sorted(glob.glob(os.path.join(paths.OPTIONS, "fig[0-9]*.opts")))}
STUDIES["paper_model"] = os.path.join(paths.OPTIONS, "paper_model.opts")      # the paper's truncated model
STUDIES["critical_roughness"] = os.path.join(paths.OPTIONS, "critical_roughness.opts")


def _pm(e: dict | None, key: str) -> str:
    if not e:
        return "-"
    bar = e.get(f"{key}_err")
    return f"{e[key]:.6f}" + (f" +- {bar:.1e}" if bar else "")


def study(name: str) -> None:
    """Run the study options/NAME.opts as ``./run study`` does (from the repository, NP ranks) and
    write NAME.md, the table of each case's events (or cusps) with their error bars."""
    np_ = os.environ.get("NP")
    launcher = ["mpiexec", "-n", np_] if np_ else []
    cmd = launcher + [sys.executable, "-m", "petsc_adhesion", "-options_file", os.path.relpath(STUDIES[name], ROOT)]
    os.makedirs(os.path.join(ROOT, "results"), exist_ok=True)
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if proc.returncode not in (0, 3):
        raise RuntimeError(f"{' '.join(cmd)}: {proc.stderr.strip().splitlines()[-1]}")
    with open(os.path.join(OUT, f"{name}.json")) as f:
        s = json.load(f)
    table = _critical_table(s) if s["kind"] == "critical" else _events_table(s)
    with open(os.path.join(OUT, f"{name}.md"), "w") as f:
        f.write(f"<!-- made by: ./run figures {name} (the study options/{name}.opts) -->\n{table}\n")


def _events_table(s: dict) -> str:
    rows = []
    for c in s["cases"]:
        # the primary turning points: snap-on at the largest lambda, snap-off at the smallest
        folds = {k: f([e for e in c["folds"] if e["kind"] == k], key=lambda e: e["lambda"], default=None)
                 for k, f in (("snap_on", max), ("snap_off", min))}
        eq = c["equilibria"][0] if c["equilibria"] else None
        po = c["pull_off"]
        rows.append([", ".join(f"{k.replace('adh_', '')} = {v:g}" for k, v in c["values"].items()),
                     _pm(po, "F"), _pm(po, "lambda"), _pm(folds.get("snap_on"), "lambda"),
                     _pm(folds.get("snap_off"), "lambda"), _pm(eq, "lambda"),
                     "-" if s["study"]["compute"] == "pull_off" else str(len(c["folds"])),
                     f"{c['wall_time_s']:.1f}" + ("" if c["complete"] else " (incomplete)")])
    rows += [[f"case {f['case'] + 1} failed: {f['error']}"] + ["-"] * 7 for f in s["failed"]]
    return _table(["case", "pull-off F", "pull-off lambda", "snap-on lambda", "snap-off lambda",
                   "equilibrium lambda", "turning points", "time (s)"], rows)


def _critical_table(s: dict) -> str:
    """The cusps of a critical study: sigma_c(mu), then mu_c(sigma), each with the cusp's lambda and F."""
    rows = []
    for name, fixed, k in (("critical_roughness", "mu", "sigma_c"), ("critical_mu", "sigma", "mu_c")):
        for c in s[name]:
            rows.append([f"{fixed} = {c[fixed]:g}", f"{k} = {c[k]:.7f} +- {c[k + '_err']:.1e}",
                         _pm(c, "lambda_c"), _pm(c, "F_c"), " ".join(f"{v:.7f}" for v in c[k + "_grid"]),
                         "/".join(str(n) for n in c["n_nodes"]), f"{c['wall_time_s']:.1f}"
                         + (f" ({c['warning']})" if c.get("warning") else "")])
    rows += [[f"case {f['case'] + 1} failed: {f['error']}"] + ["-"] * 6 for f in s["failed"]]
    return _table(["case", "critical value", "lambda at the cusp", "F at the cusp", "on each grid level",
                   "nodes", "time (s)"], rows)


def validation():
    """docs/validation.md from the studies (``./run figures`` runs them first; alone, run them before)."""
    from ..benchmarks import validation as v

    v.write()


def _afm(name: str) -> None:
    """docs/figures/afm_NAME.png and .md of docs/afm.md (:mod:`petsc_adhesion.benchmarks.afm`)."""
    from . import afm

    afm.FIGURES[name]()


OWN = {f.__name__: f for f in (convergence, hermite, coarse, quadrature, models, critical_models, validation)}
OWN |= {f"afm_{n}": (lambda n=n: _afm(n)) for n in ("example", "stiffness", "radius")}
FIGURES = {**{n: (lambda n=n: study(n)) for n in STUDIES}, **OWN}

if __name__ == "__main__":
    names = sys.argv[1:] or list(FIGURES)
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        sys.exit(f"unknown figure {unknown[0]}; one of: {', '.join(FIGURES)}")
    os.makedirs(OUT, exist_ok=True)
    for name in names:
        print(f"figure {name} ...", flush=True)
        FIGURES[name]()
