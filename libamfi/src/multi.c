/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * multi.c: several vehicles on the span solved together (issue 13). Every
 * vehicle's axles move at its own speed from its own entry time; all axles go
 * into one sweep (solver.c's amfi_solve_window/_lambda/_end), coincident
 * axles (amfi.h, AMFI_MULTI_COINCIDENT_M: found from the geometry before
 * any sweep) as one unknown, then each vehicle's GVW comes
 * from its own axles' mean forces, with a quality figure from a second sweep
 * at a tenth of λ (how far the weight moves when the regularisation that
 * decides the load split between close axles is loosened) and a
 * separability figure from the normal matrix of a constant-axle-load model
 * (see amfi_vehicle_result in amfi.h). An event of several vehicles at a
 * fixed λ is weighed by the λ/10 sweep (round six), or at λ·lambda_factor
 * when the caller sets one (round five).
 * Pure computation; runs on the caller's thread and uses the solver handle's
 * workspace, the quality figures' part included (mq_reserve): grown here,
 * before any time loop, at the first event of a given size; an event no
 * larger than one before allocates nothing.
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

/* The quality figures' scratch for events of up to na axles (0, or
 * AMFI_ENOMEM), in doubles: normal_matrix's Φ (4m), G (2m), c (ns·m),
 * q (2m·na), mode values (n), y (ns·na); then A (na²), U (na² + na) and
 * quad_inverse's M (na²) and u (na); m the modes of the sweep (all n in
 * nodal coordinates). Reallocated only when na exceeds every event's
 * before. */
static size_t mq_head(const struct amfi_solver *s, int na)
{
    const size_t m = (size_t)(s->mode ? s->m : s->n), ns = (size_t)s->ns, k = (size_t)na;
    return 6 * m + ns * m + 2 * m * k + (size_t)s->n + ns * k; /* normal_matrix's part */
}

static int mq_reserve(struct amfi_solver *s, int na)
{
    if (na <= s->mq_na)
        return AMFI_OK;
    const size_t k = (size_t)na;
    const size_t len = mq_head(s, na) + 3 * k * k + 2 * k;
    double *p = malloc(sizeof(double) * len);
    if (!p)
        return AMFI_ENOMEM;
    free(s->mq);
    s->bytes += sizeof(double) * (len - s->mq_len);
    s->mq = p;
    s->mq_len = len;
    s->mq_na = na;
    return AMFI_OK;
}

/* Normal matrix A (na × na) of the constant-axle-load model: column a is the
 * sensors' response, in the solver's output equation (paper: backward
 * difference of modal velocities), to a unit load moving with axle a while it
 * is on the span. Modes: the solver's (modal) or all (nodal). Scratch: the
 * head of s->mq (mq_reserve for at least na axles), A not in it. */
static void normal_matrix(const struct amfi_solver *s, double *A)
{
    const amfi_bridge *b = s->b;
    const int n = s->n, na = s->na, ns = s->ns, N = s->N;
    const int m = s->mode ? s->m : n;
    const double L = b->p.span_m, h = s->h;
    double *Phi = s->mq;
    double *G = Phi + 4 * (size_t)m;
    double *c = G + 2 * (size_t)m;
    double *q = c + (size_t)ns * m;
    double *all = q + (size_t)2 * m * na;
    double *y = all + n;
    memset(q, 0, sizeof(double) * 2 * (size_t)m * na);
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
}

/* Coincident axles. Axle a moves as x = vf[a]·t − off[a] and is on the span
 * over [off/vf, (off + L)/vf]; the largest distance between two axles while
 * either is on the span (their difference is linear in t: at the ends of
 * the hull of the two intervals). */
static double axle_gap_max(double L, double vfa, double offa, double vfb, double offb)
{
    const double t0 = fmin(offa / vfa, offb / vfb);
    const double t1 = fmax((offa + L) / vfa, (offb + L) / vfb);
    const double d0 = fabs((vfa - vfb) * t0 - (offa - offb));
    const double d1 = fabs((vfa - vfb) * t1 - (offa - offb));
    return fmax(d0, d1);
}

static int uf_root(int *parent, int a)
{
    while (parent[a] != a)
        a = parent[a] = parent[parent[a]];
    return a;
}

/* Join the sets of a and b, the smaller index the root (so a set's root is
 * its first member). */
static void uf_join(int *parent, int a, int b)
{
    a = uf_root(parent, a);
    b = uf_root(parent, b);
    if (a < b)
        parent[b] = a;
    else if (b < a)
        parent[a] = b;
}

/* The event's unknowns: axles (vf, off: na of them, vehicle by vehicle;
 * veh[a] the vehicle of axle a) within AMFI_MULTI_COINCIDENT_M of each
 * other, or of one calculation step's travel when that is longer, all
 * along their crossing are one unknown (transitively). unk[a]: the unknown
 * of axle a, numbered in order of first axle; cnt[u]: its axles; vf_u,
 * off_u: its trajectory, the mean of its axles'. vgroup[v]: the first
 * vehicle whose axles share an unknown with v's (transitively; v itself
 * when none do). Returns the number of unknowns. */
static int coincident_axles(double L, double h, int na, const double *vf, const double *off,
                            const int *veh, int nv, int *unk, int *cnt, double *vf_u,
                            double *off_u, int *vgroup)
{
    int parent[AMFI_MAX_EVENT_AXLES];
    for (int a = 0; a < na; a++)
        parent[a] = a;
    for (int a = 0; a < na; a++)
        for (int b = a + 1; b < na; b++) {
            const double tol = fmax(AMFI_MULTI_COINCIDENT_M, fmax(vf[a], vf[b]) * h);
            if (axle_gap_max(L, vf[a], off[a], vf[b], off[b]) <= tol)
                uf_join(parent, a, b);
        }
    int nu = 0, first[AMFI_MAX_EVENT_AXLES];
    for (int a = 0; a < na; a++) {
        const int r = uf_root(parent, a);
        if (r == a) { /* the first axle of its set */
            first[nu] = a;
            unk[a] = nu++;
        } else {
            unk[a] = unk[r];
        }
    }
    for (int u = 0; u < nu; u++) {
        cnt[u] = 0;
        vf_u[u] = 0.0;
        off_u[u] = 0.0;
    }
    for (int a = 0; a < na; a++) {
        cnt[unk[a]]++;
        vf_u[unk[a]] += vf[a];
        off_u[unk[a]] += off[a];
    }
    for (int u = 0; u < nu; u++) {
        vf_u[u] /= cnt[u];
        off_u[u] /= cnt[u];
    }
    int vp[AMFI_MAX_VEHICLES];
    for (int v = 0; v < nv; v++)
        vp[v] = v;
    for (int a = 0; a < na; a++)
        uf_join(vp, veh[a], veh[first[unk[a]]]);
    for (int v = 0; v < nv; v++)
        vgroup[v] = uf_root(vp, v);
    return nu;
}

/* Each vehicle's GVW, kg, from the sweep's forces in s->force (one column
 * per unknown): the sum of its axles' mean forces while on the span (as
 * amfi_solve_end), an unknown of several axles shared evenly among them. */
static void vehicle_gvw(const struct amfi_solver *s, const amfi_multi_passage *p,
                        const int *unk, const int *cnt, double *gvw)
{
    int i = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        gvw[v] = 0.0;
        for (int a = 0; a < p->vehicle[v].n_axles; a++, i++)
            gvw[v] += amfi_axle_mean_force(s, unk[i]) / cnt[unk[i]] / AMFI_GRAVITY;
    }
}

