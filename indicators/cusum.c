/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cusum.c: the one-sided CUSUM and Siegmund's ARL approximation (cusum.h).
 * Pure computation; the caller owns the state.
 */
#include "cusum.h"

#include <math.h>

double amfi_cusum_arl(double k_ref, double h, double mu)
{
    const double d = mu - k_ref, b = h + 1.166, x = 2.0 * d * b;
    /* exp(−x) + x − 1 loses all its digits for small x: the series there */
    if (fabs(x) < 1e-3)
        return b * b * (1.0 - x / 3.0 + x * x / 12.0);
    return (expm1(-x) + x) / (2.0 * d * d);
}

double amfi_cusum_threshold(double k_ref, double arl0, double mu)
{
    if (!isfinite(k_ref) || !isfinite(arl0) || !isfinite(mu) || k_ref <= 0.0 || arl0 < 1.0 ||
        mu < 0.0 || mu >= k_ref)
        return -1.0;
    if (amfi_cusum_arl(k_ref, 0.0, mu) >= arl0)
        return 0.0;
    double lo = 0.0, hi = 1.0;
    while (amfi_cusum_arl(k_ref, hi, mu) < arl0) {
        lo = hi;
        hi *= 2.0;
        if (hi > 1e6)
            return -1.0;
    }
    for (int i = 0; i < 100 && hi - lo > 1e-10 * hi; i++) {
        const double m = 0.5 * (lo + hi);
        if (amfi_cusum_arl(k_ref, m, mu) < arl0)
            lo = m;
        else
            hi = m;
    }
    return hi;
}

void amfi_cusum_init(amfi_cusum *c, double k_ref, double h)
{
    c->k_ref = k_ref;
    c->h = h;
    c->s = 0.0;
    c->n = 0;
    c->alerted = 0;
    c->zero_run = 0;
}

int amfi_cusum_add(amfi_cusum *c, double z)
{
    c->s += z - c->k_ref;
    if (c->s < 0.0)
        c->s = 0.0;
    c->n++;
    return c->s >= c->h;
}

void amfi_cusum_reset(amfi_cusum *c)
{
    c->s = 0.0;
    c->n = 0;
}

int amfi_cusum_alert_step(amfi_cusum *c, double z, int clear_after)
{
    const int over = amfi_cusum_add(c, z);
    if (!c->alerted) {
        if (!over)
            return 0;
        c->alerted = 1;
        c->zero_run = 0;
        return 1;
    }
    if (c->s > c->h)
        c->s = c->h;
    c->zero_run = c->s > 0 ? 0 : c->zero_run + 1;
    if (c->zero_run < clear_after)
        return 0;
    c->alerted = 0;
    c->zero_run = 0;
    return -1;
}

void amfi_cusum_set_alerted(amfi_cusum *c, int alerted)
{
    c->alerted = alerted != 0;
    c->zero_run = 0;
}
