"""Where a force map's curves come from, and where each lies on the sample: a map file afmformats reads (JPK
``.jpk-force-map`` and ``.jpk-qi-data``, AFM Workshop's ``.zip``; an Asylum ``.ARDF`` is refused, with
what to do), a folder of single-curve
files (an instrument's folder of a map's curves placed by their names or headers: maps/folders.py), or a
list file of paths.

A map file's curves carry their place on the scan grid in afmformats' metadata: ``grid index x`` and
``grid index y`` (the pixel), ``grid shape x`` and ``grid shape y`` (the grid's pixels), ``grid size x`` and
``grid size y`` (its extent, m) and ``position x``, ``position y`` (the curve's place, m).  A file whose curves
state none of it is a row of pixels in the file's order.  A folder's curves are its files in the order of
their names, a list file's its lines (a path, relative to the list's folder, then optionally the pixel's
indices ``ix iy``; ``#`` comments); both lie in a row unless a grid ``shape`` is given (nx, ny: the curves fill
it row by row, x fastest), or, for a folder, the instrument's names or headers place them (Asylum's
``LineNNNNPointNNNN.ibw`` and notes, AFM Workshop's mapping headers: maps/folders.py, which also refuses a
folder of two instruments or two grids).

The source is opened once per rank; :meth:`MapSource.curve` reads one curve, raising
:class:`~petsc_adhesion.fitting.data.CurveFileError` (one line) for one that cannot be read: the map flags
that pixel and goes on.
"""
from __future__ import annotations

import math
import os
import stat
from dataclasses import dataclass, field

from ..fitting.data import AFM_EXTENSIONS, CurveFileError, MeasuredCurve, NeedsInstrument, afm_curve, load_afm, \
    read_curve
from .folders import ARDF_REFUSAL, Layout, LayoutError, list_folder, place_folder

__all__ = ["MapSourceError", "ShapeError", "MapEntry", "Grid", "MapSource", "open_map", "curves_map", "READ_ERRORS"]

#: What afmformats' readers raise on a damaged curve inside a map whose index it read (its data are read
#: when first asked for): the curve is flagged, the map goes on.
READ_ERRORS = (CurveFileError, KeyError, ValueError, IndexError, TypeError, OSError, EOFError)


class MapSourceError(ValueError):
    """A map source that cannot be read at all: one line, naming the source."""


class ShapeError(MapSourceError):
    """A grid shape given that the source cannot take (too few pixels for its curves, or a source that places
    its curves itself): the shape is at fault, not the source (the command line names -fit_map_shape)."""


@dataclass(frozen=True)
class MapEntry:
    """One curve of a map: ``index`` its number in the source (0, 1, ...), ``ix``, ``iy`` its pixel, ``x``,
    ``y`` its position on the sample (m; None where the source states none), ``label`` where it comes from
    (the file, and the curve's number in it)."""

    index: int
    ix: int
    iy: int
    x: float | None = None
    y: float | None = None
    label: str = ""


@dataclass(frozen=True)
class Grid:
    """The scan grid: ``shape`` (nx, ny) pixels, ``size`` (m, the extent in x and y; None where the source
    states none), ``origin`` the position of pixel (0, 0) (m; None likewise)."""

    shape: tuple
    size: tuple | None = None
    origin: tuple | None = None

    @property
    def pixel(self) -> tuple | None:
        """The pixel's size in x and y (m), None without a size."""
        if self.size is None:
            return None
        return (self.size[0] / self.shape[0], self.size[1] / self.shape[1])


@dataclass
class MapSource:
    """An opened map: its ``path``, ``kind`` (afm, folder, list, curves), ``grid`` and ``entries``; the
    curves read on demand by :meth:`curve`."""

    path: str
    kind: str
    grid: Grid
    entries: tuple
    _afm: list | None = field(default=None, repr=False)
    _files: tuple = field(default=(), repr=False)
    _curves: tuple = field(default=(), repr=False)
    _missing: dict = field(default_factory=dict, repr=False)     # index: the instrument whose grid has it

    def __len__(self) -> int:
        return len(self.entries)

    @property
    def files(self) -> tuple:
        """The files the map reads: its map file, or its curves' files (none for curves given as values)."""
        if self.kind == "afm":
            return (self.path,)
        return tuple(f for i, f in enumerate(self._files) if i not in self._missing)

    def curve(self, entry: MapEntry, spring: float | None = None, invols: float | None = None) -> MeasuredCurve:
        """The measured curve of ``entry`` (SI); ``spring``, ``invols`` as
        :func:`~petsc_adhesion.fitting.data.read_curve`'s.  CurveFileError (one line) where it cannot be read."""
        if self.kind == "curves":
            return self._curves[entry.index]
        if self.kind == "afm":
            assert self._afm is not None, "an afmformats map holds its curves"
            try:
                return afm_curve(self._afm[entry.index], self.path, entry.index, len(self._afm), spring, invols)
            except CurveFileError:
                raise
            except READ_ERRORS as e:        # a curve damaged inside the file: afmformats reads it only now
                raise CurveFileError(f"'{os.path.basename(self.path)}' curve {entry.index}: cannot be read "
                                     f"({type(e).__name__}: {str(e).splitlines()[0][:100] if str(e) else ''})") \
                    from None
        path = self._files[entry.index]
        if entry.index in self._missing:
            g = self.grid.shape
            raise CurveFileError(f"'{entry.label}': missing: the {self._missing[entry.index]} map's grid of {g[0]} x "
                                 f"{g[1]} has pixel ({entry.ix}, {entry.iy}), the folder no curve for it")
        try:
            regular = stat.S_ISREG(os.stat(path).st_mode)
        except OSError as e:
            raise CurveFileError(f"'{os.path.basename(path)}': cannot be read ({e.strerror})") from None
        if not regular:             # a FIFO or a device listed would block or never end: never opened
            raise CurveFileError(f"'{os.path.basename(path)}': not a regular file")
        return read_curve(path, 0, spring=spring, invols=invols)


