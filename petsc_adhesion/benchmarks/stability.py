"""The stability matrix of docs/stability.md: every Tabor parameter and roughness, default settings.

    ./run stability            # all cells, two at a time, into docs/stability.md (about 6 minutes)
    ./run stability 20 2       # one cell (mu, sigma), printed
    ./run stability truncated  # the truncated model's rows only, into their table of docs/stability.md
    python -m petsc_adhesion.benchmarks.stability truncated 10 0 [MU SIGMA ...]  # those rows only, rewritten
    python -m petsc_adhesion.benchmarks.stability refinement 10 -6 [STEPS]  # its events on levels -2 .. 2
    python -m petsc_adhesion.benchmarks.stability truncated-check  # mu = 10 to F = 0.5 against the half-infinite

Each cell traces the curve from far apart to F >= 2 with the program's
defaults and -cont_error_estimate, as a user would, and records whether it
completed (exit status 0 and a complete result), its turning points, pull-off
with its error bar, the smallest step, rejected steps, domain-guard
activations, the most Newton and Krylov iterations of one point, the nodes,
regrids, the wall time and the warnings.  Extra rows: strong compression
(F up to 50 at mu = 1 and 10) and the smallest Tabor parameter (mu = 1e-4).  A table of its own: the
paper's truncated model (r_m = 10, no far field) at every mu it is traced to (tracing/edge_grids.py
MU_TRUNCATED), traced in the physical frame throughout.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

from . import paths

__all__ = ["MUS", "SIGMAS", "EXTRA", "TRUNCATED", "TRUNCATED_OPTIONS", "cell", "main", "OUT", "TIMEOUT", "HEAD",
           "STABILITY_DOC", "TRUNCATED_MARK", "REFINED_MARK", "LEVELS",
           "refinement", "refinement_table", "HALF_INFINITE_10", "TRUNCATION", "truncated_check"]

MUS = (0.001, 0.01, 0.1, 1.0, 3.0, 4.5, 7.0, 10.0, 20.0, 50.0, 100.0, 300.0, 1000.0)
SIGMAS = (0.0, 0.1, 0.2, 0.4, 1.0, 2.0)
#: (mu, sigma, extra options, what the row shows)
EXTRA = ((1.0, 0.0, ("-cont_F_max", "50"), "strong compression"),
         (10.0, 0.0, ("-cont_F_max", "50"), "strong compression"),
         (1e-4, 0.0, (), "smallest Tabor parameter"))
#: The truncated model's cells (mu, sigma) and their options: r_m = 10 without the far field (the paper's model).
TRUNCATED = tuple((m, s) for m in (0.1, 1.0, 3.0, 10.0) for s in (0.0, 0.3, 1.0)) + ((5.0, 0.0), (7.0, 0.0))
TRUNCATED_OPTIONS = ("-adh_rmax", "10", "-adh_farfield", "false")
OUT = os.path.join(paths.DOCS, "stability.md")
#: A cell's wall-clock limit (s).  mu = 10 truncated takes about 4 minutes of CPU, and on two cores shared by
#: 15 to 30 processes it took 3695 s of wall time (docs/stability.md): 1800 s would have cut it short.
TIMEOUT = 5400
#: The line that opens the truncated model's table in docs/stability.md (``truncated`` rewrites what follows,
#: up to REFINED_MARK: the refinement tables after it are kept).
TRUNCATED_MARK = "## The truncated model"
REFINED_MARK = "## The truncated model's events refined"


def cell(mu: float, sigma: float, extra=()) -> dict:
    """One traced curve with default settings: its summary and how the process ended."""
    with tempfile.TemporaryDirectory() as tmp:
        js = os.path.join(tmp, "s.json")
        cmd = [sys.executable, "-m", "petsc_adhesion", "-adh_mu", f"{mu:g}", "-adh_sigma", f"{sigma:g}",
               "-cont_error_estimate", *extra, "-summary", js]
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
            status, err = proc.returncode, proc.stderr.strip()
        except subprocess.TimeoutExpired:
            status, err = None, f"no result in {TIMEOUT} s"
        wall = time.perf_counter() - t0
        summary = json.load(open(js)) if os.path.exists(js) else None
    return {"mu": mu, "sigma": sigma, "extra": list(extra), "status": status, "error": err, "wall_s": wall,
            "summary": summary}


def _row(c: dict, what: str = "") -> str:
    s = c["summary"]
    if s is None:
        label = f"{c['sigma']:g}{(' ' + what) if what else ''}"
        return f"| {c['mu']:g} | {label} | no: {c['error'] or c['status']} |" + " |" * 12
    po = s["pull_off"] or {}
    err = f" +- {po['F_err']:.1e}" if "F_err" in po else " (no bar)"
    done = "yes" if c["status"] == 0 and s["complete"] else f"no (exit {c['status']})"
    folds = len(s["folds"])
    return (f"| {c['mu']:g} | {c['sigma']:g}{(' ' + what) if what else ''} | {done} | {folds} | "
            f"{po.get('F', float('nan')):.5f}{err} | {s['smallest_step']:.1e} | {s['rejected_steps']} | "
            f"{s['guard_activations']} | {s['most_newton_its']} | {s['most_ksp_its']} | {s['n_nodes']} | "
            f"{s['regrids']} | {s['wall_gap']:.2g} | {c['wall_s']:.1f} | {'; '.join(s['warnings']) or '-'} |")


HEAD = ("| mu | sigma | completed | turning points | pull-off F (error bar) | smallest step | rejected | "
        "guard | Newton (most) | Krylov (most) | nodes | regrids | wall gap | wall (s) | warnings |\n" + "|---" * 15 + "|")


#: The refinement levels of :func:`refinement`: the default grid's error-bar levels and two finer.
LEVELS = (-2, -1, 0, 1, 2)


def refinement(mu: float, lam_max: float = math.inf, steps: int | None = None, sigma: float = 0.0) -> list:
    """The truncated model's events (r_m = 10, no far field) on the default grids, traced to ``lam_max`` (or for
    ``steps`` steps at most), each
    located again on the nested levels LEVELS of its grid (twice and four times as fine among them): per event
    (label, lambda or F, {level: value}, default best value, its bar).  The differences of successive
    levels fall by 4 where the error is h^2 (error_bars.extrapolate), and the default value, made from
    levels -2, -1, 0, must lie within its bar of the finest levels' Richardson value."""
    from dataclasses import replace

    from ..discretization import preconditioning
    from ..discretization.problem import far_approach
    from ..model.parameters import Model
    from ..tracing import results
    from ..tracing.error_bars import event_errors, relocate
    from ..tracing.trace import curve_settings, step_scale
    from ..tracing.tracer import Tracer

    model = Model(mu=mu, sigma=sigma, rmax=10.0, farfield=False)
    settings = replace(curve_settings(step_scale(model)), p_max=lam_max)
    if steps is not None:
        settings = replace(settings, max_steps=steps)
    tracer = Tracer(model, settings, results.curve_events(()), None, None, preconditioning.Dense(), rmax=10.0)
    out = []
    try:
        for seg in tracer.run(far_approach(model)):
            for found in seg.finder.found:
                est = event_errors(tracer, seg, found)
                values = {0: found.point}
                for level in LEVELS:
                    if level != 0:
                        values[level] = relocate(tracer, seg, found, level)
                for key in ("lambda", "F"):
                    got = {k: (p.p if key == "lambda" else p.values["F"]) for k, p in values.items() if p is not None}
                    m = None if est is None else (est.lam if key == "lambda" else est.F)
                    out.append((found.label, key, got, None if m is None else m.value, None if m is None else m.err))
    finally:
        tracer.destroy()
    return out


