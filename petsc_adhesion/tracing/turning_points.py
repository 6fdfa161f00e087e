"""Which turning points of a curve an instrument meets: the primary jump-in and jump-off, and the narrow
secondary fold pairs between them grouped (docs/results.md, "Primary events and secondary fold pairs").

Under displacement control the approach follows the far branch to its first turning point, the primary
jump-in, and lands on the contact branch; the retraction follows the contact branch to its turning point of
least lambda, the primary jump-off (docs/soft.md).  A soft sphere's curve bends back and forth between them
as the contact forms (its lambda-dot changes sign a few more times): those further turning points lie on the
part of the curve the two jumps pass over, which neither an approach nor a retraction visits.  Where they
lie close together (their span in lambda within :data:`GROUP_SHARE` of the hysteresis, the distance of the
primary jumps, and their span in F within :data:`GROUP_SHARE` of the pull-off force) they are one
:class:`EventGroup`: on a figure of the whole curve they are one spot.  Behind a spring the same, in the
spring's base Z (its jumps).  Nothing is dropped: every turning point stays an event of the curve, with its
bar or the reason it has none; a group only says which belong together.

Plain values (no PETSc): a reader of result files may call it.
"""
from __future__ import annotations

from dataclasses import dataclass

from .curve import Curve, Event

__all__ = ["GROUP_SHARE", "EventGroup", "TurningPoints", "turning_points", "rigid_turning_points",
           "spring_turning_points"]

#: A cluster of secondary turning points is grouped when it spans at most this share of the curve's scales:
#: the hysteresis in the control (lambda, or Z behind a spring) and the pull-off force.  Measured on the
#: default curves of docs/soft.md: 1.1% of the hysteresis at mu = 20, 0.4% at mu = 5 and 200, 0.15% at
#: mu = 1000, the force spans below 0.5%; a twentieth of a figure's width is a few pixels of a line.
GROUP_SHARE = 0.05


def _bar_failed(e: Event) -> bool:
    """Whether the event's error bar was tried and not had (its note says why)."""
    return e.note is not None


@dataclass(frozen=True)
class EventGroup:
    """Secondary turning points close together (see the module): ``members``, their indices among the
    curve's turning points (:attr:`TurningPoints.points`, in the order found); the control's span ``lo``
    to ``hi`` (lambda, or Z behind a spring) and the load's ``F_lo`` to ``F_hi``; ``share``, the larger of
    the two spans over the curve's scales (at most :data:`GROUP_SHARE`); ``without_bar``, the members whose
    error bar was tried and not had (each event's note says why)."""

    control: str
    members: tuple[int, ...]
    lo: float
    hi: float
    F_lo: float
    F_hi: float
    share: float
    without_bar: tuple[int, ...]

    @property
    def count(self) -> int:
        """How many turning points the group holds."""
        return len(self.members)

    @property
    def centre(self) -> float:
        """The middle of the group's span in its control."""
        return 0.5 * (self.lo + self.hi)

    @property
    def width(self) -> float:
        """The group's span in its control."""
        return self.hi - self.lo


@dataclass(frozen=True)
class TurningPoints:
    """A curve's turning points under one control (``control``: "lambda" for a rigid machine, "Z" behind a
    spring): ``points`` in the order found; ``jump_in`` and ``jump_off``, the indices of the primary ones
    (None where the curve has none: no far branch, no turning point of the contact branch); ``groups`` of
    the secondary ones; ``scale`` and ``F_scale``, the hysteresis in the control and the pull-off force
    they were measured against (None without both primary jumps and a pull-off)."""

    control: str
    points: tuple[Event, ...]
    jump_in: int | None
    jump_off: int | None
    groups: tuple[EventGroup, ...]
    scale: float | None
    F_scale: float | None

    @property
    def ungrouped(self) -> tuple[int, ...]:
        """The indices of the turning points neither primary nor in a group, in the order found."""
        grouped = {i for g in self.groups for i in g.members}
        return tuple(i for i in range(len(self.points))
                     if i not in grouped and i not in (self.jump_in, self.jump_off))


def _at(e: Event, control: str) -> float:
    if control == "Z":
        assert e.Z is not None, "a jump behind a spring has its Z"
        return e.Z.value
    return e.lam.value


def turning_points(points, on: str, off: str, pull_off: Event | None, control: str = "lambda",
                   share: float = GROUP_SHARE) -> TurningPoints:
    """The turning points ``points`` (in the order found; kinds ``on``, ``off``) with their primary jumps
    and groups (see the module), measured against the ``pull_off``'s force."""
    points = tuple(points)
    ons = [i for i, e in enumerate(points) if e.kind == on]
    offs = [i for i, e in enumerate(points) if e.kind == off]
    jump_in = ons[0] if ons else None                 # the end of the far branch: the first one reached
    jump_off = min(offs, key=lambda i: _at(points[i], control)) if offs else None
    if jump_in is None or jump_off is None or pull_off is None or jump_off < jump_in:
        return TurningPoints(control, points, jump_in, jump_off, (), None, None)
    scale = abs(_at(points[jump_in], control) - _at(points[jump_off], control))
    F_scale = abs(pull_off.F.value)
    # the part of the curve the two jumps pass over: the turning points found between them
    between = sorted(range(jump_in + 1, jump_off), key=lambda i: _at(points[i], control))
    clusters: list[list[int]] = []
    for i in between:                                 # neighbours in the control closer than the share
        if clusters and _at(points[i], control) - _at(points[clusters[-1][-1]], control) <= share * scale:
            clusters[-1].append(i)
        else:
            clusters.append([i])
    groups = []
    for c in clusters:
        xs, Fs = [_at(points[i], control) for i in c], [points[i].F.value for i in c]
        spans = ((max(xs) - min(xs)) / scale if scale > 0 else float("inf"),
                 (max(Fs) - min(Fs)) / F_scale if F_scale > 0 else float("inf"))
        if len(c) >= 2 and max(spans) <= share:
            members = tuple(sorted(c))
            groups.append(EventGroup(control, members, min(xs), max(xs), min(Fs), max(Fs), max(spans),
                                     tuple(i for i in members if _bar_failed(points[i]))))
    return TurningPoints(control, points, jump_in, jump_off, tuple(groups), scale, F_scale)


def rigid_turning_points(curve: Curve) -> TurningPoints:
    """The snap-on and snap-off of a curve under displacement control (a rigid machine)."""
    folds = [e for e in curve.events if e.kind in ("snap_on", "snap_off")]
    return turning_points(folds, "snap_on", "snap_off", curve.pull_off)


def spring_turning_points(curve: Curve) -> TurningPoints | None:
    """The jump-in and jump-off behind the curve's spring, in its base Z (None without a spring)."""
    if curve.spring is None:
        return None
    return turning_points(curve.spring.jumps, "jump_in", "jump_off", curve.pull_off, "Z")
