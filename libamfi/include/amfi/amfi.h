/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi.h: the numerical core of amfi: acceleration-based moving force
 * identification (A-MFI) on a finite-element beam bridge.
 *
 * Pure computation: no I/O, no printing, no exit. Every function that can fail
 * returns an int status (0 ok, negative AMFI_E* on error) and, when `err` is
 * not NULL, writes a one-line message of at most `errlen` bytes into it.
 *
 * Matrices are row-major doubles; every matrix argument states its shape.
 * Sign convention (docs/model.md §0): deflection, acceleration and axle forces
 * are positive downward. Units are SI unless a name says otherwise.
 *
 * Workload: one bridge model per site (created once), one solver workspace
 * per worker thread (created once per problem size), then many passages of
 * about 1 s at 5000 Hz, each solved in milliseconds. Nothing here allocates
 * inside a time-step loop, and a solve allocates nothing unless its problem
 * is larger than every one the solver has seen (more steps or axles, a
 * longer L-curve search than the default; the first speed search, its
 * coarse model and minimiser): amfi_solve, amfi_solve_speed and
 * amfi_solve_multi grow the workspace once, before any time loop
 * (tests/libamfi/test_solve_alloc.c counts). A handle is not thread-safe;
 * distinct handles are independent (the bridge model is read-only after
 * creation and may be shared by several solvers and threads).
 */
#ifndef AMFI_AMFI_H
#define AMFI_AMFI_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- status codes ------------------------------------------------------ */
#define AMFI_OK 0
#define AMFI_EINVAL (-1)  /* an argument is out of range or inconsistent */
#define AMFI_ENOMEM (-2)  /* allocation failed */
#define AMFI_ENUM (-3)    /* a numerical step failed (LAPACK info != 0, NaN) */
#define AMFI_ERANGE (-4)  /* the data does not cover the passage window */

#define AMFI_MAX_SUPPORTS 16
#define AMFI_MAX_SENSORS 8
#define AMFI_MAX_AXLES 12 /* axles of one vehicle (amfi_passage, amfi_vehicle) */
/* Axles of one event of several vehicles (amfi_solve_multi), apart from one
 * vehicle's: three or four trucks share a 20 m span at a dense flow. */
#define AMFI_MAX_EVENT_AXLES 48
#define AMFI_GRAVITY 9.81 /* m/s², paper §3.2 */

const char *amfi_strerror(int status); /* static string; never NULL */

/* Threads OpenBLAS may use (process-wide). The solver's matrices are small:
 * programs that parallelise across passages should set 1, which also stops
 * OpenBLAS's idle threads spinning against the workers on a 2-core box. */
void amfi_set_blas_threads(int n);

/* ---- bridge: Euler-Bernoulli FE beam (docs/model.md §1) ---------------- */

typedef struct amfi_support {
    double x_m;         /* position along the beam, m, snapped to the nearest node */
    int restrain_w;     /* 1: vertical displacement fixed */
    int restrain_theta; /* 1: rotation fixed */
    /* Finite stiffness of a DOF that is not fixed (0: none). A bearing that
     * is not quite a pin (partly fixed by friction, elastomer, abutment) has
     * a rotational spring; an elastomeric bearing or a soft pier a vertical
     * one. Both >= 0 and finite; a spring on a fixed DOF is refused. A
     * spring counts as a restraint against rigid-body motion. */
    double k_w_npm;        /* vertical spring, N/m */
    double k_theta_nmprad; /* rotational spring, N·m/rad */
} amfi_support;

/* A part of the beam with its own section: haunches, a thicker deck,
 * surfacing or barriers. The elements whose mid-point lies in
 * [x0_m, x1_m) take the segment's E·I and mass per length instead of the
 * beam's E_pa·I_m4 and density_kgm3·A_m2 (0 keeps the beam's). Segments do
 * not overlap; damage scales their E·I like the beam's. */
#define AMFI_MAX_SEGMENTS 16
typedef struct amfi_segment {
    double x0_m, x1_m; /* 0 <= x0 < x1 <= span_m */
    double EI_nm2;     /* flexural stiffness (healthy), N·m², > 0, or 0 */
    double mass_kgpm;  /* mass per length, kg/m, > 0, or 0 */
} amfi_segment;