#: The half-infinite model's turning points at mu = 10 (the mu = 10 row of the table above, its summary):
#: snap-on, snap-off, snap-on before the contact, and the contact's snap-off, each with a bar below 2e-6.
HALF_INFINITE_10 = (-6.08463995, -6.42384017, -6.31243824, -16.20065750)
#: What the truncation moves them by at most: the load beyond r_m = 10 is about 5e-4 of the pull-off at
#: these approaches (reference.load_beyond), the deflection it causes inside 8.5e-5 (far_deflection); the
#: turning points before the contact, where the load is about 0.05, move by 1.7e-3 (measured).
TRUNCATION = 5e-3


def truncated_check() -> list[str]:
    """mu = MU_TRUNCATED = 10 truncated at r_m = 10, traced past its equilibrium to F = 0.5 (3426 steps; 143 s
    measured once, 2011 s of wall time at a load of 15 to 30: too slow for the suite; tests/test_truncated.py
    checks mu = 4): what is wrong, one line each (none when the curve completes with exit 0 and no warning,
    has two fold pairs as the half-infinite model has, within TRUNCATION of its turning points, a pull-off
    within 1% of JKR's -3/4 and one equilibrium)."""
    from ..model.reference.jkr import JKR_PULL_OFF
    from ..tracing.edge_grids import MU_TRUNCATED

    c = cell(MU_TRUNCATED, 0.0, (*TRUNCATED_OPTIONS, "-cont_F_max", "0.5", "-cont_error_estimate", "false"))
    s, wrong = c["summary"], []
    if c["status"] != 0 or s is None or not s["complete"] or s["warnings"]:
        return [f"exit {c['status']}: {c['error'] or (s and s['warnings'])}"]
    kinds = [e["kind"] for e in s["folds"]]
    if kinds != ["snap_on", "snap_off", "snap_on", "snap_off"]:
        wrong.append(f"turning points {kinds}, not two pairs")
    for e, half in zip(s["folds"], HALF_INFINITE_10):
        if abs(e["lambda"] - half) >= TRUNCATION:
            wrong.append(f"{e['kind']} at lambda = {e['lambda']:.8f}, the half-infinite model's at {half:.8f}")
    if abs(s["pull_off"]["F"] / JKR_PULL_OFF - 1) >= 0.01:
        wrong.append(f"pull-off F = {s['pull_off']['F']:.6f}, more than 1% from JKR's {JKR_PULL_OFF}")
    if len(s["equilibria"]) != 1:
        wrong.append(f"{len(s['equilibria'])} equilibria, not one")
    print(f"mu = 10 truncated to F = 0.5: {s['steps']} steps, {c['wall_s']:.0f} s; turning points "
          + ", ".join(f"{e['lambda']:.6f}" for e in s["folds"]) + f"; pull-off {s['pull_off']['F']:.6f}")
    return wrong


