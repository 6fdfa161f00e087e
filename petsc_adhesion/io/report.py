"""The console report of a run: the curve's events with their bars, in the model's units and in SI."""
from __future__ import annotations

from ..errors import tell
from ..tracing.curve import Curve, Cycle, Event, Solution
from ..tracing.measured import Measured, Missing
from .summary import summary_of


def spread_lines(spread) -> list[str]:
    """The console lines of a model spread (:func:`~petsc_adhesion.tracing.model_spread.report_lines`,
    imported here: it traces curves, and a reader of files need not load PETSc)."""
    from ..tracing.model_spread import report_lines

    return report_lines(spread)

__all__ = ["report_curve", "report_solve", "study_spread_line"]


def _pm(name: str, m: Measured, digits: int = 8) -> str:
    """``name = value`` with its bar when it has one."""
    return f"{name} = {m.value:.{digits}f}" + ("" if m.err is None or m.err == 0 else f" +- {m.err:.1e}")


def _note(e: Event) -> str:
    """Why an event has no bar, when it has none."""
    return "  (no error bar: not found again on the nested levels)" if e.note else ""


def _energy(c: Cycle) -> str:
    """The energy of a cycle with its bar and the number of loops, or why there is none."""
    if isinstance(c.energy, Missing):
        return f"none: {c.energy.reason}"
    loops = f"{c.loops} hysteresis loop{'s' * (c.loops != 1)}"
    return f"{_pm('energy', c.energy, 8)}  ({loops})"


def report_curve(curve: Curve) -> None:
    """The console lines of a curve (rank 0)."""
    out = []
    d, po = curve.diagnostics, curve.pull_off
    extra = f" + {d.error_estimate.wall_time_s:.3g} s for the error bars" if d.error_estimate is not None else ""
    out.append(f"mu = {curve.model.mu:g}  sigma = {curve.model.sigma:g}  N = {curve.grid.largest}  steps {d.steps} "
               f"(rejected {d.rejected_steps})  {d.wall_time_s:.3g} s{extra}; stopped: {d.stop_reason}")
    if po:
        out.append(f"  pull-off (load control)  {_pm('lambda', po.lam)}  {_pm('F', po.F)}{_note(po)}")
    for f in curve.events:
        if f.kind not in ("snap_on", "snap_off"):
            continue
        to = f"  -> lands at {_pm('F', f.landing.F)}" if f.landing else ""
        out.append(f"  {f.kind:<23}  {_pm('lambda', f.lam)}  {_pm('F', f.F)}{to}{_note(f)}")
    for e in curve.events_of("equilibrium"):
        out.append(f"  equilibrium F = 0       {_pm('lambda', e.lam)}{_note(e)}")
    for e in curve.events_of("lambda"):
        out.append(f"  at lambda               {_pm('lambda', e.lam)}  {_pm('F', e.F)}{_note(e)}")
    out.append(f"  energy of a cycle       {_energy(curve.rigid)}  (rigid machine)")
    sp = curve.spring
    if sp is not None:
        for f in sp.jumps:
            assert f.Z is not None, "a jump behind the spring has its Z"
            land = f.landing
            to = f"  -> lands at {_pm('lambda', land.lam)}  {_pm('F', land.F)}" if land else ""
            out.append(f"  {f.kind:<8} (K = {sp.K:.4g})  {_pm('Z', f.Z)}  {_pm('lambda', f.lam)}  {_pm('F', f.F)}{to}"
                       f"{_note(f)}")
        out.append(f"  energy of a cycle       {_energy(sp.cycle)}  (spring K = {sp.K:.4g})")
    if curve.spread is not None:        # the model's spread, apart from the numerical bars above
        out += [f"  {line}" for line in spread_lines(curve.spread)]
    if curve.model.bodies is not None:
        out += _physical_lines(summary_of(curve)["physical"])
    for w in curve.warnings:
        out.append(f"  WARNING: {w}")
    tell("\n".join(out))


