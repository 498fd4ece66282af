/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * drift.c: amfid's speed-drift alert (issue 12): each stored passage whose
 * speed was estimated (solver.speed: estimate) feeds its correction c =
 * speed weighed with / detector's speed − 1 to the engine
 * (indicators/speed_drift.h), whose raise and clear events go out like the
 * other alerts (stored, published on the alert channel, counted in the
 * metrics, alerts.command, the journal: pipeline.c's emit_alert). At start
 * the window is refilled from the store's newest estimated passages and an
 * alert open before a restart stays open (not raised twice).
 *
 * Thread: the main thread only. Owns d->drift (created by amfid_start from
 * alerts.speed_drift; a reload reports a change, which applies at the next
 * start, like the indicator settings).
 */
#include <stdio.h>
#include <stdlib.h>

#include "amfid.h"

int drift_create(daemon_s *d, char *err, size_t errlen)
{
    d->drift_params = d->cfg.daemon.speed_drift;
    return amfi_speed_drift_create(&d->drift_params, &d->drift, err, errlen);
}

void drift_restore(daemon_s *d)
{
    char err[512];
    int open = 0;
    if (!d->drift || !d->drift_params.enabled)
        return;
    amfi_speed_pair *p = NULL;
    size_t n = 0;
    if (amfi_store_recent_speed_pairs(d->store, d->drift_params.window, &p, &n, err,
                                      sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return;
    }
    double *c = malloc((n ? n : 1) * sizeof *c);
    if (!c) {
        free(p);
        LOG_WARN("speed drift: out of memory for %zu corrections; the window starts empty", n);
        return;
    }
    for (size_t k = 0; k < n; k++)
        c[k] = amfi_speed_correction(p[k].speed_mps, p[k].speed_given_mps);
    int taken = amfi_speed_drift_prefill(d->drift, c, (int)n);
    free(c);
    free(p);
    if (amfi_store_alert_open(d->store, "speed_drift", &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        open = 0;
    }
    amfi_speed_drift_set_alerted(d->drift, open);
    metrics_alert(d, "speed_drift", open);
    if (taken > 0 || open)
        LOG_INFO("speed drift: %d estimated passages from the store%s", taken,
                 open ? "; the speed_drift alert is open" : "");
}

void drift_feed(daemon_s *d, int64_t utime, double speed_mps, double speed_given_mps)
{
    if (!d->drift || !d->drift_params.enabled)
        return;
    double c = amfi_speed_correction(speed_mps, speed_given_mps);
    amfi_alert_event al;
    amfi_speed_drift_eval ev;
    int bits = amfi_speed_drift_push(d->drift, c, &ev, &al);
    if (bits < 0) {
        set_error(d, "speed drift: correction of %.3f m/s against %.3f m/s refused", speed_mps,
                  speed_given_mps);
        return;
    }
    if (bits & AMFI_IND_ALERT)
        emit_alert(d, utime, &al, 0);
}

void drift_reload(daemon_s *d, const amfi_site_config *n)
{
    if (!amfi_speed_drift_params_equal(&n->daemon.speed_drift, &d->drift_params))
        LOG_WARN("reload: alerts.speed_drift takes effect at the next start");
}

void drift_destroy(daemon_s *d)
{
    amfi_speed_drift_destroy(d->drift);
    d->drift = NULL;
}
