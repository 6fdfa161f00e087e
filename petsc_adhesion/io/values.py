"""The library's result values as a tree of JSON values and numpy arrays, and back: the checkpoint's one
serializer (a study's finished cases, a curve's error-bar estimates already made).

:func:`encode` reads a frozen dataclass field by field into ``{"__type__": its class name, field: value,
...}``, a tuple into ``{"__tuple__": [...]}`` (so that it comes back a tuple, not a list), a dict into
``{"__dict__": {...}}``; numpy arrays stay arrays (the checkpoint's file keeps them in its ``.npz``
archive), numpy scalars become Python's.  :func:`decode` builds the objects again by their constructors,
from the classes of :func:`known` alone: a checkpoint names no code to run, it only holds values (no
pickle: a checkpoint file is input, and input is not trusted).  A float goes through JSON as ``repr``
writes it, the shortest text that reads back to the same double, so a value comes back bit for bit.
"""
from __future__ import annotations

from dataclasses import fields, is_dataclass
from functools import lru_cache

import numpy as np

__all__ = ["encode", "decode", "known"]

_TYPE, _TUPLE, _DICT = "__type__", "__tuple__", "__dict__"


@lru_cache(maxsize=1)
def known() -> dict:
    """Class name -> class, of every value a checkpoint may hold: a curve and its parts, a critical study's
    cusp, a model spread, an event's estimate, a study's case."""
    # here, not at the top: the readers of result files (io.summary, plot) need not load PETSc, which
    # tracing.critical and tracing.error_bars do
    from ..model import parameters, physical, topography
    from ..tracing import case, critical, curve, error_bars, legs, measured, model_spread, tracer

    classes = [parameters.Model, physical.Bodies, measured.Measured, measured.Missing, critical.Critical,
               error_bars.Estimate, error_bars.LandingEstimate, model_spread.Rule, model_spread.Quantity,
               model_spread.ModelSpread, case.CaseResult,
               tracer.Point]   # the points an estimate located (core's Point, as tracing's tracer holds it)
    # a curve's parts, the legs behind its spring, the topography its model was read from: every value class
    # their modules export
    for module in (curve, legs, topography):
        classes += [c for c in (getattr(module, name) for name in module.__all__)
                    if isinstance(c, type) and is_dataclass(c)]
    return {c.__name__: c for c in classes}


def encode(value):
    """``value`` as a tree of JSON values and numpy arrays (see the module); TypeError for anything but the
    package's values and plain data (:func:`decode` reads back the classes of :func:`known`)."""
    if value is None or isinstance(value, (bool, int, float, str, np.ndarray)):
        return value
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, tuple):
        return {_TUPLE: [encode(v) for v in value]}
    if isinstance(value, list):
        return [encode(v) for v in value]
    if isinstance(value, dict):
        return {_DICT: {str(k): encode(v) for k, v in value.items()}}
    if is_dataclass(value) and not isinstance(value, type):
        name = type(value).__name__
        # the package's own values; decode reads back only those of known(), which encode need not load
        # (it imports PETSc's modules: a save of a smooth curve's estimates would load them for nothing)
        if not type(value).__module__.startswith("petsc_adhesion."):
            raise TypeError(f"{name}: not a result value a checkpoint holds")
        return {_TYPE: name, **{f.name: encode(getattr(value, f.name)) for f in fields(value) if f.init}}
    raise TypeError(f"{type(value).__name__}: not a result value a checkpoint holds")


def decode(tree, classes: dict | None = None):
    """The value :func:`encode` made ``tree`` of; ValueError for a tree it did not make (an unknown class,
    a field the class has not)."""
    classes = known() if classes is None else classes
    if isinstance(tree, list):
        return [decode(v, classes) for v in tree]
    if not isinstance(tree, dict):
        return tree
    if _TUPLE in tree:
        return tuple(decode(v, classes) for v in tree[_TUPLE])
    if _DICT in tree:
        return {k: decode(v, classes) for k, v in tree[_DICT].items()}
    name = tree.get(_TYPE)
    if name not in classes:
        raise ValueError(f"a value of unknown type {name!r}")
    try:
        return classes[name](**{k: decode(v, classes) for k, v in tree.items() if k != _TYPE})
    except TypeError as e:                  # a field the class has not, or one missing
        raise ValueError(f"a {name} this version cannot read ({e})") from None
