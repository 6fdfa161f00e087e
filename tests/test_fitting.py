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
from petsc_adhesion.fitting.results import FitChoice, Spring, misfit_p  # noqa: E402
from petsc_adhesion.fitting.synthetic import Sampling, synthetic_curve  # noqa: E402
from petsc_adhesion.model.physical import Bodies  # noqa: E402
from petsc_adhesion.tracing.measured import Measured, Missing  # noqa: E402

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
    assert abs(f.gamma.value / 0.05 - 1) < 5e-3 and abs(f.mu - 0.01) < 1e-4
    assert f.closed_form("dmt").gamma == pytest.approx(0.05, rel=1e-12)
    assert f.closed_form("jkr").gamma == pytest.approx(0.05 * 4 / 3, rel=1e-12)
    assert f.trustworthy and f.warnings == ()


def test_pull_off_of_an_independent_curve_gives_its_gamma_back():
    """P from the whole default curve (traced past equilibrium, with its error bars) at w = 0.05, mu = 1:
    the fit, which traces its own truncated curves, gives w back within its bar."""
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import trace_curve

    b = _bodies(1.0)
    c = trace_curve(Model(mu=1.0))
    P = abs(c.pull_off.F.value) * 2 * math.pi * b.R * 0.05
    f = fit_pull_off(P, b, P_err=0.01 * P)
    assert f.gamma.covers(0.05, 1.96) and f.P == Measured(P, 0.01 * P)
    # a 1% force gives w to about 1 / (1 + (2/3) dln|F|/dlnmu) %: the bar says so
    assert f.gamma.relative == pytest.approx(0.01 / (1 + 2 / 3 * f.dlnF_dlnmu), rel=0.02)
    assert f.closed_form("dmt").gamma < f.gamma.value < f.closed_form("jkr").gamma
    assert f.trustworthy


def test_a_pull_off_as_uncertain_as_itself_leaves_w_undetermined():
    """P_err = P: the bar of w is about P_err / P over 1 + (2/3) dln|F|/dlnmu (near 1 at small mu), so its 95%
    interval is wider than w: w is Missing with that reason, and the fit does not hold."""
    b = _bodies(0.01)
    P = 2 * math.pi * b.R * 0.05
    f = fit_pull_off(P, b, P_err=P)
    assert isinstance(f.gamma, Missing) and f.gamma.reason.startswith("its 95% interval")
    assert not f.complete and not f.trustworthy
    assert f.warnings == (f"gamma undetermined: {f.gamma.reason}",)


def test_undetermined_is_a_95_percent_interval_wider_than_the_value():
    """The rule's edge: a bar of 1 / 1.96 of the value is the widest a determined value may have."""
    from petsc_adhesion.fitting.results import undetermined

    assert undetermined(1.0, 0.999 / 1.959964) is None
    assert undetermined(-1.0, 0.999 / 1.959964) is None
    assert undetermined(1.0, 1.001 / 1.959964).startswith("its 95% interval")
    assert "singular" in undetermined(1.0, None) and "singular" in undetermined(1.0, math.nan)


@pytest.mark.parametrize("P", [0.0, -1e-9, math.inf, 1.0])
def test_a_pull_off_no_w_gives_is_one_line(P):
    with pytest.raises(PullOffFitError) as e:
        fit_pull_off(P, _bodies(1.0))
    assert "\n" not in str(e.value)


# -- the curve --------------------------------------------------------------------------------------------
R, EPS, K_SPRING, W = 20e-9, 0.3e-9, 1.0, 0.05
#: What a fit of a curve is given: the tip and epsilon, no moduli.
TIP = Bodies(radius=R, young1=None, poisson1=None, epsilon=EPS)


def _truth(mu):
    """The bodies of the synthetic curves: w = W, E* from eq. (9) at ``mu`` (on a rigid flat)."""
    return Bodies(radius=R, young1=W * math.sqrt(R / (mu**3 * EPS**3)), poisson1=0.0, epsilon=EPS, gamma=W)


