"""docs/afm.md and what it stands on: the figure of a curve behind a spring, the options file of the map of
the jumps, and the tables of ``python -m petsc_adhesion.benchmarks.afm`` against the library now."""
import json
import math
import os
import re

import matplotlib
import matplotlib.image
import numpy as np
import pytest

from conftest import ROOT, drawn_figure, run_cli

matplotlib.use("Agg")


def _panels(path):
    """The labels of every panel of the figure of a result file (x label | y label, secondary axes too)."""
    return [" ".join(a.get_xlabel() + "|" + a.get_ylabel() for a in [ax, *ax.child_axes])
            for ax in drawn_figure(path).axes]


def test_the_plot_of_a_spring_run_has_its_force_distance_and_contact_panels(tmp_path):
    out = tmp_path / "k.h5"
    proc = run_cli("-adh_mu", 1, "-afm_spring", 0.5, "-cont_F_max", 0.5, "-out", out, "-plot", tmp_path / "k.png")
    assert proc.returncode == 0, proc.stderr
    labels = _panels(out)
    assert len(labels) == 3, labels
    assert any(lab.startswith("approach lambda") for lab in labels)
    assert any("base of the spring Z" in lab and "force F" in lab for lab in labels)    # the instrument's legs
    assert any("contact radius" in lab for lab in labels)
    # the run's -plot and the plot command draw it
    proc = run_cli("plot", out, "-o", tmp_path / "again.png")
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    for png in ("k.png", "again.png"):
        img = matplotlib.image.imread(tmp_path / png)
        assert img.shape[1] > 1500 and img.std() > 0.01


def test_a_cantilever_in_si_gets_nm_and_nn_on_its_force_distance_panel(tmp_path):
    out = tmp_path / "p.h5"
    proc = run_cli("-phys_radius", 20e-9, "-phys_young1", 150e9, "-phys_poisson1", 0.27, "-phys_gamma", 0.05,
                   "-phys_epsilon", 0.3e-9, "-phys_spring", 1, "-cont_F_max", 0, "-cont_error_estimate", "false",
                   "-out", out)
    assert proc.returncode == 0, proc.stderr
    labels = _panels(out)
    # the instrument's legs on the main axes in nm and nN (no second axes there)
    assert "piezo displacement Z (nm)|force (nN)" in labels, labels
    assert any("contact radius (nm)" in lab for lab in labels)


def test_a_curve_without_spring_keeps_its_one_panel(tmp_path):
    out = tmp_path / "r.h5"
    proc = run_cli("-adh_mu", 1, "-cont_F_max", 0, "-cont_error_estimate", "false", "-out", out)
    assert proc.returncode == 0, proc.stderr
    assert len(_panels(out)) == 1


