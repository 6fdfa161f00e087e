"""The files of four runs as values, to hold the typed-results refactor to the numbers it started from.

``digest(path)`` turns a result file (JSON, HDF5 or CSV) into plain data: every
number, string and array, with timings, versions and paths left out.  ``CASES``
are the runs (the README's demo, a study, a run behind a spring, a fit of a
synthetic curve); ``python tests/golden.py`` writes their digests to
tests/data/golden/ from the code as it is (run it only when a change of the
numbers is meant, and say so in the commit).
"""
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(HERE, "data", "golden")
#: Keys whose values are the machine's or the moment's, not the model's.
SKIP = ("wall_time", "time_s", "times_s", "version", "seconds", "mpi_ranks", "date", "host", "path", "file", "command",
        "argv", "elapsed", "_s_", "rate")

BODIES = ["-phys_radius", "20e-9", "-phys_young1", "150e9", "-phys_poisson1", "0.27", "-phys_epsilon", "0.3e-9"]

#: name -> (arguments, the output files by option)
CASES = {
    "demo": (["-adh_mu", "1", "-adh_sigma", "0", "-cont_at_lambda", "0", "-profiles"], ("-out", "-summary", "-csv", "-csv_events")),
    "study": (["-study_mu", "1,3", "-study_sigma", "0,0.3", "-study_compute", "pull_off"],
              ("-out", "-summary", "-csv")),
    "spring": (["-adh_mu", "2", "-afm_spring", "0.5"], ("-out", "-summary", "-csv", "-csv_events")),
    "fit": (["-fit_curve", "@curve.csv", *BODIES[:2], *BODIES[-2:], "-phys_spring", "1"],
            ("-out", "-summary", "-csv")),
}
EXT = {"-out": "h5", "-summary": "json", "-csv": "csv", "-csv_events": "events.csv"}


#: Options that name the run's own files.
FILES = ("out", "summary", "csv", "csv_events", "plot", "fit_curve", "options_file")


def _skipped(key: str) -> bool:
    return key in FILES or any(s in key for s in SKIP)


def _plain(x, key=""):
    if isinstance(x, dict):
        return {k: _plain(v, k) for k, v in sorted(x.items()) if not _skipped(k)}
    if isinstance(x, (list, tuple)):
        return [_plain(v, key) for v in x]
    if isinstance(x, bytes):
        return x.decode()
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "SO":
            return [v.decode() if isinstance(v, bytes) else str(v) for v in x.ravel()]
        return _plain(x.tolist(), key)
    if isinstance(x, np.generic):
        return _plain(x.item(), key)
    return x


def digest(path: str):
    """The values a result file holds (see the module)."""
    if path.endswith(".json"):
        with open(path) as f:
            return _plain(json.load(f))
    if path.endswith(".h5"):
        import h5py
        out = {}
        with h5py.File(path, "r") as f:
            def visit(name, obj):
                attrs = {k: obj.attrs[k] for k in obj.attrs if k not in ("description", "units")}
                out[name] = {"attrs": attrs, **({"data": obj[()]} if isinstance(obj, h5py.Dataset) else {})}
            visit("/", f)
            f.visititems(visit)
        return _plain(out)
    with open(path) as f:
        rows = [line.rstrip("\n").split(",") for line in f]
    return [[_number(c) for c in row] for row in rows]


def _number(c: str):
    try:
        return float(c)
    except ValueError:
        return c


def same(a, b, rtol=1e-9, atol=1e-13, where="") -> list:
    """Where two digests differ (an empty list when they hold the same values)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}/{k}: only in {'the new' if k in a else 'the golden'}" for k in set(a) ^ set(b)]
        for k in sorted(set(a) & set(b)):
            out += same(a[k], b[k], rtol, atol, f"{where}/{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} entries, golden {len(b)}"]
        out = []
        for i, (x, y) in enumerate(zip(a, b)):
            out += same(x, y, rtol, atol, f"{where}[{i}]")
        return out
    if isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return [] if a == b else [f"{where}: {a!r}, golden {b!r}"]
    if math.isnan(a) and math.isnan(b):
        return []
    return [] if abs(a - b) <= atol + rtol * abs(b) or a == b else [f"{where}: {a!r}, golden {b!r}"]


def synthetic_csv(path: str) -> None:
    """The fit case's data: a curve made by the solver (mu = 1 for a 20 nm tip on a 150 GPa flat) with noise."""
    from petsc_adhesion.fitting.results import Spring
    from petsc_adhesion.fitting.synthetic import Sampling, synthetic_curve
    from petsc_adhesion.model.physical import Bodies

    bodies = Bodies(radius=20e-9, young1=150e9 / 2, poisson1=0.27, epsilon=0.3e-9, gamma=0.05)
    c = synthetic_curve(bodies, Spring(1.0), Sampling(noise=2e-11, points=150, seed=4))
    with open(path, "w") as f:
        f.write("z (nm), F (nN)\n")
        f.writelines(f"{z * 1e9:.10g}, {F * 1e9:.10g}\n" for z, F in zip(c.z, c.F))


def run_case(name: str, out_dir: str, run) -> dict:
    """Run case ``name`` with ``run(*args)`` (the command line, returning a CompletedProcess) writing into
    ``out_dir``; the digests of its files by option."""
    args, outs = CASES[name]
    args = [os.path.join(GOLDEN, a[1:]) if a.startswith("@") else a for a in args]
    files = {o: os.path.join(out_dir, f"{name}.{EXT[o]}") for o in outs}
    p = run(*args, *[w for o in outs for w in (o, files[o])])
    if p.returncode not in (0, 3):
        raise RuntimeError(f"{name}: exit {p.returncode}: {p.stderr}")
    return {o: digest(f) for o, f in files.items()}


def main() -> int:
    import subprocess
    import tempfile

    sys.path.insert(0, HERE)
    from conftest import run_cli

    os.makedirs(GOLDEN, exist_ok=True)
    if not os.path.exists(os.path.join(GOLDEN, "curve.csv")):
        synthetic_csv(os.path.join(GOLDEN, "curve.csv"))
    with tempfile.TemporaryDirectory() as d:
        for name in (sys.argv[1:] or CASES):
            dig = run_case(name, d, run_cli)
            with open(os.path.join(GOLDEN, f"{name}.json"), "w") as f:
                json.dump(dig, f, indent=0, sort_keys=True)
            print(name, "written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
