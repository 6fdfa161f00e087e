"""Measured roughness heights read from files: plain text tables, Gwyddion's .gsf and ASCII exports, .npy.

Heights come in metres (or a unit a header states), are levelled (the mean plane
removed) and returned in units of epsilon; anything that gives no distribution (no
heights, values that are not finite, all equal) is one line (:class:`HeightFileError`).
"""
from __future__ import annotations

import math
import os

import numpy as np

__all__ = ["HeightFileError", "read_heights"]


class HeightFileError(ValueError):
    """Heights that give no distribution; the message is one line."""


def _check(S: np.ndarray, what: str) -> None:
    if S.size == 0:
        raise HeightFileError(f"{what}: no heights")
    bad = S.size - np.count_nonzero(np.isfinite(S))
    if bad:
        raise HeightFileError(f"{what}: {bad} of {S.size} heights are not finite")
    if S.size < 2 or S.min() == S.max():
        raise HeightFileError(f"{what}: all heights are equal, no roughness")
    with np.errstate(over="ignore", invalid="ignore"):
        spread = float(S.max() - S.min()) + float(np.sqrt(np.mean((S - np.mean(S)) ** 2)))
    if not np.isfinite(spread):
        raise HeightFileError(f"{what}: heights from {S.min():.3g} to {S.max():.3g}: their spread overflows double "
                              f"precision")


#: Length units accepted from a file header, in metres.
_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "\u00b5m": 1e-6, "\u03bcm": 1e-6, "nm": 1e-9, "pm": 1e-12}


_GSF_MAGIC = b"Gwyddion Simple Field 1.0\n"


def read_heights(path: str, epsilon: float | None = None, unit: float | None = None) -> np.ndarray:
    """Heights in units of epsilon from a file: a list of heights or a topography map.

    Formats, by file name:

    ``*.gsf``
        Gwyddion Simple Field: little-endian float32 map after a ``name = value``
        header (``XRes``, ``YRes``, ``ZUnits``).  Gwyddion reads the instruments'
        own formats and writes this one, with its unit.
    ``*.npy``
        a NumPy array, 1-D (list) or 2-D (map): exact, no parsing, no unit.
    anything else
        whitespace-separated text, ``#`` comments: one value per line is a list, a
        rectangular table a map, as Gwyddion's "ASCII data matrix" export, whose
        ``# Value units: m`` header line gives the unit.

    A map is levelled by subtracting its least-squares plane (the mean plane of
    eq. 6; plane tilt is sample mounting, not roughness); a list is returned as read.

    Parameters
    ----------
    path
        The file.
    epsilon
        Equilibrium spacing in metres; needed when the heights have a length unit.
    unit
        Metres per stored value, for a file that states no unit.  With neither, the
        values are heights in units of epsilon.

    Raises
    ------
    HeightFileError
        Unreadable, empty, non-numeric, non-finite or flat data, or a length unit
        without epsilon; the one-line message starts with the file name.
    """
    name = f"'{os.path.basename(str(path))}'"
    try:
        if str(path).endswith(".gsf"):
            Z, stated = _read_gsf(path)
        elif str(path).endswith(".npy"):
            Z, stated = _read_npy(path), None
        else:
            Z, stated = _read_text(path)
    except HeightFileError as e:
        raise HeightFileError(f"{name}: {e}") from None
    except OSError as e:
        raise HeightFileError(f"{name}: cannot read: {e.strerror or e}") from None
    _check(Z, name)
    if stated is not None and unit is not None:
        raise HeightFileError(f"{name}: the file states its unit ({stated}), give none")
    scale = _UNITS[stated] if stated is not None else unit
    if scale is not None:
        if not (math.isfinite(scale) and scale > 0):
            raise HeightFileError(f"{name}: the unit must be a length > 0 in metres, got {scale:g}")
        if epsilon is None or not (math.isfinite(epsilon) and epsilon > 0):
            raise HeightFileError(f"{name}: heights in metres need epsilon (> 0, in metres) for units of epsilon")
        Z = Z * (scale / epsilon)
    if Z.ndim == 2:
        spread = np.ptp(Z)
        Z = _level(Z)
        if np.ptp(Z) <= 1e-6 * spread:  # a plane, up to float32 rounding
            raise HeightFileError(f"{name}: the map is a plane, no roughness")
    return Z.ravel()


