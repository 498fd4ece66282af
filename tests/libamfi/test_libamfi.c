/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_libamfi.c: unit tests of the numerical core against analytical
 * results, slow reference paths and an independent forward integrator.
 * Each tolerance says why it is what it is.
 */
#define _GNU_SOURCE
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "amfi/amfi.h"

#include "paper20_fixture.h"

/* ---- FE model ---------------------------------------------------------- */

static void fe_frequencies(void **state)
{
    (void)state;
    const double *w = amfi_bridge_omega(bridge);
    const double L = 20.0, EI = 3.5e10 * 0.2991, mu = 2400.0 * 2.046;
    /* docs/model.md §1: f1 = 5.734 Hz within 0.1 %. */
    double f1 = w[0] / (2 * M_PI);
    assert_true(fabs(f1 / 5.734 - 1.0) < 1e-3);
    /* Simply supported beam: f_k = k²π/(2L²)·√(EI/μ); 20 cubic elements
     * are far inside 1 % for modes 2-5. */
    for (int k = 2; k <= 5; k++) {
        double fa = k * k * M_PI / (2 * L * L) * sqrt(EI / mu);
        double fk = w[k - 1] / (2 * M_PI);
        assert_true(fabs(fk / fa - 1.0) < 1e-2);
    }
    /* Rayleigh damping hits 3 % at modes 1 and 2. */
    const double *z = amfi_bridge_zeta(bridge);
    assert_true(fabs(z[0] - 0.03) < 1e-12 && fabs(z[1] - 0.03) < 1e-12);
}

static void fe_modes_orthonormal(void **state)
{
    (void)state;
    const int n = amfi_bridge_ndof(bridge);
    assert_int_equal(n, 40); /* 42 DOF less w at both supports */
    const double *M = amfi_bridge_mass(bridge), *K = amfi_bridge_stiffness(bridge);
    const double *P = amfi_bridge_modes(bridge), *w = amfi_bridge_omega(bridge);
    /* ΨᵀMΨ = I and ΨᵀKΨ = Ω²: LAPACK's backward-stable dsygvd gives
     * O(n·ε·κ) residuals; 1e-8 relative leaves a wide margin. */
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) {
            double m = 0.0, k = 0.0;
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    m += P[i * n + a] * M[i * n + j] * P[j * n + b];
                    k += P[i * n + a] * K[i * n + j] * P[j * n + b];
                }
            assert_true(fabs(m - (a == b)) < 1e-8);
            assert_true(fabs(k - (a == b) * w[a] * w[a]) < 1e-8 * w[n - 1] * w[n - 1]);
        }
}

static void fe_damage_lowers_frequency(void **state)
{
    (void)state;
    amfi_bridge_params p;
    amfi_bridge *d;
    amfi_bridge_params_paper20(&p);
    p.damage = 0.10;
    assert_int_equal(amfi_bridge_create(&p, &d, NULL, 0), 0);
    /* ω ∝ √E: 10 % stiffness loss gives √0.9 on every mode. */
    for (int k = 0; k < 5; k++)
        assert_true(fabs(amfi_bridge_omega(d)[k] / amfi_bridge_omega(bridge)[k] - sqrt(0.9)) <
                    1e-9);
    amfi_bridge_destroy(d);
}

static void fe_rejects_bad_params(void **state)
{
    (void)state;
    amfi_bridge_params p;
    amfi_bridge *d = NULL;
    char err[256];
    amfi_bridge_params_paper20(&p);
    p.n_supports = 1; /* one pin: a mechanism */
    assert_int_equal(amfi_bridge_create(&p, &d, err, sizeof err), AMFI_EINVAL);
    assert_non_null(strstr(err, "mechanism"));
    amfi_bridge_params_paper20(&p);
    p.span_m = -1;
    assert_int_equal(amfi_bridge_create(&p, &d, err, sizeof err), AMFI_EINVAL);
    amfi_bridge_params_paper20(&p);
    p.damage = 1.0;
    assert_int_equal(amfi_bridge_create(&p, &d, err, sizeof err), AMFI_EINVAL);
    amfi_bridge_params_paper20(&p);
    p.supports[1].x_m = 25;
    assert_int_equal(amfi_bridge_create(&p, &d, err, sizeof err), AMFI_EINVAL);
    assert_null(d);
}

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

/* Issue 9 item 6: every documented element count 1 .. 1000 builds (450 and
 * more were refused as a "mechanism" by an eigenvalue-ratio threshold that
 * the spectrum itself crossed), with the simply supported beam's f_k =
 * k²π/(2L²)·√(EI/μ); and a real mechanism is refused before any
 * eigenproblem, at any size. */
