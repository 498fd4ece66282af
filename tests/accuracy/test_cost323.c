/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_cost323: the COST 323 accuracy classes (accuracy/cost323.h) against
 * the specification's published case and its tables.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "cost323.h"

static void near(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol))
        fail_msg("got %.6f, want %.6f +- %g", got, want, tol);
}

/* The specification's example: 15 trucks from the traffic, full
 * reproducibility (RR2), environment I, gross weight m = 1.38 %,
 * s = 3.43 %: π₀ = 85.19 %, B(10) accepted with π = 95.7 %. */
static void published_case(void **state)
{
    (void)state;
    amfi_cost323_result r;
    char why[200];
    assert_int_equal(amfi_cost323_evaluate_stats(AMFI_COST323_GROSS, 15, 1.38, 3.43,
                                                 AMFI_COST323_RR2, AMFI_COST323_ENV_I, 0, &r,
                                                 why, sizeof why),
                     0);
    near(r.pi0_pct, 85.19, 0.005);
    assert_string_equal(r.class_name, "B(10)");
    assert_int_equal(r.class_value, 10);
    near(r.delta_pct, 10.0, 0);
    near(r.pi_pct, 95.7, 0.05);
    /* B+(7) is refused: its confidence is below π₀ */
    double pi7 = amfi_cost323_confidence(15, 1.38, 3.43, 7.0);
    assert_true(pi7 < r.pi0_pct);
    /* δ_min lies between the two and reaches π₀ exactly */
    assert_true(r.delta_min_pct > 7.0 && r.delta_min_pct < 10.0);
    near(amfi_cost323_confidence(15, 1.38, 3.43, r.delta_min_pct), r.pi0_pct, 1e-6);
}

/* π₀ falls from r1 to RR2 and from environment I to III, rises with n
 * towards 2Φ(ν/f) − 1. */
static void min_confidence_order(void **state)
{
    (void)state;
    double last = 101;
    for (int c = 0; c < AMFI_COST323_N_CONDITIONS; c++) {
        double p = amfi_cost323_min_confidence(30, c, AMFI_COST323_ENV_I);
        assert_true(p < last);
        last = p;
        assert_true(amfi_cost323_min_confidence(30, c, AMFI_COST323_ENV_II) < p);
        assert_true(amfi_cost323_min_confidence(30, c, AMFI_COST323_ENV_III) <
                    amfi_cost323_min_confidence(30, c, AMFI_COST323_ENV_II));
        assert_true(amfi_cost323_min_confidence(100, c, AMFI_COST323_ENV_I) > p);
    }
    /* the limit: RR2, I, n → ∞: 2Φ(2) − 1 = 95.45 % */
    near(amfi_cost323_min_confidence(100000000, AMFI_COST323_RR2, AMFI_COST323_ENV_I), 95.45,
         0.005);
    assert_true(isnan(amfi_cost323_min_confidence(1, AMFI_COST323_RR2, AMFI_COST323_ENV_I)));
}

/* The tolerance table (the specification's table 1) and the E classes. */
static void tolerances(void **state)
{
    (void)state;
    static const struct {
        int v;
        double d[4];
    } t[] = {{5, {5, 7, 8, 10}},     {7, {7, 10, 11, 14}},   {10, {10, 13, 15, 20}},
             {15, {15, 18, 20, 25}}, {20, {20, 23, 25, 30}}, {25, {25, 28, 30, 35}},
             {30, {30, 33, 36, 41}}, {40, {40, 44, 48, 53}}};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        for (int c = 0; c < AMFI_COST323_N_CRITERIA; c++) {
            near(amfi_cost323_tolerance(c, t[i].v, 0), t[i].d[c], 1e-12);
            near(amfi_cost323_tolerance(c, t[i].v, 1), 0.8 * t[i].d[c], 1e-12);
        }
    assert_true(isnan(amfi_cost323_tolerance(AMFI_COST323_GROSS, 6, 0)));
    assert_true(isnan(amfi_cost323_tolerance(AMFI_COST323_GROSS, 12, 0)));
    assert_true(isnan(amfi_cost323_tolerance(AMFI_COST323_GROSS, 105, 0)));
    char name[16];
    static const struct {
        int v;
        const char *s;
    } names[] = {{5, "A(5)"},   {7, "B+(7)"},  {10, "B(10)"}, {15, "C(15)"},
                 {20, "D+(20)"}, {25, "D(25)"}, {35, "E(35)"}, {0, "none"}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        amfi_cost323_class_name(names[i].v, name, sizeof name);
        assert_string_equal(name, names[i].s);
    }
}

