/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * report_summary.c: amfi-report's summary and errors against the truth
 * (report_summary.h).
 */
#include "report_summary.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "report_cols.h"
#include "report_natfreq.h"
#include "report_residual.h"
#include "report_scale.h"

/* amfid's intake counters of its newest run (meta intake.*), if any. */
typedef struct report_intake {
    int found;
    long long run, received, refused, dropped, missing, lost;
    char as_of[40];
} report_intake;

static int read_intake(amfi_store *s, report_intake *in, char *err, size_t errlen)
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

/* ---- the summary as a table -------------------------------------------------- */

static int print_baseline(report_ctx *c)
{
    amfi_baseline b;
    int found = 0;
    char err[256], t[32];
    if (amfi_store_get_baseline(c->s, &b, &found, err, sizeof err) != 0)
        return report_fail(c, "%s", err);
    if (!found) {
        fprintf(c->out, "baseline     none yet (amfid sets it from the first ok "
                        "passages, or --set-baseline*)\n");
        return 0;
    }
    char m1[32], m2[32];
    const char *u = report_mass_unit(c->units);
    fprintf(c->out, "baseline     mean %s %s, STD %s %s, n %d, %s, from %s UTC%s%s%s\n",
            report_mass(c->units, b.mean_kg, m1), u, report_mass(c->units, b.std_kg, m2), u, b.n,
            b.source, report_utc(b.utime_set, t),
            b.note[0] ? " \"" : "", b.note, b.note[0] ? "\"" : "");
    return 0;
}

int summary_table(report_ctx *c)
{
    amfi_passage_summary sum;
    double *g = NULL;
    size_t ng = 0;
    char a[32], b[32], d[32];
    FILE *f = c->out;
    amfi_store *s = c->s;
    if (amfi_store_passage_summary(s, &sum, c->err, sizeof c->err) != 0)
        return -1;
    fprintf(f, "== passages\n");
    if (sum.total == 0)
        fprintf(f, "time span    (no passages yet)\n");
    else
        fprintf(f, "time span    %s .. %s UTC (%s)\n", report_utc(sum.utime_first, a),
                report_utc(sum.utime_last, b),
                report_duration((double)(sum.utime_last - sum.utime_first) / 1e6, d));
    fprintf(f, "passages     %lld\n", (long long)sum.total);
    for (int k = 0; k < AMFI_STORE_N_STATUS; k++)
        fprintf(f, "  %-10s %8lld  %5.1f %%\n", amfi_store_status_name(k),
                (long long)sum.by_status[k],
                sum.total ? 100.0 * (double)sum.by_status[k] / (double)sum.total : 0.0);
    if (amfi_store_all_ok_gvw(s, &g, &ng, c->err, sizeof c->err) != 0)
        return -1;
    double mean = 0, std = 0;
    const size_t n_ok = ng;
    if (ng == 0) {
        fprintf(f, "GVW, ok      (no ok passages)\n");
    } else {
        report_mean_std(g, ng, &mean, &std);
        report_sort(g, ng);
        char m[4][32];
        const char *u = report_mass_unit(c->units);
        fprintf(f, "GVW, ok      n %zu, mean %s %s, STD %s %s, min %s, median %s, max %s %s\n",
                ng, report_mass(c->units, mean, m[0]), u, report_mass(c->units, std, a), u,
                report_mass(c->units, g[0], m[1]),
                report_mass(c->units, report_percentile(g, ng, 50), m[2]),
                report_mass(c->units, g[ng - 1], m[3]), u);
    }
    free(g);
    /* what the STD and mean rules were fed (at the calibration temperature
     * with daemon.indicators.temperature: compensated), when it is not the
     * raw GVW itself (no deck temperature, or raw) */
    const double raw_mean = mean, raw_std = std;
    if (amfi_store_all_fed_gvw(s, &g, &ng, c->err, sizeof c->err) != 0)
        return -1;
    if (ng > 0)
        report_mean_std(g, ng, &mean, &std);
    if (ng > 0 && (ng != n_ok || mean != raw_mean || !(std == raw_std || isnan(std)))) {
        report_sort(g, ng);
        char m[4][32];
        const char *u = report_mass_unit(c->units);
        fprintf(f, "GVW, fed     n %zu, mean %s %s, STD %s %s, min %s, median %s, max %s %s "
                   "(the STD and mean rules' input: compensated to the calibration temperature)\n",
                ng, report_mass(c->units, mean, m[0]), u, report_mass(c->units, std, a), u,
                report_mass(c->units, g[0], m[1]),
                report_mass(c->units, report_percentile(g, ng, 50), m[2]),
                report_mass(c->units, g[ng - 1], m[3]), u);
    }
    free(g);
    report_intake in;
    if (read_intake(s, &in, c->err, sizeof c->err) != 0)
        return -1;
    if (in.found)
        fprintf(f, "bus          run %lld (as of %s): %lld messages received, %lld refused, "
                   "%lld kernel drops, %lld samples missing, %lld passages not stored\n",
                in.run, in.as_of, in.received, in.refused, in.dropped, in.missing, in.lost);
    amfi_environment_summary env;
    if (amfi_store_environment_summary(s, &env, c->err, sizeof c->err) != 0)
        return -1;
    if (env.n > 0)
        fprintf(f, "temperature  deck %.1f .. %.1f °C, air %.1f .. %.1f °C, %lld readings, "
                   "%s .. %s UTC\n",
                env.deck_min_c, env.deck_max_c, env.air_min_c, env.air_max_c, (long long)env.n,
                report_utc(env.utime_first, a), report_utc(env.utime_last, b));
    if (report_scale_summary(s, f, c->err, sizeof c->err) != 0)
        return -1;
    char f1line[1024];
    if (natfreq_summary(s, f1line, sizeof f1line, c->err, sizeof c->err) != 0)
        return -1;
    fprintf(f, "%s", f1line);
    if (residual_summary(s, f1line, sizeof f1line, c->err, sizeof c->err) != 0)
        return -1;
    fprintf(f, "%s", f1line);
    return print_baseline(c);
}

