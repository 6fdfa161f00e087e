"""The closed forms (DMT, JKR, Maugis-Dugdale) against the model's own pull-off: the table of docs/fitting.md
"How far JKR, DMT and Maugis-Dugdale are from the model", made by
``python -m petsc_adhesion.benchmarks.fitting pull_off``."""

import math
import time

__all__ = ["PULL_OFF_MUS", "pull_off_rows", "pull_off_section"]

#: Tabor parameters of the pull-off table.
PULL_OFF_MUS = (0.01, 0.03, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 7.0, 10.0)


# -- the closed forms against the model's pull-off ----------------------------------------
def pull_off_rows() -> list:
    """For each mu of PULL_OFF_MUS: the model's load-controlled pull-off (best value and bar), and the work of
    adhesion DMT, JKR and Maugis-Dugdale give from the pull-off force it makes, against the true one."""
    import petsc4py

    petsc4py.init([])
    from ..fitting.pull_off import closed_forms, model_pull_off
    from ..model.parameters import Model
    from ..model.physical import Bodies

    rows = []
    R, eps, w, nu = 1e-6, 0.4e-9, 0.05, 0.3
    for mu in PULL_OFF_MUS:
        t = time.perf_counter()
        e = model_pull_off(Model(mu=mu), error_bars=True)
        E = w * math.sqrt(R / (mu**3 * eps**3))                 # eq. (9) solved for E*
        b = Bodies(radius=R, young1=E * (1 - nu**2), poisson1=nu, epsilon=eps, gamma=w)
        P = abs(e.F) * 2 * math.pi * R * w
        cf = closed_forms(P, b)
        rows.append({"mu": mu, "F": e.F, "F_err": e.F_err, "seconds": time.perf_counter() - t,
                     **{f"{c.name}_ratio": c.gamma / w for c in cf}})
        print(f"mu = {mu:g}: F = {e.F:.6f}", flush=True)
    return rows


def pull_off_section(rows: list, made: dict) -> str:
    lines = ["## How far JKR, DMT and Maugis-Dugdale are from the model", "",
             "<!-- made by: python -m petsc_adhesion.benchmarks.fitting pull_off (data: docs/data/fitting_pull_off.json;"
             " -table redraws from it) -->", "",
             "A sphere of the model at Tabor parameter mu pulls off at P = |F_p(mu)| 2 pi R w (load control, the "
             "smooth half-infinite model, its best value extrapolated over nested grids, with its bar).  Given that "
             "P, each closed form gives a work of adhesion; the table is its distance from the true w, in per cent "
             "(DMT: P / 2 pi R; JKR: P / 1.5 pi R; Maugis-Dugdale: solved self-consistently with lambda_MD = "
             "1.157 mu(w), since mu itself moves with w by eq. 9).  `-fit_pull_off` gives w back from the model's "
             "own pull-off, to its bar.", "",
             "| mu | model pull-off F_p (2 pi R w) | DMT w / w - 1 | JKR w / w - 1 | Maugis-Dugdale w / w - 1 |",
             "|---|---|---|---|---|"]
    for r in rows:
        bar = f" +- {r['F_err']:.1e}" if r.get("F_err") else ""
        lines.append(f"| {r['mu']:g} | {r['F']:.6f}{bar} | {100 * (r['dmt_ratio'] - 1):+.2f}% | "
                     f"{100 * (r['jkr_ratio'] - 1):+.2f}% | {100 * (r['maugis_dugdale_ratio'] - 1):+.2f}% |")
    worst = {k: max(rows, key=lambda r: abs(r[f"{k}_ratio"] - 1)) for k in ("dmt", "jkr", "maugis_dugdale")}
    lines += ["", "Largest distances over the table: " + "; ".join(
        f"{name} {100 * (worst[k][f'{k}_ratio'] - 1):+.1f}% (mu = {worst[k]['mu']:g})"
        for k, name in (("dmt", "DMT"), ("jkr", "JKR"), ("maugis_dugdale", "Maugis-Dugdale"))) + "."]
    return "\n".join(lines) + "\n"
