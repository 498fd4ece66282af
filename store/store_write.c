/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_write.c: the store's inserts (passages with their axles, truth,
 * indicators, alerts, baselines, meta, runs). Every argument is checked
 * first (store_check.c) and a row with one bad field stores nothing; a
 * passage or a truth is one transaction with its axle rows. The thread of
 * the handle (amfid's pipeline thread); no state beyond the handle.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "store_internal.h"

/* The columns by the column table (store_columns.c), then what it cannot
 * say: the axle arrays and the rule of status ok. */
static int check_passage(const amfi_passage_row *r, char *err, size_t errlen)
{
    char name[48];
    int rc = st_check_row(amfi_store_tabledef_find("passages"), r, "passages", err, errlen);
    if (rc != 0)
        return rc;
    for (int k = 0; rc == 0 && k < r->n_axles - 1; k++) {
        snprintf(name, sizeof name, "passages: spacing_m[%d]", k);
        rc = st_check_num(name, r->spacing_m[k], &R_SPACING, err, errlen);
    }
    for (int k = 0; rc == 0 && k < r->n_axles; k++) {
        snprintf(name, sizeof name, "passages: axle_kg[%d]", k);
        rc = st_check_num(name, r->axle_kg[k], &R_KG, err, errlen);
    }
    if (rc != 0 || strcmp(r->status, "ok") != 0)
        return rc;
    /* status ok: a solved passage with everything known */
    if (r->n_axles < 1)
        return st_fail(err, errlen, AMFI_EINVAL,
                    "passages: status ok needs n_axles >= 1 (got 0)");
    rc = st_check_known("passages: status ok: gvw_kg", r->gvw_kg, &R_KG_POS, err,
                     errlen);
    if (rc == 0)
        rc = st_check_known("passages: status ok: speed_mps", r->speed_mps,
                         &R_SPEED_POS, err, errlen);
    for (int k = 0; rc == 0 && k < r->n_axles - 1; k++) {
        snprintf(name, sizeof name, "passages: status ok: spacing_m[%d]", k);
        rc = st_check_known(name, r->spacing_m[k], &R_SPACING, err, errlen);
    }
    for (int k = 0; rc == 0 && k < r->n_axles; k++) {
        snprintf(name, sizeof name, "passages: status ok: axle_kg[%d]", k);
        rc = st_check_known(name, r->axle_kg[k], &R_KG, err, errlen);
    }
    return rc;
}

/* ---- writes --------------------------------------------------------------- */

int amfi_store_add_passage(amfi_store *s, const amfi_passage_row *r,
                           int64_t *id, char *err, size_t errlen)
{
    int64_t pid = 0;
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_passage(r, err, errlen);
    if (rc == 0)
        rc = st_begin(s, err, errlen);
    if (rc == 0) {
        int b = st_bind_row(s->st[ST_INS_PASSAGE], amfi_store_tabledef_find("passages"), r);
        rc = st_run(s, ST_INS_PASSAGE, b, "passages: insert", err, errlen);
        if (rc == 0)
            pid = sqlite3_last_insert_rowid(s->db);
    }
    for (int k = 0; rc == 0 && k < r->n_axles; k++) {
        sqlite3_stmt *st = s->st[ST_INS_AXLE];
        int b = sqlite3_bind_int64(st, 1, pid);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 2, k + 1);
        if (b == SQLITE_OK)
            b = k == 0 ? sqlite3_bind_null(st, 3)
                       : st_bind_real(st, 3, r->spacing_m[k - 1]);
        if (b == SQLITE_OK) b = st_bind_real(st, 4, r->axle_kg[k]);
        rc = st_run(s, ST_INS_AXLE, b, "axles: insert", err, errlen);
    }
    /* the raw samples: under a savepoint, never the passage's failure */
    if (rc == 0 && r->raw)
        st_raw_write(s, pid, r->raw);
    if (rc == 0)
        rc = st_commit(s, err, errlen);
    if (rc != 0 && s)
        st_rollback(s);
    if (rc != 0 && r && r->raw && r->raw->status == 0) {
        r->raw->status = rc; /* rolled back with the passage */
        r->raw->stored_window_id = r->raw->bytes = r->raw->raw_bytes = 0;
        snprintf(r->raw->err, sizeof r->raw->err, "the passage was not stored");
    }
    if (rc == 0 && id)
        *id = pid;
    return rc;
}

