/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema (fleet_schema.c): its migrations, applied in
 * order by amfi-sync (fleet_migrations records the applied versions), and
 * the site tables it holds with the columns shipped, read by amfi-sync and
 * amfi-report --pg alike. */
#ifndef AMFI_FLEET_SCHEMA_H
#define AMFI_FLEET_SCHEMA_H

#include <stddef.h>
#include <stdint.h>

#include "store_columns.h"

struct fleet_migration {
    int version;
    const char *description;
    const char *sql;
};
extern const struct fleet_migration fleet_migrations[];
extern const int fleet_n_migrations;
/* roles.sql: the roles and row-level security of the current version, one
 * source (installed as share/amfi/roles.sql; docs/fleet.md, Roles). Runs
 * again without change. amfi-sync runs it once, in the same transaction,
 * after the last of the migrations it applies when one of them is of
 * version FLEET_ROLES_SQL_FROM or later: it describes the current schema,
 * so it cannot run between two migrations. A migration that adds a table
 * or a view adds its rights and policies to roles.sql. */
extern const char *const fleet_roles_sql;
#define FLEET_ROLES_SQL_FROM 8

/* One shipped site table: its name and the child table shipped in the same
 * transaction (axles for passages). The columns shipped are those of the
 * store's column table (store_columns.h) that a central version added
 * (amfi_store_coldef.shipped > 0), in the table's order, id first; the site
 * store's rules for them (amfi_store_value_problem) are checked by
 * amfi-sync on every value it reads before anything of a pass is shipped. */
struct fleet_table {
    const char *name;
    const char *child;         /* NULL or child table */
    const char *child_parent;  /* the parent id column in the child */
};
extern const struct fleet_table fleet_tables[];
extern const int fleet_n_tables;

/* The shipped columns of the site table `table`: up to max of their
 * descriptions into defs and names into names (either may be NULL);
 * returns their number (0: not a store table). */
int fleet_columns(const char *table, const amfi_store_coldef **defs, const char **names, int max);
/* "id, vehicle_id, ..." of the same columns into buf. */
void fleet_cols_text(const char *table, char *buf, size_t len);
/* Leading columns in the row hash: those of the central version that
 * created the table, so that marks written before a column was added still
 * match. */
int fleet_hash_cols(const char *table);

/* The oldest site store schema (PRAGMA user_version) whose columns
 * fleet_tables names: amfid migrates older stores when it starts. */
#define FLEET_MIN_STORE_VERSION 13

/* A site's facts (fleet_sites; the site store's meta site.*) as
 * amfid.yaml(5) allows them, checked by amfi-sync before it ships them and
 * by amfi-report --pg when it reads them back: site.name and
 * site.bridge_type valid UTF-8 without control characters (their lengths
 * are the caller's to check); site.latitude / longitude a number of degrees
 * in [-lim, lim] (nothing after it, not out of a double's range). 1 or 0. */
int fleet_site_text_ok(const char *s);
int fleet_site_coord_ok(const char *s, double lim);

#endif
