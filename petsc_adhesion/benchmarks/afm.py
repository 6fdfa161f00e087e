"""The figures and tables of docs/afm.md: from an AFM cantilever to the force-distance curve, its jumps and the
energy of a cycle.

    python -m petsc_adhesion.benchmarks.afm                      # all three, into docs/figures/afm_*.png and afm_*.md
    python -m petsc_adhesion.benchmarks.afm example radius       # some of them: example, stiffness, radius
    ./run figures afm_example afm_stiffness afm_radius           # the same, through the figures' command

- ``example`` (afm_example): a silicon-nitride tip (R = 20 nm) on a glass flat and on a polystyrene flat,
  gamma = 0.05 J/m^2, epsilon = 0.3 nm, behind cantilevers of k = 0.1, 1 and 10 N/m: the force against the
  base position Z in nN and nm with the jumps, and the table of the jumps, the pull-off and the energy of a
  cycle with their error bars.
- ``stiffness`` (afm_stiffness): the jump-in distance, the energy of a cycle and the jump-off force against
  the dimensionless stiffness K from 1e-3 to 10 for mu = 0.5, 1 and 3, with their limits: the rigid machine
  (K -> infinity), the load-controlled pull-off and the rigid sphere's jump-in (K -> 0).
- ``radius`` (afm_radius): the contact radius against the load along the curve for mu = 1 and 5 beside the
  closed forms of JKR, DMT and Maugis-Dugdale.

Each calls the library (:func:`~petsc_adhesion.tracing.trace.trace_curve`, one process, one rank) and the
closed forms of :mod:`petsc_adhesion.model.reference`; the run time of each is written under its table.
"""
from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

from .. import brent
from ..io.plot.curve import contact_load, force_distance
from ..io.plot.read import figure
from ..io.summary import branch_record, event_record
from ..model.parameters import Model
from ..model.physical import Bodies
from ..model.reference.jkr import jkr_load, jkr_zero_load
from ..model.reference.maugis_dugdale import maugis_dugdale_curve, maugis_parameter
from ..model.reference.rigid import rigid_load
from ..tracing.measured import Measured
from ..tracing.trace import CurveRequest, trace_curve
from . import paths

__all__ = ["COMMAND", "TIP", "FLATS", "CANTILEVERS", "STIFFNESSES", "MUS", "RADIUS_MUS", "bodies", "cantilever",
           "primary", "rigid_sphere_jump_in", "dmt_radius", "md_radius", "example", "stiffness", "radius",
           "FIGURES", "main"]

COMMAND = "python -m petsc_adhesion.benchmarks.afm"
#: The tip: a silicon-nitride-like apex (radius m, modulus Pa, Poisson's ratio), the work of adhesion (J/m^2)
#: and the equilibrium spacing (m).
TIP = {"radius": 20e-9, "young1": 150e9, "poisson1": 0.27, "gamma": 0.05, "epsilon": 0.3e-9}
#: The flats: name -> modulus and Poisson's ratio (a glass; polystyrene as docs/materials.md's [4]).
FLATS = {"glass": {"young2": 70e9, "poisson2": 0.17}, "polystyrene": {"young2": 3.0e9, "poisson2": 0.34}}
#: Spring constants of the cantilevers (N/m).
CANTILEVERS = (0.1, 1.0, 10.0)
#: Dimensionless stiffnesses K of the sweep: 1e-3 to 10, four a decade.
STIFFNESSES = tuple(float(k) for k in np.logspace(-3.0, 1.0, 17))
#: Tabor parameters of the sweep in K and of the contact-radius figure.
MUS = (0.5, 1.0, 3.0)
RADIUS_MUS = (0.1, 1.0, 5.0)
#: The events that get error bars behind a spring (the others are not needed by the figures).
JUMP_KINDS = ("jump_in", "jump_off")
RIGID_KINDS = ("snap_on", "snap_off", "F_min", "equilibrium")


def bodies(flat: str) -> Bodies:
    """The tip of :data:`TIP` on the flat ``flat`` of :data:`FLATS`."""
    return Bodies(**TIP, **FLATS[flat])


