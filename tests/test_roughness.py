"""Height distributions bounded above, their wall quadrature, and height files (roughness.py)."""
import math

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad

from petsc_adhesion.model.roughness import DISTRIBUTIONS, Measured, TruncatedGaussian, Weibull, WallQuadrature
from petsc_adhesion.model.heights import HeightFileError, read_heights

# quad warns when it meets rounding, i.e. when the reference is as good as it gets
pytestmark = pytest.mark.filterwarnings("ignore", category=IntegrationWarning)


def moment(dist, f) -> float:
    """integral f(S) pdf(S) dS by quad, on panels of rms/2 over the support (60 rms for an open tail)."""
    lo = dist.bottom if math.isfinite(dist.bottom) else dist.top - 60 * dist.rms
    edges = np.linspace(lo, dist.top, int((dist.top - lo) / (dist.rms / 2)) + 2)
    return sum(quad(lambda S: f(S) * float(dist.pdf(S)), a, b, epsabs=0, epsrel=1e-13, limit=200)[0]
               for a, b in zip(edges[:-1], edges[1:]))


def reference(dist, d: float, k: int) -> float:
    """E[(d + u)^-k], u = S_max - S, by quad on the density in v = log(1 + u/d).

    The substitution is exact; quad gets unit panels in v and panels of rms/2 in u,
    so it sees the wall on the scale d and the density on the scale of its rms.
    """
    lo = dist.bottom if math.isfinite(dist.bottom) else dist.top - 60 * dist.rms
    U = dist.top - lo
    V = math.log1p(U / d)
    breaks = set(np.arange(0.0, V, 1.0)) | {math.log1p(u / d) for u in np.arange(dist.rms / 2, U, dist.rms / 2)}
    edges = sorted(breaks | {V})

    def f(v):
        return float(dist.pdf(dist.top - d * math.expm1(v))) * math.exp((1 - k) * v)

    panels = zip(edges[:-1], edges[1:])
    return d ** (1 - k) * sum(quad(f, a, b, epsabs=0, epsrel=1e-13, limit=200)[0] for a, b in panels)


def rule_average(rule: WallQuadrature, d: float, k: int) -> float:
    g, w = rule.near(np.array([d]))
    return float(w[0] @ g[0] ** -k + rule.weights @ (d + rule.depths) ** -k)


# -- the distributions --------------------------------------------------------------

@pytest.mark.parametrize("cutoff", [1.0, 3.0, 6.0])
def test_truncated_gaussian_moments(cutoff):
    """Unit mass, zero mean and skewness, the stated rms, the highest asperity at K sigma."""
    dist = TruncatedGaussian(0.7, cutoff)
    assert moment(dist, lambda S: 1.0) == pytest.approx(1.0, abs=1e-12)
    assert moment(dist, lambda S: S) == pytest.approx(0.0, abs=1e-12)
    assert math.sqrt(moment(dist, lambda S: S * S)) == pytest.approx(dist.rms, rel=1e-12)
    assert moment(dist, lambda S: S ** 3) == pytest.approx(0.0, abs=1e-12)
    assert dist.top == dist.cutoff * 0.7 == -dist.bottom
    assert dist.pdf(dist.top) > 0 and dist.pdf(dist.top * (1 + 1e-12)) == 0
    # the weight of eq. (3) with paper note 1 of docs/model.md: exp(-S^2 / (2 sigma^2))
    assert dist.pdf(0.7) / dist.pdf(0.0) == pytest.approx(math.exp(-0.5), rel=1e-14)


@pytest.mark.parametrize("skewness", [-2.0, -1.0, 0.0, 0.5])
def test_weibull_has_the_requested_rms_and_skewness(skewness):
    """Moments computed by quad on the density, independently of the Gamma-function formulas."""
    dist = Weibull(0.3, skewness)
    mean = moment(dist, lambda S: S)
    var = moment(dist, lambda S: (S - mean) ** 2)
    assert moment(dist, lambda S: 1.0) == pytest.approx(1.0, abs=1e-12)
    assert mean == pytest.approx(0.0, abs=1e-12)
    assert math.sqrt(var) == pytest.approx(0.3, rel=1e-11)
    assert moment(dist, lambda S: (S - mean) ** 3) / var ** 1.5 == pytest.approx(skewness, abs=1e-10)
    # bounded above: nothing above the highest asperity
    assert dist.pdf(dist.top + 1e-12) == 0 and dist.bottom == -math.inf


