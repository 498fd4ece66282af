/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * passage.h: one simulated and measured vehicle passage, the unit of the
 * paper's experiments and of sim_publisher's offline output.
 *
 * A target vehicle, optionally behind a preceding one, drives its approach
 * and crosses the (possibly damaged) bridge; the accelerometers are
 * recorded from pre_s before the target's front axle enters until post_s
 * after its rear axle leaves, then the measurement model is applied: noise
 * of a fraction of the record's RMS (per sensor) and a relative error on the
 * speed the detector reports. Truth: the target's static loads and its mean
 * contact forces while on the span.
 */
#ifndef AMFI_PASSAGE_SIM_H
#define AMFI_PASSAGE_SIM_H

#include <gsl/gsl_rng.h>
#include <stddef.h>

#include "traffic.h"
#include "vbi.h"

typedef struct amfi_measure {
    double noise_frac;     /* Gaussian noise std as a fraction of the record's RMS, >= 0 */
    double speed_err_mean; /* relative speed error, mean (0.01 = +1 %) */
    double speed_err_std;  /* relative speed error, std, >= 0 */
} amfi_measure;

typedef struct amfi_passage_spec {
    amfi_halfcar car;      /* the target vehicle (a half-car) ... */
    amfi_truck truck;      /* ... or this one when truck.n_axles > 0 (vehicle.h) */
    double speed_mps;      /* its true speed */
    int track;             /* its profile track */
    int preceding;         /* 1: a vehicle crosses before it */
    amfi_halfcar prec_car;
    amfi_truck prec_truck; /* as truck */
    double prec_speed_mps;
    int prec_track;
    double gap_s;          /* preceding vehicle's rear axle leaves the bridge
                              gap_s before the target's front axle enters
                              (negative: both on the span for −gap_s) */
    double pre_s, post_s;  /* record around the target's time on the span, >= 0 */
} amfi_passage_spec;

typedef struct amfi_passage_rec {
    int n;                    /* samples per sensor */
    int n_sensors;
    double t_first_s;         /* time of sample 0 relative to the target's entry (−pre_s) */
    double speed_measured_mps; /* what the detector reports */
    amfi_sim_vehicle truth;   /* the target after it left (mean forces, contact) */
} amfi_passage_rec;

/* The target of a passage from a WIM record: for two axles a half-car with
 * the record's weights and spacing and Table 2 properties drawn from `d`
 * with rng (NULL: the means); for more, the model of the record's class
 * (vclass.h, its properties drawn with rng); the record's speed, a carpet
 * track drawn with std_tracks (prof NULL: track 0). pre_s, post_s and the
 * preceding vehicle are left to the caller (zero, none). */
int amfi_passage_spec_from_rec(const amfi_vehicle_rec *rec, const amfi_halfcar_dist *d,
                               const amfi_profile *prof, double std_tracks, gsl_rng *rng,
                               amfi_passage_spec *spec, char *err, size_t errlen);

/* Samples a passage of this spec records (for sizing the buffer). */
/* The static axle loads (N) and the axle positions behind axle 1 (m) of
 * a spec's target; returns its axle count. */
int amfi_passage_axles(const amfi_passage_spec *spec, double *W_N, double *x_m);

int amfi_passage_samples(const amfi_bridge *b, const amfi_sim_params *sp,
                         const amfi_passage_spec *spec);

/* Simulate and measure. accel: cap × n_sensors (row per sample). rng draws
 * the noise and the speed error (NULL only when both are zero). */
int amfi_passage_simulate(const amfi_bridge *b, const amfi_profile *prof,
                          const amfi_sim_params *sp, const amfi_passage_spec *spec,
                          const amfi_measure *m, gsl_rng *rng, double *accel, int cap,
                          amfi_passage_rec *out, char *err, size_t errlen);

#endif
