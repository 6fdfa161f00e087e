"""Synthetic force curves made by the forward solver: the truth the fit of a measured curve is checked on.

A cantilever of spring constant k (N/m) on a sphere of radius R: its base at piezo
position z, Z = s (z - z_0) / eps in the model's units, and the force it measures

    F(z) = F_0 + b (z - z_0) + d [retract] + 2 pi R w f(Z; mu, K, sigma) / c + noise,   K = k eps / (2 pi R w)

with f the model's force behind the spring on the approach or the retract
(:class:`~petsc_adhesion.fitting.forward.ForwardCurve`), mu from w and E* by eq. (9),
and the noise Gaussian of standard deviation ``noise`` (N), independent from point to
point (a cantilever's thermal noise, its correlation time below the sampling's).
The instrument's errors as a fit meets them: the file's deflection converted with a
sensitivity c times too small (the force it states is the true over c), a baseline
sloped by b N/m in z (the virtual deflection: light of the laser scattered by the
sample, a lever's drift) and the retract's baseline offset by d N (the drag of the
medium on the moving lever).
The piezo moves evenly from ``approach`` epsilon before the jump-in (or the start of
contact) to where the load reaches ``top`` (in 2 pi R w), and back; where the retract's
jump-off lies farther out than that (a soft lever stretches far before it lets go: at
K = 0.01 about 1 / K = 100 epsilon behind the contact), the piezo starts ``past``
epsilon beyond the jump-off instead, as a user sets the range of a curve to see its
pull-off: a retract that ends still in contact holds no pull-off, and w is then bounded
from below alone.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np

from ..model.parameters import Model
from ..model.physical import Bodies
from .data import MeasuredCurve
from .forward import APPROACH, RETRACT, ForwardCurve
from .results import Spring

__all__ = ["Sampling", "forward_curve", "synthetic_curve", "truth_settings", "rough_truth"]


@dataclass(frozen=True)
class Sampling:
    """How a synthetic curve is measured: ``points`` samples on each of approach and retract, Gaussian noise
    of ``noise`` N (the stream of ``seed``), the piezo from ``approach`` epsilon before the jump-in, or ``past``
    epsilon beyond the retract's jump-off where that is farther out, to the load ``top`` (2 pi R w), the contact
    point ``z0`` (m), the baseline ``F0`` (N) and the direction of the
    approach (+1: z grows towards the surface); the instrument's errors: the true sensitivity ``invols_scale``
    times the one the force was converted with, the baseline's slope ``virtual_deflection`` (N/m) and the
    retract's baseline offset ``drag`` (N)."""

    noise: float = 0.0
    points: int = 400
    top: float = 2.0
    approach: float = 30.0
    z0: float = 0.0
    F0: float = 0.0
    direction: int = 1
    seed: int = 0
    invols_scale: float = 1.0
    virtual_deflection: float = 0.0
    drag: float = 0.0
    past: float = 10.0


def truth_settings(model: Model, top: float, finer: float = 1.0):
    """The continuation's settings of a curve made to be measured (:func:`forward_curve`) to the load ``top``:
    below mu = MU_SOFT the library's curve's (units of 1); from MU_SOFT on a fit's branch's
    (:func:`~petsc_adhesion.fitting.branches.branch_settings`: units of mu, steps of at most 0.05 mu and 0.05
    in F), their largest steps divided by ``finer``; on a rough sphere the load within WALL_BEND_F / (2 finer) of its
    tangent's line in a step (:func:`rough_truth`).

    Why: in units of 1 a curve at mu = 60 took 45 CPU s (lambda runs over some 600 epsilon in steps of at most
    0.5), and above mu of about 100 the continuation's cap of 5000 steps would cut it short; a fit's branch at
    mu = 100 in units of mu reads within 1.5e-4 of 2 pi R w of the dense one behind K = 0.005 and 0.048
    (docs/fitting.md, "What a branch costs")."""
    from ..discretization.problem import step_scale
    from ..tracing.trace import curve_settings
    from .branches import branch_settings

    if step_scale(model) == 1.0:
        return rough_truth(curve_settings(observable_max=top), model, finer)
    s = branch_settings(model, top)
    return rough_truth(replace(s, ds=s.ds / finer, ds_max=s.ds_max / finer, observable_step=s.observable_step / finer),
                       model, finer)


