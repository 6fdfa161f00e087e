"""docs/mean_field.md: how far the mean field holds, against explicit rough contacts solved by
ContactMechanics + Adhesion (the ContactEngineering codes) in an environment of their own.

The same sphere (mu = 0.3, 1, 3: a case's fourth field, MU when it names none) on a few explicit rough
surfaces.  Their side: an FFT elastic half-space (free,
non-periodic), the explicit topography of sphere plus roughness, the Lennard-Jones 9-3 surface stress of our
eq. (5) (their ``Lj82``), energy minimisation in displacement control (stable states only), approach and
retract on a lattice of lambda.  Our side: the mean field of the same surface, its own pixel heights as the
measured law (``-adh_roughness measured``), and the paper's Gaussian rule (16-point Hermite) at the same rms,
with the truncated Gaussian cut at the surface's own highest height beside it.  Compared: the pull-off (the
most tensile load on retract), the snap-on and snap-off, the hysteresis of the displacement-controlled cycle,
against the roughness, with the seed-to-seed spread of the explicit runs as their bar::

    python3 -m venv .venv-peer
    .venv-peer/bin/pip install ContactMechanics Adhesion NuMPI SurfaceTopography   # not muFFT: below
    export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
    # their side, in their environment (about 18 CPU minutes; merged into the JSON after every curve):
    nice -n 10 .venv-peer/bin/python petsc_adhesion/benchmarks/peer_rough.py peer --out docs/data/peer_rough.json
    # ours, in ours (35 CPU seconds): docs/data/mean_field.json, the table docs/figures/mean_field.md, the
    # figure docs/figures/mean_field.png
    nice -n 10 python -m petsc_adhesion.benchmarks.mean_field --data docs/data/peer_rough.json

(``.venv-peer`` is the user's to make, not part of the repository.)  The first command runs this file as a
script under the peer's interpreter: at module level it imports nothing but the standard library and numpy,
and the peer's packages inside its functions; our side is :mod:`.mean_field`, which imports this module.  The peer's cases can be
split over processes (``peer --cases 64:0.3:1,64:0.3:1:3,... --out part.json``, ``--retract
64:0.3:1:0.5:-3.5:3``) and their files joined
(``peer_rough.py merge --out docs/data/peer_rough.json part1.json part2.json ...``), as the stored file was.

``muFFT`` 0.95 (the last on the registry) is left out: installed beside muGrid 1.6 it replaces muGrid's
``__init__`` with one that lacks ``FFTEngine``, and ContactMechanics 1.8.3 then fails to import
(``ImportError: cannot import name 'FFTEngine' from 'muGrid'``); ContactMechanics needs muGrid only.

Units (as :mod:`.peers`, exact): R = epsilon = gamma = 1, lengths in the plane in sqrt(R epsilon), gaps in
epsilon, the contact modulus E* = mu^(-3/2), ``Lj82(w=1, z0=1)`` whose traction is (8/3)(g^-9 - g^-3), the
load F = compute_normal_force() / (2 pi) plus the rigid far field outside the square (:func:`far_field_load`),
lambda = offset + 1.  The roughness z(x, y) (up: towards the sphere) is added to the sphere's heights
-(x^2 + y^2)/2, so the gap is r^2/2 + u + 1 - lambda - z: z is the S of our eq. (7), whose pixel heights
are the measured law of the mean field.

The surfaces (:func:`surface`): Gaussian, self-affine (Hurst 0.8) between the wavelengths 2L/M_LO and
2L/M_HI, periodic on the square, synthesised from Gaussian Fourier amplitudes drawn from the seed.  Not
SurfaceTopography's ``fourier_synthesis``: its draw depends on the number of pixels, and the refinement must
sample the same surface on finer grids.  Ours is a trigonometric polynomial with no mode at or above half
the pixels, so every grid of n >= 2 M_HI + 1 pixels samples the same continuous surface and its pixel rms is
sigma exactly (Parseval on the grid); both sides draw it from the seed and the peer's heights' digest is
checked against ours.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys
import tempfile
import time

import numpy as np

#: Tabor parameter of a run that names none: the first set of runs (the stored file's runs without a "mu" are
#: at this one).  A case's own mu is its fourth field (``--cases n:sigma:seed:mu``).
MU = 1.0
#: Half width of the square [-L, L]^2 (sqrt(R epsilon)); the contact (radius below 2.5 up to F = 0 at mu = 1)
#: lies well inside, the traction beyond is the rigid far field.
L = 5.0
#: The roughness's modes: wave numbers m = 2L / wavelength from M_LO to M_HI (wavelengths 1.67 to 0.625,
#: against the smooth contact's diameter of about 2 to 4.6 between the pull-off and F = 0), Hurst exponent.
M_LO, M_HI, HURST = 6, 16, 0.8
#: Pixels per side of the main runs and of the refinement.
N_MAIN, N_FINE = 64, 128
#: rms heights (epsilon) and seeds of the explicit surfaces.
SIGMAS = (0.1, 0.3, 1.0, 2.0)
SEEDS = (1, 2, 3)
#: The refinement: the smooth sphere and two rough surfaces (sigma, seed), their retraction alone from lam_hi
#: down to lam_lo (about the pull-off) on both grids.
REFINED = ((0.0, 0, 0.5, -1.4), (0.3, 2, 0.5, -1.6), (1.0, 1, 0.5, -2.3))
#: Displacement-control lattice step, the pull-off's refinement step, the approach's stop (the load at
#: equilibrium, past the pull-off), the start before the highest asperity under the sphere.
DLAM, DLAM_FINE, F_STOP, START_GAP = 0.05, 0.01, 0.0, 2.6
#: A lattice step whose load changes by more than this is steep (the steepest of each leg is stored; the
#: snaps are read from the bistable range of approach and retraction, :func:`.mean_field.bistable`).
JUMP_DF = 0.05
#: The linear core of the law below this gap (a line search guard, as peers.py; states are checked above it).
R_TI = 0.5


def start_gap(mu: float) -> float:
    """The approach's start before the highest asperity under the sphere: START_GAP up to mu = 1, beyond it
    START_GAP mu^0.8, so that the retraction, which ends there, passes the snap-off of a softer sphere (ours
    of the smooth sphere at mu = 3 lies at lambda -4.99, the start at -6.3)."""
    return START_GAP * max(1.0, mu) ** 0.8


def surface(n: int, sigma: float, seed: int, half_width: float = L) -> np.ndarray:
    """The rough heights z at the centres of an n x n grid on [-L, L]^2: a Gaussian self-affine surface of
    rms sigma (exactly, on every grid with n > 2 M_HI) drawn from ``seed``, the same continuous surface
    on every such grid (only modes |m| <= M_HI, their amplitudes drawn independently of n)."""
    if n <= 2 * M_HI:
        raise ValueError(f"n = {n} must exceed 2 M_HI = {2 * M_HI} to sample the surface")
    if sigma == 0.0:
        return np.zeros((n, n))
    rng = np.random.default_rng(seed)
    m = np.arange(-M_HI, M_HI + 1)
    mx, my = np.meshgrid(m, m, indexing="ij")
    k = np.hypot(mx, my)
    band = (k >= M_LO) & (k <= M_HI)
    # the half plane of independent modes: c_{-m} = conj(c_m) makes z real
    half = (mx > 0) | ((mx == 0) & (my > 0))
    amp = np.where(band & half, k.clip(1) ** (-1.0 - HURST), 0.0)    # C(q) ~ q^(-2-2H), amplitude its root
    c = amp * (rng.standard_normal(k.shape) + 1j * rng.standard_normal(k.shape))
    # z(x) = 2 Re sum_half c_m exp(i q_m (x + L)) at x = -L + (j + 1/2) h: the FFT of c e^{i q h / 2}
    h = 2.0 * half_width / n
    spec = np.zeros((n, n), complex)
    shift = np.exp(1j * np.pi * (mx + my) / n)                      # q_m h / 2 = pi m / n
    spec[mx % n, my % n] = c * shift
    z = 2.0 * np.real(np.fft.ifft2(spec)) * n * n
    return z * (sigma / np.sqrt(np.mean(z ** 2)))


def digest(z: np.ndarray) -> str:
    """The heights' digest at 1e-9 epsilon: what both sides check they share."""
    return hashlib.sha256(np.round(z, 9).tobytes()).hexdigest()[:16]


