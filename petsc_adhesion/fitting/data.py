"""Measured force-distance curves read from files: plain text or CSV, and the AFM formats afmformats reads.

A curve is the piezo (base) displacement z and the force F of one approach and
the retract that follows, in the order measured.  What is read:

plain text or CSV (any name; ``.csv``, ``.txt``, ``.tsv``, ``.dat`` ...)
    Two or more columns: the piezo displacement, then the force; further columns
    are ignored.  Columns are separated by commas, semicolons, tabs or blanks;
    lines starting with ``#`` and empty lines are skipped.  One header line may
    come first, naming the columns; a unit in parentheses or brackets after a
    name is honoured (displacement: m, mm, um, nm, pm; force: N, mN, uN, nN, pN),
    and a name without one is taken in SI, as are the columns of a file without a
    header.  The force is tensile (attractive) negative, as a cantilever's
    deflection towards the surface gives it.  The second column may instead be the
    cantilever's deflection, in a length unit (m, nm, ...: the force is the spring
    constant times it) or in volts (V, mV: times the sensitivity in m/V too); the
    spring constant and the sensitivity are then the caller's (``spring``,
    ``invols``), and a deflection without them is :class:`NeedsInstrument`.
an AFM file afmformats reads
    JPK (``.jpk-force``, ``.jpk-force-map``, ``.jpk-qi-data``, ``.jpk-qi-series``),
    Asylum Research / Igor (``.ibw``), AFM Workshop (``.csv``), NT-MDT (``.txt``),
    afmformats' own ``.h5`` and ``.tab``, and their ``.zip``: the column ``height
    (piezo)`` (else ``height (measured)``) and ``force``, with the spring constant
    (N/m) and the sensitivity (m/V) of the file's metadata when it states them.  A
    file of several curves (a force map) gives the one of ``index``.  A sensitivity
    ``invols`` given replaces the file's (its force rescaled by their ratio: the
    deflection is the measured voltage times it); a file that states no spring
    constant takes ``spring`` for its deflection column.  An AFM Workshop curve in
    volts (``T-B(V)``) whose header states no calibration, alone (``.csv``) or in
    the zip of a map (its first curve's header read for the map's), is read with
    ``invols`` and ``spring`` (afmformats' ``meta_override``), :class:`NeedsInstrument`
    without.

Approach and retract are split where the displacement turns: at its extreme
farthest from the first sample.  Either sign convention of the displacement is
taken: the approach is the direction in which it moves first.  Anything that is
no such curve (no number, one column, too few points, values that are not
finite, a curve that does not turn back) is one line (:class:`CurveFileError`).
"""
from __future__ import annotations

import contextlib
import io
import logging
import os
import re
import warnings
import zipfile
import zlib
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import printable as _printable

__all__ = ["CurveFileError", "NeedsInstrument", "MeasuredCurve", "VOLT_UNITS", "read_curve", "load_afm", "afm_curve",
           "workshop_header",
           "AFM_EXTENSIONS",
           "LENGTH_UNITS", "FORCE_UNITS",
           "MIN_POINTS", "MAX_TEXT_BYTES"]

#: The extensions afmformats reads (0.18): a file of these is read through it (``.csv`` and ``.txt`` only when
#: they are not plain columns of numbers).
AFM_EXTENSIONS = (".jpk-force", ".jpk-force-map", ".jpk-qi-data", ".jpk-qi-series", ".ibw", ".h5", ".tab", ".zip",
                  ".csv", ".txt")
#: Length and force units a text header may state, in SI.
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "\u00b5m": 1e-6, "\u03bcm": 1e-6, "nm": 1e-9, "pm": 1e-12}
#: Voltage units a text header may state for a deflection in volts, in V.
VOLT_UNITS = {"V": 1.0, "mV": 1e-3}
FORCE_UNITS = {"n": 1.0, "mn": 1e-3, "un": 1e-6, "\u00b5n": 1e-6, "\u03bcn": 1e-6, "nn": 1e-9, "pn": 1e-12}
#: The fewest points of each of approach and retract.
MIN_POINTS = 10
#: The largest text file read (a curve of 10^7 points).
MAX_TEXT_BYTES = 1 << 30
#: What an AFM measures, in SI: the piezo's travel over a curve (from a tenth of a nanometre to a millimetre;
#: scanners travel up to about 100 um) and the largest force (a femtonewton to 0.1 mN: a stiff lever of
#: 100 N/m bent by a micrometre), each with a decade or more to spare.  A column outside is in another unit
#: than its header (or SI, without one) says.
PLAUSIBLE_TRAVEL_M = (1e-10, 1e-3)
PLAUSIBLE_FORCE_N = (1e-15, 1e-4)
#: The travel and force of a typical curve: the unit said to be likely puts the column nearest these.
TYPICAL_TRAVEL_M, TYPICAL_FORCE_N = 1e-7, 1e-8


