"""The study driver: options -> model -> grid -> solver -> results -> files.

A study is either one solve at a fixed approach (``-adh_lambda``) or the whole
load-approach curve by continuation (the default).
"""
from __future__ import annotations

import sys
import time

import numpy as np
import petsc4py
from mpi4py import MPI
from petsc4py import PETSc

from . import __version__, grid
from .continuation import Continuation, Settings
from .events import EventFinder, grid_warning
from .influence import create_influence
from .model import Model, scales, tabor
from .options import TABLE, AppOptions, InputError, check_unused, print_help
from .output import check_writable, write_h5, write_json
from .residual import Problem
from .solver import create_snes, solve

__all__ = ["read_model", "read_grid", "gather", "main"]

_APP = ("adh_", "grid_", "cont_")


def _is_app(name: str) -> bool:
    return name.startswith(_APP) or name in TABLE


def read_physical(opts: AppOptions) -> tuple | None:
    phys = opts.reals("adh_physical")
    if phys and len(phys) != 4:
        raise InputError(f"-adh_physical: expected 4 positive reals R,gamma,E,epsilon (SI), got {len(phys)}")
    if phys and opts.db.hasName("adh_mu"):
        raise InputError("-adh_mu: not with -adh_physical, which sets mu by eq. (9)")
    return phys or None


def read_model(opts: AppOptions) -> Model:
    phys = read_physical(opts)
    mu = tabor(*phys) if phys else opts.real("adh_mu")
    if phys and not 0 <= mu <= TABLE["adh_mu"].hi:
        raise InputError(f"-adh_physical: gives mu = {mu:.3g}, outside [0, {TABLE['adh_mu'].hi:g}]")
    model = Model(mu=mu, sigma=opts.real("adh_sigma"), rmax=opts.real("adh_rmax"),
                  roughness=opts.choice("adh_roughness"), hermite_points=opts.int("adh_hermite_points"))
    if model.roughness == "none" and model.sigma > 0:
        raise InputError(f"-adh_sigma: must be 0 with -adh_roughness none, got {model.sigma:g}")
    return model


def read_grid(opts: AppOptions, model: Model) -> np.ndarray:
    kind = opts.choice("grid_type")
    n, nu = opts.int("grid_n"), opts.int("grid_paper_uniform")
    extra, start = opts.int("grid_paper_extra"), opts.real("grid_paper_refine_from")
    split = opts.int("grid_paper_split")
    if kind == "uniform":
        return grid.uniform(n, model.rmax)
    if extra > nu - 1:
        raise InputError(f"-grid_paper_extra: expected an integer in [0, {nu - 1}], got {extra}")
    if start >= model.rmax:
        raise InputError(f"-grid_paper_refine_from: expected a real in [0, {model.rmax:g}), got {start:g}")
    return grid.paper(model.rmax, nu, extra, start, split)


def gather(v: PETSc.Vec) -> np.ndarray:
    """The whole of a distributed vector, on every rank."""
    scatter, full = PETSc.Scatter.toAll(v)
    scatter.scatter(v, full, PETSc.InsertMode.INSERT, PETSc.ScatterMode.FORWARD)
    out = full.getArray(readonly=True).copy()
    scatter.destroy()
    full.destroy()
    return out


def _guess(problem: Problem, lam: float, path: str | None) -> PETSc.Vec:
    H = problem.rigid(lam, problem.create_vec())
    if path is None:
        return H
    try:
        import h5py
        with h5py.File(path, "r") as f:
            r0, h0 = f["grid/r"][()], f["solution/H"][()]
    except (OSError, KeyError) as e:
        raise InputError(f"-adh_guess: cannot read grid/r and solution/H from '{path}' ({e})") from None
    h = np.interp(problem.r[problem.lo:problem.hi], r0, h0)
    if not np.all(np.isfinite(h)) or np.any(h <= problem.law.wall):
        raise InputError(f"-adh_guess: H in '{path}' is not finite and above the wall {problem.law.wall:g}")
    H.setArray(h)
    return H


