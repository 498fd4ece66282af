/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * lcurve.c: choice of λ by the L-curve (Hansen 1992; paper Figure 2).
 *
 * For each λ, one sweep gives the residual norm ρ = ‖y − d‖_W and the
 * smoothing norm η = ‖r‖. On the curve (log ρ, log η), ordered by
 * increasing λ, the corner is the point of maximum signed curvature (the
 * curve turns counter-clockwise there, from falling steeply to running
 * flat). Curvature at an interior point is the Menger curvature of it and
 * its two neighbours, 2·((p₂ − p₁) × (p₃ − p₂)) / (|p₂ − p₁||p₃ − p₂||p₃ − p₁|),
 * which does not depend on how the λ are spaced.
 *
 * Search: a log grid lo..hi with per_decade points per decade; then the
 * interval between the best interior point's two neighbours is refined with
 * refine_points more log-spaced λ, and the curvature is recomputed over all
 * points. Cost: (grid + refine) sweeps, plus the final sweep at the chosen λ.
 */
#include <math.h>
#include <stdlib.h>

#include "solver_internal.h"

/* Points of the search l: the grid (at least 3) and the refinement. */
static int lcurve_points(const amfi_lambda *l, int *ngrid)
{
    const double dec = log10(l->lcurve_hi / l->lcurve_lo);
    int n = (int)floor(dec * l->lcurve_per_decade + 1e-9) + 1;
    if (n < 3)
        n = 3;
    if (ngrid)
        *ngrid = n;
    return n + l->lcurve_refine_points;
}

/* One block of 4 × want doubles (λ, ρ, η, κ), replacing the old one only
 * when it is too small. */
int amfi_lcurve_reserve(struct amfi_solver *s, const amfi_lambda *l)
{
    const int want = lcurve_points(l, NULL);
    if (want <= s->lc_cap)
        return 0;
    double *a = malloc(sizeof(double) * 4 * (size_t)want);
    if (!a)
        return AMFI_ENOMEM;
    free(s->lc_lam);
    s->bytes += sizeof(double) * 4 * (size_t)(want - s->lc_cap);
    s->lc_lam = a;
    s->lc_res = a + want;
    s->lc_smo = a + 2 * (size_t)want;
    s->lc_kap = a + 3 * (size_t)want;
    s->lc_cap = want;
    return 0;
}

/* Insert keeping λ ascending. */
static void insert(struct amfi_solver *s, double lam, double rho, double eta)
{
    int i = s->lc_n;
    while (i > 0 && s->lc_lam[i - 1] > lam) {
        s->lc_lam[i] = s->lc_lam[i - 1];
        s->lc_res[i] = s->lc_res[i - 1];
        s->lc_smo[i] = s->lc_smo[i - 1];
        i--;
    }
    s->lc_lam[i] = lam;
    s->lc_res[i] = rho;
    s->lc_smo[i] = eta;
    s->lc_n++;
}

/* Curvatures; returns the index of the maximum (−1 if fewer than 3 points). */
static int curvature(struct amfi_solver *s)
{
    int best = -1;
    const int n = s->lc_n;
    for (int i = 0; i < n; i++)
        s->lc_kap[i] = NAN;
    for (int i = 1; i + 1 < n; i++) {
        double x1 = log10(s->lc_res[i - 1]), y1 = log10(s->lc_smo[i - 1]);
        double x2 = log10(s->lc_res[i]), y2 = log10(s->lc_smo[i]);
        double x3 = log10(s->lc_res[i + 1]), y3 = log10(s->lc_smo[i + 1]);
        double ax = x2 - x1, ay = y2 - y1, bx = x3 - x2, by = y3 - y2;
        double den = hypot(ax, ay) * hypot(bx, by) * hypot(x3 - x1, y3 - y1);
        double k = den > 0 ? 2.0 * (ax * by - ay * bx) / den : 0.0;
        s->lc_kap[i] = k;
        if (isfinite(k) && (best < 0 || k > s->lc_kap[best]))
            best = i;
    }
    return best;
}

int amfi_lcurve(struct amfi_solver *s, const amfi_lambda *l, double scale, double *lam_h,
                int *n_solves)
{
    const double dec = log10(l->lcurve_hi / l->lcurve_lo);
    int ngrid;
    lcurve_points(l, &ngrid);
    if (amfi_lcurve_reserve(s, l))
        return AMFI_ENOMEM;
    s->lc_n = 0;
    int rc;
    for (int i = 0; i < ngrid; i++) {
        double lam = l->lcurve_lo * pow(10.0, dec * i / (ngrid - 1));
        double rho, eta;
        if ((rc = amfi_sweep(s, lam * scale, &rho, &eta)) != 0)
            return rc;
        (*n_solves)++;
        insert(s, lam, rho, eta);
    }
    int best = curvature(s);
    if (best < 0)
        return AMFI_ENUM;
    const int nref = l->lcurve_refine_points;
    if (nref > 0) {
        double lo = log10(s->lc_lam[best - 1]), hi = log10(s->lc_lam[best + 1]);
        double mid = log10(s->lc_lam[best]);
        for (int i = 1; i <= nref; i++) {
            double e = lo + (hi - lo) * i / (nref + 1);
            if (fabs(e - mid) < 1e-9 * (hi - lo))
                continue; /* already on the grid */
            double lam = pow(10.0, e), rho, eta;
            if ((rc = amfi_sweep(s, lam * scale, &rho, &eta)) != 0)
                return rc;
            (*n_solves)++;
            insert(s, lam, rho, eta);
        }
        best = curvature(s);
    }
    *lam_h = s->lc_lam[best] * scale;
    return AMFI_OK;
}
