"""petsc_adhesion/app/options/petsc_options.txt: PETSc's own option names, for the did-you-mean hint of an
unknown option.

    python -m petsc_adhesion.benchmarks.petsc_names

PETSc's ``-help`` over every solver configuration the program offers, collected.
"""
from __future__ import annotations

from petsc4py import PETSc

from ..app.options.checks import _NAMES_FILE
from ..app.options.table import TABLE
from ..core.newton import role_of

__all__ = ["write"]


def write() -> None:
    """Collect PETSc's option names from its -help over the solver configurations offered here."""
    import re
    import subprocess
    import sys

    names = set()
    base = [sys.executable, "-m", "petsc_adhesion", "-help", "-adh_lambda", "-2", "-grid_type", "uniform",
            "-grid_n", "21"]
    variants = [("-adh_pmat", kind, "-pc_type", pc) for kind in ("dense", "band")
                for pc in ("lu", "ilu", "bjacobi", "asm", "jacobi", "none", "hypre", "gamg", "cholesky", "icc")]
    variants += [("-ksp_type", k) for k in ("fgmres", "bcgs", "cg", "lgmres", "gcr")]
    variants += [("-snes_linesearch_type", k) for k in ("basic", "l2", "cp")]
    variants += [("-adh_pmat", "band", "-pc_type", "lu", "-pc_factor_mat_solver_type", "mumps")]
    for extra in variants:
        proc = subprocess.run(base + list(extra), capture_output=True, text=True)
        # each solver's options under a prefix of its own (SolverOptions): the names as users give them
        names |= {role_of(n) for n in re.findall(r"^\s+-([a-z][a-z0-9_]*)", proc.stdout, re.M)}
    names -= set(TABLE)
    names |= {"sub_" + n for n in names if n.startswith(("ksp_", "pc_"))}
    with open(_NAMES_FILE, "w") as f:
        f.write(f"# PETSc {'%d.%d.%d' % PETSc.Sys.getVersion()} option names from its -help over the solver "
                "configurations petsc-adhesion offers;\n# made by: python -m petsc_adhesion.benchmarks.petsc_names\n")
        f.write("\n".join(sorted(names)) + "\n")


if __name__ == "__main__":
    write()