/* uᵀ M⁻¹ u for the SPD block M of A (na × na) on the k rows/cols idx[0..k),
 * u = ones; M: k² doubles of scratch, u: k. */
static int quad_inverse(const double *A, int na, const int *idx, int k, double *out, double *M,
                        double *u)
{
    for (int i = 0; i < k; i++) {
        u[i] = 1.0;
        for (int j = 0; j < k; j++)
            M[i * k + j] = A[idx[i] * na + idx[j]];
    }
    int rc = amfi_spd_solve(k, M, u);
    double v = 0.0;
    for (int i = 0; i < k; i++)
        v += u[i];
    *out = v;
    return rc ? AMFI_ENUM : AMFI_OK;
}

/* Spread the forces of the nu unknowns in s->force ((N + 1) × nu) over the
 * na axles ((N + 1) × na, in place: the workspace holds na_max >= na
 * columns), an unknown's force shared evenly among its axles. */
static void spread_forces(struct amfi_solver *s, int nu, int na, const int *unk, const int *cnt)
{
    double row[AMFI_MAX_EVENT_AXLES];
    for (int j = s->N; j >= 0; j--) { /* row j moves right: later rows first */
        memcpy(row, s->force + (size_t)j * nu, sizeof(double) * nu);
        for (int a = 0; a < na; a++)
            s->force[(size_t)j * na + a] = row[unk[a]] / cnt[unk[a]];
    }
}

