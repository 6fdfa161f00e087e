"""The primary events first and the narrow secondary fold pairs grouped (tracing/turning_points.py, docs/results.md).

The real soft case is the default curve at mu = 20 (about 10 s of CPU): its jump-in ends the far branch,
its jump-off and pull-off lie within 0.3% of the JKR limits (docs/soft.md), and between them the curve
turns four more times within 0.25 of lambda = -8.87, 1.1% of its hysteresis.
"""
import json
import re

import pytest

from conftest import run_cli
from petsc_adhesion.model.reference.jkr import JKR_PULL_OFF, jkr_fixed_grip_pull_off
from petsc_adhesion.tracing.curve import Event
from petsc_adhesion.tracing.measured import Measured
from petsc_adhesion.tracing.turning_points import GROUP_SHARE, turning_points

MU = 20.0


@pytest.fixture(scope="module")
def soft(tmp_path_factory):
    js = tmp_path_factory.mktemp("soft") / "s.json"
    proc = run_cli("-adh_mu", MU, "-summary", js)
    assert proc.returncode == 0, proc.stderr
    return json.loads(js.read_text()), proc.stdout


def test_the_primary_events_of_a_soft_curve_are_the_instruments(soft):
    """The jump-in is the first turning point on approach (the end of the far branch, the snap-on of largest
    lambda here), the jump-off the snap-off of least lambda; both are the very records of ``folds``, and the
    jump-off and pull-off are JKR's to 0.3% at mu = 20 (the distances of docs/soft.md)."""
    s, _ = soft
    p, folds = s["primary"], s["folds"]
    assert p["jump_in"]["index"] == 0 and p["jump_in"]["kind"] == "snap_on"
    assert p["jump_in"]["lambda"] == max(f["lambda"] for f in folds if f["kind"] == "snap_on")
    assert p["jump_off"]["kind"] == "snap_off"
    assert p["jump_off"]["lambda"] == min(f["lambda"] for f in folds)
    for key in ("jump_in", "jump_off"):                  # the same values as the ungrouped list holds
        rec = dict(p[key])
        assert folds[rec.pop("index")] == rec
    assert p["pull_off"] == s["pull_off"]
    lam_s, F_s = jkr_fixed_grip_pull_off(MU)
    assert p["jump_off"]["F"] == pytest.approx(F_s, rel=3e-3)
    assert p["jump_off"]["lambda"] == pytest.approx(lam_s, rel=5e-3)
    assert p["pull_off"]["F"] == pytest.approx(JKR_PULL_OFF, rel=3e-3)


def test_the_secondary_fold_pairs_are_one_group(soft):
    """Four further turning points (two fold pairs) between the primary jumps, one group: its span the
    extremes of its members' values, 0.2506 wide in lambda about -8.865 (1.06% of the hysteresis 23.72),
    their loads within 0.36% of the pull-off force; each member still in ``folds`` with its bar."""
    s, _ = soft
    folds, (g,) = s["folds"], s["fold_groups"]
    assert len(folds) == 6 and g["count"] == 4 and g["members"] == [1, 2, 3, 4]
    members = [folds[i] for i in g["members"]]
    assert sorted(f["kind"] for f in members) == ["snap_off", "snap_off", "snap_on", "snap_on"]
    lams, Fs = [f["lambda"] for f in members], [f["F"] for f in members]
    assert (g["lambda_lo"], g["lambda_hi"], g["F_lo"], g["F_hi"]) == (min(lams), max(lams), min(Fs), max(Fs))
    assert g["width"] == pytest.approx(0.2506, abs=2e-3) and g["lambda"] == pytest.approx(-8.865, abs=2e-3)
    hysteresis = s["primary"]["jump_in"]["lambda"] - s["primary"]["jump_off"]["lambda"]
    assert hysteresis == pytest.approx(23.72, abs=0.01)
    assert g["share"] == pytest.approx(g["width"] / hysteresis, rel=1e-12) and g["share"] < 0.0107
    assert (g["F_hi"] - g["F_lo"]) / abs(s["pull_off"]["F"]) < 0.0037
    assert all(p["jump_in"]["lambda"] > f["lambda"] > p["jump_off"]["lambda"]
               for p in [s["primary"]] for f in members)
    assert all("lambda_err" in f or "error_note" in f for f in folds)
    assert g["without_bar"] == [i for i in g["members"] if "error_note" in folds[i]]


