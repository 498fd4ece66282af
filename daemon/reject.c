/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * reject.c: amfid's count of refused bus messages, per input channel and per
 * reason, and the rate limit on their log lines (issue: 40 000 bad messages
 * once wrote 15 049 lines). Every refusal is counted and becomes the status
 * message's last_error; the log gets at most REJECT_LOG_BURST lines in full
 * per REJECT_LOG_PERIOD_S seconds of wall time, and then, once the period
 * is over, one summary line with what was held back, by channel and reason.
 * The store gets the same counts as rows of the table refusals, one per
 * channel and reason every daemon.intake.summary_period_s of wall time and
 * at stop, with the first refused message's line: a flood costs a few rows
 * a period, never one fsync'd row per message.
 *
 * A module (ctx.h): its timer (every daemon.status_period_s) closes the
 * log period and stores the summary rows when their period is over; its
 * final writes the last summary and the totals.
 *
 * Thread: the main thread only (the bus handlers, the timers, the drain).
 * Owns the counts.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "amfi_msg_check.h"
#include "ctx.h"

#define REJECT_LOG_BURST 20
#define REJECT_LOG_PERIOD_S 60.0

#define REJECT_EXAMPLE 512

static struct reject_state {
    int64_t count[REJECT_NINPUTS][REJECT_NREASONS]; /* since start */
    int64_t total;
    int64_t held, held_by[REJECT_NINPUTS][REJECT_NREASONS]; /* not logged this period */
    int logged;                                             /* lines logged this period */
    double period_start;                                    /* amfi_mono_s() */
    /* the store's summary (table refusals), every daemon.intake.summary_period_s */
    int64_t sum_count[REJECT_NINPUTS][REJECT_NREASONS];     /* this summary period */
    char sum_example[REJECT_NINPUTS][REJECT_NREASONS][REJECT_EXAMPLE]; /* the first's line */
    double sum_start;                                       /* amfi_mono_s() */
    int64_t sum_start_wall;                                 /* µs, wall clock */
    int64_t summaries_stored, summaries_lost;               /* rows */
} R;

static const char *const input_name[REJECT_NINPUTS] = {"accel", "vehicle", "truth",
                                                         "environment"};

/* the intake's bounds (intake.c, environment.c) */
static const char *intake_reason_name(int reason)
{
    switch (reason) {
    case REJECT_RATE: return "rate_limited";
    case REJECT_SOURCE: return "source";
    case REJECT_IMPLAUSIBLE: return "implausible";
    default: return NULL;
    }
}

const char *reject_reason_name(int reason)
{
    if (intake_reason_name(reason))
        return intake_reason_name(reason);
    if (reason == REJECT_INVALID)
        return "invalid";
    if (reason == REJECT_QUARANTINE)
        return "quarantined";
    if (reason >= REJECT_AUTH && reason < REJECT_NREASONS)
        return amfi_auth_reason_name(reason - REJECT_AUTH);
    return amfi_msg_reason_name(reason);
}

static const char *channel_of(const amfid_ctx *c, int input)
{
    switch (input) {
    case REJECT_ACCEL: return c->cfg->daemon.ch_accel;
    case REJECT_VEHICLE: return c->cfg->daemon.ch_vehicle;
    case REJECT_ENVIRONMENT: return c->cfg->daemon.ch_environment;
    default: return c->cfg->daemon.ch_truth;
    }
}

/* One line: what was held back since the period began (nothing if none). */
static void summarise(amfid_ctx *c, double now)
{
    struct reject_state *r = &R;
    if (r->held > 0) {
        char line[1024];
        size_t n = (size_t)snprintf(line, sizeof line,
                                    "%lld more refused messages not logged in the last %.0f s:",
                                    (long long)r->held, now - r->period_start);
        for (int i = 0; i < REJECT_NINPUTS; i++)
            for (int k = 0; k < REJECT_NREASONS; k++)
                if (r->held_by[i][k] > 0 && n < sizeof line)
                    n += (size_t)snprintf(line + n, sizeof line - n, " %s/%s %lld",
                                          channel_of(c, i), reject_reason_name(k),
                                          (long long)r->held_by[i][k]);
        LOG_WARN("%s (totals since start: amfid's status message and log at stop)", line);
    }
    r->held = 0;
    memset(r->held_by, 0, sizeof r->held_by);
    r->logged = 0;
    r->period_start = now;
}

static int64_t wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* The summary period's rows into the store, one transaction (the counts
 * are kept for the next try when the store refuses, up to one more period). */
