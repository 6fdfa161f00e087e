"""The curve family table against the solver: a small table built here (mu 0.1 to 0.8, sigma 0 to 0.1), its
nodes reproducing the solver's sampled curves to round-off, its off-node curves within the error it measured,
its legs behind a spring against fitting/forward.py's on the same curve, its refusals and its file."""
import dataclasses
import math
import re

import numpy as np
import pytest

from petsc_adhesion.family.build import TableGrid, build, event_points, regrid_points, trace_node
from petsc_adhesion.family.coordinate import NotMonotone, coordinate, sample, stretch, unstretch
from petsc_adhesion.family.legs import spring_legs
from petsc_adhesion.family.table import FORMAT_VERSION, FamilyTable, OutOfRange, TableError, lagrange

MU, SIGMA = (0.1, 0.2, 0.4, 0.8), (0.0, 0.05, 0.1)


@pytest.fixture(scope="module")
def table():
    """The table of 12 nodes, its error measured at its 6 cell centres behind one spring."""
    from petsc_adhesion.benchmarks.family import measure

    return measure(build(TableGrid(mu=MU, sigma=SIGMA, n_tau=150)), springs=(0.5,))


def _solver_events(c):
    """snap_on, snap_off and the pull-off of a traced curve, on its grid."""
    def grid(m):
        return m.grid if m.grid is not None else m.value
    out = {k: [(grid(e.lam), grid(e.F)) for e in c.events if e.kind == k] for k in ("snap_on", "snap_off")}
    out["pull_off"] = [min(((grid(e.lam), grid(e.F)) for e in c.events if e.kind == "F_min"), key=lambda x: x[1])]
    return out


def test_lagrange_weights_are_exact_for_cubics_and_at_nodes():
    """Four nodes reproduce a cubic anywhere between them (its interpolant is itself) and a node's value
    exactly (weights one and zeros)."""
    nodes = np.log(np.array([0.1, 0.2, 0.4, 0.8, 1.6, 3.2]))
    p = np.array([0.3, -1.2, 0.7, 2.0])
    for x in (-2.1, -1.0, 0.05, 1.1):
        i0, w = lagrange(nodes, x)
        assert abs(w @ np.polyval(p, nodes[i0:i0 + 4]) - np.polyval(p, x)) < 1e-12
    for k, x in enumerate(nodes):
        i0, w = lagrange(nodes, x)
        assert np.array_equal(w, (np.arange(i0, i0 + 4) == k).astype(float))


def test_the_coordinate_of_a_rigid_sphere_and_its_stretch():
    """On a rigid sphere in contact, H = H(0) + r^2/2 crosses the level at a^2/2 = level - H(0): s is
    level - 2 H(0) (grows as H(0) falls); tau spans [-1, 1] and unstretch inverts it."""
    H0 = np.linspace(0.4, -0.3, 8)
    a = np.sqrt(2 * (0.5 - H0))
    assert np.allclose(coordinate(H0, a), 0.5 - 2 * H0, rtol=0, atol=1e-14)
    s = np.linspace(-20.0, 30.0, 101)
    t = stretch(s, 0.1, -20.0, 30.0, 0.01)
    assert t[0] == -1.0 and abs(t[-1] - 1.0) < 1e-15 and np.all(np.diff(t) > 0)
    assert np.allclose(unstretch(t, 0.1, -20.0, 30.0, 0.01), s, rtol=0, atol=1e-10)


def test_a_coordinate_that_falls_back_is_refused():
    """A curve along which s = a^2/2 - H(0) falls by more than a regrid's hair cannot be tabulated."""
    H0 = np.r_[np.linspace(3.0, 0.0, 20), 1.0, np.linspace(-0.01, -0.1, 10)]
    a = np.zeros(H0.size)
    with pytest.raises(NotMonotone, match="falls by"):
        sample(-H0, np.linspace(-0.1, 2.5, H0.size), H0, a, 0.5, 2.0, np.linspace(-1, 1, 11), 1.0)


def test_the_coordinate_grows_along_the_solver_curves():
    """Along the solver's curves through their folds (mu = 2: a pair; mu = 3, sigma = 0.5), leaving out the
    second point of a state on two grids (a regrid), s falls by no more than a hair of its range."""
    for mu, sigma in ((2.0, 0.0), (3.0, 0.5)):
        b = trace_node(mu, sigma).branch
        own = ~regrid_points(b)
        s = coordinate(b.H0[own], b.contact_radius[own])
        falls = np.diff(s)[np.diff(s) < 0]
        assert (falls.size == 0 or -falls.min() < 1e-4 * np.ptp(s)), (mu, sigma, falls)


def test_the_nodes_reproduce_the_solver_to_round_off(table):
    """At a node the interpolant is the node's curve: the solver's curve traced again and sampled on the
    table's coordinate, to round-off; its events are the solver's to the sampling's accuracy."""
    from petsc_adhesion.discretization.contact import edge_level
    from petsc_adhesion.model.pressure import pressure_law

    for mu, sigma in ((0.4, 0.05), (0.8, 0.1)):
        c = trace_node(mu, sigma)
        b = c.branch
        ref = sample(b.lam, b.F, b.H0, b.contact_radius, edge_level(pressure_law(c.model)), table.F_max,
                     table.tau, mu, regrid_points(b), event_points(c))
        got = table.curve(mu, sigma)
        assert np.max(np.abs(got.lam - ref.lam)) < 1e-12 and np.max(np.abs(got.F - ref.F)) < 1e-12
        want = _solver_events(c)
        mine = {k: [(e.lam.value, e.F.value) for e in got.events() if e.kind == k] for k in want}
        assert len(mine["snap_on"]) == len(want["snap_on"]) and len(mine["snap_off"]) == len(want["snap_off"])
        (l, F), = mine["pull_off"]
        assert abs(F - want["pull_off"][0][1]) < 1e-4          # the pull-off: a minimum, its F well conditioned


