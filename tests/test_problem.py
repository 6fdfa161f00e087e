"""The adhesion problem's linearization against its own residual, by finite differences.

The shell Jacobian (eq. 23), dG/dlambda, the assembled rows, the band and the
diagonal the Jacobi PC reads are each checked against central differences of
the residual of eq. (12), on a smooth and a rough (16-point Hermite) case, at
states with contact (not the trivial far field).
"""
import numpy as np
import pytest
from petsc4py import PETSc

from petsc_adhesion.discretization import preconditioning
from conftest import make_problem

#: (model, smallest gap above the wall of the roughness rule): both with a repulsive centre
CASES = {"smooth": (dict(mu=2.0, sigma=0.0), 0.8), "rough": (dict(mu=2.0, sigma=0.1), 0.3)}


def state(case):
    """A state with a repulsive centre (flat near the wall), attraction around it.

    The derivatives hold at any admissible state, a solution or not.
    """
    model, gap = CASES[case]
    pb, _ = make_problem(**model, pmat="band")
    H = pb.create_vec()
    H.setArray(np.maximum(0.5 * pb.r**2 - 1.0, pb.law.wall + gap))
    assert pb.law(H.getArray())[0].max() > 0.1
    return pb, H


def residual(pb, h, lam):
    H, G = pb.create_vec(), pb.create_vec()
    H.setArray(h)
    pb.residual(H, lam, G)
    return G.getArray().copy()


@pytest.mark.parametrize("case", list(CASES))
def test_shell_jacobian_is_the_derivative_of_the_residual(case):
    pb, H = state(case)
    h = H.getArray().copy()
    pb.linearize(H, 1.0)
    rng = np.random.default_rng(1)
    for v in (rng.standard_normal(h.size), np.exp(-pb.r)):        # rough and smooth directions
        x, y = pb.create_vec(), pb.create_vec()
        x.setArray(v)
        pb.jacobian.mult(x, y)
        eps = 1e-6 / np.abs(v).max()
        fd = (residual(pb, h + eps * v, 1.0) - residual(pb, h - eps * v, 1.0)) / (2 * eps)
        # central differences: O(eps^2) truncation and 1e-16 |G| / eps rounding; measured <= 5e-10
        assert np.abs(y.getArray() - fd).max() < 1e-8 * np.abs(fd).max()


@pytest.mark.parametrize("case", list(CASES))
def test_dG_dlambda_is_the_derivative_of_the_residual(case):
    pb, H = state(case)
    h = H.getArray().copy()
    fd = (residual(pb, h, 1.0 + 1e-3) - residual(pb, h, 1.0 - 1e-3)) / 2e-3
    out = pb.dG_dp(H, 1.0, np.zeros(h.size))
    np.testing.assert_allclose(out, fd, rtol=0, atol=1e-9)


@pytest.mark.parametrize("case", list(CASES))
def test_assembled_rows_band_and_diagonal_match_the_shell(case):
    pb, H = state(case)
    pb.linearize(H, 1.0)
    n = pb.r.size
    dense = pb.jacobian_rows(np.empty((n, n)))
    # columns of the shell applied to unit vectors
    cols = np.empty((n, n))
    e, y = pb.create_vec(), pb.create_vec()
    for j in range(n):
        e.set(0.0)
        e.setValue(j, 1.0)
        e.assemble()
        pb.jacobian.mult(e, y)
        cols[:, j] = y.getArray()
    np.testing.assert_allclose(dense, cols, rtol=0, atol=1e-12 * np.abs(cols).max())
    # the Jacobi PC's diagonal
    d = pb.create_vec()
    pb.jacobian.getDiagonal(d)
    np.testing.assert_allclose(d.getArray(), np.diag(cols), rtol=1e-13, atol=1e-15)
    # the band strategy keeps the near field exactly and nothing else
    band = preconditioning.Band(5)
    ai, aj = band.pattern(pb.layout)
    v = pb.band_values(ai, aj)
    rows = np.repeat(np.arange(n), np.diff(ai))
    assert np.all(np.abs(rows - aj) <= 5)
    np.testing.assert_allclose(v, cols[rows, aj], rtol=0, atol=1e-12 * np.abs(cols).max())


def test_jacobi_preconditioner_on_the_shell():
    """-pc_type jacobi with -adh_pmat shell: PETSc reads the shell's diagonal; Newton converges
    to the state the assembled LU finds."""
    ref, newton = make_problem(mu=1.0)
    H0 = ref.rigid(-2.0, ref.create_vec())
    assert newton.solve(-2.0, H0)
    pb, _ = make_problem(mu=1.0, pmat="shell")
    from petsc_adhesion.core.newton import Newton, PetscSettings
    # the solver's settings are values now, applied under a prefix of its own
    newton = Newton(pb, "jacobitest_", settings=PetscSettings(pc_type="jacobi"))
    assert newton.snes.getKSP().getPC().getType() == "jacobi"
    H = pb.rigid(-2.0, pb.create_vec())
    assert newton.solve(-2.0, H)
    assert np.abs(H.getArray() - H0.getArray()).max() < 1e-9
    newton.destroy()
