"""A measured topography (an AFM or profilometer file) as a value: its heights, pixel size, unit and statistics.

The files are read by SurfaceTopography (an optional extra, imported when a file is
read: it reads the instruments' own formats with their units and physical sizes).  A
:class:`Topography` holds the detrended heights in metres, the pixel size (None where
the file states no lateral size), the file's unit and the detrending, and its
:class:`Statistics`: rms, skewness and kurtosis with their sampling uncertainty.

**The sampling uncertainty.**  The pixels of a map are correlated, so the moments of N
pixels are known far worse than N independent samples would say.  For a Gaussian
field of autocorrelation rho the leading-order variances of the sample moments are
(the moments' influence functions are the Hermite polynomials H_2, H_3, H_4, whose
covariances are k! rho^k)

    var(rms) = rms^2 / (2 N_2),  var(skewness) = 6 / N_3,  var(kurtosis) = 24 / N_4,
    N_k = N^2 / sum_ij |rho_ij|^k,

the independent samples for each moment.  rho is the map's own autocorrelation (by FFT,
zero-padded: no periodicity assumed), summed over the lags within five correlation
lengths (where rho first falls below 1/e along either axis), beyond which the estimate
of rho is noise.  Exact to leading order for a Gaussian surface; for another an
estimate.  A surface correlated over its whole scan (no 1/e within half of it) gets
the sum over half the scan and a note: its uncertainty is then a lower bound.

**Choices.**  Undefined pixels (masked or NaN) are refused: filling them is a choice
about the surface the user makes (SurfaceTopography's ``interpolate_undefined_data``,
Gwyddion).  A line profile is accepted: its heights sample the same distribution as a
map of an isotropic surface, with fewer independent samples (its own autocorrelation,
in one dimension).  A file that states no length unit takes the user's (``unit``);
one that states no lateral size has its heights read and its size and correlation
length absent (the statistics counted in pixels).  Heights that the detrending leaves
within 1e-6 of the data's range (a plane, up to float32 rounding) are a flat surface:
zero, with no moments.

:func:`gap_heights` gives the heights of the gap between two surfaces: the sum of
their independent heights, whose distribution is the convolution of theirs.
"""
from __future__ import annotations

import contextlib
import io
import math
import os
from dataclasses import dataclass, field

import numpy as np

from .heights import HeightFileError

__all__ = ["Moment", "Statistics", "Topography", "TopographyError", "DETRENDS", "LENGTH_UNITS", "read_topography",
           "statistics", "gap_heights", "RANKS"]


class TopographyError(HeightFileError):
    """A topography file that gives no heights; the message is one line, starting with the file name."""


#: -adh_topography_detrend -> SurfaceTopography's detrend mode: the mean only, the least-squares plane (tilt is
#: mounting, not roughness), or the second-order polynomial (the curvature of a bent sample or a scanner's bow).
DETRENDS = {"none": "center", "plane": "height", "curvature": "curvature"}
#: Length units a user may state for a file that states none, in metres.
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "A": 1e-10, "pm": 1e-12}
#: The gap of two surfaces is convolved on a grid of 8 RANKS steps over the larger surface's range of heights.
RANKS = 1024
#: Lags within this many correlation lengths enter the sums of rho^k.
WINDOW = 5.0


@dataclass(frozen=True)
class Moment:
    """A sample moment and its standard uncertainty (None where it cannot be estimated)."""

    value: float
    err: float | None


@dataclass(frozen=True)
class Statistics:
    """The heights' moments with their sampling uncertainty.

    ``rms`` (metres), ``skewness``, ``kurtosis`` (3 for a Gaussian) as :class:`Moment`;
    ``correlation_length`` (pixels along each axis: where rho first falls below 1/e, interpolated),
    ``independent`` (N_2, N_3, N_4 of the module docstring); ``note``: why an uncertainty is a
    lower bound ('' when it is not); ``highest``, ``lowest``: the extreme heights from the mean (metres).
    """

    rms: Moment
    skewness: Moment
    kurtosis: Moment
    correlation_length: tuple
    independent: tuple
    highest: float
    lowest: float
    note: str = ""


