/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * scale.h: the scale indicator (issue 14): the factor by which the
 * distribution of inferred gross vehicle weights (GVW) is stretched against
 * the healthy baseline, made robust to the traffic mix, compensated for the
 * deck temperature, and watched by a one-sided CUSUM (cusum.h). A uniform
 * stiffness loss d scales every inferred GVW by 1 / (1 − d); so does a
 * warm deck (the modulus falls) and, the other way, a frozen one.
 *
 *   classes    the baseline's temperature-compensated GVWs are split at
 *              class_split_kg into empty and loaded vehicles, whose
 *              empirical CDFs E and L are the reference. A block of B
 *              vehicles is fitted with the same two classes stretched by a
 *              common factor s and with a FREE
 *              loaded share pi (Cramér–von Mises fit, pi within the
 *              baseline's ± share_range, since a scale and a share can
 *              mimic each other when the classes touch): the mix moves pi,
 *              the stiffness moves s. Why not quantile ratios:
 *              docs/indicators.md ("Scale indicator"), measured with
 *              amfi-year-sim --mix-probe.
 *   temperature ln GVW = b0 + b_warm · h1(T) + b_frost · h2(T) with the knee
 *              at knee_c: h1 = max(T − knee, 0), h2 = clamp(T − knee,
 *              floor − knee, 0) (flat below the floor, like the frozen
 *              deck). The slopes are fitted on the baseline blocks by a
 *              ridge regression towards the prior slopes (prior SD
 *              slope_prior_sd): where the baseline covers a side of the
 *              knee the data decide, where it does not (no frost in a
 *              summer baseline) the prior stands. Each vehicle's GVW is
 *              divided by exp(b_warm h1(T) + b_frost h2(T)) before use.
 *   CUSUM      z = (ln s − mean0) / sigma0, mean0 the mean ln s of the
 *              baseline blocks (the estimator's small offset), sigma0 the larger of the SD of the
 *              baseline blocks' residual ln s and a bootstrap SD of one
 *              block's ln s; k_ref = ln(1 / (1 − design_shift)) / (2
 *              sigma0); h from the target false alarms per year through
 *              Siegmund's approximation with ARL0 = blocks per year /
 *              false_alarms_per_year (blocks per year from
 *              vehicles_per_day), held at a null mean of 1 / sqrt(baseline
 *              blocks) (the standard error of mean0, in sigma0 units).
 *   alert      kind "scale_shift", level warning: raised when S >= h,
 *              cleared after clear_after consecutive blocks with S = 0
 *              (while raised, S is capped at h, so a clear takes about
 *              h / k_ref + clear_after blocks after the shift is gone).
 *              Alerts are state changes (one event each).
 *
 * Workload: one push per ok passage (O(1)); every B pushes one fit of a
 * block (a sort and about 90 passes of O(B)); the baseline fit once (a sort
 * of n_b values, its blocks and 2 × 100 bootstrap blocks). Pure computation: no I/O,
 * no logging; allocation only in amfi_scale_create. One handle is used by
 * one thread at a time.
 */
#ifndef AMFI_INDICATORS_SCALE_H
#define AMFI_INDICATORS_SCALE_H

#include <stddef.h>

#include "indicators.h" /* AMFI_IND_* codes, AMFI_IND_MAX_GVW_KG, amfi_alert_event */

/* Deck temperatures outside this range are refused (°C). */
#define AMFI_SCALE_T_MIN (-60.0)
#define AMFI_SCALE_T_MAX 90.0

typedef struct amfi_scale_params {
    int block;                /* B: vehicles per scale estimate, >= 50 */
    int baseline_blocks;      /* blocks in the baseline, >= 4 */
    double class_split_kg;    /* GVW between empty and loaded vehicles at the site, kg */
    double share_range;       /* a block's loaded share is fitted within the baseline's ± this */
    double ref_c;             /* deck temperature at which the solver's modulus holds, °C */
    double knee_c;            /* knee of the temperature model, °C */
    double floor_c;           /* below this the model is flat, °C (< knee_c) */
    double warm_slope;        /* prior d ln(GVW) / dT above the knee, 1/°C */
    double frost_slope;       /* prior d ln(GVW) / dT between floor and knee, 1/°C */
    double slope_prior_sd;    /* prior SD of both slopes, 1/°C, > 0 (0: slopes fixed) */
    double design_shift;      /* stiffness loss the CUSUM is tuned for, (0, 0.5) */
    double false_alarms_per_year; /* target, > 0 */
    double vehicles_per_day;  /* expected flow, converts the target to an ARL0, > 0 */
    int clear_after;          /* blocks with S = 0 that clear the alert, >= 1 */
} amfi_scale_params;

/* The defaults (B 500, 40 blocks, knee 0 °C, floor −10 °C, slopes 0.0025 and
 * 0.018 /°C, prior SD 0.001, design 2.5 %, 0.05 false alarms a year at
 * 2000 vehicles a day: the design rate; the measured one is about 5 times
 * that, docs/indicators.md), justified in docs/indicators.md. */
void amfi_scale_params_default(amfi_scale_params *p);

/* 0 when *p is valid, else AMFI_IND_EINVAL with *field (may be NULL) the
 * parameter's name and err (may be NULL) a message naming it. */
int amfi_scale_params_check(const amfi_scale_params *p, const char **field, char *err,
                            size_t errlen);

typedef struct amfi_scale amfi_scale;

int amfi_scale_create(const amfi_scale_params *p, amfi_scale **out, char *err, size_t errlen);
void amfi_scale_destroy(amfi_scale *s); /* NULL-safe */

