/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vbi.c: coupled vehicle-bridge time integration (see vbi.h).
 *
 * Newmark, average acceleration, on M a + C v + K u = f for every
 * subsystem: with the predictors û = u + dt·v + dt²/4·a, v̂ = v + dt/2·a,
 * the new acceleration solves S a' = f' − (C v̂ + K û), S = M + dt/2·C +
 * dt²/4·K, and u' = û + β a', v' = v̂ + dt/2·a' (β = dt²/4).
 *   bridge, per mode k: S_k = 1 + dt·ζω + β ω², f_k = Σ_J ψ_k(x_J)(W_J + P_J)
 *   vehicle: S_v (n × n, inverted once with LAPACK), f_v = −P_i on axle i's hop DOF
 * Both new axle hops and new bridge deflections under the axles are affine
 * in the dynamic tyre forces P, so P_I = kt_I (y_u,I' − w(x_I)' + r_I) is
 *   (I + β·diag(kt)(A + B)) P = c,
 * A_IJ = (S_v⁻¹) between the hop DOFs of one vehicle, B_IJ = Σ_k ψ_k(x_I)ψ_k(x_J)/S_k.
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vbi.h"

#define MD AMFI_TRUCK_MAX_DOF
#define MAX_AX (AMFI_SIM_MAX_ACTIVE * AMFI_MAX_AXLES) /* axles in the simulation */

typedef struct active {
    amfi_sim_vehicle v;
    int nd, h0;                     /* DOFs; the first hop DOF (vehicle.h) */
    double u[MD], vel[MD], acc[MD]; /* vehicle.h's DOF order */
    double K[MD * MD], C[MD * MD];  /* suspension matrices, row-major nd × nd */
    double Sinv[MD * MD];           /* (M + dt/2 C + β K)⁻¹ */
    double sumF[AMFI_MAX_AXLES];
} active;

struct amfi_sim {
    const amfi_bridge *b;
    const amfi_profile *prof;
    amfi_sim_params p;
    double L;
    int n;          /* bridge modes (= DOFs) */
    int sub;        /* integration steps per sample */
    long step;      /* steps done; t = step·dt */
    const double *omega, *zeta;
    double *q, *qd, *qdd;   /* n: modal state */
    double *Sk;             /* n: effective modal mass */
    double *qh, *pred;      /* n: predictors */
    double *cs;             /* n_sensors × n: ψ_k(x_s) */
    double *phi;            /* MAX_AX × n: ψ_k at the axles */
    double *Amat, *Ms;      /* MAX_AX²: the coupling matrix and its working copy */
    active act[AMFI_SIM_MAX_ACTIVE];
    int n_act;
    amfi_sim_vehicle pend[AMFI_SIM_MAX_PENDING];
    int n_pend;
    amfi_sim_vehicle done[AMFI_SIM_MAX_PENDING];
    int n_done;
    amfi_sim_hook hook;
    void *hook_user;
};

static int fail(char *err, size_t errlen, const char *fmt, double a, double b)
{
    if (err && errlen)
        snprintf(err, errlen, fmt, a, b);
    return -1;
}

void amfi_sim_params_default(amfi_sim_params *p, double span_m)
{
    memset(p, 0, sizeof *p);
    p->dt_s = 1e-4;
    p->scan_rate_hz = 1000.0;
    p->approach_m = 100.0; /* assumed, docs/simulator.md */
    p->exit_m = 5.0;
    p->n_sensors = 1;
    p->sensor_x_m[0] = 0.5 * span_m;
}

void amfi_sim_destroy(amfi_sim *s)
{
    if (!s)
        return;
    free(s->q);
    free(s->qd);
    free(s->qdd);
    free(s->Sk);
    free(s->qh);
    free(s->pred);
    free(s->cs);
    free(s->phi);
    free(s->Amat);
    free(s->Ms);
    free(s);
}

