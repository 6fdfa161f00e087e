"""The curve family table: built, its interpolation error measured against the solver, its speed (docs/family.md).

    OPENBLAS_NUM_THREADS=1 mpiexec -n 2 python -m petsc_adhesion.benchmarks.family build --out family.npz \\
        [--mu 1e-3 1e3] [--per-decade 4] [--sigma 0 0.05 ... 3] [--n-tau 300] [--springs 0.02 0.5 10]
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.family speed family.npz [--repeats 20]

``build`` traces the nodes (:func:`~petsc_adhesion.family.build.build`, spread over the
ranks), then the error: at the centre of every cell of the grid (in ln mu and sigma;
the midpoints in ln mu when the table has one sigma) the solver's curve and the table's
are compared (the midpoints spread over the ranks too):

- the events of a rigid machine: snap-on and snap-off (each of the solver's matched to
  the table's nearest of its kind; a pair the other lacks counts as its own width) and
  the pull-off, in lambda and F (their values on the solver's grid);
- behind each spring of ``--springs`` (units 2 pi R w / epsilon): the solver's curve
  traced behind it (:class:`~petsc_adhesion.fitting.forward.ForwardCurve`) against the
  table's legs (:meth:`~petsc_adhesion.family.table.FamilyCurve.behind`): F at the
  solver's own points on the pieces each leg follows (its computed states, no
  interpolation on its side) up to where the table ends (F_max), leaving out the Z within
  twice the jumps' error of a jump of either (there a vertical jump makes any difference
  in Z one of O(1) in F); the jumps' Z and the force at their turning points (the
  library's located events).  The solver's curve is traced again with shorter steps
  where its legs leave out a jump it located (a loop narrower than a step,
  :func:`_truth`); a loop one side lacks (about the cusp where it is born) counts as
  its extent, its width in Z and its jump in F (:func:`_leg_jumps`).

``measure TABLE`` measures (again) a built table's midpoints, in parts by ``--mu-min``,
``--mu-max``, ``--sigma-range``, or only those it holds as infinite (``--infinite``).
The table is written with these errors (``FamilyTable.with_error``), all or nothing, and
the report gives the cost per node and the error per midpoint.  ``speed`` times what a
fit will call per evaluation: the interpolated curve at (mu, sigma), behind a spring, F at
500 base positions on both legs (median of ``--repeats``).  A benchmark is a measurement,
not a test: the machine's load is printed with it.
"""
from __future__ import annotations

import argparse
import itertools
import math
import os
import sys
import time

import numpy as np

from ..errors import say
from ..family.build import F_MAX, TableGrid, build, log_nodes, node_cost, regrid_points, spread, trace_node
from ..family.table import APPROACH, ERROR_FIELDS, RETRACT, FamilyTable, OutOfRange
from ._args import OneLineParser

#: The springs the error is measured behind (units 2 pi R w / epsilon): very soft and soft (jumps far out, the
#: rigid sphere's law), middling.  K = 10 (stiff: the legs follow the curve's folds) is left out: on a 20 nm tip
#: at w = 0.05 J/m^2 it is a 210 N/m lever, on a micrometre colloid 10^4 N/m, beyond any instrument's
#: (real levers are K = 1e-4 to 0.5, docs/family.md); it measured no larger an error than 0.5 (0.0063 against
#: 0.0036 in F at Z at mu 1.8, 0.0071 against 0.0065 at mu 3.1).
SPRINGS = (0.002, 0.02, 0.5)
#: The default sigma nodes: 0.05 apart up to 0.5, where the pull-off falls fastest (docs/family.md measures the
#: error of 0.1 against 0.05 apart there), then 0.1 to 1 and 0.25 to 3.
SIGMA_NODES = tuple(np.round(np.r_[np.arange(0.0, 0.5, 0.05), np.arange(0.5, 1.0, 0.1), np.arange(1.0, 3.01, 0.25)], 10))


