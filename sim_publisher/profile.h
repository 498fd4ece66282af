/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * profile.h: random road profiles for the simulator (docs/simulator-inputs.md §1): ISO 8608
 * roughness classes, one track or a "carpet" of parallel, correlated tracks.
 *
 * Roughness: ISO 8608:2016 displacement PSD (one-sided, per cycle/m)
 *     G_d(n) = G_d(n0)·(n/n0)^(−2),  n0 = 0.1 cycle/m,
 * G_d(n0) the geometric mean of the class (A 16e-6 m³, each class ×4 up to
 * H 262144e-6 m³), or any level given explicitly, or zero (smooth road).
 *
 * Synthesis: a sum of harmonics with deterministic amplitudes and uniform
 * random phases (ISO 8608 Annex; for several tracks the spectral
 * representation method of Shinozuka & Jan 1972, J. Sound Vib. 25(1),
 * 111-128, in the form of Deodatis 1996, J. Eng. Mech. 122(8), 778-787):
 *     z_i(x) = Σ_k A_k Σ_{m<=i} L_im(n_k) cos(2π n_k x + φ_mk),
 *     A_k² / 2 = ∫ G_d(n) dn over [(k − ½)Δn, (k + ½)Δn] ∩ [n_min, n_max],
 *     L(n) L(n)ᵀ = R(n) (Cholesky of the coherence matrix below),
 * φ_mk independent and uniform on [0, 2π). The harmonics are the multiples
 * n_k = k·Δn, Δn = 1/L_p, whose interval overlaps the band [n_min, n_max];
 * L_p = M·dx >= length + dx is the synthesis period (M the smallest
 * 2^a·3^b·5^c grid size that covers the length), so the whole grid is one
 * inverse FFT per track and the profile does not repeat inside [0, length].
 * Integrating G_d over each harmonic's interval (rather than G_d(n_k)·Δn)
 * makes the total variance exactly the band's, σ² = G_d(n0)·n0²·(1/n_min −
 * 1/n_max) (class A, 0.01 .. 10 cycle/m: σ = 4.0 mm). Defaults: n = 0.01 ..
 * 10 cycle/m (wavelengths 100 m .. 0.1 m), dx = 0.02 m; a 200 m profile has
 * L_p = 202.5 m and 2024 harmonics 0.00494 cycle/m apart (0.00988 .. 10).
 * On the grid the heights are exact; half-way between grid points the
 * linear interpolation scales a harmonic by cos(π n dx) (0.81 at 10
 * cycle/m, 0.998 at 1 cycle/m, with dx = 0.02 m).
 *
 * Transverse coherence: the isotropic road surface (Kamash & Robson 1978,
 * "The application of isotropy in road surface modelling", J. Sound Vib.
 * 57(1), 89-100; also in Cebon 1999, "Handbook of Vehicle-Road
 * Interaction", Swets & Zeitlinger): two parallel tracks b apart have the
 * cross-spectral density G_d(n)·ρ(n, b). For the waviness w = 2 of ISO 8608
 * the isotropic integral has a closed form,
 *     ρ(n, b) = 2π n b · K1(2π n b)     (K1: modified Bessel function),
 * real, 1 at b = 0, falling with n·b (0.98 at n·b = 0.02, 0.50 at 0.2,
 * 0.006 at 1). R(n)_il = ρ(n, |i − l|·spacing).
 *
 * Same parameters and seed (gsl_rng_mt19937; GSL maps seed 0 to 4357) give
 * the same heights bit for bit on a given build. Track i does not depend on
 * how many tracks follow it: a 1-track profile equals track 0 of an 11-track
 * carpet with the same seed.
 *
 * Heights are positive UP (road surface above its mean), in m, on the grid
 * x_j = j·dx, and linearly interpolated between grid points.
 *
 * Workload: one profile per simulation (created once: O(tracks³ · harmonics
 * + tracks · M log M): 3.8 ms for the defaults, 96 ms for 4000 m), then
 * amfi_profile_height at every integration step for every axle: O(1), about
 * 5 ns, no allocation, no locking. A profile is read-only after creation and may be
 * shared by threads. Memory: 8 bytes × tracks × (length/dx + 1).
 */
#ifndef AMFI_SIM_PROFILE_H
#define AMFI_SIM_PROFILE_H

#include <stddef.h>

#include <gsl/gsl_rng.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AMFI_PROFILE_N0_CPM 0.1      /* ISO 8608 reference spatial frequency, cycle/m */
#define AMFI_PROFILE_MAX_TRACKS 64
#define AMFI_PROFILE_MAX_POINTS 50000000L /* tracks × grid points, 400 MB */

typedef struct amfi_profile_params {
    char iso_class;         /* 'A' .. 'H' (ISO 8608 class, lower case accepted),
                               or 0 for a smooth (zero) road */
    double gd_n0_m3;        /* G_d(n0), m³, 0 .. 1: > 0 overrides iso_class;
                               0 uses the class */
    double length_m;        /* the profile covers x = 0 .. length_m, m, 1 .. 1e5 */
    double dx_m;            /* grid step, m, 1e-3 .. 1 */
    double n_min_cpm;       /* lowest spatial frequency, cycle/m, > 0 */
    double n_max_cpm;       /* highest, cycle/m, n_min < n_max < 1/(2 dx) */
    int n_tracks;           /* parallel tracks, 1 .. AMFI_PROFILE_MAX_TRACKS */
    double track_spacing_m; /* transverse distance of adjacent tracks, m, 0.01 .. 10 */
    unsigned long seed;     /* gsl_rng_mt19937 seed */
} amfi_profile_params;

/* Class A, 200 m, dx 0.02 m, n = 0.01 .. 10 cycle/m, a carpet of 11 tracks
 * 0.2 m apart (paper §3.1), seed 1. */
void amfi_profile_params_default(amfi_profile_params *p);

/* G_d(n0) of an ISO 8608 class (geometric mean), m³; 0 for anything that is
 * not 'A' .. 'H' / 'a' .. 'h'. */
double amfi_profile_class_gd(char iso_class);

/* The coherence model above: ρ(n, b) = 2πnb·K1(2πnb), 1 for n·b <= 0. */
double amfi_profile_coherence(double n_cpm, double b_m);

typedef struct amfi_profile amfi_profile; /* opaque, read-only once created */

/* Validate `p`, synthesise every track on the grid. Returns 0 and *out (free
 * with amfi_profile_destroy), or AMFI_EINVAL / AMFI_ENOMEM with a one-line
 * message "field: problem" in err (may be NULL). */
int amfi_profile_create(const amfi_profile_params *p, amfi_profile **out,
                        char *err, size_t errlen);
void amfi_profile_destroy(amfi_profile *p); /* NULL-safe */

/* Road height of `track` at x_m, m, positive up: linear interpolation on the
 * grid. x outside [0, length] clamps to the ends (a NaN x gives the x = 0
 * height); a track outside 0 .. n_tracks − 1 clamps to the nearest track.
 * O(1), no allocation. */
double amfi_profile_height(const amfi_profile *p, int track, double x_m);

/* A vehicle's track: a normal distribution over the track index with mean
 * (n_tracks − 1)/2 (the centre track; between the two middle tracks for an
 * even count) and standard deviation std_tracks (in tracks), truncated to
 * the carpet [−0.5, n_tracks − 0.5) and rounded to the nearest index.
 * Exactly one gsl_rng_uniform draw (inverse CDF). std_tracks <= 0 or NaN,
 * or a single track, gives the centre track (the upper middle one for an
 * even count) without a draw. Returns 0 .. n_tracks − 1. */
int amfi_profile_draw_track(const amfi_profile *p, double std_tracks,
                            gsl_rng *rng);

int amfi_profile_tracks(const amfi_profile *p);       /* n_tracks */
double amfi_profile_length(const amfi_profile *p);    /* length_m */
const amfi_profile_params *amfi_profile_params_of(const amfi_profile *p);

/* What was synthesised (for reports and tests). */
typedef struct amfi_profile_info {
    double gd_n0_m3;     /* G_d(n0) used, m³ (0: smooth) */
    double period_m;     /* synthesis period L_p = M·dx, m */
    double dn_cpm;       /* harmonic spacing 1/L_p, cycle/m */
    int n_harmonics;     /* harmonics in [n_min, n_max] (0 when smooth) */
    double n_first_cpm;  /* lowest and highest harmonic, cycle/m */
    double n_last_cpm;
    double sigma_m;      /* ensemble RMS height sqrt(Σ_k G_d(n_k)·Δn), m */
    long n_points;       /* grid points per track, length/dx + 1 rounded up */
} amfi_profile_info;
void amfi_profile_get_info(const amfi_profile *p, amfi_profile_info *out);

/* The grid of one track: n_points heights at x_j = j·dx (m, up), owned by
 * the profile. NULL when track is out of range. */
const double *amfi_profile_grid(const amfi_profile *p, int track);

#ifdef __cplusplus
}
#endif
#endif /* AMFI_SIM_PROFILE_H */
