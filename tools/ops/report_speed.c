/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_speed.c: amfi-report's speed-corrections section (report_speed.h):
 * c = speed_mps / speed_given_mps − 1 of every estimated passage in the
 * selection, its distribution (median, p5, p25, p75, p95, mean, STD, the
 * share beyond ±1 % and ±3 %) and one line per UTC day (n, median, p5,
 * p95): a detector that slowly goes out of calibration shows as a drifting
 * daily median. The speeds are read once (24 bytes a passage: a year of a
 * busy site, 2 M passages, is 48 MB at most). Single-threaded.
 */
#define _GNU_SOURCE
#include "report_speed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "report_cols.h"

#define DAY_US INT64_C(86400000000)

/* Statistics of c[0 .. n−1] (fractions), which it sorts. */
static void stats_of(double *c, size_t n, speed_stats *st)
{
    size_t o1 = 0, o3 = 0;
    for (size_t k = 0; k < n; k++) {
        o1 += fabs(c[k]) > 0.01;
        o3 += fabs(c[k]) > 0.03;
    }
    report_mean_std(c, n, &st->mean, &st->std);
    report_sort(c, n);
    st->n = n;
    st->median = report_percentile(c, n, 50);
    st->p5 = report_percentile(c, n, 5);
    st->p25 = report_percentile(c, n, 25);
    st->p75 = report_percentile(c, n, 75);
    st->p95 = report_percentile(c, n, 95);
    double *v[] = {&st->median, &st->p5, &st->p25, &st->p75, &st->p95, &st->mean, &st->std};
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++)
        *v[k] *= 100.0;
    st->over1 = n ? 100.0 * (double)o1 / (double)n : NAN;
    st->over3 = n ? 100.0 * (double)o3 / (double)n : NAN;
}

int speed_corrections(amfi_store *s, const export_opts *o, speed_stats *all, speed_day **days,
                      size_t *ndays, char *err, size_t errlen)
{
    amfi_passage_filter f = {.from = o->from, .to = o->to, .status = NULL,
                             .lane_given = o->lane_given, .lane = o->lane};
    amfi_speed_pair *p = NULL;
    size_t n = 0, nd = 0;
    *days = NULL;
    *ndays = 0;
    if (amfi_store_speed_pairs(s, &f, &p, &n, err, errlen) != 0)
        return -1;
    double *c = malloc((n ? n : 1) * sizeof *c);
    speed_day *d = NULL;
    if (!c) {
        free(p);
        snprintf(err, errlen, "out of memory for %zu speed corrections", n);
        return -1;
    }
    /* the pairs are in time order: each day is one run of them */
    size_t cap = 0;
    for (size_t k = 0; k < n;) {
        int64_t day = p[k].utime / DAY_US;
        size_t e = k;
        while (e < n && p[e].utime / DAY_US == day) {
            c[e] = p[e].speed_mps / p[e].speed_given_mps - 1.0;
            e++;
        }
        if (nd == cap) {
            size_t nc = cap ? 2 * cap : 64;
            speed_day *nd2 = realloc(d, nc * sizeof *nd2);
            if (!nd2) {
                free(d), free(c), free(p);
                snprintf(err, errlen, "out of memory for %zu days of speed corrections", nc);
                return -1;
            }
            d = nd2;
            cap = nc;
        }
        d[nd].day_utime = day * DAY_US;
        double *tmp = malloc((e - k) * sizeof *tmp);
        if (!tmp) {
            free(d), free(c), free(p);
            snprintf(err, errlen, "out of memory for a day of speed corrections");
            return -1;
        }
        memcpy(tmp, c + k, (e - k) * sizeof *tmp);
        stats_of(tmp, e - k, &d[nd].st);
        free(tmp);
        nd++;
        k = e;
    }
    stats_of(c, n, all);
    free(c);
    free(p);
    *days = d;
    *ndays = nd;
    return 0;
}

static const char *day_str(int64_t utime, char buf[32])
{
    return report_utc_fmt(utime, "%Y-%m-%d", buf);
}

/* "%+.2f %%" or "-" */
static const char *pct(double x, char buf[32])
{
    if (isnan(x))
        return "-";
    snprintf(buf, 32, "%+.2f %%", fabs(x) < 0.005 ? 0.0 : x); /* never "-0.00 %" */
    return buf;
}

