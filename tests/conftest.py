"""Shared fixtures: petsc4py initialised once, and runners for the command line."""
import os
import shutil
import subprocess
import sys

import petsc4py
import pytest

# the program's name as the library takes it: in pytest-xdist's workers sys.argv[0] is '-c', an option to PETSc
petsc4py.init([sys.argv[0] if sys.argv[0] and not sys.argv[0].startswith("-") else "pytest"])

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# the benchmarks read docs/ and options/ of this checkout, wherever pytest runs from
os.environ.setdefault("PETSC_ADHESION_CHECKOUT", ROOT)


#: What Open MPI's start of this process as a singleton puts into its environment (a pytest-xdist worker's
#: start is not isolated: OMPI_MCA_ess=singleton, the address of its PMIx server, ...): an mpiexec a test starts
#: with them exits 1 without a word; they are no setting of the user's.
_MPI_STARTED = ("PMIX_", "PMI_", "OMPI_COMMAND", "OMPI_ARGV", "OMPI_MCA_ess", "OMPI_MCA_orte_", "OMPI_MCA_pmix",
                "OMPI_COMM_WORLD_", "OMPI_UNIVERSE_SIZE", "OMPI_FILE_LOCATION", "OMPI_APP_CTX", "OMPI_FIRST_RANKS",
                "OMPI_NUM_APP_CTX", "OMPI_MCA_initial_wdir", "OMPI_MCA_shmem_RUNTIME")


def _mpi_started(key: str) -> bool:
    return key.startswith(_MPI_STARTED)


def _env():
    # PETSC_DIR is the environment's business (./run and the venv set it for Debian's PETSc)
    env = {k: v for k, v in os.environ.items() if not _mpi_started(k)}
    env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    # this checkout's package, also for a script run from another folder (not the one the venv installed)
    env["PYTHONPATH"] = os.pathsep.join([ROOT, *filter(None, [os.environ.get("PYTHONPATH")])])
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    env.setdefault("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
    # a waiting rank yields its core: the suite's workers (pytest-xdist) share the cores with the ranks a test
    # starts, and Open MPI's busy wait on a machine it does not know is full slows a two-rank run many times
    env.setdefault("OMPI_MCA_mpi_yield_when_idle", "1")
    return env


def run_cli(*args, np=1, cwd=None, timeout=600):
    """Run petsc-adhesion (on ``np`` ranks through mpiexec) and return the CompletedProcess."""
    cmd = [sys.executable, "-m", "petsc_adhesion", *map(str, args)]
    if np > 1:
        mpiexec = shutil.which("mpiexec")
        if mpiexec is None:
            pytest.skip("mpiexec not found")
        cmd = [mpiexec, "-n", str(np), *cmd]
    return subprocess.run(cmd, cwd=cwd or ROOT, env=_env(), capture_output=True, text=True, timeout=timeout)


def drawn_figure(path):
    """The first figure the plot of the result file ``path`` makes (``io/plot/curve.py``'s ``curve_figure``,
    drawn to nowhere), for a test to read its panels."""
    from petsc_adhesion.io.plot import curve as plot_curve

    made = []
    real = plot_curve.figure

    def keep(**kw):
        made.append(real(**kw))
        return made[-1]

    plot_curve.figure = keep
    try:
        plot_curve.curve_figure(str(path), os.devnull)
    finally:
        plot_curve.figure = real
    return made[0]


@pytest.fixture
def cli():
    return run_cli


def make_problem(mu=1.0, sigma=0.0, r=None, pmat="dense", **model):
    """A Problem and its fixed-approach Newton solver on grid r (default: uniform, 201 nodes)."""
    from petsc_adhesion.discretization import grid, preconditioning
    from petsc_adhesion.discretization.influence import create_influence
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.discretization.problem import Problem
    from petsc_adhesion.core.newton import Newton

    r = grid.uniform(201, 10.0) if r is None else r
    pb = Problem(Model(mu=mu, sigma=sigma, **model), r, create_influence(r), preconditioning.create(pmat))
    return pb, Newton(pb)
