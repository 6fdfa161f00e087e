"""A population's result files and console lines (docs/population.md): the CSV of a row per particle, the
HDF5 file, the JSON summary, the figure, the report.

The only place a :class:`~petsc_adhesion.population.results.PopulationResult` becomes keys: its values are
read by attribute (a Measured's value and bar as ``x`` and ``x_err``; a Missing as an empty cell, null,
or NaN in a dataset, with its reason beside it).
"""
from __future__ import annotations

import csv
import math
import textwrap

import numpy as np

from ..errors import tell
from ..tracing.measured import Measured

__all__ = ["population_summary", "write_population", "report_population", "COLUMNS"]

#: The CSV's columns, a row per particle.
COLUMNS = ("index", "radius_m", "site_x_m", "site_y_m", "mu", "footprint_radius_m", "pixels", "independent",
           "rms_m", "skewness", "sigma", "F", "F_err", "force_N", "force_err_N", "passes", "note", "missing",
           "energy", "energy_err", "energy_J", "energy_err_J", "energy_missing")


def _num(x) -> object:
    return "" if x is None else x


def _pair(q) -> list:
    """A Measured's value and bar as two cells; a Missing's as two empty ones."""
    return [q.value, _num(q.err)] if isinstance(q, Measured) else ["", ""]


def _row(p) -> list:
    po = p.pull_off
    site = p.site or (None, None)
    return [p.index, p.radius, _num(site[0]), _num(site[1]), p.mu, _num(p.footprint_radius), p.pixels,
            p.independent, _num(p.rms), _num(p.skewness), _num(p.sigma), *_pair(po), *_pair(p.force),
            p.passes, p.note, "" if isinstance(po, Measured) else po.reason, *_pair(p.energy), *_pair(p.work),
            "" if isinstance(p.energy, Measured) else p.energy.reason]


