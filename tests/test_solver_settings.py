"""PETSc's solver settings as typed objects (PetscSettings in SolverChoice), each solver's own; the library's
entry checks; the Python API from a thread other than the main one."""
import math
import subprocess
import sys

import numpy as np
import pytest

import petsc_adhesion as pa
from conftest import ROOT, _env
from petsc_adhesion.core.newton import PetscSettings, Tolerances

CURVE = {"mu": 1.0, "grid_type": "uniform", "grid_n": 101, "cont_F_max": 0}


def _problem(n=101):
    from petsc_adhesion.discretization import grid
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import discretize
    from petsc_adhesion.discretization import preconditioning

    return discretize(Model(mu=1.0, rmax=10.0), grid.uniform(n, 10.0), preconditioning.create("dense"))


def _reported(snes):
    """What PETSc reports of a SNES and its KSP: types and tolerances."""
    from petsc_adhesion.core import capi

    ksp = snes.getKSP()
    return {"snes": snes.getTolerances(), "linesearch": capi.linesearch_type(snes), "ksp": ksp.getType(),
            "ksp_tol": ksp.getTolerances()[:2] + ksp.getTolerances()[3:], "pc": ksp.getPC().getType()}


# -- 1. each solver its settings, the others its defaults -----------------------------------------------
def test_each_solver_gets_its_own_settings_and_keeps_the_defaults_not_given():
    from petsc4py import PETSc
    from petsc_adhesion.core.continuation import Continuation
    from petsc_adhesion.core.newton import Newton

    db = PETSc.Options()
    # what a caller left in the global database under the roles' prefixes: the library reads none of it
    db.setValue("arc_ksp_type", "cg")
    db.setValue("nat_snes_rtol", "0.5")
    db.setValue("snes_max_it", "3")
    pb1, pb2 = _problem(), _problem()
    a = Continuation(pb1, arclength=PetscSettings(ksp_type="gmres", ksp_rtol=1e-12, linesearch="bt"),
                     natural=PetscSettings(snes_max_it=7, options={"ksp_pc_side": "right"}))
    b = Continuation(pb2, arclength=PetscSettings(ksp_type="bcgs", pc_type="jacobi", snes_rtol=1e-6))
    fixed = Newton(pb2, "", settings=PetscSettings(snes_atol=1e-9, ksp_max_it=77))
    try:
        t = Tolerances()
        unit_atol = t.snes_atol           # unit 1: the natural corrector's default atol is Tolerances'
        # given: as given; not given: the defaults each solver set before this change (the golden files hold them)
        assert _reported(a.bordered.snes) == {"snes": (t.snes_rtol, t.snes_atol, t.snes_stol, t.snes_max_it),
                                              "linesearch": "bt", "ksp": "gmres",
                                              "ksp_tol": (1e-12, t.ksp_atol, t.ksp_max_it), "pc": "lu"}
        assert _reported(a.newton.snes) == {"snes": (t.snes_rtol, unit_atol, t.snes_stol, 7), "linesearch": "basic",
                                            "ksp": "gmres", "ksp_tol": (t.ksp_rtol, t.ksp_atol, t.ksp_max_it),
                                            "pc": "lu"}
        assert a.newton.snes.getKSP().getPCSide() == PETSc.PC.Side.RIGHT
        assert a.bordered.snes.getKSP().getPCSide() == b.newton.snes.getKSP().getPCSide() == PETSc.PC.Side.LEFT
        assert _reported(b.bordered.snes) == {"snes": (1e-6, t.snes_atol, t.snes_stol, t.snes_max_it),
                                              "linesearch": "basic", "ksp": "bcgs",
                                              "ksp_tol": (t.ksp_rtol, t.ksp_atol, t.ksp_max_it), "pc": "jacobi"}
        assert _reported(b.newton.snes) == {"snes": (t.snes_rtol, unit_atol, t.snes_stol, t.snes_max_it),
                                            "linesearch": "basic", "ksp": "gmres",
                                            "ksp_tol": (t.ksp_rtol, t.ksp_atol, t.ksp_max_it), "pc": "lu"}
        assert _reported(fixed.snes) == {"snes": (t.snes_rtol, 1e-9, t.snes_stol, t.snes_max_it), "linesearch": "bt",
                                         "ksp": "gmres", "ksp_tol": (t.ksp_rtol, t.ksp_atol, 77), "pc": "lu"}
        prefixes = {s.getOptionsPrefix() for s in (a.newton.snes, a.bordered.snes, b.newton.snes, b.bordered.snes,
                                                   fixed.snes)}
        assert len(prefixes) == 5, prefixes
    finally:
        for obj in (a, b, fixed, pb1, pb2):
            obj.destroy()
        for name in ("arc_ksp_type", "nat_snes_rtol", "snes_max_it"):
            db.delValue(name)
    # the solvers took their values out of the database again
    assert not [k for k in db.getAll() if k.startswith("pa") and k[2:3].isdigit()]


