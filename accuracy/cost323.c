/* SPDX-License-Identifier: GPL-3.0-or-later */
/* cost323.c: COST 323 accuracy classes (cost323.h has the formulas). */
#include "cost323.h"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const criterion_names[AMFI_COST323_N_CRITERIA] = {
    "gross", "group", "single", "group_axle"};
static const char *const condition_names[AMFI_COST323_N_CONDITIONS] = {"r1", "r2", "RR1",
                                                                       "RR2"};
static const char *const environment_names[AMFI_COST323_N_ENVIRONMENTS] = {"I", "II", "III"};
/* ν of π₀ per test condition, and the environment's divisor */
static const double condition_nu[AMFI_COST323_N_CONDITIONS] = {2.675, 2.36, 2.155, 2.0};
static const double environment_f[AMFI_COST323_N_ENVIRONMENTS] = {1.0, 1.05, 1.1};

/* The named classes A(5) .. D(25): gross-weight value and the tolerance of
 * each criterion (the specification's table 1). */
static const struct {
    int value;
    double delta[AMFI_COST323_N_CRITERIA];
} named[] = {
    {5, {5, 7, 8, 10}},     {7, {7, 10, 11, 14}},   {10, {10, 13, 15, 20}},
    {15, {15, 18, 20, 25}}, {20, {20, 23, 25, 30}}, {25, {25, 28, 30, 35}},
};
#define N_NAMED (int)(sizeof named / sizeof named[0])

/* index of s in names[0 .. n), or −1 */
static int parse_name(const char *s, const char *const *names, int n)
{
    if (!s)
        return -1;
    for (int i = 0; i < n; i++)
        if (strcmp(s, names[i]) == 0)
            return i;
    return -1;
}

/* names[i] for 0 <= i < n, else "?" */
static const char *name_of(int i, const char *const *names, int n)
{
    return i >= 0 && i < n ? names[i] : "?";
}

/* The three enums' names and parsers, one pair each. */
#define NAMED_ENUM(type, fn, names, count)                                  \
    const char *amfi_cost323_##fn##_name(type v)                            \
    {                                                                       \
        return name_of((int)v, names, count);                               \
    }                                                                       \
    int amfi_cost323_##fn##_parse(const char *s, type *out)                 \
    {                                                                       \
        int i = parse_name(s, names, count);                                \
        if (i >= 0)                                                         \
            *out = (type)i;                                                 \
        return i >= 0 ? 0 : -1;                                             \
    }
NAMED_ENUM(amfi_cost323_criterion, criterion, criterion_names, AMFI_COST323_N_CRITERIA)
NAMED_ENUM(amfi_cost323_condition, condition, condition_names, AMFI_COST323_N_CONDITIONS)
NAMED_ENUM(amfi_cost323_environment, environment, environment_names, AMFI_COST323_N_ENVIRONMENTS)
#undef NAMED_ENUM

/* t/√n: the two-sided 95 % Student quantile over √n */
static double t_term(int n)
{
    return gsl_cdf_tdist_Qinv(0.025, (double)(n - 1)) / sqrt((double)n);
}

double amfi_cost323_min_confidence(int n, amfi_cost323_condition cond,
                                   amfi_cost323_environment env)
{
    if (n < 2 || (unsigned)cond >= AMFI_COST323_N_CONDITIONS ||
        (unsigned)env >= AMFI_COST323_N_ENVIRONMENTS)
        return NAN;
    double x = condition_nu[cond] / environment_f[env] - t_term(n);
    return 100.0 * (2.0 * gsl_cdf_ugaussian_P(x) - 1.0);
}

double amfi_cost323_confidence(int n, double m, double s, double delta)
{
    if (n < 2 || !isfinite(m) || !isfinite(s) || s < 0 || !(delta >= 0))
        return NAN;
    if (s == 0)
        return fabs(m) < delta ? 100.0 : 0.0;
    double c = t_term(n), nu = (double)(n - 1);
    return 100.0 * (1.0 - gsl_cdf_tdist_Q((delta - m) / s - c, nu) -
                    gsl_cdf_tdist_Q((delta + m) / s - c, nu));
}

static int is_class_value(int v)
{
    if (v == 5 || v == 7)
        return 1;
    return v >= 10 && v <= AMFI_COST323_MAX_CLASS && v % 5 == 0;
}

double amfi_cost323_tolerance(amfi_cost323_criterion c, int v, int initial)
{
    if ((unsigned)c >= AMFI_COST323_N_CRITERIA || !is_class_value(v))
        return NAN;
    double d = NAN;
    for (int i = 0; i < N_NAMED; i++)
        if (named[i].value == v)
            d = named[i].delta[c];
    if (isnan(d)) { /* class E(v), v > 25 */
        switch (c) {
        case AMFI_COST323_GROSS: d = v; break;
        case AMFI_COST323_GROUP: d = v < 30 ? v + 3.0 : 1.1 * v; break;
        case AMFI_COST323_SINGLE: d = 1.2 * v; break;
        default: d = 1.2 * v + 5.0; break;
        }
    }
    return initial ? 0.8 * d : d;
}

