/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_multi.c: unit tests of amfi_solve_multi (several vehicles on the span
 * solved jointly, issue 13) against prescribed moving forces (constant, and
 * bouncing for the quality figure) put through the independent Newmark
 * forward integrator, on the paper-20m
 * bridge, at one sensor (mid-span) and three (quarter, mid, three-quarter).
 * Each tolerance says why it is what it is.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "amfi/amfi.h"
#include "paper20_fixture.h"

#define SPEED 25.0 /* every vehicle (the forward integrator has one speed) */
#define RATE 1000.0

static const double sensors[3] = {10.0, 5.0, 15.0}; /* mid-span first */

/* An event: vehicles with entry times, spacings and constant axle forces. */
typedef struct event {
    amfi_multi_passage p;
    double force_N[AMFI_MAX_EVENT_AXLES]; /* all axles, vehicle by vehicle */
    int na;
    double *accel[3];
} event;

static double const_force(double t, int a, void *user)
{
    (void)t;
    return ((const double *)user)[a];
}

/* Record the event at ns sensors from t = t0 (the bridge at rest, no axle on
 * it) to the last exit + 0.05 s; the clock of entry_s is shifted by t0. */
static void record(event *ev, int ns, double t0)
{
    double off[AMFI_MAX_EVENT_AXLES];
    int i = 0;
    for (int v = 0; v < ev->p.n_vehicles; v++) {
        const amfi_vehicle *ve = &ev->p.vehicle[v];
        double o = SPEED * ve->entry_s;
        for (int a = 0; a < ve->n_axles; a++, i++) {
            if (a > 0)
                o += ve->axle_spacing_m[a - 1];
            off[i] = o;
        }
    }
    ev->na = i;
    amfi_passage_times w = amfi_multi_window(20.0, &ev->p, 0.0, 0.0);
    assert_true(w.start_s >= 0.0);
    int n = (int)((w.end_s + 0.05) * RATE) + 1;
    double *all = malloc(sizeof(double) * n * ns);
    char err[256];
    assert_int_equal(amfi_forward_newmark(bridge, SPEED, ev->na, off, const_force, ev->force_N,
                                          ns, sensors, 2e-5, RATE, n, all, err, sizeof err),
                     0);
    for (int s = 0; s < ns; s++) {
        ev->accel[s] = malloc(sizeof(double) * n);
        for (int k = 0; k < n; k++)
            ev->accel[s][k] = all[k * ns + s];
        ev->p.accel[s] = ev->accel[s];
    }
    free(all);
    ev->p.n_samples = n;
    ev->p.scan_rate_hz = RATE;
    ev->p.t_first_s = t0;
    for (int v = 0; v < ev->p.n_vehicles; v++)
        ev->p.vehicle[v].entry_s += t0;
}

static void event_free(event *ev)
{
    for (int s = 0; s < 3; s++)
        free(ev->accel[s]);
}

static void add_vehicle(event *ev, double entry_s, int n_axles, const double *spacing,
                        const double *force_N)
{
    amfi_vehicle *ve = &ev->p.vehicle[ev->p.n_vehicles++];
    ve->entry_s = entry_s;
    ve->speed_mps = SPEED;
    ve->n_axles = n_axles;
    for (int a = 0; a + 1 < n_axles; a++)
        ve->axle_spacing_m[a] = spacing[a];
    for (int a = 0; a < n_axles; a++)
        ev->force_N[ev->na++] = force_N[a];
}

static amfi_solver *make_solver_at(int ns, int max_axles, amfi_coords coords, double rate_hz)
{
    amfi_solver_params sp;
    amfi_solver *s = NULL;
    char err[256];
    amfi_solver_params_default(&sp, 20.0);
    sp.n_sensors = ns;
    for (int i = 0; i < ns; i++) {
        sp.sensor_x_m[i] = sensors[i];
        sp.sensor_weight[i] = 1.0;
    }
    sp.calc_rate_hz = rate_hz;
    sp.max_axles = max_axles;
    sp.coords = coords;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    return s;
}

/* At the default 5000 Hz (at 1000 Hz one vehicle alone errs by -1.06 %). */
static amfi_solver *make_solver(int ns, int max_axles, amfi_coords coords)
{
    return make_solver_at(ns, max_axles, coords, 5000.0);
}

/* The fifteen-axle events at 2000 Hz: what they check (the event limit, the
 * memory budget's checkpoints, segments) does not depend on the rate, and
 * under the sanitizers they took 37 s at 5000 Hz. */
#define TRUCK_RATE_HZ 2000.0

