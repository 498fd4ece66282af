/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ring.c: the per-sensor sample ring (see ring.h).
 */
#include <math.h>
#include <stdlib.h>

#include "ring.h"

/* Samples live in chunks of CHUNK, allocated when a sample of theirs is
 * first written and freed once they fall out of the window (newest − cap,
 * newest]: a ring costs memory for the data it holds, not for its capacity
 * (a sensor that never sends costs nothing, one that stops costs what it
 * last held). Chunk c (samples c·CHUNK .. c·CHUNK + CHUNK − 1) sits in
 * table entry c mod n_chunks, tagged with c; an entry of another tag or
 * none is missing data (NaN). n_chunks covers the window with one to spare,
 * so two chunks of the window never share an entry. */
#define CHUNK 4096

typedef struct chunk {
    int64_t tag;        /* the chunk number held, −1: none */
    double *x;          /* CHUNK samples, NaN = missing; NULL: none */
} chunk;

struct amfi_ring {
    double rate;        /* Hz */
    int64_t origin;     /* µs of sample 0 */
    int started;
    int64_t cap;        /* samples held */
    int64_t newest;     /* index of the newest sample, −1 before any */
    chunk *tab;         /* n_chunks entries */
    int64_t n_chunks;
    int64_t held;       /* chunks allocated now */
    int64_t freed_below; /* every chunk below this number is freed */
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
    r->n_chunks = (r->cap + CHUNK - 1) / CHUNK + 2;
    r->tab = calloc((size_t)r->n_chunks, sizeof *r->tab);
    if (!r->tab) {
        free(r);
        return NULL;
    }
    for (int64_t i = 0; i < r->n_chunks; i++)
        r->tab[i].tag = -1;
    return r;
}

static void drop_all(amfi_ring *r)
{
    for (int64_t i = 0; i < r->n_chunks; i++) {
        free(r->tab[i].x);
        r->tab[i].x = NULL;
        r->tab[i].tag = -1;
    }
    r->held = 0;
    r->freed_below = 0;
}

void amfi_ring_destroy(amfi_ring *r)
{
    if (!r)
        return;
    drop_all(r);
    free(r->tab);
    free(r);
}

int64_t amfi_ring_bytes(const amfi_ring *r)
{
    return r->held * (int64_t)(CHUNK * sizeof(double)) +
           r->n_chunks * (int64_t)sizeof(chunk) + (int64_t)sizeof *r;
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

/* Sample k (>= 0) to read: NULL when its chunk is not held (missing). */
static const double *slot_r(const amfi_ring *r, int64_t k)
{
    const int64_t c = k / CHUNK;
    const chunk *e = &r->tab[c % r->n_chunks];
    return e->tag == c ? &e->x[k % CHUNK] : NULL;
}

/* Sample k (>= 0) to write: its chunk allocated (NaN-filled) if need be,
 * replacing a chunk of the entry that left the window; NULL: out of memory. */
static double *slot_w(amfi_ring *r, int64_t k)
{
    const int64_t c = k / CHUNK;
    chunk *e = &r->tab[c % r->n_chunks];
    if (e->tag != c) {
        if (!e->x) {
            e->x = malloc(sizeof(double) * CHUNK);
            if (!e->x)
                return NULL;
            r->held++;
        }
        for (int i = 0; i < CHUNK; i++)
            e->x[i] = NAN;
        e->tag = c;
    }
    return &e->x[k % CHUNK];
}

/* Free the chunks wholly older than the window (after newest moved on). */
static void trim(amfi_ring *r)
{
    const int64_t below = amfi_ring_oldest(r) / CHUNK; /* chunks < below are out */
    if (below - r->freed_below > r->n_chunks)
        r->freed_below = below - r->n_chunks;
    for (int64_t c = r->freed_below; c < below; c++) {
        chunk *e = &r->tab[c % r->n_chunks];
        if (e->tag >= 0 && e->tag < below) {
            free(e->x);
            e->x = NULL;
            e->tag = -1;
            r->held--;
        }
    }
    if (below > r->freed_below)
        r->freed_below = below;
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
        drop_all(r);
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
            if (k < amfi_ring_oldest(r) || isnan(x[i]))
                continue;
            const double *q = slot_r(r, k);
            if (q && !isnan(*q))
                continue;
            double *p = slot_w(r, k);
            if (!p) {
                *why = "out of memory for the samples";
                r->st.rejected++;
                return AMFI_RING_REJECT;
            }
            *p = x[i];
            fills++;
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
    /* Extends the newest: a gap is what was never written (NaN, or a chunk
     * not held); count it, then store. */
    if (r->newest >= 0 && k0 > r->newest + 1)
        r->st.missing += k0 - r->newest - 1;
    for (int i = 0; i < n; i++) {
        int64_t k = k0 + i;
        if (r->newest >= 0 && k <= r->newest) { /* overlap with what we hold */
            if (k < amfi_ring_oldest(r) || isnan(x[i]))
                continue;
            const double *q = slot_r(r, k);
            if (!q || isnan(*q)) {
                double *p = slot_w(r, k);
                if (!p)
                    goto oom;
                *p = x[i];
                r->st.filled++;
                r->st.missing--;
            }
            continue;
        }
        /* samples that would leave the window at once (a block longer than
         * the ring) are not written */
        if (k <= k1 - r->cap)
            continue;
        double *p = slot_w(r, k);
        if (!p)
            goto oom;
        *p = x[i];
    }
    if (k1 > r->newest)
        r->newest = k1;
    trim(r);
    r->st.blocks++;
    return restarted ? AMFI_RING_RESTART : AMFI_RING_OK;
oom:
    /* what was written stays (newest moves over it: the rest is missing) */
    if (k1 > r->newest)
        r->newest = k1;
    trim(r);
    *why = "out of memory for the samples";
    r->st.rejected++;
    return AMFI_RING_REJECT;
}

int amfi_ring_get(const amfi_ring *r, int64_t k0, int n, double *out)
{
    if (r->newest < 0 || k0 < amfi_ring_oldest(r) || k0 + n - 1 > r->newest || n < 0)
        return -1;
    int missing = 0;
    for (int i = 0; i < n; i++) {
        const double *q = slot_r(r, k0 + i);
        out[i] = q ? *q : NAN;
        missing += isnan(out[i]) != 0;
    }
    return missing;
}
