/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_environment.c: the simulated site climate and the modulus law
 * (sim_publisher/environment.c) and the drifting traffic mix
 * (sim_publisher/mix.c): the documented coefficients, continuity at the
 * frost knee, reproducibility, the time compression, a simulated year's
 * temperature range, and the class draw of the mix against the shipped
 * population.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "environment.h"
#include "mix.h"
#include "site.h"
#include "traffic.h"

static void modulus_law(void **state)
{
    amfi_env_params p;
    (void)state;
    amfi_env_params_site(&p);
    assert_float_equal(amfi_env_modulus_factor(&p, p.ref_c), 1.0, 1e-12);
    /* warm branch: −0.25 %/°C */
    assert_float_equal(amfi_env_modulus_factor(&p, 30.0), 1.0 - 0.0025 * 20.0, 1e-12);
    /* continuous at the knee */
    assert_float_equal(amfi_env_modulus_factor(&p, -1e-9), amfi_env_modulus_factor(&p, 0.0),
                       1e-9);
    /* frost: +2 %/°C of the value at 0 °C, constant below the floor */
    const double f0 = amfi_env_modulus_factor(&p, 0.0);
    assert_float_equal(amfi_env_modulus_factor(&p, -5.0), f0 * 1.10, 1e-12);
    assert_float_equal(amfi_env_modulus_factor(&p, -10.0), f0 * 1.20, 1e-12);
    assert_float_equal(amfi_env_modulus_factor(&p, -25.0), f0 * 1.20, 1e-12);
    /* monotone non-increasing over the range of a year */
    double prev = amfi_env_modulus_factor(&p, -30.0);
    for (double t = -30.0; t <= 45.0; t += 0.25) {
        const double f = amfi_env_modulus_factor(&p, t);
        assert_true(f <= prev + 1e-15);
        prev = f;
    }
}

static void air_mean_cycles(void **state)
{
    amfi_env_params p;
    (void)state;
    amfi_env_params_site(&p);
    /* coldest day at the coldest hour (3 a.m., 12 h from 15:00) */
    const double cold = amfi_env_air_mean(&p, p.coldest_day + 3.0 / 24.0);
    assert_float_equal(cold, p.mean_c - p.seasonal_amp_c - p.daily_amp_c, 1e-3);
    /* day 197 (182 days later, the seasonal maximum within 0.01 °C) at the
     * warmest hour */
    const double warm = amfi_env_air_mean(&p, 197.0 + 15.0 / 24.0);
    assert_float_equal(warm, p.mean_c + p.seasonal_amp_c + p.daily_amp_c, 1e-2);
}

static void year_of_weather(double compression, double data_s, uint64_t seed, double *mn,
                            double *mx, double *mean_air, double *last_deck)
{
    amfi_env_params p;
    amfi_env_state s;
    amfi_env_params_site(&p);
    p.compression = compression;
    amfi_env_init(&s, &p, 0.0, seed);
    *mn = 1e9;
    *mx = -1e9;
    double sum = 0.0;
    long n = 0;
    for (double t = 0.0; t <= data_s; t += 3600.0 / compression) {
        amfi_env_advance(&s, t);
        if (s.deck_c < *mn)
            *mn = s.deck_c;
        if (s.deck_c > *mx)
            *mx = s.deck_c;
        sum += s.air_c;
        n++;
    }
    *mean_air = sum / (double)n;
    *last_deck = s.deck_c;
}

static void a_year(void **state)
{
    double mn, mx, mean, last;
    (void)state;
    year_of_weather(1.0, 365.0 * 86400.0, 7, &mn, &mx, &mean, &last);
    /* frost and summer in one year; the mean near the annual mean */
    assert_true(mn < -3.0);
    assert_true(mx > 20.0);
    assert_true(fabs(mean - 9.0) < 1.5);
    assert_true(mn > -40.0 && mx < 50.0);
}

static void reproducible_and_compressed(void **state)
{
    double a[4], b[4], c[4];
    (void)state;
    year_of_weather(1.0, 40.0 * 86400.0, 11, &a[0], &a[1], &a[2], &a[3]);
    year_of_weather(1.0, 40.0 * 86400.0, 11, &b[0], &b[1], &b[2], &b[3]);
    for (int i = 0; i < 4; i++)
        assert_float_equal(a[i], b[i], 0.0);
    /* 40 site days at compression 100 = 9.6 h of data time, same weather */
    year_of_weather(100.0, 40.0 * 86400.0 / 100.0, 11, &c[0], &c[1], &c[2], &c[3]);
    for (int i = 0; i < 4; i++)
        assert_float_equal(a[i], c[i], 1e-9);
    /* another seed, other weather */
    year_of_weather(1.0, 40.0 * 86400.0, 12, &c[0], &c[1], &c[2], &c[3]);
    assert_true(c[3] != a[3]);
}