/* The fitted baseline model (valid once amfi_scale_has_baseline). */
typedef struct amfi_scale_model {
    double pi;                /* loaded share of the baseline */
    double warm_slope, frost_slope; /* fitted slopes, 1/°C */
    double t_min_c, t_max_c;  /* deck temperature range of the baseline */
    double mean0;             /* mean ln s of the baseline blocks (the estimator's offset) */
    double sigma0;            /* SD of one block's ln s under the null */
    double sigma_resid, sigma_boot; /* its two estimates */
    double k_ref, h;          /* the CUSUM's reference value and threshold, sigma0 units */
} amfi_scale_model;

int amfi_scale_has_baseline(const amfi_scale *s);
/* Copies the model into *m; AMFI_IND_EINVAL before the baseline exists. */
int amfi_scale_get_model(const amfi_scale *s, amfi_scale_model *m);

/* Restore the alert state after a restart (0 or 1). */
void amfi_scale_set_alerted(amfi_scale *s, int alerted);

/* "baseline" | "normal" | "watch" (S > 0) | "alert" (a static string). */
const char *amfi_scale_state(const amfi_scale *s);

typedef struct amfi_scale_eval {
    int n;                    /* vehicles in the block (B), or the baseline's count */
    double scale;             /* s: the block's compensated stretch against the baseline */
    double pi;                /* the block's loaded share */
    double deck_mean_c;       /* mean deck temperature of the block */
    double raw_scale;         /* s of the block without temperature compensation */
    double z;                 /* ln s / sigma0 */
    double cusum, h;          /* S after this block, and the threshold */
    const char *state;
} amfi_scale_eval;

/* Feed one ok passage: GVW (kg) and deck temperature (°C) at its time.
 * Returns a mask of AMFI_IND_EVAL (a block was evaluated, *eval),
 * AMFI_IND_BASELINE (the baseline model was just fitted; a degenerate
 * baseline, e.g. a class with fewer than 2 vehicles, is dropped and
 * collected again, returning 0) and AMFI_IND_ALERT
 * (*alert holds a state change); 0 when the push only entered the block.
 * Returns AMFI_IND_EINVAL for a GVW that is not finite, <= 0 or above
 * AMFI_IND_MAX_GVW_KG, or a temperature not finite or outside
 * [AMFI_SCALE_T_MIN, AMFI_SCALE_T_MAX]; nothing changes then. eval and
 * alert may be NULL. */
int amfi_scale_push(amfi_scale *s, double gvw_kg, double deck_c, amfi_scale_eval *eval,
                    amfi_alert_event *alert);

/* The factor that brings a GVW inferred at deck temperature deck_c to the
 * calibration temperature p->ref_c under the model with slopes warm and
 * frost (p's knee_c and floor_c): exp(−(warm · (h1(T) − h1(ref)) + frost ·
 * (h2(T) − h2(ref)))). */
double amfi_scale_temp_factor(const amfi_scale_params *p, double warm, double frost,
                              double deck_c);

/* The model's two regressors at deck temperature deck_c (p's knee_c and
 * floor_c): g1 = max(T − knee, 0), g2 = clamp(T − knee, floor − knee, 0). */
void amfi_scale_temp_terms(const amfi_scale_params *p, double deck_c, double *g1, double *g2);

/* The ridge regression of the temperature model, shared by the indicators
 * that compensate for it (the scale's baseline blocks, the natural
 * frequency): y = d0 + d1 g1 + d2 g2 by least squares with lam added to the
 * slopes' diagonal (shrinking d1, d2 towards 0: fit y as the residual of
 * the prior slopes to shrink towards the prior). Zero it, add the points,
 * solve: AMFI_IND_OK, or AMFI_IND_EINVAL when singular. */
typedef struct amfi_temp_ridge {
    double a[3][3], r[3]; /* normal equations */
    int n;
} amfi_temp_ridge;
void amfi_temp_ridge_add(amfi_temp_ridge *t, double g1, double g2, double y);
int amfi_temp_ridge_solve(const amfi_temp_ridge *t, double lam, double d[3]);

/* The baseline's two classes (empty: compensated GVW below class_split_kg,
 * loaded: above), their empirical CDFs tabulated on a grid, and the share
 * of loaded vehicles. A value type (about 16 kB). */
#define AMFI_SCALE_GRID 1024
typedef struct amfi_scale_ref {
    double split_kg, pi;
    double share_range;                /* a block's share stays within pi ± this */
    double x0, dx;                     /* grid: x0 + g · dx, g < AMFI_SCALE_GRID */
    double f_empty[AMFI_SCALE_GRID], f_loaded[AMFI_SCALE_GRID];
} amfi_scale_ref;

/* Fit *r to the n >= 4 values w (kg; sorted in place), a block's share
 * constrained to the baseline's ± share_range (0, 1]. AMFI_IND_EINVAL when
 * a class has fewer than 2 values or an argument is out of range. */
int amfi_scale_ref_fit(amfi_scale_ref *r, double *w, int n, double split_kg, double share_range);

/* The robust block estimator (tests, tools): ln s of the n >= 2 values x
 * (kg, compensated; sorted in place) against *r, the block's loaded share
 * in *pi (may be NULL): the (s, pi) minimizing the Cramér–von Mises
 * distance between the block's empirical CDF and pi · L(x / s) + (1 − pi) ·
 * E(x / s), pi in closed form (clamped to the baseline's ± share_range), ln s by a scan of [−0.3, 0.3] and a golden
 * section (to 1e-6). NAN when n < 2. */
double amfi_scale_ref_block_log(const amfi_scale_ref *r, double *x, int n, double *pi);

#endif
