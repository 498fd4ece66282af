/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_export.c: amfi-report's records (report_export.h): every section in
 * CSV and JSON, and the passage list, the GVW histogram per lane and the
 * overloads against legal limits in all three formats. Streams the passages
 * (amfi_store_each_passage_where, filtered in SQL): a year of traffic is
 * never held in memory; the passage list is written row by row in every
 * format (in JSON, element by element into the document's "passages").
 */
#define _GNU_SOURCE
#include "report_export.h"
#include "report_natfreq.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_json.h"

#define MAX_LANES 64 /* distinct lanes a histogram keeps apart */
#define MAX_BINS 100000

/* ---- small writers ------------------------------------------------------- */

const char *export_utc(int64_t utime, const char *fmt, char buf[32])
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (!gmtime_r(&t, &tm) || strftime(buf, 32, fmt, &tm) == 0)
        snprintf(buf, 32, "%lld", (long long)utime);
    return buf;
}

static const char *iso(int64_t utime, char buf[32])
{
    return export_utc(utime, "%Y-%m-%dT%H:%M:%SZ", buf);
}

/* Would a spreadsheet read this text cell as a formula? It starts, after
 * any blanks, with = + - @ (or their full-width forms U+FF1D U+FF0B
 * U+FF0D U+FF20), or with a tab, carriage return or line feed (the OWASP
 * CSV-injection set). */
static int csv_formula_like(const char *s)
{
    while (*s == ' ')
        s++;
    if (*s && strchr("=+-@\t\r\n", *s))
        return 1;
    const unsigned char *u = (const unsigned char *)s;
    return u[0] == 0xef && ((u[1] == 0xbc && (u[2] == 0x9d || u[2] == 0x8b || u[2] == 0x8d))
                            || (u[1] == 0xbc && u[2] == 0xa0));
}

/* A text field from the store, RFC 4180: quoted when it holds a comma, a
 * quote or a line break, and a cell that would start a formula neutralised
 * with a leading single quote (the text is still all there). Numbers are
 * written by csv_num and fprintf, never through here. */