int speed_table(report_ctx *c)
{
    speed_stats all;
    speed_day *d = NULL;
    size_t nd = 0;
    char a[32], b[32], e[32], t[32];
    FILE *f = c->out;
    if (speed_corrections(c->s, &c->ex, &all, &d, &nd, c->err, sizeof c->err) != 0)
        return -1;
    fprintf(f, "== speed corrections (c = speed weighed with / detector's speed - 1)\n");
    if (all.n == 0) {
        fprintf(f, "(no estimated passages in the selection: amfid estimates the speed "
                   "with solver.speed: estimate)\n");
    } else {
        fprintf(f, "estimated    %zu passages, %s .. %s\n", all.n, day_str(d[0].day_utime, a),
                day_str(d[nd - 1].day_utime, b));
        if (isnan(all.std))
            snprintf(e, sizeof e, "-");
        else
            snprintf(e, sizeof e, "%.2f %%", all.std);
        fprintf(f, "c            median %s, mean %s, STD %s\n", pct(all.median, a),
                pct(all.mean, b), e);
        fprintf(f, "percentiles  p5 %s, p25 %s, ", pct(all.p5, a), pct(all.p25, b));
        fprintf(f, "p75 %s, ", pct(all.p75, a));
        fprintf(f, "p95 %s\n", pct(all.p95, b));
        fprintf(f, "|c| > 1 %%    %.1f %% of them; |c| > 3 %%: %.1f %%\n", all.over1,
                all.over3);
        fprintf(f, "%-10s  %6s  %9s  %9s  %9s\n", "day (UTC)", "n", "median", "p5", "p95");
        for (size_t k = 0; k < nd; k++)
            fprintf(f, "%-10s  %6zu  %9s  %9s  %9s\n", day_str(d[k].day_utime, t), d[k].st.n,
                    pct(d[k].st.median, a), pct(d[k].st.p5, b), pct(d[k].st.p95, e));
    }
    free(d);
    return 0;
}

/* One line of the CSV: "all" or a day, and its statistics. In JSON, "all"
 * is the section's object (COL_JSON) and each day an element of its "days"
 * (COL_JSON2, fewer figures). */
typedef struct speed_row {
    const char *day;
    const speed_stats *st;
} speed_row;

#define W(w) (((const speed_row *)(w))->st)
static void w_day(const void *w, report_val *v) { v->s = ((const speed_row *)w)->day; }
static void w_n(const void *w, report_val *v) { v->i = (int64_t)W(w)->n; }
static void w_median(const void *w, report_val *v) { v->x = W(w)->median; }
static void w_p5(const void *w, report_val *v) { v->x = W(w)->p5; }
static void w_p25(const void *w, report_val *v) { v->x = W(w)->p25; }
static void w_p75(const void *w, report_val *v) { v->x = W(w)->p75; }
static void w_p95(const void *w, report_val *v) { v->x = W(w)->p95; }
static void w_mean(const void *w, report_val *v) { v->x = W(w)->mean; }
static void w_std(const void *w, report_val *v) { v->x = W(w)->std; }
static void w_over1(const void *w, report_val *v) { v->x = W(w)->over1; }
static void w_over3(const void *w, report_val *v) { v->x = W(w)->over3; }
#undef W

#define ALL3 (COL_CSV | COL_JSON | COL_JSON2)
static const report_col speed_cols[] = {
    REPORT_COL("day", COL_WORD, "", NULL, COL_CSV | COL_JSON2, w_day),
    REPORT_COL("n", COL_INT, "", NULL, ALL3, w_n),
    REPORT_COL("median_pct", COL_NUM, "%", "%.4f", ALL3, w_median),
    REPORT_COL("p5_pct", COL_NUM, "%", "%.4f", ALL3, w_p5),
    REPORT_COL("p25_pct", COL_NUM, "%", "%.4f", COL_BOTH, w_p25),
    REPORT_COL("p75_pct", COL_NUM, "%", "%.4f", COL_BOTH, w_p75),
    REPORT_COL("p95_pct", COL_NUM, "%", "%.4f", ALL3, w_p95),
    REPORT_COL("mean_pct", COL_NUM, "%", "%.4f", ALL3, w_mean),
    REPORT_COL("std_pct", COL_NUM, "%", "%.4f", ALL3, w_std),
    REPORT_COL("over_1pct_share_pct", COL_NUM, "%", "%.4f", COL_BOTH, w_over1),
    REPORT_COL("over_3pct_share_pct", COL_NUM, "%", "%.4f", COL_BOTH, w_over3),
};
#undef ALL3

