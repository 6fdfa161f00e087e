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

Open MPI 4 gives every isolated singleton the same session folder
(``<tmp>/ompi.<host>.<uid>/jf.0/1/0``): a process that ends removes it while
another that starts is making it, and that one's MPI_Init aborts with
"orte_session_dir failed" (``python -m petsc_adhesion.benchmarks.singleton``:
11 of 1,200 starts failed, eight at a time, and none with a folder each; a CI
run of the test suite lost two runs to it).  Each singleton therefore
gets a session folder of its own, named by its process id (:func:`session_folder`);
a folder named so for another process (inherited from the process that started
this one) is replaced, one the user named is kept.

:func:`surroundings` says, before MPI_Init, what in the process's surroundings would make Open MPI's
start-up fail with its page of text and an abort (the command line and the library's start ask it).
"""
from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["OPENMPI_SINGLETON", "SESSION_VARIABLE", "launched", "session_folder", "singleton_defaults",
           "surroundings", "SHARED_MEMORY_VARIABLES", "SHARED_MEMORY_DEFAULT"]

#: Open MPI's variables for a process that talks to no other
OPENMPI_SINGLETON = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_ess_singleton_isolated": "1"}

#: set by Open MPI's mpiexec, PMIx, Slurm's srun and the MPICH/Hydra launchers
_LAUNCHER_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID")


def launched(environ: MutableMapping[str, str] = os.environ) -> bool:
    """Whether a launcher started this process (then it is not a singleton)."""
    return any(v in environ for v in _LAUNCHER_VARIABLES)


#: Open MPI 4's variable that places a job family's session folder (an isolated singleton's whole one)
SESSION_VARIABLE = "OMPI_MCA_orte_jobfam_session_dir"
#: The start of the name of a session folder this module chose (the process id follows)
_SESSION_NAME = "petsc-adhesion-singleton."


def session_folder(environ: MutableMapping[str, str], pid: int) -> str:
    """The session folder of the isolated singleton ``pid``: in the folder Open MPI would use for its
    sessions (``OMPI_MCA_orte_tmpdir_base``, else TMPDIR, else /tmp), ``ompi.<uid>/petsc-adhesion-singleton.<pid>``.
    Open MPI makes it (with its parents) in MPI_Init and removes it in MPI_Finalize; no two live processes
    share a process id, so no two share the folder."""
    base = environ.get("OMPI_MCA_orte_tmpdir_base") or environ.get("TMPDIR") or "/tmp"
    return os.path.join(base, f"ompi.{os.getuid()}", f"{_SESSION_NAME}{pid}")


def _ours_for_another(path: str, pid: int) -> bool:
    """Whether ``path`` is a session folder this module chose for a process other than ``pid``."""
    name = os.path.basename(path)
    return name.startswith(_SESSION_NAME) and name != f"{_SESSION_NAME}{pid}"


def singleton_defaults(environ: MutableMapping[str, str] = os.environ, pid: int | None = None) -> None:
    """Before MPI_Init: :data:`OPENMPI_SINGLETON` where not launched and not set by the user, and, for an
    isolated singleton, a session folder of its own (:func:`session_folder`; ``pid``: this process's id)."""
    if launched(environ):
        return
    for k, v in OPENMPI_SINGLETON.items():
        environ.setdefault(k, v)
    if environ.get("OMPI_MCA_ess_singleton_isolated") != "1":
        return          # Open MPI's daemon gives the process a folder named by its id itself
    pid = os.getpid() if pid is None else pid
    if SESSION_VARIABLE not in environ or _ours_for_another(environ[SESSION_VARIABLE], pid):
        environ[SESSION_VARIABLE] = session_folder(environ, pid)


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
