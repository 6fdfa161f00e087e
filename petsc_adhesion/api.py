"""The Python API: a load-approach curve or a fixed-approach solve from a notebook or a script.

    import petsc_adhesion as pa
    c = pa.curve(mu=1.0, grid_type="uniform", grid_n=201)
    print(c.pull_off.F, "+-", c.pull_off.F_err)
    s = pa.solve(-2.0, mu=1.0, snes_rtol=1e-12)                   # H(r), P(r), F at lambda = -2

Each call is one run of the command line (:func:`petsc_adhesion.study.main`) on the
options given as keywords: ``grid_n=201`` is ``-grid_n 201``, ``True`` a bare flag,
``False`` ``false``, a list a comma-separated value, ``None`` leaves the option out.
They are checked as the command line checks them (the same one-line
:class:`~petsc_adhesion.errors.InputError`, unknown options refused, before any work)
and PETSc's options (``arc_snes_rtol=1e-10``, ``pc_type="lu"``) reach its solvers;
``PETSC_OPTIONS`` and ``.petscrc`` are read as at the command line's start.  Each run
has an options database of its own, so runs in one process do not see each other's
options, nor the caller's; a run destroys the PETSc objects it makes, failed runs too (a
PETSc type name that does not exist, ``pc_type="nonesuch"``, included).
``out=``, ``summary=`` and ``plot=`` write the command line's files, all or nothing.

PETSc is initialised on the first call, not on ``import petsc_adhesion``.  Under
``mpiexec`` every rank makes the same call (a collective one), and every rank gets
the whole result; rank 0 writes the files.
"""
from __future__ import annotations

import json
import re
import sys
import warnings
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError

__all__ = ["curve", "solve", "Curve", "Event", "Solution"]


@dataclass(frozen=True)
class Event:
    """One event of a curve (:mod:`petsc_adhesion.results` names the kinds): its best values and bars.

    ``lam`` and ``F`` are the best values (Richardson-extrapolated over nested grids),
    ``lam_err`` and ``F_err`` their error bars, ``lam_grid`` and ``F_grid`` the values
    on the grid the event was located on (None, like the bars, without an error
    estimate: ``note`` says why).  ``stable`` is None at a fold (marginal).  ``landing``:
    where the jump from a fold lands (kind ``"landing"``).  ``contact_radius``: where the
    separation rises through the edge level, on that grid (no bar).  ``r``, ``H``, ``P``: the
    profiles of eq. (12) and (14) with ``profiles=True``, else None.
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
    note: str | None = None
    landing: Event | None = None
    r: np.ndarray | None = field(default=None, repr=False)
    H: np.ndarray | None = field(default=None, repr=False)
    P: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def from_record(cls, e: dict) -> Event:
        """The event of a result file's record (:func:`petsc_adhesion.results.event_record`)."""
        def num(key):
            return None if e.get(key) is None else float(e[key])
        return cls(kind=e["kind"], lam=float(e["lambda"]), F=float(e["F"]), H0=float(e["H0"]),
                   stable=None if e.get("stable") is None else bool(e["stable"]), lam_err=num("lambda_err"),
                   F_err=num("F_err"), lam_grid=num("lambda_grid"), F_grid=num("F_grid"), F_beyond=num("F_beyond"),
                   contact_radius=num("contact_radius"),
                   levels=tuple(int(k) for k in e.get("levels", ())), note=e.get("error_note"),
                   landing=cls.from_record({"kind": "landing", **e["landing"]}) if e.get("landing") else None,
                   r=e.get("r"), H=e.get("H"), P=e.get("P"))


@dataclass(frozen=True)
class Curve:
    """A load-approach curve: its computed points, events, pull-off and the JSON summary.

    ``lam``, ``F``, ``H0`` and ``stable`` hold one entry a computed point, in the
    order traced (lambda = alpha / epsilon, F in 2 pi R gamma by eq. (26), H0 =
    H(0), stable under displacement control); ``summary`` is the dict the command
    line's ``-summary`` file holds (docs/output.md).
    """

    lam: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    H0: np.ndarray = field(repr=False)
    stable: np.ndarray = field(repr=False)
    events: tuple
    pull_off: Event | None
    summary: dict = field(repr=False)

    @property
    def complete(self) -> bool:
        """Whether the curve is what was asked for (the command line's exit status 0, not 3)."""
        return bool(self.summary["complete"])

    @property
    def warnings(self) -> list:
        """What makes the curve untrustworthy, one line each (the command line's WARNING lines)."""
        return list(self.summary["warnings"])

    def events_of(self, kind: str) -> tuple:
        """The events of one kind: snap_on, snap_off, F_min, F_max, equilibrium or lambda."""
        return tuple(e for e in self.events if e.kind == kind)


@dataclass(frozen=True)
class Solution:
    """The state at one fixed approach ``lam``: H(r) (eq. 12), P(r) (eq. 14) on the nodes r, the
    load F (eq. 26; ``F_beyond`` of it from beyond r_m) and the JSON summary of ``-summary``."""

    lam: float
    F: float
    H0: float
    F_beyond: float
    r: np.ndarray = field(repr=False)
    H: np.ndarray = field(repr=False)
    P: np.ndarray = field(repr=False)
    summary: dict = field(repr=False)


def curve(mu: float | None = None, sigma: float | None = None, **options) -> Curve:
    """Trace the load-approach curve of ``-adh_mu mu -adh_sigma sigma`` and the ``options``.

    mu, sigma: the Tabor parameter (eq. 9) and the roughness; None: the
    program's defaults (mu = 1, sigma = 0).  ``options``: application and PETSc
    options by name without the dash (see the module).  Raises
    :class:`~petsc_adhesion.errors.InputError` for bad input (nothing computed,
    nothing written) and RuntimeError when no result can be had; a curve that
    is not what was asked for (``complete`` False) comes back with a warning.
    """
    if "adh_lambda" in options:
        raise InputError("-adh_lambda: curve() traces the whole curve; solve(lam) solves at one approach")
    kept = _run(_argv(options, adh_mu=mu, adh_sigma=sigma))
    return _curve(kept)


