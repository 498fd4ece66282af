/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vehicle.c: half-car parameters, the baseline vehicle and per-vehicle draws
 * from the paper's Table 2.
 */
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdio.h>

#include "amfi/amfi.h"
#include "vehicle.h"

static int fail(char *err, size_t errlen, const char *msg, double v)
{
    if (err && errlen)
        snprintf(err, errlen, msg, v);
    return -1;
}

int amfi_halfcar_finish(amfi_halfcar *v, char *err, size_t errlen)
{
    if (!(v->ms_kg > 0))
        return fail(err, errlen, "body mass must be > 0 (got %g kg)", v->ms_kg);
    if (!(v->Is_kgm2 > 0))
        return fail(err, errlen, "pitch inertia must be > 0 (got %g)", v->Is_kgm2);
    if (!(v->D1_m > 0) || !(v->D2_m > 0))
        return fail(err, errlen, "the CG must lie between the axles (D1 = %g m)", v->D1_m);
    for (int i = 0; i < 2; i++) {
        if (!(v->mu_kg[i] > 0))
            return fail(err, errlen, "unsprung mass must be > 0 (got %g kg)", v->mu_kg[i]);
        if (!(v->ks_Nm[i] > 0))
            return fail(err, errlen, "suspension stiffness must be > 0 (got %g)", v->ks_Nm[i]);
        if (!(v->cs_Nsm[i] >= 0) || !(v->kt_Nm[i] >= 0))
            return fail(err, errlen, "damping and tyre stiffness must be >= 0 (got %g)",
                        v->cs_Nsm[i] < 0 ? v->cs_Nsm[i] : v->kt_Nm[i]);
    }
    const double S = v->D1_m + v->D2_m;
    v->W_N[0] = (v->ms_kg * v->D2_m / S + v->mu_kg[0]) * AMFI_GRAVITY;
    v->W_N[1] = (v->ms_kg * v->D1_m / S + v->mu_kg[1]) * AMFI_GRAVITY;
    return 0;
}

void amfi_halfcar_baseline(amfi_halfcar *v)
{
    *v = (amfi_halfcar){0};
    v->mu_kg[0] = 1100.0;
    v->mu_kg[1] = 700.0;
    v->ms_kg = 18000.0 - 1100.0 - 700.0;
    v->D1_m = 2.13;
    v->D2_m = 2.87;
    v->Is_kgm2 = v->ms_kg * v->D1_m * v->D2_m; /* assumed, docs/simulator.md */
    v->ks_Nm[0] = 0.4e6;
    v->ks_Nm[1] = 1.0e6;
    v->cs_Nsm[0] = 10e3;
    v->cs_Nsm[1] = 20e3;
    v->kt_Nm[0] = 1.75e6;
    v->kt_Nm[1] = 1.75e6;
    amfi_halfcar_finish(v, NULL, 0);
}

void amfi_halfcar_dist_paper(amfi_halfcar_dist *d)
{
    *d = (amfi_halfcar_dist){
        .mu_kg = {{1100.0, 300.0}, {700.0, 250.0}},
        .ks_Nm = {{0.4e6, 0.1e6}, {1.0e6, 0.3e6}},
        .cs_Nsm = {{10e3, 2.5e3}, {20e3, 5e3}},
        .kt_Nm = {{1.75e6, 0.5e6}, {1.75e6, 0.5e6}},
        .trunc_sigma = 2.0,
    };
}

/* Truncated normal by rejection on [max(lo, mean − kσ), min(hi, mean + kσ)]. */
static double draw(gsl_rng *rng, const double ms[2], double k, double lo, double hi)
{
    double a = fmax(lo, ms[0] - k * ms[1]), b = fmin(hi, ms[0] + k * ms[1]);
    if (!rng || !(b > a))
        return fmin(fmax(ms[0], a), b > a ? b : a);
    for (int i = 0; i < 10000; i++) {
        double x = ms[0] + gsl_ran_gaussian(rng, ms[1]);
        if (x >= a && x <= b)
            return x;
    }
    return a + (b - a) * gsl_rng_uniform(rng); /* a sliver of the tail: uniform */
}

int amfi_halfcar_from_weights(double gvw_kg, double axle1_kg, double axle2_kg, double spacing_m,
                              const amfi_halfcar_dist *d, gsl_rng *rng, amfi_halfcar *v,
                              char *err, size_t errlen)
{
    if (!(gvw_kg > 0) || !(axle1_kg > 0) || !(axle2_kg > 0) || !(spacing_m > 0))
        return fail(err, errlen, "weights and spacing must be > 0 (GVW %g kg)", gvw_kg);
    const double k = d->trunc_sigma;
    *v = (amfi_halfcar){0};
    v->mu_kg[0] = draw(rng, d->mu_kg[0], k, 50.0, 0.5 * axle1_kg);
    v->mu_kg[1] = draw(rng, d->mu_kg[1], k, 50.0, 0.5 * axle2_kg);
    for (int i = 0; i < 2; i++) {
        v->ks_Nm[i] = draw(rng, d->ks_Nm[i], k, 1.0, INFINITY);
        v->cs_Nsm[i] = draw(rng, d->cs_Nsm[i], k, 0.0, INFINITY);
        v->kt_Nm[i] = draw(rng, d->kt_Nm[i], k, 1.0, INFINITY);
    }
    /* The WIM GVW is the sum of the axles; use that sum so the loads match. */
    const double total = axle1_kg + axle2_kg;
    v->ms_kg = total - v->mu_kg[0] - v->mu_kg[1];
    v->D2_m = spacing_m * (axle1_kg - v->mu_kg[0]) / v->ms_kg;
    v->D1_m = spacing_m - v->D2_m;
    v->Is_kgm2 = v->ms_kg * v->D1_m * v->D2_m;
    return amfi_halfcar_finish(v, err, errlen);
}
