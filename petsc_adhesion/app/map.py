"""A run that fits a force map: ``-fit_map SOURCE`` (docs/maps.md).

    petsc-adhesion -fit_map cells.jpk-force-map -phys_radius 20e-9 -phys_epsilon 0.3e-9 -out map.h5 \\
        -csv map.csv -plot map.png
    mpiexec -n 4 petsc-adhesion -fit_map curves/ -fit_map_shape 8,8 ... -out map.h5

As ``-fit_curve``'s run: the options read into typed objects and checked before any work (one line naming
the option, exit status 2, nothing written), the same options of the bodies, the instrument and the fit
(:func:`petsc_adhesion.app.fit._curve_choice`'s), and the library fits
(:func:`~petsc_adhesion.maps.fit.fit_map`: the curves dealt to the ranks).  Rank 0 keeps a journal of the
fitted pixels beside the output (``OUT.journal``, -out's or else -csv's), a line per pixel as each round
ends: a map killed and run again with the same options takes up its pixels and fits the rest, and gives the
same files as one never interrupted (tests/test_map.py); a journal of other options or another source is
refused in one line.  Once the map is fitted rank 0 writes its files all together (an earlier result
replaced whole or not at all) and removes the journal.  Exit status 0 when every pixel's fit holds, 3 when
any is flagged (its reason in the table).
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
from dataclasses import dataclass, replace

from petsc4py import PETSc

from ..errors import InputError, collective, printable
from ..fitting.data import CurveFileError, NeedsInstrument
from ..fitting.results import FitChoice, Spring
from ..io.inputs import check_input
from ..io.map import Journal, JournalError, map_tree, pixel_fields, report_map, write_map_csv, write_map_h5
from ..io.resultset import PLOT_FORMATS, check_targets, plot_format, written
from ..io.summary import program_record
from ..maps.fit import MapProgress, fit_map
from ..maps.result import Pixel
from ..maps.source import MapEntry, MapSource, MapSourceError, ShapeError, open_map
from ..model.parameters import Model
from ..model.physical import Bodies
from ..tracing.curve import Program
from ..tracing.trace import GridChoice
from .fit import _curve_choice, _moduli, _refuse_others, _template, instrument_error
from .options.checks import check_misspelled, check_petsc_values
from .options.plausible import PLAUSIBLE, implausible
from .options.reading import AppOptions, read_grid, read_model_spread, read_solver
from .options.table import ROUGHNESS_OPTIONS, TABLE
from .progress import Progress

__all__ = ["MapRequest", "read", "execute", "main", "journal_path"]

#: The largest map file read (afmformats reads a map's curves from it as they are asked for, not whole).
MAP_BYTES = 1 << 40
#: The outputs a map writes.
_OUTPUTS = ("out", "csv", "plot")
#: Options a map does not take, each with why.
_NOT_WITH = {"fit_curve": "a run fits one measurement: a curve or a map",
             "fit_pull_off": "a run fits one measurement: a pull-off or a map",
             "fit_pull_off_err": "it is -fit_pull_off's", "fit_curve_index": "a map fits every curve",
             "summary": "a map's results are its HDF5 file (-out) and its table (-csv)"}


@dataclass
class MapRequest:
    """A map's inputs, read and checked."""

    source: MapSource
    model: Model
    grid: GridChoice
    solver: object
    bodies: Bodies
    spring: Spring | None           # None: each curve's file's spring constant
    choice: FitChoice
    invols: float | None
    targets: dict
    journal: str
    fingerprint: str
    spread_rules: tuple | None = None
    warnings: tuple = ()


def journal_path(targets: dict) -> str:
    """The journal beside the map's HDF5 file (or its CSV without one)."""
    return (targets.get("out") or targets["csv"]) + ".journal"


def _fingerprint(opts: AppOptions, source: MapSource) -> str:
    """What makes a map the same map: its options (the outputs and progress lines aside) and its source's
    curves (each file's name and size)."""
    given = {k: v for k, v in opts.given().items() if k not in (*_OUTPUTS, "progress", "progress_interval")}
    files = source.files
    sizes = [(os.path.abspath(f), os.path.getsize(f) if os.path.exists(f) else -1) for f in files]
    blob = json.dumps({"options": sorted(given.items()), "source": sizes, "curves": len(source.entries)})
    return hashlib.sha256(blob.encode()).hexdigest()


