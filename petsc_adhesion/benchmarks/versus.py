"""This checkout against another commit, as whole processes: the CPU time of the same runs, interleaved.

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.versus [--against COMMIT] [--pairs K]
        [--runs demo,spring,study] [--write]

Each run is a whole ``python -m petsc_adhesion`` process (import, tracing, error bars, files, figure), once from
this checkout and once from a worktree of COMMIT (default: the commit before the typed results, 4581078), K times
each, alternating, so that both see the same load.  What is compared is the CPU time the process used (user +
system, of the child), not the wall time: on shared cores the wall time measures the other work as much as ours.
A ratio above 1 is this checkout's loss.  With ``--write`` the table becomes the section "## Against an earlier
commit" of docs/performance.md.

The runs take what each commit's options files hold, so both compute the same model on the same grids; what one
commit computes and the other does not (a bar estimated from one more level, the instrument's legs) is part of
the cost measured, and said next to the table.
"""
from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile

from .paths import DOCS, ROOT, write_section

__all__ = ["RUNS", "cpu_of", "compare", "table", "main"]

#: name -> the options of one run (files written into the run's own folder).
RUNS = {
    "demo": ["-options_file", "{tree}/options/demo.opts"],
    "spring": ["-adh_mu", "1", "-afm_spring", "0.5", "-summary", "s.json", "-out", "s.h5"],
    "rough": ["-adh_mu", "1", "-adh_sigma", "0.1", "-adh_model_spread", "false", "-summary", "r.json"],
}
#: Options a run takes only on the newer commits (dropped for a tree whose program refuses them).
NEWER = {"-adh_model_spread"}


def cpu_of(tree: str, argv: list[str], workdir: str) -> float:
    """CPU seconds (user + system) of one ``python -m petsc_adhesion`` process run from ``tree``."""
    env = dict(os.environ, PYTHONPATH=tree, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    os.makedirs(os.path.join(workdir, "results"), exist_ok=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, "-m", "petsc_adhesion", *[a.format(tree=tree) for a in argv]],
                       cwd=workdir, env=env, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(f"{tree}: {' '.join(argv)} exited {p.returncode}: {p.stderr.strip()[-300:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _accepts(tree: str, option: str) -> bool:
    """Whether ``tree``'s option table knows ``option`` (an older commit's does not know the newer ones)."""
    for root, _, files in os.walk(os.path.join(tree, "petsc_adhesion", "app")):
        for f in files:
            if f.endswith(".py") and option.lstrip("-") in open(os.path.join(root, f)).read():
                return True
    return False


def compare(old: str, new: str, names: list[str], pairs: int) -> dict:
    """name -> (old CPU times, new CPU times), ``pairs`` alternating runs each."""
    out = {}
    with tempfile.TemporaryDirectory(prefix="petsc-adhesion-versus-") as tmp:
        for name in names:
            argv = RUNS[name]
            o_argv = argv
            for opt in NEWER:
                if opt in argv and not _accepts(old, opt):
                    i = argv.index(opt)
                    o_argv = argv[:i] + argv[i + 2:]
            olds, news = [], []
            for k in range(pairs):
                olds.append(cpu_of(old, o_argv, os.path.join(tmp, f"old-{name}")))
                news.append(cpu_of(new, argv, os.path.join(tmp, f"new-{name}")))
                print(f"  {name} pair {k + 1}/{pairs}: {olds[-1]:.3f} s against {news[-1]:.3f} s", flush=True)
            out[name] = (olds, news)
    return out


def table(results: dict, against: str) -> str:
    """The markdown table of :func:`compare`'s results."""
    lines = [f"| run | CPU at {against} (median, s) | CPU here (median, s) | ratio of medians | pair ratios (min, median, max) |",
             "|---|---|---|---|---|"]
    for name, (olds, news) in results.items():
        ratios = sorted(n / o for n, o in zip(news, olds))
        lines.append(f"| {name} | {statistics.median(olds):.3f} | {statistics.median(news):.3f} | "
                     f"{statistics.median(news) / statistics.median(olds):.3f} | "
                     f"{ratios[0]:.3f}, {statistics.median(ratios):.3f}, {ratios[-1]:.3f} ({len(ratios)} pairs) |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m petsc_adhesion.benchmarks.versus", description=__doc__.split("\n")[0])
    ap.add_argument("--against", default="4581078", help="the commit to compare with (default 4581078)")
    ap.add_argument("--pairs", type=int, default=7, help="alternating runs of each (default 7)")
    ap.add_argument("--runs", default="demo,spring,rough", help=f"comma-separated, of {', '.join(RUNS)}")
    ap.add_argument("--write", action="store_true", help="write the table into docs/performance.md")
    a = ap.parse_args(argv)
    names = a.runs.split(",")
    bad = [n for n in names if n not in RUNS]
    if bad or a.pairs < 1:
        print(f"versus: --runs takes {', '.join(RUNS)} and --pairs a positive count", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="petsc-adhesion-old-") as tmp:
        old = os.path.join(tmp, "old")
        p = subprocess.run(["git", "worktree", "add", "--detach", old, a.against], cwd=ROOT, capture_output=True, text=True)
        if p.returncode != 0:
            print(f"versus: --against {a.against}: {p.stderr.strip()}", file=sys.stderr)
            return 2
        try:
            load = os.getloadavg()[0]
            results = compare(old, ROOT, names, a.pairs)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", old], cwd=ROOT, capture_output=True)
    text = table(results, a.against)
    print(text)
    print(f"load average before the runs: {load:.1f}")
    if a.write:
        write_section(os.path.join(DOCS, "performance.md"),
                      "## Against an earlier commit\n\n<!-- made by: python -m petsc_adhesion.benchmarks.versus "
                      f"--against {a.against} --pairs {a.pairs} --runs {a.runs} --write -->\n"
                      "CPU time (user + system) of whole processes, this checkout and the earlier commit alternating "
                      f"(load average {load:.1f} before the runs on 2 cores).\n\n" + text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
