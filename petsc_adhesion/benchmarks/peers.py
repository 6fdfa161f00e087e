"""Peer benchmark: the same sphere-on-flat Lennard-Jones problem solved with
ContactMechanics + Adhesion (the ContactEngineering codes on PyPI).

Standalone script.  It does NOT import ``petsc_adhesion`` or ``petsc4py`` and
must run under its own virtual environment, never the project's::

    python3 -m venv .venv-peers
    .venv-peers/bin/pip install contactmechanics adhesion
    export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
    P=".venv-peers/bin/python petsc_adhesion/benchmarks/peers.py \\
       --out docs/data/peer_contactmechanics.json"
    $P --mu 1 --n 64,128,256                           # benchmark table
    $P --mu 2,0.5 --n 64,128,256
    $P --mu 1 --n 128 --gtol-rel 1e-6 --tag check-gtol   # sensitivity checks
    $P --mu 1 --n 128 --maxcor 10 --tag check-maxcor
    $P --mu 1,2 --n 128 --dlam 0.05 --tag check-dlam

(``.venv-peers`` is the user's to create and is not part of the repository.)
Each (mu, n) curve is merged into the JSON file (a run with the same tag, mu,
n, L, step and tolerances replaces the old entry) and the file is rewritten
atomically after every curve, so these commands regenerate
``docs/data/peer_contactmechanics.json`` as stored (about 45 minutes of one
core; a curve takes 10 s to 15 min, see ``cpu_time_s``).  Runs tagged
"main" form the benchmark table; the "check-*" runs measure the dependence
on the minimiser tolerance, its memory and the load step.

What it computes
----------------
For each Tabor parameter mu and grid size n, the load-displacement curve that
a ContactMechanics/Adhesion user obtains by energy minimisation in
displacement control: the rigid-body offset is stepped from far apart into
contact (approach) and back out (retraction); at every step the total energy
(elastic + interaction) is minimised, warm-started from the previous step's
displacement field, so the computed state follows a stable branch and jumps to
the other branch where that branch ends (a fold).  The unstable branch is
never computed.  Recorded per curve:

* the load path F(lambda), approach and retraction separately;
* the load-controlled pull-off F_p: the most tensile load on the computed
  path, refined by parabolic interpolation on the retraction branch (see
  below), and the raw path minimum;
* the lambda brackets of the jump-in (approach) and jump-out (retraction);
* wall time and process CPU time for the whole curve, number of minimiser
  iterations and function evaluations, load average, package versions, CPU.

Unit mapping (exact)
-----------------------------------------------
R = epsilon = gamma = 1, so lengths in the plane are in sqrt(R epsilon) = 1
and gaps in epsilon = 1.  The package's contact modulus is
E* = mu^(-3/2) (its Green's function is u = (1 / (pi E*)) int p / r, and
mu = (R gamma^2 / (E*^2 epsilon^3))^(1/3)).  Interaction
``Adhesion.Interactions.Lj82(w=1, z0=1)``: energy per area
W(g) = -(4/3) (1/g)^2 + (1/3) (1/g)^8, i.e. the traction
(8/3) [(1/g)^9 - (1/g)^3] of the project (repulsion positive).  Heights
-(x^2 + y^2) / 2 at the pixel centres x_i = -L + (i + 1/2) h, h = 2L/n, of a
symmetric n x n grid on [-L, L]^2; ``FreeFFTElasticHalfSpace`` (zero padding
to 2n x 2n, non-periodic); ``SmoothContactSystem``.  The package's gap is
u - heights - offset, the project's r^2/2 + u + 1 - lambda, so

    lambda = offset + 1,     F = compute_normal_force() / (2 pi)

(``compute_normal_force`` is the sum of the interaction forces per pixel,
repulsion positive; the project's F < 0 is attraction and has the same sign
convention, checked by the far-apart state, which is attractive, F < 0).

Far field
---------
The traction outside the square [-L, L]^2 is missing from the package's
force.  It is added analytically to every state:

    F_tail = (8 / 2 pi) int_0^{pi/4} int_{L / cos t}^inf s(g(r)) r dr dt,
    s(g) = (8/3) (g^-9 - g^-3),  g(r) = r^2/2 + 1 - lambda + 2 F_raw mu^{3/2} / r,

the last term being the surface displacement of the net load at distance r
(Boussinesq, first order).  The JSON stores F_raw (the package's value),
F_tail and F = F_raw + F_tail (F_tail = -1.01e-3 to -1.07e-3 at the
pull-off for mu = 0.5 to 2).  Not corrected: the missing traction would also
pull the surface inside the square towards the sphere, by about
(mu^{3/2} / pi) int_outside s / r dA = 0.7e-4, 2.1e-4 and 5.5e-4 epsilon at
the centre for mu = 0.5, 1, 2 (at the pull-off); that acts as an extra
approach, so the package's lambda of an event (pull-off, jumps) exceeds the
full-plane value by about that much, while F_p, a stationary value, changes
only at second order.

Choices
-------
* L = 7.5 (sqrt(R epsilon)): the rigid-gap tail is (4/3) / (L^2/2 + 1 -
  lambda)^2 ~ 1.5e-3 for the disc r > L, less for the square, and is added as
  above; the zone with gap < 1.2 (the peak-stress gap) has radius < 2.6
  up to lambda_max = 0.5 for mu <= 2, below L/2, so
  the zero-padded free boundary is far from the contact; a larger L at the
  same n would coarsen h = 2L/n, which dominates the error.
* Minimiser: the package's ``SmoothContactSystem.minimize_proxy`` (scipy
  L-BFGS-B on the energy with its gradient) with the settings of the
  package's own example ``examples/adhesive_simulation_sphere.py``:
  ``ftol = 0`` (stop on the gradient only), ``maxcor = 3``,
  ``gtol = gtol_rel * max_tensile * area_per_pt`` with gtol_rel = 1e-4 (the
  largest pixel force imbalance, relative to the peak LJ stress 1.0264 acting
  on one pixel).  At mu = 1, n = 128, gtol_rel = 1e-6 or maxcor = 10 change
  the pull-off by 1e-6 and leave the jump brackets unchanged; dlam = 0.05
  gives the same pull-off and brackets nested in those of dlam = 0.1 (runs
  tagged "check-*" in the JSON).
* Line-search guard: ``Lj82(1, 1).linearize_core(r_ti=0.5)`` replaces the
  law by its tangent for gaps below 0.5 epsilon, so that a trial step of the
  line search cannot cross g = 0 (where the 8-2 energy is symmetric).  Every
  converged state is checked to have min gap > r_ti (``min_gap`` in the JSON),
  so all reported states are states of the exact Lj82 law.
* Load steps: lambda lattice lambda_start + k * dlam (default dlam = 0.1),
  identical on approach and retraction; a step whose load change exceeds
  dF_max (default 0.04) is halved and retried from the last accepted state
  (step halving on the branch it is on), down to dlam_min = dlam / 64.  A step
  at dlam_min whose load still changes by more than dF_max is a jump: its
  bracket [last state on the old branch, first state on the new] is at most
  dlam / 64 = 0.0016 wide.  After a halved step the step doubles again,
  snapping back onto the lattice.  A jump that changes the smallest gap by
  more than 0.25 epsilon goes into or out of contact (``jump_in``,
  ``jump_out``); smaller jumps (load changes of a few 1e-2 with the smallest
  gap nearly unchanged) are the contact edge hopping from one ring of pixels
  to the next: lattice trapping, counted in ``lattice_jumps`` and listed in
  ``all_jumps``.
* Approach from lambda_start (default -(1.5 + 1.5 mu), beyond the jump-out,
  where only the non-contact state exists; u = 0 initial guess) to
  lambda_max (default 0.5, past the pull-off); retraction back to
  lambda_start, or to 0.5 beyond the jump-out once it has happened.
* Pull-off refinement: the three retraction states around the smallest F
  (lattice spacing) define a parabola; its vertex is computed (warm start from
  the smallest state), then a second parabola through the three best states.
  F_p is the smallest load among all computed states (path + refinement);
  ``pulloff_path`` is the minimum over the lattice path alone.

Caveats a reader must know: the jump brackets are brackets of where the
*minimiser* leaves the branch; close to a fold the energy is flat, L-BFGS-B
converges slowly and gtol decides how close to the fold a state is still
accepted.  The pixel lattice breaks the axial symmetry: the contact edge is
lattice-trapped, F(lambda) is wiggly on the scale h, the pull-off lambda
moves with n by more than the pull-off load does, and on a coarse grid
(h = 0.23 at n = 64, mu = 2) the trapped states carry more tension than the
continuum (pull-off too tensile by 0.02) and the jump-out moves.  Wall times
depend on the load of the (shared) machine; cpu_time_s is the process time.
"""

