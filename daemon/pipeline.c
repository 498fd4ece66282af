/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pipeline.c: amfid's in-order pipeline: finished passages (solved or not)
 * parked by their release order and, in that order, stored (one
 * transaction each), published on the passage channel, and the ok ones fed
 * to the modules: each module's row hook fills its columns before the row
 * is stored, each one's on_passage runs after it is stored, in the order
 * of the table of modules (amfid.c): the natural frequency, the metrics,
 * the passage channel (here), the speed-drift alert, the STD and mean
 * rules, the scale indicator and the known-truck runs. An event of several vehicles weighed together
 * (tracker.h) becomes one row per vehicle, in entry order, each with the
 * event's size and its own weight and quality; with
 * daemon.indicators.single_presence_only the indicators take only the
 * passages weighed alone (the one filter here, not in the engine).
 *
 * The pipeline is three parts: the reorder buffer (reorder.c: results parked
 * by their release order, handed on consecutively), the store sink (sink.c)
 * and, here, the fan-out of a stored passage. A passage is acknowledged
 * when its transaction has committed; only then is it published and fed to
 * the indicators. When the store cannot write (disk full, I/O error,
 * read-only, locked) the sink holds the passage, in order, in a queue
 * bounded in bytes (daemon.store.held_max_bytes) and retries with a backoff
 * (1 s doubling to 30 s); amfid is then degraded (status message state,
 * sd_notify STATUS, a `store_degraded` alert on the bus and in the log,
 * raised and cleared here, cleared when the queue has drained). What
 * overflows the queue is counted and each such vehicle logged with its id
 * and time.
 *
 * A module (ctx.h): its tick stores what the solvers handed back and
 * retries the held passages; its on_passage publishes the passage.
 *
 * Thread: the main thread only. Owns the reorder buffer and the sink and
 * the store handle's passage writes; it takes jobs back from the solver
 * pool's result queue (pool.h), after which they are its own.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "amfi_alert_t.h"
#include "amfi_classify.h"
#include "amfi_passage_t.h"
#include "ctx.h"
#include "reorder.h"
#include "sink.h"

static struct {
    reorder *reorder;
    sink *sink;
    int64_t stored, ok;         /* passages stored, of which ok */
    /* the store_degraded alert while the sink holds passages */
    int64_t degraded_utime;     /* data time it was raised */
    char degraded_msg[1024];    /* its message, stored once the store writes again */
} P;

/* The speed the passage was weighed with: the estimate when the solver
 * estimated it (solver.speed: estimate), else the detector's. */
static double speed_used(const job *j)
{
    return j->speed_estimated ? j->speed_used_mps : j->w.v.speed_mps;
}

static void publish_passage(amfid_ctx *d, const amfid_passage *p)
{
    const job *j = p->j;
    const int64_t id = p->id;
    const amfi_passage_row *r = p->r;
    amfi_passage_t m;
    memset(&m, 0, sizeof m);
    m.utime = j->w.v.utime;
    m.passage_id = id;
    m.vehicle_id = j->w.v.vehicle_id;
    m.lane = (int16_t)j->w.v.lane;
    m.speed_mps = speed_used(j);
    m.status = (char *)j->status;
    m.reason = (char *)j->reason;
    m.gvw_kg = j->solved ? j->gvw_kg : NAN;
    m.n_axles = (int16_t)(j->solved ? j->w.v.n_axles : 0);
    m.axle_kg = (double *)j->axle_kg;
    m.lambda = j->solved ? j->lambda_used : NAN;
    m.residual_rms = j->solved ? j->residual_rms : NAN;
    m.formulation = (char *)amfi_formulation_name(d->cfg->solver.formulation);
    m.solve_ms = j->solve_ms;
    m.site_id = (char *)d->cfg->site.id;
    m.speed_given_mps = j->w.v.speed_given_mps;
    m.speed_estimated = (int8_t)j->speed_estimated;
    m.n_vehicles = (int16_t)(j->w.n_vehicles > 1 ? j->w.n_vehicles : 1);
    m.quality = j->quality > 0 ? j->quality : NAN;
    m.reference_gvw_kg = j->w.v.reference_gvw_kg > 0 ? j->w.v.reference_gvw_kg : NAN;
    m.f1_hz = r->f1_hz;
    m.f1_comp_hz = r->f1_comp_hz;
    m.fit_ratio = r->fit_ratio > 0 ? r->fit_ratio : NAN;
    /* the class and groups as stored (the classes module's row hook): the
     * groups' axles and, solved, their loads from the row's axles */
    int16_t g_axles[AMFI_MAX_AXLES] = {0};
    double g_kg[AMFI_MAX_AXLES] = {0};
    m.vehicle_class = (char *)(r->vclass ? r->vclass : "");
    m.overload = (int8_t)(r->has_overload ? r->overload : -1);
    m.loads_refused = (char *)(r->loads_refused ? r->loads_refused : "");
    if (r->vclass && r->axle_groups) {
        amfi_axle_group g[AMFI_MAX_AXLES];
        int ng = amfi_axle_groups(r->n_axles, r->spacing_m, j->solved ? r->axle_kg : NULL,
                                  d->cfg->classes.group_spacing_m, g);
        for (int k = 0; k < ng; k++) {
            g_axles[k] = (int16_t)g[k].n_axles;
            g_kg[k] = g[k].load_kg;
        }
        m.n_groups = (int8_t)(ng > 0 ? ng : 0);
    }
    m.group_axles = g_axles;
    m.group_load_kg = g_kg;
    BUS_PUBLISH(d, amfi_passage_t, d->cfg->daemon.ch_passage, &m);
}

