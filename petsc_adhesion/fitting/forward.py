"""The force a cantilever measures against its base position: the traced curve behind a spring, read as an
approach and a retract.

The construction (stable pieces between the turning points of Z = lambda + F / K,
jumps vertical in F at constant Z: :mod:`petsc_adhesion.tracing.legs`, the
instrument's legs' own; F(Z) between the points by splines, the far branch
continued by the rigid sphere's load, eq. 28: :class:`~petsc_adhesion.family.legs.Legs`,
shared with the family table's interpolated curves) is not repeated here; a traced
:class:`~petsc_adhesion.tracing.curve.Curve` is read into it: its branch's points,
its stability behind the spring, and its jump_in and jump_off events (their values
on their grid, and the state the library found each jump lands on).

The curve family table (:mod:`petsc_adhesion.family.table`) gives the same
:class:`~petsc_adhesion.family.legs.Legs` interpolated, in milliseconds: a fit's search
runs on it where it covers the model (:func:`open_table`, :func:`table_covers`).
"""
from __future__ import annotations

import math
import os

import numpy as np

from ..family.legs import APPROACH, RETRACT, Legs, Piece
from ..family.table import SHIPPED, FamilyTable, default_table, shipped
from ..tracing.legs import turn_of

__all__ = ["Piece", "ForwardCurve", "aligned_contact", "APPROACH", "RETRACT", "curve_stop_reason", "curve_jumps", "pull_off_values",
           "open_table", "table_choice", "table_covers", "table_legs", "SIGMA_SEARCH", "rough_first"]


# -- what fitting/ reads of a traced Curve: these functions alone ---------------------------------------------
def curve_stop_reason(curve) -> str:
    """Why the traced curve ended."""
    return str(curve.diagnostics.stop_reason)


def curve_jumps(curve, kind: str) -> list:
    """The events of ``kind`` (jump_in or jump_off) of a curve traced behind a spring."""
    return [e for e in curve.events if e.kind == kind]


def pull_off_values(e) -> tuple[float, float | None, float]:
    """A pull-off event's (best F, its bar or None, F on its grid)."""
    F = e.F                             # a Measured
    return float(F.value), (None if F.err is None else float(F.err)), \
        float(F.grid if F.grid is not None else F.value)


class ForwardCurve(Legs):
    """F(Z) on the approach and the retract of a traced :class:`~petsc_adhesion.tracing.curve.Curve` behind a
    spring of stiffness ``K`` (:class:`~petsc_adhesion.family.legs.Legs`); everything in the model's units."""

    def __init__(self, curve, K: float):
        b = curve.branch
        super().__init__(b.lam, b.F, b.stable_spring, K, [turn_of(e) for e in curve_jumps(curve, "jump_in")],
                         [turn_of(e) for e in curve_jumps(curve, "jump_off")])


# -- the curve family table as a fit's forward model ----------------------------------------------------------
#: The sigma a fitted roughness is searched over: outcome.py's SIGMA_MAX (not imported: outcome imports this module).
SIGMA_SEARCH = 3.0


def open_table(spec) -> FamilyTable | None:
    """The table a fit searches on: ``spec`` "default" (the package's, :data:`~petsc_adhesion.family.table.SHIPPED`),
    a shipped table's name, a file, a FamilyTable, or "none"/None (the solver alone).  ValueError, one line, for a
    file that is no table."""
    if spec is None or isinstance(spec, FamilyTable):
        return spec
    if not isinstance(spec, str) or not spec:
        raise ValueError(f"expected a table file, default or none, got {spec!r}")
    if spec == "none":
        return None
    if spec == "default" or spec in SHIPPED:
        return shipped(SHIPPED[0] if spec == "default" else spec)
    return FamilyTable.load(spec)


