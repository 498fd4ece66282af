/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_rows.c: the rows of the tables written from a row struct, from the
 * column table (store_columns.c): the INSERT text, the check of every
 * column by its rule, the binding loop, and the batch insert in one
 * transaction. The caller's thread; no state.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

int st_insert_sql(const amfi_store_tabledef *t, char *buf, size_t len)
{
    size_t k = (size_t)snprintf(buf, len, "INSERT INTO %s (", t->name);
    int n = 0;
    for (int j = 0; j < t->ncols && k < len; j++)
        if (t->cols[j].ctype != AMFI_C_NONE)
            k += (size_t)snprintf(buf + k, len - k, "%s%s", n++ ? ", " : "", t->cols[j].name);
    if (k < len)
        k += (size_t)snprintf(buf + k, len - k, ") VALUES (");
    n = 0;
    for (int j = 0; j < t->ncols && k < len; j++) {
        const amfi_store_coldef *c = &t->cols[j];
        if (c->ctype == AMFI_C_NONE)
            continue;
        n++;
        if (c->cut)
            k += (size_t)snprintf(buf + k, len - k, "%ssubstr(?%d, 1, %d)", n > 1 ? ", " : "", n,
                                  c->cut);
        else
            k += (size_t)snprintf(buf + k, len - k, "%s?%d", n > 1 ? ", " : "", n);
    }
    if (k < len)
        k += (size_t)snprintf(buf + k, len - k, ")");
    return k < len ? 0 : -1;
}

/* ---- a column's value in the row struct ---------------------------------- */

static int64_t field_int(const amfi_store_coldef *c, const void *row)
{
    const char *p = (const char *)row + c->off;
    if (c->ctype == AMFI_C_INT) {
        int v;
        memcpy(&v, p, sizeof v);
        return v;
    }
    int64_t v;
    memcpy(&v, p, sizeof v);
    return v;
}

static double field_real(const amfi_store_coldef *c, const void *row)
{
    double v;
    memcpy(&v, (const char *)row + c->off, sizeof v);
    return v;
}

static const char *field_text(const amfi_store_coldef *c, const void *row)
{
    if (c->ctype == AMFI_C_CHARS)
        return (const char *)row + c->off;
    const char *v;
    memcpy(&v, (const char *)row + c->off, sizeof v);
    return v;
}

/* The column is NULL for this row by its rule (or that of its `with`). */
static int is_null(const amfi_store_tabledef *t, const amfi_store_coldef *c, const void *row)
{
    if (c->with) {
        int w = amfi_store_coldef_index(t, c->with);
        if (w >= 0 && is_null(t, &t->cols[w], row))
            return 1;
    }
    switch (c->null_rule) {
    case AMFI_NULL_NAN: return isnan(field_real(c, row));
    case AMFI_NULL_ZERO: {
        double x = field_real(c, row);
        return isnan(x) || x == 0.0;
    }
    case AMFI_NULL_PTR: return field_text(c, row) == NULL;
    case AMFI_NULL_FLAG: {
        int flag;
        memcpy(&flag, (const char *)row + c->flag_off, sizeof flag);
        return flag == 0;
    }
    case AMFI_NULL_OPTIONAL: return field_int(c, row) <= 0;
    default: return 0;
    }
}

/* ---- checks ---------------------------------------------------------------- */

static int check_int(const char *name, const amfi_store_coldef *c, int64_t v, char *err,
                     size_t errlen)
{
    if (c->ilo == 0 && c->ihi == AMFI_STORE_MAX_UTIME)
        return st_check_utime(name, v, err, errlen);
    if (v >= c->ilo && v <= c->ihi)
        return 0;
    if (c->ilo == 0 && c->ihi == 1)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: %lld is not 0 or 1", name, (long long)v);
    if (c->ihi == INT64_MAX || c->ihi == INT32_MAX)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: %lld must be >= %lld", name, (long long)v,
                       (long long)c->ilo);
    return st_fail(err, errlen, AMFI_EINVAL, "%s: %lld is out of range [%lld, %lld]", name,
                   (long long)v, (long long)c->ilo, (long long)c->ihi);
}

