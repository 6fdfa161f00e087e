"""A particle population on a topography (petsc_adhesion.population, docs/population.md): against the rigid
sphere and the smooth solver on a flat surface, the Gaussian rule on a synthetic Gaussian surface, exact
scaling, the spread against the footprint, the seed, the ranks, the files and the refusals.

The table evaluator is tested with :class:`NodeRule` below: the Gaussian rule traced by the solver at a few
nodes of sigma (and mu) and interpolated, a PullOffModel as the family's table is one (here only: the library
holds no stand-in)."""
import csv
import math
import os

import numpy as np
import pytest

from conftest import ROOT, run_cli
from petsc_adhesion.model.parameters import Model
from petsc_adhesion.model.physical import Bodies
from petsc_adhesion.model.reference.rigid import DMT_PULL_OFF
from petsc_adhesion.model.topography import Topography, statistics
from petsc_adhesion.population import population
from petsc_adhesion.population.evaluate import GaussianRule, Trace, _pull_off
from petsc_adhesion.population.footprint import MIN_PIXELS, ZONE_SHARE, footprint, zone_radius
from petsc_adhesion.population.results import energy_fit, lognormal_fit
from petsc_adhesion.tracing.measured import Measured, Missing
from petsc_adhesion.population.sample import RadiusLaw, draw

EPS = 4e-10
AFM = os.path.join(ROOT, "tests", "data", "wsxm-afm-topography.top")
BODIES = Bodies(radius=1e-6, young1=7e10, poisson1=0.17, gamma=0.05, epsilon=EPS)


def gaussian_surface(n=256, rms=0.3 * EPS, corr=2.0, pixel=2e-9, seed=1, scale=1.0):
    """A Gaussian field of rms ``rms`` (m) and a Gaussian autocorrelation of length ``corr`` pixels (white noise
    filtered in Fourier space), as a Topography of ``pixel`` m pixels."""
    rng = np.random.default_rng(seed)
    k = np.fft.fftfreq(n)
    spectrum = np.exp(-(k[:, None] ** 2 + k[None, :] ** 2) * (np.pi * corr) ** 2)
    z = np.real(np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * np.sqrt(spectrum)))
    z = (z - z.mean()) * (rms / z.std()) * scale
    return Topography(z, (pixel, pixel), "synthetic", "m", "option", "none", statistics(z))


def flat_surface(n=128, pixel=2e-9, tilt=0.0):
    """A plane of slope ``tilt`` (0: flat) as a Topography, its statistics as read_topography gives a flat
    surface's (no moments) where it is flat."""
    from petsc_adhesion.model.topography import Moment, Statistics

    x = np.arange(n) * pixel
    z = tilt * (x[:, None] + 0.5 * x[None, :])
    z = z - z.mean()
    stats = statistics(z) if tilt else Statistics(Moment(0.0, 0.0), Moment(math.nan, None), Moment(math.nan, None),
                                                  (math.nan, math.nan), (float(z.size),) * 3, 0.0, 0.0, "flat")
    return Topography(z, (pixel, pixel), "flat", "m", "option", "none", stats)


class NodeRule:
    """The Gaussian rule's pull-off traced by the solver at nodes of (ln mu, sigma), interpolated bilinearly;
    its bar the nodes' largest solver bar plus the interpolation's error (the linear against the quadratic
    through three sigma nodes)."""

    def __init__(self, mus, sigmas):
        self.mus, self.sigmas = np.asarray(mus, float), np.asarray(sigmas, float)
        rule = GaussianRule()
        F, err = rule.pull_off(*[a.ravel() for a in np.meshgrid(self.mus, self.sigmas, indexing="ij")])
        self.F = F.reshape(self.mus.size, self.sigmas.size)
        self.err = np.nanmax(err)
        self.calls = 0

    def covers(self, mu, sigma):
        mu, sigma = np.asarray(mu, float), np.asarray(sigma, float)
        return (mu >= self.mus[0]) & (mu <= self.mus[-1]) & (sigma >= self.sigmas[0]) & (sigma <= self.sigmas[-1])

    def _along(self, row, s):
        lin = np.interp(s, self.sigmas, row)
        i = np.clip(np.searchsorted(self.sigmas, s) - 1, 0, self.sigmas.size - 3)
        quad = np.array([np.polyval(np.polyfit(self.sigmas[j:j + 3], row[j:j + 3], 2), x) for j, x in zip(i, s)])
        return lin, np.abs(quad - lin)

    def pull_off(self, mu, sigma):
        self.calls += 1
        mu, sigma = np.atleast_1d(np.asarray(mu, float)), np.atleast_1d(np.asarray(sigma, float))
        rows = [self._along(self.F[k], sigma) for k in range(self.mus.size)]
        if self.mus.size == 1:
            return rows[0][0], rows[0][1] + self.err
        t = np.clip((np.log(mu) - np.log(self.mus[0])) / (np.log(self.mus[-1]) - np.log(self.mus[0])), 0, 1)
        F = (1 - t) * rows[0][0] + t * rows[-1][0]
        return F, np.maximum(rows[0][1], rows[-1][1]) + self.err


