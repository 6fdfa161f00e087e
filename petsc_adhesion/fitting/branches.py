"""The solver's branch F(lambda) of (mu, sigma) traced once, without a spring, and read behind any spring; the
branches a process has traced kept for its later fits (docs/fitting.md, "The solver's curves").

In units of 2 pi R w and epsilon the load-approach branch depends on (mu, sigma) (and the model's law and
domain) alone; a cantilever of stiffness K only maps it to its base position Z = lambda + F / K, its jumps at
the turning points of Z.  So the solver traces the branch once, with a rigid machine, to a load of the ladder
F_max = 2, 2.83, 4, 5.66, ... past what the data reach (the contact continued linearly beyond, as past any traced
curve's end), and every spring a fit asks for (its K moves with w and the spring constant) reads the same
branch: along the family's coordinate s = a^2 / 2 - H(0), monotone through the folds
(:mod:`~petsc_adhesion.family.coordinate`, stretched about the contact's forming), by
:meth:`~petsc_adhesion.family.table.FamilyCurve.behind`, the construction the table's interpolated curves use
(:func:`~petsc_adhesion.family.legs.spring_legs`: the turning points of Z on cubic splines through the
branch's points, the far branch continued by eq. 28 beyond a soft spring's jump-in).  Checked against curves
traced with the spring in the system (tests/test_fit_branches.py): the jumps agree within the traced jumps'
own error (their grid value's distance from the extrapolated one, or their bar), the force between them to
2e-4 of 2 pi R w.

The branch is traced with steps of at most STEP_F in F (the library's default is 0.2): between sparser points
a spline's F about the pull-off misses the solver's by 1e-3, which behind a soft spring (K = 0.005) moves the
jump-off by 0.24 epsilon; at STEP_F it is 1e-4.

A branch is kept by what makes it (the model with its mu and sigma, the grid, the solver's settings, the
ranks, the load of the ladder), so a fit's result never depends on which fits ran before it in the process:
the same branch is traced again or found.  Where its coordinate s is not monotone (a fall beyond a regrid's
two grids at one state) there is no branch to read and the caller traces with its spring (None).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from ..family.coordinate import coordinate, rising, stretch, width
from ..family.legs import Legs
from ..family.table import FamilyCurve
from ..tracing.measured import Missing

__all__ = ["SolverBranch", "BranchCache", "BRANCHES", "STEP_F", "f_level", "branch_settings"]

#: The branch's largest step in F (units 2 pi R w; the continuation's observable_step).
STEP_F = 0.05
#: The branch's largest continuation step in units of mu where its curve is traced in those units (mu >= 20).
DS_MAX_PER_MU = 0.05
#: The loads the branches are traced to: F_LADDER times powers of 2, RUNGS of them an octave (2, 2.83, 4, 5.66, ...):
#: a branch is traced at most 41% past the load the data need (100% with one rung an octave: at mu = 1 and 10 the
#: synthetic curves of docs/fitting.md need 2.7 to 2.9, and the stretch from there to 4 took 17 of 144 and about
#: 30 of 420 steps).
F_LADDER = 2.0
RUNGS = 2
#: Branches kept by a process (the oldest dropped first).
KEEP = 256


def f_level(needed: float) -> float:
    """The load of the ladder a branch is traced to: the first of 2, 2 sqrt 2, 4, ... at or past ``needed``."""
    return F_LADDER * 2.0 ** (max(0, math.ceil(RUNGS * math.log2(max(needed, 1e-300) / F_LADDER) - 1e-12)) / RUNGS)


def branch_settings(model, f_max: float):
    """The continuation's settings of a branch: the library's curve's in its units
    (:func:`~petsc_adhesion.discretization.problem.step_scale`: mu from 20 on, as the table's curves are traced)
    to the load ``f_max``, with steps of at most STEP_F in F and of at most DS_MAX_PER_MU times mu in the
    continuation's norm there, the quadratic predictor, and on a rough sphere F within
    :data:`~petsc_adhesion.tracing.trace.WALL_BEND_F` of its tangent's line in a step.

    Why the units: in units of 1 a branch at mu = 100 took 4878 steps (the continuation's cap is 5000; at mu =
    1000 it would stop at the cap) where lambda runs over 1000 epsilon: 104 s of CPU.  In units of mu with steps
    of 0.05 mu, 578 steps and 14 s: read behind K = 0.005 and 0.048 within 1.5e-4 of 2 pi R w of those dense
    points beyond 0.1 epsilon of the jumps, behind a stiff K = 0.5 within 8e-4 on the approach and 4e-3 (0.4 of 1%
    noise) on the retract, beyond 0.2 epsilon of the jumps.  Steps of 0.025 mu (1047 steps, 21 s) are not
    better: 5e-4 and 1.7e-3 there, and a second jump-in 0.025 epsilon before the first behind K = 0.005; with the
    library's 0.5 mu the far branch's few points were 0.03 off (a spline between them).  Below mu = 20 the steps
    stay at 0.5: at mu = 10 a bound of 1 put a second jump-in behind K = 0.005.

    Why the predictor: Newton starts nearer the corrected point (the tracer takes it itself in a soft sphere's
    frame of the edge from mu = 20): the same points to the solver's tolerance, at mu = 1 and 10 the branch read
    behind K = 0.005 to 0.5 within 4e-5 of the linear predictor's, in about 0.8 of its CPU (docs/fitting.md,
    "What a branch costs")."""
    from ..discretization.problem import step_scale
    from ..tracing.trace import curve_settings, wall_bend

    scale = step_scale(model)
    s = curve_settings(scale, observable_max=f_max, observable_step=STEP_F, predictor="quadratic",
                       observable_bend=wall_bend(model))
    return s if scale == 1.0 else replace(s, ds=min(s.ds, DS_MAX_PER_MU * scale), ds_max=DS_MAX_PER_MU * scale)


@dataclass(frozen=True)
class SolverBranch:
    """One branch the solver traced without a spring: its (mu, sigma), the load ``f_max`` it was traced to, its
    points on the coordinate (``curve``, a FamilyCurve of the solver's points, its error Missing: no table),
    the ``notes`` of a curve that ended early, the solver's CPU ``seconds``."""

    mu: float
    sigma: float
    f_max: float
    curve: FamilyCurve = field(repr=False)
    notes: tuple = ()
    seconds: float = 0.0

    def legs(self, K: float, reach: float | None = None) -> Legs:
        """F(Z) on the approach and the retract behind a spring of stiffness ``K`` (units 2 pi R w / epsilon),
        the far branch tabulated beyond the base position ``reach``."""
        legs = self.curve.behind(K, reach).legs
        legs.notes.extend(self.notes)
        return legs

    @classmethod
    def of(cls, curve, f_max: float, seconds: float = 0.0) -> SolverBranch | None:
        """The branch of a traced :class:`~petsc_adhesion.tracing.curve.Curve` (no spring), or None where its
        coordinate s falls (module docstring).  The points that repeat a state on a new grid (a regrid) and
        any a hair behind the one before are left out, as the table's sampling leaves them."""
        from ..discretization.contact import edge_level
        from ..model.pressure import pressure_law

        b = curve.branch
        own = np.asarray(b.corrector) != b"regrid"
        s = coordinate(b.H0, b.contact_radius)[own]
        lam, F = np.asarray(b.lam, float)[own], np.asarray(b.F, float)[own]
        if s.size < 4:
            return None
        kept, fall = rising(s)
        if fall > 1e-4 or len(kept) < 4:
            return None
        s, lam, F = s[kept], lam[kept], F[kept]
        m = curve.model
        s0 = 0.5 - edge_level(pressure_law(m))
        # the coordinate stretched about the contact's forming (even spacing for the splines), where it forms
        t = stretch(s, s0, float(s[0]), float(s[-1]), width(m.mu)) if s[0] < s0 < s[-1] else s
        notes = () if curve.complete else (
            f"the curve at mu = {m.mu:.4g} ended early ({curve.diagnostics.stop_reason}); continued linearly",)
        return cls(float(m.mu), float(m.sigma), float(f_max),
                   FamilyCurve(float(m.mu), float(m.sigma), np.asarray(t, float), lam, F, float(F[-1]),
                               Missing("the solver's own curve: no table error")), notes, seconds)


@dataclass
class BranchCache:
    """The branches a process traced, by what makes them (module docstring); ``traced`` counts the traces."""

    kept: dict = field(default_factory=dict)
    traced: int = 0

    @staticmethod
    def key(model, f_max: float, grid, solver, comm) -> tuple:
        from petsc4py import PETSc

        size = (comm or PETSc.COMM_WORLD).getSize()
        return (repr(model), float(f_max), repr(grid), repr(solver), size)

    def get(self, model, needed: float, grid, solver, comm) -> tuple[SolverBranch | None, bool]:
        """(the branch of ``model`` (its mu and sigma) traced past the load ``needed``, whether it was traced
        now); the branch None where it cannot be read.  Collective on ``comm`` when it traces."""
        import time

        from ..tracing.trace import CurveRequest, trace_curve

        model = replace(model, bodies=None)
        f_max = f_level(needed)
        key = self.key(model, f_max, grid, solver, comm)
        if key in self.kept:
            return self.kept[key], False
        c0 = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            c = trace_curve(model, grid, solver, branch_settings(model, f_max),
                            CurveRequest(error_bars=False, kinds=(), cycles=False), comm=comm)
        self.traced += 1
        branch = SolverBranch.of(c, f_max, time.process_time() - c0)
        if len(self.kept) >= KEEP:
            self.kept.pop(next(iter(self.kept)))
        self.kept[key] = branch
        return branch, True

    def legs(self, model, needed: float, K: float, reach: float, grid, solver, comm) -> tuple[Legs, int]:
        """(F(Z) of ``model`` behind the spring ``K`` past the load ``needed``, the curves traced for it): read
        from the branch; where there is none to read, the curve traced with the spring in the system (to
        ``needed``, not kept).  Collective on ``comm`` when it traces."""
        branch, traced = self.get(model, needed, grid, solver, comm)
        if branch is not None:
            return branch.legs(K, reach), int(traced)
        from ..tracing.trace import CurveRequest, curve_settings, trace_curve
        from .forward import ForwardCurve, curve_stop_reason

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            c = trace_curve(replace(model, bodies=None), grid, solver, curve_settings(observable_max=needed),
                            CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=K), comm=comm)
        fc = ForwardCurve(c, K)
        fc.notes.append("the branch's coordinate s falls: the curve traced with the spring in the system")
        if not c.complete:
            fc.notes.append(f"the curve at mu = {model.mu:.4g}, K = {K:.4g} ended early ({curve_stop_reason(c)}); "
                            f"continued linearly")
        return fc, int(traced) + 1

    def clear(self) -> None:
        """Forget every branch (a test that counts traces starts from none)."""
        self.kept.clear()


#: The process's branches: every fit's solver curves are read from it.
BRANCHES = BranchCache()
