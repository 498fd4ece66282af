/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_passages.c: amfi-report's passage sections and plots
 * (report_passages.h).
 */
#define _GNU_SOURCE
#include "report_passages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amfi_classify.h"
#include "report_cols.h"

#define MAX_LANES 64 /* distinct lanes a histogram keeps apart */
#define MAX_BINS 100000
#define JSON_FLAGS (JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10))

/* The passages of o's range and lane and of `status` (NULL: any), read
 * through the store's filtered iterator: the filter is SQL. */
static int each(report_ctx *c, const char *status, amfi_store_passage_fn fn, void *ctx)
{
    const export_opts *o = &c->ex;
    amfi_passage_filter f = {.from = o->from, .to = o->to, .status = status,
                             .lane_given = o->lane_given, .lane = o->lane};
    return amfi_store_each_passage_where(c->s, &f, fn, ctx, c->err, sizeof c->err);
}

/* ---- the passage list ------------------------------------------------------ */

typedef struct pas_row {
    int64_t id;
    const amfi_passage_row *r;
    char t[32]; /* its time, ISO 8601 */
} pas_row;

#define R(row) (((const pas_row *)(row))->r)
static void p_time(const void *w, report_val *v) { v->s = ((const pas_row *)w)->t; }
static void p_utime(const void *w, report_val *v) { v->i = R(w)->utime; }
static void p_id(const void *w, report_val *v) { v->i = ((const pas_row *)w)->id; }
static void p_vehicle(const void *w, report_val *v) { v->i = R(w)->vehicle_id; }
static void p_lane(const void *w, report_val *v) { v->i = R(w)->lane; }
static void p_speed(const void *w, report_val *v) { v->x = R(w)->speed_mps; }
static void p_axles(const void *w, report_val *v) { v->i = R(w)->n_axles; }
static void p_gvw(const void *w, report_val *v) { v->x = R(w)->gvw_kg; }
static void p_loads(const void *w, report_val *v)
{
    v->v = R(w)->axle_kg;
    v->n = R(w)->n_axles;
}
static void p_spacing(const void *w, report_val *v)
{
    v->v = R(w)->spacing_m;
    v->n = R(w)->n_axles > 0 ? R(w)->n_axles - 1 : 0;
}
static void p_status(const void *w, report_val *v) { v->s = R(w)->status; }
static void p_reason(const void *w, report_val *v) { v->s = R(w)->reason; }
static void p_given(const void *w, report_val *v) { v->x = R(w)->speed_given_mps; }
static void p_estimated(const void *w, report_val *v) { v->i = R(w)->speed_estimated; }
static void p_vehicles(const void *w, report_val *v) { v->i = R(w)->n_vehicles; }
static void p_quality(const void *w, report_val *v) { v->x = R(w)->quality; }
static void p_class(const void *w, report_val *v)
{
    v->s = R(w)->vclass;
    v->null = !v->s;
}

static const report_col passage_cols[] = {
    REPORT_COL("time_utc", COL_WORD, "", NULL, COL_BOTH, p_time),
    REPORT_COL("utime", COL_INT, "us", NULL, COL_BOTH, p_utime),
    REPORT_COL("passage_id", COL_INT, "", NULL, COL_BOTH, p_id),
    REPORT_COL("vehicle_id", COL_INT, "", NULL, COL_BOTH, p_vehicle),
    REPORT_COL("lane", COL_INT, "", NULL, COL_BOTH, p_lane),
    REPORT_COL("speed_mps", COL_NUM, "m/s", "%.3f", COL_BOTH, p_speed),
    REPORT_COL("n_axles", COL_INT, "", NULL, COL_BOTH, p_axles),
    REPORT_COL("gvw_kg", COL_NUM, "kg", "%.1f", COL_BOTH, p_gvw),
    REPORT_COL("axle%d_kg", COL_NUMS, "kg", "%.1f", COL_BOTH, p_loads,
               .json = "axle_kg", .width = AMFI_MAX_AXLES),
    REPORT_COL("spacing%d_m", COL_NUMS, "m", "%.3f", COL_BOTH, p_spacing,
               .json = "spacing_m", .width = AMFI_MAX_AXLES - 1),
    REPORT_COL("status", COL_TEXT, "", NULL, COL_BOTH, p_status),
    REPORT_COL("reason", COL_TEXT, "", NULL, COL_BOTH, p_reason),
    REPORT_COL("speed_given_mps", COL_NUM, "m/s", "%.3f", COL_BOTH, p_given),
    REPORT_COL("speed_estimated", COL_BOOL, "", NULL, COL_BOTH, p_estimated),
    REPORT_COL("n_vehicles", COL_INT, "", NULL, COL_BOTH, p_vehicles),
    REPORT_COL("quality", COL_NUM, "", "%.4g", COL_BOTH, p_quality),
    REPORT_COL("class", COL_TEXT, "", NULL, COL_BOTH, p_class),
};
#undef R

typedef struct list_ctx {
    int fmt;
    int units;
    FILE *f;
    int64_t n;
    int werr; /* 1: the output refused a write */
} list_ctx;

static void table_line(FILE *f, int units, int64_t id, const amfi_passage_row *r)
{
    char t[32], loads[12 * 10 + 1] = "", m[32];
    size_t used = 0;
    for (int a = 0; a < r->n_axles && used < sizeof loads; a++) {
        int w = snprintf(loads + used, sizeof loads - used, "%s%s", a ? "/" : "",
                         report_mass(units, r->axle_kg[a], m));
        used += w > 0 ? (size_t)w : 0;
    }
    char spb[32], gvwb[32];
    const char *sp = report_speed(units, r->speed_mps, spb), *gvw = report_mass(units, r->gvw_kg, gvwb);
    fprintf(f, "%-20s  %8lld  %10lld  %4d  %6s  %2d  %8s  %-28s  %-8s  %.200s\n",
            report_iso(r->utime, t), (long long)id, (long long)r->vehicle_id, r->lane, sp,
            r->n_axles, gvw, loads[0] ? loads : "-", r->status, r->reason);
}