/* ---- the summary as items ------------------------------------------------------ */

typedef struct sum_row {
    amfi_passage_summary sum;
    char first[32], last[32]; /* ISO 8601 */
    size_t ng;
    double mean, std, min, max;
    amfi_baseline b;
    int found;
    char from[32];
    report_intake in;
    natfreq_stats nf;
    residual_stats rs;
} sum_row;

#define S(w) ((const sum_row *)(w))
static void s_first(const void *w, report_val *v) { v->s = S(w)->first, v->null = !S(w)->sum.total; }
static void s_last(const void *w, report_val *v) { v->s = S(w)->last, v->null = !S(w)->sum.total; }
static void s_total(const void *w, report_val *v) { v->i = S(w)->sum.total; }
static const char *status_key(int k) { return amfi_store_status_name(k); }
static void s_by_status(const void *w, report_val *v) { v->iv = S(w)->sum.by_status; }
static void s_ng(const void *w, report_val *v) { v->i = (int64_t)S(w)->ng; }
static void s_mean(const void *w, report_val *v) { v->x = S(w)->mean; }
static void s_std(const void *w, report_val *v) { v->x = S(w)->std; }
static void s_min(const void *w, report_val *v) { v->x = S(w)->min; }
static void s_max(const void *w, report_val *v) { v->x = S(w)->max; }
static int s_has_baseline(const void *w) { return S(w)->found; }
static void s_b_mean(const void *w, report_val *v) { v->x = S(w)->found ? S(w)->b.mean_kg : NAN; }
static void s_b_std(const void *w, report_val *v) { v->x = S(w)->found ? S(w)->b.std_kg : NAN; }
static void s_b_n(const void *w, report_val *v) { v->i = S(w)->found ? S(w)->b.n : 0; }
static void s_b_source(const void *w, report_val *v) { v->s = S(w)->b.source; }
static void s_b_from(const void *w, report_val *v) { v->s = S(w)->from; }
static int s_has_intake(const void *w) { return S(w)->in.found; }
static void s_run(const void *w, report_val *v) { v->i = S(w)->in.run; }
static void s_as_of(const void *w, report_val *v) { v->s = S(w)->in.as_of; }
static void s_received(const void *w, report_val *v) { v->i = S(w)->in.received; }
static void s_refused(const void *w, report_val *v) { v->i = S(w)->in.refused; }
static void s_dropped(const void *w, report_val *v) { v->i = S(w)->in.dropped; }
static void s_missing(const void *w, report_val *v) { v->i = S(w)->in.missing; }
static void s_lost(const void *w, report_val *v) { v->i = S(w)->in.lost; }
static void s_f1_n(const void *w, report_val *v) { v->i = (int64_t)S(w)->nf.n; }
static void s_f1_mean(const void *w, report_val *v) { v->x = S(w)->nf.mean_hz; }
static void s_f1_sd(const void *w, report_val *v) { v->x = S(w)->nf.sd_hz; }
static void s_f1c_n(const void *w, report_val *v) { v->i = (int64_t)S(w)->nf.n_comp; }
static void s_f1c_mean(const void *w, report_val *v) { v->x = S(w)->nf.comp_mean_hz; }
static void s_f1c_sd(const void *w, report_val *v) { v->x = S(w)->nf.comp_sd_hz; }
static void s_res_n(const void *w, report_val *v) { v->i = (int64_t)S(w)->rs.n; }
static void s_res_median(const void *w, report_val *v) { v->x = S(w)->rs.median; }
static void s_res_p95(const void *w, report_val *v) { v->x = S(w)->rs.p95; }
static void s_res_first(const void *w, report_val *v) { v->x = S(w)->rs.first_median; }
static void s_res_last(const void *w, report_val *v) { v->x = S(w)->rs.last_median; }
static void s_res_growth(const void *w, report_val *v) { v->x = S(w)->rs.growth; }
static void s_res_quality(const void *w, report_val *v) { v->x = S(w)->rs.quality_median; }
#undef S

