"""The load-controlled pull-off F_po(mu, sigma) tabulated over the model's range and interpolated, with the
solver's bar at every node and the interpolation's error measured against the solver (docs/fitting.md).

In units of 2 pi R w the pull-off of a sphere under load control, the most tensile
load F_min of its curve F(lambda), is a function of two numbers under the default
roughness rule (the paper's 16-point Gauss-Hermite average, eq. 14): the Tabor
parameter mu (eq. 9) and sigma = rms / epsilon.  From the rigid sphere's -1
(Bradley; DMT's 2 pi R w, mu -> 0) to JKR's -3/4 (mu -> infinity) it moves by a
quarter in mu, and by orders of magnitude in sigma: the roughness's repulsion holds
the surfaces apart (at mu = 0.01, F_po = -0.92 at sigma = 0.1, -0.32 at 0.3,
-0.0035 at 3).  So the table interpolates

    y(ln mu, sigma) = ln |F_po|

by cubic Hermite interpolation, first along sigma for every node of mu, then along
ln mu, the slopes at the nodes by the modified Akima rule (:func:`makima_slopes`: each
from the four secants about it, so that the sharp bend of the pull-off at sigma 0.15 to
0.2, where the gap at its most tensile point moves fast (on the rigid sphere from 0.16
to 0.42 epsilon between them), does not ring into the cells beyond it, as a global
spline's does: measured on the rows up to mu = 1 with sigma nodes 0.05 apart there, the
largest error at the cells' centres 1.3e-2 against 1.6e-2, 2.8% of the pull-off against
4.4%; a node at 0.175 then took it to 4.1e-3), and F_po = -exp(y); lambda at the
pull-off likewise, as
lambda / (1 + mu) (it grows like mu towards JKR: lambda ~ -0.77 mu there).  A node
is one curve of the library's (:func:`~petsc_adhesion.tracing.trace.trace_curve`:
grids that follow the contact edge, the default rule) traced only until the load
rises back through ``F_STOP`` after its most tensile point, with the error bar of
the pull-off (its F_min located again on nested grids and extrapolated,
:mod:`~petsc_adhesion.tracing.error_bars`).  The interpolation's error is measured
at the centre of every cell (the midpoint in ln mu and sigma) against the solver
there and stored per cell; the error stated at a point is ``SAFETY`` times the
largest relative error of the cells about it (its own and their neighbours) times the
pull-off there, and a value's bar is that plus the largest solver bar at the corners of
its cell (lambda's: absolute errors).

The file: .npz with its format name and version, the program's version, the nodes,
their values, bars and costs, the error per cell; written all together or not at
all (a temporary file beside it, renamed over it).  The shipped one is
``family/pull_off.npz`` (``python -m petsc_adhesion.benchmarks.pull_off build``).
"""
from __future__ import annotations

import math
import os
import time
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from ..model.parameters import Model
from ..tracing.measured import Measured
from ..version import __version__
from .table import OutOfRange, load_npz, save_npz

__all__ = ["FORMAT", "FORMAT_VERSION", "F_STOP", "SAFETY", "DEFAULT_PATH", "OutOfRange", "PullOffTable",
           "NodeValue", "trace_pull_off", "table_model", "describes", "makima_slopes", "hermite", "INTERPOLANT"]

FORMAT = "petsc-adhesion pull-off table"
FORMAT_VERSION = 1
#: The load a node's curve is traced to: it stops when F rises back through it after the pull-off (the most
#: tensile load lies before it: at the nodes tested the same F_min as the default curve traced to F = 2, within
#: their bars).  At large mu it saves little: the JKR curve's load is back at 0 only at lambda = 1.95 mu.
F_STOP = 0.1
#: What the error stated about a point is of the largest measured at the cell centres about it (the error varies
#: within a cell; the curve family's measured 1.4 times at a third of a cell: docs/family.md).
SAFETY = 2.0
#: The interpolant: "hermite" (cubic Hermite with modified Akima slopes along sigma, then along ln mu: local,
#: exact at the nodes) or "spline" (scipy's bicubic interpolating spline: global, it rings off a sharp bend).
INTERPOLANT = "hermite"
#: The table shipped in the package.
DEFAULT_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "pull_off.npz")


