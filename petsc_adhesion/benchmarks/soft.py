"""docs/soft.md: soft spheres, the JKR end of the model and the cost of a curve against mu.

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.soft          # mu = 5, 20, 100, 300, 1000
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.soft -quick   # mu = 20, 100
    ... [-memory_gib G]        # the cap on every process started (8 GiB; 0: none)

For every mu one default curve (:func:`~petsc_adhesion.tracing.trace.trace_curve`: grids that follow the
edge, error bars, one rank) is traced and timed, in a process of its own; it gives (1) the JKR limit: the
pull-off, the fixed-grip snap-off and the zero load, scaled by the powers of mu that make the JKR values
(:mod:`~petsc_adhesion.model.reference.jkr`) constants, their distances from them with their bars, a power
of mu fitted, and Maugis-Dugdale's distances (:mod:`~petsc_adhesion.model.reference.maugis_dugdale`);
(2) soft_curves.png, F against lambda / mu beside the JKR and Maugis-Dugdale curves; (3) the cost: steps,
nodes, the call's time and the whole process's (``python -m petsc_adhesion -adh_mu MU -cont_error_estimate
true``, median of 3 runs, 1 at mu = 1000) against the targets, the load average beside them.  It writes
docs/soft.md and docs/figures/soft_*.png into the checkout it runs in (:mod:`.paths`).
"""
from __future__ import annotations

import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from .. import brent
from ..model.parameters import Model
from ..model.reference.jkr import JKR_PULL_OFF, jkr_approach, jkr_fixed_grip_pull_off, jkr_load, jkr_zero_load
from ..model.reference.maugis_dugdale import maugis_dugdale_curve, maugis_dugdale_pull_off, maugis_parameter
from ..tracing.trace import trace_curve
from . import paths

__all__ = ["MUS", "QUICK", "FIGURE_MUS", "TARGETS", "COMMAND", "QUANTITIES", "FIGURES", "power_fit",
           "jkr_limits", "ours", "maugis_dugdale_values", "measure", "measure_apart", "run_child", "markdown", "main"]

#: The Tabor parameters of the full run, and of -quick.
MUS = (5.0, 20.0, 100.0, 300.0, 1000.0)
QUICK = (20.0, 100.0)
#: The curves drawn in soft_curves.png (those of them that were traced).
FIGURE_MUS = (20.0, 100.0, 1000.0)
#: Time targets of a default curve with error bars on one core (s).
TARGETS = {20.0: 10.0, 100.0: 20.0, 1000.0: 60.0}
#: The command that writes docs/soft.md, as the page names it.
COMMAND = "python -m petsc_adhesion.benchmarks.soft"
#: The fit of the distances uses the mu at least this large (all mu when fewer than two are).
FIT_FROM = 100.0
#: Repeats of the whole process: 3, one from this mu on (a run of minutes).
ONE_RUN_FROM = 1000.0
#: A whole process is given up after this long (s); a worker (one mu: its curve and its processes) after this.
PROCESS_TIMEOUT = 1200.0
WORKER_TIMEOUT = 3600.0
#: The cap on the address space of every process the benchmark starts (GiB; -memory_gib): the machine is shared.
MEMORY_GIB = 8.0
#: The figures written, by name (docs/figures/NAME.png).
FIGURES = ("soft_curves", "soft_jkr")
#: A distance from JKR is resolved where it is at least this many of its error bars.
RESOLVED = 2.0
#: The compared quantities: key, how the page names it, the exponent its distance from JKR is expected to fall
#: with: the cohesive zone over the contact radius, 0.75 mu^-1.5 / 2.4 mu^0.5, as Maugis-Dugdale's do.
QUANTITIES = (
    ("pull_off_F", "load-control pull-off F_p", -2.0),
    ("snap_off_F", "fixed-grip snap-off F", -2.0),
    ("snap_off_lam", "fixed-grip snap-off lambda / mu", -2.0),
    ("zero_lam", "zero-load approach lambda / mu", -2.0),
    ("zero_a", "zero-load contact radius a / mu^(1/2)", -2.0),
)


def power_fit(mu, distance) -> tuple[float, float]:
    """(p, c) of the least-squares fit |distance| = c mu^p in log-log (at least two points; zeros left out).

    >>> p, c = power_fit([10.0, 100.0, 1000.0], [3e-2, 3e-4, 3e-6])
    >>> round(p, 12), round(c, 12)
    (-2.0, 3.0)
    """
    mu, d = np.asarray(mu, dtype=float), np.abs(np.asarray(distance, dtype=float))
    keep = d > 0
    if keep.sum() < 2:
        raise ValueError("a power fit needs two nonzero distances")
    p, logc = np.polyfit(np.log(mu[keep]), np.log(d[keep]), 1)
    return float(p), float(math.exp(logc))


