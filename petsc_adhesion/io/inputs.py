"""Input files judged by what they are before they are opened: a regular, readable file of a sane size, or one line.

Every file option goes through :func:`check_input` before anything reads it
(-options_file and the files PETSC_OPTIONS and .petscrc name, -adh_roughness_file,
-adh_guess, -cont_restart): a FIFO or a terminal would block the read for ever, a
device such as /dev/zero would fill the memory, a directory or a symbolic link
that loops has nothing to read.  ``os.stat`` follows links, so a link to a regular
file is that file.
"""
from __future__ import annotations

import errno
import os
import stat

from ..errors import InputError, printable

__all__ = ["check_input", "file_problem", "size_words", "MAX_INPUT_BYTES"]

#: The largest input file read whole (2 GiB): a height map of 10^8 doubles; nothing larger is plausible.
MAX_INPUT_BYTES = 2 << 30

_KINDS = {stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device", stat.S_IFIFO: "a FIFO",
          stat.S_IFSOCK: "a socket", stat.S_IFDIR: "a directory"}


def size_words(n: float) -> str:
    """``n`` bytes in the largest binary unit that shows it as at least 1 (bytes, KiB, MiB, GiB, TiB), with the
    digits that tell two sizes apart: a limit and a size over it never read the same ('0.0 GiB', '0 GiB')."""
    n = float(n)
    for unit in ("TiB", "GiB", "MiB", "KiB"):
        scale = float(1 << {"KiB": 10, "MiB": 20, "GiB": 30, "TiB": 40}[unit])
        if abs(n) >= scale:
            value = n / scale
            return f"{value:.0f} {unit}" if value == round(value) else f"{value:.3g} {unit}"
    return f"{n:.0f} bytes"


def file_problem(path: str, max_bytes: int = MAX_INPUT_BYTES) -> str | None:
    """Why ``path`` cannot be read as an input file, in words ('is a FIFO', ...), or None when it can."""
    if not path:
        return "is an empty name"
    try:
        st = os.stat(path)
    except OSError as e:
        if e.errno == errno.ELOOP:
            return "is a symbolic link that loops"
        if e.errno == errno.ENOENT:
            return "does not exist" if not os.path.islink(path) else "is a symbolic link to nothing"
        return f"cannot be read ({e.strerror})"
    kind = stat.S_IFMT(st.st_mode)
    if kind != stat.S_IFREG:
        return f"is {_KINDS.get(kind, 'not a regular file')}, not a regular file"
    if not os.access(path, os.R_OK):
        return "cannot be read (permission denied)"
    if st.st_size > max_bytes:
        has, limit = size_words(st.st_size), size_words(max_bytes)
        if has == limit:                       # just over the limit: the bytes tell them apart
            has, limit = f"{st.st_size} bytes", f"{max_bytes} bytes ({limit})"
        return f"has {has}, more than the {limit} read whole"
    return None


def check_input(option: str, path: str, max_bytes: int = MAX_INPUT_BYTES) -> None:
    """InputError naming ``-option`` unless ``path`` is a regular, readable file of at most ``max_bytes``."""
    why = file_problem(path, max_bytes)
    if why == "does not exist":
        raise InputError(f"-{option}: no file '{printable(path)}'")
    if why:
        raise InputError(f"-{option}: '{printable(path)}' {why}")
