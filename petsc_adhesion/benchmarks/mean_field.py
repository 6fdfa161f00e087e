"""docs/mean_field.md's table and figure: our side of :mod:`.peer_rough` (the project's environment).

For each explicit rough sphere of the peer's data file (``docs/data/peer_rough.json``), at its own Tabor
parameter (a run's ``mu``; the runs stored without one are at MU = 1), the mean field of the same surface: its pixel heights as the measured law (all of the square's, and the footprint's under the
sphere), the paper's Gaussian rule at its rms and the Gaussian cut at its own highest height; kept in
``docs/data/mean_field.json``; then the table ``docs/figures/mean_field.md`` and the figure
``docs/figures/mean_field.png``::

    OPENBLAS_NUM_THREADS=1 nice -n 10 python -m petsc_adhesion.benchmarks.mean_field
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.mean_field --reuse               # table, figure

The first keeps the curves already in ``mean_field.json`` for the same surfaces (``--fresh``: all again).

Each surface is drawn again from its seed (:func:`.peer_rough.surface`) and must be the peer's (its digest).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

import numpy as np

from .peer_rough import DLAM, L, MU, N_MAIN, digest, run_mu, surface, write_atomic

__all__ = ["FOOTPRINT", "OUR_F_MAX", "BISTABLE", "pull_off_runs", "run_key", "gaussian_key", "our_curve", "ours_for",
           "gaussian_laws", "bistable", "tables", "figure", "main"]

#: The footprint whose pixel heights make the local law: the sphere's contact up to F = 0 lies inside it.
FOOTPRINT = 2.5
#: Our curves stop past the equilibrium, where the peer's approach does (F_STOP).
OUR_F_MAX = 0.05


def _event(c, kind):
    ev = c.events_of(kind)
    return None if not ev else float(ev[0].lam.value)


def pull_off_runs(peer: dict) -> list:
    """The peer's pull-offs on N_MAIN pixels, one per (mu, sigma, seed): the full curve's, or where there is
    none the retraction alone (``kind`` 'retract': at mu = 3 the approach to F = 0 would carry the contact to
    the square's edge, and its cost is that of four retractions)."""
    full = [r for r in peer["runs"] if r["n"] == N_MAIN]
    have = {(run_mu(r), r["sigma"], r["seed"]) for r in full}
    alone = [dict(r, kind="retract") for r in peer.get("retract_runs", [])
             if r["n"] == N_MAIN and (run_mu(r), r["sigma"], r["seed"]) not in have]
    return [dict(r, kind="runs") for r in full] + alone


def run_key(run: dict) -> str:
    """A peer run's key in our file: n:sigma:seed at MU (the keys stored before the mu was a case's), and
    n:sigma:seed:mu at any other mu."""
    mu = run_mu(run)
    return f"{run['n']}:{run['sigma']}:{run['seed']}" + ("" if mu == MU else f":{mu:g}")


def gaussian_key(sigma: float, mu: float) -> str:
    """The Gaussian laws' key in our file: the rms at MU (as stored before), sigma:mu at any other mu."""
    return str(sigma) + ("" if mu == MU else f":{mu:g}")


def our_curve(mu: float = MU, sigma: float | None = None, **options) -> dict:
    """Our curve (no model spread: the laws are compared here one by one): the pull-off, the folds in
    lambda, the cycle's energy, the branch; and its CPU time."""
    from petsc_adhesion import curve
    from petsc_adhesion.tracing.measured import Measured
    c0 = time.process_time()
    c = curve(mu, sigma, cont_F_max=OUR_F_MAX, adh_model_spread=False, **options)
    energy = c.rigid.energy
    return dict(sigma=float(c.model.sigma), pull_off=dict(F=float(c.pull_off.F.value), err=float(c.pull_off.F.err),
                                                         lam=float(c.pull_off.lam.value)),
                snap_on=_event(c, "snap_on"), snap_off=_event(c, "snap_off"),
                hysteresis=float(energy.value) if isinstance(energy, Measured) else None,
                branch=dict(lam=c.lam.tolist(), F=c.F.tolist(), stable=c.branch.stable.tolist()),
                complete=bool(c.complete), warnings=list(c.warnings), cpu_time_s=time.process_time() - c0)


def ours_for(run: dict, tmp: str) -> dict:
    """The mean field of one peer surface: its pixel heights as the measured law (all of the square's, and
    the footprint's), the paper's Gaussian rule at its rms, the truncated Gaussian cut at its own top.  The
    surface is drawn again from its seed and must be the peer's (their digests)."""
    n, sigma, seed, mu = run["n"], run["sigma"], run["seed"], run_mu(run)
    z = surface(n, sigma, seed)
    if digest(z) != run["digest"]:
        raise RuntimeError(f"the surface n {n} sigma {sigma} seed {seed} is not the peer's (digest)")
    if sigma == 0.0:
        return dict(smooth=our_curve(mu, sigma=0.0))
    x = -L + (np.arange(n) + 0.5) * (2.0 * L / n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    out = {}
    for name, heights in (("measured", z.ravel()), ("footprint", z[np.hypot(X, Y) < FOOTPRINT])):
        path = os.path.join(tmp, f"{name}.npy")
        np.save(path, heights)            # 1-D: read as they are (a 2-D map would be levelled by its plane)
        out[name] = our_curve(mu, adh_roughness="measured", adh_roughness_file=path)
        out[name]["top"] = float(heights.max())
    return out


def gaussian_laws(sigma: float, tops, mu: float = MU) -> dict:
    """The paper's Gaussian rule (16-point Hermite) at rms sigma, and the truncated Gaussian cut at each
    surface's own highest height (K = top / sigma, two decimals; sigma that of the uncut Gaussian)."""
    out = {"hermite": our_curve(mu, sigma=sigma)}
    for top in tops:
        K = round(top / sigma, 2)
        out[f"truncated:{K}"] = our_curve(mu, sigma=sigma, adh_roughness="truncated_gaussian", adh_roughness_cutoff=K)
    return out


def ours_main(argv) -> int:
    """Our side of every peer run in the data file, written beside it (``mean_field.json``), then the table
    and the figure."""
    p = argparse.ArgumentParser(prog="python -m petsc_adhesion.benchmarks.mean_field")
    p.add_argument("--data", default=os.path.join("docs", "data", "peer_rough.json"))
    p.add_argument("--ours", default=os.path.join("docs", "data", "mean_field.json"))
    p.add_argument("--figure", default=os.path.join("docs", "figures", "mean_field.png"))
    p.add_argument("--table", default=os.path.join("docs", "figures", "mean_field.md"))
    p.add_argument("--reuse", action="store_true", help="the table and figure from --ours as it is")
    p.add_argument("--fresh", action="store_true",
                   help="every curve again (without it, the curves already in --ours for the same peer "
                        "surfaces are kept and only the missing ones computed)")
    a = p.parse_args(argv)
    for path in [a.data] + ([a.ours] if a.reuse else []):
        if not os.path.exists(path):
            print(f"mean_field: {path} does not exist (--data: the peer's file of peer_rough.py peer; --reuse "
                  "needs --ours)", file=sys.stderr)
            return 2
    with open(a.data) as f:
        peer = json.load(f)
    if a.reuse:
        with open(a.ours) as f:
            ours = json.load(f)
    else:
        old = {"runs": {}, "gaussian": {}, "retract": {}}
        if os.path.exists(a.ours) and not a.fresh:
            with open(a.ours) as f:
                old.update(json.load(f))
        ours = {"runs": {}, "gaussian": {}, "retract": {}}
        with tempfile.TemporaryDirectory() as tmp:
            for kind, runs in (("runs", peer["runs"]), ("retract", peer.get("retract_runs", []))):
                for run in runs:
                    key = run_key(run)
                    # a kept curve is of the same surface: the heights' digest is checked when it is made
                    ours[kind][key] = old[kind][key] if key in old[kind] else ours_for(run, tmp)
                    print(kind, key, {k: round(v["pull_off"]["F"], 5) for k, v in ours[kind][key].items()},
                          flush=True)
            main = [r for r in pull_off_runs(peer) if r["sigma"] > 0]
            for mu, sigma in sorted({(run_mu(r), r["sigma"]) for r in main}):
                tops = [ours[r["kind"]][run_key(r)]["measured"]["top"] for r in main
                        if (run_mu(r), r["sigma"]) == (mu, sigma)]
                key = gaussian_key(sigma, mu)
                kept = old["gaussian"].get(key)
                want = {f"truncated:{round(t / sigma, 2)}" for t in tops} | {"hermite"}
                ours["gaussian"][key] = kept if kept is not None and set(kept) == want \
                    else gaussian_laws(sigma, tops, mu)
        write_atomic(a.ours, ours)
    table = tables(peer, ours)
    d = os.path.dirname(os.path.abspath(a.table))
    fd, tmp = tempfile.mkstemp(dir=d, suffix=".md")
    with os.fdopen(fd, "w") as f:
        f.write(f"<!-- made by: python -m petsc_adhesion.benchmarks.mean_field (docs/mean_field.md) -->\n{table}\n")
    os.chmod(tmp, 0o644)
    os.replace(tmp, a.table)
    figure(peer, ours, a.figure)
    print(table)
    return 0


def _stats(values):
    v = np.array([x for x in values if x is not None], float)
    if v.size == 0:
        return None
    return float(v.mean()), (float(v.std(ddof=1)) if v.size > 1 else None), float(v.min()), float(v.max())


def _ms(st, digits=4):
    if st is None:
        return "-"
    mean, sd, lo, hi = st
    return f"{mean:.{digits}f}" + ("" if sd is None else f" +- {sd:.{digits}f}")


#: Approach and retraction at one lambda on different branches: their loads differ by more than this (on one
#: branch, by the minimiser's tolerance, 2e-4 at most in these runs).
BISTABLE = 1e-3


def bistable(run: dict):
    """The explicit curve's bistable range on the lattice, (lowest, highest lambda), or None: the states
    where the approach and the retraction differ in load by more than BISTABLE."""
    a = {round(lam, 6): F for lam, F in zip(run["approach"]["lam"], run["approach"]["F"])}
    lams = [lam for lam, F in zip(run["retract"]["lam"], run["retract"]["F"])
            if round(lam, 6) in a and abs(a[round(lam, 6)] - F) > BISTABLE]
    return (min(lams), max(lams)) if lams else None


def _mus(runs) -> list:
    return sorted({run_mu(r) for r in runs})


def tables(peer: dict, ours: dict) -> str:
    """The comparison, one row per (mu, rms): the explicit runs' mean and seed-to-seed spread, each mean field;
    the folds surface by surface; the grid (the retractions alone on two grids)."""
    every_po = pull_off_runs(peer)
    main = [r for r in every_po if r["sigma"] > 0]
    smooth = {run_mu(r): r for r in every_po if r["sigma"] == 0}
    lines = ["Pull-off F (load / (2 pi R gamma)) at each Tabor parameter mu: the explicit runs' mean +- their "
             "seed-to-seed standard deviation (over the seeds of the third column), the mean field of each "
             "surface's own pixel heights (mean +- spread over the seeds): all of the square's and the "
             "footprint's (r < 2.5), the paper's Gaussian rule (16 points) at the same rms, the Gaussian cut at "
             "each surface's own top; the ratio of the explicit pull-off to the mean field of the square's "
             "heights (mean over the seeds of each seed's ratio); sigma 0: the smooth sphere, the explicit "
             "run against our curve.  'retraction': the explicit pull-off of the retraction alone from a state in "
             "contact (the grid's table below), no full curve.", "",
             "| mu | sigma (rms / epsilon) | seeds | explicit (ContactMechanics) | mean field, the square's heights | "
             "mean field, the footprint's heights | Gaussian rule, 16 points | Gaussian cut at the own top | "
             "highest height / rms | explicit / mean field |", "|---|---|---|---|---|---|---|---|---|---|"]
    for mu in _mus(main + list(smooth.values())):
        if mu in smooth:
            r = smooth[mu]
            o = ours[r["kind"]][run_key(r)]["smooth"]["pull_off"]
            lines.append(f"| {mu:g} | 0 | {'retraction' if r['kind'] == 'retract' else '-'} | {r['pull_off']['F']:.4f} | {o['F']:.4f} (smooth) | - | - | - | - | "
                         f"{r['pull_off']['F'] / o['F']:.3f} |")
        for sigma in sorted({r["sigma"] for r in main if run_mu(r) == mu}):
            rs = [r for r in main if (run_mu(r), r["sigma"]) == (mu, sigma)]
            mine = [ours[r["kind"]][run_key(r)] for r in rs]
            g = ours["gaussian"][gaussian_key(sigma, mu)]
            trunc = [v["pull_off"]["F"] for k, v in g.items() if k.startswith("truncated")]
            ratio = [r["pull_off"]["F"] / o["measured"]["pull_off"]["F"] for r, o in zip(rs, mine)]
            seeds = ", ".join(str(r["seed"]) + (" (retraction)" if r["kind"] == "retract" else "") for r in rs)
            lines.append(f"| {mu:g} | {sigma:g} | {seeds} | "
                         f"{_ms(_stats([r['pull_off']['F'] for r in rs]))} | "
                         f"{_ms(_stats([o['measured']['pull_off']['F'] for o in mine]))} | "
                         f"{_ms(_stats([o['footprint']['pull_off']['F'] for o in mine]))} | "
                         f"{g['hermite']['pull_off']['F']:.4f} | {_ms(_stats(trunc))} | "
                         f"{_ms(_stats([o['measured']['top'] / sigma for o in mine]), 2)} | {_ms(_stats(ratio), 2)} |")
    lines += ["", "Snap-on and snap-off (lambda, approach / epsilon) and the hysteresis (the energy of the "
              "displacement-controlled cycle, 2 pi R gamma epsilon), surface by surface.  The explicit ones: the "
              f"lattice's bistable range (where approach and retraction differ by more than {BISTABLE:g} in load; "
              "on one branch they agree to 2e-4): the snap-on lies within DLAM = 0.05 above it, the snap-off "
              "within 0.05 below; 'none': no bistable state, the curve reversible.  The mean field's: its folds "
              "in lambda (of the square's heights; of the smooth sphere at sigma 0).", "",
              "| mu | sigma | seed | snap-on, explicit | snap-on, mean field | snap-off, explicit | "
              "snap-off, mean field | hysteresis, explicit | hysteresis, mean field |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in sorted((r for r in every_po if r["kind"] == "runs"), key=lambda r: (run_mu(r), r["sigma"], r["seed"])):
        o = ours["runs"][run_key(r)]
        m = o["smooth" if r["sigma"] == 0 else "measured"]
        b = bistable(r)
        on = "none" if b is None else f"{b[1]:.2f} to {b[1] + DLAM:.2f}"
        off = "none" if b is None else f"{b[0] - DLAM:.2f} to {b[0]:.2f}"

        def fold(x):
            return "none" if x is None else f"{x:.4f}"
        hm = "-" if m["hysteresis"] is None else f"{m['hysteresis']:.4f}"
        lines.append(f"| {run_mu(r):g} | {r['sigma']:g} | {r['seed'] if r['sigma'] > 0 else '-'} | {on} | "
                     f"{fold(m['snap_on'])} | {off} | {fold(m['snap_off'])} | {r['hysteresis']:.4f} | {hm} |")
    lines += ["", "The grid: the same continuous surfaces on two grids (64 pixels a side: pixel 0.156 "
              "sqrt(R epsilon); 128: 0.078), the explicit retraction alone about the pull-off (from a state in "
              "contact), the full curve's pull-off on the same grid, and the mean field of each grid's pixel "
              "heights (our curve of the smooth sphere at sigma 0).", "",
              "| mu | surface | pixels | explicit pull-off F (retraction) | its lambda | the full curve's | "
              "mean field (the square's heights) | explicit / ours - 1 | CPU (s) |",
              "|---|---|---|---|---|---|---|---|---|"]
    full = {case: r for r in peer["runs"] for case in [(run_mu(r), r["sigma"], r["seed"], r["n"])]}
    for r in sorted(peer.get("retract_runs", []), key=lambda r: (run_mu(r), r["sigma"], r["seed"], r["n"])):
        mu, sigma, seed = run_mu(r), r["sigma"], r["seed"]
        o = ours["retract"][run_key(r)]
        mf = o["smooth" if sigma == 0.0 else "measured"]["pull_off"]
        name = "smooth" if sigma == 0.0 else f"sigma {sigma:g}, seed {seed}"
        f = full.get((mu, sigma, seed, r["n"]))
        lines.append(f"| {mu:g} | {name} | {r['n']} | {r['pull_off']['F']:.5f}"
                     + (" (at the range's end)" if r["pull_off"]["at_end"] else "")
                     + f" | {r['pull_off']['lam']:.3f} | " + (f"{f['pull_off']['F']:.5f}" if f else "-")
                     + f" | {mf['F']:.5f} +- {mf['err']:.0e} | {r['pull_off']['F'] / mf['F'] - 1:+.4f} | "
                       f"{r['cpu_time_s']:.0f} |")
    every = peer["runs"] + peer.get("retract_runs", [])
    mine = list(ours["runs"].values()) + list(ours.get("retract", {}).values()) + list(ours["gaussian"].values())
    ocpu = sum(v["cpu_time_s"] for o in mine for v in o.values())
    ver = peer["runs"][0]["versions"]
    lines += [""]
    for mu in _mus(every):
        runs = [r for r in every if run_mu(r) == mu]
        curves = [r for r in runs if "approach" in r]
        each = "" if not curves else (f", {min(r['cpu_time_s'] for r in curves):.0f} to "
                                      f"{max(r['cpu_time_s'] for r in curves):.0f} s each")
        lines.append(f"CPU time at mu = {mu:g}: the explicit runs {sum(r['cpu_time_s'] for r in runs) / 60:.1f} min "
                     f"({len(curves)} curves{each}, and {len(runs) - len(curves)} retractions;"
                     f" {sum(r['solves'] for r in runs)} minimisations).")
    lines += ["", f"Ours: {ocpu:.0f} s ({sum(len(o) for o in mine)} curves); ContactMechanics "
              f"{ver['ContactMechanics']}, Adhesion {ver['Adhesion']}, muGrid {ver['muGrid']}, one core each, "
              f"the machine shared (load average "
              f"{min(r['loadavg'][0] for r in every):.0f} to {max(r['loadavg'][0] for r in every):.0f})."]
    return "\n".join(lines)


def _ours_of(ours: dict, runs, sigma: float, law: str) -> list:
    """Our curves under ``law`` for the peer runs (of :func:`pull_off_runs`) at ``sigma``."""
    return [ours[r["kind"]][run_key(r)][law] for r in runs if r["sigma"] == sigma]


def _curve_panel(ax, r, ours):
    """One explicit curve (approach, retraction) against the mean field of its heights and the Gaussian rule."""
    sigma, mu = r["sigma"], run_mu(r)
    o = ours["runs"][run_key(r)]
    ax.plot(r["approach"]["lam"], r["approach"]["F"], "o", ms=2.5, color="C0", label="explicit, approach")
    ax.plot(r["retract"]["lam"], r["retract"]["F"], "s", ms=2.5, mfc="none", color="C3", label="explicit, retract")
    curves = [("mean field (own heights)", o["smooth" if sigma == 0 else "measured"]["branch"], "k")]
    if sigma > 0:
        curves.append(("Gaussian rule, 16 points", ours["gaussian"][gaussian_key(sigma, mu)]["hermite"]["branch"],
                       "C2"))
    for label, b, col in curves:
        lam, F, st = (np.array(b[k]) for k in ("lam", "F", "stable"))
        ax.plot(lam, np.where(st, F, np.nan), "-", color=col, lw=1.2, label=label)
        ax.plot(lam, np.where(st, np.nan, F), ":", color=col, lw=1.0)
    ax.set_xlim(min(r["approach"]["lam"]), max(r["approach"]["lam"]) + 0.1)
    ax.set_ylim(min(min(r["retract"]["F"]), o[next(iter(o))]["pull_off"]["F"]) * 1.15 - 0.02, 0.05)
    ax.set_title(("smooth" if sigma == 0 else f"sigma = {sigma:g}, seed {r['seed']}") + f", mu = {mu:g}")
    ax.set_xlabel("lambda (approach / epsilon)")
    ax.set_ylabel("F / (2 pi R gamma)")
    ax.legend(fontsize=7, loc="lower left")


def _bar(spreads):
    """Error bars of the seed spreads; no bar where one seed gives none (and none at all where no rms has
    two seeds: matplotlib refuses bars that are all missing)."""
    if all(x is None for x in spreads):
        return None
    return [np.nan if x is None else x for x in spreads]


def figure(peer: dict, ours: dict, path: str) -> None:
    """F(lambda) of the first seed at each rms at MU, and of one rms at each other mu: the explicit approach
    and retract against the mean field's branch (stable solid, unstable dotted) and the Gaussian rule's; the
    pull-off against sigma at each mu; the ratio explicit / mean field against sigma, one line per mu."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    main = [r for r in peer["runs"] if r["n"] == N_MAIN]
    po = pull_off_runs(peer)
    mus = _mus(po)
    first = [min((r for r in main if run_mu(r) == MU and r["sigma"] == s), key=lambda r: r["seed"])
             for s in sorted({r["sigma"] for r in main if run_mu(r) == MU})]
    # at each other mu the curve of the rms whose explicit and mean-field pull-offs differ most (the first seed)
    for mu in mus:
        rs = [r for r in main if run_mu(r) == mu and r["sigma"] > 0]
        if mu != MU and rs:
            first.append(max(sorted(rs, key=lambda r: (r["seed"], r["sigma"])),
                             key=lambda r: r["pull_off"]["F"] / ours["runs"][run_key(r)]["measured"]["pull_off"]["F"]))
    rows = int(np.ceil((len(first) + 2) / 3))
    fig, axes = plt.subplots(rows, 3, figsize=(13, 3.75 * rows))
    for ax, r in zip(axes.flat, first):
        _curve_panel(ax, r, ours)
    ax, axr = axes.flat[len(first)], axes.flat[len(first) + 1]
    for ax_ in axes.flat[len(first) + 2:]:
        ax_.set_visible(False)
    for i, mu in enumerate(mus):
        col = f"C{i}"
        at = [r for r in po if run_mu(r) == mu]
        rough = sorted({r["sigma"] for r in at if r["sigma"] > 0})
        ex = [_stats([r["pull_off"]["F"] for r in at if r["sigma"] == s]) for s in rough]
        ax.errorbar(rough, [-e[0] for e in ex], yerr=_bar([e[1] for e in ex]), fmt="o",
                    color=col, capsize=3, label=f"mu = {mu:g}: explicit (mean +- seed spread)")
        ax.plot(rough, [-np.mean([c["pull_off"]["F"] for c in _ours_of(ours, at, s, "measured")]) for s in rough],
                "-", marker=".", color=col, label=f"mu = {mu:g}: mean field, the square's heights")
        ax.plot(rough, [-ours["gaussian"][gaussian_key(s, mu)]["hermite"]["pull_off"]["F"] for s in rough],
                ":", color=col, label=f"mu = {mu:g}: Gaussian rule, 16 points")
        sm = [r for r in at if r["sigma"] == 0]
        if sm:
            ax.axhline(-sm[0]["pull_off"]["F"], color=col, lw=0.6, ls="--")
        ratio = [_stats([r["pull_off"]["F"] / ours[r["kind"]][run_key(r)]["measured"]["pull_off"]["F"]
                         for r in at if r["sigma"] == s]) for s in rough]
        axr.errorbar(rough, [q[0] for q in ratio], yerr=_bar([q[1] for q in ratio]),
                     fmt="o-", color=col, capsize=3, label=f"mu = {mu:g}")
    for a_, title, ylab in ((ax, "pull-off against roughness (dashed: smooth)", "pull-off -F / (2 pi R gamma)"),
                            (axr, "explicit / mean field (the square's heights)", "pull-off ratio")):
        a_.set_xscale("log")
        a_.set_yscale("log")
        ticks = sorted({r["sigma"] for r in po if r["sigma"] > 0})
        a_.set_xticks(ticks, [f"{s:g}" for s in ticks])
        a_.minorticks_off()
        a_.grid(True, which="major", color="0.9", lw=0.5)
        a_.set_xlabel("sigma (rms / epsilon)")
        a_.set_ylabel(ylab)
        a_.set_title(title)
        a_.legend(fontsize=6)
    axr.axhline(1.0, color="0.6", lw=0.8)
    from matplotlib.ticker import LogLocator, ScalarFormatter
    axr.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axr.yaxis.set_major_formatter(ScalarFormatter())
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    return ours_main(sys.argv[1:] if argv is None else list(argv))


if __name__ == "__main__":
    sys.exit(main())
