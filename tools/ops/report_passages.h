/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_passages.h: amfi-report's passage sections (report_passages.c):
 * --passages (one line per passage: time, lane, speed, axles, GVW, axle
 * loads, status, reason), --histogram (GVW of the ok passages per lane) and
 * --overloads (ok passages over the legal GVW or axle limit; those whose
 * loads the classification refused listed apart, never as overloads), as
 * tables and as CSV and JSON (report_cols.h); and the plots of the
 * passages: gvw.png, gvw_histogram.png, passages_per_hour.png and
 * speed.png. The passages are streamed (amfi_store_each_passage_where,
 * filtered in SQL): a year of traffic is never held in memory (the
 * --overloads table keeps only the refused passages for its last section,
 * about 200 bytes each: a broken solve, rare); the passage list is written
 * row by row in every format (in JSON, element by element to c->out: the
 * caller writes the document around it). Single-threaded.
 */
#ifndef REPORT_PASSAGES_H
#define REPORT_PASSAGES_H

#include "report.h"
#include "report_plot.h"

/* Sections: 0, or −1 with the message in c->err. On an error the passage
 * list is cut short. */
int passages_table(report_ctx *c);
int passages_export(report_ctx *c);
int histogram_table(report_ctx *c);
int histogram_export(report_ctx *c);
int overloads_table(report_ctx *c);
int overloads_export(report_ctx *c);

/* Plots (report_plot_fn). */
int passages_plot_gvw(report_plot_frame *p, int *made, char *err, size_t errlen);
int passages_plot_histogram(report_plot_frame *p, int *made, char *err, size_t errlen);
int passages_plot_per_hour(report_plot_frame *p, int *made, char *err, size_t errlen);
int passages_plot_speed(report_plot_frame *p, int *made, char *err, size_t errlen);

#endif /* REPORT_PASSAGES_H */