static void store_summary(amfid_ctx *c, double now)
{
    struct reject_state *r = &R;
    amfi_refusal_row rows[REJECT_NINPUTS * REJECT_NREASONS];
    int n = 0;
    const int64_t end = wall_us();
    if (r->sum_start_wall == 0)
        r->sum_start_wall = end;
    for (int i = 0; i < REJECT_NINPUTS; i++)
        for (int k = 0; k < REJECT_NREASONS; k++)
            if (r->sum_count[i][k] > 0)
                rows[n++] = (amfi_refusal_row){r->sum_start_wall,
                                               end < r->sum_start_wall ? r->sum_start_wall : end,
                                               channel_of(c, i), input_name[i],
                                               reject_reason_name(k), r->sum_count[i][k],
                                               r->sum_example[i][k]};
    if (n > 0 && c->store) {
        char err[256];
        if (amfi_store_add_refusals(c->store, rows, n, err, sizeof err) != 0) {
            if (now - r->sum_start < 2.0 * c->cfg->daemon.summary_period_s)
                return; /* kept, retried at the next tick (the counts grow) */
            LOG_WARN("store: the summary of refused messages (%d rows) is lost: %s (the "
                     "counts since start are in the log at stop and in the status message)",
                     n, err);
            r->summaries_lost += n;
        } else {
            r->summaries_stored += n;
        }
    }
    memset(r->sum_count, 0, sizeof r->sum_count);
    r->sum_start = now;
    r->sum_start_wall = end;
}

void reject_note(amfid_ctx *c, int input, int reason, const char *fmt, ...)
{
    struct reject_state *r = &R;
    if (input < 0 || input >= REJECT_NINPUTS || reason < 0 || reason >= REJECT_NREASONS)
        return;
    r->count[input][reason]++;
    r->total++;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->last_error, sizeof c->last_error, fmt, ap);
    va_end(ap);
    if (r->sum_count[input][reason]++ == 0)
        snprintf(r->sum_example[input][reason], REJECT_EXAMPLE, "%s", c->last_error);
    double now = amfi_mono_s();
    if (now - r->period_start >= REJECT_LOG_PERIOD_S)
        summarise(c, now);
    if (r->logged < REJECT_LOG_BURST) {
        r->logged++;
        LOG_WARN("%s", c->last_error);
        if (r->logged == REJECT_LOG_BURST)
            LOG_WARN("further refused messages are counted and summarised once per %.0f s",
                     REJECT_LOG_PERIOD_S);
    } else {
        r->held++;
        r->held_by[input][reason]++;
    }
}

static int reject_tick(amfid_ctx *c)
{
    double now = amfi_mono_s();
    if (now - R.period_start >= REJECT_LOG_PERIOD_S)
        summarise(c, now);
    if (R.sum_start == 0.0) {
        R.sum_start = now;
        R.sum_start_wall = wall_us();
    }
    if (now - R.sum_start >= c->cfg->daemon.summary_period_s)
        store_summary(c, now);
    return 0;
}

static int reject_start(amfid_ctx *c, char *err, size_t errlen)
{
    (void)c, (void)err, (void)errlen;
    memset(&R, 0, sizeof R);
    return 0;
}

static int reject_restore(amfid_ctx *c)
{
    R.sum_start = amfi_mono_s();
    R.sum_start_wall = wall_us();
    return timer_add(c->timers, &c->cfg->daemon.status_period_s, reject_tick) ? 1 : 0;
}

static void reject_final(amfid_ctx *c)
{
    summarise(c, amfi_mono_s());
    store_summary(c, 1e300); /* at stop: stored now or lost (counted) */
    for (int i = 0; i < REJECT_NINPUTS; i++)
        for (int k = 0; k < REJECT_NREASONS; k++)
            if (R.count[i][k] > 0)
                LOG_INFO("refused since start: %s (%s) %s: %lld", channel_of(c, i),
                         input_name[i], reject_reason_name(k), (long long)R.count[i][k]);
}

static void reject_metrics(amfid_ctx *c, amfid_stats *s)
{
    (void)c;
    s->refused_total = R.total;
    memcpy(s->refused, R.count, sizeof s->refused);
    s->summaries_lost = R.summaries_lost;
}

const amfid_module reject_module = {
    .name = "reject",
    .start = reject_start,
    .restore = reject_restore,
    .metrics = reject_metrics,
    .final = reject_final,
};
