/* SPDX-License-Identifier: GPL-3.0-or-later */
/* report_pg.h: amfi-report --pg, the report from the central PostgreSQL
 * (report_pg.c). CONNINFO goes to libpq (PG* variables, service file,
 * password file); the password is never printed. A server not on this
 * machine is reached over TLS only, unless allow_plaintext (fleet_pg.h); a
 * connection so refused returns 2. Errors: one line in err, without the
 * program name. */
#ifndef AMFI_REPORT_PG_H
#define AMFI_REPORT_PG_H

#include <stdio.h>

/* The fleet summary on out (the central view fleet_summary): format NULL or
 * "table" one line per site, "csv" a header and one line per site, "json"
 * one document. 0, 1 (server away, query failed, a central row that is not
 * what the sites ship) or 2 (connection refused: TLS, password file). */
int report_pg_fleet(const char *conninfo, int allow_plaintext, const char *format, FILE *out,
                    char *err, size_t errlen);

/* A new store at path (which must not exist) holding every central row of
 * site; *rows gets their number. 0; 1 server away or a row the store's
 * schema refuses (named by table and id); 2 no such site (err lists the
 * sites there are) or the connection refused (TLS, password file). */
int report_pg_fetch_site(const char *conninfo, int allow_plaintext, const char *site, const char *path,
                         long *rows, char *err, size_t errlen);

#endif
