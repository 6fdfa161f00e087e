"""The CSV exports: -csv (the curve), -csv_events (its events) and a study's table of events (-csv).

Each file is read back with the standard library's csv module and judged against what the same run wrote
elsewhere: the HDF5 file (bit for bit), the JSON summary, the scales of the physical group, Z = lambda + F/K
behind a spring.  The failure rules are those of every output: all files of a run or none, never over an
input, one line naming the option and exit 2 for a bad path, nothing written.

The runs are made once per module, two at a time on the two cores (about 0.5 s each at mu = 1).
"""
import csv
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from conftest import _env, run_cli

h5py = pytest.importorskip("h5py")

PREFIX = "petsc-adhesion: error: "
FAST = ("-grid_type", "uniform", "-grid_n", "101")
#: a curve of well under a second with its events, and without error bars
CURVE = ("-adh_mu", "1", *FAST, "-cont_F_max", "0", "-cont_error_estimate", "false")
STUDY = ("-study_mu", "0.5,1", *FAST, "-cont_F_max", "0", "-cont_error_estimate", "false")
SOLVE = ("-adh_mu", "1", "-adh_lambda", "-2", *FAST)
#: R = 10 nm, E = 1.25 GPa, gamma = 0.1 J/m^2, epsilon = 0.4 nm: mu = 1
PHYSICAL = ("-phys_radius", "10e-9", "-phys_young1", "1.25e9", "-phys_poisson1", "0", "-phys_gamma", "0.1",
            "-phys_epsilon", "4e-10")
K = 0.5

EPS, LOAD, RAD = "[epsilon]", "[2 pi R gamma]", "[sqrt(epsilon R)]"
CURVE_HEADER = [f"lambda {EPS}", f"F {LOAD}", f"contact_radius {RAD}", "stable"]
#: behind a spring, the two legs its cantilever follows (tests/test_legs.py judges them)
SPRING_HEADER = ["leg", f"Z {EPS}", f"separation {EPS}", f"deflection {EPS}", f"F {LOAD}", f"lambda {EPS}",
                 f"contact_radius {RAD}", "jump"]
EVENT_HEADER = ["kind", f"lambda {EPS}", f"lambda_err {EPS}", f"F {LOAD}", f"F_err {LOAD}", f"Z {EPS}",
                f"Z_err {EPS}", f"H0 {EPS}", f"contact_radius {RAD}", f"contact_radius_err {RAD}", "stable", "levels",
                f"landing_lambda {EPS}", f"landing_lambda_err {EPS}", f"landing_F {LOAD}", f"landing_F_err {LOAD}",
                f"landing_Z {EPS}", f"landing_contact_radius {RAD}", f"landing_contact_radius_err {RAD}",
                f"lambda_grid {EPS}", f"F_grid {LOAD}"]
#: the physical twins the events' CSV adds: name -> (the dimensionless column, the scale in the physical group)
EVENT_PHYSICAL = {"lambda_nm": ("lambda", "approach_nm"), "lambda_err_nm": ("lambda_err", "approach_nm"),
                  "F_nN": ("F", "force_nN"), "F_err_nN": ("F_err", "force_nN"), "Z_nm": ("Z", "approach_nm"),
                  "Z_err_nm": ("Z_err", "approach_nm"), "H0_nm": ("H0", "approach_nm"),
                  "contact_radius_nm": ("contact_radius", "radius_nm"),
                  "contact_radius_err_nm": ("contact_radius_err", "radius_nm"),
                  "landing_lambda_nm": ("landing_lambda", "approach_nm"),
                  "landing_lambda_err_nm": ("landing_lambda_err", "approach_nm"),
                  "landing_F_nN": ("landing_F", "force_nN"), "landing_F_err_nN": ("landing_F_err", "force_nN"),
                  "landing_Z_nm": ("landing_Z", "approach_nm"),
                  "landing_contact_radius_nm": ("landing_contact_radius", "radius_nm"),
                  "landing_contact_radius_err_nm": ("landing_contact_radius_err", "radius_nm"),
                  "lambda_grid_nm": ("lambda_grid", "approach_nm"), "F_grid_nN": ("F_grid", "force_nN")}
