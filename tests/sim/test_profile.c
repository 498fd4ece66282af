/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_profile.c: road profiles (sim_publisher/profile.c) against ISO 8608
 * and the isotropic coherence model they document.
 *
 * The module's .c is included so that the FFT synthesis can be checked
 * against a direct sum of the same harmonics (the slow, obvious reference).
 * The statistical checks run on one long profile (4000 m, seed 1, 11 tracks
 * 0.2 m apart, class A, n = 0.01 .. 10 cycle/m): their tolerances are stated
 * where they are asserted, and the measured figures are printed (they are
 * the ones quoted in docs/simulator-inputs.md).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <gsl/gsl_fft_real.h>

#include "profile.c"

#define LONG_M 4000.0

static amfi_profile *long_prof; /* built once in setup: class A, 4000 m, 11 tracks */
static char err[512];

static amfi_profile *make(const amfi_profile_params *p)
{
    amfi_profile *pr = NULL;
    int rc = amfi_profile_create(p, &pr, err, sizeof err);
    if (rc)
        fail_msg("amfi_profile_create: %d: %s", rc, err);
    return pr;
}

/* ---- parameters --------------------------------------------------------- */

static void expect_bad(const amfi_profile_params *p, const char *what)
{
    amfi_profile *pr = (amfi_profile *)&err; /* must be reset to NULL */
    int rc = amfi_profile_create(p, &pr, err, sizeof err);
    assert_int_equal(rc, AMFI_EINVAL);
    assert_null(pr);
    if (!strstr(err, what))
        fail_msg("got '%s', expected '%s'", err, what);
}

static void test_params(void **state)
{
    (void)state;
    amfi_profile_params d, p;
    amfi_profile_params_default(&d);
    assert_int_equal(d.iso_class, 'A');
    assert_int_equal(d.n_tracks, 11);
    assert_true(d.track_spacing_m == 0.2);
    for (char c = 'A'; c <= 'H'; c++)
        assert_true(fabs(amfi_profile_class_gd(c) / (16e-6 * pow(4.0, c - 'A')) - 1) < 1e-15);
    assert_true(amfi_profile_class_gd('c') == 256e-6);
    assert_true(amfi_profile_class_gd('H') == 262144e-6);
    assert_true(amfi_profile_class_gd('I') == 0.0);
    assert_true(amfi_profile_class_gd(0) == 0.0);

    p = d, p.iso_class = 'Z';
    expect_bad(&p, "iso_class");
    p = d, p.gd_n0_m3 = -1e-6;
    expect_bad(&p, "gd_n0_m3");
    p = d, p.gd_n0_m3 = NAN;
    expect_bad(&p, "gd_n0_m3");
    p = d, p.length_m = 0.5;
    expect_bad(&p, "length_m");
    p = d, p.dx_m = 0.0;
    expect_bad(&p, "dx_m");
    p = d, p.n_min_cpm = 0.0;
    expect_bad(&p, "n_min_cpm");
    p = d, p.n_max_cpm = 25.0; /* Nyquist of dx = 0.02 m */
    expect_bad(&p, "Nyquist");
    p = d, p.n_max_cpm = 0.005;
    expect_bad(&p, "n_max_cpm");
    p = d, p.n_tracks = 0;
    expect_bad(&p, "n_tracks");
    p = d, p.n_tracks = AMFI_PROFILE_MAX_TRACKS + 1;
    expect_bad(&p, "n_tracks");
    p = d, p.track_spacing_m = 0.0;
    expect_bad(&p, "track_spacing_m");
    p = d, p.length_m = 1e5, p.dx_m = 1e-3;
    expect_bad(&p, "grid points");
    p = d, p.length_m = 1.0, p.n_min_cpm = 0.1, p.n_max_cpm = 0.2; /* Δn ≈ 0.98 */
    expect_bad(&p, "no harmonic");

    /* the documented synthesis of the defaults */
    amfi_profile *pr = make(&d);
    amfi_profile_info in;
    amfi_profile_get_info(pr, &in);
    print_message("default: period %.4g m, dn %.6g cycle/m, %d harmonics %.5g .. %.5g cycle/m, "
                  "%ld points, sigma %.4g mm\n",
                  in.period_m, in.dn_cpm, in.n_harmonics, in.n_first_cpm, in.n_last_cpm,
                  in.n_points, 1e3 * in.sigma_m);
    assert_true(fabs(in.period_m - 202.5) < 1e-9);
    assert_int_equal(in.n_points, 10001);
    assert_int_equal(in.n_harmonics, 2024); /* k = 2 .. 2025 */
    assert_true(fabs(in.n_first_cpm - 2 / 202.5) < 1e-12);
    assert_true(fabs(in.n_last_cpm - 10.0) < 1e-12); /* 10 × 202.5 is a harmonic */
    /* σ² = G(n0) n0² (1/n_min − 1/n_max) exactly (each harmonic carries its
     * interval's integral): 4.0 mm */
    assert_true(fabs(in.sigma_m / sqrt(16e-6 * 0.01 * (100.0 - 0.1)) - 1) < 1e-12);
    assert_int_equal(amfi_profile_tracks(pr), 11);
    assert_true(amfi_profile_length(pr) == 200.0);
    assert_true(amfi_profile_params_of(pr)->seed == 1);
    assert_null(amfi_profile_grid(pr, 11));
    assert_null(amfi_profile_grid(pr, -1));
    amfi_profile_destroy(pr);
    amfi_profile_destroy(NULL);
}

