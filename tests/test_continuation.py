"""The whole load-approach curve: events, stability, correctors, refinement, ranks.

Every run is ``python -m petsc_adhesion`` in a subprocess (conftest.run_cli),
writing a JSON summary and an HDF5 file.  The runs are grouped in
module-scoped fixtures, each group run two at a time (the machine has two
cores), and a run asked for by several groups is made once (``_DONE``).

The checks compare with independent truth only: the closed form of mu = 0
(eq. 28), the numbers the paper quotes (within the digits it gives; see
docs/model.md for its typos), a Jacobian and a residual built
here from the influence matrix and the pressure law, the order of
convergence under refinement, and invariance under the corrector, the event
tolerance and the number of ranks.
"""
import hashlib
import json
import math
import os
import re
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from conftest import in_process, run_cli
from petsc_adhesion.discretization.grid import load_weights
from petsc_adhesion.discretization.influence import influence_rows
from petsc_adhesion.model.reference.rigid import RIGID_EQUILIBRIUM, load_beyond, rigid_load
from petsc_adhesion.model.pressure import PressureLaw

h5py = pytest.importorskip("h5py")


# -- running the program -----------------------------------------------------------
class Run:
    """One finished run: its process, JSON summary and HDF5 file."""

    def __init__(self, args, nranks, proc, folder):
        self.args, self.nranks, self.proc = args, nranks, proc
        self.json_path = os.path.join(folder, "summary.json")
        self.h5_path = os.path.join(folder, "result.h5")

    @property
    def summary(self) -> dict:
        with open(self.json_path) as f:
            return json.load(f)

    def h5(self):
        return h5py.File(self.h5_path, "r")

    def curve(self) -> dict:
        with self.h5() as f:
            return {k: f["curve"][k][()] for k in f["curve"]}

    def events(self) -> list:
        """Events of the HDF5 file in order: attrs, H and P (with -profiles), landing."""
        out = []
        with self.h5() as f:
            r = f["grid/r"][()]
            for key in sorted(f["events"]):
                g = f["events"][key]
                ev = {**dict(g.attrs), "r": r}
                ev["kind"] = str(ev["kind"])
                for name in ("H", "P"):
                    if name in g:
                        ev[name] = g[name][()]
                if "landing" in g:
                    land = g["landing"]
                    ev["landing"] = {**dict(land.attrs), **{k: land[k][()] for k in ("H", "P") if k in land}}
                out.append(ev)
        return out


#: (args, ranks) -> Run, so that a run shared by several fixtures is made once
_DONE: dict = {}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return tmp_path_factory.mktemp("continuation")


def run_many(workdir, jobs: dict) -> dict:
    """{name: (args, ranks[, exit status])} -> {name: Run}, each run once per module: one rank's runs by main() in
    this process (conftest.in_process), one after the other; two ranks' under mpiexec, two at a time.

    The exit status is 0 unless given: 3 is a result written that is not the
    whole curve asked for (natural continuation stops at a fold; a staircase).
    """
    todo = {}
    for name, (args, nranks, *status) in jobs.items():
        key = (tuple(map(str, args)), nranks)
        if key not in _DONE:
            todo[key] = status[0] if status else 0
    if todo:
        def one(key):
            args, nranks = key
            folder = os.path.join(str(workdir), hashlib.sha1(repr(key).encode()).hexdigest()[:16])
            os.makedirs(folder, exist_ok=True)
            files = ("-summary", os.path.join(folder, "summary.json"), "-out", os.path.join(folder, "result.h5"))
            # one rank: main() in this process, one run after the other (a process of its own adds about 1 CPU s
            # to start Python and PETSc); two ranks under mpiexec, two at a time
            proc = in_process(*args, *files) if nranks == 1 else run_cli(*args, *files, np=nranks)
            return Run(args, nranks, proc, folder)

        runs = {key: one(key) for key in todo if key[1] == 1}     # in the main thread: main() sets signal handlers
        there = [key for key in todo if key[1] > 1]
        with ThreadPoolExecutor(max_workers=2) as pool:
            runs |= dict(zip(there, pool.map(one, there)))
        for key in todo:
            run = runs[key]
            assert run.proc.returncode == todo[key], (
                f"petsc-adhesion {' '.join(key[0])} (np={key[1]}) failed:\n{run.proc.stderr}")
            _DONE[key] = run
    return {name: _DONE[(tuple(map(str, spec[0])), spec[1])] for name, spec in jobs.items()}


