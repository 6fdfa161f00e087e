"""Result files: their layout (docs/output.md) and their writing, by rank 0.

The layout of a curve or a solve is built here from the result dicts of
:mod:`petsc_adhesion.results`, once for the JSON summary and the HDF5 tree;
the files of one run are written into the temporaries of a
:class:`~petsc_adhesion.files.ResultSet` and committed together.
"""
from __future__ import annotations

import json
import os

import numpy as np

from .files import PLOT_FORMATS, ResultSet
from .physical import in_units

__all__ = ["write_h5", "write_json", "curve_summary", "curve_tree", "write_curve", "write_solve", "study_table",
           "write_study", "CRITICAL_KEYS", "critical_table", "write_critical"]


# Units of the dimensionless results (docs/model.md)
_EPS, _LOAD, _RAD, _PRES = "epsilon", "2 pi R gamma", "sqrt(epsilon R)", "8 gamma / (3 epsilon)"
_STATE = f"lambda, H0: {_EPS}; F: {_LOAD}"
_ERRORS = f"lambda_err, lambda_grid: {_EPS}; F_err, F_grid, F_beyond: {_LOAD}; contact_radius: {_RAD}"
_PHYS = ("R_m, epsilon_m: m; E_Pa: Pa; gamma_J_m2: J/m^2; mu: 1; sigma: epsilon; force_nN: nN per 2 pi R gamma; "
         "approach_nm: nm per epsilon; radius_nm: nm per sqrt(epsilon R); pressure_MPa: MPa per 8 gamma / (3 epsilon)")
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
    "curve/ds": ("1", "the step that reached the point (0 at the start)"),
    "curve/newton_its": ("", "Newton iterations of the corrector"),
    "curve/ksp_its": ("", "Krylov iterations of the corrector and the tangent"),
    "curve/corrector": ("", "start, natural (eq. 21-22) or arclength (eq. 24-25)"),
    "events": ("", "events located on the curve, in the order found"),
    "events/*": (f"{_STATE}; {_ERRORS}", "one event: kind (snap_on, snap_off, F_min, F_max, equilibrium, "
                 "lambda), its state, stability, error estimates"),
    "events/*/r": (_RAD, "the nodes of the grid the event was located on (-profiles)"),
    "events/*/H": (_EPS, "separation at the nodes at the event (-profiles)"),
    "events/*/P": (_PRES, "pressure at the nodes at the event (-profiles)"),
    "events/*/landing": (_STATE, "where the jump from this fold lands: the other stable branch at its lambda"),
    "events/*/landing/r": (_RAD, "the nodes of the grid the landing was located on (-profiles)"),
    "events/*/landing/H": (_EPS, "separation at the nodes after the jump (-profiles)"),
    "events/*/landing/P": (_PRES, "pressure at the nodes after the jump (-profiles)"),
    "summary": (f"{_STATE}; {_ERRORS}; *_s: s; *_nm: nm; *_nN: nN", "the JSON summary (docs/output.md); "
                "physical: its events in nm and nN"),
    "study": ("", "a study (kind: study): what its cases compute, the options swept, ranks per case, the figure"),
    "cases": ("", "the cases of a study that ran, in their order; each holds a curve's layout and its values"),
    "cases/*": ("", "one case: the options it sets (values), its model, grid, curve, events and summary"),
    "cases/*/values": ("", "the options this case sets (name without the dash: value)"),
    "failed": ("", "the cases of a study that did not run or failed, each with its one-line reason"),
    "table": (f"{_STATE}; {_ERRORS}", "every case's events, one row each: case number, the swept options, kind, "
              "best lambda and F with their error bars (NaN: none), the single-grid values"),
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


def _describe(name: str, obj) -> None:
    key = "/".join("*" if part.isdigit() else part for part in name.split("/"))
    if key.startswith("cases/*/") and key not in DESCRIBE:     # a study's case holds a curve's layout
        key = key[len("cases/*/"):]
    if key.startswith(("summary/", "study/", "failed/")):
        key = key.split("/")[0]
    elif key.startswith(("table/", "critical_roughness/", "critical_mu/")):
        key = key.split("/")[0] + "/*"
    units, text = DESCRIBE[key]
    obj.attrs["units"], obj.attrs["description"] = units, text


