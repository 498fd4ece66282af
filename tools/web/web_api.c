/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * web_api.c: amfi-web's JSON API (docs/web.md): /api/status,
 * /api/passages, /api/passages/ID, /api/alerts, /api/trends, /api/classes.
 * Every parameter is checked where it enters: an unknown or repeated one,
 * or a value out of its rule, is a 400 naming it. Every answer is built
 * with jansson, so text from the store is escaped by construction; numbers
 * that are unknown (NaN) are null. The caller's thread (the server's one).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_config.h"
#include "amfi_json.h"
#include "level_rule.h"
#include "web.h"

#define DEFAULT_LIMIT 50
#define DEFAULT_POINTS 200
#define MAX_CLASSES 256
#define MAX_ALERTS 500
#define DAY_US INT64_C(86400000000)
/* /api/trends and /api/classes without `from`: the 30 days before `to`, or
   before the newest passage (a whole store's year of passages costs about
   a second per million rows scanned: docs/results/web.md) */
#define DEFAULT_DAYS 30

/* At most 64 bytes of s, bytes outside printable ASCII as '?': for messages
   about what a client sent (which need not be UTF-8). */
static void shown(const char *s, char *buf, size_t len)
{
    size_t k = 0;
    for (; s && s[k] && k + 1 < len && k < 64; k++)
        buf[k] = (s[k] < 0x20 || s[k] > 0x7e) ? '?' : s[k];
    buf[k] = '\0';
}

json_t *web_error(const char *msg, const char *name)
{
    json_t *o = json_object();
    json_object_set_new(o, "error", json_string(msg));
    if (name) {
        char n[80];
        shown(name, n, sizeof n);
        json_object_set_new(o, "parameter", json_string(n));
    }
    return o;
}

static web_reply reply(unsigned status, json_t *body)
{
    return (web_reply){status, body};
}

static web_reply bad(const char *name, const char *fmt, const char *value)
{
    char v[80], msg[256];
    shown(value, v, sizeof v);
    snprintf(msg, sizeof msg, fmt, v);
    return reply(400, web_error(msg, name));
}

static web_reply store_failed(const char *err)
{
    return reply(500, web_error(err, NULL));
}

/* ---- parameters ------------------------------------------------------------ */

/* Checks that every parameter is one of allowed (NULL-terminated) and given
   once; 0, or fills *r with the 400. */
static int only(const web_param *p, int np, const char *const *allowed, web_reply *r)
{
    for (int i = 0; i < np; i++) {
        int k = 0;
        while (allowed[k] && strcmp(allowed[k], p[i].name) != 0)
            k++;
        if (!allowed[k]) {
            char list[256] = "";
            for (k = 0; allowed[k]; k++) {
                strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
                strncat(list, allowed[k], sizeof list - strlen(list) - 1);
            }
            char n[80], msg[400];
            shown(p[i].name, n, sizeof n);
            snprintf(msg, sizeof msg, "unknown parameter '%s' (this path takes: %s)", n,
                     k ? list : "none");
            *r = reply(400, web_error(msg, p[i].name));
            return -1;
        }
        for (int j = 0; j < i; j++)
            if (strcmp(p[j].name, p[i].name) == 0) {
                *r = bad(p[i].name, "parameter '%s' given twice", p[i].name);
                return -1;
            }
    }
    return 0;
}

static const char *get(const web_param *p, int np, const char *name)
{
    for (int i = 0; i < np; i++)
        if (strcmp(p[i].name, name) == 0)
            return p[i].value ? p[i].value : "";
    return NULL;
}

/* Time parameter `name` into *t (unchanged when absent); 0 or fills *r. */
static int time_param(const web_param *p, int np, const char *name, int64_t *t, web_reply *r)
{
    const char *v = get(p, np, name);
    if (!v)
        return 0;
    if (web_parse_time(v, t) != 0) {
        *r = bad(name,
                 "'%s' is not a time: ISO-8601 UTC (2026-01-31, 2026-01-31T08:00:00Z) or "
                 "seconds since 1970, up to 9999-12-31",
                 v);
        return -1;
    }
    return 0;
}