#: the events' attributes in the HDF5 file and the JSON summary that the events' CSV holds
EVENT_KEYS = ("lambda", "lambda_err", "F", "F_err", "Z", "Z_err", "H0", "contact_radius", "contact_radius_err",
              "lambda_grid", "F_grid")
LANDING_KEYS = ("lambda", "lambda_err", "F", "F_err", "Z", "contact_radius", "contact_radius_err")


# -- helpers ---------------------------------------------------------------------------------------------
def read_csv(path) -> tuple[list, dict]:
    """The header (names with units) and the columns by bare name (the unit in brackets dropped)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    assert all(len(r) == len(header) for r in body), "a row of another length than the header"
    cols = {name.split(" [")[0]: [r[i] for r in body] for i, name in enumerate(header)}
    assert len(cols) == len(header), "two columns of one name"
    return header, cols


def floats(cells) -> np.ndarray:
    """Cells as doubles, an empty cell NaN."""
    return np.array([float(c) if c != "" else np.nan for c in cells], dtype=float)


def same_bits(a, b) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def text(v) -> str:
    return v.decode() if isinstance(v, bytes) else str(v)


def listing(folder) -> list:
    """Every entry of ``folder``, hidden ones (temporaries, journals) included."""
    return sorted(os.listdir(folder))


def snapshot(folder) -> dict:
    return {name: open(os.path.join(folder, name), "rb").read() for name in listing(folder)
            if os.path.isfile(os.path.join(folder, name))}


def one_line(proc, status=2) -> str:
    """The one error line of a refused or failed run (the text after the prefix)."""
    lines = proc.stderr.splitlines()
    assert proc.returncode == status and len(lines) == 1 and lines[0].startswith(PREFIX), \
        (proc.returncode, proc.stderr)
    return lines[0][len(PREFIX):]


def summary_events(summary: dict) -> list:
    """Every event of a curve's summary: folds, load extrema, equilibria, lambdas asked for, a spring's jumps."""
    out = [e for k in ("folds", "load_extrema", "equilibria", "at_lambda") for e in summary[k]]
    return out + (summary["spring"]["jumps"] if summary.get("spring") else [])


# -- the runs --------------------------------------------------------------------------------------------
RUNS = {
    # mu = 1 with error bars: folds with landings, an extremum, an equilibrium
    "plain": ("-adh_mu", "1", "-out", "c.h5", "-summary", "c.json", "-csv", "c.csv", "-csv_events", "e.csv"),
    # behind a spring: its legs (-csv), jumps with their landings (-csv_events)
    "spring": ("-adh_mu", "1", "-afm_spring", str(K), "-out", "c.h5", "-summary", "c.json", "-csv", "c.csv",
               "-csv_events", "e.csv"),
    # physical inputs, no error bars: columns in nm and nN, empty bars
    "physical": (*PHYSICAL, "-cont_error_estimate", "false", "-out", "c.h5", "-summary", "c.json", "-csv",
                 "c.csv", "-csv_events", "e.csv"),
    # a study: its table where -csv says
    "study": (*STUDY, "-out", "s.h5", "-summary", "s.json", "-csv", "s.csv"),
    # a study without -csv writes no table
    "study_no_csv": (*STUDY, "-out", "s.h5", "-cont_error_estimate", "false"),
    # a study of a swept option, its table where -csv says
    "study_option": ("-study_mu", "1", "-study_option", "cont_F_max", "-study_values", "0,0.5", *FAST,
                     "-cont_error_estimate", "false", "-out", "x.h5", "-csv", "table.csv"),
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folders = {key: tmp_path_factory.mktemp(key) for key in RUNS}
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {key: pool.submit(run_cli, *args, cwd=folders[key]) for key, args in RUNS.items()}
        procs = {key: f.result() for key, f in futures.items()}
    for key, proc in procs.items():
        assert proc.returncode == 0, (key, proc.stderr)
    return {key: folders[key] for key in RUNS}


# -- the curve -------------------------------------------------------------------------------------------
def test_curve_header_names_and_units(runs):
    assert read_csv(runs["plain"] / "c.csv")[0] == CURVE_HEADER
    assert read_csv(runs["spring"] / "c.csv")[0] == SPRING_HEADER
    assert read_csv(runs["physical"] / "c.csv")[0] == CURVE_HEADER + [
        "lambda_nm [nm]", "F_nN [nN]", "contact_radius_nm [nm]"]


@pytest.mark.parametrize("key", ["plain", "physical"])
def test_curve_equals_the_h5_curve_bit_for_bit(runs, key):
    """Every point in traced order, each number the HDF5 dataset's double, stable as 0/1."""
    _, cols = read_csv(runs[key] / "c.csv")
    with h5py.File(runs[key] / "c.h5", "r") as f:
        curve = {k: f["curve"][k][()] for k in f["curve"]}
    assert len(cols["lambda"]) == curve["lambda"].size > 10
    for k in ("lambda", "F", "contact_radius"):
        assert same_bits(floats(cols[k]), curve[k]), k
    assert cols["stable"] == ["1" if s else "0" for s in curve["stable"]]
    assert "Z" not in cols and "stable_spring" not in cols and "leg" not in cols
    assert set(cols["stable"]) == {"0", "1"}