static void fe_element_counts(void **state)
{
    (void)state;
    const double L = 20.0, EI = 3.5e10 * 0.2991, mu = 2400.0 * 2.046;
    const double fa = M_PI / (2 * L * L) * sqrt(EI / mu);
    const int counts[] = {1, 450, 1000};
    char err[256];
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++) {
        amfi_bridge_params p;
        amfi_bridge *b = NULL;
        amfi_bridge_params_paper20(&p);
        p.n_elements = counts[c];
        double t0 = now_ms();
        int rc = amfi_bridge_create(&p, &b, err, sizeof err);
        double ms = now_ms() - t0;
        if (rc)
            fail_msg("%d elements refused: %s", counts[c], err);
        const int n = amfi_bridge_ndof(b);
        assert_int_equal(n, 2 * counts[c]); /* 2(ne + 1) less w at both supports */
        const double *w = amfi_bridge_omega(b);
        double f1 = w[0] / (2 * M_PI);
        printf("%4d elements: %4d DOF, f1 %.9f Hz (beam %.9f, %+.1e), built in %.0f ms\n",
               counts[c], n, f1, fa, f1 / fa - 1.0, ms);
        if (counts[c] == 1) {
            /* one cubic element: Rayleigh-Ritz, so above the beam, by 11 % */
            assert_true(f1 > fa && f1 / fa - 1.0 < 0.12);
        } else {
            /* discretisation error ~(le/L)⁴ is nil here; what is left is
             * round-off of a spectrum spanning ω²_max/ω²_1 = 2.6e13 at 1000
             * elements, 8.5e-7 measured: 1e-5 leaves a margin */
            assert_true(fabs(f1 / fa - 1.0) < 1e-5);
            assert_true(fabs(w[1] / (2 * M_PI) / (4 * fa) - 1.0) < 1e-5);
            /* modes 1, 2 and the highest M-normalised and M-orthogonal */
            const double *M = amfi_bridge_mass(b), *P = amfi_bridge_modes(b);
            const int ks[3] = {0, 1, n - 1};
            for (int x = 0; x < 3; x++)
                for (int y = 0; y < 3; y++) {
                    double m = 0.0;
                    for (int i = 0; i < n; i++) {
                        double mi = 0.0;
                        for (int j = i - 3 < 0 ? 0 : i - 3; j <= i + 3 && j < n; j++)
                            mi += M[(size_t)i * n + j] * P[(size_t)j * n + ks[y]];
                        m += P[(size_t)i * n + ks[x]] * mi;
                    }
                    assert_true(fabs(m - (x == y)) < 1e-8);
                }
        }
        amfi_bridge_destroy(b);
    }
    /* A cantilever (w and θ at one node) is no mechanism: f1 = 1.87510407²
     * /(2πL²)·√(EI/μ). */
    amfi_bridge_params p;
    amfi_bridge *b = NULL;
    amfi_bridge_params_paper20(&p);
    p.n_elements = 100;
    p.n_supports = 1;
    p.supports[0] = (amfi_support){.x_m = 0.0, .restrain_w = 1, .restrain_theta = 1};
    assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_OK);
    const double bl = 1.87510407;
    assert_true(fabs(amfi_bridge_omega(b)[0] / (bl * bl / (L * L) * sqrt(EI / mu)) - 1.0) < 1e-6);
    amfi_bridge_destroy(b);
    /* Real mechanisms at 1000 elements, refused at once: one pin (rotation),
     * rotations held but no w (vertical translation). */
    for (int k = 0; k < 2; k++) {
        amfi_bridge_params_paper20(&p);
        p.n_elements = 1000;
        if (k == 0) {
            p.n_supports = 1;
            p.supports[0] = (amfi_support){.x_m = 10.0, .restrain_w = 1, .restrain_theta = 0};
        } else {
            p.supports[0] = (amfi_support){.x_m = 0.0, .restrain_w = 0, .restrain_theta = 1};
            p.supports[1] = (amfi_support){.x_m = 20.0, .restrain_w = 0, .restrain_theta = 1};
        }
        b = NULL;
        double t0 = now_ms();
        assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_EINVAL);
        double ms = now_ms() - t0;
        printf("mechanism refused in %.1f ms: %s\n", ms, err);
        assert_null(b);
        assert_non_null(strstr(err, "mechanism"));
        assert_non_null(strstr(err, k == 0 ? "rotate about node 500" : "up and down"));
    }
}

/* βL/2 = a of the symmetric first mode of a beam pinned at both ends with a
 * rotational spring k at each: −4a·cos a = κ(sin a + cos a·tanh a),
 * κ = kL/EI (from w = A cos βx' + B cosh βx' about mid-span with w = 0 and
 * EI w'' = −k w' at the ends); a = π/2 at κ = 0, 2.3650 (fixed) as κ → ∞. */
static double spring_pin_a(double kappa)
{
    double lo = M_PI / 2, hi = 2.36502037;
    for (int i = 0; i < 200; i++) {
        double a = 0.5 * (lo + hi);
        double g = -4 * a * cos(a) - kappa * (sin(a) + cos(a) * tanh(a));
        if (g < 0)
            lo = a;
        else
            hi = a;
    }
    return 0.5 * (lo + hi);
}

