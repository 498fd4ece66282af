/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_daemon_core.c: the sample ring (gaps, duplicates, out-of-order and
 * late blocks) and the passage tracker (windows in data time, release
 * order, gaps, late vehicle events, multiple presence; events of vehicles
 * sharing the span: chains, two lanes, the limits, contradicting events;
 * the free vibration after the last exit).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "ring.h"
#include "tracker.h"

#define RATE 1000.0
#define T0 1767225600000000LL /* µs */

static void block(double *x, int n, double v)
{
    for (int i = 0; i < n; i++)
        x[i] = v + i;
}

static void ring_in_order_and_gaps(void **state)
{
    (void)state;
    amfi_ring *r = amfi_ring_create(RATE, 10.0);
    double x[100], out[300];
    block(x, 100, 0);
    assert_int_equal(amfi_ring_put(r, T0, RATE, 100, x, NULL), AMFI_RING_OK);
    block(x, 100, 100);
    assert_int_equal(amfi_ring_put(r, T0 + 100000, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_int_equal(amfi_ring_newest(r), 199);
    assert_int_equal(amfi_ring_get(r, 0, 200, out), 0);
    assert_true(out[150] == 150.0);
    /* skip one block: 100 samples missing */
    block(x, 100, 300);
    assert_int_equal(amfi_ring_put(r, T0 + 300000, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_int_equal(amfi_ring_get(r, 150, 200, out), 100);
    assert_int_equal(amfi_ring_stats_of(r)->missing, 100);
    /* the missing block arrives late (out of order): the gap fills */
    block(x, 100, 200);
    assert_int_equal(amfi_ring_put(r, T0 + 200000, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_int_equal(amfi_ring_get(r, 150, 200, out), 0);
    assert_true(out[100] == 250.0);
    assert_int_equal(amfi_ring_stats_of(r)->missing, 0);
    /* a duplicate */
    assert_int_equal(amfi_ring_put(r, T0 + 200000, RATE, 100, x, NULL), AMFI_RING_DUP);
    assert_int_equal(amfi_ring_stats_of(r)->duplicates, 1);
    /* not held: beyond the newest */
    assert_int_equal(amfi_ring_get(r, 350, 100, out), -1);
    amfi_ring_destroy(r);
}

static void ring_rejects_and_late(void **state)
{
    (void)state;
    amfi_ring *r = amfi_ring_create(RATE, 5.0);
    double x[100];
    const char *why = NULL;
    block(x, 100, 0);
    assert_int_equal(amfi_ring_put(r, T0, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_int_equal(amfi_ring_put(r, T0 + 100000, 999.0, 100, x, &why), AMFI_RING_REJECT);
    assert_non_null(strstr(why, "rate"));
    assert_int_equal(amfi_ring_put(r, T0 + 100400, RATE, 100, x, &why), AMFI_RING_REJECT);
    assert_non_null(strstr(why, "grid"));
    /* one block two hours ahead is quarantined, not adopted (issue 9: it used
     * to be refused, and after a real outage every later block with it) */
    assert_int_equal(amfi_ring_put(r, T0 + 7200000000LL, RATE, 100, x, &why),
                     AMFI_RING_QUARANTINE);
    assert_int_equal(amfi_ring_newest(r), 99);
    /* run 10 s ahead; the first block is now older than the ring */
    for (int k = 1; k <= 100; k++)
        assert_int_equal(amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL),
                         AMFI_RING_OK);
    assert_int_equal(amfi_ring_put(r, T0, RATE, 100, x, NULL), AMFI_RING_LATE);
    assert_int_equal(amfi_ring_stats_of(r)->late, 1);
    amfi_ring_destroy(r);
}

static amfi_ring *filled(double seconds_of_data)
{
    amfi_ring *r = amfi_ring_create(RATE, 60.0);
    double x[100];
    block(x, 100, 0);
    for (int k = 0; k < (int)(seconds_of_data * 10); k++)
        amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL);
    return r;
}

static amfi_vehicle_ev vehicle(int64_t id, double entry_s)
{
    amfi_vehicle_ev v;
    memset(&v, 0, sizeof v);
    v.vehicle_id = id;
    v.utime = T0 + (int64_t)(entry_s * 1e6);
    v.speed_mps = 25.0;
    v.n_axles = 2;
    v.spacing_m[0] = 5.0;
    return v;
}

/* A single block dated far ahead never moves the stream's time; the stream
 * goes on and the candidate is dropped. */
static void ring_one_wrong_time_is_ignored(void **state)
{
    (void)state;
    amfi_ring *r = amfi_ring_create(RATE, 5.0);
    double x[100];
    block(x, 100, 1.0);
    for (int k = 0; k < 10; k++)
        assert_int_equal(amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL), AMFI_RING_OK);
    const int64_t far[] = {T0 + 3600000000LL, (int64_t)253402300799000000LL, INT64_MAX / 2};
    for (int i = 0; i < 3; i++) {
        assert_int_equal(amfi_ring_put(r, far[i], RATE, 100, x, NULL), AMFI_RING_QUARANTINE);
        assert_int_equal(amfi_ring_put(r, T0 + (10 + i) * 100000LL, RATE, 100, x, NULL),
                         AMFI_RING_OK);
        assert_int_equal(amfi_ring_jump_pending(r), 0);
    }
    assert_int_equal(amfi_ring_newest(r), 1299);
    assert_int_equal(amfi_ring_stats_of(r)->quarantined, 3);
    assert_int_equal(amfi_ring_stats_of(r)->restarts, 0);
    amfi_ring_destroy(r);
}

/* An outage of two hours, then the stream resumes: confirmed after
 * AMFI_RING_CONFIRM blocks, the ring restarts and holds the new data. */
static void ring_outage_then_resume(void **state)
{
    (void)state;
    amfi_ring *r = amfi_ring_create(RATE, 5.0);
    double x[100], out[100];
    block(x, 100, 2.0);
    for (int k = 0; k < 10; k++)
        amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL);
    const int64_t T1 = T0 + 7200000000LL;
    for (int k = 0; k < AMFI_RING_CONFIRM - 1; k++) {
        assert_int_equal(amfi_ring_put(r, T1 + k * 100000LL, RATE, 100, x, NULL),
                         AMFI_RING_QUARANTINE);
        assert_int_equal(amfi_ring_jump_pending(r), 1);
    }
    assert_int_equal(amfi_ring_put(r, T1 + (AMFI_RING_CONFIRM - 1) * 100000LL, RATE, 100, x, NULL),
                     AMFI_RING_RESTART);
    const amfi_ring_stats *st = amfi_ring_stats_of(r);
    assert_int_equal(st->restarts, 1);
    assert_int_equal(st->restart_utime, T1 + (AMFI_RING_CONFIRM - 1) * 100000LL);
    assert_true(fabs(st->last_jump_s - (7200.0 + 0.1 * (AMFI_RING_CONFIRM - 1) - 1.0)) < 1e-6);
    /* the stream goes on after the restart */
    assert_int_equal(amfi_ring_put(r, T1 + AMFI_RING_CONFIRM * 100000LL, RATE, 100, x, NULL),
                     AMFI_RING_OK);
    int64_t k = amfi_ring_index(r, T1 + AMFI_RING_CONFIRM * 100000LL);
    assert_int_equal(amfi_ring_get(r, k, 100, out), 0);
    assert_true(out[0] == 2.0);
    amfi_ring_destroy(r);
}

/* A poisoned first block (an hour ahead of the real stream): the real blocks
 * confirm the jump back, and a vehicle of the real stream is weighed, not
 * stored late (issue 9). While the jump is under test, the tracker waits. */
static void tracker_after_poisoned_first_block(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 0.0, 0, 0.0, 0.0}; /* events off */
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = amfi_ring_create(RATE, 60.0);
    amfi_ring *rings[1] = {r};
    double x[100];
    block(x, 100, 0.5);
    assert_int_equal(amfi_ring_put(r, T0 + 3600000000LL, RATE, 100, x, NULL), AMFI_RING_OK);
    amfi_vehicle_ev a = vehicle(1, 0.5);
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), 0);
    amfi_window w;
    assert_int_equal(amfi_ring_put(r, T0, RATE, 100, x, NULL), AMFI_RING_QUARANTINE);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 0); /* waits: a jump under test */
    for (int k = 1; k < 30; k++)
        assert_true(amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL) >= 0);
    assert_int_equal(amfi_ring_stats_of(r)->restarts, 1);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    /* its window begins 0.15 s after T0: the restart at T0 + 0.2 s leaves a
     * gap at its start, stored as such with the reason */
    assert_string_equal(w.status, "gap");
    assert_non_null(strstr(w.reason, "stream jumped"));
    /* a vehicle after the restart is ok */
    amfi_vehicle_ev b = vehicle(2, 1.8);
    assert_int_equal(amfi_tracker_add(t, &b, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    amfi_ring_destroy(r);
    amfi_tracker_destroy(t);
}

static void tracker_windows(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 0.0, 0, 0.0, 0.0}; /* events off */
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(3.0); /* samples 0 .. 2999 */
    amfi_ring *rings[1] = {r};
    amfi_window w;
    /* two vehicles far apart, added out of order: released by entry time */
    amfi_vehicle_ev b = vehicle(2, 1.9), a = vehicle(1, 0.5);
    assert_int_equal(amfi_tracker_add(t, &b, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), -1); /* duplicate id */
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.seq, 1);
    /* window: entry 0.5 s − 0.35 s .. entry + 1.0 s + 0.05 s */
    assert_int_equal(w.k0[0], 150);
    assert_int_equal(w.n, 1401);
    assert_true(fabs(w.t_first_s + 0.35) < 1e-9);
    /* vehicle 2's window ends at 1.9 + 1.05 = 2.95 s: held */
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 2);
    assert_string_equal(w.status, "ok");
    /* a third, whose data has not all arrived: waits */
    amfi_vehicle_ev c = vehicle(3, 2.5);
    assert_int_equal(amfi_tracker_add(t, &c, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 0);
    /* on shutdown it is released as a gap */
    assert_int_equal(amfi_tracker_next(t, rings, 1, &w), 1);
    assert_string_equal(w.status, "gap");
    assert_int_equal(amfi_tracker_pending(t), 0);
    amfi_ring_destroy(r);
    amfi_tracker_destroy(t);
}

