"""A force map's files (docs/maps.md): its HDF5 file, its CSV table, its journal and its console lines.

The only place a map's typed result (:class:`~petsc_adhesion.maps.result.MapResult` and its
:class:`~petsc_adhesion.maps.result.Pixel` values) becomes keys, read by attribute: :func:`pixel_record` is a
pixel as JSON values (a Measured quantity ``q`` as ``q`` and ``q_err``, its note ``q_note``; a Missing one as
null with its reason under ``missing``), :func:`pixel_fields` the way back (a pixel's where and its
constructor's fields, typed), the journal (:class:`Journal`) a header line and one such record per line,
:func:`write_map_h5` and :func:`write_map_csv` the files, :func:`report_map` the console lines.
"""
from __future__ import annotations

import csv
import json
import math
import os

import numpy as np

from ..errors import tell
from ..tracing.measured import Measured, Missing
from ..version import __version__

__all__ = ["QUANTITY_UNITS", "pixel_record", "pixel_fields", "Journal", "JournalError", "map_tree", "write_map_h5",
           "write_map_csv", "report_map", "JOURNAL_FORMAT", "CSV_COLUMNS"]

#: Each quantity of a pixel, its unit in the files and its description.
QUANTITY_UNITS = {
    "gamma": ("J/m^2", "the work of adhesion w fitted"),
    "E_star": ("Pa", "the reduced modulus E* fitted (eq. 2)"),
    "rms": ("m", "the rms roughness, where fitted"),
    "pull_off": ("N", "the pull-off the curve shows: its least retract force below the baseline"),
    "jump_in": ("N", "the approach's jump to contact the curve shows (the largest drop between two samples)"),
    "energy": ("J", "the energy a cycle dissipates: the area between approach and retract"),
}
#: The journal's first line names this format; a journal of another is refused.
JOURNAL_FORMAT = 1
_JOURNAL_KIND = "petsc-adhesion map journal"


# -- a pixel as values and back ----------------------------------------------------------------------------
def _finite(x) -> float | None:
    return float(x) if x is not None and math.isfinite(x) else None


def pixel_record(p) -> dict:
    """A :class:`~petsc_adhesion.maps.result.Pixel` as JSON values (see the module)."""
    e = p.entry
    rec: dict = {"index": e.index, "ix": e.ix, "iy": e.iy, "x": e.x, "y": e.y, "label": e.label,
                 "status": p.status, "reasons": list(p.reasons), "rms_fitted": p.rms is not None,
                 "reduced_chi2": _finite(p.reduced_chi2), "p_value": _finite(p.p_value), "traces": p.traces,
                 "missing": {}}
    for q in QUANTITY_UNITS:
        v = getattr(p, q)
        if isinstance(v, Measured):
            rec[q], rec[f"{q}_err"], rec[f"{q}_note"] = float(v.value), _finite(v.err), v.note
        else:
            rec[q] = rec[f"{q}_err"] = rec[f"{q}_note"] = None
            if isinstance(v, Missing):
                rec["missing"][q] = v.reason
    return rec


def pixel_fields(rec: dict) -> tuple[dict, dict]:
    """The fields of a pixel's :class:`~petsc_adhesion.maps.source.MapEntry` and of its
    :class:`~petsc_adhesion.maps.result.Pixel` (beside the entry), typed, from its :func:`pixel_record`."""
    entry = {k: rec[k] for k in ("index", "ix", "iy", "x", "y", "label")}
    fields: dict = {"status": rec["status"], "reasons": tuple(rec["reasons"]),
                    "reduced_chi2": rec["reduced_chi2"], "p_value": rec["p_value"], "traces": rec["traces"]}
    for q in QUANTITY_UNITS:
        if rec[q] is not None:
            fields[q] = Measured(rec[q], rec[f"{q}_err"], note=rec[f"{q}_note"])
        elif q in rec["missing"]:
            fields[q] = Missing(rec["missing"][q])
        else:
            fields[q] = None
    if not rec["rms_fitted"]:
        fields["rms"] = None
    return entry, fields