# -- independent numerics -------------------------------------------------------------
_INFLUENCE: dict = {}


def influence(r: np.ndarray) -> np.ndarray:
    key = hashlib.sha1(np.ascontiguousarray(r).tobytes()).hexdigest()
    if key not in _INFLUENCE:
        _INFLUENCE[key] = influence_rows(r, 0, r.size)
    return _INFLUENCE[key]


def coupling(mu: float) -> float:
    """c = 32 mu^1.5 / (3 pi) of eq. (12)."""
    return 32.0 * mu**1.5 / (3.0 * math.pi)


def jacobian(r, H, mu, sigma=0.0) -> np.ndarray:
    """G_H = I - c A diag(P'(H)) (eq. 23), built here from the influence rows and the pressure law."""
    _, dp = PressureLaw(sigma)(H)
    return np.eye(r.size) - coupling(mu) * influence(r) * dp


def residual(r, H, lam, mu, sigma=0.0) -> np.ndarray:
    """G(H, lambda) of eq. (12)."""
    p, _ = PressureLaw(sigma)(H)
    return H + lam - 0.5 * r * r - coupling(mu) * influence(r) @ p


def condition_ratio(J) -> float:
    s = np.linalg.svd(J, compute_uv=False)
    return s[-1] / s[0]


def unstable_modes(J) -> int:
    """Eigenvalues of G_H with negative real part (0: stable under displacement control)."""
    return int(np.sum(np.linalg.eigvals(J).real < 0))


def by_kind(events, kind):
    return [e for e in events if e["kind"] == kind]


def folds_of(summary):
    return {f["kind"]: f for f in summary["folds"]}


# -- the runs -------------------------------------------------------------------------
#: mu = 1 on the paper grid, with states recorded at lambda = -3 (far from the folds),
#: -1.7 (between snap-off -1.74 and snap-on -1.63: three states) and 0 (Fig. 12)
MU1 = ("-adh_mu", "1", "-grid_type", "paper", "-cont_at_lambda", "-3,-1.7,0", "-profiles")
#: the paper's grid and truncated model on [0, 10] (docs/numerics.md)
PAPER_MODEL = ("-grid_type", "paper", "-adh_farfield", "false", "-adh_model_spread", "false")
#: mu = 0.01: a denser curve (ds_max 0.05) for the comparison with eq. (28)
DMT = ("-grid_type", "paper", "-cont_ds_max", "0.05", "-cont_at_lambda", "0", "-profiles")


def uniform(n):
    return ("-grid_type", "uniform", "-grid_n", str(n))


CONVERGENCE_N = (101, 201, 401, 801)


@pytest.fixture(scope="module")
def mu1(workdir):
    return run_many(workdir, {"auto": (MU1, 1)})["auto"]


@pytest.fixture(scope="module")
def mu1_variants(workdir):
    return run_many(workdir, {
        "auto": (MU1, 1),
        "arclength": ((*MU1, "-cont_type", "arclength"), 1),
        "natural": ((*MU1, "-cont_type", "natural"), 1, 3),
        "tight": ((*MU1, "-cont_event_tol", "1e-12"), 1),
    })


@pytest.fixture(scope="module")
def dmt(workdir):
    return run_many(workdir, {
        "mu0.01": (("-adh_mu", "0.01", *DMT), 1),
        "mu0.005": (("-adh_mu", "0.005", *DMT), 1),
        "solve0": (("-adh_mu", "0.01", "-adh_lambda", "0", "-grid_type", "paper"), 1),
    })


