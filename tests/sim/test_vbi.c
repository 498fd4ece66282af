/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_vbi.c: the vehicle-bridge interaction simulator against analytical
 * results and physical invariants (issue 3 §3).
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

#include "amfi/amfi.h"
#include "profile.h"
#include "vbi.h"
#include "vehicle.h"

static amfi_bridge *make_bridge(double zeta, double damage)
{
    amfi_bridge_params p;
    amfi_bridge *b = NULL;
    amfi_bridge_params_paper20(&p);
    p.damping_ratio = zeta;
    p.damage = damage;
    assert_int_equal(amfi_bridge_create(&p, &b, NULL, 0), 0);
    return b;
}

/* Frýba (1972), §1.3: an undamped simply supported beam under a constant
 * force P moving at v, from rest, while the force is on the beam:
 *   w(x, t) = Σ_j 2P/(μL) · sin(jπx/L) / (ω_j² − (jΩ)²) · [sin jΩt − (jΩ/ω_j) sin ω_j t],
 * Ω = πv/L, ω_j = (jπ/L)²√(EI/μ). */
static double fryba(double P, double v, double t, double x)
{
    const double L = 20.0, EI = 3.5e10 * 0.2991, mu = 2400.0 * 2.046;
    const double Om = M_PI * v / L;
    double w = 0.0;
    for (int j = 1; j <= 200; j++) {
        double wj = (j * M_PI / L) * (j * M_PI / L) * sqrt(EI / mu);
        double jO = j * Om;
        w += 2.0 * P / (mu * L) * sin(j * M_PI * x / L) / (wj * wj - jO * jO) *
             (sin(jO * t) - jO / wj * sin(wj * t));
    }
    return w;
}

/* A constant moving force (tyres of zero stiffness carry exactly W) on the
 * undamped bridge: mid-span deflection within 1 % of the analytical series
 * (the FE model's own discretisation error is below 0.03 % in frequency). */
static void constant_force_vs_fryba(void **state)
{
    (void)state;
    amfi_bridge *b = make_bridge(0.0, 0.0);
    amfi_sim_params sp;
    amfi_sim *s;
    char err[256];
    amfi_sim_params_default(&sp, 20.0);
    sp.approach_m = 0.0;
    sp.dt_s = 1e-4;
    assert_int_equal(amfi_sim_create(b, NULL, &sp, &s, err, sizeof err), 0);
    amfi_sim_vehicle v;
    memset(&v, 0, sizeof v);
    amfi_halfcar_baseline(&v.car);
    v.car.kt_Nm[0] = v.car.kt_Nm[1] = 0.0;
    v.speed_mps = 25.0;
    v.t_entry_s = 0.0;
    assert_int_equal(amfi_sim_add(s, &v, err, sizeof err), 0);
    amfi_halfcar_finish(&v.car, NULL, 0);
    const double W1 = v.car.W_N[0], W2 = v.car.W_N[1], lag = 5.0 / 25.0;
    double acc[1], emax = 0.0, wmax = 0.0;
    for (int k = 0; k < 800; k++) { /* 0 .. 0.8 s: axle 1 on the span */
        double t = amfi_sim_time(s);
        double wa = fryba(W1, 25.0, t, 10.0) + (t > lag ? fryba(W2, 25.0, t - lag, 10.0) : 0.0);
        double ws = amfi_sim_deflection(s, 10.0);
        emax = fmax(emax, fabs(ws - wa));
        wmax = fmax(wmax, fabs(wa));
        assert_int_equal(amfi_sim_advance(s, 1, acc, err, sizeof err), 0);
    }
    print_message("Fryba: peak mid-span deflection %.4g mm, max difference %.3g%% of it\n",
                  1e3 * wmax, 100 * emax / wmax);
    assert_true(emax < 0.01 * wmax);
    amfi_sim_destroy(s);
    amfi_bridge_destroy(b);
}

static void record_forces(void *user, double t, const amfi_sim_vehicle *v, const double x[2],
                          const double F[2])
{
    (void)t;
    (void)v;
    (void)x;
    double *out = user; /* max |F − W| seen, per axle */
    out[0] = fmax(out[0], fabs(F[0] - out[2]));
    out[1] = fmax(out[1], fabs(F[1] - out[3]));
}

/* A vehicle on a flat rigid road stays at static equilibrium, and its
 * static axle loads are the configured ones. */
