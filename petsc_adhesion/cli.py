"""Command line entry: ``petsc-adhesion [PETSc and application options]``.

    mpiexec -n 2 petsc-adhesion -options_file options/fig5_mu1.opts -arc_snes_monitor

Bad input ends in one line on stderr, exit status 2, and no output file.
"""
from __future__ import annotations

import os
import sys

__all__ = ["main"]


def _options_files(argv: list[str]) -> list[str]:
    """The files named by -options_file on the command line."""
    return [argv[i + 1] if i + 1 < len(argv) else "" for i, a in enumerate(argv) if a == "-options_file"]


def _options_file_error(path: str) -> str | None:
    """What PETSc would abort on in an options file, said in one line (None: fine).

    Its syntax: a line is '-name [value]' or 'alias -name -other', '#' and '!'
    start comments; a nested -options_file is checked too.
    """
    if not path or not os.path.isfile(path) or not os.access(path, os.R_OK):
        return f"-options_file: cannot read '{path}'"
    with open(path, errors="replace") as f:
        for n, line in enumerate(f, 1):
            tokens = line.split("#")[0].split("!")[0].split()
            ok = not tokens or (tokens[0] == "alias" and len(tokens) == 3) or \
                (tokens[0].startswith("-") and len(tokens) <= 2)
            if not ok:
                return f"-options_file {path}: line {n}: expected '-name [value]', got '{line.strip()}'"
            if tokens and tokens[0] == "-options_file":
                inner = _options_file_error(tokens[1] if len(tokens) > 1 else "")
                if inner:
                    return inner
    return None


def _error(msg: str, status: int) -> int:
    """Say ``msg`` once, on rank 0's stderr; return the exit status."""
    from mpi4py import MPI

    if MPI.COMM_WORLD.Get_rank() == 0:
        print(f"petsc-adhesion: error: {msg}", file=sys.stderr, flush=True)
    return status


def main(argv: list[str] | None = None) -> int:
    """Run the program on ``argv`` (default: sys.argv); the exit status: 0, 1 (failed), 2 (bad input)."""
    argv = list(sys.argv if argv is None else argv)
    # PETSc aborts with a page of text on a bad options file: say it in one line first
    for path in _options_files(argv):
        bad = _options_file_error(path)
        if bad:
            return _error(bad, 2)
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
    except OSError as e:
        return _error(f"cannot write '{e.filename}': {e.strerror}", 1)
    except (RuntimeError, FloatingPointError) as e:
        return _error(str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__, 1)
