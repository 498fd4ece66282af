/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi-sync: ships a site store's new rows (passages with axles, indicators,
 * alerts, baseline, runs, environment, scale_evals) into the central
 * PostgreSQL (issues 15 and 14). Every value is checked against the site
 * store's rules (fleet_col) before anything of a pass is shipped.
 *
 * Single-threaded. Reads the SQLite store read-only (SQLITE_OPEN_READONLY; in
 * WAL mode a reader never blocks amfid's writer) and writes the central
 * database with libpq, as the site's own role, which row-level security
 * binds to the site's rows (central version 6), over TLS to a server not on
 * this machine (fleet_pg.c). Each batch is one PostgreSQL transaction holding
 * the rows (COPY into a temporary table, then INSERT ... SELECT) and the
 * table's high-water mark in fleet_sync_state, so a crash
 * at any moment leaves either the whole batch or none of it. The mark also
 * keeps a hash of the last shipped row: a store restored from an older backup
 * (ids going backwards, or a different row at a shipped id) is refused. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <inttypes.h>
#include <libpq-fe.h>
#include <signal.h>
#include <sqlite3.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <systemd/sd-daemon.h>

#include "amfi_cli.h"
#include "amfi_config.h"
#include "fleet_pg.h"
#include "fleet_schema.h"
#include "amfi_time.h"

enum { BATCH_ROWS = 5000, SITE_ID_MAX = 63 };


static volatile sig_atomic_t stop_requested;
static void on_signal(int sig) { (void)sig; stop_requested = 1; }

/* 64-bit FNV-1a over a row's text form (fields separated by 0x1f); row_hash
 * takes the first ncols columns (fleet_table.hash_cols). */
static uint64_t fnv1a(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) { h ^= b[i]; h *= 0x100000001b3ULL; }
    return h;
}

/* Append s to buf (growing) with COPY text escapes; NULL -> \N. */
struct buf { char *p; size_t n, cap; };
static int buf_put(struct buf *b, const char *s, size_t n)
{
    if (b->n + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap * 2 : 65536;
        while (cap < b->n + n + 1) cap *= 2;
        char *q = realloc(b->p, cap);
        if (!q) return -1;
        b->p = q; b->cap = cap;
    }
    memcpy(b->p + b->n, s, n);
    b->n += n;
    return 0;
}
static int buf_field(struct buf *b, const unsigned char *s, int isnull)
{
    if (isnull) return buf_put(b, "\\N", 2);
    for (; *s; s++) {
        const char *e = NULL;
        switch (*s) {
        case '\\': e = "\\\\"; break;
        case '\t': e = "\\t"; break;
        case '\n': e = "\\n"; break;
        case '\r': e = "\\r"; break;
        default: break;
        }
        if (e ? buf_put(b, e, 2) : buf_put(b, (const char *)s, 1)) return -1;
    }
    return 0;
}

/* Text of the column of the current row; REAL as %.17g so the copy is exact. */
static const unsigned char *col_text(sqlite3_stmt *st, int i, char tmp[40], int *isnull)
{
    int t = sqlite3_column_type(st, i);
    *isnull = t == SQLITE_NULL;
    if (t == SQLITE_FLOAT) {
        snprintf(tmp, 40, "%.17g", sqlite3_column_double(st, i));
        return (const unsigned char *)tmp;
    }
    return *isnull ? (const unsigned char *)"" : sqlite3_column_text(st, i);
}

static uint64_t row_hash(sqlite3_stmt *st, int ncols)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    char tmp[40];
    int isnull;
    for (int i = 0; i < ncols && i < sqlite3_column_count(st); i++) {
        const unsigned char *s = col_text(st, i, tmp, &isnull);
        h = fnv1a(h, isnull ? "\x01N" : (const char *)s, isnull ? 2 : strlen((const char *)s));
        h = fnv1a(h, "\x1f", 1);
    }
    return h;
}

/* Watchdog pings while a long first sync ships batch after batch, and while
 * follow mode sleeps: at most every half watchdog period (none when systemd
 * set no watchdog). */
static uint64_t wd_usec;
static double wd_last;
static void keepalive(void)
{
    if (!wd_usec) return;
    double now = amfi_mono_s();
    if (now - wd_last >= 0.5e-6 * (double)wd_usec) {
        sd_notify(0, "WATCHDOG=1");
        wd_last = now;
    }
}

/* The store read without its -wal and -shm files (docs/fleet.md, "amfi-sync's
 * user"): amfi-sync's user may only read the store, and SQLite cannot read a
 * WAL database whose -shm it can neither open nor create, which is the case
 * when amfid is stopped (it removes both at a clean close). Then the store is
 * opened immutable (no locks, no -shm), which is right only while nobody
 * writes it: the main file's identity, size and modification time are noted
 * when it is opened and every batch is committed only if they have not
 * changed and no -wal file has appeared (amfid started meanwhile); otherwise
 * the batch is rolled back and the pass retried. */
static int store_immutable;
static struct stat store_st;
static char store_wal[4200];
static int store_moved(const char *store)
{
    if (!store_immutable) return 0;
    struct stat st;
    if (stat(store, &st) != 0 || st.st_ino != store_st.st_ino || st.st_dev != store_st.st_dev
        || st.st_size != store_st.st_size || st.st_mtim.tv_sec != store_st.st_mtim.tv_sec
        || st.st_mtim.tv_nsec != store_st.st_mtim.tv_nsec || access(store_wal, F_OK) == 0) {
        fprintf(stderr, "amfi-sync: %s: the store changed while it was read without its -wal file "
                        "(amfid started?): batch rolled back, retried\n", store);
        return 1;
    }
    return 0;
}

static int pg_ok(PGresult *r, const char *what)
{
    ExecStatusType s = PQresultStatus(r);
    if (s == PGRES_COMMAND_OK || s == PGRES_TUPLES_OK) return 0;
    fprintf(stderr, "amfi-sync: PostgreSQL: %s: %s", what, PQresultErrorMessage(r));
    return -1;
}
static int pg_exec(PGconn *pg, const char *sql, const char *what)
{
    PGresult *r = PQexec(pg, sql);
    int rc = pg_ok(r, what);
    PQclear(r);
    return rc;
}

