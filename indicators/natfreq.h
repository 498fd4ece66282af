/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * natfreq.h: the bridge's first natural frequency and its damping ratio
 * from a segment of free vibration (issue 14, item 4): the acceleration
 * one sensor records after the last axle has left the span.
 *
 * Method (measured in tests/indicators/test_natfreq.c, docs/indicators.md section 9):
 *   1. the mean is removed; a Hann-windowed periodogram, zero-padded to at
 *      least 8 times the segment, gives the strongest peak in [f_lo, f_hi]
 *      (the first mode), refined by a parabola through the log power of
 *      the three bins around it;
 *   2. the further peaks above 1.5 f_peak (up to 0.45 of the sample
 *      rate, at least 1 % of the first peak's power) start the other modes,
 *      up to n_modes in all; with `follow` set the band holds the one mode
 *      followed (amfid: a band around the site model's frequency of that
 *      mode), and the other modes are the strongest peaks outside the band,
 *      below or above it, however strong (a continuous bridge's second
 *      mode may be stronger than its first at a sensor);
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

#include "scale.h" /* the temperature model (compensation) */

#define AMFI_NATFREQ_MAX_MODES 3

typedef struct amfi_natfreq_params {
    double f_lo_hz, f_hi_hz; /* band of the first mode, 0 < lo < hi */
    int n_modes;             /* modes fitted, 1 .. AMFI_NATFREQ_MAX_MODES */
    double min_periods;      /* shortest segment, periods of the peak, >= 1 */
    double min_r2;           /* least fit R², [0, 1) */
    double max_zeta;         /* largest damping ratio accepted, (0, 1) */
    double max_se_frac;      /* largest standard error of f1 over f1, > 0 */
    int follow;              /* 0: mode 1 is the strongest peak in the band and the
                                other modes lie above 1.5 times it; 1: the band
                                holds the mode followed only, the other modes are
                                searched on both sides of it */
} amfi_natfreq_params;

/* Defaults: band 0.5 .. 50 Hz, 2 modes, 4 periods, R² 0.8, zeta 0.2, SE 1 %,
 * follow 0 (amfid sets the band and follow from its site model). */
void amfi_natfreq_params_default(amfi_natfreq_params *p);

/* 0 when valid, else -1 with err naming the parameter. */
int amfi_natfreq_params_check(const amfi_natfreq_params *p, char *err, size_t errlen);

/* The estimator's parameters for following one mode of a site model whose
 * natural circular frequencies are omega[0 .. n − 1] (rad/s, ascending:
 * amfi_bridge_omega): mode k (1-based) at f_k = omega[k − 1] / 2 pi is
 * searched in [f_k (1 − band), f_k (1 + band)], but no nearer its
 * neighbours than their geometric means with f_k (a continuous bridge's
 * first two modes may be 1.2 to 1.6 times apart and alike at a sensor:
 * docs/results/continuous-sensors.md), within site's [f_lo_hz, f_hi_hz];
 * out is site with that band and follow set, *f_mode_hz f_k. mode 0: out is
 * site unchanged (the strongest peak in its band), *f_mode_hz NaN. 0, or -1
 * with err (daemon.natural_frequency.mode beyond the model's modes, or f_k
 * outside [f_lo_hz, f_hi_hz], or band not in (0, 0.5]). */
int amfi_natfreq_follow(const amfi_natfreq_params *site, const double *omega, int n, int mode,
                        double band, amfi_natfreq_params *out, double *f_mode_hz, char *err,
                        size_t errlen);

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

/* ---- temperature compensation ---- */

/* The frequency's deck-temperature model is the scale indicator's (scale.h)
 * with f1 ∝ sqrt(E) and inferred weights ∝ 1 / E: ln f1 = c + a_w g1(T) +
 * a_f g2(T), the prior slopes −warm_slope / 2 and −frost_slope / 2 of the
 * scale's parameters (prior SD slope_prior_sd / 2), fitted by the shared
 * ridge regression (amfi_temp_ridge) over the first baseline_n estimates
 * with a deck temperature, the ridge weight from the fit's own residual
 * variance. Compensated: f1 · amfi_scale_temp_factor(tp, a_w, a_f, T), f1
 * at the calibration temperature tp.ref_c. Allocation only at create; one
 * handle, one thread. */
typedef struct amfi_natfreq_comp amfi_natfreq_comp;

typedef struct amfi_natfreq_model {
    int n;                      /* estimates in the baseline */
    double warm, frost;         /* fitted slopes of ln f1, 1/°C */
    double f_ref_hz;            /* mean compensated f1 of the baseline, Hz */
    double sd_rel;              /* SD of the baseline's compensated ln f1 */
    double t_min_c, t_max_c;    /* its deck temperature range */
} amfi_natfreq_model;

/* tp: the scale indicator's parameters (knee, floor, ref, prior slopes and
 * their SD; scale.h); baseline_n >= 10. 0, or AMFI_NATFREQ_EINVAL (err). */
int amfi_natfreq_comp_create(const amfi_scale_params *tp, int baseline_n,
                             amfi_natfreq_comp **out, char *err, size_t errlen);
void amfi_natfreq_comp_destroy(amfi_natfreq_comp *c); /* NULL-safe */

/* One accepted estimate and the deck temperature at its time: collected
 * until the baseline is full, then fitted. Returns 1 when this push
 * completed the baseline (the model exists from now on), 0 otherwise,
 * AMFI_NATFREQ_EINVAL for f1 not in (0, 1000] or T not finite (nothing
 * changes then). After the baseline it does nothing (0). */
int amfi_natfreq_comp_push(amfi_natfreq_comp *c, double f1_hz, double deck_c);

/* f1 at the calibration temperature; NaN before the baseline or for a T
 * that is not finite. */
double amfi_natfreq_comp_apply(const amfi_natfreq_comp *c, double f1_hz, double deck_c);

/* 1 and *m once the baseline is fitted, else 0. */
int amfi_natfreq_comp_model(const amfi_natfreq_comp *c, amfi_natfreq_model *m);

#endif