def _nm_nN(e: dict, key: str, unit: str) -> str:
    k = f"{key}_{unit}"
    bar = e.get(f"{key}_err_{unit}")
    return f"{key} = {e[k]:.5g} {unit}" + (f" +- {bar:.1g}" if bar else "")


def _physical_lines(p: dict) -> list[str]:
    """The events again in nm and nN, under the inputs that made mu (and sigma)."""
    sigma = f", sigma = {p['sigma']:.4g}" if "sigma" in p else ""
    radius = f"{p['R_m'] * 1e6:.4g} um" if p["R_m"] >= 1e-6 else f"{p['R_m'] * 1e9:.4g} nm"
    out = [f"  in physical units: R = {radius}, E = {p['E_Pa'] / 1e9:.4g} GPa, gamma = "
           f"{p['gamma_J_m2'] * 1e3:.4g} mJ/m^2, epsilon = {p['epsilon_m'] * 1e9:.4g} nm: mu = {p['mu']:.4g}{sigma}"]
    events = ([("pull-off", p["pull_off"])] if p["pull_off"] else []) + \
        [(e["kind"], e) for k in ("folds", "equilibria", "at_lambda") for e in p[k]] + \
        [(e["kind"], e) for e in p.get("spring", {}).get("jumps", [])]
    for name, e in events:
        force = f"  {_nm_nN(e, 'F', 'nN')}" if "F_nN" in e and name != "equilibrium" else ""
        base = f"  {_nm_nN(e, 'Z', 'nm')}" if "Z_nm" in e else ""
        out.append(f"    {name:<21}{base}  {_nm_nN(e, 'lambda', 'nm')}{force}  contact radius "
                   f"{e['contact_radius_nm']:.4g} nm")
    for name, q in (("rigid machine", p), (f"spring k = {p['spring']['k_N_m']:.4g} N/m", p.get("spring")) if "spring" in p
                    else (None, None)):
        if name and q is not None and "energy_aJ" in q:
            out.append(f"    energy of a cycle, {name}: {_nm_nN(q, 'energy', 'aJ')}")
    return out


def report_solve(s: Solution) -> None:
    """The console line of a fixed-approach solve (rank 0), and its physical values."""
    line = (f"lambda = {s.lam:.10g}  F = {s.F:.10g}  H0 = {s.H0:.10g}  "
            f"Newton {s.snes_iterations}  KSP {s.ksp_iterations}  {s.wall_time_s:.3g} s")
    if s.model.bodies is not None:
        d = s.model.bodies.describe()
        physical = {"mu": d["mu"], "lambda_nm": s.lam * d["approach_nm"], "F_nN": s.F * d["force_nN"],
                    "H0_nm": s.H0 * d["approach_nm"]}
        line += (f"\n  in physical units (mu = {physical['mu']:.4g}): lambda = {physical['lambda_nm']:.5g} nm  "
                 f"F = {physical['F_nN']:.5g} nN  H0 = {physical['H0_nm']:.5g} nm")
    tell(line)


def study_spread_line(done: list) -> str | None:
    """The one line a study says of its cases' model spreads (``done``: its cases that ran, each a
    :class:`~petsc_adhesion.tracing.case.CaseResult`): how many of those with a spread warn (the roughness
    law moves an event beyond ten error bars or 10 % of its value), and where to read them; None when no case
    has one.  One line for the study, not one a case: each case's warnings are in its files."""
    spreads = [r for r in done if isinstance(r.result, Curve) and r.result.spread is not None
               and not isinstance(r.result.spread, Missing)]
    if not spreads:
        return None
    warned = [r for r in spreads if r.result.spread.warnings]
    cases = ", ".join(str(r.case + 1) for r in warned)
    return (f"model spread: {len(warned)} of the {len(spreads)} rough case{'s' * (len(spreads) != 1)} warn"
            + ("" if not warned else f" (case{'s' * (len(warned) != 1)} {cases}): the roughness law moves an event "
               "beyond ten error bars or 10% of its value; each case's model_spread in the files says which and "
               "by how much"))
