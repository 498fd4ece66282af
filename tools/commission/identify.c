/* SPDX-License-Identifier: GPL-3.0-or-later */
/* identify.c: the three stages of commissioning (commission.h). */
#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "commission.h"

const char *const cm_param_names[CM_N_PARAMS] = {
    "stiffness-to-mass ratio", "mass (common) scale", "bearing rotational stiffness",
    "sensor offset", "detector clock offset", "detector speed scale",
    "segment 1 stiffness", "segment 2 stiffness", "segment 3 stiffness", "segment 4 stiffness",
    "segment 5 stiffness", "segment 6 stiffness", "segment 7 stiffness", "segment 8 stiffness",
    "segment 9 stiffness", "segment 10 stiffness", "segment 11 stiffness",
    "segment 12 stiffness", "segment 13 stiffness", "segment 14 stiffness",
    "segment 15 stiffness", "segment 16 stiffness"};

/* finite-difference steps of the Jacobian, in the parameters' own units.
 * The cost is smooth at these scales (the solve interpolates the samples
 * to any entry time; the window's length changes by one calculation step
 * per 1e-4 of speed): the steps must be small against the width of the
 * valley around the truth, about 1 ms of clock and 0.1 % of speed on a
 * 20 m span, or the forward differences' bias (step × curvature / 2) moves
 * the point where the search stops. The former steps (1.5 ms, 0.2 %) left
 * the mass 4.5 % and the speed scale 2.2 % off on noise-free runs whose
 * cost at the truth was 7 times lower than at the point found. */
static const double fd_step_base[CM_P_SEG] = {0.001, 0.001, 0.02, 0.01, 0.0001, 0.0002};
/* a segment's log E·I: as the common stiffness's */
static double fd_step(int k) { return k < CM_P_SEG ? fd_step_base[k] : 0.001; }

/* the scans' calculation rate and runs (they only find the valley) */
#define SCAN_RATE_HZ 1000.0
#define SCAN_RUNS 6

/* The residuals' weights. A run's GVW error and its axles' carry the
 * calibration truck's own dynamics (its mean axle forces on the span differ
 * from the weighed static loads by a percent or more, by speed, in a way no
 * bridge model removes); the residual over the free vibration carries only
 * the model: on six runs of the two-axle half-car and the five-axle A23
 * (E +10 %, 10 ms late) the truth's axle terms cost more than a wrong
 * model's (stiffness x1.123, mass x1.021, speed x1.010: traffic 1.6 %
 * heavy) while its free-vibration residual was 50 times lower. The weights
 * are the inverse of each term's scatter at the truth (GVW about 1 %, axles
 * about 2.5 %, free vibration about 0.1 % of the signal). */
#define W_GVW 1.0
#define W_AXLE 0.2
#define W_FREE 10.0

/* iterations of the search from the scans' point: on 20 noise-free runs it
 * is within 0.3 % of the truth's stiffness and mass after about 5; each
 * costs one evaluation per fitted parameter and one more */
#define MAX_ITER 10

/* The search stops when a trial step lies within the finite-difference
 * steps of the accepted point in every parameter (the point stays the
 * accepted one): the forward differences cannot resolve a better point
 * there, and the steps that follow are as small (on the combination case,
 * with the search let run on, the next accepted step moved the sensor by
 * 1 mm and the rest by less than their difference steps).
 * GSL's trust region would go on trying up to 15 ever shorter steps (each
 * an evaluation of every searched run at the site's rate) before it reports
 * no progress: on the combination case 10 rejected trials after the point
 * had stopped moving (stiffness, mass, κ, sensor, clock and speed the same
 * to 4 digits from evaluation 37 to 53), about 10 % of the CPU time. A
 * count of rejections alone is no such test: the first trials after a
 * rejection are often the same step (the trust region still contains it),
 * and 4 of them in a row came while the search was still moving. */

/* κ below this is a pin (log κ is held there) */
#define KAPPA_PIN 1e-3

void cm_options_default(cm_options *o)
{
    memset(o, 0, sizeof *o);
    for (int i = 0; i < CM_P_SEG; i++)
        o->fit[i] = 1;
    o->tail_s = 1.0;
    o->search_rate_hz = 0; /* the site's calc_rate_hz */
    o->max_search_runs = 8;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* the process's CPU time (the stages' figures in the report) */
static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* supports whose rotation is free (the bearings whose stiffness is fitted) */
static int rotatable(const amfi_support *s) { return !s->restrain_theta; }

static double design_EI(const amfi_site_config *d) { return d->bridge.E_pa * d->bridge.I_m4; }

int cm_site_apply(const amfi_site_config *design, const double *p, amfi_site_config *out,
                  char *err, size_t errlen)
{
    *out = *design;
    amfi_bridge_params *b = &out->bridge;
    const double sE = exp(p[CM_P_EI] + p[CM_P_MASS]), sM = exp(p[CM_P_MASS]);
    b->E_pa *= sE;
    b->density_kgm3 *= sM;
    for (int i = 0; i < b->n_segments; i++) {
        b->segments[i].EI_nm2 *= sE * exp(p[CM_P_SEG + i]);
        b->segments[i].mass_kgpm *= sM;
    }
    /* κ relative to the beam's own (updated) E·I: then every frequency
     * goes as √r at a fixed κ, and the scan below can meet f1 exactly */
    const double kappa = exp(p[CM_P_KAPPA]) > KAPPA_PIN ? exp(p[CM_P_KAPPA]) : 0.0;
    for (int i = 0; i < b->n_supports; i++)
        if (rotatable(&b->supports[i]))
            b->supports[i].k_theta_nmprad = kappa * sE * design_EI(design) / b->span_m;
    for (int s = 0; s < out->solver.n_sensors; s++) {
        double x = design->solver.sensor_x_m[s] + p[CM_P_SENSOR];
        if (!(x >= 0 && x <= b->span_m)) {
            snprintf(err, errlen, "sensor %d moved to %.3f m, off the span", out->sensor_id[s], x);
            return -1;
        }
        out->solver.sensor_x_m[s] = x;
    }
    return 0;
}

/* The residual over the run's free vibration, on a stretch of the file's
 * clock fixed by the detector's values alone: from after the last axle has
 * left under any plausible detector error (speed ±5 %, clock ±50 ms, then
 * 0.1 s for the higher modes) to the end of the shortest plausible window;
 * RMS there over the window's signal RMS. The whole window's residual is no
 * measure of the model: while the model has axles on the span its forces
 * absorb what it gets wrong, so a model that believes the trucks slower
 * (the speed scale 2-3 % high) keeps them on the span longer and fits
 * better there (measured on noise-free runs: 0.0076 at speed x1.03 against
 * 0.0086 at the truth, at 1000 Hz). Over a stretch where every candidate
 * model has the span empty only the model's free vibration from the state
 * the forces left explains the data. NaN when the stretch is empty. */
static double free_residual(const cm_run *r, const amfi_result *res, double clock,
                            double tail_s, int ns, double span_m)
{
    const double on = amfi_passage_window(span_m, r->speed_ref_mps, r->n_axles, r->spacing_m, 0, 0)
                          .on_span_s;
    const double ta = r->entry_s + 1.05 * on + 0.05 + 0.1;
    const double tb = r->entry_s + 0.95 * on - 0.05 + tail_s;
    const double entry_file = r->entry_s - clock; /* the model's entry on the file's clock */
    /* At the data's samples, the model interpolated between its steps: data
     * interpolated to the model's steps instead average two noisy samples
     * where a step falls between them, and the residual of noisy data then
     * depended on the entry time's fraction of a sample (measured: 3 %
     * noise, the scans at 1000 Hz, cost 0.16 at clock offsets half a sample
     * off the samples against 0.31 on them, and a clock of +14.5 ms found
     * for 0). */
    double sum = 0;
    long cnt = 0;
    int k0 = (int)ceil((ta - r->t0_s) * r->rate_hz), k1 = (int)floor((tb - r->t0_s) * r->rate_hz);
    if (k0 < 0)
        k0 = 0;
    if (k1 > r->n_samples - 1)
        k1 = r->n_samples - 1;
    for (int k = k0; k <= k1; k++) {
        const double tf = r->t0_s + k / r->rate_hz;
        /* model step j at entry_file + t0_s + j·h, y_j for j = 1 .. n_steps */
        const double u = (tf - entry_file - res->t0_s) / res->h_s;
        const int j = (int)floor(u);
        if (j < 1 || j + 1 > res->n_steps)
            continue;
        const double f = u - j;
        for (int si = 0; si < ns; si++) {
            const double m = (1 - f) * res->model_accel[(size_t)(j - 1) * (size_t)ns + (size_t)si] +
                             f * res->model_accel[(size_t)j * (size_t)ns + (size_t)si];
            const double e = m - r->accel[si][k];
            sum += e * e;
            cnt++;
        }
    }
    if (cnt == 0 || !(res->signal_rms > 0))
        return NAN;
    return sqrt(sum / (double)cnt) / res->signal_rms;
}

