/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_modal.c: the A-MFI backward/forward sweep in modal coordinates on
 * the reduced state z = [q₁, q₁', …, q_m, q_m', g₁ … g_na] (2m + na).
 *
 * Why reduced: in the paper formulation (docs/model.md §4) the X' block of the
 * augmented state never feeds forward, and y_{j+1} = Q x_{j+1} is a function
 * of [X_j; g_j] only:
 *     y_{j+1} = C_j z_j,  C_j = [Cx, Cg_j],  Cx = ψ(x_s)·(velocity row of (Φ − I)/h),
 *                                            Cg_j = ψ(x_s)·(velocity row of P_j)/h,
 *     z_{j+1} = A_j z_j + T r_j,  A_j = [[Φ, P_j], [0, I]],  T = [0; I].
 * The cost J = Σ_j (C_j z_j − d_{j+1})ᵀW(·) + λ Σ_j r_jᵀr_j is the paper's
 * eq 21 exactly, so the answer is the full-state one (tests check it against
 * the dense nodal path). With V_j(z) = zᵀR_j z + s_jᵀz (V_N = 0), Appendix A:
 *     K_j = (λI + R_gg)⁻¹,  Z = R − R T K Tᵀ R,
 *     R_j = C_jᵀWC_j + A_jᵀ Z A_j,  s_j = −2C_jᵀW d_{j+1} + A_jᵀ(I − R T K Tᵀ) s,
 *     r_j = −K_j(Tᵀ R A_j z_j + ½ Tᵀ s)      (R, s of step j + 1).
 * Φ is block diagonal (one 2 × 2 block per mode), so A_jᵀ Z A_j costs
 * O((2m)²·na) per step instead of O((2m + na)³). Only the upper block
 * triangle of R_xx is kept. Memory: gains, O(N·na·(2m + na)); beyond the
 * solver's budget (sweep_budget) O(sqrt N): checkpoints of the backward
 * state and one block's gains, recomputed in the forward pass.
 */
#include <math.h>
#include <string.h>

#include "dense.h"
#include "solver_internal.h"

size_t amfi_sweep_modal_scratch(int m, int na, int ns)
{
    size_t m2 = 2 * (size_t)m;
    return m2 * m2              /* Rxx */
           + 5 * m2 * na        /* Rxg, Ux, Vx, Y, P */
           + 6 * (size_t)na * na /* Rgg, Ugg, K, Vg, Zgg, Lg scratch */
           + 3 * m2             /* sx, zsx, x */
           + 8 * (size_t)na     /* sg, zsg, g, r, g0 ... */
           + (size_t)na * m     /* phi */
           + 2 * (size_t)ns * na + 2 * (size_t)ns + 16;
}

/* Mode values at the axles of step j: phi (na × m), P (2m × na), Cg (ns × na). */
static void step_rows(const struct amfi_solver *s, int j, double *phi, double *P, double *Cg)
{
    const int m = s->m, na = s->na, ns = s->ns;
    const double L = s->b->p.span_m;
    for (int a = 0; a < na; a++) {
        double x = axle_x(s, a, j);
        double *ph = phi + (size_t)a * m;
        if (!(x >= 0.0 && x <= L)) {
            memset(ph, 0, sizeof(double) * m);
            continue;
        }
        int e;
        double xi, N[4];
        amfi_bridge_locate(s->b, x, &e, &xi);
        amfi_hermite(xi, s->b->le, N);
        const double *p0 = s->pe + (size_t)e * 4 * m;
        for (int k = 0; k < m; k++)
            ph[k] = N[0] * p0[k] + N[1] * p0[m + k] + N[2] * p0[2 * m + k] + N[3] * p0[3 * m + k];
    }
    for (int k = 0; k < m; k++)
        for (int a = 0; a < na; a++) {
            P[(2 * k) * na + a] = s->Gm[2 * k] * phi[a * m + k];
            P[(2 * k + 1) * na + a] = s->Gm[2 * k + 1] * phi[a * m + k];
        }
    const double ih = 1.0 / s->h;
    for (int si = 0; si < ns; si++)
        for (int a = 0; a < na; a++) {
            double v = 0.0;
            for (int k = 0; k < m; k++)
                v += s->c[si * m + k] * P[(2 * k + 1) * na + a];
            Cg[si * na + a] = v * ih;
        }
}