/* Exit codes: 0 done, 1 server or store trouble (retry), 2 usage, 3 refused. */
enum { EX_RETRY = 1, EX_USAGE = 2, EX_REFUSED = 3 };

/* Apply the central migrations not yet applied (under an advisory lock so
 * several sites starting at once do not race). */
static int apply_schema(PGconn *pg)
{
    if (pg_exec(pg, "BEGIN", "BEGIN")) return EX_RETRY;
    if (pg_exec(pg, "SELECT pg_advisory_xact_lock(1095583305)", "schema lock")) {
        pg_exec(pg, "ROLLBACK", "ROLLBACK");
        return EX_RETRY;
    }
    /* Look before creating: a writer role without CREATE on the schema
     * (docs/fleet.md, Roles) must get past an up-to-date schema. */
    PGresult *r = PQexec(pg, "SELECT to_regclass('fleet_migrations') IS NOT NULL");
    int exists = !pg_ok(r, "schema lookup") && PQgetvalue(r, 0, 0)[0] == 't';
    PQclear(r);
    if (!exists
        && pg_exec(pg, "CREATE TABLE fleet_migrations (version integer PRIMARY KEY, "
                       "description text NOT NULL, applied_at timestamptz NOT NULL DEFAULT now())",
                   "fleet_migrations")) {
        fprintf(stderr, "amfi-sync: the central database has no amfi schema and this role cannot create "
                        "it: run 'amfi-sync --init-schema' as the database owner (docs/fleet.md)\n");
        pg_exec(pg, "ROLLBACK", "ROLLBACK");
        return EX_RETRY;
    }
    r = PQexec(pg, "SELECT coalesce(max(version), 0) FROM fleet_migrations");
    if (pg_ok(r, "schema version")) {
        /* no right to read it: a role of no site (the shared writer of the
         * central versions before 6, retired by version 6) */
        const char *state = PQresultErrorField(r, PG_DIAG_SQLSTATE);
        int denied = state && strcmp(state, "42501") == 0;
        if (denied)
            fprintf(stderr, "amfi-sync: this role is not a site's role: the owner creates one per site "
                            "with 'amfi-sync --init-site-role SITE' (docs/fleet.md, Roles)\n");
        PQclear(r);
        pg_exec(pg, "ROLLBACK", "ROLLBACK");
        return denied ? EX_USAGE : EX_RETRY;
    }
    int have = atoi(PQgetvalue(r, 0, 0));
    PQclear(r);
    for (int i = have; i < fleet_n_migrations; i++) {
        char ins[256];
        snprintf(ins, sizeof ins, "INSERT INTO fleet_migrations (version, description) VALUES (%d, '%s')",
                 fleet_migrations[i].version, fleet_migrations[i].description);
        if (pg_exec(pg, fleet_migrations[i].sql, "migration") || pg_exec(pg, ins, "migration record")) {
            fprintf(stderr, "amfi-sync: the central schema is at version %d, this program needs %d: "
                            "run 'amfi-sync --init-schema' as the database owner (docs/fleet.md)\n",
                    have, fleet_n_migrations);
            pg_exec(pg, "ROLLBACK", "ROLLBACK");
            return EX_RETRY;
        }
    }
    return pg_exec(pg, "COMMIT", "COMMIT") ? EX_RETRY : 0;
}


/* COPY the rows of one SELECT into table dst with the site id in front;
 * the last row's id and the hash of its first hash_cols columns go to
 * *last_id and *last_hash when last_id is not NULL. */
static int copy_rows(PGconn *pg, sqlite3 *db, const char *site, const char *dst, const char *cols,
                     int hash_cols,
                     const char *sel, int64_t lo, int64_t hi, int64_t *last_id, uint64_t *last_hash,
                     long *nrows)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, sel, -1, &st, NULL) != SQLITE_OK) {
        fprintf(stderr, "amfi-sync: store: %s: %s\n", dst, sqlite3_errmsg(db));
        return EX_RETRY;
    }
    sqlite3_bind_int64(st, 1, lo);
    sqlite3_bind_int64(st, 2, hi);
    struct buf b = {0};
    int rc, n = 0;
    char tmp[40];
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        int isnull;
        buf_field(&b, (const unsigned char *)site, 0);
        for (int i = 0; i < sqlite3_column_count(st); i++) {
            buf_put(&b, "\t", 1);
            const unsigned char *s = col_text(st, i, tmp, &isnull);
            if (buf_field(&b, s, isnull)) { rc = SQLITE_NOMEM; break; }
        }
        if (buf_put(&b, "\n", 1)) { rc = SQLITE_NOMEM; break; }
        if (last_id) { *last_id = sqlite3_column_int64(st, 0); *last_hash = row_hash(st, hash_cols); }
        n++;
    }
    if (rc != SQLITE_DONE) {
        fprintf(stderr, "amfi-sync: store: reading %s: %s\n", dst, sqlite3_errmsg(db));
        sqlite3_finalize(st); free(b.p);
        return EX_RETRY;
    }
    sqlite3_finalize(st);
    *nrows = n;
    if (n == 0) { free(b.p); return 0; }
    /* PostgreSQL refuses COPY FROM into a table whose row-level security
     * binds the role (every site role, docs/fleet.md, Roles): the rows go
     * by COPY into a temporary table of the same columns (this session's
     * own, emptied at every commit), then by one INSERT ... SELECT into the
     * site table, where the policies check every row. */
    char copy[2048];
    snprintf(copy, sizeof copy,
             "CREATE TEMP TABLE IF NOT EXISTS amfi_in_%s (LIKE %s) ON COMMIT DELETE ROWS", dst, dst);
    if (pg_exec(pg, copy, "temporary table")) { free(b.p); return EX_RETRY; }
    snprintf(copy, sizeof copy, "COPY pg_temp.amfi_in_%s (site_id, %s) FROM STDIN", dst, cols);
    PGresult *r = PQexec(pg, copy);
    if (PQresultStatus(r) != PGRES_COPY_IN) { pg_ok(r, copy); PQclear(r); free(b.p); return EX_RETRY; }
    PQclear(r);
    int bad = PQputCopyData(pg, b.p, (int)b.n) != 1 || PQputCopyEnd(pg, NULL) != 1;
    free(b.p);
    r = PQgetResult(pg);
    bad |= pg_ok(r, dst) != 0;
    PQclear(r);
    while ((r = PQgetResult(pg))) PQclear(r);
    if (bad) return EX_RETRY;
    snprintf(copy, sizeof copy, "INSERT INTO %s (site_id, %s) SELECT site_id, %s FROM pg_temp.amfi_in_%s",
             dst, cols, cols, dst);
    return pg_exec(pg, copy, dst) ? EX_RETRY : 0;
}