static int range_params(const web_param *p, int np, int64_t *from, int64_t *to, web_reply *r)
{
    *from = 0;
    *to = AMFI_STORE_MAX_UTIME;
    if (time_param(p, np, "from", from, r) || time_param(p, np, "to", to, r))
        return -1;
    if (*from > *to) {
        *r = reply(400, web_error("from is after to", "from"));
        return -1;
    }
    return 0;
}

/* range_params, and without `from` the DEFAULT_DAYS days before `to` or, without
   `to` either, before the newest passage (its end inclusive). */
static int window_params(amfi_store *s, const web_param *p, int np, int64_t *from, int64_t *to,
                         web_reply *r)
{
    if (range_params(p, np, from, to, r))
        return -1;
    if (get(p, np, "from"))
        return 0;
    int64_t end = *to;
    if (!get(p, np, "to")) {
        amfi_web_status st;
        char err[512];
        if (amfi_store_web_status(s, AMFI_STORE_MAX_UTIME, &st, err, sizeof err)) {
            *r = store_failed(err);
            return -1;
        }
        end = st.last_id > 0 ? st.last_utime : web_now_us();
    }
    *from = end > DEFAULT_DAYS * DAY_US ? end - DEFAULT_DAYS * DAY_US : 0;
    return 0;
}

/* Integer parameter in [lo, hi]; above hi is capped to hi when cap. */
static int int_param(const web_param *p, int np, const char *name, long lo, long hi, int cap,
                     long *out, web_reply *r)
{
    const char *v = get(p, np, name);
    if (!v)
        return 0;
    char *end;
    errno = 0;
    long x = strtol(v, &end, 10);
    if (!*v || *end || errno || v[0] == '+' || v[0] == ' ' || x < lo || (!cap && x > hi)) {
        char fmt[160];
        snprintf(fmt, sizeof fmt, "'%%s' is not an integer in [%ld, %ld]", lo, hi);
        *r = bad(name, fmt, v);
        return -1;
    }
    *out = x > hi ? hi : x;
    return 0;
}

/* ---- JSON pieces ------------------------------------------------------------- */

static void set_time(json_t *o, const char *key, int64_t utime)
{
    char t[40], k[48];
    json_object_set_new(o, key, json_integer(utime));
    snprintf(k, sizeof k, "%s_utc", key);
    json_object_set_new(o, k, json_string(web_format_time(utime, t, sizeof t)));
}

static json_t *str_or_null(const char *s)
{
    return s ? json_string(s) : json_null();
}

