/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dense.c: the small dense linear-algebra helpers of the sweeps (dense.h):
 * an SPD inverse (LAPACK's symmetric factorisation, Cholesky above 24 × 24)
 * and a ridged SPD solve (LAPACK's Cholesky).
 * Pure functions of their arguments; no allocation.
 */
#include <string.h>

#include <lapacke.h>

#include "dense.h"

/* 1 if the Bunch-Kaufman factor's D (dsytrf, lower, column-major) is
 * positive definite: by Sylvester's law of inertia, so is the matrix. */
static int bk_positive(int n, const double *F, const lapack_int *ipiv)
{
    for (int k = 0; k < n;) {
        double d11 = F[k * n + k];
        if (ipiv[k] > 0) { /* 1 × 1 pivot */
            if (!(d11 > 0.0))
                return 0;
            k++;
        } else { /* 2 × 2 pivot in rows and columns k, k + 1 */
            if (k + 1 >= n)
                return 0;
            double d21 = F[k * n + k + 1], d22 = F[(k + 1) * n + k + 1];
            if (!(d11 > 0.0 && d22 > 0.0 && d11 * d22 - d21 * d21 > 0.0))
                return 0;
            k += 2;
        }
    }
    return 1;
}

int amfi_spd_inverse(int na, double *A)
{
    /* Up to AMFI_DENSE_MAX: LAPACK's symmetric factorisation and solve
     * (dsytrf, dsytrs) against the identity. They run on level-1/2 BLAS
     * that OpenBLAS executes without a work buffer. OpenBLAS's own
     * dpotrf/dpotri (the first version) take one from its global pool on
     * every call, under a mutex all threads share: at a 2 × 2 matrix once
     * per time step, with two solver threads, that lock cost amfid a third
     * of its solve time (docs/solver.md, "Cost"). Positive definiteness is
     * checked on the factor's D, as dpotrf's info would report it. */
    if (na >= 1 && na <= AMFI_DENSE_MAX) {
        double B[AMFI_DENSE_MAX * AMFI_DENSE_MAX], work[AMFI_DENSE_MAX];
        lapack_int ipiv[AMFI_DENSE_MAX];
        lapack_int info = LAPACKE_dsytrf_work(LAPACK_COL_MAJOR, 'L', na, A, na, ipiv, work, na);
        if (info != 0)
            return (int)(info > 0 ? info : -info);
        if (!bk_positive(na, A, ipiv))
            return 1;
        memset(B, 0, sizeof(double) * (size_t)na * (size_t)na);
        for (int i = 0; i < na; i++)
            B[i * na + i] = 1.0;
        info = LAPACKE_dsytrs_work(LAPACK_COL_MAJOR, 'L', na, na, A, na, ipiv, B, na);
        if (info != 0)
            return (int)(info > 0 ? info : -info);
        for (int j = 0; j < na; j++) /* the lower triangle, mirrored */
            for (int i = j; i < na; i++)
                A[j * na + i] = A[i * na + j] = B[j * na + i];
        return 0;
    }
    lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', na, A, na);
    if (info == 0)
        info = LAPACKE_dpotri_work(LAPACK_COL_MAJOR, 'L', na, A, na);
    if (info != 0)
        return (int)info;
    for (int i = 0; i < na; i++) /* mirror the lower triangle */
        for (int j = i + 1; j < na; j++)
            A[j * na + i] = A[i * na + j];
    return 0;
}

int amfi_spd_solve(int n, double *A, double *b)
{
    /* The entries span many orders of magnitude (a slow mode's displacement,
     * a fast mode's velocity, a force not yet on the span), so any ridge is
     * relative to each diagonal entry: it changes a well-posed answer by
     * round-off only. A state the data cannot see at all (zero row) is
     * pinned at zero. */
    for (int i = 0; i < n; i++) {
        double *d = &A[(size_t)i * n + i];
        if (*d > 0.0) {
            *d *= 1.0 + 1e-13;
        } else {
            *d = 1.0;
            b[i] = 0.0;
        }
    }
    return LAPACKE_dposv_work(LAPACK_COL_MAJOR, 'U', n, 1, A, n, b, n) == 0 ? 0 : -1;
}
