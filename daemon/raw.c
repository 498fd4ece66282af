/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * raw.c: the passages' raw samples (daemon.store.raw): the samples of every
 * sensor in the window the solver weighed, with their time base, the
 * detector records and the solver's settings, written with the passage in
 * its transaction (store.h, "raw samples": raw_windows, passage_raw), so
 * that amfi-solve --from-store re-weighs it; and the retention, by age and
 * size, oldest first, never the passages.
 *
 * Which passages: keep all (every passage weighed: ok, solver error,
 * overload, inseparable), failed (those not stored ok: the ones worth a
 * second look) or none. A window that was never complete (gap) or never
 * released to the solver (late, multiple, invalid) has no samples. An
 * event's vehicles share one window: the first vehicle's passage holds it
 * (pipeline.c hands that vehicle the event's samples), the later ones link
 * to it. A passage the store held (degraded) has lost its samples (sink.h):
 * it is stored without.
 *
 * A module (ctx.h): restore reads the store's usage and adds the retention
 * timer (every 60 s; again at the next turn while more is due; once more at
 * the drain, final), row points
 * the row at the window (the store encodes it into the handle's reused
 * buffers: no allocation per passage once they fit), on_passage counts
 * and remembers an event's window for its later vehicles, metrics and final
 * report. The settings are restart-only (amfid.yaml(5)).
 *
 * Thread: the main thread only.
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ctx.h"

#define PRUNE_PERIOD_S 60.0
#define PRUNE_BATCH 500 /* windows deleted a turn (one transaction) */
#define LOG_FIRST 10    /* raw rows not written: the first logged, then every 1000th */

static struct {
    amfi_raw_window w;   /* the window of the passage being stored */
    amfi_raw_put put;    /* its put (the row points at it) */
    int in_row;          /* the row of the passage being stored points at put */
    int holder;          /* put writes a window (1) or a link (0) */
    int64_t event_seq;   /* the event whose window was written last (release order) */
    int64_t event_window;/* and its raw_windows id, for the event's later vehicles */
    int64_t windows, links, bytes, bytes_in, failed;
    int64_t pruned_age, pruned_size, pruned_bytes;
    int64_t kept_windows, kept_bytes;
    double period_s;
} R;

static const char *const keep_names[] = {"none", "failed", "all"};

static int raw_start(amfid_ctx *c, char *err, size_t errlen)
{
    (void)c, (void)err, (void)errlen;
    memset(&R, 0, sizeof R);
    R.period_s = PRUNE_PERIOD_S;
    return 0;
}

/* The retention: windows older than max_age_days (against the stream's data
 * time), then the oldest beyond max_mib. 1 (again at the next turn) while
 * more is due. */
static int raw_prune(amfid_ctx *c)
{
    const amfi_daemon_config *dc = &c->cfg->daemon;
    int64_t before = 0;
    if (dc->raw_max_age_days > 0 && c->newest_utime > 0) {
        before = c->newest_utime - (int64_t)(dc->raw_max_age_days * 86400e6);
        if (before <= 0)
            before = 0;
    }
    const int64_t max_bytes = dc->raw_max_mib > 0 ? (int64_t)(dc->raw_max_mib * 1048576.0) : -1;
    if (before == 0 && max_bytes < 0)
        return 0;
    amfi_raw_pruned pr;
    char err[256];
    if (amfi_store_raw_prune(c->store, before, max_bytes, PRUNE_BATCH, &pr, err, sizeof err)) {
        ctx_error(c, "raw samples: retention: %s", err);
        return 0;
    }
    if (pr.by_age + pr.by_size > 0) {
        R.pruned_age += pr.by_age;
        R.pruned_size += pr.by_size;
        R.pruned_bytes += pr.bytes;
        R.kept_windows -= pr.by_age + pr.by_size;
        R.kept_bytes -= pr.bytes;
        if (R.kept_windows < 0 || R.kept_bytes < 0) /* another writer: read it again */
            amfi_store_raw_usage(c->store, &R.kept_windows, &R.kept_bytes, err, sizeof err);
        LOG_INFO("raw samples: %" PRId64 " windows deleted older than %g days, %" PRId64
                 " beyond %g MiB (%.1f MiB); %" PRId64 " windows, %.1f MiB kept",
                 pr.by_age, dc->raw_max_age_days, pr.by_size, dc->raw_max_mib,
                 (double)pr.bytes / 1048576.0, R.kept_windows,
                 (double)R.kept_bytes / 1048576.0);
    }
    return pr.more ? 1 : 0;
}

static int raw_restore(amfid_ctx *c)
{
    char err[256];
    const amfi_daemon_config *dc = &c->cfg->daemon;
    if (amfi_store_raw_usage(c->store, &R.kept_windows, &R.kept_bytes, err, sizeof err)) {
        LOG_ERR("raw samples: %s", err);
        return 1;
    }
    LOG_INFO("raw samples: keep %s as %s; %" PRId64 " windows, %.1f MiB stored; deleted after %g "
             "days (0: never) or beyond %g MiB (0: no bound)",
             keep_names[dc->raw_keep], dc->raw_float32 ? "float32" : "float64", R.kept_windows,
             (double)R.kept_bytes / 1048576.0,
             dc->raw_max_age_days, dc->raw_max_mib);
    if (timer_add(c->timers, &R.period_s, raw_prune) != 0) {
        LOG_ERR("raw samples: no room for the retention timer");
        return 1;
    }
    return 0;
}

/* The index of the job's vehicle in its event. */
static int vehicle_index(const job *j)
{
    for (int i = 0; i < j->w.n_vehicles; i++)
        if (j->w.ev[i].vehicle_id == j->w.v.vehicle_id && j->w.ev[i].utime == j->w.v.utime)
            return i;
    return 0;
}

static void copy_vehicle(const amfi_vehicle_ev *e, amfi_raw_vehicle *o)
{
    o->vehicle_id = e->vehicle_id;
    o->utime = e->utime;
    o->lane = e->lane;
    o->speed_mps = e->speed_mps;
    o->n_axles = e->n_axles;
    for (int a = 0; a + 1 < e->n_axles; a++)
        o->spacing_m[a] = e->spacing_m[a];
}

static void raw_row(amfid_ctx *c, const amfid_passage *p, amfi_passage_row *r)
{
    const job *j = p->j;
    const amfi_daemon_config *dc = &c->cfg->daemon;
    R.in_row = 0;
    r->raw = NULL;
    if (dc->raw_keep == AMFI_RAW_KEEP_NONE)
        return;
    const int multi = j->w.n_vehicles > 1;
    const int ok = j->solved && strcmp(j->status, "ok") == 0;
    /* an event's window is kept (failed) when any of its vehicles is not ok */
    if (dc->raw_keep == AMFI_RAW_KEEP_FAILED && ok && !(multi && j->event_not_ok))
        return;
    memset(&R.put, 0, sizeof R.put);
    const int idx = multi ? vehicle_index(j) : 0;
    if (j->accel && j->w.n > 0 && strcmp(j->w.status, "ok") == 0 &&
        strcmp(j->status, "gap") != 0) {
        amfi_raw_window *w = &R.w;
        w->utime = multi ? j->w.ev[0].utime : j->w.v.utime;
        w->rate_hz = j->scan_rate_hz;
        w->t_first_s = j->w.t_first_s;
        w->n_samples = j->w.n;
        w->n_sensors = j->n_sensors;
        for (int i = 0; i < j->n_sensors; i++) {
            w->sensor_id[i] = c->cfg->sensor_id[i];
            w->sensor_at_m[i] = c->cfg->solver.sensor_x_m[i];
        }
        w->n_vehicles = multi ? j->w.n_vehicles : 1;
        for (int v = 0; v < w->n_vehicles; v++)
            copy_vehicle(multi ? &j->w.ev[v] : &j->w.v, &w->vehicle[v]);
        w->lambda = j->lambda;
        w->speed_estimate = j->speed_estimate;
        w->speed_prior = j->speed_prior;
        w->samples = j->accel;
        R.put.window = w;
        R.put.float32 = dc->raw_float32;
        R.put.vehicle = idx;
        R.holder = 1;
    } else if (multi && idx > 0 && R.event_seq == j->w.seq && R.event_window > 0) {
        R.put.window_id = R.event_window;
        R.put.vehicle = idx;
        R.holder = 0;
    } else {
        return;
    }
    R.in_row = 1;
    r->raw = &R.put;
}

static void raw_passage(amfid_ctx *c, const amfid_passage *p)
{
    if (!R.in_row)
        return;
    R.in_row = 0;
    const amfi_raw_put *put = &R.put;
    if (put->status != 0) {
        R.failed++;
        if (R.failed <= LOG_FIRST || R.failed % 1000 == 0)
            LOG_WARN("raw samples of passage %" PRId64 " (vehicle %" PRId64
                        ") not stored (%" PRId64 " so far): %s",
                        p->id, p->j->w.v.vehicle_id, R.failed, put->err);
        (void)c;
        return;
    }
    if (R.holder) {
        R.windows++;
        R.bytes += put->bytes;
        R.bytes_in += put->raw_bytes;
        R.kept_windows++;
        R.kept_bytes += put->bytes;
        R.event_seq = p->j->w.seq;
        R.event_window = put->stored_window_id;
    } else {
        R.links++;
    }
}

static void raw_metrics(amfid_ctx *c, amfid_stats *s)
{
    (void)c;
    s->raw_windows = R.windows;
    s->raw_links = R.links;
    s->raw_bytes = R.bytes;
    s->raw_bytes_in = R.bytes_in;
    s->raw_failed = R.failed;
    s->raw_pruned_age = R.pruned_age;
    s->raw_pruned_size = R.pruned_size;
    s->raw_pruned_bytes = R.pruned_bytes;
    s->raw_kept_windows = R.kept_windows;
    s->raw_kept_bytes = R.kept_bytes;
}

static void raw_final(amfid_ctx *c)
{
    /* the retention once more at the drain (the last minute's passages):
     * bounded, a batch a call */
    for (int k = 0; k < 1000 && raw_prune(c); k++)
        ;
    LOG_INFO("raw samples: %" PRId64 " windows written (%.1f MiB, %.1f MiB as float64: "
             "ratio %.2f), %" PRId64 " passages linked to their event's, %" PRId64
             " not written; %" PRId64 " deleted by age, %" PRId64 " by size",
             R.windows, (double)R.bytes / 1048576.0, (double)R.bytes_in / 1048576.0,
             R.bytes > 0 ? (double)R.bytes_in / (double)R.bytes : 0.0, R.links, R.failed,
             R.pruned_age, R.pruned_size);
}

const amfid_module raw_module = {
    .name = "raw",
    .section = "daemon.store.raw",
    .start = raw_start,
    .restore = raw_restore,
    .row = raw_row,
    .on_passage = raw_passage,
    .metrics = raw_metrics,
    .final = raw_final,
};
