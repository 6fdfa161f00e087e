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
"""
from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["OPENMPI_SINGLETON", "launched", "singleton_defaults"]

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