/* Bearing springs and segments against analytical results. */
static void fe_bearings_and_segments(void **state)
{
    (void)state;
    const double L = 20.0, EI = 3.5e10 * 0.2991, mu = 2400.0 * 2.046;
    char err[256];
    amfi_bridge_params p;
    amfi_bridge *b = NULL;
    /* Partly fixed bearings: rotational springs κ = kL/EI at both pins. */
    const double kappas[] = {0.5, 2.0, 20.0};
    double last = 0;
    for (size_t i = 0; i < sizeof kappas / sizeof kappas[0]; i++) {
        amfi_bridge_params_paper20(&p);
        p.n_elements = 100;
        p.supports[0].k_theta_nmprad = p.supports[1].k_theta_nmprad = kappas[i] * EI / L;
        assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_OK);
        double a = spring_pin_a(kappas[i]), beta = 2 * a / L;
        double w = beta * beta * sqrt(EI / mu), got = amfi_bridge_omega(b)[0];
        printf("rotational springs kL/EI = %g: f1 %.5f Hz, analytical %.5f Hz\n", kappas[i],
               got / (2 * M_PI), w / (2 * M_PI));
        assert_true(fabs(got / w - 1) < 1e-5);
        assert_true(got > last);
        last = got;
        amfi_bridge_destroy(b);
        b = NULL;
    }
    /* Elastic bearings under a (nearly) rigid beam: bounce ω² = 2k/(μL),
     * rocking ω² = 6k/(μL). */
    amfi_bridge_params_paper20(&p);
    p.E_pa *= 1e5;
    for (int s = 0; s < 2; s++) {
        p.supports[s].restrain_w = 0;
        p.supports[s].k_w_npm = 1e6;
    }
    assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_OK);
    assert_true(fabs(amfi_bridge_omega(b)[0] / sqrt(2e6 / (mu * L)) - 1) < 1e-5);
    assert_true(fabs(amfi_bridge_omega(b)[1] / sqrt(6e6 / (mu * L)) - 1) < 1e-5);
    amfi_bridge_destroy(b);
    b = NULL;
    /* A segment over the whole span: twice the E·I gives √2 times every ω,
     * twice the mass 1/√2; damage scales the segment's E·I. */
    amfi_bridge *ref = NULL;
    amfi_bridge_params_paper20(&p);
    assert_int_equal(amfi_bridge_create(&p, &ref, err, sizeof err), AMFI_OK);
    const double f[3][3] = {{2, 0, M_SQRT2}, {0, 2, M_SQRT1_2}, {2, 2, 1}};
    for (int c = 0; c < 3; c++) {
        amfi_bridge_params_paper20(&p);
        p.n_segments = 1;
        p.segments[0] = (amfi_segment){0.0, L, f[c][0] * EI, f[c][1] * mu};
        assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_OK);
        for (int k = 0; k < 5; k++)
            if (!(fabs(amfi_bridge_omega(b)[k] / amfi_bridge_omega(ref)[k] - f[c][2]) < 1e-9))
                fail_msg("segment case %d mode %d: ratio %.12f, want %.12f", c, k,
                         amfi_bridge_omega(b)[k] / amfi_bridge_omega(ref)[k], f[c][2]);
        amfi_bridge_destroy(b);
        b = NULL;
    }
    amfi_bridge_params_paper20(&p);
    p.n_segments = 1;
    p.segments[0] = (amfi_segment){0.0, L, 2 * EI, 0};
    p.damage = 0.19;
    assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_OK);
    assert_true(fabs(amfi_bridge_omega(b)[0] / amfi_bridge_omega(ref)[0] - M_SQRT2 * 0.9) < 1e-9);
    amfi_bridge_destroy(b);
    b = NULL;
    /* Haunches: stiffer end thirds raise f1 but less than a stiffer span;
     * the elements take the section at their middle. */
    amfi_bridge_params_paper20(&p);
    p.n_segments = 2;
    p.segments[0] = (amfi_segment){0.0, 5.0, 2 * EI, 0};
    p.segments[1] = (amfi_segment){15.0, 20.0, 2 * EI, 0};
    assert_int_equal(amfi_bridge_create(&p, &b, err, sizeof err), AMFI_OK);
    double r = amfi_bridge_omega(b)[0] / amfi_bridge_omega(ref)[0];
    assert_true(r > 1.0 && r < M_SQRT2);
    assert_true(amfi_bridge_params_EI(&p, 4.99) == 2 * EI && amfi_bridge_params_EI(&p, 5.0) == EI);
    assert_true(amfi_bridge_params_mass(&p, 17.0) == mu);
    amfi_bridge_destroy(b);
    b = NULL;
    amfi_bridge_destroy(ref);
    /* Refused: a spring on a fixed DOF, a negative spring, overlapping
     * segments, a segment off the beam, a rotational spring alone (the beam
     * can still move up and down). A cantilever on an elastic bearing with
     * a rotational spring is no mechanism. */
    for (int c = 0; c < 6; c++) {
        amfi_bridge_params_paper20(&p);
        const char *want = NULL;
        switch (c) {
        case 0: p.supports[0].k_w_npm = 1e9; want = "vertical spring on a fixed"; break;
        case 1: p.supports[1].k_theta_nmprad = -1; want = "finite and >= 0"; break;
        case 2:
            p.n_segments = 2;
            p.segments[0] = (amfi_segment){0, 10, EI, 0};
            p.segments[1] = (amfi_segment){9, 12, EI, 0};
            want = "overlaps";
            break;
        case 3:
            p.n_segments = 1;
            p.segments[0] = (amfi_segment){10, 21, EI, 0};
            want = "not a part of the beam";
            break;
        case 4:
            p.n_supports = 1;
            p.supports[0] = (amfi_support){.x_m = 0, .k_theta_nmprad = 1e9};
            want = "up and down";
            break;
        case 5:
            p.n_supports = 1;
            p.supports[0] = (amfi_support){.x_m = 0, .k_w_npm = 1e9, .k_theta_nmprad = 1e11};
            break;
        }
        b = NULL;
        int rc = amfi_bridge_create(&p, &b, err, sizeof err);
        if (!want) {
            assert_int_equal(rc, AMFI_OK);
            amfi_bridge_destroy(b);
            continue;
        }
        assert_int_equal(rc, AMFI_EINVAL);
        assert_null(b);
        if (!strstr(err, want))
            fail_msg("case %d: '%s' lacks '%s'", c, err, want);
    }
}

/* The passage window (amfi.h), shared by the solver, the daemon and the tools. */
static void passage_window(void **state)
{
    (void)state;
    const double sp[2] = {5.0, 1.5};
    amfi_passage_times w = amfi_passage_window(20.0, 25.0, 3, sp, 0.0, 0.3);
    assert_true(w.start_s == 0.0 && !signbit(w.start_s)); /* never −0 */
    assert_true(w.on_span_s == (20.0 + 5.0 + 1.5) / 25.0);
    assert_true(w.end_s == (20.0 + 5.0 + 1.5) / 25.0 + 0.3);
    w = amfi_passage_window(20.0, 10.0, 1, NULL, 0.25, 0.0);
    assert_true(w.start_s == -0.25 && w.on_span_s == 2.0 && w.end_s == 2.0);
}

static void load_vector(void **state)
{
    (void)state;
    const int n = amfi_bridge_ndof(bridge);
    double v[64];
    /* At node 10 (x = 10 m): unit on w_10, zero elsewhere. */
    assert_int_equal(amfi_bridge_shape(bridge, 10.0, v), 0);
    int d10 = amfi_bridge_dof(bridge, 10, 0);
    for (int i = 0; i < n; i++)
        assert_true(fabs(v[i] - (i == d10)) < 1e-15);
    /* Mid-element: Hermite values 1/2, l/8, 1/2, −l/8. */
    amfi_bridge_shape(bridge, 10.5, v);
    assert_true(fabs(v[amfi_bridge_dof(bridge, 10, 0)] - 0.5) < 1e-15);
    assert_true(fabs(v[amfi_bridge_dof(bridge, 10, 1)] - 0.125) < 1e-15);
    assert_true(fabs(v[amfi_bridge_dof(bridge, 11, 0)] - 0.5) < 1e-15);
    assert_true(fabs(v[amfi_bridge_dof(bridge, 11, 1)] + 0.125) < 1e-15);
    /* Off the span: zeros and 1. */
    assert_int_equal(amfi_bridge_shape(bridge, -0.01, v), 1);
    for (int i = 0; i < n; i++)
        assert_true(v[i] == 0.0);
    assert_int_equal(amfi_bridge_shape(bridge, 20.01, v), 1);
    assert_int_equal(amfi_bridge_shape(bridge, NAN, v), 1);
    /* Mode values: ψ_k(x) = shape(x)·Ψ[:, k], to round-off. */
    const double *P = amfi_bridge_modes(bridge);
    double phi[64];
    for (double x = 0.0; x <= 20.0; x += 0.37) {
        amfi_bridge_shape(bridge, x, v);
        assert_int_equal(amfi_bridge_mode_values(bridge, x, phi), 0);
        for (int k = 0; k < n; k++) {
            double ref = 0.0;
            for (int i = 0; i < n; i++)
                ref += v[i] * P[i * n + k];
            assert_true(fabs(phi[k] - ref) < 1e-12);
        }
    }
    assert_int_equal(amfi_bridge_mode_values(bridge, 20.5, phi), 1);
    assert_true(phi[0] == 0.0);
    /* Restrained DOFs: the support node's w is not a free DOF. */
    assert_int_equal(amfi_bridge_dof(bridge, 0, 0), -1);
    assert_true(amfi_bridge_dof(bridge, 0, 1) >= 0);
}