/* Every value of the rows SELECT sel gives (ids above hwm) against the
 * site store's rules (fleet_col): a store that breaks its own schema (a
 * damaged file, a row written around amfid) is refused before anything of
 * the pass is shipped, naming the table, the row and the column. */
static int check_rows(sqlite3 *db, const char *site, const char *store, const char *table,
                      const struct fleet_col *rules, int key_cols, const char *sel, int64_t hwm)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, sel, -1, &st, NULL) != SQLITE_OK) {
        fprintf(stderr, "amfi-sync: store: %s: %s\n", table, sqlite3_errmsg(db));
        return EX_RETRY;
    }
    int ncols = sqlite3_column_count(st);
    for (int i = 0; i <= ncols; i++)
        if ((i == ncols) != (rules[i].name == NULL)
            || (i < ncols && strcmp(rules[i].name, sqlite3_column_name(st, i)) != 0)) {
            fprintf(stderr, "amfi-sync: internal: %s: the rules do not match the columns shipped\n", table);
            sqlite3_finalize(st);
            return EX_USAGE;
        }
    sqlite3_bind_int64(st, 1, hwm);
    int rc;
    long n = 0;
    char msg[200];
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        for (int i = 0; i < ncols; i++) {
            int type = sqlite3_column_type(st, i);
            const char *text = type == SQLITE_TEXT ? (const char *)sqlite3_column_text(st, i) : NULL;
            const char *why = fleet_col_problem(
                &rules[i], type, type == SQLITE_INTEGER ? sqlite3_column_int64(st, i) : 0,
                type == SQLITE_FLOAT ? sqlite3_column_double(st, i) : 0, text,
                text ? sqlite3_column_bytes(st, i) : 0, msg, sizeof msg);
            if (!why) continue;
            char key[96] = "";
            for (int k = 0; k < key_cols; k++)
                snprintf(key + strlen(key), sizeof key - strlen(key), "%s%s %lld", k ? ", " : "",
                         rules[k].name, (long long)sqlite3_column_int64(st, k));
            fprintf(stderr,
                    "amfi-sync: refused: site '%s' store %s: table %s, %s, column %s: %s "
                    "(the site store's rules, docs/schema.md). Nothing shipped "
                    "(see docs/fleet.md, 'Bad values')\n",
                    site, store, table, key, rules[i].name, why);
            sqlite3_finalize(st);
            return EX_REFUSED;
        }
        if (++n % 4096 == 0) keepalive();
    }
    if (rc != SQLITE_DONE) fprintf(stderr, "amfi-sync: store: reading %s: %s\n", table, sqlite3_errmsg(db));
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? 0 : EX_RETRY;
}

