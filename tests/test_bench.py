"""The benchmark runs and writes its JSON (no timing is asserted: the cores are shared)."""
import json
import math
import subprocess
import sys

from conftest import ROOT, _env


def test_bench_influence_json(tmp_path):
    path = tmp_path / "bench.json"
    cmd = [sys.executable, "-m", "petsc_adhesion.bench", "-bench_only", "influence",
           "-bench_repeats", "1", "-bench_json", str(path)]
    run = subprocess.run(cmd, cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    out = json.loads(path.read_text())
    assert out["mpi_ranks"] == 1 and "petsc_version" in out
    assert set(out["results"]) == {"influence_531", "influence_4000"}
    for key, n in (("influence_531", 531), ("influence_4000", 4000)):
        q = out["results"][key]
        assert q["n_nodes"] == n and q["repeats"] == 1
        for t in ("median_s", "min_s", "max_s"):
            assert math.isfinite(q[t]) and q[t] > 0
        assert q["min_s"] <= q["median_s"] <= q["max_s"]
    assert out["results"]["influence_531"]["target_s"] == 0.3
    assert isinstance(out["results"]["influence_531"]["met"], bool)
    assert "influence build, N = 531" in run.stdout
