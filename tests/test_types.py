"""The library type-checked by mypy, and the wheel without the benchmarks.

mypy reads its settings from pyproject.toml ([tool.mypy]: the library petsc_adhesion/, the benchmarks
excluded, check_untyped_defs); the problems and pressure laws are checked against the protocols of
core/protocol.py wherever a function takes one.  ./run installs mypy; without it the check skips.
The benchmarks stay in the checkout (./run bench, ./run figures) and out of the wheel: the wheel built
from pyproject.toml's settings holds every module of the library and none of the benchmarks.
"""
import glob
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import zipfile

import pytest

from conftest import ROOT

PACKAGE = os.path.join(ROOT, "petsc_adhesion")
BENCHMARKS = os.path.join(PACKAGE, "benchmarks")


def _library_modules() -> set:
    """Paths (relative to the checkout, '/'-separated) of the library's modules: every .py file of the
    package outside the benchmarks."""
    out = set()
    for d, dirs, files in os.walk(PACKAGE):
        dirs[:] = [x for x in dirs if x != "__pycache__" and os.path.join(d, x) != BENCHMARKS]
        out |= {os.path.relpath(os.path.join(d, f), ROOT).replace(os.sep, "/") for f in files if f.endswith(".py")}
    return out


@pytest.fixture(scope="module")
def mypy(tmp_path_factory):
    """Run mypy with pyproject.toml's settings from the checkout; its cache outside the checkout, shared by
    this module's runs."""
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed in this Python (./run setup installs it)")
    cache = tmp_path_factory.mktemp("mypy_cache")

    def run(*args):
        cmd = [sys.executable, "-m", "mypy", "--config-file", os.path.join(ROOT, "pyproject.toml"),
               "--cache-dir", str(cache), *args]
        return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)

    return run


def test_library_has_no_type_errors(mypy):
    """mypy over the library as pyproject.toml configures it: no errors, and every library module checked."""
    r = mypy()
    assert r.returncode == 0, "mypy found errors:\n" + r.stdout + r.stderr
    m = re.search(r"Success: no issues found in (\d+) source files", r.stdout)
    assert m, r.stdout + r.stderr
    # the check reached the whole library, no more (the benchmarks excluded), no less
    assert int(m.group(1)) == len(_library_modules())


LAW = '''
import numpy as np
from petsc_adhesion.discretization.resolution import attraction_range


class Law:
    """A smooth law by its members: eq. (5) at the gap H + 1."""
    rule, n, sigma, smooth = "none", 1, 0.0, True
{wall}
    def __call__(self, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g = H + 1.0
        return g ** -9 - g ** -3, 3 * g ** -4 - 9 * g ** -10

    def error(self, H: np.ndarray) -> np.ndarray:
        return np.zeros_like(H)

    def describe(self) -> dict:
        return {{}}


attraction_range(Law())
'''


#: Each class of the library as the protocol it implements: mypy compares their members' types.
CONFORMS = '''
from petsc_adhesion.core.fold import FoldSystem
from petsc_adhesion.core.protocol import ContinuationProblem, FoldBase, PressureLaw, TracedProblem
from petsc_adhesion.discretization.edge_frame import EdgeFrameProblem
from petsc_adhesion.discretization.problem import Problem
from petsc_adhesion.model import pressure


def physical(p: Problem) -> tuple[TracedProblem, FoldBase]:
    return p, p


def edge(p: EdgeFrameProblem) -> TracedProblem:
    return p


def fold(f: FoldSystem[Problem]) -> ContinuationProblem:
    return f


def laws(a: pressure.PressureLaw, b: pressure.WallLaw, c: pressure.HistogramLaw) -> list[PressureLaw]:
    return [a, b, c]
'''


def test_the_classes_conform_to_their_protocols_and_a_law_without_wall_does_not(mypy, tmp_path):
    """The problems (physical frame, frame of the edge, fold system) and the pressure laws conform to the
    protocols of core/protocol.py in their members' types, not only their names (which tests/test_protocol.py
    checks at run time); a law lacking its wall is a type error where a law is taken, the same law with it
    is not."""
    (tmp_path / "conforms.py").write_text(CONFORMS)
    (tmp_path / "with_wall.py").write_text(LAW.format(wall="    wall = -1.0\n"))
    (tmp_path / "without_wall.py").write_text(LAW.format(wall=""))
    r = mypy(*(str(tmp_path / f) for f in ("conforms.py", "with_wall.py", "without_wall.py")))
    assert r.returncode == 1, r.stdout + r.stderr
    assert "conforms.py" not in r.stdout and "with_wall.py" not in r.stdout.replace("without_wall.py", ""), r.stdout
    assert re.search(r'without_wall\.py:\d+: error: Argument 1 to "attraction_range" has incompatible type "Law"; '
                     r'expected "PressureLaw".*\n.*without_wall\.py:\d+: note: "Law" is missing following "PressureLaw" '
                     r'protocol member:\n.*without_wall\.py:\d+: note: +wall\n', r.stdout), r.stdout


def test_wheel_leaves_out_the_benchmarks(tmp_path):
    """The wheel built with pyproject.toml's settings: every library module, the options' table and the shipped
    tables of family/, no benchmark."""
    src = tmp_path / "src"
    src.mkdir()
    for f in ("pyproject.toml", "README.md"):
        shutil.copy(os.path.join(ROOT, f), src / f)
    # a copy, so that the build's egg-info and build/ land outside the checkout
    shutil.copytree(PACKAGE, src / "petsc_adhesion", ignore=shutil.ignore_patterns("__pycache__"))
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
                        "--no-index", "-w", str(tmp_path / "dist"), str(src)],
                       capture_output=True, text=True, timeout=300, env=dict(os.environ, PYTHONWARNINGS="ignore"))
    assert r.returncode == 0, r.stdout + r.stderr
    wheels = glob.glob(str(tmp_path / "dist" / "petsc_adhesion-*.whl"))
    assert len(wheels) == 1, wheels
    names = set(zipfile.ZipFile(wheels[0]).namelist())
    assert not [n for n in names if n.startswith("petsc_adhesion/benchmarks")]
    assert {n for n in names if n.endswith(".py")} == _library_modules()
    assert "petsc_adhesion/app/options/petsc_options.txt" in names
    # the shipped tables: an installed package without them would fall back to the solver without a word
    shipped = {os.path.relpath(f, ROOT) for f in glob.glob(os.path.join(PACKAGE, "family", "**", "*.npz"), recursive=True)}
    assert shipped and shipped <= names, (shipped, sorted(n for n in names if n.endswith(".npz")))