import argparse
import importlib.metadata
import json
import os
import platform
import sys
import tempfile
import time

import numpy as np
from Adhesion.Interactions import Lj82
from Adhesion.System import SmoothContactSystem
from ContactMechanics import FreeFFTElasticHalfSpace
from scipy.integrate import quad
from SurfaceTopography import Topography

# A jump changing the smallest gap by more than this (epsilon) goes into or
# out of contact; smaller jumps are lattice hops of the contact edge.
CONTACT_JUMP_GAP = 0.25

# The commands that regenerate docs/data/peer_contactmechanics.json (run
# from the repository root with OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=1).
REGENERATE = [
    "python3 -m venv .venv-peers && .venv-peers/bin/pip install "
    "contactmechanics adhesion",
] + [".venv-peers/bin/python petsc_adhesion/benchmarks/peers.py "
     "--out docs/data/peer_contactmechanics.json " + args for args in (
         "--mu 1 --n 64,128,256",
         "--mu 2,0.5 --n 64,128,256",
         "--mu 1 --n 128 --gtol-rel 1e-6 --tag check-gtol",
         "--mu 1 --n 128 --maxcor 10 --tag check-maxcor",
         "--mu 1,2 --n 128 --dlam 0.05 --tag check-dlam")]

PACKAGES = ("ContactMechanics", "Adhesion", "SurfaceTopography", "muGrid",
            "NuMPI", "numpy", "scipy")

