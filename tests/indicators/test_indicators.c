/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_indicators.c: amfid's damage indicator engine (indicators/indicators.c):
 * parameter checks, the automatic and explicit baselines, prefill, the
 * evaluation cadence, the window statistics against a naive recomputation,
 * the F and Welch p-values against hand-computed closed forms, the
 * raise/clear hysteresis and debounce, the mean-shift kind, input
 * rejection, and the defaults on simulated streams (a long healthy stream
 * raises nothing; a 10 % damage step is caught within the delay
 * docs/indicators.md promises). Streams use the model of
 * tools/research/amfi-indicator-sim.c with fixed seeds.
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

#include "indicators.h"

/* Relative tolerance of the window statistics against the naive sums: both
 * are two-pass over at most a few hundred values of ~1e4 kg, so they agree
 * to a few hundred ulps; 1e-12 leaves room and still catches any real
 * error (a wrong value in the window moves the mean by >= 1e-4). */
#define STAT_TOL 1e-12

static amfi_indicators *make(const amfi_indicator_params *p)
{
    char err[256] = "";
    amfi_indicators *ind = NULL;
    int rc = amfi_indicators_create(p, &ind, err, sizeof err);
    if (rc != 0)
        fail_msg("create: %s", err);
    assert_non_null(ind);
    return ind;
}

/* Small parameters for the hand-made cases: W, K, baseline_n given; no
 * alert (ratio 100, p 1, no mean rule) unless a test sets the rules. */
static amfi_indicator_params small(int w, int k, int nb)
{
    amfi_indicator_params p;
    amfi_indicator_params_default(&p);
    p.window = w;
    p.every = k;
    p.baseline_n = nb;
    p.std_alert_ratio = 100.0;
    p.std_clear_ratio = 1.0;
    p.std_alert_p = 1.0;
    p.mean_alert_p = 1.0;
    p.raise_after = 1;
    p.clear_after = 1;
    p.mean_shift = 0;
    return p;
}

static int push(amfi_indicators *ind, double x, amfi_indicator_eval *e,
                amfi_alert_event ev[2], int *n)
{
    int rc = amfi_indicators_push(ind, x, e, ev, n);
    assert_true(rc >= 0);
    return rc;
}

static void naive(const double *x, int n, double *mean, double *std)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += x[i];
    *mean = s / n;
    double ss = 0;
    for (int i = 0; i < n; i++)
        ss += (x[i] - *mean) * (x[i] - *mean);
    *std = sqrt(ss / (n - 1));
}

static void assert_rel(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol * fabs(want)))
        fail_msg("got %.17g, want %.17g (rel tol %g)", got, want, tol);
}

/* --- parameters --- */