def jkr_limits(mu: float) -> dict:
    """The JKR values of :data:`QUANTITIES` at ``mu``, scaled (they are constants: the JKR curve is
    self-similar in lambda / mu, F and a / mu^(1/2))."""
    lam_fg, F_fg = jkr_fixed_grip_pull_off(mu)
    a0, lam0 = jkr_zero_load(mu)
    return {"pull_off_F": JKR_PULL_OFF, "snap_off_F": F_fg, "snap_off_lam": lam_fg / mu,
            "zero_lam": lam0 / mu, "zero_a": a0 / math.sqrt(mu)}


def ours(curve, mu: float) -> dict:
    """The curve's values of :data:`QUANTITIES` as (value, bar), scaled like :func:`jkr_limits`; the
    fixed-grip snap-off is the primary one (the fold of least lambda), the equilibrium the last (F = 0 in
    contact)."""
    def bar(x):
        return float("nan") if x is None else float(x)

    out = {}
    po = curve.pull_off
    if po is not None:
        out["pull_off_F"] = (po.F.value, bar(po.F.err))
    offs = curve.events_of("snap_off")
    if offs:
        so = min(offs, key=lambda e: e.lam.value)
        out["snap_off_F"] = (so.F.value, bar(so.F.err))
        out["snap_off_lam"] = (so.lam.value / mu, bar(so.lam.err) / mu)
    eqs = curve.events_of("equilibrium")
    if eqs:
        eq = max(eqs, key=lambda e: e.lam.value)
        out["zero_lam"] = (eq.lam.value / mu, bar(eq.lam.err) / mu)
        if eq.contact_radius is not None:
            out["zero_a"] = (eq.contact_radius.value / math.sqrt(mu), bar(eq.contact_radius.err) / math.sqrt(mu))
    return out


def _md_at(mu: float, x):
    """Maugis-Dugdale's (A, F, lambda) at m = 1 + e^x."""
    return maugis_dugdale_curve(mu, 1.0 + np.exp(x))


def maugis_dugdale_values(mu: float) -> dict:
    """The Maugis-Dugdale values of :data:`QUANTITIES` at ``mu`` (lambda_MD = maugis_parameter(mu)), scaled
    like :func:`jkr_limits`: the pull-off from :func:`maugis_dugdale_pull_off`, the fixed-grip snap-off
    (least lambda) and the zero load on the curve, bracketed on a grid in log(m - 1) and refined by Brent."""
    x = np.linspace(math.log(1e-14), math.log(1e6), 4001)
    A, F, lam = _md_at(mu, x)
    i = int(np.argmin(lam))
    xs = brent.minimum(lambda y: float(_md_at(mu, y)[2]), x[max(i - 1, 0)], x[min(i + 1, x.size - 1)], xatol=1e-12)
    A_fg, F_fg, lam_fg = (float(v) for v in _md_at(mu, xs))
    j = int(np.flatnonzero(np.diff(np.sign(F)) != 0)[0])       # F falls through 0 as m grows (the contact shrinks)
    xz = brent.root(lambda y: float(_md_at(mu, y)[1]), x[j], x[j + 1])
    A0, _, lam0 = (float(v) for v in _md_at(mu, xz))
    return {"pull_off_F": float(maugis_dugdale_pull_off(mu)), "snap_off_F": F_fg, "snap_off_lam": lam_fg / mu,
            "zero_lam": lam0 / mu, "zero_a": A0 / math.sqrt(mu)}


def _marks(curve, mu: float) -> list[tuple]:
    """The pull-off and the primary snap-off of a curve as (lambda / mu, F, their bars) for the figure."""
    offs = curve.events_of("snap_off")
    events = [curve.pull_off, min(offs, key=lambda e: e.lam.value) if offs else None]
    return [(e.lam.value / mu, e.F.value, (e.lam.err or 0.0) / mu, e.F.err or 0.0) for e in events if e is not None]


