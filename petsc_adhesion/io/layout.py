"""The layout of the result files: the HDF5 trees of a curve, a solve, a study and a critical study, and the units
and description of every group and dataset (docs/output.md)."""
from __future__ import annotations

import numpy as np

from ..tracing.measured import Missing
from .summary import branch_record, event_record, head_of, legs_record, solve_record, spread_record, summary_of

__all__ = ["DESCRIBE", "curve_tree", "study_table", "CRITICAL_KEYS", "critical_table", "with_options", "case_tree", "solve_tree",
           "spread_tree"]

# Units of the dimensionless results (docs/model.md)
_EPS, _LOAD, _RAD, _PRES = "epsilon", "2 pi R gamma", "sqrt(epsilon R)", "8 gamma / (3 epsilon)"
_STATE = f"lambda, H0: {_EPS}; F: {_LOAD}"


_ERRORS = (f"lambda_err, lambda_grid, Z, Z_err, Z_grid: {_EPS}; F_err, F_grid, F_beyond: {_LOAD}; "
           f"contact_radius, contact_radius_err, contact_radius_grid: {_RAD}")


_PHYS = ("R_m, epsilon_m: m; E_Pa: Pa; gamma_J_m2: J/m^2; mu: 1; sigma: epsilon; force_nN: nN per 2 pi R gamma; "
         "approach_nm: nm per epsilon; radius_nm: nm per sqrt(epsilon R); pressure_MPa: MPa per 8 gamma / (3 epsilon); "
         "work_aJ: aJ per 2 pi R gamma epsilon")


