/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-year-sim: a year of traffic at a site, from the per-vehicle error
 * model, with the site climate and the drifting mix of sim_publisher's
 * --environment site (sim_publisher/environment.c, mix.c, used as they
 * are), watched by amfid's indicator engine (indicators/indicators.c, the
 * STD and mean rules), the scale indicator (indicators/scale.c) and the
 * known-truck runs (indicators/known_truck.c), side by side: false alarms
 * per healthy year and detection delays in vehicles (runs) and days, with
 * the environment on and off (issue 14, docs/results/year-evaluation.md).
 *
 *   amfi-year-sim [--seed S] [--years N] [--det-runs N] [--flow VEH_PER_DAY]
 *                 [--population FILE] [--meas-rel F] [--std-filter F] [--scale-filter F]
 *                 [--damage P1,P2,...] [--meas-sd T]
 *                 [--drift on|off|both|temperature|mix]
 *                 [--scale-fa F] [--mix-probe] [--prior-scale F] [--truck-runs N]
 *                 [--std-raw] [--scale-block B] [--scale-baseline-blocks N]
 *                 [--scale-design D] [--baseline-n N]
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
 * --population FILE (e.g. sim_publisher/data/population-eu.csv): the true
 * GVW is a record of the file instead, drawn as sim_publisher --environment
 * site draws it (amfi_mix_classify_by_class: loaded at or above its own
 * class's median; amfi_mix_pick with the day's loaded share, or the file's
 * own loaded fraction with drift off), classed by classify/ (scheme eu).
 * --meas-rel F adds an error part proportional to the true GVW: e ~
 * normal(0, sqrt(meas_sd² + (F · GVW)²)).
 *
 * Class filters (--std-filter, --scale-filter, as amfid's
 * daemon.indicators.classes and min_gvw_kg): "all", or CLASSES[@MIN_KG]
 * (comma-separated EU classes or "trucks", every class but CAR): only the
 * vehicles of those classes whose weight fed (at the calibration
 * temperature) is at least MIN_KG feed that indicator. A filtered
 * indicator's baseline takes as many of its vehicles as pooled (its days
 * grow with 1 / the fraction of the file that passes), and the scale
 * indicator's vehicles_per_day and class_split_kg are the flow × that
 * fraction and the median of the records that pass.
 *
 * Indicators: amfid's engine with amfi_indicator_params_default (the STD
 * rule "std_increase", warning, and the mean rule "mean_shift", info; the
 * automatic baseline is the first baseline_n vehicles after commissioning,
 * --baseline-n), fed as amfid feeds them by default
 * (daemon.indicators.temperature: compensated): each weight brought to the
 * calibration temperature by the scale indicator's temperature model, its
 * fitted slopes once its baseline exists, its prior slopes before; --std-raw
 * feeds them the raw weights (the paper's rule as it stood).
 * The scale indicator with amfi_scale_params_default (vehicles_per_day =
 * --flow; --scale-fa its target; --scale-block, --scale-baseline-blocks and
 * --scale-design as a site or a test sets them), fed each vehicle's deck
 * temperature (drift off: a constant 10 °C). Known truck: --truck-runs runs a week (default 1;
 * every 7 / N days from the third day, between 8 and 16 h) of a 14 t truck, inferred = (14 t + e) / ((1 − d) ·
 * f(T_deck)) with the same e, amfi_known_truck_params_default with run_sd =
 * --meas-sd / 14 t, the prior temperature slopes.
 *
 * Baselines take T0 days: the larger of 30 days (the known truck's 4 weekly
 * runs) and 1.2 × the vehicles of the longer baseline (the STD rule's
 * baseline_n, the scale indicator's block × baseline blocks) / --flow (30 at
 * the default 2000 a day; 436 at 55 a day).
 * False alarms: --years healthy runs of T0 + 335 days (365 at the default
 * flow: the baselines and at least a year watched after them); every raise
 * of a kind is a false alarm of that kind; printed per healthy run (a year
 * watched; the mean over runs).
 * Detection: --det-runs runs per damage level, the damage starting at a
 * uniformly random time in days [T0, T0 + 305) of the run (after the
 * baselines); delay = vehicles (known truck: runs) and days from the damage
 * to each warning kind's first raise after it, or "not within" the rest of
 * the run (T0 + 455 days). A run whose alert is raised before the damage is counted
 * as false and still runs on (the raise must happen again after a clear to
 * count).
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

#include "amfi_classify.h"
#include "amfi_cli.h"
#include "environment.h"
#include "indicators.h"
#include "mix.h"
#include "known_truck.h"
#include "scale.h"
#include "traffic.h"

#define PROG "amfi-year-sim"
#define GVW_MU 8765.0
#define GVW_SD 1960.0
#define GVW_LO 4000.0
#define GVW_HI 15000.0
#define MAX_DAMAGE 8
#define DAY_S 86400.0
#define TRUCK_KG 14000.0 /* the known truck's reference GVW: a loaded two-axle truck */
#define DECK_OFF_C 10.0 /* drift off: a constant deck at the modulus law's reference */
/* What drifts in a run (--drift): the deck temperature (the bridge's
 * modulus), the traffic mix (the loaded share and the weekday flow). */
#define DRIFT_TEMP 1
#define DRIFT_MIX 2

/* Which vehicles feed an indicator (--std-filter, --scale-filter): every one,
 * or those of the classes in `mask` (bit: amfi_eu_class) whose weight fed
 * (at the calibration temperature where the rules get it so) is at least
 * min_kg. */
typedef struct {
    int all;
    unsigned mask;
    double min_kg;
    char text[64];
} filter;

/* --population: the records, their EU class (classify/, −1: none), the mix's
 * per-class empty/loaded split (sim_publisher/mix.c) and the population's own
 * loaded fraction (the share with drift off). */
static struct {
    amfi_vehicle_rec *recs;
    int n;
    int *cls;
    amfi_mix_classes mc;
    double own_share;
} POP;

typedef struct {
    unsigned long seed;
    long years, det_runs;
    double flow, meas_sd;
    int n_damage;
    double damage[MAX_DAMAGE];
    int n_modes, modes[2];  /* --drift: the drift masks evaluated, in order */
    double scale_fa; /* --scale-fa: the scale indicator's target false alarms a year (0: default) */
    int mix_probe;   /* --mix-probe */
    double prior_scale; /* --prior-scale: the temperature model's prior slopes × this */
    int truck_runs;     /* --truck-runs: known-truck runs a week */
    int std_comp;       /* the STD/mean engine gets temperature-compensated weights
                           (the scale model's slopes once fitted, its prior
                           slopes before); 0: --std-raw */
    int scale_block, scale_blocks; /* --scale-block, --scale-baseline-blocks (0: default) */
    double scale_design;           /* --scale-design (0: default) */
    int baseline_n;                /* --baseline-n: the STD rule's baseline (0: default) */
    const char *population;        /* --population: a vehicle file (NULL: the normal law) */
    double meas_rel;               /* --meas-rel: the error's part proportional to GVW */
    filter std_f, scale_f;         /* --std-filter, --scale-filter */
} opts;

/* One run's world: the climate, the calendar, the damage. */
typedef struct {
    gsl_rng *rng;
    int drift;         /* DRIFT_TEMP | DRIFT_MIX */
    amfi_env_state env;
    amfi_mix_params mix;
    double day0;       /* day of the year at run time 0 */
    double damage;     /* from damage_t_s on */
    double damage_t_s; /* run time of the damage, s; INFINITY: none */
    double deck_c;     /* deck temperature at the last vehicle (drift off: DECK_OFF_C) */
    int cls;           /* EU class of the last vehicle (−1: none; the normal law: −1) */
} world;

/* A true GVW, loaded with probability `share`. */
static double draw_gvw(gsl_rng *rng, double share)
{
    const int loaded = gsl_rng_uniform(rng) < share;
    double x;
    do
        x = GVW_MU + gsl_ran_gaussian_ziggurat(rng, GVW_SD);
    while (x < GVW_LO || x > GVW_HI || (x >= GVW_MU) != loaded);
    return x;
}

static double true_gvw(world *w, double t_s)
{
    if (POP.recs) { /* the vehicle file: a record of the day's share, sim_publisher's draw */
        const double share = (w->drift & DRIFT_MIX)
                                 ? amfi_mix_loaded_share(&w->mix, w->day0 + t_s / DAY_S)
                                 : POP.own_share;
        const double u1 = gsl_rng_uniform(w->rng), u2 = gsl_rng_uniform(w->rng);
        const int k = amfi_mix_pick(&POP.mc, share, u1, u2);
        w->cls = POP.cls[k];
        return POP.recs[k].gvw_kg;
    }
    w->cls = -1;
    return draw_gvw(w->rng,
                    (w->drift & DRIFT_MIX) ? amfi_mix_loaded_share(&w->mix, w->day0 + t_s / DAY_S)
                                           : 0.5);
}

static double inferred(world *w, double t_s, double meas_sd, double meas_rel)
{
    double f = 1.0;
    w->deck_c = DECK_OFF_C;
    if (w->drift & DRIFT_TEMP) {
        amfi_env_advance(&w->env, t_s);
        f = amfi_env_modulus_factor(&w->env.p, w->env.deck_c);
        w->deck_c = w->env.deck_c;
    }
    const double d = t_s >= w->damage_t_s ? w->damage : 0.0;
    const double g = true_gvw(w, t_s);
    double x = g + gsl_ran_gaussian_ziggurat(w->rng, meas_rel > 0 ? hypot(meas_sd, meas_rel * g)
                                                                   : meas_sd);
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
    w->mix.split_kg = GVW_MU; /* the normal law's; a vehicle file splits per class */
    w->damage_t_s = INFINITY;
}

/* The indicators of one run, side by side. */
enum { K_STD, K_MEAN, K_SCALE, K_TRUCK, N_KIND };
static const char *const kind_name[N_KIND] = {"std_increase", "mean_shift", "scale_shift",
                                              "known_truck"};

typedef struct {
    amfi_indicators *ind;
    amfi_scale *scale;
    amfi_known_truck *truck;
    amfi_scale_params sp; /* the scale indicator's parameters (its temperature model) */
    int std_comp;         /* feed the STD/mean engine compensated weights */
    const filter *std_f, *scale_f;
} engines;

/* 1 when a vehicle of class cls (−1: none) whose weight fed is g_kg passes f. */
static int passes(const filter *f, int cls, double g_kg)
{
    if (f->all)
        return 1;
    return cls >= 0 && (f->mask & (1u << cls)) && g_kg >= f->min_kg;
}

static int cmp_double(const void *a, const void *b);

/* The median true GVW of the vehicle file's records that pass f. */
static double filter_median(const filter *f)
{
    double *g = malloc(sizeof(double) * (size_t)POP.n);
    int m = 0;
    if (!g) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        exit(1);
    }
    for (int i = 0; i < POP.n; i++)
        if (passes(f, POP.cls[i], POP.recs[i].gvw_kg))
            g[m++] = POP.recs[i].gvw_kg;
    qsort(g, (size_t)m, sizeof *g, cmp_double);
    const double med = m % 2 ? g[m / 2] : 0.5 * (g[m / 2 - 1] + g[m / 2]);
    free(g);
    return med;
}

