"""Measured topographies in (model/topography.py, -adh_topography): read by SurfaceTopography, their statistics and
sampling uncertainty, the gap of two surfaces, and the run's result against the Gaussian laws.

Independent truth: the heights and the plane fitted with numpy's least squares on SurfaceTopography's raw
heights; the sampling uncertainty against the spread of many synthetic Gaussian surfaces (Monte Carlo);
cumulants of independent sums (variance and third cumulant add); a flat surface against the smooth run; a
synthetic Gaussian surface against the truncated Gaussian at its own highest point, within the band its
rms's sampling error makes.
"""
import json
import math
import os
import sys

import numpy as np
import pytest

from conftest import ROOT, in_process
from test_cli import run_all

pytest.importorskip("SurfaceTopography")
from petsc_adhesion.model.topography import (  # noqa: E402
    Topography, TopographyError, gap_heights, read_topography, statistics)

AFM = os.path.join(ROOT, "tests", "data", "wsxm-afm-topography.top")
EPS = 4e-10
PHYS = ("-phys_radius", "1e-6", "-phys_gamma", "0.05", "-phys_young1", "1e10", "-phys_poisson1", "0",
        "-phys_epsilon", str(EPS))
GRID = ("-grid_type", "uniform", "-grid_n", "201", "-adh_rmax", "10", "-cont_F_max", "0.2",
        "-cont_error_estimate", "false")
MEASURED = ("-adh_roughness", "measured")


def gaussian_field(n: int, xi: float, rng) -> np.ndarray:
    """A periodic Gaussian random field of n x n pixels, Gaussian autocorrelation of width about xi pixels."""
    k = np.fft.fftfreq(n)
    filt = np.exp(-(k[:, None] ** 2 + k[None, :] ** 2) * (math.pi * xi) ** 2 / 2)
    return np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * filt).real


def write_map(path, z, unit="nm", size=256.0, stated=True):
    """SurfaceTopography's text format: a matrix with its size and unit in the header."""
    header = f"Channel: Height\nWidth: {size:g} {unit}\nHeight: {size:g} {unit}\nValue units: {unit}" if stated else ""
    np.savetxt(path, z, header=header)
    return str(path)


# -- the reader -----------------------------------------------------------------------

def test_the_afm_file():
    """The WSxM AFM image: its unit and size from the file, its heights SurfaceTopography's minus the plane numpy
    fits; curvature removes more, none only the mean."""
    import SurfaceTopography
    raw = SurfaceTopography.open_topography(AFM).topography().heights()
    t = read_topography(AFM)
    assert (t.kind, t.pixels, t.unit, t.unit_source, t.detrend) == ("map", (256, 256), "nm", "file", "plane")
    assert t.size == pytest.approx((600e-9, 600e-9), rel=1e-12)
    i, j = np.indices(raw.shape)
    A = np.column_stack([np.ones(raw.size), i.ravel(), j.ravel()])
    plane = raw.ravel() - A @ np.linalg.lstsq(A, raw.ravel(), rcond=None)[0]
    assert np.allclose(t.heights.ravel(), plane * 1e-9, rtol=0, atol=1e-12 * 1e-9 * np.ptp(raw))
    assert t.stats.rms.value == pytest.approx(np.sqrt(np.mean(plane ** 2)) * 1e-9, rel=1e-12)
    none, curv = read_topography(AFM, "none"), read_topography(AFM, "curvature")
    assert none.stats.rms.value == pytest.approx(np.std(raw) * 1e-9, rel=1e-12)
    assert curv.stats.rms.value < t.stats.rms.value < none.stats.rms.value
    # a spiky surface: heights skewed up, heavy-tailed; their bars from ~60 independent samples, not 65536
    s = t.stats
    assert s.skewness.value > 2 and s.kurtosis.value > 10 and 20 < s.independent[0] < 200
    assert s.rms.err == pytest.approx(s.rms.value / math.sqrt(2 * s.independent[0]), rel=1e-12)


