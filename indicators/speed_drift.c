/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * speed_drift.c: the speed-drift alert engine (speed_drift.h): a ring of
 * the last W speed corrections, their median, and the raise / clear rule
 * with hysteresis. Pure computation; the caller's thread.
 */
#include "speed_drift.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct amfi_speed_drift {
    amfi_speed_drift_params p;
    double *ring;    /* W corrections, the oldest at `head` once full */
    double *scratch; /* W: the sorted copy for the median */
    int head, n;     /* next slot; corrections held (<= W) */
    int alerted;     /* 1 while raised */
};

void amfi_speed_drift_params_default(amfi_speed_drift_params *p)
{
    p->enabled = 1;
    p->window = 200;
    p->threshold = 0.02;
}

#define BLAME(name, ...)                                                                      \
    do {                                                                                      \
        if (field)                                                                            \
            *field = name;                                                                    \
        if (err && errlen)                                                                    \
            snprintf(err, errlen, __VA_ARGS__);                                               \
        return AMFI_IND_EINVAL;                                                               \
    } while (0)

int amfi_speed_drift_params_check(const amfi_speed_drift_params *p, const char **field,
                                  char *err, size_t errlen)
{
    if (field)
        *field = NULL;
    if (!p)
        BLAME(NULL, "speed drift: no parameters");
    if (p->enabled != 0 && p->enabled != 1)
        BLAME("enabled", "enabled must be on or off (1 or 0), got %d", p->enabled);
    if (p->window < 2 || p->window > AMFI_SPEED_DRIFT_MAX_WINDOW)
        BLAME("window", "window must be 2 .. %d estimated passages, got %d",
              AMFI_SPEED_DRIFT_MAX_WINDOW, p->window);
    if (!(p->threshold > 0 && p->threshold <= AMFI_SPEED_DRIFT_MAX_THRESHOLD))
        BLAME("threshold", "threshold must be in (0, %g], got %g", AMFI_SPEED_DRIFT_MAX_THRESHOLD,
              p->threshold);
    return AMFI_IND_OK;
}

int amfi_speed_drift_params_equal(const amfi_speed_drift_params *a,
                                  const amfi_speed_drift_params *b)
{
    return a->enabled == b->enabled && a->window == b->window && a->threshold == b->threshold;
}

int amfi_speed_drift_create(const amfi_speed_drift_params *p, amfi_speed_drift **out, char *err,
                            size_t errlen)
{
    const char *field = NULL;
    char why[192];
    if (out)
        *out = NULL;
    if (!out) {
        if (err && errlen)
            snprintf(err, errlen, "speed drift: no output");
        return AMFI_IND_EINVAL;
    }
    if (amfi_speed_drift_params_check(p, &field, why, sizeof why) != 0) {
        if (err && errlen)
            snprintf(err, errlen, "speed drift: %s", why);
        return AMFI_IND_EINVAL;
    }
    amfi_speed_drift *sd = calloc(1, sizeof *sd);
    if (sd) {
        sd->ring = malloc(sizeof(double) * (size_t)p->window);
        sd->scratch = malloc(sizeof(double) * (size_t)p->window);
    }
    if (!sd || !sd->ring || !sd->scratch) {
        amfi_speed_drift_destroy(sd);
        if (err && errlen)
            snprintf(err, errlen, "speed drift: out of memory for a window of %d", p->window);
        return AMFI_IND_ENOMEM;
    }
    sd->p = *p;
    *out = sd;
    return AMFI_IND_OK;
}

void amfi_speed_drift_destroy(amfi_speed_drift *sd)
{
    if (!sd)
        return;
    free(sd->ring);
    free(sd->scratch);
    free(sd);
}

double amfi_speed_correction(double speed_mps, double speed_given_mps)
{
    if (!(isfinite(speed_mps) && isfinite(speed_given_mps) && speed_mps > 0
          && speed_given_mps > 0))
        return NAN;
    return speed_mps / speed_given_mps - 1.0;
}

static int valid(double c) { return isfinite(c) && c > -1.0 && c < 1.0; }

static void enter(amfi_speed_drift *sd, double c)
{
    sd->ring[sd->head] = c;
    sd->head = (sd->head + 1) % sd->p.window;
    if (sd->n < sd->p.window)
        sd->n++;
}

int amfi_speed_drift_prefill(amfi_speed_drift *sd, const double *c, int n)
{
    if (!sd || n < 0 || (n > 0 && !c))
        return AMFI_IND_EINVAL;
    int taken = 0;
    for (int k = 0; k < n; k++)
        if (valid(c[k])) {
            enter(sd, c[k]);
            taken++;
        }
    return taken;
}

void amfi_speed_drift_set_alerted(amfi_speed_drift *sd, int raised)
{
    if (sd)
        sd->alerted = raised != 0;
}

int amfi_speed_drift_alerted(const amfi_speed_drift *sd) { return sd ? sd->alerted : 0; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(amfi_speed_drift *sd)
{
    int n = sd->n;
    memcpy(sd->scratch, sd->ring, sizeof(double) * (size_t)n);
    qsort(sd->scratch, (size_t)n, sizeof(double), cmp_double);
    return n % 2 ? sd->scratch[n / 2] : 0.5 * (sd->scratch[n / 2 - 1] + sd->scratch[n / 2]);
}

int amfi_speed_drift_push(amfi_speed_drift *sd, double c, amfi_speed_drift_eval *eval,
                          amfi_alert_event *alert)
{
    if (!sd || !valid(c))
        return AMFI_IND_EINVAL;
    if (!sd->p.enabled)
        return 0;
    enter(sd, c);
    if (sd->n < sd->p.window)
        return 0;
    double m = median(sd);
    if (eval) {
        eval->n = sd->n;
        eval->median = m;
    }
    int bits = AMFI_IND_EVAL;
    const double th = sd->p.threshold;
    int raise = !sd->alerted && fabs(m) > th;
    int clear = sd->alerted && fabs(m) < th / 2;
    if (!raise && !clear)
        return bits;
    sd->alerted = raise;
    if (alert) {
        memset(alert, 0, sizeof *alert);
        alert->level = "info";
        alert->kind = "speed_drift";
        alert->raised = raise;
        /* the detector's reading relative to the estimate: given = used / (1 + c) */
        if (raise)
            snprintf(alert->message, sizeof alert->message,
                     "median speed correction %+.2f %% over the last %d estimated passages "
                     "(beyond +/-%.2f %%): the speed detector reads %.1f %% %s; check its "
                     "calibration",
                     100 * m, sd->n, 100 * th, 100 * fabs(1 / (1 + m) - 1),
                     m < 0 ? "high" : "low");
        else
            snprintf(alert->message, sizeof alert->message,
                     "median speed correction %+.2f %% over the last %d estimated passages, "
                     "back within +/-%.2f %%",
                     100 * m, sd->n, 100 * th / 2);
    }
    return bits | AMFI_IND_ALERT;
}
