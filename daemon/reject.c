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
 * Thread: the main thread only (the bus handlers, the heartbeat, the drain).
 * Owns d->rej.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "amfi_msg_check.h"
#include "amfid.h"

#define REJECT_LOG_BURST 20
#define REJECT_LOG_PERIOD_S 60.0

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

static const char *channel_of(const daemon_s *d, int input)
{
    switch (input) {
    case REJECT_ACCEL: return d->cfg.daemon.ch_accel;
    case REJECT_VEHICLE: return d->cfg.daemon.ch_vehicle;
    case REJECT_ENVIRONMENT: return d->cfg.daemon.ch_environment;
    default: return d->cfg.daemon.ch_truth;
    }
}

/* One line: what was held back since the period began (nothing if none). */
static void summarise(daemon_s *d, double now)
{
    reject_state *r = &d->rej;
    if (r->held > 0) {
        char line[1024];
        size_t n = (size_t)snprintf(line, sizeof line,
                                    "%lld more refused messages not logged in the last %.0f s:",
                                    (long long)r->held, now - r->period_start);
        for (int i = 0; i < REJECT_NINPUTS; i++)
            for (int k = 0; k < REJECT_NREASONS; k++)
                if (r->held_by[i][k] > 0 && n < sizeof line)
                    n += (size_t)snprintf(line + n, sizeof line - n, " %s/%s %lld",
                                          channel_of(d, i), reject_reason_name(k),
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
static void store_summary(daemon_s *d, double now)
{
    reject_state *r = &d->rej;
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
                                               channel_of(d, i), input_name[i],
                                               reject_reason_name(k), r->sum_count[i][k],
                                               r->sum_example[i][k]};
    if (n > 0 && d->store) {
        char err[256];
        if (amfi_store_add_refusals(d->store, rows, n, err, sizeof err) != 0) {
            if (now - r->sum_start < 2.0 * d->cfg.daemon.summary_period_s)
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

void reject_note(daemon_s *d, int input, int reason, const char *fmt, ...)
{
    reject_state *r = &d->rej;
    if (input < 0 || input >= REJECT_NINPUTS || reason < 0 || reason >= REJECT_NREASONS)
        return;
    r->count[input][reason]++;
    r->total++;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->last_error, sizeof d->last_error, fmt, ap);
    va_end(ap);
    if (r->sum_count[input][reason]++ == 0)
        snprintf(r->sum_example[input][reason], REJECT_EXAMPLE, "%s", d->last_error);
    double now = amfi_mono_s();
    if (now - r->period_start >= REJECT_LOG_PERIOD_S)
        summarise(d, now);
    if (r->logged < REJECT_LOG_BURST) {
        r->logged++;
        LOG_WARN("%s", d->last_error);
        if (r->logged == REJECT_LOG_BURST)
            LOG_WARN("further refused messages are counted and summarised once per %.0f s",
                     REJECT_LOG_PERIOD_S);
    } else {
        r->held++;
        r->held_by[input][reason]++;
    }
}

void reject_tick(daemon_s *d)
{
    double now = amfi_mono_s();
    if (now - d->rej.period_start >= REJECT_LOG_PERIOD_S)
        summarise(d, now);
    if (d->rej.sum_start == 0.0) {
        d->rej.sum_start = now;
        d->rej.sum_start_wall = wall_us();
    }
    if (now - d->rej.sum_start >= d->cfg.daemon.summary_period_s)
        store_summary(d, now);
}

void reject_final(daemon_s *d)
{
    summarise(d, amfi_mono_s());
    store_summary(d, 1e300); /* at stop: stored now or lost (counted) */
    const reject_state *r = &d->rej;
    for (int i = 0; i < REJECT_NINPUTS; i++)
        for (int k = 0; k < REJECT_NREASONS; k++)
            if (r->count[i][k] > 0)
                LOG_INFO("refused since start: %s (%s) %s: %lld", channel_of(d, i),
                         input_name[i], reject_reason_name(k), (long long)r->count[i][k]);
}
