"""Application options: the one place where their defaults, ranges and help live.

Each option is read from the PETSc options database where it is used
(``opts.real("adh_mu")``); this table is what makes the value checked, its
default single and ``-help`` complete.  PETSc's own options (``-snes_*``,
``-ksp_*``, ``-pc_*``, ``-log_view`` ...) are left to PETSc; any option that
nobody used by the end of a run is reported as unknown (:func:`check_unused`).
"""
from __future__ import annotations

import ctypes
import difflib
import math
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from .grid import PAPER_EXTRA, PAPER_UNIFORM
from .model import Model

__all__ = ["InputError", "Option", "TABLE", "AppOptions", "check_unused", "petsc_error", "print_help"]


class InputError(Exception):
    """Bad user input: reported as one line, with a non-zero exit status."""


@dataclass(frozen=True)
class Option:
    name: str
    kind: str          # "real" | "int" | "choice" | "string" | "flag" | "reals"
    default: object
    help: str
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    choices: tuple = ()

    def allowed(self) -> str:
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind in ("real", "int", "reals"):
            left = "(" if self.lo_open else "["
            what = {"real": "a finite real", "int": "an integer",
                    "reals": "comma-separated finite reals"}[self.kind]
            if self.lo == -math.inf and self.hi == math.inf:
                return what
            return f"{what} in {left}{_fmt(self.lo)}, {_fmt(self.hi)}]"
        return {"string": "a file name", "flag": "true or false"}[self.kind]


def _fmt(x: float) -> str:
    return "inf" if x == math.inf else "-inf" if x == -math.inf else f"{x:g}"


_INF = math.inf
_M = Model()
TABLE = {o.name: o for o in [
    # model (paper eq. 9-14)
    Option("adh_mu", "real", _M.mu, "Tabor parameter mu (eq. 9)", 0.0, 50.0),
    Option("adh_physical", "reals", (), "R,gamma,E,epsilon in SI (m, J/m^2, Pa, m): mu from eq. (9), "
           "results also in SI", 0.0, 1e12, lo_open=True),
    Option("adh_sigma", "real", _M.sigma, "roughness: standard deviation of the heights / epsilon", 0.0, 5.0),
    Option("adh_roughness", "choice", _M.roughness, "roughness average of the pressure (eq. 14)",
           choices=("none", "hermite")),
    Option("adh_hermite_points", "int", _M.hermite_points, "points of the Gauss-Hermite rule (eq. 14)", 2, 200),
    Option("adh_rmax", "real", _M.rmax, "end r_m of the computational domain", 0.0, 1e3, lo_open=True),
    Option("adh_lambda", "real", None, "solve at this one approach lambda only (no continuation)", -1e3, 1e3),
    Option("adh_guess", "string", None, "HDF5 result whose H(r) is the initial guess of -adh_lambda"),
    Option("adh_pmat", "choice", "dense", "matrix handed to the preconditioner: the assembled Jacobian, "
           "its near-field band (AIJ), or the shell itself", choices=("dense", "band", "shell")),
    Option("adh_pmat_band", "int", 64, "half bandwidth of -adh_pmat band", 0, 10**6),
    Option("adh_pc_reuse_its", "int", 10, "keep the preconditioner while Krylov needs at most this many "
           "iterations (0: rebuild at every Newton iteration)", 0, 10**6),
    # grid
    Option("grid_type", "choice", "paper", "node set", choices=("paper", "uniform")),
    Option("grid_n", "int", 531, "number of nodes of -grid_type uniform", 3, 200000),
    Option("grid_paper_uniform", "int", PAPER_UNIFORM, "uniform nodes of -grid_type paper", 3, 200000),
    Option("grid_paper_extra", "int", PAPER_EXTRA, "elements refined by -grid_type paper", 0, 200000),
    Option("grid_paper_split", "int", 2, "parts each refined element is split into", 2, 1000),
    Option("grid_paper_refine_from", "real", 0.0, "first refined element of -grid_type paper starts here", 0.0, 1e3),
    # continuation
    Option("cont_type", "choice", "auto", "corrector: switch at |lambdadot| < 0.5 (paper), or one kind",
           choices=("auto", "natural", "arclength")),
    Option("cont_lambda_start", "real", None, "first approach (default: below the reach of the forces)", -1e3, 1e3),
    Option("cont_lambda_max", "real", None, "stop at this approach (default: past equilibrium)", -1e3, 1e3),
    Option("cont_F_max", "real", 2.0, "stop at this compressive load", -_INF, 1e6),
    Option("cont_max_steps", "int", 2000, "stop after this many accepted steps", 1, 10**7),
    Option("cont_dF_max", "real", 0.2, "largest change of the load in one step, relative above |F| = 1", 0.0, 1e6, lo_open=True),
    Option("cont_max_folds", "int", 12, "stop after this many turning points (a grid that traps the "
           "contact edge makes dozens)", 0, 10**6),
    Option("cont_ds", "real", 0.05, "first arclength step", 0.0, 1e3, lo_open=True),
    Option("cont_ds_min", "real", 1e-7, "smallest step before giving up", 0.0, 1e3, lo_open=True),
    Option("cont_ds_max", "real", 0.5, "largest step", 0.0, 1e3, lo_open=True),
    Option("cont_newton_target", "int", 5, "corrector iterations aimed at by the step control", 1, 100),
    Option("cont_max_deviation", "real", 0.2, "largest corrector distance from the predictor, per unit step "
           "(bounds the step by the curvature)", 0.0, 10.0, lo_open=True),
    Option("cont_at_lambda", "reals", (), "approaches at which to record the state (e.g. 0 for Fig. 12)", -1e3, 1e3),
    Option("cont_event_tol", "real", 1e-10, "event location tolerance in lambda", 0.0, 1.0, lo_open=True),
    Option("cont_monitor", "flag", False, "one line a continuation step"),
    Option("cont_error_estimate", "flag", False, "trace again on every other node and give each event "
           "its discretization error (Richardson) and the load truncated beyond r_m"),
    # output
    Option("out", "string", None, "HDF5 result file"),
    Option("summary", "string", None, "JSON summary file"),
    Option("profiles", "flag", False, "store H(r) and P(r) at every event"),
    Option("plot", "string", None, "PNG of the load-approach curve (and the profiles with -profiles)"),
]}


