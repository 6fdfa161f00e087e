"""petsc-adhesion: adhesive contact of a rough elastic microparticle with a flat.

The self-consistent model of Cheng, Dunn and Brach (J. Adhesion 78, 2002):
Lennard-Jones surface stress (Derjaguin approximation) coupled to half-space
elasticity, Gaussian roughness averaged over the gap, solved with PETSc.

From Python (docs/python.md): :func:`curve` traces a load-approach curve,
:func:`solve` solves at one approach; PETSc starts on the first call, not on import.
"""
from .singleton import singleton_defaults

singleton_defaults()   # before any MPI_Init in this process: see petsc_adhesion.singleton

from .api import Curve, Event, Solution, curve, solve
from .errors import InputError

__version__ = "0.1.0"
__all__ = ["__version__", "curve", "solve", "Curve", "Event", "Solution", "InputError"]
