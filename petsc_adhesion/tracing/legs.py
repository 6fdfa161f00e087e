"""The force curve an instrument records behind a spring: the approach and the retract as the two legs a
cantilever follows, made from the traced curve (its stable pieces, jumps vertical at constant Z).

Behind a spring of stiffness K the base sits at Z = lambda + F / K (units of
epsilon; F in 2 pi R gamma).  Where dZ/ds > 0 along the traced curve the state is
stable behind the spring (``Branch.stable_spring``); each run of such points is a
:class:`Piece`, on which Z grows with lambda.  A piece ends at a turning point of
Z: a jump_in where Z is largest (the approach leaves the piece there), a jump_off
where it is smallest (the retract leaves it there); the jump is vertical in F at
constant Z and lands on the piece the library found its landing on
(``Event.landing``, located by the solver at the jump's Z).  So:

- the approach follows the first piece (the far branch) up to its jump_in, jumps
  to the piece it lands on, follows that up to its own jump_in, and so on to the
  last piece, which it follows to the curve's end (the trigger, ``-afm_trigger``
  or ``-phys_trigger``, or the stop load ``-cont_F_max``);
- the retract follows the last piece back down to its jump_off, jumps to the
  piece it lands on, and so on back to the far branch, to the curve's first point.

The legs hold the solver's points and nothing else: the traced points, the
turning points and their landings at their values on the grid the curve was
traced on (the best values and bars are the events'); no point is drawn between
them, so a leg is as fine as the continuation's steps (which a run with a trigger
bounds by the trigger's range, :func:`figure_step`).

The pieces, the pieces their jumps land on and the chains each leg follows are
made from arrays and turning points (:func:`stable_pieces` of a branch's
lambda, F and stability and its :class:`Turn` s, :func:`landing_piece`,
:func:`chain`): one construction for the traced branch (:func:`branch_pieces`,
the legs here), and for the splines of :mod:`petsc_adhesion.family.legs`, which
predict F(Z) for the fit's forward model and the family table's curves.

Pieces narrower than one step of the curve (a fold pair inside one step) have no
traced point of their own: their turning points are left out with a note.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .curve import Branch

__all__ = ["APPROACH", "RETRACT", "LEGS", "State", "Turn", "Piece", "Leg", "InstrumentCurve", "turn_of",
           "stable_pieces", "branch_pieces", "landing_piece", "chain", "instrument_curve", "figure_step",
           "FIGURE_STEPS", "TRIGGER_FACTOR"]

APPROACH, RETRACT = "approach", "retract"
LEGS = (APPROACH, RETRACT)
#: Steps of the load, at least, between the pull-off and the trigger: what a figure of the legs needs to show
#: the contact branch bend (the issue's probe had 3 points on it with -cont_dF_max 0.2).
FIGURE_STEPS = 50
#: The default trigger of a run with a spring and physical inputs: this many times the rigid sphere's pull-off
#: (an instrument's setpoint of a few times the adhesion, so that the jumps and the pull-off are readable).
TRIGGER_FACTOR = 3.0


def figure_step(trigger: float, pull_off: float) -> float:
    """The largest change of the load in one step (relative above |F| = 1, as ``Settings.observable_step``)
    that puts :data:`FIGURE_STEPS` steps between the load ``pull_off`` (negative) and the ``trigger``."""
    span = float(trigger) - min(float(pull_off), 0.0)
    return span / (FIGURE_STEPS * max(1.0, abs(float(trigger))))


def _grid_value(e, key: str) -> float:
    """An event's (or a landing's) ``key`` on its grid (its best value when it has none): lam, F or
    contact_radius (NaN where it has none)."""
    m = getattr(e, key)                 # a Measured, or None (a contact radius not computed)
    if m is None:
        return float("nan")
    return float(m.grid if m.grid is not None else m.value)


@dataclass(frozen=True)
class State:
    """One state of a branch as the legs read it: its ``lam``, ``F`` and ``contact_radius`` (NaN: none)."""

    lam: float
    F: float
    contact_radius: float = float("nan")

    def Z(self, K: float) -> float:
        """The base position behind a spring of stiffness ``K``: Z = lambda + F / K."""
        return self.lam + self.F / K


@dataclass(frozen=True)
class Turn(State):
    """A turning point of Z = lambda + F / K (a jump_in or a jump_off) and the ``landing``, the state its jump
    lands on (None: not known; the next piece holding its Z is taken)."""

    landing: State | None = None


def turn_of(event) -> Turn:
    """A jump_in or jump_off event (or a landing) as the turning point the legs read: its values on its grid,
    and its landing's where the library found one."""
    land = getattr(event, "landing", None)
    return Turn(_grid_value(event, "lam"), _grid_value(event, "F"), _grid_value(event, "contact_radius"),
                None if land is None else turn_of(land))


