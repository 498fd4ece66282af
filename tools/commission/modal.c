/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * modal.c: the first mode of a free-vibration record (commission.h).
 *
 * A spectral peak search (a direct DFT on a 0.01 Hz grid between f_lo and
 * f_hi: a few thousand samples, no FFT length to choose) gives ω; the
 * amplitudes follow linearly; then GSL's multifit_nlinear (trust region,
 * Levenberg-Marquardt, finite-difference Jacobian) fits
 *     y(t) = e^{−ζωt}(a cos ω_d t + b sin ω_d t) + c,   ω_d = ω √(1 − ζ²).
 */
#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <string.h>

#include "commission.h"

typedef struct fit_data {
    const double *y;
    int n;
    double dt;
} fit_data;

/* x = (ω, ζ, a, b, c) */
static int resid(const gsl_vector *x, void *p, gsl_vector *f)
{
    const fit_data *d = p;
    double w = gsl_vector_get(x, 0), z = gsl_vector_get(x, 1), a = gsl_vector_get(x, 2),
           b = gsl_vector_get(x, 3), c = gsl_vector_get(x, 4);
    double zz = z * z < 0.81 ? z * z : 0.81, wd = w * sqrt(1 - zz);
    for (int k = 0; k < d->n; k++) {
        double t = k * d->dt, e = exp(-z * w * t);
        gsl_vector_set(f, k, e * (a * cos(wd * t) + b * sin(wd * t)) + c - d->y[k]);
    }
    return GSL_SUCCESS;
}

int cm_modal_fit(const double *y, int n, double rate_hz, double f_lo, double f_hi,
                 cm_modal *out)
{
    memset(out, 0, sizeof *out);
    const double dt = 1.0 / rate_hz, T = n * dt;
    if (n < 16 || !(f_lo > 0) || !(f_hi > f_lo) || T * f_lo < 4 || f_hi > rate_hz / 2)
        return -1;
    double mean = gsl_stats_mean(y, 1, (size_t)n);
    /* peak of |Σ (y − mean) e^{−iωt}| */
    double best = -1, f0 = f_lo;
    for (double f = f_lo; f <= f_hi; f += 0.01) {
        double re = 0, im = 0, w = 2 * M_PI * f;
        for (int k = 0; k < n; k++) {
            re += (y[k] - mean) * cos(w * k * dt);
            im -= (y[k] - mean) * sin(w * k * dt);
        }
        double p = re * re + im * im;
        if (p > best) {
            best = p;
            f0 = f;
        }
    }
    /* amplitudes at ζ = 0.02 by linear least squares on (cos, sin) */
    double w0 = 2 * M_PI * f0, z0 = 0.02, scc = 0, sss = 0, scs = 0, syc = 0, sys = 0;
    for (int k = 0; k < n; k++) {
        double t = k * dt, e = exp(-z0 * w0 * t), c = e * cos(w0 * t), s = e * sin(w0 * t);
        scc += c * c;
        sss += s * s;
        scs += c * s;
        syc += (y[k] - mean) * c;
        sys += (y[k] - mean) * s;
    }
    double det = scc * sss - scs * scs;
    if (!(fabs(det) > 0))
        return -1;
    double a0 = (syc * sss - sys * scs) / det, b0 = (sys * scc - syc * scs) / det;

    fit_data d = {y, n, dt};
    gsl_multifit_nlinear_fdf fdf = {.f = resid, .df = NULL, .fvv = NULL, .n = (size_t)n, .p = 5,
                                    .params = &d};
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    gsl_multifit_nlinear_workspace *ws =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, (size_t)n, 5);
    if (!ws)
        return -1;
    double x0[5] = {w0, z0, a0, b0, mean};
    gsl_vector_view xv = gsl_vector_view_array(x0, 5);
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int info = 0, rc = gsl_multifit_nlinear_init(&xv.vector, &fdf, ws);
    if (rc == GSL_SUCCESS)
        rc = gsl_multifit_nlinear_driver(200, 1e-10, 1e-10, 1e-12, NULL, NULL, &info, ws);
    gsl_set_error_handler(old);
    int ret = -1;
    if (rc == GSL_SUCCESS || rc == GSL_EMAXITER) {
        const gsl_vector *x = ws->x;
        double w = gsl_vector_get(x, 0), z = gsl_vector_get(x, 1);
        double a = gsl_vector_get(x, 2), b = gsl_vector_get(x, 3);
        double chi;
        gsl_blas_ddot(ws->f, ws->f, &chi);
        double ss = 0;
        for (int k = 0; k < n; k++)
            ss += (y[k] - mean) * (y[k] - mean);
        if (w > 2 * M_PI * f_lo * 0.5 && w < 2 * M_PI * f_hi * 2 && z > 0 && z < 0.5 && ss > 0) {
            out->ok = 1;
            out->f_hz = w / (2 * M_PI);
            out->zeta = z;
            out->amplitude = hypot(a, b);
            out->fit_rel = sqrt(chi / ss);
            ret = 0;
        }
    }
    gsl_multifit_nlinear_free(ws);
    return ret;
}
