/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ring.h: one sensor's recent samples, indexed by absolute sample number.
 *
 * Sample k is at utime origin + k·1e6/rate µs; the rate is given at
 * creation, the first block fixes the origin. Blocks normally arrive in order; a block that starts after the
 * newest sample leaves a gap (its samples are missing, NaN, and counted); a
 * block that starts earlier fills missing samples (out-of-order arrival) or
 * is a duplicate (counted, ignored); a block older than the ring holds is
 * late (counted, dropped). The capacity is fixed at creation, the memory
 * is not: samples are kept in chunks allocated as data arrive and freed
 * once they leave the window (a ring of an hour at a high rate costs
 * nothing until data come, and what it holds after). The rate is the
 * sensor's configured one (sensors[].rate_hz): a block at another rate is
 * refused, never adopted. Not thread-safe: the bus thread owns it.
 *
 * Time that jumps (docs/daemon.md, "Time that jumps"): a block that starts
 * more than AMFI_RING_FAR_S (or the ring's length, if longer) after the
 * newest sample, or ends that much before the oldest one, is not adopted
 * (nearer ones are a gap or late, as above): it is quarantined
 * (counted, its samples dropped). Only when AMFI_RING_CONFIRM blocks in a
 * row continue each other on the new time line (each starting where the
 * previous one ended, within a quarter sample) with no block of the current
 * stream in between, the jump is taken as real (an outage that ended, a
 * clock that was reset, a poisoned first block): the ring restarts at the
 * confirming block, every sample before it is gone, and restart_utime says
 * when. One wrong timestamp therefore never moves the stream's time.
 */
#ifndef AMFI_RING_H
#define AMFI_RING_H

#include <stdint.h>

typedef struct amfi_ring_stats {
    int64_t blocks;          /* accepted */
    int64_t duplicates;      /* every sample already present */
    int64_t late;            /* older than the ring */
    int64_t filled;          /* samples that filled an earlier gap */
    int64_t missing;         /* samples skipped by gaps (net of later fills) */
    int64_t rejected;        /* inconsistent rate or time */
    int64_t quarantined;     /* blocks far from the stream, not adopted */
    int64_t restarts;        /* jumps confirmed: the ring started over */
    int64_t restart_utime;   /* µs of the first sample after the last restart */
    double last_jump_s;      /* the last confirmed jump, s (+ forward, − back) */
} amfi_ring_stats;

#define AMFI_RING_CONFIRM 3    /* blocks in a row that confirm a jump */
#define AMFI_RING_FAR_S 600.0 /* s from the stream beyond which a block is a jump */

typedef struct amfi_ring amfi_ring;

/* rate_hz > 0; capacity in seconds of samples. Free with amfi_ring_destroy. */
amfi_ring *amfi_ring_create(double rate_hz, double seconds);
void amfi_ring_destroy(amfi_ring *r); /* NULL-safe */

enum { AMFI_RING_OK = 0, AMFI_RING_DUP = 1, AMFI_RING_LATE = 2, AMFI_RING_QUARANTINE = 3,
       AMFI_RING_RESTART = 4, AMFI_RING_REJECT = -1 };

/* Put n samples (m/s²) starting at utime (µs) with sample rate rate_hz.
 * Returns AMFI_RING_OK (stored, possibly filling a gap), _DUP, _LATE,
 * _QUARANTINE (far from the stream, not adopted: see above), _RESTART (a
 * jump confirmed: the ring started over at this block, which is stored), or
 * _REJECT (rate differs from the ring's by more than 1e-6, or a start that
 * is not on the sample grid within a quarter sample); `why` then says which. */
int amfi_ring_put(amfi_ring *r, int64_t utime, double rate_hz, int n, const double *x,
                  const char **why);

double amfi_ring_rate(const amfi_ring *r);
int64_t amfi_ring_bytes(const amfi_ring *r);   /* memory held now (samples, table) */
int amfi_ring_started(const amfi_ring *r);      /* 1 once a block was stored */
int64_t amfi_ring_newest(const amfi_ring *r);   /* newest sample index, −1 if none */
int64_t amfi_ring_oldest(const amfi_ring *r);   /* oldest index still held */
int64_t amfi_ring_index(const amfi_ring *r, int64_t utime); /* nearest sample index */
double amfi_ring_utime(const amfi_ring *r, int64_t k);      /* µs of sample k */

/* Copy samples k0 .. k0 + n − 1 into out. Returns the number of missing
 * (NaN) samples among them, or −1 when part of the range is not held
 * (older than the ring or newer than the newest sample). */
int amfi_ring_get(const amfi_ring *r, int64_t k0, int n, double *out);

const amfi_ring_stats *amfi_ring_stats_of(const amfi_ring *r);
/* 1 while quarantined blocks could still confirm a jump (a decision about a
 * passage whose data is not in the ring should wait). */
int amfi_ring_jump_pending(const amfi_ring *r);

#endif