static int check_text(const char *name, const amfi_store_coldef *c, const char *s, char *err,
                      size_t errlen)
{
    size_t mn = (size_t)(c->wmax ? c->wmin : c->min_len);
    size_t mx = c->wmax ? (size_t)c->wmax : c->max_len ? (size_t)c->max_len : (size_t)-1;
    switch (c->text_kind) {
    case AMFI_TEXT_ENUM: {
        char shown[160];
        return st_check_enum(name, s, c->words, amfi_store_coldef_words(c, ", ", shown, sizeof shown),
                             err, errlen);
    }
    case AMFI_TEXT_TOKEN: return st_check_token(name, s, mx, "_", 1, err, errlen);
    case AMFI_TEXT_BYTES: {
        size_t n = s ? strlen(s) : 0;
        if (!s || n < mn || (n > mx && !c->cut))
            return st_fail(err, errlen, AMFI_EINVAL, "%s: %s%zu bytes, not %zu .. %zu", name,
                           s ? "" : "NULL, ", n, mn, mx);
        return 0;
    }
    default: return st_check_text(name, s, mn, mx, err, errlen);
    }
}

int st_check_row(const amfi_store_tabledef *t, const void *row, const char *prefix, char *err,
                 size_t errlen)
{
    char name[96];
    if (!row)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: row is NULL", t->name);
    for (int j = 0; j < t->ncols; j++) {
        const amfi_store_coldef *c = &t->cols[j];
        if (c->ctype == AMFI_C_NONE || is_null(t, c, row))
            continue;
        snprintf(name, sizeof name, "%s.%s", prefix, c->name);
        int rc = 0;
        if (c->sql_type == AMFI_SQL_INTEGER) {
            int64_t v = field_int(c, row);
            if (c->null_rule == AMFI_NULL_ZERO_AS && v == 0)
                v = c->zero_as;
            rc = check_int(name, c, v, err, errlen);
        } else if (c->sql_type == AMFI_SQL_REAL) {
            range rg = {c->lo, c->hi, c->open & 1, c->unit, (c->open & 2) != 0};
            rc = c->null_rule == AMFI_NULL_NEVER || c->null_rule == AMFI_NULL_FLAG
                     ? st_check_known(name, field_real(c, row), &rg, err, errlen)
                     : st_check_num(name, field_real(c, row), &rg, err, errlen);
        } else {
            const char *s = field_text(c, row);
            if (!s && c->null_rule == AMFI_NULL_EMPTY)
                s = "";
            rc = check_text(name, c, s, err, errlen);
        }
        if (rc != 0)
            return rc;
    }
    return 0;
}

int st_bind_row(sqlite3_stmt *st, const amfi_store_tabledef *t, const void *row)
{
    int b = SQLITE_OK, i = 0;
    for (int j = 0; b == SQLITE_OK && j < t->ncols; j++) {
        const amfi_store_coldef *c = &t->cols[j];
        if (c->ctype == AMFI_C_NONE)
            continue;
        i++;
        if (is_null(t, c, row)) {
            b = sqlite3_bind_null(st, i);
        } else if (c->sql_type == AMFI_SQL_INTEGER) {
            int64_t v = field_int(c, row);
            if (c->null_rule == AMFI_NULL_ZERO_AS && v == 0)
                v = c->zero_as;
            b = sqlite3_bind_int64(st, i, v);
        } else if (c->sql_type == AMFI_SQL_REAL) {
            b = sqlite3_bind_double(st, i, field_real(c, row));
        } else {
            const char *s = field_text(c, row);
            b = st_bind_text(st, i, !s && c->null_rule == AMFI_NULL_EMPTY ? "" : s);
        }
    }
    return b;
}