def table_model(mu: float, sigma: float) -> Model:
    """The model a node stands for: the default roughness rule (16-point Gauss-Hermite), the half-infinite
    model on the grids that follow the edge."""
    return Model(mu=float(mu), sigma=float(sigma))


def describes(model: Model) -> bool:
    """Whether the table's model is ``model``'s but for mu and sigma: its roughness rule (any, when smooth) and
    its domain (the half-infinite model; r_m the default of the grids that follow the edge, or None)."""
    from ..tracing.trace import GridChoice

    ref = table_model(model.mu, model.sigma)
    rule = model.sigma == 0 or (model.roughness == ref.roughness and model.hermite_points == ref.hermite_points)
    return rule and model.farfield and model.rmax in (None, GridChoice().default_rmax)


@dataclass(frozen=True)
class NodeValue:
    """A node's pull-off as the solver gives it: F and lambda (Measured: best, bar, value on the grid), the
    CPU seconds it took, or ``failed`` the reason it could not be traced."""

    mu: float
    sigma: float
    F: Measured | None
    lam: Measured | None
    seconds: float
    failed: str | None = None


def trace_pull_off(mu: float, sigma: float, error_bars: bool = True, comm=None) -> NodeValue:
    """The pull-off of ``table_model(mu, sigma)``: its curve traced until F rises back through ``F_STOP``,
    its F_min located (and, with ``error_bars``, extrapolated over nested grids with its bar).  A curve that
    ends without one, or incomplete, is a NodeValue with ``failed`` its reason (collective on ``comm``)."""
    from ..discretization.problem import step_scale
    from ..tracing.trace import CurveRequest, curve_settings, trace_curve

    model = table_model(mu, sigma)
    t0 = time.process_time()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            c = trace_curve(model, settings=curve_settings(step_scale(model), observable_max=F_STOP),
                            request=CurveRequest(error_bars=error_bars, kinds=("F_min",)), comm=comm)
    except (ValueError, RuntimeError, FloatingPointError) as e:
        text = str(e).strip().splitlines()
        return NodeValue(mu, sigma, None, None, time.process_time() - t0, text[0] if text else type(e).__name__)
    sec = time.process_time() - t0
    if c.pull_off is None:
        return NodeValue(mu, sigma, None, None, sec, f"no pull-off ({c.diagnostics.stop_reason})")
    if not c.complete:
        return NodeValue(mu, sigma, None, None, sec, f"incomplete: {c.assessment.incomplete[0]}")
    return NodeValue(mu, sigma, c.pull_off.F, c.pull_off.lam, sec)


def _bar(m: Measured) -> float:
    return float(m.err) if m.err is not None else math.nan


def _grid(m: Measured) -> float:
    return float(m.grid if m.grid is not None else m.value)


