"""docs/validation.md: the paper's numbers beside ours, and the analytic limits, from the studies.

    ./run figures paper_model validation     # the paper's model, then the comparison with the figNN studies

Every number is read from the JSON summaries (and, for the profiles' peaks, the HDF5
files) of the studies that make the paper's figures (``./run figures figNN``, run
first) and of ``options/paper_model.opts`` (the paper's truncated model on its grid):
no second path to the numbers.  The limits come from :mod:`petsc_adhesion.model.reference`.
"""
from __future__ import annotations

import json
import math
import os

from ..model.reference.jkr import jkr_zero_load
from ..model.reference.maugis_dugdale import maugis_dugdale_pull_off
from ..model.reference.rigid import rigid_load
from . import paths

__all__ = ["PAPER", "write", "FIG", "REDUCTION"]

FIG = paths.FIGURES

#: The numbers of the paper's results section: (what, mu, sigma, event, key, paper value as printed, note).
#: event: pull_off, snap_on, snap_off (primary), equilibrium; key: lambda, F, H0.
PAPER = [
    ("pull-off F, smooth, small mu (Fig. 4)", 0.01, 0.0, "pull_off", "F", "-1", ""),
    ("pull-off lambda, smooth, small mu", 0.01, 0.0, "pull_off", "lambda", "0", ""),
    ("equilibrium, mu = 0.01", 0.01, 0.0, "equilibrium", "lambda", "0.206", "paper note 7: the mu = 0 value 1 - 2^(-1/3)"),
    ("equilibrium, mu = 0.01 (Fig. 13 text)", 0.01, 0.0, "equilibrium", "lambda", "0.21", ""),
    ("snap-off lambda, mu = 1 (the paper's A)", 1.0, 0.0, "snap_off", "lambda", "-1.74", "paper note 4: called snap-on there"),
    ("snap-on lambda, mu = 1 (the paper's B)", 1.0, 0.0, "snap_on", "lambda", "-1.63", "paper note 4: called snap-off there"),
    ("equilibrium, mu = 1", 1.0, 0.0, "equilibrium", "lambda", "2.07", ""),
    ("equilibrium, mu = 7", 7.0, 0.0, "equilibrium", "lambda", "13.44", "the N = 531 grid does not resolve mu = 7"),
    ("pull-off F, mu = 0.01, sigma = 0.2", 0.01, 0.2, "pull_off", "F", "-0.64", ""),
    ("pull-off lambda, mu = 0.01, sigma = 0.2", 0.01, 0.2, "pull_off", "lambda", "-0.42", ""),
    ("pull-off F, mu = 0.01, sigma = 0.4", 0.01, 0.4, "pull_off", "F", "-0.18", "paper note 5: printed 0.18"),
    ("pull-off F, mu = 0.01, sigma = 1", 0.01, 1.0, "pull_off", "F", "-0.03", ""),
    ("pull-off lambda, mu = 0.01, sigma = 1", 0.01, 1.0, "pull_off", "lambda", "-5.78", ""),
    ("equilibrium, mu = 0.01, sigma = 1", 0.01, 1.0, "equilibrium", "lambda", "-5.71", ""),
    ("pull-off F, mu = 2", 2.0, 0.0, "pull_off", "F", "-0.79", ""),
    ("pull-off lambda, mu = 2", 2.0, 0.0, "pull_off", "lambda", "-1.66", ""),
    ("pull-off F, mu = 2, sigma = 0.2", 2.0, 0.2, "pull_off", "F", "-0.52", ""),
    ("pull-off lambda, mu = 2, sigma = 0.2", 2.0, 0.2, "pull_off", "lambda", "-1.71", ""),
    ("pull-off F, mu = 2, sigma = 0.4", 2.0, 0.4, "pull_off", "F", "-0.167", ""),
    ("pull-off lambda, mu = 2, sigma = 0.4", 2.0, 0.4, "pull_off", "lambda", "-2.31", ""),
    ("pull-off F, mu = 2, sigma = 1", 2.0, 1.0, "pull_off", "F", "-0.03", ""),
    ("pull-off lambda, mu = 2, sigma = 1", 2.0, 1.0, "pull_off", "lambda", "-5.91", ""),
    ("snap-on lambda, mu = 2", 2.0, 0.0, "snap_on", "lambda", "-2.55", ""),
    ("snap-on F, mu = 2", 2.0, 0.0, "snap_on", "F", "-1.82", "paper note 6: ten times ours"),
    ("snap-off lambda, mu = 2", 2.0, 0.0, "snap_off", "lambda", "-3.38", ""),
    ("snap-off F, mu = 2", 2.0, 0.0, "snap_off", "F", "-4.54", "paper note 6: ten times ours"),
    ("snap-on lambda, mu = 2, sigma = 0.2", 2.0, 0.2, "snap_on", "lambda", "-2.58", ""),
    ("snap-on F, mu = 2, sigma = 0.2", 2.0, 0.2, "snap_on", "F", "-1.80", "paper note 6: ten times ours"),
    ("snap-off lambda, mu = 2, sigma = 0.2", 2.0, 0.2, "snap_off", "lambda", "-2.95", ""),
    ("snap-off F, mu = 2, sigma = 0.2", 2.0, 0.2, "snap_off", "F", "-3.17", "paper note 6: ten times ours"),
    ("snap-on lambda, mu = 2, sigma = 0.3", 2.0, 0.3, "snap_on", "lambda", "-2.61", ""),
    ("snap-on F, mu = 2, sigma = 0.3", 2.0, 0.3, "snap_on", "F", "-1.79", "paper note 6: ten times ours"),
    ("snap-off lambda, mu = 2, sigma = 0.3", 2.0, 0.3, "snap_off", "lambda", "-2.63", "paper note 5: printed 2.63"),
    ("snap-off F, mu = 2, sigma = 0.3", 2.0, 0.3, "snap_off", "F", "-2.01", "paper note 6: ten times ours"),
    ("equilibrium, mu = 2", 2.0, 0.0, "equilibrium", "lambda", "4.00", ""),
    ("equilibrium, mu = 2, sigma = 0.2", 2.0, 0.2, "equilibrium", "lambda", "2.59", ""),
    ("equilibrium, mu = 2, sigma = 0.4", 2.0, 0.4, "equilibrium", "lambda", "-0.364", ""),
    ("equilibrium, mu = 2, sigma = 1", 2.0, 1.0, "equilibrium", "lambda", "-5.28", ""),
    ("H(0) at pull-off, mu = 2 (Fig. 15)", 2.0, 0.0, "pull_off", "H0", "-0.009", ""),
    ("H(0) at pull-off, mu = 2, sigma = 0.2", 2.0, 0.2, "pull_off", "H0", "0.419", ""),
    ("H(0) at pull-off, mu = 2, sigma = 0.4", 2.0, 0.4, "pull_off", "H0", "1.760", ""),
    ("H(0) at pull-off, mu = 2, sigma = 1", 2.0, 1.0, "pull_off", "H0", "5.902", "just above the rule's wall, 5.63"),
    ("H(0) at equilibrium, mu = 2 (Fig. 16)", 2.0, 0.0, "equilibrium", "H0", "-0.0270", ""),
    ("H(0) at equilibrium, mu = 2, sigma = 0.2", 2.0, 0.2, "equilibrium", "H0", "0.4154", ""),
    ("H(0) at equilibrium, mu = 2, sigma = 0.4", 2.0, 0.4, "equilibrium", "H0", "1.7512", ""),
    ("H(0) at equilibrium, mu = 2, sigma = 1", 2.0, 1.0, "equilibrium", "H0", "5.7412", ""),
]
#: The paper's reduction rates (eq. 29): (mu, sigma, percent); mu = 2's from its Fig. 14 text.
REDUCTION = [(0.01, 0.2, 36), (0.01, 0.4, 82), (0.01, 1.0, 97), (2.0, 0.2, 34), (2.0, 0.4, 79), (2.0, 1.0, 96)]


