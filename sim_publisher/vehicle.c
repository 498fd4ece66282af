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

/* ---- the general linear multi-body vehicle (vehicle.h) ------------------- */

#include <string.h>

#define TFAIL(...) (err && errlen ? snprintf(err, errlen, __VA_ARGS__) : 0, -1)

int amfi_truck_ndof(const amfi_truck *t) { return amfi_truck_hop0(t) + t->n_axles; }
int amfi_truck_hop0(const amfi_truck *t) { return t->n_bodies == 2 ? 3 : 2; }

void amfi_truck_body_point(const amfi_truck *t, int body, double x_m, double *g)
{
    memset(g, 0, sizeof(double) * AMFI_TRUCK_MAX_DOF);
    g[0] = 1.0;
    if (body == 0) {
        g[1] = x_m - t->xcg_m[0];
    } else { /* through the kingpin: z0 + θ0·(x_k − x_cg0) + θ1·(x − x_k) */
        g[1] = t->xk_m - t->xcg_m[0];
        g[2] = x_m - t->xk_m;
    }
}

int amfi_truck_finish(amfi_truck *t, char *err, size_t errlen)
{
    const int n = t->n_axles, nb = t->n_bodies;
    if (n < 2 || n > AMFI_MAX_AXLES)
        return TFAIL("%d axles (2 .. %d)", n, AMFI_MAX_AXLES);
    if (nb < 1 || nb > AMFI_TRUCK_MAX_BODIES)
        return TFAIL("%d bodies (1 or 2)", nb);
    if (t->x_m[0] != 0.0)
        return TFAIL("axle 1 at %g m, not 0", t->x_m[0]);
    for (int i = 0; i < n; i++) {
        if (i > 0 && !(t->x_m[i] - t->x_m[i - 1] >= 0.3 && t->x_m[i] - t->x_m[i - 1] <= 30.0))
            return TFAIL("axle %d is %g m behind axle %d (0.3 .. 30 m)", i + 1,
                         t->x_m[i] - t->x_m[i - 1], i);
        if (t->body[i] < 0 || t->body[i] >= nb || (i > 0 && t->body[i] < t->body[i - 1]))
            return TFAIL("axle %d on body %d: the bodies' axles must follow each other", i + 1,
                         t->body[i]);
        if (!(t->mu_kg[i] > 0) || !(t->mu_kg[i] < 1e4))
            return TFAIL("axle %d: unsprung mass %g kg out of (0, 10000)", i + 1, t->mu_kg[i]);
        if (!(t->ks_Nm[i] > 0) || !(t->ks_Nm[i] < 1e9))
            return TFAIL("axle %d: suspension stiffness %g N/m out of (0, 1e9)", i + 1,
                         t->ks_Nm[i]);
        if (!(t->cs_Nsm[i] >= 0) || !(t->cs_Nsm[i] < 1e8) || !(t->kt_Nm[i] >= 0) ||
            !(t->kt_Nm[i] < 1e10))
            return TFAIL("axle %d: damping %g N·s/m or tyre stiffness %g N/m out of range", i + 1,
                         t->cs_Nsm[i], t->kt_Nm[i]);
        if (!(t->W_N[i] > t->mu_kg[i] * AMFI_GRAVITY) || !(t->W_N[i] < 1e6))
            return TFAIL("axle %d: static load %g N not above its unsprung weight %g N (or "
                         "above 1e6 N)",
                         i + 1, t->W_N[i], t->mu_kg[i] * AMFI_GRAVITY);
        if (t->share[i] < 0)
            return TFAIL("axle %d: load-sharing set %d < 0", i + 1, t->share[i]);
        if (t->share[i] > 0) {
            int j = i - 1; /* the set's previous axle must be the one before */
            int seen = 0;
            for (int k = 0; k < i; k++)
                if (t->share[k] == t->share[i])
                    seen = 1;
            if (seen && (t->share[j] != t->share[i] || t->body[j] != t->body[i]))
                return TFAIL("axle %d: load-sharing set %d is not adjacent axles of one body",
                             i + 1, t->share[i]);
            if (seen) {
                double a = t->W_N[i] - t->mu_kg[i] * AMFI_GRAVITY,
                       b = t->W_N[j] - t->mu_kg[j] * AMFI_GRAVITY;
                if (!(fabs(a - b) <= 1e-6 * fmax(a, b)))
                    return TFAIL("axles %d and %d share their suspension but carry %g and %g N "
                                 "on their springs",
                                 j + 1, i + 1, b, a);
            }
        }
    }
    if (t->body[0] != 0 || t->body[n - 1] != nb - 1)
        return TFAIL("every one of the %d bodies needs axles", nb);
    for (int b = 0; b < nb; b++) {
        if (!(t->ms_kg[b] > 0) || !(t->Is_kgm2[b] > 0))
            return TFAIL("body %d: mass %g kg and pitch inertia %g kg·m² must be > 0", b + 1,
                         t->ms_kg[b], t->Is_kgm2[b]);
        /* supports: independent axles, load-sharing sets once, the kingpin */
        int sup = b == 1;
        for (int i = 0; i < n; i++)
            if (t->body[i] == b && (t->share[i] == 0 || i == 0 || t->share[i - 1] != t->share[i]))
                sup++;
        if (sup < 2)
            return TFAIL("body %d rests on %d support (a load-sharing group counts once): its "
                         "pitch is free",
                         b + 1, sup);
    }
    if (nb == 2) {
        int last0 = 0;
        while (t->body[last0 + 1] == 0)
            last0++;
        if (!(t->xk_m >= -1.0 && t->xk_m <= t->x_m[last0] + 1.5 && t->xk_m < t->x_m[last0 + 1]))
            return TFAIL("kingpin at %g m: not over the tractor (axle 1 − 1 m .. last tractor "
                         "axle + 1.5 m)",
                         t->xk_m);
    }
    /* static equilibrium, trailer first: the kingpin load from its forces */
    const double g = AMFI_GRAVITY;
    double S[AMFI_MAX_AXLES];
    for (int i = 0; i < n; i++)
        S[i] = t->W_N[i] - t->mu_kg[i] * g;
    t->Fk_N = 0.0;
    for (int b = nb - 1; b >= 0; b--) {
        double F = -t->ms_kg[b] * g, Mo = -t->ms_kg[b] * g * t->xcg_m[b], len = 0.0;
        for (int i = 0; i < n; i++)
            if (t->body[i] == b) {
                F += S[i];
                Mo += S[i] * t->x_m[i];
                len = fmax(len, fabs(t->x_m[i] - t->xcg_m[b]));
            }
        if (b == 1) {
            t->Fk_N = -F; /* the kingpin carries the rest */
            Mo += t->Fk_N * t->xk_m;
            F = 0.0;
            if (!(t->Fk_N >= 0))
                return TFAIL("the semi-trailer's axles carry %g N more than its weight: the "
                             "kingpin would pull",
                             -t->Fk_N);
        } else if (nb == 2) {
            F -= t->Fk_N;
            Mo -= t->Fk_N * t->xk_m;
        }
        const double W = t->ms_kg[b] * g + (b == 0 ? t->Fk_N : 0.0);
        if (!(fabs(F) <= 1e-6 * W) || !(fabs(Mo) <= 1e-6 * W * fmax(len, 1.0)))
            return TFAIL("body %d is not in static equilibrium (force %g N, moment %g N·m "
                         "left)",
                         b + 1, F, Mo);
    }
    return 0;
}

