"""The Lennard-Jones pressure law and its roughness average (paper eq. 5, 7, 10, 13-14).

P > 0 is repulsion.  In units of 8 gamma / (3 epsilon) the law of a gap g (units of
epsilon) is sigma_LJ(g) = g^-9 - g^-3 (eq. 5), and the pressure at mean separation H
is its average over the roughness heights S, P(H) = E[sigma_LJ(H + 1 - S)] (eq. 7, 10).

Every law below is called on an array of nodal H and returns (P, dP/dH), and has

``wall``
    the H at or below which some gap closes; the law raises FloatingPointError there;
``smooth``
    True when there is no roughness (sigma = 0): eq. (5), no quadrature;
``n``
    points per node; ``rule`` its name; ``sigma`` the rms of the heights;
``error(H)``
    an estimate of the quadrature error of P.

:class:`PressureLaw` is the paper's model: Gaussian heights and the n-point
Gauss-Hermite rule of eq. (14).  The continuous Gaussian average diverges, so that
rule is part of the model, its outermost node is a hard wall (every gap
H - sqrt(2) sigma x_l + 1 must stay positive) and its ``shifts`` and ``weights`` say
where.  :class:`WallLaw` and :class:`HistogramLaw` average over height
distributions bounded above (:mod:`.roughness`), whose averages converge: their
wall is the highest asperity, and their quadrature error is controlled.
"""
from __future__ import annotations

import math

import numpy as np

from .parameters import Model
from .roughness import NEAR_POINTS, Measured, WallQuadrature, distribution, panel_points

__all__ = ["lennard_jones", "PressureLaw", "WallLaw", "HistogramLaw", "law_for", "pressure_law", "curvature", "sigma_rates",
           "RULES", "TEMPORARY", "STEP"]

#: Doubles per (nodes x points) temporary: 96 KiB stays below glibc's 128 KiB mmap threshold,
#: above which every temporary is a fresh mapping whose page faults cost more than the arithmetic.
TEMPORARY = 12288


