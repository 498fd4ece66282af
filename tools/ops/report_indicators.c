/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_indicators.c: amfi-report's indicator trend and alerts
 * (report_indicators.h).
 */
#include "report_indicators.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_cli.h"
#include "report_cols.h"

/* ---- the rows in --from .. --to --------------------------------------------- */

#define MAX_INDICATORS 10000000
#define MAX_ALERTS 1000000

/* Every indicator row (at most MAX_INDICATORS) with its time in
 * [c->ex.from, c->ex.to], newest first: *out malloc'd (free it). */
static int indicators_in_range(report_ctx *c, amfi_indicator_rec **out, int *n)
{
    int64_t total = 0;
    *out = NULL;
    *n = 0;
    if (amfi_store_count(c->s, AMFI_STORE_INDICATORS, &total, c->err, sizeof c->err))
        return -1;
    int max = total > 0 ? (int)(total < MAX_INDICATORS ? total : MAX_INDICATORS) : 1, m = 0;
    amfi_indicator_rec *rec = calloc((size_t)max, sizeof *rec);
    if (!rec)
        return report_fail(c, "out of memory for %d indicators", max);
    if (total > 0 && amfi_store_recent_indicators(c->s, max, rec, &m, c->err, sizeof c->err)) {
        free(rec);
        return -1;
    }
    int k = 0;
    for (int i = 0; i < m; i++)
        if (rec[i].row.utime >= c->ex.from && rec[i].row.utime <= c->ex.to)
            rec[k++] = rec[i];
    *out = rec;
    *n = k;
    return 0;
}

/* The same of the alert rows (at most MAX_ALERTS). */
static int alerts_in_range(report_ctx *c, amfi_alert_rec **out, int *n)
{
    int64_t total = 0;
    *out = NULL;
    *n = 0;
    if (amfi_store_count(c->s, AMFI_STORE_ALERTS, &total, c->err, sizeof c->err))
        return -1;
    int max = total > 0 ? (int)(total < MAX_ALERTS ? total : MAX_ALERTS) : 1, m = 0;
    amfi_alert_rec *rec = calloc((size_t)max, sizeof *rec);
    if (!rec)
        return report_fail(c, "out of memory for %d alerts", max);
    if (total > 0 && amfi_store_recent_alerts(c->s, max, rec, &m, c->err, sizeof c->err)) {
        free(rec);
        return -1;
    }
    int k = 0;
    for (int i = 0; i < m; i++)
        if (rec[i].utime >= c->ex.from && rec[i].utime <= c->ex.to)
            rec[k++] = rec[i];
    *out = rec;
    *n = k;
    return 0;
}

/* ", from T to T" when --from or --to narrowed the rows, else "" */
static const char *range_words(const report_ctx *c, char buf[96])
{
    char a[32], b[32];
    buf[0] = '\0';
    if (c->ex.from > 0 || c->ex.to < AMFI_STORE_MAX_UTIME)
        snprintf(buf, 96, " from %s to %s UTC", report_utc(c->ex.from, a),
                 report_utc(c->ex.to, b));
    return buf;
}

/* ---- the trend ------------------------------------------------------------- */

