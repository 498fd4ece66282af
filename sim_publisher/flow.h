/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * flow.h: random (Poisson) traffic with overlapping vehicles for the
 * streaming simulator (issue 13): arrivals per lane with a mean and a
 * minimum headway, one or two lanes, vehicles of one lane never
 * overtaking each other on the span.
 *
 * Headways within a lane are a shifted exponential: min_headway_s plus an
 * exponential of mean (mean_headway_s − min_headway_s), so the mean is
 * mean_headway_s. A vehicle faster than its lane's leader is held back
 * until its front axle stays at least min_headway_s behind the leader's
 * front axle over the whole span (checked at entry and exit: the times are
 * linear in position) and at the start of the approach. Every lane loads the same beam (no width).
 *
 * Pure computation on caller-owned state; one thread (the simulator's main).
 */
#ifndef AMFI_SIM_FLOW_H
#define AMFI_SIM_FLOW_H

#include <gsl/gsl_rng.h>
#include <stddef.h>

#define AMFI_FLOW_MAX_LANES 2

typedef struct amfi_flow {
    int lanes;              /* 1 or 2 */
    double mean_headway_s;  /* per lane, > min_headway_s */
    double min_headway_s;   /* per lane, >= 0 */
    double span_m;          /* > 0 */
    double approach_m;      /* the simulated approach, >= 0 */
    double t0_s;            /* earliest entry */
    /* state */
    double next_s[AMFI_FLOW_MAX_LANES];      /* nominal next arrival per lane */
    double last_entry_s[AMFI_FLOW_MAX_LANES]; /* the lane's last entry, < t0: none */
    double last_speed[AMFI_FLOW_MAX_LANES];
    int started[AMFI_FLOW_MAX_LANES];
} amfi_flow;

/* Check the parameters (message naming the option in err) and start the
 * lanes' first arrivals at t0_s + an exponential draw. 0 or AMFI_EINVAL. */
int amfi_flow_init(amfi_flow *f, int lanes, double mean_headway_s, double min_headway_s,
                   double span_m, double approach_m, double t0_s, gsl_rng *rng, char *err, size_t errlen);

/* The next vehicle at speed_mps (> 0): its lane (1-based, the lane with the
 * earliest nominal arrival) and its entry time (front axle onto the span).
 * Entries across lanes are not ordered; sort them afterwards. */
void amfi_flow_next(amfi_flow *f, double speed_mps, gsl_rng *rng, int *lane, double *entry_s);

#endif
