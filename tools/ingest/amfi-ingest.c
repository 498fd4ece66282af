/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-ingest: real instruments onto the amfi bus (docs/ingest.md,
 * amfi-ingest(1)). Reads MiniSEED records (files, or a stream: a FIFO,
 * stdin, a file a logger is writing) and the line protocol (a file, TCP
 * peers on ingest.line.listen, a serial port), and publishes signed
 * accel_block_t and vehicle_t messages on the site's channels as amfid
 * expects them (sensor ids, rates and channels from the site file).
 *
 *   amfi-ingest [--config SITE] [options] FILE.mseed ... [--lines FILE]
 *       files: every record of every file, and every line, merged in the
 *       order of their data time; then exit
 *   amfi-ingest [--config SITE] [options] [--mseed-stream PATH] ...
 *       service: the streams, the TCP listener and the serial port, until
 *       SIGTERM or SIGINT
 *
 * Thread: one; everything in the loop below.
 */
#define _GNU_SOURCE /* accept4 */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "amfi_cli.h"
#include "amfi_time.h"
#include "amfi_version.h"
#include "ingest.h"

#define PROG "amfi-ingest"
#ifndef AMFID_DEFAULT_CONFIG
#define AMFID_DEFAULT_CONFIG "/etc/amfid/amfid.yaml"
#endif
#define MAX_INPUTS 64

typedef struct opts {
    const char *config, *bus_key, *lcm_url, *listen, *serial;
    int baud, unsigned_ok, check;
    double speedup; /* files: data time / wall time; 0 as fast as possible */
    const char *mseed[MAX_INPUTS];
    int n_mseed;
    const char *lines[MAX_INPUTS];
    int n_lines;
    const char *streams[MAX_INPUTS];
    int n_streams;
} opts;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: %s [--config SITE.yaml] [--bus-key FILE | --unsigned] [--lcm-url URL]\n"
            "       [--speedup X] [--lines FILE]... [FILE.mseed ...]\n"
            "   or: %s [--config SITE.yaml] ... [--mseed-stream PATH]... [--listen ADDR:PORT|none]\n"
            "       [--serial DEV|none] [--baud N]\n"
            "\n"
            "Real instruments onto the amfi bus: MiniSEED records and the line protocol\n"
            "(docs/ingest.md) published as signed accel_block_t and vehicle_t messages.\n"
            "With files (MiniSEED operands, --lines): everything merged in data-time order,\n"
            "then exit. Without: a service reading the streams, the TCP listener\n"
            "(ingest.line.listen) and the serial port (ingest.line.serial) until SIGTERM.\n"
            "  -c, --config FILE        the site file (default " AMFID_DEFAULT_CONFIG "):\n"
            "                           sensors, daemon.channels, daemon.bus, ingest\n"
            "  -k, --bus-key FILE       the site's bus key (else daemon.bus.key_file, else\n"
            "                           the credential amfi-bus-key)\n"
            "      --unsigned           publish unsigned (a lab bus, daemon.bus.auth: off)\n"
            "  -u, --lcm-url URL        the bus (default: LCM's default URL)\n"
            "  -l, --lines FILE         line protocol records from FILE (- stdin)\n"
            "      --speedup X          files: data time / wall time (default 0: no pacing)\n"
            "  -m, --mseed-stream PATH  MiniSEED records from a FIFO, - (stdin) or a file\n"
            "                           being written (followed as it grows)\n"
            "      --listen ADDR:PORT   the TCP listener (none: off; default ingest.line.listen)\n"
            "      --serial DEV         the serial port (none: off; default ingest.line.serial)\n"
            "      --baud N             its speed (default ingest.line.baud)\n"
            "  -C, --check-config       check the site file and the key, print the mapping\n"
            "  -h, --help               this help\n"
            "  -V, --version            print the version\n"
            "Exit status: 0 done (files) or stopped by a signal (service); 1 a setup\n"
            "failure (configuration, key, bus, input); 2 a bad command line. Bad records\n"
            "and lines are counted and named on stderr, never fatal.\n",
            PROG, PROG);
}

enum { O_UNSIGNED = 256, O_SPEEDUP, O_LISTEN, O_SERIAL, O_BAUD };

static const struct option longopts[] = {
    {"config", required_argument, NULL, 'c'},
    {"bus-key", required_argument, NULL, 'k'},
    {"unsigned", no_argument, NULL, O_UNSIGNED},
    {"lcm-url", required_argument, NULL, 'u'},
    {"lines", required_argument, NULL, 'l'},
    {"speedup", required_argument, NULL, O_SPEEDUP},
    {"mseed-stream", required_argument, NULL, 'm'},
    {"listen", required_argument, NULL, O_LISTEN},
    {"serial", required_argument, NULL, O_SERIAL},
    {"baud", required_argument, NULL, O_BAUD},
    {"check-config", no_argument, NULL, 'C'},
    AMFI_CLI_END};

