"""Fitting measurements with the model: the tables and figures of docs/fitting.md.

    python -m petsc_adhesion.benchmarks.fitting pull_off   # JKR, DMT, Maugis-Dugdale against ours, by mu
    python -m petsc_adhesion.benchmarks.fitting coverage   # do the curve fit's 95% intervals hold? (about 30 min)
    python -m petsc_adhesion.benchmarks.fitting real       # the measured curve of tests/data, fitted, with its figure
    python -m petsc_adhesion.benchmarks.fitting speed [-before] [-cache DIR] [-mus 0.001,0.1]  # one fit's CPU
    python -m petsc_adhesion.benchmarks.fitting table_coverage [-cases N] [-cache DIR] [-collect]   # mu 1e-3 to 1e3
    mpiexec -n 2 python -m petsc_adhesion.benchmarks.fitting table_coverage -cases 200 -cache DIR   # over ranks
    python -m petsc_adhesion.benchmarks.fitting -table     # the sections again from docs/data/fitting_*.json

Each part writes its JSON into docs/data/ and its section of docs/fitting.md (in
place of the one there).  The coverage runs its cases in two processes; ``speed`` and
``table_coverage`` run theirs one after the other in this process (``speed`` times
each fit's CPU, ``time.process_time``), keeping the synthetic curves they made in
``-cache DIR`` (made once, by the solver; a later run fits them again).
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import closed_forms, paths

__all__ = ["COVERAGE_MUS", "COVERAGE_SEEDS", "REAL", "coverage_case", "main"]

DOC = os.path.join(paths.DOCS, "fitting.md")
#: Tabor parameters of the coverage study, each with COVERAGE_SEEDS noise streams.
COVERAGE_MUS = (0.3, 0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0)
COVERAGE_SEEDS = (1, 2, 3)
#: The synthetic measurement: tip radius (m), epsilon (m), spring constant (N/m), work of adhesion (J/m^2),
#: the noise (a share of 2 pi R w), points per leg.
SYNTH = {"radius": 20e-9, "epsilon": 0.3e-9, "spring": 1.0, "gamma": 0.05, "noise_share": 0.01, "points": 300}
#: The measured curve of tests/data and what is assumed of it (docs/fitting.md).
REAL = {"file": "tests/data/fmt-igor-fd_SiN_FD_plot.ibw", "spring": 1.18, "radius": 20e-9, "epsilon": 0.3e-9,
        "young1": 250e9, "poisson1": 0.25}


#: The speed of one fit: Tabor parameters, and the seeds at each (one where a curve costs a minute or more).
SPEED_MUS = (1e-3, 0.1, 1.0, 10.0, 100.0, 1000.0)
SPEED_SEEDS = {1e-3: (1, 2, 3, 4, 5), 0.1: (1, 2, 3, 4, 5), 1.0: (1, 2, 3, 4, 5), 10.0: (1, 2, 3, 4, 5),
               100.0: (1, 2, 3), 1000.0: (1, 2, 3)}
#: The solver path (-fit_table none) timed where it takes minutes at most: today's fits, "before".
BEFORE_MUS = (1e-3, 0.1, 1.0)
#: The coverage over the table's range: cases drawn (stream TABLE_COVERAGE_SEED) log-uniform in mu over
#: [1e-3, 1e3] and in the spring K over [1e-4, 0.5] (units 2 pi R w / eps: a 2 mN/m to 10 N/m lever on a 20 nm
#: tip at w = 0.05 J/m^2), the noise one of 0.3%, 1%, 3% of 2 pi R w.
TABLE_COVERAGE_SEED = 3434
NOISE_SHARES = (0.003, 0.01, 0.03)
#: The largest roughness sigma = rms / eps drawn; the version of the cases and of the synthetic curves (a
#: journal's or the data file's rows of another version are not this study's: the retract reaching its
#: pull-off since version 2; version 3: the fit's steps and bars on the solver's Jacobian, the rebuilt tables,
#: the truths from mu = 20 on in units of mu; version 4: a rough truth's and a rough branch's bends bounded
#: (-cont_dF_bend), a rough fit searched on the rough table first and from several sigma, a search on a table
#: allowed 5 times the cap on evaluations; version 5: the rough table rebuilt with its nodes' bends bounded;
#: version 6: the starts' contact point on the least force where a curve has no jump-off, a rough start's w the
#: pull-off table's, the rough table to mu = 10).
SIGMA_TOP = 2.0
TABLE_COVERAGE_VERSION = 6
#: In the order the cases run: one rough case after every ROUGH_EVERY smooth ones.
ROUGH_EVERY = 4


def _data(name: str) -> str:
    return os.path.join(paths.DATA, f"fitting_{name}.json")


def _init():
    import petsc4py

    petsc4py.init([])


# -- coverage ------------------------------------------------------------------------
def coverage_case(mu: float, seed: int) -> dict:
    """One synthetic curve (forward solver, finer steps than the fit's, noise of ``seed``) and its fit."""
    _init()
    from ..fitting.curve_fit import fit_curve
    from ..fitting.results import Spring
    from ..fitting.synthetic import Sampling, synthetic_curve
    from ..io.fit import fit_record
    from ..model.physical import Bodies
    from ..tracing.trace import curve_settings

    s = SYNTH
    R, eps, k, w = s["radius"], s["epsilon"], s["spring"], s["gamma"]
    E = w * math.sqrt(R / (mu**3 * eps**3))                      # eq. (9) solved for E*
    rng = np.random.default_rng(1000 + seed)
    z0, F0 = float(rng.uniform(-20e-9, 20e-9)), float(rng.uniform(-1e-9, 1e-9))
    noise = s["noise_share"] * 2 * math.pi * R * w
    t = time.perf_counter()
    truth = Bodies(radius=R, young1=E, poisson1=0.0, epsilon=eps, gamma=w)
    data = synthetic_curve(truth, Spring(k), Sampling(noise=noise, points=s["points"], z0=z0, F0=F0, seed=seed),
                           settings=curve_settings(observable_max=2.0, ds_max=0.2, observable_step=0.1))
    made = time.perf_counter() - t
    fit = fit_curve(data, Bodies(radius=R, young1=None, poisson1=None, epsilon=eps), Spring(k), table="none")
    row = {"mu": mu, "seed": seed, "gamma": w, "E_star": E, "z0_m": z0, "F0_N": F0, "noise_N": noise,
           "K": data.metadata["K"], "synth_s": made}
    f = fit_record(fit)
    row["fit"] = {k_: f[k_] for k_ in ("gamma", "gamma_err", "E_star", "E_star_err", "mu", "reduced_chi2",
                                       "p_value", "traces", "iterations", "wall_time_s", "status", "notes",
                                       "warnings") if k_ in f}
    row["fit"]["z0_m"], row["fit"]["z0_err_m"] = f["offsets"]["z0_m"], f["offsets"]["z0_err_m"]
    return row


def _case_process(args) -> dict:
    mu, seed = args
    p = subprocess.run([sys.executable, "-m", "petsc_adhesion.benchmarks.fitting", "-case", repr(mu), str(seed)],
                       capture_output=True, text=True, cwd=paths.ROOT)
    if p.returncode:
        return {"mu": mu, "seed": seed, "error": (p.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(p.stdout.strip().splitlines()[-1])


def _inside(row: dict, key: str, err: str = "") -> bool | None:
    f = row.get("fit")
    if not f or not f.get(f"{key}_err{err}"):
        return None
    return abs(f[key] - row[key]) <= 1.96 * f[f"{key}_err{err}"]


def coverage_section(rows: list, made: dict) -> str:
    ok = [r for r in rows if "fit" in r and r["fit"].get("gamma_err") and r["fit"].get("E_star_err")]
    lines = ["## Coverage of the curve fit's intervals", "",
             "<!-- made by: python -m petsc_adhesion.benchmarks.fitting coverage (data: docs/data/fitting_coverage.json;"
             " -table redraws from it) -->", "",
             f"Synthetic curves made by the forward solver (R = {SYNTH['radius'] * 1e9:g} nm, epsilon = "
             f"{SYNTH['epsilon'] * 1e9:g} nm, k = {SYNTH['spring']:g} N/m, w = {SYNTH['gamma']:g} J/m^2, E* from "
             f"mu by eq. 9; {SYNTH['points']} points a leg; Gaussian noise of {SYNTH['noise_share']:.0%} of "
             f"2 pi R w; the contact point and baseline drawn at random), traced with steps half the fit's "
             f"(`ds_max` 0.2, `cont_dF_max` 0.1), fitted by `fit_curve` with nothing but R, epsilon and k given, on the "
             f"solver's curves throughout (`-fit_table none`; through the table: \"Coverage over the table's range\"). "
             f"{len(ok)} of {len(rows)} cases fitted; mu = {', '.join(f'{m:g}' for m in COVERAGE_MUS)}, seeds "
             f"{', '.join(str(s) for s in COVERAGE_SEEDS)}.", ""]
    for key, label in (("gamma", "w"), ("E_star", "E*")):
        for err, what in (("_fit", "the Jacobian's bar alone"), ("", "the stated bar")):
            got = [_inside(r, key, err) for r in ok]
            got = [g for g in got if g is not None]
            if got:
                lines.append(f"- {label}: the true value inside the 95% interval (+-1.96 bars) of {what} in "
                             f"**{sum(got)} of {len(got)}** cases ({sum(got) / len(got):.0%}).")
    zs = {k: [(r["fit"][k] - r[k]) / r["fit"][f"{k}_err"] for r in ok] for k in ("gamma", "E_star")}
    if ok:
        lines += ["", f"Mean (fitted - true) / bar: w {np.mean(zs['gamma']):+.2f}, E* {np.mean(zs['E_star']):+.2f}; "
                      f"standard deviation w {np.std(zs['gamma']):.2f}, E* {np.std(zs['E_star']):.2f} (1 for bars that "
                      f"are right).  The bars are the Jacobian's, s^2 (J^T J)^-1, with no model-error term: the "
                      f"coverage measured does not call for one at this noise.  E* comes out low by about half a bar "
                      f"on average (a bias whose cause is not located here; the synthetic curves are traced with "
                      f"finer steps than the fit's), and the one miss of w is at mu = 10, "
                      f"where the bars are narrowest relative to the curve's resolution."]
    lines += ["", "| mu | seed | w fitted (J/m^2) | (w - w_true) / bar | E* fitted (Pa) | (E* - E*_true) / bar | "
              "reduced chi^2 | curves traced | fit time (s) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "fit" not in r:
            lines.append(f"| {r['mu']:g} | {r['seed']} | failed: {r['error']} | | | | | | |")
            continue
        if r not in ok:
            lines.append(f"| {r['mu']:g} | {r['seed']} | undetermined: {'; '.join(r['fit'].get('warnings', []))} "
                         f"| | | | | | |")
            continue
        f = r["fit"]
        lines.append(f"| {r['mu']:g} | {r['seed']} | {f['gamma']:.5g} +- {f['gamma_err']:.2g} | "
                     f"{(f['gamma'] - r['gamma']) / f['gamma_err']:+.2f} | {f['E_star']:.5g} +- {f['E_star_err']:.2g} | "
                     f"{(f['E_star'] - r['E_star']) / f['E_star_err']:+.2f} | {f['reduced_chi2']:.3f} | "
                     f"{f['traces']} | {f['wall_time_s']:.1f} |")
    times = [r["fit"]["wall_time_s"] for r in ok]
    if times:
        lines += ["", f"Fit times: median {np.median(times):.1f} s, longest {max(times):.1f} s (two fits at a time "
                      f"on a machine of {os.cpu_count()} cores shared with other work, load average 5 to 7; the "
                      f"study took {made.get('study_s', 0) / 60:.1f} min).  Alone on a core, one fit takes about "
                      f"10 s at mu = 1, 50 s at mu = 3 and 140 s at mu = 10 (`-bench_only fit` times mu = 1)."]
    return "\n".join(lines) + "\n"


# -- the speed and the coverage over the table's range ------------------------------------
def table_cases(n: int) -> list[dict]:
    """The first ``n`` cases of the coverage over the table's range: mu, K, the noise's share, sigma (0 for
    half of them, else uniform in (0, SIGMA_TOP]), the seed."""
    rng = np.random.default_rng(TABLE_COVERAGE_SEED)
    out = []
    for i in range(n):
        mu = float(10 ** rng.uniform(-3, 3))
        K = float(10 ** rng.uniform(-4, math.log10(0.5)))
        noise = float(NOISE_SHARES[int(rng.integers(len(NOISE_SHARES)))])
        rough = bool(rng.uniform() < 0.5)
        sigma = float(rng.uniform(0.0, SIGMA_TOP)) if rough else 0.0
        out.append({"case": i, "mu": mu, "K": K, "noise_share": noise, "sigma": round(sigma, 6), "seed": 100 + i})
    return out


#: The noiseless curves made in this process, by (mu, K, R, finer).
_CLEAN: dict = {}


def _synthetic(mu: float, K: float, noise_share: float, seed: int, cache: str | None, finer: bool,
               sigma: float = 0.0, comm=None):
    """A synthetic curve made by the solver (finer steps than the fit's where ``finer``) at (mu, K) with noise,
    the contact point and baseline drawn from ``seed``; read from ``cache`` where it was made before. (data,
    truth dict, the bodies given to the fit, the spring)."""
    from ..fitting.data import MeasuredCurve
    from ..fitting.results import Spring
    from ..discretization.problem import step_scale
    from ..fitting.synthetic import Sampling, rough_truth, synthetic_curve, truth_settings
    from ..model.parameters import Model
    from ..model.physical import Bodies
    from ..tracing.trace import curve_settings

    s = SYNTH
    # the tip's radius grows with mu above 1 as the indentation at the top load does (about 5 mu epsilon at
    # F = 2), so that it stays below a sixth of R, inside the model's domain (R / 4, domain.py)
    R, eps, w = s["radius"] * max(1.0, mu), s["epsilon"], s["gamma"]
    E = w * math.sqrt(R / (mu**3 * eps**3))                      # eq. (9) solved for E*
    k = K * 2 * math.pi * R * w / eps
    rng = np.random.default_rng(1000 + seed)
    z0, F0 = float(rng.uniform(-20e-9, 20e-9)), float(rng.uniform(-1e-9, 1e-9))
    noise = noise_share * 2 * math.pi * R * w
    tag = ("" if R == s["radius"] else f"_R{R:.4g}") + (f"_s{sigma:.6g}" if sigma > 0 else "")
    name = None if cache is None else \
        os.path.join(cache, f"curve_{mu:.6g}_{K:.6g}_{noise_share:g}_{seed}_{int(finer)}{tag}.npz")
    made = math.nan
    if name is not None and os.path.exists(name):
        with np.load(name) as z:
            data = MeasuredCurve(z=z["z"], F=z["F"], turn=int(z["turn"]), direction=1, spring=k, source="synthetic")
    else:
        c0 = time.process_time()
        # finer: steps half the fit's; from mu = 20 on in units of mu, where units of 1 would pass the
        # continuation's cap of 5000 steps above mu of about 100 (fitting/synthetic.py truth_settings)
        settings = None if not finer else rough_truth(curve_settings(observable_max=2.0, ds_max=0.2,
                                                                     observable_step=0.1), Model(mu=mu, sigma=sigma),
                                                      2.0) \
            if step_scale(Model(mu=mu)) == 1.0 else truth_settings(Model(mu=mu, sigma=sigma), 2.0, finer=2.0)
        made_of = (mu, K, R, finer, sigma)
        if made_of not in _CLEAN:      # one truth's noiseless curve, traced once: each seed shifts it, adds noise
            _CLEAN[made_of] = synthetic_curve(Bodies(radius=R, young1=E, poisson1=0.0, epsilon=eps, gamma=w,
                                                     rms=sigma * eps if sigma > 0 else None),
                                              Spring(k), Sampling(points=s["points"]), settings=settings,
                                              comm=comm)
        c = _CLEAN[made_of]            # as synthetic_curve adds them: z0 and F0, then the noise of the seed
        F = c.F + F0 + noise * np.random.default_rng(seed).standard_normal(c.F.size)
        data = MeasuredCurve(z=c.z + z0, F=F, turn=c.turn, direction=1, spring=k, source="synthetic")
        made = time.process_time() - c0
        if name is not None:
            np.savez(name, z=data.z, F=data.F, turn=data.turn)
    truth = {"mu": mu, "K": K, "gamma": w, "E_star": E, "z0_m": z0, "noise_N": noise, "made_cpu_s": made, "R": R,
             "sigma": sigma, "rms": sigma * eps}
    return data, truth, Bodies(radius=R, young1=None, poisson1=None, epsilon=eps), Spring(k)


def _fit_row(data, truth, bodies, spring, table, rough: bool = False, comm=None) -> dict:
    """One fit of a synthetic curve (its roughness fitted where ``rough``), timed (CPU), against the truth."""
    from ..fitting.curve_fit import TableStep, fit_curve
    from ..fitting.results import FitChoice

    c0, t0 = time.process_time(), time.perf_counter()
    try:
        fit = fit_curve(data, bodies, spring, FitChoice(roughness=rough), table=table, comm=comm)
    except ValueError as e:
        return {**truth, "error": str(e).splitlines()[0]}
    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
    row = {**truth, "cpu_s": cpu, "wall_s": wall, "traces": fit.traces, "iterations": fit.iterations,
           "reduced_chi2": fit.reduced_chi2, "mu_fit": fit.mu, "warnings": list(fit.warnings)}
    for key in ("gamma", "E_star", "rms"):
        q = getattr(fit, key)
        row[f"{key}_fit"] = getattr(q, "value", None)
        row[f"{key}_err"] = getattr(q, "err", None)
    if isinstance(fit.path, TableStep):
        row["search_cpu_s"] = fit.path.seconds
        row["curves"] = fit.path.curves
        row["shared"] = fit.path.shared
        row["differenced"] = fit.path.differenced     # the curves of the solver's Jacobian's branch columns
        row["lattice_mu"] = fit.path.lattice_mu
        row["step_bars"] = {c: float(b) for c, b in zip(fit.path.coordinates, fit.path.bars)}
        row["table_share"] = {c: float(v) for c, v in zip(fit.path.coordinates, fit.path.contribution)}
    else:
        row["path"] = fit.path
    return row


def _partial(name: str, rows: list) -> None:
    """The rows so far (a study stopped part way keeps them: ``-table`` redraws from the file)."""
    with open(_data(name) + ".partial", "w") as f:
        json.dump({"made": {"load": f"{os.getloadavg()[0]:.1f}", "partial": True, **paths.source()}, "rows": rows},
                  f, indent=1)


def speed_rows(before: bool, cache: str | None, mus: tuple | None = None) -> list:
    """The CPU of one fit through the table (and with ``before`` on the solver alone) at SPEED_MUS (``mus``: those
    of them alone): at each mu curves of one truth with the noise of each seed, fitted one after the other in this
    process (the first at a mu traces its solver curve, the later ones find it where they land on its lattice
    point)."""
    _init()
    import scipy.stats  # noqa: F401  (a fit's p-value imports it once a process: 1 s, outside the timings)

    from ..family.table import shipped
    from ..fitting.branches import BRANCHES

    shipped()                                            # read once, outside the timings
    rows = []
    K = SYNTH["spring"] * SYNTH["epsilon"] / (2 * math.pi * SYNTH["radius"] * SYNTH["gamma"])
    for mu in [m for m in (BEFORE_MUS if before else SPEED_MUS) if mus is None or m in mus]:
        BRANCHES.clear()                                # each mu's first fit pays for its curves
        for order, seed in enumerate(SPEED_SEEDS[mu][:1] if before else SPEED_SEEDS[mu]):
            data, truth, bodies, spring = _synthetic(mu, K, SYNTH["noise_share"], seed, cache, finer=False)
            row = _fit_row(data, truth, bodies, spring, "none" if before else "default")
            row.update(seed=seed, path_kind="solver" if before else "table", order=order)
            rows.append(row)
            _partial("speed_before" if before else "speed", rows)
            print(f"mu {mu:g} seed {seed}: {row.get('cpu_s', math.nan):.3f} s CPU, traces {row.get('traces')}, "
                  f"shared {row.get('shared')}", flush=True)
    return rows


def speed_section(rows: list, made: dict) -> str:
    lines = ["## The speed of a curve fit", "",
             "<!-- made by: python -m petsc_adhesion.benchmarks.fitting speed [-before] -cache DIR (data: "
             "docs/data/fitting_speed.json; -table redraws from it) -->", "",
             f"Fits of synthetic curves (made by the solver: R = {SYNTH['radius'] * 1e9:g} nm times mu above 1, "
             f"inside the model's domain at the top load; epsilon = "
             f"{SYNTH['epsilon'] * 1e9:g} nm, K = 0.048 (k = 1 N/m at R = 20 nm), w = {SYNTH['gamma']:g} J/m^2, noise "
             f"{SYNTH['noise_share']:.0%} of 2 pi R w, {SYNTH['points']} points a leg), at each mu one truth with the "
             "noise of several seeds fitted one after the other in one process, their CPU time "
             "(`time.process_time`; the machine's two cores shared with other work, load average "
             f"{made.get('load', '?')}).  The first fit at a mu traces its solver curve(s); a later one finds a "
             "curve traced before where it lands on the same lattice point (`shared`), else traces its own.  "
             "Through the table: the search (`TableStep.seconds`) and the rest, nearly all the solver's curves.  "
             "`-fit_table none`: the solver's curves throughout (before).", "",
             "| mu | path | first fit CPU (s) | later fits | their median CPU (s) | their CPU (s) | search, median (s) "
             "| solver curves (traced / found) |",
             "|---|---|---|---|---|---|---|---|"]
    for kind in ("table", "solver"):
        for mu in SPEED_MUS:
            sel = [r for r in rows if r.get("path_kind") == kind and r["mu"] == mu and "cpu_s" in r]
            if not sel:
                continue
            first, later = sel[0], sel[1:]
            mu_cell = f"{mu:g}" if "earlier" not in first else f"{mu:g} (an earlier run, {first['earlier']})"
            search = [r["search_cpu_s"] for r in sel if "search_cpu_s" in r]
            cpus = [r["cpu_s"] for r in later]
            med = f"{np.median(cpus):.3g}" if cpus else "-"
            each = ", ".join(f"{c:.2g}" for c in cpus) or "-"
            counts = ", ".join(f"{r['traces']}/{r.get('shared', 0)}" for r in sel)
            lines.append(f"| {mu_cell} | {kind} | {first['cpu_s']:.3g} | {len(later)} | {med} | {each} | "
                         f"{f'{np.median(search):.3g}' if search else '-'} | {counts} |")
    refused = [r for r in rows if "cpu_s" not in r]
    for r in refused:
        lines.append(f"\nmu = {r['mu']:g}: {r.get('error', 'no fit')}")
    return "\n".join(lines) + "\n"


def _journal_rows(cache: str | None) -> dict:
    """The finished cases of this version (TABLE_COVERAGE_VERSION), by case number: the journals in ``cache``
    (one a rank: table_coverage.<rank>.jsonl, a line a case) and the rows of the data file (a next session's
    start: the committed study continues)."""
    done = {}
    if os.path.exists(_data("table_coverage")):
        with open(_data("table_coverage")) as f:
            done.update((r["case"], r) for r in json.load(f).get("rows", [])
                        if r.get("version") == TABLE_COVERAGE_VERSION)
    if cache:
        for name in sorted(os.listdir(cache)):
            if name.startswith("table_coverage.") and name.endswith(".jsonl"):
                with open(os.path.join(cache, name)) as f:
                    for line in f:
                        try:
                            r = json.loads(line)
                        except json.JSONDecodeError:      # a line cut by a kill: the case runs again
                            continue
                        if r.get("version") == TABLE_COVERAGE_VERSION:
                            done[r["case"]] = r
    return done


def table_coverage_rows(n: int, cache: str | None, make_only: bool = False, made_only: bool = False,
                        collect: bool = False, only: str | None = None) -> list:
    """The first ``n`` cases of :func:`table_cases`, the cheapest first (the smooth by mu, a rough one after
    every ROUGH_EVERY of them), dealt to the
    MPI ranks in turn: each a curve made by the solver (finer steps than the fit's), fitted through the default
    table (its roughness fitted where the truth's sigma > 0); each finished case journaled at once by its rank
    (``cache``/table_coverage.<rank>.jsonl), and a case journaled before (by any number of ranks, or in the
    data file) not run again: a kill or a next session continues.  Returns every finished case's row on rank 0
    (``make_only``: the curves made into the cache only, no rows; ``made_only``: the cases whose curve is in
    the cache alone; ``collect``: none run, the journaled rows gathered into the data file, as while another
    run goes on), None on the others.  ``only``: "smooth" or "rough", those cases alone."""
    _init()
    from petsc4py import PETSc

    world = PETSc.COMM_WORLD.tompi4py()
    rank, size = world.Get_rank(), world.Get_size()
    done = _journal_rows(cache)
    # the cheapest first among the cases left: the smooth by mu (through the table), one rough case (its
    # roughness fitted on the solver's curves, a hundred times the CPU at low mu) after every ROUGH_EVERY
    left = [] if collect else [c for c in table_cases(n) if c["case"] not in done and
                               (only is None or (c["sigma"] > 0) == (only == "rough"))]
    smooth = sorted((c for c in left if c["sigma"] == 0), key=lambda c: c["mu"])
    rough = sorted((c for c in left if c["sigma"] > 0), key=lambda c: c["mu"])
    todo = sorted(smooth + rough, key=lambda c: (smooth.index(c) if c in smooth else
                                                ROUGH_EVERY * (rough.index(c) + 1) - 0.5))
    journal = None if cache is None or make_only else \
        open(os.path.join(cache, f"table_coverage.{rank}.jsonl"), "a")
    if rank == 0:
        print(f"{len(done)} of {n} cases journaled before; {len(todo)} to run on {size} rank(s)", flush=True)
    for case in todo[rank::size]:
        tag = ("" if case["mu"] <= 1 else f"_R{SYNTH['radius'] * case['mu']:.4g}") + \
            (f"_s{case['sigma']:.6g}" if case["sigma"] > 0 else "")
        name = f"curve_{case['mu']:.6g}_{case['K']:.6g}_{case['noise_share']:g}_{case['seed']}_1{tag}.npz"
        if made_only and not (cache and os.path.exists(os.path.join(cache, name))):
            continue
        try:
            data, truth, bodies, spring = _synthetic(case["mu"], case["K"], case["noise_share"], case["seed"],
                                                     cache, finer=True, sigma=case["sigma"], comm=PETSc.COMM_SELF)
        except Exception as e:          # the solver's failure to make the truth: said in the row, not fitted
            data, truth = None, {"mu": case["mu"], "K": case["K"], "sigma": case["sigma"],
                                 "error": f"the synthetic curve: {str(e).splitlines()[0] if str(e) else type(e).__name__}"}
        if make_only:
            continue
        row = truth if data is None else \
            _fit_row(data, truth, bodies, spring, "default", case["sigma"] > 0, PETSc.COMM_SELF)
        row.update(case=case["case"], noise_share=case["noise_share"], seed=case["seed"],
                   version=TABLE_COVERAGE_VERSION, ranks=size)
        if journal is not None:                 # on disk before the next case: a kill loses that one alone
            journal.write(json.dumps(row) + "\n"), journal.flush(), os.fsync(journal.fileno())
        done[case["case"]] = row
        print(json.dumps({k: row.get(k) for k in ("case", "mu", "K", "sigma", "gamma_fit", "gamma_err", "cpu_s",
                                                 "error")}), flush=True)
    journal.close() if journal is not None else None
    world.Barrier()
    if rank != 0 or make_only:
        return None if rank else []
    rows = sorted(_journal_rows(cache).values() if cache else done.values(), key=lambda r: r["mu"])
    return [r for r in rows if r["case"] < n]


def table_coverage_section(rows: list, made: dict) -> str:
    keys = (("gamma", "w", "ln_gamma"), ("E_star", "E*", "ln_E_star"), ("rms", "rms", "sigma"))
    with_bar = {key: [r for r in rows if r.get(f"{key}_err") and r.get(f"{key}_fit") is not None]
                for key, _, _ in keys}
    n_cases = made.get("cases", max([r["case"] for r in rows], default=-1) + 1)
    lines = ["## Coverage over the table's range", "",
             "<!-- made by: python -m petsc_adhesion.benchmarks.fitting table_coverage -cases N -cache DIR (data: "
             "docs/data/fitting_table_coverage.json; -table redraws from it; mpiexec -n 2 deals the cases to two "
             "ranks; a journal in DIR and the data file's rows: a killed or later run continues) -->", "",
             f"Synthetic curves made by the solver (not by the table; steps half the fit's; the retract past its "
             f"pull-off), the cases drawn log-uniform in mu over [1e-3, 1e3] and in K over [1e-4, 0.5], the noise "
             f"{', '.join(f'{x:.1%}' for x in NOISE_SHARES)} of 2 pi R w, sigma 0 for half of them and uniform in "
             f"(0, {SIGMA_TOP:g}] for the others (R = {SYNTH['radius'] * 1e9:g} nm times mu above 1, epsilon = "
             f"{SYNTH['epsilon'] * 1e9:g} nm, w = {SYNTH['gamma']:g} J/m^2, {SYNTH['points']} points a leg), each "
             f"fitted through the package's tables (the rough one, with the roughness fitted, where sigma > 0) with "
             f"R, epsilon and k given.  {len(rows)} of the first {n_cases} cases run so far (the cheapest first: "
             f"the smooth by mu, a rough one after every {ROUGH_EVERY}), spanning mu {min(r['mu'] for r in rows):.3g} to {max(r['mu'] for r in rows):.3g} "
             f"and sigma up to {max(r.get('sigma', 0.0) for r in rows):.2g}; "
             f"their fits' CPU {sum(r.get('cpu_s', 0.0) for r in rows):.0f} s." if rows else "No case run yet.", ""]
    for key, label, coord in keys:
        ok = with_bar[key]
        truth = (lambda r: r["rms"]) if key == "rms" else (lambda r, key=key: r[key])
        inside = [abs(r[f"{key}_fit"] - truth(r)) <= 1.96 * r[f"{key}_err"] for r in ok]
        ratio = [r[f"{key}_err"] / max(abs(r[f"{key}_fit"] - truth(r)), 1e-300) for r in ok]
        if inside:
            lines.append(f"- {label}: a bar in {len(ok)} cases, the truth inside its 95% interval in "
                         f"**{sum(inside)} of {len(inside)}** ({sum(inside) / len(inside):.0%}); median bar / error "
                         f"{np.median(ratio):.2g}.")
    lines.append("")
    missing = [r for r in rows if not with_bar["gamma"].count(r)]
    if rows:
        lines.append(f"Where w has no bar ({len(missing)} cases): " + ("; ".join(
            f"mu {r['mu']:.3g}, K {r['K']:.2g}, sigma {r.get('sigma', 0.0):.2g}" for r in missing) or "none") + ".  "
            "E* without a bar: " + (", ".join(f"mu {r['mu']:.3g} (K {r['K']:.2g})" for r in rows
                                              if r not in with_bar['E_star']) or "none") + ".")
    lines += ["", "| case | mu | K | sigma | noise | w fitted (J/m^2) | (w - w_true) / bar | E* fitted (Pa) | "
              "(E* - E*_true) / bar | sigma fitted | (sigma - sigma_true) / bar | reduced chi^2 | CPU (s) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]

    def cell(r, key):
        if r.get(f"{key}_err") and r.get(f"{key}_fit") is not None:
            t = r["rms"] if key == "rms" else r[key]
            f, e = r[f"{key}_fit"], r[f"{key}_err"]
            if key == "rms":
                f, e, t = f / SYNTH["epsilon"], e / SYNTH["epsilon"], t / SYNTH["epsilon"]
            return f"{f:.5g} +- {e:.2g}", f"{(f - t) / e:+.2f}"
        why = [w.split(":", 1)[1].strip() for w in r.get("warnings", []) if w.startswith(f"{key} undetermined")]
        return (f"none: {why[0]}" if why else "-"), ""

    for r in rows:
        head = f"| {r.get('case', '')} | {r['mu']:.3g} | {r['K']:.2g} | {r.get('sigma', 0.0):.2g} | " \
               f"{r.get('noise_share', 0):.1%} |"
        if "error" in r:
            lines.append(f"{head} {r['error']} | | | | | | | |")
            continue
        w, e, g = cell(r, "gamma"), cell(r, "E_star"), cell(r, "rms") if r.get("sigma", 0) > 0 else ("-", "")
        lines.append(f"{head} {w[0]} | {w[1]} | {e[0]} | {e[1]} | {g[0]} | {g[1]} | {r['reduced_chi2']:.3g} | "
                     f"{r['cpu_s']:.2f} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> int:
    if argv[:1] == ["-case"]:
        print(json.dumps(coverage_case(float(argv[1]), int(argv[2]))))
        return 0
    value = {a: argv[i + 1] for i, a in enumerate(argv[:-1]) if a in ("-cache", "-cases", "-mus", "-only")}
    if value.get("-only", "smooth") not in ("smooth", "rough"):
        print(f"-only {value['-only']}: expected smooth or rough (the cases of sigma = 0, or the others)",
              file=sys.stderr)
        return 2
    try:
        mus = None if "-mus" not in value else tuple(float(m) for m in value["-mus"].split(","))
    except ValueError:
        print(f"-mus {value['-mus']}: expected Tabor parameters separated by commas, of {SPEED_MUS}", file=sys.stderr)
        return 2
    if mus is not None and not set(mus) <= set(SPEED_MUS):
        print(f"-mus {value['-mus']}: expected Tabor parameters of {', '.join(f'{m:g}' for m in SPEED_MUS)}",
              file=sys.stderr)
        return 2
    parts = [a for a in argv if not a.startswith("-") and a not in value.values()] or ["pull_off", "real", "coverage"]
    redraw = "-table" in argv
    cache = value.get("-cache")
    if cache is not None:
        os.makedirs(cache, exist_ok=True)
    os.makedirs(paths.DATA, exist_ok=True)
    if "pull_off" in parts:
        if not redraw:
            t = time.perf_counter()
            rows = closed_forms.pull_off_rows()
            with open(_data("pull_off"), "w") as f:
                json.dump({"made": {"seconds": time.perf_counter() - t, **paths.source()}, "rows": rows}, f, indent=1)
        with open(_data("pull_off")) as f:
            d = json.load(f)
        text = closed_forms.pull_off_section(d["rows"], d["made"])
        paths.write_section(DOC, text)
        print(text)
    for part, rows_of, section in (("speed", lambda: speed_rows("-before" in argv, cache, mus), speed_section),
                                   ("table_coverage", lambda: table_coverage_rows(int(value.get("-cases", 60)), cache,
                                                                    "-make_only" in argv, "-made_only" in argv,
                                                                    "-collect" in argv, value.get("-only")),
                                    table_coverage_section)):
        if part not in parts:
            continue
        if not redraw:
            t = time.perf_counter()
            rows = rows_of()
            if not rows:                                    # -make_only: the curves are in the cache
                continue
            old = []
            if part == "speed" and os.path.exists(_data(part)):       # -before adds to the table path's rows
                with open(_data(part)) as f:
                    was = json.load(f)
                # and -mus to the rows of the other mu, each said to be of an earlier run (its commit)
                commit = str(was["made"].get("commit") or "?")[:7]
                old = [r for r in was["rows"] if r.get("path_kind") != rows[0].get("path_kind")] + \
                    [{**r, "earlier": r.get("earlier", commit)} for r in was["rows"]
                     if r.get("path_kind") == rows[0].get("path_kind") and mus is not None and r["mu"] not in mus]
            with open(_data(part), "w") as f:
                json.dump({"made": {"seconds": time.perf_counter() - t, "load": f"{os.getloadavg()[0]:.1f}",
                                    "cases": int(value.get("-cases", 60)), **paths.source()}, "rows": old + rows},
                          f, indent=1)
        with open(_data(part)) as f:
            d = json.load(f)
        text = section(d["rows"], d["made"])
        paths.write_section(DOC, text)
        print(text)
    if "coverage" in parts:
        if not redraw:
            t = time.perf_counter()
            cases = [(m, s) for m in COVERAGE_MUS for s in COVERAGE_SEEDS]
            cases.sort(key=lambda c: -c[0])                     # the longest first
            with ThreadPoolExecutor(2) as pool:
                rows = list(pool.map(_case_process, cases))
            rows.sort(key=lambda r: (r["mu"], r["seed"]))
            with open(_data("coverage"), "w") as f:
                json.dump({"made": {"study_s": time.perf_counter() - t, **paths.source()}, "rows": rows}, f, indent=1)
        with open(_data("coverage")) as f:
            d = json.load(f)
        text = coverage_section(d["rows"], d["made"])
        paths.write_section(DOC, text)
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