def _versions(comm) -> dict:
    return {"program": "petsc-adhesion", "version": __version__,
            "petsc_version": "%d.%d.%d" % PETSc.Sys.getVersion(),
            "petsc4py_version": petsc4py.__version__, "mpi_ranks": comm.getSize()}


def fixed_solve(problem: Problem, snes: PETSc.SNES, lam: float, H: PETSc.Vec) -> dict:
    """One solve at approach ``lam``: the state, its load and the solver's effort."""
    t0 = time.perf_counter()
    ok = solve(snes, problem, lam, H)
    wall = time.perf_counter() - t0
    if not ok:
        raise RuntimeError(f"Newton did not converge at lambda = {lam:g} "
                           f"(reason {snes.getConvergedReason()}); try -adh_guess or -snes_monitor")
    p, _ = problem.pressure(H)
    pv = problem.create_vec()
    pv.setArray(p)
    Hall, Pall = gather(H), gather(pv)
    return {"lambda": lam, "F": problem.load(H), "H0": float(Hall[0]), "H": Hall, "P": Pall,
            "snes_iterations": snes.getIterationNumber(),
            "ksp_iterations": snes.getLinearSolveIterations(), "wall_time_s": wall}


def discretize(model: Model, r: np.ndarray, opts: AppOptions, curve: bool = True):
    """Influence matrix, problem and SNES on grid r (for a curve: its natural corrector)."""
    A = create_influence(r, PETSc.COMM_WORLD)
    problem = Problem(model, r, A, opts.choice("adh_pmat"), opts.int("adh_pmat_band"), opts.int("adh_pc_reuse_its"))
    return problem, create_snes(problem, full_steps=curve)


def estimate_errors(fine: dict, coarse: dict, rmax: float) -> None:
    """Attach error estimates to the events of ``fine`` (in place).

    Discretization: Richardson for a second-order method, |X_h - X_2h| / 3,
    from the same curve traced on every other node (events matched by kind and
    order).  Domain truncation of F: the attraction of the rigid sphere beyond
    r_m, (4/3) (r_m^2/2 + 1 - lambda)^-2.
    """
    def by_kind(events):
        out = {}
        for e in events:
            out.setdefault(e["kind"], []).append(e)
        return out

    cs = by_kind(coarse["events"])
    for kind, evs in by_kind(fine["events"]).items():
        matched = len(cs.get(kind, [])) == len(evs)
        for i, e in enumerate(evs):
            e["F_truncation"] = (4.0 / 3.0) / (rmax**2 / 2 + 1 - e["lambda"]) ** 2
            if matched:
                c = cs[kind][i]
                e["lambda_err"] = abs(e["lambda"] - c["lambda"]) / 3
                e["F_err"] = abs(e["F"] - c["F"]) / 3
    fine["error_estimate"] = {"coarse_wall_time_s": coarse["wall_time_s"],
                              "coarse_events_matched": all(len(cs.get(k, [])) == len(v)
                                                           for k, v in by_kind(fine["events"]).items())}


def check_memory(n: int, pmat: str, curve: bool, ranks: int) -> None:
    """Refuse a grid whose dense matrices cannot fit: A, and G_H and the bordered
    matrix when assembled densely, N^2 doubles each, split over the ranks."""
    import os

    dense = 1 + (pmat == "dense") * (1 + curve)
    need = 8.0 * n * n * dense / ranks
    have = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    if need > 0.8 * have:
        raise InputError(f"-grid_n: N = {n} needs {need / 2**30:.0f} GiB a rank for {dense} dense N x N "
                         f"matrices, this machine has {have / 2**30:.0f} GiB; use fewer nodes, more ranks, "
                         f"or -adh_pmat band")


def start_lambda(model: Model, wall: float) -> float:
    """Default first approach: the sphere well out of reach of the surface forces.

    The rigid gap at r = 0 is then 3 + 2 mu above the wall of the roughness rule.
    """
    return -(wall + 1.0) - 3.0 - 2.0 * model.mu


