"""The paper's truncated model (-adh_rmax 10 -adh_farfield false) on the default grids, up to MU_TRUNCATED.

It is traced in the physical frame throughout, on grids graded about the contact edge that are
COARSE_MARGIN times finer than NODES_PER_ZONE asks (tracing/edge_grids.py ``margined``).  The truths:
the JKR limit of the pull-off, the turning points of the half-infinite model (which differs from the
truncated one by what lies beyond r_m = 10 only), and refinement of the events' own grids.
"""
import json

import pytest

from petsc_adhesion import Model
from petsc_adhesion.benchmarks.stability import refinement
from petsc_adhesion.model.reference.jkr import JKR_PULL_OFF
from petsc_adhesion.tracing.edge_grids import MU_TRUNCATED, margined, sharp
from conftest import run_cli

#: The half-infinite model's turning points at mu = 10 (docs/stability.md's mu = 10 row, its summary):
#: snap-on, snap-off, snap-on before the contact, and the contact's snap-off, each with a bar below 2e-6.
HALF_INFINITE_10 = (-6.08463995, -6.42384017, -6.31243824, -16.20065750)
#: What the truncation moves them by at most: the load beyond r_m = 10 is about 5e-4 of the pull-off at
#: these approaches (reference.load_beyond), the deflection it causes inside 8.5e-5 (far_deflection); the
#: turning points before the contact, where the load is about 0.05, move by 1.7e-3 (measured).
TRUNCATION = 5e-3


def test_only_the_truncated_sharp_edge_is_margined():
    """The finer grids are the truncated model's where its edge is sharp (and a soft sphere's, as before):
    the half-infinite model's grids below MU_SOFT are as they were, and so every number of its runs."""
    assert margined(Model(mu=10.0, rmax=10.0, farfield=False))
    assert margined(Model(mu=5.0, rmax=10.0, farfield=False))
    assert not margined(Model(mu=10.0, rmax=10.0))
    assert not margined(Model(mu=1.0, rmax=10.0, farfield=False)) and not sharp(Model(mu=1.0))


def test_truncated_model_at_mu_10_completes(tmp_path):
    """mu = MU_TRUNCATED = 10: the curve is traced past its equilibrium to F = 0.5 with exit 0, two fold pairs
    as the half-infinite model has at mu = 10, within TRUNCATION of its turning points, and a pull-off within
    1% of JKR's -3/4.  (On the grids of 5 nodes a zone it ended with exit 3 after 13 turning points, nine
    of them spurious pairs within 3e-3 in lambda of the contact's snap-off.)  To F = 2 its contact reaches
    r_m = 10 itself (its edge at r = 9.75, the gap at r_m below 13 epsilon), which the run says with exit 3: the
    model's domain, not the grid's (docs/stability.md).  About 3000 steps: the slowest test here."""
    out = tmp_path / "s.json"
    proc = run_cli("-adh_mu", MU_TRUNCATED, "-adh_rmax", 10, "-adh_farfield", "false", "-cont_F_max", 0.5,
                   "-cont_error_estimate", "false", "-summary", out, timeout=3600)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(out.read_text())
    assert s["complete"] and not s["warnings"]
    folds = s["folds"]
    assert [e["kind"] for e in folds] == ["snap_on", "snap_off", "snap_on", "snap_off"]
    for e, half in zip(folds, HALF_INFINITE_10):
        assert abs(e["lambda"] - half) < TRUNCATION, (e, half)
    assert s["pull_off"]["F"] == pytest.approx(JKR_PULL_OFF, rel=0.01)
    assert len(s["equilibria"]) == 1


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