class CurveFileError(ValueError):
    """A file that holds no measured force curve; the message is one line, starting with the file's name."""


class NeedsInstrument(CurveFileError):
    """A file whose deflection needs what it does not state: ``option`` names the input (``fit_invols``: the
    sensitivity in m/V; ``phys_spring``: the spring constant in N/m); or, ``given``, a file that cannot take
    that input where it was given (a sensitivity for a force); the message is one line."""

    def __init__(self, message: str, option: str, given: bool = False):
        super().__init__(message)
        self.option, self.given = option, given


class _TextCurveError(CurveFileError):
    """A file read as text, columns of numbers, whose numbers cannot be the curve: not tried as an AFM file."""


@dataclass(frozen=True)
class MeasuredCurve:
    """A measured force-distance curve in SI: ``z`` the piezo (base) displacement (m) and ``F`` the force (N,
    tensile negative), in the order measured; ``turn`` the index of the first retract sample (``z[:turn]``
    the approach); ``direction`` +1 when z grows towards the surface, -1 when it falls; ``spring`` the
    cantilever's spring constant the file states (N/m, None when it states none); ``source`` what read it
    (``text`` or afmformats' format name) and ``metadata`` what the file says of itself (JSON-able)."""

    z: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    turn: int
    direction: int
    spring: float | None = None
    sensitivity: float | None = None
    source: str = "text"
    path: str = ""
    metadata: dict = field(default_factory=dict, repr=False)

    @property
    def approach(self) -> slice:
        return slice(0, self.turn)

    @property
    def retract(self) -> slice:
        return slice(self.turn, len(self.z))

    def rescaled(self, spring: float) -> MeasuredCurve:
        """The curve with the force of a cantilever of ``spring`` N/m instead of the file's (the force is the
        spring constant times the deflection, which the file measured)."""
        from dataclasses import replace

        factor = 1.0 if self.spring is None else spring / self.spring
        return replace(self, F=self.F * factor, spring=spring)


def _name(path: str) -> str:
    return f"'{os.path.basename(str(path))}'"


def read_curve(path: str, index: int = 0, spring: float | None = None, invols: float | None = None) -> MeasuredCurve:
    """The measured curve of ``path`` (see the module for what is read); ``index``: the curve of a file of
    several; ``spring`` (N/m) and ``invols`` (m/V): the cantilever's spring constant and the deflection's
    sensitivity where the caller knows them (a deflection column needs them).  Raises
    :class:`CurveFileError` with one line."""
    ext = os.path.splitext(str(path))[1].lower()
    ext = ".jpk-" + str(path).lower().rsplit(".jpk-", 1)[1] if ".jpk-" in str(path).lower() else ext
    text_error = None
    if ext not in AFM_EXTENSIONS or (ext in (".csv", ".txt") and workshop_header(path) is None):
        try:
            if index:
                raise CurveFileError(f"{_name(path)}: a text file holds one curve; index {index} asked for")
            return _read_text(path, spring, invols)
        except (_TextCurveError, NeedsInstrument):
            raise
        except CurveFileError as e:
            if ext not in AFM_EXTENSIONS:
                raise
            text_error = e
    try:
        return _read_afm(path, index, spring, invols)
    except CurveFileError as e:
        if text_error is not None:
            raise CurveFileError(f"{text_error}; nor is it a file afmformats reads ({str(e).split(': ', 1)[-1]})") \
                from None
        raise


# -- plain text -----------------------------------------------------------------
_SPLIT = re.compile(r"[,;\t ]+")
_UNIT = re.compile(r"[(\[]\s*([^)\]]*?)\s*[)\]]\s*$")
#: Fields of a decimal-comma file ("1,5;2,3", "1,5 2,3"), split on semicolons, tabs or blanks.
_SPLIT_DECIMAL_COMMA = re.compile(r"[;\t ]+")
_DECIMAL_COMMA = re.compile(r"[-+]?\d*,\d+(?:[eE][-+]?\d+)?|[-+]?\d+(?:[eE][-+]?\d+)?")