def table_choice(spec, sigma: float, fitted: bool, mu_range: tuple) -> tuple[FamilyTable | None, str]:
    """(the table a fit searches on, its label in the fit's notes): ``spec`` as :func:`open_table` takes it, but
    "default" is the rough table where the fit has a roughness (``fitted``, or held at ``sigma`` > 0) and the
    rough table's range holds the fit's (:func:`~petsc_adhesion.family.table.default_table`: its sigma and all of
    ``mu_range``, the mu the search may reach), labelled "default rough"; the smooth one otherwise, "default".
    ValueError, one line, for a file that is no table."""
    if spec == "default":
        name = default_table(sigma, fitted, mu_range)
        return open_table(name), "default" if name == SHIPPED[0] else f"default {name}"
    family = open_table(spec)
    return family, "none" if family is None else spec if isinstance(spec, str) else "given"


def rough_first(fit, choice, model, bodies, mu_bounds: tuple):
    """A rough fit with ``-fit_table default`` (the roughness fitted, or held at a sigma > 0 of ``bodies``) where
    the shipped rough table holds its sigma (a fitted one: over the whole search, 0 to SIGMA_SEARCH) but mu over
    part of ``mu_bounds`` alone: ``fit("rough")`` (the search on the rough table, the final numbers from the
    solver), kept where mu's 95% interval ends inside the table (where the curve hardly determines mu, where the
    table's profile of mu ends: the linear interval runs to 1e139 at the DMT end); else ``fit("none")`` (the
    solver's curves throughout, over all of ``mu_bounds``), its path saying why.  None where this does not apply
    (smooth; another rule, ``model``; a rough table that holds all of mu, which "default" takes itself).

    Why: on the solver's curves throughout a rough fit takes some 75 traces (82 CPU s at mu = 0.0055, sigma = 1);
    through the rough table 3 (2.1 s) to the same optimum (mu 0.0053055 against 0.0053061).  A search bounded
    at the table's end would stop at the table's bound, not the data's: where mu or its interval reaches that end
    the solver takes over; and where the search on the table ended in another valley than the data's (a misfit,
    as at mu = 0.3, sigma = 1.5 at 1% noise: reduced chi^2 121), the solver's own search is tried."""

    from ..family.table import shipped_path
    from .results import BOUND_MARGIN, MISFIT_P

    sigma = 0.0 if bodies.rms is None else bodies.rms / bodies.epsilon
    if not (choice.roughness or sigma > 0) or not os.path.exists(shipped_path("rough")) or \
            (model is not None and (model.roughness, model.hermite_points) != ("hermite", 16)):
        return None
    t = shipped("rough")
    lo, hi = (0.0, SIGMA_SEARCH) if choice.roughness else (sigma, sigma)
    if not float(t.sigma[0]) <= lo <= hi <= float(t.sigma[-1]) or \
            default_table(sigma, choice.roughness, mu_bounds) == "rough":
        return None
    first = fit("rough")
    if isinstance(first.path, str):     # the table did not hold the model (its domain, far field): the solver's
        return first
    names, cov = first.parameters, first.covariance
    if "ln_E_star" in names:             # ln mu = (2/3)(ln w - ln E*) + const (eq. 9)
        a = np.zeros(len(names))
        a[names.index("ln_gamma")], a[names.index("ln_E_star")] = 2.0 / 3.0, -2.0 / 3.0
        var = float(a @ cov @ a)
    else:
        var = 4.0 / 9.0 * float(cov[names.index("ln_gamma"), names.index("ln_gamma")])
    top = math.log(first.mu) + 1.96 * math.sqrt(var) if math.isfinite(var) and var >= 0 else math.inf
    span = getattr(first.path, "mu_span", None)
    if span is not None:                # mu hardly determined: the profile's reach, not the line's (+-1e139)
        top = math.log(span[1])
    edge = float(t.mu[-1])
    misfit = not first.p_value >= MISFIT_P
    # a mu at the table's end (within BOUND_MARGIN) is the search's bound, not the data's (its profile goes
    # inwards alone from there: mu = 1, ending 7e-9 inside, was kept)
    if top < math.log(edge) - 1e-9 and math.log(first.mu) < math.log(edge) - BOUND_MARGIN and not misfit:
        return first
    from dataclasses import replace

    why = (f"the fit on it misfit the data (reduced chi^2 {first.reduced_chi2:.3g})" if misfit else
           f"the fit on it stopped at mu = {first.mu:.3g}, the table's end" if top < math.log(edge) - 1e-9 else
           f"the fit on it reached mu = {first.mu:.3g} with its 95% interval up to {math.exp(min(top, 700.0)):.3g}")
    return replace(fit("none"), path=f"the solver's curves throughout: the rough table holds mu up to {edge:g}, and "
                                     f"{why}")


