/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * level_rule.c: the debounced median level alert (level_rule.h). Pure
 * computation; the caller's thread.
 */
#include "level_rule.h"

#include "ind_internal.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct amfi_level_rule {
    amfi_level_params p;
    const char *kind, *level, *what;
    double *ring, *scratch; /* W each */
    int head, n;
    int alerted, streak;
};

int amfi_level_params_check(const amfi_level_params *p, const char **field, char *err,
                            size_t errlen)
{
    if (field)
        *field = NULL;
    if (!p)
        IND_BLAME(NULL, "no parameters");
    if (p->enabled != 0 && p->enabled != 1)
        IND_BLAME("enabled", "enabled must be on or off (1 or 0), got %d", p->enabled);
    if (p->window < 1 || p->window > AMFI_LEVEL_MAX_WINDOW)
        IND_BLAME("window", "window must be 1 .. %d passages, got %d", AMFI_LEVEL_MAX_WINDOW,
              p->window);
    if (!isfinite(p->raise))
        IND_BLAME("raise", "the raise level must be finite");
    if (!isfinite(p->clear) || !(p->clear < p->raise))
        IND_BLAME("clear", "the clear level (%g) must be below the raise level (%g)", p->clear,
              p->raise);
    if (p->absolute != 0 && p->absolute != 1)
        IND_BLAME("absolute", "absolute must be 1 or 0, got %d", p->absolute);
    if (p->absolute && !(p->clear > 0))
        IND_BLAME("clear", "the clear level (%g) of a rule on |median| must be above 0", p->clear);
    if (p->strict_raise != 0 && p->strict_raise != 1)
        IND_BLAME("strict_raise", "strict_raise must be 1 or 0, got %d", p->strict_raise);
    if (p->raise_after < 1 || p->raise_after > AMFI_LEVEL_MAX_DEBOUNCE)
        IND_BLAME("raise_after", "raise_after must be 1 .. %d, got %d", AMFI_LEVEL_MAX_DEBOUNCE,
              p->raise_after);
    if (p->clear_after < 1 || p->clear_after > AMFI_LEVEL_MAX_DEBOUNCE)
        IND_BLAME("clear_after", "clear_after must be 1 .. %d, got %d", AMFI_LEVEL_MAX_DEBOUNCE,
              p->clear_after);
    return AMFI_IND_OK;
}

/* The fields of the text form, in its order: 1 an int, 0 a double. */
static const ind_field level_fields[] = {
#define LF_I(f) {#f, offsetof(amfi_level_params, f), 1}
#define LF_D(f) {#f, offsetof(amfi_level_params, f), 0}
    LF_I(enabled), LF_I(window), LF_D(raise), LF_D(clear), LF_I(raise_after), LF_I(clear_after),
#undef LF_I
#undef LF_D
};
#define N_LEVEL_FIELDS (sizeof level_fields / sizeof level_fields[0])

int amfi_level_params_format(const amfi_level_params *p, char *buf, size_t len)
{
    return ind_record_format(level_fields, N_LEVEL_FIELDS, p, buf, len);
}

int amfi_level_params_parse(const char *s, amfi_level_params *p, char *err, size_t errlen)
{
    amfi_level_params q;
    memset(&q, 0, sizeof q);
    if (!p) {
        if (err && errlen)
            snprintf(err, errlen, "NULL argument");
        return AMFI_IND_EINVAL;
    }
    if (ind_record_parse(level_fields, N_LEVEL_FIELDS, s, &q, err, errlen) != AMFI_IND_OK)
        return AMFI_IND_EINVAL;
    if (amfi_level_params_check(&q, NULL, err, errlen) != AMFI_IND_OK)
        return AMFI_IND_EINVAL;
    *p = q;
    return AMFI_IND_OK;
}