int st_insert_rows(amfi_store *s, const char *name, const void *rows, int n, size_t stride,
                   int batch, int64_t *id, char *err, size_t errlen)
{
    const amfi_store_tabledef *t = amfi_store_tabledef_find(name);
    char prefix[64], sql[1024], what[96];
    sqlite3_stmt *st = NULL;
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0 && (!t || !t->row_size))
        rc = st_fail(err, errlen, AMFI_EINVAL, "%s: not a table written from a row", name);
    if (rc == 0 && (n < 0 || (n > 0 && !rows)))
        rc = st_fail(err, errlen, AMFI_EINVAL, "%s: %d rows at %p", name, n, rows);
    for (int k = 0; rc == 0 && k < n; k++) {
        if (batch)
            snprintf(prefix, sizeof prefix, "%s[%d]", name, k);
        else
            snprintf(prefix, sizeof prefix, "%s", name);
        rc = st_check_row(t, (const char *)rows + (size_t)k * stride, prefix, err, errlen);
    }
    if (rc != 0 || n == 0)
        return rc;
    if (st_insert_sql(t, sql, sizeof sql) != 0)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: the INSERT is too long", name);
    snprintf(what, sizeof what, "%s: prepare insert", name);
    rc = st_prepare(s, sql, &st, what, err, errlen);
    snprintf(what, sizeof what, "%s: insert", name);
    if (rc == 0 && n > 1)
        rc = st_begin(s, err, errlen);
    for (int k = 0; rc == 0 && k < n; k++) {
        int b = st_bind_row(st, t, (const char *)rows + (size_t)k * stride);
        int src = b == SQLITE_OK ? sqlite3_step(st) : b;
        if (src != SQLITE_DONE)
            rc = st_db_fail(s, src, what, err, errlen);
        st_done_with(st);
    }
    if (rc == 0 && id)
        *id = sqlite3_last_insert_rowid(s->db);
    if (rc == 0 && n > 1)
        rc = st_commit(s, err, errlen);
    if (rc != 0 && st && n > 1)
        st_rollback(s);
    sqlite3_finalize(st);
    return rc;
}

/* ---- reads ----------------------------------------------------------------- */

int st_select_list(const amfi_store_tabledef *t, char *buf, size_t len)
{
    size_t k = 0;
    int n = 0;
    if (len)
        buf[0] = '\0';
    for (int j = 0; j < t->ncols && k < len; j++)
        if (t->cols[j].ctype != AMFI_C_NONE)
            k += (size_t)snprintf(buf + k, len - k, "%s%s", n++ ? ", " : "", t->cols[j].name);
    return k < len ? 0 : -1;
}

static void put_int(const amfi_store_coldef *c, void *row, int64_t v)
{
    char *p = (char *)row + c->off;
    if (c->ctype == AMFI_C_INT) {
        int x = (int)v;
        memcpy(p, &x, sizeof x);
    } else {
        memcpy(p, &v, sizeof v);
    }
}

int st_read_row(sqlite3_stmt *st, int first, const amfi_store_tabledef *t, void *row,
                const origin *o, char *err, size_t errlen)
{
    int col = first, rc = 0;
    for (int j = 0; rc == 0 && j < t->ncols; j++) {
        const amfi_store_coldef *c = &t->cols[j];
        if (c->ctype == AMFI_C_NONE)
            continue;
        if (c->sql_type == AMFI_SQL_INTEGER) {
            int64_t v = 0;
            if (!(c->null_ok && sqlite3_column_type(st, col) == SQLITE_NULL))
                rc = st_read_int(st, col, c->ilo, c->ihi, o, &v, err, errlen);
            if (rc == 0)
                put_int(c, row, v);
        } else if (c->sql_type == AMFI_SQL_REAL) {
            range rg = {c->lo, c->hi, c->open & 1, c->unit, (c->open & 2) != 0};
            double x = NAN;
            rc = c->null_ok ? st_read_real_or_null(st, col, &rg, o, &x, err, errlen)
                            : st_read_real(st, col, &rg, o, &x, err, errlen);
            if (rc == 0)
                memcpy((char *)row + c->off, &x, sizeof x);
            if (rc == 0 && c->null_rule == AMFI_NULL_FLAG) {
                int flag = !isnan(x);
                memcpy((char *)row + c->flag_off, &flag, sizeof flag);
            }
        } else if (c->text_kind == AMFI_TEXT_ENUM && c->ctype == AMFI_C_STR) {
            char word[64];
            const char *found = NULL;
            rc = st_read_text(st, col, sizeof word - 1, o, word, sizeof word, NULL, 0) == 0
                     ? 0
                     : -1;
            for (const char *const *w = c->words; rc == 0 && *w && !found; w++)
                if (strcmp(*w, word) == 0)
                    found = *w;
            if (!found) {
                char problem[96];
                snprintf(problem, sizeof problem, "is not a known %s", c->name);
                rc = st_corrupt(o, st, col, err, errlen, problem);
            } else {
                memcpy((char *)row + c->off, &found, sizeof found);
            }
        } else {
            rc = st_fail(err, errlen, AMFI_EINVAL, "%s.%s: text is not read into a row",
                         t->name, c->name);
        }
        col++;
    }
    return rc;
}
