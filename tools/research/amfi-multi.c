/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * amfi-multi: the joint solve of two vehicles on the span, measured (issue 13).
 *
 *   amfi-multi [--events N] [--seed S] [--noise FRACTION] [--min-headway S]
 *              [--alone] [--loose] [--lambda-factor F] [--quarter]
 *              [--population FILE.csv [--min-gap M]] [--mid-only] [--noise-free]
 *              [--entry-shift S] [--dump DIR]
 *              [--config FILE.yaml]
 *
 * Each event: two half-cars (GVW 10..40 t, front axle share 0.35..0.6,
 * spacing 3.5..6 m, Table 2 properties drawn) on one lane at the same speed
 * (20..30 m/s), the second entering while the first is on the span (delay
 * between the front axles uniform from --min-headway, default 0.5 s as
 * sim_publisher's simulation.stream.min_headway_s, to the first's time on
 * the span; round one drew it from 0.15 s, which puts the follower's front
 * axle on or ahead of the leader's rear axle: vehicles that overlap),
 * simulated together
 * in the coupled vehicle-bridge model (sim_publisher/vbi.c) over an ISO 8608
 * class A road, recorded at the quarter, mid and three-quarter points. Each
 * event is solved jointly (amfi_solve_multi, speeds and spacings exact) from
 * the mid-span sensor alone and from all three, with no noise and with
 * --noise × the record's RMS of Gaussian noise (default 0.02).
 * Truth: each vehicle's mean contact forces while its axles are on the span.
 *
 * stdout: one CSV row per vehicle and condition (sensors, noise, event,
 * vehicle, delay_s, truth_kg, gvw_kg, err, quality, then the geometry:
 * speed, the vehicle's axle spacing, the gap from the leader's rear axle to
 * the follower's front axle, the vehicle's time on the span and the share of
 * it the other is on the span too, and truth and inferred per axle), then
 * '#' lines with the
 * summary per condition: mean abs and worst error per vehicle and of the
 * pair's sum, and how many of the largest errors (top decile) fall in the
 * worst decile by quality; with --alone, the same vehicles simulated and
 * solved one at a time (the single-vehicle reference on the same pairs).
 * --loose (round five) solves every pair once more at a tenth of λ (the
 * quality figure's sweep, here as a whole solve) and appends each vehicle's
 * loose axle loads and both solves' time to the rows (the direction the data
 * leave open, for the figures and the split prior measured offline);
 * --lambda-factor F solves the pairs at λ·F (amfi_multi_passage.lambda_factor;
 * the loose solve then at λ·F/10; without it, the library's default: pairs
 * weighed at λ/10 since round six, so rounds one to five's figures need
 * --lambda-factor 1); --quarter makes the one-sensor solve use
 * the quarter-point sensor (which sees mode 2, antisymmetric, that the
 * mid-span one does not).
 *
 * --population FILE (issue 26) draws the pair from a WIM population
 * instead (sim_publisher/data/population-eu.csv: rigid and articulated
 * trucks of 2-6 axles, the models of sim_publisher/vclass.c): two records
 * drawn uniformly, both at the leader's speed, the follower's front axle
 * entering while the leader is on the span and at least --min-gap m
 * (default 4: overhangs) behind the leader's last axle; the rows then carry
 * the class, the axle count and every axle (';'-separated lists) in place
 * of the two axle columns. --mid-only solves from the mid-span sensor
 * only (with and without noise; the condition is the first);
 * --noise-free skips the noisy conditions (their draws too, so the events
 * differ from a run with them); --entry-shift S gives the solver the
 * follower's entry S s late (the simulation is unchanged: where it falls on
 * the calculation grid). --dump DIR writes each event's
 * mid-span record as DIR/eN.csv (t,accel on the event's clock) and one line
 * per event to DIR/events.txt: the event, each vehicle's truth, and the
 * amfi-solve --vehicle arguments that solve the record with the same
 * configuration (the cross-check that the tool weighs as the library does).
 *
 * Single-threaded; everything is created once and freed at the end.
 */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "amfi/amfi.h"
#include "amfi_cli.h"
#include "amfi_config.h"
#include "amfi_datafile.h"
#include "passage.h"
#include "profile.h"
#include "traffic.h"
#include "vbi.h"
#include "vclass.h"
#include "vehicle.h"

#define PROG "amfi-multi"

static void usage(FILE *f)
{
    fprintf(f, "usage: " PROG " [--events N] [--seed S] [--noise FRACTION] [--min-headway S]\n"
               "       [--alone] [--loose] [--lambda-factor F] [--quarter] [--config FILE]\n"
               "  -n, --events N      events (vehicle pairs), 10 .. 100000 (default 100)\n"
               "  -s, --seed S        random seed (default 1)\n"
               "  -z, --noise F       noise std as a fraction of the record's RMS (0.02)\n"
               "  -m, --min-headway S least delay between the front axles, s, 0.05 .. 5 (0.5)\n"
               "  -a, --alone         also simulate and solve each vehicle without the other\n"
               "  -l, --loose         also solve each pair at λ/10: loose axle loads and the\n"
               "                      solves' times as extra columns\n"
               "  -f, --lambda-factor F  pairs solved at λ·F (amfi_multi_passage.lambda_factor),\n"
               "                      1e-4 .. 1 (default: the library's, λ/10 for pairs\n"
               "                      with the quality from λ; 1: λ, as before round six)\n"
               "  -q, --quarter       the one-sensor solves (pairs and --alone) from the\n"
               "                      quarter-point sensor instead of the mid-span one\n"
               "  -p, --population F  draw the pairs from a WIM population (multi-axle trucks)\n"
               "  -g, --min-gap M     with --population: least gap from the leader's last axle\n"
               "                      to the follower's first, m, 0 .. 50 (default 4)\n"
               "  -1, --mid-only      only the one-sensor (mid-span) conditions\n"
               "  -0, --noise-free    no noisy conditions (and no noise draws)\n"
               "  -e, --entry-shift S the follower's entry S s late in the solve, |S| <= 0.01\n"
               "  -d, --dump DIR      each event's mid-span record and amfi-solve arguments\n"
               "  -c, --config FILE   site configuration (default paper-20m.yaml)\n"
               "  -h, --help          this help\n"
               "  -V, --version       print the version\n");
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void die(const char *what, const char *err)
{
    fprintf(stderr, PROG ": %s: %s\n", what, err);
    exit(1);
}

typedef struct row {
    double err, q, gap;
} row;

static int by_abs_err(const void *a, const void *b)
{
    double x = fabs(((const row *)a)->err), y = fabs(((const row *)b)->err);
    return (x < y) - (x > y); /* descending */
}

static int by_q(const void *a, const void *b)
{
    double x = ((const row *)a)->q, y = ((const row *)b)->q;
    return (x < y) - (x > y); /* descending */
}

/* Summary of one condition: n vehicle errors with their qualities, n/2 sums. */
static void summary(const char *cond, row *v, int n, const double *sum, int ns)
{
    double ma = 0, mx = 0, sa = 0, sx = 0;
    for (int i = 0; i < n; i++) {
        ma += fabs(v[i].err);
        mx = fmax(mx, fabs(v[i].err));
    }
    for (int i = 0; i < ns; i++) {
        sa += fabs(sum[i]);
        sx = fmax(sx, fabs(sum[i]));
    }
    /* by the gap between the vehicles' nearest axles: under 3 m two trucks'
     * overhangs would overlap */
    int nc[2] = {0, 0};
    double mc[2] = {0, 0}, xc[2] = {0, 0};
    for (int i = 0; i < n; i++) {
        int k = v[i].gap >= 3.0;
        nc[k]++;
        mc[k] += fabs(v[i].err);
        xc[k] = fmax(xc[k], fabs(v[i].err));
    }
    for (int k = 0; k < 2; k++)
        if (nc[k])
            printf("# %s: gap %s 3 m: %d vehicles, mean abs %.2f %%, worst %.2f %%\n", cond,
                   k ? ">=" : "<", nc[k], 100 * mc[k] / nc[k], 100 * xc[k]);
    /* the largest errors (top decile) against the worst decile by quality */
    int d = n / 10 > 0 ? n / 10 : 1;
    qsort(v, n, sizeof *v, by_abs_err);
    double thr = fabs(v[d - 1].err);
    qsort(v, n, sizeof *v, by_q);
    int hit = 0;
    for (int i = 0; i < d; i++)
        hit += fabs(v[i].err) >= thr;
    printf("# %s: each vehicle mean abs %.2f %%, worst %.2f %%; sum of the pair mean abs "
           "%.2f %%, worst %.2f %%; the worst decile by quality holds %d of the %d largest "
           "errors (>= %.2f %%)\n",
           cond, 100 * ma / n, 100 * mx, 100 * sa / ns, 100 * sx, hit, d, 100 * thr);
}

/* The event's mid-span record and the amfi-solve arguments for it (--dump). */
static void dump_event(const char *dir, int e, const double *acc, int n, int stride,
                       double rate, const double *entry, double v, const int *nax,
                       double sp[2][AMFI_MAX_AXLES], const double *truth, const char **cls)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/e%d.csv", dir, e);
    FILE *f = fopen(path, "w");
    if (!f)
        die(path, "cannot be written");
    fprintf(f, "t,accel\n");
    for (int k = 0; k < n; k++)
        fprintf(f, "%.6f,%.9g\n", k / rate, acc[(size_t)k * stride]);
    if (fclose(f) != 0)
        die(path, "cannot be written");
    snprintf(path, sizeof path, "%s/events.txt", dir);
    f = fopen(path, e == 0 ? "w" : "a");
    if (!f)
        die(path, "cannot be written");
    fprintf(f, "%d %.1f %.1f %s %s", e, truth[0], truth[1], cls[0], cls[1]);
    for (int i = 0; i < 2; i++) {
        fprintf(f, " --vehicle %.6f:%.6f:", entry[i], v);
        for (int a = 0; a + 1 < nax[i]; a++)
            fprintf(f, "%s%.6f", a ? "," : "", sp[i][a]);
    }
    fprintf(f, "\n");
    if (fclose(f) != 0)
        die(path, "cannot be written");
}

static void print_list(const double *x, int n)
{
    for (int a = 0; a < n; a++)
        printf("%s%.1f", a ? ";" : "", x[a]);
}

int main(int argc, char **argv)
{
    static const struct option longopts[] = {{"events", required_argument, NULL, 'n'},
                                              {"seed", required_argument, NULL, 's'},
                                              {"noise", required_argument, NULL, 'z'},
                                              {"min-headway", required_argument, NULL, 'm'},
                                              {"alone", no_argument, NULL, 'a'},
                                              {"loose", no_argument, NULL, 'l'},
                                              {"lambda-factor", required_argument, NULL, 'f'},
                                              {"quarter", no_argument, NULL, 'q'},
                                              {"population", required_argument, NULL, 'p'},
                                              {"min-gap", required_argument, NULL, 'g'},
                                              {"mid-only", no_argument, NULL, '1'},
                                              {"dump", required_argument, NULL, 'd'},
                                              {"noise-free", no_argument, NULL, '0'},
                                              {"entry-shift", required_argument, NULL, 'e'},
                                              {"config", required_argument, NULL, 'c'},
                                              AMFI_CLI_END};
    int n_events = 100;
    unsigned long seed = 1;
    double noise = 0.02, min_headway = 0.5, lambda_factor = 0.0, min_gap = 4.0;
    int alone = 0, loose = 0, quarter = 0, mid_only = 0, noise_free = 0;
    double entry_shift = 0.0;
    const char *config = NULL, *population = NULL, *dump = NULL;
    amfi_cli c;
    amfi_cli_init(&c, PROG, argc, argv, longopts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'a': alone = 1; break;
        case 'l': loose = 1; break;
        case 'q': quarter = 1; break;
        case '1': mid_only = 1; break;
        case '0': noise_free = 1; break;
        case 'e': entry_shift = amfi_cli_num(&c, optarg, -0.01, 0.01); break;
        case 'f': lambda_factor = amfi_cli_num(&c, optarg, 1e-4, 1); break;
        case 'n': n_events = (int)amfi_cli_integer(&c, optarg, 10, 100000); break;
        case 's': seed = (unsigned long)amfi_cli_integer(&c, optarg, 0, 4294967295.0); break;
        case 'z': noise = amfi_cli_num(&c, optarg, 0, 1); break;
        case 'm': min_headway = amfi_cli_num(&c, optarg, 0.05, 5); break;
        case 'g': min_gap = amfi_cli_num(&c, optarg, 0, 50); break;
        case 'p': population = optarg; break;
        case 'd': dump = optarg; break;
        case 'c': config = optarg; break;
        }
    }
    amfi_set_blas_threads(1);
    char err[512], found[4096];
    static amfi_site_config cfg;
    if (!config && amfi_datafile_find("paper-20m.yaml", found, sizeof found) == 0)
        config = found;
    if (!config)
        amfi_config_defaults(&cfg);
    else if (amfi_config_load(config, &cfg, err, sizeof err) != 0)
        die("config", err);
    cfg.bridge.damage = 0.0;
    amfi_vehicle_rec *recs = NULL;
    int n_recs = 0;
    if (population && amfi_traffic_read(population, &recs, &n_recs, err, sizeof err))
        die("--population", err);
    if (population && (loose || quarter))
        die("--population", "not with --loose or --quarter");
    const double L = cfg.bridge.span_m;
    amfi_bridge *bridge;
    if (amfi_bridge_create(&cfg.bridge, &bridge, err, sizeof err))
        die("bridge", err);
    amfi_sim_params sp;
    amfi_sim_params_default(&sp, L);
    sp.n_sensors = 3;
    sp.sensor_x_m[0] = 0.5 * L;
    sp.sensor_x_m[1] = 0.25 * L;
    sp.sensor_x_m[2] = 0.75 * L;
    amfi_profile_params pp;
    amfi_profile_params_default(&pp);
    pp.iso_class = 'A';
    pp.seed = seed;
    pp.length_m = sp.approach_m + AMFI_SIM_PROFILE_LEAD_M + L + 100.0;
    amfi_profile *prof;
    if (amfi_profile_create(&pp, &prof, err, sizeof err))
        die("profile", err);
    amfi_solver *solver[2];
    for (int k = 0; k < 2; k++) {
        amfi_solver_params p = cfg.solver;
        p.n_sensors = k ? 3 : 1;
        for (int i = 0; i < p.n_sensors; i++) {
            p.sensor_x_m[i] = sp.sensor_x_m[k == 0 && quarter ? 1 : i];
            p.sensor_weight[i] = 1.0;
        }
        p.max_axles = population ? AMFI_MAX_AXLES : 4;
        p.max_duration_s = 3.0;
        if (amfi_solver_create(bridge, &p, &solver[k], err, sizeof err))
            die("solver", err);
    }
    amfi_lambda lam = cfg.lambda;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    amfi_halfcar_dist dist;
    amfi_halfcar_dist_paper(&dist);
    const int cap = (int)(sp.scan_rate_hz * 12.0);
    double *acc = malloc(sizeof(double) * cap * 3), *noisy = malloc(sizeof(double) * cap * 3);
    double *ch[2][3];
    for (int i = 0; i < 3; i++) {
        ch[0][i] = malloc(sizeof(double) * cap);
        ch[1][i] = malloc(sizeof(double) * cap);
    }
    double *alone_err[2], *alone_kg[2], *alone_truth[2];
    for (int k = 0; k < 2; k++) {
        alone_err[k] = calloc(2 * (size_t)n_events, sizeof(double));
        alone_kg[k] = calloc(2 * (size_t)n_events, sizeof(double));
        alone_truth[k] = calloc(2 * (size_t)n_events, sizeof(double));
        if (!alone_err[k] || !alone_kg[k] || !alone_truth[k])
            die("memory", "out of memory");
    }
    row *rows[4];
    double *sums[4];
    for (int k = 0; k < 4; k++) {
        rows[k] = malloc(sizeof(row) * 2 * n_events);
        sums[k] = malloc(sizeof(double) * n_events);
    }
    if (!acc || !noisy)
        die("memory", "out of memory");
    if (population)
        printf("sensors,noise,event,vehicle,delay_s,truth_kg,gvw_kg,err,quality,speed_mps,"
               "length_m,gap_m,on_span_s,shared,class,n_axles,truth_axles_kg,axles_kg,"
               "pair_err%s\n", alone ? ",alone_err" : "");
    else
        printf("sensors,noise,event,vehicle,delay_s,truth_kg,gvw_kg,err,quality,speed_mps,"
               "spacing_m,gap_m,on_span_s,shared,truth_axle1_kg,truth_axle2_kg,axle1_kg,"
               "axle2_kg%s\n",
               loose ? ",loose_axle1_kg,loose_axle2_kg,solve_ms,loose_ms" : "");
    amfi_lambda lam_loose = lam;
    lam_loose.lambda_ref *= AMFI_MULTI_QUALITY_LAMBDA;
    if (loose && lam.automatic)
        die("--loose", "needs a fixed λ in the configuration");
    for (int e = 0; e < n_events; e++) {
        amfi_sim *sim;
        if (amfi_sim_create(bridge, prof, &sp, &sim, err, sizeof err))
            die("simulation", err);
        double v;
        amfi_sim_vehicle veh[2];
        double entry[2], spacing[2][AMFI_MAX_AXLES], len[2];
        int nax[2];
        const char *cls[2] = {"R2", "R2"};
        int track = amfi_profile_tracks(prof) / 2;
        if (population) {
            const amfi_vehicle_rec *rec[2];
            for (int i = 0; i < 2; i++)
                rec[i] = &recs[gsl_rng_uniform_int(rng, (unsigned long)n_recs)];
            v = rec[0]->speed_mps;
            for (int i = 0; i < 2; i++) {
                amfi_passage_spec ps;
                if (amfi_passage_spec_from_rec(rec[i], &dist, NULL, 0.0, rng, &ps, err,
                                               sizeof err))
                    die("vehicle", err);
                memset(&veh[i], 0, sizeof veh[i]);
                veh[i].car = ps.car;
                veh[i].truck = ps.truck;
                nax[i] = rec[i]->n_axles;
                len[i] = 0.0;
                for (int a = 0; a + 1 < nax[i]; a++) {
                    spacing[i][a] = rec[i]->spacing_m[a];
                    len[i] += spacing[i][a];
                }
                const amfi_vclass *vc = amfi_vclass_get(rec[i]->vclass);
                cls[i] = vc ? vc->name : "R2";
            }
        } else {
            v = gsl_ran_flat(rng, 20.0, 30.0);
            for (int i = 0; i < 2; i++) {
                double gvw = gsl_ran_flat(rng, 10000.0, 40000.0);
                double share = gsl_ran_flat(rng, 0.35, 0.6);
                spacing[i][0] = gsl_ran_flat(rng, 3.5, 6.0);
                len[i] = spacing[i][0];
                nax[i] = 2;
                memset(&veh[i], 0, sizeof veh[i]);
                if (amfi_halfcar_from_weights(gvw, share * gvw, (1 - share) * gvw,
                                              spacing[i][0], &dist, rng, &veh[i].car, err,
                                              sizeof err))
                    die("vehicle", err);
            }
        }
        for (int i = 0; i < 2; i++) {
            veh[i].id = i;
            veh[i].speed_mps = v;
            veh[i].track = track;
        }
        double on1 = (L + len[0]) / v;
        /* the follower's front axle at least min_gap behind the leader's
         * last axle (population pairs: trucks up to 16.5 m long) */
        double lo = population ? fmax(min_headway, (len[0] + min_gap) / v) : min_headway;
        if (lo >= on1)
            die("--min-headway", "longer than a vehicle's time on the span");
        double delay = gsl_ran_flat(rng, lo, on1);
        entry[0] = sp.approach_m / v + 0.5;
        entry[1] = entry[0] + delay;
        for (int i = 0; i < 2; i++) {
            veh[i].t_entry_s = entry[i];
            if (amfi_sim_add(sim, &veh[i], err, sizeof err))
                die("simulation", err);
        }
        double t_end = entry[1] + (L + len[1]) / v + 0.5;
        int n = (int)(t_end * sp.scan_rate_hz) + 1;
        if (n > cap)
            die("simulation", "record longer than the buffer");
        if (amfi_sim_advance(sim, n, acc, err, sizeof err))
            die("simulation", err);
        double truth[2] = {NAN, NAN}, truth_ax[2][AMFI_MAX_AXLES];
        double scratch[AMFI_MAX_SENSORS];
        for (int guard = 0; guard < 100000 && amfi_sim_busy(sim); guard++)
            if (amfi_sim_advance(sim, 1, scratch, err, sizeof err))
                die("simulation", err);
        amfi_sim_vehicle d;
        while (amfi_sim_pop_done(sim, &d)) {
            truth[d.id] = 0.0;
            for (int a = 0; a < nax[d.id]; a++) {
                truth_ax[d.id][a] = d.mean_force_N[a] / AMFI_GRAVITY;
                truth[d.id] += truth_ax[d.id][a];
            }
        }
        amfi_sim_destroy(sim);
        if (!isfinite(truth[0]) || !isfinite(truth[1]))
            die("simulation", "a vehicle did not leave");
        if (dump)
            dump_event(dump, e, acc, n, 3, sp.scan_rate_hz, entry, v, nax, spacing, truth, cls);
        /* --alone: each vehicle of the pair simulated and solved without the
         * other (same road, entry and speed; no noise, no random draws, so
         * the pairs stay the same) */
        for (int i = 0; alone && i < 2; i++) {
            if (amfi_sim_create(bridge, prof, &sp, &sim, err, sizeof err))
                die("simulation", err);
            if (amfi_sim_add(sim, &veh[i], err, sizeof err))
                die("simulation", err);
            if (amfi_sim_advance(sim, n, noisy, err, sizeof err))
                die("simulation", err);
            for (int guard = 0; guard < 100000 && amfi_sim_busy(sim); guard++)
                if (amfi_sim_advance(sim, 1, scratch, err, sizeof err))
                    die("simulation", err);
            double t1 = NAN;
            while (amfi_sim_pop_done(sim, &d)) {
                t1 = 0.0;
                for (int a = 0; a < nax[i]; a++)
                    t1 += d.mean_force_N[a] / AMFI_GRAVITY;
            }
            amfi_sim_destroy(sim);
            if (!isfinite(t1))
                die("simulation", "a vehicle did not leave");
            for (int k = 0; k < 2; k++) {
                if (mid_only && k) {
                    alone_err[1][2 * e + i] = alone_kg[1][2 * e + i] = NAN;
                    alone_truth[1][2 * e + i] = NAN;
                    continue;
                }
                amfi_multi_passage mp;
                memset(&mp, 0, sizeof mp);
                mp.n_samples = n;
                mp.scan_rate_hz = sp.scan_rate_hz;
                for (int c3 = 0; c3 < 3; c3++) {
                    for (int j = 0; j < n; j++)
                        ch[1][c3][j] = noisy[j * 3 + c3];
                    mp.accel[c3] = ch[1][c3];
                }
                if (k == 0 && quarter)
                    mp.accel[0] = ch[1][1];
                mp.n_vehicles = 1;
                mp.vehicle[0].entry_s = entry[i];
                mp.vehicle[0].speed_mps = v;
                mp.vehicle[0].n_axles = nax[i];
                for (int a = 0; a + 1 < nax[i]; a++)
                    mp.vehicle[0].axle_spacing_m[a] = spacing[i][a];
                static amfi_multi_result r;
                if (amfi_solve_multi(solver[k], &mp, &lam, &r, err, sizeof err))
                    die("solve", err);
                alone_err[k][2 * e + i] = r.vehicle[0].gvw_kg / t1 - 1.0;
                alone_kg[k][2 * e + i] = r.vehicle[0].gvw_kg;
                alone_truth[k][2 * e + i] = t1;
            }
        }
        for (int z = 0; z < 2 - noise_free; z++) {
            double rms[3] = {0, 0, 0};
            for (int i = 0; i < 3; i++) {
                for (int k = 0; k < n; k++)
                    rms[i] += acc[k * 3 + i] * acc[k * 3 + i];
                rms[i] = sqrt(rms[i] / n);
                for (int k = 0; k < n; k++)
                    ch[z][i][k] = acc[k * 3 + i] +
                                  (z ? gsl_ran_gaussian(rng, noise * rms[i]) : 0.0);
            }
            for (int k = 0; k < 2; k++) {
                if (mid_only && k)
                    continue;
                amfi_multi_passage mp;
                memset(&mp, 0, sizeof mp);
                mp.n_samples = n;
                mp.scan_rate_hz = sp.scan_rate_hz;
                mp.t_first_s = 0.0;
                for (int i = 0; i < 3; i++)
                    mp.accel[i] = ch[z][i];
                if (k == 0 && quarter)
                    mp.accel[0] = ch[z][1];
                mp.n_vehicles = 2;
                for (int i = 0; i < 2; i++) {
                    mp.vehicle[i].entry_s = entry[i] + (i ? entry_shift : 0.0);
                    mp.vehicle[i].speed_mps = v;
                    mp.vehicle[i].n_axles = nax[i];
                    for (int a = 0; a + 1 < nax[i]; a++)
                        mp.vehicle[i].axle_spacing_m[a] = spacing[i][a];
                }
                mp.lambda_factor = lambda_factor;
                static amfi_multi_result r, rl;
                double t0 = now_s();
                if (amfi_solve_multi(solver[k], &mp, &lam, &r, err, sizeof err))
                    die("solve", err);
                double t1 = now_s();
                if (loose && amfi_solve_multi(solver[k], &mp, &lam_loose, &rl, err, sizeof err))
                    die("solve", err);
                double t2 = now_s();
                int cond = 2 * k + z;
                /* geometry: gap from the leader's rear axle to the follower's
                 * front axle (same speed: constant), each vehicle's time on
                 * the span and the share of it the other one is on too */
                double gap = v * delay - len[0];
                double on[2] = {(L + len[0]) / v, (L + len[1]) / v};
                double both = fmin(entry[0] + on[0], entry[1] + on[1]) - entry[1];
                sums[cond][e] = r.total_gvw_kg / (truth[0] + truth[1]) - 1.0;
                for (int i = 0; i < 2; i++) {
                    double ev = r.vehicle[i].gvw_kg / truth[i] - 1.0;
                    rows[cond][2 * e + i] = (row){ev, r.vehicle[i].quality, gap};
                    printf("%d,%g,%d,%d,%.4f,%.1f,%.1f,%.6f,%.4f,%.2f,%.3f,%.3f,%.4f,%.3f,",
                           k ? 3 : 1, z ? noise : 0.0, e, i + 1, delay, truth[i],
                           r.vehicle[i].gvw_kg, ev, r.vehicle[i].quality, v, len[i], gap,
                           on[i], both / on[i]);
                    if (population) {
                        printf("%s,%d,", cls[i], nax[i]);
                        print_list(truth_ax[i], nax[i]);
                        printf(",");
                        print_list(r.vehicle[i].axle_kg, nax[i]);
                        printf(",%.6f", sums[cond][e]);
                        if (alone)
                            printf(",%.6f", alone_err[k][2 * e + i]);
                    } else {
                        printf("%.1f,%.1f,%.1f,%.1f", truth_ax[i][0], truth_ax[i][1],
                               r.vehicle[i].axle_kg[0], r.vehicle[i].axle_kg[1]);
                    }
                    if (loose)
                        printf(",%.1f,%.1f,%.3f,%.3f", rl.vehicle[i].axle_kg[0],
                               rl.vehicle[i].axle_kg[1], 1e3 * (t1 - t0), 1e3 * (t2 - t1));
                    printf("\n");
                }
            }
        }
        fflush(stdout);
    }
    const char *names[4] = {"1 sensor, no noise", "1 sensor, noise", "3 sensors, no noise",
                            "3 sensors, noise"};
    for (int k = 0; k < 4; k++) {
        if ((mid_only && k >= 2) || (noise_free && (k & 1)))
            continue;
        char name[96];
        snprintf(name, sizeof name, "%s", names[k]);
        if (k & 1)
            snprintf(name, sizeof name, "%s %.0f %%", names[k], 100 * noise);
        summary(name, rows[k], 2 * n_events, sums[k], n_events);
    }
    for (int k = 0; k < 4; k++) {
        free(rows[k]);
        free(sums[k]);
    }
    for (int k = 0; alone && k < (mid_only ? 1 : 2); k++) {
        double ma = 0, mx = 0, sa = 0, sx = 0;
        for (int i = 0; i < 2 * n_events; i++) {
            ma += fabs(alone_err[k][i]);
            mx = fmax(mx, fabs(alone_err[k][i]));
        }
        for (int e = 0; e < n_events; e++) {
            double se = (alone_kg[k][2 * e] + alone_kg[k][2 * e + 1]) /
                            (alone_truth[k][2 * e] + alone_truth[k][2 * e + 1]) -
                        1.0;
            sa += fabs(se);
            sx = fmax(sx, fabs(se));
        }
        printf("# %s, each vehicle alone (no noise): mean abs %.2f %%, worst %.2f %%; sum of "
               "the two solved alone mean abs %.2f %%, worst %.2f %%\n",
               k ? "3 sensors" : "1 sensor", 50 * ma / n_events, 100 * mx, 100 * sa / n_events,
               100 * sx);
    }
    for (int k = 0; k < 2; k++)
        free(alone_err[k]), free(alone_kg[k]), free(alone_truth[k]);
    for (int i = 0; i < 3; i++)
        free(ch[0][i]), free(ch[1][i]);
    free(acc), free(noisy);
    gsl_rng_free(rng);
    for (int k = 0; k < 2; k++)
        amfi_solver_destroy(solver[k]);
    amfi_profile_destroy(prof);
    amfi_bridge_destroy(bridge);
    amfi_traffic_free(recs);
    return 0;
}