def refinement_table(rows) -> str:
    """:func:`refinement`'s rows as a markdown table: the values, the ratios of successive differences, and
    the default value's distance from the Richardson value of levels 1 and 2 in units of its bar."""
    lines = ["| event | of | level -2 | level -1 | level 0 | level 1 | level 2 | ratio 0/1 | ratio 1/2 | "
             "default (levels -2..0) | bar | distance from levels 1-2 / bar |", "|---" * 12 + "|"]
    for label, key, got, best, bar in rows:
        cells = [f"{got[k]:.8f}" if k in got else "-" for k in LEVELS]
        d = {k: got[k] - got[k - 1] for k in LEVELS if k in got and k - 1 in got}
        ratio = [f"{d[k] / d[k + 1]:.2f}" if k in d and k + 1 in d and d[k + 1] else "-" for k in (0, 1)]
        rich = got[2] + (got[2] - got[1]) / 3 if 1 in got and 2 in got else None
        dist = f"{abs(best - rich) / bar:.2f}" if rich is not None and best is not None and bar else "-"
        lines.append(f"| {label} | {key} | {' | '.join(cells)} | {' | '.join(ratio)} | "
                     f"{best:.8f} | {bar:.1e} | {dist} |" if best is not None else
                     f"| {label} | {key} | {' | '.join(cells)} | {' | '.join(ratio)} | - | - | - |")
    return "\n".join(lines)


def _done(c: dict) -> bool:
    return c["status"] == 0 and bool(c["summary"]) and c["summary"]["complete"]


def _failures(cells) -> str:
    return "\n".join(f"- mu = {c['mu']:g}, sigma = {c['sigma']:g}{' ' + w if w else ''}: "
                     f"{'; '.join(c['summary']['warnings']) if c['summary'] else c['error']}"
                     for c, w in cells if not _done(c)) or "none"


def _truncated_table(cells) -> str:
    """The truncated model's section: its rows and its cells not completed."""
    return TRUNCATED_DOC.format(head=HEAD, rows="\n".join(_row(c, w) for c, w in cells),
                                done=sum(_done(c) for c, _ in cells), total=len(cells), failures=_failures(cells))


def _refined_tail(text: str) -> str:
    """The refinement tables of docs/stability.md (from REFINED_MARK on), kept when the tables above are made."""
    return "\n" + REFINED_MARK + text.split(REFINED_MARK, 1)[1] if REFINED_MARK in text else ""


