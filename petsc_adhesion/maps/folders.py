"""What an instrument's folder of single-curve files says of its map: each curve's pixel, the grid and the
positions, read from the files themselves (docs/maps.md, "What a map is read from").

Asylum Research (MFP-3D, Cypher)
    A force map saved as curves is a folder of Igor binary waves named by their place,
    ``<base>LineLLLLPointPPPP.ibw`` (the line the slow scan's index, the point the fast one's), directly in the
    folder or in a subfolder a line (``FMLineLLLL/``).  Each wave's note (``key: value`` lines) states the
    map: ``FMapScanPoints`` by ``FMapScanLines`` pixels over ``FastScanSize`` by ``SlowScanSize`` metres about
    ``XOffset``, ``YOffset``, turned by ``ScanAngle`` degrees, the slow scan downwards when ``FMapScanDown``
    is 1; and the curve's own place as the x and y sensors read it, ``XLVDT`` and ``YLVDT`` (m).  The pixel is
    the name's (point, line), the line counted from the top when the scan ran down, so that the grid's y
    grows with the row.  The note's counters (``FMapLineCounter``, ``FMapPointCounter``) are not used: they are
    the software's state when the file was written, and a lone curve carries the last map's (the MFP-3D curve
    of tests/data: line 32 of a map of 32 lines).  Names without a line and a point place nothing: the
    folder is then a row, or ``-fit_map_shape``, as any other.  An ``.ARDF`` file (the whole map in Asylum's
    own format) is read by no reader here: refused, with what to do.
AFM Workshop
    A map is a ``.csv`` a curve whose header says ``Mode: Mapping`` and the curve's place, ``X, um`` and ``Y,
    um``.  As afmformats makes a grid of them, the columns and rows are the distinct positions; here they are
    placed on the finest spacing so that a missing column or row stays a gap, and a grid's pixel without a
    curve is flagged.  Curves of ``Mode: Single`` place nothing (a row, or ``-fit_map_shape``).

A folder holds one instrument's curves of one map: two instruments, two maps' names or notes of two grids
are refused in one line (a grid shape given that disagrees with the one the files state is refused by
maps/source.py).  Every pixel of the grid is an entry; one without its file is read as missing and flagged with
that reason.
"""
from __future__ import annotations

import math
import os
import re
import struct
from dataclasses import dataclass

from ..fitting.data import workshop_header

__all__ = ["Placed", "Layout", "instrument_of", "list_folder", "place_folder", "ibw_note", "ARDF_REFUSAL"]

#: An Asylum curve's name: its map's base, its line and its point.
_ASYLUM_NAME = re.compile(r"^(?P<base>.*?)Line(?P<line>\d+)Point(?P<point>\d+)\.ibw$", re.IGNORECASE)
#: A subfolder a line of an Asylum map.
_ASYLUM_LINE_DIR = re.compile(r"^FMLine\d+$", re.IGNORECASE)
#: The note's keys that state an Asylum map's grid: the same in every curve of one map.
_ASYLUM_GRID_KEYS = ("FMapScanPoints", "FMapScanLines", "FastScanSize", "SlowScanSize", "XOffset", "YOffset",
                     "ScanAngle", "FMapScanDown")
#: Why an ARDF file is refused, and what to do.
ARDF_REFUSAL = ("an Asylum ARDF force map, which afmformats does not read: export its curves as .ibw from the "
                "Asylum software (a folder of <name>LineNNNNPointNNNN.ibw) and give the folder")
#: The most pixels a grid made of positions may have a curve: beyond it the positions are on no grid.
_SPARSE = 16
#: How far a position may lie from its pixel's centre on a grid made of positions, in pixels: the positions a
#: file writes are its grid's to their printed digits.
_ON_GRID = 1e-3


class LayoutError(ValueError):
    """A folder that is no one map: one line."""


@dataclass(frozen=True)
class Placed:
    """A pixel of a map read from a folder: its ``path`` (the file, or the one expected where ``missing``),
    ``ix``, ``iy``, the position ``x``, ``y`` the file states (m; None where it states none)."""

    path: str
    ix: int
    iy: int
    x: float | None = None
    y: float | None = None
    missing: bool = False