def write_csv(path: str, result) -> None:
    """A row per particle (:data:`COLUMNS`): F in units 2 pi R w (negative), force_N its magnitude in N; a
    missing pull-off empty with its reason under ``missing``; the energy of a cycle in units 2 pi R w epsilon
    and in J (0: no hysteresis), a missing one empty with its reason under ``energy_missing``."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for p in result.particles:
            w.writerow(_row(p))


def _measured(q) -> dict:
    return {"value": q.value, "err": q.err} if isinstance(q, Measured) else {"value": None, "missing": q.reason}


def _finite(a) -> list:
    return [None if not math.isfinite(float(x)) else float(x) for x in a]


#: The most distinct reasons of missing pull-offs the report and the summary name (the CSV has every one).
REASONS = 5


def _reasons(result, energy: bool = False) -> tuple[list, int]:
    """The commonest reasons of the missing pull-offs (``energy``: energies of a cycle) with their counts (at
    most REASONS), and how many other reasons there are."""
    from collections import Counter

    which = [p.energy.reason for p in result.energy_missing] if energy else \
        [p.pull_off.reason for p in result.missing]
    counts = Counter(which).most_common()
    return counts[:REASONS], max(0, len(counts) - REASONS)


def _lognormal(fit) -> dict:
    if hasattr(fit, "median"):
        return {"median": fit.median.value, "median_err": fit.median.err, "gsd": fit.gsd.value,
                "gsd_err": fit.gsd.err, "count": fit.count, "resamples": fit.resamples}
    return {"missing": fit.reason}


def population_summary(head: dict, given: dict, result) -> dict:
    """The JSON summary: the inputs, the counts, the lognormal fit, the bins, the model spread."""
    topo = result.topography
    fit = result.fit
    out = {**head, "options": given, "population": {
        "evaluator": result.evaluator, "seed": result.seed, "count": len(result.particles),
        "radius_law": result.law.describe(), "zone_share": result.zone_share,
        "topography": {"path": topo.path, "pixels": list(topo.pixels), "size_m": list(topo.size),
                       "rms_m": topo.stats.rms.value, "rms_err_m": topo.stats.rms.err,
                       "independent": topo.stats.independent[0]},
        "bodies": result.bodies.describe()["inputs"] | {"gamma_J_m2": result.bodies.work_of_adhesion},
        "pull_offs": int(result.forces.size), "missing": len(result.missing), "flagged": len(result.flagged),
        "missing_reasons": [{"reason": r, "count": n} for r, n in _reasons(result)[0]],
        "missing_other_reasons": _reasons(result)[1],
        "ranks": result.ranks, "wall_time_s": result.wall_time, "cpu_time_s": result.cpu_time}}
    pop = out["population"]
    if hasattr(fit, "median"):
        pop["lognormal"] = {"median_N": fit.median.value, "median_err_N": fit.median.err, "gsd": fit.gsd.value,
                            "gsd_err": fit.gsd.err, "count": fit.count, "resamples": fit.resamples}
    else:
        pop["lognormal"] = {"missing": fit.reason}
    works = result.works
    reasons, others = _reasons(result, energy=True)
    pop["energy_of_a_cycle"] = {
        "machine": "rigid", "unit": "J", "computed": int(works.size), "zero": int(np.sum(works == 0)),
        "positive": int(np.sum(works > 0)), "missing": len(result.energy_missing),
        "missing_reasons": [{"reason": r, "count": n} for r, n in reasons], "missing_other_reasons": others,
        "lognormal": {(f"{k}_J" if k.startswith("median") else k): v for k, v in _lognormal(result.energy_fit).items()}}
    bins = result.bins
    pop["radius_bins"] = {"missing": bins.reason} if not hasattr(bins, "edges") else {
        "edges_m": _finite(bins.edges), "count": [int(c) for c in bins.count], "median_N": _finite(bins.median),
        "p16_N": _finite(bins.p16), "p84_N": _finite(bins.p84)}
    sp = result.spread
    pop["model_spread"] = {"missing": sp.reason} if not hasattr(sp, "indices") else {
        "rule_source": sp.rule_source, "particles": len(sp.indices), "pairs": int(sp.relative.size),
        "relative_median": sp.median, "relative_p16": sp.p16, "relative_p84": sp.p84,
        "numerical_relative": sp.numerical, "model_decides": sp.decides}
    return out


#: HDF5 datasets of the particles: name -> (units, description).
_DATASETS = {"index": ("", "the particle's index (its draws from the seed)"), "radius": ("m", "radius"),
             "site": ("m", "the footprint's centre from the first pixel (NaN: none fits the scan)"),
             "mu": ("", "Tabor's parameter at the particle's radius (eq. 9)"),
             "footprint_radius": ("m", "the footprint's radius (NaN: none)"), "pixels": ("", "pixels under it"),
             "independent": ("", "the independent samples under it (the map's N_2 share)"),
             "rms": ("m", "the footprint's rms from its mean plane (NaN: none)"),
             "skewness": ("", "its skewness (NaN: none, or flat)"), "sigma": ("epsilon", "rms / epsilon"),
             "F": ("2 pi R w", "pull-off load (NaN: missing, its reason in 'missing')"),
             "F_err": ("2 pi R w", "its bar (NaN: none)"), "force": ("N", "the pull-off force's magnitude"),
             "force_err": ("N", "its bar"), "passes": ("", "solves of the footprint iteration (0: table)"),
             "energy": ("2 pi R w epsilon", "the energy a cycle under a rigid machine dissipates (0: no hysteresis; "
                        "NaN: missing, its reason in 'energy_missing')"),
             "energy_err": ("2 pi R w epsilon", "its bar (NaN: none)"), "work": ("J", "the energy of a cycle"),
             "work_err": ("J", "its bar")}


def _particle_arrays(result) -> dict:
    ps = result.particles
    nan = math.nan

    def arr(f):
        return np.array([nan if (v := f(p)) is None else v for p in ps], dtype=float)
    return {"index": np.array([p.index for p in ps]), "radius": arr(lambda p: p.radius),
            "site": np.array([p.site if p.site else (nan, nan) for p in ps], dtype=float).reshape(len(ps), 2),
            "mu": arr(lambda p: p.mu), "footprint_radius": arr(lambda p: p.footprint_radius),
            "pixels": np.array([p.pixels for p in ps]), "independent": arr(lambda p: p.independent),
            "rms": arr(lambda p: p.rms), "skewness": arr(lambda p: p.skewness), "sigma": arr(lambda p: p.sigma),
            "F": arr(lambda p: p.pull_off.value if isinstance(p.pull_off, Measured) else None),
            "F_err": arr(lambda p: p.pull_off.err if isinstance(p.pull_off, Measured) else None),
            "force": arr(lambda p: p.force.value if isinstance(p.force, Measured) else None),
            "force_err": arr(lambda p: p.force.err if isinstance(p.force, Measured) else None),
            "passes": np.array([p.passes for p in ps]),
            "energy": arr(lambda p: p.energy.value if isinstance(p.energy, Measured) else None),
            "energy_err": arr(lambda p: p.energy.err if isinstance(p.energy, Measured) else None),
            "work": arr(lambda p: p.work.value if isinstance(p.work, Measured) else None),
            "work_err": arr(lambda p: p.work.err if isinstance(p.work, Measured) else None)}


def write_h5(path: str, summary: dict, result) -> None:
    """The HDF5 file: /particles (a dataset per column, with units and a description; the notes and
    reasons as strings) and /population (the summary's values as attributes, the bins as datasets)."""
    import json

    import h5py

    with h5py.File(path, "w") as f:
        g = f.create_group("particles")
        g.attrs["description"] = "a row per particle, index order (docs/population.md)"
        for name, data in _particle_arrays(result).items():
            d = g.create_dataset(name, data=data)
            d.attrs["units"], d.attrs["description"] = _DATASETS[name]
        s = h5py.string_dtype()
        g.create_dataset("note", data=np.array([p.note for p in result.particles], dtype=object), dtype=s)
        g.create_dataset("missing", data=np.array(["" if isinstance(p.pull_off, Measured) else p.pull_off.reason
                                                   for p in result.particles], dtype=object), dtype=s)
        g.create_dataset("energy_missing", data=np.array(["" if isinstance(p.energy, Measured) else p.energy.reason
                                                          for p in result.particles], dtype=object), dtype=s)
        pop = f.create_group("population")
        pop.attrs["description"] = "the inputs, the lognormal fit of the forces (N), the bins, the model spread"
        pop.attrs["summary_json"] = json.dumps(summary["population"], default=float)
        bins = result.bins
        if hasattr(bins, "edges"):
            for name, data, unit in (("edges", bins.edges, "m"), ("count", bins.count, ""),
                                     ("median", bins.median, "N"), ("p16", bins.p16, "N"), ("p84", bins.p84, "N")):
                d = pop.create_dataset(f"bins_{name}", data=data)
                d.attrs["units"] = unit
        sp = result.spread
        if hasattr(sp, "indices"):
            d = pop.create_dataset("spread_relative", data=sp.relative)
            d.attrs["description"] = f"(rule - measured) / |measured| of the subsample; rule: {sp.rule_source}"


def _histogram(ax, x: np.ndarray, fit, scale: float, unit: str, label: str) -> None:
    """The histogram of the positive values ``x`` (SI) in ``unit`` (SI times ``scale``), log-spaced bins, with
    the density of the lognormal ``fit`` (SI) where there is one."""
    if x.size:
        edges = np.geomspace(x.min(), x.max() * 1.0001, max(5, min(40, int(np.sqrt(x.size)) + 1)))
        ax.hist(x, bins=edges, density=True, color="0.7", label=label)
        ax.set_xscale("log")
    if hasattr(fit, "median") and x.size:
        grid = np.geomspace(x.min(), x.max(), 200)
        m, s = math.log(fit.median.value * scale), math.log(fit.gsd.value)
        if s > 0:
            ax.plot(grid, np.exp(-(np.log(grid) - m) ** 2 / (2 * s * s)) / (grid * s * math.sqrt(2 * math.pi)), "k-",
                    label=f"lognormal: median {fit.median.value * scale:.3g} {unit}, gsd {fit.gsd.value:.3g}")
    ax.set_ylabel(f"density (1/{unit})")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)


