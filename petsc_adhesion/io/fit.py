"""A fit's result files and console lines (docs/output.md, docs/fitting.md): the ``fit`` of the JSON summary
and the HDF5 group of the same name, the CSV of a fitted curve, the report.

The only place a fit's typed result (:class:`~petsc_adhesion.fitting.results.CurveFit`,
:class:`~petsc_adhesion.fitting.results.PullOffFit`) becomes keys: :func:`fit_record` reads its
attributes into the ``fit`` object (a Measured's value and bar as ``x`` and ``x_err``, a Missing as
null with its reason under ``missing``), :func:`fit_summary` and :func:`fit_tree` put it into the JSON and
the HDF5 file (the covariance as a matrix, the data and the fitted model's curve as datasets),
:func:`write_fit_csv` writes a fitted curve's points and :func:`report_fit` the console lines.
"""
from __future__ import annotations

import csv
import math

import numpy as np

from ..errors import tell
from ..tracing.measured import Measured, Missing
from .layout import spread_tree
from .report import spread_lines
from .summary import spread_record

__all__ = ["fit_record", "fit_tree", "fit_summary", "write_fit_csv", "report_fit", "DESCRIBE_FIT"]

#: Units and descriptions of the HDF5 groups of a fit (io.write describes every group with them).
DESCRIBE_FIT = {
    "fit": ("gamma*: J/m^2; E_star*: Pa; rms*: m; P*: N; F_pull_off*: 2 pi R gamma; noise_N, residual_rms_N: N; "
            "wall_time_s: s", "the fit of a measurement (kind pull_off: -fit_pull_off; curve: -fit_curve): the "
            "work of adhesion gamma and its bar gamma_err (one standard deviation), mu (eq. 9), and for a curve "
            "the reduced modulus E_star with its bar (docs/fitting.md)"),
    "fit/covariance": ("of the parameters named in fit's attribute parameters (ln E_star, ln gamma: 1; sigma: "
                       "epsilon; z0: epsilon; F0: noise_N)", "the covariance of the fitted parameters at the optimum: "
                       "s^2 (J^T J)^-1 carried to (ln E*, ln w)"),
    "fit/closed_forms": ("gamma: J/m^2", "what DMT (P / 2 pi R), JKR (P / 1.5 pi R) and the Maugis-Dugdale "
                         "transition (lambda_MD = 1.157 mu, self-consistent) give for gamma from the same pull-off"),
    "fit/iterations": ("gamma: J/m^2; F_grid: 2 pi R gamma", "the secant's steps: gamma, mu and the model's "
                       "pull-off on the grid"),
    "fit/offsets": ("z0*: m; F0*: N", "the nuisance parameters: contact point z0 and force baseline F0 with bars"),
    "fit/instrument": ("invols_scale*: 1; spring*: N/m; virtual_deflection*: N/m; drag*: N; contact_slope_N_m: N/m",
                       "the instrument's nuisance parameters (docs/fitting.md): the deflection sensitivity's scale "
                       "(the true over the file's), the spring constant, the baseline's slope in z, the retract's "
                       "baseline offset; each fitted (with its bar) or held (its note in held says at what)"),
    "fit/instrument/held": ("", "the instrument's parameters held, each with what it is held at"),
    "fit/measured": ("*_N: N; *_m: m", "what the curve shows by itself: baseline, noise, largest force, pull-off "
                     "and its position, jump-in and its size"),
    "fit/fitted": ("*_N: N; *_m: m", "the fitted model's jump-in and jump-off positions and pull-off force"),
    "fit/fixed": ("E_star: Pa", "parameters held at a given value (-fit_modulus false)"),
    "fit/given": ("*_m: m; spring_N_m: N/m; E_star_start: Pa", "the given constants: tip radius, epsilon, spring "
                  "constant (and where it came from), the modulus the fit started from"),
    "fit/missing": ("", "the quantities the fit did not determine (null above), each with its reason: at a bound "
                    "of the model's range, or undetermined (docs/fitting.md)"),
    "fit/data": ("z: m; F, F_fit: N", "the measured curve and the fit at its points: piezo displacement z, force F "
                 "(tensile negative), leg (0 approach, 1 retract), F_fit, used (0: left out, next to a jump)"),
    "fit/model": ("z: m; F_*: N", "the fitted model's force on an even grid of z on the approach and the retract"),
    "fit/model_spread": ("value, err, values, spread: J/m^2 (gamma), Pa (E*); relative: 1; wall_time_s, "
                         "rule_times_s: s",
                         "the model spread of a fit with roughness (docs/model.md, docs/fitting.md): a pull-off's "
                         "gamma by the same root solve under the other roughness laws (rules), a curve's gamma "
                         "and E* by the optimum of each law's residuals sought from the fit's (fitting/outcome.py); quantities/NNNN: the "
                         "value under the reference's law with its bar, the spread, relative and warning; its "
                         "group values: the value under each rule, one attribute per rule (absent: not found, "
                         "missing says why)"),
}


