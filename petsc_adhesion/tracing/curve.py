"""The results of the library: a load-approach curve, its events, a fixed-approach solution, and their summaries.

:func:`~petsc_adhesion.tracing.trace.trace_curve` returns a :class:`Curve`,
:func:`~petsc_adhesion.tracing.trace.solve_at` a :class:`Solution`: plain
objects, the same on every rank, holding what was computed (the points, the
events with their best values, error bars and landings, the profiles when
asked for) and the summary dict a ``-summary`` file holds (docs/output.md).
The result files are made from them (:mod:`petsc_adhesion.io.write`).

Units (docs/model.md): lambda and H in epsilon, F in 2 pi R gamma (eq. 26,
negative when tensile), r and contact radii in sqrt(epsilon R), P in
8 gamma / (3 epsilon); with physical inputs (``Model.bodies``) the summary
holds every event in nm and nN too.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.physical import in_units
from ..model.pressure import pressure_law
from ..version import __version__

__all__ = ["Event", "Curve", "Solution", "program_record", "model_record", "curve_summary", "solve_summary",
           "EVENT_KINDS"]

#: The kinds of events of a curve (:mod:`~petsc_adhesion.tracing.results` names them).
EVENT_KINDS = ("snap_on", "snap_off", "F_min", "F_max", "equilibrium", "lambda", "jump_in", "jump_off")
#: The keys of an event (and of a landing) that a summary keeps.
_BRIEF = ("kind", "lambda", "F", "Z", "H0", "contact_radius", "stable", "lambda_err", "F_err", "Z_err",
          "contact_radius_err", "lambda_grid", "F_grid", "Z_grid", "contact_radius_grid", "F_beyond", "levels",
          "target_met", "error_note", "refinement_note")
_LANDING = ("lambda", "F", "Z", "H0", "contact_radius", "lambda_err", "F_err", "Z_err", "contact_radius_err",
            "lambda_grid", "F_grid")


def program_record(comm) -> dict:
    """What every result says about the program that made it: versions and ranks (``comm``: PETSc's)."""
    import petsc4py
    from petsc4py import PETSc

    return {"program": "petsc-adhesion", "version": __version__,
            "petsc_version": "%d.%d.%d" % PETSc.Sys.getVersion(),
            "petsc4py_version": petsc4py.__version__, "mpi_ranks": comm.getSize()}


def model_record(model) -> dict:
    """The model a result was computed for: mu, sigma, r_m, the roughness average and the domain."""
    return {"mu": model.mu, "sigma": model.sigma, "rmax": model.rmax, **pressure_law(model).describe(),
            "domain": "half-infinite (the rigid sphere's attraction beyond r_m added)" if model.farfield
            else "truncated at r_m (the paper's model)"}


@dataclass(frozen=True)
class Event:
    """One event of a curve: its best values and bars.

    ``kind``: snap_on, snap_off (the turning points in lambda), F_min, F_max (the
    extrema of the load; the most tensile F_min is the pull-off under load control),
    equilibrium (F = 0), lambda (a state asked for), or behind a spring jump_in and
    jump_off (the turning points of its base Z = lambda + F / K, ``Z`` and ``Z_err``
    its value and bar; stable is then None, the state marginal under the spring).  ``lam`` and ``F`` are the best
    values (Richardson-extrapolated over nested grids), ``lam_err`` and ``F_err`` their
    error bars, ``lam_grid`` and ``F_grid`` the values on the grid the event was located
    on (None, like the bars, without an error estimate: ``note`` says why).  ``stable``
    is None at a fold (marginal).  ``landing``: where the jump from a fold lands (kind
    ``"landing"``).  ``contact_radius``: where the separation rises through the edge
    level (docs/numerics.md), its best value with ``contact_radius_err`` its bar.  ``r``, ``H``, ``P``: the profiles of eq. (12) and (14)
    when asked for, else None.
    """

    kind: str
    lam: float
    F: float
    H0: float
    stable: bool | None = None
    lam_err: float | None = None
    F_err: float | None = None
    lam_grid: float | None = None
    F_grid: float | None = None
    F_beyond: float | None = None
    contact_radius: float | None = None
    levels: tuple = ()
    target_met: bool | None = None
    note: str | None = None
    landing: Event | None = None
    Z: float | None = None
    Z_err: float | None = None
    contact_radius_err: float | None = None
    r: np.ndarray | None = field(default=None, repr=False)
    H: np.ndarray | None = field(default=None, repr=False)
    P: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def from_record(cls, e: dict) -> Event:
        """The event of a record as the result files hold it (:func:`~.results.event_record`)."""
        def num(key):
            return None if e.get(key) is None else float(e[key])
        return cls(kind=e["kind"], lam=float(e["lambda"]), F=float(e["F"]), H0=float(e["H0"]),
                   stable=None if e.get("stable") is None else bool(e["stable"]), lam_err=num("lambda_err"),
                   F_err=num("F_err"), lam_grid=num("lambda_grid"), F_grid=num("F_grid"), F_beyond=num("F_beyond"),
                   contact_radius=num("contact_radius"), contact_radius_err=num("contact_radius_err"),
                   Z=num("Z"), Z_err=num("Z_err"), levels=tuple(int(k) for k in e.get("levels", ())),
                   target_met=e.get("target_met"), note=e.get("error_note"),
                   landing=cls.from_record({"kind": "landing", **e["landing"]}) if e.get("landing") else None,
                   r=e.get("r"), H=e.get("H"), P=e.get("P"))


def _plain(x):
    """Python numbers, lists and dicts of x (as its JSON file holds it)."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return x


def _brief(e: dict) -> dict:
    out = {k: v for k, v in e.items() if k in _BRIEF}
    if "landing" in e:
        out["landing"] = {k: v for k, v in e["landing"].items() if k in _LANDING}
    return out


def _common(head: dict) -> dict:
    """The keys every summary has: versions, the model and the grid size (the largest grid's)."""
    flat = {k: v for k, v in head.items() if k not in ("options", "model", "grid")}
    sizes = head["grid"].get("n_nodes", [head["grid"]["r"].size])
    return {**flat, **head["model"], "n_nodes": int(max(sizes))}


def _cycle(c: dict) -> dict:
    return {"energy": c["energy"], "energy_err": c["energy_err"], "loops": c["loops"],
            **({"energy_note": c["energy_note"]} if "energy_note" in c else {})}


def curve_summary(res: dict, head: dict) -> dict:
    """The summary of a traced curve (``res``: :func:`~.trace.trace_curve`'s record; ``head``: the program,
    model, grid and physical inputs)."""
    ev, po = res["events"], res["pull_off"]
    cycles = res["cycles"]
    s = {**_common(head),
         "pull_off": _brief(po) if po else None,
         "folds": [_brief(e) for e in ev if e["kind"] in ("snap_on", "snap_off")],
         "equilibria": [{k: v for k, v in _brief(e).items() if k not in ("F", "F_err", "F_grid")}
                        for e in ev if e["kind"] == "equilibrium"],
         "load_extrema": [_brief(e) for e in ev if e["kind"] in ("F_min", "F_max")],
         "at_lambda": [_brief(e) for e in ev if e["kind"] == "lambda"],
         **_cycle(cycles["rigid"]),
         **({"spring": {"K": cycles["spring"]["K"],
                        "jumps": [_brief(e) for e in ev if e["kind"] in ("jump_in", "jump_off")],
                        **_cycle(cycles["spring"])}} if "spring" in cycles else {}),
         "wall_gap": res["wall_gap"],
         "steps": res["steps"], "rejected_steps": res["rejected_steps"], "regrids": res["regrids"],
         **{k: res[k] for k in ("guard_activations", "smallest_step", "most_newton_its", "most_ksp_its")},
         "stop_reason": res["stop_reason"],
         "grid_warning": res["grid_warning"], "warnings": res["warnings"], "complete": not res["incomplete"],
         "lambda_start": res["lambda_start"], "wall_time_s": res["wall_time_s"]}
    if "error_estimate" in res:
        s["error_estimate"] = res["error_estimate"]
    if "physical" in head:
        s["physical"] = in_units(s, head["physical"])
    return _plain(s)


def solve_summary(res: dict, head: dict) -> dict:
    """The summary of a fixed-approach solve (``res``: its record without the profiles)."""
    summ = {**_common(head), **res}
    if "physical" in head:
        d = head["physical"]
        summ["physical"] = {**d, "lambda_nm": res["lambda"] * d["approach_nm"], "F_nN": res["F"] * d["force_nN"],
                            "H0_nm": res["H0"] * d["approach_nm"]}
    return _plain(summ)


@dataclass(frozen=True)
class Curve:
    """A load-approach curve: its computed points, its events, its pull-off and its summary.

    ``lam``, ``F``, ``H0`` and ``stable`` hold one entry a computed point, in the order
    traced (lambda = alpha / epsilon, F in 2 pi R gamma by eq. (26), H0 = H(0), stable
    under displacement control); ``branch`` holds those, the contact radius, behind a
    spring Z and the stability under it, and the step statistics of every point
    (docs/output.md, the HDF5 group ``curve``).  ``events`` in the order
    found; ``pull_off`` the most tensile load minimum (load control).  ``summary`` is
    the dict a ``-summary`` file holds; ``head`` the program, model, grid and physical
    inputs it was computed with; ``records`` the events as the result files hold them.
    """

    lam: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    H0: np.ndarray = field(repr=False)
    stable: np.ndarray = field(repr=False)
    events: tuple
    pull_off: Event | None
    summary: dict = field(repr=False)
    branch: dict = field(repr=False)
    head: dict = field(repr=False)
    records: list = field(repr=False)

    @property
    def complete(self) -> bool:
        """Whether the curve is what was asked for (the command line's exit status 0, not 3)."""
        return bool(self.summary["complete"])

    @property
    def warnings(self) -> list:
        """What makes the curve untrustworthy, one line each (the command line's WARNING lines)."""
        return list(self.summary["warnings"])

    def events_of(self, kind: str) -> tuple:
        """The events of one kind: snap_on, snap_off, F_min, F_max, equilibrium, lambda, jump_in or jump_off."""
        return tuple(e for e in self.events if e.kind == kind)

    @property
    def contact_radius(self) -> np.ndarray:
        """The contact radius of every computed point (docs/numerics.md; units sqrt(epsilon R))."""
        return self.branch["contact_radius"]

    @property
    def Z(self) -> np.ndarray | None:
        """Behind a spring, its base position Z = lambda + F / K at every computed point (else None)."""
        return self.branch.get("Z")

    @property
    def energy(self) -> tuple:
        """(energy, bar) dissipated in one approach-retract cycle with a rigid machine (units 2 pi R gamma
        epsilon; 0 without hysteresis; None when the cycle cannot be closed or has no bar)."""
        return self.summary["energy"], self.summary["energy_err"]

    @property
    def spring(self) -> dict | None:
        """Behind a spring: {K, jumps, energy, energy_err, loops} as the summary holds it (else None)."""
        return self.summary.get("spring")

    @classmethod
    def from_result(cls, res: dict, head: dict) -> Curve:
        """The curve of a traced record (rank 0's: the points, the events as records) and its head."""
        pts = res["points"]
        branch = {"lambda": np.array([p.p for p in pts]), "F": np.array([p.values["F"] for p in pts]),
                  "stable": np.array([p.pdot > 0 for p in pts]), "ds": np.array([p.ds for p in pts]),
                  "newton_its": np.array([p.newton_its for p in pts]), "ksp_its": np.array([p.ksp_its for p in pts]),
                  "H0": np.array([p.x[0] for p in pts]), "lambdadot": np.array([p.pdot for p in pts]),
                  "corrector": np.array([p.corrector for p in pts], dtype="S9"),
                  "contact_radius": np.array(res["contact_radius"], dtype=float)}
        spring = res["cycles"].get("spring")
        if spring is not None:            # behind a spring: its base Z = lambda + F / K, stable where dZ/ds > 0
            K = spring["K"]
            branch["Z"] = branch["lambda"] + branch["F"] / K
            branch["stable_spring"] = np.array([p.pdot + p.rates["F"] / K > 0 for p in pts])
        records = [{k: v for k, v in e.items() if k != "segment"} for e in res["events"]]
        summary = curve_summary(res, head)
        events = [Event.from_record(e) for e in records]
        pull = next((ev for ev, e in zip(events, res["events"]) if e is res["pull_off"]), None)
        return cls(lam=branch["lambda"], F=branch["F"], H0=branch["H0"], stable=branch["stable"], events=tuple(events),
                   pull_off=pull, summary=summary, branch=branch, head=head, records=records)


@dataclass(frozen=True)
class Solution:
    """The state at one fixed approach ``lam``: H(r) (eq. 12) and P(r) (eq. 14) on the nodes r, the load F
    (eq. 26; ``F_beyond`` of it from beyond r_m) and the summary a ``-summary`` file holds; ``record``: the
    scalars of the solve (the solver's iterations and time among them), ``head`` as :class:`Curve`'s."""

    lam: float
    F: float
    H0: float
    F_beyond: float
    r: np.ndarray = field(repr=False)
    H: np.ndarray = field(repr=False)
    P: np.ndarray = field(repr=False)
    summary: dict = field(repr=False)
    head: dict = field(repr=False)
    record: dict = field(repr=False)

    @classmethod
    def from_result(cls, res: dict, head: dict) -> Solution:
        """The solution of a solve's record (``H`` and ``P`` whole) and its head."""
        brief = {k: v for k, v in res.items() if not isinstance(v, np.ndarray)}
        return cls(lam=float(res["lambda"]), F=float(res["F"]), H0=float(res["H0"]), F_beyond=float(res["F_beyond"]),
                   r=np.asarray(head["grid"]["r"]), H=res["H"], P=res["P"], summary=solve_summary(brief, head),
                   head=head, record=brief)
