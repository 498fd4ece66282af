/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-top: a live view of one site in a terminal, from amfid's bus
 * (docs/daemon.md, "Watching live: amfi-top"). It subscribes to what amfid
 * publishes (passage_t, alert_t, status_t on the channels of amfid.yaml),
 * verifies every message's signature as amfid does (messages/amfi_auth.h:
 * the same key lookup, daemon.bus.auth, daemon.bus.max_skew_s), checks its
 * bytes before decoding (amfi_msg_check.h), and shows the newest passages
 * (time, lane, class, speed, GVW, status, and why the axle and group loads
 * were refused when they were), the counts by status, the alerts
 * and amfid's status. No curses: on a terminal the screen is redrawn every
 * --interval with ANSI escapes; with --count N, --once, --plain or when
 * stdout is not a terminal it prints plain lines (one per passage, alert or
 * status change) and, at the end, the counts and what was refused.
 *
 *   amfi-top [--config FILE] [--lcm-url URL] [--bus-key FILE] [--rows N]
 *            [--interval S] [--count N | --once] [--plain] [--timeout S]
 *
 * Exit: 0; 1 the bus or the key cannot be opened, or --count/--once timed
 * out before they were done; 2 a bad command line or configuration.
 * Single-threaded (LCM's handlers run in lcm_handle_timeout).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <inttypes.h>
#include <lcm/lcm.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "amfi_auth.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_messages.h"
#include "amfi_msg_check.h"
#include "amfi_time.h"

#define PROG "amfi-top"
#ifndef AMFID_DEFAULT_CONFIG
#define AMFID_DEFAULT_CONFIG "/etc/amfid/amfid.yaml"
#endif
/* amfid's bus when daemon.lcm_url is "" (daemon/bus.c) */
#define AMFID_BUILTIN_URL "udpm://239.255.76.67:7667?ttl=0"

enum { MAX_ROWS = 200, N_STATUS = 8, MAX_ALERTS = 8 };
static const char *const status_names[N_STATUS] = {"ok", "gap", "late", "overload",
                                                   "multiple", "invalid", "error", "other"};

struct row {
    int64_t utime, passage_id;
    int lane;
    char cls[16], status[16];
    char refused[112]; /* why the axle and group loads were refused ("" when they were not) */
    double speed_mps, gvw_kg;
};
struct alert_row {
    int64_t utime, alert_id;
    int raised;
    char level[16], kind[32], message[160];
};

static struct {
    /* options */
    const char *config, *url_opt, *key_opt;
    int rows, plain, once;
    long count;
    double interval, timeout;
    /* what was seen */
    struct row ring[MAX_ROWS];
    int n_ring, head;
    long by_status[N_STATUS], passages, loads_refused;
    struct alert_row alerts[MAX_ALERTS];
    int n_alerts;
    long alerts_seen;
    int have_status;
    amfi_status_t last; /* strings copied below */
    char state[16], last_error[160], site[64], last_state[16];
    long refused[AMFI_AUTH_NREASONS], malformed;
    char last_refusal[200];
    /* the bus */
    amfi_auth_verifier *auth;
} T;

static volatile sig_atomic_t stop;
static void on_signal(int sig) { (void)sig; stop = 1; }

/* Text from the bus for a terminal: printable ASCII and whole UTF-8
 * sequences pass, everything else (escapes, control characters) becomes
 * '?', so a message cannot drive the terminal. At most len - 1 bytes. */
static void safe(const char *s, char *out, size_t len)
{
    size_t k = 0;
    const unsigned char *p = (const unsigned char *)(s ? s : "");
    while (*p && k + 1 < len) {
        int n = *p < 0x80 ? 1 : (*p & 0xe0) == 0xc0 && *p >= 0xc2 ? 2 : (*p & 0xf0) == 0xe0 ? 3
              : (*p & 0xf8) == 0xf0 && *p <= 0xf4 ? 4 : 0;
        int whole = n > 0 && k + (size_t)n < len;
        for (int j = 1; whole && j < n; j++)
            whole = (p[j] & 0xc0) == 0x80;
        if (!whole || (n == 1 && (*p < 0x20 || *p == 0x7f))) {
            out[k++] = '?';
            p++;
            continue;
        }
        memcpy(out + k, p, (size_t)n);
        k += (size_t)n;
        p += n;
    }
    out[k] = '\0';
}

static void utc(int64_t utime, char *buf, size_t len)
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (utime <= 0 || !gmtime_r(&t, &tm) || strftime(buf, len, "%Y-%m-%dT%H:%M:%SZ", &tm) == 0)
        snprintf(buf, len, "-");
}