def test_off_node_curves_are_the_solver_s_within_the_measured_error(table):
    """Away from the nodes and the midpoints the error was measured at (a third of the way across a cell),
    the pull-off and the force behind a spring are the solver's to within the error the table states (twice
    the largest measured at the cell centres about them)."""
    from petsc_adhesion.benchmarks.family import _spring

    worst = table.worst()
    assert isinstance(worst, TableError) and worst.points == 6
    assert 0 < worst.event_F < 0.02 and 0 < worst.F_at_Z < 0.1      # measured, and small
    for mu, sigma in ((0.1 * 2 ** (1 / 3), 0.05 / 3), (0.4 * 2 ** (2 / 3), 0.05 + 0.05 * 2 / 3)):
        err = table.error(mu, sigma)
        got = table.curve(mu, sigma)
        (pl, pF), = [(e.lam.value, e.F.value) for e in got.events() if e.kind == "pull_off"]
        want = _solver_events(trace_node(mu, sigma))["pull_off"][0]
        assert abs(pF - want[1]) <= err.event_F, (mu, sigma, pF, want, err)
        eF, eZ, eJ = _spring(table, mu, sigma, 0.5)
        assert eF <= err.F_at_Z and eZ <= err.jump_Z and eJ <= err.jump_F, (mu, sigma, eF, eZ, eJ, err)
        bars = [e.F.err for e in got.events()]
        assert all(b == err.event_F for b in bars)                 # the bar every event carries


def test_the_legs_splines_are_scipys_to_the_bit():
    """cubic_spline, the legs' splines without scipy's checks: the coefficients and the values of scipy's
    CubicSpline, to the last bit, for one column or several (each as alone), the slope given or not-a-knot at
    each end."""
    from scipy.interpolate import CubicSpline

    from petsc_adhesion.family.legs import cubic_spline

    rng = np.random.default_rng(11)
    for n in (4, 5, 9, 300):
        x = np.cumsum(rng.uniform(0.01, 2.0, n))
        Y = rng.normal(size=(n, 3))
        at = np.sort(rng.uniform(x[0] - 1, x[-1] + 1, 200))
        for left in (None, np.array([0.0, -0.3, 2.0])):
            for right in (None, np.array([0.5, 1.7, -1.0])):
                ours = cubic_spline(x, Y, left, right)
                values = ours(at)
                for j in range(3):
                    bc = ((1, left[j]) if left is not None else "not-a-knot",
                          (1, right[j]) if right is not None else "not-a-knot")
                    theirs = CubicSpline(x, Y[:, j], bc_type=bc)
                    assert np.array_equal(ours.c[:, :, j], theirs.c)
                    assert np.array_equal(values[:, j], theirs(at))
                    one = cubic_spline(x, Y[:, j], None if left is None else left[j],
                                       None if right is None else right[j])
                    assert np.array_equal(one.c, theirs.c)


def test_the_far_branch_is_the_rigid_sphere_behind_the_spring():
    """Below a branch's start the legs continue it by the rigid sphere (eq. 28) scaled to the branch there: each
    force it gives is c F_rigid(lambda) at the lambda that puts the spring's base at Z, lambda = Z - F / K,
    to 1e-13 (its Newton steps against the closed form)."""
    from petsc_adhesion.model.reference.rigid import rigid_load

    lam = np.linspace(-3.0, 0.1, 40)
    F = 0.9 * rigid_load(lam)                   # a far branch 10% weaker than the rigid sphere's
    for K in (1e-3, 0.05, 2.0):
        legs = spring_legs(np.arange(lam.size, dtype=float), lam, F, K)
        Z = np.linspace(legs.pieces[0].Z_lo - 5000.0, legs.pieces[0].Z_lo - 1e-3, 300)
        got = legs._far(Z)
        want = legs._far_factor * rigid_load(Z - got / K)
        assert np.max(np.abs(got - want) / np.abs(want)) < 1e-13


def test_spring_legs_are_forward_py_s_on_the_same_curve():
    """The legs found from a branch alone (turning points of Z where its spline's rate changes sign) against
    fitting/forward.py's from the library's located jump events on the same traced curve: the same jumps to
    the events' accuracy, the same force away from them."""
    from petsc_adhesion.discretization.problem import step_scale
    from petsc_adhesion.fitting.forward import ForwardCurve
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import CurveRequest, curve_settings, trace_curve

    K = 0.5
    model = Model(mu=2.0)
    c = trace_curve(model, settings=curve_settings(step_scale(model), ds_max=0.05),
                    request=CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=K))
    truth = ForwardCurve(c, K)
    b = c.branch
    own = ~regrid_points(b)                 # a regrid's second point at one state: its grid's values ring
    lam, F = b.lam[own], b.F[own]
    s = np.r_[0.0, np.cumsum(np.hypot(np.diff(lam), np.diff(F)))]     # arclength: monotone
    mine = spring_legs(s, lam, F, K)
    for leg in ("approach", "retract"):
        assert len(mine.jumps[leg]) == len(truth.jumps[leg]) >= 1
        assert np.allclose(mine.jumps[leg], truth.jumps[leg], rtol=0, atol=2e-3), leg
        Z = np.linspace(b.Z.min() - 1.0, b.Z.max(), 600)
        away = np.all([np.abs(Z - z) > 0.02 for z in truth.jumps[leg]], axis=0)
        assert np.max(np.abs(mine.predict(Z[away], leg) - truth.predict(Z[away], leg))) < 2e-3, leg