/* ---- the FFT against a direct sum of the harmonics ---------------------- */

static void test_fft_vs_direct_sum(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    p.length_m = 60.0;
    p.n_tracks = 4;
    p.seed = 7;
    amfi_profile *pr = make(&p);
    plan pl;
    assert_int_equal(make_plan(&p, &pl, err, sizeof err), 0);
    const long H = pl.k_hi - pl.k_lo + 1;
    double *re = malloc((size_t)(p.n_tracks * H) * sizeof *re);
    double *im = malloc((size_t)(p.n_tracks * H) * sizeof *im);
    assert_non_null(re);
    assert_non_null(im);
    assert_int_equal(synth_coefficients(&p, &pl, re, im), 0);
    amfi_profile_info in;
    amfi_profile_get_info(pr, &in);
    /* FFT rounding: about ε·log2(M) relative to the sum of |coefficients|;
     * 1e-12 of σ leaves three orders of magnitude of margin */
    double worst = 0.0;
    for (int i = 0; i < p.n_tracks; i++) {
        const double *z = amfi_profile_grid(pr, i);
        for (long j = 0; j < pl.n_points; j += 7) {
            double s = 0.0;
            for (long h = 0; h < H; h++) {
                const double arg = 2.0 * M_PI * (double)((pl.k_lo + h) * j % pl.M) / pl.M;
                s += re[i * H + h] * cos(arg) - im[i * H + h] * sin(arg);
            }
            worst = fmax(worst, fabs(z[j] - s));
        }
    }
    print_message("FFT vs direct sum: max |difference| %.3g m (sigma %.3g m)\n", worst,
                  in.sigma_m);
    assert_true(worst < 1e-12 * in.sigma_m);
    /* each track's ensemble variance is Σ A_k²/2 Σ_m L_im² = σ² (Cholesky
     * rows of a correlation matrix have unit norm, up to the dropped pivots) */
    for (int i = 0; i < p.n_tracks; i++) {
        double v = 0.0;
        for (long h = 0; h < H; h++)
            v += harmonic_var(&p, &pl, pl.k_lo + h);
        assert_true(fabs(v / (in.sigma_m * in.sigma_m) - 1) < 1e-12);
        double c2 = 0.0; /* Σ |C_ik|²/2 over k, with E over phases = v */
        for (long h = 0; h < H; h++)
            c2 += 0.5 * (re[i * H + h] * re[i * H + h] + im[i * H + h] * im[i * H + h]);
        if (i == 0) /* deterministic amplitudes: exact */
            assert_true(fabs(c2 / v - 1) < 1e-12);
    }
    free(re);
    free(im);
    amfi_profile_destroy(pr);
}