def _numbers(line: str, decimal_comma: bool = False) -> list[float] | None:
    try:
        if decimal_comma:               # a point in a file of decimal commas: a row written otherwise
            return None if "." in line else \
                [float(x.replace(",", ".")) for x in _SPLIT_DECIMAL_COMMA.split(line.strip()) if x]
        return [float(x) for x in _SPLIT.split(line.strip()) if x]
    except ValueError:
        return None


def _is_decimal_comma(line: str) -> bool:
    """Whether a line of numbers writes its decimals with commas: two or more fields apart by semicolons, tabs
    or blanks, each a number whose only separator is a comma inside it, one at least with such a comma, and no
    point anywhere ("1,5;2,3" or "1,5 2,3"; "1, 5" and "1,5" are comma-separated columns)."""
    if "." in line or "," not in line:
        return False
    fields = [x for x in _SPLIT_DECIMAL_COMMA.split(line.strip()) if x]
    return len(fields) >= 2 and all(_DECIMAL_COMMA.fullmatch(x) for x in fields) and any("," in x for x in fields)


def _unit(name: str, units: dict, what: str, column: int, path: str) -> float:
    m = _UNIT.search(name)
    if m is None:
        return 1.0
    unit = m.group(1).replace("\u00b5", "u").replace("\u03bc", "u")
    scale = units.get(unit.lower() if units is FORCE_UNITS else unit)
    if scale is None:
        raise CurveFileError(f"{_name(path)}: column {column} '{name.strip()}': '{m.group(1)}' is no {what} unit "
                             f"(expected one of {', '.join(u for u in units if u.isascii())})")
    return scale


#: How a force unit of FORCE_UNITS (kept in lower case) is written.
_FORCE_SHOWN = {"n": "N", "mn": "mN", "un": "uN", "nn": "nN", "pn": "pN"}


def _likely_unit(size: float, units: dict, typical: float, bounds: tuple) -> str | None:
    """The unit of ``units`` that puts ``size`` (the raw numbers' size) inside ``bounds`` and nearest
    ``typical``; None when none does."""
    fits = [(abs(np.log10(size * scale / typical)), u) for u, scale in units.items()
            if u.isascii() and bounds[0] <= size * scale <= bounds[1]]
    return min(fits)[1] if fits else None


def _plausible(raw: np.ndarray, scales: tuple, header: list | None, path: str) -> None:
    """Refuse a column whose values, in the unit the header states (SI without a header), no AFM measures: a
    piezo travel of metres or kilometres, forces of newtons (nm and nN numbers under an SI header), in one line
    naming the column and the unit its numbers are likely in."""
    with np.errstate(over="ignore", invalid="ignore"):
        sizes = (float(np.ptp(raw[:, 0])), float(np.max(np.abs(raw[:, 1]))))
    checks: tuple[tuple[str, str, tuple[float, float], float, dict[str, float], str, dict[str, str]], ...] = \
        (("the piezo travels", "an AFM's piezo travels", PLAUSIBLE_TRAVEL_M, TYPICAL_TRAVEL_M, LENGTH_UNITS,
          "m", {}),
         ("the largest force is", "an AFM measures", PLAUSIBLE_FORCE_N, TYPICAL_FORCE_N, FORCE_UNITS, "N",
          _FORCE_SHOWN))
    for i, (what, afm, bounds, typical, units, si, shown) in enumerate(checks):
        value = sizes[i] * scales[i]
        if sizes[i] == 0 or bounds[0] <= value <= bounds[1]:
            continue                    # a column that does not move is said by _curve
        likely = _likely_unit(sizes[i], units, typical, bounds) if np.isfinite(sizes[i]) else None
        hint = f"; its numbers are likely in {shown.get(likely, likely)}" if likely else ""
        value_text = f"{value:.3g} {si}" if np.isfinite(value) else "more than any float holds"
        column = f"column {i + 1} '{header[i].strip()}'" if header else f"column {i + 1} (no header: in {si})"
        fix = "correct the header's unit" if header else "give a header with the units, such as 'z (nm), F (nN)'"
        raise _TextCurveError(f"{_name(path)}: {column}: {what} {value_text}, where {afm} {bounds[0]:g} to "
                             f"{bounds[1]:g} {si}{hint}: {fix}")


