"""``petsc-adhesion plot RESULT.h5 [-o OUT]``: the figure of any result file, without MPI or PETSc."""
from __future__ import annotations

import h5py

from .curve import curve_figure, solve_figure

__all__ = ["USAGE", "command"]


USAGE = "usage: petsc-adhesion plot RESULT.h5 [-o OUT.png|OUT.pdf|OUT.svg]   (default OUT: RESULT.png)"


def _kind(path: str) -> str:
    """The ``kind`` of a result file; InputError for what is not one."""
    import os

    from ...errors import InputError

    if not os.path.isfile(path):
        raise InputError(f"plot: no file '{path}'")
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

    from ...errors import InputError, say
    from ..resultset import PLOT_FORMATS, check_targets, written

    if args in (["-h"], ["-help"], ["--help"]):
        print(USAGE)
        return 0
    try:
        if len(args) not in (1, 3) or (len(args) == 3 and args[1] != "-o") or args[0].startswith("-"):
            raise InputError(f"plot: expected RESULT.h5 [-o OUT], got '{' '.join(args)}' ({USAGE})")
        src = args[0]
        out = args[2] if len(args) == 3 else os.path.splitext(src)[0] + ".png"
        ext = os.path.splitext(out)[1].lower()
        if ext not in PLOT_FORMATS:
            raise InputError(f"-o: expected a file name ending in {', '.join(PLOT_FORMATS)}, got '{out}'")
        kind = _kind(src)
        check_targets({"o": out}, {"plot": [src]})
        with written({"o": out}) as files:
            _draw(kind, src, files.temp("o"), PLOT_FORMATS[ext])
            files.commit()
    except InputError as e:
        say(f"error: {e}")
        return 2
    return 0