def lennard_jones(g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sigma_LJ(g) = g^-9 - g^-3 (eq. 5, P > 0 repulsion) and its derivative 3 g^-4 - 9 g^-10."""
    g3 = 1.0 / (g * g * g)
    g9 = g3 * g3 * g3
    return g9 - g3, (3.0 * g3 - 9.0 * g9) / g


def _blocks(f, H: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """f applied to equal blocks of H with at most TEMPORARY // width nodes, results joined."""
    blocks = -(-H.size * width // TEMPORARY)
    if blocks <= 1:
        return f(H)
    parts = [f(h) for h in np.array_split(H, blocks)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _refuse_closed(gaps: np.ndarray, H: np.ndarray | None = None, wall: float = -math.inf) -> None:
    """FloatingPointError when a gap is closed, or (when given) H is at or below the wall.

    H + 1 - S_max may round to a positive gap at H = wall, hence the second test.
    """
    if np.any(gaps <= 0.0) or (H is not None and np.any(H <= wall)):
        raise FloatingPointError("separation below the wall of the roughness law")


def _smooth(sigma: float, n: int):
    return np.zeros(1), np.ones(1)


def _hermite(sigma: float, n: int):
    x, w = np.polynomial.hermite.hermgauss(n)
    return math.sqrt(2.0) * sigma * x, w / math.sqrt(math.pi)


#: Rules of :class:`PressureLaw`: name -> (sigma, n) -> (height shifts S_l, normalised weights).
RULES = {"none": _smooth, "hermite": _hermite}


class PressureLaw:
    """P(H) and dP/dH of Gaussian heights by the Gauss-Hermite rule of eq. (14).

    Parameters
    ----------
    sigma
        Standard deviation of the roughness heights (units of epsilon).
    rule
        Key of :data:`RULES`. ``sigma = 0`` always takes the smooth path.
    n
        Points of the rule.
    """

    def __init__(self, sigma: float = 0.0, rule: str = Model.roughness, n: int = Model.hermite_points):
        if sigma == 0.0:
            rule = "none"
        self.sigma, self.rule, self.n = sigma, rule, (1 if rule == "none" else n)
        self.shifts, self.weights = RULES[rule](sigma, n)
        self.smooth = rule == "none"

    @property
    def wall(self) -> float:
        """H below which a gap of the rule closes: max_l sqrt(2) sigma x_l - 1."""
        return float(self.shifts.max()) - 1.0

    def gaps(self, H: np.ndarray) -> np.ndarray:
        """Gaps H - S_l + 1, shape (len(H), n) (or (len(H),) when smooth)."""
        return H + 1.0 if self.smooth else np.subtract.outer(H + 1.0, self.shifts)

    def __call__(self, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return P(H) (eq. 14; eq. 5 when smooth) and its exact derivative dP/dH."""
        # in one piece, as before: blocks would change the BLAS row sums in the last bit
        g = self.gaps(H)
        _refuse_closed(g, H, self.wall)
        p, dp = lennard_jones(g)
        if self.smooth:
            return p, dp
        return p @ self.weights, dp @ self.weights

    def error(self, H: np.ndarray) -> np.ndarray:
        """Zero: the rule is the model (the average it stands for diverges)."""
        return np.zeros_like(H, dtype=float)

    def describe(self) -> dict:
        """The roughness model, as result files record it: {} when smooth."""
        return {} if self.smooth else {"roughness": self.rule, "hermite_points": self.n}


class WallLaw:
    """P(H) and dP/dH averaged over heights bounded above, by a quadrature resolving the wall.

    With d = H + 1 - S_max the gap at the highest asperity, P is the average of eq. (7)
    over the density of ``dist`` by :class:`~.roughness.WallQuadrature`, and dP/dH the
    average of the derivative of eq. (5) by the same rule: both to about 1e-11 relative
    for d > 1e-5 rms (tests/test_roughness.py), the derivative consistent with P to
    that accuracy.

    Parameters
    ----------
    dist
        :class:`~.roughness.TruncatedGaussian`, :class:`~.roughness.Weibull` or :class:`~.roughness.Lognormal`; zero
        rms gives the smooth law.
    points
        Points of the moving part of the rule; its fixed panels get
        :func:`~.roughness.panel_points` each.
    """

    def __init__(self, dist, points: int = NEAR_POINTS):
        self.dist, self.rule, self.sigma = dist, dist.name, dist.rms
        self.smooth = dist.rms == 0
        self.wall = dist.top - 1.0
        self.points = points
        self.quadrature = None if self.smooth else WallQuadrature(dist, points, panel_points(points))
        self.n = 1 if self.quadrature is None else self.quadrature.size
        self._reference: WallQuadrature | None = None

    def __call__(self, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return P(H) and dP/dH."""
        return self._average(H, self.quadrature)

    def error(self, H: np.ndarray) -> np.ndarray:
        """|P - P_ref|, P_ref by the rule with twice the points: the error of P itself, not of a coarser rule."""
        if self.smooth:
            return np.zeros_like(H, dtype=float)
        if self._reference is None:
            self._reference = WallQuadrature(self.dist, 2 * self.points, 2 * panel_points(self.points))
        return np.abs(self(H)[0] - self._average(H, self._reference)[0])

    def describe(self) -> dict:
        """The roughness model, as result files record it: {} when smooth."""
        if self.smooth:
            return {}
        shape = {"roughness_cutoff": self.dist.cutoff} if self.rule == "truncated_gaussian" else \
            {"lognormal_skewness": self.dist.skewness} if self.rule == "lognormal" else \
            {"roughness_skewness": self.dist.skewness}
        return {"roughness": self.rule, **shape, "rms": self.dist.rms, "highest_asperity": self.dist.top,
                "quadrature_points": self.points}

    def _average(self, H: np.ndarray, rule: WallQuadrature | None) -> tuple[np.ndarray, np.ndarray]:
        if rule is None:                    # the smooth law
            _refuse_closed(H + 1.0, H, self.wall)
            return lennard_jones(H + 1.0)

        def block(h):
            d = h + 1.0 - self.dist.top
            _refuse_closed(d, h, self.wall)
            g, w = rule.near(d)
            p, dp = lennard_jones(g)
            P, dP = np.einsum("ij,ij->i", w, p), np.einsum("ij,ij->i", w, dp)
            p, dp = lennard_jones(d[:, None] + rule.depths)
            return P + p @ rule.weights, dP + dp @ rule.weights

        return _blocks(block, H, max(rule.near_points, rule.depths.size))


class HistogramLaw:
    """P(H) and dP/dH averaged exactly over the histogram of measured heights.

    On a bin [e_j, e_j+1] of density h_j the average of eq. (5) is
    h_j [Phi(x - e_j) - Phi(x - e_j+1)], x = H + 1, with Phi(g) = g^-2/2 - g^-8/8 the
    antiderivative of sigma_LJ; summed by parts, P = sum_i c_i Phi(x - e_i) and
    dP/dH = sum_i c_i sigma_LJ(x - e_i), c_i = h_i - h_i-1 the jumps of the density.
    Exact for that density: the only error is rounding.

    Parameters
    ----------
    dist
        :class:`~.roughness.Measured`.
    """

    def __init__(self, dist: Measured):
        self.dist, self.rule, self.sigma = dist, dist.name, dist.rms
        self.smooth = False
        self.wall = dist.top - 1.0
        self.edges = dist.edges
        self.jumps = np.diff(dist.density, prepend=0.0, append=0.0)
        self.n = self.edges.size

    def __call__(self, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return P(H) and dP/dH."""
        def block(h):
            phi, p = self._kernels(h)
            return phi @ self.jumps, p @ self.jumps

        return _blocks(block, H, self.n)

    def error(self, H: np.ndarray) -> np.ndarray:
        """Rounding bound of the sum: 8 eps sum_i |c_i Phi(x - e_i)|."""
        def block(h):
            bound = 8 * np.finfo(float).eps * (np.abs(self._kernels(h)[0]) @ np.abs(self.jumps))
            return bound, bound

        return _blocks(block, H, self.n)[0]

    def describe(self) -> dict:
        """The roughness model, as result files record it."""
        d = self.dist
        return {"roughness": self.rule, "rms": d.rms, "skewness": d.skewness, "highest_asperity": d.top,
                "samples": d.samples, "bins": d.density.size}

    def _kernels(self, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Phi(x - e_i) and sigma_LJ(x - e_i), shape (len(H), edges)."""
        g = np.subtract.outer(H + 1.0, self.edges)
        _refuse_closed(g[:, -1], H, self.wall)
        r = 1.0 / g
        r2 = r * r
        r6 = r2 * r2 * r2
        return r2 * (0.5 - 0.125 * r6), r * r2 * (r6 - 1.0)


def law_for(dist, points: int = NEAR_POINTS) -> WallLaw | HistogramLaw:
    """The law averaging over ``dist``: exact for a measured histogram, the wall quadrature otherwise."""
    return HistogramLaw(dist) if isinstance(dist, Measured) else WallLaw(dist, points)


def pressure_law(model: Model) -> PressureLaw | WallLaw | HistogramLaw:
    """The pressure law of ``model``: its -adh_roughness average of eq. (5) (eq. 7, 10, 14)."""
    if model.roughness in RULES:
        return PressureLaw(model.sigma, model.roughness, model.hermite_points)
    return law_for(distribution(model), model.quadrature_points)


#: Relative step of the central differences: P'' with h = STEP (H - wall) at each node, d/dsigma with
#: STEP sigma min(1, gap / S_max).  The five-point rule's truncation, about 800 STEP^4 relative for the
#: g^-10 of P', and the laws' own error over the step (1e-11 / STEP for the wall quadratures, 1e-16 /
#: STEP for the Hermite rule) are both near 1e-9 at 1e-3.
STEP = 1e-3


def curvature(law, H: np.ndarray) -> np.ndarray:
    """P''(H) by the five-point central difference of the law's exact P' (eq. 14's derivative).

    The step h = STEP (H - wall) at each node keeps H - 2h above the wall and scales
    with the distance to it, which sets how fast the law varies (see STEP).
    """
    h = STEP * (H - law.wall)
    k = np.array([1.0, -1.0, 2.0, -2.0])[:, None]
    d = law((H + k * h).ravel())[1].reshape(4, -1)
    return (8.0 * (d[0] - d[1]) - (d[2] - d[3])) / (12.0 * h)


def sigma_rates(law_at, sigma: float, H: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """dP/dsigma and dP'/dsigma at H by the five-point central difference in sigma.

    ``law_at(s)``: the law at roughness s; ``gap``: the smallest H - wall over all
    nodes (all ranks).  The heights scale with sigma, so a change ds moves the highest
    asperity S_max by ds S_max / sigma: the step STEP sigma min(1, gap / S_max)
    moves it by at most STEP times the gap, which keeps sigma + 2 ds off the wall.
    """
    top = law_at(sigma).wall + 1.0
    ds = STEP * sigma * min(1.0, gap / top)
    P = [law_at(sigma + k * ds)(H) for k in (1.0, -1.0, 2.0, -2.0)]
    return tuple((8.0 * (P[0][i] - P[1][i]) - (P[2][i] - P[3][i])) / (12.0 * ds) for i in (0, 1))