static void parse(opts *o, int argc, char **argv)
{
    memset(o, 0, sizeof *o);
    o->config = AMFID_DEFAULT_CONFIG;
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    amfi_cli_allow_operands(&c);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'c': o->config = optarg; break;
        case 'k': o->bus_key = optarg; break;
        case O_UNSIGNED: o->unsigned_ok = 1; break;
        case 'u': o->lcm_url = optarg; break;
        case 'l':
            if (o->n_lines == MAX_INPUTS)
                amfi_cli_fail(&c, "at most %d", MAX_INPUTS);
            o->lines[o->n_lines++] = optarg;
            break;
        case O_SPEEDUP: o->speedup = amfi_cli_num(&c, optarg, 0, 1e6); break;
        case 'm':
            if (o->n_streams == MAX_INPUTS)
                amfi_cli_fail(&c, "at most %d", MAX_INPUTS);
            o->streams[o->n_streams++] = optarg;
            break;
        case O_LISTEN: o->listen = optarg; break;
        case O_SERIAL: o->serial = optarg; break;
        case O_BAUD: o->baud = (int)amfi_cli_integer(&c, optarg, 1, 4000000); break;
        case 'C': o->check = 1; break;
        default: amfi_cli_fail(&c, "unhandled option");
        }
    }
    for (int i = optind; i < argc; i++) {
        if (o->n_mseed == MAX_INPUTS) {
            amfi_cli_error(PROG, NULL, "at most %d MiniSEED files", MAX_INPUTS);
            exit(AMFI_CLI_EXIT_USAGE);
        }
        o->mseed[o->n_mseed++] = argv[i];
    }
    if ((o->n_mseed || o->n_lines) && o->n_streams) {
        amfi_cli_error(PROG, "--mseed-stream", "is the service mode; files are read alone");
        exit(AMFI_CLI_EXIT_USAGE);
    }
    if (o->unsigned_ok && o->bus_key) {
        amfi_cli_error(PROG, "--unsigned", "and --bus-key exclude each other");
        exit(AMFI_CLI_EXIT_USAGE);
    }
}

static volatile sig_atomic_t stop, want_summary;
static void on_signal(int sig)
{
    if (sig == SIGUSR1)
        want_summary = 1;
    else
        stop = 1;
}

/* ---- files: merged by data time ---------------------------------------- */

typedef struct lfile {
    FILE *f;
    line_src src;
    char *line; /* the next timed line, NULL at the end */
    size_t cap;
    double t_us;
} lfile;

/* The next line with a data time; lines without one are handled (counted
 * as bad, or skipped as comments) on the way. */
static void lfile_advance(ingest *g, lfile *l)
{
    for (;;) {
        ssize_t n = getline(&l->line, &l->cap, l->f);
        if (n < 0) {
            free(l->line);
            l->line = NULL;
            return;
        }
        if (n > 0 && l->line[n - 1] == '\n')
            l->line[--n] = '\0';
        l->t_us = line_time_us(l->line, g->cfg->ingest.line_offset_s);
        if (l->t_us != 0.0 && !memchr(l->line, '\0', (size_t)n) && n <= INGEST_MAX_LINE)
            return;
        line_feed(g, &l->src, l->line, (size_t)n); /* named and counted there */
        line_feed(g, &l->src, "\n", 1);
    }
}

static void prime(mseed_src *m, ingest *g)
{
    while (!mseed_next(m, g))
        if (mseed_fill(m) < 0 && !mseed_next(m, g))
            return;
}

static void pace(const opts *o, double t_us, double *t0_us, double w0)
{
    if (o->speedup <= 0)
        return;
    if (*t0_us == 0.0)
        *t0_us = t_us;
    const double due = w0 + 1e-6 * (t_us - *t0_us) / o->speedup - amfi_mono_s();
    if (due > 0) {
        struct timespec ts = {(time_t)due, (long)((due - floor(due)) * 1e9)};
        nanosleep(&ts, NULL);
    }
}