static json_t *passage_json(const amfi_web_passage *wp, int full)
{
    const amfi_passage_row *r = &wp->row;
    json_t *o = json_object();
    json_object_set_new(o, "id", json_integer(wp->id));
    json_object_set_new(o, "vehicle_id", json_integer(r->vehicle_id));
    set_time(o, "utime", r->utime);
    json_object_set_new(o, "lane", json_integer(r->lane));
    json_object_set_new(o, "status", json_string(r->status));
    json_object_set_new(o, "reason", json_string(r->reason ? r->reason : ""));
    json_object_set_new(o, "class", str_or_null(r->vclass));
    json_object_set_new(o, "axle_groups", str_or_null(r->axle_groups));
    json_object_set_new(o, "n_axles", json_integer(r->n_axles));
    json_object_set_new(o, "gvw_kg", amfi_json_num(r->gvw_kg));
    json_object_set_new(o, "speed_mps", amfi_json_num(r->speed_mps));
    json_object_set_new(o, "overload", r->has_overload ? json_boolean(r->overload) : json_null());
    json_object_set_new(o, "loads_refused",
                        r->loads_refused && r->loads_refused[0] ? json_string(r->loads_refused)
                                                                : json_null());
    json_object_set_new(o, "residual_rms", amfi_json_num(r->residual_rms));
    json_object_set_new(o, "quality", amfi_json_num(r->quality));
    json_object_set_new(o, "n_vehicles", json_integer(r->n_vehicles));
    if (!full)
        return o;
    json_object_set_new(o, "speed_given_mps", amfi_json_num(r->speed_given_mps));
    json_object_set_new(o, "speed_estimated", json_boolean(r->speed_estimated));
    json_object_set_new(o, "lambda", amfi_json_num(r->lambda));
    json_object_set_new(o, "formulation", str_or_null(r->formulation));
    json_object_set_new(o, "solve_ms", amfi_json_num(r->solve_ms));
    json_object_set_new(o, "reference_gvw_kg", amfi_json_num(r->reference_gvw_kg));
    json_object_set_new(o, "deck_c", r->has_deck_c ? amfi_json_num(r->deck_c) : json_null());
    json_object_set_new(o, "f1_hz", amfi_json_num(r->f1_hz));
    json_object_set_new(o, "f1_comp_hz", amfi_json_num(r->f1_comp_hz));
    json_object_set_new(o, "f1_zeta", amfi_json_num(r->f1_zeta));
    json_object_set_new(o, "f1_r2", amfi_json_num(r->f1_r2));
    json_object_set_new(o, "gvw_comp_kg", amfi_json_num(r->gvw_comp_kg));
    json_t *axles = json_array();
    for (int k = 0; k < r->n_axles; k++) {
        json_t *a = json_object();
        json_object_set_new(a, "idx", json_integer(k + 1));
        json_object_set_new(a, "load_kg", amfi_json_num(r->axle_kg[k]));
        json_object_set_new(a, "spacing_m", k ? amfi_json_num(r->spacing_m[k - 1]) : json_null());
        json_array_append_new(axles, a);
    }
    json_object_set_new(o, "axles", axles);
    /* the groups: "1-1-3" splits the axles front to back; a group's load is
       the sum of its axles' (null when one is unknown) */
    json_t *groups = json_array();
    if (r->axle_groups) {
        const char *g = r->axle_groups;
        int first = 0, ok = 1;
        while (*g && ok) {
            char *end;
            long n = strtol(g, &end, 10);
            if (end == g || n < 1 || first + n > r->n_axles) {
                ok = 0; /* groups that do not fit the axles: shown as stored only */
                break;
            }
            double sum = 0;
            json_t *gj = json_object(), *idx = json_array();
            for (int k = first; k < first + n; k++) {
                sum += r->axle_kg[k];
                json_array_append_new(idx, json_integer(k + 1));
            }
            json_object_set_new(gj, "axles", idx);
            json_object_set_new(gj, "load_kg", amfi_json_num(sum));
            json_array_append_new(groups, gj);
            first += (int)n;
            g = *end == '-' ? end + 1 : end;
            if (*end && *end != '-')
                ok = 0;
        }
        if (!ok)
            json_array_clear(groups);
    }
    json_object_set_new(o, "groups", groups);
    return o;
}

static json_t *alert_json(const amfi_alert_rec *a)
{
    json_t *o = json_object();
    json_object_set_new(o, "id", json_integer(a->id));
    set_time(o, "utime", a->utime);
    json_object_set_new(o, "level", json_string(a->level));
    json_object_set_new(o, "kind", json_string(a->kind));
    json_object_set_new(o, "raised", json_boolean(a->raised));
    json_object_set_new(o, "message", json_string(a->message));
    json_object_set_new(o, "indicator_id",
                        a->indicator_id > 0 ? json_integer(a->indicator_id) : json_null());
    return o;
}

static int open_alerts_json(amfi_store *s, json_t **out, char *err, size_t errlen)
{
    amfi_alert_rec *a = NULL;
    int n = 0;
    int rc = amfi_store_open_alerts(s, &a, &n, err, errlen);
    if (rc != 0)
        return rc;
    json_t *arr = json_array();
    for (int k = 0; k < n; k++)
        json_array_append_new(arr, alert_json(&a[k]));
    free(a);
    *out = arr;
    return 0;
}

/* ---- /api/status ------------------------------------------------------------- */

static int counts_json(amfi_store *s, int64_t since, json_t **out, char *err, size_t errlen)
{
    amfi_web_status st;
    int rc = amfi_store_web_status(s, since, &st, err, errlen);
    if (rc != 0)
        return rc;
    json_t *o = json_object(), *by = json_object();
    set_time(o, "since", since);
    json_object_set_new(o, "total", json_integer(st.since_total));
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        json_object_set_new(by, amfi_store_status_name(k), json_integer(st.since_by_status[k]));
    json_object_set_new(o, "by_status", by);
    *out = o;
    return 0;
}