def test_options_read_at_the_first_solve_reach_the_inner_solvers():
    """A block preconditioner's sub_ options and the KSP's converged_reason are read at the first solve, by
    objects made then: under the solver's own prefix they reach them (an options object of the solver's
    own, PetscObjectSetOptions, left -sub_pc_type unread with petsc4py 3.18)."""
    from petsc_adhesion.core import capi
    from petsc_adhesion.core.newton import Newton
    from petsc_adhesion.discretization import grid, preconditioning
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import discretize

    pb = discretize(Model(mu=1.0, rmax=10.0), grid.uniform(101, 10.0), preconditioning.create("band"))
    newton = Newton(pb, "", settings=PetscSettings(pc_type="bjacobi", options={
        "pc_bjacobi_blocks": "2", "sub_pc_type": "lu", "ksp_converged_reason": None}))
    H = pb.rigid(-2.0, pb.create_vec())
    try:
        mine = [n for n in capi.options_left() if n.startswith(newton.options.prefix)]
        assert sorted(mine) == [newton.options.prefix + n for n in ("ksp_converged_reason", "sub_pc_type")]
        assert newton.solve(-2.0, H)
        assert [n for n in capi.options_left() if n.startswith(newton.options.prefix)] == []
        assert newton.snes.getKSP().getPC().getType() == "bjacobi"
    finally:
        for obj in (H, newton, pb):
            obj.destroy()


def test_a_type_petsc_does_not_know_leaves_nothing_behind():
    """PETSc refuses the type when the solver is set up; the objects and the options put in for it go."""
    from petsc4py import PETSc
    from petsc_adhesion import GridChoice, Model, SolverChoice, solve_at

    before = PETSc.Options().getAll()
    with pytest.raises(PETSc.Error):
        solve_at(-2.0, Model(), GridChoice("uniform", n=41), SolverChoice(fixed=PetscSettings(ksp_type="nonesuch")))
    assert PETSc.Options().getAll() == before


def test_fold_system_takes_its_settings():
    from petsc_adhesion.core.fold import FoldSystem

    base = _problem(41)
    with pytest.raises(ValueError, match="^snes_rtol: the fold system"):
        FoldSystem(base, "sigma", PetscSettings(snes_rtol=1e-3))
    fs = FoldSystem(base, "sigma", PetscSettings(ksp_type="fgmres", ksp_max_it=123))
    try:
        assert fs.ksp.getType() == "fgmres"
        rtol, atol, _, max_it = fs.ksp.getTolerances()
        t = Tolerances()
        assert (rtol, atol, max_it) == (1e-2 * t.ksp_rtol, 1e-2 * t.ksp_atol, 123)
    finally:
        fs.destroy()


@pytest.mark.parametrize("kw, line", [
    ({"snes_rtol": 1.0}, "snes_rtol: expected a real in [0, 1)"),
    ({"ksp_atol": -1e-3}, "ksp_atol: expected a real in [0, inf]"),
    ({"ksp_rtol": math.nan}, "ksp_rtol: expected a real"),
    ({"snes_max_it": 0}, "snes_max_it: expected an integer in [1, 1e+09]"),
    ({"snes_max_it": 2.5}, "snes_max_it: expected an integer"),
    ({"ksp_type": "gm res"}, "ksp_type: expected the name of a PETSc type"),
    ({"snes_monitor": "yes"}, "snes_monitor: expected True or False"),
    ({"options": {"-ksp_view": None}}, "options: '-ksp_view' is not a PETSc option name"),
    ({"options": {"ksp_gmres_restart": 60}}, "options: ksp_gmres_restart = 60; expected a string"),
    ({"ksp_type": "bcgs", "options": {"ksp_type": "cg"}}, "options: ksp_type is given as the field ksp_type too"),
])
def test_settings_refuse_what_petsc_would_take_silently(kw, line):
    with pytest.raises(ValueError) as e:
        PetscSettings(**kw)
    assert str(e.value).startswith(line), str(e.value)


