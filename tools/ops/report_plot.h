/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_plot.h: amfi-report --plot's gnuplot helpers (report_plot.c, which
 * calls no other report file): the plot frame (the directory, the script
 * being written, the site and subtitle, the time axis, and the passages,
 * indicators, alerts and baseline that several plots draw, read once), the
 * data files under DIR/data/, gnuplot's run and the PNG check. Each plot is
 * a function of its subject's file (report_plot_fn) that writes its data
 * files and appends its commands to the script; amfi-report.c's table of
 * sections calls them in order. Single-threaded, the caller's thread; the
 * store handle stays the caller's. Memory: four doubles per passage (a
 * million passages: 32 MB).
 */
#ifndef REPORT_PLOT_H
#define REPORT_PLOT_H

#include <stddef.h>
#include <stdio.h>

#include "indicators.h"
#include "level_rule.h"
#include "store.h"

/* One passage as the plots see it. */
typedef struct report_pas {
    double t;     /* s since 1970 */
    double gvw;   /* kg or NaN */
    double speed; /* m/s or NaN */
    int status;   /* index in amfi_store_status_name order */
} report_pas;

typedef struct report_plot_frame {
    amfi_store *s;
    const char *dir;                 /* --plot DIR */
    const amfi_indicator_params *ip; /* the alert thresholds */
    const char *ip_from;             /* where they come from, for the titles */
    const amfi_level_params *mf;     /* the model_mismatch rule (alerts.model_fit) */
    const char *mf_from;             /* where it comes from, for the title */
    int units;                       /* AMFI_REPORT_UNITS_*: of GVW and speed */
    int64_t from, to;                /* --from .. --to, µs: every plot draws only these */
    FILE *gp;                        /* DIR/data/plots.gp, being written */
    char gdir[8200];                 /* dir in a gnuplot single-quoted string */
    char site[128];                  /* the site, safe in a gnuplot string */
    char sub[256];                   /* the plots' subtitle: site, span, passages */
    double t0, t1;                   /* the time axis, s since 1970 */
    report_pas *pas;                 /* every passage, oldest first */
    size_t n_pas, cap_pas;
    amfi_indicator_rec *ind;         /* every indicator row, newest first */
    int n_ind;
    amfi_alert_rec *al;              /* every alert row, newest first */
    int n_al;
    amfi_baseline b;                 /* the baseline in force, when found */
    int found;
} report_plot_frame;

/* One plot: writes its data files and appends its commands to p->gp;
 * *made = 1 when it drew its PNG (a plot without data draws none). 0, or −1
 * with a one-line message in err. */
typedef int (*report_plot_fn)(report_plot_frame *p, int *made, char *err, size_t errlen);

/* Creates dir and dir/data, reads the shared data of [from, to] (µs; 0 and
 * AMFI_STORE_MAX_UTIME: all), opens the script and writes its preamble
 * (terminal, the d and o variables, the time axis). `site` titles every
 * plot; `ip` gives the alert thresholds. 0, or −1 with the message in err
 * (report_plot_free frees it either way). */
int report_plot_begin(report_plot_frame *p, amfi_store *s, const char *dir, const char *site,
                      const amfi_indicator_params *ip, int64_t from, int64_t to, char *err,
                      size_t errlen);
/* 1 when utime lies in the plots' range */
int report_plot_in_range(const report_plot_frame *p, int64_t utime);
/* Closes the script and runs gnuplot on it. 0, or −1 with err. */
int report_plot_run(report_plot_frame *p, char *err, size_t errlen);
/* A PNG gnuplot should have written: "plot  PATH  what" on stdout, or −1
 * with err. */
int report_plot_listed(const report_plot_frame *p, const char *png, const char *what, char *err,
                       size_t errlen);
void report_plot_free(report_plot_frame *p);

/* dir/data/name opened for writing, or NULL with the message in err; closed
 * with report_data_close (0, or −1 when a write failed). */
FILE *report_data_open(const char *dir, const char *name, char *err, size_t errlen);
int report_data_close(FILE *f, const char *dir, const char *name, char *err, size_t errlen);

/* A word from the store written to a data file (an alert's level and kind,
 * an indicator's state): one whitespace-free token of printable ASCII, so
 * that a line break or blank in the store cannot add rows or columns. */
const char *report_dat_word(const char *s, char out[64]);

/* Histogram of v[0..n) into nb bins from lo by w, as fractions. */
void report_hist(const double *v, size_t n, double lo, double w, int nb, double *out);

#endif /* REPORT_PLOT_H */
