"""Soft spheres: the frame of the edge to mu = 1000, the domain options honoured there, the JKR end."""
import pytest

from petsc_adhesion import Model
from petsc_adhesion.discretization.edge_frame import EdgeFrameProblem
from petsc_adhesion.model.reference.jkr import JKR_PULL_OFF, jkr_fixed_grip_pull_off, jkr_zero_load
from petsc_adhesion.discretization.problem import far_approach
from petsc_adhesion.discretization import preconditioning
from petsc_adhesion.tracing import results
from petsc_adhesion.tracing.edge_grids import GROW, MU_TRUNCATED
from petsc_adhesion.tracing.trace import CurveRequest, curve_settings, step_scale, trace_curve
from petsc_adhesion.tracing.tracer import Tracer
from conftest import run_cli


def _trace_segments(model, **settings):
    tr = Tracer(model, curve_settings(step_scale(model), **settings), results.curve_events(()), 1e-10, None,
                preconditioning.Dense(), rmax=model.rmax)
    return tr.run(far_approach(model))


def test_truncated_model_keeps_its_domain():
    """-adh_farfield false on grids that follow the edge: the model truncated at r_m = 10 is traced in the
    physical frame throughout, every segment's nodes ending at r_m itself (the frame of the edge, whose
    grid is in r / a, would end anywhere in [r_m, GROW^4 r_m]); with the far field the frame takes over."""
    model = Model(mu=4.0, rmax=10.0, farfield=False)
    segs = _trace_segments(model, observable_max=0.0)
    try:
        assert segs and all(not isinstance(s.problem, EdgeFrameProblem) for s in segs)
        assert all(float(s.problem.r[-1]) == pytest.approx(10.0, abs=1e-12) for s in segs)
    finally:
        for s in segs:
            s.destroy()
    half = _trace_segments(Model(mu=4.0, rmax=10.0), observable_max=0.0)
    try:
        assert any(isinstance(s.problem, EdgeFrameProblem) for s in half)
    finally:
        for s in half:
            s.destroy()


def test_truncated_model_refused_where_the_physical_frame_cannot_go(tmp_path):
    """Above MU_TRUNCATED the truncated model is refused in one line naming the option, nothing written;
    the library says the same by ValueError before any work."""
    out = tmp_path / "c.h5"
    proc = run_cli("-adh_mu", 2 * MU_TRUNCATED, "-adh_farfield", "false", "-out", out)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "-adh_farfield" in lines[0] and f"mu = {MU_TRUNCATED:g}" in lines[0]
    assert not out.exists() and list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="truncated"):
        trace_curve(Model(mu=2 * MU_TRUNCATED, farfield=False))


def test_contact_reaching_the_end_of_the_frame_of_the_edge_is_said():
    """results.assess where the contact reaches r_m in the frame of the edge (which has no fixed r): at
    mu = 5 with r_m = 2 the contact grows to a = 5.4 at zero load and beyond, where the frame's grid in rho
    = r / a ends at rho_m = max(r_m GROW^2 / a_grid, GROW): the end moves with the contact, GROW times
    the contact radius at the last point; the warning names that end, not the option's value."""
    curve = trace_curve(Model(mu=5.0, rmax=2.0), request=CurveRequest(kinds=()))
    said = [w for w in curve.warnings if "reaches the end of the domain" in w]
    assert said, curve.warnings
    rm = float(said[0].split("r_m = ")[1].split()[0])
    assert rm == pytest.approx(GROW * curve.contact_radius[-1], rel=1e-4) and rm > 2.0


def _jkr_distances(mu: float) -> dict:
    """The distances of a default curve's values (no error bars) from the JKR limits at ``mu``."""
    curve = trace_curve(Model(mu=mu), request=CurveRequest(error_bars=False))
    assert curve.complete, curve.warnings
    pull = min((e for e in curve.events_of("F_min")), key=lambda e: e.F.value)
    snap = min(curve.events_of("snap_off"), key=lambda e: e.lam.value)       # the last: the contact lets go
    zero = curve.events_of("equilibrium")[-1]
    A0, lam0 = jkr_zero_load(mu)
    lam_s, F_s = jkr_fixed_grip_pull_off(mu)
    return {"pull_off": abs(pull.F.value / JKR_PULL_OFF - 1), "snap_off_F": abs(snap.F.value / F_s - 1),
            "snap_off_lambda": abs(snap.lam.value / lam_s - 1), "zero_load_lambda": abs(zero.lam.value / lam0 - 1),
            "zero_load_radius": abs(zero.contact_radius.value / A0 - 1)}