#: (mu, sigma) -> what the paper quotes: pull-off F_p and the unit of its last digit,
#: lambda_p, equilibrium lambda_e, folds (snap-on, snap-off) and their loads as printed
PAPER = {
    (2.0, 0.0): dict(Fp=-0.79, unit=0.01, lp=-1.66, le=4.00, folds=(-2.55, -3.38), loads=(-1.82, -4.54)),
    (2.0, 0.2): dict(Fp=-0.52, unit=0.01, lp=-1.71, le=2.59, folds=(-2.58, -2.95), loads=(-1.80, -3.17)),
    (2.0, 0.4): dict(Fp=-0.167, unit=0.001, lp=-2.31, le=-0.364, folds=()),
    (2.0, 1.0): dict(Fp=-0.03, unit=0.01, lp=-5.91, le=-5.28, folds=()),
    (0.01, 0.2): dict(Fp=-0.64, unit=0.01, lp=-0.42, le=None, folds=()),
    (0.01, 0.4): dict(Fp=-0.18, unit=0.01, lp=None, le=None, folds=()),     # printed "0.18" (paper note 5, docs/model.md)
    (0.01, 1.0): dict(Fp=-0.03, unit=0.01, lp=-5.78, le=-5.71, folds=()),
}


@pytest.fixture(scope="module")
def paper(workdir):
    return run_many(workdir, {key: (("-adh_mu", f"{key[0]:g}", "-adh_sigma", f"{key[1]:g}", *PAPER_MODEL), 1)
                              for key in PAPER})


@pytest.fixture(scope="module")
def convergence(workdir):
    return run_many(workdir, {n: (("-adh_mu", "1", *uniform(n)), 1) for n in CONVERGENCE_N})


@pytest.fixture(scope="module")
def ranks(workdir):
    args = ("-adh_mu", "1", *uniform(101))
    return run_many(workdir, {1: (args, 1), 2: (args, 2)})


@pytest.fixture(scope="module")
def coarse(workdir):
    return run_many(workdir, {
        126: (("-adh_mu", "3", *uniform(126)), 1, 3),
        401: (("-adh_mu", "3", *uniform(401), "-cont_at_lambda", "0", "-profiles"), 1),
    })


@pytest.fixture(scope="module")
def lambda_max(workdir):
    return run_many(workdir, {lm: (("-adh_mu", "1", *uniform(201), "-cont_lambda_max", f"{lm:g}"), 1)
                              for lm in (0.0, -0.5)})


# -- 1. mu -> 0: eq. (28) --------------------------------------------------------------
def test_small_mu_follows_rigid_closed_form(dmt):
    s = dmt["mu0.01"].summary
    # pull-off of eq. (28): F = -1 at lambda = 0
    assert abs(s["pull_off"]["F"] + 1.0) < 0.005
    assert abs(s["pull_off"]["lambda"]) < 0.01
    # one equilibrium, near 1 - 2^(-1/3) = 0.2063 (moved by elasticity, paper note 7), and the
    # paper's "lambda_e = 0.21" for the smooth surface
    (eq,) = s["equilibria"]
    assert abs(eq["lambda"] - RIGID_EQUILIBRIUM) < 0.01
    assert abs(eq["lambda"] - 0.21) <= 0.01
    assert s["folds"] == []

    # the shift of the equilibrium is elastic: it scales with c ~ mu^1.5 (ratio 2^1.5 = 2.83
    # from mu = 0.005 to 0.01); measured 2.86.  Truncation and mesh move it by < 1e-4.
    shift = {k: dmt[k].summary["equilibria"][0]["lambda"] - RIGID_EQUILIBRIUM for k in ("mu0.01", "mu0.005")}
    assert shift["mu0.01"] > 0 and shift["mu0.005"] > 0
    assert 2.5 < shift["mu0.01"] / shift["mu0.005"] < 3.2

    # the curve itself: F(lambda) against eq. (28) on [-2, 0.12] (points every ds_max 0.05).
    # Beyond 0.12 the repulsive rise is nearly vertical and the elastic shift in lambda shows
    # as an F difference growing to 3e-2 at 0.18: there the equilibrium shift above is the test.
    # The deviation is made of (a) elastic deformation at mu = 0.01: the surfaces sag towards
    # each other, -1.7e-3 near lambda = -0.2 and +2.5e-3 on the steep repulsive rise near 0.1;
    # (b) the mesh, O(h^2): the deviation changes by < 4e-5 from N = 531 to uniform N = 2001.
    # The attraction beyond r_m = 10 (4.6e-4 .. 5.1e-4 here) is in F: the model is the
    # half-infinite one.  Measured with dense sampling: max 2.53e-3, min -1.72e-3.
    c = dmt["mu0.01"].curve()
    lam, F = c["lambda"], c["F"]
    sel = (lam >= -2.0) & (lam <= 0.12)
    assert sel.sum() >= 35
    dev = np.abs(F[sel] - rigid_load(lam[sel]))
    assert dev.max() < 4e-3
    # far from contact (lambda < -1.5) elasticity is small and the far field is in F: F - F_28
    # within 1e-4 (measured 5.7e-5), where the paper's truncated F misses 4.6e-4
    far = lam <= -1.5
    assert far.sum() >= 10
    assert np.all(np.abs(F[far] - rigid_load(lam[far])) < 1e-4)
    assert np.all(-load_beyond(10.0, lam[far]) > 4e-4)


