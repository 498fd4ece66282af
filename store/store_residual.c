/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_residual.c: the solver's fit per ok passage (passages.residual_rms
 * and quality) in a time range, oldest first, in one query, for
 * amfi-report's residual line and plot. Every value read back is checked
 * as in store_read.c. The caller's thread; the statement is prepared and
 * finalized per call (no state kept in the handle).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "store_internal.h"

/* One row (id, utime, residual_rms, quality). */
static int read_residual(sqlite3_stmt *st, const void *ctx, void *rec, char *err, size_t errlen)
{
    (void)ctx;
    amfi_residual_rec *r = rec;
    origin o = {"passages", sqlite3_column_int64(st, 0)};
    r->passage_id = o.rowid;
    int rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r->utime, err, errlen);
    if (rc == 0)
        rc = st_read_real(st, 2, &R_NONNEG, &o, &r->residual_rms, err, errlen);
    if (rc == 0)
        rc = st_read_real_or_null(st, 3, &R_QUALITY, &o, &r->quality, err, errlen);
    return rc;
}

int amfi_store_residual_series(amfi_store *s, int64_t from, int64_t to, amfi_residual_rec **out,
                               size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "residuals: output is NULL");
    if (rc != 0)
        return rc;
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT id, utime, residual_rms, quality FROM passages "
                    "WHERE utime >= ?1 AND utime <= ?2 AND status = 'ok' "
                    "AND residual_rms IS NOT NULL ORDER BY utime, id",
                    &st, "residuals: prepare", err, errlen);
    if (rc != 0)
        return rc;
    sqlite3_bind_int64(st, 1, from);
    sqlite3_bind_int64(st, 2, to);
    void *a = NULL;
    rc = st_collect(s, st, read_residual, NULL, sizeof **out, 1024, "passages: read residuals",
                    "residuals", &a, n, err, errlen);
    *out = a;
    return rc;
}
