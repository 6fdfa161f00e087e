"""Options into the library's typed objects: the model, the grid and solver choices, the continuation settings
and what a curve reports, each checked as it is read (one line naming the option for a bad value)."""
from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
from petsc4py import PETSc

from ...errors import InputError, printable
from ...io.inputs import check_input
from ...model.heights import HeightFileError, read_heights
from ...model.parameters import Model, PhysicalBodies
from ...model.parameters import tabor
from ...model.physical import Bodies
from ...model.roughness import SMALLEST_RMS, Lognormal, Measured
from ...model.topography import gap_heights, read_topography
from ...core.bordered import ARCLENGTH_PREFIX
from ...core.continuation import NATURAL_PREFIX
from ...core.fold import FOLD_PREFIX
from ...core.newton import PetscSettings
from ...tracing.legs import default_trigger, figure_step, rigid_pull_off
from ...tracing.trace import CurveRequest, GridChoice, SolverChoice, curve_settings, step_scale
from .plausible import slip
from .table import TABLE, Option

__all__ = ["AppOptions", "Given", "PHYSICAL", "read_physical", "read_model", "read_measured", "read_topographies", "read_grid", "read_solver",
           "read_petsc", "ROLE_PREFIXES", "SOLVER_OPTIONS",
           "read_request", "read_settings", "read_spring", "read_trigger", "read_model_spread"]


#: The smallest positive Tabor parameter: below it the coupling mu^(3/2) of eq. (12) and the JKR scales
#: underflow, and the curve is the rigid sphere's to double precision (mu = 0 is the rigid sphere itself).
MU_SMALLEST = 1e-12
#: The longest option value read: petsc4py's PETSc.Options.getString fills a buffer of 1024 bytes and cuts a
#: longer value there without a word.
MAX_VALUE = 1023
#: The most values one option of a study may sweep (a study of that many curves takes days already).
MAX_SWEEP = 10_000


class Given:
    """Options given as values (name without dash -> value string, None for a bare flag), read as PETSc's
    options database is read, without one: the Python API's keywords.  ``left()``: those not read."""

    def __init__(self, values: dict):
        self._values = {k.lower(): v for k, v in values.items()}     # PETSc's names ignore case
        self._read: set[str] = set()

    def hasName(self, name: str) -> bool:
        return name.lower() in self._values

    def getString(self, name: str, default: str = "") -> str:
        name = name.lower()
        if name not in self._values:
            return default
        self._read.add(name)
        v = self._values[name]
        return "" if v is None else v

    def getAll(self) -> dict:
        return dict(self._values)

    def left(self) -> list[str]:
        """The names not read (as PetscOptionsLeftGet of a database)."""
        return [k for k in self._values if k not in self._read]


