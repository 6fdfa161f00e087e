"""The pull-off table built (its nodes and its error at the cells' centres, over MPI ranks), and a pull-off fit's
cost with the table and without it (docs/fitting.md).

    OPENBLAS_NUM_THREADS=1 nice -n 10 mpiexec -n 2 python -m petsc_adhesion.benchmarks.pull_off build \\
        [--out petsc_adhesion/family/pull_off.npz] [--mu 1e-3 1e-2 ... 1e3] [--sigma 0 0.05 ... 3]
    python -m petsc_adhesion.benchmarks.pull_off seed [TABLE] --out NEW.npz
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.pull_off fit [--mu 0.1 1 10 300] [--sigma 0 0.3]

``build`` traces every node (:func:`~petsc_adhesion.family.pull_off.trace_pull_off`: the
curve until F rises back through F_STOP, the pull-off's bar from nested grids), then the
solver at the centre of every cell (on its grid, no bar: the grid's error, below the nodes'
bars, is counted into the interpolation error it measures), each on one rank (``PETSc.COMM_SELF``), the costliest
first, each to the least loaded rank (:func:`~petsc_adhesion.family.build.spread`); rank 0
writes the table with its error (all or nothing) and prints the cost per node and the
error per cell.  ``seed`` journals a built table's nodes for a build into ``--out`` over more
nodes, which then traces the new nodes and every cell's centre only.  ``fit`` times
:func:`~petsc_adhesion.fitting.pull_off.fit_pull_off` (CPU seconds, ``time.process_time``) on
the pull-off of a sphere at each (mu, sigma), with the table and with the solver's secant alone
(the path before the table), and the vectorised
:func:`~petsc_adhesion.fitting.pull_off.gamma_from_pull_offs` on a map of 128 x 128 pull-offs.
A benchmark is a measurement, not a test: the machine's load is printed with it.
"""
from __future__ import annotations

import argparse
import glob
import json
import math
import os
import sys
import time

import numpy as np

from ..errors import say
from ..family.pull_off import DEFAULT_PATH, NodeValue, PullOffTable, trace_pull_off
from ..tracing.measured import Measured
from ._args import OneLineParser

#: The sigma nodes: the pull-off falls fastest between 0.1 and 0.4 (from 0.92 to 0.18 of the smooth one at mu =
#: 0.01), its sharpest bend between 0.15 and 0.2 (the error at that cell's centre was 1e-2 with nodes 0.05 apart:
#: hence 0.175), and like sigma^-2 beyond 1: from 3 to 10, the footprints' sigma on a measured AFM image (about 4.5,
#: docs/population.md), F_po = -1.28e-3 at sigma 5 and -3.23e-4 at 10 (mu 1e-3 to 100), ln |F_po| = -2 ln sigma +
#: c, smooth in sigma, and a node there cheap (0.2 s at mu = 1, 1.5 s at 100, 3.2 s at 1000, one rank).
SIGMA_NODES = (0.0, 0.05, 0.1, 0.15, 0.175, 0.2, 0.25, 0.3, 0.4, 0.6, 1.0, 1.75, 3.0, 4.0, 5.0, 6.5, 8.0, 10.0)
#: The mu nodes: about two a decade through the change from the rigid sphere's -1 to JKR's -3/4 (mu 0.1 to 10),
#: one a decade beyond, where the pull-off approaches JKR's like mu^-1.5 (docs/soft.md) and a node costs most.
MU_NODES = (1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0, 100.0, 1000.0)


def cost(case: tuple[float, float]) -> float:
    """A node's relative cost, only to order the work: the smooth curve's 0.1 + 0.7 mu^0.7 s (docs/family.md),
    a third of it from sigma = 0.5 on (measured: mu = 10, sigma = 1 in 2.1 s against 11 s smooth)."""
    mu, sigma = case
    return (0.1 + 0.7 * mu ** 0.7) * (1.0 if sigma < 0.5 else 0.3)