# Project's values (half-infinite domain / paper grid), for the comparison
# printed at the end of each curve; not used in the computation.
OURS = {1.0: dict(F_p=-0.83484, lam_p=-0.8734, snap_on=-1.62917,
                  snap_off=-1.74350),
        2.0: dict(F_p=-0.79133, lam_p=-1.65817, snap_on=-2.55174,
                  snap_off=-3.38163),
        0.5: dict(F_p=-0.89324, lam_p=-0.44703, snap_on=None,
                  snap_off=None)}


def lj_traction(g):
    """Project's traction (8/3)(g^-9 - g^-3), repulsion positive, gap g in eps."""
    return (8.0 / 3.0) * (g ** -9 - g ** -3)


def far_field_load(lam, L, F_raw, mu):
    """Load (units 2 pi R gamma) of the traction outside the square [-L, L]^2.

    8-fold symmetry: outside the square in the octant 0 <= t <= pi/4 is
    r > L / cos t.  Gap: rigid r^2/2 + 1 - lambda plus the Boussinesq
    displacement 2 F_raw mu^{3/2} / r of the net load.
    """
    c = 2.0 * F_raw * mu ** 1.5

    def inner(t):
        r0 = L / np.cos(t)
        val, _ = quad(lambda r: lj_traction(0.5 * r * r + 1.0 - lam + c / r) * r,
                      r0, np.inf, epsabs=1e-13, epsrel=1e-10, limit=200)
        return val

    val, _ = quad(inner, 0.0, np.pi / 4, epsabs=1e-13, epsrel=1e-10)
    return 8.0 * val / (2.0 * np.pi)


class PeerCurve:
    """One ContactMechanics/Adhesion system (mu, n, L) and its minimiser."""

    def __init__(self, mu, n, L, gtol_rel=1e-4, maxcor=3, r_ti=0.5,
                 maxiter=20000):
        self.mu, self.n, self.L = float(mu), int(n), float(L)
        self.h = 2.0 * L / n
        x = -L + (np.arange(n) + 0.5) * self.h
        X, Y = np.meshgrid(x, x, indexing="ij")
        topography = Topography(-(X ** 2 + Y ** 2) / 2.0,
                                physical_sizes=(2 * L, 2 * L))
        substrate = FreeFFTElasticHalfSpace((n, n), self.mu ** -1.5,
                                            physical_sizes=(2 * L, 2 * L))
        self.r_ti = r_ti
        self.interaction = Lj82(1.0, 1.0).linearize_core(r_ti=r_ti)
        self.system = SmoothContactSystem(substrate, self.interaction,
                                          topography)
        self.gtol = gtol_rel * abs(self.interaction.max_tensile) \
            * self.system.area_per_pt
        self.options = dict(gtol=self.gtol, ftol=0.0, maxcor=maxcor,
                            maxiter=maxiter, maxfun=2 * maxiter)
        self.nit = 0
        self.nfev = 0
        self.nsolve = 0

    def solve(self, lam, disp0):
        """Minimise the energy at lambda from disp0; return state dict, disp."""
        res = self.system.minimize_proxy(offset=lam - 1.0,
                                         initial_displacements=disp0,
                                         options=self.options)
        if not res.success:
            raise RuntimeError(f"L-BFGS-B failed at lambda={lam}: {res.message}")
        self.nit += int(res.nit)
        self.nfev += int(res.nfev)
        self.nsolve += 1
        F_raw = float(self.system.compute_normal_force()) / (2.0 * np.pi)
        min_gap = float(self.system.gap.min())
        if min_gap <= self.r_ti:
            raise RuntimeError(f"state at lambda={lam} touches the linear core "
                               f"(min gap {min_gap})")
        F_tail = far_field_load(lam, self.L, F_raw, self.mu)
        state = dict(lam=float(lam), F=F_raw + F_tail, F_raw=F_raw,
                     F_tail=F_tail, nit=int(res.nit), nfev=int(res.nfev),
                     min_gap=min_gap)
        return state, self.system.disp.copy()


