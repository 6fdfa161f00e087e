"""Physical inputs and results: the bodies in SI, the model they make, and results in nN, nm and MPa.

Two spheres of radii R1, R2 (R2 absent: a flat) touch as one sphere of radius
R = R1 R2 / (R1 + R2) on a flat (the paper, "The Mathematical Theory"); their
moduli combine by eq. (2), 1/E = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (E2 absent:
a rigid counterface).  The work of adhesion is given, or comes from a Hamaker
constant A and its cut-off distance D0 as gamma = A / (12 pi D0^2)
(Israelachvili, Intermolecular and Surface Forces, 3rd ed., 2011, sec. 13.6:
D0 = 0.165 nm for most solids).  These give the Tabor parameter (eq. 9) and,
with the rms roughness, sigma = rms / epsilon; the results of the
dimensionless model come back in the paper's units: loads in 2 pi R gamma,
approaches and gaps in epsilon, radii in sqrt(R epsilon), pressures in
8 gamma / (3 epsilon).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .parameters import scales, tabor

__all__ = ["Bodies", "HAMAKER_CUTOFF", "UNITS", "in_units"]

#: Israelachvili's cut-off distance D0 between contacting solids (m).
HAMAKER_CUTOFF = 0.165e-9
#: The units results are reported in, with their value in SI.
UNITS = {"nN": 1e-9, "nm": 1e-9, "MPa": 1e6, "aJ": 1e-18}


@dataclass(frozen=True)
class Bodies:
    """A sphere (or two) on a flat, in SI: radii (m), Young's moduli (Pa), Poisson's ratios, the work of
    adhesion gamma (J/m^2) or a Hamaker constant (J) with its cut-off (m), the equilibrium spacing
    epsilon (m) and the rms roughness (m) of the combined surfaces.  A fit of a force curve may leave the
    moduli None (not given: it finds E*); then ``E`` and ``mu`` are not defined."""

    radius: float
    young1: float | None
    poisson1: float | None
    epsilon: float
    gamma: float | None = None
    hamaker: float | None = None
    hamaker_cutoff: float = HAMAKER_CUTOFF
    radius2: float | None = None
    young2: float | None = None
    poisson2: float | None = None
    rms: float | None = None

    @property
    def R(self) -> float:
        """The combined radius R1 R2 / (R1 + R2) (R1 alone on a flat)."""
        return self.radius if self.radius2 is None else self.radius * self.radius2 / (self.radius + self.radius2)

    @property
    def E(self) -> float:
        """The combined modulus, eq. (2) (a rigid counterface when E2 is not given)."""
        if self.young1 is None or self.poisson1 is None:
            # the TypeError None's arithmetic raised before, with its reason
            raise TypeError("E* (eq. 2) is not defined: the sphere's modulus is not given (a fit finds it)")
        compliance = (1 - self.poisson1**2) / self.young1
        if self.young2 is not None:
            assert self.poisson2 is not None, "young2 without poisson2: the options' reading refuses it"
            compliance += (1 - self.poisson2**2) / self.young2
        return 1.0 / compliance

    @property
    def work_of_adhesion(self) -> float:
        """gamma, or A / (12 pi D0^2) from the Hamaker constant."""
        if self.gamma is not None:
            return self.gamma
        assert self.hamaker is not None, "neither gamma nor hamaker: the options' reading refuses it"
        return self.hamaker / (12 * math.pi * self.hamaker_cutoff**2)

    @property
    def mu(self) -> float:
        """Tabor's parameter, eq. (9)."""
        return tabor(self.R, self.work_of_adhesion, self.E, self.epsilon)

    @property
    def sigma(self) -> float | None:
        """The rms roughness in units of epsilon (None when not given)."""
        return None if self.rms is None else self.rms / self.epsilon

    def spring_stiffness(self, k: float) -> float:
        """The dimensionless stiffness K = k epsilon / (2 pi R gamma) of a spring of k N/m (a cantilever):
        its force k delta in units of 2 pi R gamma for an extension delta in units of epsilon."""
        return k * self.epsilon / (2 * math.pi * self.R * self.work_of_adhesion)

    def scales(self) -> dict:
        """The SI values of the model's units (:func:`~petsc_adhesion.model.parameters.scales`)."""
        return scales(self.R, self.work_of_adhesion, self.E, self.epsilon)

    def describe(self) -> dict:
        """The inputs as given and what they make, in SI, with the units each result is reported in."""
        given = {k: getattr(self, k) for k in ("radius", "radius2", "young1", "poisson1", "young2", "poisson2",
                                                "gamma", "hamaker", "epsilon", "rms") if getattr(self, k) is not None}
        if self.hamaker is not None:
            given["hamaker_cutoff"] = self.hamaker_cutoff
        sc = self.scales()
        return {"inputs": given, "R_m": self.R, "E_Pa": self.E, "gamma_J_m2": self.work_of_adhesion,
                "epsilon_m": self.epsilon, "mu": self.mu, **({"sigma": self.sigma} if self.rms is not None else {}),
                "force_nN": sc["force_N"] / UNITS["nN"], "approach_nm": sc["approach_m"] / UNITS["nm"],
                "radius_nm": sc["radius_m"] / UNITS["nm"], "pressure_MPa": sc["pressure_Pa"] / UNITS["MPa"],
                "work_aJ": sc["force_N"] * sc["approach_m"] / UNITS["aJ"]}


