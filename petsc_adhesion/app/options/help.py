"""-help: the application's options in their groups, with defaults, ranges and the solvers' prefixes."""
from __future__ import annotations

from ...errors import tell
from .table import SOLVER_PREFIXES, TABLE, Option

__all__ = ["HELP_GROUPS", "help_groups", "shown_default", "print_help", "help_text"]


#: The groups of -help and docs/usage.md: (title, the name prefixes of its options); the last takes the rest.
HELP_GROUPS = (("model (eq. 9-14) and its solver", ("adh_",)), ("physical units", ("phys_",)), ("grid", ("grid_",)),
               ("continuation, events and error bars", ("cont_", "target_")), ("studies of many cases", ("study_",)),
               ("fitting a measurement", ("fit_",)), ("a particle population", ("pop_",)),
               ("output and progress", ()))


def help_groups() -> list[tuple[str, list[Option]]]:
    """The options of :data:`TABLE` in their :data:`HELP_GROUPS`, each in table order; empty groups left out."""
    def group(name: str) -> int:
        return next((i for i, (_, prefixes) in enumerate(HELP_GROUPS) if name.startswith(prefixes)),
                    len(HELP_GROUPS) - 1)
    return [(title, members) for i, (title, _) in enumerate(HELP_GROUPS)
            if (members := [o for o in TABLE.values() if group(o.name) == i])]


def shown_default(o: Option) -> str:
    """The default of ``o`` as -help and docs/usage.md show it ("" when the option has none: the help says)."""
    if o.default in (None, ()):
        return ""
    if isinstance(o.default, bool):
        return "true" if o.default else "false"
    if isinstance(o.default, tuple):
        return ",".join(map(str, o.default))
    return str(o.default)


def help_text() -> str:
    """The application options in their groups and the solvers' prefixes, as PETSc's -help writes its own."""
    out = ["petsc-adhesion application options (PETSc's follow):"]
    for title, members in help_groups():
        out.append(f" {title}:")
        for o in members:
            default = f" <{shown_default(o)}>" if shown_default(o) else ""
            out.append(f"  -{o.name}{default}: {o.help}; {o.allowed()}")
    out.append("Solvers, each tuned by PETSc's options under its own prefix (-{prefix}snes_*, -{prefix}ksp_*, "
               "-{prefix}pc_*):")
    out += [f"  -{prefix}snes_...: {what}" for prefix, what in SOLVER_PREFIXES]
    return "\n".join(out)


def print_help(out=None) -> None:
    """:func:`help_text` on ``out`` (stdout): a closed pipe is no error, a full device is (:func:`~petsc_adhesion.errors.tell`)."""
    tell(help_text(), out)
