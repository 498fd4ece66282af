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
 * histogram per lane and the overloads against legal limits; shows the
 * speed corrections of the passages whose speed amfid estimated; draws the
 * store with gnuplot (--plot).
 * Every section prints as a table, CSV (one section at a time) or one JSON
 * document. The sections are the rows of one table below (sections[]);
 * each lives in its subject's file (report.h lists them and who calls
 * whom). With no option: summary, trend and alerts, and the speed
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

#include "amfi_classify.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_json.h"
#include "report.h"
#include "report_classes.h"
#include "report_indicators.h"
#include "report_natfreq.h"
#include "report_passages.h"
#include "report_pg.h"
#include "report_plot.h"
#include "report_residual.h"
#include "report_scale.h"
#include "report_speed.h"
#include "report_summary.h"
#include "store.h"

#define PROG "amfi-report"
#define EXIT_DATA 1
#define EXIT_USAGE 2
#define MAX_BASELINE_N 10000000
#define STR_(x) #x
#define STR(x) STR_(x)
#define HELP_INDENT "                               " /* where --help's texts start */

/* ---- the table of sections ---------------------------------------------------
 *
 * One row per section: its flag, its table, its CSV and JSON, its plots,
 * which filters it honours. parse_args, --help, the default selection, the
 * CSV and JSON document and the table output all come from it: a new
 * section is one row here (and its functions in its subject's file). */

/* A plot of --plot: its place in the gnuplot script (the plots share the
 * script's settings, so they are drawn in this order whatever the section
 * order), its PNG, what it shows, and the function that writes it. */
typedef struct plot_def {
    int place; /* > 0; 0 ends a row's list */
    const char *png, *what;
    report_plot_fn draw;
} plot_def;

/* The filters a section honours; the others see every passage. A section
 * without F_TIME refuses --from/--to (check_args), and --help says which
 * honour it, both from this table. */
#define F_TIME 1u   /* --from, --to */
#define F_STATUS 2u /* --status */
#define F_LANE 4u   /* --lane */
#define F_RANGE (F_TIME | F_LANE)

#define MAX_SECTION_PLOTS 6

typedef struct section {
    const char *name;                /* --name */
    int key;                         /* -k */
    const char *help;                /* --help's text; "\n" continues it indented */
    int (*table)(report_ctx *);      /* --format table */
    int (*export)(report_ctx *);     /* --format csv (to c->out) and json (into c->root) */
    plot_def plots[MAX_SECTION_PLOTS]; /* what it draws with --plot */
    unsigned filters;                /* F_* */
    /* with no section asked for: 1 shown; and then only when default_if
     * says yes, when that is set */
    int by_default;
    int (*default_if)(amfi_store *s, int *yes, char *err, size_t errlen);
    const char *default_when; /* what default_if asks, for --help */
    /* written as it is read, never held whole: not rendered in memory
     * first (a damaged row cuts the table short) and, in JSON, streamed
     * last into the document */
    int streamed;
} section;

enum { SEC_SUMMARY, SEC_TREND, SEC_ALERTS, SEC_ERRORS, SEC_PASSAGES, SEC_HISTOGRAM, SEC_OVERLOADS,
       SEC_SPEED, SEC_CLASSES, SEC_CLASS_HISTOGRAM, N_SECTIONS };