/* slow_frac (room for the speed search): the window ends where it would
 * for the speed·(1 − slow_frac); co-presence still goes by the measured
 * speed. 25 m/s, 25 m of span and axles: 1.0 s on the span at 25, 1.25 s
 * at 20 (slow_frac 0.2). */
static void tracker_slow_frac(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 0.0, 0, 0.2, 0.0}; /* events off */
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(4.0);
    amfi_ring *rings[1] = {r};
    amfi_window w;
    /* b enters 1.1 s after a: a has left at its measured speed (1.0 s), not
     * at 20 m/s (1.25 s); both ok, not multiple */
    amfi_vehicle_ev a = vehicle(1, 0.5), b = vehicle(2, 1.6);
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &b, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 1);
    assert_string_equal(w.status, "ok");
    /* window: entry 0.5 − 0.35 .. entry + 1.25 + 0.05 s */
    assert_int_equal(w.k0[0], 150);
    assert_int_equal(w.n, 1651);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 2);
    assert_string_equal(w.status, "ok");
    amfi_ring_destroy(r);
    amfi_tracker_destroy(t);
    /* out of range */
    amfi_tracker_params bad = p;
    bad.slow_frac = 0.6;
    assert_null(amfi_tracker_create(&bad));
    bad.slow_frac = -0.1;
    assert_null(amfi_tracker_create(&bad));
}