/* Ship one table until it has no more new rows. */
static int sync_table(PGconn *pg, sqlite3 *db, const char *site, const char *store,
                      const struct fleet_table *t, int check_only, long *total)
{
    char sql[1024];
    const char *pv[2] = {site, t->name};
    PGresult *r = PQexecParams(pg, "SELECT hwm, last_hash FROM fleet_sync_state WHERE site_id = $1 AND tbl = $2",
                               2, NULL, pv, NULL, NULL, 0);
    if (pg_ok(r, "fleet_sync_state")) { PQclear(r); return EX_RETRY; }
    int64_t hwm = 0;
    uint64_t hash = 0;
    if (PQntuples(r) == 1) {
        hwm = strtoll(PQgetvalue(r, 0, 0), NULL, 10);
        hash = strtoull(PQgetvalue(r, 0, 1), NULL, 16);
    }
    PQclear(r);
    /* The row at the mark must still be the one shipped. */
    if (hwm > 0) {
        sqlite3_stmt *st = NULL;
        snprintf(sql, sizeof sql, "SELECT %s FROM %s WHERE id = ?1", t->cols, t->name);
        if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
            fprintf(stderr, "amfi-sync: store: %s: %s\n", t->name, sqlite3_errmsg(db));
            return EX_RETRY;
        }
        sqlite3_bind_int64(st, 1, hwm);
        int rc = sqlite3_step(st);
        uint64_t h = rc == SQLITE_ROW ? row_hash(st, t->hash_cols) : 0;
        sqlite3_finalize(st);
        if (rc != SQLITE_ROW || h != hash) {
            fprintf(stderr,
                    "amfi-sync: refused: site '%s' table %s: the central database holds rows up to id %" PRId64
                    " but the store %s; was the store restored from an older backup? Nothing merged "
                    "(see docs/fleet.md, 'Restored stores')\n",
                    site, t->name, hwm, rc == SQLITE_ROW ? "has a different row at that id" : "has no row at that id");
            return EX_REFUSED;
        }
    }
    if (check_only) {
        /* the rows to ship: every value as the site store's rules say */
        snprintf(sql, sizeof sql, "SELECT %s FROM %s WHERE id > ?1 ORDER BY id", t->cols, t->name);
        int rc = check_rows(db, site, store, t->name, t->rules, 1, sql, hwm);
        if (!rc && t->child) {
            snprintf(sql, sizeof sql, "SELECT %s FROM %s WHERE %s > ?1 ORDER BY %s", t->child_cols,
                     t->child, t->child_parent, t->child_parent);
            rc = check_rows(db, site, store, t->child, t->child_rules, 2, sql, hwm);
        }
        return rc;
    }
    for (;;) {
        if (stop_requested) return 0;
        if (pg_exec(pg, "BEGIN", "BEGIN")) return EX_RETRY;
        int64_t last = hwm;
        uint64_t lh = hash;
        long n = 0, nc = 0;
        snprintf(sql, sizeof sql, "SELECT %s FROM %s WHERE id > ?1 AND ?2 > 0 ORDER BY id LIMIT %d",
                 t->cols, t->name, BATCH_ROWS);
        int rc = copy_rows(pg, db, site, t->name, t->cols, t->hash_cols, sql, hwm, 1, &last, &lh, &n);
        if (!rc && n > 0 && t->child) {
            snprintf(sql, sizeof sql, "SELECT %s FROM %s WHERE %s > ?1 AND %s <= ?2 ORDER BY %s",
                     t->child_cols, t->child, t->child_parent, t->child_parent, t->child_parent);
            rc = copy_rows(pg, db, site, t->child, t->child_cols, 0, sql, hwm, last, NULL, NULL, &nc);
        }
        if (!rc && n > 0) {
            char shwm[24], shash[24];
            snprintf(shwm, sizeof shwm, "%" PRId64, last);
            snprintf(shash, sizeof shash, "%016" PRIx64, lh);
            const char *p[4] = {site, t->name, shwm, shash};
            r = PQexecParams(pg,
                             "INSERT INTO fleet_sync_state (site_id, tbl, hwm, last_hash) VALUES ($1, $2, $3, $4) "
                             "ON CONFLICT (site_id, tbl) DO UPDATE SET hwm = EXCLUDED.hwm, "
                             "last_hash = EXCLUDED.last_hash, synced_at = now()",
                             4, NULL, p, NULL, NULL, 0);
            rc = pg_ok(r, "fleet_sync_state") ? EX_RETRY : 0;
            PQclear(r);
        }
        if (!rc && n > 0 && store_moved(store)) rc = EX_RETRY;
        if (rc || n == 0) { pg_exec(pg, "ROLLBACK", "ROLLBACK"); return rc; }
        if (pg_exec(pg, "COMMIT", "COMMIT")) return EX_RETRY;
        hwm = last;
        hash = lh;
        *total += n + nc;
        keepalive();
    }
}

/* Local ids lower than the central mark: the store went backwards. */
static int check_backwards(PGconn *pg, sqlite3 *db, const char *site)
{
    for (int i = 0; i < fleet_n_tables; i++) {
        const char *pv[2] = {site, fleet_tables[i].name};
        PGresult *r = PQexecParams(pg, "SELECT hwm FROM fleet_sync_state WHERE site_id = $1 AND tbl = $2",
                                   2, NULL, pv, NULL, NULL, 0);
        if (pg_ok(r, "fleet_sync_state")) { PQclear(r); return EX_RETRY; }
        int64_t hwm = PQntuples(r) ? strtoll(PQgetvalue(r, 0, 0), NULL, 10) : 0;
        PQclear(r);
        char sql[128];
        snprintf(sql, sizeof sql, "SELECT coalesce(max(id), 0) FROM %s", fleet_tables[i].name);
        sqlite3_stmt *st = NULL;
        if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK || sqlite3_step(st) != SQLITE_ROW) {
            fprintf(stderr, "amfi-sync: store: %s: %s\n", fleet_tables[i].name, sqlite3_errmsg(db));
            sqlite3_finalize(st);
            return EX_RETRY;
        }
        int64_t mx = sqlite3_column_int64(st, 0);
        sqlite3_finalize(st);
        if (mx < hwm) {
            fprintf(stderr,
                    "amfi-sync: refused: site '%s' table %s: the store's newest id is %" PRId64
                    " but id %" PRId64 " was already shipped (ids going backwards); was the store restored "
                    "from an older backup? Nothing merged (see docs/fleet.md, 'Restored stores')\n",
                    site, fleet_tables[i].name, mx, hwm);
            return EX_REFUSED;
        }
    }
    return 0;
}

/* The store is read as a file from elsewhere: SQLite's defensive mode, an
 * untrusted schema (views and triggers may call only innocuous functions),
 * no extension loading, triggers and views off (amfi-sync reads tables
 * only), query_only; every setting read back. A store holding a trigger or
 * a view in place of a table shipped fails on the first read of it. */
static int store_harden(sqlite3 *db, const char *store)
{
    static const struct {
        int op, want;
        const char *name;
    } set[] = {
        {SQLITE_DBCONFIG_DEFENSIVE, 1, "SQLITE_DBCONFIG_DEFENSIVE"},
        {SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, "SQLITE_DBCONFIG_TRUSTED_SCHEMA"},
        {SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION, 0, "SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION"},
        {SQLITE_DBCONFIG_ENABLE_TRIGGER, 0, "SQLITE_DBCONFIG_ENABLE_TRIGGER"},
        {SQLITE_DBCONFIG_ENABLE_VIEW, 0, "SQLITE_DBCONFIG_ENABLE_VIEW"},
    };
    for (size_t k = 0; k < sizeof set / sizeof set[0]; k++) {
        int got = -1;
        if (sqlite3_db_config(db, set[k].op, set[k].want, &got) != SQLITE_OK || got != set[k].want) {
            fprintf(stderr, "amfi-sync: %s: cannot set %s to %d (SQLite %s)\n", store, set[k].name,
                    set[k].want, sqlite3_libversion());
            return -1;
        }
    }
    char *emsg = NULL;
    if (sqlite3_exec(db, "PRAGMA query_only = ON", NULL, NULL, &emsg) != SQLITE_OK) {
        fprintf(stderr, "amfi-sync: %s: PRAGMA query_only: %s\n", store, emsg ? emsg : "failed");
        sqlite3_free(emsg);
        return -1;
    }
    return 0;
}

