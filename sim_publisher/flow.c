/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * flow.c: Poisson traffic per lane with a minimum headway and no overtaking
 * on the span (see flow.h). Pure computation; the simulator's main thread.
 */
#include "flow.h"

#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdio.h>

#include "amfi/amfi.h"

static double draw_headway(const amfi_flow *f, gsl_rng *rng)
{
    return f->min_headway_s + gsl_ran_exponential(rng, f->mean_headway_s - f->min_headway_s);
}

int amfi_flow_init(amfi_flow *f, int lanes, double mean_headway_s, double min_headway_s,
                   double span_m, double approach_m, double t0_s, gsl_rng *rng, char *err, size_t errlen)
{
    if (lanes < 1 || lanes > AMFI_FLOW_MAX_LANES) {
        snprintf(err, errlen, "--lanes: %d is not 1 or 2", lanes);
        return AMFI_EINVAL;
    }
    if (!(min_headway_s >= 0) || !(mean_headway_s > min_headway_s) || !isfinite(mean_headway_s)) {
        snprintf(err, errlen,
                 "--flow/--min-headway: the mean headway %.3g s must exceed the minimum %.3g s",
                 mean_headway_s, min_headway_s);
        return AMFI_EINVAL;
    }
    if (!(span_m > 0) || !isfinite(t0_s)) {
        snprintf(err, errlen, "flow: span %.3g m or start %.3g s invalid", span_m, t0_s);
        return AMFI_EINVAL;
    }
    f->lanes = lanes;
    f->mean_headway_s = mean_headway_s;
    f->min_headway_s = min_headway_s;
    f->span_m = span_m;
    f->approach_m = approach_m >= 0 ? approach_m : 0.0;
    f->t0_s = t0_s;
    for (int l = 0; l < AMFI_FLOW_MAX_LANES; l++) {
        f->next_s[l] = t0_s + gsl_ran_exponential(rng, mean_headway_s);
        f->last_entry_s[l] = 0.0;
        f->last_speed[l] = 0.0;
        f->started[l] = 0;
    }
    return 0;
}

void amfi_flow_next(amfi_flow *f, double speed_mps, gsl_rng *rng, int *lane, double *entry_s)
{
    int l = 0;
    for (int k = 1; k < f->lanes; k++)
        if (f->next_s[k] < f->next_s[l])
            l = k;
    double e = f->next_s[l];
    if (f->started[l]) {
        /* front axle at least min_headway_s behind the leader's, at entry
         * and at exit of the span (linear in between) */
        const double at_entry = f->last_entry_s[l] + f->min_headway_s;
        const double at_exit = f->last_entry_s[l] + f->span_m / f->last_speed[l] -
                               f->span_m / speed_mps + f->min_headway_s;
        if (e < at_entry)
            e = at_entry;
        if (e < at_exit)
            e = at_exit;
        /* and at the start of the approach, so that the simulator's lanes
         * start in order too */
        const double at_approach = f->last_entry_s[l] - f->approach_m / f->last_speed[l] +
                                   f->approach_m / speed_mps + f->min_headway_s;
        if (e < at_approach)
            e = at_approach;
    }
    f->started[l] = 1;
    f->last_entry_s[l] = e;
    f->last_speed[l] = speed_mps;
    f->next_s[l] = e + draw_headway(f, rng);
    *lane = l + 1;
    *entry_s = e;
}
