/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_speed.h: amfi-report --speed: the speed corrections of the
 * passages whose speed amfid estimated (solver.speed: estimate, issue 12):
 * the distribution of c = speed weighed with / detector's speed − 1 over the
 * selected passages (--from, --to, --lane), and its drift, one line per UTC
 * day, in the table, CSV and JSON formats (report_cols.h); and
 * speed_correction.png, the daily median with its p5-p95 band
 * (report_speed.c). Single-threaded; the store is read through store/ only
 * (amfi_store_speed_pairs).
 */
#ifndef REPORT_SPEED_H
#define REPORT_SPEED_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <jansson.h>

#include "report.h"
#include "report_plot.h"
#include "store.h"

/* Statistics of corrections, in % (c · 100). Percentiles are nearest-rank
 * (report_percentile), as in the report's other sections; NaN when n is 0
 * (std: n < 2). */
typedef struct speed_stats {
    size_t n;
    double median, p5, p25, p75, p95, mean, std;
    double over1, over3; /* share of the n with |c| > 1 %, > 3 %, in % */
} speed_stats;

/* One UTC day of corrections. */
typedef struct speed_day {
    int64_t day_utime; /* 00:00 UTC of the day, µs */
    speed_stats st;
} speed_day;

/* The corrections of the estimated passages o selects: *all over them, and
 * one entry per UTC day that has any, oldest first (*days malloc'd, free
 * it; NULL when *ndays is 0). 0, or −1 with the store's message in err. */
int speed_corrections(amfi_store *s, const export_opts *o, speed_stats *all, speed_day **days,
                      size_t *ndays, char *err, size_t errlen);

/* The section, written to c->out (table, CSV) or added to c->root as
 * "speed" (JSON). 0, or −1 with the store's message in c->err. */
int speed_table(report_ctx *c);
int speed_export(report_ctx *c);

/* speed_correction.png (report_plot_fn), when the store has estimated
 * speeds; writes speed_correction.dat. */
int speed_plot_correction(report_plot_frame *p, int *made, char *err, size_t errlen);

#endif /* REPORT_SPEED_H */