def test_the_jkr_limit_is_approached():
    """Towards the JKR end (mu = 20, then 100) every value approaches its closed form (Johnson, Kendall &
    Roberts 1971; model/reference/jkr.py): the load-control pull-off -3/4, the fixed-grip snap-off at
    F = -5/12 and lambda = -3 (pi/8)^(2/3) mu, the zero-load approach and contact radius (9 pi/2)^(1/3)
    mu^(1/2).  Measured: relative distances 0.9e-3 to 4e-3 at mu = 20, 0.5e-4 to 3e-4 at mu = 100
    (the cohesive zone's share of the contact falls like mu^-2): each falls by a factor 5 at least, and is
    below 5e-4 at mu = 100."""
    d20, d100 = _jkr_distances(20.0), _jkr_distances(100.0)
    for key in d20:
        assert d100[key] < d20[key] / 5 and d100[key] < 5e-4, (key, d20[key], d100[key])


def test_measured_zone_of_a_gaussian_attraction():
    """resolution.measured_zone on P(r) = -exp(-((r - r0) / w)^2): its inner half-width is w sqrt(ln 2)
    (closed form), reported over INNER_SHARE; no attraction gives nan; an attraction reaching the centre
    gives the peak's radius over INNER_SHARE."""
    import math
    import numpy as np
    from petsc_adhesion.discretization.resolution import INNER_SHARE, measured_zone
    r = np.linspace(0.0, 10.0, 200001)
    for r0, w in ((5.0, 0.3), (2.0, 0.01)):
        P = 0.2 * np.exp(-((r - r0 - 4 * w) / w) ** 2) - np.exp(-((r - r0) / w) ** 2)
        k = int(np.argmin(P))
        left = r[:k][P[:k] > 0.5 * P[k]][-1]
        assert measured_zone(r, P) * INNER_SHARE == pytest.approx(w * math.sqrt(math.log(2.0)), rel=2e-3)
        assert measured_zone(r, P) * INNER_SHARE == pytest.approx(r[k] - left, abs=2 * (r[1] - r[0]))
    assert math.isnan(measured_zone(r, np.exp(-r)))
    assert measured_zone(r, -np.exp(-r)) == 0.0


def test_rough_soft_sphere_bars_cover_finer_grids(tmp_path):
    """mu = 100, sigma = 1 (the roughness holds the surfaces at its wall; the edge is Hertz-like, its
    attraction 0.09 to 0.3 wide where the JKR-edge formula says 0.0018): on grids sized by the zone the
    state shows, the default run's events and bars against the same curve refined to -target_error 1e-5:
    every event within its bar; and the grids stay small (below 1000 nodes, where grids sized by the
    formula took 3745).  The reference's own bars are below a quarter of the default's (measured: 0.01 to
    0.19 of them), and it is within 2.3e-6 in lambda and 1.3e-8 in F (at most 4% of a default bar) of the
    curve refined to -target_error 3e-6, which took 64 CPU s where 1e-5 takes 20 (and the default 8.5)."""
    import json
    runs = {}
    for name, extra in (("default", ()), ("fine", ("-target_error", "1e-5"))):
        js = tmp_path / f"{name}.json"
        proc = run_cli("-adh_mu", 100, "-adh_sigma", 1, "-adh_model_spread", "false", *extra, "-summary", js)
        assert proc.returncode == 0, proc.stderr
        runs[name] = json.loads(js.read_text())
    d, f = runs["default"], runs["fine"]
    assert d["complete"] and not d["warnings"] and d["n_nodes"] < 1000
    events = lambda s: [s["pull_off"], *s["folds"], *s["equilibria"]]
    assert [e["kind"] for e in events(d)] == [e["kind"] for e in events(f)] == \
        ["F_min", "snap_on", "snap_off", "equilibrium"]
    for a, b in zip(events(d), events(f)):
        assert abs(a["lambda"] - b["lambda"]) <= a["lambda_err"] and b["lambda_err"] < a["lambda_err"] / 4, (a, b)
        if a["kind"] != "equilibrium":
            assert abs(a["F"] - b["F"]) <= a["F_err"] and b["F_err"] < a["F_err"] / 4, (a, b)
