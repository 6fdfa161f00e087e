"""A study's case as a value: what :mod:`petsc_adhesion.app.study` gathers from its groups of ranks, writes
through :mod:`petsc_adhesion.io` and journals in its checkpoint (:mod:`petsc_adhesion.io.values`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .curve import Curve
from .measured import Missing

if TYPE_CHECKING:                    # tracing.critical loads PETSc, which a reader of a study's files need not
    from .critical import Critical

__all__ = ["CaseResult"]


@dataclass(frozen=True)
class CaseResult:
    """One case of a study (:mod:`petsc_adhesion.app.study`): its number ``case``, the options it sets
    (``values``: (name without the dash, value) pairs in the order of the study's axes), its ``result`` (a
    :class:`Curve`, with the profiles the study keeps; a critical study's
    :class:`~.critical.Critical`; or :class:`~.measured.Missing` with the one-line reason it did not
    run or failed) and ``wall_time_s``, the seconds its group spent on it (None for a case left out before
    any work)."""

    case: int
    values: tuple[tuple[str, float], ...]
    result: Curve | Critical | Missing
    wall_time_s: float | None = None

    @property
    def ran(self) -> bool:
        """Whether the case has a result (it did not fail)."""
        return not isinstance(self.result, Missing)

    @property
    def complete(self) -> bool:
        """Whether the case is what was asked for: it ran and, a curve, is complete (the study's exit status)."""
        return self.ran and (not isinstance(self.result, Curve) or self.result.complete)

    def value(self, name: str) -> float:
        """The value the case sets for option ``name`` (KeyError when it sets none)."""
        for k, v in self.values:
            if k == name:
                return v
        raise KeyError(name)
