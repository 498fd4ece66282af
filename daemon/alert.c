/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * alert.c: one alert event out the way every alert goes (the context's
 * emit_alert): stored (with the indicator row it came from, if any),
 * published on the alert channel, counted in the metrics (open kinds),
 * handed to alerts.command (notify.c) and logged, a raise as a warning.
 * The modules reach it through the context only.
 *
 * Thread: the main thread only.
 */
#include "amfi_alert_t.h"
#include "ctx.h"

void alert_emit(amfid_ctx *c, int64_t utime, const amfi_alert_event *a, int64_t ind_id)
{
    char err[256];
    int64_t aid = 0;
    if (amfi_store_add_alert(c->store, utime, a->level, a->kind, a->message, ind_id, a->raised,
                             &aid, err, sizeof err))
        ctx_error(c, "store: %s", err);
    amfi_alert_t m = {utime, aid, (char *)a->level, (char *)a->kind, (char *)a->message, ind_id,
                      (int8_t)a->raised, (char *)c->cfg->site.id};
    BUS_PUBLISH(c, amfi_alert_t, c->cfg->daemon.ch_alert, &m);
    metrics_alert(a->kind, a->raised);
    notify_alert(c, utime, aid, a->level, a->kind, a->message, ind_id, a->raised);
    if (a->raised)
        LOG_WARN("ALERT %s (%s): %s", a->kind, a->level, a->message);
    else
        LOG_INFO("alert cleared %s: %s", a->kind, a->message);
}
