"""The paper's truncated model (-adh_rmax 10 -adh_farfield false) on the default grids, up to MU_TRUNCATED.

It is traced in the physical frame throughout, on grids graded about the contact edge that are
COARSE_MARGIN times finer than NODES_PER_ZONE asks (tracing/edge_grids.py ``margined``), and ends where
its contact reaches r_m (the model's own end; a load that Hertz's contact would carry past r_m is refused
before any work).  The truths: the turning points of the half-infinite model (which differs from the
truncated one by what lies beyond r_m only), Hertz's and JKR's contact radii, and refinement of the
events' own grids.  mu = 10 (about 3000 steps) is the stability benchmark's, not the suite's:
``python -m petsc_adhesion.benchmarks.stability truncated`` (docs/stability.md).
"""
import json
import math

import numpy as np
import pytest

from petsc_adhesion import Model
from petsc_adhesion.benchmarks.stability import refinement
from petsc_adhesion.model.reference.jkr import jkr_load
from petsc_adhesion.tracing.edge_grids import domain_load, margined, sharp
from petsc_adhesion.tracing.trace import CurveRequest, curve_settings, step_scale, trace_curve
from conftest import run_cli

def test_only_the_truncated_sharp_edge_is_margined():
    """The finer grids are the truncated model's where its edge is sharp (and a soft sphere's, as before):
    the half-infinite model's grids below MU_SOFT are as they were, and so every number of its runs."""
    assert margined(Model(mu=10.0, rmax=10.0, farfield=False))
    assert margined(Model(mu=5.0, rmax=10.0, farfield=False))
    assert not margined(Model(mu=10.0, rmax=10.0))
    assert not margined(Model(mu=1.0, rmax=10.0, farfield=False)) and not sharp(Model(mu=1.0))


@pytest.fixture(scope="module")
def mu4():
    """mu = 4 (a sharp edge: the margined physical-frame grids) to F = 0.5, truncated at r_m = 10 and
    half-infinite, without error bars: (truncated curve, half-infinite curve)."""
    curves = []
    for model in (Model(mu=4.0, rmax=10.0, farfield=False), Model(mu=4.0)):
        curves.append(trace_curve(model, settings=curve_settings(step_scale(model), observable_max=0.5),
                                  request=CurveRequest(error_bars=False)))
    return tuple(curves)


#: What the truncation moves mu = 4's turning points and pull-off by at most (as at mu = 10): the attraction
#: beyond r_m = 10, rigid sphere's at these approaches (reference.load_beyond), is a few 1e-3 of the
#: pull-off; measured at most 3.4e-4 in lambda and 2.1e-3 in F (the contact's snap-off, F = -0.43).
TRUNCATION_4 = 5e-3


def test_truncated_sharp_edge_agrees_with_the_half_infinite_model(mu4):
    """mu = 4 > 3.3, the truncated model on its margined physical-frame grids against the half-infinite
    model on the frame of the edge (other grids, other frame, the far field added beyond r_m): the same
    two fold pairs, each within TRUNCATION_4, and the same pull-off; a whole curve to F = 0.5, exit 0.  (The
    mu = 10 run to F = 0.5, 3000 steps, is the stability benchmark's: docs/stability.md.)"""
    truncated, half = mu4
    assert truncated.complete and not truncated.warnings, truncated.warnings
    assert half.complete, half.warnings
    a, b = truncated.events_of("snap_on") + truncated.events_of("snap_off"), \
        half.events_of("snap_on") + half.events_of("snap_off")
    assert [e.kind for e in a] == [e.kind for e in b] and len(a) == 4
    for e, f in zip(sorted(a, key=lambda e: e.lam.value), sorted(b, key=lambda e: e.lam.value)):
        assert abs(e.lam.value - f.lam.value) < TRUNCATION_4, (e.kind, e.lam.value, f.lam.value)
        assert abs(e.F.value - f.F.value) < TRUNCATION_4, (e.kind, e.F.value, f.F.value)
    pulls = [min(c.events_of("F_min"), key=lambda e: e.F.value).F.value for c in (truncated, half)]
    assert abs(pulls[0] - pulls[1]) < TRUNCATION_4, pulls


def test_hertz_radius_bounds_the_contact_from_below(mu4):
    """domain_load's premise, on both traced curves: at every compressive load the model's contact radius
    is at least Hertz's, (3 pi / 2 mu^1.5 F)^(1/3) (adhesion widens a contact at a given load), and at most
    JKR's (jkr_load at that radius is no larger than F)."""
    for curve in mu4:
        F, a = curve.F, curve.contact_radius
        on = (F > 0.05) & np.isfinite(a)
        assert on.sum() >= 5
        hertz = (1.5 * math.pi * 4.0**1.5 * F[on]) ** (1 / 3)
        assert np.all(a[on] > hertz), (a[on] - hertz).min()
        assert np.all(jkr_load(a[on], 4.0) <= F[on] + 1e-9)
        assert np.all(domain_load(4.0, a[on]) > F[on])


