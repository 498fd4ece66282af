/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_read.c: what amfid reads back at start-up (the baseline, the newest
 * ok GVWs, meta keys, whether an alert is open), the typed column readers
 * every read uses (type and range checked: a damaged row is
 * AMFI_STORE_ECORRUPT naming its table, rowid and column), the read shapes
 * the other readers share (rows into a growing array, whether a table
 * exists, a passage's axles), and the integrity check. The caller's thread; no state beyond the handle.
 */
#include <limits.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "store_internal.h"

/* ---- reads: every value checked --------------------------------------- */

/* "TABLE row N" (or "TABLE" for an aggregate) into buf. */
static const char *where(const origin *o, char buf[96])
{
    if (o->rowid < 0)
        snprintf(buf, 96, "%s", o->table);
    else
        snprintf(buf, 96, "%s row %lld", o->table, (long long)o->rowid);
    return buf;
}

int st_corrupt(const origin *o, sqlite3_stmt *st, int col, char *err,
               size_t errlen, const char *problem)
{
    char w[96];
    return st_fail(err, errlen, AMFI_STORE_ECORRUPT, "%s: %s %s", where(o, w),
                   sqlite3_column_name(st, col), problem);
}

static const char *type_name(int t)
{
    switch (t) {
    case SQLITE_INTEGER: return "an integer";
    case SQLITE_FLOAT: return "a real";
    case SQLITE_TEXT: return "text";
    case SQLITE_BLOB: return "a blob";
    default: return "NULL";
    }
}

/* A number (integer or real storage) within rg; NULL is refused. */
int st_read_real(sqlite3_stmt *st, int col, const range *rg,
                     const origin *o, double *out, char *err, size_t errlen)
{
    char problem[96];
    int t = sqlite3_column_type(st, col);
    if (t != SQLITE_FLOAT && t != SQLITE_INTEGER) {
        snprintf(problem, sizeof problem, "is %s, expected a number",
                 type_name(t));
        return st_corrupt(o, st, col, err, errlen, problem);
    }
    double x = sqlite3_column_double(st, col);
    if (!isfinite(x) || !st_in_range(x, rg)) {
        char name[192], w[96];
        snprintf(name, sizeof name, "%s: %s", where(o, w),
                 sqlite3_column_name(st, col));
        if (!isfinite(x))
            return st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                        "%s: %g is not finite", name, x);
        return st_range_fail("", name, x, rg, AMFI_STORE_ECORRUPT, err, errlen);
    }
    *out = x;
    return 0;
}

int st_read_real_or_null(sqlite3_stmt *st, int col, const range *rg,
                         const origin *o, double *out, char *err,
                         size_t errlen)
{
    if (sqlite3_column_type(st, col) == SQLITE_NULL) {
        *out = NAN;
        return 0;
    }
    return st_read_real(st, col, rg, o, out, err, errlen);
}

/* An integer (integer storage) in lo .. hi. */
int st_read_int(sqlite3_stmt *st, int col, int64_t lo, int64_t hi,
                    const origin *o, int64_t *out, char *err, size_t errlen)
{
    char problem[96];
    int t = sqlite3_column_type(st, col);
    if (t != SQLITE_INTEGER) {
        snprintf(problem, sizeof problem, "is %s, expected an integer",
                 type_name(t));
        return st_corrupt(o, st, col, err, errlen, problem);
    }
    int64_t v = sqlite3_column_int64(st, col);
    if (v < lo || v > hi) {
        snprintf(problem, sizeof problem, "= %lld is out of range [%lld, %lld]",
                 (long long)v, (long long)lo, (long long)hi);
        return st_corrupt(o, st, col, err, errlen, problem);
    }
    *out = v;
    return 0;
}

/* Text of at most max bytes, valid UTF-8 without control characters, into
 * buf (buflen > max is the caller's business; a value longer than
 * buflen − 1 but within max is AMFI_EINVAL: the buffer, not the row). */
int st_read_text(sqlite3_stmt *st, int col, size_t max, const origin *o,
                     char *buf, size_t buflen, char *err, size_t errlen)
{
    char problem[96];
    int t = sqlite3_column_type(st, col), bad;
    if (t != SQLITE_TEXT) {
        snprintf(problem, sizeof problem, "is %s, expected text", type_name(t));
        return st_corrupt(o, st, col, err, errlen, problem);
    }
    const unsigned char *txt = sqlite3_column_text(st, col);
    size_t n = (size_t)sqlite3_column_bytes(st, col);
    char w[96];
    if (!txt)
        return st_fail(err, errlen, AMFI_ENOMEM, "%s: out of memory",
                       where(o, w));
    if (n > max) {
        snprintf(problem, sizeof problem, "is %zu bytes, at most %zu allowed",
                 n, max);
        return st_corrupt(o, st, col, err, errlen, problem);
    }
    st_utf8_scan(txt, n, &bad);
    if (bad || memchr(txt, '\0', n))
        return st_corrupt(o, st, col, err, errlen,
                       "holds a control character or invalid UTF-8");
    if (n >= buflen)
        return st_fail(err, errlen, AMFI_EINVAL,
                    "%s: %s is %zu bytes, the buffer holds %zu",
                    where(o, w), sqlite3_column_name(st, col), n,
                    buflen > 0 ? buflen - 1 : 0);
    memcpy(buf, txt, n);
    buf[n] = '\0';
    return 0;
}

