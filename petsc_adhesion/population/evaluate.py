"""A particle's pull-off from its footprint's heights: two evaluators behind one protocol (:class:`Evaluator`:
``name`` and ``evaluate_all``, an :class:`Evaluation` of each particle).

**solver** (:class:`SolverEvaluator`): the curve traced by the solver under the
particle's own measured law (the footprint's heights, eq. 7 averaged over their
histogram, model/roughness.py), only until just past the pull-off (the most tensile F,
then the load's zero: ``observable_max`` 0), with its error bar from nested grids:
exact for the model.  That curve is also the whole of a cycle under a rigid machine
(tracing/energy.py): it starts on the far branch and ends compressive, past every
turning point of lambda (adhesion makes them tensile), so the energy the cycle
dissipates, the closed integral of F d lambda over the approach's snap-on and the
retraction's snap-off (units 2 pi R w epsilon), comes with it; its bar needs the two
folds located again on nested grids (``Trace.energy``: kinds snap_on and snap_off
asked for).  A curve without a turning point of lambda gives a computed 0 (no
hysteresis), not a missing value.  The footprint's size comes from the pull-off's own contact
radius, iterated (model/footprint.py): the heights of a footprint make a pull-off whose
contact radius makes the next footprint, until the next footprint holds the same pixels
to :data:`SETTLED` (at most :data:`PASSES` solves).

**table** (:class:`TableEvaluator`): any :class:`PullOffModel` -- the Gaussian rule's
pull-off F(mu, sigma) tabulated and interpolated (``petsc_adhesion.family.pull_off``'s
``PullOffTable``, loaded by :func:`load_table`), at the footprint's rms: fast, and the
rule, not the measured law.  Its footprint is sized by the smooth sphere's contact
radius at pull-off (Maugis-Dugdale), no solve to iterate on.  The table holds pull-offs
only: a particle's energy of a cycle is missing with that reason.

:class:`GaussianRule` is the rule computed by the solver itself (the 16-point Hermite
average, eq. 10, at each (mu, sigma)): what the model spread compares with where no
table is installed, a :class:`PullOffModel` too.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from ..errors import first_line
from ..model.parameters import Model
from ..model.roughness import SMALLEST_RMS
from ..tracing.measured import Measured, Missing
from ..tracing.trace import CurveRequest, GridChoice, SolverChoice, curve_settings, step_scale, trace_curve
from .footprint import Footprint, footprint, footprint_radius, md_contact_radius

__all__ = ["Evaluator", "PullOffModel", "TableMissing", "load_table", "SolverEvaluator", "TableEvaluator", "GaussianRule",
           "Evaluation", "Solved", "Trace", "PASSES", "SETTLED", "EVALUATORS", "NO_ENERGY_TABLE", "NO_ENERGY_ASKED"]

#: The most solves of the solver's footprint iteration.
PASSES = 4
#: The footprint has settled when the next pass's holds this share of its pixels more or fewer.
SETTLED = 0.01
#: -pop_evaluator's names.
EVALUATORS = ("solver", "table")
#: Why a table-evaluated particle has no energy of a cycle.
NO_ENERGY_TABLE = "the pull-off table holds pull-offs only: no energy of a cycle (the solver evaluator gives it)"
#: Why a particle has none when it was not asked for.
NO_ENERGY_ASKED = "the energy of a cycle was not asked for (-pop_energy false; Trace.energy False)"


class PullOffModel(Protocol):
    """The pull-off of the Gaussian rule at (mu, sigma), vectorized: ``pull_off(mu, sigma)`` -> (F, err), F in
    units 2 pi R w (negative: tensile), err its bar (the solver's and the interpolation's); ``covers(mu,
    sigma)`` -> bool array, where the model answers."""

    def pull_off(self, mu: np.ndarray, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """F and its bar at each (mu, sigma)."""

    def covers(self, mu: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        """Whether each (mu, sigma) lies in the model's range."""


class Evaluator(Protocol):
    """What the population asks of an evaluator: its ``name`` (the run says which it used) and
    ``evaluate_all(topography, draws, mus, epsilon)``, an :class:`Evaluation` of each particle (its draw and
    Tabor parameter), in their order."""

    name: str

    def evaluate_all(self, topography, draws: list, mus: list, epsilon: float) -> list:
        """Each particle's footprint and pull-off."""


class TableMissing(RuntimeError):
    """No pull-off table in this installation."""


def load_table() -> PullOffModel:
    """The Gaussian rule's pull-off table of ``petsc_adhesion.family.pull_off`` (``PullOffTable.default()``);
    :class:`TableMissing` where it is not installed."""
    import importlib

    try:       # the table of family/, by name: present once it is built (an installation without it refuses)
        pull_off = importlib.import_module("..family.pull_off", __package__)
    except ImportError:
        raise TableMissing("the pull-off table (petsc_adhesion.family.pull_off) is not in this installation; "
                           "use the solver") from None
    return pull_off.PullOffTable.default()


