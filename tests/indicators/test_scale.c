/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_scale.c: the scale indicator (indicators/scale.c) and its CUSUM
 * (indicators/cusum.c): Siegmund's ARL against its closed form and against
 * a Monte Carlo run length, the threshold as its inverse, the CUSUM
 * recursion by hand, parameter checks naming the field, the class
 * estimator (a stretch is found, a change of the loaded share is not taken
 * for one), the temperature model (the data decide where the baseline
 * covers a side of the knee, the prior where it does not), input
 * rejection, and streams with a seasonal deck temperature and a drifting
 * mix: no alert while healthy, a 10 % loss raised within days, the alert
 * cleared when the loss goes. The known-truck indicator
 * (indicators/known_truck.c): its baseline, compensation, CUSUM and alert.
 * Fixed seeds; a few seconds.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cusum.h"
#include "known_truck.h"
#include "scale.h"

#define SPLIT 8765.0
#define PI 3.14159265358979323846

/* A true GVW of the shipped population's law, loaded with probability
 * `share` (amfi-year-sim's model), plus a 0.3 t measurement error. */
static double draw(gsl_rng *r, double share)
{
    const int loaded = gsl_rng_uniform(r) < share;
    double x;
    do
        x = SPLIT + gsl_ran_gaussian_ziggurat(r, 1960.0);
    while (x < 4000 || x > 15000 || (x >= SPLIT) != loaded);
    return x + gsl_ran_gaussian_ziggurat(r, 300.0);
}

/* The modulus factor E(T)/E(10 °C) of docs/simulator.md, written out again
 * here (−0.25 %/°C above 0, +2 %/°C below, flat below −10 °C). */
static double modulus(double t)
{
    if (t >= 0)
        return 1.0 - 0.0025 * (t - 10.0);
    if (t < -10)
        t = -10;
    return 1.025 * (1.0 - 0.02 * t);
}

static gsl_rng *rng(unsigned long seed)
{
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(r);
    gsl_rng_set(r, seed);
    return r;
}

static amfi_scale *make(const amfi_scale_params *p)
{
    char err[256] = "";
    amfi_scale *s = NULL;
    if (amfi_scale_create(p, &s, err, sizeof err))
        fail_msg("create: %s", err);
    assert_non_null(s);
    return s;
}

/* --- CUSUM --- */

static void test_cusum_arl(void **state)
{
    (void)state;
    /* the closed form, and its Δ = 0 limit b² */
    const double k = 0.5, h = 4.0, b = h + 1.166, d = -k;
    const double want = (exp(-2 * d * b) + 2 * d * b - 1) / (2 * d * d);
    assert_true(fabs(amfi_cusum_arl(k, h, 0.0) - want) < 1e-9 * want);
    assert_true(fabs(amfi_cusum_arl(k, h, k) - b * b) < 1e-9);
    assert_true(fabs(amfi_cusum_arl(k, h, k + 1e-7) - b * b) < 1e-3);
    /* the threshold is its inverse, with and without a margin */
    for (double arl0 = 10; arl0 < 1e6; arl0 *= 7) {
        const double t = amfi_cusum_threshold(k, arl0, 0.0);
        assert_true(t >= 0);
        assert_true(fabs(amfi_cusum_arl(k, t, 0.0) - arl0) < 1e-6 * arl0);
        const double tm = amfi_cusum_threshold(k, arl0, 0.2);
        assert_true(tm > t);
        assert_true(fabs(amfi_cusum_arl(k, tm, 0.2) - arl0) < 1e-6 * arl0);
    }
    assert_true(amfi_cusum_threshold(0.0, 100, 0) < 0);
    assert_true(amfi_cusum_threshold(0.5, 0.5, 0) < 0);
    assert_true(amfi_cusum_threshold(0.5, 100, 0.5) < 0);
    assert_true(amfi_cusum_threshold(0.5, NAN, 0) < 0);
    assert_true(amfi_cusum_threshold(0.5, 1.0, 0) == 0.0);
}

