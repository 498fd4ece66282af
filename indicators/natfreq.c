/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * natfreq.c: the first natural frequency and damping ratio from a segment
 * of free vibration (natfreq.h: the method and its refusals). Pure
 * computation; any thread (GSL's error handler is the caller's: amfid
 * turns it off).
 */
#include "natfreq.h"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_fft_real.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.283185307179586

void amfi_natfreq_params_default(amfi_natfreq_params *p)
{
    memset(p, 0, sizeof *p);
    p->f_lo_hz = 0.5;
    p->f_hi_hz = 50.0;
    p->n_modes = 2;
    p->min_periods = 4.0;
    p->min_r2 = 0.8;
    p->max_zeta = 0.2;
    p->max_se_frac = 0.01;
}

int amfi_natfreq_params_check(const amfi_natfreq_params *p, char *err, size_t errlen)
{
    const char *bad = NULL;
    if (!(p->f_lo_hz > 0) || !isfinite(p->f_lo_hz))
        bad = "f_lo_hz must be > 0";
    else if (!(p->f_hi_hz > p->f_lo_hz) || !isfinite(p->f_hi_hz))
        bad = "f_hi_hz must be above f_lo_hz";
    else if (p->n_modes < 1 || p->n_modes > AMFI_NATFREQ_MAX_MODES)
        bad = "n_modes must be 1 .. 3";
    else if (!(p->min_periods >= 1) || !isfinite(p->min_periods))
        bad = "min_periods must be >= 1";
    else if (!(p->min_r2 >= 0 && p->min_r2 < 1))
        bad = "min_r2 must be in [0, 1)";
    else if (!(p->max_zeta > 0 && p->max_zeta < 1))
        bad = "max_zeta must be in (0, 1)";
    else if (!(p->max_se_frac > 0) || !isfinite(p->max_se_frac))
        bad = "max_se_frac must be > 0";
    if (bad && err && errlen)
        snprintf(err, errlen, "natural frequency: %s", bad);
    return bad ? -1 : 0;
}

int amfi_natfreq_follow(const amfi_natfreq_params *site, const double *omega, int n, int mode,
                        double band, amfi_natfreq_params *out, double *f_mode_hz, char *err,
                        size_t errlen)
{
    *out = *site;
    out->follow = 0;
    *f_mode_hz = NAN;
    if (mode <= 0)
        return 0;
    if (mode > n) {
        snprintf(err, errlen,
                 "daemon.natural_frequency.mode %d: the site's bridge model has %d modes", mode,
                 n);
        return -1;
    }
    if (!(band > 0 && band <= 0.5)) {
        snprintf(err, errlen, "daemon.natural_frequency.band %g must be in (0, 0.5]", band);
        return -1;
    }
    const double f = omega[mode - 1] / TWO_PI;
    double lo = f * (1 - band), hi = f * (1 + band);
    if (mode > 1)
        lo = fmax(lo, sqrt(f * omega[mode - 2] / TWO_PI));
    if (mode < n)
        hi = fmin(hi, sqrt(f * omega[mode] / TWO_PI));
    lo = fmax(lo, site->f_lo_hz);
    hi = fmin(hi, site->f_hi_hz);
    if (!(f > lo && f < hi)) {
        snprintf(err, errlen,
                 "daemon.natural_frequency.mode %d: the site model's frequency %.4f Hz is not "
                 "inside [f_lo_hz, f_hi_hz] = [%g, %g] Hz (or a neighbouring mode is as near)",
                 mode, f, site->f_lo_hz, site->f_hi_hz);
        return -1;
    }
    out->f_lo_hz = lo;
    out->f_hi_hz = hi;
    out->follow = 1;
    *f_mode_hz = f;
    return 0;
}

