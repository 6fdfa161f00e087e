"""State owned by its class: no object writes another's fields or reads another's privates.

An AST scan of the library's core, discretization, tracing and checkpoint (the code that holds a curve's
state) for assignments to attributes of anything but ``self`` and reads of ``_private`` attributes of
anything but ``self``, with the exceptions listed and justified below; then what the owners offer instead,
each against an independent truth: a correction that is typed and on its curve (a closed form), a domain
guard that asks without counting, a point carried between grids by the problem that receives it (exact at
the same nodes, the closed form of a rigid sphere's contact radius elsewhere), and the PETSc plumbing the
two frames share.
"""
import ast
import dataclasses
import math
import os

import numpy as np
import pytest

from conftest import ROOT, make_problem
from toy_problems import Barrier

PACKAGE = os.path.join(ROOT, "petsc_adhesion")
#: where a curve's state lives: every module of these parts, and the checkpoint
SCANNED = ("core", "discretization", "tracing", os.path.join("app", "checkpoint.py"))
#: (module, attribute) -> why another object's attribute is written there
EXCEPTIONS = {
    ("core/capi.py", "argtypes"): "ctypes declares a foreign function's signature by assignment to the "
                                  "function object this module loaded itself (ctypes has no other way)",
    ("core/capi.py", "restype"): "the same, for its result",
    ("tracing/trace.py", "estimate"): "a located event's error bars, attached by trace_curve: the typed results "
                                      "being made of a curve's events take their place",
}


def _files():
    for part in SCANNED:
        path = os.path.join(PACKAGE, part)
        if path.endswith(".py"):
            yield path
            continue
        for folder, _, names in os.walk(path):
            yield from (os.path.join(folder, n) for n in sorted(names) if n.endswith(".py"))


#: methods that change a list, dict or set in place: called on another object's field, they write it
MUTATORS = {"append", "extend", "insert", "pop", "remove", "clear", "update", "sort", "reverse", "add", "discard",
            "setdefault", "popitem"}


def _mine(node) -> bool:
    return isinstance(node, ast.Name) and node.id in ("self", "cls")


def findings(source: str, name: str = "<source>") -> list[tuple[str, int, str, str]]:
    """(module, line, kind, expression) of every write to an attribute of an object other than self (an
    assignment, or a method of MUTATORS called on it), and every read of a _private attribute of one."""
    out = []
    for node in ast.walk(ast.parse(source, name)):
        targets = []
        if isinstance(node, (ast.Assign, ast.Delete)):
            targets = node.targets
        elif isinstance(node, (ast.AugAssign, ast.AnnAssign)):
            targets = [node.target]
        for t in targets:
            for el in t.elts if isinstance(t, (ast.Tuple, ast.List)) else [t]:
                if isinstance(el, ast.Starred):
                    el = el.value
                if isinstance(el, ast.Attribute) and not _mine(el.value):
                    out.append((name, el.lineno, "write", ast.unparse(el)))
                elif isinstance(el, ast.Subscript) and isinstance(el.value, ast.Attribute) and \
                        not _mine(el.value.value):
                    out.append((name, el.lineno, "write", ast.unparse(el)))      # obj.field[i] = ...
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in ("setattr", "delattr"):
            out.append((name, node.lineno, "write", ast.unparse(node)))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in MUTATORS \
                and isinstance(node.func.value, ast.Attribute) and not _mine(node.func.value.value):
            out.append((name, node.lineno, "write", ast.unparse(node.func.value)))    # obj.field.append(...)
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__") \
                and not _mine(node.value):
            out.append((name, node.lineno, "private", ast.unparse(node)))
    return out


def _attribute(expression: str) -> str:
    return expression.rpartition(".")[2].partition("[")[0]


