/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_scale.h: amfi-report's view of the scale indicator and the
 * known-truck runs (issue 14, docs/indicators.md section 8): summary lines
 * (the newest block's raw and temperature-compensated scale and CUSUM
 * against its threshold, the range over all blocks; the known-truck
 * ratios) and the data files and gnuplot commands of their plots beside
 * report_plot.c's (report_scale.c). Single-threaded; the store is read
 * through store/ only (amfi_store_scale_evals, the environment table).
 */
#ifndef REPORT_SCALE_H
#define REPORT_SCALE_H

#include <stddef.h>
#include <stdio.h>

#include "store.h"

/* The summary lines (nothing when amfid evaluated neither), written to f.
 * 0, or −1 with the store's message in err. */
int report_scale_summary(amfi_store *s, FILE *f, char *err, size_t errlen);

/* The plots that have data: their data files under dir/data/ (scale.dat,
 * known_truck.dat, temperature.dat) and their gnuplot commands appended to
 * gp (the script of report_plot.c, its variables d and o set), drawing
 * scale.png (raw and compensated scale, CUSUM against its threshold, the
 * alerts), known_truck.png (the runs' ratios) and temperature.png (deck and
 * air). *which gets a bit per plot drawn (REPORT_SCALE_PNG_*). 0, or −1
 * with the message in err. */
#define REPORT_SCALE_PNG_SCALE 1
#define REPORT_SCALE_PNG_TRUCK 2
#define REPORT_SCALE_PNG_TEMPERATURE 4
int report_scale_plots(amfi_store *s, const char *dir, FILE *gp, const char *site, int *which,
                       char *err, size_t errlen);

#endif /* REPORT_SCALE_H */