static void test_params(void **state)
{
    (void)state;
    amfi_indicator_params d, p;
    amfi_indicator_params_default(&d);
    assert_int_equal(d.window, 500);
    amfi_indicators *ind = make(&d);
    amfi_indicators_destroy(ind);
    amfi_indicators_destroy(NULL);

    char err[256];
    /* One broken field at a time; the message names it. */
#define EXPECT_BAD(field, value)                                                              \
    do {                                                                                      \
        p = d;                                                                                \
        p.field = value;                                                                      \
        ind = (amfi_indicators *)&p;                                                          \
        err[0] = '\0';                                                                        \
        assert_int_equal(amfi_indicators_create(&p, &ind, err, sizeof err), AMFI_IND_EINVAL); \
        assert_null(ind);                                                                     \
        if (strstr(err, #field) == NULL)                                                      \
            fail_msg("%s = %s: message '%s' does not name it", #field, #value, err);          \
    } while (0)
    EXPECT_BAD(window, 1);
    EXPECT_BAD(every, 0);
    EXPECT_BAD(baseline_n, 1);
    EXPECT_BAD(std_alert_ratio, 0.9);
    EXPECT_BAD(std_alert_ratio, NAN);
    EXPECT_BAD(std_alert_p, 0.0);
    EXPECT_BAD(std_alert_p, 1.5);
    EXPECT_BAD(std_clear_ratio, 2.0);
    EXPECT_BAD(std_clear_ratio, 0.0);
    EXPECT_BAD(raise_after, 0);
    EXPECT_BAD(clear_after, 0);
    EXPECT_BAD(mean_shift, 2);
    EXPECT_BAD(mean_alert_ratio, 0.5);
    EXPECT_BAD(mean_alert_p, NAN);
    EXPECT_BAD(mean_clear_ratio, 0.99);
    EXPECT_BAD(mean_clear_ratio, 2.0);
#undef EXPECT_BAD
    assert_int_equal(amfi_indicators_create(NULL, &ind, err, sizeof err), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_create(&d, NULL, NULL, 0), AMFI_IND_EINVAL);
}

/* --- baselines --- */

/* Equality is field by field: each field changed alone makes a difference. */
static void test_params_equal(void **state)
{
    (void)state;
    amfi_indicator_params a, b;
    amfi_indicator_params_default(&a);
    memset(&b, 0xa5, sizeof b); /* different padding must not matter */
    amfi_indicator_params_default(&b);
    assert_true(amfi_indicator_params_equal(&a, &b));
    for (int k = 0; k < 12; k++) {
        amfi_indicator_params_default(&b);
        switch (k) {
        case 0: b.window++; break;
        case 1: b.every++; break;
        case 2: b.baseline_n++; break;
        case 3: b.std_alert_ratio += 0.01; break;
        case 4: b.std_alert_p /= 2; break;
        case 5: b.std_clear_ratio += 0.01; break;
        case 6: b.raise_after++; break;
        case 7: b.clear_after++; break;
        case 8: b.mean_shift = !b.mean_shift; break;
        case 9: b.mean_alert_ratio += 0.01; break;
        case 10: b.mean_alert_p /= 2; break;
        case 11: b.mean_clear_ratio += 0.01; break;
        }
        if (amfi_indicator_params_equal(&a, &b))
            fail_msg("field %d changed, yet equal", k);
    }
}

/* The text form amfid records in the store (meta daemon.indicators): every
 * field round-trips exactly, and a damaged text is refused naming the
 * field. */
static void test_params_text(void **state)
{
    (void)state;
    amfi_indicator_params a, b;
    char buf[1024], err[256];
    amfi_indicator_params_default(&a);
    a.std_alert_ratio = 1.0 + 1.0 / 3.0;
    a.mean_alert_p = 0.0123456789;
    a.window = 777;
    assert_int_equal(amfi_indicator_params_format(&a, buf, sizeof buf), AMFI_IND_OK);
    assert_non_null(strstr(buf, "window=777 every="));
    assert_int_equal(amfi_indicator_params_parse(buf, &b, err, sizeof err), AMFI_IND_OK);
    assert_true(amfi_indicator_params_equal(&a, &b));
    assert_int_equal(amfi_indicator_params_format(&a, buf, 20), AMFI_IND_EINVAL);
    static const struct {
        const char *text, *why;
    } bad[] = {
        {"window=500", "every missing"},
        {"window=500 window=500", "window given twice"},
        {"windows=500", "unknown field"},
        {"window=5x0", "window: trailing text"},
        {"std_alert_ratio=abc", "std_alert_ratio: not a number"},
        {"window=500 every=100 baseline_n=10000 std_alert_ratio=1.08 std_alert_p=0.01 "
         "std_clear_ratio=2 raise_after=6 clear_after=6 mean_shift=1 mean_alert_ratio=1.05 "
         "mean_alert_p=0.01 mean_clear_ratio=1.03", "std_clear_ratio must be"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        amfi_indicator_params_default(&b);
        assert_int_equal(amfi_indicator_params_parse(bad[k].text, &b, err, sizeof err),
                         AMFI_IND_EINVAL);
        if (!strstr(err, bad[k].why))
            fail_msg("'%s': '%s', expected '%s'", bad[k].text, err, bad[k].why);
        amfi_indicator_params_default(&a);
        assert_true(amfi_indicator_params_equal(&a, &b)); /* untouched */
    }
}

static void test_baseline_auto(void **state)
{
    (void)state;
    amfi_indicator_params p = small(4, 2, 10);
    amfi_indicators *ind = make(&p);
    double x[10];
    amfi_indicator_eval e;
    amfi_alert_event ev[2];
    int n = -1;
    assert_int_equal(amfi_indicators_has_baseline(ind), 0);
    assert_string_equal(amfi_indicators_state(ind), "baseline");
    for (int i = 0; i < 10; i++) {
        x[i] = 8000.0 + 137.0 * i + (i % 3) * 911.0;
        int rc = push(ind, x[i], &e, ev, &n);
        assert_int_equal(n, 0);
        if (i < 9) {
            /* Collecting: no evaluation although the window (4) is full. */
            assert_int_equal(rc, 0);
            assert_int_equal(amfi_indicators_has_baseline(ind), 0);
        } else {
            assert_int_equal(rc, AMFI_IND_BASELINE);
        }
    }
    double m, s;
    naive(x, 10, &m, &s);
    assert_int_equal(e.n, 10);
    assert_rel(e.baseline_mean_kg, m, STAT_TOL);
    assert_rel(e.baseline_std_kg, s, STAT_TOL);
    assert_string_equal(e.state, "baseline");
    assert_int_equal(amfi_indicators_has_baseline(ind), 1);
    assert_string_equal(amfi_indicators_state(ind), "normal");
    /* The next push evaluates the last 4 values against it. */
    int rc = push(ind, 9000.0, &e, ev, &n);
    assert_int_equal(rc, AMFI_IND_EVAL);
    double w[4] = { x[7], x[8], x[9], 9000.0 }, wm, ws;
    naive(w, 4, &wm, &ws);
    assert_rel(e.mean_kg, wm, STAT_TOL);
    assert_rel(e.std_kg, ws, STAT_TOL);
    assert_rel(e.std_ratio, ws / s, STAT_TOL);
    assert_rel(e.mean_ratio, wm / m, STAT_TOL);
    assert_rel(e.baseline_std_kg, s, STAT_TOL);
    amfi_indicators_destroy(ind);
}

static void test_baseline_constant_recollects(void **state)
{
    (void)state;
    /* baseline_n identical values have no spread: collected again. */
    amfi_indicator_params p = small(2, 1, 3);
    amfi_indicators *ind = make(&p);
    for (int i = 0; i < 3; i++)
        assert_int_equal(push(ind, 5000.0, NULL, NULL, NULL), 0);
    assert_int_equal(amfi_indicators_has_baseline(ind), 0);
    assert_int_equal(push(ind, 5000.0, NULL, NULL, NULL), 0);
    assert_int_equal(push(ind, 6000.0, NULL, NULL, NULL), 0);
    assert_int_equal(push(ind, 7000.0, NULL, NULL, NULL), AMFI_IND_BASELINE);
    amfi_indicators_destroy(ind);
}

static void test_baseline_explicit(void **state)
{
    (void)state;
    amfi_indicator_params p = small(3, 2, 1000);
    amfi_indicators *ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, NAN, 1000, 10), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_set_baseline(ind, 9000, 0.0, 10), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_set_baseline(ind, 9000, INFINITY, 10), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_set_baseline(ind, -1, 1000, 10), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_set_baseline(ind, 9000, 1000, 1), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_has_baseline(ind), 0);
    /* Two pushes of the automatic collection, then the explicit one wins. */
    push(ind, 1000.0, NULL, NULL, NULL);
    push(ind, 2000.0, NULL, NULL, NULL);
    assert_int_equal(amfi_indicators_set_baseline(ind, 2000.0, 500.0, 3), 0);
    assert_int_equal(amfi_indicators_has_baseline(ind), 1);
    amfi_indicator_eval e;
    /* The window fills at the third push: it evaluates. */
    assert_int_equal(push(ind, 3000.0, &e, NULL, NULL), AMFI_IND_EVAL);
    assert_rel(e.baseline_mean_kg, 2000.0, 0);
    assert_rel(e.baseline_std_kg, 500.0, 0);
    assert_rel(e.std_kg, 1000.0, STAT_TOL);
    assert_rel(e.std_ratio, 2.0, STAT_TOL);
    amfi_indicators_destroy(ind);
}

/* --- prefill and cadence --- */

static void test_prefill(void **state)
{
    (void)state;
    amfi_indicator_params p = small(5, 3, 100);
    amfi_indicators *ind = make(&p);
    double v[8] = { 7000, 8000, NAN, 9000, -5, 10000, 11000, 12000 };
    /* No baseline: the prefill neither evaluates nor collects one. */
    assert_int_equal(amfi_indicators_prefill(ind, v, 8), 6);
    assert_int_equal(amfi_indicators_has_baseline(ind), 0);
    assert_int_equal(amfi_indicators_prefill(ind, NULL, 1), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_prefill(ind, v, -1), AMFI_IND_EINVAL);
    assert_int_equal(amfi_indicators_prefill(ind, NULL, 0), 0);
    assert_int_equal(amfi_indicators_set_baseline(ind, 9000, 2000, 5000), 0);
    /* The first push after the prefill evaluates the last 5 values. */
    amfi_indicator_eval e;
    assert_int_equal(push(ind, 13000, &e, NULL, NULL), AMFI_IND_EVAL);
    double w[5] = { 9000, 10000, 11000, 12000, 13000 }, wm, ws;
    naive(w, 5, &wm, &ws);
    assert_int_equal(e.n, 5);
    assert_rel(e.mean_kg, wm, STAT_TOL);
    assert_rel(e.std_kg, ws, STAT_TOL);
    amfi_indicators_destroy(ind);

    /* A prefill of a window whose spread would alert raises nothing by
     * itself; the next push evaluates and raises. */
    p = small(4, 10, 100);
    p.std_alert_ratio = 2.0;
    ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 100, 1000000), 0);
    double wide[4] = { 5000, 15000, 5000, 15000 };
    assert_int_equal(amfi_indicators_prefill(ind, wide, 4), 4);
    amfi_alert_event ev[2];
    int n = -1;
    int rc = push(ind, 5000, &e, ev, &n);
    assert_int_equal(rc, AMFI_IND_EVAL | AMFI_IND_ALERT);
    assert_int_equal(n, 1);
    assert_int_equal(ev[0].raised, 1);
    amfi_indicators_destroy(ind);
}