int amfi_store_get_baseline(amfi_store *s, amfi_baseline *b, int *found,
                            char *err, size_t errlen)
{
    amfi_baseline tmp;
    int64_t v = 0;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!b || !found))
        rc = st_fail(err, errlen, AMFI_EINVAL, "baseline: output is NULL");
    if (rc != 0)
        return rc;
    *found = 0;
    memset(&tmp, 0, sizeof tmp);
    sqlite3_stmt *st = s->st[ST_GET_BASELINE];
    int src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"baseline", sqlite3_column_int64(st, 0)};
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &tmp.utime_set, err,
                      errlen);
        if (rc == 0)
            rc = st_read_int(st, 2, 2, INT_MAX, &o, &v, err, errlen);
        tmp.n = (int)v;
        if (rc == 0)
            rc = st_read_real(st, 3, &R_KG_POS, &o, &tmp.mean_kg, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 4, &R_KG_POS, &o, &tmp.std_kg, err, errlen);
        if (rc == 0)
            rc = st_read_text(st, 5, sizeof tmp.source - 1, &o, tmp.source,
                           sizeof tmp.source, err, errlen);
        if (rc == 0 && st_check_enum("source", tmp.source, st_sources, "", NULL, 0))
            rc = st_corrupt(&o, st, 5, err, errlen, "is neither auto nor manual");
        if (rc == 0)
            rc = st_read_text(st, 6, sizeof tmp.note - 1, &o, tmp.note,
                           sizeof tmp.note, err, errlen);
        if (rc == 0) {
            *b = tmp;
            *found = 1;
        }
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "baseline: read", err, errlen);
    }
    sqlite3_reset(st);
    return rc;
}

/* The rows of a bound statement "SELECT id, gvw_kg, gvw_comp_kg ... ORDER BY
 * utime DESC ... LIMIT max" into gvw[], oldest first: the weight fed
 * (version 8), else the GVW, each checked by its own name. what names the
 * read in messages. */
static int recent_gvw_rows(amfi_store *s, sqlite3_stmt *st, int max, const char *what,
                           double *gvw, int *n, char *err, size_t errlen)
{
    int rc = 0, src, count = 0;
    /* newest first into gvw[0 ..], reversed below */
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        if (count >= max)
            rc = st_fail(err, errlen, AMFI_STORE_EDB, "%s: more rows than the LIMIT", what);
        else
            rc = st_read_real(st, sqlite3_column_type(st, 2) == SQLITE_NULL ? 1 : 2, &R_KG_POS,
                              &o, &gvw[count], err, errlen);
        if (rc == 0)
            count++;
    }
    if (rc == 0 && src != SQLITE_DONE) {
        char m[64];
        snprintf(m, sizeof m, "passages: read %s", what);
        rc = st_db_fail(s, src, m, err, errlen);
    }
    if (rc != 0)
        return rc;
    for (int i = 0, j = count - 1; i < j; i++, j--) {
        double t = gvw[i];
        gvw[i] = gvw[j];
        gvw[j] = t;
    }
    *n = count;
    return 0;
}

int amfi_store_recent_ok_gvw(amfi_store *s, int max, double *gvw, int *n,
                             char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_OK;
    if (rc == 0 && (!gvw || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "recent ok GVW: output is NULL");
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "recent ok GVW: max %d must be >= 1",
                  max);
    if (rc != 0)
        return rc;
    *n = 0;
    sqlite3_stmt *st = s->st[ST_RECENT_OK];
    src = sqlite3_bind_int(st, 1, max);
    if (src == SQLITE_OK)
        rc = recent_gvw_rows(s, st, max, "recent ok GVW", gvw, n, err, errlen);
    else
        rc = st_db_fail(s, src, "passages: read recent ok GVW", err, errlen);
    st_done_with(st);
    return rc;
}

