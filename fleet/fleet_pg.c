/* SPDX-License-Identifier: GPL-3.0-or-later */
/* fleet_pg.c: the connection to the central PostgreSQL (fleet_pg.h). libpq's
 * default sslmode (prefer) falls back to plain text without a word; here a
 * server that is not on this machine gets TLS or nothing. The decision is
 * taken on the options libpq will use (the connection string, then the
 * service file, then the PG* variables), before anything is resolved or
 * sent, and checked on the connection made (PQsslInUse). */
#define _POSIX_C_SOURCE 200809L
#include "fleet_pg.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

int fleet_pg_host_local(const char *host)
{
    if (!host || !*host || host[0] == '/' || host[0] == '@') return 1;
    char b[256];
    size_t n = strlen(host);
    if (n >= sizeof b) return 0;
    memcpy(b, host, n + 1);
    if (n > 1 && b[n - 1] == '.') b[--n] = 0; /* "localhost." */
    if (strcasecmp(b, "localhost") == 0) return 1;
    struct in_addr a4;
    struct in6_addr a6;
    if (inet_pton(AF_INET, b, &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
    if (inet_pton(AF_INET6, b, &a6) == 1) return IN6_IS_ADDR_LOOPBACK(&a6);
    return 0;
}

static const char *opt(const PQconninfoOption *o, const char *kw)
{
    for (; o && o->keyword; o++)
        if (strcmp(o->keyword, kw) == 0) return o->val;
    return NULL;
}

/* Element i of a comma-separated libpq list into buf ("" when the list is
 * shorter; a single element applies to every host). */
static void list_elem(const char *list, int i, char *buf, size_t len)
{
    buf[0] = 0;
    if (!list) return;
    int count = 1;
    for (const char *p = list; *p; p++) count += *p == ',';
    if (count == 1) i = 0;
    const char *p = list;
    for (int k = 0; k < i && p; k++) {
        p = strchr(p, ',');
        if (p) p++;
    }
    if (!p) return;
    size_t n = strcspn(p, ",");
    if (n >= len) n = len - 1;
    memcpy(buf, p, n);
    buf[n] = 0;
}

static int list_len(const char *list)
{
    if (!list || !*list) return 1;
    int n = 1;
    for (const char *p = list; *p; p++) n += *p == ',';
    return n;
}

/* The password file: a regular file only its owner may read (libpq
 * silently ignores one with group or world rights). */
static int passfile_problem(const char *what, const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(err, errlen, "%s %s: %s", what, path, strerror(errno));
        return 1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "%s %s: not a regular file", what, path);
        return 1;
    }
    if (st.st_mode & (S_IRWXG | S_IRWXO)) {
        snprintf(err, errlen,
                 "%s %s: mode %04o lets other users read the password (libpq ignores such a "
                 "file): make it 0600 or 0400, readable by amfi-sync's user only",
                 what, path, (unsigned)(st.st_mode & 07777));
        return 1;
    }
    if (access(path, R_OK) != 0) {
        snprintf(err, errlen, "%s %s: %s", what, path, strerror(errno));
        return 1;
    }
    return 0;
}

/* The value libpq would use for every option but those of the connection
 * string: PQconndefaults with the connection string's service (its service
 * file, then the PG* variables, then the compiled defaults). PGSSLMODE is
 * set to a marker while it looks when it is unset, so that "nobody said"
 * can be told from libpq's default. */
static const char UNSET[] = "amfi-unset";
static PQconninfoOption *defaults_for(const char *service)
{
    char *old_service = getenv("PGSERVICE") ? strdup(getenv("PGSERVICE")) : NULL;
    int mark_sslmode = getenv("PGSSLMODE") == NULL;
    if (service) setenv("PGSERVICE", service, 1);
    if (mark_sslmode) setenv("PGSSLMODE", UNSET, 1);
    PQconninfoOption *d = PQconndefaults();
    if (mark_sslmode) unsetenv("PGSSLMODE");
    if (service) {
        if (old_service) setenv("PGSERVICE", old_service, 1);
        else unsetenv("PGSERVICE");
    }
    free(old_service);
    return d;
}

