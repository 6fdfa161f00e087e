"""Checks of the options before any work: contradictions and options the run would ignore, unused and
misspelled options, PETSc's values and errors in one line, the memory a grid needs."""
from __future__ import annotations

import difflib
import math
import os
import resource

from petsc4py import PETSc

from ... import brent
from ...core import capi
from ...core.newton import role_of
from ...discretization.preconditioning import BASE_BYTES, memory_available, memory_needed
from ...errors import InputError
from ...io.inputs import size_words
from ...model.parameters import Model
from ...model.reference.jkr import jkr_zero_load
from ...model.reference.rigid import load_beyond
from ...tracing.edge_grids import MU_TRUNCATED, domain_load
from .reading import _NUMBER, AppOptions, _strict_float, _strict_int
from .table import ROUGHNESS_OPTIONS, SOLVER_PREFIXES, TABLE, Option

__all__ = ["truncated_too_far", "APP_PREFIXES", "is_application", "check_misspelled", "DOMAIN_SHARE", "smallest_domain", "check_consistency", "check_memory", "memory_limits", "petsc_error", "PETSC_GLOBAL", "petsc_names", "check_unused", "check_petsc_values"]


#: The attraction beyond r_m may carry at most this share of the DMT pull-off at contact.
DOMAIN_SHARE = 0.05


def smallest_domain(mu: float) -> float:
    """The smallest r_m that holds the contact: the JKR contact radius at zero load, and the
    radius beyond which the rigid sphere's attraction carries at most DOMAIN_SHARE of F = -1."""
    reach = brent.root(lambda r: abs(float(load_beyond(r, 0.0))) - DOMAIN_SHARE, 0.1, 100.0)
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
                                                                                     "csv", "csv_events",
                                                                                     "target_error", "afm_spring",
                                                                                     "phys_spring"])]
    elif not opts.flag("cont_error_estimate"):
        ignored += [(n, "refines error bars, which -cont_error_estimate false turns off") for n in
                    _given(opts, ["target_error"])]
    kind = opts.choice("grid_type")
    if kind != "uniform":
        ignored += [(n, f"is a -grid_type uniform option (this run's grid is {kind})") for n in _given(opts, ["grid_n"])]
    if kind != "paper":
        ignored += [(n, f"is a -grid_type paper option (this run's grid is {kind})")
                    for n in _given(opts, [n for n in TABLE if n.startswith("grid_paper_")])]
    for name, kinds in ROUGHNESS_OPTIONS.items():
        if opts.db.hasName(name) and name.startswith("adh_topography") and model.topography:
            continue        # a flat topography: the smooth sphere, from the options that said so
        if opts.db.hasName(name):
            if model.roughness not in kinds:
                ignored.append((name, f"applies to -adh_roughness {' or '.join(kinds)}"))
            elif model.sigma == 0:
                ignored.append((name, "sets the roughness average, not used at -adh_sigma 0"))
    if opts.choice("adh_pmat") != "band":
        ignored += [(n, "applies to -adh_pmat band") for n in _given(opts, ["adh_pmat_band"])]
    if opts.choice("adh_pmat") == "shell":
        ignored += [(n, "keeps a preconditioning matrix, which -adh_pmat shell has none of")
                    for n in _given(opts, ["adh_pc_reuse_its"])]
    if opts.string("cont_checkpoint") == "none":
        ignored += [(n, "times the saves that -cont_checkpoint none turns off")
                    for n in _given(opts, ["cont_checkpoint_interval"])]
    if opts.flag("progress") is False:
        ignored += [(n, "times the progress lines that -progress false turns off")
                    for n in _given(opts, ["progress_interval"])]
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
    if opts.db.hasName("adh_rmax") and model.rmax is not None and model.rmax < smallest_domain(model.mu):
        raise InputError(f"-adh_rmax: {model.rmax:g} leaves out part of the contact at mu = {model.mu:g}: "
                         f"expected at least {smallest_domain(model.mu):.3g} (the JKR contact radius, or the "
                         f"reach of {DOMAIN_SHARE:.0%} of the attraction)")


    F_max = opts.real("cont_F_max")
    if not fixed and not model.farfield and model.rmax is not None and F_max > domain_load(model.mu, model.rmax):
        raise InputError(truncated_too_far(model.mu, model.rmax, F_max))
    if not fixed and not model.farfield and kind == "edge" and model.mu > MU_TRUNCATED:
        raise InputError(f"-adh_farfield: false (the model truncated at r_m) is traced in the physical frame, up to "
                         f"mu = {MU_TRUNCATED:g}, got mu = {model.mu:g}: leave it true (the half-infinite model, r_m's "
                         f"error in the bar) or take -grid_type uniform")


