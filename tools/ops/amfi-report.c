/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-report: what amfid's store holds, for people.
 *
 *   amfi-report --db PATH [--summary] [--trend] [--alerts] [--errors]
 *               [--passages] [--histogram] [--overloads] [--speed]
 *               [--from T] [--to T] [--status S] [--lane N] [--bin-kg W]
 *               [--format table|csv|json] [--config FILE] [--plot DIR]
 *               [--set-baseline-last N | --set-baseline MEAN_KG,STD_KG,N]
 *               [--note TEXT] [--check]
 *
 * Prints the passage summary (counts by status, GVW statistics of the ok
 * passages, time span, baseline in force), the indicator trend (the last
 * indicators as a compact table), the alerts, and the errors of the
 * inferred GVW against the truth (simulations); sets a manual baseline from
 * the last N ok passages or from explicit values; checks the file's
 * integrity; lists passages (filtered by time, status, lane), the GVW
 * histogram per lane and the overloads against legal limits (report_export.c);
 * shows the speed corrections of the passages whose speed amfid estimated
 * (report_speed.c).
 * Every section prints as a table, CSV (one section at a time) or one JSON
 * document. With no option: summary, trend and alerts, and the speed
 * corrections when the store holds estimated speeds. The table format ends
 * with the sqlite3 queries one would type next. Schema: docs/schema.md.
 *
 * The database is opened read-only (amfid may be writing it: WAL readers
 * never block the writer); only --set-baseline* opens it read-write, for
 * one INSERT. The file must exist and be an amfi store of this version:
 * amfi-report never creates or migrates one.
 *
 * Exit status: 0 ok; 1 the database cannot be read, a row is damaged, or
 * --check found a problem; 2 bad command line. Every error is one line on
 * stderr: "amfi-report: PATH: problem" or "amfi-report: --option: problem".
 *
 * Workload: one run reads the ok GVWs once (8 bytes each: a million
 * passages take 8 MB and well under a second) plus a few indexed queries.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_json.h"
#include "report_export.h"
#include "report_pg.h"
#include "report_plot.h"
#include "report_natfreq.h"
#include "report_scale.h"
#include "report_speed.h"
#include "store.h"

#define PROG "amfi-report"
#define EXIT_DATA 1
#define EXIT_USAGE 2
#define TREND_ROWS 20  /* indicators shown by --trend */
#define ALERT_ROWS 20  /* alerts shown by --alerts */
#define MAX_BASELINE_N 10000000

typedef struct options {
    const char *db;
    const char *pg;         /* --pg CONNINFO: the central database, NULL: none */
    const char *site;       /* --site ID (with --pg) */
    int allow_plaintext;    /* --allow-plaintext: no TLS to a remote --pg server */
    int summary, trend, alerts, errors, check;
    int baseline_last;   /* N of --set-baseline-last, 0: not given */
    int baseline_given;  /* --set-baseline MEAN,STD,N given */
    double mean_kg, std_kg;
    int n;
    const char *note;    /* NULL: empty */
    const char *plot_dir;   /* --plot DIR, NULL: none */
    const char *config;     /* --config FILE, NULL: none */
    int passages, histogram, overloads;
    int speed;              /* --speed; 2: by default, when the store has estimated speeds */
    int format;             /* FMT_* */
    export_opts ex;         /* --from --to --status --lane --bin-kg, limits */
    int bin_given;
} options;

static const char *g_db = "?"; /* for messages */
static FILE *g_out;             /* where a section is rendered */

static void out(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

static void out(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfprintf(g_out, fmt, ap);
    va_end(ap);
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: " PROG " --db PATH | --pg CONNINFO [--site ID] [--summary] [--trend] [--alerts] "
            "[--errors]\n"
            "       [--set-baseline-last N | --set-baseline MEAN_KG,STD_KG,N] "
            "[--note TEXT] [--check]\n"
            "       [--passages] [--histogram] [--overloads] [--from T] [--to T] "
            "[--status S]\n"
            "       [--speed] [--lane N] [--bin-kg W] [--format table|csv|json] [--plot DIR] "
            "[--config FILE]\n"
            "\n"
            "Reports on amfid's SQLite store (schema: docs/schema.md).\n"
            "  -d, --db PATH                the store (must exist)\n"
            "      --pg CONNINFO            the central PostgreSQL instead (docs/fleet.md): "
            "the fleet\n"
            "                               summary, or with --site the report of one "
            "site\n"
            "      --site ID                the site, with --pg\n"
            "      --allow-plaintext        with --pg: no TLS to a server not on this machine\n"
            "  -s, --summary                passages by status, GVW of the ok "
            "ones, time span, baseline\n"
            "  -t, --trend                  the last %d indicators\n"
            "  -a, --alerts                 the last %d alerts and those open "
            "now\n"
            "  -e, --errors                 inferred GVW against the truth "
            "(simulations)\n"
            "  -B, --set-baseline-last N    baseline (source manual) from the "
            "last N ok passages, N >= 2\n"
            "  -b, --set-baseline M,S,N     baseline mean M kg, STD S kg, from "
            "N passages\n"
            "  -n, --note TEXT              note stored with the baseline "
            "(<= 127 bytes)\n"
            "  -k, --check                  PRAGMA integrity_check and "
            "foreign_key_check\n"
            "  -P, --passages               one line per passage: time, lane, speed, "
            "axles, GVW,\n"
            "                               axle loads, status, reason\n"
            "  -H, --histogram              GVW histogram of the ok passages per lane\n"
            "  -O, --overloads              ok passages over the legal GVW or axle "
            "limit (--config)\n"
            "  -C, --speed                  speed corrections of the estimated passages "
            "(speed used /\n"
            "                               detector's - 1): distribution, one line per "
            "day\n"
            "  -f, --from T, -T, --to T     only passages in [T, T]: YYYY-MM-DD or "
            "YYYY-MM-DDTHH:MM[:SS], UTC\n"
            "  -S, --status S               only passages of status S (--passages)\n"
            "  -l, --lane N                 only lane N (--passages, --histogram, "
            "--overloads, --speed)\n"
            "  -w, --bin-kg W               histogram bin width, kg (default "
            "report.histogram_bin_kg)\n"
            "  -F, --format F               table (default), csv (one section) or "
            "json (one document)\n"
            "  -p, --plot DIR               draw PNGs into DIR (gnuplot): GVW, "
            "trend, histogram, per hour, speed\n"
            "  -c, --config FILE            the site's amfid.yaml: alert "
            "thresholds, site name, legal limits\n"
            "  -h, --help                   this help\n"
            "  -V, --version                print the version\n"
            "With no option: --summary --trend --alerts (and --speed when the store "
            "has estimated speeds).\n"
            "Exit status: 0 ok, 1 database error or check failed, 2 usage "
            "error.\n",
            TREND_ROWS, ALERT_ROWS);
}

