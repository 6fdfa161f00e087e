"""The curve family table built: one curve traced per node of a (ln mu, sigma) grid, the nodes spread over MPI
ranks, each curve sampled on the table's coordinate (:mod:`~petsc_adhesion.family.coordinate`).

Each node is the library's default curve (:func:`~petsc_adhesion.tracing.trace.trace_curve`:
grids that follow the contact edge, the default roughness rule, no error bars) traced
on one rank (``PETSc.COMM_SELF``) past the table's F_max, so that its end F = F_max
lies between two traced points; on a rough sphere its steps bend the load by at most
:data:`~petsc_adhesion.tracing.trace.WALL_BEND_F` from its tangent's line, so that the
kink where the roughness rule's outermost wall stops the sphere is a point of the curve,
not rounded over by a spline through steps on either side of it (as fits' branches).  The nodes go to the ranks the costliest first
(the cost grows with mu: 0.1 s at mu = 1e-3, 0.7 s at mu = 1, 7 s at mu = 10, 20 s at
mu = 100, 85 s at mu = 1000 on this machine, docs/family.md), each to the rank with
the least work so far; rank 0 gathers them.  Collective.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from ..discretization.contact import edge_level
from ..model.parameters import Model
from ..model.pressure import pressure_law
from .coordinate import EVENT_KINDS, EventPoint, NotMonotone, Sampled, sample, width
from .table import ERROR_FIELDS, FamilyTable, lagrange

__all__ = ["select", "join", "TableGrid", "trace_node", "spread", "build", "node_cost", "log_nodes", "regrid_points",
           "event_points", "keep_errors", "F_MAX", "ROUGHNESS", "FINER"]

#: The load the table's curves end at: the library's default stop (-cont_F_max 2).
F_MAX = 2.0
#: The roughness rule of the table: the paper's 16-point Gauss-Hermite average (eq. 14), the model's default.
ROUGHNESS = "hermite"
#: How far past F_max a node's curve is traced (its end lies between two points).
_PAST = 0.3


@dataclass(frozen=True)
class TableGrid:
    """The table's nodes: ``mu`` (increasing, > 0), ``sigma`` (increasing, >= 0) and ``n_tau``, the number of
    nodes of the curve coordinate on each side of its centre (2 n_tau + 1 in all)."""

    mu: tuple
    sigma: tuple
    n_tau: int = 300

    def __post_init__(self):
        mu, sigma = np.asarray(self.mu, float), np.asarray(self.sigma, float)
        if mu.size < 1 or not np.all(np.isfinite(mu)) or np.any(mu <= 0) or np.any(np.diff(mu) <= 0):
            raise ValueError(f"mu: expected increasing Tabor parameters > 0, got {self.mu!r}")
        if sigma.size < 1 or not np.all(np.isfinite(sigma)) or np.any(sigma < 0) or np.any(np.diff(sigma) <= 0):
            raise ValueError(f"sigma: expected increasing roughnesses >= 0, got {self.sigma!r}")
        if isinstance(self.n_tau, bool) or not isinstance(self.n_tau, int) or self.n_tau < 4:
            raise ValueError(f"n_tau: expected an integer >= 4, got {self.n_tau!r}")

    @property
    def tau(self) -> np.ndarray:
        """The coordinate's nodes: uniform on [-1, 0] and on [0, 1], 0 shared."""
        half = np.linspace(0.0, 1.0, self.n_tau + 1)
        return np.r_[-half[:0:-1], half]

    @property
    def cases(self) -> list[tuple[float, float]]:
        return [(float(m), float(s)) for m in self.mu for s in self.sigma]


#: The steps a node is traced again with where its default curve is incomplete, as a fraction of the default's.
FINER = 0.25


