/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * indicators.c: the damage indicator engine of amfid (see indicators.h for
 * the rules and docs/indicators.md for the defaults and their simulation).
 *
 * State per handle: the ring of the last W GVWs, the baseline (or the
 * running Welford sums of its automatic collection), the evaluation
 * countdown and, per indicator (STD, mean), the alert flag and the two
 * debounce counters. Memory: W doubles plus the struct, allocated once in
 * amfi_indicators_create; push, prefill and the evaluation never allocate.
 *
 * Numerics: the window statistics are recomputed exactly at each
 * evaluation in two passes (mean, then the sum of squared deviations), so
 * there are no running sums to drift; O(W) every K pushes. The baseline is
 * accumulated with Welford's update (Knuth TAOCP vol. 2, §4.2.2), exact to
 * rounding whatever baseline_n. Every GVW is finite, in (0, 1e7] kg, so
 * every sum of squares is finite and the F and t tails are called with
 * finite arguments in their domains (GSL's error handler is never reached
 * by construction: F >= 0, degrees of freedom >= 1).
 */
#include "indicators.h"
#include "ind_internal.h"

#include <gsl/gsl_cdf.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Upper bound on W: 10 million doubles (80 MB) is far beyond any use and
 * keeps W · sizeof(double) and the sums well inside range. */
#define MAX_WINDOW 10000000

/* Debounce and alert state of one indicator (STD or mean). */
typedef struct {
    int alerted;     /* 1 while the alert is raised */
    int raise_count; /* consecutive evaluations meeting the raise rule (not alerted) */
    int clear_count; /* consecutive evaluations meeting the clear rule (alerted) */
} rule_state;

struct amfi_indicators {
    amfi_indicator_params p;

    double *ring;   /* [p.window], the last ring_n GVWs (kg) */
    int ring_n;     /* values in the ring, 0 .. W */
    int ring_head;  /* index the next value is written to */

    int has_baseline;
    double b_mean, b_std; /* kg */
    int b_n;              /* vehicles behind the baseline (F test: b_n − 1 dof) */

    /* Automatic baseline collection (Welford): coll_n values so far. */
    int coll_n;
    double coll_mean, coll_m2;

    /* Eligible pushes (baseline present, window full) to skip before the
     * next evaluation: 0 means the next eligible push evaluates. */
    int countdown;

    rule_state std_rule, mean_rule;
};