def run_child(cmd: list[str], cwd: str, timeout: float, limit_bytes: int = 0) -> dict:
    """Run ``cmd``, its output to files in ``cwd``: its wall time, CPU time (user + system) and peak resident
    memory (from wait4), exit status (None when killed after ``timeout`` s) and last line of stderr."""
    import signal
    import threading

    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))   # the package's parent
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join(p for p in (here, os.environ.get("PYTHONPATH")) if p))
    with open(os.path.join(cwd, "stdout"), "w") as out, open(os.path.join(cwd, "stderr"), "w") as err:
        t0 = time.perf_counter()
        # capped: on a shared machine a run that outgrows the cap fails by itself, not by the OOM killer
        cap = (lambda: resource.setrlimit(resource.RLIMIT_AS, (limit_bytes,) * 2)) if limit_bytes else None
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=out, stderr=err, preexec_fn=cap)
        timer = threading.Timer(timeout, lambda: proc.send_signal(signal.SIGKILL))
        timer.start()
        try:
            _, status, ru = os.wait4(proc.pid, 0)
        finally:
            timer.cancel()
        wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    lines = open(os.path.join(cwd, "stderr")).read().strip().splitlines()
    killed = os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL and wall >= timeout
    return {"wall_s": wall, "cpu_s": ru.ru_utime + ru.ru_stime, "peak_mb": ru.ru_maxrss / 1024.0,
            "status": None if killed else proc.returncode, "last": lines[-1] if lines else ""}


def measure(mu: float, processes: bool = True, limit_bytes: int = 0) -> dict:
    """One default curve at ``mu`` (timed, in this process), its values, cost and branch; and, when
    ``processes``, the whole process timed (3 runs, 1 from ONE_RUN_FROM on, each capped at ``limit_bytes``)."""
    load = os.getloadavg()[0]
    c0, t0 = time.process_time(), time.perf_counter()
    curve = trace_curve(Model(mu=mu))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    d = curve.diagnostics
    folds = [e for e in curve.events if e.kind in ("snap_on", "snap_off")]
    rec = {"mu": mu, "load_before": load, "wall_s": wall, "cpu_s": cpu, "trace_s": d.wall_time_s,
           "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
           "errors_s": float("nan") if d.error_estimate is None else d.error_estimate.wall_time_s,
           "steps": d.steps, "rejected": d.rejected_steps, "regrids": d.regrids, "nodes": curve.grid.largest,
           "grids": 0 if curve.grid.n_nodes is None else len(curve.grid.n_nodes), "turning_points": len(folds),
           "folds": sorted(((f.kind, f.lam.value, f.F.value) for f in folds), key=lambda f: -f[1]),
           "complete": curve.complete, "warnings": curve.warnings, "values": ours(curve, mu),
           "jkr": jkr_limits(mu), "md": maugis_dugdale_values(mu),
           "branch": (curve.lam / mu, curve.F.copy(), curve.stable.copy()), "marks": _marks(curve, mu)}
    del curve
    if processes:                    # the whole process, one run after another in a scratch directory
        with tempfile.TemporaryDirectory() as tmp:
            rec["process"] = [run_child([sys.executable, "-m", "petsc_adhesion", "-adh_mu", f"{mu:g}",
                                         "-cont_error_estimate", "true"], tmp, PROCESS_TIMEOUT, limit_bytes)
                              for _ in range(1 if mu >= ONE_RUN_FROM else 3)]
    return rec


def measure_apart(mu: float, limit_bytes: int, timeout: float) -> dict:
    """:func:`measure` in a process of its own (``-worker``), capped at ``limit_bytes``: each mu starts from a
    fresh process and a curve that fails, or outgrows the cap, costs only its own record, which then says
    why (``failed``)."""
    import pickle

    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "record.pickle")
        run = run_child([sys.executable, "-m", "petsc_adhesion.benchmarks.soft", "-worker", f"{mu!r}", out,
                         str(limit_bytes)], tmp, timeout, limit_bytes)
        if run["status"] == 0 and os.path.exists(out):
            with open(out, "rb") as f:
                return pickle.load(f)
    why = (f"no result in {timeout:g} s" if run["status"] is None else
           f"exit {run['status']} after {run['wall_s']:.0f} s, peak {run['peak_mb'] / 1024:.1f} GiB"
           + (f" (cap {limit_bytes / 2**30:g} GiB)" if limit_bytes else "") + f": {run['last'][:200]}")
    return {"mu": mu, "failed": why}


# -- the page ----------------------------------------------------------------------------------------

def _fmt_t(t: float) -> str:
    return f"{t:.1f}" if t < 100 else f"{t:.0f}"


def _runs(stable: np.ndarray) -> list[slice]:
    """The runs of equal stability of a branch, each overlapping the next by a point (the line is whole)."""
    cuts = np.flatnonzero(np.diff(stable.astype(int)) != 0) + 1
    edges = [0, *cuts.tolist(), len(stable)]
    return [slice(a, min(b + 1, len(stable))) for a, b in zip(edges[:-1], edges[1:])]


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _jkr_curve():
    """The JKR curve, (lambda / mu, F), contact radius a / mu^(1/2) from 0.02 to 4 (mu-independent)."""
    t = np.linspace(0.02, 4.0, 800)
    return jkr_approach(t, 1.0), jkr_load(t, 1.0)