static int status_index(const char *s)
{
    for (int i = 0; i < N_STATUS - 1; i++)
        if (strcmp(s, status_names[i]) == 0)
            return i;
    return N_STATUS - 1;
}

/* "18.24 t" or "-" */
static void tonnes(double kg, char *buf, size_t len)
{
    if (isfinite(kg))
        snprintf(buf, len, "%.2f t", kg / 1000.0);
    else
        snprintf(buf, len, "-");
}
static void kmh(double mps, char *buf, size_t len)
{
    if (isfinite(mps) && mps > 0)
        snprintf(buf, len, "%.1f km/h", mps * 3.6);
    else
        snprintf(buf, len, "-");
}

static void print_row(FILE *f, const struct row *r)
{
    char t[32], sp[32], w[32];
    utc(r->utime, t, sizeof t);
    kmh(r->speed_mps, sp, sizeof sp);
    tonnes(r->gvw_kg, w, sizeof w);
    fprintf(f, "%-20s %6" PRId64 " %4d  %-7s %11s %10s  %s%s%s\n", t, r->passage_id, r->lane,
            r->cls[0] ? r->cls : "-", sp, w, r->status, r->refused[0] ? "; loads refused: " : "",
            r->refused);
}
static const char row_head[] = "time (UTC)               id lane  class         speed        GVW  status\n";

static void print_alert(FILE *f, const struct alert_row *a)
{
    char t[32];
    utc(a->utime, t, sizeof t);
    fprintf(f, "%s %-7s %-7s %-14s %s\n", t, a->raised ? "RAISED" : "cleared", a->level, a->kind,
            a->message);
}

static void print_counts(FILE *f)
{
    fprintf(f, "passages %ld:", T.passages);
    for (int i = 0; i < N_STATUS; i++)
        if (T.by_status[i] || i == 0)
            fprintf(f, " %s %ld", status_names[i], T.by_status[i]);
    if (T.loads_refused)
        fprintf(f, "; loads refused %ld", T.loads_refused);
    fputc('\n', f);
}

static void print_status(FILE *f)
{
    if (!T.have_status) {
        fprintf(f, "amfid: no status message yet\n");
        return;
    }
    char t[32];
    utc(T.last.wall_utime, t, sizeof t);
    fprintf(f, "amfid %s: %s at %s; stored %" PRId64 " (ok %" PRId64 "), queue %d, held %d, "
               "refused %" PRId64 ", dropped %" PRId64 "%s%s\n",
            T.site, T.state, t, T.last.passages_stored, T.last.passages_ok, T.last.queue_depth,
            T.last.passages_held, T.last.messages_refused, T.last.datagrams_dropped,
            T.last_error[0] ? "; last error: " : "", T.last_error);
}

static void print_refused(FILE *f)
{
    long n = T.malformed;
    for (int i = 1; i < AMFI_AUTH_NREASONS; i++)
        n += T.refused[i];
    if (!n)
        return;
    fprintf(f, "refused here: %ld (", n);
    int first = 1;
    for (int i = 1; i < AMFI_AUTH_NREASONS; i++)
        if (T.refused[i]) {
            fprintf(f, "%s%s %ld", first ? "" : ", ", amfi_auth_reason_name(i), T.refused[i]);
            first = 0;
        }
    if (T.malformed)
        fprintf(f, "%smalformed %ld", first ? "" : ", ", T.malformed);
    fprintf(f, "); last: %s\n", T.last_refusal);
}