static void deck_lags_air(void **state)
{
    amfi_env_params p;
    amfi_env_state s;
    (void)state;
    amfi_env_params_site(&p);
    p.weather_std_c = 0.0;
    amfi_env_init(&s, &p, 180.0, 1);
    double amin = 1e9, amax = -1e9, dmin = 1e9, dmax = -1e9;
    for (double t = 0.0; t <= 4 * 86400.0; t += 600.0) {
        amfi_env_advance(&s, t);
        if (t < 2 * 86400.0)
            continue; /* let the lag settle */
        amin = fmin(amin, s.air_c), amax = fmax(amax, s.air_c);
        dmin = fmin(dmin, s.deck_c), dmax = fmax(dmax, s.deck_c);
    }
    /* the deck's daily swing is damped by its 6 h inertia:
     * 1/sqrt(1 + (2π·6/24)²) = 0.54 of the air's */
    const double ratio = (dmax - dmin) / (amax - amin);
    assert_true(ratio > 0.45 && ratio < 0.62);
    /* going back in time changes nothing */
    const double d = s.deck_c;
    amfi_env_advance(&s, 0.0);
    assert_float_equal(s.deck_c, d, 0.0);
}

static void mix_calendar(void **state)
{
    amfi_mix_params p;
    (void)state;
    amfi_mix_params_site(&p);
    assert_int_equal(amfi_mix_weekday(&p, 0.5), 3); /* 2026-01-01 Thursday */
    assert_int_equal(amfi_mix_weekday(&p, 2.0), 5); /* Saturday */
    assert_int_equal(amfi_mix_weekday(&p, 3.9), 6); /* Sunday */
    assert_int_equal(amfi_mix_weekday(&p, 4.0), 0); /* Monday */
    assert_float_equal(amfi_mix_flow_factor(&p, 2.5), p.weekend_flow, 0.0);
    assert_float_equal(amfi_mix_flow_factor(&p, 4.5), 1.0, 0.0);
    /* weekend lower, winter lower than summer */
    assert_true(amfi_mix_loaded_share(&p, 2.5) < amfi_mix_loaded_share(&p, 4.5));
    assert_float_equal(amfi_mix_loaded_share(&p, 15.0 + 5.0), /* Wed 21 Jan, near the min */
                       p.weekday_share - p.seasonal_amp * cos(2 * 3.141592653589793 * 5 / 365.25),
                       1e-12);
    assert_true(amfi_mix_loaded_share(&p, 197.0) > amfi_mix_loaded_share(&p, 15.0 + 6.0));
    p.weekday_share = 0.99;
    assert_float_equal(amfi_mix_loaded_share(&p, 197.0), 0.98, 0.0);
}

static void mix_draw(void **state)
{
    amfi_vehicle_rec *recs = NULL;
    int n = 0;
    char err[256];
    amfi_mix_classes c;
    (void)state;
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population.csv", &recs, &n, err,
                                       sizeof err), 0);
    const double med = amfi_mix_median_gvw(recs, n);
    assert_true(med > 8000 && med < 9500);
    assert_int_equal(amfi_mix_classify(recs, n, med, &c, err, sizeof err), 0);
    assert_int_equal(c.n_empty + c.n_loaded, n);
    for (int i = 0; i < c.n_loaded; i++)
        assert_true(recs[c.loaded[i]].gvw_kg >= med);
    for (int i = 0; i < c.n_empty; i++)
        assert_true(recs[c.empty[i]].gvw_kg < med);
    /* a share equal to the population's loaded fraction reproduces its mean;
     * a higher share raises it and widens the loaded tail */
    const double frac = (double)c.n_loaded / n;
    double pop = 0.0, same = 0.0, more = 0.0;
    for (int i = 0; i < n; i++)
        pop += recs[i].gvw_kg / n;
    uint64_t x = 99;
    const int draws = 200000;
    for (int i = 0; i < draws; i++) {
        double u[3];
        for (int k = 0; k < 3; k++) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            u[k] = (double)(x >> 11) / 9007199254740992.0;
        }
        same += recs[amfi_mix_pick(&c, frac, u[0], u[1])].gvw_kg / draws;
        more += recs[amfi_mix_pick(&c, frac + 0.1, u[0], u[2])].gvw_kg / draws;
    }
    assert_true(fabs(same - pop) < 20.0);
    assert_true(more > pop + 200.0);
    /* the extremes of the uniforms stay in range */
    assert_int_equal(amfi_mix_pick(&c, 1.0, 0.0, 0.999999999999), c.loaded[c.n_loaded - 1]);
    assert_int_equal(amfi_mix_pick(&c, 0.0, 0.5, 0.0), c.empty[0]);
    amfi_mix_classes_free(&c);
    amfi_mix_classes_free(&c); /* idempotent */
    /* a split that leaves a class empty is refused with the reason */
    assert_int_equal(amfi_mix_classify(recs, n, 1e6, &c, err, sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "no loaded vehicle"));
    assert_null(c.loaded);
    amfi_traffic_free(recs);
}

