"""Application options: their table (help, ranges, checks) and their reading into objects.

The defaults belong to the objects the options configure (``Model``, the grid,
the continuation ``Settings``, the solvers), and this table reads them from
there: the numerical modules never import the command line.  PETSc's own
options (``-snes_*``, ``-ksp_*``, ``-pc_*``, ``-log_view`` ...) are left to
PETSc, solver by solver through their prefixes; any option that nobody used
by the end of a run is reported as unknown (:func:`check_unused`).
"""
from __future__ import annotations

import difflib
import math
import os
import re
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from . import capi, checkpoint, grid, preconditioning, progress
from .errors import InputError
from .files import printable
from .adaptive import RMAX
from .continuation import ARCLENGTH_PREFIX, CORRECTORS, NATURAL_PREFIX, Settings
from .events import EVENT_TOL
from .model import Model
from .physical import HAMAKER_CUTOFF, Bodies
from .roughness import DISTRIBUTIONS, HeightFileError, Measured, Weibull, read_heights
from .solver import PC_REUSE_ITS

__all__ = ["InputError", "Option", "TABLE", "AppOptions", "check_unused", "petsc_error", "print_help",
           "HELP_GROUPS", "help_groups", "shown_default",
           "read_model", "read_grid", "read_settings", "read_physical", "read_guess", "check_memory",
           "check_consistency", "check_petsc_values", "collective", "smallest_domain", "petsc_names",
           "F_MAX", "SOLVER_PREFIXES", "PETSC_GLOBAL"]


@dataclass(frozen=True)
class Option:
    """One application option: its kind, default, help and accepted values."""

    name: str
    kind: str          # "real" | "int" | "choice" | "string" | "flag" | "reals"
    default: object
    help: str
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    choices: tuple = ()
    hi_open: bool = False

    def allowed(self) -> str:
        """What the option accepts, in words."""
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "choices":
            return "comma-separated names from " + ", ".join(self.choices)
        if self.kind in ("real", "int", "reals", "sweep"):
            left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
            what = {"real": "a finite real", "int": "an integer", "reals": "comma-separated finite reals",
                    "sweep": "comma-separated reals or ranges lo:hi:n[:log]"}[self.kind]
            if self.lo == -math.inf and self.hi == math.inf:
                return what
            return f"{what} in {left}{_fmt(self.lo)}, {_fmt(self.hi)}{right}"
        return {"string": "a file name", "flag": "true or false"}[self.kind]


def _fmt(x: float) -> str:
    return "inf" if x == math.inf else "-inf" if x == -math.inf else f"{x:g}"


#: -adh_roughness values averaged by a Gauss-Hermite rule (pressure.RULES without "none").
RULES_HERMITE = ("hermite",)
#: The load at which a curve stops by default: past equilibrium, into compression.
F_MAX = 2.0
#: Options prefixes of the three solvers: (prefix, what it solves).
SOLVER_PREFIXES = (("", "the fixed-approach solve (-adh_lambda)"),
                   (NATURAL_PREFIX, "the continuation's natural corrector and first point"),
                   (ARCLENGTH_PREFIX, "its arclength corrector and tangents"))