/* Siegmund's approximation against simulated run lengths (N(0,1) and a
 * shift of 1): within 10 % (its known accuracy for h of a few SD). */
static void test_cusum_siegmund_mc(void **state)
{
    (void)state;
    gsl_rng *r = rng(11);
    const double k = 0.5, h = 4.0;
    for (int shifted = 0; shifted <= 1; shifted++) {
        const double mu = shifted ? 1.0 : 0.0;
        const int runs = shifted ? 20000 : 3000;
        double sum = 0;
        for (int i = 0; i < runs; i++) {
            amfi_cusum c;
            amfi_cusum_init(&c, k, h);
            while (!amfi_cusum_add(&c, mu + gsl_ran_gaussian_ziggurat(r, 1.0)))
                ;
            sum += (double)c.n;
        }
        const double mc = sum / runs, ap = amfi_cusum_arl(k, h, mu);
        if (fabs(mc - ap) > 0.1 * mc)
            fail_msg("mu %g: simulated ARL %.1f, Siegmund %.1f", mu, mc, ap);
    }
    gsl_rng_free(r);
}

static void test_cusum_recursion(void **state)
{
    (void)state;
    amfi_cusum c;
    amfi_cusum_init(&c, 0.5, 2.0);
    assert_int_equal(amfi_cusum_add(&c, 1.0), 0); /* 0.5 */
    assert_true(fabs(c.s - 0.5) < 1e-15);
    assert_int_equal(amfi_cusum_add(&c, -3.0), 0); /* max(0, 0.5 − 3.5) */
    assert_true(c.s == 0.0);
    assert_int_equal(amfi_cusum_add(&c, 1.7), 0); /* 1.2 */
    assert_int_equal(amfi_cusum_add(&c, 1.3), 1); /* 2.0 >= h */
    assert_true(fabs(c.s - 2.0) < 1e-12);
    assert_int_equal((int)c.n, 4);
    amfi_cusum_reset(&c);
    assert_true(c.s == 0.0 && c.n == 0);
}

/* --- parameters --- */

/* One broken parameter f = value in p (a copy of the defaults d): create
 * refuses it with a message naming it and leaves *out NULL, the check names
 * it in `field`. */