def _tanh_legs(A: float, w: float, K: float):
    """The legs behind K of F = -1/2 - A tanh(x / w), x = lambda + 1 (lambda from -3 to 1), sampled densely."""
    x = np.linspace(-2.0, 2.0, 4001)
    return spring_legs(x, x - 1.0, -0.5 - A * np.tanh(x / w), K)


def test_a_loop_one_side_lacks_counts_as_its_extent():
    """Behind K, F = -1/2 - A tanh(x / w) is steeper than the spring where sech^2(x / w) > K w / A: with A > K w a
    hysteresis loop between x = -x* (the approach's jump) and x* (the retract's), x* = w arccosh(sqrt(A / (K w))),
    Z = lambda + F / K, so the loop is Z(-x*) - Z(x*) = 2 (A tanh(x* / w) / K - x*) wide; the approach's jump
    lands at x_l > x* where Z(x_l) = Z(-x*), a jump in F of A (tanh(x* / w) + tanh(x_l / w)), and the retract's
    the same by symmetry.  Against the curve with A = 0.9 K w (no loop), the measurement counts the loop one side
    lacks as that width and that jump, whichever side has it; an extra jump without a partner on the other leg
    (no loop) stays an error of unknown size."""
    from scipy.optimize import brentq

    from petsc_adhesion.benchmarks.family import _leg_jumps

    K, w = 0.5, 0.2
    A = 1.2 * K * w
    xs = w * math.acosh(math.sqrt(A / (K * w)))
    Z = (lambda x: x - 1.0 + (-0.5 - A * math.tanh(x / w)) / K)
    width = Z(-xs) - Z(xs)
    xl = brentq(lambda x: Z(x) - Z(-xs), xs, 2.0)
    jump = A * (math.tanh(xs / w) + math.tanh(xl / w))
    assert 0.02 < width < 0.03 and 0.1 < jump < 0.2          # narrow in Z, large in F: a loop about its cusp
    loop, none = _tanh_legs(A, w, K), _tanh_legs(0.9 * K * w, w, K)
    assert len(loop.jumps["approach"]) == len(loop.jumps["retract"]) == 1 and not none.jumps["approach"]
    for leg in ("approach", "retract"):
        for mine, truth in ((loop, none), (none, loop)):
            eZ, eJ = _leg_jumps(mine, truth, leg)
            assert abs(eZ - width) < 1e-6 * width and abs(eJ - jump) < 1e-4 * jump, (leg, eZ, width, eJ, jump)
        assert _leg_jumps(loop, loop, leg) == (0.0, 0.0)

    # a jump with no turning point at the other end of its unstable stretch (no loop): of unknown size
    bare = type("Bare", (), dict(K=K, jumps={"approach": [-2.0], "retract": []}, chains={"approach": ([0], [-2.0])},
                                  pieces=[dataclasses.replace(loop.pieces[0], end=None)],
                                  jump_forces=lambda self, leg: [(-0.5, -0.7)] if leg == "approach" else []))()
    assert _leg_jumps(bare, none, "approach") == (math.inf, math.inf)


def test_a_loop_the_approach_passes_by_counts_as_its_extent_on_the_retract():
    """Two steps, F = -1/2 - A1 tanh((x + 1) / w) - A2 (tanh((x - 1) / w) + 1), x = lambda + 1, both steeper than
    K: the first's loop is so deep (A1 = 24 K w) that the approach's jump lands beyond the second step, whose loop
    (A2 = 1.2 K w) the retract alone passes, as a shallow wiggle about a rough curve's pull-off behind a soft
    spring.  Against the same curve with A2 = 0.9 K w (no second loop, the first the same to the bit), the extra
    jump of the retract counts as the second loop's width, 2 (A2 tanh(x* / w) / K - x*) with x* = w arccosh(sqrt(A2
    / (K w))), and its jump in F, A2 (tanh(x* / w) + tanh(|x_l - 1| / w)) to the landing x_l where Z(x_l) is the
    jump's Z; the approach's one jump is the same on both."""
    from scipy.optimize import brentq

    from petsc_adhesion.benchmarks.family import _leg_jumps

    K, w = 0.5, 0.05
    A1 = 24 * K * w

    def legs(A2):
        x = np.linspace(-3.0, 3.0, 12001)
        F = -0.5 - A1 * np.tanh((x + 1) / w) - A2 * (np.tanh((x - 1) / w) + 1)
        return spring_legs(x, x - 1.0, F, K)

    A2 = 1.2 * K * w
    xs = w * math.acosh(math.sqrt(A2 / (K * w)))
    Z = (lambda u: u + (-A2 * math.tanh(u / w)) / K)          # about x = 1, but for a constant
    width = Z(-xs) - Z(xs)
    ul = brentq(lambda u: Z(u) - Z(xs), -0.5, -xs)
    jump = A2 * (math.tanh(xs / w) + math.tanh(abs(ul) / w))
    two, one = legs(A2), legs(0.9 * K * w)
    assert len(two.jumps["approach"]) == len(one.jumps["approach"]) == 1
    assert len(two.jumps["retract"]) == 2 and len(one.jumps["retract"]) == 1
    assert _leg_jumps(two, one, "approach") == (0.0, 0.0)
    eZ, eJ = _leg_jumps(two, one, "retract")
    assert abs(eZ - width) < 1e-6 * width and abs(eJ - jump) < 1e-4 * jump, (eZ, width, eJ, jump)


