"""A curve fit's optimum read into its results: the bounds of the fitted coordinates, each quantity Measured or
Missing where it is at a bound or undetermined (docs/fitting.md, "When a fit does not hold"), the instrument's
parameters fitted or held, and w's and E*'s model spread under the other roughness laws ("The roughness
law's spread in a curve fit").

The fit's problem (``pb``: :class:`~petsc_adhesion.fitting.curve_fit._Problem`) is read for its coordinates'
names, its constants and, for the spread, its residuals under another law.
"""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from ..tracing.measured import Measured, Missing
from .domain import MU_BOUNDS
from .results import BOUND_MARGIN, Z95, FitChoice, Instrument, undetermined

__all__ = ["bounds", "verdicts", "instrument_values", "curve_spread", "branch_coordinates", "LawOptimum",
           "profiled", "to_moduli", "SIGMA_MAX", "INSTRUMENT_FACTOR", "SPREAD_STEPS", "SPREAD_TOL"]

#: The largest roughness sigma = rms / eps fitted.
SIGMA_MAX = 3.0
#: The fitted sensitivity's scale and spring constant stay within this factor of the stated.
INSTRUMENT_FACTOR = 5.0

def bounds(pb, choice: FitChoice, modulus: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The bounds of the fitted coordinates: mu in MU_BOUNDS (through w at a held modulus), sigma in [0,
    SIGMA_MAX], w in [1e-6, 100] J/m^2, the sensitivity's scale and the spring constant within a factor
    INSTRUMENT_FACTOR of the stated; the contact point, the baseline, its slope and the drag free."""
    lo = np.array([-np.inf] * len(pb.names))
    hi = np.array([np.inf] * len(pb.names))
    for j, name in enumerate(pb.names):
        if name == "ln_mu":
            lo[j], hi[j] = math.log(MU_BOUNDS[0]), math.log(MU_BOUNDS[1])
        elif name == "sigma":
            lo[j], hi[j] = 0.0, SIGMA_MAX
        elif name == "ln_gamma":
            lo[j], hi[j] = math.log(1e-6), math.log(100.0)
        elif name in ("ln_invols", "ln_k"):             # within a factor INSTRUMENT_FACTOR of the stated
            lo[j], hi[j] = -math.log(INSTRUMENT_FACTOR), math.log(INSTRUMENT_FACTOR)
    if not choice.modulus:                          # mu's bounds through w at the held modulus
        assert modulus is not None, "a held modulus is given (fit_curve refuses it otherwise)"
        E, R, eps = float(modulus), pb.R, pb.eps
        j = pb.names.index("ln_gamma")
        lo[j] = max(lo[j], math.log(math.sqrt(MU_BOUNDS[0]**3 * E**2 * eps**3 / R)))
        hi[j] = min(hi[j], math.log(math.sqrt(MU_BOUNDS[1]**3 * E**2 * eps**3 / R)))
    return lo, hi


def verdicts(pb, choice: FitChoice, x, lo, hi, p: dict, sd: dict, modulus) -> tuple[dict, list]:
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
            # the search's range: the model's, or a table's that holds less of it (the rough one: mu to 1), read
            # from the search's bounds (the table is gone by now: the solver's curves took over after it)
            k = pb.names.index("ln_mu") if "ln_mu" in pb.names else None
            rng = MU_BOUNDS if k is None else (math.exp(lo[k]), math.exp(hi[k]))
            model_s = all(math.isclose(a, b, rel_tol=1e-6) for a, b in zip(rng, MU_BOUNDS))
            rng, whose = (MU_BOUNDS, "the model's") if model_s else (rng, "the table's")
            mu_edge = rng[0] if p["mu"] < math.sqrt(rng[0] * rng[1]) else rng[1]
            where = f"mu = {p['mu']:.4g} is at the bound {mu_edge:g} of {whose} range [{rng[0]:g}, {rng[1]:g}]"
            e = sd.get("ln_E_star") if name == "ln_mu" else None
            if name == "ln_mu" and (e is None or undetermined(p["E"], p["E"] * e) is not None):
                # the bound is where the search stopped, not what the data ask for: the Jacobian's bar there
                # spans the range (DMT's end, or a contact much stiffer than the lever: the curve hardly moves
                # with mu)
                span = "a singular covariance" if e is None else \
                    f"its 95% interval in ln E* +-{Z95 * e:.3g}, a factor {math.exp(min(Z95 * e, 700.0)):.3g} either way"
                return f"{where}, where the curve does not determine it ({span}): E* is not measured by this curve"
            return f"{where}: the data ask for a mu the model does not reach"
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


def instrument_values(pb, choice: FitChoice, x, lo, hi, p: dict, sd: dict) -> tuple[Instrument, list]:
    """The instrument's nuisance parameters as Measured (fitted with their bars, held with a note) or Missing
    at a bound of the fit, and the warnings that say so."""
    warned = []

    def fitted(key, coord, value, err_of):
        j = pb.names.index(coord)
        if x[j] - lo[j] <= BOUND_MARGIN or hi[j] - x[j] <= BOUND_MARGIN:
            why = f"{value:.4g} is at a bound of the fit ({key} within a factor {math.exp(hi[j]):g} of the stated)"
            warned.append(f"{key} undetermined: {why}")
            return Missing(why)
        e = sd.get(coord)
        if e is None:
            why = "a singular covariance: the curve does not determine it"
            warned.append(f"{key} undetermined: {why}")
            return Missing(why)
        return Measured(value, err_of(e))

    if choice.invols_fitted:
        c = fitted("invols_scale", "ln_invols", p["c"], lambda e: p["c"] * e)
    else:
        c = Measured(p["c"], note="held: " + ("calibrated on the contact as on a hard substrate"
                                               if choice.calibrate_invols else "the file's sensitivity"))
    if choice.spring_err is not None:
        k = fitted("spring", "ln_k", p["k"], lambda e: p["k"] * e)
    else:
        k = Measured(p["k"], note=f"held at {pb.spring.source}")
    v = fitted("virtual_deflection", "slope", p["slope"], lambda e: e * pb.noise / pb.eps) \
        if choice.virtual_deflection else Measured(0.0, note="held at 0: not fitted (-fit_virtual_deflection)")
    d = fitted("drag", "drag", p["drag"], lambda e: e * pb.noise) if choice.drag else \
        Measured(0.0, note="held at 0: not fitted (-fit_drag)")
    return Instrument(c, k, v, d, pb.feat.contact_slope_N_m), warned


#: The law's optimum is sought in at most this many Gauss-Newton steps in the branch's coordinates.
SPREAD_STEPS = 12
#: The optimum is reached where a Gauss-Newton step, its Jacobian differenced at the point, moves each branch
#: coordinate by less than this share of its bar.
SPREAD_TOL = 0.1


def branch_coordinates(names: tuple) -> list:
    """The fitted coordinates that move the solver's branch (mu, sigma): ln mu, sigma, and ln w where E* is held
    (mu then moves with w, eq. 9).  The others (z0, F0, the instrument's; ln w beside a fitted ln mu) read the
    same branch behind another spring or scale, no curve traced (fitting/branches.py)."""
    return [j for j, n in enumerate(names) if n in ("ln_mu", "sigma") or (n == "ln_gamma" and "ln_mu" not in names)]


class LawOptimum:
    """The fit's optimum moved to another roughness law by variable projection (Golub and Pereyra): the branch's
    coordinates t (:func:`branch_coordinates`) outside, the others c inside.

    Inside, at each t, c(t) minimises |r_law(t, c)|^2 (bounded least squares on the branch read behind other
    springs and scales: no curve traced).  Outside, Gauss-Newton on the projected residuals r_P(t) = r_law(t,
    c(t)), whose Jacobian is

        J_P = (I - J_c J_c^+) J_t      (Kaufman's form: exact at c(t), where J_c^T r_P = 0),

    a step dt = -J_P^+ r_P taken only where it lowers |r_P|^2 (else retried with J_P differenced afresh at the
    point, then shortened to a quarter in bars), J_P carried between accepted steps by Broyden's rank-one update

        J_P <- J_P + (dr - J_P dt) dt^T / (dt^T dt),     dr the change of r_P,

    and c's start at the next t predicted to first order, c - J_c^+ J_t dt.  The first J_P is the fit's J
    projected (no curve), so a law near the reference costs a curve, its difference and the last step's.  Converged where a step
    with J_P differenced at the point moves each coordinate of t by less than SPREAD_TOL of its bar: there
    J_P^T r_P = J_t^T r_P, the gradient in t, is that small, and in c it is the inner solve's zero; that last
    step is taken too where it lowers |r_P|^2, so what is left is of second order.  One curve is traced per new
    t and one per coordinate of t for each difference."""

    def __init__(self, alt, x, J, bar, lo, hi):
        self.alt, self.lo, self.hi, self.bar = alt, lo, hi, bar
        self.t_idx = branch_coordinates(alt.names)
        self.c_idx = [j for j in range(len(alt.names)) if j not in self.t_idx]
        self.x = x.copy()
        self.steps: list = []           # the accepted steps in t
        self._take(J)

    def _take(self, J) -> None:
        """J_P and the first-order move of c along t (J_c^+ J_t) from a Jacobian J at (or near) the point."""
        Jt, Jc = J[:, self.t_idx], J[:, self.c_idx]
        self.M = np.linalg.lstsq(Jc, Jt, rcond=None)[0] if self.c_idx else np.zeros((0, len(self.t_idx)))
        self.JP = Jt - Jc @ self.M

    def residuals(self, x) -> np.ndarray:
        return self.alt._all(self.alt.unpack(x))[0]

    def inner(self, x) -> tuple:
        """(x with c(t) at x's t, from x's c; its residuals r_P)."""
        from scipy.optimize import least_squares

        if not self.c_idx:
            return x, self.residuals(x)
        c = self.c_idx

        def at(y):
            z = x.copy()
            z[c] = y
            return z

        lo, hi = self.lo[c], self.hi[c]
        y0 = np.clip(x[c], lo + 1e-9 * np.where(np.isfinite(hi - lo), hi - lo, 1.0), hi - 1e-9)
        res = least_squares(lambda y: self.residuals(at(y)), y0, jac=lambda y: self.alt.jacobian(at(y), c),
                            bounds=(lo, hi), method="trf", x_scale="jac", ftol=1e-10, xtol=1e-10, gtol=1e-10)
        z = at(res.x)
        return z, self.residuals(z)

    def solve(self) -> tuple:
        """(the moved optimum x, None) or (None, why it was not reached)."""
        t = self.t_idx
        x, r = self.inner(self.x)
        chi2 = float(r @ r)
        fresh, radius = False, math.inf          # J_P differenced at x; the step's largest size in bars
        for _ in range(SPREAD_STEPS):
            target = np.clip(x[t] - np.linalg.lstsq(self.JP, r, rcond=None)[0], self.lo[t], self.hi[t])
            dt = target - x[t]
            size = float(np.max(np.abs(dt) / self.bar))
            # converged by the whole step, never by one a failure cut short (that is no optimum)
            if size < SPREAD_TOL:
                if fresh:
                    names = self.alt.names
                    at = [names[j] for j in t + [names.index("ln_gamma")]
                          if min(x[j] - self.lo[j], self.hi[j] - x[j]) <= BOUND_MARGIN]
                    if at:
                        return None, f"its optimum is at the fit's bound of {', '.join(dict.fromkeys(at))}"
                    if size > 0:        # the last step too, where it lowers chi^2: its error is second order
                        y = x.copy()
                        y[t] = target
                        y, r_new = self.inner(y)
                        if float(r_new @ r_new) < chi2:
                            self.steps.append(dt)
                            x = y
                    self.x = x
                    return x, None
                self._take(self.alt.jacobian(x))
                fresh, radius = True, math.inf
                continue
            if size > radius:
                dt *= radius / size
                size = radius
            y = x.copy()
            y[t] = x[t] + dt
            if self.c_idx:
                y[self.c_idx] = np.clip(x[self.c_idx] - self.M @ dt, self.lo[self.c_idx], self.hi[self.c_idx])
            y, r_new = self.inner(y)
            chi2_new = float(r_new @ r_new)
            if chi2_new < chi2:
                self.JP += np.outer((r_new - r) - self.JP @ dt, dt) / float(dt @ dt)
                self.steps.append(dt)
                x, r, chi2 = y, r_new, chi2_new
                fresh = False
                radius = 2 * size if math.isfinite(radius) else radius
            elif not fresh:
                self._take(self.alt.jacobian(x))
                fresh = True
            else:
                radius = 0.25 * size
        return None, (f"not converged in {SPREAD_STEPS} Gauss-Newton steps (the last moved "
                      f"{size:.2g} bars): no optimum to report")


def curve_spread(pb, x, J, JtJ_inv, quantities: dict, A, rules: tuple, lo, hi):
    """w's and E*'s model spread: the fit's optimum moved to each roughness law of ``rules``, the least squares
    of that law's residuals r_law solved from the fit's optimum x by :class:`LawOptimum` (variable projection,
    Gauss-Newton in the branch's coordinates with Broyden's update of the fit's Jacobian J, differenced afresh
    where a step fails and to check convergence), within the fit's bounds.  A law whose optimum is not reached
    in SPREAD_STEPS steps, or lies at a bound, has its moved values Missing with the reason."""
    from ..tracing.model_spread import ModelSpread, Rule, spread_quantity

    model = replace(pb.template, sigma=pb.unpack(x)["sigma"])
    reference = Rule.of(model)
    if model.roughness == "none" or model.sigma == 0:
        return Missing("a smooth surface (sigma = 0): there is no roughness law to vary")
    if reference in rules:
        raise ValueError(f"{reference.label}: the reference's own law, not an alternative to it")
    if JtJ_inv is None:
        return Missing("the fit's covariance is singular: its optimum cannot be moved to another law")
    names = pb.names
    i_w = names.index("ln_gamma")
    t_idx = branch_coordinates(names)
    bar = np.sqrt(np.maximum(np.diag(JtJ_inv)[t_idx], 0.0))
    bar = np.where(bar > 0, bar, 1.0)
    moved_w: list[Measured | Missing] = []
    moved_E: list[Measured | Missing] = []
    notes, times = [], []
    t0 = time.perf_counter()
    for rule in rules:
        t = time.perf_counter()
        alt = replace(pb, template=rule.model(pb.template), cache={}, progress=None, traces=0, evaluations=0)
        alt.weight = pb.weight.copy()
        try:
            law = LawOptimum(alt, x, J, bar, lo, hi)
            xi, why = law.solve()
            if xi is None:
                moved_w.append(Missing(f"{rule.label}: {why}"))
                moved_E.append(Missing(f"{rule.label}: {why}"))
                notes.append(f"{rule.label}: {why}")
            else:
                dx = xi - x
                y = A @ xi
                moved_w.append(Measured(math.exp(y[i_w])))
                notes.append(f"{rule.label}: its optimum reached in {len(law.steps)} Gauss-Newton steps and "
                             f"{alt.traces} curves, ln w moved {dx[i_w]:+.3g}")
                if "ln_mu" in names:
                    # ln E* differs from A's row by a constant: E* at the moved optimum is E* exp(change of the row)
                    d = A @ dx
                    moved_E.append(Measured(float(quantities["E_star"].value) * math.exp(d[names.index("ln_mu")]))
                                   if isinstance(quantities["E_star"], Measured) else Missing("E* undetermined"))
        except (ValueError, RuntimeError, FloatingPointError) as why:
            moved_w.append(Missing(f"{rule.label}: {why}"))
            moved_E.append(Missing(f"{rule.label}: {why}"))
            notes.append(f"{rule.label}: its curve could not be traced at the optimum ({why})")
        pb.traces += alt.traces
        times.append(time.perf_counter() - t)
    qs = []
    if isinstance(quantities["gamma"], Measured):
        qs.append(spread_quantity("work of adhesion gamma", "gamma", quantities["gamma"], tuple(moved_w), rules,
                                  reference))
    if "ln_mu" in names and isinstance(quantities["E_star"], Measured):
        qs.append(spread_quantity("reduced modulus E*", "E_star", quantities["E_star"], tuple(moved_E), rules,
                                  reference))
    if not qs:
        return Missing(f"w and E* are undetermined under {reference.label}: no value to spread about")
    return ModelSpread(reference, rules, tuple(qs), tuple(notes), time.perf_counter() - t0, tuple(times))


def profiled(cov_p: np.ndarray, J: np.ndarray, A: np.ndarray, d, s2: float, names: tuple,
             spread: np.ndarray | None) -> np.ndarray:
    """The reported covariance where the curve hardly determines mu and the table's profile (``spread``,
    :func:`~petsc_adhesion.fitting.table_search.mu_profile`: each coordinate's largest move over the mu the
    curve allows) was taken: the others' block with ln mu held, s^2 (J_f^T J_f)^-1 over the other columns
    J_f, each bar grown by its profile's move / Z95, linearly (a 95% interval then spans the profile's range
    and the statistical interval about each end), and the table's step d d^T; ln E*'s own variance the full
    Jacobian's (what its warning quotes), uncorrelated with the rest.  The full inverse lets ln mu move along
    a direction the curve does not determine far out of the model's range (+-300 at the DMT end) and carries
    that linearly into the others (w's bar 3% to 16% at mu = 0.015, K = 0.0098, where its move over the mu
    the curve allows is 0.6%); the profile measures that move on the model's own curves.  Without a profile
    (no table, or mu determined), ``cov_p`` as it is."""
    if spread is None or "ln_mu" not in names:
        return cov_p
    j = names.index("ln_mu")
    free = np.arange(len(names)) != j
    try:
        sub = np.linalg.inv(J[:, free].T @ J[:, free]) * s2
    except np.linalg.LinAlgError:
        return cov_p
    sd = np.sqrt(np.clip(np.diag(sub), 0.0, None))
    grow = np.where(sd > 0, (sd + spread[free] / Z95) / np.where(sd > 0, sd, 1.0), 1.0)
    cov = np.zeros((len(names), len(names)))
    cov[np.ix_(free, free)] = sub * np.outer(grow, grow)
    out = A @ cov @ A.T + (np.outer(d, d) if d is not None else 0.0)
    out[j, :] = 0.0                     # the row of ln E* (A maps ln mu's index to it)
    out[:, j] = 0.0
    out[j, j] = cov_p[j, j]
    return out


def to_moduli(names: tuple) -> np.ndarray:
    """The linear map of the fitted coordinates to (ln E*, ln w, ...): ln E* = ln w - 1.5 ln mu + const
    (eq. 9), the others as they are."""
    m = len(names)
    A = np.eye(m)
    if "ln_mu" in names:
        i, j = names.index("ln_mu"), names.index("ln_gamma")
        A[i, :] = 0.0
        A[i, i], A[i, j] = -1.5, 1.0
    return A