def march(curve, lam0, disp0, F0, g0, lattice, direction, dF_max, dlam_min,
          stop_after_jump=None, log=print):
    """Step lambda through the lattice points in `lattice` (in order).

    Step halving when |dF| > dF_max; a step of dlam_min with |dF| > dF_max is
    recorded as a jump.  A jump whose smallest gap changes by more than
    CONTACT_JUMP_GAP is a jump into or out of contact ("contact"); a smaller
    one is the contact edge hopping between pixel rings ("lattice").  The
    march stops `stop_after_jump` beyond the first contact jump.  Returns
    (states, jumps, last disp, disp of the accepted lattice state with the
    smallest F).
    """
    states, jumps = [], []
    best = (np.inf, None)
    lam_c, disp_c, F_c, g_c = lam0, disp0, F0, g0
    k = 0
    step = None
    stop_at = None
    while k < len(lattice):
        target_lattice = lattice[k]
        full = abs(target_lattice - lam_c)
        s = full if step is None else min(full, 2.0 * step)
        while True:
            lam_t = lam_c + direction * s
            lam_t = round(lam_t, 12)
            if abs(lam_t - target_lattice) < 1e-10:
                lam_t = target_lattice
            st, disp_t = curve.solve(lam_t, disp_c)
            dF = st["F"] - F_c
            if abs(dF) <= dF_max:
                break
            if s <= dlam_min * (1 + 1e-9):
                kind = "contact" if abs(st["min_gap"] - g_c) \
                    > CONTACT_JUMP_GAP else "lattice"
                jumps.append(dict(kind=kind, lam_from=lam_c, lam_to=lam_t,
                                  F_from=F_c, F_to=st["F"],
                                  min_gap_from=g_c, min_gap_to=st["min_gap"],
                                  width=abs(lam_t - lam_c)))
                log(f"    {kind} jump between lambda {lam_c:.5f} and "
                    f"{lam_t:.5f}: F {F_c:.5f} -> {st['F']:.5f}, min gap "
                    f"{g_c:.4f} -> {st['min_gap']:.4f}")
                break
            s = 0.5 * s
        step = s
        st["step"] = s
        states.append(st)
        lam_c, disp_c, F_c, g_c = st["lam"], disp_t, st["F"], st["min_gap"]
        log(f"    lambda {lam_c:+.5f}  F {F_c:+.6f}  nit {st['nit']:4d}  "
            f"min gap {st['min_gap']:.4f}")
        if lam_c == target_lattice:
            k += 1
            if F_c < best[0]:
                best = (F_c, disp_c)
        if stop_after_jump is not None and stop_at is None and \
                any(j["kind"] == "contact" for j in jumps):
            stop_at = lam_c + direction * stop_after_jump
        if stop_at is not None and direction * (lam_c - stop_at) >= -1e-12:
            break
    return states, jumps, disp_c, best[1]


def parabola_vertex(l, f):
    (l0, l1, l2), (f0, f1, f2) = l, f
    den = (l0 - l1) * (l0 - l2) * (l1 - l2)
    a = (l2 * (f1 - f0) + l1 * (f0 - f2) + l0 * (f2 - f1)) / den
    b = (l2 ** 2 * (f0 - f1) + l1 ** 2 * (f2 - f0) + l0 ** 2 * (f1 - f2)) / den
    return -b / (2 * a)


