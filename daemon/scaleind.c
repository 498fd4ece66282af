/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * scaleind.c: amfid's scale indicator and known-truck runs (issue 14,
 * docs/indicators.md section 8). Each solved passage gets the deck
 * temperature at its data time from the environment readings (buffered ones
 * flushed to the store first; amfi_store_deck_c_at within
 * alerts.scale.max_temp_gap_s), stored with it (passages.deck_c). Each ok
 * passage with a temperature then feeds the scale indicator
 * (indicators/scale.h: GVW and temperature) and, when its vehicle carried a
 * reference GVW (a calibration truck), the known-truck indicator
 * (indicators/known_truck.h). Their evaluations are stored (scale_evals),
 * their raise and clear events go out like every alert (the context's
 * emit_alert). A passage without a temperature feeds neither: counted
 * (status line at stop, metrics).
 *
 * The STD and mean rules (pipeline.c) are fed each GVW brought to the
 * calibration temperature by the same temperature model
 * (daemon.indicators.temperature: compensated, docs/indicators.md 8.8); the
 * weight fed is stored with the passage (passages.gvw_comp_kg), which is
 * what their rolling window is refilled from at a restart.
 *
 * Restore: at start both indicators are rebuilt by replaying the stored
 * inputs (the ok passages with a deck temperature, in id order, through the
 * same filter), so the baseline, the temperature model, the partial block
 * and the CUSUM's evidence survive a restart exactly; the replay stores
 * and publishes nothing. An alert open in the store stays open (not raised
 * twice); one the store does not have open is not held.
 *
 * A module (ctx.h): row gives a solved passage its deck temperature and
 * its compensated weight, on_passage feeds both indicators.
 *
 * Thread: the main thread only. Owns the two indicators, their parameters
 * in force and the counters; a reload reports a change, which applies at
 * the next start.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx.h"
#include "known_truck.h"
#include "scale.h"

static struct scale_state {
    amfi_scale *scale;             /* NULL: alerts.scale.enabled off */
    amfi_known_truck *truck;       /* NULL: alerts.known_truck.enabled off */
    int enabled, truck_enabled;    /* in force (a reload reports changes) */
    int compensate;                /* daemon.indicators.temperature: compensated */
    double max_gap_s;
    amfi_scale_params params;
    amfi_known_truck_params truck_params;
    int64_t fed, no_temp, runs, refused; /* this run's: inputs, solved passages
                                    without a temperature, truck runs, refused */
    int64_t comp_fed, comp_raw;    /* this run's passages fed to the STD and mean
                                    rules compensated, and raw for want of a
                                    deck temperature (compensate on) */
    double last_scale, last_cusum; /* the newest block's (NaN: none yet) */
} S;

static int scaleind_start(amfid_ctx *d, char *err, size_t errlen)
{
    struct scale_state *c = &S;
    memset(c, 0, sizeof *c);
    const amfi_daemon_config *dc = &d->cfg->daemon;
    c->enabled = dc->scale_enabled;
    c->truck_enabled = dc->known_truck_enabled;
    c->compensate = dc->ind_temp_compensated;
    c->max_gap_s = dc->scale_max_temp_gap_s;
    c->params = dc->scale;
    c->truck_params = dc->known_truck;
    c->last_scale = c->last_cusum = NAN;
    int rc = 0;
    if (c->enabled)
        rc = amfi_scale_create(&c->params, &c->scale, err, errlen);
    if (rc == 0 && c->truck_enabled)
        rc = amfi_known_truck_create(&c->truck_params, &c->params, &c->truck, err, errlen);
    return rc;
}

/* A stored value in the scale_evals ranges, else unknown. */
static double ratio_or_nan(double x)
{
    return isfinite(x) && x > 0 && x <= 100 ? x : NAN;
}

static void store_eval(amfid_ctx *d, const amfi_scale_eval_row *r)
{
    char err[256];
    if (amfi_store_add_scale_eval(d->store, r, NULL, err, sizeof err))
        ctx_error(d, "store: %s", err);
}

/* The baseline was just fitted: the known truck takes its slopes. */
static void baseline_fitted(amfid_ctx *d, int64_t utime, int live)
{
    struct scale_state *c = &S;
    amfi_scale_model m;
    if (amfi_scale_get_model(c->scale, &m) != 0)
        return;
    if (c->truck)
        amfi_known_truck_set_slopes(c->truck, m.warm_slope, m.frost_slope);
    if (!live)
        return;
    LOG_INFO("scale indicator: baseline of %d blocks fitted: loaded share %.3f, slopes %.5f "
             "(warm) and %.5f (frost) per °C over %.1f .. %.1f °C, block SD %.4f, CUSUM k %.2f "
             "h %.2f",
             c->params.baseline_blocks, m.pi, m.warm_slope, m.frost_slope, m.t_min_c, m.t_max_c,
             m.sigma0, m.k_ref, m.h);
    amfi_scale_eval_row r = {utime, "scale_shift", c->params.block * c->params.baseline_blocks,
                             1.0, 1.0, NAN, NAN, NAN, m.h, "baseline"};
    store_eval(d, &r);
}

