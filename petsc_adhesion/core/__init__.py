"""The continuation core: predictor-corrector continuation of G(x, p) = 0 through its turning points.

It knows nothing of adhesion: it sees a problem through the protocol of
:mod:`~petsc_adhesion.core.protocol`.  Newton-Krylov at a fixed parameter
(:mod:`~petsc_adhesion.core.newton`), the bordered arclength system
(:mod:`~petsc_adhesion.core.bordered`), the continuation itself
(:mod:`~petsc_adhesion.core.continuation`), events located on the discrete
curve (:mod:`~petsc_adhesion.core.events`), the minimally augmented fold system
(:mod:`~petsc_adhesion.core.fold`) and PETSc functions petsc4py 3.18 does not
bind (:mod:`~petsc_adhesion.core.capi`).
"""