def _md_curve(mu: float):
    A, F, lam = _md_at(mu, np.linspace(math.log(1e-12), math.log(1e3), 12000))
    return lam / mu, F


def _mu_ticks(ax, mus) -> None:
    """Log axis in mu with the measured mu as its ticks."""
    ax.set_xscale("log")
    ax.set_xticks(list(mus), minor=False)
    ax.set_xticks([], minor=True)
    ax.set_xticklabels([f"{m:g}" for m in mus])
    ax.set_xlabel("mu")


#: The panels of soft_curves.png: title, lambda / mu range, F range.
_PANELS = (("load against approach, scaled", (-2.3, 2.4), (-0.85, 2.1)),
           ("about the load-control pull-off", (-0.95, -0.6), (-0.7525, -0.7475)),
           ("about the fixed-grip snap-off", (-1.625, -1.595), (-0.55, -0.30)))


def figure_curves(records: list[dict], path: str) -> list[float]:
    """soft_curves.png: F against lambda / mu for the traced mu of FIGURE_MUS (all traced mu when none is),
    JKR and Maugis-Dugdale beside; returns the mu drawn."""
    plt = _plt()
    drawn = [r for r in records if r["mu"] in FIGURE_MUS] or records
    fig, axes = plt.subplots(1, len(_PANELS), figsize=(15, 4.6))
    lj, Fj = _jkr_curve()
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (title, xlim, ylim) in zip(axes, _PANELS):
        ax.plot(lj, Fj, color="k", lw=2.4, alpha=0.3, label="JKR (every mu)")
        for k, r in enumerate(drawn):
            c = colors[k % len(colors)]
            x, F, st = r["branch"]
            for n, sl in enumerate(_runs(st)):
                ax.plot(x[sl], F[sl], color=c, lw=1.3 if ax is axes[0] else 0.8, ls="-" if st[sl.start] else "--",
                        marker=".", ms=2.5 if ax is axes[0] else 4, alpha=1.0 if ax is axes[0] else 0.6,
                        label=f"ours, mu = {r['mu']:g}" + ("" if ax is axes[0] else ": computed points")
                        if n == 0 else None)
            if ax is not axes[0]:
                for x0, F0, xe, Fe in r.get("marks", ()):
                    ax.errorbar([x0], [F0], xerr=[xe], yerr=[Fe], fmt="D", color=c, ms=5, mfc="white", zorder=5,
                                label="its event (best value, bars)" if x0 == r["marks"][0][0] else None)
            lm, Fm = _md_curve(r["mu"])
            ax.plot(lm, Fm, color=c, lw=1.0, ls=":",
                    label=f"Maugis-Dugdale, lambda_MD = {float(maugis_parameter(r['mu'])):.4g}")
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        ax.set_xlabel("lambda / mu")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("F  (2 pi R gamma)")
    axes[0].legend(fontsize=7, loc="upper left", title="dashed: unstable (fixed grip)", title_fontsize=7)
    axes[1].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return [r["mu"] for r in drawn]


def figure_jkr(records: list[dict], path: str) -> None:
    """soft_jkr.png: |distance from JKR| against mu, ours with bars (open where not resolved) and
    Maugis-Dugdale's, each quantity."""
    plt = _plt()
    fig, axes = plt.subplots(1, len(QUANTITIES), figsize=(3.2 * len(QUANTITIES), 3.5), sharey=True)
    mus = [r["mu"] for r in records]
    for ax, (key, label, _) in zip(axes, QUANTITIES):
        have = [r for r in records if key in r["values"]]
        if not have:
            continue
        m, (d, b) = np.array([r["mu"] for r in have]), np.abs(np.array([_distance(r, key) for r in have]).T)
        ok = np.array([resolved(r, key) for r in have], dtype=bool)
        ax.plot(m, d, "-", color="C0", lw=1)
        ax.errorbar(m[ok], d[ok], yerr=b[ok], fmt="o", color="C0", ms=5, label="ours")
        if (~ok).any():
            ax.plot(m[~ok], d[~ok], "o", mfc="none", color="C0", ms=5, label=f"ours, < {RESOLVED:g} bars")
            ax.plot(m[~ok], b[~ok], "v", color="C0", ms=4, alpha=0.6, label="its bar")
        ax.plot(mus, [abs(r["md"][key] - r["jkr"][key]) for r in records], "s:", color="C1", ms=4, mfc="none",
                label="Maugis-Dugdale")
        ax.set_yscale("log")
        ax.set_title(label, fontsize=8)
        _mu_ticks(ax, mus)
        ax.grid(alpha=0.3, which="both")
    axes[0].set_ylabel("|value - JKR|")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _distance(r: dict, key: str) -> tuple[float, float]:
    """(ours - JKR, our bar) of one record."""
    v, b = r["values"][key]
    return v - r["jkr"][key], b


