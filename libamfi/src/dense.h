/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dense.h: the small dense linear-algebra helpers of the sweeps, on LAPACK.
 * Leaf of libamfi's call graph (internal.h): calls LAPACK only.
 */
#ifndef AMFI_DENSE_H
#define AMFI_DENSE_H

/* A ← A⁻¹ for a small SPD matrix (column-major, na ≤ 12): LAPACK dpotrf +
 * dpotri, the lower triangle mirrored to the upper. No allocation. Returns 0
 * or the LAPACK info. */
int amfi_spd_inverse(int na, double *A);

/* Solve A x = b in place (b ← x) for a symmetric positive semi-definite A
 * (n × n, overwritten): each diagonal entry raised by 1e-13 of itself (an
 * empty row pinned at zero), then Cholesky (LAPACK dposv). Once per solve,
 * not per step. Returns 0 or −1. */
int amfi_spd_solve(int n, double *A, double *b);

#endif