/* The whole view: on a terminal after "clear screen, home". */
static void draw(FILE *f, int ansi)
{
    if (ansi)
        fputs("\033[H\033[2J", f);
    print_status(f);
    print_counts(f);
    print_refused(f);
    fputc('\n', f);
    fputs(row_head, f);
    int n = T.n_ring < T.rows ? T.n_ring : T.rows;
    for (int k = 0; k < n; k++) /* newest first */
        print_row(f, &T.ring[(T.head - 1 - k + MAX_ROWS) % MAX_ROWS]);
    if (T.n_alerts) {
        fprintf(f, "\nalerts (newest first):\n");
        for (int k = T.n_alerts - 1; k >= 0; k--)
            print_alert(f, &T.alerts[k]);
    }
    fflush(f);
}

/* Verify (signature, replay, skew) and strip the trailer; 0 to go on. */
static int admit(const lcm_recv_buf_t *rb, const char *ch, size_t *len)
{
    *len = rb->data_size;
    if (!T.auth) {
        *len = amfi_auth_bare_len(rb->data, rb->data_size);
        return 0;
    }
    char why[256];
    int r = amfi_auth_verify(T.auth, ch, rb->data, rb->data_size, rb->recv_utime, len, why,
                             sizeof why);
    if (r == AMFI_AUTH_OK)
        return 0;
    if (r > 0 && r < AMFI_AUTH_NREASONS)
        T.refused[r]++;
    safe(why, T.last_refusal, sizeof T.last_refusal);
    return -1;
}

static void malformed(const char *ch, const char *why)
{
    char w[160];
    safe(why, w, sizeof w);
    T.malformed++;
    snprintf(T.last_refusal, sizeof T.last_refusal, "%s: %s", ch, w);
}

static void on_passage(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)user;
    size_t len;
    if (admit(rb, ch, &len))
        return;
    amfi_passage_t m;
    char why[256];
    if (amfi_msg_decode_passage_t(rb->data, len, &m, why, sizeof why) != AMFI_MSG_OK) {
        malformed(ch, why);
        return;
    }
    struct row *r = &T.ring[T.head];
    r->utime = m.utime;
    r->passage_id = m.passage_id;
    r->lane = m.lane;
    r->speed_mps = m.speed_mps;
    r->gvw_kg = m.gvw_kg;
    safe(m.vehicle_class, r->cls, sizeof r->cls);
    safe(m.status, r->status, sizeof r->status);
    safe(m.loads_refused, r->refused, sizeof r->refused);
    T.loads_refused += r->refused[0] != '\0';
    T.head = (T.head + 1) % MAX_ROWS;
    if (T.n_ring < MAX_ROWS)
        T.n_ring++;
    T.by_status[status_index(r->status)]++;
    T.passages++;
    if (T.plain) {
        fputs("passage ", stdout);
        print_row(stdout, r);
        fflush(stdout);
    }
    amfi_passage_t_decode_cleanup(&m);
    if (T.count > 0 && T.passages >= T.count)
        stop = 1;
}