def midpoints(table: FamilyTable) -> list[tuple[float, float]]:
    """The centres of the grid's cells in (ln mu, sigma); the midpoints in ln mu with a single sigma."""
    lm = np.log(table.mu)
    mids = np.exp(0.5 * (lm[1:] + lm[:-1]))
    if table.sigma.size == 1:
        return [(float(m), float(table.sigma[0])) for m in mids]
    smid = 0.5 * (table.sigma[1:] + table.sigma[:-1])
    return [(float(m), float(s)) for m in mids for s in smid]


def _nearest(a: list[float], b: list[float]) -> float:
    """The largest distance from an element of the longer list to the nearest of the other; 0 when both are
    empty, inf when only one is."""
    if not a and not b:
        return 0.0
    if not a or not b:
        return math.inf
    long, short = (a, b) if len(a) >= len(b) else (b, a)
    return max(min(abs(x - y) for y in short) for x in long)


def _loop(legs, leg: str, k: int) -> tuple[float, float]:
    """(width in Z, span in F) of the hysteresis loop the ``k``-th jump of ``leg`` belongs to: the unstable stretch
    of the branch between the turning point it jumps at and the one at the other end of that stretch (the next
    piece's start after an approach's jump_in, the previous piece's end before a retract's jump_off); inf where
    the branch has no such turning point."""
    chain, _ = legs.chains[leg]
    i = chain[k]
    p = legs.pieces
    a, b = (p[i].end, p[i + 1].start if i + 1 < len(p) else None) if leg == APPROACH else \
        (p[i - 1].end if i >= 1 else None, p[i].start)
    if a is None or b is None:
        return math.inf, math.inf
    return abs(a.Z(legs.K) - b.Z(legs.K)), abs(a.F - b.F)


def _leg_jumps(mine, truth, leg: str) -> tuple[float, float]:
    """(jump Z error, jump F error) of the legs ``mine`` against ``truth`` (two :class:`Legs` behind one spring) on
    ``leg``: each of the two's jumps against the other's nearest.  Where one of them has jumps the other lacks,
    each such jump is counted as the hysteresis loop it belongs to (:func:`_loop`): about the cusp where a loop is
    born (the spring as stiff as the curve is steep, |dF/d lambda| = K) a loop narrow in Z exists on one side
    alone, and what a fit could be off by there is the loop's extent, its width in Z and its jump in F (the larger
    of the jump's F before less F after and the loop's span in F), not an unbounded error.  A loop the other leg
    does not visit counts alike (behind a soft spring a shallow wiggle about the pull-off is a loop the retract
    alone passes: the approach has jumped in before it).  An extra jump with no turning point at the other end
    of its unstable stretch (no loop) is an error of unknown size: inf."""
    js, jt = truth.jumps[leg], mine.jumps[leg]
    eZ = eJ = 0.0
    keep_s, keep_t = list(range(len(js))), list(range(len(jt)))
    if len(js) != len(jt):
        side, this, those, keep = (mine, jt, js, keep_t) if len(jt) > len(js) else (truth, js, jt, keep_s)

        def cost(extra: tuple) -> float:
            # the extra jumps are the ones that leave the smallest error: a loop one side lacks is the narrow one
            # about its cusp (by Z alone, the pull-off's jump to the far branch was taken for the extra one where
            # a wiggle's narrow loop lay beside it, and counted as the whole hysteresis loop)
            rest = [this[k] for k in range(len(this)) if k not in extra]
            return max([_loop(side, leg, k)[0] for k in extra] + [_nearest(rest, those)])

        extra = min(itertools.combinations(range(len(this)), len(this) - len(those)), key=cost)
        forces = side.jump_forces(leg)
        for k in extra:
            width, span = _loop(side, leg, k)
            eZ, eJ = max(eZ, width), max(eJ, span, abs(forces[k][0] - forces[k][1]))
            keep.remove(k)
    # the jumps both have, each with the other's nearest
    zs, zt = [js[k] for k in keep_s], [jt[k] for k in keep_t]
    eZ = max(eZ, _nearest(zs, zt))
    if zs and zt:
        fs, ft = truth.jump_forces(leg), mine.jump_forces(leg)
        for k in keep_s:
            j = min(keep_t, key=lambda i: abs(js[k] - jt[i]))
            eJ = max(eJ, abs(fs[k][0] - ft[j][0]))
    return eZ, eJ