/* ---- discretisation ---------------------------------------------------- */

static double rel_diff(int n, const double *a, const double *b)
{
    double num = 0.0, den = 0.0;
    for (int i = 0; i < n; i++) {
        num += (a[i] - b[i]) * (a[i] - b[i]);
        den += b[i] * b[i];
    }
    return sqrt(num / den);
}

static void expm_known(void **state)
{
    (void)state;
    /* Rotation generator: expm([[0, θ], [−θ, 0]]) = [[cos, sin], [−sin, cos]]. */
    for (double th = 1e-3; th < 50; th *= 7) {
        double A[4] = {0, th, -th, 0}, E[4];
        assert_int_equal(amfi_expm(2, A, E), 0);
        double X[4] = {cos(th), sin(th), -sin(th), cos(th)};
        assert_true(rel_diff(4, E, X) < 1e-13 * (1 + th));
    }
    /* Jordan block: expm([[a, 1], [0, a]]) = e^a [[1, 1], [0, 1]]. */
    double J[4] = {-3, 1, 0, -3}, E[4];
    assert_int_equal(amfi_expm(2, J, E), 0);
    double X[4] = {exp(-3), exp(-3), 0, exp(-3)};
    assert_true(rel_diff(4, E, X) < 1e-14);
    double bad[4] = {0, NAN, 0, 0};
    assert_int_equal(amfi_expm(2, bad, E), AMFI_ENUM);
}

/* Closed form of every mode against Padé on its own 2 × 2 generator, over
 * the under-, critically and over-damped regimes and up to ωh = 73. The
 * comparison is made in balanced coordinates (q, q'/ω): the raw generator
 * [[0, h], [−ω²h, ·]] spans ten orders of magnitude at ω = 7.3e4, which
 * costs Padé's scaling and squaring its accuracy, not the closed form. */
static void expm_modal_block(void **state)
{
    (void)state;
    const double zetas[] = {0.0, 0.03, 0.5, 0.999999, 1.0, 1.000001, 3.0, 12.2};
    const double omegas[] = {36.0, 1e3, 7.3e4};
    const double hs[] = {2e-4, 1e-3};
    for (size_t i = 0; i < sizeof zetas / sizeof *zetas; i++)
        for (size_t j = 0; j < sizeof omegas / sizeof *omegas; j++)
            for (size_t k = 0; k < sizeof hs / sizeof *hs; k++) {
                double w = omegas[j], z = zetas[i], h = hs[k];
                double Phi[4], G[2];
                amfi_modal_block(w, z, h, Phi, G);
                /* Van Loan on D A D⁻¹, D = diag(1, 1/ω): expm([[Ã, b̃], [0, 0]]·h). */
                double A[9] = {0, w * h, 0, -w * h, -2 * z * w * h, h / w, 0, 0, 0}, E[9];
                assert_int_equal(amfi_expm(3, A, E), 0);
                double Pb[4] = {Phi[0], Phi[1] * w, Phi[2] / w, Phi[3]};
                double Gb[2] = {G[0], G[1] / w};
                double P2[4] = {E[0], E[1], E[3], E[4]}, G2[2] = {E[2], E[5]};
                assert_true(rel_diff(4, Pb, P2) < 1e-10);
                assert_true(rel_diff(2, Gb, G2) < 1e-10);
            }
}

/* Nodal Padé discretisation against the modal closed form transformed back:
 * X = T z with T = blkdiag(Ψ, Ψ), so Φ_nodal = T Φ_modal T⁻¹,
 * T⁻¹ = blkdiag(ΨᵀM, ΨᵀM), and G_nodal = T G_modal Ψᵀ. 1e-10 relative. */
static void expm_nodal_vs_modal(void **state)
{
    (void)state;
    const int n = amfi_bridge_ndof(bridge), n2 = 2 * n;
    const double h = 2e-4;
    const double *P = amfi_bridge_modes(bridge), *M = amfi_bridge_mass(bridge);
    const double *w = amfi_bridge_omega(bridge), *z = amfi_bridge_zeta(bridge);
    double *PhiN = malloc(sizeof(double) * n2 * n2), *GN = malloc(sizeof(double) * n2 * n);
    double *PhiM = calloc(n2 * n2, sizeof(double)), *GM = calloc(n2 * n, sizeof(double));
    double *PtM = malloc(sizeof(double) * n * n);
    assert_int_equal(amfi_nodal_discretise(bridge, h, PhiN, GN), 0);
    for (int k = 0; k < n; k++)
        for (int i = 0; i < n; i++) {
            double v = 0.0;
            for (int j = 0; j < n; j++)
                v += P[j * n + k] * M[j * n + i];
            PtM[k * n + i] = v;
        }
    /* Φ_nodal[(r, i), (c, j)] = Σ_k Ψ[i,k] Φ_k[r][c] (ΨᵀM)[k, j]; r, c ∈ {u, u'} */
    for (int k = 0; k < n; k++) {
        double F[4], g[2];
        amfi_modal_block(w[k], z[k], h, F, g);
        for (int r = 0; r < 2; r++)
            for (int i = 0; i < n; i++) {
                double pik = P[i * n + k];
                for (int c = 0; c < 2; c++)
                    for (int j = 0; j < n; j++)
                        PhiM[(r * n + i) * n2 + c * n + j] += pik * F[2 * r + c] * PtM[k * n + j];
                for (int j = 0; j < n; j++)
                    GM[(r * n + i) * n + j] += pik * g[r] * P[j * n + k];
            }
    }
    /* Compare block by block: the blocks differ by orders of magnitude. */
    for (int r = 0; r < 2; r++)
        for (int c = 0; c < 2; c++) {
            double num = 0, den = 0;
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    double a = PhiN[(r * n + i) * n2 + c * n + j];
                    double b = PhiM[(r * n + i) * n2 + c * n + j];
                    num += (a - b) * (a - b);
                    den += b * b;
                }
            print_message("Phi block (%d,%d): rel %.3g\n", r, c, sqrt(num / den));
            assert_true(sqrt(num / den) < 1e-10);
        }
    for (int r = 0; r < 2; r++) {
        double e = rel_diff(n * n, GN + r * n * n, GM + r * n * n);
        print_message("G block %d: rel %.3g\n", r, e);
        assert_true(e < 1e-10);
    }
    free(PhiN);
    free(GN);
    free(PhiM);
    free(GM);
    free(PtM);
}

