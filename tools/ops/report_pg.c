/* SPDX-License-Identifier: GPL-3.0-or-later */
/* report_pg.c: amfi-report --pg, the report from the central PostgreSQL
 * (docs/fleet.md). Without --site: the fleet summary, one line per site.
 * With --site: the site's central rows are fetched (COPY ... TO STDOUT, the
 * columns fleet_columns ships) into a new private SQLite store with the site
 * store's own schema, written through the store's inserts by column value, which amfi-report then reads like any site's store:
 * one report, plot and export code for both sources, and every central row
 * checked by the store's constraints on the way in (a row that breaks one is
 * named by table and id). Single-threaded. */
#include "report_pg.h"

#include <errno.h>
#include <libpq-fe.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_config.h"
#include "amfi_json.h"
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

/* The fleet summary's columns (the view fleet_summary, central version 8):
 * 0-6 as the table prints them, then the site's facts and the full times. */
enum { FS_SITE, FS_PASSAGES, FS_LAST, FS_STATE, FS_RATIO, FS_OPEN, FS_SHIPPED, FS_NAME, FS_LAT,
       FS_LON, FS_TYPE, FS_LAST_FULL, FS_SHIPPED_FULL, FS_N };
static const char fleet_summary_sql[] =
    "SELECT site_id, passages,"
    "  to_char(last_passage AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI\"Z\"'),"
    "  state, coalesce(to_char(std_ratio, 'FM990.000'), '-'), open_alerts,"
    "  to_char(last_shipped AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI\"Z\"'),"
    "  name, latitude, longitude, bridge_type,"
    "  to_char(last_passage AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.US\"Z\"'),"
    "  to_char(last_shipped AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.US\"Z\"')"
    " FROM fleet_summary ORDER BY site_id";

/* What is wrong with row i of the fleet summary query, NULL if nothing:
 * site id as amfid's config allows it, counts, a known state, a ratio, the
 * site's name, position and bridge type as amfid.yaml(5) allows them. */
static const char *fleet_row_problem(PGresult *r, int i)
{
    static const char *const states[] = {"-", "baseline", "normal", "watch", "alert", NULL};
    if (PQgetisnull(r, i, FS_SITE) || !amfi_config_site_id_valid(PQgetvalue(r, i, FS_SITE)))
        return "site_id is not a valid site id";
    if (PQgetisnull(r, i, FS_PASSAGES) || !count_ok(PQgetvalue(r, i, FS_PASSAGES)))
        return "fleet_sync_state.hwm is not a count";
    if (PQgetisnull(r, i, FS_OPEN) || !count_ok(PQgetvalue(r, i, FS_OPEN)))
        return "the open alerts are not a count";
    int k = 0;
    while (states[k] && strcmp(states[k], PQgetvalue(r, i, FS_STATE)) != 0)
        k++;
    if (!states[k])
        return "fleet_latest_state.state is not baseline, normal, watch or alert";
    const char *ratio = PQgetvalue(r, i, FS_RATIO);
    if (strcmp(ratio, "-") != 0) {
        char *end;
        double x = strtod(ratio, &end);
        /* to_char gives '#' for a value beyond its format */
        if (end == ratio || *end || !(x >= 0))
            return "fleet_latest_state.std_ratio is not a ratio in [0, 999.999]";
    }
    if (!PQgetisnull(r, i, FS_NAME)
        && (!fleet_site_text_ok(PQgetvalue(r, i, FS_NAME)) || strlen(PQgetvalue(r, i, FS_NAME)) > 127))
        return "fleet_sites.name is not 1 .. 127 bytes of UTF-8 text without control characters";
    if (!PQgetisnull(r, i, FS_TYPE)
        && (!fleet_site_text_ok(PQgetvalue(r, i, FS_TYPE)) || strlen(PQgetvalue(r, i, FS_TYPE)) > 63))
        return "fleet_sites.bridge_type is not 1 .. 63 bytes of UTF-8 text without control characters";
    if ((!PQgetisnull(r, i, FS_LAT) && !fleet_site_coord_ok(PQgetvalue(r, i, FS_LAT), 90))
        || (!PQgetisnull(r, i, FS_LON) && !fleet_site_coord_ok(PQgetvalue(r, i, FS_LON), 180)))
        return "fleet_sites.latitude or longitude is not a number of degrees in range";
    return NULL;
}

