"""Fitting measurements (petsc_adhesion.fitting): the readers, the pull-off's work of adhesion against the DMT
limit and a curve traced independently, and the curve fit's round trip on synthetic curves made by the forward
solver with noise (the true values inside the stated 95% intervals; docs/fitting.md measures how often).
"""
import math
import sys

import numpy as np
import pytest

from conftest import ROOT

petsc4py = pytest.importorskip("petsc4py")

from petsc_adhesion.fitting.curve_fit import CurveFitError, fit_curve  # noqa: E402
from petsc_adhesion.fitting.data import CurveFileError, MeasuredCurve, read_curve  # noqa: E402
from petsc_adhesion.fitting.pull_off import PullOffFitError, fit_pull_off  # noqa: E402
from petsc_adhesion.model.physical import Bodies  # noqa: E402

IBW = f"{ROOT}/tests/data/fmt-igor-fd_SiN_FD_plot.ibw"


# -- readers ---------------------------------------------------------------------------------------------
def _write(path, text):
    path.write_text(text)
    return str(path)


def _vee(n=30):
    """A piezo ramp in and out, and a force that rises in contact."""
    z = np.r_[np.linspace(0, 50, n), np.linspace(50, 0, n)]
    return z, np.where(z > 30, z - 30, 0.0)


def test_text_with_units_in_its_header_is_read_in_si(tmp_path):
    z, F = _vee()
    rows = "\n".join(f"{a};{b}" for a, b in zip(z, F))
    d = read_curve(_write(tmp_path / "c.csv", f"# a comment\nheight (nm); force [nN]\n{rows}\n"))
    assert d.turn == 30 and d.direction == 1 and d.spring is None
    assert np.allclose(d.z, z * 1e-9) and np.allclose(d.F, F * 1e-9)


def test_text_without_header_is_si_and_either_direction(tmp_path):
    z, F = _vee()
    # in SI as an AFM measures (nm and nN): numbers no AFM gives in SI are refused (test_hostile.py)
    d = read_curve(_write(tmp_path / "c.txt", "\n".join(f"{-a * 1e-9:g}\t{b * 1e-9:g}" for a, b in zip(z, F))))
    assert d.direction == -1 and d.turn == 30 and np.allclose(d.z, -z * 1e-9, rtol=1e-5, atol=0)   # 6 digits written


@pytest.mark.parametrize("text, says", [
    ("1 2\n3\n", "line 2 has 1 column"),
    ("z (nm), F (kg)\n1, 2\n", "'kg' is no force unit"),
    ("z\n1\n", "names one column"),
    ("", "no rows of numbers"),
    ("\n".join(f"{min(i, 39 - i)} 1" for i in range(40)), "the force is constant"),
    ("\n".join(f"{i} {i}" for i in range(40)), "the retract has"),
    ("1 nan\n" * 30, "not finite"),
])
def test_text_that_is_no_curve_is_one_line(tmp_path, text, says):
    with pytest.raises(CurveFileError) as e:
        read_curve(_write(tmp_path / "c.dat", text))
    msg = str(e.value)
    assert says in msg and "\n" not in msg and msg.startswith("'c.dat'")


def test_foreign_binary_files_are_one_line(tmp_path):
    for name in ("x.ibw", "x.jpk-force", "x.csv", "x.bin"):
        p = tmp_path / name
        p.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 8)
        with pytest.raises(CurveFileError) as e:
            read_curve(str(p))
        assert "\n" not in str(e.value) and str(e.value).startswith(f"'{name}'")


def test_an_afm_file_without_afmformats_is_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "afmformats", None)          # as if it were not installed
    with pytest.raises(CurveFileError, match="needs afmformats"):
        read_curve(IBW)


def test_the_asylum_file_is_read_with_its_spring_constant():
    pytest.importorskip("afmformats")
    d = read_curve(IBW)
    assert d.source.startswith("Asylum") and d.spring == pytest.approx(1.18, abs=0.01)
    assert d.turn == 1008 and d.z.size == 2016
    assert d.F[d.retract].min() < -1e-8 < 0 < d.F[d.approach].max()   # a pull-off of about 13 nN, contact


# -- the pull-off --------------------------------------------------------------------------------------
def _bodies(mu, R=1e-6, w=0.05, eps=0.4e-9, nu=0.3):
    """Bodies at Tabor parameter ``mu`` (eq. 9 solved for E, on a rigid flat)."""
    E = w * math.sqrt(R / (mu**3 * eps**3))
    return Bodies(radius=R, young1=E * (1 - nu**2), poisson1=nu, epsilon=eps)


