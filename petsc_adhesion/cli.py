"""Command line entry: ``petsc-adhesion [PETSc and application options]``.

    mpiexec -n 2 petsc-adhesion -options_file options/fig5_mu1.opts -snes_monitor

Bad input ends in one line on stderr, exit status 2, and no output file.
"""
from __future__ import annotations

import os
import sys

__all__ = ["main"]


def _options_files(argv: list[str]) -> list[str]:
    return [argv[i + 1] if i + 1 < len(argv) else "" for i, a in enumerate(argv) if a == "-options_file"]


def _error(msg: str, status: int) -> int:
    rank = int(os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0")))
    if rank == 0:
        print(f"petsc-adhesion: error: {msg}", file=sys.stderr)
    return status


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    # PETSc aborts with a page of text on an unreadable options file: say it in one line first
    for path in _options_files(argv):
        if not path or not os.path.isfile(path) or not os.access(path, os.R_OK):
            return _error(f"-options_file: cannot read '{path}'", 2)
    import petsc4py
    petsc4py.init(argv)
    from petsc4py import PETSc

    from .options import InputError, petsc_error
    from .study import main as study

    try:
        return study()
    except InputError as e:
        return _error(str(e), 2)
    except PETSc.Error as e:
        bad = petsc_error(e)
        return _error(str(bad), 2) if bad else _error(f"PETSc error {e.ierr}", 1)
    except (RuntimeError, FloatingPointError) as e:
        return _error(str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__, 1)
