/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * solver.c: the A-MFI solver's workspace, the passage window, the data at
 * the calculation rate, and the per-axle means (docs/model.md §6-§8). The top of
 * libamfi's call graph (internal.h): calls the sweep dispatcher and the
 * L-curve, never called back by them.
 *
 * Create once per site and thread: discretisation and all buffers are sized
 * here. amfi_solve() allocates only when a passage is longer than the
 * capacity, before any time loop.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_min.h>

#include "solver_internal.h"

void amfi_solver_destroy(amfi_solver *s)
{
    if (!s)
        return;
    free(s->S);
    free(s->mode);
    free(s->Phi);
    free(s->Gm);
    free(s->c);
    free(s->Cx);
    free(s->Hxx);
    free(s->pe);
    free(s->PhiN);
    free(s->GN);
    free(s->d);
    free(s->force);
    free(s->y);
    free(s->gain);
    free(s->gofs);
    free(s->scratch);
    free(s->lc_lam); /* one block with lc_res, lc_smo, lc_kap */
    free(s->mq);
    free(s->seg);
    if (s->brent)
        gsl_min_fminimizer_free(s->brent);
    amfi_solver_destroy(s->coarse);
    free(s->grid_f);
    free(s);
}

size_t amfi_solver_workspace_bytes(const amfi_solver *s)
{
    return s->bytes + (s->coarse ? s->coarse->bytes : 0) + sizeof(double) * (size_t)s->grid_cap;
}

static int check_params(const amfi_bridge *b, const amfi_solver_params *p, char *err,
                        size_t errlen)
{
    const double L = b->p.span_m;
#define REQ(cond, ...)                                                    \
    do {                                                                  \
        if (!(cond))                                                      \
            return amfi_fail(err, errlen, AMFI_EINVAL, __VA_ARGS__);      \
    } while (0)
    REQ(p->formulation == AMFI_FORM_PAPER, "unknown formulation %d", (int)p->formulation);
    REQ(p->coords == AMFI_COORDS_MODAL || p->coords == AMFI_COORDS_NODAL,
        "unknown coordinates %d", (int)p->coords);
    REQ(p->modes >= AMFI_MODES_ALL && p->modes <= AMFI_MODES_RESOLVED, "unknown modes policy");
    REQ(p->modes != AMFI_MODES_COUNT || p->n_modes >= 1, "n_modes must be >= 1");
    REQ(isfinite(p->calc_rate_hz) && p->calc_rate_hz > 0 && p->calc_rate_hz <= 1e6,
        "calc_rate_hz must be in (0, 1e6]");
    REQ(p->n_sensors >= 1 && p->n_sensors <= AMFI_MAX_SENSORS, "n_sensors must be 1..%d",
        AMFI_MAX_SENSORS);
    for (int i = 0; i < p->n_sensors; i++) {
        REQ(isfinite(p->sensor_x_m[i]) && p->sensor_x_m[i] >= 0 && p->sensor_x_m[i] <= L,
            "sensor %d at %g m is off the span [0, %g]", i, p->sensor_x_m[i], L);
        REQ(isfinite(p->sensor_weight[i]) && p->sensor_weight[i] > 0,
            "sensor %d weight must be > 0", i);
    }
    REQ(p->max_axles >= 1 && p->max_axles <= AMFI_MAX_AXLES, "max_axles must be 1..%d",
        AMFI_MAX_AXLES);
    REQ(isfinite(p->max_duration_s) && p->max_duration_s > 0 && p->max_duration_s <= 600,
        "max_duration_s must be in (0, 600]");
    REQ(isfinite(p->pre_roll_s) && p->pre_roll_s >= 0 && p->pre_roll_s < 60,
        "pre_roll_s must be in [0, 60)");
    REQ(isfinite(p->post_roll_s) && p->post_roll_s >= 0 && p->post_roll_s < 60,
        "post_roll_s must be in [0, 60)");
    REQ(!(p->free_initial_state && p->fix_initial_force),
        "a free initial bridge state needs a free initial force");
    REQ(!p->free_initial_state || p->coords == AMFI_COORDS_MODAL,
        "a free initial bridge state is solved in modal coordinates only");
    REQ(!p->fix_initial_force || p->pre_roll_s > 0,
        "a zero initial force needs a pre-roll (pre_roll_s > 0)");
#undef REQ
    return AMFI_OK;
}