/* ---- heights: interpolation and clamping -------------------------------- */

static void test_height(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    p.length_m = 30.0;
    p.n_tracks = 3;
    amfi_profile *pr = make(&p);
    amfi_profile_info in;
    amfi_profile_get_info(pr, &in);
    const double *z1 = amfi_profile_grid(pr, 1);
    for (long j = 0; j + 1 < in.n_points; j += 13) {
        /* j·dx·(1/dx) may round to just below j: the same height to rounding */
        assert_true(fabs(amfi_profile_height(pr, 1, j * p.dx_m) - z1[j]) < 1e-15);
        const double mid = amfi_profile_height(pr, 1, (j + 0.5) * p.dx_m);
        assert_true(fabs(mid - 0.5 * (z1[j] + z1[j + 1])) < 1e-15);
        const double q = amfi_profile_height(pr, 1, (j + 0.25) * p.dx_m);
        assert_true(fabs(q - (0.75 * z1[j] + 0.25 * z1[j + 1])) < 1e-15);
    }
    const long last = in.n_points - 1; /* 30 m / 0.02 m: the last point is x = 30 m */
    assert_int_equal(last, 1500);
    assert_true(amfi_profile_height(pr, 1, -5.0) == z1[0]);
    assert_true(amfi_profile_height(pr, 1, NAN) == z1[0]);
    assert_true(fabs(amfi_profile_height(pr, 1, 30.0) - z1[last]) < 1e-15);
    assert_true(fabs(amfi_profile_height(pr, 1, 1e9) - z1[last]) < 1e-15);
    assert_true(fabs(amfi_profile_height(pr, 1, INFINITY) - z1[last]) < 1e-15);
    /* tracks clamp */
    assert_true(amfi_profile_height(pr, -3, 1.0) == amfi_profile_height(pr, 0, 1.0));
    assert_true(amfi_profile_height(pr, 99, 1.0) == amfi_profile_height(pr, 2, 1.0));
    amfi_profile_destroy(pr);
}

static void test_smooth(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    p.iso_class = 0;
    amfi_profile *pr = make(&p);
    amfi_profile_info in;
    amfi_profile_get_info(pr, &in);
    assert_int_equal(in.n_harmonics, 0);
    assert_true(in.gd_n0_m3 == 0.0 && in.sigma_m == 0.0);
    for (int i = 0; i < p.n_tracks; i++) {
        const double *z = amfi_profile_grid(pr, i);
        for (long j = 0; j < in.n_points; j++)
            assert_true(z[j] == 0.0);
        for (double x = -1.0; x < 201.0; x += 0.37)
            assert_true(amfi_profile_height(pr, i, x) == 0.0);
    }
    amfi_profile_destroy(pr);
    /* an explicit level overrides the class, even 0 */
    p.gd_n0_m3 = 16e-6;
    pr = make(&p);
    amfi_profile_get_info(pr, &in);
    assert_true(in.gd_n0_m3 == 16e-6 && in.n_harmonics > 0);
    amfi_profile_destroy(pr);
}

/* The class only scales the heights: class C (16 × class A's G_d) gives
 * exactly 4 × the class-A heights with the same seed. */
