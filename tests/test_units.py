"""Physical units: mu from eq. (9) and results in SI with -adh_physical."""
import json
import math

import pytest

from petsc_adhesion.model import scales, tabor
from conftest import run_cli


def test_tabor_parameter():
    # eq. (9) by hand: R = 1 um, gamma = 0.05 J/m^2, E = 1 GPa, epsilon = 0.4 nm
    R, g, E, e = 1e-6, 0.05, 1e9, 4e-10
    assert tabor(R, g, E, e) == pytest.approx((R * g * g / (E * E * e**3)) ** (1 / 3), rel=1e-15)
    assert tabor(R, g, E, e) == pytest.approx(3.3930, abs=1e-4)
    sc = scales(R, g, E, e)
    assert sc["force_N"] == pytest.approx(2 * math.pi * 1e-6 * 0.05)
    assert sc["radius_m"] == pytest.approx(2e-8)


def test_physical_run_reports_si(tmp_path):
    js = tmp_path / "s.json"
    # a very stiff particle (E = 1e12 Pa, diamond-like): mu = 0.0339, close to the DMT pull-off 2 pi R gamma
    proc = run_cli("-adh_physical", "1e-6,0.05,1e12,4e-10", "-cont_F_max", 0, "-grid_type", "uniform",
                   "-grid_n", 201, "-summary", js)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    assert s["mu"] == pytest.approx(tabor(1e-6, 0.05, 1e12, 4e-10))
    po = s["pull_off"]
    assert po["F_N"] == pytest.approx(po["F"] * 2 * math.pi * 1e-6 * 0.05, rel=1e-12)
    assert po["F_N"] == pytest.approx(-2 * math.pi * 1e-6 * 0.05, rel=0.01)      # DMT
    assert "N at an approach of" in proc.stdout


@pytest.mark.parametrize("args", [("-adh_physical", "1e-6,0.05"), ("-adh_physical", "1e-6,0.05,1e9,0"),
                                  ("-adh_physical", "1e-6,0.05,1e9,4e-10", "-adh_mu", 2),
                                  ("-adh_physical", "1e-3,1,1e3,1e-10")])
def test_physical_bad_input(tmp_path, args):
    proc = run_cli(*args, "-out", tmp_path / "x.h5")
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "-adh_" in proc.stderr
    assert not any(tmp_path.iterdir())