/* Size the per-passage buffers for cap steps. */
/* The per-step buffers for cap steps and na_max axles; the gain array
 * apart (gain_reserve: it scales with steps × axles × state, the product a
 * sweep needs, not the largest steps times the largest axles seen). */
static int reserve(struct amfi_solver *s, int cap)
{
    const int na = s->na_max, ns = s->ns;
    double *d = realloc(s->d, sizeof(double) * (size_t)(cap + 1) * ns);
    if (d)
        s->d = d;
    double *f = realloc(s->force, sizeof(double) * (size_t)(cap + 1) * na);
    if (f)
        s->force = f;
    double *y = realloc(s->y, sizeof(double) * (size_t)cap * ns);
    if (y)
        s->y = y;
    double *go = realloc(s->gofs, sizeof(double) * (size_t)cap * na);
    if (go)
        s->gofs = go;
    if (!d || !f || !y || !go)
        return AMFI_ENOMEM;
    s->bytes += sizeof(double) * (size_t)(cap - s->cap) * (2 * ns + na + (size_t)na);
    s->cap = cap;
    return AMFI_OK;
}

size_t amfi_gain_doubles(const struct amfi_solver *s, int N, int na)
{
    if (s->p.coords == AMFI_COORDS_MODAL) {
        int seg;
        return amfi_sweep_modal_gain_doubles(s->m, na, N, s->sweep_budget, &seg);
    }
    const size_t state = (size_t)(s->p.coords == AMFI_COORDS_MODAL ? 2 * s->m : 4 * s->n) + na;
    return (size_t)N * na * state;
}

/* The gain array for a sweep of N steps and na axles (packed by the
 * sweep's own na and state size): grown only when larger than every one
 * before. */
static int gain_reserve(struct amfi_solver *s, int N, int na)
{
    const size_t len = amfi_gain_doubles(s, N, na);
    if (len <= s->gain_len)
        return AMFI_OK;
    double *g = realloc(s->gain, sizeof(double) * len);
    if (!g)
        return AMFI_ENOMEM;
    s->gain = g;
    s->bytes += sizeof(double) * (len - s->gain_len);
    s->gain_len = len;
    return AMFI_OK;
}

static int setup_modal(struct amfi_solver *s, char *err, size_t errlen)
{
    const amfi_bridge *b = s->b;
    const int n = s->n, ns = s->ns;
    double *call = malloc(sizeof(double) * ns * n); /* ψ_k(x_s), all modes */
    int *keep = malloc(sizeof(int) * n);
    if (!call || !keep) {
        free(call);
        free(keep);
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    }
    double cmax = 0.0;
    for (int si = 0; si < ns; si++)
        for (int k = 0; k < n; k++) {
            double v = 0.0;
            for (int i = 0; i < n; i++)
                v += s->S[si * n + i] * b->Psi[i * n + k];
            call[si * n + k] = v;
            if (fabs(v) > cmax)
                cmax = fabs(v);
        }
    int m = 0;
    for (int k = 0; k < n; k++) {
        int obs = 0;
        for (int si = 0; si < ns; si++)
            if (fabs(call[si * n + k]) > 1e-9 * cmax)
                obs = 1;
        /* resolved: below the Nyquist frequency of the calculation rate */
        if (s->p.modes == AMFI_MODES_RESOLVED && b->omega[k] >= 3.14159265358979323846 * s->p.calc_rate_hz)
            obs = 0;
        if (s->p.modes == AMFI_MODES_ALL || obs)
            keep[m++] = k;
    }
    if (s->p.modes == AMFI_MODES_COUNT && s->p.n_modes < m)
        m = s->p.n_modes;
    s->m = m;
    s->mode = malloc(sizeof(int) * m);
    s->Phi = malloc(sizeof(double) * 4 * m);
    s->Gm = malloc(sizeof(double) * 2 * m);
    s->c = malloc(sizeof(double) * ns * m);
    s->Cx = malloc(sizeof(double) * ns * 2 * m);
    s->Hxx = calloc((size_t)4 * m * m, sizeof(double));
    s->pe = calloc((size_t)b->p.n_elements * 4 * m, sizeof(double));
    if (!s->mode || !s->Phi || !s->Gm || !s->c || !s->Cx || !s->Hxx || !s->pe) {
        free(call);
        free(keep);
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    }
    const double h = s->h;
    for (int q = 0; q < m; q++) {
        int k = keep[q];
        s->mode[q] = k;
        amfi_modal_block(b->omega[k], b->zeta[k], h, s->Phi + 4 * q, s->Gm + 2 * q);
        for (int si = 0; si < ns; si++) {
            double ck = call[si * n + k];
            s->c[si * m + q] = ck;
            /* paper: y_{j+1} = ψ(x_s)·(q'_{j+1} − q'_j)/h, velocity row of (Φ − I)/h */
            s->Cx[si * 2 * m + 2 * q] = ck * s->Phi[4 * q + 2] / h;
            s->Cx[si * 2 * m + 2 * q + 1] = ck * (s->Phi[4 * q + 3] - 1.0) / h;
        }
        for (int e = 0; e < b->p.n_elements; e++)
            for (int i = 0; i < 4; i++) {
                int dof = b->free_of[2 * e + i];
                s->pe[((size_t)e * 4 + i) * m + q] = dof >= 0 ? b->Psi[dof * n + k] : 0.0;
            }
    }
    const int m2 = 2 * m;
    for (int si = 0; si < ns; si++)
        for (int i = 0; i < m2; i++)
            for (int j = 0; j < m2; j++)
                s->Hxx[i * m2 + j] += s->w[si] * s->Cx[si * m2 + i] * s->Cx[si * m2 + j];
    s->bytes += sizeof(double) * ((size_t)7 * m + 3 * ns * m + 4 * (size_t)m * m +
                                  (size_t)b->p.n_elements * 4 * m);
    free(call);
    free(keep);
    return AMFI_OK;
}

