/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * newmark.c: bridge response to moving point forces, Newmark's average
 * acceleration method (γ = 1/2, β = 1/4; unconditionally stable, second
 * order) on the nodal FE equations M u'' + C u' + K u = f(t). The force
 * positions are evaluated at every step, so the load moves continuously,
 * unlike the inverse solver's zero-order hold: this is the independent
 * reference the tests check the solver against. Cost per step O(n²).
 */
#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static void load_at(const amfi_bridge *b, double t, double speed, int na, const double *off,
                    amfi_force_fn force, void *user, double *shape, double *f)
{
    memset(f, 0, sizeof(double) * b->n);
    for (int a = 0; a < na; a++) {
        double x = speed * t - off[a];
        if (amfi_bridge_shape(b, x, shape) != 0)
            continue;
        double F = force(t, a, user);
        for (int i = 0; i < b->n; i++)
            f[i] += F * shape[i];
    }
}

int amfi_forward_newmark(const amfi_bridge *b, double speed_mps, int n_axles,
                         const double *offset_m, amfi_force_fn force, void *user,
                         int n_sensors, const double *sensor_x_m, double dt_s,
                         double out_rate_hz, int n_out, double *accel_out, char *err,
                         size_t errlen)
{
    if (!b || !(speed_mps > 0) || n_axles < 1 || !offset_m || !force || n_sensors < 1 ||
        !sensor_x_m || !(dt_s > 0) || !(out_rate_hz > 0) || n_out < 1 || !accel_out)
        return amfi_fail(err, errlen, AMFI_EINVAL, "forward: invalid arguments");
    const double ratio = 1.0 / (out_rate_hz * dt_s);
    const long sub = lround(ratio);
    if (sub < 1 || fabs(ratio - (double)sub) > 1e-9 * ratio)
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "forward: 1/(out_rate·dt) = %g is not an integer", ratio);
    const int n = b->n;
    const size_t nn = (size_t)n * n;
    double *Kh = malloc(sizeof(double) * nn);
    double *S = malloc(sizeof(double) * n * n_sensors); /* n_sensors × n shape rows */
    double *u = calloc(n, sizeof(double)), *v = calloc(n, sizeof(double));
    double *a = calloc(n, sizeof(double)), *f = malloc(sizeof(double) * n);
    double *rhs = malloc(sizeof(double) * n), *tmp = malloc(sizeof(double) * n);
    double *un = malloc(sizeof(double) * n), *shape = malloc(sizeof(double) * n);
    double *Mf = malloc(sizeof(double) * nn);
    int rc = AMFI_ENOMEM;
    if (!Kh || !S || !u || !v || !a || !f || !rhs || !tmp || !un || !shape || !Mf)
        goto out;
    for (int s = 0; s < n_sensors; s++)
        amfi_bridge_shape(b, sensor_x_m[s], S + (size_t)s * n);
    const double c0 = 4.0 / (dt_s * dt_s), c1 = 2.0 / dt_s;
    for (size_t i = 0; i < nn; i++)
        Kh[i] = b->K[i] + c1 * b->C[i] + c0 * b->M[i];
    rc = AMFI_ENUM;
    /* K̂ and M are symmetric: row-major 'U' is column-major 'L', and the
     * column-major _work calls neither transpose nor allocate per step. */
    if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, Kh, n) != 0)
        goto out;
    /* At rest at t = 0: M a0 = f(0). */
    memcpy(Mf, b->M, sizeof(double) * nn);
    if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, Mf, n) != 0)
        goto out;
    load_at(b, 0.0, speed_mps, n_axles, offset_m, force, user, shape, a);
    if (LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, 1, Mf, n, a, n) != 0)
        goto out;
    for (int s = 0; s < n_sensors; s++)
        accel_out[s] = cblas_ddot(n, S + (size_t)s * n, 1, a, 1);
    const long total = (long)(n_out - 1) * sub;
    for (long k = 1; k <= total; k++) {
        const double t = k * dt_s;
        load_at(b, t, speed_mps, n_axles, offset_m, force, user, shape, f);
        /* rhs = f + M(4/dt² u + 4/dt v + a) + C(2/dt u + v) (β = 1/4, γ = 1/2) */
        for (int i = 0; i < n; i++)
            tmp[i] = c0 * u[i] + 2.0 * c1 * v[i] + a[i];
        memcpy(rhs, f, sizeof(double) * n);
        cblas_dsymv(CblasRowMajor, CblasUpper, n, 1.0, b->M, n, tmp, 1, 1.0, rhs, 1);
        for (int i = 0; i < n; i++)
            tmp[i] = c1 * u[i] + v[i];
        cblas_dsymv(CblasRowMajor, CblasUpper, n, 1.0, b->C, n, tmp, 1, 1.0, rhs, 1);
        memcpy(un, rhs, sizeof(double) * n);
        if (LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, 1, Kh, n, un, n) != 0)
            goto out;
        for (int i = 0; i < n; i++) {
            double an = c0 * (un[i] - u[i]) - 2.0 * c1 * v[i] - a[i];
            v[i] += 0.5 * dt_s * (a[i] + an);
            a[i] = an;
            u[i] = un[i];
        }
        if (k % sub == 0) {
            long o = k / sub;
            for (int s = 0; s < n_sensors; s++)
                accel_out[o * n_sensors + s] = cblas_ddot(n, S + (size_t)s * n, 1, a, 1);
        }
    }
    rc = AMFI_OK;
out:
    free(Kh);
    free(S);
    free(u);
    free(v);
    free(a);
    free(f);
    free(rhs);
    free(tmp);
    free(un);
    free(shape);
    free(Mf);
    if (rc)
        return amfi_fail(err, errlen, rc, "forward: %s", amfi_strerror(rc));
    return AMFI_OK;
}