def resolved(r: dict, key: str) -> bool:
    """Whether our distance from JKR is at least RESOLVED bars (nan bars: not resolved)."""
    if key not in r["values"]:
        return False
    d, b = _distance(r, key)
    return bool(abs(d) >= RESOLVED * b)


def fit_points(records: list[dict], key: str) -> list[dict]:
    """The records a power is fitted to: those whose distance is resolved, at mu >= FIT_FROM when two are,
    else the two largest resolved mu (none when fewer than two are resolved)."""
    res = [r for r in records if resolved(r, key)]
    big = [r for r in res if r["mu"] >= FIT_FROM]
    pts = big if len(big) >= 2 else res[-2:]
    return pts if len(pts) >= 2 else []


def _jkr_section(records: list[dict], command: str) -> list[str]:
    lim = records[0]["jkr"]
    head = "| mu | " + " | ".join(label for _, label, _ in QUANTITIES) + " |"
    rule = "|---" * (len(QUANTITIES) + 1) + "|"
    vals = [head, rule, "| JKR (mu -> infinity) | " + " | ".join(f"{lim[k]:.6f}" for k, _, _ in QUANTITIES) + " |"]
    dist = [head, rule]
    for r in records:
        cells, dcells = [], []
        for key, _, _ in QUANTITIES:
            if key not in r["values"]:
                cells.append("-")
                dcells.append("-")
                continue
            v, b = r["values"][key]
            d = v - r["jkr"][key]
            cells.append(f"{v:.6f} +- {b:.1e}")
            star = "" if resolved(r, key) else "\\*"
            dcells.append(f"{d:+.2e} +- {b:.1e}{star} (MD {r['md'][key] - r['jkr'][key]:+.1e})")
        vals.append(f"| {r['mu']:g} | " + " | ".join(cells) + " |")
        dist.append(f"| {r['mu']:g} | " + " | ".join(dcells) + " |")
    fit_rows = ["| quantity | ours: p of the distance ~ c mu^p | c | fitted on mu | Maugis-Dugdale's p (same mu) | "
                "expected p | within 2 bars of JKR at mu | p on every mu, bars ignored |", "|---" * 8 + "|"]
    notes = []
    for key, label, expected in QUANTITIES:
        pts = fit_points(records, key)
        unres = [f"{r['mu']:g}" for r in records if key in r["values"] and not resolved(r, key)]
        every = [r for r in records if key in r["values"] and _distance(r, key)[0] != 0.0]
        crude = f"{power_fit([r['mu'] for r in every], [_distance(r, key)[0] for r in every])[0]:.2f}" \
            if len(every) >= 2 else "-"
        if pts:
            mus = [r["mu"] for r in pts]
            p, c = power_fit(mus, [_distance(r, key)[0] for r in pts])
            pm, _ = power_fit(mus, [r["md"][key] - r["jkr"][key] for r in pts])
            fit_rows.append(f"| {label} | {p:.2f} | {c:.3g} | {', '.join(f'{m:g}' for m in mus)} | {pm:.2f} | "
                            f"{expected:g} | {', '.join(unres) or '-'} | {crude} |")
            if abs(p - expected) > 0.25:
                notes.append(f"{label}: falls as mu^{p:.2f} on mu = {', '.join(f'{m:g}' for m in mus)}, "
                             f"{'slower' if p > expected else 'faster'} than the expected mu^{expected:g}")
        else:
            fit_rows.append(f"| {label} | - (fewer than two distances resolved) | - | - | - | {expected:g} | "
                            f"{', '.join(unres) or '-'} | {crude} |")
    first = records[0]
    ratio = ", ".join(f"{abs(_distance(first, k)[0] / (first['md'][k] - first['jkr'][k])):.2g}"
                      for k, _, _ in QUANTITIES if k in first["values"])
    shifts = "; ".join(f"mu = {r['mu']:g}: " + ", ".join(
        f"{r['mu'] * _distance(r, k)[0]:+.3f} +- {r['mu'] * _distance(r, k)[1]:.1e}"
        for k in ("snap_off_lam", "zero_lam") if k in r["values"]) for r in records)
    return [
        "## The JKR limit", "",
        f"Made by `{command}`.  Each mu is one default curve (grids that follow the contact edge, error bars); "
        "every value is scaled by the power of mu that makes its JKR value a constant (the JKR curve is "
        "self-similar in lambda / mu, F and a / mu^(1/2)), and the constants are those of "
        "`model/reference/jkr.py`: the load-control pull-off `JKR_PULL_OFF` = -3/4, the fixed-grip snap-off "
        "`jkr_fixed_grip_pull_off` (F = -5/12 at lambda / mu = -3 (pi/8)^(2/3) = "
        f"{lim['snap_off_lam']:.5f}), the zero load `jkr_zero_load` (lambda / mu = {lim['zero_lam']:.5f}, "
        f"a / mu^(1/2) = (9 pi / 2)^(1/3) = {lim['zero_a']:.5f}).  The fixed-grip snap-off is the primary "
        "one, the fold of least lambda; the zero load is the equilibrium in contact, its contact radius where "
        "the separation rises through the edge level (docs/numerics.md).", "",
        f"Our values, with their error bars, made by `{command}`:", "", *vals, "",
        f"Their distances from JKR (ours minus JKR, with our bar; \\* where the distance is less than "
        f"{RESOLVED:g} bars, so that the curve agrees with JKR within its error bars; MD: the Maugis-Dugdale model "
        f"at the same mu, lambda_MD = {float(maugis_parameter(1.0)):.4f} mu, minus JKR), made by `{command}`:", "",
        *dist, "",
        "![distances from JKR](figures/soft_jkr.png)", "",
        f"Figure soft_jkr.png, made by `{command}`: |value - JKR| against mu, ours with its bars (filled where "
        f"resolved, at least {RESOLVED:g} bars; open where not) and Maugis-Dugdale's (dotted).", "",
        f"How the distances fall, made by `{command}`: a power c mu^p fitted (least squares in log-log) to our "
        f"resolved distances (at least {RESOLVED:g} bars) at mu >= {FIT_FROM:g}, or to the two largest resolved "
        "mu when fewer than two of those are; Maugis-Dugdale's p on the same mu beside it, and, last, the p of "
        "a fit to every mu whatever its bars (indicative only where the distances are not resolved).  A distance smaller "
        "than its bars says only that the curve meets JKR to within them: the default bars, ~1e-4, are then "
        "the limit of what the table can show (`-target_error` would tighten them, at a cost).  Expected: "
        "every distance falls as the cohesive zone over the contact radius, 0.75 mu^-1.5 / 2.4 mu^0.5, that is "
        "as mu^-2, as Maugis-Dugdale's do at every mu here.  lambda is measured from the rigid sphere touching "
        "at the equilibrium separation (H(0) = 0 at lambda = 0 for the rigid sphere), JKR's delta from "
        "touching, so no O(1) offset between them is expected (`jkr_approach` allows one): such an offset "
        "would be a constant mu times the distance of the approaches, mu (lambda / mu - JKR), which is "
        f"(fixed-grip snap-off, zero load): {shifts}.", "", *fit_rows, "",
        f"At mu = {first['mu']:g} our distances are {ratio} times Maugis-Dugdale's (in the order of the "
        "table's columns): the Lennard-Jones law's attraction has a tail (H^-3) beyond the cohesive zone "
        "that the Dugdale law cuts off, one likely reason the model sits further from JKR than Maugis-Dugdale "
        "at the same mu.", "",
        *(["Where the rate differs from the expected one (by more than 0.25):", "",
           *(f"- {n}." for n in notes), ""] if notes else
          ["Every fitted rate is within 0.25 of the expected mu^-2.", ""]),
    ]


