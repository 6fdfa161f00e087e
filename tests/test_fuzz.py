"""Fuzz: random option sets, deterministic by seed, each ending in one line and a non-zero exit or in a valid,
complete result set.

About 1000 option sets (in the suite about 420 of them, every class of input of the 1000 kept: suite_draws) are
drawn from the real option table (petsc_adhesion.app.options.TABLE) and PETSc's solver
options under the three prefixes, with valid, out-of-range, mistyped, empty, non-finite, huge and list values,
misspelt and unknown names, words without a dash, duplicates, and files: outputs at a missing directory, a
directory, /dev/null, a FIFO, a symbolic link, an input of the run, another output; options files and guesses
that are missing, empty, binary, not UTF-8, self-including, of the wrong HDF5 kind, with NaN or values below the
wall.  About half are valid runs (mu in [0, 3], sigma in [0, 1] with the 16-point rule, fixed solves and
curves) on reduced grids (mostly uniform, 21 to 61 nodes; large mu with few steps or folds), so that the
"valid, complete result" branch is exercised as much as the refusals; valid values that would make a run
long (a big grid, a long curve) are not drawn (Generator.COST).

Every case runs over an "earlier result set" (copies of a real earlier run) in the places of its outputs, and
is judged by :func:`judge`: exit status in {0, 1, 2, 3}; status 1 or 2: exactly one printable line on stderr
starting with "petsc-adhesion: error: ", the folder unchanged (hidden temporaries included) and the earlier
files byte-identical; status 0 or 3: every requested output new, complete and valid (HDF5 with the groups of
docs/output.md, JSON, PNG/PDF/SVG magic bytes), no NaN in any dataset, attribute or JSON value, no temporary or
journal left, the JSON and the HDF5 of one run consistent, and for 3 ``complete: false`` with a warning; never
"Traceback" or "PETSC ERROR"; no case slower than HANG seconds.

Most cases run in process (``petsc_adhesion.app.cli.main``, repeatable in one process) in a worker subprocess that
takes one case at a time and captures the file descriptors 1 and 2, so that a hang or a crash of the
interpreter is caught by a time-out; 30 more run as real command lines (options files are checked before
PETSc starts there), 10 of them under ``mpiexec -n 2`` (checks that could fail on one rank only).

The defects this fuzz found (and that are fixed) are kept below as regression tests with their smallest
reproducer.

Reproduce one case: ``FUZZ_CASES=17,230 pytest -q tests/test_fuzz.py -k in_process`` (the assertion message
prints the seed, the case number, its files and its command line).  ``FUZZ_SEED`` changes the seed.
"""
from __future__ import annotations

import ctypes
import json
import math
import os
import re
import select
import shlex
import shutil
import stat
import subprocess
import sys
import time
import traceback

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PREFIX = "petsc-adhesion: error: "
SEED = int(os.environ.get("FUZZ_SEED", "20261122"))
N_IN_PROCESS = 1000
#: The suite runs the first N_SUITE of the N_IN_PROCESS draws and, from the rest, each draw that brings a class
#: the first lack (:func:`suite_draws`): 189 of the 1000 at the default seed, every class drawn kept (``FUZZ_ALL=1``
#: runs all 1000).  The first 100, not 400 (434 draws): the classes are what the suite must keep, and the
#: 300 draws more repeated them in other combinations for 0.2 s each, a minute and a half of the suite.
N_SUITE = 100
N_SUBPROCESS = 30          # the last N_MPI of them under mpiexec -n 2
N_MPI = 10
HANG = 10.0                # seconds: a case slower than this is a hang (reduced grids take < 1 s)
RETRY_LIMIT = 3 * (HANG + 10)   # seconds: a command line past HANG + 10 beside others, run again alone