_INF = math.inf
_S = Settings
TABLE = {o.name: o for o in [
    # model (paper eq. 9-14)
    Option("adh_mu", "real", Model.mu, "Tabor parameter mu (eq. 9)", 0.0, 50.0),
    Option("adh_sigma", "real", Model.sigma, "roughness: standard deviation of the heights / epsilon", 0.0, 5.0),
    Option("adh_roughness", "choice", Model.roughness, "height distribution averaged over (eq. 7, 10): the "
           "paper's Gaussian by its Gauss-Hermite rule (eq. 14), whose rule is the model; Gaussian truncated at "
           "the highest asperity; skewed (reversed Weibull); measured heights; none (smooth)",
           choices=("none", *RULES_HERMITE, *DISTRIBUTIONS)),
    Option("adh_hermite_points", "int", Model.hermite_points, "points of the Gauss-Hermite rule (eq. 14)", 2, 200),
    Option("adh_roughness_cutoff", "real", Model.roughness_cutoff, "truncated_gaussian: the highest asperity, "
           "in standard deviations (-adh_sigma) of the untruncated Gaussian", 0.0, 10.0, lo_open=True),
    Option("adh_roughness_skewness", "real", Model.roughness_skewness, "weibull: skewness of the heights "
           "(-2: exponential valleys, 0.5: the most symmetric bounded)", *Weibull.SKEWNESS),
    Option("adh_roughness_file", "string", None, "measured: heights, one a line in units of epsilon; a table "
           "(Gwyddion ASCII export, '# Value units: m'), .gsf or .npy height map; it sets sigma itself"),
    Option("adh_roughness_unit", "real", None, "measured: metres per value of a file that states no unit "
           "(needs -phys_epsilon)", 0.0, 1.0, lo_open=True),
    Option("adh_quadrature_points", "int", Model.quadrature_points, "truncated_gaussian, weibull: points of "
           "the quadrature's moving part at the wall (its fixed panels get 2/3 as many)", 2, 400),
    Option("adh_rmax", "real", None, f"end r_m of the computational domain (default: {RMAX:g} on grids that "
           f"follow the contact edge, {Model.rmax:g} as in the paper otherwise)", 0.0, 1e3, lo_open=True),
    Option("adh_farfield", "flag", Model.farfield, "add the rigid sphere's attraction beyond r_m to the load: "
           "the half-infinite model (false: the paper's model truncated at r_m)"),
    Option("adh_lambda", "real", None, "solve at this one approach lambda only (no continuation)", -1e3, 1e3),
    Option("adh_guess", "string", None, "HDF5 result whose H(r) is the initial guess of -adh_lambda"),
    Option("adh_pmat", "choice", "dense", "matrix handed to the preconditioner: the assembled Jacobian, "
           "its near-field band (AIJ), or the shell itself", choices=preconditioning.KINDS),
    Option("adh_pmat_band", "int", preconditioning.BAND, "half bandwidth of -adh_pmat band", 0, 10**6),
    Option("adh_pc_reuse_its", "int", PC_REUSE_ITS, "keep the preconditioner while Krylov needs at most this many "
           "iterations (0: rebuild at every Newton iteration)", 0, 10**6),
    # grid
    # physical inputs (SI): mu from eq. (9), sigma = rms / epsilon, results also in nN, nm, MPa
    Option("phys_radius", "real", None, "radius R1 of the sphere (m); with -phys_young1, -phys_poisson1, "
           "-phys_gamma (or -phys_hamaker) and -phys_epsilon it sets mu by eq. (9), and results are reported also "
           "in nN, nm and MPa", 0.0, 1.0, lo_open=True),
    Option("phys_radius2", "real", None, "radius R2 of a second sphere (m): R = R1 R2 / (R1 + R2) (default: a "
           "flat)", 0.0, 1.0, lo_open=True),
    Option("phys_young1", "real", None, "Young's modulus E1 of the sphere (Pa)", 0.0, 1e13, lo_open=True),
    Option("phys_poisson1", "real", None, "Poisson's ratio nu1 of the sphere", -1.0, 0.5, lo_open=True),
    Option("phys_young2", "real", None, "Young's modulus E2 of the flat (or second sphere) (Pa); eq. (2) "
           "(default: rigid)", 0.0, 1e13, lo_open=True),
    Option("phys_poisson2", "real", None, "Poisson's ratio nu2 of the flat (with -phys_young2)", -1.0, 0.5,
           lo_open=True),
    Option("phys_gamma", "real", None, "work of adhesion gamma (J/m^2)", 0.0, 100.0, lo_open=True),
    Option("phys_hamaker", "real", None, "Hamaker constant A (J), instead of -phys_gamma: gamma = A / (12 pi D0^2)",
           0.0, 1e-16, lo_open=True),
    Option("phys_hamaker_cutoff", "real", None, f"cut-off distance D0 of -phys_hamaker (m; default "
           f"{HAMAKER_CUTOFF:g}, Israelachvili's)", 0.0, 1e-8, lo_open=True),
    Option("phys_epsilon", "real", None, "equilibrium spacing epsilon of the Lennard-Jones law (m)", 0.0, 1e-8,
           lo_open=True),
    Option("phys_rms", "real", None, "rms roughness of the combined surfaces (m): sigma = rms / epsilon", 0.0,
           1e-6),
    Option("grid_type", "choice", "edge", "node set: graded about the contact edge and following it along "
           "the curve; the paper's; uniform", choices=("edge", "paper", "uniform")),
    Option("grid_n", "int", grid.PAPER_UNIFORM + grid.PAPER_EXTRA, "number of nodes of -grid_type uniform",
           3, 200000),
    Option("grid_paper_uniform", "int", grid.PAPER_UNIFORM, "uniform nodes of -grid_type paper", 3, 200000),
    Option("grid_paper_extra", "int", grid.PAPER_EXTRA, "elements refined by -grid_type paper", 0, 200000),
    Option("grid_paper_split", "int", grid.PAPER_SPLIT, "parts each refined element is split into", 2, 1000),
    Option("grid_paper_refine_from", "real", 0.0, "first refined element of -grid_type paper starts here", 0.0, 1e3),
    # continuation
    Option("cont_type", "choice", _S.corrector, f"corrector: switch at |lambdadot| < {_S.switch:g} (paper), "
           "or one kind", choices=CORRECTORS),
    Option("cont_lambda_start", "real", None, "first approach (default: below the reach of the forces)", -1e3, 1e3),
    Option("cont_lambda_max", "real", None, "stop at this approach (default: past equilibrium)", -1e3, 1e3),
    Option("cont_F_max", "real", F_MAX, "stop at this compressive load", -_INF, 1e6),
    Option("cont_max_steps", "int", _S.max_steps, "stop after this many accepted steps", 1, 10**7),
    Option("cont_dF_max", "real", _S.observable_step, "largest change of the load in one step, relative above "
           "|F| = 1", 0.0, 1e6, lo_open=True),
    Option("cont_max_folds", "int", _S.max_folds, "stop after more than this many turning points (a grid that "
           "traps the contact edge makes dozens)", 0, 10**6),
    Option("cont_ds", "real", _S.ds, "first arclength step", 0.0, 1e3, lo_open=True),
    Option("cont_ds_min", "real", _S.ds_min, "smallest step before giving up", 0.0, 1e3, lo_open=True),
    Option("cont_ds_max", "real", _S.ds_max, "largest step", 0.0, 1e3, lo_open=True),
    Option("cont_newton_target", "int", _S.newton_target, "corrector iterations aimed at by the step control",
           1, 100),
    Option("cont_max_deviation", "real", _S.max_deviation, "largest corrector distance from the predictor, per "
           "unit step (bounds the step by the curvature)", 0.0, 10.0, lo_open=True),
    Option("cont_at_lambda", "reals", (), "approaches at which to record the state (e.g. 0 for Fig. 12)", -1e3, 1e3),
    Option("cont_event_tol", "real", EVENT_TOL, "event location tolerance in lambda", 0.0, 1.0, lo_open=True),
    Option("cont_monitor", "flag", _S.monitor, "one line a continuation step"),
    Option("cont_checkpoint", "string", None, "save the curve's state (a study's: its finished cases) into "
           "this file as it goes, for -cont_restart (default: .NAME.checkpoint beside -out, else -summary or "
           "-plot; the file restarted from; none: no checkpoint); a finished run removes it"),
    Option("cont_checkpoint_interval", "real", checkpoint.INTERVAL, "least seconds between two checkpoint saves "
           "(0: before every step)", 0.0, 1e6),
    Option("cont_restart", "string", None, "go on from this checkpoint of an interrupted run with the same "
           "options (output and printing options aside): the same steps, events and error bars; a study runs "
           "only the cases not in it"),
    Option("cont_error_estimate", "flag", True, "give every event its best value and error bar: located again "
           "on its grid's coarser (or finer) nested levels, Richardson-extrapolated"),
    Option("target_error", "real", None, "refine each event's levels until its error bars (lambda and F) are "
           "below this", 0.0, 1.0, lo_open=True),
    # studies: a sweep over cases (petsc_adhesion.sweep)
    Option("study_mu", "sweep", (), "study: the Tabor parameters of its cases (eq. 9)", 0.0, 50.0),
    Option("study_sigma", "sweep", (), "study: the roughness sigma of its cases", 0.0, 5.0),
    Option("study_option", "string", None, "study: a further real or integer option swept over -study_values "
           "(without the dash, e.g. phys_radius, adh_hermite_points, grid_n)"),
    Option("study_values", "sweep", (), "study: the values of -study_option", -1e12, 1e12),
    Option("study_compute", "choice", "curve", "study: what each case computes: the whole curve; the events up to "
           "equilibrium; only the pull-off and the equilibrium after it; only the turning points; the critical "
           "roughness sigma_c(mu) of each -study_mu and the critical mu_c(sigma) of each -study_sigma",
           choices=("curve", "events", "pull_off", "folds", "critical")),
    Option("study_profiles", "choices", (), "study: the event kinds whose H(r), P(r) each case keeps",
           choices=("snap_on", "snap_off", "F_min", "F_max", "equilibrium", "lambda")),
    Option("study_ranks", "int", 1, "study: MPI ranks per case; the cases are spread over the groups of this "
           "many ranks, the longest first", 1, 10**6),
    Option("study_plot", "choice", "curves", "study: what -plot draws: load-approach curves; one panel per case "
           "about its turning points; the profiles of -study_profiles; pull-off against mu; reduction of the "
           "pull-off against sigma; the boundary of hysteresis (sigma_c, mu_c: the only one, and the default, with "
           "-study_compute critical)",
           choices=("curves", "folds", "profiles", "pull_off", "reduction", "critical")),
    # output
    Option("out", "string", None, "HDF5 result file"),
    Option("summary", "string", None, "JSON summary file"),
    Option("profiles", "flag", False, "store H(r) and P(r) at every event"),
    Option("plot", "string", None, "PNG of the load-approach curve (and the profiles with -profiles)"),
    Option("progress", "flag", None, "a line on stderr every -progress_interval seconds: lambda reached, steps, "
           "events, time elapsed and an estimate of the time left (default: when stderr is a terminal)"),
    Option("progress_interval", "real", progress.INTERVAL, "least seconds between two progress lines", 0.0, 1e6,
           lo_open=True),
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
        if not math.isfinite(x) or x > o.hi or x < o.lo or (o.lo_open and x == o.lo) or (o.hi_open and x == o.hi):
            raise self._bad(o, raw)
        return x

    def real(self, name: str):
        """The value of a real option, checked against its range, or its default."""
        o, raw = TABLE[name], self._raw(name)
        return o.default if raw is None else self._number(o, raw, _strict_float)

    def int(self, name: str):
        """The value of an integer option, checked against its range, or its default."""
        o, raw = TABLE[name], self._raw(name)
        return o.default if raw is None else int(self._number(o, raw, _strict_int))

    def reals(self, name: str) -> tuple:
        """The values of a comma-separated list of reals, each checked, or the default."""
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        return tuple(self._number(o, s.strip(), _strict_float) for s in raw.split(",") if s.strip())

    def sweep(self, name: str) -> tuple:
        """The values of a sweep: comma-separated reals or ranges ``lo:hi:n`` (n evenly spaced values)
        and ``lo:hi:n:log`` (n geometrically spaced, lo > 0), each checked, in the order given.

        >>> AppOptions._range("0.01:1:3:log"), AppOptions._range("0:1:5")
        ((0.01, 0.1, 1.0), (0.0, 0.25, 0.5, 0.75, 1.0))
        """
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        out = []
        for item in (s.strip() for s in raw.split(",")):
            try:
                values = self._range(item) if ":" in item else (_strict_float(item),)
            except ValueError:
                raise self._bad(o, raw) from None
            out += [self._number(o, repr(x), float) for x in values]
        if not out:
            raise self._bad(o, raw)
        return tuple(out)

    @staticmethod
    def _range(item: str) -> tuple:
        parts = item.split(":")
        if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "log"):
            raise ValueError(item)
        lo, hi, n = _strict_float(parts[0]), _strict_float(parts[1]), _strict_int(parts[2])
        if n < 2 or not lo < hi or (len(parts) == 4 and lo <= 0):
            raise ValueError(item)
        xs = np.geomspace(lo, hi, n) if len(parts) == 4 else np.linspace(lo, hi, n)
        return tuple(float(x) for x in np.round(xs, 12))

    def choices(self, name: str) -> tuple:
        """A comma-separated subset of an option's choices, or its default."""
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        picked = tuple(s.strip() for s in raw.split(","))
        if not all(p in o.choices for p in picked):
            raise self._bad(o, raw)
        return picked

    def choice(self, name: str) -> str:
        """The value of a choice option, one of its choices, or its default."""
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        if raw not in o.choices:
            raise self._bad(o, raw)
        return raw

    def string(self, name: str):
        """The value of a string option (non-empty), or its default."""
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        if not raw:
            raise self._bad(o, raw)
        return raw

    def flag(self, name: str) -> bool:
        """The value of a flag (bare, or true/false, yes/no, on/off, 1/0), or its default."""
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        if raw.lower() in ("", "1", "true", "yes", "on"):
            return True
        if raw.lower() in ("0", "false", "no", "off"):
            return False
        raise self._bad(o, raw)

    def given(self) -> dict:
        """Every option in the database as given: name -> value string (None for a bare flag).

        petsc4py's getAll splits values at blanks; each value is read again whole,
        which marks every option used: only after the checks for unused options.
        """
        return {k: (None if v is None else self.db.getString(k, "")) for k, v in self.db.getAll().items()}

    def read_all(self) -> None:
        """Read (and so check) every application option now, before any work."""
        for name, o in TABLE.items():
            getattr(self, o.kind)(name)


#: A number as users write it: no Python extras (1_0, 0x10, whitespace), inf and nan named to be refused.
_NUMBER = re.compile(r"[+-]?((\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|inf|infinity|nan)", re.I)


def _strict_float(s: str) -> float:
    if not _NUMBER.fullmatch(s.strip()):
        raise ValueError(s)
    return float(s)


def _strict_int(s: str) -> int:
    x = _strict_float(s)
    if not math.isfinite(x) or x != int(x):
        raise ValueError(s)
    return int(x)


# -- options into objects ------------------------------------------------------------
#: The options of :class:`~petsc_adhesion.physical.Bodies`, by field.
PHYSICAL = {f: f"phys_{f}" for f in ("radius", "radius2", "young1", "poisson1", "young2", "poisson2", "gamma",
                                     "hamaker", "hamaker_cutoff", "epsilon", "rms")}


def read_physical(opts: AppOptions) -> Bodies | None:
    """The bodies of the -phys_ options (SI), or None without them; one line for a missing or
    contradicting input."""
    given = {f: opts.real(name) for f, name in PHYSICAL.items() if opts.db.hasName(name)}
    if not given:
        return None
    for f in ("radius", "young1", "poisson1", "epsilon"):
        if f not in given:
            raise InputError(f"-{PHYSICAL[f]}: required with the other -phys_ options (radius, young1, poisson1, "
                             f"epsilon, and gamma or hamaker)")
    if ("gamma" in given) == ("hamaker" in given):
        raise InputError("-phys_gamma: not with -phys_hamaker; give one of them (the work of adhesion)"
                         if "gamma" in given else "-phys_gamma: required, or -phys_hamaker (the work of adhesion)")
    if ("young2" in given) != ("poisson2" in given):
        raise InputError(f"-{PHYSICAL['poisson2' if 'young2' in given else 'young2']}: needed with "
                         f"-{PHYSICAL['young2' if 'young2' in given else 'poisson2']} (eq. 2)")
    if "hamaker_cutoff" in given and "hamaker" not in given:
        raise InputError("-phys_hamaker_cutoff: only with -phys_hamaker")
    for name, why in (("adh_mu", "the -phys_ options set mu by eq. (9)"),
                      *((("adh_sigma", "-phys_rms sets sigma = rms / epsilon"),) if "rms" in given else ())):
        if opts.db.hasName(name):
            raise InputError(f"-{name}: not with the -phys_ options: {why}")
    if "rms" in given and opts.choice("adh_roughness") == "measured":
        raise InputError("-phys_rms: not with -adh_roughness measured, whose heights set sigma")
    bodies = Bodies(**given)
    if not 0 <= bodies.mu <= TABLE["adh_mu"].hi:
        raise InputError(f"-phys_radius: with the other -phys_ options gives mu = {bodies.mu:.3g} by eq. (9), "
                         f"outside [0, {TABLE['adh_mu'].hi:g}]")
    if bodies.sigma is not None and not bodies.sigma <= TABLE["adh_sigma"].hi:
        raise InputError(f"-phys_rms: gives sigma = rms / epsilon = {bodies.sigma:.3g}, above "
                         f"{TABLE['adh_sigma'].hi:g}")
    return bodies


def read_model(opts: AppOptions) -> Model:
    """The model of -adh_mu (or the -phys_ options), -adh_sigma (or -phys_rms), -adh_rmax and the roughness
    rule."""
    phys = read_physical(opts)
    mu = phys.mu if phys else opts.real("adh_mu")
    rmax = opts.real("adh_rmax")
    if rmax is None:
        rmax = RMAX if opts.choice("grid_type") == "edge" else Model.rmax
    rough, sigma, heights = opts.choice("adh_roughness"), opts.real("adh_sigma"), None
    if phys and phys.sigma is not None:
        sigma = phys.sigma
    if rough == "measured":
        heights = read_measured(opts, phys.epsilon if phys else None)
        sigma = Measured(heights).rms
    model = Model(mu=mu, sigma=sigma, rmax=rmax, roughness=rough, hermite_points=opts.int("adh_hermite_points"),
                  roughness_cutoff=opts.real("adh_roughness_cutoff"),
                  roughness_skewness=opts.real("adh_roughness_skewness"),
                  quadrature_points=opts.int("adh_quadrature_points"), heights=heights,
                  farfield=opts.flag("adh_farfield"))
    if model.roughness == "none" and model.sigma > 0:
        raise InputError(f"-adh_sigma: must be 0 with -adh_roughness none, got {model.sigma:g}")
    return model


def read_measured(opts: AppOptions, epsilon: float | None) -> np.ndarray:
    """The heights of -adh_roughness_file in units of epsilon (:func:`~.roughness.read_heights`)."""
    path = opts.string("adh_roughness_file")
    if path is None:
        raise InputError("-adh_roughness_file: required with -adh_roughness measured: a file of heights")
    if opts.db.hasName("adh_sigma"):
        raise InputError("-adh_sigma: not with -adh_roughness measured, whose heights set it")
    try:
        heights = read_heights(path, epsilon, opts.real("adh_roughness_unit"))
        Measured(heights)
    except HeightFileError as e:
        why = str(e).replace("need epsilon (> 0, in metres) for units of epsilon", "need -phys_epsilon")
        raise InputError(f"-adh_roughness_file: {printable(why)}") from None
    if not np.sqrt(np.mean((heights - heights.mean()) ** 2)) <= TABLE["adh_sigma"].hi:
        raise InputError(f"-adh_roughness_file: heights of rms above {TABLE['adh_sigma'].hi:g} epsilon")
    return heights


def read_grid(opts: AppOptions, model: Model) -> np.ndarray | None:
    """The nodes of -grid_type on [0, r_m]; None for grids that follow the contact edge."""
    kind = opts.choice("grid_type")
    if kind == "edge":
        return None
    nu, extra = opts.int("grid_paper_uniform"), opts.int("grid_paper_extra")
    start, split = opts.real("grid_paper_refine_from"), opts.int("grid_paper_split")
    if kind == "uniform":
        return grid.uniform(opts.int("grid_n"), model.rmax)
    if extra > nu - 1:
        raise InputError(f"-grid_paper_extra: expected an integer in [0, {nu - 1}], got {extra}")
    if start >= model.rmax:
        raise InputError(f"-grid_paper_refine_from: expected a real in [0, {model.rmax:g}), got {start:g}")
    return grid.paper(model.rmax, nu, extra, start, split)


def read_settings(opts: AppOptions) -> Settings:
    """The continuation's step control and stops; the load F is the observable watched."""
    lam_max = opts.real("cont_lambda_max")
    return Settings(corrector=opts.choice("cont_type"), ds=opts.real("cont_ds"), ds_min=opts.real("cont_ds_min"),
                    ds_max=opts.real("cont_ds_max"), newton_target=opts.int("cont_newton_target"),
                    max_deviation=opts.real("cont_max_deviation"), max_folds=opts.int("cont_max_folds"),
                    observable="F", observable_step=opts.real("cont_dF_max"), observable_max=opts.real("cont_F_max"),
                    p_max=math.inf if lam_max is None else lam_max, max_steps=opts.int("cont_max_steps"),
                    pc_reuse_its=opts.int("adh_pc_reuse_its"), monitor=opts.flag("cont_monitor"))


#: Options of one roughness model: name -> the -adh_roughness values that use it.
ROUGHNESS_OPTIONS = {"adh_hermite_points": RULES_HERMITE, "adh_roughness_cutoff": ("truncated_gaussian",),
                     "adh_roughness_skewness": ("weibull",), "adh_quadrature_points": ("truncated_gaussian", "weibull"),
                     "adh_roughness_file": ("measured",), "adh_roughness_unit": ("measured",)}

#: The attraction beyond r_m may carry at most this share of the DMT pull-off at contact.
DOMAIN_SHARE = 0.05


def smallest_domain(mu: float) -> float:
    """The smallest r_m that holds the contact: the JKR contact radius at zero load, and the
    radius beyond which the rigid sphere's attraction carries at most DOMAIN_SHARE of F = -1."""
    from scipy.optimize import brentq

    from .reference import jkr_zero_load, load_beyond

    reach = brentq(lambda r: abs(load_beyond(r, 0.0)) - DOMAIN_SHARE, 0.1, 100.0)
    return max(reach, jkr_zero_load(mu)[0] if mu > 0 else 0.0)


def _given(opts: AppOptions, names) -> list[str]:
    return [n for n in names if opts.db.hasName(n)]


def check_consistency(opts: AppOptions, model: Model) -> None:
    """Refuse contradictions and options the chosen run ignores, before any work."""
    fixed = opts.real("adh_lambda") is not None
    ignored = []
    if fixed:
        ignored += [(n, "applies to a curve, not with -adh_lambda") for n in
                    _given(opts, [n for n in TABLE if n.startswith(("cont_", "progress"))] + ["profiles", "plot",
                                                                                     "target_error"])]
    elif not opts.flag("cont_error_estimate"):
        ignored += [(n, "refines error bars, which -cont_error_estimate false turns off") for n in
                    _given(opts, ["target_error"])]
    kind = opts.choice("grid_type")
    if kind == "paper":
        ignored += [(n, "is a -grid_type uniform option") for n in _given(opts, ["grid_n"])]
    else:
        ignored += [(n, "is a -grid_type paper option") for n in _given(opts, [n for n in TABLE
                                                                                if n.startswith("grid_paper_")])]
    for name, kinds in ROUGHNESS_OPTIONS.items():
        if opts.db.hasName(name):
            if model.roughness not in kinds:
                ignored.append((name, f"applies to -adh_roughness {' or '.join(kinds)}"))
            elif model.sigma == 0:
                ignored.append((name, "sets the roughness average, not used at -adh_sigma 0"))
    if opts.choice("adh_pmat") != "band":
        ignored += [(n, "applies to -adh_pmat band") for n in _given(opts, ["adh_pmat_band"])]
    if ignored:
        name, why = ignored[0]
        raise InputError(f"-{name}: {why}; remove it")
    start, stop = opts.real("cont_lambda_start"), opts.real("cont_lambda_max")
    if start is not None and stop is not None and start >= stop:
        raise InputError(f"-cont_lambda_start: {start:g} is not below -cont_lambda_max {stop:g}")
    ds, lo, hi = opts.real("cont_ds"), opts.real("cont_ds_min"), opts.real("cont_ds_max")
    if lo > hi:
        raise InputError(f"-cont_ds_min: {lo:g} is above -cont_ds_max {hi:g}")
    if not lo <= ds <= hi:
        raise InputError(f"-cont_ds: {ds:g} is outside [-cont_ds_min, -cont_ds_max] = [{lo:g}, {hi:g}]")
    for t in opts.reals("cont_at_lambda"):
        if (start is not None and t < start) or (stop is not None and t > stop):
            raise InputError(f"-cont_at_lambda: {t:g} is outside the traced range "
                             f"[{'-inf' if start is None else f'{start:g}'}, {'inf' if stop is None else f'{stop:g}'}]")
    if opts.db.hasName("adh_rmax") and model.rmax < smallest_domain(model.mu):
        raise InputError(f"-adh_rmax: {model.rmax:g} leaves out part of the contact at mu = {model.mu:g}: "
                         f"expected at least {smallest_domain(model.mu):.3g} (the JKR contact radius, or the "
                         f"reach of {DOMAIN_SHARE:.0%} of the attraction)")


def collective(comm, check, *args):
    """Run ``check(*args)`` on every rank; an InputError on any rank is raised on all (rank order).

    Keeps a check that fails on one rank only (a file part, a path) from
    leaving the others waiting in a collective call.
    """
    try:
        out, why = check(*args), None
    except InputError as e:
        out, why = None, str(e)
    whys = comm.tompi4py().allgather(why)
    first = next((w for w in whys if w), None)
    if first:
        raise InputError(first)
    return out


def check_memory(n: int, pmat: str, curve: bool, ranks: int) -> None:
    """Refuse a grid whose dense matrices cannot fit: A, and G_H and the bordered
    matrix when assembled densely, N^2 doubles each, split over the ranks."""
    import os

    dense = 1 + (pmat == "dense") * (1 + curve)
    need = 8.0 * n * n * dense / ranks
    have = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    if need > 0.8 * have:
        raise InputError(f"-grid_n: N = {n} needs {need / 2**30:.0f} GiB a rank for {dense} dense N x N "
                         f"matrices, this machine has {have / 2**30:.0f} GiB; use fewer nodes, more ranks, "
                         f"or -adh_pmat band")


def _first_line(e: BaseException) -> str:
    text = str(e).strip()
    return text.splitlines()[0] if text else type(e).__name__


def read_guess(problem, lam: float, path: str | None) -> PETSc.Vec:
    """The initial H of a fixed-approach solve: the rigid state, or H(r) of -adh_guess interpolated."""
    H = problem.rigid(lam, problem.create_vec())
    if path is None:
        return H
    shown = printable(path)
    if not os.path.isfile(path):
        raise InputError(f"-adh_guess: '{shown}' is not a regular file")
    try:
        import h5py
        with h5py.File(path, "r") as f:
            r0, h0 = f["grid/r"][()], f["solution/H"][()]
    except (OSError, KeyError, TypeError) as e:
        raise InputError(f"-adh_guess: cannot read grid/r and solution/H from '{shown}' "
                         f"({printable(_first_line(e))}); give the -out file of a fixed-approach solve") from None
    if not (np.issubdtype(r0.dtype, np.floating) and np.issubdtype(h0.dtype, np.floating)
            and r0.ndim == h0.ndim == 1 and r0.size == h0.size >= 2):
        raise InputError(f"-adh_guess: grid/r and solution/H in '{shown}' are not two real vectors of one length")
    if not (np.all(np.isfinite(r0)) and np.all(np.diff(r0) > 0)):
        raise InputError(f"-adh_guess: grid/r in '{shown}' is not finite and increasing")
    h = np.interp(problem.r[problem.lo:problem.hi], r0, h0)
    if not np.all(np.isfinite(h)) or np.any(h <= problem.law.wall):
        raise InputError(f"-adh_guess: H in '{shown}' is not finite and above the wall {problem.law.wall:g}")
    H.setArray(h)
    return H


# -- PETSc's errors and options ------------------------------------------------------
#: PETSc error codes that mean a bad option value: unknown type, wrong argument, out of range, no support.
_INPUT_CODES = (56, 62, 63, 86, 92)
#: Words of option names too common to say which option a PETSc message is about.
_GENERIC = {"type", "snes", "ksp", "view", "monitor", "options", "file", "grid", "cont", "adh"}


def petsc_error(err: PETSc.Error) -> InputError | str:
    """What a PETSc error means for the user: the option behind it (an InputError), or one line.

    PETSc keeps the specific message of its last error (PetscErrorMessage); the
    option is the one whose value the message quotes, else one whose name's
    words it uses ("Restart must be positive": -ksp_gmres_restart).
    """
    detail = capi.error_message(err.ierr) or f"PETSc error {err.ierr}"
    # the application's options are checked before PETSc sees them; a number quoted is no one's name
    given = {k: v for k, v in AppOptions().given().items() if k not in TABLE}
    words = set(detail.lower().replace("'", " ").replace('"', " ").replace(",", " ").replace(":", " ").split())
    by_value = [k for k, v in given.items() if v and v.lower() in words and not _NUMBER.fullmatch(v.strip())]
    by_name = [k for k in given if any(len(w) >= 3 and w not in _GENERIC and w in words for w in k.lower().split("_"))]
    named = by_value or by_name
    if named:
        value = f" {given[named[0]]}" if given[named[0]] else ""
        return InputError(f"-{named[0]}{value}: {detail}")
    if err.ierr in _INPUT_CODES:
        return InputError(detail)
    return f"PETSc error {err.ierr}: {detail}"


#: Options PETSc itself reads at start-up or at the end of every program: never unknown.
PETSC_GLOBAL = ("options_left", "options_view", "get_total_flops", "checkstack", "nox", "viewer_binary_skip_info",
                "options_suppress_deprecated_warnings", "options_monitor", "memory_view", "malloc_view",
                "malloc_dump", "objects_dump", "log_view", "log_view_memory", "help", "version", "skip_petscrc",
                "options_file", "info", "malloc_debug", "malloc_test", "fp_trap", "on_error_abort",
                "no_signal_handler", "history", "log_trace", "log_all", "log_exclude", "log_sync")
_SOLVER_OPTIONS = ("snes_", "ksp_", "pc_", "sub_", "mat_")
#: PETSc option names from PETSc's own -help (see :func:`petsc_names`), for the did-you-mean hint.
_NAMES_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "petsc_options.txt")


