/* SPDX-License-Identifier: GPL-3.0-or-later */
/* report_pg.c: amfi-report --pg, the report from the central PostgreSQL
 * (docs/fleet.md). Without --site: the fleet summary, one line per site.
 * With --site: the site's central rows are fetched (COPY ... TO STDOUT, the
 * columns of fleet_tables) into a new private SQLite store with the site
 * store's own schema, which amfi-report then reads like any site's store:
 * one report, plot and export code for both sources, and every central row
 * checked by the store's constraints on the way in (a row that breaks one is
 * named by table and id). Single-threaded. */
#include "report_pg.h"

#include <errno.h>
#include <libpq-fe.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_config.h"
#include "fleet_pg.h"
#include "fleet_schema.h"
#include "store.h"

static int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    size_t n = strlen(err);
    while (n > 0 && err[n - 1] == '\n') err[--n] = 0; /* libpq's messages end in \n */
    /* and may go on over more lines ("...failed: No such file or directory\n
     * \tIs the server running locally...?"): one line, as every error of
     * amfi-report is ("...directory; Is the server ...") */
    for (size_t k = 0; k < n; k++)
        if (err[k] == '\n' && err[k + 1] == '\t') {
            err[k] = ';';
            err[k + 1] = ' ';
        } else if (err[k] == '\n' || err[k] == '\r') {
            err[k] = ' ';
        }
    return rc;
}

/* TLS required for a server not on this machine unless allow_plaintext
 * (fleet_pg_connect); *rc: 1 server away, 2 refused (TLS, password file). */
static PGconn *connect_pg(const char *conninfo, int allow_plaintext, int *rc, char *err, size_t errlen)
{
    char why[1024];
    PGconn *pg = fleet_pg_connect(conninfo, NULL, allow_plaintext, NULL, rc, why, sizeof why);
    if (!pg) fail(err, errlen, *rc, "%s", why);
    return pg;
}

/* "site1, site2, ..." of the central database, for an unknown --site. */
static void known_sites(PGconn *pg, char *buf, size_t len)
{
    PGresult *r = PQexec(pg, "SELECT string_agg(DISTINCT site_id, ', ' ORDER BY site_id) "
                             "FROM fleet_sync_state");
    snprintf(buf, len, "%s",
             PQresultStatus(r) == PGRES_TUPLES_OK && !PQgetisnull(r, 0, 0) ? PQgetvalue(r, 0, 0)
                                                                             : "none");
    PQclear(r);
}

/* s with control characters and non-ASCII bytes as '?', cut to len − 1 */
static void shown(const char *s, char *buf, size_t len)
{
    size_t k = 0;
    for (; s[k] && k + 1 < len; k++)
        buf[k] = (s[k] < 0x20 || s[k] > 0x7e) ? '?' : s[k];
    buf[k] = '\0';
}

/* v is an integer in [0, INT64_MAX] (text of a bigint) */
static int count_ok(const char *v)
{
    char *end;
    errno = 0;
    long long x = strtoll(v, &end, 10);
    return errno == 0 && end != v && !*end && x >= 0;
}

/* What is wrong with row i of the fleet summary query, NULL if nothing:
 * site id as amfid's config allows it, counts, a known state, a ratio. */
static const char *fleet_row_problem(PGresult *r, int i)
{
    static const char *const states[] = {"-", "baseline", "normal", "watch", "alert", NULL};
    if (PQgetisnull(r, i, 0) || !amfi_config_site_id_valid(PQgetvalue(r, i, 0)))
        return "site_id is not a valid site id";
    if (PQgetisnull(r, i, 1) || !count_ok(PQgetvalue(r, i, 1)))
        return "fleet_sync_state.hwm is not a count";
    if (PQgetisnull(r, i, 5) || !count_ok(PQgetvalue(r, i, 5)))
        return "the open alerts are not a count";
    int k = 0;
    while (states[k] && strcmp(states[k], PQgetvalue(r, i, 3)) != 0)
        k++;
    if (!states[k])
        return "fleet_latest_state.state is not baseline, normal, watch or alert";
    const char *ratio = PQgetvalue(r, i, 4);
    if (strcmp(ratio, "-") != 0) {
        char *end;
        double x = strtod(ratio, &end);
        /* to_char gives '#' for a value beyond its format */
        if (end == ratio || *end || !(x >= 0))
            return "fleet_latest_state.std_ratio is not a ratio in [0, 999.999]";
    }
    return NULL;
}