class AppOptions:
    """Typed, checked reads of :data:`TABLE` options from the PETSc database (or a :class:`Given`)."""

    def __init__(self, db: PETSc.Options | Given | None = None):
        self.db = db or PETSc.Options()

    def _raw(self, name: str) -> str | None:
        if name not in TABLE:
            raise KeyError(name)
        if not self.db.hasName(name):
            return None
        raw = self.db.getString(name, "")
        if len(raw) >= MAX_VALUE:        # petsc4py reads a value into 1024 bytes: a longer one comes back cut
            hint = " (a study's values as ranges lo:hi:n)" if TABLE[name].kind == "sweep" else ""
            raise InputError(f"-{name}: a value of {MAX_VALUE} characters or more, of which PETSc reads only the first "
                             f"{MAX_VALUE}: give a shorter one{hint}")
        return raw

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
        items = raw.count(",") + 1
        if items > MAX_SWEEP:                          # counted before anything is made of them
            raise InputError(f"-{name}: {items} values; a sweep takes at most {MAX_SWEEP}")
        out = []
        for item in (s.strip() for s in raw.split(",")):
            try:
                values = self._range(item) if ":" in item else (_strict_float(item),)
            except ValueError:
                raise self._bad(o, raw) from None
            except OverflowError:
                raise InputError(f"-{name}: the range '{item}' has more than {MAX_SWEEP} values; a sweep takes "
                                 f"at most {MAX_SWEEP}") from None
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
        if n > MAX_SWEEP:
            raise OverflowError(item)
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

    def rules(self, name: str):
        """The roughness laws of a list law:parameter (:func:`~.model_spread.parse_rules`), or the default."""
        o, raw = TABLE[name], self._raw(name)
        if raw is None:
            return o.default
        from ...tracing.model_spread import parse_rules     # given: a rough run's spread, which loads it anyway

        try:
            return parse_rules(raw)
        except ValueError as why:
            raise InputError(f"-{name}: {printable(str(why))}") from None

    def given(self) -> dict:
        """Every option in the database as given: name -> value string (None for a bare flag).

        petsc4py's getAll splits values at blanks; each value is read again whole,
        which marks every option used: only after the checks for unused options.
        """
        return {k: (None if v is None else self.db.getString(k, "")) for k, v in self.db.getAll().items()}

    def values(self) -> dict:
        """Every application option's value, as ``repr`` of what it reads (defaults included)."""
        return {name: repr(getattr(self, o.kind)(name)) for name, o in TABLE.items()}

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
#: The options of :class:`~petsc_adhesion.model.physical.Bodies`, by field.
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
    for name, value, why in (("phys_radius2" if "radius2" in given else "phys_radius", lambda: bodies.R,
                              "the combined radius"),
                             ("phys_young2" if "young2" in given else "phys_young1", lambda: bodies.E,
                              "the combined modulus of eq. (2)"),
                             ("phys_hamaker_cutoff" if "hamaker" in given else "phys_gamma",
                              lambda: bodies.work_of_adhesion, "the work of adhesion")):
        if not 0 < _finite(value) < math.inf:
            raise InputError(f"-{name}: with the other -phys_ options gives no finite positive {why} in double "
                             f"precision (the inputs under- or overflow); give the bodies' values in SI")
    mu = _finite(lambda: bodies.mu)
    # each input's share of log mu (eq. 9), against a 1 um polymer sphere: the option that moved mu most is named
    shares = {"phys_radius": math.log(bodies.R / 1e-6) / 3,
              ("phys_gamma" if "gamma" in given else "phys_hamaker"): 2 * math.log(bodies.work_of_adhesion / 0.05) / 3,
              ("phys_young2" if bodies.young1 is not None and bodies.young2 is not None
               and bodies.young2 < bodies.young1 else "phys_young1"):
                  -2 * math.log(bodies.E / 1e9) / 3,
              "phys_epsilon": -math.log(bodies.epsilon / 4e-10)}
    logmu = math.log(tabor(1e-6, 0.05, 1e9, 4e-10)) + sum(shares.values())
    if not mu <= TABLE["adh_mu"].hi:       # an overflow of eq. (9) too: its log says by how much
        name = max(shares, key=shares.__getitem__)
        raise InputError(f"-{name}: with the other -phys_ options gives mu = {math.exp(min(logmu, 700)):.3g} by "
                         f"eq. (9), outside [0, {TABLE['adh_mu'].hi:g}]{_slip(opts, name)}")
    if mu < MU_SMALLEST:
        name = min(shares, key=shares.__getitem__)
        raise InputError(f"-{name}: with the other -phys_ options gives mu = {mu:.3g} by eq. (9), below "
                         f"{MU_SMALLEST:g}: a rigid sphere to double precision; use -adh_mu 0{_slip(opts, name)}")
    if bodies.sigma is not None and not bodies.sigma <= TABLE["adh_sigma"].hi:
        raise InputError(f"-phys_rms: gives sigma = rms / epsilon = {bodies.sigma:.3g}, above "
                         f"{TABLE['adh_sigma'].hi:g}")
    return bodies


def _slip(opts: AppOptions, name: str) -> str:
    """The likely slip of units of option ``name`` outside what the field measures, as the end of a
    refusal ("" inside it)."""
    line = slip(name, opts.real(name))
    return "" if line is None else f"; {line.split(': ', 1)[1]}"


def _finite(value) -> float:
    """``value()``, or nan where it divides by zero or overflows (underflowing inputs)."""
    try:
        return float(value())
    except (ZeroDivisionError, OverflowError, ValueError):
        return math.nan


