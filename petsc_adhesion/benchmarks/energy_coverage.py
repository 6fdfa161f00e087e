"""Does the energy's bar hold?  The section "The energy of a cycle" of docs/coverage.md.

    python -m petsc_adhesion.benchmarks.energy_coverage          # all cases (two at a time), then the table
    python -m petsc_adhesion.benchmarks.energy_coverage -table   # the table from docs/data/energy_coverage.json
    python -m petsc_adhesion.benchmarks.energy_coverage -case 1 0 0.05   # one case (mu sigma K|rigid), printed
    python -m petsc_adhesion.benchmarks.energy_coverage -mu 5 -jobs 1    # the cases of mu = 5 only (-sigma S
                                   # too), one at a time (their stored rows replaced, the others kept)
    python -m petsc_adhesion.benchmarks.energy_coverage -program -mu 3 5 -jobs 1   # their program's part again

For each case (mu, sigma, machine: the rigid machine or a spring of stiffness K) the program's energy
of one approach-retract cycle and its bar are those of ``trace_curve`` with its defaults (error bars
on).  The truth is the whole curve traced again on the default grids at refinement levels 0, 1, 2 (2^k
times the nodes), started, traced back and jumped exactly as ``trace_curve`` does, its energy at each
level computed with a quadrature tolerance 1000 times tighter, and extrapolated
(:func:`~petsc_adhesion.tracing.error_bars.extrapolate`).  Where that extrapolation's own bar is not
well below the program's bar (:data:`RESOLVE`), level 3 is traced too when affordable and levels 1, 2,
3 are used; else the case is reported as "truth not resolved".

Each case runs in a process of its own (PETSc started there), two at a time unless ``-jobs`` says.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import paths

__all__ = ["CASES", "RESOLVE", "LEVELS", "case", "derived", "table", "section", "main", "DATA", "DOC", "HEADING",
           "TRUTH_TOL", "TRUTH_HALVINGS", "LEVEL3_BUDGET"]

#: (mu, sigma, K or None: the rigid machine): mu = 1 .. 5, then mu = 0.5 (rigid: no hysteresis; K = 2: a small loop).
CASES = [(mu, s, K) for mu in (5.0, 3.0, 2.0, 1.0) for s in (0.0, 0.2) for K in (None, 0.05, 0.5, 2.0)] + \
    [(0.5, 0.0, None), (0.5, 0.2, None), (0.5, 0.0, 2.0)]
#: The truth is resolved when its own bar is at most this share of the program's bar.
RESOLVE = 0.1
#: The truth's levels, and the level added where they do not resolve it.
LEVELS = (0, 1, 2)
#: Level 3 is traced only where its expected time (8 times level 2's) is below this (seconds).
LEVEL3_BUDGET = 600.0
#: The truth's quadrature (energy.QUADRATURE_TOL 1e-5 and MAX_HALVINGS 6 by default).
TRUTH_TOL, TRUTH_HALVINGS = 1e-8, 8
DATA = os.path.join(paths.DATA, "energy_coverage.json")
DOC = os.path.join(paths.DOCS, "coverage.md")
HEADING = "## The energy of a cycle"


def _program(model, K) -> dict:
    """The program's energy and bar (trace_curve, defaults), the energies on the levels its bar came from, the
    bound the bar was before (the events' errors summed, :func:`~petsc_adhesion.tracing.energy.energy_bar`,
    for comparison) and the times."""
    from ..tracing import energy, error_bars, results
    from ..tracing.measured import Measured
    from ..tracing.trace import CurveRequest, trace_curve

    seen: dict = {}
    real_energy, real_levels, real_cycle = results._energy, error_bars.energy_levels, energy.cycle

    def machine(fold) -> str:
        return "spring" if fold.weight else "rigid"

    def bar(loop, fold, event_of_found, levels):
        seen.setdefault(machine(fold), {})["bound"] = energy.energy_bar(loop, fold, event_of_found)
        return real_energy(loop, fold, event_of_found, levels)

    def on_levels(tracer, loop, fold, estimate_of):
        t = time.perf_counter()
        out = real_levels(tracer, loop, fold, estimate_of)
        seen.setdefault(machine(fold), {}).update({"levels_s": time.perf_counter() - t,
                                                   "energies": out if isinstance(out, str) else
                                                   {str(k): v for k, v in out.items()}})
        return out

    def cycle(segments, fold):
        t = time.perf_counter()
        out = real_cycle(segments, fold)
        seen.setdefault(machine(fold), {})["cycle_s"] = time.perf_counter() - t
        return out

    results._energy, error_bars.energy_levels, energy.cycle = bar, on_levels, cycle
    try:
        t = time.perf_counter()
        c = trace_curve(model, request=CurveRequest(spring=K))
        wall = time.perf_counter() - t
    finally:
        results._energy, error_bars.energy_levels, energy.cycle = real_energy, real_levels, real_cycle
    mine = seen.get("rigid" if K is None else "spring", {})
    cyc = c.rigid if K is None else c.spring.cycle
    got = isinstance(cyc.energy, Measured)
    return {"value": cyc.energy.value if got else None, "bar": cyc.energy.err if got else None,
            "bar_note": cyc.energy.note if got else None,
            "loops": cyc.loops if got else 0, "note": None if got else cyc.energy.reason,
            "bar_levels": mine.get("energies"), "old_bar": mine.get("bound"),
            "time": {"curve_s": wall, "cycle_s": mine.get("cycle_s", 0.0), "levels_s": mine.get("levels_s", 0.0)}}


def _level(model, K, level: int) -> dict:
    """The whole curve on refinement ``level`` of the default grids, as trace_curve traces it, and its energy
    (the tight quadrature; at level 0 the program's too)."""
    from ..core.events import EVENT_TOL, Fold, jumps
    from ..discretization import preconditioning
    from ..discretization.problem import far_approach
    from ..tracing import energy, results
    from ..tracing.trace import _reach_landings, curve_settings, spring_start
    from ..tracing.tracer import Tracer

    t = time.perf_counter()
    tracer = Tracer(model, curve_settings(), results.curve_events((), K), EVENT_TOL, None, preconditioning.Dense(),
                    level=level, rmax=model.rmax)
    try:
        lam0 = far_approach(model)
        if K:
            lam0 = min(lam0, spring_start(K))
        tracer.run(lam0)
        fold = results.spring_fold(tracer.events) if K else next(e for e in tracer.events if isinstance(e, Fold))
        if K:
            _reach_landings(tracer, fold)
        segments = tracer.segments
        jumps([seg.finder for seg in segments])
        traced = time.perf_counter() - t
        out = {"folds": sum(f.event is fold for seg in segments for f in seg.finder.found),
               "nodes": int(max(seg.problem.layout.N for seg in segments)),
               "steps": sum(len(seg.cont.points) - 1 for seg in segments), "trace_s": traced}
        if level == 0:
            cyc = energy.cycle(segments, fold)
            out["energy_default"] = cyc.energy
        tol, halvings = energy.QUADRATURE_TOL, energy.MAX_HALVINGS
        energy.QUADRATURE_TOL, energy.MAX_HALVINGS = TRUTH_TOL, TRUTH_HALVINGS
        try:
            t = time.perf_counter()
            cyc = energy.cycle(segments, fold)
            out["cycle_s"] = time.perf_counter() - t
        finally:
            energy.QUADRATURE_TOL, energy.MAX_HALVINGS = tol, halvings
        out |= {"energy": cyc.energy, "loops": cyc.loops,
                "quadrature_err": cyc.quadrature_err if cyc.energy is not None else None, "note": cyc.note,
                "jumps": [{"kind": f.label, "c": fold.value(f.point), "F": f.point.values["F"],
                           "landing_F": None if f.landing is None else f.landing.values["F"]}
                          for f in cyc.jumps]}
    finally:
        tracer.destroy()
    return out


def _truth(levels: dict, use: tuple) -> tuple:
    """(value, bar) of the tight energies at the levels ``use``: exactly 0 when every level has no loop."""
    from ..tracing.error_bars import extrapolate

    vals = {k: levels[k]["energy"] for k in use}
    if all(v == 0.0 for v in vals.values()):
        return 0.0, 0.0
    return extrapolate(vals)


def _agree(levels: dict, use) -> str | None:
    """Why the levels ``use`` cannot be extrapolated together (their cycles differ), or None."""
    shapes = {k: (levels[k]["loops"], [j["kind"] for j in levels[k]["jumps"]]) for k in use}
    if any(levels[k]["energy"] is None for k in use):
        return "no cycle on level " + ", ".join(str(k) for k in use if levels[k]["energy"] is None)
    if len({json.dumps(s) for s in shapes.values()}) > 1:
        return "the levels jump differently: " + "; ".join(f"level {k}: {n} loops, jumps {', '.join(j) or 'none'}"
                                                         for k, (n, j) in shapes.items())
    return None


def case(mu: float, sigma: float, K: float | None) -> dict:
    """One case in this process: the program's value and bar, the levels, the truth."""
    import petsc4py
    petsc4py.init([sys.argv[0]])
    from ..model.parameters import Model
    from ..tracing.edge_grids import RMAX

    t0 = time.perf_counter()
    row = {"mu": mu, "sigma": sigma, "K": K}
    row |= _program(Model(mu=mu, sigma=sigma), K)
    model = Model(mu=mu, sigma=sigma, rmax=RMAX)
    levels = {k: _level(model, K, k) for k in LEVELS}
    use = LEVELS
    why = _agree(levels, use)
    truth, tbar = (None, None) if why else _truth(levels, use)
    bar = row["bar"]
    if bar is not None and (why or tbar > RESOLVE * bar):
        if 8 * levels[LEVELS[-1]]["trace_s"] < LEVEL3_BUDGET:
            levels[LEVELS[-1] + 1] = _level(model, K, LEVELS[-1] + 1)
            use = LEVELS[1:] + (LEVELS[-1] + 1,)
            why = _agree(levels, use)
            truth, tbar = (None, None) if why else _truth(levels, use)
        else:
            why = why or "level 3 too costly"
    why = why or _unresolved(row, truth, tbar)
    row |= {"levels": {str(k): v for k, v in levels.items()}, "truth_levels": list(use), "truth": truth,
            "truth_bar": tbar, "resolved": not why, "unresolved": why,
            "level0_diff": row["value"] - levels[0]["energy_default"]}
    row["time"]["case_s"] = time.perf_counter() - t0
    return row | derived(row)


def _unresolved(row: dict, truth, tbar) -> str | None:
    """Why the truth does not resolve the program's error (its bar above RESOLVE times the program's bar, or
    its error where it has none), or None."""
    if truth is None:
        return "no truth"
    if tbar > RESOLVE * (abs(row["value"] - truth) if row["bar"] is None else row["bar"]):
        return f"the truth's bar {tbar:.1e} is above {RESOLVE:g} times the program's" + \
            (" error" if row["bar"] is None else "")
    return None


def program_case(mu: float, sigma: float, K: float | None) -> dict:
    """The program's part of one case alone (this process): its value, bar, levels and times."""
    import petsc4py
    petsc4py.init([sys.argv[0]])
    from ..model.parameters import Model

    return {"mu": mu, "sigma": sigma, "K": K} | _program(Model(mu=mu, sigma=sigma), K)


def merged(stored: dict, program: dict) -> dict:
    """A stored case's truth (its traces on levels 0 .. 3 do not depend on how the program makes its bar) with
    the program's part measured again: the same value (the curve is unchanged: to 1e-12, else the row says
    it failed), the new bar, judged against the stored truth."""
    row = {k: v for k, v in stored.items() if k not in ("bar_terms", "jumps")} | program
    row["time"] = {**stored.get("time", {}), **program["time"]}
    if "failed" in stored or program["value"] != stored["value"] and \
            not (program["value"] is not None and stored["value"] is not None and
                 abs(program["value"] - stored["value"]) <= 1e-12 * max(1.0, abs(stored["value"]))):
        return {"mu": stored["mu"], "sigma": stored["sigma"], "K": stored["K"],
                "failed": [f"the program's value {program['value']} is not the stored {stored.get('value')}"],
                "time": row["time"]}
    row["value"] = stored["value"]
    if row["truth"] is not None and not (row["unresolved"] or "").startswith(("no cycle", "the levels jump")):
        row["unresolved"] = _unresolved(row, row["truth"], row["truth_bar"])
        row["resolved"] = not row["unresolved"]
    return row | derived(row)


def derived(row: dict) -> dict:
    """The error of the program's value, the ratio bar / error (None for no bar or no error) and whether the bar
    covers (None where the truth is not resolved or the program gives no bar)."""
    if row.get("truth") is None:
        return {"error": None, "ratio": None, "covered": None}
    err = abs(row["value"] - row["truth"])
    bar = row["bar"]
    return {"error": err, "ratio": bar / err if bar is not None and err > 0 else None,
            "covered": bool(err <= bar) if bar is not None and row["resolved"] else None}


def _run(c, flag: str = "-case") -> dict:
    """One case in a process of its own: whole (``-case``) or the program's part (``-program-case``)."""
    mu, sigma, K = c
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "petsc_adhesion.benchmarks.energy_coverage", flag, f"{mu:g}",
                           f"{sigma:g}", "rigid" if K is None else f"{K:g}"],
                          capture_output=True, text=True, cwd=paths.ROOT)
    if proc.returncode:
        return {"mu": mu, "sigma": sigma, "K": K, "failed": proc.stderr.strip().splitlines()[-1:],
                "time": {"process_s": time.perf_counter() - t}}
    row = json.loads(proc.stdout.strip().splitlines()[-1])
    if flag == "-case":
        row["time"]["process_s"] = time.perf_counter() - t
    print(f"mu = {mu:g}, sigma = {sigma:g}, {_machine(row)}: {time.perf_counter() - t:.0f} s"
          + ("" if flag == "-case" else " (program)"), file=sys.stderr, flush=True)
    return row