/* One input into both indicators; live: store, publish and count. */
static void push(amfid_ctx *d, int64_t utime, double gvw_kg, double deck_c, double ref_kg,
                 int live)
{
    struct scale_state *c = &S;
    amfi_alert_event al;
    if (c->scale) {
        amfi_scale_eval ev;
        int bits = amfi_scale_push(c->scale, gvw_kg, deck_c, &ev, &al);
        if (bits < 0) {
            c->refused++;
            if (live)
                ctx_error(d, "scale indicator: GVW %.1f kg at deck %.2f °C refused", gvw_kg,
                          deck_c);
        } else {
            c->fed++;
            if (bits & AMFI_IND_BASELINE)
                baseline_fitted(d, utime, live);
            if (bits & AMFI_IND_EVAL) {
                c->last_scale = ev.scale;
                c->last_cusum = ev.cusum;
                if (live) {
                    amfi_scale_eval_row r = {utime, "scale_shift", ev.n, ratio_or_nan(ev.scale),
                                             ratio_or_nan(ev.raw_scale), ev.deck_mean_c, ev.z,
                                             ev.cusum, ev.h, ev.state};
                    store_eval(d, &r);
                }
            }
            if ((bits & AMFI_IND_ALERT) && live)
                d->emit_alert(d, utime, &al, 0);
        }
    }
    if (c->truck && isfinite(ref_kg) && ref_kg > 0) {
        amfi_known_truck_eval ev;
        int bits = amfi_known_truck_push(c->truck, gvw_kg, ref_kg, deck_c, &ev, &al);
        if (bits < 0) {
            c->refused++;
            if (live)
                ctx_error(d, "known truck: GVW %.1f kg against reference %.1f kg refused",
                          gvw_kg, ref_kg);
            return;
        }
        c->runs++;
        if (live) {
            int base = strcmp(ev.state, "baseline") == 0;
            amfi_scale_eval_row r = {utime, "known_truck", ev.run, ratio_or_nan(ev.ratio_comp),
                                     ratio_or_nan(ev.ratio), deck_c, base ? NAN : ev.z,
                                     base ? NAN : ev.cusum, base ? NAN : ev.h, ev.state};
            store_eval(d, &r);
            LOG_INFO("known truck: run %d, ratio %.4f (%.4f at %.1f °C), %s", ev.run,
                     ev.ratio_comp, ev.ratio, deck_c, ev.state);
            if (bits & AMFI_IND_ALERT)
                d->emit_alert(d, utime, &al, 0);
        }
    }
}

static int wanted(const amfid_ctx *d, int n_vehicles)
{
    return !d->cfg->daemon.single_presence_only || n_vehicles <= 1;
}