def test_settings_are_values():
    s = PetscSettings(ksp_type="bcgs", options={"ksp_view": None})
    assert s == PetscSettings(ksp_type="bcgs", options={"ksp_view": None}) != PetscSettings(ksp_type="bcgs")
    with pytest.raises(TypeError):
        s.options["ksp_view"] = "x"                 # a frozen value: its options cannot change under a solver
    assert s.entries() == {"ksp_type": "bcgs", "ksp_view": None}


# -- 3. two curves, two settings, one process ----------------------------------------------------------
def test_two_curves_with_their_own_settings_in_one_process(capfd):
    from petsc_adhesion import CurveRequest, GridChoice, Model, SolverChoice, trace_curve

    grid, model = GridChoice("uniform", n=101), Model(mu=1.0)
    request = CurveRequest()
    tight = SolverChoice(arclength=PetscSettings(ksp_type="gmres", ksp_rtol=1e-12, options={"ksp_view": None}))
    other = SolverChoice(natural=PetscSettings(ksp_type="bcgs", snes_monitor=True),
                         arclength=PetscSettings(ksp_type="bcgs", pc_type="lu", options={"ksp_view": None}))
    capfd.readouterr()
    a = trace_curve(model, grid, tight, request=request)
    out_a = capfd.readouterr().out
    b = trace_curve(model, grid, other, request=request)
    out_b = capfd.readouterr().out
    # PETSc's own report of each curve's arclength KSP: its type and tolerances
    assert "type: gmres" in out_a and "relative=1e-12" in out_a and "type: bcgs" not in out_a
    assert "type: bcgs" in out_b and "type: gmres" not in out_b and "relative=1e-12" not in out_b
    # the monitor asked of one curve's natural corrector, and of it only
    assert "SNES Function norm" in out_b and "SNES Function norm" not in out_a
    # the same curve: every event the same within its error bars
    assert [e.kind for e in a.events] == [e.kind for e in b.events]
    assert len(a.events) >= 3
    for ea, eb in zip(a.events, b.events):
        assert abs(ea.F.value - eb.F.value) <= ea.F.err + eb.F.err + 1e-12, (ea.kind, ea.F, eb.F)
        assert abs(ea.lam.value - eb.lam.value) <= ea.lam.err + eb.lam.err + 1e-12, (ea.kind, ea.lam, eb.lam)


def test_api_keywords_are_the_typed_settings():
    """A solver option given to the API as a keyword: read into the settings, honoured by its solver."""
    loose = pa.solve(-2.0, mu=1.0, grid_type="uniform", grid_n=101, snes_rtol=1e-2)
    tight = pa.solve(-2.0, mu=1.0, grid_type="uniform", grid_n=101, snes_rtol=1e-12)
    from petsc_adhesion import GridChoice, Model, SolverChoice, solve_at

    lib = solve_at(-2.0, Model(mu=1.0), GridChoice("uniform", n=101), SolverChoice(fixed=PetscSettings(snes_rtol=1e-2)))
    assert lib.snes_iterations == loose.snes_iterations < tight.snes_iterations
    assert abs(lib.F - loose.F) == 0.0


# -- 4. the library's entry checks ---------------------------------------------------------------------
def _bodies(**kw):
    from petsc_adhesion import Bodies

    return Bodies(**{"radius": 1e-6, "young1": 1e9, "poisson1": 0.3, "epsilon": 4e-10, "gamma": 0.05, **kw})


