"""Closed-form reference solutions, in the project's dimensionless units.

One home for every formula, one module for each solution (the rigid sphere and
its DMT pull-off, the elastic half-space under a disk and a Hertz pressure, JKR,
Maugis-Dugdale) that tests and code compare against, so none is
copied. Units (Cheng, Dunn & Brach 2002): approach lambda = alpha/epsilon,
radii r and contact radii A in sqrt(epsilon R), pressures in 8 gamma/(3 epsilon)
(P > 0 repulsion), loads F in 2 pi R gamma (F < 0 attraction), Tabor parameter
mu = (R gamma^2 / (E^2 epsilon^3))^(1/3) with E the combined modulus of eq. (2).
The influence operator is W(r) = int t/(t + r) K(m) p(t) dt, m = 4 t r/(t + r)^2,
so that the deflection in eq. (12) is c W, c = 32 mu^(3/2)/(3 pi).

Pure numpy/scipy: no PETSc here.
"""
from .elastic import disk_deflection, hertz_deflection
from .jkr import (
           JKR_PULL_OFF,
           jkr_approach,
           jkr_fixed_grip_pull_off,
           jkr_load,
           jkr_zero_load,
)
from .maugis_dugdale import (
           maugis_dugdale_curve,
           maugis_dugdale_pull_off,
           maugis_parameter,
)
from .rigid import (
           DMT_PULL_OFF,
           RIGID_EQUILIBRIUM,
           far_deflection,
           load_beyond,
           load_beyond_rates,
           rigid_load,
)

__all__ = ["RIGID_EQUILIBRIUM", "DMT_PULL_OFF", "JKR_PULL_OFF", "rigid_load", "load_beyond", "load_beyond_rates",
           "far_deflection", "disk_deflection", "hertz_deflection", "jkr_load", "jkr_approach", "jkr_zero_load",
           "jkr_fixed_grip_pull_off", "maugis_parameter", "maugis_dugdale_curve", "maugis_dugdale_pull_off"]