def solve(lam: float, mu: float | None = None, sigma: float | None = None, **options) -> Solution:
    """Solve at the one approach ``lam`` (``-adh_lambda``) for ``-adh_mu mu -adh_sigma sigma`` and the ``options``.

    As :func:`curve`; the Newton solver's options have no prefix (``snes_rtol=1e-12``),
    and ``adh_guess`` names an ``out=`` file of an earlier solve as the initial guess.
    """
    kept = _run(_argv(options, adh_lambda=lam, adh_mu=mu, adh_sigma=sigma))
    return _solution(kept)


# -- options into a command line ---------------------------------------------------------------
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
#: What the command line does with these other than compute: the API computes.
_REFUSED = {"help": "see help(petsc_adhesion.curve) and docs/usage.md",
            "version": "see petsc_adhesion.__version__"}


def _value(name: str, v) -> list[str]:
    """The command-line words of one option's value (none for a bare flag)."""
    if isinstance(v, np.generic):
        v = v.item()
    if v is True:
        return []
    if v is False:
        return ["false"]
    if isinstance(v, (int, float)):
        return [repr(v)]
    if isinstance(v, str):
        return [v]
    if isinstance(v, (list, tuple, np.ndarray)) and all(isinstance(x, (int, float, str, np.generic)) for x in v):
        return [",".join(x if isinstance(x, str) else repr(x.item() if isinstance(x, np.generic) else x) for x in v)]
    raise InputError(f"-{name}: cannot give a {type(v).__name__} as an option's value; give a number, a string, "
                     f"True for a bare flag, or a list")


def _argv(options: dict, **named) -> list[str]:
    """The command line of the keyword ``options`` and the named parameters (name -> value, None: not given)."""
    aliases = {"adh_mu": "mu", "adh_sigma": "sigma", "adh_lambda": "lam"}
    argv = ["petsc_adhesion"]
    for name, v in named.items():
        if v is not None and name in options:
            raise InputError(f"-{name}: given twice, as {aliases[name]} and as {name}")
    for name, v in {**{k: v for k, v in named.items() if v is not None}, **options}.items():
        if not _NAME.fullmatch(name):
            raise InputError(f"'{name}': not an option name; give it without the dash, e.g. grid_n=201")
        if name in _REFUSED:
            raise InputError(f"-{name}: not in the Python API; {_REFUSED[name]}")
        if v is not None:
            argv += [f"-{name}", *_value(name, v)]
    return argv


# -- a run of the command line ----------------------------------------------------------------
def _run(argv: list[str]) -> dict | None:
    """Run the program on ``argv`` in an options database of its own; what it kept (:func:`~.study.main`),
    on rank 0, None elsewhere.  Its errors raise: InputError for bad input, RuntimeError otherwise."""
    from .cli import input_error

    bad = input_error(argv)
    if bad:
        raise InputError(bad)
    import petsc4py

    if "petsc4py.PETSc" not in sys.modules:         # options are the run's own: none at start-up
        petsc4py.init(["petsc_adhesion"])
    from petsc4py import PETSc

    from . import capi, study
    from .options import petsc_error

    kept, failed = {}, None
    with capi.options_from(argv):
        try:
            study.main(argv, keep=kept)
        except PETSc.Error as e:
            bad = petsc_error(e)                       # reads the run's options: inside the block
            failed = bad if isinstance(bad, InputError) else RuntimeError(bad)
        except (InputError, RuntimeError, FloatingPointError, OSError) as e:
            failed = e
    if failed is not None:
        # the command line's one line, without the run's frames: a notebook keeps the last error, and
        # with it every PETSc object those frames hold, past PETSc's end
        failed.__context__ = failed.__cause__ = None
        raise failed.with_traceback(None)
    return kept or None


def _plain(summary: dict) -> dict:
    """The summary as its JSON file holds it: lists, Python numbers."""
    return json.loads(json.dumps(summary, default=lambda x: x.tolist()))


def _everywhere(make, kept):
    """``make(kept)`` on rank 0, the same object on every rank."""
    from petsc4py import PETSc

    mpi = PETSc.COMM_WORLD.tompi4py()
    out = mpi.bcast(make(kept) if mpi.Get_rank() == 0 else None, root=0)
    if mpi.Get_rank() == 0:
        for w in out.summary.get("warnings", []):
            warnings.warn(f"petsc-adhesion: {w}", RuntimeWarning, stacklevel=4)
    return out


def _curve(kept: dict | None) -> Curve:
    from .output import curve_tree

    def make(k):
        res, summary = k["result"], _plain(k["summary"])
        tree = curve_tree(res, k["head"], summary)
        c, events = tree["curve"], [Event.from_record(e) for e in tree["events"]]
        pull = next((ev for ev, e in zip(events, res["events"]) if e is res["pull_off"]), None)
        return Curve(lam=c["lambda"], F=c["F"], H0=c["H0"], stable=c["stable"], events=tuple(events),
                     pull_off=pull, summary=summary)
    return _everywhere(make, kept)


def _solution(kept: dict | None) -> Solution:
    def make(k):
        res = k["result"]
        return Solution(lam=float(res["lambda"]), F=float(res["F"]), H0=float(res["H0"]),
                        F_beyond=float(res["F_beyond"]), r=np.asarray(k["head"]["grid"]["r"]), H=res["H"], P=res["P"],
                        summary=_plain(k["summary"]))
    return _everywhere(make, kept)
