"""A run of a particle population on a measured topography: ``-pop_*`` (docs/population.md).

    petsc-adhesion -adh_topography tests/data/wsxm-afm-topography.top -pop_count 200 \\
        -pop_radius_median 10e-6 -pop_radius_spread 1.3 -pop_seed 1 -phys_young1 7e10 -phys_poisson1 0.17 \\
        -phys_gamma 0.05 -phys_epsilon 4e-10 -csv pop.csv -out pop.h5 -summary pop.json -plot pop.png

As a curve's run: the options are read into the library's objects and checked before
any work (one line naming the option, exit status 2, nothing written), the library
computes (:func:`petsc_adhesion.population.compute.population`, the particles spread
over the ranks of ``mpiexec``), and rank 0 writes the files all together and the
report.  Exit status 3 (files written) where no lognormal could be fitted.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from petsc4py import PETSc

from ..errors import InputError, collective, printable
from ..io.inputs import check_input
from ..io.resultset import PLOT_FORMATS, check_targets, plot_format, written
from ..io.summary import program_record
from ..model.heights import HeightFileError
from ..model.physical import Bodies
from ..model.topography import read_topography
from ..tracing.curve import Program
from .options.checks import PETSC_GLOBAL, check_misspelled, check_petsc_values
from .options.reading import AppOptions
from .options.table import TABLE
from .optionsfile import options_files

__all__ = ["is_population", "PopulationRequest", "read", "execute", "main", "POPULATION_OPTIONS"]

#: The application options a population honours besides its own (-pop_*): the bodies but their radius, the
#: topography, the far field, its outputs.
POPULATION_OPTIONS = {"phys_young1", "phys_poisson1", "phys_young2", "phys_poisson2", "phys_gamma", "phys_hamaker",
                      "phys_hamaker_cutoff", "phys_epsilon", "adh_topography", "adh_topography_detrend",
                      "adh_topography_unit", "adh_farfield", "out", "summary", "csv", "plot"}
_OUTPUTS = ("out", "summary", "csv", "plot")
#: Why an option is not a population's.
_WHY = {"phys_radius": "the radii are -pop_radius_median or -pop_radius_file's",
        "phys_rms": "each particle's roughness is its footprint's heights",
        "adh_sigma": "each particle's roughness is its footprint's heights",
        "adh_mu": "each particle's mu is the bodies' at its radius (eq. 9)",
        "adh_roughness": "the roughness is each footprint's measured heights (the table: the Gaussian rule)",
        "adh_topography2": "a population lands on one surface's topography",
        "phys_radius2": "the particles land on a flat"}


def is_population(opts: AppOptions) -> bool:
    """Whether the options ask for a population (any -pop_ option)."""
    return any(opts.db.hasName(n) for n in TABLE if n.startswith("pop_"))


@dataclass
class PopulationRequest:
    """A population's inputs, read and checked."""

    topography: object
    bodies: Bodies
    law: object
    count: int
    seed: int
    evaluator: str
    table: object
    spread_count: int
    bins: int
    resamples: int
    trace: object
    targets: dict


def _radii(path: str) -> tuple:
    """The radii of -pop_radius_file (m), one a line, '#' comments."""
    check_input("pop_radius_file", path)
    radii = []
    with open(path, errors="replace") as f:
        for number, line in enumerate(f, 1):
            text = line.split("#")[0].strip()
            if not text:
                continue
            try:
                r = float(text)
            except ValueError:
                raise InputError(f"-pop_radius_file: line {number} of '{printable(path)}' is not a radius in m: "
                                 f"'{printable(text[:40])}'") from None
            if not (math.isfinite(r) and 0 < r <= TABLE["pop_radius_median"].hi):
                raise InputError(f"-pop_radius_file: line {number}: radius {r:g} m, expected in (0, "
                                 f"{TABLE['pop_radius_median'].hi:g}]")
            radii.append(r)
    if not radii:
        raise InputError(f"-pop_radius_file: '{printable(path)}' lists no radius")
    if len(radii) > TABLE["pop_count"].hi:
        raise InputError(f"-pop_radius_file: {len(radii)} radii, at most {TABLE['pop_count'].hi:g}")
    return tuple(radii)


def _law(opts: AppOptions):
    from ..population.sample import RadiusLaw

    median, path = opts.real("pop_radius_median"), opts.string("pop_radius_file")
    if median is not None and path is not None:
        raise InputError("-pop_radius_file: not with -pop_radius_median; the radii are a list or a lognormal")
    if path is not None:
        for name in ("pop_radius_spread", "pop_count"):
            if opts.db.hasName(name):
                raise InputError(f"-{name}: not with -pop_radius_file, whose radii are the particles")
        radii = _radii(path)
        return RadiusLaw(radii=radii), len(radii)
    if median is None:
        raise InputError("-pop_radius_median: required with a population (or -pop_radius_file), the particles' "
                         "median radius (m)")
    count = opts.int("pop_count")
    if count is None:
        raise InputError("-pop_count: required with -pop_radius_median, the number of particles")
    return RadiusLaw(median=median, spread=opts.real("pop_radius_spread")), count