/* CSV items and JSON members in one list: name (CSV item), type, unit,
 * format, where, accessor, JSON key (if another), JSON group, present. */
static const report_col summary_items[] = {
    /* the JSON object starts with the count, the CSV with the time span */
    REPORT_COL("passages", COL_INT, "", NULL, COL_JSON, s_total),
    REPORT_COL("time_first", COL_WORD, "", NULL, COL_BOTH, s_first),
    REPORT_COL("time_last", COL_WORD, "", NULL, COL_BOTH, s_last),
    REPORT_COL("passages", COL_INT, "", NULL, COL_CSV, s_total),
    REPORT_COL("passages", COL_COUNTS, "", NULL, COL_BOTH, s_by_status,
               .json = "by_status", .width = AMFI_STORE_N_STATUS, .key = status_key),
    REPORT_COL("gvw_ok_n", COL_INT, "", NULL, COL_BOTH, s_ng, .json = "n", .group = "gvw_ok"),
    REPORT_COL("gvw_ok_mean_kg", COL_NUM, "kg", "%.1f", COL_BOTH, s_mean,
               .json = "mean_kg", .group = "gvw_ok"),
    REPORT_COL("gvw_ok_std_kg", COL_NUM, "kg", "%.1f", COL_BOTH, s_std,
               .json = "std_kg", .group = "gvw_ok"),
    REPORT_COL("gvw_ok_min_kg", COL_NUM, "kg", "%.1f", COL_BOTH, s_min,
               .json = "min_kg", .group = "gvw_ok"),
    REPORT_COL("gvw_ok_max_kg", COL_NUM, "kg", "%.1f", COL_BOTH, s_max,
               .json = "max_kg", .group = "gvw_ok"),
    /* no baseline: JSON null, CSV empty figures and n 0; no intake
     * counters: JSON null, CSV without the lines */
    REPORT_COL("baseline_mean_kg", COL_NUM, "kg", "%.1f", COL_BOTH | COL_KEEP, s_b_mean,
               .json = "mean_kg", .group = "baseline", .present = s_has_baseline),
    REPORT_COL("baseline_std_kg", COL_NUM, "kg", "%.1f", COL_BOTH, s_b_std,
               .json = "std_kg", .group = "baseline"),
    REPORT_COL("baseline_n", COL_INT, "", NULL, COL_BOTH, s_b_n, .json = "n", .group = "baseline"),
    REPORT_COL("baseline_source", COL_TEXT, "", NULL, COL_JSON, s_b_source,
               .json = "source", .group = "baseline"),
    REPORT_COL("baseline_from", COL_WORD, "", NULL, COL_JSON, s_b_from,
               .json = "from", .group = "baseline"),
    REPORT_COL("intake_run", COL_INT, "", NULL, COL_BOTH, s_run,
               .json = "run", .group = "intake", .present = s_has_intake),
    REPORT_COL("intake_as_of", COL_TEXT, "", NULL, COL_BOTH, s_as_of,
               .json = "as_of", .group = "intake", .present = s_has_intake),
    REPORT_COL("intake_messages_received", COL_INT, "", NULL, COL_BOTH, s_received,
               .json = "messages_received", .group = "intake", .present = s_has_intake),
    REPORT_COL("intake_messages_refused", COL_INT, "", NULL, COL_BOTH, s_refused,
               .json = "messages_refused", .group = "intake", .present = s_has_intake),
    REPORT_COL("intake_datagrams_dropped", COL_INT, "", NULL, COL_BOTH, s_dropped,
               .json = "datagrams_dropped", .group = "intake", .present = s_has_intake),
    REPORT_COL("intake_samples_missing", COL_INT, "", NULL, COL_BOTH, s_missing,
               .json = "samples_missing", .group = "intake", .present = s_has_intake),
    REPORT_COL("intake_passages_lost", COL_INT, "", NULL, COL_BOTH, s_lost,
               .json = "passages_lost", .group = "intake", .present = s_has_intake),
    REPORT_COL("f1_n", COL_INT, "", NULL, COL_BOTH, s_f1_n,
               .json = "n", .group = "natural_frequency"),
    REPORT_COL("f1_mean_hz", COL_NUM, "Hz", "%.6f", COL_BOTH, s_f1_mean,
               .json = "mean_hz", .group = "natural_frequency"),
    REPORT_COL("f1_sd_hz", COL_NUM, "Hz", "%.6f", COL_BOTH, s_f1_sd,
               .json = "sd_hz", .group = "natural_frequency"),
    REPORT_COL("f1_comp_n", COL_INT, "", NULL, COL_BOTH, s_f1c_n,
               .json = "compensated_n", .group = "natural_frequency"),
    REPORT_COL("f1_comp_mean_hz", COL_NUM, "Hz", "%.6f", COL_BOTH, s_f1c_mean,
               .json = "compensated_mean_hz", .group = "natural_frequency"),
    REPORT_COL("f1_comp_sd_hz", COL_NUM, "Hz", "%.6f", COL_BOTH, s_f1c_sd,
               .json = "compensated_sd_hz", .group = "natural_frequency"),
    /* the solver's residual of the ok passages (report_residual.h) */
    REPORT_COL("residual_n", COL_INT, "", NULL, COL_BOTH, s_res_n, .json = "n",
               .group = "residual"),
    REPORT_COL("residual_median_mps2", COL_NUM, "m/s2", "%.6g", COL_BOTH, s_res_median,
               .json = "median_mps2", .group = "residual"),
    REPORT_COL("residual_p95_mps2", COL_NUM, "m/s2", "%.6g", COL_BOTH, s_res_p95,
               .json = "p95_mps2", .group = "residual"),
    REPORT_COL("residual_oldest_median_mps2", COL_NUM, "m/s2", "%.6g", COL_BOTH, s_res_first,
               .json = "oldest_median_mps2", .group = "residual"),
    REPORT_COL("residual_newest_median_mps2", COL_NUM, "m/s2", "%.6g", COL_BOTH, s_res_last,
               .json = "newest_median_mps2", .group = "residual"),
    REPORT_COL("residual_growth", COL_NUM, "", "%.6g", COL_BOTH, s_res_growth,
               .json = "newest_over_oldest", .group = "residual"),
    REPORT_COL("quality_median", COL_NUM, "", "%.6g", COL_BOTH, s_res_quality,
               .json = "quality_median", .group = "residual"),
};