/* ---- the solver -------------------------------------------------------- */

typedef struct case_forces {
    double F[2];   /* mean force of each axle, N */
    double amp;    /* relative sinusoidal variation */
    double f_hz;   /* its frequency */
} case_forces;

static double case_force(double t, int a, void *user)
{
    const case_forces *c = user;
    return c->F[a] * (1.0 + c->amp * sin(2 * M_PI * c->f_hz * t + 1.3 * a));
}

typedef struct recorded {
    double *accel[3]; /* per sensor */
    int n, ns;
    double rate;
} recorded;

static const double sensor_x[3] = {10.0, 5.0, 15.0}; /* mid-span first */

/* Baseline geometry: 2 axles 5 m apart at 25 m/s; 1.1 s of data from entry,
 * at ns sensors (mid-span, then the quarter points). */
static recorded record_at(case_forces *cf, double rate, int ns)
{
    recorded r = {0};
    double off[2] = {0.0, 5.0};
    r.rate = rate;
    r.ns = ns;
    r.n = (int)(1.1 * rate) + 1;
    double *all = malloc(sizeof(double) * r.n * ns);
    char err[256];
    int rc = amfi_forward_newmark(bridge, 25.0, 2, off, case_force, cf, ns, sensor_x, 2e-5,
                                  rate, r.n, all, err, sizeof err);
    assert_int_equal(rc, 0);
    for (int s = 0; s < ns; s++) {
        r.accel[s] = malloc(sizeof(double) * r.n);
        for (int i = 0; i < r.n; i++)
            r.accel[s][i] = all[i * ns + s];
    }
    free(all);
    return r;
}

static recorded record(case_forces *cf, double rate) { return record_at(cf, rate, 1); }

static void recorded_free(recorded *r)
{
    for (int s = 0; s < r->ns; s++)
        free(r->accel[s]);
}

static amfi_passage passage_of(const recorded *r)
{
    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = r->n;
    p.scan_rate_hz = r->rate;
    p.t_first_s = 0.0;
    for (int s = 0; s < r->ns; s++)
        p.accel[s] = r->accel[s];
    p.speed_mps = 25.0;
    p.n_axles = 2;
    p.axle_spacing_m[0] = 5.0;
    return p;
}

static amfi_solver *make_solver_ns(amfi_coords coords, amfi_modes modes, double rate, int ns)
{
    amfi_solver_params sp;
    amfi_solver *s = NULL;
    char err[256];
    amfi_solver_params_default(&sp, 20.0);
    sp.n_sensors = ns;
    for (int i = 0; i < ns; i++) {
        sp.sensor_x_m[i] = sensor_x[i];
        sp.sensor_weight[i] = 1.0;
    }
    sp.coords = coords;
    sp.modes = modes;
    sp.calc_rate_hz = rate;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, err, sizeof err), 0);
    return s;
}

static amfi_solver *make_solver(amfi_coords coords, amfi_modes modes, double rate)
{
    return make_solver_ns(coords, modes, rate, 1);
}

/* Copy of a result's force history (owned by the solver until next solve). */
static double *copy_forces(const amfi_result *r)
{
    size_t len = (size_t)(r->n_steps + 1) * r->n_axles;
    double *f = malloc(sizeof(double) * len);
    memcpy(f, r->force_N, sizeof(double) * len);
    return f;
}

static void modal_vs_nodal(void **state)
{
    (void)state;
    case_forces cf = {{102000.0, 74600.0}, 0.1, 2.0};
    recorded rec = record(&cf, 5000.0);
    amfi_passage p = passage_of(&rec);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_result rn, rm, ro;
    char err[256];

    amfi_solver *sn = make_solver(AMFI_COORDS_NODAL, AMFI_MODES_ALL, 5000.0);
    assert_int_equal(amfi_solve(sn, &p, &lam, &rn, err, sizeof err), 0);
    double *fn = copy_forces(&rn);
    amfi_solver *sm = make_solver(AMFI_COORDS_MODAL, AMFI_MODES_ALL, 5000.0);
    assert_int_equal(amfi_solve(sm, &p, &lam, &rm, err, sizeof err), 0);
    double *fm = copy_forces(&rm);
    amfi_solver *so = make_solver(AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 5000.0);
    assert_int_equal(amfi_solve(so, &p, &lam, &ro, err, sizeof err), 0);
    assert_int_equal(rm.n_modes, 40);
    assert_int_equal(ro.n_modes, 20); /* the symmetric modes of a mid-span sensor */
    assert_int_equal(rn.n_steps, rm.n_steps);

    double peak = 0, dmax_nm = 0, dmax_om = 0;
    for (int i = 0; i <= rm.n_steps * 2; i++) {
        peak = fmax(peak, fabs(fm[i]));
        dmax_nm = fmax(dmax_nm, fabs(fm[i] - fn[i]));
        dmax_om = fmax(dmax_om, fabs(ro.force_N[i] - fm[i]));
    }
    print_message("modal vs nodal: mean %.3g %.3g rel, history %.3g of peak; observable vs all %.3g\n",
                  rm.mean_force_N[0] / rn.mean_force_N[0] - 1,
                  rm.mean_force_N[1] / rn.mean_force_N[1] - 1, dmax_nm / peak, dmax_om / peak);
    /* The nodal path is ill-conditioned (M⁻¹K ~ 1e10): agreement to 1e-4 on
     * means and 1e-3 of the peak on histories, not to machine precision. */
    for (int a = 0; a < 2; a++)
        assert_true(fabs(rm.mean_force_N[a] / rn.mean_force_N[a] - 1) < 1e-4);
    assert_true(dmax_nm < 1e-3 * peak);
    /* Unobservable modes never reach the output: same answer to round-off. */
    assert_true(dmax_om < 1e-8 * peak);
    free(fn);
    free(fm);
    recorded_free(&rec);
    amfi_solver_destroy(sn);
    amfi_solver_destroy(sm);
    amfi_solver_destroy(so);
}

