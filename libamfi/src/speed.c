/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * speed.c: estimation of a vehicle's speed from the recorded acceleration
 * (issue 12). The detector's speed is a Gaussian prior; a trial speed moves
 * the axles through the same window, and the A-MFI fit's cost at each trial
 * (one sweep, λ fixed) is the data term of
 *   J(v) = n_eff·ln C(v) + ((v − v0)/(σ·v0))²   (amfi.h).
 * J is evaluated on a fine grid of speeds around v0 (finer than the narrow
 * dip the cost has at the true speed), then refined between the best grid
 * point's neighbours with GSL's Brent minimiser; the passage is finally solved at the estimate as
 * amfi_solve would (its own window). Sits above solver.c in libamfi's call
 * graph (internal.h): calls the solver's begin/lambda/end steps and the
 * sweep dispatcher, never called back.
 *
 * No sweep shares another's factorisation: the Riccati recursion depends on
 * where the axles are at every step, so each trial speed costs one sweep.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>

#include "solver_internal.h"

void amfi_speed_prior_default(amfi_speed_prior *p)
{
    memset(p, 0, sizeof *p);
    p->rel_sd = 0.03;
    p->range_sd = 3.0;
    p->grid_rel = 0.002;
    p->tol_rel = 2e-4;
    p->brent_evals = 6;
    p->criterion = AMFI_SPEED_REGULARISED;
}

const char *amfi_speed_criterion_name(amfi_speed_criterion c)
{
    return c == AMFI_SPEED_RESIDUAL ? "residual" : "regularised";
}

int amfi_speed_criterion_parse(const char *name, amfi_speed_criterion *c)
{
    if (!name)
        return -1;
    if (strcmp(name, "regularised") == 0) {
        *c = AMFI_SPEED_REGULARISED;
        return 0;
    }
    if (strcmp(name, "residual") == 0) {
        *c = AMFI_SPEED_RESIDUAL;
        return 0;
    }
    return -1;
}

int amfi_speed_prior_check(const amfi_speed_prior *p, double speed_mps, char *err,
                           size_t errlen)
{
    if (!p)
        return amfi_fail(err, errlen, AMFI_EINVAL, "speed prior: NULL");
    if (!(isfinite(speed_mps) && speed_mps > 0))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: the given speed %g m/s must be > 0", speed_mps);
    if (!(isfinite(p->rel_sd) && p->rel_sd > 0 && p->rel_sd < 1))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: relative SD %g must be in (0, 1)", p->rel_sd);
    if (!(isfinite(p->range_sd) && p->range_sd > 0 && p->range_sd * p->rel_sd < 0.5))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: range %g SD must be > 0 and range x SD (%g) < 0.5",
                         p->range_sd, p->range_sd * p->rel_sd);
    if (!(isfinite(p->tol_rel) && p->tol_rel > 0 && p->tol_rel < 0.01))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: tolerance %g must be in (0, 0.01)", p->tol_rel);
    if (!(isfinite(p->grid_rel) && p->grid_rel >= 1e-4 && p->grid_rel <= p->range_sd * p->rel_sd))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: grid step %g must be in [1e-4, range x SD = %g]",
                         p->grid_rel, p->range_sd * p->rel_sd);
    if (!(isfinite(p->data_dof) && p->data_dof >= 0 && p->data_dof <= 1e9))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: data_dof %g must be in [0, 1e9]", p->data_dof);
    if (p->brent_evals < 0 || p->brent_evals > 100)
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: brent_evals %d must be 0..100", p->brent_evals);
    if (p->criterion != AMFI_SPEED_REGULARISED && p->criterion != AMFI_SPEED_RESIDUAL)
        return amfi_fail(err, errlen, AMFI_EINVAL, "speed prior: unknown criterion %d",
                         (int)p->criterion);
    return AMFI_OK;
}

typedef struct search {
    struct amfi_solver *s;
    const amfi_speed_prior *pr;
    double v0, lam_h, n_eff;
    int evals, brent_left, rc;
} search;

/* J(v); a failed sweep gives DBL_MAX and its status in q->rc. */
static double objective(double v, void *user)
{
    search *q = user;
    double rn, sn;
    q->s->speed = v;
    q->evals++;
    int rc = amfi_sweep(q->s, q->lam_h, &rn, &sn);
    if (rc) {
        q->rc = rc;
        return DBL_MAX;
    }
    double c = rn * rn;
    if (q->pr->criterion == AMFI_SPEED_REGULARISED)
        c += q->lam_h * sn * sn;
    if (!(isfinite(c) && c > 0)) {
        q->rc = AMFI_ENUM;
        return DBL_MAX;
    }
    double z = (v - q->v0) / (q->pr->rel_sd * q->v0);
    return q->n_eff * log(c) + z * z;
}

/* Brent on [a, b] holding x with f(x) below both ends; returns the best. */
static double brent(search *q, double a, double fa, double x, double fx, double b, double fb,
                    double *fbest)
{
    const double tol = q->pr->tol_rel * q->v0;
    gsl_function F = {objective, q};
    gsl_min_fminimizer *m = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    if (!m) {
        q->rc = AMFI_ENOMEM;
        *fbest = fx;
        return x;
    }
    double best = x, fmin = fx;
    if (gsl_min_fminimizer_set_with_values(m, &F, x, fx, a, fa, b, fb) == GSL_SUCCESS) {
        while (q->brent_left-- > 0 && !q->rc) {
            if (gsl_min_fminimizer_iterate(m) != GSL_SUCCESS)
                break;
            double lo = gsl_min_fminimizer_x_lower(m), hi = gsl_min_fminimizer_x_upper(m);
            best = gsl_min_fminimizer_x_minimum(m);
            fmin = gsl_min_fminimizer_f_minimum(m);
            if (hi - lo < tol)
                break;
        }
    }
    gsl_min_fminimizer_free(m);
    *fbest = fmin;
    return best;
}

