/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * web_http PORT: amfi-web's HTTP answers on 127.0.0.1:PORT, serving the
 * store of web_fixture.c, checked over plain sockets (the request bytes
 * exactly as written here: no client tidies a path up): the JSON of every
 * API path against the fixture, the security headers, 400 naming the
 * parameter for each bad one, 405 for other methods, 404 for unknown paths
 * and every path traversal, HEAD, the hostile text escaped by JSON and
 * never in a page, and a fuzz loop (random bytes in paths and queries,
 * huge queries, broken request lines) answered with a clean 4xx, the server
 * alive after it. Prints one line per failure; exit 0 all passed, 1 not.
 */
#include <arpa/inet.h>
#include <jansson.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#define HOSTILE "<img src=x onerror=\"window.__xss=1\">'&amp;</td><script>window.__xss=2</script>"

static int port, failures, checks;

#define CHECK(cond, ...)                                                                        \
    do {                                                                                        \
        checks++;                                                                               \
        if (!(cond)) {                                                                          \
            failures++;                                                                         \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                                         \
            printf(__VA_ARGS__);                                                                \
            printf("\n");                                                                       \
        }                                                                                       \
    } while (0)

typedef struct resp {
    int status;        /* 0: no status line (connection closed) */
    char *head, *body; /* malloc'd, NUL-terminated */
    size_t body_len;
} resp;

static void resp_free(resp *r)
{
    free(r->head);
    free(r->body);
    memset(r, 0, sizeof *r);
}

/* Sends req (len bytes) and reads the answer until the server closes. */
static resp raw(const char *req, size_t len)
{
    resp r = {0};
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    struct timeval tv = {.tv_sec = 30};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        if (fd >= 0)
            close(fd);
        return r;
    }
    for (size_t off = 0; off < len;) {
        ssize_t n = send(fd, req + off, len - off, MSG_NOSIGNAL);
        if (n <= 0)
            break; /* the server may answer and close before reading it all */
        off += (size_t)n;
    }
    size_t cap = 65536, n = 0;
    char *buf = malloc(cap + 1);
    for (;;) {
        if (n == cap) {
            cap *= 2;
            buf = realloc(buf, cap + 1);
        }
        ssize_t k = recv(fd, buf + n, cap - n, 0);
        if (k <= 0)
            break;
        n += (size_t)k;
    }
    close(fd);
    buf[n] = 0;
    char *end = strstr(buf, "\r\n\r\n");
    if (sscanf(buf, "HTTP/1.%*d %d", &r.status) != 1 || !end) {
        r.status = 0;
        free(buf);
        return r;
    }
    r.head = strndup(buf, (size_t)(end - buf) + 2);
    r.body_len = n - (size_t)(end + 4 - buf);
    r.body = malloc(r.body_len + 1);
    memcpy(r.body, end + 4, r.body_len);
    r.body[r.body_len] = 0;
    free(buf);
    return r;
}

static resp req(const char *method, const char *target)
{
    size_t len = strlen(method) + strlen(target) + 128;
    char *s = malloc(len);
    int n = snprintf(s, len, "%s %s HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n",
                     method, target);
    resp r = raw(s, (size_t)n);
    free(s);
    return r;
}

/* header value (case-insensitive name), or NULL */
static const char *header(const resp *r, const char *name, char *buf, size_t len)
{
    if (!r->head)
        return NULL;
    size_t nl = strlen(name);
    for (const char *p = strstr(r->head, "\r\n"); p && p[2]; p = strstr(p + 2, "\r\n")) {
        if (strncasecmp(p + 2, name, nl) == 0 && p[2 + nl] == ':') {
            const char *v = p + 3 + nl;
            while (*v == ' ')
                v++;
            const char *e = strstr(v, "\r\n");
            snprintf(buf, len, "%.*s", (int)(e ? e - v : (long)strlen(v)), v);
            return buf;
        }
    }
    return NULL;
}