/* Relative GVW errors of each vehicle and of their sum. */
static double errors(const event *ev, const amfi_multi_result *r, double *err_v)
{
    double truth_all = 0.0;
    int i = 0;
    for (int v = 0; v < r->n_vehicles; v++) {
        double truth = 0.0;
        for (int a = 0; a < r->vehicle[v].n_axles; a++, i++)
            truth += ev->force_N[i] / AMFI_GRAVITY;
        truth_all += truth;
        err_v[v] = r->vehicle[v].gvw_kg / truth - 1.0;
    }
    return r->total_gvw_kg / truth_all - 1.0;
}

static const double sp2[1] = {5.0}, sp3[2] = {4.0, 1.3};
static const double f2[2] = {102000.0, 74600.0};     /* class A-like two-axle */
static const double f2b[2] = {60000.0, 90000.0};
static const double f3[3] = {70000.0, 110000.0, 100000.0};

/* One vehicle through the multi path equals amfi_solve, on a shifted clock,
 * with quality and separability exactly 1 (nothing to trade load with). */
static void single_equals_solve(void **state)
{
    (void)state;
    event ev;
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.0, 2, sp2, f2);
    ev.na = 0;
    record(&ev, 1, 0.0);
    amfi_solver *s = make_solver(1, 2, AMFI_COORDS_MODAL);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_passage one;
    memset(&one, 0, sizeof one);
    one.n_samples = ev.p.n_samples;
    one.scan_rate_hz = RATE;
    one.accel[0] = ev.accel[0];
    one.speed_mps = SPEED;
    one.n_axles = 2;
    one.axle_spacing_m[0] = 5.0;
    amfi_result r1;
    assert_int_equal(amfi_solve(s, &one, &lam, &r1, NULL, 0), 0);
    double gvw1 = r1.gvw_kg;
    printf("# one vehicle: %+.3f %%\n", 100 * (gvw1 / ((f2[0] + f2[1]) / AMFI_GRAVITY) - 1));
    /* the same data on a clock starting at 1234.5 s */
    ev.p.t_first_s = 1234.5;
    ev.p.vehicle[0].entry_s = 1234.5;
    amfi_multi_result rm;
    char err[256];
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, &rm, err, sizeof err), 0);
    /* the same sweep on the same samples: only the clock's rounding differs */
    assert_true(fabs(rm.vehicle[0].gvw_kg / gvw1 - 1.0) < 1e-6);
    assert_true(fabs(rm.all.t0_s - 1234.5) < 1e-9);
    assert_true(fabs(rm.vehicle[0].quality - 1.0) < 1e-9);
    assert_true(fabs(rm.vehicle[0].separability - 1.0) < 1e-9);
    assert_true(rm.vehicle[0].gvw_sd_kg >= 0.0);
    amfi_solver_destroy(s);
    event_free(&ev);
}

/* Two vehicles, one mid-span sensor, the second entering at 0.5 s while the
 * first (on the span 0 .. 1 s) is at mid-span. */
static void two_vehicles_one_sensor(void **state)
{
    (void)state;
    event ev;
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.0, 2, sp2, f2);
    add_vehicle(&ev, 0.5, 3, sp3, f3);
    ev.na = 0;
    record(&ev, 1, 0.0);
    /* sized for 2 axles: the event's 5 grow it */
    amfi_solver *s = make_solver(1, 2, AMFI_COORDS_MODAL);
    size_t before = amfi_solver_workspace_bytes(s);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_multi_result r;
    char err[256];
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, &r, err, sizeof err), 0);
    assert_true(amfi_solver_workspace_bytes(s) > before);
    assert_int_equal(r.n_vehicles, 2);
    assert_int_equal(r.all.n_axles, 5);
    assert_int_equal(r.vehicle[1].first_axle, 2);
    double e[2];
    double et = errors(&ev, &r, e);
    printf("# 2 vehicles, 1 sensor: total %+.3f %%, v1 %+.3f %% (q %.3g), v2 %+.3f %% (q %.3g)\n",
           100 * et, 100 * e[0], r.vehicle[0].quality, 100 * e[1], r.vehicle[1].quality);
    /* constant forces, no noise: measured -0.21 % (sum), -0.24 %, -0.19 %; one
     * vehicle alone errs by -0.21 % here. Bound: 2.5 × that, well inside the
     * issue's one-sensor targets (sum 2.5 %, each 10 %) */
    assert_true(fabs(et) < 0.005);
    assert_true(fabs(e[0]) < 0.006 && fabs(e[1]) < 0.006);
    for (int v = 0; v < 2; v++) {
        assert_true(r.vehicle[v].quality >= 1.0 && isfinite(r.vehicle[v].quality));
        assert_true(r.vehicle[v].separability >= 1.0 && isfinite(r.vehicle[v].separability));
    }
    assert_true(r.all.n_solves == 2); /* the answer's sweep and quality's at λ/10 */
    amfi_solver_destroy(s);
    event_free(&ev);
}

