/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * status.c: amfid's heartbeat and its intake record, two modules (ctx.h).
 *
 * status: every daemon.status_period_s (a timer; and once more at the
 * drain) the environment readings received are flushed to the store, the
 * status message goes out on the status channel and sd_notify STATUS is
 * set; the kernel's drops on amfid's sockets are read and a rise is logged.
 *
 * record: the intake counters of this run into the store's meta table
 * (intake.*: run, messages received and refused, kernel drops, samples
 * missing, passages not stored, environment readings, as of when), for
 * amfi-report: every 60 s (a timer; not while the store refuses writes)
 * and at the drain. A failure is logged, never fatal.
 *
 * Thread: the main thread only. Owns the drop counts.
 */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "amfi_status_t.h"
#include "ctx.h"

static struct {
    int64_t udp_drops, udp_drops_logged; /* kernel drops on our sockets */
    int64_t samples_missing;             /* as of the last heartbeat */
} H;

static int64_t wall_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

static int heartbeat(amfid_ctx *c)
{
    environment_flush(c);
    amfid_stats s;
    c->collect(c, &s);
    amfi_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = c->newest_utime;
    m.wall_utime = wall_us();
    m.blocks_received = s.blocks_received;
    m.blocks_rejected = s.blocks_rejected + s.ring_rejected + s.messages_malformed;
    m.samples_missing = s.samples_missing;
    H.samples_missing = s.samples_missing;
    m.vehicles_received = s.vehicles_received;
    m.vehicles_rejected = s.vehicles_rejected;
    m.passages_stored = s.passages_stored;
    m.passages_ok = s.passages_ok;
    m.queue_depth = s.queue_depth;
    int64_t drops = bus_udp_drops();
    if (drops > H.udp_drops)
        H.udp_drops = drops;
    if (H.udp_drops > H.udp_drops_logged) {
        LOG_WARN("the kernel dropped %lld UDP datagrams on amfid's sockets since start (%lld "
                 "new): the receive buffer overflowed; raise daemon.recv_buf_bytes and "
                 "net.core.rmem_max, or add solver threads",
                 (long long)H.udp_drops, (long long)(H.udp_drops - H.udp_drops_logged));
        H.udp_drops_logged = H.udp_drops;
    }
    m.messages_refused = s.refused_total;
    m.datagrams_dropped = H.udp_drops;
    m.passages_held = s.passages_held;
    m.state = (char *)c->state;
    m.last_error = c->last_error;
    m.site_id = (char *)c->cfg->site.id;
    BUS_PUBLISH(c, amfi_status_t, c->cfg->daemon.ch_status, &m);
    sd_notifyf(0, "STATUS=%s: %lld passages stored (%lld ok), %d queued, %lld blocks",
               c->state, (long long)s.passages_stored, (long long)s.passages_ok,
               m.queue_depth, (long long)s.blocks_received);
    return 0;
}

static int status_start(amfid_ctx *c, char *err, size_t errlen)
{
    (void)c, (void)err, (void)errlen;
    memset(&H, 0, sizeof H);
    return 0;
}

static int status_restore(amfid_ctx *c)
{
    return timer_add(c->timers, &c->cfg->daemon.status_period_s, heartbeat) ? 1 : 0;
}

static void status_final(amfid_ctx *c)
{
    heartbeat(c);
}

static void status_metrics(amfid_ctx *c, amfid_stats *s)
{
    (void)c;
    s->udp_drops = H.udp_drops;
}

const amfid_module status_module = {
    .name = "status",
    .start = status_start,
    .restore = status_restore,
    .metrics = status_metrics,
    .final = status_final,
};

/* ---- the intake in the store (for amfi-report) ------------------------------ */

static const double record_period_s = 60.0;

static void record(amfid_ctx *c)
{
    amfid_stats s;
    c->collect(c, &s);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    struct tm tm;
    char when[32];
    time_t sec = ts.tv_sec;
    gmtime_r(&sec, &tm);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
    struct {
        const char *key;
        long long v;
    } kv[] = {{"intake.run", (long long)c->run_id},
              {"intake.messages_received", (long long)s.messages_in},
              {"intake.messages_refused", (long long)s.refused_total},
              {"intake.datagrams_dropped", (long long)(H.udp_drops > 0 ? H.udp_drops : 0)},
              {"intake.samples_missing", (long long)H.samples_missing},
              {"intake.passages_lost", (long long)s.passages_lost},
              {"intake.environment_received", (long long)s.env_received},
              {"intake.environment_refused", (long long)s.env_rejected},
              {"intake.environment_stored", (long long)s.env_stored},
              {"intake.environment_lost", (long long)s.env_lost}};
    char err[256], val[32];
    int rc = 0;
    for (size_t i = 0; rc == 0 && i < sizeof kv / sizeof kv[0]; i++) {
        snprintf(val, sizeof val, "%lld", kv[i].v);
        rc = amfi_store_meta_set(c->store, kv[i].key, val, err, sizeof err);
    }
    if (rc == 0)
        rc = amfi_store_meta_set(c->store, "intake.as_of", when, err, sizeof err);
    if (rc)
        LOG_WARN("store: the intake counters: %s", err);
}

/* Not while the store refuses writes: tried again at the next turn. */
static int record_tick(amfid_ctx *c)
{
    if (pipeline_degraded())
        return 1;
    record(c);
    return 0;
}

static int record_restore(amfid_ctx *c)
{
    return timer_add(c->timers, &record_period_s, record_tick) ? 1 : 0;
}

static void record_final(amfid_ctx *c)
{
    if (!pipeline_degraded())
        record(c);
}

const amfid_module record_module = {
    .name = "record",
    .restore = record_restore,
    .final = record_final,
};
