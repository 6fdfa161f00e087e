"""Shared fixtures: petsc4py initialised once, and runners for the command line."""
import os
import shutil
import subprocess
import sys
import tempfile

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
    # Hundreds of tests start the program: without compiled modules (PYTHONDONTWRITEBYTECODE, as some shells
    # and CI images set it) each start compiles the package again, 0.15-0.2 s of its 0.65-0.85 s of CPU
    # (a fixed solve on 41 nodes, measured); they are kept outside the checkout, as the variable wants it
    if env.get("PYTHONDONTWRITEBYTECODE") and not env.get("PYTHONPYCACHEPREFIX"):
        del env["PYTHONDONTWRITEBYTECODE"]
        env["PYTHONPYCACHEPREFIX"] = PYCACHE
    return env


#: Where the programs the tests start keep their compiled modules when the environment says not to write
#: them beside the sources (see _env)
PYCACHE = os.path.join(tempfile.gettempdir(), f"petsc-adhesion-tests-pycache-{os.getuid()}")


def _ranks_core():
    """The one core all the ranks of this worker's mpiexec runs share, or None when the cores are enough for
    every worker's two ranks.

    A waiting rank of Open MPI (or MPICH) spins: with yield_when_idle it calls sched_yield in a loop, which
    costs a core while the other rank works.  Two ranks on a core of their own therefore cost two cores; with
    two pytest-xdist workers on two cores they compete with the other worker and with each other, and every
    collective waits for a rank the kernel has set aside.  Measured (mpiexec -n 2, -study_compute critical
    -study_sigma 0 -study_ranks 2, under a load of 15): 180 s wall and 48 s of CPU (26 s system) on two cores;
    70 s and 17 s on one core, where a waiting rank's yield hands the core to the one it waits for.  The
    ranks' numbers are the same either way (their placement is no input of the run)."""
    cpus = sorted(os.sched_getaffinity(0))
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    if len(cpus) >= 2 * workers or shutil.which("taskset") is None:
        return None
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    return cpus[int(worker[2:]) % len(cpus) if worker[2:].isdigit() else 0]


def _open_mpi(mpiexec: str) -> bool:
    """Whether ``mpiexec`` is Open MPI's (it binds two ranks to two cores of its own choice by default)."""
    if mpiexec not in _OPEN_MPI:
        try:
            v = subprocess.run([mpiexec, "--version"], capture_output=True, text=True, timeout=60).stdout
        except (OSError, subprocess.SubprocessError):
            v = ""
        _OPEN_MPI[mpiexec] = "Open MPI" in v or "OpenRTE" in v
    return _OPEN_MPI[mpiexec]


_OPEN_MPI: dict = {}


def mpiexec(n: int) -> list:
    """The command that starts ``n`` ranks, before the program's: ``mpiexec -n n``, and on a machine whose
    cores are fewer than the workers' ranks, all of them on one core (:func:`_ranks_core`: ``taskset``, and
    Open MPI's own binding off, which would move them back to a core each).  Skips the test without mpiexec."""
    path = shutil.which("mpiexec")
    if path is None:
        pytest.skip("mpiexec not found")
    core = _ranks_core()
    if core is None:
        return [path, "-n", str(n)]
    return [shutil.which("taskset"), "-c", str(core), path, *(["--bind-to", "none"] if _open_mpi(path) else []),
            "-n", str(n)]


def run_cli(*args, np=1, cwd=None, timeout=600):
    """Run petsc-adhesion (on ``np`` ranks through mpiexec) and return the CompletedProcess."""
    cmd = [sys.executable, "-m", "petsc_adhesion", *map(str, args)]
    if np > 1:
        cmd = [*mpiexec(np), *cmd]
    return subprocess.run(cmd, cwd=cwd or ROOT, env=_env(), capture_output=True, text=True, timeout=timeout)


def in_process(*args, cwd=None):
    """petsc-adhesion's ``main`` run in this process with ``args`` (its own options; PETSc is initialised once,
    above), in the folder ``cwd`` (default: this one), and a CompletedProcess of its exit status and what it
    wrote to Python's stdout and stderr: the program without the start of a process of its own (about 1 CPU s:
    python -m petsc_adhesion -help took 0.98), for tests that run many cheap curves or set-ups.  Call it from
    the main thread (main sets signal handlers), one run at a time."""
    import contextlib
    import io

    from petsc_adhesion.app.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(cwd or os.getcwd()), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(["petsc-adhesion", *map(str, args)])
    return subprocess.CompletedProcess(list(args), status, out.getvalue(), err.getvalue())


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


#: The files whose tests take longest (a 2-worker run's --durations, 20.8 min: two-rank runs, the fuzz, killed
#: runs, refinements), longest first.  pytest-xdist's --dist loadfile hands a worker a whole file at a time,
#: in the order of collection: alphabetically, the long test_sweep.py, test_spring.py and test_soft.py came
#: near the end, where one of them could run on one worker with the other idle.  Handed out first, the short
#: files fill the gaps at the end (the longest-first rule of scheduling on two machines).
LONGEST_FIRST = ("test_extremes.py", "test_sweep.py", "test_critical.py", "test_checkpoint.py", "test_fuzz.py",
                 "test_checkpoint_study.py",
                 "test_fitting.py", "test_hostile.py", "test_soft.py", "test_error_estimate.py", "test_spring.py",
                 "test_kill.py", "test_continuation.py", "test_fit_instrument.py")


def pytest_collection_modifyitems(items):
    """The files of LONGEST_FIRST before the rest, each file's tests in their order (a stable sort)."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))
