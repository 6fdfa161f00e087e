"""Checkpoint and restart of a study, and the typed values through the checkpoint's one serializer.

A study of eight cases killed once a case is saved (SIGTERM on one rank, SIGKILL to a two-rank mpiexec job) and
restarted runs only the cases not saved, and writes the uninterrupted study's numbers; a study's checkpoint and
a curve's are refused where they do not belong.  A study's cases, a curve with a spring and a topography saved
as the checkpoint saves them come back equal.  (Apart from tests/test_checkpoint.py, the killed curves, so that
pytest-xdist's --dist loadfile can give the two halves to two workers.)
"""
from __future__ import annotations

import json
import os
import re
import shutil
import signal
import time

import numpy as np
import pytest

from conftest import run_cli
from test_checkpoint import CASE, PREFIX, _events, _numbers, _ranks, _start, _wait
from test_checkpoint import saved  # noqa: F401  (the fixture: a checkpoint of a curve killed while it traces)


# -- a study: its finished cases kept, the rest run on restart ---------------------------------------------
STUDY = ("-grid_type", "uniform", "-grid_n", "101", "-study_mu", "0.001,0.3,0.6,1", "-study_sigma", "0,0.3",
         "-study_compute", "events", "-cont_checkpoint_interval", "0", "-out", "s.h5", "-summary", "s.json")


def _cases(folder) -> list[dict]:
    """A study's cases from its JSON summary, without their run times."""
    def bare(d):
        return {k: bare(v) for k, v in d.items() if k not in ("wall_time_s", "rule_times_s")} \
            if isinstance(d, dict) else d
    return [bare(c) for c in json.loads((folder / "s.json").read_text())["cases"]]


def _table(folder) -> dict:
    import h5py

    with h5py.File(folder / "s.h5") as f:
        return {k: f["table"][k][()] for k in f["table"] if "time" not in k}


def _saved_cases(path) -> int:
    try:
        with open(path, "rb") as f:
            f.readline()
            return json.loads(f.readline())["cases"]
    except (OSError, ValueError, KeyError):
        return 0


@pytest.fixture(scope="module")
def whole_study(tmp_path_factory):
    folder = tmp_path_factory.mktemp("study")
    proc = run_cli(*STUDY, cwd=folder)
    assert proc.returncode == 0, proc.stderr
    assert sorted(os.listdir(folder)) == ["s.h5", "s.json"], "a finished study leaves its results only"
    return folder