typedef struct amfi_bridge_params {
    double span_m;         /* beam length L, m, > 0 */
    int n_elements;        /* equal beam elements, 1 .. 1000 */
    double E_pa;           /* Young's modulus (healthy), Pa, > 0 */
    double A_m2;           /* cross-section area, m², > 0 */
    double I_m4;           /* second moment of area, m⁴, > 0 */
    double density_kgm3;   /* ρ, kg/m³, > 0; mass per length μ = ρA */
    double damping_ratio;  /* Rayleigh ξ at the two modes below, 0 .. 1 */
    int rayleigh_mode_a;   /* 1-based mode numbers where ξ is matched */
    int rayleigh_mode_b;   /* (a != b) */
    int n_supports;        /* 1 .. AMFI_MAX_SUPPORTS */
    amfi_support supports[AMFI_MAX_SUPPORTS];
    double damage;         /* δ: E_used = (1 − δ)·E in every element, 0 <= δ < 1 */
    int n_segments;        /* 0 .. AMFI_MAX_SEGMENTS */
    amfi_segment segments[AMFI_MAX_SEGMENTS];
} amfi_bridge_params;

/* The paper-20m reference values of docs/model.md §1 (simply supported, 20 m). */
void amfi_bridge_params_paper20(amfi_bridge_params *p);

typedef struct amfi_bridge amfi_bridge; /* opaque, read-only once created */

/* The E·I (healthy, before damage) and mass per length of the beam at x,
 * from its segments or its uniform section. */
double amfi_bridge_params_EI(const amfi_bridge_params *p, double x_m);
double amfi_bridge_params_mass(const amfi_bridge_params *p, double x_m);

/* Assemble M, K (consistent mass), apply supports, solve K ψ = ω² M ψ
 * (LAPACK dsygvd; inverted, M ψ = K ψ/ω², when the spectrum is wide enough
 * to cost the low modes accuracy), build Rayleigh C. Supports that leave a
 * rigid-body motion (no w held at two distinct nodes, nor w and θ) are
 * refused with AMFI_EINVAL. Work O(n³): milliseconds at 20 elements, about
 * 1.4 s of CPU at 1000 (2000 DOF). Free with amfi_bridge_destroy(). */
int amfi_bridge_create(const amfi_bridge_params *p, amfi_bridge **out,
                       char *err, size_t errlen);
void amfi_bridge_destroy(amfi_bridge *b); /* NULL-safe */

const amfi_bridge_params *amfi_bridge_params_of(const amfi_bridge *b);
int amfi_bridge_ndof(const amfi_bridge *b);        /* n: free DOFs */
const double *amfi_bridge_mass(const amfi_bridge *b);      /* n × n */
const double *amfi_bridge_stiffness(const amfi_bridge *b); /* n × n */
const double *amfi_bridge_damping(const amfi_bridge *b);   /* n × n */
/* ω_k, rad/s, ascending, k = 0 .. n−1 */
const double *amfi_bridge_omega(const amfi_bridge *b);
/* modal damping ratio ζ_k = a0/(2ω_k) + a1·ω_k/2 */
const double *amfi_bridge_zeta(const amfi_bridge *b);
/* Ψ: n × n, column k is mode k, M-orthonormal (Ψᵀ M Ψ = I) */
const double *amfi_bridge_modes(const amfi_bridge *b);
/* Rayleigh coefficients: C = a0·M + a1·K */
void amfi_bridge_rayleigh(const amfi_bridge *b, double *a0, double *a1);

/* Shape row of a point at x (m): out[n] such that w(x) = out · u (Hermitian
 * cubic interpolation in the element holding x). A downward point force F at
 * x has the nodal load vector F·out. Returns 1 and zeros out when x is off
 * the beam (x < 0 or x > L), 0 otherwise. */
int amfi_bridge_shape(const amfi_bridge *b, double x_m, double *out /* n */);

/* Mode values at x: phi[k] = ψ_k(x) = shape(x)·Ψ[:, k], k = 0 .. n−1, from a
 * table built at creation (O(n) per call, no allocation). Returns 1 and
 * zeros off the beam, 0 otherwise. */
int amfi_bridge_mode_values(const amfi_bridge *b, double x_m, double *phi /* n */);

/* Free-DOF index of node `node` (0 .. n_elements), `rot` 0 for w, 1 for θ;
 * −1 when that DOF is restrained or out of range. */
int amfi_bridge_dof(const amfi_bridge *b, int node, int rot);

/* ---- discretisation (docs/model.md §3) --------------------------------- */

/* E = expm(A) by scaling and squaring with Padé approximants (Higham 2005,
 * SIAM J. Matrix Anal. Appl. 26(4), Algorithm 2.3). A, E: n × n. E may not
 * alias A. Allocates its own scratch (called once per problem, not per step). */