def trace(problem: Problem, snes: PETSc.SNES, opts: AppOptions) -> dict:
    """The whole load-approach curve with its events (the program's main job)."""
    model = problem.model
    lam_max = opts.real("cont_lambda_max")
    settings = Settings(kind=opts.choice("cont_type"), ds=opts.real("cont_ds"), ds_min=opts.real("cont_ds_min"),
                        ds_max=opts.real("cont_ds_max"), newton_target=opts.int("cont_newton_target"),
                        max_deviation=opts.real("cont_max_deviation"), max_folds=opts.int("cont_max_folds"),
                        dF_max=opts.real("cont_dF_max"),
                        lambda_max=np.inf if lam_max is None else lam_max, F_max=opts.real("cont_F_max"),
                        max_steps=opts.int("cont_max_steps"), monitor=opts.flag("cont_monitor"))
    lam0 = opts.real("cont_lambda_start")
    lam0 = start_lambda(model, problem.law.wall) if lam0 is None else lam0
    t0 = time.perf_counter()
    cont = Continuation(problem, snes, settings)
    finder = EventFinder(cont, opts.reals("cont_at_lambda"), opts.real("cont_event_tol"), opts.flag("profiles"))
    pts = cont.run(lam0, on_step=finder)
    finder.landings()
    wall = time.perf_counter() - t0
    comm = problem.comm.tompi4py()

    def whole(h):
        parts = comm.gather(h, root=0)
        return np.concatenate(parts) if parts is not None else None

    for ev in finder.events:
        for e in (ev, ev.get("landing", {})):
            if "h" in e:
                H = whole(e.pop("h"))
                if H is not None:
                    e["H"], e["P"] = H, problem.law(H)[0]
    # the contact edge: where the attraction peaks (P most negative), on rank 0's view of the curve
    pressures = [problem.law(H)[0] for H in map(whole, (p.h for p in pts)) if H is not None]
    edges = np.array([problem.r[np.argmin(P)] for P in pressures if P.min() < 0])
    pull_off = finder.pull_off()
    coarse = grid_warning(model, problem.r, edges, cont.folds)
    return {"points": pts, "events": finder.events, "pull_off": pull_off,
            "steps": len(pts) - 1, "rejected_steps": cont.rejected, "stop_reason": cont.stop_reason,
            "grid_warning": coarse, "wall_time_s": wall,
            "warnings": curve_warnings(problem, pts, None if coarse else pull_off), "lambda_start": lam0}


#: Closer than this to the wall of the roughness rule, a state is set by its smallest weights.
WALL_GAP = 1e-3


def curve_warnings(problem: Problem, pts, pull_off) -> list[str]:
    """What makes a traced curve untrustworthy, one line each.

    ``pull_off`` None skips the check of the pull-off against the curve (when
    the grid warning already explains a curve of spurious folds).
    """
    out = []
    law = problem.law
    gap = problem.comm.tompi4py().allreduce(min(float(p.h.min()) for p in pts) - law.wall, op=MPI.MIN)
    if not law.smooth and gap < WALL_GAP:
        out.append(f"the curve comes within {gap:.1e} of the wall H = {law.wall:.6g} of the {law.n}-point "
                   f"Hermite rule, where node weights down to {law.weights.min():.1e} set the repulsion: "
                   f"the loads there are properties of the rule and ill-conditioned; use fewer points")
    lowest = min(p.F for p in pts)
    if pull_off is not None and lowest < pull_off["F"] - 1e-9:
        out.append(f"a computed point (F = {lowest:.6g}) is more tensile than the located pull-off "
                   f"({pull_off['F']:.6g}): the load varies faster than the steps resolve; "
                   f"lower -cont_dF_max or -cont_ds_max")
    return out