def figure(result, path: str, fmt: str) -> None:
    """The histogram of |F| (N) with the fitted lognormal's density, |F| against the radius with the bins'
    median and 16-84 % band, and the histogram of the positive energies of a cycle with theirs (or, where
    there is none, why)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    F = result.forces * 1e9
    radii = np.array([p.radius for p in result.particles if isinstance(p.pull_off, Measured)]) * 1e6
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(15, 4))
    _histogram(a, F, result.fit, 1e9, "nN", f"{F.size} particles ({result.evaluator})")
    a.set_xlabel("pull-off force |F| (nN)")
    works = result.works
    W = works[works > 0] * 1e15
    _histogram(c, W, result.energy_fit, 1e15, "fJ", f"{W.size} particles with hysteresis")
    c.set_xlabel("energy of a cycle, rigid machine (fJ)")
    if not W.size or not hasattr(result.energy_fit, "median"):
        why = result.energy_fit.reason if hasattr(result.energy_fit, "reason") else ""
        c.text(0.5, 0.5, "\n".join(textwrap.wrap(f"no lognormal of the energies: {why}", 40)), ha="center",
               va="center", transform=c.transAxes, fontsize=8)
    b.plot(radii, F, ".", ms=3, color="0.5", label="particles")
    bins = result.bins
    if hasattr(bins, "edges"):
        mid = np.sqrt(bins.edges[:-1] * bins.edges[1:]) * 1e6 if bins.edges.size > 2 else \
            np.array([bins.edges[0] * 1e6])
        b.errorbar(mid, bins.median * 1e9, yerr=[(bins.median - bins.p16) * 1e9, (bins.p84 - bins.median) * 1e9],
                   fmt="ko-", capsize=3, label="median, 16-84 %")
    b.set_xlabel("radius R (um)")
    b.set_ylabel("|F| (nN)")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, format=fmt, dpi=120)
    plt.close(fig)


def write_population(result, summary: dict, files, fmt: str | None = None) -> None:
    """The files of a population into the temporaries of ``files`` (a ResultSet; the caller commits)."""
    from .write import write_json

    if "out" in files.targets:
        write_h5(files.temp("out"), summary, result)
    if "summary" in files.targets:
        write_json(files.temp("summary"), summary)
    if "csv" in files.targets:
        write_csv(files.temp("csv"), result)
    if "plot" in files.targets:
        figure(result, files.temp("plot"), fmt or "png")


def report_population(result, out=None) -> None:
    """The console lines: the counts, the lognormal fit, the model spread, the time."""
    lines = [f"population: {len(result.particles)} particles, {result.law.describe()}, seed {result.seed}, "
             f"evaluator {result.evaluator}: {result.forces.size} pull-offs, {len(result.missing)} missing, "
             f"{len(result.flagged)} flagged; {result.ranks} rank(s), {result.wall_time:.3g} s "
             f"({result.cpu_time:.3g} s CPU)"]
    reasons, others = _reasons(result)
    for reason, n in reasons:
        lines.append(f"  missing ({n}): {reason}")
    if others:
        lines.append(f"  missing: {others} other reasons (the CSV's column missing)")
    fit = result.fit
    if hasattr(fit, "median"):
        lines.append(f"  lognormal of |F|: median {fit.median.value * 1e9:.5g} +- {fit.median.err * 1e9:.2g} nN, "
                     f"geometric standard deviation {fit.gsd.value:.4g} +- {fit.gsd.err:.2g} ({fit.count} "
                     f"pull-offs, {fit.resamples} bootstrap resamples)")
    else:
        lines.append(f"  no lognormal: {fit.reason}")
    works = result.works
    if works.size:
        lines.append(f"  energy of a cycle (rigid machine): {works.size} computed, {int(np.sum(works == 0))} of them 0 "
                     f"(no hysteresis), {len(result.energy_missing)} missing")
    ef = result.energy_fit
    if hasattr(ef, "median"):
        lines.append(f"  lognormal of the positive energies: median {ef.median.value * 1e15:.5g} +- "
                     f"{ef.median.err * 1e15:.2g} fJ, geometric standard deviation {ef.gsd.value:.4g} +- "
                     f"{ef.gsd.err:.2g} ({ef.count} particles)")
    elif works.size:
        lines.append(f"  no lognormal of the energies: {ef.reason}")
    else:
        reasons, _ = _reasons(result, energy=True)
        lines.append(f"  no energy of a cycle: {reasons[0][0] if reasons else ef.reason}")
    sp = result.spread
    if hasattr(sp, "indices") and sp.median is not None:
        lines.append(f"  model spread ({sp.relative.size} particles, rule: {sp.rule_source}): (rule - measured) / "
                     f"|measured| median {sp.median:+.3g} (16-84 %: {sp.p16:+.3g} to {sp.p84:+.3g}), numerical "
                     f"{sp.numerical:.2g}: " + ("the model decides" if sp.decides else "within the numerics"))
    elif hasattr(sp, "reason"):
        lines.append(f"  no model spread: {sp.reason}")
    tell("\n".join(lines), out)