def test_sampling_uncertainty_is_the_spread_of_many_surfaces():
    """40 Gaussian surfaces of one population: the spread of their rms, skewness and kurtosis is the uncertainty
    each one's own autocorrelation predicts (to the 12 % a spread of 40 is known to)."""
    rng = np.random.default_rng(35)
    scale = 1 / np.std(gaussian_field(128, 4.0, np.random.default_rng(0)))
    stats = [statistics(scale * gaussian_field(128, 4.0, rng)) for _ in range(40)]
    for name in ("rms", "skewness", "kurtosis"):
        values = np.array([getattr(s, name).value for s in stats])
        predicted = np.mean([getattr(s, name).err for s in stats])
        assert 0.7 < np.std(values, ddof=1) / predicted < 1.4, name
    # pixels correlated over ~4: far fewer independent samples than the 16384 pixels
    # (the autocorrelation exp(-r^2 / 16): 1/e at 4 pixels)
    assert 300 < stats[0].independent[0] < 1500
    assert np.mean([s.correlation_length for s in stats]) == pytest.approx(4.0, abs=0.2)


def test_gap_of_two_surfaces_is_the_convolution(tmp_path):
    """The sum of independent heights: its variance and its third cumulant are the surfaces' added; the highest
    point of the gap is the sum of the two highest."""
    rng = np.random.default_rng(7)
    a = write_map(tmp_path / "a.txt", 0.1 * gaussian_field(96, 3.0, rng) / 0.02)
    b = write_map(tmp_path / "b.txt", 0.05 * rng.exponential(1.0, (80, 90)), size=200)     # skewed
    ta, tb = read_topography(a), read_topography(b)
    g, w = gap_heights((ta, tb), EPS)
    assert w.sum() == pytest.approx(1.0, rel=1e-14) and np.all(w > 0)
    za, zb = ta.heights.ravel() / EPS, tb.heights.ravel() / EPS
    gc = g - w @ g
    assert abs(w @ g) < 1e-5 * np.sqrt(w @ gc ** 2)      # the mean: rounding to the grid only
    assert w @ gc ** 2 == pytest.approx(np.mean(za ** 2) + np.mean(zb ** 2), rel=1e-4)
    assert w @ gc ** 3 == pytest.approx(np.mean(za ** 3) + np.mean(zb ** 3), rel=1e-3)
    assert g.max() == pytest.approx(za.max() + zb.max(), rel=1e-14)
    one, none = gap_heights((ta,), EPS)
    assert np.array_equal(one, za) and none is None


def test_footprint_heights():
    """A footprint's heights: the pixels within its radius, as the map holds them."""
    t = read_topography(AFM)
    p = t.pixel_size[0]
    h = t.local((300e-9, 300e-9), 20e-9)
    assert abs(h.size - math.pi * (20e-9 / p) ** 2) < 2 * math.pi * 20e-9 / p
    assert set(h.tolist()) <= set(t.heights.ravel().tolist())
    with pytest.raises(ValueError, match="leaves the scan"):
        t.local((10e-9, 300e-9), 20e-9)


def test_without_surface_topography(monkeypatch):
    """Without the package the reader says which package, in one line."""
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)
    with pytest.raises(TopographyError, match="needs the package SurfaceTopography"):
        read_topography(AFM)


# -- through the program ----------------------------------------------------------------