/* Two vehicles side by side on two lanes (the beam has no width: both load
 * it at the same positions), entering together at one speed: the front
 * axles coincide for the whole crossing, and the data fix only their sum.
 * They are one unknown (AMFI_MULTI_COINCIDENT_M), found from the geometry
 * before the sweep: the event is solved at the call's λ with both sweeps
 * (it once failed: "quality sweep failed", then "sweep failed: numerical
 * failure" with OpenBLAS's SkylakeX kernel, ctest runs this under Haswell
 * and SkylakeX), the pair is one group with quality
 * AMFI_MULTI_QUALITY_UNFIXED and its sum right. The same for the second
 * entering 1 m behind (its middle axle on the first's rear), and 5 mm
 * behind (within the tolerance); 5 cm behind and 0.7 s apart the axles
 * stay separate unknowns. A third vehicle after the pair keeps its own
 * weight and quality. */
static void side_by_side_two_lanes(void **state)
{
    (void)state;
    amfi_solver *s = make_solver(1, 8, AMFI_COORDS_MODAL);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    static const struct {
        double entry2_s; /* the second vehicle's entry */
        int merged_with; /* its axle (0-based) that coincides with the first's
                            axle of the same unknown, -1: none */
        int first_axle;  /* that axle of the first vehicle */
        int third;       /* a third vehicle entering at 0.7 s */
    } cases[] = {
        {0.0, 0, 0, 0},          /* side by side: front axles */
        {1.0 / SPEED, 1, 1, 0},  /* 1 m behind: its 2nd axle (1 + 4 m) on the first's rear (5 m) */
        {0.005 / SPEED, 0, 0, 0}, /* 5 mm behind: within the tolerance */
        {0.05 / SPEED, -1, 0, 0}, /* 5 cm behind: separate unknowns */
        {0.7, -1, 0, 0},          /* 0.7 s apart */
        {0.0, 0, 0, 1},           /* side by side, a third vehicle after them */
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        event ev;
        memset(&ev, 0, sizeof ev);
        add_vehicle(&ev, 0.0, 2, sp2, f2);                 /* lane 1 */
        add_vehicle(&ev, cases[c].entry2_s, 3, sp3, f3);   /* lane 2 */
        if (cases[c].third)
            add_vehicle(&ev, 0.7, 2, sp2, f2b);
        ev.na = 0;
        record(&ev, 1, 0.0);
        amfi_multi_result r;
        char err[256];
        int rc = amfi_solve_multi(s, &ev.p, &lam, &r, err, sizeof err);
        if (rc != 0)
            fail_msg("case %zu: %s", c, err);
        double e[3];
        double et = errors(&ev, &r, e);
        const int merged = cases[c].merged_with >= 0;
        double truth2 = 0.0;
        for (int a = 0; a < 5; a++)
            truth2 += ev.force_N[a] / AMFI_GRAVITY;
        printf("# side by side, second at %.4f s%s: total %+.3f %%, v1 %+.3f %% (group %d, "
               "sep %.3g, q %.3g), v2 %+.3f %% (group %d, q %.3g), pair %+.3f %%, "
               "%d unknowns\n",
               cases[c].entry2_s, cases[c].third ? " + third" : "", 100 * et, 100 * e[0],
               r.vehicle[0].group, r.vehicle[0].separability, r.vehicle[0].quality,
               100 * e[1], r.vehicle[1].group, r.vehicle[1].quality,
               merged ? 100 * (r.vehicle[0].group_gvw_kg / truth2 - 1.0) : NAN, r.n_unknowns);
        /* the sum: as a vehicle alone (-0.21 %) */
        assert_true(fabs(et) < 0.01);
        /* never the numerical fallbacks: both sweeps, the weights at the
         * call's λ for one group (side by side: one load), at λ/10 with a
         * third vehicle weighed apart (the default for several) */
        assert_int_equal(r.all.n_solves, 2);
        const double lam_w =
            lam.lambda_ref * (merged && !cases[c].third ? 1.0 : AMFI_MULTI_QUALITY_LAMBDA);
        assert_true(fabs(r.all.lambda_ref / lam_w - 1.0) < 1e-9);
        assert_int_equal(r.all.n_axles, 5 + 2 * cases[c].third);
        assert_int_equal(r.n_unknowns, r.all.n_axles - merged);
        for (int v = 0; v < 2; v++) {
            const amfi_vehicle_result *vr = &r.vehicle[v];
            assert_true(isfinite(vr->separability) && isfinite(vr->gvw_sd_kg));
            if (merged) {
                assert_int_equal(vr->group, 0);
                assert_int_equal(vr->n_merged, 1);
                assert_true(vr->quality == AMFI_MULTI_QUALITY_UNFIXED);
                /* the pair's sum is what the data fix, and it is right */
                assert_true(fabs(vr->group_gvw_kg / truth2 - 1.0) < 0.01);
            } else {
                assert_int_equal(vr->group, v);
                assert_int_equal(vr->n_merged, 0);
                assert_true(vr->quality >= 1.0 && vr->quality < 1e3);
                assert_true(vr->group_gvw_kg == vr->gvw_kg);
            }
        }
        if (merged) {
            const int a1 = cases[c].first_axle, a2 = 2 + cases[c].merged_with;
            assert_int_equal(r.axle_unknown[a1], r.axle_unknown[a2]);
            /* the unknown's load split evenly, the total kept */
            assert_true(fabs(r.all.axle_kg[a1] - r.all.axle_kg[a2]) < 1e-9 * r.all.axle_kg[a1]);
            assert_true(fabs(r.vehicle[0].gvw_kg + r.vehicle[1].gvw_kg -
                             r.vehicle[0].group_gvw_kg) < 1e-6);
        } else {
            for (int a = 0; a < r.all.n_axles; a++)
                assert_int_equal(r.axle_unknown[a], a);
        }
        if (cases[c].third) {
            const amfi_vehicle_result *vr = &r.vehicle[2];
            assert_int_equal(vr->group, 2);
            assert_int_equal(vr->n_merged, 0);
            assert_true(vr->quality >= 1.0 && vr->quality < 10.0);
            assert_true(fabs(e[2]) < 0.02);
        }
        if (cases[c].entry2_s == 0.7) /* separate: each weight right */
            assert_true(fabs(e[0]) < 0.01 && fabs(e[1]) < 0.01);
        event_free(&ev);
    }
    amfi_solver_destroy(s);
}