/* "amfi-report: OPT: problem" on stderr; returns −1 */
#define usage_error(opt, ...) (amfi_cli_error(PROG, opt, __VA_ARGS__), -1)

static int data_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* "amfi-report: PATH: problem" on stderr; returns −1 */
static int data_error(const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, PROG ": %s: ", g_db);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    return -1;
}

static int parse_int(const char *s, long lo, long hi, int *v)
{
    char *end = NULL;
    long x = strtol(s, &end, 10);
    if (end == s || *end != '\0' || x < lo || x > hi)
        return -1;
    *v = (int)x;
    return 0;
}

/* "MEAN_KG,STD_KG,N" */
static int parse_baseline(const char *arg, options *o)
{
    const char *opt = "--set-baseline";
    char buf[96], *f[3], *save = NULL;
    int k = 0;
    if (strlen(arg) >= sizeof buf)
        return usage_error(opt, "'%s' is too long", amfi_cli_shown(arg));
    snprintf(buf, sizeof buf, "%s", arg);
    for (char *p = buf;; p = NULL) {
        char *t = strtok_r(p, ",", &save);
        if (!t)
            break;
        if (k == 3)
            return usage_error(opt, "'%s': expected MEAN_KG,STD_KG,N",
                               amfi_cli_shown(arg));
        f[k++] = t;
    }
    if (k != 3)
        return usage_error(opt, "'%s': expected MEAN_KG,STD_KG,N", amfi_cli_shown(arg));
    if (amfi_cli_double(f[0], &o->mean_kg) != 0 || !(o->mean_kg > 0)
        || o->mean_kg > AMFI_STORE_MAX_KG)
        return usage_error(opt, "mean '%s' is not a mass in (0, %g] kg",
                           amfi_cli_shown(f[0]), AMFI_STORE_MAX_KG);
    if (amfi_cli_double(f[1], &o->std_kg) != 0 || !(o->std_kg > 0)
        || o->std_kg > AMFI_STORE_MAX_KG)
        return usage_error(opt, "STD '%s' is not in (0, %g] kg", amfi_cli_shown(f[1]),
                           AMFI_STORE_MAX_KG);
    if (parse_int(f[2], 2, MAX_BASELINE_N, &o->n) != 0)
        return usage_error(opt, "N '%s' is not an integer in [2, %d]",
                           amfi_cli_shown(f[2]), MAX_BASELINE_N);
    o->baseline_given = 1;
    return 0;
}