def petsc_names() -> list[str]:
    """PETSc's option names (without prefix) that this program's solvers can read.

    The list is PETSc's own -help output over the solver configurations the
    program offers, made by ``python -m petsc_adhesion.options``.
    """
    with open(_NAMES_FILE) as f:
        return [ln.strip() for ln in f if ln.strip() and not ln.startswith("#")]


def _prefixes() -> tuple:
    return tuple(p for p, _ in SOLVER_PREFIXES)


def check_unused(judged=lambda name: True) -> None:
    """Raise :class:`InputError` for an option that nobody read.

    ``judged`` picks the options to judge: the application's own, which are
    all read up front, before any work; or all of them once the solvers are
    set up, when PETSc has read its own.
    """
    left = [n for n in capi.options_left() if judged(n) and n not in PETSC_GLOBAL]
    if not left:
        return
    name = left[0]
    bare = next((name[len(p):] for p in _prefixes() if p and name.startswith(p)), name)
    names = petsc_names()
    if bare in names and bare.startswith(_SOLVER_OPTIONS):
        where = ", ".join(f"-{p}{bare} for {what}" for p, what in SOLVER_PREFIXES)
        block = " (and a sub-PC option needs a block PC)" if bare.startswith("sub_") else ""
        raise InputError(f"-{name}: not used by the solvers this run configures{block}; use {where}")
    candidates = list(TABLE) + [p + n for p in _prefixes() for n in names]
    near = difflib.get_close_matches(name, candidates, n=1, cutoff=0.75)
    hint = f" (did you mean -{near[0]}?)" if near else ""
    raise InputError(f"-{name}: unknown option{hint}; -help lists the options")


