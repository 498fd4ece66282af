/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-web: the read-only web dashboard and JSON API over a site's store
 * (--db) or one site of the central PostgreSQL (--pg, --site), docs/web.md.
 * HTTP by libmicrohttpd with its internal polling thread: one thread answers
 * every request (so one store handle suffices), at most --max-connections
 * connections, each closed after --timeout idle seconds, a request's header
 * bounded by the connection's memory (64 KiB). GET and HEAD only (405
 * otherwise). Pages are static HTML and one script embedded in the program
 * (web_assets.c) that fetch the JSON API; the script draws with Chart.js,
 * read from the Debian package's file (--chartjs) and served by amfi-web
 * itself. Every answer carries a Content-Security-Policy that allows only
 * this server's own scripts, styles and data. Bound to 127.0.0.1 by default;
 * another address needs --allow-remote (docs/web.md: a reverse proxy with
 * TLS and basic auth in front is the way to serve others).
 *
 * The central database: at start and then at most every --refresh seconds
 * (when a request comes), the site's rows are fetched into a private
 * temporary store by amfi-report's code (tools/ops/report_pg.c), which
 * amfi-web then reads exactly as a site's store; the copy is removed at
 * exit. A failed refresh keeps the previous copy and is logged.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amfi_cli.h"
#include "amfi_version.h"
#include "report_pg.h"
#include "web.h"

#ifndef AMFI_WEB_CHARTJS
#define AMFI_WEB_CHARTJS "/usr/share/javascript/chart.js/chart.min.js"
#endif

#define MAX_PARAMS 16

static const char *const csp =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; "
    "connect-src 'self'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'";

typedef struct server {
    web_source src;
    /* the central database */
    const char *conninfo, *site;
    int allow_plaintext;
    double refresh_s;
    char tmpdir[256], path[2][300];
    int cur;              /* path[cur] is open */
    int64_t fetched_us;
    /* Chart.js, read at start */
    unsigned char *chartjs;
    size_t chartjs_len;
    int quiet;
} server;