int amfi_expm(int n, const double *A, double *E);

/* One mode's closed form, exact for every damping regime: for
 * q'' + 2ζω q' + ω² q = f (f held over the step), state [q; q'],
 * Phi = expm(A h) (2 × 2) and G = ∫0^h expm(A s) ds · [0; 1] (2). ω > 0. */
void amfi_modal_block(double omega, double zeta, double h, double Phi[4],
                      double G[2]);

/* Nodal zero-order hold: Phi = expm(A h) (2n × 2n) and
 * G = ∫0^h expm(A s) ds · [0; M⁻¹] (2n × n), A = [[0, I], [−M⁻¹K, −M⁻¹C]],
 * state [u; u']. G is computed with Van Loan's augmented exponential (1978),
 * which equals A⁻¹(Φ − I)[0; M⁻¹] without inverting A. */
int amfi_nodal_discretise(const amfi_bridge *b, double h, double *Phi,
                          double *G);

/* ---- forward response (independent of the solver's discretisation) ---- */

/* Bridge response to moving point forces by Newmark average acceleration
 * (γ = 1/2, β = 1/4) in nodal coordinates, starting at rest at t = 0, with
 * the force positions evaluated at every integration step. Used by tests and
 * tools as an independent reference for the inverse solver.
 *   force(t, a, user) returns the downward force of axle a at time t, N;
 *   position x_a(t) = speed·t − offset_m[a].
 *   accel_out: n_out × n_sensors, vertical acceleration at sensor_x_m at
 *   t_k = k / out_rate_hz, k = 0 .. n_out−1.
 * dt_s is the integration step; out_rate_hz·dt_s must give an integer number
 * of steps per output sample. */
typedef double (*amfi_force_fn)(double t_s, int axle, void *user);
int amfi_forward_newmark(const amfi_bridge *b, double speed_mps, int n_axles,
                         const double *offset_m, amfi_force_fn force,
                         void *user, int n_sensors, const double *sensor_x_m,
                         double dt_s, double out_rate_hz, int n_out,
                         double *accel_out, char *err, size_t errlen);

/* ---- the A-MFI solver -------------------------------------------------- */

/* Output equation. Only the paper's is kept (docs/model.md §4): the alternatives
 * were implemented and measured worse (docs/solver.md). */
typedef enum amfi_formulation {
    AMFI_FORM_PAPER = 0 /* eqs 13-20: backward-difference acceleration */
} amfi_formulation;

typedef enum amfi_coords {
    AMFI_COORDS_MODAL = 0, /* block-diagonal Φ, reduced state 2m + n_a */
    AMFI_COORDS_NODAL = 1  /* dense reference path, full state 4n + n_a */
} amfi_coords;

typedef enum amfi_modes {
    AMFI_MODES_ALL = 0,        /* every mode */
    AMFI_MODES_OBSERVABLE = 1, /* modes some sensor sees (|ψ(x_s)| > 1e-9·max) */
    AMFI_MODES_COUNT = 2,      /* the n_modes lowest observable modes */
    AMFI_MODES_RESOLVED = 3    /* observable modes the calculation step resolves:
                                  f_k < calc_rate_hz / 2 (issue 12: same GVW to
                                  0.1 kg as all observable, several times faster) */
} amfi_modes;

typedef struct amfi_solver_params {
    amfi_formulation formulation;
    amfi_coords coords;
    amfi_modes modes;
    int n_modes;            /* for AMFI_MODES_COUNT, >= 1 */
    double calc_rate_hz;    /* calculation rate 1/h, Hz (paper: 5000) */
    int n_sensors;          /* 1 .. AMFI_MAX_SENSORS */
    double sensor_x_m[AMFI_MAX_SENSORS];   /* position along the span, m */
    double sensor_weight[AMFI_MAX_SENSORS];/* W = diag(weights), > 0 */
    int max_axles;          /* workspace capacity, 1 .. AMFI_MAX_AXLES */
    double max_duration_s;  /* workspace capacity in time (grown on demand) */
    int fix_initial_force;  /* 0 (default): g_0 free, from min x0ᵀR0x0 + x0ᵀs0;
                               1: g_0 = 0 (use with pre_roll_s > 0) */
    int free_initial_state; /* 0 (default): the bridge is at rest when the window
                               starts (X_0 = 0); 1: X_0 is free too, taken with
                               g_0 from the minimum of the cost-to-go, for a
                               bridge still vibrating from earlier traffic
                               (use with a pre-roll, which shows that vibration) */
    double pre_roll_s;      /* window starts this long before entry, >= 0 */
    double post_roll_s;     /* window ends this long after the last exit, >= 0 */
} amfi_solver_params;