/* The row of a job. */
static void job_row(amfid_ctx *d, const job *j, amfi_passage_row *r)
{
    memset(r, 0, sizeof *r);
    r->vehicle_id = j->w.v.vehicle_id;
    r->utime = j->w.v.utime;
    r->lane = j->w.v.lane;
    r->speed_mps = speed_used(j);
    r->speed_given_mps = j->w.v.speed_given_mps;
    r->speed_estimated = j->speed_estimated;
    r->n_axles = j->w.v.n_axles;
    for (int a = 0; a + 1 < r->n_axles; a++)
        r->spacing_m[a] = j->w.v.spacing_m[a];
    for (int a = 0; a < r->n_axles; a++)
        r->axle_kg[a] = j->solved ? j->axle_kg[a] : NAN;
    r->gvw_kg = j->solved ? j->gvw_kg : NAN;
    r->status = j->status;
    r->reason = j->reason;
    r->lambda = j->solved ? j->lambda_used : NAN;
    r->residual_rms = j->solved ? j->residual_rms : NAN;
    r->formulation = amfi_formulation_name(d->cfg->solver.formulation);
    r->solve_ms = j->solve_ms;
    r->n_vehicles = j->w.n_vehicles > 1 ? j->w.n_vehicles : 1;
    r->quality = j->quality > 0 ? j->quality : NAN;
    r->reference_gvw_kg = j->w.v.reference_gvw_kg;
}

/* The row of a passage: the job's columns, then each module's (row hooks,
 * in table order). */
static void fill_row(amfid_ctx *d, const amfid_passage *p, amfi_passage_row *r)
{
    job_row(d, p->j, r);
    for (int i = 0; i < d->n_modules; i++)
        if (d->modules[i]->row)
            d->modules[i]->row(d, p, r);
}

/* Store one vehicle's passage (a transaction); once committed, each
 * module's on_passage in table order. 0, or −1 when the store refused
 * (the job untouched: the sink holds it). */
static int store_now(amfid_ctx *d, job *j)
{
    amfi_passage_row r;
    /* an inseparable vehicle's joint estimate (status multiple) is not fed */
    amfid_passage p = {j, &r, 0,
                       j->solved && strcmp(j->status, "ok") == 0 &&
                           (!d->cfg->daemon.single_presence_only || j->w.n_vehicles <= 1)};
    fill_row(d, &p, &r);
    char err[256];
    int rc = amfi_store_add_passage(d->store, &r, &p.id, err, sizeof err);
    if (rc == AMFI_EINVAL && strcmp(j->status, "error") != 0) {
        /* A value the store cannot hold (a solver result beyond the
         * schema's ranges: garbage samples within the intake's limits can
         * give one) is the passage's fault, not the store's: holding it
         * would block every passage behind it. It is stored as an error
         * with the store's reason and without the values. */
        snprintf(j->reason, sizeof j->reason, "result not storable: %.160s", err);
        snprintf(j->status, sizeof j->status, "error");
        j->solved = 0;
        p.feeds = 0;
        fill_row(d, &p, &r);
        ctx_error(d, "store: passage of vehicle %lld stored as error: %s",
                  (long long)r.vehicle_id, err);
        rc = amfi_store_add_passage(d->store, &r, &p.id, err, sizeof err);
    }
    if (rc) {
        ctx_error(d, "store: passage of vehicle %lld: %s", (long long)r.vehicle_id, err);
        return -1;
    }
    P.stored++;
    if (j->solved && strcmp(j->status, "ok") == 0)
        P.ok++;
    for (int i = 0; i < d->n_modules; i++)
        if (d->modules[i]->on_passage)
            d->modules[i]->on_passage(d, &p);
    return 0;
}