static void logf_(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void logf_(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("amfi-web: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* ---- the central database's copy ------------------------------------------- */

static int fetch_central(server *sv, int slot, char *err, size_t errlen)
{
    long rows = 0;
    amfi_store_remove(sv->path[slot]);
    int rc = report_pg_fetch_site(sv->conninfo, sv->allow_plaintext, sv->site, sv->path[slot],
                                  &rows, err, errlen);
    if (rc != 0) {
        amfi_store_remove(sv->path[slot]);
        return rc;
    }
    amfi_store *s = NULL;
    if (amfi_store_open_readonly(sv->path[slot], &s, err, errlen) != 0) {
        amfi_store_remove(sv->path[slot]);
        return 1;
    }
    amfi_store *old = sv->src.store;
    sv->src.store = s;
    sv->fetched_us = sv->src.as_of_us = web_now_us();
    if (old) {
        amfi_store_close(old);
        amfi_store_remove(sv->path[sv->cur]);
    }
    sv->cur = slot;
    if (!sv->quiet)
        logf_("site %s: %ld rows fetched from the central database", sv->site, rows);
    return 0;
}

static void maybe_refresh(server *sv)
{
    if (!sv->conninfo || (double)(web_now_us() - sv->fetched_us) < sv->refresh_s * 1e6)
        return;
    char err[1024];
    if (fetch_central(sv, 1 - sv->cur, err, sizeof err) != 0) {
        logf_("site %s: refresh failed, still serving the copy of %.0f s ago: %s", sv->site,
              (double)(web_now_us() - sv->fetched_us) / 1e6, err);
        sv->fetched_us = web_now_us(); /* retried after another period */
    }
}

/* ---- HTTP -------------------------------------------------------------------- */

static void headers(struct MHD_Response *r, const char *type, int cache)
{
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, "Content-Security-Policy", csp);
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(r, "X-Frame-Options", "DENY");
    MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL,
                            cache ? "public, max-age=300" : "no-store");
}

static enum MHD_Result send_json(struct MHD_Connection *c, unsigned status, json_t *body)
{
    char *text = body ? json_dumps(body, JSON_COMPACT | JSON_REAL_PRECISION(10)) : NULL;
    json_decref(body);
    if (!text) {
        text = strdup("{\"error\":\"out of memory\"}");
        status = 500;
        if (!text)
            return MHD_NO;
    }
    size_t n = strlen(text);
    char *full = realloc(text, n + 2);
    if (full) {
        full[n] = '\n';
        full[n + 1] = '\0';
        text = full;
        n++;
    }
    struct MHD_Response *r = MHD_create_response_from_buffer(n, text, MHD_RESPMEM_MUST_FREE);
    if (!r) {
        free(text);
        return MHD_NO;
    }
    headers(r, "application/json; charset=utf-8", 0);
    if (status == 405)
        MHD_add_response_header(r, MHD_HTTP_HEADER_ALLOW, "GET, HEAD");
    enum MHD_Result ret = MHD_queue_response(c, status, r);
    MHD_destroy_response(r);
    return ret;
}

static enum MHD_Result send_bytes(struct MHD_Connection *c, const void *data, size_t len,
                                  const char *type, int cache)
{
    struct MHD_Response *r =
        MHD_create_response_from_buffer(len, (void *)data, MHD_RESPMEM_PERSISTENT);
    if (!r)
        return MHD_NO;
    headers(r, type, cache);
    enum MHD_Result ret = MHD_queue_response(c, MHD_HTTP_OK, r);
    MHD_destroy_response(r);
    return ret;
}

typedef struct params {
    web_param p[MAX_PARAMS];
    int n;
    const char *too_many; /* the first parameter beyond MAX_PARAMS */
} params;

static enum MHD_Result collect(void *cls, enum MHD_ValueKind kind, const char *key,
                               const char *value)
{
    (void)kind;
    params *ps = cls;
    if (ps->n == MAX_PARAMS) {
        ps->too_many = key;
        return MHD_NO;
    }
    ps->p[ps->n].name = key;
    ps->p[ps->n].value = value;
    ps->n++;
    return MHD_YES;
}

static enum MHD_Result answer(void *cls, struct MHD_Connection *c, const char *url,
                              const char *method, const char *version, const char *upload,
                              size_t *upload_size, void **con_cls)
{
    (void)version;
    (void)upload;
    server *sv = cls;
    if (strcmp(method, MHD_HTTP_METHOD_GET) != 0 && strcmp(method, MHD_HTTP_METHOD_HEAD) != 0) {
        *upload_size = 0; /* a body is not read: the answer is the same */
        return send_json(c, 405, web_error("only GET and HEAD: amfi-web is read-only", NULL));
    }
    (void)con_cls;
    if (strncmp(url, "/api/", 5) == 0) {
        params ps = {.n = 0};
        MHD_get_connection_values(c, MHD_GET_ARGUMENT_KIND, collect, &ps);
        if (ps.too_many) {
            char msg[64];
            snprintf(msg, sizeof msg, "more than %d parameters", MAX_PARAMS);
            return send_json(c, 400, web_error(msg, ps.too_many));
        }
        maybe_refresh(sv);
        web_reply r = web_api(&sv->src, url, ps.p, ps.n);
        if (r.status >= 500) {
            json_t *e = json_object_get(r.body, "error");
            logf_("%s: %s", url, e ? json_string_value(e) : "?");
        }
        return send_json(c, r.status, r.body);
    }
    if (strcmp(url, "/static/chart.min.js") == 0) {
        if (!sv->chartjs)
            return send_json(c, 404, web_error("Chart.js is not installed (libjs-chart.js)", NULL));
        return send_bytes(c, sv->chartjs, sv->chartjs_len, "text/javascript; charset=utf-8", 1);
    }
    for (int k = 0; k < web_n_assets; k++)
        if (strcmp(url, web_assets[k].path) == 0) {
            /* pages take no parameters but the vehicle's id, read by the script */
            return send_bytes(c, web_assets[k].data, web_assets[k].len, web_assets[k].content_type,
                              strncmp(url, "/static/", 8) == 0);
        }
    return send_json(c, 404, web_error("no such page", NULL));
}

/* ---- options ------------------------------------------------------------------ */

static void usage(FILE *f)
{
    fprintf(f,
            "Usage: amfi-web --db STORE [options]\n"
            "       amfi-web --pg CONNINFO --site ID [options]\n"
            "The read-only web dashboard and JSON API of a site's store or of one site of\n"
            "the central PostgreSQL (docs/web.md, amfi-web(1)).\n"
            "  --db STORE            the site's store (opened read-only)\n"
            "  --pg CONNINFO         the central database (libpq connection string)\n"
            "  --site ID             the site to show from it\n"
            "  --refresh S           central: fetch the site again after S seconds (60)\n"
            "  --allow-plaintext     central: a server not on this machine without TLS\n"
            "  --listen ADDR:PORT    address to serve on (127.0.0.1:8080; [::1]:PORT for\n"
            "                        IPv6; port 0: any free port, printed)\n"
            "  --allow-remote        allow an address other than loopback\n"
            "  --max-connections N   connections at once (64)\n"
            "  --timeout S           close a connection idle for S seconds (15)\n"
            "  --chartjs PATH        Chart.js file to serve (%s)\n"
            "  --quiet               no start-up lines\n"
            "  --help, --version\n",
            AMFI_WEB_CHARTJS);
}

/* "A.B.C.D:PORT" or "[v6]:PORT" into *ss; 0 or −1. */
static int parse_listen(const char *s, struct sockaddr_storage *ss, socklen_t *len, int *loopback)
{
    char host[64];
    const char *colon;
    memset(ss, 0, sizeof *ss);
    if (s[0] == '[') {
        const char *close = strchr(s, ']');
        if (!close || close[1] != ':' || (size_t)(close - s - 1) >= sizeof host)
            return -1;
        memcpy(host, s + 1, (size_t)(close - s - 1));
        host[close - s - 1] = 0;
        colon = close + 1;
    } else {
        colon = strrchr(s, ':');
        if (!colon || (size_t)(colon - s) >= sizeof host)
            return -1;
        memcpy(host, s, (size_t)(colon - s));
        host[colon - s] = 0;
        if (strcmp(host, "localhost") == 0)
            strcpy(host, "127.0.0.1");
    }
    char *end;
    errno = 0;
    long port = strtol(colon + 1, &end, 10);
    if (!colon[1] || *end || errno || port < 0 || port > 65535)
        return -1;
    struct sockaddr_in *a4 = (struct sockaddr_in *)ss;
    struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)ss;
    if (s[0] != '[' && inet_pton(AF_INET, host, &a4->sin_addr) == 1) {
        a4->sin_family = AF_INET;
        a4->sin_port = htons((uint16_t)port);
        *len = sizeof *a4;
        *loopback = (ntohl(a4->sin_addr.s_addr) >> 24) == 127;
        return 0;
    }
    if (s[0] == '[' && inet_pton(AF_INET6, host, &a6->sin6_addr) == 1) {
        a6->sin6_family = AF_INET6;
        a6->sin6_port = htons((uint16_t)port);
        *len = sizeof *a6;
        *loopback = IN6_IS_ADDR_LOOPBACK(&a6->sin6_addr);
        return 0;
    }
    return -1;
}

