"""The work-precision benchmark's documents: docs/performance.md, its figures and tables, from the measurements."""
from __future__ import annotations

import math
import os
import platform

import numpy as np
import petsc4py
from petsc4py import PETSc

from ...discretization.preconditioning import REDUNDANT_MAX
from .accuracy import (
    COMMAND,
    FIGURES,
    PERFORMANCE,
    QUANTITIES,
    REPEATS,
    SCALE_STEPS,
    SLOW,
    domain_part,
    errors,
    observed_orders,
)

__all__ = ["STYLE", "FLOOR", "plot_case", "table_case", "crossover", "machine", "USER_METHODS", "compare_peers", "CASE_TITLES", "render", "write_docs"]


# -- the documents -------------------------------------------------------------------------------------
#: marker and line style per method (DiffEqDevTools: one marked line per method)
STYLE = {"paper grid": ("^", "C0"), "paper grid, extrapolated": ("v", "C0"), "uniform grid, r_m = 10": ("o", "C1"),
         "edge grid (default), grid value": ("D", "C2"), "edge grid (default), extrapolated": ("*", "C2"),
         "-target_error": ("s", "C3"), "pmat: dense LU": ("x", "C4"), "pmat: band AIJ + LU": ("+", "C4"),
         "pmat: block Jacobi (4 LU blocks)": ("1", "C4"), "pmat: none (GMRES on the operator)": ("2", "C4"),
         "numpy/scipy reference, paper grid": ("P", "C5"), "ContactMechanics + Adhesion (stored)": ("h", "C6")}


FLOOR = 1e-12


def _methods(recs):
    seen = []
    for r in recs:
        if r["method"] not in seen:
            seen.append(r["method"])
    return seen


def plot_case(data: dict, path: str) -> None:
    """The work-precision diagram of one case: one panel per quantity, log10 error against log10 median time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 9))
    truth, recs = data["truth"], data["records"]
    nf = truth["values"]["folds"][0]
    for ax, q in zip(axes.flat, QUANTITIES):
        for m in _methods(recs):
            rs = [r for r in recs if r["method"] == m]
            pts = [(r["median_s"], errors(r, truth)[q], r["values"].get("folds", (nf,))[0] not in (nf, None))
                   for r in rs]
            pts = [(t, max(e, FLOOR), wrong) for t, e, wrong in pts if e is not None]
            if not pts:
                continue
            marker, color = STYLE.get(m, ("o", "k"))
            x, y = np.log10([p[0] for p in pts]), np.log10([p[1] for p in pts])
            ax.plot(x, y, marker=marker, color=color, ls="-" if len(pts) > 1 else "none", ms=8, label=m)
            bad = [k for k, p in enumerate(pts) if p[2]]      # another event structure than the truth's: hollow
            if bad:
                ax.plot(x[bad], y[bad], marker=marker, ls="none", ms=8, mfc="white", mec=color)
        bar = truth["values"].get(q, (None, None))[1]
        if bar:
            ax.axhline(math.log10(bar), color="k", ls=":", lw=1, label="truth's own bar")
        ax.set_title(f"{q}" + (f" (truth {truth['values'][q][0]:.9f})" if q in truth["values"] else ""), fontsize=10)
        ax.set_xlabel("log10 median wall time (s)")
        ax.set_ylabel("log10 |error|")
        ax.grid(alpha=0.3)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    for ax in axes.flat[1:5]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    axes.flat[5].axis("off")
    axes.flat[5].legend(handles, labels, loc="center", fontsize=9)
    fig.suptitle(f"work-precision, mu = {data['mu']:g}, sigma = {data['sigma']:g} "
                 f"(truth: edge grid, -target_error {truth['tol']:g}, extrapolated)\n"
                 f"hollow: another number of turning points than the truth's; errors below 1e-12 drawn at 1e-12")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _e(x) -> str:
    return "-" if x is None else ("< 1e-12" if x < FLOOR else f"{x:.1e}")


def _t(s: float) -> str:
    return f"{s * 1e3:.0f} ms" if s < 1 else f"{s:.2f} s" if s < 100 else f"{s:.0f} s"


def table_case(data: dict) -> str:
    """The numbers behind one diagram: the truth, every method's errors and times, observed orders, domain part."""
    truth, recs = data["truth"], data["records"]
    lines = [f"Truth: edge grid (r_m = 150, far field added), `-target_error {truth['tol']:g}`, extrapolated; "
             f"up to {truth['n_nodes']} nodes; {_t(truth['wall_time_s'])} (one run)."
             + (f" It says: {'; '.join(truth['warnings'])}." if truth["warnings"] else ""), "",
             "| quantity | truth | its bar |", "|---|---|---|"]
    for q in QUANTITIES:
        if q in truth["values"]:
            v, b = truth["values"][q]
            lines.append(f"| {q} | {v:.10f} | {_e(b)} |")
    lines += ["", "| method | N or tol | nodes | median time | repeats | " + " | ".join(QUANTITIES) + " | folds |",
              "|---|---|---|---|---|" + "---|" * len(QUANTITIES) + "---|"]
    nfolds = truth["values"]["folds"][0]
    for r in recs:
        err = errors(r, truth)
        folds = r["values"].get("folds", (None,))[0]
        p = r["param"]
        p = "" if p is None else (f"{p:g}" if isinstance(p, float) else str(p))
        flag = ("" if folds in (None, nfolds) else " (truth: %d)" % nfolds) + (" warned" if r.get("warned") else "")
        lines.append(f"| {r['method']} | {p} | {r['n_nodes'] or ''} | {_t(r['median_s'])}"
                     f"{' (stored)' if r.get('stored') else ''} | {len(r['times'])} | "
                     + " | ".join(_e(err[q]) for q in QUANTITIES) + f" | {'-' if folds is None else folds}{flag} |")
    lines += ["", "Errors are |value - truth| (\"< 1e-12\": the same value as the truth's, where the method ran the "
              "same levels); `folds`: turning points found (the truth's number where it differs); `warned`: the run "
              "printed a warning (a grid that does not resolve the contact edge, or a target not reached).  Stored "
              "times are those of the peer's own runs."]
    orders = observed_orders(recs)
    lines += ["", "Observed orders of the uniform grids, log2 |X_h - X_h/2| / |X_h/2 - X_h/4| (independent of the truth):",
              "", "| N (finest of three) | " + " | ".join(QUANTITIES) + " |", "|---|" + "---|" * len(QUANTITIES)]
    ns = sorted({n for ps in orders.values() for n, _ in ps})
    for n in ns:
        cells = []
        for q in QUANTITIES:
            p = dict(orders[q]).get(n)
            cells.append("-" if p is None else f"{p:.2f}")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    dom = domain_part(recs, truth)
    if dom:
        lines += ["", "Domain truncation of r_m = 10 (far-field load added; the deflection it causes inside r_m is "
                  "not): paper grid extrapolated minus truth: "
                  + ", ".join(f"{q} {dom[q]:+.1e}" for q in QUANTITIES if dom[q] is not None)
                  + ".  This is the floor of the uniform and paper grids' lines."]
    else:
        lines += ["", "Domain truncation of r_m = 10: not measured here, the paper grid does not resolve this case "
                  "(it warns); uniform grids below N = 801 do not either, and give no orders."]
    return "\n".join(lines)


