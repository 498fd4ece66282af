/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * commission.h: commissioning a site's bridge model from calibration runs
 * (trucks of known static axle loads) and the bridge's own free vibration
 * (docs/commissioning.md has the method and its justification).
 *
 * Three stages:
 *  1. Modal identification: the free vibration after each run (and ambient
 *     records) is fitted with damped sinusoids (GSL multifit_nlinear), giving
 *     the first natural frequency and damping ratio with their spread.
 *  2. Model updating: the flexural stiffness scale, the mass scale, the
 *     bearings' rotational stiffness, the sensor offset, the detector's clock
 *     offset and speed scale are fitted by nonlinear least squares (GSL
 *     multifit_nlinear, trust region, finite-difference Jacobian) to
 *       - the measured f1 (weighted by its spread),
 *       - each run's A-MFI axle loads against the known static loads,
 *       - each run's A-MFI residual with the free vibration after the last
 *         axle inside the window: a model that does not fit the bridge
 *         cannot explain the free vibration with any force history.
 *  3. λ: the design's, or (fit_lambda, or a design with λ auto) the
 *     regularisation that weighs the runs best, chosen on the runs left out
 *     (leave one run out).
 * The covariance of the fit (J^T J)^-1 scaled by the residual variance gives
 * each parameter's uncertainty; parameters whose correlation is above 0.98
 * trade against each other and the set is refused, naming them.
 *
 * Not thread-safe per run set; allocation at load and per identification.
 */
#ifndef AMFI_COMMISSION_H
#define AMFI_COMMISSION_H

#include <stddef.h>

#include "amfi/amfi.h"
#include "amfi_config.h"

#define CM_MAX_RUNS 200
#define CM_MIN_RUNS 4

/* One calibration run as RUNS.csv gives it (what the detector said) and
 * its samples (every sensor of the site, in the site's sensor order). */
typedef struct cm_run {
    char file[512];         /* as written in RUNS.csv */
    long line;              /* RUNS.csv line */
    double speed_mps;       /* detector's */
    int n_axles;
    double spacing_m[AMFI_MAX_AXLES]; /* n_axles − 1, detector's */
    double entry_s;         /* detector's entry time on the file's clock */
    double axle_kg[AMFI_MAX_AXLES];   /* static, weighed */
    double gvw_kg;          /* Σ axle_kg */
    int n_samples;
    double rate_hz;
    double t0_s;            /* first sample on the file's clock */
    double *accel[AMFI_MAX_SENSORS];  /* n_samples each, owned */
    /* Each run's own speed (cm_options.speed_sd > 0; 0 and the detector's
     * speed otherwise): the run's speed at model clock offset c is
     *   speed_mps · exp(−(speed_eps + (c − cm_runs.clock_ref) · speed_gdev))
     * before the common speed scale. speed_eps: log(detector / estimated)
     * less its mean over the runs (the random part of the detector's error;
     * the mean is the common scale's); speed_gdev: how that moves with the
     * clock the estimate assumed (an entry time late by δ makes the
     * estimate match the exit, v·(1 + δ·v/L)), less its mean. */
    double speed_eps, speed_gdev;
    double speed_est_mps;   /* the estimate (0: not estimated) */
    double speed_ref_mps;   /* the speed that places the free-vibration stretch */
} cm_run;

typedef struct cm_runs {
    int n;
    int speed_estimated;    /* 1: the runs' speed_eps and speed_gdev apply */
    double clock_ref;       /* the clock offset the estimates assumed, s */
    double speed_ymean, speed_gmean; /* means of log(detector/estimate) and the slope */
    cm_run run[CM_MAX_RUNS];
} cm_runs;

/* Reads RUNS.csv (header file,speed_mps,axle_spacings_m,entry_time_s,axle_kg;
 * lists separated by ';', front to back; file relative to RUNS.csv's
 * folder) and every run's acceleration file for the site's n_sensors
 * sensors. 0, or −1 with one line "RUNS.csv:LINE: column: problem" in err.
 * Refuses: a missing or bad file, loads that do not match the axles, a
 * window (entry − 0.3 s .. last axle off + 0.5 s) outside the samples,
 * fewer than CM_MIN_RUNS or more than CM_MAX_RUNS runs. */
int cm_runs_read(const char *path, const amfi_site_config *site, cm_runs *out, char *err,
                 size_t errlen);
void cm_runs_free(cm_runs *r);

/* Damped free vibration of one or more modes fitted to y[0 .. n) sampled
 * at rate_hz: y(t) = Σ e^{−ζωt}(a cos ω_d t + b sin ω_d t). */