static void test_cadence(void **state)
{
    (void)state;
    /* Explicit baseline: W = 6, K = 4: evaluations at pushes 6, 10, 14, ...
     * Every evaluation is checked against the naive statistics of the last
     * W pushed values (the slow, obvious reference). */
    enum { W = 6, K = 4, N = 200 };
    amfi_indicator_params p = small(W, K, 100);
    amfi_indicators *ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 9000, 2000, 500), 0);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 7);
    double x[N];
    int evals = 0;
    for (int i = 0; i < N; i++) {
        x[i] = 9000 + gsl_ran_gaussian(r, 2000.0);
        if (x[i] < 1000)
            x[i] = 1000;
        amfi_indicator_eval e;
        int rc = push(ind, x[i], &e, NULL, NULL);
        int want = i + 1 >= W && (i + 1 - W) % K == 0;
        assert_int_equal((rc & AMFI_IND_EVAL) != 0, want);
        if (want) {
            double m, s;
            naive(x + i + 1 - W, W, &m, &s);
            assert_int_equal(e.n, W);
            assert_rel(e.mean_kg, m, STAT_TOL);
            assert_rel(e.std_kg, s, STAT_TOL);
            evals++;
        }
    }
    assert_int_equal(evals, (N - W) / K + 1);
    amfi_indicators_destroy(ind);

    /* Automatic baseline (n_b = 10 > W = 6): no evaluation on the
     * establishing push, one on the next, then every K. */
    p = small(W, K, 10);
    ind = make(&p);
    for (int i = 0; i < 30; i++) {
        int rc = push(ind, x[i], NULL, NULL, NULL);
        int want_eval = i >= 10 && (i - 10) % K == 0;
        assert_int_equal((rc & AMFI_IND_BASELINE) != 0, i == 9);
        assert_int_equal((rc & AMFI_IND_EVAL) != 0, want_eval);
    }
    amfi_indicators_destroy(ind);
    gsl_rng_free(r);
}

