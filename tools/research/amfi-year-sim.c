/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-year-sim: a year of traffic at a site, from the per-vehicle error
 * model, with the site climate and the drifting mix of sim_publisher's
 * --environment site (sim_publisher/environment.c, mix.c, used as they
 * are), watched by amfid's indicator engine (indicators/, used as it is):
 * false alarms per healthy year and detection delays in vehicles and days,
 * with the environment on and off (issue 14, docs/results/year-evaluation.md).
 *
 *   amfi-year-sim [--seed S] [--years N] [--det-runs N] [--flow VEH_PER_DAY]
 *                 [--damage P1,P2,...] [--meas-sd T] [--drift on|off|both]
 *
 * Stream model (kg). A run starts on a random day of the year (commissioning)
 * and lasts 365 days. Vehicles arrive uniformly within each day, --flow a
 * day on average over a week (default 2000); with drift on a weekend day
 * carries the mix's weekend factor (0.35) of a weekday. True GVW: the
 * shipped population's law, normal(8765, 1960) truncated to [4000, 15000],
 * split at its median 8765 kg into empty and loaded halves; with drift on a
 * vehicle is loaded with the mix's share of that day (weekday/weekend,
 * season), otherwise with probability 1/2 (the population itself). Inferred
 * GVW = (true + e) / ((1 − d) · f(T_deck)), e ~ normal(0, --meas-sd, default
 * 0.3 t, as amfi-indicator-sim), f the modulus factor of the deck
 * temperature at the vehicle's time with drift on (1 with drift off): the
 * solver assumes the configured modulus, the bridge has E·f·(1 − d), and a
 * uniform stiffness change scales every inferred weight by its inverse
 * (issue 14).
 *
 * Indicator: amfid's engine with amfi_indicator_params_default (the STD rule
 * "std_increase", warning, and the mean rule "mean_shift", info); the
 * automatic baseline is the first baseline_n vehicles after commissioning.
 *
 * False alarms: --years healthy runs; every raise of a kind is a false alarm
 * of that kind; printed per healthy year (the mean over runs).
 * Detection: --det-runs runs per damage level, the damage starting at a
 * uniformly random time in days [30, 335) of the run (after the baseline);
 * delay = vehicles (and days) from the damage to the first STD raise after
 * it, or "not within" the rest of the run plus 120 days. A run whose STD
 * alert is raised before the damage is counted as false and still runs on
 * (the raise must happen again after a clear to count).
 *
 * Output: a markdown table on stdout. One gsl_rng_mt19937 seeded with --seed;
 * the climate's weather per run from the same generator. Single thread.
 */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi_cli.h"
#include "environment.h"
#include "indicators.h"
#include "mix.h"

#define PROG "amfi-year-sim"
#define GVW_MU 8765.0
#define GVW_SD 1960.0
#define GVW_LO 4000.0
#define GVW_HI 15000.0
#define MAX_DAMAGE 8
#define DAY_S 86400.0

typedef struct {
    unsigned long seed;
    long years, det_runs;
    double flow, meas_sd;
    int n_damage;
    double damage[MAX_DAMAGE];
    int drift_on, drift_off;
} opts;

/* One run's world: the climate, the calendar, the damage. */
typedef struct {
    gsl_rng *rng;
    int drift;
    amfi_env_state env;
    amfi_mix_params mix;
    double day0;       /* day of the year at run time 0 */
    double damage;     /* from damage_t_s on */
    double damage_t_s; /* run time of the damage, s; INFINITY: none */
} world;

static double true_gvw(world *w, double t_s)
{
    const double share = w->drift ? amfi_mix_loaded_share(&w->mix, w->day0 + t_s / DAY_S) : 0.5;
    const int loaded = gsl_rng_uniform(w->rng) < share;
    double x;
    do
        x = GVW_MU + gsl_ran_gaussian_ziggurat(w->rng, GVW_SD);
    while (x < GVW_LO || x > GVW_HI || (x >= GVW_MU) != loaded);
    return x;
}

static double inferred(world *w, double t_s, double meas_sd)
{
    double f = 1.0;
    if (w->drift) {
        amfi_env_advance(&w->env, t_s);
        f = amfi_env_modulus_factor(&w->env.p, w->env.deck_c);
    }
    const double d = t_s >= w->damage_t_s ? w->damage : 0.0;
    double x = true_gvw(w, t_s) + gsl_ran_gaussian_ziggurat(w->rng, meas_sd);
    if (x < 1.0)
        x = 1.0;
    return x / ((1.0 - d) * f);
}

