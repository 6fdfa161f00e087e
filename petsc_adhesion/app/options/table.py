"""The option table: every application option, its kind, default, accepted values and help.

The defaults are those of the objects the options configure (``Model``,
``GridChoice``, ``SolverChoice``, ``Settings``, ``CurveRequest``), read from
there; -help and docs/usage.md are made from this table.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ...app import checkpoint, progress
from ...core.bordered import ARCLENGTH_PREFIX
from ...core.continuation import CORRECTORS, NATURAL_PREFIX, Settings
from ...core.events import EVENT_TOL
from ...core.newton import PC_REUSE_ITS
from ...discretization import grid, preconditioning
from ...model.parameters import Model
from ...model.physical import HAMAKER_CUTOFF
from ...model.roughness import DISTRIBUTIONS, Lognormal, Weibull
from ...tracing.edge_grids import RMAX
from ...tracing.trace import F_MAX

__all__ = ["Option", "RULES_HERMITE", "SOLVER_PREFIXES", "TABLE", "ROUGHNESS_OPTIONS"]


@dataclass(frozen=True)
class Option:
    """One application option: its kind, default, help and accepted values."""

    name: str
    kind: str          # "real" | "int" | "choice" | "string" | "flag" | "reals" | "rules"
    default: Any       # of the option's kind: a float for a real, a tuple for reals, ...
    help: str
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    choices: tuple = ()
    hi_open: bool = False

    def allowed(self) -> str:
        """What the option accepts, in words."""
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "choices":
            return "comma-separated names from " + ", ".join(self.choices)
        if self.kind in ("real", "int", "reals", "sweep"):
            left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
            what = {"real": "a finite real", "int": "an integer", "reals": "comma-separated finite reals",
                    "sweep": "comma-separated reals or ranges lo:hi:n[:log]"}[self.kind]
            if self.lo == -math.inf and self.hi == math.inf:
                return what
            return f"{what} in {left}{_fmt(self.lo)}, {_fmt(self.hi)}{right}"
        return {"string": "a file name", "flag": "true or false",
                "rules": "comma-separated law:parameter from " + ", ".join(f"{k}:{v}" for k, v in self.choices),
                }[self.kind]


def _fmt(x: float) -> str:
    return "inf" if x == math.inf else "-inf" if x == -math.inf else f"{x:g}"


#: -adh_roughness values averaged by a Gauss-Hermite rule (pressure.RULES without "none").
RULES_HERMITE = ("hermite",)




#: Options prefixes of the three solvers: (prefix, what it solves).
SOLVER_PREFIXES = (("", "the fixed-approach solve (-adh_lambda)"),
                   (NATURAL_PREFIX, "the continuation's natural corrector and first point"),
                   (ARCLENGTH_PREFIX, "its arclength corrector and tangents"))


_INF = math.inf


_S = Settings


TABLE = {o.name: o for o in [
    # model (paper eq. 9-14)
    Option("adh_mu", "real", Model.mu, "Tabor parameter mu (eq. 9)", 0.0, 1000.0),
    Option("adh_sigma", "real", Model.sigma, "roughness: standard deviation of the heights / epsilon", 0.0, 5.0),
    Option("adh_roughness", "choice", Model.roughness, "height distribution averaged over (eq. 7, 10): the "
           "paper's Gaussian by its Gauss-Hermite rule (eq. 14), whose rule is the model; Gaussian truncated at "
           "the highest asperity; skewed (reversed Weibull); depths below the highest asperity lognormal; measured "
           "heights; none (smooth)",
           choices=("none", *RULES_HERMITE, *DISTRIBUTIONS)),
    Option("adh_hermite_points", "int", Model.hermite_points, "points of the Gauss-Hermite rule (eq. 14)", 2, 200),
    Option("adh_roughness_cutoff", "real", Model.roughness_cutoff, "truncated_gaussian: the highest asperity, "
           "in standard deviations (-adh_sigma) of the untruncated Gaussian", 1e-6, 10.0),
    Option("adh_roughness_skewness", "real", Model.roughness_skewness, "weibull: skewness of the heights "
           "(-2: exponential valleys, 0.5: the most symmetric bounded)", *Weibull.SKEWNESS),
    Option("adh_lognormal_skewness", "real", Model.lognormal_skewness, "lognormal: skewness of the heights "
           "(negative: the long tail in the valleys, the heights bounded above)", *Lognormal.SKEWNESS),
    Option("adh_roughness_file", "string", None, "measured: heights, one a line in units of epsilon; a table "
           "(Gwyddion ASCII export, '# Value units: m'), .gsf or .npy height map; it sets sigma itself"),
    Option("adh_roughness_unit", "real", None, "measured: metres per value of a file that states no unit "
           "(needs -phys_epsilon)", 0.0, 1.0, lo_open=True),
    Option("adh_topography", "string", None, "measured: a topography file (an AFM image, a profilometer map or "
           "profile, text with a header: any format SurfaceTopography reads, with its units and size), detrended; its "
           "heights (with -adh_topography2's, combined) are the gap's; needs -phys_epsilon and SurfaceTopography"),
    Option("adh_topography2", "string", None, "measured: the second surface's topography file (the sphere's); the "
           "gap's heights are the sum of the two surfaces' (their distributions convolved)"),
    Option("adh_topography_detrend", "choice", "plane", "measured: what is removed from a topography before its "
           "heights are taken: the mean only, the least-squares plane (tilt is mounting, not roughness), or the "
           "second-order polynomial (a bent sample, a scanner's bow)", choices=("none", "plane", "curvature")),
    Option("adh_topography_unit", "choice", None, "measured: the length unit of the values of a topography file "
           "that states none (refused for one that does)", choices=("m", "mm", "um", "nm", "A", "pm")),
    Option("adh_quadrature_points", "int", Model.quadrature_points, "truncated_gaussian, weibull, lognormal: "
           "points of the quadrature's moving part at the wall (its fixed panels get 2/3 as many; lognormal has "
           "fixed panels only)", 2, 400),
    Option("adh_model_spread", "flag", None, "trace a rough curve's events again under other roughness laws "
           "(events only) and say how far they move: the model's spread beside the numerical bar (default: true "
           "when sigma > 0; docs/model.md)"),
    Option("adh_model_spread_rules", "rules", None, "the laws of -adh_model_spread (default: hermite with twice "
           "the points under hermite, truncated_gaussian:3, truncated_gaussian:4, weibull:0; the reference's own "
           "left out)", choices=(("hermite", "N"), ("truncated_gaussian", "K"), ("weibull", "skewness"),
                    ("lognormal", "skewness"))),
    Option("adh_rmax", "real", None, f"end r_m of the computational domain (default: {RMAX:g} on grids that "
           f"follow the contact edge, {grid.PAPER_RMAX:g} as in the paper otherwise)", 0.0, 1e3, lo_open=True),
    Option("adh_farfield", "flag", Model.farfield, "add the rigid sphere's attraction beyond r_m to the load: "
           "the half-infinite model (false: the paper's model truncated at r_m)"),
    Option("adh_lambda", "real", None, "solve at this one approach lambda only (no continuation)", -1e3, 1e3),
    Option("adh_guess", "string", None, "HDF5 result whose H(r) is the initial guess of -adh_lambda"),
    Option("adh_pmat", "choice", "dense", "matrix handed to the preconditioner: the assembled Jacobian, "
           "its near-field band (AIJ), or the shell itself", choices=preconditioning.KINDS),
    Option("adh_pmat_band", "int", preconditioning.BAND, "half bandwidth of -adh_pmat band", 0, 10**6),
    Option("adh_pc_reuse_its", "int", PC_REUSE_ITS, "keep the preconditioner while Krylov needs at most this many "
           "iterations (0: rebuild at every Newton iteration)", 0, 10**6),
    # grid
    # physical inputs (SI): mu from eq. (9), sigma = rms / epsilon, results also in nN, nm, MPa
    Option("phys_radius", "real", None, "radius R1 of the sphere (m); with -phys_young1, -phys_poisson1, "
           "-phys_gamma (or -phys_hamaker) and -phys_epsilon it sets mu by eq. (9), and results are reported also "
           "in nN, nm and MPa", 0.0, 1.0, lo_open=True),
    Option("phys_radius2", "real", None, "radius R2 of a second sphere (m): R = R1 R2 / (R1 + R2) (default: a "
           "flat)", 0.0, 1.0, lo_open=True),
    Option("phys_young1", "real", None, "Young's modulus E1 of the sphere (Pa)", 0.0, 1e13, lo_open=True),
    Option("phys_poisson1", "real", None, "Poisson's ratio nu1 of the sphere", -1.0, 0.5, lo_open=True),
    Option("phys_young2", "real", None, "Young's modulus E2 of the flat (or second sphere) (Pa); eq. (2) "
           "(default: rigid)", 0.0, 1e13, lo_open=True),
    Option("phys_poisson2", "real", None, "Poisson's ratio nu2 of the flat (with -phys_young2)", -1.0, 0.5,
           lo_open=True),
    Option("phys_gamma", "real", None, "work of adhesion gamma (J/m^2)", 0.0, 100.0, lo_open=True),
    Option("phys_hamaker", "real", None, "Hamaker constant A (J), instead of -phys_gamma: gamma = A / (12 pi D0^2)",
           0.0, 1e-16, lo_open=True),
    Option("phys_hamaker_cutoff", "real", None, f"cut-off distance D0 of -phys_hamaker (m; default "
           f"{HAMAKER_CUTOFF:g}, Israelachvili's)", 0.0, 1e-8, lo_open=True),
    Option("phys_epsilon", "real", None, "equilibrium spacing epsilon of the Lennard-Jones law (m)", 0.0, 1e-8,
           lo_open=True),
    Option("phys_rms", "real", None, "rms roughness of the combined surfaces (m): sigma = rms / epsilon", 0.0,
           1e-6),
    Option("grid_type", "choice", "edge", "node set: graded about the contact edge and following it along "
           "the curve; the paper's; uniform", choices=("edge", "paper", "uniform")),
    Option("grid_n", "int", grid.PAPER_UNIFORM + grid.PAPER_EXTRA, "number of nodes of -grid_type uniform",
           3, 200000),
    Option("grid_paper_uniform", "int", grid.PAPER_UNIFORM, "uniform nodes of -grid_type paper", 3, 200000),
    Option("grid_paper_extra", "int", grid.PAPER_EXTRA, "elements refined by -grid_type paper", 0, 200000),
    Option("grid_paper_split", "int", grid.PAPER_SPLIT, "parts each refined element is split into", 2, 1000),
    Option("grid_paper_refine_from", "real", 0.0, "first refined element of -grid_type paper starts here", 0.0, 1e3),
    # continuation
    Option("cont_type", "choice", _S.corrector, f"corrector: switch at |lambdadot| < {_S.switch:g} (paper), "
           "or one kind", choices=CORRECTORS),
    Option("cont_lambda_start", "real", None, "first approach (default: below the reach of the forces)", -1e3, 1e3),
    Option("cont_lambda_max", "real", None, "stop at this approach (default: past equilibrium)", -1e3, 1e3),
    Option("cont_F_max", "real", F_MAX, "stop at this compressive load (behind a spring with -phys_ inputs the "
           "default is -afm_trigger's)", -_INF, 1e6),
    Option("cont_max_steps", "int", _S.max_steps, "stop after this many accepted steps", 1, 10**7),
    Option("cont_dF_max", "real", _S.observable_step, "largest change of the load in one step, relative above "
           "|F| = 1", 0.0, 1e6, lo_open=True),
    Option("cont_dF_bend", "real", _S.observable_bend, "largest distance of the load in one step from its "
           "tangent's line (absolute; resolves a kink such as a rough sphere meeting the roughness rule's wall)",
           0.0, _INF, lo_open=True, hi_open=True),
    Option("cont_max_folds", "int", _S.max_folds, "stop after more than this many turning points (a grid that "
           "traps the contact edge makes dozens)", 0, 10**6),
    Option("cont_ds", "real", _S.ds, "first arclength step", 0.0, 1e3, lo_open=True),
    Option("cont_ds_min", "real", _S.ds_min, "smallest step before giving up", 0.0, 1e3, lo_open=True),
    Option("cont_ds_max", "real", _S.ds_max, "largest step", 0.0, 1e3, lo_open=True),
    Option("cont_newton_target", "int", _S.newton_target, "corrector iterations aimed at by the step control",
           1, 100),
    Option("cont_max_deviation", "real", _S.max_deviation, "largest corrector distance from the predictor, per "
           "unit step (bounds the step by the curvature)", 0.0, 10.0, lo_open=True),
    Option("cont_at_lambda", "reals", (), "approaches at which to record the state (e.g. 0 for Fig. 12)", -1e3, 1e3),
    Option("cont_event_tol", "real", EVENT_TOL, "event location tolerance in lambda", 0.0, 1.0, lo_open=True),
    Option("cont_monitor", "flag", _S.monitor, "one line a continuation step"),
    Option("cont_checkpoint", "string", None, "save the curve's state (a study's: its finished cases) into "
           "this file as it goes, for -cont_restart (default: .NAME.checkpoint beside -out, else -summary or "
           "-plot; the file restarted from; none: no checkpoint); a finished run removes it"),
    Option("cont_checkpoint_interval", "real", checkpoint.INTERVAL, "least seconds between two checkpoint saves "
           "(0: before every step)", 0.0, 1e6),
    Option("cont_restart", "string", None, "go on from this checkpoint of an interrupted run with the same "
           "options (output and printing options aside): the same steps, events and error bars; a study runs "
           "only the cases not in it"),
    Option("cont_error_estimate", "flag", True, "give every event its best value and error bar: located again "
           "on its grid's coarser (or finer) nested levels, Richardson-extrapolated"),
    Option("target_error", "real", None, "refine each event's levels until its error bars (lambda and F) are "
           "below this", 0.0, 1.0, lo_open=True),
    # the measuring machine (an AFM cantilever).  K below 1e-12 puts the base F / K beyond 1e12 for a unit force
    # (-afm_spring 1e-300 traced to lambda = -1.7e100 and ended early); no AFM lever is softer than about
    # 1e-3 N/m, so -phys_spring takes three decades below that (1e-300 N/m ended in numpy's overflow warnings)
    Option("afm_spring", "real", None, "drive the approach through a spring of this stiffness K (units 2 pi R "
           "gamma / epsilon; an AFM cantilever): its base Z = lambda + F / K jumps in and off where dZ/ds = 0, "
           "reported with their landings and the energy of a cycle (default: a rigid machine only)", 1e-12, 1e12),
    Option("phys_spring", "real", None, "spring constant k of the cantilever (N/m), with the other -phys_ "
           "options: K = k epsilon / (2 pi R gamma), as -afm_spring", 1e-6, 1e9),
    # an instrument's trigger: the approach ends at this load and the retract follows (tracing/legs.py)
    Option("afm_trigger", "real", None, "behind a spring: end the approach at this compressive load (units 2 pi "
           "R gamma), an instrument's trigger, the retract following; the load's steps are then at most 1/50 of "
           "the range from the pull-off to it (default with -phys_ inputs and -phys_spring: 3 times the rigid "
           "sphere's pull-off, its roughness included; not with -cont_F_max, which stops the curve otherwise)",
           0.0, 1e6, lo_open=True),
    Option("phys_trigger", "real", None, "behind a spring: the trigger force (N) with the other -phys_ options, "
           "as -afm_trigger", 0.0, 1.0, lo_open=True),
    # studies: a sweep over cases (petsc_adhesion.app.study)
    Option("study_mu", "sweep", (), "study: the Tabor parameters of its cases (eq. 9)", 0.0, 1000.0),
    Option("study_sigma", "sweep", (), "study: the roughness sigma of its cases", 0.0, 5.0),
    Option("study_option", "string", None, "study: a further real or integer option swept over -study_values "
           "(without the dash, e.g. phys_radius, adh_hermite_points, grid_n)"),
    Option("study_values", "sweep", (), "study: the values of -study_option", -1e12, 1e12),
    Option("study_compute", "choice", "curve", "study: what each case computes: the whole curve; the events up to "
           "equilibrium; only the pull-off and the equilibrium after it; only the turning points; the critical "
           "roughness sigma_c(mu) of each -study_mu and the critical mu_c(sigma) of each -study_sigma (with a "
           "spring, its jumps too)", choices=("curve", "events", "pull_off", "folds", "critical")),
    Option("study_profiles", "choices", (), "study: the event kinds whose H(r), P(r) each case keeps",
           choices=("snap_on", "snap_off", "F_min", "F_max", "equilibrium", "lambda", "jump_in", "jump_off")),
    Option("study_ranks", "int", 1, "study: MPI ranks per case; the cases are spread over the groups of this "
           "many ranks, the longest first", 1, 10**6),
    Option("study_plot", "choice", "curves", "study: what -plot draws: load-approach curves; one panel per case "
           "about its turning points; the profiles of -study_profiles; pull-off against mu; reduction of the "
           "pull-off against sigma; the boundary of hysteresis (sigma_c, mu_c: the only one, and the default, with "
           "-study_compute critical)",
           choices=("curves", "folds", "profiles", "pull_off", "reduction", "critical")),
    # fitting a measurement (petsc_adhesion.fitting; docs/fitting.md)
    Option("fit_pull_off", "real", None, "fit: the work of adhesion whose model pull-off is this measured force "
           "(N, its magnitude), with -phys_radius, -phys_young1, -phys_poisson1 (-phys_young2, -phys_poisson2: "
           "default a rigid flat), -phys_epsilon and -phys_rms if rough; reports gamma, its bar, mu and what JKR, "
           "DMT and Maugis-Dugdale give", 0.0, 1.0, lo_open=True),
    Option("fit_pull_off_err", "real", 0.0, "fit: the standard uncertainty of -fit_pull_off (N), carried into "
           "gamma's bar", 0.0, 1.0),
    Option("fit_curve", "string", None, "fit: a measured force-distance curve (text or CSV: piezo displacement "
           "and force in SI, approach then retract; or an AFM file afmformats reads): the work of adhesion and the "
           "reduced modulus E*, with the contact point and baseline, by bounded least squares; needs "
           "-phys_radius, -phys_epsilon and the spring constant (-phys_spring, or the file's)"),
    Option("fit_curve_index", "int", 0, "fit: the curve of a -fit_curve file of several (a force map)", 0, 10**9),
    Option("fit_modulus", "flag", True, "fit: fit E* (false: hold it at the -phys_young/-phys_poisson value; given "
           "with true, that value is where the fit starts)"),
    Option("fit_roughness", "flag", False, "fit: fit the rms roughness too (-phys_rms: its start, default 0.3 "
           "epsilon)"),
    Option("fit_invols", "real", None, "fit: the deflection sensitivity (m/V) of a -fit_curve file whose deflection "
           "is in volts (a text column in V or mV); for an AFM file stating its own, the force is rescaled to this "
           "one", 0.0, 1e-3, lo_open=True),
    Option("fit_invols_scale", "flag", False, "fit: fit the scale c of the deflection sensitivity (the true over "
           "the file's: force and deflection c times the file's) as a nuisance parameter; false holds it at 1 (or "
           "at -fit_calibrate_invols's)"),
    Option("fit_calibrate_invols", "flag", False, "fit: calibrate the sensitivity's scale on the contact as on a "
           "hard substrate (its slope made the lever's) before fitting; held there, or the start with "
           "-fit_invols_scale"),
    Option("fit_spring_err", "real", None, "fit: the standard uncertainty of the spring constant (N/m): k fitted "
           "with it as a Gaussian prior, its bar carried into the others' (default: k held)", 0.0, 1e3,
           lo_open=True),
    Option("fit_virtual_deflection", "flag", False, "fit: fit a baseline sloped in z (the virtual deflection, "
           "N/m)"),
    Option("fit_drag", "flag", False, "fit: fit the retract's baseline offset from the approach's (the drag of "
           "the medium, N)"),
    Option("fit_segment", "choice", "both", "fit: the legs of -fit_curve fitted", choices=("both", "approach",
                                                                                            "retract")),
    Option("fit_z_range", "reals", (), "fit: the piezo range of -fit_curve fitted, two positions lo,hi (m, in "
           "the file's z)", -1.0, 1.0),
    Option("fit_max_evals", "int", 40, "fit: the cap on the least squares' evaluations of -fit_curve (a search on "
           "the curve family table with the roughness fitted, whose evaluations cost milliseconds, 5 times it); reached, the fit ends with a "
           "WARNING and exit status 3", 1, 10**6),
    Option("fit_table", "string", "default", "fit: the curve family table -fit_curve searches on where it holds the "
           "model (then one solver curve at its optimum): default (the package's: the rough table where the fit has a "
           "roughness and its range holds the fit, else the smooth sphere's, mu 1e-3 to 1e3), smooth or rough (a "
           "shipped table by name), a table file, or none (the solver's curves throughout)"),
    Option("fit_outside_domain", "choice", "refuse", "fit: a -fit_curve outside the model's domain (a deep "
           "indentation, mu beyond its range, a contact steeper than the lever, tethers): refuse before fitting "
           "(exit 3, nothing written) or fit and warn (exit 3)", choices=("refuse", "warn")),
    Option("fit_map", "string", None, "fit: a force map (a map file afmformats reads: JPK .jpk-force-map, "
           ".jpk-qi-data; a folder of curve files, an Asylum or AFM Workshop map's placed by its files; a list file "
           ".list of paths, each optionally with its pixel "
           "'ix iy'): every curve fitted as -fit_curve fits one, over MPI ranks, each pixel's w, E*, pull-off, "
           "jump-in and energy of a cycle with their bars or the reason it has none; -out (HDF5) or -csv needed, "
           "the journal beside it resumes a killed map (docs/maps.md)"),
    Option("fit_map_shape", "reals", (), "fit: the grid nx,ny a -fit_map folder or list fills row by row (x "
           "fastest; default a row); an Asylum or AFM Workshop map's folder states its own (given, it must agree)", 1.0, 1e6),
    # a particle population on a topography (petsc_adhesion.population; docs/population.md)
    Option("pop_count", "int", None, "population: the number of particles, each landing on a random site of "
           "-adh_topography (default: as many as -pop_radius_file lists)", 1, 10**6),
    Option("pop_radius_median", "real", None, "population: the median radius of the particles (m); their radii "
           "lognormal with -pop_radius_spread", 0.0, 1e-2, lo_open=True),
    Option("pop_radius_spread", "real", 1.0, "population: the geometric standard deviation of the radii (1: every "
           "particle of -pop_radius_median)", 1.0, 100.0),
    Option("pop_radius_file", "string", None, "population: a text file of the particles' radii (m), one a line "
           "('#' comments), instead of -pop_radius_median"),
    Option("pop_seed", "int", 0, "population: the seed of every particle's radius and site (drawn by its index: "
           "the same particles on any number of ranks)", 0, 2**31 - 1),
    Option("pop_evaluator", "choice", "solver", "population: each pull-off by the solver under the footprint's "
           "measured heights (exact for the model), or by the table of the Gaussian rule at the footprint's rms "
           "(fast)", choices=("solver", "table")),
    Option("pop_spread_count", "int", 50, "population: particles evaluated under both the measured law and the "
           "Gaussian rule on the same footprints, the model spread (0: none)", 0, 10**6),
    Option("pop_bins", "int", 8, "population: bins of the pull-off against radius (log-spaced)", 1, 1000),
    Option("pop_bootstrap", "int", 200, "population: bootstrap resamples of the lognormal fit's bars", 10, 10**5),
    Option("pop_energy", "flag", True, "population: each particle's energy of a cycle under a rigid machine, with "
           "its bar (the solver evaluator; false skips it: the folds are not located again on nested grids)"),
    # output
    Option("out", "string", None, "HDF5 result file"),
    Option("summary", "string", None, "JSON summary file"),
    Option("profiles", "flag", False, "store H(r) and P(r) at every event"),
    Option("plot", "string", None, "PNG of the load-approach curve (and the profiles with -profiles); behind a "
           "spring led by the approach and retract its cantilever follows (force in nN against piezo in nm with "
           "-phys_ inputs)"),
    Option("csv", "string", None, "CSV of the load-approach curve, a row per point: lambda, F, contact radius, "
           "stable (0/1); behind a spring the approach and the retract its cantilever follows instead: leg, base "
           "Z, tip-sample separation, deflection, F, lambda, contact radius, jump (1: the tip jumps at constant Z "
           "to the next row); in nm and nN too with -phys_ inputs; a study: its table of events; not with "
           "-adh_lambda"),
    Option("csv_events", "string", None, "CSV of the curve's events, a row each: kind, best values, error bars, "
           "landing, single-grid values (in nm and nN too with -phys_ inputs); not with -adh_lambda nor in a study"),
    Option("progress", "flag", None, "a line on stderr every -progress_interval seconds: lambda reached, steps, "
           "events, time elapsed and an estimate of the time left (default: when stderr is a terminal)"),
    Option("progress_interval", "real", progress.INTERVAL, "least seconds between two progress lines", 0.0, 1e6,
           lo_open=True),
]}


#: Options of one roughness model: name -> the -adh_roughness values that use it.
ROUGHNESS_OPTIONS = {"adh_hermite_points": RULES_HERMITE, "adh_roughness_cutoff": ("truncated_gaussian",),
                     "adh_roughness_skewness": ("weibull",), "adh_lognormal_skewness": ("lognormal",),
                     "adh_quadrature_points": ("truncated_gaussian", "weibull", "lognormal"),
                     "adh_roughness_file": ("measured",), "adh_roughness_unit": ("measured",),
                     "adh_topography": ("measured",), "adh_topography2": ("measured",),
                     "adh_topography_detrend": ("measured",), "adh_topography_unit": ("measured",)}