def _deflection(header: list, path: str, spring: float | None, invols: float | None) -> tuple[float, str] | None:
    """(the factor from the second column to a force in N, what it is) where the header gives that column in
    volts or a length (a deflection), None for a force; NeedsInstrument where the factor needs the spring
    constant or the sensitivity and they are not given."""
    m = _UNIT.search(header[1])
    if m is None:
        return None
    unit = m.group(1).replace("\u00b5", "u").replace("\u03bc", "u")
    column = f"{_name(path)}: column 2 '{header[1].strip()}'"
    if unit in VOLT_UNITS:
        if invols is None:
            raise NeedsInstrument(f"{column} is a deflection in volts; the sensitivity (m/V) turns it into a "
                                  f"length", "fit_invols")
        if spring is None:
            raise NeedsInstrument(f"{column} is a deflection in volts; the spring constant (N/m) turns it into a "
                                  f"force", "phys_spring")
        return VOLT_UNITS[unit] * invols * spring, "volts"
    if unit in LENGTH_UNITS:
        if spring is None:
            raise NeedsInstrument(f"{column} is a deflection (a length); the spring constant (N/m) turns it into a "
                                  f"force", "phys_spring")
        return LENGTH_UNITS[unit] * spring, "deflection"
    return None


def _read_text(path: str, spring: float | None = None, invols: float | None = None) -> MeasuredCurve:
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_TEXT_BYTES + 1)
    except OSError as e:
        raise CurveFileError(f"{_name(path)}: cannot be read ({e.strerror})") from None
    if len(raw) > MAX_TEXT_BYTES:
        raise CurveFileError(f"{_name(path)}: more than {MAX_TEXT_BYTES >> 20} MiB of text")
    if b"\0" in raw[:4096]:
        raise CurveFileError(f"{_name(path)}: not text (a binary file)")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    rows: list[list[float]] = []
    header, scale_z, scale_F = None, 1.0, 1.0
    deflection = None
    decimal_comma = None                     # decided on the first row of numbers with a comma, then held
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if decimal_comma is None and "," in stripped:      # the first row of numbers with a comma decides
            if _is_decimal_comma(stripped):
                decimal_comma = True
            elif _numbers(stripped) is not None:
                decimal_comma = False
        values = _numbers(stripped, bool(decimal_comma))
        if values is None:
            if rows or header is not None:
                raise CurveFileError(f"{_name(path)}: line {number} is not numbers"
                                     f"{' with decimal commas, as the first row' if decimal_comma else ''}: "
                                     f"'{_printable(stripped[:60])}'")
            header = [h for h in re.split(r"\s*[,;\t]\s*", stripped)] if re.search(r"[,;\t]", stripped) \
                else stripped.split()
            if len(header) < 2:
                raise CurveFileError(f"{_name(path)}: the header '{_printable(stripped[:60])}' names one column; "
                                     f"expected the piezo displacement and the force")
            scale_z = _unit(header[0], LENGTH_UNITS, "length", 1, path)
            deflection = _deflection(header, path, spring, invols)
            scale_F = deflection[0] if deflection else _unit(header[1], FORCE_UNITS, "force", 2, path)
            continue
        if len(values) < 2:
            raise CurveFileError(f"{_name(path)}: line {number} has {len(values)} column; expected two: the piezo "
                                 f"displacement and the force")
        rows.append(values[:2])
    if not rows:
        raise CurveFileError(f"{_name(path)}: no rows of numbers")
    data = np.array(rows, dtype=float)
    with np.errstate(over="ignore"):         # a product beyond floats is said by _plausible
        curve = _curve(data[:, 0] * scale_z, data[:, 1] * scale_F, path, "text", None, None, {})
    # what is no curve in any unit (too few points, no turn, a constant force) is said first, by _curve
    _plausible(data, (scale_z, scale_F), header, path)
    if deflection is not None:
        curve = replace(curve, spring=spring, sensitivity=invols if deflection[1] == "volts" else None,
                        metadata={"deflection": deflection[1]})
    return curve


