"""What a measured curve shows by itself, and whether the model applies to it (docs/fitting.md, "Where the
model applies", "The instrument in the fit").

:func:`features`: the baseline and its noise, the contact, the pull-off and the jumps, the contact's slope and
the retract's steps; :func:`baselines`: each leg's baseline on its far part (the virtual deflection's slope, the
drag); :func:`calibrated_invols`: the deflection sensitivity's scale that makes the contact as stiff as the
lever, as on a hard substrate; :func:`domain_reasons`: why a curve is outside the model (a deep indentation,
a contact steeper than the lever, a compliant sample beyond the model's mu, tethers and long-range adhesion),
checked before a fit; and the refusals of a curve that is no force-distance relation or leaves too few points.
"""
from __future__ import annotations

import math

import numpy as np

from ..model.parameters import tabor
from ..model.physical import Bodies
from .data import MeasuredCurve
from .forward import APPROACH, RETRACT
from .results import NOISE_DOF_PER_DIFFERENCE, Features, FitChoice, Spring

__all__ = ["CurveFitError", "OutsideDomain", "features", "baselines", "calibrated_invols", "domain_reasons",
           "refuse_empty", "refuse_a_line", "MU_BOUNDS", "SIGNAL", "INDENTATION_MAX", "SLOPE_ABOVE", "REACH_EPS",
           "REACH_R"]

#: The Tabor parameters a fit may reach: the model's range and the shipped table's (below 1e-3 the sphere is rigid to
#: 1e-4 in its load; at 1e3 a PDMS sphere on glass).
MU_BOUNDS = (1e-3, 1e3)
#: Noise multiples that make a contact, an adhesion.
SIGNAL = 5.0
#: A force that is a straight line in the piezo position on both legs to this share of its range is no
#: force-distance curve (two columns of one quantity): no cantilever's noise is that small.
_LINEAR = 1e-9


class CurveFitError(ValueError):
    """A curve the fit cannot use; one line."""


class OutsideDomain(ValueError):
    """A curve outside the model's domain (docs/fitting.md, "Where the model applies"), refused before the fit;
    one line, the reasons after each other."""


def features(data: MeasuredCurve) -> Features:
    """What the measured curve shows by itself (SI): the baseline ``F0_N`` and ``noise_N`` (from the farthest
    30% of the approach: the median, and the spread of successive differences), the largest force above the
    baseline ``contact_N``; the pull-off ``pull_off_N`` (the least force of the retract, below the baseline)
    and its position ``pull_off_z_m``; the jump-in ``jump_in_z_m`` (the largest drop of the force between
    successive approach points before its largest force) and its size ``jump_in_drop_N``; and, where the
    force jumps by more than 10 noise between two points, the index of the first approach point in contact
    ``contact_from`` and of the first retract point off it ``free_from`` (None where it does not jump); the
    noise estimate's effective degrees of freedom ``noise_dof`` (docs/fitting.md)."""
    z, F, s = data.z, data.F, data.direction
    za, Fa = z[data.approach], F[data.approach]
    zr, Fr = z[data.retract], F[data.retract]
    depth = s * (za - za[0])                              # how far the approach went, from its start
    far = depth <= 0.3 * depth.max()
    if far.sum() < 5:
        far = np.arange(za.size) < max(5, za.size // 3)
    F0 = float(np.median(Fa[far]))
    d = np.diff(Fa[far])
    noise = float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2)) if d.size > 2 else 0.0
    note = None
    if noise <= 0:
        noise = 1e-3 * float(np.ptp(F)) or 1.0
        note = (f"the baseline shows no noise (its successive differences do not spread): the noise is taken as "
                f"1e-3 of the force's range, {noise:.3g} N, and chi^2 and the bars are in units of that")
    rises = np.diff(Fr)
    i_off = int(np.argmax(rises))                         # the last retract point in contact
    top = int(np.argmax(Fa))
    drops = np.diff(Fa[: top + 1])
    i_in = int(np.argmin(drops)) if drops.size else 0
    drop = float(-drops[i_in]) if drops.size else 0.0
    rise = float(rises[i_off])
    # the contact's slope over the upper half of the approach's rise, against the travel towards the surface
    upper = Fa >= F0 + 0.5 * (float(Fa.max()) - F0)
    slope = float(np.polyfit(s * za[upper], Fa[upper], 1)[0]) if np.count_nonzero(upper) >= 3 else None
    pull = float(F0 - Fr.min())
    # a step is a run of successive large rises: a jump spread over a few samples (the lever's and the
    # detector's response) is one
    big = (rises > max(10 * noise, 0.1 * pull)) if pull > 0 else np.zeros(rises.size, bool)
    steps = int(np.count_nonzero(big[1:] & ~big[:-1]) + big[:1].sum())
    return Features(F0_N=F0, noise_N=noise, noise_dof=NOISE_DOF_PER_DIFFERENCE * max(d.size, 1),
                    contact_N=float(Fa.max() - F0), pull_off_N=float(F0 - Fr.min()), pull_off_z_m=float(zr[i_off]),
                    pull_off_at_N=float(Fr[i_off]), jump_in_z_m=float(za[i_in]), jump_in_drop_N=drop,
                    jump_off_rise_N=rise, contact_from=i_in + 1 if drop > 10 * noise else None,
                    free_from=i_off + 1 if rise > 10 * noise else None, noise_note=note,
                    contact_slope_N_m=slope, retract_steps=steps)