@dataclass(frozen=True)
class Piece:
    """One piece stable behind the spring: its points in order (lambda and Z growing), the turning point it
    starts at (``start``, a jump_off) and ends at (``end``, a jump_in) put at its ends, None where the piece
    starts or ends with the branch."""

    lam: np.ndarray = field(repr=False)
    Z: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    contact_radius: np.ndarray = field(repr=False)
    start: Turn | None = None
    end: Turn | None = None

    @property
    def Z_lo(self) -> float:
        return float(self.Z[0])

    @property
    def Z_hi(self) -> float:
        return float(self.Z[-1])


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The maximal runs [i0, i1] of True in ``mask``."""
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1).tolist(), (np.flatnonzero(edges == -1) - 1).tolist()))


def _match(turns: list[Turn], used: set, lam: float, Z: float, K: float) -> Turn | None:
    """The turning point (of ``turns``, not yet used) nearest to the end (lam, Z) of a run."""
    free = [i for i in range(len(turns)) if i not in used]
    if not free:
        return None
    best = min(free, key=lambda i: abs(turns[i].lam - lam) + abs(turns[i].Z(K) - Z))
    used.add(best)
    return turns[best]


def stable_pieces(lam, F, stable, K: float, jump_in: list[Turn], jump_off: list[Turn],
                  contact_radius=None) -> tuple[list[Piece], list[str]]:
    """The pieces of a branch (its points' ``lam``, ``F``, ``contact_radius`` (None: not known) in its order,
    ``stable``: dZ/ds > 0 at each behind the spring of stiffness ``K``), each with the turning points of
    ``jump_in`` and ``jump_off`` at its ends, and notes on the turning points no piece ends at (ValueError when
    no point is stable)."""
    lam, F = np.asarray(lam, dtype=float), np.asarray(F, dtype=float)
    Z = lam + F / K
    radius = np.full_like(lam, np.nan) if contact_radius is None else np.asarray(contact_radius, dtype=float)
    turns = {"jump_in": list(jump_in), "jump_off": list(jump_off)}
    used: dict[str, set[int]] = {k: set() for k in turns}
    pieces = []
    for i0, i1 in _runs(np.asarray(stable, dtype=bool)):
        keep = slice(i0, i1 + 1)
        cols = [lam[keep], Z[keep], F[keep], radius[keep]]
        start = _match(turns["jump_off"], used["jump_off"], cols[0][0], cols[1][0], K) if i0 > 0 else None
        end = _match(turns["jump_in"], used["jump_in"], cols[0][-1], cols[1][-1], K) if i1 < lam.size - 1 else None
        if start is not None:
            cols = [np.concatenate(([v], a)) for a, v in zip(cols, (start.lam, start.Z(K), start.F,
                                                                      start.contact_radius))]
        if end is not None:
            cols = [np.concatenate((a, [v])) for a, v in zip(cols, (end.lam, end.Z(K), end.F, end.contact_radius))]
        pieces.append(Piece(cols[0], cols[1], cols[2], cols[3], start, end))
    if not pieces:
        raise ValueError("the branch has no state stable behind the spring")
    notes = [f"{len(ts) - len(used[kind])} {kind} inside one step of the curve left out (a hysteresis loop "
             f"narrower than a step)" for kind, ts in turns.items() if len(ts) > len(used[kind])]
    return pieces, notes


def branch_pieces(branch: Branch, jumps, K: float) -> tuple[list[Piece], list[str]]:
    """:func:`stable_pieces` of a traced ``branch`` behind the spring of stiffness ``K`` and its turning points
    ``jumps`` (the jump_in and jump_off events, with their landings)."""
    turns = {k: [turn_of(e) for e in jumps if e.kind == k] for k in ("jump_in", "jump_off")}
    return stable_pieces(branch.lam, branch.F, branch.stable_spring, K, turns["jump_in"], turns["jump_off"],
                         branch.contact_radius)


def landing_piece(pieces, i: int, turn: Turn, step: int, K: float) -> int | None:
    """The index of the piece (of ``pieces``: anything with ``lam`` and ``Z`` arrays, Z non-decreasing) the
    jump of ``turn`` at an end of piece ``i`` lands on, in the direction ``step`` (+1 a jump_in, -1 a
    jump_off): the one holding its landing, else the next that holds the jump's Z (the last, or the first,
    holding any Z beyond it); None where none does."""
    Zf = turn.Z(K)
    others = range(i + step, len(pieces) if step > 0 else -1, step)
    if turn.landing is not None:
        lam_l = turn.landing.lam
        for j in others:
            p = pieces[j]
            span = max(p.lam[-1] - p.lam[0], 1.0)
            if p.lam[0] - 1e-6 * span <= lam_l <= p.lam[-1] + 1e-6 * span:
                return j
    for j in others:
        p = pieces[j]
        if p.Z[0] <= Zf <= p.Z[-1] or (step > 0 and j == len(pieces) - 1 and Zf >= p.Z[0]) or \
                (step < 0 and j == 0 and Zf <= p.Z[-1]):
            return j
    return None


def chain(pieces, links: list, first: int, step: int) -> tuple[list[int], np.ndarray]:
    """The pieces a leg follows from piece ``first`` by ``links`` (the piece each one's jump lands on, or
    None) and the Z at which it leaves each (increasing on the approach, ``step`` +1; decreasing on the
    retract, -1)."""
    out, p = [first], first
    cuts: list[float] = []
    while links[p] is not None and len(out) <= len(pieces):
        nxt = links[p]
        cut = float(pieces[p].Z[-1] if step > 0 else pieces[p].Z[0])
        if nxt in out or (cuts and (cut - cuts[-1]) * step <= 0):
            break
        out.append(nxt)
        cuts.append(cut)
        p = nxt
    return out, np.array(cuts, dtype=float)


@dataclass(frozen=True)
class Leg:
    """One leg as the instrument records it, in its order: the base (piezo) position ``Z``, the force ``F``
    (eq. 26, negative when tensile), the tip's approach ``lam`` and the ``contact_radius`` (NaN at a landing
    the library gave none); ``jumps``: the indices i at which the tip jumps at constant Z from point i (a
    turning point) to point i + 1 (its landing).  Units as the curve's (epsilon, 2 pi R gamma, sqrt(epsilon R))."""

    name: str
    K: float
    Z: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    lam: np.ndarray = field(repr=False)
    contact_radius: np.ndarray = field(repr=False)
    jumps: tuple[int, ...] = ()

    @property
    def deflection(self) -> np.ndarray:
        """The cantilever's deflection F / K (epsilon; positive bent away from the flat, pushed)."""
        return self.F / self.K

    @property
    def separation(self) -> np.ndarray:
        """The tip-sample separation an instrument computes, the base's position less the deflection, counted
        positive apart: -(Z - F / K) = -lambda (epsilon; 0 where the undeformed sphere sits at epsilon from
        the flat, negative an indentation)."""
        return -self.lam


