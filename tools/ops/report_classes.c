/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_classes.c: amfi-report's --classes and --class-histogram
 * (report_classes.h).
 */
#include "report_classes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_cli.h"
#include "report_cols.h"

#define MAX_LANES 64
#define MAX_BINS 100000
#define UNCLASSIFIED "unclassified"
#define OTHER "other"

/* One ok passage as the class statistics see it. */
typedef struct cls_pas {
    double gvw;
    int cls;  /* index into names */
    int lane;
    int over; /* passages.overload: 1 */
    int refused; /* passages.loads_refused set */
} cls_pas;

typedef struct cls_data {
    char names[REPORT_MAX_CLASSES + 2][64]; /* a longer name is cut to 63 bytes */
    int n_names;
    int other;   /* index of "other", or −1 */
    cls_pas *p;
    size_t n, cap;
    int oom;
} cls_data;

static int name_index(cls_data *d, const char *name)
{
    for (int i = 0; i < d->n_names; i++)
        if (strcmp(d->names[i], name) == 0)
            return i;
    if (d->n_names >= REPORT_MAX_CLASSES) {
        if (d->other < 0) {
            d->other = d->n_names++;
            snprintf(d->names[d->other], sizeof d->names[0], "%s", OTHER);
        }
        return d->other;
    }
    snprintf(d->names[d->n_names], sizeof d->names[0], "%s", name);
    return d->n_names++;
}

static int collect(void *ctx, const amfi_class_row *r)
{
    cls_data *d = ctx;
    if (d->n == d->cap) {
        size_t cap = d->cap ? 2 * d->cap : 4096;
        cls_pas *v = realloc(d->p, cap * sizeof *v);
        if (!v) {
            d->oom = 1;
            return 1;
        }
        d->p = v;
        d->cap = cap;
    }
    cls_pas *q = &d->p[d->n++];
    q->gvw = r->gvw_kg;
    q->cls = name_index(d, r->vclass && *r->vclass ? r->vclass : UNCLASSIFIED);
    q->lane = r->lane;
    q->over = r->overload;
    q->refused = r->refused;
    return 0;
}

/* The ok passages of the selection (range, lane) with a GVW. */
static int read_classes(report_ctx *c, cls_data *d)
{
    memset(d, 0, sizeof *d);
    d->other = -1;
    amfi_passage_filter f = {.from = c->ex.from, .to = c->ex.to, .status = "ok",
                             .lane_given = c->ex.lane_given, .lane = c->ex.lane};
    int rc = amfi_store_each_class_row(c->s, &f, collect, d, c->err, sizeof c->err);
    if (d->oom)
        return report_fail(c, "out of memory for the passages of the class statistics");
    return rc ? -1 : 0;
}