static json_t *get_json(const char *target, int want)
{
    resp r = req("GET", target);
    CHECK(r.status == want, "GET %s: status %d, expected %d (%s)", target, r.status, want,
          r.body ? r.body : "");
    char ct[128];
    CHECK(r.status == 0 || (header(&r, "Content-Type", ct, sizeof ct)
                            && strncmp(ct, "application/json", 16) == 0),
          "GET %s: Content-Type not JSON", target);
    json_error_t e;
    json_t *j = r.body ? json_loads(r.body, 0, &e) : NULL;
    CHECK(j, "GET %s: not JSON: %s", target, r.body ? r.body : "(no body)");
    resp_free(&r);
    return j ? j : json_object();
}

/* json_path(j, "a.b.0.c") */
static json_t *at(json_t *j, const char *path)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *save, *t = strtok_r(buf, ".", &save); t && j; t = strtok_r(NULL, ".", &save))
        j = json_is_array(j) ? json_array_get(j, (size_t)atoi(t)) : json_object_get(j, t);
    return j;
}

static long long ival(json_t *j, const char *path)
{
    json_t *v = at(j, path);
    return json_is_integer(v) ? json_integer_value(v) : -999999;
}

static const char *sval(json_t *j, const char *path)
{
    const char *s = json_string_value(at(j, path));
    return s ? s : "(none)";
}