# -- the journal -------------------------------------------------------------------------------------------
class JournalError(ValueError):
    """A journal that is not this map's: one line."""


class Journal:
    """The pixels a map has fitted, kept beside its output as it goes (``path``): a header line with the
    map's ``fingerprint``, then one pixel record a line, each round's flushed to disk before the next.  A
    line cut short by a kill is dropped when the journal is read."""

    def __init__(self, path: str, fingerprint: str):
        self.path, self.fingerprint = path, fingerprint

    def read(self) -> list[dict]:
        """The records kept (none where no journal exists); JournalError for one of another map or format."""
        if not os.path.exists(self.path):
            return []
        name = os.path.basename(self.path)
        with open(self.path, encoding="utf-8") as f:
            text = f.read()
        lines = text.split("\n")
        try:
            head = json.loads(lines[0])
        except ValueError:
            head = None
        if not isinstance(head, dict) or head.get("journal") != _JOURNAL_KIND:
            raise JournalError(f"'{name}' is not a map's journal; move it away")
        if head.get("format") != JOURNAL_FORMAT or head.get("fingerprint") != self.fingerprint:
            raise JournalError(f"'{name}' is the journal of another map (other source or options); remove it to "
                               f"fit this one from the start")
        records = {}
        for line in lines[1:-1]:          # the last piece has no newline: complete lines only
            try:
                rec = json.loads(line)
            except ValueError:
                continue
            if isinstance(rec, dict) and "index" in rec:
                records[rec["index"]] = rec
        return list(records.values())

    def start(self) -> None:
        """A journal with its header, where none exists; a torn last line cut off."""
        if not os.path.exists(self.path):
            self._write("w", [{"journal": _JOURNAL_KIND, "format": JOURNAL_FORMAT, "fingerprint": self.fingerprint,
                               "version": __version__}])
            return
        with open(self.path, "rb+") as f:
            data = f.read()
            keep = data.rfind(b"\n") + 1
            if keep < len(data):
                f.truncate(keep)

    def append(self, pixels) -> None:
        """Each pixel's record, on disk before this returns."""
        self._write("a", [pixel_record(p) for p in pixels])

    def _write(self, mode: str, records: list) -> None:
        with open(self.path, mode, encoding="utf-8") as f:
            f.writelines(json.dumps(r, allow_nan=False) + "\n" for r in records)
            f.flush()
            os.fsync(f.fileno())

    def remove(self) -> None:
        """The journal gone, once the map's files are in place."""
        if os.path.exists(self.path):
            os.remove(self.path)


# -- the files ---------------------------------------------------------------------------------------------
def _column(pixels, q: str, part: str) -> np.ndarray:
    out = np.full(len(pixels), np.nan)
    for i, p in enumerate(pixels):
        v = getattr(p, q)
        if isinstance(v, Measured):
            x = v.value if part == "value" else v.err
            out[i] = np.nan if x is None else x
    return out