def test_the_solver_s_legs_keep_the_loop_it_located():
    """At (mu 0.237, sigma 0.225) behind K = 0.5 the default curve locates a pair of jumps within one step (35
    points), and its legs, made from the points' stability, had left the loop out (the table, which holds it,
    was counted as missing a jump).  The measurement's solver curve is traced again with shorter steps until its
    legs keep what it located: the loop is then the one a curve with steps 1/10 as long has, to 1e-4."""
    from petsc_adhesion.benchmarks.family import _truth
    from petsc_adhesion.discretization.problem import step_scale
    from petsc_adhesion.fitting.forward import ForwardCurve
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import CurveRequest, curve_settings, trace_curve

    mu, sigma, K = 0.23713737, 0.225, 0.5
    model = Model(mu=mu, sigma=sigma)
    request = CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=K)
    first = trace_curve(model, settings=curve_settings(step_scale(model), observable_max=2.3), request=request)
    assert {e.kind for e in first.events} >= {"jump_in", "jump_off"} and not ForwardCurve(first, K).jumps["approach"]
    fine = ForwardCurve(trace_curve(model, settings=curve_settings(0.1 * step_scale(model), observable_max=2.3),
                                    request=request), K)
    _, truth = _truth(mu, sigma, K, 2.0)
    for leg in ("approach", "retract"):
        assert len(truth.jumps[leg]) == len(fine.jumps[leg]) == 1
        assert abs(truth.jumps[leg][0] - fine.jumps[leg][0]) < 1e-4, (leg, truth.jumps[leg], fine.jumps[leg])


def test_the_table_s_legs_at_a_node_are_the_solver_s(table):
    """At a node, the table's curve behind a spring against the solver's traced behind it: its error there is
    the sampling's alone, below the error measured between nodes."""
    from petsc_adhesion.benchmarks.family import _spring

    eF, eZ, eJ = _spring(table, 0.4, 0.05, 0.5)
    worst = table.worst()
    assert eF < 1e-4 and eF <= worst.F_at_Z and eZ <= worst.jump_Z and eJ <= worst.jump_F


@pytest.mark.parametrize("call, says", [
    (lambda t: t.curve(0.05, 0.0), r"^mu 0\.05: the table holds mu in \[0\.1, 0\.8\]$"),
    (lambda t: t.curve(0.3, 0.7), r"^sigma 0\.7: the table holds sigma in \[0, 0\.1\]$"),
    (lambda t: t.curve(float("nan"), 0.0), r"^mu nan: the table holds mu"),
    (lambda t: t.error(2.0, 0.0), r"^mu 2\.0: the table holds mu"),
    (lambda t: t.curve(0.3, 0.0).behind(0.0), r"^K 0\.0: expected a spring stiffness, a finite real > 0$"),
    (lambda t: t.curve(0.3, 0.0).behind(1.0).predict([1e3], "approach"),
     r"^Z 1000: the table holds the curve up to F = 2, Z <= "),
    (lambda t: t.curve(0.3, 0.0).behind(1.0).predict([0.0], "up"), r"^leg 'up': expected approach or retract$"),
])
def test_out_of_range_is_one_line(table, call, says):
    with pytest.raises(OutOfRange, match=says) as e:
        call(table)
    assert "\n" not in str(e.value)


def test_the_file_round_trip_keeps_every_value(table, tmp_path):
    """Saved and loaded: the same nodes, curves, error and versions; the interpolant the same numbers."""
    path = str(tmp_path / "t.npz")
    table.save(path)
    back = FamilyTable.load(path)
    for name in ("mu", "sigma", "tau", "lam", "F", "s_lo", "s_hi", "s0", "delta", "seconds", "springs",
                 "err_mu", "err_sigma"):
        assert np.array_equal(getattr(back, name), getattr(table, name)), name
    assert all(np.array_equal(back.errors[f], table.errors[f]) for f in table.errors)
    assert (back.F_max, back.roughness, back.version) == (table.F_max, table.roughness, table.version)
    a, b = table.curve(0.3, 0.07), back.curve(0.3, 0.07)
    assert np.array_equal(a.F, b.F) and a.error == b.error


def test_a_file_of_another_version_or_no_table_is_one_line(table, tmp_path):
    path = str(tmp_path / "t.npz")
    table.save(path)
    z = dict(np.load(path))
    z["format_version"] = np.array(FORMAT_VERSION + 1)
    np.savez(str(tmp_path / "v.npz"), **z)
    with pytest.raises(ValueError, match=rf"format version {FORMAT_VERSION + 1}; this program reads version "
                                         rf"{FORMAT_VERSION} \(rebuild it\)$"):
        FamilyTable.load(str(tmp_path / "v.npz"))
    (tmp_path / "x.npz").write_text("no table")
    with pytest.raises(ValueError, match="not a curve family table"):
        FamilyTable.load(str(tmp_path / "x.npz"))