int amfi_solver_create(const amfi_bridge *b, const amfi_solver_params *p, amfi_solver **out,
                       char *err, size_t errlen)
{
    if (!b || !p || !out)
        return amfi_fail(err, errlen, AMFI_EINVAL, "solver: NULL argument");
    int rc = check_params(b, p, err, errlen);
    if (rc)
        return rc;
    struct amfi_solver *s = calloc(1, sizeof *s);
    if (!s)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
    s->b = b;
    s->p = *p;
    s->h = 1.0 / p->calc_rate_hz;
    s->n = b->n;
    s->ns = p->n_sensors;
    s->na_max = p->max_axles;
    s->sweep_budget = AMFI_MULTI_SEGMENT_BYTES / sizeof(double);
    for (int i = 0; i < s->ns; i++)
        s->w[i] = p->sensor_weight[i];
    s->S = malloc(sizeof(double) * s->ns * s->n);
    if (!s->S) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }
    for (int i = 0; i < s->ns; i++)
        amfi_bridge_shape(b, p->sensor_x_m[i], s->S + (size_t)i * s->n);

    if (p->coords == AMFI_COORDS_MODAL) {
        if ((rc = setup_modal(s, err, errlen)) != 0)
            goto fail;
        s->gstride = 2 * s->m + s->na_max;
        /* + the full R_0 and a right-hand side for a free initial state */
        s->scratch_len = amfi_sweep_modal_scratch(s->m, s->na_max, s->ns) +
                         (size_t)(s->gstride + 1) * s->gstride;
    } else {
        const int n = s->n;
        s->m = n;
        s->PhiN = malloc(sizeof(double) * 4 * n * n);
        s->GN = malloc(sizeof(double) * 2 * n * n);
        if (!s->PhiN || !s->GN) {
            rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
            goto fail;
        }
        if ((rc = amfi_nodal_discretise(b, s->h, s->PhiN, s->GN)) != 0) {
            rc = amfi_fail(err, errlen, rc, "nodal discretisation failed");
            goto fail;
        }
        s->gstride = 4 * n + s->na_max;
        s->scratch_len = amfi_sweep_nodal_scratch(n, s->na_max, s->ns);
        s->bytes += sizeof(double) * 6 * (size_t)n * n;
    }
    s->scratch = malloc(sizeof(double) * s->scratch_len);
    if (!s->scratch) {
        rc = amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory");
        goto fail;
    }
    s->bytes += sizeof(double) * s->scratch_len + sizeof *s;
    int cap = (int)ceil((p->max_duration_s + p->pre_roll_s + p->post_roll_s) * p->calc_rate_hz) + 1;
    if ((rc = reserve(s, cap)) != 0 || (rc = gain_reserve(s, cap, s->na_max)) != 0) {
        rc = amfi_fail(err, errlen, rc, "out of memory for %d steps", cap);
        goto fail;
    }
    /* the L-curve's points for the default search (a longer one grows them) */
    amfi_lambda deflam;
    amfi_lambda_default(&deflam);
    if ((rc = amfi_lcurve_reserve(s, &deflam)) != 0) {
        rc = amfi_fail(err, errlen, rc, "out of memory");
        goto fail;
    }
    *out = s;
    return AMFI_OK;