def test_contact_reaching_r_m_ends_the_truncated_curve(tmp_path):
    """mu = 4 truncated at r_m = 6: past its pull-off the contact's attraction reaches r_m, where the model
    ends.  The curve stops there (no point beyond it), before Hertz's bound domain_load(4, 6) = 5.7; its
    turning points and pull-off are whole and within TRUNCATION_4 of r_m = 10's (the load beyond r_m = 6 at
    those approaches is below 1e-3); the energy of its cycle, not traced, is absent with the reason; one
    warning names r_m and the remedy; exit 3 (the curve asked for, to F = 2, is not all there)."""
    out = tmp_path / "s.json"
    proc = run_cli("-adh_mu", 4, "-adh_rmax", 6, "-adh_farfield", "false", "-cont_error_estimate", "false",
                   "-summary", out)
    assert proc.returncode == 3, proc.stderr
    s = json.loads(out.read_text())
    assert not s["complete"] and len(s["warnings"]) == 1
    assert "end of the truncated model's domain r_m = 6" in s["warnings"][0] and "-adh_rmax" in s["warnings"][0]
    assert "end of the truncated model's domain" in s["stop_reason"]
    assert [e["kind"] for e in s["folds"]] == ["snap_on", "snap_off", "snap_on", "snap_off"]
    ref = sorted(trace_curve(Model(mu=4.0, rmax=10.0, farfield=False),
                             settings=curve_settings(step_scale(Model(mu=4.0)), observable_max=-0.6),
                             request=CurveRequest(error_bars=False)).events_of("snap_on"),
                 key=lambda e: e.lam.value)
    got = sorted((e for e in s["folds"] if e["kind"] == "snap_on"), key=lambda e: e["lambda"])
    for e, r in zip(got, ref):
        assert abs(e["lambda"] - r.lam.value) < TRUNCATION_4, (e, r.lam.value)
    assert s["pull_off"]["F"] < -0.75 and s["pull_off"]["contact_radius"] < 6.0


def test_load_beyond_the_truncated_domain_refused(tmp_path):
    """-cont_F_max past domain_load (Hertz's contact, the narrowest, already at r_m) is refused before any
    work: one line naming the option, the bound and the remedies, exit 2, nothing written; the library
    says it by ValueError.  At mu = 10, r_m = 10 the bound is F = 6.71 ((2 / (3 pi)) 1000 / 10^1.5)."""
    out = tmp_path / "c.h5"
    proc = run_cli("-adh_mu", 10, "-adh_rmax", 10, "-adh_farfield", "false", "-cont_F_max", 7, "-out", out)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "-cont_F_max: 7 lies beyond the truncated model's domain" in lines[0], lines
    assert "F = 6.711" in lines[0] and "-adh_rmax above 10.14" in lines[0], lines[0]
    assert list(tmp_path.iterdir()) == []
    model = Model(mu=10.0, rmax=10.0, farfield=False)
    with pytest.raises(ValueError, match="beyond the truncated model's domain"):
        trace_curve(model, settings=curve_settings(step_scale(model), observable_max=7.0))


#: mu = 5 truncated on the grids before the margin (5 nodes a zone), its default run's best values and bars
#: (`petsc-adhesion -adh_mu 5 -adh_rmax 10 -adh_farfield false` at commit 9a5e7c4): lambda of the
#: turning points in the curve's order, and the pull-off's F.
OLD_5 = {"folds": ((-4.26280573, 2.3e-08), (-4.52005516, 6.4e-08), (-4.50399263, 1.3e-07), (-8.18905894, 4.6e-05)),
         "pull_off_F": (-0.76239200, 3.6e-06)}


def test_truncated_events_refine_at_second_order_and_their_bars_cover():
    """mu = 5, traced past its pull-off (lambda = -3.5): every event located again on its own grids at
    levels -2 .. 2 (stability.refinement: twice and four times as fine as the default among them).  The
    differences of the default and the finer levels fall by 4 (order 2, the collocation's) for every event,
    the default best value lies within its bar of the Richardson value of levels 1 and 2, and agrees with
    the old grids' values within the two bars."""
    rows = refinement(5.0, -3.5)
    labels = [label for label, key, *_ in rows if key == "lambda"]
    assert labels.count("snap_on") == 2 and labels.count("snap_off") == 2 and "F_min" in labels
    for label, key, got, best, bar in rows:
        d0, d1 = got[0] - got[1], got[1] - got[2]
        assert 3.0 < d0 / d1 < 5.5, (label, key, got)
        richardson = got[2] + (got[2] - got[1]) / 3
        assert abs(best - richardson) <= bar, (label, key, best, bar, richardson)
    folds = [(best, bar) for label, key, got, best, bar in rows if key == "lambda" and label.startswith("snap")]
    for (new, new_bar), (old, old_bar) in zip(folds, OLD_5["folds"]):
        assert abs(new - old) <= new_bar + old_bar, (new, new_bar, old, old_bar)
    pull = min((best, bar) for label, key, got, best, bar in rows if label == "F_min" and key == "F")
    assert abs(pull[0] - OLD_5["pull_off_F"][0]) <= pull[1] + OLD_5["pull_off_F"][1]
