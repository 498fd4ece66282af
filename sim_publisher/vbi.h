/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vbi.h: vehicle-bridge interaction: half-car vehicles driving over a road
 * profile onto the FE bridge, the coupled system integrated in time.
 *
 * The bridge in modal coordinates (all modes of the libamfi model, which
 * equals the nodal model), each vehicle in its own 4 DOF, coupled through
 * the tyres: P_i = kt_i·(y_u,i − w(x_i) + r(x_i)) is the dynamic tyre force
 * and F_i = W_i + P_i the contact force on the bridge (downward). Newmark's
 * average acceleration (γ = 1/2, β = 1/4) on the whole coupled system: each
 * subsystem's new acceleration is linear in the contact forces, so one small
 * linear system per step (one unknown per axle in the simulation, LAPACK
 * dgesv) gives the exact implicit coupling. A tyre that would pull
 * (F_i < 0) has left the road: its force is set to zero (P_i = −W_i), the
 * system re-solved, and the lost-contact steps counted per axle.
 *
 * Road coordinate: x = 0 at the bridge entry, the bridge on [0, L]; ahead of
 * it a rigid approach. The profile's own coordinate is x + approach_m +
 * AMFI_SIM_PROFILE_LEAD_M (so the rear axle's start is inside the profile).
 *
 * Vehicles: the half-car, or any linear multi-body vehicle of vehicle.h
 * (rigid trucks, tractor and semi-trailer, load-sharing axle groups): each
 * has its own n DOFs (S_v n × n), one unknown per axle in the coupling.
 *
 * Workload: one simulation per bridge state; vehicles are added in any
 * order before they start their approach, and leave after exit_m past the
 * bridge. Cost per step O(n_modes·axles² + axles³) over all the axles in
 * the simulation; nothing is allocated per step.
 */
#ifndef AMFI_VBI_H
#define AMFI_VBI_H

#include <stddef.h>

#include "amfi/amfi.h"
#include "profile.h"
#include "vehicle.h"

#define AMFI_SIM_MAX_ACTIVE 16   /* vehicles in the simulation at once */
#define AMFI_SIM_MAX_PENDING 256 /* added, not yet started */
#define AMFI_SIM_PROFILE_LEAD_M 30.0

typedef struct amfi_sim_params {
    double dt_s;         /* integration step; 1/(scan_rate·dt) must be an integer */
    double scan_rate_hz; /* accelerometer sampling rate */
    double approach_m;   /* rigid approach driven before the bridge (100 m) */
    double exit_m;       /* driven after the bridge before a vehicle leaves */
    int n_sensors;       /* 1 .. AMFI_MAX_SENSORS */
    double sensor_x_m[AMFI_MAX_SENSORS];
} amfi_sim_params;

/* dt 0.1 ms, 1000 Hz, approach 100 m, exit 5 m, one sensor at mid-span. */
void amfi_sim_params_default(amfi_sim_params *p, double span_m);

typedef struct amfi_sim_vehicle {
    /* in */
    long id;
    amfi_halfcar car;  /* the two-axle half-car, used when truck.n_axles is 0 */
    amfi_truck truck;  /* any vehicle (vehicle.h); n_axles 0: the half-car `car` */
    double speed_mps;  /* > 0 */
    double t_entry_s;  /* when the front axle reaches x = 0 */
    int track;         /* profile track, 0 .. n_tracks − 1 */
    /* out, when the vehicle has left (per axle, front first; the half-car
     * is filled in as truck on amfi_sim_add) */
    double mean_force_N[AMFI_MAX_AXLES]; /* mean contact force while the axle is on [0, L] */
    double min_force_N[AMFI_MAX_AXLES], max_force_N[AMFI_MAX_AXLES]; /* over the same time */
    long lost_contact_steps[AMFI_MAX_AXLES];            /* steps with the tyre off the road */
    long on_span_steps[AMFI_MAX_AXLES];
} amfi_sim_vehicle;

typedef struct amfi_sim amfi_sim;

/* `b` (the simulated bridge, damage included) and `prof` (NULL: a smooth
 * road) must outlive the simulation. Free with amfi_sim_destroy(). */
int amfi_sim_create(const amfi_bridge *b, const amfi_profile *prof, const amfi_sim_params *p,
                    amfi_sim **out, char *err, size_t errlen);
void amfi_sim_destroy(amfi_sim *s); /* NULL-safe */

/* Queue a vehicle. It starts (at rest, static equilibrium) when its front
 * axle is approach_m before the bridge; that moment must not have passed. */
int amfi_sim_add(amfi_sim *s, const amfi_sim_vehicle *v, char *err, size_t errlen);

/* Write n_samples accelerometer samples (n_samples × n_sensors, m/s²,
 * positive downward), the first at the current time, advancing the
 * simulation by n_samples sampling periods. */
int amfi_sim_advance(amfi_sim *s, int n_samples, double *accel, char *err, size_t errlen);

/* Pop a vehicle that has left the simulation (1), or none (0). */
int amfi_sim_pop_done(amfi_sim *s, amfi_sim_vehicle *out);

double amfi_sim_time(const amfi_sim *s);   /* time of the next sample, s */
int amfi_sim_busy(const amfi_sim *s);      /* vehicles pending or active */

/* Called after every integration step for every active vehicle: time, the
 * vehicle, its axles' positions (m) and contact forces (N), v->truck.n_axles
 * of each. For force histories in experiments; NULL to stop. */
typedef void (*amfi_sim_hook)(void *user, double t_s, const amfi_sim_vehicle *v,
                              const double *x_m, const double *F_N);
void amfi_sim_set_hook(amfi_sim *s, amfi_sim_hook fn, void *user);

/* Replace the simulated bridge (a damage step) while traffic runs: the
 * deflections and velocities are carried over through the nodal DOFs
 * (u = Ψ q, then q' = Ψ'ᵀ M u, the mass being unchanged by damage). `b`
 * must have the same mesh and supports, and outlive the simulation. */
int amfi_sim_set_bridge(amfi_sim *s, const amfi_bridge *b, char *err, size_t errlen);

/* Bridge deflection at x (m, positive downward) at the current time. */
double amfi_sim_deflection(amfi_sim *s, double x_m);

/* Vehicle DOFs of an active vehicle (testing): amfi_truck_ndof values in
 * the order of vehicle.h (the half-car: y_s, θ, y_u1, y_u2). Returns 0, or
 * −1 when no active vehicle has that id. */
int amfi_sim_vehicle_state(const amfi_sim *s, long id, double *u);

#endif
