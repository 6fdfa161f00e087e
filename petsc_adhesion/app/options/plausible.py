"""What the field measures: the physical inputs' plausible ranges, and one warning line for a value outside,
naming the option and the likely slip of units (docs/materials.md, "Plausible inputs").

The table's own ranges (:mod:`.table`) refuse what the model cannot take; these ranges are narrower: a value
outside them is possible but suspicious (a work of adhesion of 50 J/m^2 is 50 mJ/m^2 typed in the wrong
unit), so the run goes on and says so.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Plausible", "PLAUSIBLE", "implausible", "slip"]


@dataclass(frozen=True)
class Plausible:
    """The range ``lo`` to ``hi`` (in the option's SI ``unit``) that measured values of ``what`` fall in;
    ``low`` and ``high`` say what a value below or above it would be; ``low_slips`` and ``high_slips`` the
    units such a value was likely typed in, each with what one of it is in ``unit`` (none: an exponent's
    slip, and ``example`` shows a value in the option's unit)."""

    what: str
    unit: str
    lo: float
    hi: float
    low: str
    high: str
    low_slips: tuple[tuple[str, float], ...]
    high_slips: tuple[tuple[str, float], ...]
    example: str


_RADIUS = Plausible("a radius", "m", 1e-9, 1e-2, "below 1 nm, smaller than any tip (a few atoms)",
                    "above 1 cm, larger than the lenses of JKR tests", (), (("mm", 1e-3),), "20 nm is 2e-8")
_MODULUS = Plausible("a Young's modulus", "Pa", 1e3, 1.2e12, "below 1 kPa, softer than the softest gels",
                     "above 1200 GPa, stiffer than diamond", (("MPa", 1e6), ("GPa", 1e9)), (), "2 MPa is 2e6")
_SPACING = Plausible("an equilibrium spacing", "m", 1e-10, 1e-9, "below 0.1 nm, less than an atom's radius",
                     "above 1 nm, more than the spacing of molecular contacts", (), (), "0.3 nm is 3e-10")

#: Option -> its plausible range (docs/materials.md says where each bound comes from).
PLAUSIBLE = {
    "phys_radius": _RADIUS, "phys_radius2": _RADIUS,
    "phys_young1": _MODULUS, "phys_young2": _MODULUS,
    "phys_gamma": Plausible("a work of adhesion", "J/m^2", 1e-4, 1.0, "below 0.1 mJ/m^2, less than surfaces keep "
                            "in water", "above 1 J/m^2, more than all but clean metals in vacuum", (),
                            (("mJ/m^2", 1e-3),), "50 mJ/m^2 is 0.05"),
    "phys_hamaker": Plausible("a Hamaker constant", "J", 1e-22, 1e-18, "below 1e-22 J, weaker than across any "
                              "liquid", "above 1e-18 J, stronger than metals'", (), (), "100 zJ is 1e-19"),
    "phys_epsilon": _SPACING, "phys_hamaker_cutoff": _SPACING,
    "phys_spring": Plausible("a cantilever's spring constant", "N/m", 1e-3, 1e3, "below 1 mN/m, softer than any "
                             "AFM cantilever", "above 1000 N/m, stiffer than any AFM cantilever", (),
                             (("mN/m", 1e-3),), "0.1 N/m = 100 pN/nm is 0.1"),
    "fit_pull_off": Plausible("a pull-off force", "N", 1e-12, 1e-3, "below 1 pN, under an AFM's force noise",
                              "above 1 mN, more than a colloidal probe's", (), (("nN", 1e-9), ("uN", 1e-6)),
                              "10 nN is 1e-8"),
}


def slip(name: str, value: float) -> str | None:
    """The one line of warning for ``value`` of option ``name`` outside its plausible range (None inside, or
    for an option without one): what the value would be, and the likely slip of units."""
    p = PLAUSIBLE.get(name)
    if p is None or p.lo <= value <= p.hi:
        return None
    where, slips = (p.low, p.low_slips) if value < p.lo else (p.high, p.high_slips)
    if slips:
        meant = (f"was {value:g} {' or '.join(u for u, _ in slips)} meant (-{name} "
                 f"{' or '.join(f'{value * f:g}' for _, f in slips)})?")
    else:
        meant = f"check its exponent ({p.example})"
    return f"-{name} {value:g}: {p.what} {where}; the option is in {p.unit}: {meant}"


def implausible(values: dict) -> list[str]:
    """The warning lines of the options ``values`` (name -> value, None: not given) outside what the field
    measures, in the table's order."""
    return [line for name in PLAUSIBLE if values.get(name) is not None
            for line in [slip(name, values[name])] if line is not None]
