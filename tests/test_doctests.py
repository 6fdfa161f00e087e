"""The examples in the docstrings of every module of the package are right (doctest)."""
import doctest
import importlib
import os

import pytest

from conftest import ROOT

#: Modules that run a program when imported (a package's __main__), or need what the project does not install.
_NOT_IMPORTED = {"petsc_adhesion.__main__", "petsc_adhesion.benchmarks.__main__",
                 "petsc_adhesion.benchmarks.workprecision.__main__", "petsc_adhesion.benchmarks.peers"}


def _modules() -> list[str]:
    out = []
    for folder, _, files in os.walk(os.path.join(ROOT, "petsc_adhesion")):
        for name in files:
            if name.endswith(".py"):
                rel = os.path.relpath(os.path.join(folder, name), ROOT)[:-3].replace(os.sep, ".")
                out.append(rel[: -len(".__init__")] if rel.endswith(".__init__") else rel)
    return sorted(set(out) - _NOT_IMPORTED)


MODULES = _modules()


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0


def test_the_examples_are_many():
    """The modules with examples keep them (a guard against a test that runs none)."""
    attempted = sum(doctest.testmod(importlib.import_module(n), optionflags=doctest.NORMALIZE_WHITESPACE,
                                    report=False).attempted for n in MODULES)
    assert len(MODULES) > 50 and attempted >= 15, (len(MODULES), attempted)