typedef struct cm_modal {
    int ok;
    double f_hz;       /* undamped natural frequency ω/2π of the first mode */
    double zeta;       /* its damping ratio */
    double amplitude;  /* sqrt(a² + b²), m/s² */
    double fit_rel;    /* RMS residual / RMS signal */
} cm_modal;

/* Fits the first mode to the record y (a free-vibration tail), searching
 * from the largest spectral peak between f_lo and f_hi Hz. 0 and *out, or
 * −1 when the record is too short (< 4 periods) or the fit fails. */
int cm_modal_fit(const double *y, int n, double rate_hz, double f_lo, double f_hi,
                 cm_modal *out);

/* The updated parameters, relative to the design site file. */
/* The stiffness and mass enter as their ratio (what f1 fixes) and a common
 * scale (what the known loads fix: scaling E·I and μ together leaves every
 * frequency and mode and scales the inferred forces): E·I = c·r·EI_design,
 * μ = c·μ_design. */
enum {
    CM_P_EI,     /* log r: stiffness over mass, relative to the design's */
    CM_P_MASS,   /* log c: the common scale (= the mass scale) */
    CM_P_KAPPA,  /* log κ, κ = k_θ L / EI (the updated E·I): the bearings' rotational
                    stiffness */
    CM_P_SENSOR, /* sensor offset, m (every sensor moved alike) */
    CM_P_CLOCK,  /* detector clock offset, s: detector time − true time */
    CM_P_SPEED,  /* log of the detector's speed scale: reported / true */
    /* Per-segment stiffness (cm_options.n_segments > 0): CM_P_SEG + i is
     * the log of segment i's E·I relative to the common stiffness scale
     * (site segment i's E·I = c·r·e^{p}·its design E·I). One segment, the
     * one holding the first sensor, is the reference (held at 0: f1 and the
     * ratio r fix the common level); the others are fitted. 0 and unused
     * otherwise (a design's own segments then scale with the common scale). */
    CM_P_SEG,
    CM_N_PARAMS = CM_P_SEG + AMFI_MAX_SEGMENTS
};

/* Per-segment fits: at most this many equal segments, at least 2 runs per
 * fitted parameter, and each segment's stiffness known to within
 * CM_SEG_MAX_SD (relative standard uncertainty) or the fit is refused. */
#define CM_MAX_FIT_SEGMENTS 8
#define CM_SEG_MAX_SD 0.02

typedef struct cm_options {
    int fit[CM_N_PARAMS];    /* 1: fitted, 0: held at the design's */
    double tail_s;           /* free vibration in the window, s (default 1.0) */
    double search_rate_hz;   /* calculation rate of the search (0, the default:
                                the site's calc_rate_hz; the bearing scan at
                                2000 Hz at most) */
    int max_search_runs;     /* runs used while searching (default 8, spread in speed) */
    int fit_lambda;          /* 1: λ from the runs (leave one out); 0 (default): the
                                design's (the runs' λ weighed traffic 0.3-0.6 % heavy) */
    double speed_sd;         /* > 0: the detector's speed carries a random error of this
                                relative SD per run (the paper's Table 5: 0.03): each
                                run's speed is estimated from its acceleration
                                (amfi_solve_speed, this SD as the prior) and only the
                                mean of the detector's error is its speed scale;
                                0 (default): the detector's speeds, one common scale */
    int resolved_modes;      /* 1: solve with the modes the calculation step resolves
                                (AMFI_MODES_RESOLVED) where the site says observable or
                                all: the scans and the search (set by cm_identify); the
                                weighings before and after keep the site's modes */
    int n_segments;          /* > 0: the span cut into this many equal segments, each
                                with its own E·I scale (2 .. CM_MAX_FIT_SEGMENTS; the
                                design's own segments must end on their boundaries);
                                0 (default): one stiffness scale for the whole beam */
    int verbose;             /* progress on stderr */
} cm_options;

void cm_options_default(cm_options *o);

/* What one model makes of the runs. */
typedef struct cm_eval {
    double gvw_err_pct[CM_MAX_RUNS]; /* 100 (GVW − known)/known */
    double axle_err_pct[CM_MAX_RUNS][AMFI_MAX_AXLES];
    double resid_rel[CM_MAX_RUNS];   /* residual RMS / signal RMS, with the tail */
    double free_rel[CM_MAX_RUNS];    /* residual RMS over the free vibration only (a
                                        stretch fixed on the file's clock) / signal RMS */
    double f1_hz;                    /* the model's first natural frequency */
    double mean_abs_gvw_pct, worst_gvw_pct, mean_gvw_pct, mean_resid_rel;
} cm_eval;

