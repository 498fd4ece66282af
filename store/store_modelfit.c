/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_modelfit.c: the figures amfid's model_mismatch and natfreq alerts
 * watch, read back after a restart to refill their windows: the newest
 * passages' fit_ratio (schema version 12) and f1_comp_hz (version 7), not
 * NULL, oldest first; and every fit_ratio of a time range, for
 * amfi-report's fit_ratio.png. Every value read back is checked as in store_read.c.
 * The caller's thread; the statement is prepared and finalized per call.
 */
#include <stdint.h>
#include <stdlib.h>

#include "store_internal.h"

/* One value (id, the value) in range rg. */
static int read_value(sqlite3_stmt *st, const void *rg, void *rec, char *err, size_t errlen)
{
    origin o = {"passages", sqlite3_column_int64(st, 0)};
    return st_read_real(st, 1, rg, &o, rec, err, errlen);
}

/* The newest max values of a column (SQL text fixed here: no name reaches
 * SQL from outside: id, the value, not NULL, newest first, LIMIT ?1),
 * oldest first. */
static int recent(amfi_store *s, const char *sql, const char *what, const range *rg, int max,
                  double **out, size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "%s: output is NULL", what);
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "%s: max %d must be >= 1", what, max);
    if (rc != 0)
        return rc;
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s, sql, &st, what, err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_int64(st, 1, max);
    void *v = NULL;
    rc = st_collect(s, st, read_value, rg, sizeof **out, (size_t)max, what, "values", &v, n, err,
                    errlen);
    double *a = v;
    for (size_t i = 0, k = *n; i < k / 2; i++) { /* newest first → oldest first */
        double t = a[i];
        a[i] = a[k - 1 - i];
        a[k - 1 - i] = t;
    }
    *out = a;
    return rc;
}

int amfi_store_recent_fit_ratios(amfi_store *s, int max, double **out, size_t *n, char *err,
                                 size_t errlen)
{
    return recent(s,
                  "SELECT id, fit_ratio FROM passages WHERE fit_ratio IS NOT NULL "
                  "ORDER BY utime DESC, id DESC LIMIT ?1",
                  "passages: read the newest model fits", &R_RATIO, max, out, n, err, errlen);
}

int amfi_store_recent_f1_comp(amfi_store *s, int max, double **out, size_t *n, char *err,
                              size_t errlen)
{
    static const range hz = {0.0, 1000.0, 1, "Hz", 0};
    return recent(s,
                  "SELECT id, f1_comp_hz FROM passages WHERE f1_comp_hz IS NOT NULL "
                  "ORDER BY utime DESC, id DESC LIMIT ?1",
                  "passages: read the newest compensated natural frequencies", &hz, max, out, n,
                  err, errlen);
}

int amfi_store_fit_ratio_series(amfi_store *s, int64_t from, int64_t to, amfi_fit_rec **out,
                                size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "model fits: output is NULL");
    if (rc != 0)
        return rc;
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    amfi_fit_rec *a = NULL;
    size_t k = 0, cap = 0;
    int src = sqlite3_prepare_v2(s->db,
                                 "SELECT id, utime, fit_ratio FROM passages WHERE utime >= ?1 "
                                 "AND utime <= ?2 AND fit_ratio IS NOT NULL ORDER BY utime, id",
                                 -1, &st, NULL);
    if (src != SQLITE_OK) {
        rc = st_db_fail(s, src, "model fits: prepare", err, errlen);
    } else {
        sqlite3_bind_int64(st, 1, from);
        sqlite3_bind_int64(st, 2, to);
        while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
            origin o = {"passages", sqlite3_column_int64(st, 0)};
            amfi_fit_rec r;
            r.passage_id = o.rowid;
            rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime, err, errlen);
            if (rc == 0)
                rc = st_read_real(st, 2, &R_RATIO, &o, &r.fit_ratio, err, errlen);
            if (rc == 0 && k == cap) {
                size_t nc = cap ? 2 * cap : 1024;
                amfi_fit_rec *na = realloc(a, nc * sizeof *na);
                if (!na)
                    rc = st_fail(err, errlen, AMFI_ENOMEM, "out of memory for %zu model fits", nc);
                else
                    a = na, cap = nc;
            }
            if (rc == 0)
                a[k++] = r;
        }
        if (rc == 0 && src != SQLITE_DONE)
            rc = st_db_fail(s, src, "passages: read model fits", err, errlen);
    }
    sqlite3_finalize(st);
    if (rc != 0 || k == 0) {
        free(a);
        return rc;
    }
    *out = a;
    *n = k;
    return 0;
}
