/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * scale.c: the scale indicator (scale.h): the baseline's empty/loaded
 * classes, the temperature model, the robust block estimator and its CUSUM.
 * Pure computation; the handle is owned by one thread at a time.
 */
#include "scale.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cusum.h"
#include "ind_internal.h"

#define BOOT_N 100 /* bootstrap blocks for sigma_boot */

struct amfi_scale {
    amfi_scale_params p;
    int n_base;             /* baseline_blocks · block */
    double *bx, *bt, *bw;   /* baseline GVW, temperature, compensated GVW */
    double *bs;             /* scratch of the baseline's size (sorted copies) */
    amfi_scale_ref ref;     /* the baseline's classes */
    int nb;                 /* baseline values collected */
    int have_model;
    amfi_scale_model m;
    double *xr, *xw;        /* current block: raw and compensated GVW */
    int nx;
    double t_sum;
    amfi_cusum cusum;
};

void amfi_scale_params_default(amfi_scale_params *p)
{
    memset(p, 0, sizeof *p);
    p->block = 500;
    p->baseline_blocks = 40;
    p->knee_c = 0.0;
    p->ref_c = 10.0;
    p->class_split_kg = 8765.0;
    p->share_range = 0.15;
    p->floor_c = -10.0;
    p->warm_slope = 0.0025;
    p->frost_slope = 0.018;
    p->slope_prior_sd = 0.001;
    p->design_shift = 0.025;
    p->false_alarms_per_year = 0.05; /* measured: about 0.25 a year (docs/indicators.md) */
    p->vehicles_per_day = 2000.0;
    p->clear_after = 4;
}

static int bad(const char *name, const char **field, char *err, size_t errlen, const char *why)
{
    return ind_bad("scale indicator", name, field, err, errlen, why);
}

int amfi_scale_params_check(const amfi_scale_params *p, const char **field, char *err,
                            size_t errlen)
{
    if (field)
        *field = NULL;
    if (p->block < 50 || p->block > 1000000)
        return bad("block", field, err, errlen, "must be in [50, 1000000]");
    if (p->baseline_blocks < 4 || p->baseline_blocks > 10000 ||
        (double)p->baseline_blocks * p->block > 1e8)
        return bad("baseline_blocks", field, err, errlen,
                   "must be in [4, 10000] with block · baseline_blocks <= 1e8");
    if (!ind_in(p->knee_c, -30, 30))
        return bad("knee_c", field, err, errlen, "must be in [-30, 30] °C");
    if (!ind_in(p->ref_c, -30, 40))
        return bad("ref_c", field, err, errlen, "must be in [-30, 40] °C");
    if (!ind_in(p->class_split_kg, 100, AMFI_IND_MAX_GVW_KG))
        return bad("class_split_kg", field, err, errlen, "must be in [100, 1e7] kg");
    if (!ind_in(p->share_range, 0.01, 1))
        return bad("share_range", field, err, errlen, "must be in [0.01, 1]");
    if (!ind_in(p->floor_c, -60, p->knee_c - 0.5))
        return bad("floor_c", field, err, errlen, "must be in [-60, knee_c - 0.5] °C");
    if (!ind_in(p->warm_slope, -0.1, 0.1))
        return bad("warm_slope", field, err, errlen, "must be in [-0.1, 0.1] per °C");
    if (!ind_in(p->frost_slope, -0.1, 0.1))
        return bad("frost_slope", field, err, errlen, "must be in [-0.1, 0.1] per °C");
    if (!ind_in(p->slope_prior_sd, 0, 0.1))
        return bad("slope_prior_sd", field, err, errlen, "must be in [0, 0.1] per °C");
    if (!ind_in(p->design_shift, 1e-4, 0.5) || p->design_shift >= 0.5)
        return bad("design_shift", field, err, errlen, "must be in [0.0001, 0.5)");
    if (!ind_in(p->false_alarms_per_year, 1e-4, 1000))
        return bad("false_alarms_per_year", field, err, errlen, "must be in [0.0001, 1000]");
    if (!ind_in(p->vehicles_per_day, 1, 1e7))
        return bad("vehicles_per_day", field, err, errlen, "must be in [1, 1e7]");
    if (p->clear_after < 1 || p->clear_after > 1000000)
        return bad("clear_after", field, err, errlen, "must be in [1, 1000000]");
    return AMFI_IND_OK;
}