def _events(table: FamilyTable, mu: float, sigma: float, solver) -> tuple[float, float]:
    """(largest error in lambda, in F) of the snap-on, snap-off and pull-off of the table against ``solver``'s
    traced curve."""
    def grid(m):
        return float(m.grid if m.grid is not None else m.value)

    theirs = {k: [(grid(e.lam), grid(e.F)) for e in solver.events if e.kind == k] for k in ("snap_on", "snap_off")}
    F_min = [(grid(e.lam), grid(e.F)) for e in solver.events if e.kind == "F_min"]
    theirs["pull_off"] = [min(F_min, key=lambda x: x[1])] if F_min else []
    return _event_error(_table_events(table.curve(mu, sigma)), theirs)


def _table_events(curve) -> dict:
    """A table curve's snap-on, snap-off and pull-off: (lambda, F) lists by kind."""
    mine = curve.events()
    return {k: [(e.lam.value, e.F.value) for e in mine if e.kind == k] for k in ("snap_on", "snap_off", "pull_off")}


def _event_error(mine: dict, theirs: dict) -> tuple[float, float]:
    """(largest error in lambda, in F) between two curves' events (lists of (lambda, F) by kind)."""
    el = ef = 0.0
    for kind in ("snap_on", "snap_off", "pull_off"):
        t, s = mine[kind], theirs[kind]
        if bool(t) != bool(s):
            # a fold pair one side lacks (about the cusp where it is born): its width is the error
            both = (mine["snap_on"] + mine["snap_off"]) or (theirs["snap_on"] + theirs["snap_off"])
            lams, Fs = [x for x, _ in both], [y for _, y in both]
            el, ef = max(el, max(lams) - min(lams)), max(ef, max(Fs) - min(Fs))
            continue
        for (tl, tf), (sl, sf) in _pairs(t, s):
            el, ef = max(el, abs(tl - sl)), max(ef, abs(tf - sf))
    return el, ef


def _pairs(t: list, s: list) -> list:
    """Each of the longer list's events with the other's nearest in lambda."""
    long, short = (t, s) if len(t) >= len(s) else (s, t)
    out = [(x, min(short, key=lambda y: abs(y[0] - x[0]))) for x in long]
    return out if long is t else [(b, a) for a, b in out]


#: How often the solver's curve behind a spring is traced again with steps a quarter as long, where its legs left out
#: a turning point it located (:func:`_truth`).
REFINE = 2


def _truth(mu: float, sigma: float, K: float, F_max: float):
    """(the solver's curve behind K, its legs as :class:`~petsc_adhesion.fitting.forward.ForwardCurve`), traced
    with the default steps, and again with steps a quarter as long (at most ``REFINE`` times) while its legs leave
    out a turning point the solver located.  A hysteresis loop narrower than a step has no point on its unstable
    part, and the legs, made from the points' stability, leave it out (tracing/legs.py notes it): measured so, a
    table that holds the loop was counted as missing a jump the solver lacked.  At (mu 0.237, sigma 0.225) behind
    K = 0.5 the default curve (35 points) located the pair of jumps and its legs had none; with steps a quarter as
    long (75 points) the legs hold the loop at Z = -1.7419 and -1.7676 (and the same to 1e-12 with steps 1/10 and
    1/25 as long), the table's at -1.7358 and -1.7741 (docs/family.md)."""
    from petsc4py import PETSc

    from ..discretization.problem import step_scale
    from ..fitting.forward import ForwardCurve, curve_jumps
    from ..model.parameters import Model
    from ..tracing.trace import CurveRequest, curve_settings, trace_curve, wall_bend

    model = Model(mu=mu, sigma=sigma)
    scale = step_scale(model)
    # on a rough sphere the load bent by half the table's nodes' bound in a step: the truth holds the kink where
    # the roughness rule's wall stops the sphere at least as closely as the table's nodes do
    bend = wall_bend(model) / 2.0
    for _ in range(REFINE + 1):
        c = trace_curve(model, settings=curve_settings(scale, observable_max=F_max + 0.3, observable_bend=bend),
                        request=CurveRequest(error_bars=False, kinds=("jump_in", "jump_off"), spring=K),
                        comm=PETSc.COMM_SELF)
        truth = ForwardCurve(c, K)
        kept = sum(p.start is not None for p in truth.pieces) + sum(p.end is not None for p in truth.pieces)
        if kept == len(curve_jumps(c, "jump_in")) + len(curve_jumps(c, "jump_off")):
            break
        scale /= 4.0
        bend /= 4.0
    return c, truth


