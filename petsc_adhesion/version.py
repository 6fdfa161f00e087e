"""The version of petsc-adhesion (a leaf module: the result files record it)."""
__version__ = "0.1.0"