/* The store_degraded alert. Raised, it cannot be stored (that is what it
 * says): it is published and logged, and its time and text are kept; once
 * the store takes writes again, the raise and the clear are both written to
 * the alerts table, so that the store's history shows the outage. */
static void publish_store_alert(amfid_ctx *d, int raised, const char *msg)
{
    int64_t aid = 0;
    int64_t now = d->newest_utime > 0 ? d->newest_utime : 0;
    if (raised) {
        P.degraded_utime = now;
        snprintf(P.degraded_msg, sizeof P.degraded_msg, "%s", msg);
    } else {
        char err[256];
        if (amfi_store_add_alert(d->store, P.degraded_utime, "warning", "store_degraded",
                                 P.degraded_msg, 0, 1, NULL, err, sizeof err) ||
            amfi_store_add_alert(d->store, now, "warning", "store_degraded", msg, 0, 0, &aid,
                                 err, sizeof err))
            ctx_error(d, "store: the store_degraded alert: %s", err);
    }
    amfi_alert_t m = {now, aid, (char *)"warning", (char *)"store_degraded",
                      (char *)msg, 0, (int8_t)raised, (char *)d->cfg->site.id};
    BUS_PUBLISH(d, amfi_alert_t, d->cfg->daemon.ch_alert, &m);
    metrics_alert("store_degraded", raised);
    notify_alert(d, now, aid, "warning", "store_degraded", msg, 0, raised);
    if (raised)
        LOG_ERR("ALERT store_degraded (warning): %s", msg);
    else
        LOG_INFO("alert cleared store_degraded: %s", msg);
}

/* The sink became degraded, or is not any more (sink.h). */
static void on_degraded(void *arg, int on)
{
    amfid_ctx *d = arg;
    char msg[1000];
    sink_stats st;
    sink_stats_of(P.sink, &st);
    if (on) {
        d->state = "degraded";
        snprintf(msg, sizeof msg,
                 "the store %.300s cannot be written (%.300s); passages are held in memory (up to %d) "
                 "and retried",
                 d->cfg->daemon.db_path, d->last_error, sink_capacity(P.sink));
        publish_store_alert(d, 1, msg);
        sd_notifyf(0, "STATUS=degraded: store cannot be written, %d passages held", st.held);
    } else {
        if (strcmp(d->state, "degraded") == 0)
            d->state = "running";
        snprintf(msg, sizeof msg,
                 "the store %.300s takes writes again; every held passage is stored (%d at most "
                 "were held, %lld lost to overflow)",
                 d->cfg->daemon.db_path, st.peak, (long long)st.lost);
        publish_store_alert(d, 0, msg);
    }
}

static int write_passage(void *arg, job *j)
{
    return store_now(arg, j);
}

/* The job of vehicle i of an event: its own vehicle, result and status
 * (the event's when the event was not solved); the first vehicle's takes
 * the event's samples (its passage holds the event's raw window, raw.c),
 * the others none. NULL: out of memory. */
static job *vehicle_job(job *e, int i)
{
    job *j = malloc(sizeof *j);
    if (!j)
        return NULL;
    *j = *e;
    j->accel = NULL;
    if (i == 0) {
        j->accel = e->accel;
        e->accel = NULL;
    }
    j->w.v = e->w.ev[i];
    j->quality = NAN;
    if (!e->solved)
        return j;
    const job_vehicle *o = &e->veh[i];
    j->quality = o->quality;
    j->solved = o->solved;
    j->gvw_kg = o->solved ? o->gvw_kg : NAN;
    for (int a = 0; a < AMFI_MAX_AXLES; a++)
        j->axle_kg[a] = o->solved && a < j->w.v.n_axles ? o->axle_kg[a] : NAN;
    if (!o->solved) {
        snprintf(j->status, sizeof j->status, "error");
        snprintf(j->reason, sizeof j->reason, "%s", o->reason);
    }
    return j;
}

