"""The pull-off table (petsc_adhesion.family.pull_off) against the solver and the closed forms, the fit of a
pull-off through it at large mu, and a map of pull-offs turned into a map of w (docs/fitting.md).

The truths: the solver's whole default curve (traced to F = 2, not the table's truncated one), the rigid sphere's
pull-off (eq. 28: -1 smooth; with roughness the least of (8/3) times the averaged law integrated from the gap
out, Derjaguin's approximation, exact for the rigid sphere), JKR's -3/4, and the solver between the nodes.
"""
import math

import numpy as np
import pytest

petsc4py = pytest.importorskip("petsc4py")

from petsc_adhesion.family.pull_off import FORMAT_VERSION, OutOfRange, PullOffTable, trace_pull_off  # noqa: E402
from petsc_adhesion.fitting.pull_off import (PullOffFitError, fit_pull_off, gamma_from_pull_offs,  # noqa: E402
                                             model_pull_off)
from petsc_adhesion.model.parameters import Model  # noqa: E402
from petsc_adhesion.model.physical import Bodies  # noqa: E402
from petsc_adhesion.model.reference.jkr import JKR_PULL_OFF  # noqa: E402
from petsc_adhesion.tracing.measured import Measured, Missing  # noqa: E402

TABLE = PullOffTable.default()
#: The largest mu of the shipped table.
TOP = float(TABLE.mu[-1])


def _bodies(mu, R=1e-6, w=0.05, eps=0.4e-9, nu=0.3, sigma=0.0):
    """Bodies at Tabor parameter ``mu`` for work of adhesion ``w`` (eq. 9 solved for E, on a rigid flat)."""
    E = w * math.sqrt(R / (mu**3 * eps**3))
    return Bodies(radius=R, young1=E * (1 - nu**2), poisson1=nu, epsilon=eps, rms=sigma * eps if sigma else None)


def _node(mu, sigma):
    i = int(np.argmin(abs(np.log(TABLE.mu / mu))))
    j = int(np.argmin(abs(TABLE.sigma - sigma)))
    return i, j, float(TABLE.mu[i]), float(TABLE.sigma[j])


def test_the_shipped_table_spans_its_range_and_states_its_error():
    """The shipped table: mu 1e-3 to 1000, the forward model's range (docs/fitting.md), sigma 0 to 10 (the
    footprints of a measured AFM image reach 4.5: docs/population.md), its error measured in every cell, a bar at
    every node."""
    assert TABLE.mu[0] == pytest.approx(1e-3) and TABLE.mu[-1] == pytest.approx(1000.0)
    assert TABLE.sigma[0] == 0 and TABLE.sigma[-1] == pytest.approx(10.0)
    assert TABLE.measured and np.all(np.isfinite(TABLE.cell_F)) and np.all(np.isfinite(TABLE.F_err))
    F, err = TABLE.pull_off(np.array([[1e-3], [1.0], [TOP]]), np.array([0.0, 0.5, 3.0, 10.0]))
    assert F.shape == err.shape == (3, 4) and np.all(F < 0) and np.all((err > 0) & np.isfinite(err))


@pytest.mark.parametrize("mu, sigma", [(0.1, 0.3), (3.0, 0.0)])
def test_a_node_is_the_pull_off_of_the_solvers_whole_curve(mu, sigma):
    """At a node the table is the solver's pull-off: the interpolant passes through the node's value, and that
    value (traced only to F_STOP) is the most tensile load of the default curve traced to F = 2 with its bars."""
    from petsc_adhesion.tracing.trace import trace_curve

    i, j, mu, sigma = _node(mu, sigma)
    F, err = TABLE.pull_off(mu, sigma)
    assert float(F) == pytest.approx(TABLE.F[i, j], rel=1e-12, abs=0)
    whole = trace_curve(Model(mu=mu, sigma=sigma)).pull_off.F
    assert abs(TABLE.F[i, j] - whole.value) <= TABLE.F_err[i, j] + whole.err
    assert TABLE.F_err[i, j] <= float(err)


def _rigid_pull_off(sigma):
    """The rigid sphere's pull-off under the averaged law: F(lambda) = (8/3) int_{-lambda}^inf p(H) dH (eq. 28 is
    its smooth case: -1 at lambda = 0), its least value over lambda."""
    from scipy.integrate import quad
    from scipy.optimize import minimize_scalar

    from petsc_adhesion.model.pressure import pressure_law

    law = pressure_law(Model(sigma=sigma))

    def F(h):
        return 8 / 3 * quad(lambda H: float(law(np.array([H]))[0][0]), h, np.inf, limit=400, epsabs=1e-13)[0]
    hs = np.linspace(law.wall + 1e-3, law.wall + 10 + 2 * sigma, 80)
    k = int(np.argmin([F(h) for h in hs]))
    return minimize_scalar(F, bracket=(hs[max(k - 1, 0)], hs[k], hs[k + 1]), tol=1e-10).fun