def trace_node(mu: float, sigma: float, F_max: float = F_MAX, comm=None, step: float = 1.0):
    """The default curve of (mu, sigma), no error bars, traced past ``F_max`` (a Curve; collective on comm);
    ``step``: its steps (first, largest and the events' unit) as a fraction of the default's."""
    from ..discretization.problem import step_scale
    from ..tracing.trace import CurveRequest, curve_settings, trace_curve, wall_bend

    model = Model(mu=mu, sigma=sigma, roughness=ROUGHNESS)
    settings = curve_settings(step * step_scale(model), observable_max=F_max + _PAST,
                              observable_bend=wall_bend(model) * step)
    # shorter steps, as many more of them allowed (mu 1000, sigma 0.15 used the default's 5000 at a quarter)
    settings = replace(settings, max_steps=int(math.ceil(settings.max_steps / min(step, 1.0))))
    return trace_curve(model, settings=settings, request=CurveRequest(error_bars=False), comm=comm)


def regrid_points(branch) -> np.ndarray:
    """The points of a traced branch that repeat the state before them on a new grid (its corrector 'regrid')."""
    return np.asarray(branch.corrector) == b"regrid"


def event_points(curve) -> tuple:
    """The turning points and F = 0 the solver located on a traced curve (its events of the kinds a sampling
    takes, :data:`~petsc_adhesion.family.coordinate.EVENT_KINDS`), each on the grid it was located on."""
    def grid(m):
        return float(m.grid if m.grid is not None else m.value)
    return tuple(EventPoint(e.kind, grid(e.lam), grid(e.F), float(e.H0), grid(e.contact_radius))
                 for e in curve.events if e.kind in EVENT_KINDS and e.contact_radius is not None)


def _node(mu: float, sigma: float, tau: np.ndarray, F_max: float):
    """(sampled curve or the reason it is not, seconds) of one node, on this rank alone."""
    from petsc4py import PETSc

    t0 = time.perf_counter()
    out: Sampled | str
    try:
        try:
            c = trace_node(mu, sigma, F_max, PETSc.COMM_SELF)
            short = not c.complete
        except (ValueError, RuntimeError):  # an event not located with the default steps (mu 1000, sigma 1.5)
            short = True
        if short:
            # a load that varies faster than the default steps resolve (mu 3.16, sigma 0.2: "a computed point
            # is a load minimum more tensile than the located pull-off"): the same curve with shorter steps
            c = trace_node(mu, sigma, F_max, PETSc.COMM_SELF, FINER)
        if not c.complete:
            raise ValueError(f"the curve is incomplete with the default steps and with {FINER:g} of them: "
                             f"{c.assessment.incomplete[0]}")
        b = c.branch
        out = sample(b.lam, b.F, b.H0, b.contact_radius, edge_level(pressure_law(c.model)), F_max, tau, mu,
                     regrid_points(b), event_points(c))
    except (NotMonotone, ValueError, RuntimeError) as e:     # said, not raised: the other ranks wait for it
        out = f"mu {mu:g}, sigma {sigma:g}: {str(e).splitlines()[0] if str(e) else type(e).__name__}"
    return out, time.perf_counter() - t0


def spread(cases: list, work, cost, comm=None) -> list:
    """``work(case)`` for every case, the cases spread over the ranks of ``comm`` (PETSc.COMM_WORLD), the
    costliest first, each to the rank with the least ``cost`` so far; every rank gets the results in the
    cases' order (collective)."""
    from petsc4py import PETSc

    mpi = (comm or PETSc.COMM_WORLD).tompi4py()
    size, rank = mpi.Get_size(), mpi.Get_rank()
    load = [0.0] * size
    mine = []
    for i in sorted(range(len(cases)), key=lambda i: -cost(cases[i])):
        r = int(np.argmin(load))
        load[r] += cost(cases[i])
        if r == rank:
            mine.append(i)
    done = {i: work(cases[i]) for i in mine}
    merged: dict = {}
    for part in mpi.allgather(done):
        merged.update(part)
    return [merged[i] for i in range(len(cases))]