/* Every table shipped (and meta) must be a table of the file, not a view
 * or a virtual table put in its place: refused (exit 3) naming it. */
static int store_tables_real(sqlite3 *db, const char *store)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, "SELECT type, coalesce(sql, '') FROM sqlite_schema WHERE name = ?1",
                           -1, &st, NULL) != SQLITE_OK) {
        fprintf(stderr, "amfi-sync: %s: reading the schema: %s\n", store, sqlite3_errmsg(db));
        return -1;
    }
    int bad = 0;
    for (int i = -1; !bad && i < 2 * fleet_n_tables; i++) {
        const char *name = i < 0 ? "meta" : i % 2 ? fleet_tables[i / 2].child : fleet_tables[i / 2].name;
        if (!name)
            continue;
        sqlite3_reset(st);
        sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
        int src = sqlite3_step(st);
        const char *type = src == SQLITE_ROW ? (const char *)sqlite3_column_text(st, 0) : NULL;
        const char *sql = src == SQLITE_ROW ? (const char *)sqlite3_column_text(st, 1) : "";
        if (src == SQLITE_ROW && type && strcmp(type, "table") == 0
            && strncmp(sql, "CREATE VIRTUAL", 14) != 0)
            continue;
        if (src != SQLITE_ROW && src != SQLITE_DONE)
            fprintf(stderr, "amfi-sync: %s: reading the schema: %s\n", store, sqlite3_errmsg(db));
        else
            fprintf(stderr, "amfi-sync: refused: store %s: '%s' is %s, not a table: not an amfi "
                            "store (nothing shipped)\n", store, name,
                    src == SQLITE_DONE ? "missing" : type && strcmp(type, "table") ? type
                                                                                 : "a virtual table");
        bad = 1;
    }
    sqlite3_finalize(st);
    return bad ? -1 : 0;
}

static int store_site_id(sqlite3 *db, char out[SITE_ID_MAX + 1])
{
    sqlite3_stmt *st = NULL;
    int found = 0;
    if (sqlite3_prepare_v2(db, "SELECT value FROM meta WHERE key = 'site.id'", -1, &st, NULL) == SQLITE_OK
        && sqlite3_step(st) == SQLITE_ROW) {
        const char *v = (const char *)sqlite3_column_text(st, 0);
        if (v && strlen(v) <= SITE_ID_MAX) { strcpy(out, v); found = 1; }
    }
    sqlite3_finalize(st);
    return found;
}

/* The connection as the options say (fleet_pg_connect: TLS for a server
 * not on this machine, the password file checked). */
static const char *opt_passfile;
static int opt_allow_plaintext;
static PGconn *connect_central(const char *conninfo, int *rc)
{
    char err[1024];
    PGconn *pg = fleet_pg_connect(conninfo, opt_passfile, opt_allow_plaintext, NULL, rc, err, sizeof err);
    if (!pg) {
        size_t n = strlen(err);
        fprintf(stderr, "amfi-sync: %s%s", err, n && err[n - 1] == '\n' ? "" : "\n");
        *rc = *rc == 2 ? EX_USAGE : EX_RETRY;
        return NULL;
    }
    pg_exec(pg, "SET client_min_messages = warning", "SET");
    return pg;
}

/* "over TLS (TLSv1.3)" or "without TLS", for the pass's line */
static const char *tls_note(PGconn *pg, char *buf, size_t len)
{
    const char *proto = PQsslAttribute(pg, "protocol");
    if (!PQsslInUse(pg)) snprintf(buf, len, "without TLS");
    else snprintf(buf, len, "over TLS (%s)", proto ? proto : "?");
    return buf;
}

/* A role bound by row-level security (a site's login role, docs/fleet.md,
 * Roles) ships only the site that fleet_site_roles gives it; the owner (not
 * bound) ships any. */
static int check_role(PGconn *pg, const char *site)
{
    PGresult *r = PQexec(pg, "SELECT row_security_active('passages'), current_user, "
                             "(SELECT site_id FROM fleet_site_roles WHERE role_name = current_user)");
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        fprintf(stderr, "amfi-sync: PostgreSQL: the role's site: %s"
                        "amfi-sync: this role is not a site's role: the owner creates one per site "
                        "with 'amfi-sync --init-site-role SITE' (docs/fleet.md, Roles)\n",
                PQresultErrorMessage(r));
        PQclear(r);
        return EX_USAGE;
    }
    int rc = 0;
    if (PQgetvalue(r, 0, 0)[0] == 't') {
        if (PQgetisnull(r, 0, 2)) {
            fprintf(stderr, "amfi-sync: the role '%s' is bound by the row-level security but is no "
                            "site's role (fleet_site_roles): the owner creates one per site with "
                            "'amfi-sync --init-site-role %s' (docs/fleet.md, Roles)\n",
                    PQgetvalue(r, 0, 1), site);
            rc = EX_USAGE;
        } else if (strcmp(PQgetvalue(r, 0, 2), site) != 0) {
            fprintf(stderr, "amfi-sync: the role '%s' is the role of site '%s' (fleet_site_roles), "
                            "not of this store's site '%s': give this site its own role "
                            "(docs/fleet.md, Roles)\n",
                    PQgetvalue(r, 0, 1), PQgetvalue(r, 0, 2), site);
            rc = EX_USAGE;
        }
    }
    PQclear(r);
    return rc;
}

/* The store opened read-only; without its -wal file and unable to create a
 * -shm (amfi-sync's user only reads, amfid stopped), immutable (see
 * store_moved). */
