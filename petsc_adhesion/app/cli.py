"""Command line entry: ``petsc-adhesion [PETSc and application options]``, or
``petsc-adhesion plot RESULT.h5 [-o OUT]`` (:func:`petsc_adhesion.io.plot.command`).

    mpiexec -n 2 petsc-adhesion -options_file options/fig5_mu1.opts -arc_snes_monitor

Exit status: 0 done; 1 failed (no result); 2 bad input (one line naming the
option, nothing written); 3 result written but not what was asked for
(a stalled curve, an event not reached: its warnings say why); 129, 130 and
143 interrupted by SIGHUP, SIGINT or SIGTERM (nothing written; one that comes
once the results are in place is said in one line, and the run ends with its
own status).  Every error is one line
on stderr from rank 0; no traceback reaches the user.
"""
from __future__ import annotations

import os
import signal
import sys
import time
from contextlib import nullcontext

from ..errors import Interrupted, first_line, interrupted_in, printable, say, tell
from ..io.resultset import said_after
from ..singleton import surroundings
from .optionsfile import environment_error, file_error, named_file_error, options_files, stray_word

__all__ = ["main", "input_error", "EXIT_OK", "EXIT_FAILED", "EXIT_INPUT", "EXIT_INCOMPLETE"]

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_INCOMPLETE = 0, 1, 2, 3


def _on_signal(signum, frame):
    raise Interrupted(signum)


#: How long the other ranks wait for rank 0 to have written the line before they exit ...
SETTLE_S = 10.0
#: ... and before MPI is initialised, where they cannot know when it has.
SETTLE_BEFORE_MPI_S = 2.0
#: A launcher's rank of this process (Open MPI, PMIx, MPICH's PMI, Slurm).
_RANK_VARIABLES = ("OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID")


def _say(msg: str) -> None:
    """One line on rank 0's stderr (before MPI is there to ask, rank 0 by the launcher's variables).

    On several ranks the others wait until rank 0 has written it (a barrier, at most SETTLE_S): a rank
    that exits first with a non-zero status makes mpiexec abort the job, and rank 0 was killed before
    its line was out (found by the fuzz: exit 2 with no line, Open MPI's notices only)."""
    if "mpi4py.MPI" in sys.modules:
        from mpi4py import MPI

        comm = MPI.COMM_WORLD
        if comm.Get_rank() == 0:
            say(f"error: {printable(msg)}")
        if comm.Get_size() > 1 and MPI.Is_initialized() and not MPI.Is_finalized():
            request, t0 = comm.Ibarrier(), time.monotonic()
            while not request.Test() and time.monotonic() - t0 < SETTLE_S:
                time.sleep(0.002)
        return
    # before MPI: the launcher's rank; the others stay silent, and wait a moment so that rank 0's line is
    # out before their exit status makes mpiexec abort the job
    rank = next((os.environ[v] for v in _RANK_VARIABLES if v in os.environ), "0")
    if rank.strip() != "0":
        time.sleep(SETTLE_BEFORE_MPI_S)
        return
    say(f"error: {printable(msg)}")



def _version() -> str:
    from petsc4py import PETSc

    from ..version import __version__

    return f"petsc-adhesion {__version__} (PETSc {'%d.%d.%d' % PETSc.Sys.getVersion()})"


def main(argv: list[str] | None = None) -> int:
    """Run the program on ``argv`` (default: sys.argv) and return its exit status (see the module).

    Repeatable in one process: after the first run (or where PETSc is already
    initialised) each run reads its options into a database of its own, as
    PETSc's start-up would, and the caller's options come back afterwards.
    """
    argv = list(sys.argv if argv is None else argv)
    if argv[1:2] == ["plot"]:                       # a figure from a result file: no MPI, no PETSc
        from ..io.plot.command import command
        return command(argv[2:])
    old = {s: signal.signal(s, _on_signal) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        return _main(argv)
    except Interrupted as e:
        if e.done is not None:                     # rank 0's results were in place
            said_after(e.signum)
            return e.done
        _say(f"interrupted by {signal.Signals(e.signum).name}; nothing written"
             + (f"; go on with -cont_restart {printable(e.restart)}" if e.restart else ""))
        return 128 + e.signum
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)


def _signal_within(e: BaseException) -> None:
    """Raise the signal's :class:`Interrupted` that ``e`` wraps (:func:`~petsc_adhesion.errors.interrupted_in`),
    for :func:`main` to end the run as interrupted, not failed."""
    signal_ = interrupted_in(e)
    if signal_ is not None:
        raise signal_ from None