def _mu(R):
    from dataclasses import replace
    return replace(BODIES, radius=R).mu


@pytest.fixture(scope="module")
def rule_2um():
    """The rule at the one mu of R = 2 um, sigma 0 to 0.8 epsilon, nodes dense about 0.5."""
    return NodeRule([_mu(2e-6)], np.concatenate([[0.0, 0.2, 0.35], np.linspace(0.45, 0.55, 5), [0.65, 0.8]]))


def test_node_rule_is_a_pull_off_model(rule_2um):
    assert all(callable(getattr(rule_2um, m, None)) for m in ("pull_off", "covers"))     # PullOffModel's members
    F, err = rule_2um.pull_off([_mu(2e-6)], [0.0])
    # sigma = 0 is the smooth sphere: between DMT (-1) and JKR (-0.75)
    assert -1.0 < F[0] < -0.75


# -- the footprint -------------------------------------------------------------------------------
def test_the_zone_holds_its_share_of_the_rigid_sphere():
    """The rigid sphere at pull-off (eq. 27: gap 1 + r^2/2 at lambda = 0) integrated numerically over the
    zone: ZONE_SHARE of the whole (eq. 28's -1)."""
    r = np.linspace(0.0, zone_radius(), 200001)
    g = 1.0 + r * r / 2
    P = (8.0 / 3.0) * (g ** -3 - g ** -9)
    inside = float(np.sum((P[1:] * r[1:] + P[:-1] * r[:-1]) / 2 * np.diff(r)))
    assert inside == pytest.approx(ZONE_SHARE * -DMT_PULL_OFF, rel=1e-6)


def test_a_tilted_plane_is_flat_in_its_footprint():
    """The footprint's heights are from its own mean plane: a tilt is not roughness."""
    topo = flat_surface(tilt=0.01)
    fp = footprint(topo, (120e-9, 130e-9), 50e-9, EPS)
    assert fp.pixels == pytest.approx(math.pi * 25 ** 2, rel=0.05)
    assert fp.rms == 0.0 and fp.skewness is None


def test_too_few_pixels_give_no_pull_off():
    topo = gaussian_surface(n=64, pixel=50e-9)            # pixels far coarser than the zone
    r = population(topo, BODIES, RadiusLaw(median=1e-6), count=3, seed=0, spread_count=0)
    for p in r.particles:
        assert p.pixels < MIN_PIXELS and "pixels" in p.pull_off.reason
    assert not r.complete and "pull-offs" in r.fit.reason


# -- flat: the smooth sphere ---------------------------------------------------------------------
def test_a_flat_surface_gives_the_smooth_sphere_for_every_particle():
    """Every particle's pull-off is the smooth sphere's at its mu (the solver's own smooth curve, to its
    bar); at a stiff mu the rigid limit, eq. (28)'s -1."""
    topo = flat_surface()
    stiff = Bodies(radius=1e-6, young1=1e13, poisson1=0.0, gamma=0.05, epsilon=EPS)
    r = population(topo, stiff, RadiusLaw(median=0.3e-6, spread=1.5), count=4, seed=3, spread_count=0)
    assert len(r.forces) == 4
    for p in r.particles:
        assert p.sigma == 0.0
        smooth = _pull_off(Model(mu=p.mu, roughness="none"), Trace(), None).F
        assert p.pull_off.value == pytest.approx(smooth.value, abs=2 * smooth.err + 1e-12)
        assert p.mu < 0.01 and p.pull_off.value == pytest.approx(DMT_PULL_OFF, abs=0.03)
        assert p.force.value == pytest.approx(-p.pull_off.value * 2 * math.pi * p.radius * 0.05, rel=1e-12)
        # a stiff sphere has no turning point of lambda: its cycle dissipates nothing, a computed 0, not a missing
        assert isinstance(p.energy, Measured) and p.energy.value == 0.0 and p.work.value == 0.0
    assert "4 particles without hysteresis" in r.energy_fit.reason and r.works.size == 4