int amfi_scale_create(const amfi_scale_params *p, amfi_scale **out, char *err, size_t errlen)
{
    if (!out || !p) {
        if (err && errlen)
            snprintf(err, errlen, "scale indicator: %s is NULL", !out ? "out" : "params");
        if (out)
            *out = NULL;
        return AMFI_IND_EINVAL;
    }
    *out = NULL;
    int rc = amfi_scale_params_check(p, NULL, err, errlen);
    if (rc)
        return rc;
    amfi_scale *s = calloc(1, sizeof *s);
    if (!s)
        goto nomem;
    s->p = *p;
    s->n_base = p->baseline_blocks * p->block;
    s->bx = malloc(sizeof(double) * (size_t)s->n_base);
    s->bt = malloc(sizeof(double) * (size_t)s->n_base);
    s->bw = malloc(sizeof(double) * (size_t)s->n_base);
    s->bs = malloc(sizeof(double) * (size_t)s->n_base);
    s->xr = malloc(sizeof(double) * (size_t)p->block);
    s->xw = malloc(sizeof(double) * (size_t)p->block);
    if (!s->bx || !s->bt || !s->bw || !s->bs || !s->xr || !s->xw)
        goto nomem;
    *out = s;
    return AMFI_IND_OK;
nomem:
    amfi_scale_destroy(s);
    if (err && errlen)
        snprintf(err, errlen, "scale indicator: out of memory (block %d, %d blocks)", p->block,
                 p->baseline_blocks);
    return AMFI_IND_ENOMEM;
}

void amfi_scale_destroy(amfi_scale *s)
{
    if (!s)
        return;
    free(s->bx);
    free(s->bt);
    free(s->bw);
    free(s->bs);
    free(s->xr);
    free(s->xw);
    free(s);
}

int amfi_scale_has_baseline(const amfi_scale *s)
{
    return s->have_model;
}

int amfi_scale_get_model(const amfi_scale *s, amfi_scale_model *m)
{
    if (!s->have_model)
        return AMFI_IND_EINVAL;
    *m = s->m;
    return AMFI_IND_OK;
}

void amfi_scale_set_alerted(amfi_scale *s, int alerted)
{
    amfi_cusum_set_alerted(&s->cusum, alerted);
}

const char *amfi_scale_state(const amfi_scale *s)
{
    if (!s->have_model)
        return "baseline";
    if (s->cusum.alerted)
        return "alert";
    return s->cusum.s > 0.0 ? "watch" : "normal";
}

/* ---- the reference classes ---- */