static void test_class_scaling(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    p.length_m = 100.0;
    amfi_profile *a = make(&p);
    p.iso_class = 'C';
    amfi_profile *c = make(&p);
    p.iso_class = 'A';
    p.gd_n0_m3 = 256e-6;
    amfi_profile *c2 = make(&p);
    amfi_profile_info in;
    amfi_profile_get_info(a, &in);
    for (int i = 0; i < 11; i++) {
        const double *za = amfi_profile_grid(a, i), *zc = amfi_profile_grid(c, i);
        const double *zc2 = amfi_profile_grid(c2, i);
        for (long j = 0; j < in.n_points; j++) {
            assert_true(fabs(zc[j] - 4.0 * za[j]) < 1e-12 * in.sigma_m);
            assert_true(zc[j] == zc2[j]);
        }
    }
    amfi_profile_destroy(a);
    amfi_profile_destroy(c);
    amfi_profile_destroy(c2);
}

/* ---- seeding ------------------------------------------------------------ */

static void test_seed(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    amfi_profile *a = make(&p), *b = make(&p);
    amfi_profile_info in;
    amfi_profile_get_info(a, &in);
    for (int i = 0; i < p.n_tracks; i++)
        assert_memory_equal(amfi_profile_grid(a, i), amfi_profile_grid(b, i),
                            (size_t)in.n_points * sizeof(double));
    p.seed = 2;
    amfi_profile *c = make(&p);
    for (int i = 0; i < p.n_tracks; i++) {
        const double *za = amfi_profile_grid(a, i), *zc = amfi_profile_grid(c, i);
        double d2 = 0.0;
        for (long j = 0; j < in.n_points; j++)
            d2 += (za[j] - zc[j]) * (za[j] - zc[j]);
        /* two independent realisations: RMS difference about σ·√2 */
        assert_true(sqrt(d2 / in.n_points) > 0.3 * in.sigma_m);
    }
    /* a track does not depend on how many tracks follow it */
    p.seed = 1;
    p.n_tracks = 1;
    amfi_profile *one = make(&p);
    assert_memory_equal(amfi_profile_grid(one, 0), amfi_profile_grid(a, 0),
                        (size_t)in.n_points * sizeof(double));
    p.n_tracks = 4;
    amfi_profile *four = make(&p);
    for (int i = 0; i < 4; i++)
        assert_memory_equal(amfi_profile_grid(four, i), amfi_profile_grid(a, i),
                            (size_t)in.n_points * sizeof(double));
    amfi_profile_destroy(a);
    amfi_profile_destroy(b);
    amfi_profile_destroy(c);
    amfi_profile_destroy(one);
    amfi_profile_destroy(four);
}

/* ---- spectrum ----------------------------------------------------------- */

/* Welch estimate of the one-sided PSD of z[0 .. n) (step dx): Hann window,
 * segments of S = 2048 points (40.96 m, bins 0.0244 cycle/m apart), 50 %
 * overlap, mean removed per segment. P[k], k = 0 .. S/2, m³. */
#define WELCH_S 2048
static void welch(const double *z, long n, double dx, double *P)
{
    double w[WELCH_S], seg[WELCH_S], U = 0.0;
    for (int j = 0; j < WELCH_S; j++) {
        w[j] = 0.5 * (1.0 - cos(2.0 * M_PI * j / WELCH_S));
        U += w[j] * w[j];
    }
    for (int k = 0; k <= WELCH_S / 2; k++)
        P[k] = 0.0;
    int segs = 0;
    for (long s0 = 0; s0 + WELCH_S <= n; s0 += WELCH_S / 2, segs++) {
        double mean = 0.0;
        for (int j = 0; j < WELCH_S; j++)
            mean += z[s0 + j];
        mean /= WELCH_S;
        for (int j = 0; j < WELCH_S; j++)
            seg[j] = w[j] * (z[s0 + j] - mean);
        assert_int_equal(gsl_fft_real_radix2_transform(seg, 1, WELCH_S), 0);
        /* radix-2 halfcomplex: Re_k at k, Im_k at S − k */
        for (int k = 1; k < WELCH_S / 2; k++)
            P[k] += seg[k] * seg[k] + seg[WELCH_S - k] * seg[WELCH_S - k];
    }
    for (int k = 0; k <= WELCH_S / 2; k++)
        P[k] *= 2.0 * dx / (U * segs);
}

