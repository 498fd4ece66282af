/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * multi.c: several vehicles on the span solved together (issue 13). Every
 * vehicle's axles move at its own speed from its own entry time; all axles go
 * into one sweep (solver.c's amfi_solve_window/_lambda/_end), then each vehicle's GVW comes
 * from its own axles' mean forces, with a quality figure from a second sweep
 * at a tenth of λ (how far the weight moves when the regularisation that
 * decides the load split between close axles is loosened) and a
 * separability figure from the normal matrix of a constant-axle-load model
 * (see amfi_vehicle_result in amfi.h). An event of several vehicles may be
 * solved at a fraction of λ (amfi_multi_passage.lambda_factor, round five).
 * Pure computation; runs on the caller's thread and uses the solver handle's
 * workspace (grown here, before any time loop) plus per-call scratch for the
 * quality figure.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dense.h"
#include "solver_internal.h"

amfi_passage_times amfi_multi_window(double span_m, const amfi_multi_passage *p,
                                     double pre_roll_s, double post_roll_s)
{
    amfi_passage_times w = {0.0, 0.0, 0.0};
    for (int v = 0; v < p->n_vehicles; v++) {
        const amfi_vehicle *ve = &p->vehicle[v];
        amfi_passage_times one = amfi_passage_window(span_m, ve->speed_mps, ve->n_axles,
                                                     ve->axle_spacing_m, 0.0, 0.0);
        double exit_s = ve->entry_s + one.on_span_s;
        if (v == 0 || ve->entry_s < w.start_s)
            w.start_s = ve->entry_s;
        if (v == 0 || exit_s > w.on_span_s)
            w.on_span_s = exit_s;
    }
    w.start_s -= pre_roll_s;
    w.end_s = w.on_span_s + post_roll_s;
    return w;
}

/* Normal matrix A (na × na) of the constant-axle-load model: column a is the
 * sensors' response, in the solver's output equation (paper: backward
 * difference of modal velocities), to a unit load moving with axle a while it
 * is on the span. Modes: the solver's (modal) or all (nodal). */
static int normal_matrix(const struct amfi_solver *s, double *A)
{
    const amfi_bridge *b = s->b;
    const int n = s->n, na = s->na, ns = s->ns, N = s->N;
    const int m = s->mode ? s->m : n;
    const double L = b->p.span_m, h = s->h;
    double *Phi = malloc(sizeof(double) * 4 * m);
    double *G = malloc(sizeof(double) * 2 * m);
    double *c = malloc(sizeof(double) * ns * m);
    double *q = calloc((size_t)2 * m * na, sizeof(double));
    double *all = malloc(sizeof(double) * n);
    double *y = malloc(sizeof(double) * ns * na);
    if (!Phi || !G || !c || !q || !all || !y) {
        free(Phi), free(G), free(c), free(q), free(all), free(y);
        return AMFI_ENOMEM;
    }
    int *mode = s->mode;
    for (int si = 0; si < ns; si++) {
        amfi_bridge_mode_values(b, s->p.sensor_x_m[si], all);
        for (int k = 0; k < m; k++)
            c[si * m + k] = all[mode ? mode[k] : k];
    }
    for (int k = 0; k < m; k++) {
        int kk = mode ? mode[k] : k;
        amfi_modal_block(b->omega[kk], b->zeta[kk], h, Phi + 4 * k, G + 2 * k);
    }
    memset(A, 0, sizeof(double) * na * na);
    /* q: per axle a, per mode k, state [q, q'] of the unit-load response */
    for (int j = 0; j < N; j++) {
        memset(y, 0, sizeof(double) * ns * na);
        for (int a = 0; a < na; a++) {
            double x = axle_x(s, a, j);
            int on = x >= 0.0 && x <= L;
            if (on)
                amfi_bridge_mode_values(b, x, all);
            double *qa = q + (size_t)2 * m * a;
            for (int k = 0; k < m; k++) {
                const double *F = Phi + 4 * k;
                double f = on ? all[mode ? mode[k] : k] : 0.0;
                double q0 = qa[2 * k], q1 = qa[2 * k + 1];
                double n0 = F[0] * q0 + F[1] * q1 + G[2 * k] * f;
                double n1 = F[2] * q0 + F[3] * q1 + G[2 * k + 1] * f;
                double dv = (n1 - q1) / h;
                for (int si = 0; si < ns; si++)
                    y[si * na + a] += c[si * m + k] * dv;
                qa[2 * k] = n0;
                qa[2 * k + 1] = n1;
            }
        }
        for (int si = 0; si < ns; si++)
            for (int a = 0; a < na; a++)
                for (int bb = a; bb < na; bb++)
                    A[a * na + bb] += s->w[si] * y[si * na + a] * y[si * na + bb];
    }
    for (int a = 0; a < na; a++)
        for (int bb = 0; bb < a; bb++)
            A[a * na + bb] = A[bb * na + a];
    free(Phi), free(G), free(c), free(q), free(all), free(y);
    return AMFI_OK;
}

/* Each vehicle's GVW, kg, from the sweep's forces in s->force: the sum of
 * its axles' mean forces while on the span (as amfi_solve_end). */
static void vehicle_gvw(const struct amfi_solver *s, const amfi_multi_passage *p, double *gvw)
{
    int i = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        gvw[v] = 0.0;
        for (int a = 0; a < p->vehicle[v].n_axles; a++, i++)
            gvw[v] += amfi_axle_mean_force(s, i) / AMFI_GRAVITY;
    }
}

