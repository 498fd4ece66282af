/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_store_columns: the store's column table (store/store_columns.c) is
 * the one source of the schema's columns, so it must agree with what the
 * migrations build: every table of a fresh store has exactly the columns of
 * its table, in order, with their SQL type and NULL rule; each column exists
 * from its `since` version on and not before (stores made at each version
 * by the store's own migrations); the column table's REAL ranges are the
 * DDL's (a value just outside each range is refused by the file's CHECK and
 * reported by amfi_store_value_problem); and the column table in
 * docs/schema.md is exactly what amfi-store-schema --markdown writes.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store.h"
#include "store_columns.h"
#include "store_fixture.h"
#include "store_testing.h"

#ifndef AMFI_SCHEMA_DOC
#error "AMFI_SCHEMA_DOC (path of docs/schema.md) must be defined"
#endif

static int setup(void **state) { return store_fixture_setup(state, "amfi_test_columns"); }
static int teardown(void **state)
{
    static const char *const extra[] = {"v1.db", "v2.db", "v3.db", "v4.db", "v5.db", "v6.db",
                                        "v7.db", "v8.db", "v9.db", "v10.db", "v11.db", NULL};
    return store_fixture_teardown(state, extra);
}

/* PRAGMA table_info rows collected: name, type, notnull, pk. */
struct info {
    int n;
    char name[64][48], type[64][16];
    int notnull[64], pk[64];
};
static int info_row(void *ctx, int n, const char *const *t)
{
    struct info *in = ctx;
    assert_true(n >= 6 && in->n < 64);
    snprintf(in->name[in->n], sizeof in->name[0], "%s", t[1]);
    snprintf(in->type[in->n], sizeof in->type[0], "%s", t[2]);
    in->notnull[in->n] = atoi(t[3]);
    in->pk[in->n] = atoi(t[5]);
    in->n++;
    return 0;
}

static void table_info(amfi_store_test_db *db, const char *table, struct info *in)
{
    char sql[128], err[512];
    memset(in, 0, sizeof *in);
    snprintf(sql, sizeof sql, "PRAGMA table_info(%s)", table);
    if (amfi_store_test_rows(db, sql, info_row, in, err, sizeof err) != 0)
        fail_msg("%s", err);
}

struct names {
    int n;
    char v[32][48];
};
static int tab_row(void *ctx, int n, const char *const *t)
{
    struct names *tabs = ctx;
    assert_true(n == 1 && tabs->n < 32);
    snprintf(tabs->v[tabs->n++], 48, "%s", t[0]);
    return 0;
}

/* A fresh store's tables are the column table's, column by column. */
static void test_fresh_store_matches(void **state)
{
    fixture *f = *state;
    char err[512];
    amfi_store_test_db *db = amfi_store_test_open(f->path, 0, err, sizeof err);
    assert_non_null(db);
    for (int k = 0; k < amfi_store_n_tabledefs; k++) {
        const amfi_store_tabledef *t = &amfi_store_tabledefs[k];
        struct info in;
        table_info(db, t->name, &in);
        if (in.n != t->ncols)
            fail_msg("%s: the store has %d columns, the column table %d", t->name, in.n, t->ncols);
        for (int j = 0; j < t->ncols; j++) {
            const amfi_store_coldef *c = &t->cols[j];
            const char *type = c->sql_type == AMFI_SQL_INTEGER ? "INTEGER"
                               : c->sql_type == AMFI_SQL_REAL  ? "REAL"
                               : c->sql_type == AMFI_SQL_BLOB  ? "BLOB"
                                                               : "TEXT";
            if (strcmp(in.name[j], c->name) != 0)
                fail_msg("%s column %d: the store has %s, the column table %s", t->name, j,
                         in.name[j], c->name);
            if (strcmp(in.type[j], type) != 0)
                fail_msg("%s.%s: type %s in the store, %s in the column table", t->name, c->name,
                         in.type[j], type);
            /* an INTEGER PRIMARY KEY (the rowid) is NOT NULL without saying so */
            int notnull = in.notnull[j] || (in.pk[j] && strcmp(in.type[j], "INTEGER") == 0);
            if (notnull == c->null_ok)
                fail_msg("%s.%s: %s in the store, %s in the column table", t->name, c->name,
                         notnull ? "NOT NULL" : "NULL allowed",
                         c->null_ok ? "NULL allowed" : "NOT NULL");
        }
    }
    /* and every table of the store has a column table */
    struct names tabs;
    memset(&tabs, 0, sizeof tabs);
    assert_int_equal(0, amfi_store_test_rows(db,
                                             "SELECT name FROM sqlite_schema WHERE type = 'table' "
                                             "AND name <> 'schema_migrations' ORDER BY name",
                                             tab_row, &tabs, err, sizeof err));
    for (int k = 0; k < tabs.n; k++)
        if (!amfi_store_tabledef_find(tabs.v[k]))
            fail_msg("table %s of the store has no column table", tabs.v[k]);
    assert_int_equal(tabs.n, amfi_store_n_tabledefs);
    amfi_store_test_close(db);
}

