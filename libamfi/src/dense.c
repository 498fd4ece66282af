/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dense.c: the small dense linear-algebra helpers of the sweeps (dense.h):
 * an SPD inverse and a ridged SPD solve, both on LAPACK's Cholesky.
 * Pure functions of their arguments; no allocation.
 */
#include <lapacke.h>

#include "dense.h"

int amfi_spd_inverse(int na, double *A)
{
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
