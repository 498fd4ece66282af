/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * environment.h: the simulated site climate (simulation.environment: site)
 * and the bridge's stiffness as a function of its deck temperature
 * (docs/simulator.md, "Environment").
 *
 * Air temperature = annual mean + seasonal cosine (coldest mid-January) +
 * daily cosine (warmest mid-afternoon) + weather noise, an AR(1) process
 * sampled hourly. The deck follows the air through a first-order lag
 * (thermal inertia of the concrete). The modulus factor E(T)/E(T_ref) is
 * bilinear with a knee at 0 °C: a small linear softening with temperature
 * above freezing and a steep stiffening below (the Z24 bridge, Peeters &
 * De Roeck 2001; coefficients and their reading in docs/simulator.md).
 *
 * Time compression: the model runs on site time = c · data time, c =
 * simulation.time_compression (1: real time), so a short stream can span
 * the temperature range of a year.
 *
 * Pure computation with an explicit state; no global state. The state is
 * owned by its caller (sim_publisher's main thread, or a tool's loop).
 */
#ifndef AMFI_SIM_ENVIRONMENT_H
#define AMFI_SIM_ENVIRONMENT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct amfi_env_params {
    double mean_c;          /* annual mean air temperature, °C */
    double seasonal_amp_c;  /* seasonal amplitude (half the peak-to-peak), °C */
    double coldest_day;     /* day of the year of the seasonal minimum, 0 .. 365 */
    double daily_amp_c;     /* daily amplitude, °C */
    double warmest_hour;    /* hour of the daily maximum, 0 .. 24 */
    double weather_std_c;   /* stationary std of the AR(1) weather noise, °C */
    double weather_tau_h;   /* its correlation time, h (phi = exp(−1 h / tau)) */
    double deck_tau_h;      /* deck lag behind the air, h */
    double ref_c;           /* temperature where the modulus factor is 1, °C (> 0) */
    double warm_slope;      /* −dE/E per °C above 0 °C */
    double frost_slope;     /* +dE/E per °C below 0 °C */
    double frost_floor_c;   /* below this the factor stays constant, °C */
    double compression;     /* site time / data time, >= 1 */
} amfi_env_params;

/* Central-European lowland defaults with the Z24 coefficients. */
void amfi_env_params_site(amfi_env_params *p);

typedef struct amfi_env_state {
    amfi_env_params p;
    uint64_t rng;           /* splitmix64 state of the weather noise */
    double weather_c;       /* current AR(1) value */
    double t_site_s;        /* site time of the last step, s since the start */
    double air_c, deck_c;   /* the last values */
    double next_weather_s;  /* site time of the next hourly weather step */
    double day0;            /* site day of the year at data time 0 */
} amfi_env_state;

/* Start at site time 0 = `day0` (day of the year, fractional) with the
 * deck at the air temperature. seed: any. */
void amfi_env_init(amfi_env_state *s, const amfi_env_params *p, double day0,
                   uint64_t seed);

/* Advance to data time t_s (seconds since the start, non-decreasing; an
 * earlier time leaves the state as it is) and set air_c and deck_c. */
void amfi_env_advance(amfi_env_state *s, double t_s);

/* The deterministic part: air temperature at a site day (no weather). */
double amfi_env_air_mean(const amfi_env_params *p, double day);

/* A uniform in [0, 1) that depends only on `key` (the splitmix64 step the
 * weather noise uses), for reproducible per-vehicle draws. */
double amfi_env_hash_unit(uint64_t key);

/* E(T) / E(ref_c), bilinear with a knee at 0 °C, constant below
 * frost_floor_c. */
double amfi_env_modulus_factor(const amfi_env_params *p, double deck_c);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_SIM_ENVIRONMENT_H */
