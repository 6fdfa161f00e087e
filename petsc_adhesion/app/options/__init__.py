"""Application options: their table, their reading into typed objects, their checks, and -help.

The defaults belong to the objects the options configure (``Model``, the grid,
the continuation ``Settings``, the solvers), and the table reads them from
there: the library never imports the command line.  The solvers' PETSc options
(``-snes_*``, ``-ksp_*``, ``-pc_*`` under ``nat_``, ``arc_`` or no prefix) are read
here into each solver's :class:`~petsc_adhesion.core.newton.PetscSettings`
(:func:`~.reading.read_petsc`); PETSc's others (``-log_view`` ...) are left to
PETSc; any option that nobody used by the end of a run is reported as unknown
(:func:`~.checks.check_unused`), a solver's by the name the user gave it.

=============  ================================================================
module         what
=============  ================================================================
``table``      :data:`~.table.TABLE`: every application option, its kind, default, range and help
``reading``    :class:`~.reading.AppOptions` (typed, checked reads) and the readers into objects
``checks``     contradictions, unused options, PETSc's values and errors, memory
``help``       ``-help`` and the groups docs/usage.md is made from
=============  ================================================================
"""
