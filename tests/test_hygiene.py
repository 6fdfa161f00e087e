"""Every PETSc object a call makes is destroyed on every path: success, a refused option, a failed solve, a
failed change of grid.  PETSc keeps a list of its live objects (-objects_dump); a script in its own process
makes each call and reads that list after it (test_api.py does the same for the Python API's calls)."""
import json
import subprocess
import sys

import conftest

_SCRIPT = r'''
import ctypes, gc, json, sys
import petsc4py
petsc4py.init([sys.argv[0], "-objects_dump"])
from petsc4py import PETSc
import numpy as np

lib = ctypes.CDLL(PETSc.__file__)
lib.PetscObjectsView.argtypes = [ctypes.c_void_p]


def live():
    gc.collect()
    PETSc.garbage_cleanup()
    v = PETSc.Viewer().createASCII(sys.argv[1], comm=PETSc.COMM_SELF)
    lib.PetscObjectsView(ctypes.c_void_p(v.handle))
    v.destroy()
    return [ln for ln in open(sys.argv[1]).read().splitlines()[2:] if "PetscViewer" not in ln]


from petsc_adhesion.discretization import grid, preconditioning
from petsc_adhesion.discretization.edge_frame import EdgeFrameProblem
from petsc_adhesion.discretization.influence import create_influence
from petsc_adhesion.discretization.problem import Problem
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.tracing import tracer as tracing_tracer
from petsc_adhesion.tracing.critical import fold_system
from petsc_adhesion.core.newton import PetscSettings
from petsc_adhesion.tracing.trace import GridChoice, SolverChoice, solve_at, trace_curve

out = {"before": live()}

# the shells' diagonals (-pc_type jacobi reads them), asked for again and again
rho = np.linspace(0.0, 3.0, 61)
pb = EdgeFrameProblem(Model(mu=20.0, rmax=150.0), rho, create_influence(rho), 2.0, preconditioning.Shell())
x = pb.create_vec()
x.set(1.0)
pb.linearize(x, -5.0)
d = pb.jacobian.createVecLeft()
for _ in range(3):
    pb.jacobian.getDiagonal(d)
for obj in (d, x, pb):
    obj.destroy()
r = grid.uniform(51, 10.0)
pb = Problem(Model(mu=1.0), r, create_influence(r), preconditioning.Shell())
d = pb.jacobian.createVecLeft()
for _ in range(3):
    pb.jacobian.getDiagonal(d)
d.destroy()
pb.destroy()
out["diagonals"] = live()

# the fold system, its KSP refused
try:
    fold_system(Model(mu=2.0, sigma=0.2, rmax=10.0), grid.uniform(51, 10.0), "sigma", 0.2,
                settings=PetscSettings(options={"ksp_type": "nonesuch"}))
except PETSc.Error:
    out["fold refused"] = True
out["fold"] = live()

# a fixed-approach solve whose Newton fails: its guess vector too
try:
    solve_at(-2.0, Model(mu=1.0), GridChoice("uniform", n=101), SolverChoice(fixed=PetscSettings(snes_max_it=1)))
except RuntimeError:
    out["solve failed"] = True
out["solve"] = live()

# a curve whose change of grid fails: the new segment and every other
calls = {"n": 0}
real = tracing_tracer.carry


def failing(*args, **kw):
    calls["n"] += 1
    if calls["n"] > 1:
        raise RuntimeError("a change of grid that fails")
    return real(*args, **kw)


tracing_tracer.carry = failing
try:
    trace_curve(Model(mu=5.0))
except RuntimeError:
    out["curve failed"] = calls["n"]
tracing_tracer.carry = real
out["curve"] = live()
print(json.dumps(out))
'''


def test_no_petsc_object_outlives_its_call(tmp_path):
    script = tmp_path / "hygiene.py"
    script.write_text(_SCRIPT)
    proc = subprocess.run([sys.executable, str(script), str(tmp_path / "objects.txt")], env=conftest._env(),
                          cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.splitlines()[-1])
    assert out["before"] == []
    assert out["fold refused"] and out["solve failed"] and out["curve failed"] == 2   # each path was taken
    for key in ("diagonals", "fold", "solve", "curve"):
        assert out[key] == [], (key, out[key])
