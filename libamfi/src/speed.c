/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * speed.c: estimation of a vehicle's speed from the recorded acceleration
 * (issue 12). The detector's speed is a Gaussian prior; a trial speed moves
 * the axles through the same window, and the A-MFI fit's cost at each trial
 * (one sweep, λ fixed) is the data term of
 *   J(v) = n_eff·ln C(v) + ((v − v0)/(σ·v0))²   (amfi.h).
 * Two levels (docs/solver.md, "Speed estimation"): J is evaluated on a grid
 * of speeds around v0 finer than the narrow dip the cost has at the true
 * speed, on a coarse model (the same bridge and sensors at coarse_rate_hz,
 * with the modes that rate resolves: a sweep costs ~1/13 of the full
 * model's); then the full model refines around the coarse pick (3 points
 * 0.3 % apart, widened toward a pick at an end up to ±0.9 %, then the
 * parabola's vertex, or GSL's Brent minimiser with brent_evals > 0: 3-8
 * sweeps with the final solve); the passage is finally solved at the
 * estimate as amfi_solve would (its own window). With coarse_rate_hz 0 (or
 * not below the calculation rate) the grid runs on the full model (the
 * first version: ~97 sweeps a passage). Sits above solver.c in libamfi's
 * call graph (internal.h): calls the solver's begin/lambda/end steps and
 * the sweep dispatcher, never called back. The coarse model is a second
 * amfi_solver owned by the first (s->coarse), created at the first search
 * that needs it.
 *
 * No sweep shares another's factorisation: the Riccati recursion depends on
 * where the axles are at every step, so each trial speed costs one sweep.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>

#include "solver_internal.h"

void amfi_speed_prior_default(amfi_speed_prior *p)
{
    memset(p, 0, sizeof *p);
    p->rel_sd = 0.03;
    p->range_sd = 3.0;
    p->grid_rel = 0.003;
    p->tol_rel = 2e-4;
    p->brent_evals = 0;
    p->local_half = 1;
    p->coarse_rate_hz = 1000.0;
    p->criterion = AMFI_SPEED_REGULARISED;
    p->pick = AMFI_SPEED_PICK_DIP;
}

const char *amfi_speed_pick_name(amfi_speed_pick p)
{
    return p == AMFI_SPEED_PICK_MIN ? "min" : "dip";
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
    if (p->local_half < 1 || p->local_half > 3)
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: local_half %d must be 1..3", p->local_half);
    if (!(isfinite(p->coarse_rate_hz) &&
          (p->coarse_rate_hz == 0 || (p->coarse_rate_hz >= 100 && p->coarse_rate_hz <= 1e6))))
        return amfi_fail(err, errlen, AMFI_EINVAL,
                         "speed prior: coarse rate %g Hz must be 0 (none) or in [100, 1e6]",
                         p->coarse_rate_hz);
    if (p->pick != AMFI_SPEED_PICK_MIN && p->pick != AMFI_SPEED_PICK_DIP)
        return amfi_fail(err, errlen, AMFI_EINVAL, "speed prior: unknown pick %d", (int)p->pick);
    if (p->criterion != AMFI_SPEED_REGULARISED && p->criterion != AMFI_SPEED_RESIDUAL)
        return amfi_fail(err, errlen, AMFI_EINVAL, "speed prior: unknown criterion %d",
                         (int)p->criterion);
    return AMFI_OK;
}

/* One level of the search: its solver (window set), λ per step and n_eff. */
typedef struct search {
    struct amfi_solver *s;
    const amfi_speed_prior *pr;
    double v0, lam_h, n_eff;
    int evals, brent_left, rc;
} search;

