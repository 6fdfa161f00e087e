"""docs/model.md, section "The model spread, measured": what the spread costs, and the silica probe's pull-off
under each roughness law.

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.model_spread           # mu = 1, 10, 100
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.model_spread -quick    # mu = 1, 10

(1) The cost: for each mu and sigma = 0.5, 1.67 (the Hermite rule of 16 points, grids that follow the edge,
one rank) the default curve with its error bars (:func:`~petsc_adhesion.tracing.trace.trace_curve`) and its
spread over the default laws (:func:`~petsc_adhesion.tracing.model_spread.model_spread`: four curves, events
only) are timed, with the largest relative spread of the pull-off and whether it warns.  (2) The probe: a
5 um silica sphere on a silicon wafer (E, nu of docs/materials.md), w = 0.05 J/m^2, epsilon = 0.3 nm, rms
0.5 nm (mu = 0.577, sigma = 1.67): its pull-off in nN under the 16-point rule with its bar, and under each
law of the spread.  It writes the section into docs/model.md of the checkout it runs in (:mod:`.paths`).
"""
from __future__ import annotations

import os
import platform
import sys
import time

from ..model.parameters import Model
from ..model.physical import Bodies
from ..tracing.model_spread import model_spread
from ..tracing.trace import trace_curve
from . import paths

__all__ = ["MUS", "QUICK", "SIGMAS", "PROBE", "COMMAND", "HEADING", "cost", "probe", "markdown", "main"]

#: The Tabor parameters of the cost, and of -quick.
MUS = (1.0, 10.0, 100.0)
QUICK = (1.0, 10.0)
#: The roughness of the cost's curves (the Hermite rule of 16 points).
SIGMAS = (0.5, 5.0 / 3.0)
#: The silica probe of the table.
PROBE = Bodies(radius=5e-6, young1=73e9, poisson1=0.17, young2=130e9, poisson2=0.28, gamma=0.05, epsilon=3e-10,
               rms=5e-10)
#: The command that writes the section, as the page names it.
COMMAND = "python -m petsc_adhesion.benchmarks.model_spread"
HEADING = "## The model spread, measured"


def cost(mu: float, sigma: float) -> dict:
    """The curve's time (with error bars) and its spread's (four laws, events only), and the pull-off's
    largest relative spread."""
    model = Model(mu=mu, sigma=sigma)
    t0, c0 = time.perf_counter(), time.process_time()
    curve = trace_curve(model)
    t1, c1 = time.perf_counter(), time.process_time()
    spread = model_spread(curve, model)
    t2, c2 = time.perf_counter(), time.process_time()
    q = spread.quantity("pull-off F")
    return {"mu": mu, "sigma": sigma, "curve_s": t1 - t0, "spread_s": t2 - t1, "curve_cpu_s": c1 - c0,
            "spread_cpu_s": c2 - c1, "relative": q.relative, "warns": bool(spread.warnings),
            "notes": len(spread.notes), "rules": {r.label: t for r, t in zip(spread.rules, spread.rule_times_s)}}


def probe() -> tuple:
    """The probe's spread and reference curve."""
    model = Model(mu=PROBE.mu, sigma=PROBE.sigma, bodies=PROBE)
    curve = trace_curve(model)
    return model, curve, model_spread(curve, model)


def markdown(rows: list, probed: tuple) -> str:
    """The section: the probe's table, then the cost's."""
    model, curve, spread = probed
    q, lam = spread.quantity("pull-off F"), spread.quantity("pull-off lambda")
    nN, nm = spread.force_nN, spread.approach_nm
    out = [HEADING, "",
           f"Made by `{COMMAND}` ({platform.node() or 'this machine'}, one rank, the load average "
           f"{os.getloadavg()[0]:.1f} at the start: the cores may be shared).", "",
           f"**The silica probe**: a 5 um silica sphere on a silicon wafer, w = {PROBE.gamma:g} J/m^2, "
           f"epsilon = 0.3 nm, rms 0.5 nm: mu = {model.mu:.4g}, sigma = {model.sigma:.4g}.  Its pull-off "
           "under each law (the 16-point rule's with its error bar; the others events only):", "",
           "| law | pull-off F (nN) | its lambda (nm) |", "|---|---|---|",
           f"| {spread.reference.label} (the default) | {q.reference.value * nN:.4g} +- "
           f"{(q.reference.err or 0) * nN:.1g} | {lam.reference.value * nm:.4g} |"]
    for r, v, w in zip(spread.rules, q.values, lam.values):
        out.append(f"| {r.label} | {v.value * nN:.4g} | {w.value * nm:.4g} |" if hasattr(v, "value") else
                   f"| {r.label} | none: {v.reason} | |")
    out += ["", f"Spread of the pull-off: {q.spread * nN:.4g} nN, {q.relative:.3g} times the value"
            + ("; the warning fires." if q.warning else "."), "",
            "**The cost** of the spread (four curves, events only) against the curve's own (with its error bars), "
            "the Hermite rule of 16 points, grids that follow the edge:", "",
            "| mu | sigma | curve: wall, CPU (s) | spread: wall, CPU (s) | spread / curve (CPU) | "
            "each law's share of the spread's wall time | pull-off: relative spread | warns |",
            "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        share = ", ".join(f"{k} {100 * t / r['spread_s']:.0f}%" for k, t in r["rules"].items())
        out.append(f"| {r['mu']:g} | {r['sigma']:.3g} | {r['curve_s']:.1f}, {r['curve_cpu_s']:.1f} | "
                   f"{r['spread_s']:.1f}, {r['spread_cpu_s']:.1f} | {r['spread_cpu_s'] / r['curve_cpu_s']:.2f} | "
                   f"{share} | {r['relative']:.3g} | {'yes' if r['warns'] else 'no'} |")
    return "\n".join(out) + "\n"


def main(argv: list | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    mus = QUICK if "-quick" in argv else MUS
    rows = []
    for mu in mus:
        for sigma in SIGMAS:
            rows.append(cost(mu, sigma))
            print(rows[-1], flush=True)
    text = markdown(rows, probe())
    print(text)
    paths.write_section(os.path.join(paths.DOCS, "model.md"), text, HEADING)


if __name__ == "__main__":
    import petsc4py

    petsc4py.init([sys.argv[0]])
    main()
