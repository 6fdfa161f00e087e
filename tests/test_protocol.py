"""Every problem class against the protocol of the continuation core, and its linearization against finite
differences of its own residual (pacopy's habit): the physical frame (tests/test_problem.py checks its
Jacobian), the frame of the contact edge, the fold system on the adhesion problem, and the adhesion problem's
hooks for the fold system (the transpose of G_H, the second derivatives, the derivatives in sigma and mu).

Central differences: O(eps^2) truncation and rounding of order 1e-16 |G| / eps; the bounds below are about
ten times the largest error measured.
"""
import numpy as np
import pytest
from petsc4py import PETSc

from conftest import make_problem
from petsc_adhesion.core.fold import FoldSystem
from petsc_adhesion.core.protocol import ContinuationProblem, FoldBase, PressureLaw, TracedProblem
from petsc_adhesion.discretization import grid, preconditioning
from petsc_adhesion.discretization.edge_frame import EdgeFrameProblem
from petsc_adhesion.discretization.influence import create_influence
from petsc_adhesion.model import pressure
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.model.roughness import Measured, TruncatedGaussian, Weibull
from petsc_adhesion.tracing.critical import fold_system


def _vec(pb, values):
    v = pb.create_vec()
    v.setArray(values)
    return v


def _residual(pb, x, p):
    X, G = _vec(pb, x), pb.create_vec()
    pb.residual(X, p, G)
    out = G.getArray().copy()
    X.destroy(), G.destroy()
    return out


def _mult(M, pb, v, transpose=False):
    x, y = _vec(pb, v), pb.create_vec()
    (M.multTranspose if transpose else M.mult)(x, y)
    out = y.getArray().copy()
    x.destroy(), y.destroy()
    return out


def _check_jacobian(pb, x, p, bound):
    """J v against the central difference of the residual, in a rough and a smooth direction."""
    X = _vec(pb, x)
    pb.linearize(X, p)
    rng = np.random.default_rng(3)
    for v in (rng.standard_normal(x.size), np.exp(-np.linspace(0.0, 5.0, x.size))):
        eps = 1e-6 / np.abs(v).max()
        fd = (_residual(pb, x + eps * v, p) - _residual(pb, x - eps * v, p)) / (2 * eps)
        pb.linearize(X, p)                      # the differences moved the state below (the fold system's)
        jv = _mult(pb.jacobian, pb, v)
        assert np.abs(jv - fd).max() < bound * np.abs(fd).max(), np.abs(jv - fd).max() / np.abs(fd).max()
    X.destroy()


def _contact_state(pb, r, gap):
    """A state with a repulsive centre (flat near the wall) and attraction around it."""
    return np.maximum(0.5 * r**2 - 1.0, pb.law.wall + gap)


# -- the pressure laws ----------------------------------------------------------------------------------
LAWS = {"smooth": lambda: pressure.PressureLaw(0.0), "hermite": lambda: pressure.PressureLaw(0.2, "hermite", 16),
        "truncated_gaussian": lambda: pressure.WallLaw(TruncatedGaussian(0.2, 3.0)),
        "weibull": lambda: pressure.WallLaw(Weibull(0.2, -1.0)),
        "measured": lambda: pressure.HistogramLaw(Measured(0.2 * np.sin(np.arange(1.0, 2001.0))))}


@pytest.mark.parametrize("kind", LAWS)
def test_every_pressure_law_keeps_the_protocol(kind):
    """Each law is a PressureLaw: (P, dP/dH) of H's shape above its wall, FloatingPointError at it,
    dP/dH the derivative of P (central differences, step 1e-5: error ~1e-9 relative), error(H) >= 0 of H's
    shape, and nothing to describe exactly when smooth.  (mypy checks the members' types, tests/test_types.py.)"""
    law = LAWS[kind]()
    assert isinstance(law, PressureLaw)
    assert law.smooth == (kind == "smooth") and law.n >= 1 and (law.describe() == {}) == law.smooth
    H = law.wall + np.array([0.3, 0.8, 1.5, 4.0])
    P, dP = law(H)
    assert P.shape == dP.shape == law.error(H).shape == H.shape and np.all(law.error(H) >= 0)
    h = 1e-5
    assert np.allclose(dP, (law(H + h)[0] - law(H - h)[0]) / (2 * h), rtol=1e-6, atol=1e-9)
    with pytest.raises(FloatingPointError):
        law(np.array([law.wall + 1.0, law.wall]))


