/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dense.h: the small dense linear-algebra helpers of the sweeps, on LAPACK.
 * Leaf of libamfi's call graph (internal.h): calls LAPACK only.
 */
#ifndef AMFI_DENSE_H
#define AMFI_DENSE_H

/* Largest matrix amfi_spd_inverse inverts with its work on the stack. */
#define AMFI_DENSE_MAX 24

/* A ← A⁻¹ for a small symmetric positive definite matrix (column-major):
 * LAPACK dsytrf + dsytrs against the identity (na ≤ AMFI_DENSE_MAX; larger:
 * dpotrf + dpotri), symmetric to the last bit. No allocation, no OpenBLAS
 * work buffer. Returns 0, or > 0 when A is not positive definite (or
 * singular). */
int amfi_spd_inverse(int na, double *A);

/* Solve A x = b in place (b ← x) for a symmetric positive semi-definite A
 * (n × n, overwritten): each diagonal entry raised by 1e-13 of itself (an
 * empty row pinned at zero), then Cholesky (LAPACK dposv). Once per solve,
 * not per step. Returns 0 or −1. */
int amfi_spd_solve(int n, double *A, double *b);

#endif
