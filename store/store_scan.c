/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_scan.c: rows as column values for other programs (store.h, "rows as
 * column values"): amfi-sync's scans of a table by key range, the schema
 * objects it checks, a table's largest key, transactions around several
 * calls, and the inserts by column values of amfi-report --pg and
 * amfi-fleet-bench. Table and column names are those of the column table
 * (store_columns.c): nothing else is put into SQL; values are bound. The
 * caller's thread; statements prepared and finalized per call (the
 * inserter keeps its one).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

/* t and its columns cols[0 .. n − 1] are in the column table. */
static int known_cols(const char *table, const char *const *cols, int n,
                      const amfi_store_tabledef **t, char *err, size_t errlen)
{
    *t = amfi_store_tabledef_find(table);
    if (!*t)
        return st_fail(err, errlen, AMFI_EINVAL, "store: no table '%s'", table ? table : "(null)");
    if (n < 1 || n > 64 || !cols)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: %d columns asked", table, n);
    for (int k = 0; k < n; k++)
        if (amfi_store_coldef_index(*t, cols[k]) < 0)
            return st_fail(err, errlen, AMFI_EINVAL, "%s: no column '%s'", table,
                           cols[k] ? cols[k] : "(null)");
    return 0;
}

static size_t col_list(char *buf, size_t len, const char *const *cols, int n)
{
    size_t k = 0;
    for (int j = 0; j < n && k < len; j++)
        k += (size_t)snprintf(buf + k, len - k, "%s%s", j ? ", " : "", cols[j]);
    return k;
}

int amfi_store_object_type(amfi_store *s, const char *name, char *type, size_t len, char *err,
                           size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!name || !type || len < 16))
        rc = st_fail(err, errlen, AMFI_EINVAL, "store: object type: bad arguments");
    if (rc == 0)
        rc = st_prepare(s, "SELECT type, coalesce(sql, '') FROM sqlite_schema WHERE name = ?1", &st,
                        "reading the schema", err, errlen);
    if (rc != 0)
        return rc;
    type[0] = '\0';
    int src = sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        const char *t = (const char *)sqlite3_column_text(st, 0);
        const char *sql = (const char *)sqlite3_column_text(st, 1);
        if (t && strcmp(t, "table") == 0 && sql && strncmp(sql, "CREATE VIRTUAL", 14) == 0)
            snprintf(type, len, "virtual table");
        else
            snprintf(type, len, "%s", t ? t : "");
    } else if (src != SQLITE_DONE) {
        rc = st_db_fail(s, src, "reading the schema", err, errlen);
    }
    sqlite3_finalize(st);
    return rc;
}

int amfi_store_max_key(amfi_store *s, const char *table, int64_t *max, char *err, size_t errlen)
{
    const amfi_store_tabledef *t = amfi_store_tabledef_find(table);
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0 && (!t || !t->key || !max))
        rc = st_fail(err, errlen, AMFI_EINVAL, "store: no keyed table '%s'", table ? table : "");
    if (rc != 0)
        return rc;
    char sql[128], what[64];
    snprintf(sql, sizeof sql, "SELECT coalesce(max(%s), 0) FROM %s", t->key, t->name);
    snprintf(what, sizeof what, "%s", t->name);
    *max = 0;
    return st_one_off(s, sql, what, max, NULL, 0, err, errlen);
}

static void value_of(sqlite3_stmt *st, int i, amfi_store_value *v)
{
    memset(v, 0, sizeof *v);
    switch (sqlite3_column_type(st, i)) {
    case SQLITE_INTEGER:
        v->type = AMFI_SQL_INTEGER;
        v->i = sqlite3_column_int64(st, i);
        break;
    case SQLITE_FLOAT:
        v->type = AMFI_SQL_REAL;
        v->r = sqlite3_column_double(st, i);
        break;
    case SQLITE_TEXT:
    case SQLITE_BLOB:
        v->type = sqlite3_column_type(st, i) == SQLITE_TEXT ? AMFI_SQL_TEXT : 'b';
        v->text = (const char *)sqlite3_column_text(st, i);
        v->len = sqlite3_column_bytes(st, i);
        if (!v->text)
            v->text = "";
        break;
    default:
        break;
    }
}

