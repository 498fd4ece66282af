/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema (fleet_schema.c): its migrations, applied in
 * order by amfi-sync (fleet_migrations records the applied versions), and
 * the site tables it holds with the columns shipped, read by amfi-sync and
 * amfi-report --pg alike. */
#ifndef AMFI_FLEET_SCHEMA_H
#define AMFI_FLEET_SCHEMA_H

struct fleet_migration {
    int version;
    const char *description;
    const char *sql;
};
extern const struct fleet_migration fleet_migrations[];
extern const int fleet_n_migrations;

/* One shipped site table: its name, the columns copied (id first; the same
 * names in the site store and the central table) and the child table
 * shipped in the same transaction (axles for passages). */
struct fleet_table {
    const char *name;
    const char *cols;
    int hash_cols;             /* leading columns in the row hash: those of
                                  central version 1, so that marks written
                                  before a column was added still match */
    const char *child;         /* NULL or child table */
    const char *child_cols;    /* its columns, parent id first */
    const char *child_parent;  /* the parent id column in the child */
};
extern const struct fleet_table fleet_tables[];
extern const int fleet_n_tables;

/* The oldest site store schema (PRAGMA user_version) whose columns
 * fleet_tables names: amfid migrates older stores when it starts. */
#define FLEET_MIN_STORE_VERSION 4

#endif