# -- 2. mu = 1: snap-on, snap-off, landings ------------------------------------------
def test_mu1_folds_and_landings(mu1):
    s = mu1.summary
    assert [f["kind"] for f in s["folds"]].count("snap_on") == 1
    assert [f["kind"] for f in s["folds"]].count("snap_off") == 1
    assert len(s["folds"]) == 2
    on, off = folds_of(s)["snap_on"], folds_of(s)["snap_off"]
    # hysteresis: the jump-in on approach comes at the larger lambda (paper note 4: the paper's
    # mu = 1 text swaps the labels of -1.63 and -1.74)
    assert on["lambda"] > off["lambda"]
    assert abs(on["lambda"] - (-1.63)) <= 0.01
    assert abs(off["lambda"] - (-1.74)) <= 0.01
    (eq,) = s["equilibria"]
    assert abs(eq["lambda"] - 2.07) <= 0.01

    # each fold lands on the other stable branch at the same lambda ...
    for f in (on, off):
        assert abs(f["landing"]["lambda"] - f["lambda"]) < 1e-8
    # ... on the other side in load: snap-on jumps into contact (more tensile),
    # snap-off out of it (less tensile)
    assert on["landing"]["F"] < on["F"]
    assert off["landing"]["F"] > off["F"]
    # the pull-off is the most tensile load on the curve
    assert s["pull_off"]["F"] <= min(on["landing"]["F"], off["F"])

    # the landing states are stable: G_H built here has no eigenvalue with negative real part
    for ev in by_kind(mu1.events(), "snap_on") + by_kind(mu1.events(), "snap_off"):
        land = ev["landing"]
        assert abs(land["lambda"] - ev["lambda"]) < 1e-8
        assert unstable_modes(jacobian(ev["r"], land["H"], 1.0)) == 0


# -- 3. the paper's numbers ------------------------------------------------------------
@pytest.mark.parametrize("key", list(PAPER), ids=[f"mu{m:g}-sigma{s:g}" for m, s in PAPER])
def test_paper_values(paper, key):
    ref, s = PAPER[key], paper[key].summary
    po = s["pull_off"]
    # pull-off load within one unit of the paper's last digit
    assert abs(po["F"] - ref["Fp"]) <= ref["unit"] * (1 + 1e-9)
    # its lambda is ill-conditioned: F is flat at the pull-off (dF/dlambda = 0), so a load
    # error delta moves lambda_p by ~ sqrt(delta / F''); the paper's own grid and rounding
    # leave a few hundredths (measured: 0.019 at sigma 0.2, 0.033 at sigma 0.4, 0.027 at sigma 1)
    if ref["lp"] is not None:
        assert abs(po["lambda"] - ref["lp"]) < 0.05
    # equilibria within 0.01.  Observed differences: 0.0055 (4.00), 0.0051 (2.59),
    # 0.0044 (-0.364: four units of the paper's third digit; ours is converged, -0.35958 on
    # uniform N = 501 and -0.35956 on N = 1001), 0.0038 (-5.28), 0.0002 (-5.71)
    if ref["le"] is not None:
        assert len(s["equilibria"]) == 1
        assert abs(s["equilibria"][0]["lambda"] - ref["le"]) <= 0.01
    if not ref["folds"]:
        assert s["folds"] == []
        return
    on, off = folds_of(s)["snap_on"], folds_of(s)["snap_off"]
    assert len(s["folds"]) == 2
    assert abs(on["lambda"] - ref["folds"][0]) <= 0.01
    assert abs(off["lambda"] - ref["folds"][1]) <= 0.01
    # paper note 6 (docs/model.md): the loads the paper prints at the folds cannot be on the curve, whose most
    # tensile load is the pull-off; they are ten times ours (typo by a factor 10):
    # -0.1834 / -0.4544 (sigma 0) and -0.1818 / -0.3176 (sigma 0.2)
    for f, printed in zip((on, off), ref["loads"]):
        assert f["F"] > po["F"]
        assert printed < po["F"]
        assert abs(f["F"] - printed / 10) < 0.002


