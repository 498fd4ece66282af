/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_web.c: the reads of amfi-web (tools/web/, docs/web.md), the
 * read-only dashboard: the status (newest passage, counts by status since a
 * time), the passages newest first (time range, status, class, a limit),
 * one passage with its axles, trends bucketed in SQL (a bounded number of
 * points whatever the store's size), the per-class statistics and meta keys
 * by prefix. Reads only. Every query is written so that SQLite can walk an
 * index (passages_utime, passages_status_utime, indicators_utime,
 * environment_utime): a page costs what it shows, not the store's size
 * (docs/results/web.md measures it on 1 M passages). Every value read back
 * is checked as in store_read.c. The caller's thread; statements are
 * prepared and finalized per call (no state kept in the handle).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

static int check_range(int64_t from, int64_t to, const char *what, char *err, size_t errlen)
{
    if (from < 0 || to < 0 || from > AMFI_STORE_MAX_UTIME || to > AMFI_STORE_MAX_UTIME)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: time range [%lld, %lld] outside [0, %lld]",
                       what, (long long)from, (long long)to, (long long)AMFI_STORE_MAX_UTIME);
    return 0;
}

/* ---- status --------------------------------------------------------------- */

int amfi_store_web_status(amfi_store *s, int64_t since, amfi_web_status *out, char *err,
                          size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && !out)
        rc = st_fail(err, errlen, AMFI_EINVAL, "status: output is NULL");
    if (rc == 0)
        rc = check_range(since, since, "status", err, errlen);
    if (rc != 0)
        return rc;
    memset(out, 0, sizeof *out);
    sqlite3_stmt *st = NULL;
    /* newest passage: the end of passages_utime */
    rc = st_prepare(s, "SELECT id, utime FROM passages ORDER BY utime DESC, id DESC LIMIT 1", &st,
                    "status: newest passage", err, errlen);
    if (rc == 0) {
        int src = sqlite3_step(st);
        if (src == SQLITE_ROW) {
            origin o = {"passages", sqlite3_column_int64(st, 0)};
            out->last_id = o.rowid;
            rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &out->last_utime, err, errlen);
        } else if (src != SQLITE_DONE) {
            rc = st_db_fail(s, src, "status: newest passage", err, errlen);
        }
    }
    sqlite3_finalize(st);
    st = NULL;
    if (rc == 0)
        rc = amfi_store_count(s, AMFI_STORE_PASSAGES, &out->total, err, errlen);
    /* one range of passages_status_utime per status */
    if (rc == 0)
        rc = st_prepare(s, "SELECT count(*) FROM passages WHERE status = ?1 AND utime >= ?2", &st,
                        "status: counts", err, errlen);
    for (int k = 0; rc == 0 && k < AMFI_STORE_N_STATUS; k++) {
        sqlite3_bind_text(st, 1, st_statuses[k], -1, SQLITE_STATIC);
        sqlite3_bind_int64(st, 2, since);
        int src = sqlite3_step(st);
        if (src == SQLITE_ROW) {
            origin o = {"passages", -1};
            rc = st_read_int(st, 0, 0, INT64_MAX, &o, &out->since_by_status[k], err, errlen);
            out->since_total += out->since_by_status[k];
        } else {
            rc = st_db_fail(s, src, "status: counts", err, errlen);
        }
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    return rc;
}

/* ---- passages --------------------------------------------------------------- */

#define PASSAGE_COLS                                                                              \
    "id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason, lambda, "           \
    "residual_rms, formulation, solve_ms, speed_given_mps, speed_estimated, n_vehicles, quality, " \
    "reference_gvw_kg, deck_c, f1_hz, f1_comp_hz, f1_zeta, f1_r2, gvw_comp_kg, class, "            \
    "axle_groups, overload, loads_refused"

/* Optional text column col into buf (NULL: *ptr NULL). */
static int opt_text(sqlite3_stmt *st, int col, const origin *o, char *buf, size_t len,
                    const char **ptr, char *err, size_t errlen)
{
    *ptr = NULL;
    if (sqlite3_column_type(st, col) == SQLITE_NULL)
        return 0;
    int rc = st_read_text(st, col, len - 1, o, buf, len, err, errlen);
    if (rc == 0)
        *ptr = buf;
    return rc;
}

