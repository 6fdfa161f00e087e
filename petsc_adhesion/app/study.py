"""Studies: a sweep over cases described by options, spread over MPI ranks.

    ./run study options/fig18.opts
    mpiexec -n 2 petsc-adhesion -options_file options/fig18.opts

The cases are the product of ``-study_mu``, ``-study_sigma`` and ``-study_option``'s
``-study_values`` (each a list or ranges ``lo:hi:n[:log]``); every other option
applies to every case, which runs exactly as a single curve with those options
(:func:`petsc_adhesion.app.run.curve`).  ``-study_compute`` says what a case
computes and ``-study_profiles`` which states it keeps, so that a case leaves
out what the study does not use.

With P ranks the cases go to P / ``-study_ranks`` groups (MPI subcommunicators),
the longest first to the least loaded group (by :func:`cost`); each group runs
its cases in that order.  Rank 0 prints a line for every finished case, with
the elapsed time and an estimate of the time left, when it next comes up for
air (after a step of its own curve, or a case).  A case whose options are
bad is said in one line before any work and left out; a case that fails at
run time is said in one line and recorded; the others run, and the study's
files hold them (exit status 3 when any case is missing).  One HDF5 file (a
group per case and a table of every case's events with their error bars), one
JSON summary (``cases``: each case's ``mu``, ``sigma`` and the keys of a single
curve's summary), the figure of ``-study_plot`` and the table of events as CSV
(``-csv``, when given) are written together, by :mod:`petsc_adhesion.io` from each
case's :class:`~petsc_adhesion.tracing.case.CaseResult` (gathered to rank 0 as values).
A rough case carries its model spread (:mod:`petsc_adhesion.tracing.model_spread`,
unless ``-adh_model_spread false``), as a single rough run does; the study says in
one line how many of them warn.

Rank 0 saves the finished cases (each a CaseResult, through :mod:`petsc_adhesion.io.values`) into a
checkpoint as they reach it (at most
every ``-cont_checkpoint_interval`` seconds; by default beside ``-out``):
after a kill, ``-cont_restart FILE`` with the same options (on any number of
ranks) runs only the cases not in it, and the study's files equal an
uninterrupted run's.  A case cut off mid-way runs again from its start.
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from petsc4py import PETSc

from ..core.newton import is_solvers_own
from ..errors import InputError, Interrupted, collective, say
from ..io.report import study_spread_line
from ..io.resultset import check_targets, mark_done, written
from ..io.summary import program_record
from ..io.write import write_critical, write_study
from ..tracing.case import CaseResult
from ..tracing.curve import Curve, Program
from ..tracing.measured import Missing
from ..tracing.model_spread import model_spread
from ..tracing.trace import trace_curve
from .checkpoint import open_checkpoint
from .options.checks import check_misspelled, check_petsc_values, check_unused
from .options.reading import ROLE_PREFIXES, SOLVER_OPTIONS, AppOptions, Given, read_model, read_petsc
from .options.table import TABLE
from .optionsfile import options_files
from .progress import clock
from .run import Request, read

if TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["Case", "cases", "cost", "assign", "spread", "main", "KINDS"]

#: The event kinds each -study_compute reports (None: all) and whether it stops at equilibrium.
KINDS = {"curve": (None, False), "events": (None, True), "pull_off": (("F_min", "equilibrium"), True),
         "folds": (("snap_on", "snap_off"), True)}
#: The most cases of one study (each a curve of seconds to minutes).
MAX_CASES = 10_000
#: Options a study sets for its cases or writes itself; a -study_option cannot be one of them.
_OWN = ("adh_mu", "adh_sigma", "adh_lambda", "out", "summary", "plot")
_TAG = 17
#: Options of the study as a whole, not of its cases
_STUDY_FILES = ("out", "summary", "plot", "csv", "options_file", "cont_checkpoint", "cont_checkpoint_interval",
                "cont_restart")


@dataclass
class Case:
    """One case of a study: its number and the options it sets."""

    index: int
    values: dict                                      # option name -> value
    error: str | None = field(default=None)          # why it cannot run, or None
    #: its options read into the library's objects (:class:`~petsc_adhesion.app.run.Request`), once
    request: tuple[Request, bool | None] | None = field(default=None, repr=False, compare=False)

    @property
    def label(self) -> str:
        names = {"adh_mu": "mu", "adh_sigma": "sigma"}
        return ", ".join(f"{names.get(k, k)} = {v:g}" for k, v in self.values.items())

    def options(self, study: dict) -> dict:
        """The options of this case: the study's (``study``: name -> value), less the study's own files
        and checkpoint, with its values."""
        keep = {k: v for k, v in study.items() if k not in _STUDY_FILES}
        return keep | {k: f"{v:.17g}" for k, v in self.values.items()}


def _check(opts: AppOptions) -> tuple[list, str]:
    """The study's axes (option, values), checked; and the option its -study_values sweep."""
    axes, swept = [], opts.string("study_option")
    for name, own in (("study_mu", "adh_mu"), ("study_sigma", "adh_sigma")):
        if opts.db.hasName(name):
            if opts.db.hasName(own):
                raise InputError(f"-{own}: not with -{name}, which sets it for each case")
            axes.append((own, opts.sweep(name)))
    if swept is not None:
        o = TABLE.get(swept.lstrip("-"))
        if o is None or o.kind not in ("real", "int") or o.name in _OWN or o.name.startswith("study_"):
            why = "use -study_mu or -study_sigma" if o is not None and o.name in ("adh_mu", "adh_sigma") else \
                "expected the name of a real or integer option (without the dash) other than the study's own"
            raise InputError(f"-study_option: '{swept}': {why}")
        if opts.db.hasName(o.name):
            raise InputError(f"-{o.name}: not with -study_option {o.name}, which sets it for each case")
        if not opts.db.hasName("study_values"):
            raise InputError("-study_values: required with -study_option: the values it takes")
        axes.append((o.name, opts.sweep("study_values")))
    elif opts.db.hasName("study_values"):
        raise InputError("-study_values: only with -study_option, the option they are values of")
    if opts.real("adh_lambda") is not None:
        raise InputError("-adh_lambda: a study traces curves; remove it")
    if opts.db.hasName("study_ranks") and PETSc.COMM_WORLD.getSize() % opts.int("study_ranks"):
        raise InputError(f"-study_ranks: {opts.int('study_ranks')} does not divide the "
                         f"{PETSc.COMM_WORLD.getSize()} ranks of the run")
    if not axes:
        raise InputError("-study_mu: a study needs -study_mu, -study_sigma or -study_option")
    count = math.prod(len(v) for _, v in axes)
    if count > MAX_CASES:
        name = {"adh_mu": "study_mu", "adh_sigma": "study_sigma"}.get(axes[0][0], "study_values")
        raise InputError(f"-{name}: the study has {count} cases ({' x '.join(str(len(v)) for _, v in axes)}); "
                         f"a study runs at most {MAX_CASES}")
    return axes, swept