class AppOptions:
    """Typed, checked reads of :data:`TABLE` options from the PETSc database."""

    def __init__(self, db: PETSc.Options | None = None):
        self.db = db or PETSc.Options()

    def _raw(self, name: str) -> str | None:
        if name not in TABLE:
            raise KeyError(name)
        if not self.db.hasName(name):
            return None
        return self.db.getString(name, "")

    def _bad(self, o: Option, raw: str) -> InputError:
        return InputError(f"-{o.name}: expected {o.allowed()}, got '{raw}'")

    def _number(self, o: Option, raw: str, cast) -> float:
        try:
            x = cast(raw)
        except ValueError:
            raise self._bad(o, raw) from None
        if not math.isfinite(x) or x > o.hi or x < o.lo or (o.lo_open and x == o.lo):
            raise self._bad(o, raw)
        return x

    def real(self, name: str):
        o, raw = TABLE[name], self._raw(name)
        return o.default if raw is None else self._number(o, raw, float)

    def int(self, name: str):
        o, raw = TABLE[name], self._raw(name)
        return o.default if raw is None else int(self._number(o, raw, _strict_int))

    def reals(self, name: str) -> tuple:
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        return tuple(self._number(o, s.strip(), float) for s in raw.split(",") if s.strip())

    def choice(self, name: str) -> str:
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        if raw not in o.choices:
            raise self._bad(o, raw)
        return raw

    def string(self, name: str):
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        if not raw:
            raise self._bad(o, raw)
        return raw

    def flag(self, name: str) -> bool:
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        if raw.lower() in ("", "1", "true", "yes", "on"):
            return True
        if raw.lower() in ("0", "false", "no", "off"):
            return False
        raise self._bad(o, raw)


def _strict_int(s: str) -> int:
    x = float(s)
    if x != int(x):
        raise ValueError(s)
    return int(x)


