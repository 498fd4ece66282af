/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema (fleet_schema.c): its migrations, applied in
 * order by amfi-sync (fleet_migrations records the applied versions), and
 * the site tables it holds with the columns shipped, read by amfi-sync and
 * amfi-report --pg alike. */
#ifndef AMFI_FLEET_SCHEMA_H
#define AMFI_FLEET_SCHEMA_H

#include <stddef.h>
#include <stdint.h>

struct fleet_migration {
    int version;
    const char *description;
    const char *sql;
};
extern const struct fleet_migration fleet_migrations[];
extern const int fleet_n_migrations;

/* What a shipped column may hold: the site store's rules (its types and
 * CHECK constraints, docs/schema.md), checked by amfi-sync on every value
 * it reads before anything of a pass is shipped. One per column of
 * fleet_table.cols, in that order, ended by a NULL name. */
enum fleet_col_type { FLEET_INT = 'i', FLEET_REAL = 'r', FLEET_TEXT = 't' };
struct fleet_col {
    const char *name;
    char type;            /* enum fleet_col_type */
    char null_ok;         /* NULL allowed */
    char open;            /* FLEET_REAL: 1 lo excluded, 2 hi excluded (bits) */
    double lo, hi;        /* FLEET_REAL: the range (finite values only) */
    int64_t ilo, ihi;     /* FLEET_INT: the range */
    const char *values;   /* FLEET_TEXT: "a|b|c", the values allowed, or NULL */
    int min_len, max_len; /* FLEET_TEXT: bytes (max 0: no limit); valid UTF-8,
                             no NUL */
};

/* What is wrong with a value of column c, NULL if nothing. The value comes
 * as its SQLite storage class (type: 1 integer, 2 real, 3 text, 5 NULL, as
 * SQLITE_INTEGER...) with i, r or text/len set accordingly; msg (at least
 * 160 bytes) receives the explanation returned. */
const char *fleet_col_problem(const struct fleet_col *c, int type, int64_t i, double r,
                              const char *text, int len, char *msg, size_t msglen);

/* One shipped site table: its name, the columns copied (id first; the same
 * names in the site store and the central table) with their rules, and the
 * child table shipped in the same transaction (axles for passages). */
struct fleet_table {
    const char *name;
    const char *cols;
    const struct fleet_col *rules;       /* cols' rules */
    const struct fleet_col *child_rules; /* child_cols' rules, or NULL */
    int hash_cols;             /* leading columns in the row hash: those of
                                  the central version that created the
                                  table, so that marks written before a
                                  column was added still match */
    const char *child;         /* NULL or child table */
    const char *child_cols;    /* its columns, parent id first */
    const char *child_parent;  /* the parent id column in the child */
};
extern const struct fleet_table fleet_tables[];
extern const int fleet_n_tables;

/* The oldest site store schema (PRAGMA user_version) whose columns
 * fleet_tables names: amfid migrates older stores when it starts. */
#define FLEET_MIN_STORE_VERSION 8

#endif