# ======================================================================================================
# The worker: ``python tests/test_fuzz.py --worker`` runs cases in process, one JSON line in, one out
# ======================================================================================================
def _worker() -> None:
    proto_in = os.fdopen(os.dup(0), "r")
    proto_out = os.fdopen(os.dup(1), "w")
    null = os.open(os.devnull, os.O_RDWR)
    os.dup2(null, 0)                       # nothing the program reads may eat the protocol
    os.dup2(null, 1)
    import petsc4py
    petsc4py.init([sys.argv[0]])
    from petsc4py import PETSc  # noqa: F401  (PETSc is initialised: every case gets its own options)

    from petsc_adhesion.app.cli import main
    libc = ctypes.CDLL(None)

    def flush():
        sys.stdout.flush()
        sys.stderr.flush()
        libc.fflush(None)

    saved_env = dict(os.environ)
    for line in proto_in:
        case = json.loads(line)
        os.chdir(case["cwd"])
        os.environ.update(case.get("env", {}))
        fds = {fd: os.dup(fd) for fd in (1, 2)}
        out = os.open(case["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        err = os.open(case["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        flush()
        os.dup2(out, 1)
        os.dup2(err, 2)
        escaped, status = None, None
        t0 = time.perf_counter()
        try:
            status = main(["petsc-adhesion", *case["args"]])
        except BaseException:              # noqa: B036  (anything escaping main is a defect)
            escaped = traceback.format_exc()
        finally:
            elapsed = time.perf_counter() - t0
            flush()
            for fd, copy in fds.items():
                os.dup2(copy, fd)
                os.close(copy)
            os.close(out)
            os.close(err)
            os.environ.clear()
            os.environ.update(saved_env)
            os.chdir(ROOT)
        proto_out.write(json.dumps({"id": case["id"], "status": status, "escaped": escaped,
                                    "elapsed": elapsed}) + "\n")
        proto_out.flush()


if __name__ == "__main__" and sys.argv[1:] == ["--worker"]:
    _worker()
    sys.exit(0)

# ======================================================================================================
# Everything below runs in pytest
# ======================================================================================================
import pytest  # noqa: E402

import conftest  # noqa: E402
from conftest import run_cli  # noqa: E402
from petsc_adhesion.app.options.table import TABLE
from petsc_adhesion.app.options.checks import petsc_names

h5py = pytest.importorskip("h5py")

OUTPUTS = ("out", "summary", "plot", "csv", "csv_events")
#: the option sets of the earlier result set (a curve: it has all three files) and of the guess files
EARLIER_ARGS = ("-adh_mu", "0.77", "-grid_type", "uniform", "-grid_n", "33", "-cont_F_max", "0")
GUESS_ARGS = ("-adh_mu", "1", "-adh_lambda", "-2", "-grid_type", "uniform", "-grid_n", "41")
PLOT_MAGIC = {".png": b"\x89PNG", ".pdf": b"%PDF", ".svg": b"<?xml"}


# -- the case generator ---------------------------------------------------------------------------------
def _num(x: float) -> str:
    return f"{x:.6g}"


class Case(dict):
    """One fuzz case: ``args`` (with ``{D}`` for its folder), ``files`` (relative path -> spec), ``env``,
    ``outputs`` (option -> path it names, when the run should write it), ``cat`` (its category)."""

    def __init__(self, cid: int, cat: str):
        super().__init__(id=cid, cat=cat, args=[], files={}, env={}, outputs={}, special=None)

    def add(self, *args) -> "Case":
        self["args"] += [str(a) for a in args]
        return self


#: PETSc solver options worth fuzzing (no graphics, viewers to files, debuggers or sleeps)
_PETSC_SKIP = re.compile(r"draw|lg_|plot|debugger|device|display|_view|viewer|malloc|sleep|^log|info|fp_trap|"
                         r"help|options_|on_error|signal|tmp|version|flops|mpi_return|hypre|gamg|mg_|"
                         r"fischer|matsolve|eigen|singular|explicit|_$|ksp_monitor_|snes_monitor_")
_PETSC_VALUES = ["", "1", "0", "-1", "2", "10", "1e-8", "0.5", "1e300", "-1e300", "nan", "inf", "abc", "1,2",
                 "true", "false", "gmres", "lu", "none", "jacobi", "basic", "bt", "cp", "l2", "newtonls",
                 "newtontr", "ngmres", "nrichardson", "qn", "anderson", "ncg", "ksponly", "fgmres", "bcgs",
                 "cg", "preonly", "richardson", "ilu", "bjacobi", "asm", "sor", "cholesky", "icc", "mumps",
                 "petsc", "superlu", "nd", "natural", "rcm", "NONZERO", "positive_definite", "1000000000"]
_PETSC_TYPES = {"snes_type": ["newtonls", "newtontr", "ngmres", "nrichardson", "qn", "anderson", "ncg", "ksponly",
                              "ngs", "ms", "composite", "shell", "vinewtonrsls", "vinewtonssls", "aspin", "nasm",
                              "fas", "patch", "python", "bogus"],
                "ksp_type": ["gmres", "fgmres", "lgmres", "bcgs", "cg", "preonly", "richardson", "gcr", "minres",
                             "tfqmr", "chebyshev", "cgs", "bicg", "pipecg", "fcg", "dgmres", "python", "bogus"],
                "pc_type": ["lu", "ilu", "none", "jacobi", "bjacobi", "asm", "sor", "cholesky", "icc", "eisenstat",
                            "pbjacobi", "kaczmarz", "shell", "composite", "ksp", "redundant", "python", "bogus"],
                "snes_linesearch_type": ["basic", "bt", "cp", "l2", "nleqerr", "shell", "bogus"]}
_BAD_REAL = ["abc", "", "nan", "NaN", "inf", "-inf", "+Infinity", "1e400", "-1e400", "1,2", "1;2", "0x10", "1_0",
             " 1", "1 ", "1.5.2", "--1", "1e", "e1", ".", "-", "+", "True", "\uff11", "1\u00a0", "\u0661", "1e-400",
             "9" * 400, "1/2", "1+1", "(1)", "1.0f", "1d0"]
_BAD_INT = ["1.5", "2.000001", "1e3", "1e30", "-1", "0x1F", "1_000", "9" * 40, "3.0", "nan", "inf", "", "one",
            "2,3", "+7", "07"]
_BAD_CHOICE = ["", "Uniform", "PAPER", "paper ", " paper", "hermite,none", "none,hermite", "1", "bogus", "nan",
               "dens", "arclengths", "auto\t", "\u00e9"]
_BAD_FLAG = ["maybe", "2", "-1", "TRUE", "nan", "y", "n", "enable", "1.0", "truee", "on off"]
_BAD_REALS = ["1,,2", ",", ",,", "1;2", "nan,1", "1 2", "[1,2]", "(1,2)", "1,2,", ",1", "inf", "1e400,1",
              "a,b", "1,2,3,4,5", "1e-7,0.05,1e9", "1e-6,0.05,1e9,4e-10,1", "0,0,0,0", "-1,1,1,1",
              "1e-6,0.05,-1e9,4e-10", "1e13,1,1,1"]


class Generator:
    """The cases of one seed."""

    def __init__(self, seed: int):
        self.rng = np.random.default_rng(seed)
        names = petsc_names()
        self.petsc = sorted(n for n in names if n.startswith(("snes_", "ksp_", "pc_"))
                            and not _PETSC_SKIP.search(n))
        self.app = sorted(TABLE)
        self.forced = 0             # how many of FORCED_MPI were drawn

    # small helpers
    def pick(self, seq):
        return seq[int(self.rng.integers(len(seq)))]

    def chance(self, p: float) -> bool:
        return bool(self.rng.random() < p)

    # -- valid pieces ----------------------------------------------------------------------------------
    def grid(self, case: Case, mu: float = 1.0) -> None:
        """A reduced grid: uniform (21 to 61 nodes), the paper's on few nodes, or (mu <= 1.5) the default
        one that follows the contact edge, when the option table has it (a few hundred nodes, < 0.5 s)."""
        r = self.rng.random()
        if r < 0.06 and mu <= 1.5 and "edge" in TABLE["grid_type"].choices:
            case.add("-grid_type", "edge")
        elif r < 0.14:
            case.add("-grid_type", "paper", "-grid_paper_uniform", int(self.rng.integers(21, 50)),
                     "-grid_paper_extra", int(self.rng.integers(0, 10)),
                     "-grid_paper_split", int(self.rng.integers(2, 4)))
        else:
            case.add("-grid_type", "uniform", "-grid_n", int(self.rng.integers(21, 62)))

    def model(self, case: Case, curve: bool) -> tuple:
        """-adh_mu (or the -phys_ options) in [0, 3], -adh_sigma in [0, 1]; returns (mu, sigma)."""
        if curve and self.chance(0.08):             # SI inputs: mu from eq. (9), about 0.1 to 3
            R, mu = 10 ** self.rng.uniform(-7, -5), self.rng.uniform(0.1, 3.0)
            E = (R * 0.05**2 / (mu ** 3 * (4e-10) ** 3)) ** 0.5
            case.add("-phys_radius", f"{R:.4g}", "-phys_gamma", "0.05", "-phys_young1", f"{E:.4g}",
                     "-phys_poisson1", "0", "-phys_epsilon", "4e-10")
        else:
            mu = 0.0 if self.chance(0.1) else round(float(self.rng.uniform(0, 3)), 3)
            case.add("-adh_mu", _num(mu))
        sigma = 0.0
        if self.chance(0.4):
            sigma = round(float(self.rng.uniform(0, 1)), 3)
            case.add("-adh_sigma", _num(sigma))
            if sigma > 0 and self.chance(0.2):
                case.add("-adh_hermite_points", self.pick([2, 4, 8, 16, 20]))
            if sigma > 0 and curve:     # the model spread's four more curves are past HANG (test_model_spread.py)
                case.add("-adh_model_spread", "false")
        if self.chance(0.1):
            case.add("-adh_pmat", "band", "-adh_pmat_band", int(self.rng.integers(0, 30)))
        elif self.chance(0.1):
            case.add("-adh_pmat", self.pick(["dense", "shell"]))
        return mu, sigma

    def curve_options(self, case: Case) -> None:
        case.add("-cont_F_max", self.pick(["0", "-0.2", "0.5", "1", "0"]))
        if self.chance(0.3):
            case.add("-cont_max_steps", int(self.rng.integers(1, 80)))
        if self.chance(0.15):
            values = self.rng.uniform(-3, 1, int(self.rng.integers(1, 3)))
            case.add("-cont_at_lambda", ",".join(_num(x) for x in values))
        if self.chance(0.1):
            case.add("-cont_type", self.pick(["auto", "natural", "arclength"]))
        if self.chance(0.1):
            case.add("-profiles")
        if self.chance(0.05):
            case.add("-cont_error_estimate")
        if self.chance(0.05):
            case.add("-cont_monitor")

    def outputs(self, case: Case, curve: bool, p_plot: float = 0.1) -> None:
        """Outputs at ordinary places, most over an earlier file of the same name."""
        opts = [o for o in OUTPUTS if o in ("out", "summary") or curve]     # plot and CSV: curves only
        for o in opts:
            if (o == "plot" and not self.chance(p_plot)) or (o != "plot" and not self.chance(0.6)):
                continue
            ext = {"out": ".h5", "summary": ".json", "plot": self.pick([".png", ".png", ".pdf", ".svg"]),
                   "csv": ".csv", "csv_events": ".csv"}[o]
            name = f"r{case['id']}_{o}{ext}"
            where = self.pick(["abs", "abs", "rel", "sub"])
            rel = f"sub/{name}" if where == "sub" else name
            if where == "sub":
                case["files"]["sub"] = "dir"
            if self.chance(0.7):
                case["files"][rel] = f"earlier:{o}"
            path = rel if where == "rel" else "{D}/" + rel
            case.add(f"-{o}", path)
            case["outputs"][o] = rel

    def valid_curve(self, case: Case) -> Case:
        mu, sigma = self.model(case, True)
        self.grid(case, mu)
        self.curve_options(case)
        if mu > 1.0 and sigma < 0.3 and "-cont_max_steps" not in case["args"]:
            # a coarse grid traps the contact edge of a large mu: a staircase of folds, seconds long
            case.add(*self.pick([("-cont_max_folds", int(self.rng.integers(0, 3))),
                                 ("-cont_max_steps", int(self.rng.integers(5, 40)))]))
        self.outputs(case, True)
        return case

    def valid_solve(self, case: Case) -> Case:
        self.model(case, False)
        self.grid(case)
        case.add("-adh_lambda", _num(round(float(self.rng.uniform(-4, 1.5)), 3)))
        if self.chance(0.15):
            case["files"]["guess.h5"] = "guess:good"
            case.add("-adh_guess", "guess.h5")
        if self.chance(0.1):
            case.add(self.pick(["-snes_monitor", "-ksp_converged_reason", "-snes_converged_reason"]))
        self.outputs(case, False)
        return case

    def valid(self, case: Case) -> Case:
        return self.valid_curve(case) if self.chance(0.6) else self.valid_solve(case)

    # -- bad values of application options -------------------------------------------------------------
    def value(self, o) -> str:
        """A random value for option ``o``: valid (cheap ones only), at a bound, or bad."""
        r = self.rng.random()
        if o.kind in ("real", "int"):
            if r < 0.25:
                lo = o.lo if math.isfinite(o.lo) else -1e3
                hi = min(o.hi, lo + 10) if math.isfinite(o.hi) else lo + 10
                x = self.rng.uniform(lo, hi)
                return str(int(round(x))) if o.kind == "int" else _num(x)
            if r < 0.45:
                edge = self.pick([o.lo, o.hi, o.lo - 1, o.hi + 1, o.hi * 10, -o.hi])
                if not math.isfinite(edge):
                    return self.pick(["1e308", "-1e308", "1.8e308"])
                return str(int(edge)) if o.kind == "int" else _num(edge)
            return self.pick(_BAD_INT if o.kind == "int" else _BAD_REAL)
        if o.kind == "choice":
            return self.pick(list(o.choices)) if r < 0.4 else self.pick(_BAD_CHOICE)
        if o.kind == "flag":
            return self.pick(["", "1", "0", "true", "false", "yes", "no", "on", "off"]) if r < 0.4 \
                else self.pick(_BAD_FLAG)
        if o.kind == "reals":
            return self.pick(["-1", "0", "-1,0.5", "-2,-1,0"]) if r < 0.3 else self.pick(_BAD_REALS)
        return self.pick(["", "x", "nope/x.h5", "/", ".", "-", "a b", "\t"])      # string

    def mutated(self, case: Case) -> Case:
        self.valid(case)
        for _ in range(int(self.rng.integers(1, 4))):
            name = self.pick(self.app)
            if name in OUTPUTS or name == "adh_guess":
                continue
            o = TABLE[name]
            if o.kind == "flag" and self.chance(0.5):
                case.add(f"-{name}")
            else:
                v = self.value(o)
                if self.costly(o, v):
                    continue
                case.add(f"-{name}", v)
        return case

    #: the highest valid value drawn for the options that set a run's cost (a grid, a long curve)
    COST = {"grid_n": 80, "grid_paper_uniform": 80, "grid_paper_extra": 30, "grid_paper_split": 4,
            "adh_hermite_points": 40, "cont_max_steps": 400, "adh_rmax": 30, "cont_F_max": 5,
            "cont_lambda_max": 20, "cont_max_folds": 4, "adh_mu": 3}

    @classmethod
    def costly(cls, o, v: str) -> bool:
        """A valid but expensive value (a big grid, a long curve): not drawn, so that no valid case comes
        close to HANG."""
        try:
            x = float(v)
        except ValueError:
            return False
        if o.name not in cls.COST or not math.isfinite(x) or not o.lo <= x <= o.hi:
            return False
        return x > cls.COST[o.name]

    # -- PETSc's solver options --------------------------------------------------------------------------
    def petsc_opts(self, case: Case) -> Case:
        self.valid(case)
        for _ in range(int(self.rng.integers(1, 4))):
            name = self.pick(self.petsc)
            bare = name
            prefix = self.pick(["", "nat_", "arc_"])
            if self.chance(0.1):
                prefix = self.pick(["sub_", "nat_sub_", "foo_", "arc_nat_", "NAT_"])
            if bare in _PETSC_TYPES and self.chance(0.7):
                value = self.pick(_PETSC_TYPES[bare])
            else:
                value = self.pick(_PETSC_VALUES)
            if value == "" or self.chance(0.1):
                case.add(f"-{prefix}{bare}")
            else:
                case.add(f"-{prefix}{bare}", value)
        return case

    # -- names -------------------------------------------------------------------------------------------
    def misspelt(self, name: str) -> str:
        chars = list(name)
        i = int(self.rng.integers(len(chars)))
        op = self.pick(["drop", "swap", "dup", "case", "sub"])
        if op == "drop" and len(chars) > 1:
            del chars[i]
        elif op == "swap" and i + 1 < len(chars):
            chars[i], chars[i + 1] = chars[i + 1], chars[i]
        elif op == "dup":
            chars.insert(i, chars[i])
        elif op == "case":
            chars[i] = chars[i].upper()
        else:
            chars[i] = self.pick(list("abcdefghijklmnopqrstuvwxyz_0"))
        return "".join(chars)

    def names(self, case: Case) -> Case:
        self.valid(case)
        for _ in range(int(self.rng.integers(1, 3))):
            kind = self.pick(["misspelt", "misspelt", "random", "nodash", "duplicate", "dashes", "unicode",
                              "empty", "prefixed_app", "bare_value"])
            name = self.pick(self.app)
            if kind == "misspelt":
                bad, value = self.misspelt(name), self.value(TABLE[name])
                # a "misspelling" may be right; one that names an output would be an output the oracle
                # does not know of (the misspelling of an option whose name is one letter from -out)
                if bad not in OUTPUTS and not (bad in TABLE and self.costly(TABLE[bad], value)):
                    case.add(f"-{bad}", *([] if self.chance(0.3) else [value]))
            elif kind == "random":
                n = int(self.rng.integers(1, 20))
                bad = "".join(self.pick(list("abcdefghijklmnopqrstuvwxyz_0123456789")) for _ in range(n))
                case.add(f"-{bad}", *([] if self.chance(0.4) else ["1"]))
            elif kind == "nodash":
                case.add(name, "1")
            elif kind == "duplicate":
                o = TABLE[name]
                if name in OUTPUTS or name == "adh_guess" or o.kind == "string":
                    name, o = "adh_mu", TABLE["adh_mu"]
                a, b = self.value(o), self.value(o)
                if not (self.costly(o, a) or self.costly(o, b)):
                    case.add(f"-{name}", a, f"-{name}", b)
            elif kind == "dashes":
                case.add(f"--{name}", "1")
            elif kind == "unicode":
                case.add("-adh_\u03bc", "1")
            elif kind == "empty":
                case.add(self.pick(["", "-", " ", "--"]))
            elif kind == "prefixed_app":
                case.add(f"-{self.pick(['nat_', 'arc_', 'sub_'])}{name}", "1")
            else:
                case.add(self.pick(["1", "-1", "x", "-.5", "1e3"]))
        return case

    # -- output paths --------------------------------------------------------------------------------
    def output_paths(self, case: Case) -> Case:
        curve = self.chance(0.6)
        (self.valid_curve if curve else self.valid_solve)(case)
        opt = self.pick(["out", "summary", "plot"] if curve else ["out", "summary"])
        ext = {"out": ".h5", "summary": ".json", "plot": ".png"}[opt]
        kind = self.pick(["missing_dir", "directory", "devnull", "fifo", "symlink", "dangling", "options_file",
                          "guess", "other_output", "dotdot_other", "hardlink_other", "nonutf8", "empty_name",
                          "no_value", "long_name", "newline_name", "trailing_slash", "plot_ext",
                          "dev_zero", "socket", "root_dir", "unreadable_earlier"])
        D = "{D}"
        if kind == "missing_dir":
            path = f"{D}/nodir/x{ext}"
        elif kind == "directory":
            case["files"]["adir"] = "dir"
            path = f"{D}/adir"
        elif kind == "devnull":
            path = "/dev/null"
        elif kind == "dev_zero":
            path = "/dev/zero"
        elif kind == "root_dir":
            path = "/"
        elif kind == "fifo":
            case["files"]["fifo"] = "fifo"
            path = f"{D}/fifo"
        elif kind == "socket":
            case["files"]["sock"] = "socket"
            path = f"{D}/sock"
        elif kind == "symlink":
            case["files"]["target" + ext] = f"earlier:{opt}"
            case["files"]["link" + ext] = "symlink:target" + ext
            path = f"{D}/link{ext}"
        elif kind == "dangling":
            case["files"]["dangling" + ext] = "symlink:nowhere" + ext
            path = f"{D}/dangling{ext}"
        elif kind == "options_file":
            case["files"]["in.opts"] = "text:-cont_monitor false\n" if "-adh_lambda" not in case["args"] \
                else "text:-snes_max_it 50\n"
            case.add("-options_file", "in.opts")
            path = f"{D}/in.opts"
        elif kind == "guess":
            if "-adh_lambda" in case["args"] and "-adh_guess" not in case["args"]:
                case["files"]["g.h5"] = "guess:good"
                case.add("-adh_guess", f"{D}/g.h5")
                path = "g.h5"
            else:
                path = f"{D}/nodir/x{ext}"
        elif kind in ("other_output", "dotdot_other", "hardlink_other"):
            others = [o for o in case["outputs"] if o != opt]
            if not others:
                other = "summary" if opt != "summary" else "out"
                case["files"][f"o{case['id']}"] = f"earlier:{other}"
                case.add(f"-{other}", f"{D}/o{case['id']}")
                case["outputs"][other] = f"o{case['id']}"
                others = [other]
            rel = case["outputs"][self.pick(others)]
            if kind == "other_output":
                path = f"{D}/{rel}"
            elif kind == "dotdot_other":
                case["files"]["sub"] = "dir"
                path = f"{D}/sub/../{rel}"
            else:
                if rel not in case["files"]:
                    case["files"][rel] = f"earlier:{opt}"
                case["files"][f"hl{ext}"] = f"hardlink:{rel}"
                path = f"{D}/hl{ext}"
        elif kind == "nonutf8":
            path = f"{D}/r\udcff{ext}"
        elif kind == "empty_name":
            path = ""
        elif kind == "no_value":                    # a bare -out first: the later value, if any, wins
            case["args"] = [f"-{opt}", *case["args"]]
            case["special"] = kind
            return case
        elif kind == "long_name":
            path = f"{D}/" + "n" * int(self.rng.integers(230, 260)) + ext
        elif kind == "newline_name":
            path = f"{D}/new\nline\x1b[1m{ext}"
        elif kind == "trailing_slash":
            path = f"{D}/t{ext}/"
        elif kind == "plot_ext":
            opt = "plot" if curve else "out"
            path = f"{D}/p" + self.pick([".jpg", ".PNG", ".Svg", "", ".png.h5", ".eps", ".h5"])
        else:                                       # an earlier file we may not replace (root can, though)
            case["files"][f"ro{ext}"] = f"earlier:{opt}:ro"
            path = f"{D}/ro{ext}"
        # replace the output's earlier value (last wins in PETSc, but keep one occurrence)
        args = case["args"]
        if f"-{opt}" in args:
            i = args.index(f"-{opt}")
            del args[i:i + 2]
        case.add(f"-{opt}", path)
        case["special"] = kind
        case["outputs"].pop(opt, None)
        if path.startswith("{D}/"):                 # a name some of these may take: an optional output
            case["outputs"][opt] = "?" + os.path.normpath(path[4:])
        return case

    # -- input files -----------------------------------------------------------------------------------
    def input_files(self, case: Case, kind: str | None = None) -> Case:
        kind = kind or self.pick([
            "opts_missing", "opts_empty", "opts_binary", "opts_nonutf8", "opts_self", "opts_cycle", "opts_valid",
            "opts_bad_line", "opts_directory", "opts_fifo", "opts_nested_missing", "opts_alias", "opts_outputs",
            "opts_no_value", "opts_crlf", "opts_nul", "opts_devnull", "opts_last", "opts_empty_name",
            "guess_missing", "guess_empty", "guess_binary", "guess_text_h5", "guess_curve", "guess_no_grid",
            "guess_nan", "guess_nan_far", "guess_below_wall", "guess_good", "guess_ragged", "guess_directory",
            "guess_devnull", "guess_options_file", "guess_nonutf8", "guess_unsorted", "guess_empty_arrays",
            "guess_ints", "guess_inf_r"])
        # not here: a FIFO as -adh_guess hangs (test_guess_fifo_is_refused), 10 s a case
        case["special"] = kind
        if kind.startswith("guess"):
            self.valid_solve(case)
            case["args"] = [a for a in case["args"]]
            if "-adh_guess" in case["args"]:
                i = case["args"].index("-adh_guess")
                del case["args"][i:i + 2]
            what = kind[len("guess_"):]
            spec = {"missing": None, "directory": "dir", "devnull": None, "options_file": "text:-adh_mu 1\n",
                    "nonutf8": None, "fifo": "fifo"}.get(what, f"guess:{what}")
            name = {"devnull": "/dev/null", "nonutf8": "g\udcff.h5"}.get(what, "g.h5")
            if spec:
                case["files"][name] = spec
            if what == "options_file":
                case.add("-options_file", name)
            case.add("-adh_guess", name)
            return case
        self.valid(case)
        if kind == "opts_last":
            case.add("-options_file")
            return case
        if kind == "opts_empty_name":
            case.add("-options_file", "")
            return case
        spec = {"missing": None, "empty": "text:", "binary": "bytes:" + os.urandom(0).hex(),
                "nonutf8": "bytes:" + "-adh_mu \xff\xfe1\n".encode("latin-1").hex(),
                "self": "text:-options_file in.opts\n", "cycle": "text:-options_file in2.opts\n",
                "valid": "text:# a comment\n-adh_mu 0.5 ! another\n\n",
                "bad_line": "text:" + self.pick(["adh_mu 1\n", "-adh_mu 1 2\n", "-adh_mu = 1\n", "alias -a\n",
                                                 "- 1\n", "-adh_mu 1 # ok\n-cont_F_max 0 0\n"]),
                "directory": "dir", "fifo": "fifo", "nested_missing": "text:-options_file nowhere.opts\n",
                "alias": "text:alias -mu -adh_mu\n-mu 0.5\n",
                "outputs": "text:-summary from_opts.json\n", "no_value": "text:-adh_mu\n",
                "crlf": "text:-adh_mu 0.5\r\n-adh_sigma 0\r\n", "nul": "bytes:" + b"-adh_mu 0.5\x00 1\n".hex(),
                "devnull": None}[kind[len("opts_"):]]
        if kind == "opts_binary":
            spec = "bytes:" + bytes(self.rng.integers(0, 256, 64, dtype=np.uint8)).hex()
        name = "/dev/null" if kind == "opts_devnull" else "in.opts"
        if spec:
            case["files"][name] = spec
        if kind == "opts_cycle":
            case["files"]["in2.opts"] = "text:-options_file in.opts\n"
        if kind == "opts_outputs":                  # the file's -summary: none on the command line
            if "-summary" in case["args"]:
                i = case["args"].index("-summary")
                del case["args"][i:i + 2]
            case["files"]["from_opts.json"] = "earlier:summary"
            case["outputs"]["summary"] = "from_opts.json"
        if kind in ("opts_valid", "opts_alias", "opts_crlf"):
            case["args"] = [a for a in case["args"]]
            if "-adh_mu" in case["args"]:                   # the command line would override the file
                i = case["args"].index("-adh_mu")
                del case["args"][i:i + 2]
            while any(a.startswith("-phys_") for a in case["args"] if isinstance(a, str)):
                i = next(k for k, a in enumerate(case["args"]) if isinstance(a, str) and a.startswith("-phys_"))
                del case["args"][i:i + 2]
        pos = int(self.rng.integers(0, len(case["args"]) // 2 + 1)) * 2
        case["args"][pos:pos] = ["-options_file", name]
        return case

    # -- the environment and odd singletons ------------------------------------------------------------
    def environment(self, case: Case) -> Case:
        self.valid(case)
        kind = self.pick(["petsc_options_ok", "petsc_options_word", "petsc_options_bad", "petscrc_ok",
                          "petscrc_bad", "petscrc_binary", "help", "version", "skip_petscrc"])
        case["special"] = kind
        if kind == "petsc_options_ok":
            case["env"]["PETSC_OPTIONS"] = "-cont_event_tol 1e-6" if "-adh_lambda" not in case["args"] \
                else "-snes_rtol 1e-9"
        elif kind == "petsc_options_word":
            case["env"]["PETSC_OPTIONS"] = self.pick(["adh_mu 2", "-adh_mu 1 2", "x"])
        elif kind == "petsc_options_bad":
            case["env"]["PETSC_OPTIONS"] = self.pick(["-adh_mu nan", "-adh_muu 1", "-grid_n 2"])
        elif kind == "petscrc_ok":
            case["files"][".petscrc"] = "text:-adh_sigma 0\n"
        elif kind == "petscrc_bad":
            case["files"][".petscrc"] = "text:adh_mu 1\n"
        elif kind == "petscrc_binary":
            case["files"]["petscrc"] = "bytes:00ff10"
        elif kind == "skip_petscrc":
            case["files"][".petscrc"] = "text:adh_mu 1\n"
            case.add("-skip_petscrc")
        else:
            case.add(f"-{kind}")
        return case

    #: the first cases for 2 ranks: guesses bad in rank 1's rows only (a check that fails on one rank)
    FORCED_MPI = ("guess_below_wall", "guess_nan_far")

    def case(self, cid: int, mpi: bool = False) -> Case:
        cats = [("valid", 0.42), ("mutated", 0.18), ("petsc", 0.10), ("names", 0.08), ("output_paths", 0.10),
                ("input_files", 0.09), ("environment", 0.03)]
        if mpi:         # under mpiexec: the checks that could differ between ranks
            cats = [("valid", 0.3), ("mutated", 0.15), ("petsc", 0.1), ("output_paths", 0.2), ("input_files", 0.25)]
            if self.forced < len(self.FORCED_MPI):
                self.forced += 1
                return self.input_files(Case(cid, "input_files"), self.FORCED_MPI[self.forced - 1])
        r, acc = self.rng.random(), 0.0
        for cat, w in cats:
            acc += w
            if r < acc:
                break
        case = Case(cid, cat)
        {"valid": self.valid, "mutated": self.mutated, "petsc": self.petsc_opts, "names": self.names,
         "output_paths": self.output_paths, "input_files": self.input_files,
         "environment": self.environment}[cat](case)
        return case


def generate(seed: int, n: int, start: int = 0, mpi: int = 0) -> list[Case]:
    """``n`` cases numbered from ``start``, the last ``mpi`` of them meant for 2 ranks."""
    gen = Generator(seed)
    return [gen.case(i, mpi=i >= start + n - mpi) for i in range(start, start + n)]


# -- the files of a case ----------------------------------------------------------------------------------
def _h5(path, **datasets) -> None:
    with h5py.File(path, "w") as f:
        for name, value in datasets.items():
            f[name.replace("__", "/")] = value


def make_guess(path: str, kind: str, assets: dict) -> None:
    """A guess file of ``kind`` (``good``: a real -out of a solve; the others each wrong in one way)."""
    r = np.linspace(0.0, 10.0, 41)
    H = 0.5 * r * r + 3.0
    if kind == "good":
        shutil.copyfile(assets["guess"], path)
    elif kind == "curve":
        shutil.copyfile(assets["out"], path)
    elif kind == "empty":
        open(path, "wb").close()
    elif kind == "binary":
        with open(path, "wb") as f:
            f.write(bytes(range(256)) * 8)
    elif kind == "text_h5":
        with open(path, "w") as f:
            f.write("grid/r = 0 1 2\nsolution/H = 1 2 3\n")
    elif kind == "no_grid":
        _h5(path, solution__H=H)
    elif kind == "nan":
        H[5] = np.nan
        _h5(path, grid__r=r, solution__H=H)
    elif kind == "nan_far":                         # in the rows of rank 1 of 2 only
        H[-3] = np.nan
        _h5(path, grid__r=r, solution__H=H)
    elif kind == "below_wall":
        H[-10:] = -5.0
        _h5(path, grid__r=r, solution__H=H)
    elif kind == "ragged":
        _h5(path, grid__r=r, solution__H=H[:-3])
    elif kind == "unsorted":
        _h5(path, grid__r=r[::-1].copy(), solution__H=H)
    elif kind == "empty_arrays":
        _h5(path, grid__r=np.zeros(0), solution__H=np.zeros(0))
    elif kind == "ints":
        _h5(path, grid__r=np.arange(41), solution__H=np.full(41, 3))
    elif kind == "inf_r":
        r[-1] = np.inf
        _h5(path, grid__r=r, solution__H=H)
    else:
        raise ValueError(kind)


def prepare(case: Case, folder: str, assets: dict) -> None:
    """The case's folder with its files (``case['files']``: relative path -> spec)."""
    import socket

    os.makedirs(folder)
    order = {"dir": 0, "symlink": 2, "hardlink": 2}
    for rel, spec in sorted(case["files"].items(), key=lambda kv: (order.get(kv[1].split(":")[0], 1), kv[0])):
        path = rel if os.path.isabs(rel) else os.path.join(folder, rel)
        kind, _, arg = spec.partition(":")
        if kind == "dir":
            os.makedirs(path, exist_ok=True)
        elif kind == "fifo":
            os.mkfifo(path)
        elif kind == "socket":                     # bound by a relative name: AF_UNIX paths are short
            s, here = socket.socket(socket.AF_UNIX), os.getcwd()
            try:
                os.chdir(os.path.dirname(path))
                s.bind(os.path.basename(path))
            finally:
                os.chdir(here)
                s.close()
        elif kind == "symlink":
            os.symlink(arg, path)
        elif kind == "hardlink":
            os.link(os.path.join(folder, arg), path)
        elif kind == "earlier":
            opt, _, mode = arg.partition(":")
            shutil.copyfile(assets[opt], path)
            if mode == "ro":
                os.chmod(path, 0o444)
        elif kind == "text":
            with open(path, "w", newline="") as f:
                f.write(arg)
        elif kind == "bytes":
            with open(path, "wb") as f:
                f.write(bytes.fromhex(arg))
        elif kind == "guess":
            make_guess(path, arg, assets)
        else:
            raise ValueError(spec)


def listing(folder: str) -> dict:
    """Every entry under ``folder`` (hidden ones included): relative path -> (kind, bytes of a regular file)."""
    out = {}
    for top, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = os.path.join(top, name)
            st = os.lstat(path)
            rel = os.path.relpath(path, folder)
            if stat.S_ISREG(st.st_mode):
                with open(path, "rb") as f:
                    out[rel] = ("file", f.read())
            elif stat.S_ISLNK(st.st_mode):
                out[rel] = ("link", os.readlink(path))
            else:
                out[rel] = (stat.S_IFMT(st.st_mode), None)
    return out


def command_line(case: Case, folder: str, np_: int = 1) -> str:
    args = [a.replace("{D}", folder) for a in case["args"]]
    env = "".join(f"{k}={shlex.quote(v)} " for k, v in case["env"].items())
    mpi = f"mpiexec -n {np_} " if np_ > 1 else ""
    return f"cd {shlex.quote(folder)} && {env}{mpi}.venv/bin/python -m petsc_adhesion " + \
        " ".join(shlex.quote(a) for a in args)


def describe(case: Case, folder: str, np_: int = 1) -> str:
    files = ", ".join(f"{k}={v[:60]}" for k, v in sorted(case["files"].items())) or "none"
    return (f"seed {SEED}, case {case['id']} ({case['cat']}{'/' + case['special'] if case['special'] else ''}); "
            f"files: {files}\n    reproduce: FUZZ_SEED={SEED} FUZZ_CASES={case['id']} pytest -q tests/test_fuzz.py\n"
            f"    command: {command_line(case, folder, np_)}")


# -- judging a result -------------------------------------------------------------------------------------
def _no_constant(name):
    raise ValueError(f"JSON holds {name}")


def _nonfinite(value) -> bool:
    a = np.asarray(value)
    if a.dtype.kind in "fc":
        return not np.all(np.isfinite(a))
    return False


COMMON_KEYS = ("program", "version", "petsc_version", "petsc4py_version", "mpi_ranks", "mu", "sigma", "rmax",
               "n_nodes")
SOLVE_KEYS = ("lambda", "F", "H0", "snes_iterations", "ksp_iterations", "wall_time_s")
CURVE_KEYS = ("pull_off", "folds", "equilibria", "load_extrema", "at_lambda", "steps", "rejected_steps",
              "stop_reason", "grid_warning", "warnings", "complete", "lambda_start", "wall_time_s")


def check_json(path: str) -> tuple[list, dict]:
    bad = []
    try:
        with open(path, "rb") as f:
            s = json.loads(f.read().decode("utf-8"), parse_constant=_no_constant)
    except (ValueError, UnicodeDecodeError) as e:
        return [f"{path}: not valid JSON ({e})"], {}
    if not isinstance(s, dict):
        return [f"{path}: not a JSON object"], {}
    kind = "curve" if "steps" in s else "solve"
    missing = [k for k in COMMON_KEYS + (CURVE_KEYS if kind == "curve" else SOLVE_KEYS) if k not in s]
    if missing:
        bad.append(f"{path}: JSON summary lacks {missing}")
    if s.get("program") != "petsc-adhesion":
        bad.append(f"{path}: program is {s.get('program')!r}")
    info = {"kind": kind, "mu": s.get("mu"), "n": s.get("n_nodes"), "complete": s.get("complete"),
            "warnings": s.get("warnings"), "F": s.get("F"),
            "pull_off": (s.get("pull_off") or {}).get("F") if kind == "curve" else None}
    return bad, info


def check_h5(path: str) -> tuple[list, dict]:
    bad = []
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        return [f"{path}: HDF5 does not open ({e})"], {}
    with f:
        a = f.attrs
        for k in ("program", "version", "petsc_version", "petsc4py_version", "mpi_ranks", "kind"):
            if k not in a:
                bad.append(f"{path}: root attribute {k} missing")
        kind = a.get("kind")
        need = ["options", "model", "grid/r"] + (["solution/H", "solution/P"] if kind == "solve" else
                                                 [f"curve/{k}" for k in ("lambda", "F", "H0", "lambdadot", "stable",
                                                                         "ds", "newton_its", "ksp_its",
                                                                         "corrector")] + ["summary"])
        for k in need:
            if k not in f:
                bad.append(f"{path}: {k} missing (kind {kind!r})")
        seen = [("/", f)]
        f.visititems(lambda name, obj: seen.append((name, obj)))
        for name, obj in seen:
            if "units" not in obj.attrs or "description" not in obj.attrs:
                bad.append(f"{path}: {name} has no units or description")
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fc" and _nonfinite(obj[()]):
                bad.append(f"{path}: dataset {name} holds NaN or inf")
            for k, v in obj.attrs.items():
                if _nonfinite(v):
                    bad.append(f"{path}: attribute {name}:{k} = {v} is not finite")
        n = f["grid/r"].shape[0] if "grid/r" in f else None
        if kind == "solve" and "solution/H" in f and f["solution/H"].shape != (n,):
            bad.append(f"{path}: solution/H has {f['solution/H'].shape} values on {n} nodes")
        s = f["summary"].attrs if "summary" in f else {}
        po = f["summary/pull_off"].attrs.get("F") if "summary/pull_off" in f else None
        info = {"kind": kind, "mu": f["model"].attrs.get("mu") if "model" in f else None, "n": n,
                "complete": bool(s["complete"]) if "complete" in s else None,
                "warnings": list(s["warnings"]) if "warnings" in s else None,
                "F": f["solution"].attrs.get("F") if "solution" in f else None, "pull_off": po}
    return bad, info


def check_csv(path: str, opt: str) -> list:
    """A CSV export: its header's first column (lambda for -csv, leg for -csv behind a spring: its legs; kind
    for -csv_events), every row as long as the header, every number finite."""
    import csv
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        return [f"{path}: not a CSV file ({e})"]
    first = ("kind",) if opt == "csv_events" else ("lambda", "leg")
    if not rows or not rows[0] or not rows[0][0].startswith(first):
        return [f"{path}: -{opt} has no header starting with {first} ({rows[:1]!r})"]
    bad = [f"{path}: row {i} has {len(r)} cells, the header {len(rows[0])}" for i, r in enumerate(rows[1:], 1)
           if len(r) != len(rows[0])]
    for i, r in enumerate(rows[1:], 1):
        for cell in r:
            try:
                v = float(cell)
            except ValueError:
                continue
            if not math.isfinite(v):
                bad.append(f"{path}: row {i} holds {cell}")
    return bad


def check_plot(path: str) -> list:
    ext = os.path.splitext(path)[1].lower()
    with open(path, "rb") as f:
        head = f.read(8)
    magic = PLOT_MAGIC.get(ext)
    return [] if magic and head.startswith(magic) else [f"{path}: not a {ext or '?'} figure ({head!r})"]


def _without_mpiexec(text: str) -> str:
    """stderr without Open MPI's own notices (blocks between lines of dashes): mpiexec's, not the program's."""
    keep, inside = [], False
    for ln in text.splitlines():
        if re.fullmatch(r"-{20,}", ln.strip()):
            inside = not inside
        elif not inside:
            keep.append(ln)
    return "\n".join(keep)


def judge(case: Case, res: dict, before: dict, after: dict, out: bytes, err: bytes, folder: str) -> list[str]:
    """Everything wrong with one run (empty: fine)."""
    bad = []
    if res.get("hang"):
        return [f"hang: no answer within {res['hang']:.0f} s"]
    if res.get("crash") is not None:
        return [f"the interpreter died (status {res['crash']}); stderr: {err[-300:]!r}"]
    if res.get("escaped"):
        return [f"an exception escaped main: {res['escaped'].strip().splitlines()[-1]}"]
    status = res["status"]
    text_out, text_err = out.decode("utf-8", "replace"), err.decode("utf-8", "replace")
    for what, text in (("stdout", text_out), ("stderr", text_err)):
        for word in ("Traceback", "PETSC ERROR"):
            if word in text:
                bad.append(f"{word!r} on {what}")
    try:
        err.decode("utf-8")
    except UnicodeDecodeError:
        bad.append("stderr is not UTF-8")
    lines = [ln for ln in _without_mpiexec(text_err).splitlines() if ln.strip()]
    # an accepted input outside what the field measures is said before any work, one line each
    # (app/options/plausible.py): beside a later error's line, not in its place
    lines = [ln for ln in lines if not ln.startswith(f"{PREFIX[:-len('error: ')]}warning: -")]
    if not all(c.isprintable() for ln in lines for c in ln):
        bad.append(f"unprintable characters on stderr: {text_err[:300]!r}")
    if res.get("hang") is None and res.get("status") is not None and res["status"] < 0:
        bad.append(f"killed by signal {-res['status']}")
    if status not in (0, 1, 2, 3):
        bad.append(f"exit status {status}")
        return bad
    temps = [p for p in after if re.search(r"(^|/)\.[^/]*\.(partial-[^/]*|commit)$", p)]
    if temps:
        bad.append(f"temporaries left: {temps}")
    if status in (1, 2):
        if len(lines) != 1 or not lines[0].startswith(PREFIX):
            bad.append(f"exit {status} without exactly one '{PREFIX}...' line: {text_err[-600:]!r}")
        if after != before:
            changed = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
            bad.append(f"exit {status}, yet the folder changed: {changed}")
        return bad
    # status 0 or 3: a result; every requested output new and valid, nothing else touched
    changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
    wanted = {rel.lstrip("?"): (opt, not rel.startswith("?")) for opt, rel in case["outputs"].items()}
    for rel in sorted(changed - set(wanted)):
        bad.append(f"exit {status} changed {rel!r}, which is no output of the run")
    infos = {}
    if "-version" in case["args"] or "-help" in case["args"]:
        wanted = {rel: (opt, False) for rel, (opt, _) in wanted.items()}   # nothing is run
    for rel, (opt, required) in wanted.items():
        if rel not in changed:
            if required:
                bad.append(f"exit {status}, yet -{opt} {rel} is " + ("missing" if rel not in after else
                                                                      "the earlier file"))
            continue
        if after.get(rel, (None,))[0] != "file":
            bad.append(f"-{opt} {rel} is not a regular file after the run")
            continue
        path = os.path.join(folder, rel)
        if opt == "out":
            problems, infos[opt] = check_h5(path)
        elif opt == "summary":
            problems, infos[opt] = check_json(path)
        elif opt in ("csv", "csv_events"):
            problems = check_csv(path, opt)
        else:
            problems = check_plot(path)
        bad += problems
    if "-version" in case["args"] or "-help" in case["args"]:
        return bad
    for opt, info in infos.items():
        if info.get("kind") == "curve":
            if info.get("complete") is not (status == 0):
                bad.append(f"exit {status} with complete = {info.get('complete')} in -{opt}")
            if status == 3 and not info.get("warnings"):
                bad.append(f"exit 3 without a warning in -{opt}")
        elif status == 3:
            bad.append(f"exit 3 from a fixed-approach solve (-{opt} kind {info.get('kind')})")
    if "out" in infos and "summary" in infos:
        a, b = infos["out"], infos["summary"]
        for k in ("kind", "n", "mu", "complete", "F", "pull_off"):
            if a.get(k) != b.get(k) and not (k == "complete" and a.get("kind") == "solve"):
                bad.append(f"-out and -summary disagree on {k}: {a.get(k)} vs {b.get(k)} (a mixed set?)")
    if status == 3 and "WARNING" not in text_out:
        bad.append("exit 3 without a WARNING line on stdout")
    monitors = any(re.search(r"monitor|view|converged_reason", a) for a in case["args"])
    if not monitors and re.search(r"\bnan\b", text_out, re.I):
        bad.append(f"NaN on stdout: {text_out[-400:]!r}")
    return bad


# -- running cases ----------------------------------------------------------------------------------------
class Worker:
    """A ``python tests/test_fuzz.py --worker`` process, restarted after a hang or a crash."""

    def __init__(self, logdir: str):
        self.logdir, self.proc, self.starts = logdir, None, 0

    def _start(self) -> None:
        self.starts += 1
        log = open(os.path.join(self.logdir, f"worker{self.starts}.log"), "wb")
        self.proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker"], cwd=ROOT,
                                     env=conftest._env(), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=log, text=True, bufsize=1)
        log.close()

    def run(self, case: Case, folder: str, capture: str) -> dict:
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        args = [a.replace("{D}", folder) for a in case["args"]]
        msg = {"id": case["id"], "cwd": folder, "args": args, "env": case["env"],
               "stdout": capture + ".out", "stderr": capture + ".err"}
        t0 = time.perf_counter()
        try:
            self.proc.stdin.write(json.dumps(msg) + "\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            pass
        ready, _, _ = select.select([self.proc.stdout], [], [], HANG)
        if not ready:
            self.stop()
            return {"hang": time.perf_counter() - t0}
        line = self.proc.stdout.readline()
        if not line:
            code = self.proc.wait()
            self.proc = None
            return {"crash": code}
        return json.loads(line)

    def stop(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None

    def close(self):
        """End the worker; its exit status (None if none was running)."""
        code = None
        if self.proc is not None:
            self.proc.stdin.close()
            try:
                code = self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.stop()
                code = "hang at exit"
            self.proc = None
        return code


@pytest.fixture(scope="module")
def assets(tmp_path_factory):
    """The earlier result set (a curve: -out, -summary, -plot, -csv, -csv_events) and a guess (-out of a solve)."""
    d = tmp_path_factory.mktemp("assets")
    runs = {"earlier": [*EARLIER_ARGS, "-out", d / "e.h5", "-summary", d / "e.json", "-plot", d / "e.png",
                        "-csv", d / "e.csv", "-csv_events", d / "ee.csv"],
            "guess": [*GUESS_ARGS, "-out", d / "g.h5"]}
    procs = {k: subprocess.Popen([sys.executable, "-m", "petsc_adhesion", *map(str, a)], cwd=ROOT,
                                 env=conftest._env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
             for k, a in runs.items()}
    for k, p in procs.items():
        _, e = p.communicate(timeout=120)
        assert p.returncode in (0, 3), (k, e)
    return {"out": str(d / "e.h5"), "summary": str(d / "e.json"), "plot": str(d / "e.png"), "guess": str(d / "g.h5"),
            "csv": str(d / "e.csv"), "csv_events": str(d / "ee.csv")}


def classes(case: Case) -> set:
    """The classes of input a draw belongs to: its category with its special kind (a kind of file, of
    environment, of output path: None for the categories without), and each application option it names."""
    return {("category", case["cat"], case["special"])} | \
        {("option", a[1:]) for a in case["args"] if a.startswith("-") and a[1:] in TABLE}


def suite_draws(cases: list, first: int = N_SUITE) -> list:
    """The first ``first`` of ``cases``, then each later one that brings a class (:func:`classes`) none before it
    has: every class of the whole draw, fewer draws of each (at the default seed 189 of 1000, with all of its
    66 categories and special kinds and 102 application options; measured by test_fuzz_suite_keeps_every_class)."""
    out, seen = list(cases[:first]), set().union(set(), *(classes(c) for c in cases[:first]))
    for c in cases[first:]:
        new = classes(c) - seen
        if new:
            out.append(c)
            seen |= new
    return out


def _selected(cases: list) -> list:
    only = os.environ.get("FUZZ_CASES")
    if not only:
        return cases if os.environ.get("FUZZ_ALL") else suite_draws(cases)
    ids = {int(x) for x in only.split(",")}
    return [c for c in cases if c["id"] in ids]


def _run_in_process(cases, root, assets, worker):
    failures, stats = [], {}
    for case in cases:
        folder = os.path.join(root, f"c{case['id']:05d}")
        prepare(case, folder, assets)
        before = listing(folder)
        capture = os.path.join(root, f"c{case['id']:05d}")
        res = worker.run(case, folder, capture)
        after = listing(folder)
        read = lambda p: open(p, "rb").read() if os.path.exists(p) else b""     # noqa: E731
        out, err = read(capture + ".out"), read(capture + ".err")
        problems = judge(case, res, before, after, out, err, folder)
        if os.environ.get("FUZZ_TRACE"):
            print(f"case {case['id']} {case['cat']} {case['special']} status {res.get('status')} "
                  f"{res.get('elapsed', -1):.3f} s {len(problems)} problems", flush=True)
        key = (case["cat"], "hang" if res.get("hang") else res.get("status"))
        stats[key] = stats.get(key, 0) + 1
        stats[("time", case["cat"])] = stats.get(("time", case["cat"]), 0.0) + res.get("elapsed", HANG)
        if problems:
            failures.append(f"{describe(case, folder)}\n    status {res.get('status')}: "
                            + "\n    ".join(problems) + f"\n    stderr: {err[-300:]!r}")
        else:
            shutil.rmtree(folder, ignore_errors=True)
            for ext in (".out", ".err"):
                if os.path.exists(capture + ext):
                    os.remove(capture + ext)
    return failures, stats


def _summary(stats: dict) -> str:
    cats = sorted({k[0] for k in stats if k[0] != "time"})
    rows = []
    for c in cats:
        by = {k[1]: v for k, v in stats.items() if k[0] == c}
        rows.append(f"  {c:<13} " + "  ".join(f"{s}: {n}" for s, n in sorted(by.items(), key=str)) +
                    f"  ({stats.get(('time', c), 0):.1f} s)")
    return "\n".join(rows)


def test_fuzz_in_process(tmp_path, assets):
    """N_IN_PROCESS random option sets (in the suite those of :func:`suite_draws`) through cli.main in a worker
    process, each judged by :func:`judge`."""
    cases = _selected(generate(SEED, N_IN_PROCESS))
    worker = Worker(str(tmp_path))
    t0 = time.perf_counter()
    try:
        failures, stats = _run_in_process(cases, str(tmp_path), assets, worker)
    finally:
        code = worker.close()
    if code not in (0, None):
        failures.append(f"the worker ended with status {code} after its last case (see {tmp_path}/worker*.log)")
    print(f"\nfuzz, seed {SEED}: {len(cases)} cases in {time.perf_counter() - t0:.1f} s\n" + _summary(stats))
    report = f"{len(failures)} of {len(cases)} cases failed:\n" + "\n".join(failures[:30])
    assert not failures, report.encode("utf-8", "backslashreplace").decode("utf-8")   # surrogate escapes: see below


def test_fuzz_suite_keeps_every_class():
    """The suite's draws (suite_draws) hold every class of input of all N_IN_PROCESS draws, in fewer than half
    the cases, and the first N_SUITE draws alone lack some (so that the draws after them are needed)."""
    full = generate(SEED, N_IN_PROCESS)
    chosen = suite_draws(full)
    every = set().union(*(classes(c) for c in full))
    assert set().union(*(classes(c) for c in chosen)) == every
    assert len(chosen) < N_IN_PROCESS / 2 and [c["id"] for c in chosen[:N_SUITE]] == list(range(N_SUITE))
    assert set().union(*(classes(c) for c in full[:N_SUITE])) < every
    cats = {k[1] for k in every if k[0] == "category"}
    assert cats == {"valid", "mutated", "petsc", "names", "output_paths", "input_files", "environment"}


# -- the command line: real processes, some under mpiexec -n 2 ------------------------------------------
def _run_sub(case: Case, folder: str, np_: int, limit: float = HANG + 10) -> tuple[dict, bytes, bytes]:
    """One case as a real command line in ``folder``: (status and elapsed, or hang), stdout, stderr.  ``limit``:
    HANG plus the start of Python, PETSc and MPI."""
    cmd = [sys.executable, "-m", "petsc_adhesion", *[a.replace("{D}", folder) for a in case["args"]]]
    if np_ > 1:
        mpiexec = shutil.which("mpiexec")
        if mpiexec is None:
            pytest.skip("mpiexec not found")
        cmd = [*conftest.mpiexec(np_), *cmd]
    env = dict(conftest._env(), **case["env"])
    if np_ > 1:                 # two ranks on two shared cores: spin less while waiting
        env["OMPI_MCA_mpi_yield_when_idle"] = "1"
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        out, err = proc.communicate(timeout=limit)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, 9)
        out, err = proc.communicate()
        return {"hang": time.perf_counter() - t0}, out, err
    status = proc.returncode
    return {"status": status, "elapsed": time.perf_counter() - t0}, out, err


def test_fuzz_command_line(tmp_path, assets):
    """N_SUBPROCESS random option sets as real command lines (the last N_MPI on 2 ranks), two at a time."""
    from concurrent.futures import ThreadPoolExecutor

    cases = generate(SEED + 1, N_SUBPROCESS, start=100000, mpi=N_MPI)
    nps = {c["id"]: 2 if i >= len(cases) - N_MPI else 1 for i, c in enumerate(cases)}
    cases = _selected(cases)
    for c in cases:
        prepare(c, str(tmp_path / f"c{c['id']}"), assets)
    befores = {c["id"]: listing(str(tmp_path / f"c{c['id']}")) for c in cases}
    t0 = time.perf_counter()
    runs = {}
    for np_, workers in ((1, 2), (2, 2)):      # two at a time
        these = [c for c in cases if nps[c["id"]] == np_]
        with ThreadPoolExecutor(max_workers=workers) as pool:
            runs |= dict(zip([c["id"] for c in these],
                             pool.map(lambda c: _run_sub(c, str(tmp_path / f"c{c['id']}"), np_), these)))
    # A case past its limit while another case (and, under pytest-xdist, another test) shares the two cores is run
    # again alone, from a fresh folder, with RETRY_LIMIT: a start slowed by the machine's load is not a hang (a
    # fresh clone's suite beside a second job had 4 of 30 cases past 20 s, and none in the clone's suite alone),
    # while a real hang (a deadlock, a loop without end) passes any limit again.
    for c in cases:
        if runs[c["id"]][0].get("hang"):
            folder = str(tmp_path / f"c{c['id']}")
            for top, dirs, _ in os.walk(folder):          # read-only folders the case made must be removable
                for d in dirs:
                    os.chmod(os.path.join(top, d), 0o755)
            shutil.rmtree(folder)
            prepare(c, folder, assets)
            befores[c["id"]] = listing(folder)
            runs[c["id"]] = _run_sub(c, folder, nps[c["id"]], RETRY_LIMIT)
    failures, stats = [], {}
    for c in cases:
        folder = str(tmp_path / f"c{c['id']}")
        res, out, err = runs[c["id"]]
        problems = judge(c, res, befores[c["id"]], listing(folder), out, err, folder)
        if os.environ.get("FUZZ_TRACE"):
            print(f"case {c['id']} np={nps[c['id']]} {c['cat']} {c['special']} status {res.get('status')} "
                  f"{res.get('elapsed', -1):.3f} s {len(problems)} problems", flush=True)
        key = (f"{c['cat']}{' np=2' if nps[c['id']] > 1 else ''}", "hang" if res.get("hang") else res.get("status"))
        stats[key] = stats.get(key, 0) + 1
        if problems:
            failures.append(f"{describe(c, folder, nps[c['id']])}\n    status {res.get('status')}: "
                            + "\n    ".join(problems) + f"\n    stderr: {err[-400:]!r}")
    print(f"\ncommand-line fuzz, seed {SEED + 1}: {len(cases)} cases in {time.perf_counter() - t0:.1f} s\n"
          + _summary(stats))
    # the cases' arguments hold undecodable bytes (surrogate escapes): a report that pytest-xdist's workers can send
    report = (f"{len(failures)} of {len(cases)} cases failed:\n" + "\n".join(failures))
    assert not failures, report.encode("utf-8", "backslashreplace").decode("utf-8")


# ======================================================================================================
# Defects the fuzz found, fixed, each with its smallest reproducer
# ======================================================================================================
SOLVE = ("-adh_mu", "1", "-adh_lambda", "-2", "-grid_type", "uniform", "-grid_n", "41")
CURVE = ("-adh_mu", "0.5", "-grid_type", "uniform", "-grid_n", "41", "-cont_F_max", "0")


def one_line(proc, status=2) -> str:
    assert "Traceback" not in proc.stdout + proc.stderr and "PETSC ERROR" not in proc.stderr, proc.stderr[-800:]
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith(PREFIX), proc.stderr[-800:]
    assert proc.returncode == status, (proc.returncode, proc.stderr)
    return lines[0][len(PREFIX):]


def test_integer_option_inf_is_one_line(tmp_path):
    line = one_line(run_cli(*CURVE, "-cont_max_steps", "inf", "-out", tmp_path / "x.h5", cwd=tmp_path))
    assert line.startswith("-cont_max_steps"), line
    assert os.listdir(tmp_path) == []


def test_options_file_value_not_utf8_is_one_line(tmp_path):
    (tmp_path / "in.opts").write_bytes(b"-adh_mu \xff\xfe1\n")
    line = one_line(run_cli(*SOLVE[2:], "-options_file", "in.opts", "-out", tmp_path / "x.h5", cwd=tmp_path))
    assert "-adh_mu" in line and "\\xff" in line, line
    assert sorted(os.listdir(tmp_path)) == ["in.opts"]


def test_options_file_without_name_is_one_line(tmp_path):
    line = one_line(run_cli(*SOLVE, "-out", tmp_path / "x.h5", "-options_file", "", cwd=tmp_path))
    assert line.startswith("-options_file"), line
    assert os.listdir(tmp_path) == []


def test_python_solver_type_is_one_line(tmp_path):
    line = one_line(run_cli(*SOLVE, "-snes_type", "python", "-out", tmp_path / "x.h5", cwd=tmp_path), status=2)
    assert line.startswith("-snes_type python"), line
    assert os.listdir(tmp_path) == []


def test_guess_fifo_is_refused(tmp_path):
    os.mkfifo(tmp_path / "g.h5")
    try:
        proc = run_cli(*SOLVE, "-adh_guess", "g.h5", "-out", tmp_path / "x.h5", cwd=tmp_path, timeout=5)
    except subprocess.TimeoutExpired:
        pytest.fail("hang: -adh_guess g.h5 (a FIFO) had no answer within 5 s (a refusal takes about 1 s)")
    assert one_line(proc).startswith("-adh_guess"), proc.stderr
    assert sorted(os.listdir(tmp_path)) == ["g.h5"]


def test_petsc_error_does_not_blame_an_unrelated_option(tmp_path):
    proc = run_cli(*SOLVE, "-snes_type", "fas", cwd=tmp_path)
    assert proc.returncode in (1, 2) and proc.stderr.startswith(PREFIX), proc.stderr
    assert not proc.stderr[len(PREFIX):].startswith("-adh_mu"), proc.stderr


def test_no_nan_in_a_fixed_grid_curve(tmp_path):
    proc = run_cli(*CURVE, "-out", tmp_path / "c.h5", cwd=tmp_path)
    assert proc.returncode in (0, 3), proc.stderr
    problems, _ = check_h5(str(tmp_path / "c.h5"))
    assert not problems, problems
