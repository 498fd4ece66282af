/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_natfreq.h: amfi-report's natural-frequency lines (issue 14, item
 * 4): the bridge's first natural frequency amfid estimated from each
 * passage's free vibration, raw and compensated for the deck temperature,
 * as a summary line (and one for the estimates amfid refused, from the
 * meta table's natfreq.* counters), its figures for the CSV and JSON
 * summary (report_export.c) and, with --plot, natfreq.png
 * (report_natfreq.c). Single-threaded; the store is read through store/
 * only (amfi_store_f1_series, amfi_store_meta_get).
 */
#ifndef REPORT_NATFREQ_H
#define REPORT_NATFREQ_H

#include <stddef.h>
#include <stdio.h>

#include "report_plot.h"
#include "store.h"

/* The figures of the summary: every passage with an f1, raw and
 * compensated (means and SDs in Hz; NaN when n is 0, SD when n < 2). */
typedef struct natfreq_stats {
    size_t n, n_comp;
    double mean_hz, sd_hz, comp_mean_hz, comp_sd_hz;
} natfreq_stats;

/* 0, or −1 with the store's message in err. */
int natfreq_read_stats(amfi_store *s, natfreq_stats *st, char *err, size_t errlen);

/* The summary's lines into line (""when the store holds no f1): "natural
 * f1 ..." and, when amfid recorded refusals, "  not estimated ...". 0, or
 * −1 with the store's message in err. */
int natfreq_summary(amfi_store *s, char *line, size_t len, char *err, size_t errlen);

/* natfreq.png (report_plot_fn): writes dir/data/natfreq.dat (time, raw,
 * compensated, damping) and appends the plot's commands to the script, when
 * the store holds an f1 (else nothing is written). */
int natfreq_plot(report_plot_frame *p, int *made, char *err, size_t errlen);

#endif /* REPORT_NATFREQ_H */