/* True mean of each axle's force over the steps it is on the span, and the
 * RMS history error away from entry and exit (first and last 10 % of each
 * axle's time on the span), relative to the axle's mean force. */
static void compare_truth(const amfi_result *r, case_forces *cf, double *mean_err,
                          double *hist_err, double *gvw_err)
{
    double tsum = 0.0, esum = 0.0;
    const double v = 25.0, off[2] = {0.0, 5.0}, L = 20.0;
    for (int a = 0; a < 2; a++) {
        double sum = 0, n = 0, e2 = 0, ne = 0;
        for (int j = 0; j <= r->n_steps; j++) {
            double t = r->t0_s + j * r->h_s, x = v * t - off[a];
            if (x < 0 || x > L)
                continue;
            sum += case_force(t, a, cf);
            n++;
            if (x > 0.1 * L && x < 0.9 * L) {
                /* g_j is held over [t_j, t_j + h): compare with mid-step truth */
                double e = r->force_N[j * 2 + a] - case_force(t + 0.5 * r->h_s, a, cf);
                e2 += e * e;
                ne++;
            }
        }
        mean_err[a] = r->mean_force_N[a] / (sum / n) - 1.0;
        tsum += sum / n;
        esum += r->mean_force_N[a];
        hist_err[a] = sqrt(e2 / ne) / (sum / n);
    }
    *gvw_err = esum / tsum - 1.0;
}

/* Issue 2 §4: the paper formulation at 5000 Hz recovers the mean axle
 * forces within 0.5 % and the histories within 5 % RMS away from entry and
 * exit, from 5000 Hz and from 1000 Hz data.
 * Constant forces: one mid-span sensor, as in the paper.
 * Forces varying 10 % at 2 Hz (a body-bounce frequency): with one mid-span
 * sensor the split between two axles on the span is not identifiable (the
 * residual is at round-off level while axle 1 is +2.5 % and axle 2 −4.6 %:
 * another force pair explains the same acceleration, and Tikhonov picks the
 * smoother one). Their sum, the GVW, is identified within 1 % (measured
 * −0.46 % from 5000 Hz and −0.68 % from 1000 Hz data). With three
 * sensors (quarter, mid, three-quarter span) the split is identified, and
 * the 0.5 % / 5 % targets hold per axle. The data are noise-free, so λ is
 * the smallest of the range 1e-12..1e-8 where the baseline GVW is flat
 * (an earlier independent check). Axle 2's mean carries a bias from its first metres on the
 * span, where no sensor sees it and smoothing sets its force: with three
 * sensors and 1000 Hz data it is −0.33 % at λ = 1e-12, −0.53 % at 1e-10,
 * −0.51 % at 1e-9; the paper's 7.94e-9 gives −1.6 % at 5000 Hz. */
static void recovers_forward_forces(void **state)
{
    (void)state;
    const double rates[2] = {5000.0, 1000.0};
    const struct { double amp; int ns; int per_axle; } cases[3] = {
        {0.0, 1, 1}, {0.1, 3, 1}, {0.1, 1, 0}};
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    lam.lambda_ref = 1e-12;
    for (int c = 0; c < 3; c++) {
        amfi_solver *s = make_solver_ns(AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 5000.0,
                                        cases[c].ns);
        for (int k = 0; k < 2; k++) {
            case_forces cf = {{102000.0, 74600.0}, cases[c].amp, 2.0};
            recorded rec = record_at(&cf, rates[k], cases[c].ns);
            amfi_passage p = passage_of(&rec);
            amfi_result r;
            char err[256];
            assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), 0);
            double me[2], he[2], ge;
            compare_truth(&r, &cf, me, he, &ge);
            print_message("amp %.2f, %d sensor(s), data %4.0f Hz: lambda %.2g, mean error "
                          "%+.3f%% %+.3f%%, GVW %+.3f%%, history RMS %.2f%% %.2f%%\n",
                          cases[c].amp, cases[c].ns, rates[k], r.lambda_ref, 100 * me[0],
                          100 * me[1], 100 * ge, 100 * he[0], 100 * he[1]);
            assert_true(fabs(ge) < (cases[c].per_axle ? 0.005 : 0.01));
            if (cases[c].per_axle)
                for (int a = 0; a < 2; a++) {
                    assert_true(fabs(me[a]) < 0.005);
                    assert_true(he[a] < 0.05);
                }
            recorded_free(&rec);
        }
        amfi_solver_destroy(s);
    }
}

/* λ is stored rate-independent: the same lambda_ref at 2500 and 5000 Hz
 * gives the same weights (within the discretisation's own difference). */