#: PETSc's solver options whose values PETSc accepts out of range or takes as "default"
#: without a word: name -> (kind, lowest, highest, lowest open, highest open).
_PETSC_RANGES = {
    "snes_rtol": ("real", 0.0, 1.0, False, True), "snes_atol": ("real", 0.0, math.inf, False, False),
    "snes_stol": ("real", 0.0, 1.0, False, True), "snes_max_it": ("int", 1, 10**9, False, False),
    "snes_max_funcs": ("int", 1, 10**12, False, False), "ksp_rtol": ("real", 0.0, 1.0, False, True),
    "ksp_atol": ("real", 0.0, math.inf, False, False), "ksp_max_it": ("int", 1, 10**9, False, False),
    "ksp_divtol": ("real", 1.0, math.inf, True, False), "snes_linesearch_damping": ("real", 0.0, 1.0, True, False),
    "snes_linesearch_max_it": ("int", 1, 10**6, False, False), "ksp_gmres_restart": ("int", 1, 10**6, False, False),
}


def check_petsc_values(db: PETSc.Options | None = None) -> None:
    """Raise :class:`InputError` for a solver tolerance or count out of its range, under any prefix,
    or a Python solver type (it needs a context this program does not give)."""
    db = db or PETSc.Options()
    for name, value in db.getAll().items():        # getAll does not mark options used, getString would
        if name.endswith("_type") and value == "python":
            raise InputError(f"-{name} python: a Python type needs its context, which this program does not "
                             f"set; choose one of PETSc's own types")
    for prefix in _prefixes():
        for name, (kind, lo, hi, lo_open, hi_open) in _PETSC_RANGES.items():
            if not db.hasName(prefix + name):
                continue
            o = Option(prefix + name, kind, None, "", lo, hi, lo_open, hi_open=hi_open)
            AppOptions(db)._number(o, db.getString(prefix + name, ""), _strict_float if kind == "real" else _strict_int)