/* Least-squares line log10 P = a + s·log10(n/n0) over n_lo <= n <= n_hi. */
static void fit(const double *P, double dx, double n_lo, double n_hi, double *level,
                double *slope)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int m = 0;
    for (int k = 1; k < WELCH_S / 2; k++) {
        const double n = k / (WELCH_S * dx);
        if (n < n_lo || n > n_hi)
            continue;
        const double x = log10(n / AMFI_PROFILE_N0_CPM), y = log10(P[k]);
        sx += x, sy += y, sxx += x * x, sxy += x * y, m++;
    }
    *slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    *level = pow(10.0, (sy - *slope * sx) / m);
}

/* Tolerance: Welch over ~190 overlapping segments has a relative standard
 * error of ~9 % per bin, and the fit pools ~200 bins, so the level at n0 is
 * good to a few %; ±10 % on the level and ±0.1 on the slope leave room for
 * the Hann window's leakage and for the log's bias (E log P < log E P by
 * ~1/(2·K_eff), about 0.3 %). Checked on the centre track, the first track
 * (deterministic amplitudes) and the last one. */
static void test_psd(void **state)
{
    (void)state;
    amfi_profile_info in;
    amfi_profile_get_info(long_prof, &in);
    const double dx = amfi_profile_params_of(long_prof)->dx_m;
    static double P[WELCH_S / 2 + 1];
    const int tracks[] = {5, 0, 10};
    for (int t = 0; t < 3; t++) {
        welch(amfi_profile_grid(long_prof, tracks[t]), in.n_points, dx, P);
        double level, slope;
        fit(P, dx, 0.1, 5.0, &level, &slope);
        print_message("PSD track %d, fit over 0.1 .. 5 cycle/m: G_d(n0) = %.4g m³ (%+.1f %% of "
                      "16e-6), slope %.4f\n",
                      tracks[t], level, 100.0 * (level / 16e-6 - 1), slope);
        assert_true(fabs(level / 16e-6 - 1) < 0.10);
        assert_true(fabs(slope + 2.0) < 0.1);
        /* outside the band there is nothing: well above 10 cycle/m the
         * estimate is leakage only, orders of magnitude below the line */
        fit(P, dx, 12.0, 20.0, &level, &slope);
        assert_true(level * pow(15.0 / 0.1, slope) < 1e-3 * 16e-6 * pow(15.0 / 0.1, -2));
    }
}

/* ---- the carpet's transverse correlation -------------------------------- */

static void test_coherence(void **state)
{
    (void)state;
    assert_true(amfi_profile_coherence(1.0, 0.0) == 1.0);
    assert_true(amfi_profile_coherence(0.0, 0.2) == 1.0);
    /* z·K1(z) at z = 1: K1(1) = 0.601907230197235 (Abramowitz & Stegun 9.8) */
    assert_true(fabs(amfi_profile_coherence(1.0 / (2 * M_PI), 1.0) - 0.601907230197235) < 1e-12);
    /* small z: 1 + (z²/2)·ln(z/2) + ...; large z: sqrt(πz/2)·e^{−z} */
    assert_true(amfi_profile_coherence(0.1, 0.2) > 0.97);
    assert_true(amfi_profile_coherence(20.0, 200.0) == 0.0); /* underflows quietly */
    double prev = 1.0;
    for (double n = 0.01; n < 20.0; n *= 1.1) {
        const double r = amfi_profile_coherence(n, 0.2);
        assert_true((r < prev && r > 0.0) || r == 0.0);
        prev = r;
    }
}