def read_model(opts: AppOptions) -> Model:
    """The model of -adh_mu (or the -phys_ options), -adh_sigma (or -phys_rms), -adh_rmax and the roughness
    rule."""
    phys = read_physical(opts)
    mu = phys.mu if phys else opts.real("adh_mu")
    if 0 < mu < MU_SMALLEST:
        raise InputError(f"-adh_mu: expected 0 (a rigid sphere) or a real in [{MU_SMALLEST:g}, {TABLE['adh_mu'].hi:g}], "
                         f"got {mu:g}: below it mu^(3/2) underflows, and the sphere is rigid to double precision")
    rmax = opts.real("adh_rmax")
    if rmax is None:
        rmax = GridChoice(opts.choice("grid_type")).default_rmax
    rough, sigma, heights, weights = opts.choice("adh_roughness"), opts.real("adh_sigma"), None, None
    if phys and phys.sigma is not None:
        sigma = phys.sigma
    topography: tuple = ()
    if rough == "measured" and (opts.db.hasName("adh_topography") or opts.db.hasName("adh_topography2")):
        heights, weights, topography = read_topographies(opts, phys.epsilon if phys else None)
        if heights is None:           # a flat surface: the smooth sphere, the record saying why
            rough, sigma = "none", 0.0
        else:
            sigma = Measured(heights, weights=weights).rms
    elif rough == "measured":
        heights = read_measured(opts, phys.epsilon if phys else None)
        sigma = Measured(heights).rms
    model = Model(mu=mu, sigma=sigma, rmax=rmax, roughness=rough, hermite_points=opts.int("adh_hermite_points"),
                  roughness_cutoff=opts.real("adh_roughness_cutoff"),
                  roughness_skewness=opts.real("adh_roughness_skewness"),
                  lognormal_skewness=opts.real("adh_lognormal_skewness"),
                  quadrature_points=opts.int("adh_quadrature_points"), heights=heights, height_weights=weights,
                  topography=topography,
                  farfield=opts.flag("adh_farfield"), bodies=phys)
    if model.roughness == "none" and model.sigma > 0:
        raise InputError(f"-adh_sigma: must be 0 with -adh_roughness none, got {model.sigma:g}")
    if model.roughness == Lognormal.name and model.sigma > 0 and not Lognormal(sigma, model.lognormal_skewness).wall_pressure > 0:
        raise InputError(f"-adh_lognormal_skewness: {model.lognormal_skewness:g} at sigma {model.sigma:g} puts the highest "
                         f"asperity {Lognormal(sigma, model.lognormal_skewness).top:.3g} epsilon up with no weight near it: "
                         "the heights repel nowhere (P at the wall <= 0); give a more negative skewness or a smaller rms")
    return model


def read_measured(opts: AppOptions, epsilon: float | None) -> np.ndarray:
    """The heights of -adh_roughness_file in units of epsilon (:func:`~.roughness.read_heights`)."""
    path = opts.string("adh_roughness_file")
    for name in ("adh_topography_detrend", "adh_topography_unit"):
        if opts.db.hasName(name):
            raise InputError(f"-{name}: applies to -adh_topography, not to -adh_roughness_file")
    if path is None:
        raise InputError("-adh_roughness_file: required with -adh_roughness measured: a file of heights")
    if opts.db.hasName("adh_sigma"):
        raise InputError("-adh_sigma: not with -adh_roughness measured, whose heights set it")
    check_input("adh_roughness_file", path)
    try:
        heights = read_heights(path, epsilon, opts.real("adh_roughness_unit"))
        Measured(heights)
    except HeightFileError as e:
        why = str(e).replace("need epsilon (> 0, in metres) for units of epsilon", "need -phys_epsilon")
        raise InputError(f"-adh_roughness_file: {printable(why)}") from None
    if not np.sqrt(np.mean((heights - heights.mean()) ** 2)) <= TABLE["adh_sigma"].hi:
        raise InputError(f"-adh_roughness_file: heights of rms above {TABLE['adh_sigma'].hi:g} epsilon")
    return heights