static const section sections[N_SECTIONS] = {
    [SEC_SUMMARY] = {
        .name = "summary", .key = 's',
        .help = "passages by status, GVW of the ok ones, time span, baseline,\n"
                "the solver's residual",
        .table = summary_table, .export = summary_export,
        .plots = {{7, "scale.png", "scale indicator: raw and temperature-compensated scale, "
                   "CUSUM and threshold", scale_plot_scale},
                  {8, "known_truck.png", "known-truck runs: ratio inferred / reference, raw and "
                   "compensated", scale_plot_known_truck},
                  {9, "temperature.png", "deck and air temperature", scale_plot_temperature},
                  {10, "natfreq.png", "natural frequency per passage, raw and "
                   "temperature-compensated", natfreq_plot},
                  {11, "residual.png", "solver residual per ok passage and its running median",
                   residual_plot},
                  {12, "fit_ratio.png", "model fit ratio per passage, its running median, the "
                   "model_mismatch thresholds", fit_ratio_plot}},
        .by_default = 1},
    [SEC_TREND] = {
        .name = "trend", .key = 't', .help = "the last " STR(REPORT_TREND_ROWS) " indicators",
        .table = trend_table, .export = trend_export,
        .plots = {{2, "trend.png", "indicator trend, thresholds, alerts raised and cleared",
                   indicators_plot_trend}},
        .filters = F_TIME, .by_default = 1},
    [SEC_ALERTS] = {
        .name = "alerts", .key = 'a',
        .help = "the last " STR(REPORT_ALERT_ROWS) " alerts and those open now (open\n"
                "now whatever the range)",
        .table = alerts_table, .export = alerts_export, .filters = F_TIME, .by_default = 1},
    [SEC_ERRORS] = {
        .name = "errors", .key = 'e', .help = "inferred GVW against the truth (simulations)",
        .table = errors_table, .export = errors_export},
    [SEC_PASSAGES] = {
        .name = "passages", .key = 'P',
        .help = "one line per passage: time, lane, speed, axles, GVW,\n"
                "axle loads, status, reason",
        .table = passages_table, .export = passages_export,
        .plots = {{1, "gvw.png", "inferred GVW per passage over time, baseline band",
                   passages_plot_gvw},
                  {4, "passages_per_hour.png", "passages per hour by status",
                   passages_plot_per_hour},
                  {5, "speed.png", "speed distribution", passages_plot_speed}},
        .filters = F_RANGE | F_STATUS, .streamed = 1},
    [SEC_HISTOGRAM] = {
        .name = "histogram", .key = 'H', .help = "GVW histogram of the ok passages per lane",
        .table = histogram_table, .export = histogram_export,
        .plots = {{3, "gvw_histogram.png", "GVW histogram, baseline against the latest window",
                   passages_plot_histogram}},
        .filters = F_RANGE},
    [SEC_OVERLOADS] = {
        .name = "overloads", .key = 'O',
        .help = "ok passages over their class's legal GVW or an axle group\n"
                "over its limit (classes: of --config), by class",
        .table = overloads_table, .export = overloads_export, .filters = F_RANGE},
    [SEC_SPEED] = {
        .name = "speed", .key = 'C',
        .help = "speed corrections of the estimated passages (speed used /\n"
                "detector's - 1): distribution, one line per day",
        .table = speed_table, .export = speed_export,
        .plots = {{6, "speed_correction.png", "daily median speed correction, p5 .. p95",
                   speed_plot_correction}},
        .filters = F_RANGE, .by_default = 1, .default_if = amfi_store_has_estimated,
        .default_when = "when the store has estimated speeds"},
    [SEC_CLASSES] = {
        .name = "classes", .key = 'L',
        .help = "ok passages per vehicle class, all lanes and per lane:\n"
                "count, share, GVW mean, STD, p5, p50, p95, max, overloaded",
        .table = classes_table, .export = classes_export, .filters = F_RANGE},
    [SEC_CLASS_HISTOGRAM] = {
        .name = "class-histogram", .key = 'Y',
        .help = "GVW histogram of the ok passages per vehicle class",
        .table = class_histogram_table, .export = class_histogram_export, .filters = F_RANGE},
};

/* ---- the other options ------------------------------------------------------- */

/* --help lists these in this order; a row with sections = N stands for the
 * sections from the table whose index is in [N's first, its last]. */
typedef struct option_row {
    const char *name;
    int has_arg;
    int key;          /* getopt's value; shown as -k when show_short */
    int show_short;
    const char *arg;  /* the value's name in --help, or NULL */
    const char *help; /* NULL: not listed (shown with another row) */
    int first, last;  /* a row of sections: first .. last in the table (last > 0) */
    int builtin;      /* --help and --version: amfi_cli's own */
} option_row;

#define OPT(name_, arg_, key_, shown_, what_, help_, ...)                                       \
    {.name = (name_), .has_arg = (arg_), .key = (key_), .show_short = (shown_), .arg = (what_),   \
     .help = (help_), __VA_ARGS__}
static const option_row option_rows[] = {
    OPT("db", 1, 'd', 1, "PATH", "the store (must exist)"),
    OPT("pg", 1, 'G', 0, "CONNINFO", "the central PostgreSQL instead (docs/fleet.md): the fleet\n"
                                  "summary, or with --site the report of one site"),
    OPT("site", 1, 'I', 0, "ID", "the site, with --pg"),
    OPT("allow-plaintext", 0, 'X', 0, NULL, "with --pg: no TLS to a server not on this machine"),
    {.first = SEC_SUMMARY, .last = SEC_ERRORS},
    OPT("set-baseline-last", 1, 'B', 1, "N", "baseline (source manual) from the last N ok passages, "
                                          "N >= 2"),
    OPT("set-baseline", 1, 'b', 1, "M,S,N", "baseline mean M kg, STD S kg, from N passages"),
    OPT("note", 1, 'n', 1, "TEXT", "note stored with the baseline (<= 127 bytes)"),
    OPT("force", 0, 'K', 0, NULL, "with --set-baseline*: set it even while an alert is open\n"
                                 "(refused by default: a baseline from damaged data)"),
    OPT("check", 0, 'k', 1, NULL, "PRAGMA integrity_check and foreign_key_check"),
    {.first = SEC_PASSAGES, .last = SEC_CLASS_HISTOGRAM},
    OPT("from", 1, 'f', 1, "T, -T, --to T", "only passages in [T, T]: YYYY-MM-DD or "
                                         "YYYY-MM-DDTHH:MM[:SS], UTC"),
    OPT("to", 1, 'T', 1, NULL, NULL),
    OPT("status", 1, 'S', 1, "S", "only passages of status S (--passages)"),
    OPT("lane", 1, 'l', 1, "N", "only lane N (the sections marked --lane above)"),
    OPT("bin-kg", 1, 'w', 1, "W", "histogram bin width, kg (default report.histogram_bin_kg)"),
    OPT("format", 1, 'F', 1, "F", "table (default), csv (one section) or json (one document)"),
    OPT("units", 1, 'U', 0, "U", "tables and plots in si (kg, m/s) or engineering (t, km/h)\n"
                              "(default report.units: si); CSV and JSON always kg, m/s"),
    OPT("plot", 1, 'p', 1, "DIR", "draw PNGs into DIR (gnuplot): GVW, trend, histogram, per hour, "
                               "speed,\nresidual, ... [honours --from --to]"),
    OPT("config", 1, 'c', 1, "FILE", "the site's amfid.yaml: alert thresholds, site name, legal "
                                  "limits"),
    OPT("help", 0, 'h', 1, NULL, "this help", .builtin = 1),
    OPT("version", 0, 'V', 1, NULL, "print the version", .builtin = 1),
};
#define N_OPTION_ROWS (sizeof option_rows / sizeof option_rows[0])