const char *amfi_natfreq_code_name(int code)
{
    switch (code) {
    case AMFI_NATFREQ_OK: return "ok";
    case AMFI_NATFREQ_SHORT: return "short";
    case AMFI_NATFREQ_NOPEAK: return "no_peak";
    case AMFI_NATFREQ_NOFIT: return "no_fit";
    case AMFI_NATFREQ_DAMPING: return "damping";
    case AMFI_NATFREQ_NOISY: return "noisy";
    default: return "invalid";
    }
}

/* ---- step 1 and 2: the periodogram's peaks ---- */

typedef struct spectrum {
    double *pw;   /* power per bin, 0 .. nfft/2 */
    int nfft;
    double df;    /* Hz per bin */
} spectrum;

static int periodogram(const double *x, int n, double mean, double rate, spectrum *s)
{
    int nfft = 1;
    while (nfft < 8 * n || nfft < 4096)
        nfft *= 2;
    double *buf = calloc((size_t)nfft, sizeof *buf);
    s->pw = malloc(sizeof(double) * (size_t)(nfft / 2 + 1));
    if (!buf || !s->pw) {
        free(buf);
        free(s->pw);
        s->pw = NULL;
        return -1;
    }
    for (int i = 0; i < n; i++) {
        const double w = n > 1 ? 0.5 - 0.5 * cos(TWO_PI * i / (n - 1)) : 1.0;
        buf[i] = (x[i] - mean) * w;
    }
    gsl_fft_real_radix2_transform(buf, 1, (size_t)nfft);
    /* half-complex: buf[k] real, buf[nfft − k] imaginary */
    s->pw[0] = buf[0] * buf[0];
    for (int k = 1; k < nfft / 2; k++)
        s->pw[k] = buf[k] * buf[k] + buf[nfft - k] * buf[nfft - k];
    s->pw[nfft / 2] = buf[nfft / 2] * buf[nfft / 2];
    s->nfft = nfft;
    s->df = rate / nfft;
    free(buf);
    return 0;
}

/* The parabola through the log power at k − 1, k, k + 1: the vertex, Hz. */
static double refine(const spectrum *s, int k)
{
    const double a = log(s->pw[k - 1] + 1e-300), b = log(s->pw[k] + 1e-300),
                 c = log(s->pw[k + 1] + 1e-300);
    const double den = a - 2 * b + c;
    double d = den < 0 ? 0.5 * (a - c) / den : 0.0;
    if (d > 0.5)
        d = 0.5;
    if (d < -0.5)
        d = -0.5;
    return (k + d) * s->df;
}

/* The strongest local maximum in bins [k_lo, k_hi] above min_pw, or −1. */
static int strongest(const spectrum *s, int k_lo, int k_hi, double min_pw, const int *skip,
                     int n_skip, int skip_halfwidth)
{
    int best = -1;
    if (k_lo < 1)
        k_lo = 1;
    if (k_hi > s->nfft / 2 - 1)
        k_hi = s->nfft / 2 - 1;
    for (int k = k_lo; k <= k_hi; k++) {
        if (!(s->pw[k] > s->pw[k - 1] && s->pw[k] >= s->pw[k + 1]) || !(s->pw[k] > min_pw))
            continue;
        int near = 0;
        for (int j = 0; j < n_skip; j++)
            near |= abs(k - skip[j]) <= skip_halfwidth;
        if (!near && (best < 0 || s->pw[k] > s->pw[best]))
            best = k;
    }
    return best;
}

/* ---- step 3: damped sinusoids by nonlinear least squares ---- */

typedef struct fitdata {
    const double *x;
    int n, m; /* samples, modes */
    double h; /* sample step, s */
} fitdata;