def test_a_flat_surface_gives_the_smooth_spheres_energy_of_a_cycle():
    """A soft particle (mu = 2) on a flat: its energy of a cycle is the smooth sphere's from the main program's
    own curve at that mu (traced to F = 2 with every event, the Curve's rigid cycle), within their bars, and
    positive (the snap-on and snap-off of a rigid machine at mu above about 1); in J, times 2 pi R w epsilon.
    Without it asked for (Trace.energy False) the same pull-off, the energy missing with the reason."""
    from petsc_adhesion.tracing.trace import trace_curve

    soft = Bodies(radius=1e-6, young1=2.2e9, poisson1=0.0, gamma=0.05, epsilon=EPS)
    r = population(flat_surface(), soft, RadiusLaw(median=1e-6), count=1, seed=1, spread_count=0)
    p = r.particles[0]
    assert p.mu == pytest.approx(2.0, rel=0.01)
    main = trace_curve(Model(mu=p.mu)).rigid.energy
    assert main.value > 0.3 and p.energy.err > 0
    assert abs(p.energy.value - main.value) <= p.energy.err + main.err, (p.energy, main)
    assert p.work.value == pytest.approx(p.energy.value * 2 * math.pi * 1e-6 * 0.05 * EPS, rel=1e-12)
    off = population(flat_surface(), soft, RadiusLaw(median=1e-6), count=1, seed=1, spread_count=0,
                     trace=Trace(energy=False)).particles[0]
    assert off.pull_off == p.pull_off
    assert isinstance(off.energy, Missing) and "not asked for" in off.energy.reason


def test_the_energies_lognormal_is_of_the_positive_ones():
    """Zeros (particles without hysteresis) are counted, not fitted: a known lognormal's samples with zeros
    among them give its median and gsd within three bootstrap bars in at least 90 of 100 samples; fewer than
    three positive ones give no fit, saying how many were 0 and how many missing."""
    hits = 0
    for k in range(100):
        x = np.exp(np.random.default_rng(k).normal(math.log(3e-16), math.log(1.6), 60))
        fit = energy_fit(np.concatenate([x, np.zeros(25)]), missing=2, seed=k)
        assert fit.count == 60
        hits += fit.median.covers(3e-16, 3) and fit.gsd.covers(1.6, 3)
    assert hits >= 90
    none = energy_fit(np.array([0.0, 0.0, 0.0, 1e-16, 2e-16]), missing=4, seed=0)
    assert isinstance(none, Missing) and none.reason.startswith("2 positive energies") and \
        "3 particles without hysteresis" in none.reason and "4 without an energy" in none.reason


# -- a Gaussian surface: the Gaussian rule -------------------------------------------------------
def test_the_table_path_on_a_gaussian_surface_is_the_rule_at_its_rms(rule_2um):
    """One radius, footprints of about 940 independent samples: the table's pull-offs' median is the rule
    at the surface's rms within twice its sampling error.  The footprints overlap: the independent ones are
    about the area the sites may take over a footprint's (n_eff), not the particles."""
    topo = gaussian_surface(rms=0.5 * EPS, n=512)
    r = population(topo, BODIES, RadiusLaw(median=2e-6), count=200, seed=2, evaluator="table", table=rule_2um,
                   spread_count=0)
    F = np.array([p.pull_off.value for p in r.particles])
    assert F.size == 200 and all(p.note == "" for p in r.particles)
    # the table holds pull-offs only: no energy of a cycle, each particle saying why (never a 0)
    assert all(isinstance(p.energy, Missing) and "holds pull-offs only" in p.energy.reason for p in r.particles)
    assert r.works.size == 0 and "200 without an energy" in r.energy_fit.reason
    truth, bar = rule_2um.pull_off([_mu(2e-6)], [topo.stats.rms.value / EPS])
    rf, L = r.particles[0].footprint_radius, topo.size[0]
    n_eff = min(F.size, (L - 2 * rf) ** 2 / (math.pi * rf * rf))
    sampling = 1.2533 * F.std() / math.sqrt(n_eff)
    assert abs(np.median(F) - truth[0]) < 2 * sampling + bar[0], (np.median(F), truth[0], sampling, n_eff)