/* one model on the runs marked in use (NULL: all) */
int cm_evaluate(const amfi_site_config *site, const double *p, const cm_runs *runs,
                const cm_options *o, double calc_rate_hz, const int *use, cm_eval *ev,
                char *err, size_t errlen)
{
    memset(ev, 0, sizeof *ev);
    amfi_bridge *b = NULL;
    amfi_solver *s = NULL;
    if (amfi_bridge_create(&site->bridge, &b, err, errlen) != AMFI_OK)
        return -1;
    ev->f1_hz = amfi_bridge_omega(b)[0] / (2 * M_PI);
    amfi_solver_params sp = site->solver;
    sp.calc_rate_hz = calc_rate_hz;
    sp.post_roll_s = o->tail_s;
    if (o->resolved_modes &&
        (sp.modes == AMFI_MODES_OBSERVABLE || sp.modes == AMFI_MODES_ALL))
        sp.modes = AMFI_MODES_RESOLVED;
    sp.max_axles = AMFI_MAX_AXLES;
    if (amfi_solver_create(b, &sp, &s, err, errlen) != AMFI_OK) {
        amfi_bridge_destroy(b);
        return -1;
    }
    /* the detector as the site file says (the design's detector: section, a
     * commissioning's starting point), corrected by p */
    const double scale = site->detector.speed_scale * exp(p[CM_P_SPEED]),
                 clock = site->detector.clock_offset_s + p[CM_P_CLOCK];
    int n = 0, rc = 0;
    double sum_abs = 0, sum = 0, sum_res = 0;
    for (int i = 0; i < runs->n; i++) {
        if (use && !use[i])
            continue;
        const cm_run *r = &runs->run[i];
        amfi_passage ps;
        memset(&ps, 0, sizeof ps);
        ps.n_samples = r->n_samples;
        ps.scan_rate_hz = r->rate_hz;
        /* the run's own speed (speed_sd > 0), then the common scale */
        const double lv = runs->speed_estimated
                              ? r->speed_eps + (p[CM_P_CLOCK] - runs->clock_ref) * r->speed_gdev
                              : 0.0;
        ps.speed_mps = r->speed_mps * exp(-lv) / scale;
        ps.n_axles = r->n_axles;
        for (int a = 0; a + 1 < r->n_axles; a++)
            ps.axle_spacing_m[a] = r->spacing_m[a] / scale;
        ps.t_first_s = r->t0_s - (r->entry_s - clock);
        for (int k = 0; k < site->solver.n_sensors; k++)
            ps.accel[k] = r->accel[k];
        amfi_result res;
        char e2[256];
        if (amfi_solve(s, &ps, &site->lambda, &res, e2, sizeof e2) != AMFI_OK) {
            snprintf(err, errlen, "run %s (line %ld): %s", r->file, r->line, e2);
            rc = -1;
            break;
        }
        ev->gvw_err_pct[i] = 100.0 * (res.gvw_kg - r->gvw_kg) / r->gvw_kg;
        for (int a = 0; a < r->n_axles; a++)
            ev->axle_err_pct[i][a] = 100.0 * (res.axle_kg[a] - r->axle_kg[a]) / r->axle_kg[a];
        ev->resid_rel[i] = res.signal_rms > 0 ? res.residual_rms / res.signal_rms : NAN;
        ev->free_rel[i] = free_residual(r, &res, clock, o->tail_s, site->solver.n_sensors,
                                        site->bridge.span_m);
        sum_abs += fabs(ev->gvw_err_pct[i]);
        sum += ev->gvw_err_pct[i];
        sum_res += ev->resid_rel[i];
        if (n == 0 || fabs(ev->gvw_err_pct[i]) > fabs(ev->worst_gvw_pct))
            ev->worst_gvw_pct = ev->gvw_err_pct[i];
        n++;
    }
    if (n > 0) {
        ev->mean_abs_gvw_pct = sum_abs / n;
        ev->mean_gvw_pct = sum / n;
        ev->mean_resid_rel = sum_res / n;
    }
    amfi_solver_destroy(s);
    amfi_bridge_destroy(b);
    return rc;
}

/* ---- stage 1 ---------------------------------------------------------- */

int cm_modal_identify(const cm_runs *runs, const amfi_site_config *design,
                      const double *const *amb, const int *amb_n, const double *amb_rate,
                      int n_amb, cm_result *res, char *err, size_t errlen)
{
    amfi_bridge *b = NULL;
    if (amfi_bridge_create(&design->bridge, &b, err, errlen) != AMFI_OK)
        return -1;
    const double f_design = amfi_bridge_omega(b)[0] / (2 * M_PI);
    const double f2 = amfi_bridge_omega(b)[1] / (2 * M_PI);
    amfi_bridge_destroy(b);
    /* a real bridge's f1 within a factor of two of its drawings' (springs,
     * stiffness, mass), below the design's second mode */
    const double lo = 0.5 * f_design, hi = fmin(2.0 * f_design, 0.5 * (f_design + f2) * 1.3);
    double f[CM_MAX_RUNS + 64], z[CM_MAX_RUNS + 64];
    int m = 0;
    for (int i = 0; i < runs->n; i++) {
        const cm_run *r = &runs->run[i];
        amfi_passage_times w = amfi_passage_window(design->bridge.span_m, r->speed_mps,
                                                   r->n_axles, r->spacing_m, 0, 0);
        /* from 0.15 s after the last axle left (higher modes decayed) */
        double t_from = r->entry_s + w.on_span_s + 0.15;
        int k0 = (int)ceil((t_from - r->t0_s) * r->rate_hz);
        if (k0 < 0 || k0 >= r->n_samples)
            continue;
        /* every sensor's tail; the best-fitted one counts (a sensor near a
         * node of the first mode sees little of it) */
        cm_modal md, best = {0};
        for (int k = 0; k < design->solver.n_sensors; k++)
            if (cm_modal_fit(r->accel[k] + k0, r->n_samples - k0, r->rate_hz, lo, hi, &md) ==
                    0 &&
                md.fit_rel < 0.5 && (!best.ok || md.fit_rel < best.fit_rel))
                best = md, best.ok = 1;
        if (best.ok)
            f[m] = best.f_hz, z[m++] = best.zeta;
    }
    for (int i = 0; i < n_amb && m < CM_MAX_RUNS + 64; i++) {
        cm_modal md;
        if (cm_modal_fit(amb[i], amb_n[i], amb_rate[i], lo, hi, &md) == 0 && md.fit_rel < 0.8)
            f[m] = md.f_hz, z[m++] = md.zeta;
    }
    res->n_modal = m;
    if (m < 3) {
        snprintf(err, errlen,
                 "the free vibration gave the first natural frequency in %d record%s; at least "
                 "3 are needed (record at least %.1f s after each run, or give --ambient "
                 "records)",
                 m, m == 1 ? "" : "s", 4.0 / lo + 0.15);
        return -1;
    }
    gsl_sort(f, 1, (size_t)m);
    gsl_sort(z, 1, (size_t)m);
    res->f1_meas_hz = gsl_stats_median_from_sorted_data(f, 1, (size_t)m);
    res->zeta_meas = gsl_stats_median_from_sorted_data(z, 1, (size_t)m);
    /* the standard error of the median, from the spread (1.2533 σ/√m) */
    res->f1_meas_sd_hz = 1.2533 * gsl_stats_sd(f, 1, (size_t)m) / sqrt(m);
    res->zeta_meas_sd = 1.2533 * gsl_stats_sd(z, 1, (size_t)m) / sqrt(m);
    return 0;
}

/* ---- stage 2 ---------------------------------------------------------- */

typedef struct nls {
    const amfi_site_config *design;
    const cm_runs *runs;
    const cm_options *o;
    const int *use;
    int n_use;
    int idx[CM_N_PARAMS]; /* fitted parameter k is p[idx[k]] */
    int n_fit;
    double p0[CM_N_PARAMS]; /* held values */
    double f1, f1_sd;
    int match_f1; /* CM_P_EI follows the others so that f1 is met exactly */
    double rate_hz; /* calculation rate of the evaluations */
    int evaluations;
    char err[512];
    int failed;
    /* the residuals at the last point the driver asked for (not the
     * Jacobian's perturbed points): the trust-region driver asks for the
     * Jacobian at the point it has just evaluated, which the forward
     * differences need as their base; reusing it saves one evaluation of
     * every run per iteration */
    double x_last[CM_N_PARAMS];
    gsl_vector *f_last;
    int have_last, in_jacobian;
    /* the lowest cost (the accepted point's) and its point */
    double cost_best, x_best[CM_N_PARAMS];
    int stalled; /* a trial within the difference steps of it: the search stops */
} nls;

/* residuals: the f1 term, then per run the GVW, the axles and the fit */
static size_t n_resid(const nls *q, const cm_runs *runs)
{
    size_t m = 1;
    for (int i = 0; i < runs->n; i++)
        if (q->use[i])
            m += 2 + (size_t)runs->run[i].n_axles;
    return m;
}

static void unpack(const nls *q, const gsl_vector *x, double *p)
{
    memcpy(p, q->p0, sizeof q->p0);
    for (int k = 0; k < q->n_fit; k++)
        p[q->idx[k]] = gsl_vector_get(x, (size_t)k);
}