def _petsc_int():
    return ctypes.c_int64 if np.dtype(PETSc.IntType).itemsize == 8 else ctypes.c_int32


def unused_options() -> list[str]:
    """Names of the options in the database that no object has read.

    petsc4py has no binding of PetscOptionsLeftGet, so it is called through
    ctypes on the symbols that petsc4py's extension module already links.
    """
    lib = ctypes.CDLL(PETSc.__file__)
    argtypes = [ctypes.c_void_p, ctypes.POINTER(_petsc_int()),
                ctypes.POINTER(ctypes.POINTER(ctypes.c_char_p)),
                ctypes.POINTER(ctypes.POINTER(ctypes.c_char_p))]
    get, restore = lib.PetscOptionsLeftGet, lib.PetscOptionsLeftRestore
    get.argtypes = restore.argtypes = argtypes
    n = _petsc_int()()
    names = ctypes.POINTER(ctypes.c_char_p)()
    values = ctypes.POINTER(ctypes.c_char_p)()
    if get(None, ctypes.byref(n), ctypes.byref(names), ctypes.byref(values)):
        raise RuntimeError("PetscOptionsLeftGet failed")
    left = [names[i].decode() for i in range(n.value)]
    restore(None, ctypes.byref(n), ctypes.byref(names), ctypes.byref(values))
    return left


#: PETSc error codes that mean a bad option value: unknown type, wrong argument, out of range.
_INPUT_CODES = (86, 62, 63)


def petsc_error(err: PETSc.Error) -> InputError | None:
    """The InputError behind a PETSc error raised by a bad option value, if it is one.

    PETSc keeps the specific message of its last error (PetscErrorMessage); the
    option is found as the one whose value the message quotes.
    """
    if err.ierr not in _INPUT_CODES:
        return None
    lib = ctypes.CDLL(PETSc.__file__)
    get = lib.PetscErrorMessage
    get.argtypes = [ctypes.c_int, ctypes.POINTER(ctypes.c_char_p), ctypes.POINTER(ctypes.c_char_p)]
    text, specific = ctypes.c_char_p(), ctypes.c_char_p()
    get(err.ierr, ctypes.byref(text), ctypes.byref(specific))
    detail = (specific.value or text.value or b"").decode(errors="replace").strip()
    words = set(detail.replace("'", " ").replace('"', " ").split())
    named = [k for k, v in PETSc.Options().getAll().items() if v and v in words]
    where = f"-{named[0]} {PETSc.Options().getString(named[0])}: " if named else ""
    return InputError(f"{where}{detail}")


def check_unused(judged=lambda name: True) -> None:
    """Raise :class:`InputError` for an option that nobody read.

    ``judged`` picks the options to judge: the application's own, which are
    all read up front, before any work; or all of them at the end of a run,
    when PETSc has read its own.
    """
    left = [n for n in unused_options() if judged(n)]
    if left:
        name = left[0]
        if name in _PETSC_COMMON:
            raise InputError(f"-{name}: not used by the solvers this run configures "
                             f"(e.g. a sub-PC option without a block PC)")
        near = difflib.get_close_matches(name, list(TABLE) + _PETSC_COMMON, n=1)
        hint = f" (did you mean -{near[0]}?)" if near else ""
        raise InputError(f"-{name}: unknown option{hint}; -help lists the options")


# A few PETSc options users type, for the did-you-mean hint only.
_PETSC_COMMON = ["snes_monitor", "ksp_monitor", "snes_view", "ksp_view", "log_view",
                 "snes_rtol", "snes_atol", "snes_max_it", "ksp_rtol", "ksp_type", "pc_type",
                 "snes_lag_preconditioner", "options_file", "help", "snes_converged_reason",
                 "ksp_converged_reason", "pc_factor_mat_solver_type", "sub_pc_type"]


def print_help(out) -> None:
    """Write the application options, as PETSc's -help writes its own."""
    out.write("petsc-adhesion application options (PETSc's follow):\n")
    for o in TABLE.values():
        default = "" if o.default in (None, ()) else f" <{o.default}>"
        out.write(f"  -{o.name}{default}: {o.help}; {o.allowed()}\n")