def _value(q) -> float | None:
    return float(q.value) if isinstance(q, Measured) else None


def _err(q) -> float | None:
    return None if not isinstance(q, Measured) or q.err is None else float(q.err)


def _finite(x) -> float | None:
    return float(x) if x is not None and math.isfinite(x) else None


def _missing(**quantities) -> dict:
    return {k: q.reason for k, q in quantities.items() if isinstance(q, Missing)}


def _verdict(fit) -> dict:
    return {"complete": fit.complete, "trustworthy": fit.trustworthy, "warnings": list(fit.warnings)}


def _instrument_record(ins) -> dict:
    """The instrument's parameters: value and bar of each fitted one, the value of each held one with what it
    is held at under ``held``, a Missing one null with its reason under ``missing``."""
    rec: dict = {"held": {}, "missing": {}}
    for key in ("invols_scale", "spring", "virtual_deflection", "drag"):
        q = getattr(ins, key)
        rec[key], rec[f"{key}_err"] = _value(q), _err(q)
        if isinstance(q, Missing):
            rec["missing"][key] = q.reason
        elif q.err is None:
            rec["held"][key] = q.note or "held"
    if ins.contact_slope is not None:
        rec["contact_slope_N_m"] = ins.contact_slope
    return rec


def _curve_record(fit) -> dict:
    d, m, f = fit.data, fit.measured, fit.fitted
    given = {"radius_m": fit.bodies.R, "epsilon_m": fit.bodies.epsilon, "spring_N_m": fit.spring.k,
             "file": d.path, "format": d.source, "spring_from": fit.spring.source}
    if fit.choice.modulus and fit.bodies.young1 is not None:
        given["E_star_start"] = fit.bodies.E
    if fit.noise_stated:
        given["noise_N"] = fit.noise_N
    return {"kind": "curve", "gamma": _value(fit.gamma), "gamma_err": _err(fit.gamma),
            "E_star": _value(fit.E_star), "E_star_err": _err(fit.E_star),
            "rms": _value(fit.rms), "rms_err": _err(fit.rms), "mu": fit.mu, "sigma": fit.sigma, "K": fit.K,
            "offsets": {"z0_m": _value(fit.z0), "z0_err_m": _err(fit.z0), "F0_N": _value(fit.F0),
                        "F0_err_N": _err(fit.F0)},
            "chi2": fit.chi2, "dof": fit.dof, "reduced_chi2": _finite(fit.reduced_chi2),
            "p_value": _finite(fit.p_value), "noise_N": fit.noise_N, "residual_rms_N": fit.residual_rms_N,
            "n_points": int(d.z.size), "parameters": list(fit.parameters),
            "covariance": [[_finite(c) for c in row] for row in np.asarray(fit.covariance, dtype=float)],
            "measured": {"pull_off_N": m.pull_off_N, "pull_off_z_m": m.pull_off_z_m, "jump_in_z_m": m.jump_in_z_m,
                         "jump_in_drop_N": m.jump_in_drop_N, "contact_N": m.contact_N, "F0_N": m.F0_N,
                         "noise_N": m.noise_N},
            "fitted": {k: v for k, v in (("jump_in_z_m", f.jump_in_z_m), ("pull_off_N", f.pull_off_N),
                                         ("jump_off_z_m", f.jump_off_z_m)) if v is not None},
            "fixed": {"E_star": fit.E_star.value} if not fit.choice.modulus else {},
            "given": given, "traces": fit.traces, "iterations": fit.iterations, "status": fit.status,
            "wall_time_s": fit.wall_time_s, "notes": list(fit.notes),
            "missing": _missing(gamma=fit.gamma, E_star=fit.E_star, rms=fit.rms, z0=fit.z0, F0=fit.F0),
            "segment": fit.segment,
            **({"z_range_m": list(fit.z_range)} if fit.z_range is not None else {}),
            **({"instrument": _instrument_record(fit.instrument)} if fit.instrument is not None else {}),
            **({"model_spread": spread_record(fit.spread)} if fit.spread is not None else {}),
            **_verdict(fit)}


