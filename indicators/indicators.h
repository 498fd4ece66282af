/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * indicators.h: amfid's damage indicator engine. It watches the spread of
 * the inferred gross vehicle weights (GVW) of ok passages: the paper's
 * damage indicator is the standard deviation of inferred GVW over a batch of
 * vehicles (paper §4.2, Table 4), which rises as the bridge loses stiffness.
 *
 * Workload: one push per ok passage (O(1)); every K pushes an evaluation of
 * the rolling window of the last W GVWs, recomputed exactly in two passes
 * (O(W), no running sums, so no drift), plus one F and one t distribution
 * tail (GSL). Pure computation: no I/O, no printing, no logging; the only
 * allocation is in amfi_indicators_create. One handle is used by one thread
 * at a time.
 *
 * The rules, the defaults and the simulation that justifies them are in
 * docs/indicators.md (tools/amfi-indicator-sim.c measures them).
 *
 *   baseline   the first baseline_n ok GVWs after commissioning (or a
 *              baseline set explicitly / restored from the store) give the
 *              healthy mean and STD. State "baseline" until then.
 *   window     a ring of the last W ok GVWs (every push enters it, also
 *              during the baseline collection).
 *   cadence    once a baseline exists and the window is full, the first push
 *              evaluates, then every K-th push. The push that establishes
 *              the automatic baseline does not evaluate; the next one does.
 *              set_baseline and prefill restart the cadence (the next push
 *              evaluates).
 *   STD rule   raise when std_ratio = window STD / baseline STD >=
 *              std_alert_ratio AND the one-sided variance-ratio test
 *              p = P(F >= s_w²/s_b²), F ~ F(W − 1, n_b − 1), is <= std_alert_p,
 *              for raise_after consecutive evaluations; clear when
 *              std_ratio < std_clear_ratio for clear_after consecutive
 *              evaluations (hysteresis). Level "warning", kind
 *              "std_increase".
 *   mean rule  (mean_shift = 1) the same with mean_ratio = window mean /
 *              baseline mean and a two-sided Welch t-test; the direction of
 *              the shift is not assumed: raise when mean_ratio >=
 *              mean_alert_ratio or <= 1 / mean_alert_ratio, clear when it is
 *              back inside (1 / mean_clear_ratio, mean_clear_ratio). Level
 *              "info", kind "mean_shift" (the mean drifts with the traffic
 *              mix in real traffic).
 *   alerts     are state changes: one event when raised, one when cleared.
 *
 * GVWs are in kg. A GVW that is not finite, <= 0 or above
 * AMFI_IND_MAX_GVW_KG is rejected with AMFI_IND_EINVAL and changes nothing.
 */
#ifndef AMFI_DAEMON_INDICATORS_H
#define AMFI_DAEMON_INDICATORS_H

#include <stddef.h>

/* Status codes (the same values as libamfi's AMFI_OK / AMFI_EINVAL /
 * AMFI_ENOMEM; this module does not depend on libamfi). */
#define AMFI_IND_OK 0
#define AMFI_IND_EINVAL (-1) /* an argument is out of range or inconsistent */
#define AMFI_IND_ENOMEM (-2) /* allocation failed (create only) */

/* Bits of amfi_indicators_push's return value (>= 0). */
#define AMFI_IND_EVAL 1     /* an evaluation is in *eval */
#define AMFI_IND_BASELINE 2 /* the automatic baseline was just established (in *eval) */
#define AMFI_IND_ALERT 4    /* alert state changes are in alerts[0 .. *n_alerts − 1] */

/* Plausibility bound: 10 000 t. Keeps every sum of squares finite. */
#define AMFI_IND_MAX_GVW_KG 1e7

typedef struct amfi_indicators amfi_indicators;

typedef struct amfi_indicator_params {
    int window;             /* W: ok passages in the rolling window, >= 2 (paper batches: 500) */
    int every;              /* K: evaluate every K ok passages once the window is full, >= 1 */
    int baseline_n;         /* ok passages collected for the automatic baseline after
                             * commissioning, >= 2 */
    double std_alert_ratio; /* raise when window STD / baseline STD >= this (>= 1) ... */
    double std_alert_p;     /* ... and the one-sided variance-ratio test p-value <= this, (0, 1] */
    double std_clear_ratio; /* hysteresis: clear when the ratio falls below this,
                             * (0, std_alert_ratio] */
    int raise_after;        /* consecutive evaluations meeting the raise rule (debounce), >= 1 */
    int clear_after;        /* consecutive evaluations meeting the clear rule, >= 1 */
    int mean_shift;         /* 1: also watch the mean (Welch t-test against the baseline),
                             * level info; 0: off */
    double mean_alert_ratio; /* raise when window mean / baseline mean >= this or <= 1 / this
                              * (>= 1) ... */
    double mean_alert_p;     /* ... and the two-sided Welch p-value <= this, (0, 1] */
    double mean_clear_ratio; /* clear when the mean ratio is back inside
                              * (1 / this, this), [1, mean_alert_ratio] */
} amfi_indicator_params;

/* The defaults (W 500, K 100, n_b 10000, R 1.08, ...), justified in
 * docs/indicators.md. */
void amfi_indicator_params_default(amfi_indicator_params *p);