def cases(axes: list) -> list[Case]:
    """The product of the axes, the first varying slowest."""
    names = [n for n, _ in axes]
    return [Case(i, dict(zip(names, vals))) for i, vals in enumerate(itertools.product(*(v for _, v in axes)))]


#: What a law of the model spread costs against the case's own curve with its error bars: its curve is
#: traced with the same grids and settings, without error bars, but the bounded laws' wall quadrature costs
#: more per evaluation (measured: the four default laws 5.8 and 6.8 times the case at mu = 3 and 1, sigma =
#: 0.3, -study_compute pull_off; docs/studies.md).
SPREAD_RULE_COST = 1.6


def cost(case: Case) -> float:
    """A rough relative run time of a case, for ordering: the contact widens with mu (more steps,
    larger grids), roughness adds its quadrature to every evaluation, and a rough case's model spread
    traces its events again under each other law."""
    mu = case.values.get("adh_mu", 1.0)
    rules = case.request[0].spread_rules if case.request is not None else None
    return (1.0 + mu) * (1.5 if case.values.get("adh_sigma", 0.0) > 0 else 1.0) * \
        (1.0 + SPREAD_RULE_COST * len(rules or ()))


def assign(todo: list[Case], groups: int) -> list[list[Case]]:
    """Longest first, each to the group with the least work so far (LPT scheduling)."""
    load = [0.0] * groups
    out: list[list[Case]] = [[] for _ in range(groups)]
    for c in sorted(todo, key=lambda c: (-cost(c), c.index)):
        g = min(range(groups), key=lambda k: (load[k], k))
        out[g].append(c)
        load[g] += cost(c)
    return out


