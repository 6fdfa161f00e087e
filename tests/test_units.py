"""Physical units: the -phys_ options, mu from eq. (9), results in nN, nm and MPa.

The reference numbers are worked by hand: R = 1 um, gamma = 0.05 J/m^2,
epsilon = 0.4 nm give 2 pi R gamma = 314.159 nN, sqrt(epsilon R) = 20 nm,
8 gamma / (3 epsilon) = 333.33 MPa; with E = 1 GPa,
mu = (1e-6 * 0.0025 / (1e18 * 6.4e-29))^(1/3) = 39.0625^(1/3) = 3.393022.
Two spheres of 1 and 3 um make R = 0.75 um; E1 = 1 GPa with nu1 = 0.5 and
E2 = 2 GPa with nu2 = 0 make 1/E = 0.75e-9 + 0.5e-9, E = 0.8 GPa (eq. 2);
A = 1e-19 J with D0 = 0.165 nm makes gamma = A / (12 pi D0^2) = 0.097432 J/m^2.
"""
import json
import math

import h5py
import pytest

from conftest import run_cli
from petsc_adhesion.model.parameters import scales, tabor
from petsc_adhesion.model.physical import Bodies

#: R = 1 um, E = 1 GPa (rigid flat), gamma = 0.05 J/m^2, epsilon = 0.4 nm: mu = 3.393
SOFT = ("-phys_radius", 1e-6, "-phys_young1", 1e9, "-phys_poisson1", 0, "-phys_gamma", 0.05, "-phys_epsilon", 4e-10)


def test_tabor_parameter_and_scales():
    R, g, E, e = 1e-6, 0.05, 1e9, 4e-10
    assert tabor(R, g, E, e) == pytest.approx(3.393022, rel=1e-6)
    assert tabor(R, g, 1e12, e) == pytest.approx(0.03393022, rel=1e-6)   # E^(-2/3)
    sc = scales(R, g, E, e)
    assert sc["force_N"] == pytest.approx(3.1415927e-7, rel=1e-7)
    assert sc["radius_m"] == pytest.approx(2e-8, rel=1e-12)
    assert sc["approach_m"] == 4e-10
    assert sc["pressure_Pa"] == pytest.approx(3.3333333e8, rel=1e-7)


def test_combined_bodies():
    b = Bodies(radius=1e-6, radius2=3e-6, young1=1e9, poisson1=0.5, young2=2e9, poisson2=0.0, hamaker=1e-19,
               epsilon=4e-10, rms=2e-10)
    assert b.R == pytest.approx(0.75e-6, rel=1e-14)
    assert b.E == pytest.approx(0.8e9, rel=1e-14)
    assert b.work_of_adhesion == pytest.approx(0.097432, rel=1e-5)
    assert b.sigma == pytest.approx(0.5, rel=1e-14)
    d = b.describe()
    assert d["mu"] == pytest.approx(tabor(0.75e-6, b.work_of_adhesion, 0.8e9, 4e-10), rel=1e-14)
    assert d["force_nN"] == pytest.approx(2 * math.pi * 0.75e-6 * b.work_of_adhesion * 1e9, rel=1e-14)
    assert d["inputs"]["hamaker_cutoff"] == 0.165e-9


def test_stiff_particle_pulls_off_at_dmt(tmp_path):
    """E = 1e12 Pa: mu = 0.0339, the pull-off close to DMT's 2 pi R gamma = 314.16 nN."""
    js = tmp_path / "s.json"
    proc = run_cli(*SOFT[:2], "-phys_young1", 1e12, *SOFT[4:], "-cont_F_max", 0, "-grid_type", "uniform",
                   "-grid_n", 201, "-summary", js)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    assert s["mu"] == pytest.approx(0.03393022, rel=1e-6)
    po, phys = s["pull_off"], s["physical"]["pull_off"]
    assert phys["F_nN"] == pytest.approx(-314.159, rel=0.01)                # DMT
    assert phys["F_nN"] / po["F"] == pytest.approx(314.15927, rel=1e-7)
    assert phys["lambda_nm"] / po["lambda"] == pytest.approx(0.4, rel=1e-12)
    assert phys["F_err_nN"] / po["F_err"] == pytest.approx(314.15927, rel=1e-7)
    assert "in physical units: R = 1 um" in proc.stdout and "nN" in proc.stdout