/* --- p-values against closed forms --- */

static void test_pvalues(void **state)
{
    (void)state;
    /* Window {1, 2, 3} t: s_w = 1000 kg, mean 2000 kg. Baseline STD 500 kg:
     * F = 4 with (2, n_b − 1) dof. For d1 = 2 the F tail is closed:
     * Q(F) = (1 + 2F/d2)^(−d2/2), so n_b = 3 (d2 = 2): 1/(1 + 4) = 0.2 and
     * n_b = 5 (d2 = 4): (1 + 2)^−2 = 1/9. */
    amfi_indicator_params p = small(3, 1, 100);
    amfi_indicator_eval e;
    struct {
        int nb;
        double q;
    } c[] = { { 3, 0.2 }, { 5, 1.0 / 9.0 } };
    for (int k = 0; k < 2; k++) {
        amfi_indicators *ind = make(&p);
        assert_int_equal(amfi_indicators_set_baseline(ind, 2000, 500, c[k].nb), 0);
        push(ind, 1000, NULL, NULL, NULL);
        push(ind, 2000, NULL, NULL, NULL);
        assert_int_equal(push(ind, 3000, &e, NULL, NULL), AMFI_IND_EVAL);
        assert_rel(e.std_ratio, 2.0, STAT_TOL);
        /* GSL's incomplete beta: ~1e-15 relative; 1e-10 is ample. */
        assert_rel(e.p_value, c[k].q, 1e-10);
        /* Equal means: t = 0, two-sided p = 1. */
        assert_rel(e.mean_ratio, 1.0, STAT_TOL);
        assert_rel(e.mean_p, 1.0, 1e-12);
        amfi_indicators_destroy(ind);
    }
    /* Welch with a constant window {2, 2, 2} t (s_w = 0) against a baseline
     * of mean 1 t, STD 1 t, n = 3: t = 1000 / sqrt(1e6 / 3) = sqrt(3), and
     * Welch–Satterthwaite gives ν = n_b − 1 = 2, where the t tail is closed:
     * two-sided p = 1 − t / sqrt(2 + t²) = 1 − sqrt(3/5). The F test of a
     * zero window variance: p = 1. */
    amfi_indicators *ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 1000, 1000, 3), 0);
    for (int i = 0; i < 3; i++)
        push(ind, 2000, &e, NULL, NULL);
    assert_rel(e.mean_ratio, 2.0, STAT_TOL);
    assert_rel(e.mean_p, 1.0 - sqrt(3.0 / 5.0), 1e-10);
    assert_rel(e.std_ratio + 1.0, 1.0, 0);
    assert_rel(e.p_value, 1.0, 0);
    amfi_indicators_destroy(ind);
}