def _spring(table: FamilyTable, mu: float, sigma: float, K: float) -> tuple[float, float, float]:
    """(F at fixed Z, jump Z, jump F) errors of the table's legs behind K against the solver's (:func:`_truth`)."""
    c, truth = _truth(mu, sigma, K, table.F_max)
    mine = table.curve(mu, sigma).behind(K)
    b = c.branch
    own = ~regrid_points(b)
    # the piece of the solver's legs each point is on: the pieces are the runs of stable points in the branch's
    # order (tracing/legs.py), so the k-th run is piece k.  (Its lambda alone does not say: the far piece and the
    # contact overlap in lambda between the jumps, and a contact point there read on the far piece made the
    # "error" of 0.5-0.7 in F at Z at mu 1-3 of the earlier measurements.)
    stable = np.asarray(b.stable_spring, dtype=bool)
    run = np.where(stable, np.cumsum(np.diff(np.r_[False, stable].astype(np.int8)) == 1) - 1, -1)[own]
    lam, F = b.lam[own], b.F[own]
    Z = lam + F / K
    inside = Z <= mine.Z_max
    eF = eZ = eJ = 0.0
    for leg in (APPROACH, RETRACT):
        js, jt = truth.jumps[leg], mine.legs.jumps[leg]
        dz, dj = _leg_jumps(mine.legs, truth, leg)
        eZ, eJ = max(eZ, dz), max(eJ, dj)
        # the solver's own points on the pieces this leg follows (no interpolation on its side), away from
        # the jumps of either
        piece = truth.assign(Z, leg)
        on = inside & (run == piece)
        w = 2.0 * (dz if math.isfinite(dz) else 0.0) + 1e-9
        for z in js + jt:
            on &= np.abs(Z - z) > w
        if on.any():
            eF = max(eF, float(np.max(np.abs(F[on] - mine.predict(Z[on], leg)))))
    return eF, eZ, eJ