static int parse_args(int argc, char **argv, options *o)
{
    static const struct option longopts[] = {
        {"db", required_argument, NULL, 'd'},
        {"summary", no_argument, NULL, 's'},
        {"trend", no_argument, NULL, 't'},
        {"alerts", no_argument, NULL, 'a'},
        {"errors", no_argument, NULL, 'e'},
        {"set-baseline-last", required_argument, NULL, 'B'},
        {"set-baseline", required_argument, NULL, 'b'},
        {"note", required_argument, NULL, 'n'},
        {"check", no_argument, NULL, 'k'},
        {"plot", required_argument, NULL, 'p'},
        {"config", required_argument, NULL, 'c'},
        {"passages", no_argument, NULL, 'P'},
        {"histogram", no_argument, NULL, 'H'},
        {"overloads", no_argument, NULL, 'O'},
        {"speed", no_argument, NULL, 'C'},
        {"from", required_argument, NULL, 'f'},
        {"to", required_argument, NULL, 'T'},
        {"status", required_argument, NULL, 'S'},
        {"lane", required_argument, NULL, 'l'},
        {"bin-kg", required_argument, NULL, 'w'},
        {"format", required_argument, NULL, 'F'},
        {"pg", required_argument, NULL, 'G'},
        {"site", required_argument, NULL, 'I'},
        {"allow-plaintext", no_argument, NULL, 'X'},
        AMFI_CLI_END};
    memset(o, 0, sizeof *o);
    o->ex.from = 0;
    o->ex.to = AMFI_STORE_MAX_UTIME;
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *opt = c.opt, *val = optarg;
        switch (k) {
        case 's': o->summary = 1; break;
        case 't': o->trend = 1; break;
        case 'a': o->alerts = 1; break;
        case 'e': o->errors = 1; break;
        case 'k': o->check = 1; break;
        case 'd':
            if (!*val)
                return usage_error(opt, "empty value");
            o->db = val;
            break;
        case 'p':
        case 'c':
            if (!*val)
                return usage_error(opt, "empty value");
            *(k == 'p' ? &o->plot_dir : &o->config) = val;
            break;
        case 'G':
        case 'I':
            if (!*val)
                return usage_error(opt, "empty value");
            *(k == 'G' ? &o->pg : &o->site) = val;
            if (k == 'I' && !amfi_config_site_id_valid(val))
                return usage_error(opt, "'%s' is not a site id (1 to 63 of A-Z a-z 0-9 _ . -)",
                                   amfi_cli_shown(val));
            break;
        case 'X': o->allow_plaintext = 1; break;
        case 'P': o->passages = 1; break;
        case 'H': o->histogram = 1; break;
        case 'O': o->overloads = 1; break;
        case 'C': o->speed = 1; break;
        case 'f':
        case 'T':
            {
                char why[128];
                if (export_parse_time(val, k == 'T', k == 'f' ? &o->ex.from : &o->ex.to,
                                      why, sizeof why) != 0)
                    return usage_error(opt, "'%s' is not a UTC time (%s): use YYYY-MM-DD, "
                                       "YYYY-MM-DDTHH:MM[:SS[.ffffff]][Z]",
                                       amfi_cli_shown(val), why);
            }
            break;
        case 'S': {
            int found = 0;
            for (int i = 0; i < AMFI_STORE_N_STATUS; i++)
                if (strcmp(val, amfi_store_status_name(i)) == 0) {
                    o->ex.status = amfi_store_status_name(i);
                    found = 1;
                }
            if (!found)
                return usage_error(opt, "'%s' is not a status (%s)", amfi_cli_shown(val),
                                   AMFI_STORE_STATUSES);
            break;
        }
        case 'l':
            if (parse_int(val, -32768, 32767, &o->ex.lane) != 0)
                return usage_error(opt, "'%s' is not a lane number in [-32768, 32767]",
                                   amfi_cli_shown(val));
            o->ex.lane_given = 1;
            break;
        case 'w': {
            char *end = NULL;
            double w = strtod(val, &end);
            if (!*val || *end || !(w >= 100 && w <= 1e5))
                return usage_error(opt, "'%s' is not a bin width in [100, 100000] kg",
                                   amfi_cli_shown(val));
            o->ex.bin_kg = w;
            o->bin_given = 1;
            break;
        }
        case 'F':
            if (strcmp(val, "table") == 0)
                o->format = FMT_TABLE;
            else if (strcmp(val, "csv") == 0)
                o->format = FMT_CSV;
            else if (strcmp(val, "json") == 0)
                o->format = FMT_JSON;
            else
                return usage_error(opt, "'%s' is not table, csv or json", amfi_cli_shown(val));
            break;
        case 'B':
            if (parse_int(val, 2, MAX_BASELINE_N, &o->baseline_last) != 0)
                return usage_error(opt, "'%s' is not an integer in [2, %d]",
                                   amfi_cli_shown(val), MAX_BASELINE_N);
            break;
        case 'b':
            if (parse_baseline(val, o) != 0)
                return -1;
            break;
        case 'n':
            if (strlen(val) > 127)
                return usage_error(opt, "%zu bytes, at most 127", strlen(val));
            o->note = val;
            break;
        }
    }
    if (o->db && o->pg)
        return usage_error("--pg", "give --db or --pg, not both");
    if (!o->db && !o->pg)
        return usage_error("--db", "missing (see --help)");
    if (o->site && !o->pg)
        return usage_error("--site", "only with --pg");
    if (o->allow_plaintext && !o->pg)
        return usage_error("--allow-plaintext", "only with --pg");
    if (o->pg && (o->baseline_last || o->baseline_given || o->check))
        return usage_error("--pg", "the central database is read only here: --set-baseline* and "
                           "--check work on a site's store (--db)");
    if (o->pg && !o->site) {
        if (o->summary || o->trend || o->alerts || o->errors || o->passages || o->histogram
            || o->overloads || o->speed || o->plot_dir || o->format != FMT_TABLE)
            return usage_error("--site", "the report sections need one site: without --site, "
                               "--pg prints the fleet summary only");
        return 0;
    }
    if (o->baseline_last && o->baseline_given)
        return usage_error("--set-baseline", "give --set-baseline-last or "
                           "--set-baseline, not both");
    if (o->note && !o->baseline_last && !o->baseline_given)
        return usage_error("--note", "only with --set-baseline-last or "
                           "--set-baseline");
    if (o->ex.from > o->ex.to)
        return usage_error("--from", "after --to");
    if (!o->summary && !o->trend && !o->alerts && !o->errors && !o->check
        && !o->plot_dir && !o->baseline_last && !o->baseline_given && !o->passages
        && !o->histogram && !o->overloads && !o->speed) {
        o->summary = o->trend = o->alerts = 1;
        o->speed = 2; /* when the store has estimated speeds (report_main) */
    }
    if (o->ex.status && !o->passages)
        return usage_error("--status", "only with --passages");
    if (o->format != FMT_TABLE) {
        int n = o->summary + o->trend + o->alerts + o->errors + o->passages + o->histogram
                + o->overloads + (o->speed == 1);
        if (o->check || o->plot_dir || o->baseline_last || o->baseline_given)
            return usage_error("--format", "csv and json are for the report sections, not "
                               "--check, --plot or --set-baseline*");
        if (o->format == FMT_CSV && n != 1)
            return usage_error("--format", "csv takes one section at a time (%d given)", n);
    }
    return 0;
}

