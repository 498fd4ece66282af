/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vehicle.h: the half-car vehicle of docs/simulator.md (paper §3.1, Table 2).
 *
 * Four DOF, all positive downward and measured from static equilibrium on a
 * flat rigid road: body bounce y_s, body pitch θ (positive when the rear
 * goes down), front and rear axle hop y_u1, y_u2. Axle 1 (front) is D1 ahead
 * of the body's centre of gravity, axle 2 is D2 behind it.
 */
#ifndef AMFI_VEHICLE_H
#define AMFI_VEHICLE_H

#include <gsl/gsl_rng.h>
#include <stddef.h>

typedef struct amfi_halfcar {
    double ms_kg;      /* sprung (body) mass, > 0 */
    double Is_kgm2;    /* body pitch inertia, > 0 (assumed ms·D1·D2) */
    double mu_kg[2];   /* unsprung masses, front, rear, > 0 */
    double ks_Nm[2];   /* suspension stiffness, > 0 */
    double cs_Nsm[2];  /* suspension damping, >= 0 */
    double kt_Nm[2];   /* tyre stiffness, >= 0 (0: a constant moving force) */
    double D1_m, D2_m; /* CG to front / rear axle, > 0; spacing S = D1 + D2 */
    double W_N[2];     /* static axle loads (derived: amfi_halfcar_finish) */
} amfi_halfcar;

/* Derive the static axle loads from masses and geometry. Returns 0, or −1
 * with a message when a value is out of range. */
int amfi_halfcar_finish(amfi_halfcar *v, char *err, size_t errlen);

/* The baseline 18 t vehicle of docs/simulator.md: Table 2 means, S = 5 m,
 * D1 = 2.13 m, D2 = 2.87 m (static loads 102.0 and 74.6 kN). */
void amfi_halfcar_baseline(amfi_halfcar *v);

/* Table 2 mechanical properties as (mean, std) pairs. */
typedef struct amfi_halfcar_dist {
    double mu_kg[2][2], ks_Nm[2][2], cs_Nsm[2][2], kt_Nm[2][2];
    double trunc_sigma; /* each draw truncated to mean ± trunc_sigma·std */
} amfi_halfcar_dist;

void amfi_halfcar_dist_paper(amfi_halfcar_dist *d); /* Table 2, ± 2σ */

/* A vehicle from its weights (a WIM record) and Table 2: every property drawn
 * from its truncated normal (rng may be NULL: the means); the unsprung
 * masses are also kept below half their axle's load so that the body
 * carries weight on both axles; the body mass is GVW − Σ unsprung; D1, D2
 * from the axle-load split (static equilibrium of the body):
 * D2 = S·(axle1 − mu1)/ms, D1 = S − D2. Returns 0 or −1 with a message. */
int amfi_halfcar_from_weights(double gvw_kg, double axle1_kg, double axle2_kg, double spacing_m,
                              const amfi_halfcar_dist *d, gsl_rng *rng, amfi_halfcar *v,
                              char *err, size_t errlen);

#endif