/* Vehicle i of the solved event (or passage) e, weighed as j: when the
 * data do not fix its own weight, status "multiple" with the reason, the
 * joint estimate kept in the row (gvw, axles, quality: the sum is not lost)
 * but not fed to the indicators. In order: another vehicle on the span in
 * its window but outside its solve (the event cut down at a limit); axles
 * the solver merged with another vehicle's (coincident all along: its
 * group, amfi_vehicle_result.group, whose sum is given); an
 * axle within daemon.inseparable_gap_m of another vehicle's for at least
 * daemon.inseparable_share of its crossing (one point of the beam: only
 * the two vehicles' sum is fixed, and it is given); a quality figure above
 * daemon.inseparable_quality, or daemon.inseparable_quality_lanes in an
 * event with vehicles of several lanes (its weight moves when λ is
 * loosened). */
/* Another vehicle of event e in vehicle i's group of coincident axles
 * (amfi_solve_multi merged their axles), or −1. */
static int coincident_with(const job *e, int i)
{
    for (int v = 0; v < e->w.n_vehicles; v++)
        if (v != i && e->veh[v].group == e->veh[i].group)
            return v;
    return -1;
}

static void mark_inseparable(const amfid_ctx *d, const job *e, int i, job *j)
{
    if (!j->solved || strcmp(j->status, "ok") != 0)
        return;
    const amfi_daemon_config *c = &d->cfg->daemon;
    if (e->w.outside[i]) {
        snprintf(j->reason, sizeof j->reason,
                 "inseparable: vehicle %lld was on the span inside its window but not weighed "
                 "with it (event cut down at a limit); the weight misses that load",
                 (long long)e->w.outside_id[i]);
    } else if (e->w.n_vehicles > 1 && coincident_with(e, i) >= 0) {
        const int k = coincident_with(e, i);
        int n = 0;
        for (int v = 0; v < e->w.n_vehicles; v++)
            n += e->veh[v].group == e->veh[i].group;
        snprintf(j->reason, sizeof j->reason,
                 "inseparable: axles at one point with vehicle %lld's all along its crossing "
                 "(one unknown in the solve); %.0f kg the %d together; the weight is an even "
                 "split of that",
                 (long long)e->w.ev[k].vehicle_id, e->veh[i].group_gvw_kg, n);
    } else if (e->w.n_vehicles > 1) {
        amfi_nearness nr;
        amfi_window_nearness(&e->w, d->cfg->bridge.span_m, c->inseparable_gap_m, i, &nr);
        int lanes = 1; /* 2: the event has vehicles of more than one lane */
        for (int k = 1; k < e->w.n_vehicles; k++)
            if (e->w.ev[k].lane != e->w.ev[0].lane)
                lanes = 2;
        if (nr.other >= 0 && nr.share >= c->inseparable_share) {
            const job_vehicle *o = &e->veh[nr.other];
            char sum[64] = "";
            if (o->solved)
                snprintf(sum, sizeof sum, "; %.0f kg the two together", j->gvw_kg + o->gvw_kg);
            snprintf(j->reason, sizeof j->reason,
                     "inseparable: axles within %.2g m of vehicle %lld's for %.0f %% of its "
                     "crossing (closest %.2f m)%s; the weight is the joint estimate",
                     c->inseparable_gap_m, (long long)e->w.ev[nr.other].vehicle_id,
                     100.0 * nr.share, nr.min_gap_m, sum);
        } else if (j->quality > (lanes > 1 ? c->inseparable_quality_lanes
                                           : c->inseparable_quality)) {
            snprintf(j->reason, sizeof j->reason,
                     "inseparable: its weight moves %.1f %% when λ is loosened tenfold (quality "
                     "%.2f > %.2g%s); the %d vehicles weigh %.0f kg together",
                     j->quality - 1.0, j->quality,
                     lanes > 1 ? c->inseparable_quality_lanes : c->inseparable_quality,
                     lanes > 1 ? ", vehicles of several lanes" : "", e->w.n_vehicles, e->gvw_kg);
        } else {
            return;
        }
    } else {
        return;
    }
    snprintf(j->status, sizeof j->status, "multiple");
}