def read_topographies(opts: AppOptions, epsilon: float | None) -> tuple:
    """The gap's heights in units of epsilon from -adh_topography (and -adh_topography2), their weights (None:
    equal) and the :class:`~petsc_adhesion.model.topography.Topography` of each; the heights None for a flat gap (rms below
    :data:`~petsc_adhesion.model.roughness.SMALLEST_RMS` epsilon: the smooth sphere)."""
    first, second = opts.string("adh_topography"), opts.string("adh_topography2")
    if first is None:
        raise InputError("-adh_topography2: the second surface's, only with -adh_topography (the first's)")
    for name in ("adh_roughness_file", "adh_roughness_unit", "adh_sigma"):
        if opts.db.hasName(name):
            raise InputError(f"-{name}: not with -adh_topography, whose heights set the roughness")
    if epsilon is None:
        raise InputError("-adh_topography: heights in metres need -phys_epsilon (with the other -phys_ options) to "
                         "become sigma in units of epsilon")
    surfaces = []
    for name, path in (("adh_topography", first), ("adh_topography2", second)):
        if path is None:
            continue
        check_input(name, path)
        try:
            surfaces.append(read_topography(path, opts.choice("adh_topography_detrend"),
                                            opts.choice("adh_topography_unit")))
        except HeightFileError as e:
            why = str(e).replace("give the unit of its values", "give -adh_topography_unit").replace(
                "give none", "give no -adh_topography_unit")
            raise InputError(f"-{name}: {printable(why)}") from None
    heights, weights = gap_heights(tuple(surfaces), epsilon)
    w = np.full(heights.size, 1 / heights.size) if weights is None else weights
    rms = float(np.sqrt(w @ (heights - w @ heights) ** 2))
    if rms < SMALLEST_RMS:
        return None, None, tuple(surfaces)
    if not rms <= TABLE["adh_sigma"].hi:
        raise InputError(f"-adh_topography: heights of rms {rms:.3g} epsilon, above {TABLE['adh_sigma'].hi:g}")
    return heights, weights, tuple(surfaces)


def read_grid(opts: AppOptions, model: Model) -> GridChoice:
    """The grid of -grid_type and its options, checked against the domain [0, r_m] of ``model``."""
    kind = opts.choice("grid_type")
    choice = GridChoice(kind, n=opts.int("grid_n"), paper_uniform=opts.int("grid_paper_uniform"),
                        paper_extra=opts.int("grid_paper_extra"), paper_split=opts.int("grid_paper_split"),
                        paper_refine_from=opts.real("grid_paper_refine_from"))
    if kind == "paper":
        nu, extra, start = choice.paper_uniform, choice.paper_extra, choice.paper_refine_from
        if extra > nu - 1:
            raise InputError(f"-grid_paper_extra: expected an integer in [0, {nu - 1}], got {extra}")
        assert model.rmax is not None, "read_model gives the model its domain"
        if start >= model.rmax:
            raise InputError(f"-grid_paper_refine_from: expected a real in [0, {model.rmax:g}), got {start:g}")
    return choice


#: The prefixes of the solvers' roles, as the command line gives their options (SolverChoice's fields).
ROLE_PREFIXES = {"natural": NATURAL_PREFIX, "arclength": ARCLENGTH_PREFIX, "fixed": "", "fold": FOLD_PREFIX}
#: The beginnings of the options of a solver's PETSc objects (its SNES, KSP, PC, a block PC's, matrices).
SOLVER_OPTIONS = ("snes_", "ksp_", "pc_", "sub_", "mat_")
#: PetscSettings' fields read from their options (without prefix), with how each value is read.
_TYPED = {"snes_rtol": "real", "snes_atol": "real", "snes_stol": "real", "snes_max_it": "int",
          "snes_linesearch_type": "name", "ksp_type": "name", "ksp_rtol": "real", "ksp_atol": "real",
          "ksp_max_it": "int", "pc_type": "name", "snes_monitor": "flag", "ksp_monitor": "flag"}
_FIELD = {"snes_linesearch_type": "linesearch"}


def read_petsc(opts: AppOptions, prefix: str) -> PetscSettings:
    """The :class:`~petsc_adhesion.core.newton.PetscSettings` of the solver whose options begin with ``prefix``
    (``nat_``, ``arc_``, ``fold_``, none for the fixed-approach solve): its SNES, KSP, PC and matrix options in
    the database, each marked read here.  An option no solver reads (misspelt, or for a PC not chosen) reaches
    the solver all the same and is left unread there (:func:`~.checks.check_unused` names it)."""
    others = tuple(p for p in ROLE_PREFIXES.values() if p and p != prefix)
    kw: dict[str, Any] = {}
    extra: dict[str, str | None] = {}
    for name in opts.db.getAll():
        bare = name[len(prefix):]
        if not name.startswith(prefix) or name in TABLE or (not prefix and name.startswith(others)) \
                or not bare.startswith(SOLVER_OPTIONS):
            continue
        raw = opts.db.getString(name, "")
        kind = _TYPED.get(bare)
        field_name = _FIELD.get(bare, bare)
        try:
            if kind == "real":
                kw[field_name] = _strict_float(raw)
            elif kind == "int":
                kw[field_name] = _strict_int(raw)
            elif kind == "name":
                kw[field_name] = raw
            elif kind == "flag" and raw == "":
                kw[field_name] = True
            else:                                   # a monitor's viewer, and every other option
                extra[bare] = raw if raw != "" else None
        except ValueError:
            raise InputError(f"-{name}: expected a {'real' if kind == 'real' else 'integer'}, got '{raw}'") from None
    try:
        return PetscSettings(**kw, options=extra)
    except ValueError as e:
        field_name = str(e).split(":", 1)[0]
        option = next((k for k in _TYPED if _FIELD.get(k, k) == field_name), field_name)
        raise InputError(f"-{prefix}{option}: {str(e).split(': ', 1)[1]}") from None