static int restore_open(amfid_ctx *d, const char *kind)
{
    char err[256];
    int open = 0;
    if (amfi_store_alert_open(d->store, kind, &open, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        open = 0;
    }
    metrics_alert(kind, open);
    return open;
}

static int scaleind_restore(amfid_ctx *d)
{
    struct scale_state *c = &S;
    if (!c->scale && !c->truck)
        return 0;
    char err[512];
    int64_t after = 0;
    int64_t replayed = 0;
    for (;;) {
        amfi_scale_input *in = NULL;
        size_t n = 0;
        if (amfi_store_scale_inputs(d->store, after, 4096, &in, &n, err, sizeof err) != 0) {
            LOG_WARN("store: %s (the scale indicator starts from what was read)", err);
            break;
        }
        for (size_t k = 0; k < n; k++)
            if (wanted(d, in[k].n_vehicles)) {
                push(d, in[k].utime, in[k].gvw_kg, in[k].deck_c, in[k].reference_gvw_kg, 0);
                replayed++;
            }
        if (n > 0)
            after = in[n - 1].id;
        free(in);
        if (n < 4096)
            break;
    }
    int open_s = 0, open_t = 0;
    if (c->scale) {
        open_s = restore_open(d, "scale_shift");
        amfi_scale_set_alerted(c->scale, open_s);
    }
    if (c->truck) {
        open_t = restore_open(d, "known_truck");
        amfi_known_truck_set_alerted(c->truck, open_t);
    }
    if (replayed > 0 || open_s || open_t)
        LOG_INFO("scale indicator: %lld passages replayed from the store (%s, %lld known-truck "
                 "runs)%s%s",
                 (long long)replayed, c->scale ? amfi_scale_state(c->scale) : "off",
                 (long long)c->runs, open_s ? "; the scale_shift alert is open" : "",
                 open_t ? "; the known_truck alert is open" : "");
    c->fed = c->runs = c->refused = 0; /* the counters are this run's */
    return 0;
}

static void scaleind_deck(amfid_ctx *d, amfi_passage_row *r)
{
    struct scale_state *c = &S;
    r->has_deck_c = 0;
    if (!c->scale && !c->truck && !c->compensate)
        return;
    double t = environment_deck_at(d, r->utime, c->max_gap_s);
    if (isfinite(t)) {
        r->has_deck_c = 1;
        r->deck_c = t;
    } else {
        c->no_temp++;
    }
}

/* A compensation factor outside this range is not used (the passage feeds
 * its raw GVW, counted): the model's own range at -60 .. 80 °C with the
 * prior slopes is 0.84 .. 1.18. */
#define COMP_FACTOR_MIN 0.5
#define COMP_FACTOR_MAX 2.0

static void scaleind_comp(amfi_passage_row *r)
{
    struct scale_state *c = &S;
    r->gvw_comp_kg = r->gvw_kg;
    if (!c->compensate)
        return;
    double f = NAN;
    if (r->has_deck_c) {
        double warm = c->params.warm_slope, frost = c->params.frost_slope;
        amfi_scale_model m;
        if (c->scale && amfi_scale_get_model(c->scale, &m) == AMFI_IND_OK) {
            warm = m.warm_slope;
            frost = m.frost_slope;
        }
        f = amfi_scale_temp_factor(&c->params, warm, frost, r->deck_c);
    }
    if (isfinite(f) && f >= COMP_FACTOR_MIN && f <= COMP_FACTOR_MAX) {
        r->gvw_comp_kg = r->gvw_kg * f;
        c->comp_fed++;
    } else {
        c->comp_raw++;
    }
}

static void scaleind_feed(amfid_ctx *d, const amfid_passage *p)
{
    const amfi_passage_row *r = p->r;
    if (!p->j->solved || strcmp(p->j->status, "ok") != 0)
        return;
    if (!r->has_deck_c || !wanted(d, r->n_vehicles))
        return;
    push(d, r->utime, r->gvw_kg, r->deck_c,
         r->reference_gvw_kg != 0.0 ? r->reference_gvw_kg : NAN, 1);
}




static void scaleind_final(amfid_ctx *d)
{
    (void)d;
    const struct scale_state *c = &S;
    if (c->compensate && (c->comp_fed > 0 || c->comp_raw > 0))
        LOG_INFO("STD and mean rules: %lld passages fed at the calibration temperature "
                 "(%.1f °C), %lld raw (no deck temperature within %.0f s)",
                 (long long)c->comp_fed, c->params.ref_c, (long long)c->comp_raw, c->max_gap_s);
    if (!c->scale && !c->truck)
        return;
    LOG_INFO("scale indicator: %lld passages fed (%s), %lld solved passages without a deck "
             "temperature within %.0f s (skipped), %lld known-truck runs, %lld refused",
             (long long)c->fed, c->scale ? amfi_scale_state(c->scale) : "off",
             (long long)c->no_temp, c->max_gap_s, (long long)c->runs, (long long)c->refused);
}

static void scaleind_stop(amfid_ctx *d)
{
    (void)d;
    amfi_scale_destroy(S.scale);
    amfi_known_truck_destroy(S.truck);
    memset(&S, 0, sizeof S);
}

/* A solved passage's row: its deck temperature (scaleind_deck) and, when it
 * feeds the STD and mean rules, the weight they are fed (scaleind_comp). */
static void scaleind_row(amfid_ctx *d, const amfid_passage *p, amfi_passage_row *r)
{
    if (!p->j->solved)
        return;
    scaleind_deck(d, r);
    if (p->feeds)
        scaleind_comp(r);
}

static void scaleind_metrics(amfid_ctx *d, amfid_stats *s)
{
    (void)d;
    s->last_scale = S.last_scale;
    s->last_cusum = S.last_cusum;
    s->scale_fed = S.fed;
    s->scale_no_temp = S.no_temp;
}

void scaleind_view_of(scaleind_view *v)
{
    v->scale_state = S.scale ? amfi_scale_state(S.scale) : NULL;
    v->truck_state = S.truck ? amfi_known_truck_state(S.truck) : NULL;
    v->fed = S.fed;
    v->no_temp = S.no_temp;
    v->comp_fed = S.comp_fed;
    v->comp_raw = S.comp_raw;
    v->compensate = S.compensate;
    amfi_scale_model m;
    v->fitted = S.scale && amfi_scale_get_model(S.scale, &m) == AMFI_IND_OK;
    v->warm_slope = v->fitted ? m.warm_slope : NAN;
    v->frost_slope = v->fitted ? m.frost_slope : NAN;
}

const amfid_module scaleind_module = {
    .name = "scaleind",
    .section = "alerts.scale / alerts.known_truck",
    .start = scaleind_start,
    .restore = scaleind_restore,
    .row = scaleind_row,
    .on_passage = scaleind_feed,
    .metrics = scaleind_metrics,
    .final = scaleind_final,
    .stop = scaleind_stop,
};