#: The groups of -help and docs/usage.md: (title, the name prefixes of its options); the last takes the rest.
HELP_GROUPS = (("model (eq. 9-14) and its solver", ("adh_",)), ("physical units", ("phys_",)), ("grid", ("grid_",)),
               ("continuation, events and error bars", ("cont_", "target_")), ("studies of many cases", ("study_",)),
               ("output and progress", ()))


def help_groups() -> list[tuple[str, list[Option]]]:
    """The options of :data:`TABLE` in their :data:`HELP_GROUPS`, each in table order; empty groups left out."""
    def group(name: str) -> int:
        return next((i for i, (_, prefixes) in enumerate(HELP_GROUPS) if name.startswith(prefixes)),
                    len(HELP_GROUPS) - 1)
    return [(title, members) for i, (title, _) in enumerate(HELP_GROUPS)
            if (members := [o for o in TABLE.values() if group(o.name) == i])]


def shown_default(o: Option) -> str:
    """The default of ``o`` as -help and docs/usage.md show it ("" when the option has none: the help says)."""
    if o.default in (None, ()):
        return ""
    if isinstance(o.default, bool):
        return "true" if o.default else "false"
    if isinstance(o.default, tuple):
        return ",".join(map(str, o.default))
    return str(o.default)


def print_help(out) -> None:
    """Write the application options in their groups and the solvers' prefixes, as PETSc's -help writes its own."""
    out.write("petsc-adhesion application options (PETSc's follow):\n")
    for title, members in help_groups():
        out.write(f" {title}:\n")
        for o in members:
            default = f" <{shown_default(o)}>" if shown_default(o) else ""
            out.write(f"  -{o.name}{default}: {o.help}; {o.allowed()}\n")
    out.write("Solvers, each tuned by PETSc's options under its own prefix (-{prefix}snes_*, -{prefix}ksp_*, "
              "-{prefix}pc_*):\n")
    for prefix, what in SOLVER_PREFIXES:
        out.write(f"  -{prefix}snes_...: {what}\n")


