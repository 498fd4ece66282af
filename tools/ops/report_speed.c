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

#include "amfi_json.h"

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
    return export_utc(utime, "%Y-%m-%d", buf);
}

/* "%+.2f %%" or "-" */
static const char *pct(double x, char buf[32])
{
    if (isnan(x))
        return "-";
    snprintf(buf, 32, "%+.2f %%", fabs(x) < 0.005 ? 0.0 : x); /* never "-0.00 %" */
    return buf;
}

static void csv_row(FILE *f, const char *day, const speed_stats *st)
{
    const double v[] = {st->median, st->p5, st->p25, st->p75, st->p95, st->mean, st->std,
                        st->over1, st->over3};
    fprintf(f, "%s,%zu", day, st->n);
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        fputc(',', f);
        if (!isnan(v[k]))
            fprintf(f, "%.4f", v[k]);
    }
    fputc('\n', f);
}

static json_t *json_stats(const speed_stats *st, int full)
{
    json_t *o = json_object();
    json_object_set_new(o, "n", json_integer((json_int_t)st->n));
    json_object_set_new(o, "median_pct", amfi_json_num(st->median));
    json_object_set_new(o, "p5_pct", amfi_json_num(st->p5));
    if (full)
        json_object_set_new(o, "p25_pct", amfi_json_num(st->p25)),
        json_object_set_new(o, "p75_pct", amfi_json_num(st->p75));
    json_object_set_new(o, "p95_pct", amfi_json_num(st->p95));
    json_object_set_new(o, "mean_pct", amfi_json_num(st->mean));
    json_object_set_new(o, "std_pct", amfi_json_num(st->std));
    if (full)
        json_object_set_new(o, "over_1pct_share_pct", amfi_json_num(st->over1)),
        json_object_set_new(o, "over_3pct_share_pct", amfi_json_num(st->over3));
    return o;
}

int export_speed(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root, char *err,
                 size_t errlen)
{
    speed_stats all;
    speed_day *d = NULL;
    size_t nd = 0;
    char a[32], b[32], c[32], t[32];
    if (speed_corrections(s, o, &all, &d, &nd, err, errlen) != 0)
        return -1;
    if (fmt == FMT_TABLE) {
        fprintf(f, "== speed corrections (c = speed weighed with / detector's speed - 1)\n");
        if (all.n == 0) {
            fprintf(f, "(no estimated passages in the selection: amfid estimates the speed "
                       "with solver.speed: estimate)\n");
        } else {
            fprintf(f, "estimated    %zu passages, %s .. %s\n", all.n,
                    day_str(d[0].day_utime, a), day_str(d[nd - 1].day_utime, b));
            if (isnan(all.std))
                snprintf(c, sizeof c, "-");
            else
                snprintf(c, sizeof c, "%.2f %%", all.std);
            fprintf(f, "c            median %s, mean %s, STD %s\n", pct(all.median, a),
                    pct(all.mean, b), c);
            fprintf(f, "percentiles  p5 %s, p25 %s, ", pct(all.p5, a), pct(all.p25, b));
            fprintf(f, "p75 %s, ", pct(all.p75, a));
            fprintf(f, "p95 %s\n", pct(all.p95, b));
            fprintf(f, "|c| > 1 %%    %.1f %% of them; |c| > 3 %%: %.1f %%\n", all.over1,
                    all.over3);
            fprintf(f, "%-10s  %6s  %9s  %9s  %9s\n", "day (UTC)", "n", "median", "p5", "p95");
            for (size_t k = 0; k < nd; k++)
                fprintf(f, "%-10s  %6zu  %9s  %9s  %9s\n", day_str(d[k].day_utime, t),
                        d[k].st.n, pct(d[k].st.median, a), pct(d[k].st.p5, b),
                        pct(d[k].st.p95, c));
        }
    } else if (fmt == FMT_CSV) {
        fprintf(f, "day,n,median_pct,p5_pct,p25_pct,p75_pct,p95_pct,mean_pct,std_pct,"
                   "over_1pct_share_pct,over_3pct_share_pct\n");
        csv_row(f, "all", &all);
        for (size_t k = 0; k < nd; k++)
            csv_row(f, day_str(d[k].day_utime, t), &d[k].st);
    } else {
        json_t *so = json_stats(&all, 1), *arr = json_array();
        for (size_t k = 0; k < nd; k++) {
            json_t *e = json_object();
            json_object_set_new(e, "day", json_string(day_str(d[k].day_utime, t)));
            json_t *st = json_stats(&d[k].st, 0);
            json_object_update(e, st); /* "day" first, then the statistics */
            json_decref(st);
            json_array_append_new(arr, e);
        }
        json_object_set_new(so, "days", arr);
        json_object_set_new(root, "speed", so);
    }
    free(d);
    return 0;
}
