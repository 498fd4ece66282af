/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * level_rule.h: a debounced level alert on the median of a rolling window,
 * the rule behind amfid's model_mismatch, natfreq and speed_drift alerts: each passage
 * gives one figure x (the model's relative residual over the free
 * vibration; the compensated natural frequency's relative drop), the median
 * of the last W figures is compared with two levels.
 *
 *   window    a ring of the last W figures; an evaluation needs it full.
 *   cadence   every push with a full window evaluates (O(W log W)).
 *   raise     after raise_after consecutive evaluations with median >= raise
 *             (median > raise with strict_raise).
 *   clear     after clear_after consecutive evaluations with median < clear
 *             (clear < raise: hysteresis).
 *   absolute  the rule looks at |median| instead: a drift either way (the
 *             speed-drift alert, speed_drift.c: |median c| > T, < T / 2).
 *   alerts    are state changes: one event when raised, one when cleared;
 *             the kind and level are the caller's (create).
 *
 * Why a median: one passage whose free vibration was disturbed (a vehicle
 * on the approach, a gust) moves the mean of the window, not its median;
 * what the rule is for (a model that no longer fits, a lost stiffness)
 * moves every passage's figure. Pure computation: no I/O; the only
 * allocation is in amfi_level_rule_create. One handle, one thread at a time.
 */
#ifndef AMFI_LEVEL_RULE_H
#define AMFI_LEVEL_RULE_H

#include <stddef.h>

#include "indicators.h" /* AMFI_IND_* codes and bits, amfi_alert_event */

#define AMFI_LEVEL_MAX_WINDOW 100000
#define AMFI_LEVEL_MAX_DEBOUNCE 100000

typedef struct amfi_level_params {
    int enabled;     /* 1: evaluate; 0: nothing happens */
    int window;      /* W: figures in the window, 1 .. AMFI_LEVEL_MAX_WINDOW */
    double raise;    /* raise when the median >= raise, finite, > clear */
    double clear;    /* clear when the median < clear, finite */
    int raise_after; /* consecutive evaluations meeting the raise rule, 1 .. 100000 */
    int clear_after; /* consecutive evaluations meeting the clear rule, 1 .. 100000 */
    int absolute;     /* 1: compare |median| with the levels (then clear > 0); 0: the median */
    int strict_raise; /* 1: raise when above raise (>); 0: at or above (>=) */
} amfi_level_params;

/* 0 when *p is valid, else AMFI_IND_EINVAL with *field (may be NULL) the
 * name of the parameter blamed and err (may be NULL) a message naming it. */
int amfi_level_params_check(const amfi_level_params *p, const char **field, char *err,
                            size_t errlen);

/* The parameters as one line of text, "enabled=1 window=25 raise=0.1
 * clear=0.05 raise_after=10 clear_after=25" (doubles with %.17g: read back
 * exactly), into buf: amfid records what its rules ran with in the store
 * (meta alerts.model_fit), the reports draw those thresholds. 0, or
 * AMFI_IND_EINVAL when buf is too small (then "" in it) or an argument NULL. */
int amfi_level_params_format(const amfi_level_params *p, char *buf, size_t len);
/* The line back: every field there once, as written by
 * amfi_level_params_format, and the whole passing amfi_level_params_check.
 * 0 (and *p), or AMFI_IND_EINVAL with err naming the field or the text at
 * fault (*p unchanged). */
int amfi_level_params_parse(const char *s, amfi_level_params *p, char *err, size_t errlen);

typedef struct amfi_level_rule amfi_level_rule;

/* kind and level: static strings put into the events ("model_mismatch",
 * "warning"); what: the figure's name for the messages ("residual ratio").
 * 0 and *out, or AMFI_IND_EINVAL / AMFI_IND_ENOMEM with err. */
int amfi_level_rule_create(const amfi_level_params *p, const char *kind, const char *level,
                           const char *what, amfi_level_rule **out, char *err, size_t errlen);
void amfi_level_rule_destroy(amfi_level_rule *l); /* NULL-safe */

/* Refill the window after a restart (oldest first; non-finite values
 * skipped). No evaluation. Returns the number taken or AMFI_IND_EINVAL. */
int amfi_level_rule_prefill(amfi_level_rule *l, const double *x, int n);
/* Restore the alert state (the store's last event of the kind). */
void amfi_level_rule_set_alerted(amfi_level_rule *l, int raised);
int amfi_level_rule_alerted(const amfi_level_rule *l);

typedef struct amfi_level_eval {
    int n;         /* figures in the window */
    double median; /* their median */
    int streak;    /* consecutive evaluations meeting the rule towards the other state */
} amfi_level_eval;

/* Feed one figure (finite). Returns AMFI_IND_EVAL when the window is full
 * (then *eval), | AMFI_IND_ALERT when the alert was raised or cleared (then
 * *alert); 0 when the figure only entered the window or the rule is off;
 * AMFI_IND_EINVAL for a non-finite x or a NULL handle (nothing changes). */
int amfi_level_rule_push(amfi_level_rule *l, double x, amfi_level_eval *eval,
                         amfi_alert_event *alert);

#endif /* AMFI_LEVEL_RULE_H */
