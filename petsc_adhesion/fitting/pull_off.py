"""The work of adhesion from a measured pull-off force: the model's own pull-off, solved for gamma.

A sphere of radius R pulls off a flat under load control at P = |F_p(mu)| 2 pi R w
(F_p the model's most tensile load, in 2 pi R w), where the Tabor parameter itself
depends on the unknown work of adhesion w by eq. (9), mu = (R w^2 / (E^2 eps^3))^(1/3),
mu proportional to w^(2/3), with the roughness sigma = rms / eps fixed.  Given P, the
bodies (R, E from eq. 2, eps, rms) and nothing of w, :func:`fit_pull_off` solves

    g(w) = ln(2 pi R w |F_p(mu(w))| / P) = 0

for w.  Where the pull-off table (:class:`~petsc_adhesion.family.pull_off.PullOffTable`)
holds the root and describes the model (its roughness rule and domain): the table's
root (:func:`gamma_from_pull_offs`) is the start, one curve with error bars there gives
the best F_p (extrapolated over nested grids) and its bar, a Newton step with the
table's slope s = d ln P / d ln w = 1 + (2/3) d ln|F_p| / d ln mu moves w, one curve on
the grid at the new w (scaled by the first's best over its grid value) and a second
Newton step end it: two curves.  Elsewhere (mu below the table's 1e-3 or above its
largest, sigma beyond its largest, another roughness law) the secant in ln w on the solver's pull-off on the grid, from
the table's root or the Maugis-Dugdale value, then one curve with error bars at the
root and a Newton step onto its best F_p, s by central differences (two more curves, mu
(1 +- 1.3%)).  The bar, from the pull-off's bar F_err, the measurement's P_err and the
iteration's last step in ln w (zero after the secant):

    gamma_err = gamma sqrt(((F_err / F_p)^2 + (P_err / P)^2) / s^2 + step^2)

Beside it, what the closed forms would have said: DMT's w = P / (2 pi R), JKR's
w = P / (1.5 pi R) and Maugis-Dugdale's, solved self-consistently in the same way with
its pull-off at lambda_MD = 1.157 mu (:mod:`~petsc_adhesion.model.reference.maugis_dugdale`;
a smooth surface: the roughness does not enter it).

With roughness, gamma's model spread (``spread_rules``;
:mod:`~petsc_adhesion.tracing.model_spread`): the same root solve under each other
roughness law, on the grid without bars, the largest distance from gamma and the
warning of a curve's spread (beyond ten of gamma's bars or 10 % of it).

Many pull-offs at once (a force map's adhesion): :func:`gamma_from_pull_offs`, by the
table alone, each value with the table's bar and the measurement's carried into w.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from .. import brent
from ..model.parameters import Model, tabor
from ..model.physical import Bodies
from ..model.reference.maugis_dugdale import maugis_dugdale_pull_off
from ..tracing.measured import Measured, Missing
from ..family.pull_off import F_STOP, PullOffTable, describes
from .forward import curve_stop_reason, pull_off_values
from .results import BOUND_MARGIN, Z95, ClosedForm, PullOffFit, undetermined

if TYPE_CHECKING:                    # tracing.model_spread traces curves: loaded where a spread is made
    from ..tracing.model_spread import ModelSpread

__all__ = ["PullOffFit", "PullOffFitError", "PullOffCurveError", "fit_pull_off", "model_pull_off", "maugis_dugdale_gamma", "MU_RANGE",
           "closed_forms", "PullOffMap", "gamma_from_pull_offs"]

#: The Tabor parameters the model is solved for: from -adh_mu's least positive value (below the pull-off table's
#: 1e-3 by the solver's secant alone) to the table's and the forward model's 1000 (docs/soft.md).
MU_RANGE = (1e-12, 1000.0)
#: Half the step in ln w of the derivative d ln|F_p| / d ln w (so mu moves by 2/3 of it).
_DLOGW = 0.02


class PullOffFitError(ValueError):
    """A pull-off no work of adhesion gives within the model's range; one line."""


class PullOffCurveError(RuntimeError):
    """The model's pull-off at a work of adhesion the fit needed could not be computed (the solver's curve
    failed there, and where the secant could, at the points it tried instead); one line naming w and why."""