/* Three vehicles in a chain (A-B-C: A and C never meet), at three sensors,
 * modal and dense nodal paths agree. */
static void three_vehicles_three_sensors(void **state)
{
    (void)state;
    event ev;
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.0, 2, sp2, f2);
    add_vehicle(&ev, 0.6, 3, sp3, f3);
    add_vehicle(&ev, 1.3, 2, sp2, f2b);
    ev.na = 0;
    record(&ev, 3, 0.0);
    amfi_solver *s = make_solver(3, 7, AMFI_COORDS_MODAL);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_multi_result r;
    char err[256];
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, &r, err, sizeof err), 0);
    double e[3];
    double et = errors(&ev, &r, e);
    printf("# 3 vehicles, 3 sensors: total %+.3f %%, %+.3f %% %+.3f %% %+.3f %% (q %.3g %.3g %.3g)\n",
           100 * et, 100 * e[0], 100 * e[1], 100 * e[2], r.vehicle[0].quality,
           r.vehicle[1].quality, r.vehicle[2].quality);
    /* measured -0.39 % (sum), -0.40 / -0.37 / -0.41 %; the issue's
     * three-sensor target is 5 % worst: bound at 1 % */
    for (int v = 0; v < 3; v++)
        assert_true(fabs(e[v]) < 0.01);
    assert_true(fabs(et) < 0.01);
    amfi_solver *sn = make_solver(3, 7, AMFI_COORDS_NODAL);
    amfi_multi_result rn;
    assert_int_equal(amfi_solve_multi(sn, &ev.p, &lam, &rn, err, sizeof err), 0);
    /* the same cost minimised in two coordinate systems (test_libamfi's
     * modal_vs_nodal bound); separabilities from all modes vs the observable
     * ones; qualities from the same two sweeps (at λ and λ/10) */
    for (int v = 0; v < 3; v++) {
        assert_true(fabs(rn.vehicle[v].gvw_kg / r.vehicle[v].gvw_kg - 1.0) < 1e-3);
        assert_true(fabs(rn.vehicle[v].separability / r.vehicle[v].separability - 1.0) < 0.05);
        assert_true(fabs(rn.vehicle[v].quality / r.vehicle[v].quality - 1.0) < 0.05);
    }
    amfi_solver_destroy(sn);
    amfi_solver_destroy(s);
    event_free(&ev);
}

