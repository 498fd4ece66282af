/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_speed.c: unit tests of the speed estimation (libamfi/src/speed.c,
 * issue 12): prescribed moving forces recorded by the independent Newmark
 * integrator at the true speed, solved from a biased detector speed; and
 * the refusal of bad priors. Each tolerance says why it is what it is.
 */
#define _GNU_SOURCE
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "amfi/amfi.h"

#include "paper20_fixture.h"

#define TRUE_SPEED 25.0
#define RATE 1000.0
#define SECONDS 1.6 /* the window at −12 % speed is 1.14 s */

static const double axle_N[2] = {102000.0, 74600.0};

/* Two axles 5 m apart, ±10 % at 2 Hz (the bounce of a vehicle on its springs). */
static double forces(double t, int a, void *user)
{
    (void)user;
    return axle_N[a] * (1.0 + 0.1 * sin(2 * M_PI * 2.0 * t + 1.3 * a));
}

/* Mid-span acceleration at RATE for SECONDS from entry, with white noise of
 * `noise` × its RMS (seeded). */
static double *record_on(const amfi_bridge *on, double noise, int *n)
{
    const double off[2] = {0.0, 5.0}, xs = 10.0;
    *n = (int)(SECONDS * RATE) + 1;
    double *acc = malloc(sizeof(double) * *n);
    char err[256];
    assert_int_equal(amfi_forward_newmark(on, TRUE_SPEED, 2, off, forces, NULL, 1, &xs,
                                          2e-5, RATE, *n, acc, err, sizeof err),
                     0);
    if (noise > 0) {
        double rms = 0;
        for (int i = 0; i < *n; i++)
            rms += acc[i] * acc[i];
        rms = sqrt(rms / *n);
        gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
        gsl_rng_set(r, 12);
        for (int i = 0; i < *n; i++)
            acc[i] += gsl_ran_gaussian(r, noise * rms);
        gsl_rng_free(r);
    }
    return acc;
}

static double *record(double noise, int *n) { return record_on(bridge, noise, n); }

static amfi_solver *solver(void)
{
    amfi_solver_params sp;
    amfi_solver *s = NULL;
    char err[256];
    amfi_solver_params_default(&sp, 20.0);
    sp.max_duration_s = SECONDS;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    return s;
}

static amfi_passage passage(const double *acc, int n, double speed)
{
    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = n;
    p.scan_rate_hz = RATE;
    p.accel[0] = acc;
    p.speed_mps = speed;
    p.n_axles = 2;
    p.axle_spacing_m[0] = 5.0;
    return p;
}

static const double true_gvw_kg = (102000.0 + 74600.0) / AMFI_GRAVITY;

/* A detector 4 % off either way: both criteria bring the speed back to
 * within 0.5 % (the target RMS) and the GVW to within 1 %, where the
 * biased speed alone errs by several %. With 3 % noise the same. */