def measure(table: FamilyTable, springs=SPRINGS, comm=None, out=None, mu_max: float = math.inf,
            mu_min: float = 0.0, sigma_range: tuple = (0.0, math.inf), infinite: bool = False) -> FamilyTable:
    """The table with its interpolation error measured at its midpoints from ``mu_min`` up to ``mu_max`` and
    with sigma in ``sigma_range`` (module docstring; ``infinite``: of those, only the ones whose error the table
    holds as infinite, measured again), kept with the midpoints the table had measured outside that range (so
    that a table can be measured in parts); about the others the table's error is Missing, not measured;
    collective."""
    from petsc4py import PETSc

    if table.measured and not np.allclose(table.springs, springs):
        raise ValueError(f"--springs {list(springs)}: the table's error was measured behind {list(table.springs)}; "
                         "a part is measured behind the same springs")

    def work(case):
        mu, sigma = case
        t0 = time.perf_counter()
        try:
            solver = trace_node(mu, sigma, table.F_max, PETSc.COMM_SELF)
            el, ef = _events(table, mu, sigma, solver)
            per_K = [_spring(table, mu, sigma, K) for K in springs]
            row = dict(F_at_Z=max(p[0] for p in per_K), jump_Z=max(p[1] for p in per_K),
                       jump_F=max(p[2] for p in per_K), event_lam=el, event_F=ef)
        except (RuntimeError, ValueError) as e:
            row = {f: math.inf for f in ERROR_FIELDS}
            row["why"] = str(e).splitlines()[0] if str(e) else type(e).__name__
        row["seconds"] = time.perf_counter() - t0
        return row

    cases = [c for c in midpoints(table) if mu_min <= c[0] <= mu_max and sigma_range[0] <= c[1] <= sigma_range[1]]
    if infinite:
        bad = [k for k in range(table.err_mu.size) if not all(math.isfinite(table.errors[f][k]) for f in ERROR_FIELDS)]
        cases = [c for c in cases if any(math.isclose(table.err_mu[k], c[0], rel_tol=1e-9) and
                                         math.isclose(table.err_sigma[k], c[1], abs_tol=1e-12) for k in bad)]
    rows = spread(cases, work, lambda c: node_cost(c) * (1 + len(springs)), comm)
    if out is not None:
        out("| mu | sigma | F at Z | jump Z | jump F | event lambda | event F | solver (s) |")
        out("|---|---|---|---|---|---|---|---|")
        for (m, s), r in zip(cases, rows):
            out(f"| {m:.4g} | {s:.3g} | " + " | ".join(f"{r[f]:.2g}" for f in ERROR_FIELDS) +
                f" | {r['seconds']:.1f} |" + (f" {r['why']}" if "why" in r else ""))
    # the midpoints measured before and not now: kept, so that the parts of a table's error add up
    kept = [k for k in range(table.err_mu.size) if not any(
        math.isclose(table.err_mu[k], m, rel_tol=1e-9) and math.isclose(table.err_sigma[k], s, abs_tol=1e-12)
        for m, s in cases)]
    return table.with_error([table.err_mu[k] for k in kept] + [c[0] for c in cases],
                            [table.err_sigma[k] for k in kept] + [c[1] for c in cases], springs,
                            {f: [table.errors[f][k] for k in kept] + [r[f] for r in rows] for f in ERROR_FIELDS})


def _legs_error(mine, truth, K: float) -> tuple[float, float, float]:
    """(F at fixed Z, jump Z, jump F) errors of the table curve ``mine`` behind K against the curve ``truth``
    (a node's own), F compared at 4000 base positions on each leg away from the jumps of either by twice
    their distance."""
    a, b = mine.behind(K), truth.behind(K)
    Z = np.linspace(b.legs.pieces[0].Z_lo, min(a.Z_max, b.Z_max), 4000)
    eF = eZ = eJ = 0.0
    for leg in (APPROACH, RETRACT):
        js, jt = b.legs.jumps[leg], a.legs.jumps[leg]
        dz, dj = _leg_jumps(a.legs, b.legs, leg)
        eZ, eJ = max(eZ, dz), max(eJ, dj)
        on = np.ones(Z.size, dtype=bool)
        w = 2.0 * (dz if math.isfinite(dz) else 0.0) + 1e-9
        for z in js + jt:
            on &= np.abs(Z - z) > w
        if on.any():
            eF = max(eF, float(np.max(np.abs(a.predict(Z[on], leg) - b.predict(Z[on], leg)))))
    return eF, eZ, eJ