typedef struct options {
    const char *db;
    const char *pg;         /* --pg CONNINFO: the central database, NULL: none */
    const char *site;       /* --site ID (with --pg) */
    int allow_plaintext;    /* --allow-plaintext: no TLS to a remote --pg server */
    int sel[N_SECTIONS];    /* 1: asked for; 2: by default, if its default_if says yes */
    int check;
    int baseline_last;   /* N of --set-baseline-last, 0: not given */
    int baseline_given;  /* --set-baseline MEAN,STD,N given */
    double mean_kg, std_kg;
    int n;
    const char *note;    /* NULL: empty */
    int force;           /* --force: a baseline even while an alert is open */
    const char *plot_dir;   /* --plot DIR, NULL: none */
    const char *config;     /* --config FILE, NULL: none */
    int format;             /* FMT_* */
    export_opts ex;         /* --from --to --status --lane --bin-kg, limits */
    int bin_given;
    int units;              /* --units: AMFI_REPORT_UNITS_*, −1: report.units */
    const char *range_opt;  /* "--from" or "--to" when one was given, else NULL */
} options;

/* --help: "  -k, --name ARG" in 31 columns, then its text */
static void help_line(FILE *f, int key, int show_short, const char *name, const char *arg,
                      const char *help)
{
    char left[64], shrt[8] = "    ";
    if (show_short)
        snprintf(shrt, sizeof shrt, "-%c, ", key);
    snprintf(left, sizeof left, "%s%s%s", name, arg ? " " : "", arg ? arg : "");
    fprintf(f, "  %s--%-23s", shrt, left);
    for (const char *p = help; *p; p++) {
        fputc(*p, f);
        if (*p == '\n')
            fputs(HELP_INDENT, f);
    }
    fputc('\n', f);
}

/* A section's --help text and, from its filters, what it honours. */
static void section_help(int k, char *text, size_t len)
{
    const unsigned fl = sections[k].filters;
    if (fl & F_TIME)
        snprintf(text, len, "%s\n[honours --from --to%s%s]", sections[k].help,
                 fl & F_LANE ? " --lane" : "", fl & F_STATUS ? " --status" : "");
    else
        snprintf(text, len, "%s\n[the whole store: refuses --from and --to]", sections[k].help);
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
            "       [--speed] [--classes] [--class-histogram] [--lane N] [--bin-kg W]\n"
            "       [--format table|csv|json] [--units si|engineering] [--plot DIR]\n"
            "       [--config FILE] [--force]\n"
            "\n"
            "Reports on amfid's SQLite store (schema: docs/schema.md).\n");
    for (size_t i = 0; i < N_OPTION_ROWS; i++) {
        const option_row *r = &option_rows[i];
        if (r->last > 0) {
            for (int k = r->first; k <= r->last; k++) {
                char text[512];
                section_help(k, text, sizeof text);
                help_line(f, sections[k].key, 1, sections[k].name, NULL, text);
            }
        } else if (r->help) {
            help_line(f, r->key, r->show_short, r->name, r->arg, r->help);
        }
    }
    fputs("With no option:", f);
    for (int k = 0; k < N_SECTIONS; k++)
        if (sections[k].by_default && !sections[k].default_if)
            fprintf(f, " --%s", sections[k].name);
    for (int k = 0; k < N_SECTIONS; k++)
        if (sections[k].by_default && sections[k].default_if)
            fprintf(f, " (and --%s %s)", sections[k].name, sections[k].default_when);
    fputs(".\nExit status: 0 ok, 1 database error or check failed, 2 usage error.\n", f);
}

/* "amfi-report: OPT: problem" on stderr; returns −1 */
#define usage_error(opt, ...) (amfi_cli_error(PROG, opt, __VA_ARGS__), -1)

