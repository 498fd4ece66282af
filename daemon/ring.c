/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ring.c: the per-sensor sample ring (see ring.h).
 */
#include <math.h>
#include <stdlib.h>

#include "ring.h"

struct amfi_ring {
    double rate;        /* Hz */
    int64_t origin;     /* µs of sample 0 */
    int started;
    int64_t cap;        /* samples held */
    int64_t newest;     /* index of the newest sample, −1 before any */
    double *buf;        /* cap, sample k at buf[k mod cap]; NaN = missing */
    amfi_ring_stats st;
    /* a jump under test: blocks far from the stream that continue each other */
    int cand_count;     /* 0: none */
    double cand_next;   /* µs where the next block of the candidate starts */
};

amfi_ring *amfi_ring_create(double rate_hz, double seconds)
{
    if (!(rate_hz > 0 && rate_hz <= 1e6) || !(seconds > 0 && seconds <= 3600))
        return NULL;
    amfi_ring *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->rate = rate_hz;
    r->cap = (int64_t)ceil(seconds * rate_hz);
    r->newest = -1;
    r->buf = malloc(sizeof(double) * (size_t)r->cap);
    if (!r->buf) {
        free(r);
        return NULL;
    }
    for (int64_t i = 0; i < r->cap; i++)
        r->buf[i] = NAN;
    return r;
}

void amfi_ring_destroy(amfi_ring *r)
{
    if (!r)
        return;
    free(r->buf);
    free(r);
}

double amfi_ring_rate(const amfi_ring *r) { return r->rate; }
int amfi_ring_started(const amfi_ring *r) { return r->started; }
int64_t amfi_ring_newest(const amfi_ring *r) { return r->newest; }
const amfi_ring_stats *amfi_ring_stats_of(const amfi_ring *r) { return &r->st; }
int amfi_ring_jump_pending(const amfi_ring *r) { return r->cand_count > 0; }

int64_t amfi_ring_oldest(const amfi_ring *r)
{
    int64_t o = r->newest - r->cap + 1;
    return o < 0 ? 0 : o;
}

int64_t amfi_ring_index(const amfi_ring *r, int64_t utime)
{
    return (int64_t)llround((double)(utime - r->origin) * r->rate * 1e-6);
}

double amfi_ring_utime(const amfi_ring *r, int64_t k)
{
    return (double)r->origin + (double)k * 1e6 / r->rate;
}

static double *slot(const amfi_ring *r, int64_t k)
{
    int64_t i = k % r->cap;
    return &r->buf[i < 0 ? i + r->cap : i];
}

int amfi_ring_put(amfi_ring *r, int64_t utime, double rate_hz, int n, const double *x,
                  const char **why)
{
    const char *dummy;
    if (!why)
        why = &dummy;
    *why = "";
    if (n <= 0) {
        *why = "empty block";
        r->st.rejected++;
        return AMFI_RING_REJECT;
    }
    if (!(fabs(rate_hz - r->rate) <= 1e-6 * r->rate)) {
        *why = "sample rate differs from the sensor's";
        r->st.rejected++;
        return AMFI_RING_REJECT;
    }
    if (!r->started) {
        r->origin = utime;
        r->started = 1;
    }
    int restarted = 0;
    double exact = (double)(utime - r->origin) * r->rate * 1e-6;
    /* Far from the stream: more than AMFI_RING_FAR_S (or the ring's length,
     * if longer) past either end of what the ring holds? */
    const double far = fmax((double)r->cap, AMFI_RING_FAR_S * r->rate);
    if (r->newest >= 0 && (exact - (double)r->newest > far ||
                           exact + n - 1 < (double)amfi_ring_oldest(r) - far)) {
        const double period_us = 1e6 / r->rate;
        if (r->cand_count > 0 && fabs((double)utime - r->cand_next) <= 0.25 * period_us)
            r->cand_count++;
        else
            r->cand_count = 1;
        r->cand_next = (double)utime + n * period_us;
        if (r->cand_count < AMFI_RING_CONFIRM) {
            *why = "block far from the stream's time (quarantined until confirmed)";
            r->st.quarantined++;
            return AMFI_RING_QUARANTINE;
        }
        /* Confirmed: start over on the new time line at this block. */
        r->st.last_jump_s = ((double)utime - amfi_ring_utime(r, r->newest + 1)) * 1e-6;
        r->origin = utime;
        r->newest = -1;
        for (int64_t i = 0; i < r->cap; i++)
            r->buf[i] = NAN;
        r->st.restarts++;
        r->st.restart_utime = utime;
        r->cand_count = 0;
        restarted = 1;
        exact = 0.0;
    } else {
        r->cand_count = 0; /* the stream goes on: no jump */
    }
    int64_t k0 = (int64_t)llround(exact);
    if (fabs(exact - (double)k0) > 0.25) {
        *why = "block start is off the sample grid";
        r->st.rejected++;
        return AMFI_RING_REJECT;
    }
    const int64_t k1 = k0 + n - 1;
    if (r->newest >= 0 && k1 < amfi_ring_oldest(r)) {
        r->st.late++;
        return AMFI_RING_LATE;
    }
    if (r->newest >= 0 && k1 <= r->newest) {
        /* Entirely within what we hold: a duplicate, or a fill. */
        int64_t fills = 0;
        for (int i = 0; i < n; i++) {
            int64_t k = k0 + i;
            if (k < amfi_ring_oldest(r))
                continue;
            double *p = slot(r, k);
            if (isnan(*p) && !isnan(x[i])) {
                *p = x[i];
                fills++;
            }
        }
        if (fills == 0) {
            r->st.duplicates++;
            return AMFI_RING_DUP;
        }
        r->st.filled += fills;
        r->st.missing -= fills;
        r->st.blocks++;
        return AMFI_RING_OK;
    }
    /* Extends the newest: mark a gap, then store. */
    if (r->newest >= 0 && k0 > r->newest + 1) {
        int64_t gap = k0 - r->newest - 1;
        r->st.missing += gap;
        int64_t from = gap > r->cap ? k0 - r->cap : r->newest + 1;
        for (int64_t k = from; k < k0; k++)
            *slot(r, k) = NAN;
    }
    for (int i = 0; i < n; i++) {
        int64_t k = k0 + i;
        if (r->newest >= 0 && k <= r->newest) { /* overlap with what we hold */
            double *p = slot(r, k);
            if (isnan(*p) && k >= amfi_ring_oldest(r)) {
                *p = x[i];
                r->st.filled++;
                r->st.missing--;
            }
            continue;
        }
        *slot(r, k) = x[i];
    }
    if (k1 > r->newest)
        r->newest = k1;
    r->st.blocks++;
    return restarted ? AMFI_RING_RESTART : AMFI_RING_OK;
}

int amfi_ring_get(const amfi_ring *r, int64_t k0, int n, double *out)
{
    if (r->newest < 0 || k0 < amfi_ring_oldest(r) || k0 + n - 1 > r->newest || n < 0)
        return -1;
    int missing = 0;
    for (int i = 0; i < n; i++) {
        out[i] = *slot(r, k0 + i);
        missing += isnan(out[i]) != 0;
    }
    return missing;
}
