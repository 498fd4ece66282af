/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * tracker.c: passage windows from vehicle events and sample rings: one
 * vehicle alone, or an event of the vehicles that share the span (tracker.h).
 * Thread: the bus (main) thread, which owns the tracker.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tracker.h"

#define RECENT 64
#define AMFI_STR_(x) #x
#define AMFI_STR(x) AMFI_STR_(x)

typedef struct span {
    int64_t id;
    double t_in, t_out; /* µs: first axle on, last axle off */
} span;

struct amfi_tracker {
    amfi_tracker_params p;
    amfi_vehicle_ev pend[AMFI_TRACKER_MAX_PENDING]; /* sorted by utime */
    int n_pend;
    span recent[RECENT]; /* released vehicles, for multiple presence */
    int n_recent, recent_head;
    int64_t seq;
    int64_t arrivals;    /* vehicles queued so far */
};

amfi_tracker *amfi_tracker_create(const amfi_tracker_params *p)
{
    if (!(p->span_m > 0) || !(p->pre_s >= 0) || !(p->post_s >= 0) || !(p->max_wait_s > 0) ||
        p->n_sensors < 1 || p->n_sensors > AMFI_MAX_SENSORS || !(p->max_event_s >= 0) ||
        p->max_event_axles < 0 || p->max_event_axles == 1 ||
        p->max_event_axles > AMFI_MAX_EVENT_AXLES || !(p->slow_frac >= 0) || !(p->slow_frac <= 0.5) ||
        !(p->free_s >= 0) || !(p->free_s <= 3600))
        return NULL;
    amfi_tracker *t = calloc(1, sizeof *t);
    if (t) {
        t->p = *p;
        if (t->p.max_event_axles == 0)
            t->p.max_event_axles = AMFI_MAX_EVENT_AXLES;
    }
    return t;
}

void amfi_tracker_destroy(amfi_tracker *t) { free(t); }
int amfi_tracker_pending(const amfi_tracker *t) { return t->n_pend; }

int amfi_tracker_set_max_wait(amfi_tracker *t, double max_wait_s)
{
    if (!t || !(max_wait_s > 0))
        return -1;
    t->p.max_wait_s = max_wait_s;
    return 0;
}

/* The vehicle's passage window (libamfi's one definition), seconds from its
 * entry, at its speed·(1 − frac). */
static amfi_passage_times window_at(const amfi_tracker *t, const amfi_vehicle_ev *v,
                                    double frac)
{
    return amfi_passage_window(t->p.span_m, v->speed_mps * (1.0 - frac), v->n_axles,
                               v->spacing_m, t->p.pre_s, t->p.post_s);
}

/* The data a passage needs: the window at the slowest speed the speed
 * search may try (slow_frac; 0 without it). */
static amfi_passage_times window_of(const amfi_tracker *t, const amfi_vehicle_ev *v)
{
    return window_at(t, v, t->p.slow_frac);
}

/* While the vehicle is on the span, at its measured speed. */
static span span_of(const amfi_tracker *t, const amfi_vehicle_ev *v)
{
    amfi_passage_times w = amfi_passage_window(t->p.span_m, v->speed_mps, v->n_axles,
                                               v->spacing_m, 0.0, 0.0);
    span s = {v->vehicle_id, (double)v->utime, (double)v->utime + 1e6 * w.on_span_s};
    return s;
}

/* What makes two vehicles one event: with events, their windows overlap
 * (one on the span inside the other's pre- or post-roll would be a force
 * the other's solve does not know); without, their times on the span
 * (then "multiple", as before events). */
static span reach_of(const amfi_tracker *t, const amfi_vehicle_ev *v)
{
    if (!(t->p.max_event_s > 0))
        return span_of(t, v);
    const amfi_passage_times w = window_at(t, v, 0.0); /* at the measured speed */
    span s = {v->vehicle_id, (double)v->utime + 1e6 * w.start_s,
              (double)v->utime + 1e6 * w.end_s};
    return s;
}

