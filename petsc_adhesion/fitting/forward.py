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

from ..family.legs import APPROACH, RETRACT, Legs, Piece
from ..family.table import SHIPPED, FamilyTable, default_table, shipped
from ..tracing.legs import turn_of

__all__ = ["Piece", "ForwardCurve", "APPROACH", "RETRACT", "curve_stop_reason", "curve_jumps", "pull_off_values",
           "open_table", "table_choice", "table_covers", "table_legs", "SIGMA_SEARCH"]


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
