/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * discretise.c: zero-order-hold discretisation of the bridge (docs/model.md §3),
 * in modal coordinates (closed form per mode) and in nodal coordinates
 * (Padé matrix exponential).
 */
#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

/*
 * For A = [[0, 1], [−ω², −2ζω]], expm(A t) = e^{μt}[c(t) I + s(t)(A − μI)],
 * μ = −ζω. Underdamped: c = cos ω_d t, s = sin(ω_d t)/ω_d, ω_d = ω√(1−ζ²).
 * Overdamped (the high Rayleigh modes, ζ up to ~20): with the eigenvalues
 * λ₁ = ω²/λ₂ (slow, written so as not to cancel) and λ₂ = μ − β, β = ω√(ζ²−1),
 * e^{μt}c = e^{λ₁t}(1 + e^{−2βt})/2 and e^{μt}s = −e^{λ₁t}·expm1(−2βt)/(2β),
 * which neither overflow nor cancel; β = 0 is the critical limit s = t.
 * G = A⁻¹(Φ − I)[0; 1].
 */
void amfi_modal_block(double omega, double zeta, double h, double Phi[4], double G[2])
{
    double Ec, Es; /* e^{μh}·c(h), e^{μh}·s(h) */
    if (zeta < 1.0) {
        double wd = omega * sqrt(1.0 - zeta * zeta);
        double e = exp(-zeta * omega * h);
        Ec = e * cos(wd * h);
        Es = e * sin(wd * h) / wd;
    } else {
        double beta = omega * sqrt(zeta * zeta - 1.0);
        double l2 = -zeta * omega - beta;
        double l1 = omega * omega / l2;
        double e1 = exp(l1 * h);
        Ec = e1 * (1.0 + exp(-2.0 * beta * h)) / 2.0;
        Es = beta > 0 ? -e1 * expm1(-2.0 * beta * h) / (2.0 * beta) : h * e1;
    }
    double zw = zeta * omega, w2 = omega * omega;
    Phi[0] = Ec + Es * zw;
    Phi[1] = Es;
    Phi[2] = -w2 * Es;
    Phi[3] = Ec - Es * zw;
    /* A⁻¹ = [[−2ζω, −1], [ω², 0]]/ω²; (Φ − I)[0;1] = [Φ01; Φ11 − 1] */
    G[0] = (1.0 - Ec - zw * Es) / w2;
    G[1] = Es;
}

/*
 * Van Loan (1978): expm([[A, B], [0, 0]]·h) = [[Φ, Γ], [0, I]] with
 * Γ = ∫0^h e^{As} ds B. Here B = [0; M⁻¹] (2n × n), so the augmented matrix
 * is 3n × 3n and Γ = G exactly, with no inverse of A.
 */
int amfi_nodal_discretise(const amfi_bridge *b, double h, double *Phi, double *G)
{
    const int n = b->n, n2 = 2 * n, n3 = 3 * n;
    double *Minv = calloc((size_t)n * n, sizeof(double));
    double *MK = malloc(sizeof(double) * n * n);
    double *MC = malloc(sizeof(double) * n * n);
    double *Mw = malloc(sizeof(double) * n * n);
    double *Aug = calloc((size_t)n3 * n3, sizeof(double));
    double *E = malloc(sizeof(double) * n3 * n3);
    int rc = AMFI_ENOMEM;
    if (!Minv || !MK || !MC || !Mw || !Aug || !E)
        goto out;
    rc = AMFI_ENUM;
    /* M⁻¹, M⁻¹K, M⁻¹C by Cholesky solves. */
    for (int i = 0; i < n; i++)
        Minv[i * n + i] = 1.0;
    memcpy(MK, b->K, sizeof(double) * n * n);
    memcpy(MC, b->C, sizeof(double) * n * n);
    memcpy(Mw, b->M, sizeof(double) * n * n);
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'U', n, Mw, n) != 0)
        goto out;
    if (LAPACKE_dpotrs(LAPACK_ROW_MAJOR, 'U', n, n, Mw, n, Minv, n) != 0 ||
        LAPACKE_dpotrs(LAPACK_ROW_MAJOR, 'U', n, n, Mw, n, MK, n) != 0 ||
        LAPACKE_dpotrs(LAPACK_ROW_MAJOR, 'U', n, n, Mw, n, MC, n) != 0)
        goto out;
    for (int i = 0; i < n; i++) {
        Aug[i * n3 + n + i] = h; /* du/dt = u' */
        for (int j = 0; j < n; j++) {
            Aug[(n + i) * n3 + j] = -h * MK[i * n + j];
            Aug[(n + i) * n3 + n + j] = -h * MC[i * n + j];
            Aug[(n + i) * n3 + n2 + j] = h * Minv[i * n + j];
        }
    }
    if (amfi_expm(n3, Aug, E) != 0)
        goto out;
    for (int i = 0; i < n2; i++) {
        memcpy(Phi + (size_t)i * n2, E + (size_t)i * n3, sizeof(double) * n2);
        memcpy(G + (size_t)i * n, E + (size_t)i * n3 + n2, sizeof(double) * n);
    }
    rc = AMFI_OK;
out:
    free(Minv);
    free(MK);
    free(MC);
    free(Mw);
    free(Aug);
    free(E);
    return rc;
}