int amfi_tracker_add(amfi_tracker *t, const amfi_vehicle_ev *v, amfi_vehicle_ev *evicted,
                     const char **why)
{
    const char *dummy;
    if (!why)
        why = &dummy;
    *why = "";
    for (int i = 0; i < t->n_pend; i++)
        if (t->pend[i].vehicle_id == v->vehicle_id) {
            *why = "vehicle id already pending";
            return -1;
        }
    int rc = 0;
    if (t->n_pend == AMFI_TRACKER_MAX_PENDING) {
        int stale = 0;
        for (int i = 1; i < t->n_pend; i++)
            if (t->pend[i].arrival < t->pend[stale].arrival)
                stale = i;
        if (evicted)
            *evicted = t->pend[stale];
        memmove(t->pend + stale, t->pend + stale + 1,
                sizeof *t->pend * (size_t)(t->n_pend - stale - 1));
        t->n_pend--;
        *why = "evicted: the tracker was full (" AMFI_STR(AMFI_TRACKER_MAX_PENDING)
               " vehicles waiting for their data) and this one had waited longest";
        rc = 1;
    }
    int i = t->n_pend;
    while (i > 0 && t->pend[i - 1].utime > v->utime) {
        t->pend[i] = t->pend[i - 1];
        i--;
    }
    t->pend[i] = *v;
    t->pend[i].arrival = ++t->arrivals;
    t->n_pend++;
    return rc;
}

int amfi_tracker_take_after(amfi_tracker *t, int64_t limit, amfi_vehicle_ev *out)
{
    if (t->n_pend == 0 || t->pend[t->n_pend - 1].utime <= limit)
        return 0;
    *out = t->pend[--t->n_pend];
    return 1;
}

static int in_event(const amfi_window *w, int64_t id)
{
    for (int i = 0; i < w->n_vehicles; i++)
        if (w->ev[i].vehicle_id == id)
            return 1;
    return 0;
}

/* Another vehicle (pending or recently released), not of the event w, on
 * the span during `me` (µs). */
static int foreign_during(const amfi_tracker *t, span me, const amfi_window *w, int64_t *other)
{
    for (int i = 0; i < t->n_pend; i++) {
        if (in_event(w, t->pend[i].vehicle_id))
            continue;
        span o = span_of(t, &t->pend[i]);
        if (o.t_in < me.t_out && me.t_in < o.t_out) {
            *other = o.id;
            return 1;
        }
    }
    for (int i = 0; i < t->n_recent; i++) {
        const span *o = &t->recent[i];
        if (!in_event(w, o->id) && o->t_in < me.t_out && me.t_in < o->t_out) {
            *other = o->id;
            return 1;
        }
    }
    return 0;
}

/* ... on the span at the same time as v. */
static int overlapping(const amfi_tracker *t, const amfi_vehicle_ev *v, const amfi_window *w,
                       int64_t *other)
{
    return foreign_during(t, span_of(t, v), w, other);
}

/* ... on the span inside v's window (reach_of): a force v's solve does not
 * know. */
static int outside_window(const amfi_tracker *t, const amfi_vehicle_ev *v, const amfi_window *w,
                          int64_t *other)
{
    return foreign_during(t, reach_of(t, v), w, other);
}

/* Front axle position of v at time t_us (µs), m from the entry. */
static double front_m(const amfi_vehicle_ev *v, double t_us)
{
    return v->speed_mps * 1e-6 * (t_us - (double)v->utime);
}

/* Vehicles of one lane in the event overtaking each other on the span (a
 * follower's front axle level with or ahead of its leader's while both are
 * on it): the events contradict each other. 1 with the reason, else 0. */
static int inconsistent(const amfi_tracker *t, const amfi_window *w, char *why, size_t len)
{
    for (int i = 0; i < w->n_vehicles; i++)
        for (int j = i + 1; j < w->n_vehicles; j++) {
            const amfi_vehicle_ev *a = &w->ev[i], *b = &w->ev[j]; /* a entered first */
            if (a->lane != b->lane)
                continue;
            span sa = span_of(t, a), sb = span_of(t, b);
            double lo = fmax(sa.t_in, sb.t_in), hi = fmin(sa.t_out, sb.t_out);
            if (lo >= hi)
                continue;
            /* fronts are linear in time: their gap's worst is at an end;
             * the front leaves the span before the last axle does */
            double hi_front = fmin(hi, fmin((double)a->utime + 1e6 * t->p.span_m / a->speed_mps,
                                            (double)b->utime + 1e6 * t->p.span_m / b->speed_mps));
            double g0 = front_m(a, lo) - front_m(b, lo);
            double g1 = hi_front > lo ? front_m(a, hi_front) - front_m(b, hi_front) : g0;
            if (g0 <= 0 || g1 <= 0) {
                snprintf(why, len,
                         "vehicles %lld and %lld of lane %d contradict each other: %lld would "
                         "overtake %lld on the span (%.2f s apart at %.1f and %.1f m/s)",
                         (long long)a->vehicle_id, (long long)b->vehicle_id, a->lane,
                         (long long)b->vehicle_id, (long long)a->vehicle_id,
                         1e-6 * (double)(b->utime - a->utime), a->speed_mps, b->speed_mps);
                return 1;
            }
        }
    return 0;
}

