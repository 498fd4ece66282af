/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cost323.h: the accuracy classes of weigh-in-motion systems in the COST 323
 * European specification (B. Jacob, E. J. O'Brien, S. Jehaes (eds.),
 * "Weigh-in-Motion of Road Vehicles: Final Report of the COST 323 Action",
 * LCPC, Paris, 2002, appendix 1).
 *
 * A criterion's relative errors e_i = 100 (measured − reference) / reference
 * (%) over n vehicles have a mean m and a sample standard deviation s. For a
 * tolerance δ, the confidence that an error lies in [−δ, δ], from Student's
 * t with n − 1 degrees of freedom and its two-sided 95 % quantile t,
 *
 *     π(δ) = 1 − Q((δ − m)/s − t/√n) − Q((δ + m)/s − t/√n),
 *
 * Q the upper tail of Student's t (n − 1). A class is accepted for a
 * criterion when π(δ) ≥ π₀ for that criterion's δ at the class, where the
 * minimum confidence depends on the test conditions and the environment:
 *
 *     π₀ = 2 Φ(ν / f − t/√n) − 1,
 *
 * ν = 2.675 (r1, full repeatability), 2.36 (r2, extended repeatability),
 * 2.155 (RR1, limited reproducibility), 2.0 (RR2, full reproducibility) and
 * f = 1, 1.05, 1.1 for environments I, II, III. The classes and their
 * tolerances δ (%):
 *
 *     class          A(5)  B+(7)  B(10)  C(15)  D+(20)  D(25)  E(v), v > 25
 *     gross weight      5      7     10     15      20     25    v
 *     group of axles    7     10     13     18      23     28    v + 3 (v < 30), 1.1 v
 *     single axle       8     11     15     20      25     30    1.2 v
 *     axle of a group  10     14     20     25      30     35    1.2 v + 5
 *
 * (E classes by steps of 5.) At an initial verification the tolerances are
 * reduced to 0.8 δ. The accepted class of a criterion is the best class whose
 * δ satisfies π(δ) ≥ π₀; the system's class is the worst of its criteria's.
 * Pure computation on GSL's distributions; no allocation; thread-safe.
 */
#ifndef AMFI_COST323_H
#define AMFI_COST323_H

#include <stddef.h>

typedef enum {
    AMFI_COST323_GROSS = 0,   /* gross vehicle weight */
    AMFI_COST323_GROUP,       /* a group of axles (tandem, tridem) as a whole */
    AMFI_COST323_SINGLE,      /* a single axle (not in a group) */
    AMFI_COST323_GROUP_AXLE,  /* one axle inside a group */
    AMFI_COST323_N_CRITERIA
} amfi_cost323_criterion;

typedef enum {
    AMFI_COST323_R1 = 0, /* full repeatability: one vehicle, many runs, one speed and load */
    AMFI_COST323_R2,     /* extended repeatability: a few vehicles, speeds, loads */
    AMFI_COST323_RR1,    /* limited reproducibility: a few vehicles, a short period */
    AMFI_COST323_RR2,    /* full reproducibility: traffic or many vehicles over time */
    AMFI_COST323_N_CONDITIONS
} amfi_cost323_condition;

typedef enum {
    AMFI_COST323_ENV_I = 0, /* environmental repeatability: one period, stable */
    AMFI_COST323_ENV_II,    /* limited environmental reproducibility */
    AMFI_COST323_ENV_III,   /* full environmental reproducibility: a year */
    AMFI_COST323_N_ENVIRONMENTS
} amfi_cost323_environment;

/* The largest class value tried (E(100)); a criterion worse than that has
 * no class (class_value 0, class_name "none"). */
#define AMFI_COST323_MAX_CLASS 100

typedef struct {
    int n;               /* vehicles (or axles, groups) */
    double mean_pct;     /* mean relative error m, % */
    double std_pct;      /* sample standard deviation s (n − 1), % */
    double pi0_pct;      /* minimum confidence π₀ for n and the conditions, % */
    double delta_min_pct;/* the smallest δ with π(δ) = π₀ (the criterion's own
                            tolerance, before rounding to a class), % */
    int class_value;     /* the accepted class's gross-weight value: 5, 7, 10,
                            15, 20, 25, 30, 35, ...; 0 = none up to E(100) */
    double delta_pct;    /* the criterion's tolerance at that class, % */
    double pi_pct;       /* π(delta_pct): the confidence reached, % */
    char class_name[16]; /* "A(5)", "B+(7)", "B(10)", ..., "E(30)", "none" */
} amfi_cost323_result;

/* Names as in the specification and on amfi-accuracy's command line:
 * "gross", "group", "single", "group_axle"; "r1", "r2", "RR1", "RR2";
 * "I", "II", "III". The parsers take exactly these spellings and return 0,
 * or −1 for anything else. */
const char *amfi_cost323_criterion_name(amfi_cost323_criterion c);
int amfi_cost323_criterion_parse(const char *s, amfi_cost323_criterion *out);
const char *amfi_cost323_condition_name(amfi_cost323_condition c);
int amfi_cost323_condition_parse(const char *s, amfi_cost323_condition *out);
const char *amfi_cost323_environment_name(amfi_cost323_environment e);
int amfi_cost323_environment_parse(const char *s, amfi_cost323_environment *out);

/* π₀ in % for n ≥ 2 samples; NaN for n < 2 or an unknown condition. It can
 * be ≤ 0 for very small n (no class can then be stated). */
double amfi_cost323_min_confidence(int n, amfi_cost323_condition cond,
                                   amfi_cost323_environment env);

/* π(δ) in % for n ≥ 2, mean m and standard deviation s ≥ 0 (%); s = 0 gives
 * 100 when |m| < δ and 0 otherwise. NaN for bad arguments. */
double amfi_cost323_confidence(int n, double mean_pct, double std_pct, double delta_pct);

/* The criterion's tolerance δ (%) at the class whose gross-weight value is
 * class_value (5, 7, 10, 15, 20, 25, then multiples of 5), times 0.8 at an
 * initial verification. NaN for a value that is not a class. */
double amfi_cost323_tolerance(amfi_cost323_criterion c, int class_value, int initial_verification);

/* "A(5)" etc. for a class value into out (at least 16 bytes); "none" for 0. */
void amfi_cost323_class_name(int class_value, char *out, size_t outlen);

/* Evaluates one criterion from its relative errors err_pct[0 .. n) (%).
 * 0 and *out; −1 with a one-line reason in why (whylen bytes) when n < 2,
 * an error is not finite, or π₀ ≤ 0 (too few samples for any class). A
 * criterion whose errors reach no class up to E(100) returns 0 with
 * class_value 0. */
int amfi_cost323_evaluate(amfi_cost323_criterion c, const double *err_pct, int n,
                          amfi_cost323_condition cond, amfi_cost323_environment env,
                          int initial_verification, amfi_cost323_result *out,
                          char *why, size_t whylen);

/* The same from n, m and s already computed (the published cases). */
int amfi_cost323_evaluate_stats(amfi_cost323_criterion c, int n, double mean_pct,
                                double std_pct, amfi_cost323_condition cond,
                                amfi_cost323_environment env, int initial_verification,
                                amfi_cost323_result *out, char *why, size_t whylen);

#endif
