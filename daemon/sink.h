/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sink.h: amfid's store sink: passages handed on in order are written
 * (ops->write: the store, then what follows a stored passage); when the
 * store cannot write (disk full, I/O error, read-only, locked) the passage
 * is held, in order, behind any already held, and retried with a backoff
 * (first_wait_s doubling to max_wait_s); the sink is then degraded
 * (ops->degraded(1): the store_degraded alert) until the held queue has
 * drained (ops->degraded(0)). The held queue is bounded in bytes
 * (daemon.store.held_max_bytes; a held passage keeps only its row's data,
 * sizeof(job), its samples freed): what overflows it is counted (lost,
 * overflow) and each such vehicle logged with its id and time. Nothing
 * acknowledged is lost: a passage is acknowledged when write returned 0.
 *
 * Invariants (assert()): the held bytes are the held passages' bytes and
 * never above the bound; held passages leave in the order they came.
 *
 * Thread: one (amfid's main thread). Calls job_free (pool.c), the log and
 * its ops; nothing else of amfid's.
 */
#ifndef AMFID_SINK_H
#define AMFID_SINK_H

#include <stddef.h>
#include <stdint.h>

#include "pool.h"

typedef struct sink sink;

typedef struct sink_ops {
    /* Write j: 0 (stored and acknowledged; the sink then frees j), or −1
     * (the store refused; j is the sink's to hold, unchanged). */
    int (*write)(void *arg, job *j);
    /* The sink became degraded (1: the first passage held) or is not any
     * more (0: every held passage stored). */
    void (*degraded)(void *arg, int on);
    void *arg;
    /* Why the store refuses (the last error), for the log at shutdown. */
    const char *last_error;
} sink_ops;

typedef struct sink_params {
    size_t max_bytes;     /* held queue bound, bytes (>= sizeof(job)) */
    double first_wait_s;  /* first retry this long after the first hold */
    double max_wait_s;    /* the backoff doubles up to this */
} sink_params;

typedef struct sink_stats {
    int held, peak;             /* passages held now, at most since start */
    size_t bytes, peak_bytes;   /* their bytes */
    int64_t lost;               /* passages not stored: overflow, shutdown, sink_lost */
    int64_t overflow;           /* of which the held queue was full */
    int degraded;
} sink_stats;

/* NULL: out of memory or a bound below one passage. */
sink *sink_create(const sink_params *p, const sink_ops *ops);
/* Frees every passage still held (only left on an early error); NULL-safe. */
void sink_destroy(sink *s);
/* Store j in order: behind the held passages (held), or now (written, or
 * held when the store refuses). Takes j. 0 stored now, −1 held or lost. */
int sink_put(sink *s, job *j);
/* Retry the held passages when their time has come (from the loop, final
 * 0); with final > 0 (stopping) keep trying for up to final seconds, then
 * count and log every passage still held as not stored. */
void sink_retry(sink *s, double final);
/* Count n passages lost before they reached the sink (out of memory). */
void sink_lost(sink *s, int64_t n);
void sink_stats_of(const sink *s, sink_stats *st);
/* The bound in passages (held_max_bytes / a held passage's bytes). */
int sink_capacity(const sink *s);

#endif /* AMFID_SINK_H */