int report_pg_fleet(const char *conninfo, int allow_plaintext, FILE *out, char *err, size_t errlen)
{
    int crc;
    PGconn *pg = connect_pg(conninfo, allow_plaintext, &crc, err, errlen);
    if (!pg) return crc;
    /* Per site: the newest passage id and time shipped (ids are never
     * reused in a store, so the id counts the passages), the latest
     * indicator, the open alerts and when the site last shipped. Index
     * lookups only: instant on a fleet of 36 M passages. */
    PGresult *r = PQexec(pg,
        "SELECT s.site_id, s.hwm,"
        "  to_char(to_timestamp((SELECT max(utime) FROM passages p WHERE p.site_id = s.site_id) / 1e6)"
        "          AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI\"Z\"'),"
        "  coalesce(l.state, '-'), coalesce(to_char(l.std_ratio, 'FM990.000'), '-'),"
        "  (SELECT count(*) FROM fleet_open_alerts a WHERE a.site_id = s.site_id),"
        "  to_char(g.synced_at AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI\"Z\"')"
        " FROM fleet_sync_state s"
        " LEFT JOIN fleet_latest_state l ON l.site_id = s.site_id"
        " LEFT JOIN (SELECT site_id, max(synced_at) AS synced_at FROM fleet_sync_state GROUP BY 1) g"
        "   ON g.site_id = s.site_id"
        " WHERE s.tbl = 'passages' ORDER BY s.site_id");
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        fail(err, errlen, 1, "fleet summary: %s", PQerrorMessage(pg));
        PQclear(r);
        PQfinish(pg);
        return 1;
    }
    /* every row checked before anything is printed: a bad one is an error
     * naming the site, not a broken line in the table */
    for (int i = 0; i < PQntuples(r); i++) {
        const char *why = fleet_row_problem(r, i);
        if (why) {
            char site[48];
            shown(PQgetvalue(r, i, 0), site, sizeof site);
            fail(err, errlen, 1, "fleet summary: central row %d (site '%s'): %s", i + 1, site,
                 why);
            PQclear(r);
            PQfinish(pg);
            return 1;
        }
    }
    fprintf(out, "fleet        %d sites on %s/%s\n", PQntuples(r), PQhost(pg), PQdb(pg));
    fprintf(out, "%-24s %10s  %-17s  %-8s %9s  %5s  %-17s\n", "site", "passages", "last passage",
            "state", "STD ratio", "open", "last shipped");
    for (int i = 0; i < PQntuples(r); i++)
        fprintf(out, "%-24s %10s  %-17s  %-8s %9s  %5s  %-17s\n", PQgetvalue(r, i, 0),
                PQgetvalue(r, i, 1), PQgetisnull(r, i, 2) ? "-" : PQgetvalue(r, i, 2),
                PQgetvalue(r, i, 3), PQgetvalue(r, i, 4), PQgetvalue(r, i, 5), PQgetvalue(r, i, 6));
    PQclear(r);
    PQfinish(pg);
    return 0;
}

/* One COPY text-format field in place: "\N" is NULL (returns NULL),
 * backslash escapes decoded (PostgreSQL COPY, text format). */
static char *copy_field(char *f)
{
    if (strcmp(f, "\\N") == 0) return NULL;
    char *w = f;
    for (char *p = f; *p; p++) {
        if (*p != '\\' || !p[1]) { *w++ = *p; continue; }
        p++;
        switch (*p) {
        case 'b': *w++ = '\b'; break;
        case 'f': *w++ = '\f'; break;
        case 'n': *w++ = '\n'; break;
        case 'r': *w++ = '\r'; break;
        case 't': *w++ = '\t'; break;
        case 'v': *w++ = '\v'; break;
        case 'x': {
            int v = 0, k = 0;
            while (k < 2 && ((p[1] >= '0' && p[1] <= '9') || (p[1] >= 'a' && p[1] <= 'f')
                             || (p[1] >= 'A' && p[1] <= 'F'))) {
                char c = *++p;
                v = 16 * v + (c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10);
                k++;
            }
            *w++ = (char)v;
            break;
        }
        default:
            if (*p >= '0' && *p <= '7') {
                int v = *p - '0';
                for (int k = 0; k < 2 && p[1] >= '0' && p[1] <= '7'; k++) v = 8 * v + (*++p - '0');
                *w++ = (char)v;
            } else {
                *w++ = *p;
            }
        }
    }
    *w = 0;
    return f;
}

/* Copies `table` (columns `cols`) of one site from the central database into
 * the store db: COPY out, one INSERT per row; *n gets the rows. */