/* parameters: c, then per mode sigma, w, a, b */
static int model_f(const gsl_vector *p, void *v, gsl_vector *f)
{
    const fitdata *d = v;
    const double c = gsl_vector_get(p, 0);
    for (int i = 0; i < d->n; i++) {
        const double t = i * d->h;
        double y = c;
        for (int k = 0; k < d->m; k++) {
            const double sg = gsl_vector_get(p, 1 + 4 * k), w = gsl_vector_get(p, 2 + 4 * k),
                         a = gsl_vector_get(p, 3 + 4 * k), b = gsl_vector_get(p, 4 + 4 * k);
            y += exp(-sg * t) * (a * cos(w * t) + b * sin(w * t));
        }
        gsl_vector_set(f, (size_t)i, y - d->x[i]);
    }
    return GSL_SUCCESS;
}

static int model_df(const gsl_vector *p, void *v, gsl_matrix *J)
{
    const fitdata *d = v;
    for (int i = 0; i < d->n; i++) {
        const double t = i * d->h;
        gsl_matrix_set(J, (size_t)i, 0, 1.0);
        for (int k = 0; k < d->m; k++) {
            const double sg = gsl_vector_get(p, 1 + 4 * k), w = gsl_vector_get(p, 2 + 4 * k),
                         a = gsl_vector_get(p, 3 + 4 * k), b = gsl_vector_get(p, 4 + 4 * k);
            const double e = exp(-sg * t), cs = cos(w * t), sn = sin(w * t);
            gsl_matrix_set(J, (size_t)i, (size_t)(1 + 4 * k), -t * e * (a * cs + b * sn));
            gsl_matrix_set(J, (size_t)i, (size_t)(2 + 4 * k), t * e * (-a * sn + b * cs));
            gsl_matrix_set(J, (size_t)i, (size_t)(3 + 4 * k), e * cs);
            gsl_matrix_set(J, (size_t)i, (size_t)(4 + 4 * k), e * sn);
        }
    }
    return GSL_SUCCESS;
}

/* The linear least squares of (c, a_k, b_k) at fixed sigma_k, w_k (set in
 * p), written into p; the residual sum of squares, or INFINITY. */
static double linear_start(const fitdata *d, gsl_vector *p)
{
    const int q = 1 + 2 * d->m;
    gsl_matrix *A = gsl_matrix_alloc((size_t)d->n, (size_t)q);
    gsl_vector *y = gsl_vector_alloc((size_t)d->n), *tau = gsl_vector_alloc((size_t)q),
               *sol = gsl_vector_alloc((size_t)q), *res = gsl_vector_alloc((size_t)d->n);
    double ssr = INFINITY;
    if (A && y && tau && sol && res) {
        for (int i = 0; i < d->n; i++) {
            const double t = i * d->h;
            gsl_matrix_set(A, (size_t)i, 0, 1.0);
            for (int k = 0; k < d->m; k++) {
                const double e = exp(-gsl_vector_get(p, 1 + 4 * k) * t),
                             w = gsl_vector_get(p, 2 + 4 * k);
                gsl_matrix_set(A, (size_t)i, (size_t)(1 + 2 * k), e * cos(w * t));
                gsl_matrix_set(A, (size_t)i, (size_t)(2 + 2 * k), e * sin(w * t));
            }
            gsl_vector_set(y, (size_t)i, d->x[i]);
        }
        if (gsl_linalg_QR_decomp(A, tau) == GSL_SUCCESS &&
            gsl_linalg_QR_lssolve(A, tau, y, sol, res) == GSL_SUCCESS) {
            double s = 0;
            gsl_blas_ddot(res, res, &s);
            ssr = s;
            gsl_vector_set(p, 0, gsl_vector_get(sol, 0));
            for (int k = 0; k < d->m; k++) {
                gsl_vector_set(p, (size_t)(3 + 4 * k), gsl_vector_get(sol, (size_t)(1 + 2 * k)));
                gsl_vector_set(p, (size_t)(4 + 4 * k), gsl_vector_get(sol, (size_t)(2 + 2 * k)));
            }
        }
    }
    gsl_matrix_free(A);
    gsl_vector_free(y);
    gsl_vector_free(tau);
    gsl_vector_free(sol);
    gsl_vector_free(res);
    return isfinite(ssr) ? ssr : INFINITY;
}

