"""The library's result values as the files' keys: a curve's JSON summary, its events and branch as the HDF5
records, a solve's summary (docs/output.md).

The one place where the objects of :mod:`petsc_adhesion.tracing.curve` become keys.
An event (or a landing) is read field by field (:func:`event_record`): a
:class:`~petsc_adhesion.tracing.measured.Measured` ``x`` becomes ``x``, ``x_err``
and ``x_grid`` (the last two absent where the value has no bar or no other grid
value), a nested value a nested record, a profile the arrays r, H and P, and a
field that is None (or an empty tuple) is absent.  So a new field of an event
reaches the JSON and HDF5 files with no change here; the CSV names its columns
(:data:`~petsc_adhesion.io.text.EVENT_COLUMNS`).
"""
from __future__ import annotations

from dataclasses import fields, is_dataclass
from typing import TYPE_CHECKING, cast

import numpy as np

from ..model.physical import in_units
from ..model.pressure import pressure_law
from ..model.roughness import SMALLEST_RMS
from ..tracing.curve import Curve, Cycle, Profile, Program, Solution
from ..tracing.measured import Measured, Missing
from ..tracing.turning_points import TurningPoints, rigid_turning_points, spring_turning_points

if TYPE_CHECKING:                    # tracing.critical loads PETSc, which a file reader need not
    from ..tracing.critical import Critical
    from ..tracing.model_spread import ModelSpread

__all__ = ["event_record", "branch_record", "program_record", "model_record", "head_of", "summary_of",
           "solve_summary", "cycle_summary", "critical_record", "spread_record", "legs_record", "LEG_KEYS",
           "primary_record", "groups_record", "topography_record", "KEYS"]

#: A field's name -> the key the files have always used for it.
KEYS = {"lam": "lambda", "note": "error_note"}


def event_record(obj, profiles: bool = True) -> dict:
    """An :class:`~petsc_adhesion.tracing.curve.Event` (or its landing) as the files hold it, read from its
    fields (see the module); ``profiles`` False leaves out r, H and P (a summary's, a study case's)."""
    out: dict[str, object] = {}
    for f in fields(obj):
        v, key = getattr(obj, f.name), KEYS.get(f.name, f.name)
        if v is None or (isinstance(v, tuple) and not v):
            continue
        if isinstance(v, Measured):
            out[key] = v.value
            if v.err is not None:
                out[f"{key}_err"] = v.err
            if v.grid is not None:
                out[f"{key}_grid"] = v.grid
        elif isinstance(v, Profile):
            if profiles:
                out |= {"r": v.r, "H": v.H, "P": v.P}
        elif is_dataclass(v):
            out[key] = event_record(v, profiles)
        else:
            out[key] = list(v) if isinstance(v, tuple) else v
    return out


#: The branch's fields -> the HDF5 datasets of the group ``curve``.
_BRANCH = {"lam": "lambda"}


def branch_record(curve: Curve) -> dict:
    """The points of a curve as the HDF5 group ``curve`` holds them (Z and stable_spring behind a spring)."""
    b = curve.branch
    return {_BRANCH.get(f.name, f.name): getattr(b, f.name) for f in fields(b) if getattr(b, f.name) is not None}


#: A leg's arrays as the HDF5 group ``instrument/approach`` (``retract``) holds them, in the CSV's order.
LEG_KEYS = ("Z", "separation", "deflection", "F", "lambda", "contact_radius")


def legs_record(legs) -> dict:
    """The instrument's legs (:class:`~petsc_adhesion.tracing.legs.InstrumentCurve`) as the HDF5 group
    ``instrument`` holds them: K, the trigger (absent without one) and whether the approach reached it, the
    notes, and a group per leg with its arrays and the indices of its jumps; a Missing: its reason alone."""
    if isinstance(legs, Missing):
        return {"missing": legs.reason}
    out: dict[str, object] = {"K": legs.K, "reached": legs.reached}
    if legs.trigger is not None:
        out["trigger"] = legs.trigger
    if legs.notes:
        out["notes"] = list(legs.notes)
    for leg in legs.legs:
        out[leg.name] = {"Z": leg.Z, "separation": leg.separation, "deflection": leg.deflection, "F": leg.F,
                         "lambda": leg.lam, "contact_radius": leg.contact_radius,
                         "jumps": np.asarray(leg.jumps, dtype=np.int64)}
    return out


def program_record(p: Program) -> dict:
    """What a result says about the :class:`~petsc_adhesion.tracing.curve.Program` that made it: versions
    and ranks."""
    return {k.name: getattr(p, k.name) for k in fields(p)}


