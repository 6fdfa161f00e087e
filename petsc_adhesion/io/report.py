"""The console report of a run: the curve's events with their bars, in the model's units and in SI."""
from __future__ import annotations

from ..errors import tell
from ..tracing.curve import Curve, Cycle, Event, Solution
from ..tracing.measured import Measured, Missing
from ..tracing.turning_points import EventGroup, TurningPoints, rigid_turning_points, spring_turning_points
from .summary import summary_of, topography_record


def spread_lines(spread) -> list[str]:
    """The console lines of a model spread (:func:`~petsc_adhesion.tracing.model_spread.report_lines`,
    imported here: it traces curves, and a reader of files need not load PETSc)."""
    from ..tracing.model_spread import report_lines

    return report_lines(spread)

__all__ = ["report_curve", "report_solve", "topography_lines", "study_spread_line"]


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


def _fold(f: Event, name: str) -> str:
    """A turning point under displacement control, its landing and bar."""
    to = f"  -> lands at {_pm('F', f.landing.F)}" if f.landing else ""
    return f"  {name:<23}  {_pm('lambda', f.lam)}  {_pm('F', f.F)}{to}{_note(f)}"


def _jump(f: Event, K: float) -> str:
    """A jump behind the spring of stiffness K, its landing and bar."""
    assert f.Z is not None, "a jump behind the spring has its Z"
    land = f.landing
    to = f"  -> lands at {_pm('lambda', land.lam)}  {_pm('F', land.F)}" if land else ""
    return f"  {f.kind:<8} (K = {K:.4g})  {_pm('Z', f.Z)}  {_pm('lambda', f.lam)}  {_pm('F', f.F)}{to}{_note(f)}"


def _groups(tp: TurningPoints, kinds: str) -> list[str]:
    """One line a group of secondary turning points: how many, where, how wide against the hysteresis."""
    return [_group(g, tp, kinds) for g in tp.groups]


def _group(g: EventGroup, tp: TurningPoints, kinds: str) -> str:
    assert tp.scale is not None, "a curve with groups has its scales"
    pairs = f" ({g.count // 2} fold pair{'s' * (g.count // 2 != 1)})" if g.count % 2 == 0 else ""
    bars = "" if not g.without_bar else f"; {len(g.without_bar)} without an error bar (the files say why)"
    return (f"  {g.count} further {kinds}{pairs} within {g.width / 2:.2g} of {g.control} = {g.centre:.6g} "
            f"(width {g.width:.2g}, {g.width / tp.scale:.1%} of the hysteresis), F from {g.F_lo:.6g} to "
            f"{g.F_hi:.6g}: on the branch the jumps pass over{bars}")


def report_curve(curve: Curve) -> None:
    """The console lines of a curve (rank 0)."""
    out = []
    d, po = curve.diagnostics, curve.pull_off
    extra = f" + {d.error_estimate.wall_time_s:.3g} s for the error bars" if d.error_estimate is not None else ""
    out.append(f"mu = {curve.model.mu:g}  sigma = {curve.model.sigma:g}  N = {curve.grid.largest}  steps {d.steps} "
               f"(rejected {d.rejected_steps})  {d.wall_time_s:.3g} s{extra}; stopped: {d.stop_reason}")
    rigid = rigid_turning_points(curve)
    # what an instrument meets first (the primary jump-in, the pull-off, the primary jump-off), then the
    # turning points the jumps pass over, grouped where they lie close together (tracing/turning_points.py)
    for i, name in ((rigid.jump_in, "jump-in"), (None, "pull-off"), (rigid.jump_off, "jump-off")):
        if name == "pull-off" and po:
            out.append(f"  pull-off (load control)  {_pm('lambda', po.lam)}  {_pm('F', po.F)}{_note(po)}")
        elif i is not None:
            out.append(_fold(rigid.points[i], f"{rigid.points[i].kind} ({name})"))
    out += _groups(rigid, "turning points")
    out += [_fold(rigid.points[i], rigid.points[i].kind) for i in rigid.ungrouped]
    for e in curve.events_of("equilibrium"):
        out.append(f"  equilibrium F = 0       {_pm('lambda', e.lam)}{_note(e)}")
    for e in curve.events_of("lambda"):
        out.append(f"  at lambda               {_pm('lambda', e.lam)}  {_pm('F', e.F)}{_note(e)}")
    out.append(f"  energy of a cycle       {_energy(curve.rigid)}  (rigid machine)")
    sp, behind = curve.spring, spring_turning_points(curve)
    if sp is not None and behind is not None:
        primary = [i for i in (behind.jump_in, behind.jump_off) if i is not None]
        out += [_jump(behind.points[i], sp.K) for i in primary]
        out += _groups(behind, "turning points of Z")
        out += [_jump(behind.points[i], sp.K) for i in behind.ungrouped]
        out.append(f"  energy of a cycle       {_energy(sp.cycle)}  (spring K = {sp.K:.4g})")
    if curve.model.topography:
        out += topography_lines(curve.model)
    if curve.spread is not None:        # the model's spread, apart from the numerical bars above
        out += [f"  {line}" for line in spread_lines(curve.spread)]
    if curve.model.bodies is not None:
        out += _physical_lines(summary_of(curve)["physical"], rigid, behind)
    for w in curve.warnings:
        out.append(f"  WARNING: {w}")
    tell("\n".join(out))