@dataclass(frozen=True)
class Trace:
    """How the solver traces a pull-off: its grid and solvers, the far field, the error bars, and whether the
    energy of the rigid machine's cycle is given with its bar (``energy``: its two folds located on nested
    grids too)."""

    grid: GridChoice = GridChoice()
    solver: SolverChoice = SolverChoice()
    farfield: bool = True
    error_bars: bool = True
    energy: bool = True


@dataclass(frozen=True)
class Solved:
    """One curve's answer for a particle: the pull-off ``F`` (units 2 pi R w), the ``contact_radius`` there
    (units sqrt(R epsilon); None where not had) and the ``energy`` of the rigid machine's cycle (units
    2 pi R w epsilon: Measured, a computed 0 without hysteresis, or Missing with why)."""

    F: Measured | Missing
    contact_radius: float | None
    energy: Measured | Missing


def _pull_off(model: Model, how: Trace, comm) -> Solved:
    """The most tensile load of ``model``'s curve traced just past it, its contact radius there, and the
    energy of the cycle that curve closes (module docstring)."""
    settings = replace(curve_settings(step_scale(model)), observable_max=0.0)
    kinds = ("F_min", "equilibrium") + (("snap_on", "snap_off") if how.energy else ())
    try:
        c = trace_curve(model, how.grid, how.solver, settings=settings,
                        request=CurveRequest(kinds=kinds, error_bars=how.error_bars), comm=comm)
    except (RuntimeError, ValueError, FloatingPointError) as e:
        why = Missing(f"the solver failed: {first_line(e)}")
        return Solved(why, None, why)
    energy = c.rigid.energy if how.energy else Missing(NO_ENERGY_ASKED)
    po = c.pull_off
    if po is None:
        return Solved(Missing("the curve has no pull-off: " + ("; ".join(c.assessment.warnings) or
                                                                "it stopped before")), None, energy)
    a = po.contact_radius.value if isinstance(po.contact_radius, Measured) else None
    return Solved(po.F, a, energy)


def measured_model(mu: float, heights: np.ndarray, farfield: bool = True) -> Model:
    """The model of a particle of Tabor parameter ``mu`` on ``heights`` (units of epsilon, from their mean
    plane): the measured law, or the smooth sphere where they are flat (rms below SMALLEST_RMS)."""
    h = np.asarray(heights, dtype=float)
    if h.size == 0 or float(np.sqrt(np.mean((h - h.mean()) ** 2))) < SMALLEST_RMS:
        return Model(mu=mu, roughness="none", farfield=farfield)
    return Model(mu=mu, roughness="measured", heights=h, farfield=farfield)


@dataclass(frozen=True)
class Evaluation:
    """One particle evaluated: its ``footprint`` (None: none fits the scan), ``pull_off`` (units 2 pi R w) or
    why it is missing, the ``energy`` of its cycle (units 2 pi R w epsilon) or why it is missing, the solves
    of its footprint iteration (``passes``; 0 for the table) and a ``note``."""

    footprint: Footprint | None
    pull_off: Measured | Missing
    energy: Measured | Missing
    passes: int = 0
    note: str = ""


class SolverEvaluator:
    """The measured law by the solver, the footprint iterated (module docstring); ``comm`` of each curve
    (one rank: the particles are spread over the ranks)."""

    name = "solver"

    def __init__(self, trace: Trace = Trace(), comm=None):
        self.trace, self.comm = trace, comm

    def measured(self, mu: float, heights: np.ndarray, energy: bool | None = None) -> Solved:
        """The pull-off, its contact radius and the energy of a cycle of a particle of ``mu`` on ``heights``
        (units of epsilon); ``energy`` False leaves the energy out (None: as the evaluator's Trace says)."""
        how = self.trace if energy is None else replace(self.trace, energy=energy)
        return _pull_off(measured_model(mu, heights, self.trace.farfield), how, self.comm)

    def evaluate(self, topography, draw, mu: float, epsilon: float) -> Evaluation:
        """The particle ``draw`` (:class:`~petsc_adhesion.population.sample.Draw`: its radius and site deviates)
        of Tabor parameter ``mu``.  Each pass's site is the draw's uniform deviates mapped onto the sites where
        that pass's footprint fits (:meth:`~petsc_adhesion.population.sample.Draw.site`): the settled footprint
        lies inside the scan, its site uniform over those where it does (a pass moves it by at most the
        change of the footprint's radius)."""
        R, passes, a = draw.radius, 0, md_contact_radius(mu)

        def at(a: float) -> Footprint | None:
            radius = footprint_radius(a, R, epsilon)
            site = draw.site(radius, topography.size, topography.pixel_size)
            return None if site is None else footprint(topography, site, radius, epsilon)

        fp = at(a)
        while True:
            if fp is None:
                why = Missing(f"the footprint (contact radius {a:.3g} sqrt(R epsilon) at pull-off) is larger than "
                              f"the scan")
                return Evaluation(None, why, why, passes)
            if not fp.usable:
                return Evaluation(fp, Missing(fp.note), Missing(fp.note), passes)
            got = self.measured(mu, fp.heights)
            passes += 1
            F, a_new = got.F, got.contact_radius
            if not isinstance(F, Measured) or a_new is None:
                return Evaluation(fp, F, got.energy, passes)
            nxt = at(a_new)
            # settled: the next footprint holds the same pixels to SETTLED (its heights, its pull-off the same)
            if nxt is not None and abs(nxt.pixels - fp.pixels) <= SETTLED * fp.pixels:
                return Evaluation(fp, F, got.energy, passes)
            if passes == PASSES:
                return Evaluation(fp, F, got.energy, passes, f"the footprint had not settled after {PASSES} solves "
                                                             f"({fp.pixels} then {nxt.pixels if nxt else 'no'} "
                                                             f"pixels)")
            fp, a = nxt, a_new


    def evaluate_all(self, topography, draws: list, mus: list, epsilon: float) -> list:
        """Each particle by :meth:`evaluate`, one after the other."""
        return [self.evaluate(topography, d, mu, epsilon) for d, mu in zip(draws, mus)]