def test_the_scan_sees_what_it_forbids():
    """The scan finds each kind of trespass in a made-up module (so that its silence below means something)."""
    source = ("def f(seg, other, rows):\n"
              "    seg.cont.points = []\n"
              "    seg.problem.guarded += 1\n"
              "    other.values['F'] = 0.0\n"
              "    a, other.b = 1, 2\n"
              "    setattr(other, 'c', 3)\n"
              "    other.found.append(rows)\n"
              "    rows.append(other)\n"
              "    return other._x, rows\n"
              "class C:\n"
              "    def g(self):\n"
              "        self.a, self._b = 1, self._c\n")
    got = [(line, kind) for _, line, kind, _ in findings(source)]
    assert got.count((9, "private")) == 1 and len(got) == 7
    assert {line for line, kind in got if kind == "write"} == {2, 3, 4, 5, 6, 7}


def test_no_object_writes_another_objects_fields_or_reads_its_privates():
    """Nowhere in core/, discretization/, tracing/ and app/checkpoint.py but the listed exceptions."""
    bad, used = [], set()
    for path in _files():
        rel = os.path.relpath(path, PACKAGE).replace(os.sep, "/")
        with open(path) as f:
            for name, line, kind, expr in findings(f.read(), rel):
                key = (name, _attribute(expr))
                if kind == "write" and key in EXCEPTIONS:
                    used.add(key)
                    continue
                bad.append(f"{name}:{line}: {kind} {expr}")
    assert not bad, "state changed or read from outside its owner:\n" + "\n".join(bad)
    assert used <= set(EXCEPTIONS)


def test_the_tracer_asks_no_problem_for_its_class():
    """tracing/ carries a point between grids through the protocol (TracedProblem.carry), never by
    isinstance on a problem class."""
    classes = {"Problem", "EdgeFrameProblem", "FoldSystem"}
    bad = []
    for folder, _, names in os.walk(os.path.join(PACKAGE, "tracing")):
        for n in names:
            if not n.endswith(".py"):
                continue
            path = os.path.join(folder, n)
            for node in ast.walk(ast.parse(open(path).read(), path)):
                if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "isinstance":
                    named = {x.id for x in ast.walk(node.args[1]) if isinstance(x, ast.Name)}
                    if named & classes:
                        bad.append(f"{n}:{node.lineno}: {ast.unparse(node)}")
    assert not bad, bad


# -- the corrector's typed result ----------------------------------------------------------------------------
@pytest.fixture
def barrier():
    """p + x + 1/x = 0 traced from x = 2, p = -5/2 towards its fold at x = 1, p = -2."""
    from petsc_adhesion.core.continuation import Continuation, Settings
    pb = Barrier()
    cont = Continuation(pb, Settings(corrector="natural"))
    x = pb.vec(2.0)
    start = cont.start(x, -2.5)
    x.destroy()
    yield cont, start
    cont.destroy()
    pb.destroy()


def test_a_correction_is_typed_frozen_and_on_the_curve(barrier):
    """The natural corrector's Correction: on p = -(x + 1/x) to Newton's tolerance, its tangent the unit
    vector along (1, -(1 - 1/x^2)) (the curve's slope), its work counted; it cannot be changed."""
    from petsc_adhesion.core.continuation import Correction
    cont, a = barrier
    c = cont.correct(a, 0.1)
    assert isinstance(c, Correction) and c.converged and c.reason == "converged" and c.corrector == "natural"
    x = float(c.x[0])
    assert abs(c.p + x + 1.0 / x) < 1e-12 and 1.0 < x < 2.0
    slope = -(1.0 - 1.0 / x**2)
    assert math.hypot(float(c.xdot[0]), c.pdot) == pytest.approx(1.0, abs=1e-12)
    assert c.pdot / float(c.xdot[0]) == pytest.approx(slope, rel=1e-9) and c.pdot > 0      # towards larger p
    assert c.newton_its >= 1 and c.tangent_its >= 1
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.p = 0.0