def model_record(model) -> dict:
    """The model a result was computed for: mu, sigma, r_m, the roughness average and the domain."""
    return {"mu": model.mu, "sigma": model.sigma, "rmax": model.rmax, **pressure_law(model).describe(),
            "domain": "half-infinite (the rigid sphere's attraction beyond r_m added)" if model.farfield
            else "truncated at r_m (the paper's model)"}


def _moment(name: str, m, unit: str = "") -> dict:
    """A sample moment and its uncertainty as keys (the uncertainty absent where there is none)."""
    return {f"{name}{unit}": m.value, **({f"{name}_err{unit}": m.err} if m.err is not None else {})}


def topography_record(model) -> dict:
    """The topographies a measured model's heights came from (docs/topography.md): per surface its file,
    kind, pixels, size, unit, detrending and moments with their sampling uncertainty; the gap's rms in
    epsilon; where the gap is flat, why the model is the smooth sphere.  {} without a topography."""
    if not model.topography:
        return {}
    surfaces = []
    for t in model.topography:
        st = t.stats
        r = {"file": t.path, "kind": t.kind, "pixels": list(t.pixels), "unit": t.unit, "unit_source": t.unit_source,
             "detrend": t.detrend, **_moment("rms", st.rms, "_m"), "highest_m": st.highest, "lowest_m": st.lowest}
        if st.rms.value > 0:
            r |= {**_moment("skewness", st.skewness), **_moment("kurtosis", st.kurtosis),
                  "correlation_length_pixels": list(st.correlation_length),
                  "independent_samples": list(st.independent)}
        if t.size is not None:
            r |= {"size_m": list(t.size), "pixel_size_m": list(t.pixel_size)}
        else:
            r["size_note"] = "the file states no lateral size: the correlation length in pixels only"
        if st.note:
            r["note"] = st.note
        surfaces.append(r)
    eps = model.bodies.scales()["approach_m"]
    rms = float(np.sqrt(sum(t.stats.rms.value ** 2 for t in model.topography)))
    err = float(np.sqrt(sum((t.stats.rms.value * t.stats.rms.err) ** 2 for t in model.topography))) / rms \
        if rms > 0 else 0.0
    out = {"surfaces": surfaces, "gap_rms_m": rms, "gap_rms_err_m": err, "gap_rms_epsilon": rms / eps,
           "gap_rms_err_epsilon": err / eps,
           "gap": "one surface's heights" if len(surfaces) == 1 else
           "the sum of the two surfaces' heights: their distributions convolved"}
    if model.roughness == "none":
        out["smooth"] = (f"the gap's rms {rms / eps:.3g} epsilon is below {SMALLEST_RMS:g}: the model is the smooth "
                         "sphere")
    return out


def _grid(result) -> dict:
    g = result.grid
    out = {"r": g.r}
    if g.lam is not None:
        out |= {"lambda": g.lam, "n_nodes": g.n_nodes, **({"edge": g.edge} if g.edge is not None else {})}
    return out


def head_of(result) -> dict:
    """The program, model, grid and physical inputs of a curve or a solution, as the files hold them."""
    head = {**program_record(result.program), "model": model_record(result.model), "grid": _grid(result)}
    if result.model.bodies is not None:
        head["physical"] = result.model.bodies.describe()
    if result.model.topography:
        head["topography"] = topography_record(result.model)
    return head