/* The backward sweep's work space (amfi_sweep_modal_scratch). */
typedef struct bwork {
    double *Rxx, *Rxg, *Ux, *Vx, *Y, *P, *Rgg, *Ugg, *K, *Vg, *Zgg, *sx, *zsx, *x, *sg, *zsg,
        *g, *r, *phi, *Cg;
} bwork;

/* One backward step j: R, s of step j + 1 to those of step j; the gains of
 * step j into gj (na × (2m + na); NULL: not kept) and s->gofs. */
static int back_step(struct amfi_solver *s, const bwork *wk, int j, double lam, double *gj)
{
    const int m = s->m, m2 = 2 * m, na = s->na, ns = s->ns;
    const int nst = m2 + na;
    double *Rxx = wk->Rxx, *Rxg = wk->Rxg, *Ux = wk->Ux, *Vx = wk->Vx, *Y = wk->Y, *P = wk->P;
    double *Rgg = wk->Rgg, *Ugg = wk->Ugg, *K = wk->K, *Vg = wk->Vg, *Zgg = wk->Zgg;
    double *sx = wk->sx, *zsx = wk->zsx, *sg = wk->sg, *zsg = wk->zsg, *phi = wk->phi,
           *Cg = wk->Cg;
    const double *Phi = s->Phi, *Cx = s->Cx, *Hxx = s->Hxx;
    {
        const double *dj = s->d + (size_t)(j + 1) * ns;
        step_rows(s, j, phi, P, Cg);
        memcpy(Ux, Rxg, sizeof(double) * m2 * na);
        memcpy(Ugg, Rgg, sizeof(double) * na * na);
        /* K = (λI + R_gg)⁻¹ */
        memcpy(K, Ugg, sizeof(double) * na * na);
        for (int a = 0; a < na; a++)
            K[a * na + a] += lam;
        if (amfi_spd_inverse(na, K) != 0)
            return AMFI_ENUM;
        /* Vx = Ux K, Vg = Ugg K */
        for (int i = 0; i < m2; i++)
            for (int b = 0; b < na; b++) {
                double v = 0.0;
                for (int c = 0; c < na; c++)
                    v += Ux[i * na + c] * K[c * na + b];
                Vx[i * na + b] = v;
            }
        for (int a = 0; a < na; a++)
            for (int b = 0; b < na; b++) {
                double v = 0.0;
                for (int c = 0; c < na; c++)
                    v += Ugg[a * na + c] * K[c * na + b];
                Vg[a * na + b] = v;
            }
        /* Gains of step j: r_j = −(gain_j z_j + gofs_j),
         * gain = K TᵀRA = [Vxᵀ Φ, Vxᵀ P + Vgᵀ], gofs = ½ K s_g. */
        for (int a = 0; a < na && gj; a++) {
            double *row = gj + (size_t)a * nst;
            for (int k = 0; k < m; k++) {
                const double *F = Phi + 4 * k;
                double v0 = Vx[(2 * k) * na + a], v1 = Vx[(2 * k + 1) * na + a];
                row[2 * k] = v0 * F[0] + v1 * F[2];
                row[2 * k + 1] = v0 * F[1] + v1 * F[3];
            }
            for (int b = 0; b < na; b++) {
                double v = Vg[b * na + a];
                for (int i = 0; i < m2; i++)
                    v += Vx[i * na + a] * P[i * na + b];
                row[m2 + b] = v;
            }
            double o = 0.0;
            for (int b = 0; b < na; b++)
                o += K[a * na + b] * sg[b];
            s->gofs[(size_t)j * na + a] = 0.5 * o;
        }
        /* (I − R T K Tᵀ) s */
        for (int i = 0; i < m2; i++) {
            double v = sx[i];
            for (int b = 0; b < na; b++)
                v -= Vx[i * na + b] * sg[b];
            zsx[i] = v;
        }
        for (int a = 0; a < na; a++) {
            double v = sg[a];
            for (int b = 0; b < na; b++)
                v -= Vg[a * na + b] * sg[b];
            zsg[a] = v;
        }
        /* Z_gg = Ugg − Vg Ugg; Z_xg = λ Vx (= Ux − Vx Ugg, since K⁻¹ = λI + Ugg) */
        for (int a = 0; a < na; a++)
            for (int b = 0; b < na; b++) {
                double v = Ugg[a * na + b];
                for (int c = 0; c < na; c++)
                    v -= Vg[a * na + c] * Ugg[c * na + b];
                Zgg[a * na + b] = v;
            }
        for (int i = 0; i < m2 * na; i++)
            Y[i] = lam * Vx[i];
        /* One pass over the upper block triangle: Z_kl = R_kl − Vx_k Ux_lᵀ,
         * Y = Z_xx P + Z_xg, R_kl ← Φ_kᵀ Z_kl Φ_l + H_kl. */
        for (int k = 0; k < m; k++) {
            const double *Fk = Phi + 4 * k;
            const double *vk0 = Vx + (2 * k) * na, *vk1 = vk0 + na;
            const double *pk0 = P + (2 * k) * na, *pk1 = pk0 + na;
            double *yk0 = Y + (2 * k) * na, *yk1 = yk0 + na;
            for (int l = k; l < m; l++) {
                const double *Fl = Phi + 4 * l;
                const double *ul0 = Ux + (2 * l) * na, *ul1 = ul0 + na;
                double *r0 = Rxx + (size_t)(2 * k) * m2 + 2 * l, *r1 = r0 + m2;
                double z00 = r0[0], z01 = r0[1], z10 = r1[0], z11 = r1[1];
                for (int c = 0; c < na; c++) {
                    z00 -= vk0[c] * ul0[c];
                    z01 -= vk0[c] * ul1[c];
                    z10 -= vk1[c] * ul0[c];
                    z11 -= vk1[c] * ul1[c];
                }
                const double *pl0 = P + (2 * l) * na, *pl1 = pl0 + na;
                for (int b = 0; b < na; b++) {
                    yk0[b] += z00 * pl0[b] + z01 * pl1[b];
                    yk1[b] += z10 * pl0[b] + z11 * pl1[b];
                }
                if (l != k) {
                    double *yl0 = Y + (2 * l) * na, *yl1 = yl0 + na;
                    for (int b = 0; b < na; b++) {
                        yl0[b] += z00 * pk0[b] + z10 * pk1[b];
                        yl1[b] += z01 * pk0[b] + z11 * pk1[b];
                    }
                }
                /* T = Z Φ_l, then Φ_kᵀ T */
                double t00 = z00 * Fl[0] + z01 * Fl[2], t01 = z00 * Fl[1] + z01 * Fl[3];
                double t10 = z10 * Fl[0] + z11 * Fl[2], t11 = z10 * Fl[1] + z11 * Fl[3];
                const double *h0 = Hxx + (size_t)(2 * k) * m2 + 2 * l, *h1 = h0 + m2;
                r0[0] = Fk[0] * t00 + Fk[2] * t10 + h0[0];
                r0[1] = Fk[0] * t01 + Fk[2] * t11 + h0[1];
                r1[0] = Fk[1] * t00 + Fk[3] * t10 + h1[0];
                r1[1] = Fk[1] * t01 + Fk[3] * t11 + h1[1];
            }
        }
        /* R_xg = Φᵀ Y + Cxᵀ W Cg */
        for (int k = 0; k < m; k++) {
            const double *F = Phi + 4 * k;
            for (int b = 0; b < na; b++) {
                double y0 = Y[(2 * k) * na + b], y1 = Y[(2 * k + 1) * na + b];
                double c0 = 0.0, c1 = 0.0;
                for (int si = 0; si < ns; si++) {
                    double wc = s->w[si] * Cg[si * na + b];
                    c0 += Cx[si * m2 + 2 * k] * wc;
                    c1 += Cx[si * m2 + 2 * k + 1] * wc;
                }
                Rxg[(2 * k) * na + b] = F[0] * y0 + F[2] * y1 + c0;
                Rxg[(2 * k + 1) * na + b] = F[1] * y0 + F[3] * y1 + c1;
            }
        }
        /* R_gg = Pᵀ Y + λ Vxᵀ P + Z_gg + Cgᵀ W Cg */
        for (int a = 0; a < na; a++)
            for (int b = 0; b < na; b++) {
                double v = Zgg[a * na + b];
                for (int i = 0; i < m2; i++)
                    v += P[i * na + a] * Y[i * na + b] + lam * Vx[i * na + a] * P[i * na + b];
                for (int si = 0; si < ns; si++)
                    v += s->w[si] * Cg[si * na + a] * Cg[si * na + b];
                Rgg[a * na + b] = v;
            }
        for (int a = 0; a < na; a++) /* symmetrise against round-off drift */
            for (int b = a + 1; b < na; b++)
                Rgg[a * na + b] = Rgg[b * na + a] = 0.5 * (Rgg[a * na + b] + Rgg[b * na + a]);
        /* s_x = Φᵀ zs_x − 2 Cxᵀ W d; s_g = Pᵀ zs_x + zs_g − 2 Cgᵀ W d */
        for (int k = 0; k < m; k++) {
            const double *F = Phi + 4 * k;
            double z0 = zsx[2 * k], z1 = zsx[2 * k + 1];
            double c0 = 0.0, c1 = 0.0;
            for (int si = 0; si < ns; si++) {
                double wd = s->w[si] * dj[si];
                c0 += Cx[si * m2 + 2 * k] * wd;
                c1 += Cx[si * m2 + 2 * k + 1] * wd;
            }
            sx[2 * k] = F[0] * z0 + F[2] * z1 - 2.0 * c0;
            sx[2 * k + 1] = F[1] * z0 + F[3] * z1 - 2.0 * c1;
        }
        for (int a = 0; a < na; a++) {
            double v = zsg[a];
            for (int i = 0; i < m2; i++)
                v += P[i * na + a] * zsx[i];
            for (int si = 0; si < ns; si++)
                v -= 2.0 * s->w[si] * Cg[si * na + a] * dj[si];
            sg[a] = v;
        }
    }
    return AMFI_OK;
}

