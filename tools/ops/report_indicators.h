/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_indicators.h: amfi-report's damage indicators and alerts
 * (report_indicators.c): --trend (the table shows the last
 * REPORT_TREND_ROWS indicator rows, CSV and JSON every one) and --alerts
 * (the table shows the alerts open now and the last REPORT_ALERT_ROWS rows,
 * CSV and JSON every one); trend.png (STD ratio, p-value and mean ratio
 * against the alert thresholds, every alert raised or cleared marked).
 * Single-threaded.
 */
#ifndef REPORT_INDICATORS_H
#define REPORT_INDICATORS_H

#include "report.h"
#include "report_plot.h"

#define REPORT_TREND_ROWS 20 /* indicators shown by --trend */
#define REPORT_ALERT_ROWS 20 /* alerts shown by --alerts */

/* Sections: 0, or −1 with the message in c->err. */
int trend_table(report_ctx *c);
int trend_export(report_ctx *c);
int alerts_table(report_ctx *c);
int alerts_export(report_ctx *c);

/* trend.png (report_plot_fn); writes indicators.dat and alerts.dat. */
int indicators_plot_trend(report_plot_frame *p, int *made, char *err, size_t errlen);

#endif /* REPORT_INDICATORS_H */