def _case(c: Case, study: dict) -> AppOptions:
    """The options of case ``c``, read as values (no options database)."""
    return AppOptions(Given(c.options(study)))


def _validate(todo: list[Case], study: dict, argv: list[str], compute: str = "curve", keep: tuple = ()) -> None:
    """Each case's options checked as a single run's would be and read into the library's objects
    (``c.request``), before any work (every rank alike); an option of a case that nothing reads is refused
    here (one a solver leaves unread, when it has read its own)."""
    kinds, stop = KINDS[compute]
    for c in todo:
        try:
            opts = _case(c, study)
            req = read(opts, PETSc.COMM_SELF, argv, kinds, bool(keep), case=True)
            unread = set(opts.db.left())
            check_unused(lambda name: name in unread, opts.db)
            if stop and not opts.db.hasName("cont_F_max"):
                req = replace(req, settings=replace(req.settings, observable_max=0.0))
            c.request = (req, opts.flag("profiles"))
        except InputError as e:
            c.error = str(e)


def _check_spread(opts: AppOptions, good: list[Case]) -> None:
    """A model spread asked for (-adh_model_spread true, -adh_model_spread_rules) is computed for each rough
    case; a study with none is refused, as a smooth single run is."""
    for name in ("adh_model_spread", "adh_model_spread_rules"):
        if opts.db.hasName(name) and opts.flag("adh_model_spread") is not False and \
                not any(c.request is not None and c.request[0].model.sigma > 0
                        and c.request[0].model.roughness != "none" for c in good):
            raise InputError(f"-{name}: no case of the study is rough (sigma > 0): there is no roughness law to vary")


def _run(c: Case, comm, keep: tuple) -> CaseResult | None:
    """One case on ``comm``, from the objects its options were read into: its result on the group's rank 0
    (None elsewhere), the curve with the profiles the study keeps and, for a rough case, its model spread
    (unless -adh_model_spread false)."""
    assert c.request is not None, "_validate has read every case that runs"
    req, profiles = c.request
    # the solvers' own options: one they leave unread (a sub-PC's without a block PC) is refused
    curve = trace_curve(req.model, req.grid, req.solver, req.settings, req.curve, comm=comm,
                        started=lambda: check_unused(is_solvers_own))
    if req.spread_rules is not None:   # the same curve under the other laws, events only (as app/run.py)
        curve = replace(curve, spread=model_spread(curve, req.model, req.grid, req.solver, req.settings, req.curve,
                                                   req.spread_rules, comm=comm))
    if comm.getRank():
        return None
    return CaseResult(c.index, tuple(c.values.items()), curve.keeping_profiles(None if profiles else keep))


def _failure(c: Case, why: str, wall: float | None = None) -> CaseResult:
    return CaseResult(c.index, tuple(c.values.items()), Missing(why), wall)


class _Progress:
    """Rank 0's line per finished case: which, how long, elapsed, and the time left by the cases' costs;
    rank 0 also keeps every finished case's record (``records``, those of a restart first) and saves them
    into the ``journal`` as they come."""

    def __init__(self, comm, todo: list[Case], records: list[CaseResult], journal):
        self.mpi, self.t0, self.total = comm.tompi4py(), time.perf_counter(), sum(cost(c) for c in todo)
        self.done, self.count, self.n = 0.0, len(records), len(records) + len(todo)
        self.sent: list[MPI.Request] = []
        self.records, self.journal = list(records), journal

    def finished(self, rec: CaseResult, brief: dict) -> None:
        """A group leader's case is done: rank 0 keeps and says it, another leader sends it to rank 0."""
        if self.mpi.Get_rank() == 0:
            self._keep(rec, brief)
        else:
            self.sent.append(self.mpi.isend((rec, brief), dest=0, tag=_TAG))

    def poll(self, block: bool = False) -> None:
        """Rank 0: keep and say what the other groups finished (``block``: wait for all of them, polling,
        so that a signal is taken at once)."""
        if self.mpi.Get_rank():
            return
        while True:
            if self.mpi.iprobe(tag=_TAG):
                self._keep(*self.mpi.recv(tag=_TAG))
            elif block and self.count < self.n:
                time.sleep(0.01)
            else:
                return

    def close(self) -> None:
        for req in self.sent:
            req.wait()

    def _keep(self, rec: CaseResult, brief: dict) -> None:
        self.records.append(rec)
        self.journal.save_cases(self.records)
        self.count += 1
        self.done += brief["cost"]
        elapsed = time.perf_counter() - self.t0
        left = elapsed * max(self.total - self.done, 0.0) / self.done if self.done else float("nan")
        say(f"case {rec.case + 1} ({brief['label']}) {brief['what']}; {self.count}/{self.n} done, "
            f"{clock(elapsed)} elapsed, about {clock(left)} left")