def test_paper_profiles_at_r0(paper):
    """Mean separation at r = 0 at pull-off and at equilibrium, mu = 2 (paper, Figs. 15, 16)."""
    pull = {0.0: -0.009, 0.2: 0.419, 0.4: 1.760}      # sigma = 1: paper 5.902, see below
    equi = {0.0: -0.0270, 0.2: 0.4154, 0.4: 1.7512, 1.0: 5.7412}
    for sigma, h0 in pull.items():
        s = paper[(2.0, sigma)].summary
        (fmin,) = [e for e in s["load_extrema"] if e["kind"] == "F_min"]
        assert abs(fmin["H0"] - h0) <= 0.001
    for sigma, h0 in equi.items():
        (ev,) = by_kind(paper[(2.0, sigma)].events(), "equilibrium")
        # one unit of the paper's fourth decimal at sigma <= 0.4; 5.7407 against 5.7412 at sigma 1
        assert abs(ev["H0"] - h0) <= (0.0001 if sigma < 1 else 0.001) * (1 + 1e-9)
    # sigma = 1 at pull-off: ours H0 = 5.779 at lambda_p = -5.883, i.e. a sag of the centre of
    # H0 + lambda_p = -0.104, which is what c (pi/2) integral P dr gives for the weak attraction
    # spread over r < 10 at mu = 2; the paper's 5.902 at -5.91 (sag -0.008) does not fit its
    # own equilibrium sag (5.7412 - 5.28 = 0.46 vs ours 0.4645).  Not asserted; reported.


# -- 4. the Jacobian is singular at the folds ------------------------------------------
def test_jacobian_singular_at_folds(mu1):
    events = mu1.events()
    folds = by_kind(events, "snap_on") + by_kind(events, "snap_off")
    assert len(folds) == 2
    for ev in folds:
        J = jacobian(ev["r"], ev["H"], 1.0)
        # measured 7.8e-11 (snap-on) and 3.0e-12 (snap-off): the folds are located to 1e-10
        assert condition_ratio(J) < 1e-6
    regular = [e for e in by_kind(events, "lambda") if abs(e["lambda"] - (-3.0)) < 1e-8 or abs(e["lambda"]) < 1e-8]
    assert len(regular) == 2
    for ev in regular:
        # measured 0.92 at lambda = -3 and 4.2e-3 at lambda = 0 (in contact: the stiff
        # repulsion makes the largest singular value large)
        assert condition_ratio(jacobian(ev["r"], ev["H"], 1.0)) > 1e-3


# -- 5. stability ---------------------------------------------------------------------
def test_stability(mu1):
    s = mu1.summary
    c = mu1.curve()
    assert c["stable"].dtype == bool
    np.testing.assert_array_equal(c["stable"], c["lambdadot"] > 0)
    # the unstable part of the curve lies between the folds
    on, off = folds_of(s)["snap_on"], folds_of(s)["snap_off"]
    lam_u = c["lambda"][~c["stable"]]
    assert lam_u.size > 0
    assert np.all((lam_u >= off["lambda"] - 1e-9) & (lam_u <= on["lambda"] + 1e-9))

    events = mu1.events()
    three = [e for e in by_kind(events, "lambda") if abs(e["lambda"] + 1.7) < 1e-8]
    assert len(three) == 3
    modes = [unstable_modes(jacobian(e["r"], e["H"], 1.0)) for e in three]
    flags = [bool(e["stable"]) for e in three]
    # two stable states (no negative eigenvalue) and one unstable (exactly one)
    assert sorted(modes) == [0, 0, 1]
    assert flags == [m == 0 for m in modes]
    # the unstable state's load lies between those of the stable ones
    Fs = sorted(e["F"] for e in three)
    (unstable,) = [e for e, m in zip(three, modes) if m == 1]
    assert unstable["F"] == Fs[1]
    # far from the folds and in contact: stable
    for lam in (-3.0, 0.0):
        (e,) = [e for e in by_kind(events, "lambda") if abs(e["lambda"] - lam) < 1e-8]
        assert e["stable"] and unstable_modes(jacobian(e["r"], e["H"], 1.0)) == 0
    # and at the pull-off and the equilibrium
    for kind in ("F_min", "equilibrium"):
        for e in by_kind(events, kind):
            assert e["stable"] and unstable_modes(jacobian(e["r"], e["H"], 1.0)) == 0