/* Free vibration (free_s, the natural frequency): an ok window waits for
 * free_s of data after its last exit and carries those samples; the next
 * vehicle's entry cuts them; a flush releases the passage without them.
 * 25 m/s, 25 m of span and axles: 1.0 s on the span. */
static void tracker_free_vibration(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 0.0, 0, 0.0, 2.0}; /* events off */
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(3.0); /* samples 0 .. 2999 */
    amfi_ring *rings[1] = {r};
    amfi_window w;
    amfi_vehicle_ev a = vehicle(1, 0.5), b = vehicle(2, 5.0), c = vehicle(3, 6.6);
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), 0);
    /* a's solve window (to 1.55 s) is in, its free vibration (1.5 .. 3.5 s)
     * not: held */
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 0);
    double x[100];
    block(x, 100, 0);
    for (int k = 30; k < 70; k++) /* to 7 s */
        amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL);
    assert_int_equal(amfi_tracker_add(t, &b, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &c, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.k0[0], 150); /* the solve window as without */
    assert_int_equal(w.n, 1401);
    assert_int_equal(w.free_k0[0], 1500);
    assert_int_equal(w.free_n, 2001);
    assert_string_equal(w.free_why, "");
    /* b leaves at 6.0 s, c enters at 6.6 s: cut there */
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 2);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.free_k0[0], 6000);
    assert_int_equal(w.free_n, 601);
    assert_string_equal(w.free_why, "cut at the next vehicle's entry");
    /* c's solve window ends at 7.65 s: waits; a flush releases it (gap) */
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 0);
    for (int k = 70; k < 80; k++) /* to 8 s: c's data in, its free vibration not */
        amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 1, &w), 1);
    assert_int_equal(w.v.vehicle_id, 3);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.free_n, 0);
    assert_string_equal(w.free_why, "the free vibration's data did not all arrive");
    amfi_ring_destroy(r);
    amfi_tracker_destroy(t);
    amfi_tracker_params bad = p;
    bad.free_s = -1;
    assert_null(amfi_tracker_create(&bad));
}