/* The one validation of the parameters (amfi_indicators_create and the
 * site-file loader both use it): 0 when *p is valid, else AMFI_IND_EINVAL
 * with *field (may be NULL) set to the name of the parameter blamed (a
 * static string, the key under daemon.indicators in the site file) and err
 * (may be NULL) holding a message that names it. */
int amfi_indicator_params_check(const amfi_indicator_params *p, const char **field, char *err,
                                size_t errlen);

/* The parameters as one line of text, "window=500 every=100 ... " (every
 * field, its site-file key, doubles with 17 significant digits): what amfid
 * ran with, recorded in the store's meta (daemon.indicators) for the
 * reports. 0, or AMFI_IND_EINVAL when buf is too small. */
int amfi_indicator_params_format(const amfi_indicator_params *p, char *buf, size_t len);
/* The line back: every field must be there once, as written by
 * amfi_indicator_params_format, and the whole must pass
 * amfi_indicator_params_check. 0, or AMFI_IND_EINVAL with err naming the
 * field or the text at fault. */
int amfi_indicator_params_parse(const char *s, amfi_indicator_params *p, char *err,
                                size_t errlen);

/* 1 when every field of a equals the same field of b (compared field by
 * field, not by memory: padding and field order do not matter), else 0. */
int amfi_indicator_params_equal(const amfi_indicator_params *a, const amfi_indicator_params *b);

/* Validate *p and allocate the engine (the ring of W doubles). On success
 * *out owns it (free with amfi_indicators_destroy) and 0 is returned; on
 * failure *out is NULL, AMFI_IND_EINVAL or AMFI_IND_ENOMEM is returned and
 * err (may be NULL) holds a message naming the parameter. */
int amfi_indicators_create(const amfi_indicator_params *p, amfi_indicators **out, char *err,
                           size_t errlen);

/* NULL-safe. */
void amfi_indicators_destroy(amfi_indicators *ind);

/* Set the healthy baseline explicitly (commissioning by hand, or restored
 * from the store after a restart): mean and STD of inferred GVW in kg over
 * n >= 2 vehicles (n sets the F test's degrees of freedom). Stops an
 * automatic collection in progress; the next push evaluates if the window
 * is full (then every K). Resets the debounce counters but not the alert
 * states: an alert raised against the old baseline is cleared by
 * the normal hysteresis rule, with its event. Returns 0, or AMFI_IND_EINVAL
 * (mean or std not finite or <= 0, n < 2) and changes nothing. */
int amfi_indicators_set_baseline(amfi_indicators *ind, double mean_kg, double std_kg, int n);

/* 1 when a baseline exists (automatic or explicit), else 0. */
int amfi_indicators_has_baseline(const amfi_indicators *ind);

/* Refill the window after a restart with the last ok GVWs from the store,
 * oldest first (gvw_kg[0 .. n − 1]; only the last W matter). No evaluation,
 * no alert, no baseline collection; the next push may evaluate. Invalid
 * values are skipped like push rejects them. Returns the number of values
 * taken, or AMFI_IND_EINVAL (n < 0, or gvw_kg NULL with n > 0). */
int amfi_indicators_prefill(amfi_indicators *ind, const double *gvw_kg, int n);

/* Restore the alert states after a restart (from the store's last alert
 * events), so that an alert raised before the restart is not raised again
 * (and its clear is still reported once): std_alert, mean_alert 0 or 1. */
void amfi_indicators_set_alerted(amfi_indicators *ind, int std_alert, int mean_alert);

/* The current state of the STD indicator: "baseline" | "normal" | "watch" |
 * "alert" (a static string). */
const char *amfi_indicators_state(const amfi_indicators *ind);

typedef struct amfi_indicator_eval {
    int n;                   /* vehicles in the window (W), or baseline_n on AMFI_IND_BASELINE */
    double mean_kg, std_kg;  /* window mean and sample STD (n − 1) */
    double baseline_mean_kg, baseline_std_kg;
    double std_ratio;        /* std_kg / baseline_std_kg */
    double p_value;          /* one-sided F test P(F >= std_ratio²), F(W − 1, n_b − 1) */
    double mean_ratio;       /* mean_kg / baseline_mean_kg */
    double mean_p;           /* two-sided Welch t-test of the means */
    const char *state;       /* STD indicator: "baseline" | "normal" | "watch" | "alert" */
} amfi_indicator_eval;

typedef struct amfi_alert_event {
    const char *level;       /* "warning" (std_increase) | "info" (mean_shift) */
    const char *kind;        /* "std_increase" | "mean_shift" */
    int raised;              /* 1 raised, 0 cleared */
    char message[256];       /* one line for people, with the numbers */
} amfi_alert_event;

/* Feed one ok passage's GVW (kg). Returns a bit mask of AMFI_IND_EVAL,
 * AMFI_IND_BASELINE (then *eval holds the new baseline, state "baseline")
 * and AMFI_IND_ALERT (alert state changes in alerts[0 .. *n_alerts − 1],
 * at most 2, the STD one first); 0 when the push only entered the window.
 * Returns AMFI_IND_EINVAL for a rejected GVW (not finite, <= 0, or above
 * AMFI_IND_MAX_GVW_KG) and changes nothing. eval, alerts and n_alerts may be
 * NULL (then that output is not written; *n_alerts is set to 0 first). */
int amfi_indicators_push(amfi_indicators *ind, double gvw_kg, amfi_indicator_eval *eval,
                         amfi_alert_event alerts[2], int *n_alerts);

#endif
