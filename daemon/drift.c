/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * drift.c: amfid's speed-drift alert (issue 12): each stored passage whose
 * speed was estimated (solver.speed: estimate) feeds its correction c =
 * speed weighed with / detector's speed − 1 to the engine (the detector's
 * speed as detector.speed_scale corrects it: the drift since commissioning)
 * (indicators/speed_drift.h), whose raise and clear events go out like the
 * other alerts (stored, published on the alert channel, counted in the
 * metrics, alerts.command, the journal: the context's emit_alert). At start
 * the window is refilled from the store's newest estimated passages and an
 * alert open before a restart stays open (not raised twice).
 *
 * A module (ctx.h). Thread: the main thread only. Owns the engine (built
 * at start from alerts.speed_drift; a reload reports a change, which
 * applies at the next start, like the indicator settings).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx.h"
#include "speed_drift.h"

static struct {
    amfi_speed_drift *drift;
    amfi_speed_drift_params params; /* in force */
} D;

static int drift_start(amfid_ctx *c, char *err, size_t errlen)
{
    memset(&D, 0, sizeof D);
    D.params = c->cfg->daemon.speed_drift;
    return amfi_speed_drift_create(&D.params, &D.drift, err, errlen);
}

static int drift_restore(amfid_ctx *c)
{
    char err[512];
    int open = 0;
    const double scale = c->cfg->detector.speed_scale;
    if (!D.drift || !D.params.enabled)
        return 0;
    amfi_speed_pair *p = NULL;
    size_t n = 0;
    if (amfi_store_recent_speed_pairs(c->store, D.params.window, &p, &n, err,
                                      sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return 0;
    }
    double *x = malloc((n ? n : 1) * sizeof *x);
    if (!x) {
        free(p);
        LOG_WARN("speed drift: out of memory for %zu corrections; the window starts empty", n);
        return 0;
    }
    for (size_t k = 0; k < n; k++)
        x[k] = amfi_speed_correction(p[k].speed_mps, p[k].speed_given_mps / scale);
    int taken = amfi_speed_drift_prefill(D.drift, x, (int)n);
    free(x);
    free(p);
    if (amfi_store_alert_open(c->store, "speed_drift", &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        open = 0;
    }
    amfi_speed_drift_set_alerted(D.drift, open);
    metrics_alert("speed_drift", open);
    if (taken > 0 || open)
        LOG_INFO("speed drift: %d estimated passages from the store%s", taken,
                 open ? "; the speed_drift alert is open" : "");
    return 0;
}

/* A stored passage whose speed was estimated: its two speeds, m/s. */
static void drift_feed(amfid_ctx *c, const amfid_passage *ps)
{
    if (!ps->j->speed_estimated || !D.drift || !D.params.enabled)
        return;
    /* against the detector's speed as commissioning corrects it: the drift
     * since commissioning (a known speed_scale is no drift) */
    const double speed_mps = ps->r->speed_mps, speed_given_mps = ps->r->speed_given_mps;
    double x = amfi_speed_correction(speed_mps, speed_given_mps / c->cfg->detector.speed_scale);
    amfi_alert_event al;
    amfi_speed_drift_eval ev;
    int bits = amfi_speed_drift_push(D.drift, x, &ev, &al);
    if (bits < 0) {
        ctx_error(c, "speed drift: correction of %.3f m/s against %.3f m/s refused", speed_mps,
                  speed_given_mps);
        return;
    }
    if (bits & AMFI_IND_ALERT)
        c->emit_alert(c, ps->j->w.v.utime, &al, 0);
}


static void drift_stop(amfid_ctx *c)
{
    (void)c;
    amfi_speed_drift_destroy(D.drift);
    memset(&D, 0, sizeof D);
}

const amfid_module drift_module = {
    .name = "drift",
    .section = "alerts.speed_drift",
    .start = drift_start,
    .restore = drift_restore,
    .on_passage = drift_feed,
    .stop = drift_stop,
};
