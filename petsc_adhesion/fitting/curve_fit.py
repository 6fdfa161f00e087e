"""The work of adhesion and the modulus from a measured force-distance curve: the model behind the cantilever,
fitted by bounded least squares.

The measured force at piezo position z is modelled as

    F(z) = F_0 + b (z - z_0) + d [retract] + (k_s / (k c)) 2 pi R w f(Z; mu, K, sigma),   Z = s (z - z_0) / eps

with f the model's force against the base position Z of a spring of stiffness K = k eps / (2 pi R w) on the
approach or the retract (:class:`~petsc_adhesion.fitting.forward.ForwardCurve`: its jumps vertical in F at
constant Z), mu by eq. (9) from w and the reduced modulus E*, sigma = rms / eps,
s the direction of the approach, z_0 the contact point (where the undeflected
spring holds the undeformed sphere at the flat, lambda = 0) and F_0 the force baseline there.  The instrument
(docs/fitting.md, "The instrument in the fit"): the true deflection sensitivity c times the file's, the true
spring constant k against the stated k_s (K = k eps / (2 pi R w)), the virtual deflection b (N/m) and the
retract's baseline offset d (the drag), each fitted or held (:class:`FitChoice`).  The
unknowns are w and E* (optionally the rms roughness), with z_0, F_0 and the
instrument's as nuisance parameters; R, eps and k_s are given.  They are fitted in
x = (ln mu, ln w, [sigma], z_0 / eps, F_0 / s_F, [ln c], [ln (k / k_s)], [b eps / s_F],
[d / s_F]) by scipy's trust-region reflective least squares within bounds (mu in
[1e-3, 1e3], the model's range; sigma in [0, 3]; c and k within a factor 5 of the
stated), on the residuals (F_model - F_i) / s_F, s_F the noise of the far baseline,
and with a stated uncertainty of the spring constant the prior's (k - k_s) / dk.
The segment (approach, retract or both) and the piezo range fitted select the points;
the samples taken during a jump (the detector spreads it over a few) are on neither
branch and left out.  Before the fit the curve is checked against the model's domain
(:func:`domain_reasons`).

Each evaluation at new (mu, sigma) reads the solver's branch, traced once without a spring and kept by the
process (:mod:`~petsc_adhesion.fitting.branches`), behind the spring K, or, where the
curve family table holds the model, interpolates it in milliseconds: then the solver traces one curve near the
table's optimum and a Gauss-Newton step makes the result the solver's, the step added to the bars
(:mod:`~petsc_adhesion.fitting.table_search`; ``CurveFit.path`` says which path).  The Jacobian's columns in
ln mu, ln w and sigma are forward differences (relative step 2e-3) of the prediction *with each point kept on
the branch it was on* (a jump does not move across a point within a difference), those of z_0 and F_0 exact on
the traced curve.  Bars from the Jacobian at the optimum:
covariance s^2 (J^T J)^-1, s^2 = sum of squared residuals / (n - p), carried to
(ln E*, ln w) by the linear map of eq. (9), ln E* = ln w + (ln R - 3 ln mu - 3 ln eps)/2;
the bar of w is w sd(ln w), that of E* is E* sd(ln E*) (a 95% interval is +-1.96 bars;
docs/fitting.md measures how often it holds).  The result is a
:class:`~petsc_adhesion.fitting.results.CurveFit`, each quantity Measured or Missing where a
parameter is at a bound or undetermined, with a warning for each, and for a chi^2 the noise
cannot explain (:mod:`~petsc_adhesion.fitting.results`).

With roughness, w's and E*'s model spread: the optimum moved to each other roughness law, the least
squares of the residuals r_law under that law solved from the fit's optimum by Gauss-Newton in the branch's
coordinates with the others re-solved at each (variable projection; a few curves per law;
:func:`~petsc_adhesion.fitting.outcome.curve_spread`).  What the curve shows by itself
and the domain's checks are :mod:`~petsc_adhesion.fitting.domain`'s, the optimum's reading
:mod:`~petsc_adhesion.fitting.outcome`'s.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..model.parameters import Model, tabor
from ..model.physical import Bodies
from .data import MeasuredCurve
from .branches import BRANCHES
from .forward import APPROACH, RETRACT, ForwardCurve, aligned_contact, rough_first, table_choice, table_covers, table_legs
from .domain import (MU_BOUNDS, SIGNAL, CurveFitError, OutsideDomain, baselines, calibrated_invols,
                     domain_reasons, features, refuse_a_line, refuse_empty)
from .outcome import SIGMA_MAX, bounds, curve_spread, instrument_values, profiled, to_moduli, verdicts
from .pull_off import maugis_dugdale_gamma
from .results import CurveFit, Features, FitChoice, FittedFeatures, Spring, misfit, misfit_p
from .table_search import START_MUS, START_SIGMAS, TABLE_CAP, TableStep, search_cap, searched, start_gamma, cpu, mu_profile, solver_steps, table_bounds

if TYPE_CHECKING:
    from ..family.table import FamilyTable
    from ..tracing.trace import GridChoice, SolverChoice

__all__ = ["CurveFit", "CurveFitError", "OutsideDomain", "FitProgress", "FittedModel", "domain_reasons",
           "calibrated_invols", "fit_curve", "features", "MU_BOUNDS", "SIGMA_MAX", "predict_curve", "TableStep"]

#: Relative step of the Jacobian's differences in ln mu, ln w (and the step in sigma).
_STEP = 2e-3
#: The points before each measured jump always left out of the fit.
EDGE_POINTS = 3
#: A change between successive samples after a jump's largest, in its direction, beyond this share of that
#: largest: the jump still under way (the sample is on neither branch).
JUMP_TAIL = 0.25
@dataclass(frozen=True)
class FitProgress:
    """How far a fit has gone: least-squares ``evaluations``, curves ``traced``, the best reduced chi^2, the seconds
    ``elapsed`` and the search's ``cap`` on evaluations (TABLE_EVALS times the fit's on a rough fit's table)."""

    evaluations: int
    traces: int
    best_reduced_chi2: float
    elapsed: float
    cap: int = 0


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
    choice: FitChoice = field(default_factory=FitChoice)
    cache: dict = field(default_factory=dict)
    traces: int = 0
    notes: list = field(default_factory=list)
    evaluations: int = 0
    best_chi2: float = math.inf
    progress: Callable[[FitProgress], None] | None = None     # after each evaluation (None: silent)
    t0: float = field(default_factory=time.perf_counter)
    table: FamilyTable | None = None   # the FamilyTable the search runs on (None: the solver's curves)
    upper: np.ndarray | None = None     # the search's upper bounds (a table's differences turn back at them)
    mu_span: tuple | None = None        # where the table's profile of mu ran (table_search.mu_profile)

    def __post_init__(self):
        self.legs = np.r_[np.zeros(self.data.turn, int), np.ones(self.data.z.size - self.data.turn, int)]
        # each point's branch, as the measured jumps say: 0 off the contact, 1 in it, -1 no jump (the model's decide)
        self.R, self.eps = self.bodies.R, self.bodies.epsilon
        feat = self.feat
        turn, n = self.data.turn, self.data.z.size
        self.labels = np.full(n, -1)
        if feat.contact_from is not None:
            self.labels[:turn] = np.arange(turn) >= feat.contact_from
        if feat.free_from is not None:
            self.labels[turn:] = np.arange(n - turn) < feat.free_from
        # (fixed for the fit: its every evaluation assigns the points to pieces by them)
        self.contact = self.labels == 1
        self.unlabelled = [(name, own) for name, own in ((APPROACH, (self.legs == 0) & (self.labels < 0)),
                                                         (RETRACT, (self.legs == 1) & (self.labels < 0))) if own.any()]
        # the points fitted: the legs of the segment asked for, within the piezo range asked for
        ch = self.choice
        self.mask = np.ones(n)
        if ch.segment != "both":
            self.mask[self.legs != (0 if ch.segment == APPROACH else 1)] = 0.0
        if ch.z_range is not None:
            self.mask[(self.data.z < ch.z_range[0]) | (self.data.z > ch.z_range[1])] = 0.0
        self.weight = self.mask.copy()
        self.names = (() if self.E_fixed is not None else ("ln_mu",)) + ("ln_gamma",) + \
            (("sigma",) if self.fit_sigma else ()) + ("z0", "F0") + \
            (("ln_invols",) if ch.invols_fitted else ()) + (("ln_k",) if ch.spring_err is not None else ()) + \
            (("slope",) if ch.virtual_deflection else ()) + (("drag",) if ch.drag else ())
        self.invols_held = ch.invols_scale
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
        self.weight = self.mask.copy()
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
        self.weight[self.during_jumps()] = 0.0

    def during_jumps(self) -> np.ndarray:
        """The samples taken while the lever jumped: a jump the detector spreads over a few samples (its and the
        lever's response) leaves points after the largest change still moving the jump's way by more than
        JUMP_TAIL of it, on neither branch (indices into the curve)."""
        F, turn, out = self.data.F, self.data.turn, []
        for i, start, sign in ((self.feat.contact_from, 0, -1), (self.feat.free_from, turn, +1)):
            if i is None:
                continue
            j = start + i                       # the first point past the largest change
            largest = sign * (F[j] - F[j - 1])
            end = turn if start == 0 else F.size
            while j + 1 < end and sign * (F[j + 1] - F[j]) > JUMP_TAIL * largest:
                out.append(j)
                j += 1
        return np.array(out, dtype=int)

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
        c = math.exp(x["ln_invols"]) if "ln_invols" in x else self.invols_held
        k = self.spring.k * math.exp(x["ln_k"]) if "ln_k" in x else self.spring.k
        # the file's force is the stated k times the file's deflection; the true force is the true k times the
        # true deflection, c times the file's: F_file = F_true k_stated / (k c)
        return {"w": w, "E": E, "mu": mu, "sigma": max(sigma, 0.0), "K": k * self.eps / (2 * math.pi * self.R * w),
                "z0": x["z0"] * self.eps, "F0": x["F0"] * self.noise, "c": c, "k": k,
                "gain": self.spring.k / (k * c), "slope": x.get("slope", 0.0) * self.noise / self.eps,
                "drag": x.get("drag", 0.0) * self.noise}

    def forward(self, p: dict) -> ForwardCurve:
        key = (round(p["mu"], 12), round(math.log(p["K"]), 12), round(p["sigma"], 12))
        if key not in self.cache and self.table is not None:
            if len(self.cache) > 64:
                self.cache.pop(next(iter(self.cache)))
            Z = self.Z(p)           # the far branch tabulated beyond the data, with room for z0 to move
            reach = float(Z.min()) - 10.0 - 0.1 * float(np.ptp(Z))
            self.cache[key] = table_legs(self.table, p["mu"], p["sigma"], p["K"], reach)
        if key not in self.cache:
            # the solver's branch of (mu, sigma), traced once in the process and read behind this K (branches.py)
            f_max = max(1.3 * (self.Fmax_data - p["F0"]) / (p["gain"] * 2 * math.pi * self.R * p["w"]) + 0.3, 0.5)
            Z = self.Z(p)
            model = replace(self.template, mu=p["mu"], sigma=p["sigma"], bodies=None)
            legs, traced = BRANCHES.legs(model, f_max, p["K"], float(Z.min()) - 10.0 - 0.1 * float(np.ptp(Z)),
                                         self.grid, self.solver, self.comm)
            self.traces += traced
            if len(self.cache) > 64:
                self.cache.pop(next(iter(self.cache)))
            self.cache[key] = legs
        return self.cache[key]

    def Z(self, p: dict) -> np.ndarray:
        return self.data.direction * (self.data.z - p["z0"]) / self.eps

    def assign(self, fc: ForwardCurve, Z: np.ndarray) -> np.ndarray:
        """The piece of every point: the far branch (the first piece) or the contact (the last) as the measured
        jumps say, else (a leg without a jump) the piece the model's own jumps put it on."""
        pieces = np.where(self.contact, len(fc.pieces) - 1, 0)
        for name, own in self.unlabelled:
            pieces[own] = fc.assign(Z[own], name)
        return pieces

    def model_force(self, p: dict, pieces: np.ndarray | None = None, fc: ForwardCurve | None = None):
        """(the model's force at every point in N, the pieces they are on)."""
        fc = fc or self.forward(p)
        Z = self.Z(p)
        if pieces is None:
            pieces = self.assign(fc, Z)
        # the baseline: F0 at the contact point, sloped in z by the virtual deflection, the retract's offset by
        # the drag; the model's force as the file measures it (its gain: the sensitivity's and spring's errors)
        base = p["F0"] + p["slope"] * (self.data.z - p["z0"]) + p["drag"] * self.legs
        return base + p["gain"] * 2 * math.pi * self.R * p["w"] * fc.evaluate(Z, pieces), pieces

    def measured_jumps(self) -> list[tuple[str, float, float]]:
        """The jumps the curve shows: (leg, piezo position between the two points about it, its uncertainty: the
        distance of the two over sqrt(12), the spread of a position anywhere between them)."""
        out, turn = [], self.data.turn
        for leg, i in ((APPROACH, self.feat.contact_from), (RETRACT, self.feat.free_from)):
            if i is not None:
                j = i if leg == APPROACH else turn + i
                if not (self.mask[j - 1] and self.mask[j]):
                    continue                    # a jump outside the segment or the range fitted
                a, b = self.data.z[j - 1], self.data.z[j]
                out.append((leg, 0.5 * (a + b), abs(b - a) / math.sqrt(12.0)))
        return out

    @property
    def points(self) -> int:
        """The residuals that are data: the points fitted, the measured jumps, the spring constant's prior."""
        return int(np.count_nonzero(self.weight)) + len(self.jumps) + ("ln_k" in self.names)

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
        if "ln_k" in self.names:            # the spring constant's stated uncertainty: a Gaussian prior
            assert self.choice.spring_err is not None, "ln_k is fitted with a stated uncertainty"
            rJ.append((p["k"] - self.spring.k) / self.choice.spring_err)
        return np.concatenate((rF, rJ)), pieces

    def residuals(self, x) -> np.ndarray:
        r = self._all(self.unpack(x))[0]
        self.evaluations += 1
        self.best_chi2 = min(self.best_chi2, float(r @ r))
        if self.progress is not None:
            dof = max(self.points - len(self.names), 1)
            self.progress(FitProgress(self.evaluations, self.traces, self.best_chi2 / dof, time.perf_counter() - self.t0,
                                      search_cap(self.choice, self.table)))
        return r

    def jacobian(self, x, columns=None) -> np.ndarray:
        """Forward differences, every point kept on its piece (see the module); the columns of the coordinates
        ``columns`` (indices) alone where given."""
        x = np.asarray(x, dtype=float)
        p = self.unpack(x)
        base, pieces = self._all(p)
        columns = range(len(self.names)) if columns is None else list(columns)
        J = np.empty((base.size, len(columns)))
        n_pieces = len(self.forward(p).pieces)
        for col, j in enumerate(columns):
            name = self.names[j]
            h = 1e-4 if name == "z0" else 1.0 if name in ("F0", "slope", "drag") else _STEP
            if self.table is not None and self.upper is not None and x[j] + h > self.upper[j]:
                h = -h                  # the table ends at its last node: the difference turns back
            xh = x.copy()
            xh[j] += h
            q = self.unpack(xh)
            fc = self.forward(q)
            rh, _ = self._all(q, pieces if len(fc.pieces) == n_pieces else None, fc)
            J[:, col] = (rh - base) / h
        return J


