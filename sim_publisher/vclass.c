/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vclass.c: the heavy-vehicle classes and their vehicle models (vclass.h;
 * figures and sources in docs/simulator.md, "Vehicle classes").
 */
#include "vclass.h"

#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define S AMFI_AXLE_STEER
#define DA AMFI_AXLE_DRIVE_AIR
#define DL AMFI_AXLE_DRIVE_LEAF
#define TA AMFI_AXLE_TRAILER_AIR
#define TL AMFI_AXLE_TRAILER_LEAF

/* Shares of heavy vehicles: A23, R2, A22 and R3 from a WIM-derived Swiss
 * traffic model; R4, A32 and A33 assumed, closing the sum to 100 %. */
static const amfi_vclass classes[] = {
    {"R2", "two-axle rigid truck (the paper's half-car)", 2, 0, {0, 1}, {0, 0}, {S, DL},
     20.3, 0.55, 7000, 1000, 12500, 2500, 3500, 18000,
     {0.55, 0.45}, {0.36, 0.64},
     {4.8}, {0.5}, {3.5}, {6.0}, 0, 0},
    {"R3", "three-axle rigid truck, steer + walking-beam tandem", 3, 0, {0, 1, 1}, {0, 1},
     {S, DL, DL}, 8.0, 0.55, 12000, 1500, 22500, 2500, 8000, 26000,
     {0.45, 0.275, 0.275}, {0.27, 0.365, 0.365},
     {4.6, 1.35}, {0.5, 0.05}, {3.4, 1.25}, {6.0, 1.45}, 0, 0},
    {"R4", "four-axle rigid truck 8x4, twin steer + walking-beam tandem", 4, 0, {0, 0, 1, 1},
     {0, 1}, {S, S, DL, DL}, 4.0, 0.55, 15000, 1500, 28500, 2500, 10000, 32000,
     {0.28, 0.28, 0.22, 0.22}, {0.21, 0.21, 0.29, 0.29},
     {1.9, 3.4, 1.35}, {0.1, 0.4, 0.05}, {1.7, 2.6, 1.25}, {2.1, 4.4, 1.45}, 0, 0},
    {"A22", "2-axle tractor + semi-trailer with a leaf-spring tandem", 4, 2, {0, 1, 2, 2},
     {0, 0, 0}, {S, DA, TL, TL}, 12.2, 0.6, 13500, 1500, 29000, 4000, 9000, 36000,
     {0.42, 0.30, 0.14, 0.14}, {0.19, 0.31, 0.25, 0.25},
     {3.7, 6.6, 1.31}, {0.2, 0.6, 0.05}, {3.3, 5.2, 1.2}, {4.2, 8.2, 1.45}, 7000, 0.5},
    {"A23", "2-axle tractor + semi-trailer with an air-sprung tridem", 5, 2, {0, 1, 2, 2, 2},
     {0, 0, 1}, {S, DA, TA, TA, TA}, 41.7, 0.65, 14500, 1500, 33000, 4500, 10000, 40000,
     {0.36, 0.30, 0.113, 0.113, 0.113}, {0.17, 0.28, 0.183, 0.183, 0.183},
     {3.75, 6.0, 1.31, 1.31}, {0.2, 0.5, 0.02, 0.02}, {3.3, 5.0, 1.25, 1.25},
     {4.2, 7.5, 1.4, 1.4}, 7000, 0.5},
    {"A32", "3-axle tractor (air tandem) + semi-trailer with an air tandem", 5, 3,
     {0, 1, 1, 2, 2}, {0, 1, 1}, {S, DA, DA, TA, TA}, 7.8, 0.65, 15500, 1500, 33500, 4500,
     10000, 40000, {0.34, 0.18, 0.18, 0.15, 0.15}, {0.17, 0.22, 0.22, 0.195, 0.195},
     {3.3, 1.35, 5.8, 1.31}, {0.2, 0.05, 0.5, 0.03}, {2.9, 1.25, 4.8, 1.25},
     {3.8, 1.45, 7.2, 1.4}, 8800, 0.3},
    {"A33", "3-axle tractor (air tandem) + semi-trailer with an air tridem (44 t: 40-ft "
            "container)",
     6, 3, {0, 1, 1, 2, 2, 2}, {0, 1, 1}, {S, DA, DA, TA, TA, TA}, 6.0, 0.65, 16500, 1500,
     36000, 5000, 11000, 44000, {0.32, 0.16, 0.16, 0.12, 0.12, 0.12},
     {0.16, 0.2, 0.2, 0.147, 0.147, 0.146},
     {3.3, 1.35, 5.3, 1.31, 1.31}, {0.2, 0.05, 0.5, 0.02, 0.02}, {2.9, 1.25, 4.3, 1.25, 1.25},
     {3.8, 1.45, 6.6, 1.4, 1.4}, 8800, 0.3},
};

#define N_CLASSES ((int)(sizeof classes / sizeof classes[0]))

int amfi_vclass_count(void) { return N_CLASSES; }
const amfi_vclass *amfi_vclass_get(int i) { return i >= 0 && i < N_CLASSES ? &classes[i] : NULL; }

