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
    double r2; /* the last sweep's residual ‖y − d‖²_W */
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
    q->r2 = c;
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

/* The full model's local search around a pick x (the solver's window set,
 * q->n_eff with it): x + k·d, k = −local_half .. local_half, widened one
 * point at a time toward a pick at an end up to ±3 (±0.9 %: on simulated
 * traffic the coarse model's dip lies up to 0.8 % from the full model's,
 * docs/results/speed-estimation.md), the pick among them (local_pick),
 * then refine() between its neighbours: *best and *fbest. −1 when no
 * point lies in [wlo, hi] or a sweep failed (q->rc). */
static int local_search(search *q, double x, double d, double wlo, double hi, double *best,
                        double *fbest)
{
    const amfi_speed_prior *pr = q->pr;
    const double v0 = q->v0;
    double lx[7], lf[7];
    int nl = 0, k_first = 0, k_last = -1;
    for (int k = -pr->local_half; k <= pr->local_half && !q->rc; k++) {
        double v = x + k * d;
        if (v < wlo - 1e-9 * v0 || v > hi + 1e-9 * v0)
            continue;
        if (nl == 0)
            k_first = k;
        k_last = k;
        lx[nl] = v, lf[nl] = objective(v, q);
        nl++;
    }
    if (q->rc || nl < 1)
        return -1;
    int kb = local_pick(pr, lx, lf, nl, x, d);
    for (;;) {
        double v;
        if (kb == 0 && k_first > -3 && (v = x + (k_first - 1) * d) >= wlo - 1e-9 * v0) {
            memmove(lx + 1, lx, sizeof(double) * (size_t)nl);
            memmove(lf + 1, lf, sizeof(double) * (size_t)nl);
            lx[0] = v, lf[0] = objective(v, q);
            k_first--;
        } else if (kb == nl - 1 && k_last < 3 && (v = x + (k_last + 1) * d) <= hi + 1e-9 * v0) {
            lx[nl] = v, lf[nl] = objective(v, q);
            k_last++;
        } else {
            break;
        }
        nl++;
        if (q->rc)
            return -1;
        kb = local_pick(pr, lx, lf, nl, x, d);
    }
    *best = lx[kb], *fbest = lf[kb];
    if (kb > 0 && kb < nl - 1) {
        *best = refine(q, lx[kb - 1], lf[kb - 1], lx[kb], lf[kb], lx[kb + 1], lf[kb + 1], fbest);
        if (q->rc)
            return -1;
    }
    return 0;
}

/* The axle groups' aliases of the coarse pick x. Axles i < j, S_i < S_j
 * behind the first, on a span L: at the trial speed v (L + S_j)/(L + S_i)
 * axle j leaves the span when axle i truly left, and for the axles of a
 * tandem or tridem (1.3 m apart) that is 4-6 % faster than the truth; the
 * coarse grid's deepest dip can be that alias, with a shallower dip at the
 * truth (docs/results/class-accuracy.md). So the candidates for the truth
 * are x (L + S_i)/(L + S_j) for every pair whose ratio is within the range
 * (range_sd·σ) and whose speed is not below lo, each at the coarse grid's
 * deepest dip within 2 steps (0.6 %) of it, none where the coarse grid has
 * no dip there (a point of the slow trend is no candidate); at most
 * AMFI_SPEED_ALIASES, 2 grid steps apart and from x. J on the grid: fv[k]
 * at g0 + k·g, k = 0 .. n − 1. Their speeds in xc; returns how many. */