/* One row of PASSAGE_COLS into p (no axles: spacing and loads NaN). */
static int read_passage(sqlite3_stmt *st, amfi_web_passage *p, char *err, size_t errlen)
{
    amfi_passage_row *r = &p->row;
    memset(p, 0, sizeof *p);
    for (int k = 0; k < AMFI_MAX_AXLES; k++)
        r->spacing_m[k] = r->axle_kg[k] = NAN;
    origin o = {"passages", sqlite3_column_int64(st, 0)};
    p->id = o.rowid;
    int64_t v = 0;
    int rc = st_read_int(st, 1, INT64_MIN, INT64_MAX, &o, &r->vehicle_id, err, errlen);
    if (rc == 0) rc = st_read_int(st, 2, 0, AMFI_STORE_MAX_UTIME, &o, &r->utime, err, errlen);
    if (rc == 0) rc = st_read_int(st, 3, -32768, 32767, &o, &v, err, errlen);
    r->lane = (int)v;
    if (rc == 0) rc = st_read_real_or_null(st, 4, &R_SPEED, &o, &r->speed_mps, err, errlen);
    if (rc == 0) rc = st_read_int(st, 5, 0, AMFI_MAX_AXLES, &o, &v, err, errlen);
    r->n_axles = (int)v;
    if (rc == 0) rc = st_read_real_or_null(st, 6, &R_KG, &o, &r->gvw_kg, err, errlen);
    if (rc == 0) rc = st_read_text(st, 7, sizeof p->status - 1, &o, p->status, sizeof p->status, err, errlen);
    if (rc == 0) {
        int k = 0;
        while (st_statuses[k] && strcmp(st_statuses[k], p->status) != 0)
            k++;
        if (!st_statuses[k])
            rc = st_corrupt(&o, st, 7, err, errlen, "is not a known status");
        else
            r->status = st_statuses[k];
    }
    if (rc == 0) rc = st_read_text(st, 8, AMFI_STORE_REASON_MAX, &o, p->reason, sizeof p->reason, err, errlen);
    r->reason = p->reason;
    if (rc == 0) rc = st_read_real_or_null(st, 9, &R_POS, &o, &r->lambda, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 10, &R_NONNEG, &o, &r->residual_rms, err, errlen);
    if (rc == 0) rc = opt_text(st, 11, &o, p->formulation, sizeof p->formulation, &r->formulation, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 12, &R_MS, &o, &r->solve_ms, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 13, &R_SPEED, &o, &r->speed_given_mps, err, errlen);
    if (rc == 0) rc = st_read_int(st, 14, 0, 1, &o, &v, err, errlen);
    r->speed_estimated = (int)v;
    if (rc == 0) rc = st_read_int(st, 15, 1, 64, &o, &v, err, errlen);
    r->n_vehicles = (int)v;
    if (rc == 0) rc = st_read_real_or_null(st, 16, &R_QUALITY, &o, &r->quality, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 17, &R_REF_KG, &o, &r->reference_gvw_kg, err, errlen);
    if (rc == 0 && sqlite3_column_type(st, 18) != SQLITE_NULL) {
        rc = st_read_real(st, 18, &R_TEMP_C, &o, &r->deck_c, err, errlen);
        r->has_deck_c = 1;
    }
    if (rc == 0) rc = st_read_real_or_null(st, 19, &R_HZ, &o, &r->f1_hz, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 20, &R_HZ, &o, &r->f1_comp_hz, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 21, &R_ZETA, &o, &r->f1_zeta, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 22, &R_PROB, &o, &r->f1_r2, err, errlen);
    if (rc == 0) rc = st_read_real_or_null(st, 23, &R_KG_POS, &o, &r->gvw_comp_kg, err, errlen);
    if (rc == 0) rc = opt_text(st, 24, &o, p->vclass, sizeof p->vclass, &r->vclass, err, errlen);
    if (rc == 0) rc = opt_text(st, 25, &o, p->groups, sizeof p->groups, &r->axle_groups, err, errlen);
    if (rc == 0 && sqlite3_column_type(st, 26) != SQLITE_NULL) {
        rc = st_read_int(st, 26, 0, 1, &o, &v, err, errlen);
        r->has_overload = 1;
        r->overload = (int)v;
    }
    if (rc == 0)
        rc = opt_text(st, 27, &o, p->refused, sizeof p->refused, &r->loads_refused, err, errlen);
    return rc;
}