static int refuse(amfi_natfreq_result *r, int code, const char *why)
{
    r->f1_hz = r->zeta = r->f1_se_hz = NAN;
    r->reason = why;
    return code;
}

int amfi_natfreq_estimate(const double *x, int n, double rate_hz, const amfi_natfreq_params *p,
                          amfi_natfreq_result *r)
{
    memset(r, 0, sizeof *r);
    r->f_peak_hz = r->r2 = r->periods = r->amplitude = NAN;
    if (!x || n < 8 || !(rate_hz > 0) || !isfinite(rate_hz) || !p ||
        amfi_natfreq_params_check(p, NULL, 0))
        return refuse(r, AMFI_NATFREQ_EINVAL, "invalid arguments");
    double mean = 0;
    for (int i = 0; i < n; i++) {
        if (!isfinite(x[i]))
            return refuse(r, AMFI_NATFREQ_EINVAL, "a sample is not finite");
        mean += x[i];
    }
    mean /= n;
    const double dur = n / rate_hz;
    if (dur * p->f_hi_hz < p->min_periods && dur * p->f_lo_hz < p->min_periods &&
        dur * 0.45 * rate_hz < p->min_periods)
        return refuse(r, AMFI_NATFREQ_SHORT, "segment shorter than min_periods at any frequency");

    spectrum s = {0};
    if (periodogram(x, n, mean, rate_hz, &s))
        return refuse(r, AMFI_NATFREQ_EINVAL, "out of memory");
    const int k_lo = (int)ceil(p->f_lo_hz / s.df), k_hi = (int)floor(p->f_hi_hz / s.df);
    const int k1 = strongest(&s, k_lo, k_hi, 0.0, NULL, 0, 0);
    if (k1 < 0 || k1 <= k_lo || k1 >= k_hi || k1 >= s.nfft / 2 - 1) {
        free(s.pw);
        return refuse(r, AMFI_NATFREQ_NOPEAK, "no spectral peak inside the band");
    }
    r->f_peak_hz = refine(&s, k1);
    r->periods = dur * r->f_peak_hz;
    if (r->periods < p->min_periods) {
        free(s.pw);
        return refuse(r, AMFI_NATFREQ_SHORT, "segment shorter than min_periods periods");
    }
    /* the other modes' starts: the strongest peaks above 1.5 f_peak, at
     * least 1 % of the first's power, and a main lobe apart */
    double f0[AMFI_NATFREQ_MAX_MODES] = {r->f_peak_hz};
    int kk[AMFI_NATFREQ_MAX_MODES] = {k1};
    int m = 1;
    const int lobe = (int)ceil(2.0 * s.nfft / n); /* Hann main lobe half-width, bins */
    const int k_top = (int)floor(0.45 * rate_hz / s.df);
    while (m < p->n_modes) {
        int k;
        if (p->follow) {
            /* below the band (clear of the mean's lobe) or above it, the
             * stronger of the two */
            const int kb = strongest(&s, lobe + 1, k_lo - 1, 0.01 * s.pw[k1], kk, m, lobe);
            const int ka = strongest(&s, k_hi + 1, k_top, 0.01 * s.pw[k1], kk, m, lobe);
            k = kb < 0 ? ka : ka < 0 ? kb : s.pw[ka] >= s.pw[kb] ? ka : kb;
        } else {
            k = strongest(&s, (int)ceil(1.5 * k1), k_top, 0.01 * s.pw[k1], kk, m, lobe);
        }
        if (k < 0)
            break;
        kk[m] = k;
        f0[m++] = refine(&s, k);
    }
    free(s.pw);
    r->n_modes = m;

    fitdata d = {x, n, m, 1.0 / rate_hz};
    const int np = 1 + 4 * m;
    if (n <= np + 2)
        return refuse(r, AMFI_NATFREQ_SHORT, "too few samples for the fit");
    gsl_vector *p0 = gsl_vector_alloc((size_t)np), *best = gsl_vector_alloc((size_t)np);
    gsl_matrix *cov = gsl_matrix_alloc((size_t)np, (size_t)np);
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    gsl_multifit_nlinear_workspace *ws =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, (size_t)n, (size_t)np);
    int code = AMFI_NATFREQ_OK;
    if (!p0 || !best || !cov || !ws) {
        code = refuse(r, AMFI_NATFREQ_EINVAL, "out of memory");
        goto out;
    }
    /* the start: the periodogram's frequencies, the best of a few damping
     * ratios (the same for every mode), the linear amplitudes there */
    {
        static const double zetas[] = {0.005, 0.01, 0.02, 0.04, 0.08, 0.16};
        double best_ssr = INFINITY;
        for (size_t z = 0; z < sizeof zetas / sizeof *zetas; z++) {
            for (int k = 0; k < m; k++) {
                const double w = TWO_PI * f0[k];
                gsl_vector_set(p0, (size_t)(1 + 4 * k), zetas[z] * w);
                gsl_vector_set(p0, (size_t)(2 + 4 * k), w);
            }
            const double ssr = linear_start(&d, p0);
            if (ssr < best_ssr) {
                best_ssr = ssr;
                gsl_vector_memcpy(best, p0);
            }
        }
        if (!isfinite(best_ssr)) {
            code = refuse(r, AMFI_NATFREQ_NOFIT, "the starting fit failed");
            goto out;
        }
    }
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = model_f;
    fdf.df = model_df;
    fdf.n = (size_t)n;
    fdf.p = (size_t)np;
    fdf.params = &d;
    int info = 0;
    if (gsl_multifit_nlinear_init(best, &fdf, ws) != GSL_SUCCESS) {
        code = refuse(r, AMFI_NATFREQ_NOFIT, "the fit could not start");
        goto out;
    }
    const int st = gsl_multifit_nlinear_driver(200, 1e-10, 1e-10, 1e-10, NULL, NULL, &info, ws);
    const gsl_vector *sol = gsl_multifit_nlinear_position(ws);
    const gsl_vector *res = gsl_multifit_nlinear_residual(ws);
    if (st != GSL_SUCCESS && st != GSL_EMAXITER && st != GSL_ENOPROG) {
        code = refuse(r, AMFI_NATFREQ_NOFIT, "the nonlinear fit failed");
        goto out;
    }
    {
        double ssr = 0, sst = 0;
        gsl_blas_ddot(res, res, &ssr);
        for (int i = 0; i < n; i++)
            sst += (x[i] - mean) * (x[i] - mean);
        r->r2 = sst > 0 ? 1.0 - ssr / sst : NAN;
        /* mode 1: the fitted mode nearest the peak (the fit keeps the order
         * it started in, but a mode may wander) */
        int k1f = 0;
        for (int k = 1; k < m; k++)
            if (fabs(gsl_vector_get(sol, 2 + 4 * k) - TWO_PI * f0[0]) <
                fabs(gsl_vector_get(sol, 2 + 4 * k1f) - TWO_PI * f0[0]))
                k1f = k;
        const double sg = gsl_vector_get(sol, (size_t)(1 + 4 * k1f)),
                     w = fabs(gsl_vector_get(sol, (size_t)(2 + 4 * k1f))),
                     a = gsl_vector_get(sol, (size_t)(3 + 4 * k1f)),
                     b = gsl_vector_get(sol, (size_t)(4 + 4 * k1f));
        const double wn = sqrt(sg * sg + w * w);
        r->f1_hz = wn / TWO_PI;
        r->zeta = wn > 0 ? sg / wn : NAN;
        r->amplitude = hypot(a, b);
        /* SE of f1: covariance scaled by the residual variance */
        double se = NAN;
        if (gsl_multifit_nlinear_covar(gsl_multifit_nlinear_jac(ws), 0.0, cov) == GSL_SUCCESS) {
            const double s2 = ssr / (n - np);
            const size_t is = (size_t)(1 + 4 * k1f), iw = (size_t)(2 + 4 * k1f);
            /* d wn = (sg d sg + w d w) / wn */
            const double gs = wn > 0 ? sg / wn : 0, gw = wn > 0 ? w / wn : 0;
            const double var = s2 * (gs * gs * gsl_matrix_get(cov, is, is) +
                                     2 * gs * gw * gsl_matrix_get(cov, is, iw) +
                                     gw * gw * gsl_matrix_get(cov, iw, iw));
            se = var >= 0 ? sqrt(var) / TWO_PI : NAN;
        }
        r->f1_se_hz = se;
        r->reason = "";
        if (!isfinite(r->f1_hz) || !(r->f1_hz >= p->f_lo_hz && r->f1_hz <= p->f_hi_hz) ||
            !(fabs(r->f1_hz - r->f_peak_hz) < 0.25 * r->f_peak_hz)) {
            code = AMFI_NATFREQ_NOFIT;
            r->reason = "the fit's frequency left the band or the peak";
        } else if (!(r->zeta >= 0 && r->zeta <= p->max_zeta)) {
            code = AMFI_NATFREQ_DAMPING;
            r->reason = "the fit's damping ratio is outside [0, max_zeta]";
        } else if (!(r->r2 >= p->min_r2)) {
            code = AMFI_NATFREQ_NOISY;
            r->reason = "the fit's R² is below min_r2 (too noisy)";
        } else if (!(se <= p->max_se_frac * r->f1_hz)) {
            code = AMFI_NATFREQ_NOISY;
            r->reason = "the standard error of f1 is above max_se_frac (too noisy)";
        }
        if (code != AMFI_NATFREQ_OK)
            refuse(r, code, r->reason);
    }