static int list_one(void *vctx, int64_t id, const amfi_passage_row *r)
{
    list_ctx *c = vctx;
    c->n++;
    if (c->fmt == FMT_TABLE) {
        table_line(c->f, c->units, id, r);
        return 0;
    }
    pas_row row = {.id = id, .r = r};
    report_iso(r->utime, row.t);
    if (c->fmt == FMT_CSV) {
        report_cols_csv_row(c->f, passage_cols, REPORT_NCOLS(passage_cols), &row);
        return 0;
    }
    /* streamed: one element at a time, never the whole array */
    json_t *o = report_cols_json_row(passage_cols, REPORT_NCOLS(passage_cols), &row, COL_JSON);
    if (!o || (c->n > 1 && fputc(',', c->f) == EOF) || json_dumpf(o, c->f, JSON_FLAGS)) {
        json_decref(o);
        c->werr = 1;
        return 1;
    }
    json_decref(o);
    return 0;
}

static int list(report_ctx *c, int fmt)
{
    list_ctx l = {fmt, c->units, c->out, 0, 0};
    FILE *f = c->out;
    char hg[16], hl[32];
    snprintf(hg, sizeof hg, "GVW %s", report_mass_unit(c->units));
    snprintf(hl, sizeof hl, "axle loads %s", report_mass_unit(c->units));
    if (fmt == FMT_TABLE)
        fprintf(f, "== passages\n%-20s  %8s  %10s  %4s  %6s  %2s  %8s  %-28s  %-8s  %s\n",
                "time (UTC)", "id", "vehicle", "lane", report_speed_unit(c->units), "ax", hg, hl,
                "status", "reason");
    else if (fmt == FMT_CSV)
        report_cols_csv_header(f, passage_cols, REPORT_NCOLS(passage_cols), NULL, 0);
    else
        fputc('[', f);
    int rc = each(c, c->ex.status, list_one, &l);
    if (l.werr)
        report_fail(c, "passages: cannot write the output");
    if (fmt == FMT_TABLE && rc == 0)
        fprintf(f, "(%lld passages)\n", (long long)l.n);
    if (fmt == FMT_JSON && rc == 0)
        fputc(']', f);
    if (rc == 0 && ferror(f))
        return report_fail(c, "passages: cannot write the output");
    return rc ? -1 : 0;
}

int passages_table(report_ctx *c) { return list(c, FMT_TABLE); }
int passages_export(report_ctx *c) { return list(c, c->format); }

/* ---- histogram per lane ---------------------------------------------------------- */

typedef struct hist_ctx {
    double bin_kg;
    int lanes[MAX_LANES], n_lanes;
    int64_t *count; /* [bin * MAX_LANES + lane index] */
    int n_bins;     /* bins in use: 0 .. n_bins − 1 */
    int64_t other_lanes;
    int oom;
    /* lanes in increasing order, and their columns in count */
    int sorted[MAX_LANES], order[MAX_LANES];
} hist_ctx;