static void tracker_multiple_and_late(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 0.0, 0, 0.0, 0.0}; /* events off */
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(4.0);
    amfi_ring *rings[1] = {r};
    amfi_window w;
    /* two vehicles 0.4 s apart: both on the span at once */
    amfi_vehicle_ev a = vehicle(1, 1.0), b = vehicle(2, 1.4);
    amfi_tracker_add(t, &a, NULL, NULL);
    amfi_tracker_add(t, &b, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "multiple");
    assert_non_null(strstr(w.reason, "vehicle 2"));
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "multiple"); /* against the released vehicle 1 */
    amfi_tracker_destroy(t);
    /* a vehicle event whose data has left a short ring */
    amfi_ring *s = amfi_ring_create(RATE, 5.0);
    double x[100];
    block(x, 100, 0);
    for (int k = 0; k < 100; k++)
        amfi_ring_put(s, T0 + k * 100000LL, RATE, 100, x, NULL);
    amfi_ring *srings[1] = {s};
    t = amfi_tracker_create(&p);
    amfi_vehicle_ev old = vehicle(9, 1.0);
    amfi_tracker_add(t, &old, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, srings, 0, &w), 1);
    assert_string_equal(w.status, "late");
    /* data arriving block by block, the tracker asked after each (as the
     * daemon does): released as soon as its window is covered */
    amfi_vehicle_ev next = vehicle(10, 9.0); /* window to 10.05 s */
    amfi_tracker_add(t, &next, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, srings, 0, &w), 0);
    int released_at = -1;
    for (int k = 100; k < 120 && released_at < 0; k++) {
        amfi_ring_put(s, T0 + k * 100000LL, RATE, 100, x, NULL);
        if (amfi_tracker_next(t, srings, 0, &w) == 1)
            released_at = k;
    }
    assert_int_equal(released_at, 100); /* the block 10.0 .. 10.099 s */
    assert_string_equal(w.status, "ok");
    amfi_tracker_destroy(t);
    /* two sensors, the second falls silent: given up max_wait (5 s) after
     * the window's end, as a gap */
    amfi_tracker_params p2 = {20.0, 0.35, 0.05, 5.0, 2, 0.0, 0, 0.0, 0.0};
    t = amfi_tracker_create(&p2);
    amfi_ring *a1 = amfi_ring_create(RATE, 60.0), *a2 = amfi_ring_create(RATE, 60.0);
    amfi_ring *two[2] = {a1, a2};
    for (int k = 0; k < 20; k++) { /* 2 s on both */
        amfi_ring_put(a1, T0 + k * 100000LL, RATE, 100, x, NULL);
        amfi_ring_put(a2, T0 + k * 100000LL, RATE, 100, x, NULL);
    }
    amfi_vehicle_ev v2 = vehicle(11, 1.5); /* window to 2.55 s */
    amfi_tracker_add(t, &v2, NULL, NULL);
    int k = 20;
    for (; k < 120; k++) {
        amfi_ring_put(a1, T0 + k * 100000LL, RATE, 100, x, NULL);
        if (amfi_tracker_next(t, two, 0, &w) == 1)
            break;
    }
    assert_string_equal(w.status, "gap");
    assert_int_equal(k, 75); /* block 75 ends at 7.599 s > 2.55 + 5 s */
    amfi_ring_destroy(a1);
    amfi_ring_destroy(a2);
    amfi_ring_destroy(s);
    amfi_ring_destroy(r);
    amfi_tracker_destroy(t);
}

static amfi_vehicle_ev vehicle_in(int64_t id, double entry_s, int lane, double speed_mps,
                                   int n_axles)
{
    amfi_vehicle_ev v = vehicle(id, entry_s);
    v.lane = lane;
    v.speed_mps = speed_mps;
    v.n_axles = n_axles;
    for (int a = 0; a + 1 < n_axles; a++)
        v.spacing_m[a] = 4.0;
    return v;
}

static amfi_window last_window; /* pair_released_as's window */

/* Add two vehicles; the next window is one event of n with this status
 * (and a reason holding `why`, unless NULL); it is left in last_window. */
static void pair_released_as(amfi_tracker *t, amfi_ring **rings, amfi_vehicle_ev a,
                             amfi_vehicle_ev b, const char *status, int n, const char *why)
{
    amfi_window w;
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &b, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, status);
    assert_int_equal(w.n_vehicles, n);
    assert_int_equal(w.ev[0].vehicle_id, a.vehicle_id);
    if (why)
        assert_non_null(strstr(w.reason, why));
    last_window = w;
}

/* Vehicles whose times on the span overlap form one event: a chain of three
 * (the first and the last never meet), one window from the first's start to
 * the last's end; two lanes at the same time; a vehicle alone stays alone;
 * one of a lane overtaking another on the span is a contradiction. */
