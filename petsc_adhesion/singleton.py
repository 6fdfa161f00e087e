"""How a process started without ``mpiexec`` (an MPI singleton) initialises Open MPI.

Open MPI 4's singleton start-up forks a runtime daemon and probes the UCX
network layer before MPI_Init returns: 300 to 400 ms on every plain run, a
notebook's first call and each test subprocess, for a process that never sends
a message.  One process needs neither, so a singleton is asked for the
shared-memory point-to-point layer (``pml ob1``) and no daemon
(``ess_singleton_isolated``); MPI_Init then takes about 30 ms.  A variable
the user set wins, a process launched by ``mpiexec``, ``srun`` or any PMI
launcher is left alone, and other MPI libraries ignore Open MPI's variables.
Processes this one starts inherit the variables (harmless on one machine;
:mod:`petsc_adhesion.benchmarks.leaveout` strips them before its own ``mpiexec``).

:func:`surroundings` says, before MPI_Init, what in the process's surroundings would make Open MPI's
start-up fail with its page of text and an abort (the command line and the library's start ask it).
"""
from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["OPENMPI_SINGLETON", "launched", "singleton_defaults", "surroundings", "SHARED_MEMORY_VARIABLES",
           "SHARED_MEMORY_DEFAULT"]

#: Open MPI's variables for a process that talks to no other
OPENMPI_SINGLETON = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_ess_singleton_isolated": "1"}

#: set by Open MPI's mpiexec, PMIx, Slurm's srun and the MPICH/Hydra launchers
_LAUNCHER_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID")


def launched(environ: MutableMapping[str, str] = os.environ) -> bool:
    """Whether a launcher started this process (then it is not a singleton)."""
    return any(v in environ for v in _LAUNCHER_VARIABLES)


def singleton_defaults(environ: MutableMapping[str, str] = os.environ) -> None:
    """Before MPI_Init: :data:`OPENMPI_SINGLETON` where not launched and not set by the user."""
    if not launched(environ):
        for k, v in OPENMPI_SINGLETON.items():
            environ.setdefault(k, v)


#: Where Open MPI's shared-memory transport keeps its segments, the variable that moves it (Open MPI 4's vader,
#: 5's sm), and its default.
SHARED_MEMORY_VARIABLES = ("OMPI_MCA_btl_vader_backing_directory", "OMPI_MCA_btl_sm_backing_directory")
SHARED_MEMORY_DEFAULT = "/dev/shm"


def _writable_directory(path: str) -> bool:
    return os.path.isdir(path) and os.access(path, os.W_OK | os.X_OK)


def _printable(text: str) -> str:
    """``text`` with control characters and undecodable bytes escaped, for one line (errors.printable's rule;
    this leaf module imports nothing of the package)."""
    text = text.encode("utf-8", errors="surrogateescape").decode("utf-8", errors="backslashreplace")
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def surroundings(environ: MutableMapping[str, str] = os.environ) -> str | None:
    """What in the process's surroundings would make MPI or PETSc fail with a page of text, in one line with
    its remedy, or None; asked before MPI_Init.

    - a working directory that was removed (PETSc reads .petscrc there);
    - a TMPDIR that is not a writable directory, where this process's MPI_Init makes Open MPI's session
      folder: a singleton's (measured: Open MPI 4's orte_init fails, MPI_Init aborts the process).  Under
      Open MPI's mpiexec the launcher has made that folder before any rank runs (its own failure there is its
      own text, before any code of ours), and a rank's TMPDIR is not read by MPI_Init (measured: two ranks
      with TMPDIR a file start and run), so it is not asked there;
    - on several ranks, a shared-memory folder (/dev/shm, or the one Open MPI is told to use) the ranks
      cannot make their segments in (Open MPI's page of warnings at MPI_Init, or its abort).  One process
      alone makes no segment (measured: a singleton runs with that folder unusable), so it is not asked.
    """
    try:
        os.getcwd()
    except OSError:
        return "the working directory no longer exists (it was removed): change to one that does"
    tmp = environ.get("TMPDIR")
    if tmp is not None and "OMPI_COMM_WORLD_SIZE" not in environ and not _writable_directory(tmp):
        return f"TMPDIR: '{_printable(tmp)}' is not a writable directory (MPI keeps its session files there): " \
               f"set it to one that is, or unset it"
    size = environ.get("OMPI_COMM_WORLD_SIZE", "1")
    if size.isdigit() and int(size) > 1:
        named = next((v for v in SHARED_MEMORY_VARIABLES if environ.get(v)), None)
        shm = environ[named] if named else SHARED_MEMORY_DEFAULT
        if not _writable_directory(shm):
            where = f"{named}: '{_printable(shm)}'" if named else f"'{shm}'"
            remedy = "set it to a writable folder, or unset it" if named else \
                f"mount it writable (a tmpfs), or set {SHARED_MEMORY_VARIABLES[0]} to a writable folder such as /tmp"
            return f"{where} is not a writable directory (the ranks share memory through files there): {remedy}"
    return None
