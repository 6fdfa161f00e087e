"""The work of adhesion and the modulus from a measured force-distance curve: the model behind the cantilever,
fitted by bounded least squares.

The measured force at piezo position z is modelled as

    F(z) = F_0 + 2 pi R w f(Z; mu, K, sigma),   Z = s (z - z_0) / eps

with f the model's force against the base position Z of a spring of stiffness
K = k eps / (2 pi R w) on the approach or the retract
(:class:`~petsc_adhesion.fitting.forward.ForwardCurve`: its jumps vertical in F at
constant Z), mu by eq. (9) from w and the reduced modulus E*, sigma = rms / eps,
s the direction of the approach, z_0 the contact point (where the undeflected
spring holds the undeformed sphere at the flat, lambda = 0) and F_0 the force
baseline.  The unknowns are w and E* (optionally the rms roughness), with z_0 and
F_0 as nuisance parameters; R, eps and k are given.  They are fitted in
x = (ln mu, ln w, [sigma], z_0 / eps, F_0 / s_F) by scipy's trust-region reflective
least squares within bounds (mu in [1e-3, 50], the model's range; sigma in [0, 3]),
on the residuals (F_model - F_i) / s_F, s_F the noise of the far baseline.

Each evaluation at new (mu, K, sigma) traces one curve behind the spring (no error
bars; cached).  The Jacobian's columns in ln mu, ln w and sigma are forward
differences (relative step 2e-3) of the prediction *with each point kept on the
branch it was on* (a jump does not move across a point within a difference), those
of z_0 and F_0 exact on the traced curve.  Bars from the Jacobian at the optimum:
covariance s^2 (J^T J)^-1, s^2 = sum of squared residuals / (n - p), carried to
(ln E*, ln w) by the linear map of eq. (9), ln E* = ln w + (ln R - 3 ln mu - 3 ln eps)/2;
the bar of w is w sd(ln w), that of E* is E* sd(ln E*) (a 95% interval is +-1.96 bars;
docs/fitting.md measures how often it holds).  The result is a
:class:`~petsc_adhesion.fitting.results.CurveFit`, each quantity Measured or Missing where a
parameter is at a bound or undetermined, with a warning for each, and for a chi^2 the noise
cannot explain (:mod:`~petsc_adhesion.fitting.results`).
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..model.parameters import Model, tabor
from ..model.physical import Bodies
from ..tracing.measured import Measured, Missing
from .data import MeasuredCurve
from .forward import APPROACH, RETRACT, ForwardCurve, curve_stop_reason
from .pull_off import maugis_dugdale_gamma
from .results import (BOUND_MARGIN, NOISE_DOF_PER_DIFFERENCE, CurveFit, Features, FitChoice, FittedFeatures,
                      Spring, misfit, misfit_p, undetermined)

if TYPE_CHECKING:
    from ..tracing.trace import GridChoice, SolverChoice

__all__ = ["CurveFit", "CurveFitError", "FittedModel", "fit_curve", "features", "MU_BOUNDS", "SIGMA_MAX",
           "predict_curve"]

#: The Tabor parameters a fit may reach (the model's range; below 1e-3 the sphere is rigid to 1e-4 in its load).
MU_BOUNDS = (1e-3, 50.0)
#: The largest roughness sigma = rms / eps fitted.
SIGMA_MAX = 3.0
#: Relative step of the Jacobian's differences in ln mu, ln w (and the step in sigma).
_STEP = 2e-3
#: The points before each measured jump always left out of the fit.
EDGE_POINTS = 3
#: Noise multiples that make a contact, an adhesion.
_SIGNAL = 5.0
#: A force that is a straight line in the piezo position on both legs to this share of its range is no
#: force-distance curve (two columns of one quantity): no cantilever's noise is that small.
_LINEAR = 1e-9


class CurveFitError(ValueError):
    """A curve the fit cannot use; one line."""


def features(data: MeasuredCurve) -> Features:
    """What the measured curve shows by itself (SI): the baseline ``F0_N`` and ``noise_N`` (from the farthest
    30% of the approach: the median, and the spread of successive differences), the largest force above the
    baseline ``contact_N``; the pull-off ``pull_off_N`` (the least force of the retract, below the baseline)
    and its position ``pull_off_z_m``; the jump-in ``jump_in_z_m`` (the largest drop of the force between
    successive approach points before its largest force) and its size ``jump_in_drop_N``; and, where the
    force jumps by more than 10 noise between two points, the index of the first approach point in contact
    ``contact_from`` and of the first retract point off it ``free_from`` (None where it does not jump); the
    noise estimate's effective degrees of freedom ``noise_dof`` (docs/fitting.md)."""
    z, F, s = data.z, data.F, data.direction
    za, Fa = z[data.approach], F[data.approach]
    zr, Fr = z[data.retract], F[data.retract]
    depth = s * (za - za[0])                              # how far the approach went, from its start
    far = depth <= 0.3 * depth.max()
    if far.sum() < 5:
        far = np.arange(za.size) < max(5, za.size // 3)
    F0 = float(np.median(Fa[far]))
    d = np.diff(Fa[far])
    noise = float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2)) if d.size > 2 else 0.0
    note = None
    if noise <= 0:
        noise = 1e-3 * float(np.ptp(F)) or 1.0
        note = (f"the baseline shows no noise (its successive differences do not spread): the noise is taken as "
                f"1e-3 of the force's range, {noise:.3g} N, and chi^2 and the bars are in units of that")
    rises = np.diff(Fr)
    i_off = int(np.argmax(rises))                         # the last retract point in contact
    top = int(np.argmax(Fa))
    drops = np.diff(Fa[: top + 1])
    i_in = int(np.argmin(drops)) if drops.size else 0
    drop = float(-drops[i_in]) if drops.size else 0.0
    rise = float(rises[i_off])
    return Features(F0_N=F0, noise_N=noise, noise_dof=NOISE_DOF_PER_DIFFERENCE * max(d.size, 1),
                    contact_N=float(Fa.max() - F0), pull_off_N=float(F0 - Fr.min()), pull_off_z_m=float(zr[i_off]),
                    pull_off_at_N=float(Fr[i_off]), jump_in_z_m=float(za[i_in]), jump_in_drop_N=drop,
                    jump_off_rise_N=rise, contact_from=i_in + 1 if drop > 10 * noise else None,
                    free_from=i_off + 1 if rise > 10 * noise else None, noise_note=note)