int amfi_solve_speed(amfi_solver *s, const amfi_passage *ps, const amfi_lambda *lam,
                     const amfi_speed_prior *pr, amfi_result *res, amfi_speed_result *sr,
                     char *err, size_t errlen)
{
    if (!s || !ps || !lam || !pr || !res || !sr)
        return amfi_fail(err, errlen, AMFI_EINVAL, "speed search: NULL argument");
    int rc = amfi_speed_prior_check(pr, ps->speed_mps, err, errlen);
    if (rc)
        return rc;
    const double v0 = ps->speed_mps, step = pr->rel_sd * v0;
    double lo = v0 - pr->range_sd * step, hi = v0 + pr->range_sd * step;
    /* Raise the low end to the slowest speed whose window the data cover. */
    if (ps->n_samples >= 2 && isfinite(ps->scan_rate_hz) && ps->scan_rate_hz > 0 &&
        isfinite(ps->t_first_s) && ps->n_axles >= 1 && ps->n_axles <= AMFI_MAX_AXLES) {
        double t_last = ps->t_first_s + (ps->n_samples - 1) / ps->scan_rate_hz;
        amfi_passage_times w1 = amfi_passage_window(s->b->p.span_m, 1.0, ps->n_axles,
                                                    ps->axle_spacing_m, 0.0, 0.0);
        double avail = t_last - s->p.post_roll_s;
        if (avail > 0 && isfinite(w1.on_span_s) && w1.on_span_s > 0) {
            double vmin = w1.on_span_s / avail * (1.0 + 1e-9);
            if (vmin > lo)
                lo = vmin < v0 ? vmin : v0;
        }
    }
    if ((rc = amfi_solve_begin(s, ps, lam, lo, err, errlen)) != 0)
        return rc;
    search q = {s, pr, v0, 0.0, 0.0, 0, pr->brent_evals, 0};
    int n_lc = 0;
    s->speed = v0;
    if ((rc = amfi_solve_lambda(s, lam, &q.lam_h, &n_lc, err, errlen)) != 0)
        return rc;
    double data_steps = s->N * (ps->scan_rate_hz < s->p.calc_rate_hz
                                    ? ps->scan_rate_hz / s->p.calc_rate_hz
                                    : 1.0);
    q.n_eff = pr->data_dof > 0 ? pr->data_dof : data_steps * s->ns;

    /* Grid: v0 + i·grid_rel·v0 over [lo, hi]. The cost has a narrow dip at
     * the true speed (about ±0.25 % wide: the entry and exit transients of
     * the axles) on a slope (docs/solver.md), so a bracketing search from a
     * few points finds the slope's end, not the dip; the grid must be finer
     * than the dip. Then Brent between the best point's neighbours. */
    const double g = pr->grid_rel * v0;
    int i_lo = -(int)floor((v0 - lo) / g + 1e-9), i_hi = (int)floor((hi - v0) / g + 1e-9);
    double best = v0, fbest = DBL_MAX, f0 = DBL_MAX;
    double xa = v0, fa = DBL_MAX, xb = v0, fb = DBL_MAX, prev_x = v0, prev_f = DBL_MAX;
    int best_i = 0, edge = 0;
    for (int i = i_lo; i <= i_hi && !q.rc; i++) {
        double v = v0 + i * g, f = objective(v, &q);
        if (i == 0)
            f0 = f;
        if (f < fbest) {
            best = v, fbest = f, best_i = i;
            xa = prev_x, fa = prev_f;
            edge = i == i_lo || i == i_hi;
            xb = v, fb = DBL_MAX; /* until the next point */
        } else if (i == best_i + 1) {
            xb = v, fb = f;
        }
        prev_x = v, prev_f = f;
    }
    if (q.rc)
        return amfi_fail(err, errlen, q.rc, "speed search: sweep failed: %s",
                         amfi_strerror(q.rc));
    sr->at_bound = edge;
    if (!edge && fbest < fa && fbest < fb) {
        best = brent(&q, xa, fa, best, fbest, xb, fb, &fbest);
        if (q.rc)
            return amfi_fail(err, errlen, q.rc, "speed search: sweep failed: %s",
                             amfi_strerror(q.rc));
    }
    sr->speed_given_mps = v0;
    sr->speed_mps = best;
    sr->lo_mps = lo;
    sr->hi_mps = hi;
    sr->n_evals = q.evals;
    sr->j_given = f0;
    sr->j_best = fbest;

    /* The result: amfi_solve at the estimate, in its own window, same λ. */
    amfi_passage pv = *ps;
    pv.speed_mps = best;
    if ((rc = amfi_solve_begin(s, &pv, lam, best, err, errlen)) != 0)
        return rc;
    rc = amfi_solve_end(s, lam, q.lam_h, n_lc + q.evals, res, err, errlen);
    if (rc == AMFI_OK && lam->automatic) {
        /* the L-curve was run at v0 in the search window: keep λ, drop the points */
        res->lcurve_n = 0;
    }
    return rc;
}