int amfi_level_rule_create(const amfi_level_params *p, const char *kind, const char *level,
                           const char *what, amfi_level_rule **out, char *err, size_t errlen)
{
    char why[192];
    if (out)
        *out = NULL;
    if (!out || !kind || !level || !what) {
        if (err && errlen)
            snprintf(err, errlen, "level rule: no output, kind, level or name");
        return AMFI_IND_EINVAL;
    }
    if (amfi_level_params_check(p, NULL, why, sizeof why) != 0) {
        if (err && errlen)
            snprintf(err, errlen, "%s: %s", kind, why);
        return AMFI_IND_EINVAL;
    }
    amfi_level_rule *l = calloc(1, sizeof *l);
    if (l) {
        l->ring = malloc(sizeof(double) * (size_t)p->window);
        l->scratch = malloc(sizeof(double) * (size_t)p->window);
    }
    if (!l || !l->ring || !l->scratch) {
        amfi_level_rule_destroy(l);
        if (err && errlen)
            snprintf(err, errlen, "%s: out of memory for a window of %d", kind, p->window);
        return AMFI_IND_ENOMEM;
    }
    l->p = *p;
    l->kind = kind;
    l->level = level;
    l->what = what;
    *out = l;
    return AMFI_IND_OK;
}

void amfi_level_rule_destroy(amfi_level_rule *l)
{
    if (!l)
        return;
    free(l->ring);
    free(l->scratch);
    free(l);
}

static void enter(amfi_level_rule *l, double x)
{
    l->ring[l->head] = x;
    l->head = (l->head + 1) % l->p.window;
    if (l->n < l->p.window)
        l->n++;
}

int amfi_level_rule_prefill(amfi_level_rule *l, const double *x, int n)
{
    if (!l || n < 0 || (n > 0 && !x))
        return AMFI_IND_EINVAL;
    int taken = 0;
    for (int k = 0; k < n; k++)
        if (isfinite(x[k])) {
            enter(l, x[k]);
            taken++;
        }
    return taken;
}

void amfi_level_rule_set_alerted(amfi_level_rule *l, int raised)
{
    if (l) {
        l->alerted = raised != 0;
        l->streak = 0;
    }
}

int amfi_level_rule_alerted(const amfi_level_rule *l) { return l ? l->alerted : 0; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(amfi_level_rule *l)
{
    const int n = l->n;
    memcpy(l->scratch, l->ring, sizeof(double) * (size_t)n);
    qsort(l->scratch, (size_t)n, sizeof(double), cmp_double);
    return n % 2 ? l->scratch[n / 2] : 0.5 * (l->scratch[n / 2 - 1] + l->scratch[n / 2]);
}

int amfi_level_rule_push(amfi_level_rule *l, double x, amfi_level_eval *eval,
                         amfi_alert_event *alert)
{
    if (!l || !isfinite(x))
        return AMFI_IND_EINVAL;
    if (!l->p.enabled)
        return 0;
    enter(l, x);
    if (l->n < l->p.window)
        return 0;
    const double m = median(l), v = l->p.absolute ? fabs(m) : m;
    const int meets = l->alerted          ? v < l->p.clear
                      : l->p.strict_raise ? v > l->p.raise
                                          : v >= l->p.raise;
    l->streak = meets ? l->streak + 1 : 0;
    const int change = l->streak >= (l->alerted ? l->p.clear_after : l->p.raise_after);
    if (eval) {
        eval->n = l->n;
        eval->median = m;
        eval->streak = l->streak;
    }
    if (!change)
        return AMFI_IND_EVAL;
    l->alerted = !l->alerted;
    l->streak = 0;
    if (alert) {
        memset(alert, 0, sizeof *alert);
        alert->level = l->level;
        alert->kind = l->kind;
        alert->raised = l->alerted;
        const char *pm = l->p.absolute ? "+/-" : "";
        if (l->alerted)
            snprintf(alert->message, sizeof alert->message,
                     "median %s %.4g over the last %d passages, %s %s%.4g for %d "
                     "evaluations in a row",
                     l->what, m, l->n,
                     l->p.absolute ? (l->p.strict_raise ? "beyond" : "at or beyond")
                                   : (l->p.strict_raise ? "above" : "at or above"),
                     pm, l->p.raise, l->p.raise_after);
        else
            snprintf(alert->message, sizeof alert->message,
                     "median %s %.4g over the last %d passages, %s %s%.4g for %d evaluations "
                     "in a row",
                     l->what, m, l->n, l->p.absolute ? "within" : "below", pm, l->p.clear,
                     l->p.clear_after);
    }
    return AMFI_IND_EVAL | AMFI_IND_ALERT;
}