static void tracker_events_chain_and_lanes(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 0, 0.0, 0.0};
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(14.0);
    amfi_ring *rings[1] = {r};
    amfi_window w;
    /* each on the span 1.0 s (25 m + 5 m at 25 m/s) */
    amfi_vehicle_ev a = vehicle(1, 1.0), b = vehicle(2, 1.8), c = vehicle(3, 2.6),
                    d = vehicle(4, 5.0);
    assert_int_equal(amfi_tracker_add(t, &c, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &d, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &a, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_add(t, &b, NULL, NULL), 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.n_vehicles, 3);
    assert_int_equal(w.v.vehicle_id, 1);
    assert_int_equal(w.ev[0].vehicle_id, 1);
    assert_int_equal(w.ev[1].vehicle_id, 2);
    assert_int_equal(w.ev[2].vehicle_id, 3);
    assert_int_equal(w.seq, 1);
    /* 1.0 − 0.35 s .. 2.6 + 1.0 + 0.05 s */
    assert_int_equal(w.k0[0], 650);
    assert_int_equal(w.n, 3001);
    assert_true(fabs(w.t_first_s + 0.35) < 1e-9);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.n_vehicles, 1);
    assert_int_equal(w.v.vehicle_id, 4);
    assert_int_equal(w.seq, 2);
    /* two lanes, side by side: one event */
    amfi_vehicle_ev e = vehicle_in(5, 7.0, 1, 25.0, 2), f = vehicle_in(6, 7.0, 2, 20.0, 3);
    amfi_tracker_add(t, &e, NULL, NULL);
    amfi_tracker_add(t, &f, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.n_vehicles, 2);
    assert_int_equal(w.ev[1].lane, 2);
    /* ends with f: 7.0 + (20 + 8) / 20 + 0.05 s */
    assert_int_equal(w.n, (int)lround((1.4 + 0.05 + 0.35) * RATE) + 1);
    /* lane 1: vehicle 8 enters 0.3 s after 7 at twice its speed and would
     * pass it on the span: both stored invalid with the reason, at once */
    pair_released_as(t, rings, vehicle_in(7, 9.0, 1, 20.0, 2), vehicle_in(8, 9.3, 1, 40.0, 2),
                     "invalid", 2, "8 would overtake 7");
    /* the same pair on two lanes is fine */
    pair_released_as(t, rings, vehicle_in(9, 11.0, 1, 20.0, 2),
                     vehicle_in(10, 11.3, 2, 40.0, 2), "ok", 2, NULL);
    assert_int_equal(amfi_tracker_pending(t), 0);
    amfi_ring_destroy(r);
    amfi_tracker_destroy(t);
}

/* The limits: an event too long, with too many axles or vehicles, is
 * released at once (its data not waited for) as multiple with the reason;
 * a vehicle that overlaps one already released is multiple too. */