/* n_eff of J for the solver's current window: the data samples in it. */
static double n_eff_of(const struct amfi_solver *s, const amfi_passage *ps,
                       const amfi_speed_prior *pr)
{
    if (pr->data_dof > 0)
        return pr->data_dof;
    double data_steps = s->N * (ps->scan_rate_hz < s->p.calc_rate_hz
                                    ? ps->scan_rate_hz / s->p.calc_rate_hz
                                    : 1.0);
    return data_steps * s->ns;
}

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
    if (!(a < x && x < b && fx < fa && fx < fb)) { /* not a bracket: GSL would abort */
        *fbest = fx;
        return x;
    }
    gsl_function F = {objective, q};
    /* one minimiser per solver, allocated at its first search: set_with_values
     * starts it afresh each time */
    if (!q->s->brent)
        q->s->brent = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    gsl_min_fminimizer *m = q->s->brent;
    if (!m) {
        q->rc = AMFI_ENOMEM;
        *fbest = fx;
        return x;
    }
    double best = x, fmin = fx;
    /* GSL's Brent evaluates J once when it is set (at its first golden
     * point), then once an iteration: brent_evals counts them all */
    if (q->brent_left-- > 0 &&
        gsl_min_fminimizer_set_with_values(m, &F, x, fx, a, fa, b, fb) == GSL_SUCCESS) {
        best = gsl_min_fminimizer_x_minimum(m);
        fmin = gsl_min_fminimizer_f_minimum(m);
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
    *fbest = fmin;
    return best;
}

/* The refinement between a pick x and its equally spaced neighbours a < x
 * < b, on either level: Brent with brent_evals > 0, else the vertex of the
 * parabola through the three (no sweep; *fbest stays J at x, J at the
 * vertex is not known). */
static double refine(search *q, double a, double fa, double x, double fx, double b, double fb,
                     double *fbest)
{
    if (q->pr->brent_evals > 0)
        return brent(q, a, fa, x, fx, b, fb, fbest);
    *fbest = fx;
    double den = fa - 2.0 * fx + fb;
    if (a < x && x < b && den > 0.0 && fx <= fa && fx <= fb)
        return x + 0.5 * (x - a) * (fa - fb) / den;
    return x;
}

/* The grid v0 + i·g over [glo, ghi] (the range [lo, hi] and, for pick
 * dip, the trend's points beyond it): the picked point (prior->pick) among
 * the points in [lo, hi], whether it is an end of the range, and its
 * neighbours (xa, fa), (xb, fb) for Brent. J at every point goes to fv. */
typedef struct grid_best {
    double x, f, xa, fa, xb, fb, f0, dip;
    int edge;
} grid_best;

static int grid_points(double v0, double lo, double hi, double g, int *i_lo)
{
    *i_lo = -(int)floor((v0 - lo) / g + 1e-9);
    return (int)floor((hi - v0) / g + 1e-9) - *i_lo + 1;
}

/* The dip's trend: the grid points 0.6-1.2 % away on each side, k0..k1 steps. */
static void trend_span(const amfi_speed_prior *pr, int *k0, int *k1)
{
    *k0 = (int)lround(0.006 / pr->grid_rel);
    if (*k0 < 2)
        *k0 = 2;
    *k1 = 2 * *k0;
}

double amfi_speed_dip_at(const amfi_speed_prior *p, const double *j, int n, int k)
{
    int k0, k1;
    trend_span(p, &k0, &k1);
    if (!j || k < k1 || k + k1 >= n)
        return NAN;
    double sl = 0.0, sr = 0.0;
    for (int i = k0; i <= k1; i++)
        sl += j[k - i], sr += j[k + i];
    return j[k] - 0.5 * (sl + sr) / (k1 - k0 + 1);
}

