/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * modelfit.c: amfid's model fit and its alert, model_mismatch
 * (docs/indicators.md section 10). A vehicle weighed alone whose free
 * vibration after the last axle was recorded (the tracker's
 * daemon.natural_frequency.free_s, not cut by the next vehicle for at
 * least alerts.model_fit.free_s) is solved a second time by its solver
 * thread over the window extended alerts.model_fit.free_s past the last
 * exit (pool.c, fit_job), and the model's RMS residual over that free
 * vibration relative to the signal's RMS there is stored with the passage
 * (passages.fit_ratio). The forced part fits any stiffness (the forces
 * absorb it: the residual there stays about 1 %); the free vibration is the
 * state at exit left to itself, which only the right bridge reproduces: a
 * wrong or outdated commissioning, a seized bearing or damage shows as a
 * residual there. The median of the last alerts.model_fit.window figures
 * is watched by a debounced level rule with hysteresis (level_rule.h):
 * raised (warning, model_mismatch) at or above raise for raise_after
 * passages in a row, cleared below clear for clear_after.
 *
 * A module (ctx.h): start builds the rule; restore records its parameters
 * in the store (meta alerts.model_fit, for amfi-report and amfi-web) and
 * refills it from the store's newest fit_ratio values and the open alert; row fills
 * passages.fit_ratio; on_passage feeds the rule; final logs the counts.
 * modelfit_take (intake.c, at release) copies the window and its free
 * vibration for the solver thread.
 *
 * Thread: the main thread only (the solver thread reads only its job).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx.h"
#include "level_rule.h"

static struct {
    amfi_level_rule *rule; /* NULL: off */
    int64_t fitted, not_alone, short_free, refused;
    double last_median;
} M;

static int on(const amfid_ctx *c)
{
    return c->cfg->daemon.model_fit.enabled && c->cfg->daemon.natfreq_free_s > 0;
}

void modelfit_take(amfid_ctx *c, job *j, amfi_ring *const *rings)
{
    if (!on(c) || strcmp(j->w.status, "ok") != 0)
        return;
    if (j->w.n_vehicles != 1) {
        M.not_alone++;
        return;
    }
    const double rate = j->scan_rate_hz;
    /* room past the fitted free vibration for a slower estimated speed */
    const int need = (int)ceil((c->cfg->daemon.model_fit_free_s + 0.1) * rate);
    int n = -1;
    for (int s = 0; s < j->n_sensors; s++) {
        if (!rings[s] || j->w.free_n < need) {
            n = -1;
            break;
        }
        const int64_t end = j->w.free_k0[s] + j->w.free_n; /* one past the last */
        const int64_t ns = end - j->w.k0[s];
        if (ns < j->w.n || ns > (int64_t)j->w.n + (int64_t)ceil(60.0 * rate)) {
            n = -1;
            break;
        }
        if (n < 0 || ns < n)
            n = (int)ns;
    }
    if (n < 0) {
        M.short_free++;
        return;
    }
    double *a = malloc(sizeof(double) * (size_t)n * (size_t)j->n_sensors);
    if (!a) {
        ctx_error(c, "model fit: out of memory for %d samples", n);
        return;
    }
    for (int s = 0; s < j->n_sensors; s++)
        if (amfi_ring_get(rings[s], j->w.k0[s], n, a + (size_t)s * n) != 0) {
            free(a);
            M.short_free++;
            return;
        }
    j->accel_fit = a;
    j->fit_n = n;
    j->fit_scale = freevib_time_scale(c, j->w.v.utime);
}

static int modelfit_start(amfid_ctx *c, char *err, size_t errlen)
{
    memset(&M, 0, sizeof M);
    M.last_median = NAN;
    if (!on(c))
        return 0;
    return amfi_level_rule_create(&c->cfg->daemon.model_fit, "model_mismatch", "warning",
                                  "model residual over the free vibration / signal", &M.rule,
                                  err, errlen) != 0;
}

static int modelfit_restore(amfid_ctx *c)
{
    char err[256];
    int open = 0;
    /* what this run's rule uses, for the reports (meta alerts.model_fit,
     * enabled=0 when the fit is off; a reload does not change it: it
     * applies at the next start) */
    amfi_level_params rec = c->cfg->daemon.model_fit;
    char params[256];
    rec.enabled = on(c);
    snprintf(err, sizeof err, "the text is longer than %zu bytes", sizeof params);
    if (amfi_level_params_format(&rec, params, sizeof params) != 0
        || amfi_store_meta_set(c->store, "alerts.model_fit", params, err, sizeof err) != 0)
        LOG_WARN("store: the model fit's parameters not recorded: %s", err);
    if (!M.rule)
        return 0;
    double *x = NULL;
    size_t n = 0;
    if (amfi_store_recent_fit_ratios(c->store, c->cfg->daemon.model_fit.window, &x, &n, err,
                                     sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        n = 0;
    }
    const int taken = amfi_level_rule_prefill(M.rule, x, (int)n);
    free(x);
    if (amfi_store_alert_open(c->store, "model_mismatch", &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        open = 0;
    }
    amfi_level_rule_set_alerted(M.rule, open);
    metrics_alert("model_mismatch", open);
    if (taken > 0 || open)
        LOG_INFO("model fit: %d passages from the store%s", taken,
                 open ? "; the model_mismatch alert is open" : "");
    return 0;
}

static void modelfit_row(amfid_ctx *c, const amfid_passage *p, amfi_passage_row *r)
{
    (void)c;
    r->fit_ratio = p->j->fit_done ? p->j->fit_ratio : NAN;
}

static void modelfit_feed(amfid_ctx *c, const amfid_passage *p)
{
    const job *j = p->j;
    if (!M.rule || !j->accel_fit || !j->solved)
        return;
    if (!j->fit_done) {
        M.refused++;
        return;
    }
    M.fitted++;
    amfi_level_eval ev;
    amfi_alert_event a;
    const int bits = amfi_level_rule_push(M.rule, j->fit_ratio, &ev, &a);
    if (bits & AMFI_IND_EVAL)
        M.last_median = ev.median;
    if (bits > 0 && (bits & AMFI_IND_ALERT)) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s%s", a.message,
                 a.raised ? ": the site's model no longer fits the bridge (commissioning, "
                            "bearings, sensor position or damage)"
                          : "");
        size_t len = strlen(msg);
        if (len >= sizeof a.message)
            len = sizeof a.message - 1;
        memcpy(a.message, msg, len);
        a.message[len] = '\0';
        c->emit_alert(c, j->w.v.utime, &a, 0);
    }
}

static void modelfit_final(amfid_ctx *c)
{
    (void)c;
    if (M.rule)
        LOG_INFO("model fit: %lld passages fitted (median of the window %.4f), not: %lld "
                 "weighed with others, %lld without enough free vibration, %lld refused",
                 (long long)M.fitted, M.last_median, (long long)M.not_alone,
                 (long long)M.short_free, (long long)M.refused);
}

static void modelfit_stop(amfid_ctx *c)
{
    (void)c;
    amfi_level_rule_destroy(M.rule);
    memset(&M, 0, sizeof M);
}

const amfid_module modelfit_module = {
    .name = "modelfit",
    .section = "alerts.model_fit",
    .start = modelfit_start,
    .restore = modelfit_restore,
    .row = modelfit_row,
    .on_passage = modelfit_feed,
    .final = modelfit_final,
    .stop = modelfit_stop,
};
