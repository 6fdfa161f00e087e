"""The Lennard-Jones pressure law and its roughness average (eq. 5, 10, 13-14).

P > 0 is repulsion.  With roughness, P is averaged over Gaussian heights by a
Gauss-Hermite rule; the continuous average of (H - S + 1)^-9 diverges, so the
rule is part of the model (the paper's: 16 points), and its outermost node is a
hard wall: every gap H - sqrt(2) sigma x_l + 1 must stay positive.
"""
from __future__ import annotations

import math

import numpy as np

from .model import Model

__all__ = ["PressureLaw", "RULES"]


def _smooth(sigma: float, n: int):
    return np.zeros(1), np.ones(1)


def _hermite(sigma: float, n: int):
    x, w = np.polynomial.hermite.hermgauss(n)
    return math.sqrt(2.0) * sigma * x, w / math.sqrt(math.pi)


#: Roughness rules: name -> (sigma, n) -> (height shifts S_l, normalised weights).
RULES = {"none": _smooth, "hermite": _hermite}


class PressureLaw:
    """P(H) and dP/dH on nodal separations.

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

    def __call__(self, H: np.ndarray):
        """Return P(H) (eq. 14; eq. 5 when smooth) and its exact derivative dP/dH."""
        g = self.gaps(H)
        if np.any(g <= 0.0):
            raise FloatingPointError("separation below the wall of the roughness rule")
        g3 = 1.0 / (g * g * g)
        g9 = g3 * g3 * g3
        p = g9 - g3
        dp = (3.0 * g3 - 9.0 * g9) / g
        if self.smooth:
            return p, dp
        return p @ self.weights, dp @ self.weights