def test_soft_particle_contact_radius_is_jkr(tmp_path):
    """mu = 3.39: at zero load the contact radius approaches JKR's a0 = (6 pi gamma R^2 / K)^(1/3),
    K = 4 E / 3 = 1.333 GPa: 89.1 nm; the files carry the inputs and their units."""
    js, h5 = tmp_path / "s.json", tmp_path / "s.h5"
    proc = run_cli(*SOFT, "-cont_F_max", 0, "-summary", js, "-out", h5)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    a0 = (6 * math.pi * 0.05 * 1e-12 / (4e9 / 3)) ** (1 / 3) * 1e9
    eq = s["physical"]["equilibria"][0]
    assert eq["contact_radius_nm"] == pytest.approx(a0, rel=0.01)
    assert eq["contact_radius_nm"] == pytest.approx(s["equilibria"][0]["contact_radius"] * 20.0, rel=1e-12)
    assert -1.0 < s["pull_off"]["F"] < -0.75                             # between DMT and JKR
    with h5py.File(h5, "r") as f:
        g = f["physical"]
        assert g.attrs["mu"] == pytest.approx(3.393022, rel=1e-6) and g["inputs"].attrs["young1"] == 1e9
        assert "E_Pa: Pa" in g.attrs["units"] and "young*: Pa" in g["inputs"].attrs["units"]
        assert f["summary/physical/pull_off"].attrs["F_nN"] == s["physical"]["pull_off"]["F_nN"]


def test_solve_and_rms(tmp_path):
    js = tmp_path / "s.json"
    proc = run_cli(*SOFT, "-phys_rms", 1e-10, "-adh_lambda", -8, "-grid_type", "uniform", "-grid_n", 101,
                   "-summary", js)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(js.read_text())
    assert s["sigma"] == pytest.approx(0.25, rel=1e-14)
    assert s["physical"]["lambda_nm"] == pytest.approx(-3.2, rel=1e-14)
    assert s["physical"]["F_nN"] == pytest.approx(s["F"] * 314.15927, rel=1e-7)
    assert "nN" in proc.stdout


@pytest.mark.parametrize("args, line", [
    (SOFT[2:], "-phys_radius: required with the other -phys_ options"),
    (SOFT[:6] + SOFT[8:], "-phys_gamma: required, or -phys_hamaker"),
    (SOFT + ("-phys_hamaker", 1e-19), "-phys_gamma: not with -phys_hamaker"),
    (SOFT + ("-phys_young2", 1e9), "-phys_poisson2: needed with -phys_young2"),
    (SOFT + ("-phys_hamaker_cutoff", 2e-10), "-phys_hamaker_cutoff: only with -phys_hamaker"),
    (SOFT + ("-adh_mu", 2), "-adh_mu: not with the -phys_ options"),
    (SOFT + ("-phys_rms", 1e-10, "-adh_sigma", 0.2), "-adh_sigma: not with the -phys_ options"),
    (SOFT + ("-phys_poisson1", 0.7), "-phys_poisson1: expected"),
    (("-phys_radius", 1e-3, "-phys_young1", 1e3, "-phys_poisson1", 0, "-phys_gamma", 1, "-phys_epsilon", 1e-10),
     "-phys_young1: with the other -phys_ options gives mu"),          # the modulus 1e-6 of a polymer's
    (SOFT + ("-phys_rms", 1e-8), "-phys_rms: gives sigma = rms / epsilon = 25"),
    # a misspelling is named as such, before the option it leaves missing
    (("-phys_radis", 1e-6) + SOFT[2:], "-phys_radis: unknown option (did you mean -phys_radius?)"),
    (SOFT[:6] + ("-phys_gama", 0.05) + SOFT[8:], "-phys_gama: unknown option (did you mean -phys_gamma?)"),
    (SOFT + ("-phys_young", 1e9, "-phys_poisson2", 0.3), "-phys_young: unknown option (did you mean -phys_young2?)"),
    (SOFT + ("-phys_sprng", 0.1), "-phys_sprng: unknown option (did you mean -phys_spring?)"),
    (("-adh_roughness", "measured", "-adh_roughnes_file", "h.txt"),
     "-adh_roughnes_file: unknown option (did you mean -adh_roughness_file?)")])
def test_physical_bad_input(tmp_path, args, line):
    """One line naming the option and what is wrong, exit 2, nothing written."""
    proc = run_cli(*args, "-out", tmp_path / "x.h5")
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith(f"petsc-adhesion: error: {line}"), proc.stderr
    assert not any(tmp_path.iterdir())
