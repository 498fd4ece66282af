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
 * Thread: the main thread only (the bus handler inside lcm_handle, the
 * heartbeat, the drain). Owns d->env (the buffer and its counters).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "amfi_environment_t.h"
#include "amfid.h"

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

void environment_flush(daemon_s *d)
{
    env_state *e = &d->env;
    if (e->n == 0 || !d->store)
        return;
    char err[256];
    int rc = amfi_store_add_environment(d->store, e->buf, e->n, err, sizeof err);
    if (rc == 0) {
        e->stored += e->n;
        e->n = 0;
        e->failing = 0;
    } else if (!e->failing) { /* kept and retried at the next flush; logged once */
        e->failing = 1;
        LOG_WARN("store: %d environment readings not stored yet (retried): %s", e->n, err);
    }
}

double environment_deck_at(daemon_s *d, int64_t utime, double max_gap_s)
{
    environment_flush(d); /* the readings received so far are in the store */
    char err[256];
    double t = NAN;
    if (amfi_store_deck_c_at(d->store, utime, (int64_t)llround(1e6 * max_gap_s), &t, err,
                             sizeof err) != 0) {
        set_error(d, "store: %s", err);
        return NAN;
    }
    return t;
}

void environment_on_message(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    daemon_s *d = user;
    env_state *e = &d->env;
    amfi_environment_t m;
    if (intake_decode(d, AMFI_MSG_ENVIRONMENT_T, REJECT_ENVIRONMENT, "environment_t", rb, ch,
                      &m)) {
        e->rejected++;
        return;
    }
    e->received++;
    const amfi_daemon_config *c = &d->cfg.daemon;
    if (!intake_take(d, REJECT_ENVIRONMENT, 1.0)) {
        e->rejected++;
        reject_note(d, REJECT_ENVIRONMENT, REJECT_RATE,
                    "%s: environment_t refused: over the channel's rate limit "
                    "(daemon.intake.environment_per_s %g)",
                    ch, c->environment_per_s);
        return;
    }
    const double skew_s = c->environment_max_skew_s;
    char why[200] = "";
    if (m.utime <= 0 || m.utime > AMFI_STORE_MAX_UTIME)
        snprintf(why, sizeof why, "utime %lld out of (0, year 9999]", (long long)m.utime);
    else if (d->newest_utime > 0 && fabs((double)m.utime - (double)d->newest_utime) > 1e6 * skew_s)
        snprintf(why, sizeof why,
                 "utime %lld is %.0f s from the stream's newest data time (more than "
                 "daemon.environment_max_skew_s %.0f s)",
                 (long long)m.utime, 1e-6 * ((double)m.utime - (double)d->newest_utime), skew_s);
    else if (!temp_ok(m.deck_c))
        snprintf(why, sizeof why, "deck_c %.6g is not a temperature in [-60, 80] °C", m.deck_c);
    else if (!temp_ok(m.air_c))
        snprintf(why, sizeof why, "air_c %.6g is not a temperature in [-60, 80] °C", m.air_c);
    if (why[0]) {
        e->rejected++;
        reject_note(d, REJECT_ENVIRONMENT, REJECT_INVALID, "%s: environment_t rejected: %s", ch,
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
                reject_note(d, REJECT_ENVIRONMENT, REJECT_IMPLAUSIBLE,
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
        environment_flush(d);
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