def model_pull_off(model: Model, grid=None, solver=None, error_bars: bool = False, comm=None):
    """The load-controlled pull-off of ``model`` (its most tensile F_min, an
    :class:`~petsc_adhesion.tracing.curve.Event`): the curve traced until the load rises back through the
    table's F_STOP, with the steps of a soft sphere scaled by mu as the library's (the pull-off table's nodes
    are the same curves)."""
    from ..discretization.problem import step_scale
    from ..tracing.trace import CurveRequest, GridChoice, SolverChoice, curve_settings, trace_curve

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        c = trace_curve(model, grid or GridChoice(), solver or SolverChoice(),
                        curve_settings(step_scale(model), observable_max=F_STOP),
                        CurveRequest(error_bars=error_bars, kinds=("F_min",)), comm=comm)
    if c.pull_off is None:
        raise RuntimeError(f"the curve at mu = {model.mu:.6g} has no pull-off ({curve_stop_reason(c)})")
    return c.pull_off


def closed_forms(P: float, bodies: Bodies) -> tuple:
    """What DMT, JKR and Maugis-Dugdale give for the work of adhesion of the pull-off P (N) of ``bodies``
    (their R, E, epsilon): a :class:`~petsc_adhesion.fitting.results.ClosedForm` each."""
    R = bodies.R

    def mu(w):
        return tabor(R, w, bodies.E, bodies.epsilon)

    out = []
    for name, factor in (("dmt", 2.0), ("jkr", 1.5)):
        w = P / (factor * math.pi * R)
        out.append(ClosedForm(name, w, mu(w), f"P / ({factor:g} pi R)"))
    w = maugis_dugdale_gamma(P, R, bodies.E, bodies.epsilon)
    out.append(ClosedForm("maugis_dugdale", w, mu(w), "P = 2 pi R w |F_MD(1.157 mu(w))|", 1.157 * mu(w)))
    return tuple(out)


def maugis_dugdale_gamma(P: float, R: float, E: float, epsilon: float) -> float:
    """The w of 2 pi R w |F_MD(mu(w))| = P with Maugis-Dugdale's pull-off (lambda_MD = 1.157 mu): it lies
    between DMT's P / (2 pi R) and JKR's P / (1.5 pi R)."""
    def g(lnw):
        w = math.exp(lnw)
        return 2 * math.pi * R * w * abs(float(maugis_dugdale_pull_off(tabor(R, w, E, epsilon)))) - P

    lo, hi = math.log(P / (2 * math.pi * R)), math.log(P / (1.5 * math.pi * R))
    glo, ghi = g(lo), g(hi)
    if glo >= 0:
        return math.exp(lo)
    if ghi <= 0:
        return math.exp(hi)
    return math.exp(brent.root(g, lo, hi, xtol=1e-12))