static void lambda_rate_independent(void **state)
{
    (void)state;
    case_forces cf = {{102000.0, 74600.0}, 0.1, 2.0};
    recorded rec = record(&cf, 5000.0);
    amfi_passage p = passage_of(&rec);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    lam.lambda_ref = 1e-7; /* well into the smoothing regime, where scaling matters */
    double gvw[2];
    const double rate[2] = {5000.0, 2500.0};
    for (int i = 0; i < 2; i++) {
        amfi_solver *s = make_solver(AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, rate[i]);
        amfi_result r;
        assert_int_equal(amfi_solve(s, &p, &lam, &r, NULL, 0), 0);
        assert_true(fabs(r.lambda_ref - 1e-7) < 1e-20);
        assert_true(fabs(r.lambda_h - 1e-7 * (rate[i] / 5000.0) * (rate[i] / 5000.0)) < 1e-20);
        gvw[i] = r.gvw_kg;
        amfi_solver_destroy(s);
    }
    print_message("GVW at 5000 / 2500 Hz with one lambda_ref: %.1f / %.1f kg\n", gvw[0], gvw[1]);
    assert_true(fabs(gvw[1] / gvw[0] - 1) < 0.01);
    recorded_free(&rec);
}

/* On a noisy case (5 % noise on 5000 Hz data) the default L-curve search
 * lands near the corner found by brute force on a fine grid (8 per decade
 * over the same range): within half a decade. */
static void lcurve_finds_corner(void **state)
{
    (void)state;
    case_forces cf = {{102000.0, 74600.0}, 0.1, 2.0};
    recorded rec = record(&cf, 5000.0);
    double rms = 0;
    for (int i = 0; i < rec.n; i++)
        rms += rec.accel[0][i] * rec.accel[0][i];
    rms = sqrt(rms / rec.n);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 42);
    for (int i = 0; i < rec.n; i++) /* 5 % noise, the paper's worst case */
        rec.accel[0][i] += gsl_ran_gaussian(rng, 0.05 * rms);
    gsl_rng_free(rng);
    amfi_passage p = passage_of(&rec);
    amfi_solver *s = make_solver(AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 5000.0);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    lam.automatic = 1;
    amfi_result r;
    char err[256];
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), 0);
    double chosen = r.lambda_ref, gvw = r.gvw_kg;
    assert_int_equal(r.lcurve_n, 17 + 4); /* 1e-13..1e-5 at 2/decade, 4 refinements */
    for (int i = 1; i < r.lcurve_n; i++) { /* sorted; residual grows with λ */
        assert_true(r.lcurve_lambda_ref[i] > r.lcurve_lambda_ref[i - 1]);
        assert_true(r.lcurve_residual[i] >= r.lcurve_residual[i - 1] * (1 - 1e-9));
    }
    /* Brute force: a fine grid and its own curvature maximum. */
    lam.lcurve_per_decade = 8;
    lam.lcurve_refine_points = 0;
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), 0);
    double fine = r.lambda_ref;
    print_message("L-curve: search %.3g (GVW %.1f kg), fine grid %.3g (GVW %.1f kg), %d solves\n",
                  chosen, gvw, fine, r.gvw_kg, r.n_solves);
    assert_true(fabs(log10(chosen / fine)) <= 0.5);
    /* And the corner is a sensible weight: within 5 % (noise 5 %). */
    assert_true(fabs(gvw / (176600.0 / AMFI_GRAVITY) - 1) < 0.05);
    amfi_solver_destroy(s);
    recorded_free(&rec);
}

static void solve_rejects_bad_passages(void **state)
{
    (void)state;
    double acc[600] = {0};
    amfi_solver *s = make_solver(AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 5000.0);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = 600;
    p.scan_rate_hz = 1000.0;
    p.accel[0] = acc;
    p.speed_mps = 25.0;
    p.n_axles = 2;
    p.axle_spacing_m[0] = 5.0;
    amfi_result r;
    char err[256];
    /* 0.6 s of data, window 1.0 s */
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), AMFI_ERANGE);
    assert_non_null(strstr(err, "window"));
    p.speed_mps = 0;
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    p.speed_mps = 50.0; /* 0.5 s window: covered */
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), 0);
    assert_true(fabs(r.gvw_kg) < 1e-6); /* zero data, zero weight */
    p.n_axles = 3; /* solver sized for 2 */
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    p.n_axles = 2;
    p.axle_spacing_m[0] = -1;
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    p.axle_spacing_m[0] = 5;
    lam.lambda_ref = -1;
    assert_int_equal(amfi_solve(s, &p, &lam, &r, err, sizeof err), AMFI_EINVAL);
    amfi_solver_destroy(s);
}

/* g_0 = 0 with a pre-roll (docs/model.md §6): the window starts 0.2 s before
 * entry on a bridge at rest. The smoothing term spreads the ramp from 0 to
 * the axle load into the first part of the span, so the weights come out
 * low: −2.7 % here on constant forces (an earlier independent check saw
 * −2.1 % with vehicle dynamics), where a free g_0 gives −0.2 %. That is why
 * g_0 is free by default. */
static void zero_initial_force_with_preroll(void **state)
{
    (void)state;
    case_forces cf = {{102000.0, 74600.0}, 0.0, 2.0};
    recorded rec = record(&cf, 1000.0);
    const int pad = 200; /* 0.2 s of rest before entry */
    double *acc = calloc(rec.n + pad, sizeof(double));
    memcpy(acc + pad, rec.accel[0], sizeof(double) * rec.n);
    amfi_passage p = passage_of(&rec);
    p.accel[0] = acc;
    p.n_samples = rec.n + pad;
    p.t_first_s = -0.2;
    amfi_solver_params sp;
    amfi_solver *s;
    amfi_solver_params_default(&sp, 20.0);
    sp.fix_initial_force = 1;
    sp.pre_roll_s = 0.2;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, NULL, 0), 0);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_result r;
    assert_int_equal(amfi_solve(s, &p, &lam, &r, NULL, 0), 0);
    assert_true(fabs(r.t0_s + 0.2) < 1e-12);
    assert_true(r.force_N[0] == 0.0 && r.force_N[1] == 0.0);
    double e = r.gvw_kg / (176600.0 / AMFI_GRAVITY) - 1;
    /* The same data, g_0 free, no pre-roll. */
    amfi_solver *sf = make_solver(AMFI_COORDS_MODAL, AMFI_MODES_OBSERVABLE, 5000.0);
    amfi_result rf;
    assert_int_equal(amfi_solve(sf, &p, &lam, &rf, NULL, 0), 0);
    double ef = rf.gvw_kg / (176600.0 / AMFI_GRAVITY) - 1;
    amfi_solver_destroy(sf);
    print_message("g0 = 0 with 0.2 s pre-roll: GVW error %+.3f%%; g0 free: %+.3f%%\n", 100 * e,
                  100 * ef);
    assert_true(e < 0.0 && e > -0.04); /* biased low, by a few per cent */
    assert_true(fabs(ef) < 0.005 && fabs(ef) < fabs(e));
    /* Without a pre-roll a fixed g_0 is refused at creation. */
    amfi_solver *bad = NULL;
    sp.pre_roll_s = 0.0;
    assert_int_equal(amfi_solver_create(bridge, &sp, &bad, NULL, 0), AMFI_EINVAL);
    amfi_solver_destroy(s);
    free(acc);
    recorded_free(&rec);
}