def _cases(name: str) -> list[dict]:
    with open(os.path.join(FIG, f"{name}.json")) as f:
        return json.load(f)["cases"]


def _event(case: dict, event: str) -> dict | None:
    if event == "pull_off":
        return case["pull_off"]
    if event == "equilibrium":
        return case["equilibria"][0] if case["equilibria"] else None
    folds = [e for e in case["folds"] if e["kind"] == event]
    pick = max if event == "snap_on" else min               # the primary pair
    return pick(folds, key=lambda e: e["lambda"]) if folds else None


def _find(cases: list[dict], mu: float, sigma: float) -> dict | None:
    return next((c for c in cases if math.isclose(c["mu"], mu) and math.isclose(c["sigma"], sigma)), None)


def _ours(sources, mu, sigma, event, key):
    for cases in sources:
        c = _find(cases, mu, sigma)
        e = _event(c, event) if c else None
        if e is not None and key in e:
            return e[key], e.get(f"{key}_err", 0.0) if key != "H0" else None
    return None, None


def _fmt(x, bar) -> str:
    if x is None:
        return "-"
    return f"{x:.5f}" + (f" +- {bar:.1e}" if bar else "")


def _verdict(paper: str, x, bar, note: str) -> str:
    if x is None:
        return "not computed"
    p = float(paper)
    digits = len(paper.split(".")[1]) if "." in paper else 0
    half = 0.5 * 10.0 ** -digits
    if abs(x - p) <= half + (bar or 0.0):
        return "agrees to the paper's digits"
    if "ten times" in note and abs(10 * x - p) <= 10 * half:
        return "agrees x10 (paper note 6)"
    return f"differs by {x - p:+.2g}"