def test_spring_legs_equal_the_h5_legs_bit_for_bit(runs):
    """Behind a spring: the approach's points then the retract's, each number the HDF5 group instrument's."""
    _, cols = read_csv(runs["spring"] / "c.csv")
    with h5py.File(runs["spring"] / "c.h5", "r") as f:
        legs = {leg: {k: f["instrument"][leg][k][()] for k in f["instrument"][leg]} for leg in ("approach", "retract")}
    n = legs["approach"]["Z"].size
    assert cols["leg"] == ["approach"] * n + ["retract"] * legs["retract"]["Z"].size and n > 10
    for k in ("Z", "separation", "deflection", "F", "lambda", "contact_radius"):
        assert same_bits(floats(cols[k]), np.r_[legs["approach"][k], legs["retract"][k]]), k
    assert cols["jump"].count("1") == 2                      # one jump a leg at mu = 1, K = 0.5


def test_spring_base_is_lambda_plus_F_over_K(runs):
    """Behind a spring of K = 0.5 its base Z = lambda + F / K, on the legs and at every jump."""
    _, cols = read_csv(runs["spring"] / "c.csv")
    lam, F, Z = floats(cols["lambda"]), floats(cols["F"]), floats(cols["Z"])
    # a landing's lambda and F are located at the jump's Z by the solver, to its tolerance (2e-12 measured)
    np.testing.assert_allclose(Z, lam + F / K, rtol=0, atol=1e-10 * np.max(np.abs(Z)))
    np.testing.assert_allclose(floats(cols["separation"]), -lam, rtol=0, atol=0)
    np.testing.assert_allclose(floats(cols["deflection"]), F / K, rtol=0, atol=0)
    _, ev = read_csv(runs["spring"] / "e.csv")
    jumps = [i for i, k in enumerate(ev["kind"]) if k in ("jump_in", "jump_off")]
    assert sorted(ev["kind"][i] for i in jumps) == ["jump_in", "jump_off"]
    for i in jumps:       # the best values too: the extrapolation is linear in the levels' values
        z = float(ev["Z"][i])
        assert abs(z - (float(ev["lambda"][i]) + float(ev["F"][i]) / K)) < 1e-12 * max(1.0, abs(z))
        landing = float(ev["landing_lambda"][i]) + float(ev["landing_F"][i]) / K   # located again: to its bar
        assert abs(landing - z) < float(ev["Z_err"][i])
        assert ev["landing_Z"][i] == ev["Z"][i]                 # a jump lands at the same Z
    others = [i for i in range(len(ev["kind"])) if i not in jumps]
    assert others and all(ev["Z"][i] == "" and ev["landing_Z"][i] == "" for i in others)