/* Three vehicles at one sensor; the first vehicle's separability figure is
 * worse (larger) when the second follows it closely (1.25 m between axles,
 * most of the crossing together) than when it enters as the first is about
 * to leave. Measured: 1.23 against 1.12. */
static void separability_ranks_close_axles(void **state)
{
    (void)state;
    amfi_solver *s = make_solver(1, 7, AMFI_COORDS_MODAL);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    double q[2];
    const double entry2[2] = {0.25, 0.9}; /* 1.25 m gap, 2 s together; 17.5 m gap, 0.1 s */
    for (int c = 0; c < 2; c++) {
        event ev;
        memset(&ev, 0, sizeof ev);
        add_vehicle(&ev, 0.0, 2, sp2, f2);
        add_vehicle(&ev, entry2[c], 3, sp3, f3);
        add_vehicle(&ev, entry2[c] + 0.9, 2, sp2, f2b);
        ev.na = 0;
        record(&ev, 1, 0.0);
        amfi_multi_result r;
        char err[256];
        assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, &r, err, sizeof err), 0);
        double e[3];
        double et = errors(&ev, &r, e);
        printf("# chain of 3, entry2 %.2f s: total %+.3f %%, %+.3f %% %+.3f %% %+.3f %% "
               "(separability %.3g %.3g %.3g)\n",
               entry2[c], 100 * et, 100 * e[0], 100 * e[1], 100 * e[2],
               r.vehicle[0].separability, r.vehicle[1].separability, r.vehicle[2].separability);
        assert_true(fabs(et) < 0.01); /* measured -0.23, -0.25 % */
        q[c] = r.vehicle[0].separability;
        event_free(&ev);
    }
    assert_true(q[0] > q[1]);
    amfi_solver_destroy(s);
}

/* Axle forces that vary (a 10 % bounce at 2.2-3.1 Hz, each axle its own
 * phase): truth is each axle's mean force while on the span. */
typedef struct bounce {
    double f0[AMFI_MAX_AXLES], hz[AMFI_MAX_AXLES], phase[AMFI_MAX_AXLES];
} bounce;

static double bounce_force(double t, int a, void *user)
{
    const bounce *b = user;
    return b->f0[a] * (1.0 + 0.1 * sin(6.283185307179586 * b->hz[a] * t + b->phase[a]));
}

/* The bouncing pair: two two-axle vehicles at one sensor, the follower's
 * front axle `gap` m behind the leader's rear axle, solved with
 * amfi_multi_passage.lambda_factor = factor; each vehicle's GVW error
 * against its axles' mean forces on the span, and its quality. */
static void bounce_pair(amfi_solver *s, double gap, double factor, double *e, double *q,
                        double *sep)
{
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    bounce b = {{102000.0, 74600.0, 60000.0, 90000.0},
                {2.2, 3.1, 2.6, 2.9},
                {0.0, 1.9, 4.1, 0.7}};
    const double sp[1] = {5.0};
    amfi_multi_passage *p = calloc(1, sizeof *p);
    /* x = v·t − off: the leader enters at 0, the follower (5 + gap)/v later */
    const double off[4] = {0.0, 5.0, 5.0 + gap, 10.0 + gap};
    for (int v = 0; v < 2; v++) {
        p->vehicle[v].entry_s = off[2 * v] / SPEED;
        p->vehicle[v].speed_mps = SPEED;
        p->vehicle[v].n_axles = 2;
        p->vehicle[v].axle_spacing_m[0] = sp[0];
    }
    p->n_vehicles = 2;
    p->lambda_factor = factor;
    amfi_passage_times w = amfi_multi_window(20.0, p, 0.0, 0.0);
    int n = (int)((w.end_s + 0.05) * RATE) + 1;
    double *acc = malloc(sizeof(double) * n);
    char err[256];
    assert_int_equal(amfi_forward_newmark(bridge, SPEED, 4, off, bounce_force, &b, 1, sensors,
                                          2e-5, RATE, n, acc, err, sizeof err),
                     0);
    p->n_samples = n;
    p->scan_rate_hz = RATE;
    p->accel[0] = acc;
    amfi_multi_result *r = malloc(sizeof *r);
    assert_int_equal(amfi_solve_multi(s, p, &lam, r, err, sizeof err), 0);
    for (int v = 0; v < 2; v++) {
        /* truth: the mean of each axle's force over its steps on the span */
        double truth = 0.0;
        for (int a = 2 * v; a < 2 * v + 2; a++) {
            double sum = 0.0;
            int cnt = 0;
            for (int k = 0; k < 100000; k++) {
                double t = k / 5000.0, x = SPEED * t - off[a];
                if (x > 20.0)
                    break;
                if (x >= 0.0) {
                    sum += bounce_force(t, a, &b);
                    cnt++;
                }
            }
            truth += sum / cnt / AMFI_GRAVITY;
        }
        e[v] = r->vehicle[v].gvw_kg / truth - 1.0;
        q[v] = r->vehicle[v].quality;
        sep[v] = r->vehicle[v].separability;
        printf("# bouncing pair, gap %.0f m, λ factor %g: vehicle %d %+.3f %% (quality %.3f, "
               "separability %.3f)\n",
               gap, factor, v + 1, 100 * e[v], q[v], sep[v]);
    }
    free(r), free(acc), free(p);
}