fail:
    amfi_solver_destroy(s);
    return rc;
}

amfi_passage_times amfi_passage_window(double span_m, double speed_mps, int n_axles,
                                       const double *axle_spacing_m, double pre_roll_s,
                                       double post_roll_s)
{
    double total = 0.0;
    for (int a = 0; a + 1 < n_axles; a++)
        total += axle_spacing_m[a];
    amfi_passage_times w;
    w.start_s = 0.0 - pre_roll_s;
    w.on_span_s = (span_m + total) / speed_mps;
    w.end_s = w.on_span_s + post_roll_s;
    return w;
}

/* Linear interpolation of the scan-rate samples to the calculation steps
 * (paper §3.3). */
static void resample(struct amfi_solver *s, const amfi_passage *ps)
{
    const int ns = s->ns;
    for (int j = 0; j <= s->N; j++) {
        double u = (s->t0 + j * s->h - ps->t_first_s) * ps->scan_rate_hz;
        int k = (int)floor(u);
        if (k < 0)
            k = 0;
        if (k > ps->n_samples - 2)
            k = ps->n_samples - 2;
        double f = u - k;
        if (f < 0)
            f = 0;
        if (f > 1)
            f = 1;
        for (int si = 0; si < ns; si++)
            s->d[(size_t)j * ns + si] = (1 - f) * ps->accel[si][k] + f * ps->accel[si][k + 1];
    }
}

int amfi_check_samples_lambda(const struct amfi_solver *s, const amfi_passage *ps,
                              const amfi_lambda *lam, char *err, size_t errlen)
{
#define REQ(cond, st, ...)                                                \
    do {                                                                  \
        if (!(cond))                                                      \
            return amfi_fail(err, errlen, st, __VA_ARGS__);               \
    } while (0)
    REQ(ps->n_samples >= 2, AMFI_EINVAL, "need at least 2 samples");
    REQ(isfinite(ps->scan_rate_hz) && ps->scan_rate_hz > 0, AMFI_EINVAL,
        "scan rate must be > 0");
    REQ(isfinite(ps->t_first_s), AMFI_EINVAL, "t_first_s is not finite");
    for (int si = 0; si < s->ns; si++)
        REQ(ps->accel[si], AMFI_EINVAL, "sensor %d has no samples", si);
    if (lam->automatic) {
        REQ(isfinite(lam->lcurve_lo) && isfinite(lam->lcurve_hi) && lam->lcurve_lo > 0 &&
                lam->lcurve_hi > lam->lcurve_lo,
            AMFI_EINVAL, "L-curve range must satisfy 0 < lo < hi");
        REQ(lam->lcurve_per_decade >= 1 && lam->lcurve_per_decade <= 100 &&
                lam->lcurve_refine_points >= 0 && lam->lcurve_refine_points <= 100,
            AMFI_EINVAL, "L-curve: per_decade 1..100, refine 0..100");
    } else {
        REQ(isfinite(lam->lambda_ref) && lam->lambda_ref > 0, AMFI_EINVAL,
            "lambda must be > 0");
    }
    REQ(isfinite(lam->ref_rate_hz) && lam->ref_rate_hz > 0, AMFI_EINVAL,
        "lambda reference rate must be > 0");

#undef REQ
    return AMFI_OK;
}