/* The event that starts with pend[0]: the pending vehicles, by entry, whose
 * window (by_window) or time on the span overlaps the chain's so far. Fills
 * out->ev and out->n_vehicles; returns NULL, or the status of a bad event
 * ("multiple": a limit broken; "invalid": the vehicles contradict each
 * other) with the reason in out->reason. */
static const char *gather(const amfi_tracker *t, amfi_window *out, int by_window)
{
    out->ev[0] = t->pend[0];
    out->n_vehicles = 1;
    out->reason[0] = '\0';
    if (!(t->p.max_event_s > 0))
        return NULL;
    span (*const reach)(const amfi_tracker *, const amfi_vehicle_ev *) =
        by_window ? reach_of : span_of;
    const span first = reach(t, &t->pend[0]);
    double end = first.t_out;                       /* of the windows */
    double exit_us = span_of(t, &t->pend[0]).t_out; /* the last exit */
    int axles = t->pend[0].n_axles;
    for (int i = 1; i < t->n_pend; i++) {
        const amfi_vehicle_ev *v = &t->pend[i];
        const span s = reach(t, v);
        if (s.t_in >= end)
            break;
        if (out->n_vehicles == AMFI_MAX_VEHICLES) {
            snprintf(out->reason, sizeof out->reason,
                     "vehicle %lld joins an event of %d vehicles on the span together: more "
                     "than %d cannot be weighed together",
                     (long long)v->vehicle_id, out->n_vehicles, AMFI_MAX_VEHICLES);
            return "multiple";
        }
        out->ev[out->n_vehicles++] = *v;
        axles += v->n_axles;
        end = fmax(end, s.t_out);
        exit_us = fmax(exit_us, span_of(t, v).t_out);
        if (axles > t->p.max_event_axles) {
            snprintf(out->reason, sizeof out->reason,
                     "%d vehicles on the span together with %d axles in all: more than "
                     "daemon.max_event_axles (%d)",
                     out->n_vehicles, axles, t->p.max_event_axles);
            return "multiple";
        }
        const double on_s = 1e-6 * (exit_us - (double)t->pend[0].utime);
        if (on_s > t->p.max_event_s) {
            snprintf(out->reason, sizeof out->reason,
                     "%d vehicles on the span one after another for %.2f s: longer than "
                     "daemon.max_event_s (%.2f s)",
                     out->n_vehicles, on_s, t->p.max_event_s);
            return "multiple";
        }
    }
    if (out->n_vehicles > 1 && inconsistent(t, out, out->reason, sizeof out->reason))
        return "invalid";
    return NULL;
}

/* Remember the released vehicles' spans and take them off the queue (the
 * event's vehicles are the first n of pend). */
static void release(amfi_tracker *t, amfi_window *out)
{
    out->seq = ++t->seq;
    for (int i = 0; i < out->n_vehicles; i++) {
        t->recent[t->recent_head] = span_of(t, &t->pend[i]);
        t->recent_head = (t->recent_head + 1) % RECENT;
        if (t->n_recent < RECENT)
            t->n_recent++;
    }
    memmove(t->pend, t->pend + out->n_vehicles,
            sizeof *t->pend * (size_t)(t->n_pend - out->n_vehicles));
    t->n_pend -= out->n_vehicles;
}