static int open_store(const char *store, sqlite3 **db, int *store_version)
{
    store_immutable = 0;
    snprintf(store_wal, sizeof store_wal, "%s-wal", store);
    for (int pass = 0; pass < 2; pass++) {
        char uri[3 * 4096 + 32];
        const char *name = store;
        if (pass == 1) {
            /* a file: URI with the path percent-encoded */
            size_t k = (size_t)snprintf(uri, sizeof uri, "file:");
            for (const unsigned char *p = (const unsigned char *)store; *p && k + 4 < sizeof uri; p++) {
                if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9')
                    || strchr("/._-~", *p))
                    uri[k++] = (char)*p;
                else
                    k += (size_t)snprintf(uri + k, sizeof uri - k, "%%%02X", *p);
            }
            snprintf(uri + k, sizeof uri - k, "?immutable=1");
            name = uri;
            if (stat(store, &store_st) != 0) break;
            store_immutable = 1;
        }
        if (sqlite3_open_v2(name, db, SQLITE_OPEN_READONLY | (pass ? SQLITE_OPEN_URI : 0), NULL) != SQLITE_OK) {
            fprintf(stderr, "amfi-sync: %s: cannot open the store read-only: %s\n", store, sqlite3_errmsg(*db));
            sqlite3_close(*db);
            *db = NULL;
            return EX_RETRY;
        }
        sqlite3_busy_timeout(*db, 5000);
        if (store_harden(*db, store) != 0) {
            sqlite3_close(*db);
            *db = NULL;
            return EX_REFUSED;
        }
        sqlite3_stmt *uv = NULL;
        int ok = sqlite3_prepare_v2(*db, "PRAGMA user_version", -1, &uv, NULL) == SQLITE_OK
                 && sqlite3_step(uv) == SQLITE_ROW;
        if (ok) *store_version = sqlite3_column_int(uv, 0);
        sqlite3_finalize(uv);
        if (ok) return 0;
        int code = sqlite3_errcode(*db) & 0xff;
        if (pass == 0 && (code == SQLITE_READONLY || code == SQLITE_CANTOPEN)
            && access(store_wal, F_OK) != 0 && errno == ENOENT) {
            sqlite3_close(*db);
            *db = NULL;
            continue;
        }
        fprintf(stderr, "amfi-sync: %s: cannot read the store: %s\n", store, sqlite3_errmsg(*db));
        sqlite3_close(*db);
        *db = NULL;
        return EX_RETRY;
    }
    fprintf(stderr, "amfi-sync: %s: cannot read the store: %s\n", store, strerror(errno));
    return EX_RETRY;
}

/* One pass: connect, create or migrate the central schema, open the store,
 * check the role against its site, check and ship every table. site_opt:
 * the site id the caller expects (site_src names where it came from, for
 * the messages); *shipped (if not NULL) gets the rows shipped. Returns 0 or
 * an EX_ code. */
static int sync_once(const char *conninfo, const char *store, const char *site_opt,
                     const char *site_src, int init_only, int quiet, long *shipped)
{
    int rc;
    PGconn *pg = connect_central(conninfo, &rc);
    if (!pg) return rc;
    rc = apply_schema(pg);
    if (rc || init_only) {
        char tls[64];
        if (!rc && !quiet)
            fprintf(stderr, "amfi-sync: central schema at version %d on %s/%s %s\n", fleet_n_migrations,
                    PQhost(pg), PQdb(pg), tls_note(pg, tls, sizeof tls));
        PQfinish(pg);
        return rc;
    }
    sqlite3 *db = NULL;
    /* The columns shipped are those of the current store schema; amfid
     * migrates an older store when it starts (read-only here, amfi-sync
     * cannot). Retried: follow mode goes on once amfid has run. */
    int store_version = -1;
    rc = open_store(store, &db, &store_version);
    if (rc) {
        PQfinish(pg);
        return rc;
    }
    if (store_version < FLEET_MIN_STORE_VERSION) {
        fprintf(stderr, "amfi-sync: %s: store schema version %d, this amfi-sync needs %d or newer: "
                        "start the new amfid once (it migrates the store), then sync\n",
                store, store_version, FLEET_MIN_STORE_VERSION);
        sqlite3_close(db);
        PQfinish(pg);
        return EX_RETRY;
    }
    if (store_tables_real(db, store) != 0) {
        rc = EX_REFUSED;
        goto out;
    }
    char site[SITE_ID_MAX + 1] = "";
    if (!store_site_id(db, site)) {
        if (!site_opt) {
            fprintf(stderr, "amfi-sync: %s: no meta 'site.id' in the store; give --site ID\n", store);
            rc = EX_USAGE;
            goto out;
        }
        snprintf(site, sizeof site, "%s", site_opt);
    } else if (site_opt && strcmp(site, site_opt) != 0) {
        fprintf(stderr, "amfi-sync: %s: the store belongs to site '%s' (meta 'site.id') but %s gives '%s'\n",
                store, site, site_src, site_opt);
        rc = EX_USAGE;
        goto out;
    }
    if (!amfi_config_site_id_valid(site)) {
        fprintf(stderr, "amfi-sync: site id '%s' is not 1..63 bytes of [A-Za-z0-9_.-]\n", site);
        rc = EX_USAGE;
        goto out;
    }
    rc = check_role(pg, site);
    if (rc) goto out;
    /* One read transaction for the whole pass: a consistent snapshot while
     * amfid keeps writing (WAL). */
    sqlite3_exec(db, "BEGIN", NULL, NULL, NULL);
    rc = check_backwards(pg, db, site);
    long total = 0;
    /* every table checked (its mark, then its new rows' values) before any
     * is shipped */
    for (int i = 0; !rc && i < fleet_n_tables; i++)
        rc = sync_table(pg, db, site, store, &fleet_tables[i], 1, &total);
    for (int i = 0; !rc && i < fleet_n_tables && !stop_requested; i++)
        rc = sync_table(pg, db, site, store, &fleet_tables[i], 0, &total);
    sqlite3_exec(db, "COMMIT", NULL, NULL, NULL);
    if (shipped) *shipped = total;
    char tls[64];
    if (!rc && !quiet && total > 0)
        fprintf(stderr, "amfi-sync: site '%s': %ld rows shipped to %s/%s %s\n", site, total, PQhost(pg),
                PQdb(pg), tls_note(pg, tls, sizeof tls));
out:
    sqlite3_close(db);
    PQfinish(pg);
    return rc;
}

