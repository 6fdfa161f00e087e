"""How often MPI_Init fails when isolated singletons start and end at once: one session folder for all (Open
MPI 4's) against a folder each (petsc_adhesion/singleton.py's).

    python -m petsc_adhesion.benchmarks.singleton [-starts 1200] [-at_once 8]

Each start is a Python process that imports mpi4py and initialises MPI as a singleton (``pml ob1``,
``ess_singleton_isolated``), ``-at_once`` of them at a time, ``-starts`` in all, for each of the two ways;
it prints the starts that failed (MPI_Init aborted) and Open MPI's reason for the first.  Open MPI 4.1
puts every isolated singleton's session in ``<tmp>/ompi.<host>.<uid>/jf.0/1/0``; a process that ends
removes the folder while another is making it.  A measurement of a race, not a test: its count varies
from run to run, and on a machine with fewer cores the windows meet less often.
"""
from __future__ import annotations

import concurrent.futures
import os
import subprocess
import sys
import time

from ..singleton import OPENMPI_SINGLETON, SESSION_VARIABLE
from ._args import OneLineParser

__all__ = ["race", "main"]

#: The child: this package's singleton defaults read from the module's file alone (the leaf imports only os;
#: the package's own import would dominate the start), then MPI_Init.
_CHILD = ("import importlib.util, sys; spec = importlib.util.spec_from_file_location('s', sys.argv[1]); "
          "s = importlib.util.module_from_spec(spec); spec.loader.exec_module(s); "
          "sys.argv[2] == 'own' and s.singleton_defaults(); "
          "from mpi4py import MPI; MPI.COMM_WORLD.Get_size()")
_MODULE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "singleton.py")


def _environment() -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PMIX_", "OMPI_")) and k != SESSION_VARIABLE}
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env | OPENMPI_SINGLETON


def _start(way: str, env: dict) -> str | None:
    p = subprocess.run([sys.executable, "-c", _CHILD, _MODULE, way], env=env, capture_output=True, text=True)
    return None if p.returncode == 0 else p.stderr


def race(way: str, starts: int, at_once: int) -> tuple[int, str | None, float]:
    """The failed starts of ``starts`` singletons, ``at_once`` at a time, with ``way`` ("shared": Open MPI's
    one folder; "own": :func:`petsc_adhesion.singleton.singleton_defaults`), the first failure's text and the
    wall time (s)."""
    env, t0 = _environment(), time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(at_once) as pool:
        failures = [e for e in pool.map(lambda _: _start(way, env), range(starts)) if e is not None]
    return len(failures), (failures[0] if failures else None), time.perf_counter() - t0


def _reason(text: str) -> str:
    keys = ("orte_session_dir failed", "Directory:", "Error:")
    return "; ".join(ln.strip() for ln in text.splitlines() if ln.strip().startswith(keys))[:300]


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(prog="python -m petsc_adhesion.benchmarks.singleton", label="singleton",
                           description=__doc__.split("\n\n")[0])
    parser.add_argument("-starts", type=int, default=1200, help="processes started for each way (default 1200)")
    parser.add_argument("-at_once", type=int, default=8, help="processes running at a time (default 8)")
    a = parser.parse_args(argv)
    for name in ("starts", "at_once"):
        if getattr(a, name) < 1:
            parser.error(f"-{name}: takes a positive whole number, got {getattr(a, name)}")
    print(f"{a.starts} isolated singleton starts, {a.at_once} at a time, load {os.getloadavg()[0]:.1f}")
    for way, name in (("shared", "one session folder for all (Open MPI 4's)"),
                      ("own", "a folder each (petsc-adhesion's singleton defaults)")):
        failed, first, wall = race(way, a.starts, a.at_once)
        print(f"  {name}: {failed} of {a.starts} failed ({wall:.0f} s)"
              + (f"; the first: {_reason(first)}" if first else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
