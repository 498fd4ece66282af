/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bridge.c: Euler-Bernoulli beam finite elements (docs/model.md §1).
 *
 * Equal elements, 2 DOF per node (w down, θ), consistent mass, supports that
 * remove DOFs or add bearing springs (vertical, rotational), segments with
 * their own E·I and mass per length, a uniform damage factor on E·I,
 * Rayleigh damping matched at two modes. The generalized eigenproblem K ψ = ω² M ψ is solved once with LAPACK
 * dsygvd (inverted, M ψ = K ψ/ω², for the wide spectra of fine meshes; see
 * modes()), giving M-orthonormal modes; supports that leave a rigid-body
 * motion are refused before it. Work: O(n³) once per site (0.5 ms at 20
 * elements, 1.4 s of CPU at 1000).
 */
#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

void amfi_hermite(double xi, double le, double N[4])
{
    double x2 = xi * xi, x3 = x2 * xi;
    N[0] = 1.0 - 3.0 * x2 + 2.0 * x3;
    N[1] = le * (xi - 2.0 * x2 + x3);
    N[2] = 3.0 * x2 - 2.0 * x3;
    N[3] = le * (x3 - x2);
}

void amfi_bridge_locate(const amfi_bridge *b, double x, int *elem, double *xi)
{
    int e = (int)floor(x / b->le);
    if (e < 0)
        e = 0;
    if (e >= b->p.n_elements)
        e = b->p.n_elements - 1;
    *elem = e;
    *xi = (x - e * b->le) / b->le;
}

static int check_params(const amfi_bridge_params *p, char *err, size_t errlen)
{
#define REQ(cond, ...)                                                    \
    do {                                                                  \
        if (!(cond))                                                      \
            return amfi_fail(err, errlen, AMFI_EINVAL, __VA_ARGS__);      \
    } while (0)
    REQ(p, "bridge parameters are NULL");
    REQ(isfinite(p->span_m) && p->span_m > 0, "span_m must be > 0 (got %g)", p->span_m);
    REQ(p->n_elements >= 1 && p->n_elements <= 1000, "n_elements must be 1..1000 (got %d)", p->n_elements);
    REQ(isfinite(p->E_pa) && p->E_pa > 0, "E_pa must be > 0");
    REQ(isfinite(p->A_m2) && p->A_m2 > 0, "A_m2 must be > 0");
    REQ(isfinite(p->I_m4) && p->I_m4 > 0, "I_m4 must be > 0");
    REQ(isfinite(p->density_kgm3) && p->density_kgm3 > 0, "density_kgm3 must be > 0");
    REQ(isfinite(p->damping_ratio) && p->damping_ratio >= 0 && p->damping_ratio < 1,
        "damping_ratio must be in [0, 1)");
    REQ(p->rayleigh_mode_a >= 1 && p->rayleigh_mode_b >= 1 &&
            p->rayleigh_mode_a != p->rayleigh_mode_b,
        "Rayleigh modes must be two distinct mode numbers >= 1");
    REQ(p->n_supports >= 1 && p->n_supports <= AMFI_MAX_SUPPORTS, "n_supports must be 1..%d",
        AMFI_MAX_SUPPORTS);
    for (int i = 0; i < p->n_supports; i++) {
        const amfi_support *s = &p->supports[i];
        REQ(isfinite(s->x_m) && s->x_m >= 0 && s->x_m <= p->span_m,
            "support %d: position %g m is off the beam [0, %g]", i, s->x_m, p->span_m);
        REQ(isfinite(s->k_w_npm) && s->k_w_npm >= 0 && isfinite(s->k_theta_nmprad) &&
                s->k_theta_nmprad >= 0,
            "support %d: spring stiffnesses must be finite and >= 0", i);
        REQ(!(s->restrain_w && s->k_w_npm > 0),
            "support %d: a vertical spring on a fixed vertical displacement", i);
        REQ(!(s->restrain_theta && s->k_theta_nmprad > 0),
            "support %d: a rotational spring on a fixed rotation", i);
        REQ(s->restrain_w || s->restrain_theta || s->k_w_npm > 0 || s->k_theta_nmprad > 0,
            "support %d restrains nothing", i);
    }
    REQ(p->n_segments >= 0 && p->n_segments <= AMFI_MAX_SEGMENTS, "n_segments must be 0..%d",
        AMFI_MAX_SEGMENTS);
    for (int i = 0; i < p->n_segments; i++) {
        const amfi_segment *g = &p->segments[i];
        REQ(isfinite(g->x0_m) && isfinite(g->x1_m) && g->x0_m >= 0 && g->x0_m < g->x1_m &&
                g->x1_m <= p->span_m,
            "segment %d: [%g, %g) m is not a part of the beam [0, %g]", i, g->x0_m, g->x1_m,
            p->span_m);
        REQ(isfinite(g->EI_nm2) && g->EI_nm2 >= 0, "segment %d: EI must be > 0 (or 0: the beam's)",
            i);
        REQ(isfinite(g->mass_kgpm) && g->mass_kgpm >= 0,
            "segment %d: mass per length must be > 0 (or 0: the beam's)", i);
        for (int j = 0; j < i; j++)
            REQ(g->x1_m <= p->segments[j].x0_m || g->x0_m >= p->segments[j].x1_m,
                "segment %d overlaps segment %d", i, j);
    }
    REQ(isfinite(p->damage) && p->damage >= 0 && p->damage < 1, "damage must be in [0, 1)");
#undef REQ
    return AMFI_OK;
}