def test_the_report_says_the_primary_events_first_and_the_group_in_one_line(soft):
    s, out = soft
    lines = out.splitlines()
    assert lines[1].startswith("  snap_on (jump-in)") and lines[2].startswith("  pull-off (load control)")
    assert lines[3].startswith("  snap_off (jump-off)")
    assert re.match(r"  4 further turning points \(2 fold pairs\) within 0\.13 of lambda = -8\.86\d* \(width 0\.25, "
                    r"1\.1% of the hysteresis\)", lines[4]), lines[4]
    assert sum(line.lstrip().startswith(("snap_on", "snap_off")) for line in lines) == 2   # none one by one
    jump_in = s["primary"]["jump_in"]
    assert f"lambda = {jump_in['lambda']:.8f}" in lines[1]


def _fold(kind, lam, F, note=None):
    return Event(kind=kind, lam=Measured(lam, 1e-6), F=Measured(F, 1e-6), H0=0.0, note=note)


PULL = Event(kind="F_min", lam=Measured(-5.0), F=Measured(-0.75), H0=0.0)


def test_a_wide_secondary_pair_is_listed_and_a_narrow_one_grouped():
    """The rule on made-up turning points: hysteresis 10 (jump-in at -1, jump-off at -11), so GROUP_SHARE
    of it is 0.5 in lambda and of the pull-off 0.0375 in F."""
    width = 0.9 * GROUP_SHARE * 10
    narrow = [_fold("snap_on", -1, -0.1), _fold("snap_off", -2, -0.11), _fold("snap_on", -2 + width, -0.10, "why"),
              _fold("snap_off", -11, -0.4)]
    tp = turning_points(narrow, "snap_on", "snap_off", PULL)
    assert (tp.jump_in, tp.jump_off, tp.scale, tp.F_scale) == (0, 3, 10, 0.75)
    (g,) = tp.groups
    assert g.members == (1, 2) and g.width == pytest.approx(width) and g.without_bar == (2,)
    assert tp.ungrouped == ()
    wide = [_fold("snap_on", -1, -0.1), _fold("snap_off", -2, -0.11), _fold("snap_on", -2 + 2 * width, -0.10),
            _fold("snap_off", -11, -0.4)]
    tp = turning_points(wide, "snap_on", "snap_off", PULL)
    assert tp.groups == () and tp.ungrouped == (1, 2)
    deep = [_fold("snap_on", -1, -0.1), _fold("snap_off", -2, -0.11), _fold("snap_on", -1.9, -0.2),
            _fold("snap_off", -11, -0.4)]                  # near in lambda, but 0.09 apart in F: listed
    assert turning_points(deep, "snap_on", "snap_off", PULL).groups == ()


def test_no_groups_without_both_primary_jumps_or_a_pull_off():
    """A turning point before the jump-in is not between the jumps (the curve did not start on a far
    branch): listed; without a pull-off there is no force to measure a group against: all listed."""
    pts = [_fold("snap_off", -2, -0.11), _fold("snap_on", -1.99, -0.1), _fold("snap_off", -11, -0.4)]
    tp = turning_points(pts, "snap_on", "snap_off", PULL)
    assert tp.jump_in == 1 and tp.jump_off == 2 and tp.groups == () and tp.ungrouped == (0,)
    pts = [_fold("snap_on", -1, -0.1), _fold("snap_off", -2, -0.11), _fold("snap_on", -1.99, -0.1),
           _fold("snap_off", -11, -0.4)]
    assert turning_points(pts, "snap_on", "snap_off", None).groups == ()
