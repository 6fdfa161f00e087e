"""Where the benchmarks read the project's options files and write its documents: the checkout they run in.

``./run bench``, ``./run figures``, ``./run stability`` and ``./run coverage`` run from the checkout's top,
which holds ``docs/`` and ``options/``; ``PETSC_ADHESION_CHECKOUT`` names another.  The benchmarks find
neither through the package's own files: an installed package has no ``docs/`` beside it.
"""
from __future__ import annotations

import os
import subprocess

__all__ = ["ROOT", "DOCS", "FIGURES", "OPTIONS", "DATA", "source", "write_section"]

#: The checkout: its top holds docs/ and options/.
ROOT = os.path.abspath(os.environ.get("PETSC_ADHESION_CHECKOUT", os.getcwd()))
DOCS = os.path.join(ROOT, "docs")
FIGURES = os.path.join(DOCS, "figures")
DATA = os.path.join(DOCS, "data")
OPTIONS = os.path.join(ROOT, "options")


def source() -> dict:
    """The library a study measured: the checkout's commit and the package's files changed since."""
    def git(*args):
        p = subprocess.run(["git", *args], capture_output=True, text=True, cwd=ROOT)
        return p.stdout.strip() if p.returncode == 0 else None

    changed = git("status", "--porcelain", "--", "petsc_adhesion")
    return {"commit": git("rev-parse", "HEAD"), "changed": None if changed is None else changed.splitlines()}


def write_section(doc_path: str, text: str, heading: str | None = None) -> None:
    """``text`` as the section ``heading`` (default: its own first line, a '## ' heading) of the document
    ``doc_path``: in place of the one there, else at the end."""
    heading = heading or text.split("\n", 1)[0]
    with open(doc_path) as f:
        doc = f.read()
    if heading + "\n" in doc:
        head, rest = doc.split(heading + "\n", 1)
        tail = rest.split("\n## ", 1)
        doc = head + text + ("\n## " + tail[1] if len(tail) > 1 else "")
    else:
        doc = doc.rstrip("\n") + "\n\n" + text
    with open(doc_path, "w") as f:
        f.write(doc)
