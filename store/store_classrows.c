/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_classrows.c: the class, lane, GVW, overload flag and refusal of the ok
 * passages with a GVW in a time range (and lane), in one query without
 * their axle rows, for amfi-report's --classes and --class-histogram.
 * Every value read back is checked as in store_read.c. The caller's
 * thread; the statement is prepared and finalized per call.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "store_internal.h"

int amfi_store_each_class_row(amfi_store *s, const amfi_passage_filter *f,
                              amfi_store_class_fn fn, void *ctx, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!fn || !f))
        rc = st_fail(err, errlen, AMFI_EINVAL, "class rows: no function or filter");
    if (rc == 0 && f->lane_given && (f->lane < -32768 || f->lane > 32767))
        rc = st_fail(err, errlen, AMFI_EINVAL, "class rows: lane %d outside [-32768, 32767]",
                     f->lane);
    if (rc != 0)
        return rc;
    sqlite3_stmt *p = NULL;
    int src = sqlite3_prepare_v2(s->db,
        "SELECT id, lane, gvw_kg, class, overload, coalesce(loads_refused, '') <> '' "
        "FROM passages WHERE utime >= ?1 "
        "AND utime <= ?2 AND status = 'ok' AND gvw_kg IS NOT NULL "
        "AND (?3 IS NULL OR lane = ?3) ORDER BY utime, id", -1, &p, NULL);
    if (src != SQLITE_OK) {
        rc = st_db_fail(s, src, "class rows: prepare", err, errlen);
        sqlite3_finalize(p);
        return rc;
    }
    sqlite3_bind_int64(p, 1, f->from);
    sqlite3_bind_int64(p, 2, f->to);
    if (f->lane_given)
        sqlite3_bind_int(p, 3, f->lane);
    while (rc == 0 && (src = sqlite3_step(p)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(p, 0)};
        amfi_class_row r;
        int64_t v = 0;
        char cls[16];
        memset(&r, 0, sizeof r);
        rc = st_read_int(p, 1, -32768, 32767, &o, &v, err, errlen);
        r.lane = (int)v;
        if (rc == 0)
            rc = st_read_real(p, 2, &R_KG_POS, &o, &r.gvw_kg, err, errlen);
        if (rc == 0 && sqlite3_column_type(p, 3) != SQLITE_NULL) {
            rc = st_read_text(p, 3, sizeof cls - 1, &o, cls, sizeof cls, err, errlen);
            r.vclass = cls;
        }
        if (rc == 0 && sqlite3_column_type(p, 4) != SQLITE_NULL) {
            rc = st_read_int(p, 4, 0, 1, &o, &v, err, errlen);
            r.overload = (int)v;
        }
        if (rc == 0) {
            rc = st_read_int(p, 5, 0, 1, &o, &v, err, errlen);
            r.refused = (int)v;
        }
        if (rc == 0)
            rc = fn(ctx, &r);
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "passages: read class rows", err, errlen);
    sqlite3_finalize(p);
    return rc;
}