def test_pull_off_at_small_mu_is_dmt():
    """As mu -> 0 the pull-off is the rigid sphere's, 2 pi R w (Derjaguin, Muller and Toporov): the fit gives
    DMT's w to within the elastic correction, which vanishes with mu."""
    b = _bodies(0.01)
    P = 2 * math.pi * b.R * 0.05
    f = fit_pull_off(P, b)
    assert abs(f.gamma / 0.05 - 1) < 5e-3 and abs(f.mu - 0.01) < 1e-4
    assert f.closed_forms["dmt"]["gamma"] == pytest.approx(0.05, rel=1e-12)
    assert f.closed_forms["jkr"]["gamma"] == pytest.approx(0.05 * 4 / 3, rel=1e-12)


def test_pull_off_of_an_independent_curve_gives_its_gamma_back():
    """P from the whole default curve (traced past equilibrium, with its error bars) at w = 0.05, mu = 1:
    the fit, which traces its own truncated curves, gives w back within its bar."""
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import trace_curve

    b = _bodies(1.0)
    c = trace_curve(Model(mu=1.0))
    P = abs(c.pull_off.F.value) * 2 * math.pi * b.R * 0.05
    f = fit_pull_off(P, b, P_err=0.01 * P)
    assert abs(f.gamma - 0.05) < 1.96 * f.gamma_err
    # a 1% force gives w to about 1 / (1 + (2/3) dln|F|/dlnmu) %: the bar says so
    assert f.gamma_err / f.gamma == pytest.approx(0.01 / (1 + 2 / 3 * f.dlnF_dlnmu), rel=0.02)
    assert f.closed_forms["dmt"]["gamma"] < f.gamma < f.closed_forms["jkr"]["gamma"]


@pytest.mark.parametrize("P", [0.0, -1e-9, math.inf, 1.0])
def test_a_pull_off_no_w_gives_is_one_line(P):
    with pytest.raises(PullOffFitError) as e:
        fit_pull_off(P, _bodies(1.0))
    assert "\n" not in str(e.value)


# -- the curve --------------------------------------------------------------------------------------------
R, EPS, K_SPRING, W = 20e-9, 0.3e-9, 1.0, 0.05


@pytest.mark.parametrize("mu, seed", [(0.5, 11), (1.0, 12), (2.0, 13)])
def test_curve_fit_recovers_a_synthetic_curve(mu, seed):
    """A curve made by the forward solver (finer steps than the fit's) with 1% noise, a contact point and a
    baseline: w and E* inside their 95% intervals, the contact point too."""
    from petsc_adhesion.fitting.synthetic import synthetic_curve
    from petsc_adhesion.tracing.trace import curve_settings

    E = W * math.sqrt(R / (mu**3 * EPS**3))
    noise = 0.01 * 2 * math.pi * R * W
    d = synthetic_curve(R, EPS, K_SPRING, W, E, noise=noise, points=300, z0=7e-9, F0=-3e-10, seed=seed,
                        settings=curve_settings(observable_max=2.0, ds_max=0.2, observable_step=0.1))
    f = fit_curve(d, R, EPS, K_SPRING)
    assert abs(f.gamma - W) <= 1.96 * f.gamma_err, (f.gamma, f.gamma_err)
    assert abs(f.E_star - E) <= 1.96 * f.E_star_err, (f.E_star, f.E_star_err)
    assert abs(f.z0 - 7e-9) <= 1.96 * f.z0_err
    assert f.gamma_err / W < 0.05 and f.E_star_err / E < 0.2     # the bars say something
    assert 0.7 < f.chi2 / f.dof < 2.0                             # the noise, not a misfit


def _curve(F_contact, F_pull):
    """A measured-looking curve: a flat baseline with noise, a linear contact, and a retract that holds on to
    ``F_pull`` below the baseline before it lets go."""
    rng = np.random.default_rng(0)
    z = np.linspace(0, 100e-9, 200)
    Fa = np.where(z > 80e-9, (z - 80e-9) / 20e-9 * F_contact, 0.0)
    Fr = np.where(z > 70e-9, (z - 80e-9) / 20e-9 * (F_contact + F_pull) + F_pull * 0, 0.0)
    Fr = np.maximum(Fr, np.where(z > 70e-9, -F_pull, 0.0))
    F = np.r_[Fa, Fr[::-1]] + 1e-12 * rng.standard_normal(400)
    return MeasuredCurve(z=np.r_[z, z[::-1]], F=F, turn=200, direction=1, spring=1.0)


@pytest.mark.parametrize("F_contact, F_pull, says", [(0.0, 0.0, "no contact"), (5e-9, 0.0, "no adhesion")])
def test_a_curve_without_contact_or_adhesion_is_one_line(F_contact, F_pull, says):
    with pytest.raises(CurveFitError) as e:
        fit_curve(_curve(F_contact, F_pull), R, EPS, 1.0)
    assert str(e.value).startswith(says) and "\n" not in str(e.value)
