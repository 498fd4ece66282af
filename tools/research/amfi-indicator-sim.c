/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-indicator-sim: Monte-Carlo false-alarm rate and detection delay of
 * amfid's damage indicator engine (daemon/indicators.c, used as is) on
 * simulated streams of inferred GVW, to choose and justify its defaults
 * (docs/indicators.md).
 *
 *   amfi-indicator-sim [--sweep] [--seed S] [--fa-runs N] [--fa-vehicles N]
 *                      [--det-runs N] [--damage P1,P2,...] [--horizon N]
 *                      [--meas-sd T] [--meas-sd-10 T]
 *                      [--window W] [--every K] [--baseline-n N]
 *                      [--std-alert-ratio R] [--std-alert-p P]
 *                      [--std-clear-ratio C] [--raise-after N]
 *                      [--clear-after N] [--mean-shift 0|1]
 *                      [--mean-alert-ratio R] [--mean-alert-p P]
 *                      [--mean-clear-ratio C]
 *
 * Stream model (kg). True GVW: the shipped synthetic population's law
 * (tools/research/amfi-population.c): normal(8765, 1960) truncated to [4000, 15000],
 * mean 8800 and STD 1900. Inferred GVW = (true + e) / (1 − d), e ~
 * normal(0, σ_e(d)): damage d scales every inferred weight by 1/(1 − d), as
 * amfi-paper measured (docs/results/paper.md: STD and mean both ×1.11 at
 * 10 %); σ_e(d) = --meas-sd + (--meas-sd-10 − --meas-sd)·d/0.10, default
 * 0.3 t at every d (healthy inferred STD 1.92 t, as measured). With
 * --meas-sd-10 0.83 the STD grows ×1.19 at 10 %, like amfi-paper's batches
 * with the paper's Table 5 inaccuracies (1.91 → 2.27 t).
 *
 * False alarms: --fa-runs runs, each a new engine that collects its own
 * automatic baseline (baseline_n healthy vehicles), then --fa-vehicles
 * healthy vehicles; every raise is a false alarm. Rate per 100 000 vehicles,
 * ± the standard error over runs (alarms cluster in runs whose baseline came
 * out low, so the runs, not the alarms, are the independent units); with no
 * alarm at all, the 95 % upper bound 3/N.
 *
 * Detection: --det-runs runs per damage level, each a new engine with its
 * own automatic baseline, then W + U{0 .. K − 1} healthy vehicles (window
 * full, random phase against the evaluation cadence), then damaged vehicles
 * until the alert (or --horizon vehicles). Delay = damaged vehicles pushed
 * up to and including the one whose push raised the alert. A run in which
 * a false alarm came during the healthy part is redrawn (and counted).
 *
 * Output: markdown on stdout, one table row per parameter set (--sweep: the
 * built-in candidates of docs/indicators.md; otherwise the defaults of
 * amfi_indicator_params_default with the options applied). Progress and the
 * run time on stderr. One gsl_rng_mt19937 seeded with --seed, used in a
 * fixed order, so a seed always gives the same table.
 *
 * Cost: about 0.04 µs per vehicle plus one evaluation (O(W) and two
 * distribution tails) every K vehicles. With the defaults (1e9 healthy
 * vehicles and 2 × 2000 detection runs per parameter set) one set takes
 * about a minute on one core, --sweep (13 sets) about 12 minutes.
 */
#include <errno.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_cli.h"
#include "indicators.h"

#define PROG "amfi-indicator-sim"

/* The population law of tools/research/amfi-population.c (kg). */
#define GVW_MU 8765.0
#define GVW_SD 1960.0
#define GVW_LO 4000.0
#define GVW_HI 15000.0

#define MAX_DAMAGE 8

typedef struct {
    unsigned long seed;
    long fa_runs, fa_vehicles, det_runs, horizon;
    long after;               /* damaged vehicles pushed after the alert (clears) */
    int explicit_baseline;    /* 1: set_baseline(population values, n = 1e6) */
    double pop_mean, pop_std; /* kg, of 1e6 healthy inferred GVWs (explicit baseline) */
    int n_damage;
    double damage[MAX_DAMAGE]; /* fractions, (0, 0.5] */
    double meas_sd, meas_sd_10; /* kg */
} sim_opts;

