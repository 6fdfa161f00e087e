"""Options files and PETSc's start-up options, checked before PETSc reads them.

PETSc aborts with a page of text on a malformed options file, silently skips
a word without a dash in PETSC_OPTIONS, and recurses on a file that includes
itself; these checks say each in one line first.  No PETSc import here: they
run before PETSc is initialised.
"""
from __future__ import annotations

import os

from ..errors import printable
from ..io.inputs import file_problem

#: The largest options file read (16 MiB): options files are a few lines.
MAX_OPTIONS_BYTES = 16 << 20

__all__ = ["options_files", "file_error", "named_file_error", "environment_error", "stray_word", "MAX_OPTIONS_BYTES"]


def _is_value(token: str) -> bool:
    """A token PETSc takes as a value, not as an option name: no leading dash, or a negative number."""
    return not token.startswith("-") or token[1:2].isdigit() or token[1:2] == "."


def stray_word(tokens: list[str]) -> str | None:
    """The first word that is neither an option nor the value of the option before it (PETSc ignores it)."""
    for i, t in enumerate(tokens):
        if _is_value(t) and (i == 0 or _is_value(tokens[i - 1])):
            return t
    return None


def _lines(path: str):
    with open(path, "rb") as f:
        for n, raw in enumerate(f, 1):
            line = raw.decode("utf-8", errors="surrogateescape")
            yield n, line, line.split("#")[0].split("!")[0].split()


def _utf8(line: str) -> bool:
    try:
        line.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def options_files(argv: list[str]) -> list[str]:
    """The files named by -options_file on the command line and, recursively, inside them."""
    out = []
    todo = [argv[i + 1] if i + 1 < len(argv) else "" for i, a in enumerate(argv) if a == "-options_file"]
    while todo:
        path = todo.pop(0)
        if path in out:
            continue
        out.append(path)
        if file_problem(path, MAX_OPTIONS_BYTES) is None:
            todo += [t[1] for _, _, t in _lines(path) if len(t) == 2 and t[0] == "-options_file"]
    return out


def file_error(path: str, opened: tuple = ()) -> str | None:
    """What PETSc would abort on in an options file, said in one line (None: fine).

    Its syntax: a line is '-name [value]' or 'alias -name -other', '#' and '!'
    start comments; a nested -options_file is checked too, and a cycle of
    them refused.
    """
    shown = printable(path)
    why = file_problem(path, MAX_OPTIONS_BYTES)
    if why:
        return f"-options_file: '{shown}' {why}"
    real = os.path.realpath(path)
    if real in opened:
        return f"-options_file {shown}: includes itself (through -options_file)"
    for n, line, tokens in _lines(path):
        ok = not tokens or (tokens[0] == "alias" and len(tokens) == 3) or \
            (tokens[0].startswith("-") and len(tokens) <= 2)
        if not _utf8(line):
            return f"-options_file {shown}: line {n} is not UTF-8: '{printable(line.strip())}'"
        if not ok:
            return f"-options_file {shown}: line {n}: expected '-name [value]', got '{printable(line.strip())}'"
        if tokens and tokens[0] == "-options_file":
            inner = file_error(tokens[1] if len(tokens) > 1 else "", opened + (real,))
            if inner:
                return inner
    return None


#: The variables PETSc reads as options at start-up, which petsc4py hands to Python as text: each must be UTF-8.
TEXT_VARIABLES = ("PETSC_OPTIONS", "PETSC_OPTIONS_YAML")


def undecodable_variable() -> str | None:
    """The first of :data:`TEXT_VARIABLES` whose value is not UTF-8 (Python keeps its bytes as surrogates, which
    PETSc's options and petsc4py cannot take), said in one line; None when all are."""
    for name in TEXT_VARIABLES:
        value = os.environ.get(name)
        if value is not None and not _utf8(value):
            return f"{name}: '{printable(value)}' is not valid UTF-8: write it in UTF-8, or unset it"
    return None


def environment_error(argv: list[str]) -> str | None:
    """What PETSc would abort on, or silently skip, in PETSC_OPTIONS and the .petscrc files; a variable PETSc
    reads that is not UTF-8."""
    bad = undecodable_variable()
    if bad:
        return bad
    env = os.environ.get("PETSC_OPTIONS", "").split()
    word = stray_word(env)
    if word is not None:
        return f"PETSC_OPTIONS: '{printable(word)}' is neither an option (they start with '-') nor an option's value"
    for i, t in enumerate(env):
        if t in ("-options_file", "-options_file_yaml"):
            bad = file_error(env[i + 1] if i + 1 < len(env) else "") if t == "-options_file" else \
                named_file_error(t, env[i + 1] if i + 1 < len(env) else "")
            if bad:
                return f"PETSC_OPTIONS: {bad}"
    if "-skip_petscrc" in argv + env:
        return None
    for rc in (os.path.join(os.path.expanduser("~"), ".petscrc"), ".petscrc", "petscrc"):
        if os.path.lexists(rc):
            bad = file_error(rc)
            if bad:
                return bad.replace("-options_file", f"{rc} (read by PETSc at start-up)", 1)
    return None


def named_file_error(option: str, path: str) -> str | None:
    """A file option PETSc reads at start-up, judged by what it is."""
    why = file_problem(path, MAX_OPTIONS_BYTES)
    return f"{option}: '{printable(path)}' {why}" if why else None
