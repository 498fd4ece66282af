/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_report.c: the queries of reports (amfi-report): counts, the passage
 * summary, the ok GVWs, the newest indicators and alerts, the alerts open
 * now, the GVW errors against the truth. Each returns typed rows, every
 * value checked as in store_read.c. The caller's thread; no state beyond
 * the handle (arrays it allocates are the caller's).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

const char *amfi_store_status_name(int k)
{
    return k >= 0 && k < AMFI_STORE_N_STATUS ? st_statuses[k] : NULL;
}
_Static_assert(sizeof st_statuses / sizeof st_statuses[0] == AMFI_STORE_N_STATUS + 1,
               "AMFI_STORE_N_STATUS counts AMFI_STORE_STATUSES");

/* Index of s in a NULL-terminated list, −1 when absent. */
static int index_of(const char *s, const char *const *list)
{
    for (int k = 0; list[k]; k++)
        if (strcmp(s, list[k]) == 0)
            return k;
    return -1;
}

/* A growing array of doubles (malloc'd, the caller's). */
typedef struct vec {
    double *v;
    size_t n, cap;
} vec;

static int vec_push(vec *a, double x, char *err, size_t errlen)
{
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 1024;
        double *v = realloc(a->v, cap * sizeof *v);
        if (!v)
            return st_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        a->v = v;
        a->cap = cap;
    }
    a->v[a->n++] = x;
    return 0;
}

/* rc 0: the array becomes the caller's (*out, *n); else it is freed. */
static int vec_hand_over(vec *a, int rc, double **out, size_t *n)
{
    if (rc != 0) {
        free(a->v);
        return rc;
    }
    *out = a->v;
    *n = a->n;
    return 0;
}

/* Step st to completion: rc 0 with src SQLITE_DONE is a clean end. */
static int end_of(amfi_store *s, int rc, int src, const char *what, char *err,
                  size_t errlen)
{
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, what, err, errlen);
    return rc;
}

int amfi_store_count(amfi_store *s, amfi_store_table t, int64_t *n, char *err,
                     size_t errlen)
{
    static const struct {
        int stmt;
        const char *table;
    } which[] = {{ST_COUNT_PASSAGES, "passages"},
                 {ST_COUNT_INDICATORS, "indicators"},
                 {ST_COUNT_ALERTS, "alerts"},
                 {ST_COUNT_TRUTH, "truth"}};
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && !n)
        rc = st_fail(err, errlen, AMFI_EINVAL, "count: output is NULL");
    if (rc == 0 && ((int)t < 0 || (int)t >= (int)(sizeof which / sizeof which[0])))
        rc = st_fail(err, errlen, AMFI_EINVAL, "count: unknown table %d", (int)t);
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = s->st[which[t].stmt];
    origin o = {which[t].table, -1};
    int src = sqlite3_step(st);
    if (src == SQLITE_ROW)
        rc = st_read_int(st, 0, 0, INT64_MAX, &o, n, err, errlen);
    else
        rc = st_db_fail(s, src, which[t].table, err, errlen);
    st_done_with(st);
    return rc;
}

int amfi_store_passage_summary(amfi_store *s, amfi_passage_summary *out,
                               char *err, size_t errlen)
{
    amfi_passage_summary r;
    origin o = {"passages", -1};
    char ex[48];
    int rc = st_check_handle(s, 0, err, errlen), src;
    if (rc == 0 && !out)
        rc = st_fail(err, errlen, AMFI_EINVAL, "passages: output is NULL");
    if (rc != 0)
        return rc;
    memset(&r, 0, sizeof r);
    sqlite3_stmt *st = s->st[ST_PASSAGE_SPAN];
    src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        rc = st_read_int(st, 0, 0, INT64_MAX, &o, &r.total, err, errlen);
        if (rc == 0 && r.total > 0)
            rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime_first,
                             err, errlen);
        if (rc == 0 && r.total > 0)
            rc = st_read_int(st, 2, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime_last,
                             err, errlen);
    } else {
        rc = st_db_fail(s, src, "passages: time span", err, errlen);
    }
    st_done_with(st);
    st = s->st[ST_PASSAGE_BY_STATUS];
    src = SQLITE_DONE;
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        char name[64];
        int64_t n = 0;
        rc = st_read_text(st, 0, sizeof name - 1, &o, name, sizeof name, err,
                          errlen);
        if (rc == 0)
            rc = st_read_int(st, 1, 0, INT64_MAX, &o, &n, err, errlen);
        int k = rc == 0 ? index_of(name, st_statuses) : -1;
        if (rc == 0 && k < 0)
            rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                         "passages: %lld rows have the unknown status '%s'",
                         (long long)n, st_excerpt(name, ex));
        if (rc == 0)
            r.by_status[k] = n;
    }
    rc = end_of(s, rc, src, "passages: count by status", err, errlen);
    st_done_with(st);
    if (rc == 0)
        *out = r;
    return rc;
}

