/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_scale.c: the scale and known-truck indicators' rows (issue 14):
 * each scale block and known-truck run amfid evaluated (scale_evals), and
 * the inputs amfid replays at start to restore both indicators (the ok
 * passages with the deck temperature taken for them, paged by id). Every
 * argument is checked before it is written and every value read back is
 * checked as in store_read.c. The caller's thread; statements are prepared
 * and finalized per call (no state in the handle).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

static const char *const kinds[] = {"scale_shift", "known_truck", NULL};
static const range R_SCALE = {0.0, 100.0, 1, "", 0};
static const range R_Z = {-1e6, 1e6, 0, "", 0};
static const range R_STAT = {0.0, 1e6, 0, "", 0};

int amfi_store_add_scale_eval(amfi_store *s, const amfi_scale_eval_row *r, int64_t *id,
                              char *err, size_t errlen)
{
    if (!r)
        return st_fail(err, errlen, AMFI_EINVAL, "scale_evals: row is NULL");
    return st_insert_rows(s, "scale_evals", r, 1, sizeof *r, 0, id, err, errlen);
}

int amfi_store_scale_inputs(amfi_store *s, int64_t after_id, int max, amfi_scale_input **out,
                            size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "scale inputs: output is NULL");
    if (rc == 0 && max < 1)
        rc = st_fail(err, errlen, AMFI_EINVAL, "scale inputs: max %d must be >= 1", max);
    if (rc != 0)
        return rc;
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT id, utime, gvw_kg, deck_c, reference_gvw_kg, n_vehicles FROM passages "
                    "WHERE status = 'ok' AND deck_c IS NOT NULL AND id > ?1 ORDER BY id LIMIT ?2",
                    &st, "scale inputs: prepare", err, errlen);
    if (rc != 0)
        return rc;
    amfi_scale_input *v = malloc(sizeof *v * (size_t)max);
    if (!v) {
        sqlite3_finalize(st);
        return st_fail(err, errlen, AMFI_ENOMEM, "scale inputs: out of memory for %d rows", max);
    }
    size_t k = 0;
    int src = sqlite3_bind_int64(st, 1, after_id);
    if (src == SQLITE_OK)
        src = sqlite3_bind_int(st, 2, max);
    while (rc == 0 && src == SQLITE_OK && (src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        amfi_scale_input *r = &v[k];
        int64_t nv = 1;
        r->id = o.rowid;
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r->utime, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 2, &R_KG_POS, &o, &r->gvw_kg, err, errlen);
        if (rc == 0)
            rc = st_read_real(st, 3, &R_TEMP_C, &o, &r->deck_c, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 4, &R_REF_KG, &o, &r->reference_gvw_kg, err, errlen);
        if (rc == 0)
            rc = st_read_int(st, 5, 1, 64, &o, &nv, err, errlen);
        r->n_vehicles = (int)nv;
        k++;
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "scale inputs: read", err, errlen);
    sqlite3_finalize(st);
    if (rc != 0 || k == 0) {
        free(v);
        return rc;
    }
    *out = v;
    *n = k;
    return 0;
}

int amfi_store_scale_evals(amfi_store *s, const char *kind, amfi_scale_eval_rec **out,
                           size_t *n, char *err, size_t errlen)
{
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!out || !n))
        rc = st_fail(err, errlen, AMFI_EINVAL, "scale_evals: output is NULL");
    if (rc == 0)
        rc = st_check_enum("scale_evals: kind asked", kind, kinds, "scale_shift, known_truck",
                           err, errlen);
    if (rc != 0)
        return rc;
    *out = NULL;
    *n = 0;
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s,
                    "SELECT id, utime, n, value, raw, deck_c, z, cusum, h, state FROM scale_evals "
                    "WHERE kind = ?1 ORDER BY utime, id",
                    &st, "scale_evals: prepare read", err, errlen);
    if (rc != 0)
        return rc;
    size_t cap = 0, k = 0;
    amfi_scale_eval_rec *v = NULL;
    int src = st_bind_text(st, 1, kind);
    while (rc == 0 && src == SQLITE_OK && (src = sqlite3_step(st)) == SQLITE_ROW) {
        if (k == cap) {
            size_t nc = cap ? 2 * cap : 256;
            amfi_scale_eval_rec *nv = realloc(v, sizeof *v * nc);
            if (!nv) {
                rc = st_fail(err, errlen, AMFI_ENOMEM, "scale_evals: out of memory");
                break;
            }
            v = nv;
            cap = nc;
        }
        origin o = {"scale_evals", sqlite3_column_int64(st, 0)};
        amfi_scale_eval_rec *r = &v[k];
        int64_t cnt = 0;
        memset(r, 0, sizeof *r);
        r->id = o.rowid;
        snprintf(r->kind, sizeof r->kind, "%s", kind);
        rc = st_read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &r->utime, err, errlen);
        if (rc == 0)
            rc = st_read_int(st, 2, 0, INT32_MAX, &o, &cnt, err, errlen);
        r->n = (int)cnt;
        if (rc == 0)
            rc = st_read_real_or_null(st, 3, &R_SCALE, &o, &r->value, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 4, &R_SCALE, &o, &r->raw, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 5, &R_TEMP_C, &o, &r->deck_c, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 6, &R_Z, &o, &r->z, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 7, &R_STAT, &o, &r->cusum, err, errlen);
        if (rc == 0)
            rc = st_read_real_or_null(st, 8, &R_STAT, &o, &r->h, err, errlen);
        if (rc == 0)
            rc = st_read_text(st, 9, sizeof r->state - 1, &o, r->state, sizeof r->state, err,
                              errlen);
        k++;
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, "scale_evals: read", err, errlen);
    sqlite3_finalize(st);
    if (rc != 0 || k == 0) {
        free(v);
        return rc;
    }
    *out = v;
    *n = k;
    return 0;
}