/* The event's samples as a passage (its vehicle fields unset): what the
 * checks and the solve read of the data. */
static amfi_passage samples_of(const amfi_multi_passage *p)
{
    amfi_passage samples;
    memset(&samples, 0, sizeof samples);
    samples.n_samples = p->n_samples;
    samples.scan_rate_hz = p->scan_rate_hz;
    samples.t_first_s = p->t_first_s;
    memcpy(samples.accel, p->accel, sizeof samples.accel);
    return samples;
}

/* The joint solve of the vehicles of p (validated by amfi_solve_multi,
 * at most AMFI_MAX_EVENT_AXLES axles) over the window [t_start, t_end] on
 * the samples' clock, inside the samples. Every axle must be on the span
 * at some step of the window (the segments drop those that are not). */
static int solve_joint(struct amfi_solver *s, const amfi_multi_passage *p, double t_start,
                       double t_end, const amfi_lambda *lam, amfi_multi_result *res, char *err,
                       size_t errlen)
{
#define REQ(cond, st, ...)                                                \
    do {                                                                  \
        if (!(cond))                                                      \
            return amfi_fail(err, errlen, st, __VA_ARGS__);               \
    } while (0)
    int na = 0, rc;
    for (int v = 0; v < p->n_vehicles; v++)
        na += p->vehicle[v].n_axles;
    const amfi_passage samples = samples_of(p);
    const double L = s->b->p.span_m;
    if (amfi_solver_grow_axles(s, na) != 0 || mq_reserve(s, na) != 0)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory for %d axles", na);
    /* axle i of vehicle v at x = v·(t − entry) − offset_i = v·t − (v·entry + offset_i):
     * speed 1, the vehicle's speed as the axle's factor (solver_internal.h) */
    double vf[AMFI_MAX_EVENT_AXLES], off[AMFI_MAX_EVENT_AXLES];
    int veh[AMFI_MAX_EVENT_AXLES];
    int i = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        const amfi_vehicle *ve = &p->vehicle[v];
        double o = 0.0;
        for (int a = 0; a < ve->n_axles; a++, i++) {
            if (a > 0)
                o += ve->axle_spacing_m[a - 1];
            vf[i] = ve->speed_mps;
            off[i] = ve->speed_mps * ve->entry_s + o;
            veh[i] = v;
        }
    }
    /* Coincident axles are one unknown, decided from the geometry before
     * any sweep: the data fix only their sum (a constant difference of
     * their forces changes neither the fit nor the smoothing term), so
     * kept apart they leave the sweep's start singular, and whether its
     * factorisation noticed depended on the BLAS's summation order. */
    int unk[AMFI_MAX_EVENT_AXLES], cnt[AMFI_MAX_EVENT_AXLES], vgroup[AMFI_MAX_VEHICLES];
    double vf_u[AMFI_MAX_EVENT_AXLES], off_u[AMFI_MAX_EVENT_AXLES];
    const int nu = coincident_axles(L, s->h, na, vf, off, veh, p->n_vehicles, unk, cnt, vf_u,
                                    off_u, vgroup);
    s->speed = 1.0;
    for (int u = 0; u < nu; u++) {
        s->vf[u] = vf_u[u];
        s->off[u] = off_u[u];
    }
    memset(res, 0, sizeof *res);
    double lam_h;
    int n_solves = 0;
    if ((rc = amfi_solve_window(s, &samples, nu, t_start, t_end, err, errlen)) != 0 ||
        (rc = amfi_solve_lambda(s, lam, &lam_h, &n_solves, err, errlen)) != 0)
        return rc;
    /* An event of several vehicles at a fixed λ, lambda_factor 0 (the
     * default): swept at λ and at λ·AMFI_MULTI_QUALITY_LAMBDA, the weights
     * are the second sweep's, the quality figure the change between the
     * two. The fixed λ (one vehicle's) over-smooths a joint solve: on
     * simulated truck pairs the pair sums erred 1.2-1.5 % mean abs, up to
     * −6.8 %, at λ and 0.55 %, 1.5 % at λ/10, where the same vehicles
     * solved alone do not move with λ (docs/results/multi-vehicle.md,
     * round six). With lambda_factor f: the weights at λ·f, the quality
     * against λ·f·AMFI_MULTI_QUALITY_LAMBDA (f = 1: the weights at λ, as
     * before round six); with the L-curve (lam->automatic) and no f, the
     * weights at the L-curve's λ. A vehicle alone is solved at λ: it has
     * nothing to trade load with and needs no second sweep; so, by
     * default, is an event whose vehicles all share coincident axles (one
     * group, side by side: one load, weighed as one vehicle). */
    const int several = p->n_vehicles > 1;
    int n_groups = 0; /* vehicles weighed apart (coincident axles: one group) */
    for (int v = 0; v < p->n_vehicles; v++)
        n_groups += vgroup[v] == v;
    const int loosen = n_groups > 1 && p->lambda_factor == 0.0 && !lam->automatic;
    if (several && p->lambda_factor > 0.0)
        lam_h *= p->lambda_factor;
    /* the quality's other sweep first (solve_end's sweep then leaves the
     * answer in the workspace) */
    double other[AMFI_MAX_VEHICLES];
    const double lam_other = loosen ? lam_h : lam_h * AMFI_MULTI_QUALITY_LAMBDA;
    if (loosen)
        lam_h *= AMFI_MULTI_QUALITY_LAMBDA;
    if (several) {
        double rn, sn;
        rc = amfi_sweep(s, lam_other, &rn, &sn);
        if (rc != 0)
            return amfi_fail(err, errlen, rc, "quality sweep failed: %s", amfi_strerror(rc));
        n_solves++;
        vehicle_gvw(s, p, unk, cnt, other);
    }
    if ((rc = amfi_solve_end(s, lam, lam_h, n_solves, &res->all, err, errlen)) != 0)
        return rc;
    REQ(isfinite(res->all.gvw_kg), AMFI_ENUM, "the joint solution is not finite");

    /* separability on the unknowns (s->na = nu still): A, U, and
     * quad_inverse's M and u after normal_matrix's scratch in s->mq */
    double *A = s->mq + mq_head(s, s->mq_na);
    double *U = A + (size_t)nu * nu;
    double *Mq = U + (size_t)nu * nu + nu;
    double *uq = Mq + (size_t)nu * nu;
    normal_matrix(s, A);
    /* a relative ridge of 1e-12 keeps A invertible for axles close to each
     * other but outside the coincidence tolerance */
    double tr = 0.0;
    for (int u = 0; u < nu; u++)
        tr += A[u * nu + u];
    for (int u = 0; u < nu; u++)
        A[u * nu + u] += 1e-12 * tr / nu;

    /* the joint result on the axles: an unknown's force and mean shared
     * evenly among its axles (their sum is what the data fix) */
    double mf[AMFI_MAX_EVENT_AXLES];
    memcpy(mf, res->all.mean_force_N, sizeof(double) * nu);
    spread_forces(s, nu, na, unk, cnt);
    s->na = na;
    for (int a = 0; a < na; a++) {
        s->vf[a] = vf[a];
        s->off[a] = off[a];
    }
    res->all.n_axles = na;
    res->all.force_N = s->force;
    res->all.gvw_kg = 0.0;
    for (int a = 0; a < na; a++) {
        res->all.mean_force_N[a] = mf[unk[a]] / cnt[unk[a]];
        res->all.axle_kg[a] = res->all.mean_force_N[a] / AMFI_GRAVITY;
        res->all.gvw_kg += res->all.axle_kg[a];
        res->axle_unknown[a] = unk[a];
    }
    res->n_unknowns = nu;
    res->n_vehicles = p->n_vehicles;
    res->n_segments = 1;
    res->total_gvw_kg = 0.0;
    i = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        amfi_vehicle_result *vr = &res->vehicle[v];
        vr->first_axle = i;
        vr->n_axles = p->vehicle[v].n_axles;
        vr->segment = 0;
        vr->group = vgroup[v];
        vr->n_merged = 0;
        vr->gvw_kg = 0.0;
        for (int a = 0; a < vr->n_axles; a++) {
            vr->axle_kg[a] = res->all.axle_kg[i + a];
            vr->gvw_kg += vr->axle_kg[a];
            for (int b = 0; b < na; b++)
                if (unk[b] == unk[i + a] && veh[b] != v) {
                    vr->n_merged++;
                    break;
                }
        }
        res->total_gvw_kg += vr->gvw_kg;
        i += vr->n_axles;
    }
    for (int v = 0; v < p->n_vehicles; v++) {
        amfi_vehicle_result *vr = &res->vehicle[v];
        int grouped = 0; /* other vehicles in its group */
        vr->group_gvw_kg = 0.0;
        for (int w = 0; w < p->n_vehicles; w++)
            if (vgroup[w] == vgroup[v]) {
                vr->group_gvw_kg += res->vehicle[w].gvw_kg;
                grouped += w != v;
            }
        /* joint: uᵀA⁻¹u with u the indicator of the unknowns of its group's
         * axles (the vehicle's own when it has no group) */
        int idx[AMFI_MAX_EVENT_AXLES], k = 0;
        memcpy(U, A, sizeof(double) * nu * nu);
        double *u = U + nu * nu;
        for (int q = 0; q < nu; q++) {
            int in = 0;
            for (int a = 0; a < na; a++)
                if (unk[a] == q && vgroup[veh[a]] == vgroup[v])
                    in = 1;
            u[q] = in;
            if (in)
                idx[k++] = q;
        }
        double joint = NAN, alone = NAN;
        rc = amfi_spd_solve(nu, U, u) ? AMFI_ENUM : AMFI_OK;
        if (!rc) {
            joint = 0.0;
            for (int q = 0; q < k; q++)
                joint += u[idx[q]];
            rc = quad_inverse(A, nu, idx, k, &alone, Mq, uq);
        }
        if (rc) {
            return amfi_fail(err, errlen, rc, "quality of vehicle %d: %s", v + 1,
                             amfi_strerror(rc));
        }
        vr->separability = sqrt(joint / alone);
        vr->gvw_sd_kg = res->all.residual_rms * sqrt(joint) / AMFI_GRAVITY;
        vr->quality = 1.0;
        if (grouped) {
            vr->quality = AMFI_MULTI_QUALITY_UNFIXED;
        } else if (p->n_vehicles > 1) {
            /* the change between λ and λ/10, relative to the tighter
             * solve's weight (the returned one's before round six) */
            const double tight = loosen ? other[v] : vr->gvw_kg;
            vr->quality = 1.0 + 100.0 * fabs(other[v] - vr->gvw_kg) / fabs(tight);
            if (!isfinite(vr->quality)) {
                return amfi_fail(err, errlen, AMFI_ENUM, "quality of vehicle %d is not finite",
                                 v + 1);
            }
        }
    }