def test_the_solver_on_a_gaussian_surface_is_the_gaussian_law_at_its_top():
    """The measured law of a Gaussian sample is the Gaussian cut at the sample's own top (the law that
    converges, docs/topography.md): the solver's median within three sampling errors of the truncated
    Gaussian at the footprints' median rms and top; the untruncated 16-point rule, whose top is 4.7 rms, far
    outside (it puts the sphere on asperities the footprint does not have)."""
    topo = gaussian_surface(rms=0.3 * EPS, n=512)
    r = population(topo, BODIES, RadiusLaw(median=2e-6), count=12, seed=1, spread_count=0)
    F = np.array([p.pull_off.value for p in r.particles])
    s = np.array([p.sigma for p in r.particles])
    K = [footprint(topo, p.site, p.footprint_radius, EPS).heights.max() / p.sigma for p in r.particles]
    mu = r.particles[0].mu
    law = Model(mu=mu, sigma=float(np.median(s)), roughness="truncated_gaussian",
                roughness_cutoff=float(np.median(K)))
    truth = _pull_off(law, Trace(), None).F.value
    sampling = 1.2533 * F.std() / math.sqrt(F.size)
    assert abs(np.median(F) - truth) < 3 * sampling, (np.median(F), truth, sampling)
    hermite = GaussianRule().one(mu, float(np.median(s))).value
    assert abs(np.median(F) - hermite) > 5 * sampling


def test_scaling_the_heights_by_two_doubles_each_sigma(rule_2um):
    """Same seed, same sites (the table's footprint does not depend on the heights): every local sigma doubles."""
    a = population(gaussian_surface(), BODIES, RadiusLaw(median=2e-6), count=20, seed=4, evaluator="table",
                   table=rule_2um, spread_count=0)
    b = population(gaussian_surface(scale=2.0), BODIES, RadiusLaw(median=2e-6), count=20, seed=4,
                   evaluator="table", table=rule_2um, spread_count=0)
    for p, q in zip(a.particles, b.particles):
        assert p.site == q.site and p.pixels == q.pixels
        assert q.sigma == pytest.approx(2 * p.sigma, rel=1e-12)
        assert q.skewness == pytest.approx(p.skewness, rel=1e-9)


def test_the_spread_falls_as_the_footprint_grows():
    """On a homogeneous Gaussian surface the local rms, and with it the pull-off, varies less between
    particles as their footprints hold more independent samples: for four times the area, about half the
    relative spread of sigma (1 / sqrt(N)), and a smaller spread of the pull-off."""
    topo = gaussian_surface(rms=0.5 * EPS, n=512, corr=4.0)
    rule = NodeRule([_mu(0.5e-6), _mu(8e-6)], np.linspace(0.2, 0.8, 7))
    spreads = []
    for R in (0.5e-6, 8e-6):
        r = population(topo, BODIES, RadiusLaw(median=R), count=60, seed=5, evaluator="table", table=rule,
                       spread_count=0)
        s = np.array([p.sigma for p in r.particles])
        F = r.forces
        spreads.append((s.std() / s.mean(), F.std() / F.mean(), np.mean([p.independent for p in r.particles])))
    (s1, f1, n1), (s2, f2, n2) = spreads
    assert n2 > 3 * n1
    assert s2 < s1 * 0.8 and f2 < f1 * 0.8
    assert s2 / s1 == pytest.approx(math.sqrt(n1 / n2), rel=0.5)


# -- the draws -----------------------------------------------------------------------------------
def test_the_seed_reproduces_the_population_particle_by_particle(rule_2um):
    law = RadiusLaw(median=2e-6, spread=1.0)
    a = population(gaussian_surface(), BODIES, law, count=10, seed=7, evaluator="table", table=rule_2um,
                   spread_count=0)
    b = population(gaussian_surface(), BODIES, law, count=10, seed=7, evaluator="table", table=rule_2um,
                   spread_count=0)
    c = population(gaussian_surface(), BODIES, law, count=4, seed=7, evaluator="table", table=rule_2um,
                   spread_count=0)
    d = population(gaussian_surface(), BODIES, law, count=10, seed=8, evaluator="table", table=rule_2um,
                   spread_count=0)
    assert a.particles == b.particles
    assert a.particles[:4] == c.particles           # particle i is drawn by its index, not its neighbours
    assert all(p.site != q.site for p, q in zip(a.particles, d.particles))