def map_tree(result, options: dict, head: dict) -> dict:
    """The HDF5 tree of a map (see docs/maps.md for every name): attributes, ``pixels`` (a column per field),
    ``images`` (a (ny, nx) array per quantity, NaN where no curve lies or its fit does not hold) and ``fit``
    (what was fitted and given)."""
    px = result.pixels
    g = result.grid
    cols: dict = {
        "index": np.array([p.entry.index for p in px], dtype=np.int64),
        "ix": np.array([p.entry.ix for p in px], dtype=np.int64),
        "iy": np.array([p.entry.iy for p in px], dtype=np.int64),
        "x": np.array([np.nan if p.entry.x is None else p.entry.x for p in px]),
        "y": np.array([np.nan if p.entry.y is None else p.entry.y for p in px]),
        "label": [p.entry.label for p in px],
        "status": [p.status for p in px],
        "reasons": ["; ".join(p.reasons) for p in px],
        "reduced_chi2": np.array([np.nan if p.reduced_chi2 is None else p.reduced_chi2 for p in px]),
        "p_value": np.array([np.nan if p.p_value is None else p.p_value for p in px]),
        "traces": np.array([p.traces for p in px], dtype=np.int64),
    }
    for q in QUANTITY_UNITS:
        cols[q] = _column(px, q, "value")
        cols[f"{q}_err"] = _column(px, q, "err")
        cols[f"{q}_missing"] = [getattr(p, q).reason if isinstance(getattr(p, q), Missing) else "" for p in px]
    images = {q: result.image(q) for q in QUANTITY_UNITS}
    images["reduced_chi2"] = result.image("reduced_chi2")
    ch, b = result.choice, result.bodies
    fit = {"modulus": "fitted" if ch.modulus else "held", "roughness": "fitted" if ch.roughness else "held",
           "segment": ch.segment, "invols_scale": "fitted" if ch.invols_fitted else "held",
           "spring": "fitted" if ch.spring_err is not None else "held",
           "virtual_deflection": "fitted" if ch.virtual_deflection else "not in the model",
           "drag": "fitted" if ch.drag else "not in the model", "max_evaluations": ch.max_evaluations,
           "outside_domain": ch.outside_domain, "radius_m": b.R, "epsilon_m": b.epsilon,
           "spring_N_m": result.spring.k if result.spring is not None else "each curve's file's",
           "spring_source": result.spring.source if result.spring is not None else "the files"}
    attrs = {"kind": "map", "version": __version__, "source": result.source, "source_kind": result.kind,
             "grid_shape": list(g.shape), "grid_size_m": list(g.size) if g.size else "not stated by the source",
             "grid_origin_m": list(g.origin) if g.origin else "not stated by the source",
             "curves": len(px), "ranks": result.ranks, "resumed": result.resumed,
             **{f"n_{s}": result.count(s) for s in ("ok", "warned", "refused", "outside", "unreadable", "failed")}}
    return {"attrs": {**attrs, **{k: v for k, v in head.items() if isinstance(v, (str, int, float))}},
            "pixels": cols, "images": images, "fit": fit, "options": dict(options)}


def _attr(v):
    import h5py

    if isinstance(v, (list, tuple)) and v and all(isinstance(x, (int, float)) for x in v):
        return np.array(v)
    if isinstance(v, (list, tuple)):
        return np.array([str(x) for x in v], dtype=h5py.string_dtype())
    return "" if v is None else v


def write_map_h5(path: str, tree: dict) -> None:
    """The map's tree (:func:`map_tree`) as HDF5, with units and descriptions."""
    import h5py

    with h5py.File(path, "w") as f:
        for k, v in tree["attrs"].items():
            f.attrs[k] = _attr(v)
        f.attrs["description"] = "a force map fitted by petsc-adhesion -fit_map (docs/maps.md)"
        pix = f.create_group("pixels")
        pix.attrs["description"] = ("a row per curve of the source, in its order: its pixel (ix, iy) and position "
                                    "(x, y: m, NaN where the source states none), how its fit ended (status, "
                                    "reasons), each quantity with its bar (q, q_err: NaN where Missing, its "
                                    "reason in q_missing), reduced chi^2, p-value")
        for k, v in tree["pixels"].items():
            data = np.array(v, dtype=h5py.string_dtype()) if isinstance(v, list) else v
            d = pix.create_dataset(k, data=data)
            base = k[:-4] if k.endswith("_err") else k
            d.attrs["units"] = QUANTITY_UNITS[base][0] if base in QUANTITY_UNITS else \
                "m" if k in ("x", "y") else ""
        img = f.create_group("images")
        img.attrs["description"] = ("each quantity on the grid, shape (ny, nx): NaN where no curve lies, where it "
                                    "is Missing, and where its pixel's fit does not hold (status other than ok)")
        for k, v in tree["images"].items():
            d = img.create_dataset(k, data=v)
            d.attrs["units"] = QUANTITY_UNITS[k][0] if k in QUANTITY_UNITS else ""
            d.attrs["description"] = QUANTITY_UNITS[k][1] if k in QUANTITY_UNITS else "the fit's reduced chi^2"
        fit = f.create_group("fit")
        fit.attrs["description"] = "what each curve's fit fitted and held, and the constants given"
        for k, v in tree["fit"].items():
            fit.attrs[k] = _attr(v)
        opts = f.create_group("options")
        opts.attrs["description"] = "the run's options as given"
        for k, v in tree["options"].items():
            opts.attrs[k] = _attr(v)


