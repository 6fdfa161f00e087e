"""A fit's result files and console lines (docs/output.md, docs/fitting.md): the ``fit`` of the JSON summary
and the HDF5 group of the same name, the CSV of a fitted curve, the report.

The fit's summary is the library's (:attr:`~petsc_adhesion.fitting.pull_off.PullOffFit.summary`,
:attr:`~petsc_adhesion.fitting.curve_fit.CurveFit.summary`); a curve's data and the fitted
model's force at its points go into the HDF5 file's ``fit/data`` and the CSV.
"""
from __future__ import annotations

import csv

import numpy as np

from ..errors import tell

__all__ = ["fit_tree", "fit_summary", "write_fit_csv", "report_fit", "DESCRIBE_FIT"]

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
    "fit/measured": ("*_N: N; *_m: m", "what the curve shows by itself: baseline, noise, largest force, pull-off "
                     "and its position, jump-in and its size"),
    "fit/fitted": ("*_N: N; *_m: m", "the fitted model's jump-in and jump-off positions and pull-off force"),
    "fit/fixed": ("E_star: Pa", "parameters held at a given value (-fit_modulus false)"),
    "fit/given": ("*_m: m; spring_N_m: N/m; E_star_start: Pa", "the given constants: tip radius, epsilon, spring "
                  "constant (and where it came from), the modulus the fit started from"),
    "fit/data": ("z: m; F, F_fit: N", "the measured curve and the fit at its points: piezo displacement z, force F "
                 "(tensile negative), leg (0 approach, 1 retract), F_fit, used (0: left out, next to a jump)"),
    "fit/model": ("z: m; F_*: N", "the fitted model's force on an even grid of z on the approach and the retract"),
}


def fit_summary(head: dict, options: dict, fit_summary_: dict) -> dict:
    """The JSON summary of a fit: the program, the options as given, the fit."""
    return {**head, "kind": "fit", "options": options, "fit": fit_summary_}


def fit_tree(head: dict, options: dict, fit_summary_: dict, data: dict | None = None,
             model: dict | None = None) -> dict:
    """The HDF5 tree of a fit: its summary, the covariance as a matrix, the data and the model's curve."""
    fit = dict(fit_summary_)
    if "covariance" in fit:
        fit["covariance"] = np.asarray(fit["covariance"], dtype=float)
    fit.pop("notes", None)
    fit["notes"] = list(fit_summary_.get("notes", ())) or ""
    if data is not None:
        fit["data"] = {k: np.asarray(v) for k, v in data.items()}
    if model is not None:
        fit["model"] = {k: np.asarray(v) for k, v in model.items()}
    return {**head, "kind": "fit", "options": options, "fit": fit}


def write_fit_csv(path: str, data: dict) -> None:
    """A row per measured point: z (m), F (N), leg (0 approach, 1 retract), F_fit (N), used (0/1)."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["z_m", "F_N", "leg", "F_fit_N", "used"])
        for row in zip(data["z"], data["F"], data["leg"], data["F_fit"], data["used"]):
            w.writerow([f"{row[0]:.10g}", f"{row[1]:.10g}", int(row[2]), f"{row[3]:.10g}", int(row[4])])


def _pct(x: float, ref: float) -> str:
    return f"{100 * (x / ref - 1):+.1f}%"


def report_fit(s: dict) -> None:
    """The console lines of a fit's summary (rank 0)."""
    out = []
    if s["kind"] == "pull_off":
        err = f" +- {s['P_err_N'] * 1e9:.3g}" if s["P_err_N"] else ""
        out.append(f"fit of the pull-off P = {s['P_N'] * 1e9:.6g}{err} nN: {s['curves_traced']} curves traced, "
                   f"{s['wall_time_s']:.3g} s")
        out.append(f"  gamma = {s['gamma']:.6g} +- {s['gamma_err']:.2g} J/m^2   mu = {s['mu']:.6g}   sigma = "
                   f"{s['sigma']:g}   model pull-off F = {s['F_pull_off']:.8f} +- {s['F_pull_off_err']:.1e} "
                   f"(2 pi R gamma)")
        names = {"jkr": "JKR", "dmt": "DMT", "maugis_dugdale": "Maugis-Dugdale"}
        for key, name in names.items():
            c = s["closed_forms"][key]
            out.append(f"  {name:<15} would say gamma = {c['gamma']:.6g} J/m^2 ({_pct(c['gamma'], s['gamma'])} "
                       f"from ours; {c['formula']})")
    else:
        out.append(f"fit of the curve {s['given'].get('file', '')}: {s['n_points']} points, {s['traces']} curves "
                   f"traced, {s['iterations']} evaluations, {s['wall_time_s']:.3g} s ({s['status']})")
        out.append(f"  gamma = {s['gamma']:.6g} +- {s['gamma_err']:.2g} J/m^2   E* = {s['E_star'] / 1e9:.6g} +- "
                   f"{s['E_star_err'] / 1e9:.2g} GPa   mu = {s['mu']:.4g}   K = {s['K']:.4g}")
        if s.get("rms") is not None:
            bar = f" +- {s['rms_err'] * 1e9:.2g}" if s.get("rms_err") else " (held)"
            out.append(f"  rms = {s['rms'] * 1e9:.4g}{bar} nm   sigma = {s['sigma']:.4g}")
        o = s["offsets"]
        out.append(f"  contact point z0 = {o['z0_m'] * 1e9:.6g} +- {o['z0_err_m'] * 1e9:.2g} nm   baseline F0 = "
                   f"{o['F0_N'] * 1e9:.5g} +- {o['F0_err_N'] * 1e9:.2g} nN")
        out.append(f"  noise {s['noise_N'] * 1e9:.3g} nN, residual rms {s['residual_rms_N'] * 1e9:.3g} nN, reduced "
                   f"chi^2 {s['reduced_chi2']:.3g} ({s['dof']} degrees of freedom); pull-off measured "
                   f"{s['measured']['pull_off_N'] * 1e9:.4g} nN, fitted {s['fitted']['pull_off_N'] * 1e9:.4g} nN")
    for n in s.get("notes", ()):
        out.append(f"  note: {n}")
    tell("\n".join(out))