def test_physical_columns_are_the_scales_of_the_h5_file(runs):
    """lambda_nm, F_nN, contact_radius_nm: the dimensionless column times approach_nm, force_nN, radius_nm
    of the HDF5 physical group (the same product, so the same double)."""
    _, cols = read_csv(runs["physical"] / "c.csv")
    with h5py.File(runs["physical"] / "c.h5", "r") as f:
        phys = dict(f["physical"].attrs)
        curve = {k: f["curve"][k][()] for k in ("lambda", "F", "contact_radius")}
    assert phys["approach_nm"] == pytest.approx(0.4) and phys["radius_nm"] == pytest.approx(2.0)
    for name, k, scale in (("lambda_nm", "lambda", "approach_nm"), ("F_nN", "F", "force_nN"),
                           ("contact_radius_nm", "contact_radius", "radius_nm")):
        assert same_bits(floats(cols[name]), curve[k] * phys[scale]), name
    _, ev = read_csv(runs["physical"] / "e.csv")
    for name, (k, scale) in EVENT_PHYSICAL.items():         # empty where the dimensionless cell is
        assert same_bits(floats(ev[name]), floats(ev[k]) * phys[scale]), name
    assert all(c != "" for c in ev["lambda_nm"] + ev["H0_nm"])


# -- the events ------------------------------------------------------------------------------------------
def test_events_header_names_and_units(runs):
    assert read_csv(runs["plain"] / "e.csv")[0] == EVENT_HEADER
    assert read_csv(runs["spring"] / "e.csv")[0] == EVENT_HEADER
    unit = {"nm": "[nm]", "nN": "[nN]"}
    assert read_csv(runs["physical"] / "e.csv")[0] == EVENT_HEADER + [
        f"{name} {unit[name.rsplit('_', 1)[1]]}" for name in EVENT_PHYSICAL]


def _attrs(group) -> dict:
    return {k: v for k, v in group.attrs.items() if k not in ("units", "description")}


@pytest.mark.parametrize("key", ["plain", "spring", "physical"])
def test_events_equal_the_h5_events_bit_for_bit(runs, key):
    """One row per group of events/, in order: each value the attribute's double, empty where the group has
    no such attribute (no bar, no landing, no spring, no stability at a fold)."""
    _, cols = read_csv(runs[key] / "e.csv")
    with h5py.File(runs[key] / "c.h5", "r") as f:
        groups = [f["events"][name] for name in sorted(f["events"])]
        assert len(cols["kind"]) == len(groups) >= 4
        for i, g in enumerate(groups):
            a = _attrs(g)
            land = _attrs(g["landing"]) if "landing" in g else {}
            assert cols["kind"][i] == text(a["kind"])
            for k in EVENT_KEYS:
                assert cols[k][i] == "" if k not in a else same_bits(float(cols[k][i]), a[k]), (i, k)
            for k in LANDING_KEYS:
                cell = cols[f"landing_{k}"][i]
                assert cell == "" if k not in land else same_bits(float(cell), land[k]), (i, k)
            assert cols["stable"][i] == ("" if "stable" not in a else "1" if a["stable"] else "0")
            assert cols["levels"][i] == ("" if "levels" not in a else " ".join(str(int(x)) for x in a["levels"]))
    if key == "physical":                   # without error bars: none in the file, none in the table
        for k in ("lambda_err", "F_err", "contact_radius_err", "levels", "lambda_grid", "F_grid",
                  "landing_F_err", "lambda_err_nm", "F_err_nN"):
            assert set(cols[k]) == {""}, k
    else:
        assert all(c != "" for c in cols["lambda_err"]) and all(c != "" for c in cols["levels"])
    folds = [i for i, k in enumerate(cols["kind"]) if k in ("snap_on", "snap_off")]
    assert len(folds) == 2 and all(cols["landing_F"][i] != "" and cols["stable"][i] == "" for i in folds)