/* Each column appears with the migration its `since` names. */
static void test_since(void **state)
{
    fixture *f = *state;
    char path[160], err[512];
    for (int v = 1; v <= AMFI_STORE_SCHEMA_VERSION; v++) {
        snprintf(path, sizeof path, "%s/v%d.db", f->dir, v);
        if (amfi_store_test_create(path, v, err, sizeof err) != 0)
            fail_msg("version %d: %s", v, err);
        amfi_store_test_db *db = amfi_store_test_open(path, 0, err, sizeof err);
        assert_non_null(db);
        int64_t uv = 0;
        assert_int_equal(0, amfi_store_test_int(db, "PRAGMA user_version", &uv, err, sizeof err));
        assert_int_equal(v, uv);
        for (int k = 0; k < amfi_store_n_tabledefs; k++) {
            const amfi_store_tabledef *t = &amfi_store_tabledefs[k];
            struct info in;
            table_info(db, t->name, &in);
            for (int j = 0; j < t->ncols; j++) {
                int found = 0;
                for (int i = 0; i < in.n; i++)
                    found |= strcmp(in.name[i], t->cols[j].name) == 0;
                if (found != (t->cols[j].since <= v))
                    fail_msg("%s.%s (since %d) is %s a version-%d store", t->name,
                             t->cols[j].name, t->cols[j].since, found ? "in" : "not in", v);
            }
        }
        amfi_store_test_close(db);
    }
}

/* The section of docs/schema.md between the column markers. */
static char *doc_section(void)
{
    FILE *fp = fopen(AMFI_SCHEMA_DOC, "r");
    char line[4096];
    size_t cap = 1 << 17, len = 0;
    char *out = malloc(cap);
    int in = 0, blocks = 0;
    assert_non_null(fp);
    assert_non_null(out);
    out[0] = '\0';
    while (fgets(line, sizeof line, fp)) {
        if (strncmp(line, "<!-- columns:begin -->", 22) == 0) {
            in = 1;
            blocks++;
            continue;
        }
        if (strncmp(line, "<!-- columns:end -->", 20) == 0) {
            in = 0;
            continue;
        }
        if (!in)
            continue;
        size_t n = strlen(line);
        assert_true(len + n + 1 < cap);
        memcpy(out + len, line, n + 1);
        len += n;
    }
    fclose(fp);
    assert_int_equal(1, blocks);
    return out;
}

static void test_doc_matches(void **state)
{
    (void)state;
    char *gen = NULL;
    size_t glen = 0;
    FILE *m = open_memstream(&gen, &glen);
    assert_non_null(m);
    assert_int_equal(0, amfi_store_columns_markdown(m));
    assert_int_equal(0, fclose(m));
    char *doc = doc_section();
    if (strcmp(gen, doc) != 0) {
        const char *p = gen, *q = doc;
        while (*p && *p == *q) {
            p++;
            q++;
        }
        while (p > gen && p[-1] != '\n') {
            p--;
            q--;
        }
        fail_msg("docs/schema.md's column table differs from the column table (regenerate it "
                 "with amfi-store-schema --markdown):\n table: %.200s\n doc:   %.200s",
                 p, q);
    }
    free(gen);
    free(doc);
}

/* The ranges are the DDL's: for every bounded REAL column, the value just
 * outside each bound is refused by the file's CHECK and named by
 * amfi_store_value_problem; the bound itself (when closed) passes both. */
