"""This checkout against another commit, as whole processes: the CPU time of the same runs, interleaved.

    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.versus [--against COMMIT] [--pairs K]
        [--runs demo,spring,study] [--write]
    OPENBLAS_NUM_THREADS=1 python -m petsc_adhesion.benchmarks.versus --count [--against COMMIT] [--write]

Each run is a whole ``python -m petsc_adhesion`` process (import, tracing, error bars, files, figure), once from
this checkout and once from a worktree of COMMIT (default: the commit before the typed results, 4581078), K times
each, alternating, so that both see the same load.  What is compared is the CPU time the process used (user +
system, of the child), not the wall time: on shared cores the wall time measures the other work as much as ours.
A ratio above 1 is this checkout's loss.  With ``--write`` the table becomes the section "## Against an earlier
commit" of docs/performance.md.

The runs take what each commit's options files hold, so both compute the same model on the same grids; what one
commit computes and the other does not (a bar estimated from one more level, the instrument's legs) is part of
the cost measured, and said next to the table.

CPU times of two-second processes on shared cores scatter by 20 to 40% from run to run, more than the difference
to be resolved.  ``--count`` measures what does not scatter: the instructions each process executes, counted by
valgrind (``cachegrind --cache-sim=no``, one run each: the count repeats to 0.1%), and the solver's work, PETSc's
event counts from ``-log_view`` (SNES solves, residual evaluations, KSP solves, flops).  Their ratio tells a
slower program from one that solves more: the instructions per residual evaluation compare the two commits'
cost of the same unit of work, whatever each chose to compute.
"""
from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile

from .paths import DOCS, ROOT, write_section

__all__ = ["RUNS", "EVENTS", "cpu_of", "compare", "table", "counts_of", "count", "count_table", "count_summary",
           "main"]

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


#: PETSc's events whose counts -log_view prints, compared between the commits.
EVENTS = ("SNESSolve", "SNESFunctionEval", "KSPSolve")


def _argv_for(tree: str, argv: list[str]) -> list[str]:
    """``argv`` as ``tree``'s program takes it: the newer options dropped where it does not know them."""
    out = list(argv)
    for opt in NEWER:
        if opt in out and not _accepts(tree, opt):
            i = out.index(opt)
            out = out[:i] + out[i + 2:]
    return out


def counts_of(tree: str, argv: list[str], workdir: str) -> dict:
    """What one run of ``tree`` executes, independent of the load: ``instructions`` (valgrind's I refs of the
    whole process) and PETSc's event counts (:data:`EVENTS`) and ``flops`` from a second run with -log_view."""
    env = dict(os.environ, PYTHONPATH=tree, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    os.makedirs(os.path.join(workdir, "results"), exist_ok=True)
    args = [a.format(tree=tree) for a in argv]
    out = {}
    # -log_view's run first: it also compiles what the tree's changed modules need, a cost of the first run
    # after a checkout that is not the program's
    p = subprocess.run([sys.executable, "-m", "petsc_adhesion", *args, "-log_view"], cwd=workdir, env=env,
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{tree}: {' '.join(argv)} -log_view exited {p.returncode}: {p.stderr.strip()[-300:]}")
    for ev in EVENTS:
        m = re.search(rf"^{ev}\s+(\d+)", p.stdout, re.M)
        out[ev] = int(m.group(1)) if m else 0
    m = re.search(r"^Flops:\s+([\d.e+]+)", p.stdout, re.M)
    out["flops"] = float(m.group(1)) if m else float("nan")
    p = subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null",
                        sys.executable, "-m", "petsc_adhesion", *args], cwd=workdir, env=env, capture_output=True,
                       text=True)
    m = re.findall(r"I\s+refs:\s+([\d,]+)", p.stderr)
    if p.returncode != 0 or not m:
        raise RuntimeError(f"{tree}: valgrind {' '.join(argv)} exited {p.returncode}: {p.stderr.strip()[-300:]}")
    out["instructions"] = int(m[-1].replace(",", ""))
    return out