int amfi_truck_from_halfcar(const amfi_halfcar *v, amfi_truck *t, char *err, size_t errlen)
{
    memset(t, 0, sizeof *t);
    t->n_axles = 2;
    t->n_bodies = 1;
    t->x_m[1] = v->D1_m + v->D2_m;
    t->xcg_m[0] = v->D1_m;
    t->ms_kg[0] = v->ms_kg;
    t->Is_kgm2[0] = v->Is_kgm2;
    for (int i = 0; i < 2; i++) {
        t->mu_kg[i] = v->mu_kg[i];
        t->ks_Nm[i] = v->ks_Nm[i];
        t->cs_Nsm[i] = v->cs_Nsm[i];
        t->kt_Nm[i] = v->kt_Nm[i];
        t->W_N[i] = v->W_N[i];
    }
    return amfi_truck_finish(t, err, errlen);
}

int amfi_truck_matrices(const amfi_truck *t, double *M, double *C, double *K)
{
    const int nd = amfi_truck_ndof(t), h0 = amfi_truck_hop0(t), n = t->n_axles;
    memset(M, 0, sizeof(double) * nd * nd);
    memset(C, 0, sizeof(double) * nd * nd);
    memset(K, 0, sizeof(double) * nd * nd);
    double g[AMFI_TRUCK_MAX_DOF];
    /* bodies: the mass at its CG through g, the pitch inertia on its angle */
    for (int b = 0; b < t->n_bodies; b++) {
        amfi_truck_body_point(t, b, t->xcg_m[b], g);
        for (int r = 0; r < h0; r++)
            for (int q = 0; q < h0; q++)
                M[r * nd + q] += t->ms_kg[b] * g[r] * g[q];
        M[(1 + b) * nd + 1 + b] += t->Is_kgm2[b];
    }
    for (int i = 0; i < n; i++)
        M[(h0 + i) * nd + h0 + i] = t->mu_kg[i];
    /* suspensions: deflection e_i = d_i·u, d_i = g(x_i) − e_hop(i) */
    double d[AMFI_MAX_AXLES][AMFI_TRUCK_MAX_DOF];
    for (int i = 0; i < n; i++) {
        amfi_truck_body_point(t, t->body[i], t->x_m[i], d[i]);
        d[i][h0 + i] = -1.0;
        for (int r = 0; r < nd; r++)
            for (int q = 0; q < nd; q++)
                C[r * nd + q] += t->cs_Nsm[i] * d[i][r] * d[i][q];
    }
    for (int i = 0; i < n;) {
        int j = i + 1;
        if (t->share[i] > 0)
            while (j < n && t->share[j] == t->share[i])
                j++;
        /* one spring over axles i .. j−1: k̄/m·(Σ d)(Σ d)ᵀ, m = j − i */
        double ds[AMFI_TRUCK_MAX_DOF] = {0}, kbar = 0.0;
        for (int a = i; a < j; a++) {
            kbar += t->ks_Nm[a] / (j - i);
            for (int r = 0; r < nd; r++)
                ds[r] += d[a][r];
        }
        for (int r = 0; r < nd; r++)
            for (int q = 0; q < nd; q++)
                K[r * nd + q] += kbar / (j - i) * ds[r] * ds[q];
        i = j;
    }
    return nd;
}
