"""The error bars of the events hold: against the closed form of the rigid sphere, and against
deeper refinement; -target_error delivers what it is asked for.

The estimator (error_estimate.py) locates each event again on nested levels of
its own grid and extrapolates; its calibration over 207 quantities is
docs/coverage.md.  Here the truth is independent of it: eq. (28) at mu = 0 (the
half-infinite model, far field included), and at mu = 1 a run refined until its
bars are below 3e-8.
"""
import json

import pytest

from conftest import run_cli
from petsc_adhesion.model.reference.rigid import RIGID_EQUILIBRIUM, rigid_load


def summary(tmp_path, name, *args):
    out = tmp_path / f"{name}.json"
    proc = run_cli(*args, "-summary", out)
    assert proc.returncode == 0, proc.stderr
    return json.loads(out.read_text())


def test_bars_cover_the_rigid_closed_form(tmp_path):
    """mu = 0: pull-off F = -1 at lambda = 0, equilibrium 1 - 2^(-1/3), F(lambda) of eq. (28).

    Measured: every bar 3.1 times the error it covers; the best values 40 to 70 times
    closer than the grid's, 6 times at lambda = 0.1 where the grid's error is small."""
    s = summary(tmp_path, "rigid", "-adh_mu", 0, "-cont_at_lambda", "-0.5,0.1")
    po, (eq,) = s["pull_off"], s["equilibria"]
    checks = [(po["F"], po["F_err"], po["F_grid"], -1.0), (po["lambda"], po["lambda_err"], po["lambda_grid"], 0.0),
              (eq["lambda"], eq["lambda_err"], eq["lambda_grid"], RIGID_EQUILIBRIUM)]
    checks += [(e["F"], e["F_err"], e["F_grid"], rigid_load(e["lambda"])) for e in s["at_lambda"]]
    assert len(checks) == 5
    for best, bar, grid, exact in checks:
        assert abs(best - exact) <= bar                           # covered
        assert bar <= 5 * abs(best - exact)                       # not vacuous
        assert abs(best - exact) <= 0.2 * abs(grid - exact)       # and better than the grid's value


@pytest.fixture(scope="module")
def refined(tmp_path_factory):
    """mu = 1, the events up to equilibrium, refined to -target_error 1e-7: bars 8e-9 to 2.8e-8, its values
    within 7.7e-9 of a run refined to 1e-8 (whose bars are 2e-9 to 3.7e-9), which took 18.5 CPU s where this
    takes 5.9 (measured, load 10).  The checks below add the reference's bar to the one they test."""
    return summary(tmp_path_factory.mktemp("refined"), "ref", "-adh_mu", 1, "-cont_F_max", 0, "-target_error", 1e-7)


def _events(s):
    out = [("pull_off", s["pull_off"])] + [(f["kind"], f) for f in s["folds"]] \
        + [("equilibrium", e) for e in s["equilibria"]]
    out += [(f["kind"] + " landing", f["landing"]) for f in s["folds"]]
    return out


@pytest.mark.parametrize("target", [None, 1e-4, 1e-6], ids=["default", "1e-4", "1e-6"])
def test_bars_cover_a_refined_truth(tmp_path, refined, target):
    """The default bars and -target_error 1e-4 and 1e-6 cover the refined values; the targets are met."""
    args = ("-target_error", target) if target else ()
    s = summary(tmp_path, "run", "-adh_mu", 1, "-cont_F_max", 0, *args)
    assert s["complete"]
    for (kind, e), (_, t) in zip(_events(s), _events(refined)):
        assert t.get("F_err", 0) <= 3e-8 and t.get("lambda_err", 0) <= 3e-8
        for q in ("lambda", "F"):
            if f"{q}_err" not in e:             # a landing's lambda is its fold's; an equilibrium's F is 0
                continue
            assert abs(e[q] - t[q]) <= e[f"{q}_err"] + t[f"{q}_err"], (kind, q, e[q], t[q], e[f"{q}_err"])
            if target:
                assert e[f"{q}_err"] <= target, (kind, q)


def test_a_flat_pull_off_gets_its_bar(tmp_path):
    """mu = 3, sigma = 0.2: F is so flat about the pull-off (2e-6 over 0.01 in lambda) that on the finer
    levels its lambda lies 0.024 back, behind the first point of the step that found it.  Its levels'
    traces start a step further back: it has a bar (before: none, 'not found again'), and the bars cover
    a run refined to 1e-5 (measured: lambda 2.7e-3 off with a bar of 6.8e-3, F 1.1e-6 with 2.8e-6, each 0.40
    of the two bars summed; the reference's bars 9.7e-6 and 1.2e-8, its values within 3.9e-6 and 2.2e-9 of a run
    refined to 1e-6, which took 50 CPU s where this takes 21; the grid's values 2500 of its bars off)."""
    args = ("-adh_mu", 3, "-adh_sigma", 0.2, "-cont_F_max", 0, "-adh_model_spread", "false")
    po, ref = (summary(tmp_path, name, *args, *extra)["pull_off"]
               for name, extra in (("run", ()), ("refined", ("-target_error", 1e-5))))
    assert "error_note" not in po and ref["lambda_err"] <= 1e-5 and ref["F_err"] <= 1e-5
    for q in ("lambda", "F"):
        assert abs(po[q] - ref[q]) <= po[f"{q}_err"] + ref[f"{q}_err"], (q, po[q], ref[q], po[f"{q}_err"])
        assert abs(po[f"{q}_grid"] - ref[q]) > ref[f"{q}_err"]         # a grid value that needs its bar
