"""Open MPI singleton defaults (petsc_adhesion/singleton.py): a plain run gets them, a launched one does
not, a user's setting wins, and MPI works either way."""
import json
import os
import shutil
import subprocess
import sys

import pytest

from petsc_adhesion.singleton import OPENMPI_SINGLETON, SESSION_VARIABLE, session_folder, singleton_defaults

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
    env = {"OMPI_MCA_pml": "ucx", "TMPDIR": "/scratch"}
    singleton_defaults(env, pid=17)
    assert env == {"OMPI_MCA_pml": "ucx", "OMPI_MCA_ess_singleton_isolated": "1", "TMPDIR": "/scratch",
                   SESSION_VARIABLE: f"/scratch/ompi.{os.getuid()}/petsc-adhesion-singleton.17"}
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


def test_each_isolated_singleton_has_a_session_folder_of_its_own():
    """Open MPI 4 puts every isolated singleton's session in one folder, which one process removes while
    another makes it (MPI_Init aborts: benchmarks/singleton.py).  Two processes get two folders; a folder
    chosen for another process (inherited from the one that started this) is replaced, one the user named is
    kept, and a singleton with its daemon (not isolated) is left to Open MPI's folder named by its id."""
    a, b = {}, {}
    singleton_defaults(a, pid=101)
    singleton_defaults(b, pid=102)
    assert a[SESSION_VARIABLE] != b[SESSION_VARIABLE]
    inherited = dict(a)
    singleton_defaults(inherited, pid=103)
    assert inherited[SESSION_VARIABLE] == session_folder(a, 103)
    users = {SESSION_VARIABLE: "/scratch/mine"}
    singleton_defaults(users, pid=104)
    assert users[SESSION_VARIABLE] == "/scratch/mine"
    daemon = {"OMPI_MCA_ess_singleton_isolated": "0"}
    singleton_defaults(daemon, pid=105)
    assert SESSION_VARIABLE not in daemon


def test_open_mpi_keeps_the_session_in_the_folder_and_removes_it(tmp_path):
    """The folder named is the one Open MPI makes in MPI_Init and removes in MPI_Finalize (read from the
    file system, not from the variable): a session folder the variable did not move would be the shared one."""
    code = ("import os, json, petsc_adhesion; from mpi4py import MPI; MPI.COMM_WORLD.Get_size(); "
            "d = os.environ['%s']; print(json.dumps({'folder': d, 'during': sorted(os.listdir(d))}))" % SESSION_VARIABLE)
    env = _clean_env(TMPDIR=str(tmp_path))
    (out,) = _probe([sys.executable, "-c", code], env)
    assert out["folder"].startswith(str(tmp_path / f"ompi.{os.getuid()}" / "petsc-adhesion-singleton."))
    assert out["during"], "Open MPI made nothing in the folder"
    assert not os.path.exists(out["folder"]), "the session folder outlived the process"
