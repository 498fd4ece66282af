/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * intake.c: amfid's bus intake: the LCM handlers of accelerometer blocks,
 * vehicle events and (simulations) the truth (the environment's handler is
 * environment.c's own; the truth only when daemon.simulation is true),
 * each message authenticated first (bus.c) and validated where
 * it enters (messages name the channel and the field); samples into the
 * rings, vehicles into the tracker; and the windows the tracker decides,
 * filled from the rings into jobs for the solver pool (or straight to the
 * pipeline when they cannot be solved).
 *
 * Every message is counted, checked on its raw bytes and rate-limited
 * (admit.c); refused messages are counted per input and reason and logged
 * within a rate limit (reject.c).
 *
 * A module (ctx.h): restore builds the tracker and wants the inputs
 * (bus_want); reload applies the live intake bounds and max_wait_s (the
 * tracker's own copy) and logs the detector's corrections (detector.*,
 * applied to every vehicle where it is admitted, read live); its tick releases the windows decided; final logs
 * what the bounds did.
 *
 * Thread: the main thread only (inside lcm_handle and the loop). Owns the
 * rings (created here at the first block of each sensor), the tracker and
 * the intake counters; a job leaves it complete: the λ policy and the
 * sample rate it needs are copied into it here, so the solver threads read
 * nothing shared.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_accel_block_t.h"
#include "amfi_truth_t.h"
#include "amfi_vehicle_t.h"
#include "ctx.h"

#define MAX_BLOCK 4096 /* samples per accel block accepted */

static struct {
    amfi_ring *rings[AMFI_MAX_SENSORS];
    amfi_tracker *tracker;
    int64_t blocks_received, blocks_rejected, vehicles_received, vehicles_rejected;
    int64_t truth_received;
    int64_t vehicles_evicted;   /* the tracker was full: the stalest went (stored) */
    int64_t references_refused; /* calibration references not taken (source, range) */
    int64_t invalid_unstored;   /* refused vehicles over the rate: summarised only */
} I;

/* ---- windows to jobs ---------------------------------------------------- */

void intake_release(amfid_ctx *d, int flush)
{
    amfi_window w;
    const int ns = d->cfg->solver.n_sensors;
    /* Before the first sample nothing is decided: the vehicles queued so
     * far are checked against the data time when it comes (on_accel), and
     * one dated far ahead is refused then, never stored as a passage at
     * its forged date. */
    if (!flush && d->newest_utime == 0)
        return;
    while (amfi_tracker_next(I.tracker, I.rings, flush, &w)) {
        job *j = calloc(1, sizeof *j);
        if (!j) {
            ctx_error(d, "out of memory for a passage");
            continue;
        }
        j->w = w;
        j->n_sensors = ns;
        j->gvw_kg = NAN;
        j->f1_hz = j->f1_zeta = j->f1_r2 = NAN;
        /* everything the solver thread reads travels with the job */
        j->lambda = d->cfg->lambda;
        j->speed_estimate = d->cfg->speed_estimate;
        j->speed_prior = d->cfg->speed_prior;
        /* an ok window has data from every sensor; the others (gap: a
         * sensor that never sent a block) may have no ring at all */
        j->scan_rate_hz = I.rings[0] ? amfi_ring_rate(I.rings[0]) : 0.0;
        snprintf(j->status, sizeof j->status, "%s", w.status);
        snprintf(j->reason, sizeof j->reason, "%s", w.reason);
        if (strcmp(w.status, "ok") == 0) {
            j->accel = malloc(sizeof(double) * (size_t)ns * (size_t)(w.n > 0 ? w.n : 1));
            int missing = 0;
            for (int s = 0; s < ns && j->accel; s++) {
                int m = amfi_ring_get(I.rings[s], w.k0[s], w.n, j->accel + (size_t)s * w.n);
                missing += m < 0 ? w.n : m;
            }
            freevib_estimate(d, j, I.rings); /* the free vibration's samples are in the rings now */
            modelfit_take(d, j, I.rings);
            if (!j->accel || missing > 0) {
                snprintf(j->status, sizeof j->status, "gap");
                snprintf(j->reason, sizeof j->reason, "%d samples missing in the window",
                         missing);
            } else if (queue_push(&d->pool->jobs, j) == 0) {
                continue; /* a solver thread has it */
            } else {
                snprintf(j->status, sizeof j->status, "overload");
                snprintf(j->reason, sizeof j->reason,
                         "solver queue full (%d passages waiting)", d->cfg->daemon.queue_size);
            }
        }
        pipeline_complete(d, j);
    }
}

/* ---- bus handlers: validate at the boundary ---------------------------- */

static void store_refused(amfid_ctx *d, int64_t vehicle_id, int64_t utime, int lane,
                          const char *status, const char *reason);

static int sensor_index(const amfid_ctx *d, int id)
{
    for (int i = 0; i < d->cfg->solver.n_sensors; i++)
        if (d->cfg->sensor_id[i] == id)
            return i;
    return -1;
}

static void on_accel(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    amfid_ctx *d = user;
    amfi_accel_block_t m;
    if (admit_decode(d, AMFI_MSG_ACCEL_BLOCK_T, REJECT_ACCEL, "accel_block_t", rb, ch, &m))
        return;
    I.blocks_received++;
    const char *why = NULL;
    char wbuf[160];
    int idx = sensor_index(d, m.sensor_id);
    if (idx < 0)
        why = "sensor_id not in the configuration";
    else if (!(m.sample_rate_hz > 0 && m.sample_rate_hz <= 100000))
        why = "sample_rate_hz out of (0, 100000]";
    else if (!(fabs(m.sample_rate_hz - d->cfg->sensor_rate_hz[idx]) <=
               1e-6 * d->cfg->sensor_rate_hz[idx])) {
        /* the rate is the site file's, never the bus's (one block at another
         * rate once fixed a sensor's rate until restart) */
        snprintf(wbuf, sizeof wbuf, "sample_rate_hz %.6g differs from sensors[%d].rate_hz (%.6g Hz)",
                 m.sample_rate_hz, idx, d->cfg->sensor_rate_hz[idx]);
        why = wbuf;
    } else if (m.n < 1 || m.n > MAX_BLOCK)
        why = "n out of 1 .. 4096";
    else if (m.utime <= 0 || m.utime > AMFI_STORE_MAX_UTIME)
        why = "utime out of (0, year 9999]";
    for (int i = 0; !why && i < m.n; i++)
        if (!isfinite(m.accel[i]) || fabs(m.accel[i]) > 1000.0)
            why = "accel has a non-finite or absurd (> 1000 m/s²) value";
    /* The channel's rate, in samples, charged for the blocks that pass the
     * checks (a refused block costs its check only and takes nothing from
     * the real stream's allowance). */
    if (!why && !admit_take(d, REJECT_ACCEL, (double)m.n)) {
        I.blocks_rejected++;
        reject_note(d, REJECT_ACCEL, REJECT_RATE,
                    "%s: accel_block_t sensor %d seq %lld refused: over the channel's rate limit "
                    "(daemon.intake.accel_margin %g × the sensors' rate_hz: %.0f samples/s)",
                    ch, m.sensor_id, (long long)m.seq, d->cfg->daemon.accel_margin,
                    admit_rate(REJECT_ACCEL));
        amfi_accel_block_t_decode_cleanup(&m);
        return;
    }
    if (!why && !I.rings[idx]) {
        I.rings[idx] = amfi_ring_create(d->cfg->sensor_rate_hz[idx], d->cfg->daemon.ring_s);
        if (!I.rings[idx])
            why = "cannot create the sample ring";
    }
    if (!why) {
        const char *rwhy = NULL;
        amfi_ring *r = I.rings[idx];
        int rc = amfi_ring_put(r, m.utime, m.sample_rate_hz, m.n, m.accel, &rwhy);
        if (rc == AMFI_RING_REJECT) {
            why = rwhy;
        } else if (rc == AMFI_RING_QUARANTINE) {
            reject_note(d, REJECT_ACCEL, REJECT_QUARANTINE,
                        "%s: accel_block_t sensor %d seq %lld quarantined: it starts %.3f s "
                        "from the stream's newest sample; adopted only when %d blocks in a row "
                        "confirm the jump",
                        ch, m.sensor_id, (long long)m.seq,
                        1e-6 * ((double)m.utime - amfi_ring_utime(r, amfi_ring_newest(r))),
                        AMFI_RING_CONFIRM);
        } else {
            if (rc == AMFI_RING_RESTART)
                LOG_WARN("%s: sensor %d: the data's time jumped by %+.3f s, confirmed by %d "
                         "blocks in a row: the ring restarts at utime %lld; passages in the "
                         "hole are stored as gap",
                         ch, m.sensor_id, amfi_ring_stats_of(r)->last_jump_s, AMFI_RING_CONFIRM,
                         (long long)m.utime);
            /* the stream's time: the newest sample of any ring (it may go
             * back after a confirmed jump) */
            int64_t newest = 0;
            for (int s = 0; s < d->cfg->solver.n_sensors; s++)
                if (I.rings[s] && amfi_ring_newest(I.rings[s]) >= 0) {
                    double u = amfi_ring_utime(I.rings[s], amfi_ring_newest(I.rings[s]));
                    if (u > (double)newest)
                        newest = (int64_t)u;
                }
            const int64_t before = d->newest_utime;
            d->newest_utime = newest;
            /* vehicles queued before the data came (or before it caught
             * up) and dated past it by more than vehicle_ahead_s: refused
             * now, as they would have been on arrival */
            amfi_vehicle_ev ev;
            const double limit = (double)newest + 1e6 * d->cfg->daemon.vehicle_ahead_s;
            while (newest > before && amfi_tracker_take_after(I.tracker, (int64_t)fmin(limit, 9e18), &ev)) {
                char reason[200];
                I.vehicles_rejected++;
                snprintf(reason, sizeof reason,
                         "%s: vehicle_t %lld rejected: utime %.0f s past the newest data time "
                         "(daemon.intake.vehicle_ahead_s %g s)",
                         d->cfg->daemon.ch_vehicle, (long long)ev.vehicle_id,
                         1e-6 * (double)(ev.utime - newest), d->cfg->daemon.vehicle_ahead_s);
                reject_note(d, REJECT_VEHICLE, REJECT_INVALID, "%s", reason);
                store_refused(d, ev.vehicle_id, ev.utime, ev.lane, "invalid", reason);
            }
        }
    }
    if (why) {
        I.blocks_rejected++;
        reject_note(d, REJECT_ACCEL, REJECT_INVALID, "%s: accel_block_t sensor %d seq %lld rejected: %s",
                    ch, m.sensor_id, (long long)m.seq, why);
    }
    amfi_accel_block_t_decode_cleanup(&m);
}

/* A vehicle that will not be weighed, stored now with its status and reason
 * (outside the entry order): at its own time if it is plausible (at most
 * daemon.intake.vehicle_ahead_s after the newest data time, and a time the
 * store can hold), else at the newest data time, else the wall clock: the
 * row must exist, and a forged date must not move the store's time span. */
static void store_refused(amfid_ctx *d, int64_t vehicle_id, int64_t utime, int lane,
                          const char *status, const char *reason)
{
    job *j = calloc(1, sizeof *j);
    if (!j)
        return;
    j->w.v.vehicle_id = vehicle_id;
    const int ahead = d->newest_utime > 0 &&
                      (double)utime > (double)d->newest_utime + 1e6 * d->cfg->daemon.vehicle_ahead_s;
    if (utime > 0 && utime <= AMFI_STORE_MAX_UTIME && !ahead)
        j->w.v.utime = utime;
    else if (d->newest_utime > 0 && d->newest_utime <= AMFI_STORE_MAX_UTIME)
        j->w.v.utime = d->newest_utime;
    else {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        j->w.v.utime = (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
    }
    j->w.v.lane = lane;
    j->w.v.speed_mps = j->w.v.speed_given_mps = NAN;
    j->w.v.n_axles = 0;
    j->gvw_kg = NAN;
    snprintf(j->status, sizeof j->status, "%s", status);
    snprintf(j->reason, sizeof j->reason, "%s", reason);
    pipeline_store_now(d, j); /* takes the job */
}

static void store_invalid(amfid_ctx *d, const amfi_vehicle_t *m, const char *why)
{
    /* A rejected vehicle is still a stored passage, with the reason; the raw
     * values that failed are in the reason, not in the typed columns. */
    char reason[400]; /* cut to the job's reason by store_refused */
    snprintf(reason, sizeof reason,
             "%.128s (speed_mps %.6g, n_axles %d, utime %lld, reference_gvw_kg %.6g)", why,
             m->speed_mps, m->n_axles, (long long)m->utime, m->reference_gvw_kg);
    store_refused(d, m->vehicle_id, m->utime, m->lane, "invalid", reason);
}

/* 1 when `src` is one of daemon.intake.calibration_sources (comma-separated). */
static int calibration_source(const amfid_ctx *d, const char *src)
{
    const char *list = d->cfg->daemon.calibration_sources;
    const size_t n = src ? strlen(src) : 0;
    if (n == 0)
        return 0;
    for (const char *p = list; *p;) {
        const size_t len = strcspn(p, ",");
        if (len == n && strncmp(p, src, n) == 0)
            return 1;
        p += len;
        if (*p == ',')
            p++;
    }
    return 0;
}

static void on_vehicle(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    amfid_ctx *d = user;
    amfi_vehicle_t m;
    /* A malformed one is not a vehicle we can name: no row (there is no id
     * to store it under); counted per reason and in the status message. */
    if (admit_decode(d, AMFI_MSG_VEHICLE_T, REJECT_VEHICLE, "vehicle_t", rb, ch, &m))
        return;
    I.vehicles_received++;
    const amfi_daemon_config *c = &d->cfg->daemon;
    /* Over the channel's rate: counted and summarised, no row (a flood of
     * refused vehicles once wrote one fsync'd row each). */
    if (!admit_take(d, REJECT_VEHICLE, 1.0)) {
        I.vehicles_rejected++;
        I.invalid_unstored++;
        reject_note(d, REJECT_VEHICLE, REJECT_RATE,
                    "%s: vehicle_t %lld refused: over the channel's rate limit "
                    "(daemon.intake.vehicles_per_s %g)",
                    ch, (long long)m.vehicle_id, c->vehicles_per_s);
        amfi_vehicle_t_decode_cleanup(&m);
        return;
    }
    const char *why = NULL;
    char buf[200], wbuf[160];
    double length_m = 0.0;
    if (!(m.speed_mps >= 1.0 && m.speed_mps <= 60.0))
        why = "speed_mps out of [1, 60]";
    else if (m.n_axles < 1 || m.n_axles > d->cfg->solver.max_axles)
        why = "n_axles out of range for the solver";
    else if (m.n_spacings != m.n_axles - 1)
        why = "n_spacings must be n_axles - 1";
    else if (m.utime <= 0 || m.utime > AMFI_STORE_MAX_UTIME)
        why = "utime out of (0, year 9999]";
    for (int a = 0; !why && a < m.n_spacings; a++)
        if (!(m.axle_spacing_m[a] >= 0.5 && m.axle_spacing_m[a] <= 30.0))
            why = "axle_spacing_m out of [0.5, 30]";
    /* The vehicle as the detector's commissioning says it really was
     * (detector.*, amfi_config_detector_correct, as amfi-solve): entry time on the
     * accelerometers' clock, speed and spacings unscaled. The checks below
     * and the tracker see the corrected vehicle; the stored row keeps the
     * detector's speed beside the one weighed with (docs/daemon.md). */
    int64_t utime = m.utime;
    double speed_mps = m.speed_mps, spacing_m[AMFI_MAX_AXLES];
    if (!why) {
        for (int a = 0; a < m.n_spacings; a++)
            spacing_m[a] = m.axle_spacing_m[a];
        amfi_config_detector_correct(&d->cfg->detector, NULL, &utime, &speed_mps, spacing_m,
                              m.n_spacings);
        for (int a = 0; a < m.n_spacings; a++)
            length_m += spacing_m[a];
        if (utime <= 0)
            why = "utime before 1970 once corrected by detector.clock_offset_s";
    }
    /* Plausible for the span: a crawling or endless "vehicle" would hold the
     * span for every real one around it (one at 1 m/s once made 12 real
     * passages multiple); and not dated past the data (256 dated 2286 once
     * filled the tracker). */
    if (!why && speed_mps < c->min_speed_mps) {
        snprintf(wbuf, sizeof wbuf, "speed_mps %.3g below daemon.intake.min_speed_mps (%g m/s)",
                 speed_mps, c->min_speed_mps);
        why = wbuf;
    } else if (!why && length_m > c->max_length_m) {
        snprintf(wbuf, sizeof wbuf,
                 "first to last axle %.1f m, more than daemon.intake.max_length_m (%g m)",
                 length_m, c->max_length_m);
        why = wbuf;
    } else if (!why && d->newest_utime > 0 &&
               (double)m.utime > (double)d->newest_utime + 1e6 * c->vehicle_ahead_s) {
        snprintf(wbuf, sizeof wbuf,
                 "utime %.0f s past the newest data time ("
                 "daemon.intake.vehicle_ahead_s %g s)",
                 1e-6 * (double)(m.utime - d->newest_utime), c->vehicle_ahead_s);
        why = wbuf;
    }
    /* a calibration truck's reference: 0 or NaN none, else finite in 1 .. 100 t */
    int has_ref = m.reference_gvw_kg != 0.0 && !isnan(m.reference_gvw_kg);
    if (!why && has_ref &&
        !(m.reference_gvw_kg >= AMFI_STORE_MIN_REF_KG && m.reference_gvw_kg <= AMFI_STORE_MAX_REF_KG))
        why = "reference_gvw_kg out of [1000, 100000] kg";
    /* ... taken only from a configured source and within the calibration
     * trucks' range; otherwise the vehicle is weighed without it (a
     * detector that flags every vehicle would mask damage), counted */
    if (!why && has_ref && !calibration_source(d, m.source)) {
        has_ref = 0;
        I.references_refused++;
        reject_note(d, REJECT_VEHICLE, REJECT_SOURCE,
                    "%s: vehicle_t %lld: reference_gvw_kg %.6g not taken: source '%.64s' is not "
                    "in daemon.intake.calibration_sources; weighed without it",
                    ch, (long long)m.vehicle_id, m.reference_gvw_kg, m.source ? m.source : "");
    } else if (!why && has_ref && !(m.reference_gvw_kg >= c->calibration_min_kg &&
                                    m.reference_gvw_kg <= c->calibration_max_kg)) {
        has_ref = 0;
        I.references_refused++;
        reject_note(d, REJECT_VEHICLE, REJECT_IMPLAUSIBLE,
                    "%s: vehicle_t %lld: reference_gvw_kg %.6g not taken: outside "
                    "daemon.intake.calibration_min_kg .. calibration_max_kg (%g .. %g kg); "
                    "weighed without it",
                    ch, (long long)m.vehicle_id, m.reference_gvw_kg, c->calibration_min_kg,
                    c->calibration_max_kg);
    }
    if (!why) {
        amfi_vehicle_ev v, ev;
        memset(&v, 0, sizeof v);
        v.vehicle_id = m.vehicle_id;
        v.utime = utime;
        v.lane = m.lane;
        v.speed_mps = speed_mps;
        v.speed_given_mps = m.speed_mps;
        v.n_axles = m.n_axles;
        for (int a = 0; a < m.n_spacings; a++)
            v.spacing_m[a] = spacing_m[a];
        v.reference_gvw_kg = has_ref ? m.reference_gvw_kg : 0.0;
        const char *twhy = NULL;
        int trc = amfi_tracker_add(I.tracker, &v, &ev, &twhy);
        if (trc < 0) {
            why = twhy;
        } else if (trc == 1) { /* the stalest waiting vehicle made room: stored, never lost */
            I.vehicles_evicted++;
            snprintf(buf, sizeof buf, "%s: vehicle_t %lld %s", ch, (long long)ev.vehicle_id, twhy);
            if (I.vehicles_evicted <= 5)
                LOG_WARN("%s%s", buf, I.vehicles_evicted == 5 ? " (further ones counted)" : "");
            store_refused(d, ev.vehicle_id, ev.utime, ev.lane, "overload", buf);
        }
    }
    if (why) {
        I.vehicles_rejected++;
        snprintf(buf, sizeof buf, "%s: vehicle_t %lld rejected: %s", ch, (long long)m.vehicle_id,
                 why);
        reject_note(d, REJECT_VEHICLE, REJECT_INVALID, "%s", buf);
        store_invalid(d, &m, buf);
    }
    amfi_vehicle_t_decode_cleanup(&m);
}

static void on_truth(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    amfid_ctx *d = user;
    amfi_truth_t m;
    if (admit_decode(d, AMFI_MSG_TRUTH_T, REJECT_TRUTH, "truth_t", rb, ch, &m))
        return;
    char err[256];
    if (!admit_take(d, REJECT_TRUTH, 1.0))
        reject_note(d, REJECT_TRUTH, REJECT_RATE,
                    "%s: truth_t %lld refused: over the channel's rate limit "
                    "(daemon.intake.truth_per_s %g)",
                    ch, (long long)m.vehicle_id, d->cfg->daemon.truth_per_s);
    else if (!(m.gvw_kg > 0 && m.gvw_kg < 1e6) || m.n_axles < 1 || m.n_axles > AMFI_MAX_AXLES)
        reject_note(d, REJECT_TRUTH, REJECT_INVALID,
                    "%s: truth_t %lld rejected: gvw or n_axles out of range", ch,
                    (long long)m.vehicle_id);
    else if (amfi_store_add_truth(d->store, m.vehicle_id, m.utime, m.gvw_kg, m.n_axles,
                                  m.axle_kg, m.mean_force_N, m.speed_true_mps, err, sizeof err))
        reject_note(d, REJECT_TRUTH, REJECT_INVALID, "%s: truth_t %lld: %s", ch,
                    (long long)m.vehicle_id, err);
    else
        I.truth_received++;
    amfi_truth_t_decode_cleanup(&m);
}

/* ---- the module ---------------------------------------------------------- */

/* The detector's corrections in force (the detector's own entry time of a
 * stored passage is its utime plus the offset logged here). */
static void log_detector(const char *when, const amfi_detector_config *dt)
{
    LOG_INFO("%sdetector: entry times corrected by detector.clock_offset_s %g s, speeds and "
             "spacings by detector.speed_scale %g",
             when, dt->clock_offset_s, dt->speed_scale);
}


static int intake_start(amfid_ctx *c, char *err, size_t errlen)
{
    (void)c, (void)err, (void)errlen;
    memset(&I, 0, sizeof I);
    admit_reset();
    return 0;
}

static int intake_restore(amfid_ctx *c)
{
    const amfi_site_config *cfg = c->cfg;
    amfi_tracker_params tp = {cfg->bridge.span_m,
                              cfg->solver.pre_roll_s + cfg->daemon.margin_s,
                              cfg->solver.post_roll_s + cfg->daemon.margin_s,
                              cfg->daemon.max_wait_s, cfg->solver.n_sensors,
                              cfg->daemon.max_event_s, cfg->daemon.max_event_axles,
                              /* room for the speed search, also when a reload
                                 turns it on */
                              amfi_speed_slowest_frac(&cfg->speed_prior),
                              cfg->daemon.natfreq_free_s};
    I.tracker = amfi_tracker_create(&tp);
    if (!I.tracker) {
        LOG_ERR("out of memory at start-up");
        return 1;
    }
    admit_limits(c, cfg); /* the rate limits of the inputs: full buckets */
    if (cfg->detector.clock_offset_s != 0.0 || cfg->detector.speed_scale != 1.0)
        log_detector("", &cfg->detector);
    bus_want(REJECT_ACCEL, cfg->daemon.ch_accel, on_accel);
    bus_want(REJECT_VEHICLE, cfg->daemon.ch_vehicle, on_vehicle);
    /* the truth is a simulation's: in production not even subscribed */
    if (cfg->daemon.simulation)
        bus_want(REJECT_TRUTH, cfg->daemon.ch_truth, on_truth);
    return 0;
}

/* The intake's bounds (daemon.intake.*) apply now, the buckets kept (a
 * lower limit cuts what is left of the allowance); max_wait_s too: the
 * tracker reads its own copy of its parameters. */
static void intake_reload(amfid_ctx *c, const amfi_site_config *old, const amfi_site_config *n)
{
    admit_limits(c, c->cfg);
    amfi_tracker_set_max_wait(I.tracker, c->cfg->daemon.max_wait_s);
    /* the detector's corrections: from the next vehicle admitted on */
    if (old->detector.clock_offset_s != n->detector.clock_offset_s ||
        old->detector.speed_scale != n->detector.speed_scale)
        log_detector("reload: ", &n->detector);
}

static void intake_tick(amfid_ctx *c)
{
    intake_release(c, 0);
}

static void intake_final(amfid_ctx *c)
{
    (void)c;
    if (I.vehicles_evicted + I.references_refused + I.invalid_unstored > 0)
        LOG_INFO("intake: %lld waiting vehicles evicted (stored as overload), %lld calibration "
                 "references not taken, %lld refused vehicles over the rate limit (summarised, "
                 "no row)",
                 (long long)I.vehicles_evicted, (long long)I.references_refused,
                 (long long)I.invalid_unstored);
}

static void intake_metrics(amfid_ctx *c, amfid_stats *s)
{
    s->blocks_received = I.blocks_received;
    s->blocks_rejected = I.blocks_rejected;
    s->vehicles_received = I.vehicles_received;
    s->vehicles_rejected = I.vehicles_rejected;
    s->truth_received = I.truth_received;
    s->vehicles_evicted = I.vehicles_evicted;
    s->references_refused = I.references_refused;
    s->invalid_unstored = I.invalid_unstored;
    s->samples_missing = s->ring_rejected = 0;
    for (int i = 0; i < c->cfg->solver.n_sensors; i++)
        if (I.rings[i]) {
            const amfi_ring_stats *st = amfi_ring_stats_of(I.rings[i]);
            s->samples_missing += st->missing;
            s->ring_rejected += st->late + st->duplicates;
        }
    admit_stats(s);
}

static void intake_stop(amfid_ctx *c)
{
    (void)c;
    for (int i = 0; i < AMFI_MAX_SENSORS; i++)
        amfi_ring_destroy(I.rings[i]);
    amfi_tracker_destroy(I.tracker);
    memset(&I, 0, sizeof I);
}

const amfid_module intake_module = {
    .name = "intake",
    .start = intake_start,
    .restore = intake_restore,
    .reload = intake_reload,
    .tick = intake_tick,
    .metrics = intake_metrics,
    .final = intake_final,
    .stop = intake_stop,
};
