"""Newton never leaves the domain: every gap H - sqrt(2) sigma x_l + 1 stays positive."""
import numpy as np

from petsc_adhesion.discretization import problem
from petsc_adhesion.core import newton as solver
from conftest import make_problem


def test_step_across_the_wall_is_shortened():
    pb, _ = make_problem(mu=1.0, sigma=0.5)
    H = pb.rigid(0.0, pb.create_vec())
    h = H.getArray().copy()
    Y = pb.create_vec()
    y = np.zeros_like(h)
    y[:5] = h[:5] - pb.law.wall + 1.0          # new H = h - y lies 1 below the wall
    Y.setArray(y)
    assert solver.guard(pb, h, Y)
    new = h - Y.getArray()
    room = h - pb.law.wall
    assert np.all(new - pb.law.wall >= (1 - problem.TO_WALL) * room - 1e-12)
    # a step that stays inside is left alone
    Y.setArray(0.5 * (h - pb.law.wall))
    assert not solver.guard(pb, h, Y)
    assert np.allclose(Y.getArray(), 0.5 * (h - pb.law.wall))


def test_newton_through_the_wall_region_converges(monkeypatch):
    """mu = 1, sigma = 0.5, lambda = 0 from the rigid state: plain Newton steps cross the
    wall of the 16-point rule (measured: 16 of 26); each is shortened, the residual is never
    evaluated outside, and Newton converges."""
    crossings, shortened = [], []
    orig = solver.guard

    def spy(pb, h, Y, y=None):
        yy = (Y.getArray(readonly=True) if y is None else y).copy()
        crossings.append(bool(np.any(h - yy <= pb.law.wall)))
        changed = orig(pb, h, Y, y)
        shortened.append(changed)
        return changed

    monkeypatch.setattr(solver, "guard", spy)
    pb, newton = make_problem(mu=1.0, sigma=0.5)
    seen = []
    inner = pb.law.__call__

    class Law(type(pb.law)):
        def __call__(self, H):
            seen.append(float(np.min(H - self.wall)))
            return inner(H)

    pb.law.__class__ = Law
    H = pb.rigid(0.0, pb.create_vec())
    assert newton.solve(0.0, H)
    assert sum(crossings) >= 1
    assert all(s for c, s in zip(crossings, shortened) if c)
    assert min(seen) > 0                          # never evaluated at a closed gap
    G = pb.create_vec()
    pb.residual(H, 0.0, G)
    assert np.isfinite(H.getArray()).all() and G.norm() < 1e-9


def test_continuation_step_leaving_the_domain_is_retried_smaller():
    """A predictor beyond the wall is refused before any evaluation (step retried at half)."""
    from petsc_adhesion.core.continuation import Continuation, Settings
    pb, _ = make_problem(mu=1.0, sigma=0.5)
    cont = Continuation(pb, Settings(observable="F"))
    a = cont.start(pb.rigid(-3.0, pb.create_vec()), -3.0)
    assert a.xdot[0] < 0 and a.pdot > 0          # approaching: lambda up, H down
    # a step long enough to push the predicted H(0) twice as far as the wall
    big = 2 * (a.x[0] - pb.law.wall) / -a.xdot[0]
    assert not pb.inside(a.x + big * a.xdot)
    assert cont.step(a, big) is None
    assert cont.step(a, 0.05) is not None
