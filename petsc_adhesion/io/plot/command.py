"""``petsc-adhesion plot RESULT.h5 [-o OUT]``: the figure of any result file, without MPI or PETSc."""
from __future__ import annotations

import h5py

from .curve import curve_figure, solve_figure

__all__ = ["USAGE", "command"]


USAGE = "usage: petsc-adhesion plot RESULT.h5 [-o OUT.png|OUT.pdf|OUT.svg]   (default OUT: RESULT.png)"


def _kind(path: str) -> str:
    """The ``kind`` of a result file; InputError for what is not one."""
    from ...errors import InputError
    from ..inputs import file_problem

    why = file_problem(path)
    if why:
        raise InputError(f"plot: no file '{path}'" if why == "does not exist" else f"plot: '{path}' {why}")
    try:
        with h5py.File(path, "r") as f:
            kind = f.attrs.get("kind")
    except OSError:
        raise InputError(f"plot: '{path}' is not an HDF5 file") from None
    kind = kind.decode() if isinstance(kind, bytes) else kind
    if kind not in ("curve", "solve", "study", "critical"):
        raise InputError(f"plot: '{path}' is not a petsc-adhesion result (no curve, solve, study or critical kind)")
    return kind


def _draw(kind: str, path: str, out: str, fmt: str) -> None:
    from ..plot import study as studyplot

    if kind == "curve":
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

    Returns 0, or 2 after one line on stderr (a missing or foreign file, a bad argument, an output
    that cannot be written or would overwrite the input).
    """
    import os

    from ...errors import InputError, first_line, printable, say, tell
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
            except (KeyError, TypeError, ValueError, IndexError, AttributeError, OSError) as e:
                if isinstance(e, OSError) and e.filename:             # our own output
                    raise
                raise InputError(f"plot: '{src}' is not a whole {kind} result ({type(e).__name__}: "
                                 f"{first_line(e)})") from None
            files.commit()
    except InputError as e:
        say(f"error: {printable(str(e))}")
        return 2
    except OSError as e:
        say(f"error: cannot write '{printable(str(e.filename or out))}': {e.strerror}")
        return 1
    return 0