/* --- hysteresis and debounce --- */

/* Push one disjoint window (W = K = 4) of mean 10 t and sample STD `std`:
 * {m − a, m + a, m − a, m + a} has s = a·sqrt(4/3). Returns the last push's
 * result, with the events. */
static int block(amfi_indicators *ind, double std, amfi_indicator_eval *e,
                 amfi_alert_event ev[2], int *n)
{
    double a = std / sqrt(4.0 / 3.0);
    int rc = 0;
    for (int i = 0; i < 4; i++) {
        rc = push(ind, 10000.0 + (i % 2 ? a : -a), e, ev, n);
        if (i < 3)
            assert_int_equal(rc, 0);
    }
    assert_true(rc & AMFI_IND_EVAL);
    return rc;
}

static void test_hysteresis(void **state)
{
    (void)state;
    amfi_indicator_params p = small(4, 4, 100);
    p.std_alert_ratio = 1.5;
    p.std_clear_ratio = 1.2;
    p.raise_after = 3;
    p.clear_after = 2;
    amfi_indicators *ind = make(&p);
    /* Baseline STD 1 t over a million vehicles: the F test has (3, 999999)
     * dof; with p 1 only the ratio rule decides here. */
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 1000, 1000000), 0);
    amfi_indicator_eval e;
    amfi_alert_event ev[2];
    int n;
    /* ratio per disjoint window, and the expected state after it */
    struct {
        double ratio;
        const char *state;
        int event; /* +1 raised, −1 cleared, 0 none */
    } seq[] = {
        { 1.0, "normal", 0 },  { 1.6, "watch", 0 },   { 1.6, "watch", 0 },
        { 1.4, "normal", 0 },  /* one miss resets the debounce */
        { 1.6, "watch", 0 },   { 1.7, "watch", 0 },   { 1.55, "alert", 1 },
        { 1.8, "alert", 0 },   { 2.0, "alert", 0 },   /* raised once, not repeated */
        { 1.3, "alert", 0 },   /* between clear and raise: stays */
        { 1.1, "alert", 0 },   { 1.3, "alert", 0 },   /* a clear streak broken */
        { 1.1, "alert", 0 },   { 1.0, "normal", -1 }, /* cleared once */
        { 1.1, "normal", 0 },  { 1.0, "normal", 0 },  { 1.6, "watch", 0 },
    };
    int raised = 0, cleared = 0;
    for (size_t i = 0; i < sizeof seq / sizeof seq[0]; i++) {
        int rc = block(ind, 1000.0 * seq[i].ratio, &e, ev, &n);
        assert_rel(e.std_ratio, seq[i].ratio, 1e-12);
        if (strcmp(e.state, seq[i].state) != 0)
            fail_msg("step %zu (ratio %g): state %s, want %s", i, seq[i].ratio, e.state,
                     seq[i].state);
        assert_string_equal(amfi_indicators_state(ind), seq[i].state);
        if (seq[i].event == 0) {
            assert_int_equal(rc & AMFI_IND_ALERT, 0);
            assert_int_equal(n, 0);
            continue;
        }
        assert_int_equal(rc, AMFI_IND_EVAL | AMFI_IND_ALERT);
        assert_int_equal(n, 1);
        assert_string_equal(ev[0].kind, "std_increase");
        assert_string_equal(ev[0].level, "warning");
        assert_int_equal(ev[0].raised, seq[i].event > 0);
        assert_non_null(strstr(ev[0].message, "STD of inferred GVW"));
        raised += seq[i].event > 0;
        cleared += seq[i].event < 0;
    }
    assert_int_equal(raised, 1);
    assert_int_equal(cleared, 1);
    amfi_indicators_destroy(ind);
}