def _speed_table(rows: dict) -> str:
    lines = ["| quantity | median | min | max | repeats | target | met |", "|---|---|---|---|---|---|---|"]
    for r in rows.values():
        met = "-" if r["met"] is None else "yes" if r["met"] else "**no**"
        lines.append(f"| {r['quantity']} | {_t(r['median_s'])} | {_t(r['min_s'])} | {_t(r['max_s'])} | {r['repeats']} | "
                     f"{'-' if r['target_s'] is None else _t(r['target_s'])} | {met} |")
    return "\n".join(lines)


def _profile_lines(pr: dict, bars: dict) -> list[str]:
    """Where the curve's time goes, from :func:`profile`, against the curve-with-bars row ``bars``."""
    total = pr["total_s"]
    rows = [(k, v) for k, v in pr["own"].items() if v >= 0.01 * total]
    rest = total - sum(v for _, v in rows)
    table = "| where | own time | share |\n|---|---|---|\n" + "\n".join(
        f"| {k} | {_t(v)} | {100 * v / total:.0f}% |" for k, v in rows) + \
        f"\n| everything else (each below 1%) | {_t(rest)} | {100 * rest / total:.0f}% |"
    top, share = rows[0][0], rows[0][1] / total
    stages = "; ".join(f"{k} {_t(v)} ({100 * v / total:.0f}%)" for k, v in pr["stages"].items())
    return ["Where the curve's time goes: the mu = 1 curve with error bars once under cProfile "
            f"(`petsc_adhesion.benchmarks.workprecision.profile`, after a warm run; the profiler slows the Python side, so "
            f"the shares are the measurement): {_t(total)} in all, {pr['snes_solves']} SNES solves.  Own time of "
            f"every function, summed by where it runs:", "", table, "",
            f"Stages (cumulative, they nest): {stages}.  The largest single place is {top} with "
            f"{100 * share:.0f}% (under the profiler, which inflates the Python places); the curve with bars "
            f"({_t(bars['median_s'])}) is {100 * (bars['median_s'] / bars['target_s'] - 1):+.0f}% from its target "
            f"({_t(bars['target_s'])}).", ""]