def _level(Z: np.ndarray) -> np.ndarray:
    """Z minus its least-squares plane a + b i + c j; on a full grid the centred i and j are orthogonal."""
    i = np.arange(Z.shape[0]) - (Z.shape[0] - 1) / 2
    j = np.arange(Z.shape[1]) - (Z.shape[1] - 1) / 2
    bi = i @ Z.mean(axis=1) / (i @ i)
    bj = Z.mean(axis=0) @ j / (j @ j)
    return Z - Z.mean() - bi * i[:, None] - bj * j[None, :]


def _read_text(path: str) -> tuple[np.ndarray, str | None]:
    rows, stated = [], None
    with open(path, encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            line = line.strip()
            if line.startswith("#"):
                key, _, value = line[1:].partition(":")
                if key.strip().lower() == "value units":
                    stated = _length(value.strip())
                continue
            if not line:
                continue
            try:
                rows.append([float(x) for x in line.split()])
            except ValueError:
                bad = next(x for x in line.split() if not _number(x))
                raise HeightFileError(f"line {lineno}: '{bad[:20]}' is not a number") from None
            if len(rows[-1]) != len(rows[0]):
                raise HeightFileError(f"line {lineno} has {len(rows[-1])} values, the first row {len(rows[0])}")
    if not rows:
        raise HeightFileError("no heights")
    Z = np.array(rows)
    if Z.shape[1] == 1:
        return Z[:, 0], stated
    if Z.shape[0] < 2:
        raise HeightFileError("one row is no map; give one height per line")
    return Z, stated


def _number(x: str) -> bool:
    try:
        float(x)
    except ValueError:
        return False
    return True


def _length(text: str) -> str:
    if text not in _UNITS:
        raise HeightFileError(f"the value unit '{text}' is not a length ({', '.join(_UNITS)})")
    return text


def _read_npy(path: str) -> np.ndarray:
    try:
        Z = np.load(path, allow_pickle=False)
    except (ValueError, EOFError) as e:
        raise HeightFileError(f"not a NumPy array file ({str(e).splitlines()[0]})") from None
    if not isinstance(Z, np.ndarray):           # an .npz archive of several arrays
        Z.close()
        raise HeightFileError("is an .npz archive of several arrays, not one NumPy array (.npy)")
    if Z.ndim not in (1, 2) or Z.dtype.kind not in "iuf":
        raise HeightFileError(f"holds a {Z.ndim}-D {Z.dtype} array, not 1-D or 2-D real numbers")
    if Z.ndim == 2 and min(Z.shape) < 2:
        raise HeightFileError(f"a {Z.shape[0]} x {Z.shape[1]} map: need at least 2 x 2")
    return Z.astype(float)


def _read_gsf(path: str) -> tuple[np.ndarray, str | None]:
    with open(path, "rb") as f:
        raw = f.read()
    if not raw.startswith(_GSF_MAGIC):
        raise HeightFileError("not a Gwyddion Simple Field file (no magic line)")
    end = raw.find(b"\0", len(_GSF_MAGIC))
    if end < 0:
        raise HeightFileError("no NUL byte ends the header")
    header = {}
    for line in raw[len(_GSF_MAGIC):end].decode("utf-8", "replace").splitlines():
        key, eq, value = line.partition("=")
        if eq:
            header[key.strip()] = value.strip()
    try:
        nx, ny = int(header["XRes"]), int(header["YRes"])
    except (KeyError, ValueError):
        raise HeightFileError("XRes and YRes must be integers in the header") from None
    if nx < 2 or ny < 2:
        raise HeightFileError(f"a {ny} x {nx} map: need at least 2 x 2")
    start = end + 4 - end % 4  # 1 to 4 NULs align the data to 4 bytes
    if len(raw) - start != 4 * nx * ny:
        raise HeightFileError(f"{len(raw) - start} bytes of data for {ny} x {nx} float32 values")
    Z = np.frombuffer(raw, dtype="<f4", offset=start).reshape(ny, nx).astype(float)
    unit = header.get("ZUnits")
    return Z, (_length(unit) if unit else None)