def _shape(opts: AppOptions) -> tuple | None:
    raw = opts.reals("fit_map_shape")
    if not opts.db.hasName("fit_map_shape"):
        return None
    if len(raw) != 2 or any(v != int(v) or v < 1 for v in raw):
        raise InputError(f"-fit_map_shape: expected two whole numbers nx,ny of at least 1, got "
                         f"'{opts.string('fit_map_shape')}'")
    return int(raw[0]), int(raw[1])


def read(opts: AppOptions, comm, argv: list[str]) -> MapRequest:
    """Read and check a map's options before any work (see the module)."""
    check_misspelled(opts)
    check_petsc_values(opts.db)
    for name, why in _NOT_WITH.items():
        if opts.db.hasName(name):
            raise InputError(f"-{name}: not with -fit_map: {why}; remove it")
    _refuse_others(opts, "-fit_map")
    for name in ("phys_radius", "phys_epsilon"):
        if not opts.db.hasName(name):
            need = "the tip's radius R" if name == "phys_radius" else "the Lennard-Jones law's epsilon"
            raise InputError(f"-{name}: required with -fit_map ({need}, m)")
    eps, rms = opts.real("phys_epsilon"), opts.real("phys_rms")
    if opts.choice("adh_roughness") == "none" and rms:
        raise InputError("-phys_rms: not with -adh_roughness none (a smooth surface)")
    model = _template(opts, rms, eps)
    fit_modulus, fit_rough = opts.flag("fit_modulus"), opts.flag("fit_roughness")
    for name, kinds in ROUGHNESS_OPTIONS.items():
        if opts.db.hasName(name) and (model.roughness not in kinds or (model.sigma == 0 and not fit_rough)):
            raise InputError(f"-{name}: applies to -adh_roughness {' or '.join(kinds)} with a roughness "
                             f"(-phys_rms or -fit_roughness); remove it")
    if fit_rough and model.roughness == "none":
        raise InputError("-fit_roughness: not with -adh_roughness none (a smooth surface)")
    grid, solver = read_grid(opts, model), read_solver(opts)
    targets = {k: opts.string(k) for k in _OUTPUTS if opts.string(k)}
    if "out" not in targets and "csv" not in targets:
        raise InputError("-out: required with -fit_map (or -csv): the map's files, its journal beside them")
    if "plot" in targets and plot_format(targets["plot"]) is None:
        raise InputError(f"-plot: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{targets['plot']}'")
    _moduli(opts, not fit_modulus, "-fit_modulus false")
    bodies = Bodies(radius=opts.real("phys_radius"), young1=opts.real("phys_young1"),
                    poisson1=opts.real("phys_poisson1"), epsilon=eps, radius2=opts.real("phys_radius2"),
                    young2=opts.real("phys_young2"), poisson2=opts.real("phys_poisson2"), rms=rms)
    choice = _curve_choice(opts, fit_modulus, fit_rough)
    rough = model.roughness != "none" and (model.sigma > 0 or fit_rough)
    spread = read_model_spread(opts, replace(model, sigma=model.sigma or (0.3 if rough else 0.0)))
    path = opts.string("fit_map")
    if not os.path.isdir(path):
        check_input("fit_map", path, MAP_BYTES)     # a FIFO, a device, a link to nothing: named, never opened
    shape, k, invols = _shape(opts), opts.real("phys_spring"), opts.real("fit_invols")
    try:
        source = open_map(path, shape, k, invols)
    except NeedsInstrument as e:    # a map file read only calibrated (AFM Workshop's zip in volts)
        raise instrument_error(e, "-fit_map") from None
    except ShapeError as e:         # the source is read, the shape given is what it cannot take
        raise InputError(f"-fit_map_shape: {printable(str(e))}") from None
    except MapSourceError as e:
        raise InputError(f"-fit_map: {printable(str(e))}") from None
    _first_curve(source, k, invols)
    targets_in = {"fit_map": [path, *source.files]}
    req = MapRequest(source, model, grid, solver, bodies, None if k is None else Spring(k, "-phys_spring"), choice,
                     invols, targets, journal_path(targets), _fingerprint(opts, source), spread)
    if comm.getRank() == 0:
        check_targets(targets, targets_in)
    return replace(req, warnings=tuple(implausible({n: opts.real(n) for n in PLAUSIBLE if n in TABLE})))