/* The stiffness-to-mass ratio that gives the measured f1 with the other
 * parameters in p (every frequency goes as √r: exact). f1 is measured to a
 * few hundredths of a percent, far tighter than anything else fixes r, so
 * r follows the bearings along that constraint instead of being a free
 * parameter strongly correlated with them. */
static int match_f1(const amfi_site_config *design, double f1_meas, double *p, char *err,
                    size_t errlen)
{
    amfi_site_config st;
    amfi_bridge *b = NULL;
    p[CM_P_EI] = 0;
    if (cm_site_apply(design, p, &st, err, errlen) != 0 ||
        amfi_bridge_create(&st.bridge, &b, err, errlen) != AMFI_OK)
        return -1;
    p[CM_P_EI] = 2 * log(f1_meas / (amfi_bridge_omega(b)[0] / (2 * M_PI)));
    amfi_bridge_destroy(b);
    return 0;
}

static int residuals(const gsl_vector *x, void *user, gsl_vector *f)
{
    nls *q = user;
    double p[CM_N_PARAMS];
    unpack(q, x, p);
    amfi_site_config site;
    cm_eval ev;
    q->evaluations++;
    if ((q->match_f1 && match_f1(q->design, q->f1, p, q->err, sizeof q->err) != 0) ||
        cm_site_apply(q->design, p, &site, q->err, sizeof q->err) != 0 ||
        cm_evaluate(&site, p, q->runs, q->o, q->rate_hz, q->use, &ev, q->err,
                    sizeof q->err) != 0) {
        /* a model that cannot be solved: a large residual steers the trust
         * region back */
        for (size_t i = 0; i < f->size; i++)
            gsl_vector_set(f, i, 1e3);
        q->failed = 1;
        return GSL_SUCCESS;
    }
    size_t m = 0;
    gsl_vector_set(f, m++, (ev.f1_hz - q->f1) / q->f1_sd);
    for (int i = 0; i < q->runs->n; i++) {
        if (!q->use[i])
            continue;
        const cm_run *r = &q->runs->run[i];
        gsl_vector_set(f, m++, W_GVW * ev.gvw_err_pct[i] / 100.0);
        for (int a = 0; a < r->n_axles; a++)
            gsl_vector_set(f, m++,
                           W_AXLE * ev.axle_err_pct[i][a] / 100.0 * r->axle_kg[a] / r->gvw_kg);
        gsl_vector_set(f, m++,
                       W_FREE * (isfinite(ev.free_rel[i]) ? ev.free_rel[i] : ev.resid_rel[i]));
    }
    if (q->o->verbose)
        fprintf(stderr, "amfi-commission: eval %d: EI x%.4f mass x%.4f kappa %.3f sensor %+.3f m "
                        "clock %+.4f s speed x%.4f: f1 %.4f Hz, GVW mean |err| %.2f %%, fit %.4f\n",
                q->evaluations, exp(p[CM_P_EI] + p[CM_P_MASS]), exp(p[CM_P_MASS]),
                exp(p[CM_P_KAPPA]), p[CM_P_SENSOR], p[CM_P_CLOCK],
                exp(p[CM_P_SPEED]), ev.f1_hz, ev.mean_abs_gvw_pct, ev.mean_resid_rel);
    if (q->o->verbose && q->o->n_segments > 0) {
        fprintf(stderr, "amfi-commission:   segments' E.I x");
        for (int i = 0; i < q->o->n_segments; i++)
            fprintf(stderr, " %.4f", exp(p[CM_P_EI] + p[CM_P_MASS] + p[CM_P_SEG + i]));
        fprintf(stderr, "\n");
    }
    if (!q->in_jacobian && q->f_last && q->f_last->size == f->size) {
        for (int k = 0; k < q->n_fit; k++)
            q->x_last[k] = gsl_vector_get(x, (size_t)k);
        gsl_vector_memcpy(q->f_last, f);
        q->have_last = 1;
        double c;
        gsl_blas_ddot(f, f, &c);
        int k = 0;
        while (isfinite(q->cost_best) && k < q->n_fit &&
               fabs(q->x_last[k] - q->x_best[k]) <= fd_step(q->idx[k]))
            k++;
        if (isfinite(q->cost_best) && k == q->n_fit) {
            q->stalled = 1;
            return GSL_EBADFUNC; /* ends gsl_multifit_nlinear_iterate; x stays */
        }
        if (c < q->cost_best) {
            q->cost_best = c;
            memcpy(q->x_best, q->x_last, sizeof q->x_best);
        }
    }
    return GSL_SUCCESS;
}

/* 1 when x is the point of the residuals kept in q->f_last */
static int is_last(const nls *q, const gsl_vector *x)
{
    if (!q->have_last)
        return 0;
    for (int k = 0; k < q->n_fit; k++)
        if (q->x_last[k] != gsl_vector_get(x, (size_t)k))
            return 0;
    return 1;
}

/* forward differences with fixed steps per parameter */
static int jacobian(const gsl_vector *x, void *user, gsl_matrix *J)
{
    nls *q = user;
    const size_t m = J->size1;
    gsl_vector *f0 = gsl_vector_alloc(m), *f1 = gsl_vector_alloc(m), *xh = gsl_vector_alloc(x->size);
    if (!f0 || !f1 || !xh) {
        gsl_vector_free(f0);
        gsl_vector_free(f1);
        gsl_vector_free(xh);
        return GSL_ENOMEM;
    }
    if (is_last(q, x))
        gsl_vector_memcpy(f0, q->f_last);
    else
        residuals(x, user, f0);
    q->in_jacobian = 1;
    for (int k = 0; k < q->n_fit; k++) {
        gsl_vector_memcpy(xh, x);
        double h = fd_step(q->idx[k]);
        gsl_vector_set(xh, (size_t)k, gsl_vector_get(x, (size_t)k) + h);
        residuals(xh, user, f1);
        for (size_t i = 0; i < m; i++)
            gsl_matrix_set(J, i, (size_t)k, (gsl_vector_get(f1, i) - gsl_vector_get(f0, i)) / h);
    }
    q->in_jacobian = 0;
    gsl_vector_free(f0);
    gsl_vector_free(f1);
    gsl_vector_free(xh);
    return GSL_SUCCESS;
}

/* runs used while searching: up to max, spread over the speeds and the
 * trucks (every k-th run in speed order) */
static int pick_runs(const cm_runs *runs, int max, int *use)
{
    double sp[CM_MAX_RUNS];
    size_t order[CM_MAX_RUNS];
    for (int i = 0; i < runs->n; i++) {
        sp[i] = runs->run[i].speed_mps;
        use[i] = 0;
    }
    gsl_sort_index(order, sp, 1, (size_t)runs->n);
    int n = runs->n < max ? runs->n : max;
    for (int k = 0; k < n; k++)
        use[order[(size_t)((k + 0.5) * runs->n / n)]] = 1;
    return n;
}

/* The scans' cost at p (κ, sensor, clock and speed as given): f1 met
 * exactly, the common scale set from the loads (p's CM_P_EI and CM_P_MASS
 * written), then the free-vibration residuals and the spread of the GVW and
 * axle errors about their mean (what no common scale can remove). A model
 * that cannot be built or solved (a sensor off the span) costs +inf. */
static int scan_cost(nls *q, double *p, double *cost)
{
    amfi_site_config st;
    cm_eval ev;
    char e2[512];
    p[CM_P_MASS] = 0;
    if (match_f1(q->design, q->f1, p, e2, sizeof e2) != 0 ||
        cm_site_apply(q->design, p, &st, e2, sizeof e2) != 0) {
        *cost = INFINITY; /* e.g. the sensor moved off the span */
        return 0;
    }
    q->evaluations++;
    if (cm_evaluate(&st, p, q->runs, q->o, q->rate_hz, q->use, &ev, e2, sizeof e2) != 0) {
        *cost = INFINITY;
        return 0;
    }
    p[CM_P_MASS] = -log1p(ev.mean_gvw_pct / 100.0);
    double c = 0;
    for (int i = 0; i < q->runs->n; i++) {
        if (!q->use[i])
            continue;
        const cm_run *r = &q->runs->run[i];
        const double fr =
            W_FREE * (isfinite(ev.free_rel[i]) ? ev.free_rel[i] : ev.resid_rel[i]);
        const double dg = W_GVW * (ev.gvw_err_pct[i] - ev.mean_gvw_pct) / 100.0;
        c += fr * fr + dg * dg;
        for (int a = 0; a < r->n_axles; a++) {
            const double da = W_AXLE * (ev.axle_err_pct[i][a] - ev.mean_gvw_pct) / 100.0 *
                              r->axle_kg[a] / r->gvw_kg;
            c += da * da;
        }
    }
    *cost = isfinite(c) ? c : INFINITY;
    return 0;
}

