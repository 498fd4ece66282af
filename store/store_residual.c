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
    amfi_residual_rec *a = NULL;
    size_t k = 0, cap = 0;
    int src = sqlite3_prepare_v2(s->db,
                                 "SELECT id, utime, residual_rms, quality FROM passages "
                                 "WHERE utime >= ?1 AND utime <= ?2 AND status = 'ok' "
                                 "AND residual_rms IS NOT NULL ORDER BY utime, id",
                                 -1, &st, NULL);
    if (src != SQLITE_OK) {
        rc = st_db_fail(s, src, "residuals: prepare", err, errlen);
    } else {
        sqlite3_bind_int64(st, 1, from);
        sqlite3_bind_int64(st, 2, to);
        while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
            origin o = {"passages", sqlite3_column_int64(st, 0)};
            amfi_residual_rec r;
            r.passage_id = o.rowid;
            rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime, err, errlen);
            if (rc == 0)
                rc = st_read_real(st, 2, &R_NONNEG, &o, &r.residual_rms, err, errlen);
            if (rc == 0)
                rc = st_read_real_or_null(st, 3, &R_QUALITY, &o, &r.quality, err, errlen);
            if (rc == 0 && k == cap) {
                size_t nc = cap ? 2 * cap : 1024;
                amfi_residual_rec *na = realloc(a, nc * sizeof *na);
                if (!na)
                    rc = st_fail(err, errlen, AMFI_ENOMEM, "out of memory for %zu residuals", nc);
                else
                    a = na, cap = nc;
            }
            if (rc == 0)
                a[k++] = r;
        }
        if (rc == 0 && src != SQLITE_DONE)
            rc = st_db_fail(s, src, "passages: read residuals", err, errlen);
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