int amfi_sim_create(const amfi_bridge *b, const amfi_profile *prof, const amfi_sim_params *p,
                    amfi_sim **out, char *err, size_t errlen)
{
    if (!b || !p || !out)
        return fail(err, errlen, "sim: NULL argument%.0g%.0g", 0, 0);
    if (!(p->dt_s > 0 && p->dt_s <= 1e-2) || !(p->scan_rate_hz > 0))
        return fail(err, errlen, "sim: dt %g s and scan rate %g Hz must be > 0", p->dt_s,
                    p->scan_rate_hz);
    double ratio = 1.0 / (p->scan_rate_hz * p->dt_s);
    long sub = lround(ratio);
    if (sub < 1 || fabs(ratio - sub) > 1e-9 * ratio)
        return fail(err, errlen, "sim: 1/(scan rate·dt) = %g is not an integer%.0g", ratio, 0);
    if (!(p->approach_m >= 0) || !(p->exit_m >= 0))
        return fail(err, errlen, "sim: approach %g m and exit %g m must be >= 0", p->approach_m,
                    p->exit_m);
    const double L = amfi_bridge_params_of(b)->span_m;
    if (p->n_sensors < 1 || p->n_sensors > AMFI_MAX_SENSORS)
        return fail(err, errlen, "sim: %g sensors (1..%g)", p->n_sensors, AMFI_MAX_SENSORS);
    for (int i = 0; i < p->n_sensors; i++)
        if (!(p->sensor_x_m[i] >= 0 && p->sensor_x_m[i] <= L))
            return fail(err, errlen, "sim: sensor at %g m is off the span [0, %g]",
                        p->sensor_x_m[i], L);
    amfi_sim *s = calloc(1, sizeof *s);
    if (!s)
        return fail(err, errlen, "sim: out of memory%.0g%.0g", 0, 0);
    s->b = b;
    s->prof = prof;
    s->p = *p;
    s->L = L;
    s->n = amfi_bridge_ndof(b);
    s->sub = (int)sub;
    s->omega = amfi_bridge_omega(b);
    s->zeta = amfi_bridge_zeta(b);
    const int n = s->n;
    s->q = calloc(n, sizeof(double));
    s->qd = calloc(n, sizeof(double));
    s->qdd = calloc(n, sizeof(double));
    s->Sk = malloc(sizeof(double) * n);
    s->qh = malloc(sizeof(double) * n);
    s->pred = malloc(sizeof(double) * n);
    s->cs = malloc(sizeof(double) * n * p->n_sensors);
    s->phi = malloc(sizeof(double) * n * MAX_AX);
    s->Amat = malloc(sizeof(double) * MAX_AX * MAX_AX);
    s->Ms = malloc(sizeof(double) * MAX_AX * MAX_AX);
    if (!s->q || !s->qd || !s->qdd || !s->Sk || !s->qh || !s->pred || !s->cs || !s->phi ||
        !s->Amat || !s->Ms) {
        amfi_sim_destroy(s);
        return fail(err, errlen, "sim: out of memory%.0g%.0g", 0, 0);
    }
    const double dt = p->dt_s, beta = dt * dt / 4.0;
    for (int k = 0; k < n; k++)
        s->Sk[k] = 1.0 + dt * s->zeta[k] * s->omega[k] + beta * s->omega[k] * s->omega[k];
    for (int i = 0; i < p->n_sensors; i++)
        amfi_bridge_mode_values(b, p->sensor_x_m[i], s->cs + (size_t)i * n);
    *out = s;
    return 0;
}

void amfi_sim_set_hook(amfi_sim *s, amfi_sim_hook fn, void *user)
{
    s->hook = fn;
    s->hook_user = user;
}

double amfi_sim_time(const amfi_sim *s) { return s->step * s->p.dt_s; }
int amfi_sim_busy(const amfi_sim *s) { return s->n_pend + s->n_act; }

static double t_start(const amfi_sim *s, const amfi_sim_vehicle *v)
{
    return v->t_entry_s - s->p.approach_m / v->speed_mps;
}