/* The backward state of a step (what back_step carries): Rxx, Rxg, Rgg,
 * sx, sg, in doubles. */
static size_t state_doubles(int m, int na)
{
    const size_t m2 = 2 * (size_t)m;
    return m2 * m2 + m2 * na + (size_t)na * na + m2 + na;
}

static void state_copy(const bwork *wk, int m, int na, double *dst, int save)
{
    const size_t m2 = 2 * (size_t)m;
    double *part[5] = {wk->Rxx, wk->Rxg, wk->Rgg, wk->sx, wk->sg};
    const size_t len[5] = {m2 * m2, m2 * na, (size_t)na * na, m2, (size_t)na};
    for (int i = 0; i < 5; i++) {
        if (save)
            memcpy(dst, part[i], sizeof(double) * len[i]);
        else
            memcpy(part[i], dst, sizeof(double) * len[i]);
        dst += len[i];
    }
}

size_t amfi_sweep_modal_gain_doubles(int m, int na, int N, size_t budget, int *seg)
{
    const size_t row = (size_t)na * (2 * (size_t)m + na);
    if ((size_t)N * row <= budget || N < 4) {
        *seg = N;
        return (size_t)N * row;
    }
    /* checkpoints every C steps and one segment's gains: N/C·state + C·row
     * is least at C = sqrt(N·state/row) */
    const size_t st = state_doubles(m, na);
    int C = (int)ceil(sqrt((double)N * (double)st / (double)row));
    if (C < 1)
        C = 1;
    if (C > N)
        C = N;
    *seg = C;
    return (size_t)C * row + (size_t)((N + C - 1) / C) * st;
}