int speed_export(report_ctx *c)
{
    speed_stats all;
    speed_day *d = NULL;
    size_t nd = 0;
    char t[32];
    if (speed_corrections(c->s, &c->ex, &all, &d, &nd, c->err, sizeof c->err) != 0)
        return -1;
    speed_row r = {"all", &all};
    if (c->format == FMT_CSV) {
        report_cols_csv_header(c->out, speed_cols, REPORT_NCOLS(speed_cols), NULL, 0);
        report_cols_csv_row(c->out, speed_cols, REPORT_NCOLS(speed_cols), &r);
        for (size_t k = 0; k < nd; k++) {
            speed_row rd = {day_str(d[k].day_utime, t), &d[k].st};
            report_cols_csv_row(c->out, speed_cols, REPORT_NCOLS(speed_cols), &rd);
        }
    } else {
        json_t *so = report_cols_json_row(speed_cols, REPORT_NCOLS(speed_cols), &r, COL_JSON);
        json_t *arr = json_array();
        for (size_t k = 0; k < nd; k++) {
            speed_row rd = {day_str(d[k].day_utime, t), &d[k].st};
            json_array_append_new(arr, report_cols_json_row(speed_cols, REPORT_NCOLS(speed_cols),
                                                            &rd, COL_JSON2));
        }
        json_object_set_new(so, "days", arr);
        json_object_set_new(c->root, "speed", so);
    }
    free(d);
    return 0;
}

int speed_plot_correction(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    export_opts every = {.from = 0, .to = AMFI_STORE_MAX_UTIME};
    speed_stats sall;
    speed_day *d = NULL;
    size_t nd = 0;
    if (speed_corrections(p->s, &every, &sall, &d, &nd, err, errlen) != 0)
        return -1;
    if (nd == 0)
        return 0;
    FILE *f = report_data_open(p->dir, "speed_correction.dat", err, errlen);
    if (!f) {
        free(d);
        return -1;
    }
    fprintf(f, "# day_utc_s n median_pct p5_pct p95_pct (c = speed used / detector's - 1)\n");
    for (size_t k = 0; k < nd; k++)
        fprintf(f, "%.0f %zu %.4f %.4f %.4f\n", (double)d[k].day_utime / 1e6, d[k].st.n,
                d[k].st.median, d[k].st.p5, d[k].st.p95);
    if (report_data_close(f, p->dir, "speed_correction.dat", err, errlen) != 0) {
        free(d);
        return -1;
    }
    fprintf(p->gp,
        "unset label 99\nset output o.'speed_correction.png'\n"
        "set xdata time\nset timefmt '%%s'\nset format x \"%%d %%b\\n%%Y\"\nset autoscale x\n"
        "set xrange [%.0f:%.0f]\nset xtics 86400\nset autoscale y\n"
        "set title \"Speed correction of the estimated passages per day (c = speed used / detector's - 1)\\n%s\"\n"
        "set xlabel 'day (UTC, data time)'\nset ylabel 'c (%%)'\n"
        "plot d.'speed_correction.dat' using 1:4:5 with filledcurves fc rgb '#aec7e8' fs transparent solid 0.5 title 'p5 .. p95', \\\n"
        "     d.'speed_correction.dat' using 1:3 with linespoints pt 7 ps 0.6 lw 2 lc rgb '#1f77b4' title 'daily median', \\\n"
        "     0 with lines dt 2 lc rgb 'black' notitle\n"
        "set output\nset xtics autofreq\n",
        (double)d[0].day_utime / 1e6 - 43200, (double)d[nd - 1].day_utime / 1e6 + 43200, p->sub);
    free(d);
    *made = 1;
    return 0;
}