def _paper_table() -> list[str]:
    default = [_cases(n) for n in ("fig04", "fig05", "fig08", "fig13", "fig14", "fig15", "fig16")]
    paper_model = [_cases("paper_model")]
    rows = ["| quantity | paper | ours (half-infinite model, default grids) | verdict | ours (paper's truncated "
            "model, N = 531) | verdict | note |", "|---|---|---|---|---|---|---|"]
    for what, mu, sigma, event, key, paper, note in PAPER:
        x, bar = _ours(default, mu, sigma, event, key)
        y, ybar = _ours(paper_model, mu, sigma, event, key)
        rows.append(f"| {what} | {paper} | {_fmt(x, bar)} | {_verdict(paper, x, bar, note)} | {_fmt(y, ybar)} | "
                    f"{_verdict(paper, y, ybar, note) if y is not None else '-'} | {note} |")
    return rows


def _reduction_table() -> list[str]:
    cases = _cases("fig17") + _cases("fig18")
    rows = ["| mu | sigma | paper | ours |", "|---|---|---|---|"]
    for mu, sigma, percent in REDUCTION:
        c, c0 = _find(cases, mu, sigma), _find(cases, mu, 0.0)
        if c is None or c0 is None:
            continue
        F, F0 = c["pull_off"]["F"], c0["pull_off"]["F"]
        bar = (c["pull_off"]["F_err"] + abs(F / F0) * c0["pull_off"]["F_err"]) / abs(F0)
        rows.append(f"| {mu:g} | {sigma:g} | {percent}% | {100 * (1 - F / F0):.2f}% +- {100 * bar:.1g}% |")
    return rows


def _limits() -> list[str]:
    smooth = sorted((c for c in _cases("fig18") if c["sigma"] == 0.0), key=lambda c: c["mu"])
    rows = ["| mu | pull-off F (ours) | 1 + F: distance from DMT | F + 0.75: from JKR | Maugis-Dugdale | "
            "ours / MD - 1 | equilibrium lambda (ours) | JKR zero-load lambda | ours / JKR - 1 |",
            "|---|---|---|---|---|---|---|---|---|"]
    for c in smooth:
        po, eq = c["pull_off"], c["equilibria"][0]
        md = float(maugis_dugdale_pull_off(c["mu"]))
        _, lam_jkr = jkr_zero_load(c["mu"])
        rows.append(f"| {c['mu']:.4g} | {po['F']:.6f} +- {po['F_err']:.1e} | {1 + po['F']:.2e} | "
                    f"{po['F'] + 0.75:.2e} | {md:.5f} | {po['F'] / md - 1:+.2%} | {eq['lambda']:.4f} | "
                    f"{lam_jkr:.4f} | {eq['lambda'] / lam_jkr - 1:+.2%} |")
    small = smooth[:2]
    rate = math.log((1 + small[1]["pull_off"]["F"]) / (1 + small[0]["pull_off"]["F"])) / \
        math.log(small[1]["mu"] / small[0]["mu"])
    big = smooth[-2:]
    jrate = math.log((big[1]["pull_off"]["F"] + 0.75) / (big[0]["pull_off"]["F"] + 0.75)) / \
        math.log(big[1]["mu"] / big[0]["mu"])
    eq0 = _find(_cases("fig04"), 0.01, 0.0)["equilibria"][0]["lambda"]
    return rows + ["", f"The distance from DMT shrinks as mu^{rate:.2f} between the two smallest mu, the "
                   f"distance from JKR as mu^{jrate:.2f} between the two largest.  At mu = 0.01 the equilibrium "
                   f"approach is {eq0:.5f}, against the rigid (mu = 0, eq. 28) 1 - 2^(-1/3) = "
                   f"{1 - 2 ** (-1 / 3):.5f}, where the rigid load {rigid_load(1 - 2 ** (-1 / 3)):.1e} vanishes."]