def lj_traction(g):
    """Our surface stress (8/3)(g^-9 - g^-3), eq. (5), repulsion positive, gap g in epsilon."""
    return (8.0 / 3.0) * (g ** -9 - g ** -3)


def far_field_load(lam: float, F_raw: float, mu: float = MU, half_width: float = L) -> float:
    """The load (units 2 pi R gamma) of the traction outside the square, where the peer computes none: the
    smooth rigid gap r^2/2 + 1 - lambda plus the Boussinesq displacement 2 F mu^(3/2) / r of the net load
    (as :mod:`.peers`; the roughness out there, at gaps above 12 epsilon, changes it by O(sigma^2/g^2))."""
    from scipy.integrate import quad
    c = 2.0 * F_raw * mu ** 1.5

    def inner(t):
        val, _ = quad(lambda r: lj_traction(0.5 * r * r + 1.0 - lam + c / r) * r, half_width / np.cos(t),
                      np.inf, epsabs=1e-13, epsrel=1e-10, limit=200)
        return val

    val, _ = quad(inner, 0.0, np.pi / 4, epsabs=1e-13, epsrel=1e-10)
    return 8.0 * val / (2.0 * np.pi)


class PeerSystem:
    """One explicit rough sphere in ContactMechanics + Adhesion and its minimiser (peer's environment)."""

    def __init__(self, n: int, sigma: float, seed: int, gtol_rel: float = 1e-4, mu: float = MU):
        from Adhesion.Interactions import Lj82
        from Adhesion.System import SmoothContactSystem
        from ContactMechanics import FreeFFTElasticHalfSpace
        from SurfaceTopography import Topography
        self.n, self.sigma, self.seed, self.mu = n, sigma, seed, mu
        self.h = 2.0 * L / n
        x = -L + (np.arange(n) + 0.5) * self.h
        X, Y = np.meshgrid(x, x, indexing="ij")
        self.z = surface(n, sigma, seed)
        self.r = np.hypot(X, Y)
        topography = Topography(-(X ** 2 + Y ** 2) / 2.0 + self.z, physical_sizes=(2 * L, 2 * L))
        substrate = FreeFFTElasticHalfSpace((n, n), mu ** -1.5, physical_sizes=(2 * L, 2 * L))
        self.interaction = Lj82(1.0, 1.0).linearize_core(r_ti=R_TI)
        self.system = SmoothContactSystem(substrate, self.interaction, topography)
        # the settings of the package's own adhesive-sphere example (peers.py): stop on the gradient, the
        # largest pixel force imbalance 1e-4 of the peak stress on one pixel
        gtol = gtol_rel * abs(self.interaction.max_tensile) * self.system.area_per_pt
        self.options = dict(gtol=gtol, ftol=0.0, maxcor=3, maxiter=20000, maxfun=40000)
        self.solves = 0
        self.iterations = 0

    def solve(self, lam: float, disp0):
        """The energy minimised at lambda from disp0: the state (lambda, F, its parts, the smallest gap, the
        pixels within 1.5 epsilon: in contact) and the displacement."""
        res = self.system.minimize_proxy(offset=lam - 1.0, initial_displacements=disp0, options=self.options)
        if not res.success:
            raise RuntimeError(f"L-BFGS-B failed at lambda = {lam}: {res.message}")
        self.solves += 1
        self.iterations += int(res.nit)
        gap = self.system.gap
        if gap.min() <= R_TI:
            raise RuntimeError(f"the state at lambda = {lam} reaches the linear core (smallest gap {gap.min()})")
        F_raw = float(self.system.compute_normal_force()) / (2.0 * np.pi)
        F_tail = far_field_load(lam, F_raw, self.mu)
        contact = gap < 1.5
        return dict(lam=float(lam), F=F_raw + F_tail, F_tail=F_tail, min_gap=float(gap.min()),
                    contact_pixels=int(contact.sum())), self.system.disp.copy()