PGconn *fleet_pg_connect(const char *conninfo, const char *passfile, int allow_plaintext,
                         int *tls, int *rc, char *err, size_t errlen)
{
    *rc = 2;
    if (tls) *tls = 0;
    if (passfile && passfile_problem("--passfile", passfile, err, errlen)) return NULL;
    if (!passfile && getenv("PGPASSFILE") && *getenv("PGPASSFILE")
        && passfile_problem("PGPASSFILE", getenv("PGPASSFILE"), err, errlen))
        return NULL;
    char *perr = NULL;
    PQconninfoOption *given = PQconninfoParse(conninfo, &perr);
    if (!given) {
        snprintf(err, errlen, "--pg: %s", perr ? perr : "out of memory");
        PQfreemem(perr);
        size_t n = strlen(err);
        while (n > 0 && err[n - 1] == '\n') err[--n] = 0;
        return NULL;
    }
    PQconninfoOption *dflt = defaults_for(opt(given, "service"));
    const char *host = opt(given, "host") ? opt(given, "host") : opt(dflt, "host");
    const char *hostaddr = opt(given, "hostaddr") ? opt(given, "hostaddr") : opt(dflt, "hostaddr");
    const char *sslmode = opt(given, "sslmode") ? opt(given, "sslmode") : opt(dflt, "sslmode");
    const char *rootcert =
        opt(given, "sslrootcert") ? opt(given, "sslrootcert") : opt(dflt, "sslrootcert");
    if (sslmode && strcmp(sslmode, UNSET) == 0) sslmode = NULL;
    /* the first host not on this machine, if any */
    char remote[256] = "";
    int n = list_len(hostaddr && *hostaddr ? hostaddr : host);
    if (list_len(host) > n) n = list_len(host);
    for (int i = 0; i < n && !remote[0]; i++) {
        char h[256], a[256];
        list_elem(host, i, h, sizeof h);
        list_elem(hostaddr, i, a, sizeof a);
        const char *dest = a[0] ? a : h;
        if (!fleet_pg_host_local(dest)) snprintf(remote, sizeof remote, "%s", dest);
    }
    const char *force = NULL;
    int need_tls = remote[0] && !allow_plaintext;
    if (need_tls) {
        if (sslmode && (strcmp(sslmode, "disable") == 0 || strcmp(sslmode, "allow") == 0)) {
            snprintf(err, errlen,
                     "--pg: the server %s is not on this machine and sslmode=%s would send the "
                     "rows and the password in plain text: refused, nothing sent. Use "
                     "sslmode=verify-full (or require), or --allow-plaintext on a network you "
                     "trust (docs/fleet.md, TLS)",
                     remote, sslmode);
            PQconninfoFree(given);
            PQconninfoFree(dflt);
            return NULL;
        }
        /* prefer (libpq's default) would fall back to plain text */
        if (!sslmode || strcmp(sslmode, "prefer") == 0)
            force = rootcert && *rootcert ? "verify-full" : "require";
    }
    PQconninfoFree(given);
    PQconninfoFree(dflt);
    const char *kw[4] = {"dbname", NULL, NULL, NULL}, *val[4] = {conninfo, NULL, NULL, NULL};
    int k = 1;
    if (force) { kw[k] = "sslmode"; val[k++] = force; }
    if (passfile) { kw[k] = "passfile"; val[k++] = passfile; }
    PGconn *pg = PQconnectdbParams(kw, val, 1);
    if (PQstatus(pg) != CONNECTION_OK) {
        snprintf(err, errlen, "cannot connect to PostgreSQL: %s", PQerrorMessage(pg));
        PQfinish(pg);
        *rc = 1;
        return NULL;
    }
    int in_tls = PQsslInUse(pg);
    if (tls) *tls = in_tls;
    if (need_tls && !in_tls) {
        snprintf(err, errlen,
                 "--pg: the connection to %s is not encrypted (TLS not in use): refused. Give "
                 "the server a certificate (ssl = on) or --allow-plaintext on a network you "
                 "trust (docs/fleet.md, TLS)",
                 remote);
        PQfinish(pg);
        return NULL;
    }
    return pg;
}