# -- the physical frame ---------------------------------------------------------------------------------
def test_the_physical_frame_is_a_traced_problem_and_a_fold_base():
    pb, newton = make_problem(mu=2.0, sigma=0.1)
    assert isinstance(pb, TracedProblem) and isinstance(pb, FoldBase)
    newton.destroy()
    pb.destroy()


# -- the frame of the contact edge ----------------------------------------------------------------------
@pytest.fixture(params=[0.0, 0.2], ids=["smooth", "rough"])
def edge_frame(request):
    model = Model(mu=20.0, sigma=request.param, rmax=150.0)
    rho = np.concatenate([np.linspace(0.0, 0.9, 40), np.linspace(0.9, 1.1, 81)[1:], np.geomspace(1.1, 30.0, 60)[1:]])
    a = 4.0
    pb = EdgeFrameProblem(model, rho, create_influence(rho), a, preconditioning.Dense())
    # a state: flat contact below the edge level, rising as the rigid sphere beyond
    H = np.maximum(0.5 * (a * rho) ** 2 - 0.5 * a * a + pb.level, pb.law.wall + 0.4)
    x = np.append(H - 0.5 * (a * rho) ** 2, a)
    yield pb, x
    pb.destroy()


def test_the_edge_frame_is_a_traced_problem(edge_frame):
    pb, _ = edge_frame
    assert isinstance(pb, TracedProblem)


def test_the_edge_frame_jacobian_is_the_derivative_of_its_residual(edge_frame):
    """[[I - c a Ahat diag(P'), dG/da], [pin, a]] (the pin and the contact radius included)."""
    pb, x = edge_frame
    _check_jacobian(pb, x, -30.0, 1e-7)


def test_the_edge_frame_dG_dlambda_is_the_derivative_of_its_residual(edge_frame):
    pb, x = edge_frame
    # G is linear in lambda: a long difference has no truncation, and |c a Ahat P| ~ 1e6 rounds less over it
    fd = (_residual(pb, x, -29.0) - _residual(pb, x, -31.0)) / 2.0
    X = _vec(pb, x)
    out = pb.dG_dp(X, -30.0, np.zeros(x.size))
    np.testing.assert_allclose(out, fd, rtol=0, atol=1e-8)
    X.destroy()


# -- the adhesion problem's hooks for the fold system ---------------------------------------------------
@pytest.fixture(params=["smooth", "rough"])
def hooked(request):
    sigma = 0.0 if request.param == "smooth" else 0.15
    pb, newton = make_problem(mu=2.0, sigma=sigma, r=grid.uniform(121, 6.0))
    newton.destroy()
    h = _contact_state(pb, pb.r, 0.4 if sigma else 0.8)
    pb.set_parameter("mu", 2.0)
    yield pb, h, sigma
    pb.destroy()


def test_the_transpose_hook_is_the_transpose_of_the_jacobian(hooked):
    pb, h, _ = hooked
    H = _vec(pb, h)
    pb.linearize(H, 1.0)
    rows = pb.jacobian_rows(np.empty((h.size, h.size)))
    u = np.random.default_rng(5).standard_normal(h.size)
    x, y = _vec(pb, u), pb.create_vec()
    pb.jacobian_transpose(x, y)
    np.testing.assert_allclose(y.getArray(), rows.T @ u, rtol=0, atol=1e-12 * np.abs(rows.T @ u).max())
    for v in (H, x, y):
        v.destroy()