def test_the_map_options_file_runs_and_holds_the_jumps_of_every_case(tmp_path):
    """options/afm_map.opts, cut to two cases here (the command line's options override the file's)."""
    (tmp_path / "results").mkdir()
    proc = run_cli("-options_file", os.path.join(ROOT, "options", "afm_map.opts"), "-study_mu", 1,
                   "-study_values", "0.1,1", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    s = json.load(open(tmp_path / "results" / "afm_map.json"))
    assert s["study"]["axes"] == ["adh_mu", "afm_spring"]
    assert [c["values"]["afm_spring"] for c in s["cases"]] == [0.1, 1.0]
    for c in s["cases"]:
        sp = c["spring"]
        assert sp["K"] == c["values"]["afm_spring"]
        assert [j["kind"] for j in sp["jumps"]] == ["jump_in", "jump_off"]
        for j in sp["jumps"]:
            assert j["Z_err"] < 1e-3 and j["landing"]["Z"] == j["Z"]
        assert sp["energy"] > c["energy"] > 0 and sp["energy_err"] < 1e-2 * sp["energy"]


def _row(name, first):
    """The cells of the row of docs/figures/NAME.md whose first cells are ``first``."""
    text = open(os.path.join(ROOT, "docs", "figures", f"{name}.md")).read()
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[:len(first)] == list(first):
            return cells
    raise AssertionError(f"no row {first} in {name}.md")


def _value(cell):
    m = re.match(r"(-?\d+\.\d+)(?: \+- (\S+))?", cell)
    return float(m.group(1)), float(m.group(2)) if m.group(2) else None


def test_the_stiffness_table_is_what_the_library_gives_now():
    from petsc_adhesion import Model, trace_curve
    from petsc_adhesion.benchmarks import afm
    from petsc_adhesion.tracing.trace import CurveRequest

    cells = _row("afm_stiffness", ["0.1"])
    head = _row("afm_stiffness", ["K"])
    c = trace_curve(Model(mu=1.0), request=CurveRequest(spring=0.1, kinds=afm.JUMP_KINDS))
    jin, joff = afm.primary(c)
    got = {"jump-in distance -Z": -jin.Z.value, "jump-off F": joff.F.value, "energy": c.spring.cycle.energy.value}
    for name, now in got.items():
        value, bar = _value(cells[head.index(f"mu = 1: {name}")])
        assert abs(value - now) <= max(2 * bar, 1e-4 * abs(now)), (name, value, now)


def test_the_example_table_is_what_the_library_gives_now():
    from petsc_adhesion.benchmarks import afm

    b = afm.bodies("glass")
    d = b.describe()
    c = afm.cantilever(b, 1.0)
    jin, joff = afm.primary(c)
    cells = _row("afm_example", ["glass", f"{b.mu:.4f}", "1"])
    assert _value(cells[4])[0] == pytest.approx(jin.Z.value * d["approach_nm"], abs=1e-4)
    assert _value(cells[8])[0] == pytest.approx(joff.F.value * d["force_nN"], abs=1e-4)
    assert _value(cells[9])[0] == pytest.approx(c.spring.cycle.energy.value * d["work_aJ"], abs=1e-3)


def test_the_closed_forms_of_the_figures():
    from petsc_adhesion.benchmarks import afm
    from petsc_adhesion.model.reference.jkr import jkr_load
    from petsc_adhesion.model.reference.rigid import rigid_load

    # DMT: Hertz's load (JKR's first term) plus the DMT pull-off -1
    mu, A = 2.0, 1.7
    hertz = jkr_load(A, mu) + math.sqrt(2 * A**3 / (math.pi * mu**1.5))
    assert afm.dmt_radius(hertz - 1.0, mu) == pytest.approx(A, rel=1e-12)
    # the rigid sphere's jump-in: where its load's slope is -K, Z = lambda + F / K
    K = 0.05
    Z = afm.rigid_sphere_jump_in(K)
    lam = np.linspace(-30, 0.5, 300001)
    F = rigid_load(lam)
    Zs = lam + F / K
    assert Z == pytest.approx(Zs[: np.argmin(F)].max(), abs=1e-6)
    assert afm.rigid_sphere_jump_in(1.1) is None
    # Maugis-Dugdale between DMT and JKR at zero load
    md = afm.md_radius(1.0)
    assert afm.dmt_radius(0.0, 1.0) < md["zero"] < 2.418


def test_afm_md_names_its_figures_and_commands():
    text = open(os.path.join(ROOT, "docs", "afm.md")).read()
    pngs = re.findall(r"\(figures/(afm_\w+)\.png\)", text)
    assert sorted(pngs) == ["afm_example", "afm_probe", "afm_radius", "afm_stiffness", "afm_tip"]
    for png in ("afm_probe", "afm_tip"):        # the program's own figure: made by the command shown beside it
        assert os.path.exists(os.path.join(ROOT, "docs", "figures", f"{png}.png"))
        command = text.split(f"-plot docs/figures/{png}.png")[0].rsplit("```sh", 1)[1]
        assert "petsc-adhesion" in command and "-phys_spring" in command
        assert text.index(f"-plot docs/figures/{png}.png") < text.index(f"(figures/{png}.png)")
    for png in ("afm_example", "afm_radius", "afm_stiffness"):
        assert os.path.exists(os.path.join(ROOT, "docs", "figures", f"{png}.png"))
        table = open(os.path.join(ROOT, "docs", "figures", f"{png}.md")).read()
        what = png.split("_", 1)[1]
        assert f"made by: ./run figures {png} (python -m petsc_adhesion.benchmarks.afm {what})" in table
        assert f"python -m petsc_adhesion.benchmarks.afm {what}" in text or \
            "python -m petsc_adhesion.benchmarks.afm`" in text
    for needle in ("options/afm_map.opts", "CurveRequest(spring=", "curve.spring", "curve.rigid.energy",
                   "curve.contact_radius", "-afm_spring", "-phys_spring", "-phys_trigger", "-afm_trigger",
                   "curve.instrument"):
        assert needle in text, needle


def test_the_worked_example_in_afm_md_is_its_table():
    """The rows docs/afm.md quotes are docs/figures/afm_example.md's, to the digits shown."""
    text = open(os.path.join(ROOT, "docs", "afm.md")).read()
    quoted = re.findall(r"^\| (glass|polystyrene) \| (\S+) \| (.*) \|$", text, re.M)
    assert len(quoted) == 6
    for flat, k, rest in quoted:
        cells = rest.split(" | ")
        full = next(r for r in (_row_all("afm_example")) if r[0] == flat and r[2] == k)
        for mine, theirs in zip(cells, (full[4], full[5], full[7], full[8], full[9])):
            a, b = _value(mine)[0], _value(theirs)[0]
            digits = len(mine.split()[0].split(".")[1])
            assert abs(a - b) <= 0.6 * 10**-digits, (flat, k, mine, theirs)


def _row_all(name):
    text = open(os.path.join(ROOT, "docs", "figures", f"{name}.md")).read()
    return [[c.strip() for c in line.strip().strip("|").split("|")] for line in text.splitlines()
            if line.startswith("| ")]


def test_the_python_example_of_afm_md_runs():
    from petsc_adhesion import Bodies, CurveRequest, Model, trace_curve

    tip = Bodies(radius=20e-9, young1=150e9, poisson1=0.27, young2=70e9, poisson2=0.17, gamma=0.05, epsilon=0.3e-9)
    K = tip.spring_stiffness(1.0)
    assert K == pytest.approx(0.04775, abs=1e-5)
    curve = trace_curve(Model(mu=tip.mu, bodies=tip), request=CurveRequest(spring=K, kinds=("jump_in", "jump_off")))
    assert [j.kind for j in curve.spring.jumps] == ["jump_in", "jump_off"]
    assert curve.rigid.energy.value == 0.0 and curve.spring.cycle.energy.value > 0
    assert curve.Z.shape == curve.F.shape == curve.contact_radius.shape
    jump_in = curve.events_of("jump_in")[0]
    assert jump_in.landing.Z.value == jump_in.Z.value and jump_in.Z.err > 0