#undef REQ
    return AMFI_OK;
}

/* The gain array of a sweep of N steps and na axles kept whole. */
static size_t full_gain_doubles(const struct amfi_solver *s, int N, int na)
{
    const size_t state = (size_t)(s->p.coords == AMFI_COORDS_MODAL ? 2 * s->m : 4 * s->n) + na;
    return (size_t)N * na * state;
}

/* Axle k of vehicle ve (offset o_k behind its first) is on the span over
 * [entry + o_k/v, entry + (o_k + L)/v]. */
static double axle_in(const amfi_vehicle *ve, double o)
{
    return ve->entry_s + o / ve->speed_mps;
}

/* The axles of vehicle ve on the span for more than two calculation steps
 * inside [t0, t1]: a contiguous run a0 .. a0 + *n − 1 (0 when none);
 * their offsets o[] (o[0] = 0). */
static int axles_inside(const amfi_vehicle *ve, double L, double h, double t0, double t1,
                        int *n)
{
    double o = 0.0;
    int a0 = -1;
    *n = 0;
    for (int a = 0; a < ve->n_axles; a++) {
        if (a > 0)
            o += ve->axle_spacing_m[a - 1];
        const double in = axle_in(ve, o), out = axle_in(ve, o + L);
        if (fmin(out, t1) - fmax(in, t0) > 2.0 * h) {
            if (a0 < 0)
                a0 = a;
            ++*n;
        }
    }
    return a0 < 0 ? 0 : a0;
}

