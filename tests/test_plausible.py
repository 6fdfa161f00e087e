"""Inputs outside what the field measures warn in one line naming the option and the likely slip of units;
the docs' own examples do not (app/options/plausible.py, docs/materials.md)."""
import glob
import json
import os
import re
import warnings

import pytest

import petsc_adhesion as pa
from conftest import ROOT, run_cli
from petsc_adhesion.app.options.plausible import PLAUSIBLE, implausible, slip
from petsc_adhesion.app.options.table import TABLE

#: R = 1 um, E = 1 GPa, gamma = 0.05 J/m^2, epsilon = 0.4 nm (mu = 3.39), solved far out on a small grid
BODIES = {"phys_radius": 1e-6, "phys_young1": 1e9, "phys_poisson1": 0.0, "phys_gamma": 0.05, "phys_epsilon": 4e-10}
FAST = ("-adh_lambda", -30, "-grid_type", "uniform", "-grid_n", 51)


@pytest.mark.parametrize("name, value, words", [
    ("phys_gamma", 50, "above 1 J/m^2; was 50 mJ/m^2 meant (-phys_gamma 0.05)?"),
    ("phys_gamma", 5e-5, "below 0.1 mJ/m^2; check its exponent"),
    ("phys_spring", 5000, "above 1000 N/m; was 5000 mN/m meant (-phys_spring 5)?"),
    ("phys_spring", 1e-4, "below 1 mN/m; check its exponent"),
    ("phys_radius", 5e-10, "below 1 nm; check its exponent"),
    ("phys_radius2", 0.05, "above 1 cm; was 0.05 mm meant (-phys_radius2 5e-05)?"),
    ("phys_young1", 2, "below 1 kPa; was 2 MPa or GPa meant (-phys_young1 2e+06 or 2e+09)?"),
    ("phys_young2", 2e12, "above 1200 GPa; check its exponent"),
    ("phys_epsilon", 4e-9, "above 1 nm; check its exponent"),
    ("phys_epsilon", 4e-11, "below 0.1 nm; check its exponent"),
    ("phys_hamaker_cutoff", 2e-9, "above 1 nm; check its exponent"),
    ("phys_hamaker", 5e-18, "above 1e-18 J; check its exponent"),
    ("fit_pull_off", 0.0125, "above 1 mN; was 0.0125 nN or uN meant (-fit_pull_off 1.25e-11 or 1.25e-08)?"),
])
def test_one_line_names_the_option_and_the_slip(name, value, words):
    """Every bound of the table: the line starts with the option and its value, says on which side of the
    field's range it lies, in what unit the option is, and what the value likely was."""
    line = slip(name, value)
    assert line is not None and "\n" not in line and line.startswith(f"-{name} {value:g}: ")
    where, meant = words.split("; ")
    assert where in line and f"the option is in {PLAUSIBLE[name].unit}: {meant}" in line, line


def test_the_ranges_are_inside_what_the_options_accept():
    """A warning is for a value the model takes: each plausible range lies inside its option's table range
    (outside that, the option is refused), and its ends do not warn."""
    for name, p in PLAUSIBLE.items():
        o = TABLE[name]
        assert o.lo <= p.lo < p.hi <= o.hi, name
        assert slip(name, p.lo) is None and slip(name, p.hi) is None
        assert slip(name, p.lo * 0.99) is not None and slip(name, p.hi * 1.01) is not None


def _documented() -> list[tuple[str, str, float]]:
    """Every value of a plausibility-checked option in the README, docs/ and options/: as a command line's
    ``-name value``, an options file's ``-name value`` or the Python API's ``name=value``; not the lines
    that show a warning or a slip (docs/materials.md's, which say "meant")."""
    names = "|".join(sorted(PLAUSIBLE, key=len, reverse=True))
    pattern = re.compile(rf"(?<![\w])-?({names})(?:\s+|=)([-+]?\d[\d.]*(?:[eE][-+]?\d+)?)")
    found = []
    for path in ["README.md", *sorted(glob.glob(os.path.join(ROOT, "docs", "*.md"))),
                 *sorted(glob.glob(os.path.join(ROOT, "options", "*.opts")))]:
        for line in open(os.path.join(ROOT, path)):
            if "meant" not in line:
                found += [(os.path.basename(path), m.group(1), float(m.group(2))) for m in pattern.finditer(line)]
    return found