static void test_ranges_are_the_ddl(void **state)
{
    fixture *f = *state;
    char err[512], sql[512], msg[200];
    amfi_store_test_db *db = amfi_store_test_open(f->path, 0, err, sizeof err);
    assert_non_null(db);
    int tried = 0;
    for (int k = 0; k < amfi_store_n_tabledefs; k++) {
        const amfi_store_tabledef *t = &amfi_store_tabledefs[k];
        for (int j = 0; j < t->ncols; j++) {
            const amfi_store_coldef *c = &t->cols[j];
            if (c->sql_type != AMFI_SQL_REAL)
                continue;
            double bounds[2] = {c->lo, c->hi};
            for (int b = 0; b < 2; b++) {
                if (isinf(bounds[b]))
                    continue;
                int open = b == 0 ? (c->open & 1) : (c->open & 2);
                double out = bounds[b] + (b == 0 ? -1 : 1) * (fabs(bounds[b]) * 1e-9 + 1e-9);
                amfi_store_value v = {.type = AMFI_SQL_REAL, .r = out};
                if (!amfi_store_value_problem(c, &v, msg, sizeof msg))
                    fail_msg("%s.%s: %.17g outside the range passes the column table", t->name,
                             c->name, out);
                v.r = bounds[b];
                if (!open && amfi_store_value_problem(c, &v, msg, sizeof msg))
                    fail_msg("%s.%s: the bound %.17g is refused: %s", t->name, c->name,
                             bounds[b], msg);
                /* the DDL: the column's CHECK text evaluated on the value */
                char check[512] = "";
                snprintf(sql, sizeof sql,
                         "SELECT sql FROM sqlite_schema WHERE type = 'table' AND name = '%s'",
                         t->name);
                char ddl[16384];
                assert_int_equal(0, amfi_store_test_text(db, sql, ddl, sizeof ddl, err, sizeof err));
                /* the column's definition line(s): from "  NAME " (or
                 * "COLUMN NAME ") to the next column's */
                char key[64];
                snprintf(key, sizeof key, "\n  %s ", c->name);
                const char *p = strstr(ddl, key);
                if (!p) {
                    snprintf(key, sizeof key, "ADD COLUMN %s ", c->name);
                    p = strstr(ddl, key);
                }
                if (!p) {
                    snprintf(key, sizeof key, " %s REAL", c->name);
                    p = strstr(ddl, key);
                }
                assert_non_null(p);
                const char *cp = strstr(p, "CHECK (");
                assert_non_null(cp);
                cp += 6;
                int depth = 0;
                size_t n = 0;
                for (; *cp && n + 1 < sizeof check; cp++) {
                    check[n++] = *cp;
                    if (*cp == '(') depth++;
                    if (*cp == ')' && --depth == 0) break;
                }
                check[n] = '\0';
                /* CHECK (x BETWEEN ...) with x replaced: evaluate it on
                 * the value as a literal in a CTE named like the column */
                int64_t yes = -1;
                snprintf(sql, sizeof sql, "WITH v(%s) AS (SELECT %.17g) SELECT %s FROM v", c->name,
                         out, check);
                assert_int_equal(0, amfi_store_test_int(db, sql, &yes, err, sizeof err));
                if (yes != 0)
                    fail_msg("%s.%s: %.17g is outside the column table's range but the DDL's "
                             "CHECK %s accepts it", t->name, c->name, out, check);
                if (!open) {
                    snprintf(sql, sizeof sql, "WITH v(%s) AS (SELECT %.17g) SELECT %s FROM v",
                             c->name, bounds[b], check);
                    assert_int_equal(0, amfi_store_test_int(db, sql, &yes, err, sizeof err));
                    if (yes != 1)
                        fail_msg("%s.%s: the bound %.17g is the column table's but the DDL's "
                                 "CHECK %s refuses it", t->name, c->name, bounds[b], check);
                }
                tried++;
            }
        }
    }
    assert_true(tried > 40);
    amfi_store_test_close(db);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_fresh_store_matches, setup, teardown),
        cmocka_unit_test_setup_teardown(test_since, setup, teardown),
        cmocka_unit_test_setup_teardown(test_doc_matches, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ranges_are_the_ddl, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