def run_curve(mu, n, L, dlam, lam_start, lam_max, dF_max, dlam_min_div,
              gtol_rel, maxcor, log=print):
    curve = PeerCurve(mu, n, L, gtol_rel=gtol_rel, maxcor=maxcor)
    dlam_min = dlam / dlam_min_div
    nk = int(round((lam_max - lam_start) / dlam))
    lattice = [round(lam_start + k * dlam, 12) for k in range(nk + 1)]
    load0 = os.getloadavg()
    t0, c0 = time.perf_counter(), time.process_time()

    log(f"mu={mu} n={n} L={L} h={curve.h:.5f} approach")
    st0, disp = curve.solve(lattice[0], None)
    st0["step"] = 0.0
    app, jin, disp, _ = march(curve, st0["lam"], disp, st0["F"],
                              st0["min_gap"], lattice[1:],
                           +1, dF_max, dlam_min, log=log)
    app = [st0] + app
    log("  retraction")
    ret, jout, _, disp_best = march(curve, app[-1]["lam"], disp, app[-1]["F"],
                                    app[-1]["min_gap"], lattice[-2::-1], -1, dF_max, dlam_min,
                         stop_after_jump=0.5, log=log)
    ret = [app[-1]] + ret

    # Pull-off: parabolic refinement on the retraction branch (lattice states).
    lat = {round(x, 10) for x in lattice}
    retl = [s for s in ret if round(s["lam"], 10) in lat]
    path = app + ret
    i = int(np.argmin([s["F"] for s in retl]))
    path_min = min(path, key=lambda s: s["F"])
    refine = []
    if 0 < i < len(retl) - 1:
        pts = retl[i - 1:i + 2]
        disp_i = disp_best  # warm start: the lattice minimum state
        for _ in range(2):
            lv = parabola_vertex([p["lam"] for p in pts], [p["F"] for p in pts])
            st, disp_v = curve.solve(lv, disp_i)
            refine.append(st)
            log(f"  pull-off refinement lambda {lv:+.6f}  F {st['F']:+.7f}")
            pts = sorted(pts + [st], key=lambda s: s["F"])[:3]
            pts.sort(key=lambda s: s["lam"])
            disp_i = disp_v
    best = min(path + refine, key=lambda s: s["F"])
    wall = time.perf_counter() - t0
    cpu = time.process_time() - c0
    load1 = os.getloadavg()

    def jumpd(js):
        js = [j for j in js if j["kind"] == "contact"]
        if not js:
            return None
        j = js[0]
        return dict(j, lam_lo=min(j["lam_from"], j["lam_to"]),
                    lam_hi=max(j["lam_from"], j["lam_to"]))

    def cols(states):
        keys = ("lam", "F", "F_raw", "F_tail", "nit", "min_gap")
        return {k: [s[k] for s in states] for k in keys}

    out = dict(
        mu=mu, n=n, L=L, h=curve.h, padded_grid=[2 * n, 2 * n],
        contact_modulus=mu ** -1.5,
        dlam=dlam, dlam_min=dlam_min, dF_max=dF_max,
        lam_start=lam_start, lam_max=lam_max,
        minimiser=dict(method="L-BFGS-B via SmoothContactSystem.minimize_proxy",
                       gtol_rel=gtol_rel, gtol=curve.gtol, ftol=0.0,
                       maxcor=maxcor, line_search_guard_r_ti=curve.r_ti),
        pulloff=dict(F=best["F"], lam=best["lam"], F_raw=best["F_raw"],
                     F_tail=best["F_tail"]),
        pulloff_path=dict(F=path_min["F"], lam=path_min["lam"],
                          F_raw=path_min["F_raw"], F_tail=path_min["F_tail"]),
        pulloff_refinement=cols(refine),
        jump_in=jumpd(jin), jump_out=jumpd(jout),
        all_jumps=dict(approach=jin, retraction=jout),
        lattice_jumps=dict(approach=sum(j["kind"] == "lattice" for j in jin),
                           retraction=sum(j["kind"] == "lattice" for j in jout)),
        approach=cols(app), retraction=cols(ret),
        wall_time_s=wall, cpu_time_s=cpu,
        minimiser_calls=curve.nsolve, minimiser_iterations=curve.nit,
        function_evaluations=curve.nfev,
        loadavg_start=list(load0), loadavg_end=list(load1),
    )
    ours = OURS.get(float(mu))
    log(f"  pull-off F = {best['F']:.6f} (raw {best['F_raw']:.6f}, tail "
        f"{best['F_tail']:.2e}) at lambda = {best['lam']:.5f}"
        + (f"; ours {ours['F_p']} at {ours['lam_p']}" if ours else ""))
    log(f"  jump-in {out['jump_in'] and [out['jump_in']['lam_lo'], out['jump_in']['lam_hi']]}"
        f", jump-out {out['jump_out'] and [out['jump_out']['lam_lo'], out['jump_out']['lam_hi']]}"
        + (f"; ours snap-on {ours['snap_on']}, snap-off {ours['snap_off']}" if ours else ""))
    log(f"  wall {wall:.1f} s, cpu {cpu:.1f} s, {curve.nsolve} minimisations, "
        f"{curve.nit} iterations")
    return out