@dataclass(frozen=True)
class Layout:
    """A folder's map: the ``instrument``, the grid's ``shape`` (nx, ny), ``size`` and ``origin`` (m, None
    where not stated), its ``pixels`` (in the order measured) and what in the files gave the shape
    (``shape_from``, for a refusal of another shape)."""

    instrument: str
    shape: tuple
    size: tuple | None
    origin: tuple | None
    pixels: tuple
    shape_from: str = ""


def list_folder(path: str) -> list:
    """The curve files of a folder, in the order of their names: its files, or those of its Asylum line
    subfolders (``FMLineNNNN``) where it holds only such subfolders."""
    names = sorted(f for f in os.listdir(path) if not f.startswith("."))
    files = [os.path.join(path, f) for f in names if os.path.isfile(os.path.join(path, f))]
    lines = [os.path.join(path, f) for f in names if _ASYLUM_LINE_DIR.match(f) and os.path.isdir(os.path.join(path, f))]
    if files or not lines:
        return files
    return [os.path.join(d, f) for d in lines for f in sorted(os.listdir(d))
            if not f.startswith(".") and os.path.isfile(os.path.join(d, f))]


def instrument_of(path: str) -> str:
    """Whose curve file ``path`` is, by its name and, for a ``.csv`` or ``.txt``, its first line."""
    low = path.lower()
    if low.endswith(".ardf"):
        return "Asylum ARDF"
    if low.endswith(".ibw"):
        return "Asylum"
    if ".jpk-" in os.path.basename(low):
        return "JPK"
    if low.endswith((".csv", ".txt")) and workshop_header(path) is not None:
        return "AFM Workshop"
    if low.endswith((".h5", ".tab", ".zip")):
        return "afmformats"
    return "text"


def place_folder(files: list, name: str) -> Layout | None:
    """The map of a folder's ``files`` (see the module); None where their instrument places nothing (the
    caller lays them in a row or on a shape given).  LayoutError (one line) for a folder that is no one map."""
    kinds: dict[str, list] = {}
    for f in files:
        kinds.setdefault(instrument_of(f), []).append(f)
    if len(kinds) > 1:
        said = ", ".join(f"{k} {len(v)} (e.g. '{os.path.basename(v[0])}')" for k, v in kinds.items())
        raise LayoutError(f"{name}: curves of more than one instrument ({said}); a map is one instrument's: give "
                          f"each its own folder")
    kind = next(iter(kinds))
    if kind == "Asylum ARDF":
        raise LayoutError(f"{name}: holds {ARDF_REFUSAL}")
    if kind == "Asylum":
        return _asylum(files, name)
    if kind == "AFM Workshop":
        return _workshop(files, name)
    return None


# -- Asylum ----------------------------------------------------------------------------------------------------
def ibw_note(path: str) -> dict:
    """The note of an Igor binary wave (version 5, as Asylum writes them), ``key: value`` lines as a dict of
    strings, read from the file's header and its note alone (the wave's data are skipped: a map's folder is
    read at once).  OSError or ValueError for a file that is none."""
    with open(path, "rb") as f:
        head = f.read(64)
        if len(head) < 64:
            raise ValueError("shorter than an Igor wave's header")
        order = next((o for o in "<>" if struct.unpack(o + "h", head[:2])[0] == 5), None)
        if order is None:
            raise ValueError("not an Igor binary wave of version 5")
        # BinHeader5: version, checksum, then wfmSize, formulaSize, noteSize (longs); the note follows the
        # wave (its header and data: wfmSize bytes) and the formula
        wfm, formula, note = struct.unpack(order + "3i", head[4:16])
        if min(wfm, formula, note) < 0:
            raise ValueError("a negative size in its header")
        f.seek(64 + wfm + formula)
        text = f.read(note)
    if len(text) < note:
        raise ValueError("its note is cut short")
    out: dict[str, str] = {}
    for line in text.decode("latin-1").split("\r"):
        if ":" in line:
            key, value = line.split(":", 1)
            out.setdefault(key.strip(), value.strip())      # a key written twice: its first value, as afmformats
    return out