/* Correlation coefficient of a[0 .. n) and b[0 .. n). */
static double corr(const double *a, const double *b, long n)
{
    double ma = 0, mb = 0, sab = 0, saa = 0, sbb = 0;
    for (long j = 0; j < n; j++)
        ma += a[j], mb += b[j];
    ma /= n, mb /= n;
    for (long j = 0; j < n; j++) {
        sab += (a[j] - ma) * (b[j] - mb);
        saa += (a[j] - ma) * (a[j] - ma);
        sbb += (b[j] - mb) * (b[j] - mb);
    }
    return sab / sqrt(saa * sbb);
}

/* The model's correlation of heights (weights: each harmonic's variance) or
 * of slopes from first differences (weights × |2 sin(π n dx)/dx|²) of two
 * tracks b apart, over the profile's harmonics. */
static double model_corr(const amfi_profile *pr, double b, int slopes)
{
    const amfi_profile_params *p = amfi_profile_params_of(pr);
    plan pl;
    assert_int_equal(make_plan(p, &pl, err, sizeof err), 0);
    double num = 0, den = 0;
    for (long k = pl.k_lo; k <= pl.k_hi; k++) {
        const double n = k / pl.Lp;
        double wgt = harmonic_var(p, &pl, k);
        if (slopes)
            wgt *= pow(2.0 * sin(M_PI * n * p->dx_m) / p->dx_m, 2);
        num += wgt * amfi_profile_coherence(n, b);
        den += wgt;
    }
    return num / den;
}

/* Tolerances: the slope correlation sums ~190 000 nearly independent
 * contributions, so its sample value is within ~0.01 of the model; ±0.03.
 * The height correlation is dominated by the longest waves (0.01 .. 0.1
 * cycle/m: only 40 .. 400 cycles in 4000 m), so 1 − ρ is checked within a
 * factor 1.5 of the model. Both must fall with distance. */
static void test_carpet_correlation(void **state)
{
    (void)state;
    amfi_profile_info in;
    amfi_profile_get_info(long_prof, &in);
    const long n = in.n_points;
    const double s = amfi_profile_params_of(long_prof)->track_spacing_m;
    double *da = malloc((size_t)n * sizeof *da), *db = malloc((size_t)n * sizeof *db);
    assert_non_null(da);
    assert_non_null(db);
    const int c = 5;
    double prev_h = 1.0, prev_s = 1.0;
    for (int d = 1; d <= 5; d++) {
        double rh = 0, rs = 0;
        for (int side = -1; side <= 1; side += 2) { /* average c±d */
            const double *a = amfi_profile_grid(long_prof, c), *b = amfi_profile_grid(long_prof, c + side * d);
            rh += 0.5 * corr(a, b, n);
            for (long j = 0; j + 1 < n; j++)
                da[j] = a[j + 1] - a[j], db[j] = b[j + 1] - b[j];
            rs += 0.5 * corr(da, db, n - 1);
        }
        const double mh = model_corr(long_prof, d * s, 0), ms = model_corr(long_prof, d * s, 1);
        print_message("tracks %.1f m apart: height correlation %.4f (model %.4f), slope "
                      "correlation %.4f (model %.4f)\n",
                      d * s, rh, mh, rs, ms);
        assert_true((1 - rh) / (1 - mh) > 1 / 1.5 && (1 - rh) / (1 - mh) < 1.5);
        assert_true(fabs(rs - ms) < 0.03);
        assert_true(rh < prev_h && rs < prev_s);
        prev_h = rh, prev_s = rs;
        if (d == 1) { /* the documented ranges for adjacent tracks */
            assert_true(rh > 0.95 && rh < 0.995);
            assert_true(rs > 0.08 && rs < 0.16);
        }
    }
    free(da);
    free(db);
}

/* ---- per-vehicle track -------------------------------------------------- */