# -- afmformats ------------------------------------------------------------------
def workshop_header(path: str) -> dict | None:
    """The header of an AFM Workshop curve (``.csv``: a first line ``Force-Distance Curve``, then ``key:
    value`` lines, then the columns' names): its keys and values as written (``Mode``, ``Point``, ``X, um``,
    ``Y, um``, ...) and ``columns``; of a ``.zip`` (AFM Workshop's zipped map), its first curve's, by name as
    afmformats orders them; None for a file that is not one (or cannot be read)."""
    try:
        if str(path).lower().endswith(".zip"):
            with zipfile.ZipFile(path) as z:
                names = sorted(z.namelist())
                if not names:
                    return None
                with z.open(names[0]) as raw:
                    text = io.TextIOWrapper(raw, encoding="utf-8", errors="replace")
                    lines = [text.readline() for _ in range(64)]
        else:
            with open(path, encoding="utf-8", errors="replace") as f:
                lines = [f.readline() for _ in range(64)]       # the header is about a dozen lines
    except (OSError, EOFError, RuntimeError, NotImplementedError, zipfile.BadZipFile, zlib.error):
        return None     # (an encrypted member is RuntimeError, an unknown compression NotImplementedError)
    if not lines[0].strip().startswith("Force-Distance Curve"):
        return None
    head: dict = {}
    for line in lines[1:]:
        if line.count(",") >= 3:            # the columns' names, as afmformats finds them
            head["columns"] = [c.strip() for c in line.strip().split(",")]
            return head
        if ":" in line:
            key, value = line.split(":", 1)
            head[key.strip()] = value.strip()
    return None


def _workshop_override(path: str, spring_given: float | None, invols: float | None) -> dict | None:
    """What afmformats needs to read an AFM Workshop file whose deflection is in volts (``T-B(V)``, the
    photodiode's top-bottom signal), a curve or a zipped map: the sensitivity and the spring constant, the
    caller's where the header states none (AFM Workshop writes 1 for a value not set, and afmformats takes 1
    as none; without them its reader stops with its own 'Please specify ...')."""
    head = workshop_header(path) if str(path).lower().endswith((".csv", ".zip")) else None
    if head is None or not any("T-B(V)" in c for c in head["columns"]):
        return None
    stated = {k: head.get(k, "1") for k in ("Light Lever Gain, mV/nm", "Force Constant, nN/nm")}
    if all(_float(v) not in (None, 1.0) for v in stated.values()):
        return None                         # the file calibrates itself
    if invols is None:
        raise NeedsInstrument(f"{_name(path)}: its deflection is in volts (AFM Workshop's T-B(V)) and it states no "
                              f"sensitivity: give it in m/V", "fit_invols")
    if spring_given is None:
        raise NeedsInstrument(f"{_name(path)}: its deflection is in volts and it states no spring constant: give "
                              f"it in N/m", "phys_spring")
    return {"sensitivity": invols, "spring constant": spring_given}


