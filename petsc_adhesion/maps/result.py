"""A force map's result as values: a :class:`Pixel` per curve and the :class:`MapResult` (docs/maps.md).

A pixel's fitted quantities are its :class:`~petsc_adhesion.fitting.results.CurveFit`'s own (``gamma``,
``E_star``, ``rms``: :class:`~petsc_adhesion.tracing.measured.Measured` with one standard deviation, held ones
without a bar, :class:`~petsc_adhesion.tracing.measured.Missing` with the reason the fit did not determine
them); what the curve shows by itself beside them is measured on its data (:func:`measured_quantities`):

- ``pull_off`` (N): the least retract force below the baseline; its bar the noise of one sample;
- ``jump_in`` (N): the approach's jump to contact, the largest drop between two successive samples; its bar
  the noise of a difference of two samples, sqrt 2 times a sample's; Missing where the approach shows no jump
  of more than 10 noise;
- ``energy`` (J): the energy the cycle dissipates, the area between approach and retract,
  E = s sum over the cycle of (F - F_0) dz by the trapezoidal rule (s the approach's direction), its bar the
  noise carried through the rule's weights, sqrt(sum (w_i noise)^2), and the rule's own error, estimated by
  its difference from the rectangle rule (a jump between two samples is where it is largest), in quadrature.

A curve that cannot be fitted is a pixel with a ``status`` other than ``ok`` and its ``reasons``, the fitted
quantities Missing with the same reason: never a number.  The statuses: ``ok`` (the fit holds), ``warned``
(fitted, its values kept as the fit gives them, but a rule of docs/fitting.md fired: a parameter at a bound
or undetermined, a misfit, the cap on evaluations), ``refused`` (no contact, no adhesion, no force-distance
relation), ``outside`` (outside the model's domain), ``unreadable`` (the curve cannot be read) and
``failed`` (the solver failed on it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..fitting.data import MeasuredCurve
from ..fitting.results import CurveFit, FitChoice, Spring
from ..model.physical import Bodies
from ..tracing.measured import Measured, Missing
from .source import Grid, MapEntry

__all__ = ["STATUSES", "Pixel", "MapResult", "Shown", "fitted_pixel", "flagged_pixel", "measured_quantities",
           "QUANTITIES"]

#: What a pixel's fit can end as (see the module).
STATUSES = ("ok", "warned", "refused", "outside", "unreadable", "failed")
#: The quantities of a pixel, each a Measured or Missing (``rms`` also None: not fitted).
QUANTITIES = ("gamma", "E_star", "rms", "pull_off", "jump_in", "energy")
#: The quantities of the fit (drawn only where it holds); the others are what the curve shows by itself.
FITTED = ("gamma", "E_star", "rms", "reduced_chi2")

Quantity = Measured | Missing


@dataclass(frozen=True)
class Pixel:
    """One curve of a map (see the module): where it lies (``entry``), how its fit ended (``status`` and its
    ``reasons``), its quantities, its fit's reduced chi^2 and p-value (None without a fit) and the curves the
    fit traced."""

    entry: MapEntry
    status: str
    reasons: tuple
    gamma: Quantity
    E_star: Quantity
    rms: Quantity | None
    pull_off: Quantity
    jump_in: Quantity
    energy: Quantity
    reduced_chi2: float | None = None
    p_value: float | None = None
    traces: int = 0

    def __post_init__(self):
        if self.status not in STATUSES:
            raise ValueError(f"status: expected one of {', '.join(STATUSES)}, got {self.status!r}")
        if self.status != "ok" and not self.reasons:
            raise ValueError(f"a pixel of status {self.status} says why")

    @property
    def fitted(self) -> bool:
        """Whether the curve was fitted (its numbers are the fit's, held or not)."""
        return self.status in ("ok", "warned")


@dataclass(frozen=True)
class MapResult:
    """A fitted force map: its ``source`` (the path or a name) and ``kind`` (afm, folder, list, curves), its
    ``grid``, a :class:`Pixel` per curve in the source's order; what was fitted and held (``choice``), the
    ``bodies`` given and the ``spring`` (None: each curve's file's); ``resumed`` the pixels taken from a
    journal of an earlier, interrupted run; ``ranks`` the MPI ranks that fitted it and its ``wall_time_s``."""

    source: str
    kind: str
    grid: Grid
    pixels: tuple
    choice: FitChoice
    bodies: Bodies
    spring: Spring | None
    resumed: int = 0
    ranks: int = 1
    wall_time_s: float = 0.0

    def count(self, status: str) -> int:
        """The pixels of ``status``."""
        return sum(p.status == status for p in self.pixels)

    @property
    def trustworthy(self) -> bool:
        """Whether every pixel's fit holds (exit status 0, else 3)."""
        return all(p.status == "ok" for p in self.pixels)

    def image(self, quantity: str) -> np.ndarray:
        """The values of ``quantity`` (a name of QUANTITIES, ``reduced_chi2``) on the grid, shape (ny, nx): NaN
        where no curve lies, where it is Missing, and for a fitted quantity (w, E*, rms, reduced chi^2) where
        the pixel's fit does not hold (what the curve shows by itself, its pull-off, jump-in and energy, is
        drawn wherever the curve was read)."""
        nx, ny = self.grid.shape
        out = np.full((ny, nx), np.nan)
        for p in self.pixels:
            if quantity in FITTED and p.status != "ok":
                continue
            v = getattr(p, quantity)
            v = v.value if isinstance(v, Measured) else v if isinstance(v, float) else None
            if v is not None:
                out[p.entry.iy, p.entry.ix] = v
        return out


@dataclass(frozen=True)
class Shown:
    """What a curve shows by itself (see the module): its ``pull_off``, ``jump_in`` and ``energy``."""

    pull_off: Quantity
    jump_in: Quantity
    energy: Quantity


def flagged_pixel(entry: MapEntry, status: str, reason: str, data: MeasuredCurve | None = None,
                  rms_fitted: bool = False) -> Pixel:
    """The pixel of a curve that was not fitted: every fitted quantity Missing with ``reason``; what the
    curve shows by itself measured where it was read (``data``)."""
    shown = measured_quantities(data) if data is not None else Shown(Missing(reason), Missing(reason),
                                                                     Missing(reason))
    return Pixel(entry, status, (reason,), Missing(reason), Missing(reason), Missing(reason) if rms_fitted else None,
                 shown.pull_off, shown.jump_in, shown.energy)


def fitted_pixel(entry: MapEntry, fit: CurveFit) -> Pixel:
    """The pixel of a fitted curve: the fit's quantities, the curve's own measured on its data."""
    data = fit.data
    assert isinstance(data, MeasuredCurve), "a curve fit holds the measured curve"
    shown = measured_quantities(data)
    status = "ok" if fit.trustworthy else "warned"
    reasons = tuple(fit.warnings) or (() if fit.complete else ("a quantity fitted is undetermined",))
    chi2 = fit.reduced_chi2
    return Pixel(entry, status, reasons, fit.gamma, fit.E_star, fit.rms, shown.pull_off, shown.jump_in,
                 shown.energy, chi2 if math.isfinite(chi2) else None,
                 fit.p_value if math.isfinite(fit.p_value) else None, fit.traces)


#: A jump between successive samples beyond this many noises is a jump (as fitting/domain.py's features).
JUMP_NOISES = 10.0


def measured_quantities(data: MeasuredCurve) -> Shown:
    """What ``data`` shows by itself, with bars (see the module): pull_off, jump_in, energy (Measured or
    Missing)."""
    from ..fitting.domain import features

    try:
        feat = features(data)
    except (ValueError, ArithmeticError, IndexError) as e:
        why = f"the curve's features cannot be read ({type(e).__name__})"
        return Shown(Missing(why), Missing(why), Missing(why))
    noise = feat.noise_N
    note = "the noise of one sample" + (f"; {feat.noise_note}" if feat.noise_note else "")
    pull: Quantity
    jump: Quantity
    if feat.pull_off_N > 0:
        pull = Measured(feat.pull_off_N, noise, note=note)
    else:
        pull = Missing("the retract does not fall below the baseline")
    if feat.contact_from is not None and feat.jump_in_drop_N > JUMP_NOISES * noise:
        jump = Measured(feat.jump_in_drop_N, math.sqrt(2) * noise, note="a difference of two samples' noise")
    else:
        jump = Missing(f"the approach does not jump by more than {JUMP_NOISES:g} noise")
    return Shown(pull, jump, _energy(data, feat.F0_N, noise))


def _energy(data: MeasuredCurve, F0: float, noise: float) -> Quantity:
    """The energy the cycle dissipates (J; see the module), with its bar."""
    z, F = data.z, data.F - F0
    dz = np.diff(z)
    trap = float(np.sum(0.5 * (F[1:] + F[:-1]) * dz)) * data.direction
    rect = float(np.sum(F[:-1] * dz)) * data.direction
    w = np.zeros(z.size)                        # the trapezoidal rule's weights on each sample
    w[1:] += 0.5 * dz
    w[:-1] += 0.5 * dz
    err = math.hypot(noise * float(np.sqrt(np.sum(w * w))), trap - rect)
    if not (math.isfinite(trap) and math.isfinite(err)):
        return Missing("the cycle's area is not finite")
    return Measured(trap, err, note="the noise through the trapezoidal rule and the rule's error, in quadrature")