def rough_truth(settings, model: Model, finer: float = 1.0):
    """``settings`` with, on a rough sphere, the load within
    :data:`~petsc_adhesion.tracing.trace.WALL_BEND_F` / (2 finer) of its tangent's line in a step.

    Why: a rough sphere's load turns sharply where the roughness rule's outermost wall stops it (at mu = 0.0055,
    sigma = 1, dF/dlambda from 0 to 50 within 0.02 epsilon); steps bounded in F and in the state's norm alone pass
    over the kink and the spline through their points rounds it: the curves made with the library's steps,
    with 0.2 and 0.05 steps differed from one another by chi^2 of 165 to 11,594 at 0.3% noise, where a fit's
    model at the truth must meet its curve to the noise.  With the bound at 5e-4 the curve is within 3.1e-4 of
    one with steps of 0.005 (a tenth of 0.3% noise), with finer = 2 (the bound 2.5e-4) within 1.1e-5."""
    from ..tracing.trace import wall_bend

    return replace(settings, observable_bend=min(settings.observable_bend, wall_bend(model) / (2.0 * finer)))


def forward_curve(model: Model, K: float, top: float = 2.0, grid=None, solver=None, settings=None,
                  comm=None) -> ForwardCurve:
    """The force of ``model`` (its mu and sigma) against the base position behind a spring of stiffness ``K``
    (units of 2 pi R w / eps), traced to the load ``top`` (no error bars), with ``settings`` or
    :func:`truth_settings`."""
    from ..tracing.trace import CurveRequest, GridChoice, SolverChoice, trace_curve

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        c = trace_curve(replace(model, bodies=None), grid or GridChoice(), solver or SolverChoice(),
                        settings or truth_settings(model, top),
                        CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=K), comm=comm)
    return ForwardCurve(c, K)


def synthetic_curve(bodies: Bodies, spring: Spring, sampling: Sampling = Sampling(), model: Model | None = None,
                    grid=None, settings=None, comm=None) -> MeasuredCurve:
    """A force curve measured on the model (SI) for ``bodies`` (their R, E by eq. 2, epsilon, gamma and rms)
    behind ``spring``, sampled as ``sampling`` says; the roughness average and domain of ``model``.  ``comm``:
    the ranks that trace it together (PETSc's world by default; ``PETSc.COMM_SELF`` where each rank makes a
    curve of its own, as a study dealing cases to its ranks does: on the world, ranks tracing different curves
    would meet in each other's collective operations)."""
    R, eps, w, E = bodies.R, bodies.epsilon, bodies.work_of_adhesion, bodies.E
    mu, sigma = bodies.mu, bodies.sigma or 0.0
    K = spring.K(bodies, w)
    s = sampling
    top = s.top
    fc = forward_curve(replace(model or Model(), mu=mu, sigma=sigma), K, top, grid, settings=settings, comm=comm)
    last = fc.pieces[-1]
    Z_hi = float(np.interp(top, last.F, last.Z)) if last.F[-1] >= top else last.Z_hi
    jumps = fc.jumps[APPROACH]
    Z_lo = (jumps[0] if jumps else fc.pieces[0].Z_hi) - s.approach
    offs = fc.jumps[RETRACT]
    if offs:                            # the retract shows its pull-off and the free lever past it
        Z_lo = min(Z_lo, min(offs) - s.past)
    Z = np.linspace(Z_lo, Z_hi, s.points)
    scale = 2 * math.pi * R * w
    z = s.z0 + s.direction * eps * np.r_[Z, Z[::-1]]
    F = np.r_[fc.predict(Z, APPROACH), fc.predict(Z[::-1], RETRACT)] * scale / s.invols_scale + s.F0 + \
        s.virtual_deflection * (z - s.z0) + s.drag * (np.arange(z.size) >= s.points)
    rng = np.random.default_rng(s.seed)
    F = F + s.noise * rng.standard_normal(F.size)
    return MeasuredCurve(z=z, F=F, turn=s.points, direction=s.direction, spring=spring.k, source="synthetic",
                         metadata={"gamma": w, "E_star": E, "mu": mu, "K": K, "sigma": sigma, "noise_N": s.noise,
                                   "z0_m": s.z0, "F0_N": s.F0, "seed": s.seed,
                                   "invols_scale": s.invols_scale, "virtual_deflection_N_m": s.virtual_deflection,
                                   "drag_N": s.drag})