/* Defaults: paper formulation, modal, observable modes, 5000 Hz, one sensor
 * at mid-span of `span_m` with weight 1, 2 axles, 2 s, g_0 free, no rolls. */
void amfi_solver_params_default(amfi_solver_params *p, double span_m);

/* λ policy. λ is stored rate-independent (docs/model.md §7): the residual sum has
 * N ∝ 1/h terms and r ∝ h, so the per-step λ_h = lambda_ref·(h_ref/h)², with
 * h_ref = 1/ref_rate_hz. lambda_ref is the λ one would use at ref_rate_hz
 * (the paper's 7.94e-9 at 5000 Hz). */
typedef struct amfi_lambda {
    int automatic;       /* 0: fixed lambda_ref; 1: L-curve */
    double lambda_ref;   /* fixed value, at ref_rate_hz, > 0 */
    double ref_rate_hz;  /* default 5000 */
    /* L-curve search, all λ at ref_rate_hz: a log grid from lo to hi with
     * per_decade points; then the best interior point's neighbourhood
     * (± one coarse step) refined with refine_points more points. */
    double lcurve_lo, lcurve_hi;
    int lcurve_per_decade;
    int lcurve_refine_points;
} amfi_lambda;

void amfi_lambda_default(amfi_lambda *l); /* fixed 7.94e-9 at 5000 Hz; grid 1e-13..1e-5, 2/decade, 4 refine */

/* One passage as recorded: accelerations sampled uniformly at scan_rate_hz,
 * sample k at time t_first_s + k/scan_rate_hz, where t = 0 is the moment the
 * first axle reaches x = 0. The window (entry − pre_roll .. last exit +
 * post_roll) must lie within the samples. */
typedef struct amfi_passage {
    int n_samples;
    double scan_rate_hz;
    double t_first_s;
    const double *accel[AMFI_MAX_SENSORS]; /* per sensor, n_samples, m/s² */
    double speed_mps;                      /* > 0 */
    int n_axles;                           /* 1 .. max_axles */
    double axle_spacing_m[AMFI_MAX_AXLES]; /* n_axles − 1 spacings, > 0 */
} amfi_passage;

/* The passage window, in seconds relative to entry (t = 0 when the first
 * axle reaches x = 0): the vehicle is on the span over [0, on_span_s]; a
 * solve needs data over [start_s, end_s]. */
typedef struct amfi_passage_times {
    double start_s;   /* entry − pre_roll_s (never −0) */
    double on_span_s; /* (span_m + Σ axle spacings) / speed: the last axle leaves */
    double end_s;     /* on_span_s + post_roll_s */
} amfi_passage_times;

/* The window of a passage of n_axles axles (axle_spacing_m: n_axles − 1
 * spacings, m, summed in order) at speed_mps over a span of span_m. The one
 * definition the solver, the daemon and the tools share; no validation
 * (amfi_solve checks its passage). */
amfi_passage_times amfi_passage_window(double span_m, double speed_mps, int n_axles,
                                       const double *axle_spacing_m, double pre_roll_s,
                                       double post_roll_s);

typedef struct amfi_result {
    double lambda_h;     /* per-step λ actually used */
    double lambda_ref;   /* the same, at ref_rate_hz */
    double h_s;          /* calculation step */
    int n_steps;         /* N: forces at t_0 .. t_N, N + 1 values per axle */
    double t0_s;         /* time of step 0 (relative to entry) */
    int n_axles;
    const double *force_N; /* (N + 1) × n_axles, row-major; owned by the
                              solver, valid until the next solve */
    const double *model_accel; /* N × n_sensors: fitted y_1 .. y_N */
    /* (AMFI_MAX_EVENT_AXLES: the joint solve of an event uses this too) */
    double mean_force_N[AMFI_MAX_EVENT_AXLES]; /* mean of g_a while axle a is on span */
    double axle_kg[AMFI_MAX_EVENT_AXLES];      /* mean_force / g */
    double gvw_kg;                       /* Σ axle_kg */
    double residual_norm;  /* sqrt Σ_j (y_j − d_j)ᵀ W (y_j − d_j) */
    double smoothing_norm; /* sqrt Σ_j r_jᵀ r_j, N */
    double residual_rms;   /* residual_norm / sqrt(N·n_sensors), m/s² */
    double signal_rms;     /* RMS of the data d_1..d_N, m/s² */
    int n_modes;           /* modes used (modal), or n (nodal) */
    int n_solves;          /* sweeps run (1, or the L-curve's count) */
    /* L-curve (automatic λ only): points sorted by λ, owned by the solver */
    int lcurve_n;
    const double *lcurve_lambda_ref; /* lcurve_n */
    const double *lcurve_residual;   /* lcurve_n, residual norm */
    const double *lcurve_smoothing;  /* lcurve_n, smoothing norm */
    const double *lcurve_curvature;  /* lcurve_n, signed; NaN at the ends */
} amfi_result;

