"""Newton (SNES) for G(H; lambda) = 0 at a fixed approach lambda.

The SNES gets the residual of eq. (12), the shell Jacobian and a
preconditioning matrix from :class:`~petsc_adhesion.residual.Problem`, and the
domain guard as its line-search pre-check.  Defaults are set here, before
``setFromOptions()``, so every one of them can be overridden at run time.
"""
from __future__ import annotations

from petsc4py import PETSc

__all__ = ["configure", "create_snes", "default_pc", "solve"]


def default_pc(pc: PETSc.PC, pmat: str) -> None:
    """Preconditioner for the kind of matrix it gets (overridable: -pc_type ...).

    dense: LU on one rank, block Jacobi with dense LU per rank otherwise;
    band: LU of the near-field AIJ on one rank, block Jacobi + ILU in parallel;
    shell: none.
    """
    if pmat == "shell":
        pc.setType("none")
    elif pc.getComm().getSize() == 1:
        pc.setType("lu")
    else:
        pc.setType("bjacobi")
        # the sub-PC type goes through the database (sub-KSPs exist only after setup),
        # and only while block Jacobi is in effect: an unread option is an error here
        opts = PETSc.Options(pc.getOptionsPrefix() or "")
        if not opts.hasName("pc_type") and not opts.hasName("sub_pc_type"):
            opts.setValue("sub_pc_type", "lu" if pmat == "dense" else "ilu")


def configure(snes: PETSc.SNES, pmat: str, precheck, full_steps: bool = False) -> PETSc.SNES:
    """Newton-Krylov (GMRES) defaults shared by the fixed-lambda and bordered SNES.

    Tight enough for events located to 1e-8 in lambda; ``setFromOptions()``
    comes last, so each default can be overridden at run time.  ``full_steps``:
    Newton starts from a continuation predictor, close to the curve, where full
    steps (shortened at the wall) need no backtracking: the ``basic`` line search
    unless the user chose one; it halves the residual evaluations of ``bt``.
    """
    opts = PETSc.Options(snes.getOptionsPrefix() or "")
    # petsc4py 3.18 has no SNESLineSearch object: the default goes through the
    # database, for this setFromOptions only, so that it does not leak into others
    default_ls = full_steps and not opts.hasName("snes_linesearch_type")
    if default_ls:
        opts.setValue("snes_linesearch_type", "basic")
    snes.setType("newtonls")
    snes.setTolerances(rtol=1e-10, atol=1e-10, stol=1e-14, max_it=50)
    ksp = snes.getKSP()
    ksp.setType("gmres")
    ksp.setTolerances(rtol=1e-10, atol=1e-13, max_it=400)
    default_pc(ksp.getPC(), pmat)
    snes.setLineSearchPreCheck(precheck)
    snes.setFromOptions()
    if default_ls:
        opts.delValue("snes_linesearch_type")
    return snes


def create_snes(problem, full_steps: bool = False) -> PETSc.SNES:
    """A Newton-Krylov SNES on ``problem`` at ``problem.lam`` (``full_steps``: see configure)."""
    snes = PETSc.SNES().create(problem.comm)
    snes.setFunction(problem.form_function, problem.create_vec())
    snes.setJacobian(problem.form_jacobian, problem.J, problem.P)
    return configure(snes, problem.pmat_kind, problem.precheck, full_steps)


def solve(snes: PETSc.SNES, problem, lam: float, H: PETSc.Vec) -> bool:
    """Solve G(H; lam) = 0 in place from the guess in H; True when converged."""
    problem.lam = lam
    snes.solve(None, H)
    return snes.getConvergedReason() > 0