@pytest.mark.parametrize("key", ["plain", "spring", "physical"])
def test_events_match_the_json_summary(runs, key):
    """Every event of the summary (folds, extrema, equilibria, a spring's jumps) is one row, with its values;
    with physical inputs the nm and nN columns are the summary's physical values."""
    _, cols = read_csv(runs[key] / "e.csv")
    summary = json.loads((runs[key] / "c.json").read_text())
    events = summary_events(summary)
    assert len(events) == len(cols["kind"])
    phys = summary.get("physical")
    phys_events = summary_events(phys) if phys else [None] * len(events)
    seen = set()
    for e, pe in zip(events, phys_events):
        rows = [i for i in range(len(cols["kind"])) if cols["kind"][i] == e["kind"]
                and float(cols["lambda"][i]) == e["lambda"]]
        assert len(rows) == 1, e
        i = rows[0]
        seen.add(i)
        for k in EVENT_KEYS:
            if k in e:
                assert float(cols[k][i]) == e[k], (e["kind"], k)
        for k in LANDING_KEYS:
            if k in e.get("landing", {}):
                assert float(cols[f"landing_{k}"][i]) == e["landing"][k], (e["kind"], k)
        if "levels" in e:
            assert [int(x) for x in cols["levels"][i].split()] == e["levels"]
        if pe is not None:
            assert pe["kind"] == e["kind"]
            for name, value in pe.items():
                if name == "kind":
                    continue
                if name == "landing":
                    for sub, v in value.items():
                        if f"landing_{sub}" in cols:
                            assert float(cols[f"landing_{sub}"][i]) == v, (e["kind"], sub)
                elif name in cols:
                    assert float(cols[name][i]) == value, (e["kind"], name)
    assert seen == set(range(len(cols["kind"])))


def test_only_the_named_files(runs):
    """A curve run writes its four files and nothing else: no temporary, journal or checkpoint stays."""
    assert listing(runs["plain"]) == ["c.csv", "c.h5", "c.json", "e.csv"]


# -- a study ---------------------------------------------------------------------------------------------
def _check_table(path, h5) -> tuple[list, dict]:
    header, cols = read_csv(path)
    with h5py.File(h5, "r") as f:
        table = {k: f["table"][k][()] for k in f["table"]}
        per_case = {int(g.attrs["case"]): len(g["events"]) if "events" in g else 0 for g in f["cases"].values()}
    names = [h.split(" [")[0] for h in header]
    assert sorted(names) == sorted(table)
    for k, v in table.items():
        if k == "kind":
            assert cols[k] == [text(x) for x in v]
        elif k == "case":
            assert cols[k] == [str(int(x)) for x in v]
        else:                               # NaN in the file: an empty cell
            assert same_bits(floats(cols[k]), v), k
    cases = [int(c) for c in cols["case"]]
    assert {c: cases.count(c) for c in set(cases)} == {case: n for case, n in per_case.items() if n}
    assert cases == sorted(cases)
    return header, cols


def test_study_table(runs):
    """-csv s.csv: one row per event of each case, its columns the HDF5 table's; without -csv, no table
    (nothing is written that the run was not asked to write)."""
    assert listing(runs["study_no_csv"]) == ["s.h5"]
    assert listing(runs["study"]) == ["s.csv", "s.h5", "s.json"]
    header, cols = _check_table(runs["study"] / "s.csv", runs["study"] / "s.h5")
    assert header == ["case", "adh_mu [1]", "kind", f"lambda {EPS}", f"lambda_err {EPS}", f"F {LOAD}",
                      f"F_err {LOAD}", f"lambda_grid {EPS}", f"F_grid {LOAD}", f"Z {EPS}", f"Z_err {EPS}",
                      f"contact_radius {RAD}", f"contact_radius_err {RAD}"]
    assert sorted(set(cols["adh_mu"])) == ["0.5", "1.0"]
    assert set(cols["lambda_err"]) == {""}       # -cont_error_estimate false: no bars


