"""PETSc started for this program: its options read from a command line, the process's signal handlers kept.

PETSc's start-up installs handlers of its own for SIGHUP, SIGPIPE, SIGINT and other
signals: on SIGHUP or a broken pipe (``petsc-adhesion ... | head -1``) a run would
end in PETSc's error page and MPI_Abort.  It is started with
``-no_signal_handler`` (taken out of the options database again, so that no file
records it), and the handlers the process had before (Python's: SIGPIPE ignored,
so a write to a closed pipe is an error the writer sees; the command line's:
SIGINT, SIGTERM and SIGHUP end the run in one line) are kept.

Before MPI_Init the process's surroundings are asked (:func:`petsc_adhesion.singleton.surroundings`): an
unwritable TMPDIR in a process that starts MPI itself would end a library call's process in Open MPI's
page and abort; it is a :class:`StartError` in one line with its remedy instead.
"""
from __future__ import annotations

import atexit
import importlib
import signal
import sys
import threading

from ..singleton import surroundings

__all__ = ["start_petsc", "program_name", "KEPT_SIGNALS", "StartError"]

#: The signals whose handlers the process keeps through PETSc's start-up.
KEPT_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGPIPE") if hasattr(signal, name))


class StartError(RuntimeError):
    """MPI cannot start in these surroundings: one line naming what and the remedy."""


def program_name() -> str:
    """The program's name PETSc is started with: sys.argv[0], except where Python gives none that is a name
    (``python -c`` gives '-c', a script on standard input '-', an embedding interpreter ''), which PETSc would
    take for an option of the run (the API then refused '-c: unknown option')."""
    name = sys.argv[0] if sys.argv else ""
    return name if name and not name.startswith("-") else "petsc_adhesion"


def start_petsc(argv: list[str] | None = None) -> bool:
    """Initialise PETSc with ``argv`` (its options) unless it runs already; True when it was started here.

    StartError, before MPI_Init, where the surroundings would make it abort (MPI not yet started by
    anyone: once mpi4py has, its session folder exists and nothing here is asked)."""
    if "petsc4py.PETSc" in sys.modules:
        return False
    if "mpi4py.MPI" not in sys.modules:
        bad = surroundings()
        if bad:
            raise StartError(bad)
    import petsc4py

    kept = {s: signal.getsignal(s) for s in KEPT_SIGNALS}
    argv = list(argv if argv is not None else [program_name()])
    asked = "-no_signal_handler" in argv
    # -help is put in the database after the start-up: PETSc's start-up would print its banner and its
    # debugger options first (ours follow from app/options), and from 3.21 on fail before any handler of
    # ours can say so in one line when standard output cannot be written (a full device)
    helping = [i for i, a in enumerate(argv) if a == "-help"]
    value = None
    if helping:
        i = helping[-1]
        value = argv[i + 1] if i + 1 < len(argv) and not argv[i + 1].startswith("-") else None
        argv = [a for k, a in enumerate(argv) if k not in helping and not (value is not None and k == i + 1)]
    # PETSc installs its handlers early in its start-up, before it prints -help: none at all
    petsc4py.init(argv if asked else argv + ["-no_signal_handler"])
    PETSc = importlib.import_module("petsc4py.PETSc")     # initialises PETSc
    if not asked:                                          # not the run's option: not in its files
        PETSc.Options().delValue("no_signal_handler")
    if helping:
        PETSc.Options().setValue("help", value)
    # Python sets handlers from the main thread only (ValueError elsewhere); from another thread (a web
    # server's, a notebook executor's) PETSc, started without its own, changed none to put back
    if threading.current_thread() is threading.main_thread():
        for s, handler in kept.items():
            if handler is not None:
                signal.signal(s, handler)
    atexit.register(_quiet_finalize, not any(a.lstrip("-") == "options_left" for a in argv))
    return True


def _quiet_finalize(no_options_left: bool) -> None:
    """PETSc's finalize writes nothing to standard output that the command line did not ask for.

    PETSc 3.21 lists the unused options on standard output at PetscFinalize (3.18 does not):
    a refused run's options, the Python interpreter's own arguments; and with -help it prints
    the help of -log_view there.  On a closed or full standard output that write fails and the
    process ends with PETSc's error page after our one line.  We refuse options ourselves
    (app/options), so the list says nothing new (unless -options_left was given); the help was
    printed while the run read its options.  Python's exit handlers run before petsc4py's
    PetscFinalize, so the database is as set here when it is read.
    """
    PETSc = sys.modules.get("petsc4py.PETSc")
    if PETSc is not None and PETSc.Sys.isInitialized() and not PETSc.Sys.isFinalized():
        opts = PETSc.Options()
        if no_options_left:
            opts.setValue("options_left", "0")
        opts.delValue("help")
