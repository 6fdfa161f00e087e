"""Checkpoint and restart: runs killed at random moments and restarted end with an uninterrupted run's events.

The curve is mu = 2 on the default grids that follow the contact edge (11 segments, each on its own grid,
two folds with their landings, a pull-off, an equilibrium, a state asked for by -cont_at_lambda 0), saving
before every step (-cont_checkpoint_interval 0) so that a checkpoint is there early.  Each run is killed at a
moment drawn by seed, while it traces (a share of the time from its first checkpoint to its error bars) or
while it computes the error bars (a share of that stage, seen from the checkpoint's header), by SIGTERM,
SIGINT or SIGKILL, on one rank and under ``mpiexec -n 2`` (SIGTERM to the job's process group, mpiexec and its
ranks, as a batch system sends it; SIGKILL to rank 0; Open MPI's mpiexec takes SIGINT for itself and lets the
ranks run on); one run is
killed, restarted, killed again and restarted.  Every restarted run must report the uninterrupted run's
steps and events: lambda, F, their error bars and the landings', to 1e-10 (they agree to the last bit); the
killed runs write no result and say, in one line, the checkpoint to go on from; a finished run leaves nothing
but its results.  Reproduce with ``CHECKPOINT_SEED=... pytest -q tests/test_checkpoint.py -s`` (the log
lists every kill).
"""
from __future__ import annotations

import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import conftest
from conftest import run_cli

SEED = int(os.environ.get("CHECKPOINT_SEED", "20261122"))
CASE = ("-adh_mu", "2", "-cont_at_lambda", "0")
SAVE = ("-cont_checkpoint_interval", "0")
PREFIX = "petsc-adhesion: error: "
#: (signal, target, stage) of the kills; "chain": killed by SIGKILL while it traces, restarted, the restart killed
#: by SIGINT in its error bars, restarted.  Each path once: SIGTERM and SIGINT have one handler (app/cli.py), so
#: the one rank's runs end by its handler in either stage (TERM in the trace, INT in the error bars) and without
#: it in either (KILL in the error bars, the chain's KILL in the trace); a separate SIGKILL in the trace and a
#: SIGINT in the error bars of a first run repeated the chain's two kills (two runs and restarts more, 22% of the
#: test's time)
PLAN = {1: [("TERM", "run", "trace"), ("KILL", "run", "errors"), ("chain", "run", "trace")],
        2: [("TERM", "group", "trace"), ("KILL", "rank0", "errors")]}


def _env(np_: int) -> dict:
    env = conftest._env()
    if np_ > 1:          # two ranks on two shared cores: spin less
        env["OMPI_MCA_mpi_yield_when_idle"] = "1"
    return env


def _command(np_: int, *args) -> list[str]:
    cmd = [sys.executable, "-m", "petsc_adhesion", *map(str, args)]
    return [*conftest.mpiexec(np_), *cmd] if np_ > 1 else cmd


