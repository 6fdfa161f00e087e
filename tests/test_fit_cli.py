"""The fits on the command line: -fit_pull_off and -fit_curve honoured (their files and report), and every input
they cannot use refused in one line naming the option, exit status 2, nothing written."""
import json
import math
import os

import numpy as np
import pytest

from conftest import ROOT, run_cli
from test_hostile import listing, one_line

BODIES = ("-phys_radius", "20e-9", "-phys_young1", "150e9", "-phys_poisson1", "0.27", "-phys_epsilon", "0.3e-9")
TIP = ("-phys_radius", "20e-9", "-phys_epsilon", "0.3e-9")
IBW = os.path.join(ROOT, "tests", "data", "fmt-igor-fd_SiN_FD_plot.ibw")


def _csv(tmp_path, name="c.csv", adhesion=True, contact=True):
    """A curve in nm and nN with a header: baseline, a linear contact, a pull-off (or none)."""
    rng = np.random.default_rng(0)
    z = np.linspace(0, 100, 200)
    Fa = np.where(z > 80, (z - 80) * 0.5, 0.0) * contact
    Fr = np.maximum(np.where(z > 70, (z - 80) * 0.5, 0.0) * contact, -4.0 * adhesion * (z > 70))
    F = np.r_[Fa, Fr[::-1]] + 0.01 * rng.standard_normal(400)
    p = tmp_path / name
    p.write_text("z (nm), F (nN)\n" + "\n".join(f"{a:.6g}, {b:.6g}" for a, b in zip(np.r_[z, z[::-1]], F)))
    return str(p)


