"""The layers of the package, checked on its import graph (imports inside functions included).

Data flow one way: the continuation core knows nothing of adhesion, the model nothing of its discretization,
the library (core, model, discretization, tracing) nothing of the application or the files it writes, and
nothing but the benchmarks imports the benchmarks.  No module imports itself through others (no cycle).
A contract on the import graph of our own, in the manner of import-linter's layers and forbidden contracts:
ast reads every ``import`` and ``from ... import`` of every module, at any depth.
"""
import ast
import os

import pytest

from conftest import ROOT

PACKAGE = os.path.join(ROOT, "petsc_adhesion")
#: Leaf modules every part may import (they import nothing of the package).
LEAVES = {"petsc_adhesion.errors", "petsc_adhesion.version", "petsc_adhesion.singleton", "petsc_adhesion.brent"}
#: part -> the parts it may import (besides itself and LEAVES)
ALLOWED = {
    "core": set(),
    "model": set(),
    "discretization": {"core", "model"},
    "tracing": {"core", "model", "discretization"},
    "family": {"core", "model", "discretization", "tracing"},
    "io": {"model", "tracing"},
    "fitting": {"core", "model", "discretization", "tracing", "family"},
    "maps": {"core", "model", "discretization", "tracing", "fitting", "family"},
    "population": {"core", "model", "discretization", "tracing", "family"},
    "app": {"core", "model", "discretization", "tracing", "io", "fitting", "family", "maps", "population"},
    "benchmarks": {"core", "model", "discretization", "tracing", "io", "app", "fitting", "family", "maps", "population"},
}


def _module(path: str) -> str:
    rel = os.path.relpath(path, ROOT)[:-3].replace(os.sep, ".")
    return rel[: -len(".__init__")] if rel.endswith(".__init__") else rel


def _graph() -> dict:
    """module -> {imported module of the package: first line}, every import at any depth; and the imports
    whose module does not exist."""
    graph, missing = {}, []
    for folder, _, files in os.walk(PACKAGE):
        for name in files:
            if not name.endswith(".py"):
                continue
            path = os.path.join(folder, name)
            me = _module(path)
            package = me if name == "__init__.py" else me.rpartition(".")[0]
            edges = graph.setdefault(me, {})
            for node in ast.walk(ast.parse(open(path).read(), path)):
                if isinstance(node, ast.Import):
                    targets = [(a.name, None) for a in node.names]
                elif isinstance(node, ast.ImportFrom):
                    base = node.module or ""
                    if node.level:
                        parts = package.split(".")
                        base = ".".join(parts[: len(parts) - node.level + 1] + ([base] if base else []))
                    # "from X import y": y may be a module of X, or a name defined in X
                    targets = [(f"{base}.{a.name}", base) for a in node.names]
                    if base.startswith("petsc_adhesion"):
                        missing.append((me, node.lineno, base))
                else:
                    continue
                for t in targets:
                    if t[0].startswith("petsc_adhesion"):
                        edges.setdefault(t, node.lineno)
    modules = set(graph)

    def target(t):
        # "from X import y": the module X.y, or, where y is a name defined in X, the module X
        name, base = t
        return name if name in modules or base is None else _owner(base, modules)

    return ({m: {target(t): line for t, line in edges.items() if target(t)} for m, edges in graph.items()},
            [f"{m}:{line}: no module {b}" for m, line, b in missing if b not in modules])


def _owner(target: str, modules: set) -> str | None:
    while target and target not in modules:
        target = target.rpartition(".")[0]
    return target or None


def _part(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and parts[1] in ALLOWED) else None


GRAPH, MISSING = _graph()


def test_every_import_of_the_package_names_a_module_of_it():
    """A relative import gone wrong in a move (an import inside a function fails only when it runs)."""
    assert not MISSING, MISSING


def test_the_graph_is_read():
    """The reader sees the package's imports (a guard against a contract that checks nothing)."""
    assert len(GRAPH) > 40
    assert "petsc_adhesion.core.newton" in GRAPH["petsc_adhesion.core.continuation"]
    assert "petsc_adhesion.tracing.trace" in GRAPH["petsc_adhesion.app.run"]
    # an import inside a function counts too
    assert "petsc_adhesion.app.study" in GRAPH["petsc_adhesion.app.cli"]


@pytest.mark.parametrize("part", sorted(ALLOWED))
def test_each_part_imports_only_what_lies_below_it(part):
    bad = []
    for module, edges in GRAPH.items():
        if _part(module) != part:
            continue
        for target, line in edges.items():
            other = _part(target)
            if target in LEAVES or other == part or target == "petsc_adhesion" and part == "benchmarks":
                continue
            if other not in ALLOWED[part]:
                bad.append(f"{module}:{line} imports {target}")
    assert not bad, "\n".join(bad)


def test_the_leaves_import_nothing_of_the_package():
    for leaf in LEAVES:
        assert not GRAPH[leaf], (leaf, GRAPH[leaf])


def test_only_the_benchmarks_import_the_benchmarks():
    bad = [f"{m} imports {t}" for m, edges in GRAPH.items() for t in edges
           if _part(t) == "benchmarks" and _part(m) != "benchmarks"]
    assert not bad, bad


def test_no_module_imports_itself_through_others():
    """No cycle of imports, whether at the top of a module or inside a function (Tarjan's components)."""
    index, low, stack, on, cycles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in GRAPH.get(v, {}):
            if w == v:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    assert not cycles, cycles


def test_no_module_is_over_600_lines():
    long = {}
    for folder, _, files in os.walk(PACKAGE):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                n = sum(1 for _ in open(path))
                if n > 600:
                    long[os.path.relpath(path, ROOT)] = n
    assert not long, long
