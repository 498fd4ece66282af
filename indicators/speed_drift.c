/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * speed_drift.c: the speed-drift alert engine (speed_drift.h): the median
 * level rule (level_rule.c) on |median c| over the last W speed
 * corrections, raised above the threshold, cleared below half of it, with
 * the speed drift's own parameters, refusals and messages. Pure
 * computation; the caller's thread.
 */
#include "speed_drift.h"

#include "ind_internal.h"
#include "level_rule.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct amfi_speed_drift {
    amfi_speed_drift_params p;
    amfi_level_rule *rule; /* |median c| > threshold raises, < threshold / 2 clears */
};

void amfi_speed_drift_params_default(amfi_speed_drift_params *p)
{
    p->enabled = 1;
    p->window = 200;
    p->threshold = 0.02;
}

int amfi_speed_drift_params_check(const amfi_speed_drift_params *p, const char **field,
                                  char *err, size_t errlen)
{
    if (field)
        *field = NULL;
    if (!p)
        IND_BLAME(NULL, "speed drift: no parameters");
    if (p->enabled != 0 && p->enabled != 1)
        IND_BLAME("enabled", "enabled must be on or off (1 or 0), got %d", p->enabled);
    if (p->window < 2 || p->window > AMFI_SPEED_DRIFT_MAX_WINDOW)
        IND_BLAME("window", "window must be 2 .. %d estimated passages, got %d",
              AMFI_SPEED_DRIFT_MAX_WINDOW, p->window);
    if (!(p->threshold > 0 && p->threshold <= AMFI_SPEED_DRIFT_MAX_THRESHOLD))
        IND_BLAME("threshold", "threshold must be in (0, %g], got %g", AMFI_SPEED_DRIFT_MAX_THRESHOLD,
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
    const amfi_level_params lp = {.enabled = p->enabled,
                                  .window = p->window,
                                  .raise = p->threshold,
                                  .clear = p->threshold / 2,
                                  .raise_after = 1,
                                  .clear_after = 1,
                                  .absolute = 1,
                                  .strict_raise = 1};
    amfi_speed_drift *sd = calloc(1, sizeof *sd);
    int rc = sd ? amfi_level_rule_create(&lp, "speed_drift", "info", "speed correction",
                                         &sd->rule, why, sizeof why)
                : AMFI_IND_ENOMEM;
    if (rc != 0) {
        amfi_speed_drift_destroy(sd);
        if (err && errlen) {
            if (rc == AMFI_IND_ENOMEM)
                snprintf(err, errlen, "speed drift: out of memory for a window of %d",
                         p->window);
            else
                snprintf(err, errlen, "speed drift: %s", why);
        }
        return rc;
    }
    sd->p = *p;
    *out = sd;
    return AMFI_IND_OK;
}

void amfi_speed_drift_destroy(amfi_speed_drift *sd)
{
    if (!sd)
        return;
    amfi_level_rule_destroy(sd->rule);
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

int amfi_speed_drift_prefill(amfi_speed_drift *sd, const double *c, int n)
{
    if (!sd || n < 0 || (n > 0 && !c))
        return AMFI_IND_EINVAL;
    int taken = 0;
    for (int k = 0; k < n; k++)
        if (valid(c[k]))
            taken += amfi_level_rule_prefill(sd->rule, &c[k], 1);
    return taken;
}

void amfi_speed_drift_set_alerted(amfi_speed_drift *sd, int raised)
{
    if (sd)
        amfi_level_rule_set_alerted(sd->rule, raised);
}

int amfi_speed_drift_alerted(const amfi_speed_drift *sd)
{
    return sd ? amfi_level_rule_alerted(sd->rule) : 0;
}

int amfi_speed_drift_push(amfi_speed_drift *sd, double c, amfi_speed_drift_eval *eval,
                          amfi_alert_event *alert)
{
    if (!sd || !valid(c))
        return AMFI_IND_EINVAL;
    amfi_level_eval ev;
    const int bits = amfi_level_rule_push(sd->rule, c, &ev, alert);
    if (!(bits & AMFI_IND_EVAL))
        return bits;
    if (eval) {
        eval->n = ev.n;
        eval->median = ev.median;
    }
    if (!(bits & AMFI_IND_ALERT) || !alert)
        return bits;
    /* the rule's event (level "info", kind "speed_drift") in the speed drift's
     * words; the detector's reading relative to the estimate: given = used / (1 + c) */
    const double m = ev.median, th = sd->p.threshold;
    if (alert->raised)
        snprintf(alert->message, sizeof alert->message,
                 "median speed correction %+.2f %% over the last %d estimated passages "
                 "(beyond +/-%.2f %%): the speed detector reads %.1f %% %s; check its "
                 "calibration",
                 100 * m, ev.n, 100 * th, 100 * fabs(1 / (1 + m) - 1), m < 0 ? "high" : "low");
    else
        snprintf(alert->message, sizeof alert->message,
                 "median speed correction %+.2f %% over the last %d estimated passages, "
                 "back within +/-%.2f %%",
                 100 * m, ev.n, 100 * th / 2);
    return bits;
}
