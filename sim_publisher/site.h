/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * site.h: simulation.environment: site for a streaming run: the site
 * climate (environment.h) on the stream's data clock, the drifting mix
 * (mix.h) choosing each vehicle's population record, and the bridges of
 * the temperature-scaled moduli (the segments' own E·I scaled alike), built
 * on demand and kept until the run
 * ends (amfi_sim_set_bridge needs the bridge to outlive the simulation).
 *
 * Owned and used by sim_publisher's main thread only.
 */
#ifndef AMFI_SIM_SITE_H
#define AMFI_SIM_SITE_H

#include <stddef.h>
#include <stdint.h>

#include "amfi/amfi.h"
#include "environment.h"
#include "mix.h"
#include "traffic.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Moduli are rounded to this relative step (0.1 %: a weight effect ten times
 * below the error of one inferred weight), so at most a few hundred
 * bridges are built over a year. */
#define AMFI_SITE_MODULUS_STEP 1e-3

typedef struct amfi_site_bridge {
    long key;        /* lround(factor / AMFI_SITE_MODULUS_STEP) */
    double damage;
    amfi_bridge *b;
} amfi_site_bridge;

typedef struct amfi_site {
    amfi_env_state env;
    amfi_mix_params mix;
    amfi_mix_classes classes;
    double day0;           /* day of the year (UTC, fractional) at data time 0 */
    double compression;
    amfi_bridge_params bp; /* the configured bridge, damage ignored */
    amfi_site_bridge *bridges;
    int n_bridges, cap_bridges;
} amfi_site;

/* Set up for a stream starting at start_utime (µs since 1970) with the
 * site defaults, the given compression (>= 1) and seed, the mix split at
 * each vehicle class's median GVW (mix.h; split_kg is the population's
 * median). 0, or an AMFI_E* code with a message. */
int amfi_site_init(amfi_site *s, const amfi_bridge_params *bp, const amfi_vehicle_rec *recs,
                   int n_recs, int64_t start_utime, double compression, uint64_t seed,
                   char *err, size_t errlen);
void amfi_site_free(amfi_site *s); /* NULL-safe, idempotent */

/* Site day of the year (fractional) at data time t_s. */
double amfi_site_day(const amfi_site *s, double t_s);

/* The population record for vehicle `i` entering at data time t_s: drawn
 * from the mix of that site day with uniforms derived from (seed, i). */
int amfi_site_pick(const amfi_site *s, uint64_t seed, long i, double t_s);

/* Advance the climate to data time t_s and return the bridge of the deck
 * temperature's modulus with stiffness loss `damage` (built if new; owned
 * by s). NULL with a message on failure. */
const amfi_bridge *amfi_site_bridge_at(amfi_site *s, double t_s, double damage, char *err,
                                       size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_SIM_SITE_H */