out:
    gsl_vector_free(p0);
    gsl_vector_free(best);
    gsl_matrix_free(cov);
    if (ws)
        gsl_multifit_nlinear_free(ws);
    return code;
}

/* ---- temperature compensation ---- */

struct amfi_natfreq_comp {
    amfi_scale_params tp;
    int cap, n;
    double *t, *y; /* the baseline: deck temperature, ln f1 */
    int have;
    amfi_natfreq_model m;
};

int amfi_natfreq_comp_create(const amfi_scale_params *tp, int baseline_n,
                             amfi_natfreq_comp **out, char *err, size_t errlen)
{
    *out = NULL;
    const char *field = NULL;
    if (amfi_scale_params_check(tp, &field, err, errlen) != 0)
        return AMFI_NATFREQ_EINVAL;
    if (baseline_n < 10) {
        if (err && errlen)
            snprintf(err, errlen, "natural frequency: baseline_n %d must be >= 10", baseline_n);
        return AMFI_NATFREQ_EINVAL;
    }
    amfi_natfreq_comp *c = calloc(1, sizeof *c);
    if (c) {
        c->t = malloc(sizeof(double) * (size_t)baseline_n);
        c->y = malloc(sizeof(double) * (size_t)baseline_n);
    }
    if (!c || !c->t || !c->y) {
        amfi_natfreq_comp_destroy(c);
        if (err && errlen)
            snprintf(err, errlen, "natural frequency: out of memory");
        return AMFI_NATFREQ_EINVAL;
    }
    c->tp = *tp;
    c->cap = baseline_n;
    *out = c;
    return AMFI_NATFREQ_OK;
}