def test_study_table_where_csv_says(runs):
    """-csv names the table's file; a swept option's column is named by the option."""
    assert listing(runs["study_option"]) == ["table.csv", "x.h5"]
    header, cols = _check_table(runs["study_option"] / "table.csv", runs["study_option"] / "x.h5")
    assert header[:4] == ["case", "adh_mu [1]", "cont_F_max", "kind"]
    assert sorted(set(cols["cont_F_max"])) == ["0.0", "0.5"]


# -- refusals and failures -------------------------------------------------------------------------------
EARLIER = b"earlier,table\n1,2\n"

#: refused before any work: (arguments, the files placed before (name -> bytes), how the line starts)
REFUSED = {
    "csv_is_out": ((*CURVE, "-out", "c.h5", "-csv", "c.h5"), {}, "-csv: 'c.h5' is also the file of -out"),
    "events_is_csv": ((*CURVE, "-csv", "c.csv", "-csv_events", "c.csv"), {"c.csv": EARLIER},
                      "-csv_events: 'c.csv' is also the file of -csv"),
    "csv_is_a_directory": ((*CURVE, "-csv", "d"), {}, "-csv: 'd' is a directory"),
    "csv_ends_in_a_slash": ((*CURVE, "-csv", "d/"), {}, "-csv: 'd/' names a directory"),
    "csv_unwritable": ((*CURVE, "-csv", "/proc/petsc-adhesion.csv"), {}, "-csv: cannot write"),
    "events_missing_dir": ((*CURVE, "-csv_events", "nodir/e.csv"), {}, "-csv_events: cannot write 'nodir/e.csv' "
                                                                     "(no directory"),
    "summary_missing_dir": ((*CURVE, "-csv", "c.csv", "-out", "c.h5", "-summary", "nodir/c.json"),
                            {"c.csv": EARLIER}, "-summary: cannot write"),
    "csv_is_the_heights": ((*CURVE, "-adh_roughness", "measured", "-adh_roughness_file", "h.txt", "-csv", "h.txt"),
                           {}, "-csv: 'h.txt' is an input of this run (-adh_roughness_file)"),
    "events_is_the_options_file": ((*CURVE, "-options_file", "o.opts", "-csv_events", "o.opts"),
                                   {"o.opts": b"# the run's options are on its command line\n"}, "-csv_events: 'o.opts' is an input of this run "
                                                               "(-options_file)"),
    "csv_with_lambda": ((*SOLVE, "-csv", "c.csv"), {}, "-csv: applies to a curve, not with -adh_lambda; remove it"),
    "events_with_lambda": ((*SOLVE, "-out", "c.h5", "-csv_events", "e.csv"), {},
                           "-csv_events: applies to a curve, not with -adh_lambda; remove it"),
    "study_events": ((*STUDY, "-out", "s.h5", "-csv_events", "e.csv"), {}, "-csv_events: "),
    "critical_csv": (("-study_mu", "1", "-study_compute", "critical", "-out", "k.h5", "-csv", "k.csv"), {},
                     "-csv: -study_compute critical has no table of events"),
    "study_csv_is_summary": ((*STUDY, "-summary", "s.json", "-csv", "s.json"), {},
                             "-csv: 's.json' is also the file of -summary"),
}


def _heights() -> bytes:
    z = np.random.default_rng(3).normal(size=200)
    return "".join(f"{float(v)!r}\n" for v in 0.5 * (z - z.mean()) / z.std()).encode()