def node_cost(case: tuple[float, float]) -> float:
    """A node's relative cost, only to order the work: 0.1 + 0.7 mu^0.7 s, through the measured 0.7 s at mu = 1
    and 85 s at mu = 1000 (docs/family.md)."""
    mu = case[0]
    return 0.1 + 0.7 * mu ** 0.7


def build(grid: TableGrid, F_max: float = F_MAX, comm=None, say=None) -> FamilyTable:
    """The table of ``grid``'s nodes (its error not yet measured: :meth:`FamilyTable.with_error`); RuntimeError
    naming every node that could not be tabulated.  ``say(text)`` is told of each node as rank 0 gathers."""
    tau = grid.tau
    results = spread(grid.cases, lambda c: _node(c[0], c[1], tau, F_max), node_cost, comm)
    bad = [r for r, _ in results if isinstance(r, str)]
    if bad:
        raise RuntimeError(f"{len(bad)} node{'s' * (len(bad) != 1)} could not be tabulated: " + "; ".join(bad))
    shape = (len(grid.mu), len(grid.sigma))
    pick = (lambda f: np.array([getattr(r, f) for r, _ in results]).reshape(shape + (-1,)))
    scalar = (lambda f: np.array([getattr(r, f) for r, _ in results], float).reshape(shape))
    if say is not None:
        for (m, s), (_, sec) in zip(grid.cases, results):
            say(f"mu {m:g} sigma {s:g}: {sec:.2f} s")
    delta = np.array([width(m) for m, _ in grid.cases]).reshape(shape)
    return FamilyTable(mu=np.asarray(grid.mu, float), sigma=np.asarray(grid.sigma, float), tau=tau,
                       lam=pick("lam"), F=pick("F"), s_lo=scalar("s_lo"), s_hi=scalar("s_hi"), s0=scalar("s0"),
                       delta=delta, F_max=float(F_max), roughness=f"{ROUGHNESS} {Model().hermite_points}",
                       seconds=np.array([sec for _, sec in results]).reshape(shape))


def log_nodes(lo: float, hi: float, per_decade: float) -> tuple:
    """Nodes from ``lo`` to ``hi`` uniform in ln mu, ``per_decade`` intervals a decade (at least one)."""
    n = max(int(math.ceil(per_decade * math.log10(hi / lo) - 1e-9)), 1)
    return tuple(float(x) for x in np.geomspace(lo, hi, n + 1))


def select(table: FamilyTable, mu=None, sigma=None) -> FamilyTable:
    """The table of ``table``'s nodes at the indices ``mu`` and ``sigma`` (None: all), its error not measured
    (its cells are others)."""
    i = np.arange(table.mu.size) if mu is None else np.asarray(mu, int)
    j = np.arange(table.sigma.size) if sigma is None else np.asarray(sigma, int)
    ix = np.ix_(i, j)
    seconds = None if table.seconds is None else table.seconds[ix]
    return replace(table, mu=table.mu[i], sigma=table.sigma[j], lam=table.lam[ix], F=table.F[ix],
                   s_lo=table.s_lo[ix], s_hi=table.s_hi[ix], s0=table.s0[ix], delta=table.delta[ix],
                   seconds=seconds, springs=np.zeros(0), err_mu=np.zeros(0), err_sigma=np.zeros(0), errors={})


