"""The curve family table: F(lambda; mu, sigma) on a grid of (ln mu, sigma), read back and interpolated, with the
interpolation error measured against the solver.

In units of 2 pi R w and epsilon the model under the default roughness rule (the
paper's 16-point Gauss-Hermite average, eq. 14) is a two-parameter family of curves.
The table holds each node's curve as lambda and F at the nodes tau of the coordinate
of :mod:`~petsc_adhesion.family.coordinate` (monotone along the whole branch, through
its folds), from the library's start far out of reach of the forces to F = F_max.  At
any (mu, sigma) in its range the curve is interpolated at every tau node by the cubic
Lagrange polynomials through the four nearest nodes in ln mu and in sigma (exact at a
node), and read as a function of tau by cubic splines: its turning points in lambda
(snap-on, snap-off), its pull-off (the most tensile F) and, behind a spring of
stiffness K, the legs of :func:`~petsc_adhesion.family.legs.spring_legs` (Z = lambda +
F / K, vertical jumps).  Every value carries as its bar the interpolation error
measured against the solver at the midpoints of the grid's cells about it
(:class:`TableError`), which the builder writes into the file
(``python -m petsc_adhesion.benchmarks.family``, docs/family.md).  Out of range
(mu, sigma, a force past F_max) is refused with one line (:class:`OutOfRange`).

The file: .npz with its format name and version, the program's version, the grid it
was made on and the measured error; written all together or not at all.
"""
from __future__ import annotations

import functools
import math
import os
import zipfile
import zlib
from dataclasses import dataclass, field, replace

import numpy as np

from ..tracing.measured import Measured, Missing
from ..version import __version__
from .legs import APPROACH, RETRACT, Legs, spring_legs

__all__ = ["save_npz", "load_npz", "FORMAT", "FORMAT_VERSION", "SHIPPED", "shipped_path", "shipped", "default_table",
           "OutOfRange", "TableError",
           "FamilyTable", "FamilyCurve", "SpringCurve", "TableEvent", "lagrange"]

FORMAT = "petsc-adhesion curve family"
FORMAT_VERSION = 1
#: What the error stated about a point is of the largest measured at the cell centres about it: the error varies
#: within a cell, and at a third of the way across the first cell of a small table (mu 0.126, sigma 0.017) the
#: pull-off's was 1.4 times the largest at the centres about it (docs/family.md).
SAFETY = 2.0
#: The fields of a TableError, as the file's arrays err_<name>.
ERROR_FIELDS = ("F_at_Z", "jump_Z", "jump_F", "event_lam", "event_F")


#: The tables the package ships (petsc_adhesion/family/data/NAME.npz), by name: "smooth", sigma = 0 over mu 1e-3
#: to 1e3; "rough", sigma 0 to 3 over the part of that mu range built so far (docs/family.md says how each was
#: built, its range and its measured error).  The first is the default of a fit without roughness
#: (:func:`default_table`).
SHIPPED = ("smooth", "rough")


def shipped_path(name: str = SHIPPED[0]) -> str:
    """The file of the shipped table ``name`` (ValueError, one line, for a name the package does not ship)."""
    if name not in SHIPPED:
        raise ValueError(f"table '{name}': the package ships {', '.join(SHIPPED)}")
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", f"{name}.npz")


@functools.lru_cache(maxsize=4)
def shipped(name: str = SHIPPED[0]) -> FamilyTable:
    """The shipped table ``name``, read once per process (a FamilyTable is immutable)."""
    return FamilyTable.load(shipped_path(name))


def default_table(sigma: float, fitted: bool, mu_range: tuple[float, float]) -> str:
    """The shipped table a fit's "default" is: "rough" where the fit has a roughness (``fitted``, or held at
    ``sigma`` > 0) and the rough table's range holds the fit's, its sigma and the whole ``mu_range`` the fit may
    reach (a search bounded at a table's mu short of the model's would end at the table's bound, not the
    data's: while the rough table is built over part of the mu range alone it is taken by its name,
    ``-fit_table rough``); "smooth" otherwise (SHIPPED[0]; a roughness it does not hold then goes through the
    solver, said by the fit)."""
    if (fitted or sigma > 0) and os.path.exists(shipped_path("rough")):
        t = shipped("rough")
        lo, hi = mu_range
        if t.sigma[0] <= sigma <= t.sigma[-1] and t.mu[0] <= lo * (1 + 1e-9) and t.mu[-1] >= hi * (1 - 1e-9):
            return "rough"
    return SHIPPED[0]


