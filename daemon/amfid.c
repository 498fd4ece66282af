/*
 * amfid: the bridge monitoring daemon.
 *
 *   amfid [--config FILE] [--db PATH] [--lcm-url URL] [--check-config]
 *
 * Listens on LCM to accelerometer blocks and vehicle events (and, from a
 * simulation, the truth), cuts the stream into vehicle passages, weighs each
 * vehicle with A-MFI on solver threads, stores every passage in SQLite (one
 * transaction each, in the order of the vehicles' entry), watches the spread
 * of the inferred weights and raises alerts; publishes passages, indicators,
 * alerts and a heartbeat. Runs in the foreground, logs to stderr (journald
 * takes it), speaks sd_notify (READY, STATUS, WATCHDOG).
 *
 * Threads: the main thread owns the bus, the rings, the tracker, the store
 * and the indicators; solver threads take passages from a bounded queue and
 * hand results back through a second queue and an eventfd. Time is the
 * data's time (message utimes): replaying a log at any speed stores the
 * same rows.
 *
 * Signals: SIGTERM/SIGINT stop reading the bus, let the solver threads
 * finish what is queued, store every pending passage (those whose data never
 * came as "gap") and close the database; SIGHUP reloads the configuration
 * (what cannot change while running is reported and kept).
 *
 * Exit status: 0 after a signal; 1 a runtime failure (store, bus); 2 bad
 * command line or configuration.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <lcm/lcm.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <systemd/sd-daemon.h>
#include <time.h>
#include <unistd.h>

#include "amfi/amfi.h"
#include "amfi_accel_block_t.h"
#include "amfi_alert_t.h"
#include "amfi_config.h"
#include "amfi_indicator_t.h"
#include "amfi_passage_t.h"
#include "amfi_status_t.h"
#include "amfi_truth_t.h"
#include "amfi_vehicle_t.h"
#include "indicators.h"
#include "ring.h"
#include "store.h"
#include "tracker.h"

#ifndef AMFID_DEFAULT_CONFIG
#define AMFID_DEFAULT_CONFIG "/etc/amfid/amfid.yaml"
#endif
#define MAX_BLOCK 4096 /* samples per accel block accepted */

/* ---- logging ----------------------------------------------------------- */