int trend_table(report_ctx *c)
{
    amfi_indicator_rec *all = NULL;
    int n_all = 0;
    char rw[96];
    FILE *f = c->out;
    if (indicators_in_range(c, &all, &n_all) != 0)
        return -1;
    const int64_t total = n_all;
    const int nl = n_all < REPORT_TREND_ROWS ? n_all : REPORT_TREND_ROWS;
    const amfi_indicator_rec *rec = all;
    fprintf(f, "== indicators (last %lld of %lld%s)\n",
            total < REPORT_TREND_ROWS ? (long long)total : (long long)REPORT_TREND_ROWS,
            (long long)total, range_words(c, rw));
    if (total == 0) {
        fprintf(f, "(none yet: amfid writes one every few ok passages once its "
                   "window is full)\n");
        free(all);
        return 0;
    }
    char hm[16], hs[16];
    snprintf(hm, sizeof hm, "mean %s", report_mass_unit(c->units));
    snprintf(hs, sizeof hs, "STD %s", report_mass_unit(c->units));
    fprintf(f, "%-19s  %6s  %9s  %8s  %6s  %8s  %s\n", "time (UTC)", "n", hm, hs, "ratio", "p",
            "state");
    for (int k = nl - 1; k >= 0; k--) { /* oldest first */
        const amfi_indicator_row *r = &rec[k].row;
        char t[32], b1[32], b2[32], b3[32], b4[32];
        fprintf(f, "%-19.19s  %6lld  %9.31s  %8.31s  %6.31s  %8.31s  %.8s\n",
                report_utc(r->utime, t), (long long)r->n, report_mass(c->units, r->mean_kg, b1),
                report_mass(c->units, r->std_kg, b2), report_num(r->std_ratio, "%.3f", b3),
                report_num(r->p_value, "%.2e", b4), r->state);
    }
    free(all);
    return 0;
}

typedef struct ind_row {
    const amfi_indicator_rec *rec;
    char t[32];
} ind_row;

#define I(w) (&((const ind_row *)(w))->rec->row)
static void i_id(const void *w, report_val *v) { v->i = ((const ind_row *)w)->rec->id; }
static void i_time(const void *w, report_val *v) { v->s = ((const ind_row *)w)->t; }
static void i_utime(const void *w, report_val *v) { v->i = I(w)->utime; }
static void i_n(const void *w, report_val *v) { v->i = I(w)->n; }
static void i_mean(const void *w, report_val *v) { v->x = I(w)->mean_kg; }
static void i_std(const void *w, report_val *v) { v->x = I(w)->std_kg; }
static void i_bmean(const void *w, report_val *v) { v->x = I(w)->baseline_mean_kg; }
static void i_bstd(const void *w, report_val *v) { v->x = I(w)->baseline_std_kg; }
static void i_ratio(const void *w, report_val *v) { v->x = I(w)->std_ratio; }
static void i_p(const void *w, report_val *v) { v->x = I(w)->p_value; }
static void i_state(const void *w, report_val *v) { v->s = I(w)->state; }
#undef I

static const report_col trend_cols[] = {
    REPORT_COL("indicator_id", COL_INT, "", NULL, COL_BOTH, i_id),
    REPORT_COL("time_utc", COL_WORD, "", NULL, COL_BOTH, i_time),
    REPORT_COL("utime", COL_INT, "us", NULL, COL_BOTH, i_utime),
    REPORT_COL("n", COL_INT, "", NULL, COL_BOTH, i_n),
    REPORT_COL("mean_kg", COL_NUM, "kg", "%.1f", COL_BOTH, i_mean),
    REPORT_COL("std_kg", COL_NUM, "kg", "%.1f", COL_BOTH, i_std),
    REPORT_COL("baseline_mean_kg", COL_NUM, "kg", "%.1f", COL_BOTH, i_bmean),
    REPORT_COL("baseline_std_kg", COL_NUM, "kg", "%.1f", COL_BOTH, i_bstd),
    REPORT_COL("std_ratio", COL_NUM, "", "%.6f", COL_BOTH, i_ratio),
    REPORT_COL("p_value", COL_NUM, "", "%.6g", COL_BOTH, i_p),
    REPORT_COL("state", COL_TEXT, "", NULL, COL_BOTH, i_state),
};

int trend_export(report_ctx *c)
{
    amfi_indicator_rec *rec = NULL;
    int n = 0;
    if (indicators_in_range(c, &rec, &n) != 0)
        return -1;
    json_t *arr = c->format == FMT_JSON ? json_array() : NULL;
    if (!arr)
        report_cols_csv_header(c->out, trend_cols, REPORT_NCOLS(trend_cols), NULL, 0);
    for (int k = n - 1; k >= 0; k--) { /* oldest first */
        ind_row w = {.rec = &rec[k]};
        report_iso(rec[k].row.utime, w.t);
        if (arr)
            json_array_append_new(arr, report_cols_json_row(trend_cols, REPORT_NCOLS(trend_cols),
                                                            &w, COL_JSON));
        else
            report_cols_csv_row(c->out, trend_cols, REPORT_NCOLS(trend_cols), &w);
    }
    free(rec);
    if (arr)
        json_object_set_new(c->root, "trend", arr);
    return 0;
}

