"""The model spread of a rough curve: its events under the other roughness laws, beside the numerical bar.

The Gaussian average of the Lennard-Jones law (eq. 7, 10) diverges: (H + 1 - S)^-9 is
not integrable where a height S closes the gap, so the paper's n-point Gauss-Hermite
rule (eq. 14) is a regularization whose outermost node is a hard wall
(docs/model.md).  From sigma ~ 0.2 on, that node, not the surface, sets the answer:
the error bar of an event (:mod:`.error_bars`) says how well the discrete problem of
the chosen law was solved, not how far another, equally defensible law would put it.

:func:`model_spread` traces the same curve (the same grid, solver, settings and
request, events only: no error bars) under alternative laws: the Hermite rule with
twice the points, and laws whose averages converge because their heights are bounded
above (the truncated Gaussian at K = 3 and 4, the reversed Weibull of skewness 0), or
the rules the caller names; and returns a :class:`ModelSpread`: for every event
quantity of the reference curve its value under each law, the largest distance from
the reference, and a warning where that spread exceeds ten error bars or 10 % of
the value (either: the bar alone then misleads, or the law moves the answer by more
than the rms is usually known to).  Events are matched by kind and order; a law with another set of events
(no hysteresis, say) is that spread itself, and is said so, not an error.

A traced curve is read through one function, :func:`curve_values`, into
:class:`~.measured.Measured` values: only it knows the curve's type.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

from ..model.roughness import Lognormal, Measured as Heights, Weibull
from .measured import Measured, Missing
from .trace import CurveRequest, GridChoice, SolverChoice, trace_curve

__all__ = ["Rule", "EventValues", "CurveValues", "Quantity", "ModelSpread", "curve_values", "parse_rules",
           "default_rules", "model_spread", "spread_quantity", "report_lines", "WARN_BARS", "WARN_RELATIVE", "KINDS", "LAWS"]

#: A spread warns when it exceeds this many error bars of the reference value ...
WARN_BARS = 10.0
#: ... or this fraction of its magnitude, however large the bar: beyond it the law changes the answer
#: by more than a surface's rms is usually known to.
WARN_RELATIVE = 0.1
#: The event kinds compared, matched by kind and order (the pull-off, the most tensile F_min, apart).
KINDS = ("snap_on", "snap_off", "equilibrium", "jump_in", "jump_off")
#: The laws a rule names, and the Model field its parameter sets: name -> (field, cast, (lo, hi), in words).
#: Hermite up to 400 points: twice the largest -adh_hermite_points, the default rule of a reference at 200.
LAWS = {"hermite": ("hermite_points", int, (2, 400), "points of the Gauss-Hermite rule, an integer in [2, 400]"),
        "truncated_gaussian": ("roughness_cutoff", float, (1e-6, 10.0),
                               "the highest asperity K in standard deviations, in [1e-06, 10]"),
        "weibull": ("roughness_skewness", float, Weibull.SKEWNESS,
                    "the skewness of the heights, in [%g, %g]" % Weibull.SKEWNESS),
        "lognormal": ("lognormal_skewness", float, Lognormal.SKEWNESS,
                      "the skewness of the heights, in [%g, %g]" % Lognormal.SKEWNESS)}


@dataclass(frozen=True)
class Rule:
    """A roughness law and its one parameter: ``hermite`` (points of the rule), ``truncated_gaussian`` (the
    cut-off K), ``weibull`` and ``lognormal`` (the skewness) or ``measured`` (the heights of the model, no parameter)."""

    law: str
    parameter: float | None = None

    def __post_init__(self):
        if self.law == "measured":
            if self.parameter is not None:
                raise ValueError("measured: takes no parameter (its heights are the model's)")
            return
        if self.law not in LAWS:
            raise ValueError(f"roughness law '{self.law}': expected one of {', '.join(LAWS)}")
        _, cast, (lo, hi), words = LAWS[self.law]
        p = self.parameter
        if p is None or not math.isfinite(p) or cast(p) != p or not lo <= p <= hi:
            raise ValueError(f"{self.law}: expected {words}, got {p!r}")

    @property
    def label(self) -> str:
        """As the option -adh_model_spread_rules spells it: hermite:32, truncated_gaussian:3, weibull:-1."""
        return self.law if self.parameter is None else f"{self.law}:{self.parameter:g}"

    @classmethod
    def of(cls, model) -> Rule:
        """The rule of ``model`` (its -adh_roughness and that law's parameter)."""
        if model.roughness == "measured":
            return cls("measured")
        field, cast, _, _ = LAWS[model.roughness]
        return cls(model.roughness, cast(getattr(model, field)))

    def model(self, model):
        """``model`` under this law: the same mu, sigma (the rms of the measured heights when the reference
        has them), domain and physical inputs."""
        if self.law == "measured":
            if model.heights is None:
                raise ValueError("measured: the reference model has no measured heights")
            return replace(model, roughness="measured")
        field, cast, _, _ = LAWS[self.law]
        return replace(model, roughness=self.law, **{field: cast(self.parameter)})


def parse_rules(text: str) -> tuple:
    """The rules of a comma-separated list ``law:parameter`` (hermite:32,truncated_gaussian:3,weibull:0);
    ValueError naming the first bad one."""
    rules = []
    for item in text.split(","):
        law, _, p = item.strip().partition(":")
        if law not in LAWS:
            raise ValueError(f"'{item.strip()}': expected law:parameter, the law one of {', '.join(LAWS)}")
        try:
            rules.append(Rule(law, float(p)))
        except ValueError:
            raise ValueError(f"'{item.strip()}': {law} takes {LAWS[law][3]}") from None
    if len(set(rules)) != len(rules):
        raise ValueError(f"'{text}': a rule named twice")
    return tuple(rules)


def default_rules(model) -> tuple:
    """The laws a rough model is compared with, its own left out.

    Under the Hermite rule: the rule with twice the points (the regularization refined:
    a converged answer would not move), and the laws whose averages converge.  Those are
    the truncated Gaussian at K = 3 and 4, the cut-offs most polished and deposited
    surfaces fall between, and the reversed Weibull of skewness 0: a bounded law with
    the Gaussian's first three moments but another upper tail (its highest asperity at
    3.24 rms), so that the shape of the tail, not only its end, is varied.

    Under measured heights, first what the Gaussian rule with their rms gives (the paper's
    16-point Hermite rule) and the truncated Gaussian whose highest asperity is the
    heights' own (K = highest height / rms, to two decimals, at most 10): the same rms and
    top, the Gaussian's shape, so that the distance is the measured shape's alone.
    """
    own = Rule.of(model)
    rules: tuple[Rule, ...] = (Rule("hermite", 2 * model.hermite_points),) if own.law == "hermite" else ()
    if own.law == "measured" and model.heights is not None:
        heights = Heights(model.heights, weights=model.height_weights)
        rules += (Rule("hermite", 16), Rule("truncated_gaussian", min(10.0, round(heights.top / heights.rms, 2))))
    rules += (Rule("truncated_gaussian", 3.0), Rule("truncated_gaussian", 4.0), Rule("weibull", 0.0))
    return tuple(dict.fromkeys(r for r in rules if r != own))


@dataclass(frozen=True)
class EventValues:
    """What the spread reads of one event: its kind, lambda and F as :class:`~.measured.Measured`."""

    kind: str
    lam: Measured
    F: Measured


@dataclass(frozen=True)
class CurveValues:
    """What the spread reads of a curve: its events of :data:`KINDS` in the order found, its pull-off (None
    without one), the energy of a cycle with a rigid machine (Missing where it was not computed), whether the
    curve is complete."""

    events: tuple
    pull_off: EventValues | None
    energy: Measured | Missing
    complete: bool


def curve_values(curve) -> CurveValues:
    """The values of a traced :class:`~.curve.Curve` the spread compares: the one function that reads the
    curve's type (an event's ``lam`` and ``F`` are :class:`~.measured.Measured`, the rigid machine's cycle
    energy Measured or Missing, completeness the curve's assessment)."""
    def values(e) -> EventValues:
        return EventValues(e.kind, e.lam, e.F)

    return CurveValues(events=tuple(values(e) for e in curve.events if e.kind in KINDS),
                       pull_off=None if curve.pull_off is None else values(curve.pull_off),
                       energy=curve.rigid.energy, complete=curve.complete)


@dataclass(frozen=True)
class Quantity:
    """One quantity of the reference curve across the laws.

    ``name``: e.g. "pull-off F", "snap_on lambda", "snap_off #2 F", "energy of a cycle"; ``unit``: "F",
    "lambda" or "energy" (the scale it is in); ``reference``: its value and bar; ``values``: under each rule
    of :attr:`ModelSpread.rules`, in their order, Missing where the law's curve has no such event;
    ``spread``: the largest distance from the reference over the laws that have it (None: none has);
    ``relative``: that over the reference's magnitude (for lambda at least 1, epsilon: its zero is a
    convention); ``warning``: one line where the spread exceeds :data:`WARN_BARS` bars or
    :data:`WARN_RELATIVE` of the value (None else).
    """

    name: str
    unit: str
    reference: Measured
    values: tuple
    spread: float | None
    relative: float | None
    warning: str | None


@dataclass(frozen=True)
class ModelSpread:
    """The reference curve's events under other roughness laws.

    ``reference``: the rule the curve was traced with; ``rules``: the others, in the order of every
    :attr:`Quantity.values`; ``quantities``: one per event quantity of the reference; ``notes``: where a law
    has another set of events (that is its spread), or its curve failed or ended early (a fit's spread: how
    each law's optimum was reached, or why not); ``wall_time_s``:
    the time of all the laws' curves, ``rule_times_s`` of each; ``force_nN``, ``approach_nm``: the units of
    F and lambda in nN and nm with physical inputs (None without).
    """

    reference: Rule
    rules: tuple
    quantities: tuple
    notes: tuple
    wall_time_s: float
    rule_times_s: tuple = ()
    force_nN: float | None = None
    approach_nm: float | None = None

    @property
    def warnings(self) -> list:
        """The quantities' warnings, one line each."""
        return [q.warning for q in self.quantities if q.warning]

    def quantity(self, name: str) -> Quantity:
        """The quantity of that name (KeyError without it)."""
        for q in self.quantities:
            if q.name == name:
                return q
        raise KeyError(name)

    def of_events(self, curve) -> tuple:
        """For each event of ``curve`` (the reference, in its order) the spreads of its lambda and its F, a
        pair, each None where the spread has not that quantity (an event of a kind not compared, an
        equilibrium's F, a quantity no other law has); the pull-off (the most tensile F_min) is found by
        its values, as a study's table lists it among the events."""
        ref = curve_values(curve)
        pull = ref.pull_off
        seen: dict[str, int] = {}
        counts = _counts(ref)
        spreads = {q.name: q.spread for q in self.quantities}
        out = []
        for e in curve.events:
            if pull is not None and e.kind == pull.kind and (e.lam, e.F) == (pull.lam, pull.F):
                name: str | None = "pull-off"
            elif e.kind in KINDS:
                seen[e.kind] = seen.get(e.kind, 0) + 1
                name = _named(e.kind, seen[e.kind], counts[e.kind])
            else:
                name = None
            out.append((None, None) if name is None else
                       (spreads.get(f"{name} lambda"), spreads.get(f"{name} F")))
        return tuple(out)


def _named(kind: str, k: int, n: int) -> str:
    """The name of the k-th (from 1) of the ``n`` events of ``kind`` among a spread's quantities."""
    return kind if n == 1 else f"{kind} #{k}"


def _matched(ref: CurveValues, alt: CurveValues) -> tuple[list, list]:
    """(names, (reference, alternative) pairs of EventValues, the alternative None where it has not the
    event), matched by kind and order; the pull-off first."""
    names, pairs = [], []
    if ref.pull_off is not None:
        names.append("pull-off")
        pairs.append((ref.pull_off, alt.pull_off))
    for kind in KINDS:
        mine = [e for e in ref.events if e.kind == kind]
        theirs = [e for e in alt.events if e.kind == kind]
        for k, e in enumerate(mine):
            names.append(_named(kind, k + 1, len(mine)))
            pairs.append((e, theirs[k] if k < len(theirs) else None))
    return names, pairs


def _counts(v: CurveValues) -> dict:
    return {kind: sum(e.kind == kind for e in v.events) for kind in KINDS}


def _difference(rule: Rule, ref: CurveValues, alt: CurveValues) -> str | None:
    """One line where the law's curve has another set of events than the reference's."""
    mine, theirs = _counts(ref), _counts(alt)
    if mine == theirs and (ref.pull_off is None) == (alt.pull_off is None):
        return None
    def listing(c):
        return ", ".join(f"{n} {k}" for k, n in c.items() if n) or "no turning point nor equilibrium"
    hyst = {k: mine[k] > 0 for k in ("snap_on", "snap_off")} != {k: theirs[k] > 0 for k in ("snap_on", "snap_off")}
    return (f"{rule.label} has other events than the reference: {listing(theirs)} against {listing(mine)}"
            + ("; the hysteresis itself depends on the law" if hyst else "")
            + ("" if alt.pull_off is not None or ref.pull_off is None else "; no pull-off"))


def _missing(rule: Rule, alt: CurveValues | None, name: str) -> Missing:
    if alt is None:
        return Missing(f"{rule.label}: its curve could not be traced")
    return Missing(f"{rule.label}: its curve has no {name}")


def _advice(reference: Rule) -> str:
    if reference.law == "hermite":
        why = "the Gaussian average diverges and the rule's outermost node sets this"
    elif reference.law == "measured":
        why = "the measured heights' shape and highest asperity set this"
    else:
        why = "the highest asperity assumed sets this"
    return (f"{why}: take a law whose average converges with the highest asperity you believe in "
            "(-adh_roughness truncated_gaussian -adh_roughness_cutoff K, weibull), or, best, your surface's "
            "measured heights (-adh_roughness measured -adh_roughness_file)")


def spread_quantity(name: str, unit: str, ref: Measured, values: tuple, rules: tuple, reference: Rule) -> Quantity:
    """The spread of one quantity (the distances of the laws that have it) and its warning; also of a quantity
    not of a curve (the work of adhesion of a pull-off fit, :mod:`~petsc_adhesion.fitting.pull_off`)."""
    dist = [(abs(v.value - ref.value), r) for v, r in zip(values, rules) if isinstance(v, Measured)]
    if not dist:
        return Quantity(name, unit, ref, values, None, None, None)
    spread, far = max(dist, key=lambda d: d[0])
    # lambda's zero is a convention (the rigid sphere's mean planes epsilon apart): its spread is measured
    # against its magnitude but at least epsilon, the law's own length, so that an equilibrium near
    # lambda = 0 does not make any spread large
    scale = max(abs(ref.value), 1.0) if unit == "lambda" else abs(ref.value)
    relative = spread / scale if scale else (0.0 if spread == 0 else math.inf)
    bar = ref.err if ref.err is not None and math.isfinite(ref.err) else 0.0    # no bar: the 10 % alone
    # either bar is reason to warn: past ten error bars the law matters more than the numerics (the bar
    # alone would mislead), past 10 % it matters to a user who knows the rms to 10 % at best
    warning = None
    if (bar > 0 and spread > WARN_BARS * bar) or spread > WARN_RELATIVE * scale:
        far_value = next(v for v, r in zip(values, rules) if r == far).value
        size = [] if math.isinf(relative) else [f"{100 * relative:.3g}% of the value"]
        if bar:
            size.append(f"{spread / bar:.2g} times its error bar")
        warning = (f"the {name} is {ref.value:.6g} under {reference.label} and {far_value:.6g} under "
                   f"{far.label}: the roughness law moves it by {spread:.3g}"
                   + (f" ({', '.join(size)})" if size else "") + "; " + _advice(reference))
    return Quantity(name, unit, ref, values, spread, relative, warning)


def model_spread(curve, model, grid_choice: GridChoice = GridChoice(), solver: SolverChoice = SolverChoice(),
                 settings=None, request: CurveRequest = CurveRequest(), rules: tuple | None = None,
                 comm=None) -> ModelSpread | Missing:
    """The spread of ``curve`` (traced for ``model`` with ``grid_choice``, ``solver``, ``settings`` and
    ``request``) over the roughness laws ``rules`` (default :func:`default_rules`); collective, as
    :func:`~.trace.trace_curve`.

    Each law's curve is traced with the same arguments and ``request`` without error bars, profiles or
    target error: the events only.  A smooth model (sigma = 0) has no law to vary: Missing with the reason.
    ValueError when a rule is the reference's own, or names measured heights the model has not.
    """
    if model.roughness == "none" or model.sigma == 0:
        return Missing("a smooth surface (sigma = 0): there is no roughness law to vary")
    reference = Rule.of(model)
    rules = default_rules(model) if rules is None else tuple(rules)
    if reference in rules:
        raise ValueError(f"{reference.label}: the reference's own law, not an alternative to it")
    models = [r.model(model) for r in rules]
    quick = replace(request, error_bars=False, profiles=False, target_error=None)
    ref = curve_values(curve)
    alts: list[CurveValues | None] = []
    notes: list[str] = []
    times: list[float] = []
    t0 = time.perf_counter()
    for rule, m in zip(rules, models):
        times.append(time.perf_counter())
        try:
            alt = curve_values(trace_curve(m, grid_choice, solver, settings, quick, comm=comm))
        except (RuntimeError, FloatingPointError) as why:
            notes.append(f"{rule.label}: its curve could not be traced ({why})")
            alts.append(None)
            continue
        if not alt.complete:
            notes.append(f"{rule.label}: its curve ended early (its values are of the part traced)")
        diff = _difference(rule, ref, alt)
        if diff:
            notes.append(diff)
        alts.append(alt)
    wall = time.perf_counter() - t0
    spent = tuple(b - a for a, b in zip(times, [*times[1:], t0 + wall]))       # each law's wall time
    none = CurveValues((), None, Missing("not traced"), False)
    names, own = _matched(ref, none)
    matched = [_matched(ref, none if alt is None else alt)[1] for alt in alts]
    quantities = []
    for i, (name, (e, _)) in enumerate(zip(names, own)):
        fields = (("lam", "lambda"),) if e.kind == "equilibrium" else (("lam", "lambda"), ("F", "F"))
        for attr, unit in fields:
            values = tuple(_missing(rule, alt, name) if pairs[i][1] is None else getattr(pairs[i][1], attr)
                           for rule, alt, pairs in zip(rules, alts, matched))
            quantities.append(spread_quantity(f"{name} {unit}", unit, getattr(e, attr), values, rules, reference))
    if isinstance(ref.energy, Measured):
        values = tuple(Missing(f"{rule.label}: its curve could not be traced") if alt is None else alt.energy
                       for alt, rule in zip(alts, rules))
        quantities.append(spread_quantity("energy of a cycle", "energy", ref.energy, values, rules, reference))
    bodies = model.bodies
    units = bodies.scales() if bodies is not None else None
    return ModelSpread(reference, rules, tuple(quantities), tuple(notes), wall, spent,
                       None if units is None else units["force_N"] * 1e9,
                       None if units is None else units["approach_m"] * 1e9)


def _scaled(spread: ModelSpread, unit: str, x: float) -> str:
    """x in its unit, and in nN or nm with physical inputs."""
    scale, name = {"F": (spread.force_nN, "nN"), "lambda": (spread.approach_nm, "nm")}.get(unit, (None, ""))
    return f"{x:.6g}" if scale is None else f"{x:.6g} ({x * scale:.4g} {name})"


def report_lines(spread: ModelSpread | Missing) -> list:
    """The lines of the console report of a spread: the laws compared, a row per quantity (its value under
    the reference with its bar, under each law, the spread absolute and relative), the notes, and the
    warnings as WARNING lines."""
    if isinstance(spread, Missing):
        return [f"model spread: none ({spread.reason})"]
    lines = [f"model spread: the events under {len(spread.rules)} other roughness law"
             f"{'s' * (len(spread.rules) != 1)} ({', '.join(r.label for r in spread.rules)}; events only, "
             f"{spread.wall_time_s:.1f} s) against {spread.reference.label}"]
    for q in spread.quantities:
        bar = "" if q.reference.err is None else f" +- {q.reference.err:.2g}"
        under = "; ".join(f"{r.label} {_scaled(spread, q.unit, v.value)}" if isinstance(v, Measured)
                          else f"{r.label} none" for r, v in zip(spread.rules, q.values))
        size = ("not computed" if q.spread is None else
                f"{q.spread:.3g}" + ("" if q.relative is None or math.isinf(q.relative)
                                     else f" ({100 * q.relative:.3g}%)"))
        lines.append(f"  {q.name}: {_scaled(spread, q.unit, q.reference.value)}{bar}; {under}; spread {size}")
    lines += [f"  note: {n}" for n in spread.notes]
    lines += [f"WARNING: {w}" for w in spread.warnings]
    return lines