static grid_best grid(search *q, double glo, double ghi, double lo, double hi, double g,
                      double *fv)
{
    const double v0 = q->v0, eps = 1e-9 * v0;
    int i_lo, n = grid_points(v0, glo, ghi, g, &i_lo);
    grid_best r = {v0, DBL_MAX, v0, DBL_MAX, v0, DBL_MAX, DBL_MAX, NAN, 0};
    int c_lo = n, c_hi = -1; /* the candidates: the points in [lo, hi] */
    for (int k = 0; k < n && !q->rc; k++) {
        double v = v0 + (i_lo + k) * g;
        fv[k] = objective(v, q);
        if (i_lo + k == 0)
            r.f0 = fv[k];
        if (v >= lo - eps && v <= hi + eps) {
            if (k < c_lo)
                c_lo = k;
            c_hi = k;
        }
    }
    if (q->rc || c_hi < c_lo)
        return r;
    int best = c_lo;
    for (int k = c_lo; k <= c_hi; k++)
        if (fv[k] < fv[best])
            best = k;
    if (q->pr->pick == AMFI_SPEED_PICK_DIP) {
        int pick = -1;
        double rmin = 0.0;
        for (int k = c_lo; k <= c_hi; k++) {
            double dip = amfi_speed_dip_at(q->pr, fv, n, k); /* NAN: no trend */
            if (dip < rmin)
                rmin = dip, pick = k;
        }
        if (pick >= 0)
            best = pick, r.dip = rmin;
    }
    r.x = v0 + (i_lo + best) * g;
    r.f = fv[best];
    r.edge = best == c_lo || best == c_hi;
    if (best > 0)
        r.xa = r.x - g, r.fa = fv[best - 1];
    if (best < n - 1)
        r.xb = r.x + g, r.fb = fv[best + 1];
    return r;
}

double amfi_speed_slowest_frac(const amfi_speed_prior *p)
{
    double f = p->range_sd * p->rel_sd;
    if (p->pick == AMFI_SPEED_PICK_DIP) {
        int k0, k1;
        trend_span(p, &k0, &k1);
        f += k1 * p->grid_rel;
    }
    return isfinite(f) && f > 0 ? (f < 0.5 ? f : 0.5) : 0.0;
}

/* The grid's values: a buffer kept with the solver, grown on demand. */
static double *grid_buffer(struct amfi_solver *s, int n)
{
    if (n > s->grid_cap) {
        double *p = realloc(s->grid_f, sizeof(double) * (size_t)n);
        if (!p)
            return NULL;
        s->grid_f = p;
        s->grid_cap = n;
    }
    return s->grid_f;
}

/* The local grid's pick among (lx, lf)[0 .. nl) (increasing speeds, d
 * apart around x): the point deepest below the line through the others
 * (pick dip: the full model's J has a trend here too, the coarse pick can
 * sit 0.8 % from the dip, on the slope, so the smallest J may be an end),
 * then the lower of it and its neighbours (the dip spans one or two
 * points); the smallest J for pick min or when no point lies below. */
static int local_pick(const amfi_speed_prior *pr, const double *lx, const double *lf, int nl,
                      double x, double d)
{
    int kb = 0;
    for (int k = 1; k < nl; k++)
        if (lf[k] < lf[kb])
            kb = k;
    if (pr->pick == AMFI_SPEED_PICK_DIP && nl >= 4) {
        double rmin = 0.0;
        int kd = -1;
        for (int k = 0; k < nl; k++) {
            double sx = 0, sy = 0, sxx = 0, sxy = 0;
            int m = 0;
            for (int i = 0; i < nl; i++) {
                if (i == k)
                    continue;
                double u = (lx[i] - x) / d;
                sx += u, sy += lf[i], sxx += u * u, sxy += u * lf[i], m++;
            }
            double den = m * sxx - sx * sx;
            if (!(den > 0))
                continue;
            double slope = (m * sxy - sx * sy) / den, icpt = (sy - slope * sx) / m;
            double rk = lf[k] - (icpt + slope * (lx[k] - x) / d);
            if (rk < rmin)
                rmin = rk, kd = k;
        }
        if (kd >= 0) {
            kb = kd;
            if (kd > 0 && lf[kd - 1] < lf[kb])
                kb = kd - 1;
            if (kd < nl - 1 && lf[kd + 1] < lf[kb])
                kb = kd + 1;
        }
    }
    return kb;
}

/* The coarse model: the solver's bridge, sensors and policies at `rate` Hz
 * with the observable modes that rate resolves (modal). Kept with the
 * solver; rebuilt only when the rate changes. */
static int coarse_solver(struct amfi_solver *s, double rate, char *err, size_t errlen)
{
    if (s->coarse && s->coarse->p.calc_rate_hz == rate)
        return AMFI_OK;
    amfi_solver_destroy(s->coarse);
    s->coarse = NULL;
    amfi_solver_params p = s->p;
    p.calc_rate_hz = rate;
    p.coords = AMFI_COORDS_MODAL;
    p.modes = AMFI_MODES_RESOLVED;
    char e[200];
    int rc = amfi_solver_create(s->b, &p, &s->coarse, e, sizeof e);
    if (rc)
        return amfi_fail(err, errlen, rc, "speed search: the coarse model at %g Hz: %s", rate,
                         e);
    return AMFI_OK;
}