static int data_error(const report_ctx *c, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* "amfi-report: PATH: problem" (the site with --pg) on stderr; returns −1 */
static int data_error(const report_ctx *c, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, PROG ": %s: ", c->name);
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

static int check_args(options *o);

static int parse_args(int argc, char **argv, options *o)
{
    struct option longopts[N_OPTION_ROWS + N_SECTIONS + 1];
    size_t nl = 0;
    for (size_t i = 0; i < N_OPTION_ROWS; i++)
        if (option_rows[i].name && !option_rows[i].builtin)
            longopts[nl++] = (struct option){option_rows[i].name,
                                             option_rows[i].has_arg ? required_argument
                                                                    : no_argument,
                                             NULL, option_rows[i].key};
    for (int k = 0; k < N_SECTIONS; k++)
        longopts[nl++] = (struct option){sections[k].name, no_argument, NULL, sections[k].key};
    const struct option tail[] = {AMFI_CLI_END};
    struct option all[sizeof longopts / sizeof longopts[0] + sizeof tail / sizeof tail[0]];
    memcpy(all, longopts, nl * sizeof *all);
    memcpy(all + nl, tail, sizeof tail);
    memset(o, 0, sizeof *o);
    o->units = -1;
    o->ex.from = 0;
    o->ex.to = AMFI_STORE_MAX_UTIME;
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, all, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *opt = c.opt, *val = optarg;
        int sec = -1;
        for (int i = 0; i < N_SECTIONS; i++)
            if (sections[i].key == k)
                sec = i;
        if (sec >= 0) {
            o->sel[sec] = 1;
            continue;
        }
        switch (k) {
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
        case 'K': o->force = 1; break;
        case 'U':
            if (strcmp(val, "si") == 0)
                o->units = AMFI_REPORT_UNITS_SI;
            else if (strcmp(val, "engineering") == 0)
                o->units = AMFI_REPORT_UNITS_ENGINEERING;
            else
                return usage_error(opt, "'%s' is not si or engineering", amfi_cli_shown(val));
            break;
        case 'f':
        case 'T':
            {
                char why[128];
                if (report_parse_time(val, k == 'T', k == 'f' ? &o->ex.from : &o->ex.to,
                                      why, sizeof why) != 0)
                    return usage_error(opt, "'%s' is not a UTC time (%s): use YYYY-MM-DD, "
                                       "YYYY-MM-DDTHH:MM[:SS[.ffffff]][Z]",
                                       amfi_cli_shown(val), why);
                if (!o->range_opt)
                    o->range_opt = k == 'f' ? "--from" : "--to";
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
    return check_args(o);
}

/* The rules between options, in the order they are checked; then the
 * default sections when none was asked for. */
static int check_args(options *o)
{
    int asked = 0, n_status = 0; /* sections asked for; of them, those --status filters */
    for (int k = 0; k < N_SECTIONS; k++)
        asked += o->sel[k];
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
        if (asked || o->plot_dir)
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
    if (o->force && !o->baseline_last && !o->baseline_given)
        return usage_error("--force", "only with --set-baseline-last or --set-baseline");
    if (o->ex.from > o->ex.to)
        return usage_error("--from", "after --to");
    if (o->range_opt && (o->check || o->baseline_last || o->baseline_given))
        return usage_error(o->range_opt, "%s works on the whole store and does not honour "
                           "--from/--to", o->check ? "--check" : o->baseline_last
                           ? "--set-baseline-last" : "--set-baseline");
    if (!asked && !o->check && !o->plot_dir && !o->baseline_last && !o->baseline_given)
        for (int k = 0; k < N_SECTIONS; k++)
            o->sel[k] = sections[k].by_default ? (sections[k].default_if ? 2 : 1) : 0;
    /* every section asked for (or shown by default) honours the range, or
     * it is refused: never silently the whole store */
    for (int k = 0; o->range_opt && k < N_SECTIONS; k++)
        if (o->sel[k] && !(sections[k].filters & F_TIME)) {
            char with[256] = "";
            size_t at = 0;
            for (int j = 0; j < N_SECTIONS; j++)
                if ((sections[j].filters & F_TIME) && at < sizeof with)
                    at += (size_t)snprintf(with + at, sizeof with - at, "--%s ",
                                           sections[j].name);
            return usage_error(o->range_opt, "--%s%s reports the whole store and does not honour "
                               "--from/--to; these do: %s--plot", sections[k].name,
                               asked ? "" : " (shown with no section asked for)", with);
        }
    /* --lane likewise */
    for (int k = 0; o->ex.lane_given && k < N_SECTIONS; k++)
        if (o->sel[k] && !(sections[k].filters & F_LANE)) {
            char with[256] = "";
            size_t at = 0;
            for (int j = 0; j < N_SECTIONS; j++)
                if ((sections[j].filters & F_LANE) && at < sizeof with)
                    at += (size_t)snprintf(with + at, sizeof with - at, "%s--%s",
                                           at ? " " : "", sections[j].name);
            return usage_error("--lane", "--%s%s covers every lane and does not honour --lane; "
                               "these do: %s", sections[k].name,
                               asked ? "" : " (shown with no section asked for)", with);
        }
    if (o->ex.lane_given && (o->check || o->baseline_last || o->baseline_given || o->plot_dir))
        return usage_error("--lane", "--check, --set-baseline* and --plot cover every lane");
    for (int k = 0; k < N_SECTIONS; k++)
        n_status += o->sel[k] && (sections[k].filters & F_STATUS);
    if (o->ex.status && !n_status) {
        char with[256] = "";
        size_t at = 0;
        for (int k = 0; k < N_SECTIONS; k++)
            if ((sections[k].filters & F_STATUS) && at < sizeof with)
                at += (size_t)snprintf(with + at, sizeof with - at, "%s--%s", at ? " or " : "",
                                       sections[k].name);
        return usage_error("--status", "only with %s", with);
    }
    if (o->format != FMT_TABLE) {
        int n = 0;
        for (int k = 0; k < N_SECTIONS; k++)
            n += o->sel[k] == 1;
        if (o->check || o->plot_dir || o->baseline_last || o->baseline_given)
            return usage_error("--format", "csv and json are for the report sections, not "
                               "--check, --plot or --set-baseline*");
        if (o->format == FMT_CSV && n != 1)
            return usage_error("--format", "csv takes one section at a time (%d given)", n);
    }
    return 0;
}

static int set_baseline(const options *o, const report_ctx *c)
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
    /* an open alert: the recent passages may come from a damaged bridge,
     * and a baseline taken from them would hide the damage */
    amfi_alert_rec *open = NULL;
    int n_open = 0;
    if (amfi_store_open_alerts(s, &open, &n_open, err, sizeof err) != 0)
        rc = data_error(c, "%s", err);
    if (rc == 0 && n_open > 0) {
        char t[32], names[512] = "";
        size_t at = 0;
        for (int k = 0; k < n_open && at < sizeof names; k++)
            at += (size_t)snprintf(names + at, sizeof names - at, "%s%s %s (since %s UTC)",
                                   k ? ", " : "", amfi_cli_shown(open[k].level),
                                   amfi_cli_shown(open[k].kind), report_utc(open[k].utime, t));
        if (o->force)
            printf("warning: --force: a baseline while %d alert%s open: %s\n", n_open,
                   n_open > 1 ? "s are" : " is", names);
        else
            rc = data_error(c, "%d alert%s open: %s; a baseline now may be taken from damaged "
                            "data: clear the cause first, or give --force", n_open,
                            n_open > 1 ? "s are" : " is", names);
    }
    free(open);
    if (rc == 0 && o->baseline_last) {
        g = malloc((size_t)o->baseline_last * sizeof *g);
        if (!g)
            rc = data_error(c, "out of memory");
        /* the passages amfid feeds the rules: its class filter as it
         * recorded it (meta daemon.indicators.classes), else every one */
        char rec[512], names_buf[128] = "";
        const char *names[32];
        int found = 0, n_names = 0;
        double min_kg = 0.0;
        if (rc == 0 && amfi_store_meta_get(s, "daemon.indicators.classes", rec, sizeof rec,
                                           &found, err, sizeof err) != 0)
            rc = data_error(c, "%s", err);
        if (rc == 0 && found) {
            char *end = NULL;
            const char *m = strstr(rec, " min_gvw_kg=");
            if (strncmp(rec, "classes=", 8) != 0 || !m || (size_t)(m - rec - 8) >= sizeof names_buf)
                rc = data_error(c, "meta daemon.indicators.classes: '%s' is not "
                                "'classes=LIST min_gvw_kg=KG'", amfi_cli_shown(rec));
            if (rc == 0) {
                memcpy(names_buf, rec + 8, (size_t)(m - rec - 8));
                names_buf[m - rec - 8] = '\0';
                min_kg = strtod(m + 12, &end);
                if (end == m + 12 || *end || !(min_kg >= 0.0 && min_kg <= 1e5))
                    rc = data_error(c, "meta daemon.indicators.classes: min_gvw_kg in '%s'",
                                    amfi_cli_shown(rec));
            }
            for (char *save = NULL, *t = rc == 0 ? strtok_r(names_buf, ",", &save) : NULL;
                 t && n_names < 32; t = strtok_r(NULL, ",", &save))
                names[n_names++] = t;
        }
        if (rc == 0
            && amfi_store_recent_fed_gvw(s, o->baseline_last, names, n_names, min_kg, 0, g, &n,
                                         err, sizeof err) != 0)
            rc = data_error(c, "%s", err);
        if (rc == 0 && n < o->baseline_last)
            rc = data_error(c, "only %d ok passages stored, --set-baseline-last "
                            "asked for %d", n, o->baseline_last);
        if (rc == 0) {
            report_mean_std(g, (size_t)n, &b.mean_kg, &b.std_kg);
            b.n = n;
        }
    } else if (rc == 0) {
        b.mean_kg = o->mean_kg;
        b.std_kg = o->std_kg;
        b.n = o->n;
    }
    /* it applies from the newest passage stored (data time) */
    if (rc == 0) {
        amfi_passage_summary sum;
        if (amfi_store_passage_summary(s, &sum, err, sizeof err) != 0)
            rc = data_error(c, "%s", err);
        else
            b.utime_set = sum.utime_last;
    }
    if (rc == 0) {
        snprintf(b.source, sizeof b.source, "manual");
        snprintf(b.note, sizeof b.note, "%s", o->note ? o->note : "");
        if (amfi_store_set_baseline(s, &b, err, sizeof err) != 0)
            rc = data_error(c, "%s", err);
    }
    if (rc == 0) {
        char t[32];
        char m1[32], m2[32];
        const char *u = report_mass_unit(c->units);
        printf("baseline set: mean %s %s, STD %s %s, n %d, manual, from %s UTC\n",
               report_mass(c->units, b.mean_kg, m1), u, report_mass(c->units, b.std_kg, m2), u,
               b.n, report_utc(b.utime_set, t));
        printf("(a running amfid applies the newest baseline row within a few seconds)\n");
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
    const int *sel = o->sel;
    if (o->pg) {
        /* the central database; the connection as given to --pg, not
         * echoed (it may hold a password) */
        printf("\nNext, with psql on the central database (docs/fleet.md lists the views):\n");
        printf("  psql -c \"SELECT * FROM fleet_daily_trend WHERE site_id = '%s' ORDER BY day\"\n",
               o->site);
        if (sel[SEC_TREND] || sel[SEC_ALERTS])
            printf("  psql -c \"SELECT * FROM indicators WHERE site_id = '%s' "
                   "ORDER BY utime DESC LIMIT 50\"\n", o->site);
        if (sel[SEC_SUMMARY])
            printf("  psql -c \"SELECT * FROM fleet_passages_daily WHERE site_id = '%s' "
                   "AND status <> 'ok'\"\n", o->site);
        return;
    }
    shell_word(o->db, w, sizeof w);
    printf("\nNext, with sqlite3 (docs/schema.md lists every table and view):\n");
    printf("  sqlite3 -header -column %s \"SELECT * FROM daily_trend\"\n", w);
    if (sel[SEC_TREND] || sel[SEC_ALERTS])
        printf("  sqlite3 -header -column %s \"SELECT * FROM window_trend "
               "ORDER BY utime DESC LIMIT 50\"\n", w);
    if (sel[SEC_SUMMARY])
        printf("  sqlite3 -header -column %s \"SELECT status, reason, "
               "count(*) FROM passages WHERE status <> 'ok' GROUP BY 1, 2\"\n",
               w);
    if (sel[SEC_ERRORS])
        printf("  sqlite3 -header -column %s \"SELECT * FROM passage_errors "
               "ORDER BY abs(gvw_error_pct) DESC LIMIT 20\"\n", w);
    if (o->baseline_last || o->baseline_given)
        printf("  sqlite3 -header -column %s \"SELECT * FROM baseline ORDER BY "
               "id DESC LIMIT 5\"\n", w);
}

/* ---- dispatch ---------------------------------------------------------------- */

/* The context of section k: the filters it honours, the others open. */
static void context_for(report_ctx *c, const options *o, int k)
{
    c->ex = o->ex;
    if (!(sections[k].filters & F_TIME)) {
        c->ex.from = 0;
        c->ex.to = AMFI_STORE_MAX_UTIME;
    }
    if (!(sections[k].filters & F_LANE)) {
        c->ex.lane_given = 0;
        c->ex.lane = 0;
    }
    if (!(sections[k].filters & F_STATUS))
        c->ex.status = NULL;
}

/* --format csv|json: the chosen sections as one CSV table or one JSON
 * document ({"site_id": ..., "summary": {...}, ..., "passages": [...]}).
 * CSV (one section) goes straight to stdout. In JSON, the sections that are
 * not streamed are built first (small: counts, bins, the indicator and
 * alert rows) and the streamed ones (the passage array) written last,
 * element by element: a year of passages is never held in memory. A store
 * error part-way ends the output short, with the message on stderr and
 * exit 1. */
static int export_all(const options *o, report_ctx *c)
{
    c->out = stdout;
    if (o->format == FMT_CSV) {
        for (int k = 0; k < N_SECTIONS; k++)
            if (o->sel[k]) {
                context_for(c, o, k);
                return sections[k].export(c) ? data_error(c, "%s", c->err) : 0;
            }
        return 0;
    }
    json_t *root = json_object();
    if (!root)
        return data_error(c, "out of memory");
    c->root = root;
    char site[256] = "";
    int found = 0, rc = 0, streamed = 0;
    rc = amfi_store_meta_get(c->s, "site.id", site, sizeof site, &found, c->err, sizeof c->err);
    json_object_set_new(root, "site_id", found ? json_string(site) : json_null());
    for (int k = 0; rc == 0 && k < N_SECTIONS; k++) {
        if (!o->sel[k] || sections[k].streamed) {
            streamed += o->sel[k] != 0;
            continue;
        }
        context_for(c, o, k);
        rc = sections[k].export(c);
    }
    if (rc != 0) {
        json_decref(root);
        return data_error(c, "%s", c->err);
    }
    if (!streamed)
        return amfi_json_print(stdout, root) != 0
                   ? data_error(c, "cannot write the JSON document") : 0;
    /* the document without its closing brace, then each streamed section */
    char *head = json_dumps(root, JSON_COMPACT | JSON_PRESERVE_ORDER
                                      | JSON_REAL_PRECISION(10));
    json_decref(root);
    c->root = NULL;
    size_t hl = head ? strlen(head) : 0;
    if (hl < 2 || head[hl - 1] != '}') {
        free(head);
        return data_error(c, "cannot write the JSON document");
    }
    fwrite(head, 1, hl - 1, stdout);
    free(head);
    for (int k = 0; k < N_SECTIONS; k++) {
        if (!o->sel[k] || !sections[k].streamed)
            continue;
        printf(",\"%s\":", sections[k].name);
        context_for(c, o, k);
        if (sections[k].export(c) != 0)
            return data_error(c, "%s", c->err);
    }
    if (fputs("}\n", stdout) == EOF || ferror(stdout))
        return data_error(c, "cannot write the JSON document");
    return 0;
}

/* One section as a table. Rendered in memory and printed only when it is
 * complete (a damaged row gives its error line, not half a table), unless
 * it is streamed (a year of passages is not rendered in memory first: a
 * damaged row ends the list with its error line). Sections are separated by
 * a blank line. */
static int run_section(const options *o, report_ctx *c, int k, int *printed)
{
    context_for(c, o, k);
    if (sections[k].streamed) {
        if (*printed)
            putchar('\n');
        c->out = stdout;
        *printed = 1;
        return sections[k].table(c) ? data_error(c, "%s", c->err) : 0;
    }
    char *buf = NULL;
    size_t len = 0;
    c->out = open_memstream(&buf, &len);
    if (!c->out)
        return data_error(c, "out of memory");
    int rc = sections[k].table(c);
    fclose(c->out);
    c->out = stdout;
    if (rc == 0) {
        if (*printed)
            putchar('\n');
        fwrite(buf, 1, len, stdout);
        *printed = 1;
    } else {
        data_error(c, "%s", c->err);
    }
    free(buf);
    return rc;
}

/* --plot: site name from the store's meta (site.name), else the config's
 * bridge.name, else the database's file name; thresholds from what amfid
 * recorded in the store (meta daemon.indicators, alerts.model_fit), else
 * --config, else the defaults. Every section's plots, in their places. */
static int plot(const options *o, const amfi_site_config *cfg, const report_ctx *c)
{
    amfi_store *s = c->s;
    char site[4097], err[1024]; /* meta values hold at most 4096 bytes */
    int found = 0;
    amfi_indicator_params ip;
    amfi_indicator_params_default(&ip);
    const char *ip_from = "built-in defaults";
    if (amfi_store_meta_get(s, "site.name", site, sizeof site, &found, err,
                            sizeof err) != 0)
        return data_error(c, "%s", err);
    /* the thresholds: what amfid ran with (meta daemon.indicators), else
     * --config's, else the defaults */
    char rec[4097], why[256];
    int have_rec = 0;
    if (amfi_store_meta_get(s, "daemon.indicators", rec, sizeof rec, &have_rec, err,
                            sizeof err) != 0)
        return data_error(c, "%s", err);
    if (have_rec) {
        if (amfi_indicator_params_parse(rec, &ip, why, sizeof why) != 0)
            return data_error(c, "meta daemon.indicators: %s", why);
        ip_from = "amfid's, from the store";
    } else if (cfg) {
        ip = cfg->daemon.indicators;
        ip_from = "--config";
    }
    /* the model fit's rule likewise (meta alerts.model_fit), else
     * --config's, else the loader's defaults */
    amfi_level_params mf;
    const char *mf_from = "built-in defaults";
    if (amfi_store_meta_get(s, "alerts.model_fit", rec, sizeof rec, &have_rec, err,
                            sizeof err) != 0)
        return data_error(c, "%s", err);
    if (have_rec) {
        if (amfi_level_params_parse(rec, &mf, why, sizeof why) != 0)
            return data_error(c, "meta alerts.model_fit: %s", why);
        mf_from = "amfid's, from the store";
    } else if (cfg) {
        mf = cfg->daemon.model_fit;
        mf_from = "--config";
    } else {
        amfi_site_config *d = malloc(sizeof *d);
        if (!d)
            return data_error(c, "out of memory");
        amfi_config_defaults(d);
        mf = d->daemon.model_fit;
        free(d);
    }
    if (cfg) {
        if (!found) {
            snprintf(site, sizeof site, "%s", cfg->site.name);
            found = 1;
        }
    }
    if (!found) {
        const char *b = strrchr(o->db, '/');
        snprintf(site, sizeof site, "%s", b ? b + 1 : o->db);
    }
    /* every section's plots in their places */
    enum { MAX_PLOTS = N_SECTIONS * MAX_SECTION_PLOTS };
    const plot_def *order[MAX_PLOTS], *made[MAX_PLOTS];
    int n_plots = 0, n_made = 0, rc = 0;
    for (int k = 0; k < N_SECTIONS; k++)
        for (int j = 0; j < MAX_SECTION_PLOTS && sections[k].plots[j].place > 0; j++) {
            int i = n_plots++;
            for (; i > 0 && order[i - 1]->place > sections[k].plots[j].place; i--)
                order[i] = order[i - 1];
            order[i] = &sections[k].plots[j];
        }
    report_plot_frame p;
    rc = report_plot_begin(&p, s, o->plot_dir, site, &ip, o->ex.from, o->ex.to, err, sizeof err);
    p.ip_from = ip_from;
    p.mf = &mf;
    p.mf_from = mf_from;
    p.units = c->units;
    for (int i = 0; rc == 0 && i < n_plots; i++) {
        int drawn = 0;
        rc = order[i]->draw(&p, &drawn, err, sizeof err);
        if (rc == 0 && drawn)
            made[n_made++] = order[i];
    }
    if (rc == 0)
        rc = report_plot_run(&p, err, sizeof err);
    for (int i = 0; rc == 0 && i < n_made; i++)
        rc = report_plot_listed(&p, made[i]->png, made[i]->what, err, sizeof err);
    report_plot_free(&p);
    if (rc != 0) {
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
        rc = report_pg_fleet(o.pg, o.allow_plaintext,
                             o.format == FMT_CSV ? "csv" : o.format == FMT_JSON ? "json" : NULL,
                             stdout, err, sizeof err);
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
    report_ctx c;
    char err[512];
    int rc = 0, printed = 0;
    memset(&c, 0, sizeof c);
    c.name = o.pg ? o.site : o.db;
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
    if (amfi_store_open_readonly(o.db, &c.s, err, sizeof err) != 0) {
        /* the store's message starts with the path already */
        fprintf(stderr, PROG ": %s\n", err);
        free(cfg);
        return EXIT_DATA;
    }
    c.db = o.db;
    c.site = o.site;
    c.format = o.format;
    c.cfg = o.config ? cfg : NULL;
    /* the classes and limits: what amfid ran with (meta daemon.classes),
     * else --config's, else the defaults */
    static amfi_class_params recorded;
    char rec[4097];
    int have_rec = 0;
    c.classes = &cfg->classes;
    c.classes_from = o.config ? "--config" : "built-in defaults";
    if (amfi_store_meta_get(c.s, "daemon.classes", rec, sizeof rec, &have_rec, err,
                            sizeof err) != 0) {
        data_error(&c, "%s", err);
        amfi_store_close(c.s);
        free(cfg);
        return EXIT_DATA;
    }
    if (have_rec) {
        char why[256];
        if (amfi_class_params_parse(rec, &recorded, why, sizeof why) != 0) {
            data_error(&c, "meta daemon.classes: %s", why);
            amfi_store_close(c.s);
            free(cfg);
            return EXIT_DATA;
        }
        c.classes = &recorded;
        c.classes_from = "amfid's, from the store";
    }
    c.units = o.units >= 0 ? o.units : cfg->report.units;
    c.out = stdout;
    /* the sections shown by default only when the store has their data */
    for (int k = 0; k < N_SECTIONS; k++) {
        if (o.sel[k] != 2)
            continue;
        int yes = 0;
        if (sections[k].default_if(c.s, &yes, err, sizeof err) != 0) {
            data_error(&c, "%s", err);
            amfi_store_close(c.s);
            free(cfg);
            return EXIT_DATA;
        }
        o.sel[k] = yes;
    }
    if (o.format != FMT_TABLE) {
        rc = export_all(&o, &c);
        amfi_store_close(c.s);
        free(cfg);
        fflush(stdout);
        return rc == 0 ? 0 : EXIT_DATA;
    }
    if (o.baseline_last || o.baseline_given) {
        rc = set_baseline(&o, &c);
        printed = rc == 0;
    }
    for (int k = 0; rc == 0 && k < N_SECTIONS; k++)
        if (o.sel[k])
            rc = run_section(&o, &c, k, &printed);
    if (rc == 0 && o.plot_dir) {
        if (printed)
            printf("\n");
        rc = plot(&o, o.config ? cfg : NULL, &c);
        printed = 1;
    }
    if (rc == 0 && o.check) {
        char result[1024];
        int st = amfi_store_integrity_check(c.s, result, sizeof result, err, sizeof err);
        if (printed)
            printf("\n");
        printf("integrity    %s\n", result);
        if (st != 0 || strcmp(result, "ok") != 0)
            rc = data_error(&c, "integrity check failed: %s", result);
    }
    if (rc == 0 && (o.sel[SEC_SUMMARY] || o.sel[SEC_TREND] || o.sel[SEC_ALERTS]
                    || o.sel[SEC_ERRORS] || o.baseline_last || o.baseline_given))
        print_next(&o);
    amfi_store_close(c.s);
    free(cfg);
    fflush(stdout);
    return rc == 0 ? 0 : EXIT_DATA;
}