/* From raw errors: a tight sample is A(5); the same sample judged at an
 * initial verification (0.8 δ) or as a single axle (wider δ) moves as the
 * tables say; a sample beyond E(100) has no class. */
static void from_errors(void **state)
{
    (void)state;
    double e[40];
    for (int i = 0; i < 40; i++)
        e[i] = 0.3 + 1.0 * sin(1.7 * i); /* m ≈ 0.3, s ≈ 0.7 */
    amfi_cost323_result r, ri, rs;
    char why[200];
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 40, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     0);
    assert_int_equal(r.n, 40);
    assert_string_equal(r.class_name, "A(5)");
    assert_true(r.pi_pct >= r.pi0_pct);
    for (int i = 0; i < 40; i++)
        e[i] = 1.0 + 6.0 * sin(1.7 * i); /* m ≈ 1, s ≈ 4.3 */
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 40, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     0);
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 40, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 1, &ri, why, sizeof why),
                     0);
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_SINGLE, e, 40, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &rs, why, sizeof why),
                     0);
    assert_true(ri.class_value > r.class_value);  /* stricter tolerances */
    assert_true(rs.class_value < r.class_value);  /* a single axle is allowed more */
    /* the accepted class is the best one: the class below it fails */
    assert_int_equal(r.class_value, 10);
    assert_true(amfi_cost323_confidence(40, r.mean_pct, r.std_pct,
                                        amfi_cost323_tolerance(AMFI_COST323_GROSS, 7, 0)) <
                r.pi0_pct);
    for (int i = 0; i < 40; i++)
        e[i] = 150.0 + 50.0 * sin(1.7 * i);
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 40, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     0);
    assert_int_equal(r.class_value, 0);
    assert_string_equal(r.class_name, "none");
    /* exact weights: s = 0 */
    for (int i = 0; i < 40; i++)
        e[i] = 0.2;
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 40, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     0);
    assert_string_equal(r.class_name, "A(5)");
    near(r.pi_pct, 100, 0);
}

/* What cannot be classed says why. */
static void refusals(void **state)
{
    (void)state;
    amfi_cost323_result r;
    char why[200];
    double e[3] = {1, 2, NAN};
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 1, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     -1);
    assert_non_null(strstr(why, "fewer than 2"));
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 3, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     -1);
    assert_non_null(strstr(why, "not finite"));
    /* two values: t(0.975, 1)/√2 = 8.98 leaves π₀ < 0 */
    assert_int_equal(amfi_cost323_evaluate(AMFI_COST323_GROSS, e, 2, AMFI_COST323_RR2,
                                           AMFI_COST323_ENV_I, 0, &r, why, sizeof why),
                     -1);
    assert_non_null(strstr(why, "too few"));
    amfi_cost323_criterion c;
    amfi_cost323_condition k;
    amfi_cost323_environment v;
    assert_int_equal(amfi_cost323_criterion_parse("group_axle", &c), 0);
    assert_int_equal(c, AMFI_COST323_GROUP_AXLE);
    assert_int_equal(amfi_cost323_criterion_parse("axle", &c), -1);
    assert_int_equal(amfi_cost323_condition_parse("RR1", &k), 0);
    assert_int_equal(k, AMFI_COST323_RR1);
    assert_int_equal(amfi_cost323_condition_parse("rr1", &k), -1);
    assert_int_equal(amfi_cost323_environment_parse("III", &v), 0);
    assert_int_equal(amfi_cost323_environment_parse("IV", &v), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(published_case), cmocka_unit_test(min_confidence_order),
        cmocka_unit_test(tolerances),     cmocka_unit_test(from_errors),
        cmocka_unit_test(refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