static void test_p_rule_and_restore(void **state)
{
    (void)state;
    /* Both conditions: ratio 2 over W = 4 against a baseline of n = 3 has
     * p = Q(4; 3, 2) ≈ 0.2: the p rule (0.05) keeps it quiet. */
    amfi_indicator_params p = small(4, 4, 100);
    p.std_alert_ratio = 1.5;
    p.std_alert_p = 0.05;
    p.std_clear_ratio = 1.2;
    amfi_indicators *ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 1000, 3), 0);
    amfi_indicator_eval e;
    amfi_alert_event ev[2];
    int n;
    for (int i = 0; i < 5; i++) {
        int rc = block(ind, 2000.0, &e, ev, &n);
        assert_true(e.p_value > 0.05);
        assert_int_equal(rc, AMFI_IND_EVAL);
        assert_string_equal(e.state, "normal");
    }
    /* The same windows against a baseline of a million vehicles alert. */
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 1000, 1000000), 0);
    /* set_baseline restarts the cadence: the next push evaluates (the
     * window is {m + a, m − a, m + a, m − a}, the same spread). */
    int rc = push(ind, 10000.0 - 2000.0 / sqrt(4.0 / 3.0), &e, ev, &n);
    assert_int_equal(rc, AMFI_IND_EVAL | AMFI_IND_ALERT);
    assert_rel(e.std_ratio, 2.0, 1e-12);
    assert_true(e.p_value < 0.05);
    amfi_indicators_destroy(ind);

    /* After a restart with the alert restored, the high spread raises
     * nothing again, and the clear comes once. */
    ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 1000, 1000000), 0);
    amfi_indicators_set_alerted(ind, 1, 0);
    assert_string_equal(amfi_indicators_state(ind), "alert");
    assert_int_equal(block(ind, 2000.0, &e, ev, &n), AMFI_IND_EVAL);
    assert_string_equal(e.state, "alert");
    assert_int_equal(block(ind, 1000.0, &e, ev, &n), AMFI_IND_EVAL | AMFI_IND_ALERT);
    assert_int_equal(ev[0].raised, 0);
    assert_string_equal(e.state, "normal");
    amfi_indicators_destroy(ind);
}