def _real(note: dict, key: str) -> float | None:
    try:
        v = float(note.get(key, ""))
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def _asylum(files: list, name: str) -> Layout | None:
    matched = [(_ASYLUM_NAME.match(os.path.basename(f)), f) for f in files]
    if not any(m for m, _ in matched):
        return None
    unnamed = [f for m, f in matched if not m]
    if unnamed:
        raise LayoutError(f"{name}: '{os.path.basename(unnamed[0])}' is no curve of an Asylum map (its name has "
                          f"no LineNNNNPointNNNN) beside {len(files) - len(unnamed)} that are")
    named = [(m, f) for m, f in matched if m is not None]
    bases = sorted({m["base"] for m, _ in named})
    if len(bases) > 1:
        raise LayoutError(f"{name}: the curves of two Asylum maps ('{bases[0]}' and '{bases[1]}' before "
                          f"LineNNNNPointNNNN); give each its own folder")
    notes: dict[str, dict] = {}
    grid: tuple | None = None
    first = ""
    for m, f in named:
        try:
            note = ibw_note(f)
        except (OSError, ValueError):
            continue                        # a damaged curve: the map flags it when it is read
        notes[f] = note
        g = tuple(note.get(k) for k in _ASYLUM_GRID_KEYS)
        if grid is None:
            grid, first = g, f
        elif g != grid:
            k = next(k for k, a, b in zip(_ASYLUM_GRID_KEYS, grid, g) if a != b)
            raise LayoutError(f"{name}: curves of two grids: '{os.path.basename(first)}' states {k} "
                              f"{grid[_ASYLUM_GRID_KEYS.index(k)]}, '{os.path.basename(f)}' "
                              f"{g[_ASYLUM_GRID_KEYS.index(k)]}")
    if grid is None:
        raise LayoutError(f"{name}: no curve's note can be read to state the map's grid")
    note = notes[first]
    nx, ny = _real(note, "FMapScanPoints"), _real(note, "FMapScanLines")
    if not nx or not ny or nx != int(nx) or ny != int(ny) or nx < 1 or ny < 1:
        raise LayoutError(f"{name}: the note of '{os.path.basename(first)}' states no map's grid (FMapScanPoints "
                          f"{note.get('FMapScanPoints')}, FMapScanLines {note.get('FMapScanLines')})")
    nx, ny = int(nx), int(ny)
    down = _real(note, "FMapScanDown") == 1
    cells: dict[tuple[int, int], str] = {}
    for m, f in named:
        point, line = int(m["point"]), int(m["line"])
        if point >= nx or line >= ny:
            raise LayoutError(f"{name}: '{os.path.basename(f)}' is at point {point} of line {line}, beyond the "
                              f"grid of {nx} x {ny} its note states")
        if (point, line) in cells:
            raise LayoutError(f"{name}: '{os.path.basename(cells[point, line])}' and '{os.path.basename(f)}' are "
                              f"at the same point {point} of line {line}")
        cells[point, line] = f
    sx, sy = _real(note, "FastScanSize"), _real(note, "SlowScanSize")
    cx, cy, angle = _real(note, "XOffset"), _real(note, "YOffset"), _real(note, "ScanAngle")
    size = (sx, sy) if sx and sy and sx > 0 and sy > 0 else None
    origin = None
    if size is not None and cx is not None and cy is not None and angle == 0:   # a turned grid: its own frame
        w, h = size
        origin = (cx - w / 2 + w / nx / 2, cy - h / 2 + h / ny / 2)
    # where a curve is missing, its name as the map's others are written (their digits and folder)
    f0 = named[0][1]
    m0 = named[0][0]
    width_l, width_p = len(m0["line"]), len(m0["point"])
    sub = os.path.basename(os.path.dirname(f0)) if _ASYLUM_LINE_DIR.match(os.path.basename(os.path.dirname(f0))) \
        else None
    top = os.path.dirname(os.path.dirname(f0)) if sub else os.path.dirname(f0)
    pixels = []
    for line in range(ny):
        for point in range(nx):
            iy = ny - 1 - line if down else line
            f = cells.get((point, line))
            if f is None:
                leaf = f"{bases[0]}Line{line:0{width_l}d}Point{point:0{width_p}d}.ibw"
                folder = os.path.join(top, f"FMLine{line:0{len(sub) - 6}d}") if sub else top
                pixels.append(Placed(os.path.join(folder, leaf), point, iy, missing=True))
                continue
            n = notes.get(f, {})
            pixels.append(Placed(f, point, iy, _real(n, "XLVDT"), _real(n, "YLVDT")))
    return Layout("Asylum", (nx, ny), size, origin, tuple(pixels), "their notes' FMapScanPoints, FMapScanLines")


