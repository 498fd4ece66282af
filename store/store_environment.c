/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_environment.c: the bridge's environment (issue 14): the readings
 * amfid received on its environment channel (environment_t), stored in
 * batches (one transaction per batch, all or nothing), the deck temperature
 * at a given data time (interpolated between the two readings around it
 * within a maximum gap), and the summary amfi-report prints; and amfid's
 * periodic summaries of refused bus messages (table refusals). Every value
 * read back is checked as in store_read.c. The caller's thread; the
 * statements are prepared and finalized per call (no state in the handle).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

int amfi_store_add_environment(amfi_store *s, const amfi_environment_row *rows, int n,
                               char *err, size_t errlen)
{
    return st_insert_rows(s, "environment", rows, n, sizeof *rows, 1, NULL, err, errlen);
}

/* The reading nearest to utime on one side (before: utime <= t, newest;
 * else utime >= t, oldest): *found 0 when none. */
static int one_side(amfi_store *s, int64_t t, int before, int64_t *u, double *deck, int *found,
                    char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int rc = st_prepare(s,
                     before ? "SELECT id, utime, deck_c FROM environment WHERE utime <= ?1 "
                              "ORDER BY utime DESC, id DESC LIMIT 1"
                            : "SELECT id, utime, deck_c FROM environment WHERE utime >= ?1 "
                              "ORDER BY utime ASC, id ASC LIMIT 1",
                     &st, "environment: prepare lookup", err, errlen);
    *found = 0;
    if (rc != 0)
        return rc;
    int src = sqlite3_bind_int64(st, 1, t);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"environment", sqlite3_column_int64(st, 0)};
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, u, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 2, &R_TEMP_C, &o, deck, err, errlen);
        *found = rc == 0;
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "environment: lookup", err, errlen);
    }
    sqlite3_finalize(st);
    return rc;
}

int amfi_store_deck_c_at(amfi_store *s, int64_t utime, int64_t max_gap_us, double *deck_c,
                         char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && !deck_c)
        rc = st_fail(err, errlen, AMFI_EINVAL, "environment: output is NULL");
    if (rc == 0)
        rc = st_check_utime("environment: utime asked", utime, err, errlen);
    if (rc == 0 && max_gap_us < 0)
        rc = st_fail(err, errlen, AMFI_EINVAL, "environment: max_gap_us %lld is negative",
                     (long long)max_gap_us);
    if (rc != 0)
        return rc;
    *deck_c = NAN;
    int64_t u0 = 0, u1 = 0;
    double d0 = NAN, d1 = NAN;
    int f0 = 0, f1 = 0;
    rc = one_side(s, utime, 1, &u0, &d0, &f0, err, errlen);
    if (rc == 0)
        rc = one_side(s, utime, 0, &u1, &d1, &f1, err, errlen);
    if (rc != 0)
        return rc;
    if (f0 && f1) {
        if (u1 == u0) /* a reading at utime itself */
            *deck_c = d0;
        else if (u1 - u0 <= max_gap_us) /* between two readings close enough */
            *deck_c = d0 + (d1 - d0) * (double)(utime - u0) / (double)(u1 - u0);
        else if (utime - u0 <= max_gap_us / 2) /* nearest, within half the gap */
            *deck_c = d0;
        else if (u1 - utime <= max_gap_us / 2)
            *deck_c = d1;
    } else if (f0 && utime - u0 <= max_gap_us / 2) { /* after the last reading */
        *deck_c = d0;
    } else if (f1 && u1 - utime <= max_gap_us / 2) { /* before the first */
        *deck_c = d1;
    }
    return 0;
}

int amfi_store_environment_summary(amfi_store *s, amfi_environment_summary *out, char *err,
                                   size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && !out)
        rc = st_fail(err, errlen, AMFI_EINVAL, "environment: output is NULL");
    if (rc == 0)
        rc = st_prepare(s,
                     "SELECT count(*), min(utime), max(utime), min(deck_c), max(deck_c), "
                     "min(air_c), max(air_c) FROM environment",
                     &st, "environment: prepare summary", err, errlen);
    if (rc != 0)
        return rc;
    amfi_environment_summary r;
    memset(&r, 0, sizeof r);
    r.deck_min_c = r.deck_max_c = r.air_min_c = r.air_max_c = NAN;
    origin o = {"environment", -1};
    int src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        rc = st_read_int(st, 0, 0, INT64_MAX, &o, &r.n, err, errlen);
        if (rc == 0 && r.n > 0)
            rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime_first, err, errlen);
        if (rc == 0 && r.n > 0)
            rc = st_read_int(st, 2, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime_last, err, errlen);
        if (rc == 0 && r.n > 0)
            rc = st_read_real(st, 3, &R_TEMP_C, &o, &r.deck_min_c, err, errlen);
        if (rc == 0 && r.n > 0)
            rc = st_read_real(st, 4, &R_TEMP_C, &o, &r.deck_max_c, err, errlen);
        if (rc == 0 && r.n > 0)
            rc = st_read_real(st, 5, &R_TEMP_C, &o, &r.air_min_c, err, errlen);
        if (rc == 0 && r.n > 0)
            rc = st_read_real(st, 6, &R_TEMP_C, &o, &r.air_max_c, err, errlen);
    } else {
        rc = st_db_fail(s, src, "environment: summary", err, errlen);
    }
    sqlite3_finalize(st);
    if (rc == 0)
        *out = r;
    return rc;
}

int amfi_store_environment_rows(amfi_store *s, amfi_environment_row **out, size_t *n, char *err,
                                size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "environment: output is NULL");
    const amfi_store_tabledef *t = amfi_store_tabledef_find("environment");
    char list[256], sql[384];
    if (rc == 0 && st_select_list(t, list, sizeof list) == 0)
        snprintf(sql, sizeof sql, "SELECT id, %s FROM environment ORDER BY utime, id", list);
    if (rc == 0)
        rc = st_prepare(s, sql, &st, "environment: prepare rows", err, errlen);
    if (rc != 0)
        return rc;
    *out = NULL;
    *n = 0;
    amfi_environment_row *v = NULL;
    size_t cap = 0, k = 0;
    int src = SQLITE_DONE;
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        if (k == cap) {
            size_t nc = cap ? 2 * cap : 1024;
            amfi_environment_row *nv = realloc(v, sizeof *v * nc);
            if (!nv) {
                rc = st_fail(err, errlen, AMFI_ENOMEM, "environment: out of memory");
                break;
            }
            v = nv;
            cap = nc;
        }
        origin o = {"environment", sqlite3_column_int64(st, 0)};
        rc = st_read_row(st, 1, t, &v[k], &o, err, errlen);
        k++;
        src = SQLITE_DONE;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "environment: rows", err, errlen);
    sqlite3_finalize(st);
    if (rc != 0 || k == 0) {
        free(v);
        return rc;
    }
    *out = v;
    *n = k;
    return 0;
}

int amfi_store_add_refusals(amfi_store *s, const amfi_refusal_row *rows, int n, char *err,
                            size_t errlen)
{
    /* what the column table cannot say: the period's order */
    for (int k = 0; n > 0 && rows && k < n; k++)
        if (rows[k].period_end < rows[k].period_start)
            return st_fail(err, errlen, AMFI_EINVAL,
                           "refusals[%d].period_end: %lld is before period_start %lld", k,
                           (long long)rows[k].period_end, (long long)rows[k].period_start);
    return st_insert_rows(s, "refusals", rows, n, sizeof *rows, 1, NULL, err, errlen);
}