@dataclass(frozen=True)
class InstrumentCurve:
    """The approach and the retract a cantilever of stiffness ``K`` follows (:class:`Leg` each); ``trigger``:
    the load the approach was to end at (-afm_trigger, -phys_trigger or -cont_F_max; None: none), ``reached``
    whether the curve got there, ``notes`` what the legs leave out."""

    K: float
    approach: Leg
    retract: Leg
    trigger: float | None
    reached: bool
    notes: tuple[str, ...] = ()

    @property
    def legs(self) -> tuple[Leg, Leg]:
        return self.approach, self.retract

    @property
    def area(self) -> float:
        """The closed integral of F dZ round the two legs (the trapezoidal rule on their points): the energy
        of the cycle as the legs' polygon holds it (units 2 pi R gamma epsilon)."""
        Z = np.r_[self.approach.Z, self.retract.Z]
        F = np.r_[self.approach.F, self.retract.F]
        return float(abs(np.sum((Z[1:] - Z[:-1]) * (F[1:] + F[:-1])) / 2.0))


def _landing_point(pieces, j: int, turn: Turn, kind: str, K: float, notes: list) -> tuple:
    """(Z, F, lam, contact radius) where the jump of ``turn`` (a ``kind``) lands on piece ``j``: its landing at
    its grid values, else (none found) the piece's points interpolated at the jump's Z, said in a note."""
    Zf = turn.Z(K)
    land = turn.landing
    if land is not None:
        return Zf, land.F, land.lam, land.contact_radius
    p = pieces[j]
    notes.append(f"the {kind} at Z = {Zf:.6g} has no landing located by the solver: its landing is "
                 f"interpolated between the traced points")
    return Zf, float(np.interp(Zf, p.Z, p.F)), float(np.interp(Zf, p.Z, p.lam)), float("nan")


