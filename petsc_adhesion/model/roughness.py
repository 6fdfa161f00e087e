"""Roughness heights bounded above, and the quadrature of averages over them.

The pressure of paper eq. (7) and (10) is the average of the Lennard-Jones law over
the roughness heights S (units of epsilon, from the mean plane).  With the Gaussian
of eq. (3) (weight exp(-S^2/(2 sigma^2)), docs/model.md, paper note 1) that average diverges:
heights above H + 1 close the gap, and (H + 1 - S)^-9 is not integrable there.  It
exists for every H above a wall only when the heights are bounded above, by the
highest asperity S_max (:attr:`top` of each distribution); the gap to it,
d = H + 1 - S_max > 0, then sets how singular the integrand is.

With u = S_max - S the depth below the highest asperity and q(u) its density,

    E[f(H + 1 - S)] = integral_0^U q(u) f(d + u) du,

and f ~ g^-9 gathers the integral on u ~ d: a rule fixed in S loses accuracy as d
falls.  :class:`WallQuadrature` splits the depths at a width b of the distribution.
On [0, b] its nodes move with d: u = d (e^v - 1), Gauss in v in [0, log(1 + b/d)],
where g^-k du = d^(1-k) e^((1-k) v) dv is smooth for every d (Gauss-Jacobi when
q ~ u^beta at the top).  On [b, U] they are fixed: Gauss panels in log u next to the
top, where the poles of (d + u)^-k sit at Im log u = +-pi whatever d >= 0, and in a
variable of the distribution in the bulk.  It averages f and f' alike, to about
1e-11 relative for d from 1e-5 rms to infinity (tests/test_roughness.py).

Families, by name (:data:`DISTRIBUTIONS`):

``truncated_gaussian``
    eq. (3) cut at +-K sigma (:class:`TruncatedGaussian`);
``weibull``
    reversed Weibull heights, skewed and bounded above by construction (:class:`Weibull`);
``lognormal``
    heights whose depth below the highest asperity is lognormal (:class:`Lognormal`), the
    distribution the paper suggests, its long tail in the valleys;
``measured``
    the histogram of heights read from a file (:class:`Measured`, :func:`read_heights`),
    averaged exactly by ``pressure.HistogramLaw``.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import gamma, roots_jacobi

from .. import brent
from .heights import HeightFileError, _check

__all__ = ["TruncatedGaussian", "Weibull", "Lognormal", "Measured", "WallQuadrature", "DISTRIBUTIONS", "NEAR_POINTS", "PANEL_POINTS", "panel_points", "distribution"]

#: Points of the moving rule on [0, b]: relative error below 1e-11 while b/d <= 5e3.
NEAR_POINTS = 24
#: Points of each fixed panel on [b, U].
PANEL_POINTS = 16


def panel_points(near_points: int) -> int:
    """Points of each fixed panel for a moving rule of ``near_points``: in the ratio of the defaults."""
    return max(2, -(-near_points * PANEL_POINTS // NEAR_POINTS))


def _gauss(n: int, lo: float, hi: float, log: bool) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights for integral_lo^hi du, in the variable log u when ``log``."""
    x, w = np.polynomial.legendre.leggauss(n)
    if not log:
        return lo + (hi - lo) * (x + 1) / 2, w * (hi - lo) / 2
    a, b = math.log(lo), math.log(hi)
    u = np.exp(a + (b - a) * (x + 1) / 2)
    return u, w * (b - a) / 2 * u