def machine():
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return dict(cpu=cpu, cores=os.cpu_count(), python=platform.python_version(),
                platform=platform.platform(),
                OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS"),
                OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS"))


def versions():
    v = {}
    for p in PACKAGES:
        try:
            v[p] = importlib.metadata.version(p)
        except importlib.metadata.PackageNotFoundError:
            v[p] = None
    return v


def write_atomic(path, data):
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".peer_cm.", suffix=".json")
    umask = os.umask(0)
    os.umask(umask)
    os.fchmod(fd, 0o666 & ~umask)  # mkstemp makes 0600; a data file is 0644
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(data, f, indent=1)
            f.write("\n")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def key(run):
    return (run.get("tag"), run["mu"], run["n"], run["L"], run["dlam"],
            run["minimiser"]["gtol_rel"], run["minimiser"]["maxcor"])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--mu", default="1", help="comma list of Tabor parameters")
    p.add_argument("--n", default="64,128,256", help="comma list of grid sizes")
    p.add_argument("--L", type=float, default=7.5,
                   help="half width of the square, sqrt(R eps)")
    p.add_argument("--dlam", type=float, default=0.1, help="lattice step")
    p.add_argument("--halvings", type=int, default=64,
                   help="dlam_min = dlam / HALVINGS (a power of 2)")
    p.add_argument("--dF-max", type=float, default=0.04,
                   help="largest load change of an accepted step")
    p.add_argument("--lam-start", type=float, default=None,
                   help="default -(1.5 + 1.5 mu)")
    p.add_argument("--lam-max", type=float, default=0.5)
    p.add_argument("--gtol-rel", type=float, default=1e-4)
    p.add_argument("--maxcor", type=int, default=3)
    p.add_argument("--tag", default="main",
                   help="'main' for the benchmark table; other tags mark "
                        "sensitivity checks (tolerance, load step)")
    p.add_argument("--out", default=None, help="JSON file (merged, atomic)")
    a = p.parse_args(argv)

    data = {"runs": []}
    if a.out and os.path.exists(a.out):
        with open(a.out) as f:
            data = json.load(f)
    data.update(
        description=("ContactMechanics + Adhesion (FFT half-space, L-BFGS-B "
                     "energy minimisation in displacement control) on the "
                     "project's smooth sphere / Lennard-Jones problem; "
                     "made by petsc_adhesion/benchmarks/peers.py, see "
                     "its docstring for units and choices"),
        units=dict(lam="approach / epsilon (lambda = offset + 1)",
                   F="load / (2 pi R gamma), F < 0 attraction, includes F_tail",
                   F_raw="compute_normal_force() / (2 pi), traction in [-L, L]^2 only",
                   F_tail="analytic traction outside [-L, L]^2",
                   L="sqrt(R epsilon)", h="sqrt(R epsilon)"),
        regenerate=REGENERATE,
    )
    data.pop("command", None)
    command = " ".join(["python", "petsc_adhesion/benchmarks/peers.py"]
                       + (sys.argv[1:] if argv is None else list(argv)))
    for mu in [float(x) for x in a.mu.split(",")]:
        for n in [int(x) for x in a.n.split(",")]:
            lam_start = a.lam_start if a.lam_start is not None \
                else -(1.5 + 1.5 * mu)
            run = run_curve(mu, n, a.L, a.dlam, lam_start, a.lam_max,
                            a.dF_max, a.halvings, a.gtol_rel, a.maxcor)
            run["versions"] = versions()
            run["machine"] = machine()
            run["date"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
            run["command"] = command
            run["tag"] = a.tag
            if a.out:
                if os.path.exists(a.out):
                    with open(a.out) as f:
                        data["runs"] = json.load(f).get("runs", [])
                data["runs"] = [r for r in data["runs"] if key(r) != key(run)]
                data["runs"].append(run)
                data["runs"].sort(key=lambda r: (r["tag"] != "main", r["tag"],
                                                 r["mu"], r["n"]))
                write_atomic(a.out, data)


if __name__ == "__main__":
    main()
