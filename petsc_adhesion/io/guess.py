"""The initial guess of a fixed-approach solve, read from the HDF5 file of an earlier one (-adh_guess)."""
from __future__ import annotations

import numpy as np

from ..errors import InputError, first_line, printable
from .inputs import check_input

__all__ = ["read_guess"]


def read_guess(path: str, wall: float) -> tuple[np.ndarray, np.ndarray]:
    """(r, H) of the -out file of a fixed-approach solve at ``path``, checked: two real vectors of one length, r
    finite and increasing, H finite and above ``wall`` (the pressure law's); one line naming -adh_guess else."""
    shown = printable(path)
    check_input("adh_guess", path)
    try:
        import h5py
        with h5py.File(path, "r") as f:
            r0, h0 = f["grid/r"][()], f["solution/H"][()]
    except (OSError, KeyError, TypeError, ValueError, IndexError, AttributeError, RuntimeError) as e:
        # a file damaged inside: h5py raises any of these (RuntimeError from a heap or an attribute message
        # that runs off its buffer)
        raise InputError(f"-adh_guess: cannot read grid/r and solution/H from '{shown}' "
                         f"({printable(first_line(e))}); give the -out file of a fixed-approach solve") from None
    if not (np.issubdtype(r0.dtype, np.floating) and np.issubdtype(h0.dtype, np.floating)
            and r0.ndim == h0.ndim == 1 and r0.size == h0.size >= 2):
        raise InputError(f"-adh_guess: grid/r and solution/H in '{shown}' are not two real vectors of one length")
    if not (np.all(np.isfinite(r0)) and np.all(np.diff(r0) > 0)):
        raise InputError(f"-adh_guess: grid/r in '{shown}' is not finite and increasing")
    if not np.all(np.isfinite(h0)) or np.any(h0 <= wall):
        raise InputError(f"-adh_guess: H in '{shown}' is not finite and above the wall {wall:g}")
    return r0, h0