int amfi_store_scan(amfi_store *s, const char *table, const char *const *cols, int ncols,
                    int64_t lo, int64_t hi, int limit, amfi_store_values_fn fn, void *ctx,
                    char *err, size_t errlen)
{
    const amfi_store_tabledef *t = NULL;
    int rc = st_check_handle(s, 0, err, errlen);
    if (rc == 0)
        rc = known_cols(table, cols, ncols, &t, err, errlen);
    if (rc == 0 && (!t->key || !fn || limit < 0))
        rc = st_fail(err, errlen, AMFI_EINVAL, "%s: cannot be scanned so", table);
    if (rc != 0)
        return rc;
    char sql[2048], what[64];
    size_t k = (size_t)snprintf(sql, sizeof sql, "SELECT ");
    k += col_list(sql + k, sizeof sql - k, cols, ncols);
    if (k < sizeof sql)
        k += (size_t)snprintf(sql + k, sizeof sql - k,
                              " FROM %s WHERE %s > ?1 AND %s <= ?2 ORDER BY %s", t->name, t->key,
                              t->key, t->key);
    if (k < sizeof sql && limit > 0)
        k += (size_t)snprintf(sql + k, sizeof sql - k, " LIMIT %d", limit);
    if (k >= sizeof sql)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: too many columns", table);
    snprintf(what, sizeof what, "%s: read", t->name);
    sqlite3_stmt *st = NULL;
    rc = st_prepare(s, sql, &st, what, err, errlen);
    if (rc != 0)
        return rc;
    amfi_store_value v[64];
    int src = sqlite3_bind_int64(st, 1, lo);
    if (src == SQLITE_OK)
        src = sqlite3_bind_int64(st, 2, hi);
    while (src == SQLITE_OK && rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        for (int j = 0; j < ncols; j++)
            value_of(st, j, &v[j]);
        rc = fn(ctx, v, ncols);
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = st_db_fail(s, src, what, err, errlen);
    sqlite3_finalize(st);
    return rc;
}

int amfi_store_transaction(amfi_store *s, int what, char *err, size_t errlen)
{
    static const char *const sql[] = {"BEGIN", "BEGIN IMMEDIATE", "COMMIT", "ROLLBACK"};
    int rc = st_check_handle(s, what == AMFI_STORE_TX_WRITE, err, errlen);
    if (rc == 0 && (what < 0 || what > AMFI_STORE_TX_ROLLBACK))
        rc = st_fail(err, errlen, AMFI_EINVAL, "store: transaction %d", what);
    if (rc == 0 && what == AMFI_STORE_TX_ROLLBACK && sqlite3_get_autocommit(s->db))
        return 0;
    if (rc == 0)
        rc = st_one_off(s, sql[what], s->path, NULL, NULL, 0, err, errlen);
    return rc;
}

struct amfi_store_inserter {
    amfi_store *s;
    sqlite3_stmt *st;
    int ncols;
};

int amfi_store_inserter_open(amfi_store *s, const char *table, const char *const *cols, int ncols,
                             amfi_store_inserter **out, char *err, size_t errlen)
{
    const amfi_store_tabledef *t = NULL;
    int rc = st_check_handle(s, 1, err, errlen);
    if (rc == 0 && !out)
        rc = st_fail(err, errlen, AMFI_EINVAL, "store: inserter: out is NULL");
    if (rc == 0)
        rc = known_cols(table, cols, ncols, &t, err, errlen);
    if (rc != 0)
        return rc;
    *out = NULL;
    char sql[2048];
    size_t k = (size_t)snprintf(sql, sizeof sql, "INSERT INTO %s (", t->name);
    k += col_list(sql + k, sizeof sql - k, cols, ncols);
    for (int j = 0; j < ncols && k < sizeof sql; j++)
        k += (size_t)snprintf(sql + k, sizeof sql - k, "%s?%d", j ? ", " : ") VALUES (", j + 1);
    if (k < sizeof sql)
        k += (size_t)snprintf(sql + k, sizeof sql - k, ")");
    if (k >= sizeof sql)
        return st_fail(err, errlen, AMFI_EINVAL, "%s: too many columns", table);
    amfi_store_inserter *ins = calloc(1, sizeof *ins);
    if (!ins)
        return st_fail(err, errlen, AMFI_ENOMEM, "%s: out of memory", table);
    ins->s = s;
    ins->ncols = ncols;
    rc = st_prepare(s, sql, &ins->st, table, err, errlen);
    if (rc != 0) {
        free(ins);
        return rc;
    }
    *out = ins;
    return 0;
}

int amfi_store_insert_values(amfi_store_inserter *ins, const amfi_store_value *v, char *err,
                             size_t errlen)
{
    if (!ins || !v)
        return st_fail(err, errlen, AMFI_EINVAL, "store: insert: NULL");
    int src = SQLITE_OK;
    for (int j = 0; src == SQLITE_OK && j < ins->ncols; j++) {
        switch (v[j].type) {
        case AMFI_SQL_INTEGER: src = sqlite3_bind_int64(ins->st, j + 1, v[j].i); break;
        case AMFI_SQL_REAL: src = sqlite3_bind_double(ins->st, j + 1, v[j].r); break;
        case AMFI_SQL_TEXT:
            src = v[j].text ? sqlite3_bind_text(ins->st, j + 1, v[j].text, -1, SQLITE_STATIC)
                            : sqlite3_bind_null(ins->st, j + 1);
            break;
        default: src = sqlite3_bind_null(ins->st, j + 1); break;
        }
    }
    if (src == SQLITE_OK)
        src = sqlite3_step(ins->st);
    int rc = 0;
    if (src != SQLITE_DONE)
        rc = st_fail(err, errlen, st_status_of(src), "%s", sqlite3_errmsg(ins->s->db));
    st_done_with(ins->st);
    return rc;
}

void amfi_store_inserter_close(amfi_store_inserter *ins)
{
    if (!ins)
        return;
    sqlite3_finalize(ins->st);
    free(ins);
}