@pytest.mark.parametrize("call, line", [
    (lambda L: L.trace_curve(L.Model(mu=math.nan)), "mu: expected a finite real >= 0, got nan"),
    (lambda L: L.trace_curve(L.Model(mu=-1.0)), "mu: expected a finite real >= 0, got -1.0"),
    (lambda L: L.trace_curve(L.Model(mu=1.0, sigma=math.nan)), "sigma: expected a finite real >= 0"),
    (lambda L: L.solve_at(-2.0, L.Model(sigma=math.inf)), "sigma: expected a finite real >= 0, got inf"),
    (lambda L: L.solve_at(math.nan, L.Model()), "lam: expected the approach, a finite real"),
    (lambda L: L.trace_curve(L.Model(bodies=_bodies(epsilon=0.0))), "epsilon: expected the equilibrium spacing"),
    (lambda L: L.solve_at(-2.0, L.Model(bodies=_bodies(epsilon=-4e-10))), "epsilon: expected the equilibrium"),
    (lambda L: L.trace_curve(L.Model(bodies=_bodies(gamma=math.nan))), "gamma: expected the work of adhesion"),
    (lambda L: L.trace_curve(L.Model(), L.SolverChoice(pmat="lu")), "pmat 'lu': expected one of dense, band, shell"),
    (lambda L: L.trace_curve(L.Model(), request={"spring": 1}), "request: expected a CurveRequest"),
    (lambda L: L.trace_curve(L.Model(), solver=L.SolverChoice(fixed=PetscSettings(snes_rtol=1e-3))),
     "solver.fixed: settings of a solver trace_curve does not make (it makes natural and arclength)"),
    (lambda L: L.solve_at(-2.0, L.Model(), solver=L.SolverChoice(arclength=PetscSettings(ksp_type="cg"))),
     "solver.arclength: settings of a solver solve_at does not make (it makes fixed)"),
    (lambda L: L.trace_curve(L.Model(), solver=L.SolverChoice(fold=PetscSettings(ksp_type="cg"))),
     "solver.fold: settings of a solver trace_curve does not make"),
    (lambda L: L.CurveRequest(spring=0.0), "spring stiffness 0.0: expected a finite K > 0"),
    (lambda L: L.CurveRequest(spring=-1.0), "spring stiffness -1.0"),
    (lambda L: L.CurveRequest(spring=math.nan), "spring stiffness nan"),
    (lambda L: L.CurveRequest(spring=math.inf), "spring stiffness inf"),
])
def test_library_entry_refuses_in_one_line(call, line):
    import petsc_adhesion as L

    with pytest.raises(ValueError) as e:
        call(L)
    assert str(e.value).startswith(line) and "\n" not in str(e.value), str(e.value)


@pytest.mark.parametrize("kw, line", [
    ({"mu": math.nan}, "-adh_mu: expected"), ({"sigma": math.nan}, "-adh_sigma: expected"),
    ({"afm_spring": 0.0}, "-afm_spring: expected"), ({"afm_spring": -2.0}, "-afm_spring: expected"),
    ({"afm_spring": math.inf}, "-afm_spring: expected"), ({"afm_spring": math.nan}, "-afm_spring: expected"),
    ({"mu": None, "phys_radius": 1e-6, "phys_young1": 1e9, "phys_poisson1": 0.3, "phys_gamma": 0.05,
      "phys_epsilon": 0.0}, "-phys_epsilon: expected"),
    ({"nat_ksp_rtol": 2.0}, "-nat_ksp_rtol: expected"),
])
def test_api_entry_refuses_in_one_line(kw, line):
    with pytest.raises(pa.InputError) as e:
        pa.curve(**{**CURVE, **kw})
    assert str(e.value).startswith(line) and "\n" not in str(e.value), str(e.value)


# -- 4. the first call from a thread that is not the main one ------------------------------------------
def test_first_api_call_from_another_thread():
    """PETSc started by a first call from a worker thread (a web server's, a notebook executor's): Python
    sets signal handlers from the main thread only; the result is the main thread's."""
    code = ("import json, threading, petsc_adhesion as pa\n"
            "out = {}\n"
            "def work():\n"
            "    try:\n"
            "        out['F'] = pa.solve(-2.0, mu=1.0, grid_type='uniform', grid_n=101).F\n"
            "    except BaseException as e:\n"
            "        out['error'] = repr(e)\n"
            "t = threading.Thread(target=work); t.start(); t.join()\n"
            "out['main'] = pa.solve(-2.0, mu=1.0, grid_type='uniform', grid_n=101).F\n"
            "print(json.dumps(out))\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    import json
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert "error" not in out, out
    assert out["F"] == out["main"] and np.isfinite(out["F"])
