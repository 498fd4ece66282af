/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_speed.c: the speeds of the passages whose speed was estimated
 * (issue 12): the detector's and the one weighed with, for amfi-report's
 * speed corrections (a filtered range, oldest first) and for amfid's
 * speed-drift alert (the newest N, refilled at start-up). Every value read
 * back is checked as in store_read.c. The caller's thread; the statements
 * are prepared and finalized per call (no state kept in the handle).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

int amfi_store_has_estimated(amfi_store *s, int *yes, char *err, size_t errlen)
{
    int64_t v = 0;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && !yes)
        rc = st_fail(err, errlen, AMFI_EINVAL, "speeds: output is NULL");
    if (rc == 0)
        rc = st_one_off(s, "SELECT EXISTS (SELECT 1 FROM passages WHERE speed_estimated = 1 "
                           "AND speed_mps > 0 AND speed_given_mps > 0)",
                        "passages: estimated speeds", &v, NULL, 0, err, errlen);
    if (rc == 0)
        *yes = v != 0;
    return rc;
}

/* One row (id, utime, speed_mps, speed_given_mps). */
static int read_pair(sqlite3_stmt *st, const void *ctx, void *rec, char *err, size_t errlen)
{
    (void)ctx;
    amfi_speed_pair *p = rec;
    origin o = {"passages", sqlite3_column_int64(st, 0)};
    int rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &p->utime, err, errlen);
    if (rc == 0)
        rc = st_read_real(st, 2, &R_SPEED_POS, &o, &p->speed_mps, err, errlen);
    if (rc == 0)
        rc = st_read_real(st, 3, &R_SPEED_POS, &o, &p->speed_given_mps, err, errlen);
    return rc;
}

/* Run one of the two queries (SQL parameters: ?1 .. ?4 the filter's from,
 * to, status, lane; or ?1 the limit) into *out. */
static int query_pairs(amfi_store *s, const char *sql, const amfi_passage_filter *f, int max,
                       amfi_speed_pair **out, size_t *n, char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    *out = NULL;
    *n = 0;
    int rc = st_prepare(s, sql, &st, "speeds: prepare", err, errlen);
    if (rc != 0)
        return rc;
    if (f) {
        sqlite3_bind_int64(st, 1, f->from);
        sqlite3_bind_int64(st, 2, f->to);
        if (f->status)
            sqlite3_bind_text(st, 3, f->status, -1, SQLITE_TRANSIENT);
        if (f->lane_given)
            sqlite3_bind_int(st, 4, f->lane);
    } else {
        sqlite3_bind_int(st, 1, max);
    }
    void *a = NULL;
    rc = st_collect(s, st, read_pair, NULL, sizeof **out, 256, "passages: read estimated speeds",
                    "speeds", &a, n, err, errlen);
    *out = a;
    return rc;
}

int amfi_store_speed_pairs(amfi_store *s, const amfi_passage_filter *f, amfi_speed_pair **out,
                           size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!f || !out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "speeds: no filter or output");
    if (rc == 0 && f->lane_given && (f->lane < -32768 || f->lane > 32767))
        rc = st_fail(err, errlen, AMFI_EINVAL, "speeds: lane %d outside [-32768, 32767]",
                     f->lane);
    if (rc == 0 && f->status
        && st_check_enum("speeds: status", f->status, st_statuses, AMFI_STORE_STATUSES, err,
                         errlen) != 0)
        rc = AMFI_EINVAL;
    if (rc != 0)
        return rc;
    return query_pairs(s,
        "SELECT id, utime, speed_mps, speed_given_mps FROM passages "
        "WHERE utime >= ?1 AND utime <= ?2 AND (?3 IS NULL OR status = ?3) "
        "AND (?4 IS NULL OR lane = ?4) AND speed_estimated = 1 "
        "AND speed_mps > 0 AND speed_given_mps > 0 ORDER BY utime, id",
        f, 0, out, n, err, errlen);
}

int amfi_store_recent_speed_pairs(amfi_store *s, int max, amfi_speed_pair **out, size_t *n,
                                  char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "speeds: output is NULL");
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "speeds: max %d must be >= 1", max);
    if (rc != 0)
        return rc;
    return query_pairs(s,
        "SELECT * FROM (SELECT id, utime, speed_mps, speed_given_mps FROM passages "
        "WHERE speed_estimated = 1 AND speed_mps > 0 AND speed_given_mps > 0 "
        "ORDER BY utime DESC, id DESC LIMIT ?1) ORDER BY utime, id",
        NULL, max, out, n, err, errlen);
}