static int run_files(const opts *o, ingest *g)
{
    mseed_src *ms = calloc((size_t)o->n_mseed + 1, sizeof *ms);
    lfile *lf = calloc((size_t)o->n_lines + 1, sizeof *lf);
    char err[700];
    int rc = 1;
    if (!ms || !lf)
        goto out;
    for (int i = 0; i < o->n_mseed; i++) {
        if (mseed_open(&ms[i], o->mseed[i], 0, err, sizeof err)) {
            fprintf(stderr, "%s: %s\n", PROG, err);
            for (int j = 0; j < i; j++)
                mseed_close(&ms[j]);
            goto out;
        }
    }
    for (int i = 0; i < o->n_lines; i++) {
        lf[i].f = strcmp(o->lines[i], "-") ? fopen(o->lines[i], "r") : stdin;
        snprintf(lf[i].src.name, sizeof lf[i].src.name, "%s",
                 strcmp(o->lines[i], "-") ? o->lines[i] : "stdin");
        if (!lf[i].f) {
            fprintf(stderr, "%s: %s: %s\n", PROG, o->lines[i], strerror(errno));
            for (int j = 0; j < o->n_mseed; j++)
                mseed_close(&ms[j]);
            for (int j = 0; j < i; j++)
                if (lf[j].f != stdin)
                    fclose(lf[j].f);
            goto out;
        }
    }
    for (int i = 0; i < o->n_mseed; i++)
        prime(&ms[i], g);
    for (int i = 0; i < o->n_lines; i++)
        lfile_advance(g, &lf[i]);
    const double w0 = amfi_mono_s();
    double t0 = 0.0;
    while (!stop) {
        int best = -1, is_line = 0;
        double bt = 0.0;
        for (int i = 0; i < o->n_mseed; i++)
            if (ms[i].msr && (best < 0 || ms[i].start_us < bt)) {
                best = i;
                bt = ms[i].start_us;
            }
        for (int i = 0; i < o->n_lines; i++)
            if (lf[i].line && (best < 0 || lf[i].t_us < bt)) {
                best = i;
                is_line = 1;
                bt = lf[i].t_us;
            }
        if (best < 0)
            break;
        pace(o, bt, &t0, w0);
        if (is_line) {
            line_feed(g, &lf[best].src, lf[best].line, strlen(lf[best].line));
            line_feed(g, &lf[best].src, "\n", 1);
            lfile_advance(g, &lf[best]);
        } else {
            mseed_publish(&ms[best], g);
            prime(&ms[best], g);
        }
    }
    ingest_flush(g, 0);
    for (int i = 0; i < o->n_mseed; i++)
        mseed_close(&ms[i]);
    for (int i = 0; i < o->n_lines; i++) {
        line_finish(g, &lf[i].src);
        free(lf[i].line);
        if (lf[i].f != stdin)
            fclose(lf[i].f);
    }
    rc = 0;
out:
    free(ms);
    free(lf);
    return rc;
}

/* ---- service: streams, TCP peers, the serial port ---------------------- */

typedef struct peer {
    int fd;
    line_src src;
} peer;