static int meta_add(void *ctx, const char *key, const char *value)
{
    json_object_set_new((json_t *)ctx, key, json_string(value));
    return 0;
}

static web_reply api_status(const web_source *src, const web_param *p, int np)
{
    static const char *const allowed[] = {NULL};
    web_reply r;
    if (only(p, np, allowed, &r))
        return r;
    char err[512];
    amfi_store *s = src->store;
    amfi_web_status st;
    if (amfi_store_web_status(s, AMFI_STORE_MAX_UTIME, &st, err, sizeof err))
        return store_failed(err);
    json_t *o = json_object();
    char site[AMFI_STORE_META_VALUE_MAX + 1], name[AMFI_STORE_META_VALUE_MAX + 1];
    int found = 0, found_name = 0;
    if (amfi_store_meta_get(s, "site.id", site, sizeof site, &found, err, sizeof err)
        || amfi_store_meta_get(s, "site.name", name, sizeof name, &found_name, err, sizeof err)) {
        json_decref(o);
        return store_failed(err);
    }
    json_object_set_new(o, "site", found ? json_string(site) : json_null());
    json_object_set_new(o, "site_name", found_name ? json_string(name) : json_null());
    json_object_set_new(o, "source", json_string(src->kind));
    json_object_set_new(o, "source_name", json_string(src->name));
    if (src->as_of_us > 0)
        set_time(o, "fetched", src->as_of_us);
    json_object_set_new(o, "store_version", json_integer(AMFI_STORE_SCHEMA_VERSION));
    set_time(o, "now", web_now_us());
    json_object_set_new(o, "passages", json_integer(st.total));
    if (st.last_id > 0) {
        json_t *last = json_object();
        json_object_set_new(last, "id", json_integer(st.last_id));
        set_time(last, "utime", st.last_utime);
        json_object_set_new(o, "last_passage", last);
    } else {
        json_object_set_new(o, "last_passage", json_null());
    }
    /* today: the UTC day of the wall clock; newest_day: the UTC day of the
       newest passage (a store being replayed or copied lags the clock) */
    int64_t now = web_now_us();
    json_t *today = NULL, *newest = NULL, *alerts = NULL, *metrics = json_object();
    int rc = counts_json(s, now - now % DAY_US, &today, err, sizeof err);
    if (rc == 0)
        rc = counts_json(s, st.last_id > 0 ? st.last_utime - st.last_utime % DAY_US : 0, &newest,
                         err, sizeof err);
    if (rc == 0)
        rc = open_alerts_json(s, &alerts, err, sizeof err);
    if (rc == 0)
        rc = amfi_store_web_meta(s, "intake.", meta_add, metrics, err, sizeof err);
    amfi_indicator_rec ind;
    int nind = 0;
    if (rc == 0)
        rc = amfi_store_recent_indicators(s, 1, &ind, &nind, err, sizeof err);
    amfi_baseline b;
    int has_b = 0;
    if (rc == 0)
        rc = amfi_store_get_baseline(s, &b, &has_b, err, sizeof err);
    if (rc != 0) {
        json_decref(o);
        json_decref(today);
        json_decref(newest);
        json_decref(alerts);
        json_decref(metrics);
        return store_failed(err);
    }
    json_object_set_new(o, "today", today);
    json_object_set_new(o, "newest_day", newest);
    json_object_set_new(o, "open_alerts", alerts);
    json_object_set_new(o, "metrics", json_object_size(metrics) ? metrics : (json_decref(metrics), json_null()));
    if (nind == 1) {
        json_t *i = json_object();
        json_object_set_new(i, "id", json_integer(ind.id));
        set_time(i, "utime", ind.row.utime);
        json_object_set_new(i, "state", json_string(ind.row.state));
        json_object_set_new(i, "n", json_integer(ind.row.n));
        json_object_set_new(i, "std_ratio", amfi_json_num(ind.row.std_ratio));
        json_object_set_new(i, "p_value", amfi_json_num(ind.row.p_value));
        json_object_set_new(o, "indicator", i);
    } else {
        json_object_set_new(o, "indicator", json_null());
    }
    if (has_b) {
        json_t *bj = json_object();
        set_time(bj, "utime_set", b.utime_set);
        json_object_set_new(bj, "n", json_integer(b.n));
        json_object_set_new(bj, "mean_kg", amfi_json_num(b.mean_kg));
        json_object_set_new(bj, "std_kg", amfi_json_num(b.std_kg));
        json_object_set_new(bj, "source", json_string(b.source));
        json_object_set_new(o, "baseline", bj);
    } else {
        json_object_set_new(o, "baseline", json_null());
    }
    return reply(200, o);
}