int amfi_store_recent_fed_gvw(amfi_store *s, int max, const char *const *classes,
                              int n_classes, double min_kg, int single_only, double *gvw,
                              int *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_OK;
    if (rc == 0 && (!gvw || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "recent fed GVW: output is NULL");
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "recent fed GVW: max %d must be >= 1", max);
    if (rc == 0 && (n_classes < 0 || n_classes > 64 || (n_classes > 0 && !classes)))
        rc = st_fail(err, errlen, AMFI_EINVAL, "recent fed GVW: %d classes (0 .. 64)",
                     n_classes);
    for (int k = 0; rc == 0 && k < n_classes; k++)
        if (!classes[k] || !classes[k][0] || strlen(classes[k]) > 15)
            rc = st_fail(err, errlen, AMFI_EINVAL,
                         "recent fed GVW: class %d is empty or longer than 15 bytes", k);
    if (rc == 0 && !(min_kg >= 0.0 && min_kg <= AMFI_STORE_MAX_KG))
        rc = st_fail(err, errlen, AMFI_EINVAL, "recent fed GVW: min_kg %g out of [0, %g]",
                     min_kg, (double)AMFI_STORE_MAX_KG);
    if (rc != 0)
        return rc;
    *n = 0;
    /* the same rows, in the same order, as recent_ok_gvw, restricted */
    char sql[1024];
    size_t len = (size_t)snprintf(sql, sizeof sql,
                                  "SELECT id, gvw_kg, gvw_comp_kg FROM passages WHERE status = 'ok'"
                                  " AND coalesce(gvw_comp_kg, gvw_kg) >= ?2%s",
                                  single_only ? " AND coalesce(n_vehicles, 1) <= 1" : "");
    for (int k = 0; k < n_classes; k++)
        len += (size_t)snprintf(sql + len, sizeof sql - len, "%s?%d", k ? ", " : " AND class IN (",
                                k + 3);
    len += (size_t)snprintf(sql + len, sizeof sql - len, "%s ORDER BY utime DESC, id DESC LIMIT ?1",
                            n_classes ? ")" : "");
    sqlite3_stmt *st = NULL;
    src = sqlite3_prepare_v2(s->db, sql, -1, &st, NULL);
    if (src == SQLITE_OK)
        src = sqlite3_bind_int(st, 1, max);
    if (src == SQLITE_OK)
        src = sqlite3_bind_double(st, 2, min_kg);
    for (int k = 0; src == SQLITE_OK && k < n_classes; k++)
        src = sqlite3_bind_text(st, k + 3, classes[k], -1, SQLITE_TRANSIENT);
    if (src == SQLITE_OK)
        rc = recent_gvw_rows(s, st, max, "recent fed GVW", gvw, n, err, errlen);
    else
        rc = st_db_fail(s, src, "passages: read recent fed GVW", err, errlen);
    sqlite3_finalize(st);
    return rc;
}

int amfi_store_meta_get(amfi_store *s, const char *key, char *val,
                        size_t vallen, int *found, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!val || vallen == 0 || !found))
        rc = st_fail(err, errlen, AMFI_EINVAL, "meta: output is NULL or empty");
    if (rc == 0)
        rc = st_check_meta_key(key, err, errlen);
    if (rc != 0)
        return rc;
    *found = 0;
    val[0] = '\0';
    sqlite3_stmt *st = s->st[ST_META_GET];
    int src = st_bind_text(st, 1, key);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"meta", sqlite3_column_int64(st, 0)};
        rc = st_read_text(st, 1, AMFI_STORE_META_VALUE_MAX, &o, val, vallen, err,
                       errlen);
        if (rc == 0)
            *found = 1;
        else
            val[0] = '\0';
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "meta: read", err, errlen);
    }
    st_done_with(st);
    return rc;
}

/* ---- alerts --------------------------------------------------------------- */

int amfi_store_alert_open(amfi_store *s, const char *kind, int *open,
                          char *err, size_t errlen)
{
    int64_t raised = 0;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && !open)
        rc = st_fail(err, errlen, AMFI_EINVAL, "alerts: output is NULL");
    if (rc == 0)
        rc = st_check_token("alerts.kind", kind, 31, "_", 1, err, errlen);
    if (rc != 0)
        return rc;
    *open = 0;
    sqlite3_stmt *st = s->st[ST_ALERT_LAST_OF_KIND];
    int src = st_bind_text(st, 1, kind);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"alerts", sqlite3_column_int64(st, 0)};
        rc = st_read_int(st, 1, 0, 1, &o, &raised, err, errlen);
        if (rc == 0)
            *open = raised == 1;
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "alerts: read", err, errlen);
    }
    st_done_with(st);
    return rc;
}

/* ---- maintenance -------------------------------------------------------- */

/* Append "; " (unless first) and piece to result (len > 0), truncating. */
static void append(char *result, size_t len, const char *piece)
{
    size_t used = strlen(result);
    if (used + 1 >= len)
        return;
    snprintf(result + used, len - used, "%s%s", used ? "; " : "", piece);
}