def _brief(c: Case, rec: CaseResult) -> dict:
    """What the progress line says about a finished case: its label, its cost (for the time left), what
    it found."""
    out = {"label": c.label, "cost": cost(c)}
    if isinstance(rec.result, Missing):
        return out | {"what": f"failed: {rec.result.reason}"}
    assert isinstance(rec.result, Curve), "a study of curves"
    po = rec.result.pull_off
    what = f"done in {rec.result.diagnostics.wall_time_s:.1f} s"
    if po:
        what += f", pull-off F = {po.F.value:.6f}" + (f" +- {po.F.err:.1e}" if po.F.err else "")
    return out | {"what": what}


def main(opts: AppOptions, argv: list[str], helping: bool = False) -> int:
    """The study of the options database: its cases, spread over the ranks; its files from rank 0.

    Returns the exit status: 0, or 3 when a case is missing (each said in one line).
    ``helping`` (-help): check the study and its cases, then stop.
    """
    world = PETSc.COMM_WORLD
    mpi = world.tompi4py()
    collective(world, check_misspelled, opts)     # before the options required together: named as such
    axes, _ = collective(world, _check, opts)
    compute = opts.choice("study_compute")
    if compute == "critical":
        return _critical_main(opts, argv, axes, helping)
    if opts.choice("study_plot") == "critical":
        raise InputError("-study_plot: critical draws the cusps of -study_compute critical, not curves; "
                         "one of curves, folds, profiles, pull_off, reduction")
    keep = opts.choices("study_profiles")
    todo = cases(axes)
    targets, journal = _files(opts, argv)
    given = opts.given()
    _validate(todo, given, argv, compute, keep)
    bad = [c for c in todo if c.error]
    if len(bad) == len(todo):
        raise InputError(bad[0].error)
    _check_spread(opts, [c for c in todo if not c.error])
    if mpi.Get_rank() == 0:
        for c in bad:
            say(f"case {c.index + 1} ({c.label}) left out: {c.error}")
        # the inputs outside what the field measures, each line once (the cases share most options)
        for line in dict.fromkeys(w for c in todo if c.request for w in c.request[0].warnings):
            say(f"warning: {line}")
    if helping:
        return 0
    files = None
    status: int | None = 0
    try:
        with journal.on_interrupt():
            records = spread([c for c in todo if not c.error], opts.int("study_ranks"),
                             lambda c, comm: _run(c, comm, keep), _brief, journal)
            if mpi.Get_rank() == 0:
                assert records is not None, "rank 0 holds every case's result"
                failed = [_failure(c, c.error) for c in bad if c.error is not None] + \
                    [r for r in records if not r.ran]
                done = [r for r in records if r.ran]
                study = {"compute": compute, "axes": [n for n, _ in axes], "ranks_per_case": opts.int("study_ranks"),
                         "cases": len(todo), "profiles": list(keep), "plot": opts.choice("study_plot")}
                status = 3 if failed or not all(r.complete for r in done) else 0
                if not done:                 # nothing to replace an earlier result set with
                    status = None
                else:
                    line = study_spread_line(done)
                    if line:
                        say(line)
                    with written(targets, journal.paths()) as files:
                        write_study({**program_record(Program.of(world)), "options": opts.given()}, study, done,
                                    sorted(failed, key=lambda r: r.case), files)
        status = mpi.bcast(status, root=0)
        if status is None:
            raise RuntimeError(f"none of the {len(todo)} cases ran (each is said above); nothing written")
        return status
    except Interrupted as e:
        mark_done(e, files, status)
        raise