def _pull_off_record(fit) -> dict:
    forms = {}
    for c in fit.closed_forms:
        forms[c.name] = {"gamma": c.gamma, "mu": c.mu, **({"lambda_MD": c.lambda_MD} if c.lambda_MD else {}),
                         "formula": c.formula}
    return {"kind": "pull_off", "P_N": fit.P.value, "P_err_N": fit.P.err, "gamma": _value(fit.gamma),
            "gamma_err": _err(fit.gamma), "mu": fit.mu, "sigma": fit.sigma, "F_pull_off": fit.F.value,
            "F_pull_off_err": fit.F.err, "F_pull_off_grid": fit.F.grid, "dlnF_dlnmu": fit.dlnF_dlnmu,
            "closed_forms": forms, "curves_traced": fit.curves, "wall_time_s": fit.wall_time_s,
            "iterations": [{"gamma": g, "mu": m, "F_grid": f} for g, m, f in fit.history],
            "missing": _missing(gamma=fit.gamma), **_verdict(fit),
            **({"model_spread": spread_record(fit.spread)} if fit.spread is not None else {})}


def fit_record(fit) -> dict:
    """The ``fit`` object of a ``-summary`` file (docs/fitting.md) read off a CurveFit or a PullOffFit."""
    return _pull_off_record(fit) if hasattr(fit, "closed_forms") else _curve_record(fit)


def fit_summary(head: dict, options: dict, fit) -> dict:
    """The JSON summary of a fit: the program, the options as given, the fit."""
    return {**head, "kind": "fit", "options": options, "fit": fit_record(fit)}


def fit_tree(head: dict, options: dict, fit, model: dict | None = None) -> dict:
    """The HDF5 tree of a fit: its record, the covariance as a matrix, a curve's data and fit at its points,
    and ``model`` (the fitted model's force on an even grid, from the caller) where given."""
    rec = fit_record(fit)
    if "covariance" in rec:
        rec["covariance"] = np.asarray(fit.covariance, dtype=float)
    for key in ("notes", "warnings"):
        rec[key] = list(rec[key]) if rec.get(key) else ""
    if not hasattr(fit, "closed_forms"):
        rec["data"] = {"z": np.asarray(fit.data.z), "F": np.asarray(fit.data.F), "leg": np.asarray(fit.leg),
                       "F_fit": np.asarray(fit.F_fit), "used": np.asarray(fit.used).astype(int)}
    if model is not None:
        rec["model"] = {k: np.asarray(v) for k, v in model.items()}
    if getattr(fit, "spread", None) is not None:       # a law's missing value NaN, as a curve's spread
        rec["model_spread"] = spread_tree(fit.spread)
    return {**head, "kind": "fit", "options": options, "fit": rec}


def write_fit_csv(path: str, data: dict) -> None:
    """A row per measured point: z (m), F (N), leg (0 approach, 1 retract), F_fit (N), used (0/1), from the
    ``data`` group of :func:`fit_tree`."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["z_m", "F_N", "leg", "F_fit_N", "used"])
        for row in zip(data["z"], data["F"], data["leg"], data["F_fit"], data["used"]):
            w.writerow([f"{row[0]:.10g}", f"{row[1]:.10g}", int(row[2]), f"{row[3]:.10g}", int(row[4])])


def _pct(x: float, ref: float) -> str:
    return f"{100 * (x / ref - 1):+.1f}%"


def _count(n: int, noun: str) -> str:
    """``n`` and the noun, singular for one ("1 curve traced", "18 evaluations")."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _pm(q, scale: float, unit: str, digits: str = ".6g") -> str:
    """``value +- bar unit`` of a Measured in ``unit`` (``scale`` SI per unit); its note where it has no bar;
    ``undetermined`` for a Missing."""
    if isinstance(q, Missing):
        return "undetermined"
    if q.err is not None:
        return f"{q.value / scale:{digits}} +- {q.err / scale:.2g} {unit}"
    return f"{q.value / scale:{digits}} {unit}" + (f" ({q.note})" if q.note else "")