def test_lognormal_radii_have_their_median_and_spread():
    law = RadiusLaw(median=3e-6, spread=1.5)
    R = np.array([draw(i, 11, law).radius for i in range(4000)])
    ln = np.log(R)
    assert math.exp(np.median(ln)) == pytest.approx(3e-6, rel=3 * 1.2533 * math.log(1.5) / math.sqrt(4000))
    assert math.exp(ln.std()) == pytest.approx(1.5, rel=0.03)


def test_the_lognormal_fit_and_its_bars_cover_the_truth():
    """Samples of a known lognormal: the fitted median and gsd within three bootstrap bars of the truth, in
    at least 90 of 100 samples (a 3-bar interval misses 0.3 % of a Gaussian's)."""
    hits = 0
    for k in range(100):
        x = np.exp(np.random.default_rng(k).normal(math.log(2e-8), math.log(1.4), 80))
        fit = lognormal_fit(x, seed=k)
        hits += fit.median.covers(2e-8, 3) and fit.gsd.covers(1.4, 3)
    assert hits >= 90


# -- the command line ----------------------------------------------------------------------------
_CLI = ("-adh_topography", AFM, "-pop_radius_median", "10e-6", "-pop_radius_spread", "1.2", "-phys_young1", "7e10",
        "-phys_poisson1", "0.17", "-phys_gamma", "0.05", "-phys_epsilon", "4e-10")


def _rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_one_and_two_ranks_give_the_same_population(tmp_path):
    """The particles by index, spread over the ranks: the same rows, value for value, and the same fit."""
    args = (*_CLI, "-pop_count", "4", "-pop_seed", "3", "-pop_spread_count", "2")
    one = run_cli(*args, "-csv", tmp_path / "one.csv", "-summary", tmp_path / "one.json", "-out", tmp_path / "one.h5",
                  "-plot", tmp_path / "one.png")
    assert one.returncode == 0, one.stderr
    two = run_cli(*args, "-csv", tmp_path / "two.csv", np=2)
    assert two.returncode == 0, two.stderr
    a, b = _rows(tmp_path / "one.csv"), _rows(tmp_path / "two.csv")
    assert len(a) == 4 and a == b
    assert all(float(r["F"]) < 0 and float(r["F_err"]) < 1e-3 * abs(float(r["F"])) for r in a)
    import h5py
    import json
    with h5py.File(tmp_path / "one.h5") as f:
        assert np.allclose(f["particles/F"][()], [float(r["F"]) for r in a], rtol=1e-15)
        assert f["particles/force"].attrs["units"] == "N"
    summary = json.load(open(tmp_path / "one.json"))["population"]
    assert summary["pull_offs"] == 4 and summary["evaluator"] == "solver"
    assert summary["lognormal"]["median_N"] == pytest.approx(
        math.exp(np.mean(np.log([float(r["force_N"]) for r in a]))), rel=1e-12)
    assert summary["model_spread"]["particles"] == 2
    assert os.path.getsize(tmp_path / "one.png") > 10000
    # the energy of a cycle in every row, the same on two ranks (above), in the HDF5 and the JSON as in the CSV
    assert all(r["energy"] != "" and r["energy_missing"] == "" and float(r["energy"]) >= 0 for r in a)
    energy = summary["energy_of_a_cycle"]
    assert energy["computed"] == 4 and energy["machine"] == "rigid"
    assert energy["zero"] == sum(float(r["energy"]) == 0 for r in a)
    with h5py.File(tmp_path / "one.h5") as f:
        assert np.allclose(f["particles/work"][()], [float(r["energy_J"]) for r in a], rtol=1e-15, atol=0)


