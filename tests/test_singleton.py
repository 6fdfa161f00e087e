"""Open MPI singleton defaults (petsc_adhesion/singleton.py): a plain run gets them, a launched one does
not, a user's setting wins, and MPI works either way."""
import json
import shutil
import subprocess
import sys

import pytest

from petsc_adhesion.singleton import OPENMPI_SINGLETON, singleton_defaults

from conftest import ROOT, _env

PROBE = ("import os, json, petsc_adhesion; from mpi4py import MPI; c = MPI.COMM_WORLD; "
         "print(json.dumps({'size': c.Get_size(), 'sum': c.allreduce(c.Get_rank() + 1), "
         "'env': {k: os.environ.get(k) for k in %r}}))" % sorted(OPENMPI_SINGLETON))


def _clean_env(**extra):
    env = {k: v for k, v in _env().items() if k not in OPENMPI_SINGLETON and not k.startswith(("PMIX_", "PMI_"))
           and k not in ("OMPI_COMM_WORLD_SIZE", "SLURM_PROCID")}
    return env | extra


def _probe(cmd, env):
    """The JSON objects the ranks printed: each rank's one write, which a launcher may pass on run together
    (MPICH's Hydra gave '{...}{...}' on one line, its newlines elsewhere)."""
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    decoder, text, outs, i = json.JSONDecoder(), p.stdout, [], p.stdout.find("{")
    while i >= 0:
        obj, end = decoder.raw_decode(text, i)
        outs.append(obj)
        i = text.find("{", end)
    return outs


def test_user_setting_and_launcher_win():
    env = {"OMPI_MCA_pml": "ucx"}
    singleton_defaults(env)
    assert env == {"OMPI_MCA_pml": "ucx", "OMPI_MCA_ess_singleton_isolated": "1"}
    for launcher in ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"):
        env = {launcher: "0"}
        singleton_defaults(env)
        assert env == {launcher: "0"}


def test_plain_process_gets_the_defaults_and_mpi_works():
    (out,) = _probe([sys.executable, "-c", PROBE], _clean_env())
    assert out == {"size": 1, "sum": 1, "env": OPENMPI_SINGLETON}


def test_process_under_mpiexec_is_left_alone():
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        pytest.skip("mpiexec not found")
    outs = _probe([mpiexec, "-n", "2", sys.executable, "-c", PROBE], _clean_env())
    assert len(outs) == 2
    for out in outs:
        assert out == {"size": 2, "sum": 3, "env": {k: None for k in OPENMPI_SINGLETON}}