/* µs since 1970 → "YYYY-MM-DD HH:MM:SS" (UTC). */
static const char *utc(long long utime, char buf[32])
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (!gmtime_r(&t, &tm) || strftime(buf, 32, "%Y-%m-%d %H:%M:%S", &tm) == 0)
        snprintf(buf, 32, "%lld us", utime);
    return buf;
}

static const char *duration(double s, char buf[32])
{
    if (s < 120)
        snprintf(buf, 32, "%.0f s", s);
    else if (s < 7200)
        snprintf(buf, 32, "%.1f min", s / 60);
    else if (s < 172800)
        snprintf(buf, 32, "%.1f h", s / 3600);
    else
        snprintf(buf, 32, "%.1f days", s / 86400);
    return buf;
}

/* "-" for NaN, else printf of fmt into buf. */
static const char *num(double x, const char *fmt, char buf[32])
{
    if (isnan(x))
        return "-";
    snprintf(buf, 32, fmt, x);
    return buf;
}

/* ---- sections ------------------------------------------------------------ */

static int print_baseline(amfi_store *s)
{
    amfi_baseline b;
    int found = 0;
    char err[256], t[32];
    if (amfi_store_get_baseline(s, &b, &found, err, sizeof err) != 0)
        return data_error("%s", err);
    if (!found) {
        out("baseline     none yet (amfid sets it from the first ok "
               "passages, or --set-baseline*)\n");
        return 0;
    }
    out("baseline     mean %.0f kg, STD %.0f kg, n %d, %s, from %s UTC%s%s%s\n",
           b.mean_kg, b.std_kg, b.n, b.source, utc(b.utime_set, t),
           b.note[0] ? " \"" : "", b.note, b.note[0] ? "\"" : "");
    return 0;
}

static int section_summary(amfi_store *s)
{
    amfi_passage_summary sum;
    double *g = NULL;
    size_t ng = 0;
    char a[32], b[32], c[32], err[512];
    if (amfi_store_passage_summary(s, &sum, err, sizeof err) != 0)
        return data_error("%s", err);
    out("== passages\n");
    if (sum.total == 0)
        out("time span    (no passages yet)\n");
    else
        out("time span    %s .. %s UTC (%s)\n", utc(sum.utime_first, a),
               utc(sum.utime_last, b),
               duration((double)(sum.utime_last - sum.utime_first) / 1e6, c));
    out("passages     %lld\n", (long long)sum.total);
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        out("  %-10s %8lld  %5.1f %%\n", amfi_store_status_name(k),
               (long long)sum.by_status[k],
               sum.total ? 100.0 * (double)sum.by_status[k] / (double)sum.total : 0.0);
    if (amfi_store_all_ok_gvw(s, &g, &ng, err, sizeof err) != 0)
        return data_error("%s", err);
    double mean = 0, std = 0;
    const size_t n_ok = ng;
    if (ng == 0) {
        out("GVW, ok      (no ok passages)\n");
    } else {
        report_mean_std(g, ng, &mean, &std);
        report_sort(g, ng);
        out("GVW, ok      n %zu, mean %.0f kg, STD %s kg, min %.0f, "
               "median %.0f, max %.0f kg\n",
               ng, mean, num(std, "%.0f", a), g[0],
               report_percentile(g, ng, 50), g[ng - 1]);
    }
    free(g);
    /* what the STD and mean rules were fed (at the calibration temperature
     * with daemon.indicators.temperature: compensated), when it is not the
     * raw GVW itself (no deck temperature, or raw) */
    const double raw_mean = mean, raw_std = std;
    if (amfi_store_all_fed_gvw(s, &g, &ng, err, sizeof err) != 0)
        return data_error("%s", err);
    if (ng > 0)
        report_mean_std(g, ng, &mean, &std);
    if (ng > 0 && (ng != n_ok || mean != raw_mean || !(std == raw_std || isnan(std)))) {
        report_sort(g, ng);
        out("GVW, fed     n %zu, mean %.0f kg, STD %s kg, min %.0f, median %.0f, max %.0f kg "
            "(the STD and mean rules' input: compensated to the calibration temperature)\n",
            ng, mean, num(std, "%.0f", a), g[0], report_percentile(g, ng, 50), g[ng - 1]);
    }
    free(g);
    report_intake in;
    if (export_read_intake(s, &in, err, sizeof err) != 0)
        return data_error("%s", err);
    if (in.found)
        out("bus          run %lld (as of %s): %lld messages received, %lld refused, "
            "%lld kernel drops, %lld samples missing, %lld passages not stored\n",
            in.run, in.as_of, in.received, in.refused, in.dropped, in.missing, in.lost);
    amfi_environment_summary env;
    if (amfi_store_environment_summary(s, &env, err, sizeof err) != 0)
        return data_error("%s", err);
    if (env.n > 0)
        out("temperature  deck %.1f .. %.1f °C, air %.1f .. %.1f °C, %lld readings, "
            "%s .. %s UTC\n",
            env.deck_min_c, env.deck_max_c, env.air_min_c, env.air_max_c, (long long)env.n,
            utc(env.utime_first, a), utc(env.utime_last, b));
    if (report_scale_summary(s, g_out, err, sizeof err) != 0)
        return data_error("%s", err);
    char f1line[1024];
    if (natfreq_summary(s, f1line, sizeof f1line, err, sizeof err) != 0)
        return data_error("%s", err);
    out("%s", f1line);
    return print_baseline(s);
}

