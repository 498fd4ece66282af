/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * calibration.h: the offline records of a simulated commissioning
 * (sim_publisher --calibration-runs DIR, --ambient-out FILE): pre-weighed
 * trucks crossing the bridge one at a time, each run's accelerations with
 * the free vibration after the last axle left, what the detector reported
 * and the truth; and an ambient record of the bridge under white-noise
 * excitation for modal identification. docs/simulator.md has the formats.
 *
 * The bridge, the sensor positions (sp) and the detector's errors are the
 * as-built ones (amfi_as_built.h): the files carry what the detector says,
 * the truth files what happened.
 *
 * Vehicles: a two-axle truck is the simulator's half-car (vehicle.h, Table 2
 * means: the same truck at every run) driving over the road carpet (vbi.h);
 * a truck of three or more axles whose spacings fit a class of vclass.h is
 * that class's model (amfi_vclass_truck with the class's mean properties,
 * each load-sharing group's static load equalised, its sum kept: RUNS.csv
 * gives those equalised loads, what a weighbridge weighs) over the carpet;
 * any other layout is a set of constant moving forces (its static axle
 * loads) on the bridge, integrated by libamfi's amfi_forward_newmark (no
 * suspension, no road roughness). The truth file names the model of each
 * run (halfcar, the class's name, or forces).
 *
 * Workload: N runs of a few seconds each, a few seconds of CPU in all; the
 * ambient record a few minutes of data in about a second. Main thread only.
 */
#ifndef AMFI_SIM_CALIBRATION_H
#define AMFI_SIM_CALIBRATION_H

#include <stddef.h>

#include "amfi/amfi.h"
#include "amfi_as_built.h"
#include "profile.h"
#include "vbi.h"
#include "vehicle.h"

#define AMFI_CAL_MAX_TRUCKS 8

typedef struct amfi_cal_truck {
    int n_axles;                           /* 2 .. AMFI_MAX_AXLES */
    double spacing_m[AMFI_MAX_AXLES - 1];  /* front to back, > 0 */
    double axle_kg[AMFI_MAX_AXLES];        /* static loads, front to back, > 0 */
} amfi_cal_truck;

/* Parse "S1,S2,.../L1,L2,..." (spacings in m, then axle loads in kg, front to
 * back; one more load than spacings). 0, or −1 with a message. */
int amfi_cal_truck_parse(const char *s, amfi_cal_truck *t, char *err, size_t errlen);

/* The defaults: a loaded two-axle rigid, 5.0 m, 7000 + 11000 kg (18 t), and a
 * loaded five-axle articulated, 3.6, 5.5, 1.3, 1.3 m, 7000, 11000, 7300,
 * 7300, 7400 kg (40 t). Returns the count (2). */
int amfi_cal_default_trucks(amfi_cal_truck t[AMFI_CAL_MAX_TRUCKS]);

typedef struct amfi_cal_params {
    int n_trucks;
    amfi_cal_truck trucks[AMFI_CAL_MAX_TRUCKS];
    int runs_per_truck;          /* >= 1 */
    double speed_lo, speed_hi;   /* true speeds spread evenly over [lo, hi], m/s */
    double pre_s, tail_s;        /* record before entry / after the last axle leaves */
    double noise_frac;           /* noise, fraction of each record's RMS */
    double noise_ms2;            /* noise, m/s² (added after) */
    double speed_err_mean, speed_err_std; /* the detector's random speed error */
    double track_std;            /* half-car: spread of the carpet track */
    unsigned long seed;
    amfi_detector_error det;     /* the detector's systematic errors */
    const int *sensor_id;        /* sp->n_sensors ids for the file header */
} amfi_cal_params;

/* Write dir/runNNN.csv, dir/RUNS.csv and dir/RUNS.truth.csv (dir must
 * exist). b: the bridge the trucks cross; sp: its true sensor positions.
 * 0, or −1 with a message. */
int amfi_cal_runs_write(const char *dir, const amfi_bridge *b, const amfi_profile *prof,
                        const amfi_sim_params *sp, const amfi_halfcar_dist *dist,
                        const amfi_cal_params *p, char *err, size_t errlen);

typedef struct amfi_ambient_params {
    double duration_s;   /* recorded, > 0 */
    double force_std_n;  /* white-noise force at every node, N per sample (20 N at
                            1000 Hz: about 5 mm/s² RMS on paper-20m) */
    double noise_frac, noise_ms2;
    unsigned long seed;
    const int *sensor_id;
} amfi_ambient_params;

/* Write the ambient record `path`: the bridge (its modes below half the
 * sampling rate, exact zero-order-hold modal integration) under independent
 * white-noise forces at every node, held over each sample, started at rest
 * and recorded after a warm-up of ten first-mode decay times (at most 60 s).
 * 0, or −1 with a message. */
int amfi_ambient_write(const char *path, const amfi_bridge *b, const amfi_sim_params *sp,
                       const amfi_ambient_params *p, char *err, size_t errlen);

/* Write an acceleration record in amfi-solve's format: n rows of ns sensors
 * (acc row per sample) at `rate` Hz, header "t,accel" with one sensor and
 * "t,accel_ID,..." (ids: the site's sensors[].id) with several. 0, or −1
 * with a message. */
int amfi_sim_write_accel(const char *path, int n, int ns, const int *ids, double rate,
                         const double *acc, char *err, size_t errlen);

/* v[0 .. n) with fmt, separated by ';' (the list columns of RUNS.csv,
 * TRUTH.csv and meta.csv). */
void amfi_sim_put_list(FILE *f, const double *v, int n, const char *fmt);

#endif /* AMFI_SIM_CALIBRATION_H */
