/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * environment.c: the simulated site climate and the deck-temperature law of
 * the bridge modulus (environment.h; model and coefficients in
 * docs/simulator.md, "Environment"). Pure computation on a caller-owned
 * state; any thread.
 */
#include "environment.h"


#include <math.h>

#define TWO_PI 6.283185307179586
#include <string.h>

#define DAY_S 86400.0
#define HOUR_S 3600.0
#define YEAR_D 365.25

void amfi_env_params_site(amfi_env_params *p)
{
    memset(p, 0, sizeof *p);
    p->mean_c = 9.0;          /* central-European lowland annual mean */
    p->seasonal_amp_c = 9.0;  /* January about 0 °C, July about 18 °C */
    p->coldest_day = 15.0;    /* mid-January */
    p->daily_amp_c = 4.0;     /* clear days reach 5 .. 6, overcast 1 .. 2 */
    p->warmest_hour = 15.0;
    p->weather_std_c = 3.5;   /* synoptic anomalies of a few °C */
    p->weather_tau_h = 72.0;  /* lasting about three days */
    p->deck_tau_h = 6.0;      /* concrete deck inertia */
    p->ref_c = 10.0;
    p->warm_slope = 0.0025;   /* Z24 above 0 °C: f1 −0.13 %/°C, E ∝ f² */
    p->frost_slope = 0.02;    /* Z24 below 0 °C: f1 +1 %/°C (asphalt stiffening) */
    p->frost_floor_c = -10.0;
    p->compression = 1.0;
}

/* splitmix64 and a Box-Muller normal: reproducible without GSL */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static uint64_t next_u64(uint64_t *x)
{
    return mix64(*x += 0x9e3779b97f4a7c15ull);
}

double amfi_env_hash_unit(uint64_t key)
{
    return (double)(mix64(key + 0x9e3779b97f4a7c15ull) >> 11) / 9007199254740992.0;
}

static double unit(uint64_t *x) /* (0, 1) */
{
    return ((double)(next_u64(x) >> 11) + 0.5) / 9007199254740992.0;
}

static double gauss(uint64_t *x)
{
    const double u = unit(x), v = unit(x);
    return sqrt(-2.0 * log(u)) * cos(TWO_PI * v);
}

double amfi_env_air_mean(const amfi_env_params *p, double day)
{
    const double hour = (day - floor(day)) * 24.0;
    return p->mean_c - p->seasonal_amp_c * cos(TWO_PI * (day - p->coldest_day) / YEAR_D) +
           p->daily_amp_c * cos(TWO_PI * (hour - p->warmest_hour) / 24.0);
}

double amfi_env_modulus_factor(const amfi_env_params *p, double deck_c)
{
    const double at0 = 1.0 + p->warm_slope * p->ref_c;
    if (deck_c >= 0.0)
        return 1.0 - p->warm_slope * (deck_c - p->ref_c);
    if (deck_c < p->frost_floor_c)
        deck_c = p->frost_floor_c;
    return at0 * (1.0 - p->frost_slope * deck_c);
}

/* site day of the state's site time */
static double site_day(const amfi_env_state *s, double day0)
{
    return day0 + s->t_site_s / DAY_S;
}

void amfi_env_init(amfi_env_state *s, const amfi_env_params *p, double day0, uint64_t seed)
{
    memset(s, 0, sizeof *s);
    s->p = *p;
    s->rng = seed ^ 0x656e7669726f6eull;
    s->weather_c = p->weather_std_c * gauss(&s->rng);
    s->t_site_s = 0.0;
    s->next_weather_s = HOUR_S;
    s->air_c = amfi_env_air_mean(p, day0) + s->weather_c;
    s->deck_c = s->air_c;
    s->day0 = day0;
}

void amfi_env_advance(amfi_env_state *s, double t_s)
{
    const amfi_env_params *p = &s->p;
    const double target = t_s * p->compression;
    const double phi = exp(-1.0 / p->weather_tau_h);
    const double innov = p->weather_std_c * sqrt(1.0 - phi * phi);
    const double max_step = 600.0; /* deck lag integrated in ≤ 10 min site steps */

    while (s->t_site_s < target) {
        double h = target - s->t_site_s;
        if (h > max_step)
            h = max_step;
        if (s->t_site_s + h > s->next_weather_s)
            h = s->next_weather_s - s->t_site_s;
        s->t_site_s += h;
        if (s->t_site_s >= s->next_weather_s) {
            s->weather_c = phi * s->weather_c + innov * gauss(&s->rng);
            s->next_weather_s += HOUR_S;
        }
        s->air_c = amfi_env_air_mean(p, site_day(s, s->day0)) + s->weather_c;
        /* exact first-order lag over h toward the current air temperature */
        s->deck_c = s->air_c + (s->deck_c - s->air_c) * exp(-h / (p->deck_tau_h * HOUR_S));
    }
}