/* ---- /api/passages ----------------------------------------------------------- */

static int add_passage(void *ctx, const amfi_web_passage *p)
{
    json_array_append_new((json_t *)ctx, passage_json(p, 0));
    return 0;
}

/* A class name as the store holds them: 1 .. 15 bytes of [A-Za-z0-9_.-] */
static int class_ok(const char *c)
{
    size_t n = strlen(c);
    return n >= 1 && n <= 15 && strspn(c, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                          "0123456789_.-") == n;
}

static web_reply api_passages(const web_source *src, const web_param *p, int np)
{
    static const char *const allowed[] = {"from", "to", "limit", "status", "class", NULL};
    web_reply r;
    amfi_web_query q = {.limit = DEFAULT_LIMIT};
    long limit = DEFAULT_LIMIT;
    if (only(p, np, allowed, &r) || range_params(p, np, &q.from, &q.to, &r)
        || int_param(p, np, "limit", 1, AMFI_WEB_MAX_LIMIT, 1, &limit, &r))
        return r;
    q.limit = (int)limit;
    q.status = get(p, np, "status");
    if (q.status) {
        int k = 0;
        while (amfi_store_status_name(k) && strcmp(amfi_store_status_name(k), q.status) != 0)
            k++;
        if (!amfi_store_status_name(k))
            return bad("status", "'%s' is not a status (" AMFI_STORE_STATUSES ")", q.status);
    }
    q.vclass = get(p, np, "class");
    if (q.vclass && !class_ok(q.vclass))
        return bad("class", "'%s' is not a class name (1 to 15 of A-Z a-z 0-9 _ . -)", q.vclass);
    char err[512];
    json_t *arr = json_array();
    if (amfi_store_web_passages(src->store, &q, add_passage, arr, err, sizeof err)) {
        json_decref(arr);
        return store_failed(err);
    }
    json_t *o = json_object();
    set_time(o, "from", q.from);
    set_time(o, "to", q.to);
    json_object_set_new(o, "limit", json_integer(q.limit));
    json_object_set_new(o, "count", json_integer((json_int_t)json_array_size(arr)));
    json_object_set_new(o, "passages", arr);
    return reply(200, o);
}

static web_reply api_passage(const web_source *src, const char *id_text, const web_param *p,
                             int np)
{
    static const char *const allowed[] = {NULL};
    web_reply r;
    if (only(p, np, allowed, &r))
        return r;
    size_t nd = strspn(id_text, "0123456789");
    if (nd == 0 || nd > 18 || id_text[nd] || id_text[0] == '0')
        return reply(404, web_error("no such passage: the id is a positive integer", NULL));
    int64_t id = strtoll(id_text, NULL, 10);
    amfi_web_passage *wp = malloc(sizeof *wp);
    if (!wp)
        return store_failed("out of memory");
    int found = 0;
    char err[512];
    if (amfi_store_web_passage(src->store, id, wp, &found, err, sizeof err)) {
        free(wp);
        return store_failed(err);
    }
    if (!found) {
        free(wp);
        char msg[64];
        snprintf(msg, sizeof msg, "no passage %lld", (long long)id);
        return reply(404, web_error(msg, NULL));
    }
    json_t *o = passage_json(wp, 1);
    char why[600];
    json_t *raw = web_raw(src, wp, why, sizeof why);
    free(wp);
    json_object_set_new(o, "raw", raw ? raw : json_null());
    json_object_set_new(o, "raw_reason", raw ? json_null() : json_string(why));
    return reply(200, o);
}