def topography_lines(model) -> list[str]:
    """The console lines of a model's topographies: each file's size, pixels, detrending and moments with their
    sampling uncertainty; the gap's rms in epsilon; why the model is smooth where the gap is flat."""
    rec = topography_record(model)
    out = []
    for s in rec["surfaces"]:
        size = (" x ".join(f"{x * 1e6:.4g}" for x in s["size_m"]) + " um") if "size_m" in s else "size not stated"
        moments = ""
        if "skewness" in s:
            moments = (f", skewness {s['skewness']:.3g} +- {s['skewness_err']:.2g}, kurtosis {s['kurtosis']:.3g} +- "
                       f"{s['kurtosis_err']:.2g} (about {s['independent_samples'][0]:.0f} independent samples)")
        out.append(f"  topography {s['file']}: a {s['kind']} of {' x '.join(map(str, s['pixels']))} pixels, {size}, "
                   f"detrend {s['detrend']}: rms {s['rms_m'] * 1e9:.4g} +- {s['rms_err_m'] * 1e9:.2g} nm{moments}")
        if "note" in s:
            out.append(f"    note: {s['note']}")
    out.append(f"  the gap ({rec['gap']}): rms {rec['gap_rms_epsilon']:.4g} +- {rec['gap_rms_err_epsilon']:.2g} "
               "epsilon" + (f"; {rec['smooth']}" if "smooth" in rec else ""))
    return out


def _nm_nN(e: dict, key: str, unit: str) -> str:
    k = f"{key}_{unit}"
    bar = e.get(f"{key}_err_{unit}")
    return f"{key} = {e[k]:.5g} {unit}" + (f" +- {bar:.1g}" if bar else "")


def _physical_lines(p: dict, rigid: TurningPoints, behind: TurningPoints | None) -> list[str]:
    """The events again in nm and nN, under the inputs that made mu (and sigma): the primary ones first, the
    groups of secondary turning points as their spans, as above."""
    sigma = f", sigma = {p['sigma']:.4g}" if "sigma" in p else ""
    radius = f"{p['R_m'] * 1e6:.4g} um" if p["R_m"] >= 1e-6 else f"{p['R_m'] * 1e9:.4g} nm"
    out = [f"  in physical units: R = {radius}, E = {p['E_Pa'] / 1e9:.4g} GPa, gamma = "
           f"{p['gamma_J_m2'] * 1e3:.4g} mJ/m^2, epsilon = {p['epsilon_m'] * 1e9:.4g} nm: mu = {p['mu']:.4g}{sigma}"]
    folds, jumps = p["folds"], p.get("spring", {}).get("jumps", [])
    events = [(f"{folds[i]['kind']} ({name})", folds[i]) for i, name in ((rigid.jump_in, "jump-in"),
                                                                        (rigid.jump_off, "jump-off")) if i is not None]
    if p["pull_off"]:
        events.insert(1 if rigid.jump_in is not None else 0, ("pull-off", p["pull_off"]))
    groups = [_group_nm(g, "lambda") for g in p["fold_groups"]]
    rest = [(folds[i]["kind"], folds[i]) for i in rigid.ungrouped] + \
        [(e["kind"], e) for k in ("equilibria", "at_lambda") for e in p[k]]
    if behind is not None:
        rest += [(jumps[i]["kind"], jumps[i]) for i in (behind.jump_in, behind.jump_off) if i is not None]
        rest += [(jumps[i]["kind"], jumps[i]) for i in behind.ungrouped]
    def line(name: str, e: dict) -> str:
        force = f"  {_nm_nN(e, 'F', 'nN')}" if "F_nN" in e and name != "equilibrium" else ""
        base = f"  {_nm_nN(e, 'Z', 'nm')}" if "Z_nm" in e else ""
        return f"    {name:<21}{base}  {_nm_nN(e, 'lambda', 'nm')}{force}  contact radius {e['contact_radius_nm']:.4g} nm"

    out += [line(n, e) for n, e in events] + groups + [line(n, e) for n, e in rest]
    out += [_group_nm(g, "Z") for g in p.get("spring", {}).get("jump_groups", [])]
    for name, q in (("rigid machine", p), (f"spring k = {p['spring']['k_N_m']:.4g} N/m", p.get("spring")) if "spring" in p
                    else (None, None)):
        if name and q is not None and "energy_aJ" in q:
            out.append(f"    energy of a cycle, {name}: {_nm_nN(q, 'energy', 'aJ')}")
    return out


def _group_nm(g: dict, control: str) -> str:
    """A group of secondary turning points in nm and nN."""
    return (f"    further turning points   within {g['width_nm'] / 2:.2g} nm of {control} = {g[f'{control}_nm']:.5g} nm, "
            f"F from {g['F_lo_nN']:.5g} to {g['F_hi_nN']:.5g} nN")


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
    if s.model.topography:
        line += "\n" + "\n".join(topography_lines(s.model))
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
