/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * mix.h: a traffic mix that drifts with the weekday and the season
 * (simulation.environment: site; docs/simulator.md, "Traffic mix").
 *
 * The population's vehicles are split at a GVW into "empty" (below) and
 * "loaded" (at or above) classes (with vehicle classes: at each class's
 * own median); each simulated vehicle is drawn from the
 * loaded class with the probability amfi_mix_loaded_share(day) and from the
 * empty class otherwise, uniformly within its class. With a share equal to
 * the population's own loaded fraction the draw reproduces the population;
 * the share moves with the weekday (lower at weekends) and the season
 * (lower in winter). The daily flow factor (weekend traffic of heavy
 * vehicles is lower) is given for tools that set a flow per day.
 *
 * Pure computation on caller-owned data; any thread.
 */
#ifndef AMFI_SIM_MIX_H
#define AMFI_SIM_MIX_H

#include "traffic.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct amfi_mix_params {
    double split_kg;        /* loaded: GVW >= split_kg */
    double weekday_share;   /* loaded share Monday .. Friday, annual mean, (0, 1) */
    double weekend_share;   /* loaded share Saturday and Sunday, (0, 1) */
    double seasonal_amp;    /* ± change of the share over the year (minimum in
                               mid-January), absolute, [0, 0.5) */
    double weekend_flow;    /* weekend daily flow / weekday flow, (0, 1] */
    int day0_weekday;       /* weekday of day 0 of the year, 0 = Monday .. 6 */
} amfi_mix_params;

/* The shipped site defaults (docs/simulator.md). split_kg is set from the
 * population by amfi_mix_classify; the defaults make the weekday share the
 * population's own loaded fraction when split_kg is its median. */
void amfi_mix_params_site(amfi_mix_params *p);

/* Weekday of a (fractional) day of the year: 0 = Monday .. 6 = Sunday. */
int amfi_mix_weekday(const amfi_mix_params *p, double day);

/* Loaded share on day `day` (of the year, fractional), clamped to
 * [0.02, 0.98]. */
double amfi_mix_loaded_share(const amfi_mix_params *p, double day);

/* Daily flow relative to a weekday: 1 or weekend_flow. */
double amfi_mix_flow_factor(const amfi_mix_params *p, double day);

typedef struct amfi_mix_classes {
    int *empty, *loaded; /* record indices of each class */
    int n_empty, n_loaded;
} amfi_mix_classes;

/* Split `recs` at split_kg. 0, or AMFI_EINVAL when a class would be empty,
 * AMFI_ENOMEM; a message in err. Free with amfi_mix_classes_free. */
int amfi_mix_classify(const amfi_vehicle_rec *recs, int n, double split_kg,
                      amfi_mix_classes *c, char *err, size_t errlen);
void amfi_mix_classes_free(amfi_mix_classes *c); /* NULL-safe, idempotent */

/* The same with a split per vehicle class (amfi_vehicle_rec.vclass): a
 * record is loaded at or above its own class's median GVW (records without
 * a class together), so that the loaded and empty draws keep the mix of
 * classes. With one class in recs it equals amfi_mix_classify at the
 * population's median. */
int amfi_mix_classify_by_class(const amfi_vehicle_rec *recs, int n, amfi_mix_classes *c,
                               char *err, size_t errlen);

/* The record index for one vehicle: u_class and u_pick uniform in [0, 1). */
int amfi_mix_pick(const amfi_mix_classes *c, double share, double u_class, double u_pick);

/* The median GVW of recs (the default split). n >= 1. */
double amfi_mix_median_gvw(const amfi_vehicle_rec *recs, int n);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_SIM_MIX_H */