static void world_start(world *w, gsl_rng *rng, int drift)
{
    amfi_env_params ep;
    memset(w, 0, sizeof *w);
    w->rng = rng;
    w->drift = drift;
    w->day0 = floor(gsl_rng_uniform(rng) * 365.0);
    amfi_env_params_site(&ep);
    amfi_env_init(&w->env, &ep, w->day0, gsl_rng_get(rng));
    amfi_mix_params_site(&w->mix);
    w->mix.split_kg = GVW_MU;
    w->damage_t_s = INFINITY;
}

static amfi_indicators *make(void)
{
    amfi_indicator_params p;
    amfi_indicators *ind;
    char err[256];
    amfi_indicator_params_default(&p);
    if (amfi_indicators_create(&p, &ind, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        exit(2);
    }
    return ind;
}

/* Raises in this push: bit 1 std_increase, bit 2 mean_shift. */
static int push(amfi_indicators *ind, double gvw)
{
    amfi_alert_event ev[2];
    int n = 0, r = 0;
    if (amfi_indicators_push(ind, gvw, NULL, ev, &n) < 0) {
        fprintf(stderr, "%s: push rejected %g kg\n", PROG, gvw);
        exit(1);
    }
    for (int i = 0; i < n; i++)
        if (ev[i].raised)
            r |= strcmp(ev[i].kind, "std_increase") == 0 ? 1 : 2;
    return r;
}

/* Drive one run for `days` days, counting raises per kind in fa[]. Returns
 * the vehicles pushed. With stop_on_detect, stops at the first STD raise
 * after the damage and sets *delay_veh, *delay_days (raises before the
 * damage are counted in fa[0]). */
static long run(world *w, const opts *o, double days, long fa[2], int stop_on_detect,
                long *delay_veh, double *delay_days)
{
    amfi_indicators *ind = make();
    long pushed = 0, after = 0;
    for (long day = 0; day < (long)days; day++) {
        /* --flow is the mean over a week: with drift on the weekdays carry
         * more, the weekend days the mix's weekend factor of a weekday */
        const double flow =
            w->drift ? o->flow * 7.0 / (5.0 + 2.0 * w->mix.weekend_flow) *
                           amfi_mix_flow_factor(&w->mix, w->day0 + day)
                     : o->flow;
        const long n = (long)floor(flow + gsl_rng_uniform(w->rng));
        for (long i = 0; i < n; i++) {
            const double t = (day + (i + gsl_rng_uniform(w->rng)) / (double)n) * DAY_S;
            const int r = push(ind, inferred(w, t, o->meas_sd));
            pushed++;
            if (t >= w->damage_t_s)
                after++;
            if (r & 1) {
                if (stop_on_detect && t >= w->damage_t_s) {
                    *delay_veh = after;
                    *delay_days = (t - w->damage_t_s) / DAY_S;
                    amfi_indicators_destroy(ind);
                    return pushed;
                }
                fa[0]++;
            }
            if (r & 2)
                fa[1]++;
        }
    }
    amfi_indicators_destroy(ind);
    return pushed;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double quantile(double *v, long n, double q) /* v sorted; nearest rank */
{
    long k = (long)ceil(q * (double)n) - 1;
    if (k < 0)
        k = 0;
    if (k >= n)
        k = n - 1;
    return v[k];
}

static void evaluate(const opts *o, gsl_rng *rng, int drift)
{
    long fa[2] = {0, 0}, vehicles = 0;
    world w;
    for (long y = 0; y < o->years; y++) {
        world_start(&w, rng, drift);
        vehicles += run(&w, o, 365.0, fa, 0, NULL, NULL);
    }
    printf("| %s | healthy | %ld years, %.0f vehicles/year | std_increase %.2f/year, "
           "mean_shift %.2f/year | | | | |\n",
           drift ? "on" : "off", o->years, (double)vehicles / (double)o->years,
           (double)fa[0] / (double)o->years, (double)fa[1] / (double)o->years);
    fflush(stdout);
    for (int k = 0; k < o->n_damage; k++) {
        double *dv = malloc(sizeof(double) * (size_t)o->det_runs);
        double *dd = malloc(sizeof(double) * (size_t)o->det_runs);
        long found = 0, early = 0;
        if (!dv || !dd) {
            fprintf(stderr, "%s: out of memory\n", PROG);
            exit(1);
        }
        for (long r = 0; r < o->det_runs; r++) {
            long f2[2] = {0, 0}, veh = -1;
            double days = -1.0;
            world_start(&w, rng, drift);
            w.damage = o->damage[k];
            w.damage_t_s = (30.0 + gsl_rng_uniform(rng) * 305.0) * DAY_S;
            (void)run(&w, o, 365.0 + 120.0, f2, 1, &veh, &days);
            early += f2[0] > 0;
            if (veh >= 0) {
                dv[found] = (double)veh;
                dd[found] = days;
                found++;
            }
        }
        qsort(dv, (size_t)found, sizeof *dv, cmp_double);
        qsort(dd, (size_t)found, sizeof *dd, cmp_double);
        if (found)
            printf("| %s | %.1f %% | %ld/%ld detected (%ld runs with a false STD alert "
                   "before) | | %.0f | %.0f | %.2f | %.2f |\n",
                   drift ? "on" : "off", 100.0 * o->damage[k], found, o->det_runs, early,
                   quantile(dv, found, 0.5), quantile(dv, found, 0.95), quantile(dd, found, 0.5),
                   quantile(dd, found, 0.95));
        else
            printf("| %s | %.1f %% | 0/%ld detected | | | | | |\n", drift ? "on" : "off",
                   100.0 * o->damage[k], o->det_runs);
        fflush(stdout);
        free(dv);
        free(dd);
    }
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: %s [--seed S] [--years N] [--det-runs N] [--flow VEH_PER_DAY]\n"
            "       [--damage P1,P2,...] [--meas-sd T] [--drift on|off|both]\n"
            "A year of traffic with the site climate and the drifting mix, watched by\n"
            "amfid's indicator engine: false alarms per healthy year, detection delays.\n"
            "  --seed S          generator seed (default 1)\n"
            "  --years N         healthy years simulated (default 20)\n"
            "  --det-runs N      detection runs per damage level (default 20)\n"
            "  --flow N          vehicles per weekday (default 2000)\n"
            "  --damage LIST     stiffness losses, fractions (default 0.025,0.05,0.10)\n"
            "  --meas-sd T       per-vehicle error, t (default 0.3)\n"
            "  --drift WHICH     temperature and mix drift on, off or both (default both)\n"
            "  -h, --help        this help\n"
            "  -V, --version     print the version\n",
            PROG);
}

int main(int argc, char **argv)
{
    opts o = {.seed = 1, .years = 20, .det_runs = 20, .flow = 2000, .meas_sd = 300.0,
              .n_damage = 3, .damage = {0.025, 0.05, 0.10}, .drift_on = 1, .drift_off = 1};
    enum { O_SEED = 256, O_YEARS, O_DET_RUNS, O_FLOW, O_DAMAGE, O_MEAS_SD, O_DRIFT };
    static const struct option longopts[] = {
        {"seed", required_argument, NULL, O_SEED},
        {"years", required_argument, NULL, O_YEARS},
        {"det-runs", required_argument, NULL, O_DET_RUNS},
        {"flow", required_argument, NULL, O_FLOW},
        {"damage", required_argument, NULL, O_DAMAGE},
        {"meas-sd", required_argument, NULL, O_MEAS_SD},
        {"drift", required_argument, NULL, O_DRIFT},
        AMFI_CLI_END};
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        const char *v = optarg;
        switch (k) {
        case O_SEED: o.seed = (unsigned long)amfi_cli_integer(&c, v, 0, 4294967295.0); break;
        case O_YEARS: o.years = amfi_cli_integer(&c, v, 1, 1e5); break;
        case O_DET_RUNS: o.det_runs = amfi_cli_integer(&c, v, 1, 1e5); break;
        case O_FLOW: o.flow = amfi_cli_num(&c, v, 1, 1e6); break;
        case O_DAMAGE:
            o.n_damage = amfi_cli_list(&c, v, o.damage, MAX_DAMAGE, 1e-4, 0.5);
            break;
        case O_MEAS_SD: o.meas_sd = 1000.0 * amfi_cli_num(&c, v, 0, 10); break;
        case O_DRIFT:
            if (!strcmp(v, "on") || !strcmp(v, "off") || !strcmp(v, "both")) {
                o.drift_on = strcmp(v, "off") != 0;
                o.drift_off = strcmp(v, "on") != 0;
            } else {
                amfi_cli_fail(&c, "'%s' is not on, off or both", amfi_cli_shown(v));
            }
            break;
        }
    }
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng)
        return 1;
    gsl_rng_set(rng, o.seed);
    const clock_t c0 = clock();
    printf("| drift | damage | runs | false alarms | median delay (vehicles) | p95 (vehicles) "
           "| median delay (days) | p95 (days) |\n|---|---|---|---|---|---|---|---|\n");
    if (o.drift_off)
        evaluate(&o, rng, 0);
    if (o.drift_on)
        evaluate(&o, rng, 1);
    fprintf(stderr, "%s: %.1f s CPU\n", PROG, (double)(clock() - c0) / CLOCKS_PER_SEC);
    gsl_rng_free(rng);
    return 0;
}