static int listen_on(const char *addr, char *err, size_t errlen)
{
    char host[64];
    int port;
    if (amfi_config_ingest_listen_parse(addr, host, &port)) {
        snprintf(err, errlen, "listen address '%s' is not IPV4-ADDRESS:PORT", addr);
        return -1;
    }
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, host, &sa.sin_addr);
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    int one = 1;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) ||
        bind(fd, (struct sockaddr *)&sa, sizeof sa) || listen(fd, 8)) {
        snprintf(err, errlen, "cannot listen on %s: %s", addr, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    return fd;
}

static int run_service(const opts *o, ingest *g)
{
    const amfi_ingest_config *ic = &g->cfg->ingest;
    const char *listen_addr = o->listen ? o->listen : ic->listen;
    const char *serial = o->serial ? o->serial : ic->serial;
    const int baud = o->baud ? o->baud : ic->baud;
    if (!strcmp(listen_addr, "none"))
        listen_addr = "";
    if (!strcmp(serial, "none"))
        serial = "";
    char err[700];
    int lfd = -1, sfd = -1, rc = 1, n_peers = 0;
    peer *peers = calloc((size_t)ic->max_clients, sizeof *peers);
    mseed_src *ms = calloc((size_t)o->n_streams + 1, sizeof *ms);
    line_src sline = {.fd = -1};
    if (!peers || !ms)
        goto out;
    int n_ms = 0;
    for (; n_ms < o->n_streams; n_ms++)
        if (mseed_open(&ms[n_ms], o->streams[n_ms], 1, err, sizeof err)) {
            fprintf(stderr, "%s: %s\n", PROG, err);
            goto out;
        }
    if (listen_addr[0] && (lfd = listen_on(listen_addr, err, sizeof err)) < 0) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        goto out;
    }
    if (serial[0]) {
        if ((sfd = serial_open(serial, baud, err, sizeof err)) < 0) {
            fprintf(stderr, "%s: %s\n", PROG, err);
            goto out;
        }
        snprintf(sline.name, sizeof sline.name, "%s", serial);
    }
    if (lfd < 0 && sfd < 0 && n_ms == 0) {
        fprintf(stderr, "%s: nothing to read: no files, no --mseed-stream, no listener "
                "(ingest.line.listen) and no serial port (ingest.line.serial)\n", PROG);
        goto out;
    }
    fprintf(stderr, "%s: running: %d MiniSEED stream%s%s%s%s%s%s\n", PROG, n_ms,
            n_ms == 1 ? "" : "s", lfd >= 0 ? ", line protocol on tcp " : "",
            lfd >= 0 ? listen_addr : "", sfd >= 0 ? ", line protocol on " : "",
            sfd >= 0 ? serial : "", g->signer ? "" : " (UNSIGNED)");
    int open_streams = n_ms;
    while (!stop) {
        struct pollfd pf[2 + 64 + MAX_INPUTS];
        int np = 0, i_l = -1, i_s = -1, i_p = -1, i_m = -1;
        if (lfd >= 0) {
            i_l = np;
            pf[np++] = (struct pollfd){lfd, POLLIN, 0};
        }
        if (sfd >= 0) {
            i_s = np;
            pf[np++] = (struct pollfd){sfd, POLLIN, 0};
        }
        i_p = np;
        for (int i = 0; i < n_peers; i++)
            pf[np++] = (struct pollfd){peers[i].fd, POLLIN, 0};
        i_m = np;
        for (int i = 0; i < n_ms; i++) /* a followed regular file is read each turn */
            pf[np++] = (struct pollfd){ms[i].eof || ms[i].follow ? -1 : ms[i].fd, POLLIN, 0};
        int r = poll(pf, (nfds_t)np, 200);
        if (r < 0 && errno != EINTR) {
            fprintf(stderr, "%s: poll: %s\n", PROG, strerror(errno));
            break;
        }
        if (want_summary) {
            want_summary = 0;
            ingest_summary(g, stderr);
        }
        char buf[65536];
        if (i_l >= 0 && (pf[i_l].revents & POLLIN)) {
            struct sockaddr_in sa;
            socklen_t sl = sizeof sa;
            int cfd = accept4(lfd, (struct sockaddr *)&sa, &sl, SOCK_NONBLOCK | SOCK_CLOEXEC);
            if (cfd >= 0 && n_peers == ic->max_clients) {
                fprintf(stderr, "%s: tcp: a connection refused: %d peers connected "
                        "(ingest.line.max_clients)\n", PROG, n_peers);
                close(cfd);
            } else if (cfd >= 0) {
                char a[INET_ADDRSTRLEN] = "?";
                inet_ntop(AF_INET, &sa.sin_addr, a, sizeof a);
                peers[n_peers] = (peer){.fd = cfd};
                snprintf(peers[n_peers].src.name, sizeof peers[n_peers].src.name, "%s:%u", a,
                         (unsigned)ntohs(sa.sin_port));
                fprintf(stderr, "%s: tcp: %s connected\n", PROG, peers[n_peers].src.name);
                n_peers++;
            }
        }
        if (i_s >= 0 && (pf[i_s].revents & (POLLIN | POLLHUP | POLLERR))) {
            ssize_t n = read(sfd, buf, sizeof buf);
            if (n > 0)
                line_feed(g, &sline, buf, (size_t)n);
            else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
                fprintf(stderr, "%s: %s: %s; closed\n", PROG, serial,
                        n == 0 ? "end of input" : strerror(errno));
                line_finish(g, &sline);
                close(sfd);
                sfd = -1;
            }
        }
        for (int i = n_peers - 1; i >= 0; i--) {
            if (!(pf[i_p + i].revents & (POLLIN | POLLHUP | POLLERR)))
                continue;
            ssize_t n = read(peers[i].fd, buf, sizeof buf);
            if (n > 0) {
                line_feed(g, &peers[i].src, buf, (size_t)n);
            } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
                line_finish(g, &peers[i].src);
                fprintf(stderr, "%s: tcp: %s disconnected after %lld lines\n", PROG,
                        peers[i].src.name, peers[i].src.lineno);
                close(peers[i].fd);
                peers[i] = peers[--n_peers];
            }
        }
        for (int i = 0; i < n_ms; i++) {
            if (ms[i].eof)
                continue;
            if (ms[i].follow || (pf[i_m + i].revents & (POLLIN | POLLHUP | POLLERR))) {
                int f;
                while ((f = mseed_fill(&ms[i])) > 0)
                    while (mseed_next(&ms[i], g))
                        mseed_publish(&ms[i], g);
                while (mseed_next(&ms[i], g))
                    mseed_publish(&ms[i], g);
                if (ms[i].eof) {
                    fprintf(stderr, "%s: %s: end of the stream after %lld records\n", PROG,
                            ms[i].name, ms[i].recno);
                    open_streams--;
                }
            }
        }
        ingest_flush(g, 1.0); /* a partial block waits at most a second of silence */
        if (open_streams == 0 && lfd < 0 && sfd < 0) {
            fprintf(stderr, "%s: every input ended\n", PROG);
            break; /* the streams and the serial line were everything, and they ended */
        }
    }
    ingest_flush(g, 0);
    rc = 0;