static void logm(const char *prefix, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void logm(const char *prefix, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs(prefix, stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}
#define LOG_INFO(...) logm(SD_INFO "amfid: ", __VA_ARGS__)
#define LOG_WARN(...) logm(SD_WARNING "amfid: ", __VA_ARGS__)
#define LOG_ERR(...) logm(SD_ERR "amfid: ", __VA_ARGS__)

static volatile sig_atomic_t stop_flag, reload_flag;
static void on_stop(int sig)
{
    (void)sig;
    stop_flag = 1;
}
static void on_hup(int sig)
{
    (void)sig;
    reload_flag = 1;
}

static int64_t wall_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

static double mono_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* ---- passages between the threads ------------------------------------- */

typedef struct job {
    amfi_window w;           /* the window (and its status) */
    int n_sensors;
    double *accel;           /* n_sensors × w.n, owned */
    /* result */
    int solved;
    double gvw_kg, axle_kg[AMFI_MAX_AXLES], lambda, residual_rms, solve_ms;
    char status[16];
    char reason[200];
} job;

typedef struct queue {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    job **items;
    int cap, head, n;
    int closed;
} queue;

static int queue_init(queue *q, int cap)
{
    memset(q, 0, sizeof *q);
    q->items = calloc((size_t)cap, sizeof *q->items);
    q->cap = cap;
    pthread_mutex_init(&q->mu, NULL);
    pthread_cond_init(&q->cv, NULL);
    return q->items ? 0 : -1;
}

static void queue_fini(queue *q)
{
    free(q->items);
    pthread_mutex_destroy(&q->mu);
    pthread_cond_destroy(&q->cv);
}

/* 0 queued, −1 full. */
static int queue_push(queue *q, job *j)
{
    int rc = -1;
    pthread_mutex_lock(&q->mu);
    if (q->n < q->cap) {
        q->items[(q->head + q->n) % q->cap] = j;
        q->n++;
        rc = 0;
        pthread_cond_signal(&q->cv);
    }
    pthread_mutex_unlock(&q->mu);
    return rc;
}

/* Blocks until a job or the queue is closed and empty (NULL). */
static job *queue_pop(queue *q, int wait)
{
    job *j = NULL;
    pthread_mutex_lock(&q->mu);
    while (wait && q->n == 0 && !q->closed)
        pthread_cond_wait(&q->cv, &q->mu);
    if (q->n > 0) {
        j = q->items[q->head];
        q->head = (q->head + 1) % q->cap;
        q->n--;
    }
    pthread_mutex_unlock(&q->mu);
    return j;
}

static int queue_depth(queue *q)
{
    pthread_mutex_lock(&q->mu);
    int n = q->n;
    pthread_mutex_unlock(&q->mu);
    return n;
}

static void queue_close(queue *q)
{
    pthread_mutex_lock(&q->mu);
    q->closed = 1;
    pthread_cond_broadcast(&q->cv);
    pthread_mutex_unlock(&q->mu);
}

static void job_free(job *j)
{
    if (j) {
        free(j->accel);
        free(j);
    }
}

/* ---- the daemon -------------------------------------------------------- */

typedef struct daemon_s {
    amfi_site_config cfg;
    const char *config_path;
    amfi_bridge *bridge;
    lcm_t *lcm;
    amfi_store *store;
    amfi_indicators *ind;
    amfi_tracker *tracker;
    amfi_ring *rings[AMFI_MAX_SENSORS];
    queue jobs, results;
    int efd;                       /* results ready */
    pthread_t *threads;
    int n_threads;
    /* reorder: results stored in seq order */
    job **pending;                 /* ring of size pend_cap indexed by seq */
    int pend_cap;
    int64_t next_seq;              /* next seq to store */
    int64_t released;              /* windows released by the tracker */
    /* counters (status_t) */
    int64_t blocks_received, blocks_rejected, vehicles_received, vehicles_rejected;
    int64_t messages_malformed, passages_stored, passages_ok, truth_received;
    int64_t newest_utime;
    char last_error[256];
    const char *state;
} daemon_s;

static void set_error(daemon_s *d, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_error(daemon_s *d, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->last_error, sizeof d->last_error, fmt, ap);
    va_end(ap);
    LOG_WARN("%s", d->last_error);
}

/* ---- solver threads ---------------------------------------------------- */

typedef struct worker_arg {
    daemon_s *d;
    amfi_solver *solver;
} worker_arg;

static void solve_job(const daemon_s *d, amfi_solver *s, job *j)
{
    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = j->w.n;
    p.scan_rate_hz = amfi_ring_rate(d->rings[0]);
    p.t_first_s = j->w.t_first_s;
    for (int i = 0; i < j->n_sensors; i++)
        p.accel[i] = j->accel + (size_t)i * j->w.n;
    p.speed_mps = j->w.v.speed_mps;
    p.n_axles = j->w.v.n_axles;
    for (int a = 0; a + 1 < p.n_axles; a++)
        p.axle_spacing_m[a] = j->w.v.spacing_m[a];
    amfi_result r;
    char err[256];
    double t0 = mono_s();
    int rc = amfi_solve(s, &p, &d->cfg.lambda, &r, err, sizeof err);
    j->solve_ms = 1e3 * (mono_s() - t0);
    if (rc != 0) {
        snprintf(j->status, sizeof j->status, "error");
        snprintf(j->reason, sizeof j->reason, "solver: %.180s", err);
        j->gvw_kg = NAN;
        return;
    }
    if (!(r.gvw_kg > 0.0) || !isfinite(r.gvw_kg)) {
        /* e.g. a silent sensor: stored as an error with the number, not lost */
        snprintf(j->status, sizeof j->status, "error");
        snprintf(j->reason, sizeof j->reason,
                 "inferred GVW %.0f kg is not positive: no response from the bridge?", r.gvw_kg);
        j->gvw_kg = NAN;
        return;
    }
    j->solved = 1;
    snprintf(j->status, sizeof j->status, "ok");
    j->gvw_kg = r.gvw_kg;
    for (int a = 0; a < r.n_axles; a++)
        j->axle_kg[a] = r.axle_kg[a];
    j->lambda = r.lambda_ref;
    j->residual_rms = r.residual_rms;
}

static void *worker_main(void *arg)
{
    worker_arg *wa = arg;
    job *j;
    while ((j = queue_pop(&wa->d->jobs, 1)) != NULL) {
        solve_job(wa->d, wa->solver, j);
        while (queue_push(&wa->d->results, j) != 0) /* never full: sized with jobs */
            usleep(1000);
        uint64_t one = 1;
        if (write(wa->d->efd, &one, sizeof one) < 0)
            continue; /* the main thread also polls the queue */
    }
    return NULL;
}

/* ---- storing and publishing, in seq order ------------------------------ */

static void publish_passage(daemon_s *d, const job *j, int64_t id)
{
    amfi_passage_t m;
    memset(&m, 0, sizeof m);
    m.utime = j->w.v.utime;
    m.passage_id = id;
    m.vehicle_id = j->w.v.vehicle_id;
    m.lane = (int16_t)j->w.v.lane;
    m.speed_mps = j->w.v.speed_mps;
    m.status = (char *)j->status;
    m.reason = (char *)j->reason;
    m.gvw_kg = j->solved ? j->gvw_kg : NAN;
    m.n_axles = (int16_t)(j->solved ? j->w.v.n_axles : 0);
    m.axle_kg = (double *)j->axle_kg;
    m.lambda = j->solved ? j->lambda : NAN;
    m.residual_rms = j->solved ? j->residual_rms : NAN;
    m.formulation = (char *)amfi_formulation_name(d->cfg.solver.formulation);
    m.solve_ms = j->solve_ms;
    amfi_passage_t_publish(d->lcm, d->cfg.daemon.ch_passage, &m);
}

static void feed_indicators(daemon_s *d, const job *j)
{
    amfi_indicator_eval ev;
    amfi_alert_event al[2];
    int n_al = 0;
    int bits = amfi_indicators_push(d->ind, j->gvw_kg, &ev, al, &n_al);
    if (bits < 0) {
        set_error(d, "indicators: GVW %.1f kg of vehicle %lld refused", j->gvw_kg,
                  (long long)j->w.v.vehicle_id);
        return;
    }
    char err[256];
    if (bits & AMFI_IND_BASELINE) {
        amfi_baseline b;
        memset(&b, 0, sizeof b);
        b.utime_set = j->w.v.utime;
        b.n = ev.n;
        b.mean_kg = ev.baseline_mean_kg;
        b.std_kg = ev.baseline_std_kg;
        snprintf(b.source, sizeof b.source, "auto");
        snprintf(b.note, sizeof b.note, "first %d ok passages", ev.n);
        if (amfi_store_set_baseline(d->store, &b, err, sizeof err))
            set_error(d, "store: %s", err);
        LOG_INFO("baseline established: mean %.0f kg, STD %.0f kg over %d passages",
                 ev.baseline_mean_kg, ev.baseline_std_kg, ev.n);
    }
    int64_t ind_id = 0;
    if (bits & AMFI_IND_EVAL) {
        amfi_indicator_row row = {j->w.v.utime, ev.n, ev.mean_kg, ev.std_kg,
                                  ev.baseline_mean_kg, ev.baseline_std_kg, ev.std_ratio,
                                  ev.p_value, ev.state};
        if (amfi_store_add_indicator(d->store, &row, &ind_id, err, sizeof err))
            set_error(d, "store: %s", err);
        amfi_indicator_t m = {j->w.v.utime, ind_id, ev.n, ev.mean_kg, ev.std_kg,
                              ev.baseline_mean_kg, ev.baseline_std_kg, ev.std_ratio,
                              ev.p_value, (char *)ev.state};
        amfi_indicator_t_publish(d->lcm, d->cfg.daemon.ch_indicator, &m);
    }
    for (int i = 0; (bits & AMFI_IND_ALERT) && i < n_al; i++) {
        int64_t aid = 0;
        if (amfi_store_add_alert(d->store, j->w.v.utime, al[i].level, al[i].kind, al[i].message,
                                 ind_id, al[i].raised, &aid, err, sizeof err))
            set_error(d, "store: %s", err);
        amfi_alert_t m = {j->w.v.utime, aid, (char *)al[i].level, (char *)al[i].kind,
                          al[i].message, ind_id, (int8_t)al[i].raised};
        amfi_alert_t_publish(d->lcm, d->cfg.daemon.ch_alert, &m);
        if (al[i].raised)
            LOG_WARN("ALERT %s (%s): %s", al[i].kind, al[i].level, al[i].message);
        else
            LOG_INFO("alert cleared %s: %s", al[i].kind, al[i].message);
    }
}

static int store_job(daemon_s *d, job *j)
{
    amfi_passage_row r;
    memset(&r, 0, sizeof r);
    r.vehicle_id = j->w.v.vehicle_id;
    r.utime = j->w.v.utime;
    r.lane = j->w.v.lane;
    r.speed_mps = j->w.v.speed_mps;
    r.n_axles = j->w.v.n_axles;
    for (int a = 0; a + 1 < r.n_axles; a++)
        r.spacing_m[a] = j->w.v.spacing_m[a];
    for (int a = 0; a < r.n_axles; a++)
        r.axle_kg[a] = j->solved ? j->axle_kg[a] : NAN;
    r.gvw_kg = j->solved ? j->gvw_kg : NAN;
    r.status = j->status;
    r.reason = j->reason;
    r.lambda = j->solved ? j->lambda : NAN;
    r.residual_rms = j->solved ? j->residual_rms : NAN;
    r.formulation = amfi_formulation_name(d->cfg.solver.formulation);
    r.solve_ms = j->solve_ms;
    int64_t id = 0;
    char err[256];
    if (amfi_store_add_passage(d->store, &r, &id, err, sizeof err)) {
        set_error(d, "store: passage of vehicle %lld: %s", (long long)r.vehicle_id, err);
        return -1;
    }
    d->passages_stored++;
    publish_passage(d, j, id);
    if (j->solved) {
        d->passages_ok++;
        feed_indicators(d, j);
    }
    return 0;
}

/* Park a finished job by seq; store every consecutive one from next_seq.
 * The parking ring grows when the solvers fall far behind (windows that
 * bypass them keep arriving): a passage is never dropped for lack of room. */
static int complete(daemon_s *d, job *j)
{
    int64_t seq = j->w.seq;
    if (seq - d->next_seq >= d->pend_cap) {
        int cap = d->pend_cap;
        while (seq - d->next_seq >= cap)
            cap *= 2;
        job **np = calloc((size_t)cap, sizeof *np);
        if (!np) { /* out of memory: store it now, out of order, rather than lose it */
            set_error(d, "out of memory for the reorder buffer: passage %lld stored out of order",
                      (long long)seq);
            int rc = store_job(d, j);
            job_free(j);
            return rc;
        }
        for (int i = 0; i < d->pend_cap; i++)
            if (d->pending[i])
                np[d->pending[i]->w.seq % cap] = d->pending[i];
        free(d->pending);
        d->pending = np;
        d->pend_cap = cap;
    }
    d->pending[seq % d->pend_cap] = j;
    int rc = 0;
    while (d->pending[d->next_seq % d->pend_cap] &&
           d->pending[d->next_seq % d->pend_cap]->w.seq == d->next_seq) {
        job *k = d->pending[d->next_seq % d->pend_cap];
        d->pending[d->next_seq % d->pend_cap] = NULL;
        if (store_job(d, k))
            rc = -1;
        job_free(k);
        d->next_seq++;
    }
    return rc;
}

static void drain_results(daemon_s *d)
{
    uint64_t v;
    if (read(d->efd, &v, sizeof v) < 0 && errno != EAGAIN)
        set_error(d, "eventfd: %s", strerror(errno));
    job *j;
    while ((j = queue_pop(&d->results, 0)) != NULL)
        complete(d, j);
}

/* Windows the tracker has decided: to the solvers, or straight to the store. */
static void release_windows(daemon_s *d, int flush)
{
    amfi_window w;
    const int ns = d->cfg.solver.n_sensors;
    while (amfi_tracker_next(d->tracker, d->rings, flush, &w)) {
        d->released++;
        job *j = calloc(1, sizeof *j);
        if (!j) {
            set_error(d, "out of memory for a passage");
            continue;
        }
        j->w = w;
        j->n_sensors = ns;
        j->gvw_kg = NAN;
        snprintf(j->status, sizeof j->status, "%s", w.status);
        snprintf(j->reason, sizeof j->reason, "%s", w.reason);
        if (strcmp(w.status, "ok") == 0) {
            j->accel = malloc(sizeof(double) * (size_t)ns * (size_t)(w.n > 0 ? w.n : 1));
            int missing = 0;
            for (int s = 0; s < ns && j->accel; s++) {
                int m = amfi_ring_get(d->rings[s], w.k0[s], w.n, j->accel + (size_t)s * w.n);
                missing += m < 0 ? w.n : m;
            }
            if (!j->accel || missing > 0) {
                snprintf(j->status, sizeof j->status, "gap");
                snprintf(j->reason, sizeof j->reason, "%d samples missing in the window",
                         missing);
            } else if (queue_push(&d->jobs, j) == 0) {
                continue; /* a solver thread has it */
            } else {
                snprintf(j->status, sizeof j->status, "overload");
                snprintf(j->reason, sizeof j->reason,
                         "solver queue full (%d passages waiting)", d->cfg.daemon.queue_size);
            }
        }
        complete(d, j);
    }
}

/* ---- bus handlers: validate at the boundary ---------------------------- */

static int sensor_index(const daemon_s *d, int id)
{
    for (int i = 0; i < d->cfg.solver.n_sensors; i++)
        if (d->cfg.sensor_id[i] == id)
            return i;
    return -1;
}

static void on_accel(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    daemon_s *d = user;
    amfi_accel_block_t m;
    memset(&m, 0, sizeof m);
    if (amfi_accel_block_t_decode(rb->data, 0, (int)rb->data_size, &m) < 0) {
        d->messages_malformed++;
        set_error(d, "%s: malformed accel_block_t (%u bytes) rejected", ch, rb->data_size);
        amfi_accel_block_t_decode_cleanup(&m); /* it may have allocated before failing */
        return;
    }
    d->blocks_received++;
    const char *why = NULL;
    int idx = sensor_index(d, m.sensor_id);
    if (idx < 0)
        why = "sensor_id not in the configuration";
    else if (!(m.sample_rate_hz > 0 && m.sample_rate_hz <= 100000))
        why = "sample_rate_hz out of (0, 100000]";
    else if (m.n < 1 || m.n > MAX_BLOCK)
        why = "n out of 1 .. 4096";
    else if (m.utime <= 0)
        why = "utime must be > 0";
    for (int i = 0; !why && i < m.n; i++)
        if (!isfinite(m.accel[i]) || fabs(m.accel[i]) > 1000.0)
            why = "accel has a non-finite or absurd (> 1000 m/s²) value";
    if (!why && !d->rings[idx]) {
        d->rings[idx] = amfi_ring_create(m.sample_rate_hz, d->cfg.daemon.ring_s);
        if (!d->rings[idx])
            why = "cannot create the sample ring";
    }
    if (!why) {
        const char *rwhy = NULL;
        int rc = amfi_ring_put(d->rings[idx], m.utime, m.sample_rate_hz, m.n, m.accel, &rwhy);
        if (rc == AMFI_RING_REJECT)
            why = rwhy;
        else if (m.utime > d->newest_utime)
            d->newest_utime = m.utime;
    }
    if (why) {
        d->blocks_rejected++;
        set_error(d, "%s: accel_block_t sensor %d seq %lld rejected: %s", ch, m.sensor_id,
                  (long long)m.seq, why);
    }
    amfi_accel_block_t_decode_cleanup(&m);
}

static void store_invalid(daemon_s *d, const amfi_vehicle_t *m, const char *why)
{
    /* A rejected vehicle is still a stored passage, with the reason; the raw
     * values that failed are in the reason, not in the typed columns. */
    job *j = calloc(1, sizeof *j);
    if (!j)
        return;
    j->w.v.vehicle_id = m->vehicle_id;
    j->w.v.utime = (m->utime > 0 && m->utime < 253402300800000000LL) ? m->utime
                                                                       : d->newest_utime;
    j->w.v.lane = m->lane; /* int16_t on the bus */
    j->w.v.speed_mps = NAN;
    j->w.v.n_axles = 0;
    j->gvw_kg = NAN;
    snprintf(j->status, sizeof j->status, "invalid");
    snprintf(j->reason, sizeof j->reason, "%.120s (speed_mps %.6g, n_axles %d, utime %lld)",
             why, m->speed_mps, m->n_axles, (long long)m->utime);
    /* outside the entry order: stored now */
    store_job(d, j);
    job_free(j);
}

static void on_vehicle(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    daemon_s *d = user;
    amfi_vehicle_t m;
    memset(&m, 0, sizeof m);
    if (amfi_vehicle_t_decode(rb->data, 0, (int)rb->data_size, &m) < 0) {
        d->messages_malformed++;
        set_error(d, "%s: malformed vehicle_t (%u bytes) rejected", ch, rb->data_size);
        amfi_vehicle_t_decode_cleanup(&m); /* it may have allocated before failing */
        return;
    }
    d->vehicles_received++;
    const char *why = NULL;
    char buf[200];
    if (!(m.speed_mps >= 1.0 && m.speed_mps <= 60.0))
        why = "speed_mps out of [1, 60]";
    else if (m.n_axles < 1 || m.n_axles > d->cfg.solver.max_axles)
        why = "n_axles out of range for the solver";
    else if (m.n_spacings != m.n_axles - 1)
        why = "n_spacings must be n_axles - 1";
    else if (m.utime <= 0)
        why = "utime must be > 0";
    for (int a = 0; !why && a < m.n_spacings; a++)
        if (!(m.axle_spacing_m[a] >= 0.5 && m.axle_spacing_m[a] <= 30.0))
            why = "axle_spacing_m out of [0.5, 30]";
    if (!why) {
        amfi_vehicle_ev v;
        memset(&v, 0, sizeof v);
        v.vehicle_id = m.vehicle_id;
        v.utime = m.utime;
        v.lane = m.lane;
        v.speed_mps = m.speed_mps;
        v.n_axles = m.n_axles;
        for (int a = 0; a < m.n_spacings; a++)
            v.spacing_m[a] = m.axle_spacing_m[a];
        const char *twhy = NULL;
        if (amfi_tracker_add(d->tracker, &v, &twhy) != 0)
            why = twhy;
    }
    if (why) {
        d->vehicles_rejected++;
        snprintf(buf, sizeof buf, "%s: vehicle_t %lld rejected: %s", ch, (long long)m.vehicle_id,
                 why);
        set_error(d, "%s", buf);
        store_invalid(d, &m, buf);
    }
    amfi_vehicle_t_decode_cleanup(&m);
}

static void on_truth(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    daemon_s *d = user;
    amfi_truth_t m;
    memset(&m, 0, sizeof m);
    if (amfi_truth_t_decode(rb->data, 0, (int)rb->data_size, &m) < 0) {
        d->messages_malformed++;
        set_error(d, "%s: malformed truth_t (%u bytes) rejected", ch, rb->data_size);
        amfi_truth_t_decode_cleanup(&m); /* it may have allocated before failing */
        return;
    }
    char err[256];
    if (!(m.gvw_kg > 0 && m.gvw_kg < 1e6) || m.n_axles < 1 || m.n_axles > AMFI_MAX_AXLES)
        set_error(d, "%s: truth_t %lld rejected: gvw or n_axles out of range", ch,
                  (long long)m.vehicle_id);
    else if (amfi_store_add_truth(d->store, m.vehicle_id, m.utime, m.gvw_kg, m.n_axles,
                                  m.axle_kg, m.mean_force_N, m.speed_true_mps, err, sizeof err))
        set_error(d, "%s: truth_t %lld: %s", ch, (long long)m.vehicle_id, err);
    else
        d->truth_received++;
    amfi_truth_t_decode_cleanup(&m);
}

/* ---- heartbeat ---------------------------------------------------------- */

static void heartbeat(daemon_s *d)
{
    int64_t missing = 0, rejected_ring = 0;
    for (int i = 0; i < d->cfg.solver.n_sensors; i++)
        if (d->rings[i]) {
            const amfi_ring_stats *st = amfi_ring_stats_of(d->rings[i]);
            missing += st->missing;
            rejected_ring += st->late + st->duplicates;
        }
    amfi_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = d->newest_utime;
    m.wall_utime = wall_us();
    m.blocks_received = d->blocks_received;
    m.blocks_rejected = d->blocks_rejected + rejected_ring + d->messages_malformed;
    m.samples_missing = missing;
    m.vehicles_received = d->vehicles_received;
    m.vehicles_rejected = d->vehicles_rejected;
    m.passages_stored = d->passages_stored;
    m.passages_ok = d->passages_ok;
    m.queue_depth = queue_depth(&d->jobs);
    m.state = (char *)d->state;
    m.last_error = d->last_error;
    amfi_status_t_publish(d->lcm, d->cfg.daemon.ch_status, &m);
    sd_notifyf(0, "STATUS=%s: %lld passages stored (%lld ok), %d queued, %lld blocks",
               d->state, (long long)d->passages_stored, (long long)d->passages_ok,
               m.queue_depth, (long long)d->blocks_received);
}

/* ---- set-up and tear-down ----------------------------------------------- */

static void usage(void)
{
    fprintf(stderr, "usage: amfid [--config FILE] [--db PATH] [--lcm-url URL] [--check-config]\n");
}

static int load_config(const char *path, amfi_site_config *c)
{
    char err[512];
    amfi_config_defaults(c);
    if (amfi_config_load(path, c, err, sizeof err)) {
        fprintf(stderr, "amfid: %s\n", err);
        return -1;
    }
    return 0;
}

static void indicator_params(const amfi_daemon_config *dc, amfi_indicator_params *p)
{
    *p = dc->indicators;
}

/* 1 when the newest alert of `kind` in the store was a raise (still open). */
static int last_alert_raised(amfi_store *st, const char *kind)
{
    char err[256];
    int open = 0;
    if (amfi_store_alert_open(st, kind, &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return 0;
    }
    return open;
}

/* SIGHUP: apply what can change while running, report the rest. */
static void reload(daemon_s *d)
{
    amfi_site_config n;
    if (load_config(d->config_path, &n)) {
        LOG_ERR("reload: the new configuration is refused; keeping the running one");
        return;
    }
    /* keep the command-line overrides */
    memcpy(n.daemon.db_path, d->cfg.daemon.db_path, sizeof n.daemon.db_path);
    memcpy(n.daemon.lcm_url, d->cfg.daemon.lcm_url, sizeof n.daemon.lcm_url);
    if (memcmp(&n.bridge, &d->cfg.bridge, sizeof n.bridge) ||
        memcmp(&n.solver, &d->cfg.solver, sizeof n.solver) ||
        memcmp(n.sensor_id, d->cfg.sensor_id, sizeof n.sensor_id))
        LOG_WARN("reload: bridge, sensors and solver changes take effect at the next start");
    if (strcmp(n.daemon.ch_accel, d->cfg.daemon.ch_accel) ||
        strcmp(n.daemon.ch_vehicle, d->cfg.daemon.ch_vehicle) ||
        strcmp(n.daemon.ch_truth, d->cfg.daemon.ch_truth) ||
        n.daemon.workers != d->cfg.daemon.workers ||
        n.daemon.queue_size != d->cfg.daemon.queue_size || n.daemon.ring_s != d->cfg.daemon.ring_s ||
        n.daemon.sync_full != d->cfg.daemon.sync_full)
        LOG_WARN("reload: channels, workers, queue, ring and store changes take effect at the "
                 "next start");
    /* λ policy, output channels, heartbeat, waits: now. */
    d->cfg.lambda = n.lambda;
    memcpy(d->cfg.daemon.ch_passage, n.daemon.ch_passage, sizeof n.daemon.ch_passage);
    memcpy(d->cfg.daemon.ch_indicator, n.daemon.ch_indicator, sizeof n.daemon.ch_indicator);
    memcpy(d->cfg.daemon.ch_alert, n.daemon.ch_alert, sizeof n.daemon.ch_alert);
    memcpy(d->cfg.daemon.ch_status, n.daemon.ch_status, sizeof n.daemon.ch_status);
    d->cfg.daemon.status_period_s = n.daemon.status_period_s;
    d->cfg.daemon.max_wait_s = n.daemon.max_wait_s;
    amfi_indicator_params ip;
    indicator_params(&n.daemon, &ip);
    if (memcmp(&n.daemon.indicators, &d->cfg.daemon.indicators, sizeof n.daemon.indicators))
        LOG_WARN("reload: indicator settings take effect at the next start");
    LOG_INFO("reload: configuration %s applied", d->config_path);
}

int main(int argc, char **argv)
{
    const char *config = AMFID_DEFAULT_CONFIG, *db = NULL, *url = NULL;
    int check_only = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--check-config"))
            check_only = 1;
        else if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            usage();
            return 0;
        } else if (i + 1 < argc && !strcmp(argv[i], "--config"))
            config = argv[++i];
        else if (i + 1 < argc && !strcmp(argv[i], "--db"))
            db = argv[++i];
        else if (i + 1 < argc && !strcmp(argv[i], "--lcm-url"))
            url = argv[++i];
        else {
            fprintf(stderr, "amfid: %s: unknown option or missing value\n", argv[i]);
            usage();
            return 2;
        }
    }
    static daemon_s d; /* large; zeroed */
    d.config_path = config;
    d.efd = -1;
    d.state = "starting";
    if (load_config(config, &d.cfg))
        return 2;
    if (db)
        snprintf(d.cfg.daemon.db_path, sizeof d.cfg.daemon.db_path, "%s", db);
    if (url)
        snprintf(d.cfg.daemon.lcm_url, sizeof d.cfg.daemon.lcm_url, "%s", url);
    char err[512];
    if (amfi_bridge_create(&d.cfg.bridge, &d.bridge, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: bridge: %s\n", config, err);
        return 2;
    }
    amfi_indicator_params ip;
    indicator_params(&d.cfg.daemon, &ip);
    if (amfi_indicators_create(&ip, &d.ind, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: daemon.indicators: %s\n", config, err);
        amfi_bridge_destroy(d.bridge);
        return 2;
    }
    /* A solver is built once here to check the solver section. */
    amfi_solver *probe = NULL;
    if (amfi_solver_create(d.bridge, &d.cfg.solver, &probe, err, sizeof err)) {
        fprintf(stderr, "amfid: %s: solver: %s\n", config, err);
        amfi_indicators_destroy(d.ind);
        amfi_bridge_destroy(d.bridge);
        return 2;
    }
    amfi_solver_destroy(probe);
    if (check_only) {
        printf("amfid: %s: ok (bridge %s, %d sensor(s), %d worker(s), store %s)\n", config,
               d.cfg.name, d.cfg.solver.n_sensors, d.cfg.daemon.workers, d.cfg.daemon.db_path);
        amfi_indicators_destroy(d.ind);
        amfi_bridge_destroy(d.bridge);
        return 0;
    }
    amfi_set_blas_threads(1);
    int rc = 1;
    /* Build in dependency order; tear down in reverse at `out`. */
    if (amfi_store_open(d.cfg.daemon.db_path, d.cfg.daemon.sync_full, &d.store, err, sizeof err)) {
        LOG_ERR("store %s: %s", d.cfg.daemon.db_path, err);
        goto out;
    }
    {
        amfi_baseline b;
        int found = 0;
        if (amfi_store_get_baseline(d.store, &b, &found, err, sizeof err) == 0 && found) {
            amfi_indicators_set_baseline(d.ind, b.mean_kg, b.std_kg, b.n);
            LOG_INFO("baseline from the store: mean %.0f kg, STD %.0f kg (%d, %s)", b.mean_kg,
                     b.std_kg, b.n, b.source);
            double *g = malloc(sizeof(double) * (size_t)ip.window);
            int n = 0;
            if (g && amfi_store_recent_ok_gvw(d.store, ip.window, g, &n, err, sizeof err) == 0)
                amfi_indicators_prefill(d.ind, g, n);
            free(g);
            /* An alert open before a restart stays open, not raised twice. */
            int open_std = last_alert_raised(d.store, "std_increase");
            int open_mean = last_alert_raised(d.store, "mean_shift");
            amfi_indicators_set_alerted(d.ind, open_std, open_mean);
            if (open_std || open_mean)
                LOG_INFO("open alerts restored from the store:%s%s", open_std ? " std_increase" : "",
                         open_mean ? " mean_shift" : "");
        }
    }
    amfi_tracker_params tp = {d.cfg.bridge.span_m, d.cfg.solver.pre_roll_s + d.cfg.daemon.margin_s,
                              d.cfg.solver.post_roll_s + d.cfg.daemon.margin_s,
                              d.cfg.daemon.max_wait_s, d.cfg.solver.n_sensors};
    d.tracker = amfi_tracker_create(&tp);
    d.pend_cap = d.cfg.daemon.queue_size + AMFI_TRACKER_MAX_PENDING + 16;
    d.pending = calloc((size_t)d.pend_cap, sizeof *d.pending);
    d.next_seq = 1;
    d.efd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (!d.tracker || !d.pending || d.efd < 0 || queue_init(&d.jobs, d.cfg.daemon.queue_size) ||
        queue_init(&d.results, d.cfg.daemon.queue_size + d.cfg.daemon.workers + 1)) {
        LOG_ERR("out of memory at start-up");
        goto out;
    }
    d.lcm = lcm_create(d.cfg.daemon.lcm_url[0] ? d.cfg.daemon.lcm_url : NULL);
    if (!d.lcm) {
        LOG_ERR("cannot open the LCM bus '%s'", d.cfg.daemon.lcm_url);
        goto out;
    }
    lcm_subscribe(d.lcm, d.cfg.daemon.ch_accel, on_accel, &d);
    lcm_subscribe(d.lcm, d.cfg.daemon.ch_vehicle, on_vehicle, &d);
    lcm_subscribe(d.lcm, d.cfg.daemon.ch_truth, on_truth, &d);
    d.n_threads = d.cfg.daemon.workers;
    d.threads = calloc((size_t)d.n_threads, sizeof *d.threads);
    worker_arg *wa = calloc((size_t)d.n_threads, sizeof *wa);
    if (!d.threads || !wa) {
        LOG_ERR("out of memory at start-up");
        free(wa);
        goto out;
    }
    int started = 0;
    for (int i = 0; i < d.n_threads; i++) {
        wa[i].d = &d;
        if (amfi_solver_create(d.bridge, &d.cfg.solver, &wa[i].solver, err, sizeof err) ||
            pthread_create(&d.threads[i], NULL, worker_main, &wa[i]) != 0) {
            LOG_ERR("solver thread %d: %s", i, err);
            amfi_solver_destroy(wa[i].solver);
            wa[i].solver = NULL;
            break;
        }
        started++;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sa.sa_handler = on_hup;
    sigaction(SIGHUP, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

    if (started == d.n_threads) {
        d.state = "running";
        sd_notify(0, "READY=1");
        LOG_INFO("running: bus '%s', store %s, %d solver thread(s), bridge %s",
                 d.cfg.daemon.lcm_url[0] ? d.cfg.daemon.lcm_url : "(default)",
                 d.cfg.daemon.db_path, d.n_threads, d.cfg.name);
        uint64_t wd_usec = 0;
        int wd = sd_watchdog_enabled(0, &wd_usec) > 0;
        double last_beat = 0.0, last_wd = 0.0;
        int lfd = lcm_get_fileno(d.lcm);
        const int replay = strncmp(d.cfg.daemon.lcm_url, "file://", 7) == 0;
        rc = 0;
        while (!stop_flag) {
            /* Replaying a log, the bus waits for the solvers (no overload,
             * the same rows at any speed); a live bus is always read. */
            const int hold = replay && queue_depth(&d.jobs) >= d.cfg.daemon.queue_size;
            struct pollfd pf[2] = {{hold ? -1 : lfd, POLLIN, 0}, {d.efd, POLLIN, 0}};
            int pr = poll(pf, 2, 100);
            if (pr < 0 && errno != EINTR) {
                LOG_ERR("poll: %s", strerror(errno));
                rc = 1;
                break;
            }
            if (pr > 0 && (pf[0].revents & POLLIN) && lcm_handle(d.lcm) != 0) {
                if (replay) { /* file:// provider: the end of the log */
                    LOG_INFO("the bus has no more data (end of log)");
                    break;
                }
                /* a live bus: a receive error is logged and counted, not fatal */
                d.messages_malformed++;
                set_error(&d, "LCM receive error on '%s'", d.cfg.daemon.lcm_url);
            }
            if (pr > 0 && (pf[0].revents & (POLLHUP | POLLERR | POLLNVAL))) {
                LOG_INFO("the bus closed");
                break;
            }
            release_windows(&d, 0);
            drain_results(&d);
            if (reload_flag) {
                reload_flag = 0;
                reload(&d);
            }
            double now = mono_s();
            if (now - last_beat >= d.cfg.daemon.status_period_s) {
                heartbeat(&d);
                last_beat = now;
            }
            if (wd && now - last_wd >= 0.5e-6 * (double)wd_usec) {
                sd_notify(0, "WATCHDOG=1");
                last_wd = now;
            }
        }
        /* Drain: every pending passage is stored, solved or with its reason. */
        d.state = "draining";
        sd_notify(0, "STOPPING=1");
        release_windows(&d, 1);
        queue_close(&d.jobs);
        for (int i = 0; i < started; i++)
            pthread_join(d.threads[i], NULL);
        started = 0;
        drain_results(&d);
        heartbeat(&d);
        LOG_INFO("stopped: %lld passages stored (%lld ok), %lld blocks, %lld vehicles, %lld "
                 "rejected messages",
                 (long long)d.passages_stored, (long long)d.passages_ok,
                 (long long)d.blocks_received, (long long)d.vehicles_received,
                 (long long)(d.blocks_rejected + d.vehicles_rejected + d.messages_malformed));
    }
    queue_close(&d.jobs);
    for (int i = 0; i < started; i++)
        pthread_join(d.threads[i], NULL);
    for (int i = 0; i < d.n_threads; i++)
        amfi_solver_destroy(wa[i].solver);
    free(wa);
out:
    if (d.lcm)
        lcm_destroy(d.lcm);
    if (d.pending)
        for (int i = 0; i < d.pend_cap; i++)
            job_free(d.pending[i]);
    free(d.pending);
    free(d.threads);
    if (d.jobs.items)
        queue_fini(&d.jobs);
    if (d.results.items)
        queue_fini(&d.results);
    if (d.efd >= 0)
        close(d.efd);
    for (int i = 0; i < AMFI_MAX_SENSORS; i++)
        amfi_ring_destroy(d.rings[i]);
    amfi_tracker_destroy(d.tracker);
    amfi_store_close(d.store);
    amfi_indicators_destroy(d.ind);
    amfi_bridge_destroy(d.bridge);
    return rc;
}