def points(mu: tuple, sigma: tuple) -> list[tuple[str, float, float]]:
    """What a build traces, in the order it is done: each row of nodes in mu, then the centres of the cells
    below it (so that the rows done by any time make a table: :func:`assemble`)."""
    out = []
    lm = np.log(np.asarray(mu, float))
    smid = 0.5 * (np.asarray(sigma[1:]) + np.asarray(sigma[:-1]))
    for k, m in enumerate(mu):
        out += [("node", float(m), float(s)) for s in sigma]
        if k:
            out += [("centre", float(math.exp(0.5 * (lm[k] + lm[k - 1]))), float(s)) for s in smid]
    return out


def _key(kind: str, mu: float, sigma: float) -> str:
    return f"{kind} {mu:.10g} {sigma:.10g}"


def _record(kind: str, n: NodeValue) -> str:
    def m(q):
        return None if q is None else [q.value, q.err, q.grid]
    return json.dumps({"kind": kind, "mu": n.mu, "sigma": n.sigma, "F": m(n.F), "lam": m(n.lam),
                       "seconds": n.seconds, "failed": n.failed})


def journal(out: str) -> dict:
    """The points traced so far by builds into ``out`` (their journals ``out.journal<rank>.jsonl``): key ->
    NodeValue."""
    done = {}
    for path in sorted(glob.glob(glob.escape(out) + ".journal*.jsonl")):
        with open(path) as fh:
            for line in fh:
                if not line.strip():
                    continue
                r = json.loads(line)
                q = [None if r[k] is None else Measured(r[k][0], r[k][1], r[k][2]) for k in ("F", "lam")]
                done[_key(r["kind"], r["mu"], r["sigma"])] = NodeValue(r["mu"], r["sigma"], q[0], q[1],
                                                                       r["seconds"], r["failed"])
    return done


