/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * speed_drift.h: amfid's speed-drift alert (issue 12). When amfid estimates
 * each vehicle's speed from the acceleration (solver.speed: estimate), the
 * correction c = speed weighed with / detector's speed − 1 of a well
 * calibrated detector scatters around 0; a detector going out of
 * calibration (a loop's geometry, a radar's angle) moves its median. This
 * engine keeps the corrections of the last W estimated passages and raises
 * an info alert, kind "speed_drift", when |median c| > threshold, and
 * clears it when |median c| < threshold / 2 (hysteresis: a median hovering
 * at the threshold does not raise and clear on every passage).
 *
 *   window    a ring of the last W corrections; an evaluation needs it
 *             full (W estimated passages since commissioning, counting
 *             those refilled from the store after a restart).
 *   cadence   every push with a full window evaluates (O(W log W): a sort
 *             of a copy; W = 200 takes microseconds).
 *   median    of the W corrections; for even W the mean of the two middle
 *             values.
 *   alerts    are state changes: one event when raised, one when cleared.
 *
 * Pure computation: no I/O, no logging; the only allocation is in
 * amfi_speed_drift_create. Built on the median level rule (level_rule.h:
 * absolute, strict_raise). One handle is used by one thread at a time
 * (amfid: the main thread, the pipeline). Parameters and defaults:
 * docs/indicators.md, amfid.yaml(5) alerts.speed_drift.
 */
#ifndef AMFI_SPEED_DRIFT_H
#define AMFI_SPEED_DRIFT_H

#include <stddef.h>

#include "indicators.h" /* AMFI_IND_* codes and bits, amfi_alert_event */

/* Bounds of the parameters. */
#define AMFI_SPEED_DRIFT_MAX_WINDOW 100000
#define AMFI_SPEED_DRIFT_MAX_THRESHOLD 0.5

typedef struct amfi_speed_drift_params {
    int enabled;      /* 1: watch the corrections (no estimated passage: nothing happens) */
    int window;       /* W: estimated passages in the window, 2 .. 100000 (default 200) */
    double threshold; /* raise when |median c| > this, (0, 0.5] (default 0.02, i.e. 2 %);
                         clear when |median c| < threshold / 2 */
} amfi_speed_drift_params;

/* enabled 1, window 200, threshold 0.02. */
void amfi_speed_drift_params_default(amfi_speed_drift_params *p);

/* 0 when *p is valid, else AMFI_IND_EINVAL with *field (may be NULL) set
 * to the name of the parameter blamed (the key under alerts.speed_drift)
 * and err (may be NULL) holding a message naming it. */
int amfi_speed_drift_params_check(const amfi_speed_drift_params *p, const char **field,
                                  char *err, size_t errlen);

/* 1 when every field of a equals the same field of b, else 0. */
int amfi_speed_drift_params_equal(const amfi_speed_drift_params *a,
                                  const amfi_speed_drift_params *b);

typedef struct amfi_speed_drift amfi_speed_drift;

/* Validate *p and allocate the ring (2 · W doubles). 0 and *out, or
 * AMFI_IND_EINVAL / AMFI_IND_ENOMEM with *out NULL and err naming the
 * parameter. */
int amfi_speed_drift_create(const amfi_speed_drift_params *p, amfi_speed_drift **out, char *err,
                            size_t errlen);

/* NULL-safe. */
void amfi_speed_drift_destroy(amfi_speed_drift *sd);

/* The correction of one passage: speed_mps / speed_given_mps − 1, or NaN
 * when either speed is not finite or not > 0. */
double amfi_speed_correction(double speed_mps, double speed_given_mps);

/* Refill the window after a restart with the newest corrections from the
 * store, oldest first (c[0 .. n − 1]; only the last W matter). No
 * evaluation, no alert. Values that push would refuse are skipped. Returns
 * the number taken, or AMFI_IND_EINVAL (n < 0, or c NULL with n > 0). */
int amfi_speed_drift_prefill(amfi_speed_drift *sd, const double *c, int n);

/* Restore the alert state after a restart (the store's last speed_drift
 * event): 1 raised, 0 not. */
void amfi_speed_drift_set_alerted(amfi_speed_drift *sd, int raised);

/* 1 while the alert is raised. */
int amfi_speed_drift_alerted(const amfi_speed_drift *sd);

typedef struct amfi_speed_drift_eval {
    int n;         /* corrections in the window (W once full) */
    double median; /* median correction, a fraction (−0.04: 4 % slower than the detector) */
} amfi_speed_drift_eval;

/* Feed the correction c of one estimated passage (a fraction, finite, in
 * (−1, 1)). Returns a bit mask: AMFI_IND_EVAL when the window is full (then
 * *eval holds n and the median), AMFI_IND_ALERT when the alert was raised or
 * cleared (then *alert is filled: level "info", kind "speed_drift");
 * 0 when the correction only entered the window (or enabled is 0: then
 * nothing happens); AMFI_IND_EINVAL for a refused c or a NULL handle
 * (nothing changes). eval and alert may be NULL. */
int amfi_speed_drift_push(amfi_speed_drift *sd, double c, amfi_speed_drift_eval *eval,
                          amfi_alert_event *alert);

#endif /* AMFI_SPEED_DRIFT_H */