out:
    for (int i = 0; i < n_peers; i++) {
        line_finish(g, &peers[i].src);
        close(peers[i].fd);
    }
    for (int i = 0; i < o->n_streams && ms; i++)
        if (ms[i].buf || ms[i].fd > 0)
            mseed_close(&ms[i]);
    if (lfd >= 0)
        close(lfd);
    if (sfd >= 0) {
        line_finish(g, &sline);
        close(sfd);
    }
    free(peers);
    free(ms);
    return rc;
}

/* ---- main ---------------------------------------------------------------- */

int main(int argc, char **argv)
{
    opts o;
    parse(&o, argc, argv);
    static amfi_site_config cfg;
    char err[4400];
    if (amfi_config_load(o.config, &cfg, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        return 1;
    }
    const amfi_ingest_config *ic = &cfg.ingest;
    amfi_auth_signer signer;
    int have_signer = 0;
    if (!o.unsigned_ok) {
        char kbuf[4096];
        const char *origin = NULL;
        const char *kp = amfi_auth_key_path(o.bus_key, cfg.daemon.bus_key_file, kbuf, sizeof kbuf,
                                            &origin);
        amfi_auth_key key;
        if (!kp) {
            fprintf(stderr, "%s: no bus key (--bus-key, daemon.bus.key_file, credential %s); "
                    "--unsigned publishes without one (a lab bus, daemon.bus.auth: off)\n",
                    PROG, AMFI_AUTH_CREDENTIAL);
            return 1;
        }
        if (amfi_auth_key_load(kp, &key, err, sizeof err)) {
            fprintf(stderr, "%s: %s (from the %s)\n", PROG, err, origin);
            return 1;
        }
        if (amfi_auth_signer_init(&signer, &key, ic->producer, err, sizeof err)) {
            fprintf(stderr, "%s: bus key: %s\n", PROG, err);
            return 1;
        }
        memset(&key, 0, sizeof key);
        have_signer = 1;
    }
    if (o.check) {
        printf("%s: %s: ok: %d channel%s, producer %s, blocks of %d samples, max_jump_s %g%s\n",
               PROG, o.config, ic->n_channels, ic->n_channels == 1 ? "" : "s", ic->producer,
               ic->block, ic->max_jump_s, have_signer ? ", bus key ok" : ", unsigned");
        for (int i = 0; i < ic->n_channels; i++) {
            int idx = -1;
            for (int s = 0; s < cfg.solver.n_sensors; s++)
                if (cfg.sensor_id[s] == ic->ch[i].sensor_id)
                    idx = s;
            printf("  %s -> sensor %d (%g Hz), gain %g m/s² per count, offset %g s\n",
                   ic->ch[i].seed, ic->ch[i].sensor_id, idx >= 0 ? cfg.sensor_rate_hz[idx] : 0.0,
                   ic->ch[i].gain, ic->ch[i].offset_s);
        }
        if (have_signer)
            amfi_auth_signer_free(&signer);
        return 0;
    }
    if (o.n_mseed && ic->n_channels == 0)
        fprintf(stderr, "%s: %s: no ingest.channels: every MiniSEED record will be "
                "counted as an unmapped channel\n", PROG, o.config);
    lcm_t *lcm = lcm_create(o.lcm_url);
    if (!lcm) {
        fprintf(stderr, "%s: cannot open the LCM bus '%s'\n", PROG,
                o.lcm_url ? o.lcm_url : "(default)");
        if (have_signer)
            amfi_auth_signer_free(&signer);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGUSR1, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    ingest g;
    ingest_init(&g, &cfg, lcm, have_signer ? &signer : NULL);
    const int files = o.n_mseed || o.n_lines;
    g.live = !files;
    int rc = files ? run_files(&o, &g) : run_service(&o, &g);
    ingest_summary(&g, stderr);
    ingest_free(&g);
    lcm_destroy(lcm);
    if (have_signer)
        amfi_auth_signer_free(&signer);
    return rc;
}