int amfi_sweep_modal(struct amfi_solver *s, double lam, double *res_norm, double *smo_norm)
{
    const int m = s->m, m2 = 2 * m, na = s->na, ns = s->ns, N = s->N;
    const int nst = m2 + na; /* state size, gain row stride */
    double *w = s->scratch;
    double *Rxx = w;  w += (size_t)m2 * m2;
    double *Rxg = w;  w += (size_t)m2 * na;
    double *Ux = w;   w += (size_t)m2 * na;
    double *Vx = w;   w += (size_t)m2 * na;
    double *Y = w;    w += (size_t)m2 * na;
    double *P = w;    w += (size_t)m2 * na;
    double *Rgg = w;  w += (size_t)na * na;
    double *Ugg = w;  w += (size_t)na * na;
    double *K = w;    w += (size_t)na * na;
    double *Vg = w;   w += (size_t)na * na;
    double *Zgg = w;  w += (size_t)na * na;
    double *sx = w;   w += m2;
    double *zsx = w;  w += m2;
    double *x = w;    w += m2;
    double *sg = w;   w += na;
    double *zsg = w;  w += na;
    double *g = w;    w += na;
    double *r = w;    w += na;
    double *phi = w;  w += (size_t)na * m;
    double *Cg = w;   w += (size_t)ns * na;
    const double *Phi = s->Phi, *Cx = s->Cx;

    memset(Rxx, 0, sizeof(double) * m2 * m2);
    memset(Rxg, 0, sizeof(double) * m2 * na);
    memset(Rgg, 0, sizeof(double) * na * na);
    memset(sx, 0, sizeof(double) * m2);
    memset(sg, 0, sizeof(double) * na);

    const bwork wk = {Rxx, Rxg, Ux, Vx, Y, P, Rgg, Ugg, K, Vg, Zgg, sx, zsx, x, sg, zsg, g, r, phi, Cg};
    /* Gains of C steps at a time (C = N: all, when they fit the budget):
     * the backward pass saves its state every C steps; the forward pass
     * then recomputes each later block's gains from its checkpoint (the
     * same steps from the same state: the same numbers), so the memory is
     * O(sqrt N) for twice the backward work. */
    int C;
    const size_t grow = (size_t)na * nst; /* gains of one step */
    amfi_sweep_modal_gain_doubles(m, na, N, s->sweep_budget, &C);
    const int nblk = (N + C - 1) / C;
    const size_t st = state_doubles(m, na);
    double *ckpt = s->gain + (size_t)C * grow; /* checkpoint k: state before block k's steps */
    for (int j = N - 1; j >= 0; j--) {
        if (C < N && (j + 1) % C == 0 && j + 1 < N) /* R, s before block (j+1)/C's steps */
            state_copy(&wk, m, na, ckpt + (size_t)((j + 1) / C) * st, 1);
        double *gj = j < C ? s->gain + (size_t)j * grow : NULL;
        if (back_step(s, &wk, j, lam, gj) != 0)
            return AMFI_ENUM;
    }
    /* Start: at rest with g_0 free (argmin over g of gᵀR_gg g + s_gᵀg), or
     * with the whole z_0 free (argmin of z_0ᵀR_0 z_0 + s_0ᵀz_0). */
    memset(x, 0, sizeof(double) * m2);
    memset(g, 0, sizeof(double) * na);
    if (s->p.free_initial_state) {
        /* R_0 in full from its stored parts into the L-curve-free scratch
         * at the end of the workspace (nst² doubles, sized at create). */
        double *A = s->scratch + amfi_sweep_modal_scratch(s->m, s->na_max, s->ns);
        double *rhs = A + (size_t)nst * nst;
        for (int i = 0; i < m2; i++)
            for (int k = i; k < m2; k++) {
                /* only the upper block triangle of Rxx is valid */
                double v = (k / 2 >= i / 2) ? Rxx[(size_t)i * m2 + k] : Rxx[(size_t)k * m2 + i];
                A[(size_t)i * nst + k] = A[(size_t)k * nst + i] = v;
            }
        for (int i = 0; i < m2; i++)
            for (int b = 0; b < na; b++)
                A[(size_t)i * nst + m2 + b] = A[(size_t)(m2 + b) * nst + i] = Rxg[i * na + b];
        for (int a = 0; a < na; a++)
            for (int b = 0; b < na; b++)
                A[(size_t)(m2 + a) * nst + m2 + b] = Rgg[a * na + b];
        for (int i = 0; i < m2; i++)
            rhs[i] = -0.5 * sx[i];
        for (int a = 0; a < na; a++)
            rhs[m2 + a] = -0.5 * sg[a];
        if (amfi_spd_solve(nst, A, rhs) != 0)
            return AMFI_ENUM;
        memcpy(x, rhs, sizeof(double) * m2);
        memcpy(g, rhs + m2, sizeof(double) * na);
    } else if (!s->p.fix_initial_force) {
        memcpy(K, Rgg, sizeof(double) * na * na);
        if (amfi_spd_inverse(na, K) != 0)
            return AMFI_ENUM;
        for (int a = 0; a < na; a++) {
            double v = 0.0;
            for (int b = 0; b < na; b++)
                v += K[a * na + b] * sg[b];
            g[a] = -0.5 * v;
        }
    }

    double res2 = 0.0, smo2 = 0.0;
    /* a block's recomputation uses the backward work space only (not x,
     * g, r; phi, P, Cg are set again by step_rows below) */
    for (int j = 0; j < N; j++) {
        if (j > 0 && j % C == 0) { /* block j/C: its gains from its checkpoint */
            const int hi = j / C + 1 < nblk ? j + C : N;
            if (hi < N)
                state_copy(&wk, m, na, ckpt + (size_t)(hi / C) * st, 0);
            else {
                memset(Rxx, 0, sizeof(double) * m2 * m2);
                memset(Rxg, 0, sizeof(double) * m2 * na);
                memset(Rgg, 0, sizeof(double) * na * na);
                memset(sx, 0, sizeof(double) * m2);
                memset(sg, 0, sizeof(double) * na);
            }
            for (int jj = hi - 1; jj >= j; jj--)
                if (back_step(s, &wk, jj, lam, s->gain + (size_t)(jj - j) * grow) != 0)
                    return AMFI_ENUM;
        }
        const double *dj = s->d + (size_t)(j + 1) * ns;
        step_rows(s, j, phi, P, Cg);
        const double *gj = s->gain + (size_t)(j % C) * grow;
        for (int a = 0; a < na; a++) {
            const double *row = gj + (size_t)a * nst;
            double v = s->gofs[(size_t)j * na + a];
            for (int i = 0; i < m2; i++)
                v += row[i] * x[i];
            for (int b = 0; b < na; b++)
                v += row[m2 + b] * g[b];
            r[a] = -v;
            s->force[(size_t)j * na + a] = g[a];
        }
        for (int si = 0; si < ns; si++) {
            double v = 0.0;
            for (int i = 0; i < m2; i++)
                v += Cx[si * m2 + i] * x[i];
            for (int b = 0; b < na; b++)
                v += Cg[si * na + b] * g[b];
            s->y[(size_t)j * ns + si] = v;
            res2 += s->w[si] * (v - dj[si]) * (v - dj[si]);
        }
        for (int k = 0; k < m; k++) {
            const double *F = Phi + 4 * k;
            double q0 = x[2 * k], q1 = x[2 * k + 1];
            double p0 = 0.0, p1 = 0.0;
            for (int b = 0; b < na; b++) {
                p0 += P[(2 * k) * na + b] * g[b];
                p1 += P[(2 * k + 1) * na + b] * g[b];
            }
            x[2 * k] = F[0] * q0 + F[1] * q1 + p0;
            x[2 * k + 1] = F[2] * q0 + F[3] * q1 + p1;
        }
        for (int a = 0; a < na; a++) {
            g[a] += r[a];
            smo2 += r[a] * r[a];
        }
    }
    for (int a = 0; a < na; a++)
        s->force[(size_t)N * na + a] = g[a];
    *res_norm = sqrt(res2);
    *smo_norm = sqrt(smo2);
    return isfinite(res2) && isfinite(smo2) ? AMFI_OK : AMFI_ENUM;
}