#: The CSV table's columns (a row per curve; a Missing quantity's cells empty, its reason under missing).
CSV_COLUMNS = ["index", "ix", "iy", "x_m", "y_m", "status", *[c for q, (u, _) in QUANTITY_UNITS.items() for c in
               (f"{q}_{u.replace('/', '_').replace('^', '')}", f"{q}_err")], "reduced_chi2", "p_value", "reasons",
               "missing"]


def _cell(x) -> str:
    return "" if x is None or (isinstance(x, float) and not math.isfinite(x)) else repr(float(x))


def write_map_csv(path: str, result) -> None:
    """The map's table: a row per curve (columns :data:`CSV_COLUMNS`; SI; numbers as Python writes them, so
    that they read back exactly)."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(CSV_COLUMNS)
        for p in result.pixels:
            row = [p.entry.index, p.entry.ix, p.entry.iy, _cell(p.entry.x), _cell(p.entry.y), p.status]
            missing = []
            for q in QUANTITY_UNITS:
                v = getattr(p, q)
                row += [_cell(v.value), _cell(v.err)] if isinstance(v, Measured) else ["", ""]
                # a flagged pixel's reasons say why its fit is absent; what its curve shows by itself (the
                # jump-in, say) may be absent for a reason of its own, said here as for a fitted pixel
                if isinstance(v, Missing) and (p.fitted or v.reason not in ("; ".join(p.reasons), *p.reasons)):
                    missing.append(f"{q}: {v.reason}")
            row += [_cell(p.reduced_chi2), _cell(p.p_value), "; ".join(p.reasons), "; ".join(missing)]
            w.writerow(row)


def _median(result, q: str, scale: float) -> str:
    v = result.image(q)
    v = v[np.isfinite(v)]
    if not v.size:
        return "none"
    lo, mid, hi = np.percentile(v, [16, 50, 84]) / scale
    return f"{mid:.4g} (16-84%: {lo:.4g} to {hi:.4g})"


def report_map(result) -> None:
    """The console lines of a map: its curves by status, the median of each quantity over the pixels whose
    fit holds, and the first reason of each kind of flag."""
    n = len(result.pixels)
    counts = ", ".join(f"{result.count(s)} {s}" for s in ("ok", "warned", "refused", "outside", "unreadable",
                                                            "failed") if result.count(s))
    resumed = f", {result.resumed} from the journal" if result.resumed else ""
    tell(f"map: {n} curves on a {result.grid.shape[0]} x {result.grid.shape[1]} grid: {counts}{resumed}; "
         f"{result.ranks} rank{'s' * (result.ranks != 1)}, {result.wall_time_s:.3g} s")
    if result.count("ok"):
        tell(f"  w     [mJ/m^2] {_median(result, 'gamma', 1e-3)}")
        tell(f"  E*    [MPa]    {_median(result, 'E_star', 1e6)}")
        tell(f"  pull-off [nN]  {_median(result, 'pull_off', 1e-9)}")
        tell(f"  energy [aJ]    {_median(result, 'energy', 1e-18)}")
    seen = set()
    for p in result.pixels:
        if p.status != "ok" and p.status not in seen:
            seen.add(p.status)
            tell(f"  {p.status} (curve {p.entry.index}, pixel {p.entry.ix},{p.entry.iy}): {p.reasons[0][:300]}")
