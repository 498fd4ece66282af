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

/* Step st (columns id, utime, speed_mps, speed_given_mps), appending to *a. */
static int read_pairs(amfi_store *s, sqlite3_stmt *st, amfi_speed_pair **a, size_t *n,
                      char *err, size_t errlen)
{
    size_t cap = 0;
    int rc = 0, src;
    while ((src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        amfi_speed_pair p;
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &p.utime, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 2, &R_SPEED_POS, &o, &p.speed_mps, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 3, &R_SPEED_POS, &o, &p.speed_given_mps, err, errlen);
        if (rc != 0)
            return rc;
        if (*n == cap) {
            size_t nc = cap ? 2 * cap : 256;
            amfi_speed_pair *na = realloc(*a, nc * sizeof *na);
            if (!na)
                return st_fail(err, errlen, AMFI_ENOMEM, "out of memory for %zu speeds", nc);
            *a = na;
            cap = nc;
        }
        (*a)[(*n)++] = p;
    }
    if (src != SQLITE_DONE)
        rc = st_db_fail(s, src, "passages: read estimated speeds", err, errlen);
    return rc;
}

/* Hand the array over (rc 0) or free it. */
static int hand_over(int rc, amfi_speed_pair *a, size_t n, amfi_speed_pair **out, size_t *nout)
{
    if (rc != 0 || n == 0) {
        free(a);
        a = NULL;
        n = 0;
    }
    *out = a;
    *nout = n;
    return rc;
}

/* Run one of the two queries (SQL parameters: ?1 .. ?4 the filter's from,
 * to, status, lane; or ?1 the limit) into *out. */
static int query_pairs(amfi_store *s, const char *sql, const amfi_passage_filter *f, int max,
                       amfi_speed_pair **out, size_t *n, char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    amfi_speed_pair *a = NULL;
    size_t k = 0;
    int rc = 0, src = sqlite3_prepare_v2(s->db, sql, -1, &st, NULL);
    if (src != SQLITE_OK) {
        rc = st_db_fail(s, src, "speeds: prepare", err, errlen);
    } else if (f) {
        sqlite3_bind_int64(st, 1, f->from);
        sqlite3_bind_int64(st, 2, f->to);
        if (f->status)
            sqlite3_bind_text(st, 3, f->status, -1, SQLITE_TRANSIENT);
        if (f->lane_given)
            sqlite3_bind_int(st, 4, f->lane);
    } else {
        sqlite3_bind_int(st, 1, max);
    }
    if (rc == 0)
        rc = read_pairs(s, st, &a, &k, err, errlen);
    sqlite3_finalize(st);
    return hand_over(rc, a, k, out, n);
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