static void static_equilibrium(void **state)
{
    (void)state;
    amfi_bridge *b = make_bridge(0.03, 0.0);
    amfi_sim_params sp;
    amfi_sim *s;
    amfi_sim_params_default(&sp, 20.0);
    sp.approach_m = 1000.0; /* stays on the rigid approach for the test */
    assert_int_equal(amfi_sim_create(b, NULL, &sp, &s, NULL, 0), 0);
    amfi_sim_vehicle v;
    memset(&v, 0, sizeof v);
    amfi_halfcar_dist d;
    amfi_halfcar_dist_paper(&d);
    char err[256];
    /* From WIM weights: 6000 + 4000 kg, 4.5 m, Table 2 means. */
    assert_int_equal(amfi_halfcar_from_weights(10000, 6000, 4000, 4.5, &d, NULL, &v.car, err,
                                               sizeof err), 0);
    assert_true(fabs(v.car.W_N[0] - 6000 * AMFI_GRAVITY) < 1e-6);
    assert_true(fabs(v.car.W_N[1] - 4000 * AMFI_GRAVITY) < 1e-6);
    assert_true(fabs(v.car.D1_m + v.car.D2_m - 4.5) < 1e-12);
    /* The baseline: 102.0 and 74.6 kN (docs/simulator.md). */
    amfi_halfcar base;
    amfi_halfcar_baseline(&base);
    assert_true(fabs(base.W_N[0] - 102.0e3) < 0.1e3 && fabs(base.W_N[1] - 74.6e3) < 0.1e3);
    v.id = 7;
    v.speed_mps = 25.0;
    v.t_entry_s = 1000.0 / 25.0;
    assert_int_equal(amfi_sim_add(s, &v, err, sizeof err), 0);
    double seen[4] = {0, 0, v.car.W_N[0], v.car.W_N[1]}, acc[200], u[4];
    amfi_sim_set_hook(s, record_forces, seen);
    assert_int_equal(amfi_sim_advance(s, 200, acc, err, sizeof err), 0);
    assert_int_equal(amfi_sim_vehicle_state(s, 7, u), 0);
    for (int i = 0; i < 4; i++)
        assert_true(fabs(u[i]) < 1e-15);
    assert_true(seen[0] < 1e-9 && seen[1] < 1e-9);
    for (int i = 0; i < 200; i++)
        assert_true(acc[i] == 0.0);
    amfi_sim_destroy(s);
    amfi_bridge_destroy(b);
}

/* Run one vehicle across and return it when it has left. */
static amfi_sim_vehicle cross(const amfi_bridge *b, const amfi_profile *prof,
                              amfi_sim_vehicle v, double *accel, int n)
{
    amfi_sim_params sp;
    amfi_sim *s;
    char err[256];
    amfi_sim_params_default(&sp, 20.0);
    assert_int_equal(amfi_sim_create(b, prof, &sp, &s, err, sizeof err), 0);
    assert_int_equal(amfi_sim_add(s, &v, err, sizeof err), 0);
    assert_int_equal(amfi_sim_advance(s, n, accel, err, sizeof err), 0);
    amfi_sim_vehicle out;
    assert_int_equal(amfi_sim_pop_done(s, &out), 1);
    amfi_sim_destroy(s);
    return out;
}

/* On a smooth healthy bridge at 25 m/s the mean contact force of each axle
 * while on the span is within 2 % of its static load. */
static void smooth_mean_force(void **state)
{
    (void)state;
    amfi_bridge *b = make_bridge(0.03, 0.0);
    amfi_sim_vehicle v;
    memset(&v, 0, sizeof v);
    amfi_halfcar_baseline(&v.car);
    v.speed_mps = 25.0;
    v.t_entry_s = 100.0 / 25.0;
    double *acc = malloc(sizeof(double) * 6000);
    amfi_sim_vehicle out = cross(b, NULL, v, acc, 6000);
    for (int i = 0; i < 2; i++) {
        double e = out.mean_force_N[i] / v.car.W_N[i] - 1;
        print_message("smooth road, axle %d: mean contact force %.1f N, static %.1f N (%+.3f%%), "
                      "range %.0f .. %.0f N\n",
                      i + 1, out.mean_force_N[i], v.car.W_N[i], 100 * e, out.min_force_N[i],
                      out.max_force_N[i]);
        assert_true(fabs(e) < 0.02);
        assert_int_equal(out.lost_contact_steps[i], 0);
        assert_true(out.on_span_steps[i] > 7900 && out.on_span_steps[i] < 8100);
    }
    free(acc);
    amfi_bridge_destroy(b);
}

/* The same seed gives the same bytes; another gives others. */
static void same_seed_same_output(void **state)
{
    (void)state;
    amfi_bridge *b = make_bridge(0.03, 0.0);
    amfi_profile_params pp;
    amfi_profile_params_default(&pp);
    double *acc[3];
    for (int r = 0; r < 3; r++) {
        amfi_profile *prof;
        pp.seed = r < 2 ? 11 : 12;
        assert_int_equal(amfi_profile_create(&pp, &prof, NULL, 0), 0);
        amfi_sim_vehicle v;
        memset(&v, 0, sizeof v);
        amfi_halfcar_baseline(&v.car);
        v.speed_mps = 25.0;
        v.t_entry_s = 4.0;
        v.track = 5;
        acc[r] = malloc(sizeof(double) * 5500);
        cross(b, prof, v, acc[r], 5500);
        amfi_profile_destroy(prof);
    }
    assert_memory_equal(acc[0], acc[1], sizeof(double) * 5500);
    assert_memory_not_equal(acc[0], acc[2], sizeof(double) * 5500);
    for (int r = 0; r < 3; r++)
        free(acc[r]);
    amfi_bridge_destroy(b);
}

