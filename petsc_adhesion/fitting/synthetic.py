"""Synthetic force curves made by the forward solver: the truth the fit of a measured curve is checked on.

A cantilever of spring constant k (N/m) on a sphere of radius R: its base at piezo
position z, Z = s (z - z_0) / eps in the model's units, and the force it measures

    F(z) = F_0 + 2 pi R w f(Z; mu, K, sigma) + noise,   K = k eps / (2 pi R w)

with f the model's force behind the spring on the approach or the retract
(:class:`~petsc_adhesion.fitting.forward.ForwardCurve`), mu from w and E* by eq. (9),
and the noise Gaussian of standard deviation ``noise`` (N), independent from point to
point (a cantilever's thermal noise, its correlation time below the sampling's).
The piezo moves evenly from ``approach`` epsilon before the jump-in (or the start of
contact) to where the load reaches ``top`` (in 2 pi R w), and back.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ..model.parameters import Model, tabor
from .data import MeasuredCurve
from .forward import APPROACH, RETRACT, ForwardCurve

__all__ = ["forward_curve", "synthetic_curve"]


def forward_curve(mu: float, K: float, sigma: float = 0.0, top: float = 2.0, model: Model | None = None,
                  grid=None, solver=None, settings=None, comm=None) -> ForwardCurve:
    """The model's force against the base position behind a spring of stiffness ``K`` (units of 2 pi R w /
    eps) at Tabor parameter ``mu`` and roughness ``sigma``, traced to the load ``top`` (no error bars)."""
    from ..tracing.trace import CurveRequest, GridChoice, SolverChoice, curve_settings, trace_curve

    model = replace(model or Model(), mu=mu, sigma=sigma, bodies=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        c = trace_curve(model, grid or GridChoice(), solver or SolverChoice(),
                        settings or curve_settings(observable_max=top),
                        CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=K), comm=comm)
    return ForwardCurve(c, K)


def synthetic_curve(radius: float, epsilon: float, spring: float, gamma: float, modulus: float,
                    sigma: float = 0.0, noise: float = 0.0, points: int = 400, top: float = 2.0,
                    approach: float = 30.0, z0: float = 0.0, F0: float = 0.0, direction: int = 1, seed: int = 0,
                    model: Model | None = None, grid=None, settings=None) -> MeasuredCurve:
    """A force curve measured on the model (SI): ``points`` samples on each of approach and retract, with
    Gaussian noise of ``noise`` N (the stream of ``seed``); the contact point ``z0`` (m), the baseline ``F0``
    (N) and the direction of the approach (+1: z grows towards the surface)."""
    R, eps, w, E = radius, epsilon, gamma, modulus
    mu = tabor(R, w, E, eps)
    K = spring * eps / (2 * math.pi * R * w)
    fc = forward_curve(mu, K, sigma, top, model, grid, settings=settings)
    last = fc.pieces[-1]
    Z_hi = float(np.interp(top, last.F, last.Z)) if last.F[-1] >= top else last.Z_hi
    jumps = fc.jumps[APPROACH]
    Z_lo = (jumps[0] if jumps else fc.pieces[0].Z_hi) - approach
    Z = np.linspace(Z_lo, Z_hi, points)
    scale = 2 * math.pi * R * w
    F = np.r_[fc.predict(Z, APPROACH), fc.predict(Z[::-1], RETRACT)] * scale + F0
    rng = np.random.default_rng(seed)
    F = F + noise * rng.standard_normal(F.size)
    z = z0 + direction * eps * np.r_[Z, Z[::-1]]
    return MeasuredCurve(z=z, F=F, turn=points, direction=direction, spring=spring, source="synthetic",
                         metadata={"gamma": w, "E_star": E, "mu": mu, "K": K, "sigma": sigma, "noise_N": noise,
                                   "z0_m": z0, "F0_N": F0, "seed": seed})