#define SWEEP_FAILED(q)                                                                  \
    amfi_fail(err, errlen, (q).rc, "speed search: sweep failed: %s", amfi_strerror((q).rc))

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
    double lo = v0 - pr->range_sd * step, hi = v0 + pr->range_sd * step, vmin = 0.0;
    /* Raise the low end to the slowest speed whose window the data cover. */
    if (ps->n_samples >= 2 && isfinite(ps->scan_rate_hz) && ps->scan_rate_hz > 0 &&
        isfinite(ps->t_first_s) && ps->n_axles >= 1 && ps->n_axles <= AMFI_MAX_AXLES) {
        double t_last = ps->t_first_s + (ps->n_samples - 1) / ps->scan_rate_hz;
        amfi_passage_times w1 = amfi_passage_window(s->b->p.span_m, 1.0, ps->n_axles,
                                                    ps->axle_spacing_m, 0.0, 0.0);
        double avail = t_last - s->p.post_roll_s;
        if (avail > 0 && isfinite(w1.on_span_s) && w1.on_span_s > 0) {
            vmin = w1.on_span_s / avail * (1.0 + 1e-9);
            if (vmin > lo)
                lo = vmin < v0 ? vmin : v0;
        }
    }
    const int two_level = pr->coarse_rate_hz > 0 && pr->coarse_rate_hz < s->p.calc_rate_hz;
    const double g = pr->grid_rel * v0;
    /* pick dip: the trend's points beyond the range, as far as the data cover */
    double glo = lo, ghi = hi;
    if (pr->pick == AMFI_SPEED_PICK_DIP) {
        int k0, k1;
        trend_span(pr, &k0, &k1);
        glo = lo - k1 * g, ghi = hi + k1 * g;
        if (glo < vmin)
            glo = vmin;
        if (glo < 0.5 * lo)
            glo = 0.5 * lo;
        if (glo > lo) /* data short of even the range's low end: amfi_solve_begin says so */
            glo = lo;
    }
    int i_lo;
    double *fv = grid_buffer(s, grid_points(v0, glo, ghi, g, &i_lo));
    if (!fv)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "speed search: out of memory");

    /* λ on the full model: fixed, or the L-curve's at v0 in the search window. */
    search q = {s, pr, v0, 0.0, 0.0, 0, pr->brent_evals, 0};
    int n_lc = 0;
    if (!two_level || lam->automatic) {
        if ((rc = amfi_solve_begin(s, ps, lam, glo, err, errlen)) != 0)
            return rc;
        s->speed = v0;
    }
    if ((rc = amfi_solve_lambda(s, lam, &q.lam_h, &n_lc, err, errlen)) != 0)
        return rc;

    double best, fbest, j_given, j_best = DBL_MAX, dip;
    int edge, n_coarse = 0;
    if (!two_level) {
        /* The grid on the full model, then refine() between the pick's neighbours. */
        q.n_eff = n_eff_of(s, ps, pr);
        grid_best r = grid(&q, glo, ghi, lo, hi, g, fv);
        if (q.rc)
            return SWEEP_FAILED(q);
        best = r.x, fbest = r.f, edge = r.edge, dip = r.dip;
        j_given = r.f0;
        if (!edge) {
            best = refine(&q, r.xa, r.fa, r.x, r.f, r.xb, r.fb, &fbest);
            if (q.rc)
                return SWEEP_FAILED(q);
        }
    } else {
        /* 1. The grid on the coarse model, at the same λ (rate-independent λ_ref). */
        if ((rc = coarse_solver(s, pr->coarse_rate_hz, err, errlen)) != 0)
            return rc;
        struct amfi_solver *c = s->coarse;
        if ((rc = amfi_solve_begin(c, ps, lam, glo, err, errlen)) != 0)
            return rc;
        search qc = {c, pr, v0, q.lam_h / amfi_lambda_scale(s, lam) * amfi_lambda_scale(c, lam),
                     n_eff_of(c, ps, pr), 0, 0, 0};
        grid_best r = grid(&qc, glo, ghi, lo, hi, g, fv);
        n_coarse = qc.evals;
        if (qc.rc)
            return SWEEP_FAILED(qc);
        edge = r.edge, dip = r.dip;
        /* 2. The full model on a local grid around the coarse pick: x + k·d,
         * d = 0.3 % of the given speed whatever the coarse grid's step (the
         * points are closer than the full model's dip half-width to any
         * speed between them), k = −local_half .. local_half, widened to
         * ±3 (±0.9 %: on simulated traffic the coarse model's dip lies up
         * to 0.8 % from the full model's, docs/results/speed-estimation.md)
         * while the pick sits at an end; the pick is, as on the coarse
         * grid, the point deepest below the others' trend (pick dip, from
         * 4 points) or the smallest; then the parabola's vertex or Brent
         * between the pick's neighbours. Its window is that of the slowest
         * point it may try. */
        const double d = 0.003 * v0;
        double wlo = r.x - 3.0 * d;
        if (wlo < lo)
            wlo = lo;
        if ((rc = amfi_solve_begin(s, ps, lam, wlo, err, errlen)) != 0)
            return rc;
        q.n_eff = n_eff_of(s, ps, pr);
        /* k from −h .. h (h = local_half), widened one point at a time on
         * the side where the pick sits at the end, up to ±3 */
        double lx[7], lf[7];
        int nl = 0, k_first = 0, k_last = -1;
        for (int k = -pr->local_half; k <= pr->local_half && !q.rc; k++) {
            double v = r.x + k * d;
            if (v < wlo - 1e-9 * v0 || v > hi + 1e-9 * v0)
                continue;
            if (nl == 0)
                k_first = k;
            k_last = k;
            lx[nl] = v, lf[nl] = objective(v, &q);
            nl++;
        }
        if (q.rc)
            return SWEEP_FAILED(q);
        if (nl < 1)
            return amfi_fail(err, errlen, AMFI_EINVAL, "speed search: no local point in range");
        int kb = local_pick(pr, lx, lf, nl, r.x, d);
        for (;;) {
            double v;
            if (kb == 0 && k_first > -3 && (v = r.x + (k_first - 1) * d) >= wlo - 1e-9 * v0) {
                memmove(lx + 1, lx, sizeof(double) * (size_t)nl);
                memmove(lf + 1, lf, sizeof(double) * (size_t)nl);
                lx[0] = v, lf[0] = objective(v, &q);
                k_first--;
            } else if (kb == nl - 1 && k_last < 3 &&
                       (v = r.x + (k_last + 1) * d) <= hi + 1e-9 * v0) {
                lx[nl] = v, lf[nl] = objective(v, &q);
                k_last++;
            } else {
                break;
            }
            nl++;
            if (q.rc)
                return SWEEP_FAILED(q);
            kb = local_pick(pr, lx, lf, nl, r.x, d);
        }
        best = lx[kb], fbest = lf[kb];
        if (kb > 0 && kb < nl - 1) {
            best = refine(&q, lx[kb - 1], lf[kb - 1], lx[kb], lf[kb], lx[kb + 1], lf[kb + 1],
                          &fbest);
            if (q.rc)
                return SWEEP_FAILED(q);
        }
        /* J at v0 and at the minimum, both on the model of the grid. */
        j_given = r.f0, j_best = r.f;
    }
    sr->at_bound = edge;
    sr->speed_given_mps = v0;
    sr->speed_mps = best;
    sr->lo_mps = lo;
    sr->hi_mps = hi;
    sr->n_evals = q.evals;
    sr->n_coarse = n_coarse;
    sr->dip = dip;
    sr->grid_n = grid_points(v0, glo, ghi, g, &i_lo);
    sr->grid_lo_mps = v0 + i_lo * g;
    sr->grid_step_mps = g;
    sr->grid_j = fv;
    sr->j_given = j_given;
    sr->j_best = two_level ? j_best : fbest;

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
