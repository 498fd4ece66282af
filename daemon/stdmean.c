/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * stdmean.c: amfid's STD and mean rules (indicators/indicators.h,
 * daemon.indicators): every ok passage that feeds them (single presence
 * when daemon.indicators.single_presence_only) pushes its GVW, at the
 * calibration temperature where it is compensated (scaleind.c fills
 * gvw_comp_kg); the baseline, each evaluation and the alerts are stored and
 * published (the evaluation on the indicator channel, the alerts through
 * the context's emit_alert) and the newest evaluation goes to the metrics.
 * At start the baseline, the window's GVWs and the open alerts come back
 * from the store (an alert open before a restart stays open, not raised
 * twice), and the parameters in force are recorded in meta
 * (daemon.indicators) for the reports. A baseline written into the store while amfid runs (amfi-report
 * --set-baseline*) is applied without a restart: a timer compares the
 * store's newest baseline row with the one in force every
 * BASELINE_POLL_S seconds.
 *
 * daemon.indicators.classes and min_gvw_kg restrict the passages that feed
 * the rules to some classes (passages.class, classes.c) and to a weight fed
 * of at least min_gvw_kg; the automatic baseline (its note names the
 * filter), the window refilled at start (amfi_store_recent_fed_gvw) and
 * the live feed take the same passages. An automatic baseline whose note
 * names another filter is not applied at start: the rules collect a new
 * one. The passages fed and those left out are counted and logged at the
 * end.
 *
 * A module (ctx.h). Thread: the main thread only. Owns the engine and its
 * parameters in force (a reload reports a change, which applies at the
 * next start).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_classify.h"
#include "amfi_indicator_t.h"
#include "ctx.h"

/* How often the store's newest baseline is compared with the one in force. */
#define BASELINE_POLL_S 2.0
static const double baseline_poll_s = BASELINE_POLL_S;

static struct {
    amfi_indicators *ind;
    amfi_indicator_params params; /* in force */
    amfi_baseline applied;        /* the store's baseline row in force (or seen) */
    int has_applied;
    /* daemon.indicators.classes, min_gvw_kg (in force: restart-only) */
    unsigned cls_mask;                        /* bit: amfi_class_index; 0 every class */
    int n_cls;
    char cls_name[32][AMFI_CLASS_NAME_LEN];
    double min_kg;
    char filter_text[160];                    /* " of classes A23 from 25000 kg"; "" none */
    long long fed, not_class, below_min;
} M;

/* The automatic baseline's note: what it was collected from (cut to the
 * note's length, the same cut when it is written and when it is compared). */
static void auto_note(char *buf, size_t len, int n)
{
    const int w = snprintf(buf, len, "first %d ok passages", n);
    if (w > 0 && (size_t)w < len)
        snprintf(buf + w, len - (size_t)w, "%.*s", (int)(len - (size_t)w - 1), M.filter_text);
}

/* 1 when the stored passage p passes daemon.indicators.classes and min_gvw_kg
 * (counted). */
static int passes_filter(const amfid_passage *p)
{
    if (M.cls_mask) {
        const char *v = p->r->vclass;
        int k = -1;
        for (int i = 0; v && i < M.n_cls && k < 0; i++)
            if (strcmp(v, M.cls_name[i]) == 0)
                k = i;
        if (k < 0) {
            M.not_class++;
            return 0;
        }
    }
    if (p->r->gvw_comp_kg < M.min_kg) {
        M.below_min++;
        return 0;
    }
    M.fed++;
    return 1;
}

static int same_baseline(const amfi_baseline *a, const amfi_baseline *b)
{
    return a->utime_set == b->utime_set && a->n == b->n && a->mean_kg == b->mean_kg
           && a->std_kg == b->std_kg && strcmp(a->source, b->source) == 0
           && strcmp(a->note, b->note) == 0;
}

/* The timer: a newer baseline row in the store (amfi-report --set-baseline*)
 * replaces the one in force; the rules start counting afresh against it. */
static int baseline_tick(amfid_ctx *c)
{
    amfi_baseline b;
    int found = 0;
    char err[512];
    if (amfi_store_get_baseline(c->store, &b, &found, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return 0;
    }
    if (!found || (M.has_applied && same_baseline(&b, &M.applied)))
        return 0;
    if (amfi_indicators_set_baseline(M.ind, b.mean_kg, b.std_kg, b.n) != 0) {
        LOG_WARN("store: baseline mean %.0f kg, STD %.0f kg, n %d (%s) refused by the rules",
                 b.mean_kg, b.std_kg, b.n, b.source);
    } else {
        LOG_INFO("baseline changed in the store, applied: mean %.0f kg, STD %.0f kg (%d, %s%s%s)",
                 b.mean_kg, b.std_kg, b.n, b.source, b.note[0] ? ": " : "", b.note);
    }
    M.applied = b;
    M.has_applied = 1;
    return 0;
}

static int stdmean_start(amfid_ctx *c, char *err, size_t errlen)
{
    memset(&M, 0, sizeof M);
    M.params = c->cfg->daemon.indicators;
    /* the class filter: names checked by the loader (section_daemon.c) */
    const char *s = c->cfg->daemon.ind_classes;
    size_t n = 0;
    for (const char *p = s; *p && M.n_cls < 32;) {
        const size_t len = strcspn(p, ",");
        snprintf(M.cls_name[M.n_cls], sizeof M.cls_name[M.n_cls], "%.*s", (int)len, p);
        const int k = amfi_class_index(c->cfg->classes.scheme, M.cls_name[M.n_cls]);
        if (k < 0) {
            snprintf(err, errlen, "daemon.indicators.classes: '%s' is not a class",
                     M.cls_name[M.n_cls]);
            return 1;
        }
        M.cls_mask |= 1u << k;
        n += (size_t)snprintf(M.filter_text + n, n < sizeof M.filter_text ? sizeof M.filter_text - n : 0,
                              "%s%s", M.n_cls ? "," : " of classes ", M.cls_name[M.n_cls]);
        M.n_cls++;
        p += len;
        if (*p == ',')
            p++;
    }
    M.min_kg = c->cfg->daemon.ind_min_gvw_kg;
    if (M.min_kg > 0 && n < sizeof M.filter_text)
        snprintf(M.filter_text + n, sizeof M.filter_text - n, " from %.0f kg", M.min_kg);
    return amfi_indicators_create(&M.params, &M.ind, err, errlen);
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

/* The baseline, the window's GVWs and the open alerts from the store; the
 * baseline's timer. */
static int stdmean_restore(amfid_ctx *c)
{
    amfi_baseline b;
    int found = 0;
    char err[512];
    if (timer_add(c->timers, &baseline_poll_s, baseline_tick) != 0)
        return 1;
    /* what this run's rules use, for the reports (meta daemon.indicators;
     * a reload does not change them: they apply at the next start) */
    char params[1024];
    snprintf(err, sizeof err, "the text is longer than %zu bytes", sizeof params);
    if (amfi_indicator_params_format(&M.params, params, sizeof params) != 0
        || amfi_store_meta_set(c->store, "daemon.indicators", params, err, sizeof err) != 0)
        LOG_WARN("store: the indicator parameters not recorded: %s", err);
    snprintf(params, sizeof params, "classes=%s min_gvw_kg=%.17g", c->cfg->daemon.ind_classes,
             M.min_kg);
    if (amfi_store_meta_set(c->store, "daemon.indicators.classes", params, err, sizeof err) != 0)
        LOG_WARN("store: the indicators' class filter not recorded: %s", err);
    if (amfi_store_get_baseline(c->store, &b, &found, err, sizeof err) != 0) {
        LOG_WARN("store: %s", err);
        return 0;
    }
    if (!found)
        return 0;
    char note[sizeof b.note];
    auto_note(note, sizeof note, b.n);
    /* filtered: the note must name this filter; pooled: any automatic
     * baseline but one whose note names a filter (notes of older versions
     * or of other tools are taken as before) */
    const int other = M.filter_text[0] ? strcmp(b.note, note) != 0
                                       : strstr(b.note, " ok passages of classes ") != NULL ||
                                             strstr(b.note, " ok passages from ") != NULL;
    if (strcmp(b.source, "auto") == 0 && other) {
        /* collected from other passages (another class filter): seen, not
         * applied; the timer leaves it be */
        LOG_WARN("baseline in the store (%s: %s) was not collected from the passages that feed "
                 "the rules now (%s%s): not applied, a new one is collected",
                 b.source, b.note, "ok passages", M.filter_text);
        M.applied = b;
        M.has_applied = 1;
        return 0;
    }
    amfi_indicators_set_baseline(M.ind, b.mean_kg, b.std_kg, b.n);
    M.applied = b;
    M.has_applied = 1;
    LOG_INFO("baseline from the store: mean %.0f kg, STD %.0f kg (%d, %s)", b.mean_kg,
             b.std_kg, b.n, b.source);
    double *g = malloc(sizeof(double) * (size_t)M.params.window);
    int n = 0;
    const char *names[32];
    for (int i = 0; i < M.n_cls; i++)
        names[i] = M.cls_name[i];
    if (g && amfi_store_recent_fed_gvw(c->store, M.params.window, names, M.n_cls, M.min_kg,
                                       c->cfg->daemon.single_presence_only, g, &n, err,
                                       sizeof err) == 0) {
        amfi_indicators_prefill(M.ind, g, n);
        LOG_INFO("window refilled from the store: %d ok passages%s", n, M.filter_text);
    } else if (g) {
        LOG_WARN("store: %s", err);
    }
    free(g);
    /* An alert open before a restart stays open, not raised twice. */
    int open_std = last_alert_raised(c->store, "std_increase");
    int open_mean = last_alert_raised(c->store, "mean_shift");
    amfi_indicators_set_alerted(M.ind, open_std, open_mean);
    metrics_alert("std_increase", open_std);
    metrics_alert("mean_shift", open_mean);
    if (open_std || open_mean)
        LOG_INFO("open alerts restored from the store:%s%s", open_std ? " std_increase" : "",
                 open_mean ? " mean_shift" : "");
    return 0;
}

/* A stored passage that feeds the rules: its GVW (compensated: gvw_comp_kg). */
static void stdmean_feed(amfid_ctx *c, const amfid_passage *p)
{
    if (!p->feeds || !passes_filter(p))
        return;
    const job *j = p->j;
    const double gvw_kg = p->r->gvw_comp_kg;
    amfi_indicator_eval ev;
    amfi_alert_event al[2];
    int n_al = 0;
    int bits = amfi_indicators_push(M.ind, gvw_kg, &ev, al, &n_al);
    if (bits < 0) {
        ctx_error(c, "indicators: GVW %.1f kg of vehicle %lld refused", gvw_kg,
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
        auto_note(b.note, sizeof b.note, ev.n);
        if (amfi_store_set_baseline(c->store, &b, err, sizeof err))
            ctx_error(c, "store: %s", err);
        M.applied = b; /* in force already: the timer leaves it be */
        M.has_applied = 1;
        LOG_INFO("baseline established: mean %.0f kg, STD %.0f kg over %d passages",
                 ev.baseline_mean_kg, ev.baseline_std_kg, ev.n);
    }
    int64_t ind_id = 0;
    if (bits & AMFI_IND_EVAL) {
        amfi_indicator_row row = {j->w.v.utime, ev.n, ev.mean_kg, ev.std_kg,
                                  ev.baseline_mean_kg, ev.baseline_std_kg, ev.std_ratio,
                                  ev.p_value, ev.state};
        if (amfi_store_add_indicator(c->store, &row, &ind_id, err, sizeof err))
            ctx_error(c, "store: %s", err);
        amfi_indicator_t m = {j->w.v.utime, ind_id, ev.n, ev.mean_kg, ev.std_kg,
                              ev.baseline_mean_kg, ev.baseline_std_kg, ev.std_ratio,
                              ev.p_value, (char *)ev.state, (char *)c->cfg->site.id};
        BUS_PUBLISH(c, amfi_indicator_t, c->cfg->daemon.ch_indicator, &m);
        metrics_indicator(ev.std_ratio, ev.p_value,
                          ev.baseline_mean_kg > 0 ? ev.mean_kg / ev.baseline_mean_kg : NAN);
    }
    for (int i = 0; (bits & AMFI_IND_ALERT) && i < n_al; i++)
        c->emit_alert(c, j->w.v.utime, &al[i], ind_id);
}


static void stdmean_final(amfid_ctx *c)
{
    (void)c;
    if (M.cls_mask || M.min_kg > 0)
        LOG_INFO("STD and mean rules: %lld passages fed%s, %lld of other classes or none, "
                 "%lld below %.0f kg left out",
                 M.fed, M.filter_text, M.not_class, M.below_min, M.min_kg);
}

static void stdmean_stop(amfid_ctx *c)
{
    (void)c;
    amfi_indicators_destroy(M.ind);
    memset(&M, 0, sizeof M);
}

const amfid_module stdmean_module = {
    .name = "stdmean",
    .section = "daemon.indicators",
    .start = stdmean_start,
    .restore = stdmean_restore,
    .on_passage = stdmean_feed,
    .final = stdmean_final,
    .stop = stdmean_stop,
};