void amfi_cost323_class_name(int v, char *out, size_t outlen)
{
    const char *letter = v <= 0 ? NULL : v <= 5 ? "A" : v <= 7 ? "B+" : v <= 10 ? "B"
                                      : v <= 15 ? "C" : v <= 20 ? "D+" : v <= 25 ? "D" : "E";
    if (!letter)
        snprintf(out, outlen, "none");
    else
        snprintf(out, outlen, "%s(%d)", letter, v);
}

static void say(char *why, size_t whylen, const char *msg)
{
    if (why && whylen)
        snprintf(why, whylen, "%s", msg);
}

struct pi_args {
    int n;
    double m, s, pi0;
};

static double pi_minus_pi0(double delta, void *p)
{
    const struct pi_args *a = p;
    return amfi_cost323_confidence(a->n, a->m, a->s, delta) - a->pi0;
}

/* The δ with π(δ) = π₀ (π increases with δ): Brent's method on a bracket
 * [|m|, hi] widened until π(hi) ≥ π₀. */
static double delta_min(int n, double m, double s, double pi0)
{
    if (s == 0)
        return fabs(m);
    struct pi_args a = {n, m, s, pi0};
    double lo = 0, hi = fabs(m) + s;
    while (pi_minus_pi0(hi, &a) < 0) {
        lo = hi;
        hi *= 2;
        if (hi > 1e9)
            return NAN;
    }
    if (pi_minus_pi0(lo, &a) >= 0)
        return lo;
    gsl_function f = {pi_minus_pi0, &a};
    gsl_root_fsolver *sv = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!sv)
        return NAN;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    double r = NAN;
    if (gsl_root_fsolver_set(sv, &f, lo, hi) == GSL_SUCCESS) {
        for (int it = 0; it < 200; it++) {
            if (gsl_root_fsolver_iterate(sv) != GSL_SUCCESS)
                break;
            double x0 = gsl_root_fsolver_x_lower(sv), x1 = gsl_root_fsolver_x_upper(sv);
            r = gsl_root_fsolver_root(sv);
            if (gsl_root_test_interval(x0, x1, 1e-10, 1e-10) == GSL_SUCCESS)
                break;
        }
    }
    gsl_set_error_handler(old);
    gsl_root_fsolver_free(sv);
    return r;
}

int amfi_cost323_evaluate_stats(amfi_cost323_criterion c, int n, double m, double s,
                                amfi_cost323_condition cond, amfi_cost323_environment env,
                                int initial, amfi_cost323_result *out, char *why,
                                size_t whylen)
{
    if ((unsigned)c >= AMFI_COST323_N_CRITERIA || (unsigned)cond >= AMFI_COST323_N_CONDITIONS ||
        (unsigned)env >= AMFI_COST323_N_ENVIRONMENTS || !out) {
        say(why, whylen, "unknown criterion, condition or environment");
        return -1;
    }
    if (n < 2) {
        say(why, whylen, "fewer than 2 values: no mean and standard deviation");
        return -1;
    }
    if (!isfinite(m) || !isfinite(s) || s < 0) {
        say(why, whylen, "the mean or the standard deviation is not finite");
        return -1;
    }
    memset(out, 0, sizeof *out);
    out->n = n;
    out->mean_pct = m;
    out->std_pct = s;
    out->pi0_pct = amfi_cost323_min_confidence(n, cond, env);
    if (!(out->pi0_pct > 0)) {
        if (why && whylen)
            snprintf(why, whylen,
                     "%d values are too few for a class under %s, environment %s "
                     "(minimum confidence %.1f %% <= 0)",
                     n, condition_names[cond], environment_names[env], out->pi0_pct);
        return -1;
    }
    out->delta_min_pct = delta_min(n, m, s, out->pi0_pct);
    out->delta_pct = NAN;
    out->pi_pct = NAN;
    for (int v = 5; v <= AMFI_COST323_MAX_CLASS; v = v == 5 ? 7 : v == 7 ? 10 : v + 5) {
        double d = amfi_cost323_tolerance(c, v, initial);
        double pi = amfi_cost323_confidence(n, m, s, d);
        if (pi >= out->pi0_pct) {
            out->class_value = v;
            out->delta_pct = d;
            out->pi_pct = pi;
            break;
        }
    }
    amfi_cost323_class_name(out->class_value, out->class_name, sizeof out->class_name);
    return 0;
}

int amfi_cost323_evaluate(amfi_cost323_criterion c, const double *err, int n,
                          amfi_cost323_condition cond, amfi_cost323_environment env,
                          int initial, amfi_cost323_result *out, char *why, size_t whylen)
{
    if (n < 2 || !err) {
        say(why, whylen, "fewer than 2 values: no mean and standard deviation");
        return -1;
    }
    for (int i = 0; i < n; i++)
        if (!isfinite(err[i])) {
            if (why && whylen)
                snprintf(why, whylen, "value %d of %d is not finite", i + 1, n);
            return -1;
        }
    double m = gsl_stats_mean(err, 1, (size_t)n);
    double s = gsl_stats_sd_m(err, 1, (size_t)n, m);
    return amfi_cost323_evaluate_stats(c, n, m, s, cond, env, initial, out, why, whylen);
}