def _write(group, tree: dict) -> None:
    """Dicts become groups, lists of dicts numbered groups; arrays datasets; scalars, strings and lists of
    numbers or strings attributes (None: an empty string)."""
    import h5py

    for key, val in tree.items():
        if isinstance(val, dict):
            _write(group.require_group(key), val)
        elif isinstance(val, (list, tuple)) and val and isinstance(val[0], dict):
            sub = group.require_group(key)
            for i, item in enumerate(val):
                _write(sub.require_group(f"{i:04d}"), item)
        elif isinstance(val, (list, tuple)) and all(isinstance(v, (int, float)) for v in val) and val:
            group.attrs[key] = np.array(val)
        elif isinstance(val, (list, tuple)):
            group.attrs[key] = np.array([str(v) for v in val], dtype=h5py.string_dtype())
        elif isinstance(val, np.ndarray):
            group.create_dataset(key, data=val)
        else:
            group.attrs[key] = "" if val is None else val


def write_h5(path: str, tree: dict) -> None:
    """The tree as an HDF5 file (see :func:`_write`), every group and dataset with units and a description."""
    import h5py

    with h5py.File(path, "w") as f:
        _write(f, tree)
        _describe("", f)
        f.visititems(_describe)


def _plain(x):
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x


def write_json(path: str, summary: dict) -> None:
    """The summary as JSON (no NaN allowed)."""
    with open(path, "w") as f:
        json.dump(_plain(summary), f, indent=1, allow_nan=False)
        f.write("\n")


# -- layout ---------------------------------------------------------------------
_BRIEF = ("kind", "lambda", "F", "H0", "contact_radius", "stable", "lambda_err", "F_err", "lambda_grid", "F_grid", "F_beyond",
          "levels", "target_met", "error_note")


def _brief(e: dict) -> dict:
    out = {k: v for k, v in e.items() if k in _BRIEF}
    if "landing" in e:
        out["landing"] = {k: v for k, v in e["landing"].items()
                          if k in ("lambda", "F", "H0", "contact_radius", "F_err", "F_grid")}
    return out


def _common(head: dict) -> dict:
    """The keys every summary has: versions, the model and the grid size (the largest grid's)."""
    flat = {k: v for k, v in head.items() if k not in ("options", "model", "grid")}
    sizes = head["grid"].get("n_nodes", [head["grid"]["r"].size])
    return {**flat, **head["model"], "n_nodes": int(max(sizes))}


def curve_summary(res: dict, head: dict) -> dict:
    """The JSON summary of a traced curve."""
    ev, po = res["events"], res["pull_off"]
    s = {**_common(head),
         "pull_off": _brief(po) if po else None,
         "folds": [_brief(e) for e in ev if e["kind"] in ("snap_on", "snap_off")],
         "equilibria": [{k: v for k, v in _brief(e).items() if k not in ("F", "F_err", "F_grid")}
                       for e in ev if e["kind"] == "equilibrium"],
         "load_extrema": [_brief(e) for e in ev if e["kind"] in ("F_min", "F_max")],
         "at_lambda": [_brief(e) for e in ev if e["kind"] == "lambda"],
         "wall_gap": res["wall_gap"],
         "steps": res["steps"], "rejected_steps": res["rejected_steps"], "regrids": res["regrids"],
         **{k: res[k] for k in ("guard_activations", "smallest_step", "most_newton_its", "most_ksp_its")},
         "stop_reason": res["stop_reason"],
         "grid_warning": res["grid_warning"], "warnings": res["warnings"], "complete": not res["incomplete"],
         "lambda_start": res["lambda_start"], "wall_time_s": res["wall_time_s"]}
    if "error_estimate" in res:
        s["error_estimate"] = res["error_estimate"]
    if "physical" in head:
        s["physical"] = in_units(s, head["physical"])
    return s


def curve_tree(res: dict, head: dict, summary: dict) -> dict:
    """The HDF5 tree of a traced curve: the points, the events, and the summary."""
    pts = res["points"]
    curve = {"lambda": np.array([p.p for p in pts]), "F": np.array([p.values["F"] for p in pts]),
             "stable": np.array([p.pdot > 0 for p in pts]), "ds": np.array([p.ds for p in pts]),
             "newton_its": np.array([p.newton_its for p in pts]), "ksp_its": np.array([p.ksp_its for p in pts]),
             "H0": np.array([p.x[0] for p in pts]), "lambdadot": np.array([p.pdot for p in pts]),
             "corrector": np.array([p.corrector for p in pts], dtype="S9")}
    events = [{k: v for k, v in e.items() if k != "segment"} for e in res["events"]]
    return {**head, "kind": "curve", "curve": curve, "events": events, "summary": summary}