def _bodies(opts: AppOptions, radius: float) -> Bodies:
    def given(n):
        return opts.db.hasName(n)
    for a, b in (("phys_young1", "phys_poisson1"), ("phys_young2", "phys_poisson2")):
        if given(a) != given(b):
            raise InputError(f"-{b if given(a) else a}: needed with -{a if given(a) else b} (eq. 2)")
    for name, what in (("phys_young1", "the particles' modulus, with -phys_poisson1"),
                       ("phys_epsilon", "the Lennard-Jones law's epsilon, m")):
        if not given(name):
            raise InputError(f"-{name}: required with a population ({what})")
    if given("phys_gamma") == given("phys_hamaker"):
        raise InputError("-phys_gamma: a population needs the work of adhesion: -phys_gamma or -phys_hamaker, "
                         "one of them")
    if given("phys_hamaker_cutoff") and not given("phys_hamaker"):
        raise InputError("-phys_hamaker_cutoff: only with -phys_hamaker")
    kw = {} if not given("phys_hamaker_cutoff") else {"hamaker_cutoff": opts.real("phys_hamaker_cutoff")}
    bodies = Bodies(radius=radius, young1=opts.real("phys_young1"), poisson1=opts.real("phys_poisson1"),
                    epsilon=opts.real("phys_epsilon"), gamma=opts.real("phys_gamma"),
                    hamaker=opts.real("phys_hamaker"), young2=opts.real("phys_young2"),
                    poisson2=opts.real("phys_poisson2"), **kw)
    if not (math.isfinite(bodies.E) and bodies.E > 0):
        raise InputError("-phys_young1: with the other moduli gives no finite positive E* (eq. 2)")
    return bodies


def read(opts: AppOptions, comm, argv: list[str]) -> PopulationRequest:
    """Read and check a population's options before any work (see the module)."""
    from ..population.evaluate import TableMissing, Trace, load_table

    check_misspelled(opts)
    check_petsc_values(opts.db)
    for name in TABLE:
        if opts.db.hasName(name) and not name.startswith("pop_") and name not in POPULATION_OPTIONS:
            why = _WHY.get(name, "a population traces its own curves, just past each pull-off")
            raise InputError(f"-{name}: not with a population (-pop_*): {why}; remove it")
    for name in opts.db.getAll():
        if name not in TABLE and name not in PETSC_GLOBAL:
            raise InputError(f"-{name}: a population's solvers take their own settings; remove it")
    path = opts.string("adh_topography")
    if path is None:
        raise InputError("-adh_topography: required with a population, the surface the particles land on")
    law, count = _law(opts)
    bodies = _bodies(opts, law.radii[0] if law.listed else law.median)
    targets = {k: opts.string(k) for k in _OUTPUTS if opts.string(k)}
    if "plot" in targets and plot_format(targets["plot"]) is None:
        raise InputError(f"-plot: expected a file name ending in {', '.join(PLOT_FORMATS)}, got "
                         f"'{printable(targets['plot'])}'")
    check_input("adh_topography", path)
    try:
        topo = read_topography(path, opts.choice("adh_topography_detrend"), opts.choice("adh_topography_unit"))
    except HeightFileError as e:
        why = str(e).replace("give the unit of its values", "give -adh_topography_unit").replace(
            "give none", "give no -adh_topography_unit")
        raise InputError(f"-adh_topography: {printable(why)}") from None
    if topo.kind != "map" or topo.pixel_size is None:
        raise InputError(f"-adh_topography: '{printable(path)}' is "
                         f"{'a profile' if topo.kind != 'map' else 'a map of no stated lateral size'}: particles "
                         f"land on a map with its size")
    evaluator = opts.choice("pop_evaluator")
    energy = opts.flag("pop_energy")
    if evaluator == "table" and opts.db.hasName("pop_energy") and energy:
        raise InputError("-pop_energy: true is not with -pop_evaluator table, whose pull-off table holds pull-offs "
                         "only (the solver gives the energy of a cycle); remove it")
    table = None
    if evaluator == "table":
        try:
            table = load_table()
        except TableMissing as e:
            raise InputError(f"-pop_evaluator: table: {e}") from None
    else:
        try:          # the model spread's rule from the table where there is one, else the solver's rule
            table = load_table()
        except TableMissing:
            table = None
    inputs = {"options_file": options_files(argv), "adh_topography": [path],
              "pop_radius_file": [opts.string("pop_radius_file") or ""]}
    if comm.getRank() == 0:
        check_targets(targets, inputs)
    return PopulationRequest(topo, bodies, law, count, opts.int("pop_seed"), evaluator, table,
                             opts.int("pop_spread_count"), opts.int("pop_bins"), opts.int("pop_bootstrap"),
                             Trace(farfield=opts.flag("adh_farfield"), energy=energy and evaluator == "solver"),
                             targets)


def execute(opts: AppOptions, argv: list[str], report: bool = True):
    """The population of the options database: (exit status, the result)."""
    from ..io.population import population_summary, report_population, write_population
    from ..population.compute import population

    comm = PETSc.COMM_WORLD
    req = collective(comm, read, opts, comm, argv)
    result = population(req.topography, req.bodies, req.law, req.count, req.seed, req.evaluator, req.table,
                        comm, req.spread_count, req.bins, req.resamples, req.trace)
    if comm.getRank() == 0:
        summary = population_summary(program_record(Program.of(comm)), opts.given(), result)
        with written(req.targets) as files:
            fmt = plot_format(req.targets["plot"]) if "plot" in req.targets else None
            write_population(result, summary, files, fmt)
            if report:
                report_population(result)
            files.commit()
    PETSc.garbage_cleanup()
    return (0 if result.complete else 3), result


def main(opts: AppOptions, argv: list[str], helping: bool = False) -> int:
    """A population of the options database; its exit status (``helping``: checked only; a study's options
    refused, as every command of one request refuses them)."""
    from .run import command_main

    return command_main(opts, argv, helping, read, execute)