def curve_summary(res: dict) -> dict:
    """The JSON summary of a traced curve (schema in docs/output.md)."""
    def brief(e):
        keep = ("kind", "lambda", "F", "H0", "stable", "lambda_err", "F_err", "F_truncation")
        return {k: v for k, v in e.items() if k in keep} | (
            {"landing": {k: v for k, v in e["landing"].items() if k in ("lambda", "F", "H0")}}
            if "landing" in e else {})
    ev = res["events"]
    po = res["pull_off"]
    return {"pull_off": brief(po) if po else None,
            "folds": [brief(e) for e in ev if e["kind"] in ("snap_on", "snap_off")],
            "equilibria": [{k: v for k, v in brief(e).items() if k != "F"}
                           for e in ev if e["kind"] == "equilibrium"],
            "load_extrema": [brief(e) for e in ev if e["kind"] in ("F_min", "F_max")],
            "at_lambda": [brief(e) for e in ev if e["kind"] == "lambda"],
            "steps": res["steps"], "rejected_steps": res["rejected_steps"], "stop_reason": res["stop_reason"],
            "grid_warning": res["grid_warning"], "warnings": res["warnings"],
            "wall_time_s": res["wall_time_s"]} | (
                {"error_estimate": res["error_estimate"]} if "error_estimate" in res else {})


def curve_tree(res: dict) -> dict:
    pts = res["points"]
    curve = {"lambda": np.array([p.lam for p in pts]), "F": np.array([p.F for p in pts]),
             "stable": np.array([p.tl > 0 for p in pts]), "ds": np.array([p.ds for p in pts]),
             "newton_its": np.array([p.its for p in pts]), "ksp_its": np.array([p.ksp_its for p in pts]),
             "H0": np.array([p.h[0] for p in pts]), "lambdadot": np.array([p.tl for p in pts]),
             "corrector": np.array([p.kind for p in pts], dtype="S9")}
    events = [{k: v for k, v in e.items() if k != "segment"} for e in res["events"]]
    return {"curve": curve, "events": events}


def main() -> int:
    comm = PETSc.COMM_WORLD
    opts = AppOptions()
    helping = opts.db.hasName("help")
    if helping and comm.getRank() == 0:
        print_help(sys.stdout)
    model = read_model(opts)
    r = read_grid(opts, model)
    lam = opts.real("adh_lambda")
    guess = opts.string("adh_guess")
    out, summary, plot = opts.string("out"), opts.string("summary"), opts.string("plot")
    check_memory(r.size, opts.choice("adh_pmat"), lam is None, comm.getSize())
    if guess is not None and lam is None:
        raise InputError("-adh_guess: only with -adh_lambda (the curve starts from the rigid state)")
    for name in TABLE:                      # read every app option now, so a typo is caught before any work
        getattr(opts, TABLE[name].kind)(name)
    check_unused(_is_app)
    check_writable("out", out)
    check_writable("summary", summary)
    check_writable("plot", plot)
    if plot and lam is not None:
        raise InputError("-plot: draws a curve; not with -adh_lambda")

    problem, snes = discretize(model, r, opts, curve=lam is None)
    if helping:
        return 0
    if lam is None:
        res = trace(problem, snes, opts)
        if opts.flag("cont_error_estimate"):
            coarse = r[::2] if r.size % 2 else np.append(r[::2], r[-1])
            estimate_errors(res, trace(*discretize(model, coarse, opts), opts), model.rmax)
    else:
        res = fixed_solve(problem, snes, lam, _guess(problem, lam, guess))
    check_unused()                          # PETSc has read all of its options by now
    if comm.getRank() == 0:
        phys = read_physical(opts)
        units = {"scales": scales(*phys)} if phys else {}
        head = {**_versions(comm), "options": opts.db.getAll(), "model": _model_attrs(model), "grid": {"r": r},
                **units}
        (write_curve if lam is None else write_solve)(res, head, out, summary, plot)
    return 0