def _rerun_truncated(pairs) -> int:
    """The truncated cells ``pairs`` (mu, sigma) traced again, their rows of docs/stability.md replaced (the
    others kept as they were), the counts made again from the rows."""
    unknown = [p for p in pairs if p not in TRUNCATED]
    if unknown:
        print(f"not a truncated cell: {unknown}; the cells are {TRUNCATED}", file=sys.stderr)
        return 2
    cells = {(c["mu"], c["sigma"]): c for c, _ in _run([(m, s, TRUNCATED_OPTIONS, "truncated") for m, s in pairs])}
    with open(OUT) as f:
        text = f.read()
    head, section = text.split(TRUNCATED_MARK, 1)
    section = section.split(REFINED_MARK)[0]
    old_rows, old_failures = {}, {}
    for line in section.splitlines():
        parts = [p.strip() for p in line.split("|")]
        if line.startswith("| ") and len(parts) > 3 and parts[2].endswith("truncated"):
            old_rows[(float(parts[1]), float(parts[2].split()[0]))] = line
        elif line.startswith("- mu = "):
            mu, sigma = line[len("- mu = "):].split(":")[0].replace("sigma = ", "").replace(" truncated", "").split(",")
            old_failures[(float(mu), float(sigma))] = line
        elif line.startswith("Cells not completed: - mu = "):
            rest = line[len("Cells not completed: "):]
            mu, sigma = rest[len("- mu = "):].split(":")[0].replace("sigma = ", "").replace(" truncated", "").split(",")
            old_failures[(float(mu), float(sigma))] = rest
    rows, failures = [], []
    for key in TRUNCATED:
        if key in cells:
            rows.append(_row(cells[key], "truncated"))
            if not _done(cells[key]):
                failures.append(_failures([(cells[key], "truncated")]))
        elif key in old_rows:
            rows.append(old_rows[key])
            if key in old_failures:
                failures.append(old_failures[key])
    done = sum(1 for r in rows if r.split("|")[3].strip() == "yes")
    unrun = [f"mu = {m:g}, sigma = {sg:g}" for m, sg in TRUNCATED if (m, sg) not in cells and (m, sg) not in old_rows]
    said = ("\n".join(failures) or "none") + \
        (f"\n\nCells without a row (in TRUNCATED, not traced yet): {'; '.join(unrun)}" if unrun else "")
    with open(OUT, "w") as f:
        f.write(head.rstrip("\n") + "\n\n" + TRUNCATED_DOC.format(head=HEAD, rows="\n".join(rows), done=done,
                                                                total=len(rows),
                                                                failures=said)
                + _refined_tail(text))
    print(f"{len(cells)} truncated cells traced again; {done} of {len(rows)} completed; docs/stability.md written")
    return 0


def _run(jobs) -> list:
    with ThreadPoolExecutor(2) as pool:
        return list(pool.map(lambda j: (cell(*j[:3]), j[3]), jobs))


def main(argv: list[str]) -> int:
    """All cells into docs/stability.md; ``truncated``: the truncated model's table alone rewritten; or the one
    cell given as mu sigma, printed."""
    truncated = [(m, s, TRUNCATED_OPTIONS, "truncated") for m, s in TRUNCATED]
    if argv[:1] == ["refinement"]:
        mu, lam_max = float(argv[1]), float(argv[2]) if len(argv) > 2 else math.inf
        print(refinement_table(refinement(mu, lam_max, int(argv[3]) if len(argv) > 3 else None)))
        return 0
    if argv == ["truncated-check"]:
        wrong = truncated_check()
        print("\n".join(wrong) or "mu = 10 truncated: as the half-infinite model, within TRUNCATION")
        return 1 if wrong else 0
    if argv == ["truncated"]:
        cells = _run(truncated)
        with open(OUT) as f:
            text = f.read()
        head = text.split(TRUNCATED_MARK)[0].rstrip("\n") + "\n\n"
        with open(OUT, "w") as f:
            f.write(head + _truncated_table(cells) + _refined_tail(text))
        print(f"{sum(_done(c) for c, _ in cells)} of {len(cells)} truncated cells completed; docs/stability.md written")
        return 0
    if argv[:1] == ["truncated"]:
        pairs = [(float(argv[i]), float(argv[i + 1])) for i in range(1, len(argv) - 1, 2)]
        return _rerun_truncated(pairs)
    if argv:
        c = cell(float(argv[0]), float(argv[1]))
        print(HEAD + "\n" + _row(c))
        return 0
    jobs = [(m, s, (), "") for m in MUS for s in SIGMAS] + [(m, s, e, w) for m, s, e, w in EXTRA]
    cells = _run(jobs + truncated)
    main_cells, trunc_cells = cells[:len(jobs)], cells[len(jobs):]
    rows = "\n".join(_row(c, w) for c, w in main_cells)
    done = sum(_done(c) for c, _ in main_cells)
    with open(OUT) as f:
        tail = _refined_tail(f.read())
    with open(OUT, "w") as f:
        f.write(STABILITY_DOC.format(head=HEAD, rows=rows, done=done, total=len(main_cells),
                                     failures=_failures(main_cells),
                                     machine=f"{os.cpu_count()} cores, two cells at a time, one rank each")
                + _truncated_table(trunc_cells) + tail)
    print(f"{done} of {len(main_cells)} cells and {sum(_done(c) for c, _ in trunc_cells)} of {len(trunc_cells)} "
          f"truncated cells completed; docs/stability.md written")
    return 0


