"""The console report of a run: the curve's events with their bars, in the model's units and in SI."""
from __future__ import annotations

from ..errors import tell

__all__ = ["report_curve", "report_solve"]


def _pm(e: dict, key: str, digits: int = 8) -> str:
    """``key = value`` with its bar when it has one."""
    bar = e.get(f"{key}_err")
    return f"{key} = {e[key]:.{digits}f}" + ("" if bar is None or bar == 0 else f" +- {bar:.1e}")


def _note(e: dict) -> str:
    """Why an event has no bar, when it has none."""
    return "  (no error bar: not found again on the nested levels)" if e.get("error_note") else ""


def _energy(s: dict) -> str:
    """The energy of a cycle with its bar and the number of loops, or why there is none."""
    if s["energy"] is None:
        return f"none: {s.get('energy_note', 'no cycle')}"
    loops = f"{s['loops']} hysteresis loop{'s' * (s['loops'] != 1)}"
    return f"{_pm(s, 'energy', 8)}  ({loops})"


def report_curve(s: dict) -> None:
    """The console lines of a curve's summary (rank 0)."""
    out = []
    po = s["pull_off"]
    extra = f" + {s['error_estimate']['wall_time_s']:.3g} s for the error bars" if "error_estimate" in s else ""
    out.append(f"mu = {s['mu']:g}  sigma = {s['sigma']:g}  N = {s['n_nodes']}  steps {s['steps']} "
               f"(rejected {s['rejected_steps']})  {s['wall_time_s']:.3g} s{extra}; stopped: {s['stop_reason']}")
    if po:
        out.append(f"  pull-off (load control)  {_pm(po, 'lambda')}  {_pm(po, 'F')}{_note(po)}")
    for f in s["folds"]:
        land = f.get("landing")
        to = f"  -> lands at {_pm(land, 'F')}" if land else ""
        out.append(f"  {f['kind']:<23}  {_pm(f, 'lambda')}  {_pm(f, 'F')}{to}{_note(f)}")
    for e in s["equilibria"]:
        out.append(f"  equilibrium F = 0       {_pm(e, 'lambda')}{_note(e)}")
    for e in s["at_lambda"]:
        out.append(f"  at lambda               {_pm(e, 'lambda')}  {_pm(e, 'F')}{_note(e)}")
    out.append(f"  energy of a cycle       {_energy(s)}  (rigid machine)")
    sp = s.get("spring")
    if sp:
        for f in sp["jumps"]:
            land = f.get("landing")
            to = f"  -> lands at {_pm(land, 'lambda')}  {_pm(land, 'F')}" if land else ""
            out.append(f"  {f['kind']:<8} (K = {sp['K']:.4g})  {_pm(f, 'Z')}  {_pm(f, 'lambda')}  {_pm(f, 'F')}{to}"
                       f"{_note(f)}")
        out.append(f"  energy of a cycle       {_energy(sp)}  (spring K = {sp['K']:.4g})")
    if "physical" in s:
        out += _physical_lines(s["physical"])
    for w in s["warnings"]:
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
        if name and "energy_aJ" in q:
            out.append(f"    energy of a cycle, {name}: {_nm_nN(q, 'energy', 'aJ')}")
    return out


def report_solve(res: dict, physical: dict | None = None) -> None:
    """The console line of a fixed-approach solve (rank 0), and its physical values (``physical`` of the
    summary)."""
    line = (f"lambda = {res['lambda']:.10g}  F = {res['F']:.10g}  H0 = {res['H0']:.10g}  "
            f"Newton {res['snes_iterations']}  KSP {res['ksp_iterations']}  {res['wall_time_s']:.3g} s")
    if physical:
        line += (f"\n  in physical units (mu = {physical['mu']:.4g}): lambda = {physical['lambda_nm']:.5g} nm  "
                 f"F = {physical['F_nN']:.5g} nN  H0 = {physical['H0_nm']:.5g} nm")
    tell(line)