int amfi_store_add_truth(amfi_store *s, int64_t vehicle_id, int64_t utime,
                         double gvw_kg, int n_axles, const double *axle_kg,
                         const double *mean_force_N, double speed_true_mps,
                         char *err, size_t errlen)
{
    char name[48];
    int64_t tid = 0;
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = st_check_utime("truth.utime", utime, err, errlen);
    if (rc == 0)
        rc = st_check_known("truth.gvw_kg", gvw_kg, &R_KG_POS, err, errlen);
    if (rc == 0 && (n_axles < 1 || n_axles > AMFI_MAX_AXLES))
        rc = st_fail(err, errlen, AMFI_EINVAL,
                  "truth.n_axles: %d is out of range [1, %d]", n_axles,
                  AMFI_MAX_AXLES);
    if (rc == 0 && !axle_kg)
        rc = st_fail(err, errlen, AMFI_EINVAL, "truth: axle_kg is NULL");
    for (int k = 0; rc == 0 && k < n_axles; k++) {
        snprintf(name, sizeof name, "truth: axle_kg[%d]", k);
        rc = st_check_known(name, axle_kg[k], &R_KG_POS, err, errlen);
    }
    for (int k = 0; rc == 0 && mean_force_N && k < n_axles; k++) {
        snprintf(name, sizeof name, "truth: mean_force_N[%d]", k);
        rc = st_check_num(name, mean_force_N[k], &R_FORCE, err, errlen);
    }
    if (rc == 0)
        rc = st_check_num("truth.speed_true_mps", speed_true_mps, &R_SPEED_POS,
                       err, errlen);
    if (rc == 0)
        rc = st_begin(s, err, errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_TRUTH];
        int b = sqlite3_bind_int64(st, 1, vehicle_id);
        if (b == SQLITE_OK) b = sqlite3_bind_int64(st, 2, utime);
        if (b == SQLITE_OK) b = sqlite3_bind_double(st, 3, gvw_kg);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 4, n_axles);
        if (b == SQLITE_OK) b = st_bind_real(st, 5, speed_true_mps);
        rc = st_run(s, ST_INS_TRUTH, b, "truth: insert", err, errlen);
        if (rc == 0)
            tid = sqlite3_last_insert_rowid(s->db);
    }
    for (int k = 0; rc == 0 && k < n_axles; k++) {
        sqlite3_stmt *st = s->st[ST_INS_TRUTH_AXLE];
        int b = sqlite3_bind_int64(st, 1, tid);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 2, k + 1);
        if (b == SQLITE_OK) b = sqlite3_bind_double(st, 3, axle_kg[k]);
        if (b == SQLITE_OK)
            b = st_bind_real(st, 4, mean_force_N ? mean_force_N[k] : NAN);
        rc = st_run(s, ST_INS_TRUTH_AXLE, b, "truth_axles: insert", err, errlen);
    }
    if (rc == 0)
        rc = st_commit(s, err, errlen);
    if (rc != 0 && s)
        st_rollback(s);
    return rc;
}

int amfi_store_add_indicator(amfi_store *s, const amfi_indicator_row *r,
                             int64_t *id, char *err, size_t errlen)
{
    const amfi_store_tabledef *t = amfi_store_tabledef_find("indicators");
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = st_check_row(t, r, "indicators", err, errlen);
    if (rc == 0)
        rc = st_run(s, ST_INS_INDICATOR, st_bind_row(s->st[ST_INS_INDICATOR], t, r),
                    "indicators: insert", err, errlen);
    if (rc == 0 && id)
        *id = sqlite3_last_insert_rowid(s->db);
    return rc;
}