class OutOfRange(ValueError):
    """A request outside the table's range: one line naming the quantity and the range it accepts."""


@dataclass(frozen=True)
class TableError:
    """The interpolation error measured against the solver (the largest over the midpoints it summarizes):
    ``F_at_Z``, the force at fixed base positions Z behind the springs, away from their jumps; ``jump_Z`` and
    ``jump_F``, the base position of the springs' jumps and the force at their turning points; ``event_lam``
    and ``event_F``, lambda and F of the snap-on, snap-off and pull-off; ``points``, how many midpoints."""

    F_at_Z: float
    jump_Z: float
    jump_F: float
    event_lam: float
    event_F: float
    points: int


def lagrange(nodes: np.ndarray, x: float, order: int = 4) -> tuple[int, np.ndarray]:
    """(first index, weights) of the Lagrange polynomial through the ``order`` nodes nearest to ``x`` (fewer
    where there are fewer): a value at ``x`` is the weights' sum over those nodes' values, exactly the node's
    own at a node."""
    n = nodes.size
    m = min(order, n)
    i0 = int(np.clip(np.searchsorted(nodes, x) - m // 2, 0, n - m))
    xs = nodes[i0:i0 + m]
    w = np.ones(m)
    for j in range(m):
        for k in range(m):
            if k != j:
                w[j] *= (x - xs[k]) / (xs[j] - xs[k])
    return i0, w


@dataclass(frozen=True)
class TableEvent:
    """An event of an interpolated curve: ``kind`` (snap_on, snap_off, pull_off), ``lam`` and ``F`` with the
    table's interpolation error as their bars."""

    kind: str
    lam: Measured
    F: Measured


@dataclass(frozen=True)
class FamilyTable:
    """The tabulated family (module docstring): nodes ``mu`` (increasing, interpolated in ln mu), ``sigma``
    (increasing), ``tau`` (-1 to 1); ``lam`` and ``F`` of shape (mu, sigma, tau); each node curve's ``s_lo``,
    ``s_hi``, ``s0`` and ``delta`` of shape (mu, sigma); the force the curves end at, ``F_max``; the roughness
    rule; the program ``version`` that made it; the cost of each node's trace (``seconds``, wall time); the
    measured error at the midpoints ``err_mu``, ``err_sigma`` (``errors``: one array per
    :class:`TableError` field) behind the springs ``springs``, empty until measured."""

    mu: np.ndarray
    sigma: np.ndarray
    tau: np.ndarray
    lam: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    s_lo: np.ndarray = field(repr=False)
    s_hi: np.ndarray = field(repr=False)
    s0: np.ndarray = field(repr=False)
    delta: np.ndarray = field(repr=False)
    F_max: float
    roughness: str
    version: str = __version__
    seconds: np.ndarray | None = field(default=None, repr=False)
    springs: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    err_mu: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    err_sigma: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    errors: dict = field(default_factory=dict, repr=False)

    # -- the range and the error -------------------------------------------------------
    def check(self, mu: float, sigma: float) -> None:
        """OutOfRange, one line, for (mu, sigma) outside the table."""
        for name, v, nodes in (("mu", mu, self.mu), ("sigma", sigma, self.sigma)):
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or \
                    not math.isfinite(v) or not (nodes[0] * (1 - 1e-12) - 1e-15 <= v <= nodes[-1] * (1 + 1e-12) + 1e-15):
                raise OutOfRange(f"{name} {v!r}: the table holds {name} in [{nodes[0]:g}, {nodes[-1]:g}]")

    @property
    def measured(self) -> bool:
        """Whether the interpolation error was measured (the builder's second step)."""
        return self.err_mu.size > 0

    def error(self, mu: float, sigma: float) -> TableError | Missing:
        """The interpolation error stated about (mu, sigma): SAFETY times the largest measured at the midpoints of
        the cells about it (its cell and their neighbours, in ln mu and sigma); Missing where the table was not
        measured, or not at its own cell's centre."""
        self.check(mu, sigma)
        if not self.measured:
            return Missing("the table's interpolation error was not measured (built without its midpoints)")
        lm, nodes = math.log(mu), np.log(self.mu)
        i = int(np.clip(np.searchsorted(nodes, lm), 1, max(nodes.size - 1, 1)))
        lo_m, hi_m = nodes[max(i - 2, 0)], nodes[min(i + 1, nodes.size - 1)]
        j = int(np.clip(np.searchsorted(self.sigma, sigma), 1, max(self.sigma.size - 1, 1)))
        lo_s, hi_s = self.sigma[max(j - 2, 0)], self.sigma[min(j + 1, self.sigma.size - 1)]
        em = np.log(self.err_mu)
        near = (em >= lo_m - 1e-12) & (em <= hi_m + 1e-12) & (self.err_sigma >= lo_s - 1e-12) & \
            (self.err_sigma <= hi_s + 1e-12)
        # its own cell's centre measured, too: a table measured in parts may hold its neighbours' alone
        s0, s1 = self.sigma[j - 1], self.sigma[min(j, self.sigma.size - 1)]
        own = near & (em >= nodes[i - 1] - 1e-12) & (em <= nodes[min(i, nodes.size - 1)] + 1e-12) & \
            (self.err_sigma >= s0 - 1e-12) & (self.err_sigma <= s1 + 1e-12)
        if not own.any():
            return Missing(f"the table's interpolation error was not measured about mu = {mu:.4g}, sigma = "
                           f"{sigma:.4g} (its cell's centre was not; it was measured at {self.err_mu.size} cell "
                           f"centres, mu {self.err_mu.min():.4g} to {self.err_mu.max():.4g})")
        return TableError(**{f: SAFETY * float(np.max(self.errors[f][near])) for f in ERROR_FIELDS},
                          points=int(near.sum()))

    def worst(self) -> TableError | Missing:
        """The largest interpolation error measured over the whole table (as measured, without SAFETY)."""
        if not self.measured:
            return Missing("the table's interpolation error was not measured (built without its midpoints)")
        return TableError(**{f: float(np.max(self.errors[f])) for f in ERROR_FIELDS}, points=int(self.err_mu.size))

    def with_error(self, mu: np.ndarray, sigma: np.ndarray, springs, errors: dict) -> FamilyTable:
        """This table with the error measured at the midpoints (``mu``, ``sigma``): ``errors`` one array per
        :class:`TableError` field, behind the ``springs``."""
        missing = set(ERROR_FIELDS) - set(errors)
        if missing:
            raise ValueError(f"errors: expected the fields {', '.join(ERROR_FIELDS)}; missing {', '.join(sorted(missing))}")
        return replace(self, err_mu=np.asarray(mu, float), err_sigma=np.asarray(sigma, float),
                       springs=np.asarray(springs, float),
                       errors={f: np.asarray(errors[f], float) for f in ERROR_FIELDS})

    # -- a curve -----------------------------------------------------------------------
    def curve(self, mu: float, sigma: float, error: bool = True) -> FamilyCurve:
        """The interpolated curve at (mu, sigma): lambda and F at the nodes tau (OutOfRange outside the table);
        ``error`` False: without the interpolation error stated about it (Missing: a fit's search reads the legs
        alone, and the error's lookup was a tenth of a curve behind a spring)."""
        self.check(mu, sigma)
        i0, wm = lagrange(np.log(self.mu), math.log(mu))
        j0, ws = lagrange(self.sigma, float(sigma))
        w = wm[:, None] * ws[None, :]
        block = (slice(i0, i0 + wm.size), slice(j0, j0 + ws.size))
        lam = np.tensordot(w, self.lam[block], axes=([0, 1], [0, 1]))
        F = np.tensordot(w, self.F[block], axes=([0, 1], [0, 1]))
        return FamilyCurve(float(mu), float(sigma), self.tau, lam, F, self.F_max, self.error(mu, sigma) if error else
                           Missing("the table's interpolation error was not asked for with this curve"))

    # -- the file ----------------------------------------------------------------------
    #: The arrays a table's file holds beside its format and version.
    _ARRAYS = ("mu", "sigma", "tau", "lam", "F", "s_lo", "s_hi", "s0", "delta", "F_max", "roughness",
               "program_version", "seconds", "springs", "err_mu", "err_sigma", *(f"err_{f}" for f in ERROR_FIELDS))

    def save(self, path: str) -> None:
        """Write the table to ``path`` (.npz), all or nothing: a temporary file beside it, renamed over it."""
        arrays = dict(format=np.array(FORMAT), format_version=np.array(FORMAT_VERSION),
                      program_version=np.array(self.version), roughness=np.array(self.roughness),
                      F_max=np.array(self.F_max), mu=self.mu, sigma=self.sigma, tau=self.tau, lam=self.lam,
                      F=self.F, s_lo=self.s_lo, s_hi=self.s_hi, s0=self.s0, delta=self.delta,
                      seconds=np.full(self.s_lo.shape, np.nan) if self.seconds is None else self.seconds,
                      springs=self.springs, err_mu=self.err_mu, err_sigma=self.err_sigma,
                      **{f"err_{f}": self.errors.get(f, np.zeros(0)) for f in ERROR_FIELDS})
        save_npz(path, arrays)

    @classmethod
    def load(cls, path: str) -> FamilyTable:
        """The table in ``path``; ValueError, one line, for a file that is no table of this format version."""
        d = load_npz(path, "curve family table", FORMAT, FORMAT_VERSION, cls._ARRAYS)
        why = _arrays_wrong(d)
        if why:
            raise ValueError(f"{path}: not a curve family table ({why}; rebuild it)")
        errors = {f: d[f"err_{f}"] for f in ERROR_FIELDS} if d["err_mu"].size else {}
        return cls(mu=d["mu"], sigma=d["sigma"], tau=d["tau"], lam=d["lam"], F=d["F"], s_lo=d["s_lo"],
                   s_hi=d["s_hi"], s0=d["s0"], delta=d["delta"], F_max=float(d["F_max"]),
                   roughness=str(d["roughness"]), version=str(d["program_version"]), seconds=d["seconds"],
                   springs=d["springs"], err_mu=d["err_mu"], err_sigma=d["err_sigma"], errors=errors)


def _arrays_wrong(d: dict) -> str | None:
    """What is wrong with a family table's arrays ``d`` as read (None where nothing): the nodes mu (positive) and
    sigma (not negative) increasing, tau increasing; lam and F finite of shape (mu, sigma, tau); each node's
    coordinate (s_lo, s_hi, s0, delta) and cost of shape (mu, sigma); F_max a finite number; the measured
    midpoints err_mu, err_sigma and each error field of one length.  Interpolation reads these by position, so a
    table of the right names but another shape would give numbers of nobody's curve, or an IndexError deep in a
    fit."""
    def vector(name: str, low: float | None) -> str | None:
        a = d[name]
        if a.ndim != 1 or a.size < 1 or a.dtype.kind not in "fiu" or not np.all(np.isfinite(a)) \
                or np.any(np.diff(a) <= 0) or (low is not None and a[0] < low):
            return f"{name}: expected increasing finite nodes{'' if low is None else f' of at least {low:g}'}"
        return None

    for name, low in (("mu", 1e-300), ("sigma", 0.0), ("tau", None)):
        bad = vector(name, low)
        if bad:
            return bad
    nodes = (d["mu"].size, d["sigma"].size)
    for name in ("lam", "F"):
        a = d[name]
        if a.shape != (*nodes, d["tau"].size) or a.dtype.kind != "f" or not np.all(np.isfinite(a)):
            return f"{name}: expected finite values of shape (mu, sigma, tau) = {(*nodes, d['tau'].size)}"
    for name in ("s_lo", "s_hi", "s0", "delta", "seconds"):
        if d[name].shape != nodes:
            return f"{name}: expected shape (mu, sigma) = {nodes}"
    if d["F_max"].shape != () or d["F_max"].dtype.kind not in "fiu" or not np.isfinite(d["F_max"]):
        return "F_max: expected one finite number"
    n = d["err_mu"].shape
    if len(n) != 1 or any(d[f"err_{f}"].shape != n for f in ("sigma", *ERROR_FIELDS)):
        return "the measured error: expected err_mu, err_sigma and each error field of one length"
    return None


@dataclass(frozen=True)
class FamilyCurve:
    """One interpolated curve: ``lam`` and ``F`` at the nodes ``tau``, ending at F = ``F_max``; ``error`` the
    table's measured interpolation error about it (a :class:`TableError`, or Missing)."""

    mu: float
    sigma: float
    tau: np.ndarray = field(repr=False)
    lam: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    F_max: float
    error: TableError | Missing = field(repr=False)

    def _bar(self, name: str) -> tuple[float | None, str | None]:
        if isinstance(self.error, TableError):
            return getattr(self.error, name), None
        return None, self.error.reason

    def events(self) -> tuple[TableEvent, ...]:
        """The turning points of lambda along tau (snap_on where lambda is largest, snap_off where smallest,
        in their order) and the pull-off (the most tensile F), each with the table's error as its bars."""
        from scipy.interpolate import CubicSpline

        L, G = CubicSpline(self.tau, self.lam), CubicSpline(self.tau, self.F)
        roots = np.asarray(L.derivative().roots(extrapolate=False), dtype=float)
        curv = L.derivative(2)(roots)
        el, note = self._bar("event_lam")
        ef, _ = self._bar("event_F")
        out = [TableEvent("snap_on" if c < 0 else "snap_off", Measured(float(L(r)), el, note=note),
                          Measured(float(G(r)), ef, note=note)) for r, c in zip(roots, curv) if c != 0]
        dG = np.asarray(G.derivative().roots(extrapolate=False), dtype=float)
        cand = np.r_[dG, self.tau[np.argmin(self.F)]]
        r = cand[int(np.argmin(G(cand)))]
        out.append(TableEvent("pull_off", Measured(float(L(r)), el, note=note), Measured(float(G(r)), ef, note=note)))
        return tuple(out)

    def behind(self, K: float, reach: float | None = None) -> SpringCurve:
        """The curve behind a spring of stiffness ``K`` (units 2 pi R w / epsilon): its approach and retract;
        ``reach``, a base position the far branch is to be tabulated beyond (a fit's farthest point: there the
        legs interpolate instead of solving eq. 28 for each Z).

        The table's curves start where the library's do, out of reach of the forces; behind a spring softer
        than the forces' gradient there, the approach jumps in before that start, so the far branch is
        continued out to beyond the spring's start (:func:`~petsc_adhesion.tracing.trace.spring_start`) by the
        rigid sphere's load (eq. 28) matched to the curve at its start, as
        :class:`~petsc_adhesion.family.legs.Legs` continues it below a branch's start."""
        if isinstance(K, bool) or not isinstance(K, (int, float, np.integer, np.floating)) or \
                not (math.isfinite(K) and K > 0):
            raise OutOfRange(f"K {K!r}: expected a spring stiffness, a finite real > 0")
        t, lam, F = self._far(float(K), reach)
        return SpringCurve(self, float(K), spring_legs(t, lam, F, float(K)))

    def _far(self, K: float, reach: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(coordinate, lambda, F) of the curve with its far branch continued out to beyond the spring's start:
        points uniform in ln(1 - lambda) at tau < -1, their coordinate matched to the curve's rate at its start
        (so that the splines in it do not ring at the seam)."""
        from ..model.reference.rigid import rigid_load
        from ..tracing.trace import spring_start

        lam0, F0 = float(self.lam[0]), float(self.F[0])
        far = min(spring_start(K), lam0, lam0 if reach is None or not math.isfinite(reach) else reach) - 2.0
        rigid0 = float(rigid_load(lam0))
        factor = F0 / rigid0 if rigid0 < 0 and F0 < 0 else 1.0
        u0, u1 = math.log(1.0 - lam0), math.log(1.0 - far)
        rate = (self.lam[1] - self.lam[0]) / (self.tau[1] - self.tau[0])       # d lambda / d tau at the start
        n = max(int(math.ceil((u1 - u0) * (1.0 - lam0) / max(rate * (self.tau[1] - self.tau[0]), 1e-300))), 8)
        u = np.linspace(u1, u0, min(n, 200) + 1)[:-1]
        lam_far = 1.0 - np.exp(u)
        t_far = self.tau[0] - (u - u0) * (1.0 - lam0) / rate
        return (np.concatenate((t_far, self.tau)), np.concatenate((lam_far, self.lam)),
                np.concatenate((factor * rigid_load(lam_far), self.F)))


@dataclass(frozen=True)
class SpringCurve:
    """An interpolated curve behind a spring of stiffness ``K``: the force on the approach and the retract at
    base positions Z up to ``Z_max`` (where the contact's load reaches the table's F_max), its jumps."""

    curve: FamilyCurve
    K: float
    legs: Legs = field(repr=False)

    @property
    def Z_max(self) -> float:
        """The largest base position the table covers: where the contact's load reaches F_max."""
        return float(self.curve.lam[-1] + self.curve.F[-1] / self.K)

    def predict(self, Z, leg: str) -> np.ndarray:
        """The force at the base positions ``Z`` along ``leg`` (approach or retract); OutOfRange past Z_max."""
        if leg not in (APPROACH, RETRACT):
            raise OutOfRange(f"leg '{leg}': expected {APPROACH} or {RETRACT}")
        Z = np.asarray(Z, dtype=float)
        if Z.size and not np.all(np.isfinite(Z)):
            raise OutOfRange("Z: expected finite base positions")
        if Z.size and Z.max() > self.Z_max + 1e-9 * max(1.0, abs(self.Z_max)):
            raise OutOfRange(f"Z {Z.max():.6g}: the table holds the curve up to F = {self.curve.F_max:g}, "
                             f"Z <= {self.Z_max:.6g} behind this spring")
        return self.legs.predict(Z, leg)

    def jumps(self, leg: str) -> tuple[tuple[Measured, Measured, Measured], ...]:
        """The jumps of ``leg``: (Z, F before, F after) each, with the table's error as their bars."""
        ez, note = self.curve._bar("jump_Z")
        ef, _ = self.curve._bar("jump_F")
        return tuple((Measured(float(z), ez, note=note), Measured(b, ef, note=note), Measured(a, ef, note=note))
                     for z, (b, a) in zip(self.legs.jumps[leg], self.legs.jump_forces(leg)))


def save_npz(path: str, arrays: dict) -> None:
    """``arrays`` into the .npz ``path``, all or nothing: a temporary file beside it, flushed to the disk and renamed
    over it, so that a failed write never damages an earlier table (the family's and the pull-off table's files)."""
    tmp = f"{path}.part{os.getpid()}.npz"
    try:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def load_npz(path: str, kind: str, fmt: str, version: int, names: tuple[str, ...]) -> dict:
    """The arrays of the .npz ``path`` that holds a ``kind`` (a table's name in a message) written as format ``fmt``
    of ``version`` with at least the arrays ``names``; ValueError, one line beginning with ``path``, for a file that
    is none: not an .npz archive (numpy would read any other file as a pickle, and a table is data: no pickles),
    truncated or corrupted, of another format or version, or missing one of the arrays (both tables' loaders)."""
    d = None
    try:
        # np.load reads a file that is neither .npz nor .npy as a pickle: the zip's own signature decides first.
        with open(path, "rb") as fh:
            zipped = fh.read(4) in (b"PK\x03\x04", b"PK\x05\x06")
        if zipped:
            with np.load(path, allow_pickle=False) as z:
                d = {k: z[k] for k in z.files}
        why = "not an .npz archive"
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as e:
        # Truncated: BadZipFile; a member corrupted: zlib.error or a CRC's BadZipFile; unreadable: OSError.
        why = str(e).splitlines()[0] if str(e) else type(e).__name__
        if isinstance(e, (zipfile.BadZipFile, zlib.error, EOFError)):
            why = f"a truncated or corrupted .npz archive: {why}"
    if d is None:
        raise ValueError(f"{path}: not a {kind} ({why})")
    if str(d.get("format", "")) != fmt:
        raise ValueError(f"{path}: not a {kind} (no format '{fmt}')")
    got = d.get("format_version")
    if got is None or got.shape != () or got.dtype.kind not in "iu":
        raise ValueError(f"{path}: a {kind} without an integer format version; this program reads version "
                         f"{version} (rebuild it)")
    if int(got) != version:
        raise ValueError(f"{path}: a {kind} of format version {int(got)}; this program reads version {version} "
                         f"(rebuild it)")
    missing = [k for k in names if k not in d]
    if missing:
        raise ValueError(f"{path}: a {kind} without the array{'s' if len(missing) > 1 else ''} "
                         f"{', '.join(missing)} (rebuild it)")
    return d