def _startup_lines(data: dict) -> list[str]:
    """Where the whole-process second goes: the start-up floor, stage by stage, against the target."""
    st, sp = {r["stage"]: r for r in data["startup"]}, data["speed"]
    rows = data["startup"]
    head = f"| a fresh interpreter doing only this | fastest of {rows[0]['repeats']} | median |\n|---|---|---|\n"
    table = head + "\n".join(f"| {r['stage']} | {_t(r['min_s'])} | {_t(r['median_s'])} |" for r in rows)
    floor = rows[-1]["min_s"]
    numpy = st["numpy"]["min_s"]
    mpi_own = st["mpi4py (MPI_Init), Open MPI's own singleton start-up"]["min_s"]
    mpi_ours = st["mpi4py (MPI_Init), petsc-adhesion's singleton defaults"]["min_s"]
    petsc = st["petsc4py (MPI_Init, PetscInitialize)"]["min_s"]
    bars = sp["speed_curve_bars"]["median_s"]
    least = floor + bars
    verdict = (f"within the 1 s whole-process target by {_t(1.0 - least)} at best" if least <= 1.0 else
               f"the 1 s whole-process target is out of reach on this stack without cutting the curve itself "
               f"below {_t(max(1.0 - floor, 0.0))}")
    return ["Start-up, stage by stage (`python -c CODE`, `petsc_adhesion.benchmarks.workprecision.STARTUP`).  Every process "
            "here runs as a user's Python does, with its bytecode cache written: one that may not write it "
            "(`PYTHONDONTWRITEBYTECODE`, set in this machine's sandbox) compiles petsc-adhesion's 31 modules at "
            "every start (40-60 ms here).", "", table, "",
            f"Before any work a run pays {_t(floor)} to have its modules loaded and PETSc and MPI initialised (its "
            f"floor: the fastest runs; MPI_Init and PetscInitialize alone {_t(petsc - numpy)}); a run that writes "
            f"files adds h5py's import.  Open MPI's own singleton start-up (a runtime daemon forked, the UCX "
            f"network layer probed) would add {_t(mpi_own - mpi_ours)} to every run that is not launched by mpiexec: "
            f"petsc-adhesion asks such a process for the shared-memory layer and no daemon "
            f"(`petsc_adhesion/singleton.py`; a variable the user set wins).  With the curve and its bars "
            f"({_t(bars)}) that is {_t(least)} at the least: {verdict}.", ""]