/* The weights of statement `which` (id, weight), each in (0, 1e6] kg. */
static int all_weights(amfi_store *s, int which, double **gvw, size_t *n, char *err,
                       size_t errlen)
{
    vec g = {0};
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_DONE;
    if (rc == 0 && (!gvw || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "ok GVW: output is NULL");
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = s->st[which];
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        double x = 0;
        rc = st_read_real(st, 1, &R_FINITE, &o, &x, err, errlen);
        if (rc == 0 && !(x > 0 && x <= AMFI_STORE_MAX_KG))
            rc = st_corrupt(&o, st, 1, err, errlen,
                            "is out of range for an ok passage");
        if (rc == 0)
            rc = vec_push(&g, x, err, errlen);
    }
    rc = end_of(s, rc, src, "passages: read ok GVW", err, errlen);
    st_done_with(st);
    return vec_hand_over(&g, rc, gvw, n);
}

int amfi_store_all_ok_gvw(amfi_store *s, double **gvw, size_t *n, char *err,
                          size_t errlen)
{
    return all_weights(s, ST_ALL_OK_GVW, gvw, n, err, errlen);
}

int amfi_store_all_fed_gvw(amfi_store *s, double **gvw, size_t *n, char *err,
                           size_t errlen)
{
    return all_weights(s, ST_ALL_FED_GVW, gvw, n, err, errlen);
}

int amfi_store_recent_indicators(amfi_store *s, int max,
                                 amfi_indicator_rec *out, int *n, char *err,
                                 size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_DONE, count = 0;
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "indicators: output is NULL");
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "indicators: max %d must be >= 1",
                     max);
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = s->st[ST_RECENT_INDICATORS];
    src = sqlite3_bind_int(st, 1, max);
    while (rc == 0 && src == SQLITE_OK && count < max
           && (src = sqlite3_step(st)) == SQLITE_ROW) {
        amfi_indicator_rec *r = &out[count];
        origin o = {"indicators", sqlite3_column_int64(st, 0)};
        memset(r, 0, sizeof *r);
        r->id = o.rowid;
        rc = st_read_row(st, 1, amfi_store_tabledef_find("indicators"), &r->row, &o, err, errlen);
        if (rc == 0)
            count++;
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_OK && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "indicators: read", err, errlen);
    st_done_with(st);
    *n = count;
    return rc;
}