@dataclass
class _Problem:
    """The data, the constants and the cache of traced curves of one fit."""

    data: MeasuredCurve
    bodies: Bodies
    spring: Spring
    template: Model
    grid: GridChoice
    solver: SolverChoice
    comm: object
    E_fixed: float | None
    fit_sigma: bool
    sigma_fixed: float
    noise: float
    feat: Features
    Fmax_data: float
    cache: dict = field(default_factory=dict)
    traces: int = 0
    notes: list = field(default_factory=list)

    def __post_init__(self):
        self.legs = np.r_[np.zeros(self.data.turn, int), np.ones(self.data.z.size - self.data.turn, int)]
        # the branch each point is on, as the measured jumps say: 0 off the contact, 1 in contact, -1 where
        # the curve shows no jump (there the model's own jumps decide)
        self.R, self.eps = self.bodies.R, self.bodies.epsilon
        feat = self.feat
        turn, n = self.data.turn, self.data.z.size
        self.labels = np.full(n, -1)
        if feat.contact_from is not None:
            self.labels[:turn] = np.arange(turn) >= feat.contact_from
        if feat.free_from is not None:
            self.labels[turn:] = np.arange(n - turn) < feat.free_from
        self.weight = np.ones(n)
        self.names = (() if self.E_fixed is not None else ("ln_mu",)) + ("ln_gamma",) + \
            (("sigma",) if self.fit_sigma else ()) + ("z0", "F0")
        self.jumps = self.measured_jumps()

    def leave_out_edges(self, x) -> None:
        """Leave out of the fit the points just before each measured jump, where the branch is steeper than the
        spring in the model at ``x`` (|dF/dZ| > K: the force goes as the square root of the distance to the
        turning point, and a real cantilever jumps early, by thermal activation), and at least the last
        EDGE_POINTS before it.  Fixed for the whole fit."""
        p = self.unpack(x)
        fc = self.forward(p)
        Z = self.Z(p)
        turn, n = self.data.turn, self.data.z.size
        self.weight = np.ones(n)
        i = self.feat.contact_from
        if i is not None:
            jump = 0.5 * (Z[i - 1] + Z[i])
            near = (np.arange(n) < i) & (jump - Z <= fc.steep(APPROACH))
            near[max(i - EDGE_POINTS, 0):i] = True
            self.weight[near] = 0.0
        i = self.feat.free_from
        if i is not None:
            jump = 0.5 * (Z[turn + i - 1] + Z[turn + i])
            near = (np.arange(n) >= turn) & (np.arange(n) < turn + i) & (Z - jump <= fc.steep(RETRACT))
            near[turn + max(i - EDGE_POINTS, 0):turn + i] = True
            self.weight[near] = 0.0

    # x -> physical parameters
    def unpack(self, x) -> dict:
        x = dict(zip(self.names, x))
        w = math.exp(x["ln_gamma"])
        if self.E_fixed is None:
            mu = math.exp(x["ln_mu"])
            E = w * math.sqrt(self.R / (mu**3 * self.eps**3))
        else:
            E = self.E_fixed
            mu = tabor(self.R, w, E, self.eps)
        sigma = x["sigma"] if self.fit_sigma else self.sigma_fixed
        return {"w": w, "E": E, "mu": mu, "sigma": max(sigma, 0.0), "K": self.spring.K(self.bodies, w),
                "z0": x["z0"] * self.eps, "F0": x["F0"] * self.noise}

    def forward(self, p: dict) -> ForwardCurve:
        key = (round(p["mu"], 12), round(math.log(p["K"]), 12), round(p["sigma"], 12))
        if key not in self.cache:
            from ..tracing.trace import CurveRequest, curve_settings, trace_curve

            f_max = max(1.3 * (self.Fmax_data - p["F0"]) / (2 * math.pi * self.R * p["w"]) + 0.3, 0.5)
            model = replace(self.template, mu=p["mu"], sigma=p["sigma"], bodies=None)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                c = trace_curve(model, self.grid, self.solver, curve_settings(observable_max=f_max),
                                CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=p["K"]),
                                comm=self.comm)
            self.traces += 1
            if not c.complete:
                self.notes.append(f"the curve at mu = {p['mu']:.4g}, K = {p['K']:.4g} ended early "
                                  f"({curve_stop_reason(c)}); continued linearly")
            if len(self.cache) > 64:
                self.cache.pop(next(iter(self.cache)))
            self.cache[key] = ForwardCurve(c, p["K"])
        return self.cache[key]

    def Z(self, p: dict) -> np.ndarray:
        return self.data.direction * (self.data.z - p["z0"]) / self.eps

    def assign(self, fc: ForwardCurve, Z: np.ndarray) -> np.ndarray:
        """The piece of every point: the far branch (the first piece) or the contact (the last) as the measured
        jumps say, else (a leg without a jump) the piece the model's own jumps put it on."""
        pieces = np.where(self.labels == 1, len(fc.pieces) - 1, 0)
        for leg, name in ((0, APPROACH), (1, RETRACT)):
            own = (self.legs == leg) & (self.labels < 0)
            if own.any():
                pieces[own] = fc.assign(Z[own], name)
        return pieces

    def model_force(self, p: dict, pieces: np.ndarray | None = None, fc: ForwardCurve | None = None):
        """(the model's force at every point in N, the pieces they are on)."""
        fc = fc or self.forward(p)
        Z = self.Z(p)
        if pieces is None:
            pieces = self.assign(fc, Z)
        return p["F0"] + 2 * math.pi * self.R * p["w"] * fc.evaluate(Z, pieces), pieces

    def measured_jumps(self) -> list[tuple[str, float, float]]:
        """The jumps the curve shows: (leg, piezo position between the two points about it, its uncertainty: the
        distance of the two over sqrt(12), the spread of a position anywhere between them)."""
        out, turn = [], self.data.turn
        for leg, i in ((APPROACH, self.feat.contact_from), (RETRACT, self.feat.free_from)):
            if i is not None:
                j = i if leg == APPROACH else turn + i
                a, b = self.data.z[j - 1], self.data.z[j]
                out.append((leg, 0.5 * (a + b), abs(b - a) / math.sqrt(12.0)))
        return out

    def _all(self, p: dict, pieces: np.ndarray | None = None, fc: ForwardCurve | None = None):
        """(the residuals: the forces' in units of the noise, then each measured jump's position against the
        model's turning point in units of its uncertainty; the pieces of the points)."""
        fc = fc or self.forward(p)
        Fm, pieces = self.model_force(p, pieces, fc)
        rF = self.weight * (Fm - self.data.F) / self.noise
        rJ = []
        for leg, z, dz in self.jumps:
            cuts = fc.jumps[leg]
            model = p["z0"] + self.data.direction * self.eps * cuts[0] if cuts else z
            rJ.append((model - z) / dz)
        return np.r_[rF, rJ], pieces

    def residuals(self, x) -> np.ndarray:
        return self._all(self.unpack(x))[0]

    def jacobian(self, x) -> np.ndarray:
        """Forward differences, every point kept on its piece (see the module)."""
        x = np.asarray(x, dtype=float)
        p = self.unpack(x)
        base, pieces = self._all(p)
        J = np.empty((base.size, len(self.names)))
        n_pieces = len(self.forward(p).pieces)
        for j, name in enumerate(self.names):
            h = 1e-4 if name == "z0" else 1.0 if name == "F0" else _STEP
            xh = x.copy()
            xh[j] += h
            q = self.unpack(xh)
            fc = self.forward(q)
            rh, _ = self._all(q, pieces if len(fc.pieces) == n_pieces else None, fc)
            J[:, j] = (rh - base) / h
        return J