int amfi_sim_add(amfi_sim *s, const amfi_sim_vehicle *v, char *err, size_t errlen)
{
    if (!(v->speed_mps > 0 && v->speed_mps <= 100))
        return fail(err, errlen, "sim: vehicle speed %g m/s out of (0, 100]%.0g", v->speed_mps,
                    0);
    if (s->prof && (v->track < 0 || v->track >= amfi_profile_tracks(s->prof)))
        return fail(err, errlen, "sim: track %g out of range (%g tracks)", v->track,
                    amfi_profile_tracks(s->prof));
    amfi_sim_vehicle w = *v;
    if (w.truck.n_axles == 0) { /* the half-car */
        if (amfi_halfcar_finish(&w.car, err, errlen) ||
            amfi_truck_from_halfcar(&w.car, &w.truck, err, errlen))
            return -1;
    } else if (amfi_truck_finish(&w.truck, err, errlen)) {
        return -1;
    }
    if (t_start(s, v) < amfi_sim_time(s) - 0.5 * s->p.dt_s)
        return fail(err, errlen, "sim: vehicle starts its approach at %g s, before now (%g s)",
                    t_start(s, v), amfi_sim_time(s));
    if (s->n_pend == AMFI_SIM_MAX_PENDING)
        return fail(err, errlen, "sim: more than %g vehicles pending%.0g", AMFI_SIM_MAX_PENDING,
                    0);
    s->pend[s->n_pend++] = w;
    return 0;
}

/* Build one vehicle's matrices and (M + dt/2 C + β K)⁻¹. */
static int start(amfi_sim *s, const amfi_sim_vehicle *v)
{
    if (s->n_act == AMFI_SIM_MAX_ACTIVE)
        return -1;
    active *a = &s->act[s->n_act];
    memset(a, 0, sizeof *a);
    a->v = *v;
    const amfi_truck *t = &v->truck;
    double M[MD * MD];
    const int nd = amfi_truck_matrices(t, M, a->C, a->K);
    a->nd = nd;
    a->h0 = amfi_truck_hop0(t);
    for (int i = 0; i < t->n_axles; i++) {
        a->v.min_force_N[i] = INFINITY;
        a->v.max_force_N[i] = -INFINITY;
    }
    const double dt = s->p.dt_s, beta = dt * dt / 4.0;
    for (int r = 0; r < nd; r++)
        for (int q = 0; q < nd; q++)
            a->Sinv[r * nd + q] = M[r * nd + q] + 0.5 * dt * a->C[r * nd + q] +
                                  beta * a->K[r * nd + q];
    /* SPD: Cholesky inverse (column-major 'L' is row-major 'U' here). */
    if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', nd, a->Sinv, nd) != 0 ||
        LAPACKE_dpotri_work(LAPACK_COL_MAJOR, 'L', nd, a->Sinv, nd) != 0)
        return -1;
    /* dpotri filled column-major 'L', i.e. the row-major upper triangle. */
    for (int r = 0; r < nd; r++)
        for (int q = 0; q < r; q++)
            a->Sinv[r * nd + q] = a->Sinv[q * nd + r];
    s->n_act++;
    return 0;
}

/* Road height under an axle (m, positive up). */
static double road(const amfi_sim *s, int track, double x)
{
    if (!s->prof)
        return 0.0;
    return amfi_profile_height(s->prof, track, x + s->p.approach_m + AMFI_SIM_PROFILE_LEAD_M);
}

/* Retire vehicles whose rear axle is exit_m past the bridge. */
static void retire(amfi_sim *s)
{
    const double t = amfi_sim_time(s);
    for (int i = 0; i < s->n_act;) {
        active *a = &s->act[i];
        const double S = a->v.truck.x_m[a->v.truck.n_axles - 1];
        double x2 = a->v.speed_mps * (t - a->v.t_entry_s) - S;
        if (x2 <= s->L + s->p.exit_m) {
            i++;
            continue;
        }
        for (int k = 0; k < a->v.truck.n_axles; k++)
            a->v.mean_force_N[k] =
                a->v.on_span_steps[k] ? a->sumF[k] / a->v.on_span_steps[k] : NAN;
        if (s->n_done < AMFI_SIM_MAX_PENDING)
            s->done[s->n_done++] = a->v;
        s->act[i] = s->act[--s->n_act];
    }
}