int summary_export(report_ctx *c)
{
    sum_row r;
    double *g = NULL;
    char *err = c->err;
    const size_t errlen = sizeof c->err;
    memset(&r, 0, sizeof r);
    if (amfi_store_passage_summary(c->s, &r.sum, err, errlen) ||
        amfi_store_all_ok_gvw(c->s, &g, &r.ng, err, errlen) ||
        amfi_store_get_baseline(c->s, &r.b, &r.found, err, errlen) ||
        read_intake(c->s, &r.in, err, errlen) || natfreq_read_stats(c->s, &r.nf, err, errlen) ||
        residual_read_stats(c->s, &r.rs, err, errlen)) {
        free(g);
        return -1;
    }
    report_mean_std(g, r.ng, &r.mean, &r.std);
    report_sort(g, r.ng);
    r.min = r.ng ? g[0] : NAN;
    r.max = r.ng ? g[r.ng - 1] : NAN;
    free(g);
    report_iso(r.sum.utime_first, r.first);
    report_iso(r.sum.utime_last, r.last);
    report_iso(r.b.utime_set, r.from);
    if (c->format == FMT_CSV)
        report_cols_csv_items(c->out, summary_items, REPORT_NCOLS(summary_items), &r);
    else
        json_object_set_new(c->root, "summary",
                            report_cols_json_items(summary_items, REPORT_NCOLS(summary_items), &r));
    return 0;
}

/* ---- errors against the truth ------------------------------------------------- */