/* The fraction of the vehicle file (true GVW, the population's own mix) that
 * passes f: the flow an indicator so filtered is fed, for its baseline's days
 * and the scale indicator's vehicles a day. */
static double filter_fraction(const filter *f)
{
    if (f->all || !POP.recs)
        return 1.0;
    long k = 0;
    for (int i = 0; i < POP.n; i++)
        k += passes(f, POP.cls[i], POP.recs[i].gvw_kg);
    return (double)k / POP.n;
}

/* The STD engine's and the scale indicator's parameters: the defaults with
 * the options applied. */
static void engine_params(const opts *o, amfi_indicator_params *pp, amfi_scale_params *spp)
{
    amfi_indicator_params p;
    amfi_scale_params sp;
    amfi_indicator_params_default(&p);
    amfi_scale_params_default(&sp);
    sp.vehicles_per_day = o->flow * filter_fraction(&o->scale_f);
    if (POP.recs) /* as a site sets alerts.scale.class_split_kg: the median of what it is fed */
        sp.class_split_kg = filter_median(&o->scale_f);
    if (o->baseline_n > 0)
        p.baseline_n = o->baseline_n;
    if (o->scale_block > 0)
        sp.block = o->scale_block;
    if (o->scale_blocks > 0)
        sp.baseline_blocks = o->scale_blocks;
    if (o->scale_design > 0)
        sp.design_shift = o->scale_design;
    if (o->scale_fa > 0)
        sp.false_alarms_per_year = o->scale_fa;
    sp.warm_slope *= o->prior_scale;
    sp.frost_slope *= o->prior_scale;
    *pp = p;
    *spp = sp;
}