def baselines(data: MeasuredCurve) -> tuple[float, float, float]:
    """Each leg's baseline on its far part (the farthest 30% of its travel from the surface): the approach's
    line a + b z (N, N/m: the virtual deflection b) and the retract's offset from it (N: the drag), the
    median of its far part less the approach's line there."""
    z, F, s = data.z, data.F, data.direction
    out = []
    for sl in (data.approach, data.retract):
        zz, FF = z[sl], F[sl]
        depth = s * (zz - zz.min() if s > 0 else zz - zz.max())
        far = depth <= 0.3 * depth.max()
        if far.sum() < 5:
            far = np.argsort(depth)[:5]
        out.append((zz[far], FF[far]))
    (za, Fa), (zr, Fr) = out
    b, a = np.polyfit(za, Fa, 1) if np.ptp(za) > 0 else (0.0, float(np.median(Fa)))
    drag = float(np.median(Fr - (a + b * zr)))
    return float(a), float(b), drag


def calibrated_invols(feat: Features, spring: Spring, baseline_slope: float = 0.0) -> float:
    """The scale c of the deflection sensitivity that makes the approach's contact as stiff as the lever, as on
    a hard substrate (there the piezo's travel is the lever's deflection, so the true slope is k):
    c = k / (S - b), S the measured contact slope and b the baseline's.  CurveFitError where the curve shows
    no contact slope."""
    S = feat.contact_slope_N_m
    if S is None or not math.isfinite(S) or S - baseline_slope <= 0:
        raise CurveFitError("the sensitivity cannot be calibrated: the approach shows no rising contact slope")
    return spring.k / (S - baseline_slope)


#: The deepest indentation a small-strain half-space model of a sphere describes, over its radius: the
#: contact radius sqrt(R delta) is then half of R, where the paraboloid's height falls 6.7% short of the
#: sphere's at the contact's edge (2.9% at a third of R).
INDENTATION_MAX = 1 / 4
#: A contact slope above the lever's by more than this share (no series of springs makes it).
SLOPE_ABOVE = 0.1
#: A reach of the retract's adhesion beyond the model's, over the larger of this many epsilon and ...
REACH_EPS = 30.0
#: ... this share of the tip's radius: long-range or tether adhesion.
REACH_R = 0.1