def fit_pull_off(P: float, bodies: Bodies, P_err: float = 0.0, model: Model | None = None, grid=None, solver=None,
                 comm=None, rtol: float = 1e-7, spread_rules: tuple | None = None, table: PullOffTable | None = None,
                 use_table: bool = True) -> PullOffFit:
    """The work of adhesion whose model pull-off is the measured ``P`` (N, its magnitude), with its bar (see
    the module for the equations).

    Parameters
    ----------
    P, P_err
        The measured pull-off force's magnitude and its standard uncertainty (N; 0: exact).
    bodies : Bodies
        Radii, moduli, epsilon and the rms roughness (SI); its work of adhesion is ignored.
    model : Model
        The roughness average and domain (its mu, sigma and bodies are replaced); default the smooth model.
    grid, solver, comm
        As :func:`~petsc_adhesion.tracing.trace.trace_curve`'s.
    rtol
        The relative tolerance of w on the grid (the secant's, where the table does not describe the model).
    spread_rules
        The roughness laws (:class:`~petsc_adhesion.tracing.model_spread.Rule`) gamma is solved for again,
        its model spread (None: none; a rough model only).
    table, use_table
        The pull-off table the start is read from (None: the package's, :meth:`PullOffTable.default`);
        ``use_table`` False: the secant from Maugis-Dugdale's w alone (the path before the table).

    Returns the :class:`~petsc_adhesion.fitting.results.PullOffFit`, its ``warnings`` saying where it does
    not hold (mu at a bound of the model's range; w undetermined, Missing then).  Raises
    :class:`PullOffFitError` (one line) for a P no w gives: P <= 0 or not finite, or a w whose mu would leave
    [1e-12, 1000].
    """
    t0 = time.perf_counter()
    if not (math.isfinite(P) and P > 0):
        raise PullOffFitError(f"the pull-off force must be a finite positive magnitude (N), got {P!r}")
    if not (math.isfinite(P_err) and P_err >= 0):
        raise PullOffFitError(f"the pull-off's uncertainty must be finite and >= 0 (N), got {P_err!r}")
    template = model or Model()
    R, E, eps = bodies.R, bodies.E, bodies.epsilon
    sigma = bodies.sigma if bodies.sigma is not None else template.sigma
    history = []

    def mu_of(w):
        return tabor(R, w, E, eps)

    def w_of(mu):
        return math.sqrt(mu**3 * E**2 * eps**3 / R)

    lo_w, hi_w = w_of(MU_RANGE[0]), w_of(MU_RANGE[1])

    def model_at(w, law=template):
        return replace(law, mu=mu_of(w), sigma=sigma, bodies=replace(bodies, gamma=w, hamaker=None))

    cache = {}

    def curve_at(w: float, error_bars: bool = False):
        """The model's pull-off event at w; PullOffCurveError (one line naming w) where its curve fails."""
        try:
            return model_pull_off(model_at(w), grid, solver, error_bars=error_bars, comm=comm)
        except RuntimeError as why:
            raise PullOffCurveError(f"the model's pull-off at w = {w:.6g} J/m^2 (mu = {mu_of(w):.6g}) could not be "
                                    f"computed: {str(why).splitlines()[0] if str(why) else type(why).__name__}") from None

    def pull(lnw: float) -> float:
        """|F_p| on the grid at w = exp(lnw)."""
        if lnw not in cache:
            w = math.exp(lnw)
            e = curve_at(w)
            cache[lnw] = abs(pull_off_values(e)[0])
            history.append((w, mu_of(w), pull_off_values(e)[0]))
        return cache[lnw]

    def g(lnw: float) -> float:
        return math.log(2 * math.pi * R * math.exp(lnw) * pull(lnw) / P)

    def root_under(law: Model, x0: float) -> float:
        """w of the same root solve under another roughness law, on the grid (no bar)."""
        def g_law(lnw: float) -> float:
            F = pull_off_values(model_pull_off(model_at(math.exp(lnw), law), grid, solver, comm=comm))[0]
            return math.log(2 * math.pi * R * math.exp(lnw) * abs(F) / P)
        return math.exp(_solve(g_law, x0, math.log(lo_w), math.log(hi_w), rtol, P, mu_of))

    start = _table_start(P, bodies, sigma, table, mu_of) if use_table else None
    w_md = maugis_dugdale_gamma(P, R, E, eps)
    if start is None and w_md > hi_w * 1.5:
        raise PullOffFitError(f"P = {P:.4g} N needs a work of adhesion near {w_md:.3g} J/m^2 (Maugis-Dugdale), "
                              f"where mu = {mu_of(w_md):.3g} by eq. (9) is above {MU_RANGE[1]:g}, the model's "
                              f"range (-adh_mu)")
    if start is not None and describes(replace(template, sigma=sigma)):
        lnw, F_best, F_err, Fg, slope_w, step, traced = _table_path(start, g, pull, lambda w: curve_at(w, True), P, R)
        curves = traced
    else:
        x0 = start[0] if start is not None else math.log(min(max(w_md, lo_w), hi_w))
        lnw = _solve(g, x0, math.log(lo_w), math.log(hi_w), rtol, P, mu_of)
        w = math.exp(lnw)
        # the best pull-off at the root (extrapolated over nested grids), its bar, and the slope of |F_p| in mu
        best = curve_at(w, True)
        F_best, F_err, Fg = pull_off_values(best)
        up = min(lnw + _DLOGW, math.log(hi_w))
        down = max(lnw - _DLOGW, math.log(lo_w))
        slope_w = 1.0 + (math.log(pull(up)) - math.log(pull(down))) / (up - down)     # d ln(w |F_p|) / d ln w
        if slope_w <= 0:
            raise PullOffFitError(f"P = {P:.4g} N: the model's pull-off falls faster than 1/w about w = {w:.4g} "
                                  f"J/m^2 (mu = {mu_of(w):.3g}): the pull-off does not determine w there")
        lnw -= math.log(abs(F_best) / abs(Fg)) / slope_w       # one Newton step onto the best pull-off
        step, curves = 0.0, len(cache) + 1
    w = math.exp(lnw)
    gamma, warned = _verdict(w, F_best, F_err, P, P_err, slope_w, mu_of(w), step)
    spread = None if spread_rules is None else \
        _gamma_spread(gamma, replace(template, sigma=sigma), tuple(spread_rules), lambda law: root_under(law, lnw))
    return PullOffFit(P=Measured(P, P_err), gamma=gamma, mu=mu_of(w), sigma=sigma,
                      F=Measured(F_best, F_err, Fg, None if F_err is not None else "no bar: the grids did not nest"),
                      dlnF_dlnmu=(slope_w - 1.0) * 1.5, closed_forms=closed_forms(P, bodies), curves=curves,
                      wall_time_s=time.perf_counter() - t0, bodies=replace(bodies, gamma=w, hamaker=None),
                      history=tuple(history), warnings=tuple(warned), spread=spread)