static int fetch_table(PGconn *pg, sqlite3 *db, const char *site_lit, const char *table,
                       const char *cols, const char *order, long *n, char *err, size_t errlen)
{
    int ncols = 1;
    for (const char *c = cols; *c; c++) ncols += *c == ',';
    char sql[1024], ins[1024], marks[256] = "";
    for (int i = 0; i < ncols; i++) strcat(marks, i ? ", ?" : "?");
    snprintf(ins, sizeof ins, "INSERT INTO %s (%s) VALUES (%s)", table, cols, marks);
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, ins, -1, &st, NULL) != SQLITE_OK)
        return fail(err, errlen, 1, "%s: %s", table, sqlite3_errmsg(db));
    snprintf(sql, sizeof sql, "COPY (SELECT %s FROM %s WHERE site_id = %s ORDER BY %s) TO STDOUT",
             cols, table, site_lit, order);
    PGresult *r = PQexec(pg, sql);
    int rc = 0;
    if (PQresultStatus(r) != PGRES_COPY_OUT)
        rc = fail(err, errlen, 1, "central %s: %s", table, PQerrorMessage(pg));
    PQclear(r);
    char *row = NULL;
    int len;
    while (rc == 0 && (len = PQgetCopyData(pg, &row, 0)) > 0) {
        if (row[len - 1] == '\n') row[len - 1] = 0;
        char *id = NULL;
        int k = 0;
        for (char *f = row; f && k < ncols; k++) {
            char *tab = strchr(f, '\t');
            if (tab) *tab = 0;
            char *v = copy_field(f);
            if (k == 0) id = v;
            if (v) sqlite3_bind_text(st, k + 1, v, -1, SQLITE_STATIC);
            f = tab ? tab + 1 : NULL;
        }
        if (k != ncols)
            rc = fail(err, errlen, 1, "central %s: a row with %d of %d columns", table, k, ncols);
        else if (sqlite3_step(st) != SQLITE_DONE)
            rc = fail(err, errlen, 1, "central %s row (site %s, %s %s) refused by the store schema: %s",
                      table, site_lit, strcmp(table, "axles") ? "id" : "passage_id",
                      id ? id : "NULL", sqlite3_errmsg(db));
        else
            (*n)++;
        /* the fields are bound SQLITE_STATIC: unbind before the row goes */
        sqlite3_reset(st);
        sqlite3_clear_bindings(st);
        PQfreemem(row);
        row = NULL;
    }
    if (rc == 0 && len == -2)
        rc = fail(err, errlen, 1, "central %s: %s", table, PQerrorMessage(pg));
    /* drain the COPY and its result whatever happened above */
    while (rc != 0 && (len = PQgetCopyData(pg, &row, 0)) > 0) PQfreemem(row);
    while ((r = PQgetResult(pg)) != NULL) {
        if (rc == 0 && PQresultStatus(r) != PGRES_COMMAND_OK)
            rc = fail(err, errlen, 1, "central %s: %s", table, PQerrorMessage(pg));
        PQclear(r);
    }
    sqlite3_finalize(st);
    return rc;
}

int report_pg_fetch_site(const char *conninfo, int allow_plaintext, const char *site, const char *path,
                         long *rows, char *err, size_t errlen)
{
    int crc;
    PGconn *pg = connect_pg(conninfo, allow_plaintext, &crc, err, errlen);
    if (!pg) return crc;
    const char *pv[1] = {site};
    PGresult *r = PQexecParams(pg, "SELECT 1 FROM fleet_sync_state WHERE site_id = $1 LIMIT 1", 1,
                               NULL, pv, NULL, NULL, 0);
    int rc = 0;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        rc = fail(err, errlen, 1, "central database: %s", PQerrorMessage(pg));
    } else if (PQntuples(r) == 0) {
        char known[2048];
        known_sites(pg, known, sizeof known);
        rc = fail(err, errlen, 2, "--site: no site '%s' in the central database (sites: %s)", site,
                  known);
    }
    PQclear(r);
    if (rc) { PQfinish(pg); return rc; }

    amfi_store *s = NULL;
    if (amfi_store_open(path, 0, &s, err, errlen) != 0
        || amfi_store_meta_set(s, "site.id", site, err, errlen) != 0) {
        amfi_store_close(s);
        PQfinish(pg);
        return 1;
    }
    amfi_store_close(s);
    sqlite3 *db = NULL;
    char *lit = PQescapeLiteral(pg, site, strlen(site));
    if (!lit || sqlite3_open_v2(path, &db, SQLITE_OPEN_READWRITE, NULL) != SQLITE_OK) {
        rc = fail(err, errlen, 1, "%s: %s", path, lit ? sqlite3_errmsg(db) : PQerrorMessage(pg));
        goto out;
    }
    sqlite3_exec(db, "PRAGMA synchronous = OFF; BEGIN", NULL, NULL, NULL);
    /* one snapshot of the central tables for the whole fetch */
    r = PQexec(pg, "BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY");
    if (PQresultStatus(r) != PGRES_COMMAND_OK)
        rc = fail(err, errlen, 1, "central database: %s", PQerrorMessage(pg));
    PQclear(r);
    *rows = 0;
    for (int i = 0; rc == 0 && i < fleet_n_tables; i++) {
        const struct fleet_table *t = &fleet_tables[i];
        rc = fetch_table(pg, db, lit, t->name, t->cols, "id", rows, err, errlen);
        if (rc == 0 && t->child) {
            char order[128];
            snprintf(order, sizeof order, "%s, idx", t->child_parent);
            rc = fetch_table(pg, db, lit, t->child, t->child_cols, order, rows, err, errlen);
        }
    }
    if (rc == 0 && sqlite3_exec(db, "COMMIT", NULL, NULL, NULL) != SQLITE_OK)
        rc = fail(err, errlen, 1, "%s: %s", path, sqlite3_errmsg(db));
out:
    PQfreemem(lit);
    sqlite3_close(db);
    PQfinish(pg);
    return rc;
}