@pytest.mark.parametrize("sigma", [0.0, 0.2, 1.0, 3.0, 4.5, 10.0])
def test_the_stiff_end_is_the_rigid_spheres(sigma):
    """mu -> 0: the rigid sphere's pull-off, -1 smooth (Bradley's 2 pi R w), and the averaged law's least
    integral with roughness (-0.645 at sigma 0.2, -0.0309 at 1, -0.0035 at 3, -3.2e-4 at 10; 4.5 between two
    nodes); at mu = 1e-3 the elastic correction is below 1e-4 of it."""
    truth = -1.0 if sigma == 0 else _rigid_pull_off(sigma)
    if sigma == 0:
        assert _rigid_pull_off(0.0) == pytest.approx(-1.0, abs=1e-9)
    F, err = TABLE.pull_off(1e-3, sigma)
    assert abs(float(F) - truth) <= float(err) + 1e-4 * abs(truth)


def test_the_soft_end_approaches_jkrs():
    """Smooth, towards large mu: JKR's -3/4, approached from below, the distance falling like mu^-1.5
    (docs/soft.md: 0.147 mu^-1.52 fitted at mu 5 and 20, 1.2e-4 +- 8.4e-5 at mu = 100): within 0.2 mu^-1.5 and
    the table's bar at its largest mu, and shrinking along its last rows."""
    mu = TABLE.mu[TABLE.mu >= 1.0]
    F, err = TABLE.pull_off(mu, 0.0)
    gap = JKR_PULL_OFF - F
    assert np.all(gap > -err) and np.all(np.diff(gap) < 0)
    assert gap[-1] <= 0.2 * mu[-1] ** -1.5 + err[-1] and err[-1] < 5e-3


@pytest.mark.parametrize("mu, sigma", [(0.05, 0.22), (0.3, 0.63), (1.3, 0.13), (4.0, 1.7), (0.45, 4.4), (20.0, 7.2)])
def test_between_the_nodes_the_solver_is_within_the_stated_bar(mu, sigma):
    """Points off the nodes and off the cells' centres (where the error was measured): the solver's pull-off
    lies within the table's bar (its own bar added), which is not wider than a tenth of the pull-off."""
    s = trace_pull_off(mu, sigma)
    assert s.failed is None, s.failed
    F, err = TABLE.pull_off(mu, sigma)
    assert abs(float(F) - s.F.value) <= float(err) + s.F.err
    assert float(err) < 0.1 * abs(s.F.value)


#: The solver's pull-off at mu = 500, sigma = 0.45 (between the nodes 100 and 1000 and 0.4 and 0.6, off the cells'
#: centres): trace_pull_off(500, 0.45), F and its bar from nested grids, lambda and its bar; stored, since the curve
#: costs 29 s of CPU (one rank, load 9).
MU_500 = (500.0, 0.45, -0.11028402464898411, 1.248955727729696e-05, -109.86289139668196, 0.0022067645247807314)


def test_the_last_row_holds_the_solver_between_its_nodes():
    """Between the nodes mu = 100 and 1000 (the row the table reaches mu = 1000 with), the solver's pull-off lies
    within the table's bar and its own (5.2e-5 off; the bar 2.4e-3, 2.2% of the pull-off), lambda too (2.2 off, a bar
    of 6.6: lambda / (1 + mu) interpolated, which suits JKR's lambda ~ -0.77 mu better than a rough sphere's)."""
    mu, sigma, F, F_err, lam, lam_err = MU_500
    tab, bar = TABLE.pull_off(mu, sigma)
    assert TOP == pytest.approx(1000.0) and abs(float(tab) - F) <= float(bar) + F_err
    assert float(bar) < 0.05 * abs(F)
    tl, tl_err = TABLE.pull_off_lambda(mu, sigma)
    assert abs(float(tl) - lam) <= float(tl_err) + lam_err


