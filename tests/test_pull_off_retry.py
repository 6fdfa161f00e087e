"""A curve of -fit_pull_off's secant that fails: the iterate moved back and the secant goes on; where every
curve fails, one line naming the w whose pull-off could not be computed.

The failure itself (a fold pair inside one step whose landing was sought beyond its step: mu = 2.1719,
sigma = 0.33) is cured in core/events.py (tests/test_fold_pair_landing.py); one solver failure at one w
says nothing of the root, so a failure is injected here at a chosen curve, and the truth is the w the
measured force was made from: P from the model's own best pull-off at w = 0.05 J/m^2 (mu = 0.3, a curve
of its own with error bars), the fit by the secant alone (use_table False) must give that w back within
its bar although one of its curves failed.
"""
import math
import os
import subprocess
import sys

import conftest
import pytest

from petsc_adhesion.fitting import pull_off as po
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.model.physical import Bodies

R, EPS, W, MU = 20e-9, 0.3e-9, 0.05, 0.3


def _bodies():
    """A rigid flat and a sphere at Tabor parameter MU for w = W (eq. 9 solved for E*)."""
    return Bodies(radius=R, young1=W * math.sqrt(R / (MU**3 * EPS**3)), poisson1=0.0, epsilon=EPS)


def _failing(monkeypatch, fails):
    """model_pull_off that raises the tracer's RuntimeError at the calls ``fails`` says (by call number)."""
    real, calls = po.model_pull_off, []

    def model_pull_off(model, *args, **kw):
        calls.append(model.mu)
        if fails(len(calls)):
            raise RuntimeError("event location failed near lambda = -2.75761")
        return real(model, *args, **kw)

    monkeypatch.setattr(po, "model_pull_off", model_pull_off)
    return calls


def test_a_failed_secant_curve_is_stepped_around(monkeypatch):
    """The secant's second curve fails; the iterate moved half-way back is traced instead and the fit gives
    back the w that made P, within its bar (P exact: the bar is the pull-off's own, about 1e-6 of w)."""
    P = abs(po.model_pull_off(Model(mu=MU), error_bars=True).F.value) * 2 * math.pi * R * W
    calls = _failing(monkeypatch, lambda n: n == 2)
    f = po.fit_pull_off(P, _bodies(), use_table=False)
    assert len(calls) >= 4 and calls[2] != calls[1]            # the failed iterate not asked again
    assert f.trustworthy and f.gamma.covers(W, 1.96), (f.gamma, W)
    assert f.mu == pytest.approx(MU, rel=1e-5)


def test_a_pull_off_no_curve_reaches_is_one_line_naming_w(monkeypatch):
    """Every curve fails: PullOffCurveError, one line that names the w (and mu) whose pull-off could not be
    computed and the solver's reason; the start and its RETRIES moves were tried."""
    calls = _failing(monkeypatch, lambda n: True)
    with pytest.raises(po.PullOffCurveError) as e:
        po.fit_pull_off(1e-9, _bodies(), use_table=False)
    msg = str(e.value)
    assert "\n" not in msg and "could not be computed" in msg and "event location failed" in msg
    w = float(msg.split("w = ")[1].split()[0])
    assert msg.startswith(f"the model's pull-off at w = {w:.6g} J/m^2 (mu = ")
    assert len(calls) == po.RETRIES + 1


def test_the_command_line_says_it_in_one_line_and_exits_3(tmp_path):
    """-fit_pull_off where the solver cannot trace the curve it needs (made to fail in the process): one line
    naming the fit, the w and the solver's reason, exit status 3, nothing written (before: the tracer's bare
    'event location failed near lambda = ...', exit 1)."""
    code = ("from petsc_adhesion.fitting import pull_off as po; from petsc_adhesion.app.cli import main\n"
            "def fail(*a, **k):\n    raise RuntimeError('event location failed near lambda = -2.75761')\n"
            "po.model_pull_off = fail\n"
            "raise SystemExit(main(['x', '-fit_pull_off', '1.37e-9', '-phys_radius', '20e-9', '-phys_young1', "
            f"'{_bodies().young1!r}', '-phys_poisson1', '0', '-phys_epsilon', '0.3e-9', '-summary', 'fit.json']))")
    proc = subprocess.run([sys.executable, "-c", code], env=conftest._env(), capture_output=True, text=True,
                          cwd=tmp_path, timeout=600)
    assert proc.returncode == 3, proc.stderr
    (line,) = proc.stderr.strip().splitlines()
    assert line.startswith("petsc-adhesion: -fit_pull_off: no work of adhesion: the model's pull-off at w = "), line
    assert line.endswith("could not be computed: event location failed near lambda = -2.75761"), line
    assert os.listdir(tmp_path) == []