static void recovers_biased_speed(void **state)
{
    (void)state;
    amfi_solver *s = solver();
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    /* (noise, bias, criterion, coarse rate): the two-level search (coarse
     * model at 1000 Hz, the default) and the grid on the full model (coarse
     * 0); the residual criterion once, on the full model only (it is the
     * weaker one: on the coarse model its minimum is the range's slow end,
     * docs/results/speed-estimation.md); kept short for ASan */
    const struct { double noise, bias; int c; double coarse; } cases[] = {
        {0.0, -0.04, 0, 1000}, {0.03, -0.04, 0, 1000}, {0.03, 0.04, 0, 1000},
        {0.03, -0.04, 0, 0},   {0.03, -0.04, 1, 0}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int n;
        double *acc = record(cases[k].noise, &n);
        {
                const double bias[1] = {cases[k].bias}, noise[1] = {cases[k].noise};
                const int b = 0, c = cases[k].c;
                amfi_passage p = passage(acc, n, TRUE_SPEED * (1 + bias[b]));
                amfi_speed_prior pr;
                amfi_speed_prior_default(&pr);
                pr.criterion = (amfi_speed_criterion)c;
                pr.coarse_rate_hz = cases[k].coarse;
                pr.range_sd = 1.5; /* ±4.5 %: holds the ±4 % bias, 46 grid sweeps */
                amfi_result plain, est;
                amfi_speed_result sr;
                char err[256];
                assert_int_equal(amfi_solve(s, &p, &lam, &plain, err, sizeof err), 0);
                double gvw_plain = plain.gvw_kg;
                int rc = amfi_solve_speed(s, &p, &lam, &pr, &est, &sr, err, sizeof err);
                if (rc)
                    fail_msg("%s", err);
                double ve = sr.speed_mps / TRUE_SPEED - 1, ge = est.gvw_kg / true_gvw_kg - 1;
                print_message("noise %.0f%% given %+.0f%% %-11s coarse %4.0f Hz: speed %+.3f%% "
                              "in %d sweeps (+%d coarse), GVW %+.2f%% (given speed: %+.2f%%)\n",
                              100 * noise[b], 100 * bias[b], amfi_speed_criterion_name(pr.criterion),
                              pr.coarse_rate_hz, 100 * ve, est.n_solves, sr.n_coarse, 100 * ge,
                              100 * (gvw_plain / true_gvw_kg - 1));
                assert_true(fabs(ve) < 0.005);
                assert_true(fabs(ge) < 0.01);
                /* the budget: <= 10 full-model sweeps, final solve included */
                if (pr.coarse_rate_hz > 0) {
                    assert_true(est.n_solves <= 10);
                    assert_true(sr.n_coarse > 0);
                } else {
                    assert_int_equal(sr.n_coarse, 0);
                }
                assert_false(sr.at_bound);
                assert_true(sr.j_best <= sr.j_given);
                assert_true(sr.speed_given_mps == p.speed_mps);
                /* the result is amfi_solve's at the estimate */
                amfi_passage pv = p;
                pv.speed_mps = sr.speed_mps;
                double g_est = est.gvw_kg;
                assert_int_equal(amfi_solve(s, &pv, &lam, &plain, err, sizeof err), 0);
                assert_true(fabs(plain.gvw_kg - g_est) <= 1e-9 * g_est);
                if (pr.coarse_rate_hz > 0) {
                    /* round four's refinement (7 local points, 2 Brent
                     * sweeps) lands within a local step's third (0.1 %) of
                     * the widening 3-point grid and the parabola's vertex */
                    amfi_speed_prior p7 = pr;
                    amfi_speed_result s7;
                    p7.local_half = 3;
                    p7.brent_evals = 2;
                    assert_int_equal(amfi_solve_speed(s, &p, &lam, &p7, &plain, &s7, err,
                                                      sizeof err),
                                     0);
                    print_message("  7 local points + Brent: speed %+.3f%% in %d sweeps\n",
                                  100 * (s7.speed_mps / TRUE_SPEED - 1), plain.n_solves);
                    assert_true(fabs(s7.speed_mps / sr.speed_mps - 1) < 0.001);
                    assert_true(plain.n_solves > est.n_solves);
                }
            }
        free(acc);
    }
    amfi_solver_destroy(s);
}

/* A bridge 10 % softer than the solver's model (the damage the estimate must
 * not absorb): recorded on the damaged bridge with 3 % noise, solved with
 * the healthy model from a detector speed 4 % slow and 4 % fast. Pick dip
 * finds the true speed within 0.5 % (the RMS target) and keeps the
 * damage's growth of the inferred GVW, 1/(1 − δ) − 1 = +11.1 %, within a
 * quarter of it (the criterion); pick min is printed beside it (it
 * follows the misfit to slower speeds, docs/results/speed-estimation.md). */
static void damaged_bridge(void **state)
{
    (void)state;
    amfi_bridge_params bp;
    amfi_bridge *soft;
    char err[256];
    amfi_bridge_params_paper20(&bp);
    bp.damage = 0.1;
    assert_int_equal(amfi_bridge_create(&bp, &soft, err, sizeof err), 0);
    int n;
    double *acc = record_on(soft, 0.03, &n);
    amfi_solver *s = solver();
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    const double growth = 1 / (1 - bp.damage) - 1;
    for (int k = 0; k < 2; k++) {
        const double bias = k ? 0.04 : -0.04;
        amfi_passage p = passage(acc, n, TRUE_SPEED * (1 + bias));
        for (int pick = AMFI_SPEED_PICK_MIN; pick <= AMFI_SPEED_PICK_DIP; pick++) {
            amfi_speed_prior pr;
            amfi_speed_prior_default(&pr);
            pr.pick = (amfi_speed_pick)pick;
            amfi_result est;
            amfi_speed_result sr;
            if (amfi_solve_speed(s, &p, &lam, &pr, &est, &sr, err, sizeof err))
                fail_msg("%s", err);
            double ve = sr.speed_mps / TRUE_SPEED - 1, ge = est.gvw_kg / true_gvw_kg - 1;
            print_message("damage 10%% given %+.0f%% pick %s: speed %+.3f%%, GVW %+.2f%% "
                          "(1/(1 - d) - 1 = %+.2f%%), dip %g, %d sweeps\n",
                          100 * bias, amfi_speed_pick_name(pr.pick), 100 * ve, 100 * ge,
                          100 * growth, sr.dip, est.n_solves);
            if (pick == AMFI_SPEED_PICK_DIP) {
                assert_true(fabs(ve) < 0.005);
                assert_true(fabs(ge - growth) < 0.25 * growth);
                assert_true(sr.dip < 0);
                assert_true(est.n_solves <= 10);
                assert_int_equal(sr.n_aliases, 0); /* two axles: none within the range */
            }
        }
    }
    free(acc);
    amfi_solver_destroy(s);
    amfi_bridge_destroy(soft);
}