@pytest.mark.parametrize("extra, named", [
    ((), None),                                                    # baseline: filled in below
    (("-pop_radius_file", "radii.txt"), "-pop_radius_file: not with -pop_radius_median"),
    (("-phys_radius", "1e-6"), "-phys_radius: not with a population"),
    (("-pop_evaluator", "nonesuch"), "-pop_evaluator: expected one of solver, table"),
    (("-pop_count", "0"), "-pop_count: expected an integer in [1"),
    (("-adh_sigma", "0.3"), "-adh_sigma: not with a population"),
    (("-pop_radius_spread", "0.5"), "-pop_radius_spread: expected a finite real in [1"),
    (("-plot", "x.txt"), "-plot: expected a file name ending in"),
    (("-arc_snes_rtol", "1e-9"), "-arc_snes_rtol: a population's solvers take their own settings"),
    (("-pop_evaluator", "table", "-pop_energy", "true"), "-pop_energy: true is not with -pop_evaluator table"),
    (("-pop_energy", "maybe"), "-pop_energy: expected true or false"),
])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, extra, named):
    (tmp_path / "radii.txt").write_text("1e-6\n2e-6\n")
    (tmp_path / "old.csv").write_text("an earlier result\n")
    if not extra:
        extra, named = ("-phys_epsilon", "-1"), "-phys_epsilon"
    args = [a for a in _CLI]
    proc = run_cli(*args, "-pop_count", "3", *extra, "-csv", tmp_path / "old.csv", "-summary", tmp_path / "s.json",
                   cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and named in lines[0], lines
    assert (tmp_path / "old.csv").read_text() == "an earlier result\n" and not (tmp_path / "s.json").exists()


def test_the_required_options_are_named(tmp_path):
    for drop, named in (("-adh_topography", "-adh_topography: required"),
                        ("-pop_radius_median", "-pop_radius_median: required"),
                        ("-phys_young1", "-phys_poisson1: needed with -phys_poisson1")):
        args = list(_CLI) + ["-pop_count", "2"]
        i = args.index(drop)
        del args[i:i + 2]
        proc = run_cli(*args, cwd=tmp_path)
        assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
        assert named.split(":")[0] in proc.stderr, proc.stderr
    proc = run_cli(*_CLI, "-pop_count", "2", "-pop_evaluator", "table", cwd=tmp_path)
    try:
        from petsc_adhesion.family import pull_off  # noqa: F401
    except ImportError:
        assert proc.returncode == 2 and "-pop_evaluator: table:" in proc.stderr, proc.stderr


def test_a_footprint_of_few_independent_samples_keeps_its_value_with_a_note():
    """The AFM image's correlation length (about 55 nm) is that of a 1 um particle's footprint: a couple of
    independent samples under it, the pull-off computed (the model's answer for those heights) and noted."""
    from petsc_adhesion.model.topography import read_topography

    import petsc_adhesion as pa

    topo = read_topography(AFM)
    r = pa.particle_population(topo, BODIES, RadiusLaw(median=1e-6), count=2, seed=1, spread_count=0)
    for p in r.particles:
        assert p.pull_off.value < 0 and p.independent < 5
        assert "independent samples" in p.note
    assert len(r.flagged) == 2


def test_a_footprint_past_the_edge_is_refused_or_clipped_with_a_note():
    """A later pass's wider footprint about the first's site may reach past the scan: its pixels inside, noted
    (the disk's area inside the scan, to a pixel's rim); asked without clip, a ValueError."""
    topo = gaussian_surface(n=128)
    with pytest.raises(ValueError):
        footprint(topo, (10e-9, 100e-9), 20e-9, EPS)
    fp = footprint(topo, (-1e-9, 100e-9), 20e-9, EPS, clip=True)      # the centre on the scan's edge
    assert "past the scan's edge" in fp.note
    assert fp.pixels == pytest.approx(math.pi * 10 ** 2 / 2, rel=0.1)


def test_the_shipped_table_evaluates_inside_its_range_and_flags_the_rest():
    """Through the package's own PullOffTable: a footprint's (mu, sigma) inside the table gets the Gaussian rule's
    pull-off, equal to the solver's at that point within the table's bar; one beyond the table's sigma is Missing
    with the reason (the table refuses it: it is never asked)."""
    from petsc_adhesion.family.pull_off import PullOffTable
    from petsc_adhesion.population.evaluate import TableEvaluator
    from petsc_adhesion.tracing.measured import Missing

    table = PullOffTable.default()
    inside, beyond = (0.4, 0.5), (0.4, float(table.sigma[-1]) + 1.5)
    got = TableEvaluator(table).evaluate_many(np.array([inside[0], beyond[0]]), np.array([inside[1], beyond[1]]))
    solver = GaussianRule().one(*inside)
    assert abs(got[0].value - solver.value) <= got[0].err + (solver.err or 0.0), (got[0], solver)
    assert isinstance(got[1], Missing)
    assert "outside the table" in got[1].reason