def _files(opts: AppOptions, argv: list[str], table: bool = True):
    """The study's files (-out, -summary, -plot and, for a ``table`` of events, its CSV -csv: nothing the
    user did not name), checked writable and apart from its inputs, and its checkpoint
    (:func:`~petsc_adhesion.app.checkpoint.open_checkpoint`; collective)."""
    if opts.db.hasName("csv_events"):
        raise InputError("-csv_events: writes the events of one curve, not of a study (its table of events goes to "
                         "-csv); remove it")
    targets = {k: opts.string(k) for k in ("out", "summary", "plot") if opts.string(k)}
    given = opts.string("csv")
    if given and not table:
        raise InputError("-csv: -study_compute critical has no table of events (its cusps are in -out and "
                         "-summary); remove it")
    if given:
        targets["csv"] = given
    inputs = {"options_file": options_files(argv), "adh_roughness_file": [opts.string("adh_roughness_file") or ""]}
    world = PETSc.COMM_WORLD

    collective(world, lambda: check_targets(targets, inputs) if world.getRank() == 0 else None)
    return targets, open_checkpoint(opts, targets, inputs, world, study=True)


def spread(todo: list[Case], ranks: int, work, brief, journal) -> list[CaseResult] | None:
    """``work(case, comm)`` for each case, the cases spread over groups of ``ranks`` ranks (LPT by
    :func:`cost`); a progress line on rank 0 for each finished case (``brief(case, result)``).

    ``work`` returns the case's :class:`~petsc_adhesion.tracing.case.CaseResult` on its group's rank 0; a
    case that raises is one whose result is Missing with its one-line error.  ``journal`` (a study's
    :class:`~petsc_adhesion.app.checkpoint.Checkpoint`): the cases of its restart are not run again, rank 0
    saves the finished ones into it.  Returns every case's result on rank 0, in case order (None elsewhere);
    they reach rank 0 as values (pickled by mpi4py).
    """
    world = PETSc.COMM_WORLD
    mpi = world.tompi4py()
    done, records = journal.cases()
    todo = [c for c in todo if c.index not in done]
    if done and mpi.Get_rank() == 0:
        say(f"going on from the checkpoint {journal.restart}: {len(done)} case"
            f"{'s' * (len(done) != 1)} done, {len(todo)} to run")
    color = mpi.Get_rank() // ranks
    plan_of = assign(todo, mpi.Get_size() // ranks)
    sub = mpi.Split(color, mpi.Get_rank())
    comm = PETSc.Comm(sub)
    progress = _Progress(world, todo, records, journal)
    try:
        for c in plan_of[color]:
            t0 = time.perf_counter()
            try:
                rec = work(c, comm)
            except (InputError, RuntimeError, FloatingPointError, PETSc.Error) as e:
                rec = _failure(c, _one_line(e))
            if sub.Get_rank() == 0:
                rec = replace(rec, wall_time_s=time.perf_counter() - t0)
                progress.finished(rec, brief(c, rec))
            progress.poll()
        progress.poll(block=True)
    finally:
        sub.Free()
    progress.close()
    return sorted(progress.records, key=lambda r: r.case) if mpi.Get_rank() == 0 else None


def _critical_main(opts: AppOptions, argv: list[str], axes: list, helping: bool) -> int:
    """-study_compute critical: sigma_c at each -study_mu and mu_c at each -study_sigma
    (:mod:`~petsc_adhesion.tracing.critical`), each a case; the files from rank 0."""
    world = PETSc.COMM_WORLD
    mpi = world.tompi4py()
    other = [n for n, _ in axes if n not in ("adh_mu", "adh_sigma")]
    if other:
        raise InputError("-study_option: not with -study_compute critical, which continues the turning points "
                         "in mu (each -study_sigma) and in sigma (each -study_mu)")
    if opts.db.hasName("study_plot") and opts.choice("study_plot") != "critical":
        raise InputError(f"-study_plot: {opts.choice('study_plot')} draws curves; -study_compute critical "
                         f"draws 'critical'")
    for name in ("adh_pmat", "adh_pmat_band", "adh_pc_reuse_its"):
        if opts.db.hasName(name):
            raise InputError(f"-{name}: not with -study_compute critical, whose preconditioners are dense (the "
                             f"fold system borders the base problem's); remove it")
    model = collective(world, read_model, opts)
    solver = collective(world, _critical_solver, opts)
    collective(world, check_petsc_values, opts.db)
    todo = [Case(i, {name: v}) for i, (name, v) in enumerate((n, v) for n, vals in axes for v in vals)]
    targets, journal = _files(opts, argv, table=False)
    # every solver made once and freed, before any work: an option nothing reads is refused here
    from ..tracing.critical import configure_solvers
    collective(world, configure_solvers, model, solver, world, check_unused)
    if helping:
        return 0
    files = None
    status: int | None = 0
    try:
        with journal.on_interrupt():
            records = spread(todo, opts.int("study_ranks"), lambda c, comm: _cusp(c, model, solver, comm), _cusp_brief,
                             journal)
            if mpi.Get_rank() == 0:
                assert records is not None, "rank 0 holds every case's result"
                failed = [r for r in records if not r.ran]
                done = [r for r in records if r.ran]
                study = {"compute": "critical", "axes": [n for n, _ in axes],
                         "ranks_per_case": opts.int("study_ranks"), "cases": len(todo), "plot": "critical"}
                status = 3 if failed else 0
                if not done:                 # nothing to replace an earlier result set with
                    status = None
                else:
                    with written(targets, journal.paths()) as files:
                        write_critical({**program_record(Program.of(world)), "options": opts.given()}, study, done, failed,
                                       files)
        check_unused()
        status = mpi.bcast(status, root=0)
        if status is None:
            raise RuntimeError(f"none of the {len(todo)} cases ran (each is said above); nothing written")
        return status
    except Interrupted as e:
        mark_done(e, files, status)
        raise


def _critical_solver(opts: AppOptions):
    """The PETSc settings of a critical study's solvers (:func:`~.options.reading.read_petsc`): the
    correctors' (-nat_, -arc_) and the fold system's (-fold_).  There is no fixed-approach solve: its
    options (no prefix) are left unread, and refused as such."""
    from ..tracing.trace import SolverChoice

    fixed = next((n for n in opts.db.getAll() if n.startswith(SOLVER_OPTIONS)), None)
    if fixed is not None:
        raise InputError(f"-{fixed}: -study_compute critical makes no fixed-approach solve; use -nat_{fixed} for "
                         f"the correctors' natural solves, -arc_{fixed} for their arclength solves, "
                         f"-fold_{fixed} for the fold system's bordered solves")
    roles = {role: read_petsc(opts, ROLE_PREFIXES[role]) for role in ("natural", "arclength", "fold")}
    if roles["fold"].snes_given:
        name = roles["fold"].snes_given[0]
        raise InputError(f"-fold_{name}: the fold system's bordered solves have a KSP, no SNES; give its "
                         f"-fold_ksp_ and -fold_pc_ options, or -nat_{name}, -arc_{name} for the correctors")
    return SolverChoice(natural=roles["natural"], arclength=roles["arclength"], fold=roles["fold"])


def _cusp(c: Case, model, solver, comm) -> CaseResult | None:
    """One case of a critical study: sigma_c at its mu, or mu_c at its sigma, its solvers with ``solver``'s
    settings."""
    from ..tracing.critical import mu_c, sigma_c

    (name, value), = c.values.items()
    try:
        out = sigma_c(model, value, comm=comm, solver=solver) if name == "adh_mu" else \
            mu_c(model, value, comm=comm, solver=solver)
    except ValueError as e:                        # no cusp in the range searched
        raise RuntimeError(str(e)) from None
    return CaseResult(c.index, tuple(c.values.items()), out) if comm.getRank() == 0 else None


def _cusp_brief(c: Case, rec: CaseResult) -> dict:
    out = {"label": c.label, "cost": cost(c)}
    if isinstance(rec.result, Missing):
        return out | {"what": f"failed: {rec.result.reason}"}
    cusp = rec.result
    assert not isinstance(cusp, Curve), "a critical study's cases are cusps"
    return out | {"what": f"{cusp.kind} = {cusp.value.value:.6f} +- {cusp.value.err:.1e} in {cusp.wall_time_s:.1f} s"}


def _one_line(e: BaseException) -> str:
    if isinstance(e, PETSc.Error):
        from .options.checks import petsc_error
        return str(petsc_error(e))
    text = str(e).strip()
    return text.splitlines()[0] if text else type(e).__name__