/* A five-axle articulated truck (the EU population's A23: 3.44, 6.14,
 * 1.33, 1.32 m; a tridem at the back): a trial speed (L + S_j)/(L + S_i)
 * faster makes axle j leave the span when axle i truly did, 4.3-4.6 % for
 * the tridem's neighbours, and on the coupled simulator's passages the
 * coarse grid's deepest dip can be that alias (docs/results/class-accuracy.md;
 * tests/tools/solve_speed.sh has such a passage, where the alias judged on
 * the full model wins). So the full model also judges the coarse pick's
 * aliases, the speeds (L + S_i)/(L + S_j) times the pick, slower. These
 * prescribed forces do not make the alias deep enough to mislead the coarse
 * grid, its pick is the truth: here, that the aliases are found
 * (n_aliases) and none replaces the truth (a slower trial keeps axles on the
 * span and fits a little better, the judge's margins must hold), the
 * estimate within 0.5 %, from a detector 3 % slow and 3 % fast. The
 * two-axle vehicle of the tests above has no alias within the range (25 %
 * for its 5 m) and finds none. */
static const double truck_N[5] = {60590.0, 92750.0, 60860.0, 60860.0, 60860.0};
static const double truck_off[5] = {0.0, 3.44, 9.58, 10.91, 12.23};
static double truck_forces(double t, int a, void *user)
{
    (void)user;
    return truck_N[a] * (1.0 + 0.08 * sin(2 * M_PI * 1.7 * t + 0.9 * a));
}

static void group_alias(void **state)
{
    (void)state;
    const double xs = 10.0, secs = 2.2; /* the window at -10 % is 1.78 s */
    const int n = (int)(secs * RATE) + 1;
    double *acc = malloc(sizeof(double) * n);
    char err[256];
    assert_int_equal(amfi_forward_newmark(bridge, TRUE_SPEED, 5, truck_off, truck_forces, NULL, 1,
                                          &xs, 2e-5, RATE, n, acc, err, sizeof err),
                     0);
    amfi_solver_params sp;
    amfi_solver *s = NULL;
    amfi_solver_params_default(&sp, 20.0);
    sp.max_duration_s = secs;
    sp.max_axles = 5;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    const double biases[2] = {-0.03, 0.03};
    for (int k = 0; k < 2; k++) {
        amfi_passage p;
        memset(&p, 0, sizeof p);
        p.n_samples = n;
        p.scan_rate_hz = RATE;
        p.accel[0] = acc;
        p.speed_mps = TRUE_SPEED * (1 + biases[k]);
        p.n_axles = 5;
        for (int a = 0; a < 4; a++)
            p.axle_spacing_m[a] = truck_off[a + 1] - truck_off[a];
        amfi_speed_prior pr;
        amfi_speed_prior_default(&pr);
        amfi_result est;
        amfi_speed_result sr;
        if (amfi_solve_speed(s, &p, &lam, &pr, &est, &sr, err, sizeof err))
            fail_msg("%s", err);
        double ve = sr.speed_mps / TRUE_SPEED - 1;
        print_message("five axles, given %+.0f%%: speed %+.3f%%, %d aliases, %d judged (%s), "
                      "%d sweeps (+%d coarse)\n",
                      100 * biases[k], 100 * ve, sr.n_aliases, sr.n_aliases_judged,
                      sr.alias ? "one won" : "none won", est.n_solves, sr.n_coarse);
        assert_true(sr.n_aliases >= 1);
        assert_int_equal(sr.alias, 0);
        assert_true(fabs(ve) < 0.005);
    }
    free(acc);
    amfi_solver_destroy(s);
}

