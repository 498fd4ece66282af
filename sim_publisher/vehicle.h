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

#include "amfi/amfi.h"

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

/* ---- the general linear multi-body vehicle ------------------------------
 *
 * One rigid body (a rigid truck) or two (a tractor, body 0, and a
 * semi-trailer, body 1, joined at the fifth wheel), 2 .. AMFI_MAX_AXLES
 * axles, each with its unsprung mass, suspension spring and damper to the
 * body above it and tyre spring to the road. Coordinates as the half-car's:
 * positive downward from static equilibrium, a pitch positive when the rear
 * goes down, positions x measured backward from axle 1.
 *
 * DOFs: tractor (or rigid body) heave z0 and pitch θ0; the semi-trailer's
 * pitch θ1 (its heave is eliminated by the fifth-wheel constraint: the
 * trailer's displacement at the kingpin x_k equals the tractor's there,
 * z1(x) = z0 + θ0·(x_k − x_cg0) + θ1·(x − x_k), the pitch free); one hop
 * per axle. A one-body vehicle has 2 + n_axles DOFs, an articulated one
 * 3 + n_axles (at most AMFI_TRUCK_MAX_DOF). The half-car is the one-body
 * two-axle case, with the same DOF order (z, θ, y_u1, y_u2).
 *
 * Suspension: axles with share[i] = 0 have their own spring; axles with the
 * same share[i] > 0 (adjacent axles of one body: a walking beam or air
 * springs joined by a line) have one load-sharing spring of stiffness
 * mean(ks) whose force is the same on every axle of the set,
 * F = k̄·mean(e) with e the suspension deflections (potential
 * k̄/(2n)·(Σe)²); their dampers stay per axle. Static axle loads W_N are
 * an input (the design loads; the dynamic model runs about that static
 * state) and must be in equilibrium with the masses (amfi_truck_finish). */
#define AMFI_TRUCK_MAX_BODIES 2
#define AMFI_TRUCK_MAX_DOF (AMFI_TRUCK_MAX_BODIES + 1 + AMFI_MAX_AXLES)

typedef struct amfi_truck {
    int n_axles;                   /* 2 .. AMFI_MAX_AXLES; 0: not set */
    int n_bodies;                  /* 1 rigid, 2 tractor + semi-trailer */
    double x_m[AMFI_MAX_AXLES];    /* axle i behind axle 1, x_m[0] = 0, increasing */
    int body[AMFI_MAX_AXLES];      /* 0, or 1 for the semi-trailer's axles (the last ones) */
    int share[AMFI_MAX_AXLES];     /* load-sharing set (>= 1, adjacent axles) or 0 */
    double mu_kg[AMFI_MAX_AXLES];  /* unsprung masses, > 0 */
    double ks_Nm[AMFI_MAX_AXLES];  /* suspension stiffness, > 0 */
    double cs_Nsm[AMFI_MAX_AXLES]; /* suspension damping, >= 0 */
    double kt_Nm[AMFI_MAX_AXLES];  /* tyre stiffness, >= 0 */
    double W_N[AMFI_MAX_AXLES];    /* static axle loads, > mu·g */
    double ms_kg[AMFI_TRUCK_MAX_BODIES];   /* body (sprung) masses, > 0 */
    double Is_kgm2[AMFI_TRUCK_MAX_BODIES]; /* pitch inertias about the CG, > 0 */
    double xcg_m[AMFI_TRUCK_MAX_BODIES];   /* CG behind axle 1 */
    double xk_m;                   /* fifth wheel (kingpin) behind axle 1 */
    double Fk_N;                   /* static kingpin load (derived: amfi_truck_finish) */
} amfi_truck;

/* Check a truck: ranges, layout (every body supported at two places at
 * least, counting a load-sharing set once and the kingpin for the
 * trailer), load-sharing sets with equal static spring forces
 * (W − mu·g, to 1e-6), every body in static equilibrium of forces and
 * moments (to 1e-6 of its weight and weight × length); sets Fk_N.
 * 0, or −1 with a message. */
int amfi_truck_finish(amfi_truck *t, char *err, size_t errlen);

/* The half-car as a one-body two-axle truck (v finished first). */
int amfi_truck_from_halfcar(const amfi_halfcar *v, amfi_truck *t, char *err, size_t errlen);

/* Number of DOFs and the index of axle 0's hop DOF (the others follow). */
int amfi_truck_ndof(const amfi_truck *t);
int amfi_truck_hop0(const amfi_truck *t);

/* Mass, damping and stiffness matrices (row-major, ndof × ndof) of the
 * vehicle on its suspension, without the tyres; add kt on the hop
 * diagonal for the vehicle on a rigid road. Returns ndof. */
int amfi_truck_matrices(const amfi_truck *t, double *M, double *C, double *K);

/* Row vector g (AMFI_TRUCK_MAX_DOF) of the displacement of body `body`'s
 * point at x: the displacement there is g·u. */
void amfi_truck_body_point(const amfi_truck *t, int body, double x_m, double *g);

#endif