def _scaling_table(rows: list) -> str:
    lines = ["| N | pmat | ranks | influence build | solve (fresh factorization) | Newton / KSP its | "
             "time per continuation step | peak RSS per rank (max / sum) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("skipped") or r.get("failed"):
            why = "skipped (predicted over the time budget)" if r.get("skipped") else f"failed: {r['failed'][-120:]}"
            lines.append(f"| {r['n']} | {r['pmat']} | {r['ranks']} | {why} | | | | |")
            continue
        lines.append(f"| {r['n']}{' (run separately)' if r.get('separate') else ''} | {r['pmat']} | {r['ranks']} | "
                     f"{_t(r['build_s'])} | {_t(r['solve_s'])} | "
                     f"{r['newton_its']} / {r['ksp_its']} | {_t(r['step_s'])} ({r['steps']} steps) | "
                     f"{r['rss_max_mib']:.0f} / {r['rss_sum_mib']:.0f} MiB |")
    return "\n".join(lines)


def _one_and_two(rows: list, kind: str, most: float = math.inf):
    """(N, one rank's row, two ranks' row) at the largest N up to ``most`` measured on both, or None."""
    got = {(r["n"], r["ranks"]): r for r in rows if r.get("pmat") == kind and "step_s" in r}
    both = [n for n, k in got if k == 1 and (n, 2) in got and n <= most]
    return (max(both), got[(max(both), 1)], got[(max(both), 2)]) if both else None


def _rank_statement(rows: list) -> str:
    """Two ranks against one at the largest N measured on both, per pmat, and where the whole LU is factored."""
    out = []
    for kind in ("dense", "band"):
        if pair := _one_and_two(rows, kind):
            n, a, b = pair
            out.append(f"{kind} at N = {n}: a step takes {_t(b['step_s'])} on two ranks against {_t(a['step_s'])} on "
                       f"one (speed-up {a['step_s'] / b['step_s']:.2f}), the influence matrix "
                       f"{_t(b['build_s'])} against {_t(a['build_s'])}, peak memory per rank "
                       f"{b['rss_max_mib']:.0f} MiB against {a['rss_max_mib']:.0f} MiB")
    if pair := _one_and_two(rows, "dense", REDUNDANT_MAX):
        n, a, b = pair
        out.append(f"up to N = {REDUNDANT_MAX}, where each rank factors the whole matrix, two ranks are no faster "
                   f"for one curve (dense at N = {n}: {_t(b['step_s'])} a step against {_t(a['step_s'])} on one "
                   f"rank): the price of a preconditioner that stays exact at the folds; a study spreads its "
                   f"cases over the ranks instead")
    return ("Two ranks (one a core): " + "; ".join(out) + ".") if out else ""


def crossover(rows: list) -> int | None:
    """The smallest N from which on band's solve and step (1 rank) are faster than dense's at every measured N,
    both measured (one run each: a few milliseconds' luck at N = 100 is no crossover)."""
    one = {(r["n"], r["pmat"]): r for r in rows if r.get("ranks") == 1 and "step_s" in r}
    both = sorted(n for n, k in one if k == "dense" and (n, "band") in one)
    cost = {n: {k: one[(n, k)]["step_s"] + one[(n, k)]["solve_s"] for k in ("dense", "band")} for n in both}
    wins = [cost[n]["band"] < cost[n]["dense"] for n in both]
    return next((n for i, n in enumerate(both) if all(wins[i:])), None)


def machine() -> dict:
    """What the numbers were measured on."""
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    mem = next((int(ln.split()[1]) // 1024 for ln in open("/proc/meminfo") if ln.startswith("MemTotal")), 0)
    import scipy
    return {"cpu": cpu, "cores": os.cpu_count(), "memory_mib": mem, "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__, "petsc": "%d.%d.%d" % PETSc.Sys.getVersion(),
            "petsc4py": petsc4py.__version__, "platform": platform.platform(),
            "openblas_num_threads": os.environ.get("OPENBLAS_NUM_THREADS", "unset")}


#: what a user of ours would run for a given accuracy (a coarse uniform grid can be right by luck)
USER_METHODS = ("edge grid (default), grid value", "edge grid (default), extrapolated", "-target_error")


def _best_within(recs, truth, q, err, exclude=()):
    """Our fastest default-grid record (:data:`USER_METHODS`) whose error in ``q`` is at most ``err``:
    (record, its error) or None."""
    ok = [(r, errors(r, truth)[q]) for r in recs if r["method"] in USER_METHODS]
    ok = [(r, e) for r, e in ok if e is not None and e <= err]
    return min(ok, key=lambda re: re[0]["median_s"]) if ok else None


def compare_peers(data: dict) -> str:
    """Text and table: the numpy reference and ContactMechanics against ours at mu = 1."""
    truth, recs = data["truth"], data["records"]
    npy = next(r for r in recs if r["method"].startswith("numpy"))
    ours = next(r for r in recs if r["method"] == "paper grid")
    lines = ["| quantity | numpy/scipy, paper grid | ours, paper grid | difference |", "|---|---|---|---|"]
    for q in QUANTITIES:
        a, b = npy["values"].get(q, (None,))[0], ours["values"].get(q, (None,))[0]
        if a is not None and b is not None:
            lines.append(f"| {q} | {a:.12f} | {b:.12f} | {abs(a - b):.1e} |")
    lines += ["", f"Time on the paper grid (N = 531, the same discrete problem, influence matrix included): numpy/scipy "
              f"{_t(npy['median_s'])} ({npy.get('steps')} steps), ours {_t(ours['median_s'])}: ratio "
              f"{npy['median_s'] / ours['median_s']:.1f} (medians of this run).  At equal accuracy (our fastest "
              f"method whose error is at most the numpy code's, against the truth):", "",
              "| quantity | numpy/scipy error | ours at that accuracy | our time | time ratio |", "|---|---|---|---|---|"]
    enp = errors(npy, truth)
    for q in QUANTITIES:
        best = _best_within(recs, truth, q, enp[q], exclude=("ContactMechanics", "numpy")) if enp[q] is not None else None
        if best:
            r, e = best
            p = "" if r["param"] is None else f" {r['param']:g}" if isinstance(r["param"], float) else f" {r['param']}"
            lines.append(f"| {q} | {_e(enp[q])} | {r['method']}{p} ({_e(e)}) | {_t(r['median_s'])} | "
                         f"{npy['median_s'] / r['median_s']:.1f} |")
    lines += [""]
    cm = [r for r in recs if r.get("stored")]
    lines += ["ContactMechanics + Adhesion (stored runs; FFT half-space on [-7.5, 7.5]^2, L-BFGS-B in displacement "
              "control, wall time as stored) against the truth, and our fastest run on the default grid (grid value, "
              "extrapolated, or -target_error) at least as accurate:", "",
              "| n (pixels per side) | stored wall time | quantity | its error | ours at that accuracy | our time | time ratio |",
              "|---|---|---|---|---|---|---|"]
    for r in cm:
        err = errors(r, truth)
        for q in QUANTITIES:
            if err[q] is None:
                continue
            best = _best_within(recs, truth, q, err[q])
            who = "-" if best is None else f"{best[0]['method']}{'' if best[0]['param'] is None else ' ' + format(best[0]['param'], 'g') if isinstance(best[0]['param'], float) else ' ' + str(best[0]['param'])} ({_e(best[1])})"
            lines.append(f"| {r['param']} | {_t(r['median_s'])} | {q} | {_e(err[q])} | {who} | "
                         f"{'-' if best is None else _t(best[0]['median_s'])} | "
                         f"{'-' if best is None else format(r['median_s'] / best[0]['median_s'], '.0f')} |")
    return "\n".join(lines)


CASE_TITLES = {"mu1": "mu = 1, smooth", "mu2_rough": "mu = 2, sigma = 0.2 (Gauss-Hermite roughness)",
               "mu5": "mu = 5, smooth (stiff: a secondary fold pair)"}


def _losses(data: dict) -> list[str]:
    """Statements where a method of ours is slower or less accurate than another, from the numbers."""
    out = []
    for case in data["cases"]:
        truth, recs = case["truth"], case["records"]
        t = CASE_TITLES[case["case"]]
        edge = next(r for r in recs if r["method"] == "edge grid (default), grid value")
        for r in recs:
            if r["method"].startswith("pmat:") and r["method"] != "pmat: dense LU":
                d = next(x for x in recs if x["method"] == "pmat: dense LU")
                if r["median_s"] > 1.1 * d["median_s"]:
                    out.append(f"{t}: {r['method'][6:]} takes {r['median_s'] / d['median_s']:.1f} times the time of "
                               f"dense LU on the edge grid ({_t(r['median_s'])} against {_t(d['median_s'])}).")
        paper = next(r for r in recs if r["method"] == "paper grid")
        if paper["median_s"] < edge["median_s"]:
            out.append(f"{t}: the paper grid is faster than the default edge grid ({_t(paper['median_s'])} against "
                       f"{_t(edge['median_s'])}), but its errors are those of r_m = 10 (table).")
        nf = truth["values"]["folds"][0]
        wrong = {}                            # a wrong event structure: message -> the runs that have it
        for r in recs:
            if r.get("stored"):
                continue
            got = r["values"].get("folds", (nf,))[0]
            missing = [q for q in QUANTITIES if q in truth["values"] and q not in r["values"]]
            parts = ([f"{got} turning points where the truth has {nf}"] if got not in (nf, None) else []) + \
                ([f"no {', '.join(missing)}"] if missing else [])
            if parts:
                msg = " and ".join(parts) + (" (each run printed a warning)" if r.get("warned") else " without a warning")
                wrong.setdefault(msg, []).append(r["method"] + ("" if r["param"] is None else f" {r['param']:g}"
                                                                if isinstance(r["param"], float) else f" {r['param']}"))
        for msg, who in wrong.items():
            out.append(f"{t}: {'; '.join(who)}: {msg}.")
        grid_v = next(r for r in recs if r["method"] == "edge grid (default), grid value")
        extra = next(r for r in recs if r["method"] == "edge grid (default), extrapolated")
        eg, ex = errors(grid_v, truth), errors(extra, truth)
        worse = [f"{q} ({ex[q]:.1e} against {eg[q]:.1e})" for q in QUANTITIES
                 if ex[q] is not None and eg[q] is not None and ex[q] > 1.5 * eg[q]]
        if worse:
            out.append(f"{t}: the default extrapolated value is further from the truth than the grid value it "
                       f"corrects for {', '.join(worse)}: the coarse levels -2 and -1 are not yet in the asymptotic "
                       f"range.")
        for r in recs:                        # bars that did not cover their error against the truth
            if r.get("stored"):
                continue
            err = errors(r, truth)
            for q in QUANTITIES:
                bar = r["values"].get(q, (None, None))[1]
                if bar is not None and err[q] is not None and err[q] > bar:
                    tb = truth["values"][q][1] or 0.0
                    out.append(f"{t}: the bar of {q} from {r['method']}"
                               f"{'' if r['param'] is None else ' ' + format(r['param'], 'g')} ({bar:.1e}) is below "
                               f"its error against the truth ({err[q]:.1e}; the truth's own bar {tb:.1e}).")
        for r in (r for r in recs if r["method"] == "-target_error"):
            err = errors(r, truth)
            over = [f"{q} {e:.1e}" for q, e in err.items() if e is not None and e > r["param"]]
            if over:
                out.append(f"{t}: -target_error {r['param']:g} was not delivered: {', '.join(over)} against the "
                           f"truth (whose own bars are a few 1e-9).")
    npy = [r for c in data["cases"] for r in c["records"] if r["method"].startswith("numpy")]
    ours = [r for c in data["cases"] for r in c["records"] if r["method"] == "paper grid" and c["case"] == "mu1"]
    if npy and ours and npy[0]["median_s"] < ours[0]["median_s"]:
        out.append(f"mu = 1: the plain numpy/scipy code is faster than ours on the paper grid "
                   f"({_t(npy[0]['median_s'])} against {_t(ours[0]['median_s'])}).")
    for r in data["speed"].values():
        if r["met"] is False:
            out.append(f"Speed: {r['quantity']} took {_t(r['median_s'])}, the target is {_t(r['target_s'])}.")
    return out


def _summary(data: dict) -> list[str]:
    """Accuracy, bars, speed and scaling in one bullet each, from the numbers."""
    sp = data["speed"]
    mu1 = next(c for c in data["cases"] if c["case"] == "mu1")
    npy = next(r for r in mu1["records"] if r["method"].startswith("numpy"))
    paper = next(r for r in mu1["records"] if r["method"] == "paper grid")
    sc = data["scaling"]
    done8000 = [f"{r['pmat']} on {r['ranks']} rank(s)" for r in sc if r["n"] == 8000 and "step_s" in r]
    n_cross = crossover(sc)
    cm_t, cm_e, ours_t, ratios = [], [], [], []
    for r in (r for r in mu1["records"] if r.get("stored")):
        cm_t.append(r["median_s"])
        for q, e in errors(r, mu1["truth"]).items():
            best = _best_within(mu1["records"], mu1["truth"], q, e) if e is not None else None
            if e is not None:
                cm_e.append(e)
            if best:
                ours_t.append(best[0]["median_s"])
                ratios.append(r["median_s"] / best[0]["median_s"])
    met = [f"{r['quantity']} {_t(r['median_s'])} (target {_t(r['target_s'])}: {'met' if r['met'] else 'missed'})"
           for r in sp.values()]
    return ["- Work-precision diagrams: mu = 1, mu = 2 with sigma = 0.2 and mu = 5, every method asked for; "
            "uniform grids reach N = 4001 at mu = 1 only (1601 and 801 in the other cases, for the time budget).",
            f"- Against what users would use instead: the numpy/scipy code agrees with ours on the paper grid "
            f"to 1e-10 and takes {npy['median_s'] / paper['median_s']:.1f} times our time there; ContactMechanics + "
            f"Adhesion (stored) takes {_t(min(cm_t))} to {_t(max(cm_t))} per curve for errors of {min(cm_e):.0e} to "
            f"{max(cm_e):.0e}, which our default grid matches in {_t(min(ours_t))} to {_t(max(ours_t))} (time ratios "
            f"{min(ratios):.0f} to {max(ratios):.0f} at equal accuracy), and it cannot locate the folds or follow "
            f"the unstable branch.",
            "- Speed: " + "; ".join(met) + ".",
            "- Scaling: N = 100 to 4000 on 1 and 2 ranks, dense and band"
            + (f"; N = 8000 measured for {', '.join(done8000)}" if done8000 else "; N = 8000 predicted over the time budget, not run")
            + (f"; the band preconditioner is faster from N = {n_cross} on one rank." if n_cross else ".")]


def render(data: dict) -> str:
    """docs/performance.md."""
    m = data["machine"]
    L = [f"<!-- made by: {COMMAND} (petsc_adhesion/benchmarks/workprecision); do not edit by hand -->",
         "# Performance: error against run time", "",
         "Work-precision diagrams, the comparison with what users would use instead, "
         "speed and scaling.  Everything on this page (tables, figures, the statements with numbers) is written "
         "by one command,", "", "```sh", COMMAND, "```", "",
         f"(the opt-in part of `./run bench`; `./run bench -bench_workprecision` runs it after the default parts).  "
         f"This run: {data['date']}, {data['total_s'] / 60:.1f} minutes"
         + (", **quick mode** (fewer sizes and repeats)" if data.get("quick") else "") + ".", "",
         "## Summary", "", *_summary(data), "",
         "## The machine", "",
         f"{m['cpu']}, {m['cores']} cores, {m['memory_mib'] / 1024:.0f} GiB; {m['platform']}; Python {m['python']}, "
         f"numpy {m['numpy']}, scipy {m['scipy']}, PETSc {m['petsc']} and petsc4py {m['petsc4py']} (Debian), "
         f"OPENBLAS_NUM_THREADS={m['openblas_num_threads']}.  Load average {data['load_before'][0]:.2f} before the "
         f"run and {data['load_after'][0]:.2f} after it (its last part runs two ranks on the two cores).  On this "
         "shared machine single timings vary by up to 40%, so every time is the median of repeated runs "
         f"({REPEATS}, one run where a single run took more than {SLOW:g} s), and comparisons are ratios of medians "
         "measured in the same run.", "",
         "## Work-precision diagrams", "",
         "In the manner of DiffEqDevTools' work-precision sets: log10 |error| against log10 median wall time, one "
         "marked line per method, one panel per quantity: the pull-off F and lambda (the most tensile load), the "
         "primary turning points' lambda (snap-on: the fold of largest lambda; snap-off: of smallest) and the "
         "equilibrium lambda (F = 0).  Each time is that of one call of `study.trace` (influence matrices, "
         "solvers, continuation and, where used, error bars; not the process start-up).", "",
         "- **Truth**: the default grid refined by `-target_error 1e-9`, extrapolated (levels up to 4, 16 times the "
         "nodes; 1e-9 itself is not reached, the bars it reaches are in each table, about 2e-9 to 7e-9, so errors "
         "below about 1e-8 are not resolved by this truth).  `-target_error 1e-8` reaches the same finest level as the "
         "truth for most events, so its errors against it are zero or nearly: they say only that both agree.  The model is the half-infinite one.",
         "- **paper grid**: N = 531 on r_m = 10 (`-grid_type paper -adh_rmax 10`, far-field load added, the "
         "default), its grid value and its extrapolated value with bars (`paper grid, extrapolated`).",
         "- **uniform grid, r_m = 10**: N = 101, 201, 401, 801, 1601 and 4001 at mu = 1; up to 1601 at mu = 2 "
         "rough and 801 at mu = 5 (a curve costs about N^2.7 here: 125 s at N = 4001, mu = 1; the other cases "
         "take 3 to 10 times longer at equal N, so larger grids there would exceed the benchmark's time budget), "
         "grid values; its error has two parts, "
         "discretization (order ~2, observed orders below) and the domain truncation of r_m = 10 (the far-field load "
         "is added, the deflection it causes inside r_m is not), stated under each table and the floor of the line.",
         "- **edge grid (default)**: grids following the contact edge, r_m = 150, its grid value (no bars) and the "
         "default extrapolated value with bars.",
         "- **-target_error**: 1e-3 to 1e-8 on the edge grid, extrapolated.",
         "- **pmat**: the preconditioning choices on the edge grid (no bars): `-adh_pmat dense` (LU, the default), "
         "`band` (AIJ of |i - j| <= 64, LU), block Jacobi with 4 LU blocks on the band matrix (through the solvers' "
         "prefixes: `-nat_pc_type bjacobi -nat_pc_bjacobi_blocks 4 -nat_sub_pc_type lu` and the same for `arc_`) and "
         "`shell` (no preconditioner: GMRES on the operator).  They solve the same discrete problem: their errors "
         "coincide, their times differ.",
         "- mu = 1 only: the **numpy/scipy reference** (`workprecision.numpy_curve`, below) on the paper grid, and "
         "the stored **ContactMechanics + Adhesion** runs (n = 64, 128, 256 pixels per side).", ""]
    for case in data["cases"]:
        name = f"wp_{case['case']}"
        L += [f"### {CASE_TITLES[case['case']]}", "", f"![work-precision {case['case']}](figures/{name}.png)", "",
              f"Table: [figures/{name}.md](figures/{name}.md), the same numbers:", "", table_case(case), ""]
    mu1 = next(c for c in data["cases"] if c["case"] == "mu1")
    L += ["## Against what users would use instead", "",
          "### (a) A plain numpy/scipy implementation", "",
          "`workprecision.numpy_curve` is what a scientist would write in a few dozen lines: the package's influence "
          "matrix as a dense numpy array, the Lennard-Jones law, Newton with `scipy.linalg.lu_factor` of the "
          "bordered Jacobian at every iteration, pseudo-arclength continuation with a tangent predictor and simple "
          "step control (grow by 1.3 after an easy step, halve after a failure), folds by a sign change of "
          "lambdadot, the pull-off by one of dF/ds, the equilibrium by one of F, each located by the secant method "
          "on the step length.  It is an independent implementation of the same discrete problem (mu = 1, paper "
          "grid), so the event values must agree to the solvers' tolerances, and they do "
          "(`tests/test_workprecision.py` checks it):", "", compare_peers(mu1), "",
          "What it cannot do that ours does: error bars and extrapolation, grids that follow the contact edge "
          "(on a uniform or paper grid its cost grows as N^3 per factorization, and at mu = 5 a uniform grid fine "
          "enough for the cohesive zone is in the thousands of nodes), roughness, more than one rank, a domain guard "
          "(it rejects a step that closes a gap instead of shortening it).", "",
          "### (b) ContactMechanics + Adhesion", "",
          "Not installed nor run here: its results are stored in `docs/data/peer_contactmechanics.json` with the "
          "commands that regenerate them (`petsc_adhesion/benchmarks/peers.py`, own virtual environment, about "
          "45 minutes).  Its points are on the mu = 1 diagram with their stored wall times (same machine type, "
          "measured on another day under a similar load).  Its jumps are brackets of the displacement steps: the "
          "error of a fold's lambda is at least half the bracket, 7.8e-4 here.", "",
          "What it cannot do: follow the unstable branch (energy minimisation in displacement control jumps at the "
          "folds), so the turning points are known only to a bracket of the load step and the snap-on and snap-off "
          "loads are those of the last stable state before the jump; no equilibrium (its curves stop at lambda = "
          "0.5); no error estimate; its finite square [-7.5, 7.5]^2 leaves a deflection of about 2e-4 at the centre "
          "uncorrected (see the script's docstring).  What it does that we do not: full 2-D contact of arbitrary "
          "topographies.", "",
          "## Speed", "",
          "The mu = 1 curve on the default grid, one rank: continuation without and with error bars (in-process, "
          "time of `study.trace`; no bars: `wall_time_s`, its continuation alone), the whole process "
          "`python -m petsc_adhesion -adh_mu 1` (start-up, imports and output included), and the pull-off to 1e-6 "
          "and 1e-8 of the half-infinite model (`-target_error`, whole process).", "", _speed_table(data["speed"]), "",
          f"The whole process minus the in-process curve with bars (medians): "
          f"{_t(data['speed']['speed_process']['median_s'] - data['speed']['speed_curve_bars']['median_s'])} of "
          f"start-up (Python, numpy, petsc4py and MPI initialisation, imports, option checks) and output files.", ""]
    if "profile" in data:
        L += _profile_lines(data["profile"], data["speed"]["speed_curve_bars"])
    if "startup" in data:
        L += _startup_lines(data)
    L += ['Soft spheres (mu = 5 to 1000): steps, nodes and time of a default curve with its error bars against mu, one core, in [soft.md](soft.md#the-cost-against-mu), made by `python -m petsc_adhesion.benchmarks.soft`.', ""]
    sc = data["scaling"]
    n_cross = crossover(sc)
    L += ["## Scaling", "",
          f"Uniform grids on [0, 10] at mu = 1, each in its own process "
          f"(`python -m petsc_adhesion.benchmarks.workprecision scale N PMAT STEPS`, under `mpiexec -n 2` for two ranks): the "
          f"influence matrix, one Newton solve at lambda = -2 from the rigid guess (fresh factorization), then "
          f"{SCALE_STEPS} continuation steps from there towards the snap-on (the time per step includes rejected "
          f"steps and refactorizations), and the peak resident memory of each rank (VmHWM of /proc/self/status; "
          f"getrusage's ru_maxrss is carried across exec by Linux and reported the benchmark process's own peak).  One "
          f"run each.  On two ranks the preconditioner is the LU of the whole matrix on each rank (PCREDUNDANT) up to "
          f"N = {REDUNDANT_MAX}, and block Jacobi with one LU block per rank beyond (PETSc's dense LU is "
          f"sequential), which does more GMRES iterations than one rank's LU.  A size whose predicted time exceeds "
          f"100 s for its (ranks, pmat) is skipped by the command; rows marked \"run separately\" were measured "
          f"after the command by the same worker, `python -m petsc_adhesion.benchmarks.workprecision scale N PMAT "
          f"{SCALE_STEPS}`, and merged (`python -m petsc_adhesion.benchmarks.workprecision docs DUMP` re-renders this page "
          f"from a run's measurements).", "", _scaling_table(sc), "",
          ("The dense operator stops being the right choice for the preconditioner at about N = "
           f"{n_cross}: from there the band matrix's solve and step (1 rank) are faster." if n_cross else
           "In the measured range the band preconditioner never beat the dense one on one rank.")
          + "  That is mu = 1 on uniform grids; on the default edge grids (300 to 500 nodes) dense LU is the "
          "faster choice in every case of the diagrams, and at mu = 5 the band preconditioner's run stops without "
          "the equilibrium (tables above)."
          + "  The operator itself (the influence matrix, O(N^2) memory and work per product) stays dense in "
          "every variant; at N = 8000 it alone is 0.5 GiB per copy.  " + _rank_statement(sc), "",
          "## Where we lose", "",
          "Every case where one of our methods was slower than another, less accurate than it claimed, or found a "
          "different curve, as measured in this run:", ""]
    L += [f"- {s}" for s in _losses(data)] or ["- nowhere in this run."]
    L += [""]
    return "\n".join(L) + "\n"


def write_docs(data: dict) -> None:
    """docs/performance.md and docs/figures/wp_<case>.{png,md} from the measured ``data``."""
    os.makedirs(FIGURES, exist_ok=True)
    for case in data["cases"]:
        name = f"wp_{case['case']}"
        plot_case(case, os.path.join(FIGURES, f"{name}.png"))
        with open(os.path.join(FIGURES, f"{name}.md"), "w") as f:
            f.write(f"<!-- made by: {COMMAND} -->\n{table_case(case)}\n")
    with open(PERFORMANCE, "w") as f:
        f.write(render(data))
