"""Plain-text exports (CSV): the load-approach curve, its events, and a study's table of events (docs/output.md).

Each file has one header line, every column named with its unit in brackets (none for the labels and the
0/1 flags), then one row per point or event.  Numbers are written as ``repr`` writes them, the shortest
text that reads back to the same double; a cell is empty where the value does not exist (no error bar,
no landing, no spring; NaN in the HDF5 table of a study).  With physical inputs each dimensionless column
has a twin in nm or nN (the value times the scale of the ``physical`` group).  Behind a spring the curve's
CSV holds the two legs the cantilever follows (approach, then retract; the traced points are the HDF5 file's).
"""
from __future__ import annotations

import csv
import math

import numpy as np

from .layout import _EPS, _LOAD, _RAD
from ..tracing.measured import Missing
from .summary import branch_record, event_record, legs_record

__all__ = ["CURVE_COLUMNS", "EVENT_COLUMNS", "LEG_COLUMNS", "curve_csv_columns", "legs_csv_columns", "event_csv_columns", "table_csv_columns",
           "write_csv", "write_curve_csv", "write_events_csv", "write_table_csv"]

#: unit of a dimensionless column -> (the suffix of its physical twin, its unit, the scale in the physical group)
_PHYSICAL = {_EPS: ("nm", "nm", "approach_nm"), _LOAD: ("nN", "nN", "force_nN"), _RAD: ("nm", "nm", "radius_nm")}

#: The curve's columns: (key of the HDF5 group curve, unit or None); Z and stable_spring only behind a spring.
CURVE_COLUMNS = (("lambda", _EPS), ("F", _LOAD), ("Z", _EPS), ("contact_radius", _RAD), ("stable", None),
                 ("stable_spring", None))

#: The legs' columns after ``leg`` (approach or retract), and a ``jump`` flag last: (key of a leg's group in
#: the HDF5 group instrument, unit).
LEG_COLUMNS = (("Z", _EPS), ("separation", _EPS), ("deflection", _EPS), ("F", _LOAD), ("lambda", _EPS),
               ("contact_radius", _RAD))

#: The events' columns: (name, unit or None); ``landing_X`` is X of the fold's landing.
EVENT_COLUMNS = (("kind", None), ("lambda", _EPS), ("lambda_err", _EPS), ("F", _LOAD), ("F_err", _LOAD),
                 ("Z", _EPS), ("Z_err", _EPS), ("H0", _EPS), ("contact_radius", _RAD), ("contact_radius_err", _RAD),
                 ("stable", None), ("levels", None), ("landing_lambda", _EPS), ("landing_lambda_err", _EPS),
                 ("landing_F", _LOAD), ("landing_F_err", _LOAD), ("landing_Z", _EPS),
                 ("landing_contact_radius", _RAD), ("landing_contact_radius_err", _RAD), ("lambda_grid", _EPS),
                 ("F_grid", _LOAD))

#: Units of a study table's columns (layout.study_table) and of the options -study_mu and -study_sigma sweep;
#: another swept option's column is in the option's own unit, as it takes its values.
_TABLE_UNITS = {"adh_mu": "1", "adh_sigma": _EPS, "lambda": _EPS, "lambda_err": _EPS, "lambda_grid": _EPS,
                "F": _LOAD, "F_err": _LOAD, "F_grid": _LOAD, "Z": _EPS, "Z_err": _EPS, "contact_radius": _RAD,
                "contact_radius_err": _RAD, "lambda_spread": _EPS, "F_spread": _LOAD}


def _header(name: str, unit: str | None) -> str:
    return name if unit is None else f"{name} [{unit}]"


def _cell(x) -> str:
    """One value as text: a flag 0/1, an integer, a float exactly (``repr``), levels space-separated, a
    missing or NaN value empty."""
    if x is None:
        return ""
    if isinstance(x, (bool, np.bool_)):
        return "1" if x else "0"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        return "" if math.isnan(x) else repr(float(x))
    if isinstance(x, bytes):
        return x.decode()
    if isinstance(x, (list, tuple, np.ndarray)):
        return " ".join(_cell(v) for v in x)
    return str(x)