@dataclass(frozen=True)
class Topography:
    """A measured topography: detrended heights in metres (a map, or a profile), and what the file said.

    ``pixel_size``: metres per pixel along each axis (None: the file states no lateral size);
    ``path``: the file as given; ``unit``: its length unit and ``unit_source`` ('file' or 'option');
    ``detrend``: a key of :data:`DETRENDS`; ``stats``: its :class:`Statistics`.
    """

    heights: np.ndarray = field(repr=False)
    pixel_size: tuple | None
    path: str
    unit: str
    unit_source: str
    detrend: str
    stats: Statistics

    @property
    def kind(self) -> str:
        """'map' or 'profile'."""
        return "map" if self.heights.ndim == 2 else "profile"

    @property
    def pixels(self) -> tuple:
        """The pixels along each axis."""
        return tuple(self.heights.shape)

    @property
    def size(self) -> tuple | None:
        """The physical size along each axis (metres), None where the file states none."""
        return None if self.pixel_size is None else tuple(n * p for n, p in zip(self.pixels, self.pixel_size))

    def local(self, center: tuple, radius: float) -> np.ndarray:
        """The heights (metres, from the whole map's mean plane) of the pixels within ``radius`` (metres) of
        ``center`` (metres from the first pixel, along each axis): a footprint's own heights.  ValueError without
        a pixel size, or when the disk leaves the scan."""
        if self.pixel_size is None:
            raise ValueError(f"{self.path}: the file states no lateral size: no footprint in metres")
        axes = [np.arange(n) * p for n, p in zip(self.pixels, self.pixel_size)]
        for c, a, p in zip(center, axes, self.pixel_size):
            if c - radius < a[0] - p / 2 or c + radius > a[-1] + p / 2:
                raise ValueError(f"the footprint of radius {radius:g} m at {center} leaves the scan")
        grids = np.meshgrid(*axes, indexing="ij")
        inside = sum((g - c) ** 2 for g, c in zip(grids, center)) <= radius * radius
        return self.heights[inside]