def read_solver(opts: AppOptions) -> SolverChoice:
    """What every solver's preconditioner is built from (-adh_pmat, -adh_pmat_band), how long it is kept, and
    the PETSc settings of the solvers this run makes (:func:`read_petsc`): a curve's correctors (-nat_, -arc_),
    or the fixed-approach solve (no prefix) with -adh_lambda."""
    roles = ("natural", "arclength") if opts.real("adh_lambda") is None else ("fixed",)
    return SolverChoice(pmat=opts.choice("adh_pmat"), band=opts.int("adh_pmat_band"),
                        pc_reuse_its=opts.int("adh_pc_reuse_its"),
                        **{role: read_petsc(opts, ROLE_PREFIXES[role]) for role in roles})


def read_spring(opts: AppOptions, bodies: PhysicalBodies | None) -> float | None:
    """The stiffness K of the spring the approach is driven through (-afm_spring, or -phys_spring with the
    bodies: K = k epsilon / (2 pi R gamma)), or None for a rigid machine."""
    K, k = opts.real("afm_spring"), opts.real("phys_spring")
    if K is not None and k is not None:
        raise InputError("-phys_spring: not with -afm_spring; give one of them (the spring's stiffness)")
    if k is None:
        return K
    if bodies is None:
        raise InputError("-phys_spring: needs the bodies' -phys_ options (radius, young1, poisson1, gamma or "
                         "hamaker, epsilon) to make K = k epsilon / (2 pi R gamma); or give -afm_spring K")
    K = _finite(lambda: bodies.spring_stiffness(k))
    if not 0 < K <= TABLE["afm_spring"].hi:
        raise InputError(f"-phys_spring: gives K = k epsilon / (2 pi R gamma) = {K:.3g}, outside "
                         f"(0, {TABLE['afm_spring'].hi:g}]")
    return K


def read_request(opts: AppOptions, kinds: tuple | None = None, profiles: bool = False,
                 bodies: PhysicalBodies | None = None) -> CurveRequest:
    """What a curve reports (-cont_lambda_start, -cont_at_lambda, -cont_event_tol, -cont_error_estimate,
    -target_error, -profiles, the spring of -afm_spring or -phys_spring with the ``bodies``); ``kinds`` and
    ``profiles`` as a study's case asks (behind a spring its jumps are reported with any kinds: they are
    the turning points and the pull-off the cantilever sees)."""
    spring = read_spring(opts, bodies)
    if spring is not None and kinds is not None:
        kinds = tuple(kinds) + ("jump_in", "jump_off")
    return CurveRequest(lambda_start=opts.real("cont_lambda_start"), at_lambda=opts.reals("cont_at_lambda"),
                        event_tol=opts.real("cont_event_tol"), error_bars=opts.flag("cont_error_estimate"),
                        target_error=opts.real("target_error"), profiles=profiles or opts.flag("profiles"),
                        kinds=kinds, spring=spring)