def curves_map(curves, shape: tuple | None = None, name: str = "curves") -> MapSource:
    """A map of measured curves given as values (the Python API): in a row, or filling ``shape`` row by row."""
    curves = tuple(curves)
    if not curves:
        raise MapSourceError(f"{name}: no curve")
    if not all(isinstance(c, MeasuredCurve) for c in curves):
        raise MapSourceError(f"{name}: expected MeasuredCurve values")
    grid, cells = _row_grid(len(curves), shape, name)
    entries = tuple(MapEntry(i, ix, iy, label=f"curve {i}") for i, (ix, iy) in enumerate(cells))
    return MapSource(name, "curves", grid, entries, _curves=curves)


def _row_grid(n: int, shape: tuple | None, name: str) -> tuple[Grid, list]:
    """A grid of ``n`` curves: a row, or ``shape`` filled row by row (x fastest)."""
    if shape is None:
        return Grid((n, 1)), [(i, 0) for i in range(n)]
    nx, ny = shape
    if nx * ny < n:
        raise ShapeError(f"{name}: {n} curves do not fit the shape {nx} x {ny}: expected nx, ny with nx ny at "
                         f"least {n}")
    return Grid((nx, ny)), [(i % nx, i // nx) for i in range(n)]


def open_map(path: str, shape: tuple | None = None, spring: float | None = None,
             invols: float | None = None) -> MapSource:
    """The map of ``path``: a folder, a map file afmformats reads, or a list file (see the module), its curves
    filling the grid ``shape`` (nx, ny) row by row where they place nothing themselves.  A map file that
    afmformats reads only calibrated (AFM Workshop's zip in volts, its header stating no calibration) is read
    with ``spring`` (N/m) and ``invols`` (m/V), NeedsInstrument without them; the curves of any other source
    take them when read (:meth:`MapSource.curve`).  MapSourceError (one line) for a source that is no map;
    its ShapeError where ``shape`` is at fault."""
    base = os.path.basename(path.rstrip(os.sep)) or path
    if os.path.isdir(path):
        files = list_folder(path)
        if not files:
            raise MapSourceError(f"'{base}': a folder without a curve file")
        try:
            layout = place_folder(files, f"'{base}'")
        except LayoutError as e:
            raise MapSourceError(str(e)) from None
        if layout is not None:
            if shape is not None and tuple(shape) != layout.shape:
                raise ShapeError(f"'{base}': its {layout.instrument} curves state a grid of {layout.shape[0]} x "
                                 f"{layout.shape[1]} ({layout.shape_from}); the shape {shape[0]} x {shape[1]} "
                                 f"disagrees: leave it out")
            return _placed(path, layout)
        grid, cells = _row_grid(len(files), shape, f"'{base}'")
        entries = tuple(MapEntry(i, ix, iy, label=os.path.basename(f)) for i, (f, (ix, iy)) in
                        enumerate(zip(files, cells)))
        return MapSource(path, "folder", grid, entries, _files=tuple(files))
    if _is_list(path):
        return _open_list(path, shape)
    if path.lower().endswith(".ardf"):
        raise MapSourceError(f"'{base}': {ARDF_REFUSAL}")
    if not path.lower().endswith(AFM_EXTENSIONS):
        raise MapSourceError(f"'{base}': not a map: expected a folder of curves, a list file of paths (.list, "
                             f".lst) or a map file afmformats reads ({', '.join(AFM_EXTENSIONS[:4])}, ...)")
    if shape is not None:
        raise ShapeError(f"'{base}': a map file states its own grid; a shape is for a folder or a list: leave it "
                         f"out")
    try:
        curves = load_afm(path, spring, invols)
    except NeedsInstrument:
        raise                       # the caller's calibration is missing, not the source at fault
    except CurveFileError as e:
        raise MapSourceError(str(e)) from None
    entries, grid = _afm_grid(curves, base)
    return MapSource(path, "afm", grid, entries, _afm=curves)


def _placed(path: str, layout: Layout) -> MapSource:
    """The map of a folder whose files place their curves (maps/folders.py): every pixel of its grid, a
    missing curve's pixel flagged when read."""
    entries = tuple(MapEntry(i, p.ix, p.iy, p.x, p.y, os.path.basename(p.path))
                    for i, p in enumerate(layout.pixels))
    missing = {i: layout.instrument for i, p in enumerate(layout.pixels) if p.missing}
    return MapSource(path, "folder", Grid(layout.shape, layout.size, layout.origin), entries,
                     _files=tuple(p.path for p in layout.pixels), _missing=missing)


def _is_list(path: str) -> bool:
    return path.lower().endswith((".list", ".lst"))


def _open_list(path: str, shape: tuple | None) -> MapSource:
    base = os.path.basename(path)
    folder = os.path.dirname(os.path.abspath(path))
    try:
        with open(path, encoding="utf-8") as f:
            lines = [(n + 1, ln.split("#")[0].strip()) for n, ln in enumerate(f)]
    except (OSError, UnicodeDecodeError) as e:
        raise MapSourceError(f"'{base}': cannot be read as a list of paths ({type(e).__name__})") from None
    rows = [(n, ln.split()) for n, ln in lines if ln]
    if not rows:
        raise MapSourceError(f"'{base}': a list file without a path")
    placed = [len(r) == 3 for _, r in rows]
    if any(placed) and not all(placed):
        raise MapSourceError(f"'{base}': line {rows[placed.index(False)][0]}: every line a path and its pixel "
                             f"'ix iy', or none")
    files, cells = [], []
    for n, r in rows:
        if len(r) not in (1, 3):
            raise MapSourceError(f"'{base}': line {n}: expected a path, or a path and its pixel 'ix iy'")
        files.append(r[0] if os.path.isabs(r[0]) else os.path.join(folder, r[0]))
        if len(r) == 3:
            try:
                ix, iy = int(r[1]), int(r[2])
            except ValueError:
                raise MapSourceError(f"'{base}': line {n}: the pixel '{r[1]} {r[2]}' is not two whole numbers") \
                    from None
            if ix < 0 or iy < 0:
                raise MapSourceError(f"'{base}': line {n}: the pixel '{ix} {iy}' is negative")
            cells.append((ix, iy))
    if cells:
        if shape is not None:
            raise ShapeError(f"'{base}': its lines place the pixels; a shape is for a list without them: leave "
                             f"it out")
        if len(set(cells)) < len(cells):
            raise MapSourceError(f"'{base}': two lines name the same pixel")
        grid = Grid((max(c[0] for c in cells) + 1, max(c[1] for c in cells) + 1))
    else:
        grid, cells = _row_grid(len(files), shape, f"'{base}'")
    entries = tuple(MapEntry(i, ix, iy, label=os.path.basename(f)) for i, (f, (ix, iy)) in
                    enumerate(zip(files, cells)))
    return MapSource(path, "list", grid, entries, _files=tuple(files))


def _number(meta: dict, key: str):
    v = meta.get(key)
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) else None


def _afm_grid(curves: list, base: str) -> tuple[tuple, Grid]:
    """The entries and the grid of afmformats' curves (their metadata's grid index, shape, size, position)."""
    metas = []
    for i, d in enumerate(curves):
        try:
            metas.append(dict(d.metadata))
        except READ_ERRORS:         # its metadata damaged: the curve keeps its number, in a row of its own
            metas.append({})
    placed = all(_number(m, "grid index x") is not None and _number(m, "grid index y") is not None for m in metas)
    if not placed:
        grid, cells = _row_grid(len(curves), None, base)
        return tuple(MapEntry(i, ix, iy, label=f"{base} #{i}") for i, (ix, iy) in enumerate(cells)), grid
    m0 = metas[0]
    nx, ny = _number(m0, "grid shape x"), _number(m0, "grid shape y")
    cells = [(int(_number(m, "grid index x")), int(_number(m, "grid index y"))) for m in metas]
    nx = int(nx) if nx else max(c[0] for c in cells) + 1
    ny = int(ny) if ny else max(c[1] for c in cells) + 1
    sx, sy = _number(m0, "grid size x"), _number(m0, "grid size y")
    cx, cy = _number(m0, "grid center x"), _number(m0, "grid center y")
    size = (sx, sy) if sx and sy else None
    origin = None
    if size is not None and cx is not None and cy is not None:      # pixel (0, 0)'s centre
        origin = (cx - sx / 2 + sx / nx / 2, cy - sy / 2 + sy / ny / 2)
    if len(set(cells)) < len(cells):
        raise MapSourceError(f"'{base}': two curves state the same grid pixel")
    entries = tuple(MapEntry(i, ix, iy, _number(m, "position x"), _number(m, "position y"), f"{base} #{i}")
                    for i, ((ix, iy), m) in enumerate(zip(cells, metas)))
    return entries, Grid((nx, ny), size, origin)
