/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * known_truck.h: the known-truck indicator (issue 14): runs of a pre-weighed
 * calibration truck (its reference GVW from a static scale, as in bridge-WIM
 * calibration practice). Each run gives the ratio inferred / reference GVW;
 * the ratio is brought to the calibration temperature by the same bilinear
 * deck-temperature model as the scale indicator (scale.h), and its log is
 * watched by a one-sided CUSUM (cusum.h) against the mean of the first
 * baseline_runs runs.
 *
 *   z = (ln r_c − mean_b) / sigma, sigma = max(run_sd, SD of the baseline
 *   runs); k_ref = ln(1 / (1 − design_shift)) / (2 sigma); h from Siegmund's
 *   approximation with ARL0 = runs_per_year / false_alarms_per_year, held
 *   at a null mean of 1 / sqrt(baseline_runs) (the baseline mean's
 *   standard error). Alert kind "known_truck", level warning: raised when
 *   S >= h, cleared after clear_after runs with S = 0 (S capped at h while
 *   raised).
 *
 * Workload: a handful of runs a month, O(1) each; no allocation after
 * create. Pure computation; one handle is used by one thread at a time.
 */
#ifndef AMFI_INDICATORS_KNOWN_TRUCK_H
#define AMFI_INDICATORS_KNOWN_TRUCK_H

#include <stddef.h>

#include "indicators.h" /* AMFI_IND_* codes, amfi_alert_event */
#include "scale.h"      /* the temperature model's parameters */

typedef struct amfi_known_truck_params {
    int baseline_runs;            /* runs averaged for the baseline, >= 2 */
    double run_sd;                /* a-priori SD of one run's ln ratio (the per-vehicle
                                   * error over the truck's weight), > 0 */
    double design_shift;          /* stiffness loss the CUSUM is tuned for, (0, 0.5) */
    double false_alarms_per_year; /* target, > 0 */
    double runs_per_year;         /* expected runs a year (52: one a week), > 0 */
    int clear_after;              /* runs with S = 0 that clear the alert, >= 1 */
} amfi_known_truck_params;

/* Defaults: 4 baseline runs, run SD 0.02 (0.3 t over a 14 t truck), design
 * 5 %, 0.2 false alarms a year at 52 runs a year, clear after 2. */
void amfi_known_truck_params_default(amfi_known_truck_params *p);

int amfi_known_truck_params_check(const amfi_known_truck_params *p, const char **field,
                                  char *err, size_t errlen);

typedef struct amfi_known_truck amfi_known_truck;

/* temp: the temperature model (its ref_c, knee_c, floor_c, warm_slope and
 * frost_slope are used; checked like the scale indicator's). */
int amfi_known_truck_create(const amfi_known_truck_params *p, const amfi_scale_params *temp,
                            amfi_known_truck **out, char *err, size_t errlen);
void amfi_known_truck_destroy(amfi_known_truck *k); /* NULL-safe */

/* Replace the slopes (e.g. by those the scale indicator fitted); affects
 * the runs from now on. AMFI_IND_EINVAL when not finite or |slope| > 0.1. */
int amfi_known_truck_set_slopes(amfi_known_truck *k, double warm_slope, double frost_slope);

typedef struct amfi_known_truck_eval {
    int run;                 /* runs so far, this one included */
    double ratio;            /* inferred / reference */
    double ratio_comp;       /* brought to the calibration temperature */
    double baseline_ratio;   /* exp(mean_b), 0 during the baseline */
    double z, cusum, h, sigma;
    const char *state;       /* "baseline" | "normal" | "watch" | "alert" */
} amfi_known_truck_eval;

/* One run: inferred and reference GVW (kg, finite, in (0, AMFI_IND_MAX_GVW_KG]),
 * deck temperature (°C, in [AMFI_SCALE_T_MIN, AMFI_SCALE_T_MAX]). Returns a
 * mask of AMFI_IND_EVAL (always, *eval filled), AMFI_IND_BASELINE (this run
 * completed the baseline) and AMFI_IND_ALERT (*alert holds a state
 * change), or AMFI_IND_EINVAL and nothing changes. eval, alert may be NULL. */
int amfi_known_truck_push(amfi_known_truck *k, double inferred_kg, double reference_kg,
                          double deck_c, amfi_known_truck_eval *eval, amfi_alert_event *alert);

void amfi_known_truck_set_alerted(amfi_known_truck *k, int alerted);
const char *amfi_known_truck_state(const amfi_known_truck *k);

#endif