/* Store a passage, or each vehicle of an event in entry order. Takes the job. */
static int store_job(amfid_ctx *d, job *e)
{
    if (e->w.n_vehicles <= 1) {
        mark_inseparable(d, e, 0, e);
        return sink_put(P.sink, e);
    }
    int rc = 0, not_ok = 0;
    job *vj[AMFI_MAX_VEHICLES];
    for (int i = 0; i < e->w.n_vehicles; i++) {
        vj[i] = vehicle_job(e, i);
        if (vj[i])
            mark_inseparable(d, e, i, vj[i]);
        not_ok |= !vj[i] || !vj[i]->solved || strcmp(vj[i]->status, "ok") != 0;
    }
    for (int i = 0; i < e->w.n_vehicles; i++) {
        job *j = vj[i];
        if (!j) {
            sink_lost(P.sink, 1);
            ctx_error(d, "out of memory: passage of vehicle %lld at utime %lld LOST",
                      (long long)e->w.ev[i].vehicle_id, (long long)e->w.ev[i].utime);
            rc = -1;
            continue;
        }
        j->event_not_ok = not_ok;
        if (sink_put(P.sink, j))
            rc = -1;
    }
    job_free(e);
    return rc;
}

static int pipeline_start(amfid_ctx *d, char *err, size_t errlen)
{
    (void)d, (void)err, (void)errlen;
    memset(&P, 0, sizeof P);
    return 0;
}

static int pipeline_restore(amfid_ctx *d)
{
    sink_params sp = {(size_t)d->cfg->daemon.held_max_bytes, 1.0, 30.0};
    sink_ops ops = {write_passage, on_degraded, d, d->last_error};
    P.reorder = reorder_create(d->cfg->daemon.queue_size + AMFI_TRACKER_MAX_PENDING + 16, 1);
    P.sink = sink_create(&sp, &ops);
    if (!P.reorder || !P.sink) {
        LOG_ERR("out of memory at start-up");
        return 1;
    }
    return 0;
}

static void pipeline_stop(amfid_ctx *d)
{
    (void)d;
    sink_destroy(P.sink);
    reorder_destroy(P.reorder);
    memset(&P, 0, sizeof P);
}

void pipeline_retry(amfid_ctx *d, double final)
{
    (void)d;
    if (P.sink)
        sink_retry(P.sink, final);
}

int pipeline_held(void)
{
    sink_stats st;
    if (!P.sink)
        return 0;
    sink_stats_of(P.sink, &st);
    return st.held;
}

int pipeline_degraded(void)
{
    sink_stats st;
    if (!P.sink)
        return 0;
    sink_stats_of(P.sink, &st);
    return st.degraded;
}

/* Park a finished job by seq (reorder.c); store every consecutive one. */
int pipeline_complete(amfid_ctx *d, job *j)
{
    if (reorder_park(P.reorder, j)) { /* out of memory: stored now, out of order, not lost */
        ctx_error(d, "out of memory for the reorder buffer: passage %lld stored out of order",
                  (long long)j->w.seq);
        return store_job(d, j);
    }
    int rc = 0;
    job *k;
    while ((k = reorder_next(P.reorder)) != NULL)
        if (store_job(d, k))
            rc = -1;
    return rc;
}

void pipeline_drain_results(amfid_ctx *d)
{
    uint64_t v;
    if (read(d->pool->efd, &v, sizeof v) < 0 && errno != EAGAIN)
        ctx_error(d, "eventfd: %s", strerror(errno));
    job *j;
    while ((j = queue_pop(&d->pool->results, 0)) != NULL)
        pipeline_complete(d, j);
}

int pipeline_store_now(amfid_ctx *d, job *j)
{
    return store_job(d, j);
}

/* Each turn: what the solvers handed back, then the held passages when
 * their time has come. */
static void pipeline_tick(amfid_ctx *d)
{
    pipeline_drain_results(d);
    if (pipeline_held() > 0)
        pipeline_retry(d, 0);
}

static void pipeline_metrics(amfid_ctx *d, amfid_stats *s)
{
    (void)d;
    sink_stats st;
    memset(&st, 0, sizeof st);
    if (P.sink)
        sink_stats_of(P.sink, &st);
    s->passages_stored = P.stored;
    s->passages_ok = P.ok;
    s->passages_lost = st.lost;
    s->passages_held = st.held;
    s->degraded = st.degraded;
}

const amfid_module pipeline_module = {
    .name = "pipeline",
    .start = pipeline_start,
    .restore = pipeline_restore,
    .on_passage = publish_passage,
    .tick = pipeline_tick,
    .metrics = pipeline_metrics,
    .stop = pipeline_stop,
};