def cantilever(b: Bodies, k: float, kinds: tuple | None = None):
    """The curve of the bodies ``b`` behind a cantilever of ``k`` N/m (K = k epsilon / (2 pi R gamma))."""
    return trace_curve(Model(mu=b.mu, bodies=b), request=CurveRequest(spring=b.spring_stiffness(k), kinds=kinds))


def primary(curve, kinds: tuple = JUMP_KINDS) -> tuple:
    """(first, last) turning points of a curve's control: behind a spring the jump-in reached first on
    approach (largest Z) and the jump-off reached last on retraction (smallest Z); with ``RIGID`` kinds
    (snap_on, snap_off), the same in lambda.  None where there is none."""
    on, off = kinds
    value = (lambda e: e.Z.value) if on == "jump_in" else (lambda e: e.lam.value)
    ins, offs = curve.events_of(on), curve.events_of(off)
    return max(ins, key=value, default=None), min(offs, key=value, default=None)


def rigid_sphere_jump_in(K: float) -> float | None:
    """The base position Z of a rigid sphere's (mu = 0, eq. 28) jump-in behind a spring K: where its load's
    slope dF/dlambda = 8/3 (g^-9 - g^-3), g = 1 - lambda, is -K on the far branch (g > 3^(1/6)); None for
    K >= 16 / (9 sqrt 3) = 1.026, where it has none."""
    peak = 3.0 ** (1.0 / 6.0)
    if K >= 16.0 / (9.0 * math.sqrt(3.0)):
        return None
    g = brent.root(lambda g: 8.0 / 3.0 * (g**-3 - g**-9) - K, peak, 1e6)
    lam = 1.0 - g
    return lam + float(rigid_load(lam)) / K


def dmt_radius(F, mu: float):
    """DMT's contact radius at load F: Hertz's under F + 1 (the DMT pull-off is -1).

    Hertz P = 4 E a^3 / (3 R) is, in the model's units (a in sqrt(epsilon R), F in 2 pi R gamma,
    mu of eq. 9), F = (2 / (3 pi)) A^3 mu^(-3/2) (the first term of :func:`jkr_load`); so
    A = ((3 pi / 2) mu^(3/2) (F + 1))^(1/3) for F >= -1.
    """
    F = np.asarray(F, dtype=float)
    return np.cbrt(1.5 * math.pi * mu**1.5 * np.maximum(F + 1.0, 0.0))


def md_radius(mu: float) -> dict:
    """Maugis-Dugdale's contact radius at its load-controlled pull-off and at zero load, and its (F, A) curve
    (``F``, ``A``: m - 1 from 1e-12 to 1e12)."""
    x = np.linspace(math.log(1e-12), math.log(1e12), 4001)
    A, F, _ = maugis_dugdale_curve(mu, 1.0 + np.exp(x))

    def load(y):
        return float(maugis_dugdale_curve(mu, 1.0 + math.exp(y))[1])

    i = int(np.argmin(F))
    y = brent.minimum(load, x[max(i - 1, 0)], x[min(i + 1, x.size - 1)], xatol=1e-10)
    pull = float(maugis_dugdale_curve(mu, 1.0 + math.exp(y))[0])
    # zero load on the branch of large contact (m near 1): the first sign change from there
    j = int(np.argmax(F < 0.0))
    zero = float(maugis_dugdale_curve(mu, 1.0 + math.exp(brent.root(load, x[j - 1], x[j])))[0])
    return {"pull_off": pull, "zero": zero, "F": F, "A": A}


def _res(curve) -> dict:
    """A curve as the plots read it."""
    return {"curve": branch_record(curve), "events": [event_record(e) for e in curve.events],
            "mu": curve.model.mu, "sigma": curve.model.sigma}


def _energy(cycle) -> tuple:
    """(energy, bar) of a cycle; (None, None) where it is missing."""
    return (cycle.energy.value, cycle.energy.err) if isinstance(cycle.energy, Measured) else (None, None)