int amfi_vclass_find(const char *name, size_t n)
{
    for (int i = 0; i < N_CLASSES; i++)
        if (strlen(classes[i].name) == n && !memcmp(classes[i].name, name, n))
            return i;
    return -1;
}

const char *amfi_vclass_names(void) { return "R2, R3, R4, A22, A23, A32, A33"; }

#define GROUP_MAX_M 2.5
#define BETWEEN_MIN_M 2.0

int amfi_vclass_check(const amfi_vclass *c, int n_axles, const double *spacing_m, char *err,
                      size_t errlen)
{
    if (n_axles != c->n_axles) {
        if (err && errlen)
            snprintf(err, errlen, "class %s has %d axles, not %d", c->name, c->n_axles, n_axles);
        return -1;
    }
    for (int i = 0; i < n_axles - 1; i++) {
        const int in = c->group[i] == c->group[i + 1];
        const double s = spacing_m[i];
        if (in ? !(s >= 0.9 && s <= GROUP_MAX_M) : !(s >= BETWEEN_MIN_M)) {
            if (err && errlen)
                snprintf(err, errlen,
                         in ? "spacing %d: %g m between axles %d and %d of a group of class %s "
                              "(0.9 .. 2.5 m)"
                            : "spacing %d: %g m between axles %d and %d, which are in different "
                              "groups in class %s (>= 2 m)",
                         i + 1, s, i + 1, i + 2, c->name);
            return -1;
        }
    }
    return 0;
}

int amfi_vclass_guess(int n_axles, const double *spacing_m)
{
    if (n_axles == 2)
        return 0;
    for (int i = 0; i < N_CLASSES; i++)
        if (amfi_vclass_check(&classes[i], n_axles, spacing_m, NULL, 0) == 0)
            return i;
    return -1;
}

/* ---- the vehicle model ---------------------------------------------------- */

/* Per axle type: (mean, std) of the unsprung mass (kg), the tyre stiffness
 * (N/m), and either a steel spring (N/m) and damper (N·s/m) or an air
 * spring given by its natural frequency on its static load (Hz) and damping
 * ratio (docs/simulator.md). */
typedef struct axle_law {
    double mu[2], kt[2];
    int air;
    double ks[2], cs[2]; /* steel */
    double f[2], zeta[2]; /* air */
} axle_law;

static const axle_law laws[] = {
    [AMFI_AXLE_STEER] = {{700, 100}, {1.75e6, 0.2e6}, 0, {0.6e6, 0.1e6}, {15e3, 3e3}, {0}, {0}},
    [AMFI_AXLE_DRIVE_AIR] = {{1100, 150}, {3.5e6, 0.35e6}, 1, {0}, {0}, {2.0, 0.15}, {0.2, 0.04}},
    [AMFI_AXLE_DRIVE_LEAF] = {{1100, 150}, {3.5e6, 0.35e6}, 0, {1.8e6, 0.3e6}, {35e3, 7e3}, {0},
                              {0}},
    [AMFI_AXLE_TRAILER_AIR] = {{750, 100}, {2.4e6, 0.25e6}, 1, {0}, {0}, {2.0, 0.15},
                               {0.2, 0.04}},
    [AMFI_AXLE_TRAILER_LEAF] = {{750, 100}, {2.4e6, 0.25e6}, 0, {1.6e6, 0.3e6}, {30e3, 6e3}, {0},
                                {0}},
};

/* normal(ms[0], ms[1]) truncated to ±2σ and to [lo, hi] (rng NULL: the mean,
 * clamped) */
static double draw(gsl_rng *rng, const double ms[2], double lo, double hi)
{
    double a = fmax(lo, ms[0] - 2 * ms[1]), b = fmin(hi, ms[0] + 2 * ms[1]);
    if (!(b > a))
        return fmin(fmax(ms[0], lo), hi);
    if (!rng)
        return fmin(fmax(ms[0], a), b);
    for (int i = 0; i < 1000; i++) {
        double x = ms[0] + gsl_ran_gaussian(rng, ms[1]);
        if (x >= a && x <= b)
            return x;
    }
    return a + (b - a) * gsl_rng_uniform(rng);
}

#define FAIL(...) (err && errlen ? snprintf(err, errlen, __VA_ARGS__) : 0, -1)

