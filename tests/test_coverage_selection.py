"""The coverage studies' case selection (benchmarks/selection.py): ``-mu``, ``-sigma`` pick the study's own cases,
``-jobs`` the processes at once; anything else is refused in one line with exit 2 before any case runs, and
the stored data is left as it was.  Nothing is traced here."""
import os
import subprocess
import sys

from conftest import ROOT

from petsc_adhesion.benchmarks import coverage, energy_coverage
from petsc_adhesion.benchmarks.selection import selected


def test_the_cases_named_and_no_others():
    assert selected([], coverage.CASES) == (coverage.CASES, 2)
    assert selected(["-mu", "5", "7", "-sigma", "0", "-jobs", "1"], coverage.CASES) == ([(5.0, 0.0), (7.0, 0.0)], 1)
    got, jobs = selected(["-sigma", "0.2", "-mu", "5"], energy_coverage.CASES)
    assert got == [(5.0, 0.2, None), (5.0, 0.2, 0.05), (5.0, 0.2, 0.5), (5.0, 0.2, 2.0)] and jobs == 2


def test_anything_else_is_refused_in_one_line():
    for argv in (["-mu", "4"], ["-mu"], ["-sigma", "0.3"], ["-jobs", "0"], ["-jobs", "two"], ["-nu", "1"]):
        got, why = selected(argv, coverage.CASES)
        assert got is None and "-mu MU" in why and "\n" not in why, argv
    data = os.path.join(ROOT, "docs", "data", "coverage.json")
    before = os.stat(data).st_mtime_ns
    for module in ("coverage", "energy_coverage"):
        p = subprocess.run([sys.executable, "-m", f"petsc_adhesion.benchmarks.{module}", "-mu", "4"], cwd=ROOT,
                           capture_output=True, text=True, timeout=120)
        assert p.returncode == 2 and p.stdout == "" and len(p.stderr.strip().splitlines()) == 1, p.stderr
        assert p.stderr.startswith(f"{module}: the study takes -mu MU")
    assert os.stat(data).st_mtime_ns == before
