"""docs/soft.md names the command that writes it next to each table and figure, its figures exist, and the
helpers of its generator (petsc_adhesion/benchmarks/soft.py) are right on data with known answers."""
import math
import os
import re

import numpy as np
import pytest

from conftest import ROOT
from petsc_adhesion.benchmarks import soft

DOC = os.path.join(ROOT, "docs", "soft.md")


def _sections(text: str) -> list[str]:
    return re.split(r"\n(?=## )", text)


def test_soft_md_names_its_command_next_to_its_tables_and_figures():
    text = open(DOC).read()
    assert text.startswith(f"<!-- made by: OPENBLAS_NUM_THREADS=1 {soft.COMMAND}")
    pngs = re.findall(r"\(figures/(\w+)\.png\)", text)
    assert set(pngs) == set(soft.FIGURES)
    for png in pngs:
        assert os.path.exists(os.path.join(ROOT, "docs", "figures", f"{png}.png")), png
    for section in _sections(text)[1:]:
        has_table = re.search(r"^\|---", section, re.M)
        if has_table or "(figures/" in section:
            assert f"`{soft.COMMAND}" in section, section.splitlines()[0]
    for png in pngs:           # each figure's caption, the paragraph after it, names the command
        caption = text.split(f"(figures/{png}.png)")[1].strip().split("\n\n")[0]
        assert caption.startswith(f"Figure {png}.png, made by `{soft.COMMAND}"), caption


def test_power_fit_recovers_a_known_exponent():
    rng = np.random.default_rng(1)
    mu = np.array([20.0, 100.0, 300.0, 1000.0])
    d = -4e-2 * mu ** -1.7 * np.exp(1e-3 * rng.standard_normal(mu.size))   # signed: the fit takes |d|
    p, c = soft.power_fit(mu, d)
    assert p == pytest.approx(-1.7, abs=2e-3) and c == pytest.approx(4e-2, rel=1e-2)
    with pytest.raises(ValueError):
        soft.power_fit([10.0, 100.0], [1e-3, 0.0])


def test_jkr_limits_are_the_closed_forms_constants():
    """The scaled JKR values do not depend on mu and are the constants the page quotes."""
    for mu in (5.0, 1000.0):
        lim = soft.jkr_limits(mu)
        assert lim["pull_off_F"] == -0.75 and lim["snap_off_F"] == pytest.approx(-5 / 12, abs=1e-14)
        assert lim["snap_off_lam"] == pytest.approx(-3 * (math.pi / 8) ** (2 / 3), rel=1e-13)
        assert lim["snap_off_lam"] == pytest.approx(-1.60877, abs=5e-6)
        assert lim["zero_lam"] == pytest.approx(1.94889, abs=5e-6)
        assert lim["zero_a"] == pytest.approx((4.5 * math.pi) ** (1 / 3), rel=1e-13)
        assert lim["zero_a"] == pytest.approx(2.41799, abs=5e-6)


def test_maugis_dugdale_approaches_jkr_as_mu_to_the_minus_two():
    """The Maugis-Dugdale values the page sets beside ours tend to JKR's, each distance as mu^-2."""
    mus = [100.0, 300.0, 1000.0]
    for key, _, _ in soft.QUANTITIES:
        d = [soft.maugis_dugdale_values(m)[key] - soft.jkr_limits(m)[key] for m in mus]
        p, _ = soft.power_fit(mus, d)
        assert p == pytest.approx(-2.0, abs=0.05), (key, d)


def test_runs_of_stability_join():
    st = np.array([True, True, False, False, False, True])
    runs = soft._runs(st)
    assert [(s.start, s.stop) for s in runs] == [(0, 3), (2, 6), (5, 6)]