def _panels(edges, n: int, log: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Composite Gauss-Legendre rule on the panels between consecutive ``edges``."""
    parts = [_gauss(n, lo, hi, log) for lo, hi in zip(edges[:-1], edges[1:])]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


class TruncatedGaussian:
    """Gaussian heights (paper eq. 3) cut symmetrically at +-K sigma and renormalised.

    Only the upper cut is needed for a finite average: the lower tail never closes a
    gap.  Both tails are cut so that the heights keep zero mean and no odd moments,
    H stays the separation of the mean planes of eq. (6), and the surface has a
    deepest valley as it has a highest asperity; the lower cut removes the weight
    (0.13 % at K = 3) where the gaps are largest and the law weakest.

    Parameters
    ----------
    sigma
        Standard deviation of the untruncated Gaussian (units of epsilon).  The rms of
        the heights, :attr:`rms`, is slightly smaller (0.987 sigma at K = 3).
    cutoff
        K, in (0, 10]: the highest asperity is at K sigma, the wall of the pressure law
        at H = K sigma - 1.
    """

    name = "truncated_gaussian"
    skewness = 0.0
    wall_exponent = 0.0

    def __init__(self, sigma: float, cutoff: float = 3.0):
        if not (math.isfinite(sigma) and sigma >= 0):
            raise ValueError(f"sigma must be finite and >= 0, got {sigma:g}")
        if not 0 < cutoff <= 10:
            raise ValueError(f"the cutoff K must lie in (0, 10], got {cutoff:g}")
        self.sigma, self.cutoff = float(sigma), float(cutoff)
        K = self.cutoff
        self._mass = math.erf(K / math.sqrt(2))
        self.rms = self.sigma * math.sqrt(_truncated_variance(K))
        self.top, self.bottom = K * self.sigma, -K * self.sigma
        self.near_width = self.rms / 20

    def pdf(self, S: np.ndarray) -> np.ndarray:
        """Density exp(-S^2/(2 sigma^2)) / (sqrt(2 pi) sigma erf(K/sqrt 2)) on |S| <= K sigma, 0 outside."""
        S = np.asarray(S, dtype=float)
        return np.where(np.abs(S) <= self.top, self._gauss(S / self.sigma), 0.0)

    def depth_pdf(self, u: np.ndarray) -> np.ndarray:
        """Density q(u) of the depth u = S_max - S, 0 <= u <= 2 K sigma."""
        return self._gauss(self.cutoff - u / self.sigma)

    def _gauss(self, z):
        return np.exp(-0.5 * z * z) / (math.sqrt(2 * math.pi) * self.sigma * self._mass)

    def far_rule(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Fixed depths in [b, 2 K sigma] and their weights (density included).

        One panel in log u from b = rms/20 to sigma (where the moving part ends and the
        Gaussian starts to vary), then panels of at most 6 sigma in u, n points each.
        """
        b, U = self.near_width, 2 * self.top
        c = min(self.sigma, U)
        u, w = _gauss(n, b, c, log=True)
        if U > c:
            ul, wl = _panels(np.linspace(c, U, math.ceil((U - c) / (6 * self.sigma)) + 1), n)
            u, w = np.concatenate([u, ul]), np.concatenate([w, wl])
        return u, w * self.depth_pdf(u)


def _truncated_variance(K: float) -> float:
    """The variance of the standard normal truncated to [-K, K]: 1 - 2 K phi(K) / (2 Phi(K) - 1).

    Below K = 0.5 that difference cancels (it tends to K^2 / 3, a math domain error below
    K = 1e-8): there the ratio of the two moments' Taylor series, which has no cancellation.

    >>> round(_truncated_variance(3.0), 6), round(_truncated_variance(1e-9) / 1e-18, 12)
    (0.973337, 0.333333333333)
    """
    if K >= 0.5:
        return 1 - 2 * K * math.exp(-K * K / 2) / (math.sqrt(2 * math.pi) * math.erf(K / math.sqrt(2)))
    # integral_0^K z^2 e^(-z^2/2) dz / integral_0^K e^(-z^2/2) dz, term by term
    num = den = 0.0
    term = 1.0                      # (-1/2)^n / n!
    for n in range(30):
        num += term * K ** (2 * n + 3) / (2 * n + 3)
        den += term * K ** (2 * n + 1) / (2 * n + 1)
        term *= -0.5 / (n + 1)
    return num / den


class Weibull:
    """Reversed Weibull heights: S = S_max - W, W Weibull of shape k and scale lambda.

    Bounded above by construction (the Weibull law of maxima), so no cut-off is
    needed: the highest asperity, S_max = lambda Gamma(1 + 1/k), is where the mean
    is zero.  The density falls to zero at the top like (S_max - S)^(k-1) and has an
    exponential tail of valleys.  The shape follows from the skewness: -2 is k = 1
    (exponential depths, density finite at the top), 0 is k = 3.60 with
    S_max = 3.24 rms, 0.5 is k = 7.49 with S_max = 6.34 rms.  Beyond 0.59 (k > 9) the
    repulsion would stay finite at the wall, so the skewness is capped at 0.5.

    Parameters
    ----------
    sigma
        Root mean square height (units of epsilon).
    skewness
        Third standardised moment of the heights, in [-2, 0.5].
    """

    name = "weibull"
    SKEWNESS = (-2.0, 0.5)

    def __init__(self, sigma: float, skewness: float = 0.0):
        if not (math.isfinite(sigma) and sigma >= 0):
            raise ValueError(f"sigma must be finite and >= 0, got {sigma:g}")
        lo, hi = self.SKEWNESS
        if not lo <= skewness <= hi:
            raise ValueError(f"the skewness of weibull heights must lie in [{lo:g}, {hi:g}], got {skewness:g}")
        self.sigma = self.rms = float(sigma)
        self.skewness = float(skewness)
        self.shape = k = 1.0 if skewness == lo else brent.root(lambda k: _skewness(k) - skewness, 1.0, 9.0, xtol=1e-14)
        g1, g2 = gamma(1 + 1 / k), gamma(1 + 2 / k)
        self.scale = lam = self.sigma / math.sqrt(g2 - g1 * g1)
        self.top, self.bottom = lam * g1, -math.inf
        self.wall_exponent = k - 1
        # Within the top 1e-6 of the weight e^-z = 1 - z + ..., z = (u/lambda)^k < 1e-6: the
        # terms u^(k-1+jk) that no Jacobi rule in v integrates exactly weigh 1e-6 at most.
        self.near_width = min(self.sigma / 20, lam * 1e-6 ** (1 / k))

    def pdf(self, S: np.ndarray) -> np.ndarray:
        """Density (k/lambda) (u/lambda)^(k-1) exp(-(u/lambda)^k) at depth u = S_max - S >= 0, 0 above."""
        u = self.top - np.asarray(S, dtype=float)
        top = self.shape / self.scale if self.shape == 1 else 0.0
        return np.where(u > 0, self.depth_pdf(np.where(u > 0, u, 1.0)), np.where(u == 0, top, 0.0))

    def depth_pdf(self, u: np.ndarray) -> np.ndarray:
        """Density q(u) of the depth u > 0 below the highest asperity."""
        a = u / self.scale
        z = a ** self.shape
        return (self.shape / self.scale) * (z / a) * np.exp(-z)

    def far_rule(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Fixed depths in [b, inf) and their weights (density included).

        In s = log z, z = (u/lambda)^k, the weight is e^(s - e^s) ds and the gap
        d + lambda e^(s/k): both analytic in a strip whatever d.  One panel of 3 in s
        over the bulk of the weight (z from 1.84 to 37), then panels of min(6, 3k),
        i.e. at most 3 in log u, down to b; n points each.  The tail z > 37 holds
        1e-16 of the weight and is left out.
        """
        k, lam = self.shape, self.scale
        lo, step = k * math.log(self.near_width / lam), min(6.0, 3 * k)
        edges = [math.log(37.0), math.log(37.0) - 3]
        while edges[-1] - step > lo + step / 4:
            edges.append(edges[-1] - step)
        s, w = _panels([lo] + edges[::-1], n)
        z = np.exp(s)
        return lam * z ** (1 / k), w * z * np.exp(-z)


def _skewness(k: float) -> float:
    """Skewness of -W, W Weibull of shape k."""
    g1, g2, g3 = gamma(1 + 1 / k), gamma(1 + 2 / k), gamma(1 + 3 / k)
    return -(g3 - 3 * g1 * g2 + 2 * g1 ** 3) / (g2 - g1 * g1) ** 1.5


class Lognormal:
    """Heights whose depth below the highest asperity is lognormal: S = S_max - W, log W ~ N(m, s^2).

    The paper suggests a lognormal height distribution.  A lognormal is bounded on one
    side only, and the side decides whether the average of eq. (7) exists: with the
    long tail upwards (S = W - c) some heights close any gap and the average diverges
    as the Gaussian's does; with the tail downwards, into the valleys, the heights are
    bounded above by S_max = E[W] (zero mean) and the average converges.  We take the
    second: a surface of plateaus and deep valleys, skewness negative.  The density
    vanishes at the top faster than any power of the depth, so the repulsion stays
    finite at the wall itself, P(wall) = E[W^-9] - E[W^-3] = e^(-9 m + 81 s^2/2) -
    e^(-3 m + 9 s^2/2) (:attr:`wall_pressure`); the law refuses H at or below the wall
    all the same (a state there would put the highest asperity through the other
    surface).  So a lognormal surface carries no pressure above P(wall): a curve that
    needs more ends there, and where P(wall) <= 0 (at sigma = 0.2 a skewness above
    -0.6, at sigma = 1 above -1.2) the heights cannot even hold the surfaces apart
    against their attraction, and the option reader refuses them.

    The moments: Var W = (e^(s^2) - 1) e^(2 m + s^2) = rms^2 and skewness
    -(e^(s^2) + 2) sqrt(e^(s^2) - 1), which fixes s; then S_max = rms / sqrt(e^(s^2) - 1)
    (3.10 rms at skewness -1, 12.0 rms at -0.25, 1.00 rms at -4: as the skewness goes to 0 the law
    becomes the Gaussian, with no highest asperity).

    In t = log W the weight is the Gaussian phi((t - m)/s)/s dt and the gap d + e^t is
    analytic in the strip |Im t| < pi whatever d >= 0: Gauss panels in t, fixed, serve
    every d including the wall (no moving part, :attr:`near_width` 0).

    Parameters
    ----------
    sigma
        Root mean square height (units of epsilon).
    skewness
        Third standardised moment of the heights, in :attr:`SKEWNESS`.
    """

    name = "lognormal"
    SKEWNESS = (-4.0, -0.25)
    wall_exponent = 0.0
    near_width = 0.0

    def __init__(self, sigma: float, skewness: float = -1.0):
        if not (math.isfinite(sigma) and sigma >= 0):
            raise ValueError(f"sigma must be finite and >= 0, got {sigma:g}")
        lo, hi = self.SKEWNESS
        if not lo <= skewness <= hi:
            raise ValueError(f"the skewness of lognormal heights must lie in [{lo:g}, {hi:g}], got {skewness:g}")
        self.sigma = self.rms = float(sigma)
        self.skewness = float(skewness)
        self.shape = s = brent.root(lambda s: _lognormal_skewness(s) + skewness, 1e-3, 3.0, xtol=1e-15)
        spread = math.expm1(s * s)
        self.top, self.bottom = self.sigma / math.sqrt(spread), -math.inf
        self.log_median = math.log(self.top) - s * s / 2 if self.sigma > 0 else -math.inf

    @property
    def wall_pressure(self) -> float:
        """The repulsion at the wall, E[W^-9] - E[W^-3] = e^(-9 m + 81 s^2/2) - e^(-3 m + 9 s^2/2) (inf when smooth).

        Finite: no state is compressed harder than this.  Not positive (the highest asperity
        more than about 1.2 epsilon above the few at small depths: large rms, small skewness)
        it does not even hold the surfaces apart against their attraction.
        """
        if self.sigma == 0:
            return math.inf
        m, s = self.log_median, self.shape
        return math.exp(-9 * m + 40.5 * s * s) - math.exp(-3 * m + 4.5 * s * s)

    def pdf(self, S: np.ndarray) -> np.ndarray:
        """Density of the heights: the lognormal density of the depth u = S_max - S > 0, 0 at and above the top."""
        u = self.top - np.asarray(S, dtype=float)
        return np.where(u > 0, self.depth_pdf(np.where(u > 0, u, 1.0)), 0.0)

    def depth_pdf(self, u: np.ndarray) -> np.ndarray:
        """Density q(u) = exp(-(log u - m)^2 / (2 s^2)) / (u s sqrt(2 pi)) of the depth u > 0."""
        z = (np.log(u) - self.log_median) / self.shape
        return np.exp(-0.5 * z * z) / (u * self.shape * math.sqrt(2 * math.pi))

    def far_rule(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Depths e^t and their weights (density included), Gauss panels of at most min(2 s, 1) in t.

        From t = m - 9 s^2 - 9 s, 9 s below where (d + e^t)^-9 phi peaks at the wall
        (t = m - 9 s^2), to m + 9 s: the weight left out is below 1e-18 of P for every
        d >= 0.  The panels resolve the weight (width s) and the gap (strip pi) alike.
        """
        m, s = self.log_median, self.shape
        lo, hi = m - 9 * s * s - 9 * s, m + 9 * s
        t, w = _panels(np.linspace(lo, hi, math.ceil((hi - lo) / min(2 * s, 1.0)) + 1), n)
        z = (t - m) / s
        return np.exp(t), w * np.exp(-0.5 * z * z) / (s * math.sqrt(2 * math.pi))


def _lognormal_skewness(s: float) -> float:
    """Skewness (e^(s^2) + 2) sqrt(e^(s^2) - 1) of a lognormal of log-spread s."""
    x = math.expm1(s * s)
    return (x + 3) * math.sqrt(x)


class WallQuadrature:
    """Rule for E[f(d + u)] over the depth u below the highest asperity, f ~ g^-k at g = 0.

    Moving part on [0, b], b = ``dist.near_width``: u = d (e^v - 1), v in
    [0, log(1 + b/d)], Gauss-Jacobi with weight v^beta for q ~ u^beta at the top
    (beta = ``dist.wall_exponent``; Gauss-Legendre for beta = 0).  Fixed part on
    [b, U]: ``dist.far_rule``.  A rule for gaps g = d + u, so it serves the
    Lennard-Jones law and its derivative with the same accuracy.

    Parameters
    ----------
    dist
        Has ``near_width``, ``wall_exponent``, ``depth_pdf`` and ``far_rule``.
    near_points, panel_points
        Points of the moving rule and of each fixed panel.

    Attributes
    ----------
    depths, weights
        Depths u_l and weights of the fixed part (density included).
    near_points, size
        Points of the moving part, and in all, per node.
    """

    def __init__(self, dist, near_points: int = NEAR_POINTS, panel_points: int = PANEL_POINTS):
        self.near_width, self.beta = dist.near_width, dist.wall_exponent
        if self.near_width == 0:        # a density that vanishes faster than any power at the top: no moving part
            near_points = 0
        x, w = roots_jacobi(near_points, 0.0, self.beta) if near_points else (np.zeros(0), np.zeros(0))
        # the rule on [0, V] is V^(1+beta) sum w_i phi(V t_i) with phi = q g / v^beta, v^beta = V^beta t^beta
        self._t = (1 + x) / 2
        self._w = w / 2 ** (1 + self.beta) / self._t ** self.beta
        self._pdf = dist.depth_pdf
        self.depths, self.weights = dist.far_rule(panel_points)
        self.near_points, self.size = near_points, near_points + self.depths.size

    def near(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Gaps d + u and weights of the moving part, each (len(d), near_points), for d > 0."""
        d = d[:, None]
        V = np.log1p(self.near_width / d)
        v = V * self._t
        u = d * np.expm1(v)
        g = d + u
        return g, self._w * V * self._pdf(u) * g


#: The smallest rms of measured heights (units of epsilon).  The histogram's exact average sums terms of
#: the size of the density's jumps, about bins / rms, whose rounding grows as 1 / rms: at rms = 1e-4 it
#: is 5e-11 of P, at 1e-6 already 5e-9, more than the roughness changes P (about rms^2), and Newton
#: stalls on that noise (1e-11 to 5e-8).  Below it the heights are smooth to the model.
SMALLEST_RMS = 1e-4


class Measured:
    """Measured heights, averaged through their histogram.

    The heights are shifted to zero mean (S from the mean plane, as in eq. 6).  Their
    histogram, equal bins from the lowest to the highest sample, is the density: the
    highest measured height is the highest asperity and sets the wall, and the
    average of the Lennard-Jones law over a piecewise-constant density is exact in
    closed form at one term per bin edge, however many samples.  Binning moves the
    average by O(w^2) away from the wall (w the bin width; the variance by w^2/12),
    below the sampling error of a map; near the wall the law is that of the top
    bins, i.e. of the few highest samples, and a spike in the data is a wall.

    Parameters
    ----------
    heights
        Heights in units of epsilon, any shape.
    bins
        Number of bins; default Freedman-Diaconis, at most :attr:`MAX_BINS`.
    weights
        The probability of each height (a distribution given on points, e.g. the gap's
        convolution of two surfaces, :func:`~.topography.gap_heights`); None: equal.
    """

    name = "measured"
    MAX_BINS = 128

    def __init__(self, heights: np.ndarray, bins: int | None = None, weights: np.ndarray | None = None):
        S = np.asarray(heights, dtype=float).ravel()
        _check(S, "heights")
        w = np.full(S.size, 1.0 / S.size) if weights is None else np.asarray(weights, dtype=float).ravel()
        if w.shape != S.shape or not np.all(w > 0) or not np.isfinite(w.sum()):
            raise ValueError("weights: one positive weight a height")
        w = w / w.sum()
        S = S - w @ S
        self.samples = S.size
        self.rms = self.sigma = float(np.sqrt(w @ (S * S)))
        if not self.rms >= SMALLEST_RMS:
            raise HeightFileError(f"heights: rms {self.rms:.3g} epsilon, below {SMALLEST_RMS:g}: the histogram's average "
                                  f"would round to more than the roughness changes (a smooth surface: -adh_roughness none)")
        self.skewness = float(w @ S ** 3) / self.rms ** 3
        self.top, self.bottom = float(S.max()), float(S.min())
        if bins is None and weights is None:
            bins = min(np.histogram_bin_edges(S, "fd").size - 1, self.MAX_BINS)
        elif bins is None:          # Freedman-Diaconis on the weighted quartiles
            order = np.argsort(S)
            q1, q3 = np.interp([0.25, 0.75], np.cumsum(w[order]), S[order])
            width = 2 * (q3 - q1) / S.size ** (1 / 3)
            bins = self.MAX_BINS if width <= 0 else int(min(self.MAX_BINS, max(1, math.ceil((self.top - self.bottom)
                                                                                            / width))))
        if not (isinstance(bins, (int, np.integer)) and bins >= 1):
            raise ValueError(f"bins must be an integer >= 1, got {bins}")
        self.edges = np.linspace(self.bottom, self.top, bins + 1)
        mass, _ = np.histogram(S, self.edges, weights=w)
        self.density = mass / np.diff(self.edges)

    def pdf(self, S: np.ndarray) -> np.ndarray:
        """The histogram density (the top edge belongs to the top bin)."""
        S = np.asarray(S, dtype=float)
        j = np.clip(np.searchsorted(self.edges, S, side="right") - 1, 0, self.density.size - 1)
        return np.where((S >= self.bottom) & (S <= self.top), self.density[j], 0.0)


#: The distributions of -adh_roughness bounded above, by name.
DISTRIBUTIONS = (TruncatedGaussian.name, Weibull.name, Lognormal.name, Measured.name)


def distribution(model):
    """The height distribution of ``model`` (its ``roughness`` one of :data:`DISTRIBUTIONS`)."""
    if model.roughness == Measured.name:
        return Measured(model.heights, weights=model.height_weights)
    if model.roughness == Weibull.name:
        return Weibull(model.sigma, model.roughness_skewness)
    if model.roughness == Lognormal.name:
        return Lognormal(model.sigma, model.lognormal_skewness)
    return TruncatedGaussian(model.sigma, model.roughness_cutoff)