static unsigned char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *buf = NULL;
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0
        && st.st_size < 16 * 1024 * 1024 && (buf = malloc((size_t)st.st_size))) {
        if (fread(buf, 1, (size_t)st.st_size, f) != (size_t)st.st_size) {
            free(buf);
            buf = NULL;
        } else {
            *len = (size_t)st.st_size;
        }
    }
    fclose(f);
    return buf;
}

static int hexval(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

/* libmicrohttpd's unescaping of the path and the parameters, except that
   %00 stays as it is: a NUL would cut the text short ("/static/app.js%00.png"
   would be served as "/static/app.js"), so it reaches no comparison. */
static size_t unescape(void *cls, struct MHD_Connection *c, char *s)
{
    (void)cls;
    (void)c;
    char *w = s;
    for (const char *r = s; *r;) {
        int hi, lo;
        if (r[0] == '%' && r[1] && r[2] && (hi = hexval(r[1])) >= 0 && (lo = hexval(r[2])) >= 0
            && (hi | lo) != 0) {
            *w++ = (char)(hi * 16 + lo);
            r += 3;
        } else {
            *w++ = *r++;
        }
    }
    *w = 0;
    return (size_t)(w - s);
}

static void mhd_log(void *cls, const char *fmt, va_list ap)
{
    (void)cls;
    fputs("amfi-web: http: ", stderr);
    vfprintf(stderr, fmt, ap);
}

enum { O_PG = 1000, O_SITE, O_REFRESH, O_PLAIN, O_LISTEN, O_REMOTE, O_MAXC, O_TIMEOUT, O_CHARTJS,
       O_QUIET };

int main(int argc, char **argv)
{
    static const struct option opts[] = {
        {"db", required_argument, NULL, 'd'},
        {"pg", required_argument, NULL, O_PG},
        {"site", required_argument, NULL, O_SITE},
        {"refresh", required_argument, NULL, O_REFRESH},
        {"allow-plaintext", no_argument, NULL, O_PLAIN},
        {"listen", required_argument, NULL, O_LISTEN},
        {"allow-remote", no_argument, NULL, O_REMOTE},
        {"max-connections", required_argument, NULL, O_MAXC},
        {"timeout", required_argument, NULL, O_TIMEOUT},
        {"chartjs", required_argument, NULL, O_CHARTJS},
        {"quiet", no_argument, NULL, O_QUIET},
        AMFI_CLI_END};
    server sv = {.refresh_s = 60, .cur = 0};
    const char *db = NULL, *listen = "127.0.0.1:8080", *chartjs = AMFI_WEB_CHARTJS;
    int remote = 0;
    long maxc = 64, timeout = 15;
    amfi_cli c;
    amfi_cli_init(&c, "amfi-web", argc, argv, opts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'd': db = optarg; break;
        case O_PG: sv.conninfo = optarg; break;
        case O_SITE: sv.site = optarg; break;
        case O_REFRESH: sv.refresh_s = amfi_cli_num(&c, optarg, 1, 86400); break;
        case O_PLAIN: sv.allow_plaintext = 1; break;
        case O_LISTEN: listen = optarg; break;
        case O_REMOTE: remote = 1; break;
        case O_MAXC: maxc = amfi_cli_integer(&c, optarg, 1, 1024); break;
        case O_TIMEOUT: timeout = amfi_cli_integer(&c, optarg, 1, 3600); break;
        case O_CHARTJS: chartjs = optarg; break;
        case O_QUIET: sv.quiet = 1; break;
        default: usage(stderr); return AMFI_CLI_EXIT_USAGE;
        }
    }
    if (!db == !sv.conninfo) {
        amfi_cli_error("amfi-web", db ? "--db" : "--pg", "give --db STORE or --pg CONNINFO, one of them");
        return AMFI_CLI_EXIT_USAGE;
    }
    if (sv.conninfo && !sv.site) {
        amfi_cli_error("amfi-web", "--pg", "needs --site ID (amfi-report --pg CONNINFO lists the sites)");
        return AMFI_CLI_EXIT_USAGE;
    }
    if (db && sv.site) {
        amfi_cli_error("amfi-web", "--site", "only with --pg (a store holds one site)");
        return AMFI_CLI_EXIT_USAGE;
    }
    struct sockaddr_storage addr;
    socklen_t alen = 0;
    int loopback = 0;
    if (parse_listen(listen, &addr, &alen, &loopback) != 0) {
        amfi_cli_error("amfi-web", "--listen", "'%s' is not ADDR:PORT (127.0.0.1:8080, [::1]:8080)",
                       amfi_cli_shown(listen));
        return AMFI_CLI_EXIT_USAGE;
    }
    if (!loopback && !remote) {
        amfi_cli_error("amfi-web", "--listen",
                       "'%s' is not a loopback address: give --allow-remote too (better: a "
                       "reverse proxy with TLS and a password in front, docs/web.md)",
                       amfi_cli_shown(listen));
        return AMFI_CLI_EXIT_USAGE;
    }
    sv.chartjs = read_file(chartjs, &sv.chartjs_len);
    if (!sv.chartjs)
        logf_("%s: cannot read Chart.js (%s): the pages show their tables without charts "
              "(apt-get install libjs-chart.js, or --chartjs PATH)",
              chartjs, strerror(errno ? errno : ENOENT));

    char err[1024];
    if (db) {
        if (amfi_store_open_readonly(db, &sv.src.store, err, sizeof err) != 0) {
            logf_("%s", err);
            free(sv.chartjs);
            return 1;
        }
        sv.src.kind = "store";
        sv.src.name = db;
    } else {
        const char *t = getenv("TMPDIR");
        snprintf(sv.tmpdir, sizeof sv.tmpdir, "%s/amfi-web.XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(sv.tmpdir)) {
            logf_("%s: %s", sv.tmpdir, strerror(errno));
            free(sv.chartjs);
            return 1;
        }
        for (int k = 0; k < 2; k++)
            snprintf(sv.path[k], sizeof sv.path[k], "%s/central-%d.db", sv.tmpdir, k);
        sv.src.kind = "central";
        sv.src.name = sv.site;
        int rc = fetch_central(&sv, 0, err, sizeof err);
        if (rc != 0) {
            logf_("%s", err);
            rmdir(sv.tmpdir);
            free(sv.chartjs);
            return rc == 2 ? AMFI_CLI_EXIT_USAGE : 1;
        }
    }

    /* SIGINT and SIGTERM waited for here; the server's thread inherits the mask */
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
    signal(SIGPIPE, SIG_IGN);

    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_ERROR_LOG | MHD_USE_POLL;
    if (addr.ss_family == AF_INET6)
        flags |= MHD_USE_IPv6;
    struct MHD_Daemon *d = MHD_start_daemon(
        flags, 0, NULL, NULL, answer, &sv, MHD_OPTION_EXTERNAL_LOGGER, mhd_log, NULL,
        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)maxc, MHD_OPTION_PER_IP_CONNECTION_LIMIT,
        (unsigned)(maxc > 16 ? maxc / 2 : maxc), MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)timeout,
        MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)64 * 1024, MHD_OPTION_UNESCAPE_CALLBACK,
        unescape, NULL, MHD_OPTION_STRICT_FOR_CLIENT, 1, MHD_OPTION_END);
    int rc = 0;
    if (!d) {
        logf_("cannot listen on %s: %s", listen, strerror(errno));
        rc = 1;
    } else {
        const union MHD_DaemonInfo *info = MHD_get_daemon_info(d, MHD_DAEMON_INFO_BIND_PORT);
        unsigned port = info ? info->port : 0;
        char host[64] = "?";
        if (addr.ss_family == AF_INET)
            inet_ntop(AF_INET, &((struct sockaddr_in *)&addr)->sin_addr, host, sizeof host);
        else
            inet_ntop(AF_INET6, &((struct sockaddr_in6 *)&addr)->sin6_addr, host, sizeof host);
        if (!sv.quiet || strstr(listen, ":0") == listen + strlen(listen) - 2)
            logf_("serving %s %s on http://%s%s%s:%u/", sv.src.kind, sv.src.name,
                  addr.ss_family == AF_INET6 ? "[" : "", host,
                  addr.ss_family == AF_INET6 ? "]" : "", port);
        int sig = 0;
        sigwait(&set, &sig);
        MHD_stop_daemon(d);
    }
    amfi_store_close(sv.src.store);
    if (sv.conninfo) {
        amfi_store_remove(sv.path[0]);
        amfi_store_remove(sv.path[1]);
        rmdir(sv.tmpdir);
    }
    free(sv.chartjs);
    return rc;
}