/* The split per vehicle class: the shipped two-axle population (one class)
 * splits exactly as at its median; in the heavy traffic by class every
 * class is split at its own median, so that the loaded and the empty draws
 * both keep the classes' shares. */
static void mix_by_class(void **state)
{
    amfi_vehicle_rec *recs = NULL;
    int n = 0;
    char err[256];
    amfi_mix_classes a, b;
    (void)state;
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population.csv", &recs, &n, err,
                                       sizeof err), 0);
    assert_int_equal(amfi_mix_classify(recs, n, amfi_mix_median_gvw(recs, n), &a, err,
                                       sizeof err), 0);
    assert_int_equal(amfi_mix_classify_by_class(recs, n, &b, err, sizeof err), 0);
    assert_int_equal(a.n_loaded, b.n_loaded);
    assert_int_equal(a.n_empty, b.n_empty);
    assert_memory_equal(a.loaded, b.loaded, sizeof(int) * (size_t)a.n_loaded);
    amfi_mix_classes_free(&a);
    amfi_mix_classes_free(&b);
    amfi_traffic_free(recs);
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population-eu.csv", &recs, &n, err,
                                       sizeof err), 0);
    assert_int_equal(amfi_mix_classify_by_class(recs, n, &b, err, sizeof err), 0);
    int pop[16] = {0}, ld[16] = {0}, em[16] = {0};
    for (int i = 0; i < n; i++)
        pop[recs[i].vclass]++;
    for (int i = 0; i < b.n_loaded; i++)
        ld[recs[b.loaded[i]].vclass]++;
    for (int i = 0; i < b.n_empty; i++)
        em[recs[b.empty[i]].vclass]++;
    for (int k = 0; k < 16; k++) {
        if (!pop[k])
            continue;
        /* each class about half loaded, so each draw keeps its share */
        assert_true(abs(ld[k] - em[k]) <= 1);
        assert_true(fabs((double)ld[k] / b.n_loaded - (double)pop[k] / n) < 0.005);
    }
    /* with one split for all, the loaded draw would be mostly articulated */
    amfi_mix_classes c;
    assert_int_equal(amfi_mix_classify(recs, n, amfi_mix_median_gvw(recs, n), &c, err,
                                       sizeof err), 0);
    int r2 = 0;
    for (int i = 0; i < c.n_loaded; i++)
        r2 += recs[c.loaded[i]].vclass == 0;
    print_message("two-axle share of the loaded draw: %.1f %% split per class, %.1f %% at the "
                  "population's median (population %.1f %%)\n",
                  100.0 * ld[0] / b.n_loaded, 100.0 * r2 / c.n_loaded, 100.0 * pop[0] / n);
    assert_true((double)r2 / c.n_loaded < 0.5 * pop[0] / n);
    amfi_mix_classes_free(&b);
    amfi_mix_classes_free(&c);
    amfi_traffic_free(recs);
}

/* The streaming site: calendar from the start utime, the modulus-scaled
 * bridges (first circular frequency ∝ sqrt(E)) and their cache. */
