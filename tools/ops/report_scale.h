/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_scale.h: amfi-report's view of the scale indicator and the
 * known-truck runs (issue 14, docs/indicators.md section 8): summary lines
 * (the newest block's raw and temperature-compensated scale and CUSUM
 * against its threshold, the range over all blocks; the known-truck
 * ratios) and their plots (report_scale.c). Single-threaded; the store is read
 * through store/ only (amfi_store_scale_evals, the environment table).
 */
#ifndef REPORT_SCALE_H
#define REPORT_SCALE_H

#include <stddef.h>
#include <stdio.h>

#include "report_plot.h"
#include "store.h"

/* The summary lines (nothing when amfid evaluated neither), written to f.
 * 0, or −1 with the store's message in err. */
int report_scale_summary(amfi_store *s, FILE *f, char *err, size_t errlen);

/* The plots (report_plot_fn), each drawn when the store has its data, with
 * its data file under dir/data/: scale.png (raw and compensated scale,
 * CUSUM against its threshold; scale.dat), known_truck.png (the runs'
 * ratios; known_truck.dat) and temperature.png (deck and air;
 * temperature.dat). */
int scale_plot_scale(report_plot_frame *p, int *made, char *err, size_t errlen);
int scale_plot_known_truck(report_plot_frame *p, int *made, char *err, size_t errlen);
int scale_plot_temperature(report_plot_frame *p, int *made, char *err, size_t errlen);

#endif /* REPORT_SCALE_H */