static void tracker_event_limits(void **state)
{
    (void)state;
    amfi_tracker_params bad = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 1, 0.0, 0.0};
    assert_null(amfi_tracker_create(&bad));
    bad.max_event_axles = AMFI_MAX_EVENT_AXLES + 1;
    assert_null(amfi_tracker_create(&bad));
    bad.max_event_axles = 0;
    bad.max_event_s = -1.0;
    assert_null(amfi_tracker_create(&bad));

    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 2.0, 0, 0.0, 0.0};
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(0.5); /* no data for any of them yet */
    amfi_ring *rings[1] = {r};
    amfi_window w;
    amfi_vehicle_ev v1 = vehicle(1, 1.0), v2 = vehicle(2, 1.8);
    amfi_tracker_add(t, &v1, NULL, NULL);
    amfi_tracker_add(t, &v2, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 0); /* 1.8 s: waits for data */
    amfi_vehicle_ev v3 = vehicle(3, 2.6), v4 = vehicle(4, 3.4);
    amfi_tracker_add(t, &v3, NULL, NULL);
    amfi_tracker_add(t, &v4, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1); /* 2.6 s > 2 s: at once */
    assert_string_equal(w.status, "multiple");
    assert_int_equal(w.n_vehicles, 3);
    assert_non_null(strstr(w.reason, "longer than daemon.max_event_s (2.00 s)"));
    /* vehicle 4 met vehicle 3, released: multiple once its data is in */
    for (int k = 5; k < 60; k++) {
        double x[100];
        block(x, 100, 0);
        amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL);
    }
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "multiple");
    assert_int_equal(w.n_vehicles, 1);
    assert_int_equal(w.v.vehicle_id, 4);
    assert_non_null(strstr(w.reason, "vehicle 3 on the span at the same time, already stored"));
    amfi_tracker_destroy(t);

    /* axles: two three-axle vehicles, at most 5 */
    amfi_tracker_params pa = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 5, 0.0, 0.0};
    t = amfi_tracker_create(&pa);
    pair_released_as(t, rings, vehicle_in(11, 1.0, 1, 25.0, 3), vehicle_in(12, 1.2, 2, 25.0, 3),
                     "multiple", 2, "6 axles in all: more than daemon.max_event_axles (5)");
    amfi_tracker_destroy(t);

    /* over the limit by windows, within it by times on the span: cut down.
     * 2 (on the span 2.2 .. 3.2 s) is in 1's post-roll (1.0 .. 2.0 .. 2.05 s)
     * and on the span with 3: six axles by windows, at most 4: 1 alone,
     * then 2 and 3 together */
    amfi_tracker_params p4 = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 4, 0.0, 0.0};
    t = amfi_tracker_create(&p4);
    amfi_vehicle_ev c1 = vehicle(31, 1.0), c2 = vehicle(32, 2.2), c3 = vehicle(33, 2.5);
    amfi_tracker_add(t, &c1, NULL, NULL);
    amfi_tracker_add(t, &c2, NULL, NULL);
    amfi_tracker_add(t, &c3, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.n_vehicles, 1);
    assert_int_equal(w.v.vehicle_id, 31);
    assert_string_equal(w.reason, "");
    /* issue 13, inseparable: 32 is on the span after 31's window (0.65 ..
     * 2.05 s), but 31 (on the span 1.0 .. 2.0 s) is in 32's pre-roll (1.85
     * .. 2.2 s), a force outside 32's solve; 33's window starts (2.15 s)
     * after 31 left */
    assert_int_equal(w.outside[0], 0);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.n_vehicles, 2);
    assert_int_equal(w.ev[0].vehicle_id, 32);
    assert_int_equal(w.ev[1].vehicle_id, 33);
    assert_int_equal(w.outside[0], 1);
    assert_int_equal(w.outside_id[0], 31);
    assert_int_equal(w.outside[1], 0);
    amfi_tracker_destroy(t);

    /* vehicles: AMFI_MAX_VEHICLES + 1 one-axle vehicles 0.05 s apart,
     * AMFI_MAX_VEHICLES at most together */
    amfi_tracker_params pv = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 0, 0.0, 0.0};
    t = amfi_tracker_create(&pv);
    for (int i = 0; i < AMFI_MAX_VEHICLES + 1; i++) {
        amfi_vehicle_ev v = vehicle_in(20 + i, 1.0 + 0.05 * i, 1, 25.0, 1);
        assert_int_equal(amfi_tracker_add(t, &v, NULL, NULL), 0);
    }
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "multiple");
    assert_int_equal(w.n_vehicles, AMFI_MAX_VEHICLES);
    char joins[64];
    snprintf(joins, sizeof joins, "vehicle %d joins an event of %d", 20 + AMFI_MAX_VEHICLES,
             AMFI_MAX_VEHICLES);
    assert_non_null(strstr(w.reason, joins));
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_int_equal(w.v.vehicle_id, 20 + AMFI_MAX_VEHICLES);
    assert_string_equal(w.status, "multiple");
    assert_int_equal(amfi_tracker_pending(t), 0);
    amfi_tracker_destroy(t);
    amfi_ring_destroy(r);
}

/* Vehicles that cannot be separated (issue 13): side by side on two lanes
 * their axles are at one point for the whole crossing; on two lanes at
 * different speeds only while they pass each other (the shares worked out
 * by hand); a chain of three on one lane never comes within 15 m (the
 * vehicle outside a cut event: tracker_event_limits). */