/* Two two-axle vehicles at one sensor with bouncing axles: the follower's
 * front axle 1 m behind the leader's rear axle (most of the crossing
 * together: they trade load) and 15 m behind it (0.2 s together). The
 * quality figure of the close pair is the larger, and so are its errors.
 * Measured: errors -3.22 / +2.39 % at quality 1.40 / 1.15 (1 m) with the
 * weights of the λ/10 sweep (the default since round six; -2.83 / +2.24 %
 * at λ), -1.49 / +0.91 % at 1.16 / 1.27 (15 m, at λ); the separability
 * figure ranks them the wrong way round (1.07 against 1.19), which is why
 * quality replaced it. */
static void quality_ranks_traded_load(void **state)
{
    (void)state;
    amfi_solver *s = make_solver(1, 4, AMFI_COORDS_MODAL);
    const double gap[2] = {1.0, 15.0};
    double q[2], e_max[2];
    for (int c = 0; c < 2; c++) {
        double e[2], qv[2], sep[2];
        bounce_pair(s, gap[c], 0.0, e, qv, sep);
        e_max[c] = fmax(fabs(e[0]), fabs(e[1]));
        q[c] = fmax(qv[0], qv[1]);
    }
    assert_true(q[0] > q[1]);
    assert_true(e_max[0] > e_max[1]);
    amfi_solver_destroy(s);
}

/* amfi_multi_passage.lambda_factor: 0 (the default) weighs a pair at λ/10
 * (the weights of factor 0.1, exactly) with the quality figure of factor 1
 * (the change between λ and λ/10, exactly, as before round six); 0.1
 * sweeps the quality at λ/100; a vehicle alone is solved at λ whatever the
 * factor. On these synthetic pairs (a pure sinusoidal 10 % bounce) the
 * solve at λ/10 errs MORE (1 m: −3.22 / +2.39 % against −2.83 / +2.24 %),
 * unlike the coupled-model pairs of amfi-multi (two-axle half-cars, round
 * five; trucks, round six: docs/results/multi-vehicle.md), which is what
 * the default follows. */
static void lambda_factor_solves_pairs_looser(void **state)
{
    (void)state;
    amfi_solver *s = make_solver(1, 4, AMFI_COORDS_MODAL);
    const double gap[1] = {1.0};
    for (int c = 0; c < 1; c++) {
        double e0[2], e1[2], e10[2], q0[2], q1[2], q10[2], sep[2];
        bounce_pair(s, gap[c], 0.0, e0, q0, sep);
        bounce_pair(s, gap[c], 1.0, e1, q1, sep);
        bounce_pair(s, gap[c], 0.1, e10, q10, sep);
        for (int v = 0; v < 2; v++) {
            /* the default: factor 0.1's weights, factor 1's quality */
            assert_true(e10[v] == e0[v] && q1[v] == q0[v]);
            assert_true(e1[v] != e0[v]);
            double moved = 1.0 + 100.0 * fabs((1.0 + e10[v]) / (1.0 + e1[v]) - 1.0);
            assert_true(fabs(q1[v] - moved) <= 1e-6 * q1[v]);
            /* the quality sweep of the looser solve is at λ/100 */
            assert_true(q10[v] != q0[v] && q10[v] >= 1.0);
        }
    }
    /* one vehicle: the factor does not apply */
    event ev;
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.0, 2, sp2, f2);
    record(&ev, 1, 0.0);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_multi_result *r0 = malloc(sizeof *r0), *r1 = malloc(sizeof *r1);
    char err[256];
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, r0, err, sizeof err), 0);
    ev.p.lambda_factor = 0.1;
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, r1, err, sizeof err), 0);
    assert_true(r1->vehicle[0].gvw_kg == r0->vehicle[0].gvw_kg);
    assert_true(r1->all.lambda_h == r0->all.lambda_h);
    free(r0), free(r1);
    event_free(&ev);
    amfi_solver_destroy(s);
}

