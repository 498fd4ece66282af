/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * natfreq.h: the bridge's first natural frequency and its damping ratio
 * from a segment of free vibration (issue 14, item 4): the acceleration
 * one sensor records after the last axle has left the span.
 *
 * Method (measured in tests/test_natfreq.c, docs/indicators.md section 9):
 *   1. the mean is removed; a Hann-windowed periodogram, zero-padded to at
 *      least 8 times the segment, gives the strongest peak in [f_lo, f_hi]
 *      (the first mode), refined by a parabola through the log power of
 *      the three bins around it;
 *   2. the further peaks above 1.5 f_peak (up to 0.45 of the sample
 *      rate, at least 1 % of the first peak's power) start the other modes,
 *      up to n_modes in all;
 *   3. a sum of damped sinusoids plus an offset,
 *        y(t) = c + sum_k exp(−sigma_k t) (a_k cos w_k t + b_k sin w_k t),
 *      is fitted by nonlinear least squares (GSL gsl_multifit_nlinear,
 *      Levenberg-Marquardt, analytic Jacobian) from the periodogram's
 *      frequencies, the best of a few damping ratios, and the amplitudes
 *      of the linear least squares at that start;
 *   4. mode 1's undamped frequency f1 = sqrt(sigma² + w²) / 2 pi and its
 *      damping ratio zeta = sigma / sqrt(sigma² + w²) are reported with the
 *      fit's R², the segment's length in periods of f1 and the standard
 *      error of f1 from the fit's covariance.
 * Refused (a code and a static reason): a segment shorter than min_periods
 * periods of the peak, no peak in the band, a fit that fails, a damping
 * ratio outside [0, max_zeta], an f1 outside the band, R² below min_r2 (too
 * noisy), or a standard error of f1 above max_se_frac of it.
 *
 * Pure computation, no I/O; allocates per call (work arrays, the GSL
 * workspace). Any thread: no state beyond the call.
 */
#ifndef AMFI_INDICATORS_NATFREQ_H
#define AMFI_INDICATORS_NATFREQ_H

#include <stddef.h>

#define AMFI_NATFREQ_MAX_MODES 3

typedef struct amfi_natfreq_params {
    double f_lo_hz, f_hi_hz; /* band of the first mode, 0 < lo < hi */
    int n_modes;             /* modes fitted, 1 .. AMFI_NATFREQ_MAX_MODES */
    double min_periods;      /* shortest segment, periods of the peak, >= 1 */
    double min_r2;           /* least fit R², [0, 1) */
    double max_zeta;         /* largest damping ratio accepted, (0, 1) */
    double max_se_frac;      /* largest standard error of f1 over f1, > 0 */
} amfi_natfreq_params;

/* Defaults: band 0.5 .. 50 Hz, 2 modes, 4 periods, R² 0.8, zeta 0.2, SE 1 %. */
void amfi_natfreq_params_default(amfi_natfreq_params *p);

/* 0 when valid, else -1 with err naming the parameter. */
int amfi_natfreq_params_check(const amfi_natfreq_params *p, char *err, size_t errlen);

enum {
    AMFI_NATFREQ_OK = 0,
    AMFI_NATFREQ_EINVAL = -1,   /* bad argument (n < 8, rate, params) */
    AMFI_NATFREQ_SHORT = 1,     /* fewer than min_periods periods */
    AMFI_NATFREQ_NOPEAK = 2,    /* no peak in the band (flat, or at its edge) */
    AMFI_NATFREQ_NOFIT = 3,     /* the fit failed or left the band */
    AMFI_NATFREQ_DAMPING = 4,   /* zeta outside [0, max_zeta] */
    AMFI_NATFREQ_NOISY = 5,     /* R² below min_r2 or SE above max_se_frac */
    AMFI_NATFREQ_NREFUSALS = 6  /* count of codes 0 .. 5, for counters */
};

/* A short name of a code ("ok", "short", "no_peak", "no_fit", "damping",
 * "noisy", "invalid"), static. */
const char *amfi_natfreq_code_name(int code);

typedef struct amfi_natfreq_result {
    double f1_hz;       /* undamped natural frequency of mode 1 (NaN when refused) */
    double zeta;        /* its damping ratio */
    double f1_se_hz;    /* standard error of f1 from the fit */
    double f_peak_hz;   /* the periodogram's refined peak (step 1) */
    double r2;          /* fit R² over the segment */
    double periods;     /* segment length in periods of the peak */
    double amplitude;   /* mode 1's amplitude at the segment's start, input units */
    int n_modes;        /* modes fitted */
    const char *reason; /* why refused (static), "" when accepted */
} amfi_natfreq_result;

/* Estimate from x[0 .. n − 1] sampled at rate_hz. The result is filled as
 * far as the estimate got (f_peak_hz, periods, r2 when known; NaN
 * otherwise). Returns AMFI_NATFREQ_OK or a code above. */
int amfi_natfreq_estimate(const double *x, int n, double rate_hz, const amfi_natfreq_params *p,
                          amfi_natfreq_result *r);

#endif