static void tracker_inseparable(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 0, 0.0, 0.0};
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = filled(14.0);
    amfi_ring *rings[1] = {r};
    amfi_window w;
    amfi_nearness nr;
    /* side by side, same speed and spacing */
    pair_released_as(t, rings, vehicle_in(41, 1.0, 1, 25.0, 2), vehicle_in(42, 1.0, 2, 25.0, 2),
                     "ok", 2, NULL);
    w = last_window;
    for (int i = 0; i < 2; i++) {
        amfi_window_nearness(&w, 20.0, 1.0, i, &nr);
        assert_int_equal(nr.other, 1 - i);
        assert_true(nr.share > 0.99);
        assert_true(nr.min_gap_m < 1e-9);
        assert_int_equal(w.outside[i], 0);
    }
    /* 25 and 20 m/s, entering together, axles 4 m apart: within 1 m while
     * the fronts are (0 .. 0.2 s) and A's rear passes B's front (0.6 ..
     * 0.96 s, when A's rear leaves): 0.56 s of A's 0.96 s, of B's 1.2 s */
    pair_released_as(t, rings, vehicle_in(43, 3.0, 1, 25.0, 2), vehicle_in(44, 3.0, 2, 20.0, 2),
                     "ok", 2, NULL);
    w = last_window;
    amfi_window_nearness(&w, 20.0, 1.0, 0, &nr);
    assert_int_equal(nr.other, 1);
    assert_true(fabs(nr.share - 0.56 / 0.96) < 0.005);
    assert_true(nr.min_gap_m < 0.01);
    amfi_window_nearness(&w, 20.0, 1.0, 1, &nr);
    assert_int_equal(nr.other, 0);
    assert_true(fabs(nr.share - 0.56 / 1.2) < 0.005);
    amfi_window_nearness(&w, 20.0, 0.0, 1, &nr); /* gap 0: never near */
    assert_true(nr.share == 0.0);
    amfi_window_nearness(&w, 20.0, 1.0, 2, &nr); /* no such vehicle */
    assert_int_equal(nr.other, -1);
    /* a chain of three on one lane, 0.8 s apart at 25 m/s, 5 m spacing:
     * the leader's rear axle 15 m ahead of the follower's front */
    amfi_vehicle_ev a = vehicle(45, 6.0), b = vehicle(46, 6.8), c = vehicle(47, 7.6);
    amfi_tracker_add(t, &a, NULL, NULL);
    amfi_tracker_add(t, &b, NULL, NULL);
    amfi_tracker_add(t, &c, NULL, NULL);
    assert_int_equal(amfi_tracker_next(t, rings, 0, &w), 1);
    assert_string_equal(w.status, "ok");
    assert_int_equal(w.n_vehicles, 3);
    for (int i = 0; i < 3; i++) {
        amfi_window_nearness(&w, 20.0, 1.0, i, &nr);
        assert_true(nr.share == 0.0);
        assert_true(fabs(nr.min_gap_m - 15.0) < 0.03);
        assert_int_equal(w.outside[i], 0);
    }
    amfi_tracker_destroy(t);
    amfi_ring_destroy(r);
}

/* The rate is the sensor's declared one: a block at another rate is
 * refused and leaves the ring as it was (not started, no origin), so the
 * real stream that follows is stored (one 999 Hz block once fixed a
 * sensor's rate until restart). */