/* Start pending vehicles whose approach begins at or before time t. */
static int admit(amfi_sim *s)
{
    const double t = amfi_sim_time(s);
    for (int i = 0; i < s->n_pend;) {
        if (t_start(s, &s->pend[i]) > t + 0.5 * s->p.dt_s) {
            i++;
            continue;
        }
        if (start(s, &s->pend[i]) != 0)
            return -1;
        s->pend[i] = s->pend[--s->n_pend];
    }
    return 0;
}

/* One Newmark step of the coupled system, to time (step + 1)·dt. */
static int step(amfi_sim *s, char *err, size_t errlen)
{
    const int n = s->n;
    const double dt = s->p.dt_s, beta = dt * dt / 4.0, hdt = 0.5 * dt;
    const double t1 = (s->step + 1) * dt;
    double x[MAX_AX], W[MAX_AX], kt[MAX_AX], c[MAX_AX], P[MAX_AX], wfree[MAX_AX];
    int on[MAX_AX], fixed[MAX_AX], veh[MAX_AX], ax[MAX_AX], first[AMFI_SIM_MAX_ACTIVE];
    lapack_int ipiv[MAX_AX];
    double av0[AMFI_SIM_MAX_ACTIVE][MD], vh[AMFI_SIM_MAX_ACTIVE][MD], uh[AMFI_SIM_MAX_ACTIVE][MD];
    double *const Amat = s->Amat, *const Ms = s->Ms; /* na × na, column-major */
    int na = 0;

    /* Bridge predictors and the acceleration without contact forces. */
    for (int k = 0; k < n; k++) {
        double vhk = s->qd[k] + hdt * s->qdd[k];
        s->qh[k] = s->q[k] + dt * s->qd[k] + beta * s->qdd[k];
        s->pred[k] = 2.0 * s->zeta[k] * s->omega[k] * vhk + s->omega[k] * s->omega[k] * s->qh[k];
    }
    /* Vehicles: predictors, force-free acceleration, axle data. */
    for (int v = 0; v < s->n_act; v++) {
        active *a = &s->act[v];
        const int nd = a->nd;
        double f[MD];
        for (int r = 0; r < nd; r++) {
            uh[v][r] = a->u[r] + dt * a->vel[r] + beta * a->acc[r];
            vh[v][r] = a->vel[r] + hdt * a->acc[r];
        }
        for (int r = 0; r < nd; r++) {
            double pr = 0.0;
            for (int q = 0; q < nd; q++)
                pr += a->C[r * nd + q] * vh[v][q] + a->K[r * nd + q] * uh[v][q];
            f[r] = -pr;
        }
        for (int r = 0; r < nd; r++) {
            double acc = 0.0;
            for (int q = 0; q < nd; q++)
                acc += a->Sinv[r * nd + q] * f[q];
            av0[v][r] = acc;
        }
        const amfi_truck *tr = &a->v.truck;
        first[v] = na;
        for (int i = 0; i < tr->n_axles; i++, na++) {
            x[na] = a->v.speed_mps * (t1 - a->v.t_entry_s) - tr->x_m[i];
            W[na] = tr->W_N[i];
            kt[na] = tr->kt_Nm[i];
            veh[na] = v;
            ax[na] = i;
            on[na] = amfi_bridge_mode_values(s->b, x[na], s->phi + (size_t)na * n) == 0;
        }
    }
    /* c_I and the matrix (I + β diag(kt)(A + B)), column-major. */
    for (int ia = 0; ia < na; ia++) {
        const double *pI = s->phi + (size_t)ia * n;
        double w0 = 0.0; /* bridge deflection at x_I without the axle loads' new share */
        if (on[ia])
            for (int k = 0; k < n; k++)
                w0 += pI[k] * (s->qh[k] - beta * s->pred[k] / s->Sk[k]);
        wfree[ia] = w0;
        const int v = veh[ia];
        const active *a = &s->act[v];
        for (int ja = 0; ja < na; ja++) {
            double bij = 0.0;
            if (on[ia] && on[ja]) {
                const double *pJ = s->phi + (size_t)ja * n;
                for (int k = 0; k < n; k++)
                    bij += pI[k] * pJ[k] / s->Sk[k];
            }
            double aij = 0.0;
            if (veh[ja] == v) /* the same vehicle: between its hop DOFs */
                aij = a->Sinv[(a->h0 + ax[ia]) * a->nd + a->h0 + ax[ja]];
            Amat[ia + ja * na] = (ia == ja ? 1.0 : 0.0) + beta * kt[ia] * (aij + bij);
            wfree[ia] += beta * bij * W[ja];
        }
        const int hop = a->h0 + ax[ia];
        double yu = uh[v][hop] + beta * av0[v][hop];
        c[ia] = kt[ia] * (yu - wfree[ia] + road(s, a->v.track, x[ia]));
        fixed[ia] = 0;
    }
    /* Solve; a tyre with W + P < 0 leaves the road (P = −W), then re-solve. */
    for (int pass = 0; pass <= na; pass++) {
        for (int ia = 0; ia < na; ia++) {
            P[ia] = c[ia];
            for (int ja = 0; ja < na; ja++)
                Ms[ia + ja * na] = Amat[ia + ja * na];
        }
        for (int ja = 0; ja < na; ja++) {
            if (!fixed[ja])
                continue;
            for (int ia = 0; ia < na; ia++) { /* move the known P_J = −W_J to the right */
                P[ia] -= Ms[ia + ja * na] * (-W[ja]);
                Ms[ia + ja * na] = 0.0;
            }
            for (int K = 0; K < na; K++)
                Ms[ja + K * na] = 0.0;
            Ms[ja + ja * na] = 1.0;
            P[ja] = -W[ja];
        }
        if (na > 0 && LAPACKE_dgesv_work(LAPACK_COL_MAJOR, na, 1, Ms, na, ipiv, P, na) != 0)
            return fail(err, errlen, "sim: coupled system singular at t = %g s%.0g", t1, 0);
        int changed = 0;
        for (int ia = 0; ia < na; ia++)
            if (!fixed[ia] && W[ia] + P[ia] < 0.0) {
                fixed[ia] = 1;
                changed = 1;
            }
        if (!changed)
            break;
    }
    /* Bridge update. */
    for (int k = 0; k < n; k++) {
        double f = 0.0;
        for (int ia = 0; ia < na; ia++)
            if (on[ia])
                f += s->phi[(size_t)ia * n + k] * (W[ia] + P[ia]);
        double ak = (f - s->pred[k]) / s->Sk[k];
        double vhk = s->qd[k] + hdt * s->qdd[k];
        s->q[k] = s->qh[k] + beta * ak;
        s->qd[k] = vhk + hdt * ak;
        s->qdd[k] = ak;
    }
    /* Vehicle update, truth, hook. */
    for (int v = 0; v < s->n_act; v++) {
        active *a = &s->act[v];
        const int nd = a->nd, h0 = a->h0, na_v = a->v.truck.n_axles;
        const double *Pv = P + first[v];
        for (int r = 0; r < nd; r++) {
            double acc = av0[v][r];
            for (int i = 0; i < na_v; i++)
                acc -= a->Sinv[r * nd + h0 + i] * Pv[i];
            a->u[r] = uh[v][r] + beta * acc;
            a->vel[r] = vh[v][r] + hdt * acc;
            a->acc[r] = acc;
        }
        double F[AMFI_MAX_AXLES];
        for (int i = 0; i < na_v; i++) {
            int ia = first[v] + i;
            F[i] = W[ia] + P[ia];
            if (fixed[ia])
                a->v.lost_contact_steps[i]++;
            if (x[ia] >= 0.0 && x[ia] <= s->L) {
                a->sumF[i] += F[i];
                a->v.on_span_steps[i]++;
                a->v.min_force_N[i] = fmin(a->v.min_force_N[i], F[i]);
                a->v.max_force_N[i] = fmax(a->v.max_force_N[i], F[i]);
            }
        }
        if (s->hook)
            s->hook(s->hook_user, t1, &a->v, x + first[v], F);
    }
    s->step++;
    return 0;
}