@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("topo")
    rng = np.random.default_rng(2002)
    z = gaussian_field(128, 4.0, rng)
    z *= 0.08 / np.std(z)                 # rms 0.08 nm: sigma 0.2 at epsilon 0.4 nm
    gauss = write_map(d / "g.txt", z)
    t = read_topography(gauss)
    sigma, err, top = t.stats.rms.value / EPS, t.stats.rms.err / EPS, t.stats.highest / EPS
    jobs = {"measured": [*MEASURED, "-adh_topography", gauss],
            "metres": [*MEASURED, "-adh_topography", write_map(d / "m.txt", z * 1e-9, "m", 256e-9)],
            "doubled": [*MEASURED, "-adh_topography", write_map(d / "2.txt", 2 * z), "-adh_model_spread", "false"],
            "two": [*MEASURED, "-adh_topography", gauss, "-adh_topography2", write_map(
                d / "b.txt", 0.5 * gaussian_field(100, 3.0, rng) * 0.08 / 0.02, size=300), "-adh_model_spread", "false"],
            "flat": [*MEASURED, "-adh_topography", write_map(d / "f.txt", 1e-3 * np.add.outer(np.arange(40),
                                                                                             np.arange(50)))],
            "smooth": ["-adh_roughness", "none"]}
    # main() in this process, as tests/test_roughness_models.py runs its curves: a process of its own would add
    # about 1 CPU s to each of these eight cheap runs
    procs = {k: in_process(*PHYS, *GRID, *a, "-summary", d / f"{k}.json", "-out", d / f"{k}.h5")
             for k, a in jobs.items()}
    # the Gaussian cut at the same highest point, its rms one bar up and down (K to two decimals, as the spread's)
    tg = {k: in_process("-adh_mu", str(_mu()), "-adh_sigma", f"{s:.6g}", *GRID, "-adh_roughness", "truncated_gaussian",
                        "-adh_roughness_cutoff", f"{top / s:.2f}", "-adh_model_spread", "false", "-summary",
                        d / f"{k}.json") for k, s in (("up", sigma + err), ("down", sigma - err))}
    out = {"sigma": sigma, "err": err, "top": top}
    for k, p in {**procs, **tg}.items():
        assert p.returncode == 0, (k, p.stderr)
        out[k] = json.load(open(d / f"{k}.json"))
        out[k + "_stdout"] = p.stdout
    return out


def _mu() -> float:
    from petsc_adhesion.model.physical import Bodies
    return Bodies(radius=1e-6, gamma=0.05, young1=1e10, poisson1=0.0, epsilon=EPS).mu


def test_a_gaussian_surface_gives_the_gaussian_law_within_its_sampling_error(runs):
    """The synthetic Gaussian surface's pull-off is the truncated Gaussian's at its own rms and highest point,
    within the band the rms's sampling error makes (the Gaussian cut at the same top, rms +- its bar); the
    paper's 16-point Hermite rule at that rms is not (its answer is its outermost node's)."""
    m = runs["measured"]
    F = m["pull_off"]["F"]
    spread = {q["name"]: dict(zip(m["model_spread"]["rules"], q["values"])) for q in m["model_spread"]["quantities"]}
    own = f"truncated_gaussian:{min(10.0, round(runs['top'] / m['sigma'], 2)):g}"
    F_tg, F_hermite = spread["pull-off F"][own], spread["pull-off F"]["hermite:16"]
    band = abs(runs["up"]["pull_off"]["F"] - runs["down"]["pull_off"]["F"]) / 2
    assert band > 1e-3
    assert abs(F - F_tg) < 2 * band, (F, F_tg, band)
    assert abs(F - F_hermite) > 2 * band
    # the record: the file, its moments with their bars, the gap in epsilon
    t = m["topography"]
    s = t["surfaces"][0]
    assert s["kind"] == "map" and s["pixels"] == [128, 128] and s["unit"] == "nm" and s["detrend"] == "plane"
    # 0.08 nm before the plane was removed
    assert s["size_m"] == pytest.approx([256e-9, 256e-9]) and s["rms_m"] == pytest.approx(0.08e-9, rel=0.01)
    assert abs(s["skewness"]) < 3 * s["skewness_err"] and abs(s["kurtosis"] - 3) < 3 * s["kurtosis_err"]
    assert t["gap_rms_epsilon"] == pytest.approx(m["sigma"], rel=1e-9) and m["sigma"] == pytest.approx(0.2, rel=0.01)
    assert "topography" in runs["measured_stdout"] and "independent samples" in runs["measured_stdout"]


def test_units_from_the_file_and_scaling(runs):
    """The same heights written in metres give the same sigma; heights doubled double it."""
    assert runs["metres"]["sigma"] == pytest.approx(runs["measured"]["sigma"], rel=1e-9)
    assert runs["doubled"]["sigma"] == pytest.approx(2 * runs["measured"]["sigma"], rel=1e-12)


def test_two_surfaces_add_their_variances(runs):
    t = runs["two"]["topography"]
    r1, r2 = (s["rms_m"] for s in t["surfaces"])
    assert runs["two"]["sigma"] == pytest.approx(math.hypot(r1, r2) / EPS, rel=1e-3)
    assert "convolved" in t["gap"]