def _write_petsc_names() -> None:
    """Collect PETSc's option names from its -help over the solver configurations offered here."""
    import re
    import subprocess
    import sys

    names = set()
    base = [sys.executable, "-m", "petsc_adhesion", "-help", "-adh_lambda", "-2", "-grid_type", "uniform",
            "-grid_n", "21"]
    variants = [("-adh_pmat", kind, "-pc_type", pc) for kind in ("dense", "band")
                for pc in ("lu", "ilu", "bjacobi", "asm", "jacobi", "none", "hypre", "gamg", "cholesky", "icc")]
    variants += [("-ksp_type", k) for k in ("fgmres", "bcgs", "cg", "lgmres", "gcr")]
    variants += [("-snes_linesearch_type", k) for k in ("basic", "l2", "cp")]
    variants += [("-adh_pmat", "band", "-pc_type", "lu", "-pc_factor_mat_solver_type", "mumps")]
    for extra in variants:
        proc = subprocess.run(base + list(extra), capture_output=True, text=True)
        names |= set(re.findall(r"^\s+-([a-z][a-z0-9_]*)", proc.stdout, re.M))
    names -= set(TABLE)
    names |= {"sub_" + n for n in names if n.startswith(("ksp_", "pc_"))}
    with open(_NAMES_FILE, "w") as f:
        f.write(f"# PETSc {'%d.%d.%d' % PETSc.Sys.getVersion()} option names from its -help over the solver "
                "configurations petsc-adhesion offers;\n# made by: python -m petsc_adhesion.options\n")
        f.write("\n".join(sorted(names)) + "\n")


if __name__ == "__main__":
    _write_petsc_names()