static void rejects_bad_events(void **state)
{
    (void)state;
    event ev;
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.0, 2, sp2, f2);
    add_vehicle(&ev, 0.5, 2, sp2, f2b);
    ev.na = 0;
    record(&ev, 1, 0.0);
    amfi_solver *s = make_solver(1, 2, AMFI_COORDS_MODAL);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_multi_result r;
    char err[256];
    amfi_multi_passage p = ev.p;
    p.n_vehicles = 0;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    p = ev.p;
    p.vehicle[1].speed_mps = 0.0;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "vehicle 2"));
    p = ev.p;
    p.vehicle[0].axle_spacing_m[0] = -1.0;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    p = ev.p;
    p.vehicle[1].entry_s = NAN;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    /* more axles in all than AMFI_MAX_EVENT_AXLES (five of ten), and a
     * vehicle of more than AMFI_MAX_AXLES */
    p = ev.p;
    p.n_vehicles = 5;
    for (int v = 0; v < 5; v++) {
        p.vehicle[v] = ev.p.vehicle[0];
        p.vehicle[v].entry_s = 0.1 * v;
        p.vehicle[v].n_axles = 10;
        for (int a = 0; a < 9; a++)
            p.vehicle[v].axle_spacing_m[a] = 1.2;
    }
    assert_true(5 * 10 > AMFI_MAX_EVENT_AXLES);
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "axles in all"));
    p = ev.p;
    p.vehicle[1].n_axles = AMFI_MAX_AXLES + 1;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "vehicle 2"));
    /* the second vehicle leaving after the data ends */
    p = ev.p;
    p.vehicle[1].entry_s = 0.9;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_ERANGE);
    /* the λ factor: 0 (off) or 1e-4 .. 1 */
    const double bad_factor[3] = {-0.1, 2.0, NAN};
    for (int k = 0; k < 3; k++) {
        p = ev.p;
        p.lambda_factor = bad_factor[k];
        assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
        assert_non_null(strstr(err, "lambda_factor"));
    }
    p = ev.p;
    p.n_vehicles = AMFI_MAX_VEHICLES + 1;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    /* a refused event leaves the solver usable */
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, &r, err, sizeof err), 0);
    amfi_solver_destroy(s);
    event_free(&ev);
}

/* Three five-axle trucks on the span in a chain (15 axles: more than one
 * vehicle's AMFI_MAX_AXLES, refused before the event limit was apart),
 * on a solver sized for 6 axles a vehicle. Then the same event under a
 * memory budget far below its gains (the sweep keeps checkpoints and
 * recomputes: the same weights), and, with a free initial state and a
 * pre-roll, two such chains apart solved in two segments cut where the
 * span is empty. */
static const double sp5[4] = {3.6, 1.3, 5.8, 1.3};
static const double f5a[5] = {70000.0, 100000.0, 95000.0, 72000.0, 70000.0};
static const double f5b[5] = {60000.0, 80000.0, 78000.0, 65000.0, 64000.0};
static const double f5c[5] = {75000.0, 105000.0, 99000.0, 80000.0, 79000.0};

