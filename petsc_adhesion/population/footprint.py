"""A particle's footprint on the topography: the heights of the zone where it interacts, from their own mean
plane.

**Its size.**  The footprint is the interaction zone at pull-off, not the contact alone:
outside the contact the gap opens as r^2 / 2R, and the Lennard-Jones attraction there
still carries a large share of the pull-off (for the rigid sphere, all of it: DMT).  For
the rigid sphere at pull-off (lambda = 0) the attraction beyond r is eq. (28)'s tail,
``load_beyond(r, 0)`` = (8/3)(g^-8/8 - g^-2/2), g = 1 + r^2/2 (units sqrt(R epsilon));
the zone holds :data:`ZONE_SHARE` of it where r = :func:`zone_radius` (2.89: the gap
there is 5.2 epsilon).  A deformed sphere at pull-off touches over a radius a and its
gap opens from there, so the footprint's radius is

    r_f = sqrt(R epsilon) sqrt(a^2 + r_z^2),

a the contact radius at pull-off (units sqrt(R epsilon)): the solver's own for the
measured law, found by iteration (the footprint's heights make the pull-off, whose
contact radius makes the footprint; :mod:`~petsc_adhesion.population.evaluate`), and
for the table the smooth sphere's Maugis-Dugdale contact radius at pull-off
(:func:`md_contact_radius`; roughness lowers it, so the footprint is if anything too
large by a little).

**Its site.**  Uniform over the sites where the footprint lies inside the scan: each
pass of the solver's iteration maps the particle's uniform deviates onto the sites of
its own footprint's radius (sample.py), so the settled footprint lies inside.  ``clip``
takes the pixels of a disk inside the scan where one reaches past it (noted).

**Its heights.**  The pixels whose centres lie within r_f of the site, their heights
measured from the least-squares plane through them (the particle rests on its own
patch: a slope or a step the whole map's plane leaves in the patch is not roughness the
particle meets), in units of epsilon.

**Enough of them?**  A distribution needs samples: fewer than :data:`MIN_PIXELS`
pixels give none (the particle's pull-off is missing, with the reason).  The
independent samples of the patch are its share of the map's (the map's N_2 of the
rms, model/topography.py, times the patch's pixels over the map's): below
:data:`MIN_INDEPENDENT` the patch is a few asperities, not a distribution, and the
mean-field average over its heights is the model's answer but not the physics' (the
particle keeps its value and carries the note).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from .. import brent
from ..model.reference.maugis_dugdale import maugis_dugdale_curve
from ..model.reference.rigid import load_beyond

__all__ = ["ZONE_SHARE", "MIN_PIXELS", "MIN_INDEPENDENT", "Footprint", "zone_radius", "footprint_radius",
           "md_contact_radius", "footprint"]

#: The share of the rigid sphere's pull-off the footprint holds.
ZONE_SHARE = 0.95
#: Fewer pixels than this in a footprint: no distribution, no pull-off.
MIN_PIXELS = 25
#: Fewer independent samples than this: the particle's value is kept with a note.
MIN_INDEPENDENT = 5.0


@lru_cache(maxsize=None)
def zone_radius(share: float = ZONE_SHARE) -> float:
    """The radius (units sqrt(R epsilon)) within which the rigid sphere at pull-off feels ``share`` of its
    attraction (eq. 28's tail, :func:`~petsc_adhesion.model.reference.rigid.load_beyond`)."""
    return brent.root(lambda r: -load_beyond(r, 0.0) - (1.0 - share), 0.0, 100.0)


def footprint_radius(a: float, R: float, epsilon: float, share: float = ZONE_SHARE) -> float:
    """The footprint's radius (m) about a contact of radius ``a`` (units sqrt(R epsilon)): module docstring."""
    return math.sqrt(R * epsilon) * math.sqrt(a * a + zone_radius(share) ** 2)


@lru_cache(maxsize=4096)
def md_contact_radius(mu: float) -> float:
    """The smooth sphere's contact radius at its load-controlled pull-off by Maugis-Dugdale (units
    sqrt(R epsilon)): the radius where the closed form's load is most tensile."""
    if mu <= 0:
        return 0.0
    x = np.linspace(math.log(1e-10), math.log(1e10), 401)
    A, F, _ = maugis_dugdale_curve(mu, 1.0 + np.exp(x))
    return float(np.asarray(A)[int(np.argmin(F))])


@dataclass(frozen=True)
class Footprint:
    """A particle's footprint: ``center`` (m from the first pixel, each axis), ``radius`` (m), its ``pixels``,
    the ``independent`` samples they carry (module docstring), the ``heights`` from their own mean plane
    (units of epsilon), their ``rms`` (m) and ``skewness`` (None for a flat patch), and ``note``: why the
    patch is too small for a distribution ('' when it is not)."""

    center: tuple
    radius: float
    pixels: int
    independent: float
    heights: np.ndarray = field(repr=False)
    rms: float
    skewness: float | None
    note: str = ""

    @property
    def usable(self) -> bool:
        """Whether the patch has pixels enough for a distribution (:data:`MIN_PIXELS`)."""
        return self.pixels >= MIN_PIXELS


def footprint(topography, center: tuple, radius: float, epsilon: float, clip: bool = False) -> Footprint:
    """The heights of ``topography`` (a :class:`~petsc_adhesion.model.topography.Topography` map with its
    pixel size) within ``radius`` (m) of ``center`` (m), from their least-squares plane, in units of
    ``epsilon`` (m).  ValueError where the disk leaves the scan, unless ``clip``: then the pixels of the disk
    inside the scan, and a note."""
    z, p = topography.heights, topography.pixel_size
    lo, hi = [], []
    clipped = False
    for c, n, d in zip(center, z.shape, p):
        if c - radius < -d / 2 or c + radius > (n - 1) * d + d / 2:
            if not clip:
                raise ValueError(f"the footprint of radius {radius:g} m at {center} leaves the scan")
            clipped = True
        lo.append(max(0, int(math.floor((c - radius) / d))))
        hi.append(min(n, int(math.ceil((c + radius) / d)) + 1))
    # the bounding box of the disk, then the pixels whose centres lie within it
    x = np.arange(lo[0], hi[0]) * p[0] - center[0]
    y = np.arange(lo[1], hi[1]) * p[1] - center[1]
    X, Y = np.meshgrid(x, y, indexing="ij")
    inside = X * X + Y * Y <= radius * radius
    h = z[lo[0]:hi[0], lo[1]:hi[1]][inside]
    n = int(h.size)
    share = topography.stats.independent[0] / z.size       # the map's independent samples per pixel
    independent = min(float(n), n * share)
    note = ""
    if clipped:
        note = "the footprint reaches past the scan's edge: the pixels inside it"
    if n < MIN_PIXELS:
        note = f"{n} pixels under the footprint, fewer than {MIN_PIXELS}: no height distribution"
    elif independent < MIN_INDEPENDENT:
        note = (f"about {independent:.1f} independent samples under the footprint (fewer than "
                f"{MIN_INDEPENDENT:g}): a few asperities, not a distribution")
    if n >= 3:
        # the patch's own mean plane (least squares): the particle rests on its patch
        A = np.column_stack([np.ones(n), X[inside], Y[inside]])
        coef, *_ = np.linalg.lstsq(A, h, rcond=None)
        local = h - A @ coef
    else:
        local = h - h.mean() if n else h
    if n and np.ptp(local) <= 1e-9 * max(float(np.ptp(z)), epsilon):   # a flat patch, up to rounding
        local = np.zeros_like(local)
    rms = float(np.sqrt(np.mean(local * local))) if n else 0.0
    skew = float(np.mean(local ** 3) / rms ** 3) if rms > 0 else None
    return Footprint(tuple(float(c) for c in center), float(radius), n, independent, local / epsilon, rms, skew, note)