static engines make(const opts *o)
{
    amfi_indicator_params p;
    amfi_scale_params sp;
    engines e;
    char err[256];
    engine_params(o, &p, &sp);
    amfi_known_truck_params kp;
    amfi_known_truck_params_default(&kp);
    kp.run_sd = o->meas_sd / TRUCK_KG;
    kp.runs_per_year = 52.0 * o->truck_runs;
    if (amfi_indicators_create(&p, &e.ind, err, sizeof err) ||
        amfi_scale_create(&sp, &e.scale, err, sizeof err) ||
        amfi_known_truck_create(&kp, &sp, &e.truck, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        exit(2);
    }
    e.sp = sp;
    e.std_comp = o->std_comp;
    e.std_f = &o->std_f;
    e.scale_f = &o->scale_f;
    return e;
}

static void unmake(engines *e)
{
    amfi_indicators_destroy(e->ind);
    amfi_scale_destroy(e->scale);
    amfi_known_truck_destroy(e->truck);
}

/* One known-truck run at run time t_s (the deck as at the vehicle just
 * pushed): 1 << K_TRUCK when its alert was raised. */
static int truck_run(engines *e, world *w, double t_s, double meas_sd)
{
    double f = 1.0;
    if (w->drift & DRIFT_TEMP)
        f = amfi_env_modulus_factor(&w->env.p, w->env.deck_c);
    const double d = t_s >= w->damage_t_s ? w->damage : 0.0;
    const double g = (TRUCK_KG + gsl_ran_gaussian_ziggurat(w->rng, meas_sd)) / ((1.0 - d) * f);
    amfi_alert_event ev;
    const int r = amfi_known_truck_push(e->truck, g, TRUCK_KG, w->deck_c, NULL, &ev);
    if (r < 0) {
        fprintf(stderr, "%s: known-truck run rejected %g kg at %g °C\n", PROG, g, w->deck_c);
        exit(1);
    }
    return (r & AMFI_IND_ALERT) && ev.raised ? 1 << K_TRUCK : 0;
}

/* Raises in this push: bit 1 << K_*. */
static int push(engines *e, double gvw, double deck_c, int cls)
{
    amfi_alert_event ev[2], sev;
    int n = 0, r = 0;
    double g_std = gvw;
    if (e->std_comp) { /* the weight brought to the calibration temperature */
        amfi_scale_model m;
        double warm = e->sp.warm_slope, frost = e->sp.frost_slope;
        if (amfi_scale_get_model(e->scale, &m) == AMFI_IND_OK)
            warm = m.warm_slope, frost = m.frost_slope;
        g_std = gvw * amfi_scale_temp_factor(&e->sp, warm, frost, deck_c);
    }
    if (passes(e->std_f, cls, g_std) && amfi_indicators_push(e->ind, g_std, NULL, ev, &n) < 0) {
        fprintf(stderr, "%s: push rejected %g kg\n", PROG, gvw);
        exit(1);
    }
    for (int i = 0; i < n; i++)
        if (ev[i].raised)
            r |= strcmp(ev[i].kind, "std_increase") == 0 ? 1 << K_STD : 1 << K_MEAN;
    const int sr = passes(e->scale_f, cls, g_std) ? amfi_scale_push(e->scale, gvw, deck_c, NULL, &sev)
                                                   : 0;
    if (sr < 0) {
        fprintf(stderr, "%s: scale push rejected %g kg at %g °C\n", PROG, gvw, deck_c);
        exit(1);
    }
    if ((sr & AMFI_IND_ALERT) && sev.raised)
        r |= 1 << K_SCALE;
    return r;
}

/* What one run saw, per kind: raises before the damage (all of them in a
 * healthy run) and the first raise after it (-1: none). */
typedef struct {
    long fa[N_KIND];
    long det_veh[N_KIND];
    double det_days[N_KIND];
} outcome;

/* Drive one run for `days` days. With a damage, stops once every warning
 * kind (std_increase, scale_shift) was raised after it. Returns the
 * vehicles pushed. */
static long run(world *w, const opts *o, double days, outcome *out)
{
    engines e = make(o);
    long pushed = 0, after = 0, runs_after = 0, truck_j = 0;
    /* --truck-runs known-truck runs a week, every 7 / N days from day 2, between
     * 8 and 16 h */
    const double truck_every = 7.0 / o->truck_runs;
    double next_truck = (2.0 + (8.0 + 8.0 * gsl_rng_uniform(w->rng)) / 24.0) * DAY_S;
    for (int k = 0; k < N_KIND; k++) {
        out->fa[k] = 0;
        out->det_veh[k] = -1;
        out->det_days[k] = -1.0;
    }
    for (long day = 0; day < (long)days; day++) {
        /* --flow is the mean over a week: with drift on the weekdays carry
         * more, the weekend days the mix's weekend factor of a weekday */
        const double flow =
            (w->drift & DRIFT_MIX) ? o->flow * 7.0 / (5.0 + 2.0 * w->mix.weekend_flow) *
                           amfi_mix_flow_factor(&w->mix, w->day0 + day)
                     : o->flow;
        const long n = (long)floor(flow + gsl_rng_uniform(w->rng));
        for (long i = 0; i < n; i++) {
            const double t = (day + (i + gsl_rng_uniform(w->rng)) / (double)n) * DAY_S;
            const double g = inferred(w, t, o->meas_sd, o->meas_rel);
            int r = push(&e, g, w->deck_c, w->cls);
            const int damaged = t >= w->damage_t_s;
            pushed++;
            if (damaged)
                after++;
            if (t >= next_truck) {
                r |= truck_run(&e, w, t, o->meas_sd);
                if (damaged)
                    runs_after++;
                truck_j++;
                next_truck = (floor(truck_every * truck_j) + 2.0 +
                              (8.0 + 8.0 * gsl_rng_uniform(w->rng)) / 24.0) *
                             DAY_S;
            }
            for (int k = 0; k < N_KIND; k++) {
                if (!(r & (1 << k)))
                    continue;
                if (!damaged)
                    out->fa[k]++;
                else if (out->det_veh[k] < 0) {
                    out->det_veh[k] = k == K_TRUCK ? runs_after : after;
                    out->det_days[k] = (t - w->damage_t_s) / DAY_S;
                }
            }
            if (damaged && out->det_veh[K_STD] >= 0 && out->det_veh[K_MEAN] >= 0 &&
                out->det_veh[K_SCALE] >= 0 && out->det_veh[K_TRUCK] >= 0) {
                unmake(&e);
                return pushed;
            }
        }
    }
    unmake(&e);
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

/* T0: the days the baselines take (see the head of the file). */
static double baseline_days(const opts *o)
{
    amfi_indicator_params p;
    amfi_scale_params sp;
    engine_params(o, &p, &sp);
    const double nb = p.baseline_n / filter_fraction(&o->std_f),
                 ns = (double)sp.block * sp.baseline_blocks / filter_fraction(&o->scale_f);
    const double d = 1.2 * (nb > ns ? nb : ns) / o->flow;
    return d > 30.0 ? ceil(d) : 30.0;
}

/* A kind's name in the table, with its filter when it has one. */
static const char *kind_label(const opts *o, int k)
{
    static char buf[N_KIND][96];
    const filter *f = k == K_STD || k == K_MEAN ? &o->std_f : k == K_SCALE ? &o->scale_f : NULL;
    if (!f || f->all)
        return kind_name[k];
    snprintf(buf[k], sizeof buf[k], "%s [%s]", kind_name[k], f->text);
    return buf[k];
}

static void evaluate(const opts *o, gsl_rng *rng, int drift)
{
    const double t0 = baseline_days(o);
    long fa[N_KIND] = {0}, fa_runs[N_KIND] = {0}, fa_max[N_KIND] = {0}, vehicles = 0;
    world w;
    outcome oc;
    static const char *const names[4] = {"off", "temperature", "mix", "on"};
    const char *dn = names[drift & 3];
    for (long y = 0; y < o->years; y++) {
        world_start(&w, rng, drift);
        vehicles += run(&w, o, t0 + 335.0, &oc);
        for (int k = 0; k < N_KIND; k++) {
            fa[k] += oc.fa[k];
            fa_runs[k] += oc.fa[k] > 0;
            if (oc.fa[k] > fa_max[k])
                fa_max[k] = oc.fa[k];
        }
    }
    /* false alarms cluster in runs (a baseline whose SD came out low): how
     * many runs had any, and the most in one run */
    for (int k = 0; k < N_KIND; k++)
        printf("| %s | %s | healthy | %ld years, %.0f vehicles/run | %.2f/year (%ld runs with "
               "any, at most %ld in one) | | | | |\n",
               kind_label(o, k), dn, o->years, (double)vehicles / (double)o->years,
               (double)fa[k] / (double)o->years, fa_runs[k], fa_max[k]);
    fflush(stdout);
    enum { NK = 4 };
    const int kinds[NK] = {K_STD, K_MEAN, K_SCALE, K_TRUCK};
    for (int d = 0; d < o->n_damage; d++) {
        double *dv[NK], *dd[NK];
        long found[NK] = {0}, early[NK] = {0};
        for (int j = 0; j < NK; j++) {
            dv[j] = malloc(sizeof(double) * (size_t)o->det_runs);
            dd[j] = malloc(sizeof(double) * (size_t)o->det_runs);
            if (!dv[j] || !dd[j]) {
                fprintf(stderr, "%s: out of memory\n", PROG);
                exit(1);
            }
        }
        for (long r = 0; r < o->det_runs; r++) {
            world_start(&w, rng, drift);
            w.damage = o->damage[d];
            w.damage_t_s = (t0 + gsl_rng_uniform(rng) * 305.0) * DAY_S;
            (void)run(&w, o, t0 + 455.0, &oc);
            for (int j = 0; j < NK; j++) {
                const int k = kinds[j];
                early[j] += oc.fa[k] > 0;
                if (oc.det_veh[k] >= 0) {
                    dv[j][found[j]] = (double)oc.det_veh[k];
                    dd[j][found[j]] = oc.det_days[k];
                    found[j]++;
                }
            }
        }
        for (int j = 0; j < NK; j++) {
            qsort(dv[j], (size_t)found[j], sizeof(double), cmp_double);
            qsort(dd[j], (size_t)found[j], sizeof(double), cmp_double);
            if (found[j])
                printf("| %s | %s | %.1f %% | %ld/%ld detected (%ld runs with a false alert "
                       "before) | | %.0f | %.0f | %.2f | %.2f |\n",
                       kind_label(o, kinds[j]), dn, 100.0 * o->damage[d], found[j], o->det_runs,
                       early[j], quantile(dv[j], found[j], 0.5), quantile(dv[j], found[j], 0.95),
                       quantile(dd[j], found[j], 0.5), quantile(dd[j], found[j], 0.95));
            else
                printf("| %s | %s | %.1f %% | 0/%ld detected | | | | | |\n", kind_label(o, kinds[j]),
                       dn, 100.0 * o->damage[d], o->det_runs);
            free(dv[j]);
            free(dd[j]);
        }
        fflush(stdout);
    }
}

/* --mix-probe: how far each candidate scale estimator moves when only the
 * loaded share moves (no temperature, no damage): a baseline of 10 000
 * vehicles at share 1/2, then 400 blocks of 500 at each share; the mean and
 * SD of ln s per estimator, against ln(1 / (1 − 0.025)) = 0.0253 of a 2.5 %
 * loss. Estimators: the baseline's classes with a free share (scale.h), a
 * two-normal mixture with a free share, the median
 * of the log ratios of the deciles (block against baseline), the ratio of
 * the means, the ratio of the medians. */
static int cmp_double(const void *a, const void *b);

static double sorted_q(const double *v, int n, double q) /* linear interpolation */
{
    const double h = q * (n - 1);
    const int i = (int)floor(h);
    return i + 1 < n ? v[i] + (h - i) * (v[i + 1] - v[i]) : v[n - 1];
}

/* The rejected alternative, kept for --mix-probe: a two-normal mixture
 * fitted by EM to the baseline, then each block fitted with the same two
 * normals stretched by s and a free share (EM, closed-form M step in 1/s). */
#define EM_MAX_ITER 500
#define SD_FLOOR_KG 1.0

static double npdf(double x, double mu, double sd)
{
    const double z = (x - mu) / sd;
    return exp(-0.5 * z * z) / sd;
}

static int gauss_fit(const double *x, int n, double mu[2], double sd[2], double *pi)
{
    if (n < 4 || !x)
        return -1;
    double mean = 0.0;
    for (int i = 0; i < n; i++)
        mean += x[i];
    mean /= n;
    /* start: the halves below and above the mean */
    double s0 = 0, s1 = 0, q0 = 0, q1 = 0;
    int n0 = 0, n1 = 0;
    for (int i = 0; i < n; i++) {
        if (x[i] < mean) {
            s0 += x[i];
            n0++;
        } else {
            s1 += x[i];
            n1++;
        }
    }
    if (n0 < 2 || n1 < 2)
        return -1;
    mu[0] = s0 / n0;
    mu[1] = s1 / n1;
    for (int i = 0; i < n; i++) {
        if (x[i] < mean)
            q0 += (x[i] - mu[0]) * (x[i] - mu[0]);
        else
            q1 += (x[i] - mu[1]) * (x[i] - mu[1]);
    }
    sd[0] = sqrt(q0 / n0);
    sd[1] = sqrt(q1 / n1);
    if (!(sd[0] > SD_FLOOR_KG) || !(sd[1] > SD_FLOOR_KG))
        return -1;
    double w = (double)n1 / n, ll_old = -INFINITY;
    for (int it = 0; it < EM_MAX_ITER; it++) {
        double r_sum = 0, rx0 = 0, rx1 = 0, ll = 0;
        for (int i = 0; i < n; i++) {
            const double a = (1 - w) * npdf(x[i], mu[0], sd[0]), b = w * npdf(x[i], mu[1], sd[1]);
            const double t = a + b;
            const double r = t > 0 ? b / t : (x[i] > mu[1] ? 1.0 : 0.0);
            ll += log(t > 1e-300 ? t : 1e-300);
            r_sum += r;
            rx1 += r * x[i];
            rx0 += (1 - r) * x[i];
        }
        if (r_sum < 1.0 || r_sum > n - 1.0)
            return -1;
        const double m0 = rx0 / (n - r_sum), m1 = rx1 / r_sum;
        double v0 = 0, v1 = 0;
        for (int i = 0; i < n; i++) {
            const double a = (1 - w) * npdf(x[i], mu[0], sd[0]), b = w * npdf(x[i], mu[1], sd[1]);
            const double t = a + b;
            const double r = t > 0 ? b / t : (x[i] > mu[1] ? 1.0 : 0.0);
            v0 += (1 - r) * (x[i] - m0) * (x[i] - m0);
            v1 += r * (x[i] - m1) * (x[i] - m1);
        }
        mu[0] = m0;
        mu[1] = m1;
        sd[0] = fmax(sqrt(v0 / (n - r_sum)), SD_FLOOR_KG);
        sd[1] = fmax(sqrt(v1 / r_sum), SD_FLOOR_KG);
        w = r_sum / n;
        if (fabs(ll - ll_old) < 1e-10 * fabs(ll))
            break;
        ll_old = ll;
    }
    if (mu[0] > mu[1]) {
        double t = mu[0];
        mu[0] = mu[1];
        mu[1] = t;
        t = sd[0];
        sd[0] = sd[1];
        sd[1] = t;
        w = 1 - w;
    }
    *pi = w;
    return 0;
}

static double gauss_block_log(const double *x, int n, const double mu[2], const double sd[2],
                            double pi0, double *pi)
{
    if (n < 2 || !x)
        return NAN;
    double u = 1.0, w = pi0 > 0.01 && pi0 < 0.99 ? pi0 : 0.5;
    const double i0 = 1.0 / (sd[0] * sd[0]), i1 = 1.0 / (sd[1] * sd[1]);
    for (int it = 0; it < EM_MAX_ITER; it++) {
        double r_sum = 0, A = 0, B = 0;
        for (int i = 0; i < n; i++) {
            const double y = u * x[i];
            const double a = (1 - w) * npdf(y, mu[0], sd[0]), b = w * npdf(y, mu[1], sd[1]);
            const double t = a + b;
            const double r = t > 0 ? b / t : (y > 0.5 * (mu[0] + mu[1]) ? 1.0 : 0.0);
            r_sum += r;
            A += x[i] * x[i] * ((1 - r) * i0 + r * i1);
            B += x[i] * ((1 - r) * mu[0] * i0 + r * mu[1] * i1);
        }
        const double u_new = (B + sqrt(B * B + 4.0 * A * n)) / (2.0 * A);
        double w_new = r_sum / n;
        if (w_new < 1e-6)
            w_new = 1e-6;
        if (w_new > 1 - 1e-6)
            w_new = 1 - 1e-6;
        const int done = fabs(log(u_new / u)) < 1e-8 && fabs(w_new - w) < 1e-7;
        u = u_new;
        w = w_new;
        if (done)
            break;
    }
    if (pi)
        *pi = w;
    return -log(u);
}

static void mix_probe(const opts *o, gsl_rng *rng)
{
    enum { NB = 10000, B = 500, R = 400, NQ = 9 };
    static double base[NB], blk[B], sorted[B];
    static const double shares[] = {0.35, 0.40, 0.45, 0.50, 0.52, 0.57};
    double mu[2], sd[2], pi, qb[NQ], mean_b = 0;
    static amfi_scale_ref ref;
    static double scratch[B];
    for (int i = 0; i < NB; i++) {
        base[i] = draw_gvw(rng, 0.5) + gsl_ran_gaussian_ziggurat(rng, o->meas_sd);
        mean_b += base[i] / NB;
    }
    if (gauss_fit(base, NB, mu, sd, &pi)) {
        fprintf(stderr, "%s: mixture fit failed\n", PROG);
        exit(1);
    }
    printf("baseline mixture: empty %.0f ± %.0f kg, loaded %.0f ± %.0f kg, loaded share %.3f\n\n",
           mu[0], sd[0], mu[1], sd[1], pi);
    qsort(base, NB, sizeof(double), cmp_double);
    if (amfi_scale_ref_fit(&ref, base, NB, GVW_MU, 0.15)) {
        fprintf(stderr, "%s: class fit failed\n", PROG);
        exit(1);
    }
    for (int q = 0; q < NQ; q++)
        qb[q] = sorted_q(base, NB, 0.1 * (q + 1));
    printf("| loaded share | classes (free share, scale.h) | two-normal mixture (free share) "
           "| median of decile log ratios | ratio of means | ratio of medians |\n"
           "|---|---|---|---|---|---|\n");
    for (size_t k = 0; k < sizeof shares / sizeof shares[0]; k++) {
        double s1[5] = {0}, s2[5] = {0};
        for (int r = 0; r < R; r++) {
            double m = 0, e[5], lr[NQ];
            for (int i = 0; i < B; i++) {
                blk[i] = draw_gvw(rng, shares[k]) + gsl_ran_gaussian_ziggurat(rng, o->meas_sd);
                sorted[i] = blk[i];
                m += blk[i] / B;
            }
            qsort(sorted, B, sizeof(double), cmp_double);
            for (int q = 0; q < NQ; q++)
                lr[q] = log(sorted_q(sorted, B, 0.1 * (q + 1)) / qb[q]);
            qsort(lr, NQ, sizeof(double), cmp_double);
            e[1] = gauss_block_log(blk, B, mu, sd, pi, NULL);
            e[2] = lr[NQ / 2];
            e[3] = log(m / mean_b);
            e[4] = log(sorted_q(sorted, B, 0.5) / qb[4]);
            memcpy(scratch, blk, sizeof scratch);
            e[0] = amfi_scale_ref_block_log(&ref, scratch, B, NULL);
            for (int j = 0; j < 5; j++) {
                s1[j] += e[j];
                s2[j] += e[j] * e[j];
            }
        }
        printf("| %.2f |", shares[k]);
        for (int j = 0; j < 5; j++) {
            const double mean = s1[j] / R, var = (s2[j] - R * mean * mean) / (R - 1);
            printf(" %+.4f (SD %.4f) |", mean, var > 0 ? sqrt(var) : 0.0);
        }
        printf("\n");
    }
    printf("\nln s of a 2.5 %% stiffness loss: %+.4f\n", log(1.0 / 0.975));
}

/* --std-filter / --scale-filter: "all", or CLASSES[@MIN_KG] with CLASSES
 * comma-separated EU class names (classify/: CAR, R2 .. A33) or "trucks"
 * (every class but CAR). 0, or −1 with why. */
static int parse_filter(const char *v, filter *f, char *why, size_t whylen)
{
    filter t = {0};
    snprintf(t.text, sizeof t.text, "%s", v);
    if (!strcmp(v, "all")) {
        t.all = 1;
        *f = t;
        return 0;
    }
    char buf[64];
    if (strlen(v) >= sizeof buf) {
        snprintf(why, whylen, "longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", v);
    char *at = strchr(buf, '@');
    if (at) {
        char *end;
        *at++ = '\0';
        t.min_kg = strtod(at, &end);
        if (end == at || *end || !(t.min_kg >= 0 && t.min_kg <= 1e5)) {
            snprintf(why, whylen, "the weight after @ is not a number of kg in [0, 100000]");
            return -1;
        }
    }
    if (!buf[0] || buf[0] == ',' || buf[strlen(buf) - 1] == ',' || strstr(buf, ",,")) {
        snprintf(why, whylen, "an empty class name (names separated by single commas)");
        return -1;
    }
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int found = 0;
        for (int k = 0; k < AMFI_EU_N; k++)
            if (!strcmp(tok, amfi_eu_class_name((amfi_eu_class)k)) ||
                (!strcmp(tok, "trucks") && k != AMFI_EU_CAR)) {
                t.mask |= 1u << k;
                found = 1;
            }
        if (!found) {
            snprintf(why, whylen, "'%s' is not an EU class (CAR, R2 .. A33) or trucks", tok);
            return -1;
        }
    }
    if (!t.mask) {
        snprintf(why, whylen, "no class");
        return -1;
    }
    *f = t;
    return 0;
}

/* --population: the vehicle file, each record's EU class, the per-class split. */
static void load_population(const char *path)
{
    char err[512];
    amfi_class_params cp;
    amfi_class_params_default(&cp);
    if (amfi_traffic_read(path, &POP.recs, &POP.n, err, sizeof err) != 0 ||
        amfi_mix_classify_by_class(POP.recs, POP.n, &POP.mc, err, sizeof err) != 0) {
        fprintf(stderr, "%s: %s\n", PROG, err);
        exit(2);
    }
    POP.cls = malloc(sizeof(int) * (size_t)POP.n);
    if (!POP.cls) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        exit(1);
    }
    for (int i = 0; i < POP.n; i++) {
        amfi_classification k;
        const amfi_vehicle_rec *r = &POP.recs[i];
        POP.cls[i] = -1;
        if (amfi_classify(&cp, r->n_axles, r->spacing_m, r->axle_kg, &k, err, sizeof err) != 0) {
            fprintf(stderr, "%s: %s line %ld: %s\n", PROG, path, r->line, err);
            exit(2);
        }
        for (int c = 0; k.known && c < AMFI_EU_N; c++)
            if (!strcmp(k.name, amfi_eu_class_name((amfi_eu_class)c)))
                POP.cls[i] = c;
    }
    POP.own_share = (double)POP.mc.n_loaded / POP.n;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: %s [--seed S] [--years N] [--det-runs N] [--flow VEH_PER_DAY]\n"
            "       [--damage P1,P2,...] [--meas-sd T] [--drift on|off|both|temperature|mix]\n"
            "       [--scale-fa F] [--mix-probe] [--prior-scale F] [--truck-runs N]\n"
            "       [--std-raw] [--scale-block B] [--scale-baseline-blocks N]\n"
            "       [--scale-design D] [--baseline-n N] [--population FILE]\n"
            "       [--meas-rel F] [--std-filter F] [--scale-filter F]\n"
            "A year of traffic with the site climate and the drifting mix, watched by\n"
            "amfid's indicator engine: false alarms per healthy year, detection delays.\n"
            "  --seed S          generator seed (default 1)\n"
            "  --years N         healthy years simulated (default 20)\n"
            "  --det-runs N      detection runs per damage level (default 20)\n"
            "  --flow N          vehicles per weekday (default 2000)\n"
            "  --damage LIST     stiffness losses, fractions (default 0.025,0.05,0.10)\n"
            "  --meas-sd T       per-vehicle error, t (default 0.3)\n"
            "  --drift WHICH     temperature and mix drift on, off or both (default both);\n"
            "                    temperature or mix: only that one drifts\n"
            "  --scale-fa F      scale indicator's target false alarms a year (default: its own)\n"
            "  --mix-probe       only: how each scale estimator moves with the loaded share\n"
            "  --prior-scale F   temperature model's prior slopes × F (default 1: the\n"
            "                    simulator's own law)\n"
            "  --truck-runs N    known-truck runs a week, 1 .. 7 (default 1)\n"
            "  --std-raw         the STD and mean rules get the raw weights (default: as\n"
            "                    amfid, weights at the calibration temperature)\n"
            "  --scale-block B   the scale indicator's block (default: its own, 500)\n"
            "  --scale-baseline-blocks N  its baseline blocks (default 40)\n"
            "  --scale-design D  the stiffness loss its CUSUM is tuned for (default 0.025)\n"
            "  --baseline-n N    the STD rule's baseline, vehicles (default 10000)\n"
            "  --population FILE draw the vehicles from this file (sim_publisher's format,\n"
            "                    e.g. sim_publisher/data/population-eu.csv), loaded at\n"
            "                    each class's median (default: the normal law)\n"
            "  --meas-rel F      per-vehicle error's part proportional to GVW (default 0)\n"
            "  --std-filter F    vehicles fed to the STD and mean rules: all (default) or\n"
            "                    CLASSES[@MIN_KG], e.g. A23@25000 or trucks\n"
            "  --scale-filter F  the same for the scale indicator\n"
            "  -h, --help        this help\n"
            "  -V, --version     print the version\n",
            PROG);
}