def _table_start(P: float, bodies: Bodies, sigma: float, table, mu_of) -> tuple | None:
    """(ln w, d ln(w |F_p|) / d ln w) of the table's inversion of P, or None where the table does not hold the
    root (mu outside its range, or sigma beyond it) or is not installed: the secant then starts from
    Maugis-Dugdale; PullOffFitError where the root lies above mu = 1000, the model's range."""
    try:
        tab = table if table is not None else PullOffTable.default()
    except FileNotFoundError:           # a package installed without its data: the secant alone, as before
        return None
    found = gamma_from_pull_offs(np.array([P]), replace(bodies, rms=sigma * bodies.epsilon), 0.0, tab)
    if found.found[0]:
        mu = float(found.mu[0])
        return math.log(float(found.gamma[0])), 1.0 + float(tab.slope(mu, sigma)) / 1.5
    if found.side[0] > 0 and float(tab.mu[-1]) >= MU_RANGE[1] * (1 - 1e-9):
        raise PullOffFitError(f"P = {P:.4g} N needs a work of adhesion where mu is above {tab.mu[-1]:g} (the "
                              f"pull-off table's inversion), the model's range (-adh_mu)")
    return None


def _table_path(start: tuple, g, pull, best_at, P: float, R: float) -> tuple:
    """The root from the table's start (ln w0, its slope s): the best pull-off at w0 (one curve with error
    bars), a Newton step with the table's slope, the pull-off on the grid there (a second curve, scaled by the
    first's best over grid), a second Newton step; (ln w, F_best, F_err, F on the grid, slope, |last step|,
    curves traced).  The last step bounds what the iteration leaves (it contracts by the table slope's
    relative error, a few per cent), and enters the bar."""
    lnw0, slope = start
    best = best_at(math.exp(lnw0))
    F_best, F_err, Fg = pull_off_values(best)
    g0 = math.log(2 * math.pi * R * math.exp(lnw0) * abs(F_best) / P)
    lnw1 = lnw0 - g0 / slope
    if abs(lnw1 - lnw0) <= 1e-9:
        return lnw1, F_best, F_err, Fg, slope, abs(lnw1 - lnw0), 1
    ratio = abs(F_best) / abs(Fg)                     # the extrapolation's correction, nearly constant in w
    g1 = g(lnw1) + math.log(ratio)
    lnw2 = lnw1 - g1 / slope
    F1 = -pull(lnw1)
    return lnw2, F1 * ratio, F_err, F1, slope, abs(lnw2 - lnw1), 2


