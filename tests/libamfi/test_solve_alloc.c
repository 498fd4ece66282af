/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_solve_alloc.c: amfi.h's promise that a sized solver allocates
 * nothing: after one solve of a given size (which may grow the workspace),
 * further solves of that size or smaller allocate nothing, for amfi_solve
 * with the L-curve, amfi_solve_multi (one vehicle and several, fixed λ and
 * the L-curve) and amfi_solve_speed.
 *
 * Allocations are counted two ways. The link wraps malloc, calloc and
 * realloc (-Wl,--wrap, tests/libamfi/CMakeLists.txt): every call from this
 * program and from the static libamfi goes through the counters below.
 * Under AddressSanitizer (the suite's tree) the sanitizer's malloc hook
 * counts as well, which also sees allocations inside shared libraries
 * (GSL's minimiser, OpenBLAS, LAPACKE); the wrappers alone do not.
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

#if defined(__SANITIZE_ADDRESS__)
/* sanitizer/allocator_interface.h, declared here: the header is not always
 * installed with the runtime */
int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void *, size_t),
                                              void (*free_hook)(const volatile void *));
#endif

/* ---- counting ---------------------------------------------------------- */
static int counting;          /* count while set */
static long n_wrapped, n_hook; /* allocations seen by the wrappers, the hook */

void *__real_malloc(size_t n);
void *__real_calloc(size_t k, size_t n);
void *__real_realloc(void *p, size_t n);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t k, size_t n);
void *__wrap_realloc(void *p, size_t n);

void *__wrap_malloc(size_t n)
{
    n_wrapped += counting;
    return __real_malloc(n);
}

void *__wrap_calloc(size_t k, size_t n)
{
    n_wrapped += counting;
    return __real_calloc(k, n);
}

void *__wrap_realloc(void *p, size_t n)
{
    n_wrapped += counting;
    return __real_realloc(p, n);
}

#if defined(__SANITIZE_ADDRESS__)
static void on_malloc(const volatile void *p, size_t n)
{
    (void)p, (void)n;
    n_hook += counting;
}

static void on_free(const volatile void *p)
{
    (void)p;
}
#endif

static void count_start(void)
{
    n_wrapped = n_hook = 0;
    counting = 1;
}

/* Allocations since count_start(), both ways together. */
static long count_stop(void)
{
    counting = 0;
    return n_wrapped + n_hook;
}

/* ---- events ------------------------------------------------------------ */
#define SPEED 25.0
#define RATE 1000.0

static double const_force(double t, int a, void *user)
{
    (void)t;
    return ((const double *)user)[a];
}

/* An event of nv vehicles at SPEED entering at entry[v], one mid-span
 * sensor, recorded from t = 0 to the last exit + 0.05 s. */
typedef struct event {
    amfi_multi_passage p;
    double *accel;
} event;

static void record(event *ev, int nv, const double *entry, const int *n_axles,
                   const double *const *spacing, const double *force_N)
{
    memset(ev, 0, sizeof *ev);
    double off[AMFI_MAX_AXLES];
    int na = 0;
    for (int v = 0; v < nv; v++) {
        amfi_vehicle *ve = &ev->p.vehicle[v];
        ve->entry_s = entry[v];
        ve->speed_mps = SPEED;
        ve->n_axles = n_axles[v];
        double o = SPEED * entry[v];
        for (int a = 0; a < n_axles[v]; a++) {
            if (a > 0) {
                ve->axle_spacing_m[a - 1] = spacing[v][a - 1];
                o += spacing[v][a - 1];
            }
            off[na++] = o;
        }
    }
    ev->p.n_vehicles = nv;
    amfi_passage_times w = amfi_multi_window(20.0, &ev->p, 0.0, 0.0);
    int n = (int)((w.end_s + 0.05) * RATE) + 1;
    const double x = 10.0;
    ev->accel = malloc(sizeof(double) * n);
    char err[256];
    assert_int_equal(amfi_forward_newmark(bridge, SPEED, na, off, const_force,
                                          (void *)force_N, 1, &x, 2e-5, RATE, n, ev->accel,
                                          err, sizeof err),
                     0);
    ev->p.n_samples = n;
    ev->p.scan_rate_hz = RATE;
    ev->p.t_first_s = 0.0;
    ev->p.accel[0] = ev->accel;
}