int amfi_vclass_truck(const amfi_vclass *c, const double *axle_kg, const double *spacing_m,
                      gsl_rng *rng, amfi_truck *t, char *err, size_t errlen)
{
    const double g = AMFI_GRAVITY;
    const int n = c->n_axles;
    memset(t, 0, sizeof *t);
    if (c->n_axles == 2 && c->tractor_axles == 0)
        return FAIL("class %s is the half-car (vehicle.h)", c->name);
    if (amfi_vclass_check(c, n, spacing_m, err, errlen))
        return -1;
    t->n_axles = n;
    t->n_bodies = c->tractor_axles ? 2 : 1;
    for (int i = 0; i < n; i++) {
        if (!(axle_kg[i] > 0 && axle_kg[i] <= 30000))
            return FAIL("axle %d: load %g kg out of (0, 30000]", i + 1, axle_kg[i]);
        t->x_m[i] = i ? t->x_m[i - 1] + spacing_m[i - 1] : 0.0;
        t->body[i] = c->tractor_axles && i >= c->tractor_axles;
        t->share[i] = c->shared[c->group[i]] ? c->group[i] + 1 : 0;
    }
    /* loads: a load-sharing group carries its sum equally */
    double W[AMFI_MAX_AXLES];
    for (int i = 0; i < n;) {
        int j = i + 1;
        while (j < n && c->group[j] == c->group[i])
            j++;
        double sum = 0.0;
        for (int a = i; a < j; a++)
            sum += axle_kg[a];
        for (int a = i; a < j; a++)
            W[a] = t->share[a] ? sum / (j - i) : axle_kg[a];
        /* properties: drawn once per load-sharing group, else per axle */
        for (int a = i; a < j; a++) {
            if (t->share[a] && a > i) {
                t->mu_kg[a] = t->mu_kg[i];
                t->ks_Nm[a] = t->ks_Nm[i];
                t->cs_Nsm[a] = t->cs_Nsm[i];
                t->kt_Nm[a] = t->kt_Nm[i];
                continue;
            }
            const axle_law *L = &laws[c->type[a]];
            t->mu_kg[a] = draw(rng, L->mu, 150.0, 0.4 * W[a]);
            t->kt_Nm[a] = draw(rng, L->kt, 1e5, INFINITY);
            const double m_s = W[a] - t->mu_kg[a]; /* kg on the spring */
            if (L->air) {
                const double w = 6.283185307179586 * draw(rng, L->f, 0.5, 5.0);
                t->ks_Nm[a] = m_s * w * w;
                t->cs_Nsm[a] = 2.0 * draw(rng, L->zeta, 0.02, 0.5) * sqrt(t->ks_Nm[a] * m_s);
            } else {
                t->ks_Nm[a] = draw(rng, L->ks, 1e4, INFINITY);
                t->cs_Nsm[a] = draw(rng, L->cs, 0.0, INFINITY);
            }
        }
        i = j;
    }
    double Ssum[2] = {0, 0}, Smom[2] = {0, 0}, Smu[2] = {0, 0};
    for (int i = 0; i < n; i++) {
        t->W_N[i] = W[i] * g;
        const double Si = (W[i] - t->mu_kg[i]) * g;
        Ssum[t->body[i]] += Si;
        Smom[t->body[i]] += Si * t->x_m[i];
        Smu[t->body[i]] += t->mu_kg[i];
    }
    if (t->n_bodies == 1) {
        t->ms_kg[0] = Ssum[0] / g;
        t->xcg_m[0] = Smom[0] / Ssum[0];
    } else {
        /* the kingpin: ahead of the tractor's drive axle or tandem centre */
        const int nt = c->tractor_axles;
        const double xd = 0.5 * (t->x_m[1] + t->x_m[nt - 1]), xt = t->x_m[nt - 1];
        const double xk = xd - c->kingpin_ahead_m;
        t->xk_m = xk;
        /* the tractor's body: its tare less its unsprung masses; the kingpin
         * carries the rest of the tractor's axle loads. Where those loads
         * put the tractor's CG outside 15 .. 85 % of its wheelbase, the CG
         * is held at that bound and the mass follows from the moments. */
        double m0 = fmin(c->tractor_tare_kg - Smu[0], 0.95 * Ssum[0] / g);
        double Fk = Ssum[0] - m0 * g;
        double x0 = (Smom[0] - Fk * xk) / (m0 * g);
        const double lo = 0.15 * xt, hi = 0.85 * xt;
        if (x0 < lo || x0 > hi) {
            x0 = x0 < lo ? lo : hi;
            /* Ssum = m0 g + Fk, Smom = m0 g x0 + Fk xk */
            m0 = (Smom[0] - Ssum[0] * xk) / (g * (x0 - xk));
            Fk = Ssum[0] - m0 * g;
        }
        if (!(m0 > 500.0) || !(Fk >= 0.0))
            return FAIL("class %s: axle loads %g, %g .. kg leave no tractor body (%g kg) and "
                        "kingpin load (%g N)",
                        c->name, axle_kg[0], axle_kg[1], m0, Fk);
        t->ms_kg[0] = m0;
        t->xcg_m[0] = x0;
        t->ms_kg[1] = (Fk + Ssum[1]) / g;
        t->xcg_m[1] = (Fk * xk + Smom[1]) / (Fk + Ssum[1]);
    }
    /* pitch inertia m·D1·D2 over the body's supports (as the half-car) */
    for (int b = 0; b < t->n_bodies; b++) {
        double front = b == 0 ? 0.0 : t->xk_m, rear = 0.0;
        for (int i = 0; i < n; i++)
            if (t->body[i] == b)
                rear = t->x_m[i];
        const double d1 = fmax(t->xcg_m[b] - front, 0.3), d2 = fmax(rear - t->xcg_m[b], 0.3);
        t->Is_kgm2[b] = t->ms_kg[b] * d1 * d2;
    }
    return amfi_truck_finish(t, err, errlen);
}