def truncated_too_far(mu: float, rmax: float, F_max: float) -> str:
    """The line refusing -cont_F_max beyond the truncated model's domain (:func:`domain_load`)."""
    need = (1.5 * math.pi * mu**1.5 * F_max) ** (1.0 / 3.0)
    return (f"-cont_F_max: {F_max:g} lies beyond the truncated model's domain at mu = {mu:g}: even Hertz's contact, "
            f"the narrowest at a given load, reaches r_m = {rmax:g} at F = {domain_load(mu, rmax):.4g}; expected at "
            f"most that, or -adh_rmax above {need:.4g}, or -adh_farfield true (the half-infinite model)")


#: Where a control group states the memory its processes may use, and what they use now (v2, then v1).
CGROUP_MEMORY = (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                 ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"))


def _read_number(path: str) -> float | None:
    """The number a /proc or /sys file holds ('max' and what is no number: None)."""
    try:
        with open(path) as f:
            text = f.read().strip()
        return float(text)
    except (OSError, ValueError):
        return None


def _mapped_bytes() -> float:
    """The address space this process maps now (VmSize), 0 where /proc does not say."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0.0


def memory_limits(cgroups=CGROUP_MEMORY) -> list[tuple[float, float | None, str, bool]]:
    """Each limit on the memory this process may still take, as (bytes left, bytes of the limit or None, its
    name, whether what the process holds now is counted in it already): the machine's available memory
    (MemAvailable), the address-space limit (RLIMIT_AS, as ``ulimit -v`` sets it) less what the process maps
    already, and the control group's limit less what the group uses.  A limit that is not set (unlimited,
    'max', a v1 group's near 2^63) is left out."""
    out: list[tuple[float, float | None, str, bool]] = []
    machine = _mem_available()
    if machine is not None:
        out.append((machine, None, "this machine has", False))
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    except (OSError, ValueError):
        soft = resource.RLIM_INFINITY
    if soft != resource.RLIM_INFINITY and soft > 0:
        # what is mapped now holds the run's base already (BASE_BYTES of memory_needed): what is left of
        # the limit is compared with the matrices alone (the third element: the base is counted)
        out.append((soft - _mapped_bytes(), float(soft), "the address-space limit (ulimit -v, RLIMIT_AS)", True))
    for limit_path, used_path in cgroups:
        limit, used = _read_number(limit_path), _read_number(used_path)
        if limit is not None and limit < 2.0**60:           # v1 says 'unlimited' as a number near 2^63
            out.append((limit - (used or 0.0), limit, f"the control group's memory limit ({limit_path})", False))
            break
    return out


def _mem_available() -> float | None:
    """MemAvailable of /proc/meminfo in bytes, or None."""
    try:
        with open("/proc/meminfo") as f:
            info = {ln.split(":")[0]: ln.split()[1] for ln in f}
        return float(info["MemAvailable"]) * 1024
    except (OSError, KeyError, ValueError, IndexError):
        return None


def check_memory(grid_choice, pmat: str, curve: bool, ranks: int, limits=None) -> None:
    """Refuse, before any node is made, a grid whose matrices cannot fit in the memory this process may still
    take: the dense influence matrix and, with -adh_pmat dense, G_H, the bordered matrix and their factors
    (:func:`~petsc_adhesion.discretization.preconditioning.memory_needed`), split over the ranks, against the
    smallest of the machine's available memory, the process's address-space limit and its control group's
    limit (:func:`memory_limits`; ``limits`` given: those), the one that binds named."""
    n = grid_choice.size
    if n is None:
        return
    need = memory_needed(n, pmat, curve, ranks)
    limits = memory_limits() if limits is None else limits
    if not limits:
        limits = [(memory_available(), None, "this machine has", False)]
    # the shortfall under each limit: what the run still needs against what the limit leaves
    short = [(need - (BASE_BYTES if counted else 0.0) - have, have, limit, name)
             for have, limit, name, counted in limits]
    over, have, limit, name = max(short, key=lambda x: x[0])
    if over > 0:
        option = "-grid_n" if grid_choice.kind == "uniform" else "-grid_paper_extra"
        cheaper = ", or -adh_pmat band" if pmat == "dense" else ""
        where = f"{name} {size_words(max(have, 0.0))} available" if limit is None else \
            f"{name} of {size_words(limit)} leaves {size_words(max(have, 0.0))}"
        raise InputError(f"{option}: N = {n} nodes need {size_words(need)} a rank ({'a curve' if curve else 'a solve'}"
                         f" with -adh_pmat {pmat}), {where}; use fewer nodes, more ranks{cheaper}")


# -- PETSc's errors and options ------------------------------------------------------
#: PETSc error codes that mean a bad option value: unknown type, wrong argument, out of range, no support.
_INPUT_CODES = (56, 62, 63, 86, 92)


#: Words of option names too common to say which option a PETSc message is about.
_GENERIC = {"type", "snes", "ksp", "view", "monitor", "options", "file", "grid", "cont", "adh"}


def petsc_error(err: PETSc.Error, opts: AppOptions | None = None) -> InputError | str:
    """What a PETSc error means for the user: the option behind it (an InputError), or one line.

    PETSc keeps the specific message of its last error (PetscErrorMessage); the
    option is the one whose value the message quotes, else one whose name's
    words it uses ("Restart must be positive": -ksp_gmres_restart).
    """
    detail = capi.error_message(err.ierr) or f"PETSc error {err.ierr}"
    # the application's options are checked before PETSc sees them; a number quoted is no one's name
    given = {k: v for k, v in (opts or AppOptions()).given().items() if k not in TABLE}
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
    program offers, made by ``python -m petsc_adhesion.benchmarks.petsc_names``.
    """
    with open(_NAMES_FILE) as f:
        return [ln.strip() for ln in f if ln.strip() and not ln.startswith("#")]


def _prefixes() -> tuple:
    return tuple(p for p, _ in SOLVER_PREFIXES)


#: The beginnings of the application's option names (adh_, phys_, fit_, ...): an option given with one of them
#: that is not in the table is a misspelling of ours, never one of PETSc's.
APP_PREFIXES = tuple(sorted({name.split("_")[0] + "_" for name in TABLE}))


def is_application(name: str) -> bool:
    """Whether ``name`` is (or misspells) an application option: one of the table, or under its prefixes."""
    return name in TABLE or name.startswith(APP_PREFIXES)


def check_misspelled(opts: AppOptions) -> None:
    """Read every application option (each value checked) and refuse one under the application's prefixes
    that is not in the table, naming the nearest known one: first, before the checks of options required
    together (``-phys_radis`` is named as a misspelling, not reported as a missing ``-phys_radius``)."""
    opts.read_all()
    check_unused(is_application, opts.db)


def check_unused(judged=lambda name: True, db=None) -> None:
    """Raise :class:`InputError` for an option that nobody read.

    ``judged`` picks the options to judge: the application's own, which are
    all read up front, before any work; or all of them once the solvers are
    set up, when PETSc has read its own.  ``db``: the run's options when they
    are not PETSc's database (a :class:`~.reading.Given`, the Python API's), judged
    beside the solvers' own in PETSc's.
    """
    names = (db.left() if hasattr(db, "left") else []) + capi.options_left()
    # a solver's options are in the database under its own prefix (SolverOptions): named as the user gave them
    left = [role_of(n) for n in names if judged(n) and n not in PETSC_GLOBAL]
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