int amfi_sim_advance(amfi_sim *s, int n_samples, double *accel, char *err, size_t errlen)
{
    const int n = s->n, ns = s->p.n_sensors;
    for (int j = 0; j < n_samples; j++) {
        for (int i = 0; i < ns; i++) {
            double a = 0.0;
            for (int k = 0; k < n; k++)
                a += s->cs[(size_t)i * n + k] * s->qdd[k];
            accel[(size_t)j * ns + i] = a;
        }
        for (int k = 0; k < s->sub; k++) {
            if (admit(s) != 0)
                return fail(err, errlen, "sim: more than %g vehicles at once at t = %g s",
                            AMFI_SIM_MAX_ACTIVE, amfi_sim_time(s));
            if (step(s, err, errlen) != 0)
                return -1;
            retire(s);
        }
    }
    return 0;
}

int amfi_sim_pop_done(amfi_sim *s, amfi_sim_vehicle *out)
{
    if (s->n_done == 0)
        return 0;
    *out = s->done[0];
    memmove(s->done, s->done + 1, sizeof *s->done * (size_t)(s->n_done - 1));
    s->n_done--;
    return 1;
}

int amfi_sim_vehicle_state(const amfi_sim *s, long id, double *u)
{
    for (int v = 0; v < s->n_act; v++)
        if (s->act[v].v.id == id) {
            memcpy(u, s->act[v].u, sizeof(double) * (size_t)s->act[v].nd);
            return 0;
        }
    return -1;
}

