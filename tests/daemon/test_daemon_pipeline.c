/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_daemon_pipeline.c: amfid's reorder buffer (daemon/reorder.c) and
 * store sink (daemon/sink.c) on their own.
 *
 * The reorder buffer hands passages on in release order whatever order
 * they come back in, grows when one lands far ahead, and refuses (abort,
 * an assert()) to park a passage over a parked one: the pipeline before it
 * overwrote the slot without looking, losing a passage silently.
 *
 * The sink writes through a store that refuses (a full or read-only disk)
 * and then recovers: nothing acknowledged is lost, the order is kept, a
 * passage that comes while others are held waits behind them, the held
 * queue never exceeds its bound in bytes, what overflows is counted, the
 * degraded state is raised once and cleared once, and at shutdown what the
 * store still refuses is counted as lost.
 */
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "log.h"
#include "reorder.h"
#include "sink.h"

static job *mkjob(int64_t seq)
{
    job *j = calloc(1, sizeof *j);
    assert_non_null(j);
    j->w.seq = seq;
    j->w.v.vehicle_id = seq;
    j->accel = malloc(64 * sizeof(double)); /* freed when held, or with the job */
    assert_non_null(j->accel);
    return j;
}

/* ---- reorder buffer --------------------------------------------------------- */

static void reorder_in_order_of_release(void **state)
{
    (void)state;
    reorder *r = reorder_create(8, 1);
    assert_non_null(r);
    const int64_t came[] = {3, 2, 5, 1, 4, 6};
    int64_t out[6];
    int n = 0;
    for (int i = 0; i < 6; i++) {
        assert_int_equal(reorder_park(r, mkjob(came[i])), 0);
        job *j;
        while ((j = reorder_next(r)) != NULL) {
            out[n++] = j->w.seq;
            job_free(j);
        }
        if (i < 3) /* 1 has not come back yet: nothing handed on */
            assert_int_equal(n, 0);
    }
    assert_int_equal(n, 6);
    for (int i = 0; i < 6; i++)
        assert_int_equal(out[i], i + 1);
    assert_int_equal(reorder_parked(r), 0);
    assert_int_equal(reorder_next_seq(r), 7);
    reorder_destroy(r);
}

static void reorder_grows_never_drops(void **state)
{
    (void)state;
    reorder *r = reorder_create(4, 1);
    assert_non_null(r);
    for (int64_t s = 100; s >= 2; s--) /* 1 is late: 99 wait, far past 4 slots */
        assert_int_equal(reorder_park(r, mkjob(s)), 0);
    assert_null(reorder_next(r));
    assert_int_equal(reorder_parked(r), 99);
    assert_true(reorder_capacity(r) >= 100);
    assert_int_equal(reorder_park(r, mkjob(1)), 0);
    for (int64_t s = 1; s <= 100; s++) {
        job *j = reorder_next(r);
        assert_non_null(j);
        assert_int_equal(j->w.seq, s);
        job_free(j);
    }
    assert_null(reorder_next(r));
    /* parked jobs left at destroy are freed (the sanitizer tree sees a leak) */
    assert_int_equal(reorder_park(r, mkjob(102)), 0);
    reorder_destroy(r);
}

/* In a child: 0 when fn returned, the signal when it died of one. */
static int dies_of(void (*fn)(void))
{
    fflush(NULL);
    pid_t p = fork();
    assert_true(p >= 0);
    if (p == 0) {
        /* the abort is expected: no core, no sanitizer report wanted */
        signal(SIGABRT, SIG_DFL);
        fclose(stderr);
        fn();
        _exit(0);
    }
    int st = 0;
    assert_int_equal(waitpid(p, &st, 0), p);
    return WIFSIGNALED(st) ? WTERMSIG(st) : 0;
}

static void park_twice(void)
{
    reorder *r = reorder_create(8, 1);
    reorder_park(r, mkjob(3));
    reorder_park(r, mkjob(3)); /* the slot is taken: assert() */
}

static void park_released(void)
{
    reorder *r = reorder_create(8, 1);
    reorder_park(r, mkjob(1));
    job_free(reorder_next(r));
    reorder_park(r, mkjob(1)); /* seq 1 was handed on already: assert() */
}

static void reorder_invariants_asserted(void **state)
{
    (void)state;
    assert_int_equal(dies_of(park_twice), SIGABRT);
    assert_int_equal(dies_of(park_released), SIGABRT);
}

/* ---- the sink, through a store that refuses, then recovers ------------------- */

typedef struct fake_store {
    int refuse;       /* 1: every write refused (disk full, read-only) */
    int budget;       /* >= 0: writes accepted before it refuses again; −1: no limit */
    int64_t written[256];
    int n;
    int raised, cleared;
    int calls;
    char last_error[64];
} fake_store;

static int fake_write(void *arg, job *j)
{
    fake_store *f = arg;
    f->calls++;
    if (f->refuse || f->budget == 0) {
        snprintf(f->last_error, sizeof f->last_error, "database or disk is full");
        return -1;
    }
    if (f->budget > 0)
        f->budget--;
    assert_true(f->n < 256);
    f->written[f->n++] = j->w.seq;
    return 0;
}

static void fake_degraded(void *arg, int on)
{
    fake_store *f = arg;
    if (on)
        f->raised++;
    else
        f->cleared++;
}

static sink *mksink(fake_store *f, size_t max_bytes)
{
    memset(f, 0, sizeof *f);
    f->budget = -1;
    sink_params p = {max_bytes, 0.0, 0.0}; /* retry at once: no waiting in a test */
    sink_ops ops = {fake_write, fake_degraded, f, f->last_error};
    sink *s = sink_create(&p, &ops);
    assert_non_null(s);
    return s;
}

