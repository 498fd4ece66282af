/*
 * bridge.c: Euler-Bernoulli beam finite elements (docs/model.md §1).
 *
 * Equal elements, 2 DOF per node (w down, θ), consistent mass, supports that
 * remove DOFs, a uniform damage factor on E, Rayleigh damping matched at two
 * modes. The generalized eigenproblem K ψ = ω² M ψ is solved once with LAPACK
 * dsygvd, which returns M-orthonormal eigenvectors. Work: O(n³) once per site.
 */
#include <lapacke.h>
#include <math.h>
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
        REQ(s->restrain_w || s->restrain_theta, "support %d restrains nothing", i);
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

int amfi_bridge_create(const amfi_bridge_params *p, amfi_bridge **out, char *err,
                       size_t errlen)
{
    int rc = check_params(p, err, errlen);
    if (rc)
        return rc;
    amfi_bridge *b = calloc(1, sizeof *b);
    double *Mf = NULL, *Kf = NULL, *Kw = NULL, *Mw = NULL;
    if (!b)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    b->p = *p;
    const int ne = p->n_elements;
    const int nf = 2 * (ne + 1);
    b->n_full = nf;
    b->le = p->span_m / ne;
    b->free_of = malloc(sizeof(int) * nf);
    Mf = calloc((size_t)nf * nf, sizeof(double)); /* nf × nf full assembly */
    Kf = calloc((size_t)nf * nf, sizeof(double));
    if (!b->free_of || !Mf || !Kf) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }

    /* Element matrices (e.g. Przemieniecki 1968, §5 and §11). */
    const double l = b->le, l2 = l * l;
    const double EI = (1.0 - p->damage) * p->E_pa * p->I_m4;
    const double mu = p->density_kgm3 * p->A_m2;
    const double kc = EI / (l2 * l), mc = mu * l / 420.0;
    const double ke[4][4] = {{12, 6 * l, -12, 6 * l},
                             {6 * l, 4 * l2, -6 * l, 2 * l2},
                             {-12, -6 * l, 12, -6 * l},
                             {6 * l, 2 * l2, -6 * l, 4 * l2}};
    const double me[4][4] = {{156, 22 * l, 54, -13 * l},
                             {22 * l, 4 * l2, 13 * l, -3 * l2},
                             {54, 13 * l, 156, -22 * l},
                             {-13 * l, -3 * l2, -22 * l, 4 * l2}};
    for (int e = 0; e < ne; e++)
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) {
                int gi = 2 * e + i, gj = 2 * e + j;
                Kf[gi * nf + gj] += kc * ke[i][j];
                Mf[gi * nf + gj] += mc * me[i][j];
            }

    /* Supports snap to the nearest node and remove DOFs. */
    for (int i = 0; i < nf; i++)
        b->free_of[i] = 0;
    for (int s = 0; s < p->n_supports; s++) {
        int node = (int)lround(p->supports[s].x_m / l);
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
    b->M = malloc(sizeof(double) * n * n);
    b->K = malloc(sizeof(double) * n * n);
    b->C = malloc(sizeof(double) * n * n);
    b->Psi = malloc(sizeof(double) * n * n);
    b->omega = malloc(sizeof(double) * n);
    b->zeta = malloc(sizeof(double) * n);
    Mw = malloc(sizeof(double) * n * n);
    Kw = b->Psi;
    if (!b->M || !b->K || !b->C || !b->Psi || !b->omega || !b->zeta || !Mw) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }
    for (int i = 0; i < nf; i++) {
        if (b->free_of[i] < 0)
            continue;
        for (int j = 0; j < nf; j++) {
            if (b->free_of[j] < 0)
                continue;
            b->M[b->free_of[i] * n + b->free_of[j]] = Mf[i * nf + j];
            b->K[b->free_of[i] * n + b->free_of[j]] = Kf[i * nf + j];
        }
    }
    if (p->rayleigh_mode_a > n || p->rayleigh_mode_b > n) {
        rc = amfi_fail(err, errlen, AMFI_EINVAL, "Rayleigh modes %d, %d exceed the %d modes",
                       p->rayleigh_mode_a, p->rayleigh_mode_b, n);
        goto fail;
    }

    /* K ψ = ω² M ψ; dsygvd returns Ψ with Ψᵀ M Ψ = I. */
    memcpy(Kw, b->K, sizeof(double) * n * n);
    memcpy(Mw, b->M, sizeof(double) * n * n);
    lapack_int info = LAPACKE_dsygvd(LAPACK_ROW_MAJOR, 1, 'V', 'U', n, Kw, n, Mw, n, b->omega);
    if (info != 0) {
        rc = amfi_fail(err, errlen, AMFI_ENUM, "eigenproblem failed (dsygvd info %d)", (int)info);
        goto fail;
    }
    if (!(b->omega[0] > 1e-12 * b->omega[n - 1])) {
        rc = amfi_fail(err, errlen, AMFI_EINVAL,
                       "the supports leave a mechanism (lowest eigenvalue %g): restrain more DOFs",
                       b->omega[0]);
        goto fail;
    }
    for (int k = 0; k < n; k++) {
        b->omega[k] = sqrt(b->omega[k]);
        /* Deterministic sign: the largest-magnitude component is positive. */
        int imax = 0;
        for (int i = 1; i < n; i++)
            if (fabs(b->Psi[i * n + k]) > fabs(b->Psi[imax * n + k]) * (1 + 1e-9))
                imax = i;
        if (b->Psi[imax * n + k] < 0)
            for (int i = 0; i < n; i++)
                b->Psi[i * n + k] = -b->Psi[i * n + k];
    }

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
    free(Mf);
    free(Kf);
    free(Mw);
    *out = b;
    return AMFI_OK;
fail:
    free(Mf);
    free(Kf);
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