static int hist_one(void *vctx, int64_t id, const amfi_passage_row *r)
{
    hist_ctx *h = vctx;
    (void)id;
    if (!(r->gvw_kg > 0))
        return 0;
    int li = 0;
    while (li < h->n_lanes && h->lanes[li] != r->lane)
        li++;
    if (li == h->n_lanes) {
        if (h->n_lanes == MAX_LANES) {
            h->other_lanes++;
            return 0;
        }
        h->lanes[h->n_lanes++] = r->lane;
    }
    long b = (long)floor(r->gvw_kg / h->bin_kg);
    if (b >= MAX_BINS)
        b = MAX_BINS - 1;
    if (b >= h->n_bins) {
        int64_t *n = realloc(h->count, sizeof *n * (size_t)(b + 1) * MAX_LANES);
        if (!n) {
            h->oom = 1;
            return 1;
        }
        memset(n + (size_t)h->n_bins * MAX_LANES, 0,
               sizeof *n * (size_t)(b + 1 - h->n_bins) * MAX_LANES);
        h->count = n;
        h->n_bins = (int)b + 1;
    }
    h->count[(size_t)b * MAX_LANES + (size_t)li]++;
    return 0;
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The ok passages of the selection counted per bin and lane (h->count
 * freed by the caller). */
static int hist_count(report_ctx *c, hist_ctx *h)
{
    memset(h, 0, sizeof *h);
    h->bin_kg = c->ex.bin_kg;
    int rc = each(c, "ok", hist_one, h);
    if (h->oom)
        rc = report_fail(c, "out of memory for the histogram");
    if (rc)
        return -1;
    /* lanes in increasing order: a permutation of the columns */
    memcpy(h->sorted, h->lanes, sizeof(int) * (size_t)h->n_lanes);
    qsort(h->sorted, (size_t)h->n_lanes, sizeof(int), cmp_int);
    for (int i = 0; i < h->n_lanes; i++)
        for (int j = 0; j < h->n_lanes; j++)
            if (h->lanes[j] == h->sorted[i])
                h->order[i] = j;
    return 0;
}

/* One bin: its range and its counts per lane in increasing lane order. */
typedef struct bin_row {
    double lo, hi;
    int64_t n[MAX_LANES];
    int n_lanes;
    int64_t all;
} bin_row;

static void bin_of(const hist_ctx *h, int b, bin_row *r)
{
    r->lo = b * h->bin_kg;
    r->hi = (b + 1) * h->bin_kg;
    r->n_lanes = h->n_lanes;
    r->all = 0;
    for (int i = 0; i < h->n_lanes; i++) {
        r->n[i] = h->count[(size_t)b * MAX_LANES + (size_t)h->order[i]];
        r->all += r->n[i];
    }
}

static void b_lo(const void *w, report_val *v) { v->x = ((const bin_row *)w)->lo; }
static void b_hi(const void *w, report_val *v) { v->x = ((const bin_row *)w)->hi; }
static void b_counts(const void *w, report_val *v)
{
    v->iv = ((const bin_row *)w)->n;
    v->n = ((const bin_row *)w)->n_lanes;
}
static void b_all(const void *w, report_val *v) { v->i = ((const bin_row *)w)->all; }

static const report_col bin_cols[] = {
    REPORT_COL("gvw_from_kg", COL_NUM, "kg", "%.0f", COL_BOTH, b_lo),
    REPORT_COL("gvw_to_kg", COL_NUM, "kg", "%.0f", COL_BOTH, b_hi),
    REPORT_COL("lane_%d", COL_INTS, "", NULL, COL_BOTH, b_counts,
               .json = "counts"), /* one per lane */
    REPORT_COL("all", COL_INT, "", NULL, COL_BOTH, b_all),
};

int histogram_table(report_ctx *c)
{
    hist_ctx h;
    FILE *f = c->out;
    if (hist_count(c, &h) != 0) {
        free(h.count);
        return -1;
    }
    int64_t lane_total[MAX_LANES] = {0};
    char bw[32], hg[16], lo[32], hi[32];
    snprintf(hg, sizeof hg, "GVW %s", report_mass_unit(c->units));
    fprintf(f, "== GVW histogram of ok passages, %s %s bins\n%-17s",
            report_mass(c->units, c->ex.bin_kg, bw), report_mass_unit(c->units), hg);
    for (int i = 0; i < h.n_lanes; i++)
        fprintf(f, "  lane %-4d", h.sorted[i]);
    fprintf(f, "  %9s\n", "all");
    for (int b = 0; b < h.n_bins; b++) {
        bin_row r;
        bin_of(&h, b, &r);
        if (r.all == 0)
            continue;
        fprintf(f, "%7s .. %7s", report_mass(c->units, r.lo, lo), report_mass(c->units, r.hi, hi));
        for (int i = 0; i < h.n_lanes; i++) {
            lane_total[i] += r.n[i];
            fprintf(f, "  %9lld", (long long)r.n[i]);
        }
        fprintf(f, "  %9lld\n", (long long)r.all);
    }
    fprintf(f, "%-17s", "total");
    int64_t all = 0;
    for (int i = 0; i < h.n_lanes; i++)
        fprintf(f, "  %9lld", (long long)lane_total[i]), all += lane_total[i];
    fprintf(f, "  %9lld\n", (long long)all);
    if (h.other_lanes)
        fprintf(f, "(%lld passages of lanes beyond the first %d not shown)\n",
                (long long)h.other_lanes, MAX_LANES);
    free(h.count);
    return 0;
}

int histogram_export(report_ctx *c)
{
    hist_ctx h;
    if (hist_count(c, &h) != 0) {
        free(h.count);
        return -1;
    }
    json_t *bins = c->format == FMT_JSON ? json_array() : NULL;
    if (c->format == FMT_CSV)
        report_cols_csv_header(c->out, bin_cols, REPORT_NCOLS(bin_cols), h.sorted, h.n_lanes);
    for (int b = 0; b < h.n_bins; b++) {
        bin_row r;
        bin_of(&h, b, &r);
        if (bins)
            json_array_append_new(bins, report_cols_json_row(bin_cols, REPORT_NCOLS(bin_cols),
                                                             &r, COL_JSON));
        else
            report_cols_csv_row(c->out, bin_cols, REPORT_NCOLS(bin_cols), &r);
    }
    if (bins) {
        json_t *o = json_object(), *ln = json_array();
        for (int i = 0; i < h.n_lanes; i++)
            json_array_append_new(ln, json_integer(h.sorted[i]));
        json_object_set_new(o, "bin_kg", json_real(c->ex.bin_kg));
        json_object_set_new(o, "lanes", ln);
        json_object_set_new(o, "bins", bins);
        json_object_set_new(c->root, "histogram", o);
    }
    free(h.count);
    return 0;
}

/* ---- overloads -------------------------------------------------------------------- */

/* What a passage exceeded: its class's GVW limit, or a group's (a single
 * axle outside groups is a group of one). */
typedef struct over_item {
    int group;             /* 0: the gross weight; 1: an axle group */
    int first, n_axles;    /* the group's axles, 0-based (group) */
    const char *kind;      /* "gross", or the group's kind */
    double load_kg, limit_kg;
} over_item;

typedef struct over_row {
    int64_t id;
    const amfi_passage_row *r;
    char t[32], cls[AMFI_CLASS_NAME_LEN], axles[64];
    double gvw_limit_kg;
    const over_item *it; /* the CSV line's item; NULL: a refused passage's line */
    const char *refused; /* why its loads were refused, or NULL */
    int recomputed;      /* 1: refused by the report's classification (no stored reason) */
} over_row;

#define O(row) ((const over_row *)(row))
static void o_time(const void *w, report_val *v) { v->s = O(w)->t; }
static void o_utime(const void *w, report_val *v) { v->i = O(w)->r->utime; }
static void o_id(const void *w, report_val *v) { v->i = O(w)->id; }
static void o_vehicle(const void *w, report_val *v) { v->i = O(w)->r->vehicle_id; }
static void o_lane(const void *w, report_val *v) { v->i = O(w)->r->lane; }
static void o_class(const void *w, report_val *v) { v->s = O(w)->cls; }
static void o_gvw(const void *w, report_val *v) { v->x = O(w)->r->gvw_kg; }
static void o_gvw_limit(const void *w, report_val *v) { v->x = O(w)->gvw_limit_kg; }
static void o_limit(const void *w, report_val *v)
{
    v->s = !O(w)->it ? "refused" : O(w)->it->group ? "group" : "gvw";
}
static void o_axles(const void *w, report_val *v)
{
    v->s = O(w)->axles;
    v->null = !O(w)->it || !O(w)->it->group;
}
static void o_kind(const void *w, report_val *v)
{
    v->s = O(w)->it ? O(w)->it->kind : "";
    v->null = !O(w)->it;
}
static void o_load(const void *w, report_val *v) { v->x = O(w)->it ? O(w)->it->load_kg : NAN; }
static void o_limit_kg(const void *w, report_val *v)
{
    v->x = O(w)->it ? O(w)->it->limit_kg : NAN;
}
static void o_pct(const void *w, report_val *v)
{
    v->x = O(w)->it ? 100.0 * (O(w)->it->load_kg / O(w)->it->limit_kg - 1) : NAN;
}
static void o_refused(const void *w, report_val *v)
{
    v->s = O(w)->refused ? O(w)->refused : "";
    v->null = !O(w)->refused;
}
static void o_source(const void *w, report_val *v)
{
    v->s = O(w)->recomputed ? "recomputed" : "stored";
}
#undef O

/* CSV: one line per limit exceeded, and one line (limit "refused", the
 * reason in loads_refused) per passage whose loads were refused; JSON:
 * the limits inside each passage's "exceeded" array (over_item_cols) after
 * its columns (over_cols), the refused passages in "refused_passages"
 * (refused_cols). */
static const report_col over_cols[] = {
    REPORT_COL("time_utc", COL_WORD, "", NULL, COL_BOTH, o_time),
    REPORT_COL("utime", COL_INT, "us", NULL, COL_BOTH, o_utime),
    REPORT_COL("passage_id", COL_INT, "", NULL, COL_BOTH, o_id),
    REPORT_COL("vehicle_id", COL_INT, "", NULL, COL_BOTH, o_vehicle),
    REPORT_COL("lane", COL_INT, "", NULL, COL_BOTH, o_lane),
    REPORT_COL("class", COL_TEXT, "", NULL, COL_BOTH, o_class),
    REPORT_COL("gvw_kg", COL_NUM, "kg", "%.1f", COL_BOTH, o_gvw),
    REPORT_COL("gvw_limit_kg", COL_NUM, "kg", "%.1f", COL_BOTH, o_gvw_limit),
    REPORT_COL("limit", COL_WORD, "", NULL, COL_CSV, o_limit),
    REPORT_COL("axles", COL_WORD, "", NULL, COL_CSV, o_axles),
    REPORT_COL("kind", COL_WORD, "", NULL, COL_CSV, o_kind),
    REPORT_COL("load_kg", COL_NUM, "kg", "%.1f", COL_CSV, o_load),
    REPORT_COL("limit_kg", COL_NUM, "kg", "%.1f", COL_CSV, o_limit_kg),
    REPORT_COL("over_pct", COL_NUM, "%", "%.3f", COL_CSV, o_pct),
    REPORT_COL("loads_refused", COL_TEXT, "", NULL, COL_CSV, o_refused),
};
static const report_col refused_cols[] = {
    REPORT_COL("time_utc", COL_WORD, "", NULL, COL_JSON, o_time),
    REPORT_COL("utime", COL_INT, "us", NULL, COL_JSON, o_utime),
    REPORT_COL("passage_id", COL_INT, "", NULL, COL_JSON, o_id),
    REPORT_COL("vehicle_id", COL_INT, "", NULL, COL_JSON, o_vehicle),
    REPORT_COL("lane", COL_INT, "", NULL, COL_JSON, o_lane),
    REPORT_COL("class", COL_TEXT, "", NULL, COL_JSON, o_class),
    REPORT_COL("gvw_kg", COL_NUM, "kg", "%.1f", COL_JSON, o_gvw),
    REPORT_COL("loads_refused", COL_TEXT, "", NULL, COL_JSON, o_refused),
    REPORT_COL("reason_from", COL_WORD, "", NULL, COL_JSON, o_source),
};
static const report_col over_item_cols[] = {
    REPORT_COL("limit", COL_WORD, "", NULL, COL_JSON, o_limit),
    REPORT_COL("axles", COL_WORD, "", NULL, COL_JSON, o_axles),
    REPORT_COL("kind", COL_WORD, "", NULL, COL_JSON, o_kind),
    REPORT_COL("load_kg", COL_NUM, "kg", "%.1f", COL_JSON, o_load),
    REPORT_COL("limit_kg", COL_NUM, "kg", "%.1f", COL_JSON, o_limit_kg),
    REPORT_COL("over_pct", COL_NUM, "%", "%.3f", COL_JSON, o_pct),
};

#define MAX_OVER_CLASSES 32

/* The counts of one class. */
typedef struct over_class {
    char name[AMFI_CLASS_NAME_LEN];
    int64_t checked, over_gvw, over_group, over_any, refused;
} over_class;

/* A passage whose loads were refused, kept for the table's own section. */
typedef struct refused_pas {
    int64_t id, utime, vehicle_id;
    int lane, recomputed;
    double gvw_kg;
    char cls[AMFI_CLASS_NAME_LEN];
    char why[AMFI_STORE_LOADS_REFUSED_MAX + 1];
} refused_pas;

typedef struct over_ctx {
    const export_opts *o;
    int units;
    const amfi_class_params *cp;
    int fmt;
    FILE *f;
    json_t *arr, *refused_arr;
    int64_t checked, over_gvw, over_group, over_any, unclassified, refused, recomputed;
    over_class cls[MAX_OVER_CLASSES + 1]; /* the last: every further class */
    int n_cls;
    refused_pas *rp; /* the table's refused passages */
    size_t n_rp, cap_rp;
    int oom;
} over_ctx;

static over_class *class_counts(over_ctx *c, const char *name)
{
    for (int i = 0; i < c->n_cls; i++)
        if (strcmp(c->cls[i].name, name) == 0)
            return &c->cls[i];
    if (c->n_cls == MAX_OVER_CLASSES + 1)
        return &c->cls[MAX_OVER_CLASSES];
    over_class *k = &c->cls[c->n_cls++];
    snprintf(k->name, sizeof k->name, "%s", c->n_cls == MAX_OVER_CLASSES + 1 ? "other" : name);
    return k;
}

/* "2-3": the 1-based axles first .. first + n − 1 */
static void axle_words(int first, int n, char *buf, size_t len)
{
    if (n == 1)
        snprintf(buf, len, "%d", first + 1);
    else
        snprintf(buf, len, "%d-%d", first + 1, first + n);
}

/* A passage whose loads were refused: counted apart (its class's count
 * and the whole), never judged against the limits; CSV and JSON now, the
 * table's section after the overloads. */
static int over_refused(over_ctx *c, over_row *w)
{
    c->refused++;
    c->recomputed += w->recomputed;
    class_counts(c, w->cls)->refused++;
    report_iso(w->r->utime, w->t);
    if (c->fmt == FMT_CSV) {
        w->it = NULL;
        w->axles[0] = '\0';
        report_cols_csv_row(c->f, over_cols, REPORT_NCOLS(over_cols), w);
    } else if (c->fmt == FMT_JSON) {
        json_array_append_new(c->refused_arr, report_cols_json_row(refused_cols,
                                                                   REPORT_NCOLS(refused_cols),
                                                                   w, COL_JSON));
    } else {
        if (c->n_rp == c->cap_rp) {
            size_t cap = c->cap_rp ? 2 * c->cap_rp : 64;
            refused_pas *v = realloc(c->rp, cap * sizeof *v);
            if (!v) {
                c->oom = 1;
                return 1;
            }
            c->rp = v;
            c->cap_rp = cap;
        }
        refused_pas *q = &c->rp[c->n_rp++];
        *q = (refused_pas){.id = w->id, .utime = w->r->utime, .vehicle_id = w->r->vehicle_id,
                           .lane = w->r->lane, .recomputed = w->recomputed,
                           .gvw_kg = w->r->gvw_kg};
        snprintf(q->cls, sizeof q->cls, "%s", w->cls);
        snprintf(q->why, sizeof q->why, "%s", w->refused);
    }
    return 0;
}

static int over_one(void *vctx, int64_t id, const amfi_passage_row *r)
{
    over_ctx *c = vctx;
    amfi_classification cl;
    char why[256];
    over_row w = {.id = id, .r = r};
    over_item it[AMFI_MAX_AXLES + 1];
    int n_it = 0;
    /* the class, its groups and their limits (classes: of --config, else
     * the defaults); the report.limits where no class limit is known */
    if (amfi_classify(c->cp, r->n_axles, r->spacing_m, r->axle_kg, &cl, why, sizeof why) != 0) {
        c->unclassified++;
        memset(&cl, 0, sizeof cl);
        snprintf(cl.name, sizeof cl.name, "unknown");
        cl.gvw_limit_kg = NAN;
        cl.n_groups = r->n_axles;
        for (int a = 0; a < r->n_axles; a++)
            cl.group[a] = (amfi_axle_group){.first = a, .n_axles = 1, .load_kg = r->axle_kg[a],
                                            .kind = AMFI_GROUP_SINGLE, .limit_kg = NAN};
    }
    snprintf(w.cls, sizeof w.cls, "%s", cl.name);
    w.gvw_limit_kg = isfinite(cl.gvw_limit_kg) && cl.gvw_limit_kg > 0 ? cl.gvw_limit_kg
                                                                      : c->o->gvw_limit_kg;
    /* loads amfid's classification refused (passages.loads_refused, store
     * version 13), or, in rows without a stored reason (written before),
     * that the same classification refuses now: never an overload */
    w.refused = r->loads_refused;
    if (!w.refused && cl.n_axles > 0 && !cl.loads_ok && cl.loads_why[0]) {
        w.refused = cl.loads_why;
        w.recomputed = 1;
    }
    if (w.refused)
        return over_refused(c, &w);
    if (r->gvw_kg > w.gvw_limit_kg)
        it[n_it++] = (over_item){0, 0, 0, "gross", r->gvw_kg, w.gvw_limit_kg};
    int og = n_it > 0, ogr = 0;
    for (int g = 0; g < cl.n_groups; g++) {
        const amfi_axle_group *gr = &cl.group[g];
        double lim = gr->limit_kg;
        if (!(isfinite(lim) && lim > 0) && gr->n_axles == 1)
            lim = c->o->axle_limit_kg; /* a single axle without a class limit */
        if (isfinite(lim) && lim > 0 && gr->load_kg > lim) {
            it[n_it++] = (over_item){1, gr->first, gr->n_axles, amfi_group_kind_name(gr->kind),
                                     gr->load_kg, lim};
            ogr = 1;
        }
    }
    c->checked++;
    over_class *k = class_counts(c, cl.name);
    k->checked++;
    k->over_gvw += og;
    k->over_group += ogr;
    k->over_any += og || ogr;
    c->over_gvw += og;
    c->over_group += ogr;
    if (!og && !ogr)
        return 0;
    c->over_any++;
    report_iso(r->utime, w.t);
    if (c->fmt == FMT_TABLE) {
        char m1[32], m2[32];
        fprintf(c->f, "%-20s  %8lld  %10lld  %4d  %-7.7s  %8s  %8s ", w.t, (long long)id,
                (long long)r->vehicle_id, r->lane, w.cls, report_mass(c->units, r->gvw_kg, m1),
                report_mass(c->units, w.gvw_limit_kg, m2));
        for (int i = 0; i < n_it; i++) {
            char ax[64];
            axle_words(it[i].first, it[i].n_axles, ax, sizeof ax);
            if (it[i].group)
                fprintf(c->f, "%s axle%s %s %s %s > %s %s (%+.1f %%)", i ? ";" : "",
                        it[i].n_axles > 1 ? "s" : "", ax, it[i].kind,
                        report_mass(c->units, it[i].load_kg, m1),
                        report_mass(c->units, it[i].limit_kg, m2), report_mass_unit(c->units),
                        100.0 * (it[i].load_kg / it[i].limit_kg - 1));
            else
                fprintf(c->f, " GVW %+.1f %%", 100.0 * (it[i].load_kg / it[i].limit_kg - 1));
        }
        fputc('\n', c->f);
    } else if (c->fmt == FMT_CSV) {
        for (int i = 0; i < n_it; i++) {
            w.it = &it[i];
            axle_words(it[i].first, it[i].n_axles, w.axles, sizeof w.axles);
            report_cols_csv_row(c->f, over_cols, REPORT_NCOLS(over_cols), &w);
        }
    } else {
        json_t *o = report_cols_json_row(over_cols, REPORT_NCOLS(over_cols), &w, COL_JSON);
        json_t *ex = json_array();
        for (int i = 0; i < n_it; i++) {
            w.it = &it[i];
            axle_words(it[i].first, it[i].n_axles, w.axles, sizeof w.axles);
            json_array_append_new(ex, report_cols_json_row(over_item_cols,
                                                           REPORT_NCOLS(over_item_cols), &w,
                                                           COL_JSON));
        }
        json_object_set_new(o, "exceeded", ex);
        json_array_append_new(c->arr, o);
    }
    return 0;
}

static int cmp_class(const void *a, const void *b)
{
    return strcmp(((const over_class *)a)->name, ((const over_class *)b)->name);
}

static int overloads(report_ctx *rc, int fmt)
{
    const export_opts *o = &rc->ex;
    over_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return report_fail(rc, "out of memory");
    *c = (over_ctx){.o = o, .units = rc->units, .cp = rc->classes, .fmt = fmt, .f = rc->out};
    char hg[16], hl[16], l1[32], l2[32];
    snprintf(hg, sizeof hg, "GVW %s", report_mass_unit(rc->units));
    snprintf(hl, sizeof hl, "limit %s", report_mass_unit(rc->units));
    const char *scheme = amfi_class_scheme_name(rc->classes->scheme);
    if (fmt == FMT_TABLE)
        fprintf(c->f, "== overloads (ok passages; limits by class and axle group, scheme %s, %s; "
                      "report.limits GVW %s %s, axle %s %s where no class limit applies)\n"
                      "%-20s  %8s  %10s  %4s  %-7s  %8s  %8s  %s\n",
                scheme, rc->classes_from ? rc->classes_from : "built-in defaults", report_mass(rc->units, o->gvw_limit_kg, l1), report_mass_unit(rc->units),
                report_mass(rc->units, o->axle_limit_kg, l2), report_mass_unit(rc->units),
                "time (UTC)", "id", "vehicle", "lane", "class", hg, hl, "exceeded");
    else if (fmt == FMT_CSV)
        report_cols_csv_header(c->f, over_cols, REPORT_NCOLS(over_cols), NULL, 0);
    else {
        c->arr = json_array();
        c->refused_arr = json_array();
    }
    if (each(rc, "ok", over_one, c) != 0) {
        json_decref(c->arr);
        json_decref(c->refused_arr);
        int oom = c->oom;
        free(c->rp);
        free(c);
        return oom ? report_fail(rc, "out of memory for the passages whose loads were refused")
                   : -1;
    }
    qsort(c->cls, (size_t)c->n_cls, sizeof *c->cls, cmp_class);
    if (fmt == FMT_TABLE) {
        fprintf(c->f, "checked %lld ok passages: %lld over their class's GVW limit, %lld with an "
                      "axle group over its limit, %lld overloaded in all (%.2f %%)\n",
                (long long)c->checked, (long long)c->over_gvw, (long long)c->over_group,
                (long long)c->over_any,
                c->checked ? 100.0 * (double)c->over_any / (double)c->checked : 0.0);
        if (c->refused)
            fprintf(c->f, "(%lld ok passages not checked: their loads were refused, below)\n",
                    (long long)c->refused);
        if (c->unclassified)
            fprintf(c->f, "(%lld passages could not be classified: their limits are "
                          "report.limits')\n", (long long)c->unclassified);
        if (c->n_cls > 0)
            fprintf(c->f, "%-8s  %8s  %8s  %10s  %10s  %7s  %7s\n", "class", "checked",
                    "over GVW", "over group", "overloaded", "%", "refused");
        for (int i = 0; i < c->n_cls; i++) {
            char pct[16] = "-";
            if (c->cls[i].checked)
                snprintf(pct, sizeof pct, "%.2f",
                         100.0 * (double)c->cls[i].over_any / (double)c->cls[i].checked);
            fprintf(c->f, "%-8s  %8lld  %8lld  %10lld  %10lld  %7s  %7lld\n", c->cls[i].name,
                    (long long)c->cls[i].checked, (long long)c->cls[i].over_gvw,
                    (long long)c->cls[i].over_group, (long long)c->cls[i].over_any, pct,
                    (long long)c->cls[i].refused);
        }
        if (c->refused) {
            char m1[32];
            fprintf(c->f, "== loads refused (%lld ok passages: a single axle or a group below "
                          "zero, or above %g x any legal load of its axle count; not judged "
                          "against the limits, never an overload)\n"
                          "%-20s  %8s  %10s  %4s  %-7s  %8s  %s\n",
                    (long long)c->refused, AMFI_CLASS_IMPLAUSIBLE_FACTOR, "time (UTC)", "id",
                    "vehicle", "lane", "class", hg, "why");
            for (size_t i = 0; i < c->n_rp; i++) {
                const refused_pas *q = &c->rp[i];
                char t[32];
                report_iso(q->utime, t);
                fprintf(c->f, "%-20s  %8lld  %10lld  %4d  %-7.7s  %8s  loads refused: %s%s\n", t,
                        (long long)q->id, (long long)q->vehicle_id, q->lane, q->cls,
                        report_mass(c->units, q->gvw_kg, m1), q->why,
                        q->recomputed ? " (recomputed: no reason stored)" : "");
            }
        }
    } else if (fmt == FMT_JSON) {
        json_t *ob = json_object(), *bc = json_array();
        json_object_set_new(ob, "scheme", json_string(scheme));
        json_object_set_new(ob, "limits_from",
                            json_string(rc->classes_from ? rc->classes_from : "built-in defaults"));
        json_object_set_new(ob, "gvw_limit_kg", json_real(o->gvw_limit_kg));
        json_object_set_new(ob, "axle_limit_kg", json_real(o->axle_limit_kg));
        json_object_set_new(ob, "checked", json_integer(c->checked));
        json_object_set_new(ob, "over_gvw", json_integer(c->over_gvw));
        json_object_set_new(ob, "over_group", json_integer(c->over_group));
        json_object_set_new(ob, "overloaded", json_integer(c->over_any));
        json_object_set_new(ob, "unclassified", json_integer(c->unclassified));
        json_object_set_new(ob, "refused", json_integer(c->refused));
        json_object_set_new(ob, "refused_recomputed", json_integer(c->recomputed));
        for (int i = 0; i < c->n_cls; i++) {
            json_t *k = json_object();
            json_object_set_new(k, "class", json_string(c->cls[i].name));
            json_object_set_new(k, "checked", json_integer(c->cls[i].checked));
            json_object_set_new(k, "over_gvw", json_integer(c->cls[i].over_gvw));
            json_object_set_new(k, "over_group", json_integer(c->cls[i].over_group));
            json_object_set_new(k, "overloaded", json_integer(c->cls[i].over_any));
            json_object_set_new(k, "refused", json_integer(c->cls[i].refused));
            json_array_append_new(bc, k);
        }
        json_object_set_new(ob, "by_class", bc);
        json_object_set_new(ob, "passages", c->arr);
        json_object_set_new(ob, "refused_passages", c->refused_arr);
        json_object_set_new(rc->root, "overloads", ob);
    }
    free(c->rp);
    free(c);
    return 0;
}

int overloads_table(report_ctx *c) { return overloads(c, FMT_TABLE); }
int overloads_export(report_ctx *c) { return overloads(c, c->format); }

/* ---- plots ---------------------------------------------------------------------- */

static const char *const status_colour[AMFI_STORE_N_STATUS] = {
    "#1f77b4", "#ff7f0e", "#9467bd", "#d62728", "#8c564b", "#7f7f7f", "#000000"};

/* gvw.png: the GVW per passage over time with the baseline band; writes
 * passages.dat (t gvw status speed, in p->units) and band.dat. */
int passages_plot_gvw(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    FILE *f = report_data_open(p->dir, "passages.dat", err, errlen);
    if (!f)
        return -1;
    const int u = p->units;
    const char *mu = report_mass_unit(u), *su = report_speed_unit(u);
    fprintf(f, "# time_s gvw_%s status(0 ok,1 gap,2 late,3 overload,4 multiple,5 invalid,6 error) speed_%s\n",
            mu, u == AMFI_REPORT_UNITS_ENGINEERING ? "kmh" : "mps");
    size_t n_gvw = 0;
    for (size_t k = 0; k < p->n_pas; k++) {
        const report_pas *a = &p->pas[k];
        fprintf(f, "%.3f %.4f %d %.3f\n", a->t, isnan(a->gvw) ? NAN : report_mass_val(u, a->gvw),
                a->status, isnan(a->speed) ? NAN : report_speed_val(u, a->speed));
        n_gvw += !isnan(a->gvw);
    }
    if (report_data_close(f, p->dir, "passages.dat", err, errlen) != 0)
        return -1;
    /* band.dat: baseline mean ± 2 STD from when it applies */
    if (!(f = report_data_open(p->dir, "band.dat", err, errlen)))
        return -1;
    if (p->found) {
        const amfi_baseline *b = &p->b;
        double tb = fmax(p->t0, (double)b->utime_set / 1e6);
        for (int k = 0; k < 2; k++)
            fprintf(f, "%.3f %.4f %.4f %.4f\n", k ? p->t1 : tb,
                    report_mass_val(u, b->mean_kg - 2 * b->std_kg),
                    report_mass_val(u, b->mean_kg + 2 * b->std_kg), report_mass_val(u, b->mean_kg));
    } else {
        fprintf(f, "%.3f NaN NaN NaN\n", p->t0);
    }
    if (report_data_close(f, p->dir, "band.dat", err, errlen) != 0)
        return -1;
    fprintf(p->gp,
        "set output o.'gvw.png'\n"
        "set title \"Inferred gross vehicle weight per passage\\n%s\"\n"
        "set ylabel 'GVW (%s)'\n"
        "%s"
        "plot d.'band.dat' using 1:2:3 with filledcurves fc rgb '#b0d0b0' fs transparent solid 0.5 title 'baseline mean +/- 2 STD', \\\n"
        "     d.'band.dat' using 1:4 with lines lw 2 lc rgb '#2ca02c' title 'baseline mean', \\\n"
        "     d.'passages.dat' using 1:($3==0?$2:NaN) with points pt 7 ps 0.4 lc rgb '#1f77b4' title 'ok', \\\n"
        "     d.'passages.dat' using 1:($3!=0?$2:NaN) with points pt 2 ps 0.6 lc rgb '#d62728' title 'not ok (solved)'\n"
        "unset label 99\nset autoscale y\n",
        p->sub, mu,
        /* gnuplot refuses a plot without one valid point: a fixed range and a word */
        n_gvw ? "" : u == AMFI_REPORT_UNITS_ENGINEERING
                         ? "set yrange [0:60]\nset label 99 'no passage with an inferred GVW in this store' at graph 0.5, graph 0.5 center\n"
                         : "set yrange [0:60000]\nset label 99 'no passage with an inferred GVW in this store' at graph 0.5, graph 0.5 center\n");
    (void)su;
    *made = 1;
    return 0;
}

/* gvw_histogram.png: the baseline sample (the b.n ok passages up to the
 * baseline's time, else the first window) against the latest window;
 * writes histogram.dat. */
int passages_plot_histogram(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    size_t n = p->n_pas, n_ok = 0;
    double *ok = malloc((n + 1) * sizeof *ok);
    if (!ok) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < n; k++)
        if (p->pas[k].status == 0 && !isnan(p->pas[k].gvw))
            ok[n_ok++] = report_mass_val(p->units, p->pas[k].gvw);
    int win = p->n_ind > 0 && p->ind[0].row.n > 0 ? p->ind[0].row.n : 500;
    size_t nb_end = 0, nb = 0, nla = n_ok < (size_t)win ? n_ok : (size_t)win;
    if (p->found) {
        for (size_t k = 0, j = 0; k < n; k++)
            if (p->pas[k].status == 0 && !isnan(p->pas[k].gvw)) {
                j++;
                if (p->pas[k].t <= (double)p->b.utime_set / 1e6)
                    nb_end = j;
            }
        nb = nb_end < (size_t)p->b.n ? nb_end : (size_t)p->b.n;
    } else {
        nb_end = nb = nla;
    }
    const double *bl = ok + (nb_end - nb), *la = ok + (n_ok - nla);
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (size_t k = 0; k < n_ok; k++) {
        lo = fmin(lo, ok[k]);
        hi = fmax(hi, ok[k]);
    }
    if (!(hi > lo)) {
        lo = 0;
        hi = report_mass_val(p->units, 60000);
    }
    int nbins = 30;
    double w = (hi - lo) / nbins, hb[64], hl[64];
    report_hist(bl, nb, lo, w, nbins, hb);
    report_hist(la, nla, lo, w * (1 + 1e-12), nbins, hl);
    free(ok);
    FILE *f = report_data_open(p->dir, "histogram.dat", err, errlen);
    if (!f)
        return -1;
    const char *mu = report_mass_unit(p->units);
    fprintf(f, "# gvw_%s_bin_centre baseline_fraction latest_fraction (bin %.3f %s; baseline n %zu, latest n %zu)\n",
            mu, w, mu, nb, nla);
    for (int k = 0; k < nbins; k++)
        fprintf(f, "%.4f %.5f %.5f\n", lo + (k + 0.5) * w, hb[k], hl[k]);
    if (report_data_close(f, p->dir, "histogram.dat", err, errlen) != 0)
        return -1;
    fprintf(p->gp,
        "set output o.'gvw_histogram.png'\n"
        "set xdata\nset format x '%%g'\nset autoscale x\n"
        "set title \"GVW distribution: baseline (%zu ok passages) against the latest window (%zu)\\n%s\"\n"
        "set xlabel 'GVW (%s), bins of %.*f %s'\nset ylabel 'fraction of passages'\n"
        "set style fill transparent solid 0.45 noborder\nset boxwidth %.4f\n"
        "plot d.'histogram.dat' using 1:2 with boxes lc rgb '#2ca02c' title 'baseline', \\\n"
        "     d.'histogram.dat' using 1:3 with boxes lc rgb '#d62728' title 'latest window'\n",
        nb, nla, p->sub, mu, p->units == AMFI_REPORT_UNITS_ENGINEERING ? 2 : 0, w, mu, w);
    *made = 1;
    return 0;
}

