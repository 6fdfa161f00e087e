"""Results to files: HDF5 (h5py) and a JSON summary, written by rank 0, atomically.

A file is written under a temporary name in its target directory and renamed
into place, so a reader never sees a partial file and a failed run leaves none.
"""
from __future__ import annotations

import json
import os
import tempfile
from contextlib import contextmanager

import numpy as np

from .options import InputError

__all__ = ["check_writable", "write_h5", "write_json", "atomic"]


def check_writable(option: str, path: str | None) -> None:
    """Fail early, before any work, when ``path`` cannot be created (by trying)."""
    if path is None:
        return
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise InputError(f"-{option}: '{path}' is a directory")
    if not os.path.isdir(folder):
        raise InputError(f"-{option}: cannot write '{path}' (no directory '{folder}')")
    try:
        with atomic(path, keep=False):
            pass
    except OSError as e:
        raise InputError(f"-{option}: cannot write '{path}' ({e.strerror})") from None


@contextmanager
def atomic(path: str, keep: bool = True):
    """Yield a temporary path next to ``path``; rename it to ``path`` on success (``keep``)."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=folder)
    os.close(fd)
    try:
        yield tmp
        if keep:
            os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def _attrs(node, d: dict) -> None:
    for k, v in d.items():
        node.attrs[k] = "" if v is None else v


def _write(group, tree: dict) -> None:
    """Dicts become groups; arrays datasets; scalars and strings attributes."""
    for key, val in tree.items():
        if isinstance(val, dict):
            _write(group.require_group(key), val)
        elif isinstance(val, (list, tuple)) and val and isinstance(val[0], dict):
            sub = group.require_group(key)
            for i, item in enumerate(val):
                _write(sub.require_group(f"{i:04d}"), item)
        elif isinstance(val, np.ndarray):
            group.create_dataset(key, data=val)
        else:
            _attrs(group, {key: val})


def write_h5(path: str, tree: dict) -> None:
    import h5py

    with atomic(path) as tmp:
        with h5py.File(tmp, "w") as f:
            _write(f, tree)


def _plain(x):
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x


def write_json(path: str, summary: dict) -> None:
    with atomic(path) as tmp:
        with open(tmp, "w") as f:
            json.dump(_plain(summary), f, indent=1, allow_nan=False)
            f.write("\n")