def write_curve(res: dict, head: dict, files: ResultSet) -> dict:
    """The files of a traced curve, committed together; returns the summary."""
    summ = curve_summary(res, head)
    tree = curve_tree(res, head, summ)
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "plot" in files.targets:
        from .plot import curve_figure

        fmt = PLOT_FORMATS[os.path.splitext(files.targets["plot"])[1].lower()]
        curve_figure(tree, files.temp("plot"), fmt)
    if "summary" in files.targets:
        write_json(files.temp("summary"), summ)
    files.commit()
    return summ


def write_solve(res: dict, head: dict, files: ResultSet) -> dict:
    """The files of a fixed-approach solve, committed together; returns the summary."""
    brief = {k: v for k, v in res.items() if not isinstance(v, np.ndarray)}
    summ = {**_common(head), **brief}
    if "physical" in head:
        d = head["physical"]
        summ["physical"] = {**d, "lambda_nm": res["lambda"] * d["approach_nm"], "F_nN": res["F"] * d["force_nN"],
                            "H0_nm": res["H0"] * d["approach_nm"]}
    if "out" in files.targets:
        write_h5(files.temp("out"), {**head, "kind": "solve", "solution": {"H": res["H"], "P": res["P"], **brief}})
    if "summary" in files.targets:
        write_json(files.temp("summary"), summ)
    files.commit()
    return summ


def study_table(done: list[dict], axes: list[str]) -> dict:
    """Every case's events as columns: case, the swept options, kind, best values, bars, grid values."""
    rows = [(r, e) for r in done for e in r["tree"]["events"]]
    cols = {"case": np.array([r["case"] for r, _ in rows], dtype=int)}
    cols |= {name: np.array([r["values"][name] for r, _ in rows], dtype=float) for name in axes}
    cols["kind"] = np.array([e["kind"] for _, e in rows], dtype="S12")
    for k in ("lambda", "lambda_err", "F", "F_err", "lambda_grid", "F_grid"):
        cols[k] = np.array([e.get(k, np.nan) for _, e in rows], dtype=float)
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


def write_critical(prog: dict, study: dict, done: list[dict], failed: list[dict], files: ResultSet) -> dict:
    """The files of a critical study (``-study_compute critical``), committed together; returns the summary.

    ``done``: the cases that ran, each a record of :func:`~petsc_adhesion.critical.sigma_c` or
    :func:`~petsc_adhesion.critical.mu_c` with its ``kind``; ``failed``: {case, values, error}.
    """
    brief = {k: v for k, v in prog.items() if k != "options"}
    def keys(kind):
        return CRITICAL_KEYS[kind] + (f"{kind}_grid", "levels", "n_nodes", "bracket", "roughness", "rmax", "warning")

    lists = {name: [{k: r[k] for k in keys(kind) if k in r} for r in done if r["kind"] == kind]
             for name, kind in _CRITICAL}
    summ = {**brief, "kind": "critical", "study": study, **lists, "failed": failed}
    tree = {**prog, "kind": "critical", "study": study,
            **{name: critical_table(done, kind) for name, kind in _CRITICAL},
            **({"failed": [{"case": f["case"], "error": f["error"], "values": f["values"]} for f in failed]}
               if failed else {})}
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "plot" in files.targets:
        from .studyplot import critical_figure

        critical_figure(tree, files.temp("plot"), PLOT_FORMATS[os.path.splitext(files.targets["plot"])[1].lower()])
    if "summary" in files.targets:
        write_json(files.temp("summary"), summ)
    files.commit()
    return summ


def write_study(prog: dict, study: dict, done: list[dict], failed: list[dict], files: ResultSet) -> dict:
    """The files of a study (:mod:`petsc_adhesion.sweep`), committed together; returns the summary.

    ``done``: each case that ran as {case, values, summary, tree}; ``failed``: {case, values, error}.
    """
    brief = {k: v for k, v in prog.items() if k != "options"}
    cases = [{"case": r["case"], "values": r["values"], **r["summary"]} for r in done]
    summ = {**brief, "kind": "study", "study": study, "cases": cases, "failed": failed}
    tree = {**prog, "kind": "study", "study": study,
            "cases": [{"case": r["case"], "values": r["values"], **r["tree"]} for r in done],
            "table": study_table(done, study["axes"]),
            **({"failed": [{"case": f["case"], "error": f["error"], "values": f["values"]} for f in failed]}
               if failed else {})}
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "plot" in files.targets:
        from .studyplot import study_figure

        fmt = PLOT_FORMATS[os.path.splitext(files.targets["plot"])[1].lower()]
        study_figure(tree, files.temp("plot"), study["plot"], fmt)
    if "summary" in files.targets:
        write_json(files.temp("summary"), summ)
    files.commit()
    return summ
