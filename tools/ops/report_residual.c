/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_residual.c: the solver's residual per ok passage in the summary
 * and residual.png, and the model fit's fit_ratio.png (report_residual.h). Single-threaded, the caller's
 * thread.
 */
#include "report_residual.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "report.h"

/* The median of v[0 .. n−1] (copied, sorted). NaN when n is 0 or no memory. */
static double median_of(const double *v, size_t n)
{
    if (n == 0)
        return NAN;
    double *w = malloc(n * sizeof *w);
    if (!w)
        return NAN;
    memcpy(w, v, n * sizeof *w);
    report_sort(w, n);
    double m = report_percentile(w, n, 50);
    free(w);
    return m;
}

int residual_read_stats(amfi_store *s, residual_stats *st, char *err, size_t errlen)
{
    amfi_residual_rec *a = NULL;
    size_t n = 0;
    memset(st, 0, sizeof *st);
    st->median = st->p95 = st->first_median = st->last_median = st->growth = NAN;
    st->quality_median = NAN;
    if (amfi_store_residual_series(s, 0, AMFI_STORE_MAX_UTIME, &a, &n, err, errlen) != 0)
        return -1;
    st->n = n;
    if (n == 0)
        return 0;
    double *v = malloc(n * sizeof *v), *q = malloc(n * sizeof *q);
    if (!v || !q) {
        free(v);
        free(q);
        free(a);
        snprintf(err, errlen, "out of memory for %zu residuals", n);
        return -1;
    }
    size_t nq = 0;
    for (size_t i = 0; i < n; i++) {
        v[i] = a[i].residual_rms;
        if (isfinite(a[i].quality))
            q[nq++] = a[i].quality;
    }
    free(a);
    const size_t w = n < REPORT_RESIDUAL_WINDOW ? n : REPORT_RESIDUAL_WINDOW;
    st->first_median = median_of(v, w);
    st->last_median = median_of(v + (n - w), w);
    st->growth = st->first_median > 0 ? st->last_median / st->first_median : NAN;
    report_sort(v, n);
    st->median = report_percentile(v, n, 50);
    st->p95 = report_percentile(v, n, 95);
    if (nq > 0) {
        report_sort(q, nq);
        st->quality_median = report_percentile(q, nq, 50);
    }
    free(v);
    free(q);
    return 0;
}

int residual_summary(amfi_store *s, char *line, size_t len, char *err, size_t errlen)
{
    residual_stats st;
    line[0] = '\0';
    if (residual_read_stats(s, &st, err, errlen) != 0)
        return -1;
    if (st.n == 0)
        return 0;
    char g[32] = "-", qm[32] = "-";
    if (isfinite(st.growth))
        snprintf(g, sizeof g, "x %.2f", st.growth);
    if (isfinite(st.quality_median))
        snprintf(qm, sizeof qm, "%.3g", st.quality_median);
    snprintf(line, len,
             "residual     n %zu, median %.3g m/s², p95 %.3g m/s²; oldest %d median %.3g, "
             "newest %d median %.3g (%s); quality median %s\n",
             st.n, st.median, st.p95,
             (int)(st.n < REPORT_RESIDUAL_WINDOW ? st.n : REPORT_RESIDUAL_WINDOW),
             st.first_median,
             (int)(st.n < REPORT_RESIDUAL_WINDOW ? st.n : REPORT_RESIDUAL_WINDOW), st.last_median,
             g, qm);
    return 0;
}

int residual_plot(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    amfi_residual_rec *a = NULL;
    size_t n = 0;
    if (amfi_store_residual_series(p->s, p->from, p->to, &a, &n, err, errlen) != 0)
        return -1;
    if (n == 0) {
        free(a);
        return 0;
    }
    double *win = malloc(REPORT_RESIDUAL_WINDOW * sizeof *win);
    FILE *f = win ? report_data_open(p->dir, "residual.dat", err, errlen) : NULL;
    if (!f) {
        if (!win)
            snprintf(err, errlen, "out of memory");
        free(win);
        free(a);
        return -1;
    }
    size_t positive = 0;
    double lo = HUGE_VAL, hi = 0;
    fprintf(f, "# time_s residual_rms_mps2 quality running_median_mps2 (the last %d passages)\n",
            REPORT_RESIDUAL_WINDOW);
    for (size_t i = 0; i < n; i++) {
        size_t w = i + 1 < REPORT_RESIDUAL_WINDOW ? i + 1 : REPORT_RESIDUAL_WINDOW;
        for (size_t j = 0; j < w; j++)
            win[j] = a[i + 1 - w + j].residual_rms;
        report_sort(win, w);
        fprintf(f, "%.3f %.6g %.6g %.6g\n", (double)a[i].utime / 1e6, a[i].residual_rms,
                isfinite(a[i].quality) ? a[i].quality : NAN, report_percentile(win, w, 50));
        positive += a[i].residual_rms > 0;
        lo = fmin(lo, a[i].residual_rms);
        hi = fmax(hi, a[i].residual_rms);
    }
    free(win);
    free(a);
    if (report_data_close(f, p->dir, "residual.dat", err, errlen) != 0)
        return -1;
    /* the y range set (gnuplot warns on an empty one): on a log axis a
     * factor 2 around the values, else from 0 */
    char yr[160];
    if (positive == n)
        snprintf(yr, sizeof yr, "set logscale y\nset format y '%%.0e'\nset yrange [%.6g:%.6g]\n",
                 lo / 2, hi * 2);
    else
        snprintf(yr, sizeof yr, "set yrange [0:%.6g]\n", hi > 0 ? hi * 1.1 : 1.0);
    fprintf(p->gp,
            "unset label 99\nset output o.'residual.png'\n"
            "set xdata time\nset timefmt '%%s'\nset format x \"%%H:%%M\\n%%d %%b\"\n"
            "set autoscale x\n%s"
            "set title \"Solver residual per ok passage (RMS of measured - modelled response)\\n%s\"\n"
            "set xlabel 'time (UTC, data time)'\nset ylabel 'residual RMS (m/s²)'\n"
            "plot d.'residual.dat' using 1:2 with points pt 7 ps 0.4 lc rgb '#aaaaaa' title 'per passage', \\\n"
            "     d.'residual.dat' using 1:4 with lines lw 2 lc rgb '#d62728' title 'running median of %d'\n"
            "unset logscale y\nset format y '%%g'\nset autoscale y\nset output\n",
            yr, p->sub,
            REPORT_RESIDUAL_WINDOW);
    *made = 1;
    return 0;
}

