"""Where the benchmarks read the project's options files and write its documents: the checkout they run in.

``./run bench``, ``./run figures``, ``./run stability`` and ``./run coverage`` run from the checkout's top,
which holds ``docs/`` and ``options/``; ``PETSC_ADHESION_CHECKOUT`` names another.  The benchmarks find
neither through the package's own files: an installed package has no ``docs/`` beside it.
"""
from __future__ import annotations

import os

__all__ = ["ROOT", "DOCS", "FIGURES", "OPTIONS", "DATA"]

#: The checkout: its top holds docs/ and options/.
ROOT = os.path.abspath(os.environ.get("PETSC_ADHESION_CHECKOUT", os.getcwd()))
DOCS = os.path.join(ROOT, "docs")
FIGURES = os.path.join(DOCS, "figures")
DATA = os.path.join(DOCS, "data")
OPTIONS = os.path.join(ROOT, "options")
