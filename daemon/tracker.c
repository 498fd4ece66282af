/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * tracker.c: passage windows from vehicle events and sample rings.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tracker.h"

#define RECENT 64

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
};

amfi_tracker *amfi_tracker_create(const amfi_tracker_params *p)
{
    if (!(p->span_m > 0) || !(p->pre_s >= 0) || !(p->post_s >= 0) || !(p->max_wait_s > 0) ||
        p->n_sensors < 1 || p->n_sensors > AMFI_MAX_SENSORS)
        return NULL;
    amfi_tracker *t = calloc(1, sizeof *t);
    if (t)
        t->p = *p;
    return t;
}

void amfi_tracker_destroy(amfi_tracker *t) { free(t); }
int amfi_tracker_pending(const amfi_tracker *t) { return t->n_pend; }

/* The vehicle's passage window (libamfi's one definition), seconds from its entry. */
static amfi_passage_times window_of(const amfi_tracker *t, const amfi_vehicle_ev *v)
{
    return amfi_passage_window(t->p.span_m, v->speed_mps, v->n_axles, v->spacing_m,
                               t->p.pre_s, t->p.post_s);
}

static span span_of(const amfi_tracker *t, const amfi_vehicle_ev *v)
{
    span s = {v->vehicle_id, (double)v->utime,
              (double)v->utime + 1e6 * window_of(t, v).on_span_s};
    return s;
}

int amfi_tracker_add(amfi_tracker *t, const amfi_vehicle_ev *v, const char **why)
{
    const char *dummy;
    if (!why)
        why = &dummy;
    for (int i = 0; i < t->n_pend; i++)
        if (t->pend[i].vehicle_id == v->vehicle_id) {
            *why = "vehicle id already pending";
            return -1;
        }
    if (t->n_pend == AMFI_TRACKER_MAX_PENDING) {
        *why = "too many vehicles waiting for their data";
        return -1;
    }
    int i = t->n_pend;
    while (i > 0 && t->pend[i - 1].utime > v->utime) {
        t->pend[i] = t->pend[i - 1];
        i--;
    }
    t->pend[i] = *v;
    t->n_pend++;
    return 0;
}

/* Another vehicle (pending or recently released) on the span at the same time. */
static int overlapping(const amfi_tracker *t, const amfi_vehicle_ev *v, int64_t *other)
{
    span me = span_of(t, v);
    for (int i = 0; i < t->n_pend; i++) {
        if (t->pend[i].vehicle_id == v->vehicle_id)
            continue;
        span o = span_of(t, &t->pend[i]);
        if (o.t_in < me.t_out && me.t_in < o.t_out) {
            *other = o.id;
            return 1;
        }
    }
    for (int i = 0; i < t->n_recent; i++) {
        const span *o = &t->recent[i];
        if (o->id != v->vehicle_id && o->t_in < me.t_out && me.t_in < o->t_out) {
            *other = o->id;
            return 1;
        }
    }
    return 0;
}

int amfi_tracker_next(amfi_tracker *t, amfi_ring *const *rings, int flush, amfi_window *out)
{
    if (t->n_pend == 0)
        return 0;
    const amfi_vehicle_ev *v = &t->pend[0];
    const int ns = t->p.n_sensors;
    const amfi_passage_times w = window_of(t, v);
    const double t0 = (double)v->utime + 1e6 * w.start_s;
    const double t1 = (double)v->utime + 1e6 * w.end_s;
    memset(out, 0, sizeof *out);
    out->v = *v;
    out->status = "ok";
    /* Decide: all data present, data gone, or waited long enough. */
    int complete = 1, gone = 0, jumping = 0;
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
        if (overlapping(t, v, &other)) {
            out->status = "multiple";
            snprintf(out->reason, sizeof out->reason,
                     "vehicle %lld on the span at the same time", (long long)other);
        }
    }
    if (rings[0] && amfi_ring_started(rings[0]))
        out->t_first_s = (amfi_ring_utime(rings[0], out->k0[0]) - (double)v->utime) * 1e-6;
    out->seq = ++t->seq;
    /* remember its span, release */
    t->recent[t->recent_head] = span_of(t, v);
    t->recent_head = (t->recent_head + 1) % RECENT;
    if (t->n_recent < RECENT)
        t->n_recent++;
    memmove(t->pend, t->pend + 1, sizeof *t->pend * (size_t)(t->n_pend - 1));
    t->n_pend--;
    return 1;
}