def _synthetic(mu, seed, noise_share=0.01, points=300, fine=True):
    """A curve made by the forward solver (finer steps than the fit's where ``fine``) with noise of
    ``noise_share`` of 2 pi R w, a contact point and a baseline."""
    from petsc_adhesion.tracing.trace import curve_settings

    noise = noise_share * 2 * math.pi * R * W
    settings = curve_settings(observable_max=2.0, ds_max=0.2, observable_step=0.1) if fine else None
    return synthetic_curve(_truth(mu), Spring(K_SPRING),
                           Sampling(noise=noise, points=points, z0=7e-9, F0=-3e-10, seed=seed), settings=settings)


@pytest.mark.parametrize("mu, seed", [(0.5, 11), (1.0, 12), (2.0, 13)])
def test_curve_fit_recovers_a_synthetic_curve(mu, seed):
    """A curve made by the forward solver (finer steps than the fit's) with 1% noise, a contact point and a
    baseline: w and E* inside their 95% intervals, the contact point too; the fit holds (no warning)."""
    E = _truth(mu).E
    f = fit_curve(_synthetic(mu, seed), TIP, Spring(K_SPRING))
    assert f.gamma.covers(W, 1.96), f.gamma
    assert f.E_star.covers(E, 1.96), f.E_star
    assert f.z0.covers(7e-9, 1.96), f.z0
    assert f.gamma.relative < 0.05 and f.E_star.relative < 0.2     # the bars say something
    assert 0.7 < f.reduced_chi2 < 2.0                             # the noise, not a misfit
    assert f.trustworthy and f.complete and f.warnings == () and f.p_value > 1e-3
    assert f.rms is None and f.parameters == ("ln_E_star", "ln_gamma", "z0", "F0")


def test_a_noise_100_times_the_stated_is_a_misfit():
    """The same curve fitted twice: with the noise it has stated, the fit holds; stated 100 times smaller, chi^2
    grows 10^4 times and the fit says the model does not describe the data, with the figure."""
    noise = 0.01 * 2 * math.pi * R * W
    d = _synthetic(1.0, 12, fine=False, points=150)
    good = fit_curve(d, TIP, Spring(K_SPRING), FitChoice(noise=noise))
    assert good.trustworthy and good.noise_stated and good.p_value > 1e-3, good.warnings
    bad = fit_curve(d, TIP, Spring(K_SPRING), FitChoice(noise=noise / 100))
    assert not bad.trustworthy and bad.complete                 # the numbers are there; they do not hold
    # at most 10^4 times the good fit's (its optimum, now 10^4 times worse, was open to it), and far above 1
    assert 1e3 < bad.reduced_chi2 <= 1.0001e4 * good.reduced_chi2
    assert bad.p_value < 1e-6
    (w,) = bad.warnings
    assert w.startswith("the model does not describe these data: reduced chi^2 ") and f"{bad.reduced_chi2:.3g}" in w


def test_mu_driven_to_its_bound_is_missing():
    """A curve made at mu = 0.3, fitted with E* held 10^4 times too stiff: w would need mu = 0.3 / 10^(8/3) =
    6.5e-4 by eq. (9), below the model's 1e-3; the fit stops at the bound, and w is Missing with that reason."""
    truth = _truth(0.3)
    d = _synthetic(0.3, 3, fine=False, points=150)
    held = Bodies(radius=R, young1=truth.E * 1e4, poisson1=0.0, epsilon=EPS)
    f = fit_curve(d, held, Spring(K_SPRING), FitChoice(modulus=False))
    assert isinstance(f.gamma, Missing) and "at the bound 0.001 of the model's range" in f.gamma.reason
    assert f.mu == pytest.approx(1e-3, rel=0.02)
    assert f.E_star == Measured(held.E, note="held at the moduli given (eq. 2)")
    assert not f.complete and not f.trustworthy
    assert any(w.startswith("gamma undetermined: mu = ") for w in f.warnings)