def spacing(table: FamilyTable, keep, springs=SPRINGS, out=print) -> list[tuple[float, float, dict]]:
    """The pilot of a sigma spacing, on the nodes alone (docs/family.md, "Roughness in the table"): the table of
    ``table``'s nodes at the sigma ``keep`` against each node it leaves out between them, at every mu node
    (there the interpolation in mu is exact, so what is measured is the spacing in sigma's; a node is the
    solver's curve sampled, to 3e-7 in F at fixed Z).  The errors are those of :func:`measure`: the events of a
    rigid machine, the legs behind ``springs``.  Returns (mu, sigma, errors) for each left-out node."""
    from ..family.build import select

    keep = [float(x) for x in keep]
    idx = [int(np.argmin(np.abs(table.sigma - x))) for x in keep]
    if any(abs(table.sigma[i] - x) > 1e-9 for i, x in zip(idx, keep)) or len(set(idx)) < 2:
        raise ValueError(f"--keep {keep}: expected two or more of the table's sigma nodes "
                         f"({', '.join(f'{x:g}' for x in table.sigma)})")
    coarse = select(table, sigma=sorted(idx))
    left = [j for j in range(table.sigma.size) if j not in idx and coarse.sigma[0] < table.sigma[j] < coarse.sigma[-1]]
    rows = []
    out("| mu | sigma left out | spacing there | F at Z | jump Z | jump F | event lambda | event F |")
    out("|---|---|---|---|---|---|---|---|")
    for mu in table.mu:
        for j in left:
            sg = float(table.sigma[j])
            truth, mine = table.curve(float(mu), sg), coarse.curve(float(mu), sg)
            el, ef = _event_error(_table_events(mine), _table_events(truth))
            per_K = [_legs_error(mine, truth, K) for K in springs]
            row = dict(F_at_Z=max(p[0] for p in per_K), jump_Z=max(p[1] for p in per_K),
                       jump_F=max(p[2] for p in per_K), event_lam=el, event_F=ef)
            k = int(np.searchsorted(coarse.sigma, sg))
            out(f"| {mu:.4g} | {sg:g} | {coarse.sigma[k] - coarse.sigma[k - 1]:g} | " +
                " | ".join(f"{row[f]:.2g}" for f in ERROR_FIELDS) + " |")
            rows.append((float(mu), sg, row))
    return rows


def speed(table: FamilyTable, repeats: int = 20, out=print) -> None:
    """The time of one evaluation a fit makes: the curve at (mu, sigma), behind a spring, F at 500 Z on both
    legs (median, min and max of ``repeats``)."""
    out(f"load average (1 min): {os.getloadavg()[0]:.2f}")
    out("| mu | sigma | K | curve + legs + 2 x 500 Z: median wall (min-max) ms | median CPU ms | legs' pieces |")
    out("|---|---|---|---|---|---|")
    lm = np.log(table.mu)
    for mu in np.exp(np.linspace(lm[0], lm[-1], 4)):
        for sigma in (table.sigma[0], table.sigma[-1]):
            for K in (0.02, 10.0):
                sc = table.curve(mu, sigma).behind(K)
                Z = np.linspace(sc.legs.pieces[0].Z_lo - 2.0, sc.Z_max, 500)
                times, cpu = [], []
                for _ in range(repeats):
                    t0, c0 = time.perf_counter(), time.process_time()
                    sc = table.curve(mu, sigma).behind(K)
                    sc.predict(Z, APPROACH)
                    sc.predict(Z, RETRACT)
                    times.append(time.perf_counter() - t0)
                    cpu.append(time.process_time() - c0)
                ms = 1e3 * np.array(times)
                out(f"| {mu:.4g} | {sigma:g} | {K:g} | {np.median(ms):.2f} ({ms.min():.2f}-{ms.max():.2f}) | "
                    f"{1e3 * np.median(cpu):.2f} | {len(sc.legs.pieces)} |")


#: The regions of docs/family.md's error table: sigma and mu ranges (the centres strictly inside).
REGIONS_SIGMA = ((0.02, 0.2), (0.2, 0.5), (0.5, 1.0), (1.0, 3.0))
REGIONS_MU = ((0.0, 0.03), (0.03, 1.0), (1.0, 10.0), (10.0, 1e3))


def regions(table: FamilyTable, out=print) -> None:
    """The table's measured error at its centres, median / largest over each region of (sigma, mu) (a table's
    region with no centre left out), as docs/family.md shows it."""
    out("| sigma | mu | centres | F at Z | jump Z | jump F | event lambda | event F |")
    out("|---|---|---|---|---|---|---|---|")
    for slo, shi in REGIONS_SIGMA:
        for mlo, mhi in REGIONS_MU:
            sel = (table.err_sigma > slo) & (table.err_sigma < shi) & (table.err_mu > mlo) & (table.err_mu < mhi)
            if not sel.any():
                continue
            cells = " | ".join(f"{np.median(table.errors[f][sel]):.2g} / {np.max(table.errors[f][sel]):.2g}"
                               for f in ERROR_FIELDS)
            out(f"| {table.err_sigma[sel].min():.3g} to {table.err_sigma[sel].max():.3g} | "
                f"{table.err_mu[sel].min():.2g} to {table.err_mu[sel].max():.2g} | {int(sel.sum())} | {cells} |")