/* A CSV field (RFC 4180): quoted when it holds a comma, a quote or a line
 * break; NULL is empty. */
static void csv_field(FILE *out, const PGresult *r, int i, int col, int last)
{
    if (!PQgetisnull(r, i, col)) {
        const char *v = PQgetvalue(r, i, col);
        if (strpbrk(v, ",\"\r\n")) {
            fputc('"', out);
            for (; *v; v++) {
                if (*v == '"') fputc('"', out);
                fputc(*v, out);
            }
            fputc('"', out);
        } else {
            fputs(v, out);
        }
    }
    fputc(last ? '\n' : ',', out);
}

static json_t *col_text(const PGresult *r, int i, int col)
{
    return PQgetisnull(r, i, col) ? json_null() : json_string(PQgetvalue(r, i, col));
}
static json_t *col_real(const PGresult *r, int i, int col)
{
    return PQgetisnull(r, i, col) ? json_null() : amfi_json_num(strtod(PQgetvalue(r, i, col), NULL));
}
static json_t *col_count(const PGresult *r, int i, int col)
{
    return json_integer(strtoll(PQgetvalue(r, i, col), NULL, 10));
}

/* The summary as CSV (a header, one line per site) or one JSON document
 * ({"fleet": {...}, "sites": [...]}): the site's facts, counts as numbers,
 * times in ISO 8601 UTC to the µs. 0, or 1 out of memory / write error. */
static int fleet_export(PGconn *pg, PGresult *r, const char *format, FILE *out)
{
    static const int cols[] = {FS_SITE, FS_NAME, FS_LAT, FS_LON, FS_TYPE, FS_PASSAGES, FS_LAST_FULL,
                               FS_STATE, FS_RATIO, FS_OPEN, FS_SHIPPED_FULL};
    static const char *const names[] = {"site_id", "name", "latitude", "longitude", "bridge_type",
                                        "passages", "last_passage", "state", "std_ratio",
                                        "open_alerts", "last_shipped"};
    enum { NC = sizeof cols / sizeof cols[0] };
    if (strcmp(format, "csv") == 0) {
        for (int c = 0; c < NC; c++)
            fprintf(out, "%s%c", names[c], c + 1 < NC ? ',' : '\n');
        for (int i = 0; i < PQntuples(r); i++)
            for (int c = 0; c < NC; c++) {
                if (cols[c] == FS_RATIO && strcmp(PQgetvalue(r, i, FS_RATIO), "-") == 0)
                    fputc(c + 1 < NC ? ',' : '\n', out); /* no indicator yet: empty */
                else
                    csv_field(out, r, i, cols[c], c + 1 == NC);
            }
        return ferror(out) ? 1 : 0;
    }
    json_t *sites = json_array(), *root = json_object(), *fleet = json_object();
    for (int i = 0; sites && i < PQntuples(r); i++) {
        json_t *o = json_object();
        const char *ratio = PQgetvalue(r, i, FS_RATIO);
        json_object_set_new(o, "site_id", col_text(r, i, FS_SITE));
        json_object_set_new(o, "name", col_text(r, i, FS_NAME));
        json_object_set_new(o, "latitude", col_real(r, i, FS_LAT));
        json_object_set_new(o, "longitude", col_real(r, i, FS_LON));
        json_object_set_new(o, "bridge_type", col_text(r, i, FS_TYPE));
        json_object_set_new(o, "passages", col_count(r, i, FS_PASSAGES));
        json_object_set_new(o, "last_passage", col_text(r, i, FS_LAST_FULL));
        json_object_set_new(o, "state", col_text(r, i, FS_STATE));
        json_object_set_new(o, "std_ratio", strcmp(ratio, "-") ? amfi_json_num(strtod(ratio, NULL))
                                                               : json_null());
        json_object_set_new(o, "open_alerts", col_count(r, i, FS_OPEN));
        json_object_set_new(o, "last_shipped", col_text(r, i, FS_SHIPPED_FULL));
        if (!o || json_array_append_new(sites, o) != 0) {
            json_decref(sites);
            sites = NULL;
        }
    }
    if (!sites || !root || !fleet) {
        json_decref(sites);
        json_decref(root);
        json_decref(fleet);
        return 1;
    }
    json_object_set_new(fleet, "host", json_string(PQhost(pg)));
    json_object_set_new(fleet, "database", json_string(PQdb(pg)));
    json_object_set_new(fleet, "n_sites", json_integer(PQntuples(r)));
    json_object_set_new(root, "fleet", fleet);
    json_object_set_new(root, "sites", sites);
    return amfi_json_print(out, root) ? 1 : 0;
}