def test_outside_the_table_is_refused_in_one_line(tmp_path):
    far = float(TABLE.sigma[-1]) + 0.5
    assert list(TABLE.covers([1e-4, 1.0, 2 * TOP, 1.0, np.nan], [0.0, far, 0.0, 1.0, 0.0])) == \
        [False, False, False, True, False]
    for mu, sigma in ((2 * TOP, 0.0), (1.0, far), (np.nan, 0.0), (1.0, -0.1)):
        with pytest.raises(OutOfRange) as e:
            TABLE.pull_off(np.array([1.0, mu]), sigma)
        assert "\n" not in str(e.value) and f"the pull-off table holds mu in [0.001, {TOP:g}]" in str(e.value)
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a table")
    with pytest.raises(ValueError, match="not a pull-off table"):
        PullOffTable.load(str(bad))
    path = tmp_path / "t.npz"
    TABLE.save(str(path))
    again = PullOffTable.load(str(path))
    F, err = again.pull_off(0.7, 0.33)
    assert (float(F), float(err)) == tuple(float(x) for x in TABLE.pull_off(0.7, 0.33))
    with np.load(path) as z:
        d = dict(z)
    d["format_version"] = np.array(FORMAT_VERSION + 1)
    np.savez(path, **d)
    with pytest.raises(ValueError, match="rebuild it"):
        PullOffTable.load(str(path))


def test_the_pull_off_determines_w_over_the_whole_table():
    """P = 2 pi R w |F_po| rises with w wherever 1 + (2/3) d ln|F_po| / d ln mu > 0: the inversion's bisection
    needs it, and it holds on a fine grid over the table."""
    mu, sigma = np.meshgrid(np.geomspace(TABLE.mu[0], TABLE.mu[-1], 200), np.linspace(0, TABLE.sigma[-1], 201),
                            indexing="ij")
    assert np.min(1 + TABLE.slope(mu, sigma) / 1.5) > 0.2


#: A large mu of the fit's table path: beyond the fit's old range (50), between the table's nodes 10 and 100.
LARGE_MU = 60.0


def test_a_pull_off_at_large_mu_gives_w_back_through_the_table_and_the_solver():
    """w = 0.05 J/m^2 at mu = 60 (beyond the fit's old range, 50; between the table's nodes, where its
    interpolation has an error of its own): P from the solver's pull-off with its bar (a curve of its own), the
    fit inverts the table and ends on the solver's root (two curves: the table's path, the same code as at mu =
    300 for about a third of a curve's cost there), w back within its bar; the table's inversion alone within
    its own wider bar."""
    b = _bodies(LARGE_MU)
    e = model_pull_off(Model(mu=LARGE_MU), error_bars=True)
    P = abs(e.F.value) * 2 * math.pi * b.R * 0.05
    P_err = e.F.err * 2 * math.pi * b.R * 0.05
    f = fit_pull_off(P, b, P_err=P_err)
    assert isinstance(f.gamma, Measured) and f.gamma.covers(0.05, 1.96), (f.gamma, f.F)
    assert f.curves == 2 and f.mu == pytest.approx(LARGE_MU, rel=1e-3) and f.trustworthy
    assert f.closed_form("jkr").gamma == pytest.approx(0.05, rel=2e-3)     # JKR holds there
    alone = gamma_from_pull_offs(np.array([P]), b, np.array([P_err]))
    assert alone.found[0] and abs(alone.gamma[0] - 0.05) <= 1.96 * alone.gamma_err[0]
    assert alone.gamma_err[0] >= f.gamma.err


def test_a_rough_pull_off_gives_w_back():
    """sigma = 0.3 (an rms of 0.12 nm on epsilon 0.4 nm) at mu = 0.6: P from the solver's whole curve, w back
    within its bar."""
    from petsc_adhesion.tracing.trace import trace_curve

    b = _bodies(0.6, sigma=0.3)
    F = trace_curve(Model(mu=0.6, sigma=0.3)).pull_off.F
    P = abs(F.value) * 2 * math.pi * b.R * 0.05
    f = fit_pull_off(P, b, P_err=abs(F.err) * 2 * math.pi * b.R * 0.05)
    assert f.gamma.covers(0.05, 1.96) and f.sigma == pytest.approx(0.3) and f.curves <= 2


def test_a_pull_off_beyond_mu_1000_is_one_line():
    b = _bodies(1.0)
    w = 0.05 * (5000.0 / 1.0) ** 1.5                 # mu = 5000 at these moduli
    with pytest.raises(PullOffFitError) as e:
        fit_pull_off(2 * math.pi * b.R * w * 0.75, b)
    assert "\n" not in str(e.value) and "above 1000" in str(e.value)


