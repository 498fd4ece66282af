/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report.h: what every part of amfi-report shares: the output formats, the
 * passage filter (--from --to --status --lane, the histogram's bin, the
 * legal limits), the report context handed to every section instead of
 * globals, and the small helpers every subject file uses (statistics, UTC
 * times, one message per failure) from report_util.c, which calls no other
 * report file.
 *
 * The files, one per subject:
 *   amfi-report.c        options, the table of sections, dispatch, baseline,
 *                        check
 *   report_summary.c     --summary and --errors
 *   report_indicators.c  --trend and --alerts; trend.png
 *   report_passages.c    --passages, --histogram, --overloads; gvw.png,
 *                        gvw_histogram.png, passages_per_hour.png, speed.png
 *   report_speed.c       --speed; speed_correction.png
 *   report_classes.c     --classes and --class-histogram
 *   report_scale.c       the scale and known-truck lines; scale.png,
 *                        known_truck.png, temperature.png
 *   report_natfreq.c     the natural-frequency lines; natfreq.png
 *   report_residual.c    the solver's residual line; residual.png
 *   report_pg.c          --pg: the fleet and one site from PostgreSQL
 *   report_cols.c        CSV and JSON of a column list (report_cols.h)
 *   report_plot.c        gnuplot helpers and the plot frame (report_plot.h)
 *   report_util.c        statistics, times, the failure message
 *
 * Who calls whom (tests/common/call_graph.sh reads it from the objects
 * with nm, fails on a circle and when this list differs; report_cols.c,
 * report_plot.c, report_util.c and report_pg.c call no report file):
 *   amfi-report.c -> report_classes.c report_indicators.c report_natfreq.c report_passages.c report_pg.c
 *   amfi-report.c -> report_plot.c report_residual.c report_scale.c report_speed.c report_summary.c
 *   amfi-report.c -> report_util.c
 *   report_classes.c -> report_cols.c report_util.c
 *   report_indicators.c -> report_cols.c report_plot.c report_util.c
 *   report_natfreq.c -> report_plot.c
 *   report_passages.c -> report_cols.c report_plot.c report_util.c
 *   report_residual.c -> report_plot.c report_util.c
 *   report_scale.c -> report_plot.c
 *   report_speed.c -> report_cols.c report_plot.c report_util.c
 *   report_summary.c -> report_cols.c report_natfreq.c report_residual.c report_scale.c report_util.c
 *
 * Single-threaded, the caller's thread; the store is read through store/.
 */
#ifndef REPORT_H
#define REPORT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <jansson.h>

#include "amfi_config.h"
#include "store.h"

enum { FMT_TABLE, FMT_CSV, FMT_JSON };

/* The passages a section reads, and its parameters. */
typedef struct export_opts {
    int64_t from, to;      /* utime range, µs, inclusive */
    const char *status;    /* NULL: every status */
    int lane, lane_given;  /* --lane */
    double bin_kg;         /* histogram bin width, kg */
    double gvw_limit_kg;   /* legal limits for --overloads, kg */
    double axle_limit_kg;
} export_opts;

/* What a section works with. The dispatcher (amfi-report.c) fills it; a
 * section writes to out (the table, the CSV, the streamed JSON passage
 * array) or adds its object to root (JSON), and on failure returns −1 with
 * a one-line message in err (printed as "amfi-report: DB: err"). */
typedef struct report_ctx {
    amfi_store *s;                /* the store, opened read-only */
    const char *db;               /* its path */
    const char *name;             /* what messages name: db, or the site with --pg */
    const char *site;             /* --site with --pg, else NULL */
    export_opts ex;               /* the filter and parameters of this section */
    int format;                   /* FMT_* */
    FILE *out;
    json_t *root;                 /* FMT_JSON: the document */
    const amfi_site_config *cfg;  /* --config, or NULL */
    const amfi_class_params *classes; /* amfid's (meta daemon.classes), else --config's, else the defaults */
    const char *classes_from;     /* which of the three, for the output */
    int units;                    /* AMFI_REPORT_UNITS_*: of the tables (not CSV, JSON) */
    char err[512];
} report_ctx;

/* printf into c->err; returns −1. */
int report_fail(report_ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Mean and sample STD of v[0 .. n−1] (two passes; NaN when n is 0, STD
 * NaN when n < 2). */
void report_mean_std(const double *v, size_t n, double *mean, double *std);
/* Sort v[0 .. n−1] in place; then report_percentile gives the nearest-rank
 * percentile p (0 < p <= 100) of the sorted values (NaN when n is 0). */
void report_sort(double *v, size_t n);
double report_percentile(const double *v, size_t n, double p);

/* utime (µs since 1970) as strftime's fmt in UTC into buf (the number of
 * µs when it cannot be shown); returns buf. */
const char *report_utc_fmt(int64_t utime, const char *fmt, char buf[32]);
/* "2025-11-22T13:05:09Z" */
const char *report_iso(int64_t utime, char buf[32]);
/* "2025-11-22 13:05:09" ("N us" when it cannot be shown) */
const char *report_utc(long long utime, char buf[32]);
/* "42 s", "3.5 min", "2.0 h", "3.1 days" */
const char *report_duration(double s, char buf[32]);
/* "-" for NaN, else printf of fmt into buf. */
const char *report_num(double x, const char *fmt, char buf[32]);

/* The units of the tables and plots (units: AMFI_REPORT_UNITS_*): a mass in
 * kg ("%.0f") or t ("%.2f"), a speed in m/s ("%.2f") or km/h ("%.1f"); the
 * value, its unit, and the number as text ("-" for NaN). CSV and JSON stay
 * in kg and m/s. */
double report_mass_val(int units, double kg);
const char *report_mass_unit(int units);
const char *report_mass(int units, double kg, char buf[32]);
double report_speed_val(int units, double mps);
const char *report_speed_unit(int units);
const char *report_speed(int units, double mps, char buf[32]);

/* ISO 8601 in UTC: "2025-11-22", "2025-11-22T13:05", "2025-11-22 13:05:09",
 * "2025-11-22T13:05:09.25", each with an optional Z or zero offset (+00:00):
 * µs since 1970. end_of = 1 (for --to) makes a date, a minute or a second
 * its last µs. 0, or −1 with what could not be parsed in why (a missing
 * part, a field out of range naming it, another offset, trailing text). */
int report_parse_time(const char *s, int end_of, int64_t *utime, char *why, size_t whylen);

#endif /* REPORT_H */