static void csv_str(FILE *f, const char *s)
{
    int neutral = csv_formula_like(s);
    if (!strpbrk(s, ",\"\r\n")) {
        if (neutral)
            fputc('\'', f);
        fputs(s, f);
        return;
    }
    fputc('"', f);
    if (neutral)
        fputc('\'', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* A number field: empty when unknown (NaN). */
static void csv_num(FILE *f, double x, const char *fmt)
{
    if (!isnan(x))
        fprintf(f, fmt, x);
}

static json_t *jstr(const char *s) { return json_string(s ? s : ""); }

/* ---- time ------------------------------------------------------------------ */

/* n digits at *p into *v; 0, or -1 when fewer digits are there */
static int digits(const char **p, int n, int *v)
{
    *v = 0;
    for (int k = 0; k < n; k++, (*p)++) {
        if (**p < '0' || **p > '9')
            return -1;
        *v = *v * 10 + (**p - '0');
    }
    return 0;
}

#define WHY(...) (snprintf(why, whylen, __VA_ARGS__), -1)

int export_parse_time(const char *s, int end_of, int64_t *utime, char *why, size_t whylen)
{
    const char *p = s;
    int y, mo, d, h = 0, mi = 0, sec = 0, us = 0, prec = 0; /* prec: 0 day, 1 min, 2 s, 3 µs */
    if (digits(&p, 4, &y) || *p != '-')
        return WHY("no year YYYY- at its start");
    p++;
    if (digits(&p, 2, &mo) || *p != '-')
        return WHY("no month MM- after the year");
    p++;
    if (digits(&p, 2, &d))
        return WHY("no day DD after the month");
    if (*p == 'T' || *p == 't' || (*p == ' ' && p[1])) {
        p++;
        if (digits(&p, 2, &h) || *p != ':' || (p++, digits(&p, 2, &mi)))
            return WHY("no time HH:MM after '%c'", s[10]);
        prec = 1;
        if (*p == ':') {
            p++;
            if (digits(&p, 2, &sec))
                return WHY("no seconds SS after HH:MM:");
            prec = 2;
            if (*p == '.' || *p == ',') {
                int n = 0;
                for (p++; *p >= '0' && *p <= '9'; p++, n++)
                    if (n < 6)
                        us = us * 10 + (*p - '0');
                if (n == 0)
                    return WHY("no digits after the decimal mark");
                for (int k = n; k < 6; k++)
                    us *= 10;
                prec = 3;
            }
        }
    }
    /* UTC only: Z, or an offset of zero */
    if (*p == 'Z' || *p == 'z')
        p++;
    else if ((*p == '+' || *p == '-') && prec > 0) {
        const char *o = p++;
        int oh = 0, om = 0;
        int bad = digits(&p, 2, &oh);
        if (!bad && *p == ':')
            p++;
        if (bad || digits(&p, 2, &om))
            return WHY("'%s' is not a UTC offset", o);
        if (oh || om)
            return WHY("offset %.6s: only UTC times (Z or +00:00)", o);
    }
    if (*p)
        return WHY("unexpected '%.20s'", p);
    if (y < 1970 || y > 9999)
        return WHY("year %d is not in 1970 .. 9999", y);
    if (mo < 1 || mo > 12)
        return WHY("month %d is not in 1 .. 12", mo);
    static const int mdays[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    if (d < 1 || d > mdays[mo - 1] || (mo == 2 && d == 29 && !leap))
        return WHY("day %d is not in %04d-%02d", d, y, mo);
    if (h > 23)
        return WHY("hour %d is not in 0 .. 23", h);
    if (mi > 59)
        return WHY("minute %d is not in 0 .. 59", mi);
    if (sec > 59)
        return WHY("second %d is not in 0 .. 59", sec);
    struct tm tm;
    memset(&tm, 0, sizeof tm);
    tm.tm_year = y - 1900;
    tm.tm_mon = mo - 1;
    tm.tm_mday = d;
    tm.tm_hour = h;
    tm.tm_min = mi;
    tm.tm_sec = sec;
    time_t t = timegm(&tm);
    if (t == (time_t)-1)
        return WHY("not a time this system can represent");
    *utime = (int64_t)t * 1000000 + us;
    if (end_of) {
        static const int64_t span[3] = {INT64_C(86400000000), 60000000, 1000000};
        if (prec < 3)
            *utime += span[prec] - 1; /* the last µs of that day, minute or second */
    }
    return 0;
}

/* ---- statistics shared with amfi-report's tables ---------------------------------- */

void report_mean_std(const double *v, size_t n, double *mean, double *std)
{
    double s = 0, q = 0;
    for (size_t k = 0; k < n; k++)
        s += v[k];
    *mean = n ? s / (double)n : NAN;
    for (size_t k = 0; k < n; k++)
        q += (v[k] - *mean) * (v[k] - *mean);
    *std = n > 1 ? sqrt(q / (double)(n - 1)) : NAN;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void report_sort(double *v, size_t n)
{
    if (n > 1)
        qsort(v, n, sizeof *v, cmp_double);
}

double report_percentile(const double *v, size_t n, double p)
{
    if (n == 0)
        return NAN;
    size_t k = (size_t)ceil(p / 100.0 * (double)n);
    return v[k > 0 ? k - 1 : 0];
}

/* ---- amfid's intake counters (meta intake.*) ----------------------------------- */

int export_read_intake(amfi_store *s, report_intake *in, char *err, size_t errlen)
{
    struct {
        const char *key;
        long long *v;
    } kv[] = {{"intake.run", &in->run},           {"intake.messages_received", &in->received},
              {"intake.messages_refused", &in->refused}, {"intake.datagrams_dropped", &in->dropped},
              {"intake.samples_missing", &in->missing},  {"intake.passages_lost", &in->lost}};
    char val[64];
    int found = 0;
    memset(in, 0, sizeof *in);
    for (size_t i = 0; i < sizeof kv / sizeof kv[0]; i++) {
        if (amfi_store_meta_get(s, kv[i].key, val, sizeof val, &found, err, errlen))
            return -1;
        if (!found)
            return 0;
        char *end = NULL;
        *kv[i].v = strtoll(val, &end, 10);
        if (end == val || *end || *kv[i].v < 0) {
            snprintf(err, errlen, "meta: %s is '%s', not a count", kv[i].key, val);
            return -1;
        }
    }
    if (amfi_store_meta_get(s, "intake.as_of", in->as_of, sizeof in->as_of, &found, err, errlen))
        return -1;
    in->found = 1;
    return 0;
}

/* ---- summary, trend, alerts, errors: csv and json ------------------------------ */

int export_summary(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen)
{
    amfi_passage_summary sum;
    amfi_baseline b;
    int found = 0;
    double *g = NULL;
    size_t ng = 0;
    report_intake in;
    natfreq_stats nf;
    if (amfi_store_passage_summary(s, &sum, err, errlen) ||
        amfi_store_all_ok_gvw(s, &g, &ng, err, errlen) ||
        amfi_store_get_baseline(s, &b, &found, err, errlen) ||
        export_read_intake(s, &in, err, errlen) || natfreq_read_stats(s, &nf, err, errlen)) {
        free(g);
        return -1;
    }
    double mean, std;
    report_mean_std(g, ng, &mean, &std);
    report_sort(g, ng);
    double mn = ng ? g[0] : NAN, mx = ng ? g[ng - 1] : NAN;
    free(g);
    char a[32], c[32];
    if (fmt == FMT_CSV) {
        fprintf(f, "item,value\n");
        fprintf(f, "time_first,%s\n", sum.total ? iso(sum.utime_first, a) : "");
        fprintf(f, "time_last,%s\n", sum.total ? iso(sum.utime_last, c) : "");
        fprintf(f, "passages,%lld\n", (long long)sum.total);
        for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
            fprintf(f, "passages_%s,%lld\n", amfi_store_status_name(k),
                    (long long)sum.by_status[k]);
        fprintf(f, "gvw_ok_n,%zu\n", ng);
        fprintf(f, "gvw_ok_mean_kg,"), csv_num(f, mean, "%.1f"), fputc('\n', f);
        fprintf(f, "gvw_ok_std_kg,"), csv_num(f, std, "%.1f"), fputc('\n', f);
        fprintf(f, "gvw_ok_min_kg,"), csv_num(f, mn, "%.1f"), fputc('\n', f);
        fprintf(f, "gvw_ok_max_kg,"), csv_num(f, mx, "%.1f"), fputc('\n', f);
        fprintf(f, "baseline_mean_kg,"), csv_num(f, found ? b.mean_kg : NAN, "%.1f"),
            fputc('\n', f);
        fprintf(f, "baseline_std_kg,"), csv_num(f, found ? b.std_kg : NAN, "%.1f"),
            fputc('\n', f);
        fprintf(f, "baseline_n,%d\n", found ? b.n : 0);
        if (in.found) {
            fprintf(f, "intake_run,%lld\nintake_as_of,", in.run);
            csv_str(f, in.as_of);
            fprintf(f, "\nintake_messages_received,%lld\n"
                       "intake_messages_refused,%lld\nintake_datagrams_dropped,%lld\n"
                       "intake_samples_missing,%lld\nintake_passages_lost,%lld\n",
                    in.received, in.refused, in.dropped, in.missing, in.lost);
        }
        fprintf(f, "f1_n,%zu\n", nf.n);
        fprintf(f, "f1_mean_hz,"), csv_num(f, nf.mean_hz, "%.6f"), fputc('\n', f);
        fprintf(f, "f1_sd_hz,"), csv_num(f, nf.sd_hz, "%.6f"), fputc('\n', f);
        fprintf(f, "f1_comp_n,%zu\n", nf.n_comp);
        fprintf(f, "f1_comp_mean_hz,"), csv_num(f, nf.comp_mean_hz, "%.6f"), fputc('\n', f);
        fprintf(f, "f1_comp_sd_hz,"), csv_num(f, nf.comp_sd_hz, "%.6f"), fputc('\n', f);
        return 0;
    }
    json_t *o = json_object(), *st = json_object();
    json_object_set_new(o, "passages", json_integer(sum.total));
    json_object_set_new(o, "time_first", sum.total ? jstr(iso(sum.utime_first, a)) : json_null());
    json_object_set_new(o, "time_last", sum.total ? jstr(iso(sum.utime_last, c)) : json_null());
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        json_object_set_new(st, amfi_store_status_name(k), json_integer(sum.by_status[k]));
    json_object_set_new(o, "by_status", st);
    json_t *gv = json_object();
    json_object_set_new(gv, "n", json_integer((json_int_t)ng));
    json_object_set_new(gv, "mean_kg", amfi_json_num(mean));
    json_object_set_new(gv, "std_kg", amfi_json_num(std));
    json_object_set_new(gv, "min_kg", amfi_json_num(mn));
    json_object_set_new(gv, "max_kg", amfi_json_num(mx));
    json_object_set_new(o, "gvw_ok", gv);
    if (found) {
        json_t *bl = json_object();
        json_object_set_new(bl, "mean_kg", amfi_json_num(b.mean_kg));
        json_object_set_new(bl, "std_kg", amfi_json_num(b.std_kg));
        json_object_set_new(bl, "n", json_integer(b.n));
        json_object_set_new(bl, "source", jstr(b.source));
        json_object_set_new(bl, "from", jstr(iso(b.utime_set, a)));
        json_object_set_new(o, "baseline", bl);
    } else {
        json_object_set_new(o, "baseline", json_null());
    }
    if (in.found) {
        json_t *it = json_object();
        json_object_set_new(it, "run", json_integer(in.run));
        json_object_set_new(it, "as_of", jstr(in.as_of));
        json_object_set_new(it, "messages_received", json_integer(in.received));
        json_object_set_new(it, "messages_refused", json_integer(in.refused));
        json_object_set_new(it, "datagrams_dropped", json_integer(in.dropped));
        json_object_set_new(it, "samples_missing", json_integer(in.missing));
        json_object_set_new(it, "passages_lost", json_integer(in.lost));
        json_object_set_new(o, "intake", it);
    } else {
        json_object_set_new(o, "intake", json_null());
    }
    json_t *nfo = json_object();
    json_object_set_new(nfo, "n", json_integer((json_int_t)nf.n));
    json_object_set_new(nfo, "mean_hz", amfi_json_num(nf.mean_hz));
    json_object_set_new(nfo, "sd_hz", amfi_json_num(nf.sd_hz));
    json_object_set_new(nfo, "compensated_n", json_integer((json_int_t)nf.n_comp));
    json_object_set_new(nfo, "compensated_mean_hz", amfi_json_num(nf.comp_mean_hz));
    json_object_set_new(nfo, "compensated_sd_hz", amfi_json_num(nf.comp_sd_hz));
    json_object_set_new(o, "natural_frequency", nfo);
    json_object_set_new(root, "summary", o);
    return 0;
}

int export_trend(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen)
{
    int64_t total = 0;
    if (amfi_store_count(s, AMFI_STORE_INDICATORS, &total, err, errlen))
        return -1;
    int max = total > 0 ? (int)(total < 10000000 ? total : 10000000) : 1, n = 0;
    amfi_indicator_rec *rec = calloc((size_t)max, sizeof *rec);
    if (!rec) {
        snprintf(err, errlen, "out of memory for %d indicators", max);
        return -1;
    }
    if (total > 0 && amfi_store_recent_indicators(s, max, rec, &n, err, errlen)) {
        free(rec);
        return -1;
    }
    char t[32];
    json_t *arr = fmt == FMT_JSON ? json_array() : NULL;
    if (fmt == FMT_CSV)
        fprintf(f, "indicator_id,time_utc,utime,n,mean_kg,std_kg,baseline_mean_kg,"
                   "baseline_std_kg,std_ratio,p_value,state\n");
    for (int k = n - 1; k >= 0; k--) { /* oldest first */
        const amfi_indicator_row *r = &rec[k].row;
        if (fmt == FMT_CSV) {
            fprintf(f, "%lld,%s,%lld,%lld,", (long long)rec[k].id, iso(r->utime, t),
                    (long long)r->utime, (long long)r->n);
            csv_num(f, r->mean_kg, "%.1f"), fputc(',', f);
            csv_num(f, r->std_kg, "%.1f"), fputc(',', f);
            csv_num(f, r->baseline_mean_kg, "%.1f"), fputc(',', f);
            csv_num(f, r->baseline_std_kg, "%.1f"), fputc(',', f);
            csv_num(f, r->std_ratio, "%.6f"), fputc(',', f);
            csv_num(f, r->p_value, "%.6g"), fputc(',', f);
            csv_str(f, r->state);
            fputc('\n', f);
        } else {
            json_t *o = json_object();
            json_object_set_new(o, "indicator_id", json_integer(rec[k].id));
            json_object_set_new(o, "time_utc", jstr(iso(r->utime, t)));
            json_object_set_new(o, "utime", json_integer(r->utime));
            json_object_set_new(o, "n", json_integer(r->n));
            json_object_set_new(o, "mean_kg", amfi_json_num(r->mean_kg));
            json_object_set_new(o, "std_kg", amfi_json_num(r->std_kg));
            json_object_set_new(o, "baseline_mean_kg", amfi_json_num(r->baseline_mean_kg));
            json_object_set_new(o, "baseline_std_kg", amfi_json_num(r->baseline_std_kg));
            json_object_set_new(o, "std_ratio", amfi_json_num(r->std_ratio));
            json_object_set_new(o, "p_value", amfi_json_num(r->p_value));
            json_object_set_new(o, "state", jstr(r->state));
            json_array_append_new(arr, o);
        }
    }
    free(rec);
    if (arr)
        json_object_set_new(root, "trend", arr);
    return 0;
}

int export_alerts(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen)
{
    int64_t total = 0;
    if (amfi_store_count(s, AMFI_STORE_ALERTS, &total, err, errlen))
        return -1;
    int max = total > 0 ? (int)(total < 1000000 ? total : 1000000) : 1, n = 0;
    amfi_alert_rec *rec = calloc((size_t)max, sizeof *rec);
    if (!rec) {
        snprintf(err, errlen, "out of memory for %d alerts", max);
        return -1;
    }
    if (total > 0 && amfi_store_recent_alerts(s, max, rec, &n, err, errlen)) {
        free(rec);
        return -1;
    }
    char t[32];
    json_t *arr = fmt == FMT_JSON ? json_array() : NULL;
    if (fmt == FMT_CSV)
        fprintf(f, "alert_id,time_utc,utime,level,kind,event,indicator_id,message\n");
    for (int k = n - 1; k >= 0; k--) {
        const amfi_alert_rec *a = &rec[k];
        if (fmt == FMT_CSV) {
            fprintf(f, "%lld,%s,%lld,", (long long)a->id, iso(a->utime, t),
                    (long long)a->utime);
            csv_str(f, a->level);
            fputc(',', f);
            csv_str(f, a->kind);
            fprintf(f, ",%s,", a->raised ? "raised" : "cleared");
            if (a->indicator_id > 0)
                fprintf(f, "%lld", (long long)a->indicator_id);
            fputc(',', f);
            csv_str(f, a->message);
            fputc('\n', f);
        } else {
            json_t *o = json_object();
            json_object_set_new(o, "alert_id", json_integer(a->id));
            json_object_set_new(o, "time_utc", jstr(iso(a->utime, t)));
            json_object_set_new(o, "utime", json_integer(a->utime));
            json_object_set_new(o, "level", jstr(a->level));
            json_object_set_new(o, "kind", jstr(a->kind));
            json_object_set_new(o, "raised", json_boolean(a->raised));
            json_object_set_new(o, "indicator_id",
                                a->indicator_id > 0 ? json_integer(a->indicator_id) : json_null());
            json_object_set_new(o, "message", jstr(a->message));
            json_array_append_new(arr, o);
        }
    }
    free(rec);
    if (arr)
        json_object_set_new(root, "alerts", arr);
    return 0;
}

int export_errors(amfi_store *s, int fmt, FILE *f, json_t *root, char *err, size_t errlen)
{
    int64_t n_truth = 0, not_ok = 0;
    double *e = NULL;
    size_t ne = 0;
    if (amfi_store_count(s, AMFI_STORE_TRUTH, &n_truth, err, errlen) ||
        (n_truth > 0 && amfi_store_gvw_errors(s, &e, &ne, &not_ok, err, errlen)))
        return -1;
    double mean, std;
    report_mean_std(e, ne, &mean, &std);
    for (size_t k = 0; k < ne; k++)
        e[k] = fabs(e[k]);
    report_sort(e, ne);
    double med = report_percentile(e, ne, 50), p95 = report_percentile(e, ne, 95);
    double mx = ne ? e[ne - 1] : NAN;
    free(e);
    if (fmt == FMT_CSV) {
        fprintf(f, "item,value\ntruth_rows,%lld\nok_matched,%zu\nother_matched,%lld\n",
                (long long)n_truth, ne, (long long)not_ok);
        fprintf(f, "gvw_error_mean_pct,"), csv_num(f, mean, "%.4f"), fputc('\n', f);
        fprintf(f, "gvw_error_std_pct,"), csv_num(f, std, "%.4f"), fputc('\n', f);
        fprintf(f, "abs_gvw_error_median_pct,"), csv_num(f, med, "%.4f"), fputc('\n', f);
        fprintf(f, "abs_gvw_error_p95_pct,"), csv_num(f, p95, "%.4f"), fputc('\n', f);
        fprintf(f, "abs_gvw_error_max_pct,"), csv_num(f, mx, "%.4f"), fputc('\n', f);
        return 0;
    }
    json_t *o = json_object();
    json_object_set_new(o, "truth_rows", json_integer(n_truth));
    json_object_set_new(o, "ok_matched", json_integer((json_int_t)ne));
    json_object_set_new(o, "other_matched", json_integer(not_ok));
    json_object_set_new(o, "gvw_error_mean_pct", amfi_json_num(mean));
    json_object_set_new(o, "gvw_error_std_pct", amfi_json_num(std));
    json_object_set_new(o, "abs_gvw_error_median_pct", amfi_json_num(med));
    json_object_set_new(o, "abs_gvw_error_p95_pct", amfi_json_num(p95));
    json_object_set_new(o, "abs_gvw_error_max_pct", amfi_json_num(mx));
    json_object_set_new(root, "errors", o);
    return 0;
}

/* ---- passages ------------------------------------------------------------------ */

/* The passages of o's range and lane and of `status` (NULL: any), read
 * through the store's filtered iterator: the filter is SQL. */
static int each(amfi_store *s, const export_opts *o, const char *status,
                amfi_store_passage_fn fn, void *ctx, char *err, size_t errlen)
{
    amfi_passage_filter f = {.from = o->from, .to = o->to, .status = status,
                             .lane_given = o->lane_given, .lane = o->lane};
    return amfi_store_each_passage_where(s, &f, fn, ctx, err, errlen);
}

typedef struct list_ctx {
    const export_opts *o;
    int fmt;
    FILE *f;
    int64_t n;
    int werr; /* 1: the output refused a write */
} list_ctx;

static int list_one(void *vctx, int64_t id, const amfi_passage_row *r)
{
    list_ctx *c = vctx;
    char t[32];
    FILE *f = c->f;
    c->n++;
    if (c->fmt == FMT_TABLE) {
        char loads[12 * 10 + 1] = "";
        size_t used = 0;
        for (int a = 0; a < r->n_axles && used < sizeof loads; a++) {
            int w = isnan(r->axle_kg[a])
                        ? snprintf(loads + used, sizeof loads - used, "%s-", a ? "/" : "")
                        : snprintf(loads + used, sizeof loads - used, "%s%.0f", a ? "/" : "",
                                   r->axle_kg[a]);
            used += w > 0 ? (size_t)w : 0;
        }
        char sp[16] = "-", gvw[16] = "-";
        if (!isnan(r->speed_mps))
            snprintf(sp, sizeof sp, "%.2f", r->speed_mps);
        if (!isnan(r->gvw_kg))
            snprintf(gvw, sizeof gvw, "%.0f", r->gvw_kg);
        fprintf(f, "%-20s  %8lld  %10lld  %4d  %6s  %2d  %8s  %-28s  %-8s  %.200s\n",
                iso(r->utime, t), (long long)id, (long long)r->vehicle_id, r->lane, sp,
                r->n_axles, gvw, loads[0] ? loads : "-", r->status, r->reason);
    } else if (c->fmt == FMT_CSV) {
        fprintf(f, "%s,%lld,%lld,%lld,%d,", iso(r->utime, t), (long long)r->utime,
                (long long)id, (long long)r->vehicle_id, r->lane);
        csv_num(f, r->speed_mps, "%.3f");
        fprintf(f, ",%d,", r->n_axles);
        csv_num(f, r->gvw_kg, "%.1f");
        for (int a = 0; a < AMFI_MAX_AXLES; a++) {
            fputc(',', f);
            if (a < r->n_axles)
                csv_num(f, r->axle_kg[a], "%.1f");
        }
        for (int a = 0; a + 1 < AMFI_MAX_AXLES; a++) {
            fputc(',', f);
            if (a + 1 < r->n_axles)
                csv_num(f, r->spacing_m[a], "%.3f");
        }
        fputc(',', f);
        csv_str(f, r->status);
        fputc(',', f);
        csv_str(f, r->reason);
        fputc(',', f);
        csv_num(f, r->speed_given_mps, "%.3f");
        fprintf(f, ",%d,%d,", r->speed_estimated, r->n_vehicles);
        csv_num(f, r->quality, "%.4g");
        fputc('\n', f);
    } else {
        json_t *o = json_object(), *ax = json_array(), *spc = json_array();
        json_object_set_new(o, "time_utc", jstr(iso(r->utime, t)));
        json_object_set_new(o, "utime", json_integer(r->utime));
        json_object_set_new(o, "passage_id", json_integer(id));
        json_object_set_new(o, "vehicle_id", json_integer(r->vehicle_id));
        json_object_set_new(o, "lane", json_integer(r->lane));
        json_object_set_new(o, "speed_mps", amfi_json_num(r->speed_mps));
        json_object_set_new(o, "n_axles", json_integer(r->n_axles));
        json_object_set_new(o, "gvw_kg", amfi_json_num(r->gvw_kg));
        for (int a = 0; a < r->n_axles; a++)
            json_array_append_new(ax, amfi_json_num(r->axle_kg[a]));
        for (int a = 0; a + 1 < r->n_axles; a++)
            json_array_append_new(spc, amfi_json_num(r->spacing_m[a]));
        json_object_set_new(o, "axle_kg", ax);
        json_object_set_new(o, "spacing_m", spc);
        json_object_set_new(o, "status", jstr(r->status));
        json_object_set_new(o, "reason", jstr(r->reason));
        json_object_set_new(o, "speed_given_mps", amfi_json_num(r->speed_given_mps));
        json_object_set_new(o, "speed_estimated", json_boolean(r->speed_estimated));
        json_object_set_new(o, "n_vehicles", json_integer(r->n_vehicles));
        json_object_set_new(o, "quality", amfi_json_num(r->quality));
        /* streamed: one element at a time, never the whole array */
        if ((c->n > 1 && fputc(',', f) == EOF) ||
            json_dumpf(o, f, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10))) {
            json_decref(o);
            c->werr = 1;
            return 1;
        }
        json_decref(o);
    }
    return 0;
}

int export_passages(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root,
                    char *err, size_t errlen)
{
    list_ctx c = {o, fmt, f, 0, 0};
    (void)root; /* JSON: the array is written to f as it is read */
    if (fmt == FMT_TABLE) {
        fprintf(f, "== passages\n%-20s  %8s  %10s  %4s  %6s  %2s  %8s  %-28s  %-8s  %s\n",
                "time (UTC)", "id", "vehicle", "lane", "m/s", "ax", "GVW kg",
                "axle loads kg", "status", "reason");
    } else if (fmt == FMT_CSV) {
        fprintf(f, "time_utc,utime,passage_id,vehicle_id,lane,speed_mps,n_axles,gvw_kg");
        for (int a = 1; a <= AMFI_MAX_AXLES; a++)
            fprintf(f, ",axle%d_kg", a);
        for (int a = 1; a < AMFI_MAX_AXLES; a++)
            fprintf(f, ",spacing%d_m", a);
        fprintf(f, ",status,reason,speed_given_mps,speed_estimated,n_vehicles,quality\n");
    } else {
        fputc('[', f);
    }
    int rc = each(s, o, o->status, list_one, &c, err, errlen);
    if (c.werr)
        snprintf(err, errlen, "passages: cannot write the output");
    if (fmt == FMT_TABLE && rc == 0)
        fprintf(f, "(%lld passages)\n", (long long)c.n);
    if (fmt == FMT_JSON && rc == 0)
        fputc(']', f);
    return rc || ferror(f) ? -1 : 0;
}

/* ---- histogram per lane ---------------------------------------------------------- */

typedef struct hist_ctx {
    const export_opts *o;
    int lanes[MAX_LANES], n_lanes;
    int64_t *count; /* [bin * MAX_LANES + lane index] */
    int n_bins;     /* bins in use: 0 .. n_bins − 1 */
    int64_t other_lanes;
    int oom;
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
    long b = (long)floor(r->gvw_kg / h->o->bin_kg);
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

int export_histogram(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root,
                     char *err, size_t errlen)
{
    hist_ctx h;
    memset(&h, 0, sizeof h);
    h.o = o;
    int rc = each(s, o, "ok", hist_one, &h, err, errlen);
    if (h.oom) {
        snprintf(err, errlen, "out of memory for the histogram");
        rc = -1;
    }
    if (rc) {
        free(h.count);
        return -1;
    }
    /* lanes in increasing order: a permutation of the columns */
    int order[MAX_LANES], sorted[MAX_LANES];
    memcpy(sorted, h.lanes, sizeof(int) * (size_t)h.n_lanes);
    qsort(sorted, (size_t)h.n_lanes, sizeof(int), cmp_int);
    for (int i = 0; i < h.n_lanes; i++)
        for (int j = 0; j < h.n_lanes; j++)
            if (h.lanes[j] == sorted[i])
                order[i] = j;
    int64_t lane_total[MAX_LANES] = {0};
    json_t *bins = fmt == FMT_JSON ? json_array() : NULL;
    if (fmt == FMT_TABLE) {
        fprintf(f, "== GVW histogram of ok passages, %.0f kg bins\n%-17s", o->bin_kg, "GVW kg");
        for (int i = 0; i < h.n_lanes; i++)
            fprintf(f, "  lane %-4d", sorted[i]);
        fprintf(f, "  %9s\n", "all");
    } else if (fmt == FMT_CSV) {
        fprintf(f, "gvw_from_kg,gvw_to_kg");
        for (int i = 0; i < h.n_lanes; i++)
            fprintf(f, ",lane_%d", sorted[i]);
        fprintf(f, ",all\n");
    }
    for (int b = 0; b < h.n_bins; b++) {
        int64_t all = 0;
        for (int i = 0; i < h.n_lanes; i++)
            all += h.count[(size_t)b * MAX_LANES + (size_t)order[i]];
        if (all == 0 && fmt == FMT_TABLE)
            continue;
        double lo = b * o->bin_kg, hi = (b + 1) * o->bin_kg;
        if (fmt == FMT_TABLE)
            fprintf(f, "%7.0f .. %7.0f", lo, hi);
        else if (fmt == FMT_CSV)
            fprintf(f, "%.0f,%.0f", lo, hi);
        json_t *cnt = bins ? json_array() : NULL;
        for (int i = 0; i < h.n_lanes; i++) {
            int64_t n = h.count[(size_t)b * MAX_LANES + (size_t)order[i]];
            lane_total[i] += n;
            if (fmt == FMT_TABLE)
                fprintf(f, "  %9lld", (long long)n);
            else if (fmt == FMT_CSV)
                fprintf(f, ",%lld", (long long)n);
            else
                json_array_append_new(cnt, json_integer(n));
        }
        if (fmt == FMT_TABLE)
            fprintf(f, "  %9lld\n", (long long)all);
        else if (fmt == FMT_CSV)
            fprintf(f, ",%lld\n", (long long)all);
        else {
            json_t *bo = json_object();
            json_object_set_new(bo, "gvw_from_kg", json_real(lo));
            json_object_set_new(bo, "gvw_to_kg", json_real(hi));
            json_object_set_new(bo, "counts", cnt);
            json_object_set_new(bo, "all", json_integer(all));
            json_array_append_new(bins, bo);
        }
    }
    if (fmt == FMT_TABLE) {
        fprintf(f, "%-17s", "total");
        int64_t all = 0;
        for (int i = 0; i < h.n_lanes; i++)
            fprintf(f, "  %9lld", (long long)lane_total[i]), all += lane_total[i];
        fprintf(f, "  %9lld\n", (long long)all);
        if (h.other_lanes)
            fprintf(f, "(%lld passages of lanes beyond the first %d not shown)\n",
                    (long long)h.other_lanes, MAX_LANES);
    } else if (fmt == FMT_JSON) {
        json_t *o2 = json_object(), *ln = json_array();
        for (int i = 0; i < h.n_lanes; i++)
            json_array_append_new(ln, json_integer(sorted[i]));
        json_object_set_new(o2, "bin_kg", json_real(o->bin_kg));
        json_object_set_new(o2, "lanes", ln);
        json_object_set_new(o2, "bins", bins);
        json_object_set_new(root, "histogram", o2);
    }
    free(h.count);
    return 0;
}

/* ---- overloads -------------------------------------------------------------------- */

typedef struct over_ctx {
    const export_opts *o;
    int fmt;
    FILE *f;
    json_t *arr;
    int64_t checked, over_gvw, over_axle, over_any;
} over_ctx;

static int over_one(void *vctx, int64_t id, const amfi_passage_row *r)
{
    over_ctx *c = vctx;
    c->checked++;
    double maxax = -INFINITY;
    int maxi = 0;
    for (int a = 0; a < r->n_axles; a++)
        if (r->axle_kg[a] > maxax)
            maxax = r->axle_kg[a], maxi = a + 1;
    int og = r->gvw_kg > c->o->gvw_limit_kg, oa = maxax > c->o->axle_limit_kg;
    c->over_gvw += og;
    c->over_axle += oa;
    if (!og && !oa)
        return 0;
    c->over_any++;
    char t[32], what[16];
    snprintf(what, sizeof what, "%s%s%s", og ? "gvw" : "", og && oa ? "+" : "", oa ? "axle" : "");
    if (c->fmt == FMT_TABLE)
        fprintf(c->f, "%-20s  %8lld  %10lld  %4d  %8.0f  %+6.1f %%  %8.0f (axle %d)  %+6.1f %%  %s\n",
                iso(r->utime, t), (long long)id, (long long)r->vehicle_id, r->lane, r->gvw_kg,
                100.0 * (r->gvw_kg / c->o->gvw_limit_kg - 1), maxax, maxi,
                100.0 * (maxax / c->o->axle_limit_kg - 1), what);
    else if (c->fmt == FMT_CSV)
        fprintf(c->f, "%s,%lld,%lld,%lld,%d,%.1f,%.3f,%.1f,%d,%.3f,%s\n", iso(r->utime, t),
                (long long)r->utime, (long long)id, (long long)r->vehicle_id, r->lane, r->gvw_kg,
                100.0 * (r->gvw_kg / c->o->gvw_limit_kg - 1), maxax, maxi,
                100.0 * (maxax / c->o->axle_limit_kg - 1), what);
    else {
        json_t *o = json_object();
        json_object_set_new(o, "time_utc", jstr(iso(r->utime, t)));
        json_object_set_new(o, "utime", json_integer(r->utime));
        json_object_set_new(o, "passage_id", json_integer(id));
        json_object_set_new(o, "vehicle_id", json_integer(r->vehicle_id));
        json_object_set_new(o, "lane", json_integer(r->lane));
        json_object_set_new(o, "gvw_kg", amfi_json_num(r->gvw_kg));
        json_object_set_new(o, "max_axle_kg", amfi_json_num(maxax));
        json_object_set_new(o, "max_axle", json_integer(maxi));
        json_object_set_new(o, "over", jstr(what));
        json_array_append_new(c->arr, o);
    }
    return 0;
}

int export_overloads(amfi_store *s, const export_opts *o, int fmt, FILE *f, json_t *root,
                     char *err, size_t errlen)
{
    over_ctx c = {o, fmt, f, NULL, 0, 0, 0, 0};
    if (fmt == FMT_TABLE)
        fprintf(f, "== overloads (ok passages; limits: GVW %.0f kg, axle %.0f kg)\n"
                   "%-20s  %8s  %10s  %4s  %8s  %8s  %-19s  %8s  %s\n",
                o->gvw_limit_kg, o->axle_limit_kg, "time (UTC)", "id", "vehicle", "lane",
                "GVW kg", "over", "heaviest axle kg", "over", "limit");
    else if (fmt == FMT_CSV)
        fprintf(f, "time_utc,utime,passage_id,vehicle_id,lane,gvw_kg,gvw_over_pct,"
                   "max_axle_kg,max_axle,axle_over_pct,over\n");
    else
        c.arr = json_array();
    int rc = each(s, o, "ok", over_one, &c, err, errlen);
    if (rc) {
        json_decref(c.arr);
        return -1;
    }
    if (fmt == FMT_TABLE)
        fprintf(f, "checked %lld ok passages: %lld over the GVW limit, %lld with an axle over "
                   "the axle limit, %lld overloaded in all (%.2f %%)\n",
                (long long)c.checked, (long long)c.over_gvw, (long long)c.over_axle,
                (long long)c.over_any,
                c.checked ? 100.0 * (double)c.over_any / (double)c.checked : 0.0);
    else if (fmt == FMT_JSON) {
        json_t *ob = json_object();
        json_object_set_new(ob, "gvw_limit_kg", json_real(o->gvw_limit_kg));
        json_object_set_new(ob, "axle_limit_kg", json_real(o->axle_limit_kg));
        json_object_set_new(ob, "checked", json_integer(c.checked));
        json_object_set_new(ob, "over_gvw", json_integer(c.over_gvw));
        json_object_set_new(ob, "over_axle", json_integer(c.over_axle));
        json_object_set_new(ob, "overloaded", json_integer(c.over_any));
        json_object_set_new(ob, "passages", c.arr);
        json_object_set_new(root, "overloads", ob);
    }
    return 0;
}
