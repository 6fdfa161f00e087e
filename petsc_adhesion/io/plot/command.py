"""``petsc-adhesion plot RESULT.h5 [-o OUT]``: the figure of any result file, without MPI or PETSc."""
from __future__ import annotations

import errno

import h5py

from .curve import curve_figure, solve_figure

__all__ = ["USAGE", "command"]


USAGE = "usage: petsc-adhesion plot RESULT.h5 [-o OUT.png|OUT.pdf|OUT.svg]   (default OUT: RESULT.png)"


#: The kinds of result file the program writes, each drawn here.
KINDS = ("curve", "solve", "study", "critical", "fit", "map")
#: What begins an HDF5 file (at byte 0, or 512, 1024, ... after a user block).
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
#: What h5py raises on a file damaged inside (a bad symbol table, a heap or an attribute message that
#: runs off its buffer, a truncated dataset): OSError, KeyError, RuntimeError and their like.
DAMAGE = (KeyError, TypeError, ValueError, IndexError, AttributeError, RuntimeError, OSError)


class ReadFailed(Exception):
    """The machine could not read the file (an I/O error of the device): exit 1, not bad input."""


def _is_hdf5(path: str) -> bool:
    """Whether the file begins as HDF5 does (its signature at 0 or at a user block's end)."""
    try:
        with open(path, "rb") as f:
            for offset in (0, 512, 1024, 2048, 4096):
                f.seek(offset)
                if f.read(8) == HDF5_SIGNATURE:
                    return True
    except OSError:
        pass
    return False


def _damaged(path: str, e: BaseException, what: str = "result"):
    """The error to raise for ``e`` met reading ``path``: ReadFailed for the device's I/O error, else InputError
    saying the file is not HDF5, or is a damaged one (h5py's first line, so the user sees where)."""
    from ...errors import InputError, first_line, printable

    if isinstance(e, OSError) and e.errno == errno.EIO:
        return ReadFailed(f"cannot read '{printable(path)}': {e.strerror}")
    if not _is_hdf5(path):
        return InputError(f"plot: '{printable(path)}' is not an HDF5 file")
    return InputError(f"plot: '{printable(path)}' is a damaged or incomplete HDF5 {what}: it cannot be read whole "
                      f"({type(e).__name__}: {printable(first_line(e))[:160]})")


def _kind(path: str) -> str:
    """The ``kind`` of a result file; InputError for what is not one, or one that is damaged."""
    from ...errors import InputError
    from ..inputs import file_problem

    why = file_problem(path)
    if why:
        raise InputError(f"plot: no file '{path}'" if why == "does not exist" else f"plot: '{path}' {why}")
    try:
        with h5py.File(path, "r") as f:
            kind = f.attrs.get("kind")
    except DAMAGE as e:
        raise _damaged(path, e, "file") from None
    kind = kind.decode() if isinstance(kind, bytes) else kind
    if kind not in KINDS:
        raise InputError(f"plot: '{path}' is not a petsc-adhesion result (no {', '.join(KINDS[:-1])} or "
                         f"{KINDS[-1]} kind)")
    return kind


def _draw(kind: str, path: str, out: str, fmt: str) -> None:
    from ..plot import study as studyplot
    from ..plot.fit import fit_figure

    if kind == "fit":
        fit_figure(path, out, fmt)
    elif kind == "map":
        from ..plot.map import map_figure

        map_figure(path, out, fmt)
    elif kind == "curve":
        curve_figure(path, out, fmt)
    elif kind == "solve":
        solve_figure(path, out, fmt)
    elif kind == "critical":
        studyplot.critical_figure(path, out, fmt)
    else:
        with h5py.File(path, "r") as f:
            drawn = f["study"].attrs.get("plot", "curves")
        studyplot.study_figure(path, out, drawn.decode() if isinstance(drawn, bytes) else drawn, fmt)


def command(args: list[str]) -> int:
    """``petsc-adhesion plot RESULT.h5 [-o OUT]``: the figure of a result file, written whole or not at all.

    Returns 0, or 2 after one line on stderr (a missing, foreign or damaged file, a bad argument, an output
    that cannot be written or would overwrite the input), or 1 when the machine cannot read the file (an I/O
    error of its device) or write the figure.
    """
    import os

    from ...errors import InputError, printable, say, tell
    from ..resultset import PLOT_FORMATS, check_targets, plot_format, written

    if args in (["-h"], ["-help"], ["--help"]):
        try:
            tell(USAGE)
        except OSError as e:
            say(f"error: cannot write '{e.filename}': {e.strerror}")
            return 1
        return 0
    try:
        if len(args) not in (1, 3) or (len(args) == 3 and args[1] != "-o") or args[0].startswith("-"):
            raise InputError(f"plot: expected RESULT.h5 [-o OUT], got '{' '.join(args)}' ({USAGE})")
        src = args[0]
        out = args[2] if len(args) == 3 else os.path.splitext(src)[0] + ".png"
        fmt = plot_format(out)
        if fmt is None:
            raise InputError(f"-o: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{out}'")
        kind = _kind(src)
        check_targets({"o": out}, {"plot": [src]})
        with written({"o": out}) as files:
            try:
                _draw(kind, src, files.temp("o"), fmt)
            except DAMAGE as e:
                if isinstance(e, OSError) and e.filename and os.path.abspath(str(e.filename)) != \
                        os.path.abspath(src):                         # our own output
                    raise
                raise _damaged(src, e, f"{kind} result") from None
            files.commit()
    except InputError as e:
        say(f"error: {printable(str(e))}")
        return 2
    except ReadFailed as e:
        say(f"error: {printable(str(e))}")
        return 1
    except OSError as e:
        say(f"error: cannot write '{printable(str(e.filename or out))}': {e.strerror}")
        return 1
    return 0