void amfi_bridge_destroy(amfi_bridge *b)
{
    if (!b)
        return;
    free(b->free_of);
    free(b->M);
    free(b->K);
    free(b->C);
    free(b->omega);
    free(b->zeta);
    free(b->Psi);
    free(b->pe);
    free(b);
}

static const amfi_segment *segment_at(const amfi_bridge_params *p, double x)
{
    for (int i = 0; i < p->n_segments; i++)
        if (x >= p->segments[i].x0_m && x < p->segments[i].x1_m)
            return &p->segments[i];
    return NULL;
}

double amfi_bridge_params_EI(const amfi_bridge_params *p, double x)
{
    const amfi_segment *g = segment_at(p, x);
    return g && g->EI_nm2 > 0 ? g->EI_nm2 : p->E_pa * p->I_m4;
}

double amfi_bridge_params_mass(const amfi_bridge_params *p, double x)
{
    const amfi_segment *g = segment_at(p, x);
    return g && g->mass_kgpm > 0 ? g->mass_kgpm : p->density_kgm3 * p->A_m2;
}

/* The node a support snaps to. */
static int support_node(const amfi_bridge *b, const amfi_support *s)
{
    return (int)lround(s->x_m / b->le);
}

/* A rigid-body motion the supports leave free, or NULL. The unsupported
 * beam's stiffness (every element with EI > 0) has exactly the rigid motions
 * w(x) = a + b·x, θ = b as its null space; a restrained w at node i asks
 * a + b·x_i = 0 and a restrained θ asks b = 0. Only w restrained at two
 * distinct nodes, or w at one node and θ anywhere, leave a = b = 0. Exact and
 * independent of the element count, unlike any eigenvalue threshold (the
 * spectrum spans ω²_max/ω²_1 ≈ 1e13 at 1000 elements). */
static const char *rigid_motion(const amfi_bridge *b, char *buf, size_t len)
{
    int w_node = -1, w_nodes = 0, theta = 0;
    for (int node = 0; node <= b->p.n_elements; node++) {
        int w = b->free_of[2 * node] < 0, th = b->free_of[2 * node + 1] < 0;
        /* a spring holds a rigid motion like a restraint (its energy
         * k·w² or k·θ² is positive on any motion that moves it) */
        for (int s = 0; s < b->p.n_supports; s++)
            if (support_node(b, &b->p.supports[s]) == node) {
                w |= b->p.supports[s].k_w_npm > 0;
                th |= b->p.supports[s].k_theta_nmprad > 0;
            }
        if (w && w_nodes++ == 0)
            w_node = node;
        if (th)
            theta = 1;
    }
    if (w_nodes >= 2 || (w_nodes == 1 && theta))
        return NULL;
    if (w_nodes == 0)
        return "the beam can move up and down as a rigid body";
    snprintf(buf, len, "the beam can rotate about node %d at %g m", w_node, w_node * b->le);
    return buf;
}

/* Half-bandwidth of the free-DOF matrices: an element couples its 4 DOFs. */
static int half_band(const amfi_bridge *b)
{
    int kd = 0;
    for (int e = 0; e < b->p.n_elements; e++)
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) {
                int fi = b->free_of[2 * e + i], fj = b->free_of[2 * e + j];
                if (fi >= 0 && fj >= 0 && fj - fi > kd)
                    kd = fj - fi;
            }
    return kd;
}

