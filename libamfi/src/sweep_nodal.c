/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_nodal.c: the reference A-MFI sweep, exactly as docs/model.md §4-§5 writes
 * the paper formulation: nodal coordinates, the full augmented state
 * x = [X; X'; g] (4n + na), dense F_j, Q picking u'' at the sensors.
 *     F_j = [[Φ, 0, P_j], [(Φ − I)/h, 0, P_j/h], [0, 0, I]],  T = [0; 0; I]
 *     R_N = QᵀWQ, s_N = −2QᵀW d_N;  j = N−1 … 0:
 *     K_j = (λI + TᵀRT)⁻¹,  R_j = QᵀWQ + F_jᵀ(R − RTK_jTᵀR)F_j,
 *     s_j = −2QᵀW d_j + F_jᵀ(I − RTK_jTᵀ)s,
 *     r_j = −K_j(TᵀR F_j x_j + ½Tᵀs)  with R, s of step j + 1.
 * Cost O(N·(4n + na)³) with BLAS dgemm: the slow, obvious path that the
 * modal path is tested against. It inherits the nodal conditioning
 * (M⁻¹K reaches 1e10), so agreement with the modal path is to round-off of
 * that size, not to machine precision.
 */
#include <cblas.h>
#include <math.h>
#include <string.h>

#include "dense.h"
#include "solver_internal.h"

size_t amfi_sweep_nodal_scratch(int n, int na, int ns)
{
    size_t nsf = 4 * (size_t)n + na;
    return 4 * nsf * nsf + 4 * nsf * na + 4 * nsf + 4 * (size_t)na * na +
           (size_t)n * na + (size_t)ns * nsf + 16;
}

int amfi_sweep_nodal(struct amfi_solver *s, double lam, double *res_norm, double *smo_norm)
{
    const int n = s->n, n2 = 2 * n, na = s->na, ns = s->ns, N = s->N;
    const int nsf = 4 * n + na, g0c = 4 * n; /* first force column */
    const double h = s->h;
    double *w = s->scratch;
    double *R = w;   w += (size_t)nsf * nsf;
    double *Z = w;   w += (size_t)nsf * nsf;
    double *W1 = w;  w += (size_t)nsf * nsf;
    double *F = w;   w += (size_t)nsf * nsf;
    double *U = w;   w += (size_t)nsf * na;
    double *V = w;   w += (size_t)nsf * na;
    double *sv = w;  w += nsf;
    double *zs = w;  w += nsf;
    double *x = w;   w += nsf;
    double *xn = w;  w += nsf;
    double *K = w;   w += (size_t)na * na;
    double *r = w;   w += na;
    double *Lm = w;  w += (size_t)n * na;  /* n × na load shapes */
    double *Q = w;   w += (size_t)ns * nsf; /* ns × nsf */
    double *shape = W1; /* n, used only while building rows */

    /* Q: u'' at the sensors is X'[n .. 2n) = x[3n .. 4n). */
    memset(Q, 0, sizeof(double) * ns * nsf);
    for (int si = 0; si < ns; si++)
        for (int i = 0; i < n; i++)
            Q[(size_t)si * nsf + 3 * n + i] = s->S[(size_t)si * n + i];
    /* Constant part of F. */
    memset(F, 0, sizeof(double) * nsf * nsf);
    for (int i = 0; i < n2; i++)
        for (int k = 0; k < n2; k++) {
            double p = s->PhiN[(size_t)i * n2 + k];
            F[(size_t)i * nsf + k] = p;
            F[(size_t)(n2 + i) * nsf + k] = (p - (i == k ? 1.0 : 0.0)) / h;
        }
    for (int a = 0; a < na; a++)
        F[(size_t)(g0c + a) * nsf + g0c + a] = 1.0;

#define SET_P(j)                                                                  \
    do {                                                                          \
        for (int a = 0; a < na; a++) {                                            \
            amfi_bridge_shape(s->b, axle_x(s, a, (j)), shape);                    \
            for (int i = 0; i < n; i++)                                           \
                Lm[i * na + a] = shape[i];                                        \
        }                                                                         \
        for (int i = 0; i < n2; i++)                                              \
            for (int a = 0; a < na; a++) {                                        \
                double p = 0.0;                                                   \
                for (int k = 0; k < n; k++)                                       \
                    p += s->GN[(size_t)i * n + k] * Lm[k * na + a];               \
                F[(size_t)i * nsf + g0c + a] = p;                                 \
                F[(size_t)(n2 + i) * nsf + g0c + a] = p / h;                      \
            }                                                                     \
    } while (0)

    /* R_N = QᵀWQ, s_N = −2QᵀW d_N */
    memset(R, 0, sizeof(double) * nsf * nsf);
    memset(sv, 0, sizeof(double) * nsf);
    for (int si = 0; si < ns; si++) {
        cblas_dger(CblasRowMajor, nsf, nsf, s->w[si], Q + (size_t)si * nsf, 1,
                   Q + (size_t)si * nsf, 1, R, nsf);
        cblas_daxpy(nsf, -2.0 * s->w[si] * s->d[(size_t)N * ns + si], Q + (size_t)si * nsf, 1,
                    sv, 1);
    }
    for (int j = N - 1; j >= 0; j--) {
        SET_P(j);
        for (int i = 0; i < nsf; i++)
            for (int a = 0; a < na; a++)
                U[(size_t)i * na + a] = R[(size_t)i * nsf + g0c + a];
        for (int a = 0; a < na; a++)
            for (int b = 0; b < na; b++)
                K[a * na + b] = U[(size_t)(g0c + a) * na + b] + (a == b ? lam : 0.0);
        if (amfi_spd_inverse(na, K) != 0)
            return AMFI_ENUM;
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, nsf, na, na, 1.0, U, na, K, na,
                    0.0, V, na);
        /* gain_j = K TᵀR F_j = Vᵀ F_j; gofs_j = ½ K s_g */
        double *gj = s->gain + (size_t)j * na * nsf;
        cblas_dgemm(CblasRowMajor, CblasTrans, CblasNoTrans, na, nsf, nsf, 1.0, V, na, F, nsf,
                    0.0, gj, nsf);
        for (int a = 0; a < na; a++) {
            double o = 0.0;
            for (int b = 0; b < na; b++)
                o += K[a * na + b] * sv[g0c + b];
            s->gofs[(size_t)j * na + a] = 0.5 * o;
        }
        /* zs = s − V s_g; Z = R − V Uᵀ */
        memcpy(zs, sv, sizeof(double) * nsf);
        cblas_dgemv(CblasRowMajor, CblasNoTrans, nsf, na, -1.0, V, na, sv + g0c, 1, 1.0, zs, 1);
        memcpy(Z, R, sizeof(double) * nsf * nsf);
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, nsf, nsf, na, -1.0, V, na, U, na,
                    1.0, Z, nsf);
        /* R = QᵀWQ + Fᵀ Z F; s = −2QᵀW d_j + Fᵀ zs */
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, nsf, nsf, nsf, 1.0, Z, nsf, F, nsf,
                    0.0, W1, nsf);
        cblas_dgemm(CblasRowMajor, CblasTrans, CblasNoTrans, nsf, nsf, nsf, 1.0, F, nsf, W1, nsf,
                    0.0, R, nsf);
        cblas_dgemv(CblasRowMajor, CblasTrans, nsf, nsf, 1.0, F, nsf, zs, 1, 0.0, sv, 1);
        for (int si = 0; si < ns; si++) {
            cblas_dger(CblasRowMajor, nsf, nsf, s->w[si], Q + (size_t)si * nsf, 1,
                       Q + (size_t)si * nsf, 1, R, nsf);
            cblas_daxpy(nsf, -2.0 * s->w[si] * s->d[(size_t)j * ns + si], Q + (size_t)si * nsf,
                        1, sv, 1);
        }
        for (int a = 0; a < nsf; a++) /* symmetrise */
            for (int b = a + 1; b < nsf; b++) {
                double v = 0.5 * (R[(size_t)a * nsf + b] + R[(size_t)b * nsf + a]);
                R[(size_t)a * nsf + b] = R[(size_t)b * nsf + a] = v;
            }
    }
    /* x_0 = [0; 0; g_0], g_0 free: argmin gᵀR_gg g + s_gᵀ g. */
    memset(x, 0, sizeof(double) * nsf);
    if (!s->p.fix_initial_force) {
        for (int a = 0; a < na; a++)
            for (int b = 0; b < na; b++)
                K[a * na + b] = R[(size_t)(g0c + a) * nsf + g0c + b];
        if (amfi_spd_inverse(na, K) != 0)
            return AMFI_ENUM;
        for (int a = 0; a < na; a++) {
            double v = 0.0;
            for (int b = 0; b < na; b++)
                v += K[a * na + b] * sv[g0c + b];
            x[g0c + a] = -0.5 * v;
        }
    }
    double res2 = 0.0, smo2 = 0.0;
    for (int j = 0; j < N; j++) {
        SET_P(j);
        const double *gj = s->gain + (size_t)j * na * nsf;
        for (int a = 0; a < na; a++) {
            r[a] = -(cblas_ddot(nsf, gj + (size_t)a * nsf, 1, x, 1) + s->gofs[(size_t)j * na + a]);
            s->force[(size_t)j * na + a] = x[g0c + a];
        }
        cblas_dgemv(CblasRowMajor, CblasNoTrans, nsf, nsf, 1.0, F, nsf, x, 1, 0.0, xn, 1);
        for (int a = 0; a < na; a++) {
            xn[g0c + a] += r[a];
            smo2 += r[a] * r[a];
        }
        memcpy(x, xn, sizeof(double) * nsf);
        for (int si = 0; si < ns; si++) {
            double y = cblas_ddot(nsf, Q + (size_t)si * nsf, 1, x, 1);
            double e = y - s->d[(size_t)(j + 1) * ns + si];
            s->y[(size_t)j * ns + si] = y;
            res2 += s->w[si] * e * e;
        }
    }
#undef SET_P
    for (int a = 0; a < na; a++)
        s->force[(size_t)N * na + a] = x[g0c + a];
    *res_norm = sqrt(res2);
    *smo_norm = sqrt(smo2);
    return isfinite(res2) && isfinite(smo2) ? AMFI_OK : AMFI_ENUM;
}