def test_weibull_shapes_and_range():
    """Zero skewness is k = 3.60 with the top 3.24 rms up; -2 the exponential; 0.5 the cap, 6.34 rms up."""
    w = Weibull(1.0, 0.0)
    assert w.shape == pytest.approx(3.6023, abs=1e-4) and w.top == pytest.approx(3.24, abs=0.01)
    assert Weibull(1.0, -2.0).shape == 1.0
    assert Weibull(1.0, 0.5).top == pytest.approx(6.34, abs=0.01)
    for bad in (-2.1, 0.6):
        with pytest.raises(ValueError, match="skewness"):
            Weibull(1.0, bad)
    with pytest.raises(ValueError, match="cutoff"):
        TruncatedGaussian(1.0, 0.0)
    assert set(DISTRIBUTIONS) == {"truncated_gaussian", "weibull", "lognormal", "measured"}


# -- the wall quadrature ------------------------------------------------------------

#: (distribution, d / rms): the moving rule is sized for d >= 1e-5 rms.
CASES = [(TruncatedGaussian(1.0, 3.0), 1e-5), (TruncatedGaussian(1.0, 3.0), 1e-3), (TruncatedGaussian(1.0, 3.0), 0.3),
         (TruncatedGaussian(1.0, 3.0), 30.0), (TruncatedGaussian(0.2, 6.0), 1e-4), (TruncatedGaussian(0.2, 6.0), 0.3),
         (Weibull(1.0, -1.7), 1e-5), (Weibull(1.0, -1.7), 0.03), (Weibull(1.0, 0.0), 1e-4), (Weibull(1.0, 0.0), 1.0),
         (Weibull(0.5, 0.5), 1e-3), (Weibull(0.5, 0.5), 3.0)]


def case_id(case) -> str:
    dist, dr = case
    shape = f"K{dist.cutoff:g}" if dist.name == "truncated_gaussian" else f"skew{dist.skewness:g}"
    return f"{dist.name}-{shape}-d{dr:g}rms"


@pytest.mark.parametrize("dist,dr", CASES, ids=[case_id(c) for c in CASES])
def test_quadrature_converges(dist, dr):
    """E[g^-k] for the law (k = 3, 9) and its derivative (k = 4, 10) converges as the rule is refined.

    Against quad on the density; the default rule (24 moving points, 16 per fixed
    panel) is within 1e-10 relative, at the wall (d = 1e-5 rms) as far from it.
    """
    d = dr * dist.rms
    rules = [WallQuadrature(dist, n, m) for n, m in ((8, 6), (16, 11), (24, 16))]
    for k in (3, 4, 9, 10):
        ref = reference(dist, d, k)
        errs = [abs(rule_average(r, d, k) / ref - 1) for r in rules]
        # down to the accuracy of the reference, about 1e-12
        assert errs[1] <= max(errs[0], 2e-11) and errs[2] <= max(errs[1], 2e-11), (k, errs)
        assert errs[2] < 1e-10, (k, errs)


@pytest.mark.parametrize("dist", [TruncatedGaussian(1.0, 3.0), Weibull(1.0, -2.0), Weibull(1.0, 0.5)],
                         ids=lambda d: d.name)
def test_quadrature_keeps_the_mass(dist):
    """f = 1: the moving and the fixed parts add up to the whole weight for any d."""
    rule = WallQuadrature(dist)
    d = np.geomspace(1e-6, 1e6, 13)
    g, w = rule.near(d)
    assert np.allclose(w.sum(axis=1) + rule.weights.sum(), 1.0, rtol=0, atol=1e-12)
    # the moving nodes sit between the wall and the fixed ones
    assert np.all(g > d[:, None]) and np.all(g < d[:, None] + dist.near_width)