void amfi_natfreq_comp_destroy(amfi_natfreq_comp *c)
{
    if (!c)
        return;
    free(c->t);
    free(c->y);
    free(c);
}

/* The ridge fit of the baseline: the corrections to the prior slopes with
 * lam, and the residual variance. */
static int comp_solve(const amfi_natfreq_comp *c, double pw, double pf, double lam, double d[3],
                      double *var)
{
    amfi_temp_ridge tr;
    memset(&tr, 0, sizeof tr);
    for (int i = 0; i < c->n; i++) {
        double g1, g2;
        amfi_scale_temp_terms(&c->tp, c->t[i], &g1, &g2);
        amfi_temp_ridge_add(&tr, g1, g2, c->y[i] - pw * g1 - pf * g2);
    }
    if (amfi_temp_ridge_solve(&tr, lam, d) != 0)
        return -1;
    double s2 = 0;
    for (int i = 0; i < c->n; i++) {
        double g1, g2;
        amfi_scale_temp_terms(&c->tp, c->t[i], &g1, &g2);
        const double e = c->y[i] - pw * g1 - pf * g2 - d[0] - d[1] * g1 - d[2] * g2;
        s2 += e * e;
    }
    *var = s2 / (c->n > 3 ? c->n - 3 : 1);
    return 0;
}