def domain_reasons(data: MeasuredCurve, feat: Features, bodies: Bodies, spring: Spring, choice: FitChoice,
                   baseline: tuple | None = None, scale: float | None = None) -> list[str]:
    """Why the curve is outside the model's domain (docs/fitting.md, "Where the model applies"), one line
    each; empty where it is inside.  With the deflection's scale c (``scale``, else ``choice.invols_scale``)
    the true deflection is c (F - F0) / k; ``baseline`` (a, b, d) each leg's baseline (:func:`baselines`;
    None: flat at F0).  Where c is fitted and not yet known (``choice.invols_fitted``
    without ``scale``) the indentation and the contact's slope say nothing (any indentation is some c's) and
    are checked after the fit, at its c:

    - the indentation (the travel in contact less the deflection's rise) deeper than INDENTATION_MAX R;
    - a contact steeper than the lever (by SLOPE_ABOVE): the piezo's travel less than the deflection, which no
      elastic contact makes (the sensitivity or the spring constant is off), unless its scale is fitted;
    - the mu a compliant contact asks for (E* by Hertz over the indentation, w by JKR from the pull-off) above
      the model's range;
    - a retract that lets go in several steps, or whose adhesion (its last point below its baseline by more
      than 10 noise and 5% of the pull-off) reaches farther than the lever's stretch at the pull-off plus
      REACH_EPS epsilon or REACH_R of R, two samples of the piezo and, where the approach shows no
      jump-in, the lever's travel over 5 noise (where its contact's start is placed): tethers or long-range forces the Lennard-Jones sphere does not
      make."""
    out = []
    s, z, F = data.direction, data.z, data.F
    a, baseline_slope, drag = baseline if baseline is not None else (feat.F0_N, 0.0, 0.0)
    R, eps = bodies.R, bodies.epsilon
    c, k = scale or choice.invols_scale, spring.k
    unknown = choice.invols_fitted and scale is None
    za, Fa = z[data.approach], F[data.approach]
    F0 = feat.F0_N
    top = int(np.argmax(Fa))
    # the contact's start: the point after the jump-in, else where the force last leaves the baseline's noise
    if feat.contact_from is not None:
        i_c = feat.contact_from
    else:
        low = np.flatnonzero(Fa[:top + 1] <= F0 + 5 * feat.noise_N)
        i_c = int(low[-1]) if low.size else 0
    travel = s * (za[top] - za[i_c])
    rise = c * (Fa[top] - Fa[i_c]) / k
    delta = travel - rise
    if delta > INDENTATION_MAX * R and not unknown:
        out.append(f"the indentation reaches {delta * 1e9:.3g} nm, {delta / R:.2g} of the tip's radius "
                   f"{R * 1e9:.3g} nm (the travel in contact {travel * 1e9:.3g} nm less the deflection's rise "
                   f"{rise * 1e9:.3g} nm): a small-strain half-space model of a sphere holds below R/4 (a "
                   f"contact radius of R/2); fit a shallower range (-fit_z_range) or a larger tip")
    S = feat.contact_slope_N_m
    if S is not None and not unknown:
        ratio = c * (S - baseline_slope) / k
        if ratio > 1 + SLOPE_ABOVE:
            out.append(f"the contact rises at {ratio:.3g} times the lever's stiffness, steeper than any elastic "
                       f"contact behind the lever: the deflection sensitivity or the spring constant is off "
                       f"(-fit_calibrate_invols, -fit_invols_scale, -fit_spring_err)")
        elif 0 < ratio < 1 and delta > 0 and feat.pull_off_N > 0:
            # Hertz with JKR's offset: F + 2 P = (4/3) E* sqrt(R) delta^1.5 at the top; w = P / (1.5 pi R)
            P = c * feat.pull_off_N
            E = 0.75 * (c * (Fa[top] - F0) + 2 * P) / (math.sqrt(R) * delta ** 1.5)
            w = P / (1.5 * math.pi * R)
            mu = tabor(R, w, E, eps)
            if mu > MU_BOUNDS[1]:
                out.append(f"the contact rises at {ratio:.2g} of the lever's stiffness: a compliant sample, E* about "
                           f"{E:.3g} Pa by Hertz over its indentation {delta * 1e9:.3g} nm, which with w about "
                           f"{w:.3g} J/m^2 (JKR, from the pull-off) makes mu about {mu:.3g}, above the model's "
                           f"range (mu <= {MU_BOUNDS[1]:g})")
    if feat.retract_steps > 1:
        out.append(f"the retract lets go in {feat.retract_steps} steps: several bonds or a tether, which one "
                   f"sphere's Lennard-Jones adhesion does not make")
    zr, Fr = z[data.retract], F[data.retract]
    below = a + baseline_slope * zr + drag - Fr
    held_on = np.flatnonzero(below > max(10 * feat.noise_N, 0.05 * feat.pull_off_N))
    if held_on.size:
        # the approach's contact point to the last point of the retract still pulled below the baseline
        reach = s * (za[i_c] - zr[held_on[-1]])
        stretch = c * feat.pull_off_N / k
        # the contact point and the last point held on are each known to a sample: a soft lever's curve is
        # sampled coarsely (k = 2.7 mN/m on a 20 nm tip: 23 nm a sample, the stretch 2 um)
        sample = float(np.median(np.abs(np.diff(za)))) if za.size > 1 else 0.0
        # without a jump-in the contact's start is the last point within 5 noise of the baseline: up to
        # 5 noise / k of the lever's travel after the contact, and a point's own noise (as far out as the
        # largest of n samples', sqrt(2 ln n) deviations) puts it later still (a soft lever's: 420 nm at
        # 3.4 mN/m and 3% noise, where the model's own curve held on 350 nm beyond its stretch)
        late = 0.0 if feat.contact_from is not None else \
            (5 + math.sqrt(2 * math.log(max(za.size, 2)))) * feat.noise_N * c / k
        allowed = stretch + max(REACH_EPS * eps, REACH_R * R) + 2 * sample + late
        if reach > allowed:
            out.append(f"the retract holds on {reach * 1e9:.3g} nm behind the contact, beyond the lever's stretch "
                       f"at the pull-off {stretch * 1e9:.3g} nm and the model's reach: long-range or tether "
                       f"adhesion, which the Lennard-Jones sphere does not make")
    return out