static double tab_cdf(const double *f, double x0, double dx, double x)
{
    const double g = (x - x0) / dx;
    if (g <= 0)
        return 0.0;
    if (g >= AMFI_SCALE_GRID - 1)
        return 1.0;
    const int i = (int)g;
    return f[i] + (g - i) * (f[i + 1] - f[i]);
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int amfi_scale_ref_fit(amfi_scale_ref *r, double *w, int n, double split_kg, double share_range)
{
    if (!w || n < 4 || !isfinite(split_kg) || split_kg <= 0 || !(share_range > 0) ||
        share_range > 1)
        return AMFI_IND_EINVAL;
    r->share_range = share_range;
    qsort(w, (size_t)n, sizeof(double), cmp_double);
    int n0 = 0;
    while (n0 < n && w[n0] < split_kg)
        n0++;
    const int n1 = n - n0;
    if (n0 < 2 || n1 < 2)
        return AMFI_IND_EINVAL;
    r->split_kg = split_kg;
    r->pi = (double)n1 / n;
    /* the grid spans the baseline stretched by 0.6 .. 1.6 */
    r->x0 = 0.6 * w[0];
    r->dx = (1.6 * w[n - 1] - r->x0) / (AMFI_SCALE_GRID - 1);
    int i0 = 0, i1 = n0;
    for (int g = 0; g < AMFI_SCALE_GRID; g++) {
        const double x = r->x0 + g * r->dx;
        while (i0 < n0 && w[i0] <= x)
            i0++;
        while (i1 < n && w[i1] <= x)
            i1++;
        r->f_empty[g] = (double)i0 / n0;
        r->f_loaded[g] = (double)(i1 - n0) / n1;
    }
    return AMFI_IND_OK;
}

/* Cramér–von Mises distance of the sorted block x at ln s = ls, the share
 * in *pi by least squares (closed form, clamped to [0, 1]). */
static double cvm(const amfi_scale_ref *r, const double *x, int n, double ls, double *pi)
{
    const double u = exp(-ls);
    double num = 0, den = 0, c0 = 0, c1 = 0, c2 = 0;
    for (int i = 0; i < n; i++) {
        const double y = u * x[i];
        const double e = tab_cdf(r->f_empty, r->x0, r->dx, y);
        const double l = tab_cdf(r->f_loaded, r->x0, r->dx, y);
        const double t = (i + 0.5) / n - e, d = l - e;
        num += t * d;
        den += d * d;
        c0 += t * t;
        c1 += t * d;
        c2 += d * d;
    }
    double w = den > 0 ? num / den : r->pi;
    const double lo = fmax(0.0, r->pi - r->share_range), hi = fmin(1.0, r->pi + r->share_range);
    if (w < lo)
        w = lo;
    if (w > hi)
        w = hi;
    *pi = w;
    return c0 - 2 * w * c1 + w * w * c2;
}

double amfi_scale_ref_block_log(const amfi_scale_ref *r, double *x, int n, double *pi)
{
    if (!x || n < 2)
        return NAN;
    qsort(x, (size_t)n, sizeof(double), cmp_double);
    /* a coarse scan of ln s in [−0.3, 0.3], then golden section around the best */
    const double step = 0.01;
    double best = 0, best_c = INFINITY, w;
    for (int k = -30; k <= 30; k++) {
        const double c = cvm(r, x, n, k * step, &w);
        if (c < best_c) {
            best_c = c;
            best = k * step;
        }
    }
    const double gr = 0.6180339887498949;
    double a = best - step, b = best + step;
    double m1 = b - gr * (b - a), m2 = a + gr * (b - a);
    double f1 = cvm(r, x, n, m1, &w), f2 = cvm(r, x, n, m2, &w);
    while (b - a > 1e-6) {
        if (f1 < f2) {
            b = m2;
            m2 = m1;
            f2 = f1;
            m1 = b - gr * (b - a);
            f1 = cvm(r, x, n, m1, &w);
        } else {
            a = m1;
            m1 = m2;
            f1 = f2;
            m2 = a + gr * (b - a);
            f2 = cvm(r, x, n, m2, &w);
        }
    }
    const double ls = 0.5 * (a + b);
    (void)cvm(r, x, n, ls, &w);
    if (pi)
        *pi = w;
    return ls;
}

/* ---- the temperature model ---- */

static double h1(const amfi_scale_params *p, double t)
{
    return t > p->knee_c ? t - p->knee_c : 0.0;
}

static double h2(const amfi_scale_params *p, double t)
{
    if (t >= p->knee_c)
        return 0.0;
    if (t < p->floor_c)
        t = p->floor_c;
    return t - p->knee_c;
}

/* The factor that brings a GVW inferred at deck temperature t to the
 * calibration temperature ref_c. */
double amfi_scale_temp_factor(const amfi_scale_params *p, double bw, double bf, double t)
{
    return exp(-(bw * (h1(p, t) - h1(p, p->ref_c)) + bf * (h2(p, t) - h2(p, p->ref_c))));
}

/* splitmix64 for the bootstrap: reproducible, no global state */
static uint64_t next_u64(uint64_t *st)
{
    uint64_t z = (*st += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* SD of one block's ln s when the blocks are drawn from w[0 .. n − 1];
 * the block is assembled in tmp[0 .. b − 1]. */
static double bootstrap_sd(const double *w, int n, int b, double *tmp, const amfi_scale_ref *r)
{
    uint64_t st = 0x5ca1e5eedull;
    double s1 = 0, s2 = 0;
    for (int k = 0; k < BOOT_N; k++) {
        for (int i = 0; i < b; i++)
            tmp[i] = w[next_u64(&st) % (uint64_t)n];
        const double y = amfi_scale_ref_block_log(r, tmp, b, NULL);
        s1 += y;
        s2 += y * y;
    }
    const double mean = s1 / BOOT_N, var = (s2 - BOOT_N * mean * mean) / (BOOT_N - 1);
    return var > 0 ? sqrt(var) : 0.0;
}

/* ln s of baseline block j of w (copied into tmp, which the estimator sorts) */
static double base_block(const amfi_scale *s, const double *w, int j, double *tmp)
{
    const int b = s->p.block;
    memcpy(tmp, w + (size_t)j * b, sizeof(double) * (size_t)b);
    return amfi_scale_ref_block_log(&s->ref, tmp, b, NULL);
}

/* Fit the classes to the compensated baseline s->bw (a sorted copy in bs). */
static int fit_ref(amfi_scale *s)
{
    memcpy(s->bs, s->bw, sizeof(double) * (size_t)s->n_base);
    return amfi_scale_ref_fit(&s->ref, s->bs, s->n_base, s->p.class_split_kg, s->p.share_range);
}

/* Solve the 3×3 symmetric system a·x = r by Gaussian elimination with
 * partial pivoting; 0 or -1 (singular). */
static int solve3(double a[3][3], double r[3], double x[3])
{
    for (int c = 0; c < 3; c++) {
        int piv = c;
        for (int i = c + 1; i < 3; i++)
            if (fabs(a[i][c]) > fabs(a[piv][c]))
                piv = i;
        if (fabs(a[piv][c]) < 1e-300)
            return -1;
        if (piv != c) {
            for (int j = 0; j < 3; j++) {
                const double t = a[c][j];
                a[c][j] = a[piv][j];
                a[piv][j] = t;
            }
            const double t = r[c];
            r[c] = r[piv];
            r[piv] = t;
        }
        for (int i = c + 1; i < 3; i++) {
            const double f = a[i][c] / a[c][c];
            for (int j = c; j < 3; j++)
                a[i][j] -= f * a[c][j];
            r[i] -= f * r[c];
        }
    }
    for (int i = 2; i >= 0; i--) {
        double v = r[i];
        for (int j = i + 1; j < 3; j++)
            v -= a[i][j] * x[j];
        x[i] = v / a[i][i];
    }
    return 0;
}

void amfi_scale_temp_terms(const amfi_scale_params *p, double deck_c, double *g1, double *g2)
{
    *g1 = h1(p, deck_c);
    *g2 = h2(p, deck_c);
}

void amfi_temp_ridge_add(amfi_temp_ridge *t, double g1, double g2, double y)
{
    const double v[3] = {1.0, g1, g2};
    for (int k = 0; k < 3; k++) {
        t->r[k] += v[k] * y;
        for (int l = 0; l < 3; l++)
            t->a[k][l] += v[k] * v[l];
    }
    t->n++;
}

int amfi_temp_ridge_solve(const amfi_temp_ridge *t, double lam, double d[3])
{
    double a[3][3], r[3];
    memcpy(a, t->a, sizeof a);
    memcpy(r, t->r, sizeof r);
    a[1][1] += lam;
    a[2][2] += lam;
    if (solve3(a, r, d) != 0 || !isfinite(d[0]) || !isfinite(d[1]) || !isfinite(d[2]))
        return AMFI_IND_EINVAL;
    return AMFI_IND_OK;
}

/* Fit the baseline model from bx/bt; 0 or AMFI_IND_EINVAL (degenerate
 * baseline: the caller starts a new collection). */
static int fit_baseline(amfi_scale *s)
{
    const amfi_scale_params *p = &s->p;
    const int n = s->n_base, b = p->block, nblk = p->baseline_blocks;
    amfi_scale_model m;
    memset(&m, 0, sizeof m);
    m.t_min_c = INFINITY;
    m.t_max_c = -INFINITY;
    for (int i = 0; i < n; i++) {
        s->bw[i] = s->bx[i] * amfi_scale_temp_factor(p, p->warm_slope, p->frost_slope, s->bt[i]);
        m.t_min_c = fmin(m.t_min_c, s->bt[i]);
        m.t_max_c = fmax(m.t_max_c, s->bt[i]);
    }
    if (fit_ref(s))
        return AMFI_IND_EINVAL;
    double bw = p->warm_slope, bf = p->frost_slope;
    if (p->slope_prior_sd > 0) {
        /* ridge regression of the blocks' ln s on (1, mean h1, mean h2):
         * the corrections to the prior slopes, prior N(0, tau²) */
        const double sb = bootstrap_sd(s->bw, n, b, s->xw, &s->ref);
        const double lam = sb > 0 ? (sb * sb) / (p->slope_prior_sd * p->slope_prior_sd) : 0.0;
        amfi_temp_ridge tr;
        double d[3] = {0};
        memset(&tr, 0, sizeof tr);
        for (int j = 0; j < nblk; j++) {
            double g1 = 0, g2 = 0;
            for (int i = 0; i < b; i++) {
                g1 += h1(p, s->bt[(size_t)j * b + i]);
                g2 += h2(p, s->bt[(size_t)j * b + i]);
            }
            amfi_temp_ridge_add(&tr, g1 / b, g2 / b, base_block(s, s->bw, j, s->xw));
        }
        if (amfi_temp_ridge_solve(&tr, lam, d) == AMFI_IND_OK) {
            bw += d[1];
            bf += d[2];
        }
    }
    m.warm_slope = bw;
    m.frost_slope = bf;
    for (int i = 0; i < n; i++)
        s->bw[i] = s->bx[i] * amfi_scale_temp_factor(p, bw, bf, s->bt[i]);
    if (fit_ref(s))
        return AMFI_IND_EINVAL;
    m.pi = s->ref.pi;
    double s1 = 0, s2 = 0;
    for (int j = 0; j < nblk; j++) {
        const double y = base_block(s, s->bw, j, s->xw);
        s1 += y;
        s2 += y * y;
    }
    const double mean = s1 / nblk, var = (s2 - nblk * mean * mean) / (nblk - 1);
    m.mean0 = mean;
    m.sigma_resid = var > 0 ? sqrt(var) : 0.0;
    m.sigma_boot = bootstrap_sd(s->bw, n, b, s->xw, &s->ref);
    m.sigma0 = fmax(m.sigma_resid, m.sigma_boot);
    if (!(m.sigma0 > 0) || !isfinite(m.sigma0))
        return AMFI_IND_EINVAL;
    m.k_ref = log(1.0 / (1.0 - p->design_shift)) / (2.0 * m.sigma0);
    const double arl0 = p->vehicles_per_day * 365.0 / b / p->false_alarms_per_year;
    /* the baseline's offset mean0 is uncertain by sigma0 / sqrt(blocks):
     * the threshold holds the target ARL at a null mean of that size */
    const double margin = fmin(1.0 / sqrt((double)nblk), 0.9 * m.k_ref);
    m.h = amfi_cusum_threshold(m.k_ref, arl0 < 1 ? 1 : arl0, margin);
    if (!(m.h >= 0))
        return AMFI_IND_EINVAL;
    s->m = m;
    s->have_model = 1;
    const int alerted = s->cusum.alerted; /* restored before the baseline, maybe */
    amfi_cusum_init(&s->cusum, m.k_ref, m.h);
    amfi_cusum_set_alerted(&s->cusum, alerted);
    return AMFI_IND_OK;
}

int amfi_scale_push(amfi_scale *s, double gvw_kg, double deck_c, amfi_scale_eval *eval,
                    amfi_alert_event *alert)
{
    if (!isfinite(gvw_kg) || gvw_kg <= 0 || gvw_kg > AMFI_IND_MAX_GVW_KG || !isfinite(deck_c) ||
        deck_c < AMFI_SCALE_T_MIN || deck_c > AMFI_SCALE_T_MAX)
        return AMFI_IND_EINVAL;
    const amfi_scale_params *p = &s->p;
    if (!s->have_model) {
        s->bx[s->nb] = gvw_kg;
        s->bt[s->nb] = deck_c;
        if (++s->nb < s->n_base)
            return 0;
        s->nb = 0;
        if (fit_baseline(s))
            return 0; /* degenerate baseline (no spread): collect again */
        if (eval) {
            memset(eval, 0, sizeof *eval);
            eval->n = s->n_base;
            eval->scale = 1.0;
            eval->raw_scale = 1.0;
            eval->pi = s->m.pi;
            eval->h = s->m.h;
            eval->state = "baseline";
        }
        return AMFI_IND_BASELINE;
    }
    s->xr[s->nx] = gvw_kg;
    s->xw[s->nx] = gvw_kg * amfi_scale_temp_factor(p, s->m.warm_slope, s->m.frost_slope, deck_c);
    s->t_sum += deck_c;
    if (++s->nx < p->block)
        return 0;
    const int n = s->nx;
    double pi;
    const double y = amfi_scale_ref_block_log(&s->ref, s->xw, n, &pi);
    const double z = (y - s->m.mean0) / s->m.sigma0;
    const int step = amfi_cusum_alert_step(&s->cusum, z, p->clear_after);
    int rc = AMFI_IND_EVAL;
    const double tmean = s->t_sum / n;
    if (eval) {
        eval->n = n;
        eval->scale = exp(y - s->m.mean0);
        eval->pi = pi;
        eval->deck_mean_c = tmean;
        eval->raw_scale = exp(amfi_scale_ref_block_log(&s->ref, s->xr, n, NULL) - s->m.mean0);
        eval->z = z;
        eval->cusum = s->cusum.s;
        eval->h = s->m.h;
        eval->state = amfi_scale_state(s);
    }
    if (step) {
        rc |= AMFI_IND_ALERT;
        if (alert) {
            alert->level = "warning";
            alert->kind = "scale_shift";
            alert->raised = step > 0;
            if (step > 0)
                snprintf(alert->message, sizeof alert->message,
                         "scale of inferred GVW %.4f (temperature-compensated, deck %.1f °C): "
                         "CUSUM %.2f >= %.2f",
                         exp(y - s->m.mean0), tmean, s->cusum.s, s->m.h);
            else
                snprintf(alert->message, sizeof alert->message,
                         "scale of inferred GVW %.4f: CUSUM at 0 for %d blocks", exp(y - s->m.mean0),
                         p->clear_after);
        }
    }
    s->nx = 0;
    s->t_sum = 0;
    return rc;
}
