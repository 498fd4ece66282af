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

/* The plots' data under data_dir (scale.dat, known_truck.dat,
 * temperature.dat) and their gnuplot commands appended to gp, which draw
 * scale.png, known_truck.png and temperature.png into png_dir (a panel
 * saying "none yet" when there is nothing). 0, or −1 with the message in
 * err. */
int report_scale_plots(amfi_store *s, const char *data_dir, const char *png_dir, FILE *gp,
                       char *err, size_t errlen);

#endif /* REPORT_SCALE_H */