def _cost_section(records: list[dict], command: str) -> list[str]:
    rows = ["| mu | complete | turning points | steps (rejected) | regrids | grids | nodes (largest grid) | "
            "trace (s) | error bars (s) | the call: wall (CPU) (s), peak memory (GiB) | whole process: median "
            "wall (CPU) (s) [runs, min-max wall] peak memory (GiB) | target (s) | met (call) | met (process) |",
            "|---" * 14 + "|"]
    for r in records:
        t = TARGETS.get(r["mu"])
        runs = r.get("process") or []
        if runs:
            ps = [x["wall_s"] for x in runs]
            med = statistics.median(ps)
            proc = (f"{_fmt_t(med)} ({_fmt_t(statistics.median(x['cpu_s'] for x in runs))}) "
                    f"[{len(ps)}, {_fmt_t(min(ps))}-{_fmt_t(max(ps))}] "
                    f"{max(x['peak_mb'] for x in runs) / 1024:.2f}")
            if any(x["status"] != 0 for x in runs):
                proc += " exit " + ",".join("killed" if x["status"] is None else str(x["status"]) for x in runs)
                med = None if all(x["status"] != 0 for x in runs) else med
        else:
            med, proc = None, "-"
        met_call = "-" if t is None else ("met" if r["wall_s"] <= t else "missed")
        met_proc = "-" if t is None or med is None else ("met" if med <= t else "missed")
        rows.append(f"| {r['mu']:g} | {'yes' if r['complete'] else 'no'} | {r['turning_points']} | "
                    f"{r['steps']} ({r['rejected']}) | {r['regrids']} | {r['grids']} | {r['nodes']} | "
                    f"{_fmt_t(r['trace_s'])} | {_fmt_t(r['errors_s'])} | {_fmt_t(r['wall_s'])} "
                    f"({_fmt_t(r['cpu_s'])}), {r['peak_mb'] / 1024:.2f} | {proc} | {'-' if t is None else f'{t:g}'} | {met_call} | {met_proc} |")
    loads = ", ".join(f"{r['load_before']:.2f}" for r in records)
    warn = [f"- mu = {r['mu']:g}: " + "; ".join(r["warnings"]) for r in records if r["warnings"]]
    folds = [f"- mu = {r['mu']:g}: " + ", ".join(f"{k} at lambda {lam:.4f} (F = {F:.5f})" for k, lam, F in r["folds"])
             for r in records]
    return [
        "## The cost against mu", "",
        f"Made by `{command}`.  One default curve per mu, error bars included, on one core "
        "(`trace_curve(Model(mu=MU))`: the call, timed by the wall clock around it, its solvers made inside; "
        "`trace` and `error bars` are the curve's own account of its two phases), and the whole process "
        "`python -m petsc_adhesion -adh_mu MU -cont_error_estimate true` timed from outside (start-up, "
        f"PETSc, the curve and its printout; median of 3 runs, 1 from mu = "
        f"{ONE_RUN_FROM:g} on).  Nodes: the largest grid of the curve (grids that follow the edge are made "
        "along it; `grids` counts them).  The targets are for a default curve with error bars on one core.", "",
        *rows, "",
        f"Load average (1 min, {os.cpu_count()} cores) before each mu: {loads}.  Single timings on this machine "
        "vary by up to 40%, and the machine may be shared with other work: with a load above the number of "
        "cores the wall time exceeds the CPU time (in brackets), which is what the run itself cost.  The "
        "targets are met or missed on the wall time, as measured.  A benchmark is a measurement, not a test.", "",
        "The turning points of each curve, by decreasing lambda (snap_on, snap_off; the primary pair is the "
        "first and the last: the forming of the contact and the fixed-grip snap-off; any between are further "
        "pairs as the contact forms):", "", *folds, "",
        *(["Warnings:", "", *warn, ""] if warn else ["No curve warned.", ""]),
    ]