def count(old: str, new: str, names: list[str]) -> dict:
    """name -> (the old commit's :func:`counts_of`, this checkout's)."""
    out = {}
    with tempfile.TemporaryDirectory(prefix="petsc-adhesion-versus-") as tmp:
        for name in names:
            o = counts_of(old, _argv_for(old, RUNS[name]), os.path.join(tmp, f"old-{name}"))
            n = counts_of(new, RUNS[name], os.path.join(tmp, f"new-{name}"))
            print(f"  {name}: {o['instructions']:.4g} instructions against {n['instructions']:.4g}", flush=True)
            out[name] = (o, n)
    return out


def count_table(results: dict, against: str) -> str:
    """The markdown table of :func:`count`'s results: instructions, the solver's work, and the instructions per
    residual evaluation (the cost of the same unit of work) as ratios here / there."""
    lines = [f"| run | instructions at {against} | here | ratio | SNES solves there, here | residual evaluations "
             "there, here | flops ratio | instructions per residual evaluation, ratio |",
             "|---|---|---|---|---|---|---|---|"]
    for name, (o, n) in results.items():
        per = (n["instructions"] / max(n["SNESFunctionEval"], 1)) / (o["instructions"] / max(o["SNESFunctionEval"], 1))
        lines.append(f"| {name} | {o['instructions']:.4g} | {n['instructions']:.4g} | "
                     f"{n['instructions'] / o['instructions']:.3f} | {o['SNESSolve']}, {n['SNESSolve']} | "
                     f"{o['SNESFunctionEval']}, {n['SNESFunctionEval']} | {n['flops'] / o['flops']:.3f} | {per:.3f} |")
    return "\n".join(lines)


def count_summary(results: dict, against: str) -> str:
    """The paragraph under :func:`count_table`: the ranges of the ratios, and what they say."""
    def span(f):
        v = [f(o, n) for o, n in results.values()]
        return f"{100 * (min(v) - 1):.1f} to {100 * (max(v) - 1):.1f}%"
    per = [(n["instructions"] / max(n["SNESFunctionEval"], 1)) / (o["instructions"] / max(o["SNESFunctionEval"], 1))
           for o, n in results.values()]
    verdict = ("so the typed results have not made the program slower; what it costs more is what it computes more"
               if max(per) <= 1.0 else
               f"up to {100 * (max(per) - 1):.1f}% more: this checkout is slower for the same work")
    return (f"Here a run executes {span(lambda o, n: n['instructions'] / o['instructions'])} more instructions than at "
            f"{against}, and {span(lambda o, n: n['SNESSolve'] / o['SNESSolve'])} more SNES solves "
            f"({span(lambda o, n: n['SNESFunctionEval'] / o['SNESFunctionEval'])} more residual evaluations): the "
            "runs compute more here (the energy's bar from a second refinement level, the contact radius along the "
            "curve with its bar, behind a spring the instrument's legs).  The same unit of the solver's work costs "
            f"{min(per):.3f} to {max(per):.3f} times the instructions it cost there (the last column), {verdict}.  "
            "Counted by valgrind (cachegrind, no cache simulation) on one run each; two counts of the same run "
            "differ by about 1%.")


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
            o_argv = _argv_for(old, argv)
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
    ap.add_argument("--count", action="store_true",
                    help="count instructions (valgrind) and the solver's work (-log_view) instead of timing")
    ap.add_argument("--write", action="store_true", help="write the table into docs/performance.md")
    a = ap.parse_args(argv)
    names = a.runs.split(",")
    bad = [n for n in names if n not in RUNS]
    if a.count and shutil.which("valgrind") is None:
        print("versus: --count needs valgrind on the PATH", file=sys.stderr)
        return 2
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
            results = count(old, ROOT, names) if a.count else compare(old, ROOT, names, a.pairs)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", old], cwd=ROOT, capture_output=True)
    if a.count:
        text = count_table(results, a.against)
        print(text)
        if a.write:
            write_section(os.path.join(DOCS, "performance.md"),
                          "## Against an earlier commit, counted\n\n<!-- made by: python -m "
                          f"petsc_adhesion.benchmarks.versus --count --against {a.against} --runs {a.runs} --write -->\n"
                          "What each whole process executes, independent of the load (one run each): instructions "
                          "counted by valgrind, the solver's work by PETSc's -log_view.  The last column is the cost "
                          "of one residual evaluation's worth of work here against there.\n\n" + text + "\n\n"
                          + count_summary(results, a.against) + "\n")
        return 0
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