/* The sub-event of the segment [t0, t1]: every vehicle's axles on the span
 * inside it (a vehicle cut at the window's edge as one whose first axle is
 * the first inside, entering then). map[q]: the event's vehicle of q's
 * vehicle q. Returns the axles. */
static int segment_event(const amfi_multi_passage *p, double L, double h, double t0, double t1,
                         amfi_multi_passage *q, int *map)
{
    *q = *p;
    q->n_vehicles = 0;
    int na = 0;
    for (int v = 0; v < p->n_vehicles; v++) {
        const amfi_vehicle *ve = &p->vehicle[v];
        int n;
        const int a0 = axles_inside(ve, L, h, t0, t1, &n);
        if (n == 0)
            continue;
        amfi_vehicle *w = &q->vehicle[q->n_vehicles];
        double o = 0.0;
        for (int a = 0; a < a0; a++)
            o += ve->axle_spacing_m[a];
        w->entry_s = axle_in(ve, o);
        w->speed_mps = ve->speed_mps;
        w->n_axles = n;
        for (int a = 0; a + 1 < n; a++)
            w->axle_spacing_m[a] = ve->axle_spacing_m[a0 + a];
        map[q->n_vehicles++] = v;
        na += n;
    }
    return na;
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
    REQ(na <= AMFI_MAX_EVENT_AXLES, AMFI_EINVAL, "%d axles in all: at most %d in one event", na,
        AMFI_MAX_EVENT_AXLES);
    const amfi_passage samples = samples_of(p);
    int rc = amfi_check_samples_lambda(s, &samples, lam, err, errlen);
    if (rc)
        return rc;
    const double L = s->b->p.span_m, h = s->h;
    const double pre = s->p.pre_roll_s, post = s->p.post_roll_s;
    const amfi_passage_times win = amfi_multi_window(L, p, pre, post);
    const double t_last = p->t_first_s + (p->n_samples - 1) / p->scan_rate_hz;
    const double tol = 1e-9 + 1e-6 / p->scan_rate_hz;
    REQ(p->t_first_s <= win.start_s + tol && t_last >= win.end_s - tol, AMFI_ERANGE,
        "the data spans [%.6g, %.6g] s but the event needs [%.6g, %.6g] s", p->t_first_s,
        t_last, win.start_s, win.end_s);
    const size_t budget = p->max_segment_bytes ? p->max_segment_bytes : AMFI_MULTI_SEGMENT_BYTES;
    s->sweep_budget = budget / sizeof(double);
#define SWEEP_BYTES(t0, t1, n)                                                               \
    (sizeof(double) *                                                                         \
     full_gain_doubles(s, (int)ceil(((t1) - (t0)) * s->p.calc_rate_hz - 1e-6), (n)))
    const size_t whole = SWEEP_BYTES(win.start_s, win.end_s, na);
    /* a segment starts with the bridge vibrating under its neighbours: it
     * needs the free initial state (else the whole event in one sweep) */
    if (p->n_vehicles == 1 || whole <= budget || !s->p.free_initial_state) {
        rc = solve_joint(s, p, win.start_s, win.end_s, lam, res, err, errlen);
        res->max_segment_bytes = whole;
        return rc;
    }
    /* Segments: the vehicles by entry in clusters (a cluster ends where
     * the span is empty: every vehicle before has left it before the next
     * enters); each segment owns the next clusters while its window with
     * the axles on the span inside it stays within the budget (at least
     * one cluster: one whose vehicles follow each other on the span
     * without a break is never cut) and weighs them with those axles as
     * unknowns: a neighbour of another segment is then on the span inside
     * a pre- or post-roll only, its axles there unknowns with a free force
     * at the window's start. Cutting where a vehicle is on the span lost
     * the earlier data's hold on its force: a pair of trucks following
     * each other closely, cut at the follower's window, weighed the
     * follower 10 % light. */
    if (!s->seg) {
        s->seg = malloc(sizeof *s->seg);
        if (!s->seg)
            return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory for the segments");
        s->bytes += sizeof *s->seg;
    }
    amfi_multi_result *sr = s->seg;
    int order[AMFI_MAX_VEHICLES], first_axle[AMFI_MAX_VEHICLES];
    double t_in[AMFI_MAX_VEHICLES], t_out[AMFI_MAX_VEHICLES];
    for (int v = 0, i = 0; v < p->n_vehicles; v++) {
        const amfi_vehicle *ve = &p->vehicle[v];
        const amfi_passage_times one =
            amfi_passage_window(L, ve->speed_mps, ve->n_axles, ve->axle_spacing_m, 0.0, 0.0);
        t_in[v] = ve->entry_s - pre;
        t_out[v] = ve->entry_s + one.on_span_s + post;
        first_axle[v] = i;
        i += ve->n_axles;
        int k = v; /* insertion by entry, stable */
        while (k > 0 && p->vehicle[order[k - 1]].entry_s > ve->entry_s) {
            order[k] = order[k - 1];
            k--;
        }
        order[k] = v;
    }
    memset(res, 0, sizeof *res);
    res->n_vehicles = p->n_vehicles;
    amfi_multi_passage q;
    int map[AMFI_MAX_VEHICLES], nseg = 0;
    for (int k = 0; k < p->n_vehicles; nseg++) {
        /* owners order[k .. e): whole clusters */
        double t0 = t_in[order[k]], t1 = -INFINITY;
        int e = k;
        size_t bytes = 0;
        while (e < p->n_vehicles) {
            int c = e; /* the cluster order[e .. c) and its windows' end */
            double exit_max = -INFINITY, t1e = t1;
            do {
                exit_max = fmax(exit_max, t_out[order[c]] - post);
                t1e = fmax(t1e, t_out[order[c]]);
                c++;
            } while (c < p->n_vehicles && p->vehicle[order[c]].entry_s < exit_max);
            const size_t b = SWEEP_BYTES(t0, t1e, segment_event(p, L, h, t0, t1e, &q, map));
            if (e > k && b > budget)
                break;
            t1 = t1e;
            bytes = b;
            e = c;
        }
        segment_event(p, L, h, t0, t1, &q, map);
        if (bytes > res->max_segment_bytes)
            res->max_segment_bytes = bytes;
        if ((rc = solve_joint(s, &q, t0, t1, lam, sr, err, errlen)) != 0)
            return rc;
        for (int qi = 0; qi < q.n_vehicles; qi++) {
            const int v = map[qi];
            int owned = 0;
            for (int o = k; o < e; o++)
                owned |= order[o] == v;
            if (!owned)
                continue;
            amfi_vehicle_result *vr = &res->vehicle[v];
            *vr = sr->vehicle[qi];
            vr->group = map[sr->vehicle[qi].group];
            vr->segment = nseg;
            vr->first_axle = first_axle[v];
            for (int a = 0; a < vr->n_axles; a++)
                res->axle_unknown[first_axle[v] + a] =
                    sr->axle_unknown[sr->vehicle[qi].first_axle + a];
        }
        k = e;
    }
    res->all = sr->all;
    res->n_unknowns = sr->n_unknowns;
    res->n_segments = nseg;
    res->total_gvw_kg = 0.0;
    for (int v = 0; v < p->n_vehicles; v++)
        res->total_gvw_kg += res->vehicle[v].gvw_kg;
#undef SWEEP_BYTES
#undef REQ
    return AMFI_OK;
}
