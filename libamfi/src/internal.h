/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * internal.h: helpers shared by libamfi's sources; not part of the API.
 *
 * Call graph between libamfi's files (file -> files it calls). No file calls
 * back into one that calls it; tests/common/call_graph.sh (ctest libamfi_calls)
 * reads the library with nm, fails on a cycle and fails when this list
 * differs from the code:
 *   speed.c -> solver.c status.c sweep.c
 *   multi.c -> bridge.c dense.c discretise.c solver.c status.c sweep.c
 *   solver.c -> bridge.c discretise.c lcurve.c status.c sweep.c sweep_modal.c sweep_nodal.c
 *   lcurve.c -> sweep.c
 *   sweep.c -> sweep_modal.c sweep_nodal.c
 *   sweep_modal.c -> bridge.c dense.c
 *   sweep_nodal.c -> bridge.c dense.c
 *   newmark.c -> bridge.c status.c
 *   discretise.c -> expm.c
 *   bridge.c -> status.c
 * Leaves (LAPACK/BLAS only): dense.c, expm.c, status.c. solver.c calls the
 * sweeps directly only for their scratch sizes; the axle position (axle_x)
 * and the λ rate scale are inline in solver_internal.h.
 */
#ifndef AMFI_INTERNAL_H
#define AMFI_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>

#include "amfi/amfi.h"

/* Write a formatted message to err (if not NULL) and return status. */
int amfi_fail(char *err, size_t errlen, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Everything amfi_bridge_create computes; read-only afterwards. */
struct amfi_bridge {
    amfi_bridge_params p;
    int n;          /* free DOFs */
    int n_full;     /* 2·(n_elements + 1) */
    int *free_of;   /* n_full: free index of a full DOF, or −1 */
    double le;      /* element length, m */
    double *M, *K, *C; /* n × n */
    double *omega;  /* n, rad/s ascending */
    double *zeta;   /* n */
    double *Psi;    /* n × n, columns M-orthonormal */
    double a0, a1;  /* Rayleigh */
    double *pe;     /* n_elements × 4 × n: mode values at each element's DOFs */
};

/* Hermitian cubic shape functions of an element of length le at local
 * coordinate xi in [0, 1]: N[4] for (w_i, θ_i, w_j, θ_j). */
void amfi_hermite(double xi, double le, double N[4]);

/* Element holding x (0 <= x <= L) and its local xi. */
void amfi_bridge_locate(const amfi_bridge *b, double x, int *elem, double *xi);

#endif