typedef struct amfi_solver amfi_solver;

/* Discretise (once) and size the workspace for passages of up to
 * max_duration_s + rolls and max_axles axles. `b` must outlive the solver.
 * Free with amfi_solver_destroy(). */
int amfi_solver_create(const amfi_bridge *b, const amfi_solver_params *p,
                       amfi_solver **out, char *err, size_t errlen);
void amfi_solver_destroy(amfi_solver *s); /* NULL-safe */

/* Solve one passage. The workspace grows (once, before any time loop) when a
 * passage is longer than its capacity. Arrays in `res` point into the
 * solver and stay valid until the next call. */
int amfi_solve(amfi_solver *s, const amfi_passage *p, const amfi_lambda *lam,
               amfi_result *res, char *err, size_t errlen);

/* Bytes held by the solver's workspace, the speed search's coarse model included
 * (for benchmarks). */
size_t amfi_solver_workspace_bytes(const amfi_solver *s);

const char *amfi_formulation_name(amfi_formulation f);
int amfi_formulation_parse(const char *name, amfi_formulation *f); /* 0 ok */

/* ---- speed estimation (issue 12, libamfi/src/speed.c; docs/solver.md) ---- */

/* What the speed search minimises over the trial speed v (the window, λ and
 * data fixed; the detector's speed v0 with relative SD σ as a Gaussian prior):
 *   J(v) = n_eff·ln C(v) + ((v − v0)/(σ·v0))²,
 * the profile log-likelihood of Gaussian residuals of unknown variance plus
 * the prior, n_eff = data samples in the window × sensors (or data_dof
 * below). C(v) is: */
typedef enum amfi_speed_criterion {
    AMFI_SPEED_REGULARISED = 0, /* ‖y − d‖²_W + λ‖r‖²: the A-MFI fit's own cost */
    AMFI_SPEED_RESIDUAL = 1     /* ‖y − d‖²_W alone */
} amfi_speed_criterion;

/* Which point of the grid the search refines around: */
typedef enum amfi_speed_pick {
    AMFI_SPEED_PICK_MIN = 0, /* J's smallest value */
    AMFI_SPEED_PICK_DIP = 1  /* J's deepest dip below its local trend: J minus the mean
                                of J over the grid points 0.6-1.2 % slower and
                                0.6-1.2 % faster. The narrow dip at the true speed
                                (the axles' entry and exit transients) stays where it
                                is when the bridge is stiffer or softer than the
                                model, while the trend tilts towards slower speeds
                                (docs/solver.md). Points closer than 1.2 % to an end
                                of the range have no trend and are not candidates;
                                without any dip (J above its trend everywhere) the
                                smallest value is taken. */
} amfi_speed_pick;

typedef struct amfi_speed_prior {
    double rel_sd;   /* σ: the detector's relative standard deviation, 0 < σ < 1 */
    double range_sd; /* search v0·(1 ± range_sd·σ), > 0, range_sd·σ < 0.5 */
    double grid_rel; /* grid step / v0, 1e-4 .. range_sd·σ: below the cost's dip width */
    double tol_rel;  /* Brent stops when its bracket is below tol_rel·v0, 0 < tol < 0.01 */
    int brent_evals; /* Brent sweeps after the grid (GSL's first point included), 0 .. 100;
                        0: the vertex of the parabola through the pick and its neighbours */
    int local_half;  /* the full model's local grid: ±local_half points 0.3 % apart
                        around the coarse pick, widened toward a pick at its end up
                        to ±3; 1 .. 3 */
    double coarse_rate_hz; /* the grid's model: the same bridge at this calculation
                              rate with the modes it resolves, then the full model
                              refines; 0 (or >= the solver's rate): the grid on the
                              full model. 0 or [100, 1e6] */
    double data_dof; /* n_eff in J; 0: the data samples in the window (the
                        residuals as independent); a small value tempers the
                        data against the prior (model error is correlated) */
    amfi_speed_criterion criterion;
    amfi_speed_pick pick;
} amfi_speed_prior;

