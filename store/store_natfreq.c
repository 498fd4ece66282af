/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_natfreq.c: the passages' natural frequencies (issue 14, item 4;
 * schema version 6): the passages with an f1 in a time range, oldest first,
 * for amfi-report's series, and the first N of them, for amfid's
 * temperature baseline after a restart. Every value read back is checked
 * as in store_read.c. The caller's thread; the statements are prepared and
 * finalized per call (no state kept in the handle).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

/* Step st (columns id, utime, f1_hz, f1_comp_hz, f1_zeta, f1_r2), appending. */
static int read_f1(amfi_store *s, sqlite3_stmt *st, amfi_f1_rec **a, size_t *n, char *err,
                   size_t errlen)
{
    size_t cap = 0;
    int rc = 0, src;
    while ((src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        amfi_f1_rec p;
        p.passage_id = o.rowid;
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &p.utime, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 2, &R_HZ, &o, &p.f1_hz, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 3, &R_HZ, &o, &p.f1_comp_hz, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 4, &R_ZETA, &o, &p.f1_zeta, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 5, &R_PROB, &o, &p.f1_r2, err, errlen);
        if (rc != 0)
            return rc;
        if (*n == cap) {
            size_t nc = cap ? 2 * cap : 256;
            amfi_f1_rec *na = realloc(*a, nc * sizeof *na);
            if (!na)
                return st_fail(err, errlen, AMFI_ENOMEM, "out of memory for %zu frequencies",
                               nc);
            *a = na;
            cap = nc;
        }
        (*a)[(*n)++] = p;
    }
    if (src != SQLITE_DONE)
        rc = st_db_fail(s, src, "passages: read natural frequencies", err, errlen);
    return rc;
}

int amfi_store_f1_series(amfi_store *s, int64_t from, int64_t to, int max, amfi_f1_rec **out,
                         size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "natural frequencies: output is NULL");
    if (rc == 0 && max < 0)
        rc = st_fail(err, errlen, AMFI_EINVAL, "natural frequencies: max %d must be >= 0",
                     max);
    if (rc != 0)
        return rc;
    sqlite3_stmt *st = NULL;
    amfi_f1_rec *a = NULL;
    size_t k = 0;
    int src = sqlite3_prepare_v2(s->db,
                                 "SELECT id, utime, f1_hz, f1_comp_hz, f1_zeta, f1_r2 FROM passages "
                                 "WHERE utime >= ?1 AND utime <= ?2 AND f1_hz IS NOT NULL "
                                 "ORDER BY utime, id LIMIT ?3",
                                 -1, &st, NULL);
    if (src != SQLITE_OK) {
        rc = st_db_fail(s, src, "natural frequencies: prepare", err, errlen);
    } else {
        sqlite3_bind_int64(st, 1, from);
        sqlite3_bind_int64(st, 2, to);
        sqlite3_bind_int64(st, 3, max > 0 ? max : -1); /* SQLite: a negative LIMIT is none */
        rc = read_f1(s, st, &a, &k, err, errlen);
    }
    sqlite3_finalize(st);
    if (rc != 0 || k == 0) {
        free(a);
        a = NULL;
        k = 0;
    }
    *out = a;
    *n = k;
    return rc;
}