def _leg(name: str, pieces, order: list[int], step: int, K: float, notes: list) -> Leg:
    """The leg following the pieces ``order`` (approach: Z growing, ``step`` +1; retract: falling, -1)."""
    cols: list[list[float]] = [[], [], [], []]
    jumps = []
    entry = None                         # (Z, F, lam, radius) of the landing the leg enters a piece at
    for k, j in enumerate(order):
        p = pieces[j]
        idx = np.arange(p.Z.size) if step > 0 else np.arange(p.Z.size)[::-1]
        if entry is not None:
            jumps.append(len(cols[0]) - 1)
            for c, v in zip(cols, entry):
                c.append(v)
            idx = idx[(p.Z[idx] - entry[0]) * step > 0]
        for c, a in zip(cols, (p.Z, p.F, p.lam, p.contact_radius)):
            c.extend(float(v) for v in a[idx])
        if k + 1 < len(order):           # it leaves at the turning point its last point is (put there)
            fold, kind = (p.end, "jump_in") if step > 0 else (p.start, "jump_off")
            entry = _landing_point(pieces, order[k + 1], fold, kind, K, notes)
    Z, F, lam, radius = (np.array(c, dtype=float) for c in cols)
    return Leg(name, K, Z, F, lam, radius, tuple(jumps))


def instrument_curve(branch: Branch, jumps, K: float, trigger: float | None) -> InstrumentCurve:
    """The :class:`InstrumentCurve` of a branch traced behind a spring of stiffness ``K``, its turning points
    ``jumps`` (the jump_in and jump_off events, with their landings) and the load ``trigger`` it was traced to
    (None: no stop load).  ValueError when no point is stable behind the spring."""
    pieces, notes = branch_pieces(branch, jumps, K)
    ends = [landing_piece(pieces, i, p.end, +1, K) if p.end is not None else None for i, p in enumerate(pieces)]
    starts = [landing_piece(pieces, i, p.start, -1, K) if p.start is not None else None
              for i, p in enumerate(pieces)]
    for links, what, kind in ((ends, "end", "jump_in"), (starts, "start", "jump_off")):
        for i, p in enumerate(pieces):
            t = getattr(p, what)
            if t is not None and links[i] is None:
                notes.append(f"the {kind} at Z = {t.Z(K):.6g} lands on no traced piece: the leg ends there")
    up, _ = chain(pieces, ends, 0, +1)
    down, _ = chain(pieces, starts, len(pieces) - 1, -1)
    approach = _leg(APPROACH, pieces, up, +1, K, notes)
    retract = _leg(RETRACT, pieces, down, -1, K, notes)
    stop = float(trigger) if trigger is not None and np.isfinite(trigger) else None
    reached = bool(stop is not None and approach.F[-1] >= stop and up[-1] == len(pieces) - 1)
    if stop is not None and not reached:
        notes.append(f"the approach ends at F = {approach.F[-1]:.6g}, short of the trigger {stop:.6g}")
    return InstrumentCurve(K, approach, retract, stop, reached, tuple(notes))


def rigid_pull_off(model) -> float:
    """The pull-off of the rigid sphere under ``model``'s pressure law (its roughness average included): the
    least of its load F(H0) = (8/3) integral from H0 to infinity of P(H) dH (eqs. 26, 27: -1 smooth, DMT's),
    reached where P(H0) = 0.  An estimate of a curve's pull-off before it is traced: its DMT end (mu -> 0);
    a soft sphere's is smaller in magnitude, down to 3/4 of it (JKR's)."""
    from ..model.pressure import pressure_law

    law = pressure_law(model)
    H = law.wall + np.geomspace(1e-6, 1e4, 4001)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        P = np.asarray(law(H)[0], dtype=float)
    attract = np.flatnonzero(np.isfinite(P) & (P < 0))
    if not attract.size:
        raise ValueError("the pressure law attracts nowhere")
    i = int(attract[0])                 # P turns attractive between H[i - 1] and H[i]: the load is least there
    if i > 0 and np.isfinite(P[i - 1]):
        H0 = H[i - 1] + (H[i] - H[i - 1]) * P[i - 1] / (P[i - 1] - P[i])
        Ht, Pt = np.r_[H0, H[i:]], np.r_[0.0, P[i:]]
    else:
        Ht, Pt = H[i:], P[i:]
    tail = Pt[-1] * Ht[-1] / 2.0        # P ~ -H^-3 far out: the rest of the integral
    return float(8.0 / 3.0 * (np.sum(np.diff(Ht) * (Pt[1:] + Pt[:-1]) / 2.0) + tail))


def default_trigger(model) -> tuple[float, float]:
    """(the trigger, the pull-off it is made from) of a run behind a spring with physical inputs and no stop
    load given: :data:`TRIGGER_FACTOR` times the magnitude of the rigid sphere's pull-off
    (:func:`rigid_pull_off`), an instrument's setpoint of a few times the adhesion."""
    pull = rigid_pull_off(model)
    return TRIGGER_FACTOR * abs(pull), pull
