"""Physical units: mu from eq. (9) and results in SI with -adh_physical.

The reference numbers are worked by hand: R = 1 um, gamma = 0.05 J/m^2,
epsilon = 0.4 nm give 2 pi R gamma = 3.14159e-7 N, sqrt(epsilon R) = 20 nm,
8 gamma / (3 epsilon) = 3.3333e8 Pa; with E = 1 GPa,
mu = (1e-6 * 0.0025 / (1e18 * 6.4e-29))^(1/3) = 39.0625^(1/3) = 3.393022.
"""
import json

import pytest

from petsc_adhesion.model import scales, tabor
from conftest import run_cli


def test_tabor_parameter_and_scales():
    R, g, E, e = 1e-6, 0.05, 1e9, 4e-10
    assert tabor(R, g, E, e) == pytest.approx(3.393022, rel=1e-6)
    assert tabor(R, g, 1e12, e) == pytest.approx(0.03393022, rel=1e-6)   # E^(-2/3)
    sc = scales(R, g, E, e)
    assert sc["force_N"] == pytest.approx(3.1415927e-7, rel=1e-7)
    assert sc["radius_m"] == pytest.approx(2e-8, rel=1e-12)
    assert sc["approach_m"] == 4e-10
    assert sc["pressure_Pa"] == pytest.approx(3.3333333e8, rel=1e-7)


def test_physical_run_reports_si(tmp_path):
    js = tmp_path / "s.json"
    # a very stiff particle (E = 1e12 Pa, diamond-like): mu = 0.0339, close to the DMT pull-off 2 pi R gamma
    proc = run_cli("-adh_physical", "1e-6,0.05,1e12,4e-10", "-cont_F_max", 0, "-grid_type", "uniform",
                   "-grid_n", 201, "-summary", js)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    assert s["mu"] == pytest.approx(0.03393022, rel=1e-6)
    po = s["pull_off"]
    assert po["F_N"] == pytest.approx(-3.1415927e-7, rel=0.01)                # DMT
    assert po["F_N"] / po["F"] == pytest.approx(3.1415927e-7, rel=1e-7)
    assert po["lambda_m"] / po["lambda"] == pytest.approx(4e-10, rel=1e-12)
    assert "N at an approach of" in proc.stdout


@pytest.mark.parametrize("args", [("-adh_physical", "1e-6,0.05"), ("-adh_physical", "1e-6,0.05,1e9,0"),
                                  ("-adh_physical", "1e-6,0.05,1e9,4e-10", "-adh_mu", 2),
                                  ("-adh_physical", "1e-3,1,1e3,1e-10")])
def test_physical_bad_input(tmp_path, args):
    proc = run_cli(*args, "-out", tmp_path / "x.h5")
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "-adh_" in proc.stderr
    assert not any(tmp_path.iterdir())