def test_the_docs_examples_do_not_warn():
    """The README's demo, the docs' examples and the shipped options files: physical inputs all, none warned."""
    found = _documented()
    assert len(found) >= 30 and {n for _, n, _ in found} >= {"phys_radius", "phys_young1", "phys_gamma",
                                                            "phys_epsilon", "phys_spring", "fit_pull_off"}
    assert [(f, n, v) for f, n, v in found if slip(n, v)] == []


def test_a_run_warns_and_goes_on(tmp_path):
    """-phys_gamma 50 (J/m^2, typed as if mJ/m^2) on a stiff sphere (E = 1000 GPa, mu the same 3.39): one
    warning line on stderr, the run computes and writes, the value it warns about honoured (the unit of force
    2 pi R gamma = 314159 nN)."""
    js = tmp_path / "s.json"
    args = [a for k, v in {**BODIES, "phys_gamma": 50, "phys_young1": 1e12}.items() for a in (f"-{k}", v)]
    proc = run_cli(*args, *FAST, "-summary", js)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ("petsc-adhesion: warning: -phys_gamma 50: a work of adhesion above 1 J/m^2, more than all "
                           "but clean metals in vacuum; the option is in J/m^2: was 50 mJ/m^2 meant "
                           "(-phys_gamma 0.05)?\n")
    s = json.loads(js.read_text())
    assert s["mu"] == pytest.approx(3.393022, rel=1e-6)
    assert s["physical"]["force_nN"] == pytest.approx(314159.27, rel=1e-7)
    ok = run_cli(*[a for k, v in BODIES.items() for a in (f"-{k}", v)], *FAST)
    assert ok.returncode == 0 and ok.stderr == ""


def test_a_refused_mu_names_the_slip(tmp_path):
    """A modulus of 2 Pa (2 MPa meant) makes mu beyond the model's range: refused in one line, exit 2,
    nothing written, the line saying the likely slip."""
    args = [a for k, v in {**BODIES, "phys_young1": 2}.items() for a in (f"-{k}", v)]
    proc = run_cli(*args, "-out", tmp_path / "x.h5")
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("petsc-adhesion: error: -phys_young1: with the other -phys_ options gives mu")
    assert "was 2 MPa or GPa meant (-phys_young1 2e+06 or 2e+09)?" in proc.stderr
    assert not any(tmp_path.iterdir())


def test_the_python_api_warns_alike():
    """The API's keywords are checked as the command line's: a RuntimeWarning per implausible input."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = pa.solve(-30.0, **{**BODIES, "phys_spring": None, "phys_radius": 5e-10, "phys_epsilon": 4e-10},
                     grid_type="uniform", grid_n=51)
    said = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert said == ["petsc-adhesion: " + slip("phys_radius", 5e-10)], said
    assert s.model.bodies is not None and s.model.bodies.R == 5e-10          # honoured, not changed
    assert implausible({**BODIES, "phys_spring": None}) == []


def test_the_python_api_names_a_misspelling_first():
    """A misspelt keyword of ours is named with its nearest option before the options it leaves missing."""
    from petsc_adhesion.errors import InputError

    given = {**BODIES, "phys_radis": BODIES["phys_radius"]}
    del given["phys_radius"]
    with pytest.raises(InputError, match=r"^-phys_radis: unknown option \(did you mean -phys_radius\?\)"):
        pa.solve(-30.0, grid_type="uniform", grid_n=51, **given)