# -- 6. the correctors ----------------------------------------------------------------
def _event_table(run):
    """Events as (kind, lambda, F), landings included, sorted (states at one lambda by F)."""
    rows = []
    for e in run.events():
        rows.append((e["kind"], e["lambda"], e["F"]))
        if "landing" in e:
            rows.append((e["kind"] + "/landing", e["landing"]["lambda"], e["landing"]["F"]))
    return sorted(rows, key=lambda x: (x[0], round(x[1], 6), x[2]))


def test_auto_and_arclength_agree(mu1_variants):
    a, b = _event_table(mu1_variants["auto"]), _event_table(mu1_variants["arclength"])
    assert [k for k, _, _ in a] == [k for k, _, _ in b]
    assert len(a) == 11           # 2 folds + 2 landings, F_min, equilibrium, 5 states at -3, -1.7 (x3), 0
    for (k, la, Fa), (_, lb, Fb) in zip(a, b):
        assert abs(la - lb) < 1e-8, k
        assert abs(Fa - Fb) < 1e-8, k
    assert "arclength" in {x.decode() for x in mu1_variants["arclength"].curve()["corrector"]}
    assert "natural" not in {x.decode() for x in mu1_variants["arclength"].curve()["corrector"]}


def test_natural_stops_at_first_fold(mu1_variants):
    auto, nat = mu1_variants["auto"], mu1_variants["natural"]
    s = nat.summary
    assert "turning point" in s["stop_reason"]
    assert s["folds"] == [] and s["equilibria"] == [] and s["pull_off"] is None
    on = folds_of(auto.summary)["snap_on"]
    cn, ca = nat.curve(), auto.curve()
    # it gets up to the snap-on from below, without passing it
    assert np.all(cn["lambdadot"] > 0)
    assert cn["lambda"].max() <= on["lambda"] + 1e-9
    assert on["lambda"] - cn["lambda"][-1] < 1e-3
    # before it, the curves are the same: the auto corrector is natural while |lambdadot| >= 0.5,
    # so the first points coincide; the states at -3 and -1.7 (approach branch) agree to 1e-8
    k = 1
    while k < min(cn["lambda"].size, ca["lambda"].size) and ca["corrector"][k] == b"natural" \
            and cn["lambda"][k] == ca["lambda"][k]:
        k += 1
    assert k >= 10
    np.testing.assert_allclose(cn["F"][:k], ca["F"][:k], rtol=0, atol=1e-12)
    at_nat = [(e["lambda"], e["F"]) for e in by_kind(nat.events(), "lambda")]
    assert len(at_nat) == 2
    at_auto = [(e["lambda"], e["F"]) for e in by_kind(auto.events(), "lambda")]
    for lam, F in at_nat:
        first = next(x for x in at_auto if abs(x[0] - lam) < 1e-8)      # first crossing: approach branch
        assert abs(first[1] - F) < 1e-8


# -- 7. second-order convergence -------------------------------------------------------
def _quantities(summary):
    """The values of the grid, not the best values extrapolated from its levels."""
    f = folds_of(summary)
    return {"snap_on lambda": f["snap_on"]["lambda_grid"], "snap_off lambda": f["snap_off"]["lambda_grid"],
            "pull-off F": summary["pull_off"]["F_grid"], "equilibrium lambda": summary["equilibria"][0]["lambda_grid"]}


def test_events_converge_at_second_order(convergence):
    q = [_quantities(convergence[n].summary) for n in CONVERGENCE_N]
    orders = {}
    for name in q[0]:
        v = np.array([x[name] for x in q])
        d = np.abs(np.diff(v))
        orders[name] = np.log2(d[:-1] / d[1:])
    print("observed orders (101/201/401, 201/401/801):",
          {k: np.round(v, 3).tolist() for k, v in orders.items()})
    # measured: snap_on 1.985, 1.997; snap_off 1.985, 1.994; pull-off F 1.902, 1.975;
    # equilibrium 2.288, 2.021 (and 2.00 +- 0.01 on the next level, N = 1601, not run here).
    # The pull-off lambda, ill-conditioned, is left out (-0.20 then 1.995).
    for name, o in orders.items():
        assert np.all((o > 1.7) & (o < 2.4)), (name, o)
        assert abs(o[-1] - 2.0) < 0.1, (name, o)