/* p[k] over n points lo .. hi, the others as in p; p and *best move to the
 * best point when it is better than *best. (A refinement whose best point
 * is at its end was tried going on outward while the cost fell: on the
 * combination case it moved the sensor's start from 0.20 to 0.25 m, and the
 * search from there ended in another of the cost's shallow minima, sensor
 * 0.478 m for the truth's 0.5 against 0.516 from 0.20, the runs' GVW 0.69 %
 * mean abs against 0.50 and the traffic's mean -0.23 % against +0.03 %; not
 * kept.) */
static int scan_1d(nls *q, double *p, double *best, int k, double lo, double hi, int n,
                   int verbose)
{
    double bp[CM_N_PARAMS];
    memcpy(bp, p, sizeof bp);
    for (int g = 0; g < n; g++) {
        double pk[CM_N_PARAMS], c;
        memcpy(pk, p, sizeof pk);
        pk[k] = lo + (hi - lo) * g / (n - 1);
        if (scan_cost(q, pk, &c) != 0)
            return -1;
        if (verbose)
            fprintf(stderr, "amfi-commission: scan %s %s %.5g: cost %.5g\n", cm_param_names[k],
                    k == CM_P_SPEED ? "x" : "=", k == CM_P_SPEED ? exp(pk[k]) : pk[k], c);
        if (c < *best) {
            *best = c;
            memcpy(bp, pk, sizeof bp);
        }
    }
    memcpy(p, bp, sizeof bp);
    return 0;
}

static int run_nls(nls *q, double *p, double *sd, double cov_out[CM_N_PARAMS][CM_N_PARAMS],
                   double *corr_max, int *ci, int *cj, int *iterations, int max_iter, char *err,
                   size_t errlen)
{
    const size_t m = n_resid(q, q->runs), np = (size_t)q->n_fit;
    gsl_multifit_nlinear_fdf fdf = {.f = residuals, .df = jacobian, .fvv = NULL, .n = m,
                                    .p = np, .params = q};
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    fp.scale = gsl_multifit_nlinear_scale_more;
    gsl_multifit_nlinear_workspace *ws =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, m, np);
    gsl_vector *x = gsl_vector_alloc(np);
    gsl_matrix *cov = gsl_matrix_alloc(np, np);
    q->f_last = gsl_vector_alloc(m);
    q->have_last = q->in_jacobian = 0;
    if (!ws || !x || !cov || !q->f_last) {
        gsl_multifit_nlinear_free(ws);
        gsl_vector_free(x);
        gsl_matrix_free(cov);
        gsl_vector_free(q->f_last);
        q->f_last = NULL;
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < np; k++)
        gsl_vector_set(x, k, p[q->idx[k]]);
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    q->stalled = 0;
    q->cost_best = INFINITY;
    int info = 0, rc = gsl_multifit_nlinear_init(x, &fdf, ws);
    /* gsl_multifit_nlinear_driver's loop, with the stop on stalled trials:
     * ws->x and its Jacobian stay the last accepted point's */
    for (int it = 0; rc == GSL_SUCCESS && it < max_iter; it++) {
        rc = gsl_multifit_nlinear_iterate(ws);
        if (rc == GSL_EBADFUNC && q->stalled) {
            rc = GSL_SUCCESS;
            if (q->o->verbose)
                fprintf(stderr, "amfi-commission: a trial step within the difference steps "
                                "of the point: the search stops there\n");
            break;
        }
        if (rc != GSL_SUCCESS)
            break;
        if (gsl_multifit_nlinear_test(1e-3, 1e-8, 1e-8, &info, ws) == GSL_SUCCESS)
            break;
    }
    gsl_set_error_handler(old);
    int ret = 0;
    if (rc != GSL_SUCCESS && rc != GSL_EMAXITER && rc != GSL_ENOPROG) {
        snprintf(err, errlen, "the model update did not converge (%s)%s%s", gsl_strerror(rc),
                 q->failed ? ": " : "", q->failed ? q->err : "");
        ret = -1;
    } else {
        *iterations = (int)gsl_multifit_nlinear_niter(ws);
        unpack(q, ws->x, p);
        /* covariance (JᵀJ)⁻¹ scaled by the residual variance */
        gsl_matrix *Jm = gsl_multifit_nlinear_jac(ws);
        gsl_multifit_nlinear_covar(Jm, 1e-10, cov);
        double chi;
        gsl_blas_ddot(ws->f, ws->f, &chi);
        double s2 = m > np ? chi / (double)(m - np) : chi;
        *corr_max = 0;
        *ci = *cj = -1;
        for (int k = 0; k < CM_N_PARAMS; k++) {
            sd[k] = NAN;
            for (int l = 0; l < CM_N_PARAMS; l++)
                cov_out[k][l] = 0;
        }
        for (size_t k = 0; k < np; k++)
            for (size_t l = 0; l < np; l++)
                cov_out[q->idx[k]][q->idx[l]] = s2 * gsl_matrix_get(cov, k, l);
        for (size_t k = 0; k < np; k++) {
            sd[q->idx[k]] = sqrt(s2 * gsl_matrix_get(cov, k, k));
            for (size_t l = 0; l < k; l++) {
                double c = gsl_matrix_get(cov, k, l) /
                           sqrt(gsl_matrix_get(cov, k, k) * gsl_matrix_get(cov, l, l));
                if (fabs(c) > *corr_max) {
                    *corr_max = fabs(c);
                    *ci = q->idx[k];
                    *cj = q->idx[l];
                }
            }
        }
    }
    gsl_multifit_nlinear_free(ws);
    gsl_vector_free(x);
    gsl_matrix_free(cov);
    gsl_vector_free(q->f_last);
    q->f_last = NULL;
    q->have_last = 0;
    return ret;
}

/* ---- the runs' own speeds ---------------------------------------------- */

/* Each run's speed from its acceleration (speed_sd > 0): amfi_solve_speed,
 * libamfi's estimate for traffic (docs/solver.md, "Speed estimation"), on
 * the model `site` (the design with f1 met: on the design itself, 9 % too
 * soft with stiff bearings, the estimates of the combination case's runs
 * erred up to 10 %; with f1 met within 0.1 % but for 3 runs of 20), the
 * detector's speed the prior's centre with SD o->speed_sd, λ the site's,
 * the window as amfid weighs (no post-roll). The detector's entry time is
 * taken as given (clock offset 0): an entry δ late makes the estimate
 * match the exit instead, v (1 + δ v / L) (measured: +0.55 .. +1.05 % at
 * δ = 10 ms, 15-25 m/s), so each run keeps that slope and the search's
 * clock moves its speed along it (cm_run.speed_gdev).
 * Each run is then weighed at its estimate (moved along that slope by the
 * clock), and the detector's speed scale is no parameter of the scans and
 * the search: it is the mean of log(detector / estimate) over the runs,
 * which fixes it to SD/√n (refused beyond 1 %). Left as a parameter next
 * to the runs' own speeds, with the mean removed from them, it was fitted
 * from the weak rest of the cost (3 % noise, E +10 %: speed scale 0.980 and
 * clock −8 ms for 0.990 and 0, stiffness +4.4 %). A run whose estimate
 * lies at the end of the range searched is refused by name. */
