/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_testing.c: raw SQL on a store's file for tests (store_testing.h).
 * Linked by tests only. The caller's thread; the connection is its state.
 */
#include "store_testing.h"

#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_internal.h"

struct amfi_store_test_db {
    sqlite3 *db;
};

static int fail(char *err, size_t errlen, const char *what, const char *msg)
{
    if (err && errlen)
        snprintf(err, errlen, "%s: %s", what, msg);
    return -1;
}

amfi_store_test_db *amfi_store_test_open(const char *path, int create, char *err, size_t errlen)
{
    amfi_store_test_db *t = calloc(1, sizeof *t);
    if (!t) {
        fail(err, errlen, path, "out of memory");
        return NULL;
    }
    int flags = SQLITE_OPEN_READWRITE | (create ? SQLITE_OPEN_CREATE : 0);
    if (sqlite3_open_v2(path, &t->db, flags, NULL) != SQLITE_OK) {
        fail(err, errlen, path, t->db ? sqlite3_errmsg(t->db) : "cannot open");
        sqlite3_close(t->db);
        free(t);
        return NULL;
    }
    sqlite3_busy_timeout(t->db, 5000);
    return t;
}

void amfi_store_test_close(amfi_store_test_db *t)
{
    if (!t)
        return;
    sqlite3_close(t->db);
    free(t);
}

int amfi_store_test_exec(amfi_store_test_db *t, const char *sql, char *err, size_t errlen)
{
    char *msg = NULL;
    if (sqlite3_exec(t->db, sql, NULL, NULL, &msg) != SQLITE_OK) {
        fail(err, errlen, sql, msg ? msg : sqlite3_errmsg(t->db));
        sqlite3_free(msg);
        return -1;
    }
    return 0;
}

/* The first row of sql stepped in *st (NULL-free on failure); *row 1 when
 * there is one. */
static int first_row(amfi_store_test_db *t, const char *sql, sqlite3_stmt **st, int *row,
                     char *err, size_t errlen)
{
    *st = NULL;
    *row = 0;
    if (sqlite3_prepare_v2(t->db, sql, -1, st, NULL) != SQLITE_OK)
        return fail(err, errlen, sql, sqlite3_errmsg(t->db));
    int src = sqlite3_step(*st);
    if (src == SQLITE_ROW)
        *row = 1;
    else if (src != SQLITE_DONE) {
        fail(err, errlen, sql, sqlite3_errmsg(t->db));
        sqlite3_finalize(*st);
        *st = NULL;
        return -1;
    }
    return 0;
}

int amfi_store_test_int(amfi_store_test_db *t, const char *sql, int64_t *v, char *err,
                        size_t errlen)
{
    sqlite3_stmt *st;
    int row;
    *v = 0;
    if (first_row(t, sql, &st, &row, err, errlen) != 0)
        return -1;
    if (row)
        *v = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return 0;
}

int amfi_store_test_real(amfi_store_test_db *t, const char *sql, double *v, int *type, char *err,
                         size_t errlen)
{
    static const int types[] = {0, 'i', 'r', 't', 'b', 0};
    sqlite3_stmt *st;
    int row;
    *v = NAN;
    if (type)
        *type = 0;
    if (first_row(t, sql, &st, &row, err, errlen) != 0)
        return -1;
    if (row) {
        int ct = sqlite3_column_type(st, 0);
        if (type)
            *type = types[ct >= 1 && ct <= 5 ? ct : 0];
        if (ct != SQLITE_NULL)
            *v = sqlite3_column_double(st, 0);
    }
    sqlite3_finalize(st);
    return 0;
}

int amfi_store_test_text(amfi_store_test_db *t, const char *sql, char *buf, size_t len, char *err,
                         size_t errlen)
{
    sqlite3_stmt *st;
    int row;
    if (len)
        buf[0] = '\0';
    if (first_row(t, sql, &st, &row, err, errlen) != 0)
        return -1;
    if (row && sqlite3_column_text(st, 0))
        snprintf(buf, len, "%s", (const char *)sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    return 0;
}

int amfi_store_test_rows(amfi_store_test_db *t, const char *sql, amfi_store_test_row_fn fn,
                         void *ctx, char *err, size_t errlen)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(t->db, sql, -1, &st, NULL) != SQLITE_OK)
        return fail(err, errlen, sql, sqlite3_errmsg(t->db));
    int n = sqlite3_column_count(st), rc = 0, src;
    const char *text[64];
    if (n > 64)
        n = 64;
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        for (int k = 0; k < n; k++)
            text[k] = (const char *)sqlite3_column_text(st, k);
        rc = fn(ctx, n, text);
        src = SQLITE_DONE;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = fail(err, errlen, sql, sqlite3_errmsg(t->db));
    sqlite3_finalize(st);
    return rc;
}