# -- 8. located events ----------------------------------------------------------------
def test_events_are_located_not_sampled(mu1_variants):
    auto, tight = mu1_variants["auto"], mu1_variants["tight"]
    lam_curve = auto.curve()["lambda"]
    located = [e for e in auto.events() if e["kind"] in ("snap_on", "snap_off", "F_min", "equilibrium")]
    assert len(located) == 4
    for e in located:
        # measured distances to the nearest curve point: 1.0e-5 and 7.9e-6 at the folds
        # (where the step shrinks), 0.055 and 0.076 at the pull-off and the equilibrium
        assert np.abs(lam_curve - e["lambda"]).min() > 1e-6, e["kind"]
    for e in by_kind(auto.events(), "lambda"):
        assert np.abs(lam_curve - e["lambda"]).min() > 1e-6
    # the tolerance 1e-10 is met: a tolerance of 1e-12 moves nothing by 1e-8
    a, b = _event_table(auto), _event_table(tight)
    assert [k for k, _, _ in a] == [k for k, _, _ in b]
    for (k, la, Fa), (_, lb, Fb) in zip(a, b):
        assert abs(la - lb) < 1e-8, k
        assert abs(Fa - Fb) < 1e-8, k


# -- 9. ranks --------------------------------------------------------------------------
def test_two_ranks_reproduce_one(ranks):
    one, two = ranks[1].summary, ranks[2].summary
    assert one["mpi_ranks"] == 1 and two["mpi_ranks"] == 2
    assert two["steps"] == one["steps"] and len(two["folds"]) == len(one["folds"]) == 2
    a, b = _event_table(ranks[1]), _event_table(ranks[2])
    assert [k for k, _, _ in a] == [k for k, _, _ in b]
    for (k, la, Fa), (_, lb, Fb) in zip(a, b):
        # measured: 1e-9 for the ill-conditioned pull-off lambda, < 1e-12 otherwise
        assert abs(la - lb) < 1e-8, k
        assert abs(Fa - Fb) < 1e-8, k
    for fa, fb in zip(one["folds"], two["folds"]):
        assert abs(fa["H0"] - fb["H0"]) < 1e-8
        assert abs(fa["landing"]["H0"] - fb["landing"]["H0"]) < 1e-8


# -- 10. a grid that traps the contact edge ---------------------------------------------
def test_coarse_grid_warning(coarse):
    bad, good = coarse[126].summary, coarse[401].summary
    # h = 0.08: a staircase of spurious turning points, stopped by -cont_max_folds
    assert len(bad["folds"]) > 4
    assert "cont_max_folds" in bad["stop_reason"]
    warn = bad["grid_warning"]
    assert warn
    m = re.search(r"spacing <= ([0-9.eE+-]+)", warn)
    assert m, warn
    need = float(m.group(1))
    # the named spacing is met by the grid that works (h = 0.025) and not by this one (h = 0.08)
    assert 10.0 / 400 <= need < 10.0 / 125
    assert "0.08" in warn
    # h = 0.025: the two true turning points, no warning
    assert len(good["folds"]) == 2
    assert good["grid_warning"] == ""
    assert {f["kind"] for f in good["folds"]} == {"snap_on", "snap_off"}