static void three_trucks_fifteen_axles(void **state)
{
    (void)state;
    event ev;
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.0, 5, sp5, f5a);
    add_vehicle(&ev, 0.75, 5, sp5, f5b);
    add_vehicle(&ev, 1.5, 5, sp5, f5c);
    ev.na = 0;
    record(&ev, 1, 0.0);
    amfi_solver *s = make_solver_at(1, 6, AMFI_COORDS_MODAL, TRUCK_RATE_HZ);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_multi_result *r = malloc(sizeof *r), *rc = malloc(sizeof *rc);
    char err[256];
    amfi_multi_passage p = ev.p;
    p.max_segment_bytes = (size_t)1 << 40; /* gains kept whole */
    assert_int_equal(amfi_solve_multi(s, &p, &lam, r, err, sizeof err), 0);
    double e[3];
    double et = errors(&ev, r, e);
    printf("# 3 trucks, 15 axles: total %+.3f %%, %+.3f %% %+.3f %% %+.3f %%, %d segment(s), "
           "%.1f MB\n",
           100 * et, 100 * e[0], 100 * e[1], 100 * e[2], r->n_segments,
           r->max_segment_bytes / 1048576.0);
    assert_int_equal(r->all.n_axles, 15);
    for (int v = 0; v < 3; v++)
        assert_true(fabs(e[v]) < 0.02);
    /* a budget of 1 MB: checkpoints, the same solve */
    p.max_segment_bytes = (size_t)1 << 20;
    assert_true(r->max_segment_bytes > 4 * p.max_segment_bytes);
    assert_int_equal(amfi_solve_multi(s, &p, &lam, rc, err, sizeof err), 0);
    assert_int_equal(rc->n_segments, 1); /* no free initial state: never cut */
    for (int v = 0; v < 3; v++)
        assert_true(fabs(rc->vehicle[v].gvw_kg / r->vehicle[v].gvw_kg - 1.0) < 1e-9);
    size_t held = amfi_solver_workspace_bytes(s);
    amfi_solver_destroy(s);
    amfi_solver *s1 = make_solver_at(1, 6, AMFI_COORDS_MODAL, TRUCK_RATE_HZ);
    assert_int_equal(amfi_solve_multi(s1, &p, &lam, rc, err, sizeof err), 0);
    printf("# workspace: %.1f MB whole, %.1f MB under a 1 MB budget\n", held / 1048576.0,
           amfi_solver_workspace_bytes(s1) / 1048576.0);
    assert_true(amfi_solver_workspace_bytes(s1) < held / 2);
    amfi_solver_destroy(s1);
    event_free(&ev);

    /* two chains of two trucks, the span empty between them */
    memset(&ev, 0, sizeof ev);
    add_vehicle(&ev, 0.3, 5, sp5, f5a); /* the pre-roll's data from t = 0, at rest */
    add_vehicle(&ev, 1.05, 5, sp5, f5b);
    add_vehicle(&ev, 2.9, 5, sp5, f5c);
    add_vehicle(&ev, 3.6, 5, sp5, f5a);
    ev.na = 0;
    record(&ev, 1, 0.0);
    amfi_solver_params sp;
    amfi_solver_params_default(&sp, 20.0);
    sp.calc_rate_hz = TRUCK_RATE_HZ;
    sp.max_axles = 6;
    sp.free_initial_state = 1;
    sp.pre_roll_s = 0.3;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    p = ev.p;
    p.max_segment_bytes = (size_t)8 << 20;
    assert_int_equal(amfi_solve_multi(s, &p, &lam, r, err, sizeof err), 0);
    assert_int_equal(amfi_solve_multi(s, &ev.p, &lam, rc, err, sizeof err), 0);
    double e4[4], e4w[4];
    double truth[4] = {0};
    for (int v = 0, i = 0; v < 4; v++)
        for (int a = 0; a < 5; a++, i++)
            truth[v] += ev.force_N[i] / AMFI_GRAVITY;
    for (int v = 0; v < 4; v++) {
        e4[v] = r->vehicle[v].gvw_kg / truth[v] - 1.0;
        e4w[v] = rc->vehicle[v].gvw_kg / truth[v] - 1.0;
    }
    printf("# 2 + 2 trucks: %d segments: %+.3f %+.3f %+.3f %+.3f %%; whole (%d): %+.3f %+.3f "
           "%+.3f %+.3f %%\n",
           r->n_segments, 100 * e4[0], 100 * e4[1], 100 * e4[2], 100 * e4[3], rc->n_segments,
           100 * e4w[0], 100 * e4w[1], 100 * e4w[2], 100 * e4w[3]);
    assert_int_equal(r->n_segments, 2);
    assert_int_equal(r->vehicle[0].segment, 0);
    assert_int_equal(r->vehicle[3].segment, 1);
    for (int v = 0; v < 4; v++)
        assert_true(fabs(e4[v]) < 0.02);
    amfi_solver_destroy(s);
    event_free(&ev);
    free(r);
    free(rc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(single_equals_solve),
        cmocka_unit_test(two_vehicles_one_sensor),
        cmocka_unit_test(side_by_side_two_lanes),
        cmocka_unit_test(three_vehicles_three_sensors),
        cmocka_unit_test(separability_ranks_close_axles),
        cmocka_unit_test(quality_ranks_traded_load),
        cmocka_unit_test(lambda_factor_solves_pairs_looser),
        cmocka_unit_test(rejects_bad_events),
        cmocka_unit_test(three_trucks_fifteen_axles),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