/* One stream: the law above and a damage level. */
typedef struct {
    gsl_rng *rng;
    double scale;   /* 1 / (1 − d) */
    double meas_sd; /* kg */
} stream;

static double draw(stream *s)
{
    double x;
    do
        x = GVW_MU + gsl_ran_gaussian_ziggurat(s->rng, GVW_SD);
    while (x < GVW_LO || x > GVW_HI);
    x += gsl_ran_gaussian_ziggurat(s->rng, s->meas_sd);
    /* Keep the draw a valid GVW (a 4 t vehicle is 13σ above 0 even at
     * σ_e = 0.3 t; this only guards silly options). */
    if (x < 1.0)
        x = 1.0;
    return x * s->scale;
}

static void set_damage(stream *s, const sim_opts *o, double d)
{
    s->scale = 1.0 / (1.0 - d);
    s->meas_sd = o->meas_sd + (o->meas_sd_10 - o->meas_sd) * d / 0.10;
    if (s->meas_sd < 0.0)
        s->meas_sd = 0.0;
}

static amfi_indicators *make(const amfi_indicator_params *p)
{
    char err[256];
    amfi_indicators *ind;
    if (amfi_indicators_create(p, &ind, err, sizeof err) != 0) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        exit(2);
    }
    return ind;
}

/* Push one vehicle; returns bit 1 if the STD alert was raised, bit 2 if the
 * mean-shift alert was raised, bit 4 if the STD alert was cleared. */
static int push(amfi_indicators *ind, double gvw)
{
    amfi_alert_event ev[2];
    int n = 0;
    int rc = amfi_indicators_push(ind, gvw, NULL, ev, &n);
    if (rc < 0) {
        fprintf(stderr, "%s: push rejected %g kg\n", PROG, gvw);
        exit(1);
    }
    int r = 0;
    for (int i = 0; i < n; i++) {
        int is_std = strcmp(ev[i].kind, "std_increase") == 0;
        if (ev[i].raised)
            r |= is_std ? 1 : 2;
        else if (is_std)
            r |= 4;
    }
    return r;
}

/* The explicit baseline's n: the population's own figures, 1e6 vehicles. */
#define EXPLICIT_N 1000000

static void baseline(amfi_indicators *ind, stream *s, const sim_opts *o)
{
    if (o->explicit_baseline) {
        if (amfi_indicators_set_baseline(ind, o->pop_mean, o->pop_std, EXPLICIT_N) != 0) {
            fprintf(stderr, "%s: set_baseline rejected\n", PROG);
            exit(1);
        }
        return;
    }
    while (!amfi_indicators_has_baseline(ind))
        (void)push(ind, draw(s));
}

typedef struct {
    double rate, se; /* alarms per 1e5 vehicles */
    long alarms, runs_with_alarm;
    double vehicles;
    /* STD only: how long the false alerts stayed raised (vehicles from the
     * raise to the clear); those still raised at the end of their run are
     * counted in not_cleared. */
    double dur_median;
    long not_cleared;
} fa_result;

