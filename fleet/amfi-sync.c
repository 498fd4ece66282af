/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi-sync: ships a site store's new rows (passages with axles, indicators,
 * alerts, baseline, runs, environment, scale_evals) into the central
 * PostgreSQL (issues 15 and 14). Every value is checked against the site
 * store's rules (fleet_col) before anything of a pass is shipped.
 *
 * Single-threaded. Reads the SQLite store read-only through the store's API
 * (amfi_store_open_reader, rows as column values; in WAL mode a reader
 * never blocks amfid's writer) and writes the central
 * database with libpq, as the site's own role, which row-level security
 * binds to the site's rows (central version 6), over TLS to a server not on
 * this machine (fleet_pg.c). Each batch is one PostgreSQL transaction holding
 * the rows (COPY into a temporary table, then INSERT ... SELECT) and the
 * table's high-water mark in fleet_sync_state, so a crash
 * at any moment leaves either the whole batch or none of it. The mark also
 * keeps a hash of the last shipped row: a store restored from an older backup
 * (ids going backwards, or a different row at a shipped id) is refused. */
#define _POSIX_C_SOURCE 200809L
#include <inttypes.h>
#include <libpq-fe.h>
#include <signal.h>
#include <stddef.h>
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
#include "store.h"
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

static uint64_t row_hash(const amfi_store_value *v, int ncols)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    char tmp[40];
    for (int i = 0; i < ncols; i++) {
        const char *s = amfi_store_value_text(&v[i], tmp, sizeof tmp);
        h = fnv1a(h, s ? s : "\x01N", s ? strlen(s) : 2);
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
    /* roles.sql describes the current schema: once, after the last
     * migration, when one from FLEET_ROLES_SQL_FROM on was applied */
    int roles = 0, failed = 0;
    for (int i = have; i < fleet_n_migrations && !failed; i++) {
        char ins[256];
        snprintf(ins, sizeof ins, "INSERT INTO fleet_migrations (version, description) VALUES (%d, '%s')",
                 fleet_migrations[i].version, fleet_migrations[i].description);
        roles |= fleet_migrations[i].version >= FLEET_ROLES_SQL_FROM;
        failed = pg_exec(pg, fleet_migrations[i].sql, "migration") || pg_exec(pg, ins, "migration record");
    }
    if (!failed && roles)
        failed = pg_exec(pg, fleet_roles_sql, "roles.sql");
    if (failed) {
        fprintf(stderr, "amfi-sync: the central schema is at version %d, this program needs %d: "
                        "run 'amfi-sync --init-schema' as the database owner (docs/fleet.md)\n",
                have, fleet_n_migrations);
        pg_exec(pg, "ROLLBACK", "ROLLBACK");
        return EX_RETRY;
    }
    return pg_exec(pg, "COMMIT", "COMMIT") ? EX_RETRY : 0;
}


/* The rows of one scan as COPY text, the site id in front. */
struct copy_ctx {
    struct buf b;
    const char *site;
    int hash_cols;
    int64_t last_id;
    uint64_t last_hash;
    long n;
};
static int copy_row(void *ctx, const amfi_store_value *v, int n)
{
    struct copy_ctx *c = ctx;
    char tmp[40];
    if (buf_field(&c->b, (const unsigned char *)c->site, 0)) return -1;
    for (int i = 0; i < n; i++) {
        const char *s = amfi_store_value_text(&v[i], tmp, sizeof tmp);
        if (buf_put(&c->b, "\t", 1) || buf_field(&c->b, (const unsigned char *)(s ? s : ""), !s))
            return -1;
    }
    if (buf_put(&c->b, "\n", 1)) return -1;
    c->last_id = v[0].i;
    if (c->hash_cols) c->last_hash = row_hash(v, c->hash_cols < n ? c->hash_cols : n);
    c->n++;
    return 0;
}

/* COPY the rows of table src whose key is in (lo, hi], at most limit (0:
 * all), into the central table of the same name with the site id in front;
 * the last row's key and the hash of its first hash_cols columns go to
 * *last_id and *last_hash when last_id is not NULL. */
static int copy_rows(PGconn *pg, amfi_store *s, const char *site, const char *dst, int hash_cols,
                     int64_t lo, int64_t hi, int limit, int64_t *last_id, uint64_t *last_hash,
                     long *nrows)
{
    const char *names[64];
    char cols[1024], err[512];
    int ncols = fleet_columns(dst, NULL, names, 64);
    fleet_cols_text(dst, cols, sizeof cols);
    struct copy_ctx c = {{0}, site, last_id ? hash_cols : 0, 0, 0, 0};
    int rc = amfi_store_scan(s, dst, names, ncols, lo, hi, limit, copy_row, &c, err, sizeof err);
    if (rc != 0) {
        if (rc == -1) fprintf(stderr, "amfi-sync: store: %s: out of memory\n", dst);
        else fprintf(stderr, "amfi-sync: store: %s\n", err);
        free(c.b.p);
        return EX_RETRY;
    }
    if (last_id && c.n > 0) { *last_id = c.last_id; *last_hash = c.last_hash; }
    struct buf b = c.b;
    long n = c.n;
    *nrows = n;
    if (n == 0) { free(b.p); return 0; }
    /* PostgreSQL refuses COPY FROM into a table whose row-level security
     * binds the role (every site role, docs/fleet.md, Roles): the rows go
     * by COPY into a temporary table of the same columns (this session's
     * own, emptied at every commit), then by one INSERT ... SELECT into the
     * site table, where the policies check every row. */
    char copy[5120];
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

/* Every value of the rows of a table with keys above hwm against the site
 * store's rules (the store's column table): a store that breaks its own
 * schema (a damaged file, a row written around amfid) is refused before
 * anything of the pass is shipped, naming the table, the row and the
 * column. */
struct check_ctx {
    const amfi_store_coldef *defs[64];
    const char *site, *store, *table;
    int key_cols;
    long n;
};
static int check_row(void *ctx, const amfi_store_value *v, int n)
{
    struct check_ctx *c = ctx;
    char msg[200];
    for (int i = 0; i < n; i++) {
        const char *why = amfi_store_value_problem(c->defs[i], &v[i], msg, sizeof msg);
        if (!why) continue;
        char key[96] = "";
        for (int k = 0; k < c->key_cols; k++)
            snprintf(key + strlen(key), sizeof key - strlen(key), "%s%s %lld", k ? ", " : "",
                     c->defs[k]->name, (long long)(v[k].type == AMFI_SQL_INTEGER ? v[k].i : 0));
        fprintf(stderr,
                "amfi-sync: refused: site '%s' store %s: table %s, %s, column %s: %s "
                "(the site store's rules, docs/schema.md). Nothing shipped "
                "(see docs/fleet.md, 'Bad values')\n",
                c->site, c->store, c->table, key, c->defs[i]->name, why);
        return EX_REFUSED;
    }
    if (++c->n % 4096 == 0) keepalive();
    return 0;
}

static int check_rows(amfi_store *s, const char *site, const char *store, const char *table,
                      int key_cols, int64_t hwm)
{
    const char *names[64];
    char err[512];
    struct check_ctx c = {.site = site, .store = store, .table = table, .key_cols = key_cols};
    int ncols = fleet_columns(table, c.defs, names, 64);
    int rc = amfi_store_scan(s, table, names, ncols, hwm, INT64_MAX, 0, check_row, &c, err,
                             sizeof err);
    if (rc == EX_REFUSED) return rc;
    if (rc != 0) {
        fprintf(stderr, "amfi-sync: store: %s\n", err);
        return EX_RETRY;
    }
    return 0;
}

/* The hash of the row at key id (*found 0: none). */
struct mark_ctx { int hash_cols, found; uint64_t hash; };
static int mark_row(void *ctx, const amfi_store_value *v, int n)
{
    struct mark_ctx *m = ctx;
    m->found = 1;
    m->hash = row_hash(v, m->hash_cols < n ? m->hash_cols : n);
    return 0;
}

/* Ship one table until it has no more new rows. */
static int sync_table(PGconn *pg, amfi_store *db, const char *site, const char *store,
                      const struct fleet_table *t, int check_only, long *total)
{
    const char *names[64];
    char err[512];
    int ncols = fleet_columns(t->name, NULL, names, 64), hash_cols = fleet_hash_cols(t->name);
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
        struct mark_ctx m = {hash_cols, 0, 0};
        if (amfi_store_scan(db, t->name, names, ncols, hwm - 1, hwm, 1, mark_row, &m, err,
                            sizeof err) != 0) {
            fprintf(stderr, "amfi-sync: store: %s\n", err);
            return EX_RETRY;
        }
        uint64_t h = m.found ? m.hash : 0;
        if (!m.found || h != hash) {
            fprintf(stderr,
                    "amfi-sync: refused: site '%s' table %s: the central database holds rows up to id %" PRId64
                    " but the store %s; was the store restored from an older backup? Nothing merged "
                    "(see docs/fleet.md, 'Restored stores')\n",
                    site, t->name, hwm, m.found ? "has a different row at that id" : "has no row at that id");
            return EX_REFUSED;
        }
    }
    if (check_only) {
        /* the rows to ship: every value as the site store's rules say */
        int rc = check_rows(db, site, store, t->name, 1, hwm);
        if (!rc && t->child)
            rc = check_rows(db, site, store, t->child, 2, hwm);
        return rc;
    }
    for (;;) {
        if (stop_requested) return 0;
        if (pg_exec(pg, "BEGIN", "BEGIN")) return EX_RETRY;
        int64_t last = hwm;
        uint64_t lh = hash;
        long n = 0, nc = 0;
        int rc = copy_rows(pg, db, site, t->name, hash_cols, hwm, INT64_MAX, BATCH_ROWS, &last, &lh,
                           &n);
        if (!rc && n > 0 && t->child)
            rc = copy_rows(pg, db, site, t->child, 0, hwm, last, 0, NULL, NULL, &nc);
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
static int check_backwards(PGconn *pg, amfi_store *db, const char *site)
{
    for (int i = 0; i < fleet_n_tables; i++) {
        const char *pv[2] = {site, fleet_tables[i].name};
        PGresult *r = PQexecParams(pg, "SELECT hwm FROM fleet_sync_state WHERE site_id = $1 AND tbl = $2",
                                   2, NULL, pv, NULL, NULL, 0);
        if (pg_ok(r, "fleet_sync_state")) { PQclear(r); return EX_RETRY; }
        int64_t hwm = PQntuples(r) ? strtoll(PQgetvalue(r, 0, 0), NULL, 10) : 0;
        PQclear(r);
        int64_t mx = 0;
        char err[512];
        if (amfi_store_max_key(db, fleet_tables[i].name, &mx, err, sizeof err) != 0) {
            fprintf(stderr, "amfi-sync: store: %s\n", err);
            return EX_RETRY;
        }
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

/* Every table shipped (and meta) must be a table of the file, not a view
 * or a virtual table put in its place: refused (exit 3) naming it. */
static int store_tables_real(amfi_store *db, const char *store)
{
    for (int i = -1; i < 2 * fleet_n_tables; i++) {
        const char *name = i < 0 ? "meta" : i % 2 ? fleet_tables[i / 2].child : fleet_tables[i / 2].name;
        if (!name)
            continue;
        char type[32], err[512];
        if (amfi_store_object_type(db, name, type, sizeof type, err, sizeof err) != 0) {
            fprintf(stderr, "amfi-sync: %s: %s\n", store, err);
            return -1;
        }
        if (strcmp(type, "table") == 0)
            continue;
        fprintf(stderr, "amfi-sync: refused: store %s: '%s' is %s, not a table: not an amfi "
                        "store (nothing shipped)\n", store, name,
                !type[0] ? "missing" : strcmp(type, "virtual table") ? type : "a virtual table");
        return -1;
    }
    return 0;
}

static int store_site_id(amfi_store *db, char out[SITE_ID_MAX + 1])
{
    int found = 0;
    char err[256];
    /* a value too long for a site id (an error here) is no site id */
    if (amfi_store_meta_get(db, "site.id", out, SITE_ID_MAX + 1, &found, err, sizeof err) != 0)
        found = 0;
    return found;
}

/* What the store says of its site (the meta amfid writes from site.* of
 * amfid.yaml) and of itself (the started_at of its first run, written once
 * at its first start: the store's identity), each value checked as the
 * configuration loader checks it (fleet_site_text_ok, fleet_site_coord_ok);
 * "" where the store has none. */
struct site_facts {
    char name[128], lat[32], lon[32], bridge_type[64];
    char started[64]; /* runs id 1: started_at */
};
static int first_run(void *ctx, const amfi_store_value *v, int n)
{
    char tmp[40];
    const char *t = n > 1 ? amfi_store_value_text(&v[1], tmp, sizeof tmp) : NULL;
    snprintf(ctx, 64, "%s", t ? t : "");
    return 0;
}
static int site_facts_read(amfi_store *db, const char *site, const char *store, struct site_facts *f)
{
    static const struct { const char *key; size_t off, cap; double lim; } keys[] = {
        {"site.name", offsetof(struct site_facts, name), sizeof ((struct site_facts *)0)->name, 0},
        {"site.latitude", offsetof(struct site_facts, lat), sizeof ((struct site_facts *)0)->lat, 90},
        {"site.longitude", offsetof(struct site_facts, lon), sizeof ((struct site_facts *)0)->lon, 180},
        {"site.bridge_type", offsetof(struct site_facts, bridge_type),
         sizeof ((struct site_facts *)0)->bridge_type, 0},
    };
    char err[512], val[AMFI_STORE_META_VALUE_MAX + 1];
    memset(f, 0, sizeof *f);
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        int found = 0, grc = amfi_store_meta_get(db, keys[i].key, val, sizeof val, &found, err,
                                                  sizeof err);
        if (grc == AMFI_STORE_ECORRUPT) { /* a value the store's rules refuse */
            fprintf(stderr, "amfi-sync: refused: site '%s' store %s: meta '%s': %s. Nothing shipped "
                            "(see docs/fleet.md, 'Bad values')\n", site, store, keys[i].key, err);
            return EX_REFUSED;
        }
        if (grc != 0) {
            fprintf(stderr, "amfi-sync: store: %s\n", err);
            return EX_RETRY;
        }
        if (!found) continue;
        int ok = strlen(val) > 0 && strlen(val) < keys[i].cap
                 && (keys[i].lim > 0 ? fleet_site_coord_ok(val, keys[i].lim) : fleet_site_text_ok(val));
        if (!ok) {
            fprintf(stderr, "amfi-sync: refused: site '%s' store %s: meta '%s': %s (amfid.yaml(5)). "
                            "Nothing shipped (see docs/fleet.md, 'Bad values')\n",
                    site, store, keys[i].key,
                    keys[i].lim > 0 ? "not a number of degrees in range"
                                    : "not 1 .. the key's bytes of UTF-8 text without control characters");
            return EX_REFUSED;
        }
        memcpy((char *)f + keys[i].off, val, strlen(val) + 1);
    }
    if (!f->lat[0] != !f->lon[0]) {
        fprintf(stderr, "amfi-sync: refused: site '%s' store %s: meta '%s' without '%s' "
                        "(amfid.yaml(5): both or neither). Nothing shipped\n",
                site, store, f->lat[0] ? "site.latitude" : "site.longitude",
                f->lat[0] ? "site.longitude" : "site.latitude");
        return EX_REFUSED;
    }
    static const char *const cols[] = {"id", "started_at"};
    if (amfi_store_scan(db, "runs", cols, 2, 0, 1, 1, first_run, f->started, err, sizeof err) != 0) {
        fprintf(stderr, "amfi-sync: store: %s\n", err);
        return EX_RETRY;
    }
    return 0;
}

/* A site is shipped by one store (fleet_sites.store_started_at, else the
 * site's central runs row 1): another store claiming the same site id is
 * refused (exit 3) saying so, since when, and what to do, before the marks
 * would take it for a restored backup. A store without a first run (not
 * written by amfid) is not checked. */
static int check_claim(PGconn *pg, const char *site, const char *store, const struct site_facts *f)
{
    if (!f->started[0]) return 0;
    const char *pv[1] = {site};
    PGresult *r = PQexecParams(pg,
        "SELECT store_started_at, to_char(claimed_at AT TIME ZONE 'UTC', "
        "'YYYY-MM-DD\"T\"HH24:MI:SS\"Z\"'), 'fleet_sites' FROM fleet_sites "
        "WHERE site_id = $1 AND store_started_at IS NOT NULL "
        "UNION ALL SELECT started_at, started_at, 'runs' FROM runs WHERE site_id = $1 AND id = 1 "
        "LIMIT 1", 1, NULL, pv, NULL, NULL, 0);
    if (pg_ok(r, "fleet_sites")) { PQclear(r); return EX_RETRY; }
    int rc = 0;
    if (PQntuples(r) == 1 && strcmp(PQgetvalue(r, 0, 0), f->started) != 0) {
        fprintf(stderr,
                "amfi-sync: refused: another store already claims site id '%s': the central database "
                "has shipped it since %s from a store first started at %s, but this store %s "
                "was first started at %s. Two stores cannot ship one site id. Give this store's "
                "site its own site.id (a new site: before amfid's first start); or, if this store "
                "replaces the other for good, the owner first deletes the site's central rows "
                "(docs/fleet.md, 'Two stores, one site id'). Nothing shipped\n",
                site, PQgetvalue(r, 0, 1), PQgetvalue(r, 0, 0), store, f->started);
        rc = EX_REFUSED;
    }
    PQclear(r);
    return rc;
}

/* The site's row of fleet_sites: its name, position and bridge type as the
 * store says now, and the store that ships it (kept from the first pass:
 * a different one is refused by check_claim). One statement. */
static int ship_site(PGconn *pg, const char *site, const struct site_facts *f)
{
    const char *pv[7] = {site, f->started[0] ? f->started : NULL, f->name[0] ? f->name : NULL,
                         f->lat[0] ? f->lat : NULL, f->lon[0] ? f->lon : NULL,
                         f->bridge_type[0] ? f->bridge_type : NULL};
    PGresult *r = PQexecParams(pg,
        "INSERT INTO fleet_sites AS s (site_id, store_started_at, name, latitude, longitude, bridge_type) "
        "VALUES ($1, $2, $3, $4, $5, $6) ON CONFLICT (site_id) DO UPDATE SET "
        "store_started_at = coalesce(s.store_started_at, EXCLUDED.store_started_at), "
        "name = EXCLUDED.name, latitude = EXCLUDED.latitude, longitude = EXCLUDED.longitude, "
        "bridge_type = EXCLUDED.bridge_type, updated_at = now() "
        "WHERE (s.name, s.latitude, s.longitude, s.bridge_type, s.store_started_at) IS DISTINCT FROM "
        "(EXCLUDED.name, EXCLUDED.latitude, EXCLUDED.longitude, EXCLUDED.bridge_type, "
        "coalesce(s.store_started_at, EXCLUDED.store_started_at))",
        6, NULL, pv, NULL, NULL, 0);
    int rc = pg_ok(r, "fleet_sites") ? EX_RETRY : 0;
    PQclear(r);
    return rc;
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
        /* Only a refusal of this role is a usage error; a server that went
         * away (shut down between the connection and this query) or another
         * failure is retried: follow mode must outlive a restart of the
         * server at any point of a pass. */
        const char *state = PQresultErrorField(r, PG_DIAG_SQLSTATE);
        const int refused = PQstatus(pg) == CONNECTION_OK && state &&
                            (strcmp(state, "42501") == 0 || strcmp(state, "42P01") == 0);
        fprintf(stderr, "amfi-sync: PostgreSQL: the role's site: %s", PQresultErrorMessage(r));
        if (refused)
            fprintf(stderr, "amfi-sync: this role is not a site's role: the owner creates one per "
                            "site with 'amfi-sync --init-site-role SITE' (docs/fleet.md, Roles)\n");
        PQclear(r);
        return refused ? EX_USAGE : EX_RETRY;
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
static int open_store(const char *store, amfi_store **db, int *store_version)
{
    char err[4400];
    int immutable = 0;
    snprintf(store_wal, sizeof store_wal, "%s-wal", store);
    /* noted before it is opened: a change after is seen by store_moved */
    int have_st = stat(store, &store_st) == 0;
    int rc = amfi_store_open_reader(store, have_st, db, store_version, &immutable, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "amfi-sync: %s\n", err);
        return rc == AMFI_STORE_ESCHEMA ? EX_REFUSED : EX_RETRY;
    }
    store_immutable = immutable;
    return 0;
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
    amfi_store *db = NULL;
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
        amfi_store_close(db);
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
    char txerr[512];
    if (amfi_store_transaction(db, AMFI_STORE_TX_READ, txerr, sizeof txerr) != 0) {
        fprintf(stderr, "amfi-sync: %s\n", txerr);
        rc = EX_RETRY;
        goto out;
    }
    struct site_facts facts;
    rc = site_facts_read(db, site, store, &facts);
    if (!rc) rc = check_claim(pg, site, store, &facts);
    if (!rc) rc = check_backwards(pg, db, site);
    long total = 0;
    /* every table checked (its mark, then its new rows' values) before any
     * is shipped */
    for (int i = 0; !rc && i < fleet_n_tables; i++)
        rc = sync_table(pg, db, site, store, &fleet_tables[i], 1, &total);
    if (!rc && !stop_requested) rc = ship_site(pg, site, &facts);
    for (int i = 0; !rc && i < fleet_n_tables && !stop_requested; i++)
        rc = sync_table(pg, db, site, store, &fleet_tables[i], 0, &total);
    amfi_store_transaction(db, AMFI_STORE_TX_COMMIT, NULL, 0);
    if (shipped) *shipped = total;
    char tls[64];
    if (!rc && !quiet && total > 0)
        fprintf(stderr, "amfi-sync: site '%s': %ld rows shipped to %s/%s %s\n", site, total, PQhost(pg),
                PQdb(pg), tls_note(pg, tls, sizeof tls));
out:
    amfi_store_close(db);
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