def refuse_empty(data: MeasuredCurve, choice: FitChoice) -> None:
    """CurveFitError where the segment and the piezo range asked for leave too few points of the curve."""
    legs = {"approach": data.approach, "retract": data.retract}
    wanted = (APPROACH, RETRACT) if choice.segment == "both" else (choice.segment,)
    for leg in wanted:
        z = data.z[legs[leg]]
        inside = np.ones(z.size, bool) if choice.z_range is None else \
            (z >= choice.z_range[0]) & (z <= choice.z_range[1])
        if np.count_nonzero(inside) < 10:
            where = "" if choice.z_range is None else \
                f" within z in [{choice.z_range[0]:.4g}, {choice.z_range[1]:.4g}] m"
            raise CurveFitError(f"the {leg} has {int(np.count_nonzero(inside))} points{where}; a fit needs 10 at "
                                f"least (the curve's z runs over [{data.z.min():.4g}, {data.z.max():.4g}] m)")


def refuse_a_line(data: MeasuredCurve) -> None:
    """CurveFitError for a force that is a straight line in the piezo position over both legs (to _LINEAR of
    its range): two columns of one quantity, no force-distance relation."""
    A = np.c_[data.z, np.ones_like(data.z)]
    coef, *_ = np.linalg.lstsq(A, data.F, rcond=None)
    left = float(np.sqrt(np.mean((data.F - A @ coef) ** 2)))
    if left <= _LINEAR * float(np.ptp(data.F)):
        raise CurveFitError(f"no force-distance relation: the force is a straight line of the piezo position "
                            f"(slope {coef[0]:.6g} N/m) on approach and retract alike (two columns of one "
                            f"quantity?)")