@pytest.mark.parametrize("np_, sig", [(1, "TERM"), (2, "KILL")])
def test_killed_study_runs_only_the_rest(tmp_path, whole_study, np_, sig):
    """Killed once a case is saved (SIGTERM to the run; SIGKILL to the whole mpiexec job, ranks and all), the
    study restarted on one rank runs only the cases not saved, and its files hold the uninterrupted
    study's numbers: bit for bit on one rank, to 1e-10 from two (the study equals its serial run there)."""
    if np_ > 1 and shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not found")
    proc = _start(np_, tmp_path, *STUDY, *(("-study_ranks", "1") if np_ > 1 else ()))
    ck = tmp_path / ".s.h5.checkpoint"
    while _saved_cases(ck) < 1 and proc.poll() is None:
        time.sleep(0.002)
    ranks = _ranks(proc.pid) if np_ > 1 else {}
    if sig == "KILL":
        os.killpg(proc.pid, signal.SIGKILL)
    else:
        os.kill(proc.pid, signal.SIGTERM)
    status, stderr = _wait(proc, ranks)
    saved = _saved_cases(ck)
    assert 1 <= saved < 8 and status != 0, (status, saved, stderr)
    assert sorted(os.listdir(tmp_path)) == [".s.h5.checkpoint"], "a killed study writes no result"
    if sig == "TERM":
        assert stderr.splitlines()[-1] == (f"{PREFIX}interrupted by SIGTERM; nothing written; go on with "
                                           f"-cont_restart .s.h5.checkpoint"), stderr
    again = run_cli(*STUDY, "-cont_restart", ".s.h5.checkpoint", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    m = re.search(r"going on from the checkpoint \.s\.h5\.checkpoint: (\d+) cases? done, (\d+) to run", again.stderr)
    assert m and int(m[1]) == saved and int(m[2]) == 8 - saved, again.stderr
    assert len(re.findall(r"\bdone in ", again.stderr)) == 8 - saved, "only the rest are run"
    assert sorted(os.listdir(tmp_path)) == ["s.h5", "s.json"], "the checkpoint goes with the study's end"
    got, want = _cases(tmp_path), _cases(whole_study)
    if np_ == 1:
        assert got == want
        for k, v in _table(whole_study).items():
            assert np.array_equal(_table(tmp_path)[k], v, equal_nan=v.dtype.kind == "f"), k
    else:
        for a, b in zip(got, want):
            assert (a["mu"], a["sigma"]) == (b["mu"], b["sigma"])
            close = {k: v for k, v in _numbers(a["pull_off"]).items() if not abs(v - _numbers(b["pull_off"])[k]) <= 1e-10}
            assert not close, (a["mu"], a["sigma"], close)
            assert [e["kind"] for e in _events(a)] == [e["kind"] for e in _events(b)]


def test_study_restart_refuses_another_study_and_a_curve(tmp_path, saved):
    proc = _start(1, tmp_path, *STUDY)
    while _saved_cases(tmp_path / ".s.h5.checkpoint") < 1 and proc.poll() is None:
        time.sleep(0.002)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate()
    (tmp_path / "curve.ck").write_bytes(saved)
    before = sorted(os.listdir(tmp_path))
    other = list(STUDY)
    other[other.index("-study_sigma") + 1] = "0,0.4"
    for args, line in ((other + ["-cont_restart", ".s.h5.checkpoint"],
                        "was written with -study_sigma (0.0, 0.3); this run has -study_sigma (0.0, 0.4)"),
                       (STUDY + ("-cont_restart", "curve.ck"), "'curve.ck' is a curve's, this run is a study"),
                       (CASE + ("-cont_restart", ".s.h5.checkpoint", "-summary", "c.json"),
                        "is a study's, this run traces one curve")):
        p = run_cli(*args, cwd=tmp_path)
        assert p.returncode == 2 and p.stderr.startswith(PREFIX) and p.stderr.count("\n") == 1, p.stderr
        assert line in p.stderr, p.stderr
    assert sorted(os.listdir(tmp_path)) == before, "nothing written"


def test_a_study_case_round_trips_through_the_serializer(tmp_path):
    """A study's cases (a rough curve with its model spread, a cusp of a critical study, a failure) saved as
    the checkpoint saves them and read back: the study's files written from them equal those written from
    the values before the save (HDF5, JSON and CSV, every number)."""
    import dataclasses

    from golden import digest
    from petsc_adhesion.app.checkpoint import _study_cases, read_file, write_file
    from petsc_adhesion.io.resultset import written
    from petsc_adhesion.io.values import encode
    from petsc_adhesion.io.write import write_critical, write_study
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.critical import Critical
    from petsc_adhesion.tracing.case import CaseResult
    from petsc_adhesion.tracing.measured import Measured, Missing
    from petsc_adhesion.tracing.model_spread import Rule, model_spread
    from petsc_adhesion.tracing.trace import CurveRequest, GridChoice, trace_curve

    model, grid = Model(mu=1.0, sigma=0.2), GridChoice("uniform", n=101)
    curve = trace_curve(model, grid, request=CurveRequest(profiles=True))
    curve = dataclasses.replace(curve, spread=model_spread(curve, model, grid, rules=(Rule("weibull", 0.0),)))
    curve = curve.keeping_profiles(("snap_on",))
    cusp = Critical("sigma", 1.0, Measured(0.62, 1e-4, None), Measured(-1.1, 2e-4), Measured(-0.4, 3e-5), 1e-6,
                    (0, 1, 2), (101, 201, 401), (0.61, 0.615, 0.618), (-1.0, -1.05, -1.08), (-0.41, -0.405, -0.402),
                    (0.5, 0.7), 1.2, 1.3, model, 2.5, None)
    cases = [CaseResult(0, (("adh_mu", 1.0), ("adh_sigma", 0.2)), curve, 3.25),
             CaseResult(1, (("adh_mu", 2.0), ("adh_sigma", 0.2)), Missing("the first step failed"), 0.5)]
    write_file(str(tmp_path / "s.ck"), {}, {"phase": "study", "cases": [encode(c) for c in cases + [
        CaseResult(2, (("adh_mu", 1.0),), cusp, 4.0)]]})
    back = _study_cases(read_file(str(tmp_path / "s.ck"))[1])
    assert back is not None and [type(c.result) for c in back] == [type(curve), Missing, Critical]
    assert back[2].result == cusp and back[1] == cases[1] and back[0].values == cases[0].values
    # the profiles the study keeps (snap_on's) came through, the others were not kept
    assert {e.kind: e.profile is not None for e in back[0].result.events} == \
        {e.kind: e.kind == "snap_on" for e in back[0].result.events}
    study = {"compute": "curve", "axes": ["adh_mu", "adh_sigma"], "ranks_per_case": 1, "cases": 2, "profiles": [],
             "plot": "curves"}
    digests = []
    for name, values in (("before", cases + [CaseResult(2, (("adh_mu", 1.0),), cusp, 4.0)]), ("after", back)):
        targets = {k: str(tmp_path / f"{name}.{e}") for k, e in (("out", "h5"), ("summary", "json"), ("csv", "csv"))}
        with written(targets) as files:
            write_study({"program": "petsc-adhesion"}, study, values[:1], values[1:2], files)
        critical = {k: str(tmp_path / f"{name}.critical.{e}") for k, e in (("out", "h5"), ("summary", "json"))}
        with written(critical) as files:
            write_critical({"program": "petsc-adhesion"}, {"compute": "critical"}, values[2:], [], files)
        digests.append([digest(p) for p in [*targets.values(), *critical.values()]])
    # every number bit for bit (through JSON, where NaN reads as NaN: a NaN cell is equal to itself)
    for a, b in zip(*digests):
        assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)
    h5, summary, csv = digests[0][:3]
    assert "model_spread" in summary["cases"][0] and summary["failed"][0]["error"] == "the first step failed"
    assert "cases/0000/model_spread" in h5 and "F_spread [2 pi R gamma]" in csv[0]
    assert digests[0][4]["critical_roughness"][0]["sigma_c"] == 0.62