# -- AFM Workshop -----------------------------------------------------------------------------------------------
def _axis(values: list, what: str, name: str) -> tuple[float, float, int, list]:
    """A grid's axis made of the positions: its first centre, its spacing (the finest between two distinct
    positions), its count of pixels and each position's index.  LayoutError for positions off such a grid."""
    distinct = sorted(set(values))
    if len(distinct) == 1:
        return distinct[0], 0.0, 1, [0] * len(values)
    step = min(b - a for a, b in zip(distinct, distinct[1:]))
    index = [round((v - distinct[0]) / step) for v in values]
    off = max(abs(v - distinct[0] - i * step) for v, i in zip(values, index))
    if off > _ON_GRID * step:
        raise LayoutError(f"{name}: the curves' {what} positions are on no grid (one lies {off / step:.2g} of a "
                          f"pixel of {step * 1e6:.6g} um off its place)")
    return distinct[0], step, max(index) + 1, index


def _workshop(files: list, name: str) -> Layout | None:
    heads = [(f, workshop_header(f) or {}) for f in files]
    modes = {h.get("Mode", "").lower() for _, h in heads}
    if "mapping" not in modes:
        return None
    if modes != {"mapping"}:
        single = next(f for f, h in heads if h.get("Mode", "").lower() != "mapping")
        raise LayoutError(f"{name}: '{os.path.basename(single)}' is no curve of a map (Mode: "
                          f"{dict(heads)[single].get('Mode', 'none')}) beside curves of Mode: Mapping")
    xs, ys = [], []
    for f, h in heads:
        try:
            xs.append(float(h["X, um"]) * 1e-6)
            ys.append(float(h["Y, um"]) * 1e-6)
        except (KeyError, ValueError):
            raise LayoutError(f"{name}: '{os.path.basename(f)}' states no position (X, um and Y, um) of its map's "
                              f"curve") from None
    x0, dx, nx, ix = _axis(xs, "x", name)
    y0, dy, ny, iy = _axis(ys, "y", name)
    if nx * ny > _SPARSE * len(files):     # positions a hair apart make a spacing of a hair: no scan's grid
        raise LayoutError(f"{name}: the curves' positions make a grid of {nx} x {ny} pixels for {len(files)} "
                          f"curves (spacings of {dx * 1e6:.3g} and {dy * 1e6:.3g} um): positions on no scan's grid")
    cells: dict[tuple, str] = {}
    for f, i, j in zip(files, ix, iy):
        if (i, j) in cells:
            raise LayoutError(f"{name}: '{os.path.basename(cells[i, j])}' and '{os.path.basename(f)}' state the "
                              f"same position")
        cells[i, j] = f
    at = dict(zip(files, zip(xs, ys)))
    pixels = []
    for j in range(ny):
        for i in range(nx):
            f = cells.get((i, j))
            if f is None:       # no file to name: the pixel's place stands in for it
                pixels.append(Placed(f"pixel {i},{j} at x {(x0 + i * dx) * 1e6:.6g} um, y {(y0 + j * dy) * 1e6:.6g} "
                                     f"um", i, j, missing=True))
            else:
                pixels.append(Placed(f, i, j, *at[f]))
    size = (nx * dx, ny * dy) if nx > 1 and ny > 1 else None
    return Layout("AFM Workshop", (nx, ny), size, (x0, y0) if size else None, tuple(pixels),
                  "their positions X, um and Y, um")