def test_the_misfit_threshold_is_the_noise_distribution():
    """The threshold's probability against closed forms: with a stated noise, chi^2 with dof degrees of freedom
    (its mean dof: p near 1/2 there); with an estimated noise of nu degrees of freedom, Fisher's F, whose tail is
    heavier (the same chi^2 less improbable); and the Wilson-Hilferty point of p = 1e-6 for dof = 300."""
    assert misfit_p(300.0, 300, None) == pytest.approx(0.5, abs=0.02)
    assert misfit_p(1.5 * 300, 300, 30.0) > misfit_p(1.5 * 300, 300, None)
    # Wilson-Hilferty: chi^2_p = dof (1 - 2/(9 dof) + z sqrt(2/(9 dof)))^3, z = 4.7534 at p = 1e-6
    dof, z = 300, 4.753424
    x = dof * (1 - 2 / (9 * dof) + z * math.sqrt(2 / (9 * dof))) ** 3
    assert misfit_p(x, dof, None) == pytest.approx(1e-6, rel=0.1)


def test_two_equal_columns_are_no_curve():
    """A file whose force column is its displacement column: the force is a straight line of z on both legs,
    no force-distance relation; one line."""
    z = np.r_[np.linspace(0, 50e-9, 100), np.linspace(50e-9, 0, 100)]
    with pytest.raises(CurveFitError) as e:
        fit_curve(MeasuredCurve(z=z, F=z.copy(), turn=100, direction=1, spring=1.0), TIP, Spring(1.0))
    assert str(e.value).startswith("no force-distance relation") and "\n" not in str(e.value)


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
        fit_curve(_curve(F_contact, F_pull), TIP, Spring(1.0))
    assert str(e.value).startswith(says) and "\n" not in str(e.value)


def test_ranks_making_curves_of_their_own_make_the_serial_curves(tmp_path):
    """Two ranks, each making a different synthetic curve on PETSc.COMM_SELF (as a study dealing its cases to the
    ranks does), make what one process makes of each: the forces equal to round-off.  Traced on the world
    communicator, ranks tracing different curves met in each other's collective operations (the coverage
    study on two ranks ended in 'munmap_chunk(): invalid pointer' inside a Jacobian)."""
    import subprocess

    import conftest

    mus = (0.1, 0.3)
    code = ("import sys, numpy as np; import petsc4py; petsc4py.init([]); from petsc4py import PETSc\n"
            "from petsc_adhesion.fitting.results import Spring\n"
            "from petsc_adhesion.fitting.synthetic import Sampling, synthetic_curve\n"
            "from petsc_adhesion.model.physical import Bodies\n"
            "r = PETSc.COMM_WORLD.getRank(); mu = (%r, %r)[r]; R, eps, w = 20e-9, 0.3e-9, 0.05\n"
            "b = Bodies(radius=R, young1=w * (R / (mu**3 * eps**3)) ** 0.5, poisson1=0.0, epsilon=eps, gamma=w)\n"
            "c = synthetic_curve(b, Spring(1.0), Sampling(points=60), comm=PETSc.COMM_SELF)\n"
            "np.save(sys.argv[1] + '/F%%d.npy' %% r, c.F)\n") % mus
    proc = subprocess.run([*conftest.mpiexec(2), sys.executable, "-c", code, str(tmp_path)], env=conftest._env(),
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    R, eps, w = 20e-9, 0.3e-9, 0.05
    for r, mu in enumerate(mus):
        b = Bodies(radius=R, young1=w * math.sqrt(R / (mu**3 * eps**3)), poisson1=0.0, epsilon=eps, gamma=w)
        serial = synthetic_curve(b, Spring(1.0), Sampling(points=60)).F
        ranked = np.load(tmp_path / f"F{r}.npy")
        assert ranked.shape == serial.shape and np.allclose(ranked, serial, rtol=0, atol=1e-12 * np.abs(serial).max())
