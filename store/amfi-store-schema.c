/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi-store-schema: the store's column table (store_columns.c) as the
 * Markdown of docs/schema.md's section between "<!-- columns:begin -->" and
 * "<!-- columns:end -->" (--markdown), or as one line per column, tab
 * separated (--list: table, column, SQL type, NULL allowed, since, shipped),
 * for developers and the tests (store_schema_doc). Not installed. */
#include <stdio.h>
#include <string.h>

#include "store_columns.h"

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--markdown") == 0)
        return amfi_store_columns_markdown(stdout) == 0 && fflush(stdout) == 0 ? 0 : 1;
    if (argc == 2 && strcmp(argv[1], "--list") == 0) {
        for (int k = 0; k < amfi_store_n_tabledefs; k++) {
            const amfi_store_tabledef *t = &amfi_store_tabledefs[k];
            for (int j = 0; j < t->ncols; j++) {
                const amfi_store_coldef *c = &t->cols[j];
                printf("%s\t%s\t%s\t%d\t%d\t%d\n", t->name, c->name,
                       c->sql_type == AMFI_SQL_INTEGER ? "INTEGER"
                       : c->sql_type == AMFI_SQL_REAL  ? "REAL"
                       : c->sql_type == AMFI_SQL_BLOB  ? "BLOB"
                                                       : "TEXT",
                       c->null_ok, c->since, c->shipped);
            }
        }
        return fflush(stdout) == 0 ? 0 : 1;
    }
    fputs("usage: amfi-store-schema --markdown | --list\n", stderr);
    return 2;
}