static void ring_rate_is_declared(void **state)
{
    (void)state;
    amfi_ring *r = amfi_ring_create(RATE, 60.0);
    double x[137];
    block(x, 137, 0.5);
    const char *why = NULL;
    assert_int_equal(amfi_ring_put(r, T0 - 1000000, 999.0, 137, x, &why), AMFI_RING_REJECT);
    assert_non_null(strstr(why, "rate"));
    assert_int_equal(amfi_ring_started(r), 0);
    for (int k = 0; k < 10; k++)
        assert_int_equal(amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_int_equal(amfi_ring_newest(r), 999);
    assert_true(amfi_ring_utime(r, 0) == (double)T0);
    double out[1000];
    assert_int_equal(amfi_ring_get(r, 0, 1000, out), 0);
    assert_int_equal(amfi_ring_stats_of(r)->rejected, 1);
    amfi_ring_destroy(r);
}

/* Memory follows the data: an hour's ring at 100 kHz costs (almost) nothing
 * before data come, a few chunks after the first seconds, and no more than
 * its window however long the stream runs; a gap frees what left the window. */
static void ring_memory_as_data_arrive(void **state)
{
    (void)state;
    const double rate = 100000.0;
    amfi_ring *r = amfi_ring_create(rate, 3600.0);
    assert_non_null(r);
    assert_true(amfi_ring_bytes(r) < 2 << 20); /* 2.9 GB when NaN-filled at creation */
    static double x[4000];
    block(x, 4000, 0.25);
    for (int k = 0; k < 250; k++) /* 10 s */
        assert_int_equal(amfi_ring_put(r, T0 + k * 40000LL, rate, 4000, x, NULL), AMFI_RING_OK);
    const int64_t ten_s = amfi_ring_bytes(r);
    assert_true(ten_s > 8 * 1000000);  /* the samples are held: 8 MB */
    assert_true(ten_s < 10 * 1000000); /* and not much more */
    double out[4000];
    assert_int_equal(amfi_ring_get(r, 996000, 4000, out), 0);
    assert_true(out[3999] == x[3999]);
    /* a small ring wraps many times: its memory stays at its window */
    amfi_ring *s = amfi_ring_create(RATE, 10.0);
    for (int k = 0; k < 1000; k++) /* 100 s into a 10 s ring */
        assert_int_equal(amfi_ring_put(s, T0 + k * 100000LL, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_true(amfi_ring_bytes(s) <= (10000 / 4096 + 2) * 4096 * 8 + 4096);
    assert_int_equal(amfi_ring_get(s, 99900, 100, out), 0);
    assert_int_equal(amfi_ring_get(s, 90000, 10, out), 0);
    assert_int_equal(amfi_ring_get(s, 80000, 10, out), -1); /* left the window */
    /* 300 s of silence, then one block: everything before left the window,
     * its chunks are freed; the hole reads as missing */
    assert_int_equal(amfi_ring_put(s, T0 + 400000000LL, RATE, 100, x, NULL), AMFI_RING_OK);
    assert_true(amfi_ring_bytes(s) <= 2 * 4096 * 8 + 4096);
    assert_int_equal(amfi_ring_get(s, amfi_ring_newest(s) - 199, 100, out), 100);
    amfi_ring_destroy(s);
    amfi_ring_destroy(r);
}

/* A full tracker evicts the vehicle that has waited longest instead of
 * refusing every new one: 256 vehicles that never get data (forged, dated
 * in 2286) once made every real vehicle invalid. */
static void tracker_full_evicts_stalest(void **state)
{
    (void)state;
    amfi_tracker_params p = {20.0, 0.35, 0.05, 5.0, 1, 10.0, 0, 0.0, 0.0};
    amfi_tracker *t = amfi_tracker_create(&p);
    amfi_ring *r = amfi_ring_create(RATE, 60.0);
    amfi_ring *rings[1] = {r};
    for (int i = 0; i < AMFI_TRACKER_MAX_PENDING; i++) {
        amfi_vehicle_ev f = vehicle(900000 + i, 1e10 + i); /* year 2286 */
        assert_int_equal(amfi_tracker_add(t, &f, NULL, NULL), 0);
    }
    double x[100];
    block(x, 100, 0.5);
    int ok = 0, evicted = 0;
    amfi_window w;
    for (int v = 0; v < 20; v++) {
        amfi_vehicle_ev a = vehicle(1 + v, 1.0 + 3.0 * v), ev;
        const char *why = NULL;
        memset(&ev, 0, sizeof ev);
        /* full: the one queued first goes (stored by amfid, with the reason) */
        const int full = amfi_tracker_pending(t) == AMFI_TRACKER_MAX_PENDING;
        assert_int_equal(amfi_tracker_add(t, &a, &ev, &why), full);
        if (full) {
            assert_int_equal(ev.vehicle_id, 900000 + evicted++);
            assert_non_null(strstr(why, "evicted"));
        }
        /* another vehicle that never gets data fills it again */
        amfi_vehicle_ev f = vehicle(910000 + v, 2e10 + v);
        const int rc = amfi_tracker_add(t, &f, &ev, NULL);
        assert_true(rc >= 0);
        if (rc == 1)
            assert_int_equal(ev.vehicle_id, 900000 + evicted++);
        for (int k = 30 * v; k < 30 * (v + 1) + 20; k++)
            if (amfi_ring_newest(r) < (int64_t)(k + 1) * 100 - 1)
                assert_true(amfi_ring_put(r, T0 + k * 100000LL, RATE, 100, x, NULL) >= 0);
        while (amfi_tracker_next(t, rings, 0, &w) == 1)
            ok += strcmp(w.status, "ok") == 0 && w.v.vehicle_id == 1 + v;
    }
    assert_int_equal(ok, 20);
    assert_true(evicted >= 20);
    /* a duplicate id is still refused, and evicts nothing */
    amfi_vehicle_ev dup = vehicle(900100, 1e10 + 100);
    assert_int_equal(amfi_tracker_add(t, &dup, NULL, NULL), -1);
    amfi_tracker_destroy(t);
    amfi_ring_destroy(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ring_in_order_and_gaps),
        cmocka_unit_test(ring_rejects_and_late),
        cmocka_unit_test(ring_one_wrong_time_is_ignored),
        cmocka_unit_test(ring_outage_then_resume),
        cmocka_unit_test(tracker_after_poisoned_first_block),
        cmocka_unit_test(tracker_windows),
        cmocka_unit_test(tracker_multiple_and_late),
        cmocka_unit_test(tracker_events_chain_and_lanes),
        cmocka_unit_test(tracker_event_limits),
        cmocka_unit_test(tracker_inseparable),
        cmocka_unit_test(tracker_slow_frac),
        cmocka_unit_test(tracker_free_vibration),
        cmocka_unit_test(ring_rate_is_declared),
        cmocka_unit_test(ring_memory_as_data_arrive),
        cmocka_unit_test(tracker_full_evicts_stalest),
    };
    return cmocka_run_group_tests_name("daemon core", tests, NULL, NULL);
}