def join(tables: list) -> FamilyTable:
    """One table of the nodes of ``tables`` built in parts: on the same tau nodes, F_max and roughness rule, and
    either the same mu nodes (joined along sigma) or the same sigma nodes (along mu); a node two parts hold
    is taken from the first.  ValueError, one line, for parts that do not fit together.  The joined table's
    error is not measured (its cells are new)."""
    first = tables[0]
    for t in tables[1:]:
        if t.tau.shape != first.tau.shape or not np.allclose(t.tau, first.tau) or t.F_max != first.F_max or \
                t.roughness != first.roughness:
            raise ValueError("the parts differ in their tau nodes, F_max or roughness rule: they are no one table")
    same_mu = all(t.mu.shape == first.mu.shape and np.allclose(t.mu, first.mu, rtol=1e-12) for t in tables)
    same_sigma = all(t.sigma.shape == first.sigma.shape and np.allclose(t.sigma, first.sigma) for t in tables)
    if not (same_mu or same_sigma):
        raise ValueError("the parts share neither their mu nor their sigma nodes: they are joined along one axis")
    axis = 1 if same_mu else 0
    nodes = np.concatenate([t.sigma if axis else t.mu for t in tables])
    values, where = np.unique(np.round(nodes, 12), return_index=True)
    # each node's (part, index) in the joined order, the first part's where two hold it
    owner = [(int(np.searchsorted(np.cumsum([(t.sigma if axis else t.mu).size for t in tables]), w, "right")), w)
             for w in where]
    offs = np.r_[0, np.cumsum([(t.sigma if axis else t.mu).size for t in tables])]

    def stack(name):
        parts = [np.take(getattr(tables[p], name), [w - offs[p]], axis=axis) for p, w in owner]
        return np.concatenate(parts, axis=axis)

    secs = [t.seconds if t.seconds is not None else np.full(t.s_lo.shape, np.nan) for t in tables]
    seconds = np.concatenate([np.take(secs[p], [w - offs[p]], axis=axis) for p, w in owner], axis=axis)
    return replace(first, mu=first.mu if axis else nodes[where], sigma=nodes[where] if axis else first.sigma,
                   lam=stack("lam"), F=stack("F"), s_lo=stack("s_lo"), s_hi=stack("s_hi"), s0=stack("s0"),
                   delta=stack("delta"), seconds=seconds, springs=np.zeros(0), err_mu=np.zeros(0),
                   err_sigma=np.zeros(0), errors={})


def keep_errors(table: FamilyTable, old: FamilyTable) -> FamilyTable:
    """``table`` with the error ``old`` measured at those of its midpoints whose interpolant is unchanged: the
    midpoint lies in ``table``'s range and each of the nodes its cubic stencil takes (the four nearest in ln mu
    and in sigma, :func:`~petsc_adhesion.family.table.lagrange`) is a node of ``old`` with the same curve to the
    bit (lambda, F and the ends of its coordinate, on the same tau nodes and F_max); the others are left to be
    measured again (a joined table's nodes that were traced anew, or sampled otherwise)."""
    if not old.measured or old.tau.shape != table.tau.shape or not np.array_equal(old.tau, table.tau) or \
            old.F_max != table.F_max or old.roughness != table.roughness:
        return table

    def same(i: int, j: int) -> bool:
        a = np.flatnonzero(np.isclose(old.mu, table.mu[i], rtol=1e-12, atol=0))
        b = np.flatnonzero(np.isclose(old.sigma, table.sigma[j], rtol=0, atol=1e-12))
        if not (a.size and b.size):
            return False
        p, q = int(a[0]), int(b[0])
        return all(np.array_equal(getattr(old, f)[p, q], getattr(table, f)[i, j])
                   for f in ("lam", "F", "s_lo", "s_hi", "s0", "delta"))

    keep = []
    for k, (m, sg) in enumerate(zip(old.err_mu, old.err_sigma)):
        try:
            table.check(float(m), float(sg))
        except ValueError:
            continue
        i0, wm = lagrange(np.log(table.mu), math.log(m))
        j0, ws = lagrange(table.sigma, float(sg))
        if all(same(i, j) for i in range(i0, i0 + wm.size) for j in range(j0, j0 + ws.size)):
            keep.append(k)
    if not keep:
        return table
    return table.with_error(old.err_mu[keep], old.err_sigma[keep], old.springs,
                            {f: old.errors[f][keep] for f in ERROR_FIELDS})
