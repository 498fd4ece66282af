/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * reorder.h: amfid's reorder buffer: finished passages come back from the
 * solver threads in any order; each is parked under its release number
 * (amfi_window.seq, from the tracker: 1, 2, 3, ... each once) and handed on
 * only in that order, every consecutive one as soon as it is there.
 *
 * A ring of slots indexed by seq modulo its capacity, which doubles when a
 * seq lands a capacity or more ahead of the next one wanted (the solvers
 * far behind while windows that bypass them keep coming): a passage is
 * never dropped for want of room. Invariants (assert()): a slot is empty
 * before a job is parked in it; a parked job's seq is at least the next one
 * wanted (each seq comes once); a job handed on is the next one wanted.
 *
 * Thread: one (amfid's main thread). Depends on pool.h's job only.
 */
#ifndef AMFID_REORDER_H
#define AMFID_REORDER_H

#include <stdint.h>

#include "pool.h"

typedef struct reorder reorder;

/* cap slots (> 0), the first seq wanted: first_seq. NULL: out of memory. */
reorder *reorder_create(int cap, int64_t first_seq);
/* Frees the buffer and every job still parked (job_free); NULL-safe. */
void reorder_destroy(reorder *r);
/* Park j under j->w.seq (>= the next seq wanted, not parked before): 0, or
 * −1 when the ring had to grow and memory ran out (j not taken). */
int reorder_park(reorder *r, job *j);
/* The job of the next seq wanted, taken out (the next one is then wanted),
 * or NULL when it has not come back yet. */
job *reorder_next(reorder *r);
/* Jobs parked now; the next seq wanted; slots. */
int reorder_parked(const reorder *r);
int64_t reorder_next_seq(const reorder *r);
int reorder_capacity(const reorder *r);

#endif /* AMFID_REORDER_H */