static void site_stream(void **state)
{
    amfi_vehicle_rec *recs = NULL;
    int n = 0;
    char err[256];
    amfi_site s;
    amfi_bridge_params bp;
    (void)state;
    amfi_bridge_params_paper20(&bp);
    bp.damage = 0.3; /* ignored: the damage is the caller's */
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population.csv", &recs, &n, err,
                                       sizeof err), 0);
    /* 2026-01-01T12:00Z, a Thursday */
    assert_int_equal(amfi_site_init(&s, &bp, recs, n, 1767268800000000LL, 365.0, 5, err,
                                    sizeof err), 0);
    assert_float_equal(s.day0, 0.5, 1e-12);
    assert_int_equal(s.mix.day0_weekday, 3);
    assert_float_equal(amfi_site_day(&s, 86400.0), 365.5, 1e-9);
    const amfi_bridge *b0 = amfi_site_bridge_at(&s, 0.0, 0.0, err, sizeof err);
    assert_non_null(b0);
    assert_float_equal(amfi_bridge_params_of(b0)->damage, 0.0, 0.0); /* damage from the caller */
    const double f = amfi_env_modulus_factor(&s.env.p, s.env.deck_c);
    const double E = amfi_bridge_params_of(b0)->E_pa;
    assert_true(fabs(E / bp.E_pa - f) <= AMFI_SITE_MODULUS_STEP / 2 + 1e-12);
    /* same instant, same bridge; damaged is another one */
    assert_ptr_equal(amfi_site_bridge_at(&s, 0.0, 0.0, err, sizeof err), b0);
    const amfi_bridge *bd = amfi_site_bridge_at(&s, 0.0, 0.1, err, sizeof err);
    assert_non_null(bd);
    assert_ptr_not_equal(bd, b0);
    /* half a year on (compressed: 12 h of data): another modulus, frequency ∝ sqrt(E) */
    const amfi_bridge *b1 = amfi_site_bridge_at(&s, 0.5 * 86400.0, 0.0, err, sizeof err);
    assert_non_null(b1);
    const double E1 = amfi_bridge_params_of(b1)->E_pa;
    assert_true(E1 != E);
    assert_float_equal(amfi_bridge_omega(b1)[0] / amfi_bridge_omega(b0)[0], sqrt(E1 / E), 1e-6);
    /* the draw is reproducible and in range */
    for (long i = 0; i < 1000; i++) {
        const int r = amfi_site_pick(&s, 5, i, 60.0 * i);
        assert_true(r >= 0 && r < n);
        assert_int_equal(r, amfi_site_pick(&s, 5, i, 60.0 * i));
    }
    amfi_site_free(&s);
    amfi_site_free(&s);
    /* a compression below 1 is refused */
    assert_int_equal(amfi_site_init(&s, &bp, recs, n, 1767268800000000LL, 0.5, 5, err,
                                    sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "compression"));
    amfi_traffic_free(recs);
}

/* A bridge with segments (their own E·I): the deck temperature's modulus
 * scales the segments' E·I like the beam's, so a span made wholly of one
 * segment equal to the uniform section has the uniform bridge's frequencies
 * at every temperature. */
static void site_segments(void **state)
{
    amfi_vehicle_rec *recs = NULL;
    int n = 0;
    char err[256];
    amfi_site su, sg;
    amfi_bridge_params bu, bg;
    (void)state;
    amfi_bridge_params_paper20(&bu);
    bg = bu;
    bg.n_segments = 1;
    bg.segments[0] = (amfi_segment){0.0, bu.span_m, bu.E_pa * bu.I_m4, bu.density_kgm3 * bu.A_m2};
    bg.E_pa = 2.0 * bu.E_pa; /* covered by the segment everywhere: no effect */
    assert_int_equal(amfi_traffic_read(AMFI_SIM_DATA_DIR "/population.csv", &recs, &n, err,
                                       sizeof err), 0);
    assert_int_equal(amfi_site_init(&su, &bu, recs, n, 1767268800000000LL, 365.0, 5, err,
                                    sizeof err), 0);
    assert_int_equal(amfi_site_init(&sg, &bg, recs, n, 1767268800000000LL, 365.0, 5, err,
                                    sizeof err), 0);
    for (int k = 0; k < 4; k++) {
        const double t = k * 0.125 * 86400.0; /* a season apart (compressed) */
        const amfi_bridge *a = amfi_site_bridge_at(&su, t, 0.0, err, sizeof err);
        const amfi_bridge *b = amfi_site_bridge_at(&sg, t, 0.0, err, sizeof err);
        assert_non_null(a);
        assert_non_null(b);
        const double f = amfi_env_modulus_factor(&su.env.p, su.env.deck_c);
        if (k == 0)
            assert_true(fabs(f - 1.0) > 0.01); /* the check below means something */
        assert_float_equal(amfi_bridge_omega(b)[0] / amfi_bridge_omega(a)[0], 1.0, 1e-9);
    }
    amfi_site_free(&su);
    amfi_site_free(&sg);
    amfi_traffic_free(recs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(modulus_law),     cmocka_unit_test(air_mean_cycles),
        cmocka_unit_test(a_year),          cmocka_unit_test(reproducible_and_compressed),
        cmocka_unit_test(deck_lags_air),   cmocka_unit_test(mix_calendar),
        cmocka_unit_test(mix_draw),        cmocka_unit_test(mix_by_class),
        cmocka_unit_test(site_stream),     cmocka_unit_test(site_segments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