int amfi_tracker_next(amfi_tracker *t, amfi_ring *const *rings, int flush, amfi_window *out)
{
    if (t->n_pend == 0)
        return 0;
    const amfi_vehicle_ev *v = &t->pend[0];
    const int ns = t->p.n_sensors;
    memset(out, 0, sizeof *out);
    out->v = *v;
    out->status = "ok";
    /* Vehicles whose windows overlap, as one event; when that event breaks
     * a limit, those whose times on the span overlap (a smaller event: one
     * in another's pre- or post-roll only is then a force unknown to its
     * solve, the lesser evil against storing both without a weight). */
    const char *bad = gather(t, out, 1);
    if (bad && strcmp(bad, "multiple") == 0)
        bad = gather(t, out, 0);
    if (bad) { /* refused whatever its data: released at once, never waited for */
        out->status = bad;
        release(t, out);
        return 1;
    }
    /* the event's window: the earliest start to the latest end */
    double t0 = INFINITY, t1 = -INFINITY;
    for (int i = 0; i < out->n_vehicles; i++) {
        const amfi_passage_times w = window_of(t, &out->ev[i]);
        t0 = fmin(t0, (double)out->ev[i].utime + 1e6 * w.start_s);
        t1 = fmax(t1, (double)out->ev[i].utime + 1e6 * w.end_s);
    }
    /* The free vibration: from the last exit (at the measured speed) for
     * free_s, cut at the next pending vehicle's entry. */
    double fx0 = -INFINITY, fx1 = -INFINITY;
    out->free_why = "";
    if (t->p.free_s > 0) {
        for (int i = 0; i < out->n_vehicles; i++)
            fx0 = fmax(fx0, span_of(t, &out->ev[i]).t_out);
        fx1 = fx0 + 1e6 * t->p.free_s;
        for (int i = out->n_vehicles; i < t->n_pend; i++)
            if ((double)t->pend[i].utime < fx1) {
                fx1 = fmax(fx0, (double)t->pend[i].utime);
                out->free_why = "cut at the next vehicle's entry";
                break;
            }
    }
    /* Decide: all data present, data gone, or waited long enough. */
    int complete = 1, gone = 0, jumping = 0, free_complete = 1;
    const amfi_ring *gone_ring = NULL; /* a ring whose data left before t0 */
    int64_t restart_utime = 0;
    double newest_us = -INFINITY;
    int n = -1;
    for (int s = 0; s < ns; s++) {
        const amfi_ring *r = rings[s];
        if (!r || !amfi_ring_started(r)) {
            complete = 0;
            continue;
        }
        int64_t k0 = (int64_t)ceil((t0 - amfi_ring_utime(r, 0)) * amfi_ring_rate(r) * 1e-6 - 1e-6);
        int64_t k1 = (int64_t)floor((t1 - amfi_ring_utime(r, 0)) * amfi_ring_rate(r) * 1e-6 + 1e-6);
        out->k0[s] = k0;
        if (n < 0 || k1 - k0 + 1 < n)
            n = (int)(k1 - k0 + 1);
        newest_us = fmax(newest_us, amfi_ring_utime(r, amfi_ring_newest(r)));
        if (amfi_ring_newest(r) < k1)
            complete = 0;
        if (fx1 > fx0) {
            const double u0 = amfi_ring_utime(r, 0), per_us = amfi_ring_rate(r) * 1e-6;
            const int64_t f0 = (int64_t)ceil((fx0 - u0) * per_us - 1e-6),
                          f1 = (int64_t)floor((fx1 - u0) * per_us + 1e-6);
            out->free_k0[s] = f0;
            if (s == 0 || f1 - f0 + 1 < out->free_n)
                out->free_n = f1 - f0 + 1 > 0 ? (int)(f1 - f0 + 1) : 0;
            if (amfi_ring_newest(r) < f1)
                free_complete = 0;
        }
        if (k0 < amfi_ring_oldest(r)) {
            gone = 1;
            gone_ring = r;
        }
        jumping |= amfi_ring_jump_pending(r);
        const amfi_ring_stats *st = amfi_ring_stats_of(r);
        if (st->restarts > 0 && st->restart_utime > restart_utime)
            restart_utime = st->restart_utime;
    }
    if (jumping && (gone || !complete) && !flush)
        return 0; /* a jump of the data's time is under test: decide after it */
    out->n = n > 0 ? n : 0;
    if (!complete && !gone && !flush && !(newest_us > t1 + 1e6 * t->p.max_wait_s))
        return 0; /* keep waiting */
    if (complete && !free_complete && !gone && !flush &&
        !(newest_us > fx1 + 1e6 * t->p.max_wait_s))
        return 0; /* the passage's data is in: wait for its free vibration */
    if (!free_complete || !complete || gone) {
        out->free_n = 0;
        out->free_why = fx1 > fx0 ? "the free vibration's data did not all arrive" : "";
    }
    if (gone && restart_utime > 0 && t0 < (double)restart_utime) {
        out->status = "gap";
        snprintf(out->reason, sizeof out->reason,
                 "no data for this passage: the sensor stream jumped or resumed after an "
                 "outage (ring restarted %.3f s after the window's start)",
                 1e-6 * ((double)restart_utime - t0));
    } else if (gone) {
        out->status = "late";
        snprintf(out->reason, sizeof out->reason,
                 "the data for this passage had left the ring (window starts %.3f s before "
                 "the oldest sample held)",
                 1e-6 * (amfi_ring_utime(gone_ring, amfi_ring_oldest(gone_ring)) - t0));
    } else if (!complete) {
        out->status = "gap";
        snprintf(out->reason, sizeof out->reason, "%s",
                 flush ? "shut down before the passage's data arrived"
                       : "the data stream stopped before the passage's end (max_wait exceeded)");
    } else {
        int64_t other;
        for (int i = 0; i < out->n_vehicles; i++)
            if (overlapping(t, &out->ev[i], out, &other)) {
                out->status = "multiple";
                snprintf(out->reason, sizeof out->reason,
                         "vehicle %lld on the span at the same time%s", (long long)other,
                         t->p.max_event_s > 0 ? ", already stored without it" : "");
                break;
            }
        if (t->p.max_event_s > 0 && strcmp(out->status, "ok") == 0)
            for (int i = 0; i < out->n_vehicles; i++)
                out->outside[i] = outside_window(t, &out->ev[i], out, &out->outside_id[i]);
    }
    if (rings[0] && amfi_ring_started(rings[0]))
        out->t_first_s = (amfi_ring_utime(rings[0], out->k0[0]) - (double)v->utime) * 1e-6;
    release(t, out);
    return 1;
}