typedef struct cm_result {
    double p[CM_N_PARAMS];      /* fitted values (see the enum) */
    double sd[CM_N_PARAMS];     /* their standard uncertainties (NaN: held) */
    double cov[CM_N_PARAMS][CM_N_PARAMS]; /* covariance of the fitted parameters */
    double kappa_grid[16], kappa_cost[16]; /* the bearing scan: κ and its cost */
    int n_kappa;
    double corr_max;            /* the largest |correlation| between fitted params */
    int corr_i, corr_j;
    double f1_meas_hz, f1_meas_sd_hz, zeta_meas, zeta_meas_sd;
    int n_modal;                /* records whose free vibration was fitted */
    double lambda_ref;          /* chosen λ at the site's lambda_ref_rate_hz */
    int lambda_fitted;          /* 1: λ chosen from the runs; 0: the design's */
    amfi_site_config site;      /* the commissioned site */
    cm_eval before, after;      /* the design model and the commissioned one, all runs */
    double loo_gvw_err_pct[CM_MAX_RUNS]; /* leave one run out */
    int iterations, evaluations; /* the search's */
    int scan_evaluations;       /* the scans' (at their coarse rate, on fewer runs) */
    double seconds;
    /* the runs' own speeds (speed_sd > 0): each run's speed at the
     * commissioned clock and scale (the true speed as found), the SD of the
     * detector's random part over the runs, % */
    int speeds_estimated;
    double run_speed_mps[CM_MAX_RUNS];
    double run_speed_sd_pct;
    /* the detector's speed scale found (log, and its SD): p[CM_P_SPEED], or
     * with the runs' speeds estimated (p[CM_P_SPEED] then 0: each run is
     * weighed at its own) the mean of their log(detector / estimate) */
    double speed_scale_log, speed_scale_sd;
    double cpu_speed_s;         /* CPU seconds of the runs' speed estimates */
    /* process CPU seconds of the stages: modal identification with the
     * design's weighing, the scans, the search, the final weighing */
    double cpu_modal_s, cpu_scan_s, cpu_search_s, cpu_final_s;
    /* per-segment stiffness (n_segments > 0): each segment's E·I over the
     * design's (c·r·e^{p[CM_P_SEG + i]}) and its relative standard
     * uncertainty (f1's, the common scale's and the fitted parameters'
     * through the f1 constraint); the largest |correlation| between two
     * segments' stiffness or a segment's and another fitted parameter */
    int n_segments, seg_ref;
    double seg_x0_m[AMFI_MAX_SEGMENTS], seg_x1_m[AMFI_MAX_SEGMENTS];
    double seg_scale[AMFI_MAX_SEGMENTS], seg_sd_rel[AMFI_MAX_SEGMENTS];
    double seg_corr_max;
    char seg_corr_what[160];
    /* the most negative correlation between two segments (they trade: one
     * stiffer, the other softer, fit alike) */
    double seg_trade_corr;
    char seg_trade_what[160];
} cm_result;

/* Stage 1 on every run's tail and the ambient records (n_amb, each amb[i]
 * of amb_n[i] samples at amb_rate[i]): the median f1 and ζ and their
 * spreads. 0, or −1 with a reason when fewer than 3 records give a fit. */
int cm_modal_identify(const cm_runs *runs, const amfi_site_config *design,
                      const double *const *amb, const int *amb_n, const double *amb_rate,
                      int n_amb, cm_result *res, char *err, size_t errlen);

/* Evaluates a site model on the runs (with the detector corrections in p:
 * CM_P_SENSOR is already applied in `site`, clock and speed from p). */
int cm_evaluate(const amfi_site_config *site, const double *p, const cm_runs *runs,
                const cm_options *o, double calc_rate_hz, const int *use, cm_eval *ev,
                char *err, size_t errlen);

/* The site model for parameters p (design scaled, springs, sensor moved). */
int cm_site_apply(const amfi_site_config *design, const double *p, amfi_site_config *out,
                  char *err, size_t errlen);

/* All three stages (and, with o->speed_sd > 0, each run's speed estimated
 * first: written into the runs' speed fields). 0 and *res; −1 with one line in err when the runs
 * cannot identify the model (too few, speeds too alike, parameters that
 * trade against each other: named) or a solve fails. */
int cm_identify(const amfi_site_config *design, cm_runs *runs,
                const double *const *amb, const int *amb_n, const double *amb_rate, int n_amb,
                const cm_options *o, cm_result *res, char *err, size_t errlen);

extern const char *const cm_param_names[CM_N_PARAMS];

#endif