#: path pattern (numbered groups as *) -> (units, one-line description), for every group and dataset
DESCRIBE = {
    "": ("", "petsc-adhesion result: adhesive contact of an elastic sphere with a flat (Cheng, Dunn and Brach "
             "2002); kind: curve (continuation) or solve (one approach)"),
    "options": ("", "every option of the run as given (name without the dash: value)"),
    "model": (f"mu: 1; sigma: {_EPS}; rmax: {_RAD}", "the model: Tabor parameter mu (eq. 9), roughness sigma "
              "(with its averaging rule when sigma > 0), end r_m of the domain"),
    "physical": (_PHYS, "the physical inputs (-phys_, SI) as given (inputs), the combined radius and modulus "
                 "(eq. 2), the work of adhesion, epsilon, the mu (eq. 9) and sigma they make, and the value of each "
                 "unit of the model in nN, nm and MPa"),
    "physical/inputs": ("radius*: m; young*: Pa; poisson*: 1; gamma: J/m^2; hamaker: J; hamaker_cutoff: m; "
                        "epsilon: m; rms: m", "the -phys_ options as given (SI)"),
    "topography": ("*_m: m; *_epsilon: epsilon; correlation_length_pixels: pixels", "the measured topographies "
                   "the gap's heights came from (-adh_topography, docs/topography.md): the gap's rms and how it was "
                   "made; why the model is smooth when the gap is flat"),
    "topography/surfaces": ("", "one group per topography file"),
    "topography/surfaces/*": ("*_m: m; correlation_length_pixels: pixels; skewness, kurtosis: 1",
                              "one topography: its file, kind (map or profile), pixels, size, unit and where it "
                              "came from, detrending, and its heights' rms, skewness and kurtosis with their sampling "
                              "uncertainty (from the heights' own autocorrelation) and the independent samples for "
                              "each"),
    "grid": ("", "the collocation grid (of the last segment when the grid followed the contact edge)"),
    "grid/r": (_RAD, "the nodes r_i on [0, r_m]"),
    "grid/lambda": (_EPS, "approach where each segment of the curve, on its own grid, starts"),
    "grid/edge": (_RAD, "contact edge (or, in the frame of the edge, contact radius) each segment's grid is "
                        "centred on; absent on a fixed grid"),
    "grid/n_nodes": ("", "nodes of each segment's grid"),
    "solution": (f"{_STATE}; wall_time_s: s", "the state at one approach (-adh_lambda) and the solver's effort"),
    "solution/H": (_EPS, "separation H = h / epsilon - 1 at the nodes"),
    "solution/P": (_PRES, "pressure at the nodes (eq. 14), positive when repulsive"),
    "curve": ("", "the load-approach curve, one entry per computed point, start first"),
    "curve/lambda": (_EPS, "approach lambda = alpha / epsilon"),
    "curve/F": (_LOAD, "load (eq. 26), negative when tensile"),
    "curve/H0": (_EPS, "separation at r = 0"),
    "curve/lambdadot": ("1", "d lambda / ds of the unit tangent (s: pseudo-arclength)"),
    "curve/stable": ("", "stable under displacement control (lambdadot > 0)"),
    "curve/contact_radius": (_RAD, "contact radius: where the separation first rises through the edge level "
                                   "(docs/numerics.md), on the grid of the point"),
    "curve/Z": (_EPS, "base position of the spring (-afm_spring K): Z = lambda + F / K"),
    "curve/stable_spring": ("", "stable behind the spring (dZ/ds > 0)"),
    "curve/ds": ("1", "the step that reached the point (0 at the start)"),
    "curve/newton_its": ("", "Newton iterations of the corrector"),
    "curve/ksp_its": ("", "Krylov iterations of the corrector and the tangent"),
    "curve/corrector": ("", "start, natural (eq. 21-22) or arclength (eq. 24-25)"),
    "instrument": (f"K: {_LOAD} / {_EPS}; trigger: {_LOAD}", "behind a spring: the approach and the retract "
                   "its cantilever follows (tracing/legs.py), the stable branches with the jumps vertical at constant "
                   "Z, made of the solver's points (the traced points, the turning points and their landings at "
                   "their grid values); trigger: the load the approach was to end at, reached: whether it did; "
                   "missing: why there are no legs"),
    "instrument/*": ("", "one leg (approach or retract), its points in the order the instrument records them"),
    "instrument/*/Z": (_EPS, "base (piezo) position Z = lambda + F / K, growing toward the flat"),
    "instrument/*/separation": (_EPS, "tip-sample separation as an instrument computes it, -(Z - F / K) = "
                                "-lambda: 0 where the undeformed sphere sits at epsilon from the flat, negative "
                                "an indentation"),
    "instrument/*/deflection": (_EPS, "deflection of the cantilever F / K, positive pushed away from the flat"),
    "instrument/*/F": (_LOAD, "force (eq. 26), negative when tensile"),
    "instrument/*/lambda": (_EPS, "approach lambda of the tip (the sphere)"),
    "instrument/*/contact_radius": (_RAD, "contact radius (NaN at a landing the solver gave none)"),
    "instrument/*/jumps": ("", "indices i (from 0) at which the tip jumps at constant Z from point i, a turning "
                           "point, to point i + 1, its landing"),
    "events": ("", "events located on the curve, in the order found"),
    "events/*": (f"{_STATE}; {_ERRORS}", "one event: kind (snap_on, snap_off, F_min, F_max, equilibrium, "
                 "lambda; behind a spring jump_in, jump_off), its state, stability, error estimates"),
    "events/*/r": (_RAD, "the nodes of the grid the event was located on (-profiles)"),
    "events/*/H": (_EPS, "separation at the nodes at the event (-profiles)"),
    "events/*/P": (_PRES, "pressure at the nodes at the event (-profiles)"),
    "events/*/landing": (f"{_STATE}; {_ERRORS}", "where the jump from this fold lands: the other stable branch "
                         "at its lambda (behind a spring: at its Z)"),
    "events/*/landing/r": (_RAD, "the nodes of the grid the landing was located on (-profiles)"),
    "events/*/landing/H": (_EPS, "separation at the nodes after the jump (-profiles)"),
    "events/*/landing/P": (_PRES, "pressure at the nodes after the jump (-profiles)"),
    "model_spread": ("wall_time_s, rule_times_s: s; force_nN: nN per 2 pi R gamma; approach_nm: nm per epsilon",
                     "the model spread (docs/model.md): the curve's events traced again, events only, under the "
                     "other roughness laws (rules) against the reference's; notes where a law has other events; "
                     "warnings where a law moves an event beyond ten error bars or 10 % of its value"),
    "model_spread/quantities": ("", "one group per event quantity of the reference curve"),
    "model_spread/quantities/*": (f"value, err, values, spread: the quantity's unit (lambda: {_EPS}; F: {_LOAD}; "
                                  "energy: 2 pi R gamma epsilon); relative: 1",
                                  "one quantity: its value and error bar under the reference's law, the spread "
                                  "(the largest distance from the reference), relative to the value (lambda's to "
                                  "at least 1), the warning, and missing: why a law has not the quantity"),
    "model_spread/quantities/*/values": ("the quantity's unit", "the quantity under each rule, one attribute per "
                                         "rule named by it; a rule whose curve has not the event absent"),
    "summary": (f"{_STATE}; {_ERRORS}; *_s: s; *_nm: nm; *_nN: nN", "the JSON summary (docs/output.md); "
                "physical: its events in nm and nN"),
    "study": ("", "a study (kind: study): what its cases compute, the options swept, ranks per case, the figure"),
    "cases": ("", "the cases of a study that ran, in their order; each holds a curve's layout and its values"),
    "cases/*": ("", "one case: the options it sets (values), its model, grid, curve, events and summary"),
    "cases/*/values": ("", "the options this case sets (name without the dash: value)"),
    "failed": ("", "the cases of a study that did not run or failed, each with its one-line reason"),
    "table": (f"{_STATE}; {_ERRORS}; lambda_spread: {_EPS}; F_spread: {_LOAD}",
              "every case's events, one row each: case number, the swept options, kind, "
              "best lambda and F with their error bars (NaN: none), the single-grid values, Z behind a spring, "
              "the contact radius with its bar; when a case is rough, the model spread of lambda and F (NaN: "
              "none for that event)"),
    "table/*": ("", "one column of the table (units as the table's)"),
    "critical_roughness": (f"mu: 1; sigma_c*: {_EPS}; lambda_c*: {_EPS}; F_c*: {_LOAD}; wall_time_s: s",
                           "the critical roughness sigma_c(mu), above which the curve has no turning points: one "
                           "row per mu of the study, the cusp's best values, error bars and values on each level"),
    "critical_roughness/*": ("", "one column (units as the group's; *_grid, n_nodes: a row per mu, a column per "
                                 "level)"),
    "critical_mu": (f"sigma: {_EPS}; mu_c*: 1; lambda_c*: {_EPS}; F_c*: {_LOAD}; wall_time_s: s",
                    "the critical Tabor parameter mu_c(sigma), below which the curve has no turning points: one "
                    "row per sigma of the study"),
    "critical_mu/*": ("", "one column (units as the group's; *_grid, n_nodes: a row per sigma, a column per level)"),
}


