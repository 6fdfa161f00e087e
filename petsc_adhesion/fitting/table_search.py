"""A curve fit's search on the curve family table, and the solver's curve at its optimum (docs/fitting.md, "The
search on the table").

Where the table (:mod:`petsc_adhesion.family.table`) holds the model a fit asks for, the
least squares of :func:`~petsc_adhesion.fitting.curve_fit.fit_curve` run on the table's
interpolated curves (milliseconds an evaluation, against the solver's 0.1 to 85 s a
curve).  What is reported is then made the solver's: at the table's optimum x_t one
curve is traced and, with the table's Jacobian J there, one Gauss-Newton step

    dx = -(J^T J)^-1 J^T r_s(x_t)

is taken on the solver's residuals r_s.  At the table's optimum J^T r_t = 0 (r_t its residuals), so
dx = -(J^T J)^-1 J^T (r_s - r_t): the first-order move of the optimum that the table's error r_t - r_s made,
measured here against the solver.  It vanishes where the table is the solver (at a node, to the sampling's
error).  After the step what is left of it is of the order of dx times the table's relative error in J, less
than dx itself; so dx is added to the covariance as a systematic term, d d^T (d = dx in the reported
coordinates): the table's contribution to each bar, reported beside it.  Where the step moves a
parameter by more than STEP_BARS of its statistical bar another curve is traced at the stepped point and the step
repeated (SOLVER_CURVES at most): the linearisation is not trusted beyond its bar.

The last step and the bars are taken on the solver's own Jacobian J_s at the last curve, dx = -(J_s^T J_s)^-1
J_s^T r_s, covariance s^2 (J_s^T J_s)^-1: the branch's coordinates (ln mu, sigma) differenced on the solver's
curves (one more curve each; at a lattice point the same for every fit that lands there), the others read on
the same branch.  The table's J serves the search and the steps between curves alone: its interpolated curve
behind a lever a thousand times softer than the contact shows small folds (extra jumps on the approach in
contact) that come and go with mu, and a difference across one made its ln mu column 37 times the solver's
(mu = 16, K = 3.5e-4: E*'s bar 0.7%, the solver's 23%, the truth 29.5 of the table's bars off and 0.8 of the
solver's).

The first curve is not traced at x_t itself but at x_t with its ln mu moved to the nearest point of a lattice
(:func:`on_lattice`): 8 points a decade, or 2^k times as many (k from -3 to 12), the coarsest whose half-spacing is at most
LATTICE_BARS = 0.5 of ln mu's bar at x_t.  The solver's curve is a function of (mu, sigma) alone
(:mod:`~petsc_adhesion.fitting.branches`: a branch traced once and read behind any spring), so the curve of a
lattice point is traced once in a process and read by every later fit that lands near it (a map's pixels of
one material).  The step then also takes the fit from the lattice point to the optimum: at first order it
moves ln mu back by the offset (at most half a bar) and the others by nothing, and it is said and added to
the bars as any step is.  A curve after a step beyond STEP_BARS is traced at the lattice point nearest the
stepped point too, the last of SOLVER_CURVES at the stepped point itself.  A lattice point depends on the
fit's own data alone, never on the fits before it: a fit gives the same numbers
whichever curves its process had traced.

The chi^2, the residuals, the events and the fitted curve are the solver's last curve's, read (where mu is
fitted) with the parameters other than mu and sigma at their best for it, one Gauss-Newton step in them alone
(a branch is read behind any spring; w moves K); the parameters are one step from it (:class:`TableStep`
says how far).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..family.table import FamilyTable

__all__ = ["TableStep", "bounded_step", "mu_profile", "searched", "SEARCH_STARTS", "PROFILE_POINTS", "PROFILE_EVALS", "SOLVER_CURVES", "STEP_BARS", "START_MUS", "START_SIGMAS", "TABLE_EVALS", "TABLE_CAP", "search_cap", "start_gamma", "LATTICE", "LATTICE_BARS", "LATTICE_LEVELS", "COARSER",
           "on_lattice", "table_bounds", "solver_steps"]

#: The solver's curves at most after a search on the table.
SOLVER_CURVES = 3
#: A step larger than this many statistical bars in any coordinate is taken and another curve traced there.
STEP_BARS = 1.0
#: The lattice of ln mu the solver's first curve is traced on: LATTICE points a decade at level 0, each finer
#: level twice as many, up to level LATTICE_LEVELS (8 * 2^12 a decade), each coarser half as many down to
#: level -COARSER (one a decade); the coarsest whose
#: half-spacing is at most LATTICE_BARS of ln mu's bar at the table's optimum (on_lattice).
LATTICE = 8
LATTICE_LEVELS = 12
#: Coarser levels where ln mu is hardly determined (E* at the DMT end): down to a point a decade.
COARSER = 3
LATTICE_BARS = 0.5
#: The profile of ln mu from a bound (mu_profile): points a decade, and the least squares' evaluations at each.
PROFILE_POINTS = 2
PROFILE_EVALS = 12
#: The Tabor parameters the search on the table starts from (the best of them; the solver's search tries 0.1 to 3).
START_MUS = (0.003, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 100.0)
#: The roughness sigma a search on the table starts from where it is fitted, with each of START_MUS and w from
#: the measured pull-off at each (:func:`start_gamma`): from sigma = 0.3 alone with the smooth sphere's w, a fit
#: at mu = 0.0055, sigma = 1 (K = 0.19, 0.3% noise) ended at the bounds w = 1e-6 J/m^2, mu = 0.001, sigma = 0.
START_SIGMAS = (0.0, 0.3, 0.7, 1.2, 2.0)
#: A search on a table with the roughness fitted may take TABLE_EVALS times the fit's cap on evaluations
#: (-fit_max_evals), an evaluation on it costing a millisecond against a solver curve's second: its valley is
#: long (sigma and w trade along it) and the search took 74 (mu = 0.0055, sigma = 1), where the cap of 40 left w
#: 8 bars and sigma 12 bars from where it went on to.
TABLE_EVALS = 5
TABLE_CAP = f" times {TABLE_EVALS} on the table with the roughness fitted"


def search_cap(choice, table) -> int:
    """The least squares' cap on evaluations: ``choice.max_evaluations``, TABLE_EVALS times it on a ``table`` with
    the roughness fitted."""
    return choice.max_evaluations * (TABLE_EVALS if table is not None and choice.roughness else 1)


@dataclass(frozen=True)
class TableStep:
    """How a fit went through the table: ``table`` (its name or file), the least squares' ``evaluations`` on it
    and their CPU ``seconds``; the solver's ``curves`` at the optimum; the last Gauss-Newton ``step`` in each
    reported coordinate (``coordinates``: ln_E_star, ln_gamma, z0, ...; the fit's units), ``bars``, the step in
    units of each coordinate's statistical bar (its largest is what decided another curve), and
    ``contribution``, the table's share of each bar: the systematic term |step| beside the statistical bar;
    ``first``, the largest first step in bars (from the lattice point near the table's optimum); ``lattice_mu``,
    the mu of that lattice point (NaN: the first curve at the table's optimum itself); ``shared``, the solver's
    curves the process had traced before this fit (found, not traced again); ``differenced``, the curves traced
    for the solver's Jacobian at the last curve (its branch columns; 0 where found); ``mu_span``, the mu from
    and to which the table's profile describes the data (:func:`mu_profile`; None: mu determined, not profiled)."""

    table: str
    evaluations: int
    seconds: float
    curves: int
    coordinates: tuple
    step: np.ndarray
    bars: np.ndarray
    contribution: np.ndarray
    first: float = math.nan
    lattice_mu: float = math.nan
    shared: int = 0
    differenced: int = 0
    mu_span: tuple | None = None

    def describe(self, names: dict) -> str:
        """One line for the fit's notes: the path, the step, the table's share of each bar (``names``: the
        reported coordinate's label for each of ``coordinates``)."""
        share = ", ".join(f"{names.get(c, c)} {b:.2g} bars" for c, b in zip(self.coordinates, self.bars))
        return (f"the search ran on the table {self.table} ({self.evaluations} evaluations), then the solver's "
                f"{self.curves} curve{'s' * (self.curves != 1)} near its optimum"
                + (f" (the first at the lattice point mu = {self.lattice_mu:.6g})"
                   if math.isfinite(self.lattice_mu) else "")
                + (f", {self.shared} of them read from a branch traced before (by this fit or an earlier one)"
                   if self.shared else "")
                + ": chi^2, "
                f"the residuals and the events are the solver's last curve's, the parameters one Gauss-Newton step "
                f"from it on the solver's Jacobian (the bars its), the step added to each bar ({share})")


def start_gamma(pull_off_N: float, R: float, mu: float, sigma: float, fallback: float) -> float:
    """The w whose load-controlled pull-off at (mu, sigma), 2 pi R w |F_po| (the pull-off table,
    :mod:`~petsc_adhesion.family.pull_off`), is the measured ``pull_off_N``: a rough search's start at each of its
    START_SIGMAS (``fallback`` where the table does not hold (mu, sigma)).  Why: the pull-off falls by orders of
    magnitude with sigma (0.03 of the smooth sphere's at sigma = 1), and w from it as from a smooth sphere lay
    30 times too low at such a start."""
    from ..family.pull_off import PullOffTable

    try:
        t = PullOffTable.default()
    except FileNotFoundError:
        return fallback
    if not bool(t.covers(mu, sigma)) or not pull_off_N > 0:
        return fallback
    return pull_off_N / (2.0 * math.pi * R * math.exp(float(t.ln_pull_off(mu, sigma))))


def table_bounds(table: FamilyTable, names: tuple, lo: np.ndarray, hi: np.ndarray, modulus: float | None,
                 R: float, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """The search's bounds narrowed to the table's mu (ln mu; ln w through mu at a held modulus, eq. 9)."""
    lo, hi = lo.copy(), hi.copy()
    m0, m1 = float(table.mu[0]), float(table.mu[-1])
    if "ln_mu" in names:
        j = names.index("ln_mu")
        lo[j], hi[j] = max(lo[j], math.log(m0)), min(hi[j], math.log(m1))
    elif modulus is not None:
        j = names.index("ln_gamma")
        E = float(modulus)
        lo[j] = max(lo[j], math.log(math.sqrt(m0**3 * E**2 * eps**3 / R)))
        hi[j] = min(hi[j], math.log(math.sqrt(m1**3 * E**2 * eps**3 / R)))
    return lo, hi


def on_lattice(x: np.ndarray, names: tuple, sd: np.ndarray, lo: np.ndarray,
               hi: np.ndarray) -> tuple[np.ndarray, int | None]:
    """``x`` with its ln mu moved to the nearest point of the lattice (module docstring): LATTICE points a decade
    at level 0, 2^k times as many at level k (-COARSER <= k <= LATTICE_LEVELS), the coarsest level whose
    half-spacing is at most LATTICE_BARS of ln mu's bar ``sd``; (x, the level; None where x is left as it is: no
    ln mu fitted, or a bar finer than the finest level)."""
    if "ln_mu" not in names:
        return x, None
    j = names.index("ln_mu")
    for level in range(-COARSER, LATTICE_LEVELS + 1):
        h = math.log(10.0) / (LATTICE * 2**level)
        if 0.5 * h <= LATTICE_BARS * sd[j]:
            y = x.copy()
            y[j] = min(max(h * round(x[j] / h), lo[j]), hi[j])
            return y, level
    return x, None


def bounded_step(J: np.ndarray, r: np.ndarray, x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The Gauss-Newton step dx minimising |r + J dx| with x + dx inside [lo, hi] (bounded-variable least
    squares, scipy's lsq_linear: a coordinate that would cross its bound is held there and the step solved
    in the others).  The free step clipped coordinate by coordinate is not this: where two coordinates are
    correlated (ln mu with ln w at the DMT end, where the curve hardly determines mu) the step in one assumes
    the other's, and clipping that one leaves the first moved by a step meant for both (a fit of mu = 0.015,
    K = 0.0098 went from w = 0.0496 to the bound 1e-6 that way, its chi^2 from 449 to 4e6)."""
    from scipy.optimize import lsq_linear

    scale = np.linalg.norm(J, axis=0)
    scale = np.where(scale > 0, scale, 1.0)     # columns of one size: the solver's rank test is relative
    a, b = lo - x, hi - x
    sol = lsq_linear(J / scale, -r, bounds=(np.minimum(a, 0.0) * scale, np.maximum(b, 0.0) * scale),
                     method="bvls", tol=1e-12)
    return np.clip(sol.x / scale, a, b)


def _normal_inverse(J: np.ndarray) -> np.ndarray:
    """(J^T J)^-1, the pseudo-inverse where J^T J is singular (a coordinate the residuals do not move)."""
    try:
        return np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(J.T @ J)


def solver_steps(pb, x: np.ndarray, lo: np.ndarray, hi: np.ndarray, A: np.ndarray, label: str,
                 evaluations: int, seconds: float):
    """From the table's optimum ``x`` to the solver's (module docstring): (the stepped parameters, the point of
    the solver's last curve, the solver's Jacobian there, the step d in the reported coordinates (``A`` maps the
    fitted coordinates to them), the :class:`TableStep`).  ``pb`` (the fit's problem) leaves the table and
    keeps the solver's last curve in its cache."""
    J = pb.jacobian(x)
    r_t = pb._all(pb.unpack(x))[0]          # the table's residuals at its optimum: ln mu's bar there
    pb.table = None
    pb.cache.clear()
    JtJ_inv = _normal_inverse(J)
    dof = max(pb.points - x.size, 1)
    sd_t = np.sqrt(np.abs(np.diag(JtJ_inv)) * float(r_t @ r_t) / dof)
    x, level = on_lattice(x, pb.names, sd_t, lo, hi)
    lattice_mu = pb.unpack(x)["mu"] if level is not None else math.nan
    curves, first, found, differenced = 0, math.nan, 0, 0
    while True:
        before = pb.traces
        r = pb._all(pb.unpack(x))[0]         # one solver curve (cached for what the fit reads of it)
        curves += 1
        found += pb.traces == before
        # each step on the solver's own Jacobian at its curve: the table's, differenced across a fold its
        # interpolated curve shows behind a soft lever (and the solver's does not), made E*'s bar 33 times too
        # small and held the step in ln mu to a thirtieth (mu = 16, K = 3.5e-4: 0.7% against the solver's 23%,
        # the truth 29.5 bars off)
        before = pb.traces
        J = pb.jacobian(x)
        differenced += pb.traces - before
        JtJ_inv = _normal_inverse(J)
        dx = bounded_step(J, r, x, lo, hi)
        stepped = x + dx
        sd = np.sqrt(np.abs(np.diag(JtJ_inv)) * float(r @ r) / dof)
        moved = float(np.max(np.abs(dx) / np.where(sd > 0, sd, np.inf))) if dx.size else 0.0
        first = moved if curves == 1 else first
        if moved <= STEP_BARS or curves >= SOLVER_CURVES:
            break
        # the linearisation not trusted beyond its bar: a curve at the step, on the lattice but for the last
        x = on_lattice(stepped, pb.names, sd_t, lo, hi)[0] if curves < SOLVER_CURVES - 1 else stepped
    d = A @ dx
    sd_out = np.sqrt(np.abs(np.diag(A @ JtJ_inv @ A.T)) * float(r @ r) / dof)
    bars = np.abs(d) / np.where(sd_out > 0, sd_out, np.inf)
    names = tuple("ln_E_star" if n == "ln_mu" else n for n in pb.names)
    step = TableStep(label, evaluations, seconds, curves, names, d, bars, np.abs(d), first, lattice_mu, found,
                     differenced, pb.mu_span)
    # what is reported of the curve (chi^2, residuals, events) is read on the last curve's branch (its mu and
    # sigma) with the others at their best for it, one Gauss-Newton step in them alone: at the curve's own
    # point, half a bar of ln mu from the optimum with w and z0 not moved along with it, chi^2 held 7 noise
    # variances more (mu = 1, ln mu correlated with w and z0); the others at the full step's values, more still
    others = np.array([n not in ("ln_mu", "sigma") for n in pb.names])
    if "ln_mu" in pb.names and others.any():
        y = x.copy()
        y[others] = np.clip(x[others] - np.linalg.lstsq(J[:, others], r, rcond=None)[0], lo[others], hi[others])
        x = y
    return stepped, x, J, d, step


#: The starts a search on a table with the roughness fitted runs from (the best of START_MUS x START_SIGMAS by chi^2).
SEARCH_STARTS = 3


def searched(run, x0: np.ndarray, tries: list, lo: np.ndarray, hi: np.ndarray, several: bool):
    """The least squares ``run`` (a start -> scipy's result) from ``x0``, or where ``several`` (a search on a
    table with the roughness fitted) from each of the SEARCH_STARTS starts of ``tries`` ((start, chi^2) pairs)
    with the least chi^2, the result of the least cost kept; each start moved just inside [lo, hi].

    Why: from the best start alone a rough search went to the corner w = 1e-6 J/m^2, sigma = 3 (reduced chi^2
    25,562 at mu = 0.0038, sigma = 0.43, K = 0.24; the coverage study's case 134), and the fit went on to the
    solver's curves throughout (51 CPU s); from the next starts it finds the data's valley.  On the table each
    run costs a second or two."""
    def inside(x):
        return np.clip(x, lo + 1e-9 * (hi - lo if np.all(np.isfinite(hi - lo)) else 1), hi - 1e-9)

    starts = [x0] + ([t[0] for t in sorted(tries, key=lambda t: t[1])[1:SEARCH_STARTS]] if several else [])
    return min((run(inside(x)) for x in starts), key=lambda r: r.cost)


def mu_profile(pb, x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray | None:
    """Where the curve hardly determines mu at the table's optimum ``x`` (ln mu at a bound, or its linear 95%
    interval in ln E* wider than 1, as where E* is called undetermined: the DMT end, a lever so soft that the
    curve shows little but its pull-off): how far the other coordinates move over the mu the curve allows, on
    the table's profile.  ln mu is stepped from x both ways (inwards alone from a bound), PROFILE_POINTS a
    decade, the others fitted again at each (warm started, PROFILE_EVALS evaluations at most), until chi^2
    exceeds its minimum by Z95^2 s^2 (s^2 = chi^2 / (n - p), the bars' own scale: a 95% interval of ln mu
    alone) or the table ends; the coordinates at that crossing interpolated linearly between the two points
    about it.  Returns the largest |move| of each coordinate over the points inside (ln mu's own 0), None
    where ln mu is not fitted or is determined.  The Jacobian's bars cannot give this: along a direction
    the curve hardly determines, their linear step leaves the model's range (ln mu +-300) and carries w with
    it (a 3% bar), while w's real move over it is a fraction of that (0.6% at mu = 0.015, K = 0.0098) or,
    where w is read from a pull-off that moves with mu (DMT's 2 pi R w, 0.8 of it at mu = 0.5), more than
    the bar held at the optimum's mu (mu = 0.53, K = 1.3e-4: the optimum at the bound 0.001, w 12% low)."""
    from scipy.optimize import least_squares

    from .results import BOUND_MARGIN, Z95

    if "ln_mu" not in pb.names:
        return None
    j = pb.names.index("ln_mu")
    r0 = pb._all(pb.unpack(x))[0]
    chi0 = float(r0 @ r0)
    s2 = chi0 / max(pb.points - x.size, 1)
    # each way's room is towards the bound it goes to: at the lower bound upwards alone (paired the other way
    # round, a mu at its bound was profiled into the bound and the profile ended at once: mu = 0.001 to 0.001,
    # no move added, where chi^2 at mu = 0.054 lay 1.4 above the least, within 3.95)
    ways = [w for w, edge in ((1.0, hi[j] - x[j]), (-1.0, x[j] - lo[j])) if edge > BOUND_MARGIN]
    if len(ways) == 2:                  # inside its bounds: profiled where its linear bar is wide
        J = pb.jacobian(x)
        try:
            sd = math.sqrt(abs(np.linalg.inv(J.T @ J)[j, j]) * s2)
        except np.linalg.LinAlgError:
            sd = math.inf
        if Z95 * 1.5 * sd <= 1.0:       # ln E* = ln w - 1.5 ln mu: E*'s interval narrower than its value
            return None
    limit = Z95**2 * s2
    h = math.log(10.0) / PROFILE_POINTS
    free = np.arange(x.size) != j
    spread = np.zeros(x.size)
    ends = []
    for way in ways:
        y, before, before_y = x.copy(), 0.0, x.copy()

        def at(z, y=y):
            full = y.copy()
            full[free] = z
            return full

        end = x[j]
        for k in range(1, int((hi[j] - lo[j]) / h) + 2):
            y[j] = min(max(x[j] + way * k * h, lo[j]), hi[j])
            sol = least_squares(lambda z: pb._all(pb.unpack(at(z)))[0], y[free],
                                jac=lambda z: pb.jacobian(at(z))[:, free], bounds=(lo[free], hi[free]),
                                method="trf", x_scale="jac", max_nfev=PROFILE_EVALS)
            y[free] = sol.x
            rise = 2.0 * float(sol.cost) - chi0
            if rise > limit:
                t = (limit - before) / (rise - before)
                edge = before_y + t * (y - before_y)
                spread = np.maximum(spread, np.abs(edge - x))
                end = edge[j]
                break
            spread = np.maximum(spread, np.abs(y - x))
            before, before_y, end = rise, y.copy(), y[j]
            if y[j] in (lo[j], hi[j]):
                break
        ends.append(end)
    spread[j] = 0.0
    span = sorted([x[j]] + ends)
    pb.mu_span = (math.exp(span[0]), math.exp(span[-1]))
    w = pb.names.index("ln_gamma")
    pb.notes.append(f"the curve hardly determines mu: the table's profile describes it as well (chi^2 within "
                    f"{limit:.3g} of its least) from mu = {math.exp(span[0]):.3g} to {math.exp(span[-1]):.3g}, "
                    f"over which ln w moves by up to {spread[w]:.3g}, added to its bar (the others' bars with mu "
                    f"held, each grown by its move)")
    return spread


def cpu() -> float:
    """The process's CPU seconds (the search's cost, as the benchmark measures it)."""
    return time.process_time()