static int alias_candidates(const amfi_speed_prior *pr, const amfi_passage *ps, double span_m,
                            const double *fv, int n, double g0, double g, double x, double lo,
                            double hi, double *xc)
{
    double S[AMFI_MAX_AXLES];
    int na = ps->n_axles, nc = 0, kc[AMFI_SPEED_ALIASES];
    if (na < 2 || na > AMFI_MAX_AXLES)
        return 0;
    S[0] = 0.0;
    for (int a = 1; a < na; a++)
        S[a] = S[a - 1] + ps->axle_spacing_m[a - 1];
    const int kx = (int)lround((x - g0) / g);
    const double eps = 1e-9 * x;
    for (int i = 0; i + 1 < na; i++)
        for (int j = i + 1; j < na; j++) {
            double ratio = (span_m + S[j]) / (span_m + S[i]);
            if (!(ratio > 1.0 && ratio - 1.0 <= pr->range_sd * pr->rel_sd))
                continue;
            double xa = x / ratio;
            if (xa < lo - eps)
                continue;
            int k0 = (int)lround((xa - g0) / g), kb = -1;
            double db = 0.0;
            for (int k = k0 - 2; k <= k0 + 2; k++) {
                double v = g0 + k * g;
                if (k < 0 || k >= n || v < lo - eps || v > hi + eps)
                    continue;
                double dk = amfi_speed_dip_at(pr, fv, n, k); /* NAN: no trend */
                if (dk < db)
                    db = dk, kb = k;
            }
            if (kb < 0 || abs(kb - kx) <= 2)
                continue;
            int near = 0;
            for (int c = 0; c < nc && !near; c++)
                near = abs(kb - kc[c]) <= 2;
            if (near || nc == AMFI_SPEED_ALIASES)
                continue;
            kc[nc] = kb, xc[nc] = g0 + kb * g;
            nc++;
        }
    return nc;
}

/* The judge between the coarse pick's aliases and its estimate (measured
 * on the coupled simulator's traffic, docs/results/class-accuracy.md): an
 * alias is judged on the full model only if the coarse model's residual
 * there is below ALIAS_SCREEN times the one at the pick; the pick's
 * estimate is left only if the best alias's residual on the full model is
 * below ALIAS_LEAVE times the estimate's, and then for the nearest alias
 * (the least change) whose residual is below ALIAS_TAKE times it. The
 * residual, not J: J's trend towards slow speeds, where the axles stay on
 * the span and their forces absorb the misfit, made slower candidates win
 * (branch speedcand). The residual has that trend too (on the Table 5
 * batch a slower alias of a right estimate fit up to 3 times better, 4
 * times on a 10 % softer bridge), but the fast alias of the truth misses
 * the exit transients of an axle group, and the truth fit 3-14 times
 * better than it (2-4 for a single tandem): hence the wide margins. */
#define ALIAS_SCREEN 0.6
#define ALIAS_LEAVE 0.2
#define ALIAS_TAKE 0.3

/* The judge between the pick's estimate best0 and the aliases xc[0 .. nc):
 * every alias gets the local search, all in one window (that of the
 * slowest point any may try, so that their residuals compare), and the
 * fit's residual ‖y − d‖²_W (same λ) is evaluated at each estimate and at
 * best0 in that window; then the rule above. Returns the winner's index +
 * 1 (*best its estimate, *fbest J there), 0 for best0, or −1 (q->rc: a
 * failed sweep; else *rc_out, err set). */