def _autocorrelation(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rho at every lag (FFT, zero-padded to twice the size: no periodicity) and the pairs at each lag."""
    shape = [2 * n for n in z.shape]
    f = np.fft.rfftn(z, shape)
    c = np.fft.irfftn(f * np.conj(f), shape)
    count = np.ones(shape)
    for axis, n in enumerate(z.shape):
        lag = np.abs(np.fft.fftfreq(2 * n, 1 / (2 * n)))
        shape1 = [1] * z.ndim
        shape1[axis] = 2 * n
        count = count * np.maximum(n - lag, 0).reshape(shape1)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.where(count > 0, c / np.where(count > 0, count, 1) / np.mean(z * z), 0.0)
    return rho, count


def statistics(z: np.ndarray) -> Statistics:
    """The moments of heights ``z`` (a map or a profile, any length unit) and their sampling uncertainty, from
    the heights' own autocorrelation (module docstring)."""
    z = np.asarray(z, dtype=float)
    z = z - z.mean()
    N = z.size
    var = float(np.mean(z * z))
    rms = math.sqrt(var)
    skew = float(np.mean(z ** 3)) / rms ** 3
    kurt = float(np.mean(z ** 4)) / var ** 2
    rho, count = _autocorrelation(z)
    # the correlation length along each axis: the first lag where rho < 1/e (half the scan where there is none)
    lengths, note = [], ""
    for axis, n in enumerate(z.shape):
        index = [0] * z.ndim
        line = []
        for lag in range(n // 2 + 1):
            index[axis] = lag
            line.append(rho[tuple(index)])
        below = np.nonzero(np.asarray(line) < math.exp(-1))[0]
        if below.size:              # interpolated between the last lag above 1/e and the first below
            i = int(below[0])
            lengths.append(i - 1 + (line[i - 1] - math.exp(-1)) / (line[i - 1] - line[i]))
        else:
            lengths.append(float(n // 2))
            note = ("the heights are correlated over more than half the scan: their uncertainties are lower "
                    "bounds (a longer scan would tell)")
    # lags within WINDOW correlation lengths (an ellipse in pixels), and not beyond half the scan
    inside = np.ones(rho.shape, dtype=bool)
    dist = np.zeros(rho.shape)
    for axis, n in enumerate(z.shape):
        lag = np.abs(np.fft.fftfreq(2 * n, 1 / (2 * n)))
        shape1 = [1] * z.ndim
        shape1[axis] = 2 * n
        dist = dist + (lag / max(lengths[axis], 1.0)).reshape(shape1) ** 2
        inside &= (lag <= n // 2).reshape(shape1)
    inside &= dist <= WINDOW ** 2
    sums = [float(np.sum(count[inside] * np.abs(rho[inside]) ** k)) for k in (2, 3, 4)]
    n2, n3, n4 = (min(float(N), N * N / s) for s in sums)
    return Statistics(rms=Moment(rms, rms / math.sqrt(2 * n2)), skewness=Moment(skew, math.sqrt(6 / n3)),
                      kurtosis=Moment(kurt, math.sqrt(24 / n4)), correlation_length=tuple(lengths),
                      independent=(n2, n3, n4), highest=float(z.max()), lowest=float(z.min()), note=note)


def read_topography(path: str, detrend: str = "plane", unit: str | None = None) -> Topography:
    """The topography of a file SurfaceTopography reads, detrended, in metres.

    Parameters
    ----------
    path
        The file (any of SurfaceTopography's formats: AFM images, profilometer maps, text with a header).
    detrend
        A key of :data:`DETRENDS`.
    unit
        A key of :data:`LENGTH_UNITS`, for a file that states no unit (refused for one that does).

    Raises
    ------
    TopographyError
        No SurfaceTopography, not a topography file, no height data, no unit, undefined pixels, a flat
        or non-uniform scan, a unit given for a file that states one; one line starting with the file name.
    """
    name = f"'{os.path.basename(str(path))}'"
    if detrend not in DETRENDS:
        raise ValueError(f"detrend must be one of {', '.join(DETRENDS)}, got {detrend!r}")
    if unit is not None and unit not in LENGTH_UNITS:
        raise ValueError(f"unit must be one of {', '.join(LENGTH_UNITS)}, got {unit!r}")
    try:
        import SurfaceTopography
    except ImportError:
        raise TopographyError(f"{name}: reading a topography needs the package SurfaceTopography (pip install "
                              "SurfaceTopography), not installed") from None
    if not os.path.isfile(path):
        raise TopographyError(f"{name}: no file")
    try:
        # some readers print to stdout and stderr as they try a file; the run's console is ours
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            reader = SurfaceTopography.open_topography(str(path))
    except Exception as e:           # SurfaceTopography raises its own and any reader's error: none is a topography
        why = "none of its readers recognises it" if type(e).__name__ == "CannotDetectFileFormat" else \
            (str(e).strip().splitlines() or [type(e).__name__])[0][:80]
        raise TopographyError(f"{name}: not a topography file SurfaceTopography reads ({why})") from None
    if not reader.channels:
        raise TopographyError(f"{name}: no height data (no channel)")
    channel = reader.default_channel
    if not all(int(n) > 0 for n in channel.nb_grid_pts):
        raise TopographyError(f"{name}: no height data ({' x '.join(map(str, channel.nb_grid_pts))} pixels)")
    stated = channel.unit
    if stated is not None and unit is not None:
        raise TopographyError(f"{name}: the file states its unit ({stated}), give none")
    if stated is None and unit is None:
        raise TopographyError(f"{name}: the file states no length unit: give the unit of its values "
                              f"({', '.join(LENGTH_UNITS)})")
    if stated is not None and stated not in _length_units():
        raise TopographyError(f"{name}: its unit '{stated}' is not a length")
    sizes = channel.physical_sizes
    try:
        # a file without a unit: read as stated in metres, and scaled by the user's unit below
        kw: dict[str, object] = {} if stated is not None else {"unit": "m"}
        if sizes is None:       # the heights are read all the same, the lateral size stays unknown
            kw["physical_sizes"] = tuple(float(n) for n in channel.nb_grid_pts)
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            topo = reader.topography(**kw)
    except Exception as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise TopographyError(f"{name}: its height data cannot be read ({first[:80]})") from None
    if not getattr(topo, "is_uniform", True):
        raise TopographyError(f"{name}: a line scan at non-uniform positions: its heights are not equally weighted "
                              "samples; resample it uniformly first")
    raw = topo.heights()
    undefined = int(np.ma.count_masked(raw)) if np.ma.isMaskedArray(raw) else 0
    data = np.ma.getdata(raw).astype(float)
    undefined = max(undefined, int(data.size - np.count_nonzero(np.isfinite(data))))
    if data.size == 0 or data.ndim not in (1, 2):
        raise TopographyError(f"{name}: no height data")
    if undefined:
        raise TopographyError(f"{name}: {undefined} of {data.size} pixels undefined (masked or NaN): fill or crop them "
                              "first (SurfaceTopography's interpolate_undefined_data, Gwyddion)")
    if min(data.shape) < 2 or data.size < 4:
        raise TopographyError(f"{name}: {data.size} heights: too few for a distribution")
    if np.ptp(data) == 0 and detrend == "none":
        flat = data - data.mean()
    else:
        with contextlib.redirect_stdout(io.StringIO()):
            flat = np.ma.getdata(topo.detrend(detrend_mode=DETRENDS[detrend]).heights()).astype(float)
    given = str(stated) if stated is not None else str(unit)
    scale = _length_units()[given] if stated is not None else LENGTH_UNITS[given]
    z = flat * scale
    z = z - z.mean()
    if np.ptp(z) <= 1e-6 * np.ptp(data) * scale:     # a plane (or curvature) up to float32 rounding: flat
        z = np.zeros_like(z)
    pixel = None if sizes is None else tuple(float(s) * scale / n for s, n in zip(sizes, data.shape))
    if not np.any(z):                 # a flat surface: moments undefined, the gap smooth
        zero = Moment(0.0, 0.0)
        stats = Statistics(zero, Moment(math.nan, None), Moment(math.nan, None), (math.nan,) * data.ndim,
                           (float(data.size),) * 3, 0.0, 0.0, "a flat surface: no roughness")
    else:
        stats = statistics(z)
    return Topography(z, pixel, str(path), given, "file" if stated is not None else "option", detrend, stats)


def _length_units() -> dict:
    """SurfaceTopography's length units (its names, e.g. µm and Å), in metres."""
    from SurfaceTopography.Support.UnitConversion import length_units
    return dict(length_units)


def _masses(z: np.ndarray, width: float) -> np.ndarray:
    """The fraction of heights z nearest to each of max(z) - k width, k = 0, 1, ... (highest first)."""
    k = np.rint((z.max() - z.ravel()) / width).astype(int)
    return np.bincount(k) / z.size


def gap_heights(surfaces: tuple, epsilon: float) -> tuple:
    """The heights (units of epsilon) whose distribution is the gap's between the surfaces, and their weights
    (None: equal).

    One surface: its heights.  Two: the heights of each measured outwards from its body,
    the gap closes by their sum, and independent surfaces' sum has the convolution of their
    distributions.  Each surface's heights are gathered onto a common grid of
    :data:`RANKS` x 8 steps over the larger range, aligned on its highest height, and the
    masses convolved: the gap's distribution on points, its highest point the sum of the
    two highest exactly, its moments those of the sum to the grid's rounding (variance
    and third cumulant add to 1e-4 relative; tests/test_topography.py).
    """
    if not surfaces or len(surfaces) > 2:
        raise ValueError(f"one or two surfaces, got {len(surfaces)}")
    if len(surfaces) == 1:
        return surfaces[0].heights.ravel() / epsilon, None
    a, b = (t.heights for t in surfaces)
    width = max(np.ptp(a), np.ptp(b)) / (8 * RANKS)
    if width == 0:                    # two flat surfaces: a flat gap
        return np.zeros(1), None
    mass = np.convolve(_masses(a, width), _masses(b, width))
    S = (a.max() + b.max() - width * np.arange(mass.size)) / epsilon
    keep = mass > 0
    return S[keep], mass[keep]