/* passages_per_hour.png: passages per hour by status, cumulative columns so
 * the boxes stack. A bucket is one hour (what the axis says), or one day
 * over more than 400 hours (then its mean per hour). Writes hourly.dat. */
int passages_plot_per_hour(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    const double t0 = p->t0, t1 = p->t1;
    const double bw = (t1 - t0) / 3600 <= 400 ? 3600 : 86400;
    int nbk = (int)floor((t1 - t0) / bw) + 1;
    if (nbk > 100000)
        nbk = 100000;
    double *cnt = calloc((size_t)nbk * AMFI_STORE_N_STATUS, sizeof *cnt);
    if (!cnt) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    double tb0 = floor(t0 / bw) * bw;
    for (size_t k = 0; k < p->n_pas; k++) {
        int i = (int)floor((p->pas[k].t - tb0) / bw);
        if (i >= 0 && i < nbk)
            cnt[(size_t)i * AMFI_STORE_N_STATUS + (size_t)p->pas[k].status] += 3600.0 / bw;
    }
    FILE *f = report_data_open(p->dir, "hourly.dat", err, errlen);
    if (!f) {
        free(cnt);
        return -1;
    }
    fprintf(f, "# bucket_centre_s then per hour, cumulative: ok +gap +late +overload +multiple +invalid +error (bucket %.0f s)\n", bw);
    for (int i = 0; i < nbk; i++) {
        double c = 0;
        fprintf(f, "%.0f", tb0 + (i + 0.5) * bw);
        for (int k = 0; k < AMFI_STORE_N_STATUS; k++) {
            c += cnt[(size_t)i * AMFI_STORE_N_STATUS + (size_t)k];
            fprintf(f, " %.2f", c);
        }
        fputc('\n', f);
    }
    free(cnt);
    if (report_data_close(f, p->dir, "hourly.dat", err, errlen) != 0)
        return -1;
    fprintf(p->gp,
        "set output o.'passages_per_hour.png'\n"
        "set xdata time\nset format x \"%%H:%%M\\n%%d %%b\"\nset xrange [%.3f:%.3f]\n"
        "set title \"Passages per hour by status (buckets of %s)\\n%s\"\n"
        "set xlabel 'time (UTC, data time)'\nset ylabel 'passages per hour'\n"
        "set style fill solid 0.8 border lc rgb 'black'\nset boxwidth %.0f\nset yrange [0:*]\n"
        "plot ",
        tb0, tb0 + nbk * bw, bw == 3600 ? "1 h" : "1 day, mean per hour", p->sub, bw * 0.9);
    for (int k = AMFI_STORE_N_STATUS - 1; k >= 0; k--)
        fprintf(p->gp, "d.'hourly.dat' using 1:%d with boxes lc rgb '%s' title '%s'%s", k + 2,
                status_colour[k], amfi_store_status_name(k), k ? ", \\\n     " : "\n");
    *made = 1;
    return 0;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* speed.png: the speed distribution in bins of 2 km/h (engineering) or
 * 0.5 m/s (si); writes speed.dat. */
int passages_plot_speed(report_plot_frame *p, int *made, char *err, size_t errlen)
{
    size_t n_sp = 0;
    double *sp = malloc((p->n_pas + 1) * sizeof *sp);
    if (!sp) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < p->n_pas; k++)
        if (!isnan(p->pas[k].speed))
            sp[n_sp++] = report_speed_val(p->units, p->pas[k].speed);
    FILE *f = report_data_open(p->dir, "speed.dat", err, errlen);
    if (!f) {
        free(sp);
        return -1;
    }
    const int eng = p->units == AMFI_REPORT_UNITS_ENGINEERING;
    const double bw = eng ? 2.0 : 0.5;
    const char *su = report_speed_unit(p->units);
    fprintf(f, "# speed_%s_bin_centre passages (bin %g %s)\n", eng ? "kmh" : "mps", bw, su);
    qsort(sp, n_sp, sizeof *sp, cmp_d);
    for (size_t k = 0; k < n_sp;) {
        double b0 = floor(sp[k] / bw) * bw;
        size_t c = 0;
        while (k < n_sp && sp[k] < b0 + bw) {
            c++;
            k++;
        }
        fprintf(f, "%.2f %zu\n", b0 + bw / 2, c);
    }
    if (n_sp == 0)
        fprintf(f, "NaN 0\n");
    free(sp);
    if (report_data_close(f, p->dir, "speed.dat", err, errlen) != 0)
        return -1;
    fprintf(p->gp,
        "set output o.'speed.png'\n"
        "set xdata\nset format x '%%g'\nset autoscale x\nset yrange [0:*]\n"
        "set title \"Speed distribution (%zu passages with a speed)\\n%s\"\n"
        "set xlabel 'speed (%s), bins of %g %s'\nset ylabel 'passages'\n"
        "set style fill solid 0.7 border lc rgb 'black'\nset boxwidth %g\n"
        "%s"
        "plot d.'speed.dat' using 1:2 with boxes lc rgb '#1f77b4' title 'passages'\n"
        "set output\n",
        n_sp, p->sub, su, bw, su, 0.9 * bw,
        n_sp ? "" : eng ? "set xrange [0:150]\nset yrange [0:1]\nset label 99 'no passage with a speed in this store' at graph 0.5, graph 0.5 center\n"
                        : "set xrange [0:42]\nset yrange [0:1]\nset label 99 'no passage with a speed in this store' at graph 0.5, graph 0.5 center\n");
    *made = 1;
    return 0;
}