def write() -> None:
    """Write docs/validation.md from the studies' files (run them first)."""
    text = ["<!-- made by: ./run figures validation (petsc_adhesion/benchmarks/validation.py) -->", "# Validation", "",
            "Every number of the paper's results section beside ours, and the analytic limits; made by "
            "`./run figures paper_model validation` from the studies of the paper's figures (options/figNN.opts) and of "
            "its own model (options/paper_model.opts: truncated at r_m = 10 with no far field, its N = 531 "
            "grid).  Ours carry their error bars; the paper's numbers are rounded to the digits it prints.  "
            "A verdict \"agrees\" means the two differ by less than half a unit of the paper's last digit "
            "plus our bar.  A paper note is one of the numbered notes on the paper's typos in "
            "[model.md](model.md#where-the-paper-is-wrong-and-what-we-do).", "", "## The paper's numbers", "", *_paper_table(), "",
            "Where we differ, and why we keep our numbers:", "",
            "- The pull-off lambda: F is flat at its minimum, so lambda_p is ill-conditioned (a change of 1e-5 "
            "in F moves it by ~1e-2); the paper's grid and ours differ by more than that.  Our bars say how "
            "well ours is known.",
            "- The loads at the mu = 2 turning points are ten times ours in the paper (paper note 6): they cannot "
            "be on the scale of the pull-off it quotes for the same curve (-0.79), the most tensile load.",
            "- The half-infinite model adds the rigid sphere's attraction beyond r_m = 10, which the paper "
            "leaves out: it moves the equilibria by up to ~1e-3 (mu = 1) and the small-mu pull-off by ~5e-4.",
            "- The equilibrium at mu = 7: the paper's grid (spacing 0.02 at the contact edge) does not resolve "
            "the cohesive zone there (0.04 wide; 5 nodes across it need 0.008), and its own model on that grid "
            "shows a staircase of spurious turning points (docs/figures/coarse.md); ours is on grids that do.",
            "- The profiles' H(0) at pull-off and equilibrium at mu = 2 with roughness depend on the "
            "16-point rule's wall (docs/model.md); where the paper and we differ there, both are properties "
            "of the rule.", "",
            "## The reduction of the pull-off by roughness (eq. 29, Figs. 13, 14, 17)", "", *_reduction_table(), "",
            "## Analytic limits", "",
            "The smooth pull-off of the Fig. 18 study (options/fig18.opts) against the DMT limit (F_p -> -1 as "
            "mu -> 0), the JKR limit (F_p -> -0.75 as mu grows), Maugis-Dugdale's pull-off with the Lennard-Jones "
            "peak stress as the Dugdale stress (lambda_MD = 1.157 mu, reference.maugis_parameter), and the JKR "
            "approach at zero load against our equilibrium (lambda_JKR = [(9 pi/2)^(2/3) - (2 pi (9 pi/2)^(1/3))^(1/2)] mu "
            "= 1.949 mu, measured from first touch: an O(1) shift is beyond JKR).", "", *_limits(), ""]
    with open(os.path.join(paths.DOCS, "validation.md"), "w") as f:
        f.write("\n".join(text))


if __name__ == "__main__":
    write()