def fit_curve(data: MeasuredCurve, bodies: Bodies, spring: Spring, choice: FitChoice | None = None,
              model: Model | None = None, grid=None, solver=None, comm=None) -> CurveFit:
    """Fit the model to a measured force-distance curve (see the module for the model and the method).

    Parameters
    ----------
    data : MeasuredCurve
        The measurement (:func:`~petsc_adhesion.fitting.data.read_curve`).
    bodies : Bodies
        The tip's radius (and a second sphere's), epsilon; the moduli where given (E* by eq. 2: the start of
        the fit, or its value when the modulus is held; None: the start is chosen among mu = 0.1, 0.3, 1, 3);
        gamma where given (the start of w; default from the measured pull-off by Maugis-Dugdale); the rms
        roughness where given (the start with ``choice.roughness``, else held; default smooth).
    spring : Spring
        The cantilever's spring constant k (N/m).
    choice : FitChoice
        What is fitted (default: w and E*, with the noise of the far baseline).
    model : Model
        The roughness average and the domain (its mu, sigma and bodies are replaced).
    grid, solver, comm
        As :func:`~petsc_adhesion.tracing.trace.trace_curve`'s.

    Returns the :class:`~petsc_adhesion.fitting.results.CurveFit`, its ``warnings`` saying where it does not
    hold (a parameter at a bound or undetermined, Missing then; a misfit).  Raises :class:`CurveFitError`
    (one line) for a curve with no contact, no adhesion, or no force-distance relation.
    """
    from scipy.optimize import least_squares

    from ..tracing.trace import GridChoice, SolverChoice

    t0 = time.perf_counter()
    choice = choice or FitChoice()
    template = model or Model()
    grid, solver = grid or GridChoice(), solver or SolverChoice()
    modulus = bodies.E if bodies.young1 is not None else None
    if not choice.modulus and modulus is None:
        raise CurveFitError("the modulus is held but not given")
    if choice.noise is not None and not (math.isfinite(choice.noise) and choice.noise > 0):
        raise CurveFitError(f"the stated noise must be a finite positive force (N), got {choice.noise!r}")
    _refuse_a_line(data)
    feat = features(data)
    noise = feat.noise_N if choice.noise is None else float(choice.noise)
    # the most extreme of n samples of noise alone lies about sqrt(2 ln n) deviations out: a signal is beyond
    signal = (_SIGNAL + math.sqrt(2 * math.log(data.z.size))) * noise
    if feat.contact_N < signal:
        raise CurveFitError(f"no contact: the approach rises at most {feat.contact_N:.3g} N above its baseline, "
                            f"within {signal / noise:.3g} times the noise ({noise:.2g} N)")
    if feat.pull_off_N < signal:
        raise CurveFitError(f"no adhesion: the retract falls at most {feat.pull_off_N:.3g} N below the baseline "
                            f"(noise {noise:.2g} N): no pull-off, so the work of adhesion is undetermined")
    R, eps = bodies.R, bodies.epsilon
    sigma0 = 0.0 if bodies.rms is None else bodies.rms / eps
    if choice.roughness and bodies.rms is None:
        sigma0 = 0.3
    pb = _Problem(data, bodies, spring, template, grid, solver, comm,
                  None if choice.modulus or modulus is None else float(modulus),
                  choice.roughness, sigma0, noise, feat, float(data.F.max()))
    P = feat.pull_off_N

    def start(E: float) -> tuple[np.ndarray, float]:
        w = bodies.gamma if bodies.gamma is not None else maugis_dugdale_gamma(P, R, E, eps)
        mu = min(max(tabor(R, w, E, eps), MU_BOUNDS[0] * 1.01), MU_BOUNDS[1] * 0.99)
        x0 = ([] if not choice.modulus else [math.log(mu)]) + [math.log(w)] + \
            ([sigma0] if choice.roughness else []) + [0.0, feat.F0_N / noise]
        x = np.array(x0, dtype=float)
        x[-2] = _align(pb, x)
        return x, float(np.sum(pb.residuals(x) ** 2))

    if modulus is not None:
        x0, _ = start(float(modulus))
    else:
        w_guess = bodies.gamma or P / (1.75 * math.pi * R)
        tries = [start(w_guess * math.sqrt(R / (m**3 * eps**3))) for m in (0.1, 0.3, 1.0, 3.0)]
        x0 = min(tries, key=lambda t: t[1])[0]
    pb.leave_out_edges(x0)
    lo, hi = _bounds(pb, choice, modulus)
    x0 = np.clip(x0, lo + 1e-9 * (hi - lo if np.all(np.isfinite(hi - lo)) else 1), hi - 1e-9)
    res = least_squares(pb.residuals, x0, jac=pb.jacobian, bounds=(lo, hi), method="trf", x_scale="jac",
                        ftol=1e-8, xtol=1e-8, gtol=1e-8, max_nfev=choice.max_evaluations)
    x = res.x
    p = pb.unpack(x)
    r = pb.residuals(x)
    J = pb.jacobian(x)
    n, m = int(np.count_nonzero(pb.weight)) + len(pb.jumps), x.size
    chi2 = float(r @ r)
    s2 = chi2 / max(n - m, 1)
    try:
        cov = np.linalg.inv(J.T @ J) * s2
    except np.linalg.LinAlgError:
        cov = np.full((m, m), np.nan)
    # to (ln E*, ln w): ln E* = ln w - 1.5 ln mu + const
    names = list(pb.names)
    A = np.eye(m)
    if "ln_mu" in names:
        i, j = names.index("ln_mu"), names.index("ln_gamma")
        A[i, :] = 0.0
        A[i, i], A[i, j] = -1.5, 1.0
    cov_p = A @ cov @ A.T
    var = np.diag(cov_p)
    sd = np.where(np.isfinite(var) & (var >= 0), np.sqrt(np.abs(var)), np.nan)
    out_names = tuple("ln_E_star" if n_ == "ln_mu" else n_ for n_ in names)
    get = {k_: (float(v) if math.isfinite(v) else None) for k_, v in zip(out_names, sd)}
    Fm, pieces = pb.model_force(p)
    fc = pb.forward(p)
    quantities, warned = _verdicts(pb, choice, x, lo, hi, p, get, modulus)
    noise_dof = None if choice.noise is not None else feat.noise_dof
    bad = misfit(chi2, n - m, noise_dof)
    if bad:
        warned.append(bad)
    if feat.noise_note and choice.noise is None:
        warned.append(feat.noise_note)
    return CurveFit(**quantities, mu=p["mu"], sigma=p["sigma"], K=p["K"], chi2=chi2, dof=n - m, noise_N=noise,
                    noise_stated=choice.noise is not None, p_value=misfit_p(chi2, n - m, noise_dof),
                    residual_rms_N=float(np.sqrt(np.mean((Fm - data.F)[pb.weight > 0] ** 2))),
                    parameters=out_names, covariance=cov_p, data=data, F_fit=Fm, used=pb.weight > 0, leg=pb.legs,
                    branch=pb.labels, measured=feat, fitted=_fitted_features(pb, p, fc), bodies=bodies,
                    spring=spring, choice=choice, traces=pb.traces, iterations=int(res.nfev),
                    status=str(res.message), wall_time_s=time.perf_counter() - t0,
                    notes=tuple(dict.fromkeys(pb.notes + fc.notes)), warnings=tuple(warned),
                    forward=FittedModel(fc, p["z0"], p["F0"], 2 * math.pi * R * p["w"], eps, data.direction))