# -- layout ---------------------------------------------------------------------
def with_options(head: dict, options: dict) -> dict:
    """A result's head with the options of its run after the program's keys, as the files hold them."""
    program = {k: v for k, v in head.items() if k not in ("model", "grid", "physical", "topography")}
    return {**program, "options": options,
            **{k: head[k] for k in ("model", "grid", "physical", "topography") if k in head}}


def _h5_summary(summary: dict) -> dict:
    """The summary as the HDF5 group holds it: an energy that is missing is absent (its note says why),
    not an empty value."""
    def cycle(c: dict) -> dict:
        if c.get("energy") is None and "energy_note" in c:
            return {k: v for k, v in c.items() if k not in ("energy", "energy_err", "loops")}
        return c
    out = cycle(summary)
    if out.get("spring"):
        out = {**out, "spring": cycle(out["spring"])}
    return {k: v for k, v in out.items() if k != "model_spread"}     # a group of its own (spread_tree)


def spread_tree(spread) -> dict:
    """The HDF5 group ``model_spread``: the summary's record, a quantity's values a group ``values`` of one
    attribute per law that has it, named by the rule (a law without it absent, its reason in ``missing``:
    no NaN, no 0 in its place)."""
    rec = spread_record(spread)
    quantities = [{**q, "values": {r: v for r, v in zip(rec["rules"], q["values"]) if v is not None}}
                  for q in rec.get("quantities", [])]
    return {**rec, **({"quantities": quantities} if quantities else {})}