#define EXPECT_BAD_PARAM(f, value, create_call, out, check_call)                             \
    do {                                                                                      \
        p = d;                                                                                \
        p.f = value;                                                                          \
        out = (void *)&p;                                                                     \
        err[0] = '\0';                                                                        \
        assert_int_equal(create_call, AMFI_IND_EINVAL);                                       \
        assert_null(out);                                                                     \
        if (strstr(err, #f) == NULL)                                                          \
            fail_msg("%s = %s: message '%s' does not name it", #f, #value, err);              \
        field = NULL;                                                                         \
        assert_int_equal(check_call, AMFI_IND_EINVAL);                                        \
        assert_string_equal(field, #f);                                                       \
    } while (0)


static void test_params(void **state)
{
    (void)state;
    amfi_scale_params d, p;
    amfi_scale_params_default(&d);
    assert_int_equal(amfi_scale_params_check(&d, NULL, NULL, 0), AMFI_IND_OK);
    amfi_scale *s = make(&d);
    assert_string_equal(amfi_scale_state(s), "baseline");
    assert_int_equal(amfi_scale_has_baseline(s), 0);
    amfi_scale_model m;
    assert_int_equal(amfi_scale_get_model(s, &m), AMFI_IND_EINVAL);
    amfi_scale_destroy(s);
    amfi_scale_destroy(NULL);
    char err[256];
    const char *field;
#define EXPECT_BAD(f, value)                                                                  \
    EXPECT_BAD_PARAM(f, value, amfi_scale_create(&p, &s, err, sizeof err), s,                   \
                     amfi_scale_params_check(&p, &field, NULL, 0))
    EXPECT_BAD(block, 49);
    EXPECT_BAD(baseline_blocks, 3);
    EXPECT_BAD(class_split_kg, 0.0);
    EXPECT_BAD(class_split_kg, NAN);
    EXPECT_BAD(share_range, 0.0);
    EXPECT_BAD(share_range, 1.5);
    EXPECT_BAD(ref_c, 50.0);
    EXPECT_BAD(knee_c, INFINITY);
    EXPECT_BAD(floor_c, 0.0);
    EXPECT_BAD(warm_slope, 0.2);
    EXPECT_BAD(frost_slope, NAN);
    EXPECT_BAD(slope_prior_sd, -0.001);
    EXPECT_BAD(design_shift, 0.0);
    EXPECT_BAD(design_shift, 0.5);
    EXPECT_BAD(false_alarms_per_year, 0.0);
    EXPECT_BAD(vehicles_per_day, 0.0);
    EXPECT_BAD(clear_after, 0);
#undef EXPECT_BAD
    assert_int_equal(amfi_scale_create(NULL, &s, err, sizeof err), AMFI_IND_EINVAL);
    assert_null(s);
    assert_int_equal(amfi_scale_create(&d, NULL, NULL, 0), AMFI_IND_EINVAL);
}

/* --- the class estimator --- */

static void test_estimator(void **state)
{
    (void)state;
    enum { NB = 20000, B = 500, R = 60 };
    static double base[NB], blk[B];
    static amfi_scale_ref ref;
    gsl_rng *r = rng(5);
    for (int i = 0; i < NB; i++)
        base[i] = draw(r, 0.5);
    assert_int_equal(amfi_scale_ref_fit(&ref, base, NB, SPLIT, 0.15), AMFI_IND_OK);
    assert_true(fabs(ref.pi - 0.5) < 0.02);
    /* a stretch by 1.05 is measured as such, on average over blocks */
    double m = 0, m_lo = 0, m_hi = 0, pi_lo = 0, pi_hi = 0, pi, mean_lo = 0, mean_hi = 0;
    for (int k = 0; k < R; k++) {
        for (int i = 0; i < B; i++)
            blk[i] = 1.05 * draw(r, 0.5);
        m += amfi_scale_ref_block_log(&ref, blk, B, NULL) / R;
        for (int i = 0; i < B; i++) {
            blk[i] = draw(r, 0.37);
            mean_lo += log(blk[i]) / (B * R);
        }
        m_lo += amfi_scale_ref_block_log(&ref, blk, B, &pi) / R;
        pi_lo += pi / R;
        for (int i = 0; i < B; i++) {
            blk[i] = draw(r, 0.62);
            mean_hi += log(blk[i]) / (B * R);
        }
        m_hi += amfi_scale_ref_block_log(&ref, blk, B, &pi) / R;
        pi_hi += pi / R;
    }
    if (fabs(m - log(1.05)) > 0.01)
        fail_msg("stretch 1.05: mean ln s %.4f, want %.4f", m, log(1.05));
    /* a share moving from 0.37 to 0.62 moves the mean of a block by about
     * 7 %; the class estimator moves by less than a quarter of that (1.5 %
     * at most) and follows the share instead */
    if (fabs(m_hi - m_lo) > 0.015 || fabs(m_hi - m_lo) > 0.25 * (mean_hi - mean_lo))
        fail_msg("share 0.37 → 0.62 moved ln s by %.4f, the ratio of means by %.4f",
                 m_hi - m_lo, mean_hi - mean_lo);
    assert_true(pi_lo < 0.42 && pi_hi > 0.57);
    /* degenerate inputs */
    assert_true(isnan(amfi_scale_ref_block_log(&ref, blk, 1, NULL)));
    for (int i = 0; i < 10; i++)
        base[i] = 1000.0 + i;
    assert_int_equal(amfi_scale_ref_fit(&ref, base, 10, SPLIT, 0.15), AMFI_IND_EINVAL);
    assert_int_equal(amfi_scale_ref_fit(&ref, base, 10, 1005.0, 0.0), AMFI_IND_EINVAL);
    gsl_rng_free(r);
}

/* --- the temperature model --- */

/* Feed the baseline: deck temperature t_mean ± t_amp over a 2-day cycle,
 * inferred GVW = true / g(T) with g(T) = exp(−slope · (T − 10)) above 0. */
static amfi_scale *baseline(gsl_rng *r, amfi_scale_params *p, double t_mean, double t_amp,
                            double warm)
{
    amfi_scale *s = make(p);
    const long n = (long)p->block * p->baseline_blocks;
    amfi_scale_eval ev;
    for (long i = 0; i < n; i++) {
        const double t = t_mean + t_amp * sin(2 * PI * (double)i / 4000.0);
        const double g = draw(r, 0.5) * exp(warm * (t - 10.0));
        const int rc = amfi_scale_push(s, g, t, &ev, NULL);
        assert_true(rc >= 0);
        if (i < n - 1)
            assert_int_equal(rc, 0);
        else {
            assert_int_equal(rc, AMFI_IND_BASELINE);
            assert_string_equal(ev.state, "baseline");
        }
    }
    assert_int_equal(amfi_scale_has_baseline(s), 1);
    return s;
}

static void test_temperature_fit(void **state)
{
    (void)state;
    gsl_rng *r = rng(7);
    amfi_scale_params p;
    amfi_scale_model m;
    amfi_scale_params_default(&p);
    /* a warm baseline spanning 5 .. 35 °C whose true slope (0.006) is far
     * from the prior (0.0025): the data decide; no frost in it: the frost
     * slope is the prior exactly */
    amfi_scale *s = baseline(r, &p, 20.0, 15.0, 0.006);
    assert_int_equal(amfi_scale_get_model(s, &m), AMFI_IND_OK);
    if (fabs(m.warm_slope - 0.006) > 0.0012)
        fail_msg("warm slope %.5f, want 0.006", m.warm_slope);
    assert_true(m.frost_slope == p.frost_slope);
    assert_true(m.t_min_c >= 5.0 - 1e-9 && m.t_max_c <= 35.0 + 1e-9);
    assert_true(m.sigma0 > 0.005 && m.sigma0 < 0.05);
    assert_true(m.sigma0 >= m.sigma_resid && m.sigma0 >= m.sigma_boot);
    assert_true(m.h > 0 && m.k_ref > 0);
    amfi_scale_destroy(s);
    /* slopes fixed (prior SD 0): the prior stands whatever the data say */
    p.slope_prior_sd = 0.0;
    s = baseline(r, &p, 20.0, 15.0, 0.006);
    assert_int_equal(amfi_scale_get_model(s, &m), AMFI_IND_OK);
    assert_true(m.warm_slope == p.warm_slope && m.frost_slope == p.frost_slope);
    amfi_scale_destroy(s);
    gsl_rng_free(r);
}

static void test_reject(void **state)
{
    (void)state;
    amfi_scale_params p;
    amfi_scale_params_default(&p);
    p.block = 50;
    p.baseline_blocks = 4;
    amfi_scale *s = make(&p);
    const double bad_g[] = {NAN, INFINITY, 0.0, -1.0, 2e7};
    for (size_t i = 0; i < sizeof bad_g / sizeof bad_g[0]; i++)
        assert_int_equal(amfi_scale_push(s, bad_g[i], 10.0, NULL, NULL), AMFI_IND_EINVAL);
    const double bad_t[] = {NAN, -INFINITY, -60.5, 90.5};
    for (size_t i = 0; i < sizeof bad_t / sizeof bad_t[0]; i++)
        assert_int_equal(amfi_scale_push(s, 9000.0, bad_t[i], NULL, NULL), AMFI_IND_EINVAL);
    /* nothing entered: the baseline still needs all of its 200 vehicles */
    gsl_rng *r = rng(3);
    for (int i = 0; i < 199; i++)
        assert_int_equal(amfi_scale_push(s, draw(r, 0.5), 10.0, NULL, NULL), 0);
    assert_int_equal(amfi_scale_push(s, draw(r, 0.5), 10.0, NULL, NULL), AMFI_IND_BASELINE);
    amfi_scale_destroy(s);
    /* a degenerate baseline (no loaded vehicle: one class empty) is dropped
     * and collected again */
    s = make(&p);
    for (int i = 0; i < 400; i++)
        assert_int_equal(amfi_scale_push(s, 5000.0 + i, 10.0, NULL, NULL), 0);
    assert_int_equal(amfi_scale_has_baseline(s), 0);
    assert_string_equal(amfi_scale_state(s), "baseline");
    for (int i = 0; i < 199; i++)
        assert_int_equal(amfi_scale_push(s, draw(r, 0.5), 10.0, NULL, NULL), 0);
    assert_int_equal(amfi_scale_push(s, draw(r, 0.5), 10.0, NULL, NULL), AMFI_IND_BASELINE);
    gsl_rng_free(r);
    amfi_scale_destroy(s);
}

/* --- streams --- */

/* A site-like stream: deck temperature over `days` days from day0 (a
 * seasonal cosine, coldest on day 15, 9 ± 11 °C, plus a daily ±4 °C), the
 * loaded share 0.46 ± 0.06 on a weekly cycle, 2000 vehicles a day; a loss d
 * from vehicle n_d on and back to 0 from n_heal on. Returns the vehicle
 * index of the first scale_shift raise (−1 none) and counts the events. */
typedef struct {
    long first_raise, raises, clears, last_clear;
} stream_out;

static stream_out stream(amfi_scale *s, gsl_rng *r, double day0, double days, double d,
                         long n_d, long n_heal)
{
    stream_out o = {-1, 0, 0, -1};
    const long n = (long)(days * 2000);
    for (long i = 0; i < n; i++) {
        const double day = day0 + i / 2000.0;
        const double t = 9.0 - 11.0 * cos(2 * PI * (day - 15.0) / 365.0) +
                         4.0 * sin(2 * PI * day);
        const double share = 0.46 + 0.06 * sin(2 * PI * day / 7.0);
        const double loss = i >= n_d && i < n_heal ? d : 0.0;
        const double g = draw(r, share) / ((1 - loss) * modulus(t));
        amfi_alert_event ev;
        amfi_scale_eval e;
        const int rc = amfi_scale_push(s, g, t, &e, &ev);
        assert_true(rc >= 0);
        if (rc & AMFI_IND_EVAL) {
            assert_true(e.n == 500 && isfinite(e.scale) && isfinite(e.raw_scale));
            assert_true(e.cusum >= 0);
        }
        if (rc & AMFI_IND_ALERT) {
            assert_string_equal(ev.kind, "scale_shift");
            assert_string_equal(ev.level, "warning");
            assert_non_null(strstr(ev.message, "scale of inferred GVW"));
            if (ev.raised) {
                o.raises++;
                if (o.first_raise < 0)
                    o.first_raise = i;
                assert_string_equal(amfi_scale_state(s), "alert");
            } else {
                o.clears++;
                o.last_clear = i;
                assert_string_equal(amfi_scale_state(s), e.cusum > 0 ? "watch" : "normal");
            }
        }
    }
    return o;
}

/* Healthy through autumn and winter frost (commissioned in September):
 * no alert over 120 days. Then a 10 % loss: raised within 2 days. */
static void test_stream_winter(void **state)
{
    (void)state;
    gsl_rng *r = rng(21);
    amfi_scale_params p;
    amfi_scale_params_default(&p);
    amfi_scale *s = make(&p);
    stream_out o = stream(s, r, 250.0, 120.0, 0.0, 0, 0);
    if (o.raises)
        fail_msg("healthy: %ld raises, first at vehicle %ld", o.raises, o.first_raise);
    const long n_d = 1000;
    o = stream(s, r, 10.0, 4.0, 0.10, n_d, 1L << 40);
    if (o.first_raise < n_d || o.first_raise > n_d + 2 * 2000)
        fail_msg("10 %%: first raise at vehicle %ld (damage at %ld)", o.first_raise, n_d);
    amfi_scale_destroy(s);
    gsl_rng_free(r);
}

/* A 10 % loss that goes again after 2 days (a hand-made event): raised,
 * then cleared within 18 days (S capped at h drains at about k_ref a
 * block, then clear_after blocks at S = 0);
 * set_alerted restores the state after a restart. */
static void test_stream_clear(void **state)
{
    (void)state;
    gsl_rng *r = rng(23);
    amfi_scale_params p;
    amfi_scale_params_default(&p);
    p.baseline_blocks = 20;
    amfi_scale *s = make(&p);
    (void)stream(s, r, 150.0, 6.0, 0.0, 0, 0);
    assert_int_equal(amfi_scale_has_baseline(s), 1);
    stream_out o = stream(s, r, 156.0, 20.0, 0.10, 0, 4000);
    assert_int_equal(o.raises, 1);
    assert_int_equal(o.clears, 1);
    assert_true(o.first_raise < 4000 && o.last_clear > 4000);
    amfi_scale_set_alerted(s, 1);
    assert_string_equal(amfi_scale_state(s), "alert");
    amfi_scale_set_alerted(s, 0);
    assert_string_equal(amfi_scale_state(s), "normal");
    amfi_scale_destroy(s);
    gsl_rng_free(r);
}

/* --- known-truck runs --- */

static void test_known_truck(void **state)
{
    (void)state;
    amfi_known_truck_params d, p;
    amfi_scale_params tp;
    amfi_known_truck_params_default(&d);
    amfi_scale_params_default(&tp);
    amfi_known_truck *k = NULL;
    char err[256];
    const char *field;
#define EXPECT_BAD(f, value)                                                                  \
    EXPECT_BAD_PARAM(f, value, amfi_known_truck_create(&p, &tp, &k, err, sizeof err), k,        \
                     amfi_known_truck_params_check(&p, &field, NULL, 0))
    EXPECT_BAD(baseline_runs, 1);
    EXPECT_BAD(run_sd, 0.0);
    EXPECT_BAD(design_shift, NAN);
    EXPECT_BAD(false_alarms_per_year, -1.0);
    EXPECT_BAD(runs_per_year, 0.5);
    EXPECT_BAD(clear_after, 0);
#undef EXPECT_BAD
    tp.floor_c = 5.0; /* above the knee: the temperature model is checked too */
    assert_int_equal(amfi_known_truck_create(&d, &tp, &k, err, sizeof err), AMFI_IND_EINVAL);
    assert_non_null(strstr(err, "floor_c"));
    amfi_scale_params_default(&tp);
    if (amfi_known_truck_create(&d, &tp, &k, err, sizeof err))
        fail_msg("create: %s", err);
    amfi_known_truck_destroy(NULL);
    assert_string_equal(amfi_known_truck_state(k), "baseline");
    assert_int_equal(amfi_known_truck_push(k, NAN, 14000, 10, NULL, NULL), AMFI_IND_EINVAL);
    assert_int_equal(amfi_known_truck_push(k, 14000, 0, 10, NULL, NULL), AMFI_IND_EINVAL);
    assert_int_equal(amfi_known_truck_push(k, 14000, 14000, 95, NULL, NULL), AMFI_IND_EINVAL);
    assert_int_equal(amfi_known_truck_set_slopes(k, NAN, 0.01), AMFI_IND_EINVAL);

    /* the baseline: 4 runs at different deck temperatures of a bridge that
     * follows the prior model exactly: compensated ratios all 1.01 */
    const double temps[] = {-8.0, 3.0, 18.0, 31.0};
    amfi_known_truck_eval e;
    amfi_alert_event ev;
    for (int i = 0; i < 4; i++) {
        const double f = amfi_scale_temp_factor(&tp, tp.warm_slope, tp.frost_slope, temps[i]);
        const int rc = amfi_known_truck_push(k, 14000 * 1.01 / f, 14000, temps[i], &e, &ev);
        assert_int_equal(rc, i < 3 ? AMFI_IND_EVAL : AMFI_IND_EVAL | AMFI_IND_BASELINE);
        assert_true(fabs(e.ratio_comp - 1.01) < 1e-12);
        assert_string_equal(e.state, "baseline");
    }
    /* no scatter in the baseline: sigma is the a-priori run_sd */
    assert_true(fabs(e.sigma - d.run_sd) < 1e-15);
    assert_true(fabs(e.baseline_ratio - 1.01) < 1e-12);
    /* h from Siegmund: the ARL at the margin 1/sqrt(4) is 52 / 0.2 runs */
    const double kr = log(1 / 0.95) / (2 * d.run_sd);
    assert_true(fabs(amfi_cusum_arl(kr, e.h, 0.5) - 260.0) < 1e-6 * 260.0);
    /* a 5 % loss (1/0.95 on the ratio) at a frosty −5 °C: z = ln(1/0.95)/0.02
     * = 2.56, S grows by z − k_ref = 1.28 a run: raised on the run where S >= h */
    const int want = (int)ceil(e.h / kr);
    int raised_at = -1;
    for (int i = 1; i <= 10 && raised_at < 0; i++) {
        const double f = amfi_scale_temp_factor(&tp, tp.warm_slope, tp.frost_slope, -5.0);
        const int rc = amfi_known_truck_push(k, 14000 * 1.01 / (0.95 * f), 14000, -5.0, &e, &ev);
        assert_true(rc & AMFI_IND_EVAL);
        assert_true(fabs(e.z - log(1 / 0.95) / d.run_sd) < 1e-9);
        if (rc & AMFI_IND_ALERT) {
            assert_int_equal(ev.raised, 1);
            assert_string_equal(ev.kind, "known_truck");
            assert_string_equal(ev.level, "warning");
            raised_at = i;
        }
    }
    assert_int_equal(raised_at, want);
    assert_true(want <= 3);
    assert_string_equal(amfi_known_truck_state(k), "alert");
    /* healed: S (capped at h) falls by k_ref + 0 a run, then 2 runs at 0 clear */
    int cleared_at = -1;
    for (int i = 1; i <= 20 && cleared_at < 0; i++) {
        const int rc = amfi_known_truck_push(k, 14000 * 1.01 / amfi_scale_temp_factor(&tp,
                                                     tp.warm_slope, tp.frost_slope, 12.0),
                                             14000, 12.0, &e, &ev);
        if (rc & AMFI_IND_ALERT) {
            assert_int_equal(ev.raised, 0);
            cleared_at = i;
        }
    }
    assert_int_equal(cleared_at, (int)ceil(e.h / kr - 1e-9) + d.clear_after);
    assert_string_equal(amfi_known_truck_state(k), "normal");
    amfi_known_truck_set_alerted(k, 1);
    assert_string_equal(amfi_known_truck_state(k), "alert");
    amfi_known_truck_destroy(k);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cusum_arl),
        cmocka_unit_test(test_cusum_siegmund_mc),
        cmocka_unit_test(test_cusum_recursion),
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_estimator),
        cmocka_unit_test(test_temperature_fit),
        cmocka_unit_test(test_reject),
        cmocka_unit_test(test_stream_winter),
        cmocka_unit_test(test_stream_clear),
        cmocka_unit_test(test_known_truck),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