int amfi_store_add_alert(amfi_store *s, int64_t utime, const char *level,
                         const char *kind, const char *message,
                         int64_t indicator_id, int raised, int64_t *id,
                         char *err, size_t errlen)
{
    char what[64];
    const amfi_store_tabledef *t = amfi_store_tabledef_find("alerts");
    const st_alert_row r = {utime, level, kind, message, indicator_id, raised};
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = st_check_row(t, &r, "alerts", err, errlen);
    if (rc == 0) {
        snprintf(what, sizeof what, "alerts: insert (indicator_id %lld)",
                 (long long)indicator_id);
        rc = st_run(s, ST_INS_ALERT, st_bind_row(s->st[ST_INS_ALERT], t, &r), what, err,
                    errlen);
    }
    if (rc == 0 && id)
        *id = sqlite3_last_insert_rowid(s->db);
    return rc;
}

static int check_baseline(const amfi_baseline *b, char *err, size_t errlen)
{
    int rc = 0;
    if (!b)
        return st_fail(err, errlen, AMFI_EINVAL, "baseline: NULL");
    rc = st_check_utime("baseline.utime_set", b->utime_set, err, errlen);
    if (rc == 0 && b->n < 2)
        rc = st_fail(err, errlen, AMFI_EINVAL,
                  "baseline.n: %d, a STD needs at least 2 passages", b->n);
    if (rc == 0)
        rc = st_check_known("baseline.mean_kg", b->mean_kg, &R_KG_POS, err, errlen);
    if (rc == 0)
        rc = st_check_known("baseline.std_kg", b->std_kg, &R_KG_POS, err, errlen);
    if (rc == 0 && !memchr(b->source, '\0', sizeof b->source))
        rc = st_fail(err, errlen, AMFI_EINVAL, "baseline.source: not terminated");
    if (rc == 0)
        rc = st_check_enum("baseline.source", b->source, st_sources, "auto, manual",
                        err, errlen);
    if (rc == 0 && !memchr(b->note, '\0', sizeof b->note))
        rc = st_fail(err, errlen, AMFI_EINVAL,
                  "baseline.note: not terminated within %zu bytes",
                  sizeof b->note);
    if (rc == 0)
        rc = st_check_text("baseline.note", b->note, 0, sizeof b->note - 1, err,
                        errlen);
    return rc;
}

int amfi_store_set_baseline(amfi_store *s, const amfi_baseline *b, char *err,
                            size_t errlen)
{
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_baseline(b, err, errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_BASELINE];
        int q = sqlite3_bind_int64(st, 1, b->utime_set);
        if (q == SQLITE_OK) q = sqlite3_bind_int(st, 2, b->n);
        if (q == SQLITE_OK) q = sqlite3_bind_double(st, 3, b->mean_kg);
        if (q == SQLITE_OK) q = sqlite3_bind_double(st, 4, b->std_kg);
        if (q == SQLITE_OK) q = st_bind_text(st, 5, b->source);
        if (q == SQLITE_OK) q = st_bind_text(st, 6, b->note);
        rc = st_run(s, ST_INS_BASELINE, q, "baseline: insert", err, errlen);
    }
    return rc;
}


int amfi_store_meta_set(amfi_store *s, const char *key, const char *val,
                        char *err, size_t errlen)
{
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = st_check_meta_key(key, err, errlen);
    if (rc == 0)
        rc = st_check_text("meta.value", val, 0, AMFI_STORE_META_VALUE_MAX, err,
                        errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_META_SET];
        int b = st_bind_text(st, 1, key);
        if (b == SQLITE_OK) b = st_bind_text(st, 2, val);
        rc = st_run(s, ST_META_SET, b, "meta: set", err, errlen);
    }
    return rc;
}

/* ---- runs ------------------------------------------------------------------ */

int amfi_store_add_run(amfi_store *s, const char *version,
                       const char *config_path, int64_t *id, char *err,
                       size_t errlen)
{
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = st_check_text("runs.version", version, 1, 63, err, errlen);
    if (rc == 0)
        rc = st_check_text("runs.config_path", config_path, 1, 4096, err,
                           errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_RUN];
        int b = st_bind_text(st, 1, version);
        if (b == SQLITE_OK) b = st_bind_text(st, 2, config_path);
        rc = st_run(s, ST_INS_RUN, b, "runs: insert", err, errlen);
    }
    if (rc == 0 && id)
        *id = sqlite3_last_insert_rowid(s->db);
    return rc;
}