/* ---- /api/alerts ----------------------------------------------------------- */

static web_reply api_alerts(const web_source *src, const web_param *p, int np)
{
    static const char *const allowed[] = {"limit", NULL};
    web_reply r;
    long limit = 100;
    if (only(p, np, allowed, &r) || int_param(p, np, "limit", 1, MAX_ALERTS, 1, &limit, &r))
        return r;
    char err[512];
    json_t *open = NULL;
    if (open_alerts_json(src->store, &open, err, sizeof err))
        return store_failed(err);
    amfi_alert_rec *a = malloc((size_t)limit * sizeof *a);
    int n = 0;
    if (!a || amfi_store_recent_alerts(src->store, (int)limit, a, &n, err, sizeof err)) {
        free(a);
        json_decref(open);
        return store_failed(a ? err : "out of memory");
    }
    json_t *recent = json_array();
    for (int k = 0; k < n; k++)
        json_array_append_new(recent, alert_json(&a[k]));
    free(a);
    json_t *o = json_object();
    json_object_set_new(o, "open", open);
    json_object_set_new(o, "limit", json_integer(limit));
    json_object_set_new(o, "recent", recent);
    return reply(200, o);
}

/* ---- /api/trends ----------------------------------------------------------- */

static const char *const series_units[AMFI_WEB_N_SERIES] = {"kg", "", "Hz", "m/s²", "°C", ""};
#define SERIES_NAMES "gvw, indicator, natfreq, residual, temperature, fit_ratio"

/* The model_mismatch rule's levels for the fit_ratio series: what amfid
   ran with (meta alerts.model_fit, written at its start), else the
   loader's defaults (a store of an older amfid, the central database).
   NULL with err when the record is damaged or no memory. */
static json_t *model_fit_levels(amfi_store *s, char *err, size_t errlen)
{
    char rec[4097], why[256];
    int found = 0;
    amfi_level_params mf;
    const char *source = "amfid";
    if (amfi_store_meta_get(s, "alerts.model_fit", rec, sizeof rec, &found, err, errlen) != 0)
        return NULL;
    if (found) {
        if (amfi_level_params_parse(rec, &mf, why, sizeof why) != 0) {
            snprintf(err, errlen, "meta alerts.model_fit: %s", why);
            return NULL;
        }
    } else {
        amfi_site_config *d = malloc(sizeof *d);
        if (!d) {
            snprintf(err, errlen, "out of memory");
            return NULL;
        }
        amfi_config_defaults(d);
        mf = d->daemon.model_fit;
        free(d);
        source = "defaults";
    }
    json_t *o = json_object();
    json_object_set_new(o, "source", json_string(source));
    json_object_set_new(o, "enabled", json_boolean(mf.enabled));
    json_object_set_new(o, "window", json_integer(mf.window));
    json_object_set_new(o, "raise", amfi_json_num(mf.raise));
    json_object_set_new(o, "clear", amfi_json_num(mf.clear));
    json_object_set_new(o, "raise_after", json_integer(mf.raise_after));
    json_object_set_new(o, "clear_after", json_integer(mf.clear_after));
    return o;
}