static double rval(json_t *j, const char *path)
{
    json_t *v = at(j, path);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static int has_text(json_t *j, const char *path, const char *want)
{
    return strstr(sval(j, path), want) != NULL;
}

/* The raw samples of the fixture's passages (web_fixture.c). */
static void check_raw(void)
{
    const long long t0 = 1768006800000000LL; /* 2026-01-10T01:00:00Z */
    /* passage 5: every sample, exactly, with its time base and vehicle */
    json_t *j = get_json("/api/passages/5", 200);
    CHECK(json_is_object(at(j, "raw")) && json_is_null(at(j, "raw_reason")),
          "passage 5: raw %s", sval(j, "raw_reason"));
    CHECK(rval(j, "raw.rate_hz") == 1000 && ival(j, "raw.n_samples") == 1500
              && ival(j, "raw.t0_utime") == t0 + 4 * 3600000000LL - 500000
              && strcmp(sval(j, "raw.precision"), "float64") == 0
              && at(j, "raw.decimated") == NULL,
          "passage 5: time base %g %lld %lld %s", rval(j, "raw.rate_hz"),
          ival(j, "raw.n_samples"), ival(j, "raw.t0_utime"), sval(j, "raw.precision"));
    CHECK(json_array_size(at(j, "raw.sensors")) == 2
              && json_array_size(at(j, "raw.sensors.0.samples")) == 1500
              && json_array_size(at(j, "raw.sensors.1.samples")) == 1500
              && ival(j, "raw.sensors.1.id") == 7 && rval(j, "raw.sensors.1.at_m") == 15.125,
          "passage 5: sensors");
    /* amfi-web writes numbers to 10 significant digits */
    CHECK(fabs(rval(j, "raw.sensors.1.samples.100") - (0.02 * sin(0.013 * 100 + 1) + 1e-4 * 2))
              < 1e-11,
          "passage 5: sample 100 of sensor 7: %.17g", rval(j, "raw.sensors.1.samples.100"));
    CHECK(fabs(rval(j, "raw.t_entry_s") - 0.5) < 1e-9
              && fabs(rval(j, "raw.t_last_axle_s") - (0.5 + 1.3 / 20)) < 1e-9
              && json_array_size(at(j, "raw.vehicles")) == 1 && ival(j, "raw.vehicle") == 0
              && ival(j, "raw.vehicles.0.vehicle_id") == 1005
              && json_is_false(at(j, "raw.exit_marked")) && has_text(j, "raw.exit_reason", "span"),
          "passage 5: entry %g, last axle %g", rval(j, "raw.t_entry_s"),
          rval(j, "raw.t_last_axle_s"));
    json_decref(j);
    /* passage 11: 30000 samples a sensor, sent as the min and max of 2000
     * buckets of 15: 4000 points, the spike kept */
    j = get_json("/api/passages/11", 200);
    CHECK(ival(j, "raw.decimated") == 15 && ival(j, "raw.n_samples") == 30000
              && strcmp(sval(j, "raw.precision"), "float32") == 0,
          "passage 11: decimated %lld of %lld, %s", ival(j, "raw.decimated"),
          ival(j, "raw.n_samples"), sval(j, "raw.precision"));
    double top = -1;
    for (int i = 0; i < 3; i++) {
        char path[64];
        snprintf(path, sizeof path, "raw.sensors.%d.samples", i);
        json_t *a = at(j, path);
        CHECK(json_array_size(a) == 4000, "passage 11: sensor %d: %zu points", i,
              json_array_size(a));
        for (size_t k = 0; i == 1 && k < json_array_size(a); k++)
            if (json_number_value(json_array_get(a, k)) > top)
                top = json_number_value(json_array_get(a, k));
    }
    CHECK(top == 5.0, "passage 11: the spike of sensor 7 is %g, not 5", top);
    /* sample 12345 opens bucket 823: its max (the spike) comes before its min */
    CHECK(rval(j, "raw.sensors.1.samples.1646") == 5.0 && rval(j, "raw.sensors.1.samples.1647") < 1,
          "passage 11: bucket 823 is %g, %g", rval(j, "raw.sensors.1.samples.1646"),
          rval(j, "raw.sensors.1.samples.1647"));
    json_decref(j);
    /* passages 14 and 15: one event window, each its own vehicle */
    json_t *a = get_json("/api/passages/14", 200), *b = get_json("/api/passages/15", 200);
    CHECK(ival(a, "raw.window_id") > 0 && ival(a, "raw.window_id") == ival(b, "raw.window_id")
              && ival(a, "raw.vehicle") == 0 && ival(b, "raw.vehicle") == 1
              && json_array_size(at(b, "raw.vehicles")) == 2
              && json_array_size(at(b, "raw.sensors.0.samples")) == 2000
              && rval(b, "raw.rate_hz") == 500,
          "passages 14, 15: windows %lld %lld, vehicles %lld %lld", ival(a, "raw.window_id"),
          ival(b, "raw.window_id"), ival(a, "raw.vehicle"), ival(b, "raw.vehicle"));
    CHECK(fabs(rval(a, "raw.t_entry_s") - 0.5) < 1e-9 && fabs(rval(b, "raw.t_entry_s") - 1.7) < 1e-9
              && fabs(rval(b, "raw.vehicles.0.t_entry_s") - 0.5) < 1e-9,
          "passages 14, 15: entries %g %g", rval(a, "raw.t_entry_s"), rval(b, "raw.t_entry_s"));
    json_decref(a);
    json_decref(b);
    /* the reasons: deleted by the retention, never weighed, not kept, damaged */
    j = get_json("/api/passages/2", 200);
    CHECK(json_is_null(at(j, "raw")) && has_text(j, "raw_reason", "or deleted by the retention")
              && has_text(j, "raw_reason", "not newer than the oldest window kept "
                                           "(2026-01-10T05:00:00"),
          "passage 2: %s", sval(j, "raw_reason"));
    json_decref(j);
    j = get_json("/api/passages/3", 200);
    CHECK(json_is_null(at(j, "raw")) && has_text(j, "raw_reason", "never complete"),
          "passage 3: %s", sval(j, "raw_reason"));
    json_decref(j);
    j = get_json("/api/passages/7", 200);
    CHECK(json_is_null(at(j, "raw")) && has_text(j, "raw_reason", "daemon.store.raw.keep")
              && has_text(j, "raw_reason", "not the retention")
              && has_text(j, "raw_reason", "the oldest kept is from 2026-01-10T05:00:00"),
          "passage 7: %s", sval(j, "raw_reason"));
    json_decref(j);
    j = get_json("/api/passages/17", 200);
    CHECK(json_is_null(at(j, "raw")) && has_text(j, "raw_reason", "damaged")
              && has_text(j, "raw_reason", "passage 17") && ival(j, "id") == 17
              && json_array_size(at(j, "axles")) == 2,
          "passage 17: %s", sval(j, "raw_reason"));
    json_decref(j);
}

/* a 400 naming `param` */
static void bad(const char *target, const char *param)
{
    json_t *j = get_json(target, 400);
    CHECK(strcmp(sval(j, "parameter"), param) == 0, "GET %s: parameter '%s', expected '%s'",
          target, sval(j, "parameter"), param);
    CHECK(strlen(sval(j, "error")) > 5, "GET %s: no error message", target);
    json_decref(j);
}

static void ids(const char *target, const long long *want, int n)
{
    json_t *j = get_json(target, 200);
    json_t *a = json_object_get(j, "passages");
    CHECK(json_array_size(a) == (size_t)n, "GET %s: %zu passages, expected %d", target,
          json_array_size(a), n);
    for (int k = 0; k < n && k < (int)json_array_size(a); k++) {
        long long got = json_integer_value(json_object_get(json_array_get(a, (size_t)k), "id"));
        CHECK(got == want[k], "GET %s: passage %d is id %lld, expected %lld", target, k, got,
              want[k]);
    }
    json_decref(j);
}

static long long sum_n(json_t *arr)
{
    long long s = 0;
    for (size_t k = 0; k < json_array_size(arr); k++)
        s += json_integer_value(json_object_get(json_array_get(arr, k), "n"));
    return s;
}

int main(int argc, char **argv)
{
    if (argc != 2 || (port = atoi(argv[1])) <= 0) {
        fprintf(stderr, "usage: web_http PORT\n");
        return 2;
    }
    char h[512];

    /* ---- /api/status and the headers ---- */
    resp r = req("GET", "/api/status");
    CHECK(r.status == 200, "status: %d", r.status);
    CHECK(header(&r, "Content-Security-Policy", h, sizeof h) && strstr(h, "default-src 'none'")
              && strstr(h, "script-src 'self'"),
          "status: Content-Security-Policy missing or loose");
    CHECK(header(&r, "X-Content-Type-Options", h, sizeof h) && strcmp(h, "nosniff") == 0,
          "status: X-Content-Type-Options");
    CHECK(header(&r, "Cache-Control", h, sizeof h) && strcmp(h, "no-store") == 0,
          "status: Cache-Control");
    resp_free(&r);
    json_t *j = get_json("/api/status", 200);
    CHECK(strcmp(sval(j, "site"), "web-test") == 0, "status: site %s", sval(j, "site"));
    CHECK(strcmp(sval(j, "site_name"), "Bridge " HOSTILE) == 0, "status: site_name %s",
          sval(j, "site_name"));
    CHECK(ival(j, "passages") == 40, "status: passages %lld", ival(j, "passages"));
    CHECK(ival(j, "store_version") >= 10, "status: store_version");
    CHECK(ival(j, "last_passage.id") == 40, "status: last passage %lld", ival(j, "last_passage.id"));
    CHECK(strcmp(sval(j, "last_passage.utime_utc"), "2026-01-11T16:00:00.000000Z") == 0,
          "status: last passage time %s", sval(j, "last_passage.utime_utc"));
    CHECK(ival(j, "newest_day.total") == 17 && ival(j, "newest_day.by_status.ok") == 16
              && ival(j, "newest_day.by_status.invalid") == 1,
          "status: newest day %lld ok %lld invalid %lld", ival(j, "newest_day.total"),
          ival(j, "newest_day.by_status.ok"), ival(j, "newest_day.by_status.invalid"));
    CHECK(json_array_size(at(j, "open_alerts")) == 1
              && strcmp(sval(j, "open_alerts.0.kind"), "std_increase") == 0
              && strcmp(sval(j, "open_alerts.0.message"), "STD up " HOSTILE) == 0,
          "status: open alerts");
    CHECK(strcmp(sval(j, "metrics.intake.messages_received"), "(none)") == 0, "at() splits dots");
    CHECK(strcmp(json_string_value(json_object_get(json_object_get(j, "metrics"),
                                                   "intake.messages_received")) ?: "", "12345") == 0,
          "status: metrics");
    CHECK(strcmp(sval(j, "indicator.state"), "normal") == 0 && ival(j, "indicator.id") == 8,
          "status: indicator");
    CHECK(ival(j, "baseline.n") == 30, "status: baseline");
    json_decref(j);

    /* ---- /api/passages ---- */
    ids("/api/passages?limit=5", (const long long[]){40, 39, 38, 37, 36}, 5);
    ids("/api/passages?status=invalid", (const long long[]){33, 23, 13, 3}, 4);
    ids("/api/passages?from=2026-01-10T05:00:00Z&to=2026-01-10T07:00:00Z",
        (const long long[]){7, 6, 5}, 3);
    ids("/api/passages?from=1768021200&to=1768028400.5", (const long long[]){7, 6, 5}, 3);
    ids("/api/passages?from=2026-01-10T05:00&to=2026-01-10%2007:00:00.000001",
        (const long long[]){7, 6, 5}, 3);
    ids("/api/passages?class=FHWA9&status=ok&limit=3", (const long long[]){39, 36, 30}, 3);
    ids("/api/passages?from=2030-01-01", NULL, 0);
    j = get_json("/api/passages?class=FHWA9&limit=1000", 200);
    CHECK(json_array_size(at(j, "passages")) == 11, "class FHWA9: %zu",
          json_array_size(at(j, "passages")));
    for (size_t k = 0; k < json_array_size(at(j, "passages")); k++)
        CHECK(strcmp(json_string_value(json_object_get(json_array_get(at(j, "passages"), k),
                                                       "class")), "FHWA9") == 0,
              "class filter let another through");
    json_decref(j);
    j = get_json("/api/passages?limit=5000", 200);
    CHECK(ival(j, "limit") == 1000 && ival(j, "count") == 40, "limit cap: %lld %lld",
          ival(j, "limit"), ival(j, "count"));
    json_decref(j);

    /* ---- /api/passages/ID ---- */
    j = get_json("/api/passages/7", 200);
    CHECK(strcmp(sval(j, "reason"), "solver: " HOSTILE) == 0, "passage 7: reason %s",
          sval(j, "reason"));
    CHECK(strcmp(sval(j, "status"), "error") == 0, "passage 7: status");
    CHECK(json_array_size(at(j, "axles")) == 5 && json_real_value(at(j, "axles.4.load_kg")) == 7500
              && json_real_value(at(j, "axles.1.spacing_m")) > 1.29,
          "passage 7: axles");
    CHECK(json_array_size(at(j, "groups")) == 3 && json_real_value(at(j, "groups.2.load_kg")) == 22200
              && json_array_size(at(j, "groups.2.axles")) == 3,
          "passage 7: groups");
    CHECK(json_is_null(at(j, "raw")) && strlen(sval(j, "raw_reason")) > 10, "passage 7: raw");
    CHECK(strcmp(sval(j, "class"), "A23") == 0 && strcmp(sval(j, "axle_groups"), "1-1-3") == 0,
          "passage 7: class");
    CHECK(json_real_value(at(j, "residual_rms")) > 0.0069
              && json_real_value(at(j, "residual_rms")) < 0.0071,
          "passage 7: residual");
    CHECK(json_is_null(at(j, "loads_refused")), "passage 7: loads refused");
    json_decref(j);
    j = get_json("/api/passages/12", 200);
    CHECK(strcmp(sval(j, "status"), "ok") == 0 && json_is_null(at(j, "overload"))
              && strcmp(sval(j, "loads_refused"), "group 2: " HOSTILE) == 0,
          "passage 12: loads refused %s", sval(j, "loads_refused"));
    json_decref(j);
    j = get_json("/api/passages/3", 200);
    CHECK(strcmp(sval(j, "status"), "invalid") == 0 && json_is_null(at(j, "gvw_kg"))
              && json_array_size(at(j, "axles")) == 0 && json_is_null(at(j, "class")),
          "passage 3: invalid, no axles, nulls");
    json_decref(j);
    check_raw();
    json_decref(get_json("/api/passages/41", 404));
    json_decref(get_json("/api/passages/0", 404));
    json_decref(get_json("/api/passages/abc", 404));
    json_decref(get_json("/api/passages/7x", 404));
    json_decref(get_json("/api/passages/99999999999999999999999", 404));
    bad("/api/passages/7?full=1", "full");

    /* ---- /api/alerts, /api/trends, /api/classes ---- */
    j = get_json("/api/alerts", 200);
    CHECK(json_array_size(at(j, "open")) == 1 && json_array_size(at(j, "recent")) == 3
              && ival(j, "recent.0.id") == 3 && at(j, "recent.0.raised") == json_false(),
          "alerts");
    json_decref(j);
    j = get_json("/api/alerts?limit=1", 200);
    CHECK(json_array_size(at(j, "recent")) == 1, "alerts limit");
    json_decref(j);
    struct {
        const char *series;
        long long n;
    } tr[] = {{"gvw", 35},      {"indicator", 8},    {"natfreq", 20},
              {"residual", 36}, {"temperature", 12}, {"fit_ratio", 15}};
    for (int k = 0; k < 6; k++) {
        char t[96];
        snprintf(t, sizeof t, "/api/trends?series=%s&points=7", tr[k].series);
        j = get_json(t, 200);
        CHECK(json_array_size(at(j, "points")) >= 1 && json_array_size(at(j, "points")) <= 7
                  && sum_n(at(j, "points")) == tr[k].n,
              "%s: %zu points holding %lld values, expected <= 7 holding %lld", t,
              json_array_size(at(j, "points")), sum_n(at(j, "points")), tr[k].n);
        json_decref(j);
    }
    /* the model fit with the levels amfid ran with (meta alerts.model_fit) */
    j = get_json("/api/trends?series=fit_ratio&points=40", 200);
    CHECK(json_array_size(at(j, "points")) == 15 && sum_n(at(j, "points")) == 15
              && fabs(rval(j, "points.0.mean") - 0.01) < 1e-12
              && fabs(rval(j, "points.14.mean") - 0.39) < 1e-12,
          "fit_ratio: %zu points, first %g, last %g", json_array_size(at(j, "points")),
          rval(j, "points.0.mean"), rval(j, "points.14.mean"));
    CHECK(at(j, "thresholds.source") && strcmp(sval(j, "thresholds.source"), "amfid") == 0
              && fabs(rval(j, "thresholds.raise") - 0.2) < 1e-12
              && fabs(rval(j, "thresholds.clear") - 0.1) < 1e-12
              && ival(j, "thresholds.window") == 5 && ival(j, "thresholds.raise_after") == 3
              && ival(j, "thresholds.clear_after") == 4
              && at(j, "thresholds.enabled") == json_true(),
          "fit_ratio: not amfid's recorded thresholds");
    json_decref(j);
    j = get_json("/api/trends?series=residual", 200);
    CHECK(at(j, "thresholds") == NULL, "residual: thresholds it has none of");
    json_decref(j);
    j = get_json("/api/trends?series=gvw&points=1", 200);
    CHECK(json_array_size(at(j, "points")) == 1 && json_real_value(at(j, "points.0.max")) == 201500,
          "gvw in one point: max");
    json_decref(j);
    j = get_json("/api/trends?series=gvw&from=2026-01-11&to=2026-01-11T23:59:59Z", 200);
    CHECK(sum_n(at(j, "points")) == 16, "gvw of 2026-01-11: %lld", sum_n(at(j, "points")));
    json_decref(j);
    /* without from: the 30 days before `to` (or the newest passage) */
    j = get_json("/api/trends?series=gvw&to=2026-01-10T10:00:00Z", 200);
    CHECK(sum_n(at(j, "points")) == 8
              && strcmp(sval(j, "from_utc"), "2025-12-11T10:00:00.000000Z") == 0,
          "gvw up to 10:00: %lld from %s", sum_n(at(j, "points")), sval(j, "from_utc"));
    json_decref(j);
    j = get_json("/api/classes?to=2026-01-10T10:00:00Z", 200);
    CHECK(sum_n(at(j, "classes")) == 10, "classes up to 10:00: %lld", sum_n(at(j, "classes")));
    json_decref(j);
    j = get_json("/api/trends?series=gvw", 200);
    CHECK(strcmp(sval(j, "from_utc"), "2025-12-12T16:00:00.000000Z") == 0,
          "default window from %s", sval(j, "from_utc"));
    json_decref(j);
    j = get_json("/api/trends?series=gvw&from=2030-01-01", 200);
    CHECK(json_array_size(at(j, "points")) == 0, "trend of an empty range");
    json_decref(j);
    j = get_json("/api/classes", 200);
    long long total = sum_n(at(j, "classes"));
    CHECK(total == 40, "classes: %lld passages", total);
    int seen = 0;
    for (size_t k = 0; k < json_array_size(at(j, "classes")); k++) {
        json_t *c = json_array_get(at(j, "classes"), k);
        if (json_is_string(json_object_get(c, "class"))
            && strcmp(json_string_value(json_object_get(c, "class")), "FHWA9") == 0) {
            seen = 1;
            CHECK(json_integer_value(json_object_get(c, "n")) == 11
                      && json_integer_value(json_object_get(c, "n_overload")) == 1
                      && json_integer_value(json_object_get(c, "n_refused")) == 1,
                  "classes: FHWA9");
        } else {
            CHECK(json_integer_value(json_object_get(c, "n_refused")) == 0, "classes: refused %s",
                  json_string_value(json_object_get(c, "class")));
        }
    }
    CHECK(seen, "classes: no FHWA9");
    json_decref(j);

    /* ---- bad parameters: 400 naming the parameter ---- */
    bad("/api/passages?limit=0", "limit");
    bad("/api/passages?limit=-3", "limit");
    bad("/api/passages?limit=abc", "limit");
    bad("/api/passages?limit=", "limit");
    bad("/api/passages?limit=1e3", "limit");
    bad("/api/passages?limit=99999999999999999999999", "limit");
    bad("/api/passages?from=2026-13-01", "from");
    bad("/api/passages?from=2026-02-30", "from");
    bad("/api/passages?to=yesterday", "to");
    bad("/api/passages?to=-5", "to");
    bad("/api/passages?from=10000-01-01", "from");
    bad("/api/passages?from=2026-01-02&to=2026-01-01", "from");
    bad("/api/passages?status=bogus", "status");
    bad("/api/passages?status=", "status");
    bad("/api/passages?class=%3Cscript%3E", "class");
    bad("/api/passages?class=ABCDEFGHIJKLMNOPQ", "class");
    bad("/api/passages?limit=1&limit=2", "limit");
    bad("/api/passages?sort=id", "sort");
    bad("/api/status?x=1", "x");
    bad("/api/trends", "series");
    bad("/api/trends?series=bogus", "series");
    bad("/api/trends?series=gvw&points=0", "points");
    bad("/api/trends?series=gvw&points=2001", "points");
    bad("/api/passages?status=ok%00", "status");
    bad("/api/classes?from=x", "from");
    bad("/api/alerts?limit=0", "limit");
    bad("/api/passages?a=1&b=2&c=3&d=4&e=5&f=6&g=7&h=8&i=9&j=10&k=11&l=12&m=13&n=14&o=15&p=16&q=17",
        "q");
    j = get_json("/api/passages?%FF%FE=1", 400);
    CHECK(json_is_string(at(j, "parameter")), "a parameter name not UTF-8 is named (as '?')");
    json_decref(j);

    /* ---- methods ---- */
    const char *methods[] = {"POST", "PUT", "DELETE", "PATCH", "OPTIONS"};
    for (int k = 0; k < 5; k++) {
        r = req(methods[k], "/api/status");
        CHECK(r.status == 405 && header(&r, "Allow", h, sizeof h) && strcmp(h, "GET, HEAD") == 0,
              "%s: %d", methods[k], r.status);
        resp_free(&r);
    }
    const char post[] = "POST /api/status HTTP/1.1\r\nHost: x\r\nConnection: close\r\n"
                        "Content-Length: 11\r\n\r\nhello world";
    r = raw(post, sizeof post - 1);
    CHECK(r.status == 405, "POST with a body: %d", r.status);
    resp_free(&r);
    r = req("HEAD", "/api/status");
    CHECK(r.status == 200 && r.body_len == 0, "HEAD: %d, %zu body bytes", r.status, r.body_len);
    resp_free(&r);

    /* ---- pages, traversal ---- */
    const char *pages[] = {"/", "/passages", "/vehicle?id=7", "/trends", "/alerts", "/classes",
                           "/static/app.js", "/static/style.css"};
    for (int k = 0; k < 8; k++) {
        r = req("GET", pages[k]);
        CHECK(r.status == 200 && header(&r, "Content-Security-Policy", h, sizeof h)
                  && header(&r, "X-Content-Type-Options", h, sizeof h),
              "page %s: %d or headers", pages[k], r.status);
        CHECK(r.body && !strstr(r.body, "__xss") && !strstr(r.body, "web-test"),
              "page %s holds store text", pages[k]);
        resp_free(&r);
    }
    r = req("GET", "/static/chart.min.js");
    CHECK(r.status == 200 || r.status == 404, "chart.min.js: %d", r.status);
    if (access("/usr/share/javascript/chart.js/chart.min.js", R_OK) == 0)
        CHECK(r.status == 200 && r.body_len > 10000, "chart.min.js not served");
    resp_free(&r);
    const char *trav[] = {"/../../../../etc/passwd", "/static/../../../etc/passwd",
                          "/%2e%2e/%2e%2e/etc/passwd", "/static/%2e%2e/%2e%2e/etc/passwd",
                          "/static/..%2f..%2fetc%2fpasswd", "/static//etc/passwd",
                          "/api/../../etc/passwd", "/api/passages/../../../etc/passwd",
                          "/static/app.js/../../etc/passwd", "//etc/passwd", "/etc/passwd",
                          "/index.html", "/static/", "/static", "/api", "/api/",
                          "/api/nope", "/API/status", "/api/status/", "/api/passages/7/axles",
                          "/static/chart.min.js/../app.js", "/%00", "/static/app.js%00.png"};
    for (size_t k = 0; k < sizeof trav / sizeof trav[0]; k++) {
        r = req("GET", trav[k]);
        CHECK(r.status == 404 || r.status == 400, "GET %s: %d", trav[k], r.status);
        CHECK(!r.body || !strstr(r.body, "root:"), "GET %s: /etc/passwd served", trav[k]);
        resp_free(&r);
    }

    /* ---- fuzz: clean 4xx, never a crash ---- */
    srand(27);
    int bad_answers = 0;
    for (int k = 0; k < 300; k++) {
        char target[600];
        int n = 1 + rand() % 500, m = 0;
        const char *base[] = {"/", "/api/passages?", "/api/trends?series=", "/api/passages/",
                              "/static/", "/api/status?"};
        m = snprintf(target, sizeof target, "%s", base[rand() % 6]);
        for (int i = 0; i < n && m < (int)sizeof target - 4; i++) {
            int c = 33 + rand() % 94; /* printable, no space */
            if (rand() % 8 == 0)
                m += snprintf(target + m, sizeof target - (size_t)m, "%%%02X", rand() % 256);
            else
                target[m++] = (char)c;
        }
        target[m] = 0;
        r = req("GET", target);
        if (!(r.status >= 200 && r.status < 500)) {
            if (bad_answers++ < 5)
                printf("fuzz: GET %s: %d\n", target, r.status);
        }
        resp_free(&r);
    }
    CHECK(bad_answers == 0, "fuzz: %d requests without a clean answer", bad_answers);
    /* a huge query string, a huge header, broken request lines */
    size_t big = 200000;
    char *huge = malloc(big + 64);
    memcpy(huge, "/api/passages?limit=", 20);
    memset(huge + 20, '9', big);
    huge[big + 20] = 0;
    r = req("GET", huge);
    CHECK(r.status >= 400 && r.status < 500, "huge query: %d", r.status);
    resp_free(&r);
    memcpy(huge, "/api/passages?", 14);
    for (size_t i = 14; i < big; i += 4)
        memcpy(huge + i, "a=1&", 4);
    huge[big] = 0;
    r = req("GET", huge);
    CHECK(r.status >= 400 && r.status < 500, "many parameters: %d", r.status);
    resp_free(&r);
    free(huge);
    const char *broken[] = {"GET\r\n\r\n", "GARBAGE\r\n\r\n", "GET / HTTP/9.9\r\n\r\n",
                            "GET /api/status HTTP/1.1\r\n\r\n", /* no Host */
                            "GET  HTTP/1.1\r\nHost: x\r\n\r\n", "\r\n\r\n\r\n",
                            "GET /api/status HTTP/1.1\r\nHost: x\r\nContent-Length: -1\r\n\r\n"};
    for (size_t k = 0; k < sizeof broken / sizeof broken[0]; k++) {
        r = raw(broken[k], strlen(broken[k]));
        CHECK(r.status == 0 || (r.status >= 400 && r.status < 506), "broken request %zu: %d", k,
              r.status);
        resp_free(&r);
    }
    j = get_json("/api/status", 200);
    CHECK(ival(j, "passages") == 40, "the server after the fuzzing");
    json_decref(j);

    printf("web_http: %d checks, %d failed\n", checks, failures);
    return failures ? 1 : 0;
}
