/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * known_truck.c: the known-truck indicator (known_truck.h): temperature
 * compensation of each run's ratio, the baseline mean and its CUSUM. Pure
 * computation; the handle is owned by one thread at a time.
 */
#include "known_truck.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cusum.h"
#include "ind_internal.h"

#define MAX_BASELINE 1000

struct amfi_known_truck {
    amfi_known_truck_params p;
    amfi_scale_params temp;
    double warm, frost;
    int runs;
    double base[MAX_BASELINE]; /* ln ratios of the baseline runs */
    int nb, have_baseline;
    double mean_b, sigma;
    amfi_cusum cusum;
};

void amfi_known_truck_params_default(amfi_known_truck_params *p)
{
    memset(p, 0, sizeof *p);
    p->baseline_runs = 4;
    p->run_sd = 0.02;
    p->design_shift = 0.05;
    p->false_alarms_per_year = 0.2;
    p->runs_per_year = 52.0;
    p->clear_after = 2;
}

static int bad(const char *name, const char **field, char *err, size_t errlen, const char *why)
{
    return ind_bad("known-truck indicator", name, field, err, errlen, why);
}

int amfi_known_truck_params_check(const amfi_known_truck_params *p, const char **field,
                                  char *err, size_t errlen)
{
    if (field)
        *field = NULL;
    if (p->baseline_runs < 2 || p->baseline_runs > MAX_BASELINE)
        return bad("baseline_runs", field, err, errlen, "must be in [2, 1000]");
    if (!ind_in(p->run_sd, 1e-4, 1))
        return bad("run_sd", field, err, errlen, "must be in [0.0001, 1]");
    if (!ind_in(p->design_shift, 1e-4, 0.5) || p->design_shift >= 0.5)
        return bad("design_shift", field, err, errlen, "must be in [0.0001, 0.5)");
    if (!ind_in(p->false_alarms_per_year, 1e-4, 1000))
        return bad("false_alarms_per_year", field, err, errlen, "must be in [0.0001, 1000]");
    if (!ind_in(p->runs_per_year, 1, 1e5))
        return bad("runs_per_year", field, err, errlen, "must be in [1, 100000]");
    if (p->clear_after < 1 || p->clear_after > 1000000)
        return bad("clear_after", field, err, errlen, "must be in [1, 1000000]");
    return AMFI_IND_OK;
}

int amfi_known_truck_create(const amfi_known_truck_params *p, const amfi_scale_params *temp,
                            amfi_known_truck **out, char *err, size_t errlen)
{
    if (!out || !p || !temp) {
        if (err && errlen)
            snprintf(err, errlen, "known-truck indicator: %s is NULL",
                     !out ? "out" : !p ? "params" : "temperature params");
        if (out)
            *out = NULL;
        return AMFI_IND_EINVAL;
    }
    *out = NULL;
    int rc = amfi_known_truck_params_check(p, NULL, err, errlen);
    if (rc == 0)
        rc = amfi_scale_params_check(temp, NULL, err, errlen);
    if (rc)
        return rc;
    amfi_known_truck *k = calloc(1, sizeof *k);
    if (!k) {
        if (err && errlen)
            snprintf(err, errlen, "known-truck indicator: out of memory");
        return AMFI_IND_ENOMEM;
    }
    k->p = *p;
    k->temp = *temp;
    k->warm = temp->warm_slope;
    k->frost = temp->frost_slope;
    *out = k;
    return AMFI_IND_OK;
}

void amfi_known_truck_destroy(amfi_known_truck *k)
{
    free(k);
}

int amfi_known_truck_set_slopes(amfi_known_truck *k, double warm_slope, double frost_slope)
{
    if (!ind_in(warm_slope, -0.1, 0.1) || !ind_in(frost_slope, -0.1, 0.1))
        return AMFI_IND_EINVAL;
    k->warm = warm_slope;
    k->frost = frost_slope;
    return AMFI_IND_OK;
}

void amfi_known_truck_set_alerted(amfi_known_truck *k, int alerted)
{
    amfi_cusum_set_alerted(&k->cusum, alerted);
}

const char *amfi_known_truck_state(const amfi_known_truck *k)
{
    if (!k->have_baseline)
        return "baseline";
    if (k->cusum.alerted)
        return "alert";
    return k->cusum.s > 0 ? "watch" : "normal";
}