int amfi_store_web_passages(amfi_store *s, const amfi_web_query *q, amfi_web_passage_fn fn,
                            void *ctx, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!q || !fn))
        rc = st_fail(err, errlen, AMFI_EINVAL, "passages: no query or function");
    if (rc == 0)
        rc = check_range(q->from, q->to, "passages", err, errlen);
    if (rc == 0 && (q->limit < 1 || q->limit > AMFI_WEB_MAX_LIMIT))
        rc = st_fail(err, errlen, AMFI_EINVAL, "passages: limit %d outside [1, %d]", q->limit,
                     AMFI_WEB_MAX_LIMIT);
    if (rc == 0 && q->status
        && st_check_enum("passages: status", q->status, st_statuses, AMFI_STORE_STATUSES, err,
                         errlen) != 0)
        rc = AMFI_EINVAL;
    if (rc == 0 && q->vclass && st_check_text("passages: class", q->vclass, 1, 15, err, errlen))
        rc = AMFI_EINVAL;
    if (rc != 0)
        return rc;
    /* newest first along passages_utime (or passages_status_utime with a
       status): the walk stops after `limit` rows that match */
    sqlite3_stmt *st = NULL;
    const char *sql =
        q->status ? "SELECT " PASSAGE_COLS " FROM passages WHERE status = ?3 AND utime >= ?1 "
                    "AND utime <= ?2 AND (?4 IS NULL OR class = ?4) ORDER BY utime DESC, id DESC "
                    "LIMIT ?5"
                  : "SELECT " PASSAGE_COLS " FROM passages WHERE utime >= ?1 AND utime <= ?2 "
                    "AND (?4 IS NULL OR class = ?4) ORDER BY utime DESC, id DESC LIMIT ?5";
    rc = st_prepare(s, sql, &st, "passages: list", err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_int64(st, 1, q->from);
    sqlite3_bind_int64(st, 2, q->to);
    if (q->status)
        sqlite3_bind_text(st, 3, q->status, -1, SQLITE_TRANSIENT);
    if (q->vclass)
        sqlite3_bind_text(st, 4, q->vclass, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(st, 5, q->limit);
    amfi_web_passage *p = malloc(sizeof *p);
    if (!p) {
        sqlite3_finalize(st);
        return st_fail(err, errlen, AMFI_ENOMEM, "passages: out of memory");
    }
    int src = SQLITE_DONE;
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        rc = read_passage(st, p, err, errlen);
        if (rc == 0)
            rc = fn(ctx, p);
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "passages: list", err, errlen);
    free(p);
    sqlite3_finalize(st);
    return rc;
}

int amfi_store_web_passage(amfi_store *s, int64_t id, amfi_web_passage *out, int *found,
                           char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !found))
        rc = st_fail(err, errlen, AMFI_EINVAL, "passage: output is NULL");
    if (rc != 0)
        return rc;
    *found = 0;
    sqlite3_stmt *p = NULL, *a = NULL;
    rc = st_prepare(s, "SELECT " PASSAGE_COLS " FROM passages WHERE id = ?1", &p, "passage: read",
                    err, errlen);
    if (rc == 0)
        rc = st_prepare(s, "SELECT idx, spacing_m, load_kg FROM axles WHERE passage_id = ?1 "
                           "ORDER BY idx", &a, "passage: axles", err, errlen);
    if (rc == 0) {
        sqlite3_bind_int64(p, 1, id);
        int src = sqlite3_step(p);
        if (src == SQLITE_ROW) {
            rc = read_passage(p, out, err, errlen);
            if (rc == 0)
                *found = 1;
        } else if (src != SQLITE_DONE) {
            rc = st_db_fail(s, src, "passage: read", err, errlen);
        }
    }
    if (rc == 0 && *found) {
        amfi_passage_row *r = &out->row;
        int seen = 0;
        rc = st_read_axles(s, a, id, r, &seen, "passage: axles", err, errlen);
        if (rc == 0 && seen != r->n_axles)
            rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                         "%s: passages row %lld: n_axles %d but %d axle rows", s->path,
                         (long long)id, r->n_axles, seen);
    }
    if (rc != 0)
        *found = 0;
    sqlite3_finalize(p);
    sqlite3_finalize(a);
    return rc;
}

/* ---- trends ---------------------------------------------------------------- */

/* Each series: its table, value column, rule and the range its values
   must be in. Only these strings reach SQL. */
