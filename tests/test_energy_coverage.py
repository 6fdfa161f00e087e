"""The section "The energy of a cycle" of docs/coverage.md is what its command makes from its stored data
(``python -m petsc_adhesion.benchmarks.energy_coverage -table``), and that data is self-consistent.
Nothing is traced here."""
import json
import math
import os
import re

import pytest

from conftest import ROOT

from petsc_adhesion.benchmarks import energy_coverage as ec

DATA = os.path.join(ROOT, "docs", "data", "energy_coverage.json")
DOC = os.path.join(ROOT, "docs", "coverage.md")


@pytest.fixture(scope="module")
def data():
    with open(DATA) as f:
        return json.load(f)


def _section(text: str) -> str:
    start = text.index(ec.HEADING + "\n")
    end = text.find("\n## ", start + len(ec.HEADING))
    return text[start:] if end < 0 else text[start:end + 1]


def test_the_section_is_what_the_data_makes(data):
    doc = open(DOC).read()
    assert doc.count(ec.HEADING + "\n") == 1
    made = ec.section(data["rows"], data["made"])
    assert _section(doc).rstrip("\n") == made.rstrip("\n")
    assert "python -m petsc_adhesion.benchmarks.energy_coverage" in _section(doc)


def test_every_case_is_self_consistent(data):
    """error = |value - truth|, bar / error, covered = error <= bar: as stored and as derived again."""
    rows = [r for r in data["rows"] if "failed" not in r]
    assert rows
    for r in rows:
        again = ec.derived(r)
        for key in ("error", "ratio", "covered"):
            assert again[key] == r[key], (r["mu"], r["sigma"], r["K"], key)
        if r["truth"] is not None:
            assert r["error"] == abs(r["value"] - r["truth"])
        if r["covered"] is not None:
            assert r["resolved"] and r["bar"] is not None
            assert r["covered"] == (r["error"] <= r["bar"])
        if r["ratio"] is not None:
            assert math.isclose(r["ratio"], r["bar"] / r["error"])
        # the truth is extrapolated from the stored levels it names
        levels = {int(k): v for k, v in r["levels"].items()}
        assert set(r["truth_levels"]) <= set(levels)


def test_the_table_says_what_each_case_holds(data):
    """Each case's line of the table in docs/coverage.md: its value, bar, |error|, ratio and verdict."""
    doc = _section(open(DOC).read())
    lines = {}
    for line in doc.splitlines():
        cells = [c.strip() for c in line.strip("|").split(" | ")]
        if len(cells) == 14 and re.fullmatch(r"[0-9.]+", cells[0]):
            lines[cells[0], cells[1], cells[2]] = cells
    rows = [r for r in data["rows"] if "failed" not in r and not r.get("stale")]
    assert len(lines) == len(rows)
    # a case not measured again since the bar changed is named apart, not tabled
    for r in data["rows"]:
        if r.get("stale"):
            assert ec._where(r) in doc.split("Not measured again", 1)[1].split("\n", 1)[0]
    for r in rows:
        cells = lines[f"{r['mu']:g}", f"{r['sigma']:g}", "rigid" if r["K"] is None else f"K = {r['K']:g}"]
        assert float(cells[4]) == pytest.approx(r["value"], abs=1e-8)
        assert cells[5] == ec._g(r["bar"]) and cells[9] == ec._g(r["error"]) and cells[10] == ec._g(r["ratio"])
        verdict = {True: "yes", False: "**no**", None: cells[11]}[r["covered"]]
        assert cells[11] == verdict
        if r["covered"] is None:
            assert cells[11] in ("truth not resolved", "no bar")