def test_a_failed_correction_says_why_and_holds_no_point(barrier):
    """A natural predictor past the wall x = 0 (from x = 2 along the tangent (-0.8, 0.6), ds = 3: x = -0.4)
    is refused before Newton: reason "outside", no point."""
    cont, a = barrier
    assert float(a.xdot[0]) == pytest.approx(-0.8, abs=1e-12) and a.pdot == pytest.approx(0.6, abs=1e-12)
    c = cont.correct(a, 3.0)
    assert not c.converged and c.reason == "outside" and c.x is None and math.isnan(c.p)
    assert cont.step(a, 3.0) is None


def test_turn_around_puts_a_backward_run_in_the_curves_order(barrier):
    """The points of a run, turned around: in the reverse order, tangents and rates reversed, the first a
    start, each other's step the distance along the tangent before it, positive."""
    cont, a = barrier
    cont.run(a, until=lambda _, b: len(cont.points) > 4)
    before = list(cont.points)
    cont.turn_around("far")
    after = cont.points
    assert [p.p for p in after] == [p.p for p in reversed(before)]
    assert [p.pdot for p in after] == [-p.pdot for p in reversed(before)]
    assert after[0].corrector == "start" and after[0].ds == 0.0
    assert all(p.corrector == "far" and p.ds > 0 for p in after[1:])


# -- queries that change nothing --------------------------------------------------------------------------------
def test_the_domain_guard_asks_without_counting():
    """step_fraction is a query: asked twice it counts nothing; Newton's guard records a shortened step once,
    through the problem's own record_guard, and a checkpoint's count is taken up by restore_counters."""
    from petsc_adhesion.core.newton import guard
    pb, newton = make_problem()
    h = np.full(pb.hi - pb.lo, pb.law.wall + 1.0)
    y = np.full_like(h, 2.0)                    # a step of twice the room to the wall
    fractions = [pb.step_fraction(h, y) for _ in range(2)]
    assert fractions == [pytest.approx(0.45)] * 2 and pb.guarded == 0       # TO_WALL (0.9) of the room, 1
    Y = pb.create_vec()
    Y.setArray(y)
    assert guard(pb, h, Y) and pb.guarded == 1
    assert Y.getArray(readonly=True) == pytest.approx(0.9)
    pb.restore_counters(7)
    assert pb.guarded == 7
    Y.destroy()
    newton.destroy()
    pb.destroy()


# -- a point carried by the problem that receives it ---------------------------------------------------------------
def _point(x, p, xdot, pdot):
    from petsc_adhesion.core.protocol import Point
    return Point(x=np.asarray(x, dtype=float), p=p, xdot=np.asarray(xdot, dtype=float), pdot=pdot)


def _edge_frame(rho, scale, mu=1.0):
    from petsc_adhesion.discretization import preconditioning
    from petsc_adhesion.discretization.edge_frame import EdgeFrameProblem
    from petsc_adhesion.discretization.influence import create_influence
    from petsc_adhesion.model.parameters import Model
    return EdgeFrameProblem(Model(mu=mu), rho, create_influence(rho), scale, preconditioning.Dense())


def test_carry_onto_the_same_grid_is_the_identity():
    """Each frame carries a point of its own grid onto itself unchanged: the physical frame's H and tangent,
    the frame of the edge's D, a and their rates (a the scale of its nodes)."""
    pb, newton = make_problem()
    n = pb.hi - pb.lo
    r = pb.r[pb.lo:pb.hi]
    pt = _point(0.5 * r * r + 1.0 + np.cos(r), -1.0, np.sin(r), 0.3)
    x, xdot = pb.carry(pb, pt)
    assert np.max(np.abs(x - pt.x)) < 1e-13 and np.array_equal(xdot, pt.xdot) and x.size == n
    newton.destroy()
    pb.destroy()
    rho = np.linspace(0.0, 4.0, 81)
    ef = _edge_frame(rho, 1.5)
    d = 1.0 + np.cos(rho[ef.lo:ef.hi])
    ddot = np.sin(rho[ef.lo:ef.hi])
    pt = _point(np.append(d, 1.5) if ef.last else d, -1.0, np.append(ddot, 0.25) if ef.last else ddot, 0.3)
    x, xdot = ef.carry(ef, pt)
    assert np.max(np.abs(x - pt.x)) < 1e-13 and np.max(np.abs(xdot - pt.xdot)) == 0.0
    ef.destroy()