def test_a_map_of_pull_offs_becomes_a_map_of_w():
    """The pull-offs of spheres at mu = 0.01 to the table's top (its own P: the inversion gives their w back to its
    tolerance) and of one traced by the solver (w back within its bar); a P of 0, not finite, beyond the table's
    mu, below mu 1e-3, and one as uncertain as itself are entries without a value, each with its reason."""
    b = _bodies(1.0, sigma=0.2)
    c = math.sqrt(b.E**2 * b.epsilon**3 / b.R)           # w = c mu^1.5 (eq. 9)
    mus = np.array([0.01, 0.3, 3.0, 0.4 * TOP, 0.99 * TOP])
    w_true = c * mus**1.5
    P_tab = 2 * math.pi * b.R * w_true * np.abs(TABLE.pull_off(mus, 0.2)[0])
    e = trace_pull_off(2.0, 0.2)
    w2 = c * 2.0**1.5
    P_solver = 2 * math.pi * b.R * w2 * abs(e.F.value)
    P = np.array([[*P_tab, P_solver], [0.0, np.nan, P_tab[-1] * 1e3, P_tab[0] * 1e-3, P_tab[2], P_tab[2]]])
    P_err = np.zeros_like(P)
    P_err[1, 4] = P[1, 4]
    m = gamma_from_pull_offs(P, b, P_err)
    assert m.gamma.shape == P.shape and m.sigma == pytest.approx(0.2)
    assert np.allclose(m.gamma[0, :5], w_true, rtol=1e-9, atol=0)
    assert abs(m.gamma[0, 5] - w2) <= 1.96 * m.gamma_err[0, 5]
    assert np.all(m.table_err[0] <= m.gamma_err[0]) and np.all(m.gamma_err[0] < 0.05 * m.gamma[0])
    assert list(m.found[1]) == [False] * 5 + [True]
    r = m.reasons[1]
    assert r[0] == r[1] == "not a finite positive pull-off force"
    assert f"above {TOP:g}" in r[2] and "below 0.001" in r[3] and r[4].startswith("its 95% interval")
    q = m.quantity((1, 2))
    assert isinstance(q, Missing) and q.reason == r[2] and isinstance(m.quantity((0, 0)), Measured)
    assert len(m.quantities()) == P.size
    with pytest.raises(TypeError):
        gamma_from_pull_offs(P, Bodies(radius=1e-6, young1=None, poisson1=None, epsilon=0.4e-9))
    far = gamma_from_pull_offs(P_tab, _bodies(1.0, sigma=float(TABLE.sigma[-1]) + 0.5))
    assert not far.found.any() and "outside the pull-off table" in far.reasons[0]


def test_a_built_tables_nodes_resume_a_larger_build(tmp_path):
    """benchmarks.pull_off seed: the shipped table's nodes journaled for a build over one more sigma node leave
    that build the new node of every row and every cell's centre (new nodes change the interpolant about the
    old cells), and the journaled nodes make the shipped table's nodes again, value for value."""
    from petsc_adhesion.benchmarks.pull_off import _key, journal, points, seed

    out = str(tmp_path / "bigger.npz")
    assert seed(TABLE, out) == TABLE.F.size
    done = journal(out)
    sigma = tuple(float(s) for s in TABLE.sigma) + (12.0,)
    todo = [p for p in points(tuple(float(m) for m in TABLE.mu), sigma) if _key(*p) not in done]
    assert sorted((m, s) for k, m, s in todo if k == "node") == [(float(m), 12.0) for m in TABLE.mu]
    assert sum(k == "centre" for k, _, _ in todo) == (TABLE.mu.size - 1) * (len(sigma) - 1)
    again = PullOffTable.of_nodes(TABLE.mu, TABLE.sigma, [done[_key("node", float(m), float(s))]
                                                          for m in TABLE.mu for s in TABLE.sigma])
    for name in ("F", "F_err", "F_grid", "lam", "lam_err", "seconds"):
        assert np.array_equal(getattr(again, name), getattr(TABLE, name)), name


@pytest.mark.parametrize("args, says", [
    ([], "benchmarks.pull_off: the following arguments are required: command"),
    (["build", "--mu", "x"], "benchmarks.pull_off: argument --mu: invalid float value: 'x'"),
    (["seed", "--out"], "benchmarks.pull_off: argument --out: expected one argument"),
    (["report", "no/such.npz"], "benchmarks.pull_off: no/such.npz: not a pull-off table ("),
])
def test_the_builder_s_bad_input_is_one_line_and_writes_nothing(tmp_path, args, says):
    """The pull-off table's builder refuses bad arguments, its subcommands' among them, in one line naming
    itself, exit 2, no file."""
    import subprocess
    import sys

    from conftest import _env

    p = subprocess.run([sys.executable, "-m", "petsc_adhesion.benchmarks.pull_off", *args], cwd=tmp_path,
                       capture_output=True, text=True, env=_env(), timeout=300)
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("\n") == 1 and p.stderr.startswith(f"petsc-adhesion: {says}"), p.stderr
    assert list(tmp_path.iterdir()) == []