def march(system, disp, lams, stop=None):
    """States along ``lams`` warm-started each from the last, and their displacements; ``stop(state)`` ends
    the march early."""
    states, disps = [], []
    for lam in lams:
        st, disp = system.solve(lam, disp)
        states.append(st)
        disps.append(disp)
        if stop is not None and stop(st):
            break
    return states, disps


def largest_jump(states):
    """The largest load change between neighbouring states of a leg above JUMP_DF: its bracket, or None."""
    dF = np.abs(np.diff([s["F"] for s in states]))
    if dF.size == 0 or dF.max() <= JUMP_DF:
        return None
    i = int(np.argmax(dF))
    a, b = states[i], states[i + 1]
    return dict(lam_from=a["lam"], lam_to=b["lam"], F_from=a["F"], F_to=b["F"], count=int((dF > JUMP_DF).sum()))


def peer_curve(n: int, sigma: float, seed: int, log=print, mu: float = MU) -> dict:
    """Approach from START_GAP before the highest asperity under the sphere (r < 2.5) until F >= F_STOP on a
    lattice of DLAM, retract on the same lattice to the start, the pull-off refined on DLAM_FINE about the
    lattice's most tensile state (warm-started down the retract leg from the state one step before it)."""
    t0, c0 = time.perf_counter(), time.process_time()
    system = PeerSystem(n, sigma, seed, mu=mu)
    top = float(system.z[system.r < 2.5].max())
    k0 = int(np.floor((-start_gap(mu) - top) / DLAM))
    lattice = DLAM * np.arange(k0, k0 + 100000)
    log(f"mu {mu} n {n} sigma {sigma} seed {seed}: the highest asperity under the sphere {top:.3f}, "
        f"start {lattice[0]:.2f}")
    approach, disps = march(system, None, lattice, stop=lambda s: s["F"] >= F_STOP)
    back = [s["lam"] for s in approach[-2::-1]]
    retract, rdisps = march(system, disps[-1], back)
    retract, rdisps = [approach[-1]] + retract, [disps[-1]] + rdisps
    del disps
    # the pull-off: the lattice's most tensile retract state, then the finer steps about it
    i = int(np.argmin([s["F"] for s in retract]))
    fine = []
    if 0 < i < len(retract) - 1:
        lams = retract[i - 1]["lam"] - DLAM_FINE * np.arange(1, int(round(2 * DLAM / DLAM_FINE)))
        fine, _ = march(system, rdisps[i - 1], lams)
    best = min(retract + fine, key=lambda s: s["F"])
    out = dict(n=n, sigma=sigma, seed=seed, mu=mu, digest=digest(system.z), top_under_sphere=top,
               top=float(system.z.max()), pixel=system.h,
               approach={k: [s[k] for s in approach] for k in approach[0]},
               retract={k: [s[k] for s in retract] for k in retract[0]},
               pull_off=dict(F=best["F"], lam=best["lam"], F_lattice=retract[i]["F"], lam_lattice=retract[i]["lam"]),
               snap_on=largest_jump(approach), snap_off=largest_jump(retract),
               hysteresis=hysteresis(approach, retract),
               solves=system.solves, iterations=system.iterations,
               wall_time_s=time.perf_counter() - t0, cpu_time_s=time.process_time() - c0)
    log(f"  pull-off F {best['F']:.5f} at lambda {best['lam']:.3f} (lattice {retract[i]['F']:.5f}); "
        f"snap-on {out['snap_on'] and out['snap_on']['lam_from']}, snap-off "
        f"{out['snap_off'] and out['snap_off']['lam_from']}; hysteresis {out['hysteresis']:.4f}; "
        f"{system.solves} solves, {out['cpu_time_s']:.1f} s CPU")
    return out