/* The event's first vehicle as an amfi_passage. */
static amfi_passage as_passage(const event *ev)
{
    amfi_passage ps;
    memset(&ps, 0, sizeof ps);
    ps.n_samples = ev->p.n_samples;
    ps.scan_rate_hz = ev->p.scan_rate_hz;
    ps.t_first_s = ev->p.t_first_s - ev->p.vehicle[0].entry_s;
    ps.accel[0] = ev->accel;
    ps.speed_mps = ev->p.vehicle[0].speed_mps;
    ps.n_axles = ev->p.vehicle[0].n_axles;
    memcpy(ps.axle_spacing_m, ev->p.vehicle[0].axle_spacing_m, sizeof ps.axle_spacing_m);
    return ps;
}

static amfi_solver *make_solver(int max_axles)
{
    amfi_solver_params sp;
    amfi_solver *s = NULL;
    char err[256];
    amfi_solver_params_default(&sp, 20.0);
    sp.n_sensors = 1;
    sp.sensor_x_m[0] = 10.0;
    sp.sensor_weight[0] = 1.0;
    sp.calc_rate_hz = 2000.0; /* fewer steps than the default 5000 Hz: the promise does not depend on the rate */
    sp.max_axles = max_axles;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    return s;
}

static const double sp5[4] = {3.6, 6.0, 1.31, 1.31}; /* a tractor and tridem semi-trailer */
static const double f5[5] = {60000.0, 105000.0, 75000.0, 75000.0, 75000.0};
static const double sp2[1] = {4.5};
static const double f2[2] = {50000.0, 70000.0};

#define REPEAT 2

/* amfi_solve with the L-curve: the solver is sized at creation for the
 * default search (its points included), so even the first solve allocates
 * nothing; a longer search grows the points once, and the solves after it
 * allocate nothing. */
static void solve_lcurve_allocates_once(void **state)
{
    (void)state;
    event ev;
    const double entry[1] = {0.0};
    const int na[1] = {5};
    const double *const sp[1] = {sp5};
    record(&ev, 1, entry, na, sp, f5);
    amfi_solver *s = make_solver(5);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    lam.automatic = 1;
    amfi_passage ps = as_passage(&ev);
    amfi_result r;
    char err[256];
    count_start();
    assert_int_equal(amfi_solve(s, &ps, &lam, &r, err, sizeof err), 0);
    long n = count_stop();
    printf("# amfi_solve, first (L-curve, %d points): %ld allocations\n", r.lcurve_n, n);
    assert_int_equal(n, 0);
    const double gvw = r.gvw_kg;
    count_start();
    for (int k = 0; k < REPEAT; k++)
        assert_int_equal(amfi_solve(s, &ps, &lam, &r, err, sizeof err), 0);
    n = count_stop();
    printf("# amfi_solve (L-curve): %ld allocations in %d solves\n", n, REPEAT);
    assert_int_equal(n, 0);
    assert_true(r.gvw_kg == gvw); /* the same answer each time */
    /* a finer search: more points than the default */
    lam.lcurve_per_decade = 6;
    assert_int_equal(amfi_solve(s, &ps, &lam, &r, err, sizeof err), 0);
    const int npts = r.lcurve_n;
    count_start();
    for (int k = 0; k < REPEAT; k++)
        assert_int_equal(amfi_solve(s, &ps, &lam, &r, err, sizeof err), 0);
    n = count_stop();
    printf("# amfi_solve (L-curve, %d points): %ld allocations in %d solves\n", npts, n,
           REPEAT);
    assert_true(npts > 21);
    assert_int_equal(n, 0);
    amfi_solver_destroy(s);
    free(ev.accel);
}

/* amfi_solve_multi, two vehicles (quality and separability figures), fixed
 * λ and the L-curve; then a smaller event on the same solver. */