/* σ 3 %, ±3 σ, grid 0.2 %, tol 0.02 %, 2 Brent sweeps (after the grid, or the local grid of two levels), coarse model at
 * 1000 Hz, regularised cost. */
void amfi_speed_prior_default(amfi_speed_prior *p);

/* Check a prior (and the detector's speed v0): 0, or AMFI_EINVAL with a
 * message naming the bad field. */
int amfi_speed_prior_check(const amfi_speed_prior *p, double speed_mps, char *err,
                           size_t errlen);

typedef struct amfi_speed_result {
    double speed_given_mps; /* v0, the passage's speed */
    double speed_mps;       /* the estimate: the speed the result was solved with */
    double lo_mps, hi_mps;  /* the range searched (the low end raised to what the data covers) */
    int at_bound;           /* 1: the minimum lay at an end of the range */
    int n_evals;            /* full-model sweeps of the search (the final solve's apart) */
    int n_coarse;           /* coarse-model sweeps (the grid; 0 when single-level) */
    double j_given, j_best; /* J at v0 and at the grid's minimum (two levels: on the
                               coarse model) or at the estimate (one level) */
    double dip;             /* pick dip: the picked grid point's J minus its trend
                               (< 0; NAN when no dip was found or pick is min) */
    int grid_n;             /* the grid: J at grid_lo_mps + k·grid_step_mps, */
    double grid_lo_mps, grid_step_mps; /* k = 0 .. grid_n − 1, on the grid's */
    const double *grid_j;   /* model; held by the solver until its next search */
    int n_aliases;          /* two levels, pick dip: the coarse pick's axle-group aliases
                               with a coarse dip (0 .. AMFI_SPEED_ALIASES; 0 for a
                               vehicle without an axle pair that aliases within the
                               range, e.g. two axles: docs/solver.md) */
    int n_aliases_judged;   /* those the coarse residual did not rule out, judged on
                               the full model */
    int alias;              /* 1: an alias replaced the coarse pick's estimate */
} amfi_speed_result;

/* The most axle-group aliases of the coarse pick the full model judges. */
#define AMFI_SPEED_ALIASES 4

/* Estimate the passage's speed (p->speed_mps is the detector's, the prior
 * mean): J on a grid (on the coarse model, prior->coarse_rate_hz), then a
 * Brent search (GSL gsl_min) on the full model around the grid's minimum,
 * the pick's axle-group aliases judged on the full model by the residual
 * (docs/solver.md, "Axle groups' aliases"), then solve at the
 * estimate as amfi_solve does: `res` is amfi_solve's result at speed_mps
 * (res->n_solves counts every sweep, search included). λ is fixed during
 * the search (the L-curve's at v0 when lam is automatic). The axle spacings
 * are kept as measured. The data must cover the window at the given speed;
 * the search's low end is raised to the slowest speed they cover. */
int amfi_solve_speed(amfi_solver *s, const amfi_passage *p, const amfi_lambda *lam,
                     const amfi_speed_prior *prior, amfi_result *res,
                     amfi_speed_result *sr, char *err, size_t errlen);

const char *amfi_speed_criterion_name(amfi_speed_criterion c);
int amfi_speed_criterion_parse(const char *name, amfi_speed_criterion *c); /* 0 ok */
const char *amfi_speed_pick_name(amfi_speed_pick p); /* "min", "dip" */

/* How far below the detector's speed the search may try, as a fraction of
 * it (the range, and pick dip's trend points beyond it): data for a passage
 * to be estimated should cover the window of speed·(1 − this). 0 .. 0.5. */
double amfi_speed_slowest_frac(const amfi_speed_prior *p);

/* Pick dip's measure at point k of a grid of J (j[0 .. n), the prior's
 * grid step): j[k] minus the mean of the means of j over the points
 * 0.6-1.2 % slower and 0.6-1.2 % faster; NAN where those points are not
 * all on the grid (amfi-solve --speed-trace writes it beside J). */
double amfi_speed_dip_at(const amfi_speed_prior *p, const double *j, int n, int k);

/* ---- several vehicles on the span, solved jointly (multi.c) ------------ */

#define AMFI_MAX_VEHICLES 16

/* amfi_vehicle_result.quality of a vehicle whose axles share an unknown
 * with another vehicle's (coincident axles, below): the data fix only the
 * group's sum. */