def test_pull_off_on_the_command_line(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    p = run_cli("-fit_pull_off", "12.46e-9", "-fit_pull_off_err", "0.2e-9", *BODIES, "-summary", out / "f.json",
                "-out", out / "f.h5")
    assert p.returncode == 0, p.stderr
    s = json.load(open(out / "f.json"))
    fit = s["fit"]
    assert s["kind"] == "fit" and fit["kind"] == "pull_off" and s["model"]["mu"] == pytest.approx(fit["mu"])
    # the bar is the measurement's, carried by dP/dw: 0.2 / 12.46 over 1 + (2/3) dln|F|/dlnmu
    assert fit["gamma_err"] / fit["gamma"] == pytest.approx(0.2 / 12.46 / (1 + 2 / 3 * fit["dlnF_dlnmu"]), rel=0.05)
    cf = fit["closed_forms"]
    assert cf["dmt"]["gamma"] == pytest.approx(12.46e-9 / (2 * math.pi * 20e-9))
    assert cf["dmt"]["gamma"] < fit["gamma"] < cf["jkr"]["gamma"]
    assert "gamma = " in p.stdout and "JKR" in p.stdout and "Maugis-Dugdale" in p.stdout
    assert fit["trustworthy"] and fit["complete"] and fit["warnings"] == [] and fit["missing"] == {}
    assert "WARNING" not in p.stdout and "warning" not in p.stderr
    h5py = pytest.importorskip("h5py")
    with h5py.File(out / "f.h5") as f:
        assert f.attrs["kind"] == "fit" and f["fit"].attrs["gamma"] == fit["gamma"]
        assert "description" in f["fit/closed_forms"].attrs


def test_a_fitted_work_of_adhesion_no_surface_has_is_said(tmp_path):
    """500 nN from a 20 nm tip on silicon nitride: the model reaches it (mu about 1), at a w of about 5 J/m^2,
    above any but clean metals' in vacuum (plausible.py: at most 1 J/m^2): the fit is written, and a warning line
    says the value is implausible (a unit slip?); a plausible fit (above) has none."""
    p = run_cli("-fit_pull_off", "5e-7", *BODIES, "-summary", tmp_path / "f.json")
    assert p.returncode == 0, p.stderr
    gamma = json.load(open(tmp_path / "f.json"))["fit"]["gamma"]
    assert gamma > 1.0
    assert f"warning: the fitted work of adhesion {gamma:.4g} J/m^2 is above 1 J/m^2" in p.stderr, p.stderr


def test_a_pull_off_whose_w_is_undetermined_exits_3(tmp_path):
    """A pull-off as uncertain as itself: w's 95% interval is wider than w; the files are written with w null and
    its reason, the report says WARNING, exit status 3."""
    out = tmp_path / "f.json"
    p = run_cli("-fit_pull_off", "12.46e-9", "-fit_pull_off_err", "12.46e-9", *BODIES, "-summary", out)
    assert p.returncode == 3, p.stderr
    fit = json.load(open(out))["fit"]
    assert fit["gamma"] is None and fit["gamma_err"] is None and not fit["trustworthy"]
    assert fit["missing"]["gamma"].startswith("its 95% interval")
    assert f"WARNING: gamma undetermined: {fit['missing']['gamma']}" in p.stdout
    assert "gamma = undetermined" in p.stdout


REFUSALS = {
    "both": (("-fit_pull_off", "1e-8", "-fit_curve", "c.csv", *BODIES), "-fit_pull_off: not with -fit_curve"),
    "no_epsilon": (("-fit_pull_off", "1e-8", "-phys_radius", "2e-8"), "-phys_epsilon: required with -fit_pull_off"),
    "no_moduli": (("-fit_pull_off", "1e-8", *TIP), "-phys_young1: required with -fit_pull_off"),
    "gamma_given": (("-fit_pull_off", "1e-8", *BODIES, "-phys_gamma", "0.1"),
                    "-phys_gamma: not with -fit_pull_off: the work of adhesion is what the fit finds"),
    "mu_given": (("-fit_curve", "c.csv", *TIP, "-adh_mu", "1"), "-adh_mu: not with -fit_curve"),
    "cont_given": (("-fit_pull_off", "1e-8", *BODIES, "-cont_ds", "0.1"), "-cont_ds: not with -fit_pull_off"),
    "too_large": (("-fit_pull_off", "0.1", *BODIES), "-fit_pull_off: P = 0.1 N needs a work of adhesion"),
    "negative": (("-fit_pull_off", "-1e-9", *BODIES), "-fit_pull_off: expected a finite real in (0, 1]"),
    "err_alone": (("-adh_mu", "1", "-fit_pull_off_err", "1e-9"), "-fit_pull_off_err: only with -fit_pull_off"),
    "err_with_curve": (("-fit_curve", "c.csv", *TIP, "-phys_spring", "1", "-fit_pull_off_err", "1e-9"),
                       "-fit_pull_off_err: only with -fit_pull_off"),
    "plot_pull_off": (("-fit_pull_off", "1e-8", *BODIES, "-plot", "x.png"), "-plot: applies to -fit_curve"),
    "no_spring": (("-fit_curve", "c.csv", *TIP), "-phys_spring: required with -fit_curve: the file 'c.csv' states"),
    "no_radius": (("-fit_curve", "c.csv", "-phys_epsilon", "3e-10", "-phys_spring", "1"),
                  "-phys_radius: required with -fit_curve"),
    "held_without_moduli": (("-fit_curve", "c.csv", *TIP, "-phys_spring", "1", "-fit_modulus", "false"),
                            "-phys_young1: required with -fit_modulus false"),
    "no_adhesion": (("-fit_curve", "flat.csv", *TIP, "-phys_spring", "1"), "-fit_curve: no adhesion"),
    "no_contact": (("-fit_curve", "none.csv", *TIP, "-phys_spring", "1"), "-fit_curve: no contact"),
    "one_column": (("-fit_curve", "one.csv", *TIP, "-phys_spring", "1"), "-fit_curve: 'one.csv': line 2 has 1"),
    "bad_unit": (("-fit_curve", "unit.csv", *TIP, "-phys_spring", "1"), "-fit_curve: 'unit.csv': column 2"),
    "foreign": (("-fit_curve", "x.ibw", *TIP, "-phys_spring", "1"), "-fit_curve: 'x.ibw': not a force-distance"),
    "index": (("-fit_curve", IBW, *TIP, "-fit_curve_index", "3"), "-fit_curve: 'fmt-igor-fd_SiN_FD_plot.ibw': "
                                                                   "holds 1 curve; index 3"),
    "rough_none": (("-fit_curve", "c.csv", *TIP, "-phys_spring", "1", "-adh_roughness", "none", "-phys_rms",
                    "1e-10"), "-phys_rms: not with -adh_roughness none"),
}


@pytest.mark.parametrize("key", sorted(REFUSALS))
def test_what_a_fit_cannot_use_is_one_line(tmp_path, key):
    args, says = REFUSALS[key]
    _csv(tmp_path)
    _csv(tmp_path, "flat.csv", adhesion=False)
    _csv(tmp_path, "none.csv", adhesion=False, contact=False)
    (tmp_path / "one.csv").write_text("1 2\n3\n")
    (tmp_path / "unit.csv").write_text("z (nm), F (kg)\n1, 2\n")
    (tmp_path / "x.ibw").write_bytes(b"\x89PNG\r\n" + bytes(range(256)) * 4)
    out = tmp_path / "out"
    out.mkdir()
    p = run_cli(*args, "-summary", out / "f.json", "-out", out / "f.h5", cwd=tmp_path)
    msg = one_line(p)
    assert msg.startswith(says), msg
    assert listing(out) == []


def test_two_equal_columns_are_refused(tmp_path):
    """A file whose force column is its displacement column: no force-distance relation, one line naming the
    option, exit 2, nothing written (run from the checkout, as every test that needs today's library)."""
    ramp = np.r_[np.linspace(0, 50, 60), np.linspace(50, 0, 60)]
    # in units an AFM measures (nm and nN), so that the units' plausibility passes and the relation is judged
    (tmp_path / "equal.csv").write_text("z (nm), F (nN)\n" + "\n".join(f"{v:.6g}, {v:.6g}" for v in ramp))
    out = tmp_path / "out"
    out.mkdir()
    p = run_cli("-fit_curve", tmp_path / "equal.csv", *TIP, "-phys_spring", "1", "-summary", out / "f.json",
                "-out", out / "f.h5", timeout=120)
    msg = one_line(p)
    assert msg.startswith("-fit_curve: no force-distance relation: the force is a straight line of the piezo "
                          "position (slope 1 N/m)"), msg
    assert listing(out) == []


def test_the_measured_asylum_curve(tmp_path):
    """The MFP3D curve of tests/data (docs/fitting.md), read with its spring constant, E* held at the assumed
    moduli.  At the file's calibration its contact is half as stiff as the lever: a 20 nm tip indenting silicon
    by 14.5 nm, outside a small-strain model: refused before any curve is traced, exit 3, nothing written.
    With the sensitivity's scale, the virtual deflection and the drag fitted, the scale comes out 2.16 (the
    contact then as stiff as the lever) and the misfit falls from a reduced chi^2 of 6.6e4 to a few hundred,
    still one the model cannot explain: exit 3 with the WARNING line, the files written all the same."""
    pytest.importorskip("afmformats")
    out = tmp_path / "s.json"
    args = ("-fit_curve", IBW, "-phys_radius", "20e-9", "-phys_epsilon", "0.3e-9", "-phys_young1", "250e9",
            "-phys_poisson1", "0.25", "-phys_young2", "170e9", "-phys_poisson2", "0.28", "-fit_modulus", "false",
            "-summary", out, "-plot", tmp_path / "f.png", "-csv", tmp_path / "f.csv")
    p = run_cli(*args)
    assert p.returncode == 3 and len(p.stderr.splitlines()) == 1, p.stderr
    assert "outside the model's domain: the indentation reaches 14.5 nm, 0.72 of the tip's radius" in p.stderr
    assert not out.exists() and not (tmp_path / "f.png").exists()
    p = run_cli(*args, "-fit_invols_scale", "-fit_virtual_deflection", "-fit_drag")
    assert p.returncode == 3, p.stderr
    fit = json.load(open(out))["fit"]
    assert fit["given"]["spring_N_m"] == pytest.approx(1.1841) and fit["given"]["spring_from"] == "the file"
    E_star = 1 / ((1 - 0.25**2) / 250e9 + (1 - 0.28**2) / 170e9)
    assert fit["fixed"]["E_star"] == pytest.approx(E_star) and fit["E_star"] == fit["fixed"]["E_star"]
    assert fit["E_star_err"] is None                     # held: no bar, rather than a bar of 0
    assert fit["measured"]["pull_off_N"] == pytest.approx(12.84e-9, rel=2e-3)
    ins = fit["instrument"]
    # the scale that makes the contact as stiff as the lever: k / measured slope = 1.1841 / 0.552
    assert ins["invols_scale"] == pytest.approx(1.1841 / ins["contact_slope_N_m"], rel=0.03)
    assert ins["held"] == {"spring": "held at the file"}
    assert 5.5 < fit["reduced_chi2"] < 1e3 and fit["p_value"] < 1e-6
    assert not fit["trustworthy"]
    warned = [line.strip() for line in p.stdout.splitlines() if "WARNING" in line]
    assert f"WARNING: the model does not describe these data: reduced chi^2 {fit['reduced_chi2']:.3g} " \
           f"with {fit['dof']} degrees of freedom" in warned[-1]
    assert (tmp_path / "f.png").stat().st_size > 10_000
    rows = (tmp_path / "f.csv").read_text().splitlines()
    assert rows[0] == "z_m,F_N,leg,F_fit_N,used" and len(rows) == 2017


def test_a_good_synthetic_fit_exits_0(tmp_path):
    """The curve of the golden fit (tests/data/golden/curve.csv: made by the solver at w = 0.05 J/m^2 and E* =
    75 GPa / (1 - 0.27^2) with noise): exit 0, no WARNING, both true values inside their 95% intervals."""
    out = tmp_path / "s.json"
    p = run_cli("-fit_curve", os.path.join(ROOT, "tests", "data", "golden", "curve.csv"), *TIP, "-phys_spring", "1",
                "-summary", out)
    assert p.returncode == 0, p.stderr
    assert "WARNING" not in p.stdout
    fit = json.load(open(out))["fit"]
    assert fit["trustworthy"] and fit["warnings"] == [] and fit["missing"] == {}
    assert abs(fit["gamma"] - 0.05) <= 1.96 * fit["gamma_err"]
    assert abs(fit["E_star"] - 75e9 / (1 - 0.27**2)) <= 1.96 * fit["E_star_err"]
