/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * expm.c: matrix exponential by scaling and squaring with Padé approximants.
 *
 * N. J. Higham, "The scaling and squaring method for the matrix exponential
 * revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005, Algorithm 2.3: choose
 * the Padé degree m ∈ {3, 5, 7, 9, 13} from ‖A‖₁ against θ_m, scale by 2^−s
 * only for m = 13, solve (−U + V) R = U + V with LAPACK dgesv, square s
 * times. Cost: about (π_m + 2s + 4/3)·n³ flops; used once per problem size,
 * so it allocates its own scratch.
 */
#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static const double theta[5] = {1.495585217958292e-2, 2.539398330063230e-1,
                                9.504178996162932e-1, 2.097847961257068e0,
                                5.371920351148152e0};
static const int degree[5] = {3, 5, 7, 9, 13};
static const double b13[14] = {64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
                               1187353796428800.0,  129060195264000.0,   10559470521600.0,
                               670442572800.0,      33522128640.0,       1323241920.0,
                               40840800.0,          960960.0,            16380.0,
                               182.0,               1.0};
static const double b3[4] = {120.0, 60.0, 12.0, 1.0};
static const double b5[6] = {30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0};
static const double b7[8] = {17297280.0, 8648640.0, 1995840.0, 277200.0,
                             25200.0,    1512.0,    56.0,      1.0};
static const double b9[10] = {17643225600.0, 8821612800.0, 2075673600.0, 302702400.0,
                              30270240.0,    2162160.0,    110880.0,     3960.0,
                              90.0,          1.0};

static double norm1(int n, const double *A)
{
    double best = 0.0;
    for (int j = 0; j < n; j++) {
        double s = 0.0;
        for (int i = 0; i < n; i++)
            s += fabs(A[i * n + j]);
        if (s > best)
            best = s;
    }
    return best;
}

static void mul(int n, const double *X, const double *Y, double *Z)
{
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, n, n, n, 1.0, X, n, Y, n, 0.0, Z, n);
}

int amfi_expm(int n, const double *A0, double *E)
{
    if (n <= 0 || !A0 || !E)
        return AMFI_EINVAL;
    const size_t nn = (size_t)n * n;
    double *buf = malloc(sizeof(double) * nn * 7);
    lapack_int *ipiv = malloc(sizeof(lapack_int) * n);
    if (!buf || !ipiv) {
        free(buf);
        free(ipiv);
        return AMFI_ENOMEM;
    }
    double *A = buf, *A2 = buf + nn, *A4 = buf + 2 * nn, *A6 = buf + 3 * nn;
    double *U = buf + 4 * nn, *V = buf + 5 * nn, *T = buf + 6 * nn;
    for (size_t i = 0; i < nn; i++)
        if (!isfinite(A0[i])) {
            free(buf);
            free(ipiv);
            return AMFI_ENUM;
        }
    memcpy(A, A0, sizeof(double) * nn);
    double nrm = norm1(n, A);
    int s = 0, m = 13;
    for (int k = 0; k < 4; k++)
        if (nrm <= theta[k]) {
            m = degree[k];
            break;
        }
    if (m == 13 && nrm > theta[4]) {
        s = (int)ceil(log2(nrm / theta[4]));
        double sc = ldexp(1.0, -s);
        for (size_t i = 0; i < nn; i++)
            A[i] *= sc;
    }
    mul(n, A, A, A2);
    memset(U, 0, sizeof(double) * nn);
    memset(V, 0, sizeof(double) * nn);
    if (m == 13) {
        const double *b = b13;
        mul(n, A2, A2, A4);
        mul(n, A4, A2, A6);
        /* T = A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I; U = A T */
        for (size_t i = 0; i < nn; i++)
            V[i] = b[13] * A6[i] + b[11] * A4[i] + b[9] * A2[i];
        mul(n, A6, V, T);
        for (size_t i = 0; i < nn; i++)
            T[i] += b[7] * A6[i] + b[5] * A4[i] + b[3] * A2[i];
        for (int i = 0; i < n; i++)
            T[i * n + i] += b[1];
        mul(n, A, T, U);
        /* V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I */
        for (size_t i = 0; i < nn; i++)
            T[i] = b[12] * A6[i] + b[10] * A4[i] + b[8] * A2[i];
        mul(n, A6, T, V);
        for (size_t i = 0; i < nn; i++)
            V[i] += b[6] * A6[i] + b[4] * A4[i] + b[2] * A2[i];
        for (int i = 0; i < n; i++)
            V[i * n + i] += b[0];
    } else {
        const double *b = m == 3 ? b3 : m == 5 ? b5 : m == 7 ? b7 : b9;
        /* Powers P_k = A^{2k}: T accumulates the odd sum, V the even sum. */
        double *P = A4, *Pn = A6;
        memset(P, 0, sizeof(double) * nn);
        for (int i = 0; i < n; i++)
            P[i * n + i] = 1.0;
        memset(T, 0, sizeof(double) * nn);
        for (int k = 0; 2 * k <= m; k++) {
            for (size_t i = 0; i < nn; i++) {
                T[i] += b[2 * k + 1] * P[i];
                V[i] += b[2 * k] * P[i];
            }
            if (2 * k + 2 <= m) {
                mul(n, P, A2, Pn);
                double *sw = P;
                P = Pn;
                Pn = sw;
            }
        }
        mul(n, A, T, U);
    }
    /* (V − U) R = V + U */
    for (size_t i = 0; i < nn; i++) {
        double u = U[i], v = V[i];
        T[i] = v - u;
        E[i] = v + u;
    }
    lapack_int info = LAPACKE_dgesv(LAPACK_ROW_MAJOR, n, n, T, n, ipiv, E, n);
    if (info != 0) {
        free(buf);
        free(ipiv);
        return AMFI_ENUM;
    }
    for (int k = 0; k < s; k++) {
        mul(n, E, E, T);
        memcpy(E, T, sizeof(double) * nn);
    }
    free(buf);
    free(ipiv);
    return AMFI_OK;
}