def peer_retract(n: int, sigma: float, seed: int, lam_hi: float, lam_lo: float, log=print, mu: float = MU) -> dict:
    """The grid's refinement at a fifth of a curve's cost: the retraction alone, from a state in contact at
    lam_hi (a cold start, where the contact branch is the only state) down the lattice to lam_lo, the
    pull-off refined as :func:`peer_curve` does.  Run on both grids, its pull-off on the coarse one is the
    full curve's (the same branch), and the two grids' difference is the pixel's error."""
    t0, c0 = time.perf_counter(), time.process_time()
    system = PeerSystem(n, sigma, seed, mu=mu)
    lams = DLAM * np.arange(int(round(lam_hi / DLAM)), int(round(lam_lo / DLAM)) - 1, -1)
    retract, disps = march(system, None, lams)
    i = int(np.argmin([s["F"] for s in retract]))
    fine = []
    if 0 < i < len(retract) - 1:
        fine, _ = march(system, disps[i - 1],
                        retract[i - 1]["lam"] - DLAM_FINE * np.arange(1, int(round(2 * DLAM / DLAM_FINE))))
    best = min(retract + fine, key=lambda s: s["F"])
    out = dict(n=n, sigma=sigma, seed=seed, mu=mu, digest=digest(system.z), pixel=system.h, lam_hi=lam_hi,
               lam_lo=lam_lo,
               retract={k: [s[k] for s in retract] for k in retract[0]},
               pull_off=dict(F=best["F"], lam=best["lam"], F_lattice=retract[i]["F"], lam_lattice=retract[i]["lam"],
                             at_end=i in (0, len(retract) - 1)),
               solves=system.solves, iterations=system.iterations,
               wall_time_s=time.perf_counter() - t0, cpu_time_s=time.process_time() - c0)
    log(f"mu {mu} n {n} sigma {sigma} seed {seed} retract from {lam_hi}: pull-off F {best['F']:.5f} at lambda "
        f"{best['lam']:.3f}; {system.solves} solves, {out['cpu_time_s']:.1f} s CPU")
    return out