static const struct {
    const char *name, *table, *col, *cond;
    const range *rg;
} series[AMFI_WEB_N_SERIES] = {
    [AMFI_WEB_GVW] = {"gvw", "passages", "gvw_kg", "status = 'ok' AND ", &R_KG},
    [AMFI_WEB_INDICATOR] = {"indicator", "indicators", "std_ratio", "", &R_RATIO},
    [AMFI_WEB_NATFREQ] = {"natfreq", "passages", "f1_hz", "", &R_HZ},
    [AMFI_WEB_RESIDUAL] = {"residual", "passages", "residual_rms", "", &R_NONNEG},
    [AMFI_WEB_TEMPERATURE] = {"temperature", "environment", "deck_c", "", &R_TEMP_C},
    [AMFI_WEB_FIT_RATIO] = {"fit_ratio", "passages", "fit_ratio", "", &R_RATIO},
};

const char *amfi_store_web_series_name(int k)
{
    return k >= 0 && k < AMFI_WEB_N_SERIES ? series[k].name : NULL;
}

int amfi_store_web_trend(amfi_store *s, int which, int64_t from, int64_t to, int nbuckets,
                         amfi_web_bucket *out, int *n, int64_t *width, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n || !width))
        rc = st_fail(err, errlen, AMFI_EINVAL, "trend: output is NULL");
    if (rc == 0 && (which < 0 || which >= AMFI_WEB_N_SERIES))
        rc = st_fail(err, errlen, AMFI_EINVAL, "trend: series %d unknown", which);
    if (rc == 0 && (nbuckets < 1 || nbuckets > AMFI_WEB_MAX_BUCKETS))
        rc = st_fail(err, errlen, AMFI_EINVAL, "trend: %d buckets outside [1, %d]", nbuckets,
                     AMFI_WEB_MAX_BUCKETS);
    if (rc == 0)
        rc = check_range(from, to, "trend", err, errlen);
    if (rc != 0)
        return rc;
    *n = 0;
    *width = 0;
    char sql[512];
    sqlite3_stmt *st = NULL;
    /* the range narrowed to the series' data (both ends of its utime index),
       so that the buckets cover what there is */
    snprintf(sql, sizeof sql,
             "SELECT (SELECT min(utime) FROM %s WHERE utime >= ?1), "
             "(SELECT max(utime) FROM %s WHERE utime <= ?2)",
             series[which].table, series[which].table);
    rc = st_prepare(s, sql, &st, "trend: span", err, errlen);
    int64_t lo = from, hi = to;
    if (rc == 0) {
        sqlite3_bind_int64(st, 1, from);
        sqlite3_bind_int64(st, 2, to);
        int src = sqlite3_step(st);
        if (src != SQLITE_ROW)
            rc = st_db_fail(s, src, "trend: span", err, errlen);
        else if (sqlite3_column_type(st, 0) == SQLITE_NULL
                 || sqlite3_column_type(st, 1) == SQLITE_NULL)
            lo = 1, hi = 0; /* no rows */
        else
            lo = sqlite3_column_int64(st, 0), hi = sqlite3_column_int64(st, 1);
    }
    sqlite3_finalize(st);
    st = NULL;
    if (rc != 0 || lo > hi)
        return rc;
    /* whole seconds, nbuckets * w > hi − lo */
    int64_t w = ((hi - lo) / nbuckets / 1000000 + 1) * 1000000;
    *width = w;
    snprintf(sql, sizeof sql,
             "SELECT (utime - ?1) / ?3 AS b, count(%s), avg(%s), min(%s), max(%s) FROM %s "
             "WHERE %sutime >= ?1 AND utime <= ?2 AND %s IS NOT NULL GROUP BY b ORDER BY b",
             series[which].col, series[which].col, series[which].col, series[which].col,
             series[which].table, series[which].cond, series[which].col);
    rc = st_prepare(s, sql, &st, "trend: buckets", err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_int64(st, 1, lo);
    sqlite3_bind_int64(st, 2, hi);
    sqlite3_bind_int64(st, 3, w);
    int src = SQLITE_DONE;
    origin o = {series[which].table, -1};
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        int64_t b = 0;
        amfi_web_bucket k;
        rc = st_read_int(st, 0, 0, nbuckets - 1, &o, &b, err, errlen);
        if (rc == 0) rc = st_read_int(st, 1, 1, INT64_MAX, &o, &k.n, err, errlen);
        if (rc == 0) rc = st_read_real(st, 2, series[which].rg, &o, &k.mean, err, errlen);
        if (rc == 0) rc = st_read_real(st, 3, series[which].rg, &o, &k.min, err, errlen);
        if (rc == 0) rc = st_read_real(st, 4, series[which].rg, &o, &k.max, err, errlen);
        if (rc == 0 && *n >= nbuckets)
            rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT, "trend: more than %d buckets", nbuckets);
        if (rc == 0) {
            k.t0 = lo + b * w;
            out[(*n)++] = k;
        }
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "trend: buckets", err, errlen);
    sqlite3_finalize(st);
    if (rc != 0)
        *n = 0;
    return rc;
}