/* --- the mean-shift kind --- */

static void test_mean_shift(void **state)
{
    (void)state;
    amfi_indicator_params p = small(4, 4, 100);
    p.mean_shift = 1;
    p.mean_alert_ratio = 1.05;
    p.mean_clear_ratio = 1.03;
    p.mean_alert_p = 0.01;
    p.raise_after = 2;
    p.clear_after = 1;
    amfi_indicators *ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 1000, 1000000), 0);
    amfi_indicator_eval e;
    amfi_alert_event ev[2];
    int n;
    /* Windows of mean means[i] and a small spread (100 kg: t ≈ 20 for a
     * 1 t shift, Welch p ≈ 3e-4 with ν ≈ 3). */
    double means[] = { 10000, 11000, 11000, 11000, 10100, 9000, 9000, 10000 };
    int want[] = { 0, 0, 1, 0, -1, 0, 1, -1 };
    for (size_t i = 0; i < sizeof means / sizeof means[0]; i++) {
        int rc = 0;
        double a = 100.0 / sqrt(4.0 / 3.0);
        for (int j = 0; j < 4; j++)
            rc = push(ind, means[i] + (j % 2 ? a : -a), &e, ev, &n);
        assert_true(rc & AMFI_IND_EVAL);
        assert_rel(e.mean_ratio, means[i] / 10000.0, 1e-12);
        /* The STD does not rise: the STD indicator stays normal. */
        assert_string_equal(e.state, "normal");
        if (want[i] == 0) {
            assert_int_equal(n, 0);
            continue;
        }
        assert_int_equal(n, 1);
        assert_string_equal(ev[0].kind, "mean_shift");
        assert_string_equal(ev[0].level, "info");
        assert_int_equal(ev[0].raised, want[i] > 0);
        assert_non_null(strstr(ev[0].message, "mean of inferred GVW"));
        if (want[i] > 0)
            assert_true(e.mean_p <= 0.01);
    }
    amfi_indicators_destroy(ind);

    /* mean_shift 0: the same shift is reported in the evaluation only. */
    p.mean_shift = 0;
    ind = make(&p);
    assert_int_equal(amfi_indicators_set_baseline(ind, 10000, 1000, 1000000), 0);
    for (int i = 0; i < 40; i++) {
        push(ind, i % 2 ? 12100 : 11900, &e, ev, &n);
        assert_int_equal(n, 0);
    }
    assert_true(e.mean_ratio > 1.05);
    amfi_indicators_destroy(ind);
}

/* --- rejection --- */

static void test_reject(void **state)
{
    (void)state;
    amfi_indicator_params p = small(3, 1, 4);
    amfi_indicators *a = make(&p), *b = make(&p);
    const double bad[] = { NAN, INFINITY, -INFINITY, -1.0, 0.0, 2e7 };
    const double good[] = { 8000, 9000, 10500, 7000, 12000, 9500, 8800 };
    amfi_indicator_eval ea, eb;
    amfi_alert_event ev[2];
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        for (size_t j = 0; j < sizeof bad / sizeof bad[0]; j++) {
            int n = -1;
            assert_int_equal(amfi_indicators_push(a, bad[j], &ea, ev, &n), AMFI_IND_EINVAL);
            assert_int_equal(n, 0);
        }
        /* a (with the rejected values) and b (without) stay identical. */
        int ra = push(a, good[i], &ea, ev, NULL);
        int rb = push(b, good[i], &eb, ev, NULL);
        assert_int_equal(ra, rb);
        if (ra & (AMFI_IND_EVAL | AMFI_IND_BASELINE)) {
            assert_true(ea.mean_kg == eb.mean_kg);
            assert_true(ea.std_kg == eb.std_kg);
            assert_true(ea.baseline_std_kg == eb.baseline_std_kg);
        }
    }
    assert_int_equal(amfi_indicators_has_baseline(a), 1);
    amfi_indicators_destroy(a);
    amfi_indicators_destroy(b);
}