def _refuse_a_line(data: MeasuredCurve) -> None:
    """CurveFitError for a force that is a straight line in the piezo position over both legs (to _LINEAR of
    its range): two columns of one quantity, no force-distance relation."""
    A = np.c_[data.z, np.ones_like(data.z)]
    coef, *_ = np.linalg.lstsq(A, data.F, rcond=None)
    left = float(np.sqrt(np.mean((data.F - A @ coef) ** 2)))
    if left <= _LINEAR * float(np.ptp(data.F)):
        raise CurveFitError(f"no force-distance relation: the force is a straight line of the piezo position "
                            f"(slope {coef[0]:.6g} N/m) on approach and retract alike (two columns of one "
                            f"quantity?)")


def _bounds(pb: _Problem, choice: FitChoice, modulus: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The bounds of the fitted coordinates: mu in MU_BOUNDS (through w at a held modulus), sigma in [0,
    SIGMA_MAX], w in [1e-6, 100] J/m^2; the contact point and the baseline free."""
    lo = np.array([-np.inf] * len(pb.names))
    hi = np.array([np.inf] * len(pb.names))
    for j, name in enumerate(pb.names):
        if name == "ln_mu":
            lo[j], hi[j] = math.log(MU_BOUNDS[0]), math.log(MU_BOUNDS[1])
        elif name == "sigma":
            lo[j], hi[j] = 0.0, SIGMA_MAX
        elif name == "ln_gamma":
            lo[j], hi[j] = math.log(1e-6), math.log(100.0)
    if not choice.modulus:                          # mu's bounds through w at the held modulus
        assert modulus is not None, "a held modulus is given (fit_curve refuses it otherwise)"
        E, R, eps = float(modulus), pb.R, pb.eps
        j = pb.names.index("ln_gamma")
        lo[j] = max(lo[j], math.log(math.sqrt(MU_BOUNDS[0]**3 * E**2 * eps**3 / R)))
        hi[j] = min(hi[j], math.log(math.sqrt(MU_BOUNDS[1]**3 * E**2 * eps**3 / R)))
    return lo, hi


def _verdicts(pb: _Problem, choice: FitChoice, x, lo, hi, p: dict, sd: dict, modulus) -> tuple[dict, list]:
    """The fit's quantities (gamma, E_star, rms, z0, F0) as Measured, or Missing where a parameter is at a
    bound or undetermined (docs/fitting.md), and the warnings that say so."""
    eps = pb.eps
    at = {}
    for j, name in enumerate(pb.names):
        if x[j] - lo[j] <= BOUND_MARGIN or hi[j] - x[j] <= BOUND_MARGIN:
            edge = lo[j] if x[j] - lo[j] <= BOUND_MARGIN else hi[j]
            at[name] = edge
    q, warned = {}, []

    def bound_reason(name: str) -> str:
        edge = at[name]
        if name == "ln_mu" or (name == "ln_gamma" and not choice.modulus and
                                math.log(1e-6) < edge < math.log(100.0)):
            mu_edge = MU_BOUNDS[0] if p["mu"] < 1 else MU_BOUNDS[1]
            return (f"mu = {p['mu']:.4g} is at the bound {mu_edge:g} of the model's range [{MU_BOUNDS[0]:g}, "
                    f"{MU_BOUNDS[1]:g}]: the data ask for a mu the model does not reach")
        if name == "ln_gamma":
            return f"w = {p['w']:.4g} J/m^2 is at the bound {math.exp(edge):g} J/m^2 of the fit"
        return f"sigma = {p['sigma']:.4g} is at the bound {edge:g} of [0, {SIGMA_MAX:g}]"

    def judged(key: str, coord: str, value: float, err: float | None):
        why = bound_reason(coord) if coord in at else undetermined(value, err)
        if why is None:
            return Measured(value, err)
        warned.append(f"{key} undetermined: {why}")
        return Missing(why)

    w = p["w"]
    q["gamma"] = judged("gamma", "ln_gamma", w, None if sd["ln_gamma"] is None else w * sd["ln_gamma"])
    if choice.modulus:
        e = sd["ln_E_star"]
        q["E_star"] = judged("E_star", "ln_mu", p["E"], None if e is None else p["E"] * e)
    else:
        q["E_star"] = Measured(float(modulus), note="held at the moduli given (eq. 2)")
    if choice.roughness:
        e = sd["sigma"]
        q["rms"] = judged("rms", "sigma", p["sigma"] * eps, None if e is None else e * eps)
    elif pb.bodies.rms is not None:
        q["rms"] = Measured(float(pb.bodies.rms), note="held at the rms given")
    else:
        q["rms"] = None
    for key, coord, value, scale in (("z0", "z0", p["z0"], eps), ("F0", "F0", p["F0"], pb.noise)):
        e = sd[coord]
        if e is None:
            why = "a singular covariance: the curve does not determine it"
            warned.append(f"{key} undetermined: {why}")
            q[key] = Missing(why)
        else:
            q[key] = Measured(value, e * scale)
    return q, warned


def _align(pb: _Problem, x: np.ndarray) -> float:
    """The contact point z0 / eps that best puts the model's curve on the data, the other parameters held: its
    jump-off on the measured pull-off, then the least squares in z0 alone (Brent's bounded minimum)."""
    from .. import brent

    p = pb.unpack(x)
    fc = pb.forward(p)
    jumps = fc.jumps[RETRACT]
    Z_off = jumps[-1] if jumps else fc.pieces[-1].Z_lo
    guess = (pb.feat.pull_off_z_m - pb.data.direction * pb.eps * Z_off) / pb.eps
    j = pb.names.index("z0")

    def cost(z0):
        y = x.copy()
        y[j] = z0
        return float(np.sum(pb.residuals(y) ** 2))

    width = 2.0 + 0.1 * abs(Z_off)
    return brent.minimum(cost, guess - width, guess + width, xatol=1e-4)


def _fitted_features(pb: _Problem, p: dict, fc: ForwardCurve) -> FittedFeatures:
    """The fitted model's jump-in and jump-off positions and pull-off force (the least force on the retract),
    in SI."""
    scale = 2 * math.pi * pb.R * p["w"]
    ins, offs = fc.jumps[APPROACH], fc.jumps[RETRACT]
    lowest = min(float(fc.pieces[i].F.min()) for i in fc.chains[RETRACT][0])
    return FittedFeatures(pull_off_N=-lowest * scale,
                          jump_in_z_m=p["z0"] + pb.data.direction * pb.eps * ins[0] if ins else None,
                          jump_off_z_m=p["z0"] + pb.data.direction * pb.eps * offs[0] if offs else None)


@dataclass(frozen=True)
class FittedModel:
    """The model at the optimum, to predict from: its F(Z) behind the spring (``curve``, a ForwardCurve), the
    contact point ``z0`` (m), the baseline ``F0`` (N), the force scale 2 pi R w (N), epsilon (m) and the
    approach's direction."""

    curve: ForwardCurve
    z0: float
    F0: float
    scale: float
    epsilon: float
    direction: int

    def predict(self, z: np.ndarray, leg: str) -> np.ndarray:
        """The force (N) at piezo positions ``z`` on ``leg`` (approach or retract)."""
        Z = self.direction * (np.asarray(z, dtype=float) - self.z0) / self.epsilon
        return self.F0 + self.scale * self.curve.predict(Z, leg)


def predict_curve(fit: CurveFit, z: np.ndarray, leg: str) -> np.ndarray:
    """The fitted model's force (N) at piezo positions ``z`` on ``leg`` (approach or retract)."""
    if fit.forward is None:
        raise ValueError("the fit holds no model to predict from (fit_curve sets it)")
    return fit.forward.predict(z, leg)
