/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * admit.c: amfid's admission of what the inputs hand over: every message
 * counted, checked against its type on the raw bytes before lcm-gen's
 * decoder runs (amfi_msg_decode_checked, messages/amfi_msg_check.h: a
 * negative count or length in a datagram can no longer crash amfid), and
 * each input channel's rate limit: a token bucket, `rate` tokens a second,
 * at most `cap`, refilled by the wall time or the data time that passed,
 * whichever is more (a replay at any speed keeps the data's own rate; a
 * flood cannot move the data time). Shared by the bus handlers of
 * intake.c and environment.c; refusals go to reject.c.
 *
 * Thread: the main thread only. Owns the buckets and the message counters.
 */
#include <math.h>
#include <string.h>

#include "ctx.h"

static struct {
    struct bucket {
        double tokens, rate, cap;
        double last_wall;   /* amfi_mono_s() of the last refill */
        int64_t last_data;  /* newest_utime at the last refill */
    } lim[REJECT_NINPUTS];
    int64_t messages_in;    /* every message the inputs handed over */
    int64_t malformed;      /* of which the checker refused */
} A;

void admit_reset(void)
{
    memset(&A, 0, sizeof A);
}

void admit_limits(amfid_ctx *c, const amfi_site_config *cfg)
{
    const amfi_daemon_config *dc = &cfg->daemon;
    double samples = 0.0;
    for (int i = 0; i < cfg->solver.n_sensors; i++)
        samples += cfg->sensor_rate_hz[i];
    double rate[REJECT_NINPUTS];
    rate[REJECT_ACCEL] = dc->accel_margin * samples; /* samples a second */
    rate[REJECT_VEHICLE] = dc->vehicles_per_s;
    rate[REJECT_TRUTH] = dc->truth_per_s;
    rate[REJECT_ENVIRONMENT] = dc->environment_per_s;
    const double now = amfi_mono_s();
    for (int i = 0; i < REJECT_NINPUTS; i++) {
        struct bucket *b = &A.lim[i];
        const int fresh = b->cap == 0.0;
        b->rate = rate[i];
        b->cap = fmax(rate[i] * dc->burst_s, 1.0);
        if (fresh || b->tokens > b->cap)
            b->tokens = b->cap;
        b->last_wall = now;
        b->last_data = c->newest_utime;
    }
}

double admit_rate(int input)
{
    return A.lim[input].rate;
}

int admit_take(amfid_ctx *c, int input, double cost)
{
    struct bucket *b = &A.lim[input];
    if (b->cap == 0.0)
        return 1; /* no limits set */
    const double now = amfi_mono_s();
    double dt = now - b->last_wall;
    if (c->newest_utime > b->last_data)
        dt = fmax(dt, 1e-6 * (double)(c->newest_utime - b->last_data));
    if (dt > 0)
        b->tokens = fmin(b->cap, b->tokens + b->rate * dt);
    b->last_wall = now;
    b->last_data = c->newest_utime; /* back too, after a confirmed jump: no refill */
    if (b->tokens >= cost) {
        b->tokens -= cost;
        return 1;
    }
    return 0;
}

int admit_decode(amfid_ctx *c, amfi_msg_type type, int input, const char *tname,
                 const lcm_recv_buf_t *rb, const char *ch, void *m)
{
    A.messages_in++;
    char cwhy[160];
    int cr = amfi_msg_decode_checked(type, rb->data, rb->data_size, m, cwhy, sizeof cwhy);
    if (cr == AMFI_MSG_OK)
        return 0;
    A.malformed++; /* nothing decoded, nothing allocated */
    reject_note(c, input, cr, "%s: malformed %s (%u bytes) rejected: %s", ch, tname,
                rb->data_size, cwhy);
    return -1;
}

void admit_count_in(void)
{
    A.messages_in++;
}

void admit_stats(amfid_stats *s)
{
    s->messages_in = A.messages_in;
    s->messages_malformed += A.malformed;
}