/* Columns id, utime, level, kind, raised, indicator_id, message. */
static int read_alert(sqlite3_stmt *st, amfi_alert_rec *r, char *err,
                      size_t errlen)
{
    origin o = {"alerts", sqlite3_column_int64(st, 0)};
    int64_t v = 0;
    char level[16];
    memset(r, 0, sizeof *r);
    r->id = o.rowid;
    int rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r->utime, err, errlen);
    if (rc == 0)
        rc = st_read_text(st, 2, sizeof level - 1, &o, level, sizeof level, err, errlen);
    if (rc == 0 && index_of(level, st_levels) < 0)
        rc = st_corrupt(&o, st, 2, err, errlen, "is neither info nor warning");
    if (rc == 0)
        r->level = st_levels[index_of(level, st_levels)];
    if (rc == 0)
        rc = st_read_text(st, 3, sizeof r->kind - 1, &o, r->kind, sizeof r->kind,
                          err, errlen);
    if (rc == 0)
        rc = st_read_int(st, 4, 0, 1, &o, &v, err, errlen);
    r->raised = (int)v;
    if (rc == 0 && sqlite3_column_type(st, 5) != SQLITE_NULL)
        rc = st_read_int(st, 5, 1, INT64_MAX, &o, &r->indicator_id, err, errlen);
    if (rc == 0) {
        /* any text, shown on one line: control characters as '?' */
        const unsigned char *t = sqlite3_column_text(st, 6);
        size_t len = (size_t)sqlite3_column_bytes(st, 6), k = 0;
        if (sqlite3_column_type(st, 6) != SQLITE_TEXT || !t || memchr(t, '\0', len))
            rc = st_corrupt(&o, st, 6, err, errlen, "is not text");
        for (; rc == 0 && k < len && k < sizeof r->message - 1; k++)
            r->message[k] = (t[k] < 0x20 || t[k] == 0x7f) ? '?' : (char)t[k];
        r->message[k] = '\0';
    }
    return rc;
}

int amfi_store_recent_alerts(amfi_store *s, int max, amfi_alert_rec *out,
                             int *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_DONE, count = 0;
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "alerts: output is NULL");
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "alerts: max %d must be >= 1", max);
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = s->st[ST_RECENT_ALERTS];
    src = sqlite3_bind_int(st, 1, max);
    while (rc == 0 && src == SQLITE_OK && count < max
           && (src = sqlite3_step(st)) == SQLITE_ROW) {
        rc = read_alert(st, &out[count], err, errlen);
        if (rc == 0)
            count++;
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_OK && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "alerts: read", err, errlen);
    st_done_with(st);
    *n = count;
    return rc;
}

int amfi_store_open_alerts(amfi_store *s, amfi_alert_rec **out, int *n,
                           char *err, size_t errlen)
{
    amfi_alert_rec *a = NULL;
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_DONE, count = 0, cap = 0;
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "alerts: output is NULL");
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = s->st[ST_OPEN_ALERTS];
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        if (count == cap) {
            int nc = cap ? 2 * cap : 4;
            amfi_alert_rec *na = realloc(a, (size_t)nc * sizeof *na);
            if (!na) {
                rc = st_fail(err, errlen, AMFI_ENOMEM, "out of memory");
                break;
            }
            a = na;
            cap = nc;
        }
        rc = read_alert(st, &a[count], err, errlen);
        if (rc == 0)
            count++;
    }
    rc = end_of(s, rc, src, "alerts: read open", err, errlen);
    st_done_with(st);
    if (rc != 0 || count == 0) {
        free(a);
        a = NULL;
        count = rc != 0 ? 0 : count;
    }
    *out = a;
    *n = count;
    return rc;
}

int amfi_store_gvw_errors(amfi_store *s, double **pct, size_t *n,
                          int64_t *n_other, char *err, size_t errlen)
{
    vec e = {0};
    int64_t other = 0;
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_DONE;
    if (rc == 0 && (!pct || !n || !n_other))
        rc = st_fail(err, errlen, AMFI_EINVAL, "GVW errors: output is NULL");
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = s->st[ST_GVW_ERRORS];
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        char status[16];
        double x = 0;
        rc = st_read_text(st, 1, sizeof status - 1, &o, status, sizeof status, err,
                          errlen);
        if (rc == 0 && strcmp(status, "ok") != 0) {
            other++;
            continue;
        }
        if (rc == 0)
            rc = st_read_real(st, 2, &R_FINITE, &o, &x, err, errlen);
        if (rc == 0)
            rc = vec_push(&e, x, err, errlen);
    }
    rc = end_of(s, rc, src, "passage_errors: read", err, errlen);
    st_done_with(st);
    if (rc == 0)
        *n_other = other;
    return vec_hand_over(&e, rc, pct, n);
}