int report_pg_fleet(const char *conninfo, int allow_plaintext, const char *format, FILE *out,
                    char *err, size_t errlen)
{
    int crc;
    PGconn *pg = connect_pg(conninfo, allow_plaintext, &crc, err, errlen);
    if (!pg) return crc;
    /* Per site (the view fleet_summary, one source with psql's): the
     * newest passage id and time shipped (ids are never reused in a store,
     * so the id counts the passages), the latest indicator, the open
     * alerts, when the site last shipped, its name, position and bridge
     * type. Index lookups only: instant on a fleet of 36 M passages. */
    PGresult *r = PQexec(pg, fleet_summary_sql);
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        const char *state = PQresultErrorField(r, PG_DIAG_SQLSTATE);
        if (state && strcmp(state, "42P01") == 0) /* undefined table: an older central schema */
            fail(err, errlen, 1, "fleet summary: the central database has no view fleet_summary "
                 "(central schema before version %d): its owner runs 'amfi-sync --init-schema' "
                 "(docs/fleet.md)", fleet_n_migrations);
        else
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
    int rc = 0;
    if (format && strcmp(format, "table") != 0) {
        if (fleet_export(pg, r, format, out) != 0)
            rc = fail(err, errlen, 1, "fleet summary: --format %s: %s", format,
                      ferror(out) ? strerror(errno) : "out of memory");
        PQclear(r);
        PQfinish(pg);
        return rc;
    }
    fprintf(out, "fleet        %d sites on %s/%s\n", PQntuples(r), PQhost(pg), PQdb(pg));
    fprintf(out, "%-24s %10s  %-17s  %-8s %9s  %5s  %-17s  %s\n", "site", "passages", "last passage",
            "state", "STD ratio", "open", "last shipped", "name");
    for (int i = 0; i < PQntuples(r); i++)
        fprintf(out, "%-24s %10s  %-17s  %-8s %9s  %5s  %-17s  %s\n", PQgetvalue(r, i, 0),
                PQgetvalue(r, i, 1), PQgetisnull(r, i, 2) ? "-" : PQgetvalue(r, i, 2),
                PQgetvalue(r, i, 3), PQgetvalue(r, i, 4), PQgetvalue(r, i, 5), PQgetvalue(r, i, 6),
                PQgetisnull(r, i, FS_NAME) ? "-" : PQgetvalue(r, i, FS_NAME));
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

/* Copies `table` (the columns fleet_columns ships) of one site from the
 * central database into the store s: COPY out, one insert per row (every
 * value as text: the STRICT table converts it as from SQL, its constraints
 * judge it); *n gets the rows. */
static int fetch_table(PGconn *pg, amfi_store *s, const char *site_lit, const char *table,
                       const char *order, long *n, char *err, size_t errlen)
{
    const char *names[64];
    char cols[1024], sql[2048], why[512];
    int ncols = fleet_columns(table, NULL, names, 64);
    fleet_cols_text(table, cols, sizeof cols);
    amfi_store_inserter *ins = NULL;
    if (amfi_store_inserter_open(s, table, names, ncols, &ins, why, sizeof why) != 0)
        return fail(err, errlen, 1, "%s", why);
    snprintf(sql, sizeof sql, "COPY (SELECT %s FROM %s WHERE site_id = %s ORDER BY %s) TO STDOUT",
             cols, table, site_lit, order);
    PGresult *r = PQexec(pg, sql);
    int rc = 0;
    if (PQresultStatus(r) != PGRES_COPY_OUT)
        rc = fail(err, errlen, 1, "central %s: %s", table, PQerrorMessage(pg));
    PQclear(r);
    char *row = NULL;
    int len;
    amfi_store_value v[64];
    while (rc == 0 && (len = PQgetCopyData(pg, &row, 0)) > 0) {
        if (row[len - 1] == '\n') row[len - 1] = 0;
        char *id = NULL;
        int k = 0;
        for (char *f = row; f && k < ncols; k++) {
            char *tab = strchr(f, '\t');
            if (tab) *tab = 0;
            char *val = copy_field(f);
            if (k == 0) id = val;
            v[k] = (amfi_store_value){.type = val ? AMFI_SQL_TEXT : 0, .text = val,
                                      .len = val ? (int)strlen(val) : 0};
            f = tab ? tab + 1 : NULL;
        }
        if (k != ncols)
            rc = fail(err, errlen, 1, "central %s: a row with %d of %d columns", table, k, ncols);
        else if (amfi_store_insert_values(ins, v, why, sizeof why) != 0)
            rc = fail(err, errlen, 1, "central %s row (site %s, %s %s) refused by the store schema: %s",
                      table, site_lit, strcmp(table, "axles") ? "id" : "passage_id",
                      id ? id : "NULL", why);
        else
            (*n)++;
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
    amfi_store_inserter_close(ins);
    return rc;
}

/* The site's name, position and bridge type (fleet_sites, central version
 * 8) into the store's meta, as amfid writes them at a site: the report and
 * its plots are then titled by the site's name, not the temporary file's.
 * A central database before version 8 has none: nothing written. */
static int site_meta(PGconn *pg, amfi_store *s, const char *site, char *err, size_t errlen)
{
    static const char *const keys[] = {"site.name", "site.latitude", "site.longitude",
                                       "site.bridge_type"};
    const char *pv[1] = {site};
    PGresult *r = PQexecParams(pg, "SELECT name, latitude, longitude, bridge_type FROM fleet_sites "
                                   "WHERE site_id = $1 AND to_regclass('fleet_sites') IS NOT NULL",
                               1, NULL, pv, NULL, NULL, 0);
    int rc = 0;
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        const char *state = PQresultErrorField(r, PG_DIAG_SQLSTATE);
        if (!state || strcmp(state, "42P01") != 0)
            rc = fail(err, errlen, 1, "central fleet_sites: %s", PQerrorMessage(pg));
        PQclear(r);
        return rc;
    }
    for (int k = 0; rc == 0 && PQntuples(r) == 1 && k < 4; k++) {
        const char *v = PQgetvalue(r, 0, k);
        if (PQgetisnull(r, 0, k)) continue;
        int ok = k == 1 ? fleet_site_coord_ok(v, 90) : k == 2 ? fleet_site_coord_ok(v, 180)
                        : fleet_site_text_ok(v) && strlen(v) <= (k == 0 ? 127u : 63u);
        if (!ok)
            rc = fail(err, errlen, 1, "central fleet_sites (site %s): %s is not what amfid.yaml(5) "
                      "allows for %s", site, keys[k] + 5, keys[k]);
        else if (amfi_store_meta_set(s, keys[k], v, err, errlen) != 0)
            rc = 1;
    }
    PQclear(r);
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
    char *lit = PQescapeLiteral(pg, site, strlen(site));
    if (!lit) {
        rc = fail(err, errlen, 1, "%s: %s", path, PQerrorMessage(pg));
        goto out;
    }
    if (amfi_store_open(path, 0, &s, err, errlen) != 0
        || amfi_store_meta_set(s, "site.id", site, err, errlen) != 0
        || site_meta(pg, s, site, err, errlen) != 0
        || amfi_store_transaction(s, AMFI_STORE_TX_WRITE, err, errlen) != 0) {
        rc = 1;
        goto out;
    }
    /* one snapshot of the central tables for the whole fetch */
    r = PQexec(pg, "BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY");
    if (PQresultStatus(r) != PGRES_COMMAND_OK)
        rc = fail(err, errlen, 1, "central database: %s", PQerrorMessage(pg));
    PQclear(r);
    *rows = 0;
    for (int i = 0; rc == 0 && i < fleet_n_tables; i++) {
        const struct fleet_table *t = &fleet_tables[i];
        rc = fetch_table(pg, s, lit, t->name, "id", rows, err, errlen);
        if (rc == 0 && t->child) {
            char order[128];
            snprintf(order, sizeof order, "%s, idx", t->child_parent);
            rc = fetch_table(pg, s, lit, t->child, order, rows, err, errlen);
        }
    }
    if (rc == 0 && amfi_store_transaction(s, AMFI_STORE_TX_COMMIT, err, errlen) != 0)
        rc = 1;
    if (rc != 0 && s)
        amfi_store_transaction(s, AMFI_STORE_TX_ROLLBACK, NULL, 0);
out:
    PQfreemem(lit);
    amfi_store_close(s);
    PQfinish(pg);
    return rc;
}
