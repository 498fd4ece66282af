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

/* One row (id, utime, f1_hz, f1_comp_hz, f1_zeta, f1_r2). */
static int read_f1(sqlite3_stmt *st, const void *ctx, void *rec, char *err, size_t errlen)
{
    (void)ctx;
    amfi_f1_rec *p = rec;
    origin o = {"passages", sqlite3_column_int64(st, 0)};
    p->passage_id = o.rowid;
    int rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &p->utime, err, errlen);
    if (rc == 0)
        rc = st_read_real(st, 2, &R_HZ, &o, &p->f1_hz, err, errlen);
    if (rc == 0)
        rc = st_read_real_or_null(st, 3, &R_HZ, &o, &p->f1_comp_hz, err, errlen);
    if (rc == 0)
        rc = st_read_real_or_null(st, 4, &R_ZETA, &o, &p->f1_zeta, err, errlen);
    if (rc == 0)
        rc = st_read_real_or_null(st, 5, &R_PROB, &o, &p->f1_r2, err, errlen);
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
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT id, utime, f1_hz, f1_comp_hz, f1_zeta, f1_r2 FROM passages "
                    "WHERE utime >= ?1 AND utime <= ?2 AND f1_hz IS NOT NULL "
                    "ORDER BY utime, id LIMIT ?3",
                    &st, "natural frequencies: prepare", err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_int64(st, 1, from);
    sqlite3_bind_int64(st, 2, to);
    sqlite3_bind_int64(st, 3, max > 0 ? max : -1); /* SQLite: a negative LIMIT is none */
    void *a = NULL;
    rc = st_collect(s, st, read_f1, NULL, sizeof **out, 256, "passages: read natural frequencies",
                    "frequencies", &a, n, err, errlen);
    *out = a;
    return rc;
}