static void on_alert(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)user;
    size_t len;
    if (admit(rb, ch, &len))
        return;
    amfi_alert_t m;
    char why[256];
    if (amfi_msg_decode_alert_t(rb->data, len, &m, why, sizeof why) != AMFI_MSG_OK) {
        malformed(ch, why);
        return;
    }
    if (T.n_alerts == MAX_ALERTS) {
        memmove(&T.alerts[0], &T.alerts[1], sizeof T.alerts[0] * (MAX_ALERTS - 1));
        T.n_alerts--;
    }
    struct alert_row *a = &T.alerts[T.n_alerts++];
    a->utime = m.utime;
    a->alert_id = m.alert_id;
    a->raised = m.raised;
    safe(m.level, a->level, sizeof a->level);
    safe(m.kind, a->kind, sizeof a->kind);
    safe(m.message, a->message, sizeof a->message);
    T.alerts_seen++;
    if (T.plain) {
        fputs("alert   ", stdout);
        print_alert(stdout, a);
        fflush(stdout);
    }
    amfi_alert_t_decode_cleanup(&m);
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)user;
    size_t len;
    if (admit(rb, ch, &len))
        return;
    amfi_status_t m;
    char why[256];
    if (amfi_msg_decode_status_t(rb->data, len, &m, why, sizeof why) != AMFI_MSG_OK) {
        malformed(ch, why);
        return;
    }
    T.last = m;
    safe(m.state, T.state, sizeof T.state);
    safe(m.last_error, T.last_error, sizeof T.last_error);
    safe(m.site_id, T.site, sizeof T.site);
    T.last.state = T.last.last_error = T.last.site_id = NULL;
    /* plain lines: the first status and every change of state */
    if (T.plain && (!T.have_status || strcmp(T.state, T.last_state) != 0)) {
        T.have_status = 1;
        fputs("status  ", stdout);
        print_status(stdout);
        fflush(stdout);
    }
    T.have_status = 1;
    snprintf(T.last_state, sizeof T.last_state, "%s", T.state);
    amfi_status_t_decode_cleanup(&m);
    if (T.once)
        stop = 1;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: " PROG " [--config FILE] [--lcm-url URL] [--bus-key FILE] [--rows N]\n"
            "                [--interval S] [--count N | --once] [--plain] [--timeout S]\n"
            "\n"
            "A live view of one site from amfid's bus: the newest passages (time, lane,\n"
            "class, speed, GVW, status), the counts by status, the alerts and amfid's\n"
            "status (docs/daemon.md). Every message is verified with the site's bus key\n"
            "and checked before it is read.\n"
            "  -c, --config FILE   amfid's configuration (default " AMFID_DEFAULT_CONFIG "):\n"
            "                      daemon.lcm_url, the channels, daemon.bus.*\n"
            "  -u, --lcm-url URL   the bus, over daemon.lcm_url\n"
            "  -k, --bus-key FILE  the site's bus key, over daemon.bus.key_file and the\n"
            "                      systemd credential amfi-bus-key\n"
            "  -n, --rows N        passages shown on the screen, 1 .. %d (default 15)\n"
            "  -i, --interval S    screen refresh, s, 0.1 .. 60 (default 1)\n"
            "      --count N       plain lines until N passages were seen, then the counts\n"
            "      --once          plain: the view once, at amfid's next status message\n"
            "      --plain         plain lines (one per passage, alert, state change),\n"
            "                      as when stdout is not a terminal\n"
            "      --timeout S     with --count or --once: give up after S s (default 60;\n"
            "                      exit 1)\n"
            "  -h, --help          this help\n"
            "  -V, --version       the version\n"
            "Speeds in km/h, weights in tonnes, times UTC. Exit: 0; 1 bus or key trouble or\n"
            "a timeout; 2 bad command line or configuration.\n",
            MAX_ROWS);
}