static int comp_fit(amfi_natfreq_comp *c)
{
    /* priors: f1 ∝ sqrt(E), weights ∝ 1 / E */
    const double pw = -0.5 * c->tp.warm_slope, pf = -0.5 * c->tp.frost_slope;
    const double tau = 0.5 * c->tp.slope_prior_sd;
    double d[3] = {0}, var = 0;
    /* pass 1: nearly free, for the residual variance; pass 2: the ridge
     * weight var / tau² (tau 0: the prior slopes stand) */
    if (comp_solve(c, pw, pf, 1e-12, d, &var) != 0)
        var = 0;
    if (tau > 0 && var > 0) {
        if (comp_solve(c, pw, pf, var / (tau * tau), d, &var) != 0)
            d[1] = d[2] = 0;
    } else {
        d[1] = d[2] = 0;
    }
    amfi_natfreq_model m;
    memset(&m, 0, sizeof m);
    m.n = c->n;
    m.warm = pw + d[1];
    m.frost = pf + d[2];
    m.t_min_c = INFINITY;
    m.t_max_c = -INFINITY;
    double s1 = 0, s2 = 0;
    for (int i = 0; i < c->n; i++) {
        const double z = c->y[i] + log(amfi_scale_temp_factor(&c->tp, m.warm, m.frost, c->t[i]));
        s1 += z;
        s2 += z * z;
        m.t_min_c = fmin(m.t_min_c, c->t[i]);
        m.t_max_c = fmax(m.t_max_c, c->t[i]);
    }
    const double mean = s1 / c->n, v = (s2 - c->n * mean * mean) / (c->n - 1);
    m.f_ref_hz = exp(mean);
    m.sd_rel = v > 0 ? sqrt(v) : 0.0;
    if (!isfinite(m.warm) || !isfinite(m.frost) || !isfinite(m.f_ref_hz))
        return -1;
    c->m = m;
    c->have = 1;
    return 0;
}

int amfi_natfreq_comp_push(amfi_natfreq_comp *c, double f1_hz, double deck_c)
{
    if (!(f1_hz > 0 && f1_hz <= 1000) || !isfinite(deck_c))
        return AMFI_NATFREQ_EINVAL;
    if (c->have)
        return 0;
    c->t[c->n] = deck_c;
    c->y[c->n] = log(f1_hz);
    if (++c->n < c->cap)
        return 0;
    if (comp_fit(c) != 0) { /* degenerate: collect again */
        c->n = 0;
        return 0;
    }
    return 1;
}

double amfi_natfreq_comp_apply(const amfi_natfreq_comp *c, double f1_hz, double deck_c)
{
    if (!c->have || !isfinite(deck_c) || !(f1_hz > 0))
        return NAN;
    return f1_hz * amfi_scale_temp_factor(&c->tp, c->m.warm, c->m.frost, deck_c);
}

int amfi_natfreq_comp_model(const amfi_natfreq_comp *c, amfi_natfreq_model *m)
{
    if (!c->have)
        return 0;
    *m = c->m;
    return 1;
}