static int record(amfi_store_test_db *t, int version, char *err, size_t errlen);

int amfi_store_test_create(const char *path, int version, char *err, size_t errlen)
{
    if (version < 1 || version > st_n_migrations)
        return fail(err, errlen, path, "no such schema version");
    amfi_store_test_db *t = amfi_store_test_open(path, 1, err, errlen);
    if (!t)
        return -1;
    int rc = amfi_store_test_exec(t, "PRAGMA journal_mode = WAL; BEGIN IMMEDIATE", err, errlen);
    for (int k = 0; rc == 0 && k < version; k++)
        rc = amfi_store_test_exec(t, st_migrations[k].sql, err, errlen);
    if (rc == 0)
        rc = record(t, version, err, errlen);
    if (rc == 0)
        rc = amfi_store_test_exec(t, "COMMIT", err, errlen);
    amfi_store_test_close(t);
    return rc;
}

static int record(amfi_store_test_db *t, int version, char *err, size_t errlen)
{
    char sql[160];
    int rc = 0;
    for (int k = 0; rc == 0 && k < version; k++) {
        const st_migration *m = &st_migrations[k];
        sqlite3_stmt *st = NULL;
        if (sqlite3_prepare_v2(t->db,
                               "INSERT INTO schema_migrations (version, description) VALUES (?1, ?2)",
                               -1, &st, NULL) != SQLITE_OK
            || sqlite3_bind_int(st, 1, m->version) != SQLITE_OK
            || sqlite3_bind_text(st, 2, m->description, -1, SQLITE_STATIC) != SQLITE_OK
            || sqlite3_step(st) != SQLITE_DONE)
            rc = fail(err, errlen, "schema_migrations", sqlite3_errmsg(t->db));
        sqlite3_finalize(st);
    }
    snprintf(sql, sizeof sql, "PRAGMA user_version = %d", version);
    if (rc == 0)
        rc = amfi_store_test_exec(t, sql, err, errlen);
    return rc;
}

int amfi_store_test_stamp(amfi_store_test_db *t, int version, char *err, size_t errlen)
{
    if (version < 1 || version > st_n_migrations)
        return fail(err, errlen, "stamp", "no such schema version");
    return record(t, version, err, errlen);
}

int amfi_store_test_downgrade(amfi_store_test_db *t, int version, char *err, size_t errlen)
{
    char sql[256];
    if (version < 1 || version > st_n_migrations)
        return fail(err, errlen, "downgrade", "no such schema version");
    int rc = 0;
    for (int k = 0; rc == 0 && k < amfi_store_n_tabledefs; k++) {
        const amfi_store_tabledef *tb = &amfi_store_tabledefs[k];
        int created = tb->cols[0].since;
        for (int j = 1; j < tb->ncols; j++)
            if (tb->cols[j].since < created)
                created = tb->cols[j].since;
        if (created > version) {
            snprintf(sql, sizeof sql, "DROP TABLE %s", tb->name);
            rc = amfi_store_test_exec(t, sql, err, errlen);
            continue;
        }
        for (int j = tb->ncols - 1; rc == 0 && j >= 0; j--) {
            if (tb->cols[j].since <= version)
                continue;
            snprintf(sql, sizeof sql, "ALTER TABLE %s DROP COLUMN %s", tb->name, tb->cols[j].name);
            rc = amfi_store_test_exec(t, sql, err, errlen);
        }
    }
    snprintf(sql, sizeof sql, "DELETE FROM schema_migrations WHERE version > %d", version);
    if (rc == 0)
        rc = amfi_store_test_exec(t, sql, err, errlen);
    snprintf(sql, sizeof sql, "PRAGMA user_version = %d", version);
    if (rc == 0)
        rc = amfi_store_test_exec(t, sql, err, errlen);
    return rc;
}
