/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cusum.h: a one-sided upper CUSUM (Page 1954) on standardized increments,
 * and its threshold from a target average run length (ARL) under the null
 * by Siegmund's approximation (Siegmund 1985, "Sequential Analysis", eq.
 * 2.57; docs/indicators.md, "Scale indicator"), used by the scale and the
 * known-truck indicators (scale.h, known_truck.h).
 *
 *   S_0 = 0,  S_k = max(0, S_{k-1} + z_k − k_ref),  alarm when S_k >= h.
 *
 * z_k are the observations standardized under the null (mean 0, SD 1);
 * k_ref is half the standardized shift the test is tuned for. Siegmund's
 * approximation of the ARL for increments N(mu, 1):
 *
 *   ARL(mu) ≈ (exp(−2 Δ b) + 2 Δ b − 1) / (2 Δ²),  Δ = mu − k_ref,
 *   b = h + 1.166                                     (b² when Δ = 0).
 *
 * Pure computation, no allocation, no global state; a value type owned by
 * its caller (one thread at a time).
 */
#ifndef AMFI_INDICATORS_CUSUM_H
#define AMFI_INDICATORS_CUSUM_H

typedef struct amfi_cusum {
    double k_ref;   /* reference value (half the design shift), SD units, > 0 */
    double h;       /* decision threshold, SD units, > 0 */
    double s;       /* the statistic S_k */
    long n;         /* increments since the last reset */
    int alerted;    /* the alert rule's state (amfi_cusum_alert_step) */
    int zero_run;   /* increments in a row with S = 0 while alerted */
} amfi_cusum;

/* Siegmund's approximation of the ARL (in increments) of the CUSUM (k_ref,
 * h) when the increments are N(mu, 1). */
double amfi_cusum_arl(double k_ref, double h, double mu);

/* The threshold h >= 0 whose ARL at increments N(mu, 1) is arl0 (>= 1), by
 * bisection on amfi_cusum_arl (monotone in h); mu = 0 is the plain null,
 * 0 <= mu < k_ref a null whose mean is uncertain by mu (a margin). Returns
 * a negative value when k_ref <= 0, mu outside [0, k_ref), arl0 < 1 or any
 * is not finite. */
double amfi_cusum_threshold(double k_ref, double arl0, double mu);

/* S = 0, n = 0, not alerted, with the given k_ref and h. */
void amfi_cusum_init(amfi_cusum *c, double k_ref, double h);

/* Add one standardized increment z (finite); returns 1 when S >= h after
 * it, else 0. The statistic is not reset by an alarm (the caller decides). */
int amfi_cusum_add(amfi_cusum *c, double z);

/* S = 0, n = 0 (the alert state stays). */
void amfi_cusum_reset(amfi_cusum *c);

/* The alert rule of the scale and known-truck indicators: add z; when not
 * alerted and S >= h, raise (returns 1); while alerted, S is capped at h
 * (a clear does not wait for the evidence of a long alert to drain) and
 * the alert clears after clear_after increments in a row with S = 0
 * (returns −1); otherwise 0. */
int amfi_cusum_alert_step(amfi_cusum *c, double z, int clear_after);

/* Restore the alert state (after a restart): 0 or 1. */
void amfi_cusum_set_alerted(amfi_cusum *c, int alerted);

#endif
