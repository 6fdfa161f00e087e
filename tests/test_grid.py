"""Node sets and the exact weights of the piecewise-linear interpolant (eq. 11, 26)."""
import numpy as np
import pytest

from petsc_adhesion.discretization import grid


def test_paper_grid_is_531_nodes_refined_at_the_centre():
    r = grid.paper(10.0)
    h = np.diff(r)
    assert r.size == 531 and r[0] == 0 and r[-1] == 10
    assert np.allclose(h[:60], 0.01) and np.allclose(h[60:], 0.02)


def test_paper_grid_split():
    r = grid.paper(10.0, extra=100, refine_from=1.0, split=4)
    h = np.diff(r)
    assert r.size == 501 + 300
    fine = (r[:-1] >= 1.0 - 1e-12) & (r[:-1] < 3.0 - 1e-12)
    assert np.allclose(h[fine], 0.005) and np.allclose(h[~fine], 0.02)


@pytest.mark.parametrize("r", [grid.uniform(7, 3.0), grid.paper(10.0), grid.paper(5.0, 41, 7, 1.0, 3)],
                         ids=["uniform", "paper", "split"])
def test_weights_are_exact_for_the_interpolant(r):
    # integral of a piecewise-linear P times r: exact for P linear on the whole domain
    a, b, R = 0.3, -1.7, r[-1]
    P = a + b * r
    assert grid.load_weights(r) @ P == pytest.approx(a * R**2 / 2 + b * R**3 / 3, rel=1e-13)
    assert grid.l2_weights(r).sum() == pytest.approx(1.0, rel=1e-14)
