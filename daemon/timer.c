/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * timer.c: amfid's timers (ctx.h): a short list of periodic callbacks the
 * modules register (heartbeat, refusal summaries, the metrics file, the
 * intake record, ...), run by the loop after each turn, in the order added.
 * A leaf: it calls only the callbacks it is given.
 *
 * Thread: the main thread only.
 */
#include <stdlib.h>

#include "ctx.h"

struct timers {
    struct timer {
        const double *period_s; /* read at each check: a live key follows a reload
                                   at once (a shorter period is not held back by
                                   a due time computed with the old one) */
        timer_fn fn;
        double last;            /* amfi_mono_s() of the last run that succeeded */
        int ran;                /* 0: due at once */
    } t[TIMERS_MAX];
    int n;
};

timers *timers_create(void)
{
    return calloc(1, sizeof(timers));
}

void timers_destroy(timers *t)
{
    free(t);
}

int timer_add(timers *t, const double *period_s, timer_fn fn)
{
    if (!t || t->n >= TIMERS_MAX || !period_s || !fn)
        return -1;
    t->t[t->n++] = (struct timer){period_s, fn, 0.0, 0};
    return 0;
}

void timers_run(timers *t, amfid_ctx *c, double now)
{
    for (int i = 0; t && i < t->n; i++) {
        struct timer *k = &t->t[i];
        if ((!k->ran || now >= k->last + *k->period_s) && k->fn(c) == 0) {
            k->last = now;
            k->ran = 1;
        }
    }
}
