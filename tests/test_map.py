"""Force maps (-fit_map, petsc_adhesion.fit_map; docs/maps.md): a JPK map read with its grid and each pixel
flagged with its true reason; a synthetic 3x3 map whose pixels were made with known w and E* recovered within
their bars; the same table on 1 and 2 ranks; a map killed mid-way and resumed gives the files of one never
interrupted; bad input refused in one line with nothing written, or flagged per curve."""
import csv
import math
import os
import re
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import ROOT, _env, run_cli

DATA = os.path.join(ROOT, "tests", "data")
QI = os.path.join(DATA, "fmt-jpk-fd_2020.02.07-16.29.05.036.jpk-qi-data")
R, EPS, K_SPRING = 20e-9, 0.3e-9, 1.0
TIP = ("-phys_radius", R, "-phys_epsilon", EPS, "-phys_spring", K_SPRING)


def _bodies(w, mu):
    """The bodies of a synthetic curve: work of adhesion ``w``, E* from eq. (9) at ``mu`` (on a rigid flat)."""
    from petsc_adhesion.model.physical import Bodies

    return Bodies(radius=R, young1=w * math.sqrt(R / (mu**3 * EPS**3)), poisson1=0.0, epsilon=EPS, gamma=w)


def _write(path, z, F):
    with open(path, "w") as f:
        f.write("z (m), F (N)\n")
        f.writelines(f"{a!r}, {b!r}\n" for a, b in zip(z, F))


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A folder of four curve files: two made by the solver with noise (w 0.04 and 0.06 J/m^2, mu 0.1 and
    0.15), one without adhesion (the first's approach without its attraction, its retract the approach run
    back), one that is no curve."""
    from petsc_adhesion.fitting.results import Spring
    from petsc_adhesion.fitting.synthetic import Sampling, synthetic_curve

    d = tmp_path_factory.mktemp("map")
    for i, (w, mu) in enumerate([(0.04, 0.1), (0.06, 0.15)]):
        c = synthetic_curve(_bodies(w, mu), Spring(K_SPRING),
                            Sampling(noise=0.01 * 2 * math.pi * R * 0.05, points=60, z0=5e-9, seed=20 + i))
        _write(d / f"c{i}.csv", c.z, c.F)
        if i == 0:
            a = np.maximum(c.F[: c.turn], 0.0)         # no attraction, the same force both ways: no pull-off
            _write(d / "c2.csv", c.z, np.r_[a, a[::-1]])
    (d / "c3.csv").write_text("z (m), F (N)\nnot, numbers\n")
    return d


def _text(path, text):
    """``path`` with ``text`` written in it."""
    path.write_text(text)
    return path


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# -- the JPK map ------------------------------------------------------------------------------------------------
def test_a_jpk_map_gives_its_grid_and_positions():
    """The QI file's four curves on its 128 x 128 grid of 10 um: the pixel each states, and the position of
    each pixel's centre made from the grid (its origin plus the index times the pixel size) equal to the
    position the file states for the curve (to 1e-12 m)."""
    from petsc_adhesion.maps.source import open_map

    m = open_map(QI)
    assert m.kind == "afm" and m.grid.shape == (128, 128) and len(m) == 4
    assert m.grid.size == pytest.approx((10e-6, 10e-6), rel=1e-12)
    assert [(e.ix, e.iy) for e in m.entries] == [(0, 0), (1, 0), (2, 0), (3, 0)]
    px, py = m.grid.pixel
    for e in m.entries:
        assert abs(m.grid.origin[0] + e.ix * px - e.x) < 1e-12 and abs(m.grid.origin[1] + e.iy * py - e.y) < 1e-12


def test_a_jpk_map_fitted_flags_each_pixel_with_its_reason(tmp_path):
    """The QI map's curves (a compliant sample, a 20 nm tip assumed): each indents the tip by more than R/4 and
    holds on far behind the contact (tethers): every pixel 'outside' the model's domain, with those reasons,
    no w or E* a number; the pull-off and the energy of a cycle, what a curve shows by itself, with bars; the
    exit status 3; the map's figure drawn by the plot command."""
    out, table = tmp_path / "qi.h5", tmp_path / "qi.csv"
    p = run_cli("-fit_map", QI, "-phys_radius", R, "-phys_epsilon", EPS, "-out", out, "-csv", table)
    assert p.returncode == 3, p.stderr
    rows = _rows(table)
    assert [r["status"] for r in rows] == ["outside"] * 4
    for r in rows:
        assert "indentation reaches" in r["reasons"] and "tether" in r["reasons"]
        assert r["gamma_J_m2"] == r["E_star_Pa"] == ""
        # what the curve shows by itself and does not have is said, beside the fit's reasons
        assert r["jump_in_N"] == "" and r["missing"] == "jump_in: the approach does not jump by more than 10 noise"
        assert 1e-11 < float(r["pull_off_N"]) < 1e-8 and 0 < float(r["pull_off_err"]) < float(r["pull_off_N"])
        assert float(r["energy_J"]) > 10 * float(r["energy_err"]) > 0
    with h5py.File(out) as f:
        assert f.attrs["kind"] == "map" and f.attrs["n_outside"] == 4
        assert f["images/gamma"].shape == (128, 128) and np.isnan(f["images/gamma"][()]).all()
        assert np.isfinite(f["images/pull_off"][()]).sum() == 4
    fig = tmp_path / "qi.png"
    p = subprocess.run([sys.executable, "-m", "petsc_adhesion", "plot", str(out), "-o", str(fig)], env=_env(),
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert fig.stat().st_size > 10_000


# -- Asylum and AFM Workshop folders ------------------------------------------------------------------------------
SIN = os.path.join(DATA, "fmt-igor-fd_SiN_FD_plot.ibw")
WORKSHOP = os.path.join(DATA, "fmt-afm-workshop-fd_mapping_16_2018-08-01_13.07.zip")


def _note_set(data: bytes, key: str, value: str) -> bytes:
    """An Igor wave with the note's ``key: value`` written anew, in place (the value right-aligned in the old
    one's width: the note's size, and so the file's layout, unchanged)."""
    m = re.search(b"\r" + key.encode() + b":([^\r]*)", data)
    old = m.group(1)
    assert len(value) <= len(old), (key, old, value)
    return data[:m.start(1)] + value.encode().rjust(len(old)) + data[m.end(1):]


def _asylum_map(folder, nx, ny, skip=(), base="Map", lines=False):
    """The MFP-3D curve of tests/data copied as an Asylum force map of ``nx`` x ``ny`` would save it: named
    ``<base>LineLLLLPointPPPP.ibw`` (in ``FMLineLLLL/`` subfolders with ``lines``), its note stating the grid
    (FMapScanPoints ``nx``, FMapScanLines ``ny``) and each copy's place as its sensors read it
    (XLVDT, YLVDT: the pixel's centre on the note's 1 um scan about its XOffset, YOffset, the slow scan
    running down as the note's FMapScanDown 1 says: line 0 the top).  ``skip``: the (point, line) not
    written.  Returns {(point, line): (x, y)} of the copies written."""
    src = open(SIN, "rb").read()
    src = _note_set(_note_set(src, "FMapScanPoints", str(nx)), "FMapScanLines", str(ny))
    x0, y0, size = -3.2718e-05, 2.6456e-05, 1e-6          # the note's XOffset, YOffset, FastScanSize
    placed = {}
    for line in range(ny):
        for point in range(nx):
            if (point, line) in skip:
                continue
            x = x0 - size / 2 + (point + 0.5) * size / nx
            y = y0 + size / 2 - (line + 0.5) * size / ny           # scanned down: line 0 at the top
            data = _note_set(_note_set(src, "XLVDT", f"{x:.14e}"), "YLVDT", f"{y:.14e}")
            where = folder / f"FMLine{line:04d}" if lines else folder
            where.mkdir(parents=True, exist_ok=True)
            (where / f"{base}Line{line:04d}Point{point:04d}.ibw").write_bytes(data)
            placed[point, line] = (float(f"{x:.14e}"), float(f"{y:.14e}"))
    return placed


def test_an_igor_note_read_alone_is_the_note_igor2_reads():
    """The note of the Asylum curve, read from its header and note alone (the map's folder is read at once),
    equals the note igor2 reads with the whole wave, key by key."""
    from igor2 import binarywave

    from petsc_adhesion.maps.folders import ibw_note

    want = {}
    for line in binarywave.load(SIN)["wave"]["note"].decode("latin-1").split("\r"):
        if ":" in line:
            k, v = line.split(":", 1)
            want.setdefault(k.strip(), v.strip())
    got = ibw_note(SIN)
    assert got == want and got["FMapScanPoints"] == "32" and float(got["XLVDT"]) == -3.46937223456067e-05


@pytest.mark.parametrize("lines", [False, True])
def test_an_asylum_folder_gives_its_grid_and_positions(tmp_path, lines):
    """Five curves of an Asylum map of 3 x 2 (one missing), in the folder or a subfolder a line: the grid the
    notes state (3 x 2 over 1 um, about the note's offsets), each curve at the pixel its name gives (line 0 at
    the top: the scan ran down) and at the position its note states (to 1e-12 m), that position the centre of
    its pixel on the grid read; the missing pixel an entry whose curve is read as missing, with why.  Given,
    the same shape is taken; another, refused."""
    from petsc_adhesion.fitting.data import CurveFileError
    from petsc_adhesion.maps.source import ShapeError, open_map

    placed = _asylum_map(tmp_path, 3, 2, skip={(2, 1)}, lines=lines)
    m = open_map(str(tmp_path))
    assert m.grid.shape == (3, 2) and len(m) == 6 and len(m.files) == 5
    assert m.grid.size == pytest.approx((1e-6, 1e-6), rel=1e-12)
    px, py = m.grid.pixel
    for e in m.entries:
        line, point = (int(v) for v in re.fullmatch(r"MapLine(\d{4})Point(\d{4})\.ibw", e.label).groups())
        assert (e.ix, e.iy) == (point, 1 - line)
        if (point, line) not in placed:
            assert e.x is None and e.y is None
            with pytest.raises(CurveFileError, match="missing: the Asylum map's grid of 3 x 2 has pixel"):
                m.curve(e)
            continue
        assert abs(e.x - placed[point, line][0]) < 1e-12 and abs(e.y - placed[point, line][1]) < 1e-12
        assert abs(m.grid.origin[0] + e.ix * px - e.x) < 1e-12 and abs(m.grid.origin[1] + e.iy * py - e.y) < 1e-12
        assert m.curve(e).spring == pytest.approx(1.1841)
    assert open_map(str(tmp_path), (3, 2)).grid.shape == (3, 2)
    with pytest.raises(ShapeError, match=r"its Asylum curves state a grid of 3 x 2 \(their notes' FMapScanPoints, "
                                         r"FMapScanLines\); the shape 6 x 1 disagrees: leave it out$"):
        open_map(str(tmp_path), (6, 1))


def test_a_folder_of_two_instruments_two_maps_or_two_grids_is_refused(tmp_path):
    """Refused in one line each, naming what is mixed: Asylum curves beside an AFM Workshop curve; the curves of
    two Asylum maps (two bases); of two grids (a note of 4 points a line among those of 2); a curve named
    beyond the note's grid; an Asylum curve without a line and a point in its name among named ones; an ARDF
    file, alone or as the map (what to do said)."""
    import zipfile

    from petsc_adhesion.maps.source import MapSourceError, open_map

    def refused(folder, what):
        with pytest.raises(MapSourceError, match=what) as e:
            open_map(str(folder))
        assert "\n" not in str(e.value)

    a = tmp_path / "a"
    _asylum_map(a, 2, 1)
    with zipfile.ZipFile(WORKSHOP) as z:
        (a / "ws.csv").write_bytes(z.read(z.namelist()[0]))
    refused(a, r"more than one instrument \(Asylum 2 .*AFM Workshop 1")
    b = tmp_path / "b"
    _asylum_map(b, 2, 1)
    _asylum_map(b, 2, 1, base="Other")
    refused(b, "two Asylum maps")
    c = tmp_path / "c"
    _asylum_map(c, 2, 1)
    (c / "MapLine0000Point0001.ibw").write_bytes(_note_set((c / "MapLine0000Point0001.ibw").read_bytes(),
                                                           "FMapScanPoints", "4"))
    refused(c, "two grids: 'MapLine0000Point0000.ibw' states FMapScanPoints 2, 'MapLine0000Point0001.ibw' 4")
    d = tmp_path / "d"
    _asylum_map(d, 2, 1)
    (d / "MapLine0003Point0000.ibw").write_bytes((d / "MapLine0000Point0000.ibw").read_bytes())
    refused(d, "at point 0 of line 3, beyond the grid of 2 x 1")
    e = tmp_path / "e"
    _asylum_map(e, 2, 1)
    (e / "lone.ibw").write_bytes(open(SIN, "rb").read())
    refused(e, "'lone.ibw' is no curve of an Asylum map")
    f = tmp_path / "f"
    f.mkdir()
    (f / "map0001.ARDF").write_bytes(b"ARDF")
    refused(f, "export its curves as .ibw from the Asylum software")
    with pytest.raises(MapSourceError, match="ARDF force map, which afmformats does not read: export"):
        open_map(str(f / "map0001.ARDF"))


def test_the_instruments_refusals_at_the_command_line_write_nothing(tmp_path):
    """Through -fit_map: an ARDF file, a folder of two instruments, an Asylum folder with another
    -fit_map_shape: one line each naming -fit_map and what is wrong, exit 2; the earlier -out untouched."""
    import zipfile

    out = tmp_path / "m.h5"
    out.write_bytes(b"an earlier result")
    ardf = tmp_path / "map0001.ARDF"
    ardf.write_bytes(b"ARDF")
    tip = ("-phys_radius", R, "-phys_epsilon", EPS, "-out", out)
    assert "export its curves as .ibw" in _refused(run_cli("-fit_map", ardf, *tip), "fit_map")
    mixed = tmp_path / "mixed"
    _asylum_map(mixed, 2, 1)
    with zipfile.ZipFile(WORKSHOP) as z:
        (mixed / "ws.csv").write_bytes(z.read(z.namelist()[0]))
    assert "more than one instrument" in _refused(run_cli("-fit_map", mixed, *tip), "fit_map")
    (mixed / "ws.csv").unlink()
    assert "'mixed': its Asylum curves state a grid of 2 x 1 (their notes' FMapScanPoints, FMapScanLines); the " \
        "shape 1 x 2 disagrees: leave it out" in _refused(run_cli("-fit_map", mixed, *tip, "-fit_map_shape", "1,2"),
                                                          "fit_map_shape")
    assert out.read_bytes() == b"an earlier result" and not os.path.exists(str(out) + ".journal")


def test_an_afm_workshop_folder_gives_the_grid_afmformats_gives(tmp_path):
    """AFM Workshop's map (tests/data, 16 curves of Mode: Mapping in a zip) unzipped into a folder: its grid
    and each curve's pixel and position equal those afmformats makes of the zip (its grid index, shape,
    size, centre; the positions to 1e-12 m); a curve taken out leaves its pixel, read as missing; a single
    curve among them refused; -fit_map_shape other than the positions' grid refused."""
    import zipfile

    import afmformats

    from petsc_adhesion.fitting.data import CurveFileError
    from petsc_adhesion.maps.source import MapSourceError, ShapeError, open_map

    with zipfile.ZipFile(WORKSHOP) as z:
        z.extractall(tmp_path)
    truth = [d.metadata for d in afmformats.load_data(WORKSHOP, meta_override={"spring constant": 1.0,
                                                                                "sensitivity": 1e-8})]
    m = open_map(str(tmp_path))
    assert m.grid.shape == (truth[0]["grid shape x"], truth[0]["grid shape y"]) == (4, 4)
    assert m.grid.size == pytest.approx((truth[0]["grid size x"], truth[0]["grid size y"]), rel=1e-12)
    assert m.grid.origin[0] + m.grid.size[0] / 2 - m.grid.pixel[0] / 2 == pytest.approx(truth[0]["grid center x"],
                                                                                        abs=1e-12)
    assert m.grid.origin[1] + m.grid.size[1] / 2 - m.grid.pixel[1] / 2 == pytest.approx(truth[0]["grid center y"],
                                                                                        abs=1e-12)
    for e, t in zip(m.entries, truth):
        assert (e.ix, e.iy) == (t["grid index x"], t["grid index y"])
        assert abs(e.x - t["position x"]) < 1e-12 and abs(e.y - t["position y"]) < 1e-12
    gone = sorted(tmp_path.iterdir())[6]
    gone.unlink()
    m = open_map(str(tmp_path))
    assert len(m) == 16 and len(m.files) == 15 and m.entries[6].x is None
    with pytest.raises(CurveFileError, match=r"missing: the AFM Workshop map's grid of 4 x 4 has pixel \(2, 1\)"):
        m.curve(m.entries[6])
    with pytest.raises(ShapeError, match=r"its AFM Workshop curves state a grid of 4 x 4 \(their positions X, um "
                                         r"and Y, um\); the shape 2 x 8 disagrees: leave it out$"):
        open_map(str(tmp_path), (2, 8))
    # a curve in volts: its force the file's T-B (V) times the sensitivity and the spring constant given
    first = sorted(tmp_path.iterdir())[0]
    c = m.curve(m.entries[0], spring=20.0, invols=1e-8)
    volts = np.loadtxt(first, skiprows=11, delimiter=",")
    assert c.F == pytest.approx(np.r_[volts[:, 1], volts[:, 3]] * 1e-8 * 20.0, rel=1e-14, abs=0)
    assert (c.spring, c.sensitivity) == (20, 1e-8)
    single = open(first).read().replace("Mode:\tMapping", "Mode:\tSingle")
    (tmp_path / "z_single.csv").write_text(single)
    with pytest.raises(MapSourceError, match="'z_single.csv' is no curve of a map"):
        open_map(str(tmp_path))


def test_an_afm_workshop_zip_in_volts_is_read_with_its_calibration(tmp_path):
    """AFM Workshop's zipped map in volts read by open_map: each curve's force the member's T-B (V) columns
    times the sensitivity and the spring constant given (to round-off, against the member's numbers read
    here); a copy whose headers state a calibration (Light Lever Gain 50 mV/nm, so 2e-8 m/V; Force Constant
    0.5 nN/nm) is read with it and needs neither; without either where it states none, NeedsInstrument
    naming the option."""
    import zipfile

    from petsc_adhesion.fitting.data import NeedsInstrument
    from petsc_adhesion.maps.source import MapSourceError, open_map

    with zipfile.ZipFile(WORKSHOP) as z:
        members = {n: z.read(n).decode() for n in sorted(z.namelist())}
    volts = [np.loadtxt(text.splitlines()[11:], delimiter=",") for text in members.values()]

    def force(c, v, factor):
        assert c.F == pytest.approx(np.r_[v[:, 1], v[:, 3]] * factor, rel=1e-13, abs=0)

    m = open_map(WORKSHOP, spring=20.0, invols=1e-8)
    assert m.kind == "afm" and len(m) == 16 and m.grid.shape == (4, 4)
    for e, v in zip(m.entries, volts):
        c = m.curve(e, 20.0, 1e-8)
        force(c, v, 1e-8 * 20.0)
        assert (c.spring, c.sensitivity) == (20.0, 1e-8)
    for given, option in (({}, "fit_invols"), ({"invols": 1e-8}, "phys_spring")):
        with pytest.raises(NeedsInstrument) as e:
            open_map(WORKSHOP, **given)
        assert e.value.option == option and not e.value.given and "\n" not in str(e.value)
    stated = tmp_path / "stated.zip"
    with zipfile.ZipFile(stated, "w") as z:
        for name, text in members.items():
            z.writestr(name, text.replace("Y, um:", "Light Lever Gain, mV/nm:\t50\nForce Constant, nN/nm:\t0.5\nY, um:"))
    m = open_map(str(stated))
    for e, v in zip(m.entries, volts):
        force(m.curve(e), v, 2e-8 * 0.5)
    cut = tmp_path / "cut.zip"             # a zip cut short: its header unread, the source refused, not a crash
    cut.write_bytes(open(WORKSHOP, "rb").read()[:3000])
    with pytest.raises(MapSourceError, match=r"^'cut\.zip': not a force-distance curve afmformats reads \(File is "
                                             r"not a zip file\)$"):
        open_map(str(cut), spring=20.0, invols=1e-8)


def test_the_real_asylum_and_afm_workshop_maps_fitted_flag_each_pixel(tmp_path):
    """The Asylum map of 2 x 2 made of the MFP-3D curve (one pixel's file missing) and AFM Workshop's map
    (4 x 4) through -fit_map with a 20 nm tip assumed: each curve that is read indents the tip beyond R/4
    (the MFP-3D curve by 14.5 nm, 0.72 R, as -fit_curve says of it, docs/fitting.md): 'outside' with that
    reason and no w; the missing pixel 'unreadable', missing; exit status 3.  AFM Workshop's curves are in
    volts: without -fit_invols the map is refused in one line naming it, nothing written; with afmformats'
    own test calibration (10 nm/V, 20 N/m) every pixel is read, at its position, and outside; the zip given
    as it is, the same pixels with the same numbers (afmformats' map reader calibrated by the options)."""
    import zipfile

    asylum = tmp_path / "asylum"
    _asylum_map(asylum, 2, 2, skip={(1, 1)})
    table = tmp_path / "asylum.csv"
    p = run_cli("-fit_map", asylum, "-phys_radius", R, "-phys_epsilon", EPS, "-csv", table)
    assert p.returncode == 3, p.stderr
    rows = {(r["ix"], r["iy"]): r for r in _rows(table)}
    assert len(rows) == 4 and rows["1", "0"]["status"] == "unreadable"
    assert "missing" in rows["1", "0"]["reasons"] and rows["1", "0"]["x_m"] == ""
    for key in [("0", "1"), ("1", "1"), ("0", "0")]:
        r = rows[key]
        assert r["status"] == "outside" and "indentation reaches 14.5 nm, 0.72 of the tip's radius" in r["reasons"]
        assert r["gamma_J_m2"] == r["E_star_Pa"] == "" and float(r["pull_off_N"]) == pytest.approx(12.84e-9, rel=1e-3)
    ws = tmp_path / "ws"
    with zipfile.ZipFile(WORKSHOP) as z:
        z.extractall(ws)
    table = tmp_path / "ws.csv"
    _refused(run_cli("-fit_map", ws, "-phys_radius", R, "-phys_epsilon", EPS, "-csv", table), "fit_invols")
    assert not table.exists()
    p = run_cli("-fit_map", ws, "-phys_radius", R, "-phys_epsilon", EPS, "-fit_invols", 1e-8, "-phys_spring", 20,
                "-csv", table)
    assert p.returncode == 3, p.stderr
    rows = _rows(table)
    assert len(rows) == 16 and {r["status"] for r in rows} == {"outside"}
    assert all("indentation reaches" in r["reasons"] and r["gamma_J_m2"] == "" for r in rows)
    assert float(rows[5]["x_m"]) == pytest.approx(7.333333333333333e-6, abs=1e-12)
    # the zip itself, through afmformats' map reader calibrated as the folder: refused without -fit_invols and
    # then without -phys_spring (one line each naming it, nothing written); with both, every pixel the folder's
    zipped = tmp_path / "zipped.csv"
    assert "'fmt-afm-workshop-fd_mapping_16_2018-08-01_13.07.zip': its deflection is in volts (AFM Workshop's " \
        "T-B(V)) and it states no sensitivity: give it in m/V" in \
        _refused(run_cli("-fit_map", WORKSHOP, "-phys_radius", R, "-phys_epsilon", EPS, "-csv", zipped), "fit_invols")
    assert "states no spring constant: give it in N/m" in \
        _refused(run_cli("-fit_map", WORKSHOP, "-phys_radius", R, "-phys_epsilon", EPS, "-fit_invols", 1e-8, "-csv",
                         zipped), "phys_spring")
    assert not zipped.exists()
    p = run_cli("-fit_map", WORKSHOP, "-phys_radius", R, "-phys_epsilon", EPS, "-fit_invols", 1e-8, "-phys_spring",
                20, "-csv", zipped)
    assert p.returncode == 3, p.stderr
    by_pixel = {(r["ix"], r["iy"]): r for r in rows}
    for r in _rows(zipped):
        f = by_pixel[r["ix"], r["iy"]]
        assert r["status"] == "outside" and r["reasons"] == f["reasons"], (r, f)
        for q in ("x_m", "y_m", "pull_off_N", "jump_in_N", "energy_J"):
            assert float(r[q]) == pytest.approx(float(f[q]), rel=1e-12, abs=1e-18), (q, r, f)


# -- what a curve shows by itself -----------------------------------------------------------------------------
def test_the_energy_of_a_rectangular_cycle_is_its_area():
    """A cycle whose approach carries no force and whose retract holds -P over the whole travel L dissipates
    P L (the trapezoidal rule is exact on it: its bar covers it), and its pull-off is P."""
    from petsc_adhesion.fitting.data import MeasuredCurve
    from petsc_adhesion.maps.result import measured_quantities

    L, P, n = 50e-9, 2e-9, 200
    z = np.r_[np.linspace(0, L, n), np.linspace(L, 0, n)]
    F = np.r_[np.zeros(n), np.full(n, -P)]
    q = measured_quantities(MeasuredCurve(z=z, F=F, turn=n, direction=1))
    assert q.energy.value == pytest.approx(P * L, rel=1e-12) and q.energy.covers(P * L)
    assert q.pull_off.value == pytest.approx(P, rel=1e-12)
    # the same cycle measured with z falling towards the surface: the same energy
    q = measured_quantities(MeasuredCurve(z=-z, F=F, turn=n, direction=-1))
    assert q.energy.value == pytest.approx(P * L, rel=1e-12)


# -- a synthetic map --------------------------------------------------------------------------------------------
def test_a_synthetic_3x3_map_recovers_each_pixels_w_and_E():
    """Nine curves made by the solver with 1% noise, w 0.04, 0.05, 0.06 J/m^2 across and mu 0.1, 0.15, 0.2
    down (E* from eq. 9), fitted from one start (E* 30 GPa) through the Python API: every pixel's fit holds,
    and its w and E* cover their truth within 1.96 bars."""
    import petsc_adhesion as pa
    from petsc_adhesion.fitting.synthetic import Sampling
    from petsc_adhesion.maps.synthetic import synthetic_map

    W, MU = (0.04, 0.05, 0.06), (0.1, 0.15, 0.2)
    m = synthetic_map((3, 3), lambda ix, iy: _bodies(W[ix], MU[iy]), pa.Spring(K_SPRING),
                      Sampling(noise=0.01 * 2 * math.pi * R * 0.05, points=100, z0=5e-9))
    r = pa.fit_map(m, pa.Bodies(radius=R, young1=30e9, poisson1=0.0, epsilon=EPS), pa.Spring(K_SPRING))
    assert isinstance(r, pa.MapResult) and r.grid.shape == (3, 3) and r.trustworthy
    for p in r.pixels:
        truth = _bodies(W[p.entry.ix], MU[p.entry.iy])
        assert p.gamma.covers(truth.gamma, 1.96) and p.E_star.covers(truth.E, 1.96), (p.entry, p.gamma, p.E_star)
        assert p.gamma.relative < 0.05 and p.E_star.relative < 0.3     # the bars say something
    img = r.image("gamma")
    assert img.shape == (3, 3) and np.all(np.abs(img / np.array(W)[None, :] - 1) < 0.1)


# -- ranks, the journal ----------------------------------------------------------------------------------------
#: Two evaluations of each fit from a start of 30 GPa: the cap reached (warned), cheap, and the same each time.
FAST = ("-fit_max_evals", 2, "-fit_map_shape", "2,2", "-phys_young1", 30e9, "-phys_poisson1", 0.0)


def _map(folder, out, *extra, np=1):
    return run_cli("-fit_map", folder, *TIP, *FAST, "-out", out, "-csv", str(out) + ".csv", *extra, np=np)


@pytest.fixture(scope="module")
def whole(folder, tmp_path_factory):
    """The folder's map on one rank, never interrupted: its HDF5 file."""
    out = tmp_path_factory.mktemp("whole") / "one.h5"
    p = _map(folder, out)
    assert p.returncode == 3, p.stderr
    return out


def _pixels(path):
    with h5py.File(path) as f:
        return {k: v[()] for k, v in f["pixels"].items()}, {k: v[()] for k, v in f["images"].items()}


def _same(a, b):
    for (x, y) in zip(a, b):
        assert x.keys() == y.keys()
        for k in x:
            assert np.array_equal(x[k], y[k], equal_nan=x[k].dtype.kind == "f"), k


def test_one_and_two_ranks_give_the_same_map(folder, whole, tmp_path):
    """The four curves on one rank and dealt to two: the same table, the same HDF5 pixels and images, to the
    last bit; each curve flagged as it should be (the one without adhesion refused, the one that is no curve
    unreadable, the two made by the solver stopped at the cap of two evaluations: warned, their numbers
    kept)."""
    two = tmp_path / "two.h5"
    p2 = _map(folder, two, np=2)
    assert p2.returncode == 3, p2.stderr
    assert open(str(whole) + ".csv").read() == open(str(two) + ".csv").read()
    _same(_pixels(whole), _pixels(two))
    rows = _rows(str(whole) + ".csv")
    assert [r["status"] for r in rows] == ["warned", "warned", "refused", "unreadable"]
    assert "cap of 2 evaluations" in rows[0]["reasons"]
    assert "no adhesion" in rows[2]["reasons"] and "c3.csv" in rows[3]["reasons"]
    assert all(r["gamma_J_m2"] != "" for r in rows[:2]) and rows[2]["gamma_J_m2"] == rows[3]["gamma_J_m2"] == ""
    with h5py.File(two) as f:
        assert f.attrs["ranks"] == 2 and f.attrs["n_warned"] == 2
    assert not os.path.exists(str(whole) + ".journal")


def test_a_killed_map_resumes_to_the_same_files(folder, whole, tmp_path):
    """A map killed (SIGKILL) once its journal holds a pixel: no output written, the journal kept; run again
    (with progress lines: the rate, the time left), it takes that up and fits the rest, and its table and HDF5
    pixels are those of the map never interrupted; the journal is gone after."""
    out = tmp_path / "cut.h5"
    journal = str(out) + ".journal"
    cmd = [sys.executable, "-m", "petsc_adhesion", "-fit_map", str(folder), *map(str, TIP), *map(str, FAST),
           "-out", str(out), "-csv", str(out) + ".csv"]
    proc = subprocess.Popen(cmd, cwd=ROOT, env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        t0 = time.time()
        while time.time() - t0 < 300:
            if os.path.exists(journal) and open(journal).read().count("\n") >= 2:     # its header and a pixel
                break
            if proc.poll() is not None:
                pytest.fail("the map ended before it was killed")
            time.sleep(0.02)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    assert not out.exists() and os.path.exists(journal)
    kept = open(journal).read().count("\n") - 1
    assert 1 <= kept < 4
    p = _map(folder, out, "-progress", "true", "-progress_interval", 1e-6)   # progress lines: the same map
    assert p.returncode == 3, p.stderr
    assert f"{kept} of 4 curves taken up from the journal" in p.stdout
    assert f"map: 4 of 4 curves ({kept} from the journal), " in p.stderr and " curves/s, " in p.stderr
    assert open(str(out) + ".csv").read() == open(str(whole) + ".csv").read()
    _same(_pixels(out), _pixels(whole))
    with h5py.File(out) as f:
        assert f.attrs["resumed"] == kept
    assert not os.path.exists(journal)


# -- bad input ---------------------------------------------------------------------------------------------------
def _refused(p, option):
    """The one line of a refusal (exit 2) that names ``option`` first, as the option at fault."""
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"petsc-adhesion: error: -{option}: "), p.stderr
    return lines[0]


def test_refusals_write_nothing_and_keep_an_earlier_result(folder, tmp_path):
    """Each refusal one line naming the option, exit 2; the earlier -out untouched, no journal made."""
    out = tmp_path / "m.h5"
    out.write_bytes(b"an earlier result")
    base = ("-fit_map", folder, *TIP, "-out", out)
    _refused(run_cli("-fit_map", folder, *TIP), "out")                                 # nowhere to write
    _refused(run_cli("-fit_map", tmp_path / "nonesuch", *TIP, "-out", out), "fit_map")
    assert "4 curves do not fit the shape 1 x 1: expected nx, ny with nx ny at least 4" in \
        _refused(run_cli(*base, "-fit_map_shape", "1,1"), "fit_map_shape")
    _refused(run_cli(*base, "-fit_map_shape", "2.5,3"), "fit_map_shape")
    _refused(run_cli(*base, "-fit_curve", folder / "c0.csv"), "fit_curve")
    _refused(run_cli(*base, "-summary", tmp_path / "s.json"), "summary")
    _refused(run_cli(*base, "-fit_curve_index", 2), "fit_curve_index")
    _refused(run_cli("-fit_curve", folder / "c0.csv", *TIP, "-fit_map_shape", "2,3"), "fit_map_shape")
    assert "a map file states its own grid; a shape is for a folder or a list: leave it out" in \
        _refused(run_cli("-fit_map", QI, "-phys_radius", R, "-phys_epsilon", EPS, "-out", out, "-fit_map_shape",
                         "2,2"), "fit_map_shape")
    placed = tmp_path / "placed.list"           # a list whose lines place the pixels: no shape to give
    placed.write_text(f"{folder / 'c0.csv'} 0 0\n{folder / 'c1.csv'} 1 0\n")
    assert "its lines place the pixels; a shape is for a list without them: leave it out" in \
        _refused(run_cli("-fit_map", placed, *TIP, "-out", out, "-fit_map_shape", "2,1"), "fit_map_shape")
    assert "two lines name the same pixel" in \
        _refused(run_cli("-fit_map", _text(tmp_path / "twice.list", f"{folder / 'c0.csv'} 0 0\n"
                                            f"{folder / 'c1.csv'} 0 0\n"), *TIP, "-out", out), "fit_map")
    _refused(run_cli("-fit_map", os.path.join(DATA, "NOTICE"), *TIP, "-out", out), "fit_map")     # no map
    os.mkfifo(tmp_path / "fifo")
    assert "is a FIFO" in _refused(run_cli("-fit_map", tmp_path / "fifo", *TIP, "-out", out), "fit_map")
    assert out.read_bytes() == b"an earlier result"
    assert not os.path.exists(str(out) + ".journal")


def test_volts_without_a_sensitivity_and_a_journal_of_another_map(folder, tmp_path):
    """A folder of curves in volts without -fit_invols: one line naming -fit_invols.  A journal left by a map
    of other options: one line, the earlier result and the journal untouched."""
    volts = tmp_path / "volts"
    volts.mkdir()
    z = np.r_[np.linspace(0, 1e-7, 30), np.linspace(1e-7, 0, 30)]
    with open(volts / "v.csv", "w") as f:
        f.write("z (m), deflection (V)\n")
        f.writelines(f"{a!r}, {0.01 * i!r}\n" for i, a in enumerate(z))
    out = tmp_path / "v.h5"
    _refused(run_cli("-fit_map", volts, *TIP, "-out", out), "fit_invols")
    assert not out.exists()
    out.write_bytes(b"earlier")
    journal = str(out) + ".journal"
    with open(journal, "w") as f:
        f.write('{"journal": "petsc-adhesion map journal", "format": 1, "fingerprint": "another"}\n')
    before = open(journal).read()
    line = _refused(run_cli("-fit_map", folder, *TIP, "-out", out), "out")
    assert line.endswith(": -out: the journal beside it, 'v.h5.journal' is the journal of another map (other "
                         "source or options); remove it to fit this one from the start"), line
    assert out.read_bytes() == b"earlier" and open(journal).read() == before
    # without -out the journal stands beside -csv; one that is no journal at all is named as such
    table = tmp_path / "v.csv"
    _text(tmp_path / "v.csv.journal", "not a journal\n")
    line = _refused(run_cli("-fit_map", folder, *TIP, "-csv", table), "csv")
    assert line.endswith("the journal beside it, 'v.csv.journal' is not a map's journal; move it away"), line
    assert not table.exists() and open(str(table) + ".journal").read() == "not a journal\n"


def test_a_sensitivity_for_curves_in_newtons_is_refused_as_given(tmp_path):
    """AFM Workshop's map with its columns in nN (a force, no sensitivity stated) given -fit_invols: one line that
    names -fit_invols as given and to be removed (not 'required'), exit 2, nothing written; so for -fit_curve on
    one of its curves."""
    import zipfile

    ws = tmp_path / "ws"
    ws.mkdir()
    with zipfile.ZipFile(WORKSHOP) as z:
        for name in z.namelist():
            (ws / name).write_text(z.read(name).decode().replace("T-B(V)", "Force(nN)"))
    table = tmp_path / "ws.csv"
    tip = ("-phys_radius", R, "-phys_epsilon", EPS, "-fit_invols", 1e-8, "-phys_spring", 20)
    says = "gives a force, not a deflection in volts, and states no sensitivity (m/V) for the one given to " \
        "replace; remove it"
    assert _refused(run_cli("-fit_map", ws, *tip, "-csv", table), "fit_invols").endswith(says)
    first = sorted(ws.iterdir())[0]
    assert _refused(run_cli("-fit_curve", first, *tip, "-summary", tmp_path / "f.json"), "fit_invols").endswith(says)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ws"]


def test_a_list_with_a_missing_file_and_a_curve_without_retract_flags_them(folder, tmp_path):
    """A list file placing its curves on the grid: a path that does not exist and a curve whose displacement
    never turns back (no retract) are pixels flagged unreadable with their reasons; the map goes on."""
    z = np.linspace(0, 1e-7, 40)
    _write(tmp_path / "oneway.csv", z, np.linspace(0, 1e-9, 40))
    lst = tmp_path / "m.list"
    lst.write_text(f"# path ix iy\n{folder / 'c2.csv'} 0 0\nnonesuch.csv 1 0\noneway.csv 0 1\n")
    out = tmp_path / "l.csv"
    p = run_cli("-fit_map", lst, *TIP, "-csv", out)
    assert p.returncode == 3, p.stderr
    rows = _rows(out)
    assert [(r["ix"], r["iy"], r["status"]) for r in rows] == [("0", "0", "refused"), ("1", "0", "unreadable"),
                                                                ("0", "1", "unreadable")]
    assert "nonesuch.csv" in rows[1]["reasons"]
    assert "retract" in rows[2]["reasons"] or "turn" in rows[2]["reasons"], rows[2]["reasons"]


def test_a_pixel_through_the_journal_is_the_same_value(tmp_path):
    """A pixel of each kind (a fit's Measured with and without a bar, Missing, no rms; a flagged one) written
    to a journal, a torn line after it (a kill mid-write), read back: equal to the pixels written, the torn
    line dropped; a journal of another fingerprint refused."""
    from petsc_adhesion.io.map import Journal, JournalError, pixel_fields
    from petsc_adhesion.maps.result import Pixel
    from petsc_adhesion.maps.source import MapEntry
    from petsc_adhesion.tracing.measured import Measured, Missing

    a = Pixel(MapEntry(0, 1, 2, 1.5e-6, None, "a.csv"), "warned", ("a misfit",), Measured(0.05, 1e-3),
              Measured(3e10, None, note="held at 3e+10 Pa"), None, Measured(6.2e-9, 1e-11, note="n"),
              Missing("no jump"), Measured(1.0e-16, 2e-18), 1.7, 1e-9, 12)
    b = Pixel(MapEntry(1, 0, 0), "refused", ("no adhesion",), Missing("no adhesion"), Missing("no adhesion"),
              Missing("no adhesion"), Missing("x"), Missing("y"), Missing("z"))
    j = Journal(str(tmp_path / "m.journal"), "print")
    j.start()
    j.append([a, b])
    with open(j.path, "a") as f:
        f.write('{"index": 2, "ix"')                    # torn by a kill
    back = [Pixel(MapEntry(**e), **f) for e, f in map(pixel_fields, j.read())]
    assert back == [a, b]
    j.start()                                           # the torn line cut off, the rest kept
    assert open(j.path).read().count("\n") == 3 and len(j.read()) == 2
    with pytest.raises(JournalError):
        Journal(j.path, "another").read()
