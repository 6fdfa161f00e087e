"""petsc-adhesion: adhesive contact of a rough elastic microparticle with a flat.

The self-consistent model of Cheng, Dunn and Brach (J. Adhesion 78, 2002):
Lennard-Jones surface stress (Derjaguin approximation) coupled to half-space
elasticity, Gaussian roughness averaged over the gap, solved with PETSc.

From Python (docs/python.md): the library's calls take typed objects,
:func:`trace_curve` (a :class:`Model`, a :class:`GridChoice`, a
:class:`SolverChoice`, :class:`Settings`, a :class:`CurveRequest`) returns a
:class:`Curve`, :func:`solve_at` a :class:`Solution`; :func:`curve` and
:func:`solve` take the command line's options as keywords.  PETSc starts on
the first call, not on import (the library's modules are loaded on first use,
so that a program can hand PETSc its command line first).

=====================  ==============================================================
package                what
=====================  ==============================================================
``core``               continuation of G(x, p) = 0 through turning points, events, fold system
``model``              parameters and units, pressure laws and roughness, closed forms
``discretization``     grids, the influence operator, the problem in each frame
``tracing``            the curve over grids that follow the edge, error bars, results
``fitting``            measurements to the material: a pull-off's w, a force curve's w and E*
``maps``               force maps: every curve of a map fitted over MPI ranks (:func:`fit_map`)
``io``                 result files, their layout, the report, figures
``population``         a particle population on a measured topography: its pull-off distribution
``app``                options, one run, studies over MPI, checkpoints, command line, API
``benchmarks``         measurements and the docs' figures (the library never imports it)
=====================  ==============================================================
"""
from .singleton import singleton_defaults

singleton_defaults()   # before any MPI_Init in this process: see petsc_adhesion.singleton

from .app.api import curve, solve  # noqa: E402  (after the singleton's defaults)
from .errors import InputError  # noqa: E402
from .tracing.curve import Curve, Event, Solution  # noqa: E402
from .version import __version__  # noqa: E402

__all__ = ["__version__", "curve", "solve", "particle_population", "trace_curve", "solve_at", "Model", "Bodies", "GridChoice",
           "SolverChoice", "PetscSettings", "CurveRequest", "Settings", "curve_settings", "Curve", "Event", "Solution", "InputError",
           "fit_curve", "CurveFit", "Spring", "FitChoice", "read_curve", "MeasuredCurve", "fit_map", "open_map", "MapResult",
           "Pixel"]

#: Names loaded on first use (their modules import petsc4py.PETSc, which starts PETSc).
_LAZY = {"trace_curve": "tracing.trace", "solve_at": "tracing.trace", "GridChoice": "tracing.trace",
         "SolverChoice": "tracing.trace", "PetscSettings": "core.newton", "CurveRequest": "tracing.trace", "curve_settings": "tracing.trace",
         "Settings": "core.continuation", "Model": "model.parameters", "Bodies": "model.physical",
         "fit_curve": "fitting.curve_fit", "CurveFit": "fitting.results", "Spring": "fitting.results",
         "FitChoice": "fitting.results", "read_curve": "fitting.data", "MeasuredCurve": "fitting.data",
         "fit_map": "maps.fit", "open_map": "maps.source", "MapResult": "maps.result", "Pixel": "maps.result"}


def __getattr__(name: str):
    if name == "particle_population":  # the package population/ keeps its own name; its call is this one
        import importlib

        return importlib.import_module(".population.compute", __name__).population
    if name not in _LAZY:
        raise AttributeError(f"module 'petsc_adhesion' has no attribute '{name}'")
    import importlib

    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value