STABILITY_DOC = """# Stability matrix

<!-- made by: ./run stability -->
Every cell traces the load-approach curve from far apart to F >= 2 with the program's
default settings (`petsc-adhesion -adh_mu MU -adh_sigma SIGMA -cont_error_estimate`),
as a new user would.  {done} of {total} cells completed.  Machine: {machine}.

- completed: exit status 0 and a complete result (no warning that makes it incomplete).
- turning points: snap-on and snap-off events (the secondary pairs included).
- pull-off: the most tensile load with its error bar (`-cont_error_estimate`).
- smallest step, rejected steps: the step control's work; guard: Newton steps shortened
  because they would have closed a gap (the domain guard); Newton, Krylov: the most
  iterations one point took; nodes: the largest grid; regrids: changes of grid.
- wall gap: the smallest H - wall over the curve, in epsilon: how close the curve came to
  the wall of the roughness law (the outermost node of the 16-point Hermite rule,
  6.63 sigma - 1; the curve never steps into it, and below 1e-3 it is warned about).
- From mu = 20 on a sphere is soft (docs/soft.md): steps in units of mu, the frame of the
  edge; a rough soft sphere's grids resolve the cohesive zone its state shows (the roughness
  holds the surfaces at its wall and the edge is Hertz-like, 10 to 100 times wider than a
  JKR edge's; docs/numerics.md).  The several turning points of the soft rows lie within
  about 3 epsilon of the snap-on, where the contact forms: the model's (docs/numerics.md).

{head}
{rows}

Cells not completed: {failures}

"""

TRUNCATED_DOC = """## The truncated model

<!-- made by: ./run stability truncated (python -m petsc_adhesion.benchmarks.stability truncated); rows
     traced again alone by: python -m petsc_adhesion.benchmarks.stability truncated MU SIGMA ... -->
The paper's own model, `-adh_rmax 10 -adh_farfield false` (the domain ends at r_m = 10, nothing
added beyond), with the defaults otherwise and `-cont_error_estimate`.  It is traced in the physical
frame throughout (a grid in r / a could not keep its end at r_m), on grids graded about the contact
edge and regridded as it moves; a sharp edge (mu > 3.3) gets COARSE_MARGIN = 4 times the nodes a
zone of NODES_PER_ZONE (tracing/edge_grids.py `margined`), so that the edge crossing the nodes
makes no spurious turning points.  Every step there moves the edge by about a tenth of its zone:
the steps grow about as mu^2, and mu = 10 is the most it is traced to (MU_TRUNCATED).

A domain of r_m = 10 is small for a soft sphere.  Where the contact's attraction reaches r_m
(|P(r_m)| above 1e-3 of the peak attraction, the gap there below about 13 epsilon) the truncated
model ends, and so does its curve: the run stops there, its events before it whole with their
bars, and says where it ended and what to do (a larger `-adh_rmax`, or `-cont_F_max` up to that
load) with exit 3, since the curve asked for (to F = 2) is not all there.  At mu = 10 that
happens before F = 2.  A `-cont_F_max` beyond the load at which even Hertz's contact (the
narrowest an adhesive contact has at a given load) reaches r_m, (2 / (3 pi)) r_m^3 mu^-1.5
(6.71 at mu = 10), is refused in one line before any work (tracing/edge_grids.py `domain_load`).
`python -m petsc_adhesion.benchmarks.stability truncated-check` traces mu = 10 to F = 0.5 and
checks its turning points against the half-infinite model's (within 5e-3) and its pull-off
against JKR's (within 1%); tests/test_truncated.py checks mu = 4 so in the suite.  Run on the
code of these rows: 3426 steps, exit 0, the turning points at lambda = -6.082940, -6.422455,
-6.310865, -16.199210 within 5e-3 of the half-infinite model's, the pull-off -0.754219 (0.56% from
JKR's -3/4): "as the half-infinite model, within TRUNCATION" (2011 s of wall time at a load of 15
to 30 on 2 cores).
{done} of {total} cells completed.

{head}
{rows}

Cells not completed: {failures}
"""

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
