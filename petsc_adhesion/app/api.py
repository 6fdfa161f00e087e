"""The Python API with the command line's options: a curve or a fixed-approach solve from a notebook or a script.

    import petsc_adhesion as pa
    c = pa.curve(mu=1.0, grid_type="uniform", grid_n=201)
    print(c.pull_off.F.value, "+-", c.pull_off.F.err)
    s = pa.solve(-2.0, mu=1.0, snes_rtol=1e-12)                   # H(r), P(r), F at lambda = -2

Each call is one run (:func:`petsc_adhesion.app.run.execute`) of the options
given as keywords: ``grid_n=201`` is ``-grid_n 201``, ``True`` a bare flag,
``False`` ``false``, a list a comma-separated value, ``None`` leaves the option
out.  They are read into the library's objects as values, without argv and
without PETSc's options database (:class:`~petsc_adhesion.app.options.reading.Given`),
and checked as the command line reads and checks its options (the same one-line
:class:`~petsc_adhesion.errors.InputError`, unknown options refused, before any
work); the library computes with those objects
(:func:`~petsc_adhesion.tracing.trace.trace_curve`,
:func:`~petsc_adhesion.tracing.trace.solve_at`).  PETSc's solver options
(``arc_snes_rtol=1e-10``, ``pc_type="lu"``) become each solver's
:class:`~petsc_adhesion.core.newton.PetscSettings`, under the command line's
prefixes (``nat_``, ``arc_``, none for the solve); an option its solver does not
read is refused.  Calls in one process do not see each other's options, nor the
caller's, nor ``PETSC_OPTIONS`` or ``.petscrc`` (what the command line reads at its
start; options files are the command line's: ``options_file=`` is refused).  Calls
from several threads run one at a time; the first may come from any thread.  A call destroys the PETSc objects it
makes, failed calls too (a PETSc type name that does not exist,
``pc_type="nonesuch"``, included).  ``out=``, ``summary=`` and ``plot=`` write
the command line's files, all or nothing.  Without options, the library's own
calls take the objects directly (docs/python.md).

PETSc is initialised on the first call, not on ``import petsc_adhesion``.  Under
``mpiexec`` every rank makes the same call (a collective one), and every rank gets
the whole result; rank 0 writes the files.
"""
from __future__ import annotations

import math
import re
import threading
import warnings

import numpy as np

from ..errors import InputError
from ..tracing.curve import Curve, Solution

__all__ = ["curve", "solve"]


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
    return _run(_given(options, adh_mu=mu, adh_sigma=sigma))


def solve(lam: float, mu: float | None = None, sigma: float | None = None, **options) -> Solution:
    """Solve at the one approach ``lam`` (``-adh_lambda``) for ``-adh_mu mu -adh_sigma sigma`` and the ``options``.

    As :func:`curve`; the Newton solver's options have no prefix (``snes_rtol=1e-12``),
    and ``adh_guess`` names an ``out=`` file of an earlier solve as the initial guess.
    """
    if isinstance(lam, bool) or not isinstance(lam, (int, float, np.integer, np.floating)) or not math.isfinite(lam):
        raise InputError(f"-adh_lambda: solve(lam) needs the approach lam, a finite real; got {lam!r}")
    return _run(_given(options, adh_lambda=lam, adh_mu=mu, adh_sigma=sigma))


# -- keywords into options ---------------------------------------------------------------------
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
#: What the command line does with these other than compute: the API computes.
_REFUSED = {"help": "see help(petsc_adhesion.curve) and docs/usage.md",
            "version": "see petsc_adhesion.__version__",
            "options_file": "give the options as keywords (an options file is the command line's)",
            "options_file_yaml": "give the options as keywords (an options file is the command line's)"}


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


def _given(options: dict, **named) -> dict:
    """The options of the keyword ``options`` and the named parameters (name -> value, None: not given), as
    the command line's words would give them: name -> value string, None for a bare flag."""
    aliases = {"adh_mu": "mu", "adh_sigma": "sigma", "adh_lambda": "lam"}
    given = {}
    for name, v in named.items():
        if v is not None and name in options:
            raise InputError(f"-{name}: given twice, as {aliases[name]} and as {name}")
    for name, v in {**{k: v for k, v in named.items() if v is not None}, **options}.items():
        if not _NAME.fullmatch(name):
            raise InputError(f"'{name}': not an option name; give it without the dash, e.g. grid_n=201")
        if name in _REFUSED:
            raise InputError(f"-{name}: not in the Python API; {_REFUSED[name]}")
        if v is not None:
            words = _value(name, v)
            if name.lower() in given:
                raise InputError(f"-{name}: given twice (option names ignore case)")
            given[name.lower()] = words[0] if words else None
    return given


# -- a run --------------------------------------------------------------------------------------
#: One run at a time in a process: PETSc is the process's (its objects, its error state, the solvers' options
#: under their own prefixes in its database) and not made for two threads at once.  The second call waits.
_ONE_AT_A_TIME = threading.RLock()

def _run(given: dict):
    """The run of the options ``given`` (a :class:`~.options.reading.Given`, no options database): the
    library's result, on every rank.  Its errors raise: InputError for bad input, RuntimeError otherwise."""
    from ..core.start import start_petsc

    start_petsc(["petsc_adhesion"])                 # options are the run's own: none at start-up
    from petsc4py import PETSc

    from ..errors import collective
    from . import run
    from .options.checks import PETSC_GLOBAL, petsc_error
    from .options.reading import AppOptions, Given

    for name in given:
        if name in PETSC_GLOBAL:
            raise InputError(f"-{name}: PETSc's own option of a program's start or end, not of one call; "
                             f"not in the Python API")
    failed: Exception | None = None
    result = None
    with _ONE_AT_A_TIME:
        opts = AppOptions(Given(given))
        try:
            if collective(PETSc.COMM_WORLD, run.is_study, opts):
                raise InputError("-study_mu, -study_sigma, -study_option: a study of many cases runs from the "
                                 "command line (petsc-adhesion -options_file FILE); the Python API traces one curve")
            run.refuse_study_options(opts)
            _, result = run.execute(opts, ["petsc_adhesion"], report=False)
        except PETSc.Error as e:
            bad = petsc_error(e, opts)
            failed = bad if isinstance(bad, InputError) else RuntimeError(bad)
        except (InputError, RuntimeError, FloatingPointError, OSError) as e:
            failed = e
    if failed is not None:
        # the command line's one line, without the run's frames: a notebook keeps the last error, and
        # with it every PETSc object those frames hold, past PETSc's end
        failed.__context__ = failed.__cause__ = None
        raise failed.with_traceback(None)
    if PETSc.COMM_WORLD.getRank() == 0:
        for w in getattr(result, "warnings", ()):
            warnings.warn(f"petsc-adhesion: {w}", RuntimeWarning, stacklevel=3)
    return result