/* One dense generalised solve (LAPACK dsygvd) of the pencil K ψ = ω² M ψ:
 * direct (M factored), or inverted, M ψ = μ K ψ with μ = 1/ω² (K factored,
 * positive definite once rigid_motion() found no mechanism). Leaves ω
 * ascending in b->omega and Ψ (Ψᵀ M Ψ = I, row-major, column k mode k) in
 * b->Psi, signs not yet fixed. work: n × n doubles. M and K are symmetric,
 * so column-major saves LAPACKE's transposed copies: eigenvector c comes
 * back in work[c·n .. c·n + n − 1]. */
static int solve_pencil(amfi_bridge *b, int inverted, double *work, char *err, size_t errlen)
{
    const int n = b->n;
    double *fac = b->Psi; /* the factored matrix, then Ψ */
    double *om = b->omega;
    memcpy(work, inverted ? b->M : b->K, sizeof(double) * n * n);
    memcpy(fac, inverted ? b->K : b->M, sizeof(double) * n * n);
    lapack_int info = LAPACKE_dsygvd(LAPACK_COL_MAJOR, 1, 'V', 'U', n, work, n, fac, n, om);
    if (info > n && inverted)
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "the stiffness matrix is not positive definite (dsygvd info %d): "
                         "restrain more DOFs",
                         (int)info);
    if (info != 0 || !(om[0] > 0.0))
        return amfi_fail(err, errlen, AMFI_ENUM, "eigenproblem failed (dsygvd info %d)",
                         (int)info);
    if (!inverted) {
        for (int k = 0; k < n; k++)
            om[k] = sqrt(om[k]);
        for (int i = 0; i < n; i++)
            for (int k = 0; k < n; k++)
                fac[(size_t)i * n + k] = work[(size_t)k * n + i];
        return AMFI_OK;
    }
    /* Mode k is column n − 1 − k, ω_k = 1/√μ. zᵀ K z = 1, so zᵀ M z = μ, but
     * only to eps·μ_max absolute: the high modes are M-normalised by their
     * own zᵀ M z (M is banded and well conditioned: O(n·kd) per mode). */
    for (int k = 0; k < n / 2; k++) {
        double t = om[k];
        om[k] = om[n - 1 - k];
        om[n - 1 - k] = t;
    }
    const int kd = half_band(b);
    for (int k = 0; k < n; k++) {
        om[k] = 1.0 / sqrt(om[k]);
        const double *z = work + (size_t)(n - 1 - k) * n;
        double m = 0.0;
        for (int i = 0; i < n; i++) {
            double mz = 0.0;
            for (int j = i - kd < 0 ? 0 : i - kd; j <= i + kd && j < n; j++)
                mz += b->M[(size_t)i * n + j] * z[j];
            m += z[i] * mz;
        }
        fac[k] = 1.0 / sqrt(m); /* row 0 of fac is filled last, below */
    }
    for (int i = n - 1; i >= 0; i--)
        for (int k = 0; k < n; k++)
            fac[(size_t)i * n + k] = work[(size_t)(n - 1 - k) * n + i] * fac[k];
    return AMFI_OK;
}

/* ω (ascending, rad/s) and Ψ with deterministic signs.
 *
 * A backward-stable solve of either form loses about eps·ω²_max/ω²_k on mode
 * k in the direct form and eps·ω²_k/ω²_1 in the inverted one; ω²_max/ω²_1
 * grows as the element count to the fourth (4e6 at 20 elements, 2.6e13 at
 * 1000). The inverted form is solved first: it keeps the low modes, the ones
 * the solver and the indicators use, accurate at any size (f1 of the 1000-
 * element beam within 1e-6 of the analytical value, against 6e-5 direct).
 * When the direct form loses at most 1e-8 even on the lowest mode, as for
 * the shipped 20-element models, it is solved again direct, which is also
 * the most accurate on the high modes the all-modes path uses (microseconds
 * to milliseconds at that size; the results are those of earlier versions).
 * Dense dsygvd measured faster than the banded dsbgvd (2000 DOF: 1.2-1.3 s
 * of CPU against 2.15 s, dominated by dsbtrd's rotations; docs/solver.md).
 * work: n·n + 2n doubles. */