static int section_trend(amfi_store *s)
{
    int64_t total = 0;
    amfi_indicator_rec rec[TREND_ROWS];
    int nl = 0;
    char err[512];
    if (amfi_store_count(s, AMFI_STORE_INDICATORS, &total, err, sizeof err) != 0)
        return data_error("%s", err);
    out("== indicators (last %lld of %lld)\n",
           total < TREND_ROWS ? (long long)total : (long long)TREND_ROWS,
           (long long)total);
    if (total == 0) {
        out("(none yet: amfid writes one every few ok passages once its "
               "window is full)\n");
        return 0;
    }
    if (amfi_store_recent_indicators(s, TREND_ROWS, rec, &nl, err, sizeof err) != 0)
        return data_error("%s", err);
    out("%-19s  %6s  %9s  %8s  %6s  %8s  %s\n", "time (UTC)", "n",
           "mean kg", "STD kg", "ratio", "p", "state");
    for (int k = nl - 1; k >= 0; k--) { /* oldest first */
        const amfi_indicator_row *r = &rec[k].row;
        char t[32], b1[32], b2[32], b3[32], b4[32];
        out("%-19.19s  %6lld  %9.31s  %8.31s  %6.31s  %8.31s  %.8s\n",
            utc(r->utime, t), (long long)r->n, num(r->mean_kg, "%.0f", b1),
            num(r->std_kg, "%.0f", b2), num(r->std_ratio, "%.3f", b3),
            num(r->p_value, "%.2e", b4), r->state);
    }
    return 0;
}

static int section_alerts(amfi_store *s)
{
    int64_t total = 0;
    amfi_alert_rec rec[ALERT_ROWS], *open = NULL;
    int nl = 0, n_open = 0;
    char err[512];
    if (amfi_store_count(s, AMFI_STORE_ALERTS, &total, err, sizeof err) != 0)
        return data_error("%s", err);
    out("== alerts (last %lld of %lld)\n",
           total < ALERT_ROWS ? (long long)total : (long long)ALERT_ROWS,
           (long long)total);
    if (total == 0) {
        out("(none)\n");
        return 0;
    }
    if (amfi_store_open_alerts(s, &open, &n_open, err, sizeof err) != 0)
        return data_error("%s", err);
    for (int k = 0; k < n_open; k++) {
        char t[32];
        out("OPEN NOW     %s %s since %s UTC\n", amfi_cli_shown(open[k].level),
               amfi_cli_shown(open[k].kind), utc(open[k].utime, t));
    }
    free(open);
    if (n_open == 0)
        out("open now     none\n");
    if (amfi_store_recent_alerts(s, ALERT_ROWS, rec, &nl, err, sizeof err) != 0)
        return data_error("%s", err);
    out("%-19s  %-7s  %-14s  %-7s  %9s  %s\n", "time (UTC)", "level",
           "kind", "event", "indicator", "message");
    for (int k = nl - 1; k >= 0; k--) {
        const amfi_alert_rec *a = &rec[k];
        char t[32], is[32];
        if (a->indicator_id > 0)
            snprintf(is, sizeof is, "%lld", (long long)a->indicator_id);
        else
            snprintf(is, sizeof is, "-");
        /* one line per alert: the store shows control characters as '?' */
        out("%-19.19s  %-7.7s  %-14.40s  %-7s  %9.20s  %.300s\n",
            utc(a->utime, t), amfi_cli_shown(a->level), amfi_cli_shown(a->kind),
            a->raised ? "raised" : "cleared", is, a->message);
    }
    return 0;
}

static int section_errors(amfi_store *s)
{
    int64_t n_truth = 0, not_ok = 0;
    double *e = NULL;
    size_t ne = 0;
    char b[4][32], err[512];
    if (amfi_store_count(s, AMFI_STORE_TRUTH, &n_truth, err, sizeof err) != 0)
        return data_error("%s", err);
    out("== errors against the truth\n");
    if (n_truth == 0) {
        out("(no truth rows: the truth is recorded in simulations only)\n");
        return 0;
    }
    if (amfi_store_gvw_errors(s, &e, &ne, &not_ok, err, sizeof err) != 0)
        return data_error("%s", err);
    out("truth rows   %lld; ok passages matched %zu; other passages "
           "matched %lld\n", (long long)n_truth, ne, (long long)not_ok);
    if (ne > 0) {
        double mean, std;
        report_mean_std(e, ne, &mean, &std);
        out("GVW error    mean %+.2f %%, STD %s %%\n", mean,
               num(std, "%.2f", b[0]));
        for (size_t k = 0; k < ne; k++)
            e[k] = fabs(e[k]);
        report_sort(e, ne);
        out("|GVW error|  median %.2f %%, 90 %% %.2f %%, 95 %% %.2f %%, "
               "99 %% %.2f %%, max %.2f %%\n",
               report_percentile(e, ne, 50), report_percentile(e, ne, 90),
               report_percentile(e, ne, 95), report_percentile(e, ne, 99),
               e[ne - 1]);
    }
    free(e);
    return 0;
}