/* ---- classes --------------------------------------------------------------- */

int amfi_store_web_classes(amfi_store *s, int64_t from, int64_t to, amfi_web_class *out, int max,
                           int *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n || max < 1))
        rc = st_fail(err, errlen, AMFI_EINVAL, "classes: no output");
    if (rc == 0)
        rc = check_range(from, to, "classes", err, errlen);
    if (rc != 0)
        return rc;
    *n = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT class, count(*), sum(status = 'ok'), sum(coalesce(overload, 0)), "
                    "sum(coalesce(loads_refused, '') <> ''), avg(CASE WHEN status = 'ok' THEN gvw_kg END), "
                    "max(CASE WHEN status = 'ok' THEN gvw_kg END) FROM passages "
                    "WHERE utime >= ?1 AND utime <= ?2 GROUP BY class ORDER BY count(*) DESC, class",
                    &st, "classes", err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_int64(st, 1, from);
    sqlite3_bind_int64(st, 2, to);
    int src = SQLITE_DONE;
    origin o = {"passages", -1};
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        amfi_web_class c;
        memset(&c, 0, sizeof c);
        if (sqlite3_column_type(st, 0) != SQLITE_NULL)
            rc = st_read_text(st, 0, sizeof c.vclass - 1, &o, c.vclass, sizeof c.vclass, err,
                              errlen);
        if (rc == 0) rc = st_read_int(st, 1, 1, INT64_MAX, &o, &c.n, err, errlen);
        if (rc == 0) rc = st_read_int(st, 2, 0, INT64_MAX, &o, &c.n_ok, err, errlen);
        if (rc == 0) rc = st_read_int(st, 3, 0, INT64_MAX, &o, &c.n_overload, err, errlen);
        if (rc == 0) rc = st_read_int(st, 4, 0, INT64_MAX, &o, &c.n_refused, err, errlen);
        if (rc == 0) rc = st_read_real_or_null(st, 5, &R_KG, &o, &c.gvw_mean_kg, err, errlen);
        if (rc == 0) rc = st_read_real_or_null(st, 6, &R_KG, &o, &c.gvw_max_kg, err, errlen);
        if (rc == 0 && *n < max)
            out[(*n)++] = c;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "classes", err, errlen);
    sqlite3_finalize(st);
    if (rc != 0)
        *n = 0;
    return rc;
}

/* ---- meta by prefix ------------------------------------------------------- */

int amfi_store_web_meta(amfi_store *s, const char *prefix, amfi_web_meta_fn fn, void *ctx,
                        char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!prefix || !fn))
        rc = st_fail(err, errlen, AMFI_EINVAL, "meta: no prefix or function");
    if (rc == 0 && strlen(prefix) > AMFI_STORE_META_KEY_MAX)
        rc = st_fail(err, errlen, AMFI_EINVAL, "meta: prefix longer than %d bytes",
                     AMFI_STORE_META_KEY_MAX);
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s, "SELECT key, value FROM meta WHERE substr(key, 1, length(?1)) = ?1 "
                       "ORDER BY key", &st, "meta", err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_text(st, 1, prefix, -1, SQLITE_TRANSIENT);
    int src = SQLITE_DONE;
    char key[AMFI_STORE_META_KEY_MAX + 1], *val = malloc(AMFI_STORE_META_VALUE_MAX + 1);
    if (!val)
        rc = st_fail(err, errlen, AMFI_ENOMEM, "meta: out of memory");
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"meta", -1};
        rc = st_read_text(st, 0, AMFI_STORE_META_KEY_MAX, &o, key, sizeof key, err, errlen);
        if (rc == 0)
            rc = st_read_text(st, 1, AMFI_STORE_META_VALUE_MAX, &o, val,
                              AMFI_STORE_META_VALUE_MAX + 1, err, errlen);
        if (rc == 0)
            rc = fn(ctx, key, val);
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "meta", err, errlen);
    free(val);
    sqlite3_finalize(st);
    return rc;
}