int fit_ratio_plot(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    amfi_fit_rec *a = NULL;
    size_t n = 0;
    if (amfi_store_fit_ratio_series(p->s, p->from, p->to, &a, &n, err, errlen) != 0)
        return -1;
    if (n == 0) {
        free(a);
        return 0;
    }
    const amfi_level_params *mf = p->mf;
    const size_t W = (size_t)mf->window;
    double *win = malloc(W * sizeof *win);
    FILE *f = win ? report_data_open(p->dir, "fit_ratio.dat", err, errlen) : NULL;
    if (!f) {
        if (!win)
            snprintf(err, errlen, "out of memory for a window of %zu", W);
        free(win);
        free(a);
        return -1;
    }
    size_t positive = 0;
    double lo = HUGE_VAL, hi = 0;
    fprintf(f, "# time_s fit_ratio median_of_last_%zu (nan: fewer passages)\n", W);
    for (size_t i = 0; i < n; i++) {
        double med = NAN;
        if (i + 1 >= W) {
            for (size_t j = 0; j < W; j++)
                win[j] = a[i + 1 - W + j].fit_ratio;
            report_sort(win, W);
            med = report_percentile(win, W, 50);
        }
        fprintf(f, "%.3f %.6g %.6g\n", (double)a[i].utime / 1e6, a[i].fit_ratio, med);
        positive += a[i].fit_ratio > 0;
        lo = fmin(lo, a[i].fit_ratio);
        hi = fmax(hi, a[i].fit_ratio);
    }
    free(win);
    free(a);
    if (report_data_close(f, p->dir, "fit_ratio.dat", err, errlen) != 0)
        return -1;
    /* the y range holds the values and both levels: on a log axis a factor
     * 2 around them, else from 0 (a ratio of 0 has no place on a log axis) */
    const double top = fmax(hi, mf->raise), bottom = fmin(lo, mf->clear);
    char yr[160];
    if (positive == n && bottom > 0)
        snprintf(yr, sizeof yr, "set logscale y\nset format y '%%g'\nset yrange [%.6g:%.6g]\n",
                 bottom / 2, top * 2);
    else
        snprintf(yr, sizeof yr, "set yrange [0:%.6g]\n", top > 0 ? top * 1.1 : 1.0);
    fprintf(p->gp,
            "unset label 99\nset output o.'fit_ratio.png'\n"
            "set xdata time\nset timefmt '%%s'\nset format x \"%%H:%%M\\n%%d %%b\"\n"
            "set autoscale x\n%s"
            "set title \"Model fit over the free vibration after each passage (model_mismatch; "
            "thresholds: %s%s)\\n%s\"\n"
            "set xlabel 'time (UTC, data time)'\n"
            "set ylabel 'fit ratio (RMS of model - data / RMS of data)'\n"
            "plot d.'fit_ratio.dat' using 1:2 with points pt 7 ps 0.4 lc rgb '#aaaaaa' title 'per passage', \\\n"
            "     d.'fit_ratio.dat' using 1:3 with lines lw 2 lc rgb '#1f77b4' title 'median of the last %d', \\\n"
            "     %.6g with lines dt 1 lc rgb '#d62728' title 'raise at >= %.4g (%d in a row)', \\\n"
            "     %.6g with lines dt 2 lc rgb '#2ca02c' title 'clear below %.4g (%d in a row)'\n"
            "unset logscale y\nset format y '%%g'\nset autoscale y\nset output\n",
            yr, p->mf_from ? p->mf_from : "built-in defaults",
            mf->enabled ? "" : ", the alert off", p->sub, mf->window, mf->raise, mf->raise,
            mf->raise_after, mf->clear, mf->clear, mf->clear_after);
    *made = 1;
    return 0;
}