def _first_curve(source: MapSource, k: float | None, invols: float | None) -> None:
    """What the whole map needs, checked on its first curve that can be read: a sensitivity for a deflection in
    volts, a spring constant, a -fit_invols that has a deflection in volts to apply to.  A curve that cannot
    be read is the map's to flag."""
    for entry in source.entries[:8]:
        try:
            data = source.curve(entry, k, invols)
        except NeedsInstrument as e:
            raise instrument_error(e, "-fit_map") from None
        except CurveFileError:
            continue
        if invols is not None and data.sensitivity != invols:
            raise InputError(f"-fit_invols: the map's curves give a force, not a deflection in volts: no "
                             f"sensitivity to apply; remove it")
        if k is None and data.spring is None:
            raise InputError(f"-phys_spring: required with -fit_map: its curves state no spring constant (N/m)")
        return


def _resumed(req: MapRequest) -> dict:
    """The pixels of an earlier run's journal, by curve index; InputError for a journal not this map's, naming
    the output it stands beside (-out, or -csv without one): that option placed it, the source is not at fault."""
    beside = f"-{'out' if 'out' in req.targets else 'csv'}: the journal beside it"
    try:
        records = Journal(req.journal, req.fingerprint).read()
    except JournalError as e:
        raise InputError(f"{beside}, {printable(str(e))}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{beside}, '{printable(req.journal)}', cannot be read ({type(e).__name__}); move it "
                         f"away") from None
    known = {e.index: e for e in req.source.entries}
    done = {}
    for rec in records:
        entry, fields = pixel_fields(rec)
        if known.get(entry["index"]) != MapEntry(**entry):
            raise InputError(f"{beside}, '{printable(req.journal)}', names a curve the map does not hold "
                             f"({entry['index']}); remove it")
        done[entry["index"]] = Pixel(MapEntry(**entry), **fields)
    return done


def _progress(opts: AppOptions, comm):
    """The progress line of a map: curves done, the rate, the time left."""
    shown = opts.flag("progress")
    bar = Progress(comm, sys.stderr.isatty() if shown is None else shown, opts.real("progress_interval"))
    if not bar.enabled:
        return None

    def update(p: MapProgress) -> None:
        fitted = p.total - p.resumed
        done = (p.done - p.resumed) / fitted if fitted else 1.0
        resumed = f" ({p.resumed} from the journal)" if p.resumed else ""
        bar.update(done, f"map: {p.done} of {p.total} curves{resumed}, {p.rate:.3g} curves/s")
    return update


def execute(opts: AppOptions, argv: list[str], report: bool = True):
    """The map of the options database: (exit status, the MapResult)."""
    from ..errors import tell
    from .run import warn

    comm = PETSc.COMM_WORLD
    req = collective(comm, read, opts, comm, argv)
    done = collective(comm, _resumed, req)
    journal = Journal(req.journal, req.fingerprint)
    rank0 = comm.getRank() == 0
    if rank0:
        journal.start()
        if done and report:
            tell(f"map: {len(done)} of {len(req.source.entries)} curves taken up from the journal "
                 f"'{printable(req.journal)}'")
    result = fit_map(req.source, req.bodies, req.spring, req.choice, req.model, req.grid, req.solver, comm,
                     req.invols, req.spread_rules, done, journal.append if rank0 else None, _progress(opts, comm))
    warn(req.warnings, report)
    if rank0:
        tree = map_tree(result, opts.given(), program_record(Program.of(comm)))
        with written(req.targets) as files:
            if "out" in files.targets:
                write_map_h5(files.temp("out"), tree)
            if "csv" in files.targets:
                write_map_csv(files.temp("csv"), result)
            if "plot" in files.targets:
                from ..io.plot.map import map_figure

                fmt = plot_format(files.targets["plot"])
                assert fmt is not None, "read refuses a -plot that ends in no figure format"
                map_figure(tree, files.temp("plot"), fmt)
            files.commit()
        journal.remove()
        if report:
            report_map(result)
    PETSc.garbage_cleanup()
    return (0 if result.trustworthy else 3), result


def main(opts: AppOptions, argv: list[str], helping: bool = False) -> int:
    """A map of the options database; its exit status (``helping``: checked only)."""
    from .run import command_main

    return command_main(opts, argv, helping, read, execute)
