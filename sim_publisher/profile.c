/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * profile.c: ISO 8608 road profiles, single track or correlated carpet (see
 * profile.h for the model, the method and the references).
 *
 * Creation, per harmonic k (n_k = k/L_p, k = k_lo .. k_hi):
 *   1. r_d = ρ(n_k, d·spacing), d = 0 .. N−1, and the Cholesky factor L of
 *      the Toeplitz matrix R_il = r_|i−l| (N × N, lower, row-major). At low
 *      n·b every entry of R is close to 1 and R is numerically singular, so
 *      the factorisation is the semidefinite one: a pivot below PIVOT_TOL
 *      ends its column (L_jj = 0, column below zero). R is positive
 *      semidefinite in exact arithmetic (it is the cross-spectrum of an
 *      isotropic field sampled across the road, a positive-definite function
 *      of b by Bochner's theorem), so only rounding is thrown away.
 *   2. the complex coefficient of track i: C_ik = A_k Σ_{m<=i} L_im e^{jφ_mk}.
 * Then, per track, one inverse real FFT of size M (GSL mixed radix, in
 * halfcomplex storage) gives z_i at the M grid points of one period; the
 * first n_points are kept.
 *
 * The phases are drawn track-major (all harmonics of component 0, then of
 * component 1, ...), so track i depends on the seed and on components
 * 0 .. i only, whatever the number of tracks.
 */
#include "profile.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_sf_bessel.h>

#include "amfi/amfi.h"

#define PIVOT_TOL 1e-12 /* squared pivot below which a Cholesky column ends */

struct amfi_profile {
    amfi_profile_params p;
    amfi_profile_info info;
    long n_points; /* grid points per track */
    double inv_dx; /* 1/dx, 1/m */
    double x_max;  /* clamp for queries: length_m, m */
    double *z;     /* n_tracks × n_points, row-major, m, up */
};

static void msg(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void msg(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

void amfi_profile_params_default(amfi_profile_params *p)
{
    memset(p, 0, sizeof *p);
    p->iso_class = 'A';
    p->gd_n0_m3 = 0.0;
    p->length_m = 200.0;
    p->dx_m = 0.02;
    p->n_min_cpm = 0.01;
    p->n_max_cpm = 10.0;
    p->n_tracks = 11;
    p->track_spacing_m = 0.2;
    p->seed = 1;
}

double amfi_profile_class_gd(char c)
{
    if (c >= 'a' && c <= 'h')
        c = (char)(c - 'a' + 'A');
    if (c < 'A' || c > 'H')
        return 0.0;
    /* ISO 8608 Table 1: class A 16e-6 m³, ×4 per class */
    return 16e-6 * ldexp(1.0, 2 * (c - 'A'));
}

double amfi_profile_coherence(double n_cpm, double b_m)
{
    const double z = 2.0 * M_PI * n_cpm * b_m;
    if (!(z > 0.0))
        return 1.0;
    /* K1(z) = K1_scaled(z)·e^{−z}: the scaled form never underflows (the
     * plain one calls the GSL error handler for z > ~705); exp() underflows
     * quietly to 0, which is the right answer. */
    return z * gsl_sf_bessel_K1_scaled(z) * exp(-z);
}

/* Smallest m >= n whose only prime factors are 2, 3 and 5 (GSL's mixed-radix
 * FFT is fast for those). n <= 2^40. */
static long smooth_size(long n)
{
    for (long m = n;; m++) {
        long r = m;
        while (r % 2 == 0)
            r /= 2;
        while (r % 3 == 0)
            r /= 3;
        while (r % 5 == 0)
            r /= 5;
        if (r == 1)
            return m;
    }
}

/* Semidefinite Cholesky of the N × N Toeplitz matrix with first row r:
 * L (N × N, row-major, lower; the upper part is left untouched). */
static void cholesky_toeplitz(int N, const double *r, double *L)
{
    for (int j = 0; j < N; j++) {
        double d = r[0];
        for (int m = 0; m < j; m++)
            d -= L[j * N + m] * L[j * N + m];
        if (d <= PIVOT_TOL) {
            L[j * N + j] = 0.0;
            for (int i = j + 1; i < N; i++)
                L[i * N + j] = 0.0;
            continue;
        }
        const double ljj = sqrt(d);
        L[j * N + j] = ljj;
        for (int i = j + 1; i < N; i++) {
            double s = r[i - j];
            for (int m = 0; m < j; m++)
                s -= L[i * N + m] * L[j * N + m];
            L[i * N + j] = s / ljj;
        }
    }
}

/* The synthesis plan derived from validated parameters. */
typedef struct plan {
    double gd;    /* G_d(n0), m³ */
    long M;       /* FFT size (grid points per period) */
    long n_points;
    double Lp;    /* period, m */
    long k_lo, k_hi; /* harmonic range; k_hi < k_lo when there is none */
} plan;

static int make_plan(const amfi_profile_params *p, plan *pl, char *err, size_t errlen)
{
#define REQ(cond, ...)                        \
    do {                                      \
        if (!(cond)) {                        \
            msg(err, errlen, __VA_ARGS__);    \
            return AMFI_EINVAL;               \
        }                                     \
    } while (0)
    REQ(p->iso_class == 0 || amfi_profile_class_gd(p->iso_class) > 0.0,
        "iso_class: '%c' is not an ISO 8608 class A .. H (0 for smooth)",
        p->iso_class >= 0x20 && p->iso_class < 0x7f ? p->iso_class : '?');
    REQ(isfinite(p->gd_n0_m3) && p->gd_n0_m3 >= 0.0 && p->gd_n0_m3 <= 1.0,
        "gd_n0_m3: %g is not in [0, 1] m³", p->gd_n0_m3);
    REQ(isfinite(p->length_m) && p->length_m >= 1.0 && p->length_m <= 1e5,
        "length_m: %g is not in [1, 1e5] m", p->length_m);
    REQ(isfinite(p->dx_m) && p->dx_m >= 1e-3 && p->dx_m <= 1.0,
        "dx_m: %g is not in [0.001, 1] m", p->dx_m);
    REQ(p->n_tracks >= 1 && p->n_tracks <= AMFI_PROFILE_MAX_TRACKS,
        "n_tracks: %d is not in 1 .. %d", p->n_tracks, AMFI_PROFILE_MAX_TRACKS);
    REQ(isfinite(p->track_spacing_m) && p->track_spacing_m >= 0.01 && p->track_spacing_m <= 10.0,
        "track_spacing_m: %g is not in [0.01, 10] m", p->track_spacing_m);
    const double nyq = 0.5 / p->dx_m;
    REQ(isfinite(p->n_min_cpm) && p->n_min_cpm > 0.0,
        "n_min_cpm: %g must be > 0 cycle/m", p->n_min_cpm);
    REQ(isfinite(p->n_max_cpm) && p->n_max_cpm > p->n_min_cpm && p->n_max_cpm < nyq,
        "n_max_cpm: %g must be above n_min_cpm (%g) and below the grid's Nyquist frequency "
        "1/(2·dx) = %g cycle/m",
        p->n_max_cpm, p->n_min_cpm, nyq);
    pl->n_points = (long)ceil(p->length_m / p->dx_m - 1e-9) + 1;
    REQ((double)pl->n_points * p->n_tracks <= (double)AMFI_PROFILE_MAX_POINTS,
        "length_m: %g m at dx %g m over %d tracks is %.3g grid points, more than %ld",
        p->length_m, p->dx_m, p->n_tracks, (double)pl->n_points * p->n_tracks,
        AMFI_PROFILE_MAX_POINTS);
    pl->gd = p->gd_n0_m3 > 0.0 ? p->gd_n0_m3 : amfi_profile_class_gd(p->iso_class);
    pl->M = smooth_size(pl->n_points);
    pl->Lp = (double)pl->M * p->dx_m;
    /* harmonic k stands for [(k − ½)Δn, (k + ½)Δn]: keep every k whose
     * interval overlaps [n_min, n_max] */
    pl->k_lo = (long)floor(p->n_min_cpm * pl->Lp - 0.5) + 1;
    pl->k_hi = (long)ceil(p->n_max_cpm * pl->Lp + 0.5) - 1;
    if (pl->k_lo < 1)
        pl->k_lo = 1;
    if (pl->k_hi > (pl->M - 1) / 2) /* strictly below Nyquist */
        pl->k_hi = (pl->M - 1) / 2;
    REQ(pl->gd == 0.0 || pl->k_hi >= pl->k_lo,
        "n_min_cpm, n_max_cpm: no harmonic of the %g m period (spacing %g cycle/m) falls in "
        "[%g, %g] cycle/m",
        pl->Lp, 1.0 / pl->Lp, p->n_min_cpm, p->n_max_cpm);
    return 0;
#undef REQ
}

/* Variance carried by harmonic k: ∫ G_d(n) dn over [(k − ½)Δn, (k + ½)Δn]
 * clipped to [n_min, n_max], = G_d(n0)·n0²·(1/a − 1/b), m². Integrating
 * rather than taking G_d(n_k)·Δn makes the harmonics' total variance the
 * band's exactly, G_d(n0)·n0²·(1/n_min − 1/n_max), whatever Δn. */
static double harmonic_var(const amfi_profile_params *p, const plan *pl, long k)
{
    const double a = fmax((k - 0.5) / pl->Lp, p->n_min_cpm);
    const double b = fmin((k + 0.5) / pl->Lp, p->n_max_cpm);
    const double n0 = AMFI_PROFILE_N0_CPM;
    return b > a ? pl->gd * n0 * n0 * (1.0 / a - 1.0 / b) : 0.0;
}

/* Coefficients of every track: re, im (n_tracks × n_harm, row-major), with
 * z_i(x) = Σ_h re[i,h]·cos(2π n_h x) − im[i,h]·sin(2π n_h x),
 * n_h = (k_lo + h)/L_p. Draws the phases from a fresh mt19937 seeded with
 * p->seed. Returns 0 or AMFI_ENOMEM. Exposed (static) to the tests, which
 * check the FFT against a direct sum of these harmonics. */
static int synth_coefficients(const amfi_profile_params *p, const plan *pl, double *re,
                              double *im)
{
    const int N = p->n_tracks;
    const long H = pl->k_hi - pl->k_lo + 1;
    const double dn = 1.0 / pl->Lp;
    double *phi = malloc((size_t)N * (size_t)H * sizeof *phi); /* N × H */
    double *L = malloc((size_t)N * (size_t)N * sizeof *L);
    double *r = malloc(3 * (size_t)N * sizeof *r); /* r, cos φ, sin φ */
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    int rc = AMFI_ENOMEM;
    if (!phi || !L || !r || !rng)
        goto out;
    double *cph = r + N, *sph = r + 2 * N;
    gsl_rng_set(rng, p->seed);
    for (long q = 0; q < (long)N * H; q++) /* component-major, see top */
        phi[q] = 2.0 * M_PI * gsl_rng_uniform(rng);
    for (long h = 0; h < H; h++) {
        const double n = (double)(pl->k_lo + h) * dn;
        const double A = sqrt(2.0 * harmonic_var(p, pl, pl->k_lo + h));
        for (int d = 0; d < N; d++)
            r[d] = amfi_profile_coherence(n, d * p->track_spacing_m);
        cholesky_toeplitz(N, r, L);
        for (int m = 0; m < N; m++) {
            cph[m] = cos(phi[(long)m * H + h]);
            sph[m] = sin(phi[(long)m * H + h]);
        }
        for (int i = 0; i < N; i++) {
            double cr = 0.0, ci = 0.0;
            for (int m = 0; m <= i; m++) {
                cr += L[i * N + m] * cph[m];
                ci += L[i * N + m] * sph[m];
            }
            re[(long)i * H + h] = A * cr;
            im[(long)i * H + h] = A * ci;
        }
    }
    rc = 0;
out:
    gsl_rng_free(rng);
    free(r);
    free(L);
    free(phi);
    return rc;
}

int amfi_profile_create(const amfi_profile_params *p, amfi_profile **out, char *err,
                        size_t errlen)
{
    *out = NULL;
    plan pl;
    int rc = make_plan(p, &pl, err, errlen);
    if (rc)
        return rc;
    const int N = p->n_tracks;
    const long H = pl.gd > 0.0 ? pl.k_hi - pl.k_lo + 1 : 0;
    amfi_profile *pr = calloc(1, sizeof *pr);
    double *re = NULL, *im = NULL, *buf = NULL;
    gsl_fft_halfcomplex_wavetable *wt = NULL;
    gsl_fft_real_workspace *ws = NULL;
    rc = AMFI_ENOMEM;
    if (!pr)
        goto fail;
    pr->p = *p;
    pr->n_points = pl.n_points;
    pr->inv_dx = 1.0 / p->dx_m;
    pr->x_max = p->length_m;
    pr->z = calloc((size_t)N * (size_t)pl.n_points, sizeof *pr->z);
    if (!pr->z)
        goto fail;
    amfi_profile_info *in = &pr->info;
    in->gd_n0_m3 = pl.gd;
    in->period_m = pl.Lp;
    in->dn_cpm = 1.0 / pl.Lp;
    in->n_harmonics = (int)H;
    in->n_first_cpm = H ? (double)pl.k_lo / pl.Lp : 0.0;
    in->n_last_cpm = H ? (double)pl.k_hi / pl.Lp : 0.0;
    in->n_points = pl.n_points;
    double var = 0.0;
    for (long h = 0; h < H; h++)
        var += harmonic_var(p, &pl, pl.k_lo + h);
    in->sigma_m = sqrt(var);
    if (H > 0) {
        re = malloc((size_t)N * (size_t)H * sizeof *re);
        im = malloc((size_t)N * (size_t)H * sizeof *im);
        buf = malloc((size_t)pl.M * sizeof *buf);
        if (!re || !im || !buf)
            goto fail;
        if ((rc = synth_coefficients(p, &pl, re, im)) != 0)
            goto fail;
        rc = AMFI_ENOMEM;
        wt = gsl_fft_halfcomplex_wavetable_alloc((size_t)pl.M);
        ws = gsl_fft_real_workspace_alloc((size_t)pl.M);
        if (!wt || !ws)
            goto fail;
        for (int i = 0; i < N; i++) {
            /* GSL halfcomplex storage of c_0 .. c_{M−1} (c_{M−k} = conj c_k):
             * buf[0] = c_0, buf[2k−1] = Re c_k, buf[2k] = Im c_k for
             * 0 < k < M/2, buf[M−1] = Re c_{M/2} when M is even. The backward
             * transform gives Σ_k c_k e^{+2πi jk/M} = c_0 + 2 Re Σ_{0<k<M/2} ...;
             * c_k = C_ik / 2 makes that Σ Re(C_ik e^{2πi n_k x_j}). */
            memset(buf, 0, (size_t)pl.M * sizeof *buf);
            for (long h = 0; h < H; h++) {
                const long k = pl.k_lo + h;
                buf[2 * k - 1] = 0.5 * re[(long)i * H + h];
                buf[2 * k] = 0.5 * im[(long)i * H + h];
            }
            if (gsl_fft_halfcomplex_backward(buf, 1, (size_t)pl.M, wt, ws) != 0) {
                msg(err, errlen, "inverse FFT of %ld points failed", pl.M);
                rc = AMFI_ENUM;
                goto fail;
            }
            memcpy(pr->z + (long)i * pl.n_points, buf, (size_t)pl.n_points * sizeof *buf);
        }
    }
    gsl_fft_real_workspace_free(ws);
    gsl_fft_halfcomplex_wavetable_free(wt);
    free(buf);
    free(im);
    free(re);
    *out = pr;
    return 0;
fail:
    if (rc == AMFI_ENOMEM)
        msg(err, errlen, "out of memory (%d tracks × %ld points, %ld harmonics)", N, pl.M, H);
    if (ws)
        gsl_fft_real_workspace_free(ws);
    if (wt)
        gsl_fft_halfcomplex_wavetable_free(wt);
    free(buf);
    free(im);
    free(re);
    amfi_profile_destroy(pr);
    return rc;
}

void amfi_profile_destroy(amfi_profile *p)
{
    if (!p)
        return;
    free(p->z);
    free(p);
}

double amfi_profile_height(const amfi_profile *p, int track, double x_m)
{
    if (track < 0)
        track = 0;
    else if (track >= p->p.n_tracks)
        track = p->p.n_tracks - 1;
    double x = x_m > 0.0 ? (x_m < p->x_max ? x_m : p->x_max) : 0.0; /* NaN → 0 */
    const double u = x * p->inv_dx;
    long j = (long)u;
    if (j > p->n_points - 2)
        j = p->n_points - 2;
    const double t = u - (double)j;
    const double *z = p->z + (long)track * p->n_points + j;
    return z[0] + t * (z[1] - z[0]);
}

int amfi_profile_draw_track(const amfi_profile *p, double std_tracks, gsl_rng *rng)
{
    const int N = p->p.n_tracks;
    const double c = 0.5 * (N - 1);
    if (!(std_tracks > 0.0) || N == 1)
        return (int)floor(c + 0.5);
    /* inverse CDF of the normal truncated to [−0.5, N − 0.5) */
    const double Plo = gsl_cdf_ugaussian_P((-0.5 - c) / std_tracks);
    const double Phi = gsl_cdf_ugaussian_P((N - 0.5 - c) / std_tracks);
    const double P = Plo + gsl_rng_uniform(rng) * (Phi - Plo);
    double y = c + std_tracks * gsl_cdf_ugaussian_Pinv(P);
    if (!isfinite(y)) /* P = 0 (u = 0 with a bound beyond −38σ) or an absurd std */
        y = c;
    double t = floor(y + 0.5);
    if (t < 0.0)
        t = 0.0;
    if (t > N - 1)
        t = N - 1;
    return (int)t;
}

int amfi_profile_tracks(const amfi_profile *p) { return p->p.n_tracks; }

double amfi_profile_length(const amfi_profile *p) { return p->p.length_m; }

const amfi_profile_params *amfi_profile_params_of(const amfi_profile *p) { return &p->p; }

void amfi_profile_get_info(const amfi_profile *p, amfi_profile_info *out) { *out = p->info; }

const double *amfi_profile_grid(const amfi_profile *p, int track)
{
    if (track < 0 || track >= p->p.n_tracks)
        return NULL;
    return p->z + (long)track * p->n_points;
}