def _float(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _read_afm(path: str, index: int, spring_given: float | None = None,
              invols: float | None = None) -> MeasuredCurve:
    curves = load_afm(path, spring_given, invols)
    if not 0 <= index < len(curves):
        raise CurveFileError(f"{_name(path)}: holds {len(curves)} curve{'s' * (len(curves) != 1)}; index {index} "
                             f"asked for")
    return afm_curve(curves[index], path, index, len(curves), spring_given, invols)


def load_afm(path: str, spring_given: float | None = None, invols: float | None = None) -> list:
    """The force-distance curves afmformats reads in ``path`` (its data objects, in the file's order; a force
    map's curves each once: a map is opened once, not once per curve), an AFM Workshop file in volts
    calibrated with ``spring_given`` (N/m) and ``invols`` (m/V) where its header states no calibration
    (NeedsInstrument without them); CurveFileError (one line) for a file it cannot read or one without a
    curve."""
    override = _workshop_override(path, spring_given, invols)
    try:
        import afmformats
    except ImportError:
        raise CurveFileError(f"{_name(path)}: reading this format needs afmformats (pip install afmformats, or "
                             f"./run setup)") from None
    # afmformats' own errors derive from BaseException, not Exception; a damaged file raises KeyError,
    # ValueError and the like from its readers
    own = tuple(getattr(afmformats.errors, n) for n in ("AFMFileFormatError", "MissingMetaDataError")
                if hasattr(getattr(afmformats, "errors", None), n))
    # afmformats logs each recipe that fails, with a traceback, and the readers beneath it (igor2) log what
    # they could not decode, raw bytes and all, through Python's last-resort handler: every logger is quiet
    # and anything printed is kept, while the file is read; one line is ours
    disabled = logging.root.manager.disable
    try:
        logging.disable(logging.CRITICAL)
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            warnings.simplefilter("ignore")
            curves = afmformats.load_data(str(path), modality="force-distance", meta_override=override)
    except (Exception, *own) as e:
        why = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise CurveFileError(f"{_name(path)}: not a force-distance curve afmformats reads "
                             f"({_printable(why)[:120]})") from None
    finally:
        logging.disable(disabled)
    if not curves:
        raise CurveFileError(f"{_name(path)}: afmformats finds no force-distance curve in it")
    return list(curves)


def afm_curve(d, path: str, index: int, count: int, spring_given: float | None = None,
              invols: float | None = None) -> MeasuredCurve:
    """The measured curve of afmformats' data object ``d``, curve ``index`` of the ``count`` of ``path``
    (:func:`load_afm`); ``spring_given`` and ``invols`` as :func:`read_curve`'s."""
    columns = list(d.columns)
    zcol = next((c for c in ("height (piezo)", "height (measured)") if c in columns), None)
    deflected = "force" not in columns and "deflection" in columns and spring_given is not None
    if zcol is None or ("force" not in columns and not deflected):
        missing = "force" if zcol else "height (piezo)"
        raise CurveFileError(f"{_name(path)}: no column '{missing}' (it has {', '.join(columns) or 'none'}); "
                             f"a force curve needs the piezo height and the force")
    meta = {}
    for k, v in dict(d.metadata).items():
        if isinstance(v, (str, int, float, bool)) and k != "path":
            meta[k] = v.item() if isinstance(v, np.generic) else v
    spring = meta.get("spring constant")
    sens = meta.get("sensitivity")
    spring = float(spring) if isinstance(spring, (int, float)) and np.isfinite(spring) and spring > 0 else None
    sens = float(sens) if isinstance(sens, (int, float)) and np.isfinite(sens) and sens > 0 else None
    source = str(meta.get("format", "afmformats"))
    if deflected:           # no force: the deflection (m) times the spring constant given
        assert spring_given is not None, "deflected only with a spring constant given"
        F, spring = np.asarray(d["deflection"], dtype=float) * spring_given, spring_given
    else:
        F = np.asarray(d["force"], dtype=float)
    if invols is not None:
        if sens is None:
            raise NeedsInstrument(f"{_name(path)}: gives a force, not a deflection in volts, and states no "
                                  f"sensitivity (m/V) for the one given to replace", "fit_invols", given=True)
        F, sens = F * (invols / sens), invols       # the deflection is the voltage times the sensitivity
    return _curve(np.asarray(d[zcol], dtype=float), F, path, source, spring, sens,
                  {**meta, "z_column": zcol, "curves_in_file": count, "index": index})


# -- the curve -------------------------------------------------------------------
def _curve(z: np.ndarray, F: np.ndarray, path: str, source: str, spring, sensitivity, meta: dict) -> MeasuredCurve:
    n = len(z)
    bad = n - int(np.count_nonzero(np.isfinite(z) & np.isfinite(F)))
    if bad:
        raise CurveFileError(f"{_name(path)}: {bad} of {n} points are not finite")
    if n < 2 * MIN_POINTS:
        raise CurveFileError(f"{_name(path)}: {n} points; a curve needs at least {2 * MIN_POINTS} (approach and "
                             f"retract)")
    far = int(np.argmax(np.abs(z - z[0])))
    if z[far] == z[0]:
        raise CurveFileError(f"{_name(path)}: the displacement does not move")
    direction = 1 if z[far] > z[0] else -1
    turn = int(np.argmax(direction * z)) + 1        # the first extreme: a dwell there belongs to the approach
    if turn < MIN_POINTS or n - turn < MIN_POINTS:
        which = "approach" if turn < MIN_POINTS else "retract"
        raise CurveFileError(f"{_name(path)}: the {which} has {min(turn, n - turn)} points (the displacement turns "
                             f"at point {turn} of {n}); a curve needs an approach and a retract of at least "
                             f"{MIN_POINTS} each, in the order measured")
    if np.ptp(F) == 0:
        raise CurveFileError(f"{_name(path)}: the force is constant")
    return MeasuredCurve(z=np.ascontiguousarray(z), F=np.ascontiguousarray(F), turn=turn, direction=direction,
                         spring=spring, sensitivity=sensitivity, source=source, path=str(path), metadata=meta)