/* ---- the alerts ------------------------------------------------------------ */

int alerts_table(report_ctx *c)
{
    amfi_alert_rec *all = NULL, *open = NULL;
    int n_all = 0, n_open = 0;
    char rw[96];
    FILE *f = c->out;
    if (alerts_in_range(c, &all, &n_all) != 0)
        return -1;
    const int64_t total = n_all;
    const int nl = n_all < REPORT_ALERT_ROWS ? n_all : REPORT_ALERT_ROWS;
    const amfi_alert_rec *rec = all;
    fprintf(f, "== alerts (last %lld of %lld%s)\n",
            total < REPORT_ALERT_ROWS ? (long long)total : (long long)REPORT_ALERT_ROWS,
            (long long)total, range_words(c, rw));
    if (total == 0 && !rw[0]) {
        fprintf(f, "(none)\n");
        free(all);
        return 0;
    }
    if (amfi_store_open_alerts(c->s, &open, &n_open, c->err, sizeof c->err) != 0) {
        free(all);
        return -1;
    }
    for (int k = 0; k < n_open; k++) {
        char t[32];
        fprintf(f, "OPEN NOW     %s %s since %s UTC\n", amfi_cli_shown(open[k].level),
                amfi_cli_shown(open[k].kind), report_utc(open[k].utime, t));
    }
    free(open);
    if (n_open == 0)
        fprintf(f, "open now     none\n");
    if (total == 0) {
        fprintf(f, "(none in the range)\n");
        free(all);
        return 0;
    }
    fprintf(f, "%-19s  %-7s  %-14s  %-7s  %9s  %s\n", "time (UTC)", "level", "kind", "event",
            "indicator", "message");
    for (int k = nl - 1; k >= 0; k--) {
        const amfi_alert_rec *a = &rec[k];
        char t[32], is[32];
        if (a->indicator_id > 0)
            snprintf(is, sizeof is, "%lld", (long long)a->indicator_id);
        else
            snprintf(is, sizeof is, "-");
        /* one line per alert: the store shows control characters as '?' */
        fprintf(f, "%-19.19s  %-7.7s  %-14.40s  %-7s  %9.20s  %.300s\n", report_utc(a->utime, t),
                amfi_cli_shown(a->level), amfi_cli_shown(a->kind),
                a->raised ? "raised" : "cleared", is, a->message);
    }
    free(all);
    return 0;
}

typedef struct alert_row {
    const amfi_alert_rec *a;
    char t[32];
} alert_row;

#define A(w) (((const alert_row *)(w))->a)
static void a_id(const void *w, report_val *v) { v->i = A(w)->id; }
static void a_time(const void *w, report_val *v) { v->s = ((const alert_row *)w)->t; }
static void a_utime(const void *w, report_val *v) { v->i = A(w)->utime; }
static void a_level(const void *w, report_val *v) { v->s = A(w)->level; }
static void a_kind(const void *w, report_val *v) { v->s = A(w)->kind; }
static void a_event(const void *w, report_val *v) { v->s = A(w)->raised ? "raised" : "cleared"; }
static void a_raised(const void *w, report_val *v) { v->i = A(w)->raised; }
static void a_indicator(const void *w, report_val *v)
{
    v->i = A(w)->indicator_id;
    v->null = A(w)->indicator_id <= 0; /* none */
}
static void a_message(const void *w, report_val *v) { v->s = A(w)->message; }
#undef A