@pytest.fixture(scope="module")
def refused(tmp_path_factory):
    folders, jobs = {}, {}
    for key, (args, placed, _) in REFUSED.items():
        folder = folders[key] = tmp_path_factory.mktemp(key)
        (folder / "d").mkdir()
        for name, data in {"h.txt": _heights(), "s.csv": _heights(), **placed}.items():
            (folder / name).write_bytes(data)
        jobs[key] = (args, folder)
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {k: pool.submit(run_cli, *args, cwd=folder, timeout=120) for k, (args, folder) in jobs.items()}
        procs = {k: f.result() for k, f in futures.items()}
    return folders, procs


@pytest.mark.parametrize("key", list(REFUSED))
def test_bad_targets_refused_in_one_line_nothing_written(refused, key):
    """Two outputs of one path, an output that is an input, a directory, a place no file can be made,
    -csv and -csv_events with -adh_lambda, -csv_events in a study: exit 2, one line naming the option,
    every file that was there byte for byte as it was, nothing added."""
    folders, procs = refused
    args, placed, says = REFUSED[key]
    assert one_line(procs[key]).startswith(says), procs[key].stderr
    now = snapshot(folders[key])
    assert now == {"h.txt": _heights(), "s.csv": _heights(), **placed}
    assert listing(folders[key]) == sorted(["d", "h.txt", "s.csv", *placed])
    assert not os.listdir(folders[key] / "d")


def _earlier(folder, names) -> dict:
    for name in names:
        (folder / name).write_bytes(b"earlier " + name.encode() + b"\n")
    return snapshot(folder)


def test_report_that_fails_leaves_every_earlier_file(tmp_path):
    """The report goes out before the files are put in place: a standard output that cannot take it
    (a full device) fails the run after every temporary, CSVs included, was written; none of them is
    put in place, the earlier set stays byte for byte and no temporary or journal is left."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full")
    earlier = _earlier(tmp_path, ["c.h5", "c.json", "c.csv", "e.csv"])
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "petsc_adhesion", *CURVE, "-out", "c.h5", "-summary", "c.json",
                               "-csv", "c.csv", "-csv_events", "e.csv"], cwd=tmp_path, env=_env(), stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=120)
    assert proc.returncode == 1, proc.stderr
    assert snapshot(tmp_path) == earlier and listing(tmp_path) == sorted(earlier)


def test_a_curve_that_fails_leaves_the_earlier_csv(tmp_path):
    earlier = _earlier(tmp_path, ["c.csv", "e.csv"])
    proc = run_cli(*CURVE, "-nat_snes_max_it", "1", "-csv", "c.csv", "-csv_events", "e.csv", cwd=tmp_path,
                   timeout=120)
    assert "no solution at the start" in one_line(proc, 1)
    assert snapshot(tmp_path) == earlier and listing(tmp_path) == sorted(earlier)


def test_a_study_none_of_whose_cases_ran_leaves_the_earlier_table(tmp_path):
    """The study's table is one of its set of files: no case ran, none of them is replaced."""
    earlier = _earlier(tmp_path, ["s.h5", "s.csv"])
    proc = run_cli(*STUDY, "-nat_snes_max_it", "1", "-out", "s.h5", cwd=tmp_path, timeout=120)
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.splitlines()[-1].startswith(PREFIX + "none of the 2 cases ran")
    assert snapshot(tmp_path) == earlier and listing(tmp_path) == sorted(earlier)


def test_a_later_run_replaces_the_earlier_csv_whole(tmp_path):
    """An earlier file at the -csv path is replaced by the new set (not appended to, not left)."""
    _earlier(tmp_path, ["c.csv"])
    proc = run_cli(*CURVE, "-csv", "c.csv", cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    header, cols = read_csv(tmp_path / "c.csv")
    assert header == CURVE_HEADER and len(cols["lambda"]) > 10
    assert listing(tmp_path) == ["c.csv"]
