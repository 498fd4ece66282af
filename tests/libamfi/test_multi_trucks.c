/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_multi_trucks.c: amfi_solve_multi on three of the worst truck pairs
 * of tools/research/amfi-multi --population (coupled multi-body trucks on
 * the paper-20m bridge, class A road, one mid-span sensor at 1000 Hz, no
 * noise; the records in tests/libamfi/data/pair-*.txt, their origin in
 * each file's header). Solved as amfid's site solves them (paper-20m: modal,
 * observable modes, 5000 Hz, free initial state, 0.3 s pre-roll, the
 * paper's fixed λ).
 *
 * Before round six (docs/results/multi-vehicle.md) the joint solve weighed
 * an event of several vehicles at the fixed λ of one vehicle, which
 * over-smooths it: these pairs' sums erred −6.80, −4.53 and −4.36 % (each
 * vehicle up to −8.6 %), the same vehicles solved alone within 2.7 %. The
 * default now weighs them at λ/10: −1.36, −0.81 and −1.19 %. The limit,
 * 2.5 % on the pair's sum, is what the issue's independent joint solve
 * reached at worst (1.4 %) with room for the BLAS kernels and the
 * recorded 7 digits, and half the old code's smallest error here; each
 * vehicle within 5 % (the old code: up to 8.6 %; now up to 3.3 %). The
 * quality figure is the old one (the change between λ and λ/10): above 3
 * for each of these vehicles (the events the issue found at 3.4-8.3).
 *
 * usage: test_multi_trucks DATA_DIR
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

static const char *data_dir;

typedef struct pair_case {
    amfi_multi_passage p;
    double truth_kg[2];
    double *accel;
} pair_case;

/* Read DATA_DIR/name: '#' comments, "rate_hz R", two "vehicle ENTRY_S
 * SPEED S1,S2,...", "truth_kg T1 T2", "accel", then one sample a line. */
static void load(const char *name, pair_case *c)
{
    char path[4096], line[512];
    snprintf(path, sizeof path, "%s/%s", data_dir, name);
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("%s: cannot be opened", path);
    memset(c, 0, sizeof *c);
    int cap = 0, n = 0, in_accel = 0, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (line[0] == '#' || line[0] == '\n')
            continue;
        if (in_accel) {
            if (n == cap) {
                cap = cap ? 2 * cap : 4096;
                c->accel = realloc(c->accel, sizeof(double) * (size_t)cap);
                assert_non_null(c->accel);
            }
            char *end;
            c->accel[n] = strtod(line, &end);
            if (end == line || !isfinite(c->accel[n]))
                fail_msg("%s:%d: not a sample", path, lineno);
            n++;
        } else if (strncmp(line, "rate_hz ", 8) == 0) {
            c->p.scan_rate_hz = strtod(line + 8, NULL);
        } else if (strncmp(line, "vehicle ", 8) == 0) {
            assert_true(c->p.n_vehicles < 2);
            amfi_vehicle *v = &c->p.vehicle[c->p.n_vehicles++];
            char *s = line + 8, *end;
            v->entry_s = strtod(s, &end);
            v->speed_mps = strtod(end, &end);
            v->n_axles = 1;
            while (*end == ' ')
                end++;
            for (s = end; *s && *s != '\n'; s = end + (*end == ',')) {
                assert_true(v->n_axles < AMFI_MAX_AXLES);
                v->axle_spacing_m[v->n_axles - 1] = strtod(s, &end);
                if (end == s)
                    fail_msg("%s:%d: bad spacing", path, lineno);
                v->n_axles++;
            }
        } else if (strncmp(line, "truth_kg ", 9) == 0) {
            if (sscanf(line + 9, "%lf %lf", &c->truth_kg[0], &c->truth_kg[1]) != 2)
                fail_msg("%s:%d: truth_kg needs two weights", path, lineno);
        } else if (strcmp(line, "accel\n") == 0) {
            in_accel = 1;
        } else {
            fail_msg("%s:%d: unknown line", path, lineno);
        }
    }
    fclose(f);
    assert_int_equal(c->p.n_vehicles, 2);
    assert_true(c->p.scan_rate_hz > 0 && c->truth_kg[0] > 0 && c->truth_kg[1] > 0 && n > 100);
    c->p.n_samples = n;
    c->p.t_first_s = 0.0;
    c->p.accel[0] = c->accel;
}

static amfi_solver *site_solver(void)
{
    amfi_solver_params sp;
    amfi_solver *s = NULL;
    char err[256];
    amfi_solver_params_default(&sp, 20.0); /* one mid-span sensor, 5000 Hz, observable */
    sp.free_initial_state = 1;             /* paper-20m.yaml's site choices */
    sp.pre_roll_s = 0.3;
    sp.max_axles = AMFI_MAX_AXLES;
    sp.max_duration_s = 3.0;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    return s;
}

/* Solve one pair (lambda_factor f: 0 the default, 1 the old weights) and
 * return the pair sum's error; each vehicle's in e[2], its quality in q[2]. */
static double solve_pair(amfi_solver *s, pair_case *c, double f, double *e, double *q)
{
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_multi_result *r = malloc(sizeof *r);
    char err[256];
    c->p.lambda_factor = f;
    if (amfi_solve_multi(s, &c->p, &lam, r, err, sizeof err) != 0)
        fail_msg("solve: %s", err);
    for (int v = 0; v < 2; v++) {
        e[v] = r->vehicle[v].gvw_kg / c->truth_kg[v] - 1.0;
        q[v] = r->vehicle[v].quality;
    }
    double sum = r->total_gvw_kg / (c->truth_kg[0] + c->truth_kg[1]) - 1.0;
    free(r);
    return sum;
}

static void worst_truck_pairs(void **state)
{
    (void)state;
    static const char *const files[] = {"pair-a33-a23.txt", "pair-a23-a22.txt",
                                        "pair-r2-a23.txt"};
    amfi_solver *s = site_solver();
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        pair_case c;
        load(files[k], &c);
        double e[2], q[2], e1[2], q1[2];
        double sum = solve_pair(s, &c, 0.0, e, q);
        double sum1 = solve_pair(s, &c, 1.0, e1, q1);
        printf("# %s: pair %+.2f %% (at λ: %+.2f %%), vehicles %+.2f %+.2f %% (at λ: %+.2f "
               "%+.2f %%), quality %.2f %.2f\n",
               files[k], 100 * sum, 100 * sum1, 100 * e[0], 100 * e[1], 100 * e1[0],
               100 * e1[1], q[0], q[1]);
        assert_true(fabs(sum) < 0.025);
        for (int v = 0; v < 2; v++) {
            assert_true(fabs(e[v]) < 0.05);
            /* the quality figure is the old one: the same with f = 1 */
            assert_true(fabs(q[v] - q1[v]) <= 1e-9 * q1[v]);
            assert_true(q[v] > 3.0);
        }
        free(c.accel);
    }
    amfi_solver_destroy(s);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_multi_trucks DATA_DIR\n");
        return 2;
    }
    data_dir = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(worst_truck_pairs),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
