/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_summary.h: amfi-report's --summary (passages by status, GVW of the
 * ok passages and of what the indicator rules were fed, amfid's intake
 * counters, the temperature, the scale and natural-frequency lines, the
 * baseline in force) and --errors (inferred GVW against the truth of
 * simulations), as tables and as CSV and JSON items (report_summary.c).
 * Single-threaded.
 */
#ifndef REPORT_SUMMARY_H
#define REPORT_SUMMARY_H

#include "report.h"

/* Sections: 0, or −1 with the message in c->err. */
int summary_table(report_ctx *c);
int summary_export(report_ctx *c);
int errors_table(report_ctx *c);
int errors_export(report_ctx *c);

#endif /* REPORT_SUMMARY_H */
