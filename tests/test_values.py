"""The results are values: a field added to an event reaches the JSON and HDF5 files through the
serializers that read fields generically, with no change to them; and the energy of a cycle that was not
closed is missing with its reason, in the files and on the console, never 0."""
import dataclasses
import json

import numpy as np
import pytest

from conftest import run_cli
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.tracing.curve import (Assessment, Branch, Curve, Cycle, Diagnostics, Event, GridRecord, Landing,
                                          Program)
from petsc_adhesion.tracing.measured import Measured, Missing


@dataclasses.dataclass(frozen=True)
class TaggedEvent(Event):
    """An event with a quantity no serializer knows of."""

    hardness: Measured | None = None


def _curve(event, rigid=Cycle(Measured(0.25, 0.01), 1)) -> Curve:
    n = 3
    branch = Branch(lam=np.linspace(-2.0, 1.0, n), F=np.array([-0.1, -0.5, 1.0]), H0=np.ones(n),
                    stable=np.ones(n, bool), contact_radius=np.zeros(n), ds=np.zeros(n),
                    newton_its=np.ones(n, int), ksp_its=np.ones(n, int), lambdadot=np.ones(n),
                    corrector=np.array([b"start"] * n, dtype="S9"))
    diag = Diagnostics(steps=2, rejected_steps=0, regrids=0, folds=0, guard_activations=0, smallest_step=0.1,
                       most_newton_its=1, most_ksp_its=1, stop_reason="test", wall_time_s=0.0, lambda_start=-2.0,
                       wall_gap=1.0)
    return Curve(model=Model(mu=1.0, rmax=10.0), program=Program("petsc-adhesion", "0", "3.18.0", "3.18.0", 1),
                 grid=GridRecord(np.linspace(0.0, 10.0, 5)), branch=branch, events=(event,), pull_off=None,
                 rigid=rigid, spring=None, diagnostics=diag, assessment=Assessment((), ()))


def test_a_new_field_of_an_event_reaches_the_json_and_hdf5_files(tmp_path):
    h5py = pytest.importorskip("h5py")
    from petsc_adhesion.io.layout import curve_tree
    from petsc_adhesion.io.summary import summary_of
    from petsc_adhesion.io.write import write_h5, write_json

    land = Landing(lam=Measured(-1.5), F=Measured(-0.3, 2e-3, -0.31), H0=0.5)
    ev = TaggedEvent(kind="snap_on", lam=Measured(-1.25, 1e-4, -1.2501), F=Measured(-0.4, 3e-4), H0=0.7,
                     landing=land, hardness=Measured(7.5, 0.25, 7.0))
    c = _curve(ev)
    write_json(str(tmp_path / "s.json"), summary_of(c))
    with open(tmp_path / "s.json") as f:
        fold = json.load(f)["folds"][0]
    assert (fold["hardness"], fold["hardness_err"], fold["hardness_grid"]) == (7.5, 0.25, 7.0)
    assert (fold["lambda"], fold["lambda_err"], fold["lambda_grid"]) == (-1.25, 1e-4, -1.2501)
    assert fold["landing"] == {"lambda": -1.5, "F": -0.3, "F_err": 2e-3, "F_grid": -0.31, "H0": 0.5}
    write_h5(str(tmp_path / "c.h5"), curve_tree(c, {}))
    with h5py.File(tmp_path / "c.h5", "r") as f:
        a = f["events/0000"].attrs
        assert (a["hardness"], a["hardness_err"], a["hardness_grid"]) == (7.5, 0.25, 7.0)
        assert a["kind"] == "snap_on" and "Z" not in a and "stable" not in a     # None: absent
        assert f["events/0000/landing"].attrs["F_grid"] == -0.31
        assert f["summary/folds/0000"].attrs["hardness"] == 7.5


def test_a_missing_energy_is_absent_from_the_files(tmp_path):
    h5py = pytest.importorskip("h5py")
    from petsc_adhesion.io.layout import curve_tree
    from petsc_adhesion.io.summary import summary_of
    from petsc_adhesion.io.write import write_h5

    ev = Event(kind="F_min", lam=Measured(-1.0), F=Measured(-0.8), H0=0.2)
    c = _curve(ev, rigid=Cycle(Missing("the cycle was not closed: because"), None))
    s = summary_of(c)
    assert s["energy"] is None and s["energy_err"] is None and s["loops"] is None
    assert s["energy_note"] == "the cycle was not closed: because"
    write_h5(str(tmp_path / "c.h5"), curve_tree(c, {}))
    with h5py.File(tmp_path / "c.h5", "r") as f:
        a = f["summary"].attrs
        assert "energy" not in a and "energy_err" not in a and "loops" not in a
        assert a["energy_note"] == "the cycle was not closed: because"


def _summary(tmp_path, name, *args):
    out = tmp_path / f"{name}.json"
    h5 = tmp_path / f"{name}.h5"
    p = run_cli("-adh_mu", "3", *args, "-summary", out, "-out", h5)
    assert p.returncode in (0, 3), p.stderr
    with open(out) as f:
        return json.load(f), p, h5


def test_the_energy_of_a_cycle_not_closed_is_missing_with_its_reason(tmp_path):
    """mu = 3: with -cont_F_max below the pull-off (about -0.776) the curve stops on the far branch, before
    its loop; cut by -cont_max_steps before the snap-off it ends early: no energy, its reason said, never
    0.  The full curve's energy is about 1.08 (its hysteresis loop between snap-on and snap-off)."""
    h5py = pytest.importorskip("h5py")
    s, p, h5 = _summary(tmp_path, "low", "-cont_F_max", "-0.9", "-cont_error_estimate", "false")
    assert s["energy"] is None and s["energy_err"] is None and s["loops"] is None
    assert "not closed" in s["energy_note"] and "tension" in s["energy_note"]
    assert "none: the cycle was not closed" in p.stdout and "hysteresis loop" not in p.stdout
    with h5py.File(h5, "r") as f:
        assert "energy" not in f["summary"].attrs and "not closed" in f["summary"].attrs["energy_note"]
    s, p, _ = _summary(tmp_path, "cut", "-cont_max_steps", "20", "-cont_error_estimate", "false")
    assert s["energy"] is None and "ended early" in s["energy_note"] and p.returncode == 3
    s, p, _ = _summary(tmp_path, "full")
    assert s["complete"] and s["loops"] == 1 and "energy_note" not in s
    assert 1.05 < s["energy"] < 1.11 and 0 < s["energy_err"] < 0.01
    assert "(1 hysteresis loop)" in p.stdout
