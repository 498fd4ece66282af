/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_export.c: the passage listing of reports (amfi-report --passages,
 * --histogram, --overloads, --plot): every passage in a time range,
 * optionally of one status and one lane (filtered in SQL), with its axle
 * loads, oldest first, handed one typed row at a time to the
 * caller's function. Every value is checked as in store_read.c. The
 * caller's thread; the two statements are prepared and finalized per call
 * (no state kept in the handle).
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "store_internal.h"

int amfi_store_each_passage(amfi_store *s, int64_t from, int64_t to,
                            const char *status, amfi_store_passage_fn fn,
                            void *ctx, char *err, size_t errlen)
{
    amfi_passage_filter f = {.from = from, .to = to, .status = status};
    return amfi_store_each_passage_where(s, &f, fn, ctx, err, errlen);
}

int amfi_store_each_passage_where(amfi_store *s, const amfi_passage_filter *f,
                                  amfi_store_passage_fn fn, void *ctx,
                                  char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen), src = SQLITE_OK;
    if (rc == 0 && (!fn || !f))
        rc = st_fail(err, errlen, AMFI_EINVAL, "passages: no function or filter");
    if (rc == 0 && f->lane_given && (f->lane < -32768 || f->lane > 32767))
        rc = st_fail(err, errlen, AMFI_EINVAL,
                     "passages: lane %d outside [-32768, 32767]", f->lane);
    const char *status = rc == 0 ? f->status : NULL;
    if (rc == 0 && status
        && st_check_enum("passages: status", status, st_statuses,
                         AMFI_STORE_STATUSES, err, errlen) != 0)
        rc = AMFI_EINVAL;
    if (rc != 0)
        return rc;
    sqlite3_stmt *p = NULL, *a = NULL;
    src = sqlite3_prepare_v2(s->db,
        "SELECT id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, "
        "reason, speed_given_mps, speed_estimated, n_vehicles, quality, class, axle_groups, "
        "overload, loads_refused FROM passages WHERE utime >= ?1 AND utime <= ?2 "
        "AND (?3 IS NULL OR status = ?3) AND (?4 IS NULL OR lane = ?4) "
        "ORDER BY utime, id", -1, &p, NULL);
    if (src == SQLITE_OK)
        src = sqlite3_prepare_v2(s->db,
            "SELECT idx, spacing_m, load_kg FROM axles WHERE passage_id = ?1 "
            "ORDER BY idx", -1, &a, NULL);
    if (src != SQLITE_OK) {
        rc = st_db_fail(s, src, "passages: prepare", err, errlen);
        goto done;
    }
    sqlite3_bind_int64(p, 1, f->from);
    sqlite3_bind_int64(p, 2, f->to);
    if (f->lane_given)
        sqlite3_bind_int(p, 4, f->lane);
    if (status)
        sqlite3_bind_text(p, 3, status, -1, SQLITE_TRANSIENT);
    while (rc == 0 && (src = sqlite3_step(p)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(p, 0)};
        amfi_passage_row r;
        int64_t v = 0;
        char st_name[16], reason[AMFI_STORE_REASON_MAX + 1], vclass[16], groups[32],
            refused[AMFI_STORE_LOADS_REFUSED_MAX + 1];
        memset(&r, 0, sizeof r);
        for (int k = 0; k < AMFI_MAX_AXLES; k++)
            r.spacing_m[k] = r.axle_kg[k] = NAN;
        rc = st_read_int(p, 1, INT64_MIN, INT64_MAX, &o, &r.vehicle_id, err, errlen);
        if (rc == 0) rc = st_read_int(p, 2, 0, AMFI_STORE_MAX_UTIME, &o, &r.utime, err, errlen);
        if (rc == 0) rc = st_read_int(p, 3, -32768, 32767, &o, &v, err, errlen);
        r.lane = (int)v;
        if (rc == 0) rc = st_read_real_or_null(p, 4, &R_SPEED, &o, &r.speed_mps, err, errlen);
        if (rc == 0) rc = st_read_int(p, 5, 0, AMFI_MAX_AXLES, &o, &v, err, errlen);
        r.n_axles = (int)v;
        if (rc == 0) rc = st_read_real_or_null(p, 6, &R_KG, &o, &r.gvw_kg, err, errlen);
        if (rc == 0) rc = st_read_text(p, 7, sizeof st_name - 1, &o, st_name, sizeof st_name, err, errlen);
        if (rc == 0) {
            int k = 0;
            while (st_statuses[k] && strcmp(st_statuses[k], st_name) != 0)
                k++;
            if (!st_statuses[k])
                rc = st_corrupt(&o, p, 7, err, errlen, "is not a known status");
            else
                r.status = st_statuses[k];
        }
        if (rc == 0) rc = st_read_text(p, 8, AMFI_STORE_REASON_MAX, &o, reason, sizeof reason, err, errlen);
        r.reason = reason;
        if (rc == 0) rc = st_read_real_or_null(p, 9, &R_SPEED, &o, &r.speed_given_mps, err, errlen);
        if (rc == 0) rc = st_read_int(p, 10, 0, 1, &o, &v, err, errlen);
        r.speed_estimated = (int)v;
        if (rc == 0) rc = st_read_int(p, 11, 1, 64, &o, &v, err, errlen);
        r.n_vehicles = (int)v;
        if (rc == 0) rc = st_read_real_or_null(p, 12, &R_QUALITY, &o, &r.quality, err, errlen);
        if (rc == 0 && sqlite3_column_type(p, 13) != SQLITE_NULL) {
            rc = st_read_text(p, 13, sizeof vclass - 1, &o, vclass, sizeof vclass, err, errlen);
            r.vclass = vclass;
        }
        if (rc == 0 && sqlite3_column_type(p, 14) != SQLITE_NULL) {
            rc = st_read_text(p, 14, sizeof groups - 1, &o, groups, sizeof groups, err, errlen);
            r.axle_groups = groups;
        }
        if (rc == 0 && sqlite3_column_type(p, 15) != SQLITE_NULL) {
            rc = st_read_int(p, 15, 0, 1, &o, &v, err, errlen);
            r.overload = (int)v;
            r.has_overload = 1;
        }
        if (rc == 0 && sqlite3_column_type(p, 16) != SQLITE_NULL) {
            rc = st_read_text(p, 16, AMFI_STORE_LOADS_REFUSED_MAX, &o, refused, sizeof refused,
                              err, errlen);
            if (rc == 0 && !refused[0])
                rc = st_corrupt(&o, p, 16, err, errlen, "is empty (NULL when the loads were judged)");
            r.loads_refused = refused;
        }
        if (rc == 0) {
            int asrc;
            int seen = 0;
            origin oa = {"axles", o.rowid};
            sqlite3_bind_int64(a, 1, o.rowid);
            while (rc == 0 && (asrc = sqlite3_step(a)) == SQLITE_ROW) {
                int64_t idx = 0;
                rc = st_read_int(a, 0, 1, r.n_axles, &oa, &idx, err, errlen);
                double sp = NAN; /* axles.spacing_m: to axle idx − 1 */
                if (rc == 0) rc = st_read_real_or_null(a, 1, &R_SPACING, &oa, &sp, err, errlen);
                if (rc == 0 && idx > 1)
                    r.spacing_m[idx - 2] = sp;
                if (rc == 0) rc = st_read_real_or_null(a, 2, &R_KG, &oa, &r.axle_kg[idx - 1], err, errlen);
                seen++;
            }
            if (rc == 0 && asrc != SQLITE_DONE)
                rc = st_db_fail(s, asrc, "axles: read", err, errlen);
            if (rc == 0 && seen != r.n_axles)
                rc = st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                             "%s: passages row %lld: n_axles %d but %d axle rows",
                             s->path, (long long)o.rowid, r.n_axles, seen);
            sqlite3_reset(a);
        }
        if (rc == 0)
            rc = fn(ctx, o.rowid, &r);
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "passages: read", err, errlen);
done:
    sqlite3_finalize(p);
    sqlite3_finalize(a);
    return rc;
}
