/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sink.c: amfid's store sink (sink.h): write in order, hold what the store
 * refuses (bounded in bytes), retry with a backoff, degraded meanwhile.
 */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <time.h>

#include <systemd/sd-daemon.h>

#include "amfi_time.h"
#include "log.h"
#include "sink.h"

struct sink {
    sink_params p;
    sink_ops ops;
    job **held;          /* a ring of cap, n from head, oldest first */
    int cap, head, n;
    size_t bytes;
    sink_stats st;
    double retry_at, retry_wait; /* amfi_mono_s() of the next try; backoff */
};

/* What a held passage costs: its job (the samples are freed when held). */
static size_t held_bytes(const job *j)
{
    (void)j;
    return sizeof(job);
}

sink *sink_create(const sink_params *p, const sink_ops *ops)
{
    if (p->max_bytes < sizeof(job) || !ops || !ops->write)
        return NULL;
    sink *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->p = *p;
    s->ops = *ops;
    return s;
}

int sink_capacity(const sink *s)
{
    size_t n = s->p.max_bytes / sizeof(job);
    return n > (size_t)(1 << 30) ? 1 << 30 : (int)n;
}

static job *pop_front(sink *s)
{
    assert(s->n > 0);
    job *j = s->held[s->head];
    s->held[s->head] = NULL;
    s->head = (s->head + 1) % s->cap;
    s->n--;
    assert(s->bytes >= held_bytes(j));
    s->bytes -= held_bytes(j);
    assert(s->n > 0 || s->bytes == 0);
    return j;
}

void sink_destroy(sink *s)
{
    if (!s)
        return;
    while (s->n > 0)
        job_free(pop_front(s));
    free(s->held);
    free(s);
}

static void set_degraded(sink *s, int on)
{
    if (on == s->st.degraded)
        return;
    s->st.degraded = on;
    if (s->ops.degraded)
        s->ops.degraded(s->ops.arg, on);
}

/* Room for one more in the ring (it grows by doubling, up to the bound). */
static int ring_room(sink *s)
{
    if (s->n < s->cap)
        return 0;
    int cap = s->cap ? 2 * s->cap : 64;
    job **nh = calloc((size_t)cap, sizeof *nh);
    if (!nh)
        return -1;
    for (int i = 0; i < s->n; i++)
        nh[i] = s->held[(s->head + i) % s->cap];
    free(s->held);
    s->held = nh;
    s->cap = cap;
    s->head = 0;
    return 0;
}

/* Hold a passage the store refused, in order (the job keeps only what the
 * row needs: its samples are freed). */
static void hold(sink *s, job *j)
{
    if (s->bytes + held_bytes(j) > s->p.max_bytes || ring_room(s)) {
        s->st.lost++;
        s->st.overflow++;
        LOG_ERR("store: passage of vehicle %lld at utime %lld LOST: the held queue is full "
                "(%d passages; %lld lost in all)",
                (long long)j->w.v.vehicle_id, (long long)j->w.v.utime, s->n,
                (long long)s->st.lost);
        job_free(j);
        return;
    }
    free(j->accel);
    j->accel = NULL;
    s->held[(s->head + s->n) % s->cap] = j;
    s->n++;
    s->bytes += held_bytes(j);
    assert(s->bytes <= s->p.max_bytes);
    if (s->n > s->st.peak)
        s->st.peak = s->n;
    if (s->bytes > s->st.peak_bytes)
        s->st.peak_bytes = s->bytes;
    if (!s->st.degraded) {
        s->retry_wait = s->p.first_wait_s;
        s->retry_at = amfi_mono_s() + s->retry_wait;
    }
    set_degraded(s, 1);
}

int sink_put(sink *s, job *j)
{
    if (s->n > 0 || s->ops.write(s->ops.arg, j) != 0) {
        hold(s, j);
        return -1;
    }
    job_free(j);
    return 0;
}

void sink_retry(sink *s, double final)
{
    double until = amfi_mono_s() + final;
    while (s->n > 0) {
        double now = amfi_mono_s();
        if (now < s->retry_at) {
            if (final <= 0)
                return;
            if (now >= until)
                break; /* stopping, and out of time: counted below */
            double w = fmin(s->retry_at - now, until - now);
            struct timespec ts = {(time_t)w, (long)(1e9 * (w - floor(w)))};
            nanosleep(&ts, NULL);
            continue;
        }
        while (s->n > 0 && s->ops.write(s->ops.arg, s->held[s->head]) == 0)
            job_free(pop_front(s));
        if (s->n == 0) {
            LOG_INFO("store: the held passages are stored (peak %d)", s->st.peak);
            set_degraded(s, 0);
            return;
        }
        s->retry_wait = fmin(2.0 * s->retry_wait, s->p.max_wait_s);
        s->retry_at = amfi_mono_s() + s->retry_wait;
        sd_notifyf(0, "STATUS=degraded: store cannot be written, %d passages held", s->n);
        if (final <= 0 || amfi_mono_s() >= until) {
            if (final > 0)
                break;
            return;
        }
    }
    while (s->n > 0) { /* stopping, and the store still refuses */
        job *j = pop_front(s);
        LOG_ERR("store: passage of vehicle %lld at utime %lld NOT STORED: the store still "
                "refuses writes at shutdown (%s)",
                (long long)j->w.v.vehicle_id, (long long)j->w.v.utime,
                s->ops.last_error ? s->ops.last_error : "");
        s->st.lost++;
        job_free(j);
    }
}

void sink_lost(sink *s, int64_t n)
{
    s->st.lost += n;
}

void sink_stats_of(const sink *s, sink_stats *st)
{
    *st = s->st;
    st->held = s->n;
    st->bytes = s->bytes;
}
