"""Result files: their layout (docs/output.md) and their writing, by rank 0.

The layout of a curve or a solve is built from the library's result values
(:mod:`petsc_adhesion.io.summary`, :mod:`petsc_adhesion.io.layout`), once for the JSON summary and the HDF5 tree;
the files of one run are written into the temporaries of a
:class:`~petsc_adhesion.io.resultset.ResultSet` and committed together.
"""
from __future__ import annotations

import json

import numpy as np

from .layout import (
    _CRITICAL,
    CRITICAL_KEYS,
    DESCRIBE,
    case_tree,
    critical_table,
    curve_tree,
    solve_tree,
    study_table,
)
from .fit import DESCRIBE_FIT, write_fit_csv
from .resultset import ResultSet, plot_format
from .summary import critical_record, solve_summary, summary_of
from .text import write_curve_csv, write_events_csv, write_table_csv

__all__ = ["write_h5", "write_json", "write_curve", "write_solve", "write_study", "write_critical", "write_fit"]





def _figure_format(path: str) -> str:
    """The figure format -plot's file name ends in (check_targets has refused any other before the run)."""
    fmt = plot_format(path)
    if fmt is None:
        raise ValueError(f"-plot: '{path}' ends in no figure format (check_targets refuses it before a run)")
    return fmt


def _describe(name: str, obj) -> None:
    key = "/".join("*" if part.isdigit() else part for part in name.split("/"))
    if key.startswith("cases/*/") and key not in DESCRIBE:     # a study's case holds a curve's layout
        key = key[len("cases/*/"):]
    if key.startswith(("summary/", "study/", "failed/")):
        key = key.split("/")[0]
    elif key.startswith(("table/", "critical_roughness/", "critical_mu/")):
        key = key.split("/")[0] + "/*"
    elif key.startswith("instrument/"):                        # its legs, approach and retract: alike
        parts = key.split("/")
        key = "/".join(["instrument", "*", *parts[2:]])
    elif key.startswith("fit/"):                               # a fit's groups: described by their branch
        key = "/".join(key.split("/")[:2])
    units, text = DESCRIBE[key] if key in DESCRIBE else DESCRIBE_FIT[key]
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


def write_curve(curve, options: dict, files: ResultSet, commit: bool = True) -> None:
    """The files of a :class:`~petsc_adhesion.tracing.curve.Curve` (``options``: its run's, as given),
    committed together (``commit`` False: the caller commits, once the run's other output is out)."""
    tree = curve_tree(curve, options)
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "plot" in files.targets:
        from .plot.curve import curve_figure

        fmt = _figure_format(files.targets["plot"])
        curve_figure(tree, files.temp("plot"), fmt)
    if "summary" in files.targets:
        write_json(files.temp("summary"), summary_of(curve))
    if "csv" in files.targets:
        write_curve_csv(files.temp("csv"), curve)
    if "csv_events" in files.targets:
        write_events_csv(files.temp("csv_events"), curve)
    if commit:
        files.commit()


def write_fit(tree: dict, summary: dict, files) -> None:
    """The files of a fit into the temporaries of ``files`` (a ResultSet; the caller commits)."""
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "summary" in files.targets:
        write_json(files.temp("summary"), summary)
    if "plot" in files.targets:
        from .plot.fit import fit_figure

        fit_figure(tree, files.temp("plot"), _figure_format(files.targets["plot"]))
    if "csv" in files.targets:
        write_fit_csv(files.temp("csv"), tree["fit"]["data"])



def write_solve(solution, options: dict, files: ResultSet, commit: bool = True) -> None:
    """The files of a :class:`~petsc_adhesion.tracing.curve.Solution`, committed together (``commit``: as
    :func:`write_curve`)."""
    if "out" in files.targets:
        write_h5(files.temp("out"), solve_tree(solution, options))
    if "summary" in files.targets:
        write_json(files.temp("summary"), solve_summary(solution))
    if commit:
        files.commit()


def _failed(failed: list) -> list[dict]:
    """The records of the cases that did not run (:class:`~petsc_adhesion.tracing.case.CaseResult`, its
    result Missing): number, values, the one-line reason."""
    return [{"case": r.case, "values": dict(r.values), "error": r.result.reason} for r in failed]


def write_critical(prog: dict, study: dict, done: list, failed: list, files: ResultSet) -> dict:
    """The files of a critical study (``-study_compute critical``), committed together; returns the summary.

    ``done``: the cases that ran, each a :class:`~petsc_adhesion.tracing.case.CaseResult` of a
    :class:`~petsc_adhesion.tracing.critical.Critical`; ``failed``: those that did not, in case order.
    """
    brief = {k: v for k, v in prog.items() if k != "options"}
    records = [{"case": r.case, "values": dict(r.values), "kind": r.result.kind, **critical_record(r.result)}
               for r in done]
    def keys(kind):
        return CRITICAL_KEYS[kind] + (f"{kind}_grid", "levels", "n_nodes", "bracket", "roughness", "rmax", "warning")

    lost = _failed(failed)
    lists = {name: [{k: r[k] for k in keys(kind) if k in r} for r in records if r["kind"] == kind]
             for name, kind in _CRITICAL}
    summ = {**brief, "kind": "critical", "study": study, **lists, "failed": lost}
    tree = {**prog, "kind": "critical", "study": study,
            **{name: critical_table(records, kind) for name, kind in _CRITICAL},
            **({"failed": [{"case": f["case"], "error": f["error"], "values": f["values"]} for f in lost]}
               if lost else {})}
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "plot" in files.targets:
        from .plot.study import critical_figure

        critical_figure(tree, files.temp("plot"), _figure_format(files.targets["plot"]))
    if "summary" in files.targets:
        write_json(files.temp("summary"), summ)
    files.commit()
    return summ


def write_study(prog: dict, study: dict, done: list, failed: list, files: ResultSet) -> dict:
    """The files of a study (:mod:`petsc_adhesion.app.study`), its table of events as CSV among them (``csv``),
    committed together; returns the summary.

    ``done``: each case that ran, a :class:`~petsc_adhesion.tracing.case.CaseResult` of its
    :class:`~petsc_adhesion.tracing.curve.Curve`; ``failed``: those that did not, in case order.
    """
    brief = {k: v for k, v in prog.items() if k != "options"}
    cases = [{"case": r.case, "values": dict(r.values), **summary_of(r.result)} for r in done]
    lost = _failed(failed)
    summ = {**brief, "kind": "study", "study": study, "cases": cases, "failed": lost}
    tree = {**prog, "kind": "study", "study": study,
            "cases": [case_tree(r) for r in done],
            "table": study_table(done, study["axes"]),
            **({"failed": [{"case": f["case"], "error": f["error"], "values": f["values"]} for f in lost]}
               if lost else {})}
    if "out" in files.targets:
        write_h5(files.temp("out"), tree)
    if "plot" in files.targets:
        from .plot.study import study_figure

        fmt = _figure_format(files.targets["plot"])
        study_figure(tree, files.temp("plot"), study["plot"], fmt)
    if "summary" in files.targets:
        write_json(files.temp("summary"), summ)
    if "csv" in files.targets:
        write_table_csv(files.temp("csv"), tree["table"])
    files.commit()
    return summ