#define AMFI_MULTI_QUALITY_UNFIXED 1e6
/* Coincident axles, m: two axles of an event (of two vehicles, or of one)
 * whose distance stays within this, or within the distance the faster
 * travels in one calculation step when that is longer, for as long as
 * either is on the span (side by side on two lanes entering together, or
 * one axle behind another's, at one speed) are one unknown of the solve
 * (transitively). Decided from the geometry (entry times, speeds,
 * spacings) before any sweep: only their sum is in the data (a constant
 * difference of their forces changes neither the fit nor the smoothing
 * term), and solved apart they leave the sweep singular. */
#define AMFI_MULTI_COINCIDENT_M 0.01
/* The factor on λ of amfi_solve_multi's second sweep: an event of several
 * vehicles is weighed at λ times this and its quality figure is the change
 * from λ (amfi_multi_passage.lambda_factor). */
#define AMFI_MULTI_QUALITY_LAMBDA 0.1

/* One vehicle of an event: its first axle reaches x = 0 at entry_s, on the
 * samples' clock (the one of amfi_multi_passage.t_first_s). */
typedef struct amfi_vehicle {
    double entry_s;                        /* finite */
    double speed_mps;                      /* > 0 */
    int n_axles;                           /* 1 .. AMFI_MAX_AXLES; all vehicles
                                              <= AMFI_MAX_EVENT_AXLES */
    double axle_spacing_m[AMFI_MAX_AXLES]; /* n_axles − 1 spacings, > 0 */
} amfi_vehicle;

/* An event: the samples (as in amfi_passage) and the vehicles on the span,
 * in any order (results come back in the order given). */
typedef struct amfi_multi_passage {
    int n_samples;
    double scan_rate_hz;
    double t_first_s;
    const double *accel[AMFI_MAX_SENSORS];
    int n_vehicles; /* 1 .. AMFI_MAX_VEHICLES */
    amfi_vehicle vehicle[AMFI_MAX_VEHICLES];
    /* 0 (the default: a zeroed struct): an event of two or more vehicles
     * at a fixed λ is swept at λ and at λ·AMFI_MULTI_QUALITY_LAMBDA and
     * weighed by the second sweep (round six, docs/results/multi-vehicle.md:
     * the fixed λ, one vehicle's, over-smooths a joint solve; on simulated
     * truck pairs, one mid-span sensor, the pair sums erred 1.2-1.5 % mean
     * abs and up to 6.8 % at λ, 0.55 % and 1.5 % at λ/10, where the same
     * vehicles solved alone do not move with λ); with the L-curve, at its
     * λ; an event of one inseparable group (coincident axles, below: side
     * by side) at λ, as one vehicle. f in [1e-4, 1]: an event of two or more vehicles is weighed at
     * λ·f and its quality sweep run at λ·f·AMFI_MULTI_QUALITY_LAMBDA (f = 1:
     * the weights at λ, as before round six). A vehicle alone is always
     * weighed at λ. The quality figure is the same in the default and at
     * f = 1 (the change between λ and λ/10). */
    double lambda_factor;
    /* Memory budget of one sweep, bytes: an event whose gain array (steps
     * × unknowns × (2·modes + unknowns) doubles, in modal coordinates)
     * would exceed it is solved in segments (amfi_multi_result.n_segments):
     * its vehicles by entry, each segment owning the next ones whose joint
     * window (first owner's entry − pre-roll .. last owner's exit +
     * post-roll) with every axle on the span inside it stays within the
     * budget (at least one owner: a single vehicle's segment may exceed
     * it). 0: AMFI_MULTI_SEGMENT_BYTES. Memory then scales with one
     * vehicle's window and its neighbours' axles, not with the event's
     * length (docs/results/multi-vehicle.md, round seven). */
    size_t max_segment_bytes;
} amfi_multi_passage;

/* The default memory budget of one sweep of amfi_solve_multi, bytes. */
#define AMFI_MULTI_SEGMENT_BYTES ((size_t)32 << 20)