static double four_forces(double t, int a, void *user)
{
    (void)t;
    (void)user;
    return (a % 2 == 0) ? 102000.0 : 74600.0;
}

/* A bridge still vibrating from a vehicle that left 0.5 s before (paper
 * Table 5): assuming rest biases the weight; a free initial state with a
 * 0.3 s pre-roll recovers it. Independent Newmark response of two
 * identical force pairs 37.5 m apart at 25 m/s. */
static void free_initial_state_after_traffic(void **state)
{
    (void)state;
    const double off[4] = {0.0, 5.0, 37.5, 42.5}, xs = 10.0, rate = 1000.0;
    const int n = (int)(2.6 * rate) + 1;
    double *acc = malloc(sizeof(double) * n);
    assert_int_equal(amfi_forward_newmark(bridge, 25.0, 4, off, four_forces, NULL, 1, &xs, 2e-5,
                                          rate, n, acc, NULL, 0), 0);
    amfi_passage p;
    memset(&p, 0, sizeof p);
    p.n_samples = n;
    p.scan_rate_hz = rate;
    p.t_first_s = -1.5; /* the target enters 1.5 s after the first pair */
    p.accel[0] = acc;
    p.speed_mps = 25.0;
    p.n_axles = 2;
    p.axle_spacing_m[0] = 5.0;
    double err[2];
    for (int free_state = 0; free_state < 2; free_state++) {
        amfi_solver_params sp;
        amfi_solver *s;
        amfi_solver_params_default(&sp, 20.0);
        sp.free_initial_state = free_state;
        sp.pre_roll_s = 0.3;
        assert_int_equal(amfi_solver_create(bridge, &sp, &s, NULL, 0), 0);
        amfi_lambda lam;
        amfi_lambda_default(&lam);
        amfi_result r;
        assert_int_equal(amfi_solve(s, &p, &lam, &r, NULL, 0), 0);
        err[free_state] = r.gvw_kg / (176600.0 / AMFI_GRAVITY) - 1;
        amfi_solver_destroy(s);
    }
    print_message("bridge vibrating at entry: GVW error %+.2f%% assuming rest, %+.2f%% with a "
                  "free initial state\n", 100 * err[0], 100 * err[1]);
    assert_true(fabs(err[1]) < 0.005);
    assert_true(fabs(err[0]) > 2 * fabs(err[1]));
    /* On a bridge at rest a free state changes nothing (0.01 %). */
    case_forces cf = {{102000.0, 74600.0}, 0.0, 2.0};
    recorded rec = record(&cf, 1000.0);
    amfi_passage q = passage_of(&rec);
    double g[2];
    for (int free_state = 0; free_state < 2; free_state++) {
        amfi_solver_params sp;
        amfi_solver *s;
        amfi_solver_params_default(&sp, 20.0);
        sp.free_initial_state = free_state;
        assert_int_equal(amfi_solver_create(bridge, &sp, &s, NULL, 0), 0);
        amfi_lambda lam;
        amfi_lambda_default(&lam);
        amfi_result r;
        assert_int_equal(amfi_solve(s, &q, &lam, &r, NULL, 0), 0);
        g[free_state] = r.gvw_kg;
        amfi_solver_destroy(s);
    }
    assert_true(fabs(g[1] / g[0] - 1) < 1e-3);
    recorded_free(&rec);
    free(acc);
}

/* A longer passage than the workspace was sized for grows it once. */
static void solve_grows_workspace(void **state)
{
    (void)state;
    amfi_solver_params sp;
    amfi_solver *s;
    amfi_solver_params_default(&sp, 20.0);
    sp.max_duration_s = 0.1;
    assert_int_equal(amfi_solver_create(bridge, &sp, &s, NULL, 0), 0);
    size_t before = amfi_solver_workspace_bytes(s);
    case_forces cf = {{102000.0, 74600.0}, 0.0, 2.0};
    recorded rec = record(&cf, 1000.0);
    amfi_passage p = passage_of(&rec);
    amfi_lambda lam;
    amfi_lambda_default(&lam);
    amfi_result r;
    assert_int_equal(amfi_solve(s, &p, &lam, &r, NULL, 0), 0);
    assert_true(amfi_solver_workspace_bytes(s) > before);
    assert_true(fabs(r.gvw_kg / (176600.0 / AMFI_GRAVITY) - 1) < 0.005);
    amfi_solver_destroy(s);
    recorded_free(&rec);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fe_frequencies),
        cmocka_unit_test(fe_modes_orthonormal),
        cmocka_unit_test(fe_damage_lowers_frequency),
        cmocka_unit_test(fe_rejects_bad_params),
        cmocka_unit_test(fe_element_counts),
        cmocka_unit_test(fe_bearings_and_segments),
        cmocka_unit_test(passage_window),
        cmocka_unit_test(load_vector),
        cmocka_unit_test(expm_known),
        cmocka_unit_test(expm_modal_block),
        cmocka_unit_test(expm_nodal_vs_modal),
        cmocka_unit_test(modal_vs_nodal),
        cmocka_unit_test(recovers_forward_forces),
        cmocka_unit_test(lambda_rate_independent),
        cmocka_unit_test(lcurve_finds_corner),
        cmocka_unit_test(solve_rejects_bad_passages),
        cmocka_unit_test(solve_grows_workspace),
        cmocka_unit_test(zero_initial_force_with_preroll),
        cmocka_unit_test(free_initial_state_after_traffic),
    };
    return cmocka_run_group_tests_name("libamfi", tests, setup, teardown);
}
