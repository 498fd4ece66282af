/* SPDX-License-Identifier: GPL-3.0-or-later */
/* store_stamp DB [VERSION]: a store file built from docs/schema.md's DDL
 * gets the schema version (default: this program's) and the
 * schema_migrations rows the store's own migrations record
 * (amfi_store_test_stamp), so that no fixture writes a version by hand. */
#include <stdio.h>
#include <stdlib.h>

#include "store.h"
#include "store_testing.h"

int main(int argc, char **argv)
{
    char err[512];
    if (argc < 2 || argc > 3) {
        fputs("usage: store_stamp DB [VERSION]\n", stderr);
        return 2;
    }
    int v = argc == 3 ? atoi(argv[2]) : AMFI_STORE_SCHEMA_VERSION;
    amfi_store_test_db *db = amfi_store_test_open(argv[1], 0, err, sizeof err);
    int rc = db ? amfi_store_test_stamp(db, v, err, sizeof err) : -1;
    amfi_store_test_close(db);
    if (rc != 0) {
        fprintf(stderr, "store_stamp: %s\n", err);
        return 1;
    }
    return 0;
}