/* --- the defaults on simulated streams (tools/research/amfi-indicator-sim.c) --- */

static double draw(gsl_rng *r, double damage)
{
    double x;
    do
        x = 8765.0 + gsl_ran_gaussian_ziggurat(r, 1960.0);
    while (x < 4000.0 || x > 15000.0);
    return (x + gsl_ran_gaussian_ziggurat(r, 300.0)) / (1.0 - damage);
}

/* Push a stream; returns the number of STD alerts raised (and cleared in
 * *cleared), *first the 1-based index of the first raise or −1. */
static int run(amfi_indicators *ind, gsl_rng *r, double damage, long n, long *first,
               int *cleared)
{
    int raised = 0;
    *first = -1;
    *cleared = 0;
    for (long i = 1; i <= n; i++) {
        amfi_alert_event ev[2];
        int k = 0;
        int rc = amfi_indicators_push(ind, draw(r, damage), NULL, ev, &k);
        assert_true(rc >= 0);
        for (int j = 0; j < k; j++) {
            if (strcmp(ev[j].kind, "std_increase") != 0)
                continue;
            if (ev[j].raised) {
                raised++;
                if (*first < 0)
                    *first = i;
            } else {
                (*cleared)++;
            }
        }
    }
    return raised;
}

static void test_healthy_stream(void **state)
{
    (void)state;
    amfi_indicator_params p;
    amfi_indicator_params_default(&p);
    amfi_indicators *ind = make(&p);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 20240601);
    long first;
    int cleared;
    /* The automatic baseline, then 400 000 healthy vehicles. At the
     * defaults' measured rate (0.008 false alerts per 1e5 vehicles,
     * docs/indicators.md) an alert here would be a ~3 % event for a random
     * seed; with this fixed seed there is none, and a change of the rules
     * that raises the rate tenfold would very likely show here. */
    int raised = run(ind, r, 0.0, p.baseline_n + 400000L, &first, &cleared);
    assert_int_equal(amfi_indicators_has_baseline(ind), 1);
    if (raised != 0)
        fail_msg("%d false STD alerts in a healthy stream, the first after %ld vehicles",
                 raised, first);
    assert_string_not_equal(amfi_indicators_state(ind), "alert");
    amfi_indicators_destroy(ind);
    gsl_rng_free(r);
}

/* docs/indicators.md, "What the integration test may expect": with the
 * defaults and an automatic baseline, 10 % damage raises the STD alert
 * within 8000 vehicles after the step (simulated: median 840, 99th
 * percentile 3300, the largest of 4000 runs 5932). Five runs of a fixed
 * seed, each must raise once and not clear. */
#define DELAY_BOUND 8000L

static void test_damage_step(void **state)
{
    (void)state;
    amfi_indicator_params p;
    amfi_indicator_params_default(&p);
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, 424242);
    for (int k = 0; k < 5; k++) {
        amfi_indicators *ind = make(&p);
        long first;
        int cleared;
        int raised = run(ind, r, 0.0, p.baseline_n + p.window + 1000L, &first, &cleared);
        assert_int_equal(raised, 0);
        raised = run(ind, r, 0.10, DELAY_BOUND, &first, &cleared);
        if (raised != 1 || cleared != 0)
            fail_msg("run %d: %d raises, %d clears in %ld vehicles after a 10 %% step", k,
                     raised, cleared, DELAY_BOUND);
        amfi_indicators_destroy(ind);
    }
    gsl_rng_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_params_equal),
        cmocka_unit_test(test_params_text),
        cmocka_unit_test(test_baseline_auto),
        cmocka_unit_test(test_baseline_constant_recollects),
        cmocka_unit_test(test_baseline_explicit),
        cmocka_unit_test(test_prefill),
        cmocka_unit_test(test_cadence),
        cmocka_unit_test(test_pvalues),
        cmocka_unit_test(test_hysteresis),
        cmocka_unit_test(test_p_rule_and_restore),
        cmocka_unit_test(test_mean_shift),
        cmocka_unit_test(test_reject),
        cmocka_unit_test(test_healthy_stream),
        cmocka_unit_test(test_damage_step),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