static void check_bound(const sink *s, size_t max_bytes)
{
    sink_stats st;
    sink_stats_of(s, &st);
    assert_true(st.bytes <= max_bytes);
    assert_true(st.peak_bytes <= max_bytes);
    assert_int_equal(st.bytes, (size_t)st.held * sizeof(job));
}

static void sink_holds_in_order_and_recovers(void **state)
{
    (void)state;
    fake_store f;
    const size_t max = 10 * sizeof(job);
    sink *s = mksink(&f, max);
    f.refuse = 1;
    for (int64_t q = 1; q <= 5; q++)
        assert_int_equal(sink_put(s, mkjob(q)), -1);
    sink_stats st;
    sink_stats_of(s, &st);
    assert_int_equal(st.held, 5);
    assert_int_equal(st.degraded, 1);
    assert_int_equal(f.raised, 1); /* raised once, not per passage */
    check_bound(s, max);
    /* the store writes again, but a new passage still waits behind the held */
    f.refuse = 0;
    const int calls = f.calls;
    assert_int_equal(sink_put(s, mkjob(6)), -1);
    assert_int_equal(f.calls, calls);
    assert_int_equal(f.n, 0);
    sink_retry(s, 0);
    sink_stats_of(s, &st);
    assert_int_equal(st.held, 0);
    assert_int_equal(st.bytes, 0);
    assert_int_equal(st.degraded, 0);
    assert_int_equal(st.lost, 0);
    assert_int_equal(st.peak, 6);
    assert_int_equal(f.cleared, 1);
    assert_int_equal(f.n, 6);
    for (int i = 0; i < 6; i++)
        assert_int_equal(f.written[i], i + 1);
    /* and then straight through */
    assert_int_equal(sink_put(s, mkjob(7)), 0);
    assert_int_equal(f.written[6], 7);
    sink_destroy(s);
}

static void sink_bound_in_bytes(void **state)
{
    (void)state;
    fake_store f;
    const size_t max = 3 * sizeof(job) + sizeof(job) / 2; /* room for 3 */
    sink *s = mksink(&f, max);
    assert_int_equal(sink_capacity(s), 3);
    f.refuse = 1;
    for (int64_t q = 1; q <= 5; q++) {
        sink_put(s, mkjob(q));
        check_bound(s, max);
    }
    sink_stats st;
    sink_stats_of(s, &st);
    assert_int_equal(st.held, 3);
    assert_int_equal(st.lost, 2);
    assert_int_equal(st.overflow, 2);
    f.refuse = 0;
    sink_retry(s, 0);
    assert_int_equal(f.n, 3);
    for (int i = 0; i < 3; i++) /* the oldest were kept, the overflow was the newest */
        assert_int_equal(f.written[i], i + 1);
    sink_stats_of(s, &st);
    assert_int_equal(st.lost, 2);
    assert_int_equal(st.degraded, 0);
    sink_destroy(s);
}

static void sink_partial_recovery_keeps_order(void **state)
{
    (void)state;
    fake_store f;
    sink *s = mksink(&f, 100 * sizeof(job));
    f.refuse = 1;
    for (int64_t q = 1; q <= 8; q++)
        sink_put(s, mkjob(q));
    f.refuse = 0;
    f.budget = 3; /* three writes, then it refuses again */
    sink_retry(s, 0);
    sink_stats st;
    sink_stats_of(s, &st);
    assert_int_equal(st.held, 5);
    assert_int_equal(st.degraded, 1);
    assert_int_equal(f.cleared, 0);
    sink_put(s, mkjob(9)); /* behind the held */
    f.budget = -1;
    sink_retry(s, 0);
    assert_int_equal(f.n, 9);
    for (int i = 0; i < 9; i++)
        assert_int_equal(f.written[i], i + 1);
    assert_int_equal(f.raised, 1);
    assert_int_equal(f.cleared, 1);
    sink_destroy(s);
}

static void sink_shutdown_counts_what_is_refused(void **state)
{
    (void)state;
    fake_store f;
    sink *s = mksink(&f, 100 * sizeof(job));
    f.refuse = 1;
    for (int64_t q = 1; q <= 4; q++)
        sink_put(s, mkjob(q));
    sink_retry(s, 0.05); /* stopping: a bounded wait, then counted */
    sink_stats st;
    sink_stats_of(s, &st);
    assert_int_equal(st.held, 0);
    assert_int_equal(st.bytes, 0);
    assert_int_equal(st.lost, 4);
    assert_int_equal(st.overflow, 0);
    sink_lost(s, 1);
    sink_stats_of(s, &st);
    assert_int_equal(st.lost, 5);
    sink_destroy(s);
}

static void sink_refuses_a_bound_below_one_passage(void **state)
{
    (void)state;
    fake_store f;
    sink_params p = {sizeof(job) - 1, 1.0, 30.0};
    sink_ops ops = {fake_write, fake_degraded, &f, NULL};
    assert_null(sink_create(&p, &ops));
}

int main(void)
{
    amfid_log_stream = fopen("/dev/null", "w");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(reorder_in_order_of_release),
        cmocka_unit_test(reorder_grows_never_drops),
        cmocka_unit_test(reorder_invariants_asserted),
        cmocka_unit_test(sink_holds_in_order_and_recovers),
        cmocka_unit_test(sink_bound_in_bytes),
        cmocka_unit_test(sink_partial_recovery_keeps_order),
        cmocka_unit_test(sink_shutdown_counts_what_is_refused),
        cmocka_unit_test(sink_refuses_a_bound_below_one_passage),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