def _start(np_: int, folder, *args) -> subprocess.Popen:
    return subprocess.Popen(_command(np_, *args), cwd=folder, env=_env(np_), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def _phase(path) -> str | None:
    """The stage a checkpoint was saved in (its header), or None while there is none."""
    try:
        with open(path, "rb") as f:
            f.readline()
            return json.loads(f.readline())["phase"]
    except (OSError, ValueError, KeyError):
        return None


def _ranks(pid: int) -> dict:
    """The MPI ranks started by mpiexec ``pid``: rank -> pid (from /proc)."""
    ranks = {}
    for entry in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{entry}/stat") as f:
                if int(f.read().rsplit(")", 1)[1].split()[1]) != pid:
                    continue
            with open(f"/proc/{entry}/environ", "rb") as f:
                env = dict(kv.split(b"=", 1) for kv in f.read().split(b"\0") if b"=" in kv)
        except (OSError, ValueError, IndexError):
            continue
        if b"OMPI_COMM_WORLD_RANK" in env:
            ranks[int(env[b"OMPI_COMM_WORLD_RANK"])] = int(entry)
    return ranks


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _wait(proc: subprocess.Popen, ranks: dict, timeout: float = 60) -> tuple[int, str]:
    """Wait for the run and every rank of it; kill what outlives ``timeout``.  (exit status, stderr)."""
    try:
        _, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, stderr = proc.communicate()
    t0 = time.perf_counter()
    while any(_alive(p) for p in ranks.values()) and time.perf_counter() - t0 < timeout:
        time.sleep(0.02)
    return proc.returncode, stderr


def _events(summary: dict) -> list[dict]:
    return summary["folds"] + summary["equilibria"] + summary["load_extrema"] + summary["at_lambda"]


def _numbers(event: dict, prefix: str = "") -> dict:
    """Every lambda, F and error bar of an event and of its landing."""
    out = {prefix + k: v for k, v in event.items() if k in ("lambda", "F", "lambda_err", "F_err")}
    if "landing" in event:
        out |= _numbers(event["landing"], "landing ")
    return out


def _differences(got: dict, want: dict) -> list[str]:
    """Where a restarted run's summary departs from the uninterrupted run's (beyond 1e-10 for numbers)."""
    bad = [f"{k}: {got[k]} != {want[k]}" for k in ("steps", "rejected_steps", "regrids") if got[k] != want[k]]
    a, b = _events(got), _events(want)
    if [e["kind"] for e in a] != [e["kind"] for e in b]:
        return bad + [f"events {[e['kind'] for e in a]} != {[e['kind'] for e in b]}"]
    for e, f in zip(a, b):
        x, y = _numbers(e), _numbers(f)
        if set(x) != set(y):
            bad.append(f"{e['kind']}: keys {sorted(x)} != {sorted(y)}")
        bad += [f"{e['kind']} {k}: {x[k]!r} vs {y[k]!r}" for k in x if k in y and not abs(x[k] - y[k]) <= 1e-10]
    return bad


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted runs, one rank and two, saving before every step; the moments they reach their
    first checkpoint, their error bars and their end (the kills are shares of those stages)."""
    out = {}
    for np_ in (1, 2):
        if np_ > 1 and shutil.which("mpiexec") is None:
            continue
        folder = tmp_path_factory.mktemp(f"reference{np_}")
        progress = ("-progress", "-progress_interval", "0.05") if np_ == 1 else ()
        t0 = time.perf_counter()
        proc = _start(np_, folder, *CASE, *SAVE, "-cont_checkpoint", "ck", "-summary", "s.json", *progress)
        first = errors = None
        while proc.poll() is None:
            phase = _phase(folder / "ck")
            if first is None and phase:
                first = time.perf_counter() - t0
            if errors is None and phase == "errors":
                errors = time.perf_counter() - t0
            time.sleep(0.002)
        end = time.perf_counter() - t0
        _, stderr = proc.communicate()
        assert proc.returncode == 0, stderr
        assert os.listdir(folder) == ["s.json"], "a finished run leaves its results only"
        assert first is not None and errors is not None
        out[np_] = {"summary": json.loads((folder / "s.json").read_text()), "stderr": stderr,
                    "trace": (first, errors), "errors": (errors, end)}
    return out


def _kill(np_: int, folder, sig: str, target: str, stage: str, share: float, ref: dict, args=()) -> dict:
    """Start a run (or ``args``' restart) and kill it at ``share`` of ``stage``; what happened."""
    proc = _start(np_, folder, *CASE, *SAVE, "-summary", "s.json", *args)
    ck = folder / "ck"
    t0 = time.perf_counter()
    begin, end = ref[stage]
    while _phase(ck) not in ((stage,) if stage == "errors" else ("trace", "errors")) and proc.poll() is None:
        time.sleep(0.002)
    time.sleep(share * (end - begin))
    ranks = _ranks(proc.pid) if np_ > 1 else {}
    while np_ > 1 and len(ranks) < np_ and proc.poll() is None:
        time.sleep(0.01)
        ranks = _ranks(proc.pid)
    at, phase = time.perf_counter() - t0, _phase(ck)
    if proc.poll() is None:
        if target == "group":              # the whole job, mpiexec and its ranks, as a batch system ends it
            os.killpg(proc.pid, getattr(signal, f"SIG{sig}"))
        else:
            os.kill(ranks.get(0, proc.pid) if target == "rank0" else proc.pid, getattr(signal, f"SIG{sig}"))
    status, stderr = _wait(proc, ranks)
    return {"status": status, "stderr": stderr, "at": at, "phase": phase, "saved": _phase(ck),
            "files": sorted(os.listdir(folder))}


def test_killed_runs_restart_to_the_same_events(tmp_path, reference):
    rng = np.random.default_rng(SEED)
    failures, log = [], []
    for np_ in sorted(reference):
        ref = reference[np_]
        for i, (sig, target, stage) in enumerate(PLAN[np_]):
            folder = tmp_path / f"np{np_}_{i}"
            folder.mkdir()
            share = float(rng.uniform(0.05, 0.8))
            repro = f"CHECKPOINT_SEED={SEED} pytest -q tests/test_checkpoint.py  # kill {i} of np={np_}"
            kills = [(sig, stage, share)]
            if sig == "chain":
                kills = [("KILL", "trace", share), ("INT", "errors", float(rng.uniform(0.05, 0.8)))]
            args = ("-cont_checkpoint", "ck")
            for s, st, sh in kills:
                got = _kill(np_, folder, s, target, st, sh, ref, args)
                what = (f"np={np_} SIG{s} to {target} in the {st} stage at {got['at']:.2f} s ({sh:.0%}, checkpoint "
                        f"of stage {got['phase']}): exit {got['status']}, last checkpoint of stage {got['saved']}")
                log.append(what)
                if "s.json" in got["files"]:
                    # it finished before the signal came, or the signal came in its shutdown (under
                    # mpiexec a non-zero exit): the result must be whole and alone, nothing to restart
                    log.append(f"  finished before the signal (exit {got['status']})")
                    if got["saved"] is not None:
                        failures.append(f"{what}: the result and a checkpoint, {got['files']}\n    {repro}")
                    break
                if got["saved"] is None:
                    failures.append(f"{what}: files {got['files']}\n    {repro}")
                    break
                lines = [ln for ln in got["stderr"].splitlines() if ln.startswith("petsc-adhesion")]
                name = signal.Signals(getattr(signal, f"SIG{s}")).name
                said = [f"{PREFIX}interrupted by {name}; nothing written; go on with -cont_restart ck"]
                if s != "KILL" and (lines != said if np_ == 1 else lines not in ([], said)):
                    failures.append(f"{what}: stderr {got['stderr'][-400:]!r}\n    {repro}")
                if np_ == 1 and s != "KILL" and got["status"] != 128 + getattr(signal, f"SIG{s}"):
                    failures.append(f"{what}: exit status {got['status']}\n    {repro}")
                args = ("-cont_restart", "ck")
            else:
                proc = run_cli(*CASE, "-summary", "s.json", *args, np=np_, cwd=folder, timeout=120)
                if proc.returncode != 0:
                    failures.append(f"np={np_} kill {i}, the restart: exit {proc.returncode}: {proc.stderr[-400:]}")
                    continue
                if sorted(os.listdir(folder)) != ["s.json"]:
                    failures.append(f"np={np_} kill {i}: the restart left {sorted(os.listdir(folder))}")
                bad = _differences(json.loads((folder / "s.json").read_text()), ref["summary"])
                failures += [f"np={np_} kill {i}, restarted: {b}\n    {repro}" for b in bad]
            if "s.json" in got["files"]:
                bad = _differences(json.loads((folder / "s.json").read_text()), ref["summary"])
                failures += [f"np={np_} kill {i}, not killed: {b}" for b in bad]
    print(f"\nkills, seed {SEED} (stages: " + ", ".join(
        f"np={k} trace {r['trace'][0]:.2f}-{r['trace'][1]:.2f} s, errors to {r['errors'][1]:.2f} s"
        for k, r in reference.items()) + "):\n  " + "\n  ".join(log))
    assert not failures, "\n".join(failures)
    assert sum("finished before" in ln for ln in log) <= 2, log


def test_a_signal_once_the_results_are_in_place_ends_the_run_as_done(tmp_path):
    """SIGTERM from the run's last call, after its results and checkpoint went (PETSc's garbage cleanup):
    one line that says so, the run's own exit status, the results alone.  Before: 'interrupted by SIGTERM;
    nothing written' and exit 143 beside the written results, seen when a batch system's signal met a
    two-rank run in its last milliseconds."""
    code = ("import os, signal; from petsc4py import PETSc; from petsc_adhesion.app.cli import main; "
            "fired = []; PETSc.garbage_cleanup = lambda *a: fired or fired.append(1) or os.kill(os.getpid(), signal.SIGTERM); "
            "raise SystemExit(main(['x', '-adh_mu', '0.5', '-grid_type', 'uniform', '-grid_n', '101', "
            "'-cont_checkpoint', 'ck', '-cont_checkpoint_interval', '0', '-summary', 's.json']))")
    proc = subprocess.run([sys.executable, "-c", code], env=conftest._env(), capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip().splitlines() == ["petsc-adhesion: SIGTERM came after the results were written"]
    assert os.listdir(tmp_path) == ["s.json"]
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["complete"] and -1 < summary["pull_off"]["F"] < -0.75       # between DMT and JKR


def test_checkpointing_changes_no_number(tmp_path, reference):
    """The run saving before every step and one that saves nothing: the same curve."""
    proc = run_cli(*CASE, "-cont_checkpoint", "none", "-summary", tmp_path / "s.json", cwd=tmp_path)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr   # no progress lines off a terminal
    assert _differences(json.loads((tmp_path / "s.json").read_text()), reference[1]["summary"]) == []
    assert os.listdir(tmp_path) == ["s.json"]


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """A checkpoint of a run killed while it traces (one rank)."""
    folder = tmp_path_factory.mktemp("saved")
    proc = _start(1, folder, *CASE, *SAVE, "-cont_checkpoint", "ck")
    while _phase(folder / "ck") is None and proc.poll() is None:
        time.sleep(0.002)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate()
    return (folder / "ck").read_bytes()


def test_restart_refuses_what_it_cannot_continue(tmp_path, saved):
    (tmp_path / "ck").write_bytes(saved)
    (tmp_path / "foreign").write_text("mu = 2\n")
    damaged = bytearray(saved)
    damaged[-100] ^= 0x01
    (tmp_path / "damaged").write_bytes(bytes(damaged))
    (tmp_path / "short").write_bytes(saved[:len(saved) // 2])
    cases = {("-cont_restart", "missing"): "-cont_restart: no file 'missing'",
             ("-cont_restart", "foreign"): "-cont_restart: 'foreign' is not a petsc-adhesion checkpoint",
             ("-cont_restart", "damaged"): "-cont_restart: the checkpoint 'damaged' is damaged",
             ("-cont_restart", "short"): "-cont_restart: the checkpoint 'short' is damaged",
             ("-cont_restart", "ck", "-adh_mu", "3"): "was written with -adh_mu 2.0; this run has -adh_mu 3.0",
             ("-cont_restart", "ck", "-grid_type", "uniform"): "with -grid_type 'edge'; this run has -grid_type "
                                                               "'uniform'",
             ("-cont_restart", "ck", "-arc_ksp_rtol", "1e-9"): "was written without -arc_ksp_rtol",
             ("-cont_restart", "ck", "-adh_lambda", "1"): "-cont_restart: applies to a curve"}
    def refused(args):
        base = ("-cont_at_lambda", "0") if "-adh_mu" in args else ("-adh_mu", "2") if "-adh_lambda" in args else CASE
        return run_cli(*base, *args, "-summary", "s.json", cwd=tmp_path)

    with ThreadPoolExecutor(max_workers=2) as pool:           # two at a time on the two cores
        procs = dict(zip(cases, pool.map(refused, cases)))
    for args, line in cases.items():
        proc = procs[args]
        assert proc.returncode == 2, (args, proc.stderr)
        assert proc.stderr.startswith(PREFIX) and proc.stderr.count("\n") == 1 and line in proc.stderr, \
            (args, proc.stderr)
    if shutil.which("mpiexec"):
        proc = run_cli(*CASE, "-cont_restart", "ck", "-summary", "s.json", np=2, cwd=tmp_path)
        assert proc.returncode != 0 and "was written on 1 MPI rank, this run has 2" in proc.stderr, proc.stderr
    assert sorted(os.listdir(tmp_path)) == ["ck", "damaged", "foreign", "short"], "nothing written"
    assert (tmp_path / "ck").read_bytes() == saved, "the checkpoint is left as it was"


def test_progress_lines(reference):
    """The run with -progress and a short interval: lines while tracing, then over the error bars."""
    lines = reference[1]["stderr"].splitlines()
    times = r"(\d+(\.\d)? s|\d+\.\d min) elapsed(, about (\d+(\.\d)? s|\d+\.\d min) left)?"
    trace = re.compile(rf"petsc-adhesion: lambda -?\d\S* \(the curve should stop near 10\.5\), \d+ steps, "
                       rf"\d+ events?, {times}")
    bars = re.compile(rf"petsc-adhesion: error bars: \d+ of \d+ events done, {times}")
    assert lines and all(trace.fullmatch(ln) or bars.fullmatch(ln) for ln in lines), lines
    assert any(trace.fullmatch(ln) for ln in lines)
    steps = [int(re.search(r"(\d+) steps", ln).group(1)) for ln in lines if trace.fullmatch(ln)]
    assert steps == sorted(steps) and steps[-1] <= reference[1]["summary"]["steps"]


def test_a_signal_inside_a_line_leaves_it_whole():
    """SIGTERM's handler raises from inside a write once the text is taken (a run killed as it printed a
    case's progress line): the line still ends where it should, so the run's last line, which names the
    checkpoint, stands alone.  ``print`` wrote text and newline apart: the line came out without its end."""
    from petsc_adhesion.errors import Interrupted, say

    class Signalled(io.StringIO):
        hit = False

        def write(self, text):
            n = super().write(text)
            if not self.hit:
                self.hit = True
                raise Interrupted(signal.SIGTERM)
            return n

    stream = Signalled()
    with pytest.raises(Interrupted):
        say("case 8 (mu = 1, sigma = 0.3) done in 0.1 s; 1/8 done", stream)
    say("error: interrupted by SIGTERM; nothing written", stream)
    assert stream.getvalue().splitlines() == ["petsc-adhesion: case 8 (mu = 1, sigma = 0.3) done in 0.1 s; 1/8 done",
                                              "petsc-adhesion: error: interrupted by SIGTERM; nothing written"]


def test_progress_says_the_time_left_from_the_fraction_done(monkeypatch):
    """A clock run by hand: lines at most every interval; the time left is elapsed (1 - done) / done."""
    from mpi4py import MPI

    from petsc_adhesion.app import progress

    now = [100.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: now[0])
    out = io.StringIO()
    p = progress.Progress(MPI.COMM_SELF, True, interval=5.0, stream=out)
    now[0] += 4.0
    p.update(0.5, "early")                          # within the interval: nothing
    now[0] += 2.0
    p.update(0.25, "half way in lambda")            # 6 s, a quarter: 18 s left
    p.update(0.5, "again")                          # nothing: the interval starts again at each line
    now[0] += 144.0
    p.line("no fraction yet", 0.0)
    p.reset()
    now[0] += 30.0
    p.line("error bars", 0.75)
    assert out.getvalue().splitlines() == [
        "petsc-adhesion: half way in lambda, 6.0 s elapsed, about 18 s left",
        "petsc-adhesion: no fraction yet, 2.5 min elapsed",
        "petsc-adhesion: error bars, 30 s elapsed, about 10 s left"]
    quiet = io.StringIO()
    progress.Progress(MPI.COMM_SELF, False, interval=0.0, stream=quiet).line("x", 0.5)
    assert quiet.getvalue() == ""


def test_clock_examples():
    import doctest

    from petsc_adhesion.app import progress

    result = doctest.testmod(progress)
    assert result.attempted > 0 and result.failed == 0


# -- typed values through the checkpoint's one serializer (io/values.py) -----------------------------------
def _curve_run(checkpoint=None, monkeypatch=None, counts=None):
    """A small rough curve with its error bars (uniform 101 nodes, mu = 1, sigma = 0.2, stopped at
    equilibrium), the calls of the error bars' level traces counted into ``counts``."""
    from petsc_adhesion.model.parameters import Model
    from petsc_adhesion.tracing import error_bars
    from petsc_adhesion.tracing.trace import CurveRequest, GridChoice, trace_curve

    if counts is not None:
        located = error_bars.relocate

        def counted(*args, **kw):
            counts.append(args[2].label)
            return located(*args, **kw)
        monkeypatch.setattr(error_bars, "relocate", counted)
    return trace_curve(Model(mu=1.0, sigma=0.2), GridChoice("uniform", n=101), request=CurveRequest(),
                       checkpoint=checkpoint)


def test_a_restart_in_the_error_bars_keeps_the_estimates_made(tmp_path, monkeypatch):
    """A curve saved before its last event's error bars (-cont_checkpoint_interval 0 saves at every pause,
    the last one before the last event's levels): restarted, it traces that event's levels alone, and its
    events equal the uninterrupted run's, bit for bit (the estimates of the others read back from the file)."""
    from petsc4py import PETSc

    from petsc_adhesion.app.checkpoint import Checkpoint, read_file
    from petsc_adhesion.io.summary import summary_of

    path = str(tmp_path / "c.ck")
    first: list[str] = []

    class Marked(Checkpoint):
        def save(self, *args, **kw):        # where the saves fall among the level traces
            first.append("saved")
            super().save(*args, **kw)

    whole = _curve_run(Marked(path, PETSc.COMM_WORLD, {}, interval=0.0), monkeypatch, first)
    header, tree, _ = read_file(path)
    assert header["phase"] == "errors" and len(tree["estimates"]["__tuple__"]) == len(whole.events) - 1 > 1
    after = first[len(first) - first[::-1].index("saved"):]       # the level traces after the last save
    again: list[str] = []
    resumed = _curve_run(Checkpoint(None, PETSc.COMM_WORLD, {}, restart=path, saved=tree), monkeypatch, again)
    # the work counted: the levels of the last event alone, those the uninterrupted run traced after its save
    traces = [k for k in first if k != "saved"]
    assert again == after and set(again) == {whole.events[-1].kind} and len(again) < len(traces) / 3

    # the cycle's energy is integrated over the restored branch's arrays, as it was before the estimates were
    # kept: it agrees to round-off (measured 6e-14 relative), the events bit for bit
    energy = ("energy", "energy_err")

    def bare(s):
        return {k: v for k, v in s.items() if k not in ("wall_time_s", "error_estimate", *energy)}
    a, b = summary_of(resumed), summary_of(whole)
    assert bare(a) == bare(b) and a["folds"] and a["pull_off"]
    # and its bar, a difference of two levels' energies, to the same round-off of the energy (measured 1.6e-16
    # absolute, 2.6e-12 of the bar)
    assert all(abs(a[k] - b[k]) <= 1e-12 * abs(b["energy"]) for k in energy), [(a[k], b[k]) for k in energy]