static web_reply api_trends(const web_source *src, const web_param *p, int np)
{
    static const char *const allowed[] = {"series", "from", "to", "points", NULL};
    web_reply r;
    int64_t from, to;
    long points = DEFAULT_POINTS;
    if (only(p, np, allowed, &r) || window_params(src->store, p, np, &from, &to, &r)
        || int_param(p, np, "points", 1, AMFI_WEB_MAX_BUCKETS, 0, &points, &r))
        return r;
    const char *name = get(p, np, "series");
    if (!name)
        return reply(400, web_error("series is required (" SERIES_NAMES ")", "series"));
    int which = 0;
    while (amfi_store_web_series_name(which) && strcmp(amfi_store_web_series_name(which), name))
        which++;
    if (!amfi_store_web_series_name(which))
        return bad("series", "'%s' is not a series (" SERIES_NAMES ")", name);
    amfi_web_bucket *b = malloc((size_t)points * sizeof *b);
    if (!b)
        return store_failed("out of memory");
    int n = 0;
    int64_t width = 0;
    char err[512];
    if (amfi_store_web_trend(src->store, which, from, to, (int)points, b, &n, &width, err,
                             sizeof err)) {
        free(b);
        return store_failed(err);
    }
    json_t *levels = NULL;
    if (which == AMFI_WEB_FIT_RATIO && !(levels = model_fit_levels(src->store, err, sizeof err))) {
        free(b);
        return store_failed(err);
    }
    json_t *o = json_object(), *arr = json_array();
    json_object_set_new(o, "series", json_string(name));
    if (levels)
        json_object_set_new(o, "thresholds", levels);
    set_time(o, "from", from);
    set_time(o, "to", to);
    json_object_set_new(o, "unit", json_string(series_units[which]));
    json_object_set_new(o, "bucket_s", json_real((double)width / 1e6));
    for (int k = 0; k < n; k++) {
        json_t *e = json_object();
        set_time(e, "t", b[k].t0);
        json_object_set_new(e, "n", json_integer(b[k].n));
        json_object_set_new(e, "mean", amfi_json_num(b[k].mean));
        json_object_set_new(e, "min", amfi_json_num(b[k].min));
        json_object_set_new(e, "max", amfi_json_num(b[k].max));
        json_array_append_new(arr, e);
    }
    free(b);
    json_object_set_new(o, "count", json_integer(n));
    json_object_set_new(o, "points", arr);
    return reply(200, o);
}

/* ---- /api/classes ---------------------------------------------------------- */

static web_reply api_classes(const web_source *src, const web_param *p, int np)
{
    static const char *const allowed[] = {"from", "to", NULL};
    web_reply r;
    int64_t from, to;
    if (only(p, np, allowed, &r) || window_params(src->store, p, np, &from, &to, &r))
        return r;
    amfi_web_class *c = malloc(MAX_CLASSES * sizeof *c);
    int n = 0;
    char err[512];
    if (!c || amfi_store_web_classes(src->store, from, to, c, MAX_CLASSES, &n, err, sizeof err)) {
        free(c);
        return store_failed(c ? err : "out of memory");
    }
    json_t *o = json_object(), *arr = json_array();
    for (int k = 0; k < n; k++) {
        json_t *e = json_object();
        json_object_set_new(e, "class", c[k].vclass[0] ? json_string(c[k].vclass) : json_null());
        json_object_set_new(e, "n", json_integer(c[k].n));
        json_object_set_new(e, "n_ok", json_integer(c[k].n_ok));
        json_object_set_new(e, "n_overload", json_integer(c[k].n_overload));
        json_object_set_new(e, "n_refused", json_integer(c[k].n_refused));
        json_object_set_new(e, "gvw_mean_kg", amfi_json_num(c[k].gvw_mean_kg));
        json_object_set_new(e, "gvw_max_kg", amfi_json_num(c[k].gvw_max_kg));
        json_array_append_new(arr, e);
    }
    free(c);
    set_time(o, "from", from);
    set_time(o, "to", to);
    json_object_set_new(o, "classes", arr);
    return reply(200, o);
}

/* ---- routing ----------------------------------------------------------------- */

web_reply web_api(const web_source *src, const char *path, const web_param *p, int np)
{
    if (strcmp(path, "/api/status") == 0)
        return api_status(src, p, np);
    if (strcmp(path, "/api/passages") == 0)
        return api_passages(src, p, np);
    if (strncmp(path, "/api/passages/", 14) == 0)
        return api_passage(src, path + 14, p, np);
    if (strcmp(path, "/api/alerts") == 0)
        return api_alerts(src, p, np);
    if (strcmp(path, "/api/trends") == 0)
        return api_trends(src, p, np);
    if (strcmp(path, "/api/classes") == 0)
        return api_classes(src, p, np);
    return reply(404, web_error("no such API path (see docs/web.md)", NULL));
}