static int estimate_run_speeds(const amfi_site_config *site, cm_runs *runs, const cm_options *o,
                               cm_result *res, char *err, size_t errlen)
{
    amfi_bridge *b = NULL;
    amfi_solver *s = NULL;
    if (amfi_bridge_create(&site->bridge, &b, err, errlen) != AMFI_OK)
        return -1;
    amfi_solver_params sp = site->solver;
    sp.post_roll_s = 0;
    sp.max_axles = AMFI_MAX_AXLES;
    if (amfi_solver_create(b, &sp, &s, err, errlen) != AMFI_OK) {
        amfi_bridge_destroy(b);
        return -1;
    }
    amfi_speed_prior pr = site->speed_prior;
    pr.rel_sd = o->speed_sd;
    if (pr.range_sd * pr.rel_sd >= 0.5)
        pr.range_sd = 0.45 / pr.rel_sd;
    if (pr.grid_rel > pr.range_sd * pr.rel_sd)
        pr.grid_rel = pr.range_sd * pr.rel_sd;
    int rc = 0;
    double y[CM_MAX_RUNS], g[CM_MAX_RUNS], ym = 0, gm = 0;
    for (int i = 0; i < runs->n && rc == 0; i++) {
        cm_run *r = &runs->run[i];
        amfi_passage ps;
        memset(&ps, 0, sizeof ps);
        ps.n_samples = r->n_samples;
        ps.scan_rate_hz = r->rate_hz;
        /* the detector as the design's detector: section corrects it */
        const double ds = site->detector.speed_scale;
        ps.speed_mps = r->speed_mps / ds;
        ps.n_axles = r->n_axles;
        double len = site->bridge.span_m;
        for (int a = 0; a + 1 < r->n_axles; a++) {
            ps.axle_spacing_m[a] = r->spacing_m[a] / ds;
            len += ps.axle_spacing_m[a];
        }
        ps.t_first_s = r->t0_s - (r->entry_s - site->detector.clock_offset_s);
        for (int k = 0; k < site->solver.n_sensors; k++)
            ps.accel[k] = r->accel[k];
        amfi_result ar;
        amfi_speed_result sr;
        char e2[256];
        if (amfi_speed_prior_check(&pr, ps.speed_mps, e2, sizeof e2) != 0 ||
            amfi_solve_speed(s, &ps, &site->lambda, &pr, &ar, &sr, e2, sizeof e2) != AMFI_OK) {
            snprintf(err, errlen, "run %s (line %ld): its speed: %s", r->file, r->line, e2);
            rc = -1;
            break;
        }
        if (sr.at_bound) {
            snprintf(err, errlen,
                     "run %s (line %ld): its speed cannot be told from the acceleration (the "
                     "estimate, %.2f m/s, lies at the end of the range searched, %.2f .. %.2f "
                     "m/s, for the detector's %.2f): a second vehicle on the bridge, a wrong "
                     "entry time, or a detector worse than --speed-sd %g says",
                     r->file, r->line, sr.speed_mps, sr.lo_mps, sr.hi_mps, r->speed_mps,
                     o->speed_sd);
            rc = -1;
            break;
        }
        r->speed_est_mps = sr.speed_mps;
        y[i] = log(ps.speed_mps / sr.speed_mps); /* relative to the design's detector */
        g[i] = sr.speed_mps / len;
        ym += y[i] / runs->n;
        gm += g[i] / runs->n;
        if (o->verbose)
            fprintf(stderr, "amfi-commission: run %s: speed %.3f m/s estimated, detector %.3f "
                            "(%+.2f %%)\n", r->file, sr.speed_mps, r->speed_mps,
                    100 * (r->speed_mps / sr.speed_mps - 1));
    }
    amfi_solver_destroy(s);
    amfi_bridge_destroy(b);
    if (rc != 0)
        return -1;
    /* each run at its estimate; the random part's SD over the runs */
    double ss = 0;
    for (int i = 0; i < runs->n; i++) {
        cm_run *r = &runs->run[i];
        r->speed_eps = y[i];
        r->speed_gdev = g[i];
        r->speed_ref_mps = r->speed_est_mps;
        ss += (y[i] - ym) * (y[i] - ym);
    }
    const double sd = runs->n > 1 ? sqrt(ss / (runs->n - 1)) : 0.0;
    res->run_speed_sd_pct = 100 * sd;
    runs->speed_ymean = ym;
    runs->speed_gmean = gm;
    if (o->fit[CM_P_SPEED] && sd / sqrt(runs->n) > 0.01) {
        snprintf(err, errlen,
                 "the runs' speeds scatter by %.1f %% (SD) about the detector's: %d runs fix its "
                 "speed scale only to +-%.1f %% (more than 1 %%): add runs, or hold speed if the "
                 "detector's scale is known",
                 100 * sd, runs->n, 100 * sd / sqrt(runs->n));
        return -1;
    }
    runs->speed_estimated = 1;
    runs->clock_ref = 0;
    res->speeds_estimated = 1;
    return 0;
}

/* ---- per-segment stiffness --------------------------------------------- */

/* The design cut into o->n_segments equal segments, each with the design's
 * E·I and mass per length there as its own (a design's segment must end on
 * their boundaries: one scale per segment cannot stretch over a change of
 * section), the segment holding the first sensor the reference and the
 * others' E·I fitted. Refused: the stiffness held, fewer than 2 runs per
 * fitted parameter. */
static int setup_segments(amfi_site_config *d, const cm_runs *runs, cm_options *o,
                          cm_result *res, char *err, size_t errlen)
{
    amfi_bridge_params *b = &d->bridge;
    const int n = o->n_segments;
    const double L = b->span_m, w = L / n;
    if (n < 2 || n > CM_MAX_FIT_SEGMENTS) {
        snprintf(err, errlen, "--segments %d: 2 .. %d segments", n, CM_MAX_FIT_SEGMENTS);
        return -1;
    }
    if (!o->fit[CM_P_EI]) {
        snprintf(err, errlen, "a per-segment stiffness fit with the stiffness held: drop "
                              "--hold stiffness or --segments");
        return -1;
    }
    for (int i = 0; i < b->n_segments; i++) {
        const amfi_segment *g = &b->segments[i];
        for (int e = 0; e < 2; e++) {
            const double x = e ? g->x1_m : g->x0_m, k = x / w;
            if (fabs(k - round(k)) > 1e-6) {
                snprintf(err, errlen,
                         "the design's segment %d (%g .. %g m) does not end on a boundary of "
                         "%d equal segments of %g m: one stiffness scale per segment cannot "
                         "span a change of section (choose --segments so that it does)",
                         i + 1, g->x0_m, g->x1_m, n, w);
                return -1;
            }
        }
    }
    /* an element belongs to the segment holding its mid-point */
    if (b->n_elements % n != 0) {
        snprintf(err, errlen, "%d elements do not divide into %d equal segments: choose "
                              "--segments dividing bridge.elements", b->n_elements, n);
        return -1;
    }
    amfi_segment sg[AMFI_MAX_SEGMENTS];
    for (int i = 0; i < n; i++) {
        const double xm = (i + 0.5) * w;
        sg[i] = (amfi_segment){.x0_m = i * w, .x1_m = i == n - 1 ? L : (i + 1) * w,
                               .EI_nm2 = amfi_bridge_params_EI(b, xm),
                               .mass_kgpm = amfi_bridge_params_mass(b, xm)};
        res->seg_x0_m[i] = sg[i].x0_m;
        res->seg_x1_m[i] = sg[i].x1_m;
    }
    memcpy(b->segments, sg, sizeof sg[0] * (size_t)n);
    b->n_segments = n;
    int ref = (int)floor(d->solver.sensor_x_m[0] / w);
    if (ref > n - 1)
        ref = n - 1;
    res->n_segments = n;
    res->seg_ref = ref;
    int n_fit = 0;
    for (int i = 0; i < n; i++)
        o->fit[CM_P_SEG + i] = i != ref;
    for (int k = 0; k < CM_N_PARAMS; k++) /* the ratio follows f1 */
        n_fit += k != CM_P_EI && o->fit[k];
    if (runs->n < 2 * n_fit) {
        snprintf(err, errlen,
                 "%d runs for %d fitted parameters (%d segments' stiffness less the "
                 "reference's, which f1 fixes; the mass, bearings, sensor, detector): a "
                 "per-segment fit needs at least %d runs (2 per parameter), or fewer segments",
                 runs->n, n_fit, n, 2 * n_fit);
        return -1;
    }
    return 0;
}

/* Each segment's stiffness as found and its uncertainty. log S_i = log r +
 * log c + t_i with log r following f1 (match_f1): its derivatives along
 * every parameter that moves f1 (the bearings, the segments) by
 * differences, then a_iᵀ C a_j + (2 σ_f1/f1)² over the fitted parameters'
 * covariance C. The correlations of the segments with one another and
 * with the other fitted parameters: the largest is kept, named. */
static int segment_results(const amfi_site_config *design, const nls *q, const double *p,
                           cm_result *res, char *err, size_t errlen)
{
    const int n = res->n_segments;
    double dg[CM_N_PARAMS] = {0};
    for (int k = 0; k < CM_N_PARAMS; k++) {
        if (!(k == CM_P_KAPPA || k >= CM_P_SEG))
            continue;
        int fitted = 0;
        for (int j = 0; j < q->n_fit; j++)
            fitted |= q->idx[j] == k;
        if (!fitted)
            continue;
        double pk[CM_N_PARAMS], p0[CM_N_PARAMS];
        memcpy(pk, p, sizeof pk);
        memcpy(p0, p, sizeof p0);
        pk[k] += fd_step(k);
        if (match_f1(design, q->f1, p0, err, errlen) != 0 ||
            match_f1(design, q->f1, pk, err, errlen) != 0)
            return -1;
        dg[k] = (pk[CM_P_EI] - p0[CM_P_EI]) / fd_step(k);
    }
    double a[AMFI_MAX_SEGMENTS][CM_N_PARAMS];
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < CM_N_PARAMS; k++)
            a[i][k] = dg[k];
        a[i][CM_P_MASS] += 1;
        if (i != res->seg_ref)
            a[i][CM_P_SEG + i] += 1;
    }
    const double sf = 2 * res->f1_meas_sd_hz / res->f1_meas_hz;
    double cs[AMFI_MAX_SEGMENTS][AMFI_MAX_SEGMENTS], ca[AMFI_MAX_SEGMENTS][CM_N_PARAMS];
    for (int i = 0; i < n; i++) {
        for (int l = 0; l < CM_N_PARAMS; l++) {
            ca[i][l] = 0;
            for (int k = 0; k < CM_N_PARAMS; k++)
                ca[i][l] += a[i][k] * res->cov[k][l];
        }
        for (int j = 0; j < n; j++) {
            cs[i][j] = sf * sf;
            for (int l = 0; l < CM_N_PARAMS; l++)
                cs[i][j] += ca[i][l] * a[j][l];
        }
    }
    res->seg_corr_max = 0;
    res->seg_corr_what[0] = 0;
    res->seg_trade_corr = 0;
    res->seg_trade_what[0] = 0;
    for (int i = 0; i < n; i++) {
        res->seg_scale[i] = exp(p[CM_P_EI] + p[CM_P_MASS] + p[CM_P_SEG + i]);
        res->seg_sd_rel[i] = sqrt(cs[i][i]);
        for (int j = 0; j < i; j++) {
            const double c = cs[i][j] / sqrt(cs[i][i] * cs[j][j]);
            if (c < res->seg_trade_corr) {
                res->seg_trade_corr = c;
                snprintf(res->seg_trade_what, sizeof res->seg_trade_what,
                         "segment %d's stiffness (%g .. %g m) from segment %d's (%g .. %g m)",
                         i + 1, res->seg_x0_m[i], res->seg_x1_m[i], j + 1, res->seg_x0_m[j],
                         res->seg_x1_m[j]);
            }
            if (fabs(c) > res->seg_corr_max) {
                res->seg_corr_max = fabs(c);
                snprintf(res->seg_corr_what, sizeof res->seg_corr_what,
                         "segment %d's stiffness (%g .. %g m) from segment %d's (%g .. %g m)",
                         i + 1, res->seg_x0_m[i], res->seg_x1_m[i], j + 1, res->seg_x0_m[j],
                         res->seg_x1_m[j]);
            }
        }
        /* against the other fitted parameters (not the ones it is made of) */
        for (int k = CM_P_KAPPA; k < CM_P_SEG; k++) {
            if (!(res->cov[k][k] > 0))
                continue;
            const double c = ca[i][k] / sqrt(cs[i][i] * res->cov[k][k]);
            if (fabs(c) > res->seg_corr_max) {
                res->seg_corr_max = fabs(c);
                snprintf(res->seg_corr_what, sizeof res->seg_corr_what,
                         "segment %d's stiffness (%g .. %g m) from the %s", i + 1,
                         res->seg_x0_m[i], res->seg_x1_m[i], cm_param_names[k]);
            }
        }
    }
    return 0;
}