static int modes(amfi_bridge *b, double *work, char *err, size_t errlen)
{
    const int n = b->n;
    int rc = solve_pencil(b, 1, work, err, errlen);
    if (rc)
        return rc;
    const double ratio = b->omega[n - 1] / b->omega[0];
    if (DBL_EPSILON * ratio * ratio <= 1e-8 && (rc = solve_pencil(b, 0, work, err, errlen)) != 0)
        return rc;
    double *Kw = b->Psi;
    /* Deterministic sign: each mode's largest-magnitude component (the
     * first of equals, to 1e-9) is positive. */
    int *imax = (int *)work; /* n ints in n doubles */
    for (int k = 0; k < n; k++)
        imax[k] = 0;
    for (int i = 1; i < n; i++) {
        const double *row = Kw + (size_t)i * n;
        for (int k = 0; k < n; k++)
            if (fabs(row[k]) > fabs(Kw[(size_t)imax[k] * n + k]) * (1 + 1e-9))
                imax[k] = i;
    }
    double *sign = work + n;
    for (int k = 0; k < n; k++)
        sign[k] = Kw[(size_t)imax[k] * n + k] < 0 ? -1.0 : 1.0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < n; k++)
            Kw[(size_t)i * n + k] *= sign[k];
    return AMFI_OK;
}

int amfi_bridge_create(const amfi_bridge_params *p, amfi_bridge **out, char *err,
                       size_t errlen)
{
    int rc = check_params(p, err, errlen);
    if (rc)
        return rc;
    amfi_bridge *b = calloc(1, sizeof *b);
    double *Mw = NULL;
    if (!b)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    b->p = *p;
    const int ne = p->n_elements;
    const int nf = 2 * (ne + 1);
    b->n_full = nf;
    b->le = p->span_m / ne;
    b->free_of = malloc(sizeof(int) * nf);
    if (!b->free_of) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }
    const double l = b->le, l2 = l * l;

    /* Supports snap to the nearest node and remove DOFs. */
    for (int i = 0; i < nf; i++)
        b->free_of[i] = 0;
    for (int s = 0; s < p->n_supports; s++) {
        int node = support_node(b, &p->supports[s]);
        if (p->supports[s].restrain_w)
            b->free_of[2 * node] = -1;
        if (p->supports[s].restrain_theta)
            b->free_of[2 * node + 1] = -1;
    }
    int n = 0;
    for (int i = 0; i < nf; i++)
        if (b->free_of[i] == 0)
            b->free_of[i] = n++;
    b->n = n;
    if (p->rayleigh_mode_a > n || p->rayleigh_mode_b > n) {
        rc = amfi_fail(err, errlen, AMFI_EINVAL, "Rayleigh modes %d, %d exceed the %d modes",
                       p->rayleigh_mode_a, p->rayleigh_mode_b, n);
        goto fail;
    }
    char why[96];
    const char *mech = rigid_motion(b, why, sizeof why);
    if (mech) {
        rc = amfi_fail(err, errlen, AMFI_EINVAL,
                       "the supports leave a mechanism (%s): restrain more DOFs", mech);
        goto fail;
    }

    b->M = calloc((size_t)n * n, sizeof(double));
    b->K = calloc((size_t)n * n, sizeof(double));
    b->C = malloc(sizeof(double) * n * n);
    b->Psi = malloc(sizeof(double) * n * n);
    b->omega = malloc(sizeof(double) * n);
    b->zeta = malloc(sizeof(double) * n);
    Mw = malloc(sizeof(double) * ((size_t)n * n + 2 * (size_t)n)); /* see modes() */
    if (!b->M || !b->K || !b->C || !b->Psi || !b->omega || !b->zeta || !Mw) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }

    /* Element matrices (e.g. Przemieniecki 1968, §5 and §11), assembled
     * straight into the free DOFs (the same sums, element by element). */
    const double ke[4][4] = {{12, 6 * l, -12, 6 * l},
                             {6 * l, 4 * l2, -6 * l, 2 * l2},
                             {-12, -6 * l, 12, -6 * l},
                             {6 * l, 2 * l2, -6 * l, 4 * l2}};
    const double me[4][4] = {{156, 22 * l, 54, -13 * l},
                             {22 * l, 4 * l2, 13 * l, -3 * l2},
                             {54, 13 * l, 156, -22 * l},
                             {-13 * l, -3 * l2, -22 * l, 4 * l2}};
    for (int e = 0; e < ne; e++) {
        /* the element's section: its segment's, or the beam's, at its middle */
        const double xm = (e + 0.5) * l;
        const double EI = (1.0 - p->damage) * amfi_bridge_params_EI(p, xm);
        const double kc = EI / (l2 * l), mc = amfi_bridge_params_mass(p, xm) * l / 420.0;
        for (int i = 0; i < 4; i++) {
            const int fi = b->free_of[2 * e + i];
            if (fi < 0)
                continue;
            for (int j = 0; j < 4; j++) {
                const int fj = b->free_of[2 * e + j];
                if (fj < 0)
                    continue;
                b->K[(size_t)fi * n + fj] += kc * ke[i][j];
                b->M[(size_t)fi * n + fj] += mc * me[i][j];
            }
        }
    }
    /* Bearing springs on the DOFs they act on (free: a spring on a fixed
     * DOF was refused). */
    for (int s = 0; s < p->n_supports; s++) {
        const int node = support_node(b, &p->supports[s]);
        const int dw = b->free_of[2 * node], dt = b->free_of[2 * node + 1];
        if (p->supports[s].k_w_npm > 0 && dw >= 0)
            b->K[(size_t)dw * n + dw] += p->supports[s].k_w_npm;
        if (p->supports[s].k_theta_nmprad > 0 && dt >= 0)
            b->K[(size_t)dt * n + dt] += p->supports[s].k_theta_nmprad;
    }

    if ((rc = modes(b, Mw, err, errlen)) != 0)
        goto fail;

    /* Rayleigh C = a0 M + a1 K with ξ at modes a and b (Clough & Penzien §12-4). */
    double wa = b->omega[p->rayleigh_mode_a - 1], wb = b->omega[p->rayleigh_mode_b - 1];
    b->a0 = 2.0 * p->damping_ratio * wa * wb / (wa + wb);
    b->a1 = 2.0 * p->damping_ratio / (wa + wb);
    for (int i = 0; i < n * n; i++)
        b->C[i] = b->a0 * b->M[i] + b->a1 * b->K[i];
    for (int k = 0; k < n; k++)
        b->zeta[k] = b->a0 / (2.0 * b->omega[k]) + b->a1 * b->omega[k] / 2.0;

    b->pe = calloc((size_t)ne * 4 * n, sizeof(double));
    if (!b->pe) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }
    for (int e = 0; e < ne; e++)
        for (int i = 0; i < 4; i++) {
            int d = b->free_of[2 * e + i];
            if (d >= 0)
                memcpy(b->pe + ((size_t)e * 4 + i) * n, b->Psi + (size_t)d * n, sizeof(double) * n);
        }
    free(Mw);
    *out = b;
    return AMFI_OK;