int errors_table(report_ctx *c)
{
    int64_t n_truth = 0, not_ok = 0;
    double *e = NULL;
    size_t ne = 0;
    char b[32];
    FILE *f = c->out;
    if (amfi_store_count(c->s, AMFI_STORE_TRUTH, &n_truth, c->err, sizeof c->err) != 0)
        return -1;
    fprintf(f, "== errors against the truth\n");
    if (n_truth == 0) {
        fprintf(f, "(no truth rows: the truth is recorded in simulations only)\n");
        return 0;
    }
    if (amfi_store_gvw_errors(c->s, &e, &ne, &not_ok, c->err, sizeof c->err) != 0)
        return -1;
    fprintf(f, "truth rows   %lld; ok passages matched %zu; other passages "
               "matched %lld\n", (long long)n_truth, ne, (long long)not_ok);
    if (ne > 0) {
        double mean, std;
        report_mean_std(e, ne, &mean, &std);
        fprintf(f, "GVW error    mean %+.2f %%, STD %s %%\n", mean, report_num(std, "%.2f", b));
        for (size_t k = 0; k < ne; k++)
            e[k] = fabs(e[k]);
        report_sort(e, ne);
        fprintf(f, "|GVW error|  median %.2f %%, 90 %% %.2f %%, 95 %% %.2f %%, "
                   "99 %% %.2f %%, max %.2f %%\n",
                report_percentile(e, ne, 50), report_percentile(e, ne, 90),
                report_percentile(e, ne, 95), report_percentile(e, ne, 99), e[ne - 1]);
    }
    free(e);
    return 0;
}

typedef struct err_row {
    int64_t n_truth, not_ok;
    size_t ne;
    double mean, std, med, p95, max;
} err_row;

#define E(w) ((const err_row *)(w))
static void e_truth(const void *w, report_val *v) { v->i = E(w)->n_truth; }
static void e_ok(const void *w, report_val *v) { v->i = (int64_t)E(w)->ne; }
static void e_other(const void *w, report_val *v) { v->i = E(w)->not_ok; }
static void e_mean(const void *w, report_val *v) { v->x = E(w)->mean; }
static void e_std(const void *w, report_val *v) { v->x = E(w)->std; }
static void e_med(const void *w, report_val *v) { v->x = E(w)->med; }
static void e_p95(const void *w, report_val *v) { v->x = E(w)->p95; }
static void e_max(const void *w, report_val *v) { v->x = E(w)->max; }
#undef E

static const report_col error_items[] = {
    REPORT_COL("truth_rows", COL_INT, "", NULL, COL_BOTH, e_truth),
    REPORT_COL("ok_matched", COL_INT, "", NULL, COL_BOTH, e_ok),
    REPORT_COL("other_matched", COL_INT, "", NULL, COL_BOTH, e_other),
    REPORT_COL("gvw_error_mean_pct", COL_NUM, "%", "%.4f", COL_BOTH, e_mean),
    REPORT_COL("gvw_error_std_pct", COL_NUM, "%", "%.4f", COL_BOTH, e_std),
    REPORT_COL("abs_gvw_error_median_pct", COL_NUM, "%", "%.4f", COL_BOTH, e_med),
    REPORT_COL("abs_gvw_error_p95_pct", COL_NUM, "%", "%.4f", COL_BOTH, e_p95),
    REPORT_COL("abs_gvw_error_max_pct", COL_NUM, "%", "%.4f", COL_BOTH, e_max),
};

int errors_export(report_ctx *c)
{
    err_row r;
    double *e = NULL;
    memset(&r, 0, sizeof r);
    if (amfi_store_count(c->s, AMFI_STORE_TRUTH, &r.n_truth, c->err, sizeof c->err) ||
        (r.n_truth > 0
         && amfi_store_gvw_errors(c->s, &e, &r.ne, &r.not_ok, c->err, sizeof c->err)))
        return -1;
    report_mean_std(e, r.ne, &r.mean, &r.std);
    for (size_t k = 0; k < r.ne; k++)
        e[k] = fabs(e[k]);
    report_sort(e, r.ne);
    r.med = report_percentile(e, r.ne, 50);
    r.p95 = report_percentile(e, r.ne, 95);
    r.max = r.ne ? e[r.ne - 1] : NAN;
    free(e);
    if (c->format == FMT_CSV)
        report_cols_csv_items(c->out, error_items, REPORT_NCOLS(error_items), &r);
    else
        json_object_set_new(c->root, "errors",
                            report_cols_json_items(error_items, REPORT_NCOLS(error_items), &r));
    return 0;
}
