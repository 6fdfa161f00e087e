"""``petsc-adhesion plot RESULT.h5 [-o OUT]``: a figure from every kind of result file, or one line.

A figure is checked for what it must show: the panels (one without profiles, three
with them), the physical axes when the run had physical inputs, a readable image of
the default name, and nothing written (an earlier figure untouched) after any error.
"""
import os
import subprocess
import sys

import matplotlib
import matplotlib.image
import pytest

from conftest import ROOT, _env, in_process

matplotlib.use("Agg")
TINY = ("-grid_type", "uniform", "-grid_n", "101")
PHYS = ("-phys_radius", 1e-6, "-phys_young1", 1e12, "-phys_poisson1", 0, "-phys_gamma", 0.05, "-phys_epsilon", 4e-10)


def plot(*args):
    return subprocess.run([sys.executable, "-m", "petsc_adhesion", "plot", *map(str, args)], cwd=ROOT, env=_env(),
                          capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("results")
    runs = {"curve": (*TINY, "-adh_mu", 0.5, "-cont_F_max", 0), "profiles": (*TINY, "-adh_mu", 0.5, "-cont_F_max", 0,
                                                                            "-profiles"),
            "physical": (*TINY, *PHYS, "-cont_F_max", 0, "-profiles"), "solve": (*TINY, "-adh_mu", 0.5,
                                                                                  "-adh_lambda", -3),
            "study": (*TINY, "-study_mu", "0.1,0.5", "-study_compute", "pull_off", "-study_plot", "pull_off")}
    for name, args in runs.items():           # main() in this process: the files are what is plotted here
        fast = () if name == "solve" else ("-cont_error_estimate", "false")
        proc = in_process(*args, *fast, "-out", d / f"{name}.h5")
        assert proc.returncode == 0, proc.stderr
    return d


def _axes(path):
    """The figure's axes, from the function the command calls (in-process, same code)."""
    import matplotlib.pyplot as plt

    from petsc_adhesion.io.plot import command as p

    captured = {}
    real = plt.Figure.savefig

    def keep(fig, *a, **k):
        # one entry per panel: its labels and those of its secondary (physical) axes
        captured["labels"] = sorted(" ".join(a.get_xlabel() + "|" + a.get_ylabel() for a in [ax, *ax.child_axes])
                                    for ax in fig.axes)
        return real(fig, *a, **k)

    plt.Figure.savefig = keep
    try:
        p._draw(p._kind(str(path)), str(path), os.devnull, "png")
    finally:
        plt.Figure.savefig = real
    return captured["labels"]


@pytest.mark.parametrize("name", ["curve", "profiles", "physical", "solve", "study"])
def test_every_kind_draws(files, name):
    proc = plot(files / f"{name}.h5")
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    img = matplotlib.image.imread(files / f"{name}.png")
    assert img.ndim == 3 and img.shape[0] > 300 and img.std() > 0.01


def test_panels_and_physical_axes(files):
    assert len(_axes(files / "curve.h5")) == 1
    labels = _axes(files / "profiles.h5")
    assert len(labels) == 3 and any("pressure" in lab for lab in labels)
    phys = _axes(files / "physical.h5")
    for unit in ("approach (nm)", "load (nN)", "r (nm)", "pressure (MPa)"):
        assert any(unit in lab for lab in phys), (unit, phys)
    assert not any("nm" in lab for lab in labels)


def test_formats_and_output_name(files, tmp_path):
    for ext in ("pdf", "svg"):
        out = tmp_path / f"c.{ext}"
        assert plot(files / "curve.h5", "-o", out).returncode == 0
        assert out.read_bytes()[:5] in (b"%PDF-", b"<?xml")


@pytest.mark.parametrize("what, line", [
    ("missing", "plot: no file"), ("json", "is not an HDF5 file"), ("foreign", "is not a petsc-adhesion result"),
    ("jpg", "-o: expected a file name ending in .png, .pdf, .svg"), ("input", "-o: expected a file name ending"),
    ("args", "plot: expected RESULT.h5 [-o OUT]"), ("dir", "-o: cannot write")])
def test_bad_input_is_one_line_and_writes_nothing(files, tmp_path, what, line):
    import h5py

    earlier = tmp_path / "fig.png"
    earlier.write_bytes(b"an earlier figure")
    src, out = files / "curve.h5", earlier
    if what == "missing":
        src = tmp_path / "none.h5"
    elif what == "json":
        src = tmp_path / "x.json"
        src.write_text("{}")
    elif what == "foreign":
        src = tmp_path / "foreign.h5"
        with h5py.File(src, "w") as f:
            f["x"] = [1.0]
    elif what == "jpg":
        out = tmp_path / "fig.jpg"
    elif what == "input":
        out = src
    elif what == "dir":
        out = tmp_path / "no" / "fig.png"
    args = (src, "-o", out, "-x") if what == "args" else (src, "-o", out)
    before = sorted(os.listdir(tmp_path))
    proc = plot(*args)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("petsc-adhesion: error: ") and line in proc.stderr, proc.stderr
    assert sorted(os.listdir(tmp_path)) == before and earlier.read_bytes() == b"an earlier figure"