static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (err == NULL || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

void amfi_indicator_params_default(amfi_indicator_params *p)
{
    /* docs/indicators.md, "Defaults", has the simulation behind each number. */
    p->window = 500;
    p->every = 100;
    p->baseline_n = 10000;
    p->std_alert_ratio = 1.08;
    p->std_alert_p = 0.01;
    p->std_clear_ratio = 1.00;
    p->raise_after = 6;
    p->clear_after = 6;
    p->mean_shift = 1;
    p->mean_alert_ratio = 1.05;
    p->mean_alert_p = 0.01;
    p->mean_clear_ratio = 1.03;
}

int amfi_indicator_params_equal(const amfi_indicator_params *a, const amfi_indicator_params *b)
{
    return a->window == b->window && a->every == b->every && a->baseline_n == b->baseline_n &&
           a->std_alert_ratio == b->std_alert_ratio && a->std_alert_p == b->std_alert_p &&
           a->std_clear_ratio == b->std_clear_ratio && a->raise_after == b->raise_after &&
           a->clear_after == b->clear_after && a->mean_shift == b->mean_shift &&
           a->mean_alert_ratio == b->mean_alert_ratio && a->mean_alert_p == b->mean_alert_p &&
           a->mean_clear_ratio == b->mean_clear_ratio;
}

/* Name the parameter and write the message; returns AMFI_IND_EINVAL. */
static int bad(const char **field, const char *name, char *err, size_t errlen,
               const char *fmt, ...) __attribute__((format(printf, 5, 6)));

static int bad(const char **field, const char *name, char *err, size_t errlen,
               const char *fmt, ...)
{
    if (field)
        *field = name;
    if (err != NULL && errlen > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return AMFI_IND_EINVAL;
}

/* Written as !(x >= lo) so that NaN fails. */
int amfi_indicator_params_check(const amfi_indicator_params *p, const char **field, char *err,
                                size_t errlen)
{
    if (field)
        *field = NULL;
    if (p == NULL)
        return bad(field, "params", err, errlen, "params is NULL");
    if (p->window < 2 || p->window > MAX_WINDOW)
        return bad(field, "window", err, errlen, "window must be in [2, %d] (got %d)",
                   MAX_WINDOW, p->window);
    if (p->every < 1)
        return bad(field, "every", err, errlen, "every must be >= 1 (got %d)", p->every);
    if (p->baseline_n < 2)
        return bad(field, "baseline_n", err, errlen, "baseline_n must be >= 2 (got %d)",
                   p->baseline_n);
    if (!(p->std_alert_ratio >= 1.0) || !isfinite(p->std_alert_ratio))
        return bad(field, "std_alert_ratio", err, errlen,
                   "std_alert_ratio must be finite and >= 1 (got %g)", p->std_alert_ratio);
    if (!(p->std_alert_p > 0.0 && p->std_alert_p <= 1.0))
        return bad(field, "std_alert_p", err, errlen, "std_alert_p must be in (0, 1] (got %g)",
                   p->std_alert_p);
    if (!(p->std_clear_ratio > 0.0 && p->std_clear_ratio <= p->std_alert_ratio))
        return bad(field, "std_clear_ratio", err, errlen,
                   "std_clear_ratio must be > 0 and must not exceed std_alert_ratio = %g "
                   "(got %g)", p->std_alert_ratio, p->std_clear_ratio);
    if (p->raise_after < 1)
        return bad(field, "raise_after", err, errlen, "raise_after must be >= 1 (got %d)",
                   p->raise_after);
    if (p->clear_after < 1)
        return bad(field, "clear_after", err, errlen, "clear_after must be >= 1 (got %d)",
                   p->clear_after);
    if (p->mean_shift != 0 && p->mean_shift != 1)
        return bad(field, "mean_shift", err, errlen, "mean_shift must be 0 or 1 (got %d)",
                   p->mean_shift);
    if (!(p->mean_alert_ratio >= 1.0) || !isfinite(p->mean_alert_ratio))
        return bad(field, "mean_alert_ratio", err, errlen,
                   "mean_alert_ratio must be finite and >= 1 (got %g)", p->mean_alert_ratio);
    if (!(p->mean_alert_p > 0.0 && p->mean_alert_p <= 1.0))
        return bad(field, "mean_alert_p", err, errlen,
                   "mean_alert_p must be in (0, 1] (got %g)", p->mean_alert_p);
    if (!(p->mean_clear_ratio >= 1.0 && p->mean_clear_ratio <= p->mean_alert_ratio))
        return bad(field, "mean_clear_ratio", err, errlen,
                   "mean_clear_ratio must be >= 1 and must not exceed mean_alert_ratio = %g "
                   "(got %g)", p->mean_alert_ratio, p->mean_clear_ratio);
    return AMFI_IND_OK;
}

/* The fields of the text form, in its order: 1 an int, 0 a double. */
static const ind_field param_fields[] = {
#define PF_I(f) {#f, offsetof(amfi_indicator_params, f), 1}
#define PF_D(f) {#f, offsetof(amfi_indicator_params, f), 0}
    PF_I(window), PF_I(every), PF_I(baseline_n), PF_D(std_alert_ratio), PF_D(std_alert_p),
    PF_D(std_clear_ratio), PF_I(raise_after), PF_I(clear_after), PF_I(mean_shift),
    PF_D(mean_alert_ratio), PF_D(mean_alert_p), PF_D(mean_clear_ratio),
#undef PF_I
#undef PF_D
};
#define N_PARAM_FIELDS (sizeof param_fields / sizeof param_fields[0])

int amfi_indicator_params_format(const amfi_indicator_params *p, char *buf, size_t len)
{
    return ind_record_format(param_fields, N_PARAM_FIELDS, p, buf, len);
}

int amfi_indicator_params_parse(const char *s, amfi_indicator_params *p, char *err,
                                size_t errlen)
{
    amfi_indicator_params q;
    memset(&q, 0, sizeof q);
    if (p == NULL) {
        set_err(err, errlen, "NULL argument");
        return AMFI_IND_EINVAL;
    }
    if (ind_record_parse(param_fields, N_PARAM_FIELDS, s, &q, err, errlen) != AMFI_IND_OK)
        return AMFI_IND_EINVAL;
    int rc = amfi_indicator_params_check(&q, NULL, err, errlen);
    if (rc == AMFI_IND_OK)
        *p = q;
    return rc;
}

int amfi_indicators_create(const amfi_indicator_params *p, amfi_indicators **out, char *err,
                           size_t errlen)
{
    if (out == NULL) {
        set_err(err, errlen, "out is NULL");
        return AMFI_IND_EINVAL;
    }
    *out = NULL;
    if (p == NULL) {
        set_err(err, errlen, "params is NULL");
        return AMFI_IND_EINVAL;
    }
    int rc = amfi_indicator_params_check(p, NULL, err, errlen);
    if (rc != AMFI_IND_OK)
        return rc;
    amfi_indicators *ind = calloc(1, sizeof *ind);
    if (ind == NULL)
        goto nomem;
    ind->p = *p;
    ind->ring = calloc((size_t)p->window, sizeof *ind->ring);
    if (ind->ring == NULL)
        goto nomem;
    *out = ind;
    return AMFI_IND_OK;
nomem:
    amfi_indicators_destroy(ind);
    set_err(err, errlen, "out of memory for a window of %d values", p->window);
    return AMFI_IND_ENOMEM;
}

void amfi_indicators_destroy(amfi_indicators *ind)
{
    if (ind == NULL)
        return;
    free(ind->ring);
    free(ind);
}

static void reset_counters(rule_state *r)
{
    r->raise_count = 0;
    r->clear_count = 0;
}

int amfi_indicators_set_baseline(amfi_indicators *ind, double mean_kg, double std_kg, int n)
{
    if (!(mean_kg > 0.0) || !isfinite(mean_kg) || !(std_kg > 0.0) || !isfinite(std_kg) ||
        n < 2)
        return AMFI_IND_EINVAL;
    ind->has_baseline = 1;
    ind->b_mean = mean_kg;
    ind->b_std = std_kg;
    ind->b_n = n;
    ind->coll_n = 0;
    ind->coll_mean = ind->coll_m2 = 0.0;
    ind->countdown = 0;
    reset_counters(&ind->std_rule);
    reset_counters(&ind->mean_rule);
    return AMFI_IND_OK;
}

int amfi_indicators_has_baseline(const amfi_indicators *ind)
{
    return ind->has_baseline;
}

static int valid_gvw(double gvw_kg)
{
    return gvw_kg > 0.0 && gvw_kg <= AMFI_IND_MAX_GVW_KG; /* false for NaN */
}

static void ring_put(amfi_indicators *ind, double gvw_kg)
{
    ind->ring[ind->ring_head] = gvw_kg;
    ind->ring_head = ind->ring_head + 1 == ind->p.window ? 0 : ind->ring_head + 1;
    if (ind->ring_n < ind->p.window)
        ind->ring_n++;
}

int amfi_indicators_prefill(amfi_indicators *ind, const double *gvw_kg, int n)
{
    if (n < 0 || (gvw_kg == NULL && n > 0))
        return AMFI_IND_EINVAL;
    int taken = 0;
    for (int i = 0; i < n; i++) {
        if (!valid_gvw(gvw_kg[i]))
            continue;
        ring_put(ind, gvw_kg[i]);
        taken++;
    }
    ind->countdown = 0;
    return taken;
}

void amfi_indicators_set_alerted(amfi_indicators *ind, int std_alert, int mean_alert)
{
    ind->std_rule.alerted = std_alert != 0;
    ind->mean_rule.alerted = mean_alert != 0;
    reset_counters(&ind->std_rule);
    reset_counters(&ind->mean_rule);
}

const char *amfi_indicators_state(const amfi_indicators *ind)
{
    if (!ind->has_baseline)
        return "baseline";
    if (ind->std_rule.alerted)
        return "alert";
    return ind->std_rule.raise_count > 0 ? "watch" : "normal";
}

/* One debounced hysteresis step: raise_ok / clear_ok are this evaluation's
 * rules. Returns +1 when the alert is raised now, −1 when cleared, else 0. */
static int rule_step(rule_state *r, int raise_ok, int clear_ok, int raise_after,
                     int clear_after)
{
    if (!r->alerted) {
        r->clear_count = 0;
        r->raise_count = raise_ok ? r->raise_count + 1 : 0;
        if (r->raise_count >= raise_after) {
            r->alerted = 1;
            r->raise_count = 0;
            return 1;
        }
    } else {
        r->raise_count = 0;
        r->clear_count = clear_ok ? r->clear_count + 1 : 0;
        if (r->clear_count >= clear_after) {
            r->alerted = 0;
            r->clear_count = 0;
            return -1;
        }
    }
    return 0;
}

/* Mean and sample STD (n − 1) of the ring, two passes. The ring is full. */
static void window_stats(const amfi_indicators *ind, double *mean, double *std)
{
    const int n = ind->ring_n;
    double s = 0.0;
    for (int i = 0; i < n; i++)
        s += ind->ring[i];
    const double m = s / n;
    double ss = 0.0, c = 0.0;
    for (int i = 0; i < n; i++) {
        const double d = ind->ring[i] - m;
        ss += d * d;
        c += d;
    }
    /* Corrected two-pass (Chan, Golub & LeVeque 1983): c is ~0 but removes
     * the rounding error of m. */
    ss -= c * c / n;
    *mean = m;
    *std = sqrt(ss > 0.0 ? ss / (n - 1) : 0.0);
}

static void evaluate(const amfi_indicators *ind, amfi_indicator_eval *e)
{
    const int w = ind->ring_n;
    double m, s;
    window_stats(ind, &m, &s);
    e->n = w;
    e->mean_kg = m;
    e->std_kg = s;
    e->baseline_mean_kg = ind->b_mean;
    e->baseline_std_kg = ind->b_std;
    e->std_ratio = s / ind->b_std;
    /* One-sided variance-ratio test: H0 window variance = baseline
     * variance, H1 greater. */
    const double f = e->std_ratio * e->std_ratio;
    e->p_value = gsl_cdf_fdist_Q(f, (double)(w - 1), (double)(ind->b_n - 1));
    /* Welch's t-test, two-sided, Welch–Satterthwaite degrees of freedom. */
    e->mean_ratio = m / ind->b_mean;
    const double a = s * s / w, b = ind->b_std * ind->b_std / ind->b_n; /* b > 0 */
    const double t = (m - ind->b_mean) / sqrt(a + b);
    const double nu = (a + b) * (a + b) / (a * a / (w - 1) + b * b / (ind->b_n - 1));
    const double pm = 2.0 * gsl_cdf_tdist_Q(fabs(t), nu);
    e->mean_p = pm > 1.0 ? 1.0 : pm;
}

static void fill_event(amfi_alert_event *ev, const char *level, const char *kind, int raised)
{
    ev->level = level;
    ev->kind = kind;
    ev->raised = raised;
    ev->message[0] = '\0';
}

int amfi_indicators_push(amfi_indicators *ind, double gvw_kg, amfi_indicator_eval *eval,
                         amfi_alert_event alerts[2], int *n_alerts)
{
    if (n_alerts != NULL)
        *n_alerts = 0;
    if (!valid_gvw(gvw_kg))
        return AMFI_IND_EINVAL;
    ring_put(ind, gvw_kg);

    if (!ind->has_baseline) {
        /* Welford's update. */
        ind->coll_n++;
        const double d = gvw_kg - ind->coll_mean;
        ind->coll_mean += d / ind->coll_n;
        ind->coll_m2 += d * (gvw_kg - ind->coll_mean);
        if (ind->coll_n < ind->p.baseline_n)
            return 0;
        const int n = ind->coll_n;
        const double mean = ind->coll_mean;
        const double std = sqrt(ind->coll_m2 > 0.0 ? ind->coll_m2 / (n - 1) : 0.0);
        if (amfi_indicators_set_baseline(ind, mean, std, n) != AMFI_IND_OK) {
            /* All baseline_n values equal (STD 0): no usable spread; collect
             * again rather than divide by zero. */
            ind->coll_n = 0;
            ind->coll_mean = ind->coll_m2 = 0.0;
            return 0;
        }
        if (eval != NULL) {
            eval->n = n;
            eval->mean_kg = eval->baseline_mean_kg = mean;
            eval->std_kg = eval->baseline_std_kg = std;
            eval->std_ratio = eval->mean_ratio = 1.0;
            eval->p_value = eval->mean_p = 1.0;
            eval->state = "baseline";
        }
        return AMFI_IND_BASELINE;
    }

    if (ind->ring_n < ind->p.window)
        return 0;
    if (ind->countdown > 0) {
        ind->countdown--;
        return 0;
    }
    ind->countdown = ind->p.every - 1;

    amfi_indicator_eval e;
    evaluate(ind, &e);
    const amfi_indicator_params *p = &ind->p;
    amfi_alert_event ev[2];
    int nev = 0;

    const int std_raise = e.std_ratio >= p->std_alert_ratio && e.p_value <= p->std_alert_p;
    const int std_clear = e.std_ratio < p->std_clear_ratio;
    const int sc = rule_step(&ind->std_rule, std_raise, std_clear, p->raise_after,
                             p->clear_after);
    if (sc != 0) {
        amfi_alert_event *a = &ev[nev++];
        fill_event(a, "warning", "std_increase", sc > 0);
        if (sc > 0)
            snprintf(a->message, sizeof a->message,
                     "STD of inferred GVW over the last %d vehicles %.3f t is %.3f x the "
                     "baseline %.3f t (F test p = %.2g, %d evaluations in a row): possible "
                     "loss of bridge stiffness",
                     e.n, e.std_kg / 1000.0, e.std_ratio, e.baseline_std_kg / 1000.0,
                     e.p_value, p->raise_after);
        else
            snprintf(a->message, sizeof a->message,
                     "STD of inferred GVW over the last %d vehicles %.3f t is back to %.3f x "
                     "the baseline %.3f t (below %.3f, %d evaluations in a row)",
                     e.n, e.std_kg / 1000.0, e.std_ratio, e.baseline_std_kg / 1000.0,
                     p->std_clear_ratio, p->clear_after);
    }

    if (p->mean_shift) {
        const double r = e.mean_ratio;
        const int mean_raise = (r >= p->mean_alert_ratio || r <= 1.0 / p->mean_alert_ratio) &&
                               e.mean_p <= p->mean_alert_p;
        const int mean_clear = r < p->mean_clear_ratio && r > 1.0 / p->mean_clear_ratio;
        const int mc = rule_step(&ind->mean_rule, mean_raise, mean_clear, p->raise_after,
                                 p->clear_after);
        if (mc != 0) {
            amfi_alert_event *a = &ev[nev++];
            fill_event(a, "info", "mean_shift", mc > 0);
            if (mc > 0)
                snprintf(a->message, sizeof a->message,
                         "mean of inferred GVW over the last %d vehicles %.3f t is %.3f x "
                         "the baseline %.3f t (Welch p = %.2g, %d evaluations in a row); "
                         "the mean also moves with the traffic mix",
                         e.n, e.mean_kg / 1000.0, e.mean_ratio,
                         e.baseline_mean_kg / 1000.0, e.mean_p, p->raise_after);
            else
                snprintf(a->message, sizeof a->message,
                         "mean of inferred GVW over the last %d vehicles %.3f t is back to "
                         "%.3f x the baseline %.3f t (inside 1/%.3f .. %.3f, %d evaluations "
                         "in a row)",
                         e.n, e.mean_kg / 1000.0, e.mean_ratio,
                         e.baseline_mean_kg / 1000.0, p->mean_clear_ratio,
                         p->mean_clear_ratio, p->clear_after);
        }
    }

    e.state = amfi_indicators_state(ind);
    if (eval != NULL)
        *eval = e;
    int mask = AMFI_IND_EVAL;
    if (nev > 0) {
        mask |= AMFI_IND_ALERT;
        if (alerts != NULL)
            for (int i = 0; i < nev; i++)
                alerts[i] = ev[i];
        if (n_alerts != NULL)
            *n_alerts = nev;
    }
    return mask;
}
