/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_residual.h: amfi-report's view of the solver's fit per ok passage
 * (passages.residual_rms, the RMS of the measured minus the modelled
 * response, m/s², and quality, the separability from the event's other
 * vehicles): its figures for --summary (a "residual" line, and the items of
 * the CSV and JSON summary) and, with --plot, residual.png
 * (report_residual.c). A residual that grows while the traffic does not
 * change says the bridge no longer behaves as its model: the oldest and
 * the newest REPORT_RESIDUAL_WINDOW passages are set side by side.
 * And amfid's model fit (passages.fit_ratio, docs/indicators.md section
 * 10): with --plot, fit_ratio.png, each passage's fit ratio, the running
 * median the model_mismatch rule watches and its raise and clear levels.
 * Single-threaded; the store is read through amfi_store_residual_series
 * and amfi_store_fit_ratio_series.
 */
#ifndef REPORT_RESIDUAL_H
#define REPORT_RESIDUAL_H

#include <stddef.h>

#include "report_plot.h"
#include "store.h"

#define REPORT_RESIDUAL_WINDOW 50 /* passages: the oldest and newest medians, the plot's running median */

/* The figures of the ok passages with a residual (NaN when n is 0). */
typedef struct residual_stats {
    size_t n;
    double median, p95;                /* m/s² */
    double first_median, last_median; /* of the oldest and the newest window, m/s² */
    double growth;                     /* last_median / first_median */
    double quality_median;             /* NaN when no quality is stored */
} residual_stats;

/* 0, or −1 with the store's message in err. */
int residual_read_stats(amfi_store *s, residual_stats *st, char *err, size_t errlen);

/* The summary's "residual ..." line into line ("" when no ok passage has a
 * residual). 0, or −1 with the store's message in err. */
int residual_summary(amfi_store *s, char *line, size_t len, char *err, size_t errlen);

/* residual.png (report_plot_fn): writes dir/data/residual.dat (time,
 * residual, quality, running median) and appends the plot's commands, when
 * an ok passage of the plots' range has a residual. */
int residual_plot(report_plot_frame *p, int *made, char *err, size_t errlen);

/* fit_ratio.png (report_plot_fn): writes dir/data/fit_ratio.dat (time,
 * fit ratio, the median of the last p->mf->window ratios once that many
 * are there: what amfid's rule compares) and appends the plot's commands
 * with p->mf's raise and clear levels, when a passage of the plots' range
 * has a fit ratio. */
int fit_ratio_plot(report_plot_frame *p, int *made, char *err, size_t errlen);

#endif /* REPORT_RESIDUAL_H */