def table_covers(table: FamilyTable, model, rmax: float, fit_sigma: bool, sigma: float) -> str | None:
    """Why ``table`` does not hold the model a fit asks for (None where it does): the table's roughness rule,
    its domain (the end ``rmax`` of the fit's, against the default grid's that the table's nodes were traced
    on) and far field, its sigma (fitted roughness needs a table over sigma; a held one its nodes' range).  mu
    is the search's bound."""
    from ..tracing.trace import GridChoice

    lo, hi = float(table.sigma[0]), float(table.sigma[-1])
    rule = table.roughness.split()[0]
    if fit_sigma and hi <= lo:
        return f"the roughness is fitted and the table holds sigma = {lo:g} alone"
    if fit_sigma and (lo > 0 or hi < SIGMA_SEARCH):  # the search's sigma would leave the table mid-fit
        return f"the roughness is fitted over [0, {SIGMA_SEARCH:g}] and the table holds sigma in [{lo:g}, {hi:g}]"
    if not (lo - 1e-12 <= sigma <= hi + 1e-12):
        return f"sigma = {sigma:.4g} is outside the table's [{lo:g}, {hi:g}]"
    if sigma > 0 or fit_sigma:
        if model.roughness != rule or f"{model.roughness} {model.hermite_points}" != table.roughness:
            return f"the roughness law is {model.roughness}; the table holds {table.roughness}"
    elif model.roughness not in (rule, "none"):
        return f"the roughness law is {model.roughness}; the table holds {table.roughness}"
    own = GridChoice().default_rmax
    if not math.isclose(rmax, own, rel_tol=1e-12):
        return f"the domain ends at r_m = {rmax:g}; the table's at {own:g}"
    if not model.farfield:
        return "the far field is left out (-adh_farfield 0); the table's curves hold it"
    return None


def table_legs(table: FamilyTable, mu: float, sigma: float, K: float, reach: float | None = None) -> Legs:
    """The table's curve at (mu, sigma) behind the spring K as :class:`~petsc_adhesion.family.legs.Legs` (the
    contact continued linearly past the table's F_max, as a traced curve's past its end; its far branch
    tabulated beyond the base position ``reach``)."""
    return table.curve(mu, sigma, error=False).behind(K, reach).legs     # (the legs carry no error bars)


def aligned_contact(pb, x: np.ndarray) -> float:
    """The contact point z0 / eps that best puts the model's curve on the data, the other coordinates of ``x``
    held (``pb``, the curve fit's problem): its jump-off (or, behind a lever stiffer than its well, its least
    force) on the measured pull-off, then the least squares in z0 alone (Brent's bounded minimum)."""
    from .. import brent

    p = pb.unpack(x)
    fc = pb.forward(p)
    jumps = fc.jumps[RETRACT]
    # without a jump-off the pull-off is the least force; the far end of the curve (as before) put every rough
    # start 25 epsilon off (mu 0.0055, sigma 1, K 0.19), where the model is flat over the data and the search
    # went to w's bound
    Z_off = jumps[-1] if jumps else fc.least_force(RETRACT)[0]
    guess = (pb.feat.pull_off_z_m - pb.data.direction * pb.eps * Z_off) / pb.eps
    j = pb.names.index("z0")

    def cost(z0):
        y = x.copy()
        y[j] = z0
        return float(np.sum(pb._all(pb.unpack(y))[0] ** 2))

    width = 2.0 + 0.1 * abs(Z_off)
    return brent.minimum(cost, guess - width, guess + width, xatol=1e-4)