int amfi_store_integrity_check(amfi_store *s, char *result, size_t len,
                               char *err, size_t errlen)
{
    char piece[256];
    int rc = st_check_handle(s, 0, err, errlen), src, clean = 1;
    if (rc == 0 && (!result || len == 0))
        rc = st_fail(err, errlen, AMFI_EINVAL, "integrity check: result is NULL");
    if (rc != 0)
        return rc;
    result[0] = '\0';
    sqlite3_stmt *st = s->st[ST_INTEGRITY];
    while ((src = sqlite3_step(st)) == SQLITE_ROW) {
        const unsigned char *t = sqlite3_column_text(st, 0);
        if (t && strcmp((const char *)t, "ok") == 0)
            continue;
        clean = 0;
        append(result, len, t ? (const char *)t : "(no message)");
    }
    if (src != SQLITE_DONE)
        rc = st_db_fail(s, src, "integrity check", err, errlen);
    sqlite3_reset(st);
    st = s->st[ST_FK_CHECK];
    /* rows: table, rowid (NULL for WITHOUT ROWID), parent, constraint */
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        const unsigned char *tab = sqlite3_column_text(st, 0);
        const unsigned char *par = sqlite3_column_text(st, 2);
        clean = 0;
        if (sqlite3_column_type(st, 1) == SQLITE_NULL)
            snprintf(piece, sizeof piece, "foreign key: a %s row refers to a "
                     "missing %s row", tab ? (const char *)tab : "?",
                     par ? (const char *)par : "?");
        else
            snprintf(piece, sizeof piece, "foreign key: %s row %lld refers to "
                     "a missing %s row", tab ? (const char *)tab : "?",
                     (long long)sqlite3_column_int64(st, 1),
                     par ? (const char *)par : "?");
        append(result, len, piece);
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "foreign key check", err, errlen);
    sqlite3_reset(st);
    if (rc != 0) {
        /* too damaged to check: the message is the result too */
        if (err && errlen > 0)
            snprintf(result, len, "%s", err);
        else
            snprintf(result, len, "%s", amfi_store_strerror(rc));
        return rc;
    }
    if (clean)
        snprintf(result, len, "ok");
    return 0;
}

/* ---- shared read shapes ---------------------------------------------------- */

int st_collect(amfi_store *s, sqlite3_stmt *st, st_row_fn row, const void *ctx, size_t size,
               size_t cap0,
               const char *what, const char *noun, void **arr, size_t *n, char *err,
               size_t errlen)
{
    unsigned char *a = NULL;
    size_t k = 0, cap = 0;
    int rc = 0, src = SQLITE_DONE;
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        if (k == cap) {
            size_t nc = cap ? 2 * cap : cap0;
            unsigned char *na = realloc(a, nc * size);
            if (!na) {
                rc = st_fail(err, errlen, AMFI_ENOMEM, "out of memory for %zu %s", nc, noun);
                break;
            }
            a = na;
            cap = nc;
        }
        rc = row(st, ctx, a + k * size, err, errlen);
        if (rc == 0)
            k++;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, what, err, errlen);
    sqlite3_finalize(st);
    if (rc != 0 || k == 0) {
        free(a);
        a = NULL;
        k = 0;
    }
    *arr = a;
    *n = k;
    return rc;
}

int st_has_table(amfi_store *s, const char *name, int *yes, char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int rc = st_prepare(s, "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND name = ?1",
                        &st, "raw samples: schema", err, errlen);
    if (rc != 0)
        return rc;
    int src = sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_ROW)
        *yes = sqlite3_column_int(st, 0) > 0;
    else
        rc = st_db_fail(s, src, "raw samples: schema", err, errlen);
    sqlite3_finalize(st);
    return rc;
}

int st_read_axles(amfi_store *s, sqlite3_stmt *st, int64_t id, amfi_passage_row *r, int *seen,
                  const char *what, char *err, size_t errlen)
{
    origin o = {"axles", id};
    int rc = 0, k = 0, src = sqlite3_bind_int64(st, 1, id);
    while (rc == 0 && src == SQLITE_OK && (src = sqlite3_step(st)) == SQLITE_ROW) {
        int64_t idx = 0;
        rc = st_read_int(st, 0, 1, r->n_axles, &o, &idx, err, errlen);
        if (rc == 0 && idx > 1) /* axle 1 has no spacing (NULL, a CHECK of the schema) */
            rc = st_read_real_or_null(st, 1, &R_SPACING, &o, &r->spacing_m[idx - 2], err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 2, &R_KG, &o, &r->axle_kg[idx - 1], err, errlen);
        k++;
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, what, err, errlen);
    if (seen)
        *seen = k;
    return rc;
}