def _pm(x, err, scale: float = 1.0, digits: int = 4) -> str:
    if x is None:
        return "-"
    return f"{x * scale:.{digits}f}" + ("" if err is None else f" +- {abs(err * scale):.1e}")


def _table(head, rows) -> str:
    return "\n".join(["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
                     + ["| " + " | ".join(r) + " |" for r in rows])


def _save(fig, name: str, table: str, seconds: float) -> None:
    """The figure NAME.png and its table NAME.md; ``seconds``: the CPU time it took (this process's: the curves
    are traced in it), not the wall time, which on a shared machine says more of the load than of the cost."""
    fig.tight_layout()
    fig.savefig(os.path.join(paths.FIGURES, f"{name}.png"), dpi=110)
    what = name.split("_", 1)[1]
    with open(os.path.join(paths.FIGURES, f"{name}.md"), "w") as f:
        f.write(f"<!-- made by: ./run figures {name} ({COMMAND} {what}) -->\n{table}\n\n"
                f"Made in {seconds:.0f} s of CPU on one core ({COMMAND} {what}).\n")


def example() -> None:
    """afm_example: the force-distance curves of the tip on glass and on polystyrene behind three cantilevers,
    and the table of their jumps, pull-off and energy."""
    t0 = time.process_time()
    fig = figure(figsize=(13.5, 7.6))
    axes = fig.subplots(len(FLATS), len(CANTILEVERS))
    rows = []
    for row, flat in zip(axes, FLATS):
        b = bodies(flat)
        d = b.describe()
        nm, nN, aJ = d["approach_nm"], d["force_nN"], d["work_aJ"]
        for ax, k in zip(row, CANTILEVERS):
            c = cantilever(b, k)
            jin, joff = primary(c)
            force_distance(ax, _res(c), label=f"k = {k:g} N/m (K = {b.spring_stiffness(k):.3g})",
                           scale=(nm, nN))
            F_po = c.pull_off.F.value
            # from below the jump-off's landing to where the contact pushes back as hard as the pull-off pulled
            Z, F = c.Z * nm, c.F * nN
            lo = min(e.landing.Z.value for e in c.events if e.kind in JUMP_KINDS and e.landing) * nm
            past = np.nonzero((F > -F_po * nN) & (Z > 0))[0]
            hi = Z[past[0]] if past.size else Z.max()
            ax.set_xlim(lo - 0.1 * (hi - lo), hi)
            ax.set_ylim(1.2 * F_po * nN, -1.1 * F_po * nN)
            ax.set_title(f"{flat} (mu = {b.mu:.3g}), k = {k:g} N/m", fontsize=9)
            ax.set_xlabel("base position Z (nm)")
            ax.set_ylabel("force (nN)")
            ax.legend(fontsize=7, loc="lower right")
            sp = c.spring
            rows.append([flat, f"{b.mu:.4f}", f"{k:g}", f"{b.spring_stiffness(k):.5f}",
                         _pm(jin.Z.value, jin.Z.err, nm) if jin else "no jump",
                         _pm(jin.F.value, jin.F.err, nN) if jin else "-",
                         _pm(jin.landing.F.value, jin.landing.F.err, nN) if jin else "-",
                         _pm(joff.Z.value, joff.Z.err, nm) if joff else "no jump",
                         _pm(joff.F.value, joff.F.err, nN) if joff else "-",
                         _pm(*_energy(sp.cycle), aJ, 3)])
        snap_on, snap_off = primary(c, ("snap_on", "snap_off"))
        rows.append([flat, f"{b.mu:.4f}", "limits", "",
                     "k -> infinity: " + (_pm(snap_on.lam.value, snap_on.lam.err, nm) + " (snap-on)" if snap_on else "none"),
                     "", "", "k -> infinity: " + (_pm(snap_off.lam.value, snap_off.lam.err, nm) + " (snap-off)"
                                                  if snap_off else "none"),
                     "k -> 0: " + _pm(c.pull_off.F.value, c.pull_off.F.err, nN) + " (load control)",
                     "k -> infinity: " + _pm(*_energy(c.rigid), aJ, 3) + " (rigid machine)"])
    table = _table(["flat", "mu", "k (N/m)", "K", "jump-in Z (nm)", "jump-in F (nN)", "lands at F (nN)",
                    "jump-off Z (nm)", "pull-off F (nN)", "energy of a cycle (aJ)"], rows)
    b = bodies("glass")
    d = b.describe()
    table += (f"\n\nTip R = {TIP['radius'] * 1e9:g} nm, E = {TIP['young1'] / 1e9:g} GPa, nu = {TIP['poisson1']:g}; "
              f"gamma = {TIP['gamma']:g} J/m^2, epsilon = {TIP['epsilon'] * 1e9:g} nm; glass E = 70 GPa, nu = 0.17; "
              f"polystyrene E = 3.0 GPa, nu = 0.34.  Units: force 2 pi R gamma = {d['force_nN']:.4f} nN, "
              f"length epsilon = {d['approach_nm']:g} nm, energy 2 pi R gamma epsilon = {d['work_aJ']:.4f} aJ; "
              f"K = k epsilon / (2 pi R gamma) = {b.spring_stiffness(1.0):.5f} k (k in N/m).  Z and lambda are 0 "
              "where the undeformed tip would sit at the equilibrium spacing epsilon from the flat, negative "
              "before it: the jump-in distance is -Z of the jump-in.")
    _save(fig, "afm_example", table, time.process_time() - t0)


def stiffness() -> None:
    """afm_stiffness: the jump-in distance, the energy of a cycle and the jump-off force against K for each mu
    of :data:`MUS`, with the limits K -> infinity (rigid machine) and K -> 0."""
    t0 = time.process_time()
    fig = figure(figsize=(15.0, 4.6))
    ax_in, ax_e, ax_off = fig.subplots(1, 3)
    Ks = np.array(STIFFNESSES)
    cols, lims, notes, pairs = {}, [], [], []
    for mu, color in zip(MUS, ("C0", "C1", "C2")):
        rigid = trace_curve(Model(mu=mu), request=CurveRequest(kinds=RIGID_KINDS))
        snap_on, snap_off = primary(rigid, ("snap_on", "snap_off"))
        po = rigid.pull_off
        got = []
        for K in Ks:
            c = trace_curve(Model(mu=mu), request=CurveRequest(spring=float(K), kinds=JUMP_KINDS))
            jin, joff = primary(c)
            if len(c.events_of("jump_in")) > 1:
                rest = [e.Z.value for e in c.events if e.kind in JUMP_KINDS and e is not jin and e is not joff]
                pairs.append((mu, K, max(rest) - min(rest)))
            bare = [e for e in c.events if e.kind in JUMP_KINDS and e.Z.err is None]
            if bare:
                notes.append(f"mu = {mu:g}, K = {K:.4g}: no error bar on the "
                             + ", ".join(f"{e.kind} at Z = {e.Z.value:.5f}" for e in bare) + f" ({bare[0].note})")
            got.append((jin, joff, *_energy(c.spring.cycle)))
        cols[mu] = got
        have = [(K, g[0]) for K, g in zip(Ks, got) if g[0] is not None]
        ax_in.errorbar([K for K, _ in have], [-e.Z.value for _, e in have], yerr=[e.Z.err or 0 for _, e in have],
                       fmt="o-", ms=3, color=color, label=f"mu = {mu:g}")
        if snap_on:
            ax_in.axhline(-snap_on.lam.value, ls="--", color=color, lw=0.9)
        E = [(K, g[2], g[3]) for K, g in zip(Ks, got) if g[2]]
        ax_e.errorbar([x[0] for x in E], [x[1] for x in E], yerr=[x[2] or 0 for x in E], fmt="o-", ms=3,
                      color=color, label=f"mu = {mu:g}")
        if _energy(rigid.rigid)[0]:
            ax_e.axhline(_energy(rigid.rigid)[0], ls="--", color=color, lw=0.9)
        soft = Ks[Ks <= 0.3]
        ax_e.loglog(soft, po.F.value**2 / (2 * soft), ":", color=color, lw=0.9)
        off = [(K, g[1]) for K, g in zip(Ks, got) if g[1] is not None]
        ax_off.errorbar([K for K, _ in off], [-e.F.value for _, e in off], yerr=[e.F.err or 0 for _, e in off],
                        fmt="o-", ms=3, color=color, label=f"mu = {mu:g}")
        ax_off.axhline(-po.F.value, ls=":", color=color, lw=0.9)
        if snap_off:
            ax_off.axhline(-snap_off.F.value, ls="--", color=color, lw=0.9)
        lims.append((mu, snap_on, snap_off, po, _energy(rigid.rigid)))
    zr = [(K, rigid_sphere_jump_in(K)) for K in np.logspace(-3.0, math.log10(1.02), 60)]
    ax_in.plot([K for K, z in zr], [-z for K, z in zr], "k:", lw=1.0, label="rigid sphere (mu = 0)")
    ax_in.plot([], [], "k--", lw=0.9, label="rigid machine: -lambda of snap-on")
    ax_in.set_yscale("log")
    ax_in.set_ylabel("jump-in distance -Z / epsilon")
    ax_e.plot([], [], "k--", lw=0.9, label="rigid machine (mu = 0.5: none)")
    ax_e.plot([], [], "k:", lw=0.9, label="F_pull-off^2 / (2K)")
    ax_e.set_ylabel("energy of a cycle / (2 pi R gamma epsilon)")
    ax_off.plot([], [], "k:", lw=0.9, label="load control (K -> 0)")
    ax_off.plot([], [], "k--", lw=0.9, label="rigid machine: snap-off")
    ax_off.set_ylabel("jump-off force -F / (2 pi R gamma)")
    for ax in (ax_in, ax_e, ax_off):
        ax.set_xscale("log")
        ax.set_xlabel("spring stiffness K / (2 pi R gamma / epsilon)")
        ax.legend(fontsize=7)
    rows = []
    for i, K in enumerate(Ks):
        row = [f"{K:.4g}"]
        for mu in MUS:
            jin, joff, E, Eerr = cols[mu][i]
            row += [_pm(-jin.Z.value, jin.Z.err) if jin else "no jump", _pm(joff.F.value, joff.F.err) if joff else "no jump",
                    _pm(E, Eerr, digits=5)]
        rows.append(row)
    row_inf, row_0 = ["infinity (rigid machine)"], ["0 (load control)"]
    for mu, snap_on, snap_off, po, energy in lims:
        row_inf += [_pm(-snap_on.lam.value, snap_on.lam.err) + " (-lambda of snap-on)" if snap_on else "no jump",
                    _pm(snap_off.F.value, snap_off.F.err) + " (snap-off)" if snap_off else "no jump",
                    _pm(energy[0], energy[1], digits=5)]
        row_0 += ["see the rigid sphere", _pm(po.F.value, po.F.err) + " (pull-off)", "F_pull-off^2 / (2K)"]
    rows += [row_inf, row_0]
    head = ["K"] + [f"mu = {mu:g}: {q}" for mu in MUS for q in ("jump-in distance -Z", "jump-off F", "energy")]
    table = _table(head, rows)
    table += ("\n\nUnits: Z in epsilon, F in 2 pi R gamma, energy in 2 pi R gamma epsilon, K in 2 pi R gamma / "
              "epsilon.  Behind a spring the primary jumps: the jump-in reached first on approach (largest Z) and "
              "the jump-off reached last on retraction (smallest Z).  Rigid sphere (mu = 0, eq. 28): the jump-in "
              "at K = 0.001, 0.01, 0.1, 1 is -Z = "
              + ", ".join(f"{-rigid_sphere_jump_in(K):.4f}" for K in (1e-3, 1e-2, 1e-1, 1.0))
              + "; it has none for K >= 16 / (9 sqrt 3) = 1.0264.")
    for mu in sorted({p[0] for p in pairs}):
        got = [p for p in pairs if p[0] == mu]
        notes.append(f"mu = {mu:g}, K = {got[0][1]:.4g} to {got[-1][1]:.4g}: a second pair of jumps (a jump-off, then "
                     f"a jump-in, {got[0][2]:.3g} epsilon apart in Z at K = {got[0][1]:.4g}, {got[-1][2]:.2g} at "
                     f"K = {got[-1][1]:.4g}) on the rigid machine's unstable branch, about its load minimum and "
                     "maximum where the contact forms; the stretch between them is stable behind the spring, but no "
                     "cycle reaches it: the table gives the primary jumps")
    if notes:
        table += "\n\n" + "\n".join(f"- {n}" for n in notes)
    _save(fig, "afm_stiffness", table, time.process_time() - t0)


def radius() -> None:
    """afm_radius: the contact radius against the load along the curve (rigid machine) for each mu of
    :data:`RADIUS_MUS`, with JKR, DMT and Maugis-Dugdale."""
    t0 = time.process_time()
    fig = figure(figsize=(6.0 * len(RADIUS_MUS), 4.8))
    axes = fig.subplots(1, len(RADIUS_MUS))
    rows = []
    for ax, mu in zip(axes, RADIUS_MUS):
        c = trace_curve(Model(mu=mu), request=CurveRequest(kinds=RIGID_KINDS))
        top = float(c.F.max())
        contact_load(ax, _res(c), label=f"this model, mu = {mu:g}", color="k")
        A = np.linspace(0.0, 3.0 * jkr_zero_load(mu)[0], 800)
        F = jkr_load(A, mu)
        keep = F <= top
        ax.plot(F[keep], A[keep], color="C0", label="JKR")
        Fd = np.linspace(-1.0, top, 400)
        ax.plot(Fd, dmt_radius(Fd, mu), color="C2", label="DMT (Hertz under F + 1)")
        md = md_radius(mu)
        keep = md["F"] <= top
        ax.plot(md["F"][keep], md["A"][keep], color="C3",
                label=f"Maugis-Dugdale (lambda_MD = {float(maugis_parameter(mu)):.3g})")
        ax.set_title(f"mu = {mu:g}: contact radius along the curve (rigid machine)", fontsize=9)
        ax.legend(fontsize=7, loc="lower right")
        po = c.pull_off
        eq = c.events_of("equilibrium")[0]
        rows.append([f"{mu:g}", "pull-off (load control)", _pm(po.F.value, po.F.err), _pm(po.contact_radius.value,
                     po.contact_radius.err), f"{(9 * math.pi / 8) ** (1 / 3) * math.sqrt(mu):.4f}",
                     f"{md['pull_off']:.4f}", "0"])
        rows.append([f"{mu:g}", "zero load", "0", _pm(eq.contact_radius.value, eq.contact_radius.err),
                     f"{jkr_zero_load(mu)[0]:.4f}", f"{md['zero']:.4f}", f"{float(dmt_radius(0.0, mu)):.4f}"])
    table = _table(["mu", "state", "F", "contact radius (this model)", "JKR", "Maugis-Dugdale", "DMT"], rows)
    table += ("\n\nContact radii in sqrt(epsilon R), loads in 2 pi R gamma.  This model's contact radius is where "
              "the separation first rises through the edge level H = 0.5 (a gap of 1.5 epsilon, inside the "
              "cohesive zone; docs/numerics.md), with its error bar; JKR's and DMT's are where the gap closes, "
              "Maugis-Dugdale's the inner radius of its Dugdale zone.")
    _save(fig, "afm_radius", table, time.process_time() - t0)


#: name -> the function that makes docs/figures/afm_NAME.png and .md
FIGURES = {"example": example, "stiffness": stiffness, "radius": radius}


def main(argv: list[str]) -> int:
    """Make the figures named in ``argv`` (all without), print the time of each."""
    names = argv or list(FIGURES)
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        print(f"unknown figure '{unknown[0]}': one of {', '.join(FIGURES)}", file=sys.stderr)
        return 2
    os.makedirs(paths.FIGURES, exist_ok=True)
    total = time.perf_counter()
    for name in names:
        t0 = time.perf_counter()
        FIGURES[name]()
        print(f"afm_{name}: {time.perf_counter() - t0:.1f} s", flush=True)
    print(f"total {time.perf_counter() - total:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