def _undecodable(argv: list[str]) -> str | None:
    """The first argument that is not UTF-8 (PETSc cannot take it), said with its option."""
    for i, a in enumerate(argv[1:], 1):
        try:
            a.encode("utf-8")
        except UnicodeEncodeError:
            option = argv[i - 1] if argv[i - 1].startswith("-") else "argument"
            return f"{option}: the file name '{printable(a)}' is not valid UTF-8"
    return None


def input_error(argv: list[str]) -> str | None:
    """What is wrong with ``argv`` (or the options files and environment it reads) that must be said
    before PETSc reads it, in one line; None when nothing is."""
    bad = _undecodable(argv)
    word = stray_word(argv[1:])
    if word is not None and not bad:
        bad = f"'{printable(word)}' is neither an option (they start with '-') nor an option's value"
    if bad:
        return bad
    # PETSc aborts with a page of text on a bad options file: say it in one line first
    for path in options_files(argv):
        bad = file_error(path)
        if bad:
            return bad
    for i, a in enumerate(argv):
        if a == "-options_file_yaml":
            bad = named_file_error(a, argv[i + 1] if i + 1 < len(argv) else "")
            if bad:
                return bad
    return environment_error(argv)


def _program(argv: list[str]) -> int:
    """The run or the study of the options database; its exit status (errors raise)."""
    from petsc4py import PETSc

    from ..errors import collective
    from . import run
    from .options.help import print_help
    from .options.reading import AppOptions

    opts = AppOptions()
    helping = opts.db.hasName("help")
    if helping and PETSc.COMM_WORLD.getRank() == 0:
        print_help()
    # a fit and a study load their modules only when asked for: the fitting code and its scipy parts are
    # a part of a curve's start-up it does not use (docs/performance.md)
    if opts.db.hasName("fit_map"):          # the same on every rank: the options are every rank's
        from . import map as fitmap
        return fitmap.main(opts, argv, helping)
    if collective(PETSc.COMM_WORLD, run.is_fit, opts):
        from . import fit
        return fit.main(opts, argv, helping)
    run.refuse_fit_options(opts)
    from .population import is_population
    if collective(PETSc.COMM_WORLD, is_population, opts):
        from . import population
        return population.main(opts, argv, helping)
    if collective(PETSc.COMM_WORLD, run.is_study, opts):
        from . import study
        return study.main(opts, argv, helping)
    return run.main(opts, argv, helping)


def environment() -> str | None:
    """What in the process's surroundings would make MPI or PETSc fail with a page of text, in one line, or
    None (:func:`petsc_adhesion.singleton.surroundings`)."""
    return surroundings()


def _main(argv: list[str]) -> int:
    bad = input_error(argv)
    fresh = "petsc4py.PETSc" not in sys.modules
    if not bad and fresh:
        bad = environment()
    if bad:
        _say(bad)
        return EXIT_INPUT
    try:
        from ..core.start import start_petsc

        # -version is ours: PETSc's start-up would print its banner (and fail on a closed stdout from 3.21 on)
        start_petsc(argv[:1] if "-version" in argv else argv)   # the handlers of SIGINT, TERM, HUP, PIPE kept
        from petsc4py import PETSc        # PETSc's own libraries, found through PETSC_DIR
    except ImportError as e:
        _say(f"petsc4py cannot be loaded ({first_line(e)}); with PETSC_DIR = "
             f"'{printable(os.environ.get('PETSC_DIR', ''))}': set it to the PETSc petsc4py was built with, or "
             f"unset it (./run sets it up)")
        return EXIT_FAILED
    from mpi4py import MPI

    from ..core import capi
    from ..errors import InputError
    from .options.checks import petsc_error

    try:
        if "-version" in argv:
            if PETSc.COMM_WORLD.getRank() == 0:
                tell(_version())
            return EXIT_OK
        # PETSc runs already in this process (a notebook, a test): the run's own options database
        with nullcontext() if fresh else capi.options_from(argv):
            return _program(argv)
    except InputError as e:
        _say(str(e))
        return EXIT_INPUT
    except PETSc.Error as e:
        why = petsc_error(e)
        _say(str(why) if isinstance(why, InputError) else why)
        return EXIT_INPUT if isinstance(why, InputError) else EXIT_FAILED
    except (RuntimeError, FloatingPointError, OSError) as e:
        _signal_within(e)
        what = f"cannot write '{e.filename}': {e.strerror}" if isinstance(e, OSError) and e.filename \
            else first_line(e)
        _say(what)
        return EXIT_FAILED
    except Exception as e:                                  # a defect: still one line, no hang
        _signal_within(e)
        say(f"internal error on rank {MPI.COMM_WORLD.Get_rank()}: {type(e).__name__}: {printable(first_line(e))}")
        if MPI.COMM_WORLD.Get_size() > 1:
            MPI.COMM_WORLD.Abort(EXIT_FAILED)
        return EXIT_FAILED