def read_trigger(opts: AppOptions, model: Model) -> float | None:
    """The load the approach ends at behind a spring, an instrument's trigger (-afm_trigger in 2 pi R gamma,
    or -phys_trigger in N with the bodies), or None where -cont_F_max stops the curve: by default, with a
    spring and physical inputs and no -cont_F_max, :func:`~petsc_adhesion.tracing.legs.default_trigger`
    (3 times the rigid sphere's pull-off).  One line for a contradiction."""
    T, t = opts.real("afm_trigger"), opts.real("phys_trigger")
    if T is not None and t is not None:
        raise InputError("-phys_trigger: not with -afm_trigger; give one of them (the trigger force)")
    name = "phys_trigger" if t is not None else "afm_trigger"
    stop_given = opts.db.hasName("cont_F_max")
    spring = read_spring(opts, model.bodies)
    if T is None and t is None:
        return default_trigger(model)[0] if spring is not None and model.bodies is not None and not stop_given \
            else None
    if stop_given:
        raise InputError(f"-cont_F_max: not with -{name}; the trigger ends the approach (give one of them)")
    if spring is None:
        raise InputError(f"-{name}: needs a spring (-afm_spring or -phys_spring): a trigger ends an instrument's "
                         "approach; without one, -cont_F_max stops the curve")
    if t is not None:
        bodies = model.bodies
        if bodies is None:
            raise InputError("-phys_trigger: needs the bodies' -phys_ options (radius, young1, poisson1, gamma or "
                             "hamaker, epsilon) to make the force in units of 2 pi R gamma; or give -afm_trigger")
        T = _finite(lambda: t / bodies.scales()["force_N"])
        if not 0 < T <= TABLE["afm_trigger"].hi:
            raise InputError(f"-phys_trigger: gives the trigger F = {T:.3g} x 2 pi R gamma, outside "
                             f"(0, {TABLE['afm_trigger'].hi:g}]")
    return T


def read_settings(opts: AppOptions, model: Model | None = None):
    """The continuation's step control and stops; the load F is the observable watched; the step lengths
    in units of ``model``'s :func:`~petsc_adhesion.tracing.trace.step_scale` (1 without a model).  Behind a
    spring with a trigger (:func:`read_trigger`) the curve stops there, and its steps of the load are also at
    most :func:`~petsc_adhesion.tracing.legs.figure_step` (50 between the rigid sphere's pull-off and the
    trigger), so that the legs bend smoothly however large -cont_dF_max."""
    lam_max = opts.real("cont_lambda_max")
    trigger = None if model is None else read_trigger(opts, model)
    stop, dF = opts.real("cont_F_max"), opts.real("cont_dF_max")
    label = ""
    if trigger is not None:
        assert model is not None, "a trigger is read with its model"
        stop, dF = trigger, min(dF, figure_step(trigger, rigid_pull_off(model)))
        label = next((f"the trigger -{n} {opts.string(n)}" for n in ("phys_trigger", "afm_trigger") if opts.db.hasName(n)), "the default trigger, 3 times the rigid sphere's pull-off")
    return curve_settings(1.0 if model is None else step_scale(model), corrector=opts.choice("cont_type"), ds=opts.real("cont_ds"), ds_min=opts.real("cont_ds_min"),
                          ds_max=opts.real("cont_ds_max"), newton_target=opts.int("cont_newton_target"),
                          max_deviation=opts.real("cont_max_deviation"), max_folds=opts.int("cont_max_folds"),
                          observable_step=dF, observable_bend=opts.real("cont_dF_bend"), observable_max=stop, observable_max_label=label,
                          p_max=math.inf if lam_max is None else lam_max, max_steps=opts.int("cont_max_steps"),
                          pc_reuse_its=opts.int("adh_pc_reuse_its"), monitor=opts.flag("cont_monitor"))


def read_model_spread(opts: AppOptions, model: Model) -> tuple | None:
    """The roughness laws ``model``'s curve is traced again under for its model spread (-adh_model_spread,
    -adh_model_spread_rules; :func:`~petsc_adhesion.tracing.model_spread.model_spread`), or None for none: by
    default every rough model has one, a smooth one none."""
    wanted, rules = opts.flag("adh_model_spread"), opts.rules("adh_model_spread_rules")
    rough = model.roughness != "none" and model.sigma > 0
    if wanted is False:
        if rules is not None:
            raise InputError("-adh_model_spread_rules: not with -adh_model_spread false, which computes no spread")
        return None
    if not rough:
        if wanted or rules is not None:
            name = "adh_model_spread" if wanted else "adh_model_spread_rules"
            raise InputError(f"-{name}: a smooth surface (sigma = 0) has no roughness law to vary")
        return None
    # here, not at the top: a smooth run need not load the spread's module (docs/performance.md)
    from ...tracing.model_spread import Rule, default_rules

    if rules is not None and Rule.of(model) in rules:
        raise InputError(f"-adh_model_spread_rules: {Rule.of(model).label} is the model's own law, not an "
                         "alternative to it")
    return default_rules(model) if rules is None else rules