def fit_curve(data: MeasuredCurve, bodies: Bodies, spring: Spring, choice: FitChoice | None = None,
              model: Model | None = None, grid=None, solver=None, comm=None, progress=None,
              spread_rules: tuple | None = None, table="default") -> CurveFit:
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
        The cantilever's spring constant k (N/m) the file's force was converted with.
    choice : FitChoice
        What is fitted (default: w and E*, with the noise of the far baseline), the instrument's nuisance
        parameters, the segment and the piezo range, the cap on evaluations, what is done outside the domain.
    model : Model
        The roughness average and the domain (its mu, sigma and bodies are replaced).
    grid, solver, comm
        As :func:`~petsc_adhesion.tracing.trace.trace_curve`'s.
    progress : callable
        Called with a :class:`FitProgress` after every evaluation of the least squares (None: silent).
    spread_rules : tuple
        The roughness laws (:class:`~petsc_adhesion.tracing.model_spread.Rule`) the optimum is moved to, the
        model spread of w and E* (None: none; a rough model only).
    table : str, FamilyTable or None
        The curve family table the search runs on where it holds the model (:mod:`.table_search`): "default"
        (the package's), a shipped table's name, a file, a FamilyTable; "none" or None: the solver's curves
        throughout.  The result's ``path`` says which: a :class:`TableStep`, or why the solver alone.

    Returns the :class:`~petsc_adhesion.fitting.results.CurveFit`, its ``warnings`` saying where it does not
    hold (a parameter at a bound or undetermined, Missing then; a misfit; the cap on evaluations reached; a
    curve outside the domain with ``choice.outside_domain`` "warn").  Raises :class:`CurveFitError` (one line)
    for a curve with no contact, no adhesion, or no force-distance relation, :class:`OutsideDomain` for one
    outside the model's domain (``choice.outside_domain`` "refuse").
    """
    from scipy.optimize import least_squares

    if table == "default":                # a rough fit: the rough table where it holds mu, else the solver
        first = rough_first(lambda t: fit_curve(data, bodies, spring, choice, model, grid, solver, comm, progress,
                                                spread_rules, t), choice or FitChoice(), model, bodies, MU_BOUNDS)
        if first is not None:
            return first
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
    refuse_a_line(data)
    feat = features(data)
    noise = feat.noise_N if choice.noise is None else float(choice.noise)
    # the most extreme of n samples of noise alone lies about sqrt(2 ln n) deviations out: a signal is beyond
    signal = (SIGNAL + math.sqrt(2 * math.log(data.z.size))) * noise
    if feat.contact_N < signal:
        raise CurveFitError(f"no contact: the approach rises at most {feat.contact_N:.3g} N above its baseline, "
                            f"within {signal / noise:.3g} times the noise ({noise:.2g} N)")
    if feat.pull_off_N < signal:
        raise CurveFitError(f"no adhesion: the retract falls at most {feat.pull_off_N:.3g} N below the baseline "
                            f"(noise {noise:.2g} N): no pull-off, so the work of adhesion is undetermined")
    refuse_empty(data, choice)
    base = baselines(data)
    notes: list[str] = []
    if choice.calibrate_invols:
        c = calibrated_invols(feat, spring, base[1])
        notes.append(f"the sensitivity calibrated on the contact as on a hard substrate: its slope "
                     f"{feat.contact_slope_N_m:.4g} N/m less the baseline's {base[1]:.3g} N/m against the lever's "
                     f"{spring.k:.4g} N/m, scale c = {c:.4g}" + (" (the fit's start)" if choice.invols_fitted else
                                                                 " (held)"))
        choice = replace(choice, invols_scale=c)
    reasons = domain_reasons(data, feat, bodies, spring, choice, base)
    if reasons and choice.outside_domain == "refuse":
        raise OutsideDomain("; ".join(reasons))
    R, eps = bodies.R, bodies.epsilon
    sigma0 = 0.0 if bodies.rms is None else bodies.rms / eps
    if choice.roughness and bodies.rms is None:
        sigma0 = 0.3
    try:                       # "default": the rough table where the fit has a roughness its range holds
        family, label = table_choice(table, sigma0, choice.roughness, MU_BOUNDS)
    except ValueError as e:
        raise CurveFitError(f"the table: {e}") from None
    pb = _Problem(data, bodies, spring, template, grid, solver, comm,
                  None if choice.modulus or modulus is None else float(modulus),
                  choice.roughness, sigma0, noise, feat, float(data.F.max()), choice=choice, progress=progress)
    pb.notes += notes
    why_not = "-fit_table none" if family is None else \
        table_covers(family, template, template.rmax if template.rmax is not None else grid.default_rmax,
                     choice.roughness, sigma0)
    pb.table = family if why_not is None else None
    P = feat.pull_off_N * choice.invols_scale        # the pull-off as the true sensitivity makes it
    names = pb.names
    reach = MU_BOUNDS if pb.table is None else (float(pb.table.mu[0]), float(pb.table.mu[-1]))

    def start(E: float, sigma: float = sigma0, w_rough: float | None = None) -> tuple[np.ndarray, float]:
        # a rough start's w is the pull-off table's (start_gamma), never the smooth relation's, 30 times low at sigma 1
        w = bodies.gamma if bodies.gamma is not None else w_rough or maugis_dugdale_gamma(P, R, E, eps)
        mu = min(max(tabor(R, w, E, eps), reach[0] * 1.01), reach[1] * 0.99)
        if pb.table is not None and "ln_gamma" in names:     # a held modulus: w's start, too, where the
            w = math.sqrt(mu**3 * E**2 * eps**3 / R)           # table holds mu (eq. 9 inverted)
        # the baseline's start: the far approach's median, or with its slope fitted its line at the contact point
        sloped = choice.virtual_deflection
        given = {"ln_mu": math.log(mu), "ln_gamma": math.log(w), "sigma": sigma, "z0": 0.0,
                 "F0": (base[0] + base[1] * feat.pull_off_z_m if sloped else feat.F0_N) / noise,
                 "ln_invols": math.log(choice.invols_scale), "ln_k": 0.0, "slope": base[1] * eps / noise,
                 "drag": base[2] / noise}
        x = np.array([given[n_] for n_ in names], dtype=float)
        j = names.index("z0")
        x[j] = aligned_contact(pb, x)
        if sloped:
            x[names.index("F0")] = (base[0] + base[1] * x[j] * eps) / noise
        return x, float(np.sum(pb._all(pb.unpack(x))[0] ** 2))

    c0, tries = cpu(), []
    if modulus is not None:
        x0, _ = start(float(modulus))
    else:
        w_guess = bodies.gamma or P / (1.75 * math.pi * R)
        mus = (0.1, 0.3, 1.0, 3.0) if pb.table is None else \
            [m for m in START_MUS if reach[0] <= m <= reach[1]] or [math.sqrt(reach[0] * reach[1])]
        sigmas = START_SIGMAS if pb.table is not None and choice.roughness else (sigma0,)
        ws = [(m, s_, start_gamma(P, R, m, s_, w_guess) if s_ > 0 else None) for m in mus for s_ in sigmas]
        tries = [start((w_ or w_guess) * math.sqrt(R / (m**3 * eps**3)), s_, w_) for m, s_, w_ in ws]
        x0 = min(tries, key=lambda t: t[1])[0]   # (the others: table_search.searched)
    pb.leave_out_edges(x0)
    lo, hi = bounds(pb, choice, modulus)
    if pb.table is not None:
        lo, hi = table_bounds(pb.table, names, lo, hi, modulus, R, eps)
        pb.upper = hi
    pb.evaluations = 0
    cap = search_cap(choice, pb.table)
    res = searched(lambda x: least_squares(pb.residuals, x, jac=pb.jacobian, bounds=(lo, hi), method="trf",
                                           x_scale="jac", ftol=1e-8, xtol=1e-8, gtol=1e-8, max_nfev=cap),
                   x0, tries, lo, hi, pb.table is not None and choice.roughness)
    A = to_moduli(names)
    d, path = None, f"the solver's curves throughout: {why_not}"
    profile = None
    if pb.table is not None:
        profile = mu_profile(pb, res.x, lo, hi)         # mu undetermined: how far the others move with it
        x, x_curve, J, d, path = solver_steps(pb, res.x, lo, hi, A, label, pb.evaluations, cpu() - c0)
    else:
        x = x_curve = res.x
        J = pb.jacobian(x)
    p, p_curve = pb.unpack(x), pb.unpack(x_curve)
    r, _ = pb._all(p_curve)
    n, m = pb.points, x.size
    chi2 = float(r @ r)
    s2 = chi2 / max(n - m, 1)
    try:
        JtJ_inv = np.linalg.inv(J.T @ J)
        cov = JtJ_inv * s2
    except np.linalg.LinAlgError:
        JtJ_inv = None
        cov = np.full((m, m), np.nan)
    # to (ln E*, ln w): ln E* = ln w - 1.5 ln mu + const; the table's step a systematic term (table_search.py)
    cov_p = A @ cov @ A.T + (np.outer(d, d) if d is not None else 0.0)
    cov_p = profiled(cov_p, J, A, d, s2, names, profile)
    var = np.diag(cov_p)
    sd = np.where(np.isfinite(var) & (var >= 0), np.sqrt(np.abs(var)), np.nan)
    out_names = tuple("ln_E_star" if n_ == "ln_mu" else n_ for n_ in names)
    get = {k_: (float(v) if math.isfinite(v) else None) for k_, v in zip(out_names, sd)}
    Fm, pieces = pb.model_force(p_curve)
    fc = pb.forward(p_curve)
    quantities, warned = verdicts(pb, choice, x, lo, hi, p, get, modulus)
    instrument, warned_i = instrument_values(pb, choice, x, lo, hi, p, get)
    warned += warned_i
    noise_dof = None if choice.noise is not None else feat.noise_dof
    bad = misfit(chi2, n - m, noise_dof)
    if bad:
        warned.append(bad)
    if feat.noise_note and choice.noise is None:
        warned.append(feat.noise_note)
    if res.status == 0:
        warned.append(f"the fit stopped at its cap of {cap} evaluations (-fit_max_evals{TABLE_CAP * (cap > choice.max_evaluations)})"
                      f" before it converged: its numbers are where it stopped, not an optimum")
    if choice.invols_fitted:            # the indentation and the contact at the fitted scale
        fitted = (p["F0"] - p["slope"] * p["z0"], p["slope"], p["drag"])
        reasons += [why for why in domain_reasons(data, feat, bodies, Spring(p["k"]), choice, fitted, p["c"])
                    if why not in reasons]
    warned += [f"outside the model's domain: {why}" for why in reasons]
    spread = None
    if spread_rules is not None:
        spread = curve_spread(pb, x, J, JtJ_inv, quantities, A, spread_rules, lo, hi)
    used = pb.weight > 0
    return CurveFit(**quantities, mu=p["mu"], sigma=p["sigma"], K=p["K"], chi2=chi2, dof=n - m, noise_N=noise,
                    noise_stated=choice.noise is not None, p_value=misfit_p(chi2, n - m, noise_dof),
                    residual_rms_N=float(np.sqrt(np.mean((Fm - data.F)[used] ** 2))),
                    parameters=out_names, covariance=cov_p, data=data, F_fit=Fm, used=used, leg=pb.legs,
                    branch=pb.labels, measured=feat, fitted=_fitted_features(pb, p_curve, fc), bodies=bodies,
                    spring=spring, choice=choice, traces=pb.traces, iterations=int(res.nfev),
                    status=str(res.message), wall_time_s=time.perf_counter() - t0,
                    notes=tuple(dict.fromkeys(pb.notes + fc.notes + [_path_note(path)])), warnings=tuple(warned),
                    forward=FittedModel(fc, p_curve["z0"], p_curve["F0"], p_curve["gain"] * 2 * math.pi * R *
                                        p_curve["w"], eps, data.direction, p_curve["slope"], p_curve["drag"]),
                    instrument=instrument, segment=choice.segment, z_range=choice.z_range, spread=spread, path=path)


def _path_note(path) -> str:
    """The fit's note on its path: the table's search and the solver's step (TableStep), or the solver alone."""
    if isinstance(path, str):
        return path
    return path.describe({"ln_E_star": "E*", "ln_gamma": "w", "z0": "z0", "F0": "F0", "sigma": "sigma",
                          "ln_invols": "the sensitivity", "ln_k": "k", "slope": "the virtual deflection",
                          "drag": "the drag"})


def _fitted_features(pb: _Problem, p: dict, fc: ForwardCurve) -> FittedFeatures:
    """The fitted model's jump-in and jump-off positions and pull-off force (the least force on the retract),
    in SI."""
    scale = p["gain"] * 2 * math.pi * pb.R * p["w"]         # the force as the file measures it
    ins, offs = fc.jumps[APPROACH], fc.jumps[RETRACT]
    lowest = fc.least_force(RETRACT)[1]
    return FittedFeatures(pull_off_N=-lowest * scale,
                          jump_in_z_m=p["z0"] + pb.data.direction * pb.eps * ins[0] if ins else None,
                          jump_off_z_m=p["z0"] + pb.data.direction * pb.eps * offs[0] if offs else None)


@dataclass(frozen=True)
class FittedModel:
    """The model at the optimum, to predict from: its F(Z) behind the spring (``curve``, a ForwardCurve), the
    contact point ``z0`` (m), the baseline ``F0`` (N) at it, the force scale 2 pi R w (N) times the gain of
    the instrument's errors, epsilon (m), the approach's direction, the baseline's slope in z (N/m) and the
    retract's baseline offset (N)."""

    curve: ForwardCurve
    z0: float
    F0: float
    scale: float
    epsilon: float
    direction: int
    slope: float = 0.0
    drag: float = 0.0

    def predict(self, z: np.ndarray, leg: str) -> np.ndarray:
        """The force (N) at piezo positions ``z`` on ``leg`` (approach or retract)."""
        z = np.asarray(z, dtype=float)
        Z = self.direction * (z - self.z0) / self.epsilon
        base = self.F0 + self.slope * (z - self.z0) + (self.drag if leg == RETRACT else 0.0)
        return base + self.scale * self.curve.predict(Z, leg)


def predict_curve(fit: CurveFit, z: np.ndarray, leg: str) -> np.ndarray:
    """The fitted model's force (N) at piezo positions ``z`` on ``leg`` (approach or retract)."""
    if fit.forward is None:
        raise ValueError("the fit holds no model to predict from (fit_curve sets it)")
    return fit.forward.predict(z, leg)
