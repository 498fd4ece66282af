/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * tracker.h: cuts the sample stream into vehicle passages.
 *
 * Each vehicle event gives a window, entry − pre .. entry + (L + Σ spacing)/v
 * + post, in data time (message utimes, never the wall clock, so a replay at
 * any speed cuts the same windows). Windows are released in order of entry
 * time once every sensor's ring holds their last sample, or, when a sensor
 * falls silent, once the newest data is max_wait past the window's end. A
 * released window says how it is to be stored: "ok" (to be solved), "gap"
 * (samples missing), "late" (the data left the ring before the vehicle
 * event arrived), "multiple" (vehicles on the span together that cannot be
 * weighed together) or "invalid" (their events contradict each other).
 *
 * Events (issue 13): vehicles whose windows overlap (one on the span in the
 * other's pre- or post-roll is a force the other's solve would not know), on
 * any lane (the beam has no width), form one event, released as one window
 * from the first entry's window start to the last exit's window end, to be
 * solved jointly (amfi_solve_multi); a chain A-B-C, where A and C never
 * meet, is one event. An event longer than max_event_s (first entry to last
 * exit), with more than max_event_axles axles or AMFI_MAX_VEHICLES vehicles,
 * is cut down to the vehicles whose times on the span overlap; when that
 * still breaks a limit, it is released at once as "multiple" with the reason
 * (no waiting for its data); an event in which a vehicle would overtake another of its lane on
 * the span (its front axle level with or ahead of the leader's) as
 * "invalid".
 * max_event_s = 0 turns events off: every vehicle that shares the span
 * (times on the span overlapping) is "multiple", the behaviour before issue
 * 13. A vehicle whose event arrives after a partner was released is
 * "multiple" too.
 *
 * Not thread-safe: the bus thread owns it. Capacity fixed at creation; of
 * its parameters only max_wait_s changes afterwards (amfi_tracker_set_max_wait).
 */
#ifndef AMFI_TRACKER_H
#define AMFI_TRACKER_H

#include <stdint.h>

#include "amfi/amfi.h"
#include "ring.h"

#define AMFI_TRACKER_MAX_PENDING 256

typedef struct amfi_vehicle_ev {
    int64_t vehicle_id;
    int64_t utime;       /* first axle at the bridge entry, µs */
    int lane;
    double speed_mps;    /* m/s; utime, speed and spacings as detector.* corrects them */
    double speed_given_mps; /* the detector's speed as it reported it (stored) */
    int n_axles;
    double spacing_m[AMFI_MAX_AXLES]; /* n_axles − 1 */
    double reference_gvw_kg; /* a calibration truck's pre-weighed GVW, kg; 0: none */
    int64_t arrival;     /* set by amfi_tracker_add: the order vehicles were queued in */
} amfi_vehicle_ev;

typedef struct amfi_tracker_params {
    double span_m;
    double pre_s;        /* window before entry (solver pre-roll + margin) */
    double post_s;       /* window after the last exit (solver post-roll + margin) */
    double max_wait_s;   /* data time past a window's end before it is given up */
    int n_sensors;
    double max_event_s;  /* first entry to last exit of an event, s; 0: no events */
    int max_event_axles; /* axles of an event, 2 .. AMFI_MAX_EVENT_AXLES (0: that) */
    double slow_frac;    /* the window ends where it would for speed·(1 − slow_frac):
                            room for the speed search's slowest trial (0 .. 0.5) */
    double free_s;       /* free vibration wanted after the event's last exit (at the
                            measured speed), s, >= 0; 0: none (the natural frequency) */
} amfi_tracker_params;

typedef struct amfi_window {
    amfi_vehicle_ev v;    /* the first vehicle of the event (ev[0]) */
    int n_vehicles;       /* vehicles in the event, 1 .. AMFI_MAX_VEHICLES */
    amfi_vehicle_ev ev[AMFI_MAX_VEHICLES]; /* by entry time */
    int64_t seq;          /* release order, from 1 */
    int64_t k0[AMFI_MAX_SENSORS]; /* first sample index per sensor */
    int n;                /* samples per sensor */
    double t_first_s;     /* time of the first sample relative to v's entry, sensor 0 */
    const char *status;   /* "ok", "gap", "late", "multiple", "invalid" */
    char reason[200];
    /* free vibration (free_s > 0, status ok): samples from the event's last
     * exit to free_s later or to the next vehicle's entry, whichever is
     * first; free_n 0 when there is none (then free_why says why) */
    int64_t free_k0[AMFI_MAX_SENSORS]; /* first free-vibration sample per sensor */
    int free_n;           /* samples per sensor */
    const char *free_why; /* "" or why there is none or it is cut short (static) */
    /* per vehicle of an "ok" window (events on): 1 when a vehicle not weighed
     * with it (outside_id) is on the span inside its window, a force its
     * solve does not know (the event was cut down at a limit); else 0 */
    int outside[AMFI_MAX_VEHICLES];
    int64_t outside_id[AMFI_MAX_VEHICLES];
} amfi_window;

/* How close vehicle i of an event came to the others, axle by axle, while
 * on the span (amfi_window_nearness). */
typedef struct amfi_nearness {
    int other;        /* index in ev[] of the vehicle with the largest share; −1 none */
    double share;     /* of i's time on the span (first axle on to last off), 0 .. 1,
                         during which one of its axles on the span is within gap_m of
                         one of `other`'s on the span */
    double min_gap_m; /* the least distance between an axle of i and one of another
                         vehicle of the event, both on the span, m; INFINITY: never */
} amfi_nearness;

typedef struct amfi_tracker amfi_tracker;

amfi_tracker *amfi_tracker_create(const amfi_tracker_params *p);
void amfi_tracker_destroy(amfi_tracker *t);

/* Queue a validated vehicle event. Returns 0; 1 when the queue was full
 * (AMFI_TRACKER_MAX_PENDING vehicles waiting for their data): the stalest
 * one, queued first of those waiting, was evicted into *evicted (to be
 * stored with the reason, never lost) and v queued in its place; or −1
 * when the id is already pending (then `why` says so). Bounded either way:
 * vehicles that never get data (a detector ahead of a dead DAQ, forged
 * events dated in the future) cannot lock out the ones that do. */
int amfi_tracker_add(amfi_tracker *t, const amfi_vehicle_ev *v, amfi_vehicle_ev *evicted,
                     const char **why);

/* Take out the pending vehicle dated latest if its utime is after `limit`
 * (µs): 1 with it in *out, else 0 (the data time caught up with a queue
 * that vehicles dated far ahead had entered before any data). */
int amfi_tracker_take_after(amfi_tracker *t, int64_t limit, amfi_vehicle_ev *out);

/* Release the next window (one vehicle, or an event of several) if it is
 * decided (1), or none (0). rings: one per
 * sensor (NULL while a sensor has sent nothing). `flush` releases every
 * pending window now, as "gap" when its data is incomplete (shutdown). */
int amfi_tracker_next(amfi_tracker *t, amfi_ring *const *rings, int flush, amfi_window *out);

int amfi_tracker_pending(const amfi_tracker *t);

/* A reload's max_wait_s (daemon.max_wait_s, applies at once): the windows
 * still pending and every later one wait this long. 0, or −1 when it is
 * not > 0 (the tracker keeps its wait). The tracker reads its own copy of
 * the parameters: without this call a reload never reached it. */
int amfi_tracker_set_max_wait(amfi_tracker *t, double max_wait_s);

/* Vehicle i of window w against the event's other vehicles: axles of two
 * vehicles within gap_m of each other load the beam at one point, which no
 * sensor separates (only their sum): the share of i's crossing that lasts,
 * for the worst other vehicle. Geometry only (the detector's entry times,
 * speeds and spacings), sampled every millisecond. Pure; any thread. */
void amfi_window_nearness(const amfi_window *w, double span_m, double gap_m, int i,
                          amfi_nearness *out);

#endif
