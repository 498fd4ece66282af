/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * site.c: simulation.environment: site for a streaming run (site.h): the
 * climate on the data clock, the mix's record draw, and the cache of
 * temperature-scaled bridges. sim_publisher's main thread only.
 */
#define _POSIX_C_SOURCE 200809L
#include "site.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int amfi_site_init(amfi_site *s, const amfi_bridge_params *bp, const amfi_vehicle_rec *recs,
                   int n_recs, int64_t start_utime, double compression, uint64_t seed,
                   char *err, size_t errlen)
{
    amfi_env_params ep;
    struct tm tm;
    const time_t t0 = (time_t)(start_utime / 1000000);

    memset(s, 0, sizeof *s);
    if (!(compression >= 1.0)) {
        if (errlen)
            snprintf(err, errlen, "environment: time compression %g must be >= 1", compression);
        return AMFI_EINVAL;
    }
    if (!gmtime_r(&t0, &tm)) {
        if (errlen)
            snprintf(err, errlen, "environment: start utime %lld is not a UTC date",
                     (long long)start_utime);
        return AMFI_EINVAL;
    }
    s->day0 = tm.tm_yday + (tm.tm_hour * 3600.0 + tm.tm_min * 60.0 + tm.tm_sec +
                            (double)(start_utime % 1000000) * 1e-6) / 86400.0;
    s->compression = compression;
    s->bp = *bp;
    s->bp.damage = 0.0;
    amfi_env_params_site(&ep);
    ep.compression = compression;
    amfi_env_init(&s->env, &ep, s->day0, seed);
    amfi_mix_params_site(&s->mix);
    /* weekday of 1 January of the start's year, Monday = 0 */
    s->mix.day0_weekday = (((tm.tm_wday + 6) % 7 - tm.tm_yday) % 7 + 7) % 7;
    s->mix.split_kg = amfi_mix_median_gvw(recs, n_recs);
    return amfi_mix_classify_by_class(recs, n_recs, &s->classes, err, errlen);
}

void amfi_site_free(amfi_site *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->n_bridges; i++)
        amfi_bridge_destroy(s->bridges[i].b);
    free(s->bridges);
    amfi_mix_classes_free(&s->classes);
    s->bridges = NULL;
    s->n_bridges = s->cap_bridges = 0;
}

double amfi_site_day(const amfi_site *s, double t_s)
{
    return s->day0 + t_s * s->compression / 86400.0;
}

int amfi_site_pick(const amfi_site *s, uint64_t seed, long i, double t_s)
{
    const uint64_t k = seed * 0x100000001b3ull ^ (uint64_t)i * 0x2545f4914f6cdd1dull;
    const double share = amfi_mix_loaded_share(&s->mix, amfi_site_day(s, t_s));
    return amfi_mix_pick(&s->classes, share, amfi_env_hash_unit(k),
                         amfi_env_hash_unit(k ^ 0x6d6978ull));
}

const amfi_bridge *amfi_site_bridge_at(amfi_site *s, double t_s, double damage, char *err,
                                       size_t errlen)
{
    amfi_env_advance(&s->env, t_s);
    const double f = amfi_env_modulus_factor(&s->env.p, s->env.deck_c);
    const long key = lround(f / AMFI_SITE_MODULUS_STEP);
    for (int i = 0; i < s->n_bridges; i++)
        if (s->bridges[i].key == key && s->bridges[i].damage == damage)
            return s->bridges[i].b;
    if (s->n_bridges == s->cap_bridges) {
        const int cap = s->cap_bridges ? 2 * s->cap_bridges : 64;
        amfi_site_bridge *nb = realloc(s->bridges, sizeof *nb * (size_t)cap);
        if (!nb) {
            if (errlen)
                snprintf(err, errlen, "environment: out of memory");
            return NULL;
        }
        s->bridges = nb;
        s->cap_bridges = cap;
    }
    amfi_bridge_params bp = s->bp;
    bp.E_pa = s->bp.E_pa * (double)key * AMFI_SITE_MODULUS_STEP;
    /* the segments' own E·I follow the same modulus */
    for (int i = 0; i < bp.n_segments; i++)
        bp.segments[i].EI_nm2 = s->bp.segments[i].EI_nm2 * (double)key * AMFI_SITE_MODULUS_STEP;
    bp.damage = damage;
    amfi_site_bridge *e = &s->bridges[s->n_bridges];
    if (amfi_bridge_create(&bp, &e->b, err, errlen))
        return NULL;
    e->key = key;
    e->damage = damage;
    s->n_bridges++;
    return e->b;
}