int amfi_solver_grow_axles(struct amfi_solver *s, int na)
{
    if (na <= s->na_max)
        return AMFI_OK;
    if (na > AMFI_MAX_EVENT_AXLES)
        return AMFI_EINVAL;
    const int old_stride = s->gstride, old_na = s->na_max;
    const size_t old_len = s->scratch_len;
    if (s->p.coords == AMFI_COORDS_MODAL) {
        s->gstride = 2 * s->m + na;
        s->scratch_len = amfi_sweep_modal_scratch(s->m, na, s->ns) +
                         (size_t)(s->gstride + 1) * s->gstride;
    } else {
        s->gstride = 4 * s->n + na;
        s->scratch_len = amfi_sweep_nodal_scratch(s->n, na, s->ns);
    }
    double *sc = realloc(s->scratch, sizeof(double) * s->scratch_len);
    if (!sc) {
        s->gstride = old_stride;
        s->scratch_len = old_len;
        return AMFI_ENOMEM;
    }
    s->scratch = sc;
    s->bytes += sizeof(double) * (s->scratch_len - old_len);
    /* the per-step buffers at the same step capacity, for na axles */
    const int cap = s->cap;
    s->bytes -= sizeof(double) * (size_t)cap * (2 * (size_t)s->ns + 2 * (size_t)old_na);
    s->cap = 0;
    s->na_max = na;
    return reserve(s, cap);
}

int amfi_solve_window(struct amfi_solver *s, const amfi_passage *ps, int na, double t_start,
                      double t_end, char *err, size_t errlen)
{
    int N = (int)ceil((t_end - t_start) * s->p.calc_rate_hz - 1e-6);
    if (N < 2)
        N = 2;
    if ((N > s->cap && reserve(s, N) != 0) || gain_reserve(s, N, na) != 0)
        return amfi_fail(err, errlen, AMFI_ENOMEM, "out of memory for %d steps", N);
    s->N = N;
    s->na = na;
    s->t0 = t_start;
    resample(s, ps);
    s->lc_n = 0;
    return AMFI_OK;
}

int amfi_solve_begin(struct amfi_solver *s, const amfi_passage *ps, const amfi_lambda *lam,
                     double window_speed, char *err, size_t errlen)
{
    if (!s || !ps || !lam)
        return amfi_fail(err, errlen, AMFI_EINVAL, "solve: NULL argument");
    const double L = s->b->p.span_m;
#define REQ(cond, st, ...)                                                \
    do {                                                                  \
        if (!(cond))                                                      \
            return amfi_fail(err, errlen, st, __VA_ARGS__);               \
    } while (0)
    REQ(isfinite(ps->speed_mps) && ps->speed_mps > 0, AMFI_EINVAL, "speed must be > 0");
    REQ(ps->n_axles >= 1 && ps->n_axles <= s->na_max, AMFI_EINVAL,
        "%d axles: the solver was sized for 1..%d", ps->n_axles, s->na_max);
    for (int a = 0; a + 1 < ps->n_axles; a++)
        REQ(isfinite(ps->axle_spacing_m[a]) && ps->axle_spacing_m[a] > 0, AMFI_EINVAL,
            "axle spacing %d must be > 0", a + 1);
    int rc = amfi_check_samples_lambda(s, ps, lam, err, errlen);
    if (rc)
        return rc;
    /* Window: entry − pre_roll .. last axle's exit + post_roll. */
    if (!(isfinite(window_speed) && window_speed > 0))
        window_speed = ps->speed_mps;
    const amfi_passage_times win = amfi_passage_window(
        L, window_speed, ps->n_axles, ps->axle_spacing_m, s->p.pre_roll_s, s->p.post_roll_s);
    const double t_start = win.start_s, t_end = win.end_s;
    const double t_last = ps->t_first_s + (ps->n_samples - 1) / ps->scan_rate_hz;
    const double tol = 1e-9 + 1e-6 / ps->scan_rate_hz;
    REQ(ps->t_first_s <= t_start + tol && t_last >= t_end - tol, AMFI_ERANGE,
        "the data spans [%.6g, %.6g] s but the window needs [%.6g, %.6g] s", ps->t_first_s,
        t_last, t_start, t_end);
#undef REQ
    s->sweep_budget = AMFI_MULTI_SEGMENT_BYTES / sizeof(double);
    s->speed = ps->speed_mps;
    s->off[0] = 0.0;
    for (int a = 1; a < ps->n_axles; a++)
        s->off[a] = s->off[a - 1] + ps->axle_spacing_m[a - 1];
    for (int a = 0; a < ps->n_axles; a++)
        s->vf[a] = 1.0;
    return amfi_solve_window(s, ps, ps->n_axles, t_start, t_end, err, errlen);
}