def test_the_second_derivative_hook_is_the_derivative_of_the_jacobian(hooked):
    """w^T (dG_H/dH)[v]: the derivative of w^T G_H(H) v along every node."""
    pb, h, _ = hooked
    rng = np.random.default_rng(7)
    v, w = rng.standard_normal(h.size), rng.standard_normal(h.size)

    def wGv(hh):
        H = _vec(pb, hh)
        pb.linearize(H, 1.0)
        out = w @ _mult(pb.jacobian, pb, v)
        H.destroy()
        return out

    H = _vec(pb, h)
    pb.linearize(H, 1.0)
    row, along_lambda = pb.second_derivatives(h, 1.0, v, w)
    assert along_lambda == 0.0
    for k in (0, h.size // 3, h.size // 2, h.size - 1):
        e = np.zeros(h.size)
        eps = 1e-6 * (h[k] - pb.law.wall)
        e[k] = eps
        fd = (wGv(h + e) - wGv(h - e)) / (2 * eps)
        assert abs(row[k] - fd) <= 1e-6 * max(np.abs(row).max(), 1e-300), (k, row[k], fd)
    H.destroy()


@pytest.mark.parametrize("name", ["sigma", "mu"])
def test_the_parameter_hook_is_the_derivative_in_the_parameter(hooked, name):
    """dG/ds and w^T (dG_H/ds) v against central differences in s (sigma only on a rough law)."""
    pb, h, sigma = hooked
    if name == "sigma" and sigma == 0:
        pytest.skip("sigma = 0 is the smooth law: no roughness to vary")
    s = sigma if name == "sigma" else 2.0
    rng = np.random.default_rng(11)
    v, w = rng.standard_normal(h.size), rng.standard_normal(h.size)

    def at(value):
        assert pb.set_parameter(name, value)
        H = _vec(pb, h)
        pb.linearize(H, 1.0)
        out = _residual(pb, h, 1.0), w @ _mult(pb.jacobian, pb, v)
        H.destroy()
        return out

    pb.set_parameter(name, s)
    H = _vec(pb, h)
    pb.linearize(H, 1.0)
    column, derivative = pb.parameter_derivatives(name, h, 1.0, v, w, pb.domain_gap(h))
    H.destroy()
    ds = 1e-5 * s
    (G1, g1), (G0, g0) = at(s + ds), at(s - ds)
    pb.set_parameter(name, s)
    fd = (G1 - G0) / (2 * ds)
    np.testing.assert_allclose(column, fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    assert abs(derivative - (g1 - g0) / (2 * ds)) <= 1e-6 * abs(derivative)


# -- the fold system --------------------------------------------------------------------------------------
@pytest.fixture(params=["sigma", "mu"])
def fold(request):
    name = request.param
    model = Model(mu=2.0, sigma=0.15, rmax=6.0)
    r = grid.uniform(121, 6.0)
    s0 = 0.15 if name == "sigma" else 2.0
    fs = fold_system(model, r, name, s0, PETSc.COMM_WORLD)
    h = _contact_state(fs.base, r, 0.4)
    x = fs.join(h, 1.0)
    fs.adapt(x, s0)
    yield fs, x, s0
    fs.destroy()


def test_the_fold_system_is_a_continuation_problem_on_a_fold_base(fold):
    fs, _, _ = fold
    assert isinstance(fs, FoldSystem) and isinstance(fs, ContinuationProblem) and isinstance(fs.base, FoldBase)


def test_the_fold_system_jacobian_is_the_derivative_of_its_residual(fold):
    """[[G_H, G_lambda], [g_H, g_lambda]]: the row of g from the second-derivative hook, g itself from the
    bordered solves at fixed borders."""
    fs, x, s0 = fold
    _check_jacobian(fs, x, s0, 1e-6)


def test_the_fold_system_dG_ds_is_the_derivative_of_its_residual(fold):
    """[G_s; g_s]: the parameter hook's column and the derivative of g in s."""
    fs, x, s0 = fold
    ds = 1e-5 * s0
    fd = (_residual(fs, x, s0 + ds) - _residual(fs, x, s0 - ds)) / (2 * ds)
    X = _vec(fs, x)
    out = fs.dG_dp(X, s0, np.zeros(x.size))
    X.destroy()
    np.testing.assert_allclose(out, fd, rtol=0, atol=2e-6 * np.abs(fd).max())