def _plain(x):
    """Python numbers, lists and dicts of x (as its JSON file holds it)."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return x


def _common(result) -> dict:
    """The keys every summary has: versions, the model and the grid size (the largest grid's)."""
    return {**program_record(result.program), **model_record(result.model), "n_nodes": result.grid.largest}


def cycle_summary(c: Cycle) -> dict:
    """A cycle's keys: its energy with its bar and loops, or (Missing) null ones and the reason."""
    if isinstance(c.energy, Missing):
        return {"energy": None, "energy_err": None, "loops": None, "energy_note": c.energy.reason}
    return {"energy": c.energy.value, "energy_err": c.energy.err, "loops": c.loops,
            **({"energy_note": c.energy.note} if c.energy.note else {})}


def spread_record(spread: ModelSpread | Missing) -> dict:
    """A model spread (:class:`~petsc_adhesion.tracing.model_spread.ModelSpread`) as the files hold it: the
    reference's law, the other ``rules``, one record per quantity (its ``name``, ``unit``, the reference's
    ``value`` and ``err``, ``values`` under each rule in their order, null where that law's curve has not
    the event, with ``missing`` saying why, ``spread``, ``relative`` and ``warning``, each absent where
    there is none), the ``notes``, ``warnings``, wall times and the units in nN and nm; a Missing spread
    its ``reason``."""
    if isinstance(spread, Missing):
        return {"reason": spread.reason}
    quantities = []
    for q in spread.quantities:
        r = {"name": q.name, "unit": q.unit, "value": q.reference.value,
             "values": [v.value if isinstance(v, Measured) else None for v in q.values]}
        if q.reference.err is not None:
            r["err"] = q.reference.err
        if any(isinstance(v, Missing) for v in q.values):
            r["missing"] = [v.reason if isinstance(v, Missing) else "" for v in q.values]
        if q.spread is not None:
            r["spread"] = q.spread
        if q.relative is not None and np.isfinite(q.relative):     # infinite at a reference of 0: absent
            r["relative"] = q.relative
        if q.warning:
            r["warning"] = q.warning
        quantities.append(r)
    out = {"reference": spread.reference.label, "rules": [r.label for r in spread.rules],
           "quantities": quantities, "notes": list(spread.notes), "warnings": spread.warnings,
           "wall_time_s": spread.wall_time_s, "rule_times_s": list(spread.rule_times_s)}
    if spread.force_nN is not None:
        out |= {"force_nN": spread.force_nN, "approach_nm": spread.approach_nm}
    return out


def _trigger(legs) -> dict:
    """The trigger of the instrument's legs and whether the approach reached it (nothing without one)."""
    if legs is None or isinstance(legs, Missing) or legs.trigger is None:
        return {}
    return {"trigger": legs.trigger, "trigger_reached": legs.reached}


def primary_record(tp: TurningPoints, pull_off=None) -> dict:
    """The primary jump-in, (a rigid machine's: the load-control pull-off,) and jump-off of ``tp``
    (:class:`~petsc_adhesion.tracing.turning_points.TurningPoints`), each its event's record with its
    ``index`` among the turning points (``folds``, or a spring's ``jumps``), null where the curve has none."""
    def one(i):
        return None if i is None else {"index": i, **event_record(tp.points[i], profiles=False)}

    out: dict[str, object] = {"jump_in": one(tp.jump_in)}
    if tp.control == "lambda":
        out["pull_off"] = event_record(pull_off, profiles=False) if pull_off is not None else None
    out["jump_off"] = one(tp.jump_off)
    return out


def groups_record(tp: TurningPoints) -> list[dict]:
    """The groups of secondary turning points of ``tp``: each its ``count``, its ``members`` and those
    ``without_bar`` (indices among the turning points, whose records hold their bars or why not), the
    control's span (``lambda_lo``, ``lambda_hi``, the middle ``lambda`` and the ``width``; ``Z_...`` behind
    a spring), the load's (``F_lo``, ``F_hi``) and the ``share`` of the curve's scales it spans."""
    c = tp.control
    return [{"count": g.count, "members": list(g.members), "without_bar": list(g.without_bar),
             f"{c}_lo": g.lo, f"{c}_hi": g.hi, c: g.centre, "width": g.width, "F_lo": g.F_lo, "F_hi": g.F_hi,
             "share": g.share} for g in tp.groups]


def _physical_groups(groups: list[dict], control: str, d: dict) -> list[dict]:
    """Group records in nm and nN."""
    nm, nN = d["approach_nm"], d["force_nN"]
    return [{f"{control}_lo_nm": g[f"{control}_lo"] * nm, f"{control}_hi_nm": g[f"{control}_hi"] * nm,
             f"{control}_nm": g[control] * nm, "width_nm": g["width"] * nm, "F_lo_nN": g["F_lo"] * nN,
             "F_hi_nN": g["F_hi"] * nN} for g in groups]


def summary_of(curve: Curve) -> dict:
    """The JSON summary of a traced curve (docs/output.md)."""
    def brief(e):
        return event_record(e, profiles=False)

    ev, d, a = curve.events, curve.diagnostics, curve.assessment
    spread = cast("ModelSpread | Missing | None", curve.spread)
    spread_warnings = spread.warnings if spread is not None and not isinstance(spread, Missing) else []
    rigid, behind = rigid_turning_points(curve), spring_turning_points(curve)
    s = {**_common(curve),
         # first what an instrument meets; then every event, with its bar or why it has none
         "primary": primary_record(rigid, curve.pull_off),
         "fold_groups": groups_record(rigid),
         "pull_off": brief(curve.pull_off) if curve.pull_off else None,
         "folds": [brief(e) for e in ev if e.kind in ("snap_on", "snap_off")],
         "equilibria": [{k: v for k, v in brief(e).items() if k not in ("F", "F_err", "F_grid")}
                        for e in ev if e.kind == "equilibrium"],
         "load_extrema": [brief(e) for e in ev if e.kind in ("F_min", "F_max")],
         "at_lambda": [brief(e) for e in ev if e.kind == "lambda"],
         **cycle_summary(curve.rigid),
         **({"spring": {"K": curve.spring.K, "primary": primary_record(behind),
                        "jump_groups": groups_record(behind), "jumps": [brief(e) for e in curve.spring.jumps],
                        **cycle_summary(curve.spring.cycle), **_trigger(curve.spring.legs)}}
            if curve.spring is not None and behind else {}),
         "wall_gap": d.wall_gap, "steps": d.steps, "rejected_steps": d.rejected_steps, "regrids": d.regrids,
         "guard_activations": d.guard_activations, "smallest_step": d.smallest_step,
         "most_newton_its": d.most_newton_its, "most_ksp_its": d.most_ksp_its, "stop_reason": d.stop_reason,
         "grid_warning": a.grid_warning or "", "complete": a.complete,
         # the spread's warnings among the run's, though they leave it complete (docs/model.md)
         "warnings": list(a.warnings) + spread_warnings,
         "lambda_start": d.lambda_start, "wall_time_s": d.wall_time_s}
    if d.error_estimate is not None:
        est = d.error_estimate
        s["error_estimate"] = {"wall_time_s": est.wall_time_s, "target_error": est.target_error,
                               "levels": list(est.levels)}
    if curve.model.bodies is not None:
        units = curve.model.bodies.describe()
        phys = s["physical"] = in_units(s, units)
        # the primary events as the physical lists hold them, by their index; the groups' spans in nm and nN
        phys["primary"] = {k: None if v is None else {"index": v["index"], **phys["folds"][v["index"]]}
                           if k != "pull_off" else phys["pull_off"] for k, v in s["primary"].items()}
        phys["fold_groups"] = _physical_groups(s["fold_groups"], "lambda", units)
        if "spring" in s:
            phys["spring"]["primary"] = {k: None if v is None else {"index": v["index"],
                                                                     **phys["spring"]["jumps"][v["index"]]}
                                         for k, v in s["spring"]["primary"].items()}
            phys["spring"]["jump_groups"] = _physical_groups(s["spring"]["jump_groups"], "Z", units)
            if "trigger" in s["spring"]:         # the load the approach was to end at, as the instrument sets it
                phys["spring"]["trigger_nN"] = s["spring"]["trigger"] * units["force_nN"]
    if spread is not None:               # after physical: in_units reads the events, not the spread
        s["model_spread"] = spread_record(spread)
    if curve.model.topography:
        s["topography"] = topography_record(curve.model)
    return _plain(s)


def solve_record(solution: Solution) -> dict:
    """The scalars of a solve: its state and the solver's effort."""
    return {"lambda": solution.lam, "F": solution.F, "F_beyond": solution.F_beyond, "H0": solution.H0,
            "snes_iterations": solution.snes_iterations, "ksp_iterations": solution.ksp_iterations,
            "wall_time_s": solution.wall_time_s}


def solve_summary(solution: Solution) -> dict:
    """The JSON summary of a fixed-approach solve."""
    res = solve_record(solution)
    summ = {**_common(solution), **res}
    if solution.model.bodies is not None:
        d = solution.model.bodies.describe()
        summ["physical"] = {**d, "lambda_nm": res["lambda"] * d["approach_nm"], "F_nN": res["F"] * d["force_nN"],
                            "H0_nm": res["H0"] * d["approach_nm"]}
    if solution.model.topography:
        summ["topography"] = topography_record(solution.model)
    return _plain(summ)


def critical_record(c: Critical) -> dict:
    """A critical study's case (:class:`~petsc_adhesion.tracing.critical.Critical`) as the files hold it:
    ``sigma_c`` (or ``mu_c``) and lambda_c, F_c with their bars, the values on each level (``*_grid``), the
    levels and their nodes, the domain's share, the bracket, the edge and contact radius at the cusp, its
    roughness law, r_m, the wall time and any warning."""
    k = c.kind
    out: dict[str, object] = {c.fixed_name: c.fixed, k: c.value.value, f"{k}_err": c.value.err, "lambda_c": c.lam.value,
           "lambda_c_err": c.lam.err, "F_c": c.F.value, "F_c_err": c.F.err, f"{k}_domain": c.domain,
           "levels": list(c.levels), "n_nodes": list(c.n_nodes), f"{k}_grid": list(c.value_grid),
           "lambda_c_grid": list(c.lam_grid), "F_c_grid": list(c.F_grid), "bracket": list(c.bracket),
           "edge": c.edge, "contact_radius": c.contact_radius, "roughness": pressure_law(c.model).describe(),
           "rmax": c.model.rmax, "wall_time_s": c.wall_time_s}
    if c.warning is not None:
        out["warning"] = c.warning
    return out