/* Axle a's distance from the entry at time ts (s after w->v's entry). */
static double axle_x(const amfi_vehicle_ev *v, double entry_s, const double *off, int a, double ts)
{
    return v->speed_mps * (ts - entry_s) - off[a];
}

void amfi_window_nearness(const amfi_window *w, double span_m, double gap_m, int i,
                          amfi_nearness *out)
{
    out->other = -1;
    out->share = 0.0;
    out->min_gap_m = INFINITY;
    if (i < 0 || i >= w->n_vehicles)
        return;
    double entry[AMFI_MAX_VEHICLES], off[AMFI_MAX_VEHICLES][AMFI_MAX_AXLES];
    double t_in[AMFI_MAX_VEHICLES], t_out[AMFI_MAX_VEHICLES];
    for (int k = 0; k < w->n_vehicles; k++) {
        const amfi_vehicle_ev *v = &w->ev[k];
        entry[k] = 1e-6 * (double)(v->utime - w->v.utime);
        off[k][0] = 0.0;
        for (int a = 1; a < v->n_axles; a++)
            off[k][a] = off[k][a - 1] + v->spacing_m[a - 1];
        t_in[k] = entry[k];
        t_out[k] = entry[k] + (span_m + off[k][v->n_axles - 1]) / v->speed_mps;
    }
    const amfi_vehicle_ev *me = &w->ev[i];
    const double dt = 1e-3, crossing = t_out[i] - t_in[i];
    for (int k = 0; k < w->n_vehicles; k++) {
        if (k == i || t_out[k] <= t_in[i] || t_in[k] >= t_out[i])
            continue;
        const amfi_vehicle_ev *o = &w->ev[k];
        const double lo = fmax(t_in[i], t_in[k]), hi = fmin(t_out[i], t_out[k]);
        long near = 0;
        for (long s = 0; lo + ((double)s + 0.5) * dt < hi; s++) {
            const double ts = lo + ((double)s + 0.5) * dt;
            double best = INFINITY;
            for (int a = 0; a < me->n_axles; a++) {
                const double xa = axle_x(me, entry[i], off[i], a, ts);
                if (xa < 0.0 || xa > span_m)
                    continue;
                for (int b = 0; b < o->n_axles; b++) {
                    const double xb = axle_x(o, entry[k], off[k], b, ts);
                    if (xb >= 0.0 && xb <= span_m)
                        best = fmin(best, fabs(xa - xb));
                }
            }
            out->min_gap_m = fmin(out->min_gap_m, best);
            near += best < gap_m;
        }
        const double share = crossing > 0 ? fmin(1.0, (double)near * dt / crossing) : 0.0;
        if (share > out->share || (out->other < 0 && near > 0)) {
            out->share = share;
            out->other = k;
        }
    }
}