def test_carry_of_a_rigid_sphere_into_the_frame_of_its_edge():
    """A rigid sphere's state H = r^2/2 - lambda (eq. 27) carried from the physical frame: its deformation
    D = -lambda everywhere, its contact radius a = sqrt(2 (level + lambda)) where H reaches the edge level,
    and along the tangent (Hdot = -lamdot) a's rate lamdot / a, by the closed form."""
    from petsc_adhesion.discretization.contact import edge_level
    pb, newton = make_problem()
    lam, lamdot = 1.0, 0.6
    r = pb.r[pb.lo:pb.hi]
    pt = _point(0.5 * r * r - lam, lam, np.full(r.size, -lamdot), lamdot)
    a = math.sqrt(2.0 * (edge_level(pb.law) + lam))
    assert pb.radius(pt.x) == pytest.approx(a, rel=1e-12)
    ef = _edge_frame(np.linspace(0.0, 4.0, 81), a)
    x, xdot = ef.carry(pb, pt)
    nloc = ef.hi - ef.lo
    assert np.max(np.abs(x[:nloc] + lam)) < 1e-13 and np.max(np.abs(xdot[:nloc] + lamdot)) < 1e-13
    if ef.last:
        assert x[-1] == pytest.approx(a, rel=1e-12) and xdot[-1] == pytest.approx(lamdot / a, rel=1e-6)
    ef.destroy()
    newton.destroy()
    pb.destroy()


# -- the PETSc plumbing the two frames share ------------------------------------------------------------------------
def test_both_frames_share_their_petsc_plumbing():
    """One Plumbing in each frame holds the influence matrix, its work vectors, the gathers and the shell
    Jacobian; the frames' modules make none of these themselves.  The shell's diagonal (-pc_type jacobi)
    is the diagonal of the frame's dense rows of G_x, a path that shares no code with it."""
    from petsc_adhesion.discretization.plumbing import Plumbing
    for name in ("problem.py", "edge_frame.py"):
        source = open(os.path.join(PACKAGE, "discretization", name)).read()
        for made in ("createPython", "Scatter", "createVecs", "allgather", "getDiagonal"):
            assert made not in source, (name, made)
    pb, newton = make_problem()
    ef = _edge_frame(np.linspace(0.0, 4.0, 81), 1.5)
    for problem in (pb, ef):
        assert isinstance(problem.plumbing, Plumbing) and problem.jacobian is problem.plumbing.jacobian
        assert problem.layout is problem.plumbing.layout and problem.A is problem.plumbing.A
        x = problem.create_vec()
        nloc = problem.hi - problem.lo
        h = 0.5 * np.linspace(0.0, 3.0, nloc) ** 2 + 0.2       # gaps in the attraction's range
        x.setArray(np.append(h, 1.5) if problem is ef and ef.last else h)
        problem.linearize(x, 0.8)
        rows = problem.jacobian_rows(np.empty((nloc, problem.layout.N)))
        d = problem.jacobian.createVecLeft()
        problem.jacobian.getDiagonal(d)                 # through the shell to the frame's own diagonal
        diag = d.getArray(readonly=True)
        dense = rows[np.arange(nloc), np.arange(problem.lo, problem.hi)]
        assert np.max(np.abs(diag[:nloc] - dense) / np.maximum(1.0, np.abs(dense))) < 1e-14
        assert np.ptp(diag[:nloc]) > 1e-3               # P' varies: not the identity's diagonal
        if problem is ef and ef.last:
            assert diag[-1] == 1.5                      # the pin's row: d(pin)/da = a
        for v in (d, x):
            v.destroy()
    whole = pb.gather(np.arange(pb.lo, pb.hi, dtype=float))
    assert np.array_equal(whole, np.arange(pb.r.size, dtype=float))
    ef.destroy()
    newton.destroy()
    pb.destroy()