static void refuses_bad_priors(void **state)
{
    (void)state;
    amfi_solver *s = solver();
    int n;
    double *acc = record(0.0, &n);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_result res;
    amfi_speed_result sr;
    char err[256];
    const struct { double speed, sd; const char *msg; } bad[] = {
        {0.0, 0.03, "given speed"}, {-25.0, 0.03, "given speed"}, {NAN, 0.03, "given speed"},
        {25.0, 0.0, "relative SD"}, {25.0, -0.1, "relative SD"}, {25.0, 1.0, "relative SD"},
        {25.0, NAN, "relative SD"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        amfi_passage p = passage(acc, n, bad[i].speed);
        amfi_speed_prior pr;
        amfi_speed_prior_default(&pr);
        pr.rel_sd = bad[i].sd;
        err[0] = 0;
        assert_int_equal(amfi_solve_speed(s, &p, &lam, &pr, &res, &sr, err, sizeof err),
                         AMFI_EINVAL);
        assert_non_null(strstr(err, bad[i].msg));
        assert_int_equal(amfi_speed_prior_check(&pr, bad[i].speed, NULL, 0), AMFI_EINVAL);
    }
    /* the local grid's half-width: 1 .. 3 points */
    for (int h = -1; h <= 4; h += 5) {
        amfi_speed_prior ph;
        amfi_speed_prior_default(&ph);
        ph.local_half = h == -1 ? 0 : h;
        assert_int_equal(amfi_speed_prior_check(&ph, 25.0, err, sizeof err), AMFI_EINVAL);
        assert_non_null(strstr(err, "local_half"));
    }
    /* range × SD >= 0.5 would search speeds near 0 */
    amfi_speed_prior pr;
    amfi_speed_prior_default(&pr);
    pr.rel_sd = 0.2;
    assert_int_equal(amfi_speed_prior_check(&pr, 25.0, err, sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "range"));
    /* data that do not cover the given speed's window: ERANGE, as amfi_solve */
    amfi_speed_prior_default(&pr);
    amfi_passage p = passage(acc, n, 10.0);
    assert_int_equal(amfi_solve_speed(s, &p, &lam, &pr, &res, &sr, err, sizeof err),
                     AMFI_ERANGE);
    free(acc);
    amfi_solver_destroy(s);
}

/* modes: resolved keeps the observable modes below half the calculation
 * rate (10 of the 20 the mid-span sensor sees at 5000 Hz on paper-20m) and
 * weighs the same as all observable modes to 0.1 kg (the measure). */
static void resolved_modes(void **state)
{
    (void)state;
    int n;
    double *acc = record(0.03, &n);
    amfi_passage p = passage(acc, n, TRUE_SPEED);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    double gvw[2];
    int m[2];
    for (int k = 0; k < 2; k++) {
        amfi_solver_params sp;
        amfi_solver *s = NULL;
        char err[256];
        amfi_solver_params_default(&sp, 20.0);
        sp.max_duration_s = SECONDS;
        sp.modes = k ? AMFI_MODES_RESOLVED : AMFI_MODES_OBSERVABLE;
        assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
        amfi_result r;
        assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), 0);
        gvw[k] = r.gvw_kg;
        m[k] = r.n_modes;
        amfi_solver_destroy(s);
    }
    const double *w = amfi_bridge_omega(bridge);
    int below = 0; /* observable at mid-span: the odd modes */
    for (int k = 0; k < amfi_bridge_ndof(bridge); k += 2)
        below += w[k] / (2 * M_PI) < 2500.0;
    print_message("observable %d modes %.2f kg, resolved %d modes %.2f kg\n", m[0], gvw[0], m[1],
                  gvw[1]);
    assert_int_equal(m[0], 20);
    assert_int_equal(m[1], below);
    assert_int_equal(m[1], 10);
    assert_true(fabs(gvw[0] - gvw[1]) < 0.1);
    free(acc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(resolved_modes),
        cmocka_unit_test(recovers_biased_speed),
        cmocka_unit_test(refuses_bad_priors),
        cmocka_unit_test(damaged_bridge),
        cmocka_unit_test(group_alias),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
