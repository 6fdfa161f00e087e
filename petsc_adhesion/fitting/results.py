"""A fit's inputs and results as values: the spring, what is fitted, the features a curve shows, the fitted
curve (:class:`CurveFit`) and the fitted pull-off (:class:`PullOffFit`), and the rules that say when a fit does
not hold (docs/fitting.md, "When a fit does not hold").

Every fitted quantity is a :class:`~petsc_adhesion.tracing.measured.Measured` (its value and one standard
deviation) or, where the fit did not determine it, a :class:`~petsc_adhesion.tracing.measured.Missing` with the
reason; a quantity held at a given value is a ``Measured`` without a bar whose note says so.  A fit is
``complete`` when every quantity it was asked for has a number, ``trustworthy`` when besides no rule below
fired (``warnings`` empty): the command line's exit status 0, else 3.

The rules:

- a parameter at a bound (within ``BOUND_MARGIN`` of it, in the fitted coordinate): the data ask for a value
  the fit may not reach, so its value is the bound's and its bar one-sided; said, with the bound;
- a parameter undetermined: its 95% interval (1.96 bars) wider than its value, or a covariance that is
  singular or not finite there; it is Missing with that reason;
- a misfit: the probability that noise alone makes a chi^2 as large as the fit's is below ``MISFIT_P``.
  With the noise estimated from the baseline, chi^2 / dof over that estimate's own spread is Fisher's F with
  (dof, nu) degrees of freedom, nu the estimate's effective degrees of freedom (:func:`misfit_p`); with a
  stated noise, chi^2 has the chi^2 distribution with dof degrees of freedom.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..model.physical import Bodies
from ..tracing.measured import Measured, Missing

__all__ = ["Spring", "FitChoice", "Instrument", "Features", "FittedFeatures", "ClosedForm", "CurveFit", "PullOffFit",
           "BOUND_MARGIN", "MISFIT_P", "Z95", "NOISE_DOF_PER_DIFFERENCE", "misfit_p", "undetermined", "misfit"]

#: How near a bound (in the fitted coordinate: ln mu, ln w, sigma) a parameter is said to be at it: 1% in w
#: or mu, 0.01 in sigma.
BOUND_MARGIN = 0.01
#: The probability below which a chi^2 is more than the noise can make (docs/fitting.md).
MISFIT_P = 1e-6
#: The half-width of a 95% interval in standard deviations (a Gaussian's 97.5% point).
Z95 = 1.959963984540054
#: The effective degrees of freedom of the baseline's noise estimate (1.4826 MAD of successive differences
#: over sqrt 2) per difference: 2 / var(s^2 / sigma^2) measured on Gaussian noise, 0.30 to 0.32 for 30 to
#: 1000 points (MAD's efficiency 0.37 times the loss of successive differences sharing a point).
NOISE_DOF_PER_DIFFERENCE = 0.3

Quantity = Measured | Missing


class Predictor(Protocol):
    """The fitted model a :class:`CurveFit` predicts from (:class:`~petsc_adhesion.fitting.curve_fit.FittedModel`,
    named by its member here because that module imports this one)."""

    def predict(self, z: np.ndarray, leg: str) -> np.ndarray:
        """The force (N) at piezo positions ``z`` on ``leg`` (approach or retract)."""


@dataclass(frozen=True)
class Spring:
    """A cantilever: its spring constant ``k`` (N/m) and where it came from (``source``)."""

    k: float
    source: str = "given"

    def K(self, bodies: Bodies, w: float) -> float:
        """The dimensionless stiffness K = k eps / (2 pi R w) against the bodies at work of adhesion ``w``."""
        return self.k * bodies.epsilon / (2 * math.pi * bodies.R * w)


@dataclass(frozen=True)
class FitChoice:
    """What a curve fit fits: the modulus (else held at the bodies'), the roughness (else held at the bodies'
    rms, smooth without one); ``noise`` the measurement's stated noise (N, one standard deviation; None: the
    far baseline's); ``max_evaluations`` of the least squares (on the curve family table with the roughness
    fitted TABLE_EVALS times it: :mod:`~petsc_adhesion.fitting.table_search`)."""

    modulus: bool = True
    roughness: bool = False
    noise: float | None = None
    max_evaluations: int = 40
    #: the instrument's nuisance parameters (docs/fitting.md, "The instrument in the fit"): the deflection
    #: sensitivity's scale c fitted (else held at ``invols_scale``, 1 or the calibration's), the spring
    #: constant's standard uncertainty (N/m; None: k held), a baseline sloped in z (the virtual deflection),
    #: the retract's baseline offset from the approach's (drag)
    invols_fitted: bool = False
    invols_scale: float = 1.0
    calibrate_invols: bool = False
    spring_err: float | None = None
    virtual_deflection: bool = False
    drag: bool = False
    #: which legs are fitted (approach, retract, both) and the piezo range fitted (m; None: all)
    segment: str = "both"
    z_range: tuple | None = None
    #: outside the model's domain (docs/fitting.md, "Where the model applies"): refuse before fitting, or fit
    #: and warn
    outside_domain: str = "refuse"

    def __post_init__(self):
        if self.segment not in ("approach", "retract", "both"):
            raise ValueError(f"segment: expected approach, retract or both, got {self.segment!r}")
        if self.outside_domain not in ("refuse", "warn"):
            raise ValueError(f"outside_domain: expected refuse or warn, got {self.outside_domain!r}")
        if not (isinstance(self.max_evaluations, int) and self.max_evaluations >= 1):
            raise ValueError(f"max_evaluations: expected a positive integer, got {self.max_evaluations!r}")
        if not (math.isfinite(self.invols_scale) and self.invols_scale > 0):
            raise ValueError(f"invols_scale: expected a finite positive number, got {self.invols_scale!r}")
        if self.spring_err is not None and not (math.isfinite(self.spring_err) and self.spring_err > 0):
            raise ValueError(f"spring_err: expected a finite positive spring constant (N/m), got {self.spring_err!r}")
        if self.z_range is not None:
            lo, hi = self.z_range
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"z_range: expected two finite piezo positions lo < hi (m), got {self.z_range!r}")


@dataclass(frozen=True)
class Instrument:
    """The instrument's nuisance parameters of a curve fit, each a Measured (fitted: with its bar; held: no bar
    and a note saying at what) or Missing: ``invols_scale`` c, the factor the true deflection sensitivity is
    of the one the file's deflection was converted with (the true deflection and force are c times the
    file's, at the true spring constant); ``spring`` the true spring constant (N/m); ``virtual_deflection``
    the baseline's slope in z (N/m); ``drag`` the retract's baseline offset from the approach's (N);
    ``contact_slope`` the measured slope of the approach in contact (N/m, the file's force against z)."""

    invols_scale: Quantity
    spring: Quantity
    virtual_deflection: Quantity
    drag: Quantity
    contact_slope: float | None = None


@dataclass(frozen=True)
class Features:
    """What a measured curve shows by itself (SI): the baseline ``F0_N`` and its ``noise_N`` with the noise
    estimate's effective degrees of freedom ``noise_dof`` (``noise_note`` where the baseline shows none);
    the largest force above the baseline ``contact_N``; the pull-off ``pull_off_N`` at ``pull_off_z_m``
    (force there ``pull_off_at_N``); the jump-in at ``jump_in_z_m`` and its size ``jump_in_drop_N``; the
    jump-off's rise ``jump_off_rise_N``; the first approach point in contact ``contact_from`` and the first
    retract point off it ``free_from`` (None where the force does not jump by more than 10 noise); the slope of
    the approach in contact ``contact_slope_N_m`` (N/m against the piezo's travel towards the surface, over the
    upper half of the rise; None with fewer than 3 points there) and the number of steps of the retract
    ``retract_steps`` (runs of rises of more than 10 noise and a tenth of the pull-off between successive points:
    a jump spread over a few samples is one step)."""

    F0_N: float
    noise_N: float
    noise_dof: float
    contact_N: float
    pull_off_N: float
    pull_off_z_m: float
    pull_off_at_N: float
    jump_in_z_m: float
    jump_in_drop_N: float
    jump_off_rise_N: float
    contact_from: int | None
    free_from: int | None
    noise_note: str | None = None
    contact_slope_N_m: float | None = None
    retract_steps: int = 0


@dataclass(frozen=True)
class FittedFeatures:
    """The fitted model's jump-in and jump-off positions (m; None where its leg has no jump) and its pull-off
    force (N, the least force on the retract)."""

    pull_off_N: float
    jump_in_z_m: float | None = None
    jump_off_z_m: float | None = None


@dataclass(frozen=True)
class ClosedForm:
    """What a closed form says of a pull-off: its ``name`` (dmt, jkr, maugis_dugdale), ``gamma`` (J/m^2),
    ``mu`` by eq. (9) at it, its ``formula``, and Maugis-Dugdale's ``lambda_MD``."""

    name: str
    gamma: float
    mu: float
    formula: str
    lambda_MD: float | None = None


@dataclass(frozen=True)
class CurveFit:
    """A fitted force curve (SI; docs/fitting.md).

    ``gamma`` (J/m^2), ``E_star`` (Pa) and ``rms`` (m; None for a smooth surface not fitted): Measured with one
    standard deviation, held ones without a bar and a note, Missing where the fit did not determine them;
    ``z0`` (m) and ``F0`` (N) the nuisance parameters (contact point, baseline); ``mu``, ``sigma``, ``K`` of the
    fitted model; ``chi2`` in units of the noise ``noise_N`` with ``dof`` and ``p_value`` (the probability of
    noise alone giving as large a chi^2); ``parameters`` the fitted coordinates and their ``covariance``; the
    data (``data``: the MeasuredCurve) and the fit at its points (``F_fit``, ``used``, ``leg``, ``branch``);
    ``measured`` and ``fitted`` features; ``bodies`` and ``spring`` as given, ``choice`` what was fitted;
    ``notes`` (what the fit met on its way) and ``warnings`` (why it does not hold)."""

    gamma: Quantity
    E_star: Quantity
    rms: Quantity | None
    z0: Quantity
    F0: Quantity
    mu: float
    sigma: float
    K: float
    chi2: float
    dof: int
    noise_N: float
    noise_stated: bool
    p_value: float
    residual_rms_N: float
    parameters: tuple
    covariance: np.ndarray = field(repr=False)
    data: object = field(repr=False)
    F_fit: np.ndarray = field(repr=False)
    used: np.ndarray = field(repr=False)
    leg: np.ndarray = field(repr=False)
    branch: np.ndarray = field(repr=False)
    measured: Features = field(repr=False)
    fitted: FittedFeatures = field(repr=False)
    bodies: Bodies = field(repr=False)
    spring: Spring = field(repr=False)
    choice: FitChoice = field(repr=False)
    traces: int = 0
    iterations: int = 0
    status: str = ""
    wall_time_s: float = 0.0
    notes: tuple = ()
    warnings: tuple = ()
    forward: Predictor | None = field(default=None, repr=False)
    instrument: Instrument | None = field(default=None, repr=False)
    segment: str = "both"
    z_range: tuple | None = None
    spread: object = field(repr=False, default=None)    # ModelSpread | Missing | None: w, E* under other laws
    #: how the optimum was found: a curve_fit.TableStep (the search on the table, then the solver), or why the
    #: solver's curves throughout (a line)
    path: object = field(repr=False, default=None)

    @property
    def reduced_chi2(self) -> float:
        """chi^2 / dof (nan without a degree of freedom)."""
        return self.chi2 / self.dof if self.dof > 0 else math.nan

    @property
    def complete(self) -> bool:
        """Whether every quantity fitted has a number."""
        return all(isinstance(q, Measured) for q in (self.gamma, self.E_star, self.z0, self.F0)) and \
            not isinstance(self.rms, Missing)

    @property
    def trustworthy(self) -> bool:
        """Whether the fit holds: complete, and no rule of docs/fitting.md fired (exit status 0, else 3)."""
        return self.complete and not self.warnings


@dataclass(frozen=True)
class PullOffFit:
    """The work of adhesion of a measured pull-off (SI; docs/fitting.md): ``P`` the pull-off (N) with its bar
    (0: exact); ``gamma`` (J/m^2) Measured or Missing; ``mu`` (eq. 9) and ``sigma`` of the model at gamma;
    ``F`` the model's pull-off there (2 pi R gamma; its value on the grid, ``grid``); ``dlnF_dlnmu`` the slope
    of |F_p| against mu; ``closed_forms`` what DMT, JKR and Maugis-Dugdale say; ``curves`` traced,
    ``history`` the secant's (gamma, mu, F on the grid); ``warnings`` why it does not hold; ``spread``: gamma
    under other roughness laws (a :class:`~petsc_adhesion.tracing.model_spread.ModelSpread` of the one quantity
    "gamma"; None where none was asked for), whose warnings leave the fit trustworthy."""

    P: Measured
    gamma: Quantity
    mu: float
    sigma: float
    F: Measured
    dlnF_dlnmu: float
    closed_forms: tuple
    curves: int
    wall_time_s: float
    bodies: Bodies | None = field(repr=False, default=None)
    history: tuple = field(repr=False, default=())
    warnings: tuple = ()
    spread: object = field(repr=False, default=None)    # ModelSpread | Missing | None: gamma under other laws

    @property
    def complete(self) -> bool:
        return isinstance(self.gamma, Measured)

    @property
    def trustworthy(self) -> bool:
        return self.complete and not self.warnings

    def closed_form(self, name: str) -> ClosedForm:
        """The closed form ``name`` (dmt, jkr, maugis_dugdale)."""
        return next(c for c in self.closed_forms if c.name == name)


# -- the rules -------------------------------------------------------------------------------------------------
def undetermined(value: float, err: float | None) -> str | None:
    """Why a positive quantity with bar ``err`` is undetermined (None where it is determined): a bar that is
    not a finite number, or a 95% interval wider than the value."""
    if err is None or not math.isfinite(err):
        return "a singular covariance: the curve does not determine it"
    if Z95 * err > abs(value):
        return f"its 95% interval +-{Z95 * err:.3g} is wider than its value {value:.3g}"
    return None


def misfit_p(chi2: float, dof: int, noise_dof: float | None) -> float:
    """The probability that noise alone gives a chi^2 at least ``chi2`` with ``dof`` degrees of freedom: the
    chi^2 distribution's upper tail for a known noise (``noise_dof`` None), Fisher's F(dof, noise_dof) at
    chi2 / dof for a noise estimated with ``noise_dof`` effective degrees of freedom."""
    from scipy import stats

    if dof <= 0 or not math.isfinite(chi2):
        return math.nan
    if noise_dof is None:
        return float(stats.chi2.sf(chi2, dof))
    return float(stats.f.sf(chi2 / dof, dof, noise_dof))


def misfit(chi2: float, dof: int, noise_dof: float | None) -> str | None:
    """The warning of a chi^2 the noise cannot explain (p below MISFIT_P), None otherwise."""
    p = misfit_p(chi2, dof, noise_dof)
    if math.isnan(p) or p >= MISFIT_P:
        return None
    prob = f"{p:.2g}" if p > 0 else "below 1e-300"
    return (f"the model does not describe these data: reduced chi^2 {chi2 / dof:.3g} with {dof} degrees of "
            f"freedom, which the noise alone gives with probability {prob} (< {MISFIT_P:g})")
