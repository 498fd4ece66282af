/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * reorder.c: amfid's reorder buffer (reorder.h). A leaf: it calls job_free
 * (pool.c) and nothing else of amfid's.
 */
#include <assert.h>
#include <stdlib.h>

#include "reorder.h"

struct reorder {
    job **slot;      /* cap slots; slot[seq % cap]: the job of seq, or NULL */
    int cap;
    int parked;      /* non-NULL slots */
    int64_t next;    /* the next seq wanted */
};

reorder *reorder_create(int cap, int64_t first_seq)
{
    assert(cap > 0);
    reorder *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->slot = calloc((size_t)cap, sizeof *r->slot);
    if (!r->slot) {
        free(r);
        return NULL;
    }
    r->cap = cap;
    r->next = first_seq;
    return r;
}

void reorder_destroy(reorder *r)
{
    if (!r)
        return;
    for (int i = 0; i < r->cap; i++)
        job_free(r->slot[i]);
    free(r->slot);
    free(r);
}

/* Room for seq: the ring doubled until seq is less than a capacity ahead. */
static int grow(reorder *r, int64_t seq)
{
    int cap = r->cap;
    while (seq - r->next >= cap)
        cap *= 2;
    job **ns = calloc((size_t)cap, sizeof *ns);
    if (!ns)
        return -1;
    for (int i = 0; i < r->cap; i++)
        if (r->slot[i]) {
            assert(ns[r->slot[i]->w.seq % cap] == NULL);
            ns[r->slot[i]->w.seq % cap] = r->slot[i];
        }
    free(r->slot);
    r->slot = ns;
    r->cap = cap;
    return 0;
}

int reorder_park(reorder *r, job *j)
{
    const int64_t seq = j->w.seq;
    assert(seq >= r->next); /* each seq comes once, and none already handed on */
    if (seq - r->next >= r->cap && grow(r, seq))
        return -1;
    job **s = &r->slot[seq % r->cap];
    assert(*s == NULL); /* never overwrite a parked job */
    *s = j;
    r->parked++;
    assert(r->parked <= r->cap);
    return 0;
}

job *reorder_next(reorder *r)
{
    job **s = &r->slot[r->next % r->cap];
    if (!*s)
        return NULL;
    assert((*s)->w.seq == r->next); /* within a capacity of next: only next maps here */
    job *j = *s;
    *s = NULL;
    r->parked--;
    r->next++;
    assert(r->parked >= 0);
    return j;
}

int reorder_parked(const reorder *r) { return r->parked; }
int64_t reorder_next_seq(const reorder *r) { return r->next; }
int reorder_capacity(const reorder *r) { return r->cap; }