static int set_baseline(const options *o)
{
    amfi_store *s = NULL;
    amfi_baseline b;
    double *g = NULL;
    char err[512];
    int rc = 0, n = 0;
    memset(&b, 0, sizeof b);
    if (amfi_store_open_foreign(o->db, 1, &s, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": %s\n", err); /* starts with the path */
        return -1;
    }
    if (o->baseline_last) {
        g = malloc((size_t)o->baseline_last * sizeof *g);
        if (!g)
            rc = data_error("out of memory");
        if (rc == 0
            && amfi_store_recent_ok_gvw(s, o->baseline_last, g, &n, err,
                                        sizeof err) != 0)
            rc = data_error("%s", err);
        if (rc == 0 && n < o->baseline_last)
            rc = data_error("only %d ok passages stored, --set-baseline-last "
                            "asked for %d", n, o->baseline_last);
        if (rc == 0) {
            report_mean_std(g, (size_t)n, &b.mean_kg, &b.std_kg);
            b.n = n;
        }
    } else {
        b.mean_kg = o->mean_kg;
        b.std_kg = o->std_kg;
        b.n = o->n;
    }
    /* it applies from the newest passage stored (data time) */
    if (rc == 0) {
        amfi_passage_summary sum;
        if (amfi_store_passage_summary(s, &sum, err, sizeof err) != 0)
            rc = data_error("%s", err);
        else
            b.utime_set = sum.utime_last;
    }
    if (rc == 0) {
        snprintf(b.source, sizeof b.source, "manual");
        snprintf(b.note, sizeof b.note, "%s", o->note ? o->note : "");
        if (amfi_store_set_baseline(s, &b, err, sizeof err) != 0)
            rc = data_error("%s", err);
    }
    if (rc == 0) {
        char t[32];
        printf("baseline set: mean %.0f kg, STD %.0f kg, n %d, manual, from "
               "%s UTC\n", b.mean_kg, b.std_kg, b.n, utc(b.utime_set, t));
        printf("(amfid reads the newest baseline row when it starts: restart "
               "it to use this one)\n");
    }
    free(g);
    amfi_store_close(s);
    return rc;
}