/* A rough road at speed lifts a light vehicle's tyres: the contact force
 * never goes below zero and the lost contact is counted. */
static void contact_loss_reported(void **state)
{
    (void)state;
    amfi_bridge *b = make_bridge(0.03, 0.0);
    amfi_profile_params pp;
    amfi_profile_params_default(&pp);
    pp.iso_class = 'E';
    amfi_profile *prof;
    assert_int_equal(amfi_profile_create(&pp, &prof, NULL, 0), 0);
    amfi_sim_vehicle v;
    memset(&v, 0, sizeof v);
    amfi_halfcar_dist d;
    amfi_halfcar_dist_paper(&d);
    assert_int_equal(amfi_halfcar_from_weights(4000, 2200, 1800, 4.0, &d, NULL, &v.car, NULL, 0),
                     0);
    v.speed_mps = 30.0;
    v.t_entry_s = 100.0 / 30.0;
    v.track = 5;
    double *acc = malloc(sizeof(double) * 5000);
    amfi_sim_vehicle out = cross(b, prof, v, acc, 5000);
    print_message("class E, 4 t at 30 m/s: lost contact %ld + %ld steps, min force %.0f / %.0f N\n",
                  out.lost_contact_steps[0], out.lost_contact_steps[1], out.min_force_N[0],
                  out.min_force_N[1]);
    assert_true(out.lost_contact_steps[0] + out.lost_contact_steps[1] > 0);
    assert_true(out.min_force_N[0] >= 0.0 && out.min_force_N[1] >= 0.0);
    for (int i = 0; i < 5000; i++)
        assert_true(isfinite(acc[i]));
    free(acc);
    amfi_profile_destroy(prof);
    amfi_bridge_destroy(b);
}

/* Two vehicles 0.5 s apart share the bridge; both leave with their truth,
 * and the bridge still vibrates when the second one enters. */
static void two_vehicles(void **state)
{
    (void)state;
    amfi_bridge *b = make_bridge(0.03, 0.0);
    amfi_sim_params sp;
    amfi_sim *s;
    char err[256];
    amfi_sim_params_default(&sp, 20.0);
    assert_int_equal(amfi_sim_create(b, NULL, &sp, &s, err, sizeof err), 0);
    for (int i = 0; i < 2; i++) {
        amfi_sim_vehicle v;
        memset(&v, 0, sizeof v);
        amfi_halfcar_baseline(&v.car);
        v.id = i;
        v.speed_mps = 25.0;
        v.t_entry_s = 4.0 + 0.5 * i;
        assert_int_equal(amfi_sim_add(s, &v, err, sizeof err), 0);
    }
    double *acc = malloc(sizeof(double) * 7000);
    assert_int_equal(amfi_sim_advance(s, 7000, acc, err, sizeof err), 0);
    amfi_sim_vehicle out;
    int n = 0;
    while (amfi_sim_pop_done(s, &out)) {
        for (int a = 0; a < 2; a++)
            assert_true(fabs(out.mean_force_N[a] / out.car.W_N[a] - 1) < 0.03);
        n++;
    }
    assert_int_equal(n, 2);
    assert_int_equal(amfi_sim_busy(s), 0);
    /* Free vibration after both have left (t > 6 s) decays but is not zero. */
    assert_true(fabs(acc[6500]) > 0.0);
    /* Adding a vehicle whose approach has already begun is refused. */
    amfi_sim_vehicle late;
    memset(&late, 0, sizeof late);
    amfi_halfcar_baseline(&late.car);
    late.speed_mps = 25.0;
    late.t_entry_s = amfi_sim_time(s) + 1.0;
    assert_int_equal(amfi_sim_add(s, &late, err, sizeof err), -1);
    assert_non_null(strstr(err, "before now"));
    free(acc);
    amfi_sim_destroy(s);
    amfi_bridge_destroy(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(constant_force_vs_fryba), cmocka_unit_test(static_equilibrium),
        cmocka_unit_test(smooth_mean_force),       cmocka_unit_test(same_seed_same_output),
        cmocka_unit_test(contact_loss_reported),   cmocka_unit_test(two_vehicles),
    };
    return cmocka_run_group_tests_name("vbi", tests, NULL, NULL);
}