/* Class names in alphabetical order ("unclassified" and "other" last). */
static int rank(const char *s)
{
    return strcmp(s, OTHER) == 0 ? 2 : strcmp(s, UNCLASSIFIED) == 0 ? 1 : 0;
}
static const cls_data *sort_d;
static int cmp_names(const void *a, const void *b)
{
    const char *x = sort_d->names[*(const int *)a], *y = sort_d->names[*(const int *)b];
    int rx = rank(x), ry = rank(y);
    return rx != ry ? rx - ry : strcmp(x, y);
}
static void class_order(const cls_data *d, int *order)
{
    for (int i = 0; i < d->n_names; i++)
        order[i] = i;
    sort_d = d;
    qsort(order, (size_t)d->n_names, sizeof *order, cmp_names);
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* ---- --classes --------------------------------------------------------------- */

/* One row: a class over all lanes (all = 1) or in one lane. */
typedef struct cls_row {
    const char *name;
    int lane, all;
    int64_t n, over, refused;
    double share_pct, mean, std, p5, p50, p95, max;
} cls_row;

/* The statistics of the passages of class k (and lane, unless all). */
static int stats_of(const cls_data *d, int k, int all, int lane, double *buf, cls_row *r)
{
    size_t m = 0;
    r->over = r->refused = 0;
    for (size_t i = 0; i < d->n; i++)
        if (d->p[i].cls == k && (all || d->p[i].lane == lane)) {
            buf[m++] = d->p[i].gvw;
            r->over += d->p[i].over;
            r->refused += d->p[i].refused;
        }
    r->name = d->names[k];
    r->all = all;
    r->lane = lane;
    r->n = (int64_t)m;
    r->share_pct = d->n ? 100.0 * (double)m / (double)d->n : NAN;
    report_mean_std(buf, m, &r->mean, &r->std);
    report_sort(buf, m);
    r->p5 = report_percentile(buf, m, 5);
    r->p50 = report_percentile(buf, m, 50);
    r->p95 = report_percentile(buf, m, 95);
    r->max = m ? buf[m - 1] : NAN;
    return m > 0;
}

#define C(w) ((const cls_row *)(w))
static void c_class(const void *w, report_val *v) { v->s = C(w)->name; }
static void c_lane(const void *w, report_val *v)
{
    v->i = C(w)->lane;
    v->null = C(w)->all; /* all lanes */
}
static void c_n(const void *w, report_val *v) { v->i = C(w)->n; }
static void c_share(const void *w, report_val *v) { v->x = C(w)->share_pct; }
static void c_mean(const void *w, report_val *v) { v->x = C(w)->mean; }
static void c_std(const void *w, report_val *v) { v->x = C(w)->std; }
static void c_p5(const void *w, report_val *v) { v->x = C(w)->p5; }
static void c_p50(const void *w, report_val *v) { v->x = C(w)->p50; }
static void c_p95(const void *w, report_val *v) { v->x = C(w)->p95; }
static void c_max(const void *w, report_val *v) { v->x = C(w)->max; }
static void c_over(const void *w, report_val *v) { v->i = C(w)->over; }
static void c_refused(const void *w, report_val *v) { v->i = C(w)->refused; }
#undef C

static const report_col class_cols[] = {
    REPORT_COL("class", COL_TEXT, "", NULL, COL_BOTH, c_class),
    REPORT_COL("lane", COL_INT, "", NULL, COL_BOTH, c_lane), /* empty/null: every lane */
    REPORT_COL("passages", COL_INT, "", NULL, COL_BOTH, c_n),
    REPORT_COL("share_pct", COL_NUM, "%", "%.3f", COL_BOTH, c_share),
    REPORT_COL("gvw_mean_kg", COL_NUM, "kg", "%.1f", COL_BOTH, c_mean),
    REPORT_COL("gvw_std_kg", COL_NUM, "kg", "%.1f", COL_BOTH, c_std),
    REPORT_COL("gvw_p5_kg", COL_NUM, "kg", "%.1f", COL_BOTH, c_p5),
    REPORT_COL("gvw_p50_kg", COL_NUM, "kg", "%.1f", COL_BOTH, c_p50),
    REPORT_COL("gvw_p95_kg", COL_NUM, "kg", "%.1f", COL_BOTH, c_p95),
    REPORT_COL("gvw_max_kg", COL_NUM, "kg", "%.1f", COL_BOTH, c_max),
    REPORT_COL("overloaded", COL_INT, "", NULL, COL_BOTH, c_over),
    /* stored refusals (store version 13 on; --overloads recomputes older ones) */
    REPORT_COL("loads_refused", COL_INT, "", NULL, COL_BOTH, c_refused),
};

/* Calls fn for every row: each class over all lanes, then per lane. */
static int each_row(report_ctx *c, const cls_data *d, void (*fn)(report_ctx *, const cls_row *))
{
    int order[REPORT_MAX_CLASSES + 2], lanes[MAX_LANES], n_lanes = 0;
    double *buf = malloc((d->n + 1) * sizeof *buf);
    if (!buf)
        return report_fail(c, "out of memory for the class statistics");
    for (size_t i = 0; i < d->n; i++) {
        int j = 0;
        while (j < n_lanes && lanes[j] != d->p[i].lane)
            j++;
        if (j == n_lanes && n_lanes < MAX_LANES)
            lanes[n_lanes++] = d->p[i].lane;
    }
    qsort(lanes, (size_t)n_lanes, sizeof *lanes, cmp_int);
    class_order(d, order);
    for (int i = 0; i < d->n_names; i++) {
        cls_row r;
        if (stats_of(d, order[i], 1, 0, buf, &r))
            fn(c, &r);
        for (int j = 0; n_lanes > 1 && j < n_lanes; j++)
            if (stats_of(d, order[i], 0, lanes[j], buf, &r))
                fn(c, &r);
    }
    free(buf);
    return 0;
}

static void table_row(report_ctx *c, const cls_row *r)
{
    char l[16], b[6][32];
    if (r->all)
        snprintf(l, sizeof l, "all");
    else
        snprintf(l, sizeof l, "%d", r->lane);
    const int u = c->units;
    fprintf(c->out, "%-16.16s  %5s  %8lld  %6.2f  %8s  %7s  %8s  %8s  %8s  %8s  %6lld\n",
            amfi_cli_shown(r->name), l, (long long)r->n, r->share_pct, report_mass(u, r->mean, b[0]),
            report_mass(u, r->std, b[1]), report_mass(u, r->p5, b[2]),
            report_mass(u, r->p50, b[3]), report_mass(u, r->p95, b[4]),
            report_mass(u, r->max, b[5]), (long long)r->over);
}

int classes_table(report_ctx *c)
{
    cls_data d;
    int rc = read_classes(c, &d);
    if (rc == 0) {
        fprintf(c->out, "== classes of the ok passages (%zu; class as amfid stored it)\n", d.n);
        if (d.n == 0) {
            fprintf(c->out, "(no ok passage with a GVW in the selection)\n");
        } else {
            const char *u = report_mass_unit(c->units);
            char h[6][16];
            snprintf(h[0], 16, "mean %s", u);
            snprintf(h[1], 16, "STD %s", u);
            snprintf(h[2], 16, "p5 %s", u);
            snprintf(h[3], 16, "p50 %s", u);
            snprintf(h[4], 16, "p95 %s", u);
            snprintf(h[5], 16, "max %s", u);
            fprintf(c->out, "%-16s  %5s  %8s  %6s  %8s  %7s  %8s  %8s  %8s  %8s  %6s\n", "class",
                    "lane", "passages", "%", h[0], h[1], h[2], h[3], h[4], h[5], "over");
            rc = each_row(c, &d, table_row);
        }
    }
    free(d.p);
    return rc;
}

static void export_row(report_ctx *c, const cls_row *r)
{
    if (c->format == FMT_CSV)
        report_cols_csv_row(c->out, class_cols, REPORT_NCOLS(class_cols), r);
    else
        json_array_append_new(json_object_get(c->root, "classes"),
                              report_cols_json_row(class_cols, REPORT_NCOLS(class_cols), r,
                                                   COL_JSON));
}

int classes_export(report_ctx *c)
{
    cls_data d;
    int rc = read_classes(c, &d);
    if (rc == 0) {
        if (c->format == FMT_CSV)
            report_cols_csv_header(c->out, class_cols, REPORT_NCOLS(class_cols), NULL, 0);
        else
            json_object_set_new(c->root, "classes", json_array());
        rc = each_row(c, &d, export_row);
    }
    free(d.p);
    return rc;
}

/* ---- --class-histogram ---------------------------------------------------------- */

typedef struct hbin_row {
    const char *name;
    double lo, hi;
    int64_t n;
} hbin_row;

#define H(w) ((const hbin_row *)(w))
static void h_class(const void *w, report_val *v) { v->s = H(w)->name; }
static void h_lo(const void *w, report_val *v) { v->x = H(w)->lo; }
static void h_hi(const void *w, report_val *v) { v->x = H(w)->hi; }
static void h_n(const void *w, report_val *v) { v->i = H(w)->n; }
#undef H

static const report_col hbin_cols[] = {
    REPORT_COL("class", COL_TEXT, "", NULL, COL_BOTH, h_class),
    REPORT_COL("gvw_from_kg", COL_NUM, "kg", "%.0f", COL_BOTH, h_lo),
    REPORT_COL("gvw_to_kg", COL_NUM, "kg", "%.0f", COL_BOTH, h_hi),
    REPORT_COL("passages", COL_INT, "", NULL, COL_BOTH, h_n),
};

/* counts[bin * n_names + class] of the selection; *n_bins bins of bin_kg. */
static int hist_of(report_ctx *c, const cls_data *d, int64_t **counts, int *n_bins)
{
    int nb = 0;
    for (size_t i = 0; i < d->n; i++) {
        long b = (long)floor(d->p[i].gvw / c->ex.bin_kg);
        if (b >= MAX_BINS)
            b = MAX_BINS - 1;
        if (b + 1 > nb)
            nb = (int)b + 1;
    }
    *n_bins = nb;
    *counts = calloc((size_t)(nb ? nb : 1) * (size_t)(d->n_names ? d->n_names : 1),
                     sizeof **counts);
    if (!*counts)
        return report_fail(c, "out of memory for the class histogram");
    for (size_t i = 0; i < d->n; i++) {
        long b = (long)floor(d->p[i].gvw / c->ex.bin_kg);
        if (b >= MAX_BINS)
            b = MAX_BINS - 1;
        (*counts)[(size_t)b * (size_t)d->n_names + (size_t)d->p[i].cls]++;
    }
    return 0;
}

int class_histogram_table(report_ctx *c)
{
    cls_data d;
    int64_t *cnt = NULL;
    int nb = 0, order[REPORT_MAX_CLASSES + 2];
    FILE *f = c->out;
    int rc = read_classes(c, &d);
    if (rc == 0)
        rc = hist_of(c, &d, &cnt, &nb);
    if (rc == 0) {
        class_order(&d, order);
        char bw[32], hg[16], lo[32], hi[32];
        snprintf(hg, sizeof hg, "GVW %s", report_mass_unit(c->units));
        fprintf(f, "== GVW histogram of the ok passages per class, %s %s bins\n%-17s",
                report_mass(c->units, c->ex.bin_kg, bw), report_mass_unit(c->units), hg);
        for (int i = 0; i < d.n_names; i++)
            fprintf(f, "  %9.9s", amfi_cli_shown(d.names[order[i]]));
        fprintf(f, "  %9s\n", "all");
        for (int b = 0; b < nb; b++) {
            int64_t all = 0;
            for (int i = 0; i < d.n_names; i++)
                all += cnt[(size_t)b * (size_t)d.n_names + (size_t)i];
            if (all == 0)
                continue;
            fprintf(f, "%7s .. %7s", report_mass(c->units, b * c->ex.bin_kg, lo),
                    report_mass(c->units, (b + 1) * c->ex.bin_kg, hi));
            for (int i = 0; i < d.n_names; i++)
                fprintf(f, "  %9lld", (long long)cnt[(size_t)b * (size_t)d.n_names
                                                     + (size_t)order[i]]);
            fprintf(f, "  %9lld\n", (long long)all);
        }
        fprintf(f, "%-17s", "total");
        for (int i = 0; i < d.n_names; i++) {
            int64_t t = 0;
            for (int b = 0; b < nb; b++)
                t += cnt[(size_t)b * (size_t)d.n_names + (size_t)order[i]];
            fprintf(f, "  %9lld", (long long)t);
        }
        fprintf(f, "  %9zu\n", d.n);
    }
    free(cnt);
    free(d.p);
    return rc;
}

int class_histogram_export(report_ctx *c)
{
    cls_data d;
    int64_t *cnt = NULL;
    int nb = 0, order[REPORT_MAX_CLASSES + 2];
    int rc = read_classes(c, &d);
    if (rc == 0)
        rc = hist_of(c, &d, &cnt, &nb);
    if (rc == 0) {
        json_t *bins = c->format == FMT_JSON ? json_array() : NULL;
        if (!bins)
            report_cols_csv_header(c->out, hbin_cols, REPORT_NCOLS(hbin_cols), NULL, 0);
        class_order(&d, order);
        /* the bins of each class that hold a passage, class by class */
        for (int i = 0; i < d.n_names; i++)
            for (int b = 0; b < nb; b++) {
                hbin_row r = {d.names[order[i]], b * c->ex.bin_kg, (b + 1) * c->ex.bin_kg,
                              cnt[(size_t)b * (size_t)d.n_names + (size_t)order[i]]};
                if (r.n == 0)
                    continue;
                if (bins)
                    json_array_append_new(bins, report_cols_json_row(hbin_cols,
                                                                     REPORT_NCOLS(hbin_cols),
                                                                     &r, COL_JSON));
                else
                    report_cols_csv_row(c->out, hbin_cols, REPORT_NCOLS(hbin_cols), &r);
            }
        if (bins) {
            json_t *o = json_object();
            json_object_set_new(o, "bin_kg", json_real(c->ex.bin_kg));
            json_object_set_new(o, "bins", bins);
            json_object_set_new(c->root, "class_histogram", o);
        }
    }
    free(cnt);
    free(d.p);
    return rc;
}