static int fit_baseline(amfi_known_truck *k)
{
    const int n = k->nb;
    double s1 = 0, s2 = 0;
    for (int i = 0; i < n; i++)
        s1 += k->base[i];
    k->mean_b = s1 / n;
    for (int i = 0; i < n; i++)
        s2 += (k->base[i] - k->mean_b) * (k->base[i] - k->mean_b);
    k->sigma = fmax(k->p.run_sd, sqrt(s2 / (n - 1)));
    const double kr = log(1.0 / (1.0 - k->p.design_shift)) / (2.0 * k->sigma);
    const double arl0 = k->p.runs_per_year / k->p.false_alarms_per_year;
    const double margin = fmin(1.0 / sqrt((double)n), 0.9 * kr);
    const double h = amfi_cusum_threshold(kr, arl0 < 1 ? 1 : arl0, margin);
    if (!(h >= 0))
        return AMFI_IND_EINVAL;
    const int alerted = k->cusum.alerted; /* restored before the baseline, maybe */
    amfi_cusum_init(&k->cusum, kr, h);
    amfi_cusum_set_alerted(&k->cusum, alerted);
    k->have_baseline = 1;
    return AMFI_IND_OK;
}

int amfi_known_truck_push(amfi_known_truck *k, double inferred_kg, double reference_kg,
                          double deck_c, amfi_known_truck_eval *eval, amfi_alert_event *alert)
{
    if (!ind_in(inferred_kg, 1e-9, AMFI_IND_MAX_GVW_KG) || !(inferred_kg > 0) ||
        !ind_in(reference_kg, 1e-9, AMFI_IND_MAX_GVW_KG) || !(reference_kg > 0) ||
        !ind_in(deck_c, AMFI_SCALE_T_MIN, AMFI_SCALE_T_MAX))
        return AMFI_IND_EINVAL;
    const double ratio = inferred_kg / reference_kg;
    const double rc_ = ratio * amfi_scale_temp_factor(&k->temp, k->warm, k->frost, deck_c);
    const double y = log(rc_);
    int rc = AMFI_IND_EVAL;
    k->runs++;
    if (!k->have_baseline) {
        k->base[k->nb++] = y;
        if (k->nb >= k->p.baseline_runs) {
            if (fit_baseline(k))
                k->nb = 0; /* cannot happen with checked parameters; collect again */
            else
                rc |= AMFI_IND_BASELINE;
        }
        if (eval) {
            memset(eval, 0, sizeof *eval);
            eval->run = k->runs;
            eval->ratio = ratio;
            eval->ratio_comp = rc_;
            eval->baseline_ratio = k->have_baseline ? exp(k->mean_b) : 0.0;
            eval->h = k->have_baseline ? k->cusum.h : 0.0;
            eval->sigma = k->have_baseline ? k->sigma : 0.0;
            eval->state = "baseline";
        }
        return rc;
    }
    const double z = (y - k->mean_b) / k->sigma;
    const int step = amfi_cusum_alert_step(&k->cusum, z, k->p.clear_after);
    if (eval) {
        eval->run = k->runs;
        eval->ratio = ratio;
        eval->ratio_comp = rc_;
        eval->baseline_ratio = exp(k->mean_b);
        eval->z = z;
        eval->cusum = k->cusum.s;
        eval->h = k->cusum.h;
        eval->sigma = k->sigma;
        eval->state = amfi_known_truck_state(k);
    }
    if (step) {
        rc |= AMFI_IND_ALERT;
        if (alert) {
            alert->level = "warning";
            alert->kind = "known_truck";
            alert->raised = step > 0;
            if (step > 0)
                snprintf(alert->message, sizeof alert->message,
                         "known truck: inferred/reference %.4f (compensated %.4f, baseline "
                         "%.4f, deck %.1f °C): CUSUM %.2f >= %.2f",
                         ratio, rc_, exp(k->mean_b), deck_c, k->cusum.s, k->cusum.h);
            else
                snprintf(alert->message, sizeof alert->message,
                         "known truck: inferred/reference %.4f (compensated %.4f): CUSUM at 0 "
                         "for %d runs",
                         ratio, rc_, k->p.clear_after);
        }
    }
    return rc;
}