static const report_col alert_cols[] = {
    REPORT_COL("alert_id", COL_INT, "", NULL, COL_BOTH, a_id),
    REPORT_COL("time_utc", COL_WORD, "", NULL, COL_BOTH, a_time),
    REPORT_COL("utime", COL_INT, "us", NULL, COL_BOTH, a_utime),
    REPORT_COL("level", COL_TEXT, "", NULL, COL_BOTH, a_level),
    REPORT_COL("kind", COL_TEXT, "", NULL, COL_BOTH, a_kind),
    REPORT_COL("event", COL_WORD, "", NULL, COL_CSV, a_event),     /* raised or cleared */
    REPORT_COL("raised", COL_BOOL, "", NULL, COL_JSON, a_raised), /* the same, as JSON says it */
    REPORT_COL("indicator_id", COL_INT, "", NULL, COL_BOTH, a_indicator),
    REPORT_COL("message", COL_TEXT, "", NULL, COL_BOTH, a_message),
};

int alerts_export(report_ctx *c)
{
    amfi_alert_rec *rec = NULL;
    int n = 0;
    if (alerts_in_range(c, &rec, &n) != 0)
        return -1;
    json_t *arr = c->format == FMT_JSON ? json_array() : NULL;
    if (!arr)
        report_cols_csv_header(c->out, alert_cols, REPORT_NCOLS(alert_cols), NULL, 0);
    for (int k = n - 1; k >= 0; k--) {
        alert_row w = {.a = &rec[k]};
        report_iso(rec[k].utime, w.t);
        if (arr)
            json_array_append_new(arr, report_cols_json_row(alert_cols, REPORT_NCOLS(alert_cols),
                                                            &w, COL_JSON));
        else
            report_cols_csv_row(c->out, alert_cols, REPORT_NCOLS(alert_cols), &w);
    }
    free(rec);
    if (arr)
        json_object_set_new(c->root, "alerts", arr);
    return 0;
}

/* ---- trend.png -------------------------------------------------------------------- */