def _where(row: dict) -> str:
    return f"mu = {row['mu']:g}, sigma = {row['sigma']:g}, {_machine(row)}"


def _machine(row: dict) -> str:
    return "rigid" if row["K"] is None else f"K = {row['K']:g}"


def _g(x, digits: int = 2) -> str:
    return "-" if x is None else f"{x:.{digits}g}" if x == 0 else f"{x:.{digits}e}".replace("e-0", "e-").replace("e+0", "e")


def _levels_cell(r: dict) -> str:
    """The levels the program's bar came from, and the old bound's ratio to the error beside them."""
    lv = r.get("bar_levels")
    where = "-" if not r["loops"] else "events' bound" if not isinstance(lv, dict) else \
        ", ".join(sorted(lv, key=int))
    old = r.get("old_bar")
    return where + ("" if old is None or not r.get("error") else f" ({_g(old / r['error'])})")


def table(rows: list, made: dict | None = None) -> str:
    """The per-case table, the summary line and the cost, from the study's rows (those not measured again
    since the bar changed, ``stale``, named apart)."""
    stale = [r for r in rows if r.get("stale")]
    rows = [r for r in rows if not r.get("stale") or "failed" in r]        # a failed case stays under Failed
    lines = ["| mu | sigma | machine | loops | energy (program) | bar | truth | truth's bar | levels | \\|error\\| | "
             "bar / \\|error\\| | covered | bar's levels (old bound / \\|error\\|) | curve (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    counted, ratios, missed, unresolved, failed, barless = [], [], [], [], [], []
    for r in rows:
        if "failed" in r:
            failed.append(f"mu = {r['mu']:g}, sigma = {r['sigma']:g}, {_machine(r)} ({'; '.join(r['failed'])})")
            continue
        cov = "truth not resolved" if not r["resolved"] else "no bar" if r["bar"] is None else \
            "yes" if r["covered"] else "**no**"
        lines.append(f"| {r['mu']:g} | {r['sigma']:g} | {_machine(r)} | {r['loops']} | {r['value']:.8f} | {_g(r['bar'])} | "
                     + ("- | - | " if r["truth"] is None else f"{r['truth']:.8f} | {_g(r['truth_bar'], 1)} | ")
                     + f"{', '.join(map(str, r['truth_levels']))} | {_g(r['error'])} | {_g(r['ratio'])} | {cov} | "
                     f"{_levels_cell(r)} | {r['time']['curve_s']:.1f} |")
        if not r["resolved"]:
            unresolved.append(f"{_where(r)} ({r['unresolved']}; "
                              f"value {r['value']:.8f}, bar {_g(r['bar'])}"
                              + ("" if r["truth"] is None else f", truth {r['truth']:.8f} +- {_g(r['truth_bar'], 1)}")
                              + ")")
            continue
        if r["bar"] is None:
            barless.append(f"{_where(r)} (value {r['value']:.8f}, truth {r['truth']:.8f}, error {_g(r['error'])})")
            continue
        if r["loops"]:
            counted.append(r)
            if r["ratio"] is not None:
                ratios.append((r["ratio"], r))
        if not r["covered"]:
            missed.append(f"{_where(r)} (bar {_g(r['bar'])}, "
                          f"error {_g(r['error'])})")
    zeros = [r for r in rows if "failed" not in r and r["resolved"] and not r["loops"]]
    cov = sum(r["covered"] for r in counted)
    lines.append("")
    if counted:
        lo, hi = min(ratios, key=lambda x: x[0]), max(ratios, key=lambda x: x[0])
        lines.append(f"**With hysteresis: covered in {cov} of {len(counted)} cases** (a bar given, the truth resolved); "
                     f"bar / |error| median {np.median([x for x, _ in ratios]):.2g}, 90th percentile "
                     f"{np.percentile([x for x, _ in ratios], 90):.2g}, the smallest {lo[0]:.2g} "
                     f"({_where(lo[1])}), the widest {hi[0]:.3g} ({_where(hi[1])}).")
    if zeros:
        lines.append(f"Without hysteresis: {len(zeros)} cases, "
                     + ("every one 0 +- 0 on every level." if all(r["value"] == 0 and r["bar"] == 0 and r["truth"] == 0
                                                                 for r in zeros) else "NOT all 0 +- 0."))
    lines.append("\nNot covered: " + ("; ".join(missed) if missed else "none") + ".")
    lines.append("\nNo bar (an energy with hysteresis reported without one): "
                 + ("; ".join(barless) if barless else "none") + ".")
    lines.append("\nTruth not resolved: " + ("; ".join(unresolved) if unresolved else "none") + ".")
    # where the truth's own bar is known, it may still decide: |error| + its bar within the bar, or beyond it
    judged = [r for r in rows if "failed" not in r and not r["resolved"] and r["truth"] is not None and r["bar"]]
    for verdict, test in (("covered", lambda r: r["error"] + r["truth_bar"] <= r["bar"]),
                          ("missed", lambda r: r["error"] - r["truth_bar"] > r["bar"])) if judged else ():
        lines.append(f"Of these, {verdict} even with the truth's bar: "
                     + ("; ".join(_where(r) for r in judged if test(r)) or "none") + ".")
    if failed:
        lines.append("\nFailed: " + "; ".join(failed) + ".")
    if stale:
        lines.append("\nNot measured again with the bar as it is (the study was cut short): "
                     + "; ".join(_where(r) for r in stale) + ".")
    ok = [r for r in rows if "failed" not in r]
    curve = np.array([r["time"]["curve_s"] for r in ok])
    cyc = np.array([r["time"]["cycle_s"] for r in ok])
    lvl = np.array([r["time"].get("levels_s", 0.0) for r in ok if r["loops"]])
    share = lvl / np.array([r["time"]["curve_s"] for r in ok if r["loops"]])
    src = made or {}
    wall = src.get("program_s", src.get("study_s"))
    lines.append(f"\nCost: the whole curve with its error bars (`trace_curve`, what the energy needs) took "
                 f"{np.median(curve):.2g} s median, {curve.min():.2g} to {curve.max():.3g} s; `energy.cycle` "
                 f"itself {np.median(cyc) * 1e3:.0f} ms median, at most {cyc.max():.2g} s "
                 f"({np.median(cyc / curve):.1%} of the curve's time median)"
                 + ("" if not len(lvl) else
                    f"; the energy on the other levels (`error_bars.energy_levels`, with hysteresis) "
                    f"{np.median(lvl):.2g} s median, at most {lvl.max():.2g} s, {np.median(share):.0%} of the "
                    f"curve's time median, at most {share.max():.0%}")
                 + "." + ("" if wall is None else f"  The {'program' if 'program_s' in src else 'study'} took "
                          f"{wall / 60:.0f} minutes on 2 shared cores."))
    return "\n".join(lines)


def _diagnosis(rows: list) -> list:
    """Over the cases with hysteresis, a bar from the levels and a resolved truth: the level-0 error as the
    levels estimate it (|E_0 - R|, R Richardson's value of the two levels, the bar / ENERGY_BAR_FACTOR
    without the quadrature's term) against the true one, and the old bound's ratio to the error."""
    from ..tracing.error_bars import ENERGY_BAR_FACTOR, energy_bar_of

    out = []
    for r in rows:
        if "failed" in r or not r["resolved"] or not r["loops"] or r["bar"] is None:
            continue
        lv = r.get("bar_levels")
        if not isinstance(lv, dict):
            continue
        estimate = energy_bar_of({int(k): v for k, v in lv.items()}) / ENERGY_BAR_FACTOR
        out.append({"row": r, "estimate": estimate, "old": r.get("old_bar")})
    return out


def _span(xs: list) -> str:
    return f"{min(xs):.2g} to {max(xs):.3g} (median {np.median(xs):.2g})" if xs else "-"


def _again(rows: list) -> str:
    """The cases measured again whole (program and truth) at a commit of their own (``-mu``), by commit."""
    by: dict = {}
    for r in (r for r in rows if r.get("source")):
        by.setdefault((r["source"].get("commit") or "?")[:7], set()).add(r["mu"])
    return "".join(f"; the truths of mu = {', '.join(f'{m:g}' for m in sorted(mus))} traced again at commit {c}"
                   for c, mus in sorted(by.items()))


def _offsets(diag: list) -> str:
    """Where the bar's other level k is one the truth traced whole too: the loop put point by point on level k
    (the program's E_k) against the whole level-k trace's energy, beside E_0 - E_k, per case."""
    out, sizes = [], []
    for d in diag:
        r = d["row"]
        lv = {int(k): v for k, v in r["bar_levels"].items()}
        (k, ek), = ((k, v) for k, v in lv.items() if k)
        whole = r["levels"].get(str(k))
        if whole is None or whole.get("energy") is None:
            continue
        sizes.append(abs(ek - whole["energy"]))
        out.append(f"{_where(r)}: {ek - whole['energy']:+.1e} against E_0 - E_{k} = {lv[0] - ek:+.1e} "
                   f"(bar / |error| {r['ratio']:.3g})")
    return "; ".join(out) + f" (the largest difference {max(sizes):.1e})" if out else "none"


def section(rows: list, made: dict | None = None) -> str:
    """The section of docs/coverage.md, from the study's rows."""
    diag = _diagnosis([r for r in rows if not r.get("stale")])
    ok = [r for r in rows if "failed" not in r and not r.get("stale")]
    diffs = [abs(r["level0_diff"]) / abs(r["value"]) for r in ok if r["value"]]
    used = sorted({tuple(r["truth_levels"]) for r in ok})
    bar_levels = sorted({int(k) for r in ok if isinstance(r.get("bar_levels"), dict) for k in r["bar_levels"]} - {0})
    bound = [_where(r) for r in ok if r["loops"] and not isinstance(r.get("bar_levels"), dict)]
    jumps_differ = [r for r in ok if any(len(v["jumps"]) != len(r["levels"]["0"]["jumps"]) or v["folds"] !=
                                         r["levels"]["0"]["folds"] for v in r["levels"].values())]
    calib = [d["estimate"] / d["row"]["error"] for d in diag if d["row"]["error"]]
    old = [d["old"] / d["row"]["error"] for d in diag if d["old"] is not None and d["row"]["error"]]
    loose = [d["row"] for d in diag if d["row"]["ratio"] is not None and d["row"]["ratio"] > 5]
    blurred = [d["row"] for d in diag if d["row"]["error"] < d["row"]["truth_bar"]]
    safe = [d["row"]["bar"] / (d["row"]["error"] + d["row"]["truth_bar"]) for d in diag]
    src = made or {}
    truth_src = src.get("truth") or src
    return SECTION.format(
        table=table(rows, made), n=len(ok), hyst=sum(1 for r in ok if r["loops"]), m=len(diag),
        failed=sum(1 for r in rows if "failed" in r),
        resolve=RESOLVE, tol=TRUTH_TOL, budget=LEVEL3_BUDGET, same=f"{max(diffs, default=0.0):.0e}",
        used="; ".join(", ".join(map(str, u)) for u in used),
        bar_levels=", ".join(map(str, bar_levels)) or "none", bound=("none" if not bound else "; ".join(bound)),
        differ=("none" if not jumps_differ else "; ".join(_where(r) for r in jumps_differ)),
        commit=(src.get("commit") or "?")[:7], truth_commit=(truth_src.get("commit") or "?")[:7],
        again=_again(ok), offsets=_offsets(diag),
        calib=_span(calib), old=_span(old), safe=_span(safe), blurred=len(blurred),
        loose="none" if not loose else "; ".join(f"{_where(r)} ({r['ratio']:.3g})" for r in loose))


SECTION = HEADING + """

<!-- made by: python -m petsc_adhesion.benchmarks.energy_coverage (data: docs/data/energy_coverage.json; -table redraws from it) -->
Made by `python -m petsc_adhesion.benchmarks.energy_coverage` (`-table` redraws it from
docs/data/energy_coverage.json; `-program` measures the program's part again against the stored truth).
The energy one approach-retract cycle dissipates (`summary["energy"]`, and behind a spring
`summary["spring"]["energy"]`; `tracing/energy.py`) is the integral of the curve the files hold,
on its own grids (level 0).  Its bar comes from the loop computed whole on one other level of the
events' nested grids (`tracing/error_bars.py`, `energy_levels`): the nearest coarser level on which
the jumps were located (the events use it only where it resolves the contact edge), else the nearest
finer one.  The loops' borders are put on that level's curve point by point (every computed point and
every point the quadrature halved at carried to the level's grid of its segment by a zero-length
arclength correction; each corner, a fold jumped at and its landing, where the events' error bars
located it on that level) and integrated by the same quadrature on the same partition, so that the
two levels' energies differ by the grid's change alone.  The bar is three times the level-0 value's
distance from Richardson's value of the two levels (|E_0 - E_-1| from level -1, 4 |E_1 - E_0| from
level 1: three times the level-0 error that an h^2 error implies, as for the events' grid values),
plus the quadrature's estimate.  The errors of the jumps and of the borders, which largely cancel in
the loop's area, are credited, because each level's area is computed whole.  Where the level cannot
be had (a jump not located on it, a point not carried), the bar is the old bound (each jump moved by
its fold's error times its height, each stretch by its ends' errors times its width), with a note
saying so.  Levels the bars came from: {bar_levels}; the old bound: {bound}.

Why not the events' three-level extrapolation E (the bar |E_0 - E| + E's bar): on the first 14 cases
with hysteresis (mu <= 2) it missed 2 (0.42, 0.51) and its finer level cost 20 to 30% of the curve's
time at mu = 2; three times Richardson's distance from one coarser level covered all 14 (median 3).

What was measured: {n} cases ({hyst} with hysteresis; {failed} more under "Failed" below, not judged:
there the program's curve is no longer the one the stored truth started from), mu = 1, 2, 3, 5 by sigma = 0, 0.2 (the
Hermite rule), each with the rigid machine and springs K = 0.05, 0.5, 2, and mu = 0.5 (rigid:
no hysteresis; K = 2: a small loop).  The program's value and bar are `trace_curve`'s with its
defaults (commit {commit}).  The truth (traced at commit {truth_commit}{again}; the bar's code does
not enter it) is the whole curve traced again on the default grids at
refinement levels 0, 1, 2 (2^k times the nodes), started, traced back and jumped exactly as
`trace_curve` does, on grids centred where that trace moved them (not the program's), its energy
integrated with a quadrature tolerance of {tol:g} (the program's: 1e-5), and extrapolated by
`error_bars.extrapolate`.  Where that extrapolation's own bar is above {resolve:g} times the program's
bar, level 3 is traced too (when expected below {budget:.0f} s) and levels 1, 2, 3 are used, else the
case is "truth not resolved".  Levels used: {used}.  Cases whose levels found a different number of
folds or jumps: {differ}.  Level 0 of the truth's trace is the program's own curve: its energy with
the program's tolerance is the program's value to {same} (relative) in every case.  A bar covers when
|value - truth| <= bar.  The last column's levels are those the bar came from; beside them, in
brackets, the bar / |error| the old bound (sums of the events' errors) gives on the same run.

{table}

How the bar holds, on the same data ({m} cases with hysteresis, a bar from the levels and a resolved
truth).  The level-0 error the two levels imply, |E_0 - R|, is {calib} times the true error (1 would
be exact; the bar is three times it).  The old bound is {old} times the error.  Where the bar is wider
than 5 times the error: {loose}.  In {blurred} cases the error is below the truth's own bar, so their
bar / |error| is uncertain; bar / (|error| + truth's bar), a lower bound of the ratio wherever the
truth's bar holds, is {safe}.

Why the widest were wide, measured where the bar's level is one the truth traced whole too (level 1,
at mu = 3 and 5): the bar's loop on level 1 against the whole curve traced on level 1 (its own segments,
grids centred where it moved them), beside E_0 - E_1: {offsets}.  Before commit 076a832 the two
level-1 energies differed by -1.4e-4 to -2.3e-4 at sigma = 0 (one sign in every case, about as much as
E_0 - E_1; bar / |error| 90th percentile 29, the widest 40.8): the bar measured that offset.  Its cause:
where the trace passes from one segment's grid to the next, it carries the last point over by a
zero-length arclength correction, which slides along the curve by the tangential part of the
interpolation's error, and the quadrature does no work over that step (the two ends are one state), so
the slide's work is left out (mu = 5, sigma = 0, rigid: 7.3e-5 and 9.8e-5 at the loop's two handovers on
level 0, 1.9e-5 and 2.5e-5 on level 1, falling like h^2: part of each level's grid error).  The level's
loop carried both ends of every handover from level 0 and so kept level 0's slides, not its own.  A
defect, not another valid discretization: the level's loop is meant to be that level's curve under the
same quadrature, and level 0's slides do not shrink with the level.  Now a segment's first point is
carried on the level from the previous segment's last point there, as the trace carried it.  What is
left: the truth's whole traces leave the handovers' work out too, each level at its own handovers.  At
mu = 5, sigma = 0.2, rigid, their energies on levels 0, 1, 2 are 0.91858804, 0.91858454, 0.91858762,
not monotone (the truth not resolved); with the work across the handovers added (5.6e-5, 1.7e-5,
4.1e-6, falling like h^2) they are 0.91864389, 0.91860166, 0.91859169, changes of -4.2e-5 and -1.0e-5,
a clean h^2.  Integrating across the handovers would change the program's values and needs every truth
traced again: not done yet.

At mu = 2 (the level -1) the coarse level's error is 30 times the level-0 error where the bar is
widest (mu = 2, sigma = 0.2, rigid: E_-1 - E_0 = 1.4e-5, the error 4.3e-7), not 4 times: a level
not yet in the asymptotic range, which two levels cannot show.
"""


def main(argv: list[str]) -> int:
    """The study (or one case with -case mu sigma K|rigid, the program's part of one with -program-case, the
    program's part of every case against the stored truth with -program, or the table alone with -table)."""
    if argv[:1] in (["-case"], ["-program-case"]):
        K = None if argv[3] == "rigid" else float(argv[3])
        run = case if argv[0] == "-case" else program_case
        print(json.dumps(run(float(argv[1]), float(argv[2]), K)))
        return 0
    from .selection import selected
    if argv[:1] == ["-program"]:
        # the cases chosen (-mu, -sigma; all without), each stored as soon as it is done (cheapest first), the
        # others of them marked not measured again, so that a run cut short leaves a table of what it measured
        chosen, jobs = selected(argv[1:], CASES)
        if chosen is None:
            print(f"energy_coverage: {jobs}", file=sys.stderr)
            return 2
        with open(DATA) as f:
            data = json.load(f)
        if "truth" not in data["made"]:
            data["made"] = {"study_s": data["made"].get("study_s"),
                            "truth": {k: data["made"].get(k) for k in ("commit", "changed")}}
        rows = [r | {"stale": True} if (r["mu"], r["sigma"], r["K"]) in chosen else r for r in data["rows"]]
        where = {(r["mu"], r["sigma"], r["K"]): i for i, r in enumerate(rows)}
        order = sorted(chosen, key=lambda c: (c[0], c[2] is not None, c[1]))
        t = time.perf_counter()
        with ThreadPoolExecutor(jobs) as pool:
            for c, p in zip(order, pool.map(lambda c: _run(c, "-program-case"), order)):
                i = where[c]
                rows[i] = p if "failed" in p else merged({k: v for k, v in rows[i].items() if k != "stale"}, p)
                data["made"] |= {"program_s": time.perf_counter() - t, **paths.source()}
                with open(DATA + ".part", "w") as f:
                    json.dump({"made": data["made"], "rows": rows}, f, indent=1)
                os.replace(DATA + ".part", DATA)
    elif argv[:1] != ["-table"]:
        cases, jobs = selected(argv, CASES)
        if cases is None:
            print(f"energy_coverage: {jobs}", file=sys.stderr)
            return 2
        t = time.perf_counter()
        if cases != CASES and os.path.exists(DATA):
            # some cases measured again (program and truth): stored as each is done, in place of their old
            # rows, each row naming the commit it measured (the others keep the study's)
            with open(DATA) as f:
                data = json.load(f)
            with ThreadPoolExecutor(jobs) as pool:
                for c, row in zip(cases, pool.map(_run, cases)):
                    data["rows"] = [r for r in data["rows"] if (r["mu"], r["sigma"], r["K"]) != c] + \
                        [row | {"source": paths.source()}]
                    with open(DATA + ".part", "w") as f:
                        json.dump(data, f, indent=1)
                    os.replace(DATA + ".part", DATA)
        else:
            with ThreadPoolExecutor(jobs) as pool:
                rows = list(pool.map(_run, cases))
            made = {"study_s": time.perf_counter() - t, **paths.source()}
            os.makedirs(os.path.dirname(DATA), exist_ok=True)
            with open(DATA, "w") as f:
                json.dump({"made": made, "rows": rows}, f, indent=1)
    with open(DATA) as f:
        data = json.load(f)
    paths.write_section(DOC, section(data["rows"], data["made"]), HEADING)
    print(table(data["rows"], data["made"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