int amfi_solve_lambda(struct amfi_solver *s, const amfi_lambda *lam, double *lam_h,
                      int *n_solves, char *err, size_t errlen)
{
    const double scale = amfi_lambda_scale(s, lam);
    *lam_h = lam->lambda_ref * scale;
    if (lam->automatic) {
        int rc = amfi_lcurve(s, lam, scale, lam_h, n_solves);
        if (rc)
            return amfi_fail(err, errlen, rc, "L-curve search failed: %s", amfi_strerror(rc));
    }
    return AMFI_OK;
}

double amfi_axle_mean_force(const struct amfi_solver *s, int a)
{
    const double L = s->b->p.span_m;
    double sum = 0.0;
    int cnt = 0;
    for (int j = 0; j <= s->N; j++) {
        const double x = axle_x(s, a, j);
        if (x >= 0.0 && x <= L) {
            sum += s->force[(size_t)j * s->na + a];
            cnt++;
        }
    }
    return cnt ? sum / cnt : NAN;
}

int amfi_solve_end(struct amfi_solver *s, const amfi_lambda *lam, double lam_h, int n_solves,
                   amfi_result *res, char *err, size_t errlen)
{
    const int N = s->N;
    const double scale = amfi_lambda_scale(s, lam);
    double rn, sn;
    int rc = amfi_sweep(s, lam_h, &rn, &sn);
    n_solves++;
    if (rc)
        return amfi_fail(err, errlen, rc, "sweep failed: %s", amfi_strerror(rc));

    memset(res, 0, sizeof *res);
    res->lambda_h = lam_h;
    res->lambda_ref = lam_h / scale;
    res->h_s = s->h;
    res->n_steps = N;
    res->t0_s = s->t0;
    res->n_axles = s->na;
    res->force_N = s->force;
    res->model_accel = s->y;
    res->residual_norm = rn;
    res->smoothing_norm = sn;
    res->residual_rms = rn / sqrt((double)N * s->ns);
    double sig = 0.0;
    for (int j = 1; j <= N; j++)
        for (int si = 0; si < s->ns; si++)
            sig += s->d[(size_t)j * s->ns + si] * s->d[(size_t)j * s->ns + si];
    res->signal_rms = sqrt(sig / ((double)N * s->ns));
    res->n_modes = s->m;
    res->n_solves = n_solves;
    /* GVW = Σ_a mean of g_a while axle a is on the span, / g (paper §3.2). */
    res->gvw_kg = 0.0;
    for (int a = 0; a < s->na; a++) {
        res->mean_force_N[a] = amfi_axle_mean_force(s, a);
        res->axle_kg[a] = res->mean_force_N[a] / AMFI_GRAVITY;
        res->gvw_kg += res->axle_kg[a];
    }
    res->lcurve_n = s->lc_n;
    res->lcurve_lambda_ref = s->lc_lam;
    res->lcurve_residual = s->lc_res;
    res->lcurve_smoothing = s->lc_smo;
    res->lcurve_curvature = s->lc_kap;
    if (!isfinite(res->gvw_kg))
        return amfi_fail(err, errlen, AMFI_ENUM, "the solution is not finite");
    return AMFI_OK;
}

int amfi_solve(amfi_solver *s, const amfi_passage *ps, const amfi_lambda *lam,
               amfi_result *res, char *err, size_t errlen)
{
    if (!res)
        return amfi_fail(err, errlen, AMFI_EINVAL, "solve: NULL argument");
    int rc = amfi_solve_begin(s, ps, lam, ps ? ps->speed_mps : 0.0, err, errlen);
    if (rc)
        return rc;
    double lam_h;
    int n_solves = 0;
    if ((rc = amfi_solve_lambda(s, lam, &lam_h, &n_solves, err, errlen)) != 0)
        return rc;
    return amfi_solve_end(s, lam, lam_h, n_solves, res, err, errlen);
}