def _damaged(src, tmp_path):
    """(name, path, what the refusal says) of copies of the table file ``src``, each damaged one way."""
    raw = open(src, "rb").read()
    with np.load(src) as z:
        good = dict(z)

    def changed(name, **arrays):
        d = {k: v for k, v in {**good, **arrays}.items() if v is not None}
        np.savez(str(tmp_path / name), **d)
        return str(tmp_path / name)

    def written(name, data):
        (tmp_path / name).write_bytes(data)
        return str(tmp_path / name)

    middle = bytearray(raw)
    middle[len(raw) // 3:len(raw) // 3 + 200] = bytes(200)
    return [
        ("text", written("text.npz", b"no table"), r"\(not an \.npz archive\)$"),
        ("empty", written("empty.npz", b""), r"\(not an \.npz archive\)$"),
        ("truncated", written("half.npz", raw[:len(raw) // 2]), r"\(a truncated or corrupted \.npz archive: "),
        ("corrupted", written("mid.npz", bytes(middle)), r"\(a truncated or corrupted \.npz archive: "),
        ("no file", str(tmp_path / "absent.npz"), r"No such file or directory"),
        ("kind", changed("kind.npz", format=np.array("petsc-adhesion something else")), r"\(no format '"),
        ("version", changed("v.npz", format_version=np.array(7)),
         r"of format version 7; this program reads version 1 \(rebuild it\)$"),
        ("no version", changed("nov.npz", format_version=None), r"without an integer format version; this program "),
        ("text version", changed("sv.npz", format_version=np.array("1")), r"without an integer format version"),
        ("no mu", changed("nomu.npz", mu=None), r"without the array mu \(rebuild it\)$"),
        ("no roughness, sigma", changed("nors.npz", roughness=None, sigma=None),
         r"without the arrays sigma, roughness \(rebuild it\)$"),
    ]


@pytest.mark.parametrize("which", ["family", "pull-off"])
def test_every_damaged_table_file_is_one_line_naming_it(which, tmp_path):
    """Both tables' files read through family/table.py's load_npz: a file that is no table of this program's
    format and version, or lacks an array, or is no .npz, truncated or corrupted, is a ValueError of one line
    that begins with the file and says which; the file undamaged reads back the same values."""
    from petsc_adhesion.family.pull_off import DEFAULT_PATH, PullOffTable
    from petsc_adhesion.family.table import shipped_path

    cls, src, kind = (FamilyTable, shipped_path("smooth"), "curve family table") if which == "family" else \
        (PullOffTable, DEFAULT_PATH, "pull-off table")
    seen = set()
    for name, path, says in _damaged(src, tmp_path):
        with pytest.raises(ValueError) as e:
            cls.load(path)
        msg = str(e.value)
        assert "\n" not in msg and msg.startswith(f"{path}: ") and kind in msg, (name, msg)
        assert re.search(says, msg), (name, msg)
        seen.add(msg)
    assert len(seen) == 11                  # each damage said in its own words
    a, b = cls.load(src), cls.load(changed_copy(src, tmp_path))
    assert np.array_equal(a.mu, b.mu) and np.array_equal(a.F, b.F) and a.roughness == b.roughness


def test_a_family_table_of_the_right_names_but_wrong_arrays_is_one_line(tmp_path):
    """A family table's arrays are read by position: a file with every array named but one of another shape,
    order or value (a node curve cut short, mu out of order or at 0, a NaN in F, a coordinate of another grid,
    an error field shorter than its midpoints) is refused in one line naming the array, where it used to load
    and fail later inside an interpolation or give another curve's numbers."""
    from petsc_adhesion.family.table import shipped_path

    src = shipped_path("rough")
    with np.load(src) as z:
        good = dict(z)
    F_nan = good["F"].copy()
    F_nan[3, 2, 100] = np.nan
    cases = {
        "lam": dict(lam=good["lam"][:, :, :-1]),
        "F": dict(F=F_nan),
        "mu": dict(mu=good["mu"][::-1].copy()),
        "sigma": dict(sigma=np.r_[-0.05, good["sigma"][1:]]),
        "s0": dict(s0=good["s0"][:, :-1]),
        "F_max": dict(F_max=np.array([2.0, 3.0])),
        "the measured error": dict(err_jump_Z=good["err_jump_Z"][:-1]),
    }
    seen = set()
    for name, arrays in cases.items():
        path = str(tmp_path / f"{name.replace(' ', '_')}.npz")
        np.savez(path, **{**good, **arrays})
        with pytest.raises(ValueError) as e:
            FamilyTable.load(path)
        msg = str(e.value)
        assert "\n" not in msg and msg.startswith(f"{path}: not a curve family table ({name}: "), msg
        assert msg.endswith("; rebuild it)"), msg
        seen.add(msg)
    assert len(seen) == len(cases)
    np.savez(str(tmp_path / "same.npz"), **good)               # the same arrays written again read back
    assert np.array_equal(FamilyTable.load(str(tmp_path / "same.npz")).F, good["F"])


def changed_copy(src, tmp_path):
    """``src`` read and written again with numpy (uncompressed): the same arrays in another archive."""
    with np.load(src) as z:
        np.savez(str(tmp_path / "again.npz"), **dict(z))
    return str(tmp_path / "again.npz")


def test_a_failed_save_leaves_the_earlier_file(table, tmp_path, monkeypatch):
    """A write that fails half-way leaves the table written before it, and no temporary file."""
    path = str(tmp_path / "t.npz")
    table.save(path)
    before = open(path, "rb").read()

    def broken(fh, **arrays):
        fh.write(b"half")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "savez_compressed", broken)
    with pytest.raises(OSError):
        table.save(path)
    assert open(path, "rb").read() == before and sorted(p.name for p in tmp_path.iterdir()) == ["t.npz"]


def test_an_unmeasured_table_says_its_error_is_missing():
    """Built without its midpoints, a table's error is Missing with its reason, never 0, and its events carry
    no bar but that reason."""
    t = FamilyTable(mu=np.array([1.0]), sigma=np.array([0.0]), tau=np.linspace(-1, 1, 5),
                    lam=np.zeros((1, 1, 5)), F=np.zeros((1, 1, 5)), s_lo=np.zeros((1, 1)), s_hi=np.ones((1, 1)),
                    s0=np.zeros((1, 1)), delta=np.ones((1, 1)), F_max=2.0, roughness="hermite 16")
    e = t.error(1.0, 0.0)
    assert not e and "not measured" in e.reason
    assert math.isfinite(t.curve(1.0, 0.0).F[0])


@pytest.mark.parametrize("args, says", [
    (["build", "--out", "t.npz", "--mu", "3", "1"], "--mu 3 1: expected 0 < lo <= hi"),
    (["build", "--out", "t.npz", "--sigma", "0.2", "0.1"], "sigma: expected increasing roughnesses >= 0"),
    (["build", "--out", "t.npz", "--springs", "0"], "--springs [0.0]: expected stiffnesses > 0"),
    (["build", "--out", "no/such/t.npz"], "--out no/such/t.npz: no folder"),
    (["build", "--out", "t.npz", "--n-tau", "x"], "argument --n-tau: invalid int value: 'x'"),
    (["speed", "t.npz"], "t.npz: not a curve family table"),
    ([], "benchmarks.family: the following arguments are required: command"),
    (["measure"], "benchmarks.family: the following arguments are required: table"),
])
def test_the_builder_s_bad_input_is_one_line_and_writes_nothing(tmp_path, args, says):
    """The builder refuses what it cannot build before any trace: one line, exit 2, no file."""
    import subprocess
    import sys

    from conftest import _env

    p = subprocess.run([sys.executable, "-m", "petsc_adhesion.benchmarks.family", *args], cwd=tmp_path,
                       capture_output=True, text=True, env=_env(), timeout=300)
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("\n") == 1 and says in p.stderr, p.stderr
    assert list(tmp_path.iterdir()) == []


def _rough():
    from petsc_adhesion.family.table import shipped

    return shipped("rough")


def test_parts_join_into_one_table_and_a_coarser_one_is_selected():
    """A table built in parts (along sigma or mu) is joined into the table of all their nodes, the first part's
    node where two hold it, its error not measured (its cells are new); parts on other tau nodes are refused in
    one line; a selection of nodes is the coarser table the sigma pilot compares with the left-out nodes
    (docs/family.md).  On the shipped tables: no trace."""
    from petsc_adhesion.family.build import join, select

    rough = _rough()
    half = rough.sigma.size // 2
    whole = join([select(rough, sigma=range(half + 1)), select(rough, sigma=range(half, rough.sigma.size))])
    assert np.array_equal(whole.sigma, rough.sigma) and np.array_equal(whole.F, rough.F) and not whole.measured
    whole = join([select(rough, mu=[5, 6, 7]), select(rough, mu=[0, 1, 2, 3, 4, 5])])
    assert np.array_equal(whole.mu, rough.mu[:8]) and np.array_equal(whole.lam, rough.lam[:8])
    other = FamilyTable(mu=rough.mu[:1], sigma=np.array([0.3]), tau=np.linspace(-1, 1, 5), lam=np.zeros((1, 1, 5)),
                        F=np.zeros((1, 1, 5)), s_lo=np.zeros((1, 1)), s_hi=np.ones((1, 1)), s0=np.zeros((1, 1)),
                        delta=np.ones((1, 1)), F_max=2.0, roughness=rough.roughness)
    with pytest.raises(ValueError, match="^the parts differ in their tau nodes"):
        join([select(rough, mu=[0]), other])


def test_the_rough_table_at_its_nodes_is_the_solver_s():
    """The shipped rough table at two of its nodes: behind K = 0.5 the force at the solver's own points is the
    solver's (the sampling passes through them), and so is the pull-off, to 1e-4: where the traced points are
    dense (mu = 1, sigma = 0.15) on the cubic splines, where they are sparse (mu = 0.1, sigma = 0.05) on the
    shape-preserving cubic through them and the located turning points (the splines had overshot there, -0.974
    against -0.965: docs/family.md)."""
    from petsc_adhesion.benchmarks.family import _spring

    rough = _rough()
    assert rough.mu[8] == pytest.approx(0.1) and rough.mu[12] == pytest.approx(1.0)
    for mu, sigma in ((float(rough.mu[8]), 0.05), (float(rough.mu[12]), 0.15)):
        assert np.any(np.isclose(rough.sigma, sigma))
        err = rough.error(mu, sigma)
        eF, eZ, eJ = _spring(rough, mu, sigma, 0.5)
        assert eF < 1e-4, (mu, sigma, eF)
        (pl, pF), = [(e.lam.value, e.F.value) for e in rough.curve(mu, sigma).events() if e.kind == "pull_off"]
        off = abs(pF - _solver_events(trace_node(mu, sigma))["pull_off"][0][1])
        assert off < 1e-4 and eZ <= err.jump_Z and eJ <= err.jump_F, (mu, sigma, off, eZ, eJ, err)


def test_the_rough_table_between_nodes_is_within_its_stated_error():
    """At a cell centre of the rough table and a third of the way across another cell (mu and sigma both
    between nodes), its pull-off and its force behind K = 0.5 are the solver's to within the error it states
    there; and that error was measured at every cell centre of its range."""
    from petsc_adhesion.benchmarks.family import _spring, midpoints

    rough = _rough()
    assert rough.err_mu.size == (rough.mu.size - 1) * (rough.sigma.size - 1) == len(midpoints(rough))
    i, j = 6, 3                                   # mu between 0.0316 and 0.0562; sigma between two nodes
    centre = (math.sqrt(rough.mu[i] * rough.mu[i + 1]), 0.5 * (rough.sigma[j] + rough.sigma[j + 1]))
    third = (float(rough.mu[10] * (rough.mu[11] / rough.mu[10]) ** (1 / 3)),
             float(rough.sigma[-3] + (rough.sigma[-2] - rough.sigma[-3]) / 3))
    for mu, sigma in (centre, third):
        err = rough.error(mu, sigma)
        assert isinstance(err, TableError), err
        (pl, pF), = [(e.lam.value, e.F.value) for e in rough.curve(mu, sigma).events() if e.kind == "pull_off"]
        assert abs(pF - _solver_events(trace_node(mu, sigma))["pull_off"][0][1]) <= err.event_F, (mu, sigma, err)
        eF, eZ, eJ = _spring(rough, mu, sigma, 0.5)
        assert eF <= err.F_at_Z and eZ <= err.jump_Z and eJ <= err.jump_F, (mu, sigma, eF, eZ, eJ, err)


def test_the_rough_table_refuses_what_it_was_not_built_for():
    """Beyond the mu the rough table was built to, a curve is refused in one line (never extrapolated)."""
    rough = _rough()
    top = float(rough.mu[-1])
    with pytest.raises(OutOfRange, match=rf"^mu {2 * top!r}: the table holds mu in \[0\.001, {top:g}\]$"):
        rough.curve(2 * top, 1.0)
    top_s = float(rough.sigma[-1])
    with pytest.raises(OutOfRange, match=rf"^sigma {top_s + 0.5!r}: the table holds sigma in \[0, {top_s:g}\]$"):
        rough.curve(0.1, top_s + 0.5)


def test_the_shape_preserving_cubic_keeps_a_step_monotone_and_a_smooth_curve_to_fourth_order():
    """Through 9 points of a steep tanh the not-a-knot spline swings past its points, the shape-preserving cubic
    is monotone on every interval (its derivative never negative); on exp(x) it converges at the spline's fourth
    order (the error falls 14 to 18 times as the spacing halves), since smooth data leave the slopes alone."""
    from scipy.interpolate import CubicSpline

    from petsc_adhesion.family.coordinate import overshoot, shape_preserving

    x = np.linspace(-1.0, 1.0, 9)
    y = np.tanh(12 * x)
    assert overshoot(x, y, CubicSpline(x, y)) > 0.01
    c = shape_preserving(x, y)
    xs = np.linspace(-1.0, 1.0, 4001)
    assert np.allclose(c(x), y, rtol=0, atol=1e-15) and overshoot(x, y, c) == 0.0
    assert np.min(c(xs, 1)) >= -1e-12
    errs = []
    for n in (11, 21, 41):
        x = np.linspace(0.0, 2.0, n)
        errs.append(np.max(np.abs(shape_preserving(x, np.exp(x))(xs[xs >= 0] * 1.0) - np.exp(xs[xs >= 0]))))
    assert 14 < errs[0] / errs[1] < 18 and 14 < errs[1] / errs[2] < 18, errs


@pytest.mark.parametrize("mu, sigma, within", [(0.178, 1.5, 0.003), (0.0316, 0.2, 0.03)])
def test_a_sparse_rough_node_is_sampled_as_its_refined_curve(mu, sigma, within):
    """A rough curve traced with the library's default steps (no bound on its bend: a table's nodes now have one,
    and 78 and 114 points here) has few points (34 and 35) about the pull-off, and cubic splines swung past them: at (0.178, 1.5) the table's pull-off was -0.075 (an earlier table: docs/family.md) against
    the solver's -0.0139, at (0.0316, 0.2) -0.944 against -0.644.  Sampled shape-preserving through its points
    and located turning points, its pull-off is the one located on the curve traced with steps 8 times
    shorter (within 1e-4 of it), and its F at every tau node that curve's within ``within`` (the spline's were
    0.0056 and 0.32 off; the refined curve's own two samplings differ by 4e-5 and 0.01)."""
    from dataclasses import replace

    from petsc_adhesion.discretization.contact import edge_level
    from petsc_adhesion.discretization.problem import step_scale
    from petsc_adhesion.family.build import F_MAX, _PAST
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.model.pressure import pressure_law
    from petsc_adhesion.tracing.trace import CurveRequest, curve_settings, trace_curve

    tau = TableGrid(mu=(mu,), sigma=(sigma,)).tau

    def sampled(c):
        b = c.branch
        return sample(b.lam, b.F, b.H0, b.contact_radius, edge_level(pressure_law(c.model)), F_MAX, tau, mu,
                      regrid_points(b), event_points(c))
    model = Model(mu=mu, sigma=sigma)
    fine = curve_settings(step_scale(model), observable_max=F_MAX + _PAST)
    fine = replace(fine, ds=fine.ds / 8, ds_max=fine.ds_max / 8)
    coarse_c = trace_curve(model, settings=curve_settings(step_scale(model), observable_max=F_MAX + _PAST),
                           request=CurveRequest(error_bars=False))
    fine_c = trace_curve(model, settings=fine, request=CurveRequest(error_bars=False))
    assert coarse_c.branch.lam.size < 40 and fine_c.branch.lam.size > 100
    coarse, ref = sampled(coarse_c), sampled(fine_c)
    assert coarse.shape is not None                       # the spline was not kept: it swung or missed
    assert abs(coarse.F.min() - _solver_events(fine_c)["pull_off"][0][1]) < 1e-4
    assert np.max(np.abs(coarse.F - ref.F)) < within, np.max(np.abs(coarse.F - ref.F))


def test_a_joined_table_keeps_the_error_only_where_its_stencils_are_unchanged():
    """The shipped smooth table cut in two along mu and joined again keeps the error of all its measured
    midpoints; with its first node's curve changed (by 1e-9 in F), the two midpoints whose four-node stencils
    take that node (between nodes 0-1 and 1-2) are left to be measured, the others kept as they were."""
    from dataclasses import replace

    from petsc_adhesion.family.build import join, keep_errors, select
    from petsc_adhesion.family.table import shipped

    smooth = shipped("smooth")
    n = smooth.mu.size
    whole = keep_errors(join([select(smooth, mu=range(9)), select(smooth, mu=range(9, n))]), smooth)
    assert np.array_equal(whole.err_mu, smooth.err_mu) and whole.errors.keys() == smooth.errors.keys()
    assert all(np.array_equal(whole.errors[f], smooth.errors[f]) for f in smooth.errors)
    F = smooth.F.copy()
    F[0, 0] += 1e-9
    changed = keep_errors(replace(select(smooth), F=F), smooth)
    lost = sorted(set(np.round(smooth.err_mu, 12)) - set(np.round(changed.err_mu, 12)))
    mids = np.sqrt(smooth.mu[1:] * smooth.mu[:-1])
    assert np.allclose(lost, mids[:2], rtol=1e-9), (lost, mids[:3])


def test_a_node_the_default_steps_leave_incomplete_is_traced_with_shorter_ones(monkeypatch):
    """At mu 3.16, sigma 0.2 the default curve is incomplete (a computed point more tensile than the located
    pull-off: the load varies faster than the steps resolve), and `build` wrote nothing; the node is traced again
    with steps a quarter as long (FINER) and tabulated, its pull-off the one the default curve had located, to
    1e-4 (a trace with other steps: the two agree where the coarse one resolved its minimum).  The default curve
    is the one `build` traced first, kept as it passes (the same call as trace_node(mu, sigma) on one rank):
    traced once, not again here.  The nodes' bound on their bend (WALL_BEND_F) makes this node's default curve
    complete (its steps shorter where F bends), so the curves here are traced without it, as the node was
    before: the way back to shorter steps is what is tested."""
    from petsc_adhesion.family import build as building
    from petsc_adhesion.family.build import FINER
    from petsc_adhesion.tracing import trace as tracing

    monkeypatch.setattr(tracing, "wall_bend", lambda model: math.inf)

    mu, sigma = 10 ** 0.5, 0.2
    traced, trace = [], building.trace_node

    def kept(*args, **kw):
        traced.append(trace(*args, **kw))
        return traced[-1]
    monkeypatch.setattr(building, "trace_node", kept)
    node = build(TableGrid(mu=(mu,), sigma=(sigma,), n_tau=150))
    coarse, finer = traced                                # the default steps, then FINER's
    assert not coarse.complete and "faster than the steps resolve" in coarse.assessment.incomplete[0]
    assert finer.complete
    (pl, pF), = [(e.lam.value, e.F.value) for e in node.curve(mu, sigma).events() if e.kind == "pull_off"]
    want = _solver_events(coarse)["pull_off"][0][1]
    assert FINER == 0.25 and abs(pF - want) < 1e-4, (pF, want)


def test_a_node_whose_default_trace_raises_is_traced_with_shorter_ones(monkeypatch):
    """An event the default steps could not locate raised out of the build (mu 1000, sigma 1.5: "event location
    failed near lambda = -52.2"), and the build of 200 nodes wrote nothing.  Now the node is traced again with
    steps FINER as long, as an incomplete one is.  Here the default trace of a cheap node (mu 0.1, sigma 0.05)
    is made to raise so: the node is tabulated from the shorter steps' curve, its pull-off that curve's located
    one to 1e-5 (the sampling passes through the located turning points), and the second trace's steps are
    FINER's, with 1 / FINER times the default's cap on steps."""
    from petsc_adhesion.core.continuation import Settings
    from petsc_adhesion.family import build as building
    from petsc_adhesion.family.build import FINER
    from petsc_adhesion.tracing import trace as tracing

    mu, sigma = 0.1, 0.05
    steps, caps, traced = [], [], []
    trace, trace_curve = building.trace_node, tracing.trace_curve

    def failing(m, s, F_max=building.F_MAX, comm=None, step=1.0):
        steps.append(step)
        if step == 1.0:
            raise RuntimeError("event location failed near lambda = -52.2481")
        traced.append(trace(m, s, F_max, comm, step))
        return traced[-1]

    def spy(model, settings=None, **kw):
        caps.append(settings.max_steps)
        return trace_curve(model, settings=settings, **kw)
    monkeypatch.setattr(building, "trace_node", failing)
    monkeypatch.setattr(tracing, "trace_curve", spy)
    node = build(TableGrid(mu=(mu,), sigma=(sigma,), n_tau=150))
    assert steps == [1.0, FINER] and caps == [math.ceil(Settings().max_steps / FINER)], (steps, caps)
    (pF,) = [e.F.value for e in node.curve(mu, sigma).events() if e.kind == "pull_off"]
    want = _solver_events(traced[0])["pull_off"][0][1]
    assert abs(pF - want) < 1e-5, (pF, want)