def _with_physical(columns: list, physical: dict | None) -> list:
    """``columns`` (header name, unit, values), then, with ``physical`` scales, the twin in nm or nN of each
    dimensionless one (None stays None)."""
    if not physical:
        return columns
    twins = []
    for name, unit, values in columns:
        if unit in _PHYSICAL:
            suffix, phys_unit, scale = _PHYSICAL[unit]
            s = float(physical[scale])
            twins.append((f"{name}_{suffix}", phys_unit, [None if v is None else float(v) * s for v in values]))
    return columns + twins


def curve_csv_columns(branch: dict, physical: dict | None = None) -> list:
    """The columns of the curve's CSV (header name, unit, values), from the HDF5 group ``curve``
    (:func:`~petsc_adhesion.io.summary.branch_record`) and the scales of ``physical`` (or None)."""
    cols = [(k, unit, list(branch[k])) for k, unit in CURVE_COLUMNS if k in branch]
    return _with_physical(cols, physical)


def _event_value(e: dict, name: str):
    if name.startswith("landing_"):
        return e.get("landing", {}).get(name[len("landing_"):])
    return e.get(name)


def event_csv_columns(records: list[dict], physical: dict | None = None) -> list:
    """The columns of the events' CSV (header name, unit, values), one row per record of
    :func:`~petsc_adhesion.io.summary.event_record` (None where an event has no such value)."""
    cols = [(name, unit, [_event_value(e, name) for e in records]) for name, unit in EVENT_COLUMNS]
    return _with_physical(cols, physical)


def table_csv_columns(table: dict) -> list:
    """The columns of a study's table (:func:`~petsc_adhesion.io.layout.study_table`) in its order."""
    return [(k, _TABLE_UNITS.get(k), list(v)) for k, v in table.items()]


def write_csv(path: str, columns: list) -> None:
    """``columns`` (header name, unit, values) as CSV: one header line, a row per value."""
    rows = len(columns[0][2]) if columns else 0
    with open(path, "w", newline="", encoding="utf-8") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow([_header(name, unit) for name, unit, _ in columns])
        for i in range(rows):
            out.writerow([_cell(values[i]) for _, _, values in columns])


def _physical(curve) -> dict | None:
    return None if curve.model.bodies is None else curve.model.bodies.describe()


def legs_csv_columns(legs: dict, physical: dict | None = None) -> list:
    """The columns of the legs' CSV (header name, unit, values), from the HDF5 group ``instrument``
    (:func:`~petsc_adhesion.io.summary.legs_record`): a row per point, the approach's then the retract's,
    ``leg`` naming which, ``jump`` 1 at a turning point the tip jumps from (to the next row, at the same Z)."""
    names: list[str] = []
    jump: list[bool] = []
    for leg in ("approach", "retract"):
        n, at = len(legs[leg]["Z"]), set(int(i) for i in legs[leg]["jumps"])
        names += [leg] * n
        jump += [i in at for i in range(n)]
    cols: list[tuple[str, str | None, list]] = [("leg", None, names)]
    cols += [(k, unit, [float(v) for leg in ("approach", "retract") for v in legs[leg][k]])
             for k, unit in LEG_COLUMNS]
    return _with_physical(cols + [("jump", None, jump)], physical)


def write_curve_csv(path: str, curve) -> None:
    """The points of a :class:`~petsc_adhesion.tracing.curve.Curve` as CSV, in traced order; behind a spring
    the two legs its cantilever follows (:func:`legs_csv_columns`), the traced points being the HDF5 file's."""
    legs = curve.instrument
    if legs is not None and not isinstance(legs, Missing):
        write_csv(path, legs_csv_columns(legs_record(legs), _physical(curve)))
        return
    write_csv(path, curve_csv_columns(branch_record(curve), _physical(curve)))


def write_events_csv(path: str, curve) -> None:
    """The events of a :class:`~petsc_adhesion.tracing.curve.Curve` as CSV, in the order found."""
    write_csv(path, event_csv_columns([event_record(e, profiles=False) for e in curve.events], _physical(curve)))


def write_table_csv(path: str, table: dict) -> None:
    """A study's table of events (:func:`~petsc_adhesion.io.layout.study_table`) as CSV."""
    write_csv(path, table_csv_columns(table))