def makima_slopes(x: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """The slopes dY/dx at the nodes ``x`` along the last axis of ``Y`` by the modified Akima rule (local: each
    from the four secants about it, weighted so that a sharp bend does not ring into the intervals beyond it;
    the secants continued linearly past the ends)."""
    m = np.diff(Y, axis=-1) / np.diff(x)
    first, last = m[..., :1], m[..., -1:]
    m = np.concatenate([3 * first - 2 * m[..., 1:2], 2 * first - m[..., 1:2], m,
                        2 * last - m[..., -2:-1], 3 * last - 2 * m[..., -2:-1]], axis=-1)
    dm = np.abs(np.diff(m, axis=-1))
    pm = np.abs(m[..., 1:] + m[..., :-1])
    w1 = dm[..., 2:] + 0.5 * pm[..., 2:]          # |m_{i+1} - m_i| + |m_{i+1} + m_i| / 2
    w2 = dm[..., :-2] + 0.5 * pm[..., :-2]        # |m_{i-1} - m_{i-2}| + |m_{i-1} + m_{i-2}| / 2
    a, b = m[..., 1:-2], m[..., 2:-1]             # m_{i-1}, m_i
    den = w1 + w2
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(den > 0, (w1 * a + w2 * b) / np.where(den > 0, den, 1.0), 0.5 * (a + b))
    return t


def hermite(x: np.ndarray, Y: np.ndarray, D: np.ndarray, xq: np.ndarray, derivative: bool = False,
            pointwise: bool = False) -> np.ndarray:
    """The cubic Hermite interpolant through (x, Y) with slopes D (along Y's last axis) at ``xq`` (clipped to
    [x_0, x_n]): of shape (xq, *Y's leading axes) or, ``pointwise``, Y of shape (len(xq), len(x)) read point
    by point (shape (len(xq),)); its derivative with ``derivative``."""
    xq = np.clip(np.asarray(xq, float), x[0], x[-1])
    i = np.clip(np.searchsorted(x, xq, side="right") - 1, 0, x.size - 2)
    h = x[i + 1] - x[i]
    t = (xq - x[i]) / h
    if pointwise:
        k = np.arange(xq.size)
        y0, y1, d0, d1 = Y[k, i], Y[k, i + 1], D[k, i], D[k, i + 1]
    else:
        y0, y1, d0, d1 = (np.moveaxis(A[..., j], -1, 0) for A, j in ((Y, i), (Y, i + 1), (D, i), (D, i + 1)))
        h, t = h.reshape(h.shape + (1,) * (Y.ndim - 1)), t.reshape(t.shape + (1,) * (Y.ndim - 1))
    if derivative:
        return (6 * t * t - 6 * t) * (y0 - y1) / h + (3 * t * t - 4 * t + 1) * d0 + (3 * t * t - 2 * t) * d1
    return (2 * t**3 - 3 * t**2 + 1) * y0 + (t**3 - 2 * t**2 + t) * h * d0 + (-2 * t**3 + 3 * t**2) * y1 + \
        (t**3 - t**2) * h * d1


@dataclass(frozen=True)
class PullOffTable:
    """The tabulated pull-off (module docstring): nodes ``mu`` (increasing, interpolated in ln mu) and ``sigma``
    (increasing, from 0); at each node (shape (mu, sigma)) ``F`` the best pull-off (units 2 pi R w), ``F_err``
    its solver bar (nan: none), ``F_grid`` its value on the grid, ``lam`` and ``lam_err`` the approach at it,
    ``seconds`` the node's CPU time; the error measured at the cells' centres (shape (mu - 1, sigma - 1)):
    ``cell_F``, ``cell_lam`` (|interpolated - solver|), ``cell_F_err`` the solver's bar there, ``cell_seconds``;
    empty until measured."""

    mu: np.ndarray
    sigma: np.ndarray
    F: np.ndarray = field(repr=False)
    F_err: np.ndarray = field(repr=False)
    F_grid: np.ndarray = field(repr=False)
    lam: np.ndarray = field(repr=False)
    lam_err: np.ndarray = field(repr=False)
    seconds: np.ndarray = field(repr=False)
    roughness: str = "hermite 16"
    F_stop: float = F_STOP
    version: str = __version__
    cell_F: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    cell_lam: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    cell_F_err: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    cell_seconds: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)

    def __post_init__(self):
        mu, sigma = np.asarray(self.mu, float), np.asarray(self.sigma, float)
        if mu.size < 4 or sigma.size < 4 or np.any(np.diff(mu) <= 0) or np.any(np.diff(sigma) <= 0) or mu[0] <= 0 \
                or sigma[0] < 0:
            raise ValueError("a pull-off table needs at least 4 increasing mu > 0 and 4 increasing sigma >= 0")
        if np.asarray(self.F).shape != (mu.size, sigma.size) or not np.all(np.asarray(self.F) < 0):
            raise ValueError("a pull-off table's F: one negative pull-off per node, shape (mu, sigma)")

    # -- the file ------------------------------------------------------------------------------------------
    _ARRAYS = ("mu", "sigma", "F", "F_err", "F_grid", "lam", "lam_err", "seconds", "cell_F", "cell_lam",
               "cell_F_err", "cell_seconds")

    def save(self, path: str) -> None:
        """Write the table to ``path`` (.npz), all or nothing: a temporary file beside it, renamed over it."""
        arrays = {k: np.asarray(getattr(self, k), float) for k in self._ARRAYS}
        arrays.update(format=np.array(FORMAT), format_version=np.array(FORMAT_VERSION),
                      program_version=np.array(self.version), roughness=np.array(self.roughness),
                      F_stop=np.array(self.F_stop))
        save_npz(path, arrays)

    @classmethod
    def load(cls, path: str) -> PullOffTable:
        """The table in ``path``; ValueError, one line, for a file that is no pull-off table of this version."""
        d = load_npz(path, "pull-off table", FORMAT, FORMAT_VERSION,
                     (*cls._ARRAYS, "roughness", "F_stop", "program_version"))
        try:
            return cls(**{k: d[k] for k in cls._ARRAYS}, roughness=str(d["roughness"]), F_stop=float(d["F_stop"]),
                       version=str(d["program_version"]))
        except (ValueError, TypeError) as e:      # the arrays there, but not a table's (the constructor's checks)
            raise ValueError(f"{path}: {e}") from None

    @classmethod
    def default(cls) -> PullOffTable:
        """The table shipped in the package (``DEFAULT_PATH``), read once per process."""
        global _DEFAULT
        if _DEFAULT is None:
            if not os.path.exists(DEFAULT_PATH):
                raise FileNotFoundError(f"{DEFAULT_PATH}: the package's pull-off table is missing (build it: "
                                        f"python -m petsc_adhesion.benchmarks.pull_off build)")
            _DEFAULT = cls.load(DEFAULT_PATH)
        return _DEFAULT

    # -- the range -------------------------------------------------------------------------------------------
    @property
    def measured(self) -> bool:
        """Whether the interpolation error was measured at the cells' centres."""
        return self.cell_F.size > 0

    def covers(self, mu, sigma) -> np.ndarray:
        """Whether each (mu, sigma) (broadcast) lies in the table: finite, mu in [mu_0, mu_n], sigma in
        [sigma_0, sigma_n]."""
        mu, sigma = np.broadcast_arrays(np.asarray(mu, float), np.asarray(sigma, float))
        with np.errstate(invalid="ignore"):
            return np.isfinite(mu) & np.isfinite(sigma) & (mu >= self.mu[0] * (1 - 1e-12)) & \
                (mu <= self.mu[-1] * (1 + 1e-12)) & (sigma >= self.sigma[0] - 1e-12) & \
                (sigma <= self.sigma[-1] + 1e-12)

    def _checked(self, mu, sigma) -> tuple[np.ndarray, np.ndarray]:
        """(ln mu, sigma) broadcast and clipped onto the nodes; OutOfRange (one line) naming the first point
        the table does not hold."""
        mu, sigma = np.broadcast_arrays(np.asarray(mu, float), np.asarray(sigma, float))
        inside = self.covers(mu, sigma)
        if not np.all(inside):
            k = int(np.flatnonzero(~inside.ravel())[0])
            m, s = float(mu.ravel()[k]), float(sigma.ravel()[k])
            raise OutOfRange(f"(mu, sigma) = ({m:g}, {s:g}): the pull-off table holds mu in [{self.mu[0]:g}, "
                             f"{self.mu[-1]:g}] and sigma in [{self.sigma[0]:g}, {self.sigma[-1]:g}]")
        lm = np.clip(np.log(mu), math.log(self.mu[0]), math.log(self.mu[-1]))
        return lm, np.clip(sigma, self.sigma[0], self.sigma[-1])

    # -- the interpolants ---------------------------------------------------------------------------------
    def _values(self, name: str) -> np.ndarray:
        """What is interpolated: ln|F| or lambda / (1 + mu), at the nodes (mu, sigma)."""
        return np.log(-self.F) if name == "F" else self.lam / (1.0 + self.mu[:, None])

    def _eval(self, name: str, lm: np.ndarray, s: np.ndarray, dx: bool = False) -> np.ndarray:
        """The interpolant of ``name`` (or its derivative in ln mu) at (ln mu, sigma) (module docstring)."""
        if INTERPOLANT == "spline":
            cache = self.__dict__.setdefault("_splines", {})
            if name not in cache:
                from scipy.interpolate import RectBivariateSpline

                cache[name] = RectBivariateSpline(np.log(self.mu), self.sigma, self._values(name), kx=3, ky=3, s=0)
            return cache[name].ev(lm, s, dx=int(dx))
        Y = self._values(name)
        shape = np.shape(lm)
        lm, s = np.ravel(lm), np.ravel(s)
        # along sigma, every row of mu at each point's sigma: (points, mu)
        rows = hermite(self.sigma, Y, makima_slopes(self.sigma, Y), s)
        x = np.log(self.mu)
        out = hermite(x, rows, makima_slopes(x, rows), lm, derivative=dx, pointwise=True)
        return out.reshape(shape)

    def interpolated(self, mu, sigma) -> tuple[np.ndarray, np.ndarray]:
        """(F, lambda) of the interpolants at (mu, sigma) (broadcast; OutOfRange outside), without bars."""
        lm, s = self._checked(mu, sigma)
        F = -np.exp(self._eval("F", lm, s))
        lam = self._eval("lam", lm, s) * (1.0 + np.exp(lm))
        return F, lam

    def ln_pull_off(self, mu, sigma) -> np.ndarray:
        """ln |F_po| of the interpolant at (mu, sigma) (broadcast; OutOfRange outside), without bars: what an
        inversion evaluates."""
        lm, s = self._checked(mu, sigma)
        return self._eval("F", lm, s)

    def slope(self, mu, sigma) -> np.ndarray:
        """d ln|F_po| / d ln mu at (mu, sigma) (broadcast; OutOfRange outside): the interpolant's."""
        lm, s = self._checked(mu, sigma)
        return self._eval("F", lm, s, dx=True)

    def pull_off(self, mu, sigma) -> tuple[np.ndarray, np.ndarray]:
        """(F, err) at (mu, sigma), numpy arrays of their broadcast shape, units 2 pi R w: the interpolated
        pull-off and its bar, the largest solver bar at the corners of its cell plus the interpolation error
        (``SAFETY`` times the largest relative error measured at the centres of its cell and their neighbours,
        times |F|: the pull-off spans three decades in sigma; inf on a table whose error was not measured).
        OutOfRange (one line) outside the table."""
        lm, s = self._checked(mu, sigma)
        F = -np.exp(self._eval("F", lm, s))
        return F, self._node_bar(lm, s, self.F_err) + self._cell_error(lm, s, "cell_F") * np.abs(F)

    def pull_off_lambda(self, mu, sigma) -> tuple[np.ndarray, np.ndarray]:
        """(lambda, err) at the pull-off, as :meth:`pull_off` (the approach in epsilon)."""
        lm, s = self._checked(mu, sigma)
        lam = self._eval("lam", lm, s) * (1.0 + np.exp(lm))
        return lam, self._node_bar(lm, s, self.lam_err) + self._cell_error(lm, s, "cell_lam")

    def _cells(self, lm: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The cell (i, j) each point lies in: nodes i, i + 1 in mu and j, j + 1 in sigma."""
        i = np.clip(np.searchsorted(np.log(self.mu), lm, side="right") - 1, 0, self.mu.size - 2)
        j = np.clip(np.searchsorted(self.sigma, s, side="right") - 1, 0, self.sigma.size - 2)
        return i, j

    def _node_bar(self, lm, s, bars: np.ndarray) -> np.ndarray:
        """The largest of ``bars`` at the four corners of each point's cell (inf where a corner has none)."""
        i, j = self._cells(lm, s)
        b = np.where(np.isfinite(bars), bars, np.inf)
        return np.maximum.reduce([b[i, j], b[i + 1, j], b[i, j + 1], b[i + 1, j + 1]])

    def _cell_error(self, lm, s, name: str) -> np.ndarray:
        """SAFETY times the largest error ``name`` measured at the centres of each point's cell and its
        neighbours; inf where the table's error was not measured."""
        if not self.measured:
            return np.full(np.shape(lm), np.inf)
        cache = self.__dict__.setdefault("_near", {})
        if name not in cache:
            e = np.asarray(getattr(self, name), float)
            if name == "cell_F":        # relative: the pull-off spans three decades, its error with it
                centres = np.array(self.centres())
                e = e / np.abs(self.interpolated(centres[:, 0], centres[:, 1])[0]).reshape(e.shape)
            e = np.where(np.isfinite(e), e, np.inf)
            p = np.pad(e, 1, mode="edge")
            n, m = e.shape
            cache[name] = SAFETY * np.max([p[a:a + n, b:b + m] for a in range(3) for b in range(3)], axis=0)
        i, j = self._cells(lm, s)
        return cache[name][i, j]

    def with_error(self, cell_F, cell_lam, cell_F_err, cell_seconds) -> PullOffTable:
        """This table with the error measured at its cells' centres (arrays of shape (mu - 1, sigma - 1))."""
        shape = (self.mu.size - 1, self.sigma.size - 1)
        arrays = [np.asarray(a, float) for a in (cell_F, cell_lam, cell_F_err, cell_seconds)]
        if any(a.shape != shape for a in arrays):
            raise ValueError(f"the cells' errors: expected arrays of shape {shape}")
        return replace(self, cell_F=arrays[0], cell_lam=arrays[1], cell_F_err=arrays[2], cell_seconds=arrays[3])

    def centres(self) -> list[tuple[float, float]]:
        """The centres of the cells (midpoints in ln mu and in sigma), row by row in mu."""
        lm = np.log(self.mu)
        mids = np.exp(0.5 * (lm[1:] + lm[:-1]))
        smid = 0.5 * (self.sigma[1:] + self.sigma[:-1])
        return [(float(m), float(s)) for m in mids for s in smid]

    @classmethod
    def of_nodes(cls, mu, sigma, nodes: list) -> PullOffTable:
        """The table of traced ``nodes`` (NodeValues in the order of (mu, sigma) row by row); RuntimeError
        naming every node that failed."""
        bad = [f"mu {n.mu:g}, sigma {n.sigma:g}: {n.failed}" for n in nodes if n.failed is not None]
        if bad:
            raise RuntimeError(f"{len(bad)} node{'s' * (len(bad) != 1)} could not be tabulated: " + "; ".join(bad))
        shape = (len(mu), len(sigma))

        def grid(f):
            return np.array([f(n) for n in nodes], float).reshape(shape)
        return cls(mu=np.asarray(mu, float), sigma=np.asarray(sigma, float), F=grid(lambda n: n.F.value),
                   F_err=grid(lambda n: _bar(n.F)), F_grid=grid(lambda n: _grid(n.F)),
                   lam=grid(lambda n: n.lam.value), lam_err=grid(lambda n: _bar(n.lam)),
                   seconds=grid(lambda n: n.seconds))

    def measure(self, centres: list) -> PullOffTable:
        """This table with its error measured against ``centres`` (NodeValues at :meth:`centres`, in order):
        |interpolated - solver| of F and lambda per cell (the solver's best value, or on its grid where it was
        traced without a bar: the grid's error then counts into the interpolation's), infinite where the solver
        failed there."""
        shape = (self.mu.size - 1, self.sigma.size - 1)
        eF, el, bar, sec = (np.full(len(centres), np.inf) for _ in range(4))
        for k, c in enumerate(centres):
            sec[k] = c.seconds
            if c.failed is None:
                F, lam = self.interpolated(c.mu, c.sigma)
                eF[k], el[k] = abs(float(F) - c.F.value), abs(float(lam) - c.lam.value)
                bar[k] = _bar(c.F)            # nan where the centre was traced on its grid alone
        return self.with_error(eF.reshape(shape), el.reshape(shape), bar.reshape(shape), sec.reshape(shape))


_DEFAULT: PullOffTable | None = None