# -- measured heights ---------------------------------------------------------------

def test_measured_histogram():
    """Zero mean, the sample rms, the highest sample as the wall, a normalised density."""
    rng = np.random.default_rng(3)
    S = 2.0 + 0.4 * rng.standard_normal(20000)
    m = Measured(S)
    assert m.samples == S.size and m.rms == pytest.approx(S.std(), rel=1e-12)
    assert m.top == pytest.approx(S.max() - S.mean(), rel=1e-12) and m.edges[-1] == m.top
    assert np.sum(m.density * np.diff(m.edges)) == pytest.approx(1.0, rel=1e-12)
    assert m.pdf(m.top) == m.density[-1] > 0 and m.pdf(m.top + 1e-9) == 0
    assert 10 < m.density.size <= Measured.MAX_BINS
    assert Measured(S, bins=7).density.size == 7


def write_gsf(path, Z, header: str = "ZUnits = nm\n"):
    """A Gwyddion Simple Field file: magic line, header, 1-4 NULs to a multiple of 4, float32 LE data."""
    head = f"Gwyddion Simple Field 1.0\nXRes = {Z.shape[1]}\nYRes = {Z.shape[0]}\n{header}".encode()
    head += b"\0" * (4 - len(head) % 4)
    path.write_bytes(head + np.asarray(Z, dtype="<f4").tobytes())


def tilted(shape, rough):
    """A tilted plane plus roughness: levelling must give the roughness back (minus its own plane)."""
    i, j = np.indices(shape)
    return 5.0 + 0.3 * i - 0.2 * j + rough


def levelled(Z):
    """Z minus its least-squares plane, by lstsq on the pixel indices."""
    i, j = np.indices(Z.shape)
    A = np.column_stack([np.ones(Z.size), i.ravel(), j.ravel()])
    return Z.ravel() - A @ np.linalg.lstsq(A, Z.ravel(), rcond=None)[0]


def test_read_list_of_heights(tmp_path):
    """One height per line, units of epsilon, comments and blank lines skipped; the list as read."""
    p = tmp_path / "h.txt"
    p.write_text("# heights\n0.5\n\n-0.25\n1e-1\n")
    assert np.array_equal(read_heights(p), [0.5, -0.25, 0.1])
    m = Measured(read_heights(p))
    assert m.rms == pytest.approx(np.std([0.5, -0.25, 0.1]), rel=1e-14)


def test_read_gwyddion_matrix_levels_and_converts(tmp_path):
    """Gwyddion ASCII export: '# Value units: m' and epsilon give units of epsilon; the plane goes."""
    rng = np.random.default_rng(4)
    rough = 1e-9 * rng.standard_normal((30, 40))
    Z = tilted(rough.shape, 0) * 1e-9 + rough
    p = tmp_path / "map.txt"
    with open(p, "w") as f:
        f.write("# Channel: Height\n# Width: 5.000 \u00b5m\n# Height: 3.750 \u00b5m\n# Value units: m\n")
        np.savetxt(f, Z, delimiter="\t")
    S = read_heights(p, epsilon=0.5e-9)
    assert np.allclose(S, levelled(rough) / 0.5e-9, rtol=0, atol=1e-9)
    with pytest.raises(HeightFileError, match="epsilon"):
        read_heights(p)


def test_read_npy_and_gsf(tmp_path):
    """.npy: a list in units of epsilon, or a map with a unit; .gsf: ZUnits from the header."""
    rng = np.random.default_rng(5)
    rough = rng.standard_normal((16, 24))
    np.save(tmp_path / "list.npy", rough[0])
    assert np.array_equal(read_heights(tmp_path / "list.npy"), rough[0])
    np.save(tmp_path / "map.npy", tilted(rough.shape, rough))
    S = read_heights(tmp_path / "map.npy", epsilon=2e-10, unit=1e-9)
    assert np.allclose(S, 5 * levelled(rough), rtol=0, atol=1e-12)
    write_gsf(tmp_path / "map.gsf", tilted(rough.shape, rough))
    G = read_heights(tmp_path / "map.gsf", epsilon=2e-10)
    assert np.allclose(G, S, rtol=0, atol=5 * 1e-6)  # float32 data of size ~10
    write_gsf(tmp_path / "plain.gsf", rough, header="Title = no unit\n")
    assert np.allclose(read_heights(tmp_path / "plain.gsf"), levelled(rough.astype("<f4").astype(float)), atol=1e-12)