def test_a_flat_surface_is_the_smooth_sphere(runs):
    """A tilted plane, detrended, has no roughness: the smooth sphere's curve, the record saying why."""
    flat, smooth = runs["flat"], runs["smooth"]
    assert flat["sigma"] == 0 and "smooth" in flat["topography"] and "model_spread" not in flat
    s = flat["topography"]["surfaces"][0]
    assert s["rms_m"] == 0 and "skewness" not in s and "flat" in s["note"]
    assert flat["pull_off"]["F"] == smooth["pull_off"]["F"] and flat["pull_off"]["lambda"] == smooth["pull_off"]["lambda"]


# -- bad input: one line each, exit 2, nothing written --------------------------------------

def test_bad_topographies(tmp_path):
    rng = np.random.default_rng(1)
    z = rng.standard_normal((20, 30))
    nan = z.copy()
    nan[3, 4] = np.nan
    (tmp_path / "garbage.bin").write_bytes(bytes(range(256)) * 4)
    (tmp_path / "empty.txt").write_bytes(b"")
    cases = {
        "no_heights": ([*MEASURED, "-adh_topography", tmp_path / "empty.txt"], "-adh_topography",
                       "no height data"),
        "not_topography": ([*MEASURED, "-adh_topography", tmp_path / "garbage.bin"], "-adh_topography",
                           "not a topography file"),
        "no_units": ([*MEASURED, "-adh_topography", write_map(tmp_path / "nounit.txt", z, stated=False)],
                     "-adh_topography", "-adh_topography_unit"),
        "unit_twice": ([*MEASURED, "-adh_topography", write_map(tmp_path / "u.txt", z), "-adh_topography_unit", "nm"],
                       "-adh_topography", "states its unit"),
        "nan": ([*MEASURED, "-adh_topography", write_map(tmp_path / "nan.txt", nan)], "-adh_topography",
                "1 of 600 pixels undefined"),
        "no_epsilon": ([*MEASURED, "-adh_topography", write_map(tmp_path / "e.txt", z)], "-adh_topography",
                       "-phys_epsilon"),
        "second_only": ([*MEASURED, "-adh_topography2", write_map(tmp_path / "s.txt", z)], "-adh_topography2",
                        "only with -adh_topography"),
        "not_measured": (["-adh_sigma", "0.2", "-adh_topography", write_map(tmp_path / "n.txt", z)],
                         "-adh_topography", "measured"),
        "with_file": ([*MEASURED, "-adh_topography", write_map(tmp_path / "w.txt", z), "-adh_roughness_file",
                       write_map(tmp_path / "w2.txt", z)], "-adh_roughness_file", "not with -adh_topography"),
    }
    out = tmp_path / "out.json"
    procs = run_all({k: ([*(PHYS if k != "no_epsilon" else ("-adh_mu", "1")), *GRID, *args, "-summary", out], {})
                     for k, (args, _, _) in cases.items()})
    for k, (_, option, words) in cases.items():
        p = procs[k]
        lines = p.stderr.strip().splitlines()
        assert p.returncode == 2 and len(lines) == 1, (k, p.stderr)
        assert lines[0].startswith(f"petsc-adhesion: error: {option}:") and words in lines[0], (k, lines[0])
    assert not out.exists()


def test_a_profile_is_accepted_and_a_unit_can_be_stated(tmp_path):
    """A line profile: its heights sample the distribution (documented choice), its statistics in one dimension;
    a file without a unit read with the one the user states."""
    rng = np.random.default_rng(4)
    line = np.convolve(rng.standard_normal(4000), np.ones(5) / 5, "same")
    path = tmp_path / "p.txt"
    np.savetxt(path, line)
    t = read_topography(str(path), unit="nm")
    assert t.kind == "profile" and t.unit_source == "option" and t.size is None
    assert t.stats.rms.value == pytest.approx(np.std(line - np.polyval(np.polyfit(np.arange(4000), line, 1),
                                                                        np.arange(4000))) * 1e-9, rel=1e-9)
    assert 2 <= t.stats.correlation_length[0] <= 4
    assert isinstance(t, Topography)
