/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_classes.h: amfi-report's statistics per vehicle class
 * (report_classes.c), from the class amfid stored with each ok passage
 * (passages.class, store version 10; "unclassified" for rows without one):
 *   --classes          per class, over all lanes and per lane: passages,
 *                      share, GVW mean, STD, p5, median, p95, max, and the
 *                      passages amfid flagged overloaded (passages.overload);
 *   --class-histogram  the GVW histogram of each class (--bin-kg bins).
 * Tables, CSV and JSON through report_cols.h's column lists. Both honour
 * --from, --to and --lane. At most REPORT_MAX_CLASSES distinct class names
 * are kept apart (the rest counted as "other"). Memory: 16 bytes per ok
 * passage of the selection. Single-threaded.
 */
#ifndef REPORT_CLASSES_H
#define REPORT_CLASSES_H

#include "report.h"

#define REPORT_MAX_CLASSES 64

/* Sections: 0, or −1 with the message in c->err. */
int classes_table(report_ctx *c);
int classes_export(report_ctx *c);
int class_histogram_table(report_ctx *c);
int class_histogram_export(report_ctx *c);

#endif /* REPORT_CLASSES_H */