def curve_tree(curve, options: dict) -> dict:
    """The HDF5 tree of a :class:`~petsc_adhesion.tracing.curve.Curve`: its head, the options of its run, the
    points, the events, the summary and the model spread (when computed)."""
    tree = {**with_options(head_of(curve), options), "kind": "curve", "curve": branch_record(curve),
            "events": [event_record(e) for e in curve.events], "summary": _h5_summary(summary_of(curve))}
    if curve.instrument is not None:
        tree["instrument"] = legs_record(curve.instrument)
    if curve.spread is not None:
        tree["model_spread"] = spread_tree(curve.spread)
    return tree


def case_tree(case) -> dict:
    """A study's case (:class:`~petsc_adhesion.tracing.case.CaseResult` of a curve): its number and values,
    then a curve's tree without the program's keys (the profiles the study kept), and its model spread when
    computed."""
    curve = case.result
    tree = {**head_of(curve), "curve": branch_record(curve), "events": [event_record(e) for e in curve.events],
            "summary": _h5_summary(summary_of(curve))}
    out = {"case": case.case, "values": dict(case.values),
           **{k: v for k, v in tree.items() if k in ("model", "grid", "curve", "events", "summary", "physical")}}
    if curve.spread is not None:
        out["model_spread"] = spread_tree(curve.spread)
    return out


def solve_tree(solution, options: dict) -> dict:
    """The HDF5 tree of a :class:`~petsc_adhesion.tracing.curve.Solution`."""
    return {**with_options(head_of(solution), options), "kind": "solve",
            "solution": {"H": solution.H, "P": solution.P, **solve_record(solution)}}


def _spreads(curve) -> tuple:
    """The model spread of each event's lambda and F (pairs; None where there is none)."""
    spread = curve.spread
    if spread is None or isinstance(spread, Missing):
        return ((None, None),) * len(curve.events)
    return spread.of_events(curve)


def study_table(done: list, axes: list[str]) -> dict:
    """Every case's events (``done``: :class:`~petsc_adhesion.tracing.case.CaseResult` of curves) as
    columns: case, the swept options, kind, best values, bars, grid values; when a case has a model spread,
    the spread of each event's lambda and F (NaN where the event has none: a smooth case, a kind not
    compared)."""
    rows = [(r, event_record(e, profiles=False), s) for r in done
            for e, s in zip(r.result.events, _spreads(r.result))]
    cols = {"case": np.array([r.case for r, _, _ in rows], dtype=int)}
    cols |= {name: np.array([r.value(name) for r, _, _ in rows], dtype=float) for name in axes}
    cols["kind"] = np.array([e["kind"] for _, e, _ in rows], dtype="S12")
    for k in ("lambda", "lambda_err", "F", "F_err", "lambda_grid", "F_grid", "Z", "Z_err", "contact_radius",
              "contact_radius_err"):
        cols[k] = np.array([e.get(k, np.nan) for _, e, _ in rows], dtype=float)
    if any(r.result.spread is not None for r in done):
        for i, k in enumerate(("lambda_spread", "F_spread")):
            cols[k] = np.array([np.nan if s[i] is None else s[i] for _, _, s in rows], dtype=float)
    return cols


#: The columns of a critical study's cases (critical.sigma_c, critical.mu_c) by kind, in the JSON summary
#: and the HDF5 tables (which add the values on each level).
CRITICAL_KEYS = {k: (fixed, k, f"{k}_err", "lambda_c", "lambda_c_err", "F_c", "F_c_err", f"{k}_domain",
                     "contact_radius", "wall_time_s")
                 for k, fixed in (("sigma_c", "mu"), ("mu_c", "sigma"))}


_CRITICAL = (("critical_roughness", "sigma_c"), ("critical_mu", "mu_c"))


def critical_table(done: list[dict], kind: str) -> dict:
    """The columns of the critical cases of ``kind`` (sigma_c or mu_c): CRITICAL_KEYS, the values on each
    level (``*_grid``, a column per level) and the nodes of each level."""
    rows = [r for r in done if r["kind"] == kind]
    cols = {k: np.array([r[k] for r in rows], dtype=float) for k in CRITICAL_KEYS[kind]}
    for k in (f"{kind}_grid", "lambda_c_grid", "F_c_grid"):
        cols[k] = np.array([r[k] for r in rows], dtype=float)
    cols["n_nodes"] = np.array([r["n_nodes"] for r in rows], dtype=int)
    return cols