/* ---- stage 3 and the whole ------------------------------------------- */

/* GVW as amfid weighs (o_weigh: the site's post-roll), the fit with the
 * free vibration in the window (o: the tail), at the site's rate */
static int evaluate_both(const amfi_site_config *site, const double *p, const cm_runs *runs,
                         const cm_options *o, const cm_options *o_weigh, cm_eval *ev, char *err,
                         size_t errlen)
{
    cm_eval fit;
    if (cm_evaluate(site, p, runs, o_weigh, site->solver.calc_rate_hz, NULL, ev, err, errlen) !=
            0 ||
        cm_evaluate(site, p, runs, o, site->solver.calc_rate_hz, NULL, &fit, err, errlen) != 0)
        return -1;
    memcpy(ev->resid_rel, fit.resid_rel, sizeof fit.resid_rel);
    memcpy(ev->free_rel, fit.free_rel, sizeof fit.free_rel);
    ev->mean_resid_rel = fit.mean_resid_rel;
    return 0;
}

int cm_identify(const amfi_site_config *design0, cm_runs *runs,
                const double *const *amb, const int *amb_n, const double *amb_rate, int n_amb,
                const cm_options *o0, cm_result *res, char *err, size_t errlen)
{
    const double t_start = now_s();
    double c_mark = cpu_s();
    memset(res, 0, sizeof *res);
    cm_options o = *o0;
    /* The search at the rate amfid weighs at: the backward-difference
     * acceleration of a coarser model lags by about a calculation step, and
     * the clock offset found at 2000 Hz was 0.4 ms late when applied at
     * 5000 Hz (about 0.5 % of GVW on a 20 m span). */
    if (!(o.search_rate_hz > 0))
        o.search_rate_hz = design0->solver.calc_rate_hz;
    /* the tail the runs allow: the shortest free vibration after a run */
    for (int i = 0; i < runs->n; i++) {
        const cm_run *r = &runs->run[i];
        amfi_passage_times w = amfi_passage_window(design0->bridge.span_m, r->speed_mps,
                                                   r->n_axles, r->spacing_m, 0, 0);
        double avail = r->t0_s + (r->n_samples - 1) / r->rate_hz - (r->entry_s + w.on_span_s);
        if (avail - 0.1 < o.tail_s)
            o.tail_s = avail - 0.1;
    }
    if (o.tail_s < 0.3) {
        snprintf(err, errlen, "the runs keep only %.2f s of free vibration after the last "
                 "axle: record at least 1 s more", o.tail_s + 0.1);
        return -1;
    }
    /* Each run's own speed (speed_sd > 0) and a clock offset: an entry time
     * δ late moves every run's estimate to match the exit (v (1 + δ v / L)),
     * and what is left of δ in the runs is their weights' mean, which the
     * mass takes. Measured (E +10 %, 3 % noise, the detector's speed
     * N(0, 3 %), 20 runs): the scans' cost changed by 0.1 % between clock
     * offsets of 0 and −15 ms; the search stopped at −15 ms for the truth's
     * 0, with the mass +7.5 % and the stiffness +7.5 % (with the clock held:
     * −0.67 % and −0.68 %). */
    if (o.speed_sd > 0 && o.fit[CM_P_CLOCK]) {
        snprintf(err, errlen,
                 "with each run's speed estimated (--speed-sd) the runs cannot tell the "
                 "detector's clock offset from the mass: hold clock (measure the detector's "
                 "timing against the accelerometers' clock apart, e.g. with one run of a "
                 "truck whose speed is known, and give it in the design's detector: section)");
        return -1;
    }
    /* speeds: the clock offset and the speed scale separate only over a
     * spread of speeds */
    double vmin = INFINITY, vmax = 0;
    for (int i = 0; i < runs->n; i++) {
        vmin = fmin(vmin, runs->run[i].speed_mps);
        vmax = fmax(vmax, runs->run[i].speed_mps);
    }
    if ((o.fit[CM_P_CLOCK] || o.fit[CM_P_SPEED]) && vmax / vmin < 1.15) {
        snprintf(err, errlen,
                 "the runs' speeds (%.1f .. %.1f m/s) are too alike to tell the detector's "
                 "clock offset from its speed scale: spread them over at least 15 %% "
                 "(COST 323: the site's range of speeds) or hold one of the two",
                 vmin, vmax);
        return -1;
    }
    /* stage 1 */
    if (cm_modal_identify(runs, design0, amb, amb_n, amb_rate, n_amb, res, err, errlen) != 0)
        return -1;
    amfi_site_config design = *design0;
    design.bridge.damping_ratio = res->zeta_meas;
    int max_axles = 1;
    for (int i = 0; i < runs->n; i++)
        if (runs->run[i].n_axles > max_axles)
            max_axles = runs->run[i].n_axles;
    if (design.solver.max_axles < max_axles)
        design.solver.max_axles = max_axles;

    int any_rot = 0;
    for (int i = 0; i < design.bridge.n_supports; i++)
        any_rot |= rotatable(&design.bridge.supports[i]);
    o.fit[CM_P_KAPPA] &= any_rot;
    if (o.n_segments > 0 && setup_segments(&design, runs, &o, res, err, errlen) != 0)
        return -1;

    /* the design as it is: weighed as amfid weighs, and its fit with the
     * free vibration in the window */
    cm_options o_weigh = o;
    o_weigh.tail_s = design0->solver.post_roll_s;
    double p[CM_N_PARAMS] = {0};
    if (evaluate_both(design0, p, runs, &o, &o_weigh, &res->before, err, errlen) != 0)
        return -1;
    res->cpu_modal_s = cpu_s() - c_mark;
    c_mark = cpu_s();
    if (o.speed_sd > 0) {
        /* the runs' own speeds, on the design with f1 met */
        amfi_site_config sf;
        double pf[CM_N_PARAMS] = {0};
        if (match_f1(&design, res->f1_meas_hz, pf, err, errlen) != 0 ||
            cm_site_apply(&design, pf, &sf, err, errlen) != 0 ||
            estimate_run_speeds(&sf, runs, &o, res, err, errlen) != 0)
            return -1;
        o.fit[CM_P_SPEED] = 0; /* the runs' estimates carry it */
        res->cpu_speed_s = cpu_s() - c_mark;
        c_mark = cpu_s();
    }

    int use[CM_MAX_RUNS];
    nls q;
    memset(&q, 0, sizeof q);
    q.design = &design;
    q.runs = runs;
    /* The scans and the search solve with the modes the calculation step
     * resolves (below half its rate): a mode above it is aliased, and the
     * sweep's cost grows with the modes (libamfi: the same GVW to 0.1 kg
     * as every observable mode, several times faster; docs/results/
     * speed-estimation.md). The weighings before and after keep the
     * site's own modes. */
    cm_options o_search = o;
    o_search.resolved_modes = 1;
    q.o = &o_search;
    q.use = use;
    q.n_use = pick_runs(runs, o.max_search_runs, use);
    q.f1 = res->f1_meas_hz;
    /* f1 is weighted by its spread, but never tighter than 0.02 % (the
     * model's own discretisation) */
    q.f1_sd = fmax(res->f1_meas_sd_hz, 2e-4 * res->f1_meas_hz);

    /* Stage 2a: scans that put the search in the truth's valley. The cost
     * around the truth is narrow (about 1 ms of clock and 0.2 % of speed
     * on a 20 m span) and has other valleys (a speed scale 2-3 % high keeps
     * the trucks on the span longer): a local search from the design's
     * detector (clock 0, scale 1) stopped in one of those, with the mass
     * 4.5 % and the speed scale 2.2 % off. Here, on a few runs at a coarse
     * rate: the clock, then the speed scale, then the clock finer; the
     * sensor offset; the bearings' κ over a grid; the clock, speed and
     * sensor again, finer. Each point
     * has f1 met exactly (the stiffness-to-mass ratio) and the common scale
     * from the loads, and its cost does not depend on that scale. */
    double kd = 0;
    for (int i = 0; i < design.bridge.n_supports; i++)
        if (rotatable(&design.bridge.supports[i]) && design.bridge.supports[i].k_theta_nmprad > 0)
            kd = design.bridge.supports[i].k_theta_nmprad * design.bridge.span_m /
                 design_EI(&design);
    double kgrid[16] = {kd};
    int nk = 1;
    if (o.fit[CM_P_KAPPA]) {
        static const double g[] = {0, 0.1, 0.25, 0.5, 1, 2, 4, 8, 20, 60};
        for (size_t i = 0; i < sizeof g / sizeof g[0]; i++)
            if (fabs(g[i] - kd) > 1e-9)
                kgrid[nk++] = g[i];
    }
    int scan_use[CM_MAX_RUNS];
    nls qs = q;
    qs.use = scan_use;
    qs.n_use = pick_runs(runs, SCAN_RUNS, scan_use);
    qs.rate_hz = fmin(SCAN_RATE_HZ, o.search_rate_hz);
    /* Two paths, the better kept: the clock then the speed scale scanned
     * one after the other (found the combination case; stopped in a wrong
     * valley for a detector 3 % fast), and the two jointly (found that one;
     * stopped in a wrong valley on the combination case: clock 1.9 ms for
     * 10, traffic −6.2 %). */
    double best_p[CM_N_PARAMS] = {0}, best_cost = INFINITY;
    const int n_paths = o.fit[CM_P_CLOCK] && o.fit[CM_P_SPEED] ? 2 : 1;
    double clock0 = 0, speed0 = 0; /* path 0's detector after its first scans */
    for (int path = 0; path < n_paths; path++) {
        double pp[CM_N_PARAMS] = {0}, pc = INFINITY, kc[16];
        pp[CM_P_KAPPA] = log(kd > KAPPA_PIN ? kd : 0.1 * KAPPA_PIN);
        if (scan_cost(&qs, pp, &pc) != 0)
            goto scan_fail;
        if (path == 1) {
            /* jointly: a clock offset and a speed scale trade (one shifts the
             * loads, the other stretches their path), and scanned one after
             * the other from scale 1 they stopped in a wrong valley for a
             * detector 3 % fast (traffic −3.9 %) */
            double bp[CM_N_PARAMS];
            memcpy(bp, pp, sizeof bp);
            for (int a = 0; a < 17; a++)
                for (int b2 = 0; b2 < 9; b2++) {
                    double pk[CM_N_PARAMS], c;
                    memcpy(pk, pp, sizeof pk);
                    pk[CM_P_CLOCK] = -0.04 + 0.005 * a;
                    pk[CM_P_SPEED] = log(0.96 + 0.01 * b2);
                    if (scan_cost(&qs, pk, &c) != 0)
                        goto scan_fail;
                    if (c < pc) {
                        pc = c;
                        memcpy(bp, pk, sizeof bp);
                    }
                }
            memcpy(pp, bp, sizeof bp);
            if (o.verbose)
                fprintf(stderr, "amfi-commission: scan clock x speed: %+.4f s x%.4f: cost %.5g\n",
                        pp[CM_P_CLOCK], exp(pp[CM_P_SPEED]), pc);
            if (scan_1d(&qs, pp, &pc, CM_P_CLOCK, pp[CM_P_CLOCK] - 0.004,
                        pp[CM_P_CLOCK] + 0.004, 9, o.verbose) != 0 ||
                scan_1d(&qs, pp, &pc, CM_P_SPEED, pp[CM_P_SPEED] - 0.006,
                        pp[CM_P_SPEED] + 0.006, 7, o.verbose) != 0)
                goto scan_fail;
        } else if (o.fit[CM_P_CLOCK] &&
                   (scan_1d(&qs, pp, &pc, CM_P_CLOCK, -0.05, 0.05, 21, o.verbose) != 0 ||
                    (o.fit[CM_P_SPEED] &&
                     scan_1d(&qs, pp, &pc, CM_P_SPEED, log(0.95), log(1.05), 11,
                             o.verbose) != 0) ||
                    scan_1d(&qs, pp, &pc, CM_P_CLOCK, pp[CM_P_CLOCK] - 0.006,
                            pp[CM_P_CLOCK] + 0.006, 9, o.verbose) != 0))
            goto scan_fail;
        if (!o.fit[CM_P_CLOCK] && o.fit[CM_P_SPEED] &&
            scan_1d(&qs, pp, &pc, CM_P_SPEED, log(0.95), log(1.05), 11, o.verbose) != 0)
            goto scan_fail;
        /* Path 1 at path 0's point (its clock within 0.5 ms, its speed
         * within 0.05 %, less than the scans' finest steps): the stages below
         * would start from the same point and end where path 0 ended
         * (measured: the combination case's two paths reached the same clock
         * and speed, then the same cost, 0.02016, after 46 more evaluations
         * each). Path 0's result stands. Not wider: on 6 runs (E +10 %,
         * 10 ms late) path 0 stopped at 10 ms and speed x0.99875, path 1 at
         * 11 ms and x1.0000 with a lower scan cost, and the search from
         * there found another point. */
        if (path == 0) {
            clock0 = pp[CM_P_CLOCK];
            speed0 = pp[CM_P_SPEED];
        } else if (fabs(pp[CM_P_CLOCK] - clock0) <= 0.0005 &&
                   fabs(pp[CM_P_SPEED] - speed0) <= 0.0005) {
            if (o.verbose)
                fprintf(stderr, "amfi-commission: scan path 1 at path 0's point (%+.4f s x%.4f)"
                                ": path 0 kept\n", pp[CM_P_CLOCK], exp(pp[CM_P_SPEED]));
            break;
        }
        /* the sensor (the search alone moved it 0.3 m in 40 evaluations) */
        if (o.fit[CM_P_SENSOR] &&
            scan_1d(&qs, pp, &pc, CM_P_SENSOR, -1.5, 1.5, 13, o.verbose) != 0)
            goto scan_fail;
        {
            double pk0[CM_N_PARAMS];
            memcpy(pk0, pp, sizeof pk0);
            for (int g = 0; g < nk; g++) {
                double pk[CM_N_PARAMS], c;
                memcpy(pk, pk0, sizeof pk);
                pk[CM_P_KAPPA] = log(kgrid[g] > KAPPA_PIN ? kgrid[g] : 0.1 * KAPPA_PIN);
                if (scan_cost(&qs, pk, &c) != 0)
                    goto scan_fail;
                kc[g] = c;
                if (o.verbose)
                    fprintf(stderr, "amfi-commission: bearings kL/EI = %g: cost %.5g\n", kgrid[g], c);
                if (c < pc) {
                    pc = c;
                    memcpy(pp, pk, sizeof pk);
                }
            }
        }
        if ((o.fit[CM_P_CLOCK] &&
             scan_1d(&qs, pp, &pc, CM_P_CLOCK, pp[CM_P_CLOCK] - 0.003,
                     pp[CM_P_CLOCK] + 0.003, 7, o.verbose) != 0) ||
            (o.fit[CM_P_SPEED] &&
             scan_1d(&qs, pp, &pc, CM_P_SPEED, pp[CM_P_SPEED] - 0.009,
                     pp[CM_P_SPEED] + 0.009, 7, o.verbose) != 0) ||
            (o.fit[CM_P_SENSOR] &&
             scan_1d(&qs, pp, &pc, CM_P_SENSOR, pp[CM_P_SENSOR] - 0.2,
                     pp[CM_P_SENSOR] + 0.2, 9, o.verbose) != 0))
            goto scan_fail;
        if (o.verbose)
            fprintf(stderr, "amfi-commission: scan path %d: cost %.5g\n", path, pc);
        if (pc < best_cost) {
            best_cost = pc;
            memcpy(best_p, pp, sizeof pp);
            for (int g = 0; g < nk; g++)
                res->kappa_grid[g] = kgrid[g], res->kappa_cost[g] = kc[g];
        }
    }
    if (0) {
    scan_fail:
        snprintf(err, errlen, "%s", qs.err);
        return -1;
    }
    res->n_kappa = nk;
    res->scan_evaluations = qs.evaluations;
    res->cpu_scan_s = cpu_s() - c_mark;
    c_mark = cpu_s();
    memcpy(p, best_p, sizeof p);
    /* a pin stays a pin: log κ has no slope there */
    if (exp(p[CM_P_KAPPA]) <= KAPPA_PIN)
        o.fit[CM_P_KAPPA] = 0;

    /* Stage 2b: every fitted parameter from the scan's best, the ratio
     * following f1 */
    q.n_fit = 0;
    q.rate_hz = o.search_rate_hz;
    q.match_f1 = o.fit[CM_P_EI];
    for (int k = 0; k < CM_N_PARAMS; k++)
        if (o.fit[k] && k != CM_P_EI)
            q.idx[q.n_fit++] = k;
    memcpy(q.p0, p, sizeof p);
    if (q.n_fit > 0) {
        if (run_nls(&q, p, res->sd, res->cov, &res->corr_max, &res->corr_i, &res->corr_j,
                    &res->iterations, MAX_ITER, err, errlen) != 0)
            return -1;
        res->evaluations = q.evaluations;
        if (q.match_f1) {
            /* log r = 2 log(f1_meas / f1(others)): its variance from f1's
             * and, through the bearings, from κ's (d log r / d log κ by a
             * difference) */
            double pk[CM_N_PARAMS];
            memcpy(pk, p, sizeof pk);
            if (match_f1(&design, q.f1, p, err, errlen) != 0)
                return -1;
            double d = 0;
            if (o.fit[CM_P_KAPPA]) {
                pk[CM_P_KAPPA] += fd_step(CM_P_KAPPA);
                if (match_f1(&design, q.f1, pk, err, errlen) != 0)
                    return -1;
                d = (pk[CM_P_EI] - p[CM_P_EI]) / fd_step(CM_P_KAPPA);
            }
            double sf = 2 * res->f1_meas_sd_hz / res->f1_meas_hz;
            for (int k = 0; k < CM_N_PARAMS; k++)
                res->cov[CM_P_EI][k] = res->cov[k][CM_P_EI] = d * res->cov[CM_P_KAPPA][k];
            res->cov[CM_P_EI][CM_P_EI] = sf * sf + d * d * res->cov[CM_P_KAPPA][CM_P_KAPPA];
            res->sd[CM_P_EI] = sqrt(res->cov[CM_P_EI][CM_P_EI]);
        }
        if (res->corr_max > 0.98) {
            snprintf(err, errlen,
                     "the runs cannot tell the %s from the %s (correlation %.3f): they trade "
                     "against each other; %s",
                     cm_param_names[res->corr_i], cm_param_names[res->corr_j], res->corr_max,
                     res->corr_i >= CM_P_SEG || res->corr_j >= CM_P_SEG
                         ? "fewer segments, or sensors nearer the segments (a segment's "
                           "stiffness is relative to the reference segment's, the first "
                           "sensor's)"
                         : "add runs at other speeds or with another truck, or hold one of "
                           "them");
            return -1;
        }
        if (res->n_segments > 0) {
            if (segment_results(&design, &q, p, res, err, errlen) != 0)
                return -1;
            /* No refusal on the correlation between two segments' values:
             * with f1 fixed they are anti-correlated by construction (one
             * stiffer, the other softer, f1 the same) and with the mass's
             * uncertainty positively (the common level). Whether the runs
             * tell the segments apart is the fitted parameters' correlation
             * (each segment relative to the reference, above) and each
             * segment's uncertainty (below). Measured: 20 noise-free runs,
             * the left half 10 % soft, --segments 2 with the detector and
             * sensor held: the halves' correlation -0.989 while each was
             * found within 1.2 %. */
            for (int i = 0; i < res->n_segments; i++)
                if (!(res->seg_sd_rel[i] <= CM_SEG_MAX_SD)) {
                    snprintf(err, errlen,
                             "segment %d's stiffness (%g .. %g m) is found x%.4f +- %.1f %%, "
                             "more than %.0f %%: the sensors barely see it (largest "
                             "correlation: %s, %.3f); fewer segments, or sensors nearer it",
                             i + 1, res->seg_x0_m[i], res->seg_x1_m[i], res->seg_scale[i],
                             100 * res->seg_sd_rel[i], 100 * CM_SEG_MAX_SD,
                             res->seg_corr_what[0] ? res->seg_corr_what : "none",
                             res->seg_corr_max);
                    return -1;
                }
        }
    } else {
        for (int k = 0; k < CM_N_PARAMS; k++)
            res->sd[k] = NAN;
    }
    memcpy(res->p, p, sizeof p);
    if (runs->speed_estimated) { /* the speed scale: the estimates' mean at the clock found */
        res->speed_scale_log = runs->speed_ymean + (p[CM_P_CLOCK] - runs->clock_ref) *
                                                       runs->speed_gmean;
        res->speed_scale_sd = 0.01 * res->run_speed_sd_pct / sqrt(runs->n);
    } else {
        res->speed_scale_log = p[CM_P_SPEED];
        res->speed_scale_sd = res->sd[CM_P_SPEED];
    }
    for (int i = 0; i < runs->n; i++) { /* each run's speed as found */
        const cm_run *r = &runs->run[i];
        const double lv =
            runs->speed_estimated
                ? r->speed_eps + (p[CM_P_CLOCK] - runs->clock_ref) * r->speed_gdev
                : 0.0;
        res->run_speed_mps[i] = r->speed_mps * exp(-lv - p[CM_P_SPEED]) / design.detector.speed_scale;
    }
    if (cm_site_apply(&design, p, &res->site, err, errlen) != 0)
        return -1;
    res->cpu_search_s = cpu_s() - c_mark;
    c_mark = cpu_s();

    /* Stage 3: λ. By default the design's: λ chosen on the calibration runs
     * (leaving each out) went to the grid's smallest, 1e-10, on every case
     * measured (two heavy trucks ask for little smoothing), and that weighed
     * the traffic 0.3-0.6 % heavier than the design's 7.94e-9 with the same
     * model (traffic mean +0.32 against +0.03 % on the combination case,
     * +0.56 against −0.10 % with bearings of 2 EI/L; docs/results/
     * commissioning.md). With fit_lambda, or when the design's λ is auto,
     * a grid judged on the runs left out. */
    if (!o.fit_lambda && !design0->lambda.automatic) {
        res->lambda_ref = design0->lambda.lambda_ref;
        res->site.lambda = design0->lambda;
        if (evaluate_both(&res->site, p, runs, &o, &o_weigh, &res->after, err, errlen) != 0)
            return -1;
        for (int i = 0; i < runs->n; i++) /* nothing was chosen with run i */
            res->loo_gvw_err_pct[i] = res->after.gvw_err_pct[i];
        res->cpu_final_s = cpu_s() - c_mark;
        res->seconds = now_s() - t_start;
        return 0;
    }
    static const double grid[] = {1e-10, 3e-10, 1e-9, 3e-9, 7.94e-9, 2e-8, 6e-8, 2e-7, 6e-7};
    enum { NG = sizeof grid / sizeof grid[0] };
    static double err_g[NG][CM_MAX_RUNS];
    static cm_eval ev_g[NG]; /* the chosen λ's is the commissioned model's weighing */
    amfi_site_config s = res->site;
    s.lambda.automatic = 0;
    s.lambda.ref_rate_hz = design.lambda.ref_rate_hz;
    for (int g = 0; g < NG; g++) {
        s.lambda.lambda_ref = grid[g];
        if (cm_evaluate(&s, p, runs, &o_weigh, design.solver.calc_rate_hz, NULL, &ev_g[g], err,
                        errlen) != 0)
            return -1;
        memcpy(err_g[g], ev_g[g].gvw_err_pct, sizeof ev_g[g].gvw_err_pct);
    }
    int best = 0;
    double best_lcost = INFINITY;
    for (int g = 0; g < NG; g++) {
        double c = 0;
        for (int i = 0; i < runs->n; i++)
            c += err_g[g][i] * err_g[g][i];
        if (c < best_lcost)
            best_lcost = c, best = g;
    }
    for (int i = 0; i < runs->n; i++) { /* λ picked without run i */
        int bg = 0;
        double bc = INFINITY;
        for (int g = 0; g < NG; g++) {
            double c = 0;
            for (int j = 0; j < runs->n; j++)
                if (j != i)
                    c += err_g[g][j] * err_g[g][j];
            if (c < bc)
                bc = c, bg = g;
        }
        res->loo_gvw_err_pct[i] = err_g[bg][i];
    }
    res->lambda_ref = grid[best];
    res->lambda_fitted = 1;
    res->site.lambda.automatic = 0;
    res->site.lambda.lambda_ref = grid[best];
    /* the weighing at that λ is the grid's (not solved again); the fit with
     * the free vibration in the window */
    cm_eval fit;
    res->after = ev_g[best];
    if (cm_evaluate(&res->site, p, runs, &o, design.solver.calc_rate_hz, NULL, &fit, err,
                    errlen) != 0)
        return -1;
    memcpy(res->after.resid_rel, fit.resid_rel, sizeof fit.resid_rel);
    memcpy(res->after.free_rel, fit.free_rel, sizeof fit.free_rel);
    res->after.mean_resid_rel = fit.mean_resid_rel;
    res->cpu_final_s = cpu_s() - c_mark;
    res->seconds = now_s() - t_start;
    return 0;
}
