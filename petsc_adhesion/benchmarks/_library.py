"""The library's curve as the benchmarks read it: one flat record of a :class:`~petsc_adhesion.tracing.curve.Curve`."""
from __future__ import annotations

from ..io.layout import curve_tree
from ..io.summary import event_record, summary_of
from ..model.parameters import Model
from ..tracing.trace import (
    CurveRequest,
    PetscSettings,
    GridChoice,
    SolverChoice,
    curve_settings,
    trace_curve,
)

__all__ = ["flat", "traced"]


def flat(curve) -> dict:
    """The summary's keys, with the events as their records (``events``), the pull-off's record
    (``pull_off``) and the grids of the segments (``grids``)."""
    records = [event_record(e) for e in curve.events]
    pull = next((rec for ev, rec in zip(curve.events, records) if ev is curve.pull_off), None)
    return {**summary_of(curve), "events": records, "pull_off": pull, "grids": curve_tree(curve, {})["grid"]}


def traced(model: Model, nodes=None, pmat: str = "dense", settings=None, errors: bool = True,
           target_error: float | None = None, correctors: PetscSettings = PetscSettings()) -> dict:
    """:func:`flat` of the curve of ``model`` on grids that follow the edge, or on the fixed ``nodes`` (r_m their
    last), with the program's defaults but those given (``correctors``: both correctors' PETSc settings)."""
    grid_choice = GridChoice() if nodes is None else GridChoice("given", r=nodes)
    solver = SolverChoice(pmat=pmat, natural=correctors, arclength=correctors)
    return flat(trace_curve(model, grid_choice, solver, settings or curve_settings(),
                            CurveRequest(error_bars=errors, target_error=target_error)))