def test_a_spring_curve_and_a_topography_round_trip_through_the_serializer(tmp_path):
    """A curve behind a spring (its instrument's legs) and a model read from a topography file go through the
    checkpoint's serializer and come back equal: the legs' arrays bit for bit, the curve's summary equal, the
    topography's heights and statistics equal (a study journals its cases, and their models, this way)."""
    import dataclasses

    import numpy as np
    import pytest

    from petsc_adhesion.io.summary import summary_of
    from petsc_adhesion.io.values import decode, encode
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing.trace import CurveRequest, GridChoice, trace_curve

    curve = trace_curve(Model(mu=2.0, sigma=0.0), GridChoice("uniform", n=101), request=CurveRequest(spring=0.5))
    back = decode(encode(curve))
    assert summary_of(back) == summary_of(curve)
    legs, legs_back = curve.instrument, back.instrument
    assert type(legs_back) is type(legs) and len(legs.approach.Z) > 10
    for a, b in zip(legs.legs, legs_back.legs):
        assert a.name == b.name and a.jumps == b.jumps
        for f in ("Z", "F", "lam", "contact_radius"):
            assert np.array_equal(getattr(a, f), getattr(b, f), equal_nan=True), f

    pytest.importorskip("SurfaceTopography")
    from petsc_adhesion.model.topography import read_topography

    topo = read_topography(os.path.join(os.path.dirname(__file__), "data", "wsxm-afm-topography.top"))
    model = dataclasses.replace(Model(mu=1.0, sigma=0.3), topography=(topo,))
    t = decode(encode(model)).topography[0]
    assert np.array_equal(t.heights, topo.heights) and t.stats == topo.stats and t.pixel_size == topo.pixel_size