/* --init-site-role SITE [--role NAME], as the owner: the central schema
 * brought to this version, then a login role for the site (created if it
 * does not exist), a member of amfi_site, mapped to the site in
 * fleet_site_roles. Run again, it changes nothing. A role that would not be
 * bound by the row-level security (superuser, BYPASSRLS) or that reads every
 * site (amfi_reader) is refused, as is a role or a site already mapped to
 * another. No password is set: the owner sets one (or a certificate). */
static int init_site_role(const char *conninfo, const char *site, const char *role_opt, int quiet)
{
    char role[80];
    if (role_opt) {
        snprintf(role, sizeof role, "%s", role_opt);
    } else if (strlen(site) > 63 - strlen("amfi_sync_")) {
        fprintf(stderr, "amfi-sync: --init-site-role: the role name 'amfi_sync_%s' would be longer than "
                        "PostgreSQL's 63 bytes: give --role NAME\n", site);
        return EX_USAGE;
    } else {
        snprintf(role, sizeof role, "amfi_sync_%s", site);
    }
    int rc;
    PGconn *pg = connect_central(conninfo, &rc);
    if (!pg) return rc;
    rc = apply_schema(pg);
    if (rc) { PQfinish(pg); return rc; }
    char *ident = PQescapeIdentifier(pg, role, strlen(role));
    const char *pv[2] = {role, site};
    PGresult *r = NULL;
    char sql[256];
    rc = EX_RETRY;
    if (!ident || pg_exec(pg, "BEGIN", "BEGIN")) goto out;
    r = PQexecParams(pg, "SELECT rolsuper OR rolbypassrls, pg_has_role(oid, 'amfi_reader', 'MEMBER') "
                         "FROM pg_roles WHERE rolname = $1", 1, NULL, pv, NULL, NULL, 0);
    if (pg_ok(r, "the role")) goto out;
    if (PQntuples(r) == 1 && (PQgetvalue(r, 0, 0)[0] == 't' || PQgetvalue(r, 0, 1)[0] == 't')) {
        fprintf(stderr, "amfi-sync: --init-site-role: the role '%s' %s: it cannot be a site's role\n", role,
                PQgetvalue(r, 0, 0)[0] == 't' ? "is a superuser or bypasses row-level security"
                                              : "is a member of amfi_reader (reads every site)");
        rc = EX_USAGE;
        goto out;
    }
    if (PQntuples(r) == 0) {
        snprintf(sql, sizeof sql, "CREATE ROLE %s LOGIN", ident);
        if (pg_exec(pg, sql, "CREATE ROLE")) goto out;
    }
    PQclear(r);
    snprintf(sql, sizeof sql, "GRANT amfi_site TO %s", ident);
    r = PQexecParams(pg, "SELECT role_name, site_id FROM fleet_site_roles WHERE role_name = $1 OR site_id = $2",
                     2, NULL, pv, NULL, NULL, 0);
    if (pg_exec(pg, sql, "GRANT") || pg_ok(r, "fleet_site_roles")) goto out;
    int have = 0;
    for (int i = 0; i < PQntuples(r); i++) {
        if (strcmp(PQgetvalue(r, i, 0), role) == 0 && strcmp(PQgetvalue(r, i, 1), site) == 0) {
            have = 1;
            continue;
        }
        fprintf(stderr, "amfi-sync: --init-site-role: fleet_site_roles already gives the role '%s' the site "
                        "'%s': one role per site, one site per role\n",
                PQgetvalue(r, i, 0), PQgetvalue(r, i, 1));
        rc = EX_USAGE;
        goto out;
    }
    PQclear(r);
    r = have ? NULL
             : PQexecParams(pg, "INSERT INTO fleet_site_roles (role_name, site_id) VALUES ($1, $2)", 2, NULL,
                            pv, NULL, NULL, 0);
    if ((r && pg_ok(r, "fleet_site_roles")) || pg_exec(pg, "COMMIT", "COMMIT")) goto out;
    if (!quiet)
        fprintf(stderr, "amfi-sync: site '%s' ships as the role '%s' on %s/%s%s; set its password "
                        "(psql: \\password %s) or a certificate, and give the site user=%s "
                        "(docs/fleet.md, Roles)\n",
                site, role, PQhost(pg), PQdb(pg), have ? " (already so)" : "", ident, role);
    rc = 0;
out:
    PQclear(r);
    if (rc) pg_exec(pg, "ROLLBACK", "ROLLBACK");
    PQfreemem(ident);
    PQfinish(pg);
    return rc;
}

static void usage(FILE *f)
{
    fputs("usage: amfi-sync --pg CONNINFO --init-schema\n"
          "       amfi-sync --pg CONNINFO --init-site-role SITE [--role NAME]\n"
          "       amfi-sync [--config FILE] [--db STORE] --pg CONNINFO [--site ID] [--once]\n"
          "                 [--interval S] [--quiet]\n"
          "  every form also takes --passfile FILE and --allow-plaintext\n"
          "Ships the site store's new rows to the central PostgreSQL (amfi-sync(1),\n"
          "docs/fleet.md). --config: amfid's YAML (store path and site.id from it;\n"
          "--db and --site win). CONNINFO is a libpq connection string ('service=amfi',\n"
          "'host=... dbname=...'); PG* environment variables, ~/.pg_service.conf and\n"
          "~/.pgpass apply. A server not on this machine is reached over TLS only\n"
          "(--allow-plaintext: on a network you trust). Exit: 0 done, 1 server or store\n"
          "unavailable, 2 usage or configuration, 3 store refused (restored backup, other site).\n",
          f);
}

/* Sleeps s seconds or until a stop is asked, pinging the watchdog. */
static void pause_s(double s)
{
    double end = amfi_mono_s() + s;
    while (!stop_requested) {
        double left = end - amfi_mono_s();
        if (left <= 0) break;
        if (wd_usec && left > 0.25e-6 * (double)wd_usec) left = 0.25e-6 * (double)wd_usec;
        struct timespec ts = {(time_t)left, (long)((left - (double)(time_t)left) * 1e9)};
        nanosleep(&ts, NULL); /* EINTR: the loop looks at stop_requested */
        keepalive();
    }
}