static void solve_multi_allocates_once(void **state)
{
    (void)state;
    event big, small;
    const double entry[2] = {0.0, 0.45};
    const int na[2] = {5, 2};
    const double *const sp[2] = {sp5, sp2};
    double f[7];
    memcpy(f, f5, sizeof f5);
    memcpy(f + 5, f2, sizeof f2);
    record(&big, 2, entry, na, sp, f);
    record(&small, 1, entry, na + 1, sp + 1, f2);

    amfi_solver *s = make_solver(2); /* the 7-axle event grows it */
    amfi_multi_result r;
    char err[256];
    for (int automatic = 0; automatic <= 1; automatic++) {
        amfi_lambda lam;
        amfi_lambda_default(&lam);
        lam.automatic = automatic;
        assert_int_equal(amfi_solve_multi(s, &big.p, &lam, &r, err, sizeof err), 0);
        const double total = r.total_gvw_kg, q = r.vehicle[1].quality;
        count_start();
        for (int k = 0; k < REPEAT; k++)
            assert_int_equal(amfi_solve_multi(s, &big.p, &lam, &r, err, sizeof err), 0);
        long n = count_stop();
        printf("# amfi_solve_multi (2 vehicles, 7 axles, %s): %ld allocations in %d solves\n",
               automatic ? "L-curve" : "fixed lambda", n, REPEAT);
        assert_int_equal(n, 0);
        assert_true(r.total_gvw_kg == total && r.vehicle[1].quality == q);
        assert_true(isfinite(r.vehicle[0].separability) && r.vehicle[0].separability >= 1.0);
        /* a smaller event on the grown solver: nothing to grow */
        count_start();
        for (int k = 0; k < REPEAT; k++)
            assert_int_equal(amfi_solve_multi(s, &small.p, &lam, &r, err, sizeof err), 0);
        n = count_stop();
        printf("# amfi_solve_multi (1 vehicle, 2 axles, after 7): %ld allocations\n", n);
        assert_int_equal(n, 0);
    }
    amfi_solver_destroy(s);
    free(big.accel);
    free(small.accel);
}

/* amfi_solve_speed (the two-level search: coarse model, grid, Brent). */
static void solve_speed_allocates_once(void **state)
{
    (void)state;
    event ev;
    const double entry[1] = {0.0};
    const int na[1] = {2};
    const double *const sp[1] = {sp2};
    record(&ev, 1, entry, na, sp, f2);
    amfi_solver *s = make_solver(2);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_speed_prior pr;
    amfi_speed_prior_default(&pr);
    amfi_passage ps = as_passage(&ev);
    ps.speed_mps = SPEED * 1.02; /* the detector's estimate, 2 % off */
    amfi_result r;
    amfi_speed_result sr;
    char err[256];
    assert_int_equal(amfi_solve_speed(s, &ps, &lam, &pr, &r, &sr, err, sizeof err), 0);
    const double v = sr.speed_mps;
    count_start();
    for (int k = 0; k < REPEAT; k++)
        assert_int_equal(amfi_solve_speed(s, &ps, &lam, &pr, &r, &sr, err, sizeof err), 0);
    long n = count_stop();
    printf("# amfi_solve_speed: %ld allocations in %d solves (speed %.3f m/s)\n", n, REPEAT,
           sr.speed_mps);
    assert_int_equal(n, 0);
    assert_true(sr.speed_mps == v);
    /* the refinement by GSL's Brent minimiser: one per solver, kept (its
     * allocation is inside GSL, seen by the sanitizer's hook) */
    pr.brent_evals = 6;
    assert_int_equal(amfi_solve_speed(s, &ps, &lam, &pr, &r, &sr, err, sizeof err), 0);
    count_start();
    for (int k = 0; k < REPEAT; k++)
        assert_int_equal(amfi_solve_speed(s, &ps, &lam, &pr, &r, &sr, err, sizeof err), 0);
    n = count_stop();
    printf("# amfi_solve_speed (Brent, %d sweeps): %ld allocations in %d solves\n", sr.n_evals,
           n, REPEAT);
    assert_int_equal(n, 0);
    amfi_solver_destroy(s);
    free(ev.accel);
}

/* The counters themselves: a malloc in the window is seen. */
static void counter_sees_malloc(void **state)
{
    (void)state;
    void *(*volatile alloc)(size_t) = malloc; /* not elided with the free */
    count_start();
    void *p = alloc(64);
    long n = count_stop();
    free(p);
    assert_true(n >= 1);
}

int main(void)
{
#if defined(__SANITIZE_ADDRESS__)
    __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
#endif
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(counter_sees_malloc),
        cmocka_unit_test(solve_lcurve_allocates_once),
        cmocka_unit_test(solve_multi_allocates_once),
        cmocka_unit_test(solve_speed_allocates_once),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
