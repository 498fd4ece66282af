/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vclass.h: the heavy-vehicle classes of the simulated traffic
 * (docs/simulator.md, "Vehicle classes"): their layout (axles, bodies,
 * axle groups and their suspensions), their share of European motorway
 * heavy traffic, their gross-weight mixture (empty and loaded), axle-load
 * shares and spacing distributions, and the vehicle model of a record of
 * a class (vehicle.h) with its mechanical properties drawn per vehicle.
 *
 *   R2   two-axle rigid (the paper's half-car, vehicle.h)
 *   R3   three-axle rigid, steer + tandem (walking-beam bogie, load sharing)
 *   R4   four-axle rigid 8x4: twin steer (independent) + tandem (bogie)
 *   A22  2-axle tractor + 2-axle semi-trailer (independent leaf tandem)
 *   A23  2-axle tractor + tridem semi-trailer (air, load sharing)
 *   A32  3-axle tractor (air tandem) + tandem semi-trailer (air)
 *   A33  3-axle tractor (air tandem) + tridem semi-trailer (air); 44 t
 *        as the 40-ft container combination
 *
 * Pure data and computation; any thread.
 */
#ifndef AMFI_SIM_VCLASS_H
#define AMFI_SIM_VCLASS_H

#include <gsl/gsl_rng.h>
#include <stddef.h>

#include "vehicle.h"

#define AMFI_VCLASS_MAX_GROUPS 4

/* Suspension and tyre types of an axle (parameters in vclass.c). */
enum amfi_axle_type {
    AMFI_AXLE_STEER,       /* steel leaf, single tyres */
    AMFI_AXLE_DRIVE_AIR,   /* air springs, twin tyres */
    AMFI_AXLE_DRIVE_LEAF,  /* steel leaf / walking-beam bogie, twin tyres */
    AMFI_AXLE_TRAILER_AIR, /* air springs, wide single tyres */
    AMFI_AXLE_TRAILER_LEAF /* steel leaf, wide single tyres */
};

typedef struct amfi_vclass {
    const char *name;       /* "R2", "A23", ... */
    const char *what;       /* one line */
    int n_axles;
    int tractor_axles;      /* 0: rigid (one body); else the tractor's axles */
    int group[AMFI_MAX_AXLES];  /* axle group, 0-based, adjacent axles */
    int shared[AMFI_VCLASS_MAX_GROUPS]; /* per group: 1 load-sharing suspension */
    enum amfi_axle_type type[AMFI_MAX_AXLES];
    double share_pct;       /* of heavy vehicles */
    /* GVW: loaded with p_loaded, normal(mu, sd) each, truncated to [lo, hi] */
    double p_loaded, empty_mu, empty_sd, loaded_mu, loaded_sd, gvw_lo, gvw_hi;
    /* axle load shares, empty and loaded (interpolated by GVW) */
    double share_empty[AMFI_MAX_AXLES], share_loaded[AMFI_MAX_AXLES];
    /* spacings: normal(mu, sd) truncated to [lo, hi] */
    double sp_mu[AMFI_MAX_AXLES], sp_sd[AMFI_MAX_AXLES], sp_lo[AMFI_MAX_AXLES],
        sp_hi[AMFI_MAX_AXLES];
    double tractor_tare_kg; /* articulated: the tractor's empty mass */
    double kingpin_ahead_m; /* articulated: the kingpin ahead of the drive axle
                               (group centre) */
} amfi_vclass;

int amfi_vclass_count(void);
const amfi_vclass *amfi_vclass_get(int i); /* 0 .. count − 1 */

/* The class named `name` (n bytes, case-sensitive), or −1. */
int amfi_vclass_find(const char *name, size_t n);

/* "R2, R3, ..." for messages. */
const char *amfi_vclass_names(void);

/* Whether n_axles − 1 spacings fit class c: its axle count, spacings
 * inside a group 0.9 .. 2.5 m, between groups >= 2.0 m. 0, or −1 with a
 * message naming the spacing (1-based). */
int amfi_vclass_check(const amfi_vclass *c, int n_axles, const double *spacing_m, char *err,
                      size_t errlen);

/* A class for a record without one (the wide format): R2 for two axles,
 * else the first class of that axle count whose check passes; −1 none. */
int amfi_vclass_guess(int n_axles, const double *spacing_m);

/* The vehicle model of a record of class c (c->n_axles loads, kg, and
 * spacings, m): body masses and centres of gravity from the static loads
 * (equilibrium), each load-sharing group's load equalised (its sum kept),
 * axle properties drawn per vehicle (rng NULL: the means). Not for R2 (the
 * half-car). 0, or −1 with a message. */
int amfi_vclass_truck(const amfi_vclass *c, const double *axle_kg, const double *spacing_m,
                      gsl_rng *rng, amfi_truck *t, char *err, size_t errlen);

#endif
