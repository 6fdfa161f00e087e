"""PETSc C functions that petsc4py 3.18 does not bind, called through ctypes; what newer petsc4py does otherwise.

The symbols come from the PETSc library that petsc4py's extension module
already links, so they are the same PETSc the rest of the program uses.
Newer petsc4py binds some of these; one path for all versions is simpler.
From petsc4py 3.22 on an exception raised in a Python callback (a residual, a
shell Jacobian) comes out of the PETSc call as PETSc.Error 101 with the
callback's exception as its cause; :func:`python_errors` gives the caller the
callback's own exception with every version.
"""
from __future__ import annotations

import ctypes
from contextlib import contextmanager
from functools import lru_cache

import numpy as np
from petsc4py import PETSc

__all__ = ["options_left", "error_message", "set_linesearch_type", "linesearch_type", "options_from", "options_of", "python_errors"]


@contextmanager
def python_errors():
    """Around a PETSc call that calls back into Python: the callback's own exception, not petsc4py's wrapper.

    petsc4py 3.18 to 3.21 re-raise a callback's exception as it is; 3.22 and later raise
    PETSc.Error (101, "Unhandled Python Exception") from it, and the domain guard's,
    the signal handlers' and the problems' own exceptions would all read as PETSc errors
    (measured with petsc4py 3.26: the guard test and a SIGTERM during the error bars), and a callback
    called from within another (a shell Jacobian's product inside SNES) is wrapped at each level
    (a SIGTERM during a corrector: PETSc.Error from PETSc.Error from the signal's exception).
    """
    try:
        yield
    except PETSc.Error as e:
        # a callback inside a callback (a shell matrix's product inside SNES) wraps it once more
        cause = e.__cause__
        while isinstance(cause, PETSc.Error):
            cause = cause.__cause__
        if cause is None:
            raise
        raise cause.with_traceback(cause.__traceback__) from None


@lru_cache(maxsize=None)
def _lib() -> ctypes.CDLL:
    return ctypes.CDLL(PETSc.__file__)


def _petsc_int():
    return ctypes.c_int64 if np.dtype(PETSc.IntType).itemsize == 8 else ctypes.c_int32


def options_left() -> list[str]:
    """Names of the options in the database that no object has read (PetscOptionsLeftGet)."""
    lib = _lib()
    argtypes = [ctypes.c_void_p, ctypes.POINTER(_petsc_int()),
                ctypes.POINTER(ctypes.POINTER(ctypes.c_char_p)),
                ctypes.POINTER(ctypes.POINTER(ctypes.c_char_p))]
    get, restore = lib.PetscOptionsLeftGet, lib.PetscOptionsLeftRestore
    get.argtypes = restore.argtypes = argtypes
    n = _petsc_int()()
    names = ctypes.POINTER(ctypes.c_char_p)()
    values = ctypes.POINTER(ctypes.c_char_p)()
    if get(None, ctypes.byref(n), ctypes.byref(names), ctypes.byref(values)):
        raise RuntimeError("PetscOptionsLeftGet failed")
    left = [names[i].decode() for i in range(n.value)]
    restore(None, ctypes.byref(n), ctypes.byref(names), ctypes.byref(values))
    return left


def error_message(ierr: int) -> str:
    """PETSc's message for its last error of code ``ierr`` (PetscErrorMessage): the specific one if kept."""
    get = _lib().PetscErrorMessage
    get.argtypes = [ctypes.c_int, ctypes.POINTER(ctypes.c_char_p), ctypes.POINTER(ctypes.c_char_p)]
    text, specific = ctypes.c_char_p(), ctypes.c_char_p()
    get(ierr, ctypes.byref(text), ctypes.byref(specific))
    return (specific.value or text.value or b"").decode(errors="replace").strip()


def set_linesearch_type(snes: PETSc.SNES, kind: str) -> None:
    """Set the line search of ``snes`` (SNESGetLineSearch, SNESLineSearchSetType).

    Called before ``setFromOptions()``, it is a default the user's
    ``-snes_linesearch_type`` (with the solver's prefix) still overrides.
    """
    lib = _lib()
    ls = ctypes.c_void_p()
    lib.SNESGetLineSearch.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_void_p)]
    lib.SNESLineSearchSetType.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
    if lib.SNESGetLineSearch(ctypes.c_void_p(snes.handle), ctypes.byref(ls)) or \
            lib.SNESLineSearchSetType(ls, kind.encode()):
        raise RuntimeError(f"cannot set the line search type '{kind}'")


def linesearch_type(snes: PETSc.SNES) -> str:
    """The line search type of ``snes`` as PETSc has it (SNESGetLineSearch, SNESLineSearchGetType)."""
    lib = _lib()
    ls, kind = ctypes.c_void_p(), ctypes.c_char_p()
    lib.SNESGetLineSearch.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_void_p)]
    lib.SNESLineSearchGetType.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_char_p)]
    if lib.SNESGetLineSearch(ctypes.c_void_p(snes.handle), ctypes.byref(ls)) or \
            lib.SNESLineSearchGetType(ls, ctypes.byref(kind)):
        raise RuntimeError("cannot get the line search type")
    return (kind.value or b"").decode()


@contextmanager
def _pushed():
    """A fresh, empty options database, the global one for the block (PetscOptionsCreate,
    PetscOptionsPush); the caller's comes back after (PetscOptionsPop, PetscOptionsDestroy)."""
    lib = _lib()
    lib.PetscOptionsCreate.argtypes = [ctypes.POINTER(ctypes.c_void_p)]
    lib.PetscOptionsPush.argtypes = [ctypes.c_void_p]
    lib.PetscOptionsDestroy.argtypes = [ctypes.POINTER(ctypes.c_void_p)]
    db = ctypes.c_void_p()
    if lib.PetscOptionsCreate(ctypes.byref(db)) or lib.PetscOptionsPush(db):
        raise RuntimeError("cannot make an options database")
    try:
        yield
    finally:
        lib.PetscOptionsPop()
        lib.PetscOptionsDestroy(ctypes.byref(db))


@contextmanager
def options_from(argv: list[str]):
    """A fresh options database holding ``argv``'s options, as PETSc's start-up reads them
    (arguments, -options_file, PETSC_OPTIONS, .petscrc: PetscOptionsInsert, collective on
    PETSC_COMM_WORLD), the global one for the block."""
    lib, ptr = _lib(), ctypes.POINTER
    lib.PetscOptionsInsert.argtypes = [ctypes.c_void_p, ptr(ctypes.c_int), ptr(ptr(ctypes.c_char_p)), ctypes.c_char_p]
    with _pushed():
        args = [a.encode("utf-8", errors="surrogateescape") for a in argv]
        argc = ctypes.c_int(len(args))
        array = ctypes.cast((ctypes.c_char_p * len(args))(*args), ptr(ctypes.c_char_p))
        if lib.PetscOptionsInsert(None, ctypes.byref(argc), ctypes.byref(array), None):
            raise RuntimeError("PETSc could not read the options")
        yield


@contextmanager
def options_of(values: dict):
    """A fresh options database holding ``values`` (name without the dash -> value string, None
    for a bare flag), the global one for the block; reads no file, so one rank may enter alone."""
    with _pushed():
        db = PETSc.Options()
        for name, value in values.items():
            db.setValue(name, value)
        yield