typedef struct amfi_vehicle_result {
    int first_axle;   /* index of its first axle in the joint result */
    int n_axles;
    double axle_kg[AMFI_MAX_AXLES]; /* mean force of its own axles on the span / g */
    int segment;      /* the segment it was weighed in, 0-based (0 when one) */
    double gvw_kg;
    /* Coincident axles (AMFI_MULTI_COINCIDENT_M): the index, in the order
     * given, of the first vehicle of this one's inseparable group (vehicles
     * whose axles share an unknown, transitively), itself when it shares
     * none; n_merged: its axles that share an unknown with another
     * vehicle's. A shared unknown's force is split evenly among its axles
     * in axle_kg and gvw_kg, which the data do not fix: only the group's
     * sum, group_gvw_kg (= gvw_kg for a vehicle of no group), is. The
     * vehicles of a group have quality AMFI_MULTI_QUALITY_UNFIXED, and
     * gvw_sd_kg and separability are the group sum's. */
    int group;
    int n_merged;
    double group_gvw_kg;
    /* How well this vehicle's weight is determined in the event: 1 + the
     * change of its GVW, in % of the GVW at the tighter λ, between the
     * event's two sweeps (λ and λ × AMFI_MULTI_QUALITY_LAMBDA by default,
     * see lambda_factor). Load that close axles of different vehicles
     * trade is decided by the regularisation, so a weight that moves with λ
     * is one the data do not fix (docs/results/multi-vehicle.md: the worst
     * tenth by this figure holds 21-35 of the 60 largest errors of 300
     * pairs, separability 12-19). 1 exactly for a vehicle alone in its
     * event (no second sweep then). AMFI_MULTI_QUALITY_UNFIXED for every
     * vehicle of an inseparable group (coincident axles, above): the
     * weights are still returned, but the data do not fix how they split. */
    double quality;
    /* σ·sqrt(uᵀA⁻¹u)/g with σ the joint fit's residual RMS: the posterior
     * standard deviation of the weight under the constant-axle-load model
     * of separability, kg */
    double gvw_sd_kg;
    /* Separability of this vehicle's weight from the others' (the quality
     * figure before round four): with constant axle loads as the model,
     * A = Σ_j Gᵀ W G the normal matrix of all axles (G the sensors' response
     * to unit loads moving with the axles) and u the vehicle's axle
     * indicator, sqrt(uᵀA⁻¹u / uᵀ(A_vv)⁻¹u): the factor by which the other
     * vehicles inflate the standard deviation of this vehicle's weight.
     * 1 = alone or fully separable; large = its axles nearly coincide with
     * another vehicle's. It misses the trade of time-varying loads between
     * axles a metre or two apart, hence quality above. */
    double separability;
} amfi_vehicle_result;

typedef struct amfi_multi_result {
    amfi_result all; /* the joint solve: all axles, vehicle by vehicle in the
                        order given; t0_s on the samples' clock; the force
                        and mean of an unknown of coincident axles split
                        evenly among them */
    int n_unknowns;  /* the axles' unknowns: all.n_axles less coincident ones */
    int axle_unknown[AMFI_MAX_EVENT_AXLES]; /* the unknown of each axle (numbered
                                         in order of first axle); axles sharing
                                         one were coincident. A segmented event
                                         (n_segments > 1): numbered within each
                                         vehicle's segment */
    /* 1: the event was solved in one sweep over its window. > 1: it was too
     * large for the memory budget (amfi_multi_passage.max_segment_bytes) and
     * was solved in that many segments, each over the windows of some of its
     * vehicles (the segment's owners, weighed there) with every axle on the
     * span inside that window as an unknown; `all` is then the last
     * segment's joint solve (its window, its axles). */
    int n_segments;
    size_t max_segment_bytes; /* the largest segment's gain array, bytes */
    int n_vehicles;
    amfi_vehicle_result vehicle[AMFI_MAX_VEHICLES];
    double total_gvw_kg; /* Σ of the vehicles' GVW */
} amfi_multi_result;

/* The event window on the samples' clock: start_s = first entry − pre_roll,
 * on_span_s = the last exit, end_s = last exit + post_roll. No validation. */
amfi_passage_times amfi_multi_window(double span_m, const amfi_multi_passage *p,
                                     double pre_roll_s, double post_roll_s);

/* Solve all vehicles' axles in one sweep, coincident axles as one unknown
 * (AMFI_MULTI_COINCIDENT_M). The workspace grows (outside the
 * time loop) to the event's total axles and duration, the quality figures'
 * scratch included; an event no larger than one before allocates nothing.
 * An event over the memory budget is solved in segments
 * (amfi_multi_passage.max_segment_bytes). Refused: no vehicles, more than
 * AMFI_MAX_VEHICLES, a vehicle of more than AMFI_MAX_AXLES axles, more
 * than AMFI_MAX_EVENT_AXLES axles in all (AMFI_EINVAL); data not covering
 * the window (AMFI_ERANGE). */
int amfi_solve_multi(amfi_solver *s, const amfi_multi_passage *p, const amfi_lambda *lam,
                     amfi_multi_result *res, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_AMFI_H */