def markdown(records: list[dict], quick: bool, wall: float, drawn: list[float], command: str = COMMAND,
             failed=(), gib: float = MEMORY_GIB) -> str:
    """The text of docs/soft.md from the records of :func:`measure` (``failed``: (mu, why) of the curves that
    could not be traced)."""
    cmd = command + (" -quick" if quick else "")
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    mus = ", ".join(f"{r['mu']:g}" for r in records)
    text = [
        f"<!-- made by: OPENBLAS_NUM_THREADS=1 {cmd} (petsc_adhesion/benchmarks/soft.py); do not edit by hand -->",
        "# Soft spheres: the JKR end", "",
        "Large Tabor parameters (soft probes and substrates: polymers, gels, PDMS, mu of 10^2 to 10^3): the "
        "model's values against the JKR limit, its curves beside JKR's and Maugis-Dugdale's, and the cost of a "
        "curve against mu.  Everything on this page is written by one command,", "",
        "```sh", f"OPENBLAS_NUM_THREADS=1 {command}            # mu = {', '.join(f'{m:g}' for m in MUS)}",
        f"OPENBLAS_NUM_THREADS=1 {command} -quick     # mu = {', '.join(f'{m:g}' for m in QUICK)}", "```", "",
        f"This run: `{cmd}`, mu = {mus}; {stamp}, {wall / 60:.1f} minutes; one rank, "
        f"Python {platform.python_version()}, numpy {np.__version__}, OPENBLAS_NUM_THREADS="
        f"{os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}.  Each mu runs in a process of its own, and every "
        f"process the benchmark starts is capped at {gib:g} GiB of address space "
        f"(`-memory_gib`; 0: no cap): the machine is shared, and a run that outgrows the cap fails by itself "
        "and is said here rather than calling the kernel's out-of-memory killer onto other work.", "",
        *([f"**No curve at mu = {m:g}**: {why}." for m, why in failed] + [""] if failed else []),
        "## Why the cost need not grow with mu", "",
        "At large mu the contact is JKR's, its radius about 2.4 mu^(1/2), and the adhesion acts in a cohesive "
        "zone at its edge only about 0.75 mu^-1.5 wide: a fixed grid fine wherever that edge travels would need "
        "~mu^2 nodes, and steps that move a sharp edge across a fixed grid must each stay within the zone.  In "
        "the frame of the edge (r = a rho, the contact radius a an unknown, the edge pinned at rho = 1) the edge "
        "stands still, so the grid is fine only about rho = 1 and coarsens geometrically away from it (its size "
        "need grow only like log mu, not mu^2), and the curve is, to leading order, the same curve in lambda / mu "
        "and F at every mu (JKR's; the figure below), which steps scaled with mu cover in a number that need not "
        "grow.  What stays on the scale of the zone, not of mu, is the forming of the contact, where the curve "
        "turns within a few epsilon of lambda.", "",
        *_jkr_section(records, cmd),
        "## The curves beside JKR and Maugis-Dugdale", "",
        "![F against lambda / mu](figures/soft_curves.png)", "",
        f"Figure soft_curves.png, made by `{cmd}`: F against lambda / mu of our default curves at mu = "
        f"{', '.join(f'{m:g}' for m in drawn)} (solid: stable under displacement control, dashed: unstable), the "
        "JKR curve (`jkr_load`, `jkr_approach`: one curve for every mu in these variables) and the "
        "Maugis-Dugdale curve at the same mu (`maugis_dugdale_curve`, dotted, its Maugis parameter lambda_MD = "
        f"`maugis_parameter(mu)` = {float(maugis_parameter(1.0)):.4f} mu: the Dugdale stress taken as the "
        "Lennard-Jones peak traction, the work of adhesion the same).  Middle and right: about the "
        "load-control pull-off (the minimum of F) and the fixed-grip snap-off (the least lambda), where the "
        "distances of the tables above can be seen.  Neither "
        "closed form has the curve before contact (JKR's F = 0 there, Maugis-Dugdale's not drawn); ours starts "
        "out of reach of the forces.", "",
        *_cost_section(records, cmd),
    ]
    return "\n".join(text)