fail:
    free(Mw);
    amfi_bridge_destroy(b);
    return rc;
}

const amfi_bridge_params *amfi_bridge_params_of(const amfi_bridge *b) { return &b->p; }
int amfi_bridge_ndof(const amfi_bridge *b) { return b->n; }
const double *amfi_bridge_mass(const amfi_bridge *b) { return b->M; }
const double *amfi_bridge_stiffness(const amfi_bridge *b) { return b->K; }
const double *amfi_bridge_damping(const amfi_bridge *b) { return b->C; }
const double *amfi_bridge_omega(const amfi_bridge *b) { return b->omega; }
const double *amfi_bridge_zeta(const amfi_bridge *b) { return b->zeta; }
const double *amfi_bridge_modes(const amfi_bridge *b) { return b->Psi; }

void amfi_bridge_rayleigh(const amfi_bridge *b, double *a0, double *a1)
{
    *a0 = b->a0;
    *a1 = b->a1;
}

int amfi_bridge_dof(const amfi_bridge *b, int node, int rot)
{
    if (node < 0 || node > b->p.n_elements || rot < 0 || rot > 1)
        return -1;
    return b->free_of[2 * node + rot];
}

int amfi_bridge_mode_values(const amfi_bridge *b, double x_m, double *phi)
{
    const int n = b->n;
    if (!(x_m >= 0.0 && x_m <= b->p.span_m)) {
        memset(phi, 0, sizeof(double) * n);
        return 1;
    }
    int e;
    double xi, N[4];
    amfi_bridge_locate(b, x_m, &e, &xi);
    amfi_hermite(xi, b->le, N);
    const double *p0 = b->pe + (size_t)e * 4 * n;
    for (int k = 0; k < n; k++)
        phi[k] = N[0] * p0[k] + N[1] * p0[n + k] + N[2] * p0[2 * n + k] + N[3] * p0[3 * n + k];
    return 0;
}

int amfi_bridge_shape(const amfi_bridge *b, double x_m, double *out)
{
    memset(out, 0, sizeof(double) * b->n);
    if (!(x_m >= 0.0 && x_m <= b->p.span_m))
        return 1;
    int e;
    double xi, N[4];
    amfi_bridge_locate(b, x_m, &e, &xi);
    amfi_hermite(xi, b->le, N);
    for (int i = 0; i < 4; i++) {
        int d = b->free_of[2 * e + i];
        if (d >= 0)
            out[d] = N[i];
    }
    return 0;
}
