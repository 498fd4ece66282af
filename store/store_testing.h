/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_testing.h: raw SQL on a store's file, for tests only (library
 * amfi_store_testing, linked by tests and never by a program): the fixtures
 * a test needs that the store's API refuses to make (damaged rows, old
 * schema versions, a user's own SQL), and what a user's sqlite3 would see.
 * A connection is SQLite's own, with no store defences. Errors end the
 * call with a message in err; the functions never abort.
 */
#ifndef AMFI_STORE_TESTING_H
#define AMFI_STORE_TESTING_H

#include <stddef.h>
#include <stdint.h>

typedef struct amfi_store_test_db amfi_store_test_db;

/* A connection to path (read-write; created when create != 0), busy
 * timeout 5 s; NULL on failure (message in err). */
amfi_store_test_db *amfi_store_test_open(const char *path, int create, char *err, size_t errlen);
void amfi_store_test_close(amfi_store_test_db *db); /* NULL-safe */

/* Run one or more statements: 0, or -1 with SQLite's message. */
int amfi_store_test_exec(amfi_store_test_db *db, const char *sql, char *err, size_t errlen);
/* The first column of the first row: as an integer (*v 0 when NULL or no
 * row), a real (*v NaN then) or text (buf "" then); *type (when not NULL)
 * gets 'i', 'r', 't', 'b' or 0 (NULL / no row). 0, or -1. */
int amfi_store_test_int(amfi_store_test_db *db, const char *sql, int64_t *v, char *err,
                        size_t errlen);
int amfi_store_test_real(amfi_store_test_db *db, const char *sql, double *v, int *type, char *err,
                         size_t errlen);
int amfi_store_test_text(amfi_store_test_db *db, const char *sql, char *buf, size_t len, char *err,
                         size_t errlen);
/* Every row of sql: fn gets its columns as text (NULL as a NULL pointer);
 * nonzero from fn stops and is returned. */
typedef int (*amfi_store_test_row_fn)(void *ctx, int n, const char *const *text);
int amfi_store_test_rows(amfi_store_test_db *db, const char *sql, amfi_store_test_row_fn fn,
                         void *ctx, char *err, size_t errlen);

/* A new store at path (which must not exist) at schema `version` (1 ..
 * AMFI_STORE_SCHEMA_VERSION): the store's own migrations 1 .. version
 * applied and recorded as amfi_store_open does, in WAL mode. The old
 * versions of the test fixtures come from here, never from a version
 * number written by hand. 0, or -1. */
int amfi_store_test_create(const char *path, int version, char *err, size_t errlen);

/* The store taken back to schema `version`, as that version's amfid left
 * it, from the column table (store_columns.c): the tables a later migration
 * created dropped, the columns a later one added dropped (their data with
 * them), the later schema_migrations rows deleted, user_version set. 0, or
 * -1. */
int amfi_store_test_downgrade(amfi_store_test_db *db, int version, char *err, size_t errlen);

/* user_version and the schema_migrations rows 1 .. version as the store's
 * migrations record them, on a file built from docs/schema.md's DDL. 0, or
 * -1. */
int amfi_store_test_stamp(amfi_store_test_db *db, int version, char *err, size_t errlen);

#endif /* AMFI_STORE_TESTING_H */