int main(int argc, char **argv)
{
    enum { O_COUNT = 256, O_ONCE, O_PLAIN, O_TIMEOUT };
    static const struct option opts[] = {
        {"config", required_argument, NULL, 'c'},  {"lcm-url", required_argument, NULL, 'u'},
        {"bus-key", required_argument, NULL, 'k'}, {"rows", required_argument, NULL, 'n'},
        {"interval", required_argument, NULL, 'i'}, {"count", required_argument, NULL, O_COUNT},
        {"once", no_argument, NULL, O_ONCE},       {"plain", no_argument, NULL, O_PLAIN},
        {"timeout", required_argument, NULL, O_TIMEOUT}, AMFI_CLI_END};
    T.rows = 15;
    T.interval = 1;
    T.timeout = 60;
    int config_given = 0;
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, opts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'c': T.config = optarg; config_given = 1; break;
        case 'u': T.url_opt = optarg; break;
        case 'k': T.key_opt = optarg; break;
        case 'n': T.rows = (int)amfi_cli_integer(&c, optarg, 1, MAX_ROWS); break;
        case 'i': T.interval = amfi_cli_num(&c, optarg, 0.1, 60); break;
        case O_COUNT: T.count = amfi_cli_integer(&c, optarg, 1, 1e9); break;
        case O_ONCE: T.once = 1; break;
        case O_PLAIN: T.plain = 1; break;
        case O_TIMEOUT: T.timeout = amfi_cli_num(&c, optarg, 0.1, 86400); break;
        default: break;
        }
    }
    if (T.once && T.count) {
        amfi_cli_error(PROG, "--once", "give --once or --count, not both");
        return AMFI_CLI_EXIT_USAGE;
    }
    if (T.count || T.once || !isatty(STDOUT_FILENO))
        T.plain = 1;
    /* amfid's configuration: the bus, its channels and its key rules */
    static amfi_site_config cfg;
    amfi_config_defaults(&cfg);
    if (!T.config)
        T.config = AMFID_DEFAULT_CONFIG;
    if (config_given || access(T.config, R_OK) == 0) {
        char err[1024];
        if (amfi_config_load(T.config, &cfg, err, sizeof err)) {
            fprintf(stderr, PROG ": %s\n", err);
            return AMFI_CLI_EXIT_USAGE;
        }
    } else {
        T.config = "(built-in defaults)";
    }
    const amfi_daemon_config *dc = &cfg.daemon;
    const char *url = T.url_opt ? T.url_opt : dc->lcm_url[0] ? dc->lcm_url : AMFID_BUILTIN_URL;
    char kbuf[4096], kerr[4400];
    const char *origin = NULL;
    const char *kp = amfi_auth_key_path(T.key_opt, dc->bus_key_file, kbuf, sizeof kbuf, &origin);
    static amfi_auth_verifier verifier;
    if (dc->bus_auth) {
        amfi_auth_key key;
        if (!kp) {
            fprintf(stderr, PROG ": daemon.bus.auth is required (%s) but there is no bus key: give "
                            "--bus-key FILE, daemon.bus.key_file or the credential %s\n",
                    T.config, AMFI_AUTH_CREDENTIAL);
            return 1;
        }
        if (amfi_auth_key_load(kp, &key, kerr, sizeof kerr)) {
            fprintf(stderr, PROG ": %s (from the %s)\n", kerr, origin);
            return 1;
        }
        const int replay = strncmp(url, "file://", 7) == 0;
        if (amfi_auth_verifier_init(&verifier, &key, replay ? 0.0 : dc->bus_max_skew_s)) {
            fprintf(stderr, PROG ": libsodium cannot be initialised\n");
            return 1;
        }
        memset(&key, 0, sizeof key);
        T.auth = &verifier;
    } else {
        fprintf(stderr, PROG ": daemon.bus.auth is off in %s: messages are shown unverified\n",
                T.config);
    }
    lcm_t *lcm = lcm_create(url);
    if (!lcm) {
        fprintf(stderr, PROG ": cannot open the LCM bus '%s'\n", url);
        return 1;
    }
    if (!lcm_subscribe(lcm, dc->ch_passage, on_passage, NULL) ||
        !lcm_subscribe(lcm, dc->ch_alert, on_alert, NULL) ||
        !lcm_subscribe(lcm, dc->ch_status, on_status, NULL)) {
        fprintf(stderr, PROG ": cannot subscribe to %s, %s, %s\n", dc->ch_passage, dc->ch_alert,
                dc->ch_status);
        lcm_destroy(lcm);
        return 1;
    }
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    if (T.plain && !T.once)
        fprintf(stdout, "# %s on %s (%s, channels %s %s %s)\n", PROG, url,
                T.auth ? "signatures verified" : "unverified", dc->ch_passage, dc->ch_alert,
                dc->ch_status);
    fflush(stdout);
    double start = amfi_mono_s(), next_draw = start;
    int rc = 0;
    while (!stop) {
        double now = amfi_mono_s();
        if (!T.plain && now >= next_draw) {
            draw(stdout, 1);
            next_draw = now + T.interval;
        }
        if ((T.count || T.once) && now - start > T.timeout) {
            fprintf(stderr, PROG ": %s after %.0f s (%ld passages seen)\n",
                    T.once ? "no status message from amfid" : "timed out", T.timeout, T.passages);
            rc = 1;
            break;
        }
        int wait_ms = T.plain ? 200 : (int)((next_draw - now) * 1000) + 1;
        if (wait_ms > 200) wait_ms = 200;
        errno = 0;
        if (lcm_handle_timeout(lcm, wait_ms) < 0 && !stop && errno != EINTR) {
            fprintf(stderr, PROG ": the LCM bus failed\n");
            rc = 1;
            break;
        }
    }
    if (T.once && rc == 0)
        draw(stdout, 0);
    else if (T.plain) {
        print_counts(stdout);
        print_refused(stdout);
    }
    else
        draw(stdout, 1);
    lcm_destroy(lcm);
    return rc;
}
