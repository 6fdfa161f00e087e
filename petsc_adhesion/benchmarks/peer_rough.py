"""docs/mean_field.md: how far the mean field holds, against explicit rough contacts solved by
ContactMechanics + Adhesion (the ContactEngineering codes) in an environment of their own.

The same sphere (mu = 1) on a few explicit rough surfaces.  Their side: an FFT elastic half-space (free,
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
    # their side, in their environment (about 15 CPU minutes; merged into the JSON after every curve):
    nice -n 10 .venv-peer/bin/python petsc_adhesion/benchmarks/peer_rough.py peer --out docs/data/peer_rough.json
    # ours, in ours (35 CPU seconds): docs/data/mean_field.json, the table docs/figures/mean_field.md, the figure
    # docs/figures/mean_field.png
    nice -n 10 python -m petsc_adhesion.benchmarks.peer_rough --data docs/data/peer_rough.json

(``.venv-peer`` is the user's to make, not part of the repository.)  The first command runs this file as a
script under the peer's interpreter: at module level it imports nothing but the standard library and numpy,
and the peer's packages and ours are imported inside the functions of each side.  The peer's cases can be
split over processes (``peer --cases 64:0.3:1,... --out part.json``, ``--retract``) and their files joined
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

#: Tabor parameter of every run.
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
#: The refinement: the smooth sphere and one rough surface (sigma, seed), their retraction alone from lam_hi
#: down to lam_lo (about the pull-off) on both grids.
REFINED = ((0.0, 0, 0.5, -1.4), (0.3, 2, 0.5, -1.6))
#: Displacement-control lattice step, the pull-off's refinement step, the approach's stop (the load at
#: equilibrium, past the pull-off), the start before the highest asperity under the sphere.
DLAM, DLAM_FINE, F_STOP, START_GAP = 0.05, 0.01, 0.0, 2.6
#: A step whose load changes by more than this is a jump (the largest on each leg: the snap).
JUMP_DF = 0.05
#: The linear core of the law below this gap (a line search guard, as peers.py; states are checked above it).
R_TI = 0.5


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

    def __init__(self, n: int, sigma: float, seed: int, gtol_rel: float = 1e-4):
        from Adhesion.Interactions import Lj82
        from Adhesion.System import SmoothContactSystem
        from ContactMechanics import FreeFFTElasticHalfSpace
        from SurfaceTopography import Topography
        self.n, self.sigma, self.seed = n, sigma, seed
        self.h = 2.0 * L / n
        x = -L + (np.arange(n) + 0.5) * self.h
        X, Y = np.meshgrid(x, x, indexing="ij")
        self.z = surface(n, sigma, seed)
        self.r = np.hypot(X, Y)
        topography = Topography(-(X ** 2 + Y ** 2) / 2.0 + self.z, physical_sizes=(2 * L, 2 * L))
        substrate = FreeFFTElasticHalfSpace((n, n), MU ** -1.5, physical_sizes=(2 * L, 2 * L))
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
        F_tail = far_field_load(lam, F_raw)
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


def peer_curve(n: int, sigma: float, seed: int, log=print) -> dict:
    """Approach from START_GAP before the highest asperity under the sphere (r < 2.5) until F >= F_STOP on a
    lattice of DLAM, retract on the same lattice to the start, the pull-off refined on DLAM_FINE about the
    lattice's most tensile state (warm-started down the retract leg from the state one step before it)."""
    t0, c0 = time.perf_counter(), time.process_time()
    system = PeerSystem(n, sigma, seed)
    top = float(system.z[system.r < 2.5].max())
    k0 = int(np.floor((-START_GAP - top) / DLAM))
    lattice = DLAM * np.arange(k0, k0 + 100000)
    log(f"n {n} sigma {sigma} seed {seed}: the highest asperity under the sphere {top:.3f}, "
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
    out = dict(n=n, sigma=sigma, seed=seed, digest=digest(system.z), top_under_sphere=top,
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


def peer_retract(n: int, sigma: float, seed: int, lam_hi: float, lam_lo: float, log=print) -> dict:
    """The grid's refinement at a fifth of a curve's cost: the retraction alone, from a state in contact at
    lam_hi (a cold start, where the contact branch is the only state) down the lattice to lam_lo, the
    pull-off refined as :func:`peer_curve` does.  Run on both grids, its pull-off on the coarse one is the
    full curve's (the same branch), and the two grids' difference is the pixel's error."""
    t0, c0 = time.perf_counter(), time.process_time()
    system = PeerSystem(n, sigma, seed)
    lams = DLAM * np.arange(int(round(lam_hi / DLAM)), int(round(lam_lo / DLAM)) - 1, -1)
    retract, disps = march(system, None, lams)
    i = int(np.argmin([s["F"] for s in retract]))
    fine = []
    if 0 < i < len(retract) - 1:
        fine, _ = march(system, disps[i - 1],
                        retract[i - 1]["lam"] - DLAM_FINE * np.arange(1, int(round(2 * DLAM / DLAM_FINE))))
    best = min(retract + fine, key=lambda s: s["F"])
    out = dict(n=n, sigma=sigma, seed=seed, digest=digest(system.z), pixel=system.h, lam_hi=lam_hi, lam_lo=lam_lo,
               retract={k: [s[k] for s in retract] for k in retract[0]},
               pull_off=dict(F=best["F"], lam=best["lam"], F_lattice=retract[i]["F"], lam_lattice=retract[i]["lam"],
                             at_end=i in (0, len(retract) - 1)),
               solves=system.solves, iterations=system.iterations,
               wall_time_s=time.perf_counter() - t0, cpu_time_s=time.process_time() - c0)
    log(f"n {n} sigma {sigma} seed {seed} retract from {lam_hi}: pull-off F {best['F']:.5f} at lambda "
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


def peer_main(argv) -> int:
    """Their side: the curves asked for, each merged into the JSON file as it finishes."""
    p = argparse.ArgumentParser(prog="peer_rough.py peer")
    p.add_argument("--out", required=True)
    p.add_argument("--cases", default=None,
                   help="n:sigma:seed,...: these curves (with neither option: every curve at N_MAIN, "
                        "then the refinement)")
    p.add_argument("--retract", default=None,
                   help="n:sigma:seed:lam_hi:lam_lo,...: the retraction alone (the grid's refinement)")
    a = p.parse_args(argv)
    if a.retract is None and a.cases is None:     # the whole benchmark: the curves, then the refinement
        peer_main(["--out", a.out, "--cases", ",".join(f"{N_MAIN}:{s}:{k}" for s in (0.0,) + SIGMAS
                                                       for k in ((0,) if s == 0.0 else SEEDS))])
        a.retract = ",".join(f"{n}:{s}:{k}:{hi}:{lo}" for s, k, hi, lo in REFINED for n in (N_MAIN, N_FINE))
    if a.retract:
        data = {"retract_runs": []}
        if os.path.exists(a.out):
            with open(a.out) as f:
                data = json.load(f)
        for c in a.retract.split(","):
            n, s, k, hi, lo = c.split(":")
            run = peer_retract(int(n), float(s), int(k), float(hi), float(lo))
            run.update(versions=_versions(), date=time.strftime("%Y-%m-%dT%H:%M:%S%z"), loadavg=os.getloadavg())
            data["retract_runs"] = [r for r in data.get("retract_runs", [])
                                    if (r["n"], r["sigma"], r["seed"]) != (run["n"], run["sigma"], run["seed"])]
            data["retract_runs"].append(run)
            write_atomic(a.out, data)
        return 0
    cases = [(int(n), float(s), int(k)) for n, s, k in (c.split(":") for c in a.cases.split(","))]
    data = {"runs": []}
    if os.path.exists(a.out):
        with open(a.out) as f:
            data = json.load(f)
    for n, s, k in cases:
        run = peer_curve(n, s, k)
        run.update(versions=_versions(), date=time.strftime("%Y-%m-%dT%H:%M:%S%z"), loadavg=os.getloadavg())
        data["runs"] = [r for r in data.get("runs", []) if (r["n"], r["sigma"], r["seed"]) != (n, s, k)]
        data["runs"].append(run)
        data["runs"].sort(key=lambda r: (r["sigma"], r["seed"], r["n"]))
        data.update(mu=MU, L=L, modes=[M_LO, M_HI], hurst=HURST, dlam=DLAM, dlam_fine=DLAM_FINE, F_stop=F_STOP,
                    description="ContactMechanics + Adhesion: an explicit rough sphere (FFT free half-space, Lj82, "
                                "L-BFGS-B in displacement control); petsc_adhesion/benchmarks/peer_rough.py")
        write_atomic(a.out, data)
    return 0


# ---- our side (the project's environment) ----

#: The footprint whose pixel heights make the local law: the sphere's contact up to F = 0 lies inside it.
FOOTPRINT = 2.5
#: Our curves stop past the equilibrium, where the peer's approach does (F_STOP).
OUR_F_MAX = 0.05


def _event(c, kind):
    ev = c.events_of(kind)
    return None if not ev else float(ev[0].lam.value)


def our_curve(mu: float = MU, sigma: float | None = None, **options) -> dict:
    """Our curve (no model spread: the laws are compared here one by one): the pull-off, the folds in
    lambda, the cycle's energy, the branch; and its CPU time."""
    from petsc_adhesion import curve
    from petsc_adhesion.tracing.measured import Measured
    c0 = time.process_time()
    c = curve(mu, sigma, cont_F_max=OUR_F_MAX, adh_model_spread=False, **options)
    energy = c.rigid.energy
    return dict(sigma=float(c.model.sigma), pull_off=dict(F=float(c.pull_off.F.value), err=float(c.pull_off.F.err),
                                                         lam=float(c.pull_off.lam.value)),
                snap_on=_event(c, "snap_on"), snap_off=_event(c, "snap_off"),
                hysteresis=float(energy.value) if isinstance(energy, Measured) else None,
                branch=dict(lam=c.lam.tolist(), F=c.F.tolist(), stable=c.branch.stable.tolist()),
                complete=bool(c.complete), warnings=list(c.warnings), cpu_time_s=time.process_time() - c0)


def ours_for(run: dict, tmp: str) -> dict:
    """The mean field of one peer surface: its pixel heights as the measured law (all of the square's, and
    the footprint's), the paper's Gaussian rule at its rms, the truncated Gaussian cut at its own top.  The
    surface is drawn again from its seed and must be the peer's (their digests)."""
    n, sigma, seed = run["n"], run["sigma"], run["seed"]
    z = surface(n, sigma, seed)
    if digest(z) != run["digest"]:
        raise RuntimeError(f"the surface n {n} sigma {sigma} seed {seed} is not the peer's (digest)")
    if sigma == 0.0:
        return dict(smooth=our_curve(sigma=0.0))
    x = -L + (np.arange(n) + 0.5) * (2.0 * L / n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    out = {}
    for name, heights in (("measured", z.ravel()), ("footprint", z[np.hypot(X, Y) < FOOTPRINT])):
        path = os.path.join(tmp, f"{name}.npy")
        np.save(path, heights)            # 1-D: read as they are (a 2-D map would be levelled by its plane)
        out[name] = our_curve(adh_roughness="measured", adh_roughness_file=path)
        out[name]["top"] = float(heights.max())
    return out


def gaussian_laws(sigma: float, tops) -> dict:
    """The paper's Gaussian rule (16-point Hermite) at rms sigma, and the truncated Gaussian cut at each
    surface's own highest height (K = top / sigma, two decimals; sigma that of the uncut Gaussian)."""
    out = {"hermite": our_curve(sigma=sigma)}
    for top in tops:
        K = round(top / sigma, 2)
        out[f"truncated:{K}"] = our_curve(sigma=sigma, adh_roughness="truncated_gaussian", adh_roughness_cutoff=K)
    return out


def ours_main(argv) -> int:
    """Our side of every peer run in the data file, written beside it (``mean_field.json``), then the table
    and the figure."""
    p = argparse.ArgumentParser(prog="python -m petsc_adhesion.benchmarks.peer_rough")
    p.add_argument("--data", default=os.path.join("docs", "data", "peer_rough.json"))
    p.add_argument("--ours", default=os.path.join("docs", "data", "mean_field.json"))
    p.add_argument("--figure", default=os.path.join("docs", "figures", "mean_field.png"))
    p.add_argument("--table", default=os.path.join("docs", "figures", "mean_field.md"))
    p.add_argument("--reuse", action="store_true", help="the table and figure from --ours as it is")
    a = p.parse_args(argv)
    with open(a.data) as f:
        peer = json.load(f)
    if a.reuse:
        with open(a.ours) as f:
            ours = json.load(f)
    else:
        ours = {"runs": {}, "gaussian": {}}
        with tempfile.TemporaryDirectory() as tmp:
            for run in peer["runs"]:
                key = f"{run['n']}:{run['sigma']}:{run['seed']}"
                ours["runs"][key] = ours_for(run, tmp)
                print(key, {k: round(v["pull_off"]["F"], 5) for k, v in ours["runs"][key].items()}, flush=True)
            ours["retract"] = {}
            for run in peer.get("retract_runs", []):
                key = f"{run['n']}:{run['sigma']}:{run['seed']}"
                ours["retract"][key] = ours_for(run, tmp)
            for sigma in sorted({r["sigma"] for r in peer["runs"] if r["sigma"] > 0 and r["n"] == N_MAIN}):
                tops = [r["top"] for r in peer["runs"] if r["sigma"] == sigma and r["n"] == N_MAIN]
                ours["gaussian"][str(sigma)] = gaussian_laws(sigma, tops)
        write_atomic(a.ours, ours)
    table = tables(peer, ours)
    d = os.path.dirname(os.path.abspath(a.table))
    fd, tmp = tempfile.mkstemp(dir=d, suffix=".md")
    with os.fdopen(fd, "w") as f:
        f.write(f"<!-- made by: python -m petsc_adhesion.benchmarks.peer_rough (docs/mean_field.md) -->\n{table}\n")
    os.chmod(tmp, 0o644)
    os.replace(tmp, a.table)
    figure(peer, ours, a.figure)
    print(table)
    return 0


def _stats(values):
    v = np.array([x for x in values if x is not None], float)
    if v.size == 0:
        return None
    return float(v.mean()), (float(v.std(ddof=1)) if v.size > 1 else None), float(v.min()), float(v.max())


def _ms(st, digits=4):
    if st is None:
        return "-"
    mean, sd, lo, hi = st
    return f"{mean:.{digits}f}" + ("" if sd is None else f" +- {sd:.{digits}f}")


#: Approach and retraction at one lambda on different branches: their loads differ by more than this (on one
#: branch, by the minimiser's tolerance, 2e-4 at most in these runs).
BISTABLE = 1e-3


def bistable(run: dict):
    """The explicit curve's bistable range on the lattice, (lowest, highest lambda), or None: the states
    where the approach and the retraction differ in load by more than BISTABLE."""
    a = {round(lam, 6): F for lam, F in zip(run["approach"]["lam"], run["approach"]["F"])}
    lams = [lam for lam, F in zip(run["retract"]["lam"], run["retract"]["F"])
            if round(lam, 6) in a and abs(a[round(lam, 6)] - F) > BISTABLE]
    return (min(lams), max(lams)) if lams else None


def tables(peer: dict, ours: dict) -> str:
    """The comparison, one row per rms: the explicit runs' mean and seed-to-seed spread, each mean field."""
    main = [r for r in peer["runs"] if r["n"] == N_MAIN and r["sigma"] > 0]
    lines = ["Pull-off F (load / (2 pi R gamma)) at mu = 1: the explicit runs' mean +- their seed-to-seed "
             "standard deviation (over the seeds of the second column), the mean field of each surface's own "
             "pixel heights (mean +- spread over the seeds): all of the square's and the footprint's "
             "(r < 2.5), the paper's Gaussian rule (16 points) at the same rms, the Gaussian cut at each "
             "surface's own top.", "",
             "| sigma (rms / epsilon) | seeds | explicit (ContactMechanics) | mean field, the square's heights | "
             "mean field, the footprint's heights | Gaussian rule, 16 points | Gaussian cut at the own top | "
             "highest height / rms |", "|---|---|---|---|---|---|---|---|"]
    for sigma in sorted({r["sigma"] for r in main}):
        rs = [r for r in main if r["sigma"] == sigma]
        keys = [f"{r['n']}:{r['sigma']}:{r['seed']}" for r in rs]
        g = ours["gaussian"][str(sigma)]
        trunc = [v["pull_off"]["F"] for k, v in g.items() if k.startswith("truncated")]
        lines.append(f"| {sigma:g} | {', '.join(str(r['seed']) for r in rs)} | "
                     f"{_ms(_stats([r['pull_off']['F'] for r in rs]))} | "
                     f"{_ms(_stats([ours['runs'][k]['measured']['pull_off']['F'] for k in keys]))} | "
                     f"{_ms(_stats([ours['runs'][k]['footprint']['pull_off']['F'] for k in keys]))} | "
                     f"{g['hermite']['pull_off']['F']:.4f} | {_ms(_stats(trunc))} | "
                     f"{_ms(_stats([r['top'] / sigma for r in rs]), 2)} |")
    lines += ["", "Snap-on and snap-off (lambda, approach / epsilon) and the hysteresis (the energy of the "
              "displacement-controlled cycle, 2 pi R gamma epsilon), surface by surface.  The explicit ones: the "
              f"lattice's bistable range (where approach and retraction differ by more than {BISTABLE:g} in load; "
              "on one branch they agree to 2e-4): the snap-on lies within DLAM = 0.05 above it, the snap-off "
              "within 0.05 below; 'none': no bistable state, the curve reversible.  The mean field's: its folds "
              "in lambda (of the square's heights).", "",
              "| sigma | seed | snap-on, explicit | snap-on, mean field | snap-off, explicit | snap-off, mean field | "
              "hysteresis, explicit | hysteresis, mean field |", "|---|---|---|---|---|---|---|---|"]
    for r in sorted(main, key=lambda r: (r["sigma"], r["seed"])):
        m = ours["runs"][f"{r['n']}:{r['sigma']}:{r['seed']}"]["measured"]
        b = bistable(r)
        on = "none" if b is None else f"{b[1]:.2f} to {b[1] + DLAM:.2f}"
        off = "none" if b is None else f"{b[0] - DLAM:.2f} to {b[0]:.2f}"

        def fold(x):
            return "none" if x is None else f"{x:.4f}"
        lines.append(f"| {r['sigma']:g} | {r['seed']} | {on} | {fold(m['snap_on'])} | {off} | {fold(m['snap_off'])} | "
                     f"{r['hysteresis']:.4f} | {m['hysteresis']:.4f} |")
    lines += ["", "The grid: the same continuous surfaces on 64 and 128 pixels a side (pixel 0.156 and "
              "0.078 sqrt(R epsilon)), the explicit retraction alone about the pull-off (from a state in contact), "
              "the full curve's pull-off on the same grid, and the mean field of each grid's pixel heights.", "",
              "| surface | pixels | explicit pull-off F (retraction) | its lambda | the full curve's | "
              "mean field (the square's heights) | CPU (s) |", "|---|---|---|---|---|---|---|"]
    for sigma, seed, _, _ in REFINED:
        full = {r["n"]: r for r in peer["runs"] if (r["sigma"], r["seed"]) == (sigma, seed)}
        for r in sorted((r for r in peer.get("retract_runs", []) if (r["sigma"], r["seed"]) == (sigma, seed)),
                        key=lambda r: r["n"]):
            o = ours["retract"][f"{r['n']}:{r['sigma']}:{r['seed']}"]
            mf = o["smooth" if sigma == 0.0 else "measured"]["pull_off"]
            name = "smooth" if sigma == 0.0 else f"sigma {sigma:g}, seed {seed}"
            f = full.get(r["n"])
            lines.append(f"| {name} | {r['n']} | {r['pull_off']['F']:.5f}"
                         + (" (at the range's end)" if r["pull_off"]["at_end"] else "")
                         + f" | {r['pull_off']['lam']:.3f} | " + (f"{f['pull_off']['F']:.5f}" if f else "-")
                         + f" | {mf['F']:.5f} +- {mf['err']:.0e} | {r['cpu_time_s']:.0f} |")
    cpu = sum(r["cpu_time_s"] for r in peer["runs"] + peer.get("retract_runs", []))
    mine = list(ours["runs"].values()) + list(ours.get("retract", {}).values()) + list(ours["gaussian"].values())
    ocpu = sum(v["cpu_time_s"] for o in mine for v in o.values())
    ver = peer["runs"][0]["versions"]
    every = peer["runs"] + peer.get("retract_runs", [])
    lines += ["", f"CPU time: the explicit runs {cpu / 60:.1f} min ({len(peer['runs'])} curves and "
              f"{len(every) - len(peer['runs'])} retractions, {sum(r['solves'] for r in every)} minimisations), "
              f"ours {ocpu:.0f} s ({sum(len(o) for o in mine)} curves); ContactMechanics "
              f"{ver['ContactMechanics']}, Adhesion {ver['Adhesion']}, muGrid {ver['muGrid']}, one core each, "
              f"the machine shared (load average "
              f"{min(r['loadavg'][0] for r in every):.0f} to {max(r['loadavg'][0] for r in every):.0f})."]
    return "\n".join(lines)


def _ours_of(ours: dict, runs, sigma: float, law: str) -> list:
    """Our curves under ``law`` for the peer runs at ``sigma``."""
    return [ours["runs"][f"{r['n']}:{r['sigma']}:{r['seed']}"][law] for r in runs if r["sigma"] == sigma]


def figure(peer: dict, ours: dict, path: str) -> None:
    """F(lambda) of the first seed at each rms: the explicit approach and retract against the mean field's
    branch (stable solid, unstable dotted) and the Gaussian rule's; and the pull-off against sigma."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    main = [r for r in peer["runs"] if r["n"] == N_MAIN]
    sigmas = sorted({r["sigma"] for r in main})
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5))
    for ax, sigma in zip(axes.flat, sigmas):
        r = min((r for r in main if r["sigma"] == sigma), key=lambda r: r["seed"])
        o = ours["runs"][f"{r['n']}:{r['sigma']}:{r['seed']}"]
        ax.plot(r["approach"]["lam"], r["approach"]["F"], "o", ms=2.5, color="C0", label="explicit, approach")
        ax.plot(r["retract"]["lam"], r["retract"]["F"], "s", ms=2.5, mfc="none", color="C3",
                label="explicit, retract")
        curves = [("mean field (own heights)", o["smooth" if sigma == 0 else "measured"]["branch"], "k")]
        if sigma > 0:
            curves.append(("Gaussian rule, 16 points", ours["gaussian"][str(sigma)]["hermite"]["branch"], "C2"))
        for label, b, col in curves:
            lam, F, st = (np.array(b[k]) for k in ("lam", "F", "stable"))
            ax.plot(lam, np.where(st, F, np.nan), "-", color=col, lw=1.2, label=label)
            ax.plot(lam, np.where(st, np.nan, F), ":", color=col, lw=1.0)
        lo = min(r["approach"]["lam"])
        ax.set_xlim(lo, max(r["approach"]["lam"]) + 0.1)
        ax.set_ylim(min(min(r["retract"]["F"]), o[next(iter(o))]["pull_off"]["F"]) * 1.15 - 0.02, 0.05)
        ax.set_title(("smooth" if sigma == 0 else f"sigma = {sigma:g}, seed {r['seed']}") + ", mu = 1")
        ax.set_xlabel("lambda (approach / epsilon)")
        ax.set_ylabel("F / (2 pi R gamma)")
        ax.legend(fontsize=7, loc="lower left")
    ax = axes.flat[-1]
    rough = [s for s in sigmas if s > 0]
    ex = [_stats([r["pull_off"]["F"] for r in main if r["sigma"] == s]) for s in rough]
    ax.errorbar(rough, [-e[0] for e in ex], yerr=[np.nan if e[1] is None else e[1] for e in ex], fmt="o",
                color="C3", capsize=3,
                label="explicit (mean +- seed spread)")
    for label, get, fmt in (
            ("mean field, the square's heights", lambda s: _ours_of(ours, main, s, "measured"), "k-"),
            ("mean field, the footprint's heights", lambda s: _ours_of(ours, main, s, "footprint"), "k--"),
            ("Gaussian rule, 16 points", lambda s: [ours["gaussian"][str(s)]["hermite"]], "C2-"),
            ("Gaussian cut at the own top", lambda s: [v for k, v in ours["gaussian"][str(s)].items()
                                                       if k.startswith("truncated")], "C1-")):
        ax.plot(rough, [-np.mean([c["pull_off"]["F"] for c in get(s)]) for s in rough], fmt, marker=".", label=label)
    sm = [r for r in main if r["sigma"] == 0]
    if sm:
        ax.axhline(-sm[0]["pull_off"]["F"], color="0.6", lw=0.8, label="smooth sphere")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(rough, [f"{s:g}" for s in rough])
    ax.minorticks_off()
    ax.set_xlabel("sigma (rms / epsilon)")
    ax.set_ylabel("pull-off -F / (2 pi R gamma)")
    ax.set_title("pull-off against roughness, mu = 1")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def merge_main(argv) -> int:
    """``merge --out FILE A.json B.json ...``: the runs of several peer processes (each ran a part of the
    cases, ``--cases``) in one file; a later file's run replaces an earlier one's of the same case."""
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
        runs.update({(r["n"], r["sigma"], r["seed"]): r for r in d.pop("runs", [])})
        retracts.update({(r["n"], r["sigma"], r["seed"]): r for r in d.pop("retract_runs", [])})
        data.update(d)
    data["runs"] = sorted(runs.values(), key=lambda r: (r["sigma"], r["seed"], r["n"]))
    data["retract_runs"] = sorted(retracts.values(), key=lambda r: (r["sigma"], r["seed"], r["n"]))
    write_atomic(a.out, data)
    return 0


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["peer"]:
        return peer_main(argv[1:])
    if argv[:1] == ["merge"]:
        return merge_main(argv[1:])
    return ours_main(argv)


if __name__ == "__main__":
    sys.exit(main())