int main(int argc, char **argv)
{
    const char *store = NULL, *conninfo = NULL, *site = NULL, *config = NULL;
    const char *init_role_site = NULL, *role = NULL;
    int once = 0, init = 0, quiet = 0;
    double interval = 10;
    enum { O_INIT = 256, O_ONCE, O_INTERVAL, O_INIT_ROLE, O_ROLE, O_PASSFILE, O_PLAIN };
    static const struct option opts[] = {
        {"db", required_argument, NULL, 'd'},   {"pg", required_argument, NULL, 'p'},
        {"site", required_argument, NULL, 's'}, {"config", required_argument, NULL, 'c'},
        {"once", no_argument, NULL, O_ONCE},    {"init-schema", no_argument, NULL, O_INIT},
        {"interval", required_argument, NULL, O_INTERVAL},
        {"init-site-role", required_argument, NULL, O_INIT_ROLE},
        {"role", required_argument, NULL, O_ROLE},
        {"passfile", required_argument, NULL, O_PASSFILE},
        {"allow-plaintext", no_argument, NULL, O_PLAIN},
        {"quiet", no_argument, NULL, 'q'},      AMFI_CLI_END};
    amfi_cli c;
    amfi_cli_init(&c, "amfi-sync", argc, argv, opts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'd': store = optarg; break;
        case 'p': conninfo = optarg; break;
        case 's': site = optarg; break;
        case 'c': config = optarg; break;
        case O_ONCE: once = 1; break;
        case O_INIT: init = 1; break;
        case 'q': quiet = 1; break;
        case O_INTERVAL: interval = amfi_cli_num(&c, optarg, 0.1, 86400); break;
        case O_INIT_ROLE: init_role_site = optarg; break;
        case O_ROLE: role = optarg; break;
        case O_PASSFILE: opt_passfile = optarg; break;
        case O_PLAIN: opt_allow_plaintext = 1; break;
        default: usage(stderr); return EX_USAGE;
        }
    }
    if (role && !init_role_site) {
        amfi_cli_error("amfi-sync", "--role", "only with --init-site-role SITE");
        return EX_USAGE;
    }
    if (init_role_site) {
        if (!conninfo || init || once || store || config || site) {
            amfi_cli_error("amfi-sync", "--init-site-role",
                           !conninfo ? "--pg CONNINFO is required"
                                     : "takes --pg, --role, --passfile, --allow-plaintext and --quiet only");
            return EX_USAGE;
        }
        if (!amfi_config_site_id_valid(init_role_site)) {
            fprintf(stderr, "amfi-sync: --init-site-role: '%s' is not 1..63 bytes of [A-Za-z0-9_.-]\n",
                    init_role_site);
            return EX_USAGE;
        }
        if (role && !amfi_config_site_id_valid(role)) {
            fprintf(stderr, "amfi-sync: --role: '%s' is not 1..63 bytes of [A-Za-z0-9_.-]\n", role);
            return EX_USAGE;
        }
        return init_site_role(conninfo, init_role_site, role, quiet);
    }
    /* amfid's configuration: the store it writes and the site it claims.
     * Explicit options win; the store's own meta is checked against the
     * site id in sync_once (a different one is refused). */
    static amfi_site_config cfg;
    if (config) {
        char err[1024];
        if (amfi_config_load(config, &cfg, err, sizeof err) != 0) {
            fprintf(stderr, "amfi-sync: %s\n", err);
            return EX_USAGE;
        }
        if (!store) store = cfg.daemon.db_path[0] ? cfg.daemon.db_path : NULL;
        if (!site && cfg.site.id[0]) site = cfg.site.id;
    }
    if (!conninfo || (!init && !store)) {
        amfi_cli_error("amfi-sync", NULL, !conninfo ? "--pg CONNINFO is required"
                                                    : "no store: give --db STORE or --config FILE");
        usage(stderr);
        return EX_USAGE;
    }
    if (site && !amfi_config_site_id_valid(site)) {
        fprintf(stderr, "amfi-sync: --site: '%s' is not 1..63 bytes of [A-Za-z0-9_.-]\n", site);
        return EX_USAGE;
    }
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    char site_src[600] = "--site";
    if (site && site == cfg.site.id) snprintf(site_src, sizeof site_src, "%s: site.id", config);
    if (init || once) return sync_once(conninfo, store, site, site_src, init, quiet, NULL);
    /* Follow mode: a pass every interval; capped exponential backoff while
     * the server or the store is away; stops cleanly on SIGTERM after the
     * batch in flight. Under systemd (Type=notify): READY after the first
     * pass, STATUS after each, WATCHDOG pings (keepalive). */
    if (sd_watchdog_enabled(0, &wd_usec) <= 0) wd_usec = 0;
    wd_last = amfi_mono_s();
    double backoff = 1;
    int ready = 0, rc = 0;
    while (!stop_requested) {
        long shipped = 0;
        rc = sync_once(conninfo, store, site, site_src, 0, quiet, &shipped);
        if (rc == EX_REFUSED || rc == EX_USAGE) {
            sd_notifyf(0, "STATUS=refused: see the log (exit %d)", rc);
            return rc;
        }
        double wait = rc ? backoff : interval;
        if (rc)
            sd_notifyf(0, "STATUS=server or store unavailable, retry in %.0f s", wait);
        else
            sd_notifyf(0, "STATUS=%ld rows shipped in the last pass; next in %.0f s", shipped, wait);
        if (!ready) { sd_notify(0, "READY=1"); ready = 1; }
        backoff = rc ? (backoff * 2 > 60 ? 60 : backoff * 2) : 1;
        pause_s(wait);
    }
    sd_notify(0, "STOPPING=1");
    return 0;
}
