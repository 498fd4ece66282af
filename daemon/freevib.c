/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * freevib.c: amfid's natural-frequency feature (issue 14, item 4): the
 * bridge's first natural frequency from each passage's free vibration
 * after the last axle left (the tracker hands on free_s of samples, cut at
 * the next vehicle's entry: tracker.h), estimated when the window is
 * released (indicators/natfreq.h, on every sensor; the one with the
 * smallest relative standard error is kept), stored with the passage
 * (passages.f1_hz, f1_zeta, f1_r2) and, once the baseline's fit against
 * the deck temperature exists, compensated to the calibration temperature
 * (f1_comp_hz). A refused estimate is stored as NULL and counted by its
 * reason (logged at stop, in the store's meta table as natfreq.*). On an
 * event of several vehicles, the vehicle that leaves last carries it.
 *
 * The deck temperature is the store's (amfi_store_deck_c_at) at the
 * passage's time (readings up to alerts.scale.max_temp_gap_s apart, as for
 * the scale indicator), the readings received so far flushed first. The
 * baseline is the first daemon.natural_frequency.baseline_n estimates with
 * a temperature; after a restart it is read back from the store (the same
 * estimates; a temperature interpolated then where only the reading before
 * was known live can move the fit slightly).
 *
 * A module (ctx.h): restore refills the baseline, row fills the f1
 * columns, on_passage collects the baseline, a 60 s timer (and final)
 * writes the counters into the store's meta table.
 *
 * Thread: the main thread only. Owns the compensation and the counters;
 * the estimate reads the rings it is handed (the intake's).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx.h"

static struct freevib_state {
    amfi_natfreq_comp *comp;  /* NULL: off (free_s 0) or not compensated */
    int64_t estimated;        /* passages with an f1 */
    int64_t no_segment;       /* ok passages without free vibration (cut, data missing) */
    int64_t refused[AMFI_NATFREQ_NREFUSALS]; /* by amfi_natfreq_estimate's code; [0] invalid */
    int64_t no_temperature;   /* baseline candidates without a deck temperature */
    amfi_natfreq_params est;  /* the estimator's: the site's, the band the followed mode's */
    double f_mode_hz;         /* the site model's frequency of that mode; NaN: none followed */
} F;

/* At start (the baseline from the store): readings at most
 * alerts.scale.max_temp_gap_s apart are interpolated for a
 * passage's deck temperature (amfi_store_deck_c_at), as for the scale
 * indicator's; µs of data time. */
static const double record_period_s = 60.0;
static int freevib_tick(amfid_ctx *c);

static int64_t deck_gap_us(const amfid_ctx *d)
{
    return (int64_t)llround(1e6 * d->cfg->daemon.scale_max_temp_gap_s);
}

static int freevib_restore(amfid_ctx *d)
{
    char err[256];
    struct freevib_state *fv = &F;
    if (!(d->cfg->daemon.natfreq_free_s > 0))
        return 0;
    if (d->cfg->daemon.natfreq_mode > 0)
        LOG_INFO("natural frequency: following the site model's mode %d (%.4f Hz), its peak "
                 "searched in %.3f .. %.3f Hz",
                 d->cfg->daemon.natfreq_mode, fv->f_mode_hz, fv->est.f_lo_hz, fv->est.f_hi_hz);
    /* the site's temperature model: alerts.scale's knee, floor, calibration
     * temperature and prior slopes (halved and turned for f1 by natfreq.c) */
    if (amfi_natfreq_comp_create(&d->cfg->daemon.scale, d->cfg->daemon.natfreq_baseline_n,
                                 &fv->comp, err, sizeof err) != 0) {
        LOG_WARN("natural frequency: %s: not compensated for temperature", err);
        return 0;
    }
    amfi_f1_rec *a = NULL;
    size_t n = 0;
    if (amfi_store_f1_series(d->store, 0, AMFI_STORE_MAX_UTIME, 0, &a, &n, err, sizeof err)) {
        LOG_WARN("store: %s", err);
        return 0;
    }
    int used = 0, fitted = 0;
    for (size_t k = 0; k < n && !fitted; k++) {
        double t = NAN;
        if (amfi_store_deck_c_at(d->store, a[k].utime, deck_gap_us(d), &t, err, sizeof err) ||
            !isfinite(t))
            continue;
        used++;
        fitted = amfi_natfreq_comp_push(fv->comp, a[k].f1_hz, t) == 1;
    }
    free(a);
    amfi_natfreq_model m;
    if (amfi_natfreq_comp_model(fv->comp, &m))
        LOG_INFO("natural frequency: baseline from the store: %d estimates, f1 %.4f Hz at the "
                 "calibration temperature, slopes %.5f (warm) and %.5f (frost) /°C",
                 m.n, m.f_ref_hz, m.warm, m.frost);
    else if (used > 0)
        LOG_INFO("natural frequency: %d of %d baseline estimates from the store", used,
                 d->cfg->daemon.natfreq_baseline_n);
    return timer_add(d->timers, &record_period_s, freevib_tick) ? 1 : 0;
}


static void freevib_stop(amfid_ctx *c)
{
    (void)c;
    amfi_natfreq_comp_destroy(F.comp);
    memset(&F, 0, sizeof F);
}

/* The event's vehicle that leaves the span last (at its measured speed). */
static int64_t last_out(const amfid_ctx *d, const amfi_window *w)
{
    int64_t id = w->v.vehicle_id;
    double latest = -INFINITY;
    for (int i = 0; i < w->n_vehicles; i++) {
        const amfi_vehicle_ev *v = &w->ev[i];
        const amfi_passage_times pt = amfi_passage_window(d->cfg->bridge.span_m, v->speed_mps,
                                                          v->n_axles, v->spacing_m, 0.0, 0.0);
        const double out = (double)v->utime + 1e6 * pt.on_span_s;
        if (out > latest) {
            latest = out;
            id = v->vehicle_id;
        }
    }
    return id;
}

void freevib_estimate(amfid_ctx *d, job *j, amfi_ring *const *rings)
{
    struct freevib_state *fv = &F;
    j->f1_hz = j->f1_zeta = j->f1_r2 = NAN;
    j->f1_vehicle_id = j->w.v.vehicle_id;
    if (!(d->cfg->daemon.natfreq_free_s > 0) || strcmp(j->w.status, "ok") != 0)
        return;
    j->f1_vehicle_id = last_out(d, &j->w);
    const int n = j->w.free_n;
    if (n < 8) {
        fv->no_segment++;
        return;
    }
    double *x = malloc(sizeof(double) * (size_t)n);
    if (!x) {
        ctx_error(d, "natural frequency: out of memory for %d samples", n);
        return;
    }
    amfi_natfreq_result best;
    memset(&best, 0, sizeof best);
    int have = 0, first_code = AMFI_NATFREQ_EINVAL;
    for (int s = 0; s < j->n_sensors; s++) {
        if (!rings[s] || amfi_ring_get(rings[s], j->w.free_k0[s], n, x) != 0)
            continue;
        amfi_natfreq_result r;
        const int code = amfi_natfreq_estimate(x, n, amfi_ring_rate(rings[s]), &fv->est, &r);
        if (s == 0 || first_code == AMFI_NATFREQ_EINVAL)
            first_code = code;
        if (code == AMFI_NATFREQ_OK &&
            (!have || r.f1_se_hz / r.f1_hz < best.f1_se_hz / best.f1_hz)) {
            best = r;
            have = 1;
        }
    }
    free(x);
    if (!have) {
        fv->refused[first_code > 0 && first_code < AMFI_NATFREQ_NREFUSALS ? first_code : 0]++;
        return;
    }
    fv->estimated++;
    j->f1_hz = best.f1_hz;
    j->f1_zeta = best.zeta;
    j->f1_r2 = best.r2;
}

/* The deck temperature at utime, or NaN (environment_deck_at). */
static double deck_at(amfid_ctx *d, int64_t utime)
{
    return environment_deck_at(d, utime, d->cfg->daemon.scale_max_temp_gap_s);
}

int freevib_reference(double *f_ref_hz)
{
    amfi_natfreq_model m;
    if (!F.comp || !amfi_natfreq_comp_model(F.comp, &m) || !(m.f_ref_hz > 0))
        return 0;
    *f_ref_hz = m.f_ref_hz;
    return 1;
}

double freevib_time_scale(amfid_ctx *d, int64_t utime)
{
    const double t = deck_at(d, utime);
    if (!isfinite(t))
        return 1.0;
    amfi_natfreq_model m;
    double warm = -0.5 * d->cfg->daemon.scale.warm_slope, frost = -0.5 * d->cfg->daemon.scale.frost_slope;
    if (F.comp && amfi_natfreq_comp_model(F.comp, &m))
        warm = m.warm, frost = m.frost;
    const double k = amfi_scale_temp_factor(&d->cfg->daemon.scale, warm, frost, t);
    return k > 0.5 && k < 2.0 ? 1.0 / k : 1.0;
}

/* Whether this row (of an event: one vehicle's) carries the f1. */
static int carries(const job *j)
{
    return j->w.v.vehicle_id == j->f1_vehicle_id && j->f1_hz > 0;
}

static void freevib_row(amfid_ctx *d, const amfid_passage *p, amfi_passage_row *r)
{
    const job *j = p->j;
    r->f1_hz = r->f1_comp_hz = r->f1_zeta = r->f1_r2 = NAN;
    if (!carries(j))
        return;
    r->f1_hz = j->f1_hz;
    r->f1_zeta = j->f1_zeta;
    r->f1_r2 = j->f1_r2;
    if (F.comp) {
        amfi_natfreq_model m;
        if (amfi_natfreq_comp_model(F.comp, &m))
            r->f1_comp_hz = amfi_natfreq_comp_apply(F.comp, j->f1_hz, deck_at(d, j->w.v.utime));
    }
}

static void freevib_stored(amfid_ctx *d, const amfid_passage *p)
{
    const job *j = p->j;
    struct freevib_state *fv = &F;
    amfi_natfreq_model m;
    if (!carries(j) || !fv->comp || amfi_natfreq_comp_model(fv->comp, &m))
        return;
    const double t = deck_at(d, j->w.v.utime);
    if (!isfinite(t)) {
        fv->no_temperature++;
        return;
    }
    if (amfi_natfreq_comp_push(fv->comp, j->f1_hz, t) == 1 &&
        amfi_natfreq_comp_model(fv->comp, &m))
        LOG_INFO("natural frequency: baseline of %d estimates (deck %.1f .. %.1f °C): f1 %.4f Hz "
                 "at the calibration temperature, SD %.2f %%, slopes %.5f (warm) and %.5f "
                 "(frost) /°C",
                 m.n, m.t_min_c, m.t_max_c, m.f_ref_hz, 100 * m.sd_rel, m.warm, m.frost);
}

/* The counters and their names (natfreq.<name> in the meta table, and the
 * log), "estimated" first: how many, or 0 when the feature is off. */
#define N_COUNTERS (AMFI_NATFREQ_NREFUSALS + 3)
static int counters(const amfid_ctx *d, const char **name, long long *v)
{
    const struct freevib_state *fv = &F;
    if (!(d->cfg->daemon.natfreq_free_s > 0))
        return 0;
    int k = 0;
    name[k] = "estimated", v[k++] = (long long)fv->estimated;
    name[k] = "no_free_vibration", v[k++] = (long long)fv->no_segment;
    for (int c = 1; c < AMFI_NATFREQ_NREFUSALS; c++)
        name[k] = amfi_natfreq_code_name(c), v[k++] = (long long)fv->refused[c];
    name[k] = "invalid", v[k++] = (long long)fv->refused[0];
    name[k] = "no_temperature", v[k++] = (long long)fv->no_temperature;
    return k;
}

static void freevib_record(amfid_ctx *d)
{
    const char *name[N_COUNTERS];
    long long v[N_COUNTERS];
    const int n = counters(d, name, v);
    char key[64], val[32], err[256];
    for (int i = 0; i < n; i++) {
        snprintf(key, sizeof key, "natfreq.%s", name[i]);
        snprintf(val, sizeof val, "%lld", v[i]);
        if (amfi_store_meta_set(d->store, key, val, err, sizeof err) != 0) {
            ctx_error(d, "store: %s", err);
            return;
        }
    }
}

static void freevib_final(amfid_ctx *d)
{
    if (!pipeline_degraded())
        freevib_record(d);
    const char *name[N_COUNTERS];
    long long v[N_COUNTERS];
    const int n = counters(d, name, v);
    char line[512] = "";
    size_t at = 0;
    for (int i = 1; i < n && at < sizeof line; i++)
        at += (size_t)snprintf(line + at, sizeof line - at, "%s%s %lld", i > 1 ? ", " : "",
                               name[i], v[i]);
    if (n > 0)
        LOG_INFO("natural frequency: %lld passages estimated; not: %s", v[0], line);
}

/* The counters into the meta table with the intake record (status.c), every
 * 60 s and not while the store refuses writes (tried at each turn then). */
static int freevib_tick(amfid_ctx *c)
{
    if (pipeline_degraded())
        return 1;
    freevib_record(c);
    return 0;
}

static int freevib_start(amfid_ctx *c, char *err, size_t errlen)
{
    memset(&F, 0, sizeof F);
    const amfi_daemon_config *dc = &c->cfg->daemon;
    double f = NAN;
    if (!(dc->natfreq_free_s > 0))
        return 0;
    /* the site model's mode followed: its peak in a band around it
     * (natfreq.h, amfi_natfreq_follow) */
    if (amfi_natfreq_follow(&dc->natfreq, amfi_bridge_omega(c->bridge), amfi_bridge_ndof(c->bridge),
                            dc->natfreq_mode, dc->natfreq_band, &F.est, &f, err, errlen) != 0)
        return 1;
    F.f_mode_hz = f;
    return 0;
}

const amfid_module freevib_module = {
    .name = "freevib",
    .start = freevib_start,
    .restore = freevib_restore,
    .row = freevib_row,
    .on_passage = freevib_stored,
    .final = freevib_final,
    .stop = freevib_stop,
};
