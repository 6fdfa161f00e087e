"""What a study saves by leaving out what its scene does not need, measured on the Fig. 18 study.

    ./run bench -bench_only leaveout          # about 15 minutes on 2 cores; writes docs/figures/leaveout.md

The study options/fig18.opts (64 cases: 16 mu from 0.01 to 20, sigma = 0, 0.2, 0.4, 1)
is run on two ranks as the figure runs it (``-study_compute pull_off``: each case stops
at the equilibrium after the pull-off, bars only for the load minima and the
equilibrium, no profiles), then with the whole curve (``curve``: to F = 2, bars for
every event), then with every event's profiles as well (``-profiles``): wall time of
the process and size of the HDF5 file.  Beside them, the two savings that are not
options: importing matplotlib (only when something is drawn) and the roughness
quadrature at sigma = 0 (the smooth law instead of the 16-point rule, per evaluation
of the pressure and its derivative on 300 nodes).
"""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from . import paths

__all__ = ["run", "ROOT", "OUT", "VARIANTS"]

ROOT = paths.ROOT
OUT = os.path.join(paths.FIGURES, "leaveout.md")
#: name -> extra options over options/fig18.opts
VARIANTS = {"pull-off only (the figure's)": (),
            "the whole curve, every event with its bar": ("-study_compute", "curve"),
            "the whole curve, and every event's profiles": ("-study_compute", "curve", "-profiles")}


def _study(extra: tuple, folder: str, ranks: int = 2) -> tuple[float, int]:
    out = os.path.join(folder, "s.h5")
    cmd = ["mpiexec", "-n", str(ranks), sys.executable, "-m", "petsc_adhesion", "-options_file",
           "options/fig18.opts", *extra, "-out", out, "-summary", os.path.join(folder, "s.json"),
           "-plot", os.path.join(folder, "s.png")]
    from .workprecision import ENV

    # the bench's own MPI (a singleton) leaves variables that a child mpiexec must not inherit
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PMIX_", "OMPI_"))} | ENV
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if not os.path.exists(out):                # exit 3 (a case incomplete) still writes the study
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}, no result: {p.stderr.strip()[-300:]}")
    return wall, os.path.getsize(out)


def _matplotlib(repeats: int = 5) -> float:
    code = "import matplotlib; matplotlib.use('Agg'); import matplotlib.pyplot"
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        t1 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        times.append((t1 - t0) - (time.perf_counter() - t1))
    return statistics.median(times)


def _quadrature(repeats: int = 200) -> tuple[float, float]:
    """Seconds per evaluation of P(H) and P'(H) on 300 gaps above the wall: the smooth law and the 16-point rule."""
    from ..model.parameters import Model
    from ..model.pressure import pressure_law

    out = []
    for sigma in (0.0, 0.2):
        law = pressure_law(Model(sigma=sigma))
        H = law.wall + np.linspace(0.05, 40.0, 300)
        t0 = time.perf_counter()
        for _ in range(repeats):
            law(H)
        out.append((time.perf_counter() - t0) / repeats)
    return out[0], out[1]


def run() -> dict:
    """Measure, write docs/figures/leaveout.md, and return the numbers."""
    rows = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, extra in VARIANTS.items():
            rows[name] = _study(extra, folder)
            print(f"[leaveout] {name}: {rows[name][0]:.1f} s, {rows[name][1] / 2**20:.2f} MiB", flush=True)
    mpl = _matplotlib()
    smooth, rule = _quadrature()
    base_t, base_s = rows[next(iter(VARIANTS))]
    lines = ["<!-- made by: ./run bench -bench_only leaveout (petsc_adhesion/benchmarks/leaveout.py) -->",
             "The Fig. 18 study (options/fig18.opts: 64 cases), `mpiexec -n 2`, one run each "
             f"(load average before: {os.getloadavg()[0]:.2f}):", "",
             "| each case computes | wall time | HDF5 file | time saved by the figure's choice | size saved |",
             "|---|---|---|---|---|"]
    for name, (t, size) in rows.items():
        lines.append(f"| {name} | {t:.0f} s | {size / 2**20:.2f} MiB | "
                     f"{'-' if t == base_t else f'{t - base_t:.0f} s ({1 - base_t / t:.0%})'} | "
                     f"{'-' if size == base_s else f'{(size - base_s) / 2**20:.2f} MiB ({1 - base_s / size:.0%})'} |")
    lines += ["", f"Not drawing: importing matplotlib costs {mpl * 1e3:.0f} ms a process (median of 5), saved "
              "when no `-plot` is given.",
              f"No quadrature at sigma = 0: one evaluation of the pressure and its derivative on 300 nodes takes "
              f"{smooth * 1e6:.0f} us with the smooth law and {rule * 1e6:.0f} us with the 16-point rule "
              f"({rule / smooth:.1f} times as long); the 16 smooth cases of the study use the smooth law."]
    with open(OUT, "w") as f:
        f.write("\n".join(lines) + "\n")
    return {"leaveout": {name: {"wall_s": t, "h5_bytes": s} for name, (t, s) in rows.items()}
            | {"matplotlib_import_s": mpl, "law_smooth_s": smooth, "law_hermite16_s": rule}}