/* uᵀ M⁻¹ u for the SPD block M (k × k) of A at rows/cols first..first+k−1 (or
 * all of A when k == na), u = ones. */
static int quad_inverse(const double *A, int na, int first, int k, double *out)
{
    double *M = malloc(sizeof(double) * k * k);
    double *u = malloc(sizeof(double) * k);
    if (!M || !u) {
        free(M), free(u);
        return AMFI_ENOMEM;
    }
    for (int i = 0; i < k; i++) {
        u[i] = 1.0;
        for (int j = 0; j < k; j++)
            M[i * k + j] = A[(first + i) * na + first + j];
    }
    int rc = amfi_spd_solve(k, M, u);
    double v = 0.0;
    for (int i = 0; i < k; i++)
        v += u[i];
    *out = v;
    free(M), free(u);
    return rc ? AMFI_ENUM : AMFI_OK;
}

int amfi_solve_multi(amfi_solver *s, const amfi_multi_passage *p, const amfi_lambda *lam,
                     amfi_multi_result *res, char *err, size_t errlen)
{
    if (!s || !p || !lam || !res)
        return amfi_fail(err, errlen, AMFI_EINVAL, "solve_multi: NULL argument");
#define REQ(cond, st, ...)                                                \
    do {                                                                  \
        if (!(cond))                                                      \
            return amfi_fail(err, errlen, st, __VA_ARGS__);               \
    } while (0)
    REQ(p->n_vehicles >= 1 && p->n_vehicles <= AMFI_MAX_VEHICLES, AMFI_EINVAL,
        "%d vehicles: 1..%d", p->n_vehicles, AMFI_MAX_VEHICLES);
    int na = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        const amfi_vehicle *ve = &p->vehicle[v];
        REQ(isfinite(ve->entry_s), AMFI_EINVAL, "vehicle %d: entry time is not finite", v + 1);
        REQ(isfinite(ve->speed_mps) && ve->speed_mps > 0, AMFI_EINVAL,
            "vehicle %d: speed must be > 0", v + 1);
        REQ(ve->n_axles >= 1 && ve->n_axles <= AMFI_MAX_AXLES, AMFI_EINVAL,
            "vehicle %d: %d axles, 1..%d", v + 1, ve->n_axles, AMFI_MAX_AXLES);
        for (int a = 0; a + 1 < ve->n_axles; a++)
            REQ(isfinite(ve->axle_spacing_m[a]) && ve->axle_spacing_m[a] > 0, AMFI_EINVAL,
                "vehicle %d: axle spacing %d must be > 0", v + 1, a + 1);
        na += ve->n_axles;
    }
    REQ(p->lambda_factor == 0.0 || (p->lambda_factor >= 1e-4 && p->lambda_factor <= 1.0),
        AMFI_EINVAL, "lambda_factor %g: 0 (off) or 1e-4 .. 1", p->lambda_factor);
    REQ(na <= AMFI_MAX_AXLES, AMFI_EINVAL, "%d axles in all: at most %d in one event", na,
        AMFI_MAX_AXLES);
    amfi_passage samples;
    memset(&samples, 0, sizeof samples);
    samples.n_samples = p->n_samples;
    samples.scan_rate_hz = p->scan_rate_hz;
    samples.t_first_s = p->t_first_s;
    memcpy(samples.accel, p->accel, sizeof samples.accel);
    int rc = amfi_check_samples_lambda(s, &samples, lam, err, errlen);
    if (rc)
        return rc;
    const double L = s->b->p.span_m;
    const amfi_passage_times win = amfi_multi_window(L, p, s->p.pre_roll_s, s->p.post_roll_s);
    const double t_last = p->t_first_s + (p->n_samples - 1) / p->scan_rate_hz;
    const double tol = 1e-9 + 1e-6 / p->scan_rate_hz;
    REQ(p->t_first_s <= win.start_s + tol && t_last >= win.end_s - tol, AMFI_ERANGE,
        "the data spans [%.6g, %.6g] s but the event needs [%.6g, %.6g] s", p->t_first_s,
        t_last, win.start_s, win.end_s);
    if (amfi_solver_grow_axles(s, na) != 0)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory for %d axles", na);
    /* axle i of vehicle v at x = v·(t − entry) − offset_i = v·t − (v·entry + offset_i):
     * speed 1, the vehicle's speed as the axle's factor (solver_internal.h) */
    s->speed = 1.0;
    int i = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        const amfi_vehicle *ve = &p->vehicle[v];
        double off = 0.0;
        for (int a = 0; a < ve->n_axles; a++, i++) {
            if (a > 0)
                off += ve->axle_spacing_m[a - 1];
            s->vf[i] = ve->speed_mps;
            s->off[i] = ve->speed_mps * ve->entry_s + off;
        }
    }
    memset(res, 0, sizeof *res);
    double lam_h;
    int n_solves = 0;
    if ((rc = amfi_solve_window(s, &samples, na, win.start_s, win.end_s, err, errlen)) != 0 ||
        (rc = amfi_solve_lambda(s, lam, &lam_h, &n_solves, err, errlen)) != 0)
        return rc;
    if (p->n_vehicles > 1 && p->lambda_factor > 0.0)
        lam_h *= p->lambda_factor;
    /* quality: the sweep at λ·AMFI_MULTI_QUALITY_LAMBDA first (solve_end's
     * sweep then leaves the answer in the workspace); one vehicle alone has
     * nothing to trade load with and needs no second sweep */
    double loose[AMFI_MAX_VEHICLES];
    int unfixed = 0; /* a sweep failed numerically: quality AMFI_MULTI_QUALITY_UNFIXED */
    if (p->n_vehicles > 1) {
        double rn, sn;
        rc = amfi_sweep(s, lam_h * AMFI_MULTI_QUALITY_LAMBDA, &rn, &sn);
        if (rc == AMFI_ENUM) /* axles of two vehicles at one point all along (side by
                                side, entering together): the looser problem is
                                singular; the answer at λ still stands */
            unfixed = 1;
        else if (rc != 0)
            return amfi_fail(err, errlen, rc, "quality sweep failed: %s", amfi_strerror(rc));
        n_solves++;
        if (!unfixed)
            vehicle_gvw(s, p, loose);
    }
    rc = amfi_solve_end(s, lam, lam_h, n_solves, &res->all, err, errlen);
    /* the same at λ itself: the sweep can be singular to round-off (which
     * one fails depends on the BLAS's summation order); the event is then
     * solved at 10 λ (at most 100 λ, res->all.lambda_ref says which) and its
     * vehicles marked unfixed */
    for (int k = 0; rc == AMFI_ENUM && p->n_vehicles > 1 && k < 2; k++) {
        unfixed = 1;
        lam_h *= 10.0;
        rc = amfi_solve_end(s, lam, lam_h, n_solves + k + 1, &res->all, err, errlen);
    }
    if (rc != 0)
        return rc;
    REQ(isfinite(res->all.gvw_kg), AMFI_ENUM, "the joint solution is not finite");

    double *A = malloc(sizeof(double) * na * na);
    if (!A)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    rc = normal_matrix(s, A);
    if (rc) {
        free(A);
        return amfi_fail(err, errlen, rc, "quality: %s", amfi_strerror(rc));
    }
    /* a relative ridge of 1e-12 keeps A invertible when two axles coincide */
    double tr = 0.0;
    for (int a = 0; a < na; a++)
        tr += A[a * na + a];
    for (int a = 0; a < na; a++)
        A[a * na + a] += 1e-12 * tr / na;
    res->n_vehicles = p->n_vehicles;
    res->total_gvw_kg = 0.0;
    double *U = malloc(sizeof(double) * (na * na + na));
    if (!U) {
        free(A);
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    }
    i = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        amfi_vehicle_result *vr = &res->vehicle[v];
        vr->first_axle = i;
        vr->n_axles = p->vehicle[v].n_axles;
        vr->gvw_kg = 0.0;
        for (int a = 0; a < vr->n_axles; a++) {
            vr->axle_kg[a] = res->all.axle_kg[i + a];
            vr->gvw_kg += vr->axle_kg[a];
        }
        res->total_gvw_kg += vr->gvw_kg;
        /* joint: uᵀA⁻¹u with u the vehicle's indicator over all axles */
        memcpy(U, A, sizeof(double) * na * na);
        double *u = U + na * na;
        for (int a = 0; a < na; a++)
            u[a] = (a >= i && a < i + vr->n_axles) ? 1.0 : 0.0;
        double joint = NAN, alone = NAN;
        rc = amfi_spd_solve(na, U, u) ? AMFI_ENUM : AMFI_OK;
        if (!rc) {
            joint = 0.0;
            for (int a = i; a < i + vr->n_axles; a++)
                joint += u[a];
            rc = quad_inverse(A, na, i, vr->n_axles, &alone);
        }
        if (rc) {
            free(U), free(A);
            return amfi_fail(err, errlen, rc, "quality of vehicle %d: %s", v + 1,
                             amfi_strerror(rc));
        }
        vr->separability = sqrt(joint / alone);
        vr->gvw_sd_kg = res->all.residual_rms * sqrt(joint) / AMFI_GRAVITY;
        vr->quality = 1.0;
        if (p->n_vehicles > 1 && unfixed) {
            vr->quality = AMFI_MULTI_QUALITY_UNFIXED;
        } else if (p->n_vehicles > 1) {
            vr->quality = 1.0 + 100.0 * fabs(loose[v] - vr->gvw_kg) / fabs(vr->gvw_kg);
            if (!isfinite(vr->quality)) {
                free(U), free(A);
                return amfi_fail(err, errlen, AMFI_ENUM, "quality of vehicle %d is not finite",
                                 v + 1);
            }
        }
        i += vr->n_axles;
    }
    free(U), free(A);
#undef REQ
    return AMFI_OK;
}
