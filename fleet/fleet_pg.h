/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fleet_pg.c: the connection to the central PostgreSQL for amfi-sync and
 * amfi-report --pg, TLS required for a server not on this machine
 * (docs/fleet.md, "TLS"). */
#ifndef AMFI_FLEET_PG_H
#define AMFI_FLEET_PG_H

#include <libpq-fe.h>
#include <stddef.h>

/* Connects with conninfo (a libpq connection string; the service file,
 * PG* variables and password file apply as for every libpq program).
 * passfile: NULL or a password file given on the command line (checked: a
 * regular file, no group or world rights), as is PGPASSFILE when set.
 * Unless allow_plaintext, a server not on this machine (any host that is
 * not a Unix socket, localhost, 127.0.0.0/8 or ::1) must be reached over
 * TLS: an sslmode of disable or allow is refused before anything is sent;
 * no sslmode (or libpq's default prefer) becomes require, verify-full when
 * a root certificate is given (sslrootcert); and after connecting,
 * PQsslInUse must say so. Returns the connection, or NULL with err (one
 * line, no password) and *rc: 1 server away (retry), 2 refused by the rules
 * above or a bad password file (not retried). *tls (if not NULL) gets 1
 * when the connection uses TLS. */
PGconn *fleet_pg_connect(const char *conninfo, const char *passfile, int allow_plaintext,
                         int *tls, int *rc, char *err, size_t errlen);

/* Whether host (one element of libpq's host or hostaddr list) is on this
 * machine: empty (the default socket), a Unix socket directory (/...),
 * an abstract socket (@...), localhost, 127.0.0.0/8 or ::1. */
int fleet_pg_host_local(const char *host);

#endif
