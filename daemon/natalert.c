/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * natalert.c: amfid's natfreq alert (docs/indicators.md section 10): the
 * relative drop x = 1 − f1_comp / f1_ref of each passage's
 * temperature-compensated first natural frequency (freevib.c: f1 at the
 * calibration temperature, passages.f1_comp_hz) against the baseline's
 * (f1_ref: the compensation's fit over the first
 * daemon.natural_frequency.baseline_n estimates), watched by a debounced
 * median level rule with hysteresis (level_rule.h): raised (warning,
 * natfreq) when the median drop of the last alerts.natfreq.window
 * passages is at or above raise for raise_after passages in a row,
 * cleared below clear for clear_after. A uniform stiffness loss d lowers
 * f1 by 1 − sqrt(1 − d): the default raise, 1.5 %, is about 3 % of
 * stiffness.
 *
 * A site without a deck temperature (no environment_t: no compensation,
 * f1_comp_hz NULL) is watched on the raw f1 against the mean of its first
 * daemon.natural_frequency.baseline_n estimates, as the STD rule takes raw
 * weights there: a passage without a deck temperature is fed raw while the
 * compensation has no fit; once it has one, only compensated frequencies
 * are fed (a passage without a temperature is then skipped).
 *
 * A module (ctx.h): start builds the rule; restore refills it from the
 * store's newest compensated frequencies (after freevib's restore, which
 * refits the baseline) and the open alert; on_passage feeds it.
 *
 * Thread: the main thread only.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx.h"
#include "level_rule.h"

static struct {
    amfi_level_rule *rule; /* NULL: off */
    int64_t fed, fed_raw;
    double last_median;
    double raw_sum;        /* the raw baseline: the first baseline_n raw f1 */
    int raw_n;
} N;

/* The raw baseline's mean, or 0 while it is collected. */
static double raw_ref(const amfid_ctx *c)
{
    return N.raw_n >= c->cfg->daemon.natfreq_baseline_n ? N.raw_sum / N.raw_n : 0.0;
}

static int natalert_start(amfid_ctx *c, char *err, size_t errlen)
{
    memset(&N, 0, sizeof N);
    N.last_median = NAN;
    if (!c->cfg->daemon.natfreq_alert.enabled || !(c->cfg->daemon.natfreq_free_s > 0))
        return 0;
    return amfi_level_rule_create(&c->cfg->daemon.natfreq_alert, "natfreq", "warning",
                                  "drop of the natural frequency", &N.rule, err,
                                  errlen) != 0;
}

static int natalert_restore(amfid_ctx *c)
{
    char err[256];
    int open = 0;
    double ref;
    if (!N.rule)
        return 0;
    if (freevib_reference(&ref)) {
        double *f = NULL;
        size_t n = 0;
        if (amfi_store_recent_f1_comp(c->store, c->cfg->daemon.natfreq_alert.window, &f, &n,
                                      err, sizeof err) != 0) {
            LOG_WARN("store: %s", err);
            n = 0;
        }
        for (size_t k = 0; k < n; k++)
            f[k] = 1.0 - f[k] / ref;
        const int taken = amfi_level_rule_prefill(N.rule, f, (int)n);
        free(f);
        if (taken > 0)
            LOG_INFO("natfreq alert: %d compensated frequencies from the store", taken);
    }
    /* the raw baseline: the first baseline_n estimates stored */
    amfi_f1_rec *a = NULL;
    size_t na = 0;
    if (amfi_store_f1_series(c->store, 0, AMFI_STORE_MAX_UTIME, c->cfg->daemon.natfreq_baseline_n,
                             &a, &na, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        na = 0;
    }
    for (size_t k = 0; k < na; k++)
        N.raw_sum += a[k].f1_hz, N.raw_n++;
    free(a);
    if (amfi_store_alert_open(c->store, "natfreq", &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        open = 0;
    }
    amfi_level_rule_set_alerted(N.rule, open);
    metrics_alert("natfreq", open);
    if (open)
        LOG_INFO("natfreq alert: open in the store");
    return 0;
}

static void natalert_feed(amfid_ctx *c, const amfid_passage *p)
{
    double ref;
    double f = p->r->f1_comp_hz;
    const double raw = p->r->f1_hz;
    if (!N.rule || !(raw > 0) || !isfinite(raw))
        return;
    const int comp = freevib_reference(&ref);
    if (N.raw_n < c->cfg->daemon.natfreq_baseline_n) {
        N.raw_sum += raw;
        N.raw_n++;
        return;
    }
    if (comp) {
        if (!(f > 0) || !isfinite(f))
            return; /* no deck temperature: not compensated */
    } else {
        if (p->r->has_deck_c)
            return; /* a temperature: the compensation's fit is being collected */
        f = raw;
        ref = raw_ref(c);
        N.fed_raw++;
    }
    N.fed++;
    amfi_level_eval ev;
    amfi_alert_event a;
    const double x = 1.0 - f / ref;
    const int bits = amfi_level_rule_push(N.rule, x, &ev, &a);
    if (bits > 0 && (bits & AMFI_IND_EVAL))
        N.last_median = ev.median;
    if (bits > 0 && (bits & AMFI_IND_ALERT)) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s (f1 %s %.4f Hz, baseline %.4f Hz)%s", a.message,
                 comp ? "at the calibration temperature" : "uncompensated (no deck temperature)",
                 ref * (1.0 - ev.median), ref,
                 a.raised ? ": the bridge lost stiffness, or its supports or mass changed" : "");
        size_t len = strlen(msg);
        if (len >= sizeof a.message)
            len = sizeof a.message - 1;
        memcpy(a.message, msg, len);
        a.message[len] = '\0';
        c->emit_alert(c, p->j->w.v.utime, &a, 0);
    }
}

static void natalert_final(amfid_ctx *c)
{
    (void)c;
    if (N.rule && N.fed > 0)
        LOG_INFO("natfreq alert: %lld frequencies watched (%lld raw: no deck temperature), "
                 "median drop %.4f",
                 (long long)N.fed, (long long)N.fed_raw, N.last_median);
}

static void natalert_stop(amfid_ctx *c)
{
    (void)c;
    amfi_level_rule_destroy(N.rule);
    memset(&N, 0, sizeof N);
}

const amfid_module natalert_module = {
    .name = "natalert",
    .section = "alerts.natfreq",
    .start = natalert_start,
    .restore = natalert_restore,
    .on_passage = natalert_feed,
    .final = natalert_final,
    .stop = natalert_stop,
};
