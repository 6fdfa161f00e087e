"""The examples in the docstrings of the pure modules are right (doctest)."""
import doctest

import pytest

from petsc_adhesion import error_estimate, grid, model, reference


@pytest.mark.parametrize("module", [grid, model, reference, error_estimate], ids=lambda m: m.__name__)
def test_docstring_examples(module):
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