def hysteresis(approach, retract) -> float:
    """The energy of the displacement-controlled cycle, the integral of F_approach - F_retract over lambda
    on the shared lattice (trapezoid; units 2 pi R gamma epsilon)."""
    a = {round(l, 9): f for l, f in zip((s["lam"] for s in approach), (s["F"] for s in approach))}
    pts = sorted((s["lam"], a[round(s["lam"], 9)] - s["F"]) for s in retract if round(s["lam"], 9) in a)
    lam, d = np.array(pts).T
    return float(np.sum(0.5 * (d[1:] + d[:-1]) * np.diff(lam)))


def write_atomic(path: str, data: dict) -> None:
    """The JSON file whole or not at all: an earlier file is never damaged by a failed run."""
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".peer_rough.", suffix=".json")
    os.fchmod(fd, 0o644)
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(data, f, indent=1)
            f.write("\n")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _versions() -> dict:
    import importlib.metadata as md
    out = {}
    for p in ("ContactMechanics", "Adhesion", "SurfaceTopography", "muGrid", "NuMPI", "numpy", "scipy"):
        try:
            out[p] = md.version(p)
        except md.PackageNotFoundError:
            out[p] = None
    return out


def run_mu(run: dict) -> float:
    """A run's Tabor parameter: its own, or MU for the runs stored before the mu was a case's (they have none)."""
    return float(run.get("mu", MU))


def case_key(run: dict) -> tuple:
    """What names a run: (n, sigma, seed, mu); a later run of the same case replaces it."""
    return run["n"], run["sigma"], run["seed"], run_mu(run)


def _order(run: dict) -> tuple:
    return run_mu(run), run["sigma"], run["seed"], run["n"]


def _parse(option: str, text: str, fields: int):
    """``--cases``/``--retract``'s comma-separated cases of ``fields`` numbers and an optional mu > 0, or a
    one-line refusal naming the option (ValueError)."""
    accepts = {3: "n:sigma:seed[:mu]", 5: "n:sigma:seed:lam_hi:lam_lo[:mu]"}[fields]
    out = []
    for c in text.split(","):
        f = c.split(":")
        try:
            if len(f) not in (fields, fields + 1):
                raise ValueError
            vals = [int(f[0]), float(f[1]), int(f[2])] + [float(x) for x in f[3:fields]]
            mu = float(f[fields]) if len(f) > fields else MU
            if not (vals[0] > 2 * M_HI and vals[1] >= 0.0 and np.isfinite(mu) and mu > 0.0):
                raise ValueError
        except ValueError:
            raise ValueError(f"peer_rough.py: {option} accepts comma-separated {accepts} (n > {2 * M_HI}, "
                             f"sigma >= 0, mu > 0), not {c!r}") from None
        out.append(tuple(vals) + (mu,))
    return out