@dataclass(frozen=True)
class PullOffMap:
    """The works of adhesion of many pull-offs (a map of them) from the pull-off table, entry by entry in the
    shape of the pull-offs given: ``gamma`` (J/m^2) and its bar ``gamma_err`` (the table's bar and the
    measurement's carried into w), ``table_err`` (the table's share alone), ``mu`` (eq. 9 at gamma) and ``F``
    (the table's pull-off there, units 2 pi R w), NaN where the entry was not found; ``reasons`` ('' where
    found, else why: no positive force, a root outside the table, w undetermined); ``side`` of a root outside
    the table (-1 below its mu, +1 above, 0 inside); ``sigma`` the roughness of the map, ``table_version`` the
    program version that built the table."""

    gamma: np.ndarray = field(repr=False)
    gamma_err: np.ndarray = field(repr=False)
    table_err: np.ndarray = field(repr=False)
    mu: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    reasons: np.ndarray = field(repr=False)
    side: np.ndarray = field(repr=False)
    sigma: float
    table_version: str

    @property
    def found(self) -> np.ndarray:
        """Whether each entry has a work of adhesion."""
        return self.reasons == ""

    def quantity(self, index) -> Measured | Missing:
        """Entry ``index``'s work of adhesion: Measured (value, bar, a note on the table) or Missing (why)."""
        if self.reasons[index]:
            return Missing(str(self.reasons[index]))
        return Measured(float(self.gamma[index]), float(self.gamma_err[index]),
                        note=f"from the pull-off table (its share of the bar {float(self.table_err[index]):.2g})")

    def quantities(self) -> tuple:
        """Every entry's :meth:`quantity`, in the flattened order of the map."""
        return tuple(self.quantity(np.unravel_index(k, self.gamma.shape)) for k in range(self.gamma.size))


def gamma_from_pull_offs(P, bodies: Bodies, P_err=0.0, table: PullOffTable | None = None) -> PullOffMap:
    """The work of adhesion of every pull-off in ``P`` (N, magnitudes; any shape), by the pull-off table alone
    (no curve traced: a map's inversion in milliseconds), for one pair of ``bodies`` (R, E from eq. 2, epsilon,
    the rms held: sigma = rms / epsilon).

    With w = c mu^(3/2), c = (E^2 eps^3 / R)^(1/2) (eq. 9), each entry solves

        h(ln mu) = (3/2) ln mu + ln |F_po(mu, sigma)| - ln(P / (2 pi R c)) = 0

    by bisection over the table's mu, all entries at once (h rises: its slope is 1 + ... of d ln(w |F|) / d ln w
    times 3/2, positive wherever the pull-off falls slower than 1/w: over the table, checked by the tests).  The
    bar of w, relative: sqrt((F_err / |F|)^2 + (P_err / P)^2) / (1 + (2/3) d ln|F| / d ln mu), F_err the
    table's bar (its nodes' solver bars and its interpolation error); ``table_err`` the same without P_err.
    A P that is not finite and positive, a root outside the table, or a 95% interval wider than w is an entry
    without a value and with its reason (``reasons``); a sigma outside the table leaves every entry so."""
    tab = table if table is not None else PullOffTable.default()
    P = np.asarray(P, float)
    P, P_err = np.broadcast_arrays(P, np.asarray(P_err, float))
    sigma = float(bodies.sigma or 0.0)
    R, c = bodies.R, math.sqrt(bodies.E**2 * bodies.epsilon**3 / bodies.R)
    shape = P.shape
    reasons = np.full(shape, "", dtype=object)
    side = np.zeros(shape, int)
    nan = np.full(shape, np.nan)
    gamma, err, terr, mu_out, F_out = nan.copy(), nan.copy(), nan.copy(), nan.copy(), nan.copy()
    with np.errstate(invalid="ignore"):
        bad = ~(np.isfinite(P) & (P > 0))
        bad_err = ~(np.isfinite(P_err) & (P_err >= 0))
    reasons[bad] = "not a finite positive pull-off force"
    reasons[~bad & bad_err] = "its uncertainty is not finite and >= 0"
    if not bool(tab.covers(tab.mu[0], sigma)):
        reasons[reasons == ""] = (f"sigma = {sigma:.4g} lies outside the pull-off table's [{tab.sigma[0]:g}, "
                                  f"{tab.sigma[-1]:g}]")
    todo = reasons == ""
    if np.any(todo):
        target = np.log(P[todo] / (2 * math.pi * R * c))
        lo, hi = math.log(tab.mu[0]), math.log(tab.mu[-1])

        def h(x):
            return 1.5 * x + tab.ln_pull_off(np.exp(x), sigma) - target
        h_lo, h_hi = h(np.full(target.shape, lo)), h(np.full(target.shape, hi))
        below, above = h_lo > 0, h_hi < 0
        a, b = np.full(target.shape, lo), np.full(target.shape, hi)
        for _ in range(48):                    # the bracket halved to 4e-15 of the table's ln mu range
            m = 0.5 * (a + b)
            up = h(m) > 0
            b, a = np.where(up, m, b), np.where(up, a, m)
        x = np.clip(0.5 * (a + b), lo, hi)
        mu = np.exp(x)
        F, F_err = tab.pull_off(mu, sigma)
        slope_w = 1.0 + tab.slope(mu, sigma) / 1.5
        w = c * mu**1.5
        rel_t = (F_err / np.abs(F)) / slope_w
        rel = np.hypot(F_err / np.abs(F), P_err[todo] / P[todo]) / slope_w
        idx = np.flatnonzero(todo.ravel())
        r = reasons.ravel()
        for k, flat in enumerate(idx):
            if below[k]:
                r[flat] = (f"P = {P.ravel()[flat]:.4g} N needs mu below {tab.mu[0]:g}, the pull-off table's least "
                           f"(fit_pull_off solves it with the solver)")
                side.ravel()[flat] = -1
            elif above[k]:
                r[flat] = (f"P = {P.ravel()[flat]:.4g} N needs mu above {tab.mu[-1]:g}, the pull-off table's "
                           f"largest")
                side.ravel()[flat] = 1
            elif not (slope_w[k] > 0 and np.isfinite(rel[k])):
                r[flat] = "the table's pull-off falls faster than 1/w there: the pull-off does not determine w"
            elif Z95 * rel[k] > 1.0:
                r[flat] = f"its 95% interval +-{Z95 * rel[k] * w[k]:.3g} is wider than its value {w[k]:.3g}"
            else:
                gamma.ravel()[flat], err.ravel()[flat], terr.ravel()[flat] = w[k], w[k] * rel[k], w[k] * rel_t[k]
                mu_out.ravel()[flat], F_out.ravel()[flat] = mu[k], F[k]
    return PullOffMap(gamma, err, terr, mu_out, F_out, reasons, side, sigma, tab.version)


