/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema's migrations (fleet_schema.c), applied in
 * order by amfi-sync; fleet_migrations records the applied versions. */
#ifndef AMFI_FLEET_SCHEMA_H
#define AMFI_FLEET_SCHEMA_H

struct fleet_migration {
    int version;
    const char *description;
    const char *sql;
};
extern const struct fleet_migration fleet_migrations[];
extern const int fleet_n_migrations;

#endif