static int cmp_long(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

static void false_alarms(const amfi_indicator_params *p, const sim_opts *o, gsl_rng *rng,
                         fa_result *std_r, fa_result *mean_r)
{
    stream s = { rng, 1.0, 0.0 };
    set_damage(&s, o, 0.0);
    double sum[2] = { 0, 0 }, sum2[2] = { 0, 0 };
    long alarms[2] = { 0, 0 }, with[2] = { 0, 0 };
    long *dur = NULL, n_dur = 0, cap_dur = 0, not_cleared = 0;
    for (long r = 0; r < o->fa_runs; r++) {
        amfi_indicators *ind = make(p);
        baseline(ind, &s, o);
        long c[2] = { 0, 0 }, raised_at = -1;
        for (long v = 0; v < o->fa_vehicles; v++) {
            int k = push(ind, draw(&s));
            c[0] += (k & 1) != 0;
            c[1] += (k & 2) != 0;
            if (k & 1)
                raised_at = v;
            if ((k & 4) && raised_at >= 0) {
                if (n_dur == cap_dur) {
                    cap_dur = cap_dur ? 2 * cap_dur : 64;
                    long *t = realloc(dur, (size_t)cap_dur * sizeof *dur);
                    if (!t) {
                        fprintf(stderr, "%s: out of memory\n", PROG);
                        exit(1);
                    }
                    dur = t;
                }
                dur[n_dur++] = v - raised_at;
                raised_at = -1;
            }
        }
        not_cleared += raised_at >= 0;
        amfi_indicators_destroy(ind);
        for (int j = 0; j < 2; j++) {
            double rate = 1e5 * (double)c[j] / (double)o->fa_vehicles;
            sum[j] += rate;
            sum2[j] += rate * rate;
            alarms[j] += c[j];
            with[j] += c[j] > 0;
        }
    }
    fa_result *out[2] = { std_r, mean_r };
    for (int j = 0; j < 2; j++) {
        double n = (double)o->fa_runs;
        double m = sum[j] / n;
        double var = n > 1 ? (sum2[j] - n * m * m) / (n - 1) : 0.0;
        out[j]->rate = m;
        out[j]->se = sqrt(var > 0 ? var / n : 0.0);
        out[j]->alarms = alarms[j];
        out[j]->runs_with_alarm = with[j];
        out[j]->vehicles = n * (double)o->fa_vehicles;
    }
    std_r->not_cleared = not_cleared;
    std_r->dur_median = NAN;
    if (n_dur > 0) {
        qsort(dur, (size_t)n_dur, sizeof *dur, cmp_long);
        std_r->dur_median = (double)dur[(n_dur - 1) / 2];
    }
    free(dur);
}

typedef struct {
    long detected, runs, redrawn;
    double mean, se, min, median, p95, p99, max;
    long clears;          /* STD alerts cleared while the damage persisted */
    double after_vehicles; /* damaged vehicles pushed after the STD alerts */
} det_result;

static void summarise(long *delay, long n, long runs, det_result *d)
{
    d->detected = n;
    d->runs = runs;
    d->mean = d->se = d->min = d->median = d->p95 = d->p99 = d->max = NAN;
    if (n == 0)
        return;
    qsort(delay, (size_t)n, sizeof *delay, cmp_long);
    double s = 0, s2 = 0;
    for (long i = 0; i < n; i++) {
        s += (double)delay[i];
        s2 += (double)delay[i] * (double)delay[i];
    }
    d->mean = s / n;
    d->min = (double)delay[0];
    double var = n > 1 ? (s2 - n * d->mean * d->mean) / (n - 1) : 0.0;
    d->se = sqrt(var > 0 ? var / n : 0.0);
    /* Percentiles of the runs (all runs: an undetected run counts as
     * beyond the horizon, so the percentile is NaN when it falls there). */
    long i50 = (long)ceil(0.50 * runs) - 1, i95 = (long)ceil(0.95 * runs) - 1;
    long i99 = (long)ceil(0.99 * runs) - 1;
    d->median = i50 < n ? (double)delay[i50] : NAN;
    d->p95 = i95 < n ? (double)delay[i95] : NAN;
    d->p99 = i99 < n ? (double)delay[i99] : NAN;
    d->max = n == runs ? (double)delay[n - 1] : NAN;
}

static void detection(const amfi_indicator_params *p, const sim_opts *o, gsl_rng *rng,
                      double damage, det_result *std_r, det_result *mean_r)
{
    long *dl[2];
    long nd[2] = { 0, 0 }, redrawn = 0, clears = 0;
    double after_v = 0;
    for (int j = 0; j < 2; j++) {
        dl[j] = malloc((size_t)o->det_runs * sizeof(long));
        if (!dl[j]) {
            fprintf(stderr, "%s: out of memory\n", PROG);
            exit(1);
        }
    }
    stream s = { rng, 1.0, 0.0 };
    for (long r = 0; r < o->det_runs; r++) {
        amfi_indicators *ind;
        for (;;) {
            ind = make(p);
            set_damage(&s, o, 0.0);
            baseline(ind, &s, o);
            long warm = p->window + (long)gsl_rng_uniform_int(rng, (unsigned long)p->every);
            int fa = 0;
            for (long v = 0; v < warm; v++)
                fa |= push(ind, draw(&s));
            if (!fa)
                break;
            redrawn++;
            amfi_indicators_destroy(ind);
        }
        set_damage(&s, o, damage);
        long got[2] = { -1, -1 };
        /* Until the STD alert (or the horizon), then --after vehicles more
         * counting clears (the mean-shift delay is taken on the way). */
        for (long v = 1, end = o->horizon; v <= end; v++) {
            int k = push(ind, draw(&s));
            if ((k & 1) && got[0] < 0) {
                got[0] = v;
                end = v + o->after;
            }
            if ((k & 2) && got[1] < 0)
                got[1] = v;
            if (got[0] > 0) {
                clears += (k & 4) != 0;
                after_v += v > got[0];
            }
        }
        amfi_indicators_destroy(ind);
        for (int j = 0; j < 2; j++)
            if (got[j] > 0)
                dl[j][nd[j]++] = got[j];
    }
    summarise(dl[0], nd[0], o->det_runs, std_r);
    summarise(dl[1], nd[1], o->det_runs, mean_r);
    std_r->redrawn = mean_r->redrawn = redrawn;
    std_r->clears = mean_r->clears = clears;
    std_r->after_vehicles = mean_r->after_vehicles = after_v;
    free(dl[0]);
    free(dl[1]);
}

static void fmt_fa(char *buf, size_t n, const fa_result *f)
{
    if (f->alarms == 0)
        snprintf(buf, n, "0 (< %.2g)", 3e5 / f->vehicles);
    else
        snprintf(buf, n, "%.3g ± %.2g", f->rate, f->se);
}

static void fmt_q(char *buf, size_t n, double v)
{
    if (isnan(v))
        snprintf(buf, n, "—");
    else
        snprintf(buf, n, "%.0f", v);
}

/* "mean ± se; min / median / p95 / p99 / max" over the runs, or the
 * detected fraction and "min / median / p95 / p99" when some runs reached
 * the horizon (percentiles beyond it are "—"). */
static void fmt_det(char *buf, size_t n, const det_result *d)
{
    char med[32], p95[32], p99[32];
    fmt_q(med, sizeof med, d->median);
    fmt_q(p95, sizeof p95, d->p95);
    fmt_q(p99, sizeof p99, d->p99);
    if (d->detected == 0)
        snprintf(buf, n, "0 %% detected");
    else if (d->detected == d->runs)
        snprintf(buf, n, "%.0f ± %.0f; %.0f / %s / %s / %s / %.0f", d->mean, d->se, d->min, med,
                 p95, p99, d->max);
    else
        snprintf(buf, n, "%.1f %% detected; %.0f / %s / %s / %s", 100.0 * d->detected / d->runs,
                 d->min, med, p95, p99);
}

static void header(const sim_opts *o)
{
    printf("| W | K | n_b | R | p | C | raise/clear | false STD alerts /1e5 | runs with one |"
           " false STD alert lasts (median; not cleared) | false mean alerts /1e5 |");
    for (int i = 0; i < o->n_damage; i++)
        printf(" %g %%: STD alert delay |", 100 * o->damage[i]);
    if (o->n_damage > 0)
        printf(" %g %%: mean alert delay | clears /1e5 after the alert |",
               100 * o->damage[o->n_damage - 1]);
    printf("\n|");
    for (int i = 0; i < 11 + o->n_damage + 2 * (o->n_damage > 0); i++)
        printf("---|");
    printf("\n");
    fflush(stdout);
}

static void row(const amfi_indicator_params *p, const sim_opts *o, gsl_rng *rng)
{
    time_t t0 = time(NULL);
    fa_result fs, fm;
    false_alarms(p, o, rng, &fs, &fm);
    char a[64], b[64];
    fmt_fa(a, sizeof a, &fs);
    fmt_fa(b, sizeof b, &fm);
    char nb[32];
    if (o->explicit_baseline)
        snprintf(nb, sizeof nb, "explicit");
    else
        snprintf(nb, sizeof nb, "%d", p->baseline_n);
    char dur[64];
    if (fs.alarms == 0)
        snprintf(dur, sizeof dur, "—");
    else if (isnan(fs.dur_median))
        snprintf(dur, sizeof dur, "—; %ld", fs.not_cleared);
    else
        snprintf(dur, sizeof dur, "%.0f; %ld", fs.dur_median, fs.not_cleared);
    printf("| %d | %d | %s | %.4g | %.2g | %.4g | %d/%d | %s | %ld/%ld | %s | %s |",
           p->window, p->every, nb, p->std_alert_ratio, p->std_alert_p, p->std_clear_ratio,
           p->raise_after, p->clear_after, a, fs.runs_with_alarm, o->fa_runs, dur,
           p->mean_shift ? b : "off");
    det_result last_mean = { 0 };
    char clr[160] = "";
    long redrawn = 0;
    for (int i = 0; i < o->n_damage; i++) {
        det_result ds, dm;
        detection(p, o, rng, o->damage[i], &ds, &dm);
        char c[160];
        fmt_det(c, sizeof c, &ds);
        printf(" %s |", c);
        last_mean = dm;
        redrawn += ds.redrawn;
        size_t l = strlen(clr);
        if (ds.after_vehicles > 0)
            snprintf(clr + l, sizeof clr - l, "%s%.3g", i ? " / " : "",
                     1e5 * (double)ds.clears / ds.after_vehicles);
        else
            snprintf(clr + l, sizeof clr - l, "%s—", i ? " / " : "");
    }
    if (o->n_damage > 0) {
        char c[160];
        if (p->mean_shift)
            fmt_det(c, sizeof c, &last_mean);
        else
            snprintf(c, sizeof c, "off");
        printf(" %s | %s |", c, clr);
    }
    printf("\n");
    fflush(stdout);
    fprintf(stderr, "%s: row done in %ld s (%ld detection runs redrawn after a false alarm)\n",
            PROG, (long)(time(NULL) - t0), redrawn);
}

/* The candidates of docs/indicators.md's table: changes from the
 * defaults, one set per line (window, every, baseline_n, R, p, C,
 * raise_after, clear_after). */
typedef struct {
    int window, every, baseline_n;
    double ratio, p, clear;
    int raise_after, clear_after;
} candidate;

static const candidate sweep[] = {
    /* no debounce, and a first guess */
    { 500, 50, 5000, 1.08, 0.01, 1.02, 1, 1 },
    { 500, 50, 5000, 1.10, 0.01, 1.05, 3, 3 },
    /* the chosen rule (K 100, six in a row, R 1.08, C 1.00) against the
     * baseline size; 10000 is the default */
    { 500, 100, 2000, 1.08, 0.01, 1.00, 6, 6 },
    { 500, 100, 5000, 1.08, 0.01, 1.00, 6, 6 },
    { 500, 100, 10000, 1.08, 0.01, 1.00, 6, 6 },
    { 500, 100, 20000, 1.08, 0.01, 1.00, 6, 6 },
    /* the threshold and the debounce span around it */
    { 500, 100, 10000, 1.10, 0.01, 1.00, 6, 6 },
    { 500, 100, 10000, 1.09, 0.01, 1.00, 4, 4 },
    { 500, 100, 10000, 1.08, 0.01, 1.00, 8, 8 },
    { 500, 50, 10000, 1.08, 0.01, 1.00, 11, 11 },
    { 500, 250, 10000, 1.08, 0.01, 1.00, 3, 3 },
    /* the clear ratio (hysteresis) */
    { 500, 100, 10000, 1.08, 0.01, 1.02, 6, 6 },
    { 500, 100, 10000, 1.08, 0.01, 1.04, 6, 6 },
};

static void usage(FILE *f)
{
    fprintf(f,
            "usage: %s [--sweep] [--explicit-baseline] [--seed S] [--fa-runs N] [--fa-vehicles N] [--det-runs N]\n"
            "       [--damage P1,P2,...] [--horizon N] [--after N] [--meas-sd T] [--meas-sd-10 T]\n"
            "       [--window W] [--every K] [--baseline-n N] [--std-alert-ratio R]\n"
            "       [--std-alert-p P] [--std-clear-ratio C] [--raise-after N]\n"
            "       [--clear-after N] [--mean-shift 0|1] [--mean-alert-ratio R]\n"
            "       [--mean-alert-p P] [--mean-clear-ratio C]\n"
            "(damage in %%, weights in t; see the header of tools/research/amfi-indicator-sim.c)\n"
            "  -h, --help      this help\n"
            "  -V, --version   print the version\n",
            PROG);
}

/* --damage P1,P2,... in %, stored as fractions */
static void damage_list(const amfi_cli *c, const char *s, sim_opts *o)
{
    o->n_damage = amfi_cli_list(c, s, o->damage, MAX_DAMAGE, 0.1, 50.0);
    for (int i = 0; i < o->n_damage; i++)
        o->damage[i] /= 100.0;
}

int main(int argc, char **argv)
{
    sim_opts o = { .seed = 1, .fa_runs = 10000, .fa_vehicles = 100000, .det_runs = 2000,
                   .horizon = 20000, .after = 10000, .n_damage = 2, .damage = { 0.05, 0.10 },
                   .meas_sd = 300.0, .meas_sd_10 = -1.0 };
    amfi_indicator_params p;
    amfi_indicator_params_default(&p);
    int do_sweep = 0;
    enum { O_SWEEP = 256, O_EXPLICIT_BASELINE, O_SEED, O_FA_RUNS, O_FA_VEHICLES, O_DET_RUNS,
           O_AFTER, O_HORIZON, O_DAMAGE, O_MEAS_SD, O_MEAS_SD_10, O_WINDOW, O_EVERY,
           O_BASELINE_N, O_STD_ALERT_RATIO, O_STD_ALERT_P, O_STD_CLEAR_RATIO, O_RAISE_AFTER,
           O_CLEAR_AFTER, O_MEAN_SHIFT, O_MEAN_ALERT_RATIO, O_MEAN_ALERT_P, O_MEAN_CLEAR_RATIO };
    static const struct option longopts[] = {
        {"sweep", no_argument, NULL, O_SWEEP},
        {"explicit-baseline", no_argument, NULL, O_EXPLICIT_BASELINE},
        {"seed", required_argument, NULL, O_SEED},
        {"fa-runs", required_argument, NULL, O_FA_RUNS},
        {"fa-vehicles", required_argument, NULL, O_FA_VEHICLES},
        {"det-runs", required_argument, NULL, O_DET_RUNS},
        {"after", required_argument, NULL, O_AFTER},
        {"horizon", required_argument, NULL, O_HORIZON},
        {"damage", required_argument, NULL, O_DAMAGE},
        {"meas-sd", required_argument, NULL, O_MEAS_SD},
        {"meas-sd-10", required_argument, NULL, O_MEAS_SD_10},
        {"window", required_argument, NULL, O_WINDOW},
        {"every", required_argument, NULL, O_EVERY},
        {"baseline-n", required_argument, NULL, O_BASELINE_N},
        {"std-alert-ratio", required_argument, NULL, O_STD_ALERT_RATIO},
        {"std-alert-p", required_argument, NULL, O_STD_ALERT_P},
        {"std-clear-ratio", required_argument, NULL, O_STD_CLEAR_RATIO},
        {"raise-after", required_argument, NULL, O_RAISE_AFTER},
        {"clear-after", required_argument, NULL, O_CLEAR_AFTER},
        {"mean-shift", required_argument, NULL, O_MEAN_SHIFT},
        {"mean-alert-ratio", required_argument, NULL, O_MEAN_ALERT_RATIO},
        {"mean-alert-p", required_argument, NULL, O_MEAN_ALERT_P},
        {"mean-clear-ratio", required_argument, NULL, O_MEAN_CLEAR_RATIO},
        AMFI_CLI_END};
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *v = optarg;
        switch (k) {
        case O_SWEEP: do_sweep = 1; break;
        case O_EXPLICIT_BASELINE: o.explicit_baseline = 1; break;
        case O_SEED: o.seed = (unsigned long)amfi_cli_integer(&c, v, 0, 4294967295.0); break;
        case O_FA_RUNS: o.fa_runs = amfi_cli_integer(&c, v, 1, 1e7); break;
        case O_FA_VEHICLES: o.fa_vehicles = amfi_cli_integer(&c, v, 1, 1e10); break;
        case O_DET_RUNS: o.det_runs = amfi_cli_integer(&c, v, 1, 1e7); break;
        case O_AFTER: o.after = amfi_cli_integer(&c, v, 0, 1e9); break;
        case O_HORIZON: o.horizon = amfi_cli_integer(&c, v, 1, 1e9); break;
        case O_DAMAGE: damage_list(&c, v, &o); break;
        case O_MEAS_SD: o.meas_sd = 1000.0 * amfi_cli_num(&c, v, 0, 10); break;
        case O_MEAS_SD_10: o.meas_sd_10 = 1000.0 * amfi_cli_num(&c, v, 0, 10); break;
        case O_WINDOW: p.window = (int)amfi_cli_integer(&c, v, 2, 1e7); break;
        case O_EVERY: p.every = (int)amfi_cli_integer(&c, v, 1, 1e7); break;
        case O_BASELINE_N: p.baseline_n = (int)amfi_cli_integer(&c, v, 2, 1e9); break;
        case O_STD_ALERT_RATIO: p.std_alert_ratio = amfi_cli_num(&c, v, 1, 100); break;
        case O_STD_ALERT_P: p.std_alert_p = amfi_cli_num(&c, v, 1e-300, 1); break;
        case O_STD_CLEAR_RATIO: p.std_clear_ratio = amfi_cli_num(&c, v, 0, 100); break;
        case O_RAISE_AFTER: p.raise_after = (int)amfi_cli_integer(&c, v, 1, 1e6); break;
        case O_CLEAR_AFTER: p.clear_after = (int)amfi_cli_integer(&c, v, 1, 1e6); break;
        case O_MEAN_SHIFT: p.mean_shift = (int)amfi_cli_integer(&c, v, 0, 1); break;
        case O_MEAN_ALERT_RATIO: p.mean_alert_ratio = amfi_cli_num(&c, v, 1, 100); break;
        case O_MEAN_ALERT_P: p.mean_alert_p = amfi_cli_num(&c, v, 1e-300, 1); break;
        case O_MEAN_CLEAR_RATIO: p.mean_clear_ratio = amfi_cli_num(&c, v, 1, 100); break;
        }
    }
    if (o.meas_sd_10 < 0)
        o.meas_sd_10 = o.meas_sd;

    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        return 1;
    }
    gsl_rng_set(rng, o.seed);
    if (o.explicit_baseline) {
        /* The healthy population's own mean and STD (1e6 draws, Welford). */
        stream s = { rng, 1.0, 0.0 };
        set_damage(&s, &o, 0.0);
        double m = 0, m2 = 0;
        for (long i = 1; i <= EXPLICIT_N; i++) {
            double x = draw(&s), d = x - m;
            m += d / i;
            m2 += d * (x - m);
        }
        o.pop_mean = m;
        o.pop_std = sqrt(m2 / (EXPLICIT_N - 1));
    }
    printf("<!-- %s: seed %lu, %ld healthy runs x %ld vehicles, %ld detection runs per level,"
           " horizon %ld, clears counted over %ld vehicles after the alert, measurement error"
           " %.2f t (%.2f t at 10 %%), %s baseline -->\n",
           PROG, o.seed, o.fa_runs, o.fa_vehicles, o.det_runs, o.horizon, o.after,
           o.meas_sd / 1000.0, o.meas_sd_10 / 1000.0,
           o.explicit_baseline ? "explicit (population mean and STD, n = 1e6)" : "automatic");
    header(&o);
    if (do_sweep) {
        for (size_t i = 0; i < sizeof sweep / sizeof sweep[0]; i++) {
            amfi_indicator_params q = p;
            q.window = sweep[i].window;
            q.every = sweep[i].every;
            q.baseline_n = sweep[i].baseline_n;
            q.std_alert_ratio = sweep[i].ratio;
            q.std_alert_p = sweep[i].p;
            q.std_clear_ratio = sweep[i].clear;
            q.raise_after = sweep[i].raise_after;
            q.clear_after = sweep[i].clear_after;
            row(&q, &o, rng);
        }
    } else {
        row(&p, &o, rng);
    }
    gsl_rng_free(rng);
    return 0;
}