# -- 11. the state at lambda = 0 (Fig. 12), and -cont_lambda_max ---------------------
def test_state_at_lambda_zero(dmt, mu1, coarse):
    # mu = 0.01: the recorded state equals a fixed-lambda Newton solve at lambda = 0
    (ev,) = by_kind(dmt["mu0.01"].events(), "lambda")
    assert abs(ev["lambda"]) < 1e-8
    with dmt["solve0"].h5() as f:
        H_solve = f["solution/H"][()]
    F_solve = dmt["solve0"].summary["F"]
    assert abs(ev["F_grid"] - F_solve) < 1e-8
    np.testing.assert_allclose(ev["H"], H_solve, rtol=0, atol=1e-8)
    # mu = 1 (paper grid) and mu = 3 (uniform, h = 0.025): Newton from the rigid guess fails
    # at lambda = 0, so check the state against eq. (12) and (26) directly
    sag = {}
    for mu, run in ((0.01, dmt["mu0.01"]), (1.0, mu1), (3.0, coarse[401])):
        (ev,) = [e for e in by_kind(run.events(), "lambda") if abs(e["lambda"]) < 1e-8]
        r, H = ev["r"], ev["H"]
        assert np.abs(residual(r, H, ev["lambda"], mu)).max() < 1e-8
        p, _ = PressureLaw(0.0)(H)
        assert abs((8.0 / 3.0) * load_weights(r) @ p + ev["F_beyond"] - ev["F_grid"]) < 1e-10
        sag[mu] = np.abs(H - (0.5 * r * r - ev["lambda"])).max()
    # Fig. 12: little deformation at mu = 0.01, obvious at mu = 3 (measured max |H - H_rigid|:
    # 0.0024 at mu = 0.01, 1.30 at mu = 1, 4.70 at mu = 3)
    assert sag[0.01] < 0.01 < 0.5 < sag[3.0]


# -cont_lambda_max 0 was ignored before 87cebdd ("or np.inf" on a falsy 0): the run went on to
# F >= -cont_F_max (lambda 5.39) and reported the equilibrium at 2.07
@pytest.mark.parametrize("lmax", [0.0, -0.5])
def test_lambda_max_stops_there(lambda_max, lmax):
    run = lambda_max[lmax]
    s, c = run.summary, run.curve()
    lam = c["lambda"]
    assert "cont_lambda_max" in s["stop_reason"]
    # it stops at the first point at or past lambda_max: only the last step crosses it
    assert lam[-1] >= lmax
    assert np.all(lam[:-1] < lmax)
    assert lam[-1] - lmax <= c["ds"][-1]
    # nothing beyond is reported: the equilibrium (2.07) lies past both limits
    assert s["equilibria"] == []
    assert all(e["lambda"] <= lmax for e in s["folds"] + s["load_extrema"])


def test_secondary_fold_pair_is_born_between_mu_3_5_and_4(tmp_path):
    """At mu = 4 a secondary fold pair sits on the unstable branch near lambda = -4.02, less than 1e-3 wide;
    an independent grid (uniform, spacing 0.01 on r_m = 5) has it too, and mu = 3.5 has none on either
    (the paper shows it from mu = 5).  Its snap-on is not found again on the nested levels: no bar, and
    the file and the console say why."""
    window = ("-cont_F_max", "0", "-cont_lambda_max", "-3.0")
    uniform = ("-grid_type", "uniform", "-grid_n", "501", "-adh_rmax", "5", "-cont_error_estimate", "false")
    runs = [(mu, kind) for mu in (3.5, 4) for kind in ("default", "uniform")]

    def one(key):
        mu, kind = key
        summary = tmp_path / f"{mu}_{kind}.json"
        proc = run_cli("-adh_mu", mu, *window, *(uniform if kind == "uniform" else ()), "-summary", summary)
        assert proc.returncode == 0, proc.stderr
        return json.loads(summary.read_text()), proc.stdout

    with ThreadPoolExecutor(max_workers=2) as pool:
        got = dict(zip(runs, pool.map(one, runs)))
    for kind in ("default", "uniform"):
        assert [f["kind"] for f in got[(3.5, kind)][0]["folds"]] == ["snap_on", "snap_off"], kind
        folds = got[(4, kind)][0]["folds"]
        assert [f["kind"] for f in folds] == ["snap_on", "snap_off", "snap_on", "snap_off"], kind
        pair = folds[1:3]
        assert 0 < abs(pair[0]["lambda"] - pair[1]["lambda"]) < 1e-3, (kind, pair)
        assert -4.04 < pair[0]["lambda"] < -4.0, (kind, pair)
    summary, stdout = got[(4, "default")]
    bare = [f for f in summary["folds"] if "lambda_err" not in f]
    assert all(f.get("error_note", "").startswith("no error bar") for f in bare)
    assert stdout.count("(no error bar: not found again on the nested levels)") == len(bare)