def peer_main(argv) -> int:
    """Their side: the curves asked for, each merged into the JSON file as it finishes."""
    p = argparse.ArgumentParser(prog="peer_rough.py peer")
    p.add_argument("--out", required=True)
    p.add_argument("--cases", default=None,
                   help="n:sigma:seed[:mu],...: these curves (mu: MU unless given; with neither option: every "
                        "curve at N_MAIN and MU, then the refinement)")
    p.add_argument("--retract", default=None,
                   help="n:sigma:seed:lam_hi:lam_lo[:mu],...: the retraction alone (the grid's refinement)")
    a = p.parse_args(argv)
    if a.retract is None and a.cases is None:     # the whole benchmark: the curves, then the refinement
        a.cases = ",".join(f"{N_MAIN}:{s}:{k}" for s in (0.0,) + SIGMAS for k in ((0,) if s == 0.0 else SEEDS))
        a.retract = ",".join(f"{n}:{s}:{k}:{hi}:{lo}" for s, k, hi, lo in REFINED for n in (N_MAIN, N_FINE))
    try:          # every case checked before the first is run: a bad one runs nothing
        cases = _parse("--cases", a.cases, 3) if a.cases else []
        retracts = _parse("--retract", a.retract, 5) if a.retract else []
    except ValueError as e:
        print(e, file=sys.stderr)
        return 2
    data = {"runs": [], "retract_runs": []}
    if os.path.exists(a.out):
        with open(a.out) as f:
            data = json.load(f)
    stamp = dict(mu=MU, L=L, modes=[M_LO, M_HI], hurst=HURST, dlam=DLAM, dlam_fine=DLAM_FINE, F_stop=F_STOP,
                 description="ContactMechanics + Adhesion: an explicit rough sphere (FFT free half-space, Lj82, "
                             "L-BFGS-B in displacement control); petsc_adhesion/benchmarks/peer_rough.py; "
                             "a run without its own mu is at the mu here")
    for n, s, k, mu in cases:
        run = peer_curve(n, s, k, mu=mu)
        run.update(versions=_versions(), date=time.strftime("%Y-%m-%dT%H:%M:%S%z"), loadavg=os.getloadavg())
        data["runs"] = sorted([r for r in data.get("runs", []) if case_key(r) != case_key(run)] + [run], key=_order)
        data.update(stamp)
        write_atomic(a.out, data)
    for n, s, k, hi, lo, mu in retracts:
        run = peer_retract(n, s, k, hi, lo, mu=mu)
        run.update(versions=_versions(), date=time.strftime("%Y-%m-%dT%H:%M:%S%z"), loadavg=os.getloadavg())
        data["retract_runs"] = sorted([r for r in data.get("retract_runs", []) if case_key(r) != case_key(run)]
                                      + [run], key=_order)
        data.update(stamp)
        write_atomic(a.out, data)
    return 0


def merge_main(argv) -> int:
    """``merge --out FILE A.json B.json ...``: the runs of several peer processes (each ran a part of the
    cases, ``--cases``) in one file; a later file's run replaces an earlier one's of the same case.  Every
    run is written with its mu (a part's runs without one are at that part's ``mu``, MU in the first files)."""
    p = argparse.ArgumentParser(prog="peer_rough.py merge")
    p.add_argument("--out", required=True)
    p.add_argument("parts", nargs="+")
    a = p.parse_args(argv)
    data: dict = {}
    runs: dict = {}
    retracts: dict = {}
    for part in a.parts:
        with open(part) as f:
            d = json.load(f)
        for kind, into in (("runs", runs), ("retract_runs", retracts)):
            for r in d.pop(kind, []):
                r.setdefault("mu", float(d.get("mu", MU)))
                into[case_key(r)] = r
        data.update(d)
    data["mu"] = MU
    data["runs"] = sorted(runs.values(), key=_order)
    data["retract_runs"] = sorted(retracts.values(), key=_order)
    write_atomic(a.out, data)
    return 0


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["peer"]:
        return peer_main(argv[1:])
    if argv[:1] == ["merge"]:
        return merge_main(argv[1:])
    print("peer_rough.py: the first argument is peer or merge (our side: python -m "
          "petsc_adhesion.benchmarks.mean_field)", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