def build(mu: tuple, sigma: tuple, out: str, comm=None, tell=print) -> None:
    """Trace every point of :func:`points` not yet in ``out``'s journal, spread over the ranks of ``comm`` (in
    their order, each to the least loaded rank), each appended to its rank's journal as it is done (so that a
    build stopped keeps its work and a second one continues it).  Collective."""
    from petsc4py import PETSc

    mpi = (comm or PETSc.COMM_WORLD).tompi4py()
    size, rank = mpi.Get_size(), mpi.Get_rank()
    done = journal(out)
    todo = [p for p in points(mu, sigma) if _key(*p) not in done]
    load = [0.0] * size
    mine = []
    for p in todo:
        r = int(np.argmin(load))
        load[r] += cost(p[1:])
        if r == rank:
            mine.append(p)
    tell(f"{len(todo)} points to trace ({len(done)} in the journal) on {size} ranks")
    with open(f"{out}.journal{rank}.jsonl", "a") as fh:
        for kind, m, s in mine:
            n = trace_pull_off(m, s, kind == "node", PETSc.COMM_SELF)
            fh.write(_record(kind, n) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
            print(f"{kind} mu {m:g} sigma {s:g}: " + (f"F {n.F.value:.8g} +- {n.F.err or math.nan:.2g}"
                  if n.failed is None else f"FAILED {n.failed}") + f", {n.seconds:.2f} s CPU", flush=True)
    mpi.barrier()


def seed(table: PullOffTable, out: str) -> int:
    """Journal ``table``'s nodes as done for a build into ``out`` (``out.journal-seeded.jsonl``), so that a build
    over more nodes traces only the new ones: each node the solver's values and bars as that table's build traced
    them (lambda's value on its grid is not kept in a table: absent), its CPU seconds that build's.  The cells'
    centres are not seeded: new nodes change the interpolant about them, and the build traces them again.
    Returns the number of nodes journaled."""
    rows = []
    for i, m in enumerate(table.mu):
        for j, s in enumerate(table.sigma):
            F = Measured(float(table.F[i, j]), float(table.F_err[i, j]), float(table.F_grid[i, j]))
            lam = Measured(float(table.lam[i, j]), float(table.lam_err[i, j]), None)
            rows.append(_record("node", NodeValue(float(m), float(s), F, lam, float(table.seconds[i, j]))))
    with open(f"{out}.journal-seeded.jsonl", "w") as fh:
        fh.write("\n".join(rows) + "\n")
    return len(rows)


def assemble(mu: tuple, sigma: tuple, out: str) -> PullOffTable:
    """The table of the journal's rows: the nodes up to the largest mu whose row, and every row and centre
    below it, is traced; its error from the centres.  RuntimeError where fewer than 4 rows are, or a node
    failed."""
    done = journal(out)
    rows = 0
    for k, m in enumerate(mu):
        pts = [p for p in points(mu[:k + 1], sigma) if p[1] >= (mu[k - 1] if k else 0) * (1 + 1e-12)]
        if not all(_key(*p) in done for p in pts):
            break
        rows = k + 1
    if rows < 4:
        raise RuntimeError(f"only {rows} rows of nodes traced (4 at least make a table)")
    nodes = [done[_key("node", float(m), float(s))] for m in mu[:rows] for s in sigma]
    table = PullOffTable.of_nodes(mu[:rows], sigma, nodes)
    return table.measure([done[_key("centre", m, s)] for m, s in table.centres()])


def report(table: PullOffTable, tell=print) -> None:
    """The error per cell (|interpolated - solver| of F, its relative size, of lambda) and the largest."""
    tell("| mu | sigma | F solver | F error | relative | lambda error | solver bar |")
    tell("|---|---|---|---|---|---|---|")
    for k, (m, s) in enumerate(table.centres()):
        i, j = divmod(k, table.sigma.size - 1)
        F, _ = table.interpolated(m, s)
        tell(f"| {m:.4g} | {s:.4g} | {float(F):.6g} | {table.cell_F[i, j]:.2g} | "
             f"{table.cell_F[i, j] / abs(float(F)):.2g} | {table.cell_lam[i, j]:.2g} | {table.cell_F_err[i, j]:.2g} |")
    tell(f"largest error in F {np.max(table.cell_F):.3g}, in lambda {np.max(table.cell_lam):.3g}; "
         f"largest node bar {np.nanmax(table.F_err):.3g}; node CPU {np.sum(table.seconds):.1f} s, centres "
         f"{np.sum(table.cell_seconds):.1f} s")


def fit_cost(mus, sigmas, tell=print) -> None:
    """The CPU of a pull-off fit with the table and with the solver's secant alone (the path before the table,
    which refused mu above 50), at each (mu, sigma): R = 20 nm, epsilon = 0.3 nm, w = 0.05 J/m^2, E* from mu by
    eq. (9); P the table's pull-off there, its bar 1%."""
    from ..fitting.pull_off import fit_pull_off
    from ..model.physical import Bodies

    table = PullOffTable.default()
    R, eps, w = 20e-9, 0.3e-9, 0.05
    tell("| mu | sigma | w with the table (J/m^2) | curves | CPU (s) | w by the secant alone | curves | CPU (s) |")
    tell("|---|---|---|---|---|---|---|---|")
    for mu in mus:
        for sigma in sigmas:
            E = w * math.sqrt(R / (mu**3 * eps**3))
            b = Bodies(radius=R, young1=E * 0.91, poisson1=0.3, epsilon=eps, rms=sigma * eps if sigma else None)
            P = abs(float(table.pull_off(mu, sigma)[0])) * 2 * math.pi * R * w
            row = [f"{mu:g}", f"{sigma:g}"]
            for use in (True, False):
                if not use and mu > 50:
                    row += ["(refused before the table: mu above 50)", "-", "-"]
                    continue
                t = time.process_time()
                try:
                    f = fit_pull_off(P, b, P_err=0.01 * P, use_table=use)
                    g = f.gamma
                    row += [f"{g.value:.6g} +- {g.err:.2g}" if hasattr(g, "err") else f"missing: {g.reason}",
                            str(f.curves), f"{time.process_time() - t:.2f}"]
                except ValueError as e:
                    row += [f"refused: {e}", "-", f"{time.process_time() - t:.2f}"]
                except RuntimeError as e:          # a solver's curve that failed: said in the row, the rest run
                    row += [f"failed: {str(e).splitlines()[0]}", "-", f"{time.process_time() - t:.2f}"]
            tell("| " + " | ".join(row) + " |")


def map_cost(tell=print) -> None:
    """The CPU of gamma_from_pull_offs on 128 x 128 pull-offs (mu about 1 to 100, sigma 0.2)."""
    from ..fitting.pull_off import gamma_from_pull_offs
    from ..model.physical import Bodies

    R, eps = 20e-9, 0.3e-9
    b = Bodies(radius=R, young1=1e9, poisson1=0.5, epsilon=eps, rms=0.2 * eps)
    rng = np.random.default_rng(1)
    P = 2 * math.pi * R * rng.uniform(0.05, 1.0, (128, 128)) * 0.5
    t = time.process_time()
    m = gamma_from_pull_offs(P, b, P_err=0.01 * P)
    sec = time.process_time() - t
    tell(f"gamma_from_pull_offs on 128 x 128 pull-offs: {sec:.3f} s CPU; {int(np.sum(m.found))} found, "
         f"median relative bar {np.nanmedian(m.gamma_err / m.gamma):.2g}")


def _parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="python -m petsc_adhesion.benchmarks.pull_off", label="benchmarks.pull_off")
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build")
    b.add_argument("--out", default=DEFAULT_PATH)
    b.add_argument("--mu", nargs="+", type=float, default=list(MU_NODES))
    b.add_argument("--sigma", nargs="+", type=float, default=list(SIGMA_NODES))
    a = sub.add_parser("assemble")
    a.add_argument("--out", default=DEFAULT_PATH)
    a.add_argument("--mu", nargs="+", type=float, default=list(MU_NODES))
    a.add_argument("--sigma", nargs="+", type=float, default=list(SIGMA_NODES))
    d = sub.add_parser("seed")
    d.add_argument("table", nargs="?", default=DEFAULT_PATH)
    d.add_argument("--out", required=True)
    r = sub.add_parser("report")
    r.add_argument("table", nargs="?", default=DEFAULT_PATH)
    f = sub.add_parser("fit")
    f.add_argument("--mu", nargs="+", type=float, default=[0.1, 1.0, 10.0, 300.0])
    f.add_argument("--sigma", nargs="+", type=float, default=[0.0, 0.3])
    f.add_argument("--map-only", action="store_true")
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    tell = print
    tell(f"load average (1 min): {os.getloadavg()[0]:.2f}")
    if args.command == "report":
        try:
            report(PullOffTable.load(args.table))
        except ValueError as e:
            say(f"benchmarks.pull_off: {e}")
            return 2
        return 0
    if args.command == "seed":
        try:
            n = seed(PullOffTable.load(args.table), args.out)
        except (ValueError, OSError) as e:
            say(f"benchmarks.pull_off: {e}")
            return 2
        tell(f"{n} nodes of {args.table} journaled for {args.out}")
        return 0
    if args.command == "fit":
        if not args.map_only:
            fit_cost(args.mu, args.sigma)
        map_cost()
        return 0
    if args.command == "assemble":
        try:
            table = assemble(tuple(args.mu), tuple(args.sigma), args.out)
        except RuntimeError as e:
            say(f"benchmarks.pull_off: {e}")
            return 3
        table.save(args.out)
        report(table, tell)
        tell(f"written {args.out} ({os.path.getsize(args.out) / 1e3:.1f} kB): mu up to {table.mu[-1]:g}")
        return 0 if np.all(np.isfinite(table.cell_F)) else 3
    from petsc4py import PETSc

    rank = PETSc.COMM_WORLD.getRank()
    tell = print if rank == 0 else (lambda text: None)
    mu = tuple(args.mu)
    if len(mu) < 4 or mu[0] <= 0 or any(b <= a for a, b in zip(mu, mu[1:])) or \
            not os.path.isdir(os.path.dirname(os.path.abspath(args.out))):
        say(f"benchmarks.pull_off: --mu {' '.join(f'{m:g}' for m in mu)} --out {args.out}: expected at least 4 "
            f"increasing mu > 0 and an existing folder")
        return 2
    t0 = time.perf_counter()
    build(mu, tuple(args.sigma), args.out, PETSc.COMM_WORLD, tell)
    tell(f"traced in {time.perf_counter() - t0:.1f} s wall")
    if rank == 0:
        return main(["assemble", "--out", args.out, "--mu", *map(str, mu), "--sigma", *map(str, args.sigma)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