/* PATH as one shell word, for the suggested commands. */
static void shell_word(const char *s, char *out, size_t len)
{
    int plain = *s != '\0';
    for (const char *p = s; *p; p++)
        if (!strchr("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                    "0123456789_./-+,:@%=", *p))
            plain = 0;
    if (plain) {
        snprintf(out, len, "%s", s);
        return;
    }
    size_t k = 0;
    if (len < 8) {
        snprintf(out, len, "''");
        return;
    }
    out[k++] = '\'';
    for (const char *p = s; *p && k + 6 < len; p++) {
        if (*p == '\'') {
            memcpy(out + k, "'\\''", 4);
            k += 4;
        } else {
            out[k++] = *p;
        }
    }
    out[k++] = '\'';
    out[k] = '\0';
}

static void print_next(const options *o)
{
    char w[1100];
    if (o->pg) {
        /* the central database; the connection as given to --pg, not
         * echoed (it may hold a password) */
        printf("\nNext, with psql on the central database (docs/fleet.md lists the views):\n");
        printf("  psql -c \"SELECT * FROM fleet_daily_trend WHERE site_id = '%s' ORDER BY day\"\n",
               o->site);
        if (o->trend || o->alerts)
            printf("  psql -c \"SELECT * FROM indicators WHERE site_id = '%s' "
                   "ORDER BY utime DESC LIMIT 50\"\n", o->site);
        if (o->summary)
            printf("  psql -c \"SELECT * FROM fleet_passages_daily WHERE site_id = '%s' "
                   "AND status <> 'ok'\"\n", o->site);
        return;
    }
    shell_word(o->db, w, sizeof w);
    printf("\nNext, with sqlite3 (docs/schema.md lists every table and view):\n");
    printf("  sqlite3 -header -column %s \"SELECT * FROM daily_trend\"\n", w);
    if (o->trend || o->alerts)
        printf("  sqlite3 -header -column %s \"SELECT * FROM window_trend "
               "ORDER BY utime DESC LIMIT 50\"\n", w);
    if (o->summary)
        printf("  sqlite3 -header -column %s \"SELECT status, reason, "
               "count(*) FROM passages WHERE status <> 'ok' GROUP BY 1, 2\"\n",
               w);
    if (o->errors)
        printf("  sqlite3 -header -column %s \"SELECT * FROM passage_errors "
               "ORDER BY abs(gvw_error_pct) DESC LIMIT 20\"\n", w);
    if (o->baseline_last || o->baseline_given)
        printf("  sqlite3 -header -column %s \"SELECT * FROM baseline ORDER BY "
               "id DESC LIMIT 5\"\n", w);
}

/* The export sections (report_export.c) in the table format, through
 * run_section: they read the options from here. */
static const options *g_opt;
static int section_passages(amfi_store *s)
{
    char err[512];
    return export_passages(s, &g_opt->ex, FMT_TABLE, g_out, NULL, err, sizeof err)
               ? data_error("%s", err) : 0;
}
static int section_histogram(amfi_store *s)
{
    char err[512];
    return export_histogram(s, &g_opt->ex, FMT_TABLE, g_out, NULL, err, sizeof err)
               ? data_error("%s", err) : 0;
}
static int section_overloads(amfi_store *s)
{
    char err[512];
    return export_overloads(s, &g_opt->ex, FMT_TABLE, g_out, NULL, err, sizeof err)
               ? data_error("%s", err) : 0;
}
static int section_speed(amfi_store *s)
{
    char err[512];
    return export_speed(s, &g_opt->ex, FMT_TABLE, g_out, NULL, err, sizeof err)
               ? data_error("%s", err) : 0;
}

/* --format csv|json: the chosen sections as one CSV table or one JSON
 * document ({"site_id": ..., "summary": {...}, ..., "passages": [...]}).
 * CSV (one section) goes straight to stdout. In JSON, the sections other
 * than --passages are built first (small: counts, bins, the indicator and
 * alert rows) and the passage array is streamed last, element by element:
 * a year of passages is never held in memory. A store error part-way ends
 * the output short, with the message on stderr and exit 1. */
static int export_all(const options *o, amfi_store *s)
{
    char err[512];
    const int fmt = o->format;
    const export_opts *x = &o->ex;
    if (fmt == FMT_CSV) {
        int rc = 0;
        if (o->summary)
            rc = export_summary(s, fmt, stdout, NULL, err, sizeof err);
        else if (o->trend)
            rc = export_trend(s, fmt, stdout, NULL, err, sizeof err);
        else if (o->alerts)
            rc = export_alerts(s, fmt, stdout, NULL, err, sizeof err);
        else if (o->errors)
            rc = export_errors(s, fmt, stdout, NULL, err, sizeof err);
        else if (o->passages)
            rc = export_passages(s, x, fmt, stdout, NULL, err, sizeof err);
        else if (o->histogram)
            rc = export_histogram(s, x, fmt, stdout, NULL, err, sizeof err);
        else if (o->overloads)
            rc = export_overloads(s, x, fmt, stdout, NULL, err, sizeof err);
        else if (o->speed)
            rc = export_speed(s, x, fmt, stdout, NULL, err, sizeof err);
        return rc ? data_error("%s", err) : 0;
    }
    json_t *root = json_object();
    if (!root)
        return data_error("out of memory");
    char site[256] = "";
    int found = 0;
    int rc = amfi_store_meta_get(s, "site.id", site, sizeof site, &found, err, sizeof err);
    json_object_set_new(root, "site_id", found ? json_string(site) : json_null());
    if (rc == 0 && o->summary)
        rc = export_summary(s, fmt, NULL, root, err, sizeof err);
    if (rc == 0 && o->trend)
        rc = export_trend(s, fmt, NULL, root, err, sizeof err);
    if (rc == 0 && o->alerts)
        rc = export_alerts(s, fmt, NULL, root, err, sizeof err);
    if (rc == 0 && o->errors)
        rc = export_errors(s, fmt, NULL, root, err, sizeof err);
    if (rc == 0 && o->histogram)
        rc = export_histogram(s, x, fmt, NULL, root, err, sizeof err);
    if (rc == 0 && o->overloads)
        rc = export_overloads(s, x, fmt, NULL, root, err, sizeof err);
    if (rc == 0 && o->speed)
        rc = export_speed(s, x, fmt, NULL, root, err, sizeof err);
    if (rc != 0) {
        json_decref(root);
        return data_error("%s", err);
    }
    if (!o->passages)
        return amfi_json_print(stdout, root) != 0
                   ? data_error("cannot write the JSON document") : 0;
    /* the document without its closing brace, then "passages" streamed */
    char *head = json_dumps(root, JSON_COMPACT | JSON_PRESERVE_ORDER
                                      | JSON_REAL_PRECISION(10));
    json_decref(root);
    size_t hl = head ? strlen(head) : 0;
    if (hl < 2 || head[hl - 1] != '}') {
        free(head);
        return data_error("cannot write the JSON document");
    }
    fwrite(head, 1, hl - 1, stdout);
    free(head);
    fputs(",\"passages\":", stdout);
    if (export_passages(s, x, fmt, stdout, NULL, err, sizeof err) != 0)
        return data_error("%s", err);
    if (fputs("}\n", stdout) == EOF || ferror(stdout))
        return data_error("cannot write the JSON document");
    return 0;
}

/* Render one section in memory and print it only when it is complete: a
 * damaged row gives its error line, not half a table. Sections are
 * separated by a blank line. */
static int run_section(int (*fn)(amfi_store *), amfi_store *s, int *printed)
{
    char *buf = NULL;
    size_t len = 0;
    g_out = open_memstream(&buf, &len);
    if (!g_out)
        return data_error("out of memory");
    int rc = fn(s);
    fclose(g_out);
    g_out = stdout;
    if (rc == 0) {
        if (*printed)
            putchar('\n');
        fwrite(buf, 1, len, stdout);
        *printed = 1;
    }
    free(buf);
    return rc;
}

/* --plot: site name from the store's meta (site.name), else the config's
 * bridge.name, else the database's file name; thresholds from --config or
 * the indicator defaults. */
static int plot(const options *o, const amfi_site_config *c, amfi_store *s)
{
    char site[4097], err[1024]; /* meta values hold at most 4096 bytes */
    int found = 0;
    amfi_indicator_params ip;
    amfi_indicator_params_default(&ip);
    if (amfi_store_meta_get(s, "site.name", site, sizeof site, &found, err,
                            sizeof err) != 0)
        return data_error("%s", err);
    if (c) {
        ip = c->daemon.indicators;
        if (!found) {
            snprintf(site, sizeof site, "%s", c->site.name);
            found = 1;
        }
    }
    if (!found) {
        const char *b = strrchr(o->db, '/');
        snprintf(site, sizeof site, "%s", b ? b + 1 : o->db);
    }
    if (report_plot(s, o->plot_dir, site, &ip, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": --plot: %s\n", err);
        return -1;
    }
    return 0;
}

static int report_main(options *op);
static void remove_tmp(const char *dir, const char *db);

int main(int argc, char **argv)
{
    options o;
    char err[512];
    int rc = 0;

    if (parse_args(argc, argv, &o) != 0)
        return EXIT_USAGE;
    if (o.pg && !o.site) {
        rc = report_pg_fleet(o.pg, o.allow_plaintext, stdout, err, sizeof err);
        if (rc)
            fprintf(stderr, PROG ": --pg: %s\n", err);
        return rc == 2 ? EXIT_USAGE : rc ? EXIT_DATA : 0;
    }
    /* --pg --site: the site's central rows in a private temporary store,
     * reported like any store (report_pg.c) */
    char tmpdir[4096] = "", tmpdb[4200] = "";
    if (o.pg) {
        const char *t = getenv("TMPDIR");
        snprintf(tmpdir, sizeof tmpdir, "%s/amfi-report.XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(tmpdir)) {
            fprintf(stderr, PROG ": %s: %s\n", tmpdir, strerror(errno));
            return EXIT_DATA;
        }
        snprintf(tmpdb, sizeof tmpdb, "%s/%s.db", tmpdir, o.site);
        long rows = 0;
        rc = report_pg_fetch_site(o.pg, o.allow_plaintext, o.site, tmpdb, &rows, err, sizeof err);
        if (rc) {
            fprintf(stderr, PROG ": --pg: %s\n", err);
            remove_tmp(tmpdir, tmpdb);
            return rc == 2 ? EXIT_USAGE : EXIT_DATA;
        }
        o.db = tmpdb;
    }
    rc = report_main(&o);
    if (o.pg)
        remove_tmp(tmpdir, tmpdb);
    return rc;
}

static void remove_tmp(const char *dir, const char *db)
{
    amfi_store_remove(db);
    rmdir(dir);
}

/* The report of one store (o->db): the sections asked for. */
static int report_main(options *op)
{
    options o = *op;
    amfi_store *s = NULL;
    char err[512];
    int rc = 0, printed = 0;
    g_db = o.pg ? o.site : o.db;
    g_opt = &o;
    /* --config: thresholds, names, legal limits; else the defaults */
    amfi_site_config *cfg = malloc(sizeof *cfg);
    if (!cfg) {
        fprintf(stderr, PROG ": out of memory\n");
        return EXIT_DATA;
    }
    amfi_config_defaults(cfg);
    if (o.config && amfi_config_load(o.config, cfg, err, sizeof err) != 0) {
        fprintf(stderr, PROG ": --config: %s\n", err);
        free(cfg);
        return EXIT_DATA;
    }
    o.ex.gvw_limit_kg = cfg->report.gvw_limit_kg;
    o.ex.axle_limit_kg = cfg->report.axle_limit_kg;
    if (!o.bin_given)
        o.ex.bin_kg = cfg->report.bin_kg;
    /* read-only first: refuses a missing file, a non-SQLite file, a foreign
     * or newer database, before anything could write to it */
    if (amfi_store_open_readonly(o.db, &s, err, sizeof err) != 0) {
        /* the store's message starts with the path already */
        fprintf(stderr, PROG ": %s\n", err);
        free(cfg);
        return EXIT_DATA;
    }
    g_out = stdout;
    if (o.speed == 2) {
        /* by default: only when the store has estimated speeds */
        int yes = 0;
        if (amfi_store_has_estimated(s, &yes, err, sizeof err) != 0) {
            data_error("%s", err);
            amfi_store_close(s);
            free(cfg);
            return EXIT_DATA;
        }
        o.speed = yes;
    }
    if (o.format != FMT_TABLE) {
        rc = export_all(&o, s);
        amfi_store_close(s);
        free(cfg);
        fflush(stdout);
        return rc == 0 ? 0 : EXIT_DATA;
    }
    if (o.baseline_last || o.baseline_given) {
        rc = set_baseline(&o);
        printed = rc == 0;
    }
    if (rc == 0 && o.summary)
        rc = run_section(section_summary, s, &printed);
    if (rc == 0 && o.trend)
        rc = run_section(section_trend, s, &printed);
    if (rc == 0 && o.alerts)
        rc = run_section(section_alerts, s, &printed);
    if (rc == 0 && o.errors)
        rc = run_section(section_errors, s, &printed);
    if (rc == 0 && o.passages) {
        /* streamed (a year of passages is not rendered in memory first): a
         * damaged row ends the list with its error line */
        if (printed)
            putchar('\n');
        rc = section_passages(s);
        printed = 1;
    }
    if (rc == 0 && o.histogram)
        rc = run_section(section_histogram, s, &printed);
    if (rc == 0 && o.overloads)
        rc = run_section(section_overloads, s, &printed);
    if (rc == 0 && o.speed)
        rc = run_section(section_speed, s, &printed);
    if (rc == 0 && o.plot_dir) {
        if (printed)
            printf("\n");
        rc = plot(&o, o.config ? cfg : NULL, s);
        printed = 1;
    }
    if (rc == 0 && o.check) {
        char result[1024];
        int st = amfi_store_integrity_check(s, result, sizeof result, err,
                                            sizeof err);
        if (printed)
            printf("\n");
        printf("integrity    %s\n", result);
        if (st != 0 || strcmp(result, "ok") != 0)
            rc = data_error("integrity check failed: %s", result);
    }
    if (rc == 0 && (o.summary || o.trend || o.alerts || o.errors
                    || o.baseline_last || o.baseline_given))
        print_next(&o);
    amfi_store_close(s);
    free(cfg);
    fflush(stdout);
    return rc == 0 ? 0 : EXIT_DATA;
}