int main(int argc, char **argv)
{
    opts o = {.seed = 1, .years = 20, .det_runs = 20, .flow = 2000, .meas_sd = 300.0,
              .n_damage = 3, .damage = {0.025, 0.05, 0.10}, .n_modes = 2, .modes = {0, DRIFT_TEMP | DRIFT_MIX},
              .prior_scale = 1.0, .truck_runs = 1, .std_comp = 1,
              .std_f = {.all = 1, .text = "all"}, .scale_f = {.all = 1, .text = "all"}};
    enum {
        O_SEED = 256, O_YEARS, O_DET_RUNS, O_FLOW, O_DAMAGE, O_MEAS_SD, O_DRIFT, O_SCALE_FA,
        O_MIX_PROBE, O_PRIOR_SCALE, O_TRUCK_RUNS, O_STD_RAW, O_SCALE_BLOCK, O_SCALE_BLOCKS,
        O_SCALE_DESIGN, O_BASELINE_N, O_POPULATION, O_MEAS_REL, O_STD_FILTER, O_SCALE_FILTER
    };
    static const struct option longopts[] = {
        {"seed", required_argument, NULL, O_SEED},
        {"years", required_argument, NULL, O_YEARS},
        {"det-runs", required_argument, NULL, O_DET_RUNS},
        {"flow", required_argument, NULL, O_FLOW},
        {"damage", required_argument, NULL, O_DAMAGE},
        {"meas-sd", required_argument, NULL, O_MEAS_SD},
        {"drift", required_argument, NULL, O_DRIFT},
        {"scale-fa", required_argument, NULL, O_SCALE_FA},
        {"mix-probe", no_argument, NULL, O_MIX_PROBE},
        {"prior-scale", required_argument, NULL, O_PRIOR_SCALE},
        {"truck-runs", required_argument, NULL, O_TRUCK_RUNS},
        {"std-raw", no_argument, NULL, O_STD_RAW},
        {"scale-block", required_argument, NULL, O_SCALE_BLOCK},
        {"scale-baseline-blocks", required_argument, NULL, O_SCALE_BLOCKS},
        {"scale-design", required_argument, NULL, O_SCALE_DESIGN},
        {"baseline-n", required_argument, NULL, O_BASELINE_N},
        {"population", required_argument, NULL, O_POPULATION},
        {"meas-rel", required_argument, NULL, O_MEAS_REL},
        {"std-filter", required_argument, NULL, O_STD_FILTER},
        {"scale-filter", required_argument, NULL, O_SCALE_FILTER},
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
        case O_SCALE_FA: o.scale_fa = amfi_cli_num(&c, v, 1e-4, 1000); break;
        case O_MIX_PROBE: o.mix_probe = 1; break;
        case O_STD_RAW: o.std_comp = 0; break;
        case O_SCALE_BLOCK: o.scale_block = (int)amfi_cli_integer(&c, v, 50, 1e6); break;
        case O_SCALE_BLOCKS: o.scale_blocks = (int)amfi_cli_integer(&c, v, 4, 1e5); break;
        case O_SCALE_DESIGN: o.scale_design = amfi_cli_num(&c, v, 1e-3, 0.49); break;
        case O_BASELINE_N: o.baseline_n = (int)amfi_cli_integer(&c, v, 10, 1e6); break;
        case O_POPULATION: o.population = v; break;
        case O_MEAS_REL: o.meas_rel = amfi_cli_num(&c, v, 0, 0.5); break;
        case O_STD_FILTER:
        case O_SCALE_FILTER: {
            char why[128];
            if (parse_filter(v, k == O_STD_FILTER ? &o.std_f : &o.scale_f, why, sizeof why))
                amfi_cli_fail(&c, "%s '%s': %s",
                              k == O_STD_FILTER ? "--std-filter" : "--scale-filter",
                              amfi_cli_shown(v), why);
            break;
        }
        case O_PRIOR_SCALE: o.prior_scale = amfi_cli_num(&c, v, 0, 5); break;
        case O_TRUCK_RUNS: o.truck_runs = (int)amfi_cli_integer(&c, v, 1, 7); break;
        case O_DRIFT:
            o.n_modes = 1;
            if (!strcmp(v, "both"))
                o.n_modes = 2; /* off, then on */
            else if (!strcmp(v, "on"))
                o.modes[0] = DRIFT_TEMP | DRIFT_MIX;
            else if (!strcmp(v, "off"))
                o.modes[0] = 0;
            else if (!strcmp(v, "temperature"))
                o.modes[0] = DRIFT_TEMP;
            else if (!strcmp(v, "mix"))
                o.modes[0] = DRIFT_MIX;
            else
                amfi_cli_fail(&c, "'%s' is not on, off, both, temperature or mix",
                              amfi_cli_shown(v));
            if (o.n_modes == 2) {
                o.modes[0] = 0;
                o.modes[1] = DRIFT_TEMP | DRIFT_MIX;
            }
            break;
        }
    }
    if (o.population)
        load_population(o.population);
    if ((!o.std_f.all || !o.scale_f.all) && !o.population)
        amfi_cli_fail(&c, "a class filter needs --population (the normal law has no classes)");
    if (filter_fraction(&o.std_f) <= 0.0 || filter_fraction(&o.scale_f) <= 0.0)
        amfi_cli_fail(&c, "no vehicle of %s passes the filter", o.population);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng)
        return 1;
    gsl_rng_set(rng, o.seed);
    const clock_t c0 = clock();
    if (o.mix_probe) {
        mix_probe(&o, rng);
        gsl_rng_free(rng);
        return 0;
    }
    printf("| indicator | drift | damage | runs | false alarms | median delay (vehicles; "
           "known_truck: runs) | p95 (vehicles; runs) | median delay (days) | p95 (days) |\n"
           "|---|---|---|---|---|---|---|---|---|\n");
    for (int m = 0; m < o.n_modes; m++)
        evaluate(&o, rng, o.modes[m]);
    fprintf(stderr, "%s: %.1f s CPU\n", PROG, (double)(clock() - c0) / CLOCKS_PER_SEC);
    gsl_rng_free(rng);
    free(POP.cls);
    amfi_mix_classes_free(&POP.mc);
    amfi_traffic_free(POP.recs);
    return 0;
}