class TableEvaluator:
    """The Gaussian rule at the footprint's rms, from a :class:`PullOffModel` (``model``)."""

    name = "table"

    def __init__(self, model: PullOffModel):
        self.model = model

    def footprint(self, topography, draw, mu: float, epsilon: float) -> Footprint | Missing:
        """The footprint of ``draw`` sized by the smooth sphere's contact radius at pull-off, its site uniform
        over those where it fits."""
        radius = footprint_radius(md_contact_radius(mu), draw.radius, epsilon)
        site = draw.site(radius, topography.size, topography.pixel_size)
        if site is None:
            return Missing("the footprint is larger than the scan")
        return footprint(topography, site, radius, epsilon)

    def evaluate_all(self, topography, draws: list, mus: list, epsilon: float) -> list:
        """Each particle's footprint, then the rule at their rms in one call of the table."""
        found = [self.footprint(topography, d, mu, epsilon) for d, mu in zip(draws, mus)]
        usable = {k: fp for k, fp in enumerate(found) if isinstance(fp, Footprint) and fp.usable}
        values = dict(zip(usable, self.evaluate_many(np.array([mus[k] for k in usable]),
                                                     np.array([fp.rms / epsilon for fp in usable.values()]))))
        none = Missing(NO_ENERGY_TABLE)
        return [Evaluation(fp, values.get(k, Missing(fp.note)), none) if isinstance(fp, Footprint) else
                Evaluation(None, fp, none) for k, fp in enumerate(found)]

    def evaluate_many(self, mu: np.ndarray, sigma: np.ndarray) -> list[Measured | Missing]:
        """The rule's pull-off at each (mu, sigma), Missing outside the table."""
        mu, sigma = np.asarray(mu, dtype=float), np.asarray(sigma, dtype=float)
        if mu.size == 0:
            return []
        inside = np.asarray(self.model.covers(mu, sigma), dtype=bool)
        # the table refuses a point outside its range (OutOfRange): ask it for the points it covers only
        F, err = np.full(mu.shape, np.nan), np.full(mu.shape, np.nan)
        if inside.any():
            F[inside], err[inside] = (np.asarray(x, dtype=float) for x in self.model.pull_off(mu[inside], sigma[inside]))
        return [Measured(float(f), float(e)) if ok and np.isfinite(f) else
                Missing(f"mu = {m:.4g}, sigma = {s:.4g} outside the table's range")
                for f, e, ok, m, s in zip(F, err, inside, mu, sigma)]


class GaussianRule:
    """The Gaussian rule's pull-off (16-point Hermite, eq. 10) by the solver at each (mu, sigma): a
    :class:`PullOffModel` exact where the table interpolates, at a solve per point."""

    def __init__(self, trace: Trace = Trace(), comm=None):
        self.trace, self.comm = trace, comm

    def one(self, mu: float, sigma: float) -> Measured | Missing:
        """The rule's pull-off at one (mu, sigma)."""
        model = Model(mu=mu, sigma=sigma, roughness="hermite" if sigma > 0 else "none", farfield=self.trace.farfield)
        return _pull_off(model, replace(self.trace, energy=False), self.comm).F

    def pull_off(self, mu: np.ndarray, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out = [self.one(float(m), float(s)) for m, s in zip(np.ravel(mu), np.ravel(sigma))]
        F = np.array([q.value if isinstance(q, Measured) else np.nan for q in out])
        err = np.array([q.err if isinstance(q, Measured) and q.err is not None else np.nan for q in out])
        return F, err

    def covers(self, mu: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        return np.ones(np.shape(mu), dtype=bool)