def report_fit(fit) -> None:
    """The console lines of a fit (rank 0): its numbers, its notes, and a WARNING line for each reason it does
    not hold."""
    out = []
    if hasattr(fit, "closed_forms"):
        P = fit.P
        err = f" +- {P.err * 1e9:.3g}" if P.err else ""
        out.append(f"fit of the pull-off P = {P.value * 1e9:.6g}{err} nN: {_count(fit.curves, 'curve')} traced, "
                   f"{fit.wall_time_s:.3g} s")
        F_err = f"{fit.F.err:.1e}" if fit.F.err is not None else "(no bar)"
        out.append(f"  gamma = {_pm(fit.gamma, 1.0, 'J/m^2')}   mu = {fit.mu:.6g}   sigma = {fit.sigma:g}   "
                   f"model pull-off F = {fit.F.value:.8f} +- {F_err} (2 pi R gamma)")
        names = {"jkr": "JKR", "dmt": "DMT", "maugis_dugdale": "Maugis-Dugdale"}
        for key, name in names.items():
            c = fit.closed_form(key)
            ours = f"{_pct(c.gamma, fit.gamma.value)} from ours; " if isinstance(fit.gamma, Measured) else ""
            out.append(f"  {name:<15} would say gamma = {c.gamma:.6g} J/m^2 ({ours}{c.formula})")
        if fit.spread is not None:     # gamma under the other roughness laws; its warnings leave the fit trustworthy
            out += [f"  {line}" for line in spread_lines(fit.spread)]
    else:
        m, f = fit.measured, fit.fitted
        out.append(f"fit of the curve {fit.data.path or ''}: {fit.data.z.size} points, "
                   f"{_count(fit.traces, 'curve')} traced, {_count(fit.iterations, 'evaluation')}, "
                   f"{fit.wall_time_s:.3g} s ({fit.status})")
        out.append(f"  gamma = {_pm(fit.gamma, 1.0, 'J/m^2')}   E* = {_pm(fit.E_star, 1e9, 'GPa')}   "
                   f"mu = {fit.mu:.4g}   K = {fit.K:.4g}")
        if fit.rms is not None:
            out.append(f"  rms = {_pm(fit.rms, 1e-9, 'nm', '.4g')}   sigma = {fit.sigma:.4g}")
        out.append(f"  contact point z0 = {_pm(fit.z0, 1e-9, 'nm')}   baseline F0 = {_pm(fit.F0, 1e-9, 'nN', '.5g')}")
        ins = fit.instrument
        if ins is not None:
            out.append(f"  sensitivity scale c = {_pm(ins.invols_scale, 1.0, '', '.5g')}   spring k = "
                       f"{_pm(ins.spring, 1.0, 'N/m', '.5g')}")
            out.append(f"  virtual deflection = {_pm(ins.virtual_deflection, 1.0, 'N/m', '.4g')}   drag = "
                       f"{_pm(ins.drag, 1e-9, 'nN', '.4g')}   fitted: {fit.segment}"
                       + (f", z in [{fit.z_range[0] * 1e9:.6g}, {fit.z_range[1] * 1e9:.6g}] nm"
                          if fit.z_range is not None else ""))
        red = f"{fit.reduced_chi2:.3g}" if math.isfinite(fit.reduced_chi2) else "undefined"
        out.append(f"  noise {fit.noise_N * 1e9:.3g} nN{' (stated)' if fit.noise_stated else ''}, residual rms "
                   f"{fit.residual_rms_N * 1e9:.3g} nN, reduced chi^2 {red} ({fit.dof} degrees of freedom); "
                   f"pull-off measured {m.pull_off_N * 1e9:.4g} nN, fitted {f.pull_off_N * 1e9:.4g} nN")
        if fit.spread is not None:     # w and E* under the other roughness laws
            out += [f"  {line}" for line in spread_lines(fit.spread)]
    for n in getattr(fit, "notes", ()):
        out.append(f"  note: {n}")
    for w in fit.warnings:
        out.append(f"  WARNING: {w}")
    tell("\n".join(out))
