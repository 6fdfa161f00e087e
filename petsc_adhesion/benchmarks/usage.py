"""docs/usage.md, every option of the program, generated from the definitions ``-help`` prints.

    python -m petsc_adhesion.benchmarks.usage > docs/usage.md

The option table (:data:`~petsc_adhesion.app.options.TABLE`), its groups
(:func:`~petsc_adhesion.app.options.help_groups`), defaults and accepted values,
the solvers' prefixes and PETSc's own start-up options: a test fails when the
file and the table drift apart.
"""
from __future__ import annotations

import sys

from ..app.options.checks import PETSC_GLOBAL
from ..app.options.help import help_groups, shown_default
from ..app.options.table import SOLVER_PREFIXES

__all__ = ["markdown", "COMMAND"]

#: The command that makes docs/usage.md.
COMMAND = "python -m petsc_adhesion.benchmarks.usage > docs/usage.md"


def _cell(text: str) -> str:
    """Text for a cell of a Markdown table: a bar would end the cell."""
    return text.replace("|", "\\|")


def markdown() -> str:
    """docs/usage.md: the options in their -help groups (name, default, accepted values, help), the
    solvers' prefixes and the PETSc options read at start-up."""
    out = ["# Options", "",
           f"Made by `{COMMAND}` from the option table of `petsc_adhesion/app/options/table.py`, the",
           "definitions `-help` prints; do not edit it by hand (tests/test_docs.py fails when the two differ).",
           "",
           "Options go on the command line (`petsc-adhesion -adh_mu 2`), into an options file",
           "(`-options_file FILE`, one `-name value` a line, `#` comments), into `PETSC_OPTIONS`, or",
           "from Python as keywords without the dash (`petsc_adhesion.curve(grid_n=201)`, docs/python.md).",
           "A bare flag means true.  A bad value, an unknown option or one the run would ignore is",
           "refused in one line naming it, before any work (exit status 2); a misspelt one of ours",
           "(`-phys_radis`) is named with the nearest known name before any option it leaves missing.",
           "A physical input outside what the field measures (a work of adhesion above 1 J/m^2, ...)",
           "is taken, with one warning line naming the likely slip of units (docs/materials.md)."]
    for title, members in help_groups():
        out += ["", f"## {title[0].upper()}{title[1:]}", "", "| option | default | accepts | what it does |",
                "|---|---|---|---|"]
        out += [f"| `-{o.name}` | {_cell(shown_default(o))} | {_cell(o.allowed())} | {_cell(o.help)} |"
                for o in members]
    out += ["", "## Solvers and their prefixes", "",
            "Each solver reads PETSc's options (`-snes_*`, `-ksp_*`, `-pc_*`, `-mat_*`) under its own prefix,",
            "so that they can be tuned apart; `-help` with the run's options lists those its solvers read.", "",
            "| prefix | solver | for example |", "|---|---|---|"]
    out += [f"| {f'`{p}`' if p else '(none)'} | {_cell(what)} | `-{p}snes_monitor`, `-{p}ksp_type`, `-{p}pc_type` |"
            for p, what in SOLVER_PREFIXES]
    out += ["", "## PETSc's own", "",
            "PETSc reads these at start-up or at the end of a run; they are never reported as unknown:", "",
            ", ".join(f"`-{name}`" for name in sorted(PETSC_GLOBAL)) + ".", ""]
    return "\n".join(out)


if __name__ == "__main__":
    sys.stdout.write(markdown())