int indicators_plot_trend(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    char w1[64], w2[64];
    const amfi_indicator_params *ip = p->ip;
    /* indicators.dat, oldest first */
    FILE *f = report_data_open(p->dir, "indicators.dat", err, errlen);
    if (!f)
        return -1;
    fprintf(f, "# time_s std_ratio p_value mean_ratio n state\n");
    for (int k = p->n_ind - 1; k >= 0; k--) {
        const amfi_indicator_row *r = &p->ind[k].row;
        double mr = r->mean_kg / r->baseline_mean_kg;
        fprintf(f, "%.3f %.5g %.5g %.5g %d %s\n", (double)r->utime / 1e6, r->std_ratio,
                r->p_value, isfinite(mr) ? mr : NAN, r->n, report_dat_word(r->state, w1));
    }
    if (report_data_close(f, p->dir, "indicators.dat", err, errlen) != 0)
        return -1;
    /* alerts.dat: one line per alert row, oldest first */
    if (!(f = report_data_open(p->dir, "alerts.dat", err, errlen)))
        return -1;
    fprintf(f, "# alert_id time_s raised(1)/cleared(0) level kind\n");
    for (int k = p->n_al - 1; k >= 0; k--)
        fprintf(f, "%lld %.3f %d %s %s\n", (long long)p->al[k].id,
                (double)p->al[k].utime / 1e6, p->al[k].raised,
                report_dat_word(p->al[k].level, w1), report_dat_word(p->al[k].kind, w2));
    if (report_data_close(f, p->dir, "alerts.dat", err, errlen) != 0)
        return -1;
    /* each panel's y range holds its data and its thresholds with a margin,
     * so that no threshold line lies on the frame */
    double slo = fmin(ip->std_alert_ratio, ip->std_clear_ratio), shi = fmax(ip->std_alert_ratio, ip->std_clear_ratio);
    double mlo = 1.0 / ip->mean_alert_ratio, mhi = ip->mean_alert_ratio;
    double plo = ip->std_alert_p, phi = 1.0;
    for (int k = 0; k < p->n_ind; k++) {
        const amfi_indicator_row *r = &p->ind[k].row;
        double mr = r->mean_kg / r->baseline_mean_kg;
        if (isfinite(r->std_ratio)) {
            slo = fmin(slo, r->std_ratio);
            shi = fmax(shi, r->std_ratio);
        }
        if (isfinite(mr)) {
            mlo = fmin(mlo, mr);
            mhi = fmax(mhi, mr);
        }
        if (isfinite(r->p_value) && r->p_value > 0)
            plo = fmin(plo, r->p_value);
    }
    if (mlo > mhi) { /* a mean ratio threshold below 1 */
        double t = mlo;
        mlo = mhi;
        mhi = t;
    }
    const double sm = 0.08 * (shi - slo > 0 ? shi - slo : 0.1),
                 mm = 0.08 * (mhi - mlo > 0 ? mhi - mlo : 0.1);
    /* three panels with the alerts as vertical lines */
    FILE *gp = p->gp;
    fprintf(gp, "set terminal pngcairo size 960,800\nset output o.'trend.png'\n"
                "unset arrow\n");
    for (int k = p->n_al - 1; k >= 0; k--)
        fprintf(gp, "set arrow from %.3f, graph 0 to %.3f, graph 1 nohead lw 1.5 lc rgb '%s' dt %d\n",
                (double)p->al[k].utime / 1e6, (double)p->al[k].utime / 1e6,
                p->al[k].raised ? "#d62728" : "#2ca02c", p->al[k].raised ? 1 : 2);
    fprintf(gp,
        "set multiplot layout 3,1 title \"Damage indicator trend (%s)\\n%d indicator rows, %d alerts: red solid = raised, green dashed = cleared; thresholds: %s\"\n"
        "unset title\nset format x ''\nunset xlabel\n"
        "set lmargin at screen 0.09\nset rmargin at screen 0.72\n"
        "set ylabel 'STD ratio (window / baseline)'\nset yrange [%.6g:%.6g]\n"
        "plot d.'indicators.dat' using 1:2 with linespoints pt 7 ps 0.3 lc rgb '#1f77b4' title 'STD ratio', \\\n"
        "     %.4g with lines dt 1 lc rgb '#d62728' title 'raise at >= %.4g', %.4g with lines dt 2 lc rgb '#2ca02c' title 'clear below %.4g', \\\n"
        "     NaN with lines lc rgb '#d62728' title 'alert raised', NaN with lines dt 2 lc rgb '#2ca02c' title 'alert cleared'\n"
        "set ylabel 'p-value (variance ratio)'\nset logscale y\nset format y '%%.0e'\n"
        "set yrange [%.6g:%.6g]\n"
        "plot d.'indicators.dat' using 1:($3>0?$3:NaN) with linespoints pt 7 ps 0.3 lc rgb '#9467bd' title 'p (STD test)', \\\n"
        "     %.4g with lines dt 1 lc rgb '#d62728' title 'raise at p <= %.4g'\n"
        "unset logscale y\nset format y '%%g'\n"
        "set format x \"%%H:%%M\\n%%d %%b\"\nset xlabel 'time (UTC, data time)'\n"
        "set ylabel 'mean ratio (window / baseline)'\nset yrange [%.6g:%.6g]\n"
        "plot d.'indicators.dat' using 1:4 with linespoints pt 7 ps 0.3 lc rgb '#ff7f0e' title 'mean ratio', \\\n"
        "     %.4g with lines dt 1 lc rgb '#d62728' title 'mean alert %.4g and 1/%.4g', %.4g with lines dt 1 lc rgb '#d62728' notitle\n"
        "unset multiplot\nunset arrow\nset lmargin\nset rmargin\nset autoscale y\n"
        "set terminal pngcairo size 960,540\n",
        p->sub, p->n_ind, p->n_al, p->ip_from ? p->ip_from : "built-in defaults", slo - sm, shi + sm, ip->std_alert_ratio, ip->std_alert_ratio,
        ip->std_clear_ratio, ip->std_clear_ratio, plo / 4, phi * 2, ip->std_alert_p,
        ip->std_alert_p, mlo - mm, mhi + mm, ip->mean_alert_ratio, ip->mean_alert_ratio,
        ip->mean_alert_ratio, 1.0 / ip->mean_alert_ratio);
    *made = 1;
    return 0;
}