def _parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="python -m petsc_adhesion.benchmarks.family", label="benchmarks.family")
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build")
    b.add_argument("--out", required=True)
    b.add_argument("--mu", nargs=2, type=float, default=(1e-3, 1e3))
    b.add_argument("--per-decade", type=float, default=4.0)
    b.add_argument("--sigma", nargs="+", type=float, default=list(SIGMA_NODES))
    b.add_argument("--n-tau", type=int, default=300)
    b.add_argument("--springs", nargs="+", type=float, default=list(SPRINGS))
    b.add_argument("--no-error", action="store_true", help="write the nodes alone; measure the error later")
    m = sub.add_parser("measure")
    m.add_argument("table")
    m.add_argument("--springs", nargs="+", type=float, default=list(SPRINGS))
    m.add_argument("--mu-max", type=float, default=math.inf, help="measure the midpoints up to this mu alone")
    m.add_argument("--mu-min", type=float, default=0.0,
                   help="measure the midpoints from this mu alone (those measured before kept)")
    m.add_argument("--sigma-range", nargs=2, type=float, default=(0.0, math.inf),
                   help="measure the midpoints with sigma in this range alone")
    m.add_argument("--infinite", action="store_true",
                   help="measure again only the midpoints whose error the table holds as infinite")
    sp = sub.add_parser("spacing")
    sp.add_argument("table")
    sp.add_argument("--keep", nargs="+", type=float, required=True, help="the sigma nodes the coarser table keeps")
    sp.add_argument("--springs", nargs="+", type=float, default=list(SPRINGS))
    j = sub.add_parser("join")
    j.add_argument("--out", required=True)
    j.add_argument("parts", nargs="+", help="tables on the same tau nodes and the same mu (or the same sigma)")
    j.add_argument("--errors-from", help="a measured table whose error at the midpoints the joined table "
                   "interpolates from the same nodes is kept (the others are to be measured)")
    r = sub.add_parser("regions")
    r.add_argument("table")
    s = sub.add_parser("speed")
    s.add_argument("table")
    s.add_argument("--repeats", type=int, default=20)
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.command in ("speed", "regions"):
        try:
            table = FamilyTable.load(args.table)
        except ValueError as e:
            say(str(e))
            return 2
        if args.command == "regions" and not table.measured:
            say(f"benchmarks.family: {args.table}: its error is not measured (measure it first)")
            return 2
        speed(table, args.repeats) if args.command == "speed" else regions(table)
        return 0
    if args.command in ("spacing", "join"):
        from ..family.build import join, keep_errors
        try:
            if args.command == "join":
                out_dir = os.path.dirname(os.path.abspath(args.out))
                if not os.path.isdir(out_dir):
                    raise ValueError(f"--out {args.out}: no folder {out_dir}")
                table = join([FamilyTable.load(f) for f in args.parts])
                if args.errors_from:
                    table = keep_errors(table, FamilyTable.load(args.errors_from))
            else:
                if not all(K > 0 and math.isfinite(K) for K in args.springs):
                    raise ValueError(f"--springs {args.springs}: expected stiffnesses > 0")
                spacing(FamilyTable.load(args.table), args.keep, tuple(args.springs))
                return 0
        except ValueError as e:
            say(f"benchmarks.family: {e}")
            return 2
        table.save(args.out)
        if args.command == "join" and table.measured:
            todo = [(m, s) for m, s in midpoints(table) if not np.any(
                np.isclose(table.err_mu, m, rtol=1e-9) & np.isclose(table.err_sigma, s, rtol=0, atol=1e-12))]
            said = f"the error of {table.err_mu.size} midpoints kept from {args.errors_from}; " + (
                f"{len(todo)} to measure (mu {', '.join(f'{m:.4g}' for m in sorted({m for m, _ in todo}))}; sigma "
                f"{', '.join(f'{x:.4g}' for x in sorted({x for _, x in todo}))})" if todo else "none to measure")
        else:
            said = "its error not measured (measure it)"
        print(f"written {args.out} ({os.path.getsize(args.out) / 1e6:.2f} MB): mu {table.mu.size} nodes "
              f"[{table.mu[0]:g}, {table.mu[-1]:g}], sigma {table.sigma.size} [{table.sigma[0]:g}, "
              f"{table.sigma[-1]:g}], {said}")
        return 0
    from petsc4py import PETSc

    rank = PETSc.COMM_WORLD.getRank()
    tell = print if rank == 0 else (lambda text: None)
    if args.command == "measure":
        try:
            table = FamilyTable.load(args.table)
            if not all(K > 0 and math.isfinite(K) for K in args.springs):
                raise ValueError(f"--springs {args.springs}: expected stiffnesses > 0")
        except ValueError as e:
            say(f"benchmarks.family: {e}")
            return 2
        return _measured(table, args.springs, args.table, tell, rank, time.perf_counter(), args.mu_max, args.mu_min,
                         tuple(args.sigma_range), args.infinite)
    try:
        lo, hi = args.mu
        grid = TableGrid(mu=log_nodes(lo, hi, args.per_decade) if hi > lo else (lo,), sigma=tuple(args.sigma),
                         n_tau=args.n_tau)
        if not (lo > 0 and hi >= lo):
            raise ValueError(f"--mu {lo:g} {hi:g}: expected 0 < lo <= hi")
        if not all(K > 0 and math.isfinite(K) for K in args.springs):
            raise ValueError(f"--springs {args.springs}: expected stiffnesses > 0")
        out_dir = os.path.dirname(os.path.abspath(args.out))
        if not os.path.isdir(out_dir):
            raise ValueError(f"--out {args.out}: no folder {out_dir}")
    except ValueError as e:
        say(f"benchmarks.family: {e}")
        return 2
    t0 = time.perf_counter()
    tell(f"load average (1 min): {os.getloadavg()[0]:.2f}; {len(grid.cases)} nodes on "
         f"{PETSc.COMM_WORLD.getSize()} ranks, F up to {F_MAX:g}")
    try:
        table = build(grid, comm=PETSc.COMM_WORLD, say=tell)
    except RuntimeError as e:
        say(f"benchmarks.family: {e}")
        return 3
    t1 = time.perf_counter()
    tell(f"nodes: {t1 - t0:.1f} s wall ({np.nansum(table.seconds):.1f} s of traces)")
    if args.no_error:
        if rank == 0:
            table.save(args.out)
            tell(f"written {args.out} ({os.path.getsize(args.out) / 1e6:.2f} MB), its error not measured")
        return 0
    return _measured(table, args.springs, args.out, tell, rank, t1)


def _measured(table: FamilyTable, springs, out: str, tell, rank: int, t1: float, mu_max: float = math.inf,
              mu_min: float = 0.0, sigma_range: tuple = (0.0, math.inf), infinite: bool = False) -> int:
    """The table's error measured (at the midpoints from ``mu_min`` up to ``mu_max``) and the table written with it
    to ``out``; 3 where a midpoint's is infinite."""
    from petsc4py import PETSc

    try:
        table = measure(table, tuple(springs), PETSc.COMM_WORLD, tell, mu_max, mu_min, sigma_range, infinite)
    except ValueError as e:
        say(f"benchmarks.family: {e}")
        return 2
    t2 = time.perf_counter()
    tell(f"error: {t2 - t1:.1f} s wall at {table.err_mu.size} midpoints; largest {table.worst()}")
    bad = not all(np.all(np.isfinite(v)) for v in table.errors.values())
    if rank == 0:
        table.save(out)
        tell(f"written {out} ({os.path.getsize(out) / 1e6:.2f} MB)")
    return 3 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