def _gamma_spread(gamma, model: Model, rules: tuple, root) -> ModelSpread | Missing:
    """gamma's model spread: ``root(law)``, the work of adhesion of the same pull-off under each law of
    ``rules`` (the curves on the grid, no bars), against ``gamma`` under ``model``'s law, with the warning
    rule of a curve's spread (ten bars or 10 %); a law whose root fails is Missing with its reason."""
    from ..tracing.model_spread import ModelSpread, Rule, spread_quantity

    reference = Rule.of(model)
    if model.roughness == "none" or model.sigma == 0:
        return Missing("a smooth surface (sigma = 0): there is no roughness law to vary")
    if reference in rules:
        raise ValueError(f"{reference.label}: the reference's own law, not an alternative to it")
    if isinstance(gamma, Missing):
        return Missing(f"gamma is undetermined under {reference.label}: no value to spread about")
    values: list[Measured | Missing] = []
    notes, times = [], []
    t0 = time.perf_counter()
    for rule in rules:
        t = time.perf_counter()
        try:
            values.append(Measured(root(rule.model(model))))
        except (PullOffFitError, RuntimeError, FloatingPointError) as why:
            values.append(Missing(f"{rule.label}: {why}"))
            notes.append(f"{rule.label}: gamma could not be solved for ({why})")
        times.append(time.perf_counter() - t)
    q = spread_quantity("work of adhesion gamma", "gamma", gamma, tuple(values), rules, reference)
    return ModelSpread(reference, rules, (q,), tuple(notes), time.perf_counter() - t0, tuple(times))


