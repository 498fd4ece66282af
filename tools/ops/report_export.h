/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_export.h: amfi-report's sections as records for spreadsheets and
 * scripts (--format csv|json), and the sections that list or count
 * passages (--passages, --histogram, --overloads) in all three formats.
 * CSV is RFC 4180 (a header line, fields with a comma, a quote or a line
 * break quoted, quotes doubled); JSON goes through libjansson into one
 * document per run (report_export_json_*). Times are ISO 8601 UTC and, in
 * CSV and JSON, also µs since 1970 (utime). Single-threaded; the store is
 * read through store/ only.
 */
#ifndef REPORT_EXPORT_H
#define REPORT_EXPORT_H

#include <stdint.h>
#include <stdio.h>

#include <jansson.h>

#include "store.h"

enum { FMT_TABLE, FMT_CSV, FMT_JSON };

typedef struct export_opts {
    int64_t from, to;      /* utime range, µs, inclusive */
    const char *status;    /* NULL: every status */
    int lane, lane_given;  /* --lane */
    double bin_kg;         /* histogram bin width, kg */
    double gvw_limit_kg;   /* legal limits for --overloads, kg */
    double axle_limit_kg;
} export_opts;

/* One section, written to f (table, csv) or added to root under its name
 * (json). 0, or −1 with the store's message in err. */
int export_summary(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen);
int export_trend(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen);
int export_alerts(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen);
int export_errors(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen);
/* The passage list is written to f row by row in every format, JSON
 * included (a JSON array, element by element; root is not used): no whole
 * listing is ever held in memory. On an error the output is cut short. */
int export_passages(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root,
                    char *err, size_t errlen);
int export_histogram(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root,
                     char *err, size_t errlen);
int export_overloads(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root,
                     char *err, size_t errlen);

/* Mean and sample STD of v[0 .. n−1] (two passes; NaN when n is 0, STD
 * NaN when n < 2). */
void report_mean_std(const double *v, size_t n, double *mean, double *std);
/* Sort v[0 .. n−1] in place; then report_percentile gives the nearest-rank
 * percentile p (0 < p <= 100) of the sorted values (NaN when n is 0). */
void report_sort(double *v, size_t n);
double report_percentile(const double *v, size_t n, double p);

/* amfid's intake counters of its newest run (meta intake.*), if any. */
typedef struct report_intake {
    int found;
    long long run, received, refused, dropped, missing, lost;
    char as_of[40];
} report_intake;
int export_read_intake(amfi_store *s, report_intake *in, char *err, size_t errlen);

/* utime (µs since 1970) as strftime's fmt in UTC into buf (the number of
 * µs when it cannot be shown); returns buf. */
const char *export_utc(int64_t utime, const char *fmt, char buf[32]);

/* ISO 8601 in UTC: "2025-11-22", "2025-11-22T13:05", "2025-11-22 13:05:09",
 * "2025-11-22T13:05:09.25", each with an optional Z or zero offset (+00:00):
 * µs since 1970. end_of = 1 (for --to) makes a date, a minute or a second
 * its last µs. 0, or −1 with what could not be parsed in why (a missing
 * part, a field out of range naming it, another offset, trailing text). */
int export_parse_time(const char *s, int end_of, int64_t *utime, char *why, size_t whylen);

#endif /* REPORT_EXPORT_H */