static void test_draw_track(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    p.length_m = 10.0;
    amfi_profile *pr = make(&p);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 3);
    enum { DRAWS = 200000 };
    long count[11] = {0};
    double sum = 0;
    const double sd = 1.5;
    for (int i = 0; i < DRAWS; i++) {
        int t = amfi_profile_draw_track(pr, sd, rng);
        assert_true(t >= 0 && t <= 10);
        count[t]++;
        sum += t;
    }
    /* expected: the normal(5, 1.5) mass of [t − 0.5, t + 0.5), renormalised
     * to [−0.5, 10.5); each count within 5 binomial standard deviations */
    const double Z = gsl_cdf_ugaussian_P(5.5 / sd) - gsl_cdf_ugaussian_P(-5.5 / sd);
    for (int t = 0; t <= 10; t++) {
        const double pt = (gsl_cdf_ugaussian_P((t + 0.5 - 5) / sd) -
                           gsl_cdf_ugaussian_P((t - 0.5 - 5) / sd)) / Z;
        const double e = DRAWS * pt, sdev = sqrt(DRAWS * pt * (1 - pt));
        assert_true(fabs(count[t] - e) < 5 * sdev + 1);
    }
    print_message("draw_track(std 1.5 tracks): mean %.4f (centre 5), centre share %.4f\n",
                  sum / DRAWS, (double)count[5] / DRAWS);
    assert_true(fabs(sum / DRAWS - 5.0) < 0.02); /* SE 0.0034 */
    /* std <= 0, NaN: the centre track, no draw */
    gsl_rng_set(rng, 3);
    const unsigned long first = gsl_rng_get(rng);
    gsl_rng_set(rng, 3);
    assert_int_equal(amfi_profile_draw_track(pr, 0.0, rng), 5);
    assert_int_equal(amfi_profile_draw_track(pr, -1.0, rng), 5);
    assert_int_equal(amfi_profile_draw_track(pr, NAN, rng), 5);
    assert_true(gsl_rng_get(rng) == first);
    /* a huge std: still inside, roughly uniform */
    long c2[11] = {0};
    for (int i = 0; i < 11000; i++) {
        int t = amfi_profile_draw_track(pr, 1e9, rng);
        assert_true(t >= 0 && t <= 10);
        c2[t]++;
    }
    for (int t = 0; t <= 10; t++)
        assert_true(c2[t] > 800 && c2[t] < 1200);
    /* a tiny std: always the centre */
    for (int i = 0; i < 1000; i++)
        assert_int_equal(amfi_profile_draw_track(pr, 1e-3, rng), 5);
    amfi_profile_destroy(pr);
    /* an even count: the two middle tracks equally */
    p.n_tracks = 4;
    pr = make(&p);
    long c4[4] = {0};
    for (int i = 0; i < 40000; i++)
        c4[amfi_profile_draw_track(pr, 1.0, rng)]++;
    assert_true(labs(c4[1] - c4[2]) < 600 && labs(c4[0] - c4[3]) < 600); /* ~4σ */
    assert_true(c4[1] > c4[0]);
    /* a single track */
    p.n_tracks = 1;
    amfi_profile_destroy(pr);
    pr = make(&p);
    assert_int_equal(amfi_profile_draw_track(pr, 2.0, rng), 0);
    amfi_profile_destroy(pr);
    gsl_rng_free(rng);
}

static int setup(void **state)
{
    (void)state;
    amfi_profile_params p;
    amfi_profile_params_default(&p);
    p.length_m = LONG_M;
    return amfi_profile_create(&p, &long_prof, err, sizeof err);
}

static int teardown(void **state)
{
    (void)state;
    amfi_profile_destroy(long_prof);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_fft_vs_direct_sum),
        cmocka_unit_test(test_height),
        cmocka_unit_test(test_smooth),
        cmocka_unit_test(test_class_scaling),
        cmocka_unit_test(test_seed),
        cmocka_unit_test(test_psd),
        cmocka_unit_test(test_coherence),
        cmocka_unit_test(test_carpet_correlation),
        cmocka_unit_test(test_draw_track),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