double amfi_sim_deflection(amfi_sim *s, double x_m)
{
    double *phi = s->qh, w = 0.0; /* predictor scratch, free between steps */
    if (amfi_bridge_mode_values(s->b, x_m, phi) != 0)
        return 0.0;
    for (int k = 0; k < s->n; k++)
        w += phi[k] * s->q[k];
    return w;
}

int amfi_sim_set_bridge(amfi_sim *s, const amfi_bridge *b, char *err, size_t errlen)
{
    const int n = s->n;
    if (amfi_bridge_ndof(b) != n ||
        amfi_bridge_params_of(b)->span_m != amfi_bridge_params_of(s->b)->span_m)
        return fail(err, errlen, "sim: the new bridge has %g DOFs or another span (%g)",
                    amfi_bridge_ndof(b), amfi_bridge_params_of(b)->span_m);
    const double *P0 = amfi_bridge_modes(s->b), *P1 = amfi_bridge_modes(b);
    const double *M = amfi_bridge_mass(b);
    double *u = malloc(sizeof(double) * n * 3), *Mu = malloc(sizeof(double) * n * 3);
    if (!u || !Mu) {
        free(u);
        free(Mu);
        return fail(err, errlen, "sim: out of memory%.0g%.0g", 0, 0);
    }
    double *state[3] = {s->q, s->qd, s->qdd};
    for (int c = 0; c < 3; c++) {
        for (int i = 0; i < n; i++) { /* u = Ψ0 q */
            double v = 0.0;
            for (int k = 0; k < n; k++)
                v += P0[(size_t)i * n + k] * state[c][k];
            u[(size_t)c * n + i] = v;
        }
        for (int i = 0; i < n; i++) { /* M u */
            double v = 0.0;
            for (int k = 0; k < n; k++)
                v += M[(size_t)i * n + k] * u[(size_t)c * n + k];
            Mu[(size_t)c * n + i] = v;
        }
        for (int k = 0; k < n; k++) { /* q' = Ψ1ᵀ M u */
            double v = 0.0;
            for (int i = 0; i < n; i++)
                v += P1[(size_t)i * n + k] * Mu[(size_t)c * n + i];
            state[c][k] = v;
        }
    }
    free(u);
    free(Mu);
    s->b = b;
    s->omega = amfi_bridge_omega(b);
    s->zeta = amfi_bridge_zeta(b);
    const double dt = s->p.dt_s, beta = dt * dt / 4.0;
    for (int k = 0; k < n; k++)
        s->Sk[k] = 1.0 + dt * s->zeta[k] * s->omega[k] + beta * s->omega[k] * s->omega[k];
    for (int i = 0; i < s->p.n_sensors; i++)
        amfi_bridge_mode_values(b, s->p.sensor_x_m[i], s->cs + (size_t)i * n);
    return 0;
}