def _bytes(data):
    return lambda p: p.write_bytes(data)


def _text(data):
    return lambda p: p.write_text(data)


BAD = {
    "empty": ("h.txt", _text(""), "no heights"),
    "only comments": ("h.txt", _text("# nothing\n\n"), "no heights"),
    "non-numeric": ("h.txt", _text("0.1\n0.2\nabc\n"), "line 3: 'abc' is not a number"),
    "nan": ("h.txt", _text("0.1\nnan\n0.3\n"), "1 of 3 heights are not finite"),
    "inf": ("h.txt", _text("0.1\ninf\n"), "not finite"),
    "one value": ("h.txt", _text("0.1\n"), "all heights are equal"),
    "flat": ("h.txt", _text("0.2\n0.2\n0.2\n"), "all heights are equal"),
    "ragged": ("h.txt", _text("1 2 3\n4 5\n"), "line 2 has 2 values, the first row 3"),
    "one row": ("h.txt", _text("1 2 3\n"), "one row is no map"),
    "binary": ("h.txt", _bytes(b"\x89PNG\r\n\x1a\n\x00\x00"), "is not a number"),
    "unit not a length": ("h.txt", _text("# Value units: V\n1\n2\n"), "'V' is not a length"),
    "plane map": ("h.txt", _text("1 2 3\n2 3 4\n3 4 5\n"), "the map is a plane"),
    "gsf magic": ("h.gsf", _bytes(b"Gwyddion Simple Field 2.0\nXRes = 2\n\0\0"), "no magic line"),
    "gsf size": ("h.gsf", lambda p: p.write_bytes(
        b"Gwyddion Simple Field 1.0\nXRes = 3\nYRes = 3\n\0\0\0" + np.zeros(8, "<f4").tobytes()),
        "31 bytes of data for 3 x 3"),
    "gsf header": ("h.gsf", _bytes(b"Gwyddion Simple Field 1.0\nXRes = x\n\0\0\0\0"), "XRes and YRes"),
    "npy 3-D": ("h.npy", lambda p: np.save(p, np.zeros((2, 2, 2))), "3-D"),
    "npy complex": ("h.npy", lambda p: np.save(p, np.ones(3) * 1j), "complex"),
    "npy garbage": ("h.npy", _text("1\n2\n"), "not a NumPy array file"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_height_files(tmp_path, case):
    """Each bad file: HeightFileError (a ValueError), one line, naming the file and what is wrong."""
    name, write, what = BAD[case]
    write(tmp_path / name)
    with pytest.raises(ValueError) as e:
        read_heights(tmp_path / name)
    assert isinstance(e.value, HeightFileError)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"'{name}': ") and what in msg, msg


def test_unreadable_and_unit_conflicts(tmp_path):
    for path, what in ((tmp_path / "missing.txt", "No such file"), (tmp_path, "Is a directory")):
        with pytest.raises(HeightFileError, match=what):
            read_heights(path)
    p = tmp_path / "m.txt"
    p.write_text("# Value units: nm\n1\n2\n")
    with pytest.raises(HeightFileError, match="states its unit"):
        read_heights(p, epsilon=1e-10, unit=1e-9)
    assert np.allclose(read_heights(p, epsilon=0.5e-9), [2.0, 4.0])
    u = tmp_path / "u.txt"
    u.write_text("1\n2\n")
    with pytest.raises(HeightFileError, match="unit must be a length"):
        read_heights(u, epsilon=1e-10, unit=-1.0)
