/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_plot.h: amfi-report --plot: PNGs of a store drawn with gnuplot
 * (report_plot.c). Single-threaded, the caller's thread; the store handle
 * stays the caller's.
 */
#ifndef REPORT_PLOT_H
#define REPORT_PLOT_H

#include <stddef.h>
#include <stdio.h>

#include "indicators.h"
#include "store.h"

/* Write into `dir` (created if missing) gvw.png, trend.png,
 * gvw_histogram.png, passages_per_hour.png and speed.png (and
 * speed_correction.png when the store has estimated speeds; scale.png,
 * known_truck.png and temperature.png when it has scale blocks, known-truck
 * runs and environment readings, report_scale.h; natfreq.png when it has
 * natural frequencies, report_natfreq.h), plus their data
 * and the gnuplot script under dir/data/ (alerts.dat holds one line per
 * alert row). `site` titles every plot; `ip` gives the alert thresholds.
 * Prints one line per PNG ("plot  PATH  what") on stdout. Returns 0, or −1
 * with a one-line message in err. */
int report_plot(amfi_store *s, const char *dir, const char *site,
                const amfi_indicator_params *ip, char *err, size_t errlen);

/* dir/data/name opened for writing, or NULL with the message in err; closed
 * with report_data_close (0, or −1 when a write failed). */
FILE *report_data_open(const char *dir, const char *name, char *err, size_t errlen);
int report_data_close(FILE *f, const char *dir, const char *name, char *err, size_t errlen);

#endif /* REPORT_PLOT_H */