def main(argv: list[str]) -> int:
    """Trace, time, draw and write docs/soft.md (``-quick``: mu = 20, 100; ``-memory_gib G``: the cap on each
    process, MEMORY_GIB by default, 0 for none)."""
    if argv[:1] == ["-worker"]:                      # -worker MU FILE LIMIT: measure_apart's process
        import pickle
        with open(argv[2], "wb") as f:
            pickle.dump(measure(float(argv[1]), True, int(argv[3])), f)
        return 0
    quick, rest, gib = "-quick" in argv, [a for a in argv if a != "-quick"], MEMORY_GIB
    if rest:
        try:
            if rest[0] != "-memory_gib" or len(rest) != 2:
                raise ValueError(rest)
            gib = float(rest[1])
        except ValueError:
            print(f"{COMMAND}: {' '.join(rest)}?  usage: {COMMAND} [-quick] [-memory_gib G]", file=sys.stderr)
            return 2
    limit = int(gib * 2**30)
    t0 = time.perf_counter()
    records, failed = [], []
    for mu in (QUICK if quick else MUS):
        rec = measure_apart(mu, limit, WORKER_TIMEOUT)
        if "failed" in rec:
            failed.append((mu, rec["failed"]))
            print(f"mu = {mu:g}: no curve: {rec['failed']}", file=sys.stderr, flush=True)
            continue
        records.append(rec)
        ps = [x["wall_s"] for x in rec.get("process", ())] or [float("nan")]
        print(f"mu = {mu:g}: {rec['steps']} steps, {rec['nodes']} nodes, call {rec['wall_s']:.1f} s "
              f"(peak {rec['peak_mb'] / 1024:.2f} GiB), process median {statistics.median(ps):.1f} s; "
              + ", ".join(f"{k} {v[0]:.6f} +- {v[1]:.1e}" for k, v in rec["values"].items()), flush=True)
    if not records:
        print(f"{COMMAND}: no curve could be traced; nothing written", file=sys.stderr)
        return 1
    os.makedirs(paths.FIGURES, exist_ok=True)
    drawn = figure_curves(records, os.path.join(paths.FIGURES, "soft_curves.png"))
    figure_jkr(records, os.path.join(paths.FIGURES, "soft_jkr.png"))
    wall = time.perf_counter() - t0
    with open(os.path.join(paths.DOCS, "soft.md"), "w") as f:
        f.write(markdown(records, quick, wall, drawn, failed=failed, gib=gib) + "\n")
    print(f"wrote {os.path.join(paths.DOCS, 'soft.md')} and docs/figures/soft_*.png in {wall:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