def write_curve(res: dict, head: dict, out, summary, plot) -> None:
    """Files and report of a traced curve (schema in docs/output.md)."""
    flat = {k: v for k, v in head.items() if k not in ("options", "model", "grid")}
    summ = {**flat, **head["model"], "n_nodes": int(head["grid"]["r"].size), **curve_summary(res)}
    if "scales" in head and summ["pull_off"]:
        sc = head["scales"]
        summ["pull_off"] |= {"F_N": summ["pull_off"]["F"] * sc["force_N"],
                             "lambda_m": summ["pull_off"]["lambda"] * sc["approach_m"]}
    tree = {**head, "kind": "curve", **curve_tree(res),
            "summary": {k: v for k, v in summ.items() if not isinstance(v, (list, dict)) and v is not None}}
    if out:
        write_h5(out, tree)
    if plot:
        draw(plot, tree, out)
    if summary:
        write_json(summary, summ)
    _report(summ)


def write_solve(res: dict, head: dict, out, summary, plot) -> None:
    """Files and report of a fixed-lambda solve."""
    brief = {k: v for k, v in res.items() if not isinstance(v, np.ndarray)}
    if out:
        write_h5(out, {**head, "kind": "solve", "solution": {"H": res["H"], "P": res["P"], **brief}})
    if summary:
        flat = {k: v for k, v in head.items() if k not in ("options", "model", "grid")}
        write_json(summary, {**flat, **head["model"], "n_nodes": int(head["grid"]["r"].size), **brief})
    print(f"lambda = {res['lambda']:.10g}  F = {res['F']:.10g}  H0 = {res['H0']:.10g}  "
          f"Newton {res['snes_iterations']}  KSP {res['ksp_iterations']}  {res['wall_time_s']:.3g} s")


def draw(png: str, tree: dict, h5: str | None) -> None:
    """The curve figure; plotting is imported only here."""
    import tempfile

    from .output import atomic
    from .plot import curve_figure

    with tempfile.TemporaryDirectory() as tmp:
        if h5 is None:
            h5 = f"{tmp}/curve.h5"
            write_h5(h5, tree)
        with atomic(png) as target:
            curve_figure(h5, target)


def _err(e: dict) -> str:
    if "lambda_err" not in e:
        return ""
    f = f", F +- {e['F_err']:.1e} (+ truncation {e['F_truncation']:.1e})" if "F" in e else ""
    lam = f"lambda +- {e['lambda_err']:.1e}" if e["kind"] != "lambda" else "lambda exact"
    return f"   [error: {lam}{f}]"


def _model_attrs(model: Model) -> dict:
    return {"mu": model.mu, "sigma": model.sigma, "rmax": model.rmax,
            "roughness": model.roughness, "hermite_points": model.hermite_points}


def _report(s: dict) -> None:
    po = s["pull_off"]
    extra = f" + {s['error_estimate']['coarse_wall_time_s']:.3g} s for the error estimate" \
        if "error_estimate" in s else ""
    print(f"mu = {s['mu']:g}  sigma = {s['sigma']:g}  N = {s['n_nodes']}  steps {s['steps']} "
          f"(rejected {s['rejected_steps']})  {s['wall_time_s']:.3g} s{extra}; stopped: {s['stop_reason']}")
    if po:
        print(f"  pull-off (load control)  lambda = {po['lambda']:.8f}  F = {po['F']:.8f}{_err(po)}")
        if "F_N" in po:
            print(f"                           = {po['F_N']:.6g} N at an approach of {po['lambda_m']:.6g} m "
                  f"(mu = {s['mu']:.4g} from -adh_physical)")
    for f in s["folds"]:
        land = f.get("landing")
        to = f"  -> lands at F = {land['F']:.8f}" if land else ""
        print(f"  {f['kind']:<23}  lambda = {f['lambda']:.8f}  F = {f['F']:.8f}{to}{_err(f)}")
    for e in s["equilibria"]:
        print(f"  equilibrium F = 0       lambda = {e['lambda']:.8f}{_err(e)}")
    for e in s["at_lambda"]:
        print(f"  at lambda               lambda = {e['lambda']:.8f}  F = {e['F']:.8f}{_err(e)}")
    for w in ([s["grid_warning"]] if s["grid_warning"] else []) + s["warnings"]:
        print(f"  WARNING: {w}")