static int alias_judge(search *q, const amfi_passage *ps, const amfi_lambda *lam, double best0,
                       const double *xc, int nc, double d, double lo, double hi, double *best,
                       double *fbest, int *rc_out, char *err, size_t errlen)
{
    struct amfi_solver *s = q->s;
    double wlo = best0;
    for (int c = 0; c < nc; c++)
        if (xc[c] - 3.0 * d < wlo)
            wlo = xc[c] - 3.0 * d;
    if (wlo < lo)
        wlo = lo;
    int rc = amfi_solve_begin(s, ps, lam, wlo, err, errlen);
    if (rc) {
        *rc_out = rc;
        return -1;
    }
    q->n_eff = n_eff_of(s, ps, q->pr);
    objective(best0, q);
    const double r0 = q->r2;
    if (q->rc)
        return -1;
    /* the aliases nearest the pick first */
    int order[AMFI_SPEED_ALIASES];
    for (int c = 0; c < nc; c++) {
        int k = c;
        while (k > 0 && xc[order[k - 1]] < xc[c])
            order[k] = order[k - 1], k--;
        order[k] = c;
    }
    double bx[AMFI_SPEED_ALIASES], bj[AMFI_SPEED_ALIASES], br[AMFI_SPEED_ALIASES], rmin = r0;
    int ok[AMFI_SPEED_ALIASES];
    for (int o = 0; o < nc; o++) {
        double f;
        ok[o] = local_search(q, xc[order[o]], d, wlo, hi, &bx[o], &f) == 0;
        if (q->rc)
            return -1;
        if (!ok[o])
            continue;
        bj[o] = objective(bx[o], q), br[o] = q->r2;
        if (q->rc)
            return -1;
        if (br[o] < rmin)
            rmin = br[o];
    }
    if (!(rmin < ALIAS_LEAVE * r0))
        return 0;
    for (int o = 0; o < nc; o++)
        if (ok[o] && br[o] < ALIAS_TAKE * r0) {
            *best = bx[o], *fbest = bj[o];
            return order[o] + 1;
        }
    return 0;
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
    search q = {s, pr, v0, 0.0, 0.0, 0, pr->brent_evals, 0, 0.0};
    int n_lc = 0;
    if (!two_level || lam->automatic) {
        if ((rc = amfi_solve_begin(s, ps, lam, glo, err, errlen)) != 0)
            return rc;
        s->speed = v0;
    }
    if ((rc = amfi_solve_lambda(s, lam, &q.lam_h, &n_lc, err, errlen)) != 0)
        return rc;

    double best, fbest, j_given, j_best = DBL_MAX, dip;
    int edge, n_coarse = 0, n_alias = 0, n_judged = 0, alias_won = 0;
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
                     n_eff_of(c, ps, pr), 0, 0, 0, 0.0};
        grid_best r = grid(&qc, glo, ghi, lo, hi, g, fv);
        n_coarse = qc.evals;
        if (qc.rc)
            return SWEEP_FAILED(qc);
        edge = r.edge, dip = r.dip;
        /* 2. The full model on a local grid around the coarse pick
         * (local_search): x + k·d, d = 0.3 % of the given speed whatever the
         * coarse grid's step (the points are closer than the full model's
         * dip half-width to any speed between them), k = −local_half ..
         * local_half, widened to ±3 while the pick sits at an end; the pick
         * is, as on the coarse grid, the point deepest below the others'
         * trend (pick dip, from 4 points) or the smallest; then the
         * parabola's vertex or Brent between the pick's neighbours. Its
         * window is that of the slowest point it may try. */
        const double d = 0.003 * v0;
        double wlo = r.x - 3.0 * d;
        if (wlo < lo)
            wlo = lo;
        if ((rc = amfi_solve_begin(s, ps, lam, wlo, err, errlen)) != 0)
            return rc;
        q.n_eff = n_eff_of(s, ps, pr);
        if (local_search(&q, r.x, d, wlo, hi, &best, &fbest) != 0)
            return q.rc ? SWEEP_FAILED(q)
                        : amfi_fail(err, errlen, AMFI_EINVAL,
                                    "speed search: no local point in range");
        /* 3. Pick dip: the coarse pick may be the fast alias of an axle
         * group (alias_candidates): the aliases the coarse model's residual
         * does not rule out (ALIAS_SCREEN, a coarse sweep each) are judged
         * on the full model against the estimate (alias_judge). A vehicle
         * without an axle pair that aliases within the range (two axles 5 m
         * apart) has none and takes none of these sweeps. */
        if (pr->pick == AMFI_SPEED_PICK_DIP && isfinite(r.dip)) {
            double xc[AMFI_SPEED_ALIASES];
            int ci_lo, cn = grid_points(v0, glo, ghi, g, &ci_lo);
            int nc = alias_candidates(pr, ps, s->b->p.span_m, fv, cn, v0 + ci_lo * g, g, r.x,
                                      lo, hi, xc);
            if (nc > 0) {
                /* the screen: the coarse model's residual at the pick and each alias */
                objective(r.x, &qc);
                const double rp = qc.r2;
                int m = 0;
                for (int k = 0; k < nc && !qc.rc; k++) {
                    objective(xc[k], &qc);
                    if (qc.r2 < ALIAS_SCREEN * rp)
                        xc[m++] = xc[k];
                }
                n_coarse = qc.evals;
                if (qc.rc)
                    return SWEEP_FAILED(qc);
                n_alias = nc, nc = m;
            }
            if (nc > 0) {
                int arc = 0, w = alias_judge(&q, ps, lam, best, xc, nc, d, lo, hi, &best,
                                             &fbest, &arc, err, errlen);
                if (w < 0)
                    return q.rc ? SWEEP_FAILED(q) : arc;
                n_judged = nc, alias_won = w;
            }
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
    sr->n_aliases = n_alias;
    sr->n_aliases_judged = n_judged;
    sr->alias = alias_won > 0;
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