def _verdict(w: float, F: float, F_err: float | None, P: float, P_err: float, slope_w: float,
             mu: float, step: float = 0.0) -> tuple:
    """(gamma: Measured, or Missing where mu is at a bound of the model's range or w undetermined; the
    warnings that say so).  The bar: sqrt(((F_err / F)^2 + (P_err / P)^2) / slope_w^2 + step^2) relative, step
    the root iteration's last step in ln w (what it may leave)."""
    rel = math.hypot(math.hypot((F_err or 0.0) / abs(F), P_err / P) / slope_w, step)
    err = w * rel if (F_err is not None or P_err > 0) else None
    why: str | None
    lo, hi = (math.log(m) for m in MU_RANGE)
    if math.log(mu) - lo <= BOUND_MARGIN or hi - math.log(mu) <= BOUND_MARGIN:
        edge = MU_RANGE[0] if math.log(mu) - lo <= BOUND_MARGIN else MU_RANGE[1]
        why = (f"mu = {mu:.4g} is at the bound {edge:g} of the model's range [{MU_RANGE[0]:g}, {MU_RANGE[1]:g}]: "
               f"the pull-off asks for a mu the model does not reach")
    elif err is None:
        return Measured(w, None, note="no bar: neither the pull-off's nor the measurement's"), []
    else:
        why = undetermined(w, err)
    if why is None:
        return Measured(w, err), []
    return Missing(why), [f"gamma undetermined: {why}"]


#: Where the curve at a secant iterate fails, the iterate is moved this share of the way back to the last
#: one, at most RETRIES times; a failing start moves RETRY_STEP in ln w (2% in w).
RETRIES, RETRY_STEP = 3, 0.02


def _tried(g, x: float, back: float) -> tuple:
    """(x, g(x)) for the secant, or, where the curve at x fails (:class:`PullOffCurveError`: one solver failure
    at one w, a fold pair it could not resolve, says nothing of the root), for a point moved half of the way
    back towards ``back`` and again, RETRIES times; the first failure's error if all fail."""
    first: PullOffCurveError | None = None
    for _ in range(RETRIES + 1):
        try:
            return x, g(x)
        except PullOffCurveError as why:
            first = first or why
            x = back + 0.5 * (x - back)
    assert first is not None, "the loop ran at least once"
    raise first


def _solve(g, x0: float, lo: float, hi: float, rtol: float, P: float, mu_of) -> float:
    """The root of g in ln w: secant steps from x0 (g is nearly ln w + const: its slope is 1 + (2/3) d ln|F_p|
    / d ln mu), then Brent's method on a bracket when the secant does not settle."""
    x0, g0 = _tried(g, x0, min(x0 + RETRY_STEP, hi) if x0 < hi else x0 - RETRY_STEP)
    xs, gs = [x0], [g0]
    x1 = min(max(x0 - gs[0], lo), hi)             # a unit slope's step
    if x1 == x0:
        x1 = x0 - math.copysign(1e-3, gs[0])
    x1, g1 = _tried(g, x1, x0)
    xs.append(x1)
    gs.append(g1)
    for _ in range(12):
        if abs(gs[-1]) < rtol or abs(xs[-1] - xs[-2]) < rtol:
            return xs[-1]
        if gs[-1] == gs[-2]:
            break
        x = xs[-1] - gs[-1] * (xs[-1] - xs[-2]) / (gs[-1] - gs[-2])
        if not lo <= x <= hi:
            edge = hi if x > hi else lo
            if g(edge) * (1 if x > hi else -1) < 0:     # the root is past the edge of the model's range
                side = "above" if x > hi else "below"
                raise PullOffFitError(f"P = {P:.4g} N needs mu {side} {mu_of(math.exp(edge)):.3g} "
                                      f"(w = {math.exp(edge):.3g} J/m^2 gives a pull-off still too "
                                      f"{'small' if x > hi else 'large'}): outside the model's range of mu "
                                      f"[{MU_RANGE[0]:g}, {MU_RANGE[1]:g}] (-adh_mu)")
            x = edge
        x, gx = _tried(g, x, xs[-1])
        xs.append(x)
        gs.append(gx)
    # no settling: a bracket from the points seen, then Brent
    pts = sorted(zip(xs, gs))
    for (a, ga), (b, gb) in zip(pts, pts[1:]):
        if ga * gb <= 0:
            return brent.root(g, a, b, xtol=rtol)
    raise PullOffFitError(f"P = {P:.4g} N: no work of adhesion found in mu [{MU_RANGE[0]:g}, {MU_RANGE[1]:g}]")
