/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * environment.c: amfid's environment input (issue 14): the environment_t
 * readings (deck and air temperature) on daemon.channels.environment,
 * checked where they enter (the raw bytes against the type, then every
 * field: finite, -60 .. 80 °C, utime in the store's range and within
 * daemon.environment_max_skew_s of the stream's newest data time); a refused
 * one is counted and logged as the other inputs' (reject.c). Accepted ones
 * wait in a small buffer and are stored in batches, one transaction each,
 * from the heartbeat (every daemon.status_period_s), when the buffer is
 * full, and at stop: intake never waits for more than one batch.
 *
 * Bounded (docs/daemon.md, "Bounded intake"): the channel's rate limit
 * (daemon.intake.environment_per_s); a deck temperature implausible against
 * the last accepted reading (daemon.intake.deck_max_rate_c_per_min) is
 * refused unless three in a row agree; and at most one row is stored per
 * daemon.intake.environment_min_interval_s of data time (the rest counted
 * as thinned). environment_t carries no source field: the readings' source
 * is the channel (and, with an authenticated bus, the producer's key).
 *
 * A module (ctx.h): it wants its channel (bus_want) at restore; its final
 * flushes and logs the counts.
 *
 * Thread: the main thread only (the bus handler inside lcm_handle, the
 * heartbeat, the drain). Owns the buffer and its counters.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "amfi_environment_t.h"
#include "ctx.h"

#define ENV_BUF 64
static struct env_state {
    amfi_environment_row buf[ENV_BUF];
    int n;                 /* readings in buf, oldest first */
    int failing;           /* the last flush failed (logged once) */
    int64_t received, rejected, stored, lost; /* since start */
    int64_t thinned;       /* accepted, not stored: within environment_min_interval_s */
    int have_ref;          /* a reading was accepted: ref_* hold it */
    int64_t ref_utime, last_kept_utime;
    double ref_deck;
    /* implausible readings that agree with each other: adopted at the third
     * in a row (a deck sensor replaced or recalibrated, a first reading that
     * was wrong), as the rings adopt a time jump */
    int cand_n;
    int64_t cand_utime;
    double cand_deck;
} E;

static int64_t wall_now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static int temp_ok(double c)
{
    return isfinite(c) && c >= AMFI_STORE_MIN_TEMP_C && c <= AMFI_STORE_MAX_TEMP_C;
}

void environment_flush(amfid_ctx *c)
{
    struct env_state *e = &E;
    if (e->n == 0 || !c->store)
        return;
    char err[256];
    int rc = amfi_store_add_environment(c->store, e->buf, e->n, err, sizeof err);
    if (rc == 0) {
        e->stored += e->n;
        e->n = 0;
        e->failing = 0;
    } else if (!e->failing) { /* kept and retried at the next flush; logged once */
        e->failing = 1;
        LOG_WARN("store: %d environment readings not stored yet (retried): %s", e->n, err);
    }
}

double environment_deck_at(amfid_ctx *c, int64_t utime, double max_gap_s)
{
    environment_flush(c); /* the readings received so far are in the store */
    char err[256];
    double t = NAN;
    if (amfi_store_deck_c_at(c->store, utime, (int64_t)llround(1e6 * max_gap_s), &t, err,
                             sizeof err) != 0) {
        ctx_error(c, "store: %s", err);
        return NAN;
    }
    return t;
}

static void on_message(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    amfid_ctx *x = user;
    struct env_state *e = &E;
    amfi_environment_t m;
    if (admit_decode(x, AMFI_MSG_ENVIRONMENT_T, REJECT_ENVIRONMENT, "environment_t", rb, ch,
                      &m)) {
        e->rejected++;
        return;
    }
    e->received++;
    const amfi_daemon_config *c = &x->cfg->daemon;
    if (!admit_take(x, REJECT_ENVIRONMENT, 1.0)) {
        e->rejected++;
        reject_note(x, REJECT_ENVIRONMENT, REJECT_RATE,
                    "%s: environment_t refused: over the channel's rate limit "
                    "(daemon.intake.environment_per_s %g)",
                    ch, c->environment_per_s);
        return;
    }
    const double skew_s = c->environment_max_skew_s;
    char why[200] = "";
    if (m.utime <= 0 || m.utime > AMFI_STORE_MAX_UTIME)
        snprintf(why, sizeof why, "utime %lld out of (0, year 9999]", (long long)m.utime);
    else if (x->newest_utime > 0 && fabs((double)m.utime - (double)x->newest_utime) > 1e6 * skew_s)
        snprintf(why, sizeof why,
                 "utime %lld is %.0f s from the stream's newest data time (more than "
                 "daemon.environment_max_skew_s %.0f s)",
                 (long long)m.utime, 1e-6 * ((double)m.utime - (double)x->newest_utime), skew_s);
    else if (!temp_ok(m.deck_c))
        snprintf(why, sizeof why, "deck_c %.6g is not a temperature in [-60, 80] °C", m.deck_c);
    else if (!temp_ok(m.air_c))
        snprintf(why, sizeof why, "air_c %.6g is not a temperature in [-60, 80] °C", m.air_c);
    if (why[0]) {
        e->rejected++;
        reject_note(x, REJECT_ENVIRONMENT, REJECT_INVALID, "%s: environment_t rejected: %s", ch,
                    why);
        return;
    }
    /* Plausible against the last accepted reading: the deck (concrete,
     * asphalt) changes slowly; a reading further from it than
     * deck_max_rate_c_per_min allows (for at least a minute) is refused,
     * unless three such readings in a row agree with each other (a sensor
     * replaced or recalibrated, or a wrong first reading): then the third
     * is taken as the new reference. Forged readings shifted the
     * temperature compensation. */
    const double rate = c->deck_max_rate_c_min;
    if (e->have_ref) {
        const double dt_min = fabs((double)m.utime - (double)e->ref_utime) / 60e6;
        const double allowed = rate * fmax(dt_min, 1.0);
        if (fabs(m.deck_c - e->ref_deck) > allowed) {
            const double cdt_min = ((double)m.utime - (double)e->cand_utime) / 60e6;
            if (e->cand_n > 0 && cdt_min * 60.0 >= fmax(c->env_min_interval_s, 1e-6) &&
                fabs(m.deck_c - e->cand_deck) <= rate * fmax(cdt_min, 1.0))
                e->cand_n++;
            else
                e->cand_n = 1;
            e->cand_utime = m.utime;
            e->cand_deck = m.deck_c;
            if (e->cand_n < 3) {
                e->rejected++;
                reject_note(x, REJECT_ENVIRONMENT, REJECT_IMPLAUSIBLE,
                            "%s: environment_t rejected: deck_c %.2f °C is %.2f °C from the last "
                            "accepted reading (%.2f °C, %.1f min before or after): more than "
                            "daemon.intake.deck_max_rate_c_per_min %g °C/min allows",
                            ch, m.deck_c, m.deck_c - e->ref_deck, e->ref_deck, dt_min, rate);
                return;
            }
            LOG_WARN("%s: environment_t: three readings in a row agree on a deck temperature "
                     "%.2f °C away from the last accepted one (%.2f °C): taken as the new "
                     "reference",
                     ch, m.deck_c - e->ref_deck, e->ref_deck);
        }
    }
    e->cand_n = 0;
    e->have_ref = 1;
    e->ref_utime = m.utime;
    e->ref_deck = m.deck_c;
    /* At most one stored row per environment_min_interval_s of data time:
     * the compensation interpolates readings hours apart; a sensor (or a
     * flood) sending many a second does not write many rows a second. */
    if (e->last_kept_utime > 0 &&
        fabs((double)m.utime - (double)e->last_kept_utime) < 1e6 * c->env_min_interval_s) {
        e->thinned++;
        return;
    }
    e->last_kept_utime = m.utime;
    if (e->n == ENV_BUF) {
        environment_flush(x);
        if (e->n == ENV_BUF) { /* the store refuses: the oldest reading goes */
            memmove(e->buf, e->buf + 1, sizeof e->buf[0] * (ENV_BUF - 1));
            e->n--;
            e->lost++;
        }
    }
    amfi_environment_row *r = &e->buf[e->n++];
    r->utime = m.utime;
    r->deck_c = m.deck_c;
    r->air_c = m.air_c;
    r->received_utime = wall_now_us();
}

static int env_start(amfid_ctx *c, char *err, size_t errlen)
{
    (void)c, (void)err, (void)errlen;
    memset(&E, 0, sizeof E);
    return 0;
}

static int env_restore(amfid_ctx *c)
{
    bus_want(REJECT_ENVIRONMENT, c->cfg->daemon.ch_environment, on_message);
    return 0;
}

static void env_final(amfid_ctx *c)
{
    (void)c;
    if (E.received + E.rejected > 0)
        LOG_INFO("environment: %lld readings decoded, %lld refused, %lld stored%s",
                 (long long)E.received, (long long)E.rejected, (long long)E.stored,
                 E.lost + E.n > 0 ? ", some not stored (the store refused them)" : "");
    if (E.thinned > 0)
        LOG_INFO("environment: %lld accepted readings not stored (within "
                 "daemon.intake.environment_min_interval_s of a stored one)",
                 (long long)E.thinned);
}

/* After the intake's final line: what was lost. */
static void env_lost(amfid_ctx *c)
{
    (void)c;
    if (E.lost + E.n > 0)
        LOG_WARN("environment: %lld readings dropped while the store refused them, %d still "
                 "buffered at stop: not stored",
                 (long long)E.lost, E.n);
}

static void env_metrics(amfid_ctx *c, amfid_stats *s)
{
    (void)c;
    s->env_received = E.received;
    s->env_rejected = E.rejected;
    s->env_stored = E.stored;
    s->env_lost = E.lost;
    s->env_thinned = E.thinned;
    s->env_buffered = E.n;
}

const amfid_module environment_module = {
    .name = "environment",
    .start = env_start,
    .restore = env_restore,
    .metrics = env_metrics,
    .final = env_final,
};

/* The lost readings' line comes last in the drain (after the intake's):
 * a module of its own at the head of the table. */
const amfid_module environment_lost_module = {
    .name = "environment_lost",
    .final = env_lost,
};