#: event key -> (the scale it is in, the suffix of its physical key)
_CONVERT = {"lambda": ("approach_nm", "nm"), "lambda_err": ("approach_nm", "nm"), "lambda_grid": ("approach_nm", "nm"),
            "H0": ("approach_nm", "nm"), "F": ("force_nN", "nN"), "F_err": ("force_nN", "nN"),
            "F_grid": ("force_nN", "nN"), "contact_radius": ("radius_nm", "nm"),
            "contact_radius_err": ("radius_nm", "nm"), "contact_radius_grid": ("radius_nm", "nm"),
            "Z": ("approach_nm", "nm"), "Z_err": ("approach_nm", "nm"), "Z_grid": ("approach_nm", "nm"),
            "energy": ("work_aJ", "aJ"), "energy_err": ("work_aJ", "aJ")}


def _event(e: dict, d: dict) -> dict:
    out = {"kind": e["kind"]} if "kind" in e else {}
    out |= {f"{k}_{unit}": e[k] * d[scale] for k, (scale, unit) in _CONVERT.items() if e.get(k) is not None}
    if e.get("landing"):
        out["landing"] = _event(e["landing"], d)
    return out


def in_units(summary: dict, d: dict) -> dict:
    """The ``physical`` object of a curve's summary: ``d`` (:meth:`Bodies.describe`), every event of
    ``summary`` in nm and nN (``lambda_nm``, ``F_nN``, their ``_err`` and ``_grid``, ``H0_nm``,
    ``contact_radius_nm``), the energy of a cycle in aJ (``energy_aJ``, ``energy_err_aJ``) and, behind a
    spring, its stiffness in N/m (``k_N_m``), its jumps (``Z_nm`` too) and energy."""
    lists = {k: [_event(e, d) for e in summary[k]] for k in ("folds", "equilibria", "load_extrema", "at_lambda")}
    out = {**d, "pull_off": _event(summary["pull_off"], d) if summary["pull_off"] else None, **lists,
           **_event({k: summary[k] for k in ("energy", "energy_err")}, d)}
    if summary.get("spring"):
        sp = summary["spring"]
        out["spring"] = {"k_N_m": sp["K"] * d["force_nN"] / d["approach_nm"],
                         "jumps": [_event(e, d) for e in sp["jumps"]],
                         **_event({k: sp[k] for k in ("energy", "energy_err")}, d)}
    return out
